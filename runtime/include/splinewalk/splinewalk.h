/* SPDX-License-Identifier: MIT */
/* splinewalk — walk through huge trimmed-NURBS CAD models with a guaranteed screen-space error.
 *
 * The public C API: load a scene (.sws, or STEP / IGES / BREP imported through OpenCASCADE),
 * describe it, save it, pick in it, and render frames headlessly (EGL) or with the host's GL
 * context into its framebuffer. Scenes built from nodes: sw_nodes.h; objects drawn without a
 * scene: sw_immediate.h; allocator and log hooks: sw_setup.h.
 *
 * Style (CONVENTIONS.md): objects are handles holding a pool index and a generation (0 invalid; a
 * stale handle yields SW_ERR_STALE_HANDLE, never a crash); create calls take a `const *_desc` in
 * which zero means "default"; failures return an sw_result and fill the optional caller-owned
 * sw_status with the file, position and what was expected; a failed call changes nothing and calls
 * no callback after reporting the failure.
 *
 * Threads: scene handles may be used from any thread (a loaded scene is immutable); a scene
 * destroyed while another thread saves, describes or draws it stays alive until that call returns,
 * and later calls with its handle return SW_ERR_STALE_HANDLE. A renderer owns a GL context and
 * must be used and destroyed only on the thread that created it: a call from another thread
 * returns SW_ERR_INVALID_ARGUMENT and changes nothing.
 *
 * Handles: a handle holds a slot index and a 16-bit generation; {0} is never valid. After destroy
 * every copy of the handle is stale, also once the slot is reused, until its generation wraps
 * after 65,535 reuses of the same slot. Destroying twice returns SW_ERR_STALE_HANDLE.
 *
 * Ownership: the library keeps no pointer into caller memory after a call returns, except the
 * callbacks of a load while it runs. `*_ptr` functions return borrowed strings.
 *
 * Results: every function returning sw_result may also be given status == NULL; on failure the
 * status (when given) holds the result and a message naming the file, position or argument.
 * Outputs (`out`) are zeroed on failure where the documentation says so, untouched otherwise.
 *
 * Misuse: a NULL desc or required pointer, a stale handle (also a second destroy), a call from a
 * thread that does not own the renderer are programming mistakes. They return the documented
 * result and change nothing, and their message goes to the log hook at SW_LOG_ERROR (sw_setup.h);
 * a library built with SW_MISUSE_ASSERT (CMake option, on by default in Debug builds) aborts with
 * that message on stderr instead.
 */
#ifndef SPLINEWALK_H
#define SPLINEWALK_H

#include <splinewalk/sw_result.h>
#include <splinewalk/sw_defaults.h>
#include <splinewalk/sw_setup.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SW_VERSION_STRING "0.1.0"

typedef struct sw_scene {
    uint32_t id;
} sw_scene;
typedef struct sw_renderer {
    uint32_t id;
} sw_renderer;
/* A node of a node scene (sw_nodes.h): meaningful with the scene that made it. */
typedef struct sw_node {
    uint32_t id;
} sw_node;

/* ---- scenes ---------------------------------------------------------------------------------- */
typedef void (*sw_progress_fn)(void *user_data, double fraction, const char *stage);
typedef void (*sw_warning_fn)(void *user_data, const char *message);

/* A face of an imported CAD file that could not be drawn exactly as it was: repaired where an
 * exact repair exists (the surface unchanged, e.g. all weights scaled by one power of two), else
 * skipped while the rest of the file is imported. Strings are borrowed for the call only. */
typedef enum sw_face_action { SW_FACE_SKIPPED = 1, SW_FACE_REPAIRED = 2 } sw_face_action;
typedef struct sw_face_problem {
    const char *path;      /* the file */
    uint32_t face;         /* the face's index in the file: 0-based, in the order OCCT reads the
                              faces; UINT32_MAX for a face OCCT's reader dropped before it became a
                              face (then `entity` names it) */
    uint32_t entity;       /* the file's own number of such a dropped face (STEP #N, IGES
                              directory entry); 0 otherwise */
    const char *name;      /* the name of the part holding the face (STEP); "" when none */
    sw_face_action action; /* SW_FACE_SKIPPED or SW_FACE_REPAIRED */
    sw_result reason;      /* SW_ERR_INVALID_GEOMETRY (its data: a weight of 0, weights too far
                              apart, a trim loop that does not close, ...), SW_ERR_UNSUPPORTED (a
                              degree above 31), SW_ERR_INTERNAL (OCCT failed on it) */
    const char *message;   /* file, face and reason in words, as given to `warning` */
} sw_face_problem;
typedef void (*sw_face_problem_fn)(void *user_data, const sw_face_problem *problem);

