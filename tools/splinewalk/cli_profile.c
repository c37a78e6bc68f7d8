/* SPDX-License-Identifier: MIT */
/* splinewalk profile SCENE --path PATH --out DIR [...]: frames along a camera path through the
 * public renderer API, timed stage by stage on the submitting thread and, threaded, on the
 * renderer's visibility thread. */
#include "cli.h"
#include "cli_profile_out.h"

#include "sw_camera_path.h"
#include "sw_profile_report.h"
#include "sw_rt.h"
#include "sw_status_util.h"
#include "sw_th_pool.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char k_usage[] =
    "usage: splinewalk profile SCENE --path PATH --out DIR [--frames N] [--size WxH] [--error PX]\n"
    "                          [--converged] [--sequential | --threads N]\n"
    "                          [--eval hierarchy|bezier|exact] [--no-static-lod] [--no-proxies]\n"
    "                          [--lod-colors]\n"
    "                          [--no-occlusion] [--no-exact-edges] [--no-kept-grids]\n"
    "                          [--memory-budget HOST[,GPU]]\n"
    "\n"
    "Renders N frames of SCENE headlessly along the camera path PATH (docs/camera-path.md; made\n"
    "by `splinewalk path orbit|fly`) through the public renderer API. Threaded (the default), the\n"
    "renderer's visibility thread prepares frame i+1 (culling, hierarchy selection, tessellation:\n"
    "vis_ms, vis_hierarchy_ms, vis_tessellate_ms) while this thread submits frame i; frame_ms is\n"
    "this thread's time per frame and its stages: wait_visibility, trim, draw, readback, write\n"
    "(the PNG of a captured frame) and other = frame_ms minus those. With --sequential each frame\n"
    "is one sw_renderer_draw call: prepared on the visibility thread while this thread waits for\n"
    "it (wait_visibility), then submitted. Writes into\n"
    "DIR: profile.csv and profile.json (one row per frame with the stage times, patches,\n"
    "triangles, trim textures and texels, atlas pages, fallback draws, pool waits, the worker\n"
    "pool's time and task count per task kind (pool_<kind>_ms, pool_<kind>_tasks: its threads,\n"
    "beside frame_ms) and queue length at the frame's end (pool_queued), and resident memory;\n"
    "the JSON adds the run and a summary: median, p90, p99, max, mean per column),\n"
    "frametime.svg (frame time and the stage stack along the path; below, the pool's time per\n"
    "task kind and its queue), report.html, and PNGs of the first, middle and last frame.\n"
    "Everything is written aside and renamed into DIR at the end: a failed run leaves DIR as it\n"
    "was. Prints the summary; a progress bar on a terminal.\n"
    "\n"
    "options:\n"
    "  --path PATH       camera path file (required)\n"
    "  -o, --out DIR     output directory, created if missing (required)\n"
    "  --frames N        frames spread evenly over the path (default: the path's 'frames', else\n"
    "                    100)\n"
    "  --size WxH        frame size (default 1280x720)\n"
    "  --error PX        screen-space error bound in pixels, at least 0.01 (default 0.5)\n"
    "  --converged       every frame waits for the hierarchy builds and refinements it asks for\n"
    "                    (default: walkthrough mode, frames never wait; what is not ready is\n"
    "                    drawn coarser and queued)\n"
    "  --threads N       worker-pool threads (default: one per online processor)\n"
    "  --sequential      each frame in one call (sw_renderer_draw), converged, with a pool of\n"
    "                    one worker: builds run only while the frame waits for them, on that\n"
    "                    worker and the visibility thread (the pool cannot be emptied; nothing\n"
    "                    overlaps the frames)\n"
    "  --eval MODE       hierarchy (default), bezier or exact, as for `render`\n"
    "  --no-static-lod   every face by the per-frame path. By default super-surfaces are drawn\n"
    "                    from static LODs where fine enough (Kumar et al. 1997): read from the\n"
    "                    scene's `build-lod` cache, else built in the pool on first need (said\n"
    "                    on stderr); static_drawn, static_faces, static_triangles,\n"
    "                    static_requests columns\n"
    "  --no-proxies      no cluster proxies (by default, once a LOD cache is read, far groups of\n"
    "                    super-surface instances are drawn as one merged mesh within the\n"
    "                    bound: proxies_drawn, proxy_instances, proxy_triangles columns)\n"
    "  --lod-colors      colour by representation, as for `render`\n"
    "  --no-exact-edges  trim textures only (by default exact trim edges where a trim texel\n"
    "                    would exceed a quarter pixel, as for `render`: trim_exact column)\n"
    "  --no-kept-grids   every patch grid evaluated in each frame (by default grids are kept on\n"
    "                    the GPU between frames, as for `render`: grid_hits, grid_misses)\n"
    "  --no-occlusion    draw what visible planar faces hide too (culled by default, as for\n"
    "                    `render`: occlusion_tests, nodes_occluded, faces_occluded columns; a\n"
    "                    frame that hides nothing makes the next 1, 3, 7 or 15 go without "
    "it)\n" SW_CLI_MEMORY_BUDGET_HELP "                    (budget_coarsened column)\n"
    "  -h, --help        this text\n";

