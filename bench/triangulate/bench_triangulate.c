/* SPDX-License-Identifier: MIT */
/* bench_triangulate: the static-LOD builder's constrained Delaunay triangulation (CGAL, GPL-3,
 * modules/lodbuild/trim_mesh_cgal.cpp) against the one permissively licensed constrained
 * triangulator Debian 12 ships, GEOS 3.11's polygon CDT (LGPL-2.1,
 * GEOSConstrainedDelaunayTriangulation), on the trimmed domains of real faces.
 *
 * What level 0 of a static LOD needs (Kumar et al. 1997 §4.3; modules/lodbuild/static_lod.c): the
 * face's flattened trim loops as constraints, the knot lines of its Bézier patches as interior
 * constraints, interior sample points, then refinement points inserted until every triangle is
 * within its deviation bound. GEOS's polygon CDT takes a polygon with holes and nothing else: no
 * interior point and no interior segment. So it can stand in only where level 0 needs neither: an
 * affine face (a plane; sw_sg_surface_affine) with a single Bézier patch. This program counts, per
 * model, the faces of each class and, on the faces both can triangulate (the loops alone as
 * constraints), compares time, triangle counts, the smallest angle and failures, with the same
 * flattened loops given to both.
 *
 * usage: bench_triangulate [--tol REL] MODEL... (.brep/.step/.iges or .sws)
 *   --tol REL   loops flattened within REL x the face's domain size (default 1e-3)
 */
#include "cli_numbers.h"
#include "sw_lod_trim_mesh.h"
#include "sw_sg_geom.h"
#include "sw_sg_import.h"
#include "sw_sg_scene.h"
#include "sw_sg_trim.h"
#include "sw_clock.h"

#include <geos_c.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct tally {
    uint32_t faces, affine_single, needs_points, both_ok, cgal_failed, geos_failed;
    uint64_t cgal_triangles, geos_triangles;
    double cgal_ms, geos_ms, cgal_min_angle, geos_min_angle;
} tally;

static void geos_notice(const char *fmt, ...)
{
    (void)fmt; /* GEOS's notices and errors are counted as failures by the caller */
}

/* Smallest angle of triangle a, b, c, in degrees. */
static double min_angle(const double *a, const double *b, const double *c)
{
    const double *p[3] = {a, b, c};
    double best = 180.0;
    for (int i = 0; i < 3; i++) {
        const double *o = p[i], *x = p[(i + 1) % 3], *y = p[(i + 2) % 3];
        const double ux = x[0] - o[0], uy = x[1] - o[1], vx = y[0] - o[0], vy = y[1] - o[1];
        const double ang = fabs(atan2(ux * vy - uy * vx, ux * vx + uy * vy)) * 180.0 / M_PI;
        if (ang < best)
            best = ang;
    }
    return best;
}

/* CGAL: every loop vertex, every loop segment constrained; the triangles inside the loops
 * (even-odd, as the builder keeps them). Returns the triangles kept, or -1. */
static long cgal_triangulate(const sw_sg_polyline *loops, uint32_t n_loops, double *min_ang)
{
    sw_lod_cdt *cdt = NULL;
    sw_status st = {0};
    if (sw_lod_cdt_create(&cdt, &st) != SW_OK)
        return -1;
    long kept = -1;
    for (uint32_t l = 0; l < n_loops; l++) {
        const uint32_t n = loops[l].count;
        uint32_t *tags = malloc(n * sizeof *tags), *ids = malloc(n * sizeof *ids);
        uint32_t *pairs = malloc(2 * n * sizeof *pairs);
        int ok = tags && ids && pairs;
        for (uint32_t i = 0; ok && i < n; i++)
            tags[i] = i;
        ok = ok && sw_lod_cdt_insert_points(cdt, loops[l].uv, tags, n, ids, &st) == SW_OK;
        for (uint32_t i = 0; ok && i < n; i++) {
            pairs[2 * i] = ids[i];
            pairs[2 * i + 1] = ids[(i + 1) % n];
        }
        ok = ok && sw_lod_cdt_insert_constraints(cdt, pairs, n, &st) == SW_OK;
        free(tags);
        free(ids);
        free(pairs);
        if (!ok)
            goto done;
    }
    sw_lod_cdt_mesh m = {0};
    if (sw_lod_cdt_snapshot(cdt, &m, &st) != SW_OK)
        goto done;
    kept = 0;
    for (uint32_t t = 0; t < m.n_triangles; t++) {
        const double *a = m.uv + 2 * m.tri[3 * t], *b = m.uv + 2 * m.tri[3 * t + 1];
        const double *c = m.uv + 2 * m.tri[3 * t + 2];
        const double cu = (a[0] + b[0] + c[0]) / 3.0, cv = (a[1] + b[1] + c[1]) / 3.0;
        if (!sw_sg_trim_classify(loops, n_loops, cu, cv))
            continue;
        kept++;
        const double ang = min_angle(a, b, c);
        if (ang < *min_ang)
            *min_ang = ang;
    }
    sw_lod_cdt_mesh_free(&m);
done:
    sw_lod_cdt_free(cdt);
    return kept;
}

