/* SPDX-License-Identifier: MIT */
/* gpu/ private: one frame as explicit stages, each with its own input and output item lists.
 *
 *   cull        (stage_cull.c)       scene, BVH or static unit instances, view
 *                                    -> sw__fr_visible: face occurrences, unit instances, meshes
 *   select      (stage_select.c,     visible items -> sw__fr_selection: per unit instance a static
 *                stage_hierarchy.c)  level, per face occurrence its hierarchy cut (Guthe §7) or
 *                                    its own Bézier patches
 *   tessellate  (stage_tessellate*.c) selection -> sw__fr_geometry: CPU grids and triangles,
 *                                    vertex-shader patch records, draws, fat borders (§7.1),
 *                                    pending trim textures
 *   trim        (stage_trim.c)       pending trims -> resolutions and flattened loops (plain
 *                                    memory, with the trimmed faces' fat borders), then on the GL
 *                                    thread the atlas entries of the draws (§4, §4.4)
 *   outlines    (stage_shapes.c)     visible shape occurrences -> outlines in target pixels
 *   submit      (stage_submit.c)     geometry -> batch, upload, draw (the outlines last),
 *                                    present, readback
 *
 * cull, select, tessellate and the trim plan are GL-free and run in sw_gpu_frame_prepare (the
 * visibility thread); the trim atlas and submit run in sw_gpu_frame_submit (the GL thread).
 * Every stage reads the frame's constants (sw__fr_env, resolved once from the desc by frame.c)
 * and adds to the frame's stats. Never installed. */
#ifndef SW_GPU_FRAME_STAGES_H
#define SW_GPU_FRAME_STAGES_H

#include "sw_curves.h"
#include "sw_gpu_internal.h"
#include "sw_lod_cache.h"
#include "sw_lod_face_cones.h"
#include "sw_lod_sampling.h"
#include "sw_lod_static_set.h"
#include "sw_sg_bvh.h"
#include "sw_sg_trim.h"

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

enum {
    MAX_SEGMENTS = 256, /* grid segments per patch and direction */
    MAX_TRIM_LOOP_VERTICES = 1u << 22,
    MAX_BOUND_SUBDIVISION = 4, /* sub-patches per direction for the derivative bounds */
};
static const double k_max_frame_vertices = 48e6; /* ~1.5 GB of grid vertices */
/* Wanted trim texels per direction above which a face's trim box is split into tiles, each with
 * its own texture at the resolution its part of the surface needs, a hierarchy node into parts,
 * and a hierarchy-drawn face gets a texture per node. A texture is sized for the nearest point of
 * its rectangle, so smaller tiles render fewer texels in a close-up, at the cost of more draws and
 * grid cells (the 10^5 building's interior walk: 42 M texels a frame at 1024, 22 M at 512, 12 M
 * at 256; at 256 a hierarchy view of Motor-c had one border pixel deeper than the crack test
 * allows). */
static const double k_tile_texels = 512.0;
/* Wanted trim texels per direction above which the hierarchy's cut visits a node's children
 * rather than cutting the node into parts: refining also sets the geometry, and a deeper cut
 * draws more triangles and fat borders than parts of the same bicubic. */
static const double k_node_texels = 1024.0;
/* With exact trim edges (desc.trim_edges), a trimmed draw whose trim texel would exceed this many
 * pixels at its nearest point has its edges classified per fragment (trim_edges.c) instead, and
 * its loops flattened to k_exact_flat_px on screen (they are its edges and its fat borders'). */
static const double k_exact_texel_px = 0.25;
static const double k_exact_flat_px = 0.125;

/* Segment counts a direction may get, ascending: every count up to MAX_SEGMENTS for CPU grids;
 * for predefined grids (§4.2) the counts a grid class, or pieces of one class, can draw. */
typedef struct segment_set {
    int32_t n[MAX_SEGMENTS];
    int32_t count;
} segment_set;

