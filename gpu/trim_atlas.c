/* SPDX-License-Identifier: MIT */
/* The trim-texture atlas (Guthe et al. 2005 §4.4): every trim texture of a frame is a rectangle in
 * one layer ("page") of an R8 GL_TEXTURE_2D_ARRAY. New textures are sorted by height and packed
 * on shelves (placed side by side on the current row; a new row when the page's width is used
 * up; the next page when its height is), each with a gutter of SW__GPU_ATLAS_GUTTER texels so
 * that a page's fans can be drawn in one pass without toggling a neighbour's texels; then every
 * page that received entries is rendered with one render-target switch (trim_texture.c).
 *
 * Unlike the paper, which regenerates the atlas every frame, textures are kept across frames:
 * an entry is identified by its face (sw__gpu_trim_key) and its size, which the caller rounds to a
 * resolution class (frame.c: a power of two per direction), so a walkthrough re-renders a trim
 * texture only when its class changes. New entries are placed in free space (never used since the
 * last repack) of the pages already allocated. When they do not fit there, the atlas either grows
 * (new pages, every old page copied into the new array texture) or repacks: every entry of the
 * current frame packed from scratch and re-rendered from the loops kept on the CPU, the others
 * dropped. It repacks when the space taken by anything but this frame's entries (entries this
 * frame does not use, the height a shelf gives its shorter entries) is at least the space this
 * frame's entries need: growing would then copy pages of mostly dead texels, and with a new set
 * of textures every frame (an animated surface, a new scene per frame) add a page per frame up to
 * the texel limit. A new array texture is the atlas's dearest step (on llvmpipe ~50 ms per 4096^2
 * page: storage allocated and touched, old pages copied), so its size follows the need with
 * hysteresis: it grows by at least half its pages, and a repack keeps it while its page size is
 * right and it holds the pages needed, unless more than half of it has gone unused for
 * k_max_idle_frames frames (then the memory is given back). Entries unused for
 * k_max_idle_frames frames are dropped at the next begin (their loops freed; their texels stay dead
 * space until a repack).
 *
 * Loops are stored in entry-local texel coordinates, clamped to the entry's rectangle grown by one
 * texel: a loop straying outside its uv box (flattening tolerance, a box from rounded data) can
 * then reach at most its own gutter, which lookups never read (they are clamped half a texel
 * inside the rectangle, glsl/surface_trim.frag.glsl).
 */
#include "sw_gpu_internal.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { MIN_SIDE = 256, DEFAULT_MAX_SIDE = 4096, MAX_PAGES = 64 };
/* Frames an entry may go unused before begin drops it: a walkthrough coming back to a view within
 * about a second (at 60 Hz) finds its textures. */
static const uint64_t k_max_idle_frames = 64;

typedef struct entry {
    sw__gpu_trim_key key;
    int32_t w, h;
    int32_t layer, x0, y0; /* rectangle origin (inside the gutter); layer -1 = not placed */
    uint64_t used_frame;   /* frame counter value when last used */
    int rendered;          /* texels valid in the current array texture */
    int dead;              /* dropped by a repack; removed at the next begin */
    double *xy;            /* loop vertices, entry-local texel coordinates */
    uint32_t *counts;      /* per loop */
    uint32_t n_loops;
    size_t n_xy;
} entry;

typedef struct sort_key {
    int32_t h, w, id;
} sort_key;

typedef struct shelf {
    int32_t y, h, x;
} shelf;

typedef struct page {
    shelf *shelves;
    int32_t n_shelves, cap_shelves;
    int32_t top;
} page;

struct sw__gpu_atlas {
    GLuint tex;
    int32_t side, tex_side;
    int32_t n_pages, cap_layers; /* pages packed / layers allocated in tex */
    page pages[MAX_PAGES];
    entry *entries;
    int32_t n_entries, cap_entries;
    int32_t *table; /* open addressing over entries, -1 empty */
    uint32_t table_size;
    uint64_t frame;
    uint64_t busy_frame;    /* last frame that needed more than half of the allocated pages */
    struct sort_key *order; /* scratch */
    int32_t cap_order;
    float *clip; /* scratch: page vertices */
    size_t cap_clip;
    GLint *first;
    GLsizei *count;
    size_t cap_loops;
    sw__gpu_atlas_stats st;
};

