/* SPDX-License-Identifier: MIT */
/* splinewalk gpu/: an OpenGL 4.x core context (EGL; Mesa's surfaceless platform when there is no
 * display or GPU), and one converged frame of a scene: every face's Bézier patches drawn as grids
 * (evaluated on the CPU in this slice, at densities from the Filip bound, Guthe et al. 2005 §5.2),
 * trimmed faces through a trim texture made on the GPU by triangle-fan parity (§4) and a
 * fragment-discarding lookup. Frame images go out as PNG (png_stb.c, image_write.c), .exr through
 * the image module (modules/image/image_oiio.cpp).
 *
 * Threads: only the thread that created a context may call the functions taking it
 * (ARCHITECTURE.md: only the GL owner touches GL). A thread may own several headless contexts:
 * every call that draws makes its own context current first (an adopted context is the host's to
 * keep current). Precision: positions are kept in double and
 * sent relative to the camera in float; depth is reversed-Z with a float depth buffer.
 */
#ifndef SW_GPU_H
#define SW_GPU_H

#include "sw_module_abi.h"

#include "sw_sg_scene.h"

#include <splinewalk/sw_result.h>
#include <splinewalk/sw_defaults.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sw_gpu_context sw_gpu_context;

/* Creates a headless context (EGL_PLATFORM_SURFACELESS_MESA, else the EGL device platform, else
 * EGL_DEFAULT_DISPLAY) and makes it current on the calling thread. Errors: SW_ERR_NO_CONTEXT with
 * what failed and what to try. */
sw_result sw_gpu_context_create_headless(sw_gpu_context **out, sw_status *status);
/* Adopts the GL context current on the calling thread (a host's, or a GLFW window's): it must be
 * OpenGL 4.3+ core with glClipControl. The context stays the caller's: sw_gpu_context_free deletes
 * the GL objects made here (with the context current) but not the context. Errors:
 * SW_ERR_NO_CONTEXT (none current, or too old). */
sw_result sw_gpu_context_adopt_current(sw_gpu_context **out, sw_status *status);
void sw_gpu_context_free(sw_gpu_context *ctx); /* NULL allowed */

/* "GL_RENDERER / GL_VERSION" of the context (borrowed). */
const char *sw_gpu_context_description_ptr(const sw_gpu_context *ctx);

/* The memory budget (memory_budget.c): host and GPU bytes the caches kept between frames may
 * take, divided among them in fixed shares; 0 = the default (host: half of physical memory; GPU:
 * half of what the driver reports, 1 GiB where it reports nothing, as llvmpipe). A context starts
 * with the defaults. Between frames only. */
void sw_gpu_set_memory_budget(sw_gpu_context *ctx, uint64_t host, uint64_t gpu);
/* The budget in force and the GPU memory the driver reports (GL_NVX_gpu_memory_info's dedicated
 * memory, GL_ATI_meminfo's free texture memory; 0: none). */
void sw_gpu_memory_budget(const sw_gpu_context *ctx, uint64_t *host, uint64_t *gpu,
                          uint64_t *gpu_reported);

typedef struct sw_gpu_camera {
    double eye[3], target[3], up[3];
    double fovy_deg; /* vertical field of view, in [SW_FOVY_MIN_DEG, 180) */
} sw_gpu_camera;

/* The view's floors are splinewalk/sw_defaults.h's SW_FOVY_MIN_DEG and SW_ERROR_MIN_PX. */

/* A face occurrence given by the caller (immediate draws): face record, world transform (3 x 4
 * row-major), linear RGBA colour (color[3] < 0: the default grey). */
typedef struct sw_gpu_occurrence {
    uint32_t face;
    double world[12];
    float color[4];
} sw_gpu_occurrence;

/* The camera presets of `splinewalk render --view` (and sw_camera_fit), fitted to a world box (min
 * xyz, max xyz): fovy 40°, target = box centre, distance = diagonal / (2 tan 20°) × 1.1, looking
 * from direction `from` (not zero; (1,1,1) is the iso view) with `up`. A point-sized or empty box
 * gets a unit diagonal. */
void sw_gpu_camera_fit_box(const double box[6], const double from[3], const double up[3],
                           sw_gpu_camera *out);

