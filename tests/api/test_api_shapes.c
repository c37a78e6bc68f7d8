/* SPDX-License-Identifier: MIT */
/* tests/api: planar outline nodes (sw_nodes.h SHAPE), drawn in the frame, against the shared
 * library.
 *
 * usage: test_api_shapes WORKDIR   (EGL)
 *
 * The scene: a grey floor (a mesh, z = 0, [-10, 10]^2), a green wall (a mesh in the plane x = -2,
 * z in [0, 5]), a red outline laid on the floor (a rectangle [-4, 4] x [-3, 3] with a round hole of
 * radius 1.5 at (1, 0): lines and a rational-quadratic circle, even-odd) and a blue triangle
 * standing upright in the plane y = 5 (a rotated and translated SHAPE node).
 *
 * Each frame is checked against the exact geometry ray-traced here through every pixel whose 3 x 3
 * samples 1.5 px apart all agree (an anti-aliased edge cannot reach such a pixel): the nearest of
 * floor, wall and triangle (a point nearer than the frame's near plane is not seen), the floor
 * showing red where the outline lies (it is laid on it: the decal rule), the triangle blue inside
 * its outline and transparent outside; 0 wrong pixels allowed, and each case must occur: red on
 * the floor, red hidden by the wall, blue. Views: from above and aside (the wall hides the
 * outline's left part); low over the floor with the eye above the outline and a near plane of 0.9
 * (it cuts floor and outline on screen); looking away (both culled: stats).
 * Also: sw_node_set_shape replaces the outline (the check again, with the new one); a walkthrough
 * frame equals the converged one; saved and reloaded, the scene draws the same image (0 pixels
 * differ) from a file of 12 sections; bad outlines (an open loop, a loop without area, no loops, a
 * SHAPE edit of a MESH node) are refused with the loop named and change nothing.
 *
 * Labels (the text module, sw_text.h): refused with SW_ERR_UNSUPPORTED before sw_text_install;
 * then a label on screen ("Room 101", 24 px, billboarded) and one fixed in the world ("Hall", 2
 * units on the floor, at the cameras' target) drawn from two distances, the second twice the first:
 * the screen label's height in pixels stays the same (within 1 px), the world label's halves (ratio
 * 0.4-0.6); a label whose anchor is behind the camera is culled; saved and reloaded, the same
 * image; bad labels (not UTF-8, empty, spaces only, size 0, a missing font file) refused, the byte
 * or file named.
 *
 * What it catches (each planted once and seen failing): outlines not drawn (every view);
 * composited without the depth test (over the wall: aside, low); without the decal pull (hidden
 * by its own floor: low); the plane's axes swapped (every view); not cut at the near plane (low:
 * 11,778 pixels wrong); a save that drops the SHAPES section (11 sections, and the reloaded scene
 * refused: its SHAPE node names no shape).
 */
#include <splinewalk/sw_nodes.h>
#include <splinewalk/sw_text.h>

#include "test_check.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api_test_image.h"

#define W 320
#define H 240

static const char *g_work;

enum { BG, GREY, GREEN, RED, BLUE, OTHER };

/* ---- the scene ---------------------------------------------------------------------------- */

static const uint32_t k_quad_tris[6] = {0, 1, 2, 0, 2, 3};

static sw_mesh_desc quad(double pts[12])
{
    return (sw_mesh_desc){4, pts, NULL, 2, k_quad_tris};
}

/* An outline: up to 6 loops of up to 4 curves each, points and knots stored here. */
typedef struct outline {
    sw_trim_curve curves[6][4];
    sw_trim_loop loops[6];
    double pts[6][4][18], wts[6][4][9], knots[6][4][12];
    uint32_t n_loops;
} outline;

static void add_polygon(outline *o, const double (*p)[2], int n)
{
    uint32_t L = o->n_loops++;
    for (int i = 0; i < n; i++) {
        double *q = o->pts[L][i], *k = o->knots[L][i];
        q[0] = p[i][0], q[1] = p[i][1], q[2] = p[(i + 1) % n][0], q[3] = p[(i + 1) % n][1];
        k[0] = k[1] = 0, k[2] = k[3] = 1;
        o->curves[L][i] = (sw_trim_curve){1, 2, k, q, NULL};
    }
    o->loops[L] = (sw_trim_loop){o->curves[L], (uint32_t)n};
}

