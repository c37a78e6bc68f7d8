/* SPDX-License-Identifier: MIT */
/* Writes the sample T-meshes of samples/tsplines/ (and, in the build, the copies the tests compare
 * with the checked-in files): make_tspline_samples OUTDIR.
 *
 * local_refinement.tsm: the NURBS of tspline_samples.h with one control point inserted into its
 * first row (Sederberg et al. 2004 §3): Boehm insertion of LR_NEW_KNOT into that row's curve, the
 * new vertical edge running from the row into the frame, where it ends in a T-junction.
 * t_junctions.tsm: a non-uniform bicubic grid of 8 x 8 points plus a partial knot line in s (four
 * points) and one in t (two points), both ending inside the domain in T-junctions, whose points are
 * displaced so the knot lines carry real jumps of the third derivative: a tensor-product spline
 * would need both lines across the whole domain, 9 x 9 = 81 points instead of 70.
 */
#include "tspline_samples.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Shortest of %.15g..%.17g that reads back to the same double. */
static void put_double(FILE *f, const char *sep, double x)
{
    char buf[40];
    for (int prec = 15; prec <= 17; prec++) {
        snprintf(buf, sizeof buf, "%.*g", prec, x);
        if (strtod(buf, NULL) == x)
            break;
    }
    fprintf(f, "%s%s", sep, buf);
}

static void put_knots(FILE *f, const char *kw, const double *k, int n)
{
    fprintf(f, "%s %d", kw, n);
    for (int i = 0; i < n; i++)
        put_double(f, " ", k[i]);
    fprintf(f, "\n");
}

static void put_point(FILE *f, int i, int j, const double *pw)
{
    fprintf(f, "%d %d", i, j);
    for (int c = 0; c < 4; c++)
        put_double(f, " ", c < 3 ? pw[c] / pw[3] : pw[3]);
    fprintf(f, "\n");
}

static int write_local_refinement(FILE *f)
{
    double cpw[LR_NU * LR_NV * 4], row_k[LR_NU + 5], row[(LR_NU + 1) * 4];
    lr_source_cpw(cpw);
    const sw_sg_curve first_row = {3, LR_NU, 4, lr_knots_u, cpw};
    sw_sg_curve_insert_knot(&first_row, LR_NEW_KNOT, 1, row_k, row);

    fprintf(f,
            "tsm 1\n"
            "# A rational bicubic NURBS of 6 x 5 control points, locally refined: one control\n"
            "# point inserted at s = %g into the first row only (Boehm insertion into that\n"
            "# row). Its vertical edge (column 5) runs down into the frame and ends there in a\n"
            "# T-junction; rows 3..6 do not see the new knot. Same surface as the source NURBS.\n",
            LR_NEW_KNOT);
    put_knots(f, "sknots", row_k, LR_NU + 5);
    put_knots(f, "tknots", lr_knots_v, LR_NV + 4);
    const int m = LR_NU + 5, n = LR_NV + 4, new_col = 5;
    fprintf(f, "edges %d\n", n + m);
    for (int j = 0; j < n; j++)
        fprintf(f, "h %d 0 %d\n", j, m - 1);
    for (int i = 0; i < m; i++)
        fprintf(f, "v %d 0 %d\n", i, i == new_col ? 2 : n - 1);
    fprintf(f, "points %d\n", (LR_NU + 1) + LR_NU * (LR_NV - 1));
    fprintf(f, "# the refined first row (anchors in row 2), then the untouched rows\n");
    for (int i = 0; i <= LR_NU; i++)
        put_point(f, i + 2, 2, row + i * 4);
    for (int j = 1; j < LR_NV; j++)
        for (int i = 0; i < LR_NU; i++)
            put_point(f, i + 2 + (i + 2 >= new_col), j + 2, cpw + (j * LR_NU + i) * 4);
    fprintf(f, "end\n");
    return 0;
}

static const double tj_sk[13] = {0, 0, 0, 0, 0.8, 1.7, 2.3, 3, 3.6, 5, 5, 5, 5};
static const double tj_tk[13] = {0, 0, 0, 0, 0.5, 1.4, 1.8, 2.2, 3, 4, 4, 4, 4};

static void tj_point(FILE *f, int i, int j, double bump)
{
    const double x = (tj_sk[i - 1] + tj_sk[i] + tj_sk[i + 1]) / 3.0;
    const double y = (tj_tk[j - 1] + tj_tk[j] + tj_tk[j + 1]) / 3.0;
    const double pw[4] = {x, y, 0.5 * sin(0.9 * x + 0.2) * cos(0.8 * y) + bump, 1.0};
    put_point(f, i, j, pw);
}

static int write_t_junctions(FILE *f)
{
    fprintf(f,
            "tsm 1\n"
            "# A bicubic T-spline with two partial knot lines ending in T-junctions inside the\n"
            "# domain: column 6 (s = 2.3) between rows 4 and 8, and row 6 (t = 1.8) from the\n"
            "# frame to column 3. Their T-junction extensions do not cross (analysis-suitable),\n"
            "# so the blending functions sum to one. 70 points; a NURBS with the same knot lines\n"
            "# would need them across the whole domain: 9 x 9 = 81 points.\n");
    put_knots(f, "sknots", tj_sk, 13);
    put_knots(f, "tknots", tj_tk, 13);
    fprintf(f, "edges 26\n");
    for (int j = 0; j < 13; j++)
        fprintf(f, j == 6 ? "h %d 0 3\n" : "h %d 0 12\n", j);
    for (int i = 0; i < 13; i++)
        fprintf(f, i == 6 ? "v %d 4 8\n" : "v %d 0 12\n", i);
    fprintf(f, "points 70\n");
    for (int j = 2; j <= 10; j++)
        for (int i = 2; i <= 10; i++)
            if (i != 6 && j != 6)
                tj_point(f, i, j, 0.0);
    fprintf(f, "# the partial row t = 1.8 and the partial column s = 2.3, displaced\n");
    tj_point(f, 2, 6, 0.15);
    tj_point(f, 3, 6, -0.2);
    tj_point(f, 6, 4, 0.1);
    tj_point(f, 6, 5, 0.3);
    tj_point(f, 6, 7, -0.25);
    tj_point(f, 6, 8, 0.12);
    fprintf(f, "end\n");
    return 0;
}

static int write_file(const char *dir, const char *name, int (*fn)(FILE *))
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f) {
        perror(path);
        return 1;
    }
    int r = fn(f);
    return fclose(f) != 0 || r;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: make_tspline_samples OUTDIR\n");
        return 2;
    }
    return write_file(argv[1], "local_refinement.tsm", write_local_refinement) ||
           write_file(argv[1], "t_junctions.tsm", write_t_junctions);
}
