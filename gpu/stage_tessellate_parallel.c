/* SPDX-License-Identifier: MIT */
/* The tessellate stage's picks — unit instances at a static level, then per-frame faces — in
 * chunks shared by the preparing thread and the pool's workers: Kumar et al. 1997 §5's N_c
 * tessellators working on one frame's visible set. Each chunk (a run of consecutive picks) is
 * tessellated into geometry of its own, and the chunks are appended in order, every index
 * rebased, so the output is the one thread's byte for byte. A static pick is a level's triangles
 * and its faces' fat borders: with static LODs most of a frame's borders are there.
 *
 * Claiming, not queueing: the chunks are claimed from one atomic counter by the preparing thread
 * and by helper tasks submitted at FRAME priority. The preparing thread claims until none is left,
 * then waits only for chunks a worker is still running, and never runs any other task: a
 * walkthrough frame never waits behind a hierarchy build in the pool. A helper task that starts
 * after every chunk is claimed (its worker was busy) finds none and returns at once; the job it
 * holds is reference counted, so it outlives the frame's chunks safely.
 *
 * One thread (no pool, the exact path, a patch hook that expects its calls in order, or too few
 * picks to split) runs the picks straight into the frame's geometry. */
#include "frame_stages.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <sched.h>
#include <stdatomic.h>
#include <string.h>

/* The pool's task kind of the chunks. */
static sw_th_task_kind_slot k_chunk = SW_TH_TASK_KIND_SLOT("frame_stage");

enum {
    MIN_PICKS_PER_CHUNK = 16, /* below it a chunk's bookkeeping outweighs its picks */
    CHUNKS_PER_THREAD = 4,    /* chunks per participating thread, for the load's balance */
};

typedef struct chunk {
    size_t first, end; /* picks: statics first, then faces (pick_at) */
    sw__fr_geometry geo;
    sw_gpu_frame_stats st;
    sw_status status;
    sw_result r;
    int by_pool; /* claimed by a worker */
} chunk;

typedef struct tess_job {
    _Atomic int32_t refs;  /* the preparing thread and every helper task not yet returned */
    _Atomic size_t next;   /* next chunk to claim */
    _Atomic size_t done;   /* chunks finished */
    size_t n_chunks;       /* claimers past it touch nothing but the counters */
    chunk *chunks;         /* owned by the preparing thread, valid until done == n_chunks */
    const sw__fr_tess *t0; /* the frame's tessellation state: env and the Bézier sets */
    const sw__fr_visible *vis;
    const sw__fr_selection *sel;
    sw_th_pool *pool;
} tess_job;

/* Pick i of the frame: sel's static picks come first, then its face picks. */
static sw_result tess_pick(sw__fr_tess *t, const sw__fr_visible *vis, const sw__fr_selection *sel,
                           size_t i, sw_status *status)
{
    sw_result r = i < sel->n_statics
                      ? sw__fr_tess_static(t, vis, &sel->statics[i], status)
                      : sw__fr_tess_face(t, sel, &sel->faces[i - sel->n_statics], status);
    return r == SW_OK ? sw__fr_check_budget(t, status) : r;
}

static void job_release(tess_job *job)
{
    if (atomic_fetch_sub_explicit(&job->refs, 1, memory_order_acq_rel) == 1)
        sw__free(job);
}

static void run_chunk(const tess_job *job, chunk *c)
{
    sw__fr_tess t;
    memset(&t, 0, sizeof t);
    t.env = job->t0->env;
    t.bez = job->t0->bez;
    t.st = &c->st;
    t.geo = &c->geo;
    c->r = SW_OK;
    for (size_t i = c->first; i < c->end && c->r == SW_OK; ++i)
        c->r = tess_pick(&t, job->vis, job->sel, i, &c->status);
    c->by_pool = sw_th_pool_current_worker(job->pool) >= 0;
}

