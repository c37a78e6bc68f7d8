/* SPDX-License-Identifier: MIT */
/* The per-scene cache of face hierarchies (sw_lod_cache.h): builds in the worker pool on first
 * sight, at most once per face, lock-free publication and lookup, cancellation and priorities
 * through the pool's tokens, converged waits, copy-on-write refinement below the leaves (Guthe et
 * al. 2005 §6 hierarchies deepened where §7's traversal needs finer nodes) and epoch-based
 * reclamation of the versions refinement replaces.
 *
 * A slot's state word packs the state (low 3 bits) and a ticket (the rest) that grows with every
 * submission, so that the request record beside it (q_token, q_gen, q_prio, written after the
 * CAS that claims the ticket and then stamped with q_ticket) can be read consistently without a
 * lock: a reader trusts it only if q_ticket matches the word's ticket and the word did not change
 * while it read. When in doubt a requester submits again; the extra task finds the slot taken
 * and returns, so doubt costs a task, never a second build.
 *
 * The build task carries only its slot: the pool skips it when its request went stale (that is
 * the point of handing the pool the token), and anything a skipped task owned would leak. The
 * converged-mode follower and the refinement task own a small record and must release things
 * (the record, the refining flag), so they are submitted without a token and test staleness
 * themselves.
 */
#include "sw_lod_cache.h"
#include "sw_hooks.h"

#include "sw_status_util.h"

#include <assert.h>
#include <float.h>
#include <pthread.h>
#include <sched.h>
#include <stdalign.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The pool's task kinds of this cache (profile columns pool_<name>_ms, pool_<name>_tasks). */
static sw_th_task_kind_slot k_build = SW_TH_TASK_KIND_SLOT("hierarchy");
static sw_th_task_kind_slot k_wait = SW_TH_TASK_KIND_SLOT("hierarchy_wait");
static sw_th_task_kind_slot k_refine = SW_TH_TASK_KIND_SLOT("refine");

enum { STATE_BITS = 3, STATE_MASK = (1 << STATE_BITS) - 1, MAX_READERS = 65536 };

typedef struct slot {
    _Atomic uint64_t word;          /* state | ticket << STATE_BITS */
    _Atomic uint64_t q_ticket;      /* the ticket whose request q_* describe */
    _Atomic(sw_th_token *) q_token; /* the queued build's request */
    _Atomic uint64_t q_gen;
    _Atomic uint32_t q_prio;
    _Atomic int32_t refining; /* leaf being refined, -1 when none */
    _Atomic(sw_lod_hierarchy *) current;
    sw_th_group group;          /* this slot's build tasks: converged waiters wait on it */
    sw_result result;           /* FAILED: written before the release store of the state */
    char *message;              /* likewise; may be NULL */
    struct sw_lod_cache *cache; /* the build task's context is the slot itself */
} slot;

typedef struct reader {
    alignas(64) _Atomic uint64_t epoch; /* 0 outside a read section */
    _Atomic int used;
} reader;

typedef struct retired {
    struct retired *next;
    sw_lod_hierarchy *h;
    uint64_t epoch; /* the global epoch at which it was replaced */
} retired;

struct sw_lod_cache {
    const sw_sg_scene *scene;
    sw_th_pool *pool;
    sw_lod_cache_desc desc;
    uint32_t n_faces, n_readers;
    slot *slots;
    reader *readers;
    sw_th_group refine_group; /* refinements submitted without a caller's group */
    alignas(64) _Atomic uint64_t epoch;
    _Atomic size_t bytes;
    _Atomic uint64_t submitted, builds, failed, cancelled, superseded, refinements,
        refine_cancelled, retired_count, freed_count, refine_capped;
    pthread_mutex_t retire_lock; /* protects `retired`; publishers and collectors only */
    retired *retired;
};

/* ---- small helpers --------------------------------------------------------------------------- */
static inline uint32_t state_of(uint64_t w)
{
    return (uint32_t)(w & STATE_MASK);
}

static inline uint64_t ticket_of(uint64_t w)
{
    return w >> STATE_BITS;
}

static inline uint64_t make_word(uint32_t state, uint64_t ticket)
{
    return ticket << STATE_BITS | state;
}

static void count(_Atomic uint64_t *c)
{
    atomic_fetch_add_explicit(c, 1, memory_order_relaxed); /* statistics only */
}

static size_t hierarchy_bytes(const sw_lod_hierarchy *h)
{
    return sizeof *h + (size_t)h->n_nodes * sizeof *h->nodes;
}

static bool req_stale(const sw_lod_cache_req *r)
{
    return r->token && sw_th_token_current(r->token) != r->generation;
}

