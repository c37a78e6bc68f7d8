/* SPDX-License-Identifier: MIT */
/* Occlusion culling (gpu/occlusion.h, sw_gpu_frame_desc.occluders):
 *  1. The map against a dense reference, no GL: planar polygons with holes (straight and jagged
 *     edges, seen at grazing angles, crossing the near plane) drawn into the map from random views.
 *     Every map pixel marked covered must be covered by the polygon at each of 11 x 11 points of
 * its square (ray cast, even-odd), no nearer to an edge than the margin on screen, and its stored
 *     depth no nearer than the plane's there. A box the map calls hidden must be behind the stored
 *     depth at each of its surface samples. Not vacuous: a share of the pixels the polygon covers
 *     with room to spare must be marked. It catches a fill without the edge band (pixels across a
 *     hole's edge), the depth taken at the pixel centre instead of its farthest corner, a clip at
 *     the near plane that keeps what is behind the eye, and a box test that skips partial tiles.
 *  2. Frames of a generated building (a .sws given on the command line), converged at 320 x 240
 *     through its BVH: a walk through its rooms at eye height and views from outside, each drawn
 *     with and without occlusion culling, must be identical pixel for pixel, while the walk culls
 *     most of its faces as hidden (at least half of those the frustum keeps, over the walk). The
 *     walk's first view is drawn as a wireframe too, where nothing may be culled (lines hide
 *     nothing: culling there drops the rooms seen through them).
 *  3. The same with static LODs (Kumar et al. 1997: the frame culls the set's BVH of unit
 *     instances, each drawn from a static level or per frame): every third frame of the walk and
 *     the outside views identical with and without occlusion culling, and the walk culling at
 *     least half of its faces as hidden.
 * Usage: test_gpu_occlusion OUTDIR BUILDING.sws [--static]   (--static: part 3 only) */
#include "gpu_test_compare.h"
#include "hierarchy_support.h"
#include "occlusion.h"
#include "sw_lod_face_cones.h"
#include "sw_lod_static_set.h"
#include "sw_sg_bvh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "test_check.h"

/* ---- 1. the map against a dense reference --------------------------------------------------- */
static uint64_t g_rng = 0x9e3779b97f4a7c15ull;
static double rnd(void) /* [0, 1) */
{
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 7;
    g_rng ^= g_rng << 17;
    return (double)(g_rng >> 11) / 9007199254740992.0;
}

enum { MAX_PTS = 64, MAX_LOOPS = 3 };
typedef struct poly {
    double uv[MAX_LOOPS][MAX_PTS][2];
    uint32_t n[MAX_LOOPS], loops;
    double o[3], du[3], dv[3]; /* the plane's map, world = eye-relative */
} poly;