/* sw_scene_load_desc.flags */
#define SW_LOAD_PARTIAL 1u /* a truncated file is imported in part instead of refused (below) */

typedef struct sw_scene_load_desc {
    const char *path;        /* required: .sws, .step/.stp, .iges/.igs, .brep, .tsm (T-spline) */
    sw_progress_fn progress; /* NULL: none; called on the loading thread */
    sw_warning_fn warning;   /* NULL: none; each skipped or repaired face is reported here in
                                words, and OCCT's own warnings */
    void *user_data;
    sw_face_problem_fn face_problem; /* NULL: none; each skipped or repaired face as a record,
                                        on the loading thread, before the load returns */
    uint32_t flags;                  /* 0 or SW_LOAD_PARTIAL */
} sw_scene_load_desc;

/* Loads or imports a scene. A .sws file is mapped and checked (header, section table, size;
 * checksums are verified before first use). Any thread; several loads may run at once. The
 * scene is the caller's: free it with sw_scene_destroy. desc and desc->path are read during the
 * call only; callbacks run on the calling thread before it returns, never after a failure is
 * returned. *out = {0} on failure.
 * A CAD file's faces that cannot be drawn exactly are repaired or skipped, each reported to
 * face_problem and warning, and counted in sw_scene_info; the rest is imported. A structurally
 * truncated file — an IGES file whose Terminate record is missing or disagrees with the records
 * present — is SW_ERR_TRUNCATED, unless flags has SW_LOAD_PARTIAL: then only the entities whose
 * data is whole, and whose referenced entities' data is whole, are imported, and
 * sw_scene_info.partial is 1. (Truncated STEP and BREP files cannot be read at all: SW_ERR_FORMAT
 * with or without the flag.)
 * Errors: SW_ERR_INVALID_ARGUMENT (NULL desc, path or out), SW_ERR_UNSUPPORTED (unknown
 * extension or input), SW_ERR_NOT_FOUND, SW_ERR_NOT_REGULAR_FILE (a directory, FIFO or device:
 * inputs are opened without blocking and must be regular files), SW_ERR_IO, SW_ERR_FORMAT,
 * SW_ERR_TRUNCATED,
 * SW_ERR_CHECKSUM, SW_ERR_VERSION, SW_ERR_INVALID_GEOMETRY, SW_ERR_OUT_OF_MEMORY,
 * SW_ERR_LIMIT (65,535 scenes alive), SW_ERR_INTERNAL. */
SW_API sw_result sw_scene_load(const sw_scene_load_desc *desc, sw_scene *out, sw_status *status);

/* Builds the built-in default scene (OCCT's sample furniture arranged in its room, plus a motor)
 * from the occt-misc data directory `data_dir` (NULL: /usr/share/opencascade/data). desc may be
 * NULL; only its callbacks and user_data are used (its path is ignored). Thread, ownership and
 * *out as sw_scene_load. Errors: SW_ERR_INVALID_ARGUMENT (NULL out, data_dir too long), and those
 * of importing a file (SW_ERR_NOT_FOUND when the occt-misc data is missing). */
SW_API sw_result sw_scene_load_default(const char *data_dir, const sw_scene_load_desc *desc,
                                       sw_scene *out, sw_status *status);

/* Writes the scene as .sws (temporary name, then rename: a failure leaves `path` as it was). Any
 * thread. Errors: SW_ERR_INVALID_ARGUMENT (NULL path), SW_ERR_STALE_HANDLE, SW_ERR_IO, and
 * SW_ERR_CHECKSUM / SW_ERR_FORMAT for a mapped scene found corrupt on first use. */
SW_API sw_result sw_scene_save(sw_scene scene, const char *path, sw_status *status);

/* Frees the scene; later use of the handle yields SW_ERR_STALE_HANDLE. Any thread: a call using
 * the scene on another thread at that moment completes first (the memory goes with the last of
 * them), and a renderer that last drew the scene keeps its memory, with the hierarchies it built,
 * until it draws another scene or is destroyed. Errors: SW_ERR_STALE_HANDLE (already destroyed, or
 * never valid). */
SW_API sw_result sw_scene_destroy(sw_scene scene);