typedef struct profile_args {
    const char *scene, *path, *out, *eval;
    int frames; /* 0 = the path's, else 100 */
    int threads;
    int converged, sequential;
    sw_frame_desc frame;
    uint64_t budget_host, budget_gpu; /* --memory-budget; 0 = the default */
} profile_args;

static int parse_option(profile_args *a, const char *arg, const char *val)
{
    if (!strcmp(arg, "--path"))
        a->path = val;
    else if (!strcmp(arg, "-o") || !strcmp(arg, "--out") || !strcmp(arg, "--output"))
        a->out = val;
    else if (!strcmp(arg, "--frames"))
        return sw_cli_parse_count(val, 1, (int)SW_RT_PATH_MAX_FRAMES, &a->frames);
    else if (!strcmp(arg, "--size"))
        return sw_cli_parse_size(val, &a->frame.width, &a->frame.height);
    else if (!strcmp(arg, "--error"))
        return sw_cli_parse_error_px(val, &a->frame.error_px);
    else if (!strcmp(arg, "--threads"))
        return sw_cli_parse_count(val, 1, 1024, &a->threads);
    else if (!strcmp(arg, "--memory-budget"))
        return sw_cli_parse_memory_budget(val, &a->budget_host, &a->budget_gpu);
    else if (!strcmp(arg, "--eval")) {
        a->eval = val;
        a->frame.eval_exact = strcmp(val, "exact") == 0;
        a->frame.no_hierarchy = strcmp(val, "bezier") == 0;
        return strcmp(val, "hierarchy") != 0 && strcmp(val, "bezier") != 0 &&
               strcmp(val, "exact") != 0;
    } else
        return 2;
    return 0;
}

static int parse_args(int argc, char **argv, profile_args *a)
{
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(arg, "--occlusion") || !strcmp(arg, "--no-occlusion")) {
            a->frame.occlusion_culling = !strcmp(arg, "--occlusion");
            continue;
        }
        if (!strcmp(arg, "--static-lod") || !strcmp(arg, "--no-static-lod")) {
            a->frame.static_lods = !strcmp(arg, "--static-lod");
            continue;
        }
        if (!strcmp(arg, "--no-proxies")) {
            a->frame.no_proxies = 1;
            continue;
        }
        if (!strcmp(arg, "--lod-colors")) {
            a->frame.lod_colors = 1;
            continue;
        }
        if (!strcmp(arg, "--no-kept-grids")) {
            a->frame.no_kept_grids = 1;
            continue;
        }
        if (!strcmp(arg, "--exact-edges") || !strcmp(arg, "--no-exact-edges")) {
            a->frame.trim_edges = !strcmp(arg, "--exact-edges");
            continue;
        }
        if (!strcmp(arg, "--converged") || !strcmp(arg, "--sequential")) {
            a->converged = 1; /* --sequential implies it */
            if (!strcmp(arg, "--sequential"))
                a->sequential = 1;
            continue;
        }
        if (arg[0] != '-' && !a->scene) {
            a->scene = arg;
            continue;
        }
        const int bad = val ? parse_option(a, arg, val) : 2;
        if (bad == 2) {
            fprintf(stderr, "splinewalk profile: unexpected argument '%s'\n%s", arg, k_usage);
            return 2;
        }
        if (bad) {
            return sw_cli_bad_value("profile", arg, val, k_usage);
        }
        i++;
    }
    if (!a->scene || !a->path || !a->out) {
        fprintf(stderr, "splinewalk profile: need SCENE, --path PATH and --out DIR\n%s", k_usage);
        return 2;
    }
    if (a->sequential && a->threads) {
        fprintf(stderr, "splinewalk profile: --sequential and --threads exclude each other\n");
        return 2;
    }
    return 0;
}

/* ---- the run --------------------------------------------------------------------------------- */
static void choose_captures(sw_rt_profile *p, uint32_t n)
{
    const uint32_t want[3] = {0, n / 2, n - 1};
    p->n_captures = 0;
    for (int k = 0; k < 3; k++)
        if (p->n_captures == 0 || p->captures[p->n_captures - 1] != want[k])
            p->captures[p->n_captures++] = want[k];
}