static GEOSGeometry *ring_of(GEOSContextHandle_t g, const sw_sg_polyline *p)
{
    GEOSCoordSequence *cs = GEOSCoordSeq_create_r(g, p->count + 1, 2);
    for (uint32_t i = 0; cs && i <= p->count; i++) {
        const double *uv = p->uv + 2 * (i % p->count);
        GEOSCoordSeq_setXY_r(g, cs, i, uv[0], uv[1]);
    }
    return cs ? GEOSGeom_createLinearRing_r(g, cs) : NULL;
}

/* GEOS: the outer loop as the shell, the others as holes (what a polygon can say). Returns the
 * triangles, or -1 when GEOS refuses the polygon or fails. */
static long geos_triangulate(GEOSContextHandle_t g, const sw_sg_polyline *loops, uint32_t n_loops,
                             uint32_t outer, double *min_ang)
{
    GEOSGeometry *shell = ring_of(g, &loops[outer]);
    GEOSGeometry **holes = calloc(n_loops ? n_loops : 1, sizeof *holes);
    uint32_t nh = 0;
    for (uint32_t l = 0; holes && l < n_loops; l++)
        if (l != outer)
            holes[nh++] = ring_of(g, &loops[l]);
    GEOSGeometry *poly = shell && holes ? GEOSGeom_createPolygon_r(g, shell, holes, nh) : NULL;
    free(holes);
    if (!poly)
        return -1;
    GEOSGeometry *tris = GEOSConstrainedDelaunayTriangulation_r(g, poly);
    GEOSGeom_destroy_r(g, poly);
    if (!tris)
        return -1;
    const int n = GEOSGetNumGeometries_r(g, tris);
    for (int i = 0; i < n; i++) {
        const GEOSGeometry *t = GEOSGetGeometryN_r(g, tris, i);
        const GEOSCoordSequence *cs = GEOSGeom_getCoordSeq_r(g, GEOSGetExteriorRing_r(g, t));
        double p[3][2];
        for (unsigned k = 0; k < 3; k++)
            GEOSCoordSeq_getXY_r(g, cs, k, &p[k][0], &p[k][1]);
        const double ang = min_angle(p[0], p[1], p[2]);
        if (ang < *min_ang)
            *min_ang = ang;
    }
    GEOSGeom_destroy_r(g, tris);
    return n;
}

/* The loop of largest |area|: the shell (the scene marks outer loops, but a face may have
 * several; a polygon has one shell). */
static uint32_t largest_loop(const sw_sg_polyline *loops, uint32_t n)
{
    uint32_t best = 0;
    double best_area = -1.0;
    for (uint32_t l = 0; l < n; l++) {
        double a = 0.0;
        for (uint32_t i = 0; i < loops[l].count; i++) {
            const double *p = loops[l].uv + 2 * i,
                         *q = loops[l].uv + 2 * ((i + 1) % loops[l].count);
            a += p[0] * q[1] - q[0] * p[1];
        }
        if (fabs(a) > best_area) {
            best_area = fabs(a);
            best = l;
        }
    }
    return best;
}

static int single_patch(const sw_sg_surface *s)
{
    /* one Bézier patch: no interior knot in either direction */
    return s->n_u == s->deg_u + 1 && s->n_v == s->deg_v + 1;
}

static void bench_face(GEOSContextHandle_t g, const sw_sg_scene *scene, uint32_t f, double rel,
                       tally *t)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(scene);
    const sw_sg_face_rec *fr = &v->faces[f];
    sw_sg_surface s;
    sw_sg_scene_face_surface(scene, f, &s);
    double o[3], du[3], dv[3];
    t->faces++;
    if (!(sw_sg_surface_affine(&s, o, du, dv) && single_patch(&s))) {
        t->needs_points++; /* level 0 needs interior points or knot-line constraints */
        return;
    }
    t->affine_single++;
    if (!fr->n_loops)
        return;
    const double size = fmax(fr->uv_box[1] - fr->uv_box[0], fr->uv_box[3] - fr->uv_box[2]);
    sw_sg_polyline *loops = calloc(fr->n_loops, sizeof *loops);
    sw_status st = {0};
    int ok = loops != NULL;
    for (uint32_t l = 0; ok && l < fr->n_loops; l++)
        ok = sw_sg_trim_flatten_loop(scene, fr->first_loop + l, rel * size, 1u << 16, &loops[l],
                                     &st) == SW_OK &&
             loops[l].count >= 3;
    if (ok) {
        double ca = 180.0, ga = 180.0;
        double t0 = sw__clock_ms();
        const long nc = cgal_triangulate(loops, fr->n_loops, &ca);
        double t1 = sw__clock_ms();
        const long ng =
            geos_triangulate(g, loops, fr->n_loops, largest_loop(loops, fr->n_loops), &ga);
        double t2 = sw__clock_ms();
        t->cgal_failed += nc < 0;
        t->geos_failed += ng < 0;
        if (nc >= 0 && ng >= 0) {
            t->both_ok++;
            t->cgal_ms += t1 - t0;
            t->geos_ms += t2 - t1;
            t->cgal_triangles += (uint64_t)nc;
            t->geos_triangles += (uint64_t)ng;
            t->cgal_min_angle = fmin(t->cgal_min_angle, ca);
            t->geos_min_angle = fmin(t->geos_min_angle, ga);
        }
    }
    for (uint32_t l = 0; loops && l < fr->n_loops; l++)
        sw_sg_polyline_free(&loops[l]);
    free(loops);
}

