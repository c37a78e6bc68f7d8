/* SPDX-License-Identifier: MIT */
/* Shared by the scene generators (generate_building.c, generate_vehicle.c): faces built in a
 * scratch record (a NURBS surface and trim loops drawn as pen paths) and stored in a builder, or
 * only counted (a dry run, builder NULL, to plan a scene of an exact size).
 *
 * Conventions are the importer's (import_occt.cpp, OCCT's): the outer loop runs counter-clockwise
 * in (u, v), holes clockwise; consecutive trim curves share their join points bit for bit (a loop
 * is one pen path). Circles are exact: rational quadratic quarter arcs with weights 1, √2/2, 1
 * (The NURBS Book §7.3); a dome is their tensor product with the revolved meridian (§8.5).
 */
#include "generate_common.h"
#include "sw_sg_bvh.h"

#include "sw_status_util.h"

#include <math.h>
#include <string.h>

void sw__gen_v3(double out[3], const double o[3], double a, const double e[3], double b,
                const double f[3])
{
    for (int k = 0; k < 3; ++k)
        out[k] = o[k] + a * e[k] + b * f[k];
}

void sw__gen_cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static void sw__gen_set_cp(sw__gen_face *f, int i, int j, const double p[3], double w)
{
    double *q = f->cpw + ((size_t)j * f->n_u + i) * 4;
    q[0] = w * p[0], q[1] = w * p[1], q[2] = w * p[2], q[3] = w;
}

void sw__gen_face_reset(sw__gen_face *f, uint32_t kind)
{
    f->kind = kind;
    f->flags = 0;
    f->n_loops = 0;
    f->n_curves = 0;
    f->loop_first[0] = 0;
}

/* The plane o + u e + v g over [0, l] x [0, h], parameters in cm. */
void sw__gen_plane_surface(sw__gen_face *f, const double o[3], const double e[3], const double g[3],
                           double l, double h)
{
    f->deg_u = f->deg_v = 1;
    f->n_u = f->n_v = 2;
    const double ku[4] = {0, 0, l, l}, kv[4] = {0, 0, h, h};
    memcpy(f->ku, ku, sizeof ku);
    memcpy(f->kv, kv, sizeof kv);
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            double p[3];
            sw__gen_v3(p, o, i * l, e, j * h, g);
            sw__gen_set_cp(f, i, j, p, 1.0);
        }
}

/* Unit direction k (mod 4) of a circle in the plane (e1, e2): e1, e2, -e1, -e2. */
static void sw__gen_circle_dir(const double e1[3], const double e2[3], int k, double out[3])
{
    const double s1 = (k & 3) == 0 ? 1 : (k & 3) == 2 ? -1 : 0;
    const double s2 = (k & 3) == 1 ? 1 : (k & 3) == 3 ? -1 : 0;
    for (int c = 0; c < 3; ++c)
        out[c] = s1 * e1[c] + s2 * e2[c];
}

/* Quarter-arc knots for nq quadrants: 0 0 0 1 1 2 2 ... nq nq nq (u in [0, nq]). */
static int sw__gen_arc_knots(int nq, double *k)
{
    int n = 0;
    k[n++] = 0, k[n++] = 0, k[n++] = 0;
    for (int q = 1; q < nq; ++q)
        k[n++] = q, k[n++] = q;
    k[n++] = nq, k[n++] = nq, k[n++] = nq;
    return n;
}

/* The cylinder c + r (cos t e1 + sin t e2) + v axis, t over nq quadrants from e1, v in [0, len]:
 * its poles are the circle's (on the circle, weight 1) and the corners of its circumscribed
 * square (weight √2/2). Su x Sv points away from the axis when e1 x e2 = axis. */
void sw__gen_cylinder_surface(sw__gen_face *f, const double c[3], const double e1[3],
                              const double e2[3], const double axis[3], double r, int nq,
                              double len)
{
    f->deg_u = 2, f->deg_v = 1;
    f->n_u = 2 * nq + 1, f->n_v = 2;
    sw__gen_arc_knots(nq, f->ku);
    const double kv[4] = {0, 0, len, len};
    memcpy(f->kv, kv, sizeof kv);
    for (int j = 0; j < 2; ++j)
        for (int t = 0; t <= 2 * nq; ++t) {
            double a[3], b[3], p[3];
            sw__gen_circle_dir(e1, e2, t / 2, a);
            if (t & 1)
                sw__gen_circle_dir(e1, e2, t / 2 + 1, b);
            else
                b[0] = b[1] = b[2] = 0.0;
            for (int k = 0; k < 3; ++k)
                p[k] = c[k] + r * (a[k] + b[k]) + j * len * axis[k];
            sw__gen_set_cp(f, t, j, p, (t & 1) ? M_SQRT1_2 : 1.0);
        }
}

