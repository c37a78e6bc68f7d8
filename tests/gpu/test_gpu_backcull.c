/* SPDX-License-Identifier: MIT */
/* Back-patch culling (Kumar et al. 1997 §4.4; lod/static/sw_lod_face_cones.h, desc.face_cones):
 *  - on closed models, frames with culling equal frames without it from views all around the
 *    model up to silhouette slivers of the back faces' tessellation (see `slivers`: culling must
 *    never remove anything visible), while some occurrences are culled (printed per view) — a test
 *    that is not vacuous;
 *  - the flag survives a .sws round trip (the reader's validation accepts bit 2);
 *  - on open sheets no face is flagged SW_SG_FACE_CLOSED_SHELL and nothing is culled;
 *  - a closed model drawn twice through instances, once mirrored (negative determinant): the same
 *    frames, and the mirrored instance alone has occurrences culled too (a wrong orientation rule
 *    for reflections — flipping the outward cone — would cull its visible side and differ).
 * Usage: test_gpu_backcull CLOSED_MODEL... --open OPEN_MODEL... --mirror MODEL
 */
#include "gpu_test_compare.h"
#include "sw_lod_cache.h"
#include "sw_lod_face_cones.h"
#include "sw_sg_bvh.h"
#include "sw_sg_import.h"
#include "sw_sg_pick.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "test_check.h"

enum { W = 320, H = 180, N_VIEWS = 8 };
static sw_th_pool *g_pool; /* the hierarchy cache's workers */

/* Views from the eight octant directions, at the distance of `splinewalk render`'s preset. */
static sw_gpu_camera view_camera(const double b[6], int v)
{
    sw_gpu_camera c = sw_test_view_camera(b, 1);
    double dist = 0.0, dir[3] = {v & 1 ? -1.0 : 1.0, v & 2 ? -1.0 : 1.0, v & 4 ? -0.6 : 0.8};
    const double n = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    for (int k = 0; k < 3; ++k)
        dist += (c.eye[k] - c.target[k]) * (c.eye[k] - c.target[k]);
    dist = sqrt(dist);
    for (int k = 0; k < 3; ++k)
        c.eye[k] = c.target[k] + dir[k] / n * dist;
    return c;
}

static uint32_t closed_faces(const sw_sg_scene *scene)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(scene);
    uint32_t n = 0;
    for (uint32_t i = 0; i < v->n_faces; ++i)
        n += (v->faces[i].flags & SW_SG_FACE_CLOSED_SHELL) != 0;
    return n;
}

/* What culling may change. Without it, the tessellated back faces are drawn too, each within
 * ε_img of its exact surface; where one meets a front face along a silhouette or crease its
 * triangles can win pixel centres the front face's own tessellation leaves (a sliver at most about
 * ε_img + 1 px wide), so exact equality is not a property of a correct cull. What is: no pixel
 * becomes covered (culling adds nothing); a pixel that loses coverage has a covered pixel within
 * two pixels in the culled frame (it was a sliver beyond a silhouette: linkrods.step has one two
 * pixels wide at a corner); and every changed pixel has an unchanged 8-neighbour — the changes are
 * lines at most two pixels wide, while a visible face culled by mistake leaves a hole as wide as
 * the face (wider than two pixels for every face of these views but the smallest). */
typedef struct slivers {
    long gained, lone_loss, thick;
} slivers;

static int pixel_differs(const sw_gpu_image *a, const sw_gpu_image *b, size_t i)
{
    return memcmp(a->rgba + 4 * i, b->rgba + 4 * i, 4) != 0;
}

/* Whether some pixel within `r` pixels (Chebyshev) of (x, y) is covered in img. */
static int covered_near(const sw_gpu_image *img, int32_t x, int32_t y, int32_t r)
{
    for (int32_t yy = y - r; yy <= y + r; ++yy)
        for (int32_t xx = x - r; xx <= x + r; ++xx)
            if (xx >= 0 && yy >= 0 && xx < img->width && yy < img->height &&
                img->rgba[4 * ((size_t)yy * (size_t)img->width + (size_t)xx) + 3] != 0)
                return 1;
    return 0;
}

static slivers classify(const sw_gpu_image *a, const sw_gpu_image *b)
{
    slivers s = {0, 0, 0};
    for (int32_t y = 0; y < a->height; ++y)
        for (int32_t x = 0; x < a->width; ++x) {
            const size_t i = (size_t)y * (size_t)a->width + (size_t)x;
            if (!pixel_differs(a, b, i))
                continue;
            const int ca = a->rgba[4 * i + 3] != 0, cb = b->rgba[4 * i + 3] != 0;
            s.gained += !ca && cb;
            int unchanged = 0;
            for (int32_t dy = -1; dy <= 1; ++dy)
                for (int32_t dx = -1; dx <= 1; ++dx) {
                    const int32_t xx = x + dx, yy = y + dy;
                    if ((dx == 0 && dy == 0) || xx < 0 || yy < 0 || xx >= a->width ||
                        yy >= a->height)
                        continue;
                    unchanged += !pixel_differs(a, b, (size_t)yy * (size_t)a->width + (size_t)xx);
                }
            s.thick += unchanged == 0;
            s.lone_loss += ca && !cb && !covered_near(b, x, y, 2);
        }
    return s;
}