static sw_result compact(struct sw__gpu_atlas *a, sw_status *status);
static void evict_idle(struct sw__gpu_atlas *a);

static int grow32(void **p, int32_t *cap, size_t need, size_t elem)
{
    size_t c = (size_t)*cap;
    int ok = sw__grow(p, &c, need, elem);
    *cap = (int32_t)c;
    return ok;
}

static uint64_t key_hash(const sw__gpu_trim_key *k, int32_t w, int32_t h)
{
    uint64_t x = k->scene * 0x9E3779B97F4A7C15ull;
    x ^= ((uint64_t)k->face << 32 | (uint64_t)(uint32_t)w) * 0xC2B2AE3D27D4EB4Full;
    x ^= (uint64_t)(uint32_t)h * 0x165667B19E3779F9ull;
    return x ^ (x >> 29);
}

static int key_equal(const entry *e, const sw__gpu_trim_key *k, int32_t w, int32_t h)
{
    return e->w == w && e->h == h && e->key.scene == k->scene && e->key.face == k->face &&
           e->key.first_loop == k->first_loop && e->key.n_loops == k->n_loops &&
           memcmp(e->key.uv_box, k->uv_box, sizeof k->uv_box) == 0;
}

static sw_result table_rebuild(struct sw__gpu_atlas *a, sw_status *status)
{
    uint32_t size = 64;
    while (size < 2u * (uint32_t)a->n_entries + 2u)
        size *= 2;
    if (size != a->table_size) {
        int32_t *t = sw__realloc(a->table, size * sizeof *t);
        if (!t)
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim atlas: out of memory");
        a->table = t;
        a->table_size = size;
    }
    memset(a->table, 0xff, a->table_size * sizeof *a->table);
    for (int32_t i = 0; i < a->n_entries; ++i) {
        const entry *e = &a->entries[i];
        uint32_t at = (uint32_t)key_hash(&e->key, e->w, e->h) & (a->table_size - 1);
        while (a->table[at] >= 0)
            at = (at + 1) & (a->table_size - 1);
        a->table[at] = i;
    }
    return SW_OK;
}

static struct sw__gpu_atlas *atlas_get(sw_gpu_context *ctx)
{
    if (!ctx->atlas)
        ctx->atlas = sw__calloc(1, sizeof *ctx->atlas);
    return ctx->atlas;
}

/* From the context's settings only, never the atlas: a visibility thread preparing the next
 * frame asks for it while the GL thread creates or repacks the atlas. */
static int32_t max_side(const sw_gpu_context *ctx)
{
    int32_t cap = ctx->atlas_max_side ? ctx->atlas_max_side : DEFAULT_MAX_SIDE, s = MIN_SIDE;
    if (cap > ctx->max_texture_size)
        cap = ctx->max_texture_size;
    while (s * 2 <= cap)
        s *= 2;
    return s;
}

void sw__gpu_atlas_set_max_side(sw_gpu_context *ctx, int32_t side)
{
    ctx->atlas_max_side = side;
}

int32_t sw__gpu_atlas_max_entry(const sw_gpu_context *ctx)
{
    return max_side(ctx) - 2 * SW__GPU_ATLAS_GUTTER;
}

sw_result sw__gpu_atlas_begin(sw_gpu_context *ctx, sw_status *status)
{
    struct sw__gpu_atlas *a = atlas_get(ctx);
    if (!a)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim atlas: out of memory");
    a->frame++;
    memset(&a->st, 0, sizeof a->st);
    evict_idle(a);
    return compact(a, status);
}

int32_t sw__gpu_atlas_find(sw_gpu_context *ctx, const sw__gpu_trim_key *key, int32_t w, int32_t h)
{
    struct sw__gpu_atlas *a = ctx->atlas;
    if (!a || !a->table_size)
        return -1;
    uint32_t at = (uint32_t)key_hash(key, w, h) & (a->table_size - 1);
    for (; a->table[at] >= 0; at = (at + 1) & (a->table_size - 1)) {
        entry *e = &a->entries[a->table[at]];
        if (!e->dead && key_equal(e, key, w, h)) {
            e->used_frame = a->frame;
            return a->table[at];
        }
    }
    return -1;
}

