/* SPDX-License-Identifier: MIT */
/* Public scene API: load (.sws mapped, or imported through OCCT), save, describe, fit cameras. */
#include "sw_rt.h"
#include "sw_hooks.h"

#include "sw_sg_bvh.h"
#include "sw_sg_import.h"
#include "sw_sg_pick.h"
#include "sw_sg_tspline.h"
#include "sw_status_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static sw_rt_pool g_scenes = SW_RT_POOL_INIT;

static int has_extension(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext);
    return n > e && strcasecmp(path + n - e, ext) == 0;
}

static int is_cad_file(const char *path)
{
    static const char *const exts[] = {".step", ".stp", ".iges", ".igs", ".brep"};
    for (size_t i = 0; i < sizeof exts / sizeof exts[0]; i++) {
        if (has_extension(path, exts[i]))
            return 1;
    }
    return 0;
}

sw_rt_scene *sw_rt_scene_alloc(sw_sg_scene *sg)
{
    sw_rt_scene *scene = sw__calloc(1, sizeof *scene);
    if (!scene) {
        sw_sg_scene_free(sg);
        return NULL;
    }
    scene->sg = sg;
    atomic_init(&scene->refs, 1u);
    pthread_mutex_init(&scene->once_lock, NULL);
    return scene;
}

sw_result sw_rt_scene_add_handle(sw_rt_scene *scene, sw_scene *out, sw_status *status)
{
    uint32_t id = sw_rt_pool_add(&g_scenes, scene);
    if (!id) {
        sw_rt_scene_release(scene);
        return sw__fail(status, SW_ERR_LIMIT, "too many scenes loaded at once");
    }
    out->id = id;
    sw__status_ok(status);
    return SW_OK;
}

/* The loaded scene's reference becomes the pool's, dropped by sw_scene_destroy. */
static sw_result wrap_scene(sw_sg_scene *sg, sw_scene *out, sw_status *status)
{
    sw_rt_scene *scene = sw_rt_scene_alloc(sg);
    if (!scene)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "out of memory");
    return sw_rt_scene_add_handle(scene, out, status);
}

/* The importer's callbacks handed on to the host's: the context is the load desc, whose
 * user_data goes to each; the face records become the public ones (the same fields). */
static void relay_progress(void *ctx, double fraction, const char *stage)
{
    const sw_scene_load_desc *desc = ctx;
    desc->progress(desc->user_data, fraction, stage);
}

static void relay_warning(void *ctx, const char *message)
{
    const sw_scene_load_desc *desc = ctx;
    desc->warning(desc->user_data, message);
}

static void relay_face_problem(void *ctx, const sw_sg_face_problem *p)
{
    const sw_scene_load_desc *desc = ctx;
    const sw_face_problem q = {p->path,
                               p->face,
                               p->entity,
                               p->name,
                               p->action == SW_SG_FACE_REPAIRED ? SW_FACE_REPAIRED
                                                                : SW_FACE_SKIPPED,
                               p->reason,
                               p->message};
    desc->face_problem(desc->user_data, &q);
}

sw_result sw_rt_scene_read(const sw_scene_load_desc *desc, sw_sg_scene **out,
                           sw_sg_import_report *report, sw_status *status)
{
    if (report)
        memset(report, 0, sizeof *report);
    if (has_extension(desc->path, ".sws"))
        return sw_sg_scene_open(desc->path, out, status);
    if (has_extension(desc->path, ".tsm"))
        return sw_sg_tspline_import_file(desc->path, out, status);
    if (!is_cad_file(desc->path))
        return sw__fail(status, SW_ERR_UNSUPPORTED,
                        "%s: unknown extension (expected .sws, .step, .stp, .iges, .igs, .brep "
                        "or .tsm)",
                        desc->path);
    sw_sg_import_desc import = {desc->path,
                                desc->progress ? relay_progress : NULL,
                                desc->warning ? relay_warning : NULL,
                                (void *)desc,
                                desc->face_problem ? relay_face_problem : NULL,
                                (desc->flags & SW_LOAD_PARTIAL) ? SW_SG_IMPORT_PARTIAL : 0u};
    return sw_sg_cad_import_file(&import, out, report, status);
}