/* ---- the frame's constants (frame.c resolves them once per frame) -------------------------- */
typedef struct sw__fr_env {
    sw_gpu_context *ctx; /* read only: its settings (eval mode, crack fill, patch hook, atlas) */
    const sw_sg_scene *scene;
    const sw_sg_scene_view *sv;
    sw__gpu_view view;
    sw_lod_screen_view screen; /* the view as the density bound needs it */
    segment_set gpu_segments, cpu_segments;
    double eps_px;              /* ε_img */
    int exact;                  /* desc.eval_exact */
    int walkthrough;            /* desc.walkthrough: never wait for the pool */
    int lod_colors;             /* desc.lod_colors */
    int trim_edges;             /* desc.trim_edges: exact edges where a texel would be coarse */
    int grids_resident;         /* Bézier grids drawn from the context's kept grids */
    int eye_shells;             /* sw__fr_eye_shells: the eye inside a closed shell, or not */
    int32_t static_force;       /* desc.static_force */
    int proxies;                /* statics and not desc.no_proxies: the cut may stop at proxies */
    sw_lod_static_set *statics; /* NULL: every face by the per-frame path */
    sw_th_pool *pool;           /* desc.pool: tessellation chunks shared with its workers */
    struct sw__fr_border_cache *borders; /* the context's, held by this frame; NULL: none */
} sw__fr_env;

/* The constants of a frame of desc (its defaults resolved by sw__gpu_desc_defaults) but the view:
 * its eye only. Errors: SW_ERR_INVALID_ARGUMENT (static LODs of another scene). */
sw_result sw__fr_env_init(sw__fr_env *env, sw_gpu_context *ctx, const sw_sg_scene *scene,
                          const sw_gpu_frame_desc *desc, sw_status *status);
/* The view, its near plane from the eye-relative scene box (the cull stage's) unless the desc
 * gives one; the density bound's view and the grid classes' segment counts; where the eye is
 * with respect to the closed shells (sw__fr_eye_shells). Errors: those of sw__gpu_view_init. */
sw_result sw__fr_env_view(sw__fr_env *env, const sw_gpu_frame_desc *desc, const double scene_box[6],
                          sw_status *status);

/* A face occurrence as the frame draws it. */
typedef struct occurrence {
    uint32_t face;
    double world[12];
    float color[4];
} occurrence;

/* An occurrence with the colour resolved (none or unset: the default grey). */
void sw__fr_occurrence_init(occurrence *o, uint32_t face, const double world[12],
                            const float color[4]);

/* ---- cull: stage_cull.c ---------------------------------------------------------------------- */
/* Face occurrences with their eye-relative boxes (6 per occurrence). */
typedef struct sw__fr_faces {
    occurrence *occ;
    double *boxes;
    size_t n, cap_occ, cap_boxes;
} sw__fr_faces;
/* Appends an occurrence; 0: out of memory. */
int sw__fr_faces_push(sw__fr_faces *l, const occurrence *o, const double eye_box[6]);
void sw__fr_faces_free(sw__fr_faces *l);

/* A visible unit instance of the static set: its BVH item and, in the cull output's
 * unit_faces, its face occurrences that are shown (inside the frustum, not back-facing). */
typedef struct sw__fr_instance {
    uint32_t item; /* of sw_lod_static_instances.bvh */
    size_t first_face, n_faces;
} sw__fr_instance;

/* A mesh occurrence, or a shape occurrence (`mesh` is then its shape; box: of its plane box). */
typedef struct sw__fr_mesh_occ {
    uint32_t mesh;
    double world[12];
    float color[4];
    double box[6]; /* eye-relative */
} sw__fr_mesh_occ;

typedef struct sw__fr_visible {
    sw__fr_faces faces;         /* without static LODs: the visible face occurrences */
    sw__fr_instance *instances; /* with static LODs: the visible unit instances, BVH order */
    size_t n_instances, cap_instances;
    sw__fr_faces unit_faces; /* their shown faces */
    uint32_t *proxies;       /* with static LODs: nodes of their BVH drawn as proxies, ascending */
    size_t n_proxies, cap_proxies;
    sw__fr_mesh_occ *meshes; /* mesh occurrences inside the frustum */
    size_t n_meshes, cap_meshes;
    sw__fr_mesh_occ *shapes; /* shape occurrences inside the frustum */
    size_t n_shapes, cap_shapes;
} sw__fr_visible;

