/* SPDX-License-Identifier: MIT */
/* Static levels drawn from the GPU copies a context keeps between frames (gpu/resident.c) against
 * the same levels sent with every frame's mesh (the context's residency off), on MODEL's static
 * LODs built converged, over views at three distances:
 *  - The same image: at most 0.1 % of the pixels differ (the two placements round differently:
 *    positions around the unit's centre then placed in float, or placed in double then rounded),
 *    the same triangle and static counts, and every static triangle drawn resident (catches: a
 *    copy placed without its centre, planted: 70 % of the pixels differ; a level drawn twice or
 *    not at all; the triangle count losing the resident ones).
 *  - Sent once: the second frame of a view uploads exactly the levels' bytes less than the first
 *    (the copies made then: what the context holds), and less than the frame without residency
 *    by at least the static triangles' indices (catches: copies made again every frame, planted:
 *    the difference is 0; uploads miscounted).
 *  - Kept within its budget: with a budget of 0, the copies only the last frame drew stay (a far
 *    view, then a near one twice: fewer bytes after the second near one, none lost that it
 *    draws: the images still agree); with the default budget nothing is dropped; a frame of
 *    another static set (here none) drops them all (catches: a table that never evicts, planted;
 *    copies of a freed set's levels found by a new set's units).
 * Patch grids kept on the GPU (test_gpu_resident_grids) are off here: their uploads are not the
 * static levels'.
 * Usage: test_gpu_resident MODEL */
#include <splinewalk/sw_lod_build.h>
#include "frame_stages.h"
#include "gpu_test_compare.h"
#include "sw_lod_cache.h"
#include "sw_lod_static_set.h"
#include "sw_sg_bvh.h"
#include "sw_sg_import.h"

#include <stdio.h>
#include <string.h>

#include "test_check.h"

enum { W = 320, H = 240 };
static sw_th_pool *g_pool;

typedef struct model {
    sw_sg_scene *scene;
    sw_sg_bvh *bvh;
    sw_lod_cache *cache;
    sw_lod_static_set *statics;
} model;

/* The iso view with static LODs, its eye at `scale` times the fitted distance; converged. */
static sw_gpu_frame_desc view_at(const model *m, double scale)
{
    sw_gpu_frame_desc d = {0};
    d.width = W;
    d.height = H;
    d.camera = sw_test_view_camera_at(m->bvh->box, 1, scale);
    d.hierarchies = m->cache;
    d.bvh = m->bvh;
    d.pool = g_pool;
    d.static_lods = m->statics;
    return d;
}

static int render(sw_gpu_context *ctx, const model *m, const sw_gpu_frame_desc *d,
                  sw_gpu_image *img, sw_gpu_frame_stats *fs, const char *what)
{
    sw_status st = {0};
    memset(img, 0, sizeof *img);
    const sw_result r = sw_gpu_render_scene(ctx, m->scene, d, img, fs, &st);
    CHECK(r == SW_OK, "%s: %s", what, st.message);
    return r == SW_OK;
}

/* One view drawn with residency (twice) and without; the resident frames' images against the
 * other's, their uploads against each other's. Returns the bytes the context holds after. */
static size_t view_pair(sw_gpu_context *ctx, const model *m, double scale, int check_uploads)
{
    char what[64];
    snprintf(what, sizeof what, "view at %.1fx", scale);
    const sw_gpu_frame_desc d = view_at(m, scale);
    sw_gpu_image on1, on2, off;
    sw_gpu_frame_stats s1 = {0}, s2 = {0}, so = {0};
    sw__gpu_set_resident(ctx, 1);
    const size_t held0 = sw__gpu_resident_bytes(ctx);
    int ok = render(ctx, m, &d, &on1, &s1, what);
    const size_t held1 = sw__gpu_resident_bytes(ctx);
    ok = ok && render(ctx, m, &d, &on2, &s2, what);
    const size_t held2 = sw__gpu_resident_bytes(ctx);
    sw__gpu_set_resident(ctx, 0);
    ok = ok && render(ctx, m, &d, &off, &so, what);
    sw__gpu_set_resident(ctx, 1);
    if (ok) {
        const sw_test_image_diff diff = sw_test_compare_images(&on1, &off, 0);
        const sw_test_image_diff again = sw_test_compare_images(&on1, &on2, 0);
        printf("%s: %llu static triangles of %llu, %llu resident; %ld of %ld pixels differ; "
               "uploads %llu, %llu resident (%zu bytes held), %llu without\n",
               what, (unsigned long long)s1.static_triangles, (unsigned long long)s1.triangles,
               (unsigned long long)s1.resident_triangles, diff.any, diff.covered,
               (unsigned long long)s1.upload_bytes, (unsigned long long)s2.upload_bytes, held2,
               (unsigned long long)so.upload_bytes);
        CHECK(diff.covered > 0 && diff.any * 1000 <= diff.covered && again.any == 0,
              "%s: %ld of %ld pixels differ from the frame without residency, %ld from its own "
              "first frame",
              what, diff.any, diff.covered, again.any);
        CHECK(s1.static_triangles > 0 && s1.resident_triangles == s1.static_triangles &&
                  s1.triangles == so.triangles && s1.static_units_drawn == so.static_units_drawn &&
                  so.resident_triangles == 0,
              "%s: triangles %llu (%llu resident of %llu static), without residency %llu", what,
              (unsigned long long)s1.triangles, (unsigned long long)s1.resident_triangles,
              (unsigned long long)s1.static_triangles, (unsigned long long)so.triangles);
        CHECK(so.upload_bytes >= s2.upload_bytes + 12 * s2.static_triangles,
              "%s: %llu bytes uploaded with residency, %llu without", what,
              (unsigned long long)s2.upload_bytes, (unsigned long long)so.upload_bytes);
        if (check_uploads)
            CHECK(held1 > held0 && s1.upload_bytes - s2.upload_bytes == held1 - held0 &&
                      held2 == held1,
                  "%s: the first frame uploaded %llu bytes, the second %llu; the copies grew by "
                  "%zu, then %zu",
                  what, (unsigned long long)s1.upload_bytes, (unsigned long long)s2.upload_bytes,
                  held1 - held0, held2 - held1);
    }
    sw_gpu_image_free(&on1);
    sw_gpu_image_free(&on2);
    sw_gpu_image_free(&off);
    return sw__gpu_resident_bytes(ctx);
}

