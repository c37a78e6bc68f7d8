/* SPDX-License-Identifier: MIT */
/* tests/generate: the building and vehicle generators (scenegraph/generate_building.c,
 * generate_vehicle.c: `splinewalk generate building|vehicle`), for each N given:
 *  - determinism: two runs with one seed save byte-identical .sws files, another seed differs;
 *  - counts: the scene's own traversal (sw_sg_scene_compute_stats) finds N within ±10 % face
 *    occurrences, at least 10 % of them unique faces, and as many faces as the report says;
 *  - validity: the scene validates (sw_sg_scene_validate: every surface and curve), every loop is
 *    closed bit for bit (each curve's first control point is the previous one's last);
 *  - trims, against references independent of the flattening and classification under test: on
 *    a grid of points over each trimmed generated face (every tenth after the first 2000),
 *    sw_sg_trim_classify (crossing parity of
 *    the flattened loops) agrees with the winding numbers of the exact rational curves (angles
 *    summed along dense samples of sw_sg_curve_eval; points nearer a curve than its sampling
 *    step are skipped), and the area it finds inside equals what Green's theorem gives on the
 *    exact curves (Gauss-Legendre) within the grid's resolution;
 *    on the generated faces, the outer loop runs counter-clockwise and holes clockwise (OCCT's
 *    convention, as the importer keeps it), each hole lies inside the outer loop and outside the
 *    other holes, and the inside of every rectangular hole classifies out;
 *  - exact circles: every generated cylinder (columns, soffits, vaults) and dome evaluates, all
 *    over its domain, at its radius from its axis / centre to within 1e-12 of the coordinates'
 *    magnitude (rounding of the evaluation; a polynomial approximation of a circle of radius 18
 *    would be off by far more);
 *  - the vehicles' wheel arches (pairs of rational quarter arcs in a lofted bicubic panel's outer
 *    loop) map to exact semicircles in 3D: every surface point along them lies in one vertical
 *    plane's circle through the two ends, to within 1e-12 of the coordinates' magnitude;
 *  - the first N also through the BREP exporter: OCCT's reader, via the importer, finds the same
 *    faces and face occurrences, and BRepCheck_Analyzer finds every face valid.
 * Usage: test_generate DATA_DIR WORKDIR building|vehicle N...
 */
#include "sw_sg_export.h"
#include "sw_sg_generate.h"
#include "sw_sg_import.h"
#include "sw_sg_trim.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "test_check.h"

int sw_test_brep_check(const char *path, uint32_t *faces, uint32_t *invalid); /* brep_check.cpp */

static sw_sg_scene *g_models[SW_SG_BUILDING_N_MODELS];
static int g_vehicle;

/* What the tests need of either generator's report. */
typedef struct gen_report {
    uint64_t occurrences, unique_faces;
    int features; /* every kind of part the generator promises is there */
    char text[160];
} gen_report;

static sw_sg_scene *generate(uint64_t n, uint64_t seed, gen_report *rep)
{
    sw_sg_scene *s = NULL;
    sw_status st = {0};
    sw_result r;
    if (g_vehicle) {
        sw_sg_vehicle_desc d = {n, seed, (const sw_sg_scene *const *)g_models, NULL, NULL};
        sw_sg_vehicle_report vr;
        r = sw_sg_generate_vehicle(&d, &s, &vr, &st);
        rep->occurrences = vr.occurrences, rep->unique_faces = vr.unique_faces;
        rep->features = vr.vehicles > 0 && vr.with_engine > 0 && vr.arches == 4 * vr.vehicles &&
                        vr.windows >= 4 * vr.vehicles && vr.gaps == 6 * vr.vehicles;
        snprintf(rep->text, sizeof rep->text,
                 "%u cars (%u with an engine), %u arches, %u windows, %u gaps", vr.vehicles,
                 vr.with_engine, vr.arches, vr.windows, vr.gaps);
    } else {
        sw_sg_building_desc d = {n, seed, (const sw_sg_scene *const *)g_models, NULL, NULL};
        sw_sg_building_report br;
        r = sw_sg_generate_building(&d, &s, &br, &st);
        rep->occurrences = br.occurrences, rep->unique_faces = br.unique_faces;
        rep->features = br.domes + br.vaults > 0 && br.windows > 0 && br.doors > 0 &&
                        br.stairs > 0 && br.furnished > 0 && br.columns > 0;
        snprintf(rep->text, sizeof rep->text,
                 "%u storeys of %ux%u, %u domes, %u vaults, %u windows, %u doors, %u stairs, %u "
                 "furnished rooms",
                 br.floors, br.nx, br.ny, br.domes, br.vaults, br.windows, br.doors, br.stairs,
                 br.furnished);
    }
    if (r != SW_OK) {
        CHECK(0, "generate %llu seed %llu: %s", (unsigned long long)n, (unsigned long long)seed,
              st.message);
        return NULL;
    }
    return s;
}

