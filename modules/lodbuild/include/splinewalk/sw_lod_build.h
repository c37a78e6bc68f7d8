/* SPDX-License-Identifier: MIT */
/* splinewalk's LOD-building module (libsplinewalk_lodbuild; pkg-config splinewalk-lodbuild;
 * CMake splinewalk::lodbuild): static LODs of super-surfaces (Kumar et al. 1997, §4) built
 * through CGAL's constrained triangulation and distance queries (GPL-3) and OpenMesh's
 * decimater (BSD-3-Clause). Without it the core draws the static LODs a .sws stores
 * (`splinewalk build-lod`) and draws every other super-surface by the per-frame path; with it,
 * missing levels are built in the renderer's worker pool as frames need them. */
#ifndef SPLINEWALK_SW_LOD_BUILD_H
#define SPLINEWALK_SW_LOD_BUILD_H

#include <splinewalk/sw_result.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Hands the builder to the core. Any thread, any number of times; builds already queued use it
 * once they run. Returns SW_OK. */
SW_MODULE_API sw_result sw_lod_build_install(void);

#ifdef __cplusplus
}
#endif
#endif
