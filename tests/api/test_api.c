/* SPDX-License-Identifier: MIT */
/* tests/api: misuse of the public API → the sw_result each function documents in
 * runtime/include/splinewalk/splinewalk.h, never a crash or a memory error (CI runs this under
 * ASan + UBSan). Linked against libsplinewalk.so through the public headers only.
 *
 *   test_api handles  SCENE.tsm WORKDIR   NULL descs and outs, stale and forged handles, double
 *                                         destroy, slot reuse, a scene destroyed while another
 *                                         thread saves it (no GL)
 *   test_api renderer SCENE.tsm WORKDIR BIG_SCENE
 *                                         the renderer: bad frame descs, calls from a thread that
 *                                         does not own the GL context, stale renderers and scenes,
 *                                         a scene destroyed while its owner draws it, and
 *                                         BIG_SCENE destroyed after a walkthrough frame (EGL) */
#include <splinewalk/splinewalk.h>
#include <splinewalk/sw_import.h>
#include <splinewalk/sw_lod_build.h>

#include "api_test_expect.h"

#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

static const char *g_scene_path, *g_work, *g_big_scene_path;

static sw_scene load_scene(void)
{
    sw_scene_load_desc desc = {g_scene_path, NULL, NULL, NULL, NULL, 0};
    sw_scene scene = {0};
    sw_status status = {0};
    EXPECT_RESULT(sw_scene_load(&desc, &scene, &status), SW_OK);
    EXPECT(scene.id != 0);
    return scene;
}

static void work_path(char *out, size_t size, const char *name)
{
    snprintf(out, size, "%s/%s", g_work, name);
}

static int file_exists(const char *path)
{
    return access(path, F_OK) == 0;
}

/* ---- scenes, no GL ----------------------------------------------------------------------------
 */