static unsigned char *read_all(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    *size = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = malloc(*size ? *size : 1);
    if (b && fread(b, 1, *size, f) != *size) {
        free(b);
        b = NULL;
    }
    fclose(f);
    return b;
}

static int save(sw_sg_scene *s, const char *path)
{
    sw_status st = {0};
    if (sw_sg_scene_save(s, path, &st) != SW_OK) {
        CHECK(0, "save %s: %s", path, st.message);
        return 0;
    }
    return 1;
}

/* ---- determinism ----------------------------------------------------------------------------- */

static void test_determinism(uint64_t n, const char *work)
{
    char pa[1024], pb[1024], pc[1024];
    snprintf(pa, sizeof pa, "%s/a.sws", work);
    snprintf(pb, sizeof pb, "%s/b.sws", work);
    snprintf(pc, sizeof pc, "%s/c.sws", work);
    gen_report rep;
    sw_sg_scene *a = generate(n, 7, &rep), *b = generate(n, 7, &rep), *c = generate(n, 8, &rep);
    if (!a || !b || !c || !save(a, pa) || !save(b, pb) || !save(c, pc)) {
        sw_sg_scene_free(a), sw_sg_scene_free(b), sw_sg_scene_free(c);
        return;
    }
    size_t sa = 0, sb = 0, sc = 0;
    unsigned char *ba = read_all(pa, &sa), *bb = read_all(pb, &sb), *bc = read_all(pc, &sc);
    CHECK(ba && bb && sa == sb && memcmp(ba, bb, sa) == 0, "N %llu: seed 7 twice: files differ",
          (unsigned long long)n);
    CHECK(ba && bc && (sa != sc || memcmp(ba, bc, sa) != 0), "N %llu: seeds 7 and 8: same file",
          (unsigned long long)n);
    printf("  determinism: seed 7 twice %zu bytes identical, seed 8 %zu bytes different\n", sa, sc);
    free(ba), free(bb), free(bc);
    remove(pa), remove(pb), remove(pc);
    sw_sg_scene_free(a), sw_sg_scene_free(b), sw_sg_scene_free(c);
}

/* ---- faces of the generator vs faces of the furniture ---------------------------------------- */

/* 1 for faces drawn from an imported model's subtree: the importer names a model's top node after
 * its file; nodes are stored after their parents. */
static unsigned char *imported_faces(const sw_sg_scene_view *v)
{
    unsigned char *node_imp = calloc(v->n_nodes, 1), *face_imp = calloc(v->n_faces, 1);
    for (uint32_t i = 0; node_imp && face_imp && i < v->n_nodes; ++i) {
        const sw_sg_node_rec *nd = &v->nodes[i];
        const char *name = nd->name == SW_SG_NONE ? "" : v->strings + nd->name;
        const size_t len = strlen(name);
        node_imp[i] = (len > 5 && !strcmp(name + len - 5, ".brep")) ||
                      (nd->parent != SW_SG_NONE && nd->parent < i && node_imp[nd->parent]);
        if (nd->kind == SW_SG_NODE_SURFACE && node_imp[i])
            face_imp[nd->ref] = 1;
    }
    free(node_imp);
    return face_imp;
}

/* ---- trims ----------------------------------------------------------------------------------- */