/* The queued request of word w, if it can be read consistently; false when in doubt. */
static bool queued_request(slot *s, uint64_t w, sw_lod_cache_req *out)
{
    /* acquire loads: pair with the release stores in claim(), and keep the second load of the
     * word after them (a seqlock read; the word changes before q_* are rewritten). */
    if (atomic_load_explicit(&s->q_ticket, memory_order_acquire) != ticket_of(w))
        return false;
    out->token = atomic_load_explicit(&s->q_token, memory_order_acquire);
    out->generation = atomic_load_explicit(&s->q_gen, memory_order_acquire);
    out->priority = (sw_th_priority)atomic_load_explicit(&s->q_prio, memory_order_acquire);
    return atomic_load_explicit(&s->word, memory_order_acquire) == w;
}

/* Whether the queued build of word w is certain to serve fresh request r: it cannot go stale
 * while r does not, and it runs at least as early. */
static bool queued_covers(slot *s, uint64_t w, const sw_lod_cache_req *r)
{
    sw_lod_cache_req q;
    if (!queued_request(s, w, &q) || q.priority > r->priority)
        return false;
    return !q.token || (q.token == r->token && q.generation == r->generation);
}

static bool queued_stale(slot *s, uint64_t w)
{
    sw_lod_cache_req q;
    return queued_request(s, w, &q) && req_stale(&q);
}

/* ---- building -------------------------------------------------------------------------------- */
static void publish_failure(slot *s, uint64_t ticket, sw_result res, const sw_status *st)
{
    s->result = res;
    s->message = st->message[0] ? sw__strdup(st->message) : NULL;
    count(&s->cache->failed);
    /* release: pairs with the acquire loads of the word; result and message are visible first */
    atomic_store_explicit(&s->word, make_word(SW_LOD_CACHE_FAILED, ticket), memory_order_release);
}

static sw_result build_face(sw_lod_cache *c, uint32_t face, sw_lod_hierarchy **out, sw_status *st)
{
    const sw_sg_face_rec *f = &sw_sg_scene_view_ptr(c->scene)->faces[face];
    sw_sg_surface surf;
    sw_sg_scene_face_surface(c->scene, face, &surf);
    sw_lod_hierarchy_desc d = c->desc.hierarchy;
    d.use_box = 1;
    memcpy(d.uv_box, f->uv_box, sizeof d.uv_box);
    sw_result res = sw_lod_hierarchy_build(&surf, &d, out, st);
    if (res != SW_OK)
        return res;
    /* the builder grows its array by doubling: give the slack back, the version lives long */
    sw_lod_hnode *fit = sw__realloc((*out)->nodes, (size_t)(*out)->n_nodes * sizeof *fit);
    if (fit)
        (*out)->nodes = fit;
    return SW_OK;
}

static void build_task(void *ctx)
{
    slot *s = ctx;
    sw_lod_cache *c = s->cache;
    uint64_t w = atomic_load_explicit(&s->word, memory_order_acquire);
    /* Any queued ticket will do: a task the pool did not skip serves whichever request is queued
     * now. acq_rel: the winner is the only builder; losers (RUNNING, READY...) just return. */
    do {
        if (state_of(w) != SW_LOD_CACHE_QUEUED)
            return;
    } while (!atomic_compare_exchange_weak_explicit(&s->word, &w,
                                                    make_word(SW_LOD_CACHE_RUNNING, ticket_of(w)),
                                                    memory_order_acq_rel, memory_order_acquire));
    const uint32_t face = (uint32_t)(s - c->slots);
    sw_status st = {0};
    sw_lod_hierarchy *h = NULL;
    const sw_result res = build_face(c, face, &h, &st);
    count(&c->builds);
    if (res != SW_OK) {
        publish_failure(s, ticket_of(w), res, &st);
        return;
    }
    atomic_fetch_add_explicit(&c->bytes, hierarchy_bytes(h), memory_order_relaxed);
    /* release: the hierarchy's contents before its pointer (sw_lod_cache_get acquires it) */
    atomic_store_explicit(&s->current, h, memory_order_release);
    atomic_store_explicit(&s->word, make_word(SW_LOD_CACHE_READY, ticket_of(w)),
                          memory_order_release);
}

/* Takes word w (EMPTY or QUEUED) to QUEUED with the next ticket, records r beside it and submits
 * a build task. Returns SW_OK, SW_ERR_OUT_OF_MEMORY, or SW_ERR_LIMIT when w was stale (retry). */
