/* SPDX-License-Identifier: MIT */
/* tests/lodcache: the per-scene cache of face hierarchies (lod/hierarchy/sw_lod_cache.h) on a real
 * model.
 *
 *   once      4 threads request every face of the model concurrently in random order (FRAME and
 *             BACKGROUND, plain and converged): every face is built exactly once (builds ==
 *             faces, each READY), and each published hierarchy is node-by-node identical to a
 *             direct sw_lod_hierarchy_build of the same face; memory grows by exactly the
 *             hierarchies' bytes.
 *   cancel    the token is bumped while the workers are held: every build is skipped by the
 *             pool, the cache counts nothing built, the faces read EMPTY, a stale request submits
 *             nothing, a fresh one rebuilds them all (counted as reclaimed); a FRAME request
 *             supersedes a queued BACKGROUND one and still builds once.
 *   converged request_group + sw_th_group_wait returns with every face READY.
 *   refine    reader threads traverse the versions (checking the tree's invariants and touching
 *             every control point) while leaves are refined: each new version keeps the old nodes
 *             at their indices, the leaves below a refined leaf tile its rectangle and meet the
 *             finer tolerance, and dense sampling of the exact surface stays within every new
 *             leaf's bound; replaced versions are freed once the readers have moved on.
 *   failure   a face whose build fails is FAILED with its result, counted once, never rebuilt.
 *
 * Usage: test_lodcache MODE MODEL [rounds]. Plain C, exits non-zero on the first failure.
 */
#include "sw_lod_bezier.h"
#include "sw_lod_cache.h"
#include "sw_sg_import.h"

#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static int failures;