static int is_capture(const sw_rt_profile *p, uint32_t i)
{
    for (uint32_t k = 0; k < p->n_captures; k++)
        if (p->captures[k] == i)
            return 1;
    return 0;
}

static void show_progress(uint32_t done, uint32_t n, double last_ms)
{
    char stage[64];
    snprintf(stage, sizeof stage, "frame %u/%u  %.1f ms", done, n, last_ms);
    sw_cli_progress(NULL, (double)done / n, stage);
}

/* Frame i's camera along the path and, when it is captured, its staged PNG in `file` (the
 * renderer copies the path: one buffer serves the frame prepared ahead too). */
static void set_frame(const sw_rt_camera_path *path, uint32_t i, uint32_t n, sw_cli_staging *st,
                      const sw_rt_profile *p, sw_frame_desc *frame, char file[4200])
{
    sw_rt_path_eval(path, sw_rt_path_frame_time(path, i, n), &frame->camera);
    frame->output_path = NULL;
    if (is_capture(p, i)) {
        char name[64];
        sw_rt_profile_capture_name(i, name, sizeof name);
        sw_cli_staging_path(st, name, file, 4200);
        sw_cli_staging_remember(st, name);
        frame->output_path = file;
    }
}

/* One frame on this thread: drawn in one call (sequential), or — threaded — frame i + 1 handed
 * to the renderer's visibility thread, then frame i (prepared while frame i - 1 was submitted)
 * submitted. */
static sw_result one_frame(sw_renderer renderer, int threaded, const sw_rt_camera_path *path,
                           uint32_t i, uint32_t n, sw_frame_desc *frame, sw_cli_staging *st,
                           sw_rt_profile *p, sw_frame_stats *stats, double *prepare_ms,
                           sw_status *status)
{
    char file[4200];
    *prepare_ms = 0.0;
    if (!threaded) {
        set_frame(path, i, n, st, p, frame, file);
        return sw_renderer_draw(renderer, frame, stats, status);
    }
    sw_result r = SW_OK;
    if (i + 1 < n) {
        set_frame(path, i + 1, n, st, p, frame, file);
        const double t0 = sw__clock_ms();
        r = sw_renderer_prepare(renderer, frame, status);
        *prepare_ms = sw__clock_ms() - t0;
    }
    return r == SW_OK ? sw_renderer_submit(renderer, stats, status) : r;
}

/* Draws the n frames; each row's frame_ms is this thread's wall time for its frame. */
static sw_result run_frames(sw_renderer renderer, int threaded, const sw_rt_camera_path *path,
                            uint32_t n, sw_frame_desc *frame, sw_cli_staging *st, sw_rt_profile *p,
                            sw_status *status)
{
    const int tty = isatty(STDERR_FILENO);
    char file[4200];
    sw_result r = SW_OK;
    if (threaded) {
        set_frame(path, 0, n, st, p, frame, file);
        r = sw_renderer_prepare(renderer, frame, status);
    }
    for (uint32_t i = 0; i < n && r == SW_OK; i++) {
        sw_frame_stats stats = {0};
        sw_cli_pool_sample pool_start, pool_end;
        double prepare_ms;
        const double t0 = sw__clock_ms();
        sw_cli_pool_read(renderer, 0, &pool_start);
        r = one_frame(renderer, threaded, path, i, n, frame, st, p, &stats, &prepare_ms, status);
        sw_cli_pool_read(renderer, 1, &pool_end);
        const double ms = sw__clock_ms() - t0;
        const double t = sw_rt_path_frame_time(path, i, n);
        if (r != SW_OK) {
            char msg[sizeof status->message];
            snprintf(msg, sizeof msg, "%s", status->message);
            r = sw__fail(status, r, "frame %u (t = %g s): %s", i, t, msg);
            break;
        }
        sw_rt_prof_row row;
        sw_rt_profile_row(&stats, i, t, ms, prepare_ms, sw_cli_resident_bytes(), is_capture(p, i),
                          &row);
        sw_cli_pool_columns(&pool_start, &pool_end, &row);
        if (sw_rt_profile_push(p, &row) != 0)
            r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "profile: out of memory");
        if (tty)
            show_progress(i + 1, n, ms);
    }
    if (tty)
        sw_cli_progress_end();
    return r;
}

/* The pool size the renderer is asked for; 0 = one per online processor. */
static uint32_t requested_workers(const profile_args *a)
{
    return a->sequential ? 1u : (uint32_t)a->threads;
}