static sw_result claim(sw_lod_cache *c, slot *s, uint64_t w, const sw_lod_cache_req *r)
{
    const uint64_t t = ticket_of(w) + 1;
    /* acq_rel: orders the q_* stores below after the claim, for queued_request's seqlock */
    if (!atomic_compare_exchange_strong_explicit(&s->word, &w, make_word(SW_LOD_CACHE_QUEUED, t),
                                                 memory_order_acq_rel, memory_order_acquire))
        return SW_ERR_LIMIT;
    atomic_store_explicit(&s->q_token, r->token, memory_order_release);
    atomic_store_explicit(&s->q_gen, r->generation, memory_order_release);
    atomic_store_explicit(&s->q_prio, (uint32_t)r->priority, memory_order_release);
    atomic_store_explicit(&s->q_ticket, t, memory_order_release); /* last: stamps the record */
    const sw_th_task task = {build_task,
                             s,
                             r->priority,
                             r->token,
                             r->generation,
                             &s->group,
                             sw_th_task_kind_of(&k_build)};
    if (sw_th_pool_submit(c->pool, &task) != SW_OK) {
        uint64_t mine = make_word(SW_LOD_CACHE_QUEUED, t);
        atomic_compare_exchange_strong_explicit(&s->word, &mine, make_word(SW_LOD_CACHE_EMPTY, t),
                                                memory_order_acq_rel, memory_order_relaxed);
        return SW_ERR_OUT_OF_MEMORY;
    }
    count(&c->submitted);
    return SW_OK;
}

static const sw_lod_cache_req default_req = {SW_TH_PRIORITY_FRAME, NULL, 0};

sw_result sw_lod_cache_request(sw_lod_cache *c, uint32_t face, const sw_lod_cache_req *req)
{
    assert(c);
    const sw_lod_cache_req *r = req ? req : &default_req;
    if (face >= c->n_faces)
        return SW_ERR_INVALID_ARGUMENT;
    if (req_stale(r))
        return SW_OK; /* the camera moved on before we asked: nothing to do */
    slot *s = &c->slots[face];
    for (;;) {
        const uint64_t w = atomic_load_explicit(&s->word, memory_order_acquire);
        switch (state_of(w)) {
        case SW_LOD_CACHE_READY:
        case SW_LOD_CACHE_RUNNING:
            return SW_OK;
        case SW_LOD_CACHE_FAILED:
            return s->result; /* acquire load of the word above: written before FAILED */
        case SW_LOD_CACHE_QUEUED:
            if (queued_covers(s, w, r))
                return SW_OK;
            break;
        default:
            break;
        }
        const bool was_queued = state_of(w) == SW_LOD_CACHE_QUEUED;
        const bool was_stale = was_queued && queued_stale(s, w);
        const sw_result res = claim(c, s, w, r);
        if (res == SW_ERR_LIMIT)
            continue; /* someone else moved the slot on: look again */
        if (res == SW_OK && was_queued)
            count(was_stale ? &c->cancelled : &c->superseded);
        return res;
    }
}

/* ---- converged mode -------------------------------------------------------------------------- */
typedef struct follow {
    sw_lod_cache *cache;
    uint32_t face;
    sw_lod_cache_req req;
} follow;

static bool settled(uint64_t w)
{
    return state_of(w) == SW_LOD_CACHE_READY || state_of(w) == SW_LOD_CACHE_FAILED;
}

/* Runs in the caller's group until the face is built. Submitted without a token so that it is
 * never skipped and always frees its record; it checks its request's staleness itself. */
static void follow_task(void *ctx)
{
    follow *f = ctx;
    slot *s = &f->cache->slots[f->face];
    while (!req_stale(&f->req)) {
        if (settled(atomic_load_explicit(&s->word, memory_order_acquire)))
            break;
        if (sw_lod_cache_request(f->cache, f->face, &f->req) != SW_OK)
            break;
        sw_th_group_wait(f->cache->pool, &s->group); /* runs pool tasks meanwhile */
        const uint64_t w = atomic_load_explicit(&s->word, memory_order_acquire);
        if (!settled(w) && sw_th_group_pending(&s->group) == 0)
            sched_yield(); /* a requester is between its claim and its submission */
    }
    sw__free(f);
}

sw_result sw_lod_cache_request_group(sw_lod_cache *c, uint32_t face, const sw_lod_cache_req *req,
                                     sw_th_group *group)
{
    assert(c && group);
    const sw_lod_cache_req *r = req ? req : &default_req;
    const sw_result res = sw_lod_cache_request(c, face, r);
    if (res != SW_OK || req_stale(r) ||
        settled(atomic_load_explicit(&c->slots[face].word, memory_order_acquire)))
        return res;
    follow *f = sw__malloc(sizeof *f);
    if (!f)
        return SW_ERR_OUT_OF_MEMORY;
    *f = (follow){c, face, *r};
    const sw_th_task task = {
        follow_task, f, r->priority, NULL, 0, group, sw_th_task_kind_of(&k_wait)};
    if (sw_th_pool_submit(c->pool, &task) != SW_OK) {
        sw__free(f);
        return SW_ERR_OUT_OF_MEMORY;
    }
    return SW_OK;
}