#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "%s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond);               \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fputc('\n', stderr);                                                                   \
            ++failures;                                                                            \
            return;                                                                                \
        }                                                                                          \
    } while (0)

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static uint64_t xorshift(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

static size_t hier_bytes(const sw_lod_hierarchy *h)
{
    return sizeof *h + (size_t)h->n_nodes * sizeof *h->nodes;
}

/* ---- the model and its reference hierarchies ------------------------------------------------- */
typedef struct model {
    sw_sg_scene *scene;
    uint32_t n_faces;
    sw_lod_hierarchy **ref; /* direct builds; NULL where the build failed */
    sw_result *ref_result;
    double ms_direct;
} model;

static sw_lod_hierarchy_desc face_desc(const sw_sg_scene *scene, uint32_t face)
{
    sw_lod_hierarchy_desc d = {0};
    d.use_box = 1;
    memcpy(d.uv_box, sw_sg_scene_view_ptr(scene)->faces[face].uv_box, sizeof d.uv_box);
    return d;
}

static bool load_model(const char *path, model *m)
{
    memset(m, 0, sizeof *m);
    sw_sg_import_desc d = {path, NULL, NULL, NULL, NULL, 0};
    sw_status st = {0};
    if (sw_sg_import_file(&d, &m->scene, NULL, &st) != SW_OK) {
        fprintf(stderr, "%s: import failed: %s\n", path, st.message);
        return false;
    }
    m->n_faces = sw_sg_scene_view_ptr(m->scene)->n_faces;
    m->ref = calloc(m->n_faces, sizeof *m->ref);
    m->ref_result = calloc(m->n_faces, sizeof *m->ref_result);
    const double t0 = now_s();
    for (uint32_t f = 0; f < m->n_faces; ++f) {
        sw_sg_surface s;
        sw_sg_scene_face_surface(m->scene, f, &s);
        const sw_lod_hierarchy_desc hd = face_desc(m->scene, f);
        m->ref_result[f] = sw_lod_hierarchy_build(&s, &hd, &m->ref[f], NULL);
    }
    m->ms_direct = 1e3 * (now_s() - t0);
    return true;
}

static void free_model(model *m)
{
    for (uint32_t f = 0; f < m->n_faces; ++f)
        sw_lod_hierarchy_free(m->ref[f]);
    free(m->ref);
    free(m->ref_result);
    sw_sg_scene_free(m->scene);
}

/* Field by field, bit for bit (the struct has tail padding). */
static bool same_node(const sw_lod_hnode *x, const sw_lod_hnode *y)
{
    return !memcmp(x->rect, y->rect, sizeof x->rect) && !memcmp(x->cpw, y->cpw, sizeof x->cpw) &&
           !memcmp(&x->error, &y->error, sizeof x->error) &&
           !memcmp(x->box, y->box, sizeof x->box) && !memcmp(x->seg_c, y->seg_c, sizeof x->seg_c) &&
           !memcmp(x->tex_c, y->tex_c, sizeof x->tex_c) && x->child[0] == y->child[0] &&
           x->child[1] == y->child[1] && x->parent == y->parent && x->split_dir == y->split_dir &&
           x->flags == y->flags;
}

static bool same_hierarchy(const sw_lod_hierarchy *a, const sw_lod_hierarchy *b)
{
    if (a->n_nodes != b->n_nodes || a->root != b->root || a->n_patches != b->n_patches ||
        a->n_leaves != b->n_leaves || a->leaves_over_tolerance != b->leaves_over_tolerance ||
        memcmp(&a->leaf_tolerance, &b->leaf_tolerance, sizeof(double)) != 0)
        return false;
    for (int32_t i = 0; i < a->n_nodes; ++i)
        if (!same_node(&a->nodes[i], &b->nodes[i]))
            return false;
    return true;
}

static sw_th_pool *make_pool(uint32_t workers)
{
    sw_th_pool_desc pd = {0};
    pd.worker_count = workers;
    sw_th_pool *pool = NULL;
    if (sw_th_pool_create(&pd, &pool) != SW_OK) {
        fprintf(stderr, "pool creation failed\n");
        exit(2);
    }
    return pool;
}

static sw_lod_cache *make_cache(const model *m, sw_th_pool *pool)
{
    sw_lod_cache *c = NULL;
    sw_status st = {0};
    if (sw_lod_cache_create(m->scene, pool, NULL, &c, &st) != SW_OK) {
        fprintf(stderr, "cache creation failed: %s\n", st.message);
        exit(2);
    }
    return c;
}

/* Every face settled, matching the reference build (result and hierarchy). */
static void check_against_reference(const model *m, const sw_lod_cache *c)
{
    for (uint32_t f = 0; f < m->n_faces; ++f) {
        const sw_lod_cache_state s = sw_lod_cache_state_get(c, f);
        if (m->ref_result[f] != SW_OK) {
            CHECK(s == SW_LOD_CACHE_FAILED, "face %u: state %d, direct build failed", f, (int)s);
            CHECK(sw_lod_cache_failure(c, f, NULL) == m->ref_result[f], "face %u", f);
            continue;
        }
        CHECK(s == SW_LOD_CACHE_READY, "face %u: state %d", f, (int)s);
        const sw_lod_hierarchy *h = sw_lod_cache_get(c, f);
        CHECK(h && same_hierarchy(h, m->ref[f]), "face %u: differs from the direct build", f);
    }
}

static size_t reference_bytes(const model *m)
{
    size_t sum = 0;
    for (uint32_t f = 0; f < m->n_faces; ++f)
        if (m->ref[f])
            sum += hier_bytes(m->ref[f]);
    return sum;
}

/* ---- once: concurrent requesters ------------------------------------------------------------- */
typedef struct requester {
    const model *m;
    sw_lod_cache *cache;
    sw_th_pool *pool;
    uint64_t seed;
    int bad;
} requester;

static void *requester_main(void *arg)
{
    requester *r = arg;
    const uint32_t n = r->m->n_faces;
    uint32_t *order = malloc(n * sizeof *order);
    unsigned char *grouped = calloc(n, 1);
    for (uint32_t i = 0; i < n; ++i)
        order[i] = i;
    for (uint32_t i = n; i > 1; --i) { /* Fisher-Yates */
        const uint32_t j = (uint32_t)(xorshift(&r->seed) % i), t = order[i - 1];
        order[i - 1] = order[j];
        order[j] = t;
    }
    sw_th_group group;
    sw_th_group_init(&group);
    for (uint32_t i = 0; i < n; ++i) {
        const uint64_t x = xorshift(&r->seed);
        const sw_lod_cache_req req = {(x & 1) ? SW_TH_PRIORITY_BACKGROUND : SW_TH_PRIORITY_FRAME,
                                      NULL, 0};
        const uint32_t f = order[i];
        const sw_result want = r->m->ref_result[f];
        sw_result got;
        if ((x >> 1) % 3 == 0) {
            got = sw_lod_cache_request_group(r->cache, f, &req, &group);
            grouped[f] = 1;
        } else {
            got = sw_lod_cache_request(r->cache, f, &req);
        }
        /* a FAILED face returns its failure; before that, requests return SW_OK */
        if (got != SW_OK && got != want)
            r->bad = 1;
    }
    sw_th_group_wait(r->pool, &group);
    for (uint32_t f = 0; f < n; ++f) {
        const sw_lod_cache_state s = sw_lod_cache_state_get(r->cache, f);
        if (grouped[f] && s != SW_LOD_CACHE_READY && s != SW_LOD_CACHE_FAILED)
            r->bad = 2;
    }
    free(order);
    free(grouped);
    return NULL;
}

static void test_once(const model *m, int rounds)
{
    enum { THREADS = 4 };
    sw_th_pool *pool = make_pool(3);
    for (int round = 0; round < rounds; ++round) {
        sw_lod_cache *c = make_cache(m, pool);
        const size_t base = sw_lod_cache_memory(c);
        pthread_t th[THREADS];
        requester rq[THREADS];
        const double t0 = now_s();
        for (int i = 0; i < THREADS; ++i) {
            rq[i] =
                (requester){m, c, pool, 0x9E3779B97F4A7C15ull * (uint64_t)(round * 7 + i + 1), 0};
            pthread_create(&th[i], NULL, requester_main, &rq[i]);
        }
        for (int i = 0; i < THREADS; ++i) {
            pthread_join(th[i], NULL);
            CHECK(!rq[i].bad, "requester %d: %s", i,
                  rq[i].bad == 1 ? "unexpected result" : "converged face not settled");
        }
        /* what the plain requests left in flight: a converged pass over every face */
        sw_th_group g;
        sw_th_group_init(&g);
        for (uint32_t f = 0; f < m->n_faces; ++f)
            sw_lod_cache_request_group(c, f, NULL, &g);
        sw_th_group_wait(pool, &g);
        const double ms = 1e3 * (now_s() - t0);
        sw_lod_cache_stats st;
        sw_lod_cache_stats_get(c, &st);
        CHECK(st.builds == m->n_faces, "round %d: %llu builds of %u faces", round,
              (unsigned long long)st.builds, m->n_faces);
        check_against_reference(m, c);
        if (failures)
            return;
        const size_t grown = sw_lod_cache_memory(c) - base, want = reference_bytes(m);
        CHECK(grown == want, "memory grew by %zu bytes, hierarchies hold %zu", grown, want);
        printf("once round %d: %u faces, %d threads, %u workers: builds %llu (failed %llu), "
               "tasks %llu, superseded %llu; %.1f ms (direct sequential %.1f ms); memory %zu "
               "bytes (%zu fixed + %zu hierarchies)\n",
               round, m->n_faces, THREADS, sw_th_pool_worker_count(pool),
               (unsigned long long)st.builds, (unsigned long long)st.failed,
               (unsigned long long)st.submitted, (unsigned long long)st.superseded, ms,
               m->ms_direct, sw_lod_cache_memory(c), base, grown);
        sw_lod_cache_destroy(c);
    }
    sw_th_pool_destroy(pool);
}

/* ---- holding the workers so that queued tasks cannot start ----------------------------------- */
typedef struct hold {
    _Atomic int arrived, go;
    sw_th_group group;
} hold;

static void hold_task(void *ctx)
{
    hold *h = ctx;
    atomic_fetch_add(&h->arrived, 1);
    while (!atomic_load(&h->go))
        sched_yield();
}

static void hold_workers(sw_th_pool *pool, hold *h)
{
    const uint32_t n = sw_th_pool_worker_count(pool);
    atomic_store(&h->arrived, 0);
    atomic_store(&h->go, 0);
    sw_th_group_init(&h->group);
    for (uint32_t i = 0; i < n; ++i) {
        const sw_th_task t = {hold_task, h,         SW_TH_PRIORITY_FRAME, NULL,
                              0,         &h->group, SW_TH_TASK_OTHER};
        sw_th_pool_submit(pool, &t);
    }
    while (atomic_load(&h->arrived) < (int)n)
        sched_yield();
}

static void release_workers(sw_th_pool *pool, hold *h)
{
    atomic_store(&h->go, 1);
    sw_th_group_wait(pool, &h->group);
}

static bool wait_pool_cancelled(sw_th_pool *pool, uint64_t want)
{
    for (int i = 0; i < 30000; ++i) {
        sw_th_pool_stats ps;
        sw_th_pool_stats_get(pool, &ps);
        if (ps.cancelled >= want)
            return true;
        usleep(1000);
    }
    return false;
}

/* ---- cancel ---------------------------------------------------------------------------------- */
static void test_cancel(const model *m)
{
    sw_th_pool *pool = make_pool(2);
    sw_lod_cache *c = make_cache(m, pool);
    sw_th_token token;
    sw_th_token_init(&token);
    hold h;
    hold_workers(pool, &h);
    const uint64_t g0 = sw_th_token_current(&token);
    for (uint32_t f = 0; f < m->n_faces; ++f) {
        const sw_lod_cache_req req = {SW_TH_PRIORITY_FRAME, &token, g0};
        CHECK(sw_lod_cache_request(c, f, &req) == SW_OK, "face %u", f);
        CHECK(sw_lod_cache_state_get(c, f) == SW_LOD_CACHE_QUEUED, "face %u", f);
        CHECK(sw_lod_cache_request(c, f, &req) == SW_OK, "face %u", f); /* covered: no task */
    }
    const uint64_t g1 = sw_th_token_cancel(&token); /* the camera moved on */
    for (uint32_t f = 0; f < m->n_faces; ++f)
        CHECK(sw_lod_cache_state_get(c, f) == SW_LOD_CACHE_EMPTY, "face %u: stale reads EMPTY", f);
    release_workers(pool, &h);
    CHECK(wait_pool_cancelled(pool, m->n_faces), "the pool did not skip %u tasks", m->n_faces);
    sw_lod_cache_stats st;
    sw_lod_cache_stats_get(c, &st);
    CHECK(st.builds == 0 && st.submitted == m->n_faces, "builds %llu, submitted %llu",
          (unsigned long long)st.builds, (unsigned long long)st.submitted);
    for (uint32_t f = 0; f < m->n_faces; ++f) {
        CHECK(sw_lod_cache_get(c, f) == NULL, "face %u has a hierarchy", f);
        CHECK(sw_lod_cache_state_get(c, f) == SW_LOD_CACHE_EMPTY, "face %u", f);
        const sw_lod_cache_req stale = {SW_TH_PRIORITY_FRAME, &token, g0};
        CHECK(sw_lod_cache_request(c, f, &stale) == SW_OK, "face %u", f);
    }
    sw_lod_cache_stats_get(c, &st);
    CHECK(st.submitted == m->n_faces, "a stale request submitted a build");
    /* the next frame asks again: everything is rebuilt, each once */
    sw_th_group g;
    sw_th_group_init(&g);
    for (uint32_t f = 0; f < m->n_faces; ++f) {
        const sw_lod_cache_req req = {SW_TH_PRIORITY_FRAME, &token, g1};
        sw_lod_cache_request_group(c, f, &req, &g);
    }
    sw_th_group_wait(pool, &g);
    sw_lod_cache_stats_get(c, &st);
    CHECK(st.builds == m->n_faces && st.cancelled == m->n_faces,
          "builds %llu, cancelled %llu of %u", (unsigned long long)st.builds,
          (unsigned long long)st.cancelled, m->n_faces);
    check_against_reference(m, c);
    sw_th_pool_stats ps;
    sw_th_pool_stats_get(pool, &ps);
    printf("cancel: %u builds skipped by the pool (pool counted %llu), reclaimed %llu, rebuilt "
           "%llu\n",
           m->n_faces, (unsigned long long)ps.cancelled, (unsigned long long)st.cancelled,
           (unsigned long long)st.builds);
    sw_lod_cache_destroy(c);

    /* priorities: a background prefetch that the frame now needs is superseded, built once */
    c = make_cache(m, pool);
    hold_workers(pool, &h);
    const sw_lod_cache_req bg = {SW_TH_PRIORITY_BACKGROUND, &token, g1};
    const sw_lod_cache_req fr = {SW_TH_PRIORITY_FRAME, &token, g1};
    for (uint32_t f = 0; f < m->n_faces; ++f)
        sw_lod_cache_request(c, f, &bg);
    for (uint32_t f = 0; f < m->n_faces; ++f) {
        sw_lod_cache_request(c, f, &fr);
        sw_lod_cache_request(c, f, &bg); /* covered by the FRAME request */
    }
    release_workers(pool, &h);
    sw_th_group_init(&g);
    for (uint32_t f = 0; f < m->n_faces; ++f)
        sw_lod_cache_request_group(c, f, &fr, &g);
    sw_th_group_wait(pool, &g);
    sw_lod_cache_stats_get(c, &st);
    CHECK(st.superseded == m->n_faces && st.submitted == 2u * m->n_faces && st.builds == m->n_faces,
          "superseded %llu, submitted %llu, builds %llu", (unsigned long long)st.superseded,
          (unsigned long long)st.submitted, (unsigned long long)st.builds);
    check_against_reference(m, c);
    printf("priority: %llu background builds superseded by frame requests, %llu builds\n",
           (unsigned long long)st.superseded, (unsigned long long)st.builds);
    sw_lod_cache_destroy(c);
    sw_th_pool_destroy(pool);
}

/* ---- converged ------------------------------------------------------------------------------- */
static void test_converged(const model *m)
{
    sw_th_pool *pool = make_pool(2);
    sw_lod_cache *c = make_cache(m, pool);
    sw_th_token token;
    sw_th_token_init(&token);
    sw_th_group g;
    sw_th_group_init(&g);
    const double t0 = now_s();
    for (uint32_t f = 0; f < m->n_faces; ++f) {
        const sw_lod_cache_req req = {SW_TH_PRIORITY_FRAME, &token, 0};
        const sw_result r = sw_lod_cache_request_group(c, f, &req, &g);
        CHECK(r == SW_OK, "face %u: %s", f, sw_result_id_str(r));
    }
    sw_th_group_wait(pool, &g); /* this thread helps build */
    const double ms = 1e3 * (now_s() - t0);
    for (uint32_t f = 0; f < m->n_faces; ++f)
        CHECK(
            sw_lod_cache_state_get(c, f) == SW_LOD_CACHE_READY ||
                (m->ref_result[f] != SW_OK && sw_lod_cache_state_get(c, f) == SW_LOD_CACHE_FAILED),
            "face %u not settled after the converged wait", f);
    check_against_reference(m, c);
    printf("converged: %u faces settled in %.1f ms with %u workers + the waiter\n", m->n_faces, ms,
           sw_th_pool_worker_count(pool));
    sw_lod_cache_destroy(c);
    sw_th_pool_destroy(pool);
}

/* ---- refine ---------------------------------------------------------------------------------- */
typedef struct reader_arg {
    sw_lod_cache *cache;
    const uint32_t *faces;
    int n_faces;
    _Atomic int *stop;
    _Atomic long sections;
    _Atomic int bad;
    double sink;
} reader_arg;

/* The tree's invariants, touching every node's data (a freed version would show under ASan). */
static int check_tree(const sw_lod_hierarchy *h, double *sink)
{
    int32_t stack[256], top = 0, seen = 0;
    stack[top++] = h->root;
    while (top > 0) {
        const int32_t i = stack[--top];
        const sw_lod_hnode *n = &h->nodes[i];
        ++seen;
        *sink += n->cpw[63] + n->error;
        if ((n->child[0] < 0) != (n->child[1] < 0))
            return 1;
        for (int k = 0; k < 2 && n->child[0] >= 0; ++k) {
            const int32_t ci = n->child[k];
            if (ci < 0 || ci >= h->n_nodes || top >= 256)
                return 2;
            const sw_lod_hnode *ch = &h->nodes[ci];
            const double eu = 1e-12 * (fabs(n->rect[0]) + fabs(n->rect[1]) + 1.0),
                         ev = 1e-12 * (fabs(n->rect[2]) + fabs(n->rect[3]) + 1.0);
            if (ch->parent != i || ch->error > n->error || ch->rect[0] < n->rect[0] - eu ||
                ch->rect[1] > n->rect[1] + eu || ch->rect[2] < n->rect[2] - ev ||
                ch->rect[3] > n->rect[3] + ev)
                return 3;
            stack[top++] = ci;
        }
    }
    return seen == h->n_nodes ? 0 : 4;
}

static void *reader_main(void *arg)
{
    reader_arg *a = arg;
    const int32_t me = sw_lod_cache_reader_add(a->cache);
    if (me < 0) {
        atomic_store(&a->bad, -1);
        return NULL;
    }
    int bad = 0;
    while (!bad && !atomic_load_explicit(a->stop, memory_order_relaxed)) {
        sw_lod_cache_reader_enter(a->cache, me);
        for (int k = 0; k < a->n_faces && !bad; ++k) {
            const sw_lod_hierarchy *h = sw_lod_cache_get(a->cache, a->faces[k]);
            bad = h ? check_tree(h, &a->sink) : 5;
        }
        sw_lod_cache_reader_leave(a->cache, me);
        atomic_store(&a->bad, bad);
        atomic_fetch_add(&a->sections, 1);
    }
    sw_lod_cache_reader_remove(a->cache, me);
    return NULL;
}

/* Max distance, on a grid, between the exact surface and the node's bicubic over its rect. */
static double measured_distance(const sw_sg_surface *s, const sw_lod_hnode *n, int grid)
{
    double worst = 0.0;
    for (int j = 0; j <= grid; ++j)
        for (int i = 0; i <= grid; ++i) {
            const double ls = (double)i / grid, lt = (double)j / grid;
            const double u = n->rect[0] + ls * (n->rect[1] - n->rect[0]);
            const double v = n->rect[2] + lt * (n->rect[3] - n->rect[2]);
            double p[3], q[3];
            sw_sg_surface_eval(s, u, v, p);
            sw_lod_bez_eval_euclid(3, 3, 4, n->cpw, ls, lt, q);
            worst = fmax(worst, sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                                     (p[2] - q[2]) * (p[2] - q[2])));
        }
    return worst;
}

