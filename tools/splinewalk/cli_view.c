/* SPDX-License-Identifier: MIT */
/* splinewalk view SCENE: the interactive viewer. A GLFW window is the host: its context
 * is current on this thread, a renderer is made on it (sw_renderer_desc.use_current_context), and
 * frames run through the renderer's pipeline as `profile` runs them: frame i + 1 is prepared on
 * the visibility thread (sw_renderer_prepare) while frame i is submitted and presented into the
 * window (sw_frame_desc.present). Interactively that shows each camera one frame after the input
 * that made it. --script replays a camera path for a fixed number of frames (tests under
 * xvfb-run, demos) and --profile records it as `profile` does; --record writes the keys set
 * with K.
 */
#include "cli.h"
#include "cli_profile_out.h"
#include "cli_view_overlay.h"
#include "sw_rt.h"

#include "sw_camera_path.h"
#include "sw_gpu.h"

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES
#endif
#define GLFW_INCLUDE_GLCOREARB
#include <GLFW/glfw3.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char k_usage[] =
    "usage: splinewalk view SCENE [--size WxH] [--error PX] [--speed S] [--record PATH]\n"
    "                       [--script PATH --frames N [--screenshot OUT.png] [--settle]\n"
    "                        [--converged] [--profile DIR]] [--memory-budget HOST[,GPU]]\n"
    "\n"
    "Opens a window (GLFW; needs a display: under no display use `splinewalk profile`, or run\n"
    "inside xvfb-run) and walks through SCENE in walkthrough mode: frames never wait for the\n"
    "worker pool; what is not refined yet is drawn coarser and refined for later frames. As in\n"
    "`profile`, the renderer's visibility thread prepares the next frame while this one is drawn\n"
    "and shown, so a view appears one frame after the input that asked for it.\n"
    "\n"
    "keys:\n"
    "  W A S D       forward, left, back, right      Q E   down, up (along +Z)\n"
    "  mouse drag    look around (left button)      scroll   walking speed x1.25 / x0.8\n"
    "  + -           screen-space error x2 / x0.5   (shown in the title, with the frame time)\n"
    "  K             add the current camera as a key to the recording (--record)\n"
    "  L             wireframe on / off (the tessellation the error bound chose)\n"
    "  T             static LODs of super-surfaces on / off (Kumar et al. 1997; --static-lod)\n"
    "  O             occlusion culling on / off: what visible planar faces hide is not drawn\n"
    "                (on unless --no-occlusion; the image is the same, the frame cheaper)\n"
    "  C             LOD colouring on / off: static levels fine to coarse blue, teal, green,\n"
    "                yellow, orange, pink; per-frame tessellation grey, violet where cut by\n"
    "                exact trim edges\n"
    "  X             exact trim edges on / off: close-up trims cut per fragment by their\n"
    "                loops instead of trim textures (on unless --no-exact-edges)\n"
    "  A             trim-atlas overlay: the next page of the trim-texture atlas in the upper\n"
    "                right corner (white: inside the trimmed surface), then off\n"
    "  F             frame-time overlay on / off (bars of the last 120 frames, marks at 60 and\n"
    "                30 frames per second; orange: the frame drew something coarser than asked)\n"
    "  R             back to the iso view           Esc      close\n"
    "\n"
    "options:\n"
    "  --size WxH        window size (default 1280x720)\n"
    "  --error PX        screen-space error bound in pixels, at least 0.01 (default 0.5)\n"
    "  --speed S         walking speed in scene diagonals per second (default 0.1)\n"
    "  --record PATH     on close, write the keys set with K as a camera path "
    "(docs/camera-path.md)\n"
    "  --script PATH     no input: the camera follows the camera path PATH for --frames N frames\n"
    "  --frames N        frames of the script (default: the path's own count, else 120)\n"
    "  --screenshot OUT  after the script, save the window's last frame (PNG) and print its "
    "camera\n"
    "  --settle          after the script, draw the last view once more converged (every\n"
    "                    refinement done), as `splinewalk render --camera` draws it\n"
    "  --overlay         with --script: draw the frame-time overlay too (interactive: always,\n"
    "                    F toggles it)\n"
    "  --converged       with --script: every frame waits for the refinements it asks for\n"
    "                    (as `profile --converged`; the images and counters are then the same\n"
    "                    on every run)\n"
    "  --profile DIR     with --script: write DIR/profile.csv, profile.json, frametime.svg and\n"
    "                    report.html, the columns of `splinewalk profile` (docs/cli.md); frame_ms\n"
    "                    also holds the overlay and the buffer swap, in other_ms\n"
    "  --wireframe       start with the wireframe on (L toggles it)\n"
    "  --no-occlusion    start with occlusion culling off (O toggles it)\n"
    "  --no-static-lod   start with static LODs off (on by default, T toggles them: read\n"
    "                    from the scene's `build-lod` cache, else built in the pool as\n"
    "                    needed, which is said on stderr; --static-lod is the default)\n"
    "  --lod-colors      start with LOD colouring on (C toggles it)\n"
    "  --no-exact-edges  start with exact trim edges off: trim textures only, as for `render`\n"
    "                    (X toggles them)\n"
    "  --atlas-overlay   start with the trim atlas's first page shown (A cycles the "
    "pages)\n" SW_CLI_MEMORY_BUDGET_HELP "  -h, --help        this text\n";

