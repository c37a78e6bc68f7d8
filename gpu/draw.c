/* SPDX-License-Identifier: MIT */
/* Draw submission and readback shared by the scene path and the plain-triangle path: the surface
 * programs, reversed-Z depth (cleared to 0, GL_GREATER), trim-texture lookups for trimmed ranges
 * only (Guthe et al. 2005 §4.3; untrimmed ranges are drawn by programs without it), glReadPixels
 * with rows flipped to top-first and depth turned into eye-space depth. Also
 * sw_gpu_render_triangles, the path an independent reference mesh is drawn with.
 */
#include "sw_gpu_internal.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void sw__gpu_desc_defaults(const sw_gpu_frame_desc *in, sw_gpu_frame_desc *out)
{
    *out = *in;
    if (out->width == 0 && out->height == 0) {
        out->width = SW_DEFAULT_WIDTH;
        out->height = SW_DEFAULT_HEIGHT;
    }
    if (!(out->error_px > 0.0))
        out->error_px = SW_DEFAULT_ERROR_PX;
}

double sw__gpu_near_plane(const double eye[3], const double world_box[6])
{
    double rel[6], diag2 = 0.0;
    for (int k = 0; k < 3; ++k) {
        rel[k] = world_box[k] - eye[k];
        rel[3 + k] = world_box[3 + k] - eye[k];
        double e = world_box[3 + k] - world_box[k];
        diag2 += e * e;
    }
    double diag = sqrt(diag2), dist = sw__gpu_box_distance(rel);
    double n = fmax(1e-4 * diag, 0.5 * dist);
    return n > 0.0 && isfinite(n) ? n : 1e-3;
}

/* Streams a frame's bytes into buf, bound to target. Storage is made by glBufferData only when
 * the frame needs more than the buffer holds (with a quarter more room), and otherwise
 * overwritten by glBufferSubData: llvmpipe allocates fresh storage on every glBufferData and
 * clears it, which the submitting thread paid again each frame (page faults and memset). */
static void stream_to(GLenum target, GLuint buf, size_t *capacity, size_t bytes, const void *data)
{
    glBindBuffer(target, buf);
    if (bytes == 0)
        bytes = 16; /* GL wants storage behind a bound storage buffer */
    if (bytes > *capacity) {
        const size_t grown = bytes + bytes / 4;
        glBufferData(target, (GLsizeiptr)grown, NULL, GL_STREAM_DRAW);
        *capacity = grown;
    }
    if (data)
        glBufferSubData(target, 0, (GLsizeiptr)bytes, data);
}

/* stream_to, counted in the frame's uploads. */
static void send(sw_gpu_context *ctx, GLenum target, GLuint buf, size_t *capacity, size_t bytes,
                 const void *data)
{
    stream_to(target, buf, capacity, bytes, data);
    if (data)
        ctx->upload_bytes += bytes;
}

void sw__gpu_stream(sw_gpu_context *ctx, GLenum target, GLuint *buf, size_t *capacity, size_t bytes,
                    const void *data)
{
    if (!*buf)
        glGenBuffers(1, buf);
    send(ctx, target, *buf, capacity, bytes, data);
}

static void bind_mesh(sw_gpu_context *ctx, const sw__gpu_mesh *mesh)
{
    if (!ctx->mesh_vbo) {
        glGenBuffers(1, &ctx->mesh_vbo);
        glGenBuffers(1, &ctx->mesh_ibo);
    }
    glBindVertexArray(ctx->vao);
    send(ctx, GL_ARRAY_BUFFER, ctx->mesh_vbo, &ctx->mesh_vbo_cap, mesh->n_v * sizeof *mesh->v,
         mesh->v);
    send(ctx, GL_ELEMENT_ARRAY_BUFFER, ctx->mesh_ibo, &ctx->mesh_ibo_cap,
         mesh->n_idx * sizeof *mesh->idx, mesh->idx);
    sw__gpu_vertex_layout();
}

