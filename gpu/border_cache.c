/* SPDX-License-Identifier: MIT */
/* Fat borders' view-independent parts, kept between frames and shared by a face's occurrences
 * (Guthe et al. 2005 §7.1 builds a face's ribbon from its trim loops every frame): a face's loops
 * flattened at a tolerance, and each loop's samples on its surface at a sampling step
 * (sw__gpu_border_loop, gpu/crack_fill.c). The stages ask for tolerances and steps out of
 * discrete classes (trim texel classes, grid segment classes, a static face's cell count), so a
 * face seen again at a similar size, or in another instance of its part, asks for the same key:
 * only the placement under the view (a 3 x 4 transform per sample, then the view-dependent
 * inner points) is left to the frame. The ribbons are the same, bit for bit.
 *
 * Keys: (face, tolerance) for an entry of trim loops, (face, rectangle) for one rectangular loop
 * (an untrimmed face's parameter box, a hierarchy node's part of its face), and (step u, step v)
 * for a sample set of an entry; the scene's serial for the whole cache (a new scene, or the next
 * compiled version of a node scene, empties it). Concurrency: the preparing thread and the
 * tessellation chunks of its frame look up and add entries at once, without a lock: slots of an
 * open-addressed table and the head of each entry's list of sample sets are set by
 * compare-and-swap; what is published is never changed (but its last-use frame and byte count,
 * atomics) or freed during a frame. Between frames (sw__fr_border_cache_begin, on one preparing
 * thread; a second prepare of the same context meanwhile runs without the cache) the cache is
 * emptied when the scene changed, and over its byte budget it keeps only the entries the last frame
 * used: a walkthrough's working set stays, and a frame whose own set outgrows the budget adds no
 * more than the budget and reuses what it holds, rather than emptying and refilling it every frame.
 * A table found full grows. A frame's geometry keeps copies of the loops it hands to the trim stage
 * (the submitting thread draws trim textures from them), never the cache's. */
#include "frame_stages.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdatomic.h>
#include <string.h>

enum {
    MIN_SLOTS = 1 << 12,
    MAX_PROBES = 32, /* slots tried before the table counts as full for the frame */
};
/* Bytes the cache may hold (entries unused in the last frame are dropped above it). */
static const size_t k_default_budget = (size_t)64 << 20;

typedef struct border_set {
    double du, dv;
    size_t bytes;
    struct border_set *next;
    sw__gpu_border_loop **loop; /* one per loop of the entry */
} border_set;

struct sw__fr_border_entry {
    uint32_t face;
    double tol;     /* < 0: the rectangle's loop */
    double rect[4]; /* u0, u1, v0, v1 (tol < 0; else 0) */
    sw_sg_polyline *loops;
    uint32_t n, floored; /* loops, and loops flattened farther than tol somewhere */
    int *left_inside;
    _Atomic(border_set *) sets;
    _Atomic size_t bytes;       /* the entry's and its sets' */
    _Atomic uint64_t last_used; /* the cache's frame count when last looked up */
};

struct sw__fr_border_cache {
    _Atomic(sw__fr_border_entry *) *slots;
    size_t n_slots; /* a power of two */
    _Atomic size_t bytes;
    _Atomic int full; /* an entry found no slot this frame */
    _Atomic int busy; /* a prepare uses it */
    uint64_t serial;  /* the scene its entries are of */
    uint64_t frame;   /* frames begun */
    size_t budget;
};

sw__fr_border_cache *sw__fr_border_cache_new(void)
{
    sw__fr_border_cache *c = sw__calloc(1, sizeof *c);
    if (!c)
        return NULL;
    c->slots = sw__calloc(MIN_SLOTS, sizeof *c->slots);
    if (!c->slots) {
        sw__free(c);
        return NULL;
    }
    c->n_slots = MIN_SLOTS;
    c->budget = k_default_budget;
    return c;
}

static void set_free(border_set *s, uint32_t n)
{
    for (uint32_t k = 0; s->loop && k < n; ++k)
        sw__gpu_border_loop_free(s->loop[k]);
    sw__free(s->loop);
    sw__free(s);
}

static void entry_free(sw__fr_border_entry *e)
{
    if (!e)
        return;
    for (border_set *s = atomic_load(&e->sets), *next; s; s = next) {
        next = s->next;
        set_free(s, e->n);
    }
    for (uint32_t k = 0; e->loops && k < e->n; ++k)
        sw_sg_polyline_free(&e->loops[k]);
    sw__free(e->loops);
    sw__free(e->left_inside);
    sw__free(e);
}

