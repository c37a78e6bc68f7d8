/* SPDX-License-Identifier: MIT */
/* Cluster proxies' vertex clustering (lod/static/sw_lod_proxy.h): its declared bound against the
 * two one-sided distances measured by dense sampling, with a point-to-triangle distance written
 * here (projection onto the plane, else the nearest edge; not the library's Voronoi-region one).
 *
 * Input: a tessellated sphere (part 0), a two-sided thin plate beside it (part 1), a cube far
 * smaller than the coarser cells (part 1) and a thin long box (an antenna, part 0), at five cell
 * sizes. Each side of the distance is sampled at 7 points per triangle edge (28 per triangle),
 * so the sampled distance is a lower bound of the true one: a declared bound below it is wrong.
 * Also: the output is smaller at large cells, parts never mix, vertices are grouped by part, and
 * the tiny cube, smaller than a cell, is still there.
 *
 * What it catches (each planted once): triangles whose image leaves the output dropped (the cube
 * and the antenna vanish, as plain clustering lets them: 10 failures); representatives moved off
 * their vertices' mean, outside the cell (a bound over the cell's diagonal). The declared bound is
 * the largest vertex move, 7-25x the sampled distances here (moves are mostly along the surface),
 * so a bound underestimated by less than that would pass. */
#include "sw_lod_proxy.h"
#include "test_check.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct mesh {
    double *pos;
    float *nrm;
    uint32_t *part, *tri;
    uint32_t nv, nt, cap_v, cap_t;
} mesh;

static uint32_t add_vertex(mesh *m, double x, double y, double z, double nx, double ny, double nz,
                           uint32_t part)
{
    if (m->nv == m->cap_v) {
        m->cap_v = m->cap_v ? 2 * m->cap_v : 256;
        m->pos = realloc(m->pos, 3 * (size_t)m->cap_v * sizeof *m->pos);
        m->nrm = realloc(m->nrm, 3 * (size_t)m->cap_v * sizeof *m->nrm);
        m->part = realloc(m->part, (size_t)m->cap_v * sizeof *m->part);
    }
    const double l = sqrt(nx * nx + ny * ny + nz * nz);
    m->pos[3 * m->nv] = x, m->pos[3 * m->nv + 1] = y, m->pos[3 * m->nv + 2] = z;
    m->nrm[3 * m->nv] = (float)(nx / l), m->nrm[3 * m->nv + 1] = (float)(ny / l);
    m->nrm[3 * m->nv + 2] = (float)(nz / l);
    m->part[m->nv] = part;
    return m->nv++;
}

static void add_tri(mesh *m, uint32_t a, uint32_t b, uint32_t c)
{
    if (m->nt == m->cap_t) {
        m->cap_t = m->cap_t ? 2 * m->cap_t : 256;
        m->tri = realloc(m->tri, 3 * (size_t)m->cap_t * sizeof *m->tri);
    }
    m->tri[3 * m->nt] = a, m->tri[3 * m->nt + 1] = b, m->tri[3 * m->nt + 2] = c;
    m->nt++;
}

static void add_sphere(mesh *m, const double c[3], double r, int nu, int nv, uint32_t part)
{
    const uint32_t base = m->nv;
    for (int j = 0; j <= nv; ++j)
        for (int i = 0; i < nu; ++i) {
            const double th = M_PI * j / nv, ph = 2.0 * M_PI * i / nu;
            const double n[3] = {sin(th) * cos(ph), sin(th) * sin(ph), cos(th)};
            add_vertex(m, c[0] + r * n[0], c[1] + r * n[1], c[2] + r * n[2], n[0], n[1],
                       n[2] + (j == 0 ? 1e-9 : 0.0), part);
        }
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            const uint32_t a = base + (uint32_t)(j * nu + i),
                           b = base + (uint32_t)(j * nu + (i + 1) % nu);
            const uint32_t cc = a + (uint32_t)nu, d = b + (uint32_t)nu;
            add_tri(m, a, cc, b);
            add_tri(m, b, cc, d);
        }
}

/* An axis-aligned box [lo, hi], each side two triangles with its own four vertices (so its
 * normals are the sides'). */
static void add_box(mesh *m, const double lo[3], const double hi[3], uint32_t part)
{
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            double n[3] = {0, 0, 0};
            n[axis] = side ? 1.0 : -1.0;
            uint32_t q[4];
            for (int k = 0; k < 4; ++k) {
                double p[3];
                p[axis] = side ? hi[axis] : lo[axis];
                p[u] = (k == 1 || k == 2) ? hi[u] : lo[u];
                p[v] = (k >= 2) ? hi[v] : lo[v];
                q[k] = add_vertex(m, p[0], p[1], p[2], n[0], n[1], n[2], part);
            }
            add_tri(m, q[0], q[1], q[2]);
            add_tri(m, q[0], q[2], q[3]);
        }
}