/* Entry-local texel coordinates of the loops, clamped to the rectangle grown by one texel. */
static int store_loops(entry *e, const sw_sg_polyline *loops, uint32_t n_loops)
{
    size_t n = 0;
    for (uint32_t k = 0; k < n_loops; ++k)
        n += loops[k].count;
    e->xy = sw__malloc((n ? n : 1) * 2 * sizeof *e->xy);
    e->counts = sw__malloc((n_loops ? n_loops : 1) * sizeof *e->counts);
    if (!e->xy || !e->counts)
        return 0;
    const double *b = e->key.uv_box;
    double su = e->w / (b[1] - b[0]), sv = e->h / (b[3] - b[2]);
    size_t at = 0;
    for (uint32_t k = 0; k < n_loops; ++k) {
        e->counts[k] = loops[k].count;
        for (uint32_t i = 0; i < loops[k].count; ++i, ++at) {
            double x = (loops[k].uv[2 * i] - b[0]) * su, y = (loops[k].uv[2 * i + 1] - b[2]) * sv;
            e->xy[2 * at] = fmin(fmax(x, -1.0), e->w + 1.0);
            e->xy[2 * at + 1] = fmin(fmax(y, -1.0), e->h + 1.0);
        }
    }
    e->n_loops = n_loops;
    e->n_xy = n;
    return 1;
}

sw_result sw__gpu_atlas_add(sw_gpu_context *ctx, const sw__gpu_trim_key *key, int32_t w, int32_t h,
                            const sw_sg_polyline *loops, uint32_t n_loops, int32_t *out,
                            sw_status *status)
{
    struct sw__gpu_atlas *a = atlas_get(ctx);
    *out = -1;
    int32_t cap = sw__gpu_atlas_max_entry(ctx);
    if (w < 1 || h < 1 || w > cap || h > cap)
        return sw__fail(status, SW_ERR_LIMIT, "trim texture %dx%d outside 1..%d", (int)w, (int)h,
                        (int)cap);
    if (!(key->uv_box[1] > key->uv_box[0]) || !(key->uv_box[3] > key->uv_box[2]))
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY, "trim texture over an empty uv box");
    if (!a || !grow32((void **)&a->entries, &a->cap_entries, (size_t)a->n_entries + 1,
                      sizeof *a->entries))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim atlas: out of memory");
    entry *e = &a->entries[a->n_entries];
    memset(e, 0, sizeof *e);
    e->key = *key;
    e->w = w;
    e->h = h;
    e->layer = -1;
    e->used_frame = a->frame;
    if (!store_loops(e, loops, n_loops)) {
        sw__free(e->xy);
        sw__free(e->counts);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim atlas: out of memory");
    }
    a->n_entries++;
    if (2u * (uint32_t)a->n_entries + 2u > a->table_size) {
        sw_result r = table_rebuild(a, status);
        if (r != SW_OK)
            return r;
    } else {
        uint32_t at = (uint32_t)key_hash(key, w, h) & (a->table_size - 1);
        while (a->table[at] >= 0)
            at = (at + 1) & (a->table_size - 1);
        a->table[at] = a->n_entries - 1;
    }
    *out = a->n_entries - 1;
    return SW_OK;
}

/* ---- packing --------------------------------------------------------------------------------- */

/* Shelf placement of a footprint fw x fh in page p of side s: the first shelf as tall as the
 * footprint (and not more than twice as tall) with room left, else a new shelf on top. */
static int page_place(page *p, int32_t s, int32_t fw, int32_t fh, int32_t *x, int32_t *y)
{
    for (int32_t i = 0; i < p->n_shelves; ++i) {
        shelf *sh = &p->shelves[i];
        if (sh->h >= fh && sh->h <= 2 * fh && sh->x + fw <= s) {
            *x = sh->x;
            *y = sh->y;
            sh->x += fw;
            return 1;
        }
    }
    if (p->top + fh > s || fw > s)
        return 0;
    if (!grow32((void **)&p->shelves, &p->cap_shelves, (size_t)p->n_shelves + 1,
                sizeof *p->shelves))
        return 0;
    p->shelves[p->n_shelves++] = (shelf){p->top, fh, fw};
    *x = 0;
    *y = p->top;
    p->top += fh;
    return 1;
}

