/* SPDX-License-Identifier: MIT */
/* bench/tessellation: the GLU NURBS tessellator baseline (Guthe et al. 2005 §9, Fig. 9) — see
 * glu_nurbs.h. The *_DATA callbacks receive the state through gluNurbsCallbackData (without it
 * GLU passes NULL and the callbacks would crash); registering a normal callback makes GLU evaluate
 * normals (its auto_normal_flag in tessellator mode), as splinewalk's grids do.
 */
#include "glu_nurbs.h"

#include <GL/glu.h>
#include <stdlib.h>
#include <string.h>

typedef struct prim_state {
    bt_glu_mesh *m;
    GLenum type;
    size_t first; /* first vertex of the current primitive */
    float nrm[3]; /* the normal GLU sent before the next vertex */
    int oom;
} prim_state;

struct bt_glu {
    GLUnurbs *nurb;
    prim_state st;
};

/* GLU's error callback takes no user data; the benchmark tessellates on one thread. */
static GLenum g_glu_error;

static void on_error(GLenum code)
{
    if (!g_glu_error)
        g_glu_error = code;
}

static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 1;
    size_t c = *cap ? *cap * 2 : 4096;
    while (c < need)
        c *= 2;
    void *q = realloc(*p, c * elem);
    if (!q)
        return 0;
    *p = q;
    *cap = c;
    return 1;
}

static void on_begin(GLenum type, void *data)
{
    prim_state *s = data;
    s->type = type;
    s->first = s->m->n_v;
}

static void on_normal(GLfloat *n, void *data)
{
    prim_state *s = data;
    memcpy(s->nrm, n, sizeof s->nrm);
}

static void on_vertex(GLfloat *p, void *data)
{
    prim_state *s = data;
    bt_glu_mesh *m = s->m;
    if (!grow((void **)&m->v, &m->cap_v, (m->n_v + 1) * BT_GLU_VERTEX_FLOATS, sizeof *m->v)) {
        s->oom = 1;
        return;
    }
    float *v = m->v + m->n_v * BT_GLU_VERTEX_FLOATS;
    v[0] = p[0];
    v[1] = p[1];
    v[2] = p[2];
    v[3] = s->nrm[0];
    v[4] = s->nrm[1];
    v[5] = s->nrm[2];
    /* GLU 9's evaluator passes the vertex's (u, v) after it (float[5]; not part of the API). */
    v[6] = p[3];
    v[7] = p[4];
    m->n_v++;
}

static void tri(uint32_t *idx, size_t *n, size_t a, size_t b, size_t c)
{
    idx[(*n)++] = (uint32_t)a;
    idx[(*n)++] = (uint32_t)b;
    idx[(*n)++] = (uint32_t)c;
}

/* Indexed triangles of one primitive of `count` vertices starting at f. Winding is not kept
 * consistent: the draw does not cull faces. */
static void emit(bt_glu_mesh *m, GLenum type, size_t f, size_t count)
{
    size_t n = m->n_idx;
    switch (type) {
    case GL_TRIANGLES:
        for (size_t i = 0; i + 2 < count; i += 3)
            tri(m->idx, &n, f + i, f + i + 1, f + i + 2);
        m->primitives[0]++;
        break;
    case GL_TRIANGLE_STRIP:
        for (size_t i = 2; i < count; ++i)
            tri(m->idx, &n, f + i - 2, f + i - 1, f + i);
        m->primitives[1]++;
        break;
    case GL_TRIANGLE_FAN:
    case GL_POLYGON:
        for (size_t i = 2; i < count; ++i)
            tri(m->idx, &n, f, f + i - 1, f + i);
        m->primitives[type == GL_TRIANGLE_FAN ? 2 : 3]++;
        break;
    case GL_QUAD_STRIP: /* quad k is 2k, 2k+1, 2k+3, 2k+2 */
        for (size_t i = 2; i + 1 < count; i += 2) {
            tri(m->idx, &n, f + i - 2, f + i - 1, f + i + 1);
            tri(m->idx, &n, f + i - 2, f + i + 1, f + i);
        }
        m->primitives[3]++;
        break;
    case GL_QUADS:
        for (size_t i = 0; i + 3 < count; i += 4) {
            tri(m->idx, &n, f + i, f + i + 1, f + i + 2);
            tri(m->idx, &n, f + i, f + i + 2, f + i + 3);
        }
        m->primitives[3]++;
        break;
    default: /* points and lines (outline modes) carry no area */
        break;
    }
    m->n_idx = n;
}