#define SW_SURFACE_KIND_COUNT 12
typedef struct sw_scene_info {
    uint32_t faces, trimmed_faces, loops, curves;
    uint32_t faces_by_kind[SW_SURFACE_KIND_COUNT]; /* names: sw_surface_kind_name(k) */
    uint64_t bezier_patches;                       /* after extraction of every face */
    uint32_t max_degree_u, max_degree_v, max_curve_degree;
    uint64_t control_points;
    uint32_t nodes, instances;
    uint64_t face_occurrences; /* faces drawn, instances expanded */
    uint32_t adjacent_face_pairs;
    double bbox_min[3], bbox_max[3]; /* of the surfaces, the meshes and the outlines */
    size_t memory_bytes;
    uint32_t meshes;               /* triangle meshes (sw_nodes.h MESH nodes; .sws MESHES) */
    uint64_t mesh_triangles;       /* their triangles, each mesh once */
    uint64_t mesh_occurrences;     /* meshes drawn, instances expanded */
    uint64_t triangle_occurrences; /* their triangles, instances expanded */
    /* Of the CAD import that made the scene (sw_scene_load of a .step/.iges/.brep); 0 otherwise,
     * also for a .sws written from such an import. */
    uint32_t faces_skipped;  /* not in the scene, each reported to face_problem */
    uint32_t faces_repaired; /* in the scene after an exact repair */
    int32_t partial;         /* 1: a truncated file imported in part (SW_LOAD_PARTIAL) */
    uint64_t lod_cache_bytes; /* the .sws file's static LOD cache (`splinewalk build-lod`), checked
                                 against its checksum; 0: none (or damaged) */
    uint32_t shapes;          /* planar outlines (sw_nodes.h SHAPE nodes; .sws SHAPES) */
    uint64_t shape_occurrences; /* outlines drawn, instances expanded */
} sw_scene_info;

/* Describes the scene (the first call on a scene verifies it and walks it once). Any thread.
 * Errors: SW_ERR_INVALID_ARGUMENT (NULL out), SW_ERR_STALE_HANDLE, SW_ERR_CHECKSUM /
 * SW_ERR_FORMAT (a corrupt mapped scene), SW_ERR_OUT_OF_MEMORY. */
SW_API sw_result sw_scene_get_info(sw_scene scene, sw_scene_info *out, sw_status *status);
/* "plane", "cylinder", ...; "unknown" out of range; never NULL. A static string; any thread. */
SW_API const char *sw_surface_kind_name(uint32_t kind);

/* ---- picking --------------------------------------------------------------------------------- */
typedef struct sw_pick_hit {
    int32_t hit;         /* 0: the ray meets no surface (the rest is zero) */
    uint32_t surface;    /* the surface (face) hit, as counted by sw_scene_info.faces */
    uint64_t occurrence; /* which drawn occurrence of it (instances expanded; stable per scene) */
    double t;            /* point = origin + t * direction, t > 0 */
    double point[3];     /* world */
    double uv[2];        /* the surface's parameters at the point (inside its trim loops) */
    sw_node node;        /* node scenes (sw_nodes.h): the NURBS, TSPLINE, IMPORT or MESH node
                            holding the surface or mesh, as it was when the picked version was
                            compiled; {0} for scenes loaded from files */
    /* A mesh hit (surface = UINT32_MAX then, uv zero): the mesh as counted by
     * sw_scene_info.meshes, the triangle's index in it and the barycentric weights of its three
     * vertices at the point. mesh = UINT32_MAX for a surface hit. */
    uint32_t mesh, triangle;
    double barycentric[3];
} sw_pick_hit;

/* The nearest point where the ray origin + t direction (t > 0; direction not unit, not zero) meets
 * a trimmed surface or a mesh triangle of the scene (meshes: each occurrence's box, then its
 * triangles, Möller-Trumbore), through a BVH over the scene's surface occurrences (built by the
 * first pick and kept with the scene), Bézier subdivision and Newton's method on the exact NURBS
 * surface. A ray tangent to a surface may miss it. Any thread. Errors: SW_ERR_INVALID_ARGUMENT
 * (NULL pointer, zero or non-finite ray), SW_ERR_STALE_HANDLE, SW_ERR_OUT_OF_MEMORY,
 * SW_ERR_CHECKSUM / SW_ERR_FORMAT (a corrupt mapped scene). out->hit = 0 with SW_OK: no hit. */
SW_API sw_result sw_scene_pick(sw_scene scene, const double origin[3], const double direction[3],
                               sw_pick_hit *out, sw_status *status);

/* ---- cameras --------------------------------------------------------------------------------- */
/* Right-handed, world units. All zero: the iso preset fitted to the drawn scene. Otherwise eye and
 * target must differ and up must not be parallel to target - eye. */
typedef struct sw_camera {
    double eye[3], target[3], up[3];
    double fovy_deg; /* vertical field of view in degrees; 0 = SW_DEFAULT_FOVY_DEG; else in
                        [SW_FOVY_MIN_DEG, 180) */
} sw_camera;

/* The view's floors, SW_FOVY_MIN_DEG and SW_ERROR_MIN_PX, are in sw_defaults.h. */

