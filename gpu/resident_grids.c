/* SPDX-License-Identifier: MIT */
/* Patch grids kept on the GPU between frames (sw_gpu_internal.h says what is drawn how).
 * Guthe et al. 2005 §4.2 evaluates every grid vertex in the vertex shader every frame; on a CPU
 * rasteriser (llvmpipe) that is the largest part of a frame's geometry work, and it sends every
 * patch's control points again each frame. Here a grid is evaluated once, by the same vertex
 * shader (eval.vert.glsl, its outputs captured by transform feedback), in the patch's own space
 * around a centre, and drawn again while the view asks for its class or a class at most twice
 * as fine per direction (hysteresis toward finer only: a kept grid is never coarser than the
 * view needs). A draw then costs one indirect command and its placement, composed in double on the
 * CPU (ARCHITECTURE.md's precision rule).
 *
 * Keys are the grid's inputs themselves: the local control points, degrees, the sampled part of
 * the domain and the class. Two occurrences of one part, or one face seen again, find the same
 * entry; an edited surface has other control points and finds none (its old grids age out). A
 * CRC-32C of the inputs indexes an open-addressed table; an entry found is compared in full.
 *
 * Storage: one vertex buffer; an entry holds (nu + 1)(nv + 1) vertices of sw__gpu_vertex at a
 * slot of its class (freed slots are kept per class and reused by that class). Between frames,
 * over the byte budget, the entries the last frame did not draw are freed, oldest first (the
 * static levels' rule, resident.c). A miss is evaluated straight into its slot. */
#include "sw_crc32c.h"
#include "sw_gpu_internal.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <stdlib.h>
#include <string.h>

/* Bytes of vertex storage kept past a frame unless the memory budget says otherwise. */
static const size_t k_default_budget = (size_t)64 << 20;
enum { MIN_TABLE = 1 << 10, MAX_CPS = 16 };

typedef struct grid_key {
    float cps[4 * MAX_CPS];
    float st[4];
    int32_t deg_u, deg_v, level_u, level_v;
} grid_key;

typedef struct grid_entry {
    grid_key key;
    uint32_t hash;
    uint32_t first_vertex; /* of the vertex buffer */
    uint64_t last_frame;
    int32_t live;
} grid_entry;

typedef struct slot_list {
    uint32_t *first;
    size_t n, cap;
} slot_list;

/* DrawElementsIndirectCommand (GL 4.3 §10.4). */
typedef struct indirect_cmd {
    uint32_t count, instances, first_index;
    int32_t base_vertex;
    uint32_t base_instance;
} indirect_cmd;

/* The per-draw attributes of grid.vert.glsl: the placement's rows with the centre's
 * eye-relative position in w, the normals' rows with the normal sign and the atlas layer in w,
 * then colour, trim map, trim rectangle and uv map. */
typedef struct grid_instance {
    float rot[12], cof[12], color[4], trim_map[4], trim_rect[4], uv_map[4];
} grid_instance;

/* A sort item: an order key and the index it orders. */
typedef struct keyed {
    uint64_t key;
    uint32_t index;
} keyed;

struct sw__gpu_grid_cache {
    grid_entry *entries;
    size_t n_entries, cap_entries;
    uint32_t *free_entries;
    size_t n_free_entries, cap_free_entries;
    uint32_t *table; /* entry index + 1; 0 empty */
    size_t table_size;
    slot_list free_slots[SW__GPU_GRID_CLASSES][SW__GPU_GRID_CLASSES];
    GLuint vbo, instances, indirect, vao;
    GLuint xfb; /* the transform feedback object misses are captured with (a host's stays theirs) */
    size_t vbo_vertices, used_vertices; /* capacity and high-water mark */
    size_t pending_vertices;            /* of this frame's new entries, before their slots */
    size_t instance_bytes, indirect_bytes;
    size_t live_vertices, budget;
    uint64_t frame;
    /* per frame (the submitting thread's scratch) */
    uint32_t *draw_entry; /* per resident record: its entry */
    uint32_t *miss;       /* records evaluated this frame, by class and slot */
    keyed *miss_order;
    sw__gpu_patch_rec *miss_recs;
    grid_instance *inst;
    indirect_cmd *cmds;
    size_t cap_draw_entry, cap_miss, cap_miss_order, cap_miss_recs, cap_inst, cap_cmds;
};

