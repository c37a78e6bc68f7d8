/* SPDX-License-Identifier: MIT */
/* A scene's static LODs built lazily in the worker pool (lod/static/sw_lod_static_set.h says how
 * the units are formed and how slots are published). */
#include "sw_clock.h"
#include "sw_lod_static_set.h"
#include "sw_lod_static_internal.h"
#include "sw_hooks.h"

#include "sw_sg_geom.h"
#include "sw_status_util.h"

#include <assert.h>
#include <math.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The pool's task kind of the set's builds. */
static sw_th_task_kind_slot k_build = SW_TH_TASK_KIND_SLOT("static_build");

typedef struct slot {
    _Atomic int state;                    /* sw_lod_static_state */
    _Atomic(sw_lod_static_chain *) chain; /* READY: the chain */
    sw_th_group group;                    /* the slot's build task */
    sw_status failure;                    /* FAILED: why (written before the state) */
} slot;

struct sw_lod_static_set {
    const sw_sg_scene *scene;
    sw_th_pool *pool;
    sw_lod_static_desc levels;
    int keep_undrawn;          /* sw_lod_static_set_desc */
    int ignore_cached_proxies; /* sw_lod_static_set_desc */
    sw_lod_supersurfaces *ss;
    uint32_t n_faces;
    uint32_t *unit_of_face;       /* n_faces */
    uint32_t *faces;              /* grouped by unit */
    sw_lod_static_patch *patches; /* grouped by unit, sorted by (face, iv, iu) inside */
    sw_lod_static_unit *units;
    uint32_t n_units;
    slot *slots;
    /* unit instances (Kumar §4.4's BVH leaves): made once, read by every frame */
    sw_lod_static_instances in;
    sw_sg_bvh *bvh;
    sw_lod_static_instance *instances;
    sw_lod_static_occ *occs;
    double *face_boxes;
    _Atomic uint64_t n_builds, n_adopted;
    _Atomic uint64_t build_ns;
    _Atomic int cancelled; /* builds not started yet return at once (the set is going away) */
    uint64_t serial;       /* sw_lod_static_set_serial */
    sw__lod_proxies *proxies;
};

static _Atomic uint64_t g_set_serial; /* sets made by this process */

typedef struct build_job {
    sw_lod_static_set *set;
    uint32_t unit;
} build_job;

/* ---- units ------------------------------------------------------------------------------------
 */

/* Home cluster of every face: the cluster holding most of its patches, ties to the lowest index
 * (patches are grouped by cluster and sorted by face inside, so a face's patches in one cluster
 * are consecutive). Faces without patches get SW_LOD_STATIC_NO_UNIT. */
static int home_clusters(const sw_lod_supersurfaces *ss, uint32_t n_faces, uint32_t *home)
{
    uint32_t *best = sw__calloc(n_faces ? n_faces : 1, sizeof *best);
    if (!best)
        return 0;
    for (uint32_t f = 0; f < n_faces; ++f)
        home[f] = SW_LOD_STATIC_NO_UNIT;
    for (uint32_t k = 0; k < ss->n_patches;) {
        const uint32_t face = ss->patches[k].face, c = ss->cluster_of[k];
        uint32_t run = 0;
        while (k < ss->n_patches && ss->patches[k].face == face && ss->cluster_of[k] == c) {
            ++run;
            ++k;
        }
        if (face < n_faces && (run > best[face] || (run == best[face] && c < home[face]))) {
            best[face] = run;
            home[face] = c;
        }
    }
    sw__free(best);
    return 1;
}

/* Renumbers home clusters into units (in cluster order, so deterministic) and fills faces[],
 * patches[] and the units' ranges. */