static void test_null_arguments(void)
{
    sw_status status = {0};
    sw_scene scene = {12345};
    EXPECT_RESULT(sw_scene_load(NULL, &scene, &status), SW_ERR_INVALID_ARGUMENT);
    EXPECT(status.result == SW_ERR_INVALID_ARGUMENT && status.message[0] != '\0');
    EXPECT(scene.id == 0); /* *out = {0} on failure */
    sw_scene_load_desc no_path = {0};
    EXPECT_RESULT(sw_scene_load(&no_path, &scene, NULL), SW_ERR_INVALID_ARGUMENT);
    sw_scene_load_desc desc = {g_scene_path, NULL, NULL, NULL, NULL, 0};
    EXPECT_RESULT(sw_scene_load(&desc, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    EXPECT_RESULT(sw_scene_load_default(NULL, NULL, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    sw_scene_load_desc wrong_ext = {"scene.txt", NULL, NULL, NULL, NULL, 0};
    EXPECT_RESULT(sw_scene_load(&wrong_ext, &scene, NULL), SW_ERR_UNSUPPORTED);
    char missing[4096];
    work_path(missing, sizeof missing, "missing.sws");
    sw_scene_load_desc absent = {missing, NULL, NULL, NULL, NULL, 0};
    EXPECT_RESULT(sw_scene_load(&absent, &scene, NULL), SW_ERR_NOT_FOUND);

    scene = load_scene();
    sw_camera camera;
    EXPECT_RESULT(sw_scene_get_info(scene, NULL, &status), SW_ERR_INVALID_ARGUMENT);
    EXPECT_RESULT(sw_camera_fit(scene, SW_VIEW_ISO, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    EXPECT_RESULT(sw_camera_fit(scene, (sw_view_preset)4, &camera, NULL), SW_ERR_INVALID_ARGUMENT);
    EXPECT_RESULT(sw_camera_fit(scene, (sw_view_preset)-1, &camera, NULL), SW_ERR_INVALID_ARGUMENT);
    EXPECT_RESULT(sw_scene_save(scene, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    EXPECT_RESULT(sw_scene_destroy(scene), SW_OK);
}

static void expect_stale_scene(sw_scene scene, int line)
{
    sw_status status = {0};
    sw_scene_info info;
    sw_camera camera;
    char path[4096];
    work_path(path, sizeof path, "stale.sws");
    sw_test_expect_result(sw_scene_get_info(scene, &info, &status), SW_ERR_STALE_HANDLE, "get_info",
                          line);
    EXPECT(status.result == SW_ERR_STALE_HANDLE);
    sw_test_expect_result(sw_camera_fit(scene, SW_VIEW_ISO, &camera, NULL), SW_ERR_STALE_HANDLE,
                          "camera_fit", line);
    sw_test_expect_result(sw_scene_save(scene, path, NULL), SW_ERR_STALE_HANDLE, "save", line);
    EXPECT(!file_exists(path)); /* a failed call changes nothing */
    sw_test_expect_result(sw_scene_destroy(scene), SW_ERR_STALE_HANDLE, "destroy", line);
}

static void test_stale_and_double_destroy(void)
{
    sw_scene a = load_scene();
    sw_scene_info info_a;
    EXPECT_RESULT(sw_scene_get_info(a, &info_a, NULL), SW_OK);
    EXPECT(info_a.faces > 0);
    EXPECT_RESULT(sw_scene_destroy(a), SW_OK);
    expect_stale_scene(a, __LINE__); /* includes the double destroy */
    expect_stale_scene((sw_scene){0}, __LINE__);
    expect_stale_scene((sw_scene){0xffffffffu}, __LINE__);     /* forged: slot out of range */
    expect_stale_scene((sw_scene){a.id + 0x10000u}, __LINE__); /* a future generation */

    /* The slot is reused by the next scene; the old handle must stay stale and its double destroy
     * must not free the new scene. */
    sw_scene b = load_scene();
    EXPECT(b.id != a.id);
    EXPECT(((b.id ^ a.id) & 0xffffu) == 0); /* same slot, other generation: the case that matters */
    expect_stale_scene(a, __LINE__);
    sw_scene_info info_b;
    EXPECT_RESULT(sw_scene_get_info(b, &info_b, NULL), SW_OK);
    EXPECT(info_b.faces == info_a.faces);
    EXPECT_RESULT(sw_scene_destroy(b), SW_OK);
}

/* sw_scene_pick through the public API: rays from the fitted presets' eyes to the box centre of
 * the T-spline sample — at least one hits, every hit is in front of the eye and on its ray, every
 * opposite ray misses; bad arguments and stale handles give the documented results. (Accuracy
 * against OCCT: tests/pick.) */
static void test_pick(void)
{
    sw_scene scene = load_scene();
    sw_pick_hit hit;
    int hits = 0;
    double d[3] = {0, 0, 0}, eye[3] = {0, 0, 0};
    for (int view = SW_VIEW_ISO; view <= SW_VIEW_RIGHT; view++) {
        sw_camera cam;
        EXPECT_RESULT(sw_camera_fit(scene, (sw_view_preset)view, &cam, NULL), SW_OK);
        double back[3], scale = 0.0, off = 0.0;
        for (int k = 0; k < 3; k++) {
            eye[k] = cam.eye[k];
            d[k] = cam.target[k] - cam.eye[k];
            back[k] = -d[k];
            scale += fabs(d[k]);
        }
        EXPECT_RESULT(sw_scene_pick(scene, eye, d, &hit, NULL), SW_OK);
        for (int k = 0; hit.hit && k < 3; k++)
            off += fabs(eye[k] + hit.t * d[k] - hit.point[k]);
        EXPECT(!hit.hit || (hit.t > 0.0 && off < 1e-9 * scale));
        hits += hit.hit;
        EXPECT_RESULT(sw_scene_pick(scene, eye, back, &hit, NULL), SW_OK);
        EXPECT(!hit.hit);
    }
    EXPECT(hits > 0);
    double zero[3] = {0, 0, 0};
    EXPECT_RESULT(sw_scene_pick(scene, eye, zero, &hit, NULL), SW_ERR_INVALID_ARGUMENT);
    EXPECT_RESULT(sw_scene_pick(scene, NULL, d, &hit, NULL), SW_ERR_INVALID_ARGUMENT);
    EXPECT_RESULT(sw_scene_pick(scene, eye, d, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    EXPECT_RESULT(sw_scene_destroy(scene), SW_OK);
    EXPECT_RESULT(sw_scene_pick(scene, eye, d, &hit, NULL), SW_ERR_STALE_HANDLE);
}

static void test_strings(void)
{
    EXPECT(strcmp(sw_result_id_str((sw_result)SW_RESULT_COUNT), "SW_RESULT_UNKNOWN") == 0);
    EXPECT(sw_result_str((sw_result)-1) != NULL && sw_result_str((sw_result)999) != NULL);
    for (int r = 0; r < SW_RESULT_COUNT; r++) {
        EXPECT(strncmp(sw_result_id_str((sw_result)r), "SW_", 3) == 0);
        for (int q = 0; q < r; q++)
            EXPECT(strcmp(sw_result_id_str((sw_result)r), sw_result_id_str((sw_result)q)) != 0);
    }
    EXPECT(strcmp(sw_surface_kind_name(100000u), "unknown") == 0);
}

/* A scene destroyed by one thread while another saves it in a loop: each save completes (OK) or
 * finds the handle stale, never touches freed memory (ASan), and every file written is whole. */
typedef struct saver {
    sw_scene scene;
    char path[4096];
    atomic_int started;
    int saves_ok, other_result;
} saver;

static void *save_until_stale(void *arg)
{
    saver *s = arg;
    /* release: pairs with the main thread's acquire load; nothing else is published here. */
    atomic_store_explicit(&s->started, 1, memory_order_release);
    for (;;) {
        sw_result r = sw_scene_save(s->scene, s->path, NULL);
        if (r == SW_OK) {
            s->saves_ok++;
            continue;
        }
        if (r != SW_ERR_STALE_HANDLE)
            s->other_result = 1 + (int)r;
        return NULL;
    }
}

/* One race: returns how many saves completed before the handle went stale. */
static int destroy_while_saving_once(void)
{
    saver s = {.scene = load_scene()};
    sw_scene_info before;
    EXPECT_RESULT(sw_scene_get_info(s.scene, &before, NULL), SW_OK);
    work_path(s.path, sizeof s.path, "saved_while_destroyed.sws");
    remove(s.path);
    pthread_t thread;
    EXPECT(pthread_create(&thread, NULL, save_until_stale, &s) == 0);
    while (!atomic_load_explicit(&s.started, memory_order_acquire))
        sched_yield();
    EXPECT_RESULT(sw_scene_destroy(s.scene), SW_OK);
    pthread_join(thread, NULL);
    EXPECT(s.other_result == 0);
    if (s.saves_ok > 0) {
        sw_scene_load_desc desc = {s.path, NULL, NULL, NULL, NULL, 0};
        sw_scene copy;
        sw_scene_info after;
        EXPECT_RESULT(sw_scene_load(&desc, &copy, NULL), SW_OK);
        EXPECT_RESULT(sw_scene_get_info(copy, &after, NULL), SW_OK);
        EXPECT(after.faces == before.faces && after.control_points == before.control_points);
        sw_scene_destroy(copy);
    }
    return s.saves_ok;
}

/* The destroy lands at a different point of a save in each round (no timing is asserted). */
static void test_destroy_while_saving(void)
{
    enum { ROUNDS = 100 };
    int rounds_with_save = 0, saves = 0;
    for (int i = 0; i < ROUNDS; i++) {
        int n = destroy_while_saving_once();
        saves += n;
        rounds_with_save += n > 0;
    }
    printf("destroy while saving: %d rounds, %d with a save completed before the handle went "
           "stale (%d saves)\n",
           ROUNDS, rounds_with_save, saves);
}

/* ---- renderers (EGL) --------------------------------------------------------------------------
 */
static sw_frame_desc small_frame(sw_scene scene)
{
    sw_frame_desc frame = {0};
    frame.scene = scene;
    frame.width = 96;
    frame.height = 64;
    return frame;
}

/* A bad frame desc fails with `want` and writes no file. */
static void expect_bad_frame(sw_renderer r, sw_frame_desc frame, sw_result want, int line)
{
    char path[4096];
    work_path(path, sizeof path, "bad_frame.png");
    frame.output_path = path;
    sw_status status = {0};
    sw_test_expect_result(sw_renderer_draw(r, &frame, NULL, &status), want, "draw (bad frame)",
                          line);
    if (status.result != want || status.message[0] == '\0') {
        fprintf(stderr, "line %d: status holds %s '%s'\n", line, sw_result_id_str(status.result),
                status.message);
        g_failures++;
    }
    if (file_exists(path)) {
        fprintf(stderr, "line %d: a failed draw wrote %s\n", line, path);
        g_failures++;
        remove(path);
    }
}

static void test_bad_frames(sw_renderer r, sw_scene scene)
{
    sw_status status = {0};
    EXPECT_RESULT(sw_renderer_draw(r, NULL, NULL, &status), SW_ERR_INVALID_ARGUMENT);
    sw_frame_desc good = small_frame(scene);
    EXPECT_RESULT(sw_camera_fit(scene, SW_VIEW_FRONT, &good.camera, NULL), SW_OK);
    sw_frame_desc f = good;
    f.scene = (sw_scene){0};
    expect_bad_frame(r, f, SW_ERR_STALE_HANDLE, __LINE__);
    f = good;
    f.width = -1;
    expect_bad_frame(r, f, SW_ERR_INVALID_ARGUMENT, __LINE__);
    f = good;
    f.height = 16385;
    expect_bad_frame(r, f, SW_ERR_INVALID_ARGUMENT, __LINE__);
    f = good;
    f.error_px = NAN;
    expect_bad_frame(r, f, SW_ERR_INVALID_ARGUMENT, __LINE__);
    f.error_px = -0.5;
    expect_bad_frame(r, f, SW_ERR_INVALID_ARGUMENT, __LINE__);
    f = good;
    f.camera.fovy_deg = 180.0;
    expect_bad_frame(r, f, SW_ERR_INVALID_ARGUMENT, __LINE__);
    f = good;
    f.camera.eye[1] = INFINITY;
    expect_bad_frame(r, f, SW_ERR_INVALID_ARGUMENT, __LINE__);
    f = good;
    memcpy(f.camera.eye, f.camera.target, sizeof f.camera.eye); /* eye == target */
    expect_bad_frame(r, f, SW_ERR_INVALID_ARGUMENT, __LINE__);
    f = good;
    for (int k = 0; k < 3; k++) /* up along the view direction */
        f.camera.up[k] = f.camera.target[k] - f.camera.eye[k];
    expect_bad_frame(r, f, SW_ERR_INVALID_ARGUMENT, __LINE__);
    f = good;
    memset(f.camera.up, 0, sizeof f.camera.up);
    expect_bad_frame(r, f, SW_ERR_INVALID_ARGUMENT, __LINE__);

    char jpg[4096];
    work_path(jpg, sizeof jpg, "frame.jpg");
    f = good;
    f.output_path = jpg;
    EXPECT_RESULT(sw_renderer_draw(r, &f, NULL, NULL), SW_ERR_UNSUPPORTED);
    EXPECT(!file_exists(jpg));
}

/* A zero camera is the iso preset fitted to the scene (zero = default): the same frame. */
static void test_zero_camera(sw_renderer r, sw_scene scene)
{
    sw_frame_desc zero = small_frame(scene), iso = small_frame(scene);
    EXPECT_RESULT(sw_camera_fit(scene, SW_VIEW_ISO, &iso.camera, NULL), SW_OK);
    sw_frame_stats a, b;
    EXPECT_RESULT(sw_renderer_draw(r, &zero, &a, NULL), SW_OK);
    EXPECT_RESULT(sw_renderer_draw(r, &iso, &b, NULL), SW_OK);
    EXPECT(a.triangles > 0 && a.triangles == b.triangles && a.faces_drawn == b.faces_drawn);
}

typedef struct intruder {
    sw_renderer renderer;
    sw_frame_desc frame;
    sw_result draw, destroy;
    const char *description;
} intruder;

static void *use_from_other_thread(void *arg)
{
    intruder *t = arg;
    sw_status status = {0};
    t->draw = sw_renderer_draw(t->renderer, &t->frame, NULL, &status);
    t->destroy = sw_renderer_destroy(t->renderer);
    t->description = sw_renderer_description_ptr(t->renderer);
    return NULL;
}

static void test_wrong_thread(sw_renderer r, sw_scene scene)
{
    intruder t = {.renderer = r, .frame = small_frame(scene)};
    pthread_t thread;
    EXPECT(pthread_create(&thread, NULL, use_from_other_thread, &t) == 0);
    pthread_join(thread, NULL);
    EXPECT_RESULT(t.draw, SW_ERR_INVALID_ARGUMENT);
    EXPECT_RESULT(t.destroy, SW_ERR_INVALID_ARGUMENT);
    EXPECT(t.description && t.description[0] == '\0');
    /* The owner's renderer survived both calls. */
    sw_frame_stats stats;
    EXPECT_RESULT(sw_renderer_draw(r, &t.frame, &stats, NULL), SW_OK);
    EXPECT(stats.triangles > 0);
}

/* A thread with its own renderer draws beside the main thread's (each owns one GL context). */
static void *draw_with_own_renderer(void *arg)
{
    intruder *t = arg;
    t->draw = sw_renderer_create(NULL, &t->renderer, NULL);
    if (t->draw == SW_OK)
        t->draw = sw_renderer_draw(t->renderer, &t->frame, NULL, NULL);
    t->destroy = sw_renderer_destroy(t->renderer);
    return NULL;
}

static void test_second_thread_renderer(sw_scene scene)
{
    intruder t = {.frame = small_frame(scene)};
    pthread_t thread;
    EXPECT(pthread_create(&thread, NULL, draw_with_own_renderer, &t) == 0);
    pthread_join(thread, NULL);
    EXPECT_RESULT(t.draw, SW_OK);
    EXPECT_RESULT(t.destroy, SW_OK);
}

/* The scene destroyed by another thread while the owner draws it in a loop. */
typedef struct destroyer {
    sw_scene scene;
    atomic_int go;
    sw_result result;
} destroyer;

static void *destroy_when_told(void *arg)
{
    destroyer *d = arg;
    /* acquire: pairs with the drawing thread's release store after its first draw began. */
    while (!atomic_load_explicit(&d->go, memory_order_acquire))
        sched_yield();
    d->result = sw_scene_destroy(d->scene);
    return NULL;
}

/* One race: returns how many draws completed before the scene went stale. */
static int destroy_while_drawing_once(sw_renderer r)
{
    destroyer d = {.scene = load_scene()};
    pthread_t thread;
    EXPECT(pthread_create(&thread, NULL, destroy_when_told, &d) == 0);
    sw_frame_desc frame = small_frame(d.scene);
    int draws_ok = 0;
    sw_result res;
    for (;;) {
        atomic_store_explicit(&d.go, 1, memory_order_release);
        res = sw_renderer_draw(r, &frame, NULL, NULL);
        if (res != SW_OK)
            break;
        draws_ok++;
    }
    pthread_join(thread, NULL);
    EXPECT_RESULT(res, SW_ERR_STALE_HANDLE);
    EXPECT_RESULT(d.result, SW_OK);
    return draws_ok;
}

static void test_destroy_while_drawing(sw_renderer r)
{
    enum { ROUNDS = 10 };
    int draws = 0;
    for (int i = 0; i < ROUNDS; i++)
        draws += destroy_while_drawing_once(r);
    printf("destroy while drawing: %d rounds, %d draws completed before the scene went stale\n",
           ROUNDS, draws);
}

/* A walkthrough frame returns while the renderer's workers may still build hierarchies from the
 * scene (a model of a few hundred faces keeps them busy for tens of milliseconds); destroying the
 * scene right after must not free it under them (ASan), and the next frame, of another scene,
 * lets it go. */
static void test_destroy_after_walkthrough(sw_renderer r)
{
    sw_scene_load_desc desc = {g_big_scene_path, NULL, NULL, NULL, NULL, 0};
    sw_scene big;
    sw_status status = {0};
    EXPECT_RESULT(sw_scene_load(&desc, &big, &status), SW_OK);
    sw_frame_desc frame = small_frame(big);
    frame.walkthrough = 1;
    sw_frame_stats stats;
    EXPECT_RESULT(sw_renderer_draw(r, &frame, &stats, NULL), SW_OK);
    EXPECT_RESULT(sw_scene_destroy(big), SW_OK);
    EXPECT_RESULT(sw_renderer_draw(r, &frame, NULL, NULL), SW_ERR_STALE_HANDLE);
    printf("walkthrough frame: %llu fallback draws requested from the pool\n",
           (unsigned long long)stats.fallback_draws);
    sw_scene small = load_scene();
    sw_frame_desc next = small_frame(small);
    EXPECT_RESULT(sw_renderer_draw(r, &next, NULL, NULL), SW_OK);
    EXPECT_RESULT(sw_scene_destroy(small), SW_OK);
}

static void test_renderer(void)
{
    sw_renderer r = {77};
    sw_renderer_desc too_many = {.worker_threads = 1025};
    EXPECT_RESULT(sw_renderer_create(&too_many, &r, NULL), SW_ERR_INVALID_ARGUMENT);
    EXPECT(r.id == 0);
    EXPECT_RESULT(sw_renderer_create(NULL, NULL, NULL), SW_ERR_INVALID_ARGUMENT);
    /* No GL context is current on this thread yet: adopting one must fail cleanly. */
    sw_renderer_desc adopt = {.use_current_context = 1};
    EXPECT_RESULT(sw_renderer_create(&adopt, &r, NULL), SW_ERR_NO_CONTEXT);
    EXPECT(r.id == 0);
    sw_status status = {0};
    if (sw_renderer_create(NULL, &r, &status) != SW_OK) {
        fprintf(stderr, "no renderer: %s\n", status.message);
        g_failures++;
        return;
    }
    EXPECT(sw_renderer_description_ptr(r)[0] != '\0');
    sw_scene scene = load_scene();
    test_bad_frames(r, scene);
    test_zero_camera(r, scene);
    test_wrong_thread(r, scene);
    test_second_thread_renderer(scene);
    test_destroy_while_drawing(r);
    test_destroy_after_walkthrough(r);

    sw_frame_desc frame = small_frame(scene);
    EXPECT_RESULT(sw_renderer_destroy(r), SW_OK);
    EXPECT_RESULT(sw_renderer_destroy(r), SW_ERR_STALE_HANDLE);
    EXPECT_RESULT(sw_renderer_draw(r, &frame, NULL, NULL), SW_ERR_STALE_HANDLE);
    EXPECT(sw_renderer_description_ptr(r)[0] == '\0');
    /* The slot is reused; the old handle stays stale and the new renderer works. */
    sw_renderer again;
    EXPECT_RESULT(sw_renderer_create(NULL, &again, NULL), SW_OK);
    EXPECT(again.id != r.id);
    EXPECT_RESULT(sw_renderer_destroy(r), SW_ERR_STALE_HANDLE);
    EXPECT_RESULT(sw_renderer_draw(again, &frame, NULL, NULL), SW_OK);
    EXPECT_RESULT(sw_renderer_destroy(again), SW_OK);
    EXPECT_RESULT(sw_scene_destroy(scene), SW_OK);
}

/* The core alone (no module installed in this mode) reads no CAD file: a clear refusal naming the
 * module, not a crash or "not found". A core that still linked an importer would load it. */
static void test_core_without_modules(void)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/no_importer.brep", g_work);
    FILE *f = fopen(path, "w");
    EXPECT(f != NULL);
    if (f)
        fclose(f);
    sw_scene_load_desc ld = {path, NULL, NULL, NULL, NULL, 0};
    sw_scene scene = {0};
    sw_status st = {0};
    EXPECT_RESULT(sw_scene_load(&ld, &scene, &st), SW_ERR_UNSUPPORTED);
    EXPECT(strstr(st.message, "import module") != NULL);
    EXPECT(scene.id == 0);
}

/* ---- the core without the LOD builder ---------------------------------------------------------
 * Only the levels a .sws stores are drawn: the scene with a LOD cache (`splinewalk build-lod`)
 * draws super-surfaces from it, the same scene without one draws every face per frame. A core
 * that still built levels itself would draw static levels for the second; one that ignored the
 * cache would draw none for the first. */
static uint64_t static_draws_of(const char *path)
{
    sw_scene_load_desc ld = {path, NULL, NULL, NULL, NULL, 0};
    sw_scene scene = {0};
    sw_renderer r = {0};
    sw_camera c;
    sw_status st = {0};
    sw_frame_stats fs = {0};
    EXPECT_RESULT(sw_scene_load(&ld, &scene, &st), SW_OK);
    EXPECT_RESULT(sw_camera_fit(scene, SW_VIEW_ISO, &c, NULL), SW_OK);
    for (int k = 0; k < 3; ++k) /* far out: whole super-surfaces at coarse levels */
        c.eye[k] = c.target[k] + 8.0 * (c.eye[k] - c.target[k]);
    EXPECT_RESULT(sw_renderer_create(NULL, &r, &st), SW_OK);
    sw_frame_desc f = {0};
    f.scene = scene;
    f.camera = c;
    f.width = 320;
    f.height = 240;
    f.static_lods = 1; /* converged: waits for the clustering and any build it asks for */
    EXPECT_RESULT(sw_renderer_draw(r, &f, &fs, &st), SW_OK);
    EXPECT(fs.triangles > 0);
    EXPECT_RESULT(sw_renderer_destroy(r), SW_OK);
    EXPECT_RESULT(sw_scene_destroy(scene), SW_OK);
    return fs.static_drawn;
}

static void test_core_lods(const char *cached, const char *bare)
{
    const uint64_t with_cache = static_draws_of(cached), without = static_draws_of(bare);
    printf("core without the LOD builder: %llu super-surfaces drawn from the LOD cache, %llu "
           "without one\n",
           (unsigned long long)with_cache, (unsigned long long)without);
    EXPECT(with_cache > 0);
    EXPECT(without == 0);
}

int main(int argc, char **argv)
{
    int handles = argc == 4 && !strcmp(argv[1], "handles");
    int renderer = argc == 5 && !strcmp(argv[1], "renderer");
    int core_lods = argc == 4 && !strcmp(argv[1], "core_lods");
    if (renderer) /* the other modes run the core alone */
        (void)sw_import_install(), (void)sw_lod_build_install();
    if (!handles && !renderer && !core_lods) {
        fprintf(stderr, "usage: test_api handles SCENE WORKDIR\n"
                        "       test_api renderer SCENE WORKDIR BIG_SCENE\n"
                        "       test_api core_lods SCENE_WITH_LOD_CACHE.sws SCENE_WITHOUT.sws\n");
        return 2;
    }
    if (core_lods) {
        test_core_lods(argv[2], argv[3]);
        if (g_failures)
            fprintf(stderr, "%d failures\n", g_failures);
        return g_failures != 0;
    }
    g_scene_path = argv[2];
    g_work = argv[3];
    g_big_scene_path = renderer ? argv[4] : NULL;
    if (!strcmp(argv[1], "handles")) {
        test_core_without_modules();
        test_null_arguments();
        test_stale_and_double_destroy();
        test_strings();
        test_pick();
        test_destroy_while_saving();
    } else {
        test_renderer();
    }
    if (g_failures) {
        fprintf(stderr, "%d failures\n", g_failures);
        return 1;
    }
    printf("all %s checks passed\n", argv[1]);
    return 0;
}