/* A circle of nine rational quadratic points. */
static void add_circle(outline *o, double cx, double cy, double r)
{
    uint32_t L = o->n_loops++;
    double *q = o->pts[L][0], *w = o->wts[L][0], *k = o->knots[L][0];
    const double kn[12] = {0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4};
    memcpy(k, kn, sizeof kn);
    for (int i = 0; i < 9; i++) {
        const double a = M_PI / 4 * i, rr = (i % 2) ? r * sqrt(2) : r;
        q[2 * i] = cx + rr * cos(a), q[2 * i + 1] = cy + rr * sin(a);
        w[i] = (i % 2) ? sqrt(0.5) : 1.0;
    }
    q[16] = q[0], q[17] = q[1];
    o->curves[L][0] = (sw_trim_curve){2, 9, k, q, w};
    o->loops[L] = (sw_trim_loop){o->curves[L], 1};
}

/* The red outline: rectangle [-hx, hx] x [-hy, hy], hole of radius hr at (1, 0) (hr 0: none). */
static void red_outline(outline *o, double hx, double hy, double hr)
{
    memset(o, 0, sizeof *o);
    const double r[4][2] = {{-hx, -hy}, {hx, -hy}, {hx, hy}, {-hx, hy}};
    add_polygon(o, r, 4);
    if (hr > 0)
        add_circle(o, 1, 0, hr);
}

/* The blue triangle, in its node's plane: (-1.5, 0), (1.5, 0), (0, 2.5). */
static const double k_tri[3][2] = {{-1.5, 0}, {1.5, 0}, {0, 2.5}};
/* Its node's transform: plane x -> world x, plane y -> world z, origin (3, 5, 0.5). */
static const double k_sign_xf[12] = {1, 0, 0, 3, 0, 0, -1, 5, 0, 1, 0, 0.5};

typedef struct built {
    sw_scene scene;
    sw_node floor, wall, red, sign;
    double red_hx, red_hy, red_hr; /* the red outline as drawn */
} built;

static double g_floor[12] = {-10, -10, 0, 10, -10, 0, 10, 10, 0, -10, 10, 0};
static double g_wall[12] = {-2, -10, 0, -2, 10, 0, -2, 10, 5, -2, -10, 5};

static int build(built *b)
{
    memset(b, 0, sizeof *b);
    sw_status st = {0};
    CHECK(sw_scene_create(NULL, &b->scene, &st) == SW_OK, "scene: %s", st.message);
    sw_node_desc d = {0};
    sw_mesh_desc fm = quad(g_floor), wm = quad(g_wall);
    d.kind = SW_NODE_MESH;
    d.mesh = &fm;
    d.color[0] = d.color[1] = d.color[2] = 0.5f, d.color[3] = 1;
    CHECK(sw_node_add(b->scene, &d, &b->floor, &st) == SW_OK, "floor: %s", st.message);
    d.mesh = &wm;
    d.color[0] = 0.1f, d.color[1] = 0.8f, d.color[2] = 0.1f;
    CHECK(sw_node_add(b->scene, &d, &b->wall, &st) == SW_OK, "wall: %s", st.message);
    outline red, tri;
    red_outline(&red, 4, 3, 1.5);
    b->red_hx = 4, b->red_hy = 3, b->red_hr = 1.5;
    memset(&tri, 0, sizeof tri);
    add_polygon(&tri, k_tri, 3);
    sw_shape_desc rs = {red.loops, red.n_loops}, ts = {tri.loops, tri.n_loops};
    memset(&d, 0, sizeof d);
    d.kind = SW_NODE_SHAPE;
    d.shape = &rs;
    d.color[0] = 1, d.color[3] = 1;
    CHECK(sw_node_add(b->scene, &d, &b->red, &st) == SW_OK, "red outline: %s", st.message);
    d.shape = &ts;
    d.color[0] = 0, d.color[2] = 1;
    memcpy(d.transform, k_sign_xf, sizeof d.transform);
    CHECK(sw_node_add(b->scene, &d, &b->sign, &st) == SW_OK, "triangle: %s", st.message);
    return g_failures == 0;
}

/* ---- the exact scene, ray-traced ---------------------------------------------------------- */