/* Renders every view with and without culling; returns the occurrences culled over all views,
 * or UINT64_MAX on a render failure. Even views use the BVH, odd ones the full traversal; the
 * last two draw from the faces' hierarchies (Guthe §7) when `cache` is given. */
static uint64_t compare_views(sw_gpu_context *ctx, const sw_sg_scene *scene,
                              const sw_lod_face_cones *fc, const sw_sg_bvh *t, sw_lod_cache *cache)
{
    uint64_t culled = 0;
    for (int v = 0; v < N_VIEWS; ++v) {
        sw_gpu_frame_desc d;
        memset(&d, 0, sizeof d);
        d.width = W;
        d.height = H;
        d.camera = view_camera(t->box, v);
        d.bvh = v % 2 == 0 ? t : NULL;
        d.hierarchies = v >= N_VIEWS - 2 ? cache : NULL;
        sw_gpu_image a = {0}, b = {0};
        sw_gpu_frame_stats fa, fb;
        sw_status st = {0};
        int ok = sw_gpu_render_scene(ctx, scene, &d, &a, &fa, &st) == SW_OK;
        d.face_cones = fc;
        ok = ok && sw_gpu_render_scene(ctx, scene, &d, &b, &fb, &st) == SW_OK;
        CHECK(ok, "view %d: render: %s", v, st.message);
        if (!ok) {
            sw_gpu_image_free(&a);
            sw_gpu_image_free(&b);
            return UINT64_MAX;
        }
        sw_test_image_diff df = sw_test_compare_images(&a, &b, 0);
        const slivers sl = classify(&a, &b);
        CHECK(sl.gained == 0 && sl.thick == 0 && sl.lone_loss == 0,
              "view %d: %ld pixels differ with back-patch culling: %ld newly covered, %ld inside "
              "a 3x3 block of changes, %ld uncovered > 2 px from coverage",
              v, df.any, sl.gained, sl.thick, sl.lone_loss);
        CHECK(fa.faces_backculled == 0 && fb.faces_drawn + fb.faces_backculled >= fa.faces_drawn &&
                  fb.faces_drawn <= fa.faces_drawn,
              "view %d: faces drawn %llu without, %llu with (%llu back-culled)", v,
              (unsigned long long)fa.faces_drawn, (unsigned long long)fb.faces_drawn,
              (unsigned long long)fb.faces_backculled);
        printf("  view %d (%s): faces drawn %llu without, %llu with, back-culled %llu; "
               "triangles %llu -> %llu; tessellate %.1f -> %.1f ms; %ld px covered, %ld differ "
               "(silhouette slivers)\n",
               v,
               d.hierarchies ? (d.bvh ? "bvh, hierarchies" : "all, hierarchies")
                             : (d.bvh ? "bvh" : "all"),
               (unsigned long long)fa.faces_drawn, (unsigned long long)fb.faces_drawn,
               (unsigned long long)fb.faces_backculled, (unsigned long long)fa.triangles,
               (unsigned long long)fb.triangles, fa.ms_tessellate, fb.ms_tessellate, df.covered,
               df.any);
        culled += fb.faces_backculled;
        sw_gpu_image_free(&a);
        sw_gpu_image_free(&b);
    }
    return culled;
}

/* A view from inside the solid material: a ray from outside toward an occurrence's box enters the
 * model at its first hit; the eye stands 1e-4 of the diagonal beyond it, looking on along the ray,
 * where the solid's own faces are seen from behind. The frame must then do no back-patch culling
 * and leave no fat-border quad out (both assume an eye outside the solids): with the cones it must
 * equal the frame without them, pixel for pixel. Without the eye test the faces ahead, whose
 * outward cones face away from the eye, were culled. Returns 0 when the ray met nothing. */