/* The version after refining `leaf` of `old` (a copy): old nodes kept, the leaf's subtree tiles
 * its rectangle, its leaves meet tol and their bounds hold against the exact surface. */
static void check_refined(const model *m, uint32_t face, const sw_lod_hnode *old_nodes,
                          int32_t old_n, int32_t leaf, double tol, const sw_lod_hierarchy *h)
{
    CHECK(h->n_nodes >= old_n, "face %u leaf %d: nodes lost", face, leaf);
    for (int32_t i = 0; i < old_n; ++i) {
        sw_lod_hnode a = old_nodes[i], b = h->nodes[i];
        if (i == leaf && b.child[0] >= 0) { /* children hung below: links, split, error */
            CHECK(a.child[0] < 0 && b.error >= a.error, "leaf %d", leaf);
            b.child[0] = b.child[1] = a.child[0];
            b.split_dir = a.split_dir;
            b.error = a.error;
        } else if (i == leaf) { /* or a better bicubic of its own (checked below) */
            memcpy(b.cpw, a.cpw, sizeof b.cpw);
            memcpy(b.box, a.box, sizeof b.box);
            memcpy(b.seg_c, a.seg_c, sizeof b.seg_c);
            memcpy(b.tex_c, a.tex_c, sizeof b.tex_c);
            b.error = a.error;
        }
        CHECK(same_node(&a, &b), "face %u: node %d changed", face, i);
    }
    sw_sg_surface s;
    sw_sg_scene_face_surface(m->scene, face, &s);
    const sw_lod_hnode *l = &h->nodes[leaf];
    double area = 0.0;
    int32_t stack[256], top = 0, leaves = 0;
    stack[top++] = leaf;
    while (top > 0) {
        const sw_lod_hnode *n = &h->nodes[stack[--top]];
        if (n->child[0] >= 0) {
            CHECK(top + 2 <= 256, "too deep");
            stack[top++] = n->child[0];
            stack[top++] = n->child[1];
            continue;
        }
        ++leaves;
        CHECK(n->error <= tol, "face %u: new leaf error %g > tolerance %g", face, n->error, tol);
        const double d = measured_distance(&s, n, 6);
        CHECK(d <= n->error * (1.0 + 1e-9) + 1e-12, "face %u: measured %g > bound %g", face, d,
              n->error);
        area += (n->rect[1] - n->rect[0]) * (n->rect[3] - n->rect[2]);
    }
    const double la = (l->rect[1] - l->rect[0]) * (l->rect[3] - l->rect[2]);
    CHECK(fabs(area - la) <= 1e-9 * la, "leaves cover %g of the leaf's %g", area, la);
    /* a full binary tree: the leaf's subtree holds the new nodes and the leaf */
    CHECK(2 * leaves == h->n_nodes - old_n + 2, "%d leaves for %d new nodes", leaves,
          h->n_nodes - old_n);
}