/* One frame with residency at `scale`; the bytes of the copies held after it. */
static size_t resident_frame(sw_gpu_context *ctx, const model *m, double scale)
{
    const sw_gpu_frame_desc d = view_at(m, scale);
    sw_gpu_image img;
    sw_gpu_frame_stats fs;
    render(ctx, m, &d, &img, &fs, "resident frame");
    sw_gpu_image_free(&img);
    return sw__gpu_resident_bytes(ctx);
}

static void budget(sw_gpu_context *ctx, const model *m)
{
    /* the default budget: nothing dropped */
    const size_t far = resident_frame(ctx, m, 3.0), near = resident_frame(ctx, m, 1.0),
                 near2 = resident_frame(ctx, m, 1.0);
    CHECK(near >= far && near2 == near,
          "default budget: %zu bytes after a far view, %zu after a near one, %zu after it again",
          far, near, near2);
    /* a budget of 0: a frame keeps the copies the frame before it drew, no others */
    sw__gpu_resident_set_budget(ctx, 0);
    resident_frame(ctx, m, 3.0);
    const size_t mixed = resident_frame(ctx, m, 1.0), kept = resident_frame(ctx, m, 1.0);
    printf("budget 0: %zu bytes after a far and a near view, %zu after the near one again\n", mixed,
           kept);
    CHECK(kept > 0 && kept < mixed,
          "budget 0: %zu bytes after a far and a near view, %zu after the near one again", mixed,
          kept);
    view_pair(ctx, m, 1.0, 0); /* still the same image, from what is kept */
    /* a frame of another set (none): every copy dropped */
    sw_gpu_frame_desc d = view_at(m, 1.0);
    d.static_lods = NULL;
    sw_gpu_image img;
    sw_gpu_frame_stats fs;
    if (render(ctx, m, &d, &img, &fs, "without static LODs"))
        CHECK(sw__gpu_resident_bytes(ctx) == 0 && fs.resident_triangles == 0,
              "a frame of no static set: %zu bytes held, %llu resident triangles",
              sw__gpu_resident_bytes(ctx), (unsigned long long)fs.resident_triangles);
    sw_gpu_image_free(&img);
}

int main(int argc, char **argv)
{
    (void)sw_lod_build_install(); /* static LODs are built by the LOD-building module */
    if (argc != 2) {
        fprintf(stderr, "usage: %s MODEL\n", argv[0]);
        return 2;
    }
    sw_status st = {0};
    sw_gpu_context *ctx = NULL;
    sw_th_pool_desc pd = {0};
    sw_sg_import_desc id = {argv[1], NULL, NULL, NULL, NULL, 0};
    model m = {0};
    if (sw_th_pool_create(&pd, &g_pool) != SW_OK ||
        sw_gpu_context_create_headless(&ctx, &st) != SW_OK ||
        sw_sg_import_file(&id, &m.scene, NULL, &st) != SW_OK ||
        sw_sg_bvh_build(m.scene, &m.bvh, &st) != SW_OK ||
        sw_lod_cache_create(m.scene, g_pool, NULL, &m.cache, &st) != SW_OK ||
        sw_lod_static_set_create(m.scene, g_pool, NULL, &m.statics, &st) != SW_OK) {
        fprintf(stderr, "FAIL: pool, context, import, BVH or LOD sets: %s\n", st.message);
        return 1;
    }
    sw__gpu_set_grids_resident(ctx, 0);
    view_pair(ctx, &m, 3.0, 1);
    view_pair(ctx, &m, 6.0, 1);
    budget(ctx, &m);
    sw_lod_static_set_destroy(m.statics);
    sw_lod_cache_destroy(m.cache);
    sw_sg_bvh_free(m.bvh);
    sw_sg_scene_free(m.scene);
    sw_gpu_context_free(ctx);
    sw_th_pool_destroy(g_pool);
    puts(g_failures ? "FAIL" : "PASS");
    return g_failures ? 1 : 0;
}