static size_t class_vertices(int32_t lu, int32_t lv)
{
    return (size_t)(sw__gpu_grid_segments[lu] + 1) * (size_t)(sw__gpu_grid_segments[lv] + 1);
}

static struct sw__gpu_grid_cache *cache_of(sw_gpu_context *ctx)
{
    if (!ctx->grid_cache) {
        ctx->grid_cache = sw__calloc(1, sizeof *ctx->grid_cache);
        if (ctx->grid_cache)
            ctx->grid_cache->budget = k_default_budget;
    }
    return ctx->grid_cache;
}

/* The key of a record's grid but its class. */
static void key_of(const sw__gpu_patch_rec *rec, const float *cps, grid_key *k)
{
    memset(k, 0, sizeof *k);
    const size_t n = (size_t)(rec->deg_u + 1) * (size_t)(rec->deg_v + 1);
    memcpy(k->cps, cps + 4 * (size_t)rec->cp, 4 * n * sizeof *cps);
    memcpy(k->st, rec->st, sizeof k->st);
    k->deg_u = rec->deg_u;
    k->deg_v = rec->deg_v;
}

static uint32_t hash_of(uint32_t content, int32_t lu, int32_t lv)
{
    const int32_t cls[2] = {lu, lv};
    return sw__crc32c(content, cls, sizeof cls);
}

/* The entry of key k with hash h, or -1. */
static int64_t find(const struct sw__gpu_grid_cache *c, uint32_t h, const grid_key *k)
{
    if (!c->table_size)
        return -1;
    const size_t mask = c->table_size - 1;
    for (size_t i = h & mask;; i = (i + 1) & mask) {
        const uint32_t e = c->table[i];
        if (!e)
            return -1;
        const grid_entry *g = &c->entries[e - 1];
        if (g->live && g->hash == h && memcmp(&g->key, k, sizeof *k) == 0)
            return (int64_t)(e - 1);
    }
}

static void table_put(struct sw__gpu_grid_cache *c, uint32_t entry)
{
    const size_t mask = c->table_size - 1;
    size_t i = c->entries[entry].hash & mask;
    while (c->table[i])
        i = (i + 1) & mask;
    c->table[i] = entry + 1;
}

/* The table rebuilt for the live entries at twice their count or more (entries freed by
 * eviction leave no tombstones: eviction rebuilds). 0: out of memory. */
static int table_rebuild(struct sw__gpu_grid_cache *c, size_t live)
{
    size_t n = MIN_TABLE;
    while (n < 2 * live + 2)
        n *= 2;
    uint32_t *t = sw__calloc(n, sizeof *t);
    if (!t)
        return 0;
    sw__free(c->table);
    c->table = t;
    c->table_size = n;
    for (size_t e = 0; e < c->n_entries; ++e)
        if (c->entries[e].live)
            table_put(c, (uint32_t)e);
    return 1;
}

static size_t live_entries(const struct sw__gpu_grid_cache *c)
{
    return c->n_entries - c->n_free_entries;
}

static void entry_free(struct sw__gpu_grid_cache *c, uint32_t e)
{
    grid_entry *g = &c->entries[e];
    slot_list *s = &c->free_slots[g->key.level_v][g->key.level_u];
    if (sw__grow((void **)&s->first, &s->cap, s->n + 1, sizeof *s->first))
        s->first[s->n++] = g->first_vertex; /* else the slot is lost until the cache is freed */
    c->live_vertices -= class_vertices(g->key.level_u, g->key.level_v);
    g->live = 0;
    c->free_entries[c->n_free_entries++] = e; /* room reserved when the entry was made */
}