/* Signed area enclosed by the exact curves of loop l (Green: 1/2 ∮ u dv - v du), 8-point
 * Gauss-Legendre on every knot span. */
static double green_area(const sw_sg_scene *s, uint32_t l)
{
    static const double x[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                0.7966664774136267,  0.9602898564975363};
    static const double w[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                                0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                                0.2223810344533745, 0.1012285362903763};
    const sw_sg_loop_rec *lp = &sw_sg_scene_view_ptr(s)->loops[l];
    double area = 0.0;
    for (uint32_t k = 0; k < lp->n_curves; ++k) {
        sw_sg_curve c;
        sw_sg_scene_curve(s, lp->first_curve + k, &c);
        for (int32_t sp = c.degree; sp < c.n; ++sp) {
            const double a = c.knots[sp], b = c.knots[sp + 1];
            if (!(b > a))
                continue;
            for (int g = 0; g < 8; ++g) {
                const double t = 0.5 * (a + b) + 0.5 * (b - a) * x[g];
                double h[9]; /* homogeneous point and derivative */
                sw_sg_curve_eval_h(&c, t, 1, h);
                const double u = h[0] / h[2], v = h[1] / h[2];
                const double du = (h[3] - u * h[5]) / h[2], dv = (h[4] - v * h[5]) / h[2];
                area += 0.5 * (u * dv - v * du) * w[g] * 0.5 * (b - a);
            }
        }
    }
    return area;
}

typedef struct trim_stats {
    uint32_t faces, holes, rect_holes, area_checked, winding_faces;
    uint64_t points;
    double worst_area; /* |classified - exact| / allowed */
} trim_stats;

static double poly_area(const sw_sg_polyline *p)
{
    double a = 0.0;
    for (uint32_t i = 0, j = p->count - 1; i < p->count; j = i++)
        a += p->uv[2 * j] * p->uv[2 * i + 1] - p->uv[2 * i] * p->uv[2 * j + 1];
    return 0.5 * a;
}

/* The box of a polyline: u0, u1, v0, v1. */
static void poly_box(const sw_sg_polyline *p, double b[4])
{
    b[0] = b[2] = HUGE_VAL, b[1] = b[3] = -HUGE_VAL;
    for (uint32_t i = 0; i < p->count; ++i) {
        b[0] = fmin(b[0], p->uv[2 * i]), b[1] = fmax(b[1], p->uv[2 * i]);
        b[2] = fmin(b[2], p->uv[2 * i + 1]), b[3] = fmax(b[3], p->uv[2 * i + 1]);
    }
}

/* A hole whose polyline is its box's four corners: the window rectangles and the stairwells. */
static int is_rect(const sw_sg_polyline *p, const double b[4])
{
    if (p->count != 4)
        return 0;
    for (uint32_t i = 0; i < 4; ++i)
        if ((p->uv[2 * i] != b[0] && p->uv[2 * i] != b[1]) ||
            (p->uv[2 * i + 1] != b[2] && p->uv[2 * i + 1] != b[3]))
            return 0;
    return 1;
}

/* Conventions of a generated face: orientation, nesting, rectangular holes out. */
static void check_generated_loops(uint32_t f, const sw_sg_polyline *pl, uint32_t n,
                                  const sw_sg_loop_rec *loops, trim_stats *ts)
{
    for (uint32_t l = 0; l < n; ++l) {
        const int outer = (loops[l].flags & SW_SG_LOOP_OUTER) != 0;
        const double a = poly_area(&pl[l]);
        CHECK(outer == (l == 0) && (outer ? a > 0.0 : a < 0.0),
              "face %u loop %u: outer %d, polygon area %g (outer CCW, holes CW)", f, l, outer, a);
        if (l == 0)
            continue;
        ts->holes++;
        for (uint32_t i = 0; i < pl[l].count; ++i) {
            const double u = pl[l].uv[2 * i], v = pl[l].uv[2 * i + 1];
            int in_outer = sw_sg_trim_classify(&pl[0], 1, u, v), in_other = 0;
            for (uint32_t m = 1; m < n; ++m)
                in_other |= m != l && sw_sg_trim_classify(&pl[m], 1, u, v);
            CHECK(in_outer && !in_other,
                  "face %u hole %u vertex %u (%g, %g): inside the outer "
                  "loop %d, inside another hole %d",
                  f, l, i, u, v, in_outer, in_other);
            if (!in_outer || in_other)
                break;
        }
        double b[4];
        poly_box(&pl[l], b);
        if (!is_rect(&pl[l], b))
            continue;
        ts->rect_holes++;
        for (int i = 1; i < 8; ++i)
            for (int j = 1; j < 8; ++j) {
                const double u = b[0] + (b[1] - b[0]) * i / 8.0, v = b[2] + (b[3] - b[2]) * j / 8.0;
                CHECK(!sw_sg_trim_classify(pl, n, u, v),
                      "face %u: (%g, %g) inside rectangular "
                      "hole %u classified in",
                      f, u, v, l);
            }
    }
}