typedef struct view_args {
    const char *scene, *record, *script, *screenshot, *profile;
    int32_t w, h;
    int frames, settle, overlay, wireframe, static_lods, no_static_lods, lod_colors, atlas_overlay,
        no_occlusion, converged, no_exact_edges;
    double error_px, speed;
    uint64_t budget_host, budget_gpu; /* --memory-budget; 0 = the default */
} view_args;

static int parse_value(view_args *a, const char *arg, const char *val)
{
    if (!strcmp(arg, "--size"))
        return sw_cli_parse_size(val, &a->w, &a->h);
    if (!strcmp(arg, "--error"))
        return sw_cli_parse_error_px(val, &a->error_px);
    if (!strcmp(arg, "--memory-budget"))
        return sw_cli_parse_memory_budget(val, &a->budget_host, &a->budget_gpu);
    if (!strcmp(arg, "--speed"))
        return sw_cli_parse_positive(val, &a->speed);
    if (!strcmp(arg, "--frames"))
        return sw_cli_parse_count(val, 1, (int)SW_RT_PATH_MAX_FRAMES, &a->frames);
    if (!strcmp(arg, "--record"))
        a->record = val;
    else if (!strcmp(arg, "--script"))
        a->script = val;
    else if (!strcmp(arg, "--screenshot"))
        a->screenshot = val;
    else if (!strcmp(arg, "--profile"))
        a->profile = val;
    else
        return -1;
    return 0;
}

static int parse_args(int argc, char **argv, view_args *a)
{
    *a = (view_args){.w = SW_DEFAULT_WIDTH,
                     .h = SW_DEFAULT_HEIGHT,
                     .error_px = SW_DEFAULT_ERROR_PX,
                     .speed = 0.1};
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i], *val = i + 1 < argc ? argv[i + 1] : NULL;
        int *flag = !strcmp(arg, "--settle")           ? &a->settle
                    : !strcmp(arg, "--overlay")        ? &a->overlay
                    : !strcmp(arg, "--wireframe")      ? &a->wireframe
                    : !strcmp(arg, "--static-lod")     ? &a->static_lods
                    : !strcmp(arg, "--no-static-lod")  ? &a->no_static_lods
                    : !strcmp(arg, "--lod-colors")     ? &a->lod_colors
                    : !strcmp(arg, "--atlas-overlay")  ? &a->atlas_overlay
                    : !strcmp(arg, "--no-occlusion")   ? &a->no_occlusion
                    : !strcmp(arg, "--converged")      ? &a->converged
                    : !strcmp(arg, "--no-exact-edges") ? &a->no_exact_edges
                                                       : NULL;
        if (flag) {
            *flag = 1;
            continue;
        }
        if (arg[0] != '-' && !a->scene) {
            a->scene = arg;
            continue;
        }
        int bad = arg[0] == '-' && val ? parse_value(a, arg, val) : -1;
        if (bad < 0) {
            fprintf(stderr, "splinewalk view: unexpected argument '%s'\n%s", arg, k_usage);
            return 2;
        }
        if (bad) {
            return sw_cli_bad_value("view", arg, val, k_usage);
        }
        i++;
    }
    if (!a->scene) {
        fprintf(stderr, "splinewalk view: need SCENE\n%s", k_usage);
        return 2;
    }
    if ((a->screenshot || a->settle || a->frames || a->overlay || a->converged || a->profile) &&
        !a->script) {
        fprintf(stderr,
                "splinewalk view: --frames, --screenshot, --settle, --overlay, --converged and "
                "--profile need --script\n%s",
                k_usage);
        return 2;
    }
    return 0;
}

