/* SPDX-License-Identifier: MIT */
/* "Every bound holds and is tight": the rigorous error bounds of lod/ (error_bound.c)
 * for degree reduction to bicubic leaves (§6.1), pairwise simplification (§6.2) and trim curves
 * approximated by rational cubics (§4.1), checked against the distance measured independently:
 * both surfaces evaluated with the scenegraph kernel (sw_sg_bezier_patch_eval, sw_sg_curve_eval),
 * a dense grid of samples, then a pattern search around the worst sample. Inputs: random rational
 * patches and curves of degree 2-7 with weights in [0.2, 5], and every Bézier patch / trim curve of
 * the model files given on the command line.
 *
 * Usage: test_lod_bounds [--random N] [--stride K] [model files...]
 * Also builds every face's hierarchy (lod/hierarchy/hierarchy.c) and checks its nodes' accumulated
 * bounds against the exact NURBS surface. Prints, per kind: items checked, violations (measured >
 * bound), exact cases (bound at rounding level, left out of the ratio), median and minimum of
 * measured / bound. Fails (exit 1) on any violation or a median ratio below 0.1.
 */
#include "sw_lod_bezier.h"
#include "sw_lod_hierarchy.h"
#include "sw_lod_reduce.h"
#include "model_import.h"
#include "sw_sg_import.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- statistics ------------------------------------------------------------------------------ */
typedef struct stats {
    const char *name;
    long checked, violations, exact;
    double *ratios;
    long n, cap;
    double worst_excess;   /* largest (measured - bound) / bound among violations */
    int ratio_informative; /* accumulated bounds: the median is printed, not required */
} stats;

static void stats_add(stats *s, double measured, double bound, double scale)
{
    ++s->checked;
    /* The measurement itself rounds: points are evaluated in absolute coordinates. */
    const double slack = 256.0 * DBL_EPSILON * scale;
    if (!(measured <= bound + slack)) {
        ++s->violations;
        double ex = (measured - bound) / fmax(bound, 1e-300);
        if (ex > s->worst_excess)
            s->worst_excess = ex;
        if (s->violations <= 5)
            fprintf(stderr, "%s: VIOLATION measured %.17g > bound %.17g\n", s->name, measured,
                    bound);
    }
    if (bound <= 1e-8 * scale) {
        ++s->exact;
        return;
    }
    if (s->n == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 256;
        s->ratios = realloc(s->ratios, (size_t)s->cap * sizeof *s->ratios);
        if (!s->ratios) {
            fprintf(stderr, "out of memory\n");
            exit(2);
        }
    }
    if (getenv("SW_LOD_DEBUG") && measured < 0.5 * bound)
        fprintf(stderr, "%s: loose: measured %.6g bound %.6g scale %.3g\n", s->name, measured,
                bound, scale);
    s->ratios[s->n++] = measured / bound;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Prints the line and returns 1 when the kind failed. */
static int stats_report(stats *s)
{
    double median = NAN, lo = NAN;
    if (s->n > 0) {
        qsort(s->ratios, (size_t)s->n, sizeof *s->ratios, cmp_double);
        median = s->ratios[s->n / 2];
        lo = s->ratios[0];
    }
    printf("%-15s checked %7ld  violations %ld  exact %6ld  median measured/bound %.4f  min %.4f\n",
           s->name, s->checked, s->violations, s->exact, median, lo);
    int fail = s->violations > 0 || (!s->ratio_informative && s->n > 0 && !(median >= 0.1));
    free(s->ratios);
    return fail;
}

/* ---- measuring a distance -------------------------------------------------------------------- */
/* A distance function over [0,1]^d (d = 1 or 2), maximized by grid + pattern search. */
typedef double (*dist_fn)(const void *ctx, double x, double y);

static double measure_max(dist_fn f, const void *ctx, int two_d, int grid)
{
    double bx = 0.0, by = 0.0, best = -1.0;
    for (int j = 0; j <= (two_d ? grid : 0); ++j)
        for (int i = 0; i <= grid; ++i) {
            double x = (double)i / grid, y = two_d ? (double)j / grid : 0.0;
            double d = f(ctx, x, y);
            if (d > best) {
                best = d;
                bx = x;
                by = y;
            }
        }
    double h = 0.5 / grid;
    for (int it = 0; it < 400 && h > 1e-9; ++it) {
        double nbx = bx, nby = by, nbest = best;
        for (int dj = two_d ? -1 : 0; dj <= (two_d ? 1 : 0); ++dj)
            for (int di = -1; di <= 1; ++di) {
                double x = fmin(1.0, fmax(0.0, bx + di * h)), y = fmin(1.0, fmax(0.0, by + dj * h));
                double d = f(ctx, x, y);
                if (d > nbest) {
                    nbest = d;
                    nbx = x;
                    nby = y;
                }
            }
        if (nbest > best) {
            best = nbest;
            bx = nbx;
            by = nby;
        } else {
            h *= 0.5;
        }
    }
    return best;
}

static double dist3(const double a[3], const double b[3])
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

/* Original patch over rect (its local coordinates) against a bicubic over [0,1]^2. */
typedef struct patch_cmp {
    const sw_sg_bezier_patch *orig, *approx;
    double rect[4];
} patch_cmp;

static double patch_dist(const void *ctx, double x, double y)
{
    const patch_cmp *c = ctx;
    double a[3], b[3];
    sw_sg_bezier_patch_eval(c->orig, c->rect[0] + x * (c->rect[1] - c->rect[0]),
                            c->rect[2] + y * (c->rect[3] - c->rect[2]), a);
    sw_sg_bezier_patch_eval(c->approx, x, y, b);
    return dist3(a, b);
}

static sw_sg_bezier_patch bez(int32_t du, int32_t dv, double *cpw)
{
    sw_sg_bezier_patch p = {du, dv, 0, 0, 0.0, 1.0, 0.0, 1.0, cpw};
    return p;
}

static double net_scale(int32_t count, const double *cpw, int32_t dim)
{
    double m = 0.0;
    for (int32_t k = 0; k < count; ++k)
        for (int32_t a = 0; a + 1 < dim; ++a)
            m = fmax(m, fabs(cpw[k * dim + a] / cpw[k * dim + dim - 1]));
    return m;
}

static double net_diag(int32_t count, const double *cpw, int32_t dim)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, d = 0;
    for (int32_t k = 0; k < count; ++k)
        for (int32_t a = 0; a + 1 < dim; ++a) {
            lo[a] = fmin(lo[a], cpw[k * dim + a] / cpw[k * dim + dim - 1]);
            hi[a] = fmax(hi[a], cpw[k * dim + a] / cpw[k * dim + dim - 1]);
        }
    for (int32_t a = 0; a + 1 < dim; ++a)
        d += (hi[a] - lo[a]) * (hi[a] - lo[a]);
    return sqrt(d);
}