/* Faces with the most nodes (the most to refine), largest first. */
static int pick_faces(const model *m, uint32_t *out, int want)
{
    int n = 0;
    for (; n < want; ++n) {
        int32_t best = -1;
        for (uint32_t f = 0; f < m->n_faces; ++f) {
            bool taken = !m->ref[f];
            for (int k = 0; k < n && !taken; ++k)
                taken = out[k] == f;
            if (!taken && (best < 0 || m->ref[f]->n_nodes > m->ref[best]->n_nodes))
                best = (int32_t)f;
        }
        if (best < 0)
            break;
        out[n] = (uint32_t)best;
    }
    return n;
}

/* The leaf of h with the largest error (or -1). */
static int32_t worst_leaf(const sw_lod_hierarchy *h)
{
    int32_t best = -1;
    for (int32_t i = 0; i < h->n_nodes; ++i)
        if (h->nodes[i].child[0] < 0 && isfinite(h->nodes[i].error) &&
            (best < 0 || h->nodes[i].error > h->nodes[best].error))
            best = i;
    return best;
}

/* Returns once every reader has run a whole read section after this call (or stopped). */
static void readers_catch_up(reader_arg *ra, int n)
{
    for (int i = 0; i < n; ++i) {
        const long start = atomic_load(&ra[i].sections);
        while (atomic_load(&ra[i].sections) < start + 2 && !atomic_load(&ra[i].bad))
            sched_yield();
    }
}

