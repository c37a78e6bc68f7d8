/* SPDX-License-Identifier: MIT */
/* tests/api: a long walkthrough soak with live scene edits, against the shared library.
 *
 * usage: test_api_soak WORKDIR MODEL.brep FRAMES [--rss-flat PERCENT]
 *
 * A node scene holds the model (an IMPORT node), three instances of it and a wave-shaped NURBS
 * sheet. The camera orbits it in split walkthrough frames (sw_renderer_prepare on the visibility
 * thread, sw_renderer_submit here) at 160 x 120 while another thread edits the scene without a
 * pause: the sheet's control points, the instances' transforms, their visibility, and sheets
 * added and removed. Every 100 frames the process's resident memory (/proc/self/statm) goes to
 * WORKDIR/soak_rss.csv with the frame time.
 * Checked: every frame is prepared and submitted, none waits for the pool, every edit succeeds,
 * edits are published while frames run (the scene is really changing under them), and with
 * --rss-flat the resident memory after the warm-up (the first fifth of the frames, at least 200)
 * never exceeds the warm-up's highest sample (its first, before anything is cached, left out) by
 * more than PERCENT (a leak per frame or per edit, or a cache that grows with the versions
 * drawn, fails it: a planted leak of 4 KiB in each sw_node_set_nurbs gives +17.3 % over 1,000
 * frames). Against the warm-up's last sample alone it failed once unleaked: samples of a flat run
 * move by ~5 % (Motor-c, 3,000 frames: 164.7-174.9 MiB, no trend). Sanitizer builds leave
 * --rss-flat out: their allocators keep freed memory in quarantine. Run under TSan with few frames
 * in .ci/run's manner and at length by hand (docs/reliability.md).
 */
#include <splinewalk/splinewalk.h>
#include <splinewalk/sw_import.h>
#include <splinewalk/sw_lod_build.h>
#include <splinewalk/sw_nodes.h>

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

enum { SHEET_N = 6, EXTRA_SHEETS = 4, SAMPLE_EVERY = 100 };
static const double k_knots[SHEET_N + 4] = {0, 0, 0, 0, 1.0 / 3, 2.0 / 3, 1, 1, 1, 1};

static int g_failures;
#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__);                                   \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fputc('\n', stderr);                                                                   \
            g_failures++;                                                                          \
        }                                                                                          \
    } while (0)

/* A bicubic sheet over [0, 100]^2 (the model's scale) waving with `phase`. */
static sw_nurbs_desc sheet_desc(double phase, double *points)
{
    for (int j = 0; j < SHEET_N; j++)
        for (int i = 0; i < SHEET_N; i++) {
            double *p = points + 3 * (SHEET_N * j + i);
            p[0] = 100.0 * i / (SHEET_N - 1) - 50.0;
            p[1] = 100.0 * j / (SHEET_N - 1) - 50.0;
            p[2] = -60.0 + 10.0 * sin(phase + 1.3 * i) * cos(0.9 * j);
        }
    sw_nurbs_desc d = {0};
    d.degree_u = d.degree_v = 3;
    d.count_u = d.count_v = SHEET_N;
    d.knots_u = d.knots_v = k_knots;
    d.points = points;
    return d;
}

/* Rotation by `angle` about z, then a translation. */
static void placement(double angle, double dx, double dy, double m[12])
{
    const double c = cos(angle), s = sin(angle);
    const double t[12] = {c, -s, 0, dx, s, c, 0, dy, 0, 0, 1, 0};
    memcpy(m, t, sizeof t);
}

static double resident_mib(void)
{
    long pages = 0, resident = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (!f)
        return 0.0;
    if (fscanf(f, "%ld %ld", &pages, &resident) != 2)
        resident = 0;
    fclose(f);
    return (double)resident * (double)sysconf(_SC_PAGESIZE) / (1024.0 * 1024.0);
}

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return 1e3 * (double)t.tv_sec + 1e-6 * (double)t.tv_nsec;
}

typedef struct soak {
    sw_scene scene;
    sw_node sheet, model, instances[3];
    atomic_int stop, rounds, failed_edits;
} soak;