/* Checks a camera as every frame checks it, so that a front end (a camera path, a --camera option)
 * can refuse it when it is read rather than when it is drawn: the all-zero camera (the fitted
 * default) passes; otherwise every coordinate finite and at most SW_CAMERA_COORD_MAX in
 * magnitude, fovy 0 or in [SW_FOVY_MIN_DEG, 180), the eye farther from the target than 1e-9 x
 * the larger of 1 and their largest coordinate, up not zero and more than ~4.5e-5 rad away from
 * the view direction (closer, the view basis is lost in rounding). Any thread. Errors:
 * SW_ERR_INVALID_ARGUMENT (the message names the problem). */
SW_API sw_result sw_camera_check(const sw_camera *camera, sw_status *status);

typedef enum sw_view_preset {
    SW_VIEW_ISO = 0,   /* from (+1,+1,+1), up +Z */
    SW_VIEW_FRONT = 1, /* from -Y, up +Z */
    SW_VIEW_TOP = 2,   /* from +Z, up +Y */
    SW_VIEW_RIGHT = 3, /* from +X, up +Z */
} sw_view_preset;

/* Fits a preset to the scene's bounding box: fovy 40°, target = box centre, distance =
 * diagonal / (2 tan(fovy/2)) × 1.1 — the cameras of `splinewalk render --view`. Any thread.
 * Errors: SW_ERR_INVALID_ARGUMENT (NULL out, view not a preset), SW_ERR_STALE_HANDLE,
 * SW_ERR_CHECKSUM / SW_ERR_FORMAT (a corrupt mapped scene). */
SW_API sw_result sw_camera_fit(sw_scene scene, sw_view_preset view, sw_camera *out,
                               sw_status *status);

/* The matrices a frame of this camera, size (0 x 0 = 1280 x 720) and near plane draws with,
 * column-major as GL takes them (m[col * 4 + row]): view maps world to GL eye space (x right, y
 * up, looking down -z; right = normalize((target - eye) x up)), proj is the renderer's reversed-Z
 * perspective with an infinite far plane,
 *     [fx 0  0     0   ]      fy = 1 / tan(fovy / 2), fx = fy x height / width,
 *     [0  fy 0     0   ]      so that with glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE) window
 *     [0  0  0   near  ]      depth = near / d for a point at distance d > near along the view
 *     [0  0  -1    0   ]      axis: 1 at the near plane, towards 0 far away (clear to 0,
 *                             GL_GREATER).
 * Large world coordinates lose float precision in view: a host may subtract the eye from its
 * positions and drop view's translation (view[12..14]) itself. Any thread. The renderer picks the
 * near plane per frame unless sw_frame_desc.near_plane sets it; sw_frame_stats gives back the one
 * used, and these matrices. Errors: SW_ERR_INVALID_ARGUMENT (NULL pointer; a zero camera: fit one
 * with sw_camera_fit first; eye = target, up zero or parallel to the view, fovy outside
 * [SW_FOVY_MIN_DEG, 180)
 * (0 = 40); non-finite values; size outside 0..16384; near_plane not positive and finite). view
 * and proj are written on success only. */
SW_API sw_result sw_camera_matrices(const sw_camera *camera, int32_t width, int32_t height,
                                    double near_plane, double view[16], double proj[16],
                                    sw_status *status);

/* ---- rendering ------------------------------------------------------------------------------- */
typedef struct sw_renderer_desc {
    uint32_t worker_threads;     /* threads of the worker pool that builds and refines hierarchies;
                                    0 = one per online processor. A converged frame's thread also
                                    runs pool tasks while it waits for them. At most 1024. */
    int32_t use_current_context; /* 0: the renderer creates and owns a headless EGL context;
                                1: it draws with the OpenGL context current on the creating thread
                                (the host's: 4.3+ core with glClipControl), which the host keeps
                                current there for every call and destroys itself after
                                sw_renderer_destroy. Every call (create, draw, submit,
                                destroy) leaves the context's GL state as it found it:
                                bindings (program, vertex array, buffers and indexed
                                uniform / storage ranges, framebuffers, renderbuffer,
                                texture unit 0 and its sampler, the active unit),
                                capabilities, viewport, scissor, blend, depth, stencil,
                                colour masks and clear values, rasterisation, clip control,
                                pixel store, the transform feedback object and its generic
                                buffer; the renderer draws as in a fresh context meanwhile
                                (zero-to-one clip depth, reversed-Z). Not restored: texture
                                units other than 0, image units, queries, GL errors. */
    /* The memory budget of what the renderer keeps between frames, in bytes; 0 = the default.
     * Host: half to the bicubic hierarchies (over it they refine no further and faces not yet
     * built are drawn by their Bézier patches), a sixteenth (at most
     * 64 MiB) to the fat borders' cache; default half of physical memory. GPU: three eighths to
     * static levels resident in buffers, half (at most 512 M texels, one byte each) to the trim
     * atlas, a frame's trim textures taking at most half of that; default half of what the driver
     * reports, 1 GiB where it reports nothing (llvmpipe). Over a share a
     * cache keeps only what the last frame used, and the picture coarsens instead of failing:
     * sw_frame_stats.budget_coarsened counts what was drawn coarser (in bound_exceeded too). The
     * scene, the BVH and the per-frame buffers, which follow the scene and the screen, are not
     * budgeted. sw_renderer_memory_budget says what is in force. */
    uint64_t memory_budget_host, memory_budget_gpu;
} sw_renderer_desc;