static sw_result form_units(sw_lod_static_set *s, const uint32_t *home, sw_status *status)
{
    const sw_lod_supersurfaces *ss = s->ss;
    uint32_t *unit_of_cluster =
        sw__malloc((ss->n_clusters ? ss->n_clusters : 1) * sizeof(uint32_t));
    uint32_t *count = sw__calloc(ss->n_clusters + 1, sizeof(uint32_t));
    if (!unit_of_cluster || !count) {
        sw__free(unit_of_cluster);
        sw__free(count);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static LODs: out of memory");
    }
    for (uint32_t f = 0; f < s->n_faces; ++f)
        if (home[f] != SW_LOD_STATIC_NO_UNIT)
            count[home[f]]++;
    for (uint32_t c = 0; c < ss->n_clusters; ++c)
        unit_of_cluster[c] = count[c] ? s->n_units++ : SW_LOD_STATIC_NO_UNIT;
    sw__free(count);
    s->units = sw__calloc(s->n_units ? s->n_units : 1, sizeof *s->units);
    s->faces = sw__malloc((s->n_faces ? s->n_faces : 1) * sizeof *s->faces);
    s->patches = sw__malloc((ss->n_patches ? ss->n_patches : 1) * sizeof *s->patches);
    if (!s->units || !s->faces || !s->patches) {
        sw__free(unit_of_cluster);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static LODs: out of memory");
    }
    for (uint32_t f = 0; f < s->n_faces; ++f) {
        s->unit_of_face[f] =
            home[f] == SW_LOD_STATIC_NO_UNIT ? SW_LOD_STATIC_NO_UNIT : unit_of_cluster[home[f]];
        if (s->unit_of_face[f] != SW_LOD_STATIC_NO_UNIT)
            s->units[s->unit_of_face[f]].n_faces++;
    }
    for (uint32_t k = 0; k < ss->n_patches; ++k) {
        const uint32_t f = ss->patches[k].face;
        if (f < s->n_faces && s->unit_of_face[f] != SW_LOD_STATIC_NO_UNIT)
            s->units[s->unit_of_face[f]].n_patches++;
    }
    uint32_t face_at = 0, patch_at = 0;
    for (uint32_t u = 0; u < s->n_units; ++u) {
        s->units[u].first_face = face_at;
        s->units[u].first_patch = patch_at;
        face_at += s->units[u].n_faces;
        patch_at += s->units[u].n_patches;
        s->units[u].n_faces = s->units[u].n_patches = 0;
    }
    for (uint32_t f = 0; f < s->n_faces; ++f) {
        const uint32_t u = s->unit_of_face[f];
        if (u != SW_LOD_STATIC_NO_UNIT)
            s->faces[s->units[u].first_face + s->units[u].n_faces++] = f;
    }
    for (uint32_t k = 0; k < ss->n_patches; ++k) {
        const uint32_t f = ss->patches[k].face;
        if (f >= s->n_faces || s->unit_of_face[f] == SW_LOD_STATIC_NO_UNIT)
            continue;
        sw_lod_static_unit *un = &s->units[s->unit_of_face[f]];
        s->patches[un->first_patch + un->n_patches++] =
            (sw_lod_static_patch){f, ss->patches[k].iu, ss->patches[k].iv};
    }
    for (uint32_t u = 0; u < s->n_units; ++u)
        qsort(s->patches + s->units[u].first_patch, s->units[u].n_patches, sizeof *s->patches,
              sw__sl_patch_cmp);
    sw__free(unit_of_cluster);
    return SW_OK;
}

static void box_add_net(double box[6], const sw_sg_bezier_patch *p)
{
    const int32_t n = (p->deg_u + 1) * (p->deg_v + 1);
    for (int32_t i = 0; i < n; ++i) {
        const double *h = p->cpw + 4 * i;
        for (int a = 0; a < 3; ++a) {
            const double x = h[a] / h[3];
            box[a] = fmin(box[a], x);
            box[3 + a] = fmax(box[3 + a], x);
        }
    }
}

/* Each unit's box from its faces' cut nets (the patches a chain is built from: the box holds its
 * every vertex, so the frame's nearest-depth test on it is conservative). */
