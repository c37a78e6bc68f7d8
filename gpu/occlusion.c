/* SPDX-License-Identifier: MIT */
/* The occlusion map of a frame (occlusion.h: what it holds and why it is conservative). */
#include "occlusion.h"
#include "frame_stages.h"
#include "sw_hooks.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { TILE = 8 };
static const double k_scale = 4.0;        /* full-frame pixels per map pixel */
static const double k_depth_slack = 1e-3; /* relative: the GPU's float positions and depth */
static const double k_box_pixels = 2.0;   /* full-frame pixels a tested box grows by */
static const double k_box_depth_px = 4.0; /* a tested box's depth allowance: fat-border slivers
                                             on the tangent plane, this many pixels' worth */

int sw__occ_map_init(sw__occ_map *m, const sw__gpu_view *v, double eps_px)
{
    memset(m, 0, sizeof *m);
    m->w = (int32_t)ceil(v->width / k_scale);
    m->h = (int32_t)ceil(v->height / k_scale);
    m->w = m->w > 0 ? m->w : 1;
    m->h = m->h > 0 ? m->h : 1;
    m->tw = (m->w + TILE - 1) / TILE;
    m->th = (m->h + TILE - 1) / TILE;
    m->scale = k_scale;
    m->f = v->focal_px / k_scale;
    m->cx = 0.5 * v->width / k_scale;
    m->cy = 0.5 * v->height / k_scale;
    memcpy(m->right, v->right, sizeof m->right);
    memcpy(m->up, v->up, sizeof m->up);
    memcpy(m->fwd, v->fwd, sizeof m->fwd);
    m->near_plane = v->near_plane;
    m->edge_margin = (eps_px + 1.0) / k_scale;
    m->box_margin = k_box_pixels / k_scale;
    m->min_extent = 3.0;
    const size_t n = (size_t)m->w * (size_t)m->h, nt = (size_t)m->tw * (size_t)m->th;
    m->depth = sw__malloc(n * sizeof *m->depth);
    m->tile_max = sw__malloc(nt * sizeof *m->tile_max);
    if (!m->depth || !m->tile_max) {
        sw__occ_map_free(m);
        return 0;
    }
    for (size_t i = 0; i < n; ++i)
        m->depth[i] = INFINITY;
    for (size_t i = 0; i < nt; ++i)
        m->tile_max[i] = INFINITY;
    return 1;
}

void sw__occ_map_free(sw__occ_map *m)
{
    sw__free(m->depth);
    sw__free(m->tile_max);
    sw__free(m->pts);
    sw__free(m->counts);
    sw__free(m->band);
    sw__free(m->xs);
    sw__free(m->vp);
    memset(m, 0, sizeof *m);
}

/* ---- one occluder ------------------------------------------------------------------------ */
static void to_view(const sw__occ_map *m, const double p[3], double out[3])
{
    out[0] = m->right[0] * p[0] + m->right[1] * p[1] + m->right[2] * p[2];
    out[1] = m->up[0] * p[0] + m->up[1] * p[1] + m->up[2] * p[2];
    out[2] = m->fwd[0] * p[0] + m->fwd[1] * p[1] + m->fwd[2] * p[2];
}

static int push_pt(sw__occ_map *m, size_t *n, const double q[3])
{
    if (!sw__grow((void **)&m->pts, &m->cap_pts, 3 * (*n + 1), sizeof *m->pts))
        return 0;
    memcpy(m->pts + 3 * (*n)++, q, 3 * sizeof *q);
    return 1;
}

/* A loop of view-space points clipped to depth >= near (Sutherland-Hodgman: each loop's inside is
 * the original's inside in front of the plane, so the even-odd region is too), appended to m->pts
 * in view space; returns the points added, or -1 when out of memory. */
static long clip_loop(sw__occ_map *m, const double *vp, uint32_t count, size_t *n)
{
    const size_t n0 = *n;
    const double zn = m->near_plane;
    for (uint32_t i = 0; i < count; ++i) {
        const double *a = vp + 3 * i, *b = vp + 3 * ((i + 1) % count);
        const int ain = a[2] >= zn, bin = b[2] >= zn;
        if (ain && !push_pt(m, n, a))
            return -1;
        if (ain != bin) {
            const double t = (zn - a[2]) / (b[2] - a[2]);
            const double q[3] = {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), zn};
            if (!push_pt(m, n, q))
                return -1;
        }
    }
    return (long)(*n - n0);
}

