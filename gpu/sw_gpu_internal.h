/* Internal interfaces of gpu/ (never installed): the context's GL objects, the view set-up shared
 * by every draw path, CPU grid tessellation of Bézier patches (Guthe et al. 2005 §4.2, §5.2, on
 * the CPU in this slice) and trim-texture generation by fan parity (§4, §4.1, §7.1).
 * Tests include this header to check the trim texture against a CPU classification.
 */
#ifndef SW_GPU_INTERNAL_H
#define SW_GPU_INTERNAL_H

#include "sw_gpu.h"
#include "sw_sg_trim.h"

#include <GL/glcorearb.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

struct sw_gpu_context {
    void *egl_display, *egl_context; /* EGLDisplay, EGLContext */
    char description[256];
    GLint max_texture_size;
    /* grid / triangle program */
    GLuint prog_mesh;
    GLint loc_view_proj, loc_color, loc_trimmed, loc_trim;
    /* trim-texture program: 2D positions in clip space, constant colour */
    GLuint prog_trim;
    GLuint vao;
    /* main render target */
    GLuint fbo, rb_color, rb_depth;
    int32_t fbo_w, fbo_h;
    GLuint trim_fbo, trim_vbo;
    GLuint mesh_vbo, mesh_ibo; /* per-frame streaming buffers */
};

/* Last GL error as SW_ERR_GL naming `what`, or SW_OK. */
sw_result sw__gpu_check(sw_status *status, const char *what);
/* Compiles the programs (shaders.c). */
sw_result sw__gpu_programs_create(sw_gpu_context *ctx, sw_status *status);
void sw__gpu_programs_free(sw_gpu_context *ctx);
/* (Re)allocates the RGBA8 + 32F depth render target (context_egl.c). */
sw_result sw__gpu_target_ensure(sw_gpu_context *ctx, int32_t w, int32_t h, sw_status *status);
double sw__gpu_now_ms(void);

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
sw_result sw__gpu_view_init(sw__gpu_view *v, const sw_gpu_camera *cam, int32_t w, int32_t h,
                            double near_plane, sw_status *status);
/* 1 when the eye-relative box (min xyz, max xyz) may meet the frustum. */
int sw__gpu_view_box_visible(const sw__gpu_view *v, const double box[6]);
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

typedef struct sw__gpu_mesh {
    sw__gpu_vertex *v;
    uint32_t *idx;
    size_t n_v, cap_v, n_idx, cap_idx;
} sw__gpu_mesh;

void sw__gpu_mesh_free(sw__gpu_mesh *m);
sw_result sw__gpu_mesh_reserve(sw__gpu_mesh *m, size_t more_v, size_t more_idx, sw_status *status);

/* One Bézier patch of a face occurrence, its control points in eye-relative world space. */
typedef struct sw__gpu_patch {
    int32_t deg_u, deg_v;
    double *cpw;           /* (deg_u+1)(deg_v+1)*4, eye-relative world, homogeneous */
    double s0, s1, t0, t1; /* the part of the local domain inside the face's uv_box */
    double u0, u1, v0, v1; /* its parameter rectangle in the face's domain */
    int32_t col, row;      /* position in the face's patch grid */
    int32_t visible;       /* survived frustum culling */
    int32_t nu, nv;        /* grid segments (after the column/row maxima) */
} sw__gpu_patch;

/* Evaluates the visible patches of one face occurrence (grids of nu x nv cells each, neighbours
 * sharing their common edge vertices) and appends vertices and triangle indices to `mesh`.
 * `patches` is n_cols x n_rows, column fastest. normal_sign flips the normals (reversed face or
 * mirroring transform). uv_box maps the face parameter to the trim lookup's [0,1]^2. */
sw_result sw__gpu_tessellate_face(const sw__gpu_patch *patches, int32_t n_cols, int32_t n_rows,
                                  double normal_sign, const double uv_box[4], sw__gpu_mesh *mesh,
                                  sw_status *status);

/* ---- trim textures (trim_texture.c) --------------------------------------------------------- */
/* Renders loops (polylines in face parameters) into a new R8 texture of w x h texels spanning
 * uv_box: fans from each loop's first vertex toggle texels (even-odd parity, §4), then the loops
 * drawn as 1-pixel line loops SET their texels (§7.1 crack filling: boundary texels are inside).
 * The texture is returned in *tex (GL name, owned by the caller). */
sw_result sw__gpu_trim_texture_make(sw_gpu_context *ctx, const sw_sg_polyline *loops,
                                    uint32_t n_loops, const double uv_box[4], int32_t w, int32_t h,
                                    GLuint *tex, sw_status *status);
/* Reads a trim texture back (w*h bytes, row 0 = v0 side). */
sw_result sw__gpu_trim_texture_read(sw_gpu_context *ctx, GLuint tex, int32_t w, int32_t h,
                                    uint8_t *out, sw_status *status);

/* ---- drawing and readback (draw.c) ----------------------------------------------------------- */
/* A range of the frame's index buffer drawn with one colour and trim texture (0 = untrimmed). */
typedef struct sw__gpu_draw {
    size_t first_idx, n_idx;
    float color[4];
    GLuint trim_tex;
} sw__gpu_draw;

/* Fills the defaults of a frame description (size 1280 x 720, error 0.5 px). */
void sw__gpu_desc_defaults(const sw_gpu_frame_desc *in, sw_gpu_frame_desc *out);
/* Near plane for a scene box in world coordinates seen from eye: max(1e-4 x diagonal, half the
 * eye's distance to the box), never 0. */
double sw__gpu_near_plane(const double eye[3], const double world_box[6]);
/* Clears the render target, uploads `mesh` and draws every range with reversed-Z depth; waits for
 * the GPU (glFinish) so that the caller's timing is the real draw time. */
sw_result sw__gpu_draw_frame(sw_gpu_context *ctx, const sw__gpu_view *view, const float bg[4],
                             const sw__gpu_mesh *mesh, const sw__gpu_draw *draws, size_t n_draws,
                             sw_status *status);
/* Reads the frame back into `out` (rows top first; depth as eye-space depth, +INF background). */
sw_result sw__gpu_readback(sw_gpu_context *ctx, const sw__gpu_view *view, int want_depth,
                           sw_gpu_image *out, sw_status *status);

#ifdef __cplusplus
}
#endif
#endif
