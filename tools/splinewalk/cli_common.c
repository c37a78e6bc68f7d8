/* SPDX-License-Identifier: MIT */
/* Helpers shared by the splinewalk subcommands: argument parsing, progress, error reports. */
#include "cli.h"
#include "sw_rt.h"

#include "sw_safe_write.h"

#include <malloc.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

int sw_cli_is_help(const char *arg)
{
    return strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0;
}

int sw_cli_print_help(int argc, char **argv, const char *usage)
{
    for (int i = 1; i < argc; i++) {
        if (sw_cli_is_help(argv[i])) {
            fputs(usage, stdout);
            return 1;
        }
    }
    return 0;
}

int sw_cli_report(const char *cmd, const sw_status *status)
{
    fprintf(stderr, "splinewalk %s: %s (%s): %s\n", cmd, sw_result_str(status->result),
            sw_result_id_str(status->result),
            status->message[0] ? status->message : "(no details)");
    return 1;
}

int sw_cli_check_output(const char *cmd, const char *path, unsigned flags)
{
    sw_status status = {0};
    return sw__out_check(path, flags, &status) == SW_OK ? 0 : sw_cli_report(cmd, &status);
}

static struct {
    int active;
    int last_quarter;
    char stage[64];
} g_progress;

void sw_cli_progress(void *user_data, double fraction, const char *stage)
{
    (void)user_data;
    if (!(fraction >= 0.0))
        fraction = 0.0;
    if (fraction > 1.0)
        fraction = 1.0;
    if (isatty(STDERR_FILENO)) {
        int filled = (int)(fraction * 30.0);
        fprintf(stderr, "\r[%.*s%*s] %3d%% %-40.40s", filled,
                "==============================", 30 - filled, "", (int)(fraction * 100.0),
                stage ? stage : "");
        g_progress.active = 1;
        return;
    }
    int quarter = (int)(fraction * 4.0); /* logs stay short */
    if (!g_progress.active || quarter > g_progress.last_quarter ||
        (stage && strncmp(stage, g_progress.stage, sizeof g_progress.stage - 1) != 0)) {
        fprintf(stderr, "  %3d%% %s\n", (int)(fraction * 100.0), stage ? stage : "");
        g_progress.last_quarter = quarter;
        snprintf(g_progress.stage, sizeof g_progress.stage, "%s", stage ? stage : "");
        g_progress.active = 1;
    }
}

void sw_cli_progress_end(void)
{
    if (g_progress.active && isatty(STDERR_FILENO))
        fputc('\n', stderr);
    memset(&g_progress, 0, sizeof g_progress);
}

void sw_cli_warning(void *user_data, const char *message)
{
    (void)user_data;
    if (g_progress.active && isatty(STDERR_FILENO))
        fputc('\n', stderr);
    fprintf(stderr, "warning: %s\n", message);
}

static struct {
    sw_cli_face_note *notes;
    size_t n, cap;
} g_faces;

static void collect_face(void *user_data, const sw_face_problem *p)
{
    (void)user_data;
    if (g_faces.n == g_faces.cap) {
        size_t cap = g_faces.cap ? 2 * g_faces.cap : 16;
        sw_cli_face_note *grown = realloc(g_faces.notes, cap * sizeof *grown);
        if (!grown)
            return; /* the warning line still names it */
        g_faces.notes = grown, g_faces.cap = cap;
    }
    sw_cli_face_note *n = &g_faces.notes[g_faces.n++];
    n->face = p->face, n->entity = p->entity, n->action = p->action, n->reason = p->reason;
    snprintf(n->name, sizeof n->name, "%s", p->name ? p->name : "");
}

size_t sw_cli_face_notes(const sw_cli_face_note **out)
{
    *out = g_faces.notes;
    return g_faces.n;
}

sw_result sw_cli_load_scene(const char *path, uint32_t flags, sw_scene *out, sw_status *status)
{
    g_faces.n = 0;
    sw_scene_load_desc desc = {path, sw_cli_progress, sw_cli_warning, NULL, collect_face, flags};
    sw_result r = sw_scene_load(&desc, out, status);
    sw_cli_progress_end();
    return r;
}

void sw_cli_print_import_notes(FILE *f, const char *cmd, const sw_scene_info *info)
{
    if (!info->faces_skipped && !info->faces_repaired && !info->partial)
        return;
    fprintf(f, "%s: %u faces skipped, %u repaired (each named in a warning above)%s\n", cmd,
            info->faces_skipped, info->faces_repaired,
            info->partial ? "; the file is truncated and was imported in part (--partial)" : "");
}

int sw_cli_report_load(const char *cmd, const sw_status *status)
{
    int rc = sw_cli_report(cmd, status);
    if (status->result == SW_ERR_TRUNCATED)
        fprintf(stderr, "splinewalk %s: --partial imports what is whole of a truncated file\n",
                cmd);
    return rc;
}

void sw_cli_keep_freed_memory(void)
{
    mallopt(M_MMAP_THRESHOLD, 32 << 20); /* glibc's largest */
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
}

