/* SPDX-License-Identifier: MIT */
/* splinewalk info SCENE [--json] [--partial] */
#include "cli.h"
#include "sw_lod_static_set.h"
#include "sw_rt.h"

#include <stdio.h>
#include <string.h>

static const char k_usage[] =
    "usage: splinewalk info SCENE [--json] [--partial]\n"
    "\n"
    "Describes a scene (.sws, or any file `import` reads, imported on the fly): surfaces by kind\n"
    "of their source geometry, trimmed surfaces, trim loops and curves, Bézier patches after\n"
    "extraction, maximum degrees, control points, nodes and instances, face occurrences after\n"
    "instancing, adjacent face pairs, the bounding box and the memory the loaded scene takes,\n"
    "and the static LOD cache a .sws holds (`build-lod`): the settings it was built with, its\n"
    "super-surfaces with levels, and per level their triangles, vertices, bytes and error\n"
    "bounds, or why it cannot be used (an older version, a damaged section: renderers build the\n"
    "levels again); whether it fits the scene's clustering is checked when a renderer first\n"
    "uses it.\n"
    "A CAD file's faces skipped or repaired by the import are each named in a warning on stderr\n"
    "and counted (as `import` does); a truncated IGES file is refused unless --partial.\n"
    "\n"
    "options:\n"
    "  --json       print one JSON object instead of text\n"
    "  --partial    import what is whole of a truncated file (see `import --help`)\n"
    "  -h, --help   this text\n";

static void print_json_string(const char *s)
{
    putchar('"');
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            printf("\\%c", c);
        else if (c < 0x20)
            printf("\\u%04x", c);
        else
            putchar(c);
    }
    putchar('"');
}

static void print_json_faces(void);
static void print_lod_json(int got, const sw_lod_static_cache_summary *c, size_t bytes,
                           const sw_status *why);

static void print_json(const char *path, const sw_scene_info *in, int got,
                       const sw_lod_static_cache_summary *lods, size_t lod_bytes,
                       const sw_status *lod_status)
{
    printf("{\"file\": ");
    print_json_string(path);
    printf(", ");
    print_json_faces();
    printf("\"faces\": %u, \"faces_by_kind\": {", in->faces);
    for (uint32_t k = 0; k < SW_SURFACE_KIND_COUNT; k++)
        printf("%s\"%s\": %u", k ? ", " : "", sw_surface_kind_name(k), in->faces_by_kind[k]);
    printf("}, \"trimmed_faces\": %u, \"trim_loops\": %u, \"trim_curves\": %u, "
           "\"bezier_patches\": %llu, \"max_degree_u\": %u, \"max_degree_v\": %u, "
           "\"max_trim_curve_degree\": %u, \"control_points\": %llu, \"nodes\": %u, "
           "\"instances\": %u, \"face_occurrences\": %llu, \"adjacent_face_pairs\": %u, "
           "\"meshes\": %u, \"mesh_triangles\": %llu, \"mesh_occurrences\": %llu, "
           "\"triangle_occurrences\": %llu, \"shapes\": %u, \"shape_occurrences\": %llu, "
           "\"faces_skipped\": %u, \"faces_repaired\": %u, "
           "\"partial\": %s, "
           "\"bbox\": [%.17g, %.17g, %.17g, %.17g, %.17g, %.17g], \"memory_bytes\": %zu, ",
           in->trimmed_faces, in->loops, in->curves, (unsigned long long)in->bezier_patches,
           in->max_degree_u, in->max_degree_v, in->max_curve_degree,
           (unsigned long long)in->control_points, in->nodes, in->instances,
           (unsigned long long)in->face_occurrences, in->adjacent_face_pairs, in->meshes,
           (unsigned long long)in->mesh_triangles, (unsigned long long)in->mesh_occurrences,
           (unsigned long long)in->triangle_occurrences, in->shapes,
           (unsigned long long)in->shape_occurrences, in->faces_skipped, in->faces_repaired,
           in->partial ? "true" : "false", in->bbox_min[0], in->bbox_min[1], in->bbox_min[2],
           in->bbox_max[0], in->bbox_max[1], in->bbox_max[2], in->memory_bytes);
    print_lod_json(got, lods, lod_bytes, lod_status);
    printf("}\n");
}

