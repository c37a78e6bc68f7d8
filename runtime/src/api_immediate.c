/* SPDX-License-Identifier: MIT */
/* Public immediate API (sw_immediate.h): Guthe et al. 2005 §8 in modern form — trimmed NURBS
 * objects by handle, drawn by list with model matrices through the renderer's scene frame path,
 * and host shading functions linked between the library's GPU evaluation and trimming.
 *
 * An object is a private one-face scene made by the node API's own check and conversion
 * (sw__rt_nurbs_geom). A draw gathers its objects into one scene (their geometry appended as
 * prototypes, nothing drawn by traversal) and hands the frame the occurrences — face, model
 * matrix, colour — directly, so a renderer keeps that scene, with the hierarchies it builds for
 * it, for as long as the same unchanged objects are drawn, whatever their matrices. */
#include "api_nodes_internal.h"

#include "sw_gpu_internal.h"
#include "sw_hooks.h"
#include "sw_rt_misuse.h"
#include "sw_sg_generate.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct rt_nurbs {
    sw_sg_scene *geom; /* one face; replaced whole by sw_nurbs_update */
    uint64_t serial;   /* unique per geometry in the process: what a renderer's scene is keyed by */
} rt_nurbs;

static sw_rt_pool g_nurbs = SW_RT_POOL_INIT;
/* Protects every rt_nurbs (its geom and serial) and their lifetime: taken by update, destroy and
 * by a draw while it reads the objects it draws. Order: g_nurbs_lock, then g_nurbs.lock. */
static pthread_mutex_t g_nurbs_lock = PTHREAD_MUTEX_INITIALIZER;
static atomic_uint_fast64_t g_geom_serial;

#define SW__IMMEDIATE_MAX_DRAWS 65535u

/* ---- objects ----------------------------------------------------------------------------------
 */

static uint64_t next_serial(void)
{
    /* relaxed: only uniqueness matters */
    return atomic_fetch_add_explicit(&g_geom_serial, 1u, memory_order_relaxed) + 1u;
}

sw_result sw_nurbs_create(const sw_nurbs_desc *desc, sw_nurbs *out, sw_status *status)
{
    if (out)
        out->id = 0;
    if (!desc || !out)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_nurbs_create: NULL desc or out");
    rt_nurbs *n = sw__calloc(1, sizeof *n);
    if (!n)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "sw_nurbs_create: out of memory");
    sw_result r = sw__rt_nurbs_geom(desc, &n->geom, status);
    if (r != SW_OK) {
        sw__free(n);
        return r;
    }
    n->serial = next_serial();
    out->id = sw_rt_pool_add(&g_nurbs, n);
    if (!out->id) {
        sw_sg_scene_free(n->geom);
        sw__free(n);
        return sw__fail(status, SW_ERR_LIMIT, "sw_nurbs_create: 65,535 objects alive already");
    }
    sw__status_ok(status);
    return SW_OK;
}

static sw_result accept_any(void *item, void *ctx)
{
    (void)item;
    (void)ctx;
    return SW_OK;
}

/* Under g_nurbs_lock (which keeps the object alive). */
static sw_result find_nurbs(sw_nurbs handle, const char *fn, rt_nurbs **out, sw_status *status)
{
    void *item = NULL;
    if (sw_rt_pool_get_checked(&g_nurbs, handle.id, accept_any, NULL, &item) != SW_OK)
        return SW__MISUSE(status, SW_ERR_STALE_HANDLE,
                          "%s: sw_nurbs handle %#x is stale or invalid", fn, handle.id);
    *out = item;
    return SW_OK;
}