/* Classified area on a grid of cells over the face's box vs the exact area; a cell is misjudged
 * only where a loop crosses it, so the allowance is the loops' length times the cell diagonal. */
static void check_area(const sw_sg_scene *s, uint32_t f, const sw_sg_polyline *pl, uint32_t n,
                       trim_stats *ts)
{
    const sw_sg_face_rec *r = &sw_sg_scene_view_ptr(s)->faces[f];
    double exact = 0.0, length = 0.0;
    for (uint32_t l = 0; l < n; ++l) {
        const double a = green_area(s, r->first_loop + l);
        exact += (l == 0 ? 1.0 : -1.0) * fabs(a);
        for (uint32_t i = 0, j = pl[l].count - 1; i < pl[l].count; j = i++)
            length +=
                hypot(pl[l].uv[2 * i] - pl[l].uv[2 * j], pl[l].uv[2 * i + 1] - pl[l].uv[2 * j + 1]);
    }
    enum { G = 48 };
    const double du = (r->uv_box[1] - r->uv_box[0]) / G, dv = (r->uv_box[3] - r->uv_box[2]) / G;
    int in = 0;
    for (int i = 0; i < G; ++i)
        for (int j = 0; j < G; ++j)
            in += sw_sg_trim_classify(pl, n, r->uv_box[0] + (i + 0.5) * du,
                                      r->uv_box[2] + (j + 0.5) * dv);
    const double got = in * du * dv, allowed = length * hypot(du, dv) + 1e-12;
    ts->worst_area = fmax(ts->worst_area, fabs(got - exact) / allowed);
    ts->area_checked++;
    CHECK(fabs(got - exact) <= allowed, "face %u: classified area %g, exact %g (allowed %g)", f,
          got, exact, allowed);
}

/* Winding number of exact loop l around (u, v) from `samples` points per knot span; -1000 when
 * the point is within `near` of a sample (too close to trust the angle steps). */
static int winding(const sw_sg_scene *s, uint32_t l, double u, double v, int samples, double near)
{
    const sw_sg_loop_rec *lp = &sw_sg_scene_view_ptr(s)->loops[l];
    double total = 0.0, prev = 0.0;
    int first = 1;
    for (uint32_t k = 0; k < lp->n_curves; ++k) {
        sw_sg_curve c;
        sw_sg_scene_curve(s, lp->first_curve + k, &c);
        for (int32_t sp = c.degree; sp < c.n; ++sp) {
            const double a = c.knots[sp], b = c.knots[sp + 1];
            for (int i = 0; b > a && i < samples; ++i) {
                double p[2];
                sw_sg_curve_eval(&c, a + (b - a) * i / samples, p);
                if (hypot(p[0] - u, p[1] - v) < near)
                    return -1000;
                const double ang = atan2(p[1] - v, p[0] - u);
                if (!first) {
                    double d = ang - prev;
                    d -= d > M_PI ? 2 * M_PI : d < -M_PI ? -2 * M_PI : 0.0;
                    total += d;
                }
                first = 0;
                prev = ang;
            }
        }
    }
    /* closing step back to the loop's first point, the start of its first curve */
    sw_sg_curve c;
    sw_sg_scene_curve(s, lp->first_curve, &c);
    const double ang = atan2(c.cpw[1] / c.cpw[2] - v, c.cpw[0] / c.cpw[2] - u);
    double d = ang - prev;
    d -= d > M_PI ? 2 * M_PI : d < -M_PI ? -2 * M_PI : 0.0;
    return (int)lround((total + d) / (2 * M_PI));
}