/* The import's skipped and repaired faces as records: face index (null for a face the reader
 * dropped), the file's entity number (0: none), part name, what was done, the reason's id. */
static void print_json_faces(void)
{
    const sw_cli_face_note *n;
    size_t count = sw_cli_face_notes(&n);
    printf("\"face_problems\": [");
    for (size_t i = 0; i < count; i++) {
        printf("%s{\"face\": ", i ? ", " : "");
        if (n[i].face == UINT32_MAX)
            printf("null");
        else
            printf("%u", n[i].face);
        printf(", \"entity\": %u, \"name\": ", n[i].entity);
        print_json_string(n[i].name);
        printf(", \"action\": \"%s\", \"reason\": \"%s\"}",
               n[i].action == SW_FACE_REPAIRED ? "repaired" : "skipped",
               sw_result_id_str(n[i].reason));
    }
    printf("], ");
}

static void print_text(const char *path, const sw_scene_info *in)
{
    printf("%s\n", path);
    printf("  surfaces        %u (", in->faces);
    int first = 1;
    for (uint32_t k = 0; k < SW_SURFACE_KIND_COUNT; k++) {
        if (!in->faces_by_kind[k])
            continue;
        printf("%s%u %s", first ? "" : ", ", in->faces_by_kind[k], sw_surface_kind_name(k));
        first = 0;
    }
    printf(")\n");
    printf("  trimmed         %u surfaces, %u loops, %u curves (max degree %u)\n",
           in->trimmed_faces, in->loops, in->curves, in->max_curve_degree);
    printf("  Bézier patches  %llu after extraction; max degree %u x %u; %llu control points\n",
           (unsigned long long)in->bezier_patches, in->max_degree_u, in->max_degree_v,
           (unsigned long long)in->control_points);
    printf("  nodes           %u, instances %u, surfaces drawn %llu\n", in->nodes, in->instances,
           (unsigned long long)in->face_occurrences);
    printf("  adjacency       %u face pairs share an edge\n", in->adjacent_face_pairs);
    if (in->meshes)
        printf("  meshes          %u (%llu triangles); drawn %llu (%llu triangles)\n", in->meshes,
               (unsigned long long)in->mesh_triangles, (unsigned long long)in->mesh_occurrences,
               (unsigned long long)in->triangle_occurrences);
    if (in->shapes)
        printf("  outlines        %u; drawn %llu\n", in->shapes,
               (unsigned long long)in->shape_occurrences);
    printf("  bounding box    [%g %g %g] - [%g %g %g]\n", in->bbox_min[0], in->bbox_min[1],
           in->bbox_min[2], in->bbox_max[0], in->bbox_max[1], in->bbox_max[2]);
    printf("  memory          %.2f MiB\n", (double)in->memory_bytes / (1024.0 * 1024.0));
    if (in->faces_skipped || in->faces_repaired || in->partial)
        printf("  import          %u faces skipped, %u repaired%s\n", in->faces_skipped,
               in->faces_repaired, in->partial ? "; truncated file imported in part" : "");
}

/* The scene's LODS section summarized: 1 when it has one, 0 when none, -1 on a damaged one
 * (status set). */
static int lod_cache_of(sw_scene handle, const char *path, sw_lod_static_cache_summary *sum,
                        size_t *bytes, sw_status *status)
{
    sw_rt_scene *scene = NULL;
    if (sw_rt_scene_acquire(handle, &scene, status) != SW_OK)
        return -1;
    const void *data = NULL;
    sw_status none = {0};
    int got = 0;
    if (sw_sg_scene_lods(scene->sg, &data, bytes, &none) == SW_OK)
        got = sw_lod_static_cache_summarize(data, *bytes, path, sum, status) == SW_OK ? 1 : -1;
    else if (none.result != SW_ERR_NOT_FOUND) {
        *status = none;
        got = -1;
    }
    sw_rt_scene_release(scene);
    return got;
}