sw_result sw_scene_load(const sw_scene_load_desc *desc, sw_scene *out, sw_status *status)
{
    if (out)
        out->id = 0;
    if (!desc || !desc->path || !out)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_scene_load: NULL desc, path or out");
    sw_sg_scene *sg = NULL;
    sw_sg_import_report report;
    sw_result r = sw_rt_scene_read(desc, &sg, &report, status);
    if (r != SW_OK)
        return r;
    sw_rt_scene *scene = sw_rt_scene_alloc(sg);
    if (!scene)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "out of memory");
    scene->faces_skipped = report.faces_failed;
    scene->faces_repaired = report.faces_repaired;
    scene->partial = report.truncated;
    return sw_rt_scene_add_handle(scene, out, status);
}

/* The default scene: OCCT's "modern kitchen" sample models are already placed in Room.brep's
 * coordinates; a second chair is an instance of the first, and the motor stands on the table.
 * BREP files carry no colours, so each part gets one (linear RGB). */
typedef struct default_part {
    const char *file;
    int instanced; /* 1: imported once as a prototype, drawn by the instances below */
    float color[4];
} default_part;

static const default_part k_default_parts[] = {
    {"occ/Room.brep", 0, {0.80f, 0.78f, 0.74f, 1}},
    {"occ/MODERN_Table_1.brep", 0, {0.55f, 0.36f, 0.20f, 1}},
    {"occ/MODERN_Chair_1.brep", 1, {0.20f, 0.35f, 0.60f, 1}},
    {"occ/MODERN_Cooker_1.brep", 0, {0.85f, 0.85f, 0.88f, 1}},
    {"occ/MODERN_Exhaust_1.brep", 0, {0.60f, 0.62f, 0.66f, 1}},
    {"occ/MODERN_MVCooker_1.brep", 0, {0.30f, 0.30f, 0.32f, 1}},
    {"occ/MODERN_Refrigerator_1.brep", 0, {0.92f, 0.92f, 0.95f, 1}},
    {"occ/MODERN_Sink_1.brep", 0, {0.70f, 0.72f, 0.75f, 1}},
    {"occ/Motor-c.brep", 0, {0.75f, 0.30f, 0.15f, 1}},
};

/* Row-major 3x4 transforms. The chair's twin is turned by 180° about the table's vertical axis
 * (table centre x = 200, y = 214.3); the motor is scaled by 0.3 onto the table top (z = 60.4). */
static const double k_identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
static const double k_chair_twin[12] = {-1, 0, 0, 400.0, 0, -1, 0, 428.6, 0, 0, 1, 0};
static const double k_motor_on_table[12] = {0.3, 0, 0, 216.4, 0, 0.3, 0, 215.0, 0, 0, 0.3, 82.8};

static sw_result import_part(sw_sg_builder *b, uint32_t parent, const double *xform,
                             const char *data_dir, const char *file, const sw_scene_load_desc *desc,
                             sw_status *status)
{
    char path[4096];
    int n = snprintf(path, sizeof path, "%s/%s", data_dir, file);
    if (n < 0 || (size_t)n >= sizeof path)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "data directory path too long");
    sw_sg_import_desc import = {path,
                                NULL,
                                desc && desc->warning ? relay_warning : NULL,
                                (void *)desc,
                                desc && desc->face_problem ? relay_face_problem : NULL,
                                0};
    return sw_sg_cad_import_into(b, parent, xform, &import, NULL, status);
}

