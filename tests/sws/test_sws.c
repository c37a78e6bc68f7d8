/* SPDX-License-Identifier: MIT */
/* Tests of the scene container and the .sws file (scene.c, scene_validate.c, sws_file.c,
 * scene_stats.c): a round trip that must be bit-identical, traversal against transforms composed
 * independently here, and hostile files (truncated, flipped bytes, huge offsets, bad indices,
 * cycles) that must fail with the right result id and no crash; triangle meshes round-tripped
 * through the MESHES and INDICES sections, their occurrences, stats and the checks on them. Run
 * with `--write-seed DIR` it only saves the test scenes to DIR/scene.sws and DIR/meshes.sws (the
 * fuzzer's seed corpus). */
#include "sws_test_scene.h"
#include "sw_crc32c.h"

#include <setjmp.h> /* cmocka needs these before cmocka.h */
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

/* Format constants, from docs/sws-format.md (not from the implementation). */
enum { HDR_FILE_SIZE = 24, HDR_TABLE = 32, HDR_CRC = 60, ENTRY = 40, N_SEC = 8 };
static const char *const sec_names[N_SEC] = {"FACES",     "LOOPS", "CURVES",  "NODES",
                                             "ADJACENCY", "POOL",  "STRINGS", "META"};

static char g_dir[256];
static char g_path[300];
static unsigned char *g_file;
static size_t g_len;

/* ---- helpers ----------------------------------------------------------------------------------
 */

static uint32_t rd32(const unsigned char *p)
{
    uint32_t x;
    memcpy(&x, p, 4);
    return x;
}

static uint64_t rd64(const unsigned char *p)
{
    uint64_t x;
    memcpy(&x, p, 8);
    return x;
}

static void wr32(unsigned char *p, uint32_t x)
{
    memcpy(p, &x, 4);
}

static void wr64(unsigned char *p, uint64_t x)
{
    memcpy(p, &x, 8);
}

static unsigned char *read_all(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *d = malloc(n > 0 ? (size_t)n : 1);
    if (d && fread(d, 1, (size_t)n, f) != (size_t)n) {
        free(d);
        d = NULL;
    }
    fclose(f);
    *len = (size_t)n;
    return d;
}

static void write_bytes(const char *path, const void *d, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(d, 1, n, f), n);
    assert_int_equal(fclose(f), 0);
}

/* Table entry of section `id` in a file image (entries are written in id order, but look). */
static unsigned char *entry_of(unsigned char *file, uint32_t id)
{
    uint64_t table = rd64(file + HDR_TABLE);
    for (int i = 0; i < N_SEC; i++)
        if (rd32(file + table + (uint64_t)i * ENTRY) == id)
            return file + table + (uint64_t)i * ENTRY;
    fail_msg("no section %u", id);
    return NULL;
}

/* Recomputes every section checksum and the header checksum of a (patched) file image, so that
 * a test reaches the check it aims at rather than the checksum. */
static void reseal(unsigned char *file, size_t len)
{
    uint64_t table = rd64(file + HDR_TABLE);
    for (int i = 0; i < N_SEC; i++) {
        unsigned char *e = file + table + (uint64_t)i * ENTRY;
        uint64_t off = rd64(e + 8), size = rd64(e + 16);
        if (off <= len && size <= len - off)
            wr32(e + 32, sw__crc32c(0, file + off, size));
    }
    uint32_t crc = sw__crc32c(0, file, HDR_CRC);
    wr32(file + HDR_CRC, sw__crc32c(crc, file + table, (size_t)N_SEC * ENTRY));
}

/* Writes `img` to a scratch file and opens it; returns the open result. */
static sw_result open_image(const unsigned char *img, size_t len, sw_sg_scene **out, sw_status *st,
                            char *path_out)
{
    snprintf(path_out, 300, "%s/bad.sws", g_dir);
    write_bytes(path_out, img, len);
    memset(st, 0, sizeof *st);
    return sw_sg_scene_open(path_out, out, st);
}

/* Opens a patched copy of the good file and requires every section; returns that result. */
static sw_result require_patched(unsigned char *img, sw_status *st, char *path)
{
    sw_sg_scene *s = NULL;
    reseal(img, g_len);
    sw_result r = open_image(img, g_len, &s, st, path);
    if (r == SW_OK) {
        r = sw_sg_scene_require(s, SW_SG_SEC_ALL, st);
        sw_sg_scene_free(s);
    }
    return r;
}

static sw_sg_scene *build_test_scene(void)
{
    sw_sg_scene *s = NULL;
    sw_status st = {0};
    sw_result r = sw_sg_builder_finish(sws_test_builder(), &s, &st);
    if (r != SW_OK)
        fprintf(stderr, "finish: %s\n", st.message);
    assert_int_equal(r, SW_OK);
    return s;
}

static int remove_dir(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return -1;
    struct dirent *e;
    char p[600];
    while ((e = readdir(d))) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
        struct stat st;
        if (lstat(p, &st) == 0 && S_ISDIR(st.st_mode)) {
            chmod(p, 0700);
            remove_dir(p);
        } else {
            unlink(p);
        }
    }
    closedir(d);
    return rmdir(dir);
}

/* Number of entries in `dir` whose name contains ".tmp-". */
static int count_temp_files(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        n += strstr(e->d_name, ".tmp-") != NULL;
    if (d)
        closedir(d);
    return n;
}

static int group_setup(void **state)
{
    (void)state;
    const char *t = getenv("TMPDIR");
    snprintf(g_dir, sizeof g_dir, "%s/sws-test-XXXXXX", t && *t ? t : "/tmp");
    if (!mkdtemp(g_dir))
        return -1;
    snprintf(g_path, sizeof g_path, "%s/scene.sws", g_dir);
    sw_sg_scene *s = build_test_scene();
    sw_status st = {0};
    if (sw_sg_scene_save(s, g_path, &st) != SW_OK) {
        fprintf(stderr, "save: %s\n", st.message);
        return -1;
    }
    sw_sg_scene_free(s);
    g_file = read_all(g_path, &g_len);
    return g_file ? 0 : -1;
}

static int group_teardown(void **state)
{
    (void)state;
    free(g_file);
    return remove_dir(g_dir) == 0 ? 0 : -1;
}

/* ---- checksum ---------------------------------------------------------------------------------
 */

static void test_crc32c(void **state)
{
    (void)state;
    /* Reference values: the CRC-32C check value and RFC 3720 B.4 (32 bytes of zeros / 0xFF). */
    assert_int_equal(sw__crc32c(0, "123456789", 9), 0xE3069283u);
    unsigned char z[32] = {0}, f[32];
    memset(f, 0xFF, sizeof f);
    assert_int_equal(sw__crc32c(0, z, 32), 0x8A9136AAu);
    assert_int_equal(sw__crc32c(0, f, 32), 0x62A8AB43u);
    assert_int_equal(sw__crc32c_portable(0, "123456789", 9), 0xE3069283u);
    unsigned char buf[1031];
    for (size_t i = 0; i < sizeof buf; i++)
        buf[i] = (unsigned char)(i * 131u + 7u);
    for (size_t start = 0; start < 9; start++)
        for (size_t n = 0; n + start <= sizeof buf; n += 97) {
            uint32_t a = sw__crc32c(0, buf + start, n);
            assert_int_equal(a, sw__crc32c_portable(0, buf + start, n));
            uint32_t split =
                sw__crc32c(sw__crc32c(0, buf + start, n / 3), buf + start + n / 3, n - n / 3);
            assert_int_equal(a, split);
        }
}

/* ---- round trip and traversal -----------------------------------------------------------------
 */