/* Claims and runs chunks until none is left. */
static void claim_chunks(tess_job *job)
{
    for (;;) {
        size_t i = atomic_fetch_add_explicit(&job->next, 1, memory_order_relaxed);
        if (i >= job->n_chunks)
            return;
        run_chunk(job, &job->chunks[i]);
        atomic_fetch_add_explicit(&job->done, 1, memory_order_release);
    }
}

static void helper_task(void *ctx)
{
    tess_job *job = ctx;
    claim_chunks(job);
    job_release(job);
}

/* ---- appending a chunk's geometry, every index rebased ----------------------------------------
 */
static sw_result append_mesh(sw__gpu_mesh *dst, const sw__gpu_mesh *src, sw_status *status)
{
    const size_t v0 = dst->n_v;
    sw_result r = sw__gpu_mesh_reserve(dst, src->n_v, src->n_idx, status);
    if (r != SW_OK)
        return r;
    if (src->n_v > 0) /* memcpy wants real pointers even for 0 bytes */
        memcpy(dst->v + dst->n_v, src->v, src->n_v * sizeof *src->v);
    for (size_t i = 0; i < src->n_idx; ++i)
        dst->idx[dst->n_idx + i] = src->idx[i] + (uint32_t)v0;
    dst->n_v += src->n_v;
    dst->n_idx += src->n_idx;
    dst->border_capped += src->border_capped;
    return SW_OK;
}

/* Moves src's items behind dst's. src's loops change owner; the rest of src is left to free. */
static sw_result append_geometry(sw__fr_geometry *dst, sw__fr_geometry *src, sw_status *status)
{
    const size_t idx0 = dst->mesh.n_idx, draw0 = dst->n_draws, loops0 = dst->n_loops;
    const size_t cps0 = dst->n_cps;
    if (!sw__grow((void **)&dst->draws, &dst->cap_draws, draw0 + src->n_draws,
                  sizeof *dst->draws) ||
        !sw__grow((void **)&dst->trims, &dst->cap_trims, dst->n_trims + src->n_trims,
                  sizeof *dst->trims) ||
        !sw__grow((void **)&dst->shares, &dst->cap_shares, 2 * (dst->n_shares + src->n_shares),
                  sizeof *dst->shares) ||
        !sw__grow((void **)&dst->loops, &dst->cap_loops, loops0 + src->n_loops,
                  sizeof *dst->loops) ||
        !sw__grow((void **)&dst->recs, &dst->cap_recs, dst->n_recs + src->n_recs,
                  sizeof *dst->recs) ||
        !sw__grow((void **)&dst->places, &dst->cap_places, dst->n_recs + src->n_recs,
                  sizeof *dst->places) ||
        !sw__grow((void **)&dst->cps, &dst->cap_cps, 4 * (cps0 + src->n_cps), sizeof *dst->cps) ||
        !sw__grow((void **)&dst->resident, &dst->cap_resident, dst->n_resident + src->n_resident,
                  sizeof *dst->resident))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "frame geometry: out of memory");
    sw_result r = append_mesh(&dst->mesh, &src->mesh, status);
    if (r != SW_OK)
        return r;
    for (size_t i = 0; i < src->n_draws; ++i) {
        sw__gpu_draw d = src->draws[i];
        d.first_idx += idx0;
        dst->draws[dst->n_draws++] = d;
    }
    for (size_t i = 0; i < src->n_trims; ++i) {
        pending_trim p = src->trims[i];
        p.draw += draw0;
        if (p.loops >= 0)
            p.loops += (int64_t)loops0;
        dst->trims[dst->n_trims++] = p;
    }
    for (size_t i = 0; i < 2 * src->n_shares; ++i)
        dst->shares[2 * dst->n_shares + i] = src->shares[i] + draw0;
    dst->n_shares += src->n_shares;
    if (src->n_loops > 0)
        memcpy(dst->loops + loops0, src->loops, src->n_loops * sizeof *src->loops);
    dst->n_loops += src->n_loops;
    src->n_loops = 0; /* moved */
    if (src->n_recs > 0)
        memcpy(dst->places + dst->n_recs, src->places, src->n_recs * sizeof *src->places);
    for (size_t i = 0; i < src->n_recs; ++i) {
        sw__gpu_patch_rec rec = src->recs[i];
        rec.cp += (uint32_t)cps0;
        rec.draw += (int32_t)draw0;
        dst->recs[dst->n_recs++] = rec;
    }
    if (src->n_cps > 0)
        memcpy(dst->cps + 4 * cps0, src->cps, 4 * src->n_cps * sizeof *src->cps);
    dst->n_cps += src->n_cps;
    dst->gpu_vertices += src->gpu_vertices;
    dst->border_triangles += src->border_triangles;
    if (src->n_resident > 0)
        memcpy(dst->resident + dst->n_resident, src->resident,
               src->n_resident * sizeof *src->resident);
    dst->n_resident += src->n_resident;
    dst->resident_triangles += src->resident_triangles;
    return SW_OK;
}

