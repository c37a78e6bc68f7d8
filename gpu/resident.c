/* SPDX-License-Identifier: MIT */
/* Static levels kept in GPU buffers between frames (sw_gpu_internal.h says what is drawn how).
 * Kumar et al. 1997 §5 sends a super-surface's level with every frame; a resident mesh viewer
 * (and a real GPU's bus) favours sending it once: the frame then costs what changed.
 *
 * The table is indexed by (unit, level) of one static set, whose serial it keeps: a frame of
 * another set empties it (the set's address may be a freed set's, its serial is not). Units get
 * their row of SW__GPU_RESIDENT_LEVELS entries on first use. An entry holds its own vertex array
 * object, so a draw binds one object and sets two uniforms. Between frames, over the byte budget,
 * the entries the last frame did not draw are deleted (the border cache's rule: a walkthrough's
 * working set stays, and a frame whose own set outgrows the budget keeps it for that frame). */
#include "sw_gpu_internal.h"
#include "sw_hooks.h"
#include "sw_lod_static.h"
#include "sw_status_util.h"

#include <string.h>

/* Bytes of GPU buffers the table may keep past a frame (entries unused in the last frame are
 * deleted above it). */
static const size_t k_default_budget = (size_t)512 << 20;

typedef struct resident_entry {
    GLuint vao, vbo, ibo; /* vao 0: empty */
    GLsizei n_idx;        /* the triangles' indices; the lines' follow them in ibo */
    GLsizei n_line_idx;
    size_t bytes;
    uint64_t last_frame;
} resident_entry;

struct sw__gpu_resident {
    uint64_t set;          /* the serial of the set its entries are of; 0: none */
    resident_entry **rows; /* per unit, NULL until used: SW__GPU_RESIDENT_LEVELS entries */
    size_t n_rows;
    size_t bytes, budget;
    uint64_t frame; /* frames begun */
};

static struct sw__gpu_resident *table(sw_gpu_context *ctx)
{
    if (!ctx->resident) {
        ctx->resident = sw__calloc(1, sizeof *ctx->resident);
        if (ctx->resident)
            ctx->resident->budget = k_default_budget;
    }
    return ctx->resident;
}

static void entry_delete(struct sw__gpu_resident *t, resident_entry *e)
{
    if (!e->vao)
        return;
    glDeleteVertexArrays(1, &e->vao);
    glDeleteBuffers(1, &e->vbo);
    glDeleteBuffers(1, &e->ibo);
    t->bytes -= e->bytes;
    memset(e, 0, sizeof *e);
}

/* Deletes every entry (keep_since 0) or those last drawn before frame keep_since. */
static void evict(struct sw__gpu_resident *t, uint64_t keep_since)
{
    for (size_t u = 0; u < t->n_rows; ++u) {
        resident_entry *row = t->rows[u];
        for (int k = 0; row && k < SW__GPU_RESIDENT_LEVELS; ++k)
            if (row[k].vao && row[k].last_frame < keep_since)
                entry_delete(t, &row[k]);
    }
}

static void rows_free(struct sw__gpu_resident *t)
{
    evict(t, UINT64_MAX);
    for (size_t u = 0; u < t->n_rows; ++u)
        sw__free(t->rows[u]);
    sw__free(t->rows);
    t->rows = NULL;
    t->n_rows = 0;
}

void sw__gpu_resident_begin(sw_gpu_context *ctx, uint64_t set)
{
    struct sw__gpu_resident *t = set ? table(ctx) : ctx->resident; /* made by a set's frame */
    if (!t)
        return;
    if (t->set != set && t->n_rows)
        rows_free(t);
    t->set = set;
    if (t->bytes > t->budget)
        evict(t, t->frame); /* keeps what the last frame drew */
    t->frame++;
}

void sw__gpu_resident_free(sw_gpu_context *ctx)
{
    if (!ctx->resident)
        return;
    rows_free(ctx->resident);
    sw__free(ctx->resident);
    ctx->resident = NULL;
}

size_t sw__gpu_resident_bytes(const sw_gpu_context *ctx)
{
    return ctx->resident ? ctx->resident->bytes : 0;
}

size_t sw__gpu_resident_set_budget(sw_gpu_context *ctx, size_t bytes)
{
    struct sw__gpu_resident *t = table(ctx);
    if (!t)
        return 0;
    const size_t was = t->budget;
    t->budget = bytes;
    return was;
}