/* ---- the reference distance ------------------------------------------------------------------ */
static double seg_dist(const double p[3], const double a[3], const double b[3])
{
    double d[3], w[3], dd = 0.0, wd = 0.0;
    for (int k = 0; k < 3; ++k) {
        d[k] = b[k] - a[k];
        w[k] = p[k] - a[k];
        dd += d[k] * d[k];
        wd += w[k] * d[k];
    }
    const double t = dd > 0.0 ? fmin(fmax(wd / dd, 0.0), 1.0) : 0.0;
    double s = 0.0;
    for (int k = 0; k < 3; ++k)
        s += (p[k] - a[k] - t * d[k]) * (p[k] - a[k] - t * d[k]);
    return sqrt(s);
}

/* Projection onto the plane; inside by the signs of the three sub-areas; else the nearest edge. */
static double tri_dist(const double p[3], const double a[3], const double b[3], const double c[3])
{
    double e1[3], e2[3], n[3];
    for (int k = 0; k < 3; ++k) {
        e1[k] = b[k] - a[k];
        e2[k] = c[k] - a[k];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    const double nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    const double edges = fmin(seg_dist(p, a, b), fmin(seg_dist(p, b, c), seg_dist(p, c, a)));
    if (nn <= 0.0)
        return edges;
    const double h = ((p[0] - a[0]) * n[0] + (p[1] - a[1]) * n[1] + (p[2] - a[2]) * n[2]) / nn;
    const double q[3] = {p[0] - h * n[0], p[1] - h * n[1], p[2] - h * n[2]};
    const double *v[3] = {a, b, c};
    int inside = 1;
    for (int i = 0; i < 3; ++i) {
        const double *s = v[i], *t = v[(i + 1) % 3];
        const double x[3] = {t[0] - s[0], t[1] - s[1], t[2] - s[2]};
        const double y[3] = {q[0] - s[0], q[1] - s[1], q[2] - s[2]};
        const double cr[3] = {x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2],
                              x[0] * y[1] - x[1] * y[0]};
        if (cr[0] * n[0] + cr[1] * n[1] + cr[2] * n[2] < 0.0)
            inside = 0;
    }
    return inside ? fabs(h) * sqrt(nn) : edges;
}

/* max over samples of triangles of A of their distance to mesh B (brute force). */
static double sampled_distance(const double *apos, const uint32_t *atri, uint32_t ant,
                               const double *bpos, const uint32_t *btri, uint32_t bnt)
{
    enum { N = 6 };
    double worst = 0.0;
    for (uint32_t t = 0; t < ant; ++t) {
        const double *a = apos + 3 * (size_t)atri[3 * t], *b = apos + 3 * (size_t)atri[3 * t + 1],
                     *c = apos + 3 * (size_t)atri[3 * t + 2];
        for (int i = 0; i <= N; ++i)
            for (int j = 0; i + j <= N; ++j) {
                const double u = (double)i / N, v = (double)j / N, w = 1.0 - u - v;
                const double p[3] = {w * a[0] + u * b[0] + v * c[0], w * a[1] + u * b[1] + v * c[1],
                                     w * a[2] + u * b[2] + v * c[2]};
                double best = INFINITY;
                for (uint32_t s = 0; s < bnt && best > worst; ++s)
                    best = fmin(best, tri_dist(p, bpos + 3 * (size_t)btri[3 * s],
                                               bpos + 3 * (size_t)btri[3 * s + 1],
                                               bpos + 3 * (size_t)btri[3 * s + 2]));
                worst = fmax(worst, best);
            }
    }
    return worst;
}