typedef struct occ {
    uint32_t face;
    double world[12];
    float color[4];
} occ;

typedef struct occ_list {
    occ o[16];
    int n;
} occ_list;

static int collect(void *ctx, uint32_t face, const double world[12], const float color[4])
{
    occ_list *l = ctx;
    assert_true(l->n < 16);
    l->o[l->n].face = face;
    memcpy(l->o[l->n].world, world, sizeof l->o[0].world);
    memcpy(l->o[l->n].color, color, sizeof l->o[0].color);
    l->n++;
    return 0;
}

/* 4x4 homogeneous product, written independently of the library's 3x4 composition. */
static void mat4(const double m[12], double out[4][4])
{
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++)
            out[r][c] = m[4 * r + c];
    out[3][0] = out[3][1] = out[3][2] = 0;
    out[3][3] = 1;
}

static void chain(double out[12], int n, const double *const *ms)
{
    double acc[4][4], m[4][4], t[4][4];
    mat4(ms[0], acc);
    for (int k = 1; k < n; k++) {
        mat4(ms[k], m);
        for (int r = 0; r < 4; r++)
            for (int c = 0; c < 4; c++) {
                t[r][c] = 0;
                for (int i = 0; i < 4; i++)
                    t[r][c] += acc[r][i] * m[i][c];
            }
        memcpy(acc, t, sizeof acc);
    }
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++)
            out[4 * r + c] = acc[r][c];
}

static void expected_occurrences(occ_list *e)
{
    double t1[12], t2[12], s1[12], s2[12], i1[12], i2[12];
    sws_test_xforms(t1, t2, s1, s2, i1, i2);
    memset(e, 0, sizeof *e);
    e->n = 4;
    e->o[0].face = 0;
    chain(e->o[0].world, 1, (const double *const[]){t1});
    memcpy(e->o[0].color, sws_red, sizeof sws_red);
    e->o[1].face = 1;
    chain(e->o[1].world, 3, (const double *const[]){t1, t2, s1});
    memcpy(e->o[1].color, sws_green, sizeof sws_green);
    e->o[2].face = 2;
    chain(e->o[2].world, 3, (const double *const[]){t1, i2, s2});
    memcpy(e->o[2].color, sws_red, sizeof sws_red);
    e->o[3].face = 2;
    chain(e->o[3].world, 2, (const double *const[]){i1, s2});
    memcpy(e->o[3].color, sws_blue, sizeof sws_blue);
}

static int occ_matches(const occ *a, const occ *b)
{
    if (a->face != b->face || memcmp(a->color, b->color, sizeof a->color))
        return 0;
    for (int k = 0; k < 12; k++)
        if (fabs(a->world[k] - b->world[k]) > 1e-12 * (1.0 + fabs(b->world[k])))
            return 0;
    return 1;
}

/* Each expected occurrence is matched by exactly one traversed one (order is not specified). */
static void check_traversal(const sw_sg_scene *s)
{
    occ_list got = {0}, want;
    sw_sg_scene_traverse(s, collect, &got);
    expected_occurrences(&want);
    assert_int_equal(got.n, want.n);
    int used[16] = {0};
    for (int i = 0; i < want.n; i++) {
        int hits = 0;
        for (int j = 0; j < got.n; j++)
            if (!used[j] && occ_matches(&got.o[j], &want.o[i])) {
                used[j] = 1;
                hits++;
                break;
            }
        assert_int_equal(hits, 1);
    }
}

static void assert_views_identical(const sw_sg_scene_view *a, const sw_sg_scene_view *b)
{
    assert_int_equal(a->n_faces, b->n_faces);
    assert_int_equal(a->n_loops, b->n_loops);
    assert_int_equal(a->n_curves, b->n_curves);
    assert_int_equal(a->n_nodes, b->n_nodes);
    assert_int_equal(a->n_adjacency, b->n_adjacency);
    assert_int_equal(a->n_pool, b->n_pool);
    assert_int_equal(a->n_strings, b->n_strings);
    assert_int_equal(a->root, b->root);
    assert_memory_equal(a->faces, b->faces, a->n_faces * sizeof *a->faces);
    assert_memory_equal(a->loops, b->loops, a->n_loops * sizeof *a->loops);
    assert_memory_equal(a->curves, b->curves, a->n_curves * sizeof *a->curves);
    assert_memory_equal(a->nodes, b->nodes, a->n_nodes * sizeof *a->nodes);
    assert_memory_equal(a->adjacency, b->adjacency, a->n_adjacency * sizeof *a->adjacency);
    assert_memory_equal(a->pool, b->pool, a->n_pool * sizeof *a->pool);
    assert_memory_equal(a->strings, b->strings, a->n_strings);
}

static void test_roundtrip(void **state)
{
    (void)state;
    sw_sg_scene *mem = build_test_scene(), *file = NULL;
    sw_status st = {0};
    assert_string_equal(sw_sg_scene_path_ptr(mem), "");
    assert_int_equal(sw_sg_scene_open(g_path, &file, &st), SW_OK);
    assert_string_equal(sw_sg_scene_path_ptr(file), g_path);
    assert_int_equal(sw_sg_scene_require(file, SW_SG_SEC_ALL, &st), SW_OK);
    const sw_sg_scene_view *a = sw_sg_scene_view_ptr(mem), *b = sw_sg_scene_view_ptr(file);
    assert_int_equal(a->n_faces, 3);
    assert_int_equal(a->n_nodes, 9);
    assert_views_identical(a, b);
    /* The records seen through the file equal the ones the test built, field by field. */
    assert_int_equal(b->nodes[4].kind, SW_SG_NODE_SURFACE);
    assert_int_equal(b->nodes[4].ref, 1);
    assert_string_equal(b->strings + b->nodes[4].name, "face1");
    assert_int_equal(b->nodes[6].ref, 5);
    assert_int_equal(b->faces[0].n_u, 5);
    assert_int_equal(b->adjacency[1].face_b, 2);
    sw_sg_surface sa, sb;
    sw_sg_scene_face_surface(mem, 0, &sa);
    sw_sg_scene_face_surface(file, 0, &sb);
    assert_memory_equal(sa.cpw, sb.cpw, 5 * 4 * 4 * sizeof(double));
    assert_true(sb.cpw[3] == 1.0 && sb.cpw[7] == 1.25);
    sw_sg_curve ca;
    sw_sg_scene_curve(file, 5, &ca);
    assert_int_equal(ca.degree, 2);
    assert_int_equal(ca.dim, 3);
    assert_true(ca.cpw[5] == 0.7);

    check_traversal(mem);
    check_traversal(file);
    occ_list la = {0}, lb = {0};
    sw_sg_scene_traverse(mem, collect, &la);
    sw_sg_scene_traverse(file, collect, &lb);
    assert_memory_equal(la.o, lb.o, sizeof la.o);
    assert_true(sw_sg_scene_memory(file) >= g_len);
    sw_sg_scene_free(mem);
    sw_sg_scene_free(file);
}

/* Re-saving a mapped scene writes the same bytes; saving over the mapped file itself replaces it
 * by rename while the old mapping stays readable. */
static void test_resave_mapped(void **state)
{
    (void)state;
    sw_sg_scene *s = NULL;
    sw_status st = {0};
    char p2[320];
    snprintf(p2, sizeof p2, "%s/copy.sws", g_dir);
    write_bytes(p2, g_file, g_len);
    assert_int_equal(sw_sg_scene_open(p2, &s, &st), SW_OK);
    assert_int_equal(sw_sg_scene_save(s, p2, &st), SW_OK);
    size_t n = 0;
    unsigned char *again = read_all(p2, &n);
    assert_non_null(again);
    assert_int_equal(n, g_len);
    assert_memory_equal(again, g_file, g_len);
    check_traversal(s);
    free(again);
    sw_sg_scene_free(s);
    assert_int_equal(count_temp_files(g_dir), 0);
}