static sw_result build_default(sw_sg_builder *b, const char *data_dir,
                               const sw_scene_load_desc *desc, sw_status *status)
{
    size_t count = sizeof k_default_parts / sizeof k_default_parts[0];
    for (size_t i = 0; i < count; i++) {
        const default_part *part = &k_default_parts[i];
        if (desc && desc->progress)
            desc->progress(desc->user_data, (double)i / (double)count, part->file);
        int is_motor = strstr(part->file, "Motor-c") != NULL;
        uint32_t parent =
            sw_sg_builder_add_node(b, SW_SG_NODE_GROUP, part->instanced ? SW_SG_NONE : 0, 0, NULL,
                                   part->color, part->file);
        if (parent == SW_SG_NONE)
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "out of memory");
        if (part->instanced &&
            (sw_sg_builder_add_node(b, SW_SG_NODE_INSTANCE, 0, parent, k_identity, NULL, "chair") ==
                 SW_SG_NONE ||
             sw_sg_builder_add_node(b, SW_SG_NODE_INSTANCE, 0, parent, k_chair_twin, NULL,
                                    "chair twin") == SW_SG_NONE))
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "out of memory");
        sw_result r = import_part(b, parent, is_motor ? k_motor_on_table : NULL, data_dir,
                                  part->file, desc, status);
        if (r != SW_OK)
            return r;
    }
    if (desc && desc->progress)
        desc->progress(desc->user_data, 1.0, "done");
    return SW_OK;
}

sw_result sw_scene_load_default(const char *data_dir, const sw_scene_load_desc *desc, sw_scene *out,
                                sw_status *status)
{
    if (!out)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_scene_load_default: NULL out");
    out->id = 0;
    if (!data_dir)
        data_dir = "/usr/share/opencascade/data";
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "out of memory");
    sw_result r = build_default(b, data_dir, desc, status);
    if (r != SW_OK) {
        sw_sg_builder_free(b);
        return r;
    }
    sw_sg_scene *sg = NULL;
    r = sw_sg_builder_finish(b, &sg, status);
    if (r != SW_OK)
        return r;
    return wrap_scene(sg, out, status);
}

/* Runs under the scene pool's lock, so sw_scene_destroy cannot drop the pool's reference (and
 * free the scene) between the lookup and this increment. Relaxed: the pool's lock orders it
 * against the removal, and the count is already at least 1 here. */
static sw_result retain_scene(void *item, void *ctx)
{
    (void)ctx;
    atomic_fetch_add_explicit(&((sw_rt_scene *)item)->refs, 1u, memory_order_relaxed);
    return SW_OK;
}

void sw_rt_scene_retain(sw_rt_scene *scene)
{
    /* Relaxed: the caller already holds a reference, so the count cannot reach 0 meanwhile. */
    atomic_fetch_add_explicit(&scene->refs, 1u, memory_order_relaxed);
}

void sw_rt_scene_release(sw_rt_scene *scene)
{
    /* acq_rel: every use of the scene by other holders happens before the last one frees it. */
    if (atomic_fetch_sub_explicit(&scene->refs, 1u, memory_order_acq_rel) != 1u)
        return;
    sw_rt_nodes_scene_free(scene);
    sw_sg_bvh_free(scene->pick_bvh);
    sw_sg_scene_free(scene->sg);
    pthread_mutex_destroy(&scene->once_lock);
    sw__free(scene);
}

/* Verifies every section and computes the stats, exactly once per scene. Locks once_lock, which
 * guards `ready`, `ready_result` and `stats`. */
static sw_result make_ready(sw_rt_scene *scene, sw_status *status)
{
    pthread_mutex_lock(&scene->once_lock);
    if (!scene->ready) {
        sw_status local = {0};
        scene->ready_result = sw_sg_scene_require(scene->sg, SW_SG_SEC_ALL, &local);
        if (scene->ready_result == SW_OK) {
            scene->ready_result = sw_sg_scene_compute_stats(scene->sg, &scene->stats);
            if (scene->ready_result != SW_OK)
                sw__fail(&local, scene->ready_result, "%s: out of memory walking the scene",
                         sw_sg_scene_path_ptr(scene->sg));
        }
        if (scene->ready_result != SW_OK && status)
            *status = local;
        scene->ready = 1;
    } else if (scene->ready_result != SW_OK) {
        sw__fail(status, scene->ready_result, "%s: scene failed verification on first use",
                 sw_sg_scene_path_ptr(scene->sg));
    }
    sw_result r = scene->ready_result;
    pthread_mutex_unlock(&scene->once_lock);
    return r;
}