static void refine_one(const model *m, sw_lod_cache *c, sw_th_pool *pool, uint32_t face,
                       int *refined)
{
    const sw_lod_hierarchy *h = sw_lod_cache_get(c, face); /* only we refine: stable */
    const int32_t leaf = worst_leaf(h);
    CHECK(leaf >= 0, "face %u: no leaf", face);
    const double tol = h->nodes[leaf].error / 8.0;
    const int32_t old_n = h->n_nodes;
    sw_lod_hnode *copy = malloc((size_t)old_n * sizeof *copy);
    memcpy(copy, h->nodes, (size_t)old_n * sizeof *copy);
    sw_th_group g;
    sw_th_group_init(&g);
    sw_lod_refine_outcome oc;
    const sw_result r = sw_lod_cache_refine(c, face, leaf, tol, NULL, &g, &oc);
    sw_th_group_wait(pool, &g);
    if (r == SW_OK && oc == SW_LOD_REFINE_SUBMITTED) {
        const sw_lod_hierarchy *nh = sw_lod_cache_get(c, face);
        if (nh != h) {
            check_refined(m, face, copy, old_n, leaf, tol, nh);
            ++*refined;
        } else {
            ++failures;
            fprintf(stderr, "face %u leaf %d: refinement published nothing\n", face, leaf);
        }
    } else {
        ++failures;
        fprintf(stderr, "face %u leaf %d: refine %s, outcome %d\n", face, leaf, sw_result_id_str(r),
                (int)oc);
    }
    free(copy);
}