sw_result sw_nurbs_update(sw_nurbs nurbs, const sw_nurbs_desc *desc, sw_status *status)
{
    if (!desc)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_nurbs_update: NULL desc");
    sw_sg_scene *geom = NULL;
    sw_result r = sw__rt_nurbs_geom(desc, &geom, status); /* checked before anything changes */
    if (r != SW_OK)
        return r;
    pthread_mutex_lock(&g_nurbs_lock);
    rt_nurbs *n = NULL;
    r = find_nurbs(nurbs, "sw_nurbs_update", &n, status);
    if (r == SW_OK) {
        sw_sg_scene *old = n->geom;
        n->geom = geom;
        n->serial = next_serial();
        geom = old;
    }
    pthread_mutex_unlock(&g_nurbs_lock);
    sw_sg_scene_free(geom); /* the old surface, or the new one when the handle was stale */
    if (r == SW_OK)
        sw__status_ok(status);
    return r;
}

sw_result sw_nurbs_destroy(sw_nurbs nurbs)
{
    pthread_mutex_lock(&g_nurbs_lock);
    rt_nurbs *n = sw_rt_pool_remove(&g_nurbs, nurbs.id);
    pthread_mutex_unlock(&g_nurbs_lock);
    if (!n)
        return SW__MISUSE(NULL, SW_ERR_STALE_HANDLE,
                          "sw_nurbs_destroy: sw_nurbs handle %#x is stale or invalid", nurbs.id);
    sw_sg_scene_free(n->geom);
    sw__free(n);
    return SW_OK;
}

/* ---- a renderer's immediate state -------------------------------------------------------------
 */

struct sw_rt_immediate {
    sw_rt_scene *scene;   /* the scene of the objects drawn last (a reference), or NULL */
    uint64_t *serials;    /* its objects' geometry serials, in order of first appearance */
    uint32_t *first_face; /* per object of it: its first face in the scene (n_objects + 1) */
    uint32_t n_objects;
    uint32_t *slot_object; /* scratch of a draw: pool slot -> object index + 1 (0: none) */
    sw_gpu_occurrence *occ;
    size_t cap_occ;
    int has_shading;
    sw__gpu_surface_programs shading; /* the host's (sw_renderer_set_shading) */
};

void sw__rt_immediate_free(struct sw_rt_immediate *im, sw_gpu_context *gpu)
{
    if (!im)
        return;
    if (im->has_shading) {
        sw__gpu_make_current(gpu);
        sw__gpu_shading_free(gpu, &im->shading);
    }
    if (im->scene)
        sw_rt_scene_release(im->scene);
    sw__free(im->serials);
    sw__free(im->first_face);
    sw__free(im->slot_object);
    sw__free(im->occ);
    sw__free(im);
}

static sw_result immediate_state(sw_renderer renderer, const char *fn, int drawing,
                                 struct sw_rt_immediate **out, sw_gpu_context **gpu,
                                 sw_status *status)
{
    struct sw_rt_immediate **slot = NULL;
    sw_result r = sw__rt_renderer_immediate(renderer, fn, drawing, &slot, gpu, status);
    if (r != SW_OK)
        return r;
    if (!*slot && !(*slot = sw__calloc(1, sizeof **slot)))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", fn);
    *out = *slot;
    return SW_OK;
}

/* ---- drawing ----------------------------------------------------------------------------------
 */

/* One draw's objects, resolved under g_nurbs_lock: per draw its object index, and the objects
 * (first appearance first). */
typedef struct draw_set {
    uint32_t *object_of; /* per draw */
    rt_nurbs **objects;  /* n_objects */
    uint64_t *serials;   /* n_objects */
    uint32_t n_objects;
} draw_set;

static void draw_set_free(draw_set *s)
{
    sw__free(s->object_of);
    sw__free(s->objects);
    sw__free(s->serials);
}

static uint32_t slot_of(uint32_t id)
{
    return (id & 0xffffu) - 1u; /* handle_pool.c: (generation << 16) | (slot + 1) */
}