static uint64_t key_hash(uint32_t face, double tol, const double rect[4])
{
    uint64_t h = (uint64_t)face * 0x9E3779B97F4A7C15ull;
    const double parts[5] = {tol, rect[0], rect[1], rect[2], rect[3]};
    for (int k = 0; k < 5; ++k) {
        uint64_t b;
        memcpy(&b, &parts[k], sizeof b);
        h ^= b + 0x632BE59BD9B4E019ull + (h << 6) + (h >> 2);
    }
    h ^= h >> 31;
    h *= 0xBF58476D1CE4E5B9ull;
    return h ^ (h >> 29);
}

static int same_key(const sw__fr_border_entry *e, uint32_t face, double tol, const double rect[4])
{
    return e->face == face && e->tol == tol && e->rect[0] == rect[0] && e->rect[1] == rect[1] &&
           e->rect[2] == rect[2] && e->rect[3] == rect[3];
}

/* Re-files the entries into n_slots slots (a power of two, at least the entries kept); those
 * not used since frame `since` are freed (since 0: none; UINT64_MAX: all). Single thread. */
static void refile(sw__fr_border_cache *c, size_t n_slots, uint64_t since)
{
    _Atomic(sw__fr_border_entry *) *old = c->slots, *fresh = c->slots;
    const size_t n_old = c->n_slots;
    if (n_slots != n_old) {
        fresh = sw__calloc(n_slots, sizeof *fresh);
        if (!fresh) { /* keep the size; only drop */
            fresh = old;
            n_slots = n_old;
        }
    }
    /* collect first: refiling in place would meet entries not yet moved */
    size_t kept = 0;
    for (size_t i = 0; i < n_old; ++i) {
        sw__fr_border_entry *e = atomic_load_explicit(&old[i], memory_order_relaxed);
        atomic_store_explicit(&old[i], NULL, memory_order_relaxed);
        if (!e)
            continue;
        if (since == UINT64_MAX || atomic_load(&e->last_used) < since) {
            atomic_fetch_sub(&c->bytes, atomic_load(&e->bytes));
            entry_free(e);
        } else {
            atomic_store_explicit(&old[kept++], e, memory_order_relaxed);
        }
    }
    for (size_t k = 0; k < kept; ++k) {
        sw__fr_border_entry *e = atomic_load_explicit(&old[k], memory_order_relaxed);
        atomic_store_explicit(&old[k], NULL, memory_order_relaxed);
        size_t i = (size_t)key_hash(e->face, e->tol, e->rect) & (n_slots - 1);
        while (atomic_load_explicit(&fresh[i], memory_order_relaxed))
            i = (i + 1) & (n_slots - 1);
        atomic_store_explicit(&fresh[i], e, memory_order_relaxed);
    }
    if (fresh != old)
        sw__free(old);
    c->slots = fresh;
    c->n_slots = n_slots;
}

void sw__fr_border_cache_free(sw__fr_border_cache *c)
{
    if (!c)
        return;
    refile(c, c->n_slots, UINT64_MAX);
    sw__free(c->slots);
    sw__free(c);
}

size_t sw__fr_border_cache_set_budget(sw__fr_border_cache *c, size_t bytes)
{
    const size_t was = c->budget;
    c->budget = bytes;
    return was;
}

size_t sw__fr_border_cache_bytes(const sw__fr_border_cache *c)
{
    return atomic_load(&((sw__fr_border_cache *)c)->bytes);
}

sw__fr_border_cache *sw__fr_border_cache_begin(sw__fr_border_cache *c, const sw_sg_scene *scene)
{
    int idle = 0;
    if (!c || !atomic_compare_exchange_strong(&c->busy, &idle, 1))
        return NULL;
    const uint64_t serial = sw_sg_scene_serial(scene);
    const int full = atomic_exchange(&c->full, 0);
    /* a full table twice as large, while the budget can fill it (one entry: ~1 KiB) */
    const size_t n_slots = full && c->n_slots < c->budget / 1024 ? 2 * c->n_slots : c->n_slots;
    if (serial != c->serial)
        refile(c, n_slots, UINT64_MAX);
    else if (atomic_load(&c->bytes) > c->budget)
        refile(c, n_slots, c->frame); /* the entries the last frame used stay */
    else if (n_slots != c->n_slots)
        refile(c, n_slots, 0);
    c->serial = serial;
    c->frame++;
    return c;
}

void sw__fr_border_cache_end(sw__fr_border_cache *c)
{
    if (c)
        atomic_store(&c->busy, 0);
}

/* The face's loops at tol (tol < 0: the rectangle's, counter-clockwise), with their sides,
 * counted as flattened. */