void sw__gpu_vertex_layout(void)
{
    const GLsizei stride = (GLsizei)sizeof(sw__gpu_vertex);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride,
                          (const void *)offsetof(sw__gpu_vertex, pos));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride,
                          (const void *)offsetof(sw__gpu_vertex, nrm));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, stride,
                          (const void *)offsetof(sw__gpu_vertex, st));
}

/* Exact path: pieces, knots and double control points into storage buffers 2, 3, 4. */
static void upload_ssbo(sw_gpu_context *ctx, GLuint buf, size_t *capacity, GLuint binding,
                        size_t bytes, const void *data)
{
    send(ctx, GL_SHADER_STORAGE_BUFFER, buf, capacity, bytes, bytes ? data : NULL);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buf);
}

/* Exact trim edges' grids, cells and segments into storage buffers 6, 7, 8 (the surface
 * programs' fragment stage: glsl/surface_trim.frag.glsl). */
static void upload_edges(sw_gpu_context *ctx, const sw__gpu_edge_grids *e)
{
    if (!e || e->n_grids == 0)
        return;
    upload_ssbo(ctx, ctx->edge_ssbo[0], &ctx->edge_ssbo_cap[0], 6, e->n_grids * sizeof *e->grids,
                e->grids);
    upload_ssbo(ctx, ctx->edge_ssbo[1], &ctx->edge_ssbo_cap[1], 7,
                e->n_cells * 2 * sizeof *e->cells, e->cells);
    upload_ssbo(ctx, ctx->edge_ssbo[2], &ctx->edge_ssbo_cap[2], 8, e->n_segs * 4 * sizeof *e->segs,
                e->segs);
}

void sw__gpu_draw_trim_lookup(const sw_gpu_context *ctx, const sw__gpu_draw *d, float rect[4],
                              float *layer)
{
    memset(rect, 0, 4 * sizeof *rect);
    *layer = 0.0f;
    if (d->edge_grid >= 0) {
        rect[0] = (float)d->edge_grid; /* exact below 2^24 grids: a frame holds far fewer */
        rect[2] = -1.0f;
    } else if (d->trim_entry >= 0) {
        sw__gpu_trim_rect tr;
        sw__gpu_atlas_rect(ctx, d->trim_entry, &tr);
        rect[0] = (float)tr.x0;
        rect[1] = (float)tr.y0;
        rect[2] = (float)tr.w;
        rect[3] = (float)tr.h;
        *layer = (float)tr.layer;
    }
}

static void upload_exact(sw_gpu_context *ctx, const sw__gpu_patch_batch *batch)
{
    upload_ssbo(ctx, ctx->piece_ssbo, &ctx->piece_ssbo_cap, 2,
                batch->n_pieces * sizeof *batch->pieces, batch->pieces);
    upload_ssbo(ctx, ctx->knot_ssbo, &ctx->knot_ssbo_cap, 3, batch->n_knots * sizeof *batch->knots,
                batch->knots);
    upload_ssbo(ctx, ctx->dcp_ssbo, &ctx->dcp_ssbo_cap, 4, batch->n_dcps * 4 * sizeof *batch->dcps,
                batch->dcps);
}

/* Debug capture: a zeroed counter plus room for capture_max vertices (two vec4 each); the
 * programs are told the room by capture_program. */
static void capture_begin(sw_gpu_context *ctx)
{
    if (ctx->capture_max == 0)
        return;
    if (!ctx->capture_ssbo)
        glGenBuffers(1, &ctx->capture_ssbo);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, ctx->capture_ssbo);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(16 + (size_t)ctx->capture_max * 32), NULL,
                 GL_STREAM_READ);
    static const uint32_t zero[4] = {0, 0, 0, 0};
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, sizeof zero, zero);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, ctx->capture_ssbo);
}

static void capture_program(const sw_gpu_context *ctx, const sw__gpu_surface_program *prog)
{
    glUniform1i(prog->loc_capture, (GLint)ctx->capture_max);
}

void sw__gpu_set_capture(sw_gpu_context *ctx, uint32_t max_vertices)
{
    ctx->capture_max = max_vertices;
}

