/* SPDX-License-Identifier: MIT */
/* The renderer's visibility thread V (Kumar et al. 1997 §5.2, ARCHITECTURE.md "runtime/"): it
 * prepares frames — culling, hierarchy selection, densities and grids, sw_gpu_frame_prepare —
 * while the renderer's owner thread, the submission thread P, draws the frame before. Two
 * activity lists (threads/sw_th_activity.h) connect them: P → V carries the frame jobs, V → P
 * the prepared jobs, each followed by its frame's end marker.
 *
 * Kumar streams a frame's visible nodes to P one by one so that P starts pushing triangles
 * before V ends; here V hands over a whole frame, because P's first step needs all of it: the
 * trim-texture atlas (Guthe et al. 2005 §4.4) packs every trim texture of the frame into pages
 * and renders each page in one pass, before any patch is drawn. The overlap is between frames.
 * The pool T keeps working beside both (hierarchy builds and refinements).
 */
#include "sw_rt_pipeline.h"
#include "sw_hooks.h"

#include "sw_status_util.h"

#include <stdalign.h>
#include <stdlib.h>
#include <string.h>

enum { QUEUE_SLOTS = 16 }; /* > 2 jobs + 2 markers each in flight: a push never waits */

struct sw_rt_pipeline {
    sw_gpu_context *gpu;
    sw_th_spsc jobs, done; /* P → V, V → P */
    pthread_t thread;
    int started;
};

static void prepare_job(sw_rt_pipeline *p, sw_rt_frame_job *job)
{
    sw_gpu_frame_plan_recycle(p->gpu, job->spent);
    job->spent = NULL;
    const uint64_t w0 = sw_th_thread_waits().waits; /* V's blocking on the pool: the frame's */
    job->result = sw_gpu_frame_prepare(p->gpu, job->sg, &job->desc, &job->plan, &job->status);
    job->ms_visibility = job->plan ? sw_gpu_frame_plan_ms(job->plan) : 0.0;
    job->pool_waits = sw_th_thread_waits().waits - w0;
}

/* V's loop: a job, then its frame's marker; the marker of frame 0 means stop. */
static void *visibility_thread(void *arg)
{
    sw_rt_pipeline *p = arg;
    for (;;) {
        void *item = NULL;
        uint64_t frame = 0;
        if (sw_th_spsc_pop_wait_consumer(&p->jobs, &item, &frame) == SW_TH_ACT_FRAME_DONE) {
            if (frame == 0)
                return NULL;
            continue;
        }
        sw_rt_frame_job *job = item;
        prepare_job(p, job);
        sw_th_spsc_push_producer(&p->done, job);
        sw_th_spsc_end_frame_producer(&p->done, job->frame);
    }
}

sw_result sw_rt_pipeline_start(sw_gpu_context *gpu, sw_rt_pipeline **out, sw_status *status)
{
    *out = NULL;
    /* Over-aligned (its queues' indices have cache lines of their own): not malloc's alignment. */
    sw_rt_pipeline *p = sw__aligned_alloc(alignof(sw_rt_pipeline), sizeof *p);
    if (!p)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "visibility thread: out of memory");
    memset(p, 0, sizeof *p);
    p->gpu = gpu;
    if (sw_th_spsc_init(&p->jobs, QUEUE_SLOTS) != SW_OK ||
        sw_th_spsc_init(&p->done, QUEUE_SLOTS) != SW_OK) {
        sw_rt_pipeline_stop(p);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "visibility thread: out of memory");
    }
    if (pthread_create(&p->thread, NULL, visibility_thread, p) != 0) {
        sw_rt_pipeline_stop(p);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "visibility thread: could not start");
    }
    p->started = 1;
    *out = p;
    return SW_OK;
}

void sw_rt_pipeline_push(sw_rt_pipeline *p, sw_rt_frame_job *job)
{
    sw_th_spsc_push_producer(&p->jobs, job);
    sw_th_spsc_end_frame_producer(&p->jobs, job->frame);
}

sw_rt_frame_job *sw_rt_pipeline_pop(sw_rt_pipeline *p)
{
    void *item = NULL;
    uint64_t frame = 0;
    while (sw_th_spsc_pop_wait_consumer(&p->done, &item, &frame) != SW_TH_ACT_ITEM) {
    }
    sw_rt_frame_job *job = item;
    /* Its marker follows at once (V pushes both before it takes the next job). */
    while (sw_th_spsc_pop_wait_consumer(&p->done, &item, &frame) != SW_TH_ACT_FRAME_DONE) {
    }
    return job;
}

void sw_rt_pipeline_stop(sw_rt_pipeline *p)
{
    if (!p)
        return;
    if (p->started) {
        sw_th_spsc_end_frame_producer(&p->jobs, 0);
        pthread_join(p->thread, NULL);
    }
    sw_th_spsc_destroy(&p->jobs);
    sw_th_spsc_destroy(&p->done);
    sw__aligned_free(p);
}
