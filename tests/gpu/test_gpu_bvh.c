/* SPDX-License-Identifier: MIT */
/* The BVH over face occurrences (scenegraph/sw_sg_bvh.h; Kumar et al. 1997 §4.4) and the frame's
 * culling by it (desc.bvh):
 *  - structure: every occurrence of the scene's traversal is an item exactly once; every item's
 *    box contains its face's control points mapped through its transform; every node's box
 *    contains its subtree's items, which are contiguous; leaves hold <= SW_SG_BVH_LEAF items;
 *  - culling: frames drawn with the BVH are pixel-identical to frames drawn without it, with the
 *    same faces drawn, from views that see all, part, or none of the model (close-ups looking at
 *    a corner, from inside, away from the model).
 * Usage: test_gpu_bvh MODEL...
 */
#include "gpu_test_compare.h"
#include "sw_gpu_internal.h"
#include "sw_sg_bvh.h"
#include "sw_sg_import.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "test_check.h"

enum { W = 320, H = 180 };

typedef struct counter {
    uint64_t n;
} counter;

static int count_visit(void *ctx, uint32_t face, const double world[12], const float color[4])
{
    (void)face, (void)world, (void)color;
    ((counter *)ctx)->n++;
    return 0;
}

static int box_contains(const double outer[6], const double inner[6])
{
    for (int k = 0; k < 3; ++k)
        if (inner[k] < outer[k] || inner[3 + k] > outer[3 + k])
            return 0;
    return 1;
}

static void check_item(const sw_sg_scene *scene, const sw_sg_bvh *t, uint32_t item)
{
    sw_sg_bvh_item_view view;
    sw_sg_bvh_item_at(t, item, &view);
    const sw_sg_bvh_item_view *it = &view;
    sw_sg_surface s;
    sw_sg_scene_face_surface(scene, it->face, &s);
    const double *m = it->world;
    for (size_t i = 0; i < (size_t)s.n_u * (size_t)s.n_v; ++i) {
        const double *h = s.cpw + 4 * i;
        for (int r = 0; r < 3; ++r) {
            double x =
                (m[4 * r] * h[0] + m[4 * r + 1] * h[1] + m[4 * r + 2] * h[2]) / h[3] + m[4 * r + 3];
            double tol = 1e-12 * (fabs(it->box[r]) + fabs(it->box[3 + r]) + 1.0);
            if (x < it->box[r] - tol || x > it->box[3 + r] + tol) {
                CHECK(0, "face %u: a control point outside its item box", it->face);
                return;
            }
        }
    }
}

static void check_structure(const sw_sg_scene *scene, const sw_sg_bvh *t)
{
    counter c = {0};
    sw_sg_scene_traverse(scene, count_visit, &c);
    CHECK(t->n_items == c.n, "%u items for %llu occurrences", t->n_items, (unsigned long long)c.n);
    uint32_t leaf_items = 0, max_leaf = 0;
    for (uint32_t i = 0; i < t->n_nodes; ++i) {
        const sw_sg_bvh_node *n = &t->nodes[i];
        CHECK(n->first + n->count <= t->n_items, "node %u: range out of the items", i);
        double nb[6], ib[6];
        sw_sg_bvh_node_box(t, i, nb);
        for (uint32_t k = n->first; k < n->first + n->count && k < t->n_items; ++k) {
            sw_sg_bvh_item_box(t, k, ib);
            CHECK(box_contains(nb, ib), "node %u: item %u outside its box", i, k);
        }
        if (n->second < 0) {
            leaf_items += n->count;
            max_leaf = n->count > max_leaf ? n->count : max_leaf;
            continue;
        }
        const sw_sg_bvh_node *a = &t->nodes[sw_sg_bvh_child(t, i, 0)],
                             *b = &t->nodes[sw_sg_bvh_child(t, i, 1)];
        CHECK(a->first == n->first && b->first == a->first + a->count &&
                  a->count + b->count == n->count,
              "node %u: children's ranges do not split its own", i);
    }
    CHECK(leaf_items == t->n_items && max_leaf <= SW_SG_BVH_LEAF,
          "leaves hold %u items (of %u), at most %u each", leaf_items, t->n_items, max_leaf);
    for (uint32_t k = 0; k < t->n_items; ++k)
        check_item(scene, t, k);
    printf("  structure: %u items, %u nodes, %zu bytes\n", t->n_items, t->n_nodes,
           sw_sg_bvh_memory(t));
}