static int by_key(const void *a, const void *b)
{
    const keyed *x = a, *y = b;
    return x->key != y->key ? (x->key < y->key ? -1 : 1)
                            : (x->index > y->index) - (x->index < y->index);
}

/* Over the budget: the entries the last frame did not draw, oldest first, until under it. */
static void evict(struct sw__gpu_grid_cache *c)
{
    if (c->live_vertices * sizeof(sw__gpu_vertex) <= c->budget)
        return;
    keyed *old = sw__malloc((c->n_entries ? c->n_entries : 1) * sizeof *old);
    if (!old)
        return;
    size_t n = 0;
    for (size_t e = 0; e < c->n_entries; ++e)
        if (c->entries[e].live && c->entries[e].last_frame + 1 < c->frame)
            old[n++] = (keyed){c->entries[e].last_frame, (uint32_t)e};
    qsort(old, n, sizeof *old, by_key);
    size_t freed = 0;
    for (; freed < n && c->live_vertices * sizeof(sw__gpu_vertex) > c->budget; ++freed)
        entry_free(c, old[freed].index);
    sw__free(old);
    if (freed) /* freed entries leave no tombstones: the table is made again */
        table_rebuild(c, live_entries(c)); /* else the old one stays: find skips the freed */
}

/* Every entry dropped and every slot given back: the next frame evaluates what it draws. */
static void reset(struct sw__gpu_grid_cache *c)
{
    c->n_entries = c->n_free_entries = 0;
    for (int v = 0; v < SW__GPU_GRID_CLASSES; ++v)
        for (int u = 0; u < SW__GPU_GRID_CLASSES; ++u)
            c->free_slots[v][u].n = 0;
    c->used_vertices = c->live_vertices = c->pending_vertices = 0;
    if (c->table)
        memset(c->table, 0, c->table_size * sizeof *c->table);
}

void sw__gpu_grid_cache_begin(sw_gpu_context *ctx)
{
    struct sw__gpu_grid_cache *c = ctx->grid_cache;
    if (!c)
        return;
    c->frame++;
    evict(c);
    /* Freed slots serve only their class: as the classes a walk asks for shift, the buffer's
     * high-water mark could grow past the budget while most of it lies free. Past twice the
     * budget and twice what is live, everything is dropped instead, so the buffer never holds
     * more than max(2 x budget, 2 x a frame's grids) (the buffer keeps its size for the next). */
    const size_t used = c->used_vertices * sizeof(sw__gpu_vertex);
    if (used > 2 * c->budget && used > 2 * c->live_vertices * sizeof(sw__gpu_vertex))
        reset(c);
}

size_t sw__gpu_grid_cache_set_budget(sw_gpu_context *ctx, size_t bytes)
{
    struct sw__gpu_grid_cache *c = cache_of(ctx);
    if (!c)
        return 0;
    const size_t was = c->budget;
    c->budget = bytes;
    return was;
}

size_t sw__gpu_grid_cache_held(const sw_gpu_context *ctx)
{
    return ctx->grid_cache ? ctx->grid_cache->used_vertices * sizeof(sw__gpu_vertex) : 0;
}

size_t sw__gpu_grid_cache_bytes(const sw_gpu_context *ctx)
{
    return ctx->grid_cache ? ctx->grid_cache->live_vertices * sizeof(sw__gpu_vertex) : 0;
}

void sw__gpu_grid_cache_free(sw_gpu_context *ctx)
{
    struct sw__gpu_grid_cache *c = ctx->grid_cache;
    if (!c)
        return;
    GLuint bufs[3] = {c->vbo, c->instances, c->indirect};
    glDeleteBuffers(3, bufs);
    glDeleteTransformFeedbacks(1, &c->xfb);
    glDeleteVertexArrays(1, &c->vao);
    for (int v = 0; v < SW__GPU_GRID_CLASSES; ++v)
        for (int u = 0; u < SW__GPU_GRID_CLASSES; ++u)
            sw__free(c->free_slots[v][u].first);
    void *arrays[] = {c->entries,    c->free_entries, c->table, c->draw_entry, c->miss,
                      c->miss_order, c->miss_recs,    c->inst,  c->cmds};
    for (size_t i = 0; i < sizeof arrays / sizeof *arrays; ++i)
        sw__free(arrays[i]);
    sw__free(c);
    ctx->grid_cache = NULL;
}

