/* SPDX-License-Identifier: MIT */
/* Internal interfaces of gpu/ (never installed): the context's GL objects, the view set-up shared
 * by every draw path, CPU grid tessellation of Bézier patches (Guthe et al. 2005 §4.2, §5.2, on
 * the CPU in this slice) and trim-texture generation by fan parity (§4, §4.1, §7.1).
 * Tests include this header to check the trim texture against a CPU classification.
 */
#ifndef SW_GPU_INTERNAL_H
#define SW_GPU_INTERNAL_H

#include "sw_clock.h"
#include "sw_gpu.h"
#include "sw_sg_trim.h"

#include <GL/glcorearb.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Grid classes (§4.2): base grids of 1 and 3 segments subdivided by powers of two, per direction
 * independently: sw__gpu_grid_segments[c] = 1, 2, 3, 4, 6, 8, ..., 48, 64 (grid_set.c). */
enum { SW__GPU_GRID_CLASSES = 12, SW__GPU_GRID_MAX = 64 };
extern const int32_t sw__gpu_grid_segments[SW__GPU_GRID_CLASSES];

/* How patches are tessellated. AUTO: rational Bézier patches of degree <= 3 x 3 evaluated in the
 * vertex shader on predefined grids, others as CPU grids. CPU_GRIDS: every patch as a CPU grid
 * (the reference the GPU path is compared with in tests). */
typedef enum sw__gpu_eval_mode {
    SW__GPU_EVAL_AUTO = 0,
    SW__GPU_EVAL_CPU_GRIDS = 1
} sw__gpu_eval_mode;
void sw__gpu_set_eval_mode(sw_gpu_context *ctx, sw__gpu_eval_mode mode);

/* One instance of a predefined grid: a rational Bézier patch (or a piece of its domain) evaluated
 * by the vertex shader. std430 layout, mirrored by the GLSL struct in glsl/eval.vert.glsl
 * (112 bytes). */
typedef struct sw__gpu_patch_rec {
    float st[4];        /* s0, s1, t0, t1: the part of the local domain [0,1]^2 sampled */
    float trim_map[4];  /* trim lookup: (m0 + s m1, m2 + t m3) in the face's uv box's [0,1]^2 */
    float trim_rect[4]; /* atlas rectangle x0, y0, w, h in texels; w = 0 untrimmed */
    float color[4];
    uint32_t cp; /* first control point (vec4 index into the control-point buffer) */
    int32_t deg_u, deg_v;
    float layer; /* atlas layer */
    float normal_sign;
    int32_t draw;             /* CPU side: the frame draw holding the colour and the trim entry */
    int32_t level_u, level_v; /* grid class: sw__gpu_grid_segments[level] segments */
    float uv_map[4]; /* the face's parameters: (u, v) = (m0 + s m2, m1 + t m3), for shading */
} sw__gpu_patch_rec;

/* Exact evaluation (eval_exact): what a record's cp indexes instead of Bézier control points —
 * one B-spline span of a face occurrence. std430, mirrored by the GLSL struct in
 * glsl/exact.vert.glsl (64 bytes). The record's st maps to u = u0 + s (u1 - u0), v likewise. */
typedef struct sw__gpu_exact_piece {
    double u0, u1, v0, v1; /* the Bézier patch's rectangle in the face's parameters */
    uint32_t ku, kv;       /* first knot of the face's u and v knot vectors (double index) */
    uint32_t cp;           /* first control point of the face occurrence (dvec4 index) */
    int32_t stride;        /* control points per row (n_u) */
    int32_t deg_u, deg_v;
    int32_t span_u, span_v; /* knot span of [u0, u1) and [v0, v1) */
} sw__gpu_exact_piece;

/* Debug capture (tests): while max_vertices > 0, every vertex the Bézier vertex shader evaluates
 * (§4.2 path; not the exact path) is written, up to max_vertices per frame, to a buffer read
 * back with sw__gpu_capture_read after sw_gpu_render_scene. `piece` is the index of the drawn
 * GPU piece among the patch hook's gpu = 1 reports of that frame (in order); (s, t) are the
 * float local parameters the shader used; pos the eye-relative float position. A vertex shared
 * by triangles may appear more than once. */
typedef struct sw__gpu_capture_vertex {
    uint32_t piece;
    float s, t;
    float pos[3];
} sw__gpu_capture_vertex;
void sw__gpu_set_capture(sw_gpu_context *ctx, uint32_t max_vertices);
/* *out (caller frees) receives *n captured vertices of the last frame (at most max_vertices;
 * *total is how many the shader tried to write). Errors: SW_ERR_OUT_OF_MEMORY, SW_ERR_GL. */
sw_result sw__gpu_capture_read(sw_gpu_context *ctx, sw__gpu_capture_vertex **out, size_t *n,
                               size_t *total, sw_status *status);

/* Debug hook (frame.c): every drawn patch piece of a frame, as the frame built it, for tests that
 * check the drawn geometry against the exact surface on the CPU. */
typedef struct sw__gpu_drawn_patch {
    const struct sw__gpu_view *view; /* the frame's view (eye, basis, projection) */
    uint32_t face;                   /* face record of the occurrence */
    const double *world;             /* occurrence transform, 3 x 4 row-major */
    int32_t deg_u, deg_v;
    const double *cpw;     /* eye-relative world, homogeneous, (deg_u+1)(deg_v+1)*4 */
    double u0, u1, v0, v1; /* the Bézier patch's rectangle in the face's parameters */
    double s0, s1, t0, t1; /* the sampled part of its local domain [0,1]^2 */
    int32_t nu, nv;        /* grid segments drawn over [s0,s1] x [t0,t1] */
    int32_t gpu;           /* 1: a vertex-shader record (float st: grid parameters are
                              computed in float as the shader does); 0: a CPU grid */
    int32_t trimmed;       /* drawn with a trim-texture lookup */
    double eps_obj;        /* object-space tolerance the density was chosen for */
} sw__gpu_drawn_patch;
typedef void (*sw__gpu_patch_hook)(void *user, const sw__gpu_drawn_patch *p);
/* Installs (fn != NULL) or removes the hook; called on the GL thread during sw_gpu_render_scene. */
void sw__gpu_set_patch_hook(sw_gpu_context *ctx, sw__gpu_patch_hook fn, void *user);

