/* SPDX-License-Identifier: MIT */
/* splinewalk's import module (libsplinewalk_import; pkg-config splinewalk-import; CMake
 * splinewalk::import): STEP, IGES and BREP files read through OpenCASCADE (LGPL-2.1 with its
 * exception). The core library reads .sws and .tsm files only; with this module installed,
 * sw_scene_load also reads .step/.stp, .iges/.igs and .brep files and sw_scene_load_default builds
 * the default scene from OCCT's sample models. */
#ifndef SPLINEWALK_SW_IMPORT_H
#define SPLINEWALK_SW_IMPORT_H

#include <splinewalk/sw_result.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Hands the importer to the core. Any thread, any number of times, before or after scenes and
 * renderers exist; loads that already started are not affected. Without it those loads return
 * SW_ERR_UNSUPPORTED saying so. Returns SW_OK. */
SW_MODULE_API sw_result sw_import_install(void);

#ifdef __cplusplus
}
#endif
#endif