static int inside_view(sw_gpu_context *ctx, const sw_sg_scene *scene, const sw_lod_face_cones *fc,
                       const sw_sg_bvh *t, const char *name)
{
    const double *b = t->box;
    double ib[6];
    sw_sg_bvh_item_box(t, t->n_items / 2, ib);
    double c[3], dir[3] = {-0.3, -0.2, -0.93}, diag = 0.0, o[3];
    for (int k = 0; k < 3; ++k) { /* toward an occurrence's box: instances may stand apart */
        c[k] = 0.5 * (ib[k] + ib[3 + k]);
        diag += (b[3 + k] - b[k]) * (b[3 + k] - b[k]);
    }
    diag = sqrt(diag);
    for (int k = 0; k < 3; ++k)
        o[k] = c[k] - 2.0 * diag * dir[k];
    sw_sg_pick_hit hit;
    sw_status st = {0};
    if (sw_sg_pick(scene, t, o, dir, 0.0, &hit, &st) != SW_OK || hit.face == SW_SG_NONE)
        return 0;
    const double n = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    sw_gpu_frame_desc d;
    memset(&d, 0, sizeof d);
    d.width = W;
    d.height = H;
    d.bvh = t;
    for (int k = 0; k < 3; ++k) {
        d.camera.eye[k] = hit.point[k] + 1e-4 * diag * dir[k] / n;
        d.camera.target[k] = d.camera.eye[k] + dir[k];
    }
    d.camera.up[0] = 1.0;
    d.camera.fovy_deg = 60.0;
    sw_gpu_image a = {0}, bi = {0};
    sw_gpu_frame_stats fa, fb;
    int ok = sw_gpu_render_scene(ctx, scene, &d, &a, &fa, &st) == SW_OK;
    d.face_cones = fc;
    ok = ok && sw_gpu_render_scene(ctx, scene, &d, &bi, &fb, &st) == SW_OK;
    CHECK(ok, "%s inside view: render: %s", name, st.message);
    if (ok) {
        sw_test_image_diff df = sw_test_compare_images(&a, &bi, 0);
        printf("  inside the material (face %u hit): %ld px covered, %ld differ with the cones; "
               "back-culled %llu, ribbon quads left out %llu\n",
               hit.face, df.covered, df.any, (unsigned long long)fb.faces_backculled,
               (unsigned long long)fb.border_quads_away);
        CHECK(df.any == 0 && fb.faces_backculled == 0 && fb.border_quads_away == 0,
              "%s inside view: culled as if seen from outside (%ld px differ)", name, df.any);
    }
    sw_gpu_image_free(&a);
    sw_gpu_image_free(&bi);
    return 1;
}

/* Cones, BVH and hierarchy cache of the scene, then every view; returns the culled total
 * (UINT64_MAX: failed). */
static uint64_t run_scene(sw_gpu_context *ctx, const sw_sg_scene *scene, const char *name)
{
    sw_status st = {0};
    sw_lod_face_cones *fc = NULL;
    sw_sg_bvh *t = NULL;
    sw_lod_cache *cache = NULL;
    uint64_t culled = UINT64_MAX;
    if (sw_lod_face_cones_build(scene, &fc, &st) != SW_OK ||
        sw_sg_bvh_build(scene, &t, &st) != SW_OK ||
        sw_lod_cache_create(scene, g_pool, NULL, &cache, &st) != SW_OK)
        CHECK(0, "%s: cones, BVH or hierarchy cache: %s", name, st.message);
    else if (t->n_nodes == 0)
        CHECK(0, "%s: no occurrences", name);
    else {
        printf("%s: %u faces, %u closed-shell, %u with a bounded cone; %u occurrences\n", name,
               fc->n_faces, closed_faces(scene), fc->n_bounded, t->n_items);
        culled = compare_views(ctx, scene, fc, t, cache);
        if (closed_faces(scene) > 0 && !inside_view(ctx, scene, fc, t, name))
            CHECK(0, "%s: the ray into the model met nothing", name);
    }
    sw_lod_cache_destroy(cache);
    sw_lod_face_cones_free(fc);
    sw_sg_bvh_free(t);
    return culled;
}

/* The flag survives a .sws round trip, and the reader's validation accepts it. */
static void check_sws(sw_sg_scene *scene, const char *name)
{
    char path[512];
    const char *dir = getenv("TMPDIR");
    snprintf(path, sizeof path, "%s/test_gpu_backcull_%ld.sws", dir ? dir : "/tmp", (long)getpid());
    sw_status st = {0};
    sw_sg_scene *back = NULL;
    int ok = sw_sg_scene_save(scene, path, &st) == SW_OK &&
             sw_sg_scene_open(path, &back, &st) == SW_OK &&
             sw_sg_scene_require(back, SW_SG_SEC_ALL, &st) == SW_OK;
    CHECK(ok && closed_faces(back) == closed_faces(scene), "%s: .sws round trip: %s", name,
          ok ? "closed-shell faces differ" : st.message);
    sw_sg_scene_free(back);
    remove(path);
}

