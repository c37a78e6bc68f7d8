/* SPDX-License-Identifier: MIT */
/* bench_peers: splinewalk beside Mesa's GLU NURBS tessellator and OpenCASCADE's mesher
 * on the same scene, camera path, frame size and ε_img; each peer in its own child process. See
 * k_usage for what is measured and how; the figures and their reading are in bench/peers/README.md.
 */
#include "cli_numbers.h"
#include "bench_peer.h"
#include "cli.h"
#include "peer_glu.h"
#include "peer_mesh.h"
#include "peer_splinewalk.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char k_usage[] =
    "usage: bench_peers [options] SCENE...\n"
    "\n"
    "Runs three renderers of trimmed NURBS on each SCENE (.sws, or .brep / .step / .iges as\n"
    "sw_scene_load reads them) along the same camera path at the same frame size and error\n"
    "bound eps_img, each in its own child process (fork), one after the other:\n"
    "  splinewalk  the public API, threaded (sw_renderer_prepare of frame i+1 while\n"
    "              sw_renderer_submit draws frame i), walkthrough mode, default renderer,\n"
    "              static LODs (the .sws's build-lod cache, else built in the pool)\n"
    "  glu         Mesa's GLU NURBS tessellator (GLU_NURBS_TESSELLATOR, GLU_PARAMETRIC_ERROR =\n"
    "              eps_img px, gluLoadSamplingMatrices per frame, GLU_CULLING on, trim loops as\n"
    "              gluNurbsCurve) re-tessellating every face occurrence every frame; its\n"
    "              triangles uploaded to one VBO and drawn in a 4.5 core EGL context\n"
    "  occt        OpenCASCADE's BRepMesh_IncrementalMesh of the scene's BREP, once, at the\n"
    "              deflection of eps_img px at the path's nearest eye-to-scene-box distance;\n"
    "              one VBO drawn every frame\n"
    "Frame time = the wall interval between successive frames' completions: every peer\n"
    "fences its frame and waits for the frame before (one frame in flight, no glFinish, no\n"
    "readback); for splinewalk the submitting thread's prepare(i+1) + submit(i); for glu\n"
    "tessellation + upload + draw.\n"
    "Warm-up passes are drawn first and not counted (the first frame is among them); for\n"
    "splinewalk they are converged after its first frame, so that the hierarchies and static\n"
    "levels the path needs are built before the timed passes (their time is in its note). Per\n"
    "peer: median and p99 frame time, time to first frame (from the child's start: load,\n"
    "preprocessing - splinewalk's builds run in the background, GLU's control points, OCCT's\n"
    "mesh - and the first frame), peak RSS (the child's VmHWM minus its resident memory at the "
    "fork),\n"
    "triangles per frame (median), and splinewalk / peer ratios of each; for glu and occt the\n"
    "pixels their last frame covered (read back once after the timed frames), to see that both\n"
    "drew the same shape. glu first tessellates every face once in child processes of its own\n"
    "(Mesa's GLU crashes on a few faces; not counted in its time to first frame): faces it\n"
    "reports an error for or crashes on are counted (refused_faces, crashed_faces), not drawn;\n"
    "a glu frame longer than 120 s (GLU hangs on some faces in some views) ends the glu peer\n"
    "with a message naming the face.\n"
    "Set LP_NUM_THREADS and EGL_PLATFORM=surfaceless yourself: the header line echoes them.\n"
    "\n"
    "options:\n"
    "  --peers LIST    comma-separated subset of splinewalk,glu,occt (default: all three)\n"
    "  --frames N      frames along the path per pass (default 120)\n"
    "  --warmup W      uncounted passes first (default 1)\n"
    "  --passes P      counted passes (default 1)\n"
    "  --size WxH      frame size (default 1280x720)\n"
    "  --error PX      eps_img in pixels (default 0.5)\n"
    "  --path FILE     camera path (docs/camera-path.md; default: the orbit `splinewalk path\n"
    "                  orbit` makes for the scene's box)\n"
    "  --brep FILE     the scene's BREP for occt (default: SCENE itself if it is .brep, else\n"
    "                  SCENE with its extension replaced by .brep if that file exists; none:\n"
    "                  occt is skipped with a note). Only with one SCENE.\n"
    "  --no-static-lods  splinewalk without its static LODs (sw_frame_desc.static_lods: Kumar\n"
    "                  et al. 1997 super-surface meshes for what the error allows, from the\n"
    "                  .sws's build-lod cache or built in the pool; default: on, as in the\n"
    "                  CLI's walkthroughs)\n"
    "  --no-occlusion  splinewalk without occlusion culling (sw_frame_desc.occlusion_culling:\n"
    "                  what the visible planar faces hide is culled; default: on, as in the CLI)\n"
    "  --no-exact-edges  splinewalk with trim textures only (sw_frame_desc.trim_edges: close-up\n"
    "                  trims cut per fragment by their loops; default: on, as in the CLI)\n"
    "  --no-kept-grids  splinewalk evaluating every patch grid in each frame\n"
    "                  (sw_frame_desc.no_kept_grids; default: grids kept on the GPU)\n"
    "  --glibc-malloc  every peer with glibc's default trim and mmap thresholds; by default\n"
    "                  they are raised for all peers alike, as `splinewalk` does and\n"
    "                  docs/embedding.md advises (llvmpipe frees megabytes every frame)\n"
    "  --csv FILE      also write the rows as CSV (written aside, then renamed)\n"
    "  -h, --help      this text\n";