/* One surface program and the uniform locations the draws set (-1 where the program has no such
 * uniform: GL ignores those). */
typedef struct sw__gpu_surface_program {
    GLuint prog;
    GLint loc_view_proj, loc_trim;
    GLint loc_color, loc_trim_rect, loc_trim_layer, loc_uv_map; /* the mesh program's */
    GLint loc_model_rot, loc_model_off; /* the mesh program's: resident geometry's placement */
    GLint loc_grid, loc_base;                                   /* the evaluation programs' */
    GLint loc_capture;                                          /* Bézier evaluation only */
} sw__gpu_surface_program;

/* Which fragment stage a surface program has: the trim lookup (§4.3) and its discard, or neither,
 * for untrimmed draws. Without a texture read and a discard the rasteriser may test depth before
 * shading, and the trim lookup's inputs are not interpolated: on llvmpipe that is a third of the
 * fragment and setup work of a building's frame (docs/performance.md). */
enum { SW__GPU_TRIMMED = 0, SW__GPU_UNTRIMMED = 1, SW__GPU_TRIM_VARIANTS = 2 };

/* The three surface programs (mesh, Bézier evaluation, exact evaluation), each in both trim
 * variants. They share one fragment stage whose shading function is the library's or a host's
 * (sw__gpu_shading_create); the context draws with ctx->surf. A host's shading is linked into the
 * trimmed variant only, and its untrimmed variant names the same programs: the host sets its
 * uniforms on the three programs sw_renderer_shading_programs lists. */
typedef struct sw__gpu_surface_programs {
    sw__gpu_surface_program mesh[SW__GPU_TRIM_VARIANTS]; /* grids and plain triangles */
    sw__gpu_surface_program eval[SW__GPU_TRIM_VARIANTS]; /* rational Bézier patches (§4.2) */
    sw__gpu_surface_program exact[SW__GPU_TRIM_VARIANTS]; /* from knots (eval_exact) */
    /* grids kept on the GPU (resident_grids.c); 0 in a host's shading, whose frames send them */
    sw__gpu_surface_program grid[SW__GPU_TRIM_VARIANTS];
} sw__gpu_surface_programs;

struct sw_gpu_context {
    void *egl_display, *egl_context; /* EGLDisplay, EGLContext; NULL when adopted */
    int32_t gl_ready;                /* GL objects made: free deletes them */
    struct sw_th_token *walk_token;  /* walkthrough frames' hierarchy requests; bumped every frame,
                                so the requests of frames gone by are cancelled (a pointer: C++
                                tests include this header, and the token is a C11 atomic) */
    struct sw__gpu_stash *stash;     /* frame buffers kept between frames (frame_stash.c; atomics:
                                        a pointer here, as for walk_token) */
    /* fat borders' view-independent parts kept between frames (border_cache.c; held by one
     * prepare at a time) */
    struct sw__fr_border_cache *borders;
    char description[256];
    GLint max_texture_size;
    sw__gpu_surface_programs surf; /* the surface programs frames draw with */
    /* trim-texture program: 2D positions in clip space, constant colour */
    GLuint prog_trim;
    /* depth-compositing present: a fullscreen triangle reading the render target
     * (glsl/present.vert.glsl, present.frag.glsl) */
    GLuint prog_present;
    GLuint vao;
    /* main render target */
    GLuint fbo, tex_color, tex_depth; /* textures: the depth-compositing present samples them */
    /* the last submitted frame's completion fence and GL_TIMESTAMP queries (0: none pending):
     * the next submit waits for it (one frame in flight) instead of each frame's glFinish */
    GLsync frame_fence;
    GLuint frame_query[2];
    int32_t fbo_w, fbo_h;
    GLuint trim_fbo, trim_vbo;
    GLuint mesh_vbo, mesh_ibo;   /* per-frame streaming buffers */
    /* bytes of storage each streaming buffer holds (draw.c stream_to grows it, never shrinks) */
    size_t mesh_vbo_cap, mesh_ibo_cap, patch_ssbo_cap, cp_ssbo_cap;
    size_t piece_ssbo_cap, knot_ssbo_cap, dcp_ssbo_cap;
    struct sw__gpu_atlas *atlas; /* trim-texture atlas kept across frames (trim_atlas.c) */
    int32_t atlas_max_side;      /* page side limit (tests); 0 = the default; set between frames */
    /* the memory budget and its shares (memory_budget.c); set between frames */
    uint64_t budget_host, budget_gpu;
    uint64_t gpu_reported_bytes; /* what the driver reports (context set-up); 0: nothing */
    double atlas_max_texels;     /* texels the trim atlas keeps, at most */
    double atlas_frame_texels;   /* the frame's trim textures, at most (half the atlas's) */
    size_t hierarchy_bytes;      /* the hierarchies refine no further above it */
    /* predefined grids of the Bézier evaluation (§4.2; grid_set.c) */
    GLuint grid_ibo; /* every grid class's triangles, one after another */
    uint32_t grid_first[SW__GPU_GRID_CLASSES][SW__GPU_GRID_CLASSES]; /* [level v][level u] */
    uint32_t grid_count[SW__GPU_GRID_CLASSES][SW__GPU_GRID_CLASSES];
    GLuint patch_ssbo, cp_ssbo; /* per-frame patch records and control points */
    GLuint edge_ssbo[3];        /* per-frame exact trim edges: grids, cells, segments */
    size_t edge_ssbo_cap[3];
    int32_t eval_mode;          /* sw__gpu_eval_mode */
    /* the submitting thread's scratch, kept between frames (no allocation once grown) */
    struct sw__gpu_patch_rec *recs_sorted;
    size_t cap_recs_sorted;
    int32_t crack_fill_off;        /* 1: no fat borders (§7.1) */
    int32_t border_affine_off;     /* 1: affine faces' borders sampled as curved ones */
    int32_t back_ribbons_kept;     /* 1: closed shells' ribbons drawn where they face away too */
    sw__gpu_patch_hook patch_hook; /* debug hook, NULL = none */
    void *patch_hook_user;
    /* exact evaluation from knots and control points (eval_exact) */
    GLuint piece_ssbo, knot_ssbo, dcp_ssbo; /* per-frame pieces, knots, control points */
    /* debug capture of the Bézier vertex shader's output (sw__gpu_set_capture) */
    GLuint capture_ssbo;
    uint32_t capture_max; /* vertices; 0 = off */
    uint32_t *rec_source; /* sorted record -> record in append (patch hook) order */
    size_t cap_rec_source;
    /* static levels kept in GPU buffers between frames (resident.c); the frame's uploads */
    struct sw__gpu_resident *resident;
    struct sw__curves_renderer *curves; /* the outlines' programs and coverage target (lazily) */
    int32_t resident_off;  /* 1: static levels sent with the frame's mesh (tests' A/B) */
    uint64_t upload_bytes; /* the last draw's: vertices, indices and patch data sent */
    /* patch grids kept on the GPU between frames (resident_grids.c), the program that evaluates
     * them once (eval.vert.glsl, captured by transform feedback), and the last draw's counts */
    struct sw__gpu_grid_cache *grid_cache;
    sw__gpu_surface_program prog_grid_eval;
    int32_t grids_resident_off; /* 1: every grid evaluated in each frame (tests' A/B) */
    uint64_t grid_hits, grid_misses, grid_triangles;
    int64_t grid_extra_triangles; /* drawn less needed: > 0 where a finer grid was kept */
    struct sw__gpu_patch_rec *grid_recs_sorted; /* the submitting thread's, by trim variant */
    struct sw__gpu_grid_place *grid_places_sorted;
    size_t cap_grid_recs_sorted, cap_grid_places_sorted;
};