static sw_sg_scene *load(const char *path)
{
    sw_sg_import_desc id = {path, NULL, NULL, NULL, NULL, 0};
    sw_sg_scene *scene = NULL;
    sw_status st = {0};
    if (sw_sg_import_file(&id, &scene, NULL, &st) != SW_OK)
        CHECK(0, "import %s: %s", path, st.message);
    return scene;
}

/* x of a plane just beyond the model's +x side (from its BVH box), for its mirror image. */
static int mirror_plane(const char *path, double *x)
{
    sw_sg_scene *scene = load(path);
    sw_sg_bvh *t = NULL;
    sw_status st = {0};
    int ok = scene && sw_sg_bvh_build(scene, &t, &st) == SW_OK && t->n_nodes > 0;
    if (ok)
        *x = t->box[3] + 0.1 * (t->box[3] - t->box[0]);
    sw_sg_bvh_free(t);
    sw_sg_scene_free(scene);
    return ok;
}

/* The model as a prototype drawn by two instances: as it is, and mirrored in a plane x = c beside
 * it (x -> 2c - x, determinant -1); or by the mirrored instance only. */
static sw_sg_scene *mirrored(const char *path, int both)
{
    double c = 0.0;
    if (!mirror_plane(path, &c))
        return NULL;
    sw_status st = {0};
    sw_sg_builder *b = sw_sg_builder_create();
    uint32_t proto =
        b ? sw_sg_builder_add_node(b, SW_SG_NODE_GROUP, SW_SG_NONE, 0, NULL, NULL, "prototype")
          : SW_SG_NONE;
    sw_sg_import_desc id = {path, NULL, NULL, NULL, NULL, 0};
    if (proto == SW_SG_NONE || sw_sg_import_into(b, proto, NULL, &id, NULL, &st) != SW_OK) {
        CHECK(0, "mirror %s: %s", path, st.message);
        sw_sg_builder_free(b);
        return NULL;
    }
    const double ident[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    const double mirror[12] = {-1, 0, 0, 2.0 * c, 0, 1, 0, 0, 0, 0, 1, 0};
    if ((both && sw_sg_builder_add_node(b, SW_SG_NODE_INSTANCE, 0, proto, ident, NULL, "as is") ==
                     SW_SG_NONE) ||
        sw_sg_builder_add_node(b, SW_SG_NODE_INSTANCE, 0, proto, mirror, NULL, "mirrored") ==
            SW_SG_NONE) {
        CHECK(0, "mirror %s: out of memory", path);
        sw_sg_builder_free(b);
        return NULL;
    }
    sw_sg_scene *scene = NULL;
    if (sw_sg_builder_finish(b, &scene, &st) != SW_OK)
        CHECK(0, "mirror %s: %s", path, st.message);
    return scene;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s CLOSED_MODEL... --open OPEN_MODEL... --mirror MODEL\n", argv[0]);
        return 2;
    }
    sw_status st = {0};
    sw_gpu_context *ctx = NULL;
    sw_th_pool_desc pd = {0};
    if (sw_th_pool_create(&pd, &g_pool) != SW_OK) {
        fprintf(stderr, "FAIL: worker pool\n");
        return 1;
    }
    if (sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        fprintf(stderr, "FAIL: %s\n", st.message);
        return 1;
    }
    int mode = 0; /* 0 closed, 1 open, 2 mirror */
    for (int a = 1; a < argc; ++a) {
        if (strcmp(argv[a], "--open") == 0 || strcmp(argv[a], "--mirror") == 0) {
            mode = argv[a][2] == 'o' ? 1 : 2;
            continue;
        }
        if (mode == 2) {
            for (int both = 1; both >= 0; --both) {
                sw_sg_scene *scene = mirrored(argv[a], both);
                char name[512];
                snprintf(name, sizeof name, "%s %s", argv[a],
                         both ? "and its mirror image" : "mirrored only");
                uint64_t c = scene ? run_scene(ctx, scene, name) : UINT64_MAX;
                CHECK(c != UINT64_MAX && c > 0, "%s: nothing back-culled", name);
                sw_sg_scene_free(scene);
            }
            continue;
        }
        sw_sg_scene *scene = load(argv[a]);
        if (!scene)
            continue;
        const uint32_t n_closed = closed_faces(scene);
        check_sws(scene, argv[a]);
        uint64_t c = run_scene(ctx, scene, argv[a]);
        if (mode == 0)
            CHECK(c != UINT64_MAX && c > 0, "%s: closed model, nothing back-culled", argv[a]);
        else
            CHECK(n_closed == 0 && c == 0, "%s: open model, %u closed-shell faces, %llu culled",
                  argv[a], n_closed, (unsigned long long)c);
        sw_sg_scene_free(scene);
    }
    sw_gpu_context_free(ctx);
    sw_th_pool_destroy(g_pool);
    puts(g_failures ? "FAIL" : "PASS");
    return g_failures ? 1 : 0;
}
