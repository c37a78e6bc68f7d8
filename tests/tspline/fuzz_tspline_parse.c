/* SPDX-License-Identifier: MIT */
/* libFuzzer harness for .tsm loading (tspline_io.c, tspline.c, tspline_bezier.c): every input is
 * parsed and validated; a failure must come with no T-spline and a message naming the file. An
 * accepted T-spline is evaluated by all three paths (which must give finite points when its
 * coordinates are moderate: validation guarantees a positive denominator), extracted and handed
 * to a scene builder, whose own validation must accept the faces. */
#include "sw_sg_tspline.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int moderate(const sw_sg_tspline_view *v)
{
    for (size_t k = 0; k < (size_t)v->n_points * 4; k++)
        if (fabs(v->cpw[k]) > 1e100 || (k % 4 == 3 && (v->cpw[k] < 1e-100 || v->cpw[k] > 1e100)))
            return 0;
    for (size_t k = 0; k < (size_t)v->n_points * 5; k++)
        if (fabs(v->knots_u[k]) > 1e100 || fabs(v->knots_v[k]) > 1e100)
            return 0;
    return 1;
}

static void exercise(const sw_sg_tspline *ts)
{
    const sw_sg_tspline_view *v = sw_sg_tspline_view_ptr(ts);
    const int check = moderate(v);
    sw_sg_tspline_bezier bz;
    sw_status st = {0};
    if (sw_sg_tspline_extract_bezier(ts, &bz, &st) != SW_OK)
        abort(); /* creation already checked every patch weight */
    for (int k = 0; k <= 16; k++) {
        const double u = v->domain[0] + (v->domain[1] - v->domain[0]) * (k % 5) / 4.0;
        const double w = v->domain[2] + (v->domain[3] - v->domain[2]) * (k / 4 % 5) / 4.0;
        double p[3], q[3], b[3];
        sw_sg_tspline_eval_direct(ts, u, w, p);
        sw_sg_tspline_eval(ts, u, w, q);
        const sw_sg_bezier_patch *patch = &bz.patches[sw_sg_tspline_find_region(ts, u, w)];
        sw_sg_bezier_patch_eval(patch, 0.5, 0.5, b);
        if (check && !(isfinite(p[0]) && isfinite(q[0]) && isfinite(b[0])))
            abort();
    }
    sw_sg_tspline_bezier_free(&bz);
    if (v->n_regions > 4096)
        return;
    sw_sg_builder *bld = sw_sg_builder_create();
    if (!bld)
        return;
    if (sw_sg_tspline_add_to_builder(bld, ts, 0, NULL, NULL, "fuzz", NULL, &st) != SW_OK) {
        sw_sg_builder_free(bld);
        return;
    }
    sw_sg_scene *scene = NULL;
    const sw_result r = sw_sg_builder_finish(bld, &scene, &st);
    if (check && r != SW_OK)
        abort(); /* the faces of a validated T-spline are valid NURBS */
    sw_sg_scene_free(scene);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sw_sg_tspline *ts = NULL;
    sw_status st = {0};
    const sw_result r = sw_sg_tspline_load_mem((const char *)data, size, "fuzz.tsm", &ts, &st);
    if (r != SW_OK) {
        if (ts || st.result != r || (r != SW_ERR_OUT_OF_MEMORY && !strstr(st.message, "fuzz.tsm")))
            abort();
        return 0;
    }
    if (!ts)
        abort();
    exercise(ts);
    sw_sg_tspline_free(ts);
    return 0;
}