/* ---- camera --------------------------------------------------------------------------------- */

typedef struct walker {
    sw_camera cam;
    double yaw, pitch; /* radians; the view direction from them, +Z up */
    double speed;      /* world units per second */
    double mouse_x, mouse_y;
    int dragging;
} walker;

static void walker_look_from(walker *wk, const sw_camera *c)
{
    double d[3] = {c->target[0] - c->eye[0], c->target[1] - c->eye[1], c->target[2] - c->eye[2]};
    double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    wk->cam = *c;
    wk->yaw = atan2(d[1], d[0]);
    wk->pitch = asin(fmax(-1.0, fmin(1.0, d[2] / len)));
}

static void walker_direction(const walker *wk, double d[3])
{
    d[0] = cos(wk->pitch) * cos(wk->yaw);
    d[1] = cos(wk->pitch) * sin(wk->yaw);
    d[2] = sin(wk->pitch);
}

/* Moves the eye by the keys held for dt seconds, and keeps the target one unit ahead. */
static void walker_step(walker *wk, GLFWwindow *win, double dt)
{
    double d[3], side[3], move[3] = {0, 0, 0};
    walker_direction(wk, d);
    side[0] = sin(wk->yaw);
    side[1] = -cos(wk->yaw);
    side[2] = 0.0;
    const struct {
        int key;
        const double *axis;
        double sign;
    } binds[] = {
        {GLFW_KEY_W, d, 1}, {GLFW_KEY_S, d, -1}, {GLFW_KEY_D, side, 1}, {GLFW_KEY_A, side, -1}};
    for (size_t b = 0; b < sizeof binds / sizeof binds[0]; ++b) {
        if (glfwGetKey(win, binds[b].key) == GLFW_PRESS)
            for (int k = 0; k < 3; ++k)
                move[k] += binds[b].sign * binds[b].axis[k];
    }
    move[2] +=
        (glfwGetKey(win, GLFW_KEY_E) == GLFW_PRESS) - (glfwGetKey(win, GLFW_KEY_Q) == GLFW_PRESS);
    for (int k = 0; k < 3; ++k) {
        wk->cam.eye[k] += move[k] * wk->speed * dt;
        wk->cam.target[k] = wk->cam.eye[k] + d[k];
    }
    wk->cam.up[0] = wk->cam.up[1] = 0.0;
    wk->cam.up[2] = 1.0;
}

/* ---- the window and its input ------------------------------------------------------------------
 */

typedef struct viewer {
    view_args *args;
    walker wk;
    sw_camera home;
    double error_px;
    sw_rt_camera_path recording;
    uint32_t cap_keys;
    sw_cli_overlay overlay;
    sw_cli_atlas_view atlas;
    sw_renderer renderer;
    int wireframe, static_lods, lod_colors, occlusion, exact_edges;
} viewer;

static void record_key(viewer *v)
{
    if (!v->args->record)
        return;
    if (v->recording.n_keys == v->cap_keys) {
        uint32_t cap = v->cap_keys ? 2 * v->cap_keys : 16;
        sw_rt_path_key *k = realloc(v->recording.keys, cap * sizeof *k);
        if (!k)
            return;
        v->recording.keys = k;
        v->cap_keys = cap;
    }
    /* One second apart: a recording is a set of views, its timing is the path's to choose. */
    v->recording.keys[v->recording.n_keys] =
        (sw_rt_path_key){.t = (double)v->recording.n_keys, .camera = v->wk.cam};
    fprintf(stderr, "splinewalk view: key %u recorded\n", ++v->recording.n_keys);
}

