/* SPDX-License-Identifier: MIT */
/* bench/peers: splinewalk as a peer — the public API (runtime/include/splinewalk/splinewalk.h),
 * threaded (sw_renderer_prepare of frame i + 1 on the renderer's visibility thread while
 * sw_renderer_submit draws frame i, as bench/pipeline), walkthrough mode, default renderer (one
 * pool worker per processor, hierarchies). No readback: a frame's time is prepare(i + 1) +
 * submit(i), which fences frame i and waits for frame i - 1 to complete.
 */
#ifndef BP_PEER_SPLINEWALK_H
#define BP_PEER_SPLINEWALK_H

#include "bench_peer.h"

/* bp_peer_fn. With job->path NULL the orbit (or, job->fly, the fly-through) of the scene's box is
 * made here, after the load
 * (bench_scaling: the same relative path for every scene). */
int bp_peer_splinewalk(const bp_job *job, bp_result *out);

#endif
