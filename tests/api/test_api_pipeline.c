/* SPDX-License-Identifier: MIT */
/* tests/api: split frames — sw_renderer_prepare on the visibility thread, sw_renderer_submit on
 * the owner's (the frame overlap, the split calls), against the shared library.
 *
 *  1. Converged split frames equal sw_renderer_draw's: three cameras drawn in one call each, then
 *     prepared two ahead and submitted; the PNG files are byte-identical (the same pixels through
 *     the same encoder), and a different camera's file is not (the check can fail). A draw is
 *     prepared on the visibility thread too, the caller waiting for it (ms_visibility > 0 and
 *     within ms_wait_visibility; with the draw on the caller's thread ms_visibility was 0).
 *  2. Contract: a third prepare while two wait, sw_renderer_draw while frames wait and a submit
 *     with none prepared → SW_ERR_INVALID_ARGUMENT; a bad camera is refused by prepare itself;
 *     destroying a renderer with prepared frames drops them (ASan: nothing leaks or dangles).
 *  3. Overlap in walkthrough mode: FRAMES frames of a moving camera as prepare(i + 1); submit(i):
 *     no frame waits for the pool, every prepared frame is submitted once, and the visibility
 *     thread's work is reported (ms_visibility) apart from the submitting thread's (its stages,
 *     ms_wait_visibility included, are parts of ms_total; how large a part is for profiles).
 *     Pool waits are counted wherever the frame's threads block on the pool (group
 *     waits that find tasks pending and bracketed waits on tasks' results, on the visibility
 *     thread and on the submitting one; before, only the converged hierarchy stage counted, so
 *     0 held by construction). Seen failing with a planted walkthrough wait for one face's build
 *     (gpu/stage_hierarchy.c request_walkthrough): "pool waits 1" here, "pool waits 5" in 4.
 *
 *  4. With STATIC_SCENE: static LODs (Kumar §4) in walkthrough split frames, the camera far out
 *     (8x the fitted distance) and turning: no frame waits for the pool while the super-surfaces
 *     are clustered and their levels built behind the frames; once the camera stops, the builds
 *     settle (no request left, static draws made) within 300 s; the walkthrough frame and the
 *     converged one (which waits for every build it needs) are written as static_walk_0.png and
 *     static_conv_0.png, which ctest then compares (at most 0.1 % of the pixels may differ, as
 *     for walkthrough frames without static LODs: tests/gpu/test_gpu_walkthrough.c).
 *
 * usage: test_api_pipeline SCENE WORKDIR [FRAMES [STATIC_SCENE]]
 */
#include <splinewalk/splinewalk.h>
#include <splinewalk/sw_import.h>
#include <splinewalk/sw_lod_build.h>

#include "api_test_expect.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static const char *g_work;

static sw_camera orbit(const sw_camera *home, int i)
{
    sw_camera c = *home;
    double a = 0.2 * i, d[3];
    for (int k = 0; k < 3; ++k)
        d[k] = c.eye[k] - c.target[k];
    c.eye[0] = c.target[0] + d[0] * cos(a) - d[1] * sin(a);
    c.eye[1] = c.target[1] + d[0] * sin(a) + d[1] * cos(a);
    c.eye[2] = c.target[2] + d[2] * (1.0 - 0.02 * i);
    return c;
}

static sw_frame_desc frame_at(sw_scene scene, sw_camera cam, const char *out)
{
    sw_frame_desc f = {0};
    f.scene = scene;
    f.camera = cam;
    f.width = 320;
    f.height = 200;
    f.output_path = out;
    return f;
}

static char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = len > 0 ? malloc((size_t)len) : NULL;
    *n = buf && fread(buf, 1, (size_t)len, f) == (size_t)len ? (size_t)len : 0;
    fclose(f);
    return buf;
}

static int same_file(const char *a, const char *b)
{
    size_t na = 0, nb = 0;
    char *pa = slurp(a, &na), *pb = slurp(b, &nb);
    int same = pa && pb && na == nb && na > 0 && memcmp(pa, pb, na) == 0;
    free(pa);
    free(pb);
    return same;
}

static void path(char *out, const char *what, int i)
{
    snprintf(out, 1024, "%s/%s_%d.png", g_work, what, i);
}