static sw_result unit_boxes(sw_lod_static_set *s, sw_status *status)
{
    for (uint32_t u = 0; u < s->n_units; ++u) {
        sw_lod_static_unit *un = &s->units[u];
        for (int a = 0; a < 3; ++a) {
            un->box[a] = INFINITY;
            un->box[3 + a] = -INFINITY;
        }
        for (uint32_t i = 0; i < un->n_faces; ++i) {
            sw_sg_bezier_set set;
            sw_result r = sw_lod_face_patches(s->scene, s->faces[un->first_face + i], &set, status);
            if (r != SW_OK)
                return r;
            for (int32_t k = 0; k < set.n_u * set.n_v; ++k)
                box_add_net(un->box, &set.patches[k]);
            sw_sg_bezier_set_free(&set);
        }
        un->delta = s->levels.delta > 0.0 ? s->levels.delta : sw_lod_static_default_delta(un->box);
    }
    return SW_OK;
}

/* Each unit's outward cone (Kumar §4.4): its patches' pseudo-Gauss cones from the clustering
 * (outward already: negated for reversed faces), enclosed; the full cone when a face of the unit
 * is not in a closed shell of consistent orientation (seen from both sides). */
static sw_result unit_cones(sw_lod_static_set *s, sw_status *status)
{
    const sw_lod_supersurfaces *ss = s->ss;
    const sw_sg_face_rec *faces = sw_sg_scene_view_ptr(s->scene)->faces;
    uint32_t *first = sw__calloc((size_t)s->n_units + 1, sizeof *first);
    sw_lod_cone *cones = sw__malloc((ss->n_patches ? ss->n_patches : 1) * sizeof *cones);
    unsigned char *open = sw__calloc(s->n_units ? s->n_units : 1, 1);
    if (!first || !cones || !open) {
        sw__free(first);
        sw__free(cones);
        sw__free(open);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static LODs: out of memory");
    }
    for (uint32_t u = 0; u < s->n_units; ++u)
        first[u + 1] = first[u] + s->units[u].n_patches;
    for (uint32_t k = 0; k < ss->n_patches; ++k) { /* grouped by unit, as form_units counted */
        const uint32_t f = ss->patches[k].face;
        const uint32_t u = f < s->n_faces ? s->unit_of_face[f] : SW_LOD_STATIC_NO_UNIT;
        if (u == SW_LOD_STATIC_NO_UNIT)
            continue;
        cones[first[u]++] = ss->patch_cones[k];
        open[u] |= !(faces[f].flags & SW_SG_FACE_CLOSED_SHELL);
    }
    for (uint32_t u = 0; u < s->n_units; ++u) {
        sw_lod_static_unit *un = &s->units[u];
        sw_lod_cone *c = &un->cone;
        if (open[u] || un->n_patches == 0) {
            c->axis[0] = 0.0, c->axis[1] = 0.0, c->axis[2] = 1.0;
            sw_lod_cone_set_angle(c, M_PI);
        } else {
            sw_lod_cone_enclose(cones + first[u] - un->n_patches, un->n_patches, c);
        }
    }
    sw__free(first);
    sw__free(cones);
    sw__free(open);
    return SW_OK;
}

/* ---- unit instances: the leaves of Kumar §4.4's BVH ------------------------------------------ */

typedef struct pending_occ {
    sw_lod_static_occ occ;
    uint32_t instance;
} pending_occ;

typedef struct inst_build {
    const sw_lod_static_set *s;
    uint32_t *map; /* open addressing: (unit, transform) -> instance + 1; 0 empty */
    size_t cap_map;
    sw_sg_bvh_input *items; /* per instance: its transform; face = its index */
    size_t n_items, cap_items;
    sw_lod_static_instance *inst;
    size_t cap_inst;
    pending_occ *occ; /* traversal order */
    size_t n_occ, cap_occ;
    int failed; /* 1: out of memory, 2: over the limit */
} inst_build;

static uint64_t instance_hash(uint32_t unit, const double m[12])
{
    uint64_t h = 1469598103934665603ull ^ unit;
    const unsigned char *b = (const unsigned char *)m;
    for (size_t i = 0; i < 12 * sizeof *m; ++i)
        h = (h ^ b[i]) * 1099511628211ull;
    return h;
}