/* The counters a tessellation adds to (every counter of the struct but the ones set by other
 * stages, so that one added later is not lost silently: the size check below). pool_waits and
 * ms_pool_wait are not among them: they are the preparing thread's own (sw_th_thread_waits), and
 * a chunk never waits for the pool. */
static void add_stats(sw_gpu_frame_stats *d, const sw_gpu_frame_stats *s)
{
    _Static_assert(
        sizeof(sw_gpu_frame_stats) == 616, /* trim_exact*: the trim plan; shapes_*: cull and the
                                              outline stage; grid_*: submit; proxy*: drawn after
                                              the chunks; not chunks */
        "a field was added to sw_gpu_frame_stats: add it here if tessellation counts it");
    d->faces_drawn += s->faces_drawn;
    d->faces_culled += s->faces_culled;
    d->patches_trimmed += s->patches_trimmed;
    d->patches_untrimmed += s->patches_untrimmed;
    d->patches_culled += s->patches_culled;
    d->triangles += s->triangles;
    d->patches_gpu_evaluated += s->patches_gpu_evaluated;
    d->patches_exact += s->patches_exact;
    d->hlod_nodes += s->hlod_nodes;
    d->hlod_fallback_faces += s->hlod_fallback_faces;
    d->bound_exceeded += s->bound_exceeded;
    d->bound_excess_px =
        d->bound_excess_px > s->bound_excess_px ? d->bound_excess_px : s->bound_excess_px;
    d->hlod_over_budget += s->hlod_over_budget;
    d->budget_coarsened += s->budget_coarsened;
    d->faces_backculled += s->faces_backculled;
    d->trim_loops_floored += s->trim_loops_floored;
    d->borders_capped += s->borders_capped;
    d->border_loops_kept += s->border_loops_kept;
    d->border_loops_made += s->border_loops_made;
    d->border_quads_away += s->border_quads_away;
    d->static_units_drawn += s->static_units_drawn;
    d->static_faces += s->static_faces;
    d->static_triangles += s->static_triangles;
    d->static_levels_used |= s->static_levels_used;
}

/* ---- the stage's entry --------------------------------------------------------------------- */
static sw_result picks_in_line(sw__fr_tess *t, const sw__fr_visible *vis,
                               const sw__fr_selection *sel, size_t n, sw_status *status)
{
    sw_result r = SW_OK;
    for (size_t i = 0; i < n && r == SW_OK; ++i)
        r = tess_pick(t, vis, sel, i, status);
    return r;
}

/* Chunks for n picks among `threads` threads; 1: not worth splitting. */
static size_t chunk_count(size_t n, size_t threads)
{
    size_t by_size = n / MIN_PICKS_PER_CHUNK, want = CHUNKS_PER_THREAD * threads;
    return by_size < want ? by_size : want;
}

