/* SPDX-License-Identifier: MIT */
/* tests/support: a worker pool and a bicubic-hierarchy cache for a scene behind one opaque handle,
 * so that C++ tests (which cannot include the C11-atomics headers of threads/) can render through
 * the hierarchy traversal (sw_gpu_frame_desc.hierarchies). */
#ifndef SW_TEST_HIERARCHY_SUPPORT_H
#define SW_TEST_HIERARCHY_SUPPORT_H

#include "sw_sg_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

struct sw_lod_cache;
struct sw_lod_static_set;
typedef struct sw_test_hierarchies sw_test_hierarchies;

/* A pool of the default worker count and a cache of `scene` on it; NULL (message on stderr) on
 * failure. The scene must outlive it. */
sw_test_hierarchies *sw_test_hierarchies_create(const sw_sg_scene *scene);
/* The cache, for sw_gpu_frame_desc.hierarchies. */
struct sw_lod_cache *sw_test_hierarchies_cache(sw_test_hierarchies *h);
/* The scene's static LODs on the same pool (lod/static/sw_lod_static_set.h), made on the first
 * call; NULL (message on stderr) when the clustering fails. */
struct sw_lod_static_set *sw_test_hierarchies_statics(sw_test_hierarchies *h);
void sw_test_hierarchies_free(sw_test_hierarchies *h); /* NULL allowed */

#ifdef __cplusplus
}
#endif
#endif
