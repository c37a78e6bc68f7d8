/* SPDX-License-Identifier: MIT */
/* bench/peers and bench/scaling: what every peer of a side-by-side run shares — a
 * result record, running one peer in its own child process (fork) so that its peak resident
 * memory is its own (VmHWM of the child minus the resident memory it inherited at the fork), the
 * frame-time summary (median, p99: bench/common's bench_quantile), the camera of
 * frame i along a path and the matrices splinewalk's frame uses for it (gpu/camera.c). Nothing
 * here touches GL: the parent of the children never creates a context (EGL after fork is not
 * safe), each child creates its own.
 */
#ifndef BP_BENCH_PEER_H
#define BP_BENCH_PEER_H

#include <splinewalk/splinewalk.h>

#include "sw_camera_path.h"
#include "sw_gpu_internal.h"
#include "bench_stats.h"

#include <stddef.h>
#include <stdint.h>

/* One run along one path (all times in ms). Plain data: it crosses the child's pipe. */
typedef struct bp_result {
    int ok;                   /* 1: the peer ran; else `note` says why not */
    uint32_t frames;          /* frames measured (warm-up passes excluded) */
    double median_ms, p99_ms; /* frame time: the interval between completions */
    double first_frame_ms;    /* load + preprocessing + the first frame, from the child's start */
    double settle_ms; /* with bp_job.settle_target_ms: from the child's start to the end of the
                         first bp_settle_window frames whose median is within the target; -1
                         when none is */
    double peak_rss_bytes;    /* child's VmHWM minus its VmRSS at the fork */
    double triangles;         /* per frame, median over the measured frames */
    double scene_bytes;       /* splinewalk: sw_scene_info.memory_bytes; else 0 */
    uint64_t faces, refused_faces, refused_occurrences; /* GLU: faces it reported an error for */
    uint64_t gl_errors;     /* GLU: GL errors its fixed-function calls raised (drained) */
    uint32_t crashed_faces; /* GLU: of refused_faces, those that crashed it when screened */
    double screen_ms;       /* GLU: the screening of every face (not in first_frame_ms) */
    double param;           /* OCCT: deflection used (object units); else 0 */
    double box[6];          /* bp_probe_scene: the scene's world box */
    double wall_ms;         /* the parent's: the peer's process from fork to exit */
    double covered_px;      /* glu, occt: pixels drawn in the last frame (same shape?) */
    char note[640];
} bp_result;

/* What a peer is given: scene, path, frame size, ε_img and the passes. */
typedef struct bp_job {
    const char *scene;             /* what sw_scene_load reads (.sws, .brep, .step, .iges) */
    const char *brep;              /* OCCT: the same geometry as BREP (NULL: none) */
    const sw_rt_camera_path *path; /* NULL: a stock path of the scene's box made in the child */
    int fly; /* with path NULL: 0 = orbit (sw_rt_path_orbit), 1 = fly-through (sw_rt_path_fly),
                2 = walk at eye height 160 (sw_rt_path_walk: a generated building's rooms) */
    int static_lods; /* splinewalk: sw_frame_desc.static_lods (Kumar et al. 1997 static LODs) */
    int no_proxies;  /* splinewalk: sw_frame_desc.no_proxies (no cluster proxies) */
    int occlusion;   /* splinewalk: sw_frame_desc.occlusion_culling */
    int exact_edges; /* splinewalk: sw_frame_desc.trim_edges */
    int kept_grids;  /* splinewalk: !sw_frame_desc.no_kept_grids */
    uint32_t frames, warmup_passes, passes;
    int32_t width, height;
    double error_px;
    double scene_box[6]; /* world box (min xyz, max xyz) of the scene (peers' matrices, OCCT) */
    double settle_target_ms; /* splinewalk: > 0 measures bp_result.settle_ms against it */
} bp_job;

/* Frames whose median frame time says a walk has settled (bp_result.settle_ms). */
enum { bp_settle_window = 10 };

typedef int (*bp_peer_fn)(const bp_job *job, bp_result *out);

/* Runs fn(job, out) in a child process and fills *out from it (peak_rss_bytes measured there).
 * Returns 0, or -1 when the child could not run or died (out->note says how). */
int bp_run_in_child(bp_peer_fn fn, const bp_job *job, bp_result *out);

/* Median and p99 of ms[0..n) (n >= 1; not reordered) by bench_quantile. Returns 0 or -1 (memory).
 */
int bp_summarize(const double *ms, uint32_t n, double *median, double *p99);
/* The camera of frame i of job->frames along the path, fovy 0 resolved to 40 as the renderer does.
 */
void bp_frame_camera(const bp_job *job, uint32_t i, sw_camera *out);
/* The view splinewalk draws that frame with (near plane from the scene box, as gpu/draw.c). */
int bp_frame_view(const bp_job *job, const sw_camera *cam, sw__gpu_view *out);
/* The smallest eye-to-box distance over the job's frames (0 if an eye is inside the box). */
double bp_min_view_distance(const bp_job *job);

/* A peer function (run it with bp_run_in_child: loading in the parent would leave heap pages the
 * children inherit and reuse unseen): loads job->scene and fills out->box, faces (occurrences
 * drawn) and scene_bytes. */
int bp_probe_scene(const bp_job *job, bp_result *out);
/* Probes the scene in a child, then makes the orbit (sw_rt_path_orbit, 10 s, the stock path of
 * `splinewalk path orbit`) of its box, or loads `path_file` when not NULL; sets job->path and
 * job->scene_box. Returns 0, or -1 with the reason in err. */
int bp_job_path(bp_job *job, const char *path_file, sw_rt_camera_path *path, char *err,
                size_t err_size);

#endif
