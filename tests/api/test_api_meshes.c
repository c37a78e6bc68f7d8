/* SPDX-License-Identifier: MIT */
/* tests/api: triangle-mesh nodes (sw_nodes.h MESH), against the shared library.
 *
 * usage: test_api_meshes meshes WORKDIR   (no GL)
 *        test_api_meshes render WORKDIR   (EGL)
 *
 * meshes: a box mesh (flat, no normals) under a translation, an instance of it, a UV sphere with
 *   normals and a NURBS plate. Checked against independent facts: sw_scene_get_info's mesh,
 *   triangle and occurrence counts and its box against the shapes' analytic extents; a ray down
 *   onto the box's top hits the box's node at the exact t, in the triangle that holds the point
 *   by construction, with barycentric weights that rebuild the point (solved by hand below); the
 *   instance's hit names the same node with another occurrence; a ray that meets the plate before
 *   the box hits the plate; a ray into the sphere hits within its tessellation's distance of the
 *   exact sphere. sw_node_set_mesh moves the hit; bad input (NaN position, out-of-range index,
 *   zero normal, huge counts, NULL arrays, a MESH edit of a NURBS node) fails with the index named
 *   in the message and changes nothing (revision and pick unchanged). sw_camera_fit frames a
 *   mesh-only scene on its centre. Save / load: the reloaded
 *   scene has the same counts and bit-identical picks, saving it again gives the same bytes, the
 *   file has 11 sections (a scene without meshes still 8); imported under an IMPORT node the file
 *   brings its meshes, and hits name that node. The checked loader rejects a truncated
 *   file, a MESHES table entry whose size does not match its count, and an index out of range in
 *   INDICES (checksums recomputed by the test's own CRC-32C, so validation is what catches it),
 *   each with the file and a byte offset in the message.
 * render: a sphere mesh half under a NURBS plate, seen from above: every pixel whose colour is
 *   certain (the exact sphere and plane, ray-traced here through the pixel and 8 samples 1.5 px
 *   around it, agree) shows what the exact geometry says: the mesh where it is nearer (it occludes
 *   the plate), the plate where that is nearer (it occludes the mesh), background elsewhere; 0
 *   wrong pixels allowed, and both occlusion cases must occur. A plate drawn as a mesh matches the
 *   same plate drawn as NURBS (one-pixel distance). A mesh behind the camera is culled (stats).
 *   Instances of a detached mesh draw it at their places in their colours, a mesh's own colour
 *   winning over its instance's.
 *   Saved and reloaded, the scene renders to the same image (0 pixels differ); walkthrough,
 *   split and eval_exact frames of a mesh scene equal its converged frame; after sw_node_set_mesh
 * the frame shows the new sphere (ray-traced check again).
 */
#include <splinewalk/sw_nodes.h>

#include "test_check.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api_test_image.h"

static const char *g_work;

#define EXPECT_RESULT(call, want)                                                                  \
    do {                                                                                           \
        sw_result got_ = (call);                                                                   \
        CHECK(got_ == (want), "line %d: %s -> %s, expected %s", __LINE__, #call,                   \
              sw_result_id_str(got_), sw_result_id_str(want));                                     \
    } while (0)

/* ---- shapes ------------------------------------------------------------------------------------
 */
/* The box [0, 2] x [0, 2] x [0, 1]: vertex i = (2 (i & 1), 2 ((i >> 1) & 1), (i >> 2) & 1). */
static double g_box_pts[24];
static const uint32_t k_box_tris[36] = {
    0, 2, 3, 0, 3, 1, /* z = 0 */
    4, 5, 7, 4, 7, 6, /* z = 1: triangles 2 (below the diagonal y = x) and 3 (above) */
    0, 1, 5, 0, 5, 4, /* y = 0 */
    2, 6, 7, 2, 7, 3, /* y = 2 */
    0, 4, 6, 0, 6, 2, /* x = 0 */
    1, 3, 7, 1, 7, 5, /* x = 2 */
};

static sw_mesh_desc box_mesh(double height)
{
    for (int i = 0; i < 8; i++) {
        g_box_pts[3 * i] = 2.0 * (i & 1);
        g_box_pts[3 * i + 1] = 2.0 * ((i >> 1) & 1);
        g_box_pts[3 * i + 2] = height * ((i >> 2) & 1);
    }
    return (sw_mesh_desc){8, g_box_pts, NULL, 12, k_box_tris};
}

enum { SPHERE_LAT = 48, SPHERE_LON = 96 };
enum { SPHERE_V = (SPHERE_LAT + 1) * (SPHERE_LON + 1), SPHERE_T = 2 * SPHERE_LAT * SPHERE_LON };

typedef struct sphere_mesh {
    double pts[3 * SPHERE_V], nrm[3 * SPHERE_V];
    uint32_t tris[3 * SPHERE_T];
} sphere_mesh;

/* A UV sphere (inscribed: every vertex on the sphere), with the exact normals. */
static sw_mesh_desc sphere(sphere_mesh *s, const double c[3], double radius)
{
    for (int i = 0; i <= SPHERE_LAT; i++) {
        const double th = M_PI * i / SPHERE_LAT;
        for (int j = 0; j <= SPHERE_LON; j++) {
            const double ph = 2.0 * M_PI * j / SPHERE_LON;
            const double n[3] = {sin(th) * cos(ph), sin(th) * sin(ph), cos(th)};
            const int v = i * (SPHERE_LON + 1) + j;
            for (int k = 0; k < 3; k++) {
                s->nrm[3 * v + k] = n[k];
                s->pts[3 * v + k] = c[k] + radius * n[k];
            }
        }
    }
    uint32_t *t = s->tris;
    for (uint32_t i = 0; i < SPHERE_LAT; i++)
        for (uint32_t j = 0; j < SPHERE_LON; j++) {
            const uint32_t a = i * (SPHERE_LON + 1) + j, b = a + SPHERE_LON + 1;
            const uint32_t q[6] = {a, b, b + 1, a, b + 1, a + 1};
            memcpy(t, q, sizeof q);
            t += 6;
        }
    return (sw_mesh_desc){SPHERE_V, s->pts, s->nrm, SPHERE_T, s->tris};
}

