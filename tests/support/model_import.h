/* SPDX-License-Identifier: MIT */
/* tests/support: importing a sample model for a test, the same way in every test program. */
#ifndef SW_TEST_MODEL_IMPORT_H
#define SW_TEST_MODEL_IMPORT_H

#include "sw_sg_scene.h"

/* Imports `path` (anything the OCCT importer reads). Returns 1 with *out set; 0 when the file
 * holds no faces (e.g. data/occ/edge.brep: printed as skipped, *out NULL); -1 when the import
 * fails (printed on stderr, *out NULL). */
int sw_test_import_model(const char *path, sw_sg_scene **out);

#endif