/* Several leaves of one face in one task: one new version, every leaf refined in it. */
static void refine_many(sw_lod_cache *c, sw_th_pool *pool, uint32_t face)
{
    enum { MANY = 4 };
    const sw_lod_hierarchy *h = sw_lod_cache_get(c, face);
    int32_t nodes[MANY];
    double tol[MANY], err[MANY];
    uint32_t n = 0;
    for (int32_t i = 0; i < h->n_nodes && n < MANY; ++i)
        if (h->nodes[i].child[0] < 0 && h->nodes[i].error > 0.0) {
            nodes[n] = i;
            err[n] = h->nodes[i].error;
            tol[n++] = h->nodes[i].error / 4;
        }
    const int32_t n_before = h->n_nodes; /* h is freed once replaced: no reader slot here */
    if (n < 2)
        return; /* a face with fewer inexact leaves shows nothing here */
    sw_lod_cache_stats before, after;
    sw_lod_cache_stats_get(c, &before);
    sw_th_group g;
    sw_th_group_init(&g);
    sw_lod_refine_outcome oc;
    CHECK(sw_lod_cache_refine_leaves(c, face, nodes, tol, n, NULL, &g, &oc) == SW_OK &&
              oc == SW_LOD_REFINE_SUBMITTED,
          "refine_leaves: outcome %d", (int)oc);
    sw_th_group_wait(pool, &g);
    sw_lod_cache_stats_get(c, &after);
    const sw_lod_hierarchy *h2 = sw_lod_cache_get(c, face);
    CHECK(after.refinements == before.refinements + 1 && h2->n_nodes > n_before,
          "%u leaves: %llu versions published", n,
          (unsigned long long)(after.refinements - before.refinements));
    for (uint32_t k = 0; k < n; ++k) {
        const sw_lod_hnode *l = &h2->nodes[nodes[k]];
        CHECK(l->child[0] >= 0 || l->error < err[k], "leaf %d of the batch not refined", nodes[k]);
    }
    printf("refine_leaves: %u leaves of face %u in one version (%d -> %d nodes)\n", n, face,
           n_before, h2->n_nodes);
}