typedef struct tracer {
    double eye[3], fwd[3], right[3], up[3], focal, near_plane;
    const built *b;
} tracer;

static void normalize(double v[3])
{
    const double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; k++)
        v[k] /= l;
}

static void tracer_init(tracer *t, const sw_camera *c, double near_plane, const built *b)
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
    t->near_plane = near_plane;
    t->b = b;
}

static int in_red(const built *b, double x, double y)
{
    const int rect = fabs(x) <= b->red_hx && fabs(y) <= b->red_hy;
    const int hole = b->red_hr > 0 && hypot(x - 1, y) <= b->red_hr;
    return rect != hole;
}

static int in_triangle(double x, double y)
{
    int in = 1;
    for (int i = 0; i < 3; i++) {
        const double *a = k_tri[i], *e = k_tri[(i + 1) % 3];
        in &= (e[0] - a[0]) * (y - a[1]) - (e[1] - a[1]) * (x - a[0]) >= 0;
    }
    return in;
}

/* Ray parameter (the direction has unit view-axis component) to the plane n . x = c; INFINITY:
 * none, or nearer than the near plane. */
static double hit_plane(const tracer *t, const double d[3], int axis, double c)
{
    if (d[axis] == 0)
        return INFINITY;
    const double s = (c - t->eye[axis]) / d[axis];
    return s >= t->near_plane ? s : INFINITY;
}

/* What the exact scene shows at image point (x, y) (pixels from the top left). */
static int trace(const tracer *t, double x, double y)
{
    double d[3];
    for (int k = 0; k < 3; k++)
        d[k] = t->fwd[k] + (x - W / 2.0) / t->focal * t->right[k] +
               (H / 2.0 - y) / t->focal * t->up[k];
    int what = BG;
    double best = INFINITY, p[3];
    const double sf = hit_plane(t, d, 2, 0.0);
    for (int k = 0; k < 3; k++)
        p[k] = t->eye[k] + sf * d[k];
    if (sf < best && fabs(p[0]) <= 10 && fabs(p[1]) <= 10)
        best = sf, what = in_red(t->b, p[0], p[1]) ? RED : GREY;
    const double sw = hit_plane(t, d, 0, -2.0);
    for (int k = 0; k < 3; k++)
        p[k] = t->eye[k] + sw * d[k];
    if (sw < best && fabs(p[1]) <= 10 && p[2] >= 0 && p[2] <= 5)
        best = sw, what = GREEN;
    const double ss = hit_plane(t, d, 1, 5.0); /* the triangle: plane (x - 3, z - 0.5) */
    for (int k = 0; k < 3; k++)
        p[k] = t->eye[k] + ss * d[k];
    if (ss < best && in_triangle(p[0] - 3, p[2] - 0.5))
        best = ss, what = BLUE;
    return what;
}

static int classify(const unsigned char *p)
{
    const int r = p[0], g = p[1], b = p[2];
    if (r >= 250 && g >= 250 && b >= 250)
        return BG;
    if (r > 200 && g < 40 && b < 40)
        return RED;
    if (b > 200 && r < 40 && g < 40)
        return BLUE;
    if (g > r + 40 && g > b + 40)
        return GREEN;
    if (abs(r - g) < 12 && abs(g - b) < 12)
        return GREY;
    return OTHER;
}

typedef struct tally {
    long certain, wrong, red, blue, red_hidden, red_cut;
} tally;

/* Whether the ray through (x, y) meets the red outline on the floor nearer than the near plane
 * (there the near plane cuts it). */
static int red_before_near(const tracer *t, double x, double y)
{
    double d[3];
    for (int k = 0; k < 3; k++)
        d[k] = t->fwd[k] + (x - W / 2.0) / t->focal * t->right[k] +
               (H / 2.0 - y) / t->focal * t->up[k];
    if (d[2] == 0)
        return 0;
    const double s = -t->eye[2] / d[2];
    return s > 0 && s < t->near_plane && in_red(t->b, t->eye[0] + s * d[0], t->eye[1] + s * d[1]);
}