static int stop_after_one(void *ctx, uint32_t face, const double world[12], const float color[4])
{
    (void)face, (void)world, (void)color;
    ++*(int *)ctx;
    return 1;
}

static void test_default_color_and_stop(void **state)
{
    (void)state;
    sw_sg_builder *b = sw_sg_builder_create();
    sws_test_face(b, 4, 0.0, 0, 0, SW_SG_KIND_OTHER);
    uint32_t g = sw_sg_builder_add_node(b, SW_SG_NODE_GROUP, 0, SW_SG_NONE, NULL, NULL, NULL);
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, g, 0, NULL, NULL, NULL);
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, 0, NULL, NULL, NULL);
    sw_sg_scene *s = NULL;
    assert_int_equal(sw_sg_builder_finish(b, &s, NULL), SW_OK);
    occ_list l = {0};
    sw_sg_scene_traverse(s, collect, &l);
    assert_int_equal(l.n, 2);
    const float grey[4] = {0.8f, 0.8f, 0.8f, 1.0f};
    const double id[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    for (int i = 0; i < 2; i++) {
        assert_memory_equal(l.o[i].color, grey, sizeof grey);
        assert_memory_equal(l.o[i].world, id, sizeof id);
    }
    int calls = 0;
    sw_sg_scene_traverse(s, stop_after_one, &calls);
    assert_int_equal(calls, 1);
    sw_sg_scene_free(s);
}