sw_result sw__gpu_capture_read(sw_gpu_context *ctx, sw__gpu_capture_vertex **out, size_t *n,
                               size_t *total, sw_status *status)
{
    sw__gpu_make_current(ctx);
    *out = NULL;
    *n = *total = 0;
    if (!ctx->capture_ssbo || ctx->capture_max == 0)
        return SW_OK;
    uint32_t count = 0;
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, ctx->capture_ssbo);
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, sizeof count, &count);
    size_t m = count < ctx->capture_max ? count : ctx->capture_max;
    float *raw = sw__malloc((m ? m : 1) * 8 * sizeof *raw);
    sw__gpu_capture_vertex *v = sw__malloc((m ? m : 1) * sizeof *v);
    if (!raw || !v) {
        sw__free(raw);
        sw__free(v);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "capture: out of memory");
    }
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 16, (GLsizeiptr)(m * 32), raw);
    for (size_t i = 0; i < m; ++i) {
        uint32_t sorted;
        memcpy(&sorted, &raw[8 * i], sizeof sorted);
        v[i].piece = sorted < ctx->cap_rec_source ? ctx->rec_source[sorted] : UINT32_MAX;
        v[i].s = raw[8 * i + 1];
        v[i].t = raw[8 * i + 2];
        memcpy(v[i].pos, &raw[8 * i + 4], sizeof v[i].pos);
    }
    sw__free(raw);
    *out = v;
    *n = m;
    *total = count;
    return sw__gpu_check(status, "capture read");
}

/* The frame's GPU-evaluated patches (§4.2): records and control points into two shader storage
 * buffers, then per trim variant (the untrimmed first, as the batch holds them) one instanced
 * draw per non-empty grid class, attribute-less. */
void sw__gpu_upload_patches(sw_gpu_context *ctx, const sw__gpu_patch_rec *recs, size_t n_recs,
                            const float *cps, size_t n_cps)
{
    upload_ssbo(ctx, ctx->patch_ssbo, &ctx->patch_ssbo_cap, 0, n_recs * sizeof *recs, recs);
    upload_ssbo(ctx, ctx->cp_ssbo, &ctx->cp_ssbo_cap, 1, n_cps * 4 * sizeof *cps, cps);
}

static void draw_patches(sw_gpu_context *ctx, const sw__gpu_view *view,
                         const sw__gpu_patch_batch *batch)
{
    sw__gpu_upload_patches(ctx, batch->recs, batch->n_recs, batch->cps, batch->n_cps);
    if (batch->exact)
        upload_exact(ctx, batch);
    else
        capture_begin(ctx);
    glBindVertexArray(ctx->vao);
    for (GLuint a = 0; a < 3; ++a)
        glDisableVertexAttribArray(a);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ctx->grid_ibo);
    static const int k_order[SW__GPU_TRIM_VARIANTS] = {SW__GPU_UNTRIMMED, SW__GPU_TRIMMED};
    for (int k = 0; k < SW__GPU_TRIM_VARIANTS; ++k) {
        const int t = k_order[k];
        const sw__gpu_surface_program *prog =
            batch->exact ? &ctx->surf.exact[t] : &ctx->surf.eval[t];
        int used = 0;
        for (int b = 0; b < SW__GPU_GRID_CLASSES; ++b) {
            for (int a = 0; a < SW__GPU_GRID_CLASSES; ++a) {
                if (batch->count[t][b][a] == 0)
                    continue;
                if (!used++) {
                    glUseProgram(prog->prog);
                    glUniformMatrix4fv(prog->loc_view_proj, 1, GL_FALSE, view->view_proj);
                    glUniform1i(prog->loc_trim, 0);
                    if (!batch->exact)
                        capture_program(ctx, prog);
                }
                glUniform2i(prog->loc_grid, sw__gpu_grid_segments[a], sw__gpu_grid_segments[b]);
                glUniform1i(prog->loc_base, (GLint)batch->first[t][b][a]);
                glDrawElementsInstanced(GL_TRIANGLES, (GLsizei)ctx->grid_count[b][a],
                                        GL_UNSIGNED_INT,
                                        (const void *)(ctx->grid_first[b][a] * sizeof(uint32_t)),
                                        (GLsizei)batch->count[t][b][a]);
            }
        }
    }
}