static tally compare(const tracer *t, const char *png)
{
    tally c = {0};
    int w = 0, h = 0;
    unsigned char *img = sw_test_read_rgba(png, &w, &h);
    CHECK(img && w == W && h == H, "read %s", png);
    if (!img || w != W || h != H) {
        free(img);
        c.wrong = -1;
        return c;
    }
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int first = -1, same = 1;
            for (int s = 0; s < 9 && same; s++) {
                const int k = trace(t, x + 0.5 + 1.5 * (s % 3 - 1), y + 0.5 + 1.5 * (s / 3 - 1));
                same = first < 0 || k == first;
                first = k;
            }
            if (!same)
                continue;
            c.certain++;
            const unsigned char *p = img + 4 * ((size_t)y * W + x);
            const int got = classify(p);
            if (got != first && c.wrong < 5)
                printf("  %s: pixel (%d, %d) is (%d, %d, %d): class %d, the exact scene says %d\n",
                       png, x, y, p[0], p[1], p[2], got, first);
            c.wrong += got != first;
            c.red += first == RED;
            c.blue += first == BLUE;
            c.red_cut += first == RED && red_before_near(t, x + 0.5, y + 3.5);
        }
    /* red outline points hidden by the wall: where the floor ray meets the outline behind it */
    for (int y = 0; y < H; y += 2)
        for (int x = 0; x < W; x += 2) {
            double d[3];
            for (int k = 0; k < 3; k++)
                d[k] = t->fwd[k] + (x - W / 2.0) / t->focal * t->right[k] +
                       (H / 2.0 - y) / t->focal * t->up[k];
            const double sf = hit_plane(t, d, 2, 0.0);
            if (!isfinite(sf))
                continue;
            const double px = t->eye[0] + sf * d[0], py = t->eye[1] + sf * d[1];
            c.red_hidden += in_red(t->b, px, py) && trace(t, x, y) == GREEN;
        }
    free(img);
    return c;
}

/* ---- frames ------------------------------------------------------------------------------- */

static double g_near; /* the frames' near plane; 0: the renderer's own */

static int draw(sw_renderer r, sw_scene s, const sw_camera *cam, int walkthrough, const char *name,
                char *path, sw_frame_stats *fs)
{
    snprintf(path, 1024, "%s/%s.png", g_work, name);
    sw_frame_desc f = {.scene = s, .camera = *cam, .width = W, .height = H, .output_path = path};
    f.walkthrough = walkthrough;
    f.near_plane = g_near;
    sw_status st = {0};
    memset(fs, 0, sizeof *fs);
    sw_result res = sw_renderer_draw(r, &f, fs, &st);
    CHECK(res == SW_OK, "draw %s: %s", name, st.message);
    return res == SW_OK;
}

/* Draws and compares; returns the tally. */
static tally check_view(sw_renderer r, const built *b, const sw_camera *cam, const char *name,
                        sw_frame_stats *fs)
{
    char path[1024];
    tally c = {0};
    if (!draw(r, b->scene, cam, 0, name, path, fs))
        return c;
    tracer t;
    tracer_init(&t, cam, fs->near_plane, b);
    c = compare(&t, path);
    printf("%s: %ld certain pixels, %ld wrong; red %ld (%ld at the near plane's cut), blue %ld, "
           "red hidden by the wall %ld; "
           "outlines drawn %llu, culled %llu, skipped %llu, near plane %g\n",
           name, c.certain, c.wrong, c.red, c.red_cut, c.blue, c.red_hidden,
           (unsigned long long)fs->shapes_drawn, (unsigned long long)fs->shapes_culled,
           (unsigned long long)fs->shapes_skipped, fs->near_plane);
    CHECK(c.wrong == 0, "%s: %ld pixels differ from the exact scene", name, c.wrong);
    return c;
}

static const sw_camera k_aside = {{9, -8, 8}, {0, 0, 0}, {0, 0, 1}, 45};
/* low over the floor, the eye above the outline's edge: the near plane cuts it on screen */
static const sw_camera k_low = {{0.5, -1.5, 0.6}, {0.5, 4, -0.6}, {0, 0, 1}, 100};
static const sw_camera k_away = {{0, 0, 8}, {0, 0, 20}, {0, 1, 0}, 45};

