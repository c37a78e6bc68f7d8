/* SPDX-License-Identifier: MIT */
/* runtime/ internal: the visibility thread V of a renderer and its two activity lists
 * (pipeline.c says why frames, not nodes, go from V to the submission thread). Never installed.
 *
 * Threads: start, push, pop and stop are called by the renderer's owner thread (the submission
 * thread P) only; the jobs it pushes come back from pop in order, each prepared by V.
 */
#ifndef SW_RT_PIPELINE_H
#define SW_RT_PIPELINE_H

#include "sw_gpu.h"
#include "sw_th_activity.h"
#include "sw_th_pool.h"

#include <splinewalk/sw_result.h>

typedef struct sw_rt_frame_job {
    /* in: set by P before the push */
    uint64_t frame; /* 1, 2, ... in push order */
    const sw_sg_scene *sg;
    sw_gpu_frame_desc desc;
    void *user; /* P's own per-frame data (the scene reference, the output path) */
    /* an earlier frame's spent plan (sw_gpu_frame_submit_keep) or NULL: V frees it before it
     * prepares this job, so that P's frames do not pay for freeing plans */
    sw_gpu_frame_plan *spent;
    /* out: set by V */
    sw_gpu_frame_plan *plan; /* NULL on failure */
    sw_result result;
    sw_status status;
    double ms_visibility; /* V's time for the job */
    uint64_t pool_waits;  /* V's waits for the pool while preparing it (sw_th_thread_waits) */
    /* P's own: its waits for the pool while making the job (scene, caches) */
    uint64_t pool_waits_before;
} sw_rt_frame_job;

typedef struct sw_rt_pipeline sw_rt_pipeline;

/* Starts V for a context (prepare reads it; see sw_gpu_frame_prepare). Errors:
 * SW_ERR_OUT_OF_MEMORY (also when the thread cannot start). */
sw_result sw_rt_pipeline_start(sw_gpu_context *gpu, sw_rt_pipeline **out, sw_status *status);
/* Hands a job to V; never waits (at most a few jobs are in flight). */
void sw_rt_pipeline_push(sw_rt_pipeline *p, sw_rt_frame_job *job);
/* The oldest pushed job, once V has prepared it (sleeps until then). Only with a job in flight. */
sw_rt_frame_job *sw_rt_pipeline_pop(sw_rt_pipeline *p);
/* Stops V after the jobs in flight (their plans are left in the jobs, which P still owns: pop
 * them first) and joins it. NULL allowed. */
void sw_rt_pipeline_stop(sw_rt_pipeline *p);

#endif