/* ---- the three kinds of checks -------------------------------------------------------------- */
typedef struct checks {
    stats reduce, simplify, trim, hierarchy;
    int grid;
} checks;

static void check_reduction(checks *ck, int32_t du, int32_t dv, double *cpw)
{
    const int32_t count = (du + 1) * (dv + 1);
    const double diag = net_diag(count, cpw, 4), scale = net_scale(count, cpw, 4);
    if (!(diag > 0.0))
        return;
    sw_lod_reduce_desc desc = {1e-3 * diag, 6, {0.0, 0}};
    sw_lod_leaf_set set;
    if (sw_lod_reduce_leaves(du, dv, cpw, &desc, &set, NULL) != SW_OK) {
        fprintf(stderr, "reduce_leaves failed\n");
        exit(2);
    }
    sw_sg_bezier_patch orig = bez(du, dv, cpw);
    for (int32_t k = 0; k < set.count; ++k) {
        sw_lod_bicubic_leaf *l = &set.leaves[k];
        sw_sg_bezier_patch ap = bez(3, 3, l->cpw);
        patch_cmp c = {&orig, &ap, {l->rect[0], l->rect[1], l->rect[2], l->rect[3]}};
        stats_add(&ck->reduce, measure_max(patch_dist, &c, 1, ck->grid), l->error, scale);
    }
    sw_lod_leaf_set_free(&set);
}

/* Two halves of a patch (split at s along dir), each reduced; their simplification checked
 * against each half. */
static void check_simplification(checks *ck, int32_t du, int32_t dv, double *cpw, int dir, double s)
{
    const int32_t count = (du + 1) * (dv + 1);
    const double scale = net_scale(count, cpw, 4);
    double *piece = malloc(sw_lod_bez_count(du, dv, 4) * sizeof *piece);
    double child[2][64];
    for (int h = 0; h < 2; ++h) {
        double r[4] = {0.0, 1.0, 0.0, 1.0};
        r[2 * dir + (h ? 0 : 1)] = s;
        sw_lod_bez_restrict(du, dv, 4, cpw, r, piece);
        sw_lod_reduce_bicubic(du, dv, piece, child[h], NULL);
    }
    free(piece);
    sw_lod_simplify_result res;
    if (sw_lod_simplify_pair(child[0], child[1], dir, s, NULL, &res, NULL) != SW_OK) {
        fprintf(stderr, "simplify failed\n");
        exit(2);
    }
    sw_sg_bezier_patch whole = bez(3, 3, res.cpw);
    for (int h = 0; h < 2; ++h) {
        sw_sg_bezier_patch ch = bez(3, 3, child[h]);
        /* the child over [0,1]^2 against the simplified patch over its part: swap roles so that
         * the rect maps into the simplified patch */
        patch_cmp c = {&whole, &ch, {0.0, 1.0, 0.0, 1.0}};
        c.rect[2 * dir] = h ? s : 0.0;
        c.rect[2 * dir + 1] = h ? 1.0 : s;
        stats_add(&ck->simplify, measure_max(patch_dist, &c, 1, ck->grid), res.error[h], scale);
    }
}