static void test_frames(sw_renderer r, built *b)
{
    sw_frame_stats fs;
    tally c = check_view(r, b, &k_aside, "aside", &fs);
    CHECK(c.red > 1000 && c.blue > 100 && c.red_hidden > 100,
          "aside: each case occurs (red %ld, blue %ld, hidden %ld)", c.red, c.blue, c.red_hidden);
    CHECK(fs.shapes_drawn == 2 && fs.shapes_skipped == 0, "aside: %llu outlines drawn",
          (unsigned long long)fs.shapes_drawn);
    char conv[1024], walk[1024];
    snprintf(conv, sizeof conv, "%s/aside.png", g_work);
    draw(r, b->scene, &k_aside, 1, "aside_walk", walk, &fs);
    CHECK(sw_test_differing_percent(conv, walk) == 0.0, "walkthrough frame differs from converged");

    g_near = 0.9; /* a near plane the floor crosses on screen, through the outline */
    c = check_view(r, b, &k_low, "low", &fs);
    g_near = 0.0;
    CHECK(c.red > 1000 && c.red_cut > 30,
          "low: the outline shows, cut by the near plane (red %ld, "
          "%ld at the cut)",
          c.red, c.red_cut);

    char path[1024];
    draw(r, b->scene, &k_away, 0, "away", path, &fs);
    CHECK(fs.shapes_drawn == 0 && fs.shapes_culled == 2, "away: %llu drawn, %llu culled",
          (unsigned long long)fs.shapes_drawn, (unsigned long long)fs.shapes_culled);
}

static void test_set_shape(sw_renderer r, built *b)
{
    outline o;
    red_outline(&o, 2, 1, 0);
    sw_shape_desc d = {o.loops, o.n_loops};
    sw_status st = {0};
    CHECK(sw_node_set_shape(b->scene, b->red, &d, &st) == SW_OK, "set_shape: %s", st.message);
    b->red_hx = 2, b->red_hy = 1, b->red_hr = 0;
    sw_frame_stats fs;
    tally c = check_view(r, b, &k_aside, "set_shape", &fs);
    CHECK(c.red > 100, "set_shape: the new outline shows (red %ld)", c.red);
}

static uint64_t revision(sw_scene s)
{
    sw_scene_revisions rv = {0};
    sw_status st = {0};
    sw_scene_get_revisions(s, &rv, &st);
    return rv.latest;
}

static void expect_bad(built *b, const sw_shape_desc *d, sw_result want, const char *needle,
                       const char *what)
{
    const uint64_t before = revision(b->scene);
    sw_status st = {0};
    sw_node n = {0};
    sw_node_desc nd = {0};
    nd.kind = SW_NODE_SHAPE;
    nd.shape = d;
    sw_result got = sw_node_add(b->scene, &nd, &n, &st);
    CHECK(got == want && n.id == 0, "%s: add gave %s (%s)", what, sw_result_id_str(got),
          st.message);
    CHECK(!needle || strstr(st.message, needle), "%s: message \"%s\" lacks \"%s\"", what,
          st.message, needle);
    got = sw_node_set_shape(b->scene, b->red, d, &st);
    CHECK(got == want, "%s: set_shape gave %s", what, sw_result_id_str(got));
    CHECK(revision(b->scene) == before, "%s: the scene changed", what);
}

static void test_bad(built *b)
{
    outline o;
    red_outline(&o, 2, 1, 0);
    o.pts[0][1][3] += 0.01; /* the second side ends 0.01 off the third side's start */
    sw_shape_desc open = {o.loops, o.n_loops};
    expect_bad(b, &open, SW_ERR_INVALID_GEOMETRY, "loop 0", "open loop");
    outline f;
    memset(&f, 0, sizeof f);
    const double flat[3][2] = {{0, 0}, {1, 0}, {2, 0}};
    add_polygon(&f, flat, 3);
    sw_shape_desc noarea = {f.loops, f.n_loops};
    expect_bad(b, &noarea, SW_ERR_INVALID_GEOMETRY, "no area", "loop without area");
    sw_shape_desc none = {NULL, 0};
    expect_bad(b, &none, SW_ERR_INVALID_ARGUMENT, "no loops", "no loops");
    red_outline(&o, 2, 1, 0);
    sw_shape_desc ok = {o.loops, o.n_loops};
    sw_status st = {0};
    CHECK(sw_node_set_shape(b->scene, b->floor, &ok, &st) == SW_ERR_INVALID_ARGUMENT,
          "set_shape on a MESH node");
}