sw_result sw_rt_scene_lookup(sw_scene handle, sw_rt_scene **out, sw_status *status)
{
    void *item;
    *out = NULL;
    if (sw_rt_pool_get_checked(&g_scenes, handle.id, retain_scene, NULL, &item) != SW_OK)
        return SW__MISUSE(status, SW_ERR_STALE_HANDLE, "scene handle %#x is stale or invalid",
                          handle.id);
    *out = item;
    return SW_OK;
}

sw_result sw_rt_scene_acquire_frame(sw_scene handle, int walkthrough, sw_rt_scene **out,
                                    sw_status *status)
{
    sw_rt_scene *scene;
    sw_result r = sw_rt_scene_lookup(handle, &scene, status);
    if (r != SW_OK)
        return r;
    if (scene->model) { /* a node scene: its version (made ready by the compile task) */
        sw_rt_scene *version = NULL;
        r = sw_rt_model_acquire_version(scene->model, !walkthrough, &version, status);
        sw_rt_scene_release(scene);
        *out = version;
        return r;
    }
    r = make_ready(scene, status);
    if (r != SW_OK) {
        sw_rt_scene_release(scene);
        return r;
    }
    *out = scene;
    return SW_OK;
}

sw_result sw_rt_scene_acquire(sw_scene handle, sw_rt_scene **out, sw_status *status)
{
    return sw_rt_scene_acquire_frame(handle, 0, out, status);
}

sw_result sw_scene_save(sw_scene handle, const char *path, sw_status *status)
{
    if (!path)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_scene_save: NULL path");
    sw_rt_scene *scene;
    sw_result r = sw_rt_scene_acquire(handle, &scene, status);
    if (r != SW_OK)
        return r;
    r = sw_sg_scene_save(scene->sg, path, status);
    sw_rt_scene_release(scene);
    return r;
}

sw_result sw_scene_destroy(sw_scene handle)
{
    sw_rt_scene *scene = sw_rt_pool_remove(&g_scenes, handle.id);
    if (!scene)
        return SW__MISUSE(NULL, SW_ERR_STALE_HANDLE,
                          "sw_scene_destroy: scene handle %#x is stale or invalid", handle.id);
    sw_rt_scene_release(scene); /* freed now, or by the last call still using it */
    return SW_OK;
}

sw_result sw_scene_get_info(sw_scene handle, sw_scene_info *out, sw_status *status)
{
    if (!out)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_scene_get_info: NULL out");
    sw_rt_scene *scene;
    sw_result r = sw_rt_scene_acquire(handle, &scene, status);
    if (r != SW_OK)
        return r;
    const sw_sg_scene_stats *s = &scene->stats;
    memset(out, 0, sizeof *out);
    out->faces = s->faces;
    out->trimmed_faces = s->trimmed_faces;
    out->loops = s->loops;
    out->curves = s->curves;
    _Static_assert(SW_SURFACE_KIND_COUNT == SW_SG_KIND_COUNT, "surface kinds out of step");
    memcpy(out->faces_by_kind, s->faces_by_kind, sizeof out->faces_by_kind);
    out->bezier_patches = s->bezier_patches;
    out->max_degree_u = s->max_deg_u;
    out->max_degree_v = s->max_deg_v;
    out->max_curve_degree = s->max_curve_degree;
    out->control_points = s->control_points;
    out->nodes = s->nodes;
    out->instances = s->instances;
    out->face_occurrences = s->face_occurrences;
    out->adjacent_face_pairs = s->adjacency;
    memcpy(out->bbox_min, s->bbox, sizeof out->bbox_min);
    memcpy(out->bbox_max, s->bbox + 3, sizeof out->bbox_max);
    out->memory_bytes = sw_sg_scene_memory(scene->sg);
    out->meshes = s->meshes;
    out->mesh_triangles = s->mesh_triangles;
    out->mesh_occurrences = s->mesh_occurrences;
    out->shapes = s->shapes;
    out->shape_occurrences = s->shape_occurrences;
    out->triangle_occurrences = s->triangle_occurrences;
    out->faces_skipped = scene->faces_skipped;
    out->faces_repaired = scene->faces_repaired;
    out->partial = scene->partial;
    const void *lods = NULL;
    size_t lods_bytes = 0;
    if (sw_sg_scene_lods(scene->sg, &lods, &lods_bytes, NULL) == SW_OK)
        out->lod_cache_bytes = lods_bytes;
    sw_rt_scene_release(scene);
    return SW_OK;
}

