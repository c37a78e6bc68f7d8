/* SPDX-License-Identifier: MIT */
/* Frame-time profiles (never installed): one row of numbers per frame of a `splinewalk profile`
 * run, their summary (median, p90, p99, max, mean), and the files a run leaves: profile.csv,
 * profile.json, frametime.svg and report.html (hand-written SVG; the HTML is also well-formed XML).
 *
 * The stages are the renderer's own timers (sw_frame_stats) plus "other" = frame_ms - sum of the
 * measured stages: whatever the frame call spent outside them (setup, bookkeeping, the first
 * frame's pool and cache creation). Keeping "other" small is what shows that the stages account
 * for the frame.
 *
 * The worker pool's share of a frame is beside them, like the visibility thread's and the GPU's:
 * pool_<kind>_ms and pool_<kind>_tasks per task kind (sw_th_pool.h), the differences of the
 * pool's counters between the end of the previous frame and the end of this one (a worker's
 * running task counts in the frames it spans), pool_queued, the tasks waiting at the frame's end,
 * and pool_inject_peak, the longest the injection queue (tasks submitted by the visibility thread
 * and the frame's) grew during the frame.
 */
#ifndef SW_PROFILE_REPORT_H
#define SW_PROFILE_REPORT_H

#include <splinewalk/splinewalk.h>

#include "sw_th_pool.h"

#include <stdint.h>
#include <stdio.h>

/* Per task kind of the pool (sw_th_pool.h's table): the time the pool's threads spent in the
 * kind's tasks during the frame and how many ran. */
/* The pool's task kinds the profile has columns for, by the names their layers register them
 * under (sw_th_task_kind_register: lod/hierarchy/hierarchy_cache.c, lod/static/static_lod_set.c,
 * gpu/stage_tessellate_parallel.c, runtime/src/api_render.c, api_nodes_compile.c). A kind
 * registered under another name counts as "other" (sw_rt_profile_row_pool), so the kinds' times
 * still add up to the pool's busy time. */
#define SW_RT_POOL_KINDS(X, A)                                                                     \
    X(A, OTHER, "other", "tasks of no other kind")                                                 \
    X(A, HIERARCHY, "hierarchy", "bicubic hierarchy builds")                                       \
    X(A, HIERARCHY_WAIT, "hierarchy_wait",                                                         \
      "converged frames' tasks waiting for a hierarchy build (their own time, waits included)")    \
    X(A, REFINE, "refine", "refinements below a hierarchy's leaves")                               \
    X(A, STATIC_CLUSTER, "static_cluster", "super-surface clustering of a scene (static LODs)")    \
    X(A, STATIC_BUILD, "static_build", "static LOD builds of one super-surface")                   \
    X(A, STATIC_RETIRE, "static_retire", "freeing a retired set of static LODs")                   \
    X(A, STATIC_PROXY, "static_proxy", "cluster proxy builds (HLOD)")                              \
    X(A, COMPILE, "compile", "node scenes' compile tasks")                                         \
    X(A, FRAME_STAGE, "frame_stage", "chunks of a frame's tessellation taken by workers")
enum {
#define SW_RT__POOL_KIND_ENUM(a, id, name, what) SW_RT_POOL_KIND_##id,
    SW_RT_POOL_KINDS(SW_RT__POOL_KIND_ENUM, ~)
#undef SW_RT__POOL_KIND_ENUM
        SW_RT_POOL_KIND_COUNT
};
/* A profile pool kind's name ("hierarchy", ...); "?" out of range. */
const char *sw_rt_pool_kind_name(int kind);