/* Last GL error as SW_ERR_GL naming `what`, or SW_OK. */
sw_result sw__gpu_check(sw_status *status, const char *what);
/* Makes an owned (headless) context current on the calling thread if another one is; an adopted
 * context is left alone. Every entry point that issues GL calls starts with it. */
void sw__gpu_make_current(sw_gpu_context *ctx);
/* A program of one vertex and one fragment stage; `what` names it in the error (SW_ERR_GL with
 * the GLSL log). shaders.c. */
sw_result sw__gpu_program_link(const char *vs, const char *fs, const char *what, GLuint *out,
                               sw_status *status);
/* Compiles the programs (shaders.c). */
sw_result sw__gpu_programs_create(sw_gpu_context *ctx, sw_status *status);
void sw__gpu_programs_free(sw_gpu_context *ctx);

/* ---- host shading (shaders.c; Guthe et al. 2005 §8's custom shaders) ------------------------ */
/* The surface programs linked with a host's shading function `shade_source` (GLSL defining
 * vec4 sw_shade(vec3 pos, vec3 normal, vec2 uv, vec4 color), and whatever uniforms it reads) in
 * place of the library's. The context's thread. Errors: SW_ERR_INVALID_ARGUMENT (the source does
 * not compile or link with the library's stages: the GLSL log in the message), SW_ERR_GL. */
sw_result sw__gpu_shading_create(sw_gpu_context *ctx, const char *shade_source,
                                 sw__gpu_surface_programs *out, sw_status *status);
void sw__gpu_shading_free(sw_gpu_context *ctx, sw__gpu_surface_programs *p);
/* The library's GLSL by part (the values of sw_glsl_kind, sw_immediate.h); NULL out of range. */
const char *sw__gpu_glsl_source(int kind);
enum { SW__GPU_GLSL_KINDS = 6 };
/* (Re)allocates the RGBA8 + 32F depth render target, two textures (context_egl.c); leaves
 * unit 0's GL_TEXTURE_2D binding at 0. */
sw_result sw__gpu_target_ensure(sw_gpu_context *ctx, int32_t w, int32_t h, sw_status *status);
/* Adds the calling thread's pool waits since `since` (sw_th_thread_waits) to st's pool_waits and
 * ms_pool_wait: prepare and submit each take their own thread's share (context_egl.c). */
struct sw_th_wait_count; /* sw_th_pool.h (C only: this header is included by C++ tests) */
void sw__gpu_waits_since(const struct sw_th_wait_count *since, sw_gpu_frame_stats *st);

/* ---- view (camera.c) ------------------------------------------------------------------------ */
typedef struct sw__gpu_view {
    double eye[3];
    double fwd[3], right[3], up[3]; /* orthonormal camera basis, fwd = viewing direction */
    int32_t width, height;
    double tan_x, tan_y; /* half-angle tangents */
    double focal_px;     /* height / (2 tan_y) */
    double near_plane;
    double planes[5][4]; /* frustum in eye-relative world coordinates: dot(n, x) + d >= 0 inside */
    float view_proj[16]; /* column-major; maps eye-relative world to clip (reversed-Z, infinite) */
} sw__gpu_view;

/* Builds the camera basis and matrices; near_plane must be > 0. Returns SW_ERR_INVALID_ARGUMENT
 * for a degenerate camera (eye == target, up parallel to the view, fovy outside (0, 180)). */
/* The view as world-to-eye `view` (GL's eye space: x right, y up, looking down -z) and
 * `proj` (reversed-Z, infinite far plane: clip z = near, clip w = -z_eye, so zero-to-one depth
 * = near / distance along the view axis), both column-major, m[col * 4 + row]; proj * view is
 * view_proj with the eye translation put in. */
void sw__gpu_view_matrices(const sw__gpu_view *v, double view[16], double proj[16]);
sw_result sw__gpu_view_init(sw__gpu_view *v, const sw_gpu_camera *cam, int32_t w, int32_t h,
                            double near_plane, sw_status *status);
/* 1 when the eye-relative box (min xyz, max xyz) may meet the frustum. */
int sw__gpu_view_box_visible(const sw__gpu_view *v, const double box[6]);
/* 1 when the whole eye-relative box is inside the frustum (its subtree needs no more tests). */
int sw__gpu_view_box_inside(const sw__gpu_view *v, const double box[6]);
/* Smallest depth along the view axis of an eye-relative box, clamped below by the near plane. */
double sw__gpu_view_box_depth(const sw__gpu_view *v, const double box[6]);
/* Euclidean distance from the eye (origin) to an eye-relative box; 0 when inside. */
double sw__gpu_box_distance(const double box[6]);
/* Depth-buffer value (reversed-Z, infinite far) to eye-space depth along the view axis. */
float sw__gpu_depth_to_eye(const sw__gpu_view *v, float d);