static int place(struct sw__gpu_atlas *a, entry *e, int32_t max_pages)
{
    const int32_t g = SW__GPU_ATLAS_GUTTER, fw = e->w + 2 * g, fh = e->h + 2 * g;
    if (fw > a->side || fh > a->side)
        return 0;
    for (int32_t l = 0; l < max_pages; ++l) {
        if (l == a->n_pages) { /* an empty page; its shelf array is kept for reuse (freed with
                                  the atlas): zeroing the page would leak it after a reset */
            a->pages[l].n_shelves = 0;
            a->pages[l].top = 0;
            a->n_pages++;
        }
        int32_t x, y;
        if (page_place(&a->pages[l], a->side, fw, fh, &x, &y)) {
            e->layer = l;
            e->x0 = x + g;
            e->y0 = y + g;
            e->rendered = 0;
            return 1;
        }
    }
    return 0;
}

static int by_height(const void *pa, const void *pb)
{
    const sort_key *a = pa, *b = pb;
    if (a->h != b->h)
        return a->h > b->h ? -1 : 1;
    if (a->w != b->w)
        return a->w > b->w ? -1 : 1;
    return a->id - b->id;
}

/* Entry ids matching `pending` (not placed) or all used this frame, tallest first. */
static sw_result collect(struct sw__gpu_atlas *a, int all_used, int32_t *n_out, sw_status *status)
{
    if (!grow32((void **)&a->order, &a->cap_order, (size_t)a->n_entries + 1, sizeof *a->order))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim atlas: out of memory");
    int32_t n = 0;
    for (int32_t i = 0; i < a->n_entries; ++i) {
        const entry *e = &a->entries[i];
        if (e->dead || !(all_used ? e->used_frame == a->frame : e->layer < 0))
            continue;
        a->order[n++] = (sort_key){e->h, e->w, i};
    }
    qsort(a->order, (size_t)n, sizeof *a->order, by_height);
    *n_out = n;
    return SW_OK;
}

static void free_entry(entry *e)
{
    sw__free(e->xy);
    sw__free(e->counts);
    e->xy = NULL;
    e->counts = NULL;
}

/* Entries not used this frame die at a repack (their space is gone); their ids stay valid until
 * the next begin, which removes them. */
static void kill_unused(struct sw__gpu_atlas *a)
{
    for (int32_t i = 0; i < a->n_entries; ++i) {
        entry *e = &a->entries[i];
        e->layer = -1;
        e->rendered = 0;
        if (e->used_frame != a->frame && !e->dead) {
            free_entry(e);
            e->dead = 1;
        }
    }
}

/* Entries unused for more than k_max_idle_frames die (their space stays taken until a repack). */
static void evict_idle(struct sw__gpu_atlas *a)
{
    for (int32_t i = 0; i < a->n_entries; ++i) {
        entry *e = &a->entries[i];
        if (!e->dead && a->frame - e->used_frame > k_max_idle_frames) {
            free_entry(e);
            e->dead = 1;
        }
    }
}

/* Removes dead entries (ids change: only between frames). */
static sw_result compact(struct sw__gpu_atlas *a, sw_status *status)
{
    int32_t n = 0;
    for (int32_t i = 0; i < a->n_entries; ++i)
        if (!a->entries[i].dead)
            a->entries[n++] = a->entries[i];
    if (n == a->n_entries)
        return SW_OK;
    a->n_entries = n;
    return table_rebuild(a, status);
}

static sw_result alloc_layers(sw_gpu_context *ctx, struct sw__gpu_atlas *a, int32_t layers,
                              int keep, sw_status *status)
{
    GLuint tex = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D_ARRAY, tex);
    glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, GL_R8, a->side, a->side, layers);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    if (keep && a->tex && a->cap_layers > 0)
        glCopyImageSubData(a->tex, GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0, tex, GL_TEXTURE_2D_ARRAY, 0, 0,
                           0, 0, a->side, a->side, a->cap_layers);
    if (a->tex)
        glDeleteTextures(1, &a->tex);
    a->tex = tex;
    a->tex_side = a->side;
    a->cap_layers = layers;
    a->st.allocations++;
    (void)ctx;
    return sw__gpu_check(status, "trim atlas allocation");
}

/* Smallest power-of-two side (MIN_SIDE..max) whose single page takes every entry of `order` with
 * half its area to spare for later frames; the maximum when none does. */