static void test_refine(const model *m, int rounds)
{
    enum { FACES = 4, READERS = 2 };
    uint32_t faces[FACES];
    const int nf = pick_faces(m, faces, FACES);
    sw_th_pool *pool = make_pool(2);
    sw_lod_cache *c = make_cache(m, pool);
    sw_th_group g;
    sw_th_group_init(&g);
    for (int k = 0; k < nf; ++k)
        sw_lod_cache_request_group(c, faces[k], NULL, &g);
    sw_th_group_wait(pool, &g);
    const size_t mem0 = sw_lod_cache_memory(c);

    _Atomic int stop = 0;
    pthread_t th[READERS];
    reader_arg ra[READERS];
    for (int i = 0; i < READERS; ++i) {
        ra[i] = (reader_arg){c, faces, nf, &stop, 0, 0, 0.0};
        atomic_init(&ra[i].sections, 0);
        atomic_init(&ra[i].bad, 0);
        pthread_create(&th[i], NULL, reader_main, &ra[i]);
    }
    int refined = 0;
    readers_catch_up(ra, READERS);
    for (int round = 0; round < rounds && !failures; ++round)
        for (int k = 0; k < nf && !failures; ++k) {
            refine_one(m, c, pool, faces[k], &refined);
            readers_catch_up(ra, READERS); /* each version is read, and retired under readers */
        }
    atomic_store(&stop, 1);
    long sections = 0;
    for (int i = 0; i < READERS; ++i) {
        pthread_join(th[i], NULL);
        CHECK(atomic_load(&ra[i].bad) == 0, "reader %d: invariant %d broken", i,
              atomic_load(&ra[i].bad));
        sections += atomic_load(&ra[i].sections);
    }
    if (failures)
        return;

    /* what the API refuses or skips */
    const uint32_t f0 = faces[0];
    const sw_lod_hierarchy *h = sw_lod_cache_get(c, f0);
    sw_lod_refine_outcome oc;
    CHECK(sw_lod_cache_refine(c, f0, h->root, 1e-9, NULL, NULL, &oc) == SW_OK &&
              oc == SW_LOD_REFINE_DONE,
          "refining an inner node: outcome %d", (int)oc);
    CHECK(sw_lod_cache_refine(c, f0, h->n_nodes, 1e-3, NULL, NULL, &oc) == SW_ERR_INVALID_ARGUMENT,
          "node out of range");
    sw_th_token token;
    sw_th_token_init(&token);
    hold hw;
    hold_workers(pool, &hw);
    const int32_t leaf = worst_leaf(h);
    const sw_lod_cache_req req = {SW_TH_PRIORITY_BACKGROUND, &token, 0};
    CHECK(sw_lod_cache_refine(c, f0, leaf, h->nodes[leaf].error / 4, &req, NULL, &oc) == SW_OK &&
              oc == SW_LOD_REFINE_SUBMITTED,
          "outcome %d", (int)oc);
    CHECK(sw_lod_cache_refine(c, f0, leaf, h->nodes[leaf].error / 4, &req, NULL, &oc) == SW_OK &&
              oc == SW_LOD_REFINE_BUSY,
          "second refinement in flight: outcome %d", (int)oc);
    sw_th_token_cancel(&token);
    CHECK(sw_lod_cache_refine(c, faces[1 % nf], 0, 1e-3, &req, NULL, &oc) == SW_OK &&
              oc == SW_LOD_REFINE_STALE,
          "stale request: outcome %d", (int)oc);
    release_workers(pool, &hw);
    /* the cancelled refinement runs, publishes nothing, and frees the face for the next one */
    sw_lod_cache_stats st;
    for (int i = 0; i < 30000; ++i) {
        sw_lod_cache_stats_get(c, &st);
        if (st.refine_cancelled > 0)
            break;
        usleep(1000);
    }
    CHECK(sw_lod_cache_get(c, f0) == h, "a cancelled refinement published a version");

    CHECK(sw_lod_cache_collect(c) == 0, "retired versions left with no reader inside");
    /* The cancelled task ends with a collect of its own, which may have taken the last retired
     * version off the list just before ours and still be freeing it: wait for its count. */
    for (int i = 0; i < 30000; ++i) {
        sw_lod_cache_stats_get(c, &st);
        if (st.versions_freed == st.versions_retired)
            break;
        usleep(1000);
    }
    sw_lod_cache_stats_get(c, &st);
    CHECK(st.refinements == (uint64_t)refined && st.versions_retired == st.refinements &&
              st.versions_freed == st.versions_retired && st.refine_cancelled == 1,
          "refinements %llu (%d), retired %llu, freed %llu, cancelled %llu",
          (unsigned long long)st.refinements, refined, (unsigned long long)st.versions_retired,
          (unsigned long long)st.versions_freed, (unsigned long long)st.refine_cancelled);
    size_t want = mem0;
    for (int k = 0; k < nf; ++k)
        want += hier_bytes(sw_lod_cache_get(c, faces[k])) - hier_bytes(m->ref[faces[k]]);
    CHECK(sw_lod_cache_memory(c) == want, "memory %zu, expected %zu", sw_lod_cache_memory(c), want);
    printf("refine: %d refinements of %d faces (tolerance / 8 each), %ld read sections by %d "
           "readers meanwhile, %llu versions retired and freed; memory %zu -> %zu bytes\n",
           refined, nf, sections, READERS, (unsigned long long)st.versions_freed, mem0,
           sw_lod_cache_memory(c));
    refine_many(c, pool, faces[0]);
    sw_lod_cache_destroy(c);
    sw_th_pool_destroy(pool);
}

/* ---- failure --------------------------------------------------------------------------------- */
/* Two bilinear faces; the second's trim box misses its domain, so its hierarchy cannot be built. */
static sw_sg_scene *two_face_scene(void)
{
    sw_sg_builder *b = sw_sg_builder_create();
    static const double knots[4] = {0, 0, 1, 1};
    static const double cpw[16] = {0, 0, 0, 1, 1, 0, 0, 1, 0, 1, 0, 1, 1, 1, 0.5, 1};
    for (int k = 0; k < 2; ++k) {
        sw_sg_face_rec f;
        memset(&f, 0, sizeof f);
        f.deg_u = f.deg_v = 1;
        f.n_u = f.n_v = 2;
        f.knots_u = sw_sg_builder_push_doubles(b, knots, 4);
        f.knots_v = sw_sg_builder_push_doubles(b, knots, 4);
        f.cpw = sw_sg_builder_push_doubles(b, cpw, 16);
        f.kind = SW_SG_KIND_BSPLINE;
        f.uv_box[0] = f.uv_box[2] = k ? 5.0 : 0.0;
        f.uv_box[1] = f.uv_box[3] = k ? 6.0 : 1.0;
        const uint32_t face = sw_sg_builder_add_face(b, &f);
        sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, face, NULL, NULL, NULL);
    }
    sw_sg_scene *scene = NULL;
    sw_status st = {0};
    if (sw_sg_builder_finish(b, &scene, &st) != SW_OK) {
        fprintf(stderr, "scene: %s\n", st.message);
        exit(2);
    }
    return scene;
}