void sw_cli_print_frame_stats(const char *label, const sw_frame_stats *s)
{
    printf("%s: patches drawn trimmed by trim textures %llu, untrimmed %llu, culled %llu "
           "(%llu evaluated on the GPU, %llu by the exact path); faces drawn %llu, culled %llu; "
           "%llu triangles; "
           "%llu trim textures (%llu texels, %llu kept from earlier frames, %llu atlas pages)\n",
           label, (unsigned long long)s->patches_trimmed, (unsigned long long)s->patches_untrimmed,
           (unsigned long long)s->patches_culled, (unsigned long long)s->patches_gpu_evaluated,
           (unsigned long long)s->patches_exact, (unsigned long long)s->faces_drawn,
           (unsigned long long)s->faces_culled, (unsigned long long)s->triangles,
           (unsigned long long)s->trim_textures, (unsigned long long)s->trim_texels,
           (unsigned long long)s->trim_reused, (unsigned long long)s->atlas_pages);
    if (s->trim_exact > 0 || s->trim_exact_fallbacks > 0)
        printf("%*s  exact trim edges: %llu trimmed draws cut per fragment by their loops, not by "
               "a texture (%llu kept a texture: over the edge grid's limits)\n",
               (int)strlen(label), "", (unsigned long long)s->trim_exact,
               (unsigned long long)s->trim_exact_fallbacks);
    if (s->shapes_drawn + s->shapes_culled + s->shapes_skipped > 0)
        printf("%*s  outlines: %llu drawn, %llu culled, %llu skipped (a loop without area after "
               "the near-plane cut), %llu pieces drawn as chords\n",
               (int)strlen(label), "", (unsigned long long)s->shapes_drawn,
               (unsigned long long)s->shapes_culled, (unsigned long long)s->shapes_skipped,
               (unsigned long long)s->shape_fallbacks);
    if (s->hierarchy_nodes > 0)
        printf("%*s  hierarchy: %llu nodes drawn, %llu refinement rounds\n", (int)strlen(label), "",
               (unsigned long long)s->hierarchy_nodes, (unsigned long long)s->refine_rounds);
    if (s->static_drawn > 0 || s->static_requests > 0)
        printf("%*s  static LODs: %llu super-surface instances drawn (%llu faces, %llu "
               "triangles), %llu builds queued\n",
               (int)strlen(label), "", (unsigned long long)s->static_drawn,
               (unsigned long long)s->static_faces, (unsigned long long)s->static_triangles,
               (unsigned long long)s->static_requests);
    if (s->proxies_drawn > 0)
        printf(
            "%*s  cluster proxies: %llu drawn for %llu super-surface instances (%llu triangles)\n",
            (int)strlen(label), "", (unsigned long long)s->proxies_drawn,
            (unsigned long long)s->proxy_instances, (unsigned long long)s->proxy_triangles);
    if (s->resident_triangles > 0)
        printf("%*s  kept on the GPU: %llu of the triangles drawn from buffers kept between frames "
               "(static levels, patch grids); %llu patch grids found kept, %llu evaluated\n",
               (int)strlen(label), "", (unsigned long long)s->resident_triangles,
               (unsigned long long)s->grid_hits, (unsigned long long)s->grid_misses);
    if (s->bound_exceeded > 0 && s->bound_excess_px > 0.0)
        printf("%*s  error bound: %llu pieces drawn over it (worst known excess %.3g px)\n",
               (int)strlen(label), "", (unsigned long long)s->bound_exceeded, s->bound_excess_px);
    else if (s->bound_exceeded > 0)
        printf("%*s  error bound: %llu pieces drawn over it (their excess is not known)\n",
               (int)strlen(label), "", (unsigned long long)s->bound_exceeded);
    if (s->budget_coarsened > 0)
        printf("%*s  memory budget: %llu pieces drawn coarser than the view asks (a share of "
               "the budget is spent; --memory-budget)\n",
               (int)strlen(label), "", (unsigned long long)s->budget_coarsened);
    printf("%*s  upload: %.2f MiB of vertices, indices and patch data sent for the draw\n",
           (int)strlen(label), "", (double)s->upload_bytes / (1024.0 * 1024.0));
    printf("%*s  time: hierarchy builds %.1f ms, tessellate %.1f ms, trim textures %.1f ms, draw "
           "%.1f ms, readback %.1f ms, write %.1f ms, total %.1f ms\n",
           (int)strlen(label), "", s->ms_hierarchy, s->ms_tessellate, s->ms_trim, s->ms_draw,
           s->ms_readback, s->ms_write, s->ms_total);
}

const char *sw_cli_bundle_path(const char *rel, char *buf, size_t size)
{
    char exe[4096];
    const ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    char *slash = n > 0 ? (exe[n] = '\0', strrchr(exe, '/')) : NULL;
    if (!slash)
        return NULL;
    *slash = '\0'; /* bin/ */
    const int k = snprintf(buf, size, "%s/../share/splinewalk/%s", exe, rel);
    return k > 0 && (size_t)k < size && access(buf, F_OK) == 0 ? buf : NULL;
}

/* "1.50 GiB", "12.0 MiB", "512 KiB": a budget as a person reads it. */
static void human_bytes(uint64_t b, char *buf, size_t size)
{
    if (b >= (uint64_t)1 << 30)
        snprintf(buf, size, "%.2f GiB", (double)b / (double)(1 << 30));
    else if (b >= (uint64_t)1 << 20)
        snprintf(buf, size, "%.1f MiB", (double)b / (double)(1 << 20));
    else
        snprintf(buf, size, "%.0f KiB", (double)b / 1024.0);
}

void sw_cli_memory_budget_line(sw_renderer renderer, char *buf, size_t size)
{
    sw_memory_budget b;
    buf[0] = '\0';
    if (sw_renderer_memory_budget(renderer, &b, NULL) != SW_OK)
        return;
    char host[32], gpu[32], reported[64] = "the driver reports no GPU memory";
    human_bytes(b.host_bytes, host, sizeof host);
    human_bytes(b.gpu_bytes, gpu, sizeof gpu);
    if (b.gpu_reported_bytes) {
        char r[32];
        human_bytes(b.gpu_reported_bytes, r, sizeof r);
        snprintf(reported, sizeof reported, "the driver reports %s", r);
    }
    snprintf(buf, size, "memory budget: host %s, GPU %s (%s)\n", host, gpu, reported);
}
