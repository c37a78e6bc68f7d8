/* SPDX-License-Identifier: MIT */
/* splinewalk info SCENE [--json] [--partial] */
#include "cli.h"

#include <stdio.h>
#include <string.h>

static const char k_usage[] =
    "usage: splinewalk info SCENE [--json] [--partial]\n"
    "\n"
    "Describes a scene (.sws, or any file `import` reads, imported on the fly): surfaces by kind\n"
    "of their source geometry, trimmed surfaces, trim loops and curves, Bézier patches after\n"
    "extraction, maximum degrees, control points, nodes and instances, face occurrences after\n"
    "instancing, adjacent face pairs, the bounding box and the memory the loaded scene takes.\n"
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

static void print_json(const char *path, const sw_scene_info *in)
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
           "\"triangle_occurrences\": %llu, \"faces_skipped\": %u, \"faces_repaired\": %u, "
           "\"partial\": %s, "
           "\"bbox\": [%.17g, %.17g, %.17g, %.17g, %.17g, %.17g], \"memory_bytes\": %zu}\n",
           in->trimmed_faces, in->loops, in->curves, (unsigned long long)in->bezier_patches,
           in->max_degree_u, in->max_degree_v, in->max_curve_degree,
           (unsigned long long)in->control_points, in->nodes, in->instances,
           (unsigned long long)in->face_occurrences, in->adjacent_face_pairs, in->meshes,
           (unsigned long long)in->mesh_triangles, (unsigned long long)in->mesh_occurrences,
           (unsigned long long)in->triangle_occurrences, in->faces_skipped, in->faces_repaired,
           in->partial ? "true" : "false", in->bbox_min[0], in->bbox_min[1],
           in->bbox_min[2], in->bbox_max[0], in->bbox_max[1], in->bbox_max[2], in->memory_bytes);
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
    printf("  bounding box    [%g %g %g] - [%g %g %g]\n", in->bbox_min[0], in->bbox_min[1],
           in->bbox_min[2], in->bbox_max[0], in->bbox_max[1], in->bbox_max[2]);
    printf("  memory          %.2f MiB\n", (double)in->memory_bytes / (1024.0 * 1024.0));
    if (in->faces_skipped || in->faces_repaired || in->partial)
        printf("  import          %u faces skipped, %u repaired%s\n", in->faces_skipped,
               in->faces_repaired, in->partial ? "; truncated file imported in part" : "");
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
    sw_result r = sw_scene_get_info(scene, &info, &status);
    sw_scene_destroy(scene);
    if (r != SW_OK)
        return sw_cli_report("info", &status);
    if (json)
        print_json(path, &info);
    else
        print_text(path, &info);
    return 0;
}
