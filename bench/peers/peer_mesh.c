/* SPDX-License-Identifier: MIT */
/* bench/peers: the OCCT peer's frames (see peer_mesh.h). */
#include "peer_mesh.h"

#include "../tessellation/vbo_draw.h"
#include "peer_occt.h"
#include "sw_gpu.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

double bp_occt_deflection(const bp_job *job)
{
    sw_camera cam;
    bp_frame_camera(job, 0, &cam);
    double diag2 = 0.0;
    for (int k = 0; k < 3; ++k) {
        double e = job->scene_box[3 + k] - job->scene_box[k];
        diag2 += e * e;
    }
    double d = fmax(bp_min_view_distance(job), 1e-6 * sqrt(diag2));
    return job->error_px * 2.0 * d * tan(cam.fovy_deg * M_PI / 360.0) / job->height;
}

/* clip = VP (x - eye): the eye-relative view-projection moved to world coordinates. */
static void world_view_proj(const sw__gpu_view *v, float out[16])
{
    memcpy(out, v->view_proj, sizeof v->view_proj);
    for (int row = 0; row < 4; ++row) {
        double t = v->view_proj[12 + row];
        for (int c = 0; c < 3; ++c)
            t -= (double)v->view_proj[c * 4 + row] * v->eye[c];
        out[12 + row] = (float)t;
    }
}

static int draw_frame(const bp_job *job, bt_draw *d, uint32_t i, size_t n_idx)
{
    sw_camera cam;
    sw__gpu_view view;
    float vp[16];
    bp_frame_camera(job, i, &cam);
    if (bp_frame_view(job, &cam, &view) != 0)
        return -1;
    world_view_proj(&view, vp);
    return bt_draw_uploaded(d, vp, n_idx) == 0 ? 0 : -1;
}

static int frames(const bp_job *job, bt_draw *d, size_t n_idx, double t_start, bp_result *out)
{
    uint32_t n = job->frames * job->passes;
    double *ms = calloc(n, sizeof *ms);
    if (!ms)
        return -1;
    int rc = 0;
    for (uint32_t p = 0; rc == 0 && p < job->warmup_passes + job->passes; ++p)
        for (uint32_t i = 0; rc == 0 && i < job->frames; ++i) {
            double t0 = bench_now_ms();
            rc = draw_frame(job, d, i, n_idx);
            double t1 = bench_now_ms();
            if (p == 0 && i == 0)
                out->first_frame_ms = t1 - t_start;
            if (p >= job->warmup_passes)
                ms[(p - job->warmup_passes) * job->frames + i] = t1 - t0;
        }
    if (rc == 0) {
        out->frames = n;
        rc = bp_summarize(ms, n, &out->median_ms, &out->p99_ms);
    }
    free(ms);
    return rc;
}

int bp_peer_occt(const bp_job *job, bp_result *out)
{
    double t_start = bench_now_ms();
    if (!job->brep) {
        snprintf(out->note, sizeof out->note, "no BREP of the scene");
        return -1;
    }
    bp_occt_mesh m;
    out->param = bp_occt_deflection(job);
    if (bp_occt_mesh_brep(job->brep, out->param, &m, out->note, sizeof out->note) != 0)
        return -1;
    out->faces = m.faces;
    out->triangles = (double)(m.n_idx / 3);
    sw_gpu_context *ctx = NULL;
    sw_status st;
    memset(&st, 0, sizeof st);
    bt_draw *d = NULL;
    int rc = -1;
    if (sw_gpu_context_create_headless(&ctx, &st) != SW_OK)
        snprintf(out->note, sizeof out->note, "%s", st.message);
    else if ((d = bt_draw_create(job->width, job->height, out->note, sizeof out->note)) != NULL) {
        bt_draw_set_pipelined(d, 1); /* frame time: the interval between completions */
        if (bt_draw_upload(d, m.v, m.n_v, BP_OCCT_VERTEX_FLOATS, m.idx, m.n_idx) != 0)
            snprintf(out->note, sizeof out->note, "GL error uploading %zu triangles", m.n_idx / 3);
        else if ((rc = frames(job, d, m.n_idx, t_start, out)) != 0)
            snprintf(out->note, sizeof out->note, "a frame failed (GL error)");
        else {
            out->covered_px = (double)bt_draw_covered(d);
            snprintf(out->note, sizeof out->note,
                     "deflection %.4g, read %.0f ms, mesh %.0f ms, %llu of %llu faces unmeshed",
                     out->param, m.ms_read, m.ms_mesh, (unsigned long long)m.faces_unmeshed,
                     (unsigned long long)m.faces);
        }
    }
    bt_draw_free(d);
    sw_gpu_context_free(ctx);
    bp_occt_mesh_free(&m);
    return rc;
}