typedef struct sw_gpu_frame_desc {
    int32_t width, height; /* 0 = SW_DEFAULT_WIDTH x SW_DEFAULT_HEIGHT */
    double error_px;       /* screen-space error bound ε_img in pixels; 0 = SW_DEFAULT_ERROR_PX */
    sw_gpu_camera camera;
    float background[4]; /* RGBA */
    int32_t want_depth;  /* also read back depth */
    int32_t eval_exact;  /* 1: every drawn patch piece evaluated in the vertex shader from the
                            face's knot vectors and control points (B-spline basis in double,
                            any degree up to SW_GPU_EXACT_MAX_DEGREE); 0: Bézier path */
    struct sw_lod_cache *hierarchies; /* NULL: every face drawn by its own Bézier patches;
                              else the cache of `scene`'s bicubic hierarchies (Guthe §6), traversed
                              per frame (§7); the frame waits for the builds and refinements it
                              asks for in the cache's pool (converged). Ignored with eval_exact. */
    const struct sw_sg_bvh *bvh; /* NULL: every occurrence of the scene's traversal is boxed and
                              culled each frame; else the scene's BVH (sw_sg_bvh.h): subtrees
                              outside the frustum are culled, subtrees inside taken untested */
    int32_t walkthrough;         /* with hierarchies: 1 = never wait for the pool (ARCHITECTURE.md
                                    walkthrough mode): faces without a hierarchy yet are drawn by their
                                    Bézier patches, leaves too coarse are drawn as they are, and both
                                    are requested from the pool for later frames; the requests of earlier
                                    frames that have not started are cancelled */
    int32_t present;     /* 1: the frame is also copied into the framebuffer that was bound to
                            GL_DRAW_FRAMEBUFFER when the call began (a window's: 0), at its
                            origin; the caller's framebuffer bindings and viewport are restored */
    int32_t no_readback; /* 1: nothing is read back (out stays empty; want_depth ignored) */
    int32_t wireframe;   /* 1: the surfaces' triangles drawn as lines, trimmed parts still cut
                            away (inspection: grid densities, hierarchy nodes, fat borders) */
    const struct sw_lod_face_cones
        *face_cones;                       /* NULL: no back-patch culling; else the
                         scene's per-face outward normal cones (sw_lod_face_cones.h, built once
                         per scene): an occurrence of a SW_SG_FACE_CLOSED_SHELL face facing
                         away from the eye over its whole box is culled (Kumar §4.4); with
                         static_lods, whole super-surface instances by their units' cones too */
    struct sw_lod_static_set *static_lods; /* NULL: no static LODs; else the scene's set
                              (lod/static/sw_lod_static_set.h), whose BVH of unit instances then
                              culls instead of desc.bvh: a visible unit is drawn at the coarsest
                              level within the view's tolerance at its nearest point, built in
                              the pool on first need (walkthrough: queued, drawn per frame
                              meanwhile; converged: waited for). Ignored with eval_exact */
    int32_t no_proxies;   /* 1: no cluster proxies (sw_lod_static_set_build_proxies); 0: the cut
                             of the unit-instance BVH stops at a node whose built proxy is within
                             the view's tolerance and draws it instead of its subtree */
    int32_t static_force; /* tests of the joins: k > 0 draws unit i at choice (i + k) mod
                             (n + 1) among its n levels within the view's tolerance, the last
                             choice meaning the per-frame path: neighbours at different levels,
                             each good enough, and beside the trim-texture path. 0: the
                             coarsest good level */
    int32_t lod_colors;   /* 1: each draw coloured by its representation (sw__fr_lod_color) */
    int32_t trim_edges;   /* 1: a trimmed draw whose trim texel would exceed a quarter pixel has
                             its edges classified per fragment against its loops, flattened to an
                             eighth of a pixel (trim_edges.c), instead of a trim texture; 0: trim
                             textures only */
    int32_t no_kept_grids; /* 1: every Bézier grid evaluated in the frame; 0: grids kept on the
                              GPU between frames (resident_grids.c) */
    const sw_gpu_occurrence *occurrences; /* NULL: the scene's traversal (or bvh); else exactly
                              these occurrences of the scene's faces, culled one by one (bvh
                              ignored); read during prepare only */
    size_t n_occurrences;
    int32_t present_depth;   /* with present: the frame's depth written too, and only the surfaces'
                                pixels that pass GL_GREATER against the host's depth buffer; the
                                background leaves the host's pixels alone (sw__gpu_present) */
    double near_plane;       /* > 0: the projection's near plane; 0: from the scene's box */
    struct sw_th_pool *pool; /* NULL: prepare runs on the calling thread alone; else the
                              per-frame faces are tessellated in chunks by the caller and this
                              pool's workers together (the output in the same order as on one
                              thread); the caller never runs another task while it joins them */
    const struct sw_gpu_occluders *occluders; /* NULL: no occlusion culling; else the scene's
                              planar faces as occluders (sw_gpu_occluders_build, once per scene):
                              the BVH is walked near to far and what the visible planes hide
                              is culled, conservatively (gpu/occlusion.h). With desc.bvh, or
                              with static_lods over its BVH of unit instances; ignored with
                              wireframe */
} sw_gpu_frame_desc;