static void test_save_reload(sw_renderer r, built *b)
{
    char sws[1024], a[1024], c[1024];
    snprintf(sws, sizeof sws, "%s/shapes.sws", g_work);
    sw_status st = {0};
    CHECK(sw_scene_save(b->scene, sws, &st) == SW_OK, "save: %s", st.message);
    FILE *f = fopen(sws, "rb");
    unsigned char head[20] = {0};
    CHECK(f && fread(head, 1, sizeof head, f) == sizeof head, "read %s", sws);
    if (f)
        fclose(f);
    const uint32_t sections = head[16] | head[17] << 8 | head[18] << 16 | (uint32_t)head[19] << 24;
    CHECK(sections == 12, "%s has %u sections, 12 expected (SHAPES)", sws, sections);
    sw_scene loaded = {0};
    sw_scene_load_desc ld = {.path = sws};
    CHECK(sw_scene_load(&ld, &loaded, &st) == SW_OK, "load: %s", st.message);
    sw_frame_stats fs;
    draw(r, b->scene, &k_aside, 0, "before_save", a, &fs);
    draw(r, loaded, &k_aside, 0, "reloaded", c, &fs);
    CHECK(fs.shapes_drawn == 2, "reloaded: %llu outlines drawn",
          (unsigned long long)fs.shapes_drawn);
    CHECK(sw_test_differing_percent(a, c) == 0.0, "the reloaded scene draws another image");
    sw_scene_destroy(loaded);
}

/* The rows (image, top first) holding pixels of one colour class; 0 when none. */
static int class_height(const char *png, int want)
{
    int w = 0, h = 0, top = -1, bottom = -1;
    unsigned char *img = sw_test_read_rgba(png, &w, &h);
    for (int y = 0; img && y < h; y++)
        for (int x = 0; x < w; x++)
            if (classify(img + 4 * ((size_t)y * w + x)) == want) {
                top = top < 0 ? y : top;
                bottom = y;
            }
    free(img);
    return top < 0 ? 0 : bottom - top + 1;
}

static sw_result add_label(sw_scene s, const char *text, const char *font, double size, int screen,
                           const double at[3], float r, float g, float b, sw_node *n, sw_status *st)
{
    sw_label_desc l = {text, font, size, screen, 1};
    sw_node_desc d = {0};
    d.kind = SW_NODE_LABEL;
    d.label = &l;
    d.color[0] = r, d.color[1] = g, d.color[2] = b, d.color[3] = 1;
    const double xf[12] = {1, 0, 0, at[0], 0, 1, 0, at[1], 0, 0, 1, at[2]};
    memcpy(d.transform, xf, sizeof xf);
    return sw_node_add(s, &d, n, st);
}

static void expect_bad_label(sw_scene s, const char *text, const char *font, double size,
                             sw_result want, const char *needle)
{
    sw_status st = {0};
    sw_node n = {0};
    const double at[3] = {0, 0, 0};
    sw_result got = add_label(s, text, font, size, 1, at, 1, 0, 0, &n, &st);
    CHECK(got == want && n.id == 0, "bad label (%s): %s, expected %s", needle,
          sw_result_id_str(got), sw_result_id_str(want));
    CHECK(strstr(st.message, needle), "bad label: message \"%s\" lacks \"%s\"", st.message, needle);
}