static int32_t choose_side(const struct sw__gpu_atlas *a, int32_t n, int32_t max)
{
    const int32_t g = SW__GPU_ATLAS_GUTTER;
    double area = 0.0;
    int32_t tallest = 0, widest = 0;
    for (int32_t i = 0; i < n; ++i) {
        const entry *e = &a->entries[a->order[i].id];
        area += (double)(e->w + 2 * g) * (double)(e->h + 2 * g);
        tallest = e->h + 2 * g > tallest ? e->h + 2 * g : tallest;
        widest = e->w + 2 * g > widest ? e->w + 2 * g : widest;
    }
    int32_t s = MIN_SIDE;
    while (s < max && (2.0 * area > (double)s * s || tallest > s / 2 || widest > s / 2))
        s *= 2;
    return s;
}

static void reset_pages(struct sw__gpu_atlas *a)
{
    for (int32_t l = 0; l < MAX_PAGES; ++l) {
        a->pages[l].n_shelves = 0;
        a->pages[l].top = 0;
    }
    a->n_pages = 0;
}

/* Pages the atlas may hold: its share of the memory budget (R8: a byte per texel, twice what one
 * frame's textures may take, memory_budget.c), at least one. */
static int32_t page_limit(const sw_gpu_context *ctx, const struct sw__gpu_atlas *a)
{
    double per = (double)a->side * (double)a->side;
    int32_t n = (int32_t)(ctx->atlas_max_texels / per);
    return n < 1 ? 1 : (n > MAX_PAGES ? MAX_PAGES : n);
}

/* Layers for an array texture that must hold a->n_pages pages: half as many again as it has at
 * least, so that a walk needing ever more pages reallocates a logarithmic number of times. */
static int32_t grown_layers(const struct sw__gpu_atlas *a, int32_t limit)
{
    int32_t want = a->cap_layers + (a->cap_layers + 1) / 2;
    want = want > limit ? limit : want;
    return want > a->n_pages ? want : a->n_pages;
}

/* Every entry used this frame packed from scratch into a fresh, cleared array texture. */
static sw_result repack(sw_gpu_context *ctx, struct sw__gpu_atlas *a, sw_status *status)
{
    kill_unused(a);
    int32_t n = 0;
    sw_result r = collect(a, 1, &n, status);
    if (r != SW_OK)
        return r;
    a->side = choose_side(a, n, max_side(ctx));
    reset_pages(a);
    int32_t limit = page_limit(ctx, a);
    for (int32_t i = 0; i < n; ++i)
        if (!place(a, &a->entries[a->order[i].id], limit))
            return sw__fail(status, SW_ERR_LIMIT,
                            "trim textures of this frame exceed the atlas (%d pages of %d^2)",
                            (int)limit, (int)a->side);
    a->st.repacks++;
    /* every footprint is cleared before it is rendered: the old texture serves as it is unless
     * its pages have the wrong size or are too few, or it has been more than twice too large for
     * a while */
    const int oversized =
        a->cap_layers > 2 * a->n_pages && a->frame - a->busy_frame > k_max_idle_frames;
    if (a->tex && a->side == a->tex_side && a->cap_layers >= a->n_pages && !oversized)
        return SW_OK;
    const int32_t layers =
        oversized || a->side != a->tex_side ? a->n_pages : grown_layers(a, limit);
    return alloc_layers(ctx, a, layers, 0, status);
}

/* Places the entries of order[0..n) not placed yet within the first max_pages pages; 1 when all
 * of them fit. */
static int place_all(struct sw__gpu_atlas *a, int32_t n, int32_t max_pages)
{
    int all = 1;
    for (int32_t i = 0; i < n; ++i) {
        entry *e = &a->entries[a->order[i].id];
        if (e->layer < 0 && !place(a, e, max_pages))
            all = 0;
    }
    return all;
}

static double footprint(const entry *e)
{
    const int32_t g = SW__GPU_ATLAS_GUTTER;
    return (double)(e->w + 2 * g) * (double)(e->h + 2 * g);
}

/* 1 when the texels taken in the pages by anything but this frame's placed entries (entries
 * unused this frame or dropped, a shelf's height above its shorter entries) are at least what all
 * of this frame's entries need. Free space (a shelf's unused length, a page's unused top) is not
 * counted: new entries can still go there. */