/* The mesh program of a trim variant in use, its eye-relative placement set. */
static const sw__gpu_surface_program *use_mesh_program(sw_gpu_context *ctx,
                                                       const sw__gpu_view *view, int variant)
{
    static const float identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, zero[3] = {0, 0, 0};
    const sw__gpu_surface_program *prog = &ctx->surf.mesh[variant];
    glUseProgram(prog->prog);
    glUniformMatrix4fv(prog->loc_view_proj, 1, GL_FALSE, view->view_proj);
    glUniform1i(prog->loc_trim, 0);
    glUniformMatrix3fv(prog->loc_model_rot, 1, GL_TRUE, identity);
    glUniform3fv(prog->loc_model_off, 1, zero);
    return prog;
}

/* The mesh's draws of one trim variant, with that variant's mesh program. */
static void draw_mesh_variant(sw_gpu_context *ctx, const sw__gpu_view *view,
                              const sw__gpu_draw *draws, size_t n_draws, int variant)
{
    const sw__gpu_surface_program *prog = &ctx->surf.mesh[variant];
    int used = 0;
    for (size_t d = 0; d < n_draws; ++d) {
        const int trimmed = sw__gpu_draw_trimmed(&draws[d]);
        if (draws[d].n_idx == 0 || trimmed != (variant == SW__GPU_TRIMMED))
            continue;
        if (!used++)
            use_mesh_program(ctx, view, variant);
        glUniform4fv(prog->loc_color, 1, draws[d].color);
        glUniform4fv(prog->loc_uv_map, 1, draws[d].uv_map);
        /* set for untrimmed draws too (w = 0: the lookup accepts all): a host's shading draws
         * them with its trimmed program, which keeps the last trimmed draw's rectangle */
        float rect[4], layer;
        sw__gpu_draw_trim_lookup(ctx, &draws[d], rect, &layer);
        glUniform4fv(prog->loc_trim_rect, 1, rect);
        glUniform1f(prog->loc_trim_layer, layer);
        glDrawElements(GL_TRIANGLES, (GLsizei)draws[d].n_idx, GL_UNSIGNED_INT,
                       (const void *)(draws[d].first_idx * sizeof(uint32_t)));
    }
}

sw_result sw__gpu_draw_frame(sw_gpu_context *ctx, const sw__gpu_view *view,
                             const sw_gpu_frame_desc *desc, const sw__gpu_mesh *mesh,
                             const sw__gpu_draw *draws, size_t n_draws,
                             const sw__gpu_patch_batch *batch, const sw__gpu_edge_grids *edges,
                             const sw__gpu_resident_list *resident, sw_status *status)
{
    ctx->upload_bytes = 0;
    ctx->grid_hits = ctx->grid_misses = ctx->grid_triangles = ctx->grid_extra_triangles = 0;
    const float *bg = desc->background;
    sw_result r = sw__gpu_target_ensure(ctx, view->width, view->height, status);
    if (r != SW_OK)
        return r;
    glBindFramebuffer(GL_FRAMEBUFFER, ctx->fbo);
    glViewport(0, 0, view->width, view->height);
    glDisable(GL_COLOR_LOGIC_OP);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glClearColor(bg[0], bg[1], bg[2], bg[3]);
    glClearDepth(0.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    /* Lines only for the surfaces: the trim textures were made before, with filled fans. */
    if (desc->wireframe)
        glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D_ARRAY, sw__gpu_atlas_texture(ctx));
    upload_edges(ctx, edges);
    r = batch ? sw__gpu_grid_cache_draw(ctx, view, batch, status) : SW_OK;
    if (r != SW_OK)
        return r;
    if (batch && batch->n_recs > 0)
        draw_patches(ctx, view, batch);
    bind_mesh(ctx, mesh);
    draw_mesh_variant(ctx, view, draws, n_draws, SW__GPU_UNTRIMMED);
    r = resident && resident->n
            ? sw__gpu_resident_draw_all(ctx, use_mesh_program(ctx, view, SW__GPU_UNTRIMMED),
                                        resident, status)
            : SW_OK;
    draw_mesh_variant(ctx, view, draws, n_draws, SW__GPU_TRIMMED);
    if (desc->wireframe)
        glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    return r == SW_OK ? sw__gpu_check(status, "frame draw") : r;
}