/* A slot of class (lu, lv): a freed one, else past the high-water mark (the buffer grows at the
 * draw). */
static uint32_t slot_take(struct sw__gpu_grid_cache *c, int32_t lu, int32_t lv)
{
    slot_list *s = &c->free_slots[lv][lu];
    if (s->n)
        return s->first[--s->n];
    const uint32_t first = (uint32_t)c->used_vertices;
    c->used_vertices += class_vertices(lu, lv);
    return first;
}

/* A new entry for key k (hash h), its slot taken; -1 when out of memory or past 2^32 vertices. */
static int64_t entry_add(struct sw__gpu_grid_cache *c, uint32_t h, const grid_key *k)
{
    const size_t verts = class_vertices(k->level_u, k->level_v);
    if (c->used_vertices + c->pending_vertices + verts > INT32_MAX) /* base vertices are signed */
        return -1;
    if (2 * (live_entries(c) + 1) > c->table_size && !table_rebuild(c, live_entries(c) + 1))
        return -1;
    uint32_t e;
    if (c->n_free_entries) {
        e = c->free_entries[--c->n_free_entries];
    } else {
        if (!sw__grow((void **)&c->entries, &c->cap_entries, c->n_entries + 1,
                      sizeof *c->entries) ||
            !sw__grow((void **)&c->free_entries, &c->cap_free_entries, c->n_entries + 1,
                      sizeof *c->free_entries))
            return -1;
        e = (uint32_t)c->n_entries++;
    }
    grid_entry *g = &c->entries[e];
    g->key = *k;
    g->hash = h;
    g->first_vertex = UINT32_MAX; /* its slot is taken with the frame's other misses */
    c->pending_vertices += verts;
    g->last_frame = c->frame;
    g->live = 1;
    c->live_vertices += verts;
    table_put(c, e);
    return e;
}

/* The entry a record draws: its own class, else a class at most twice as fine per direction that
 * is kept (the finest segment counts last: the fewest triangles first), else a new entry of its
 * own class (*miss set). -1: out of memory. */
static int64_t lookup(struct sw__gpu_grid_cache *c, const sw__gpu_patch_rec *rec,
                      const sw__gpu_grid_place *pl, const float *cps, int *miss)
{
    grid_key k;
    key_of(rec, cps, &k);
    *miss = 0;
    const int32_t lu = rec->level_u, lv = rec->level_v;
    const int32_t su = sw__gpu_grid_segments[lu], sv = sw__gpu_grid_segments[lv];
    for (int32_t b = lv; b < SW__GPU_GRID_CLASSES && sw__gpu_grid_segments[b] <= 2 * sv; ++b)
        for (int32_t a = lu; a < SW__GPU_GRID_CLASSES && sw__gpu_grid_segments[a] <= 2 * su; ++a) {
            k.level_u = a;
            k.level_v = b;
            const int64_t e = find(c, hash_of(pl->hash, a, b), &k);
            if (e >= 0)
                return e;
        }
    k.level_u = lu;
    k.level_v = lv;
    *miss = 1;
    return entry_add(c, hash_of(pl->hash, lu, lv), &k);
}

