/* SPDX-License-Identifier: MIT */
/* Super-surfaces (Kumar et al. 1997 §3; lod/static/sw_lod_supersurface.h):
 *
 *  1. The Gauss-map cone bounds the true normals: S_u x S_v from the scenegraph's NURBS evaluator
 *     (sw_sg_surface_eval_d2, an independent code path) on a dense grid of every Bézier patch of
 *     the models given and of random rational patches of degree 2-7 with weights in [0.2, 5]
 *     (graph-like, wild, and with an edge collapsed to a pole). Samples where |W^3 Su x Sv| is
 *     below SW_LOD_GAUSS_VALID_REL of the largest control ray carry no direction and are counted
 *     apart. Any sample outside its cone fails; the median over patches of (largest sampled angle
 *     from the axis) / half-angle is printed as the tightness.
 *  2. The pseudo-normal net is W^3 (S_u x S_v): de Casteljau on the net against the evaluator's
 *     derivatives at random (s, t), relative to |W|^3 |S_s| |S_t|, within 1e-9 beyond what the
 *     rounding of positions explains (sliver and collapsed patches have derivatives at that level);
 *     and the net's true degree is at most (3m-2, 3n-2): every row's and column's top forward
 *     difference vanishes to 1e-9 beyond rounding.
 *  3. Clusters: every patch of every face in exactly one cluster; each cluster's cone within alpha
 *     (merge_alpha when SW_LOD_SS_MERGED, 90 degrees when SW_LOD_SS_MERGED_TINY) and containing
 *     every member patch's cone; sampled surface points inside the cluster's box; each cluster
 *     connected under the adjacency it reports; cross-face pairs only between B-rep-adjacent
 *     faces; two builds identical.
 *  4. Prints per model: faces, patches, clusters, mean patches per cluster, merges, build time.
 *
 * Usage: test_supersurface [--random N] [--alpha DEG] [--min PATCHES] [model files...]
 */
#include "sw_lod_bezier.h"
#include "sw_lod_supersurface.h"
#include "model_import.h"
#include "sw_sg_import.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define GRID 24

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;

static double rnd(double lo, double hi)
{
    rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * (double)(rng_state >> 11) / 9007199254740992.0;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double angle(const double *a, const double *b)
{
    const double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                         a[0] * b[1] - a[1] * b[0]};
    return atan2(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]),
                 a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
}

static double norm3(const double *a)
{
    return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
}