/* ---- CPU grids (patch_grid.c) --------------------------------------------------------------- */
typedef struct sw__gpu_vertex {
    float pos[3]; /* eye-relative world position */
    float nrm[3]; /* world normal (unnormalised is fine) */
    float st[2];  /* face parameter mapped to [0,1]^2 over the face's uv_box (trim lookup) */
} sw__gpu_vertex;

/* The attributes of sw__gpu_vertex (0 position, 1 normal, 2 st) from the bound array buffer into
 * the bound vertex array (draw.c). */
void sw__gpu_vertex_layout(void);

typedef struct sw__gpu_mesh {
    sw__gpu_vertex *v;
    uint32_t *idx;
    size_t n_v, cap_v, n_idx, cap_idx;
    uint64_t border_capped; /* fat borders sampled coarser than their cells: the sample budget
                               of sw__gpu_fat_border was hit (counted, never reset here) */
    uint64_t border_quads_away; /* fat-border quads left out facing away (likewise) */
} sw__gpu_mesh;

/* The context's border cache (border_cache.c; frame_stages.h has its frame-side calls). */
typedef struct sw__fr_border_cache sw__fr_border_cache;
sw__fr_border_cache *sw__fr_border_cache_new(void); /* NULL: out of memory */
void sw__fr_border_cache_free(sw__fr_border_cache *c);

/* The context's stash of frame buffers (frame_stash.c): spent plans and chunk geometries, emptied
 * with their arrays kept. take: an item of the role or NULL; put: 1 when stashed, 0 when the
 * stash is full (the item stays the caller's). Any thread; ctx NULL: nothing kept. */
typedef enum sw__gpu_stash_role { SW__GPU_STASH_PLAN, SW__GPU_STASH_CHUNK } sw__gpu_stash_role;
struct sw__gpu_stash *sw__gpu_stash_new(void);    /* NULL when out of memory */
void sw__gpu_stash_free(struct sw__gpu_stash *s); /* NULL allowed; frees what it holds */
void *sw__gpu_stash_take(sw_gpu_context *ctx, sw__gpu_stash_role role);
int sw__gpu_stash_put(sw_gpu_context *ctx, sw__gpu_stash_role role, void *item);

/* Liang–Barsky: 1 when segment ab meets the closed rectangle r = {x0, x1, y0, y1} (infinite
 * sides allowed), with t the parameter range of ab inside it; 0 when it misses (t untouched).
 * trim_tiles.c. */
int sw__gpu_segment_clip(const double a[2], const double b[2], const double r[4], double t[2]);
void sw__gpu_mesh_free(sw__gpu_mesh *m);
sw_result sw__gpu_mesh_reserve(sw__gpu_mesh *m, size_t more_v, size_t more_idx, sw_status *status);

/* One Bézier patch of a face occurrence, its control points in eye-relative world space. */
typedef struct sw__gpu_patch {
    int32_t deg_u, deg_v;
    double *cpw;           /* (deg_u+1)(deg_v+1)*4, eye-relative world, homogeneous */
    const double *cpo;     /* the same in the occurrence's object space; NULL: not known */
    double centre[3];      /* object space: the origin of its grid kept on the GPU */
    double s0, s1, t0, t1; /* the part of the local domain inside the face's uv_box */
    double u0, u1, v0, v1; /* its parameter rectangle in the face's domain */
    int32_t col, row;      /* position in the face's patch grid */
    int32_t visible;       /* survived frustum culling */
    int32_t nu, nv;        /* grid segments (after the column/row maxima) */
    double eps;            /* object-space tolerance of its density (§7) */
} sw__gpu_patch;

/* Evaluates the visible patches of one face occurrence (grids of nu x nv cells each, neighbours
 * sharing their common edge vertices) and appends vertices and triangle indices to `mesh`.
 * `patches` is n_cols x n_rows, column fastest. normal_sign flips the normals (reversed face or
 * mirroring transform). uv_box maps the face parameter to the trim lookup's [0,1]^2. */
sw_result sw__gpu_tessellate_face(const sw__gpu_patch *patches, int32_t n_cols, int32_t n_rows,
                                  double normal_sign, const double uv_box[4], sw__gpu_mesh *mesh,
                                  sw_status *status);

/* ---- crack filling (crack_fill.c, §7.1) ------------------------------------------------------ */
/* Appends a screen-facing ribbon (fat border), width_px pixels wide on the face's inner side, along
 * a closed polyline uv[2n] in the parameters of surface srf placed by `world` (3 x 4), sampled on
 * the exact surface with steps no longer than (du, dv). left_inside: the face lies to the left of
 * the polyline's direction in (u, v). st_box (u0, u1, v0, v1) or NULL: the rectangle the trim
 * lookup of the ribbon's draw spans (vertices then carry st over it), else st = 0 (untrimmed).
 * Bounded by the view: at most max(2 n, 64 (width + height)) samples (a loop 32 times around the
 * frame at one sample per pixel); a loop whose cells ask for more is sampled with (du, dv) scaled
 * up to fit, and mesh->border_capped counts it (the ribbon then follows the loop's chords at
 * coarser steps: within the budget, not the grid's cells). affine: 1 lets an affine surface
 * (sw_sg_surface_affine, a plane) take the ribbon from its loop's vertices and straight inner
 * steps, with no evaluation between (exact there); 0 samples it as any other. facing: NULL, or
 * the face bounds a closed shell seen from outside: the ribbon leaves out what faces away.
 * Errors: SW_ERR_OUT_OF_MEMORY, SW_ERR_LIMIT. */
typedef struct sw__gpu_ribbon_facing {
    double eye[3];  /* the eye in the surface's own space (before `world`) */
    double outward; /* +1: the shell's outside is along S_u x S_v; -1: along -(S_u x S_v) */
} sw__gpu_ribbon_facing;
sw_result sw__gpu_fat_border(const sw__gpu_view *v, const sw_sg_surface *srf,
                             const double world[12], const double *uv, size_t n, int left_inside,
                             double du, double dv, double width_px, const double *st_box,
                             int affine, const sw__gpu_ribbon_facing *facing, sw__gpu_mesh *mesh,
                             sw_status *status);