static int dead_exceeds_live(const struct sw__gpu_atlas *a)
{
    double taken = 0.0, live = 0.0, live_placed = 0.0;
    for (int32_t l = 0; l < a->n_pages; ++l)
        for (int32_t k = 0; k < a->pages[l].n_shelves; ++k) {
            const shelf *sh = &a->pages[l].shelves[k];
            taken += (double)sh->x * (double)sh->h;
        }
    for (int32_t i = 0; i < a->n_entries; ++i) {
        const entry *e = &a->entries[i];
        if (e->dead || e->used_frame != a->frame)
            continue;
        live += footprint(e);
        live_placed += e->layer >= 0 ? footprint(e) : 0.0;
    }
    return taken - live_placed >= live;
}

/* Places the pending entries in free space of the pages allocated, else in new pages unless a
 * repack is the better use of the space (dead_exceeds_live); *fits = 0 asks for the repack. */
static sw_result place_pending(sw_gpu_context *ctx, struct sw__gpu_atlas *a, int *fits,
                               sw_status *status)
{
    int32_t n = 0;
    sw_result r = collect(a, 0, &n, status);
    *fits = 1;
    if (r != SW_OK || n == 0)
        return r;
    if (!a->tex) {
        *fits = 0;
        return SW_OK;
    }
    int32_t limit = page_limit(ctx, a);
    if (place_all(a, n, a->cap_layers < limit ? a->cap_layers : limit))
        return SW_OK;
    if (dead_exceeds_live(a) || !place_all(a, n, limit)) {
        *fits = 0;
        return SW_OK;
    }
    if (a->n_pages > a->cap_layers)
        r = alloc_layers(ctx, a, grown_layers(a, limit), 1, status);
    return r;
}

static sw_result scratch_for_page(struct sw__gpu_atlas *a, size_t n_xy, size_t n_loops,
                                  sw_status *status)
{
    if (!sw__grow((void **)&a->clip, &a->cap_clip, 2 * n_xy + 2, sizeof *a->clip))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim atlas: out of memory");
    size_t cap = a->cap_loops;
    if (!sw__grow((void **)&a->first, &cap, n_loops + 1, sizeof *a->first))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim atlas: out of memory");
    cap = a->cap_loops;
    if (!sw__grow((void **)&a->count, &cap, n_loops + 1, sizeof *a->count))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim atlas: out of memory");
    a->cap_loops = cap;
    return SW_OK;
}

/* Renders the unrendered entries of one layer: all their loops in one fan pass, one line pass.
 * Each footprint is cleared first, so free space never needs to be (allocation does not clear). */
static sw_result render_layer(sw_gpu_context *ctx, struct sw__gpu_atlas *a, int32_t layer,
                              sw_status *status)
{
    size_t n_xy = 0, n_loops = 0;
    for (int32_t i = 0; i < a->n_entries; ++i) {
        const entry *e = &a->entries[i];
        if (e->layer == layer && !e->rendered) {
            n_xy += e->n_xy;
            n_loops += e->n_loops;
        }
    }
    if (n_loops == 0)
        return SW_OK;
    sw_result r = scratch_for_page(a, n_xy, n_loops, status);
    if (r != SW_OK)
        return r;
    const double scale = 2.0 / a->side;
    size_t at = 0, k = 0;
    for (int32_t i = 0; i < a->n_entries; ++i) {
        entry *e = &a->entries[i];
        if (e->layer != layer || e->rendered)
            continue;
        static const uint8_t zero = 0;
        const int32_t g = SW__GPU_ATLAS_GUTTER;
        glClearTexSubImage(a->tex, 0, e->x0 - g, e->y0 - g, layer, e->w + 2 * g, e->h + 2 * g, 1,
                           GL_RED, GL_UNSIGNED_BYTE, &zero);
        size_t v = 0;
        for (uint32_t l = 0; l < e->n_loops; ++l, ++k) {
            a->first[k] = (GLint)at;
            a->count[k] = (GLsizei)e->counts[l];
            for (uint32_t j = 0; j < e->counts[l]; ++j, ++v, ++at) {
                a->clip[2 * at] = (float)((e->x0 + e->xy[2 * v]) * scale - 1.0);
                a->clip[2 * at + 1] = (float)((e->y0 + e->xy[2 * v + 1]) * scale - 1.0);
            }
        }
        e->rendered = 1;
        a->st.rendered++;
    }
    sw__gpu_trim_page_draw(ctx, a->tex, layer, a->side, a->clip, at, a->first, a->count,
                           (GLsizei)k);
    a->st.switches++;
    return sw__gpu_check(status, "trim atlas page");
}