/* Crossing parity of the flattened loops vs winding numbers of the exact curves. */
static uint32_t check_winding(const sw_sg_scene *s, uint32_t f, const sw_sg_polyline *pl,
                              uint32_t n)
{
    const sw_sg_face_rec *r = &sw_sg_scene_view_ptr(s)->faces[f];
    enum { G = 16, SAMPLES = 64 };
    const double du = (r->uv_box[1] - r->uv_box[0]) / G, dv = (r->uv_box[3] - r->uv_box[2]) / G;
    const double near = 1e-3 * hypot(du * G, dv * G);
    uint32_t compared = 0;
    for (int i = 0; i < G; ++i)
        for (int j = 0; j < G; ++j) {
            const double u = r->uv_box[0] + (i + 0.5) * du, v = r->uv_box[2] + (j + 0.5) * dv;
            int sum = 0, skip = 0;
            for (uint32_t l = 0; l < n && !skip; ++l) {
                const int w = winding(s, r->first_loop + l, u, v, SAMPLES, near);
                skip = w == -1000;
                sum += abs(w);
            }
            if (skip)
                continue;
            const int got = sw_sg_trim_classify(pl, n, u, v);
            CHECK(got == (sum & 1), "face %u: (%g, %g) classified %d, winding numbers say %d", f, u,
                  v, got, sum & 1);
            compared++;
        }
    return compared;
}

/* Loops closed bit for bit: every curve starts on the previous one's last control point. */
static void check_closed(const sw_sg_scene *s, uint32_t f, uint32_t l)
{
    const sw_sg_loop_rec *lp = &sw_sg_scene_view_ptr(s)->loops[l];
    for (uint32_t k = 0; k < lp->n_curves; ++k) {
        sw_sg_curve a, b;
        sw_sg_scene_curve(s, lp->first_curve + (k + lp->n_curves - 1) % lp->n_curves, &a);
        sw_sg_scene_curve(s, lp->first_curve + k, &b);
        const double *e = a.cpw + (size_t)(a.n - 1) * 3, *st = b.cpw;
        CHECK(e[0] / e[2] == st[0] / st[2] && e[1] / e[2] == st[1] / st[2],
              "face %u loop %u: curve %u starts at (%.17g, %.17g), the previous ends at (%.17g, "
              "%.17g)",
              f, l, k, st[0] / st[2], st[1] / st[2], e[0] / e[2], e[1] / e[2]);
    }
}

static void test_trims(const sw_sg_scene *s, const unsigned char *imp)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(s);
    trim_stats ts = {0, 0, 0, 0, 0, 0, 0.0};
    sw_sg_polyline pl[16];
    for (uint32_t f = 0; f < v->n_faces; ++f) {
        const sw_sg_face_rec *r = &v->faces[f];
        const uint32_t n = r->n_loops < 16 ? r->n_loops : 16;
        const double tol = 1e-4 * hypot(r->uv_box[1] - r->uv_box[0], r->uv_box[3] - r->uv_box[2]);
        int ok = 1;
        for (uint32_t l = 0; l < n; ++l) {
            check_closed(s, f, r->first_loop + l);
            sw_status st = {0};
            ok = ok &&
                 sw_sg_trim_flatten_loop(s, r->first_loop + l, tol, 1u << 20, &pl[l], &st) == SW_OK;
            CHECK(ok, "face %u loop %u: %s", f, l, st.message);
        }
        if (ok && n > 0 && !imp[f]) {
            check_generated_loops(f, pl, n, &v->loops[r->first_loop], &ts);
            if (r->flags & SW_SG_FACE_TRIMMED) {
                check_area(s, f, pl, n, &ts);
                /* the winding reference costs ~1 ms a face: every face of the first 2000, then
                 * every tenth, so that 10^5 surfaces stay within minutes */
                if (ts.area_checked <= 2000 || ts.area_checked % 10 == 0)
                    ts.points += check_winding(s, f, pl, n), ts.winding_faces++;
            }
        }
        ts.faces += !imp[f];
        for (uint32_t l = 0; l < n; ++l)
            sw_sg_polyline_free(&pl[l]);
    }
    printf("  trims: %u generated faces, %u holes (%u rectangular, inside out), %llu points on %u "
           "faces classified as the exact curves' winding numbers say, %u trimmed areas within "
           "%.2f of the allowance\n",
           ts.faces, ts.holes, ts.rect_holes, (unsigned long long)ts.points, ts.winding_faces,
           ts.area_checked, ts.worst_area);
}