/* The view-independent part of one loop's fat border: its samples on the surface in the
 * surface's own space (at steps no longer than (du, dv), widened to at most max_samples and then
 * counted as capped) and its segment grid, which sw__gpu_fat_border_of places under any view and
 * transform. sw__gpu_fat_border is make, of, free; a caller that draws one loop under many views
 * or transforms keeps it (stage_tessellate.c's border cache). uv is the caller's and must outlive
 * it. Errors: SW_ERR_OUT_OF_MEMORY. */
typedef struct sw__gpu_border_loop sw__gpu_border_loop;
sw_result sw__gpu_border_loop_make(const sw_sg_surface *srf, const double *uv, size_t n,
                                   int left_inside, double du, double dv, int affine,
                                   size_t max_samples, sw__gpu_border_loop **out,
                                   sw_status *status);
void sw__gpu_border_loop_free(sw__gpu_border_loop *bl);
size_t sw__gpu_border_loop_bytes(const sw__gpu_border_loop *bl);
/* Its samples: at most max_samples whenever the loop's n <= max_samples / 2. */
size_t sw__gpu_border_loop_samples(const sw__gpu_border_loop *bl);
/* The most samples one ribbon may take in view v (a loop of n vertices). */
size_t sw__gpu_border_budget(const sw__gpu_view *v, size_t n);
/* The ribbon of a made loop (the same as sw__gpu_fat_border's with the make's arguments). */
sw_result sw__gpu_fat_border_of(const sw__gpu_view *v, const double world[12],
                                const sw__gpu_border_loop *bl, double width_px,
                                const double *st_box, const sw__gpu_ribbon_facing *facing,
                                sw__gpu_mesh *mesh, sw_status *status);
/* Waits until the last submitted frame is complete and returns its GPU time (ms, by its timestamp
 * queries; 0 when no frame is pending). GL owner thread. */
double sw__gpu_frame_complete(sw_gpu_context *ctx);
/* Crack filling on (default) or off, for tests that measure what it closes. */
void sw__gpu_set_crack_fill(sw_gpu_context *ctx, int on);
/* Static levels drawn from the GPU copies the context keeps (default), or sent with each frame's
 * mesh: the A/B of the tests and benchmarks. Between frames. */
void sw__gpu_set_resident(sw_gpu_context *ctx, int on);
/* Patch grids drawn from those the context keeps (default), or evaluated in every frame: the A/B
 * of the tests and benchmarks. Between frames. */
void sw__gpu_set_grids_resident(sw_gpu_context *ctx, int on);
/* Fat borders of affine faces by their loop's vertices (default) or sampled as curved ones: the
 * A/B of bench_prepare and the test that both cover alike. */
void sw__gpu_set_border_affine(sw_gpu_context *ctx, int on);
/* keep = 1: the parts of closed shells' fat borders that face away from the eye are drawn too (by
 * default a frame whose desc has face cones leaves them out): the A/B of tests. Between frames. */
void sw__gpu_set_back_ribbons(sw_gpu_context *ctx, int keep);

/* ---- trim textures (trim_texture.c) --------------------------------------------------------- */
/* Renders loops already in the clip space of one atlas page into layer `layer` of the R8 array
 * texture `tex` (side x side texels per layer): fans from each loop's first vertex toggle texels
 * (even-odd parity, §4), then every loop drawn as a 1-pixel line loop SETS its texels (§7.1 crack
 * filling: boundary texels are inside). One render-target switch; two multi-draw calls.
 * Loops with fewer than 3 (fans) or 2 (lines) vertices draw nothing; empty loops (count 0) are
 * allowed anywhere, first included (trim_texture.c works around llvmpipe dropping the rest). */
void sw__gpu_trim_page_draw(sw_gpu_context *ctx, GLuint tex, int32_t layer, int32_t side,
                            const float *xy, size_t n_xy, const GLint *first, const GLsizei *count,
                            GLsizei n_loops);

/* ---- trim-texture atlas (trim_atlas.c, §4.4) ------------------------------------------------- */
/* Identity of a trim texture: the scene (by serial: a freed scene's address goes to later ones,
 * such as the next compiled version of a node scene with edited loops), the face and what its
 * loops are (checked on reuse). */
typedef struct sw__gpu_trim_key {
    uint64_t scene;
    uint32_t face, first_loop, n_loops;
    double uv_box[4];
} sw__gpu_trim_key;

/* Where an entry's texels are: layer of the atlas array texture, rectangle in texels. */
typedef struct sw__gpu_trim_rect {
    int32_t layer, x0, y0, w, h;
} sw__gpu_trim_rect;

typedef struct sw__gpu_atlas_stats {
    uint32_t pages;        /* layers of the atlas */
    int32_t side;          /* texels per page side */
    uint32_t entries;      /* used this frame */
    uint32_t reused;       /* used this frame, rendered in an earlier one */
    uint32_t rendered;     /* rendered this frame */
    uint32_t switches;     /* render-target switches this frame */
    uint32_t repacks;      /* full repacks this frame (0 or 1) */
    uint32_t allocations;  /* array textures allocated this frame */
    uint64_t entry_texels; /* texels of the entries used this frame */
} sw__gpu_atlas_stats;

enum { SW__GPU_ATLAS_GUTTER = 2 }; /* texels around every entry */

/* Frame protocol, GL thread only: begin; per trimmed face find, and on a miss add; commit
 * (placement and rendering); then rect / texture for the draws. Entry ids are valid from find/add
 * until the next begin. */
sw_result sw__gpu_atlas_begin(sw_gpu_context *ctx, sw_status *status);
/* Largest page side (power of two) the atlas may use; 0 = min(4096, GL_MAX_TEXTURE_SIZE).
 * Takes effect at the next repack. For tests. */
void sw__gpu_atlas_set_max_side(sw_gpu_context *ctx, int32_t side);
/* Largest entry (w, h) that fits a page: side - 2 gutters. */
int32_t sw__gpu_atlas_max_entry(const sw_gpu_context *ctx);
/* Entry id of a cached (or already added this frame) texture of w x h texels for key, marking it
 * used; -1 when absent. */
