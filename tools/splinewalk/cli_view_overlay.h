/* SPDX-License-Identifier: MIT */
/* The viewer's overlays (cli_view_overlay.c): frame times, trim atlas. The window's GL thread
 * only. */
#ifndef SW_CLI_VIEW_OVERLAY_H
#define SW_CLI_VIEW_OVERLAY_H

enum { SW_CLI_OVERLAY_FRAMES = 120 };

typedef struct sw_cli_overlay {
    unsigned program, vao, vbo;
    float ms[SW_CLI_OVERLAY_FRAMES];
    unsigned char fallback[SW_CLI_OVERLAY_FRAMES];
    int next, count;
    int enabled;
} sw_cli_overlay;

/* Needs the window's context current. Returns 0, or -1 when the shaders do not build (the
 * overlay then draws nothing). */
int sw_cli_overlay_init(sw_cli_overlay *o);
void sw_cli_overlay_free(sw_cli_overlay *o);
void sw_cli_overlay_push(sw_cli_overlay *o, double frame_ms, int fallback);
/* Draws into the window's framebuffer (0) of w x h pixels; sets the GL state it needs. */
void sw_cli_overlay_draw(const sw_cli_overlay *o, int w, int h);

/* One page of the renderer's trim atlas in the upper right corner (key A cycles the pages). */
typedef struct sw_cli_atlas_view {
    unsigned program, vao, vbo;
    int page; /* -1: off */
} sw_cli_atlas_view;

int sw_cli_atlas_view_init(sw_cli_atlas_view *a); /* 0, or -1 (shaders do not build) */
void sw_cli_atlas_view_free(sw_cli_atlas_view *a);
/* Off -> page 0 -> ... -> the last of `pages` -> off. */
void sw_cli_atlas_view_next(sw_cli_atlas_view *a, int pages);
/* texture: the atlas's GL_TEXTURE_2D_ARRAY in the window's context (sw_gpu_trim_atlas_info). */
void sw_cli_atlas_view_draw(const sw_cli_atlas_view *a, unsigned texture, int pages, int w, int h);

#endif