static sw_result resolve_draws(struct sw_rt_immediate *im, const sw_immediate_desc *d, draw_set *s,
                               sw_status *status)
{
    const char *fn = "sw_renderer_draw_nurbs";
    s->object_of = sw__malloc(d->draw_count * sizeof *s->object_of);
    s->objects = sw__malloc(d->draw_count * sizeof *s->objects);
    s->serials = sw__malloc(d->draw_count * sizeof *s->serials);
    if (!im->slot_object)
        im->slot_object = sw__calloc(SW_RT_POOL_MAX_SLOTS + 1u, sizeof *im->slot_object);
    if (!s->object_of || !s->objects || !s->serials || !im->slot_object)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", fn);
    sw_result r = SW_OK;
    uint32_t i = 0;
    for (; i < d->draw_count && r == SW_OK; i++) {
        rt_nurbs *n = NULL;
        r = find_nurbs(d->draws[i].nurbs, fn, &n, status);
        if (r != SW_OK) {
            sw__fail(status, r, "%s: draws[%u]: sw_nurbs handle %#x is stale or invalid", fn, i,
                     d->draws[i].nurbs.id);
            break;
        }
        uint32_t *at = &im->slot_object[slot_of(d->draws[i].nurbs.id)];
        if (!*at) {
            s->objects[s->n_objects] = n;
            s->serials[s->n_objects] = n->serial;
            *at = ++s->n_objects;
        }
        s->object_of[i] = *at - 1u;
    }
    for (uint32_t k = 0; k < i; k++) /* the scratch is all zero again */
        im->slot_object[slot_of(d->draws[k].nurbs.id)] = 0;
    return r;
}

/* The objects' scene: their geometry appended as prototypes (drawn only through the frame's
 * occurrences). Under g_nurbs_lock, which keeps the geometry alive while it is copied. */
static sw_result build_scene(const draw_set *s, sw_rt_scene **out, uint32_t *first_face,
                             sw_status *status)
{
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "immediate scene: out of memory");
    uint32_t n_nodes = 1; /* the builder's root group */
    sw_result r = SW_OK;
    for (uint32_t k = 0; k < s->n_objects && r == SW_OK; k++) {
        const sw_sg_scene_view *v = sw_sg_scene_view_ptr(s->objects[k]->geom);
        first_face[k] = sw_sg_builder_face_count(b);
        uint32_t proto = SW_SG_NONE;
        r = sw__sg_append_model(b, v, n_nodes, &proto, status);
        n_nodes += v->n_nodes;
    }
    first_face[s->n_objects] = sw_sg_builder_face_count(b);
    sw_sg_scene *sg = NULL;
    if (r != SW_OK) {
        sw_sg_builder_free(b);
        return r;
    }
    if ((r = sw_sg_builder_finish(b, &sg, status)) != SW_OK)
        return r;
    sw_rt_scene *scene = sw_rt_scene_alloc(sg);
    if (!scene)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "immediate scene: out of memory");
    scene->ready = 1; /* built here, in memory: nothing to verify */
    scene->ready_result = SW_OK;
    *out = scene;
    return SW_OK;
}

/* The renderer's scene for the set: the one drawn last when it holds the same geometry in the same
 * order, else a new one (whose serial keeps the trim atlas from handing it the old one's
 * textures; those age out of the atlas like any unused entry). */
static sw_result set_scene(struct sw_rt_immediate *im, const draw_set *s, sw_status *status)
{
    if (im->scene && im->n_objects == s->n_objects &&
        memcmp(im->serials, s->serials, s->n_objects * sizeof *s->serials) == 0)
        return SW_OK;
    uint64_t *serials = sw__malloc(s->n_objects * sizeof *serials);
    uint32_t *first_face = sw__malloc((s->n_objects + 1u) * sizeof *first_face);
    sw_rt_scene *scene = NULL;
    sw_result r = serials && first_face
                      ? build_scene(s, &scene, first_face, status)
                      : sw__fail(status, SW_ERR_OUT_OF_MEMORY, "immediate scene: out of memory");
    if (r != SW_OK) {
        sw__free(serials);
        sw__free(first_face);
        return r;
    }
    memcpy(serials, s->serials, s->n_objects * sizeof *serials);
    if (im->scene)
        sw_rt_scene_release(im->scene);
    sw__free(im->serials);
    sw__free(im->first_face);
    im->scene = scene;
    im->serials = serials;
    im->first_face = first_face;
    im->n_objects = s->n_objects;
    return SW_OK;
}