/* ---- exact circles --------------------------------------------------------------------------- */

static void point(const double *h, double p[3])
{
    p[0] = h[0] / h[3], p[1] = h[1] / h[3], p[2] = h[2] / h[3];
}

/* A generated cylinder's or dome's centre and radius from its first row of poles: pole 0 (angle
 * 0) and pole 4 (angle 180 degrees) are opposite points of the circle, each with weight 1. */
static void test_circles(const sw_sg_scene *s, const unsigned char *imp)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(s);
    uint32_t cyl = 0, dome = 0;
    double worst = 0.0;
    for (uint32_t f = 0; f < v->n_faces; ++f) {
        const sw_sg_face_rec *r = &v->faces[f];
        const int is_cyl = r->kind == SW_SG_KIND_CYLINDER, is_dome = r->kind == SW_SG_KIND_SPHERE;
        if (imp[f] || !(is_cyl || is_dome))
            continue;
        sw_sg_surface sf;
        sw_sg_scene_face_surface(s, f, &sf);
        double p0[3], p4[3], q0[3], c[3], axis[3] = {0, 0, 0};
        point(sf.cpw, p0);
        point(sf.cpw + 16, p4);
        point(sf.cpw + (size_t)sf.n_u * 4, q0); /* the next row's pole 0 */
        double rad = 0.0, scale = 0.0, alen = 0.0;
        for (int k = 0; k < 3; ++k) {
            c[k] = 0.5 * (p0[k] + p4[k]);
            rad += 0.25 * (p0[k] - p4[k]) * (p0[k] - p4[k]);
            axis[k] = q0[k] - p0[k];
            alen += axis[k] * axis[k];
            scale = fmax(scale, fabs(c[k]));
        }
        rad = sqrt(rad), alen = sqrt(alen);
        scale = fmax(scale + rad, 1.0);
        for (int i = 0; i <= 12; ++i)
            for (int j = 0; j <= 6; ++j) {
                const double u =
                    sf.knots_u[sf.deg_u] + (sf.knots_u[sf.n_u] - sf.knots_u[sf.deg_u]) * i / 12.0;
                const double w =
                    sf.knots_v[sf.deg_v] + (sf.knots_v[sf.n_v] - sf.knots_v[sf.deg_v]) * j / 6.0;
                double p[3], d[3], dot = 0.0, dist = 0.0;
                sw_sg_surface_eval(&sf, u, w, p);
                for (int k = 0; k < 3; ++k)
                    d[k] = p[k] - c[k], dot += d[k] * axis[k] / alen;
                for (int k = 0; k < 3; ++k) {
                    const double e = is_cyl ? d[k] - dot * axis[k] / alen : d[k];
                    dist += e * e;
                }
                const double err = fabs(sqrt(dist) - rad) / scale;
                worst = fmax(worst, err);
                CHECK(err <= 1e-12,
                      "face %u (%s): point (%g, %g) at %.17g from the %s, radius "
                      "%.17g",
                      f, is_cyl ? "cylinder" : "dome", u, w, sqrt(dist), is_cyl ? "axis" : "centre",
                      rad);
            }
        cyl += is_cyl, dome += is_dome;
    }
    CHECK(cyl > 0, "no generated cylinder");
    printf("  circles: %u cylinders, %u domes at their radius within %.2g (relative to the "
           "coordinates)\n",
           cyl, dome, worst);
}