/* Before the view: the scene box the near plane is chosen from (eye-relative), and the mesh
 * occurrences (their boxes join it). Needs env->view.eye only. vis: zeroed, or a spent frame's
 * (its arrays reused). */
sw_result sw__fr_cull_scene_box(const sw__fr_env *env, const sw_gpu_frame_desc *desc,
                                sw__fr_visible *vis, double scene_box[6], sw_status *status);
/* After the view: the visible face occurrences (desc.occurrences, the BVH, or every occurrence
 * of the scene), or with static LODs the visible unit instances (Kumar §4.4); back-patch culling
 * by desc.face_cones; the meshes outside the frustum dropped. */
sw_result sw__fr_cull(const sw__fr_env *env, const sw_gpu_frame_desc *desc, sw__fr_visible *vis,
                      sw_gpu_frame_stats *st, sw_status *status);
void sw__fr_visible_free(sw__fr_visible *vis);
void sw__fr_visible_empty(sw__fr_visible *vis); /* counts zeroed, arrays kept */
/* Kumar §4.4's back-patch test of one face occurrence with its eye-relative box. */
int sw__fr_face_back_facing(const sw_lod_face_cones *fc, const occurrence *o, const double box[6]);
/* Where the eye is with respect to the closed shells (SW_SG_FACE_CLOSED_SHELL), which back-patch
 * culling and leaving out fat borders facing away (gpu/crack_fill.c) both take to be seen from
 * outside. UNKNOWN without face cones or a face BVH; INSIDE when one of six rays from the eye along
 * the axes meets a closed shell first from inside it (an eye inside a solid — a walk through a
 * wall, a close-up inside a part — sees that solid's faces from behind); else OUTSIDE: each ray
 * escaped or met a face from outside (six rays rather than one for solids that overlap, as an
 * assembly's parts may). */
enum { SW__FR_EYE_UNKNOWN = 0, SW__FR_EYE_INSIDE = 1, SW__FR_EYE_OUTSIDE = 2 };
int sw__fr_eye_shells(const sw__fr_env *env, const sw_gpu_frame_desc *desc);

/* ---- select: stage_select.c, stage_hierarchy.c ------------------------------------------- */
/* Texels wanted per direction of a trim texture. */
typedef struct trim_need {
    double u, v;
} trim_need;

/* A chosen item of a face's hierarchy: a node, or a part [s0,s1] x [t0,t1] of its local domain
 * (part_depth > 0). */
typedef struct hl_item {
    int32_t node, part_depth;
    double range[4];
} hl_item;
typedef struct hl_choice {
    hl_item it;
    double cpw[64]; /* the item's bicubic, eye-relative world, homogeneous */
    double cpo[64]; /* the same in the face's object space */
    double rect[4]; /* its rectangle in face parameters */
    double err_w;   /* its error bound in world units */
    double eps_obj; /* ε_obj at its nearest depth */
    trim_need need; /* trim texels over rect */
    int32_t grid_splits; /* times it was halved because its grid reached the segment limit */
} hl_choice;

/* A unit instance drawn at a static level. */
typedef struct sw__fr_static_pick {
    uint32_t instance; /* of sw__fr_visible.instances */
    const sw_lod_static_chain *chain;
    int32_t level;
    double extent_px; /* a bound of the unit's size on screen (its fat borders' sampling) */
} sw__fr_static_pick;

/* A face occurrence drawn by the per-frame path: its hierarchy cut, or (n_items 0 and
 * !hierarchy) its own Bézier patches. */
typedef struct sw__fr_face_pick {
    occurrence occ;
    int hierarchy;
    size_t first_item, n_items; /* of sw__fr_selection.items */
} sw__fr_face_pick;

typedef struct sw__fr_selection {
    sw__fr_static_pick *statics;
    size_t n_statics, cap_statics;
    sw__fr_face_pick *faces;
    size_t n_faces, cap_faces;
    hl_choice *items;
    size_t n_items, cap_items;
} sw__fr_selection;

/* The hierarchy state of a frame (desc.hierarchies): the cache, the plan's reader slot, the group
 * converged frames wait on, the walkthrough request. */
