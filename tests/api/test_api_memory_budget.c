/* SPDX-License-Identifier: MIT */
/* The renderer's memory budget (sw_renderer_desc.memory_budget_*), through the public API:
 * - a zeroed desc gets the defaults: host half of physical memory, GPU half of what the driver
 *   reports, 1 GiB where it reports nothing (llvmpipe); given values are kept exactly;
 * - a frame under a budget far below the scene's need still draws: the image is a valid, coarser
 *   one (covered pixels within a few percent of the full-budget frame's, and most of them the
 *   same), and the frame says so: budget_coarsened > 0, within bound_exceeded;
 * - with the default budget the same frame coarsens nothing;
 * - once the hierarchies hold their host share, faces not yet built are drawn by their Bézier
 *   patches: fewer hierarchy nodes drawn than with the default budget (planted: the build requests
 *   not gated → as many nodes → FAIL).
 * It would catch a budget that is ignored (no coarsening counted; planted: the trim textures'
 * share not taken from the context → budget_coarsened 0 → FAIL), a budget that breaks the frame
 * (an error, or an empty or garbage image), and coarsening counted where nothing was spent.
 * Usage: test_api_memory_budget MODEL WORKDIR */
#include "api_test_image.h"

#include <splinewalk/splinewalk.h>
#include <splinewalk/sw_import.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int g_failed;

#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            printf("FAIL: " __VA_ARGS__);                                                          \
            printf("\n");                                                                          \
            g_failed = 1;                                                                          \
        }                                                                                          \
    } while (0)

/* One converged frame of `scene` at 640x480 under the given budget, written to `png`. */
static int draw(sw_scene scene, uint64_t host, uint64_t gpu, const char *png, sw_memory_budget *b,
                sw_frame_stats *stats)
{
    sw_status st = {0};
    sw_renderer_desc rd = {0};
    rd.memory_budget_host = host;
    rd.memory_budget_gpu = gpu;
    sw_renderer r = {0};
    if (sw_renderer_create(&rd, &r, &st) != SW_OK) {
        printf("FAIL: renderer: %s\n", st.message);
        return -1;
    }
    sw_frame_desc fd = {0};
    fd.scene = scene;
    fd.width = 640;
    fd.height = 480;
    fd.output_path = png;
    int rc = sw_renderer_memory_budget(r, b, &st) == SW_OK &&
                     sw_camera_fit(scene, SW_VIEW_ISO, &fd.camera, &st) == SW_OK &&
                     sw_renderer_draw(r, &fd, stats, &st) == SW_OK
                 ? 0
                 : -1;
    if (rc)
        printf("FAIL: frame under host %llu, GPU %llu bytes: %s\n", (unsigned long long)host,
               (unsigned long long)gpu, st.message);
    sw_renderer_destroy(r);
    return rc;
}