/* Creates a renderer owned by the calling thread: headless (EGL; llvmpipe when there is no GPU),
 * its GL context then current on that thread, or on the thread's current context
 * (desc->use_current_context); destroy it there with sw_renderer_destroy.
 * desc may be NULL (defaults). Several renderers may live on different threads. *out = {0} on
 * failure. Errors: SW_ERR_INVALID_ARGUMENT (NULL out, worker_threads above 1024),
 * SW_ERR_NO_CONTEXT (with what failed), SW_ERR_OUT_OF_MEMORY, SW_ERR_LIMIT (65,535 renderers). */
SW_API sw_result sw_renderer_create(const sw_renderer_desc *desc, sw_renderer *out,
                                    sw_status *status);
/* Frees the renderer, its GL objects, its own GL context (not an adopted one), its worker pool
 * and the hierarchies it keeps (waiting for the pool's tasks). Owner thread only. Errors:
 * SW_ERR_STALE_HANDLE (already destroyed, or never valid), SW_ERR_INVALID_ARGUMENT (called from
 * another thread: the renderer stays alive and usable by its owner). */
SW_API sw_result sw_renderer_destroy(sw_renderer renderer);
/* "renderer / GL version" of the renderer's context, borrowed until the renderer is destroyed;
 * "" for a stale handle or a call from a thread other than the owner. Never NULL. */
SW_API const char *sw_renderer_description_ptr(sw_renderer renderer);

typedef struct sw_memory_budget {
    uint64_t host_bytes, gpu_bytes; /* the budget in force (sw_renderer_desc's, or the default) */
    uint64_t gpu_reported_bytes;    /* the GPU memory the driver reports (GL_NVX_gpu_memory_info,
                                       GL_ATI_meminfo); 0: it reports none (llvmpipe) */
} sw_memory_budget;
/* The renderer's memory budget. Owner thread only. Errors: SW_ERR_STALE_HANDLE,
 * SW_ERR_INVALID_ARGUMENT (NULL out, another thread). */
SW_API sw_result sw_renderer_memory_budget(sw_renderer renderer, sw_memory_budget *out,
                                           sw_status *status);