static void test_stats(void **state)
{
    (void)state;
    sw_sg_scene *s = NULL;
    sw_status st = {0};
    assert_int_equal(sw_sg_scene_open(g_path, &s, &st), SW_OK);
    assert_int_equal(sw_sg_scene_require(s, SW_SG_SEC_ALL, &st), SW_OK);
    sw_sg_scene_stats a;
    sw_sg_scene_compute_stats(s, &a);
    assert_int_equal(a.faces, 3);
    assert_int_equal(a.faces_by_kind[SW_SG_KIND_BSPLINE], 1);
    assert_int_equal(a.faces_by_kind[SW_SG_KIND_BEZIER], 1);
    assert_int_equal(a.faces_by_kind[SW_SG_KIND_PLANE], 1);
    assert_int_equal(a.trimmed_faces, 2);
    assert_int_equal(a.loops, 2);
    assert_int_equal(a.curves, 6);
    assert_int_equal(a.bezier_patches, 2 + 1 + 1); /* face 0 has two knot spans in u */
    assert_int_equal(a.max_deg_u, 3);
    assert_int_equal(a.max_curve_degree, 2);
    assert_int_equal(a.control_points, 20 + 16 + 16);
    assert_int_equal(a.nodes, 9);
    assert_int_equal(a.instances, 2);
    assert_int_equal(a.face_occurrences, 4);
    assert_int_equal(a.adjacency, 2);
    assert_true(a.memory_bytes >= g_len);

    /* The stats box is the faces sampled on a 17x17 grid over their trim boxes, each face's local
     * box placed in the world by its corners. Independently: it must contain every sample point
     * transformed directly, and lie inside the corners of each face's control-net box (the convex
     * hull bound), all through the reference transforms. */
    occ_list want;
    expected_occurrences(&want);
    double inner[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    double outer[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(s);
    for (int k = 0; k < want.n; k++) {
        sw_sg_surface f;
        sw_sg_scene_face_surface(s, want.o[k].face, &f);
        const double *m = want.o[k].world, *uv = v->faces[want.o[k].face].uv_box;
        double local[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
        for (int i = 0; i < f.n_u * f.n_v; i++)
            for (int r = 0; r < 3; r++) {
                local[r] = fmin(local[r], f.cpw[4 * i + r] / f.cpw[4 * i + 3]);
                local[3 + r] = fmax(local[3 + r], f.cpw[4 * i + r] / f.cpw[4 * i + 3]);
            }
        for (int c = 0; c < 8; c++)
            for (int r = 0; r < 3; r++) {
                double x = m[4 * r] * local[(c & 1) ? 3 : 0] +
                           m[4 * r + 1] * local[(c & 2) ? 4 : 1] +
                           m[4 * r + 2] * local[(c & 4) ? 5 : 2] + m[4 * r + 3];
                outer[r] = fmin(outer[r], x);
                outer[3 + r] = fmax(outer[3 + r], x);
            }
        for (int j = 0; j < 17; j++)
            for (int i = 0; i < 17; i++) {
                double p[3];
                sw_sg_surface_eval(&f, uv[0] + (uv[1] - uv[0]) * i / 16.0,
                                   uv[2] + (uv[3] - uv[2]) * j / 16.0, p);
                for (int r = 0; r < 3; r++) {
                    double x =
                        m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3];
                    inner[r] = fmin(inner[r], x);
                    inner[3 + r] = fmax(inner[3 + r], x);
                }
            }
    }
    for (int r = 0; r < 3; r++) {
        double tol = 1e-12 * (1.0 + fabs(outer[r]) + fabs(outer[3 + r]));
        assert_true(a.bbox[r] <= inner[r] + tol && a.bbox[3 + r] >= inner[3 + r] - tol);
        assert_true(a.bbox[r] >= outer[r] - tol && a.bbox[3 + r] <= outer[3 + r] + tol);
    }
    /* and it is the surfaces' box, not the nets': the weighted sine nets bulge beyond them in z */
    assert_true((outer[5] - outer[2]) - (a.bbox[5] - a.bbox[2]) > 1e-3);
    sw_sg_scene_free(s);
}

/* ---- hostile files ----------------------------------------------------------------------------
 */

static void expect_open(const unsigned char *img, size_t len, sw_result want)
{
    sw_sg_scene *s = (sw_sg_scene *)&s; /* must come back NULL */
    sw_status st = {0};
    char path[300];
    sw_result r = open_image(img, len, &s, &st, path);
    if (r != want)
        fprintf(stderr, "len %zu: got %s (%s)\n", len, sw_result_str(r), st.message);
    assert_int_equal(r, want);
    assert_null(s);
    assert_int_equal(st.result, want);
    assert_non_null(strstr(st.message, path));
}

static void test_truncated(void **state)
{
    (void)state;
    uint64_t table = rd64(g_file + HDR_TABLE);
    uint64_t faces = rd64(entry_of(g_file, 0) + 8), pool = rd64(entry_of(g_file, 5) + 8);
    const size_t cuts[] = {0,
                           3,
                           8,
                           11,
                           20,
                           63,
                           64,
                           (size_t)table + 7,
                           (size_t)table + 319,
                           (size_t)table + 320,
                           (size_t)faces + 50,
                           (size_t)pool + 8,
                           g_len - 1};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++)
        expect_open(g_file, cuts[i], SW_ERR_TRUNCATED);
    /* The header claims more bytes than the file has: the cut is after the table. */
    unsigned char *img = malloc(g_len);
    memcpy(img, g_file, g_len);
    wr64(img + HDR_FILE_SIZE, g_len + 4096);
    reseal(img, g_len);
    expect_open(img, g_len, SW_ERR_TRUNCATED);
    free(img);
}

static void test_checksum_each_section(void **state)
{
    (void)state;
    for (uint32_t id = 0; id < N_SEC; id++) {
        unsigned char *img = malloc(g_len);
        memcpy(img, g_file, g_len);
        unsigned char *e = entry_of(img, id);
        uint64_t off = rd64(e + 8), size = rd64(e + 16);
        assert_true(size > 0);
        img[off + size / 2] ^= 0x10;
        sw_sg_scene *s = NULL;
        sw_status st = {0};
        char path[300];
        sw_result r = open_image(img, g_len, &s, &st, path);
        if (id == 7) { /* META is verified at open: the root is needed for the view */
            assert_int_equal(r, SW_ERR_CHECKSUM);
        } else {
            assert_int_equal(r, SW_OK);
            uint32_t other = SW_SG_SEC_ALL & ~(1u << id);
            assert_int_equal(sw_sg_scene_require(s, other, &st), SW_OK);
            for (int twice = 0; twice < 2; twice++) {
                assert_int_equal(sw_sg_scene_require(s, 1u << id, &st), SW_ERR_CHECKSUM);
                assert_int_equal(sw_sg_scene_require(s, SW_SG_SEC_ALL, &st), SW_ERR_CHECKSUM);
            }
            sw_sg_scene_free(s);
        }
        assert_non_null(strstr(st.message, path));
        assert_non_null(strstr(st.message, sec_names[id]));
        free(img);
    }
}

static void test_header(void **state)
{
    (void)state;
    unsigned char *img = malloc(g_len);
    memcpy(img, g_file, g_len);
    img[2] = 'x';
    expect_open(img, g_len, SW_ERR_FORMAT);
    expect_open(img, 5, SW_ERR_FORMAT);
    memcpy(img, g_file, g_len);
    wr32(img + 8, 2);
    expect_open(img, g_len, SW_ERR_VERSION);
    expect_open(img, 40, SW_ERR_VERSION);
    wr32(img + 8, 0);
    expect_open(img, g_len, SW_ERR_VERSION);
    memcpy(img, g_file, g_len);
    img[12] ^= 1; /* flags, not resealed */
    expect_open(img, g_len, SW_ERR_CHECKSUM);
    reseal(img, g_len);
    expect_open(img, g_len, SW_ERR_FORMAT);
    memcpy(img, g_file, g_len);
    img[rd64(img + HDR_TABLE) + 8] ^= 1; /* a table byte, not resealed */
    expect_open(img, g_len, SW_ERR_CHECKSUM);
    memcpy(img, g_file, g_len);
    wr64(img + HDR_FILE_SIZE, g_len - 16); /* trailing bytes */
    reseal(img, g_len);
    expect_open(img, g_len, SW_ERR_FORMAT);
    free(img);
}

/* Huge offsets, sizes and counts in the header and table: every one is rejected, none crashes. */
static void test_overflowing_table(void **state)
{
    (void)state;
    const uint64_t huge[] = {UINT64_MAX, UINT64_MAX - 15,  UINT64_MAX / 8 + 1,
                             1ull << 63, (1ull << 61) + 1, 0xFFFFFFF0ull};
    unsigned char *img = malloc(g_len);
    for (size_t h = 0; h < sizeof huge / sizeof huge[0]; h++) {
        for (uint32_t id = 0; id < N_SEC; id++)
            for (int field = 8; field <= 24; field += 8) {
                memcpy(img, g_file, g_len);
                wr64(entry_of(img, id) + field, huge[h]);
                reseal(img, g_len);
                expect_open(img, g_len, SW_ERR_FORMAT);
            }
        /* count * record size wraps around to the real size */
        memcpy(img, g_file, g_len);
        unsigned char *e = entry_of(img, 5);
        wr64(e + 24, rd64(e + 24) + (1ull << 61));
        reseal(img, g_len);
        expect_open(img, g_len, SW_ERR_FORMAT);
        memcpy(img, g_file, g_len);
        wr64(img + HDR_TABLE, huge[h]); /* not resealed: the table is found before its CRC */
        expect_open(img, g_len, SW_ERR_FORMAT);
        memcpy(img, g_file, g_len);
        wr64(img + HDR_FILE_SIZE, huge[h]);
        reseal(img, g_len);
        expect_open(img, g_len, SW_ERR_TRUNCATED);
    }
    free(img);
}

/* Offset of record `index` of section `id` in a file image. */
static unsigned char *record(unsigned char *img, uint32_t id, uint32_t rec_size, uint32_t index)
{
    return img + rd64(entry_of(img, id) + 8) + (uint64_t)index * rec_size;
}

static void expect_require(unsigned char *img, sw_result want)
{
    sw_status st = {0};
    char path[300];
    sw_result r = require_patched(img, &st, path);
    if (r != want)
        fprintf(stderr, "got %s (%s)\n", sw_result_str(r), st.message);
    assert_int_equal(r, want);
    assert_non_null(strstr(st.message, path));
    assert_non_null(strstr(st.message, "offset"));
}

static void test_bad_records(void **state)
{
    (void)state;
    unsigned char *img = malloc(g_len);
    const uint32_t FACE = sizeof(sw_sg_face_rec), NODE = sizeof(sw_sg_node_rec);
    /* node 2 draws face 99 of 3 */
    memcpy(img, g_file, g_len);
    sw_sg_node_rec nd;
    memcpy(&nd, record(img, 3, NODE, 2), NODE);
    nd.ref = 99;
    memcpy(record(img, 3, NODE, 2), &nd, NODE);
    expect_require(img, SW_ERR_FORMAT);
    /* face 1's control points run past the pool */
    memcpy(img, g_file, g_len);
    sw_sg_face_rec f;
    memcpy(&f, record(img, 0, FACE, 1), FACE);
    f.cpw = rd64(entry_of(img, 5) + 24) - 3;
    memcpy(record(img, 0, FACE, 1), &f, FACE);
    expect_require(img, SW_ERR_FORMAT);
    f.cpw = UINT64_MAX - 1; /* offset + count would wrap */
    memcpy(record(img, 0, FACE, 1), &f, FACE);
    expect_require(img, SW_ERR_FORMAT);
    /* n_u * n_v * 4 would overflow 32 bits */
    memcpy(&f, record(g_file, 0, FACE, 1), FACE);
    f.n_u = f.n_v = 0x80000000u;
    memcpy(record(img, 0, FACE, 1), &f, FACE);
    expect_require(img, SW_ERR_INVALID_GEOMETRY);
    /* a NaN weight and decreasing knots in the pool */
    memcpy(img, g_file, g_len);
    memcpy(&f, record(img, 0, FACE, 2), FACE);
    double nan = NAN;
    memcpy(record(img, 5, 8, (uint32_t)f.cpw + 3), &nan, 8);
    expect_require(img, SW_ERR_INVALID_GEOMETRY);
    memcpy(img, g_file, g_len);
    double big = 5.0;
    memcpy(record(img, 5, 8, (uint32_t)f.knots_u + 1), &big, 8);
    expect_require(img, SW_ERR_INVALID_GEOMETRY);
    /* a loop past the curves; a name past the strings */
    memcpy(img, g_file, g_len);
    wr32(record(img, 1, 16, 1) + 4, 1000);
    expect_require(img, SW_ERR_FORMAT);
    memcpy(img, g_file, g_len);
    memcpy(&nd, record(img, 3, NODE, 1), NODE);
    nd.name = 1u << 30;
    memcpy(record(img, 3, NODE, 1), &nd, NODE);
    expect_require(img, SW_ERR_FORMAT);
    /* curve 5's control points past the pool; curve 0 of degree 0 */
    memcpy(img, g_file, g_len);
    sw_sg_curve_rec cr;
    memcpy(&cr, record(img, 2, sizeof cr, 5), sizeof cr);
    cr.cpw = rd64(entry_of(img, 5) + 24) - 8;
    memcpy(record(img, 2, sizeof cr, 5), &cr, sizeof cr);
    expect_require(img, SW_ERR_FORMAT);
    memcpy(img, g_file, g_len);
    wr32(record(img, 2, sizeof cr, 0), 0);
    expect_require(img, SW_ERR_INVALID_GEOMETRY);
    /* the adjacency names a face that does not exist */
    memcpy(img, g_file, g_len);
    wr32(record(img, 4, 8, 1) + 4, 3);
    expect_require(img, SW_ERR_FORMAT);
    /* the root out of range (META) */
    memcpy(img, g_file, g_len);
    wr32(img + rd64(entry_of(img, 7) + 8), 9);
    expect_require(img, SW_ERR_FORMAT);
    free(img);
}

static void test_cycles(void **state)
{
    (void)state;
    unsigned char *img = malloc(g_len);
    const uint32_t NODE = sizeof(sw_sg_node_rec);
    sw_sg_node_rec nd;
    /* the prototype's surface node [8] becomes an instance of the prototype [5] */
    memcpy(img, g_file, g_len);
    memcpy(&nd, record(img, 3, NODE, 8), NODE);
    nd.kind = SW_SG_NODE_INSTANCE;
    nd.ref = 5;
    memcpy(record(img, 3, NODE, 8), &nd, NODE);
    expect_require(img, SW_ERR_FORMAT);
    /* an instance of the root inside the root's subtree */
    memcpy(img, g_file, g_len);
    memcpy(&nd, record(img, 3, NODE, 7), NODE);
    nd.ref = 0;
    memcpy(record(img, 3, NODE, 7), &nd, NODE);
    expect_require(img, SW_ERR_FORMAT);
    /* a sibling chain that loops: [4]'s ... T1's children are 2, 3, 7; 7 -> 2 */
    memcpy(img, g_file, g_len);
    memcpy(&nd, record(img, 3, NODE, 7), NODE);
    nd.next_sibling = 2;
    memcpy(record(img, 3, NODE, 7), &nd, NODE);
    expect_require(img, SW_ERR_FORMAT);
    /* a parent cycle: T1 made a child of T2 while T2 is under T1 */
    memcpy(img, g_file, g_len);
    memcpy(&nd, record(img, 3, NODE, 4), NODE);
    nd.next_sibling = 1;
    memcpy(record(img, 3, NODE, 4), &nd, NODE);
    memcpy(&nd, record(img, 3, NODE, 1), NODE);
    nd.parent = 3;
    nd.next_sibling = SW_SG_NONE;
    memcpy(record(img, 3, NODE, 1), &nd, NODE);
    memcpy(&nd, record(img, 3, NODE, 0), NODE);
    nd.first_child = 6;
    memcpy(record(img, 3, NODE, 0), &nd, NODE);
    expect_require(img, SW_ERR_FORMAT);
    free(img);

    /* the builder refuses an instance cycle too */
    sw_sg_builder *b = sw_sg_builder_create();
    uint32_t p =
        sw_sg_builder_add_node(b, SW_SG_NODE_GROUP, SW_SG_NONE, SW_SG_NONE, NULL, NULL, NULL);
    uint32_t q = sw_sg_builder_add_node(b, SW_SG_NODE_GROUP, p, SW_SG_NONE, NULL, NULL, NULL);
    sw_sg_builder_add_node(b, SW_SG_NODE_INSTANCE, q, p, NULL, NULL, NULL);
    sw_sg_builder_add_node(b, SW_SG_NODE_INSTANCE, 0, p, NULL, NULL, NULL);
    sw_sg_scene *s = (sw_sg_scene *)&b;
    sw_status st = {0};
    assert_int_equal(sw_sg_builder_finish(b, &s, &st), SW_ERR_FORMAT);
    assert_null(s);
    assert_non_null(strstr(st.message, "cycle"));
}

/* Every padding byte between sections (no checksum covers them) flipped in turn: open refuses
 * it (such a flip went undetected). Catches a reader that skips the padding check. */
static void test_padding_flipped(void **state)
{
    (void)state;
    unsigned char *covered = calloc(g_len, 1);
    const uint64_t table = rd64(g_file + HDR_TABLE);
    memset(covered, 1, (size_t)(table + (uint64_t)N_SEC * ENTRY));
    for (int i = 0; i < N_SEC; i++) {
        const unsigned char *e = g_file + table + (uint64_t)i * ENTRY;
        memset(covered + rd64(e + 8), 1, (size_t)rd64(e + 16));
    }
    unsigned char *img = malloc(g_len);
    int flipped = 0;
    for (size_t i = 0; i < g_len; i++) {
        if (covered[i])
            continue;
        memcpy(img, g_file, g_len);
        img[i] ^= 0x20;
        sw_sg_scene *s = NULL;
        sw_status st = {0};
        char path[300];
        reseal(img, g_len);
        assert_int_equal(open_image(img, g_len, &s, &st, path), SW_ERR_FORMAT);
        assert_non_null(strstr(st.message, "padding"));
        assert_null(s);
        flipped++;
    }
    assert_true(flipped > 0);
    free(img);
    free(covered);
}

static void test_missing_file(void **state)
{
    (void)state;
    sw_sg_scene *s = NULL;
    sw_status st = {0};
    char p[320];
    snprintf(p, sizeof p, "%s/no-such.sws", g_dir);
    assert_int_equal(sw_sg_scene_open(p, &s, &st), SW_ERR_NOT_FOUND);
    assert_null(s);
    assert_non_null(strstr(st.message, p));
    snprintf(p, sizeof p, "%s/no-such-dir/x.sws", g_dir);
    assert_int_equal(sw_sg_scene_open(p, &s, &st), SW_ERR_NOT_FOUND);
    assert_int_equal(sw_sg_scene_open(g_dir, &s, &st), SW_ERR_NOT_REGULAR_FILE); /* a directory */
    assert_null(s);
}

/* Saves that fail leave no temporary file behind and the previous file untouched. */
static void test_failed_saves(void **state)
{
    (void)state;
    sw_sg_scene *s = build_test_scene();
    sw_status st = {0};
    char p[400], sub[320];
    snprintf(p, sizeof p, "%s/no-such-dir/x.sws", g_dir);
    assert_int_not_equal(sw_sg_scene_save(s, p, &st), SW_OK);
    assert_non_null(strstr(st.message, p));

    /* the target is a directory: refused before anything is written */
    snprintf(sub, sizeof sub, "%s/target", g_dir);
    assert_int_equal(mkdir(sub, 0700), 0);
    assert_int_equal(sw_sg_scene_save(s, sub, &st), SW_ERR_NOT_REGULAR_FILE);
    assert_int_equal(count_temp_files(g_dir), 0);
    assert_int_equal(rmdir(sub), 0);

    /* a directory we may not write to (root may: then the save succeeds, also fine) */
    assert_int_equal(mkdir(sub, 0500), 0);
    snprintf(p, sizeof p, "%s/x.sws", sub);
    if (geteuid() != 0) {
        assert_int_equal(sw_sg_scene_save(s, p, &st), SW_ERR_IO);
        assert_int_equal(count_temp_files(sub), 0);
    }
    chmod(sub, 0700);

    /* the write fails part way (file size limit): the old file stays as it was */
    snprintf(p, sizeof p, "%s/old.sws", g_dir);
    const char old[] = "previous contents";
    write_bytes(p, old, sizeof old);
    struct rlimit saved, lim;
    assert_int_equal(getrlimit(RLIMIT_FSIZE, &saved), 0);
    void (*prev)(int) = signal(SIGXFSZ, SIG_IGN);
    lim = saved;
    lim.rlim_cur = 1000;
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &lim), 0);
    sw_result r = sw_sg_scene_save(s, p, &st);
    assert_int_equal(setrlimit(RLIMIT_FSIZE, &saved), 0);
    signal(SIGXFSZ, prev);
    assert_int_equal(r, SW_ERR_IO);
    assert_int_equal(count_temp_files(g_dir), 0);
    size_t n = 0;
    unsigned char *d = read_all(p, &n);
    assert_int_equal(n, sizeof old);
    assert_memory_equal(d, old, sizeof old);
    free(d);
    sw_sg_scene_free(s);
}

