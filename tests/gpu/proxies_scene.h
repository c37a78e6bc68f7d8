/* SPDX-License-Identifier: MIT */
/* tests/gpu: a scene with its static LODs read from its LOD cache and its cluster proxies built,
 * for test_gpu_proxies.cpp (C++ cannot include the static set's header: its atomics are C11). */
#ifndef SW_TESTS_PROXIES_SCENE_H
#define SW_TESTS_PROXIES_SCENE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

struct sw_sg_scene;
struct sw_lod_static_set;
typedef struct proxies_scene proxies_scene;

/* Opens `path`, adopts its LOD cache's chains (not its proxies) and starts building the proxies in
 * the pool; NULL on failure (said on stderr). */
proxies_scene *proxies_scene_open(const char *path);
/* Returns once every proxy is built. */
void proxies_scene_wait(proxies_scene *ps);
void proxies_scene_free(proxies_scene *ps); /* NULL allowed */
const struct sw_sg_scene *proxies_scene_scene(const proxies_scene *ps);
struct sw_lod_static_set *proxies_scene_statics(const proxies_scene *ps);
void proxies_scene_box(const proxies_scene *ps, double box[6]);
/* Prints the proxies' counts; returns how many have a bound that is not finite, below their
 * inputs' own error or above it by more than a cell's diagonal (what the clustering can move a
 * vertex), or an empty part (and sets *n to the proxies found, *counted to the set's
 * count of them). */
uint32_t proxies_scene_check(const proxies_scene *ps, uint32_t *n, uint64_t *counted);

#ifdef __cplusplus
}
#endif
#endif