/* The vertex buffer grown to the high-water mark, its content copied on the GPU. */
static void vbo_grow(struct sw__gpu_grid_cache *c)
{
    if (c->used_vertices <= c->vbo_vertices)
        return;
    const size_t want = c->used_vertices + c->used_vertices / 2 + 4096;
    GLuint grown = 0;
    glGenBuffers(1, &grown);
    glBindBuffer(GL_COPY_WRITE_BUFFER, grown);
    glBufferData(GL_COPY_WRITE_BUFFER, (GLsizeiptr)(want * sizeof(sw__gpu_vertex)), NULL,
                 GL_STATIC_DRAW);
    if (c->vbo) {
        glBindBuffer(GL_COPY_READ_BUFFER, c->vbo);
        glCopyBufferSubData(GL_COPY_READ_BUFFER, GL_COPY_WRITE_BUFFER, 0, 0,
                            (GLsizeiptr)(c->vbo_vertices * sizeof(sw__gpu_vertex)));
        glDeleteBuffers(1, &c->vbo);
    }
    c->vbo = grown;
    c->vbo_vertices = want;
}

/* The slot a miss is evaluated into. */
static uint32_t miss_slot(const struct sw__gpu_grid_cache *c, size_t i)
{
    return c->entries[c->draw_entry[c->miss[i]]].first_vertex;
}

/* The misses ordered by class, and their slots taken in that order: past the high-water mark a
 * class's new grids then lie one after another, and a run of them is evaluated by one draw. */
static void order_misses(struct sw__gpu_grid_cache *c, const sw__gpu_patch_batch *batch,
                         size_t n_miss)
{
    for (size_t i = 0; i < n_miss; ++i) {
        const sw__gpu_patch_rec *r = &batch->grid_recs[c->miss[i]];
        const uint64_t cls = (uint64_t)(r->level_v * SW__GPU_GRID_CLASSES + r->level_u);
        c->miss_order[i] = (keyed){cls << 32 | i, c->miss[i]};
    }
    qsort(c->miss_order, n_miss, sizeof *c->miss_order, by_key);
    for (size_t i = 0; i < n_miss; ++i) {
        c->miss[i] = c->miss_order[i].index;
        grid_entry *g = &c->entries[c->draw_entry[c->miss[i]]];
        g->first_vertex = slot_take(c, g->key.level_u, g->key.level_v);
        c->pending_vertices -= class_vertices(g->key.level_u, g->key.level_v);
    }
}

/* The misses' grids: their records (placed at the identity: the captured st is (s, t), the
 * normal unsigned) into storage buffer 0 with the frame's control points in 1, each run of one
 * class in consecutive slots evaluated by one instanced point draw captured straight into its
 * slots of the vertex buffer (grown first). A copy from a staging buffer per grid instead made
 * llvmpipe wait for the GPU at each copy (10x the frame). On llvmpipe the evaluation itself is
 * the cost (1,267 grids of the assembly's first frame: 23 ms in runs, 26-34 ms a draw each). */
