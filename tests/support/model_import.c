/* SPDX-License-Identifier: MIT */
#include "model_import.h"

#include "sw_sg_import.h"

#include <stdio.h>

int sw_test_import_model(const char *path, sw_sg_scene **out)
{
    sw_sg_import_desc d = {path, NULL, NULL, NULL, NULL, 0};
    sw_status st = {0};
    *out = NULL;
    sw_result r = sw_sg_import_file(&d, out, NULL, &st);
    if (r == SW_ERR_FORMAT) { /* a shape without faces */
        printf("%s: skipped (%s)\n", path, st.message);
        return 0;
    }
    if (r != SW_OK) {
        fprintf(stderr, "%s: import failed: %s\n", path, st.message);
        return -1;
    }
    return 1;
}