/* ---- lookups --------------------------------------------------------------------------------- */
const sw_lod_hierarchy *sw_lod_cache_get(const sw_lod_cache *c, uint32_t face)
{
    assert(c);
    if (face >= c->n_faces)
        return NULL;
    /* seq_cst: ordered after the reader's epoch exchange in sw_lod_cache_reader_enter (the
     * reclamation argument needs both in one total order); also acquires the release store of
     * the publisher, so the hierarchy's contents are visible. */
    return atomic_load_explicit(&c->slots[face].current, memory_order_seq_cst);
}

sw_lod_cache_state sw_lod_cache_state_get(const sw_lod_cache *c, uint32_t face)
{
    assert(c && face < c->n_faces);
    slot *s = &c->slots[face];
    const uint64_t w = atomic_load_explicit(&s->word, memory_order_acquire);
    if (state_of(w) == SW_LOD_CACHE_QUEUED && queued_stale(s, w))
        return SW_LOD_CACHE_EMPTY;
    return (sw_lod_cache_state)state_of(w);
}

sw_result sw_lod_cache_failure(const sw_lod_cache *c, uint32_t face, sw_status *status)
{
    assert(c && face < c->n_faces);
    const slot *s = &c->slots[face];
    if (state_of(atomic_load_explicit(&s->word, memory_order_acquire)) != SW_LOD_CACHE_FAILED) {
        sw__status_ok(status);
        return SW_OK;
    }
    return sw__fail(status, s->result, "face %u: %s", (unsigned)face,
                    s->message ? s->message : sw_result_str(s->result));
}

uint32_t sw_lod_cache_face_count(const sw_lod_cache *c)
{
    return c->n_faces;
}

sw_th_pool *sw_lod_cache_pool(const sw_lod_cache *c)
{
    return c->pool;
}

const sw_sg_scene *sw_lod_cache_scene(const sw_lod_cache *c)
{
    return c->scene;
}

/* ---- epochs and reclamation ------------------------------------------------------------------ */
int32_t sw_lod_cache_reader_add(sw_lod_cache *c)
{
    for (uint32_t i = 0; i < c->n_readers; ++i) {
        int expected = 0;
        if (atomic_compare_exchange_strong_explicit(&c->readers[i].used, &expected, 1,
                                                    memory_order_acq_rel, memory_order_relaxed))
            return (int32_t)i;
    }
    return -1;
}

void sw_lod_cache_reader_remove(sw_lod_cache *c, int32_t r)
{
    assert(r >= 0 && (uint32_t)r < c->n_readers);
    assert(atomic_load_explicit(&c->readers[r].epoch, memory_order_relaxed) == 0);
    atomic_store_explicit(&c->readers[r].used, 0, memory_order_release);
}

void sw_lod_cache_reader_enter(sw_lod_cache *c, int32_t r)
{
    assert(r >= 0 && (uint32_t)r < c->n_readers);
    const uint64_t e = atomic_load_explicit(&c->epoch, memory_order_seq_cst);
    /* seq_cst RMW: in the total order before this section's loads of `current`, so a collector
     * that scans after a replacement either sees this epoch (<= the replacement's) or sees the
     * section over. */
    atomic_exchange_explicit(&c->readers[r].epoch, e, memory_order_seq_cst);
}

void sw_lod_cache_reader_leave(sw_lod_cache *c, int32_t r)
{
    assert(r >= 0 && (uint32_t)r < c->n_readers);
    /* release: the section's reads happen before a collector that sees 0 frees anything */
    atomic_store_explicit(&c->readers[r].epoch, 0, memory_order_release);
}

/* Smallest epoch of a reader inside a section, or UINT64_MAX when none is. */
static uint64_t oldest_reader(sw_lod_cache *c)
{
    uint64_t oldest = UINT64_MAX;
    for (uint32_t i = 0; i < c->n_readers; ++i) {
        /* seq_cst: after the retirement's epoch increment in the total order (see the header) */
        const uint64_t e = atomic_load_explicit(&c->readers[i].epoch, memory_order_seq_cst);
        if (e && e < oldest)
            oldest = e;
    }
    return oldest;
}

static void free_version(sw_lod_cache *c, sw_lod_hierarchy *h)
{
    atomic_fetch_sub_explicit(&c->bytes, hierarchy_bytes(h) + sizeof(retired),
                              memory_order_relaxed);
    sw_lod_hierarchy_free(h);
    count(&c->freed_count);
}

size_t sw_lod_cache_collect(sw_lod_cache *c)
{
    retired *done = NULL;
    size_t left = 0;
    pthread_mutex_lock(&c->retire_lock); /* protects c->retired */
    const uint64_t oldest = oldest_reader(c);
    for (retired **p = &c->retired; *p;) {
        retired *r = *p;
        if (r->epoch < oldest) { /* every reader in a section entered after r was replaced */
            *p = r->next;
            r->next = done;
            done = r;
        } else {
            p = &r->next;
            ++left;
        }
    }
    pthread_mutex_unlock(&c->retire_lock);
    while (done) {
        retired *next = done->next;
        free_version(c, done->h);
        sw__free(done);
        done = next;
    }
    return left;
}

