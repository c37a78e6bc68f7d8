/* SPDX-License-Identifier: MIT */
/* The tool installs every module: it links them all (statically, in-tree). */
#include "cli.h"

#include <splinewalk/sw_image.h>
#include <splinewalk/sw_import.h>
#include <splinewalk/sw_lod_build.h>

void sw_cli_install_modules(void)
{
    (void)sw_import_install();
    (void)sw_image_install();
    (void)sw_lod_build_install();
}