/* A level's arrays as the cache stores them. */
static double level_bytes(const sw_lod_static_cache_summary *c, uint32_t k)
{
    return (double)SW_LOD_STATIC_VERTEX_BYTES * (double)c->level_vertices[k] +
           (double)SW_LOD_STATIC_TRIANGLE_BYTES * (double)c->level_triangles[k];
}

static void print_lod_text(int got, const sw_lod_static_cache_summary *c, size_t bytes,
                           const sw_status *why)
{
    if (got < 0) {
        printf("  LOD cache       unusable (%s: %s): static LODs are built again on first use\n",
               sw_result_id_str(why->result), why->message);
        return;
    }
    if (got == 0) {
        printf("  LOD cache       none (`splinewalk build-lod` makes one; without it static LODs "
               "are built on first use)\n");
        return;
    }
    printf("  LOD cache       %.1f MiB: %u of %u super-surfaces with levels, up to %u levels, "
           "level 0 within δ %g-%g\n",
           (double)bytes / (1024.0 * 1024.0), c->chains, c->units, c->max_levels, c->delta_min,
           c->delta_max);
    const sw_lod_static_desc *d = &c->settings.levels;
    char delta[64];
    if (d->delta > 0.0)
        snprintf(delta, sizeof delta, "δ %g", d->delta);
    else
        snprintf(delta, sizeof delta, "δ %g x each super-surface's diagonal",
                 c->settings.delta_rel);
    printf("    built with    %s, %d simplified levels aiming at ε %g δ x %g^k, ε %s; level 0 at "
           "most %u vertices per patch, %u in all\n",
           delta, (int)d->n_levels, d->eps_first, d->eps_growth,
           c->settings.eps_rule == SW_LOD_STATIC_EPS_RULE ? "certified" : "of another rule",
           d->max_vertices_per_patch, d->max_vertices);
    for (uint32_t k = 0; k < c->max_levels; ++k) {
        printf("    level %u       %u super-surfaces, %llu triangles, %llu vertices, %.2f MiB, ε "
               "%g-%g",
               k, c->level_chains[k], (unsigned long long)c->level_triangles[k],
               (unsigned long long)c->level_vertices[k], level_bytes(c, k) / (1024.0 * 1024.0),
               c->level_eps_min[k], c->level_eps_max[k]);
        if (c->level_dropped[k])
            printf(" (%u of them not stored: too fine to draw, or a finer level's mesh)",
                   c->level_dropped[k]);
        printf("\n");
    }
    if (c->version < 3 || c->proxy_bytes == 0)
        printf("    proxies       none stored (walkthroughs build them in the background)\n");
    else if (c->proxies == 0)
        printf(
            "    proxies       none: no node of the instances' hierarchy has enough instances\n");
    else
        printf("    proxies       %u cluster proxies, %llu triangles, %llu vertices, %.2f MiB, "
               "error %g-%g, up to %llu instances each\n",
               c->proxies, (unsigned long long)c->proxy_triangles,
               (unsigned long long)c->proxy_vertices, (double)c->proxy_bytes / (1024.0 * 1024.0),
               c->proxy_err_min, c->proxy_err_max, (unsigned long long)c->proxy_instances);
}