static void evaluate_misses(sw_gpu_context *ctx, struct sw__gpu_grid_cache *c,
                            const sw__gpu_patch_batch *batch, size_t n_miss)
{
    static const float k_unit_map[4] = {0.0f, 1.0f, 0.0f, 1.0f}, k_uv_unit[4] = {0, 0, 1, 1};
    order_misses(c, batch, n_miss);
    for (size_t i = 0; i < n_miss; ++i) {
        sw__gpu_patch_rec *r = &c->miss_recs[i];
        *r = batch->grid_recs[c->miss[i]];
        memcpy(r->trim_map, k_unit_map, sizeof k_unit_map);
        memcpy(r->uv_map, k_uv_unit, sizeof k_uv_unit);
        r->normal_sign = 1.0f;
    }
    sw__gpu_upload_patches(ctx, c->miss_recs, n_miss, batch->cps, batch->n_cps);
    vbo_grow(c);
    glUseProgram(ctx->prog_grid_eval.prog);
    glUniform1i(ctx->prog_grid_eval.loc_capture, 0);
    glBindVertexArray(ctx->vao); /* attribute-less, as the per-frame evaluation draws */
    for (GLuint a = 0; a < 3; ++a)
        glDisableVertexAttribArray(a);
    if (!c->xfb)
        glGenTransformFeedbacks(1, &c->xfb);
    glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, c->xfb);
    glEnable(GL_RASTERIZER_DISCARD);
    for (size_t i = 0; i < n_miss;) {
        const int32_t lu = c->miss_recs[i].level_u, lv = c->miss_recs[i].level_v;
        const size_t per = class_vertices(lu, lv);
        size_t j = i + 1;
        while (j < n_miss && c->miss_recs[j].level_u == lu && c->miss_recs[j].level_v == lv &&
               miss_slot(c, j) == miss_slot(c, j - 1) + per)
            ++j;
        glUniform2i(ctx->prog_grid_eval.loc_grid, sw__gpu_grid_segments[lu],
                    sw__gpu_grid_segments[lv]);
        glUniform1i(ctx->prog_grid_eval.loc_base, (GLint)i);
        glBindBufferRange(GL_TRANSFORM_FEEDBACK_BUFFER, 0, c->vbo,
                          (GLintptr)((size_t)miss_slot(c, i) * sizeof(sw__gpu_vertex)),
                          (GLsizeiptr)((j - i) * per * sizeof(sw__gpu_vertex)));
        glBeginTransformFeedback(GL_POINTS); /* instance by instance: one grid after another */
        glDrawArraysInstanced(GL_POINTS, 0, (GLsizei)per, (GLsizei)(j - i));
        glEndTransformFeedback();
        i = j;
    }
    glDisable(GL_RASTERIZER_DISCARD);
    glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, 0);
    glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, 0);
}

static void instance_of(const sw__gpu_patch_rec *r, const sw__gpu_grid_place *pl, grid_instance *o)
{
    memcpy(o->rot, pl->rot, sizeof o->rot);
    memcpy(o->cof, pl->cof, sizeof o->cof);
    o->cof[3] = r->normal_sign;
    o->cof[7] = r->layer;
    memcpy(o->color, r->color, sizeof o->color);
    memcpy(o->trim_map, r->trim_map, sizeof o->trim_map);
    memcpy(o->trim_rect, r->trim_rect, sizeof o->trim_rect);
    memcpy(o->uv_map, r->uv_map, sizeof o->uv_map);
}

/* The vertex array of grid.vert.glsl: vertices from binding 0, per-draw attributes from binding
 * 1 (one per instance: base_instance picks the draw's). */
static void vao_make(struct sw__gpu_grid_cache *c)
{
    glGenVertexArrays(1, &c->vao);
    glBindVertexArray(c->vao);
    glVertexAttribFormat(0, 3, GL_FLOAT, GL_FALSE, (GLuint)offsetof(sw__gpu_vertex, pos));
    glVertexAttribFormat(1, 3, GL_FLOAT, GL_FALSE, (GLuint)offsetof(sw__gpu_vertex, nrm));
    glVertexAttribFormat(2, 2, GL_FLOAT, GL_FALSE, (GLuint)offsetof(sw__gpu_vertex, st));
    for (GLuint a = 0; a < 3; ++a) {
        glVertexAttribBinding(a, 0);
        glEnableVertexAttribArray(a);
    }
    for (GLuint a = 0; a < 10; ++a) {
        glVertexAttribFormat(3 + a, 4, GL_FLOAT, GL_FALSE, a * 4 * sizeof(float));
        glVertexAttribBinding(3 + a, 1);
        glEnableVertexAttribArray(3 + a);
    }
    glVertexBindingDivisor(1, 1);
}