int32_t sw__gpu_atlas_find(sw_gpu_context *ctx, const sw__gpu_trim_key *key, int32_t w, int32_t h);
/* Adds a texture of w x h texels for key whose loops (face parameters) span key->uv_box; copies
 * the loops. Errors: SW_ERR_LIMIT (w or h above sw__gpu_atlas_max_entry), SW_ERR_OUT_OF_MEMORY,
 * SW_ERR_INVALID_GEOMETRY (empty uv box). */
sw_result sw__gpu_atlas_add(sw_gpu_context *ctx, const sw__gpu_trim_key *key, int32_t w, int32_t h,
                            const sw_sg_polyline *loops, uint32_t n_loops, int32_t *entry,
                            sw_status *status);
/* Places the entries added since begin (shelf packing by height into free space, or a repack of
 * every entry used this frame when they do not fit) and renders them, one render-target switch per
 * page. Errors: SW_ERR_GL, SW_ERR_OUT_OF_MEMORY, SW_ERR_LIMIT. */
sw_result sw__gpu_atlas_commit(sw_gpu_context *ctx, sw__gpu_atlas_stats *stats, sw_status *status);
void sw__gpu_atlas_rect(const sw_gpu_context *ctx, int32_t entry, sw__gpu_trim_rect *out);
/* Forgets every entry but keeps the pages: the next frame regenerates every trim texture, as the
 * paper does each frame (benchmarks). */
void sw__gpu_atlas_invalidate(sw_gpu_context *ctx);
/* Reads layer `layer` of the atlas back (side*side bytes, row 0 at y = 0); side in *side. */
sw_result sw__gpu_atlas_read_page(sw_gpu_context *ctx, int32_t layer, uint8_t *out, size_t size,
                                  int32_t *side, sw_status *status);
/* The atlas's GL_TEXTURE_2D_ARRAY (0 before the first commit with entries). */
GLuint sw__gpu_atlas_texture(const sw_gpu_context *ctx);
void sw__gpu_atlas_free(sw_gpu_context *ctx);

/* ---- trim tiles (trim_tiles.c): loops restricted to a tile of a face's trim box -------------- */
/* Class of rect = {u0, u1, v0, v1} against closed polylines: 0 when a loop meets it, else 1 when
 * it lies inside the trimmed region (even-odd), -1 outside. */
int sw__gpu_trim_rect_class(const sw_sg_polyline *loops, uint32_t n_loops, const double rect[4]);
/* Sutherland–Hodgman clip of every loop to rect (same even-odd parity inside rect); out[n_loops]
 * is allocated (free each with sw_sg_polyline_free). Errors: SW_ERR_OUT_OF_MEMORY. */
sw_result sw__gpu_trim_clip_loops(const sw_sg_polyline *loops, uint32_t n_loops,
                                  const double rect[4], sw_sg_polyline *out, sw_status *status);

/* ---- exact trim edges (trim_edges.c): a draw's loops as per-fragment tests ------------------- */
/* A grid of cells over a draw's rectangle (st in [0, 1]^2), as the fragment shader reads it
 * (std430: glsl/surface_trim.frag.glsl's SwEdgeGrid). */
enum { SW__GPU_EDGE_REFS = 5 }; /* reference points a cell may take (trim_edges.c) */
typedef struct sw__gpu_edge_grid {
    uint32_t n[2];       /* cells in s, t */
    uint32_t first_cell; /* in the frame's cells */
    uint32_t pad;
} sw__gpu_edge_grid;

/* A frame's grids: cells are 2 uint32 each (first entry in segs; entries << 4 | its reference
 * point's number << 1 | that point's even-odd parity), segs 4 floats per entry (a segment's ends,
 * clipped to the cell, relative to the cell's reference point, in cells). */
typedef struct sw__gpu_edge_grids {
    sw__gpu_edge_grid *grids;
    uint32_t *cells;
    float *segs;
    size_t n_grids, n_cells, n_segs;
    size_t cap_grids, cap_cells, cap_segs; /* in elements of each array (2, 4 per cell, entry) */
} sw__gpu_edge_grids;

/* Appends the grid of closed loops (face parameters) over rect = {u0, u1, v0, v1}; *index is its
 * number, or -1 when it cannot be made within its limits (too many segments, no reference point
 * clear of the loops, an empty rectangle): the caller draws a trim texture instead. Errors:
 * SW_ERR_OUT_OF_MEMORY. */
sw_result sw__gpu_edge_grid_add(sw__gpu_edge_grids *out, const sw_sg_polyline *loops,
                                uint32_t n_loops, const double rect[4], int32_t *index,
                                sw_status *status);
/* The fragment shader's test on the CPU, in float as the shader does it: 1 when (s, t) of grid
 * index is inside the loops. */
int sw__gpu_edge_grid_inside(const sw__gpu_edge_grids *g, int32_t index, float s, float t);
void sw__gpu_edge_grids_empty(sw__gpu_edge_grids *g); /* counts zeroed, arrays kept */
void sw__gpu_edge_grids_free(sw__gpu_edge_grids *g);
/* Whether the path from a cell's reference point to d (both relative to it) crosses segment e =
 * {a.x, a.y, b.x, b.y}: a and b strictly on opposite sides of the path's line, half-open (a
 * vertex on the line counts on one side for both of its segments, so a path through it crosses
 * the loop once or not at all), and the path's ends on opposite sides of the segment's line.
 * glsl/surface_trim.frag.glsl does the same operations. */
static inline int sw__gpu_edge_crosses(const float d[2], const float e[4])
{
    const int ends_apart = (d[0] * e[1] - d[1] * e[0] > 0.0f) != (d[0] * e[3] - d[1] * e[2] > 0.0f);
    const float ex = e[2] - e[0], ey = e[3] - e[1];
    const int path_apart =
        (ex * -e[1] - ey * -e[0] > 0.0f) != (ex * (d[1] - e[1]) - ey * (d[0] - e[0]) > 0.0f);
    return ends_apart && path_apart;
}