enum { PEER_SW, PEER_GLU, PEER_OCCT, N_PEERS };
static const char *const k_peer_names[N_PEERS] = {"splinewalk", "glu", "occt"};
static const bp_peer_fn k_peer_fns[N_PEERS] = {bp_peer_splinewalk, bp_peer_glu, bp_peer_occt};

typedef struct args {
    int use[N_PEERS];
    int static_lods, occlusion, exact_edges, kept_grids, glibc_malloc;
    uint32_t frames, warmup, passes;
    int32_t w, h;
    double error_px;
    const char *path_file, *brep, *csv;
    char **scenes;
    int n_scenes;
} args;

static int parse_peers(const char *list, int use[N_PEERS])
{
    memset(use, 0, N_PEERS * sizeof *use);
    char buf[128];
    snprintf(buf, sizeof buf, "%s", list);
    for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
        int found = 0;
        for (int p = 0; p < N_PEERS; ++p)
            if (!strcmp(tok, k_peer_names[p]))
                use[p] = found = 1;
        if (!found)
            return -1;
    }
    return use[0] || use[1] || use[2] ? 0 : -1;
}

static int parse(int argc, char **argv, args *a)
{
    *a = (args){.use = {1, 1, 1},
                .frames = 120,
                .warmup = 1,
                .passes = 1,
                .w = 1280,
                .h = 720,
                .error_px = 0.5,
                .static_lods = 1,
                .occlusion = 1,
                .exact_edges = 1,
                .kept_grids = 1};
    a->scenes = calloc((size_t)argc, sizeof *a->scenes);
    for (int i = 1; i < argc && a->scenes; ++i) {
        const char *o = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int takes = v && o[0] == '-' && strcmp(o, "-h") && strcmp(o, "--help");
        if (!strcmp(o, "-h") || !strcmp(o, "--help"))
            return 1;
        if (!strcmp(o, "--static-lods") || !strcmp(o, "--no-static-lods")) {
            a->static_lods = !strcmp(o, "--static-lods");
            continue;
        }
        if (!strcmp(o, "--glibc-malloc")) {
            a->glibc_malloc = 1;
            continue;
        }
        if (!strcmp(o, "--occlusion") || !strcmp(o, "--no-occlusion")) {
            a->occlusion = !strcmp(o, "--occlusion");
            continue;
        }
        if (!strcmp(o, "--no-kept-grids")) {
            a->kept_grids = 0;
            continue;
        }
        if (!strcmp(o, "--exact-edges") || !strcmp(o, "--no-exact-edges")) {
            a->exact_edges = !strcmp(o, "--exact-edges");
            continue;
        }
        if (o[0] != '-') {
            a->scenes[a->n_scenes++] = argv[i];
            continue;
        }
        if (!takes)
            return -1;
        ++i;
        if (!strcmp(o, "--peers") && parse_peers(v, a->use) == 0)
            continue;
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
        else if (!strcmp(o, "--path"))
            a->path_file = v;
        else if (!strcmp(o, "--brep"))
            a->brep = v;
        else if (!strcmp(o, "--csv"))
            a->csv = v;
        else
            return -1;
    }
    int ok = a->scenes && a->n_scenes > 0 && a->frames >= 2 && a->frames <= 100000 &&
             a->passes >= 1 && a->passes <= 100 && a->warmup <= 100 && a->w > 0 && a->h > 0 &&
             a->w <= 16384 && a->h <= 16384 && a->error_px > 0.0 && isfinite(a->error_px) &&
             !(a->brep && a->n_scenes > 1);
    return ok ? 0 : -1;
}