static void on_end(void *data)
{
    prim_state *s = data;
    bt_glu_mesh *m = s->m;
    size_t count = m->n_v - s->first;
    /* At most 2 triangles per vertex of any primitive kind. */
    if (s->oom || !grow((void **)&m->idx, &m->cap_idx, m->n_idx + 6 * count, sizeof *m->idx)) {
        s->oom = 1;
        return;
    }
    emit(m, s->type, s->first, count);
}

bt_glu *bt_glu_create(float tolerance_px)
{
    bt_glu *g = calloc(1, sizeof *g);
    if (!g)
        return NULL;
    g->nurb = gluNewNurbsRenderer();
    if (!g->nurb) {
        free(g);
        return NULL;
    }
    GLUnurbs *n = g->nurb;
    gluNurbsProperty(n, GLU_NURBS_MODE, GLU_NURBS_TESSELLATOR);
    /* With the default GL_TRUE GLU reads the (absent) fixed-function matrices and silently emits
     * a fixed coarse mesh; the frame's matrices are loaded per call instead. */
    gluNurbsProperty(n, GLU_AUTO_LOAD_MATRIX, GL_FALSE);
    gluNurbsProperty(n, GLU_SAMPLING_METHOD, GLU_PARAMETRIC_ERROR);
    gluNurbsProperty(n, GLU_PARAMETRIC_TOLERANCE, tolerance_px);
    gluNurbsProperty(n, GLU_CULLING, GL_TRUE);
    gluNurbsProperty(n, GLU_DISPLAY_MODE, GLU_FILL);
    gluNurbsCallback(n, GLU_NURBS_ERROR, (_GLUfuncptr)on_error);
    gluNurbsCallback(n, GLU_NURBS_BEGIN_DATA, (_GLUfuncptr)on_begin);
    gluNurbsCallback(n, GLU_NURBS_NORMAL_DATA, (_GLUfuncptr)on_normal);
    gluNurbsCallback(n, GLU_NURBS_VERTEX_DATA, (_GLUfuncptr)on_vertex);
    gluNurbsCallback(n, GLU_NURBS_END_DATA, (_GLUfuncptr)on_end);
    gluNurbsCallbackData(n, &g->st);
    return g;
}

void bt_glu_free(bt_glu *g)
{
    if (!g)
        return;
    gluDeleteNurbsRenderer(g->nurb);
    free(g);
}

/* GLU takes non-const pointers but does not write through them. */
static GLfloat *mut(const float *p)
{
    return (GLfloat *)(uintptr_t)p;
}

static void trim_loops(GLUnurbs *n, const bt_glu_surface *s)
{
    for (int32_t l = 0; l < s->n_loops; ++l) {
        gluBeginTrim(n);
        for (int32_t c = 0; c < s->loops[l].n_curves; ++c) {
            const bt_glu_curve *cv = &s->loops[l].curves[c];
            if (cv->order == 0)
                gluPwlCurve(n, cv->n, mut(cv->pts), 2, GLU_MAP1_TRIM_2);
            else
                gluNurbsCurve(n, cv->n + cv->order, mut(cv->knots), 3, mut(cv->pts), cv->order,
                              GLU_MAP1_TRIM_3);
        }
        gluEndTrim(n);
    }
}

int bt_glu_tessellate(bt_glu *g, const bt_glu_surface *s, const float model[16],
                      const float proj[16], const int32_t viewport[4], bt_glu_mesh *out)
{
    out->n_v = out->n_idx = 0;
    memset(out->primitives, 0, sizeof out->primitives);
    g->st = (prim_state){out, 0, 0, {0.0f, 0.0f, 1.0f}, 0};
    g_glu_error = 0;
    GLint vp[4] = {viewport[0], viewport[1], viewport[2], viewport[3]};
    gluLoadSamplingMatrices(g->nurb, model, proj, vp);
    gluBeginSurface(g->nurb);
    gluNurbsSurface(g->nurb, s->n_u + s->order_u, mut(s->knots_u), s->n_v + s->order_v,
                    mut(s->knots_v), 4, 4 * s->n_u, mut(s->cpw), s->order_u, s->order_v,
                    GL_MAP2_VERTEX_4);
    trim_loops(g->nurb, s);
    gluEndSurface(g->nurb);
    if (g->st.oom)
        return -1;
    return (int)g_glu_error;
}

const char *bt_glu_error_str(int code)
{
    if (code == -1)
        return "out of memory";
    const GLubyte *s = gluErrorString((GLenum)code);
    return s ? (const char *)s : "unknown GLU error";
}

void bt_glu_mesh_free(bt_glu_mesh *m)
{
    if (!m)
        return;
    free(m->v);
    free(m->idx);
    memset(m, 0, sizeof *m);
}
