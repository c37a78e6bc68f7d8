/* gpu/ private: the state of one frame of sw_gpu_render_scene, shared by frame.c (the direct
 * Bézier-patch path, trim textures, batching) and frame_hlod.c (Guthe et al. 2005 §7: the traversal
 * of the faces' bicubic hierarchies). Never installed. */
#ifndef SW_GPU_FRAME_INTERNAL_H
#define SW_GPU_FRAME_INTERNAL_H

#include "sw_gpu_internal.h"
#include "sw_lod_cache.h"
#include "sw_lod_face_cones.h"
#include "sw_lod_sampling.h"
#include "sw_sg_bvh.h"
#include "sw_sg_trim.h"

#include <stddef.h>
#include <stdint.h>

enum {
    MAX_SEGMENTS = 256, /* grid segments per patch and direction */
    MAX_TRIM_LOOP_VERTICES = 1u << 22,
    MAX_BOUND_SUBDIVISION = 4,  /* sub-patches per direction for the derivative bounds */
    MAX_TILES_PER_DIR = 4096,   /* trim tiles of a face per direction */
    MAX_TILES_PER_FACE = 16384, /* visible trim tiles of one face occurrence (else coarser) */
};

/* Segment counts a direction may get, ascending: every count up to MAX_SEGMENTS for CPU grids;
 * for predefined grids (§4.2) the counts a grid class, or pieces of one class, can draw. */
typedef struct segment_set {
    int32_t n[MAX_SEGMENTS];
    int32_t count;
} segment_set;
static const double k_max_frame_vertices = 48e6; /* ~1.5 GB of grid vertices */
static const double k_max_frame_texels = 256e6;  /* R8 trim texels per frame */
static const double k_tile_texels = 1024.0;      /* wanted trim texels per direction above which a
                                                    face's trim box is split into tiles */

typedef struct occurrence {
    uint32_t face;
    double world[12];
    float color[4];
} occurrence;

typedef struct pending_trim {
    size_t draw;
    uint32_t face;
    double width, height; /* wanted resolution before the frame budget */
    size_t occ;           /* occurrence, for its fat border */
    double cell[2];       /* smallest grid cell of the face in u, v (fat-border sampling) */
    int64_t loops;        /* tiled face: its flattened loops in frame.loops; -1: whole trim box */
    double rect[4];       /* tiled face: the tile (face parameters) */
} pending_trim;

/* A tiled face occurrence's loops, flattened once for all its tiles. */
typedef struct face_loops {
    sw_sg_polyline *loops;
    uint32_t n;
} face_loops;

typedef struct frame {
    sw_gpu_context *ctx;
    const sw_sg_scene *scene;
    const sw_sg_scene_view *sv;
    sw__gpu_view view;
    double eps_px;
    sw_gpu_frame_stats st;
    occurrence *occ;
    size_t n_occ, cap_occ;
    int oom;
    sw_sg_bezier_set **bez; /* per face, extracted on first use in this frame */
    sw__gpu_mesh mesh;
    sw__gpu_draw *draws;
    size_t n_draws, cap_draws;
    pending_trim *trims;
    size_t n_trims, cap_trims;
    sw__gpu_patch_rec *recs; /* GPU-evaluated patches (§4.2) */
    float *cps;              /* their eye-relative homogeneous control points, 4 per point */
    size_t n_recs, cap_recs, n_cps, cap_cps;
    double gpu_vertices; /* grid vertices the vertex shader will evaluate */
    sw__gpu_patch_batch batch;
    sw_lod_screen_view screen; /* the view as the density bound needs it */
    segment_set gpu_segments, cpu_segments;
    uint64_t border_triangles; /* fat-border triangles (counted in st.triangles, which also
                                  counts the mesh at the end: subtracted there) */
    face_loops *loops;         /* of tiled faces */
    size_t n_loops, cap_loops;
    /* exact path (eval_exact): pieces, knots and eye-relative control points in double */
    int exact;
    sw__gpu_exact_piece *pieces;
    size_t n_pieces, cap_pieces;
    double *knots, *dcps;
    size_t n_knots, cap_knots, n_dcps, cap_dcps;
    const occurrence *ex_occ;    /* the occurrence whose net is at ex_base (NULL: none yet) */
    sw__gpu_exact_piece ex_base; /* its knots, control points, stride and degrees */
    sw_sg_surface ex_srf;
    /* hierarchy traversal (frame_hlod.c; NULL cache: every face drawn by its Bézier patches) */
    sw_lod_cache *cache;
    int32_t reader;    /* the frame's reader slot in the cache (epochs), -1 when none */
    sw_th_group group; /* converged mode: builds and refinements the frame waits for */
    int planning;      /* 1: traversal only asks for refinements; 0: it draws */
    int walkthrough;   /* never wait: requests carry `req` and are not waited for */
    sw_lod_cache_req req;
    uint64_t refine_asked; /* refinements submitted (or in flight) in this planning round */
    size_t *shares;        /* pairs (draw, source draw): draw uses the source's trim entry */
    size_t n_shares, cap_shares;
    /* static LODs (frame_static.c; NULL: every face by the per-frame path) */
    struct sw_lod_static_set *statics;
    int32_t static_force; /* desc.static_force */
    int lod_colors;       /* desc.lod_colors */
} frame;

