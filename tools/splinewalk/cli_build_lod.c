/* SPDX-License-Identifier: MIT */
/* splinewalk build-lod SCENE [-o OUT.sws] [--threads N] [--no-proxies] */
#include "cli.h"

#include "sw_lod_static_set.h"
#include "sw_rt.h"
#include "sw_status_util.h"
#include "sw_th_pool.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static const char k_usage[] =
    "usage: splinewalk build-lod SCENE [-o OUT.sws] [--threads N] [--no-proxies]\n"
    "\n"
    "Builds the static LODs of every super-surface of SCENE (Kumar et al. 1997 §3-§4): the\n"
    "scene's Bézier patches clustered under a 45° normal-cone bound into super-surfaces of whole\n"
    "faces, each tessellated within δ (2e-3 of its diagonal) and simplified into 4 more levels\n"
    "whose errors are certified both ways (δ plus bounds of the distances to and from level 0).\n"
    "The levels are written into the scene file's LODS section (a new file written aside, then\n"
    "renamed over OUT), so that `profile`, `view` and `render` start from them instead of\n"
    "building them (walkthroughs build what is missing in the background; `render` uses static\n"
    "LODs by default only when the file has them).\n"
    "Prints, per level, the triangles against level 0 (the exact adaptive tessellation), the\n"
    "declared errors and the triangles stored (a level finer than any frame draws, more than\n"
    "24 triangles per Bézier patch, is stored as its error alone); a progress bar on stderr.\n"
    "A super-surface whose build fails is named and drawn by the per-frame path; the others are\n"
    "kept.\n"
    "Then the cluster proxies (hierarchical LOD across objects): one mesh for every node of the\n"
    "instances' bounding-volume hierarchy with 8 or more instances under it, clustered from\n"
    "their levels with an error certified both ways, stored with the levels; frames draw one\n"
    "instead of its node's instances where its error is within the view's tolerance. Without\n"
    "them stored, a walkthrough builds them in the background.\n"
    "\n"
    "options:\n"
    "  -o, --output FILE   the .sws to write (default: SCENE itself; SCENE must then be a .sws)\n"
    "  --threads N         worker-pool threads (default: one per online processor)\n"
    "  --no-proxies        store the levels only\n"
    "  -h, --help          this text\n";

typedef struct lod_args {
    const char *scene, *out;
    int threads;
    int no_proxies;
} lod_args;

static int parse_args(int argc, char **argv, lod_args *a)
{
    for (int i = 1; i < argc; i++) {
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        if ((!strcmp(argv[i], "-o") || !strcmp(argv[i], "--output")) && val) {
            a->out = argv[++i];
        } else if (!strcmp(argv[i], "--threads") && val) {
            if (sw_cli_parse_count(val, 1, 1024, &a->threads)) {
                fprintf(stderr, "splinewalk build-lod: bad value '%s' for --threads\n%s", val,
                        k_usage);
                return 2;
            }
            i++;
        } else if (!strcmp(argv[i], "--no-proxies")) {
            a->no_proxies = 1;
        } else if (argv[i][0] != '-' && !a->scene) {
            a->scene = argv[i];
        } else {
            fprintf(stderr, "splinewalk build-lod: unexpected argument '%s'\n%s", argv[i], k_usage);
            return 2;
        }
    }
    if (!a->scene) {
        fprintf(stderr, "splinewalk build-lod: need SCENE\n%s", k_usage);
        return 2;
    }
    const size_t n = strlen(a->scene);
    if (!a->out && (n < 4 || strcmp(a->scene + n - 4, ".sws") != 0)) {
        fprintf(stderr, "splinewalk build-lod: %s is not a .sws: name the output with -o\n",
                a->scene);
        return 2;
    }
    if (!a->out)
        a->out = a->scene;
    return 0;
}