/* One round of edits: the sheet moves, one instance turns, one is shown or hidden, and a sheet
 * is added (the oldest removed once EXTRA_SHEETS are there). */
static int edit_round(soak *s, int k, sw_node extra[EXTRA_SHEETS])
{
    double pts[SHEET_N * SHEET_N * 3], m[12];
    sw_nurbs_desc nd = sheet_desc(0.05 * k, pts);
    int ok = sw_node_set_nurbs(s->scene, s->sheet, &nd, NULL) == SW_OK;
    placement(0.01 * k, 150.0 * ((k % 3) - 1), 150.0, m);
    ok &= sw_node_set_transform(s->scene, s->instances[k % 3], m, NULL) == SW_OK;
    ok &= sw_node_set_visible(s->scene, s->instances[(k + 1) % 3], k % 2, NULL) == SW_OK;
    sw_node *slot = &extra[k % EXTRA_SHEETS];
    if (slot->id)
        ok &= sw_node_remove(s->scene, *slot, NULL) == SW_OK;
    sw_node_desc g = {.kind = SW_NODE_NURBS, .nurbs = &nd};
    placement(0.0, 0.0, -150.0 - 20.0 * (k % 5), g.transform);
    ok &= sw_node_add(s->scene, &g, slot, NULL) == SW_OK;
    return ok;
}

static void *editor(void *arg)
{
    soak *s = arg;
    sw_node extra[EXTRA_SHEETS] = {{0}};
    for (int k = 0; !atomic_load(&s->stop); k++) {
        if (!edit_round(s, k, extra))
            atomic_fetch_add(&s->failed_edits, 1);
        atomic_fetch_add(&s->rounds, 1);
        nanosleep(&(struct timespec){0, 2000000}, NULL); /* about one round per frame */
    }
    return NULL;
}

static int build_scene(soak *s, const char *model)
{
    sw_status st = {0};
    double pts[SHEET_N * SHEET_N * 3];
    sw_nurbs_desc nd = sheet_desc(0.0, pts);
    sw_node_desc sheet = {.kind = SW_NODE_NURBS, .nurbs = &nd};
    sw_node_desc imp = {.kind = SW_NODE_IMPORT, .import_path = model, .detached = 1};
    if (sw_scene_create(NULL, &s->scene, &st) != SW_OK ||
        sw_node_add(s->scene, &sheet, &s->sheet, &st) != SW_OK ||
        sw_node_add(s->scene, &imp, &s->model, &st) != SW_OK) {
        fprintf(stderr, "scene: %s\n", st.message);
        return 0;
    }
    for (int i = 0; i < 3; i++) {
        sw_node_desc in = {.kind = SW_NODE_INSTANCE, .instance_of = s->model};
        placement(0.0, 150.0 * (i - 1), 0.0, in.transform);
        if (sw_node_add(s->scene, &in, &s->instances[i], &st) != SW_OK) {
            fprintf(stderr, "instance: %s\n", st.message);
            return 0;
        }
    }
    return sw_scene_flush(s->scene, &st) == SW_OK;
}

static sw_camera orbit_camera(int frame)
{
    const double a = 2.0 * M_PI * frame / 600.0;
    sw_camera c = {{350.0 * cos(a), 350.0 * sin(a), 200.0}, {0, 0, 0}, {0, 0, 1}, 45.0};
    return c;
}