static void test_equal_to_draw(sw_renderer r, sw_scene scene, const sw_camera *home)
{
    char direct[1024], split[1024];
    for (int i = 0; i < 3; ++i) {
        path(direct, "direct", i);
        sw_frame_desc f = frame_at(scene, orbit(home, 3 * i), direct);
        sw_frame_stats st = {0};
        EXPECT_RESULT(sw_renderer_draw(r, &f, &st, NULL), SW_OK);
        /* one pipeline: the draw was prepared on the visibility thread while the caller waited
         * for it (its wait covers V's time but for the clock reads' spacing) */
        EXPECT(st.ms_visibility > 0.0 && st.ms_wait_visibility >= st.ms_visibility - 0.05);
        EXPECT(st.ms_total >= st.ms_wait_visibility);
    }
    int prepared = 0, submitted = 0;
    for (; submitted < 3; ++submitted) {
        while (prepared < 3 && prepared < submitted + SW_RENDERER_MAX_PREPARED) {
            path(split, "split", prepared);
            sw_frame_desc f = frame_at(scene, orbit(home, 3 * prepared), split);
            EXPECT_RESULT(sw_renderer_prepare(r, &f, NULL), SW_OK);
            prepared++;
        }
        sw_frame_stats st;
        EXPECT_RESULT(sw_renderer_submit(r, &st, NULL), SW_OK);
        EXPECT(st.ms_visibility > 0.0 && st.ms_wait_visibility >= 0.0);
    }
    int same = 0;
    for (int i = 0; i < 3; ++i) {
        path(direct, "direct", i);
        path(split, "split", i);
        same += same_file(direct, split);
    }
    path(direct, "direct", 0);
    path(split, "split", 1);
    int control = same_file(direct, split);
    EXPECT(same == 3 && !control);
    printf("split frames = direct frames: %d of 3 byte-identical PNGs; another camera's: %s\n",
           same, control ? "identical (FAIL)" : "differs");
}