typedef struct curve_cmp {
    const sw_sg_curve *orig, *approx;
    double t0, t1;
} curve_cmp;

static double curve_dist(const void *ctx, double x, double y)
{
    (void)y;
    const curve_cmp *c = ctx;
    double a[2], b[2];
    sw_sg_curve_eval(c->orig, c->t0 + x * (c->t1 - c->t0), a);
    sw_sg_curve_eval(c->approx, x, b);
    return hypot(a[0] - b[0], a[1] - b[1]);
}

static void check_trim_curve(checks *ck, const sw_sg_curve *c)
{
    const double diag = net_diag(c->n, c->cpw, 3), scale = net_scale(c->n, c->cpw, 3);
    if (!(diag > 0.0))
        return;
    sw_lod_reduce_desc desc = {1e-4 * diag, 10, {0.0, 0}};
    sw_lod_cubic_set set;
    if (sw_lod_trim_curve_to_cubics(c, &desc, &set, NULL) != SW_OK) {
        fprintf(stderr, "trim_curve_to_cubics failed\n");
        exit(2);
    }
    static const double k01[8] = {0, 0, 0, 0, 1, 1, 1, 1};
    for (int32_t k = 0; k < set.count; ++k) {
        const sw_lod_cubic_piece *p = &set.pieces[k];
        sw_sg_curve ap = {3, 4, 3, k01, p->cpw};
        curve_cmp cc = {c, &ap, p->t0, p->t1};
        stats_add(&ck->trim, measure_max(curve_dist, &cc, 0, 8 * ck->grid), p->error, scale);
    }
    sw_lod_cubic_set_free(&set);
}

/* A face's whole hierarchy: every `stride`-th representable node (and the root) against the
 * exact NURBS surface over the node's rectangle. Node errors accumulate simplification bounds
 * (triangle inequality), so their ratio is reported but not required to be tight. */
typedef struct node_cmp {
    const sw_sg_surface *s;
    const sw_lod_hnode *n;
} node_cmp;

static double node_dist(const void *ctx, double x, double y)
{
    const node_cmp *c = ctx;
    const double *r = c->n->rect;
    double a[3], b[3];
    sw_sg_surface_eval(c->s, r[0] + x * (r[1] - r[0]), r[2] + y * (r[3] - r[2]), a);
    sw_sg_bezier_patch bp = {3, 3, 0, 0, 0.0, 1.0, 0.0, 1.0, (double *)c->n->cpw};
    sw_sg_bezier_patch_eval(&bp, x, y, b);
    return dist3(a, b);
}

static void check_hierarchy(checks *ck, const sw_sg_surface *s, const sw_sg_face_rec *face)
{
    sw_lod_hierarchy_desc desc = {0};
    desc.use_box = (face->flags & SW_SG_FACE_TRIMMED) != 0;
    for (int k = 0; k < 4; ++k)
        desc.uv_box[k] = face->uv_box[k];
    sw_lod_hierarchy *h = NULL;
    if (sw_lod_hierarchy_build(s, &desc, &h, NULL) != SW_OK) {
        fprintf(stderr, "hierarchy build failed\n");
        exit(2);
    }
    const double scale = net_scale(s->n_u * s->n_v, s->cpw, 4);
    for (int32_t i = 0; i < h->n_nodes; ++i) {
        const sw_lod_hnode *n = &h->nodes[i];
        if (!sw_lod_hnode_cpw_ptr(n) || (i % 5 && i != h->root))
            continue;
        node_cmp c = {s, n};
        stats_add(&ck->hierarchy, measure_max(node_dist, &c, 1, ck->grid), n->error, scale);
    }
    sw_lod_hierarchy_free(h);
}

/* ---- inputs ---------------------------------------------------------------------------------- */
static uint64_t rng_state = 0x9E3779B97F4A7C15ull;

static double rnd(void) /* [0, 1) */
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) * 0x1.0p-53;
}

static double rnd_weight(void) /* log-uniform in [0.2, 5] */
{
    return exp(log(0.2) + rnd() * (log(5.0) - log(0.2)));
}

