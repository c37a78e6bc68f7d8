/* SPDX-License-Identifier: MIT */
/* bench_scaling: how splinewalk's frame time and memory grow with the scene — generated
 * buildings of N = 10^3, 10^4, 10^5 (10^6 with --max) surfaces, each drawn along the orbit of its
 * own box (the same relative path: the view composition stays, the detail grows; --fly: the low
 * fly-through instead), each in its own
 * child process. The claim to test (ARCHITECTURE.md, "Scale"): cost grows with what is visible at
 * the required detail, not with the model's size. See k_usage.
 */
#define _GNU_SOURCE
#include "cli_numbers.h"
#include "cli.h"
#include "bench_peer.h"
#include "peer_splinewalk.h"
#include "scaling_svg.h"

#include <errno.h>
#include <libgen.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static const char k_usage[] =
    "usage: bench_scaling [options]\n"
    "\n"
    "Generates buildings (--vehicle: car parks) of N surfaces (`splinewalk generate building|\n"
    "vehicle --surfaces N`, seed 1; kept in DIR as building-N.sws or vehicle-N.sws and reused\n"
    "when present) for N = MIN, 10 MIN, ... up to MAX, and renders each with splinewalk (public\n"
    "API, threaded, walkthrough, as bench_peers) along the orbit of its own box (`splinewalk path\n"
    "orbit`: the same view composition at every N), each N in its own child process. Prints\n"
    "per N: face occurrences, the scene's own bytes (sw_scene_info.memory_bytes), median and\n"
    "p99 frame time (the interval between frames' completions: each submit waits for the frame\n"
    "before; no readback; warm-up passes not counted), time to first frame (load + renderer +\n"
    "first frame), peak RSS (the child's VmHWM minus its resident memory at the fork) and\n"
    "triangles per frame (median).\n"
    "Set LP_NUM_THREADS and EGL_PLATFORM=surfaceless yourself: the header line echoes them.\n"
    "\n"
    "options:\n"
    "  --min N          smallest scene (default 1000; at least 100)\n"
    "  --max N          largest scene (default 100000; 1000000 takes minutes and GBs)\n"
    "  --frames N       frames along the path per pass (default 120)\n"
    "  --warmup W       uncounted passes first (default 1)\n"
    "  --passes P       counted passes (default 1)\n"
    "  --size WxH       frame size (default 1280x720)\n"
    "  --error PX       eps_img in pixels (default 0.5)\n"
    "  --fly            the low fly-through `splinewalk path fly` makes for each box instead of\n"
    "                   the orbit (what is visible then grows less than the scene)\n"
    "  --walk           the walk `splinewalk path walk` makes (eye height 160, through the\n"
    "                   ground floor's rooms) instead of the orbit\n"
    "  --no-occlusion   without occlusion culling (default: on, as in the CLI)\n"
    "  --no-exact-edges with trim textures only (default: exact trim edges, as in the CLI)\n"
    "  --static-lods    draw far super-surfaces from static LODs, prebuilt: a scene without a\n"
    "                   LOD cache gets one first (`splinewalk build-lod`, timed and printed)\n"
    "  --no-proxies     with static LODs: no cluster proxies (default: far groups of\n"
    "                   super-surface instances drawn as one merged mesh within the bound)\n"
    "  --cold           a cold start: static LODs on but none prebuilt (scenes with a LOD cache\n"
    "                   are refused), built in the pool as the walk needs them; no warm-up; also\n"
    "                   prints when 10 consecutive frames' median first fell to --target\n"
    "  --target MS      the frame time a cold start settles at (default 100)\n"
    "  --vehicle        vehicle car parks (`splinewalk generate vehicle`) instead of buildings\n"
    "  --dir DIR        where the scenes are generated (default bench-scaling-scenes)\n"
    "  --splinewalk B   the CLI that generates them (default: splinewalk beside this program)\n"
    "  --csv FILE       the rows as CSV (default: none; written aside, then renamed)\n"
    "  --svg FILE       the plot: log-x N, frame time and memory (default: none)\n"
    "  -h, --help       this text\n";

typedef struct args {
    uint64_t min_n, max_n;
    uint32_t frames, warmup, passes;
    int32_t w, h;
    double error_px;
    const char *dir, *csv, *svg;
    int fly; /* bp_job.fly: 0 orbit, 1 fly-through, 2 walk */
    int no_occlusion, no_exact_edges, static_lods, no_proxies;
    int cold;         /* static LODs built as the walk needs them, no warm-up */
    double target_ms; /* the frame time a cold start settles at */
    const char *kind; /* what `splinewalk generate` makes: "building" or "vehicle" */
    char splinewalk[PATH_MAX];
} args;