/* Replaces the face's version by h (the caller holds the slot's refining flag, so nobody else
 * replaces it meanwhile) and retires the old one. */
static sw_result publish_version(sw_lod_cache *c, slot *s, sw_lod_hierarchy *h)
{
    retired *r = sw__malloc(sizeof *r);
    if (!r)
        return SW_ERR_OUT_OF_MEMORY;
    atomic_fetch_add_explicit(&c->bytes, hierarchy_bytes(h) + sizeof *r, memory_order_relaxed);
    /* seq_cst exchange, then the epoch increment: a reader that loaded the old pointer did so
     * before the exchange, hence entered at an epoch <= the one returned here. The exchange is
     * also the release that publishes h's contents. */
    r->h = atomic_exchange_explicit(&s->current, h, memory_order_seq_cst);
    r->epoch = atomic_fetch_add_explicit(&c->epoch, 1, memory_order_seq_cst);
    pthread_mutex_lock(&c->retire_lock); /* protects c->retired */
    r->next = c->retired;
    c->retired = r;
    pthread_mutex_unlock(&c->retire_lock);
    count(&c->retired_count);
    count(&c->refinements);
    return SW_OK;
}

/* ---- refinement below the leaves ------------------------------------------------------------- */
typedef struct refine_job {
    sw_lod_cache *cache;
    uint32_t face;
    uint32_t n;        /* leaves to refine */
    int32_t *nodes;    /* n, in the same allocation as the job */
    double *tolerance; /* n */
    sw_lod_cache_req req;
} refine_job;

/* Copy-on-write: old's nodes at their indices, then sub's nodes but its root, whose children
 * are hung under `leaf` (which keeps its bicubic: it is still the coarser choice). */
static sw_lod_hierarchy *merge_subtree(const sw_lod_hierarchy *old, int32_t leaf,
                                       const sw_lod_hierarchy *sub)
{
    const int32_t base = old->n_nodes, n = old->n_nodes + sub->n_nodes - 1;
    sw_lod_hierarchy *h = sw__malloc(sizeof *h);
    sw_lod_hnode *nodes = sw__malloc((size_t)n * sizeof *nodes);
    if (!h || !nodes) {
        sw__free(h);
        sw__free(nodes);
        return NULL;
    }
    *h = *old;
    h->nodes = nodes;
    h->n_nodes = n;
    memcpy(nodes, old->nodes, (size_t)old->n_nodes * sizeof *nodes);
#define SW__MAP(i) ((i) < 0 ? -1 : (i) == sub->root ? leaf : base + (i) - ((i) > sub->root))
    for (int32_t i = 0; i < sub->n_nodes; ++i) {
        if (i == sub->root)
            continue;
        sw_lod_hnode *d = &nodes[SW__MAP(i)];
        *d = sub->nodes[i];
        d->child[0] = SW__MAP(d->child[0]);
        d->child[1] = SW__MAP(d->child[1]);
        d->parent = SW__MAP(d->parent);
    }
#undef SW__MAP
    sw_lod_hnode *l = &nodes[leaf];
    const sw_lod_hnode *r = &sub->nodes[sub->root];
    l->split_dir = r->split_dir;
    for (int k = 0; k < 2; ++k) {
        l->child[k] = base + r->child[k] - (r->child[k] > sub->root);
        /* a coarser node never claims less than its children (sw_lod_hierarchy.h) */
        l->error = fmax(l->error, nodes[l->child[k]].error);
    }
    h->n_leaves = old->n_leaves - 1 + sub->n_leaves;
    h->leaves_over_tolerance =
        old->leaves_over_tolerance - (old->nodes[leaf].error > old->leaf_tolerance);
    for (int32_t i = base; i < n; ++i)
        if (nodes[i].child[0] < 0 && nodes[i].error > h->leaf_tolerance)
            ++h->leaves_over_tolerance;
    return h;
}

/* A copy of old whose `leaf` takes the bicubic of `better` (same rectangle, smaller bound): the
 * leaf's rectangle was reduced directly and already meets the request without a split. */
static sw_lod_hierarchy *replace_leaf(const sw_lod_hierarchy *old, int32_t leaf,
                                      const sw_lod_hnode *better)
{
    sw_lod_hierarchy *h = sw__malloc(sizeof *h);
    sw_lod_hnode *nodes = sw__malloc((size_t)old->n_nodes * sizeof *nodes);
    if (!h || !nodes) {
        sw__free(h);
        sw__free(nodes);
        return NULL;
    }
    *h = *old;
    h->nodes = nodes;
    memcpy(nodes, old->nodes, (size_t)old->n_nodes * sizeof *nodes);
    sw_lod_hnode *l = &nodes[leaf];
    memcpy(l->cpw, better->cpw, sizeof l->cpw);
    memcpy(l->box, better->box, sizeof l->box);
    memcpy(l->seg_c, better->seg_c, sizeof l->seg_c);
    memcpy(l->tex_c, better->tex_c, sizeof l->tex_c);
    l->error = better->error;
    h->leaves_over_tolerance -=
        (old->nodes[leaf].error > old->leaf_tolerance) - (l->error > old->leaf_tolerance);
    return h;
}