sw_result sw__gpu_atlas_commit(sw_gpu_context *ctx, sw__gpu_atlas_stats *stats, sw_status *status)
{
    struct sw__gpu_atlas *a = atlas_get(ctx);
    if (!a)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "trim atlas: out of memory");
    int fits = 1;
    sw_result r = place_pending(ctx, a, &fits, status);
    if (r == SW_OK && !fits)
        r = repack(ctx, a, status);
    for (int32_t l = 0; l < a->n_pages && r == SW_OK; ++l)
        r = render_layer(ctx, a, l, status);
    for (int32_t i = 0; i < a->n_entries; ++i) {
        const entry *e = &a->entries[i];
        if (e->used_frame != a->frame || e->dead)
            continue;
        a->st.entries++;
        a->st.entry_texels += (uint64_t)e->w * (uint64_t)e->h;
    }
    a->st.reused = a->st.entries - a->st.rendered;
    if (2 * a->n_pages > a->cap_layers)
        a->busy_frame = a->frame;
    a->st.pages = (uint32_t)a->cap_layers;
    a->st.side = a->side;
    if (stats)
        *stats = a->st;
    return r;
}

void sw__gpu_atlas_rect(const sw_gpu_context *ctx, int32_t id, sw__gpu_trim_rect *out)
{
    const entry *e = &ctx->atlas->entries[id];
    *out = (sw__gpu_trim_rect){e->layer, e->x0, e->y0, e->w, e->h};
}

void sw__gpu_atlas_invalidate(sw_gpu_context *ctx)
{
    struct sw__gpu_atlas *a = ctx->atlas;
    if (!a)
        return;
    for (int32_t i = 0; i < a->n_entries; ++i) {
        free_entry(&a->entries[i]);
        a->entries[i].dead = 1;
    }
    reset_pages(a);
}

sw_result sw__gpu_atlas_read_page(sw_gpu_context *ctx, int32_t layer, uint8_t *out, size_t size,
                                  int32_t *side, sw_status *status)
{
    sw__gpu_make_current(ctx);
    const struct sw__gpu_atlas *a = ctx->atlas;
    *side = a ? a->side : 0;
    if (!a || !a->tex || layer < 0 || layer >= a->cap_layers)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "atlas has no layer %d", (int)layer);
    size_t need = (size_t)a->side * (size_t)a->side;
    if (size < need)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "atlas page needs %zu bytes", need);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glGetTextureSubImage(a->tex, 0, 0, 0, layer, a->side, a->side, 1, GL_RED, GL_UNSIGNED_BYTE,
                         (GLsizei)need, out);
    return sw__gpu_check(status, "trim atlas readback");
}

GLuint sw__gpu_atlas_texture(const sw_gpu_context *ctx)
{
    return ctx->atlas ? ctx->atlas->tex : 0;
}

void sw_gpu_trim_atlas_info(const sw_gpu_context *ctx, uint32_t *texture, int32_t *pages,
                            int32_t *side)
{
    const struct sw__gpu_atlas *a = ctx->atlas;
    *texture = a ? a->tex : 0;
    *pages = a && a->tex ? a->n_pages : 0;
    *side = a ? a->side : 0;
}

void sw__gpu_atlas_free(sw_gpu_context *ctx)
{
    struct sw__gpu_atlas *a = ctx->atlas;
    if (!a)
        return;
    if (a->tex)
        glDeleteTextures(1, &a->tex);
    for (int32_t i = 0; i < a->n_entries; ++i)
        free_entry(&a->entries[i]);
    for (int32_t l = 0; l < MAX_PAGES; ++l)
        sw__free(a->pages[l].shelves);
    sw__free(a->entries);
    sw__free(a->table);
    sw__free(a->order);
    sw__free(a->clip);
    sw__free(a->first);
    sw__free(a->count);
    sw__free(a);
    ctx->atlas = NULL;
}