static int has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext);
    return n > e && !strcasecmp(path + n - e, ext);
}

/* The BREP beside a scene: itself, or SCENE.brep in place of its extension; NULL if none. */
static const char *brep_for(const char *scene, char *buf, size_t size)
{
    if (has_ext(scene, ".brep"))
        return scene;
    snprintf(buf, size, "%s", scene);
    char *dot = strrchr(buf, '.'), *slash = strrchr(buf, '/');
    if (dot && (!slash || dot > slash) && (size_t)(dot - buf) + 6 <= size)
        strcpy(dot, ".brep");
    return access(buf, R_OK) == 0 ? buf : NULL;
}

static double ratio(double sw, double peer)
{
    return sw > 0.0 && peer > 0.0 ? sw / peer : NAN;
}

static void print_row(const char *name, const bp_result *r, const bp_result *sw)
{
    if (!r->ok) {
        printf("  %-10s | not run: %s\n", name, r->note);
        return;
    }
    printf("  %-10s | %7.2f %8.2f | %9.0f | %8.1f | %10.0f | %6.2f %6.2f %7.2f %6.2f %8.3f\n", name,
           r->median_ms, r->p99_ms, r->first_frame_ms, r->peak_rss_bytes / 1048576.0, r->triangles,
           ratio(sw->median_ms, r->median_ms), ratio(sw->p99_ms, r->p99_ms),
           ratio(sw->first_frame_ms, r->first_frame_ms),
           ratio(sw->peak_rss_bytes, r->peak_rss_bytes), ratio(sw->triangles, r->triangles));
}

static void print_notes(const bp_result res[N_PEERS], const int use[N_PEERS])
{
    for (int p = 0; p < N_PEERS; ++p)
        if (use[p] && res[p].ok)
            printf("  %s: %s%sits process ran %.1f s\n", k_peer_names[p], res[p].note,
                   res[p].note[0] ? "; " : "", res[p].wall_ms / 1000.0);
    for (int p = PEER_GLU; p < N_PEERS; ++p)
        if (use[p] && res[p].ok)
            printf("  %s: %.0f pixels covered in the last frame\n", k_peer_names[p],
                   res[p].covered_px);
    if (use[PEER_GLU] && res[PEER_GLU].ok)
        printf("  glu: %llu face occurrences; %llu GL errors from GLU's fixed-function calls "
               "drained\n",
               (unsigned long long)res[PEER_GLU].faces,
               (unsigned long long)res[PEER_GLU].gl_errors);
}

static void csv_row(FILE *f, const char *scene, const args *a, const char *name, const bp_result *r,
                    const bp_result *sw)
{
    fprintf(
        f,
        "%s,%s,%d,%d,%g,%u,%d,%.4f,%.4f,%.2f,%.0f,%.0f,%.5g,%.5g,%.5g,%.5g,%.5g,%llu,%llu,%u,%.6g,",
        scene, name, a->w, a->h, a->error_px, r->frames, r->ok, r->median_ms, r->p99_ms,
        r->first_frame_ms, r->peak_rss_bytes, r->triangles, ratio(sw->median_ms, r->median_ms),
        ratio(sw->p99_ms, r->p99_ms), ratio(sw->first_frame_ms, r->first_frame_ms),
        ratio(sw->peak_rss_bytes, r->peak_rss_bytes), ratio(sw->triangles, r->triangles),
        (unsigned long long)r->faces, (unsigned long long)r->refused_faces, r->crashed_faces,
        r->param);
    if (r->covered_px > 0.0) /* glu, occt; splinewalk's frame is not read back: empty */
        fprintf(f, "%.0f", r->covered_px);
    fputc('\n', f);
}

static const char k_csv_header[] =
    "scene,peer,width,height,error_px,frames,ok,median_ms,p99_ms,first_frame_ms,peak_rss_bytes,"
    "triangles_per_frame,ratio_median,ratio_p99,ratio_first_frame,ratio_peak_rss,"
    "ratio_triangles,face_occurrences,refused_faces,crashed_faces,occt_deflection,covered_px\n";