/* ---- drawing and readback (draw.c) ----------------------------------------------------------- */
/* A range of the frame's index buffer drawn with one colour and trim texture (0 = untrimmed). */
typedef struct sw__gpu_draw {
    size_t first_idx, n_idx;
    float color[4];
    int32_t trim_entry; /* atlas entry, -1 = none */
    int32_t edge_grid;  /* exact trim edges' grid (trim_edges.c), -1 = none; trimmed when either
                           is set */
    float uv_map[4];    /* the vertices' st to the face's parameters: (u, v) = (m0 + st.x m2,
                           m1 + st.y m3); zero: uv = 0 */
} sw__gpu_draw;

static inline int sw__gpu_draw_trimmed(const sw__gpu_draw *d)
{
    return d->trim_entry >= 0 || d->edge_grid >= 0;
}
/* A draw's trim lookup as the surface programs take it (u_trim_rect, u_trim_layer; a record's
 * trim_rect, layer): its atlas rectangle in texels and layer; (grid, 0, -1, 0) for exact edges;
 * zeros when untrimmed. */
void sw__gpu_draw_trim_lookup(const sw_gpu_context *ctx, const sw__gpu_draw *d, float rect[4],
                              float *layer);

/* The frame's GPU-evaluated patches: records sorted by trim variant and grid class, control
 * points. */
typedef struct sw__gpu_patch_batch {
    const sw__gpu_patch_rec *recs;
    size_t n_recs;
    const float *cps; /* 4 floats per control point */
    size_t n_cps;
    /* exact path: records' cp index pieces; knots and eye-relative control points in double */
    int32_t exact;
    const sw__gpu_exact_piece *pieces;
    size_t n_pieces;
    const double *knots;
    size_t n_knots;
    const double *dcps; /* 4 doubles per control point */
    size_t n_dcps;
    /* records of each trim variant (SW__GPU_TRIMMED, SW__GPU_UNTRIMMED) and grid class */
    uint32_t first[SW__GPU_TRIM_VARIANTS][SW__GPU_GRID_CLASSES][SW__GPU_GRID_CLASSES];
    uint32_t count[SW__GPU_TRIM_VARIANTS][SW__GPU_GRID_CLASSES][SW__GPU_GRID_CLASSES];
    /* records drawn from the grids kept on the GPU (their cps local), by trim variant */
    const sw__gpu_patch_rec *grid_recs;
    const struct sw__gpu_grid_place *grid_places;
    size_t n_grid_recs;
    size_t grid_first[SW__GPU_TRIM_VARIANTS], grid_count[SW__GPU_TRIM_VARIANTS];
} sw__gpu_patch_batch;

/* A frame's bytes into *buf (made when 0), bound to target: storage grown by glBufferData only
 * when they do not fit (a quarter more), else overwritten; counted in ctx->upload_bytes. */
void sw__gpu_stream(sw_gpu_context *ctx, GLenum target, GLuint *buf, size_t *capacity, size_t bytes,
                    const void *data);
/* Patch records and control points into storage buffers 0 and 1 (the evaluation program's). */
void sw__gpu_upload_patches(sw_gpu_context *ctx, const sw__gpu_patch_rec *recs, size_t n_recs,
                            const float *cps, size_t n_cps);

/* Creates the grid classes' index buffer (grid_set.c). */
sw_result sw__gpu_grids_create(sw_gpu_context *ctx, sw_status *status);
void sw__gpu_grids_free(sw_gpu_context *ctx);

/* Fills the defaults of a frame description (size 1280 x 720, error 0.5 px). */
void sw__gpu_desc_defaults(const sw_gpu_frame_desc *in, sw_gpu_frame_desc *out);
/* Near plane for a scene box in world coordinates seen from eye: max(1e-4 x diagonal, half the
 * eye's distance to the box), never 0. */
double sw__gpu_near_plane(const double eye[3], const double world_box[6]);
/* Clears the render target (desc->background) and draws with reversed-Z depth (as lines with
 * desc->wireframe) the batch's patches (NULL = none), one instanced draw per trim variant and grid
 * class, then uploads `mesh` and draws its ranges, the untrimmed first. The patches go first: the
 * mesh's fat borders lie behind them (crack_fill.c), so most of their fragments fail the depth
 * test before they are shaded. Does not wait for the GPU: the frame's submit fences it. */
struct sw__gpu_resident_list; /* below */
sw_result sw__gpu_draw_frame(sw_gpu_context *ctx, const sw__gpu_view *view,
                             const sw_gpu_frame_desc *desc, const sw__gpu_mesh *mesh,
                             const sw__gpu_draw *draws, size_t n_draws,
                             const sw__gpu_patch_batch *batch, const sw__gpu_edge_grids *edges,
                             const struct sw__gpu_resident_list *resident, sw_status *status);

/* ---- resident static levels (resident.c) -------------------------------------------------------
 * A static level (Kumar et al. 1997 §4) does not change with the view, so its vertices and
 * triangles go to a GPU buffer once, in the object space of its unit around the unit's box
 * centre, and every later frame draws them with a camera-relative placement composed in double on
 * the CPU (ARCHITECTURE.md's precision rule): rot, and off = world(centre) - eye, both in float. */
typedef struct sw__gpu_resident_draw {
    const struct sw_lod_static_level *level; /* the set's (it outlives the frame) */
    uint32_t unit;                           /* of the static set */
    int32_t index;                           /* of the level in its chain */
    double centre[3]; /* object space: the origin its buffer's positions are relative to */
    float rot[9];     /* row-major: the instance transform's 3 x 3 (normals too: similarities) */
    float off[3];     /* eye-relative world position of the centre */
    float color[4];
    const uint32_t *lines; /* a cluster proxy's open edges (kept with its triangles), drawn as
                              one-pixel lines after them when draw_lines is set
                              (lod/static/sw_lod_static_set.h says why); NULL: none */
    uint32_t n_lines;
    int32_t draw_lines;
} sw__gpu_resident_draw;
typedef struct sw__gpu_resident_list {
    const sw__gpu_resident_draw *draws;
    size_t n;
    uint64_t set; /* sw_lod_static_set_serial of their set */
} sw__gpu_resident_list;
/* Levels whose index reaches this are drawn from the frame's mesh instead. */
enum { SW__GPU_RESIDENT_LEVELS = 8 };
/* Draws the list with the mesh program (untrimmed, in use with its view set), uploading the
 * levels it does not hold yet; adds the uploaded bytes to ctx->upload_bytes. After the frame's
 * sw__gpu_resident_begin with the list's set. Errors: SW_ERR_OUT_OF_MEMORY. */