const char *sw_surface_kind_name(uint32_t kind)
{
    return sw_sg_surface_kind_str(kind);
}

sw_result sw_camera_fit(sw_scene handle, sw_view_preset view, sw_camera *out, sw_status *status)
{
    if (!out || (unsigned)view > SW_VIEW_RIGHT)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_camera_fit: bad view or NULL out");
    sw_rt_scene *scene;
    sw_result r = sw_rt_scene_acquire(handle, &scene, status);
    if (r != SW_OK)
        return r;
    sw_rt_camera_fit_box(scene->stats.bbox, view, out);
    sw_rt_scene_release(scene);
    return SW_OK;
}

/* The scene's BVH for picking, built by the first pick (under once_lock; immutable after). */
static sw_result pick_bvh(sw_rt_scene *scene, const sw_sg_bvh **out, sw_status *status)
{
    pthread_mutex_lock(&scene->once_lock);
    sw_result r = scene->pick_bvh ? SW_OK : sw_sg_bvh_build(scene->sg, &scene->pick_bvh, status);
    *out = scene->pick_bvh;
    pthread_mutex_unlock(&scene->once_lock);
    return r;
}

sw_result sw_scene_pick(sw_scene handle, const double origin[3], const double direction[3],
                        sw_pick_hit *out, sw_status *status)
{
    if (!origin || !direction || !out)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_scene_pick: NULL argument");
    memset(out, 0, sizeof *out);
    sw_rt_scene *scene;
    sw_result r = sw_rt_scene_acquire(handle, &scene, status);
    if (r != SW_OK)
        return r;
    const sw_sg_bvh *bvh = NULL;
    sw_sg_pick_hit hit;
    r = pick_bvh(scene, &bvh, status);
    if (r == SW_OK)
        r = sw_sg_pick(scene->sg, bvh, origin, direction, 0.0, &hit, status);
    if (r == SW_OK && (hit.face != SW_SG_NONE || hit.mesh != SW_SG_NONE)) {
        out->hit = 1;
        out->surface = hit.face == SW_SG_NONE ? UINT32_MAX : hit.face;
        out->mesh = hit.mesh == SW_SG_NONE ? UINT32_MAX : hit.mesh;
        out->t = hit.t;
        memcpy(out->point, hit.point, sizeof out->point);
        memcpy(out->uv, hit.uv, sizeof out->uv);
        out->occurrence = hit.item;
        if (hit.face != SW_SG_NONE && scene->face_nodes)
            out->node.id = scene->face_nodes[hit.face];
        if (hit.mesh != SW_SG_NONE) {
            out->triangle = hit.triangle;
            memcpy(out->barycentric, hit.bary, sizeof out->barycentric);
            if (scene->mesh_nodes)
                out->node.id = scene->mesh_nodes[hit.mesh];
        }
    }
    sw_rt_scene_release(scene);
    return r;
}