/* Requests every unit and shows the progress until each is READY or FAILED. */
static void build_all(sw_lod_static_set *set)
{
    const uint32_t n = sw_lod_static_set_unit_count(set);
    for (uint32_t u = 0; u < n; ++u)
        sw_lod_static_set_request(set, u, SW_TH_PRIORITY_FRAME);
    for (uint32_t u = 0; u < n; ++u) {
        sw_lod_static_set_wait(set, u); /* runs pool tasks meanwhile */
        char stage[64];
        snprintf(stage, sizeof stage, "super-surface %u / %u", u + 1, n);
        sw_cli_progress(NULL, (double)(u + 1) / n, stage);
    }
    sw_cli_progress_end();
}

/* Builds the cluster proxies in the pool and shows the progress (nodes done of the candidates)
 * until every build has finished. */
static sw_result build_proxies(sw_lod_static_set *set, sw_status *status)
{
    const uint32_t n_nodes = sw_lod_static_set_instances(set)->bvh->n_nodes;
    uint64_t candidates = 0;
    for (uint32_t k = 0; k < n_nodes; ++k)
        candidates += (uint64_t)sw__lod_proxy_candidate(set, k);
    sw_result r = sw_lod_static_set_build_proxies(set, status);
    while (r == SW_OK && !sw_lod_static_set_proxies_done(set)) {
        sw_lod_static_set_stats ss;
        sw_lod_static_set_get_stats(set, &ss);
        const uint64_t done = ss.proxies + ss.proxies_failed + ss.proxies_pruned;
        char stage[64];
        snprintf(stage, sizeof stage, "cluster proxies %llu / %llu", (unsigned long long)done,
                 (unsigned long long)candidates);
        sw_cli_progress(NULL, candidates ? (double)done / (double)candidates : 1.0, stage);
        nanosleep(&(struct timespec){0, 200000000}, NULL); /* a progress bar, not a wait */
    }
    sw_lod_static_set_wait_proxies(set);
    sw_cli_progress_end();
    return r;
}

static void print_proxies(const sw_lod_static_set *set)
{
    sw_lod_static_set_stats ss;
    sw_lod_static_set_get_stats(set, &ss);
    printf("%llu cluster proxies, %llu triangles, %.1f MiB in memory (%llu nodes could not have "
           "one, %llu dropped over the proxies' memory budget), %.1f s of pool time\n",
           (unsigned long long)ss.proxies, (unsigned long long)ss.proxy_triangles,
           (double)ss.proxy_bytes / (1024.0 * 1024.0), (unsigned long long)ss.proxies_failed,
           (unsigned long long)ss.proxies_pruned, ss.proxy_seconds);
}

typedef struct level_sum {
    uint64_t triangles; /* as built, kept or not */
    uint64_t kept;      /* in levels a frame draws, which the cache stores */
    double eps_rel_max; /* declared ε / δ, largest */
    uint32_t chains;
} level_sum;

static void print_summary(const sw_lod_static_set *set, uint64_t patches)
{
    level_sum sum[9] = {{0}};
    const uint32_t n = sw_lod_static_set_unit_count(set);
    uint32_t failed = 0;
    for (uint32_t u = 0; u < n; ++u) {
        const sw_lod_static_chain *c = sw_lod_static_set_get(set, u);
        if (!c) {
            const char *msg = NULL;
            sw_lod_static_set_failure(set, u, &msg);
            if (failed++ < 5)
                fprintf(stderr, "splinewalk build-lod: super-surface %u: %s (drawn per frame)\n", u,
                        msg ? msg : "not built");
            continue;
        }
        for (int32_t k = 0; k < c->n_levels && k < 9; ++k) {
            sum[k].triangles += c->levels[k].n_triangles + c->levels[k].n_triangles_dropped;
            sum[k].kept += c->levels[k].n_triangles;
            sum[k].chains++;
            const double rel = c->levels[k].eps / c->delta;
            sum[k].eps_rel_max = rel > sum[k].eps_rel_max ? rel : sum[k].eps_rel_max;
        }
    }
    printf("%u super-surfaces of whole faces (%llu Bézier patches), %u built, %u failed\n", n,
           (unsigned long long)patches, n - failed, failed);
    printf(
        "level  triangles   vs level 0   per patch   largest declared ε / δ   stored triangles\n");
    for (int k = 0; k < 9 && sum[k].chains; ++k)
        printf("%5d  %9llu   %9.1f %%   %9.2f   %8.1f                 %9llu\n", k,
               (unsigned long long)sum[k].triangles,
               100.0 * (double)sum[k].triangles / (double)(sum[0].triangles ? sum[0].triangles : 1),
               (double)sum[k].triangles / (double)(patches ? patches : 1), sum[k].eps_rel_max,
               (unsigned long long)sum[k].kept);
}