#define SW_RT__POOL_MS_COLUMN(X, id, name, what)                                                   \
    X(POOL_##id##_MS, "pool_" name "_ms", POOL, "pool threads' ms in " what)
#define SW_RT__POOL_TASKS_COLUMN(X, id, name, what)                                                \
    X(POOL_##id##_TASKS, "pool_" name "_tasks", COUNT, "pool tasks run: " what)

/* Every per-frame column: enum, name (CSV header and JSON key), kind, what it is. */
#define SW_RT_PROFILE_COLUMNS(X)                                                                   \
    X(FRAME, "frame", INDEX, "frame index along the path")                                         \
    X(T, "t_s", SECONDS, "path time of the frame (s)")                                             \
    X(FRAME_MS, "frame_ms", FRAME,                                                                 \
      "the submitting thread's time for the frame (sw_renderer_draw, or prepare + submit)")        \
    X(WAIT_VISIBILITY_MS, "wait_visibility_ms", STAGE,                                             \
      "waiting for the visibility thread to finish the frame")                                     \
    X(PREPARE_MS, "prepare_ms", STAGE,                                                             \
      "threaded: handing the next frame to the visibility thread (sw_renderer_prepare)")           \
    X(TRIM_MS, "trim_ms", STAGE, "trim-texture generation into the atlas")                         \
    X(DRAW_MS, "draw_ms", STAGE, "upload and draw, then waiting for the frame before")             \
    X(READBACK_MS, "readback_ms", STAGE, "glReadPixels of the frame")                              \
    X(WRITE_MS, "write_ms", STAGE, "PNG write (captured frames only)")                             \
    X(OTHER_MS, "other_ms", STAGE, "frame_ms minus the stages above")                              \
    X(VIS_MS, "vis_ms", VSTAGE, "the visibility thread's time for the frame")                      \
    X(VIS_HIERARCHY_MS, "vis_hierarchy_ms", VSTAGE,                                                \
      "of vis_ms, waiting for hierarchy builds and refinements")                                   \
    X(VIS_TESSELLATE_MS, "vis_tessellate_ms", VSTAGE,                                              \
      "of vis_ms, culling, traversal, bounds, CPU grids, requests")                                \
    X(VIS_JOIN_MS, "vis_join_ms", VSTAGE,                                                          \
      "of the tessellation, waiting at its join for chunks the pool's workers still ran")          \
    X(PATCHES, "patches", COUNT, "patches drawn (trimmed + untrimmed)")                            \
    X(PATCHES_TRIMMED, "patches_trimmed", COUNT, "patches drawn with a trim texture")              \
    X(PATCHES_CULLED, "patches_culled", COUNT, "patches culled")                                   \
    X(FACES_DRAWN, "faces_drawn", COUNT, "face occurrences drawn")                                 \
    X(FACES_CULLED, "faces_culled", COUNT, "face occurrences culled")                              \
    X(HIERARCHY_NODES, "hierarchy_nodes", COUNT, "hierarchy nodes drawn")                          \
    X(REFINE_ROUNDS, "refine_rounds", COUNT, "refinement rounds waited for")                       \
    X(TRIANGLES, "triangles", COUNT, "triangles drawn (fat borders included)")                     \
    X(BORDER_TRIANGLES, "border_triangles", COUNT, "of those, the fat borders' (crack filling)")   \
    X(BORDER_LOOPS_KEPT, "border_loops_kept", COUNT, "fat-border loops from kept samples")         \
    X(BORDER_LOOPS_MADE, "border_loops_made", COUNT, "fat-border loops sampled and kept")          \
    X(BORDER_QUADS_AWAY, "border_quads_away", COUNT, "fat-border quads left out, facing away")     \
    X(TRIM_TEXTURES, "trim_textures", COUNT, "trim textures used")                                 \
    X(TRIM_TEXELS, "trim_texels", COUNT, "texels of those trim textures")                          \
    X(TRIM_REUSED, "trim_reused", COUNT, "trim textures kept from earlier frames")                 \
    X(TRIM_EXACT, "trim_exact", COUNT, "trimmed draws cut by exact edges, not a texture")          \
    X(ATLAS_PAGES, "atlas_pages", COUNT, "trim-atlas pages after the frame")                       \
    X(FALLBACK_DRAWS, "fallback_draws", COUNT, "walkthrough: drawn coarser than asked, queued")    \
    X(POOL_WAITS, "pool_waits", COUNT, "times the frame waited for the worker pool")               \
    X(GPU_MS, "gpu_ms", GPU, "GPU time of the frame before's trim + draw (GL timer queries)")      \
    X(STATIC_DRAWN, "static_drawn", COUNT, "super-surface instances drawn from static LODs")       \
    X(STATIC_FACES, "static_faces", COUNT, "face instances they cover (of faces_drawn)")           \
    X(STATIC_TRIANGLES, "static_triangles", COUNT, "their triangles (of triangles)")               \
    X(STATIC_REQUESTS, "static_requests", COUNT, "walkthrough: static LOD builds queued")          \
    X(PROXIES_DRAWN, "proxies_drawn", COUNT, "cluster proxies drawn (HLOD across objects)")        \
    X(PROXY_INSTANCES, "proxy_instances", COUNT, "super-surface instances they stand for")         \
    X(PROXY_TRIANGLES, "proxy_triangles", COUNT, "their triangles (of triangles)")                 \
    X(BOUND_EXCEEDED, "bound_exceeded", COUNT,                                                     \
      "pieces drawn whose error bound exceeds the screen-space error (capped grids, floors)")      \
    X(BOUND_EXCESS_PX, "bound_excess_px", PIXELS,                                                  \
      "the worst known bound over the screen-space error, in pixels")                              \
    X(BUDGET_COARSENED, "budget_coarsened", COUNT,                                                 \
      "pieces drawn coarser because a share of the memory budget is spent (of bound_exceeded)")    \
    X(OCCLUSION_TESTS, "occlusion_tests", COUNT,                                                   \
      "--occlusion: boxes tested against the occlusion map")                                       \
    X(NODES_OCCLUDED, "nodes_occluded", COUNT, "--occlusion: hierarchy (BVH) nodes found hidden")  \
    X(FACES_OCCLUDED, "faces_occluded", COUNT,                                                     \
      "--occlusion: face occurrences culled as hidden (of faces_culled)")                          \
    X(RESIDENT_TRIANGLES, "resident_triangles", COUNT,                                             \
      "of triangles: drawn from GPU buffers kept between frames (static levels, patch grids)")     \
    X(GRID_HITS, "grid_hits", COUNT, "patch grids drawn from those kept on the GPU")               \
    X(GRID_MISSES, "grid_misses", COUNT, "patch grids evaluated into the kept ones this frame")    \
    X(UPLOAD_BYTES, "upload_bytes", COUNT,                                                         \
      "bytes sent to the GPU for the draw (vertices, indices, patch data, new resident levels)")   \
    SW_RT_POOL_KINDS(SW_RT__POOL_MS_COLUMN, X)                                                     \
    SW_RT_POOL_KINDS(SW_RT__POOL_TASKS_COLUMN, X)                                                  \
    X(POOL_QUEUED, "pool_queued", COUNT,                                                           \
      "pool tasks waiting at the frame's end (injection queues and workers' deques)")              \
    X(POOL_INJECT_PEAK, "pool_inject_peak", COUNT,                                                 \
      "longest the pool's injection queue grew during the frame (requests from other threads)")    \
    X(RESIDENT_BYTES, "resident_bytes", COUNT,                                                     \
      "resident memory after the frame (/proc/self/statm)")                                        \
    X(CAPTURED, "captured", INDEX, "1 if the frame was written as PNG")

typedef enum sw_rt_prof_col {
#define SW_RT__COL_ENUM(id, name, kind, what) SW_RT_COL_##id,
    SW_RT_PROFILE_COLUMNS(SW_RT__COL_ENUM)
#undef SW_RT__COL_ENUM
        SW_RT_COL_COUNT
} sw_rt_prof_col;

typedef enum sw_rt_prof_kind {
    SW_RT_KIND_INDEX,
    SW_RT_KIND_SECONDS,
    SW_RT_KIND_FRAME,
    SW_RT_KIND_STAGE,  /* on the submitting thread: the stages add up to frame_ms */
    SW_RT_KIND_VSTAGE, /* on the visibility thread (threaded runs): beside frame_ms, not in it */
    SW_RT_KIND_GPU,    /* ms on the GPU (timer queries): overlaps the submitting thread's stages */
    SW_RT_KIND_POOL,   /* ms in pool tasks, summed over the pool's threads: beside frame_ms */
    SW_RT_KIND_PIXELS, /* a screen-space distance */
    SW_RT_KIND_COUNT
} sw_rt_prof_kind;

const char *sw_rt_prof_col_name(sw_rt_prof_col col);
const char *sw_rt_prof_col_what(sw_rt_prof_col col);
sw_rt_prof_kind sw_rt_prof_col_kind(sw_rt_prof_col col);

typedef struct sw_rt_prof_row {
    double v[SW_RT_COL_COUNT];
} sw_rt_prof_row;

/* What the run was; strings are borrowed and must outlive the profile. */
typedef struct sw_rt_prof_meta {
    const char *scene, *path, *renderer, *mode, *eval, *lp_num_threads; /* lp: NULL = unset */
    int32_t width, height;
    double error_px;
    uint32_t worker_threads; /* the pool's size (the default resolved) */
    int sequential;
    double wall_s; /* the whole run, frames only */
} sw_rt_prof_meta;

typedef struct sw_rt_prof_stat {
    double median, p90, p99, max, mean;
} sw_rt_prof_stat;

typedef struct sw_rt_profile {
    sw_rt_prof_meta meta;
    sw_rt_prof_row *rows;
    uint32_t n_rows, cap_rows;
    uint32_t captures[3]; /* frame indices written as PNG */
    uint32_t n_captures;
    sw_rt_prof_stat summary[SW_RT_COL_COUNT]; /* after sw_rt_profile_summarize */
} sw_rt_profile;

/* A frame's row from the renderer's stats, the submitting thread's wall time for it, the part of
 * that time it spent preparing the next frame (threaded; 0 otherwise) and resident memory; OTHER_MS
 * is frame_ms minus the measured stages. Every frame is prepared on the visibility thread: its
 * hierarchy and tessellate times are in the VIS_ columns. */
void sw_rt_profile_row(const sw_frame_stats *st, uint32_t index, double t, double frame_ms,
                       double prepare_ms, double resident_bytes, int captured, sw_rt_prof_row *out);
/* The pool columns of a row: per kind, `now` minus `before` (two samples of the pool's
 * statistics, at the end of the previous frame and of this one; zeros before the pool exists),
 * the tasks queued at this frame's end (sw_th_pool_queued) and the injection queue's peak
 * during it (sw_th_pool_inject_peak_take). */
void sw_rt_profile_row_pool(const sw_th_pool_stats *before, const sw_th_pool_stats *now,
                            int64_t queued, int64_t inject_peak, sw_rt_prof_row *row);
/* Appends a row. Returns 0, or -1 when out of memory. */
int sw_rt_profile_push(sw_rt_profile *p, const sw_rt_prof_row *row);
void sw_rt_profile_free(sw_rt_profile *p);

/* Percentiles by linear interpolation between the closest ranks (numpy's default), over every
 * frame. Returns 0, or -1 when out of memory. */
int sw_rt_profile_summarize(sw_rt_profile *p);

/* The files; each returns 0, or -1 on a write error (ferror). `svg` is frametime.svg's text,
 * inlined into the HTML. The PNG file of capture i is sw_rt_profile_capture_name(). */
int sw_rt_profile_write_csv(FILE *f, const sw_rt_profile *p);
int sw_rt_profile_write_json(FILE *f, const sw_rt_profile *p);
int sw_rt_profile_write_svg(FILE *f, const sw_rt_profile *p);
int sw_rt_profile_write_html(FILE *f, const sw_rt_profile *p, const char *svg);
/* The summary table on stdout-like streams. */
void sw_rt_profile_print_summary(FILE *f, const sw_rt_profile *p);
/* "frame-0042.png" into buf. */
void sw_rt_profile_capture_name(uint32_t frame, char *buf, size_t size);

#endif