static sw_gpu_camera camera_at(const double b[6], const double from[3], const double at[3])
{
    sw_gpu_camera c;
    memset(&c, 0, sizeof c);
    for (int k = 0; k < 3; ++k) {
        c.eye[k] = b[k] + from[k] * (b[3 + k] - b[k]);
        c.target[k] = b[k] + at[k] * (b[3 + k] - b[k]);
    }
    c.up[2] = 1.0;
    c.fovy_deg = 40.0;
    return c;
}

static void compare_views(sw_gpu_context *ctx, const sw_sg_scene *scene, const sw_sg_bvh *t,
                          const double box[6])
{
    static const double k_views[5][6] = {{1.6, 1.6, 1.6, 0.5, 0.5, 0.5},  /* all of it */
                                         {0.9, 0.9, 0.7, 1.0, 1.0, 0.5},  /* a corner, close */
                                         {0.5, 0.5, 0.5, 0.0, 0.5, 0.5},  /* from inside */
                                         {0.2, -0.3, 0.6, 0.4, 0.3, 0.4}, /* part */
                                         {-2.0, -2.0, 0.5, -3.0, -3.0, 0.5} /* away from it */};
    for (int v = 0; v < 5; ++v) {
        sw_gpu_frame_desc d;
        memset(&d, 0, sizeof d);
        d.width = W;
        d.height = H;
        d.camera = camera_at(box, k_views[v], k_views[v] + 3);
        sw_gpu_image a = {0}, b = {0};
        sw_gpu_frame_stats fa, fb;
        sw_status st = {0};
        int ok = sw_gpu_render_scene(ctx, scene, &d, &a, &fa, &st) == SW_OK;
        d.bvh = t;
        ok = ok && sw_gpu_render_scene(ctx, scene, &d, &b, &fb, &st) == SW_OK;
        CHECK(ok, "view %d: render: %s", v, st.message);
        if (ok) {
            sw_test_image_diff df = sw_test_compare_images(&a, &b, 0);
            CHECK(df.any == 0 && fa.faces_drawn == fb.faces_drawn && fa.triangles == fb.triangles,
                  "view %d: %ld pixels differ, faces drawn %llu vs %llu", v, df.any,
                  (unsigned long long)fa.faces_drawn, (unsigned long long)fb.faces_drawn);
            printf("  view %d: faces drawn %llu, culled %llu (without BVH culled %llu); "
                   "tessellate %.1f ms with, %.1f ms without; %ld px covered, %ld differ\n",
                   v, (unsigned long long)fb.faces_drawn, (unsigned long long)fb.faces_culled,
                   (unsigned long long)fa.faces_culled, fb.ms_tessellate, fa.ms_tessellate,
                   df.covered, df.any);
        }
        sw_gpu_image_free(&a);
        sw_gpu_image_free(&b);
    }
}

static void run_scene(sw_gpu_context *ctx, const sw_sg_scene *scene, const char *name)
{
    printf("%s\n", name);
    sw_sg_bvh *t = NULL;
    sw_status st = {0};
    if (sw_sg_bvh_build(scene, &t, &st) != SW_OK) {
        CHECK(0, "BVH: %s", st.message);
        return;
    }
    check_structure(scene, t);
    compare_views(ctx, scene, t, t->box);
    sw_sg_bvh_free(t);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s MODEL...\n", argv[0]);
        return 2;
    }
    sw_status st = {0};
    sw_gpu_context *ctx = NULL;
    if (sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        fprintf(stderr, "FAIL: %s\n", st.message);
        return 1;
    }
    for (int a = 1; a < argc; ++a) {
        sw_sg_import_desc id = {argv[a], NULL, NULL, NULL, NULL, 0};
        sw_sg_scene *scene = NULL;
        if (sw_sg_import_file(&id, &scene, NULL, &st) != SW_OK) {
            CHECK(0, "import %s: %s", argv[a], st.message);
            continue;
        }
        run_scene(ctx, scene, argv[a]);
        sw_sg_scene_free(scene);
    }
    sw_gpu_context_free(ctx);
    puts(g_failures ? "FAIL" : "PASS");
    return g_failures ? 1 : 0;
}
