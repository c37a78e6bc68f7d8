/* SPDX-License-Identifier: MIT */
/* The import module's entry point: OCCT's importer (modules/import/import_occt.cpp) installed into
 * the core (sw_sg_import.h). */
#include "sw_sg_import.h"

#include <splinewalk/sw_import.h>

static const sw_sg_importer k_occt = {sw_sg_import_file, sw_sg_import_into};

sw_result sw_import_install(void)
{
    sw_sg_importer_install(&k_occt);
    return SW_OK;
}