/* The hemisphere of radius r on centre c, z up: the full circle (u in [0, 4]) times the quarter
 * meridian from the equator to the pole (v in [0, 1]); weights multiply. */
void sw__gen_dome_surface(sw__gen_face *f, const double c[3], double r)
{
    f->deg_u = f->deg_v = 2;
    f->n_u = 9, f->n_v = 3;
    sw__gen_arc_knots(4, f->ku);
    sw__gen_arc_knots(1, f->kv);
    const double mr[3] = {r, r, 0}, mz[3] = {0, r, r}, mw[3] = {1, M_SQRT1_2, 1};
    for (int j = 0; j < 3; ++j)
        for (int t = 0; t <= 8; ++t) {
            double a[3], b[3] = {0, 0, 0}, p[3];
            sw__gen_circle_dir(sw__gen_x, sw__gen_y, t / 2, a);
            if (t & 1)
                sw__gen_circle_dir(sw__gen_x, sw__gen_y, t / 2 + 1, b);
            for (int k = 0; k < 3; ++k)
                p[k] = c[k] + mr[j] * (a[k] + b[k]) + mz[j] * sw__gen_z[k];
            sw__gen_set_cp(f, t, j, p, ((t & 1) ? M_SQRT1_2 : 1.0) * mw[j]);
        }
}

/* ---- trim loops, drawn as pen paths ---------------------------------------------------------- */

void sw__gen_loop_begin(sw__gen_face *f, double u, double v, uint32_t flags)
{
    f->loop_flags[f->n_loops] = flags;
    f->pen[0] = f->start[0] = u;
    f->pen[1] = f->start[1] = v;
}

static sw__gen_curve *sw__gen_next_curve(sw__gen_face *f)
{
    return f->n_curves < SW__GEN_MAX_CURVES ? &f->c[f->n_curves++] : NULL;
}

void sw__gen_line_to(sw__gen_face *f, double u, double v)
{
    sw__gen_curve *c = sw__gen_next_curve(f);
    if (!c)
        return;
    const double k[4] = {0, 0, 1, 1}, p[6] = {f->pen[0], f->pen[1], 1, u, v, 1};
    c->deg = 1, c->n = 2;
    memcpy(c->knots, k, sizeof k);
    memcpy(c->cpw, p, sizeof p);
    f->pen[0] = u, f->pen[1] = v;
}

void sw__gen_arcs(sw__gen_face *f, double cu, double cv, double r, int q0, int dir, int nq)
{
    sw__gen_ellipse_arcs(f, cu, cv, r, r, q0, dir, nq);
}

/* An ellipse is an affine image of a circle: the same weights, the poles scaled. */
void sw__gen_ellipse_arcs(sw__gen_face *f, double cu, double cv, double ru, double rv, int q0,
                          int dir, int nq)
{
    static const double du[4] = {1, 0, -1, 0}, dv[4] = {0, 1, 0, -1};
    for (int s = 0; s < nq; ++s) {
        sw__gen_curve *c = sw__gen_next_curve(f);
        if (!c)
            return;
        const int a = (q0 + dir * s) & 3, b = (q0 + dir * (s + 1)) & 3;
        const double h = M_SQRT1_2;
        const double mu = cu + ru * (du[a] + du[b]), mv = cv + rv * (dv[a] + dv[b]);
        const double eu = cu + ru * du[b], ev = cv + rv * dv[b];
        const double k[6] = {0, 0, 0, 1, 1, 1};
        const double p[9] = {f->pen[0], f->pen[1], 1, h * mu, h * mv, h, eu, ev, 1};
        c->deg = 2, c->n = 3;
        memcpy(c->knots, k, sizeof k);
        memcpy(c->cpw, p, sizeof p);
        f->pen[0] = eu, f->pen[1] = ev;
    }
}

/* Closes the loop: a line back to its start unless the pen is there already. */
void sw__gen_loop_end(sw__gen_face *f)
{
    const double du = f->pen[0] - f->start[0], dv = f->pen[1] - f->start[1];
    const double tiny = 1e-12 * (1.0 + fabs(f->start[0]) + fabs(f->start[1]));
    if (f->n_curves > 0 && (du != 0.0 || dv != 0.0) && fabs(du) <= tiny && fabs(dv) <= tiny) {
        /* an arc ending a rounding error away from the start: its end moved onto the start */
        sw__gen_curve *c = &f->c[f->n_curves - 1];
        double *e = c->cpw + 3 * (c->n - 1);
        e[0] = f->start[0] * e[2], e[1] = f->start[1] * e[2];
    } else if (du != 0.0 || dv != 0.0) {
        sw__gen_line_to(f, f->start[0], f->start[1]);
    }
    f->loop_first[++f->n_loops] = f->n_curves;
    if (f->n_loops > 1 || f->n_curves != 4)
        f->flags |= SW_SG_FACE_TRIMMED;
}