/* A square [0,1]^2 with a square hole and a jagged (star) hole. */
static void make_poly(poly *p)
{
    static const double outer[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    p->loops = 3;
    p->n[0] = 4;
    memcpy(p->uv[0], outer, sizeof outer);
    const double hx = 0.15 + 0.2 * rnd(), hy = 0.15 + 0.2 * rnd(), hs = 0.1 + 0.1 * rnd();
    const double hole[4][2] = {{hx, hy}, {hx, hy + hs}, {hx + hs, hy + hs}, {hx + hs, hy}};
    p->n[1] = 4;
    memcpy(p->uv[1], hole, sizeof hole);
    p->n[2] = 24;
    const double sx = 0.7, sy = 0.65;
    for (uint32_t i = 0; i < p->n[2]; ++i) {
        const double a = -2.0 * M_PI * i / p->n[2], r = (i & 1) ? 0.08 : 0.2;
        p->uv[2][i][0] = sx + r * cos(a);
        p->uv[2][i][1] = sy + r * sin(a);
    }
}

static int inside_uv(const poly *p, double u, double v)
{
    int in = 0;
    for (uint32_t l = 0; l < p->loops; ++l)
        for (uint32_t i = 0; i < p->n[l]; ++i) {
            const double *a = p->uv[l][i], *b = p->uv[l][(i + 1) % p->n[l]];
            if ((a[1] <= v) != (b[1] <= v) && u < a[0] + (v - a[1]) * (b[0] - a[0]) / (b[1] - a[1]))
                in = !in;
        }
    return in;
}

/* The ray through map point (x, y): where it meets the plane, (u, v) and depth; 0 if it misses. */
static int ray_plane(const sw__occ_map *m, const poly *p, double x, double y, double *u, double *v,
                     double *z)
{
    double dir[3];
    const double a = (x - m->cx) / m->f, b = (m->cy - y) / m->f;
    for (int k = 0; k < 3; ++k)
        dir[k] = m->fwd[k] + a * m->right[k] + b * m->up[k];
    /* o + u du + v dv = t dir: solve the 3x3 system [du dv -dir] (u v t) = -o */
    const double *c0 = p->du, *c1 = p->dv;
    const double c2[3] = {-dir[0], -dir[1], -dir[2]};
    const double det = c0[0] * (c1[1] * c2[2] - c1[2] * c2[1]) -
                       c1[0] * (c0[1] * c2[2] - c0[2] * c2[1]) +
                       c2[0] * (c0[1] * c1[2] - c0[2] * c1[1]);
    if (fabs(det) < 1e-300)
        return 0;
    const double r[3] = {-p->o[0], -p->o[1], -p->o[2]};
    *u = (r[0] * (c1[1] * c2[2] - c1[2] * c2[1]) - c1[0] * (r[1] * c2[2] - r[2] * c2[1]) +
          c2[0] * (r[1] * c1[2] - r[2] * c1[1])) /
         det;
    *v = (c0[0] * (r[1] * c2[2] - r[2] * c2[1]) - r[0] * (c0[1] * c2[2] - c0[2] * c2[1]) +
          c2[0] * (c0[1] * r[2] - c0[2] * r[1])) /
         det;
    *z = (c0[0] * (c1[1] * r[2] - c1[2] * r[1]) - c1[0] * (c0[1] * r[2] - c0[2] * r[1]) +
          r[0] * (c0[1] * c1[2] - c0[2] * c1[1])) /
         det;
    return *z > 0.0;
}

static void project(const sw__occ_map *m, const double q[3], double *x, double *y, double *z)
{
    double r = 0, u = 0, f = 0;
    for (int k = 0; k < 3; ++k) {
        r += m->right[k] * q[k];
        u += m->up[k] * q[k];
        f += m->fwd[k] * q[k];
    }
    *z = f;
    *x = m->cx + m->f * r / f;
    *y = m->cy - m->f * u / f;
}

/* Screen distance (map pixels) from (x, y) to the polygon's edges in front of the near plane:
 * each edge clipped there in 3D, projected (a segment), the point-segment distance in 2D. */
static double edge_distance(const sw__occ_map *m, const poly *p, double x, double y)
{
    double best = INFINITY;
    for (uint32_t l = 0; l < p->loops; ++l)
        for (uint32_t i = 0; i < p->n[l]; ++i) {
            const double *ua = p->uv[l][i], *ub = p->uv[l][(i + 1) % p->n[l]];
            double a[3], b[3], za = 0, zb = 0;
            for (int k = 0; k < 3; ++k) {
                a[k] = p->o[k] + ua[0] * p->du[k] + ua[1] * p->dv[k];
                b[k] = p->o[k] + ub[0] * p->du[k] + ub[1] * p->dv[k];
                za += m->fwd[k] * a[k];
                zb += m->fwd[k] * b[k];
            }
            if (za < m->near_plane && zb < m->near_plane)
                continue;
            if (za < m->near_plane || zb < m->near_plane) { /* clip the part behind */
                const double t = (m->near_plane - za) / (zb - za);
                double *moved = za < m->near_plane ? a : b;
                for (int k = 0; k < 3; ++k)
                    moved[k] = a[k] + t * (b[k] - a[k]);
            }
            double ax, ay, bx, by, z;
            project(m, a, &ax, &ay, &z);
            project(m, b, &bx, &by, &z);
            const double dx = bx - ax, dy = by - ay, l2 = dx * dx + dy * dy;
            double t = l2 > 0.0 ? ((x - ax) * dx + (y - ay) * dy) / l2 : 0.0;
            t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
            best = fmin(best, hypot(x - ax - t * dx, y - ay - t * dy));
        }
    return best;
}

static void map_case(int c)
{
    sw__gpu_view view;
    sw_gpu_camera cam = {{0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 50.0};
    /* random view direction, the polygon in front at a random distance and tilt */
    const double yaw = 0.4 * (rnd() - 0.5), pitch = 0.4 * (rnd() - 0.5);
    cam.target[0] = sin(yaw);
    cam.target[1] = sin(pitch);
    cam.target[2] = cos(yaw) * cos(pitch);
    sw_status st = {0};
    const double near_plane = 0.05;
    if (sw__gpu_view_init(&view, &cam, 256, 160, near_plane, &st) != SW_OK) {
        CHECK(0, "case %d: view: %s", c, st.message);
        return;
    }
    sw__occ_map m;
    if (!sw__occ_map_init(&m, &view, 0.5)) {
        CHECK(0, "case %d: map: out of memory", c);
        return;
    }
    poly p;
    make_poly(&p);
    const double size = 1.0 + 3.0 * rnd(), tilt = (c % 3 == 0 ? 1.45 : 1.2) * (rnd() - 0.5) * 2;
    const double dist =
        c % 4 == 0 ? 0.3 : 1.0 + 3.0 * rnd(); /* c % 4 == 0: across the near plane */
    const double rot = 2.0 * M_PI * rnd();
    const double ax[3] = {cos(rot), sin(rot), 0}, ay0[3] = {-sin(rot), cos(rot), 0};
    const double ay[3] = {ay0[0], ay0[1] * cos(tilt), sin(tilt) * (ay0[1] >= 0 ? 1 : -1)};
    for (int k = 0; k < 3; ++k) {
        p.du[k] = size * ax[k];
        p.dv[k] = size * ay[k];
        p.o[k] = -0.5 * size * (ax[k] + ay[k]);
    }
    p.o[2] += dist;
    /* the occluder set of one face, with its outline exact (err 0) */
    sw_gpu_occluders oc;
    memset(&oc, 0, sizeof oc);
    sw__occ_face face = {0, p.loops, 0.0};
    uint32_t first[MAX_LOOPS], count[MAX_LOOPS];
    double pts[3 * MAX_LOOPS * MAX_PTS];
    size_t np = 0;
    for (uint32_t l = 0; l < p.loops; ++l) {
        first[l] = (uint32_t)np;
        count[l] = p.n[l];
        for (uint32_t i = 0; i < p.n[l]; ++i, ++np)
            for (int k = 0; k < 3; ++k)
                pts[3 * np + k] = p.o[k] + p.uv[l][i][0] * p.du[k] + p.uv[l][i][1] * p.dv[k];
    }
    oc.n_faces = 1;
    oc.faces = &face;
    oc.loop_first = first;
    oc.loop_count = count;
    oc.points = pts;
    oc.n_loops = p.loops;
    oc.n_points = np;
    static const double identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    static const double eye[3] = {0, 0, 0};
    const int drawn = sw__occ_map_add_face(&m, &oc, 0, identity, eye);
    CHECK(drawn >= 0, "case %d: out of memory", c);
    long marked = 0, roomy = 0, bad_cover = 0, bad_depth = 0;
    enum { S = 11 };
    for (int32_t j = 0; j < m.h; ++j)
        for (int32_t i = 0; i < m.w; ++i) {
            const float d = m.depth[(size_t)j * m.w + i];
            const int is_marked = d < INFINITY;
            int all_in = 1;
            double zmax = 0.0;
            for (int b = 0; b < S; ++b)
                for (int a = 0; a < S; ++a) {
                    double u, v, z;
                    const double x = i + a / (S - 1.0), y = j + b / (S - 1.0);
                    if (!ray_plane(&m, &p, x, y, &u, &v, &z) || z < near_plane ||
                        !inside_uv(&p, u, v)) {
                        all_in = 0;
                        continue;
                    }
                    zmax = fmax(zmax, z);
                }
            const double ed = all_in ? edge_distance(&m, &p, i + 0.5, j + 0.5) : 0.0;
            roomy += all_in && ed > m.edge_margin + 1.0;
            if (!is_marked)
                continue;
            marked++;
            if (!all_in || ed < m.edge_margin) /* the square keeps the margin: its centre too */
                bad_cover++;
            else if (zmax > d * (1.0 + 1e-6))
                bad_depth++;
        }
    CHECK(bad_cover == 0, "case %d: %ld marked pixels not inside the polygon with the margin", c,
          bad_cover);
    CHECK(bad_depth == 0, "case %d: %ld marked pixels nearer than the plane somewhere", c,
          bad_depth);
    CHECK(roomy == 0 || marked * 2 >= roomy, "case %d: %ld of %ld roomy pixels marked", c, marked,
          roomy);
    /* boxes behind and in front of the plane: hidden only if each surface sample is behind */
    long hidden = 0, wrong = 0;
    for (int t = 0; t < 60; ++t) {
        const double cx = 0.6 * (rnd() - 0.5) * size, cy = 0.6 * (rnd() - 0.5) * size,
                     cz = dist + (rnd() * 2.0 - 0.5) * size, h = 0.02 + 0.1 * rnd() * size;
        const double box[6] = {cx - h, cy - h, cz - h, cx + h, cy + h, cz + h};
        if (!sw__occ_map_box_hidden(&m, box))
            continue;
        hidden++;
        for (int s = 0; s < 6 * 81; ++s) {
            const int face_k = s / 81, g = s % 81, axis = face_k % 3;
            double q[3];
            q[axis] = face_k < 3 ? box[axis] : box[3 + axis];
            q[(axis + 1) % 3] = box[(axis + 1) % 3] + (g % 9) / 8.0 * 2 * h;
            q[(axis + 2) % 3] = box[(axis + 2) % 3] + (g / 9) / 8.0 * 2 * h;
            double x, y, z;
            project(&m, q, &x, &y, &z);
            const int32_t pi = (int32_t)floor(x), pj = (int32_t)floor(y);
            if (pi < 0 || pj < 0 || pi >= m.w || pj >= m.h)
                continue; /* outside the frame: the frustum's business */
            if (!(m.depth[(size_t)pj * m.w + pi] < z)) {
                wrong++;
                break;
            }
        }
    }
    CHECK(wrong == 0, "case %d: %ld of %ld hidden boxes have a visible sample", c, wrong, hidden);
    if (c < 4)
        printf("  case %d: %ld pixels marked (%ld roomy), %ld of 60 boxes hidden\n", c, marked,
               roomy, hidden);
    sw__occ_map_free(&m);
}

/* ---- 2. frames of a building ---------------------------------------------------------------- */
enum { W = 320, H = 240, WALK = 30 };

/* The scene's BVH, cones, occluders and (made on first need) static LODs. */
typedef struct scene_set {
    sw_sg_scene *scene;
    sw_sg_bvh *bvh;
    sw_lod_face_cones *fc;
    sw_gpu_occluders *oc;
    sw_lod_static_set *statics; /* NULL: per-frame tessellation only */
} scene_set;

static sw_result frame(sw_gpu_context *ctx, const scene_set *s, int occlude,
                       const sw_gpu_camera *cam, int wireframe, sw_gpu_image *img,
                       sw_gpu_frame_stats *fs, sw_status *st)
{
    sw_gpu_frame_desc d;
    memset(&d, 0, sizeof d);
    d.width = W;
    d.height = H;
    d.camera = *cam;
    d.background[0] = d.background[1] = d.background[2] = d.background[3] = 1.0f;
    d.bvh = s->bvh;
    d.face_cones = s->fc;
    d.occluders = occlude ? s->oc : NULL;
    d.static_lods = s->statics;
    d.wireframe = wireframe;
    return sw_gpu_render_scene(ctx, s->scene, &d, img, fs, st);
}

/* Camera k of the walk: eye height 160 (the generator's centimetres) through the rooms along x,
 * weaving in y, looking ahead; then views from outside. */
static sw_gpu_camera walk_camera(const double b[6], int k)
{
    sw_gpu_camera c = {{0, 0, 0}, {0, 0, 0}, {0, 0, 1}, 60.0};
    const double s = (double)k / (WALK - 1), sx = b[3] - b[0], sy = b[4] - b[1];
    c.eye[0] = b[0] + (0.1 + 0.8 * s) * sx;
    c.eye[1] = b[1] + (0.5 + 0.3 * sin(2.0 * M_PI * s)) * sy;
    c.eye[2] = b[2] + 160.0;
    const double yaw = 0.8 * sin(4.0 * M_PI * s);
    c.target[0] = c.eye[0] + 100.0 * cos(yaw);
    c.target[1] = c.eye[1] + 100.0 * sin(yaw);
    c.target[2] = c.eye[2] - 10.0;
    return c;
}

/* One view off and on: the images must be identical; adds the faces drawn to the sums. */
static int compare_view(sw_gpu_context *ctx, const scene_set *s, int k, const sw_gpu_camera *cam,
                        int wire, uint64_t sums[3])
{
    sw_status st = {0};
    sw_gpu_image off = {0}, on = {0};
    sw_gpu_frame_stats s_off, s_on;
    if (frame(ctx, s, 0, cam, wire, &off, &s_off, &st) != SW_OK ||
        frame(ctx, s, 1, cam, wire, &on, &s_on, &st) != SW_OK) {
        CHECK(0, "frame %d: %s", k, st.message);
        sw_gpu_image_free(&off);
        sw_gpu_image_free(&on);
        return 0;
    }
    const sw_test_image_diff d = sw_test_compare_images(&off, &on, 0);
    CHECK(d.any == 0, "%sframe %d: %ld pixels differ with occlusion culling (%ld covered)",
          s->statics ? "static LODs, " : "", k, d.any, d.covered);
    if (k < WALK) {
        sums[0] += s_off.faces_drawn;
        sums[1] += s_on.faces_drawn;
        sums[2] += s_on.faces_occluded;
    }
    if (k % 10 == 0 || k >= WALK)
        printf("  frame %d: faces drawn %llu -> %llu (%llu occluded, %llu occluders, %llu "
               "tests), %ld pixels covered\n",
               k, (unsigned long long)s_off.faces_drawn, (unsigned long long)s_on.faces_drawn,
               (unsigned long long)s_on.faces_occluded, (unsigned long long)s_on.occluders_drawn,
               (unsigned long long)s_on.occlusion_tests, d.covered);
    if (s->statics && (k % 10 == 0 || k >= WALK))
        printf("    static units drawn %llu -> %llu\n",
               (unsigned long long)s_off.static_units_drawn,
               (unsigned long long)s_on.static_units_drawn);
    sw_gpu_image_free(&off);
    sw_gpu_image_free(&on);
    return 1;
}

/* The walk (every `step`-th frame) and the outside views; the first view as a wireframe too
 * (only without static LODs: the unit-instance path draws no wireframe of its own kind). */
static void walk_views(sw_gpu_context *ctx, const scene_set *s, int step)
{
    const double *b = s->bvh->box;
    uint64_t sums[3] = {0, 0, 0}; /* faces drawn off, on; occluded */
    const int last = s->statics ? WALK + 2 : WALK + 3;
    for (int k = 0; k < last; k += k < WALK ? step : 1) {
        const sw_gpu_camera cam = k < WALK       ? walk_camera(b, k)
                                  : k < WALK + 2 ? sw_test_view_camera(b, k == WALK)
                                                 : walk_camera(b, 0);
        if (!compare_view(ctx, s, k, &cam, k == WALK + 2, sums))
            break;
    }
    printf("  walk: faces drawn %llu without, %llu with occlusion culling (%llu occluded)\n",
           (unsigned long long)sums[0], (unsigned long long)sums[1], (unsigned long long)sums[2]);
    CHECK(sums[1] * 2 <= sums[0], "the walk culls less than half its faces as hidden%s",
          s->statics ? " (static LODs)" : "");
}

static void frames_case(sw_gpu_context *ctx, const char *path, int with_statics)
{
    sw_status st = {0};
    scene_set s = {0};
    sw_test_hierarchies *h = NULL;
    if (sw_sg_scene_open(path, &s.scene, &st) != SW_OK ||
        sw_sg_bvh_build(s.scene, &s.bvh, &st) != SW_OK ||
        sw_lod_face_cones_build(s.scene, &s.fc, &st) != SW_OK ||
        sw_gpu_occluders_build(s.scene, &s.oc, &st) != SW_OK) {
        CHECK(0, "%s: %s", path, st.message);
        goto done;
    }
    printf("%s: %u faces, %u occluders, %zu bytes of outlines\n", path,
           sw_sg_scene_view_ptr(s.scene)->n_faces, sw_gpu_occluders_count(s.oc),
           sw_gpu_occluders_memory(s.oc));
    CHECK(sw_gpu_occluders_count(s.oc) > 0, "no occluder in a building");
    if (!with_statics) {
        walk_views(ctx, &s, 1);
        goto done;
    }
    puts("with static LODs");
    h = sw_test_hierarchies_create(s.scene);
    s.statics = h ? sw_test_hierarchies_statics(h) : NULL;
    CHECK(s.statics != NULL, "static LODs of the building");
    if (s.statics)
        walk_views(ctx, &s, 3);
done:
    sw_test_hierarchies_free(h);
    sw_gpu_occluders_free(s.oc);
    sw_lod_face_cones_free(s.fc);
    sw_sg_bvh_free(s.bvh);
    sw_sg_scene_free(s.scene);
}

int main(int argc, char **argv)
{
    if (argc < 3 || (argc > 3 && strcmp(argv[3], "--static"))) {
        fprintf(stderr, "usage: %s OUTDIR BUILDING.sws [--static]\n", argv[0]);
        return 2;
    }
    const int with_statics = argc > 3;
    if (!with_statics) {
        puts("the occlusion map against a dense reference");
        for (int c = 0; c < 40; ++c)
            map_case(c);
    }
    sw_status st = {0};
    sw_gpu_context *ctx = NULL;
    if (sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        fprintf(stderr, "FAIL: %s\n", st.message);
        return 1;
    }
    frames_case(ctx, argv[2], with_statics);
    sw_gpu_context_free(ctx);
    puts(g_failures ? "FAIL" : "PASS");
    return g_failures ? 1 : 0;
}
