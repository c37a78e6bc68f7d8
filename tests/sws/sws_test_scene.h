/* SPDX-License-Identifier: MIT */
/* A small scene shared by the .sws tests and the fuzz seed: three bicubic faces (one with two
 * knot spans in u, rational weights), trim loops of linear and rational quadratic curves, nested
 * transforms, two instances of a detached prototype, colours set and inherited, adjacency. */
#ifndef SWS_TEST_SCENE_H
#define SWS_TEST_SCENE_H

#include "sw_sg_scene.h"

#include <math.h>
#include <string.h>

/* Transforms of the test scene (row-major 3x4), shared with the independent reference. */
static void sws_test_xforms(double t1[12], double t2[12], double s1[12], double s2[12],
                            double i1[12], double i2[12])
{
    const double c = cos(0.5), s = sin(0.5);
    const double T1[12] = {c, -s, 0, 1, s, c, 0, 2, 0, 0, 1, 3};   /* rotate z, translate */
    const double T2[12] = {2, 0, 0, -1, 0, 2, 0, 0.5, 0, 0, 2, 0}; /* scale 2, translate */
    const double S1[12] = {1, 0, 0, 0.25, 0, 1, 0, 0, 0, 0, 1, -4};
    const double S2[12] = {0.5, 0, 0, 0, 0, 1.5, 0, 0, 0, 0, 0.75, 0};
    const double I1[12] = {1, 0, 0, 10, 0, 0, -1, 0, 0, 1, 0, -2}; /* rotate x 90 degrees */
    const double I2[12] = {1, 0, 0, 5, 0, 1, 0, 0, 0, 0, 1, 0};
    memcpy(t1, T1, sizeof T1);
    memcpy(t2, T2, sizeof T2);
    memcpy(s1, S1, sizeof S1);
    memcpy(s2, S2, sizeof S2);
    memcpy(i1, I1, sizeof I1);
    memcpy(i2, I2, sizeof I2);
}

static const float sws_red[4] = {1, 0, 0, 1}, sws_green[4] = {0, 1, 0, 1},
                   sws_blue[4] = {0, 0, 1, 0.5f};

/* A bicubic face over [0,1]^2 with n_u x 4 control points (n_u = 4 or 5), shifted by `dx`. */
static uint32_t sws_test_face(sw_sg_builder *b, uint32_t n_u, double dx, uint32_t first_loop,
                              uint32_t n_loops, uint32_t kind)
{
    static const double ku5[9] = {0, 0, 0, 0, 0.5, 1, 1, 1, 1};
    static const double ku4[8] = {0, 0, 0, 0, 1, 1, 1, 1};
    double cpw[5 * 4 * 4];
    for (uint32_t j = 0; j < 4; j++)
        for (uint32_t i = 0; i < n_u; i++) {
            double w = 1.0 + 0.25 * (double)((i + 2 * j) % 3);
            double *p = &cpw[(j * n_u + i) * 4];
            p[0] = w * (dx + i);
            p[1] = w * (double)j;
            p[2] = w * 0.3 * sin((double)(i + j));
            p[3] = w;
        }
    sw_sg_face_rec f;
    memset(&f, 0, sizeof f);
    f.deg_u = f.deg_v = 3;
    f.n_u = n_u;
    f.n_v = 4;
    f.knots_u = sw_sg_builder_push_doubles(b, n_u == 5 ? ku5 : ku4, n_u + 4);
    f.knots_v = sw_sg_builder_push_doubles(b, ku4, 8);
    f.cpw = sw_sg_builder_push_doubles(b, cpw, (size_t)n_u * 16);
    f.first_loop = first_loop;
    f.n_loops = n_loops;
    f.kind = kind;
    f.flags = n_loops ? SW_SG_FACE_TRIMMED : 0;
    f.uv_box[1] = f.uv_box[3] = 1.0;
    f.tolerance = 1e-7;
    return sw_sg_builder_add_face(b, &f);
}

static uint32_t sws_test_curve(sw_sg_builder *b, uint32_t degree, const double *cpw)
{
    static const double k1[4] = {0, 0, 1, 1}, k2[6] = {0, 0, 0, 1, 1, 1};
    sw_sg_curve_rec c = {degree, degree + 1, 0, 0};
    c.knots = sw_sg_builder_push_doubles(b, degree == 1 ? k1 : k2, 2 * (degree + 1));
    c.cpw = sw_sg_builder_push_doubles(b, cpw, 3 * (degree + 1));
    return sw_sg_builder_add_curve(b, &c);
}

/* Loop 0: the domain's square (4 lines), loop 1: a lens of two rational quadratic arcs. */
static void sws_test_loops(sw_sg_builder *b)
{
    static const double sq[5][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 0}};
    for (int k = 0; k < 4; k++) {
        double cpw[6] = {sq[k][0], sq[k][1], 1, sq[k + 1][0], sq[k + 1][1], 1};
        sws_test_curve(b, 1, cpw);
    }
    const double w = 0.7;
    double a[9] = {0.3, 0.5, 1, w * 0.5, w * 0.8, w, 0.7, 0.5, 1};
    double c[9] = {0.7, 0.5, 1, w * 0.5, w * 0.2, w, 0.3, 0.5, 1};
    sws_test_curve(b, 2, a);
    sws_test_curve(b, 2, c);
    sw_sg_loop_rec outer = {0, 4, SW_SG_LOOP_OUTER, 0}, hole = {4, 2, 0, 0};
    sw_sg_builder_add_loop(b, &outer);
    sw_sg_builder_add_loop(b, &hole);
}

/* Node tree (indices in brackets):
 *   [0] root group
 *     [1] T1 red ── [2] surface face 0 (inherits red)
 *                ── [3] T2 ── [4] surface face 1 under S1, green
 *                ── [7] instance I2 of [5] (inherits red)
 *     [6] instance I1 of [5], blue
 *   [5] prototype group (detached) ── [8] surface face 2 under S2 (inherits) */
static sw_sg_builder *sws_test_builder(void)
{
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        return NULL;
    sws_test_loops(b);
    sws_test_face(b, 5, 0.0, 0, 2, SW_SG_KIND_BSPLINE);
    sws_test_face(b, 4, 7.0, 0, 1, SW_SG_KIND_BEZIER);
    sws_test_face(b, 4, -3.0, 0, 0, SW_SG_KIND_PLANE);
    double t1[12], t2[12], s1[12], s2[12], i1[12], i2[12];
    sws_test_xforms(t1, t2, s1, s2, i1, i2);
    uint32_t n1 = sw_sg_builder_add_node(b, SW_SG_NODE_TRANSFORM, 0, SW_SG_NONE, t1, sws_red, "T1");
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, n1, 0, NULL, NULL, "face0");
    uint32_t n3 = sw_sg_builder_add_node(b, SW_SG_NODE_TRANSFORM, n1, SW_SG_NONE, t2, NULL, NULL);
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, n3, 1, s1, sws_green, "face1");
    uint32_t proto =
        sw_sg_builder_add_node(b, SW_SG_NODE_GROUP, SW_SG_NONE, SW_SG_NONE, NULL, NULL, "proto");
    sw_sg_builder_add_node(b, SW_SG_NODE_INSTANCE, 0, proto, i1, sws_blue, "I1");
    sw_sg_builder_add_node(b, SW_SG_NODE_INSTANCE, n1, proto, i2, NULL, NULL);
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, proto, 2, s2, NULL, "face2");
    sw_sg_builder_add_adjacency(b, 0, 1);
    sw_sg_builder_add_adjacency(b, 1, 2);
    return b;
}

#endif