/* The planar faces of a scene as occluders: their outlines in object space, built once per scene
 * (their trim loops flattened). Errors: SW_ERR_OUT_OF_MEMORY. *out owned by the caller. */
typedef struct sw_gpu_occluders sw_gpu_occluders;
sw_result sw_gpu_occluders_build(const struct sw_sg_scene *scene, sw_gpu_occluders **out,
                                 sw_status *status);
void sw_gpu_occluders_free(sw_gpu_occluders *oc); /* NULL allowed */
size_t sw_gpu_occluders_memory(const sw_gpu_occluders *oc);
uint32_t sw_gpu_occluders_count(const sw_gpu_occluders *oc); /* faces that are occluders */

enum { SW_GPU_EXACT_MAX_DEGREE = 15 }; /* per direction; larger faces fail with SW_ERR_LIMIT */

typedef struct sw_gpu_frame_stats {
    uint64_t faces_drawn, faces_culled; /* face occurrences */
    uint64_t patches_trimmed;           /* Bézier patches drawn with a trim-texture lookup */
    uint64_t patches_untrimmed;         /* drawn without one */
    uint64_t patches_culled;   /* outside the view frustum, or outside their face's trim box */
    uint64_t triangles;        /* every triangle drawn, fat borders included */
    uint64_t border_triangles; /* of triangles: the fat borders' (Guthe §7.1 crack filling) */
    uint64_t trim_textures, trim_texels;
    uint64_t trim_exact;           /* trimmed draws with exact edges instead of a texture
                                      (desc.trim_edges) */
    uint64_t trim_exact_fallbacks; /* of those wanted, drawn with a texture: no grid could be
                                      made (trim_edges.c's limits) */
    double ms_tessellate; /* traversal, bounds, CPU grids (without ms_hierarchy) */
    double ms_trim;       /* trim-texture generation */
    double ms_draw;       /* upload and draw calls, then the wait for the frame before */
    double ms_readback;
    double ms_gpu; /* GPU time of trim textures + draw (two GL_TIMESTAMP queries) */
    /* trim-texture atlas (Guthe §4.4), kept in the context across frames */
    uint64_t atlas_pages;    /* pages (layers) after this frame */
    uint64_t atlas_texels;   /* texels of those pages */
    uint64_t trim_reused;    /* trim textures kept from an earlier frame (of trim_textures) */
    uint64_t atlas_switches; /* render-target switches for trim generation in this frame */
    uint64_t atlas_allocations; /* array textures the atlas allocated in this frame (growth, or a
                                   repack to another page size or count) */
    uint64_t patches_gpu_evaluated; /* drawn patches evaluated in the vertex shader (§4.2); the
                                       others are CPU grids */
    uint64_t patches_exact; /* of those, evaluated from knots and control points (eval_exact) */
    /* hierarchy traversal (desc.hierarchies) */
    uint64_t hlod_nodes;          /* hierarchy nodes (or parts of one) drawn */
    uint64_t hlod_fallback_faces; /* occurrences drawn by their Bézier patches: no hierarchy */
    uint64_t hlod_refine_rounds;  /* rounds of refinement below the leaves the frame waited for */
    /* the guarantee: pieces drawn whose bound exceeds ε_img — a grid whose density the segment
     * limit capped (the bound it needed is not known), a hierarchy node whose approximation
     * error left less than a quarter of ε_img to its sampling (the sampling floor), a trim loop
     * flattened at the rounding floor or depth cap (trim_loops_floored), a fat border sampled
     * coarser than its cells (borders_capped), a trim texture coarser than its need (the frame's
     * atlas budget scaled it down, or an atlas entry's size limit); the worst known total bound
     * over ε_img, in pixels (0 when none is known) */
    uint64_t bound_exceeded;
    double bound_excess_px;
    uint64_t budget_coarsened;     /* pieces drawn coarser than the view asks because a share
                                      of the memory budget is spent (memory_budget.c): trim
                                      textures scaled down, hierarchy leaves left unrefined;
                                      counted in bound_exceeded too */
    uint64_t hlod_over_budget;     /* nodes drawn although their error exceeds their share of
                                      ε_img (refinement stopped at its depth limit) */
    uint64_t hlod_waits;           /* converged: the hierarchy stage's group waits */
    uint64_t hlod_refine_requests; /* walkthrough: refinements asked for, not waited for */
    double ms_hierarchy; /* the hierarchy stage's time blocked waiting for the pool (its builds
                            and refinements), in both modes (sw_th_thread_waits) */
    /* every wait of the frame for the pool, wherever it happens (prepare and submit, on the
     * threads that ran them: sw_th_thread_waits): group waits that found tasks pending (hierarchy
     * and static-LOD builds, refinements, a cache given up), bracketed waits on tasks' results.
     * 0 in walkthrough mode unless the frame blocked (the walkthrough tests assert it) */
    uint64_t pool_waits;
    double ms_pool_wait; /* the time in those waits */
    /* BVH culling (sw_sg_bvh_cull_stats) by desc.bvh, or with desc.static_lods by the static set's
     * BVH of super-surface instances (items = unit instances): nodes classified against the
     * frustum, of them wholly inside, partly inside and outside; items classified one by one;
     * items kept, and of those the ones wholly inside */
    uint64_t bvh_nodes_visited, bvh_nodes_inside, bvh_nodes_partly, bvh_nodes_outside;
    uint64_t bvh_items_tested, bvh_items_visible, bvh_items_inside;
    uint64_t faces_backculled; /* of faces_culled: back-facing closed-shell occurrences */
    /* static LODs (desc.static_lods) */
    uint64_t static_units_drawn; /* (unit, instance) pairs drawn from a static level */
    uint64_t static_faces;       /* face occurrences they cover (of faces_drawn) */
    uint64_t static_triangles;   /* their triangles (of triangles; fat borders apart) */
    uint64_t static_requests;    /* walkthrough: unit builds queued, not waited for */
    uint64_t static_waits;       /* converged: units the frame waited for */
    uint32_t static_levels_used; /* bit k: some unit drawn at level k (31: 31 and beyond) */
    uint64_t proxies_drawn;      /* cluster proxies drawn (desc.no_proxies) */
    uint64_t proxy_instances;    /* unit instances they stand for (not in static_units_drawn) */
    uint64_t proxy_faces;        /* face occurrences they cover (of faces_drawn) */
    uint64_t proxy_triangles;    /* their triangles (of triangles) */
    /* triangle meshes (SW_SG_NODE_MESH occurrences; gpu/stage_tessellate_mesh.c) */
    uint64_t meshes_drawn, meshes_culled; /* occurrences inside / outside the frustum */
    uint64_t mesh_triangles;              /* their triangles drawn (of triangles) */
    double near_plane; /* the projection's (desc.near_plane or the scene box's) */
    /* counted fallbacks of the loops bounded at their root, 0 in an ordinary frame */
    uint64_t trim_loops_floored; /* loops flattened at the rounding floor or the depth cap
                                    (sw_sg_polyline.below_floor / depth_capped): chords may lie
                                    farther than the trim tolerance from the curve */
    uint64_t borders_capped;     /* fat borders sampled coarser than their cells: the view's
                                    sample budget (sw__gpu_mesh.border_capped) */
    /* fat-border loops placed from samples kept in the border cache, and loops whose samples
     * this frame made (and kept) */
    uint64_t border_loops_kept, border_loops_made;
    /* fat-border quads left out because the closed shell they lie on faces away from the eye
     * there (desc.face_cones: the eye is outside the solids; gpu/crack_fill.c) */
    uint64_t border_quads_away;
    /* the tessellation in chunks (desc.pool): chunks, those the pool's workers took, and the
     * time the preparing thread waited at the join for chunks a worker was still running */
    uint64_t tess_chunks, tess_chunks_by_pool;
    double ms_join;
    /* occlusion culling (desc.occluders): boxes tested against the occlusion map, BVH nodes and
     * face occurrences found hidden (of faces_culled: the occurrences under those nodes too),
     * planar faces drawn into the map */
    uint64_t occlusion_tests, nodes_occluded, faces_occluded, occluders_drawn;
    /* the submit stage's: triangles drawn from GPU buffers kept between frames (static levels,
     * gpu/resident.c; of triangles), and the bytes sent to the GPU for the draw (the frame's
     * vertices, indices and patch data, and the resident levels uploaded this frame) */
    uint64_t resident_triangles, upload_bytes;
    /* outlines (SW_SG_NODE_SHAPE occurrences; gpu/stage_shapes.c): drawn; culled (outside the
     * frustum, or nothing of them in front of the near plane); skipped (refused by the 2D path
     * after the near-plane cut); pieces drawn as their chord (sw__curves_projected.fallbacks) */
    uint64_t shapes_drawn, shapes_culled, shapes_skipped, shape_fallbacks;
    /* the submit stage's: Bézier patch grids drawn from those kept on the GPU between frames
     * (gpu/resident_grids.c; their triangles are in resident_triangles), and grids evaluated
     * into it in this frame */
    uint64_t grid_hits, grid_misses;
} sw_gpu_frame_stats;

