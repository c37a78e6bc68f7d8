/* SPDX-License-Identifier: MIT */
/* bench/peers: the splinewalk peer (see peer_splinewalk.h). */
#include "peer_splinewalk.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct sw_run {
    bp_job job; /* a copy whose path may be the one made here */
    sw_scene scene;
    sw_renderer renderer;
    sw_status st;
} sw_run;

static sw_frame_desc frame_at(const sw_run *r, uint32_t i, int converged)
{
    sw_frame_desc f;
    memset(&f, 0, sizeof f);
    f.scene = r->scene;
    f.width = r->job.width;
    f.height = r->job.height;
    f.error_px = r->job.error_px;
    f.walkthrough = !converged;
    f.static_lods = r->job.static_lods;
    f.no_proxies = r->job.no_proxies;
    f.occlusion_culling = r->job.occlusion;
    f.trim_edges = r->job.exact_edges;
    f.no_kept_grids = !r->job.kept_grids;
    bp_frame_camera(&r->job, i, &f.camera);
    return f;
}

/* Per-frame figures of a pass, one entry per frame in each array: frame time, triangles,
 * fat-border triangles and the frame's end (bench_now_ms). */
typedef struct pass_out {
    double *ms, *tri, *border, *end;
} pass_out;

/* One pass along the path, converged (every frame waits for the hierarchies and static levels it
 * asks for) or walkthrough; frame i's figures into o (NULL: none). The first frame's end time goes
 * to *t_first when not NULL. */
static int pass(sw_run *r, int converged, const pass_out *o, double *t_first)
{
    /* the first image of all is a walkthrough frame: time to first frame is what a user waits */
    sw_frame_desc f = frame_at(r, 0, converged && !t_first);
    if (sw_renderer_prepare(r->renderer, &f, &r->st) != SW_OK)
        return -1;
    for (uint32_t i = 0; i < r->job.frames; ++i) {
        sw_frame_stats fs;
        double t0 = bench_now_ms();
        if (i + 1 < r->job.frames) {
            f = frame_at(r, i + 1, converged);
            if (sw_renderer_prepare(r->renderer, &f, &r->st) != SW_OK)
                return -1;
        }
        if (sw_renderer_submit(r->renderer, &fs, &r->st) != SW_OK)
            return -1;
        double t1 = bench_now_ms();
        if (i == 0 && t_first)
            *t_first = t1;
        if (o) {
            o->ms[i] = t1 - t0;
            o->tri[i] = (double)fs.triangles;
            o->border[i] = (double)fs.border_triangles;
            o->end[i] = t1;
        }
    }
    return 0;
}

/* The end of the first bp_settle_window consecutive frames whose median is within target, from
 * t_start; -1 when none is. */
static double settle_time(const double *ms, const double *end, uint32_t n, double target,
                          double t_start)
{
    for (uint32_t i = bp_settle_window; i <= n; ++i) {
        double median, p99;
        if (bp_summarize(ms + i - bp_settle_window, bp_settle_window, &median, &p99) != 0)
            return -1.0;
        if (median <= target)
            return end[i - 1] - t_start;
    }
    return -1.0;
}

static int load(sw_run *r, sw_rt_camera_path *own_path, bp_result *out)
{
    sw_scene_load_desc ld = {r->job.scene, NULL, NULL, NULL, NULL, 0};
    sw_scene_info info;
    if (sw_scene_load(&ld, &r->scene, &r->st) != SW_OK ||
        sw_scene_get_info(r->scene, &info, &r->st) != SW_OK)
        return -1;
    out->scene_bytes = (double)info.memory_bytes;
    out->faces = info.face_occurrences;
    if (!r->job.path) {
        for (int k = 0; k < 3; ++k) {
            r->job.scene_box[k] = info.bbox_min[k];
            r->job.scene_box[3 + k] = info.bbox_max[k];
        }
        const double *box = r->job.scene_box;
        sw_result pr = r->job.fly == 2
                           ? sw_rt_path_walk(box, 160.0, 10.0, r->job.frames, own_path, &r->st)
                       : r->job.fly ? sw_rt_path_fly(box, 10.0, r->job.frames, own_path, &r->st)
                                    : sw_rt_path_orbit(box, 10.0, r->job.frames, own_path, &r->st);
        if (pr != SW_OK)
            return -1;
        r->job.path = own_path;
    }
    memcpy(out->box, r->job.scene_box, sizeof out->box);
    return 0;
}