static sw__fr_border_entry *entry_make(const sw__fr_env *env, uint32_t face, double tol,
                                       const double rect[4])
{
    const sw_sg_face_rec *rec = &env->sv->faces[face];
    sw__fr_border_entry *e = sw__calloc(1, sizeof *e);
    const uint32_t n = tol < 0.0 ? 1 : rec->n_loops;
    if (!e)
        return NULL;
    e->face = face;
    e->tol = tol;
    memcpy(e->rect, rect, sizeof e->rect);
    e->loops = sw__calloc(n ? n : 1, sizeof *e->loops);
    e->left_inside = sw__calloc(n ? n : 1, sizeof *e->left_inside);
    if (!e->loops || !e->left_inside) {
        entry_free(e);
        return NULL;
    }
    size_t bytes = sizeof *e + n * (sizeof *e->loops + sizeof *e->left_inside);
    if (tol < 0.0) {
        const double *b = rect;
        const double box[8] = {b[0], b[2], b[1], b[2], b[1], b[3], b[0], b[3]};
        if (!(e->loops[0].uv = sw__malloc(sizeof box))) {
            entry_free(e);
            return NULL;
        }
        memcpy(e->loops[0].uv, box, sizeof box);
        e->loops[0].count = 4;
        e->left_inside[0] = 1;
        e->n = 1;
    } else {
        sw_status st = {0};
        for (uint32_t k = 0; k < n; ++k, ++e->n) {
            if (sw_sg_trim_flatten_loop(env->scene, rec->first_loop + k, tol,
                                        MAX_TRIM_LOOP_VERTICES, &e->loops[k], &st) != SW_OK) {
                entry_free(e); /* the caller flattens it again and reports the error */
                return NULL;
            }
            e->floored += e->loops[k].below_floor || e->loops[k].depth_capped;
            bytes += 2 * sizeof(double) * e->loops[k].count;
        }
        for (uint32_t k = 0; k < n; ++k)
            e->left_inside[k] = sw__fr_left_is_inside(e->loops, n, k);
    }
    atomic_init(&e->bytes, bytes);
    atomic_fetch_add(&((sw__fr_border_cache *)env->borders)->bytes, bytes);
    return e;
}

/* An entry made but not published (another thread's came first, or no slot): its bytes leave. */
static void entry_discard(sw__fr_border_cache *c, sw__fr_border_entry *e)
{
    if (!e)
        return;
    atomic_fetch_sub(&c->bytes, atomic_load(&e->bytes));
    entry_free(e);
}

static const sw__fr_border_entry *entry_get(const sw__fr_env *env, uint32_t face, double tol,
                                            const double rect[4])
{
    sw__fr_border_cache *c = env->borders;
    if (!c || c->budget == 0)
        return NULL;
    const int may_add = atomic_load_explicit(&c->bytes, memory_order_relaxed) < c->budget;
    const size_t mask = c->n_slots - 1;
    size_t i = (size_t)key_hash(face, tol, rect) & mask;
    sw__fr_border_entry *made = NULL;
    for (int probe = 0; probe < MAX_PROBES; ++probe, i = (i + 1) & mask) {
        sw__fr_border_entry *e = atomic_load_explicit(&c->slots[i], memory_order_acquire);
        if (!e) {
            if (!may_add)
                return NULL; /* over the budget: what the frame finds, no more */
            if (!made && !(made = entry_make(env, face, tol, rect)))
                return NULL;
            if (atomic_compare_exchange_strong_explicit(
                    &c->slots[i], &e, made, memory_order_acq_rel, memory_order_acquire)) {
                atomic_store_explicit(&made->last_used, c->frame, memory_order_relaxed);
                return made;
            }
            /* another thread took the slot: e is its entry */
        }
        if (same_key(e, face, tol, rect)) {
            entry_discard(c, made);
            if (atomic_load_explicit(&e->last_used, memory_order_relaxed) != c->frame)
                atomic_store_explicit(&e->last_used, c->frame, memory_order_relaxed);
            return e;
        }
    }
    atomic_store(&c->full, 1);
    entry_discard(c, made);
    return NULL;
}

const sw__fr_border_entry *sw__fr_border_entry_get(const sw__fr_env *env, uint32_t face, double tol)
{
    static const double none[4] = {0.0, 0.0, 0.0, 0.0};
    return tol >= 0.0 ? entry_get(env, face, tol, none) : NULL;
}

const sw__fr_border_entry *sw__fr_border_rect_get(const sw__fr_env *env, uint32_t face,
                                                  const double rect[4])
{
    return entry_get(env, face, -1.0, rect);
}