/* The entry of (unit, level), its row made when missing; NULL when out of memory. */
static resident_entry *entry_slot(struct sw__gpu_resident *t, uint32_t unit, int32_t level)
{
    if (unit >= t->n_rows) {
        size_t n = t->n_rows ? t->n_rows : 64;
        while (n <= unit)
            n *= 2;
        resident_entry **rows = sw__realloc(t->rows, n * sizeof *rows);
        if (!rows)
            return NULL;
        memset(rows + t->n_rows, 0, (n - t->n_rows) * sizeof *rows);
        t->rows = rows;
        t->n_rows = n;
    }
    if (!t->rows[unit] && !(t->rows[unit] = sw__calloc(SW__GPU_RESIDENT_LEVELS, sizeof **t->rows)))
        return NULL;
    return &t->rows[unit][level];
}

/* The level's vertices relative to the centre (float: exact enough within a unit, whose size
 * bounds them) and its triangles into the entry's buffers; adds the bytes sent. */
static sw_result upload(sw_gpu_context *ctx, struct sw__gpu_resident *t, resident_entry *e,
                        const sw__gpu_resident_draw *d, sw_status *status)
{
    const sw_lod_static_level *lv = d->level;
    sw__gpu_vertex *v = sw__malloc((lv->n_vertices ? lv->n_vertices : 1) * sizeof *v);
    if (!v)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "resident static level: out of memory");
    for (uint32_t i = 0; i < lv->n_vertices; ++i) {
        for (int k = 0; k < 3; ++k) {
            v[i].pos[k] = (float)(lv->positions[3 * (size_t)i + (size_t)k] - d->centre[k]);
            v[i].nrm[k] = lv->normals[3 * (size_t)i + (size_t)k];
        }
        v[i].st[0] = v[i].st[1] = 0.0f;
    }
    const size_t vbytes = (size_t)lv->n_vertices * sizeof *v,
                 tbytes = (size_t)lv->n_triangles * 3 * sizeof *lv->triangles,
                 lbytes = (size_t)d->n_lines * 2 * sizeof *d->lines, ibytes = tbytes + lbytes;
    glGenVertexArrays(1, &e->vao);
    glGenBuffers(1, &e->vbo);
    glGenBuffers(1, &e->ibo);
    glBindVertexArray(e->vao);
    glBindBuffer(GL_ARRAY_BUFFER, e->vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)vbytes, v, GL_STATIC_DRAW);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, e->ibo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)ibytes, NULL, GL_STATIC_DRAW);
    glBufferSubData(GL_ELEMENT_ARRAY_BUFFER, 0, (GLsizeiptr)tbytes, lv->triangles);
    if (lbytes)
        glBufferSubData(GL_ELEMENT_ARRAY_BUFFER, (GLintptr)tbytes, (GLsizeiptr)lbytes, d->lines);
    sw__free(v);
    sw__gpu_vertex_layout();
    e->n_idx = (GLsizei)(3 * lv->n_triangles);
    e->n_line_idx = (GLsizei)(2 * d->n_lines);
    e->bytes = vbytes + ibytes;
    t->bytes += e->bytes;
    ctx->upload_bytes += e->bytes;
    return SW_OK;
}

sw_result sw__gpu_resident_draw_all(sw_gpu_context *ctx, const sw__gpu_surface_program *prog,
                                    const sw__gpu_resident_list *list, sw_status *status)
{
    if (!list || list->n == 0)
        return SW_OK;
    struct sw__gpu_resident *t = ctx->resident;
    if (!t || t->set != list->set) /* the frame's begin could not make the table */
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "resident static levels: out of memory");
    static const float no_trim[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    glUniform4fv(prog->loc_uv_map, 1, no_trim);
    glUniform4fv(prog->loc_trim_rect, 1, no_trim);
    glUniform1f(prog->loc_trim_layer, 0.0f);
    for (size_t i = 0; i < list->n; ++i) {
        const sw__gpu_resident_draw *d = &list->draws[i];
        resident_entry *e = entry_slot(t, d->unit, d->index);
        if (!e)
            return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "resident static levels: out of memory");
        if (!e->vao) {
            sw_result r = upload(ctx, t, e, d, status);
            if (r != SW_OK)
                return r;
        }
        e->last_frame = t->frame;
        glBindVertexArray(e->vao);
        glUniformMatrix3fv(prog->loc_model_rot, 1, GL_TRUE, d->rot);
        glUniform3fv(prog->loc_model_off, 1, d->off);
        glUniform4fv(prog->loc_color, 1, d->color);
        glDrawElements(GL_TRIANGLES, e->n_idx, GL_UNSIGNED_INT, NULL);
        if (e->n_line_idx && d->draw_lines)
            glDrawElements(GL_LINES, e->n_line_idx, GL_UNSIGNED_INT,
                           (const void *)((size_t)e->n_idx * sizeof(uint32_t)));
    }
    static const float identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, zero[3] = {0, 0, 0};
    glUniformMatrix3fv(prog->loc_model_rot, 1, GL_TRUE, identity);
    glUniform3fv(prog->loc_model_off, 1, zero);
    glBindVertexArray(ctx->vao);
    return SW_OK;
}