static void test_labels(sw_renderer r)
{
    sw_scene s;
    sw_status st = {0};
    CHECK(sw_scene_create(NULL, &s, &st) == SW_OK, "scene: %s", st.message);
    sw_node floor, room, hall, behind;
    sw_node_desc d = {0};
    sw_mesh_desc fm = quad(g_floor);
    d.kind = SW_NODE_MESH;
    d.mesh = &fm;
    d.color[0] = d.color[1] = d.color[2] = 0.5f, d.color[3] = 1;
    CHECK(sw_node_add(s, &d, &floor, &st) == SW_OK, "floor: %s", st.message);
    const double above[3] = {-3, 1, 1}, on[3] = {0, 1, 0}, back[3] = {0, -40, 3};
    CHECK(add_label(s, "Room 101", NULL, 24, 1, above, 1, 0, 0, &room, &st) == SW_ERR_UNSUPPORTED,
          "a label without the text module: %s", st.message);
    CHECK(strstr(st.message, "sw_text_install") != NULL, "no module: '%s'", st.message);
    CHECK(sw_text_install() == SW_OK, "sw_text_install");
    CHECK(add_label(s, "Room 101", NULL, 24, 1, above, 1, 0, 0, &room, &st) == SW_OK,
          "screen label: %s", st.message);
    CHECK(add_label(s, "Hall", NULL, 2.0, 0, on, 0, 0, 1, &hall, &st) == SW_OK, "world label: %s",
          st.message);
    CHECK(add_label(s, "behind", NULL, 24, 1, back, 1, 0, 0, &behind, &st) == SW_OK,
          "label behind: %s", st.message);
    const sw_camera near_cam = {{0, -8, 6}, {0, 1, 0.5}, {0, 0, 1}, 45};
    sw_camera far_cam = near_cam;
    for (int k = 0; k < 3; k++) /* twice as far from the labels, looking the same way */
        far_cam.eye[k] = near_cam.target[k] + 2 * (near_cam.eye[k] - near_cam.target[k]);
    char a[1024], b[1024];
    sw_frame_stats fs;
    draw(r, s, &near_cam, 0, "labels_near", a, &fs);
    CHECK(fs.shapes_drawn == 2 && fs.shapes_culled == 1,
          "labels near: %llu drawn, %llu culled (2 and the one behind the camera)",
          (unsigned long long)fs.shapes_drawn, (unsigned long long)fs.shapes_culled);
    draw(r, s, &far_cam, 0, "labels_far", b, &fs);
    const int red_a = class_height(a, RED), red_b = class_height(b, RED);
    const int blue_a = class_height(a, BLUE), blue_b = class_height(b, BLUE);
    printf("labels: screen label %d -> %d px tall, world label %d -> %d px at twice the "
           "distance\n",
           red_a, red_b, blue_a, blue_b);
    CHECK(red_a > 12 && abs(red_a - red_b) <= 1, "screen label: %d px near, %d px far", red_a,
          red_b);
    CHECK(blue_a > 10 && blue_b >= 0.4 * blue_a && blue_b <= 0.6 * blue_a,
          "world label: %d px near, %d px far", blue_a, blue_b);
    char sws[1024], c[1024];
    snprintf(sws, sizeof sws, "%s/labels.sws", g_work);
    CHECK(sw_scene_save(s, sws, &st) == SW_OK, "save labels: %s", st.message);
    sw_scene loaded = {0};
    sw_scene_load_desc ld = {.path = sws};
    CHECK(sw_scene_load(&ld, &loaded, &st) == SW_OK, "load labels: %s", st.message);
    draw(r, loaded, &near_cam, 0, "labels_reloaded", c, &fs);
    CHECK(sw_test_differing_percent(a, c) == 0.0, "reloaded labels draw another image");
    sw_scene_destroy(loaded);
    expect_bad_label(s, "\xff", NULL, 24, SW_ERR_INVALID_ARGUMENT, "byte 0");
    expect_bad_label(s, "", NULL, 24, SW_ERR_INVALID_ARGUMENT, "empty");
    expect_bad_label(s, "   ", NULL, 24, SW_ERR_INVALID_ARGUMENT, "no glyph");
    expect_bad_label(s, "x", NULL, 0, SW_ERR_INVALID_ARGUMENT, "size");
    expect_bad_label(s, "x", "/no/such/font.ttf", 24, SW_ERR_NOT_FOUND, "/no/such/font.ttf");
    sw_scene_destroy(s);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_api_shapes WORKDIR\n");
        return 2;
    }
    g_work = argv[1];
    built b;
    sw_renderer r;
    sw_status st = {0};
    if (!build(&b) || sw_renderer_create(NULL, &r, &st) != SW_OK) {
        printf("set-up failed: %s\n", st.message);
        return 1;
    }
    test_frames(r, &b);
    test_save_reload(r, &b);
    test_bad(&b);
    test_set_shape(r, &b);
    test_labels(r);
    sw_renderer_destroy(r);
    sw_scene_destroy(b.scene);
    printf("shapes: %d failure(s)\n", g_failures);
    return g_failures != 0;
}