/* Wheel arches: the outer loop's consecutive quadratic pairs on a bicubic face; the circle through
 * their 3D end points (a diameter) in the xz plane, every sample on it. */
static void test_arches(const sw_sg_scene *s, const unsigned char *imp)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(s);
    uint32_t arches = 0;
    double worst = 0.0;
    for (uint32_t f = 0; f < v->n_faces; ++f) {
        const sw_sg_face_rec *r = &v->faces[f];
        if (imp[f] || r->deg_u != 3 || r->deg_v != 3 || r->n_loops == 0)
            continue;
        sw_sg_surface sf;
        sw_sg_scene_face_surface(s, f, &sf);
        const sw_sg_loop_rec *lp = &v->loops[r->first_loop];
        for (uint32_t k = 0; k + 1 < lp->n_curves; ++k) {
            sw_sg_curve a, b;
            sw_sg_scene_curve(s, lp->first_curve + k, &a);
            sw_sg_scene_curve(s, lp->first_curve + k + 1, &b);
            if (a.degree != 2 || b.degree != 2)
                continue;
            double uv0[2], uv1[2], p0[3], p1[3], c[3], rad = 0.0, scale = 1.0;
            sw_sg_curve_eval(&a, a.knots[a.degree], uv0);
            sw_sg_curve_eval(&b, b.knots[b.n], uv1);
            sw_sg_surface_eval(&sf, uv0[0], uv0[1], p0);
            sw_sg_surface_eval(&sf, uv1[0], uv1[1], p1);
            for (int q = 0; q < 3; ++q) {
                c[q] = 0.5 * (p0[q] + p1[q]);
                scale = fmax(scale, fabs(c[q]));
            }
            rad = 0.5 * hypot(p1[0] - p0[0], p1[2] - p0[2]);
            for (int half = 0; half < 2; ++half) {
                const sw_sg_curve *cv = half ? &b : &a;
                for (int i = 0; i <= 16; ++i) {
                    const double t0 = cv->knots[cv->degree], t1 = cv->knots[cv->n];
                    double uv[2], p[3];
                    sw_sg_curve_eval(cv, t0 + (t1 - t0) * i / 16.0, uv);
                    sw_sg_surface_eval(&sf, uv[0], uv[1], p);
                    const double err = fabs(hypot(p[0] - c[0], p[2] - c[2]) - rad) / scale;
                    worst = fmax(worst, err);
                    CHECK(err <= 1e-12 && p[2] >= c[2] - 1e-9 * scale,
                          "face %u arch at curve %u: a point %.17g from the centre, radius %.17g",
                          f, k, hypot(p[0] - c[0], p[2] - c[2]), rad);
                }
            }
            arches++;
            ++k;
        }
    }
    if (g_vehicle)
        CHECK(arches > 0, "no wheel arch found");
    printf("  arches: %u wheel arches on lofted panels, exact semicircles in 3D within %.2g\n",
           arches, worst);
}

/* ---- counts ---------------------------------------------------------------------------------- */

static void test_counts(const sw_sg_scene *s, uint64_t n, const gen_report *rep)
{
    sw_sg_scene_stats ss;
    CHECK(sw_sg_scene_compute_stats(s, &ss) == SW_OK, "stats");
    const double occ = (double)ss.face_occurrences;
    CHECK(fabs(occ - (double)n) <= 0.1 * (double)n, "N %llu: %llu face occurrences",
          (unsigned long long)n, (unsigned long long)ss.face_occurrences);
    CHECK(ss.faces >= 0.1 * occ, "N %llu: %u unique faces of %.0f occurrences",
          (unsigned long long)n, ss.faces, occ);
    CHECK(rep->occurrences == ss.face_occurrences && rep->unique_faces == ss.faces,
          "report: %llu occurrences, %llu unique; the scene: %llu, %u",
          (unsigned long long)rep->occurrences, (unsigned long long)rep->unique_faces,
          (unsigned long long)ss.face_occurrences, ss.faces);
    CHECK(ss.instances > 0 && rep->features, "N %llu: %u instances, %s", (unsigned long long)n,
          ss.instances, rep->text);
    sw_status st = {0};
    CHECK(sw_sg_scene_validate(sw_sg_scene_view_ptr(s), "generated", &st) == SW_OK, "validate: %s",
          st.message);
    printf("  counts: %llu occurrences (N %llu), %u unique faces (%.1f %%), %u instances, %u "
           "trimmed faces; %s\n",
           (unsigned long long)ss.face_occurrences, (unsigned long long)n, ss.faces,
           100.0 * ss.faces / occ, ss.instances, ss.trimmed_faces, rep->text);
}