typedef struct sw__fr_hierarchy {
    sw_lod_cache *cache; /* NULL: every face drawn by its Bézier patches */
    int32_t reader;      /* the plan's reader slot in the cache (epochs), -1 when none */
    sw_th_group group;
    sw_lod_cache_req req;
    int planning;          /* 1: traversal only asks for refinements */
    uint64_t refine_asked; /* refinements submitted (or in flight) in this planning round */
} sw__fr_hierarchy;

/* Kumar §4 and Guthe §7: per visible unit instance the coarsest static level within the view's
 * tolerance (else its faces go to the per-frame path), per per-frame face occurrence its
 * hierarchy cut (converged: after the builds and refinements it needs, waited for; walkthrough:
 * requested). sel: zeroed, or a spent frame's (its arrays reused). */
sw_result sw__fr_select(const sw__fr_env *env, sw__fr_hierarchy *hy, const sw__fr_visible *vis,
                        sw__fr_selection *sel, sw_gpu_frame_stats *st, sw_status *status);
void sw__fr_selection_free(sw__fr_selection *sel);
void sw__fr_selection_empty(sw__fr_selection *sel); /* counts zeroed, arrays kept */
/* LOD colouring: static level k (fine -> coarse), -1 for the per-frame path, -2 for per-frame
 * draws cut by exact trim edges, SW__FR_PROXY_COLOR for cluster proxies. */
enum { SW__FR_PROXY_COLOR = -3 };
void sw__fr_lod_color(int32_t level, float out[4]);
/* The object-space tolerance of a unit under transform m at the view (frame-static's rule:
 * ε_img at the nearest depth of its box, over the transform's stretch), and its screen extent. */
double sw__fr_unit_tolerance(const sw__fr_env *env, const double obj_box[6], const double m[12],
                             double *extent_px);

/* stage_hierarchy.c. Walkthrough: requests the faces' hierarchies (never waits). Converged:
 * builds them and refines until the cut needs no more, waiting for the pool. */
sw_result sw__fr_hierarchy_prepare(const sw__fr_env *env, sw__fr_hierarchy *hy,
                                   const sw__fr_faces *faces, sw_gpu_frame_stats *st,
                                   sw_status *status);
/* The cut of one occurrence's hierarchy h (§7), appended to sel->items. */
sw_result sw__fr_hierarchy_cut(const sw__fr_env *env, sw__fr_hierarchy *hy, const occurrence *o,
                               const sw_lod_hierarchy *h, sw__fr_selection *sel,
                               sw_gpu_frame_stats *st, sw_status *status);

/* ---- tessellate: stage_tessellate*.c -------------------------------------------------------- */
typedef struct pending_trim {
    size_t draw;
    occurrence occ;       /* for its fat borders */
    double width, height; /* wanted resolution before the frame budget */
    double cell[2];       /* smallest grid cell of the face in u, v (fat-border sampling) */
    int64_t loops;        /* its face's flattened loops in geometry.loops (-1 until the trim
                             plan flattens a whole trim box's) */
    int32_t clip;         /* 1: a tile or a node's part: the loops clipped to rect */
    double rect[4];       /* with clip: the tile (face parameters) */
    int32_t w, h;         /* texels of its class (the trim plan) */
    int32_t grid;         /* its exact edges' grid in geometry.edges, or -1: a trim texture */
} pending_trim;

/* A face occurrence's loops, flattened once (a copy of the border cache's when it has them). */
typedef struct face_loops {
    sw_sg_polyline *loops;
    uint32_t n;
    uint32_t face;
    double tol; /* the flattening's (the border cache's key with face) */
} face_loops;

/* An outline to draw after the opaque frame (stage_shapes.c). */
typedef struct sw__fr_shape_draw {
    sw__curves_shape *shape; /* in target pixels; owned */
    sw__curves_depth depth;
    float color[4];
} sw__fr_shape_draw;