/* The fullscreen pass of a depth-compositing present, in the host's state as the host-state
 * save left it (GL defaults: no blend, scissor or masks). It reads the render target on units 0
 * (depth) and 1 (colour); unit 1 is not in the saved host state, so its 2D texture and sampler
 * are put back here. */
static void present_by_depth(sw_gpu_context *ctx, const sw__gpu_view *view)
{
    glViewport(0, 0, view->width, view->height);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER); /* reversed-Z: the host's nearer pixels stay */
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    GLint unit1_texture = 0, unit1_sampler = 0;
    glActiveTexture(GL_TEXTURE1);
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &unit1_texture);
    glGetIntegerv(GL_SAMPLER_BINDING, &unit1_sampler);
    glBindTexture(GL_TEXTURE_2D, ctx->tex_color);
    glBindSampler(1, 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, ctx->tex_depth);
    glBindSampler(0, 0);
    glUseProgram(ctx->prog_present);
    glBindVertexArray(ctx->vao);
    for (GLuint a = 0; a < 3; ++a)
        glDisableVertexAttribArray(a);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindTexture(GL_TEXTURE_2D, 0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, (GLuint)unit1_texture);
    glBindSampler(1, (GLuint)unit1_sampler);
    glActiveTexture(GL_TEXTURE0);
}

sw_result sw__gpu_present(sw_gpu_context *ctx, const sw__gpu_view *view, int depth,
                          const sw__gpu_host_state *host, sw_status *status)
{
    glBindFramebuffer(GL_READ_FRAMEBUFFER, ctx->fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, (GLuint)host->draw_fb);
    if (depth) {
        present_by_depth(ctx, view);
        return sw__gpu_check(status, "frame present (depth composite into the host's framebuffer)");
    }
    glBlitFramebuffer(0, 0, view->width, view->height, 0, 0, view->width, view->height,
                      GL_COLOR_BUFFER_BIT, GL_NEAREST);
    return sw__gpu_check(status, "frame present (blit into the host's framebuffer)");
}

static void flip_rows(const uint8_t *src, uint8_t *dst, int32_t h, size_t row_bytes)
{
    for (int32_t y = 0; y < h; ++y)
        memcpy(dst + (size_t)y * row_bytes, src + (size_t)(h - 1 - y) * row_bytes, row_bytes);
}

sw_result sw__gpu_readback(sw_gpu_context *ctx, const sw__gpu_view *view, int want_depth,
                           sw_gpu_image *out, sw_status *status)
{
    int32_t w = view->width, h = view->height;
    size_t n = (size_t)w * (size_t)h;
    memset(out, 0, sizeof *out);
    _Static_assert(sizeof(float) == 4, "RGBA8 and float depth share the readback buffer");
    uint8_t *tmp = sw__malloc(n * 4);
    out->rgba = sw__malloc(n * 4);
    out->depth = want_depth ? sw__malloc(n * sizeof *out->depth) : NULL;
    if (!tmp || !out->rgba || (want_depth && !out->depth)) {
        sw__free(tmp);
        sw_gpu_image_free(out);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "frame readback: out of memory");
    }
    out->width = w;
    out->height = h;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, ctx->fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, tmp);
    flip_rows(tmp, out->rgba, h, (size_t)w * 4);
    if (want_depth) {
        glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, tmp);
        flip_rows(tmp, (uint8_t *)out->depth, h, (size_t)w * sizeof(float));
        for (size_t i = 0; i < n; ++i)
            out->depth[i] = sw__gpu_depth_to_eye(view, out->depth[i]);
    }
    sw__free(tmp);
    sw_result r = sw__gpu_check(status, "frame readback");
    if (r != SW_OK)
        sw_gpu_image_free(out);
    return r;
}