static void random_patches(checks *ck, int per_degree)
{
    double cpw[8 * 8 * 4];
    for (int32_t du = 2; du <= 7; ++du)
        for (int32_t dv = 2; dv <= 7; ++dv)
            for (int r = 0; r < per_degree; ++r) {
                for (int32_t j = 0; j <= dv; ++j)
                    for (int32_t i = 0; i <= du; ++i) {
                        double *p = cpw + (j * (du + 1) + i) * 4, w = rnd_weight();
                        double x = (double)i / du + 0.3 * (2 * rnd() - 1);
                        double y = (double)j / dv + 0.3 * (2 * rnd() - 1);
                        double z = 0.4 * (2 * rnd() - 1);
                        p[0] = w * x;
                        p[1] = w * y;
                        p[2] = w * z;
                        p[3] = w;
                    }
                check_reduction(ck, du, dv, cpw);
                check_simplification(ck, du, dv, cpw, r & 1, 0.2 + 0.6 * rnd());
            }
}

static void random_curves(checks *ck, int per_degree)
{
    double cpw[12 * 3], knots[12 + 8];
    for (int32_t p = 2; p <= 7; ++p)
        for (int r = 0; r < 4 * per_degree; ++r) {
            const int32_t n = p + 1 + (r % 4); /* 0..3 interior knots */
            for (int32_t i = 0; i < n; ++i) {
                double w = rnd_weight(), a = 3.0 * i / n;
                cpw[i * 3] = w * (cos(a) + 0.3 * (2 * rnd() - 1));
                cpw[i * 3 + 1] = w * (sin(a) + 0.3 * (2 * rnd() - 1));
                cpw[i * 3 + 2] = w;
            }
            for (int32_t k = 0; k < n + p + 1; ++k)
                knots[k] = k <= p ? 0.0 : k >= n ? 1.0 : (double)(k - p) / (n - p);
            sw_sg_curve c = {p, n, 3, knots, cpw};
            check_trim_curve(ck, &c);
        }
}

static int check_model(checks *ck, const char *path, int stride)
{
    sw_sg_scene *scene = NULL;
    const int imported = sw_test_import_model(path, &scene);
    if (imported <= 0)
        return imported < 0;
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(scene);
    long patches = 0, curves = 0, counter = 0;
    for (uint32_t f = 0; f < v->n_faces; ++f) {
        sw_sg_surface s;
        sw_sg_scene_face_surface(scene, f, &s);
        sw_sg_bezier_set set;
        if (sw_sg_surface_extract_bezier(&s, &set, NULL) != SW_OK)
            continue;
        for (int32_t k = 0; k < set.n_u * set.n_v; ++k, ++counter) {
            if (counter % stride)
                continue;
            sw_sg_bezier_patch *p = &set.patches[k];
            check_reduction(ck, p->deg_u, p->deg_v, p->cpw);
            check_simplification(ck, p->deg_u, p->deg_v, p->cpw, (int)(counter & 1), 0.37);
            ++patches;
        }
        sw_sg_bezier_set_free(&set);
        const sw_sg_face_rec *fr = &v->faces[f];
        if (f % (uint32_t)stride == 0)
            check_hierarchy(ck, &s, fr);
        for (uint32_t l = fr->first_loop; l < fr->first_loop + fr->n_loops; ++l) {
            const sw_sg_loop_rec *lr = &v->loops[l];
            for (uint32_t c = lr->first_curve; c < lr->first_curve + lr->n_curves; ++c, ++counter) {
                if (counter % stride)
                    continue;
                sw_sg_curve cv;
                sw_sg_scene_curve(scene, c, &cv);
                check_trim_curve(ck, &cv);
                ++curves;
            }
        }
    }
    printf("%s: %u faces, %ld Bézier patches and %ld trim curves checked\n", path, v->n_faces,
           patches, curves);
    sw_sg_scene_free(scene);
    return 0;
}

int main(int argc, char **argv)
{
    checks ck;
    memset(&ck, 0, sizeof ck);
    ck.reduce.name = "reduction";
    ck.simplify.name = "simplification";
    ck.trim.name = "trim curves";
    ck.hierarchy.name = "hierarchy nodes";
    ck.hierarchy.ratio_informative = 1;
    ck.grid = 12;
    int per_degree = 0, stride = 1, fail = 0;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--random") && i + 1 < argc)
            per_degree = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--stride") && i + 1 < argc)
            stride = atoi(argv[++i]) > 0 ? atoi(argv[i]) : 1;
        else
            fail |= check_model(&ck, argv[i], stride);
    }
    if (per_degree > 0) {
        random_patches(&ck, per_degree);
        random_curves(&ck, per_degree);
        printf("random: %d patches per degree pair 2..7 x 2..7, %d curves per degree 2..7\n",
               per_degree, 4 * per_degree);
    }
    fail |= stats_report(&ck.reduce);
    fail |= stats_report(&ck.simplify);
    fail |= stats_report(&ck.trim);
    fail |= stats_report(&ck.hierarchy);
    printf("%s\n", fail ? "FAIL" : "PASS");
    return fail;
}