typedef struct sw__fr_geometry {
    sw__gpu_mesh mesh; /* CPU grids, fat borders, triangles */
    sw__gpu_draw *draws;
    size_t n_draws, cap_draws;
    pending_trim *trims;
    size_t n_trims, cap_trims;
    size_t *shares; /* pairs (draw, source draw): draw uses the source's trim entry */
    size_t n_shares, cap_shares;
    face_loops *loops;
    size_t n_loops, cap_loops;
    sw__gpu_edge_grids edges; /* the exact trim edges' grids (the trim plan) */
    sw__gpu_patch_rec *recs; /* GPU-evaluated patches (§4.2) */
    float *cps; /* their homogeneous control points, 4 per point: eye-relative, or local to the
                   patch's centre for a record drawn from the kept grids (places[i].resident) */
    sw__gpu_grid_place *places; /* per record */
    size_t n_recs, cap_recs, n_cps, cap_cps, cap_places;
    /* exact path (eval_exact): pieces, knots and eye-relative control points in double */
    sw__gpu_exact_piece *pieces;
    size_t n_pieces, cap_pieces;
    double *knots, *dcps;
    size_t n_knots, cap_knots, n_dcps, cap_dcps;
    double gpu_vertices;       /* grid vertices the vertex shader will evaluate */
    uint64_t border_triangles; /* fat-border triangles (in stats.triangles already) */
    /* static levels drawn from the context's GPU buffers (gpu/resident.c), with their
     * triangles */
    sw__gpu_resident_draw *resident;
    size_t n_resident, cap_resident;
    uint64_t resident_triangles;
    sw__fr_shape_draw *shapes; /* the outlines (stage_shapes.c) */
    size_t n_shapes, cap_shapes;
} sw__fr_geometry;
void sw__fr_geometry_free(sw__fr_geometry *g);
/* Zeroes every count, keeping the arrays (the per-face trim loops owned are freed). */
void sw__fr_geometry_empty(sw__fr_geometry *g);
/* A chunk's geometry from the context's stash (frame_stash.c; dst zeroed when none), and back:
 * emptied into the stash, or freed when it is full; g is zeroed. */
void sw__fr_chunk_geometry_take(sw_gpu_context *ctx, sw__fr_geometry *dst);
void sw__fr_chunk_geometry_give(sw_gpu_context *ctx, sw__fr_geometry *g);

/* The tessellation stage's working state. */
typedef struct sw__fr_tess {
    const sw__fr_env *env;
    sw_gpu_frame_stats *st;
    sw__fr_geometry *geo;
    _Atomic(sw_sg_bezier_set *) *bez; /* per face, extracted on first use in this frame (by
                                         whichever chunk needs it first: compare-and-swap) */
    const occurrence *ex_occ; /* exact path: the occurrence whose net is at ex_base */
    sw__gpu_exact_piece ex_base;
    sw_sg_surface ex_srf;
} sw__fr_tess;

/* Everything selected, in order: static levels, per-frame faces, meshes. The static levels and
 * per-frame faces in chunks shared with env->pool's workers when there are enough of them
 * (stage_tessellate_parallel.c). geo: zeroed, or emptied (sw__fr_geometry_empty). */
sw_result sw__fr_tessellate(const sw__fr_env *env, const sw__fr_visible *vis,
                            const sw__fr_selection *sel, sw__fr_geometry *geo,
                            sw_gpu_frame_stats *st, sw_status *status);

/* stage_tessellate_parallel.c: sel's static picks, then its face picks, into t->geo and t->st,
 * split in chunks run by the calling thread and the pool's workers, appended in order. */
sw_result sw__fr_tess_picks(sw__fr_tess *t, const sw__fr_visible *vis, const sw__fr_selection *sel,
                            sw_status *status);
/* One face pick into t (the chunk body; stage_tessellate.c). */
sw_result sw__fr_tess_face(sw__fr_tess *t, const sw__fr_selection *sel, const sw__fr_face_pick *p,
                           sw_status *status);

/* stage_tessellate.c, for the paths below. */
sw_result sw__fr_add_draw(sw__fr_tess *t, const occurrence *o, size_t first_idx, int trimmed,
                          const trim_need *need, const double cell[2], sw_status *status);
void sw__fr_report_patch(const sw__fr_tess *t, const occurrence *o, const sw__gpu_patch *pt,
                         double s0, double s1, double t0, double t1, int32_t nu, int32_t nv,
                         int gpu, int trimmed);
