/* SPDX-License-Identifier: MIT */
/* splinewalk outline OUTLINES.txt -o OUT.sws [--into SCENE] */
#include "cli.h"
#include "outline_text.h"
#include "sw_hooks.h"
#include "sw_safe_read.h"

#include <splinewalk/sw_nodes.h>

#include <stdio.h>
#include <string.h>

static const char k_usage[] =
    "usage: splinewalk outline OUTLINES.txt -o OUT.sws [--into SCENE]\n"
    "\n"
    "Places filled planar outlines (floor plans, markings, signs) into a scene: each block of\n"
    "OUTLINES.txt (docs/outlines.md) is SVG path data (M L H V Q C A Z, absolute or relative)\n"
    "in the plane of its `origin`, `x-axis` and `y-axis`, filled even-odd in its `color`.\n"
    "A `label \"TEXT\"` line places a line of text (glyph outlines through FreeType), fixed in\n"
    "that plane or, with `screen`, facing the camera at a constant size in pixels.\n"
    "Curves stay curves: lines, quadratic and cubic Béziers as given, arcs as exact conics;\n"
    "frames draw them with exact anti-aliased edges at any zoom, hidden by what lies in front,\n"
    "shown on a surface they lie on. With --into, SCENE's content (a .sws, STEP, IGES, BREP or\n"
    ".tsm file) comes first, under an import node; a .sws's static LOD cache is not carried over\n"
    "(run `splinewalk build-lod` on OUT.sws again). Writes OUT.sws (a temporary, then renamed).\n"
    "A mistake in OUTLINES.txt is reported as FILE:LINE:COLUMN and nothing is written.\n"
    "\n"
    "options:\n"
    "  -o, --output FILE   the .sws file to write (required)\n"
    "  --into SCENE        the scene the outlines are added to (default: none, outlines only)\n"
    "  -h, --help          this text\n";

/* The outlines as SHAPE nodes; a refused one is named by its line. */
static int add_outlines(sw_scene scene, const sw_outline_doc *doc, const char *file)
{
    for (size_t i = 0; i < doc->n_items; i++) {
        const sw_outline_item *it = &doc->items[i];
        sw_node_desc d = {0};
        d.kind = it->is_label ? SW_NODE_LABEL : SW_NODE_SHAPE;
        d.shape = &it->shape;
        d.label = &it->label;
        d.name = it->name[0] ? it->name : NULL;
        memcpy(d.color, it->color, sizeof d.color);
        memcpy(d.transform, it->transform, sizeof d.transform);
        sw_status st = {0};
        sw_node n;
        if (sw_node_add(scene, &d, &n, &st) != SW_OK) {
            fprintf(stderr, "splinewalk outline: %s (%s): %s:%d: %s %zu%s%s: %s\n",
                    sw_result_str(st.result), sw_result_id_str(st.result), file, it->line,
                    it->is_label ? "label" : "outline", i + 1, it->name[0] ? " " : "", it->name,
                    st.message);
            return 1;
        }
    }
    return 0;
}

static int import_scene(sw_scene scene, const char *path)
{
    sw_node_desc d = {0};
    d.kind = SW_NODE_IMPORT;
    d.import_path = path;
    d.import_warning = sw_cli_warning;
    sw_status st = {0};
    sw_node n;
    if (sw_node_add(scene, &d, &n, &st) != SW_OK)
        return sw_cli_report("outline", &st);
    return 0;
}

static int parse_file(const char *path, sw_outline_doc *doc)
{
    char *text = NULL;
    size_t len = 0;
    sw_status st = {0};
    if (sw__in_read_all(path, SW_OUTLINE_MAX_TEXT, "outline file", &text, &len, &st) != SW_OK)
        return sw_cli_report("outline", &st);
    char err[512];
    int bad = sw_outline_parse(text, len, path, doc, err, sizeof err);
    sw__free(text);
    if (bad)
        fprintf(stderr, "splinewalk outline: %s\n", err);
    return bad;
}

int sw_cli_outline(int argc, char **argv)
{
    const char *in = NULL, *out = NULL, *into = NULL;
    for (int i = 1; i < argc; i++) {
        if (sw_cli_is_help(argv[i])) {
            fputs(k_usage, stdout);
            return 0;
        } else if ((!strcmp(argv[i], "-o") || !strcmp(argv[i], "--output")) && i + 1 < argc) {
            out = argv[++i];
        } else if (!strcmp(argv[i], "--into") && i + 1 < argc) {
            into = argv[++i];
        } else if (argv[i][0] != '-' && !in) {
            in = argv[i];
        } else {
            fprintf(stderr, "splinewalk outline: unexpected argument '%s'\n%s", argv[i], k_usage);
            return 2;
        }
    }
    if (!in || !out) {
        fprintf(stderr, "splinewalk outline: need OUTLINES.txt and -o OUT.sws\n%s", k_usage);
        return 2;
    }
    if (sw_cli_check_output("outline", out, 0))
        return 1;
    sw_outline_doc doc;
    if (parse_file(in, &doc))
        return 1;
    sw_scene scene = {0};
    sw_status st = {0};
    sw_scene_desc sd = {in};
    int rc = sw_scene_create(&sd, &scene, &st) != SW_OK ? sw_cli_report("outline", &st) : 0;
    if (rc == 0 && into)
        rc = import_scene(scene, into);
    if (rc == 0)
        rc = add_outlines(scene, &doc, in);
    if (rc == 0 && sw_scene_save(scene, out, &st) != SW_OK)
        rc = sw_cli_report("outline", &st);
    if (rc == 0) {
        size_t loops = 0, labels = 0;
        for (size_t i = 0; i < doc.n_items; i++) {
            loops += doc.items[i].shape.loop_count;
            labels += doc.items[i].is_label;
        }
        printf("%s%s%s: %zu outlines (%zu loops), %zu labels -> %s\n", into ? into : "",
               into ? " + " : "", in, doc.n_items - labels, loops, labels, out);
    }
    if (scene.id)
        sw_scene_destroy(scene);
    sw_outline_doc_free(&doc);
    return rc;
}