/* Texels wanted per direction of a face's trim texture (max over its drawn patches). */
typedef struct trim_need {
    double u, v;
} trim_need;

/* ---- frame.c, for frame_hlod.c and frame_static.c ---- */
/* An occurrence as the frame draws it: the colour resolved (none or unset: the default grey). */
void sw__fr_occurrence_init(occurrence *o, uint32_t face, const double world[12],
                            const float color[4]);
/* Appends a visible occurrence to f->occ and its world box, eye-relative, to *boxes (6 per
 * occurrence, grown). 0: out of memory. */
int sw__fr_take_occurrence(frame *f, uint32_t face, const double world[12], const float color[4],
                           const double world_box[6], double **boxes, size_t *cap_boxes);
/* The view's frustum for sw_sg_bvh_cull (planes relative to the eye). */
void sw__fr_frustum(const frame *f, sw_sg_frustum *fr);
/* Adds one BVH traversal's counts to the frame's bvh_* stats. */
void sw__fr_bvh_stats(frame *f, const sw_sg_bvh_cull_stats *cs);
/* Kumar §4.4's back-patch test of one face occurrence with its eye-relative box. */
int sw__fr_face_back_facing(const sw_lod_face_cones *fc, const occurrence *o, const double box[6]);
/* SW_ERR_INVALID_ARGUMENT unless the cones are the scene's (one per face). */
sw_result sw__fr_check_cones(const frame *f, const sw_lod_face_cones *fc, sw_status *status);
/* Homogeneous control point mapped to eye-relative world space: w x' = R (w x) + w (t - eye). */
void sw__fr_xform_h(const double m[12], const double eye[3], const double in[4], double out[4]);
void sw__fr_box_empty(double box[6]);
void sw__fr_box_add(double box[6], const double h[4]); /* adds the point h / h[3] */
double sw__fr_det3(const double m[12]);
/* sqrt(|M|_1 |M|_inf) of the linear part: a bound of its spectral norm, 1 for a rigid one. */
double sw__fr_stretch_bound(const double m[12]);
/* A draw record for mesh indices from first_idx on (or for patch records pointing at it); a
 * trimmed one also gets a pending trim texture of the face's whole trim box, with `need` texels. */
sw_result sw__fr_add_draw(frame *f, const occurrence *o, size_t first_idx, int trimmed,
                          const trim_need *need, const double cell[2], sw_status *status);
void sw__fr_report_patch(const frame *f, const occurrence *o, const sw__gpu_patch *pt, double s0,
                         double s1, double t0, double t1, int32_t nu, int32_t nv, int gpu,
                         int trimmed);
/* Vertex-shader records of a visible patch; ub is the rectangle its draw's trim texture spans. */
sw_result sw__fr_gpu_patch(frame *f, const occurrence *o, const sw__gpu_patch *pt,
                           const double ub[4], double sign, int32_t draw, int trimmed,
                           sw_status *status);