/* Vertex-shader records of a visible patch; ub is the rectangle its draw's trim texture spans. */
sw_result sw__fr_gpu_patch(sw__fr_tess *t, const occurrence *o, const sw__gpu_patch *pt,
                           const double ub[4], double sign, int32_t draw, int trimmed,
                           sw_status *status);
/* ---- the border cache: border_cache.c ---------------------------------------------------------
 * A face's loops flattened at a tolerance and their border samples, kept between frames and
 * shared by the face's occurrences. begin: at a prepare's start, on its thread (NULL: no cache
 * for this frame: none, or another prepare of the context holds it); end: at its end. */
typedef struct sw__fr_border_entry sw__fr_border_entry;
sw__fr_border_cache *sw__fr_border_cache_begin(sw__fr_border_cache *c, const sw_sg_scene *scene);
void sw__fr_border_cache_end(sw__fr_border_cache *c);
/* Tests and benchmarks, between frames: 0 turns it off. Returns the budget it had. */
size_t sw__fr_border_cache_set_budget(sw__fr_border_cache *c, size_t bytes);
size_t sw__fr_border_cache_bytes(const sw__fr_border_cache *c);
/* The face's trim loops flattened at tol, looked up or made; NULL when the frame has no cache,
 * it is over its budget or full, or the loops fail (the caller then flattens them itself, and
 * reports). Any thread of the frame's preparation. */
const sw__fr_border_entry *sw__fr_border_entry_get(const sw__fr_env *env, uint32_t face,
                                                   double tol);
/* The same for one counter-clockwise loop around rect (u0, u1, v0, v1) in the face's
 * parameters: an untrimmed face's box, a hierarchy node's rectangle. */
const sw__fr_border_entry *sw__fr_border_rect_get(const sw__fr_env *env, uint32_t face,
                                                  const double rect[4]);
const sw_sg_polyline *sw__fr_border_entry_loops(const sw__fr_border_entry *e, uint32_t *n);
/* Counts the entry's loops flattened farther than their tolerance, as a flattening does. */
void sw__fr_border_entry_count(sw__fr_tess *t, const sw__fr_border_entry *e);
/* The fat borders of the entry's loops under o, sampled at steps cell (§7.1); st_box and share
 * as sw__fr_fat_border's. */
sw_result sw__fr_border_entry_ribbons(sw__fr_tess *t, const occurrence *o,
                                      const sw__fr_border_entry *e, const double cell[2],
                                      const double *st_box, size_t share, sw_status *status);
/* The fat border along rect (counter-clockwise) as sw__fr_fat_border draws it, from the cache
 * when it can; box: along the face's parameter box (an untrimmed face's). */
sw_result sw__fr_rect_border(sw__fr_tess *t, const occurrence *o, const double rect[4],
                             const double cell[2], const double *st_box, size_t share,
                             sw_status *status);
sw_result sw__fr_box_border(sw__fr_tess *t, const occurrence *o, const double cell[2],
                            sw_status *status);

/* §7.1 fat border along a closed uv loop as its own draw. st_box NULL: untrimmed; else the draw
 * uses the trim texture of draw `share` (whose texture spans st_box). */
sw_result sw__fr_fat_border(sw__fr_tess *t, const occurrence *o, const double *uv, size_t n,
                            int left_inside, const double cell[2], const double *st_box,
                            size_t share, sw_status *status);
/* The same from a loop's samples made beforehand (gpu/crack_fill.c sw__gpu_border_loop_make). */
sw_result sw__fr_placed_border(sw__fr_tess *t, const occurrence *o, const sw__gpu_border_loop *bl,
                               const double cell[2], const double *st_box, size_t share,
                               sw_status *status);
/* The face's trim loops flattened at tolerance tol into a new geometry.loops entry, *index. */
sw_result sw__fr_face_loops(sw__fr_tess *t, uint32_t face, double tol, int64_t *index,
                            sw_status *status);
/* 1 when a part `extent` wide is a sliver of a face box `box_extent` wide (stage_tessellate.c). */
int sw__fr_sliver(double extent, double box_extent);
/* Smallest cell of the visible grids pt[0..n) of a face with trim box ub, in face parameters,
 * slivers skipped (the box's extent where only slivers are visible): its borders' sampling.
 * Returns how many of pt are visible. */