static sw_result write_cache(sw_sg_scene *sg, const sw_lod_static_set *set, const char *out,
                             size_t *bytes, sw_status *status)
{
    void *blob = NULL;
    sw_result r = sw_lod_static_set_serialize(set, &blob, bytes, status);
    if (r == SW_OK)
        r = sw_sg_scene_save_lods(sg, out, blob, *bytes, status);
    free(blob);
    return r;
}

int sw_cli_build_lod(int argc, char **argv)
{
    if (sw_cli_print_help(argc, argv, k_usage))
        return 0;
    lod_args a = {0};
    int rc = parse_args(argc, argv, &a);
    if (rc)
        return rc;
    if (sw_cli_check_output("build-lod", a.out, 0))
        return 1;
    if (!sw_lod_static_builder()) {
        /* else every super-surface fails and an empty cache would replace the file's */
        fprintf(stderr, "splinewalk build-lod: this build has no LOD-building module "
                        "(libsplinewalk_lodbuild, CGAL and OpenMesh): nothing written\n");
        return 1;
    }
    sw_status status = {0};
    sw_scene handle;
    const double t0 = sw__clock_ms();
    if (sw_cli_load_scene(a.scene, 0, &handle, &status) != SW_OK)
        return sw_cli_report("build-lod", &status);
    sw_rt_scene *scene = NULL;
    sw_th_pool *pool = NULL;
    sw_lod_static_set *set = NULL;
    sw_th_pool_desc pd = {0};
    pd.worker_count = (uint32_t)a.threads;
    sw_result r = sw_rt_scene_acquire(handle, &scene, &status);
    if (r == SW_OK)
        r = sw_sg_scene_require(scene->sg, SW_SG_SEC_ALL, &status);
    if (r == SW_OK && sw_th_pool_create(&pd, &pool) != SW_OK)
        r = sw__fail(&status, SW_ERR_OUT_OF_MEMORY, "worker pool: could not start");
    const double t1 = sw__clock_ms();
    if (r == SW_OK)
        r = sw_lod_static_set_create(scene->sg, pool, NULL, &set, &status);
    const double t2 = sw__clock_ms();
    size_t bytes = 0;
    if (r == SW_OK) {
        build_all(set);
        const sw_lod_supersurfaces *ss = sw_lod_static_set_supersurfaces(set);
        print_summary(set, ss->n_patches);
    }
    const double t3 = sw__clock_ms();
    if (r == SW_OK && !a.no_proxies) {
        r = build_proxies(set, &status);
        if (r == SW_OK)
            print_proxies(set);
    }
    const double t4 = sw__clock_ms();
    if (r == SW_OK)
        r = write_cache(scene->sg, set, a.out, &bytes, &status);
    sw_lod_static_set_destroy(set);
    sw_th_pool_destroy(pool);
    if (scene)
        sw_rt_scene_release(scene);
    sw_scene_destroy(handle);
    if (r != SW_OK)
        return sw_cli_report("build-lod", &status);
    printf("%s -> %s: LOD cache %.1f MiB; load %.0f ms, clustering %.0f ms, levels %.1f s, "
           "proxies %.1f s, write %.0f ms\n",
           a.scene, a.out, (double)bytes / (1024.0 * 1024.0), t1 - t0, t2 - t1, 1e-3 * (t3 - t2),
           1e-3 * (t4 - t3), sw__clock_ms() - t4);
    return 0;
}