sw_result sw__gpu_resident_draw_all(sw_gpu_context *ctx, const sw__gpu_surface_program *prog,
                                    const sw__gpu_resident_list *list, sw_status *status);
/* Before each frame's draw (set 0: the frame has no static set): the levels of another set are
 * dropped, and over the budget those the last frame did not draw; a set's first frame makes the
 * table. */
void sw__gpu_resident_begin(sw_gpu_context *ctx, uint64_t set);
void sw__gpu_resident_free(sw_gpu_context *ctx);
/* Bytes of GPU buffers held, and the budget (tests; 0 keeps only the last frame's levels). */
size_t sw__gpu_resident_bytes(const sw_gpu_context *ctx);
size_t sw__gpu_resident_set_budget(sw_gpu_context *ctx, size_t bytes);

/* ---- patch grids kept on the GPU (resident_grids.c)
 * ---------------------------------------------- A record of the Bézier path whose control points
 * the tessellation wrote in the patch's own space (around `centre`, sw__gpu_patch) carries its
 * placement: drawn from the grid the context keeps for its inputs, evaluated (once) when there is
 * none. */
typedef struct sw__gpu_grid_place {
    uint32_t hash;     /* CRC-32C of its local control points, degrees and st (not its class) */
    uint32_t resident; /* 1: the record's control points are local and it is drawn from the cache */
    float rot[12];     /* rows of the occurrence's 3 x 3, w: the centre's eye-relative position */
    float cof[12];     /* rows of the 3 x 3's cofactor matrix (normals); w set by the draw */
} sw__gpu_grid_place;
/* Draws the batch's grid records (grid_recs, by trim variant) from the kept grids, evaluating
 * those missing; counts hits, misses and triangles in ctx. Errors: SW_ERR_OUT_OF_MEMORY. */
sw_result sw__gpu_grid_cache_draw(sw_gpu_context *ctx, const sw__gpu_view *view,
                                  const sw__gpu_patch_batch *batch, sw_status *status);
/* Before each frame's draw: over the budget, the grids the last frame did not draw are freed. */
void sw__gpu_grid_cache_begin(sw_gpu_context *ctx);
void sw__gpu_grid_cache_free(sw_gpu_context *ctx);
/* Bytes of the kept grids, and of the vertex buffer up to its high-water mark (freed slots
 * included: at most twice the budget or twice what is kept). */
size_t sw__gpu_grid_cache_bytes(const sw_gpu_context *ctx);
size_t sw__gpu_grid_cache_held(const sw_gpu_context *ctx);
size_t sw__gpu_grid_cache_set_budget(sw_gpu_context *ctx, size_t bytes);
/* The host's GL state (host_state.c says which), saved and set to GL's defaults when the
 * renderer starts working in an adopted context or on a presenting frame (desc.present), and
 * restored when it ends. */
#define SW__GPU_HOST_CAPS 33
#define SW__GPU_HOST_BUFFERS 11
#define SW__GPU_HOST_TEXTURES 11
#define SW__GPU_HOST_PIXEL_STORE 16
#define SW__GPU_HOST_INDEXED                                                                       \
    16 /* uniform and shader storage ranges saved (and fewer if the                                \
          context has fewer) */
typedef struct sw__gpu_host_range {
    GLint buffer;
    GLint64 start, size;
} sw__gpu_host_range;
typedef struct sw__gpu_host_state {
    GLint draw_fb, read_fb, viewport[4];
    GLint renderbuffer, program, vao, element_buffer, buffers[SW__GPU_HOST_BUFFERS];
    GLint xfb_object, xfb_buffer; /* transform feedback object and its generic buffer binding */
    GLint n_indexed[2];
    sw__gpu_host_range indexed[2][SW__GPU_HOST_INDEXED];            /* uniform, shader storage */
    GLint active_texture, textures[SW__GPU_HOST_TEXTURES], sampler; /* unit 0's */
    GLboolean caps[SW__GPU_HOST_CAPS];
    GLint scissor[4], blend[6];
    GLfloat blend_color[4];
    GLint depth_func;
    GLboolean depth_mask;
    GLdouble depth_clear, depth_range[2];
    GLint stencil[2][7], stencil_clear; /* front, back: func ref mask fail zfail zpass write */
    GLboolean color_mask[4];
    GLfloat color_clear[4];
    GLint cull_face, front_face, polygon_mode;
    GLfloat polygon_offset[2], line_width, point_size;
    GLint provoking_vertex, restart_index, patch_vertices, logic_op;
    GLint clip_origin, clip_depth_mode;
    GLint pixel_store[SW__GPU_HOST_PIXEL_STORE];
} sw__gpu_host_state;
void sw__gpu_host_state_save(sw__gpu_host_state *s);
void sw__gpu_host_state_restore(const sw__gpu_host_state *s);
/* 1 for a context adopted from the host (sw_gpu_context_adopt_current). */
int sw__gpu_context_adopted(const sw_gpu_context *ctx);
/* Puts the frame into the host's draw framebuffer (saved in `host`) at its origin. depth 0: a
 * blit of the colour, background included. depth 1: a fullscreen pass writes the colour and
 * gl_FragDepth of the surfaces' pixels with GL_GREATER against the host's depth buffer (any
 * format); background pixels (depth 0) are discarded, so the host's colour and depth stay. */
sw_result sw__gpu_present(sw_gpu_context *ctx, const sw__gpu_view *view, int depth,
                          const sw__gpu_host_state *host, sw_status *status);
/* Reads the frame back into `out` (rows top first; depth as eye-space depth, +INF background). */
sw_result sw__gpu_readback(sw_gpu_context *ctx, const sw__gpu_view *view, int want_depth,
                           sw_gpu_image *out, sw_status *status);

/* An RGBA8 image (top row first) as a PNG file's bytes in *bytes (sw__malloc) and *size; 0 when
 * out of memory or the size is out of range. */
int sw__gpu_png_encode(const uint8_t *rgba, int32_t width, int32_t height, void **bytes,
                       size_t *size);

#ifdef __cplusplus
}
#endif
#endif