/* §7.1 fat border along a closed uv loop as its own draw. st_box NULL: untrimmed; else the draw
 * uses the trim texture of draw `share` (whose texture spans st_box). */
sw_result sw__fr_fat_border(frame *f, const occurrence *o, const double *uv, size_t n,
                            int left_inside, const double cell[2], const double *st_box,
                            size_t share, sw_status *status);
int32_t sw__fr_class_texels(double want, int32_t max_entry);
int sw__fr_left_is_inside(const sw_sg_polyline *loops, uint32_t n_loops, uint32_t k);
/* The direct path: the face's Bézier patches (§4.2), tiled trim textures when large. */
sw_result sw__fr_draw_face(frame *f, const occurrence *o, sw_status *status);
/* Flattens the face's trim loops at tolerance tol into a new frame.loops entry; *index is it. */
sw_result sw__fr_face_loops(frame *f, uint32_t face, double tol, int64_t *index, sw_status *status);

/* ---- frame_hlod.c ---- */
/* Walkthrough: only requests the visible faces' hierarchies (never waits). Converged mode: builds
 * the hierarchies of the visible occurrences' faces (boxes: eye-relative, 6 per occurrence) and
 * refines them until the frame's cut needs no more, waiting for the pool. */
sw_result sw__fr_hlod_prepare(frame *f, const double *boxes, int walkthrough, sw_status *status);
/* Draws one occurrence from its face's hierarchy (§7), or by the direct path when it has none. */
sw_result sw__fr_hlod_draw_face(frame *f, const occurrence *o, sw_status *status);

/* ---- frame_static.c ---- */
/* Kumar §4.4 and §4 with static LODs (f->statics, not exact): culls the set's unit-instance BVH,
 * back-culls whole unit instances by their units' cones (fc may be NULL: no back culling), draws
 * the visible instances whose unit has a level fine enough for the view (their fat borders too),
 * and appends the face occurrences of the others, with their eye-relative boxes (*boxes, grown),
 * to f->occ for the per-frame path. */
sw_result sw__fr_static_collect(frame *f, const sw_lod_face_cones *fc, double **boxes,
                                sw_status *status);
/* LOD colouring: static level k (fine -> coarse), or -1 for the per-frame path. */
void sw__fr_lod_color(int32_t level, float out[4]);

/* ---- frame_mesh.c ---- */
/* Triangles in object space for sw__fr_append_triangles. */
typedef struct sw__fr_triangles {
    const double *positions; /* 3 per vertex */
    const float *normals_f;  /* 3 per vertex, or NULL */
    const double *normals_d; /* 3 per vertex, or NULL; both NULL: flat, a normal per triangle */
    double normal_matrix[9]; /* row-major 3x3 mapping normals to the world (with normals) */
    uint32_t n_vertices, n_triangles;
    const uint32_t *triangles; /* 3 per triangle */
} sw__fr_triangles;
/* Appends the triangles under the occurrence's transform (eye-relative, float) to the frame's
 * mesh as one untrimmed draw of o->color: the one triangle path of static LODs and meshes. */
sw_result sw__fr_append_triangles(frame *f, const occurrence *o, const sw__fr_triangles *t,
                                  sw_status *status);

typedef struct sw__fr_mesh_occ {
    uint32_t mesh;
    double world[12];
    float color[4];
    double box[6]; /* eye-relative */
} sw__fr_mesh_occ;
typedef struct sw__fr_meshes {
    sw__fr_mesh_occ *occ;
    size_t n, cap;
} sw__fr_meshes;
/* The scene's mesh occurrences with their eye-relative boxes, which also grow scene_box (the
 * near plane is chosen from it). Before the view is set; needs f->view.eye. */
sw_result sw__fr_meshes_collect(frame *f, sw__fr_meshes *fm, double scene_box[6],
                                sw_status *status);
/* Draws the collected occurrences inside the frustum (after the view is set). */
sw_result sw__fr_meshes_draw(frame *f, const sw__fr_meshes *fm, sw_status *status);
void sw__fr_meshes_free(sw__fr_meshes *fm);

#endif