static void print_lod_json(int got, const sw_lod_static_cache_summary *c, size_t bytes,
                           const sw_status *why)
{
    if (got == 0) {
        printf("\"lod_cache\": null");
        return;
    }
    if (got < 0) {
        printf("\"lod_cache\": {\"unusable\": \"%s\"}", sw_result_id_str(why->result));
        return;
    }
    const sw_lod_static_desc *d = &c->settings.levels;
    printf("\"lod_cache\": {\"bytes\": %zu, \"version\": %u, \"units\": %u, \"chains\": %u, "
           "\"delta_min\": %.17g, \"delta_max\": %.17g, \"settings\": {\"delta\": %.17g, "
           "\"delta_relative\": %.17g, \"levels\": %d, \"eps_first\": %.17g, \"eps_growth\": "
           "%.17g, \"eps_certified\": %s, \"max_vertices\": %u, \"max_vertices_per_patch\": %u}, "
           "\"levels\": [",
           bytes, c->version, c->units, c->chains, c->delta_min, c->delta_max, d->delta,
           c->settings.delta_rel, (int)d->n_levels, d->eps_first, d->eps_growth,
           c->settings.eps_rule == SW_LOD_STATIC_EPS_RULE ? "true" : "false", d->max_vertices,
           d->max_vertices_per_patch);
    for (uint32_t k = 0; k < c->max_levels; ++k)
        printf("%s{\"chains\": %u, \"not_stored\": %u, \"triangles\": %llu, \"vertices\": %llu, "
               "\"bytes\": %.0f, \"eps_min\": %.17g, \"eps_max\": %.17g}",
               k ? ", " : "", c->level_chains[k], c->level_dropped[k],
               (unsigned long long)c->level_triangles[k], (unsigned long long)c->level_vertices[k],
               level_bytes(c, k), c->level_eps_min[k], c->level_eps_max[k]);
    printf("], \"proxies\": ");
    if (c->version < 3 || c->proxy_bytes == 0)
        printf("null}");
    else
        printf("{\"count\": %u, \"triangles\": %llu, \"vertices\": %llu, \"bytes\": %zu, "
               "\"err_min\": %.17g, \"err_max\": %.17g, \"max_instances\": %llu}}",
               c->proxies, (unsigned long long)c->proxy_triangles,
               (unsigned long long)c->proxy_vertices, c->proxy_bytes, c->proxy_err_min,
               c->proxy_err_max, (unsigned long long)c->proxy_instances);
}

int sw_cli_info(int argc, char **argv)
{
    const char *path = NULL;
    int json = 0;
    uint32_t flags = 0;
    for (int i = 1; i < argc; i++) {
        if (sw_cli_is_help(argv[i])) {
            fputs(k_usage, stdout);
            return 0;
        } else if (!strcmp(argv[i], "--json")) {
            json = 1;
        } else if (!strcmp(argv[i], "--partial")) {
            flags |= SW_LOAD_PARTIAL;
        } else if (argv[i][0] != '-' && !path) {
            path = argv[i];
        } else {
            fprintf(stderr, "splinewalk info: unexpected argument '%s'\n%s", argv[i], k_usage);
            return 2;
        }
    }
    if (!path) {
        fprintf(stderr, "splinewalk info: need SCENE\n%s", k_usage);
        return 2;
    }
    sw_status status = {0};
    sw_scene scene;
    if (sw_cli_load_scene(path, flags, &scene, &status) != SW_OK)
        return sw_cli_report_load("info", &status);
    sw_scene_info info;
    sw_lod_static_cache_summary lods;
    size_t lod_bytes = 0;
    sw_result r = sw_scene_get_info(scene, &info, &status);
    sw_status lod_status = {0};
    const int got = r == SW_OK ? lod_cache_of(scene, path, &lods, &lod_bytes, &lod_status) : -1;
    sw_scene_destroy(scene);
    if (r != SW_OK)
        return sw_cli_report("info", &status);
    /* a cache that cannot be used is the scene's news, not a failure to describe it: renderers
     * build the levels again */
    if (json)
        print_json(path, &info, got, &lods, lod_bytes, &lod_status);
    else
        print_text(path, &info);
    if (!json)
        print_lod_text(got, &lods, lod_bytes, &lod_status);
    return 0;
}