/* ---- BREP round trip ------------------------------------------------------------------------- */

static void test_brep(const sw_sg_scene *s, const char *work)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/building.brep", work);
    sw_status st = {0};
    sw_sg_export_report er;
    if (sw_sg_export_brep(s, path, &er, &st) != SW_OK) {
        CHECK(0, "export: %s", st.message);
        return;
    }
    sw_sg_import_desc d = {path, NULL, NULL, NULL, NULL, 0};
    sw_sg_scene *back = NULL;
    if (sw_sg_import_file(&d, &back, NULL, &st) != SW_OK) {
        CHECK(0, "import of the export: %s", st.message);
        return;
    }
    sw_sg_scene_stats a, b;
    sw_sg_scene_compute_stats(s, &a);
    sw_sg_scene_compute_stats(back, &b);
    CHECK(a.faces == b.faces && a.face_occurrences == b.face_occurrences && er.faces == a.faces &&
              er.occurrences == a.face_occurrences,
          "BREP round trip: %u faces, %llu occurrences; exported %u, %llu; read back %u, %llu",
          a.faces, (unsigned long long)a.face_occurrences, er.faces,
          (unsigned long long)er.occurrences, b.faces, (unsigned long long)b.face_occurrences);
    uint32_t faces = 0, invalid = 0;
    /* OCCT's map of faces tells located faces apart: one per occurrence */
    CHECK(sw_test_brep_check(path, &faces, &invalid) == 0 && faces == a.face_occurrences &&
              invalid == 0,
          "BRepCheck_Analyzer: %u of %u located faces invalid", invalid, faces);
    printf("  BREP: %u faces, %llu occurrences written and read back; BRepCheck: %u of %u located "
           "faces invalid\n",
           er.faces, (unsigned long long)er.occurrences, invalid, faces);
    sw_sg_scene_free(back);
    remove(path);
}

int main(int argc, char **argv)
{
    if (argc < 5) {
        fprintf(stderr, "usage: test_generate DATA_DIR WORKDIR building|vehicle N...\n");
        return 2;
    }
    g_vehicle = !strcmp(argv[3], "vehicle");
    const int n_models = g_vehicle ? SW_SG_VEHICLE_N_MODELS : SW_SG_BUILDING_N_MODELS;
    const char *const *files = g_vehicle ? sw_sg_vehicle_model_files : sw_sg_building_model_files;
    for (int m = 0; m < n_models; ++m) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", argv[1], files[m]);
        sw_sg_import_desc d = {path, NULL, NULL, NULL, NULL, 0};
        sw_status st = {0};
        if (sw_sg_import_file(&d, &g_models[m], NULL, &st) != SW_OK) {
            fprintf(stderr, "%s\n", st.message);
            return 1;
        }
    }
    for (int i = 4; i < argc; ++i) {
        const uint64_t n = strtoull(argv[i], NULL, 10);
        printf("N = %llu\n", (unsigned long long)n);
        test_determinism(n, argv[2]);
        gen_report rep;
        sw_sg_scene *s = generate(n, 1, &rep);
        if (!s)
            continue;
        test_counts(s, n, &rep);
        unsigned char *imp = imported_faces(sw_sg_scene_view_ptr(s));
        test_trims(s, imp);
        test_circles(s, imp);
        if (g_vehicle)
            test_arches(s, imp);
        free(imp);
        if (i == 4)
            test_brep(s, argv[2]);
        sw_sg_scene_free(s);
    }
    for (int m = 0; m < n_models; ++m)
        sw_sg_scene_free(g_models[m]);
    printf("%d failure(s)\n", g_failures);
    return g_failures ? 1 : 0;
}