typedef struct sw_frame_desc {
    sw_scene scene;
    sw_camera camera;
    int32_t width, height;   /* 0 = 1280 x 720 */
    double error_px;         /* screen-space error ε_img in pixels; 0 = SW_DEFAULT_ERROR_PX;
                                else at least SW_ERROR_MIN_PX */
    const char *output_path; /* .png or .exr (with depth); NULL = render only. Replaced whole or
                                left as it was (a full disk is SW_ERR_IO); a device or FIFO is
                                written in place, a symbolic link written through */
    int32_t eval_exact;      /* 1: every patch evaluated from knots and control points in the
                                vertex shader (Krishnamurthy & Yasui; degree <= 15); 0: rational
                                Bézier patches (degree <= 3 in the shader, higher on the CPU) */
    int32_t no_hierarchy;    /* 0: each face drawn from its bicubic hierarchy (Guthe et al. 2005
                                §6-§7: nodes as coarse as the view allows, built and refined in the
                                renderer's worker pool and kept for later frames); 1: every face
                                drawn by its own Bézier patches. Ignored with eval_exact. */
    int32_t walkthrough;     /* 0: converged — the frame waits for every hierarchy build and
                                refinement it asks for (deterministic images); 1: walkthrough — it
                                never waits: what is not ready is drawn from what is at hand
                                (Bézier patches, coarser nodes) and asked for, for later frames */
    int32_t present;         /* 1: the frame is also copied into the framebuffer bound to
                                GL_DRAW_FRAMEBUFFER when the call began (a window's: 0), at its
                                origin, width x height, whatever the host's GL state (scissor,
                                masks, ...); that state is restored as use_current_context
                                says. Not read back unless output_path is set. With
                                present_depth: composited by depth instead (below). */
    int32_t wireframe;       /* 1: triangles drawn as lines (trimmed parts still cut away), to see
                                the tessellation the error bound chose */
    int32_t static_lods;     /* 1: Kumar et al. 1997 static LODs: the scene's super-surfaces
                                (whole faces grouped under a normal-cone bound) get simplified
                                meshes with declared errors, read from the .sws file's LOD
                                cache (`splinewalk build-lod`) or, with the LOD-building module
                                installed (sw_lod_build.h), built in the worker pool on first
                                need (their clustering too); a visible one is drawn at the
                                coarsest level within ε_img at its nearest point, else by the
                                per-frame path. Walkthrough frames never wait for the builds;
                                converged frames do. 0: every face by the per-frame path */
    int32_t no_proxies;      /* with static_lods, 0: cluster proxies across objects (HLOD): once
                                the LOD cache is read, BVH nodes of many super-surface instances
                                get one merged mesh with a certified error, built in the worker
                                pool, and a frame draws it instead of the node's instances where
                                that error is within ε_img (walkthrough frames as they are built,
                                converged frames once all are, waiting for none); 1: none */
    int32_t lod_colors;      /* 1: each surface coloured by how it is drawn: static levels fine
                                to coarse blue, teal, green, yellow, orange, pink; per-frame grey,
                                violet where cut by exact trim edges (trim_edges); cluster
                                proxies red */
    int32_t static_force;    /* tests of the joins: k > 0 draws super-surface i at choice
                                (i + k) mod (n + 1) among its n levels good enough for the view,
                                the last choice meaning the per-frame path: neighbours at
                                different levels. 0: the coarsest good level */
    int32_t present_depth;   /* with present, 1: depth compositing (a host drawing its own 3D
                                geometry around the surfaces). Instead of copying the whole
                                image, a fullscreen pass writes, for each pixel a surface covers,
                                its colour and its depth (gl_FragDepth, so any depth format of the
                                host's) where that depth is GREATER than the host's depth buffer
                                (GL_GREATER, depth writes on); background pixels are discarded:
                                the host's colour and depth stay there. The host draws with the
                                frame's matrices (sw_frame_stats.view / proj, or sw_camera_matrices
                                with near_plane set) under the same depth convention:
                                glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE), glDepthRange(0, 1),
                                depth cleared to 0, glDepthFunc(GL_GREATER). Geometry it draws
                                before the call hides the surfaces behind it; geometry drawn after
                                is hidden where a surface is nearer. A framebuffer without a
                                depth buffer gets the surfaces' colour, its background kept.
                                0: the colour copy above */
    double near_plane;       /* > 0: the projection's near plane, in world units (what lies
                                nearer is clipped); 0: chosen per frame from the scene's box
                                (max(1e-4 x its diagonal, half the eye's distance to it)), given
                                back in sw_frame_stats.near_plane */
    int32_t occlusion_culling; /* 1: what the visible planar faces hide is culled before it is
                                tessellated: the scene's bounding-volume hierarchy is walked near
                                to far and each planar face found visible is drawn into a
                                quarter-resolution depth map on the visibility thread, against
                                which the boxes behind are tested. Conservative: the image is
                                the one without it. The outlines are built once per scene, on
                                the first frame that asks. With static_lods the unit instances
                                are culled so. Not with wireframe (lines hide nothing).
                                Where a frame hides nothing the renderer rests it for the next
                                1, 3, 7 or 15 frames (the image is the same either way). The
                                CLI turns it on unless --no-occlusion.
                                0: frustum and back-patch culling */
    int32_t trim_edges;        /* 1: exact trim edges — a trimmed surface whose trim texture's
                                texel would exceed a quarter pixel at its nearest point is cut
                                per fragment against its trim loops, flattened to an eighth of a
                                pixel on screen, instead of by the texture (close-ups keep
                                smooth edges at any zoom, and need no large textures); far
                                surfaces keep their textures. 0: trim textures only */
    int32_t no_kept_grids;     /* 0: patch grids are kept on the GPU between frames — evaluated
                                the first time a patch is drawn at a density class, then drawn
                                again while the view asks for that class or one up to twice as
                                coarse (every instance of a part shares them); 1: every grid
                                evaluated in each frame from control points sent with it (the
                                A/B of benchmarks) */
} sw_frame_desc;