typedef struct sw_gpu_image {
    int32_t width, height;
    uint8_t *rgba; /* width*height*4, top row first */
    float *depth;  /* width*height, eye-space distance along the view axis; +INF = background;
                      NULL unless asked for */
} sw_gpu_image;

/* Renders one converged frame of `scene` (SW_SG_SEC_ALL required) into `out` (caller frees with
 * sw_gpu_image_free); `stats` may be NULL. Errors: SW_ERR_GL, SW_ERR_OUT_OF_MEMORY, SW_ERR_LIMIT.
 */
sw_result sw_gpu_render_scene(sw_gpu_context *ctx, const sw_sg_scene *scene,
                              const sw_gpu_frame_desc *desc, sw_gpu_image *out,
                              sw_gpu_frame_stats *stats, sw_status *status);

/* The same frame in two steps, for a visibility thread that prepares frame i+1 while the GL
 * thread submits frame i (Kumar et al. 1997 §5.2; the runtime's pipeline):
 *  - sw_gpu_frame_prepare: culling, hierarchy selection (waiting for the pool in converged mode),
 *    densities and grids, into a plan of plain memory. Any thread; never touches GL; reads the
 *    context's settings and bumps its walkthrough token only, so it may run while the context's
 *    owner submits another plan. At most one prepare per context at a time. desc is copied.
 *  - sw_gpu_frame_submit: trim atlas, upload, draw, present, readback. The context's thread only;
 *    the plan is consumed (freed) whatever the result. The scene must outlive the plan.
 *  - sw_gpu_frame_submit_keep: the same, but the plan is left spent rather than freed: its
 *    memory (a frame's arrays, thousands of blocks: up to ~1 ms to free on a 10^3-face frame) is
 *    released by sw_gpu_frame_plan_free on any thread, e.g. the one preparing the next frame, so
 *    the submitting thread does not pay for it. A spent plan no longer refers to the scene,
 *    the context or the hierarchy cache.
 * sw_gpu_render_scene is prepare then submit. Errors as for sw_gpu_render_scene; submit adds
 * SW_ERR_INVALID_ARGUMENT for a plan of another context. */