static void on_key(GLFWwindow *win, int key, int scancode, int action, int mods)
{
    (void)scancode;
    (void)mods;
    viewer *v = glfwGetWindowUserPointer(win);
    if (action != GLFW_PRESS)
        return;
    if (key == GLFW_KEY_ESCAPE)
        glfwSetWindowShouldClose(win, 1);
    else if (key == GLFW_KEY_EQUAL || key == GLFW_KEY_KP_ADD)
        v->error_px = fmin(v->error_px * 2.0, 64.0);
    else if (key == GLFW_KEY_MINUS || key == GLFW_KEY_KP_SUBTRACT)
        v->error_px = fmax(v->error_px * 0.5, 1.0 / 64.0);
    else if (key == GLFW_KEY_K)
        record_key(v);
    else if (key == GLFW_KEY_F)
        v->overlay.enabled = !v->overlay.enabled;
    else if (key == GLFW_KEY_L)
        v->wireframe = !v->wireframe;
    else if (key == GLFW_KEY_T)
        v->static_lods = !v->static_lods;
    else if (key == GLFW_KEY_O)
        v->occlusion = !v->occlusion;
    else if (key == GLFW_KEY_C)
        v->lod_colors = !v->lod_colors;
    else if (key == GLFW_KEY_X)
        v->exact_edges = !v->exact_edges;
    else if (key == GLFW_KEY_A) {
        uint32_t tex;
        int32_t pages, side;
        sw_rt_renderer_trim_atlas(v->renderer, &tex, &pages, &side);
        sw_cli_atlas_view_next(&v->atlas, pages);
    } else if (key == GLFW_KEY_R)
        walker_look_from(&v->wk, &v->home);
}

static void on_scroll(GLFWwindow *win, double dx, double dy)
{
    (void)dx;
    viewer *v = glfwGetWindowUserPointer(win);
    v->wk.speed *= dy > 0 ? 1.25 : 0.8;
}

static void on_mouse(GLFWwindow *win, double x, double y)
{
    viewer *v = glfwGetWindowUserPointer(win);
    walker *wk = &v->wk;
    int down = glfwGetMouseButton(win, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
    if (down && wk->dragging) {
        wk->yaw -= (x - wk->mouse_x) * 0.004;
        wk->pitch = fmax(-1.5, fmin(1.5, wk->pitch - (y - wk->mouse_y) * 0.004));
    }
    wk->dragging = down;
    wk->mouse_x = x;
    wk->mouse_y = y;
}

static GLFWwindow *open_window(const view_args *a)
{
    if (!glfwInit()) {
        fprintf(stderr, "splinewalk view: no display to open a window on (GLFW could not start: "
                        "DISPLAY unset or unreachable). Headless, use `splinewalk profile SCENE "
                        "--path PATH --out DIR`, or run the viewer inside xvfb-run -a.\n");
        return NULL;
    }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE); /* the frame size is the window's */
    GLFWwindow *win = glfwCreateWindow(a->w, a->h, "splinewalk", NULL, NULL);
    if (!win) {
        fprintf(stderr, "splinewalk view: the display gives no OpenGL 4.5 core window\n");
        glfwTerminate();
        return NULL;
    }
    glfwMakeContextCurrent(win);
    glfwSwapInterval(0); /* frame times are the renderer's, not the monitor's */
    return win;
}

/* ---- frames -----------------------------------------------------------------------------------
 */

/* The frame of the viewer's camera and settings now. */
static sw_frame_desc frame_desc(sw_scene scene, const viewer *v, int converged, const char *output)
{
    sw_frame_desc fd = {0};
    fd.scene = scene;
    fd.camera = v->wk.cam;
    fd.width = v->args->w;
    fd.height = v->args->h;
    fd.error_px = v->error_px;
    fd.walkthrough = !converged;
    fd.present = 1;
    fd.wireframe = v->wireframe;
    fd.static_lods = v->static_lods;
    fd.lod_colors = v->lod_colors;
    fd.trim_edges = v->exact_edges;
    fd.occlusion_culling = v->occlusion;
    fd.output_path = output;
    return fd;
}

/* Hands the frame of the viewer's camera now to the visibility thread. */
static sw_result prepare(sw_renderer r, sw_scene scene, const viewer *v, int converged,
                         sw_status *st)
{
    const sw_frame_desc fd = frame_desc(scene, v, converged, NULL);
    return sw_renderer_prepare(r, &fd, st);
}

/* One frame drawn in one call (the settled view after a script). */
static sw_result draw(sw_renderer r, sw_scene scene, const viewer *v, int converged,
                      sw_frame_stats *fs, sw_status *st)
{
    const sw_frame_desc fd = frame_desc(scene, v, converged, NULL);
    return sw_renderer_draw(r, &fd, fs, st);
}