/* Runs the peers on one scene; prints its table; appends CSV rows to csv (may be NULL). */
static int run_scene(const args *a, const char *scene, FILE *csv)
{
    char brep_buf[4096], err[512];
    bp_job job = {.scene = scene,
                  .brep = a->brep ? a->brep : brep_for(scene, brep_buf, sizeof brep_buf),
                  .frames = a->frames,
                  .warmup_passes = a->warmup,
                  .passes = a->passes,
                  .width = a->w,
                  .height = a->h,
                  .error_px = a->error_px,
                  .static_lods = a->static_lods,
                  .occlusion = a->occlusion,
                  .exact_edges = a->exact_edges,
                  .kept_grids = a->kept_grids};
    sw_rt_camera_path path;
    memset(&path, 0, sizeof path);
    if (bp_job_path(&job, a->path_file, &path, err, sizeof err) != 0) {
        fprintf(stderr, "bench_peers: %s: %s\n", scene, err);
        return -1;
    }
    bp_result res[N_PEERS];
    memset(res, 0, sizeof res);
    int failed = 0;
    for (int p = 0; p < N_PEERS; ++p)
        if (a->use[p] && bp_run_in_child(k_peer_fns[p], &job, &res[p]) != 0) {
            fprintf(stderr, "bench_peers: %s: %s: %s\n", scene, k_peer_names[p], res[p].note);
            failed = 1;
        }
    printf("\n%s (BREP: %s), %u frames x %u counted passes after %u warm-up, path: %s%s%s%s%s\n",
           scene, job.brep ? job.brep : "none", a->frames, a->passes, a->warmup,
           a->path_file ? a->path_file : "orbit of the scene box",
           a->static_lods ? "" : "; splinewalk without static LODs",
           a->occlusion ? "" : "; splinewalk without occlusion culling",
           a->exact_edges ? "" : "; splinewalk with trim textures only",
           a->kept_grids ? "" : "; splinewalk evaluating every grid in each frame");
    printf("  peer       |  frame ms: median      p99 | first (ms) | peak RSS MB | triangles | "
           "splinewalk / peer: median p99 first RSS triangles\n");
    for (int p = 0; p < N_PEERS; ++p)
        if (a->use[p]) {
            print_row(k_peer_names[p], &res[p], &res[PEER_SW]);
            if (csv)
                csv_row(csv, scene, a, k_peer_names[p], &res[p], &res[PEER_SW]);
        }
    print_notes(res, a->use);
    sw_rt_path_free(&path);
    return failed ? -1 : 0;
}

int main(int argc, char **argv)
{
    sw_cli_install_modules(); /* CAD files, .exr, static LOD builds */
    args a;
    int pr = parse(argc, argv, &a);
    if (pr != 0) {
        fputs(k_usage, pr > 0 ? stdout : stderr);
        free(a.scenes);
        return pr > 0 ? 0 : 2;
    }
    const char *lp = getenv("LP_NUM_THREADS"), *egl = getenv("EGL_PLATFORM");
    if (!a.glibc_malloc)
        sw_cli_keep_freed_memory(); /* before the peers' children are forked */
    printf("bench_peers: %dx%d, eps_img %g px, LP_NUM_THREADS=%s, EGL_PLATFORM=%s, %ld "
           "processors online, malloc %s\n",
           a.w, a.h, a.error_px, lp ? lp : "(unset)", egl ? egl : "(unset)",
           sysconf(_SC_NPROCESSORS_ONLN),
           a.glibc_malloc ? "glibc's defaults" : "keeping freed memory");
    char tmp[4200];
    FILE *csv = NULL;
    if (a.csv) {
        snprintf(tmp, sizeof tmp, "%s.tmp-%ld", a.csv, (long)getpid());
        csv = fopen(tmp, "w");
        if (!csv) {
            fprintf(stderr, "bench_peers: %s: cannot write\n", tmp);
            free(a.scenes);
            return 1;
        }
        fputs(k_csv_header, csv);
    }
    int rc = 0;
    for (int s = 0; s < a.n_scenes; ++s)
        rc |= run_scene(&a, a.scenes[s], csv) != 0;
    if (csv) {
        int bad = ferror(csv) | fclose(csv);
        if (bad || rename(tmp, a.csv) != 0) {
            fprintf(stderr, "bench_peers: %s: write failed\n", a.csv);
            remove(tmp);
            rc = 1;
        }
    }
    free(a.scenes);
    return rc;
}