typedef struct sw_frame_stats {
    uint64_t faces_drawn, faces_culled;
    uint64_t patches_trimmed, patches_untrimmed, patches_culled;
    uint64_t triangles, trim_textures, trim_texels;
    uint64_t patches_gpu_evaluated;    /* evaluated in the vertex shader; the rest are CPU grids */
    uint64_t patches_exact;            /* of those, by the exact NURBS path (eval_exact) */
    uint64_t atlas_pages, trim_reused; /* trim-texture atlas pages; textures kept from before */
    uint64_t hierarchy_nodes;          /* hierarchy nodes drawn (0 with no_hierarchy) */
    uint64_t refine_rounds;  /* rounds of refinement below the hierarchies' leaves waited for */
    uint64_t fallback_draws; /* walkthrough: faces drawn without their hierarchy, plus leaves
                                drawn coarser than the error asks, both requested from the pool */
    uint64_t pool_waits;     /* times the frame blocked on the worker pool, wherever it can
                                (hierarchy and static-LOD builds and refinements waited for, a
                                cache given up with builds in flight, a node scene's compile),
                                on every thread that worked on it; 0 in walkthrough mode unless
                                a walkthrough frame blocked */
    uint64_t bound_exceeded; /* pieces drawn whose error bound exceeds ε_img: grids capped at the
                                segment limit, hierarchy nodes at the sampling floor, trim loops
                                flattened at their floor, fat borders sampled coarser than their
                                cells, trim textures coarser than their need (the frame's atlas
                                budget), hierarchy leaves left unrefined under the memory budget */
    double bound_excess_px;  /* the worst known bound over ε_img of those, in pixels */
    double ms_hierarchy;     /* blocked waiting for hierarchy builds and refinements (both
                                modes; 0 when none was waited for) */
    double ms_tessellate, ms_trim, ms_draw, ms_readback, ms_write, ms_total;
    /* every frame is prepared on the renderer's visibility thread (sw_renderer_draw's too):
     * hierarchy and tessellate ran there, in ms_visibility (its whole time for the frame); the
     * rest on the caller's, in ms_total = ms_wait_visibility (waiting for the visibility thread;
     * in sw_renderer_draw all of ms_visibility) + trim + draw + readback + write + the call's own
     * overhead (sw_renderer_draw's prepare included) */
    double ms_visibility, ms_wait_visibility;
    double ms_gpu; /* GPU time of the trim textures and the draw, by GL timer queries, of the
                      frame before (read when it completed; of this frame when it was read back);
                      on llvmpipe the rasterizer threads' work */
    uint64_t faces_backculled; /* of faces_culled: back-facing surfaces of closed shells (Kumar
                                  §4.4 back-patch culling by normal cones) */
    /* static LODs (desc.static_lods) */
    uint64_t static_drawn;     /* super-surface instances drawn from a static level */
    uint64_t static_faces;     /* face instances they cover (of faces_drawn) */
    uint64_t static_triangles; /* their triangles (of triangles) */
    uint64_t static_requests;  /* walkthrough: builds queued instead of waited for */
    uint64_t proxies_drawn;    /* cluster proxies drawn (desc.no_proxies) */
    uint64_t proxy_instances;  /* super-surface instances they stand for */
    uint64_t proxy_triangles;  /* their triangles (of triangles) */
    /* triangle meshes (sw_nodes.h MESH nodes) */
    uint64_t meshes_drawn, meshes_culled; /* mesh occurrences inside / outside the frustum */
    uint64_t mesh_triangles;              /* their triangles drawn (of triangles) */
    /* the camera the frame drew with, for a host drawing beside it (present_depth):
     * sw_camera_matrices of its camera (resolved: a zero camera's fitted one), size and
     * near_plane */
    double near_plane;
    double view[16], proj[16];
    /* the tessellation split in chunks with the renderer's pool: chunks, those its workers ran,
     * and the time the frame's preparing thread waited at the join for a worker's chunk (it runs
     * no other task meanwhile) */
    uint64_t tess_chunks, tess_chunks_by_pool;
    double ms_join;
    /* of triangles: the fat borders drawn along the faces' boundaries to close cracks between
     * independently tessellated faces (Guthe et al. 2005 §7.1); a resident mesh has none */
    uint64_t border_triangles;
    /* fat-border loops placed from the samples the renderer keeps between frames and shares
     * between a face's occurrences, and loops whose samples this frame made */
    uint64_t border_loops_kept, border_loops_made;
    /* occlusion culling (sw_frame_desc.occlusion_culling): boxes tested against the occlusion
     * map, hierarchy nodes and face occurrences found hidden (of faces_culled, the occurrences
     * under those nodes included), planar faces drawn into the map */
    uint64_t occlusion_tests, nodes_occluded, faces_occluded, occluders_drawn;
    /* of triangles: those drawn from GPU buffers the renderer keeps between frames (static LODs'
     * levels, sent once); and the bytes sent to the GPU for the frame's draw (the vertices,
     * indices and patch data made for it, and the levels sent for the first time) */
    uint64_t resident_triangles, upload_bytes;
    /* pieces drawn coarser than the view asks because a share of the renderer's memory budget is
     * spent (sw_renderer_desc.memory_budget_*): trim textures scaled down to the frame's share,
     * hierarchy leaves left unrefined; each is in bound_exceeded too */
    uint64_t budget_coarsened;
    /* trimmed draws cut by exact trim edges instead of a texture (sw_frame_desc.trim_edges), and
     * those that wanted them but kept a texture (a grid over its limits: 2^22 loop segments, 2^20
     * cell entries, or no reference point clear of the loops) */
    uint64_t trim_exact, trim_exact_fallbacks;
    /* outlines (sw_nodes.h SHAPE nodes): drawn; culled (outside the view, or wholly behind the
     * near plane); skipped (a loop left without area once cut at the near plane); pieces drawn
     * as their chord (a control point stayed behind the eye after the splits' cap) */
    uint64_t shapes_drawn, shapes_culled, shapes_skipped, shape_fallbacks;
    /* patch grids drawn from those the renderer keeps on the GPU between frames (their
     * triangles are in resident_triangles), and grids evaluated into it for this frame (the
     * first sight of a patch, or a view that needs it finer than kept) */
    uint64_t grid_hits, grid_misses;
    /* fat-border quads left out where a closed shell faces away from the eye (hidden by its own
     * front; only while the eye is found outside every solid) */
    uint64_t border_quads_away;
} sw_frame_stats;