static void show_title(GLFWwindow *win, const viewer *v, const sw_frame_stats *fs)
{
    char title[256];
    snprintf(title, sizeof title,
             "splinewalk — %.1f ms, %llu triangles, %llu fallback draws, error %.3g px, speed %.3g",
             fs->ms_total, (unsigned long long)fs->triangles,
             (unsigned long long)fs->fallback_draws, v->error_px, v->wk.speed);
    glfwSetWindowTitle(win, title);
}

/* The host's own drawing over the presented frame (the renderer restored the framebuffer binding
 * and viewport; the rest of the state is set by the overlay). */
static void show_overlay(viewer *v, const sw_frame_stats *fs)
{
    sw_cli_overlay_push(&v->overlay, fs->ms_total, fs->fallback_draws > 0);
    sw_cli_overlay_draw(&v->overlay, v->args->w, v->args->h);
    uint32_t tex;
    int32_t pages, side;
    if (v->atlas.page >= 0 && sw_rt_renderer_trim_atlas(v->renderer, &tex, &pages, &side) == 0)
        sw_cli_atlas_view_draw(&v->atlas, tex, pages, v->args->w, v->args->h);
}

static void print_camera(const char *what, const sw_camera *c)
{
    printf("%s camera %.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", what,
           c->eye[0], c->eye[1], c->eye[2], c->target[0], c->target[1], c->target[2], c->up[0],
           c->up[1], c->up[2], c->fovy_deg);
}

/* What the window shows, saved as --screenshot: its back buffer, read after the present, before
 * the swap; the camera printed. */
static int save_screenshot(GLFWwindow *win, const viewer *v)
{
    sw_gpu_image img = {.width = v->args->w, .height = v->args->h};
    size_t row = (size_t)img.width * 4;
    uint8_t *bottom_up = malloc(row * (size_t)img.height);
    img.rgba = malloc(row * (size_t)img.height);
    if (!bottom_up || !img.rgba) {
        free(bottom_up);
        free(img.rgba);
        fprintf(stderr, "splinewalk view: out of memory for the screenshot\n");
        return 1;
    }
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, img.width, img.height, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up);
    for (int32_t y = 0; y < img.height; ++y)
        memcpy(img.rgba + (size_t)y * row, bottom_up + (size_t)(img.height - 1 - y) * row, row);
    free(bottom_up);
    sw_status st = {0};
    sw_result res = sw_gpu_image_write(&img, v->args->screenshot, &st);
    free(img.rgba);
    glfwSwapBuffers(win);
    if (res != SW_OK)
        return sw_cli_report("view", &st);
    printf("screenshot %s\n", v->args->screenshot);
    print_camera("screenshot", &v->wk.cam);
    return 0;
}

/* --profile: the run's description, as `profile` writes it. */
static void profile_meta(const viewer *v, sw_renderer r, sw_rt_profile *p)
{
    sw_rt_prof_meta *m = &p->meta;
    m->scene = v->args->scene;
    m->path = v->args->script;
    m->renderer = sw_renderer_description_ptr(r);
    m->mode = v->args->converged ? "converged" : "walkthrough";
    m->eval = "hierarchy";
    m->lp_num_threads = getenv("LP_NUM_THREADS");
    m->width = v->args->w;
    m->height = v->args->h;
    m->error_px = v->error_px;
    m->worker_threads = sw_cli_pool_workers(0);
}

/* --profile: the recorded frames summarized and written into DIR (aside, then renamed in). */
static sw_result profile_write(const char *dir, sw_rt_profile *p, sw_status *st)
{
    sw_cli_staging stage = {0};
    sw_result res = sw_cli_staging_make(dir, &stage, st);
    return res == SW_OK ? sw_cli_profile_finish(&stage, dir, p, SW_OK, st) : res;
}

/* Frame i of the script: frame i + 1 prepared (its camera set), frame i submitted, presented with
 * the overlay and swapped; with --profile its row, timed over all of that as `profile` times its
 * frames (frame_ms; the overlay and the swap fall in other_ms). */