static void cross(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static double diagonal(const double *b)
{
    return sqrt((b[3] - b[0]) * (b[3] - b[0]) + (b[4] - b[1]) * (b[4] - b[1]) +
                (b[5] - b[2]) * (b[5] - b[2]));
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* ---- checks 1 and 2 on one patch ------------------------------------------------------------- */
typedef struct cone_stats {
    long patches, full, samples, degenerate, violations, identity_checked, identity_bad;
    double worst_excess, worst_identity, worst_identity_raw;
    long blurred, degree_bad;
    double worst_degree;
    double *ratios;
    long n_ratios, cap_ratios;
    double *scratch;
    size_t cap_scratch;
} cone_stats;

/* A Bézier net as a NURBS surface over [0,1]^2 for the scenegraph evaluator. */
typedef struct bez_surface {
    sw_sg_surface s;
    double ku[64], kv[64];
} bez_surface;

static void as_surface(int32_t m, int32_t n, const double *cpw, bez_surface *b)
{
    for (int32_t k = 0; k <= m; ++k)
        b->ku[k] = 0.0, b->ku[m + 1 + k] = 1.0;
    for (int32_t k = 0; k <= n; ++k)
        b->kv[k] = 0.0, b->kv[n + 1 + k] = 1.0;
    b->s = (sw_sg_surface){m, n, m + 1, n + 1, b->ku, b->kv, cpw};
}

/* S_s x S_t (local parameters) and W at (s, t) of the patch evaluated by the evaluator over
 * surface `s` and parameter rectangle r (the patch's part of s). */
static void local_normal(const sw_sg_surface *s, const double r[4], double ls, double lt,
                         double nrm[3], double ds[3], double dt[3])
{
    sw_sg_surface_d2 d;
    sw_sg_surface_eval_d2(s, r[0] + ls * (r[1] - r[0]), r[2] + lt * (r[3] - r[2]), &d);
    for (int a = 0; a < 3; ++a)
        ds[a] = d.du[a] * (r[1] - r[0]), dt[a] = d.dv[a] * (r[3] - r[2]);
    cross(ds, dt, nrm);
}

static double *scratch_for(cone_stats *cs, size_t need)
{
    if (need > cs->cap_scratch) {
        cs->scratch = realloc(cs->scratch, need * sizeof *cs->scratch);
        cs->cap_scratch = need;
    }
    return cs->scratch;
}

static void check_patch(cone_stats *cs, int32_t m, int32_t n, const double *cpw,
                        const sw_sg_surface *s, const double r[4])
{
    if (m > SW_LOD_GAUSS_MAX_DEGREE || n > SW_LOD_GAUSS_MAX_DEGREE)
        return;
    const size_t nc = sw_lod_bez_count(3 * m - 1, 3 * n - 1, 1);
    double *scratch = scratch_for(cs, sw_lod_gauss_scratch_bound(m, n) + 4 * nc);
    double *net = scratch + sw_lod_gauss_scratch_bound(m, n), *mag = net + 3 * nc;
    sw_lod_cone cone;
    const int bounded = sw_lod_gauss_cone(m, n, cpw, scratch, &cone);
    sw_lod_pseudo_normal_net(m, n, cpw, scratch, net, mag);
    double longest = 0.0;
    for (size_t k = 0; k < nc; ++k)
        longest = fmax(longest, norm3(net + 3 * k));
    ++cs->patches;
    /* The reference derivatives are known only to the rounding of positions (the extraction's
     * knot insertion and the evaluator both work at |x| * eps): delta bounds that error over a
     * unit of local parameter, generously. */
    double xmax = 0.0;
    for (int32_t k = 0; k < (m + 1) * (n + 1); ++k)
        xmax = fmax(xmax, norm3(cpw + 4 * k) / cpw[4 * k + 3]);
    const double delta = 1e-12 * xmax;
    /* 2: the identity at a few random points */
    for (int k = 0; k < 4; ++k) {
        const double ls = rnd(0.0, 1.0), lt = rnd(0.0, 1.0);
        double nrm[3], ds[3], dt[3], h[4], bez[3];
        local_normal(s, r, ls, lt, nrm, ds, dt);
        sw_lod_bez_eval(m, n, 4, cpw, ls, lt, h);
        sw_lod_bez_eval(3 * m - 1, 3 * n - 1, 3, net, ls, lt, bez);
        const double w3 = h[3] * h[3] * h[3], scale = w3 * norm3(ds) * norm3(dt);
        if (!(scale > 0.0))
            continue;
        const double e[3] = {bez[0] - w3 * nrm[0], bez[1] - w3 * nrm[1], bez[2] - w3 * nrm[2]};
        /* beyond what the positions' rounding explains, relative to the size of the product */
        const double rel = fmax(0.0, norm3(e) - fabs(w3) * delta * (norm3(ds) + norm3(dt))) / scale;
        ++cs->identity_checked;
        cs->worst_identity_raw = fmax(cs->worst_identity_raw, norm3(e) / scale);
        if (rel > cs->worst_identity)
            cs->worst_identity = rel;
        if (!(rel <= 1e-9)) {
            ++cs->identity_bad;
        }
    }
    /* The header's claim that N has degree <= (3m-2, 3n-2): the top forward difference of every
     * row (and column) of the (3m-1, 3n-1) net vanishes. */
    for (int dir = 0; dir < 2; ++dir) {
        const int32_t du = 3 * m - 1, dv = 3 * n - 1, d = dir ? dv : du, lines = dir ? du : dv;
        double row[3 * SW_LOD_GAUSS_MAX_DEGREE + 1];
        sw_lod_binomial_row(d, row);
        for (int32_t l = 0; l <= lines; ++l)
            for (int a = 0; a < 3; ++a) {
                /* relative to the coefficients, beyond their rounding (rows of zero rays at a
                 * pole are pure rounding noise) */
                double sum = 0.0, abs_sum = 0.0, noise = 0.0;
                for (int32_t i = 0; i <= d; ++i) {
                    const int32_t k = dir ? i * (du + 1) + l : l * (du + 1) + i;
                    const double c = net[3 * k + a] * row[i];
                    sum += (i % 2 ? -c : c);
                    abs_sum += fabs(c);
                    noise += 1e-12 * mag[k] * row[i];
                }
                const double excess = fmax(0.0, fabs(sum) - noise);
                if (abs_sum > 0.0) {
                    cs->worst_degree = fmax(cs->worst_degree, excess / abs_sum);
                    cs->degree_bad += !(excess <= 1e-9 * abs_sum);
                }
            }
    }
    if (!bounded) {
        ++cs->full;
        return;
    }
    /* 1: every sampled normal with a direction inside the cone */
    double worst = 0.0;
    for (int j = 0; j <= GRID; ++j)
        for (int i = 0; i <= GRID; ++i) {
            const double ls = (double)i / GRID, lt = (double)j / GRID;
            double nrm[3], ds[3], dt[3], h[4];
            local_normal(s, r, ls, lt, nrm, ds, dt);
            sw_lod_bez_eval(m, n, 4, cpw, ls, lt, h);
            ++cs->samples;
            if (!(fabs(h[3] * h[3] * h[3]) * norm3(nrm) >= SW_LOD_GAUSS_VALID_REL * longest)) {
                ++cs->degenerate;
                continue;
            }
            const double a = angle(cone.axis, nrm);
            const double blur = fmin(1.0, delta * (norm3(ds) + norm3(dt)) / norm3(nrm));
            worst = fmax(worst, a);
            cs->blurred += blur > 1e-6;
            if (a > cone.half_angle + 1e-12 + asin(blur)) {
                if (cs->violations++ < 5)
                    fprintf(stderr,
                            "outside: degrees %dx%d at (%g, %g): angle %.6g > half-angle %.6g, "
                            "|N| / longest ray %.3g\n",
                            (int)m, (int)n, ls, lt, a, cone.half_angle,
                            fabs(h[3] * h[3] * h[3]) * norm3(nrm) / longest);
                if (a - cone.half_angle > cs->worst_excess)
                    cs->worst_excess = a - cone.half_angle;
            }
        }
    if (cone.half_angle > 1e-6) {
        if (cs->n_ratios == cs->cap_ratios) {
            cs->cap_ratios = cs->cap_ratios ? 2 * cs->cap_ratios : 1024;
            cs->ratios = realloc(cs->ratios, (size_t)cs->cap_ratios * sizeof *cs->ratios);
        }
        cs->ratios[cs->n_ratios++] = worst / cone.half_angle;
    }
}

static void random_patch(int kind, int32_t m, int32_t n, double *cpw)
{
    for (int32_t j = 0; j <= n; ++j)
        for (int32_t i = 0; i <= m; ++i) {
            double *c = cpw + 4 * (j * (m + 1) + i), x[3];
            if (kind == 1) { /* wild */
                x[0] = rnd(-1, 1), x[1] = rnd(-1, 1), x[2] = rnd(-1, 1);
            } else { /* graph-like; kind 2 collapses row 0 to a pole */
                x[0] = (double)i / m + rnd(-0.1, 0.1);
                x[1] = (double)j / n + rnd(-0.1, 0.1);
                x[2] = rnd(-0.3, 0.3);
                if (kind == 2 && j == 0)
                    x[0] = 0.5, x[1] = -0.2, x[2] = 0.1;
            }
            const double w = rnd(0.2, 5.0);
            c[0] = w * x[0], c[1] = w * x[1], c[2] = w * x[2], c[3] = w;
        }
}

static void random_patches(cone_stats *cs, int per_degree)
{
    double cpw[8 * 8 * 4];
    for (int32_t m = 2; m <= 7; ++m)
        for (int32_t n = 2; n <= 7; ++n)
            for (int k = 0; k < per_degree; ++k) {
                random_patch(k % 3, m, n, cpw);
                bez_surface b;
                as_surface(m, n, cpw, &b);
                const double r[4] = {0.0, 1.0, 0.0, 1.0};
                check_patch(cs, m, n, cpw, &b.s, r);
            }
}

static int cone_report(const char *what, cone_stats *cs)
{
    double median = 0.0;
    if (cs->n_ratios) {
        qsort(cs->ratios, (size_t)cs->n_ratios, sizeof *cs->ratios, cmp_double);
        median = cs->ratios[cs->n_ratios / 2];
    }
    printf("%s: %ld patches (%ld full cones), %ld normals sampled (%ld without direction), %ld "
           "outside the cone (worst by %.3g rad); tightness median %.3f over %ld patches; "
           "identity: %ld points, %ld beyond 1e-9 beyond position rounding (worst %.3g, raw "
           "worst %.3g); %ld normals with a reference blur above 1e-6 rad; top differences of "
           "the net: %ld beyond 1e-9 (worst %.3g)\n",
           what, cs->patches, cs->full, cs->samples, cs->degenerate, cs->violations,
           cs->worst_excess, median, cs->n_ratios, cs->identity_checked, cs->identity_bad,
           cs->worst_identity, cs->worst_identity_raw, cs->blurred, cs->degree_bad,
           cs->worst_degree);
    const int fail =
        cs->violations > 0 || cs->identity_bad > 0 || cs->degree_bad > 0 || cs->patches == 0;
    free(cs->ratios);
    cs->ratios = NULL;
    cs->n_ratios = cs->cap_ratios = 0;
    return fail;
}

/* ---- check 3 --------------------------------------------------------------------------------- */
static int fail_msg(const char *path, const char *msg, long a, long b)
{
    fprintf(stderr, "%s: %s (%ld, %ld)\n", path, msg, a, b);
    return 1;
}

static int same_output(const sw_lod_supersurfaces *a, const sw_lod_supersurfaces *b)
{
    return a->n_patches == b->n_patches && a->n_clusters == b->n_clusters &&
           a->n_adjacency == b->n_adjacency &&
           !memcmp(a->patches, b->patches, a->n_patches * sizeof *a->patches) &&
           !memcmp(a->patch_cones, b->patch_cones, a->n_patches * sizeof *a->patch_cones) &&
           !memcmp(a->cluster_of, b->cluster_of, a->n_patches * sizeof *a->cluster_of) &&
           !memcmp(a->clusters, b->clusters, a->n_clusters * sizeof *a->clusters) &&
           !memcmp(a->adjacency, b->adjacency, a->n_adjacency * sizeof *a->adjacency);
}

/* Every cluster connected under the reported adjacency (union-find over pairs inside clusters). */
static uint32_t find(uint32_t *parent, uint32_t k)
{
    while (parent[k] != k)
        k = parent[k] = parent[parent[k]];
    return k;
}

static int check_connected(const char *path, const sw_lod_supersurfaces *ss)
{
    uint32_t *parent = malloc((ss->n_patches + 1) * sizeof *parent);
    for (uint32_t k = 0; k < ss->n_patches; ++k)
        parent[k] = k;
    for (uint32_t k = 0; k < ss->n_adjacency; ++k) {
        const sw_lod_ss_pair *p = &ss->adjacency[k];
        if (ss->cluster_of[p->a] == ss->cluster_of[p->b])
            parent[find(parent, p->a)] = find(parent, p->b);
    }
    int fail = 0;
    for (uint32_t c = 0; c < ss->n_clusters && !fail; ++c) {
        const sw_lod_ss_cluster *cl = &ss->clusters[c];
        const uint32_t root = find(parent, cl->first);
        for (uint32_t k = cl->first; k < cl->first + cl->count && !fail; ++k)
            if (find(parent, k) != root)
                fail = fail_msg(path, "cluster not connected", c, k);
    }
    free(parent);
    return fail;
}

static int adjacent_faces(const sw_sg_scene_view *v, uint32_t a, uint32_t b)
{
    for (uint32_t k = 0; k < v->n_adjacency; ++k)
        if ((v->adjacency[k].face_a == a && v->adjacency[k].face_b == b) ||
            (v->adjacency[k].face_a == b && v->adjacency[k].face_b == a))
            return 1;
    return 0;
}

typedef struct model_totals {
    long faces, patches, clusters, merged, cross_pairs, wide, multi_face, largest, unpaired_faces;
} model_totals;

static sw_lod_ss_desc g_desc; /* --alpha, --min */

static int check_clusters(const char *path, const sw_sg_scene *scene,
                          const sw_lod_supersurfaces *ss, cone_stats *cs, model_totals *tot)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(scene);
    int fail = 0;
    /* exactly once: mark each (face, iu, iv) of the faces' grids */
    uint64_t total = 0;
    uint32_t *first = malloc(((size_t)v->n_faces + 1) * sizeof *first),
             *nu = malloc(((size_t)v->n_faces + 1) * sizeof *nu);
    for (uint32_t f = 0; f < v->n_faces; ++f) {
        sw_sg_bezier_set set;
        if (sw_lod_face_patches(scene, f, &set, NULL) != SW_OK)
            return fail_msg(path, "face patches failed", f, 0);
        first[f] = (uint32_t)total;
        nu[f] = (uint32_t)set.n_u;
        const sw_sg_face_rec *fr = &v->faces[f];
        sw_sg_surface s;
        sw_sg_scene_face_surface(scene, f, &s);
        for (int32_t k = 0; k < set.n_u * set.n_v; ++k) {
            const sw_sg_bezier_patch *p = &set.patches[k];
            const double r[4] = {p->u0, p->u1, p->v0, p->v1};
            check_patch(cs, p->deg_u, p->deg_v, p->cpw, &s, r);
        }
        (void)fr;
        total += (uint64_t)set.n_u * (uint64_t)set.n_v;
        sw_sg_bezier_set_free(&set);
    }
    if (total != ss->n_patches)
        fail = fail_msg(path, "patch count differs from the faces' grids", (long)total,
                        (long)ss->n_patches);
    unsigned char *seen = calloc(total + 1, 1);
    uint32_t *where = calloc(total + 1, sizeof *where);
    double(*pbox)[6] = calloc(total + 1, sizeof *pbox);
    for (uint32_t k = 0; k < ss->n_patches && !fail; ++k) {
        const sw_lod_ss_patch *p = &ss->patches[k];
        const uint64_t g = first[p->face] + (uint64_t)p->iv * nu[p->face] + p->iu;
        if (p->face >= v->n_faces || g >= total || seen[g]++)
            fail = fail_msg(path, "patch missing or repeated", p->face, k);
        else
            where[g] = k;
    }
    /* surface points of every patch inside its cluster's box */
    for (uint32_t f = 0; f < v->n_faces && !fail; ++f) {
        sw_sg_bezier_set set;
        sw_lod_face_patches(scene, f, &set, NULL);
        for (int32_t k = 0; k < set.n_u * set.n_v && !fail; ++k) {
            double *pb = pbox[where[first[f] + (uint32_t)k]];
            const sw_sg_bezier_patch *bp = &set.patches[k];
            for (int a = 0; a < 3; ++a)
                pb[a] = INFINITY, pb[3 + a] = -INFINITY;
            for (int32_t q = 0; q < (bp->deg_u + 1) * (bp->deg_v + 1); ++q)
                for (int a = 0; a < 3; ++a) {
                    const double x = bp->cpw[4 * q + a] / bp->cpw[4 * q + 3];
                    pb[a] = fmin(pb[a], x), pb[3 + a] = fmax(pb[3 + a], x);
                }
            const uint32_t c = ss->cluster_of[where[first[f] + (uint32_t)k]];
            const double *box = ss->clusters[c].box;
            for (int j = 0; j <= 4; ++j)
                for (int i = 0; i <= 4; ++i) {
                    double x[3];
                    sw_sg_bezier_patch_eval(&set.patches[k], i / 4.0, j / 4.0, x);
                    for (int a = 0; a < 3; ++a) {
                        const double slack = 1e-9 * (fabs(box[a]) + fabs(box[3 + a]) + 1);
                        if (x[a] < box[a] - slack || x[a] > box[3 + a] + slack)
                            fail = fail_msg(path, "patch point outside the cluster box", c, k);
                    }
                }
        }
        sw_sg_bezier_set_free(&set);
    }
    uint32_t next = 0;
    for (uint32_t c = 0; c < ss->n_clusters && !fail; ++c) {
        const sw_lod_ss_cluster *cl = &ss->clusters[c];
        if (cl->first != next || cl->count == 0)
            fail = fail_msg(path, "clusters do not partition the patches", c, cl->first);
        next += cl->count;
        const double bound = (cl->flags & SW_LOD_SS_MERGED_TINY) ? 0.5 * M_PI
                             : (cl->flags & SW_LOD_SS_MERGED)    ? ss->merge_alpha
                                                                 : ss->alpha;
        /* a single patch wider than alpha is a cluster of its own, with its own cone */
        const int wide_patch =
            cl->count == 1 && !(cl->flags & ~(SW_LOD_SS_FULL_CONE | SW_LOD_SS_BACK_CULLABLE));
        if (!wide_patch && !(cl->half_angle <= bound + 1e-12))
            fail = fail_msg(path, "cluster cone beyond its bound", c, cl->flags);
        if ((cl->flags & SW_LOD_SS_FULL_CONE) && cl->count != 1)
            fail = fail_msg(path, "full-cone cluster with several patches", c, cl->count);
        int closed = cl->count > 0;
        for (uint32_t k = cl->first; k < cl->first + cl->count; ++k)
            closed &= (sw_sg_scene_view_ptr(scene)->faces[ss->patches[k].face].flags &
                       SW_SG_FACE_CLOSED_SHELL) != 0;
        if (!(cl->flags & SW_LOD_SS_BACK_CULLABLE) != !closed)
            fail = fail_msg(path, "back-cullable flag differs from the faces' closed shells", c,
                            cl->flags);
        const sw_lod_cone cc = {
            {cl->axis[0], cl->axis[1], cl->axis[2]}, cl->half_angle, cl->cos_half_angle};
        for (uint32_t k = cl->first; k < cl->first + cl->count && !fail; ++k) {
            if (ss->cluster_of[k] != c)
                fail = fail_msg(path, "cluster_of disagrees", c, k);
            if (!sw_lod_cone_contains(&cc, &ss->patch_cones[k], 1e-9))
                fail = fail_msg(path, "cluster cone misses a patch cone", c, k);
        }
        tot->merged += (cl->flags & (SW_LOD_SS_MERGED | SW_LOD_SS_MERGED_TINY)) != 0;
        tot->largest = cl->count > tot->largest ? cl->count : tot->largest;
        for (uint32_t k = cl->first + 1; k < cl->first + cl->count; ++k)
            if (ss->patches[k].face != ss->patches[cl->first].face) {
                ++tot->multi_face;
                break;
            }
    }
    if (!fail && next != ss->n_patches)
        fail = fail_msg(path, "clusters do not cover the patches", next, ss->n_patches);
    for (uint32_t k = 0; k < ss->n_adjacency && !fail; ++k) {
        const sw_lod_ss_pair *p = &ss->adjacency[k];
        const uint32_t fa = ss->patches[p->a].face, fb = ss->patches[p->b].face;
        if (!(p->a < p->b) || p->b >= ss->n_patches)
            fail = fail_msg(path, "bad adjacency pair", p->a, p->b);
        else if (fa != fb) {
            ++tot->cross_pairs;
            if (!adjacent_faces(v, fa, fb))
                fail = fail_msg(path, "patches of non-adjacent faces paired", fa, fb);
        }
        /* patches that share an edge have control-point boxes that meet, up to the edge
         * tolerances and the matching's allowance for chord sagitta (1 % of a chord; taken here
         * as 1 % of the smaller box's diagonal) */
        const double *x = pbox[p->a], *y = pbox[p->b];
        const double slack = 2.0 * (v->faces[fa].tolerance + v->faces[fb].tolerance) +
                             0.01 * fmin(diagonal(x), diagonal(y)) +
                             1e-9 * (fabs(x[0]) + fabs(x[3]) + fabs(x[4]) + 1.0);
        for (int a = 0; a < 3 && !fail; ++a)
            if (x[a] > y[3 + a] + slack || y[a] > x[3 + a] + slack)
                fail = fail_msg(path, "paired patches whose boxes do not meet", p->a, p->b);
    }
    /* every B-rep edge gives at least one pair of patches across it */
    for (uint32_t k = 0; k < v->n_adjacency; ++k) {
        const uint32_t fa = v->adjacency[k].face_a, fb = v->adjacency[k].face_b;
        int found = 0;
        for (uint32_t j = 0; j < ss->n_adjacency && !found; ++j) {
            const uint32_t ga = ss->patches[ss->adjacency[j].a].face;
            const uint32_t gb = ss->patches[ss->adjacency[j].b].face;
            found = (ga == fa && gb == fb) || (ga == fb && gb == fa);
        }
        tot->unpaired_faces += !found;
    }
    for (uint32_t k = 0; k < ss->n_patches; ++k)
        tot->wide += ss->patch_cones[k].half_angle > ss->alpha;
    if (!fail)
        fail = check_connected(path, ss);
    free(first);
    free(nu);
    free(seen);
    free(where);
    free(pbox);
    return fail;
}

static int check_model(const char *path, cone_stats *cs, model_totals *all)
{
    sw_sg_scene *scene = NULL;
    const int imported = sw_test_import_model(path, &scene);
    if (imported <= 0)
        return imported < 0;
    sw_lod_supersurfaces *a = NULL, *b = NULL;
    sw_status st = {0};
    const double t0 = now_s();
    const sw_result r = sw_lod_supersurfaces_build(scene, &g_desc, &a, &st);
    const double t1 = now_s();
    int fail = 0;
    if (r != SW_OK) {
        fprintf(stderr, "%s: build failed: %s\n", path, st.message);
        fail = 1;
    } else if (sw_lod_supersurfaces_build(scene, &g_desc, &b, &st) != SW_OK || !same_output(a, b)) {
        fail = fail_msg(path, "second build differs", 0, 0);
    } else {
        model_totals tot = {0};
        const long before = cs->violations;
        fail = check_clusters(path, scene, a, cs, &tot);
        const sw_sg_scene_view *v = sw_sg_scene_view_ptr(scene);
        printf("%s: %u faces, %u patches (%ld wider than alpha), %u clusters (%.2f patches "
               "each, largest %ld, %ld over several faces, %ld grown by merging), %u adjacency "
               "pairs (%ld across faces, %u B-rep face pairs, %ld of them without a patch pair), "
               "build %.1f ms, %ld cone violations\n",
               path, v->n_faces, a->n_patches, tot.wide, a->n_clusters,
               (double)a->n_patches / (a->n_clusters ? a->n_clusters : 1), tot.largest,
               tot.multi_face, tot.merged, a->n_adjacency, tot.cross_pairs, v->n_adjacency,
               tot.unpaired_faces, 1e3 * (t1 - t0), cs->violations - before);
        all->faces += v->n_faces;
        all->patches += a->n_patches;
        all->clusters += a->n_clusters;
        all->merged += tot.merged;
        all->cross_pairs += tot.cross_pairs;
        all->wide += tot.wide;
        all->multi_face += tot.multi_face;
    }
    sw_lod_supersurfaces_free(a);
    sw_lod_supersurfaces_free(b);
    sw_sg_scene_free(scene);
    return fail;
}

static int check_bad_desc(void)
{
    /* invalid descs are refused before the scene is read */
    sw_lod_ss_desc d = {200.0, 0, 0.0, 0.0};
    sw_lod_supersurfaces *out = (sw_lod_supersurfaces *)&d;
    sw_status st = {0};
    const sw_result r = sw_lod_supersurfaces_build(NULL, &d, &out, &st);
    if (r != SW_ERR_INVALID_ARGUMENT || out != NULL) {
        fprintf(stderr, "alpha 200: expected SW_ERR_INVALID_ARGUMENT, got %d\n", (int)r);
        return 1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    int per_degree = 0, fail = check_bad_desc();
    cone_stats models = {0}, random = {0};
    model_totals all = {0};
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--random") && i + 1 < argc)
            per_degree = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--alpha") && i + 1 < argc)
            g_desc.alpha_deg = atof(argv[++i]);
        else if (!strcmp(argv[i], "--min") && i + 1 < argc)
            g_desc.min_patches = (uint32_t)atoi(argv[++i]);
        else
            fail |= check_model(argv[i], &models, &all);
    }
    if (models.patches)
        fail |= cone_report("model patches", &models);
    if (all.patches)
        printf("all models: %ld faces, %ld patches (%ld wider than alpha), %ld clusters (%.2f "
               "patches each, %ld over several faces, %ld grown by merging), %ld cross-face "
               "pairs\n",
               all.faces, all.patches, all.wide, all.clusters, (double)all.patches / all.clusters,
               all.multi_face, all.merged, all.cross_pairs);
    if (per_degree > 0) {
        random_patches(&random, per_degree);
        fail |= cone_report("random patches (degrees 2-7, weights 0.2-5)", &random);
    }
    free(models.scratch);
    free(random.scratch);
    printf("%s\n", fail ? "FAIL" : "PASS");
    return fail;
}