/* Renders one frame of this call's camera: converged by default (every refinement done before
 * the frame is drawn, so the image is deterministic: the same scene, camera and size give the
 * image `splinewalk render` gives), or walkthrough (desc->walkthrough: never waits for the
 * renderer's worker pool), and writes it to desc->output_path when that is not NULL (temporary
 * name, then rename). Owner thread only; the scene may be used by other threads meanwhile. desc is
 * read during the call only. stats may be NULL; it is written on success only. The frame runs
 * through the same pipeline as split frames (below): sw_renderer_prepare, then sw_renderer_submit,
 * in one call. There is no look-ahead: the visibility thread prepares this call's frame while the
 * caller waits, so nothing of it overlaps the caller's own work; a host that knows its next camera
 * gets the overlap from prepare/submit. Errors: SW_ERR_INVALID_ARGUMENT (NULL desc; a thread other
 * than the renderer's owner; size out of 0..16384; error_px below SW_ERROR_MIN_PX or not finite;
 * fovy out of [SW_FOVY_MIN_DEG, 180); a non-finite or degenerate camera), SW_ERR_STALE_HANDLE
 * (renderer or desc->scene), SW_ERR_UNSUPPORTED (output extension not .png or .exr), SW_ERR_IO,
 * SW_ERR_GL, SW_ERR_LIMIT, SW_ERR_OUT_OF_MEMORY, SW_ERR_CHECKSUM / SW_ERR_FORMAT (a corrupt mapped
 * scene detected on first use). */
SW_API sw_result sw_renderer_draw(sw_renderer renderer, const sw_frame_desc *desc,
                                  sw_frame_stats *stats, sw_status *status);

/* ---- split frames: the visibility / submission pipeline (Kumar et al. 1997 §5.2) -------------
 * sw_renderer_prepare hands a frame to the renderer's visibility thread, which culls it, selects
 * the hierarchy nodes and tessellates while the caller goes on — typically submitting the frame
 * before: prepare(0); loop { prepare(i + 1); submit(i); } overlaps visibility of frame i + 1 with
 * the submission of frame i. sw_renderer_submit waits for the oldest prepared frame and draws it
 * (and writes desc->output_path) on the caller's thread. At most SW_RENDERER_MAX_PREPARED frames
 * wait at a time; they are submitted in order. Walkthrough frames never wait for the worker pool;
 * a submit only waits for the visibility thread. Frames prepared together must show one scene.
 * Owner thread only. */
#define SW_RENDERER_MAX_PREPARED 2

/* Errors: as sw_renderer_draw for a bad desc or handle; SW_ERR_INVALID_ARGUMENT with
 * SW_RENDERER_MAX_PREPARED frames waiting, or a waiting frame of another scene;
 * SW_ERR_OUT_OF_MEMORY. desc (and the output path) are copied; the scene is held until the frame is
 * submitted. */
SW_API sw_result sw_renderer_prepare(sw_renderer renderer, const sw_frame_desc *desc,
                                     sw_status *status);
/* Draws the oldest prepared frame. A submit returns once its frame's GL commands are issued and
 * the frame submitted before it has completed (one frame in flight, no glFinish): what the host
 * issues next in the context comes after the frame, as GL orders commands, and a frame written to
 * output_path is complete on return. stats may be NULL; written on success only. Errors: those of
 * sw_renderer_draw, including those its preparation met (then nothing is drawn and the frame is
 * gone); SW_ERR_INVALID_ARGUMENT when no frame is prepared. sw_renderer_draw refuses to run
 * while prepared frames wait (SW_ERR_INVALID_ARGUMENT); sw_renderer_destroy drops them. */
SW_API sw_result sw_renderer_submit(sw_renderer renderer, sw_frame_stats *stats, sw_status *status);

#ifdef __cplusplus
}
#endif

#include <splinewalk/sw_nodes.h>
#include <splinewalk/sw_immediate.h>
#endif