static border_set *set_make(const sw__fr_env *env, const sw__fr_border_entry *e,
                            const double cell[2], sw_status *status)
{
    border_set *s = sw__calloc(1, sizeof *s);
    if (s)
        s->loop = sw__calloc(e->n ? e->n : 1, sizeof *s->loop);
    if (!s || !s->loop) {
        sw__free(s);
        sw__fail(status, SW_ERR_OUT_OF_MEMORY, "face %u border: out of memory", e->face);
        return NULL;
    }
    s->du = cell[0];
    s->dv = cell[1];
    sw_sg_surface srf;
    sw_sg_scene_face_surface(env->scene, e->face, &srf);
    const int affine = !env->ctx->border_affine_off;
    size_t bytes = sizeof *s + e->n * sizeof *s->loop;
    for (uint32_t k = 0; k < e->n; ++k) {
        const sw_sg_polyline *l = &e->loops[k];
        if (l->count < 2)
            continue; /* draws nothing, as sw__gpu_fat_border */
        if (sw__gpu_border_loop_make(&srf, l->uv, l->count, e->left_inside[k], cell[0], cell[1],
                                     affine, sw__gpu_border_budget(&env->view, l->count),
                                     &s->loop[k], status) != SW_OK) {
            set_free(s, e->n);
            return NULL;
        }
        bytes += sw__gpu_border_loop_bytes(s->loop[k]);
    }
    s->bytes = bytes;
    atomic_fetch_add(&((sw__fr_border_cache *)env->borders)->bytes, bytes);
    atomic_fetch_add(&((sw__fr_border_entry *)e)->bytes, bytes);
    return s;
}

static border_set *set_find(border_set *s, const double cell[2])
{
    for (; s; s = s->next)
        if (s->du == cell[0] && s->dv == cell[1])
            return s;
    return NULL;
}

/* The entry's samples at steps cell (made and published when absent); NULL: over the budget,
 * or out of memory (status set). */
static border_set *set_get(const sw__fr_env *env, const sw__fr_border_entry *e,
                           const double cell[2], int *made_here, sw_status *status)
{
    sw__fr_border_entry *me = (sw__fr_border_entry *)e; /* only its atomic list changes */
    border_set *head = atomic_load_explicit(&me->sets, memory_order_acquire);
    border_set *s = set_find(head, cell);
    *made_here = 0;
    if (s)
        return s;
    const sw__fr_border_cache *c = env->borders;
    if (atomic_load_explicit(&c->bytes, memory_order_relaxed) >= c->budget)
        return NULL; /* over the budget: sampled by the caller, not kept */
    border_set *made = set_make(env, e, cell, status);
    if (!made)
        return NULL;
    for (;;) {
        made->next = head;
        if (atomic_compare_exchange_weak_explicit(&me->sets, &head, made, memory_order_acq_rel,
                                                  memory_order_acquire)) {
            *made_here = 1;
            return made;
        }
        if ((s = set_find(head, cell))) { /* another thread published it meanwhile */
            atomic_fetch_sub(&((sw__fr_border_cache *)env->borders)->bytes, made->bytes);
            atomic_fetch_sub(&me->bytes, made->bytes);
            set_free(made, e->n);
            return s;
        }
    }
}

sw_result sw__fr_border_entry_ribbons(sw__fr_tess *t, const occurrence *o,
                                      const sw__fr_border_entry *e, const double cell[2],
                                      const double *st_box, size_t share, sw_status *status)
{
    if (t->env->ctx->crack_fill_off || !(cell[0] > 0.0) || !(cell[1] > 0.0))
        return SW_OK;
    sw_status mine = {0};
    int made_here = 0;
    const border_set *s = set_get(t->env, e, cell, &made_here, &mine);
    if (!s && mine.result != SW_OK) {
        *status = mine;
        return mine.result;
    }
    sw_result r = SW_OK;
    for (uint32_t k = 0; !s && k < e->n && r == SW_OK; ++k)
        r = sw__fr_fat_border(t, o, e->loops[k].uv, e->loops[k].count, e->left_inside[k], cell,
                              st_box, share, status);
    if (s && made_here)
        t->st->border_loops_made += e->n;
    else if (s)
        t->st->border_loops_kept += e->n;
    for (uint32_t k = 0; s && k < e->n && r == SW_OK; ++k)
        if (s->loop[k])
            r = sw__fr_placed_border(t, o, s->loop[k], cell, st_box, share, status);
    return r;
}

void sw__fr_border_entry_count(sw__fr_tess *t, const sw__fr_border_entry *e)
{
    t->st->trim_loops_floored += e->floored;
    t->st->bound_exceeded += e->floored;
}

const sw_sg_polyline *sw__fr_border_entry_loops(const sw__fr_border_entry *e, uint32_t *n)
{
    *n = e->n;
    return e->loops;
}