static tess_job *job_create(sw__fr_tess *t, const sw__fr_visible *vis, const sw__fr_selection *sel,
                            size_t n, size_t n_chunks)
{
    tess_job *job = sw__calloc(1, sizeof *job);
    chunk *chunks = sw__calloc(n_chunks, sizeof *chunks);
    if (!job || !chunks) {
        sw__free(job);
        sw__free(chunks);
        return NULL;
    }
    for (size_t c = 0; c < n_chunks; ++c) {
        chunks[c].first = n * c / n_chunks;
        chunks[c].end = n * (c + 1) / n_chunks;
        sw__fr_chunk_geometry_take(t->env->ctx, &chunks[c].geo);
    }
    atomic_init(&job->refs, 1);
    atomic_init(&job->next, 0);
    atomic_init(&job->done, 0);
    job->n_chunks = n_chunks;
    job->chunks = chunks;
    job->t0 = t;
    job->vis = vis;
    job->sel = sel;
    job->pool = t->env->pool;
    return job;
}

/* Helper tasks for the workers; each holds a reference. Returns the number submitted. */
static size_t submit_helpers(tess_job *job, size_t helpers)
{
    size_t k = 0;
    for (; k < helpers; ++k) {
        atomic_fetch_add_explicit(&job->refs, 1, memory_order_relaxed);
        sw_th_task task = {helper_task, job,  SW_TH_PRIORITY_FRAME,        NULL,
                           0,           NULL, sw_th_task_kind_of(&k_chunk)};
        if (sw_th_pool_submit(job->pool, &task) != SW_OK) {
            atomic_fetch_sub_explicit(&job->refs, 1, memory_order_relaxed);
            break; /* the chunks left are claimed by the preparing thread */
        }
    }
    return k;
}

/* Waits for the chunks a worker still runs (never running a task meanwhile). */
static void join_chunks(tess_job *job)
{
    unsigned spins = 0;
    while (atomic_load_explicit(&job->done, memory_order_acquire) < job->n_chunks)
        if (++spins > 64)
            sched_yield();
}

static sw_result merge_chunks(sw__fr_tess *t, tess_job *job, sw_status *status)
{
    sw_result r = SW_OK;
    for (size_t c = 0; c < job->n_chunks; ++c) {
        chunk *ch = &job->chunks[c];
        if (r == SW_OK && ch->r != SW_OK) {
            *status = ch->status;
            r = ch->r;
        }
        if (r == SW_OK)
            r = append_geometry(t->geo, &ch->geo, status);
        if (r == SW_OK) {
            add_stats(t->st, &ch->st);
            t->st->tess_chunks_by_pool += (uint64_t)ch->by_pool;
        }
        sw__fr_chunk_geometry_give(t->env->ctx, &ch->geo);
    }
    t->st->tess_chunks += job->n_chunks;
    return r == SW_OK ? sw__fr_check_budget(t, status) : r;
}

sw_result sw__fr_tess_picks(sw__fr_tess *t, const sw__fr_visible *vis, const sw__fr_selection *sel,
                            sw_status *status)
{
    const sw__fr_env *env = t->env;
    const size_t threads = env->pool ? 1 + (size_t)sw_th_pool_worker_count(env->pool) : 1;
    const size_t n = sel->n_statics + sel->n_faces;
    const size_t n_chunks = chunk_count(n, threads);
    if (threads < 2 || n_chunks < 2 || env->exact || env->ctx->patch_hook)
        return picks_in_line(t, vis, sel, n, status);
    tess_job *job = job_create(t, vis, sel, n, n_chunks);
    if (!job)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "frame: out of memory");
    submit_helpers(job, (threads - 1 < n_chunks - 1 ? threads - 1 : n_chunks - 1));
    claim_chunks(job);
    const double t0 = sw__clock_ms();
    join_chunks(job);
    t->st->ms_join += sw__clock_ms() - t0;
    sw_result r = merge_chunks(t, job, status);
    sw__free(job->chunks);
    job->chunks = NULL;
    job_release(job);
    return r;
}
