/* SPDX-License-Identifier: MIT */
/* The LOD-building module's entry point: the static-LOD builder (modules/lodbuild/static_lod.c with
 * its CGAL and OpenMesh shims) installed into the core's static sets (sw_lod_static.h). */
#include "sw_lod_static.h"

#include <splinewalk/sw_lod_build.h>

sw_result sw_lod_build_install(void)
{
    sw_lod_static_builder_install(sw_lod_static_build);
    return SW_OK;
}