static int measure(sw_run *r, double t_start, bp_result *out)
{
    uint32_t n = r->job.frames * r->job.passes;
    double *ms = calloc(n, sizeof *ms), *tri = calloc(n, sizeof *tri);
    double *border = calloc(n, sizeof *border), *end = calloc(n, sizeof *end);
    double t_first = 0.0;
    int rc = ms && tri && border && end ? 0 : -1;
    if (rc == 0 && sw_renderer_create(NULL, &r->renderer, &r->st) != SW_OK)
        rc = -1;
    /* Warm-up passes (the first frame among them) are converged: every hierarchy and static
     * level the path needs is built before the timed passes, as OCCT's mesh is before its first
     * frame (a walkthrough's first frames never wait for them: they are built in the pool behind
     * them, and on two cores they slow those frames down). Their time is reported. GLU and OCCT
     * get the same passes. */
    const double t_warm = bench_now_ms();
    for (uint32_t w = 0; rc == 0 && w < r->job.warmup_passes; ++w)
        rc = pass(r, 1, NULL, w == 0 ? &t_first : NULL);
    const double warm_ms = bench_now_ms() - t_warm;
    for (uint32_t p = 0; rc == 0 && p < r->job.passes; ++p) {
        const size_t at = (size_t)p * r->job.frames;
        const pass_out o = {ms + at, tri + at, border + at, end + at};
        rc = pass(r, 0, &o, r->job.warmup_passes == 0 && p == 0 ? &t_first : NULL);
    }
    if (rc == 0) {
        double tri_p99, border_median, border_p99;
        out->frames = n;
        out->first_frame_ms = t_first - t_start;
        out->settle_ms = r->job.settle_target_ms > 0.0
                             ? settle_time(ms, end, n, r->job.settle_target_ms, t_start)
                             : -1.0;
        rc = bp_summarize(ms, n, &out->median_ms, &out->p99_ms) == 0 &&
                     bp_summarize(tri, n, &out->triangles, &tri_p99) == 0 &&
                     bp_summarize(border, n, &border_median, &border_p99) == 0
                 ? 0
                 : -1;
        /* a resident mesh has no crack filling: say how much of the count it is */
        snprintf(out->note, sizeof out->note,
                 "%s; of its triangles %.0f are fat borders (median); warm-up %.1f s (converged: "
                 "the hierarchies and static levels the path needs built)",
                 sw_renderer_description_ptr(r->renderer), border_median, 1e-3 * warm_ms);
    } else if (r->st.message[0]) {
        snprintf(out->note, sizeof out->note, "%s", r->st.message);
    } else {
        snprintf(out->note, sizeof out->note, "out of memory");
    }
    free(ms);
    free(tri);
    free(border);
    free(end);
    return rc;
}

int bp_peer_splinewalk(const bp_job *job, bp_result *out)
{
    double t_start = bench_now_ms();
    sw_run r;
    memset(&r, 0, sizeof r);
    r.job = *job;
    sw_rt_camera_path own_path;
    memset(&own_path, 0, sizeof own_path);
    int rc = load(&r, &own_path, out);
    if (rc != 0)
        snprintf(out->note, sizeof out->note, "%s", r.st.message);
    else
        rc = measure(&r, t_start, out);
    if (r.renderer.id)
        sw_renderer_destroy(r.renderer);
    if (r.scene.id)
        sw_scene_destroy(r.scene);
    sw_rt_path_free(&own_path);
    return rc;
}