/* Doubles the map and inserts every instance of a unit again (load stays below 1/2). */
static int grow_map(inst_build *b)
{
    const size_t cap = b->cap_map ? 2 * b->cap_map : 1024;
    uint32_t *map = sw__calloc(cap, sizeof *map);
    if (!map)
        return 0;
    for (size_t i = 0; i < b->n_items; ++i) {
        if (b->inst[i].unit == SW_LOD_STATIC_NO_UNIT)
            continue;
        size_t k = instance_hash(b->inst[i].unit, b->items[i].world) & (cap - 1);
        while (map[k])
            k = (k + 1) & (cap - 1);
        map[k] = (uint32_t)i + 1;
    }
    sw__free(b->map);
    b->map = map;
    b->cap_map = cap;
    return 1;
}

static int new_instance(inst_build *b, uint32_t unit, const double world[12], size_t *out)
{
    if (b->n_items >= INT32_MAX ||
        !sw__grow((void **)&b->items, &b->cap_items, b->n_items + 1, sizeof *b->items) ||
        !sw__grow((void **)&b->inst, &b->cap_inst, b->n_items + 1, sizeof *b->inst))
        return 0;
    sw_sg_bvh_input *it = &b->items[b->n_items];
    memset(it, 0, sizeof *it);
    memcpy(it->world, world, sizeof it->world);
    for (int k = 0; k < 4; ++k)
        it->color[k] = -1.0f;
    it->face = (uint32_t)b->n_items;
    b->inst[b->n_items] = (sw_lod_static_instance){unit, 0, 0};
    *out = b->n_items++;
    return 1;
}

/* The instance of (unit, transform), made on first sight; a face without a unit is one alone. */
static int instance_of(inst_build *b, uint32_t unit, const double world[12], size_t *out)
{
    if (unit == SW_LOD_STATIC_NO_UNIT)
        return new_instance(b, unit, world, out);
    if (2 * (b->n_items + 1) > b->cap_map && !grow_map(b))
        return 0;
    size_t k = instance_hash(unit, world) & (b->cap_map - 1);
    for (; b->map[k]; k = (k + 1) & (b->cap_map - 1)) {
        const size_t i = b->map[k] - 1;
        if (b->inst[i].unit == unit &&
            memcmp(b->items[i].world, world, sizeof b->items[i].world) == 0) {
            *out = i;
            return 1;
        }
    }
    if (!new_instance(b, unit, world, out))
        return 0;
    b->map[k] = (uint32_t)*out + 1;
    return 1;
}

static int visit_occurrence(void *ctx, uint32_t face, const double world[12], const float color[4])
{
    inst_build *b = ctx;
    size_t i;
    if (b->n_occ >= INT32_MAX) {
        b->failed = 2;
        return 1;
    }
    if (!sw__grow((void **)&b->occ, &b->cap_occ, b->n_occ + 1, sizeof *b->occ) ||
        !instance_of(b, sw_lod_static_set_unit_of(b->s, face), world, &i)) {
        b->failed = b->n_items >= INT32_MAX ? 2 : 1;
        return 1;
    }
    static const float k_none[4] = {-1.0f, -1.0f, -1.0f, -1.0f};
    pending_occ *o = &b->occ[b->n_occ++];
    o->occ.face = face;
    memcpy(o->occ.color, color ? color : k_none, sizeof o->occ.color);
    o->instance = (uint32_t)i;
    b->inst[i].n_occ++;
    return 0;
}

/* Groups the occurrences by instance (traversal order inside), boxes the instances and the scene
 * and builds the BVH; takes b's arrays. */