/* Refinement bounded at its root: a tolerance the bounds cannot meet (their rounding
 * noise, data at the edge of the validated range) asked for ever deeper leaves, frame after
 * frame, memory growing 8-20 MB/s. A leaf is not refined further, and the fallback counted, when
 *  - it lies REFINE_MAX_DEPTH levels below the root (each level halves one direction: 2^-32 of
 *    the face's domain both ways, far below any pixel of a view above the fovy floor);
 *  - its rectangle is at the rounding floor in u or v: no wider than REFINE_FLOOR_ULPS ulps of
 *    its coordinates, where a split no longer yields distinct parameters;
 *  - the hierarchy holds REFINE_MAX_NODES nodes (~90 MB for one face): more than the pixels of a
 *    frame can use.
 * Such a leaf is drawn over budget (the frame counts it, hlod_over_budget). */
enum { REFINE_MAX_DEPTH = 64, REFINE_FLOOR_ULPS = 64, REFINE_MAX_NODES = 1 << 17 };

static int refine_capped(const sw_lod_hierarchy *h, int32_t node)
{
    if (h->n_nodes >= REFINE_MAX_NODES)
        return 1;
    const double *r = h->nodes[node].rect;
    for (int k = 0; k < 2; ++k) {
        const double mag = fmax(fabs(r[2 * k]), fabs(r[2 * k + 1]));
        if (!(r[2 * k + 1] - r[2 * k] > REFINE_FLOOR_ULPS * DBL_EPSILON * mag))
            return 1;
    }
    int32_t depth = 0;
    for (int32_t i = h->nodes[node].parent; i >= 0 && depth < REFINE_MAX_DEPTH;
         i = h->nodes[i].parent)
        ++depth;
    return depth >= REFINE_MAX_DEPTH;
}

/* The leaf's own finer hierarchy merged into a new version of cur, or NULL (nothing to publish). */
static sw_lod_hierarchy *refine_leaf(sw_lod_cache *c, uint32_t face, const sw_lod_hierarchy *cur,
                                     int32_t node, double tolerance)
{
    const sw_lod_hnode *leaf = &cur->nodes[node];
    if (leaf->child[0] >= 0 || leaf->error <= tolerance)
        return NULL;
    if (refine_capped(cur, node)) {
        count(&c->refine_capped);
        return NULL;
    }
    sw_sg_surface surf;
    sw_sg_scene_face_surface(c->scene, face, &surf);
    sw_lod_hierarchy_desc d = c->desc.hierarchy;
    d.leaf_tolerance = tolerance;
    d.use_box = 1;
    memcpy(d.uv_box, leaf->rect, sizeof d.uv_box);
    sw_lod_hierarchy *sub = NULL, *h = NULL;
    if (sw_lod_hierarchy_build(&surf, &d, &sub, NULL) != SW_OK)
        return NULL;
    const sw_lod_hnode *root = &sub->nodes[sub->root];
    if (root->child[0] >= 0 && root->child[1] >= 0)
        h = merge_subtree(cur, node, sub);
    else if ((root->flags & SW_LOD_HNODE_REPRESENTABLE) && root->error < leaf->error)
        h = replace_leaf(cur, node, root);
    sw_lod_hierarchy_free(sub);
    return h;
}

/* Every leaf of the job refined into one new version (node indices of old stay valid in each
 * intermediate version), or NULL when none could be. */
static sw_lod_hierarchy *refined_version(sw_lod_cache *c, const refine_job *j,
                                         const sw_lod_hierarchy *old)
{
    const sw_lod_hierarchy *cur = old;
    sw_lod_hierarchy *own = NULL;
    for (uint32_t k = 0; k < j->n; ++k) {
        sw_lod_hierarchy *h = refine_leaf(c, j->face, cur, j->nodes[k], j->tolerance[k]);
        if (!h)
            continue;
        sw_lod_hierarchy_free(own);
        own = h;
        cur = h;
    }
    return own;
}

static void release_refining(slot *s)
{
    /* release: the next refiner's acquire CAS sees the version published before */
    atomic_store_explicit(&s->refining, -1, memory_order_release);
}

static void refine_task(void *ctx)
{
    refine_job *j = ctx;
    sw_lod_cache *c = j->cache;
    slot *s = &c->slots[j->face];
    if (req_stale(&j->req)) {
        count(&c->refine_cancelled);
    } else {
        /* acquire: stable while we hold the refining flag, only its holder replaces versions */
        const sw_lod_hierarchy *old = atomic_load_explicit(&s->current, memory_order_acquire);
        sw_lod_hierarchy *h = refined_version(c, j, old);
        if (h && publish_version(c, s, h) != SW_OK)
            sw_lod_hierarchy_free(h);
    }
    release_refining(s);
    sw__free(j);
    sw_lod_cache_collect(c);
}