sw_result sw__gpu_grid_cache_draw(sw_gpu_context *ctx, const sw__gpu_view *view,
                                  const sw__gpu_patch_batch *batch, sw_status *status)
{
    const size_t n = batch->n_grid_recs;
    if (n == 0)
        return SW_OK;
    struct sw__gpu_grid_cache *c = cache_of(ctx);
    if (!c || !sw__grow((void **)&c->draw_entry, &c->cap_draw_entry, n, sizeof *c->draw_entry) ||
        !sw__grow((void **)&c->miss, &c->cap_miss, n, sizeof *c->miss) ||
        !sw__grow((void **)&c->miss_order, &c->cap_miss_order, n, sizeof *c->miss_order) ||
        !sw__grow((void **)&c->miss_recs, &c->cap_miss_recs, n, sizeof *c->miss_recs) ||
        !sw__grow((void **)&c->inst, &c->cap_inst, n, sizeof *c->inst) ||
        !sw__grow((void **)&c->cmds, &c->cap_cmds, n, sizeof *c->cmds))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "resident grids: out of memory");
    size_t n_miss = 0;
    for (size_t i = 0; i < n; ++i) {
        int miss = 0;
        const int64_t e =
            lookup(c, &batch->grid_recs[i], &batch->grid_places[i], batch->cps, &miss);
        if (e < 0) {
            reset(c); /* this frame's new entries have no slots yet */
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "resident grids: out of memory");
        }
        c->draw_entry[i] = (uint32_t)e;
        c->entries[e].last_frame = c->frame;
        if (miss)
            c->miss[n_miss++] = (uint32_t)i;
    }
    if (n_miss)
        evaluate_misses(ctx, c, batch, n_miss);
    vbo_grow(c);
    uint64_t triangles = 0, needed = 0;
    for (size_t i = 0; i < n; ++i) {
        const sw__gpu_patch_rec *r = &batch->grid_recs[i];
        const grid_entry *g = &c->entries[c->draw_entry[i]];
        const int32_t lu = g->key.level_u, lv = g->key.level_v;
        instance_of(r, &batch->grid_places[i], &c->inst[i]);
        c->cmds[i] = (indirect_cmd){ctx->grid_count[lv][lu], 1, ctx->grid_first[lv][lu],
                                    (int32_t)g->first_vertex, (uint32_t)i};
        triangles += ctx->grid_count[lv][lu] / 3;
        needed += ctx->grid_count[r->level_v][r->level_u] / 3;
    }
    sw__gpu_stream(ctx, GL_ARRAY_BUFFER, &c->instances, &c->instance_bytes, n * sizeof *c->inst,
                   c->inst);
    sw__gpu_stream(ctx, GL_DRAW_INDIRECT_BUFFER, &c->indirect, &c->indirect_bytes,
                   n * sizeof *c->cmds, c->cmds);
    if (!c->vao)
        vao_make(c);
    glBindVertexArray(c->vao);
    glBindVertexBuffer(0, c->vbo, 0, (GLsizei)sizeof(sw__gpu_vertex));
    glBindVertexBuffer(1, c->instances, 0, (GLsizei)sizeof(grid_instance));
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ctx->grid_ibo);
    static const int k_order[SW__GPU_TRIM_VARIANTS] = {SW__GPU_UNTRIMMED, SW__GPU_TRIMMED};
    for (int k = 0; k < SW__GPU_TRIM_VARIANTS; ++k) {
        const int t = k_order[k];
        const size_t first = batch->grid_first[t], count = batch->grid_count[t];
        if (count == 0)
            continue;
        const sw__gpu_surface_program *prog = &ctx->surf.grid[t];
        glUseProgram(prog->prog);
        glUniformMatrix4fv(prog->loc_view_proj, 1, GL_FALSE, view->view_proj);
        glUniform1i(prog->loc_trim, 0);
        glMultiDrawElementsIndirect(GL_TRIANGLES, GL_UNSIGNED_INT,
                                    (const void *)(first * sizeof *c->cmds), (GLsizei)count, 0);
    }
    glBindVertexArray(ctx->vao);
    ctx->grid_hits += n - n_miss;
    ctx->grid_misses += n_miss;
    ctx->grid_triangles += triangles;
    ctx->grid_extra_triangles += (int64_t)triangles - (int64_t)needed;
    return sw__gpu_check(status, "resident grids");
}