static const char *path_name(int fly)
{
    return fly == 2 ? "walk" : fly ? "fly-through" : "orbit";
}

static int parse(int argc, char **argv, args *a)
{
    *a = (args){.min_n = 1000,
                .max_n = 100000,
                .frames = 120,
                .warmup = 1,
                .passes = 1,
                .w = 1280,
                .h = 720,
                .error_px = 0.5,
                .target_ms = 100.0,
                .kind = "building",
                .dir = "bench-scaling-scenes"};
    for (int i = 1; i < argc; ++i) {
        const char *o = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(o, "-h") || !strcmp(o, "--help"))
            return 1;
        if (!strcmp(o, "--fly") || !strcmp(o, "--walk")) {
            a->fly = !strcmp(o, "--fly") ? 1 : 2;
            continue;
        }
        if (!strcmp(o, "--no-occlusion")) {
            a->no_occlusion = 1;
            continue;
        }
        if (!strcmp(o, "--no-exact-edges")) {
            a->no_exact_edges = 1;
            continue;
        }
        if (!strcmp(o, "--static-lods")) {
            a->static_lods = 1;
            continue;
        }
        if (!strcmp(o, "--no-proxies")) {
            a->no_proxies = 1;
            continue;
        }
        if (!strcmp(o, "--cold")) {
            a->cold = a->static_lods = 1;
            continue;
        }
        if (!strcmp(o, "--vehicle")) {
            a->kind = "vehicle";
            continue;
        }
        if (!v)
            return -1;
        ++i;
        if (!strcmp(o, "--min"))
            a->min_n = strtoull(v, NULL, 10);
        else if (!strcmp(o, "--max"))
            a->max_n = strtoull(v, NULL, 10);
        else if (!strcmp(o, "--frames"))
            a->frames = (uint32_t)strtoul(v, NULL, 10);
        else if (!strcmp(o, "--warmup"))
            a->warmup = (uint32_t)strtoul(v, NULL, 10);
        else if (!strcmp(o, "--passes"))
            a->passes = (uint32_t)strtoul(v, NULL, 10);
        else if (!strcmp(o, "--size") && !sw_cli_parse_size(v, &a->w, &a->h))
            continue;
        else if (!strcmp(o, "--error") && !sw_cli_parse_error_px(v, &a->error_px))
            continue;
        else if (!strcmp(o, "--target"))
            a->target_ms = strtod(v, NULL);
        else if (!strcmp(o, "--dir"))
            a->dir = v;
        else if (!strcmp(o, "--splinewalk"))
            snprintf(a->splinewalk, sizeof a->splinewalk, "%s", v);
        else if (!strcmp(o, "--csv"))
            a->csv = v;
        else if (!strcmp(o, "--svg"))
            a->svg = v;
        else
            return -1;
    }
    return a->min_n >= 100 && a->max_n >= a->min_n && a->max_n <= 10000000 && a->frames >= 2 &&
                   a->frames <= 100000 && a->passes >= 1 && a->passes <= 100 && a->warmup <= 100 &&
                   a->w > 0 && a->h > 0 && a->w <= 16384 && a->h <= 16384 && a->error_px > 0.0 &&
                   isfinite(a->error_px) && a->target_ms > 0.0 && isfinite(a->target_ms)
               ? 0
               : -1;
}

/* splinewalk beside /proc/self/exe (both land in build/bin). */
static int default_cli(char *out, size_t size)
{
    char self[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0)
        return -1;
    self[n] = '\0';
    return snprintf(out, size, "%s/splinewalk", dirname(self)) < (int)size ? 0 : -1;
}

/* Runs the CLI with argv (its report to stderr: it must not break the table). Returns 0 or -1. */
static int run_cli(char *const argv[])
{
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        dup2(STDERR_FILENO, STDOUT_FILENO);
        execv(argv[0], argv);
        fprintf(stderr, "bench_scaling: %s: %s\n", argv[0], strerror(errno));
        _exit(127);
    }
    int status = 0;
    return pid < 0 || waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) ? -1
                                                                                                : 0;
}

/* DIR/KIND-N.sws, generated by the CLI unless it exists. Returns 0 or -1 (message printed). */
static int scene_for(const args *a, uint64_t n, char *path, size_t size)
{
    snprintf(path, size, "%s/%s-%llu.sws", a->dir, a->kind, (unsigned long long)n);
    if (access(path, R_OK) == 0)
        return 0;
    if (mkdir(a->dir, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "bench_scaling: %s: %s\n", a->dir, strerror(errno));
        return -1;
    }
    char count[32];
    snprintf(count, sizeof count, "%llu", (unsigned long long)n);
    fprintf(stderr, "bench_scaling: generating %s\n", path);
    char *const argv[] = {(char *)a->splinewalk,
                          "generate",
                          (char *)a->kind,
                          "--surfaces",
                          count,
                          "--seed",
                          "1",
                          "-o",
                          path,
                          NULL};
    if (run_cli(argv) != 0) {
        fprintf(stderr, "bench_scaling: `%s generate %s --surfaces %s -o %s` failed\n",
                a->splinewalk, a->kind, count, path);
        return -1;
    }
    return 0;
}