/* With the refining flag held: whether any of the nodes of the face's current version is a leaf
 * above its tolerance that may still be refined (capped ones are counted in *capped). */
static sw_result refine_check(slot *s, const int32_t *nodes, const double *tolerance, uint32_t n,
                              sw_lod_refine_outcome *oc, _Atomic uint64_t *capped)
{
    const sw_lod_hierarchy *h = atomic_load_explicit(&s->current, memory_order_acquire);
    *oc = SW_LOD_REFINE_DONE;
    for (uint32_t k = 0; k < n; ++k) {
        if (nodes[k] < 0 || nodes[k] >= h->n_nodes || !(tolerance[k] > 0.0))
            return SW_ERR_INVALID_ARGUMENT;
        const sw_lod_hnode *l = &h->nodes[nodes[k]];
        if (!(l->child[0] < 0 && l->error > tolerance[k]))
            continue;
        /* a capped leaf stays as it is: asking again each frame would refine nothing */
        if (refine_capped(h, nodes[k]))
            count(capped);
        else
            *oc = SW_LOD_REFINE_SUBMITTED;
    }
    return SW_OK;
}

static refine_job *refine_job_new(sw_lod_cache *c, uint32_t face, const int32_t *nodes,
                                  const double *tolerance, uint32_t n, const sw_lod_cache_req *r)
{
    refine_job *j = sw__malloc(sizeof *j + (size_t)n * (sizeof *j->tolerance + sizeof *j->nodes));
    if (!j)
        return NULL;
    j->cache = c;
    j->face = face;
    j->n = n;
    j->tolerance = (double *)(j + 1);
    j->nodes = (int32_t *)(j->tolerance + n);
    memcpy(j->tolerance, tolerance, (size_t)n * sizeof *tolerance);
    memcpy(j->nodes, nodes, (size_t)n * sizeof *nodes);
    j->req = *r;
    return j;
}

sw_result sw_lod_cache_refine_leaves(sw_lod_cache *c, uint32_t face, const int32_t *nodes,
                                     const double *tolerance, uint32_t n,
                                     const sw_lod_cache_req *req, sw_th_group *group,
                                     sw_lod_refine_outcome *outcome)
{
    assert(c);
    sw_lod_refine_outcome oc_local, *oc = outcome ? outcome : &oc_local;
    const sw_lod_cache_req *r = req ? req : &default_req;
    *oc = SW_LOD_REFINE_DONE;
    if (face >= c->n_faces || n == 0 || !nodes || !tolerance ||
        sw_lod_cache_state_get(c, face) != SW_LOD_CACHE_READY)
        return SW_ERR_INVALID_ARGUMENT;
    if (req_stale(r)) {
        *oc = SW_LOD_REFINE_STALE;
        return SW_OK;
    }
    slot *s = &c->slots[face];
    int32_t idle = -1;
    /* acquire: pairs with release_refining, so the version read next is the newest */
    if (!atomic_compare_exchange_strong_explicit(&s->refining, &idle, nodes[0],
                                                 memory_order_acquire, memory_order_relaxed)) {
        *oc = SW_LOD_REFINE_BUSY;
        return SW_OK;
    }
    sw_result res = refine_check(s, nodes, tolerance, n, oc, &c->refine_capped);
    refine_job *j = NULL;
    if (res == SW_OK && *oc == SW_LOD_REFINE_SUBMITTED) {
        j = refine_job_new(c, face, nodes, tolerance, n, r);
        res = j ? SW_OK : SW_ERR_OUT_OF_MEMORY;
    }
    if (j) {
        /* no token for the pool: the task must run to release the flag; it checks itself */
        const sw_th_task task = {refine_task,
                                 j,
                                 r->priority,
                                 NULL,
                                 0,
                                 group ? group : &c->refine_group,
                                 sw_th_task_kind_of(&k_refine)};
        res = sw_th_pool_submit(c->pool, &task);
        if (res != SW_OK)
            sw__free(j);
    }
    if (res != SW_OK || *oc != SW_LOD_REFINE_SUBMITTED) {
        if (res != SW_OK)
            *oc = SW_LOD_REFINE_DONE;
        release_refining(s);
    }
    return res;
}

sw_result sw_lod_cache_refine(sw_lod_cache *c, uint32_t face, int32_t node, double tolerance,
                              const sw_lod_cache_req *req, sw_th_group *group,
                              sw_lod_refine_outcome *outcome)
{
    if (!(tolerance > 0.0)) {
        if (outcome)
            *outcome = SW_LOD_REFINE_DONE;
        return SW_ERR_INVALID_ARGUMENT;
    }
    return sw_lod_cache_refine_leaves(c, face, &node, &tolerance, 1, req, group, outcome);
}