static sw_result script_frame(GLFWwindow *win, sw_renderer r, sw_scene scene, viewer *v,
                              const sw_rt_camera_path *path, uint32_t i, uint32_t n,
                              sw_rt_profile *prof, sw_frame_stats *fs, sw_status *st)
{
    sw_cli_pool_sample pool_start, pool_end;
    const double t0 = sw__clock_ms();
    sw_cli_pool_read(r, 0, &pool_start);
    double prepare_ms = 0.0;
    sw_result res = SW_OK;
    if (i + 1 < n) {
        sw_rt_path_eval(path, sw_rt_path_frame_time(path, i + 1, n), &v->wk.cam);
        const double p0 = sw__clock_ms(); /* the prepare call alone, as `profile` times it */
        res = prepare(r, scene, v, v->args->converged, st);
        prepare_ms = sw__clock_ms() - p0;
    }
    if (res == SW_OK)
        res = sw_renderer_submit(r, fs, st);
    if (res != SW_OK)
        return res;
    show_overlay(v, fs);
    glfwSwapBuffers(win);
    glfwPollEvents();
    show_title(win, v, fs);
    if (!v->args->profile)
        return SW_OK;
    sw_cli_pool_read(r, 1, &pool_end);
    sw_rt_prof_row row;
    sw_rt_profile_row(fs, i, sw_rt_path_frame_time(path, i, n), sw__clock_ms() - t0, prepare_ms,
                      sw_cli_resident_bytes(), 0, &row);
    sw_cli_pool_columns(&pool_start, &pool_end, &row);
    return sw_rt_profile_push(prof, &row) == 0
               ? SW_OK
               : sw__fail(st, SW_ERR_OUT_OF_MEMORY, "profile: out of memory");
}

/* The scripted run: the path's cameras for `frames` frames, pipelined as `profile` runs them,
 * then optionally a converged frame and a screenshot of what the window shows. */
static int run_script(GLFWwindow *win, sw_renderer r, sw_scene scene, viewer *v,
                      const sw_rt_camera_path *path)
{
    uint32_t n = v->args->frames ? (uint32_t)v->args->frames : path->frames ? path->frames : 120;
    sw_status st = {0};
    sw_frame_stats fs = {0};
    sw_rt_profile prof = {0};
    uint64_t waits = 0, fallbacks = 0;
    double worst = 0.0, t0 = sw__clock_ms();
    if (v->args->profile) {
        sw_rt_renderer_time_pool_tasks(r, 1); /* the pool_<kind>_ms columns */
        profile_meta(v, r, &prof);
    }
    sw_rt_path_eval(path, sw_rt_path_frame_time(path, 0, n), &v->wk.cam);
    sw_result res = prepare(r, scene, v, v->args->converged, &st);
    uint32_t i = 0;
    for (; i < n && res == SW_OK; ++i) {
        res = script_frame(win, r, scene, v, path, i, n, &prof, &fs, &st);
        waits += fs.pool_waits;
        fallbacks += fs.fallback_draws;
        worst = fmax(worst, fs.ms_total);
        if (res == SW_OK && i + 1 < n && glfwWindowShouldClose(win)) {
            res = sw_renderer_submit(r, &fs, &st); /* the frame prepared ahead, not shown */
            n = i + 1;
        }
    }
    prof.meta.wall_s = (sw__clock_ms() - t0) / 1e3;
    if (res == SW_OK && v->args->profile)
        res = profile_write(v->args->profile, &prof, &st);
    sw_rt_profile_free(&prof);
    if (res != SW_OK)
        return sw_cli_report("view", &st);
    printf("script: %u frames in %.0f ms (slowest %.1f ms), pool waits %llu, fallback draws %llu\n",
           n, sw__clock_ms() - t0, worst, (unsigned long long)waits, (unsigned long long)fallbacks);
    if (v->args->profile)
        printf("wrote %s/profile.csv, profile.json, frametime.svg and report.html\n",
               v->args->profile);
    if (v->args->settle && draw(r, scene, v, 1, &fs, &st) != SW_OK)
        return sw_cli_report("view", &st);
    if (v->args->settle)
        show_overlay(v, &fs);
    if (!v->args->screenshot)
        return 0;
    return save_screenshot(win, v);
}

