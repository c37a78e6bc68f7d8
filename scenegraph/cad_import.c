/* SPDX-License-Identifier: MIT */
/* The importer the import module installs (sw_sg_import.h): the core reads STEP, IGES and BREP
 * files through it and never links OpenCASCADE itself. */
#include "sw_sg_import.h"
#include "sw_status_util.h"

#include <stdatomic.h>

static _Atomic(const sw_sg_importer *) g_importer;

void sw_sg_importer_install(const sw_sg_importer *importer)
{
    atomic_store_explicit(&g_importer, importer, memory_order_release);
}

static const sw_sg_importer *installed(const char *path, sw_status *status)
{
    const sw_sg_importer *im = atomic_load_explicit(&g_importer, memory_order_acquire);
    if (!im)
        sw__fail(status, SW_ERR_UNSUPPORTED,
                 "%s: reading STEP, IGES and BREP files needs the import module "
                 "(libsplinewalk_import: call sw_import_install), which this program has not "
                 "installed; `splinewalk import` converts such a file to .sws",
                 path ? path : "(null)");
    return im;
}

sw_result sw_sg_cad_import_file(const sw_sg_import_desc *desc, sw_sg_scene **out,
                                sw_sg_import_report *report, sw_status *status)
{
    const sw_sg_importer *im = installed(desc->path, status);
    return im ? im->import_file(desc, out, report, status) : SW_ERR_UNSUPPORTED;
}

sw_result sw_sg_cad_import_into(sw_sg_builder *b, uint32_t parent, const double xform[12],
                                const sw_sg_import_desc *desc, sw_sg_import_report *report,
                                sw_status *status)
{
    const sw_sg_importer *im = installed(desc->path, status);
    return im ? im->import_into(b, parent, xform, desc, report, status) : SW_ERR_UNSUPPORTED;
}