typedef struct sw_gpu_frame_plan sw_gpu_frame_plan;
sw_result sw_gpu_frame_prepare(sw_gpu_context *ctx, const sw_sg_scene *scene,
                               const sw_gpu_frame_desc *desc, sw_gpu_frame_plan **out,
                               sw_status *status);
sw_result sw_gpu_frame_submit(sw_gpu_context *ctx, sw_gpu_frame_plan *plan, sw_gpu_image *out,
                              sw_gpu_frame_stats *stats, sw_status *status);
sw_result sw_gpu_frame_submit_keep(sw_gpu_context *ctx, sw_gpu_frame_plan *plan, sw_gpu_image *out,
                                   sw_gpu_frame_stats *stats, sw_status *status);
/* An unsubmitted or spent plan; NULL allowed. */
void sw_gpu_frame_plan_free(sw_gpu_frame_plan *plan);
/* The same, but the plan's arrays (visible occurrences, choices, geometry: megabytes grown by
 * doubling) are kept in ctx, emptied, for a later prepare on ctx instead of being freed (freed
 * when ctx keeps enough already); any thread, while ctx lives. */
void sw_gpu_frame_plan_recycle(sw_gpu_context *ctx, sw_gpu_frame_plan *plan);
double sw_gpu_frame_plan_ms(const sw_gpu_frame_plan *plan); /* prepare's wall time */
/* What the prepare counted and timed (tessellation chunks, the join, culling...); the submit adds
 * the rest. */