static sw_result finish_instances(sw_lod_static_set *s, inst_build *b, sw_status *status)
{
    s->occs = sw__malloc((b->n_occ ? b->n_occ : 1) * sizeof *s->occs);
    s->instances = b->inst;
    b->inst = NULL;
    if (!s->occs) {
        sw__free(b->items);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static LODs: out of memory");
    }
    uint32_t at = 0;
    for (size_t i = 0; i < b->n_items; ++i) {
        s->instances[i].first_occ = at;
        at += s->instances[i].n_occ;
        s->instances[i].n_occ = 0;
    }
    double sb[6];
    for (int a = 0; a < 3; ++a) {
        sb[a] = INFINITY;
        sb[3 + a] = -INFINITY;
    }
    for (size_t k = 0; k < b->n_occ; ++k) {
        sw_lod_static_instance *in = &s->instances[b->occ[k].instance];
        s->occs[in->first_occ + in->n_occ++] = b->occ[k].occ;
        double box[6];
        sw_sg_box_transform(b->items[b->occ[k].instance].world,
                            s->face_boxes + 6 * (size_t)b->occ[k].occ.face, box);
        for (int a = 0; a < 3; ++a) {
            sb[a] = fmin(sb[a], box[a]);
            sb[3 + a] = fmax(sb[3 + a], box[3 + a]);
        }
    }
    for (size_t i = 0; i < b->n_items; ++i) {
        const sw_lod_static_instance *in = &s->instances[i];
        const double *local = in->unit != SW_LOD_STATIC_NO_UNIT
                                  ? s->units[in->unit].box
                                  : s->face_boxes + 6 * (size_t)s->occs[in->first_occ].face;
        sw_sg_box_transform(b->items[i].world, local, b->items[i].box);
    }
    sw_result r = sw_sg_bvh_build_items(b->items, (uint32_t)b->n_items, &s->bvh, status);
    sw__free(b->items);
    b->items = NULL;
    if (r != SW_OK)
        return r;
    s->in = (sw_lod_static_instances){s->bvh,  s->instances,       (uint32_t)b->n_items,
                                      s->occs, (uint32_t)b->n_occ, s->face_boxes,
                                      {0}};
    memcpy(s->in.scene_box, sb, sizeof s->in.scene_box);
    return SW_OK;
}

/* The scene's face occurrences grouped into unit instances and their BVH (see the header). */
static sw_result make_instances(sw_lod_static_set *s, sw_status *status)
{
    s->face_boxes = sw__malloc((s->n_faces ? s->n_faces : 1) * 6 * sizeof *s->face_boxes);
    if (!s->face_boxes)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static LODs: out of memory");
    for (uint32_t f = 0; f < s->n_faces; ++f)
        sw_sg_bvh_face_box(s->scene, f, s->face_boxes + 6 * (size_t)f);
    inst_build b = {s, NULL, 0, NULL, 0, 0, NULL, 0, NULL, 0, 0, 0};
    sw_result r = sw_sg_scene_traverse(s->scene, visit_occurrence, &b);
    sw__free(b.map);
    if (r == SW_OK && !b.failed) {
        r = finish_instances(s, &b, status);
    } else {
        sw__free(b.items);
        r = b.failed == 2
                ? sw__fail(status, SW_ERR_LIMIT,
                           "static LODs: %zu face occurrences or more (at most 2^31 - 1)", b.n_occ)
                : sw__fail(status, SW_ERR_OUT_OF_MEMORY,
                           "static LODs: %zu face occurrences: out of memory", b.n_occ);
    }
    sw__free(b.inst);
    sw__free(b.occ);
    return r;
}

