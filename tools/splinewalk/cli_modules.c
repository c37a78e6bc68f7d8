/* SPDX-License-Identifier: MIT */
/* The tool installs the modules its build links (statically, in-tree; runtime/CMakeLists.txt
 * defines SW_CLI_<MODULE> for each). Without one, the core refuses what needs it and says which
 * module that is. */
#include "cli.h"

#if SW_CLI_IMPORT
#include <splinewalk/sw_import.h>
#endif
#if SW_CLI_IMAGE
#include <splinewalk/sw_image.h>
#endif
#if SW_CLI_LOD_BUILD
#include <splinewalk/sw_lod_build.h>
#endif
#if SW_CLI_TEXT
#include <splinewalk/sw_text.h>
#endif

void sw_cli_install_modules(void)
{
#if SW_CLI_IMPORT
    (void)sw_import_install();
#endif
#if SW_CLI_IMAGE
    (void)sw_image_install();
#endif
#if SW_CLI_LOD_BUILD
    (void)sw_lod_build_install();
#endif
#if SW_CLI_TEXT
    (void)sw_text_install();
#endif
}