size_t sw__fr_grid_cell(const sw__gpu_patch *pt, size_t n, const double ub[4], double cell[2]);
/* The fat borders along every loop of a flattened entry. */
sw_result sw__fr_loop_borders(sw__fr_tess *t, const occurrence *o, int64_t loops,
                              const double cell[2], sw_status *status);
/* The normal sign of an occurrence: reversed face, mirroring transform. */
double sw__fr_normal_sign(const sw__fr_env *env, const occurrence *o);
/* 1 when the face's trim loops cut it (a trim texture is needed). */
int sw__fr_face_trimmed(const sw__fr_env *env, uint32_t face);
/* Effective segments of a direction of n segments drawn by predefined grid classes (pieces of
 * the largest class when n exceeds it). */
int32_t sw__fr_class_segments(int32_t n);
/* A bound of the float error of a patch's vertices (the vertex shader evaluates the eye-relative
 * control points in float, then projects), in pixels at the nearest depth of `box` (its
 * eye-relative box): 16 FLT_EPSILON R, R the largest control point over its weight (the bound
 * test_gpu_tspline_capture checks against double evaluation, with |P| <= R for positive weights).
 * The grid density is chosen for what it leaves of ε_img. With kept grids (env->grids_resident)
 * three times that: such a grid is evaluated around its centre (16 FLT_EPSILON s R_local, s the
 * occurrence's stretch) and placed in float (a few FLT_EPSILON (R + s R_local)), and a patch is
 * kept only where s R_local <= R (sw__fr_gpu_patch); the others are evaluated eye-relative. */
double sw__fr_float_error_px(const sw__fr_env *env, const double *cpw, size_t n,
                             const double box[6]);
/* The screen a grid density is chosen on: ε_img less what other errors spend (`spent_px`), at
 * least a quarter of ε_img (the sampling floor: over ε_img in all, counted in bound_exceeded). */
void sw__fr_screen_less(sw__fr_tess *t, double spent_px, sw_lod_screen_view *scr);
/* The limit of grid vertices per frame (SW_ERR_LIMIT past it). */
sw_result sw__fr_check_budget(const sw__fr_tess *t, sw_status *status);

/* stage_tessellate_direct.c: a face by its Bézier patches (§4.2), tiled trim textures when
 * large. */
sw_result sw__fr_tess_direct(sw__fr_tess *t, const occurrence *o, sw_status *status);
/* stage_tessellate_hierarchy.c: a face's hierarchy cut. */
sw_result sw__fr_tess_hierarchy(sw__fr_tess *t, const occurrence *o, const hl_choice *items,
                                size_t n, sw_status *status);
/* stage_tessellate_static.c: a unit instance at its static level, with its faces' borders. */
sw_result sw__fr_tess_static(sw__fr_tess *t, const sw__fr_visible *vis,
                             const sw__fr_static_pick *pick, sw_status *status);
/* The cull stage's proxies (vis->proxies), each part a draw; their instances' faces counted. */
sw_result sw__fr_tess_proxies(sw__fr_tess *t, const sw__fr_visible *vis, sw_status *status);
/* stage_tessellate_mesh.c: triangles in object space for sw__fr_append_triangles. */
typedef struct sw__fr_triangles {
    const double *positions; /* 3 per vertex */
    const float *normals_f;  /* 3 per vertex, or NULL */
    const double *normals_d; /* 3 per vertex, or NULL; both NULL: flat, a normal per triangle */
    double normal_matrix[9]; /* row-major 3x3 mapping normals to the world (with normals) */
    uint32_t n_vertices, n_triangles;
    const uint32_t *triangles; /* 3 per triangle */
} sw__fr_triangles;
/* Appends the triangles under the occurrence's transform (eye-relative, float) as one untrimmed
 * draw of o->color: the one triangle path of static LODs and meshes. */
sw_result sw__fr_append_triangles(sw__fr_tess *t, const occurrence *o, const sw__fr_triangles *tr,
                                  sw_status *status);