sw_result sw_lod_static_set_create(const sw_sg_scene *scene, sw_th_pool *pool,
                                   const sw_lod_static_set_desc *desc, sw_lod_static_set **out,
                                   sw_status *status)
{
    assert(scene && pool && out);
    *out = NULL;
    sw_lod_static_set *s = sw__calloc(1, sizeof *s);
    if (!s)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static LODs: out of memory");
    s->scene = scene;
    s->pool = pool;
    s->serial = atomic_fetch_add(&g_set_serial, 1) + 1;
    s->keep_undrawn = desc && desc->keep_undrawn;
    s->ignore_cached_proxies = desc && desc->ignore_cached_proxies;
    s->n_faces = sw_sg_scene_view_ptr(scene)->n_faces;
    /* resolved now: the cache key (lod/static/static_lod_io.c) hashes the values the chains get */
    sw_result r = sw_lod_static_desc_resolve(desc ? &desc->levels : NULL, &s->levels, status);
    if (r == SW_OK)
        r = sw_lod_supersurfaces_build(scene, desc ? &desc->clustering : NULL, &s->ss, status);
    uint32_t *home = NULL;
    if (r == SW_OK) {
        home = sw__malloc((s->n_faces ? s->n_faces : 1) * sizeof *home);
        s->unit_of_face = sw__malloc((s->n_faces ? s->n_faces : 1) * sizeof *s->unit_of_face);
        if (!home || !s->unit_of_face || !home_clusters(s->ss, s->n_faces, home))
            r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static LODs: out of memory");
    }
    if (r == SW_OK)
        r = form_units(s, home, status);
    sw__free(home);
    if (r == SW_OK)
        r = unit_boxes(s, status);
    if (r == SW_OK)
        r = unit_cones(s, status);
    if (r == SW_OK)
        r = make_instances(s, status);
    if (r == SW_OK)
        r = sw__lod_proxies_create(s->bvh->n_nodes, &s->proxies, status);
    if (r == SW_OK && !(s->slots = sw__calloc(s->n_units ? s->n_units : 1, sizeof *s->slots)))
        r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "static LODs: out of memory");
    if (r != SW_OK) {
        sw_lod_static_set_destroy(s);
        return r;
    }
    *out = s;
    return SW_OK;
}

void sw_lod_static_set_cancel(sw_lod_static_set *s)
{
    if (s)
        atomic_store_explicit(&s->cancelled, 1, memory_order_release);
}

int sw__lod_static_set_cancelled(const sw_lod_static_set *s)
{
    return atomic_load_explicit(&s->cancelled, memory_order_acquire);
}

sw_result sw_lod_static_set_build_proxies(sw_lod_static_set *s, sw_status *status)
{
    return sw__lod_proxies_start(s, s->proxies, s->pool, status);
}

sw_result sw__lod_static_set_adopt_proxies(sw_lod_static_set *s, sw_lod_proxy **by_node,
                                           uint64_t failed, uint64_t pruned)
{
    return sw__lod_proxies_adopt(s->proxies, by_node, failed, pruned);
}

int sw__lod_static_set_ignores_cached_proxies(const sw_lod_static_set *s)
{
    return s->ignore_cached_proxies;
}

int sw_lod_static_set_proxies_started(const sw_lod_static_set *s)
{
    return sw__lod_proxies_started(s->proxies);
}

int sw_lod_static_set_proxies_done(const sw_lod_static_set *s)
{
    return sw__lod_proxies_done(s->proxies);
}

void sw_lod_static_set_wait_proxies(sw_lod_static_set *s)
{
    sw__lod_proxies_wait(s->pool, s->proxies);
}

const sw_lod_proxy *sw_lod_static_set_proxy(const sw_lod_static_set *s, uint32_t node)
{
    return sw__lod_proxies_get(s->proxies, node);
}

void sw_lod_static_set_destroy(sw_lod_static_set *s)
{
    if (!s)
        return;
    sw__lod_proxies_destroy(s->pool, s->proxies); /* its builds read the chains */
    if (s->slots) {
        for (uint32_t u = 0; u < s->n_units; ++u) {
            sw_th_group_wait(s->pool, &s->slots[u].group);
            sw_lod_static_free(atomic_load(&s->slots[u].chain));
        }
    }
    sw__free(s->slots);
    sw__free(s->units);
    sw__free(s->faces);
    sw__free(s->patches);
    sw__free(s->unit_of_face);
    sw_sg_bvh_free(s->bvh);
    sw__free(s->instances);
    sw__free(s->occs);
    sw__free(s->face_boxes);
    sw_lod_supersurfaces_free(s->ss);
    sw__free(s);
}

/* ---- lookups ----------------------------------------------------------------------------------
 */

uint32_t sw_lod_static_set_unit_count(const sw_lod_static_set *s)
{
    return s->n_units;
}

uint64_t sw_lod_static_set_serial(const sw_lod_static_set *s)
{
    return s->serial;
}

const sw_sg_scene *sw_lod_static_set_scene(const sw_lod_static_set *s)
{
    return s->scene;
}