/* ---- life cycle and accounting --------------------------------------------------------------- */
sw_result sw_lod_cache_create(const sw_sg_scene *scene, sw_th_pool *pool,
                              const sw_lod_cache_desc *desc, sw_lod_cache **out, sw_status *status)
{
    assert(scene && pool && out);
    *out = NULL;
    const sw_lod_cache_desc d = desc ? *desc : (sw_lod_cache_desc){0};
    if (d.max_readers > MAX_READERS)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "lod cache: %u readers (at most %d)",
                        (unsigned)d.max_readers, MAX_READERS);
    /* Over-aligned (its epoch has a cache line of its own): not malloc's alignment. */
    sw_lod_cache *c = sw__aligned_alloc(alignof(sw_lod_cache), sizeof *c);
    if (!c)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "lod cache");
    memset(c, 0, sizeof *c);
    c->scene = scene;
    c->pool = pool;
    c->desc = d;
    c->n_faces = sw_sg_scene_view_ptr(scene)->n_faces;
    c->n_readers = d.max_readers ? d.max_readers : 64;
    c->slots = sw__calloc(c->n_faces ? c->n_faces : 1, sizeof *c->slots);
    c->readers = sw__aligned_alloc(alignof(reader), (size_t)c->n_readers * sizeof *c->readers);
    if (!c->slots || !c->readers || pthread_mutex_init(&c->retire_lock, NULL) != 0) {
        sw__free(c->slots);
        sw__aligned_free(c->readers);
        sw__aligned_free(c);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "lod cache: %u faces",
                        (unsigned)sw_sg_scene_view_ptr(scene)->n_faces);
    }
    for (uint32_t i = 0; i < c->n_faces; ++i) {
        slot *s = &c->slots[i];
        atomic_init(&s->word, make_word(SW_LOD_CACHE_EMPTY, 0));
        atomic_init(&s->q_ticket, 0);
        atomic_init(&s->q_token, NULL);
        atomic_init(&s->q_gen, 0);
        atomic_init(&s->q_prio, 0);
        atomic_init(&s->refining, -1);
        atomic_init(&s->current, NULL);
        sw_th_group_init(&s->group);
        s->cache = c;
    }
    for (uint32_t i = 0; i < c->n_readers; ++i) {
        atomic_init(&c->readers[i].epoch, 0);
        atomic_init(&c->readers[i].used, 0);
    }
    sw_th_group_init(&c->refine_group);
    atomic_init(&c->epoch, 1); /* 0 marks a reader outside a section */
    atomic_init(&c->bytes, sizeof *c + (size_t)c->n_faces * sizeof *c->slots +
                               (size_t)c->n_readers * sizeof *c->readers);
    *out = c;
    sw__status_ok(status);
    return SW_OK;
}

void sw_lod_cache_destroy(sw_lod_cache *c)
{
    if (!c)
        return;
    sw_th_group_wait(c->pool, &c->refine_group);
    for (uint32_t i = 0; i < c->n_faces; ++i)
        sw_th_group_wait(c->pool, &c->slots[i].group);
    for (uint32_t i = 0; i < c->n_faces; ++i) {
        sw_lod_hierarchy_free(atomic_load_explicit(&c->slots[i].current, memory_order_relaxed));
        sw__free(c->slots[i].message);
    }
    for (retired *r = c->retired, *next; r; r = next) {
        next = r->next;
        sw_lod_hierarchy_free(r->h);
        sw__free(r);
    }
    pthread_mutex_destroy(&c->retire_lock);
    sw__free(c->slots);
    sw__aligned_free(c->readers);
    sw__aligned_free(c);
}

size_t sw_lod_cache_memory(const sw_lod_cache *c)
{
    return atomic_load_explicit(&((sw_lod_cache *)c)->bytes, memory_order_relaxed);
}

void sw_lod_cache_stats_get(const sw_lod_cache *c, sw_lod_cache_stats *out)
{
    sw_lod_cache *m = (sw_lod_cache *)c; /* atomic loads need a non-const object in C11 */
    const memory_order o = memory_order_relaxed;
    *out = (sw_lod_cache_stats){
        atomic_load_explicit(&m->submitted, o),        atomic_load_explicit(&m->builds, o),
        atomic_load_explicit(&m->failed, o),           atomic_load_explicit(&m->cancelled, o),
        atomic_load_explicit(&m->superseded, o),       atomic_load_explicit(&m->refinements, o),
        atomic_load_explicit(&m->refine_cancelled, o), atomic_load_explicit(&m->retired_count, o),
        atomic_load_explicit(&m->freed_count, o),      sw_lod_cache_memory(c),
        atomic_load_explicit(&m->refine_capped, o)};
}