/* The frame's occurrences: every face of every draw's object, under its matrix and colour. */
static sw_result make_occurrences(struct sw_rt_immediate *im, const sw_immediate_desc *d,
                                  const draw_set *s, size_t *n_occ, sw_status *status)
{
    const char *fn = "sw_renderer_draw_nurbs";
    size_t n = 0;
    for (uint32_t i = 0; i < d->draw_count; i++) {
        uint32_t k = s->object_of[i];
        n += im->first_face[k + 1] - im->first_face[k];
    }
    if (!sw__grow((void **)&im->occ, &im->cap_occ, n ? n : 1, sizeof *im->occ))
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", fn);
    size_t at = 0;
    for (uint32_t i = 0; i < d->draw_count; i++) {
        sw_gpu_occurrence o;
        char what[64];
        snprintf(what, sizeof what, "%s: draws[%u]", fn, i);
        sw_result r = sw__rt_read_transform(d->draws[i].model, what, o.world, status);
        if (r == SW_OK)
            r = sw__rt_read_color(d->draws[i].color, what, o.color, status);
        if (r != SW_OK)
            return r;
        uint32_t k = s->object_of[i];
        for (uint32_t f = im->first_face[k]; f < im->first_face[k + 1]; f++) {
            o.face = f;
            im->occ[at++] = o;
        }
    }
    *n_occ = at;
    return SW_OK;
}

/* The world box of the occurrences' control points (their hulls bound the surfaces). */
static void occurrences_box(const sw_sg_scene *sg, const sw_gpu_occurrence *occ, size_t n,
                            double box[6])
{
    for (int k = 0; k < 3; k++) {
        box[k] = INFINITY;
        box[3 + k] = -INFINITY;
    }
    for (size_t i = 0; i < n; i++) {
        sw_sg_surface srf;
        sw_sg_scene_face_surface(sg, occ[i].face, &srf);
        const double *m = occ[i].world;
        for (int32_t p = 0; p < srf.n_u * srf.n_v; p++) {
            const double *h = srf.cpw + 4 * (size_t)p;
            for (int k = 0; k < 3; k++) {
                double x = m[4 * k] * h[0] / h[3] + m[4 * k + 1] * h[1] / h[3] +
                           m[4 * k + 2] * h[2] / h[3] + m[4 * k + 3];
                box[k] = fmin(box[k], x);
                box[3 + k] = fmax(box[3 + k], x);
            }
        }
    }
}

static int camera_zero(const sw_camera *c)
{
    for (int k = 0; k < 3; k++) {
        if (c->eye[k] != 0.0 || c->target[k] != 0.0 || c->up[k] != 0.0)
            return 0;
    }
    return c->fovy_deg == 0.0;
}

static sw_result check_immediate_desc(const sw_immediate_desc *d, sw_status *status)
{
    const char *fn = "sw_renderer_draw_nurbs";
    if (!d)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "%s: NULL desc", fn);
    if (d->draw_count < 1 || d->draw_count > SW__IMMEDIATE_MAX_DRAWS || !d->draws)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "%s: %u draws (1..%u, non-NULL draws)", fn,
                        d->draw_count, SW__IMMEDIATE_MAX_DRAWS);
    return SW_OK;
}