void sw_gpu_image_free(sw_gpu_image *img)
{
    if (!img)
        return;
    sw__free(img->rgba);
    sw__free(img->depth);
    img->rgba = NULL;
    img->depth = NULL;
}

/* Flat-shaded, un-indexed copy of the triangles, eye-relative. */
static sw_result triangles_to_mesh(const double *pos, uint32_t n_vertices, const uint32_t *indices,
                                   uint32_t n_indices, const double eye[3], sw__gpu_mesh *mesh,
                                   sw_status *status)
{
    uint32_t n_tri = n_indices / 3;
    sw_result r = sw__gpu_mesh_reserve(mesh, (size_t)n_tri * 3, (size_t)n_tri * 3, status);
    if (r != SW_OK)
        return r;
    for (uint32_t t = 0; t < n_tri; ++t) {
        double p[3][3];
        for (int c = 0; c < 3; ++c) {
            uint32_t i = indices[3 * t + (uint32_t)c];
            if (i >= n_vertices)
                return sw__fail(status, SW_ERR_INVALID_ARGUMENT,
                                "triangle %u: index %u >= %u vertices", t, i, n_vertices);
            for (int k = 0; k < 3; ++k)
                p[c][k] = pos[3 * (size_t)i + (size_t)k] - eye[k];
        }
        double e1[3], e2[3];
        for (int k = 0; k < 3; ++k) {
            e1[k] = p[1][k] - p[0][k];
            e2[k] = p[2][k] - p[0][k];
        }
        double nrm[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                         e1[0] * e2[1] - e1[1] * e2[0]};
        for (int c = 0; c < 3; ++c) {
            sw__gpu_vertex *v = &mesh->v[mesh->n_v];
            for (int k = 0; k < 3; ++k) {
                v->pos[k] = (float)p[c][k];
                v->nrm[k] = (float)nrm[k];
            }
            v->st[0] = v->st[1] = 0.0f;
            mesh->idx[mesh->n_idx++] = (uint32_t)mesh->n_v++;
        }
    }
    return SW_OK;
}

static void positions_box(const double *pos, uint32_t n, double box[6])
{
    for (int k = 0; k < 3; ++k) {
        box[k] = INFINITY;
        box[3 + k] = -INFINITY;
    }
    for (uint32_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
            box[k] = fmin(box[k], pos[3 * (size_t)i + (size_t)k]);
            box[3 + k] = fmax(box[3 + k], pos[3 * (size_t)i + (size_t)k]);
        }
    if (n == 0)
        memset(box, 0, 6 * sizeof *box);
}

sw_result sw_gpu_render_triangles(sw_gpu_context *ctx, const double *positions, uint32_t n_vertices,
                                  const uint32_t *indices, uint32_t n_indices,
                                  const sw_gpu_frame_desc *desc_in, sw_gpu_image *out,
                                  sw_status *status)
{
    memset(out, 0, sizeof *out);
    sw__gpu_make_current(ctx);
    sw_gpu_frame_desc desc;
    sw__gpu_desc_defaults(desc_in, &desc);
    double box[6];
    positions_box(positions, n_vertices, box);
    sw__gpu_view view;
    sw_result r = sw__gpu_view_init(&view, &desc.camera, desc.width, desc.height,
                                    sw__gpu_near_plane(desc.camera.eye, box), status);
    sw__gpu_mesh mesh = {0};
    if (r == SW_OK)
        r = triangles_to_mesh(positions, n_vertices, indices, n_indices, view.eye, &mesh, status);
    sw__gpu_draw draw = {0, mesh.n_idx, {0.8f, 0.8f, 0.8f, 1.0f}, -1, -1, {0.0f, 0.0f, 0.0f, 0.0f}};
    if (r == SW_OK)
        r = sw__gpu_draw_frame(ctx, &view, &desc, &mesh, &draw, 1, NULL, NULL, NULL, status);
    sw__gpu_mesh_free(&mesh);
    if (r == SW_OK)
        r = sw__gpu_readback(ctx, &view, desc.want_depth, out, status);
    if (r == SW_OK)
        sw__status_ok(status);
    return r;
}