const sw_gpu_frame_stats *sw_gpu_frame_plan_stats(const sw_gpu_frame_plan *plan);

/* Renders plain triangles (world-space double positions, 3 per vertex) through the same camera,
 * projection, depth and shading path as sw_gpu_render_scene — the path an independent reference
 * mesh is drawn with in tests. */
sw_result sw_gpu_render_triangles(sw_gpu_context *ctx, const double *positions, uint32_t n_vertices,
                                  const uint32_t *indices, uint32_t n_indices,
                                  const sw_gpu_frame_desc *desc, sw_gpu_image *out,
                                  sw_status *status);

void sw_gpu_image_free(sw_gpu_image *img); /* NULL allowed */

/* The trim-texture atlas kept in the context (Guthe §4.4): its GL_TEXTURE_2D_ARRAY (R8; 0 before
 * the first trimmed frame), the pages in use and their side in texels — for inspection (the
 * viewer's atlas overlay). The context's thread; the texture is valid until the next frame. */
void sw_gpu_trim_atlas_info(const sw_gpu_context *ctx, uint32_t *texture, int32_t *pages,
                            int32_t *side);

/* Writes an image: .png (RGBA8) or .exr (half RGBA plus a float Z channel when depth exists),
 * encoded in memory, then through the project's one writer (sw_safe_write.h: replaced whole or
 * left as it was). Errors: SW_ERR_IO (a full disk too), SW_ERR_UNSUPPORTED (no or another
 * extension), SW_ERR_NOT_FOUND (no such directory), SW_ERR_NOT_REGULAR_FILE (a directory),
 * SW_ERR_INVALID_ARGUMENT (empty image), SW_ERR_INTERNAL. An EXR's capture date is the current
 * time, or SOURCE_DATE_EPOCH (seconds since 1970, UTC) when that is set, so that one frame
 * gives the same bytes on every run. */
sw_result sw_gpu_image_write(const sw_gpu_image *img, const char *path, sw_status *status);

/* PNG is encoded by the core (gpu/png_stb.c); other types by an encoder the image module
 * installs (OpenImageIO: .exr). Without one, sw_gpu_image_write refuses them with
 * SW_ERR_UNSUPPORTED saying which module writes them. An encoder puts the whole file in *bytes
 * (sw__malloc; the caller frees it with sw__free) and touches no file. ext: lower case, without
 * the dot. Installing may race with writers (an atomic pointer); NULL uninstalls. */
typedef sw_result (*sw_gpu_image_encode_fn)(const sw_gpu_image *img, const char *path,
                                            const char *ext, void **bytes, size_t *size,
                                            sw_status *status);
SW_MODULE_ABI void sw_gpu_image_encoder_install(sw_gpu_image_encode_fn encode);
/* The image module's encoder (modules/image/image_oiio.cpp): .exr, half RGBA plus a float Z channel
 * when depth exists. */
sw_result sw_gpu_image_encode_oiio(const sw_gpu_image *img, const char *path, const char *ext,
                                   void **bytes, size_t *size, sw_status *status);

#ifdef __cplusplus
}
#endif
#endif