sw_result sw_renderer_draw_nurbs(sw_renderer renderer, const sw_immediate_desc *desc,
                                 sw_frame_stats *stats, sw_status *status)
{
    const char *fn = "sw_renderer_draw_nurbs";
    struct sw_rt_immediate *im = NULL;
    sw_gpu_context *gpu = NULL;
    sw_result r = check_immediate_desc(desc, status);
    if (r == SW_OK)
        r = immediate_state(renderer, fn, 1, &im, &gpu, status);
    if (r != SW_OK)
        return r;
    draw_set s = {0};
    size_t n_occ = 0;
    pthread_mutex_lock(&g_nurbs_lock);
    r = resolve_draws(im, desc, &s, status);
    if (r == SW_OK)
        r = set_scene(im, &s, status);
    pthread_mutex_unlock(&g_nurbs_lock);
    if (r == SW_OK)
        r = make_occurrences(im, desc, &s, &n_occ, status);
    draw_set_free(&s);
    if (r != SW_OK)
        return r;
    sw_frame_desc fd = {0};
    fd.camera = desc->camera;
    if (camera_zero(&desc->camera)) {
        double box[6];
        occurrences_box(im->scene->sg, im->occ, n_occ, box);
        sw_rt_camera_fit_box(box, SW_VIEW_ISO, &fd.camera);
    }
    fd.width = desc->width;
    fd.height = desc->height;
    fd.error_px = desc->error_px;
    fd.output_path = desc->output_path;
    fd.walkthrough = desc->walkthrough;
    fd.present = desc->present;
    fd.present_depth = desc->present_depth;
    fd.near_plane = desc->near_plane;
    fd.eval_exact = desc->eval_exact;
    const sw_rt_frame_extra extra = {
        im->occ, n_occ, im->has_shading && !desc->library_shading ? &im->shading : NULL};
    /* The frame binds the trim atlas on the active texture unit: unit 0, so that the host's
     * textures on units 1 and up stay bound (sw_immediate.h, Bindings); the host's choice of
     * active unit is given back. */
    sw__gpu_make_current(gpu);
    GLint active = GL_TEXTURE0;
    glGetIntegerv(GL_ACTIVE_TEXTURE, &active);
    glActiveTexture(GL_TEXTURE0);
    r = sw__rt_renderer_draw_scene(renderer, fn, im->scene, &fd, &extra, stats, status);
    glActiveTexture((GLenum)active);
    if (r == SW_OK)
        sw__status_ok(status);
    return r;
}

/* ---- host shading -----------------------------------------------------------------------------
 */

const char *sw_glsl_source_ptr(sw_glsl_kind kind)
{
    _Static_assert((int)SW_GLSL_KIND_COUNT == (int)SW__GPU_GLSL_KINDS,
                   "sw_glsl_kind mirrors shaders.c");
    return sw__gpu_glsl_source((int)kind);
}

sw_result sw_renderer_set_shading(sw_renderer renderer, const char *shade_source, sw_status *status)
{
    const char *fn = "sw_renderer_set_shading";
    struct sw_rt_immediate *im = NULL;
    sw_gpu_context *gpu = NULL;
    sw_result r = immediate_state(renderer, fn, 0, &im, &gpu, status);
    if (r != SW_OK)
        return r;
    sw__gpu_surface_programs p = {0};
    if (shade_source && (r = sw__gpu_shading_create(gpu, shade_source, &p, status)) != SW_OK)
        return r; /* the shading before stays */
    if (im->has_shading) {
        sw__gpu_make_current(gpu);
        sw__gpu_shading_free(gpu, &im->shading);
    }
    im->shading = p;
    im->has_shading = shade_source != NULL;
    sw__status_ok(status);
    return SW_OK;
}

sw_result sw_renderer_shading_programs(sw_renderer renderer, uint32_t out[3], sw_status *status)
{
    const char *fn = "sw_renderer_shading_programs";
    if (!out)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "%s: NULL out", fn);
    struct sw_rt_immediate *im = NULL;
    sw_gpu_context *gpu = NULL;
    sw_result r = immediate_state(renderer, fn, 0, &im, &gpu, status);
    if (r != SW_OK)
        return r;
    out[0] = im->has_shading ? im->shading.mesh[SW__GPU_TRIMMED].prog : 0u;
    out[1] = im->has_shading ? im->shading.eval[SW__GPU_TRIMMED].prog : 0u;
    out[2] = im->has_shading ? im->shading.exact[SW__GPU_TRIMMED].prog : 0u;
    sw__status_ok(status);
    return SW_OK;
}