int main(int argc, char **argv)
{
    (void)sw_import_install(), (void)sw_lod_build_install(); /* .brep scenes, static LODs */
    if (argc < 4) {
        fprintf(stderr, "usage: test_api_soak WORKDIR MODEL.brep FRAMES [--rss-flat PERCENT]\n");
        return 2;
    }
    const char *work = argv[1], *model = argv[2];
    const int frames = atoi(argv[3]);
    const double flat_pct = argc >= 6 && !strcmp(argv[4], "--rss-flat") ? atof(argv[5]) : -1.0;
    soak s = {0};
    sw_renderer r;
    sw_status st = {0};
    sw_renderer_desc rd = {.worker_threads = 2};
    if (frames < 1 || !build_scene(&s, model) || sw_renderer_create(&rd, &r, &st) != SW_OK) {
        fprintf(stderr, "set-up failed: %s\n", st.message);
        return 1;
    }
    char csv_path[1024];
    snprintf(csv_path, sizeof csv_path, "%s/soak_rss.csv", work);
    FILE *csv = fopen(csv_path, "w");
    if (!csv) {
        fprintf(stderr, "cannot write %s\n", csv_path);
        return 1;
    }
    fprintf(csv, "frame,rss_mib,frame_ms\n");
    pthread_t t;
    if (pthread_create(&t, NULL, editor, &s) != 0)
        return 1;
    const int warmup = frames / 5 > 200 ? frames / 5 : 200;
    double rss_warm = 0.0, rss_max_after = 0.0, t_last = now_ms();
    uint64_t waits = 0, published_first = 0, published_last = 0;
    int prepared = 0, submitted = 0;
    for (int k = 0; k < frames; k++) {
        sw_frame_desc f = {.scene = s.scene,
                           .camera = orbit_camera(k),
                           .width = 160,
                           .height = 120,
                           .walkthrough = 1};
        prepared += sw_renderer_prepare(r, &f, &st) == SW_OK;
        sw_frame_stats fs = {0};
        if (k > 0) { /* frame k - 1, drawn while V prepares frame k */
            submitted += sw_renderer_submit(r, &fs, &st) == SW_OK;
            waits += fs.pool_waits;
        }
        sw_scene_revisions rev;
        if (sw_scene_get_revisions(s.scene, &rev, NULL) == SW_OK) {
            if (k == 0)
                published_first = rev.published;
            published_last = rev.published;
        }
        if (k % SAMPLE_EVERY == 0 || k == frames - 1) {
            const double rss = resident_mib(), t_now = now_ms();
            fprintf(csv, "%d,%.1f,%.2f\n", k, rss, (t_now - t_last) / SAMPLE_EVERY);
            fflush(csv); /* the curve so far, for a run watched or cut short */
            t_last = t_now;
            if (k <= warmup) {
                if (k > 0 && rss > rss_warm) /* the warm-up's peak: one sample moves by ~5 % */
                    rss_warm = rss;
            } else if (rss > rss_max_after)
                rss_max_after = rss;
        }
    }
    sw_frame_stats fs = {0};
    submitted += sw_renderer_submit(r, &fs, &st) == SW_OK;
    atomic_store(&s.stop, 1);
    pthread_join(t, NULL);
    fclose(csv);
    CHECK(prepared == frames && submitted == frames, "%d of %d frames prepared, %d submitted: %s",
          prepared, frames, submitted, st.message);
    CHECK(waits == 0, "walkthrough frames waited for the pool %llu times",
          (unsigned long long)waits);
    CHECK(atomic_load(&s.failed_edits) == 0, "%d of %d edit rounds failed",
          atomic_load(&s.failed_edits), atomic_load(&s.rounds));
    CHECK(published_last > published_first + (uint64_t)frames / 10,
          "only %llu versions published during %d frames: the scene did not change under them",
          (unsigned long long)(published_last - published_first), frames);
    const int after = frames > warmup + SAMPLE_EVERY; /* samples after the warm-up */
    const double growth = after && rss_warm > 0.0 ? 100.0 * (rss_max_after / rss_warm - 1.0) : 0.0;
    if (flat_pct >= 0.0 && after)
        CHECK(growth <= flat_pct,
              "resident memory grew %.1f %% after the warm-up (%.1f -> %.1f MiB), limit %.1f %%",
              growth, rss_warm, rss_max_after, flat_pct);
    printf("soak: %d frames, %d edit rounds beside them, %llu versions published, pool waits "
           "%llu; resident %.1f MiB after %d warm-up frames",
           frames, atomic_load(&s.rounds), (unsigned long long)(published_last - published_first),
           (unsigned long long)waits, rss_warm, warmup);
    if (after)
        printf(", at most %.1f MiB after (%+.1f %%)", rss_max_after, growth);
    printf("; %s\n", csv_path);
    sw_renderer_destroy(r);
    sw_scene_destroy(s.scene);
    return g_failures ? 1 : 0;
}