void sw__gen_outer_rect(sw__gen_face *f, double l, double h)
{
    sw__gen_loop_begin(f, 0, 0, SW_SG_LOOP_OUTER);
    sw__gen_line_to(f, l, 0);
    sw__gen_line_to(f, l, h);
    sw__gen_line_to(f, 0, h);
    sw__gen_loop_end(f);
}

/* A clockwise rectangular hole [u0, u1] x [v0, v1]. */
void sw__gen_hole_rect(sw__gen_face *f, double u0, double v0, double u1, double v1)
{
    if (f->n_loops >= SW__GEN_MAX_LOOPS)
        return;
    sw__gen_loop_begin(f, u0, v0, 0);
    sw__gen_line_to(f, u0, v1);
    sw__gen_line_to(f, u1, v1);
    sw__gen_line_to(f, u1, v0);
    sw__gen_loop_end(f);
}

/* A clockwise hole: jambs up to v1, a semicircle over [u0, u1] on top. */
void sw__gen_hole_arched(sw__gen_face *f, double u0, double v0, double u1, double v1)
{
    if (f->n_loops >= SW__GEN_MAX_LOOPS)
        return;
    sw__gen_loop_begin(f, u0, v0, 0);
    sw__gen_line_to(f, u0, v1);
    sw__gen_arcs(f, 0.5 * (u0 + u1), v1, 0.5 * (u1 - u0), 2, -1, 2);
    sw__gen_line_to(f, u1, v0);
    sw__gen_loop_end(f);
}