static sw_result load(const char *path, sw_sg_scene **out, sw_status *st)
{
    const char *dot = strrchr(path, '.');
    if (dot && !strcmp(dot, ".sws"))
        return sw_sg_scene_open(path, out, st);
    sw_sg_import_desc d = {path, NULL, NULL, NULL, NULL, 0};
    return sw_sg_import_file(&d, out, NULL, st);
}

int main(int argc, char **argv)
{
    double rel = 1e-3;
    int first = 1;
    if (argc > 2 && !strcmp(argv[1], "--tol")) {
        if (sw_cli_parse_positive(argv[2], &rel))
            return sw_cli_bad_value("bench_triangulate", argv[1], argv[2], NULL);
        first = 3;
    }
    if (first >= argc || !(rel > 0.0 && rel < 1.0)) {
        fprintf(stderr, "usage: %s [--tol REL (0..1)] MODEL...\n", argv[0]);
        return 2;
    }
    GEOSContextHandle_t g = GEOS_init_r();
    GEOSContext_setNoticeHandler_r(g, geos_notice);
    GEOSContext_setErrorHandler_r(g, geos_notice);
    printf("CGAL 2D CDT (GPL-3) vs GEOS %s polygon CDT (LGPL-2.1); loops flattened within %g of "
           "each face's domain\n",
           GEOSversion(), rel);
    printf("%-24s %6s %9s %9s %7s %8s %8s %9s %9s %7s %7s %6s %6s\n", "model", "faces", "needs_pts",
           "affine1", "both", "cgal_ms", "geos_ms", "cgal_tri", "geos_tri", "cgal_a", "geos_a",
           "c_fail", "g_fail");
    tally all = {.cgal_min_angle = 180.0, .geos_min_angle = 180.0};
    for (int i = first; i < argc; i++) {
        sw_status st = {0};
        sw_sg_scene *scene = NULL;
        if (load(argv[i], &scene, &st) != SW_OK) {
            fprintf(stderr, "%s: %s\n", argv[i], st.message);
            continue;
        }
        tally t = {.cgal_min_angle = 180.0, .geos_min_angle = 180.0};
        const uint32_t n = sw_sg_scene_view_ptr(scene)->n_faces;
        for (uint32_t f = 0; f < n; f++)
            bench_face(g, scene, f, rel, &t);
        const char *name = strrchr(argv[i], '/') ? strrchr(argv[i], '/') + 1 : argv[i];
        printf("%-24s %6u %9u %9u %7u %8.2f %8.2f %9llu %9llu %7.2f %7.2f %6u %6u\n", name, t.faces,
               t.needs_points, t.affine_single, t.both_ok, t.cgal_ms, t.geos_ms,
               (unsigned long long)t.cgal_triangles, (unsigned long long)t.geos_triangles,
               t.cgal_min_angle, t.geos_min_angle, t.cgal_failed, t.geos_failed);
        all.faces += t.faces;
        all.needs_points += t.needs_points;
        all.affine_single += t.affine_single;
        all.both_ok += t.both_ok;
        all.cgal_ms += t.cgal_ms;
        all.geos_ms += t.geos_ms;
        all.cgal_triangles += t.cgal_triangles;
        all.geos_triangles += t.geos_triangles;
        all.cgal_failed += t.cgal_failed;
        all.geos_failed += t.geos_failed;
        all.cgal_min_angle = fmin(all.cgal_min_angle, t.cgal_min_angle);
        all.geos_min_angle = fmin(all.geos_min_angle, t.geos_min_angle);
        sw_sg_scene_free(scene);
    }
    printf("%-24s %6u %9u %9u %7u %8.2f %8.2f %9llu %9llu %7.2f %7.2f %6u %6u\n", "all", all.faces,
           all.needs_points, all.affine_single, all.both_ok, all.cgal_ms, all.geos_ms,
           (unsigned long long)all.cgal_triangles, (unsigned long long)all.geos_triangles,
           all.cgal_min_angle, all.geos_min_angle, all.cgal_failed, all.geos_failed);
    GEOS_finish_r(g);
    return 0;
}