const sw_lod_static_desc *sw__lod_static_set_levels(const sw_lod_static_set *s)
{
    return &s->levels;
}

uint32_t sw_lod_static_set_unit_of(const sw_lod_static_set *s, uint32_t face)
{
    return face < s->n_faces ? s->unit_of_face[face] : SW_LOD_STATIC_NO_UNIT;
}

const sw_lod_static_unit *sw_lod_static_set_unit(const sw_lod_static_set *s, uint32_t unit)
{
    return unit < s->n_units ? &s->units[unit] : NULL;
}

const uint32_t *sw_lod_static_set_faces(const sw_lod_static_set *s)
{
    return s->faces;
}

const sw_lod_static_patch *sw_lod_static_set_patches(const sw_lod_static_set *s)
{
    return s->patches;
}

const sw_lod_supersurfaces *sw_lod_static_set_supersurfaces(const sw_lod_static_set *s)
{
    return s->ss;
}

const sw_lod_static_instances *sw_lod_static_set_instances(const sw_lod_static_set *s)
{
    return &s->in;
}

sw_lod_static_state sw_lod_static_set_state(const sw_lod_static_set *s, uint32_t unit)
{
    assert(unit < s->n_units);
    return (sw_lod_static_state)atomic_load_explicit(&s->slots[unit].state, memory_order_acquire);
}

const sw_lod_static_chain *sw_lod_static_set_get(const sw_lod_static_set *s, uint32_t unit)
{
    if (unit >= s->n_units)
        return NULL;
    return atomic_load_explicit(&s->slots[unit].chain, memory_order_acquire);
}

sw_result sw_lod_static_set_failure(const sw_lod_static_set *s, uint32_t unit, const char **message)
{
    if (message)
        *message = NULL;
    if (unit >= s->n_units || sw_lod_static_set_state(s, unit) != SW_LOD_STATIC_FAILED)
        return SW_OK;
    if (message)
        *message = s->slots[unit].failure.message;
    return s->slots[unit].failure.result;
}

/* ---- builds -----------------------------------------------------------------------------------
 */

void sw__lod_static_set_trim(const sw_lod_static_set *s, sw_lod_static_chain *chain)
{
    if (!s->keep_undrawn)
        sw_lod_static_drop_undrawn(chain);
}

/* The levels no frame draws are dropped first: a chain is read by frames only. */
static void publish(sw_lod_static_set *s, slot *sl, sw_lod_static_chain *chain)
{
    sw__lod_static_set_trim(s, chain);
    atomic_store_explicit(&sl->chain, chain, memory_order_release);
    atomic_store_explicit(&sl->state, SW_LOD_STATIC_READY, memory_order_release);
}

static void build_task(void *ctx)
{
    build_job *job = ctx;
    sw_lod_static_set *s = job->set;
    const uint32_t unit = job->unit;
    const sw_lod_static_unit *un = &s->units[unit];
    slot *sl = &s->slots[unit];
    sw__free(job);
    if (atomic_load_explicit(&s->cancelled, memory_order_acquire))
        return; /* the slot stays QUEUED: nobody reads it any more */
    const uint64_t t0 = sw__clock_ns();
    sw_lod_static_chain *chain = NULL;
    sw_status st = {0};
    const sw_lod_static_build_fn build = sw_lod_static_builder();
    const sw_result r =
        build
            ? build(s->scene, s->patches + un->first_patch, un->n_patches, &s->levels, &chain, &st)
            : sw__fail(&st, SW_ERR_UNSUPPORTED,
                       "static LODs: no LOD builder is installed (the LOD-building module, "
                       "sw_lod_build_install); unit %u is drawn per frame",
                       unit);
    atomic_fetch_add(&s->build_ns, sw__clock_ns() - t0);
    atomic_fetch_add(&s->n_builds, 1);
    if (r == SW_OK) {
        publish(s, sl, chain);
        return;
    }
    sl->failure = st;
    sl->failure.result = r;
    atomic_store_explicit(&sl->state, SW_LOD_STATIC_FAILED, memory_order_release);
}