uint64_t sw__gen_mix64(uint64_t x)
{
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

uint32_t sw__gen_pick(uint64_t *s, uint32_t n)
{
    *s = sw__gen_mix64(*s);
    return (uint32_t)((*s >> 33) % n);
}

uint32_t sw__gen_node(sw__gen *g, sw_sg_node_kind kind, uint32_t parent, uint32_t ref,
                      const double xf[12], const float col[4], const char *name)
{
    const uint32_t want = g->n_nodes++;
    if (g->b && !g->oom && sw_sg_builder_add_node(g->b, kind, parent, ref, xf, col, name) != want)
        g->oom = 1;
    return want;
}

static uint64_t sw__gen_push(sw__gen *g, const double *v, size_t n)
{
    const uint64_t off = sw_sg_builder_push_doubles(g->b, v, n);
    g->oom |= off == UINT64_MAX;
    return off;
}

static void sw__gen_uv_box(const sw__gen_face *f, double box[4])
{
    box[0] = box[2] = HUGE_VAL, box[1] = box[3] = -HUGE_VAL;
    for (int k = 0; k < f->n_curves; ++k)
        for (int i = 0; i < f->c[k].n; ++i) {
            const double *p = f->c[k].cpw + 3 * i;
            box[0] = fmin(box[0], p[0] / p[2]), box[1] = fmax(box[1], p[0] / p[2]);
            box[2] = fmin(box[2], p[1] / p[2]), box[3] = fmax(box[3], p[1] / p[2]);
        }
    const double lo[2] = {f->ku[f->deg_u], f->kv[f->deg_v]}, hi[2] = {f->ku[f->n_u], f->kv[f->n_v]};
    for (int a = 0; a < 2; ++a) {
        box[2 * a] = fmax(box[2 * a], lo[a]);
        box[2 * a + 1] = fmin(box[2 * a + 1], hi[a]);
    }
}

static uint32_t sw__gen_store_face(sw__gen *g, const sw__gen_face *f)
{
    sw_sg_face_rec rec;
    memset(&rec, 0, sizeof rec);
    rec.deg_u = (uint32_t)f->deg_u, rec.deg_v = (uint32_t)f->deg_v;
    rec.n_u = (uint32_t)f->n_u, rec.n_v = (uint32_t)f->n_v;
    rec.knots_u = sw__gen_push(g, f->ku, (size_t)(f->n_u + f->deg_u + 1));
    rec.knots_v = sw__gen_push(g, f->kv, (size_t)(f->n_v + f->deg_v + 1));
    rec.cpw = sw__gen_push(g, f->cpw, (size_t)f->n_u * f->n_v * 4);
    rec.kind = f->kind;
    rec.flags = f->flags;
    rec.tolerance = 1e-7;
    sw__gen_uv_box(f, rec.uv_box);
    for (int l = 0; l < f->n_loops; ++l) {
        sw_sg_loop_rec lr = {SW_SG_NONE, (uint32_t)(f->loop_first[l + 1] - f->loop_first[l]),
                             f->loop_flags[l], 0};
        for (int k = f->loop_first[l]; k < f->loop_first[l + 1]; ++k) {
            sw_sg_curve_rec cr = {(uint32_t)f->c[k].deg, (uint32_t)f->c[k].n, 0, 0};
            cr.knots = sw__gen_push(g, f->c[k].knots, (size_t)(f->c[k].n + f->c[k].deg + 1));
            cr.cpw = sw__gen_push(g, f->c[k].cpw, (size_t)f->c[k].n * 3);
            const uint32_t ci = sw_sg_builder_add_curve(g->b, &cr);
            g->oom |= ci == SW_SG_NONE;
            if (lr.first_curve == SW_SG_NONE)
                lr.first_curve = ci;
        }
        const uint32_t li = sw_sg_builder_add_loop(g->b, &lr);
        g->oom |= li == SW_SG_NONE;
        if (l == 0)
            rec.first_loop = li;
    }
    rec.n_loops = (uint32_t)f->n_loops;
    const uint32_t fi = sw_sg_builder_add_face(g->b, &rec);
    g->oom |= fi == SW_SG_NONE;
    return fi;
}

/* Stores the scratch face and draws it under `parent` (drawn = 0: a prototype's face). */
void sw__gen_emit(sw__gen *g, uint32_t parent, const float col[4], int drawn)
{
    const sw__gen_face *f = g->face;
    g->unique++;
    g->occ += drawn != 0;
    uint32_t fi = 0;
    if (g->b && !g->oom)
        fi = sw__gen_store_face(g, f);
    sw__gen_node(g, SW_SG_NODE_SURFACE, parent, fi, NULL, col, NULL);
}

/* A planar face o + u e + v g, [0, l] x [0, h]; reversed: its normal is -(e x g). */
void sw__gen_plane(sw__gen *g, const double o[3], const double e[3], const double f3[3], double l,
                   double h, int reversed)
{
    sw__gen_face_reset(g->face, SW_SG_KIND_PLANE);
    sw__gen_plane_surface(g->face, o, e, f3, l, h);
    sw__gen_outer_rect(g->face, l, h);
    if (reversed)
        g->face->flags |= SW_SG_FACE_REVERSED;
}

void sw__gen_cylinder(sw__gen *g, const double c[3], const double e1[3], const double e2[3],
                      const double axis[3], double r, int nq, double len, int reversed)
{
    sw__gen_face_reset(g->face, SW_SG_KIND_CYLINDER);
    sw__gen_cylinder_surface(g->face, c, e1, e2, axis, r, nq, len);
    sw__gen_outer_rect(g->face, nq, len);
    if (reversed)
        g->face->flags |= SW_SG_FACE_REVERSED;
}

void sw__gen_instance(sw__gen *g, uint32_t parent, int m, const double xf[12], const float col[4])
{
    if (g->proto[m] == SW_SG_NONE) {
        const sw_sg_scene_view *v = sw_sg_scene_view_ptr(g->models[m]);
        if (g->b && !g->oom && sw__sg_append_model(g->b, v, g->n_nodes, &g->proto[m], NULL))
            g->oom = 1;
        if (!g->b)
            g->proto[m] = 0;
        g->n_nodes += v->n_nodes;
        g->unique += v->n_faces;
    }
    sw__gen_node(g, SW_SG_NODE_INSTANCE, parent, g->proto[m], xf, col, NULL);
    g->occ += g->model_occ[m];
    g->instanced += g->model_occ[m];
    g->instances++;
}

/* Each model's occurrences and the box of their control nets (as the grid measures). */
sw_result sw__gen_measure(sw__gen *g, const char *const *names, sw_status *status)
{
    for (int m = 0; m < g->n_models; ++m) {
        if (!g->models[m])
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "model %s missing", names[m]);
        uint64_t n = 0;
        sw_result r = sw_sg_occurrences_box(g->models[m], &n, g->model_box[m], status);
        if (r != SW_OK)
            return r;
        g->model_occ[m] = n;
        if (!g->model_occ[m])
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "model %s draws no faces", names[m]);
    }
    return SW_OK;
}

sw_result sw__gen_check_request(const char *what, uint64_t surfaces, const void *models,
                                sw_status *status)
{
    if (surfaces < SW_SG_BUILDING_MIN_SURFACES || surfaces > SW_SG_BUILDING_MAX_SURFACES)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "%s: %llu surfaces outside %u..%u", what,
                        (unsigned long long)surfaces, (unsigned)SW_SG_BUILDING_MIN_SURFACES,
                        (unsigned)SW_SG_BUILDING_MAX_SURFACES);
    if (!models)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "%s: no sample models", what);
    return SW_OK;
}