static void check_cell(const mesh *m, double cell, const double origin[3], uint32_t cube_first,
                       uint32_t cube_n)
{
    const sw_lod_proxy_input in = {m->pos, m->nrm, m->part, m->nv, 2, m->tri, m->nt};
    sw_lod_proxy_mesh out;
    sw_status st = {0};
    if (sw_lod_proxy_cluster(&in, cell, origin, &out, &st) != SW_OK) {
        CHECK(0, "cell %g: %s", cell, st.message);
        return;
    }
    const double to_out =
        sampled_distance(m->pos, m->tri, m->nt, out.pos, out.tri, out.n_triangles);
    const double to_in = sampled_distance(out.pos, out.tri, out.n_triangles, m->pos, m->tri, m->nt);
    const double slack = 1e-12;
    CHECK(to_out <= out.bound + slack && to_in <= out.bound + slack,
          "cell %g: sampled distances input->output %.6g, output->input %.6g, declared %.6g", cell,
          to_out, to_in, out.bound);
    CHECK(out.bound <= sqrt(3.0) * cell, "cell %g: bound %.6g over a cell's diagonal", cell,
          out.bound);
    int grouped = 1, mixed = 0;
    for (uint32_t v = 1; v < out.n_vertices; ++v)
        grouped &= out.part[v - 1] <= out.part[v];
    for (uint32_t t = 0; t < out.n_triangles; ++t)
        mixed += out.part[out.tri[3 * t]] != out.part[out.tri[3 * t + 1]] ||
                 out.part[out.tri[3 * t]] != out.part[out.tri[3 * t + 2]];
    CHECK(grouped && !mixed, "cell %g: vertices grouped by part %d, triangles mixing parts %d",
          cell, grouped, mixed);
    /* the cube (its own 24 vertices) is still covered: every corner has an output point near */
    double cube_gap = 0.0;
    for (uint32_t v = cube_first; v < cube_first + cube_n; ++v) {
        double best = INFINITY;
        for (uint32_t t = 0; t < out.n_triangles; ++t)
            best = fmin(best, tri_dist(m->pos + 3 * (size_t)v, out.pos + 3 * (size_t)out.tri[3 * t],
                                       out.pos + 3 * (size_t)out.tri[3 * t + 1],
                                       out.pos + 3 * (size_t)out.tri[3 * t + 2]));
        cube_gap = fmax(cube_gap, best);
    }
    CHECK(cube_gap <= out.bound + slack,
          "cell %g: the small cube's corners lie %.6g from the "
          "output (bound %.6g): it vanished",
          cell, cube_gap, out.bound);
    printf("  cell %-6g %6u -> %5u triangles (%llu collapsed, %llu kept as they were), bound %.5f,"
           " sampled %.5f / %.5f\n",
           cell, m->nt, out.n_triangles, (unsigned long long)out.collapsed,
           (unsigned long long)out.vanished, out.bound, to_out, to_in);
    if (cell >= 0.4)
        CHECK(out.n_triangles < m->nt / 2, "cell %g: %u of %u triangles left", cell,
              out.n_triangles, m->nt);
    sw_lod_proxy_mesh_free(&out);
}

static void check_bad_input(const mesh *m)
{
    const double origin[3] = {0, 0, 0};
    const sw_lod_proxy_input in = {m->pos, m->nrm, m->part, m->nv, 2, m->tri, m->nt};
    sw_lod_proxy_mesh out;
    sw_status st = {0};
    CHECK(sw_lod_proxy_cluster(&in, 0.0, origin, &out, &st) == SW_ERR_INVALID_ARGUMENT,
          "a zero cell accepted");
    CHECK(sw_lod_proxy_cluster(&in, 1e-300, origin, &out, &st) == SW_ERR_INVALID_ARGUMENT,
          "a grid of more than 2^40 cells per axis accepted");
    const sw_lod_proxy_input one_part = {m->pos, m->nrm, m->part, m->nv, 1, m->tri, m->nt};
    CHECK(sw_lod_proxy_cluster(&one_part, 0.1, origin, &out, &st) == SW_ERR_INVALID_ARGUMENT,
          "a part out of range accepted");
}

int main(void)
{
    mesh m;
    memset(&m, 0, sizeof m);
    const double c[3] = {0.0, 0.0, 0.0};
    add_sphere(&m, c, 1.0, 32, 16, 0);
    const double plo[3] = {1.3, -0.8, -0.5}, phi[3] = {1.31, 0.8, 0.5}; /* a thin plate */
    add_box(&m, plo, phi, 1);
    const uint32_t cube_first = m.nv;
    const double clo[3] = {-1.6, 0.0, 0.0}, chi[3] = {-1.58, 0.02, 0.02}; /* a tiny cube */
    add_box(&m, clo, chi, 1);
    const uint32_t cube_n = m.nv - cube_first;
    const double alo[3] = {0.0, 0.0, 1.0}, ahi[3] = {0.006, 0.006, 1.9}; /* an antenna */
    add_box(&m, alo, ahi, 0);
    const double origin[3] = {-2.0, -2.0, -2.0};
    printf("proxy clustering: %u vertices, %u triangles\n", m.nv, m.nt);
    const double cells[] = {0.01, 0.05, 0.1, 0.2, 0.4};
    for (size_t k = 0; k < sizeof cells / sizeof cells[0]; ++k)
        check_cell(&m, cells[k], origin, cube_first, cube_n);
    check_bad_input(&m);
    free(m.pos);
    free(m.nrm);
    free(m.part);
    free(m.tri);
    printf("%s\n", g_failures ? "FAILED" : "passed");
    return g_failures != 0;
}