static void test_builder_rejects(void **state)
{
    (void)state;
    /* a surface node naming a face that does not exist */
    sw_sg_builder *b = sw_sg_builder_create();
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, 3, NULL, NULL, NULL);
    sw_sg_scene *s = NULL;
    assert_int_equal(sw_sg_builder_finish(b, &s, NULL), SW_ERR_FORMAT);
    assert_null(s);
    /* decreasing knots */
    b = sw_sg_builder_create();
    uint32_t f = sws_test_face(b, 4, 0, 0, 0, SW_SG_KIND_OTHER);
    sw_sg_builder_pool_ptr(b)[sw_sg_builder_face_ptr(b, f)->knots_u + 4] = -1.0;
    sw_status st = {0};
    assert_int_equal(sw_sg_builder_finish(b, &s, &st), SW_ERR_INVALID_GEOMETRY);
    assert_non_null(strstr(st.message, "face 0"));
    assert_string_equal(sw_sg_surface_kind_str(SW_SG_KIND_TORUS), "torus");
    assert_string_equal(sw_sg_surface_kind_str(999), "unknown");
}

/* ---- triangle meshes (sections MESHES and INDICES) ------------------------------------------ */

/* A scene with a tetrahedron mesh (normals) under a transform and, drawn by an instance of its
 * group, again; a flat quad mesh (no normals) at the root; one face (the file must hold both). */