sw_result sw_lod_static_set_request(sw_lod_static_set *s, uint32_t unit, sw_th_priority priority)
{
    if (unit >= s->n_units)
        return SW_ERR_INVALID_ARGUMENT;
    slot *sl = &s->slots[unit];
    int expect = SW_LOD_STATIC_EMPTY;
    if (atomic_load_explicit(&sl->state, memory_order_acquire) != SW_LOD_STATIC_EMPTY ||
        !atomic_compare_exchange_strong(&sl->state, &expect, SW_LOD_STATIC_QUEUED))
        return SW_OK;
    build_job *job = sw__malloc(sizeof *job);
    if (job) {
        *job = (build_job){s, unit};
        /* in the slot's group: converged frames and destroy wait on it */
        const sw_th_task task = {
            build_task, job, priority, NULL, 0, &sl->group, sw_th_task_kind_of(&k_build)};
        if (sw_th_pool_submit(s->pool, &task) == SW_OK)
            return SW_OK;
        sw__free(job);
    }
    atomic_store(&sl->state, SW_LOD_STATIC_EMPTY);
    return SW_ERR_OUT_OF_MEMORY;
}

sw_lod_static_state sw_lod_static_set_wait(sw_lod_static_set *s, uint32_t unit)
{
    if (unit >= s->n_units)
        return SW_LOD_STATIC_EMPTY;
    if (sw_lod_static_set_request(s, unit, SW_TH_PRIORITY_FRAME) != SW_OK)
        return SW_LOD_STATIC_EMPTY;
    slot *sl = &s->slots[unit];
    int waiting = 0; /* one wait of the caller's (sw_th_thread_waits), spins included */
    for (;;) {
        const int st = atomic_load_explicit(&sl->state, memory_order_acquire);
        if (st == SW_LOD_STATIC_READY || st == SW_LOD_STATIC_FAILED || st == SW_LOD_STATIC_EMPTY) {
            if (waiting)
                sw_th_wait_end();
            return (sw_lod_static_state)st;
        }
        if (!waiting) {
            waiting = 1;
            sw_th_wait_begin();
        }
        sw_th_group_wait(s->pool, &sl->group); /* runs pool tasks meanwhile */
        if (sw_th_group_pending(&sl->group) == 0)
            sched_yield(); /* a requester is between its claim and its submission */
    }
}

sw_result sw_lod_static_set_adopt(sw_lod_static_set *s, uint32_t unit, sw_lod_static_chain *chain)
{
    if (unit >= s->n_units) {
        sw_lod_static_free(chain);
        return SW_ERR_INVALID_ARGUMENT;
    }
    slot *sl = &s->slots[unit];
    int expect = SW_LOD_STATIC_EMPTY;
    if (!atomic_compare_exchange_strong(&sl->state, &expect, SW_LOD_STATIC_QUEUED)) {
        sw_lod_static_free(chain);
        return SW_ERR_INVALID_ARGUMENT;
    }
    publish(s, sl, chain);
    atomic_fetch_add(&s->n_adopted, 1);
    return SW_OK;
}

void sw_lod_static_set_get_stats(const sw_lod_static_set *s, sw_lod_static_set_stats *out)
{
    memset(out, 0, sizeof *out);
    out->n_units = s->n_units;
    for (uint32_t u = 0; u < s->n_units; ++u) {
        switch (sw_lod_static_set_state(s, u)) {
        case SW_LOD_STATIC_READY:
            out->ready++;
            out->memory_bytes += sw_lod_static_memory(sw_lod_static_set_get(s, u));
            break;
        case SW_LOD_STATIC_FAILED:
            out->failed++;
            break;
        case SW_LOD_STATIC_QUEUED:
            out->queued++;
            break;
        default:
            break;
        }
    }
    out->builds = atomic_load(&s->n_builds);
    out->adopted = atomic_load(&s->n_adopted);
    out->build_seconds = 1e-9 * (double)atomic_load(&s->build_ns);
    sw__lod_proxies_stats(s->proxies, out);
}