static void test_failure(void)
{
    model m = {0};
    m.scene = two_face_scene();
    m.n_faces = 2;
    sw_th_pool *pool = make_pool(2);
    sw_lod_cache *c = make_cache(&m, pool);
    for (int k = 0; k < 3; ++k) {
        sw_th_group g;
        sw_th_group_init(&g);
        const sw_result r0 = sw_lod_cache_request_group(c, 0, NULL, &g);
        const sw_result r1 = sw_lod_cache_request_group(c, 1, NULL, &g);
        sw_th_group_wait(pool, &g);
        CHECK(r0 == SW_OK, "good face: %s", sw_result_id_str(r0));
        CHECK(k == 0 ? r1 == SW_OK : r1 == SW_ERR_INVALID_ARGUMENT, "round %d: %s", k,
              sw_result_id_str(r1));
    }
    for (int k = 0; k < 100; ++k)
        CHECK(sw_lod_cache_request(c, 1, NULL) == SW_ERR_INVALID_ARGUMENT, "request %d", k);
    sw_status st = {0};
    CHECK(sw_lod_cache_state_get(c, 0) == SW_LOD_CACHE_READY, "good face not READY");
    CHECK(sw_lod_cache_state_get(c, 1) == SW_LOD_CACHE_FAILED, "bad face not FAILED");
    CHECK(sw_lod_cache_get(c, 1) == NULL, "a failed face has a hierarchy");
    CHECK(sw_lod_cache_failure(c, 1, &st) == SW_ERR_INVALID_ARGUMENT && st.message[0],
          "failure not recorded");
    CHECK(sw_lod_cache_failure(c, 0, NULL) == SW_OK, "good face has a failure");
    CHECK(sw_lod_cache_request(c, 2, NULL) == SW_ERR_INVALID_ARGUMENT, "face out of range");
    sw_lod_cache_stats s;
    sw_lod_cache_stats_get(c, &s);
    CHECK(s.builds == 2 && s.failed == 1 && s.submitted == 2, "builds %llu failed %llu tasks %llu",
          (unsigned long long)s.builds, (unsigned long long)s.failed,
          (unsigned long long)s.submitted);
    printf("failure: \"%s\", built once, 103 later requests submitted nothing\n", st.message);
    sw_lod_cache_destroy(c);
    sw_th_pool_destroy(pool);
    sw_sg_scene_free(m.scene);
}

/* Refinement bounded at its root. Asking again and again for a tolerance the bounds
 * cannot meet (1e-300: what a weight of 1e-300 or a coordinate of 1e308 asked for, memory growing
 * 8-20 MB/s in refine_leaf / merge_subtree) ends: every round refines the deepest worst leaf, until
 * the depth cap, the parameter floor or the node cap refuses it, and the refusal is counted in
 * refine_capped. Planted fault (refine_capped() returning 0): all 400 rounds refine, the hierarchy
 * grows past the node cap, and the checks fail. */
static void test_runaway(const model *m)
{
    enum { ROUNDS = 400, MAX_NODES = 1 << 17 };
    uint32_t face;
    if (pick_faces(m, &face, 1) < 1) {
        ++failures;
        return;
    }
    sw_th_pool *pool = make_pool(1);
    sw_lod_cache *c = make_cache(m, pool);
    sw_th_group g;
    sw_th_group_init(&g);
    sw_lod_cache_request_group(c, face, NULL, &g);
    sw_th_group_wait(pool, &g);
    int32_t leaf = worst_leaf(sw_lod_cache_get(c, face));
    int rounds = 0, done = 0;
    for (; rounds < ROUNDS && !done && leaf >= 0; ++rounds) {
        sw_th_group_init(&g);
        sw_lod_refine_outcome oc;
        CHECK(sw_lod_cache_refine(c, face, leaf, 1e-300, NULL, &g, &oc) == SW_OK, "refine");
        sw_th_group_wait(pool, &g);
        done = oc == SW_LOD_REFINE_DONE;
        /* the deepest leaf below the one refined: follow the worse child down */
        const sw_lod_hierarchy *h = sw_lod_cache_get(c, face);
        while (h->nodes[leaf].child[0] >= 0) {
            const int32_t *ch = h->nodes[leaf].child;
            leaf = h->nodes[ch[0]].error >= h->nodes[ch[1]].error ? ch[0] : ch[1];
        }
    }
    sw_lod_cache_stats st;
    sw_lod_cache_stats_get(c, &st);
    const sw_lod_hierarchy *h = sw_lod_cache_get(c, face);
    printf("runaway: face %u, %d rounds, %d nodes, %llu refinements, %llu refused (capped), %zu "
           "bytes\n",
           face, rounds, h->n_nodes, (unsigned long long)st.refinements,
           (unsigned long long)st.refine_capped, sw_lod_cache_memory(c));
    CHECK(done, "refinement at 1e-300 still going after %d rounds", rounds);
    CHECK(st.refine_capped >= 1, "no refusal counted");
    CHECK(h->n_nodes <= MAX_NODES + 4096, "%d nodes", h->n_nodes);
    sw_lod_cache_destroy(c);
    sw_th_pool_destroy(pool);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s once|cancel|converged|refine|runaway|failure [MODEL] [rounds]\n",
                argv[0]);
        return 2;
    }
    const char *mode = argv[1];
    const int rounds = argc > 3 ? atoi(argv[3]) : 2;
    if (!strcmp(mode, "failure")) {
        test_failure();
        return failures != 0;
    }
    if (argc < 3)
        return 2;
    model m;
    if (!load_model(argv[2], &m))
        return 1;
    if (!strcmp(mode, "once"))
        test_once(&m, rounds);
    else if (!strcmp(mode, "cancel"))
        test_cancel(&m);
    else if (!strcmp(mode, "converged"))
        test_converged(&m);
    else if (!strcmp(mode, "refine"))
        test_refine(&m, rounds);
    else if (!strcmp(mode, "runaway"))
        test_runaway(&m);
    else {
        fprintf(stderr, "unknown mode %s\n", mode);
        failures = 1;
    }
    free_model(&m);
    if (failures)
        fprintf(stderr, "%d failure(s)\n", failures);
    return failures != 0;
}