/* A flat bilinear NURBS plate over [x0, x1] x [y0, y1] at height z: S(u, v) = corners blended. */
static const double k_knots2[4] = {0, 0, 1, 1};
static double g_plate[4][12];
static sw_nurbs_desc plate(int slot, double x0, double x1, double y0, double y1, double z)
{
    double *p = g_plate[slot];
    const double pts[12] = {x0, y0, z, x1, y0, z, x0, y1, z, x1, y1, z};
    memcpy(p, pts, sizeof pts);
    sw_nurbs_desc d = {0};
    d.degree_u = d.degree_v = 1;
    d.count_u = d.count_v = 2;
    d.knots_u = d.knots_v = k_knots2;
    d.points = p;
    return d;
}

static void translation(double xf[12], double x, double y, double z)
{
    static const double id[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    memcpy(xf, id, sizeof id);
    xf[3] = x, xf[7] = y, xf[11] = z;
}

static void set_color(float c[4], float r, float g, float b)
{
    c[0] = r, c[1] = g, c[2] = b, c[3] = 1.0f;
}

static sw_pick_hit pick_down(sw_scene s, double x, double y)
{
    const double o[3] = {x, y, 10.0}, d[3] = {0, 0, -1};
    sw_pick_hit h;
    memset(&h, 0, sizeof h);
    sw_status st = {0};
    CHECK(sw_scene_pick(s, o, d, &h, &st) == SW_OK, "pick at (%g, %g): %s", x, y, st.message);
    return h;
}

/* ---- the scene without GL ----------------------------------------------------------------------
 */
typedef struct built {
    sw_scene scene;
    sw_node box, shifted, copy, ball, plate;
} built;

static const double k_ball_c[3] = {-10, 0, 0};

static built build(sphere_mesh *sm)
{
    built b;
    memset(&b, 0, sizeof b);
    sw_status st = {0};
    EXPECT_RESULT(sw_scene_create(NULL, &b.scene, NULL), SW_OK);
    sw_mesh_desc bm = box_mesh(1.0);
    sw_node_desc bn = {.name = "box"};
    translation(bn.transform, 5, 0, 0);
    set_color(bn.color, 0.2f, 0.3f, 0.9f);
    CHECK(sw_node_add_mesh(b.scene, &bn, &bm, &b.box, &st) == SW_OK, "add box: %s", st.message);
    sw_node_desc t = {.kind = SW_NODE_TRANSFORM};
    translation(t.transform, 0, 10, 0);
    EXPECT_RESULT(sw_node_add(b.scene, &t, &b.shifted, NULL), SW_OK);
    sw_node_desc in = {.kind = SW_NODE_INSTANCE, .parent = b.shifted, .instance_of = b.box};
    EXPECT_RESULT(sw_node_add(b.scene, &in, &b.copy, NULL), SW_OK);
    sw_mesh_desc sd = sphere(sm, k_ball_c, 1.0);
    sw_node_desc sn = {.kind = SW_NODE_MESH, .mesh = &sd}; /* through sw_node_add as well */
    CHECK(sw_node_add(b.scene, &sn, &b.ball, &st) == SW_OK, "add sphere: %s", st.message);
    sw_nurbs_desc pd = plate(0, 6, 8, 0, 2, 3);
    sw_node_desc pn = {.kind = SW_NODE_NURBS, .nurbs = &pd};
    CHECK(sw_node_add(b.scene, &pn, &b.plate, &st) == SW_OK, "add plate: %s", st.message);
    return b;
}

static void check_info(sw_scene s, const char *what)
{
    sw_scene_info info;
    sw_status st = {0};
    CHECK(sw_scene_get_info(s, &info, &st) == SW_OK, "%s: info: %s", what, st.message);
    CHECK(info.meshes == 2 && info.mesh_triangles == 12 + SPHERE_T && info.mesh_occurrences == 3 &&
              info.triangle_occurrences == 24 + SPHERE_T && info.faces == 1 &&
              info.face_occurrences == 1,
          "%s: %u meshes, %llu triangles, %llu occurrences, %llu drawn triangles, %u faces", what,
          info.meshes, (unsigned long long)info.mesh_triangles,
          (unsigned long long)info.mesh_occurrences, (unsigned long long)info.triangle_occurrences,
          info.faces);
    /* sphere x >= -11, y, z in [-1, 1]; boxes x in [5, 7], y up to 12; plate z = 3 */
    const double lo[3] = {-11, -1, -1}, hi[3] = {8, 12, 3};
    for (int k = 0; k < 3; k++)
        CHECK(fabs(info.bbox_min[k] - lo[k]) < 1e-9 && fabs(info.bbox_max[k] - hi[k]) < 1e-9,
              "%s: box axis %d: [%.12g, %.12g], expected [%g, %g]", what, k, info.bbox_min[k],
              info.bbox_max[k], lo[k], hi[k]);
}

/* The box's top at (x, y) = (5.3, 0.4) + shift: local (0.3, 0.4) lies above the diagonal, in
 * triangle 3 = (v4, v7, v6) = ((0,0,1), (2,2,1), (0,2,1)): x = 2 b1, y = 2 b1 + 2 b2, so
 * b = (0.8, 0.15, 0.05); t = 10 - 1. */
static void check_box_hit(const sw_pick_hit *h, sw_node node, double top, const char *what)
{
    CHECK(h->hit && h->mesh != UINT32_MAX && h->surface == UINT32_MAX && h->node.id == node.id &&
              h->triangle == 3,
          "%s: hit %d mesh %u surface %u node %#x (want %#x) triangle %u", what, h->hit, h->mesh,
          h->surface, h->node.id, node.id, h->triangle);
    CHECK(fabs(h->t - (10.0 - top)) < 1e-12, "%s: t = %.15g, expected %g", what, h->t, 10.0 - top);
    const double want[3] = {0.8, 0.15, 0.05};
    for (int k = 0; k < 3; k++)
        CHECK(fabs(h->barycentric[k] - want[k]) < 1e-12, "%s: barycentric %d = %.15g, want %g",
              what, k, h->barycentric[k], want[k]);
}

static void check_picks(built *b, const char *what)
{
    sw_pick_hit h = pick_down(b->scene, 5.3, 0.4);
    check_box_hit(&h, b->box, 1.0, what);
    sw_pick_hit c = pick_down(b->scene, 5.3, 10.4);
    check_box_hit(&c, b->box, 1.0, what);
    CHECK(c.occurrence != h.occurrence, "%s: instance hit occurrence %llu = the box's", what,
          (unsigned long long)c.occurrence);
    /* The plate (z = 3) lies over the box at (7, 1): it is nearer. */
    sw_pick_hit p = pick_down(b->scene, 7.0, 1.0);
    CHECK(p.hit && p.surface == 0 && p.mesh == UINT32_MAX && fabs(p.t - 7.0) < 1e-9 &&
              p.node.id == b->plate.id,
          "%s: plate over the box: hit %d surface %u mesh %u t %g node %#x", what, p.hit, p.surface,
          p.mesh, p.t, p.node.id);
    /* Into the sphere from +x: within the inscribed tessellation's distance of the sphere. */
    const double o[3] = {-5, 0.123, 0.05}, d[3] = {-1, 0, 0};
    sw_pick_hit s;
    sw_status st = {0};
    CHECK(sw_scene_pick(b->scene, o, d, &s, &st) == SW_OK, "%s: sphere pick: %s", what, st.message);
    double r2 = 0.0;
    for (int k = 0; k < 3; k++)
        r2 += (s.point[k] - k_ball_c[k]) * (s.point[k] - k_ball_c[k]);
    const double gap = 1.0 - cos(M_PI / SPHERE_LAT) * cos(M_PI / SPHERE_LON);
    CHECK(s.hit && s.node.id == b->ball.id && sqrt(r2) <= 1.0 + 1e-12 && sqrt(r2) >= 1.0 - gap,
          "%s: sphere hit %d node %#x at distance %.9g from the centre (%.9g..1)", what, s.hit,
          s.node.id, sqrt(r2), 1.0 - gap);
    /* The point is the barycentric blend of its triangle's corners (checked via the box above);
     * a miss beside everything: */
    sw_pick_hit m = pick_down(b->scene, 30, 30);
    CHECK(!m.hit, "%s: a ray beside the scene hit", what);
}

static uint64_t latest_revision(sw_scene s)
{
    sw_scene_revisions rv = {0};
    EXPECT_RESULT(sw_scene_get_revisions(s, &rv, NULL), SW_OK);
    return rv.latest;
}

/* A bad mesh: the result, and the message naming what is at fault. */
static void expect_bad(sw_scene s, sw_node node, const sw_mesh_desc *m, sw_result want,
                       const char *needle)
{
    sw_status st = {0};
    sw_node out = {7};
    sw_result r = sw_node_add_mesh(s, NULL, m, &out, &st);
    CHECK(r == want && out.id == 0 && strstr(st.message, needle),
          "add: %s (\"%s\"), expected %s with \"%s\"", sw_result_id_str(r), st.message,
          sw_result_id_str(want), needle);
    memset(&st, 0, sizeof st);
    r = sw_node_set_mesh(s, node, m, &st);
    CHECK(r == want && strstr(st.message, needle), "set: %s (\"%s\"), expected %s with \"%s\"",
          sw_result_id_str(r), st.message, sw_result_id_str(want), needle);
}

static void test_misuse(built *b)
{
    const uint64_t before = latest_revision(b->scene);
    sw_mesh_desc m = box_mesh(1.0);
    double pts[24];
    memcpy(pts, g_box_pts, sizeof pts);
    m.positions = pts;
    pts[3 * 5 + 1] = NAN;
    expect_bad(b->scene, b->box, &m, SW_ERR_INVALID_GEOMETRY, "vertex 5");
    pts[3 * 5 + 1] = 0.0;
    uint32_t tris[36];
    memcpy(tris, k_box_tris, sizeof tris);
    m.indices = tris;
    tris[7] = 8; /* triangle 2, corner 1 */
    expect_bad(b->scene, b->box, &m, SW_ERR_INVALID_GEOMETRY, "index 7 (triangle 2, corner 1)");
    tris[7] = k_box_tris[7];
    double nrm[24] = {0};
    nrm[3 * 6 + 2] = 1.0;
    m.normals = nrm; /* vertex 0's normal is zero */
    expect_bad(b->scene, b->box, &m, SW_ERR_INVALID_GEOMETRY, "vertex 0: normal");
    m.normals = NULL;
    m.triangle_count = (1u << 24) + 1;
    expect_bad(b->scene, b->box, &m, SW_ERR_LIMIT, "triangles");
    m.triangle_count = 12;
    m.vertex_count = 2;
    expect_bad(b->scene, b->box, &m, SW_ERR_LIMIT, "vertices");
    m.vertex_count = 8;
    m.positions = NULL;
    expect_bad(b->scene, b->box, &m, SW_ERR_INVALID_ARGUMENT, "NULL positions");
    m.positions = pts;
    EXPECT_RESULT(sw_node_add_mesh(b->scene, NULL, NULL, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    sw_node_desc nomesh = {.kind = SW_NODE_MESH};
    sw_node out;
    EXPECT_RESULT(sw_node_add(b->scene, &nomesh, &out, NULL), SW_ERR_INVALID_ARGUMENT);
    EXPECT_RESULT(sw_node_set_mesh(b->scene, b->plate, &m, NULL), SW_ERR_INVALID_ARGUMENT);
    sw_nurbs_desc pd = plate(1, 0, 1, 0, 1, 0);
    EXPECT_RESULT(sw_node_set_nurbs(b->scene, b->box, &pd, NULL), SW_ERR_INVALID_ARGUMENT);
    EXPECT_RESULT(sw_node_set_mesh(b->scene, b->box, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    CHECK(latest_revision(b->scene) == before, "failed calls made revisions %llu -> %llu",
          (unsigned long long)before, (unsigned long long)latest_revision(b->scene));
    check_picks(b, "after the bad calls");
}

static void test_set_mesh(built *b)
{
    sw_mesh_desc tall = box_mesh(2.5);
    sw_status st = {0};
    CHECK(sw_node_set_mesh(b->scene, b->box, &tall, &st) == SW_OK, "set_mesh: %s", st.message);
    sw_pick_hit h = pick_down(b->scene, 5.3, 0.4);
    check_box_hit(&h, b->box, 2.5, "after set_mesh");
    sw_node_info ni;
    EXPECT_RESULT(sw_node_get_info(b->scene, b->box, &ni, NULL), SW_OK);
    CHECK(ni.kind == SW_NODE_MESH && ni.triangles == 12 && ni.faces == 0,
          "box node info: kind %d, %u triangles, %u faces", (int)ni.kind, ni.triangles, ni.faces);
    sw_mesh_desc back = box_mesh(1.0);
    EXPECT_RESULT(sw_node_set_mesh(b->scene, b->box, &back, NULL), SW_OK);
}

static unsigned char *read_file(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    unsigned char *data = NULL;
    long n = -1;
    if (f && fseek(f, 0, SEEK_END) == 0 && (n = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0) {
        data = malloc((size_t)n + 1);
        if (data && fread(data, 1, (size_t)n, f) != (size_t)n) {
            free(data);
            data = NULL;
        }
    }
    if (f)
        fclose(f);
    *size = data ? (size_t)n : 0;
    return data;
}

static int write_file(const char *path, const unsigned char *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    int ok = f && fwrite(data, 1, n, f) == n;
    if (f)
        ok &= fclose(f) == 0;
    return ok;
}

static uint32_t rd32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static uint64_t rd64(const unsigned char *p)
{
    return rd32(p) | (uint64_t)rd32(p + 4) << 32;
}

static void wr32(unsigned char *p, uint32_t x)
{
    for (int k = 0; k < 4; k++)
        p[k] = (unsigned char)(x >> (8 * k));
}

/* CRC-32C bit by bit (docs/sws-format.md: reflected 0x82F63B78, pre- and post-inverted),
 * chained like the library's: crc32c(crc32c(0, a), b) = crc32c(0, a || b). */
static uint32_t crc32c(uint32_t crc, const unsigned char *p, size_t n)
{
    uint32_t c = ~crc;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++)
            c = (c & 1u) ? (c >> 1) ^ 0x82F63B78u : c >> 1;
    }
    return ~c;
}

/* The table entry of section `id` (NULL when absent). */
static unsigned char *entry(unsigned char *file, uint32_t id)
{
    const uint32_t n = rd32(file + 16);
    for (uint32_t i = 0; i < n; i++) {
        unsigned char *e = file + rd64(file + 32) + 40 * (size_t)i;
        if (rd32(e) == id)
            return e;
    }
    return NULL;
}

static void fix_header_crc(unsigned char *file)
{
    const uint32_t n = rd32(file + 16);
    uint32_t c = crc32c(0, file, 60);
    c = crc32c(c, file + rd64(file + 32), 40 * (size_t)n);
    wr32(file + 60, c);
}

/* Loading `path` (and verifying it, which sw_scene_get_info does first) fails with want, the
 * message naming the file and a byte offset. */
static void expect_load_error(const char *path, sw_result want, const char *needle)
{
    sw_scene s = {0};
    sw_status st = {0};
    sw_scene_load_desc ld = {.path = path};
    sw_result r = sw_scene_load(&ld, &s, &st);
    if (r == SW_OK) {
        sw_scene_info info;
        r = sw_scene_get_info(s, &info, &st);
        sw_scene_destroy(s);
    }
    CHECK(r == want && strstr(st.message, path) && strstr(st.message, "offset") &&
              strstr(st.message, needle),
          "%s: %s (\"%s\"), expected %s naming the file, an offset and \"%s\"", path,
          sw_result_id_str(r), st.message, sw_result_id_str(want), needle);
    printf("rejected: %s\n", st.message);
}

static void test_damaged_files(const char *good)
{
    size_t n = 0;
    unsigned char *file = read_file(good, &n);
    CHECK(file && n > 64, "read %s", good);
    if (!file)
        return;
    char path[1024];
    snprintf(path, sizeof path, "%s/truncated.sws", g_work);
    CHECK(write_file(path, file, n - 8), "write %s", path);
    expect_load_error(path, SW_ERR_TRUNCATED, "");

    unsigned char *copy = malloc(n);
    unsigned char *e = entry(file, 9); /* MESHES */
    CHECK(e != NULL, "no MESHES entry");
    if (copy && e) {
        memcpy(copy, file, n);
        unsigned char *ce = copy + (e - file);
        wr32(ce + 24, rd32(ce + 24) + 1); /* one record more than its 88 * count bytes */
        fix_header_crc(copy);
        snprintf(path, sizeof path, "%s/bad_count.sws", g_work);
        CHECK(write_file(path, copy, n), "write %s", path);
        expect_load_error(path, SW_ERR_FORMAT, "MESHES");
    }
    e = entry(file, 10); /* INDICES */
    CHECK(e != NULL, "no INDICES entry");
    if (copy && e) {
        memcpy(copy, file, n);
        unsigned char *ce = copy + (e - file);
        unsigned char *sec = copy + rd64(ce + 8);
        wr32(sec + 4 * 4, 1000000); /* mesh 0's index 4 */
        wr32(ce + 32, crc32c(0, sec, rd64(ce + 16)));
        fix_header_crc(copy);
        snprintf(path, sizeof path, "%s/bad_index.sws", g_work);
        CHECK(write_file(path, copy, n), "write %s", path);
        expect_load_error(path, SW_ERR_FORMAT, "mesh 0");
    }
    free(copy);
    free(file);
}

static void test_save_reload(built *b)
{
    char path[1024], again[1024], plain[1024];
    snprintf(path, sizeof path, "%s/meshes.sws", g_work);
    snprintf(again, sizeof again, "%s/meshes_again.sws", g_work);
    snprintf(plain, sizeof plain, "%s/no_meshes.sws", g_work);
    sw_status st = {0};
    CHECK(sw_scene_save(b->scene, path, &st) == SW_OK, "save: %s", st.message);
    sw_scene loaded;
    sw_scene_load_desc ld = {.path = path};
    CHECK(sw_scene_load(&ld, &loaded, &st) == SW_OK, "load: %s", st.message);
    check_info(loaded, "reloaded");
    const double xy[4][2] = {{5.3, 0.4}, {5.3, 10.4}, {7.0, 1.0}, {6.9, 1.7}};
    for (int k = 0; k < 4; k++) {
        sw_pick_hit a = pick_down(b->scene, xy[k][0], xy[k][1]);
        sw_pick_hit c = pick_down(loaded, xy[k][0], xy[k][1]);
        a.node.id = 0; /* a file scene has no nodes */
        CHECK(memcmp(&a, &c, sizeof a) == 0, "pick %d differs after reload (t %.17g vs %.17g)", k,
              a.t, c.t);
    }
    CHECK(sw_scene_save(loaded, again, &st) == SW_OK, "save again: %s", st.message);
    size_t na = 0, nb = 0;
    unsigned char *fa = read_file(path, &na), *fb = read_file(again, &nb);
    CHECK(fa && fb && na == nb && memcmp(fa, fb, na) == 0,
          "saving the reloaded scene changed the file (%zu vs %zu bytes)", na, nb);
    CHECK(fa && rd32(fa + 16) == 11, "a scene with meshes has %u sections, not 11",
          fa ? rd32(fa + 16) : 0);
    free(fa);
    free(fb);
    sw_scene_destroy(loaded);
    /* The file imported under a node: its meshes come along, hits name the IMPORT node. */
    sw_scene host;
    EXPECT_RESULT(sw_scene_create(NULL, &host, NULL), SW_OK);
    sw_node_desc im = {.kind = SW_NODE_IMPORT, .import_path = path};
    sw_node imported;
    CHECK(sw_node_add(host, &im, &imported, &st) == SW_OK, "import: %s", st.message);
    check_info(host, "imported");
    sw_node_info ni;
    EXPECT_RESULT(sw_node_get_info(host, imported, &ni, NULL), SW_OK);
    CHECK(ni.triangles == 12 + SPHERE_T && ni.faces == 1, "import node: %u triangles, %u faces",
          ni.triangles, ni.faces);
    sw_pick_hit h = pick_down(host, 5.3, 0.4);
    check_box_hit(&h, imported, 1.0, "imported");
    sw_scene_destroy(host);
    /* Without meshes the file keeps the 8 sections older readers know. */
    EXPECT_RESULT(sw_node_remove(b->scene, b->copy, NULL), SW_OK);
    EXPECT_RESULT(sw_node_remove(b->scene, b->box, NULL), SW_OK);
    EXPECT_RESULT(sw_node_remove(b->scene, b->ball, NULL), SW_OK);
    CHECK(sw_scene_save(b->scene, plain, &st) == SW_OK, "save plain: %s", st.message);
    fa = read_file(plain, &na);
    CHECK(fa && rd32(fa + 16) == 8, "a scene without meshes has %u sections, not 8",
          fa ? rd32(fa + 16) : 0);
    free(fa);
    test_damaged_files(path);
}

/* A scene of one mesh: the camera presets frame its box (sw_camera_fit: target = box centre). */
static void test_camera_fit(sphere_mesh *sm)
{
    sw_scene s;
    EXPECT_RESULT(sw_scene_create(NULL, &s, NULL), SW_OK);
    sw_mesh_desc sd = sphere(sm, k_ball_c, 1.0);
    sw_node n;
    EXPECT_RESULT(sw_node_add_mesh(s, NULL, &sd, &n, NULL), SW_OK);
    sw_camera cam;
    sw_status st = {0};
    CHECK(sw_camera_fit(s, SW_VIEW_TOP, &cam, &st) == SW_OK, "camera_fit: %s", st.message);
    CHECK(fabs(cam.target[0] - k_ball_c[0]) < 1e-9 && fabs(cam.target[1] - k_ball_c[1]) < 1e-9 &&
              fabs(cam.target[2] - k_ball_c[2]) < 1e-9 && cam.eye[2] > 1.0,
          "camera_fit of a mesh: target (%g, %g, %g), eye z %g", cam.target[0], cam.target[1],
          cam.target[2], cam.eye[2]);
    sw_scene_destroy(s);
}

static void test_meshes(void)
{
    sphere_mesh *sm = malloc(sizeof *sm);
    test_camera_fit(sm);
    built b = build(sm);
    check_info(b.scene, "node scene");
    sw_node_info ni;
    EXPECT_RESULT(sw_node_get_info(b.scene, b.ball, &ni, NULL), SW_OK);
    CHECK(ni.kind == SW_NODE_MESH && ni.triangles == SPHERE_T, "sphere node: kind %d, %u triangles",
          (int)ni.kind, ni.triangles);
    check_picks(&b, "node scene");
    test_misuse(&b);
    test_set_mesh(&b);
    check_picks(&b, "after set_mesh back");
    test_save_reload(&b);
    sw_scene_destroy(b.scene);
    free(sm);
}

/* ---- rendering ---------------------------------------------------------------------------------
 */
enum { W = 320, H = 240 };
enum { BG, RED, GREEN };

typedef struct tracer {
    double eye[3], fwd[3], right[3], up[3], focal;
    double centre[3], radius; /* the exact sphere (the mesh's) */
    double plate[4], plate_z; /* x0, x1, y0, y1 of the exact plate, or x0 > x1: none */
} tracer;

static void normalize(double v[3])
{
    const double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; k++)
        v[k] /= l;
}

static void tracer_camera(tracer *t, const sw_camera *c)
{
    for (int k = 0; k < 3; k++) {
        t->eye[k] = c->eye[k];
        t->fwd[k] = c->target[k] - c->eye[k];
    }
    normalize(t->fwd);
    const double *u = c->up, *f = t->fwd;
    t->right[0] = f[1] * u[2] - f[2] * u[1];
    t->right[1] = f[2] * u[0] - f[0] * u[2];
    t->right[2] = f[0] * u[1] - f[1] * u[0];
    normalize(t->right);
    const double *r = t->right;
    t->up[0] = r[1] * f[2] - r[2] * f[1];
    t->up[1] = r[2] * f[0] - r[0] * f[2];
    t->up[2] = r[0] * f[1] - r[1] * f[0];
    t->focal = H / (2.0 * tan(c->fovy_deg * M_PI / 360.0));
}

/* What the exact geometry shows at image point (x, y) (pixels from the top left). */
static int trace(const tracer *t, double x, double y, int *behind)
{
    double d[3];
    for (int k = 0; k < 3; k++)
        d[k] = t->fwd[k] + (x - W / 2.0) / t->focal * t->right[k] +
               (H / 2.0 - y) / t->focal * t->up[k];
    double oc[3], b = 0.0, c = -t->radius * t->radius, a = 0.0;
    for (int k = 0; k < 3; k++) {
        oc[k] = t->eye[k] - t->centre[k];
        a += d[k] * d[k];
        b += oc[k] * d[k];
        c += oc[k] * oc[k];
    }
    const double disc = b * b - a * c;
    const double ts = disc >= 0.0 ? (-b - sqrt(disc)) / a : INFINITY;
    double tp = INFINITY;
    if (t->plate[0] < t->plate[1] && d[2] != 0.0) {
        const double s = (t->plate_z - t->eye[2]) / d[2];
        const double px = t->eye[0] + s * d[0], py = t->eye[1] + s * d[1];
        if (s > 0.0 && px >= t->plate[0] && px <= t->plate[1] && py >= t->plate[2] &&
            py <= t->plate[3])
            tp = s;
    }
    *behind = isfinite(ts) && isfinite(tp);
    if (!isfinite(ts) && !isfinite(tp))
        return BG;
    return ts < tp ? GREEN : RED;
}

static int classify_pixel(const unsigned char *p)
{
    if (p[0] >= 250 && p[1] >= 250 && p[2] >= 250)
        return BG;
    return p[1] > p[0] ? GREEN : RED;
}

typedef struct coverage {
    long certain, wrong, mesh_in_front, plate_in_front, green;
} coverage;

/* Compares a frame with the exact geometry at every pixel whose 3 x 3 samples 1.5 px apart all
 * agree (the rasterised edge of a within-0.1-px tessellation cannot cross such a pixel). */
static coverage compare_traced(const tracer *t, const char *png)
{
    coverage cv = {0};
    int w = 0, h = 0;
    unsigned char *img = sw_test_read_rgba(png, &w, &h);
    CHECK(img && w == W && h == H, "read %s", png);
    if (!img || w != W || h != H) {
        free(img);
        cv.wrong = -1;
        return cv;
    }
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int behind = 0, first = -1, same = 1;
            for (int s = 0; s < 9 && same; s++) {
                int bh;
                const int c =
                    trace(t, x + 0.5 + 1.5 * (s % 3 - 1), y + 0.5 + 1.5 * (s / 3 - 1), &bh);
                if (s == 4)
                    behind = bh;
                same = first < 0 || c == first;
                first = c;
            }
            if (!same)
                continue;
            cv.certain++;
            const int got = classify_pixel(img + 4 * ((size_t)y * W + x));
            cv.wrong += got != first;
            cv.green += first == GREEN;
            cv.mesh_in_front += first == GREEN && behind;
            cv.plate_in_front += first == RED && behind;
        }
    free(img);
    return cv;
}

static void draw(sw_renderer r, sw_scene s, const sw_camera *cam, int walkthrough, const char *name,
                 char *path, sw_frame_stats *fs)
{
    snprintf(path, 1024, "%s/%s.png", g_work, name);
    sw_frame_desc f = {.scene = s, .camera = *cam, .width = W, .height = H, .output_path = path};
    f.walkthrough = walkthrough;
    sw_status st = {0};
    CHECK(sw_renderer_draw(r, &f, fs, &st) == SW_OK, "draw %s: %s", name, st.message);
}

/* Pixels of one image with no pixel of the same colour (within 12 levels) within one pixel in
 * the other, the larger share of both ways (%). */
static double one_pixel_percent(const char *a, const char *b)
{
    int wa = 0, ha = 0, wb = 0, hb = 0;
    unsigned char *pa = sw_test_read_rgba(a, &wa, &ha), *pb = sw_test_read_rgba(b, &wb, &hb);
    double worst = 100.0;
    if (pa && pb && wa == wb && ha == hb && wa > 0) {
        worst = 0.0;
        for (int way = 0; way < 2; way++) {
            const unsigned char *p = way ? pb : pa, *q = way ? pa : pb;
            size_t unmatched = 0;
            for (int y = 0; y < ha; y++)
                for (int x = 0; x < wa; x++) {
                    int matched = 0;
                    for (int dy = -1; dy <= 1 && !matched; dy++)
                        for (int dx = -1; dx <= 1 && !matched; dx++) {
                            const int xx = x + dx, yy = y + dy;
                            if (xx < 0 || yy < 0 || xx >= wa || yy >= ha)
                                continue;
                            matched = 1;
                            for (int c = 0; c < 3; c++)
                                matched &= abs((int)p[4 * ((size_t)y * wa + x) + c] -
                                               (int)q[4 * ((size_t)yy * wa + xx) + c]) <= 12;
                        }
                    unmatched += !matched;
                }
            worst = fmax(worst, 100.0 * (double)unmatched / ((double)wa * ha));
        }
    }
    free(pa);
    free(pb);
    return worst;
}

static const sw_camera k_top = {{0.3, 0.2, 20.0}, {0, 0, 0}, {0, 1, 0}, 40};

/* The sphere (centre (0, 0, -2), radius R) under the red plate x in [-10, 0], y in [-10, 10] at
 * z = 0: its cap above the plate shows through on the left, the plate hides its rim there. */
static void check_against_trace(const char *png, double radius, const char *what)
{
    tracer t;
    tracer_camera(&t, &k_top);
    t.centre[0] = t.centre[1] = 0.0, t.centre[2] = -2.0;
    t.radius = radius;
    t.plate[0] = -10, t.plate[1] = 0, t.plate[2] = -10, t.plate[3] = 10, t.plate_z = 0.0;
    coverage cv = compare_traced(&t, png);
    CHECK(cv.wrong == 0 && cv.mesh_in_front > 200 && cv.plate_in_front > 200,
          "%s: %ld of %ld certain pixels wrong; mesh in front of the plate at %ld, plate in front "
          "of the mesh at %ld",
          what, cv.wrong, cv.certain, cv.mesh_in_front, cv.plate_in_front);
    printf(
        "%s: %ld of %ld certain pixels differ from the ray-traced exact sphere and plate "
        "(%ld mesh pixels; mesh occludes the plate at %ld, the plate occludes the mesh at %ld)\n",
        what, cv.wrong, cv.certain, cv.green, cv.mesh_in_front, cv.plate_in_front);
}

static void test_occlusion(sw_renderer r, sphere_mesh *sm)
{
    sw_scene s;
    sw_status st = {0};
    EXPECT_RESULT(sw_scene_create(NULL, &s, NULL), SW_OK);
    const double c[3] = {0, 0, -2};
    sw_mesh_desc md = sphere(sm, c, 3.0);
    sw_node_desc mn = {0};
    set_color(mn.color, 0.1f, 0.8f, 0.2f);
    sw_node ball;
    CHECK(sw_node_add_mesh(s, &mn, &md, &ball, &st) == SW_OK, "add sphere: %s", st.message);
    sw_nurbs_desc pd = plate(0, -10, 0, -10, 10, 0);
    sw_node_desc pn = {.kind = SW_NODE_NURBS, .nurbs = &pd};
    set_color(pn.color, 0.9f, 0.1f, 0.1f);
    sw_node pl;
    CHECK(sw_node_add(s, &pn, &pl, &st) == SW_OK, "add plate: %s", st.message);
    char conv[1024], walk[1024], split[1024], reload[1024], edited[1024];
    sw_frame_stats fs;
    memset(&fs, 0, sizeof fs);
    draw(r, s, &k_top, 0, "occlusion", conv, &fs);
    CHECK(fs.meshes_drawn == 1 && fs.meshes_culled == 0 && fs.mesh_triangles == SPHERE_T &&
              fs.faces_drawn == 1,
          "stats: %llu meshes drawn, %llu culled, %llu triangles, %llu faces",
          (unsigned long long)fs.meshes_drawn, (unsigned long long)fs.meshes_culled,
          (unsigned long long)fs.mesh_triangles, (unsigned long long)fs.faces_drawn);
    check_against_trace(conv, 3.0, "converged");

    /* Saved and reloaded: the same image. */
    char file[1024];
    snprintf(file, sizeof file, "%s/occlusion.sws", g_work);
    CHECK(sw_scene_save(s, file, &st) == SW_OK, "save: %s", st.message);
    sw_scene loaded;
    sw_scene_load_desc ld = {.path = file};
    CHECK(sw_scene_load(&ld, &loaded, &st) == SW_OK, "load: %s", st.message);
    draw(r, loaded, &k_top, 0, "occlusion_reloaded", reload, NULL);
    const double dr = sw_test_differing_percent(conv, reload);
    CHECK(dr == 0.0, "reloaded scene: %.4f %% of pixels differ", dr);
    printf("save / load: %.4f %% of pixels differ between the node scene and the reloaded file\n",
           dr);
    sw_scene_destroy(loaded);

    /* A mesh-only scene: walkthrough, split and exact frames draw it as a converged one does. */
    EXPECT_RESULT(sw_node_set_visible(s, pl, 0, NULL), SW_OK);
    draw(r, s, &k_top, 0, "mesh_only", conv, NULL);
    draw(r, s, &k_top, 1, "mesh_only_walk", walk, &fs);
    CHECK(fs.meshes_drawn == 1, "walkthrough: %llu meshes drawn",
          (unsigned long long)fs.meshes_drawn);
    snprintf(split, sizeof split, "%s/mesh_only_split.png", g_work);
    sw_frame_desc f = {.scene = s, .camera = k_top, .width = W, .height = H, .output_path = split};
    f.walkthrough = 1;
    CHECK(sw_renderer_prepare(r, &f, &st) == SW_OK, "prepare: %s", st.message);
    memset(&fs, 0, sizeof fs);
    CHECK(sw_renderer_submit(r, &fs, &st) == SW_OK, "submit: %s", st.message);
    CHECK(fs.meshes_drawn == 1, "split frame: %llu meshes drawn",
          (unsigned long long)fs.meshes_drawn);
    char exact[1024];
    snprintf(exact, sizeof exact, "%s/mesh_only_exact.png", g_work);
    sw_frame_desc fe = {.scene = s, .camera = k_top, .width = W, .height = H, .output_path = exact};
    fe.eval_exact = 1;
    CHECK(sw_renderer_draw(r, &fe, NULL, &st) == SW_OK, "exact: %s", st.message);
    const double dw = sw_test_differing_percent(conv, walk),
                 ds = sw_test_differing_percent(conv, split),
                 de = sw_test_differing_percent(conv, exact);
    CHECK(dw == 0.0 && ds == 0.0 && de == 0.0,
          "walkthrough %.4f %%, split %.4f %%, eval_exact %.4f %% differ from converged", dw, ds,
          de);
    printf("mesh only: walkthrough %.4f %%, split frame %.4f %%, eval_exact %.4f %% of pixels "
           "differ from converged\n",
           dw, ds, de);

    /* A live edit: a smaller sphere, the plate back. */
    EXPECT_RESULT(sw_node_set_visible(s, pl, 1, NULL), SW_OK);
    sw_mesh_desc smaller = sphere(sm, c, 2.5);
    CHECK(sw_node_set_mesh(s, ball, &smaller, &st) == SW_OK, "set_mesh: %s", st.message);
    draw(r, s, &k_top, 0, "occlusion_edited", edited, NULL);
    check_against_trace(edited, 2.5, "after sw_node_set_mesh");

    /* Looking away: the mesh is culled by its box. */
    const sw_camera away = {{0, 0, 20}, {0, 0, 40}, {0, 1, 0}, 40};
    memset(&fs, 0, sizeof fs);
    draw(r, s, &away, 0, "away", walk, &fs);
    CHECK(fs.meshes_culled == 1 && fs.meshes_drawn == 0, "looking away: %llu culled, %llu drawn",
          (unsigned long long)fs.meshes_culled, (unsigned long long)fs.meshes_drawn);
    sw_scene_destroy(s);
}

/* The same tilted plate as a NURBS node and as a two-triangle mesh node. */
static void test_mesh_vs_nurbs(sw_renderer r)
{
    double tilt[12] = {1, 0, 0, 0, 0, cos(0.5), -sin(0.5), 0, 0, sin(0.5), cos(0.5), 0};
    const double pts[12] = {-4, -3, 0, 4, -3, 0, -4, 3, 0, 4, 3, 0};
    const uint32_t tris[6] = {0, 1, 3, 0, 3, 2};
    sw_scene a, b;
    EXPECT_RESULT(sw_scene_create(NULL, &a, NULL), SW_OK);
    EXPECT_RESULT(sw_scene_create(NULL, &b, NULL), SW_OK);
    sw_nurbs_desc pd = plate(2, -4, 4, -3, 3, 0);
    sw_node_desc pn = {.kind = SW_NODE_NURBS, .nurbs = &pd};
    memcpy(pn.transform, tilt, sizeof tilt);
    set_color(pn.color, 0.9f, 0.6f, 0.1f);
    sw_node n;
    sw_status st = {0};
    CHECK(sw_node_add(a, &pn, &n, &st) == SW_OK, "plate: %s", st.message);
    sw_mesh_desc md = {4, pts, NULL, 2, tris};
    CHECK(sw_node_add_mesh(b, &pn, &md, &n, &st) == SW_OK, "plate mesh: %s", st.message);
    const sw_camera cam = {{3, -12, 9}, {0, 0, 0}, {0, 0, 1}, 40};
    char pa[1024], pb[1024];
    draw(r, a, &cam, 0, "plate_nurbs", pa, NULL);
    draw(r, b, &cam, 0, "plate_mesh", pb, NULL);
    const double d = one_pixel_percent(pa, pb), exact = sw_test_differing_percent(pa, pb);
    /* the control: the background differs from the plate everywhere it shows */
    CHECK(d <= 0.1, "plate as mesh vs as NURBS: %.4f %% unmatched within one pixel", d);
    printf("plate as a mesh vs as NURBS: %.4f %% of pixels unmatched within one pixel (limit "
           "0.1 %%), %.4f %% differ at all\n",
           d, exact);
    sw_scene_destroy(a);
    sw_scene_destroy(b);
}

/* The pixel where world point p shows (the tracer's camera). */
static void project(const tracer *t, const double p[3], int *x, int *y)
{
    double rel[3], r = 0.0, u = 0.0, z = 0.0;
    for (int k = 0; k < 3; k++)
        rel[k] = p[k] - t->eye[k];
    for (int k = 0; k < 3; k++) {
        r += rel[k] * t->right[k];
        u += rel[k] * t->up[k];
        z += rel[k] * t->fwd[k];
    }
    *x = (int)floor(W / 2.0 + t->focal * r / z);
    *y = (int)floor(H / 2.0 - t->focal * u / z);
}

/* Instances place a detached mesh prototype with their transforms and colours; a mesh's own
 * colour wins over its instance's (sw_nodes.h, Colours). Checked at each box's projected centre
 * and beside it (background). */
static void test_instances(sw_renderer r)
{
    sw_scene s;
    EXPECT_RESULT(sw_scene_create(NULL, &s, NULL), SW_OK);
    sw_mesh_desc bm = box_mesh(1.0);
    sw_node plain, blue;
    sw_node_desc proto = {.detached = 1};
    EXPECT_RESULT(sw_node_add_mesh(s, &proto, &bm, &plain, NULL), SW_OK);
    set_color(proto.color, 0.1f, 0.2f, 0.9f);
    EXPECT_RESULT(sw_node_add_mesh(s, &proto, &bm, &blue, NULL), SW_OK);
    const struct {
        double x;
        sw_node of;
        float c[3];
    } inst[3] = {{-6, plain, {0.9f, 0.1f, 0.1f}},
                 {-1, plain, {0.1f, 0.8f, 0.2f}},
                 {4, blue, {0.9f, 0.1f, 0.1f}}};
    for (int k = 0; k < 3; k++) {
        sw_node_desc d = {.kind = SW_NODE_INSTANCE, .instance_of = inst[k].of};
        translation(d.transform, inst[k].x, -1, 0);
        set_color(d.color, inst[k].c[0], inst[k].c[1], inst[k].c[2]);
        sw_node n;
        EXPECT_RESULT(sw_node_add(s, &d, &n, NULL), SW_OK);
    }
    const sw_camera cam = {{0, 0, 20}, {0, 0, 0}, {0, 1, 0}, 40};
    char path[1024];
    sw_frame_stats fs;
    memset(&fs, 0, sizeof fs);
    draw(r, s, &cam, 0, "instances", path, &fs);
    CHECK(fs.meshes_drawn == 3, "instances: %llu mesh occurrences drawn",
          (unsigned long long)fs.meshes_drawn);
    tracer t;
    tracer_camera(&t, &cam);
    int w = 0, h = 0;
    unsigned char *img = sw_test_read_rgba(path, &w, &h);
    CHECK(img && w == W && h == H, "read %s", path);
    const int want[3] = {0, 1, 2}; /* dominant channel: red, green, blue (the mesh's own) */
    for (int k = 0; img && w == W && h == H && k < 3; k++) {
        const double c[3] = {inst[k].x + 1.0, 0.0, 1.0}, beside[3] = {inst[k].x + 1.0, 2.5, 0.0};
        int x, y, bx, by;
        project(&t, c, &x, &y);
        project(&t, beside, &bx, &by);
        const unsigned char *p = img + 4 * ((size_t)y * W + x),
                            *q = img + 4 * ((size_t)by * W + bx);
        int dom = p[0] >= p[1] && p[0] >= p[2] ? 0 : p[1] >= p[2] ? 1 : 2;
        CHECK(dom == want[k] && q[0] >= 250 && q[1] >= 250 && q[2] >= 250,
              "instance %d: pixel (%d, %d) = (%u, %u, %u), dominant %d (want %d); beside it "
              "(%u, %u, %u)",
              k, x, y, p[0], p[1], p[2], dom, want[k], q[0], q[1], q[2]);
    }
    free(img);
    sw_scene_destroy(s);
}

static void test_render(void)
{
    sw_renderer r;
    sw_status st = {0};
    if (sw_renderer_create(NULL, &r, &st) != SW_OK) {
        CHECK(0, "renderer: %s", st.message);
        return;
    }
    sphere_mesh *sm = malloc(sizeof *sm);
    test_occlusion(r, sm);
    test_mesh_vs_nurbs(r);
    test_instances(r);
    free(sm);
    sw_renderer_destroy(r);
}

int main(int argc, char **argv)
{
    if (argc == 3 && strcmp(argv[1], "meshes") == 0) {
        g_work = argv[2];
        test_meshes();
    } else if (argc == 3 && strcmp(argv[1], "render") == 0) {
        g_work = argv[2];
        test_render();
    } else {
        fprintf(stderr, "usage: test_api_meshes meshes|render WORKDIR\n");
        return 2;
    }
    printf("%s: %d failure(s)\n", argv[1], g_failures);
    return g_failures != 0;
}