sw_result sw__fr_tess_meshes(sw__fr_tess *t, const sw__fr_visible *vis, sw_status *status);

/* ---- trim: stage_trim.c --------------------------------------------------------------------- */
/* Plain memory (prepare): every pending trim's texel class at the frame's common scale (within
 * the atlas budget), the whole-box trims' loops flattened at their texel, and the trimmed faces'
 * fat borders along them. */
sw_result sw__fr_trim_plan(const sw__fr_env *env, sw__fr_geometry *geo, sw_gpu_frame_stats *st,
                           sw_status *status);
/* The GL thread: each trim's atlas entry (found, or added and rendered), set on its draw. */
sw_result sw__fr_trim_atlas(sw_gpu_context *ctx, const sw_sg_scene *scene, sw__fr_geometry *geo,
                            sw_gpu_frame_stats *st, sw_status *status);
/* Texels of a resolution class (power-of-two footprints, gutters included). */
int32_t sw__fr_class_texels(double want, int32_t max_entry);
/* Whether the trimmed region lies to the left of loop k's direction. */
int sw__fr_left_is_inside(const sw_sg_polyline *loops, uint32_t n_loops, uint32_t k);
/* Whether a trimmed draw wanting need_u x need_v texels (a texel = the object tolerance at its
 * nearest point) gets exact edges: desc.trim_edges, and its class's texel over k_exact_texel_px in
 * either direction. */
int sw__fr_exact_edges(const sw__fr_env *env, double need_u, double need_v, int32_t max_entry);
/* The flattening tolerance (face parameters) of the loops of a draw's direction spanning `extent`
 * and wanting `need` texels: half a texel of its class, or with exact edges k_exact_flat_px. */
double sw__fr_trim_flat_tol(const sw__fr_env *env, double extent, double need, int exact,
                            int32_t max_entry);

/* ---- outlines: stage_shapes.c ------------------------------------------------------------- */
/* Plain memory (prepare): each visible shape occurrence mapped into the target's pixels
 * (sw__curves_project) as a geo->shapes entry; counted in st (drawn, culled behind the near
 * plane, skipped when the 2D path refuses it, pieces drawn as chords). Errors:
 * SW_ERR_OUT_OF_MEMORY. */
sw_result sw__fr_shapes_plan(const sw__fr_env *env, const sw__fr_visible *vis, sw__fr_geometry *geo,
                             sw_gpu_frame_stats *st, sw_status *status);
/* The GL thread, after the opaque draw into ctx->fbo: the outlines, in order, composited with
 * depth (sw__curves_draw_placed). */
sw_result sw__fr_draw_shapes(sw_gpu_context *ctx, const sw__gpu_view *view,
                             const sw__fr_geometry *geo, sw_status *status);
/* Frees the outlines' shapes (n_shapes 0; the array kept). */
void sw__fr_shapes_empty(sw__fr_geometry *geo);

/* ---- submit: stage_submit.c ------------------------------------------------------------------ */
/* Batch, upload, draw. GL thread. */
sw_result sw__fr_submit(sw_gpu_context *ctx, const sw__gpu_view *view,
                        const sw_gpu_frame_desc *desc, sw__fr_geometry *geo, sw_status *status);

/* ---- geometry helpers (frame_geom.c) -------------------------------------------------------- */
/* Homogeneous control point mapped to eye-relative world space: w x' = R (w x) + w (t - eye). */
void sw__fr_xform_h(const double m[12], const double eye[3], const double in[4], double out[4]);
void sw__fr_box_empty(double box[6]);
void sw__fr_box_add(double box[6], const double h[4]); /* adds the point h / h[3] */
/* World box to eye-relative. */
void sw__fr_eye_box(const double eye[3], const double world[6], double out[6]);
/* Eye-relative box of an object box's corners under m. */
void sw__fr_eye_box_of(const double eye[3], const double obj[6], const double m[12], double out[6]);
double sw__fr_det3(const double m[12]);
/* Cofactor matrix of the linear part (row-major 3 x 3): det(M) M^-T, the map of normals under any
 * invertible affine transform (up to the sign of det). */
void sw__fr_cofactor3(const double m[12], double out[9]);

#endif