static int run_interactive(GLFWwindow *win, sw_renderer r, sw_scene scene, viewer *v)
{
    sw_status st = {0};
    sw_frame_stats fs = {0};
    double last = glfwGetTime();
    sw_result res = prepare(r, scene, v, 0, &st);
    while (res == SW_OK && !glfwWindowShouldClose(win)) {
        glfwPollEvents();
        double now = glfwGetTime();
        walker_step(&v->wk, win, fmin(now - last, 0.25));
        last = now;
        res = prepare(r, scene, v, 0, &st); /* the next frame, while this one is drawn */
        if (res == SW_OK)
            res = sw_renderer_submit(r, &fs, &st);
        if (res != SW_OK)
            break;
        show_overlay(v, &fs);
        show_title(win, v, &fs);
        glfwSwapBuffers(win);
    }
    if (res != SW_OK)
        return sw_cli_report("view", &st);
    if (v->args->record && v->recording.n_keys > 0) {
        if (sw_rt_path_save(&v->recording, v->args->record, 0, &st) != SW_OK)
            return sw_cli_report("view", &st);
        printf("recorded %u keys to %s\n", v->recording.n_keys, v->args->record);
    }
    return 0;
}

static int view_scene(view_args *a, GLFWwindow *win, sw_scene scene,
                      const sw_rt_camera_path *script)
{
    sw_status st = {0};
    sw_scene_info info;
    if (sw_scene_get_info(scene, &info, &st) != SW_OK)
        return sw_cli_report("view", &st);
    viewer v = {.args = a,
                .error_px = a->error_px,
                .wireframe = a->wireframe,
                .static_lods = !a->no_static_lods,
                .lod_colors = a->lod_colors,
                .occlusion = !a->no_occlusion,
                .exact_edges = !a->no_exact_edges};
    if (sw_camera_fit(scene, SW_VIEW_ISO, &v.home, &st) != SW_OK)
        return sw_cli_report("view", &st);
    walker_look_from(&v.wk, &v.home);
    double diag = 0.0;
    for (int k = 0; k < 3; ++k)
        diag += (info.bbox_max[k] - info.bbox_min[k]) * (info.bbox_max[k] - info.bbox_min[k]);
    v.wk.speed = a->speed * sqrt(diag);
    glfwSetWindowUserPointer(win, &v);
    glfwSetKeyCallback(win, on_key);
    glfwSetScrollCallback(win, on_scroll);
    glfwSetCursorPosCallback(win, on_mouse);
    sw_renderer r = {0};
    sw_renderer_desc rd = {.use_current_context = 1,
                           .memory_budget_host = a->budget_host,
                           .memory_budget_gpu = a->budget_gpu};
    int rc = sw_renderer_create(&rd, &r, &st) != SW_OK ? sw_cli_report("view", &st) : 0;
    if (rc == 0) {
        char budget[256];
        sw_cli_memory_budget_line(r, budget, sizeof budget);
        printf("view: %s", budget);
    }
    if (rc == 0 && sw_cli_overlay_init(&v.overlay) != 0)
        fprintf(stderr, "splinewalk view: the frame-time overlay's shaders do not build here\n");
    if (rc == 0 && sw_cli_atlas_view_init(&v.atlas) != 0)
        fprintf(stderr, "splinewalk view: the trim-atlas overlay's shaders do not build here\n");
    v.overlay.enabled = !script || a->overlay;
    v.atlas.page = a->atlas_overlay ? 0 : -1;
    v.renderer = r;
    if (rc == 0) {
        fprintf(stderr, "splinewalk view: %s\n", sw_renderer_description_ptr(r));
        rc = script ? run_script(win, r, scene, &v, script) : run_interactive(win, r, scene, &v);
        sw_cli_overlay_free(&v.overlay);
        sw_cli_atlas_view_free(&v.atlas);
        sw_renderer_destroy(r); /* while the window's context is still current */
    }
    free(v.recording.keys);
    return rc;
}

int sw_cli_view(int argc, char **argv)
{
    if (sw_cli_print_help(argc, argv, k_usage))
        return 0;
    view_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc)
        return rc;
    sw_status st = {0};
    sw_rt_camera_path script = {0};
    if (a.script && sw_rt_path_load(a.script, &script, &st) != SW_OK)
        return sw_cli_report("view", &st);
    /* The window first: without a display the user learns it before a long import. */
    GLFWwindow *win = open_window(&a);
    sw_scene scene = {0};
    if (!win)
        rc = 1;
    else if (sw_cli_load_scene(a.scene, 0, &scene, &st) != SW_OK)
        rc = sw_cli_report("view", &st);
    else
        rc = view_scene(&a, win, scene, a.script ? &script : NULL);
    sw_scene_destroy(scene);
    sw_rt_path_free(&script);
    if (win) {
        glfwDestroyWindow(win);
        glfwTerminate();
    }
    return rc;
}
