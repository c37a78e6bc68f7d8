/* SPDX-License-Identifier: MIT */
/* libFuzzer harness for the outline text format (tools/splinewalk/outline_text.c). Any text must
 * either be refused with a "FILE:LINE:COLUMN: " message and nothing handed out, or give outlines
 * that every later step can take as they are: each item has loops, each loop curves of degree 1
 * to 3 with degree + 1 finite control points, knots 0...0 1...1, weights positive and finite (or
 * none), each curve ending bit for bit where the next begins (the last where the first begins),
 * colours inside [0, 1], a finite transform whose third column is a unit vector; a label has
 * its NUL-terminated text of at most 1,024 bytes, a positive finite size, align 0..2, no loops.
 * Planted: the closing line of a subpath left out: it fails on the first seed. */
#include "outline_text.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static void check_curve(const sw_trim_curve *c)
{
    if (c->degree < 1 || c->degree > 3 || c->count != c->degree + 1)
        abort();
    for (uint32_t i = 0; i < 2 * c->count; i++)
        if (!isfinite(c->points[i]) || c->knots[i] != (i < c->count ? 0.0 : 1.0))
            abort();
    for (uint32_t i = 0; c->weights && i < c->count; i++)
        if (!(c->weights[i] > 0.0) || !isfinite(c->weights[i]))
            abort();
}

static void check_label(const sw_outline_item *it)
{
    const sw_label_desc *l = &it->label;
    if (!l->text || strlen(l->text) > 1024 || !(l->size > 0.0) || !isfinite(l->size) ||
        l->align < 0 || l->align > 2 || (l->screen_size != 0 && l->screen_size != 1) ||
        (l->font_path && strlen(l->font_path) > 4095) || it->shape.loop_count != 0)
        abort();
}

static void check_item(const sw_outline_item *it)
{
    if (it->is_label) {
        check_label(it);
        return;
    }
    if (it->shape.loop_count == 0 || !it->shape.loops)
        abort();
    for (int k = 0; k < 4; k++)
        if (!(it->color[k] >= 0.0f && it->color[k] <= 1.0f))
            abort();
    for (int k = 0; k < 12; k++)
        if (!isfinite(it->transform[k]))
            abort();
    const double *t = it->transform;
    if (fabs(t[2] * t[2] + t[6] * t[6] + t[10] * t[10] - 1.0) > 1e-9)
        abort();
    for (uint32_t l = 0; l < it->shape.loop_count; l++) {
        const sw_trim_loop *lp = &it->shape.loops[l];
        if (lp->curve_count == 0)
            abort();
        for (uint32_t k = 0; k < lp->curve_count; k++) {
            const sw_trim_curve *c = &lp->curves[k], *n = &lp->curves[(k + 1) % lp->curve_count];
            check_curve(c);
            if (c->points[2 * c->degree] != n->points[0] ||
                c->points[2 * c->degree + 1] != n->points[1])
                abort();
        }
    }
}

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);
int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    sw_outline_doc doc;
    char err[256];
    int bad = sw_outline_parse((const char *)data, size, "fuzz", &doc, err, sizeof err);
    if (bad) {
        if (doc.n_items || doc.items || strncmp(err, "fuzz:", 5) != 0)
            abort();
        return 0;
    }
    if (doc.n_items == 0)
        abort();
    for (size_t i = 0; i < doc.n_items; i++)
        check_item(&doc.items[i]);
    sw_outline_doc_free(&doc);
    return 0;
}