/* Covered (non-background) pixels of each image, and those covered in exactly one. */
static int coverage(const char *a, const char *b, long *cov_a, long *cov_b, long *only_one)
{
    int wa, ha, wb, hb;
    unsigned char *pa = sw_test_read_rgba(a, &wa, &ha), *pb = sw_test_read_rgba(b, &wb, &hb);
    int ok = pa && pb && wa == wb && ha == hb;
    *cov_a = *cov_b = *only_one = 0;
    for (long i = 0; ok && i < (long)wa * ha; i++) {
        /* the background is the top-left pixel's colour in both (a fitted view leaves it) */
        const int ia = memcmp(pa + 4 * i, pa, 4) != 0, ib = memcmp(pb + 4 * i, pb, 4) != 0;
        *cov_a += ia, *cov_b += ib, *only_one += ia != ib;
    }
    free(pa);
    free(pb);
    return ok ? 0 : -1;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: test_api_memory_budget MODEL WORKDIR\n");
        return 2;
    }
    sw_status st = {0};
    sw_scene scene = {0};
    (void)sw_import_install();
    sw_scene_load_desc ld = {0};
    ld.path = argv[1];
    if (sw_scene_load(&ld, &scene, &st) != SW_OK) {
        printf("FAIL: load %s: %s\n", argv[1], st.message);
        return 1;
    }
    char full_png[4096], small_png[4096];
    snprintf(full_png, sizeof full_png, "%s/budget_default.png", argv[2]);
    snprintf(small_png, sizeof small_png, "%s/budget_small.png", argv[2]);
    sw_memory_budget full_b, small_b;
    sw_frame_stats full, small;
    const uint64_t small_host = 256 << 10, small_gpu = 1 << 20;
    if (draw(scene, 0, 0, full_png, &full_b, &full) ||
        draw(scene, small_host, small_gpu, small_png, &small_b, &small)) {
        sw_scene_destroy(scene);
        return 1;
    }
    sw_scene_destroy(scene);

    const uint64_t half_ram =
        (uint64_t)sysconf(_SC_PHYS_PAGES) * (uint64_t)sysconf(_SC_PAGESIZE) / 2;
    const uint64_t want_gpu = full_b.gpu_reported_bytes ? full_b.gpu_reported_bytes / 2 : 1u << 30;
    printf("default budget: host %llu, GPU %llu bytes (driver reports %llu)\n",
           (unsigned long long)full_b.host_bytes, (unsigned long long)full_b.gpu_bytes,
           (unsigned long long)full_b.gpu_reported_bytes);
    CHECK(full_b.host_bytes == half_ram, "default host budget %llu, half of memory is %llu",
          (unsigned long long)full_b.host_bytes, (unsigned long long)half_ram);
    CHECK(full_b.gpu_bytes == want_gpu, "default GPU budget %llu, want %llu",
          (unsigned long long)full_b.gpu_bytes, (unsigned long long)want_gpu);
    CHECK(small_b.host_bytes == small_host && small_b.gpu_bytes == small_gpu,
          "given budget not kept: host %llu, GPU %llu", (unsigned long long)small_b.host_bytes,
          (unsigned long long)small_b.gpu_bytes);

    printf("default budget: %llu trim texels, bound exceeded %llu, coarsened %llu\n",
           (unsigned long long)full.trim_texels, (unsigned long long)full.bound_exceeded,
           (unsigned long long)full.budget_coarsened);
    printf("small budget:   %llu trim texels, bound exceeded %llu, coarsened %llu\n",
           (unsigned long long)small.trim_texels, (unsigned long long)small.bound_exceeded,
           (unsigned long long)small.budget_coarsened);
    CHECK(full.budget_coarsened == 0, "the default budget coarsened %llu pieces",
          (unsigned long long)full.budget_coarsened);
    CHECK(small.budget_coarsened > 0 && small.budget_coarsened <= small.bound_exceeded,
          "small budget: coarsened %llu, bound exceeded %llu",
          (unsigned long long)small.budget_coarsened, (unsigned long long)small.bound_exceeded);
    CHECK(small.trim_texels * 4 <= full.trim_texels && small.trim_texels > 0,
          "small budget: %llu trim texels against %llu", (unsigned long long)small.trim_texels,
          (unsigned long long)full.trim_texels);
    printf("hierarchy nodes drawn: %llu default, %llu small budget\n",
           (unsigned long long)full.hierarchy_nodes, (unsigned long long)small.hierarchy_nodes);
    CHECK(small.hierarchy_nodes < full.hierarchy_nodes,
          "small budget: %llu hierarchy nodes drawn, as many as the default's %llu",
          (unsigned long long)small.hierarchy_nodes, (unsigned long long)full.hierarchy_nodes);
    CHECK(small.faces_drawn == full.faces_drawn, "faces drawn %llu against %llu",
          (unsigned long long)small.faces_drawn, (unsigned long long)full.faces_drawn);

    long cov_full, cov_small, only_one;
    CHECK(coverage(full_png, small_png, &cov_full, &cov_small, &only_one) == 0,
          "frames unreadable");
    printf("covered pixels: %ld default, %ld small budget, %ld covered in one only (%.2f %%)\n",
           cov_full, cov_small, only_one, cov_full ? 100.0 * only_one / cov_full : 0.0);
    /* coarser trim textures move trim edges by a texel or two: a few percent, never the model */
    CHECK(cov_full > 10000 && only_one * 50 <= cov_full, "coverage differs in %ld of %ld pixels",
          only_one, cov_full);
    printf(g_failed ? "test_api_memory_budget: FAIL\n" : "test_api_memory_budget: PASS\n");
    return g_failed;
}