/* 1 when the scene file brings a LOD cache, 0 when not, -1 when it cannot be read. */
static int has_lod_cache(const char *path)
{
    sw_scene scene = {0};
    sw_scene_info info;
    sw_status st = {0};
    const sw_scene_load_desc d = {.path = path};
    if (sw_scene_load(&d, &scene, &st) != SW_OK) {
        fprintf(stderr, "bench_scaling: %s: %s\n", path, st.message);
        return -1;
    }
    const int ok = sw_scene_get_info(scene, &info, &st) == SW_OK;
    sw_scene_destroy(scene);
    return ok ? info.lod_cache_bytes > 0 : -1;
}

/* The scene's LOD cache, built in place by `splinewalk build-lod` unless it has one; *seconds is
 * the build's wall time (0 when there was one). A cold start needs a scene without one. Returns
 * 0 or -1 (message printed). */
static int lods_for(const args *a, const char *path, double *seconds)
{
    *seconds = 0.0;
    const int has = has_lod_cache(path);
    if (a->cold) {
        if (has > 0)
            fprintf(stderr,
                    "bench_scaling: %s has a LOD cache: a cold start needs scenes without one "
                    "(another --dir)\n",
                    path);
        return has == 0 ? 0 : -1;
    }
    if (has != 0)
        return has > 0 ? 0 : -1;
    fprintf(stderr, "bench_scaling: build-lod %s\n", path);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    char *const argv[] = {(char *)a->splinewalk, "build-lod", (char *)path, NULL};
    if (run_cli(argv) != 0) {
        fprintf(stderr, "bench_scaling: `%s build-lod %s` failed\n", a->splinewalk, path);
        return -1;
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    *seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    return 0;
}

static const char k_csv_header[] =
    "surfaces,face_occurrences,scene_bytes,width,height,error_px,frames,median_ms,p99_ms,"
    "first_frame_ms,peak_rss_bytes,triangles_per_frame,settle_ms\n";

/* Writes text through a temporary file renamed over `path`. */
static int write_csv(const char *path, const uint64_t *ns, const bp_result *r, uint32_t n,
                     const args *a)
{
    char tmp[PATH_MAX + 32];
    snprintf(tmp, sizeof tmp, "%s.tmp-%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    if (!f)
        return -1;
    fputs(k_csv_header, f);
    for (uint32_t i = 0; i < n; ++i)
        fprintf(f, "%llu,%llu,%.0f,%d,%d,%g,%u,%.4f,%.4f,%.2f,%.0f,%.0f,%.0f\n",
                (unsigned long long)ns[i], (unsigned long long)r[i].faces, r[i].scene_bytes, a->w,
                a->h, a->error_px, r[i].frames, r[i].median_ms, r[i].p99_ms, r[i].first_frame_ms,
                r[i].peak_rss_bytes, r[i].triangles, r[i].settle_ms);
    int bad = ferror(f) | fclose(f);
    if (bad || rename(tmp, path) != 0) {
        remove(tmp);
        return -1;
    }
    return 0;
}

static int write_svg(const char *path, const uint64_t *ns, const bp_result *r, uint32_t n,
                     const args *a)
{
    bs_point pts[16];
    for (uint32_t i = 0; i < n; ++i)
        pts[i] = (bs_point){(double)ns[i], r[i].median_ms, r[i].p99_ms,
                            r[i].peak_rss_bytes / 1048576.0, r[i].scene_bytes / 1048576.0};
    char title[256], tmp[PATH_MAX + 32];
    snprintf(title, sizeof title,
             "splinewalk: generated %ss, %s of each box, %dx%d, eps %g px, threaded "
             "walkthrough",
             a->kind, path_name(a->fly), a->w, a->h, a->error_px);
    snprintf(tmp, sizeof tmp, "%s.tmp-%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    if (!f)
        return -1;
    int bad = bs_write_svg(f, pts, n, title) | ferror(f) | fclose(f);
    if (bad || rename(tmp, path) != 0) {
        remove(tmp);
        return -1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    sw_cli_install_modules(); /* CAD files, .exr, static LOD builds */
    args a;
    int pr = parse(argc, argv, &a);
    if (pr != 0) {
        fputs(k_usage, pr > 0 ? stdout : stderr);
        return pr > 0 ? 0 : 2;
    }
    if (!a.splinewalk[0] && default_cli(a.splinewalk, sizeof a.splinewalk) != 0) {
        fprintf(stderr,
                "bench_scaling: cannot find splinewalk beside this program; --splinewalk\n");
        return 1;
    }
    const char *lp = getenv("LP_NUM_THREADS"), *egl = getenv("EGL_PLATFORM");
    if (a.cold)
        a.warmup = 0; /* the first frame of all is the walk's */
    printf("bench_scaling: generated %ss, %s of each box, %dx%d, eps_img %g px, occlusion culling "
           "%s, exact trim edges %s, static LODs %s, %u frames x %u counted passes after %u "
           "warm-up, LP_NUM_THREADS=%s, EGL_PLATFORM=%s, %ld processors online\n",
           a.kind, path_name(a.fly), a.w, a.h, a.error_px, a.no_occlusion ? "off" : "on",
           a.no_exact_edges ? "off" : "on",
           a.cold ? "on (cold start: none prebuilt, built in the pool as the walk needs them)"
           : a.static_lods ? (a.no_proxies ? "on (prebuilt), no cluster proxies"
                                           : "on (prebuilt), cluster proxies")
                           : "off",
           a.frames, a.passes, a.warmup, lp ? lp : "(unset)", egl ? egl : "(unset)",
           sysconf(_SC_NPROCESSORS_ONLN));
    printf("  surfaces | occurrences | scene MB | frame ms: median     p99 | first (ms) | peak RSS "
           "MB | triangles\n");
    uint64_t ns[16];
    bp_result res[16];
    uint32_t n = 0;
    int rc = 0;
    for (uint64_t s = a.min_n; s <= a.max_n && n < 16; s *= 10) {
        char scene[PATH_MAX];
        double lod_s = 0.0;
        if (scene_for(&a, s, scene, sizeof scene) != 0 ||
            (a.static_lods && lods_for(&a, scene, &lod_s) != 0))
            return 1;
        if (lod_s > 0.0)
            printf("  %8llu   (build-lod: %.1f s)\n", (unsigned long long)s, lod_s);
        bp_job job = {.scene = scene,
                      .fly = a.fly,
                      .static_lods = a.static_lods,
                      .no_proxies = a.no_proxies,
                      .occlusion = !a.no_occlusion,
                      .exact_edges = !a.no_exact_edges,
                      .frames = a.frames,
                      .warmup_passes = a.warmup,
                      .passes = a.passes,
                      .width = a.w,
                      .height = a.h,
                      .error_px = a.error_px,
                      .settle_target_ms = a.cold ? a.target_ms : 0.0};
        if (bp_run_in_child(bp_peer_splinewalk, &job, &res[n]) != 0) {
            fprintf(stderr, "bench_scaling: %s: %s\n", scene, res[n].note);
            rc = 1;
            break;
        }
        const bp_result *r = &res[n];
        printf("  %8llu | %11llu | %8.2f | %15.2f %7.2f | %10.0f | %11.1f | %9.0f\n",
               (unsigned long long)s, (unsigned long long)r->faces, r->scene_bytes / 1048576.0,
               r->median_ms, r->p99_ms, r->first_frame_ms, r->peak_rss_bytes / 1048576.0,
               r->triangles);
        if (a.cold && r->settle_ms >= 0.0)
            printf("  %8llu   settled: %d frames' median <= %g ms %.1f s after the start\n",
                   (unsigned long long)s, (int)bp_settle_window, a.target_ms, 1e-3 * r->settle_ms);
        else if (a.cold)
            printf("  %8llu   not settled: no %d frames' median <= %g ms in the walk\n",
                   (unsigned long long)s, (int)bp_settle_window, a.target_ms);
        fflush(stdout);
        ns[n++] = s;
    }
    if (n > 1)
        printf(
            "  %llu / %llu surfaces: median frame time x%.2f, peak RSS x%.2f, scene bytes x%.2f\n",
            (unsigned long long)ns[n - 1], (unsigned long long)ns[0],
            res[n - 1].median_ms / res[0].median_ms,
            res[n - 1].peak_rss_bytes / res[0].peak_rss_bytes,
            res[n - 1].scene_bytes / res[0].scene_bytes);
    if (n > 0 && a.csv && write_csv(a.csv, ns, res, n, &a) != 0) {
        fprintf(stderr, "bench_scaling: %s: write failed\n", a.csv);
        rc = 1;
    }
    if (n > 0 && a.svg && write_svg(a.svg, ns, res, n, &a) != 0) {
        fprintf(stderr, "bench_scaling: %s: write failed\n", a.svg);
        rc = 1;
    }
    return rc;
}
