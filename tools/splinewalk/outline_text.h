/* SPDX-License-Identifier: MIT */
/* The outline text format of `splinewalk outline` (docs/outlines.md): blocks of SVG path data,
 * each a filled planar outline placed in 3D, parsed into sw_nodes.h shape descs. Pure: no I/O
 * (the caller reads the file), no global state. */
#ifndef SW_CLI_OUTLINE_TEXT_H
#define SW_CLI_OUTLINE_TEXT_H

#include <splinewalk/sw_nodes.h>

#include <stddef.h>
#include <stdint.h>

/* Limits (each refused with a message past it). A label's text: 1..1024 bytes. */
#define SW_OUTLINE_MAX_TEXT (64u << 20)  /* bytes of a file */
#define SW_OUTLINE_MAX_ITEMS 60000u      /* outlines of a file (a node scene holds 65,535 nodes) */
#define SW_OUTLINE_MAX_CURVES (1u << 20) /* curves of one outline */

typedef struct sw_outline_item {
    char name[64];        /* "" when none */
    int line;             /* of its `outline` or `label` line */
    float color[4];       /* linear RGBA */
    double transform[12]; /* row-major 3 x 4: plane (x, y) -> origin + x x-axis + y y-axis */
    sw_shape_desc shape;  /* an outline: loops and curves owned by the document */
    int is_label;         /* a `label` line: `label` below, `shape` empty */
    sw_label_desc label;  /* text and font owned by the document */
} sw_outline_item;

typedef struct sw_outline_doc {
    sw_outline_item *items;
    size_t n_items;
    void *storage; /* the items' loops, curves and numbers */
} sw_outline_doc;

/* Parses `text` (len bytes, not NUL-terminated necessarily). On failure returns non-zero and
 * writes "FILE:LINE:COLUMN: what is wrong" to err (file names the text in it); *out is then
 * empty. */
int sw_outline_parse(const char *text, size_t len, const char *file, sw_outline_doc *out, char *err,
                     size_t err_size);
void sw_outline_doc_free(sw_outline_doc *doc);

#endif