/* Newell's normal of a loop (view space) and its plane offset: n . p = d on the plane. */
static void loop_plane(const double *vp, uint32_t count, double n[3], double *d)
{
    double c[3] = {0, 0, 0};
    n[0] = n[1] = n[2] = 0.0;
    for (uint32_t i = 0; i < count; ++i) {
        const double *a = vp + 3 * i, *b = vp + 3 * ((i + 1) % count);
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
        for (int k = 0; k < 3; ++k)
            c[k] += a[k] / count;
    }
    *d = n[0] * c[0] + n[1] * c[1] + n[2] * c[2];
}

typedef struct rect {
    int32_t x0, y0, x1, y1; /* inclusive */
} rect;

/* Marks in m->band the rectangle's pixels whose square comes within `margin` of segment a-b. */
static void mark_edge(sw__occ_map *m, const rect *r, const double *a, const double *b,
                      double margin)
{
    const int32_t rw = r->x1 - r->x0 + 1;
    const double ylo = fmin(a[1], b[1]) - margin, yhi = fmax(a[1], b[1]) + margin;
    int32_t j0 = (int32_t)floor(ylo), j1 = (int32_t)floor(yhi);
    j0 = j0 > r->y0 ? j0 : r->y0;
    j1 = j1 < r->y1 ? j1 : r->y1;
    for (int32_t j = j0; j <= j1; ++j) {
        /* the part of the segment with y in the row's band [j - margin, j + 1 + margin] */
        const double band[4] = {-INFINITY, INFINITY, j - margin, j + 1.0 + margin};
        double t[2];
        if (!sw__gpu_segment_clip(a, b, band, t))
            continue;
        const double xa = a[0] + t[0] * (b[0] - a[0]), xb = a[0] + t[1] * (b[0] - a[0]);
        int32_t i0 = (int32_t)floor(fmin(xa, xb) - margin),
                i1 = (int32_t)floor(fmax(xa, xb) + margin);
        i0 = i0 > r->x0 ? i0 : r->x0;
        i1 = i1 < r->x1 ? i1 : r->x1;
        for (int32_t i = i0; i <= i1; ++i)
            m->band[(size_t)(j - r->y0) * rw + (i - r->x0)] = 1;
    }
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Row j's crossings of the loops at the pixel centres' height, sorted; -1 when out of memory. */
static long row_crossings(sw__occ_map *m, uint32_t n_loops, double yc)
{
    size_t n = 0, first = 0;
    for (uint32_t l = 0; l < n_loops; first += m->counts[l++])
        for (uint32_t i = 0; i < m->counts[l]; ++i) {
            const double *a = m->pts + 3 * (first + i),
                         *b = m->pts + 3 * (first + (i + 1) % m->counts[l]);
            if ((a[1] <= yc) == (b[1] <= yc))
                continue;
            if (!sw__grow((void **)&m->xs, &m->cap_xs, n + 1, sizeof *m->xs))
                return -1;
            m->xs[n++] = a[0] + (yc - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
        }
    if (n > 1) /* xs may still be NULL */
        qsort(m->xs, n, sizeof *m->xs, cmp_double);
    return (long)n;
}

static void update_tiles(sw__occ_map *m, const rect *r)
{
    for (int32_t ty = r->y0 / TILE; ty <= r->y1 / TILE; ++ty)
        for (int32_t tx = r->x0 / TILE; tx <= r->x1 / TILE; ++tx) {
            float mx = 0.0f;
            for (int32_t y = ty * TILE; y < (ty + 1) * TILE && y < m->h; ++y)
                for (int32_t x = tx * TILE; x < (tx + 1) * TILE && x < m->w; ++x)
                    mx = fmaxf(mx, m->depth[(size_t)y * m->w + x]);
            m->tile_max[(size_t)ty * m->tw + tx] = mx;
        }
}

/* 1 / depth over the map, L0 + Lx x + Ly y, of the plane n . p = d (view space). */
typedef struct inv_depth {
    double l0, lx, ly;
} inv_depth;

static inv_depth plane_inv_depth(const sw__occ_map *m, const double n[3], double d)
{
    /* p = z (a, b, 1) with a = (x - cx) / f, b = (cy - y) / f: n . p = d gives 1/z */
    inv_depth l;
    l.lx = n[0] / (m->f * d);
    l.ly = -n[1] / (m->f * d);
    l.l0 = (n[2] - n[0] * m->cx / m->f + n[1] * m->cy / m->f) / d;
    return l;
}

/* Fills the covered pixels of the projected loops in m->pts (map x, y) within r. */
static int fill(sw__occ_map *m, uint32_t n_loops, const rect *r, const inv_depth *l)
{
    const int32_t rw = r->x1 - r->x0 + 1;
    const double min_x = fmin(l->lx, 0.0), min_y = fmin(l->ly, 0.0);
    for (int32_t j = r->y0; j <= r->y1; ++j) {
        const long nx = row_crossings(m, n_loops, j + 0.5);
        if (nx < 0)
            return 0;
        for (long k = 0; k + 1 < nx; k += 2) {
            /* centres i + 0.5 in [xs[k], xs[k+1]] */
            int32_t i0 = (int32_t)ceil(m->xs[k] - 0.5), i1 = (int32_t)floor(m->xs[k + 1] - 0.5);
            i0 = i0 > r->x0 ? i0 : r->x0;
            i1 = i1 < r->x1 ? i1 : r->x1;
            for (int32_t i = i0; i <= i1; ++i) {
                if (m->band[(size_t)(j - r->y0) * rw + (i - r->x0)])
                    continue;
                const double inv = l->l0 + l->lx * i + l->ly * j + min_x + min_y;
                if (!(inv > 0.0))
                    continue;
                const float z = (float)((1.0 + k_depth_slack) / inv);
                float *dst = &m->depth[(size_t)j * m->w + i];
                *dst = fminf(*dst, z);
            }
        }
    }
    return 1;
}

/* The loops' view-space points (transformed, clipped) into m->pts and m->counts; the number of
 * loops kept, or -1 when out of memory. */
static long view_loops(sw__occ_map *m, const sw_gpu_occluders *oc, const sw__occ_face *of,
                       const double world[12], const double eye[3], double *vp_plane, double *d)
{
    size_t n = 0;
    long kept = 0;
    for (uint32_t l = 0; l < of->n_loops; ++l) {
        const uint32_t first = oc->loop_first[of->first_loop + l],
                       count = oc->loop_count[of->first_loop + l];
        if (!sw__grow((void **)&m->vp, &m->cap_vp, 3 * (size_t)count, sizeof *m->vp))
            return -1;
        for (uint32_t i = 0; i < count; ++i) {
            const double *p = oc->points + 3 * (size_t)(first + i);
            const double h[4] = {p[0], p[1], p[2], 1.0};
            double w[4];
            sw__fr_xform_h(world, eye, h, w);
            to_view(m, w, m->vp + 3 * i);
        }
        if (l == 0)
            loop_plane(m->vp, count, vp_plane, d);
        const long c = clip_loop(m, m->vp, count, &n);
        if (c < 0)
            return -1;
        if (c == 0)
            continue;
        if (!sw__grow((void **)&m->counts, &m->cap_counts, (size_t)kept + 1, sizeof *m->counts))
            return -1;
        m->counts[kept++] = (uint32_t)c;
    }
    return kept;
}

int sw__occ_map_add_face(sw__occ_map *m, const sw_gpu_occluders *oc, uint32_t face,
                         const double world[12], const double eye[3])
{
    if (!oc || face >= oc->n_faces || oc->faces[face].n_loops == 0)
        return 0;
    const sw__occ_face *of = &oc->faces[face];
    double n[3], d;
    const long loops = view_loops(m, oc, of, world, eye, n, &d);
    if (loops <= 0)
        return (int)loops;
    /* project; the nearest depth scales the outline's object error to map pixels */
    size_t total = 0;
    for (long l = 0; l < loops; ++l)
        total += m->counts[l];
    double zmin = INFINITY, bx[4] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < total; ++i) {
        double *p = m->pts + 3 * i;
        const double z = p[2];
        zmin = fmin(zmin, z);
        p[0] = m->cx + m->f * p[0] / z;
        p[1] = m->cy - m->f * p[1] / z;
        bx[0] = fmin(bx[0], p[0]);
        bx[1] = fmin(bx[1], p[1]);
        bx[2] = fmax(bx[2], p[0]);
        bx[3] = fmax(bx[3], p[1]);
    }
    const double nn = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const double margin = m->edge_margin + of->err * sw_sg_stretch_bound(world) * m->f / zmin;
    /* a plane through (nearly) the eye is seen edge-on: it covers nothing */
    if (!(nn > 0.0) || !(fabs(d) > 1e-6 * nn * zmin) || !isfinite(margin))
        return 0;
    rect r = {(int32_t)fmax(floor(bx[0]), 0.0), (int32_t)fmax(floor(bx[1]), 0.0),
              (int32_t)fmin(ceil(bx[2]) - 1.0, m->w - 1.0),
              (int32_t)fmin(ceil(bx[3]) - 1.0, m->h - 1.0)};
    if (r.x1 - r.x0 + 1 < m->min_extent || r.y1 - r.y0 + 1 < m->min_extent)
        return 0;
    const size_t area = (size_t)(r.x1 - r.x0 + 1) * (size_t)(r.y1 - r.y0 + 1);
    if (!sw__grow((void **)&m->band, &m->cap_band, area, 1))
        return -1;
    memset(m->band, 0, area);
    size_t first = 0;
    for (long l = 0; l < loops; first += m->counts[l++])
        for (uint32_t i = 0; i < m->counts[l]; ++i)
            mark_edge(m, &r, m->pts + 3 * (first + i),
                      m->pts + 3 * (first + (i + 1) % m->counts[l]), margin);
    const inv_depth l = plane_inv_depth(m, n, d);
    if (!fill(m, (uint32_t)loops, &r, &l))
        return -1;
    update_tiles(m, &r);
    m->occluders_drawn++;
    return 1;
}

/* ---- tests ------------------------------------------------------------------------------- */
int sw__occ_map_box_hidden(sw__occ_map *m, const double box[6])
{
    m->tests++;
    double zmin = INFINITY, bx[4] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
    for (int c = 0; c < 8; ++c) {
        const double p[3] = {box[(c & 1) ? 3 : 0], box[(c & 2) ? 4 : 1], box[(c & 4) ? 5 : 2]};
        double q[3];
        to_view(m, p, q);
        if (!(q[2] >= m->near_plane))
            return 0;
        zmin = fmin(zmin, q[2]);
        const double x = m->cx + m->f * q[0] / q[2], y = m->cy - m->f * q[1] / q[2];
        bx[0] = fmin(bx[0], x);
        bx[1] = fmin(bx[1], y);
        bx[2] = fmax(bx[2], x);
        bx[3] = fmax(bx[3], y);
    }
    const int32_t x0 = (int32_t)fmax(floor(bx[0] - m->box_margin), 0.0),
                  y0 = (int32_t)fmax(floor(bx[1] - m->box_margin), 0.0),
                  x1 = (int32_t)fmin(floor(bx[2] + m->box_margin), m->w - 1.0),
                  y1 = (int32_t)fmin(floor(bx[3] + m->box_margin), m->h - 1.0);
    if (x0 > x1 || y0 > y1)
        return 0;
    const float zt = (float)(zmin * (1.0 - k_box_depth_px / (m->f * m->scale)));
    for (int32_t ty = y0 / TILE; ty <= y1 / TILE; ++ty)
        for (int32_t tx = x0 / TILE; tx <= x1 / TILE; ++tx) {
            const int32_t px0 = tx * TILE, py0 = ty * TILE;
            if (px0 >= x0 && py0 >= y0 && px0 + TILE - 1 <= x1 && py0 + TILE - 1 <= y1) {
                if (!(m->tile_max[(size_t)ty * m->tw + tx] < zt))
                    return 0;
                continue;
            }
            const int32_t ya = py0 > y0 ? py0 : y0, yb = py0 + TILE - 1 < y1 ? py0 + TILE - 1 : y1;
            const int32_t xa = px0 > x0 ? px0 : x0, xb = px0 + TILE - 1 < x1 ? px0 + TILE - 1 : x1;
            for (int32_t y = ya; y <= yb; ++y)
                for (int32_t x = xa; x <= xb; ++x)
                    if (!(m->depth[(size_t)y * m->w + x] < zt))
                        return 0;
        }
    m->hidden++;
    return 1;
}