static void test_contract(sw_renderer r, sw_scene scene, const sw_camera *home)
{
    sw_frame_desc f = frame_at(scene, *home, NULL);
    EXPECT_RESULT(sw_renderer_submit(r, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    EXPECT_RESULT(sw_renderer_prepare(r, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    sw_frame_desc bad = f;
    bad.camera.up[0] = bad.camera.up[1] = bad.camera.up[2] = 0.0;
    EXPECT_RESULT(sw_renderer_prepare(r, &bad, NULL), SW_ERR_INVALID_ARGUMENT);
    EXPECT_RESULT(sw_renderer_submit(r, NULL, NULL), SW_ERR_INVALID_ARGUMENT); /* not queued */
    for (int i = 0; i < SW_RENDERER_MAX_PREPARED; ++i)
        EXPECT_RESULT(sw_renderer_prepare(r, &f, NULL), SW_OK);
    EXPECT_RESULT(sw_renderer_prepare(r, &f, NULL), SW_ERR_INVALID_ARGUMENT);
    EXPECT_RESULT(sw_renderer_draw(r, &f, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    for (int i = 0; i < SW_RENDERER_MAX_PREPARED; ++i)
        EXPECT_RESULT(sw_renderer_submit(r, NULL, NULL), SW_OK);
    EXPECT_RESULT(sw_renderer_submit(r, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    EXPECT_RESULT(sw_renderer_draw(r, &f, NULL, NULL), SW_OK);
    printf("contract: queue limit %d, draw and empty submit refused while it says so\n",
           SW_RENDERER_MAX_PREPARED);
}

static void test_walkthrough_overlap(sw_scene scene, const sw_camera *home, int frames)
{
    sw_renderer r = {0};
    sw_renderer_desc rd = {.worker_threads = 2};
    EXPECT_RESULT(sw_renderer_create(&rd, &r, NULL), SW_OK);
    uint64_t waits = 0;
    double vis = 0.0, wait = 0.0, total = 0.0, worst_gap = 0.0;
    sw_frame_desc f = frame_at(scene, orbit(home, 0), NULL);
    f.walkthrough = 1;
    EXPECT_RESULT(sw_renderer_prepare(r, &f, NULL), SW_OK);
    for (int i = 0; i < frames; ++i) {
        if (i + 1 < frames) {
            f.camera = orbit(home, i + 1);
            EXPECT_RESULT(sw_renderer_prepare(r, &f, NULL), SW_OK);
        }
        sw_frame_stats st = {0};
        EXPECT_RESULT(sw_renderer_submit(r, &st, NULL), SW_OK);
        waits += st.pool_waits;
        vis += st.ms_visibility;
        wait += st.ms_wait_visibility;
        total += st.ms_total;
        double parts =
            st.ms_wait_visibility + st.ms_trim + st.ms_draw + st.ms_readback + st.ms_write;
        worst_gap = fmax(worst_gap, st.ms_total - parts);
    }
    /* A dropped frame would leave the last submit without a frame: */
    EXPECT_RESULT(sw_renderer_submit(r, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    EXPECT(waits == 0);
    EXPECT(worst_gap >= 0.0); /* the stages are parts of the call (their sizes are a profile's) */
    printf("walkthrough, %d frames prepared one ahead: pool waits %llu; visibility thread %.1f ms "
           "in all, submitting thread %.1f ms (of which waiting for visibility %.1f); largest "
           "part of a submit outside its stages %.2f ms\n",
           frames, (unsigned long long)waits, vis, total, wait, worst_gap);
    /* Destroyed with a frame prepared: dropped, not drawn, nothing leaked. */
    EXPECT_RESULT(sw_renderer_prepare(r, &f, NULL), SW_OK);
    EXPECT_RESULT(sw_renderer_destroy(r), SW_OK);
}

/* Two headless renderers on one thread, frames interleaved: a draws, then b is created and
 * draws, then a draws the same frame again and must give the same image. A context's object names
 * are its own, so b's objects reuse the names of a's (the FBO, the trim atlas that a's second
 * frame reuses): a renderer that drew in whatever context was current would take b's atlas for
 * its own. (Found by bench_pipeline as GL_INVALID_OPERATION in the trim atlas.) */
static void test_two_renderers_one_thread(sw_scene scene, const sw_camera *home)
{
    sw_renderer a = {0}, b = {0};
    char first[1024], again[1024], other[1024];
    path(first, "two_a", 0);
    path(other, "two_b", 0);
    path(again, "two_a", 1);
    sw_frame_desc fa = frame_at(scene, orbit(home, 2), first);
    sw_frame_desc fb = frame_at(scene, orbit(home, 9), other);
    fb.width = 800;
    fb.height = 600;
    EXPECT_RESULT(sw_renderer_create(NULL, &a, NULL), SW_OK);
    EXPECT_RESULT(sw_renderer_draw(a, &fa, NULL, NULL), SW_OK);
    EXPECT_RESULT(sw_renderer_create(NULL, &b, NULL), SW_OK);
    EXPECT_RESULT(sw_renderer_draw(b, &fb, NULL, NULL), SW_OK);
    fa.output_path = again;
    sw_status st = {0};
    sw_result r = sw_renderer_draw(a, &fa, NULL, &st);
    int same = r == SW_OK && same_file(first, again);
    EXPECT(same);
    printf("two renderers on one thread: the first one's frame %s after the second drew%s%s\n",
           same ? "unchanged" : "CHANGED", r == SW_OK ? "" : ": ", r == SW_OK ? "" : st.message);
    EXPECT_RESULT(sw_renderer_destroy(a), SW_OK);
    EXPECT_RESULT(sw_renderer_destroy(b), SW_OK);
}

static sw_camera far_out(const sw_camera *home, int i)
{
    sw_camera c = orbit(home, i);
    for (int k = 0; k < 3; ++k)
        c.eye[k] = c.target[k] + 8.0 * (c.eye[k] - c.target[k]);
    return c;
}

static void test_static_walkthrough(const char *scene_path, int frames)
{
    sw_scene_load_desc ld = {scene_path, NULL, NULL, NULL, NULL, 0};
    sw_scene scene = {0};
    sw_renderer r = {0};
    sw_renderer_desc rd = {.worker_threads = 2};
    sw_camera home;
    EXPECT_RESULT(sw_scene_load(&ld, &scene, NULL), SW_OK);
    EXPECT_RESULT(sw_camera_fit(scene, SW_VIEW_ISO, &home, NULL), SW_OK);
    EXPECT_RESULT(sw_renderer_create(&rd, &r, NULL), SW_OK);
    sw_frame_desc f = frame_at(scene, far_out(&home, 0), NULL);
    f.walkthrough = 1;
    f.static_lods = 1;
    uint64_t waits = 0, requests = 0, drawn = 0;
    EXPECT_RESULT(sw_renderer_prepare(r, &f, NULL), SW_OK);
    for (int i = 0; i < frames; ++i) { /* moving */
        f.camera = far_out(&home, i + 1);
        EXPECT_RESULT(sw_renderer_prepare(r, &f, NULL), SW_OK);
        sw_frame_stats st = {0};
        EXPECT_RESULT(sw_renderer_submit(r, &st, NULL), SW_OK);
        waits += st.pool_waits;
        requests += st.static_requests;
        drawn += st.static_drawn;
    }
    sw_frame_stats st = {0};
    EXPECT_RESULT(sw_renderer_submit(r, &st, NULL), SW_OK);
    /* stopped: walkthrough frames until no build is asked for and the static draws are made */
    int settled = 0, n = 0;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (double s = 0.0; s < 300.0 && !settled; ++n) {
        EXPECT_RESULT(sw_renderer_draw(r, &f, &st, NULL), SW_OK);
        waits += st.pool_waits;
        settled = st.static_requests == 0 && st.fallback_draws == 0 && st.static_drawn > 0;
        clock_gettime(CLOCK_MONOTONIC, &t1);
        s = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    }
    EXPECT(waits == 0);
    EXPECT(settled);
    char walk[1024], conv[1024];
    path(walk, "static_walk", 0);
    path(conv, "static_conv", 0);
    f.output_path = walk;
    EXPECT_RESULT(sw_renderer_draw(r, &f, NULL, NULL), SW_OK);
    f.output_path = conv;
    f.walkthrough = 0;
    EXPECT_RESULT(sw_renderer_draw(r, &f, NULL, NULL), SW_OK);
    const int same = same_file(walk, conv);
    printf("static LODs, walkthrough: %d moving frames (%llu builds queued, %llu static draws, "
           "pool waits %llu); settled after %d more frames with %llu super-surfaces static; "
           "walkthrough frame %s the converged one (compared by ctest)\n",
           frames, (unsigned long long)requests, (unsigned long long)drawn,
           (unsigned long long)waits, n, (unsigned long long)st.static_drawn,
           same ? "byte-identical to" : "not byte-identical to");
    EXPECT_RESULT(sw_renderer_destroy(r), SW_OK);
    EXPECT_RESULT(sw_scene_destroy(scene), SW_OK);
}

int main(int argc, char **argv)
{
    (void)sw_import_install(), (void)sw_lod_build_install(); /* .brep scenes, static LODs */
    if (argc < 3 || argc > 5) {
        fprintf(stderr, "usage: %s SCENE WORKDIR [FRAMES [STATIC_SCENE]]\n", argv[0]);
        return 2;
    }
    g_work = argv[2];
    int frames = argc == 4 ? atoi(argv[3]) : 30;
    sw_scene_load_desc ld = {argv[1], NULL, NULL, NULL, NULL, 0};
    sw_scene scene = {0};
    sw_status st = {0};
    if (sw_scene_load(&ld, &scene, &st) != SW_OK || frames < 2) {
        fprintf(stderr, "cannot load %s: %s\n", argv[1], st.message);
        return 2;
    }
    sw_camera home;
    EXPECT_RESULT(sw_camera_fit(scene, SW_VIEW_ISO, &home, NULL), SW_OK);
    sw_renderer r = {0};
    sw_renderer_desc rd = {.worker_threads = 2};
    EXPECT_RESULT(sw_renderer_create(&rd, &r, &st), SW_OK);
    test_equal_to_draw(r, scene, &home);
    test_contract(r, scene, &home);
    EXPECT_RESULT(sw_renderer_destroy(r), SW_OK);
    test_walkthrough_overlap(scene, &home, frames);
    test_two_renderers_one_thread(scene, &home);
    EXPECT_RESULT(sw_scene_destroy(scene), SW_OK);
    if (argc == 5)
        test_static_walkthrough(argv[4], frames);
    printf("%s: %d failure(s)\n", g_failures ? "FAIL" : "ok", g_failures);
    return g_failures ? 1 : 0;
}