static void fill_meta(const profile_args *a, sw_renderer renderer, sw_rt_profile *p)
{
    sw_rt_prof_meta *m = &p->meta;
    m->scene = a->scene;
    m->path = a->path;
    m->renderer = sw_renderer_description_ptr(renderer);
    m->mode = a->converged ? "converged" : "walkthrough";
    m->eval = a->eval ? a->eval : "hierarchy";
    m->lp_num_threads = getenv("LP_NUM_THREADS");
    m->width = a->frame.width ? a->frame.width : SW_DEFAULT_WIDTH;
    m->height = a->frame.height ? a->frame.height : SW_DEFAULT_HEIGHT;
    m->error_px = a->frame.error_px > 0.0 ? a->frame.error_px : SW_DEFAULT_ERROR_PX;
    m->worker_threads = sw_cli_pool_workers(requested_workers(a));
    m->sequential = a->sequential;
}

/* Renderer, frames, files; the scene and path are loaded. */
static sw_result profile_run(profile_args *a, sw_scene scene, const sw_rt_camera_path *path,
                             uint32_t n, sw_rt_profile *p, sw_status *status)
{
    sw_renderer_desc rd = {0};
    rd.worker_threads = requested_workers(a);
    rd.memory_budget_host = a->budget_host;
    rd.memory_budget_gpu = a->budget_gpu;
    sw_renderer renderer = {0};
    sw_result r = sw_renderer_create(&rd, &renderer, status);
    if (r != SW_OK)
        return r;
    char budget[256];
    sw_cli_memory_budget_line(renderer, budget, sizeof budget);
    printf("profile: %s", budget);
    /* pool_<kind>_ms: two clock reads per task, nothing next to a hierarchy build's cost */
    sw_rt_renderer_time_pool_tasks(renderer, 1);
    fill_meta(a, renderer, p);
    sw_cli_staging st = {0};
    r = sw_cli_staging_make(a->out, &st, status);
    if (r == SW_OK) {
        a->frame.scene = scene;
        a->frame.walkthrough = !a->converged;
        choose_captures(p, n);
        const double t0 = sw__clock_ms();
        r = run_frames(renderer, !a->sequential, path, n, &a->frame, &st, p, status);
        p->meta.wall_s = (sw__clock_ms() - t0) / 1e3;
        r = sw_cli_profile_finish(&st, a->out, p, r, status);
    }
    sw_renderer_destroy(renderer);
    return r;
}

int sw_cli_profile(int argc, char **argv)
{
    if (sw_cli_print_help(argc, argv, k_usage))
        return 0;
    profile_args a = {0};
    a.frame.occlusion_culling = 1;
    a.frame.trim_edges = 1;
    a.frame.static_lods = 1;
    int rc = parse_args(argc, argv, &a);
    if (rc)
        return rc;

    sw_status status = {0};
    sw_rt_camera_path path; /* first: a bad path fails before any work or output */
    if (sw_rt_path_load(a.path, &path, &status) != SW_OK)
        return sw_cli_report("profile", &status);
    const uint32_t n = a.frames ? (uint32_t)a.frames : path.frames ? path.frames : 100;
    sw_scene scene;
    if (sw_cli_load_scene(a.scene, 0, &scene, &status) != SW_OK) {
        sw_rt_path_free(&path);
        return sw_cli_report("profile", &status);
    }
    sw_rt_profile prof = {0};
    sw_result r = profile_run(&a, scene, &path, n, &prof, &status);
    sw_scene_destroy(scene);
    sw_rt_path_free(&path);
    if (r != SW_OK) {
        sw_rt_profile_free(&prof);
        return sw_cli_report("profile", &status);
    }
    printf("%s along %s: %u frames at %dx%d, error %g px, %s, %u pool worker%s%s, "
           "LP_NUM_THREADS=%s, %.2f s\n",
           a.scene, a.path, n, prof.meta.width, prof.meta.height, prof.meta.error_px,
           prof.meta.mode, prof.meta.worker_threads, prof.meta.worker_threads == 1 ? "" : "s",
           a.sequential ? " (sequential)" : "",
           prof.meta.lp_num_threads ? prof.meta.lp_num_threads : "(unset)", prof.meta.wall_s);
    sw_rt_profile_print_summary(stdout, &prof);
    printf("wrote %s/profile.csv, profile.json, frametime.svg, report.html and %u frames\n", a.out,
           prof.n_captures);
    if (!isatty(STDERR_FILENO))
        fprintf(stderr, "splinewalk profile: %u/%u frames in %.2f s\n", n, n, prof.meta.wall_s);
    sw_rt_profile_free(&prof);
    return 0;
}