static sw_sg_builder *mesh_builder(void)
{
    sw_sg_builder *b = sw_sg_builder_create();
    static const double tet[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const double tet_n[12] = {-1, -1, -1, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const uint32_t tet_t[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    static const double quad[12] = {-2, -2, 5, 2, -2, 5, 2, 2, 5, -2, 2, 5.5};
    static const uint32_t quad_t[6] = {0, 1, 2, 0, 2, 3};
    sw_sg_mesh_rec m;
    memset(&m, 0, sizeof m);
    m.n_vertices = 4, m.n_triangles = 4;
    m.positions = sw_sg_builder_push_doubles(b, tet, 12);
    m.normals = sw_sg_builder_push_doubles(b, tet_n, 12);
    m.indices = sw_sg_builder_push_indices(b, tet_t, 12);
    const uint32_t m0 = sw_sg_builder_add_mesh(b, &m);
    m.n_triangles = 2;
    m.positions = sw_sg_builder_push_doubles(b, quad, 12);
    m.normals = SW_SG_NO_NORMALS;
    m.indices = sw_sg_builder_push_indices(b, quad_t, 6);
    const uint32_t m1 = sw_sg_builder_add_mesh(b, &m);
    const double t[12] = {2, 0, 0, 1, 0, 2, 0, 0, 0, 0, 2, 0},
                 shift[12] = {1, 0, 0, 0, 0, 1, 0, 7, 0, 0, 1, 0};
    const uint32_t g = sw_sg_builder_add_node(b, SW_SG_NODE_TRANSFORM, 0, 0, t, sws_red, "tet");
    sw_sg_builder_add_node(b, SW_SG_NODE_MESH, g, m0, NULL, NULL, NULL);
    sw_sg_builder_add_node(b, SW_SG_NODE_INSTANCE, 0, g, shift, sws_green, NULL);
    sw_sg_builder_add_node(b, SW_SG_NODE_MESH, 0, m1, NULL, NULL, "quad");
    const uint32_t f = sws_test_face(b, 4, 0, 0, 0, SW_SG_KIND_OTHER);
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, f, NULL, NULL, NULL);
    return b;
}

typedef struct mesh_occs {
    uint32_t mesh[8], node[8];
    double world[8][12];
    float color[8][4];
    int n;
} mesh_occs;

static int collect_mesh(void *ctx, uint32_t mesh, uint32_t node, const double world[12],
                        const float color[4])
{
    mesh_occs *o = ctx;
    if (o->n == 8)
        return 1;
    o->mesh[o->n] = mesh, o->node[o->n] = node;
    memcpy(o->world[o->n], world, sizeof o->world[0]);
    memcpy(o->color[o->n], color, sizeof o->color[0]);
    o->n++;
    return 0;
}

static void test_mesh_sections(void **state)
{
    (void)state;
    sw_sg_scene *mem = NULL, *file = NULL;
    sw_status st = {0};
    assert_int_equal(sw_sg_builder_finish(mesh_builder(), &mem, &st), SW_OK);
    char path[300], path2[300];
    snprintf(path, sizeof path, "%s/meshes.sws", g_dir);
    snprintf(path2, sizeof path2, "%s/meshes2.sws", g_dir);
    assert_int_equal(sw_sg_scene_save(mem, path, &st), SW_OK);
    assert_int_equal(sw_sg_scene_open(path, &file, &st), SW_OK);
    assert_int_equal(sw_sg_scene_require(file, SW_SG_SEC_ALL, &st), SW_OK);
    const sw_sg_scene_view *a = sw_sg_scene_view_ptr(mem), *b = sw_sg_scene_view_ptr(file);
    assert_views_identical(a, b);
    assert_int_equal(b->n_meshes, 2);
    assert_int_equal(b->n_indices, 18);
    assert_memory_equal(a->meshes, b->meshes, 2 * sizeof *a->meshes);
    assert_memory_equal(a->indices, b->indices, 18 * sizeof *a->indices);
    /* the boxes the builder computed are the positions' */
    const double quad_box[6] = {-2, -2, 5, 2, 2, 5.5};
    assert_memory_equal(b->meshes[1].box, quad_box, sizeof quad_box);
    /* layout per docs/sws-format.md: 11 sections, MESHES id 9 of 88-byte records, INDICES id 10 */
    size_t len = 0;
    unsigned char *img = read_all(path, &len);
    assert_non_null(img);
    assert_int_equal(rd32(img + 16), 11);
    const uint64_t table = rd64(img + HDR_TABLE);
    assert_int_equal(rd32(img + table + 9 * ENTRY), 9);
    assert_int_equal(rd64(img + table + 9 * ENTRY + 16), 2 * 88);
    assert_int_equal(rd32(img + table + 10 * ENTRY), 10);
    assert_int_equal(rd64(img + table + 10 * ENTRY + 24), 18);
    /* re-saving the mapped scene writes the same bytes */
    assert_int_equal(sw_sg_scene_save(file, path2, &st), SW_OK);
    size_t len2 = 0;
    unsigned char *img2 = read_all(path2, &len2);
    assert_int_equal(len, len2);
    assert_memory_equal(img, img2, len);
    /* occurrences: the tetrahedron under T and under shift * T, the quad at the root */
    mesh_occs o = {0};
    assert_int_equal(sw_sg_scene_traverse_meshes(file, collect_mesh, &o), SW_OK);
    assert_int_equal(o.n, 3);
    int seen_shifted = 0, seen_quad = 0;
    for (int k = 0; k < o.n; k++) {
        if (o.mesh[k] == 1) {
            seen_quad++;
            assert_true(o.world[k][0] == 1.0 && o.world[k][3] == 0.0);
        } else if (o.world[k][7] == 7.0) {
            seen_shifted++;
            assert_true(o.world[k][0] == 2.0 && o.world[k][3] == 1.0);
        } else {
            assert_true(o.world[k][0] == 2.0 && o.world[k][3] == 1.0 && o.world[k][7] == 0.0);
        }
        assert_int_equal(b->nodes[o.node[k]].kind, SW_SG_NODE_MESH);
    }
    assert_int_equal(seen_shifted, 1);
    assert_int_equal(seen_quad, 1);
    sw_sg_scene_stats stats;
    assert_int_equal(sw_sg_scene_compute_stats(file, &stats), SW_OK);
    assert_int_equal(stats.meshes, 2);
    assert_int_equal(stats.mesh_triangles, 6);
    assert_int_equal(stats.mesh_occurrences, 3);
    assert_int_equal(stats.triangle_occurrences, 10);
    assert_true(stats.bbox[5] == 5.5 && stats.bbox[4] == 9.0); /* quad's top; shifted tet's y */

    /* a flipped byte in MESHES is a checksum error naming it */
    unsigned char *bad = malloc(len);
    memcpy(bad, img, len);
    bad[rd64(img + table + 9 * ENTRY + 8) + 3] ^= 1;
    sw_sg_scene *s = NULL;
    char p[300];
    assert_int_equal(open_image(bad, len, &s, &st, p), SW_OK);
    assert_int_equal(sw_sg_scene_require(s, SW_SG_SEC_ALL, &st), SW_ERR_CHECKSUM);
    assert_non_null(strstr(st.message, "section MESHES at offset"));
    sw_sg_scene_free(s);
    /* a stored box that is not the positions' box, checksums made right: a format error */
    memcpy(bad, img, len);
    const uint64_t mo = rd64(img + table + 9 * ENTRY + 8);
    double big = 100.0;
    memcpy(bad + mo + 88 + 40 + 3 * 8, &big, 8); /* mesh 1, box max x */
    wr32(bad + table + 9 * ENTRY + 32, sw__crc32c(0, bad + mo, 176));
    uint32_t crc = sw__crc32c(0, bad, HDR_CRC);
    wr32(bad + HDR_CRC, sw__crc32c(crc, bad + table, 11 * ENTRY));
    assert_int_equal(open_image(bad, len, &s, &st, p), SW_OK);
    assert_int_equal(sw_sg_scene_require(s, SW_SG_SEC_ALL, &st), SW_ERR_FORMAT);
    char want[64];
    snprintf(want, sizeof want, "mesh 1 at offset %llu", (unsigned long long)(mo + 88));
    assert_non_null(strstr(st.message, want));
    sw_sg_scene_free(s);
    /* cut inside INDICES: truncated */
    assert_int_equal(open_image(img, len - 12, &s, &st, p), SW_ERR_TRUNCATED);
    free(bad);
    free(img);
    free(img2);
    sw_sg_scene_free(mem);
    sw_sg_scene_free(file);
}

/* A shape scene: a square outline (four lines) with a circular hole (one rational quadratic
 * of nine points) drawn twice (under two instances), and a label on screen (a triangle). */
static sw_sg_builder *shape_builder(void)
{
    sw_sg_builder *b = sw_sg_builder_create();
    static const double sq[4][2] = {{0, 0}, {2, 0}, {2, 1}, {0, 1}};
    static const double k1[4] = {0, 0, 1, 1};
    uint32_t first = SW_SG_NONE;
    sw_sg_loop_rec lr = {SW_SG_NONE, 4, SW_SG_LOOP_OUTER, 0};
    for (int i = 0; i < 4; i++) {
        const double cpw[6] = {sq[i][0], sq[i][1], 1, sq[(i + 1) % 4][0], sq[(i + 1) % 4][1], 1};
        sw_sg_curve_rec c = {1, 2, sw_sg_builder_push_doubles(b, k1, 4),
                             sw_sg_builder_push_doubles(b, cpw, 6)};
        uint32_t ci = sw_sg_builder_add_curve(b, &c);
        if (i == 0)
            lr.first_curve = ci;
    }
    first = sw_sg_builder_add_loop(b, &lr);
    static const double kc[12] = {0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4};
    double cpw[27];
    for (int i = 0; i < 9; i++) {
        const double a = M_PI / 4 * i, w = (i % 2) ? sqrt(0.5) : 1.0,
                     r = (i % 2) ? 0.25 * sqrt(2) : 0.25;
        cpw[3 * i] = w * (1 + r * cos(a)), cpw[3 * i + 1] = w * (0.5 + r * sin(a)),
                cpw[3 * i + 2] = w;
    }
    cpw[24] = cpw[0], cpw[25] = cpw[1];
    sw_sg_curve_rec cc = {2, 9, sw_sg_builder_push_doubles(b, kc, 12),
                          sw_sg_builder_push_doubles(b, cpw, 27)};
    sw_sg_loop_rec hole = {sw_sg_builder_add_curve(b, &cc), 1, 0, 0};
    sw_sg_builder_add_loop(b, &hole);
    sw_sg_shape_rec sh = {first, 2, 0, 0, {0}, 0.0};
    const uint32_t s0 = sw_sg_builder_add_shape(b, &sh);
    const uint32_t proto =
        sw_sg_builder_add_node(b, SW_SG_NODE_SHAPE, SW_SG_NONE, s0, NULL, NULL, NULL);
    const double t1[12] = {1, 0, 0, 5, 0, 1, 0, 0, 0, 0, 1, 0};
    sw_sg_builder_add_node(b, SW_SG_NODE_INSTANCE, 0, proto, NULL, NULL, NULL);
    sw_sg_builder_add_node(b, SW_SG_NODE_INSTANCE, 0, proto, t1, NULL, NULL);
    /* a label on screen: its own loop, 24 px per unit */
    static const double tri[3][2] = {{0, 0}, {1, 0}, {0.5, 1}};
    sw_sg_loop_rec tl = {SW_SG_NONE, 3, SW_SG_LOOP_OUTER, 0};
    for (int i = 0; i < 3; i++) {
        const double c3[6] = {tri[i][0], tri[i][1], 1, tri[(i + 1) % 3][0], tri[(i + 1) % 3][1], 1};
        sw_sg_curve_rec c = {1, 2, sw_sg_builder_push_doubles(b, k1, 4),
                             sw_sg_builder_push_doubles(b, c3, 6)};
        uint32_t ci = sw_sg_builder_add_curve(b, &c);
        if (i == 0)
            tl.first_curve = ci;
    }
    sw_sg_shape_rec label = {sw_sg_builder_add_loop(b, &tl), 1, SW_SG_SHAPE_SCREEN, 0, {0}, 24.0};
    sw_sg_builder_add_node(b, SW_SG_NODE_SHAPE, 0, sw_sg_builder_add_shape(b, &label), t1, NULL,
                           NULL);
    return b;
}

static int count_shape(void *ctx, uint32_t shape, uint32_t node, const double world[12],
                       const float color[4])
{
    (void)shape, (void)node, (void)world, (void)color;
    (*(int *)ctx)++;
    return 0;
}

/* SHAPES: round trip, layout (12 sections, 56-byte records), boxes, occurrences, stats; a stored
 * box that is not the curves' box, a label flag without its pixel size, an unknown flag: format
 * errors naming the shape. What it catches: the section not written or not read, a box trusted
 * without a check, the screen flag's size unchecked. */
static void test_shape_sections(void **state)
{
    (void)state;
    sw_sg_scene *mem = NULL, *file = NULL;
    sw_status st = {0};
    assert_int_equal(sw_sg_builder_finish(shape_builder(), &mem, &st), SW_OK);
    char path[300];
    snprintf(path, sizeof path, "%s/shapes.sws", g_dir);
    assert_int_equal(sw_sg_scene_save(mem, path, &st), SW_OK);
    assert_int_equal(sw_sg_scene_open(path, &file, &st), SW_OK);
    assert_int_equal(sw_sg_scene_require(file, SW_SG_SEC_ALL, &st), SW_OK);
    const sw_sg_scene_view *a = sw_sg_scene_view_ptr(mem), *b = sw_sg_scene_view_ptr(file);
    assert_views_identical(a, b);
    assert_int_equal(b->n_shapes, 2);
    assert_memory_equal(a->shapes, b->shapes, 2 * sizeof *a->shapes);
    const double box[4] = {0, 0, 2, 1}; /* the hole lies inside the square */
    assert_memory_equal(b->shapes[0].box, box, sizeof box);
    assert_true(b->shapes[1].flags == SW_SG_SHAPE_SCREEN && b->shapes[1].px_size == 24.0);
    size_t len = 0;
    unsigned char *img = read_all(path, &len);
    assert_non_null(img);
    assert_int_equal(rd32(img + 16), 12);
    const uint64_t table = rd64(img + HDR_TABLE);
    assert_int_equal(rd32(img + table + 11 * ENTRY), 11);
    assert_int_equal(rd64(img + table + 11 * ENTRY + 16), 2 * 56);
    int n_occ = 0;
    assert_int_equal(sw_sg_scene_traverse_shapes(file, count_shape, &n_occ), SW_OK);
    assert_int_equal(n_occ, 3);
    sw_sg_scene_stats stats;
    assert_int_equal(sw_sg_scene_compute_stats(file, &stats), SW_OK);
    assert_int_equal(stats.shapes, 2);
    assert_int_equal(stats.shape_occurrences, 3);
    /* the screen label counts its anchor only: the box reaches x = 7 (the second square), not
     * the label's 24-pixel units */
    assert_true(stats.bbox[3] == 7.0 && stats.bbox[0] == 0.0);
    const uint64_t so = rd64(img + table + 11 * ENTRY + 8);
    unsigned char *bad = malloc(len);
    struct {
        size_t at;
        uint32_t u32;
        double f64;
        int is_u32;
        const char *want;
    } cases[] = {
        {so + 16 + 2 * 8, 0, 3.0, 0, "stored box is not the box of its curves"},
        {so + 56 + 48, 0, 0.0, 0, "px per unit"}, /* the label without its size */
        {so + 8, 2, 0.0, 1, "flags 0x2"},         /* an unknown flag */
        {so + 56 + 48, 0, 1e9, 0, "px per unit"}, /* a size past the limit */
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        memcpy(bad, img, len);
        if (cases[k].is_u32)
            wr32(bad + cases[k].at, cases[k].u32);
        else
            memcpy(bad + cases[k].at, &cases[k].f64, 8);
        wr32(bad + table + 11 * ENTRY + 32, sw__crc32c(0, bad + so, 2 * 56));
        uint32_t crc = sw__crc32c(0, bad, HDR_CRC);
        wr32(bad + HDR_CRC, sw__crc32c(crc, bad + table, 12 * ENTRY));
        sw_sg_scene *s = NULL;
        char p[300];
        assert_int_equal(open_image(bad, len, &s, &st, p), SW_OK);
        assert_int_equal(sw_sg_scene_require(s, SW_SG_SEC_ALL, &st), SW_ERR_FORMAT);
        assert_non_null(strstr(st.message, "shape"));
        assert_non_null(strstr(st.message, cases[k].want));
        sw_sg_scene_free(s);
    }
    free(bad);
    free(img);
    sw_sg_scene_free(mem);
    sw_sg_scene_free(file);
}

static void test_mesh_builder_rejects(void **state)
{
    (void)state;
    static const double pts[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    static const uint32_t bad_tri[3] = {0, 1, 3};
    sw_status st = {0};
    sw_sg_scene *s = NULL;
    /* an index past the vertices */
    sw_sg_builder *b = sw_sg_builder_create();
    sw_sg_mesh_rec m;
    memset(&m, 0, sizeof m);
    m.n_vertices = 3, m.n_triangles = 1;
    m.positions = sw_sg_builder_push_doubles(b, pts, 9);
    m.normals = SW_SG_NO_NORMALS;
    m.indices = sw_sg_builder_push_indices(b, bad_tri, 3);
    sw_sg_builder_add_node(b, SW_SG_NODE_MESH, 0, sw_sg_builder_add_mesh(b, &m), NULL, NULL, NULL);
    assert_int_equal(sw_sg_builder_finish(b, &s, &st), SW_ERR_FORMAT);
    assert_non_null(strstr(st.message, "mesh 0: index 2 (triangle 0) is 3 of 3 vertices"));
    /* a mesh node naming a mesh that does not exist */
    b = sw_sg_builder_create();
    sw_sg_builder_add_node(b, SW_SG_NODE_MESH, 0, 0, NULL, NULL, NULL);
    assert_int_equal(sw_sg_builder_finish(b, &s, &st), SW_ERR_FORMAT);
    /* a non-finite position */
    b = sw_sg_builder_create();
    const double nan_pts[9] = {0, 0, 0, 1, NAN, 0, 0, 1, 0};
    static const uint32_t tri[3] = {0, 1, 2};
    m.positions = sw_sg_builder_push_doubles(b, nan_pts, 9);
    m.indices = sw_sg_builder_push_indices(b, tri, 3);
    sw_sg_builder_add_mesh(b, &m);
    assert_int_equal(sw_sg_builder_finish(b, &s, &st), SW_ERR_INVALID_GEOMETRY);
    assert_non_null(strstr(st.message, "mesh 0: vertex 1"));
    assert_null(s);
}

static int write_seed(const char *dir)
{
    char p[4096];
    snprintf(p, sizeof p, "%s/scene.sws", dir);
    mkdir(dir, 0755);
    sw_sg_scene *s = NULL;
    sw_status st = {0};
    if (sw_sg_builder_finish(sws_test_builder(), &s, &st) != SW_OK ||
        sw_sg_scene_save(s, p, &st) != SW_OK) {
        fprintf(stderr, "%s\n", st.message);
        return 1;
    }
    sw_sg_scene_free(s);
    /* and one with meshes: the fuzzer starts from the MESHES and INDICES sections too */
    snprintf(p, sizeof p, "%s/meshes.sws", dir);
    if (sw_sg_builder_finish(mesh_builder(), &s, &st) != SW_OK ||
        sw_sg_scene_save(s, p, &st) != SW_OK) {
        fprintf(stderr, "%s\n", st.message);
        return 1;
    }
    sw_sg_scene_free(s);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 3 && !strcmp(argv[1], "--write-seed"))
        return write_seed(argv[2]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_crc32c),
        cmocka_unit_test(test_roundtrip),
        cmocka_unit_test(test_resave_mapped),
        cmocka_unit_test(test_default_color_and_stop),
        cmocka_unit_test(test_stats),
        cmocka_unit_test(test_truncated),
        cmocka_unit_test(test_checksum_each_section),
        cmocka_unit_test(test_header),
        cmocka_unit_test(test_overflowing_table),
        cmocka_unit_test(test_bad_records),
        cmocka_unit_test(test_cycles),
        cmocka_unit_test(test_padding_flipped),
        cmocka_unit_test(test_missing_file),
        cmocka_unit_test(test_failed_saves),
        cmocka_unit_test(test_builder_rejects),
        cmocka_unit_test(test_mesh_sections),
        cmocka_unit_test(test_shape_sections),
        cmocka_unit_test(test_mesh_builder_rejects),
    };
    return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
