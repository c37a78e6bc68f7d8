/* The building generator (sw_sg_generate.h): storeys of nx x ny rooms of 4 m x 4 m, in
 * centimetres, z up. Every room has a floor and a ceiling (planar faces, the stair room's cut by
 * the stairwell), its south and west walls (and the east / north ones on the boundary) as two
 * planar faces each, trimmed by window holes (rectangular or arched) on the facade and by door
 * notches (rectangular or arched) inside, with the doors' reveals (jambs, a lintel or a half-
 * cylinder soffit), a column at its corner (a rational quadratic cylinder), and a straight stair
 * (one prototype, instanced per storey) in room (0, 0). Rooms with nothing above carry a roof:
 * a slab face and a dome (a revolved quarter circle: an exact sphere) or a barrel vault (a half
 * cylinder with two semicircular gables). Furniture: instances of real OCCT sample models.
 *
 * Conventions are the importer's (import_occt.cpp, OCCT's): the outer loop runs counter-clockwise
 * in (u, v), holes clockwise; consecutive trim curves share their join points bit for bit (the
 * loops are drawn as one pen path). Circles are exact: rational quadratic quarter arcs with
 * weights 1, √2/2, 1 (The NURBS Book §7.3); a dome is their tensor product with the revolved
 * meridian (§8.5).
 *
 * The count is met exactly: a dry run (the same code, counting only) finds the largest number of
 * rooms whose scene stays within N face occurrences, the remainder is filled with bollards (small
 * columns) in front of the building. Furniture is placed only while the occurrences drawn through
 * instances stay within 3x the unique faces, so at least a quarter of the faces are unique.
 * Randomness comes from a hash of (seed, room, wall), never from the order of the calls.
 */
#include "sw_sg_bvh.h"
#include "sw_sg_generate.h"

#include "sw_status_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *const sw_sg_building_model_files[SW_SG_BUILDING_N_MODELS] = {
    "occ/MODERN_Chair_1.brep",    "occ/MODERN_Table_1.brep",  "occ/MODERN_Refrigerator_1.brep",
    "occ/MODERN_MVCooker_1.brep", "occ/MODERN_Cooker_1.brep", "occ/MODERN_Exhaust_1.brep",
    "occ/MODERN_Sink_1.brep",     "occ/Motor-c.brep",         "occ/CrankArm.brep",
    "occ/Pump_Nut.brep"};
enum {
    M_CHAIR,
    M_TABLE,
    M_FRIDGE,
    M_MVCOOKER,
    M_COOKER,
    M_EXHAUST,
    M_SINK,
    M_MOTOR,
    M_CRANK,
    M_NUT
};

/* Dimensions in cm; all binary-exact so that computed join points coincide. */
#define ROOM 400.0
#define STOREY 330.0
#define SLAB 25.0
#define WALL 20.0
#define CLEAR (STOREY - SLAB)
#define COLUMN_R 18.0
#define STEPS 16
#define RISE (STOREY / STEPS) /* 20.625 */
#define GOING 22.5
#define STAIR_X0 20.0
#define STAIR_Y0 40.0
#define STAIR_W 100.0
#define DOOR_H 210.0
#define SILL 90.0
#define CUPOLA_R 150.0
#define BOLLARD_R 10.0
#define BOLLARD_H 100.0
#define FURNITURE_RATIO 3 /* occurrences through instances <= 3 x unique faces */

enum { GB_MAX_CURVES = 48, GB_MAX_LOOPS = 6, GB_MAX_NU = 9, GB_MAX_NV = 3 };
enum { SIDE_S, SIDE_W, SIDE_E, SIDE_N, SALT_ROOM = 7, SALT_ROOF = 9 };

static const double k_x[3] = {1, 0, 0}, k_y[3] = {0, 1, 0}, k_z[3] = {0, 0, 1};
static const float k_wall_col[4] = {0.80f, 0.74f, 0.62f, 1},
                   k_floor_col[4] = {0.45f, 0.33f, 0.22f, 1};
static const float k_ceiling_col[4] = {0.92f, 0.92f, 0.90f, 1},
                   k_column_col[4] = {0.70f, 0.70f, 0.75f, 1};
static const float k_roof_col[4] = {0.60f, 0.28f, 0.22f, 1},
                   k_stair_col[4] = {0.55f, 0.50f, 0.45f, 1};
static const float k_reveal_col[4] = {0.65f, 0.60f, 0.52f, 1},
                   k_fur_col[4] = {0.30f, 0.45f, 0.65f, 1};

/* ---- a face under construction -------------------------------------------------------------- */

typedef struct gb_curve {
    int deg, n;
    double knots[6], cpw[9];
} gb_curve;

typedef struct gb_face {
    int deg_u, deg_v, n_u, n_v;
    double ku[GB_MAX_NU + 3], kv[GB_MAX_NV + 3], cpw[GB_MAX_NU * GB_MAX_NV * 4];
    uint32_t kind, flags;
    int n_loops, loop_first[GB_MAX_LOOPS + 1];
    uint32_t loop_flags[GB_MAX_LOOPS];
    int n_curves;
    gb_curve c[GB_MAX_CURVES];
    double pen[2], start[2]; /* the loop being drawn */
} gb_face;

static void v3(double out[3], const double o[3], double a, const double e[3], double b,
               const double f[3])
{
    for (int k = 0; k < 3; ++k)
        out[k] = o[k] + a * e[k] + b * f[k];
}

static void cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static void set_cp(gb_face *f, int i, int j, const double p[3], double w)
{
    double *q = f->cpw + ((size_t)j * f->n_u + i) * 4;
    q[0] = w * p[0], q[1] = w * p[1], q[2] = w * p[2], q[3] = w;
}

static void face_reset(gb_face *f, uint32_t kind)
{
    f->kind = kind;
    f->flags = 0;
    f->n_loops = 0;
    f->n_curves = 0;
    f->loop_first[0] = 0;
}

/* The plane o + u e + v g over [0, l] x [0, h], parameters in cm. */
static void plane_surface(gb_face *f, const double o[3], const double e[3], const double g[3],
                          double l, double h)
{
    f->deg_u = f->deg_v = 1;
    f->n_u = f->n_v = 2;
    const double ku[4] = {0, 0, l, l}, kv[4] = {0, 0, h, h};
    memcpy(f->ku, ku, sizeof ku);
    memcpy(f->kv, kv, sizeof kv);
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            double p[3];
            v3(p, o, i * l, e, j * h, g);
            set_cp(f, i, j, p, 1.0);
        }
}

/* Unit direction k (mod 4) of a circle in the plane (e1, e2): e1, e2, -e1, -e2. */
static void circle_dir(const double e1[3], const double e2[3], int k, double out[3])
{
    const double s1 = (k & 3) == 0 ? 1 : (k & 3) == 2 ? -1 : 0;
    const double s2 = (k & 3) == 1 ? 1 : (k & 3) == 3 ? -1 : 0;
    for (int c = 0; c < 3; ++c)
        out[c] = s1 * e1[c] + s2 * e2[c];
}

/* Quarter-arc knots for nq quadrants: 0 0 0 1 1 2 2 ... nq nq nq (u in [0, nq]). */
static int arc_knots(int nq, double *k)
{
    int n = 0;
    k[n++] = 0, k[n++] = 0, k[n++] = 0;
    for (int q = 1; q < nq; ++q)
        k[n++] = q, k[n++] = q;
    k[n++] = nq, k[n++] = nq, k[n++] = nq;
    return n;
}

/* The cylinder c + r (cos t e1 + sin t e2) + v axis, t over nq quadrants from e1, v in [0, len]:
 * its poles are the circle's (on the circle, weight 1) and the corners of its circumscribed
 * square (weight √2/2). Su x Sv points away from the axis when e1 x e2 = axis. */
static void cylinder_surface(gb_face *f, const double c[3], const double e1[3], const double e2[3],
                             const double axis[3], double r, int nq, double len)
{
    f->deg_u = 2, f->deg_v = 1;
    f->n_u = 2 * nq + 1, f->n_v = 2;
    arc_knots(nq, f->ku);
    const double kv[4] = {0, 0, len, len};
    memcpy(f->kv, kv, sizeof kv);
    for (int j = 0; j < 2; ++j)
        for (int t = 0; t <= 2 * nq; ++t) {
            double a[3], b[3], p[3];
            circle_dir(e1, e2, t / 2, a);
            if (t & 1)
                circle_dir(e1, e2, t / 2 + 1, b);
            else
                b[0] = b[1] = b[2] = 0.0;
            for (int k = 0; k < 3; ++k)
                p[k] = c[k] + r * (a[k] + b[k]) + j * len * axis[k];
            set_cp(f, t, j, p, (t & 1) ? M_SQRT1_2 : 1.0);
        }
}

/* The hemisphere of radius r on centre c, z up: the full circle (u in [0, 4]) times the quarter
 * meridian from the equator to the pole (v in [0, 1]); weights multiply. */
static void dome_surface(gb_face *f, const double c[3], double r)
{
    f->deg_u = f->deg_v = 2;
    f->n_u = 9, f->n_v = 3;
    arc_knots(4, f->ku);
    arc_knots(1, f->kv);
    const double mr[3] = {r, r, 0}, mz[3] = {0, r, r}, mw[3] = {1, M_SQRT1_2, 1};
    for (int j = 0; j < 3; ++j)
        for (int t = 0; t <= 8; ++t) {
            double a[3], b[3] = {0, 0, 0}, p[3];
            circle_dir(k_x, k_y, t / 2, a);
            if (t & 1)
                circle_dir(k_x, k_y, t / 2 + 1, b);
            for (int k = 0; k < 3; ++k)
                p[k] = c[k] + mr[j] * (a[k] + b[k]) + mz[j] * k_z[k];
            set_cp(f, t, j, p, ((t & 1) ? M_SQRT1_2 : 1.0) * mw[j]);
        }
}

/* ---- trim loops, drawn as pen paths ---------------------------------------------------------- */

static void loop_begin(gb_face *f, double u, double v, uint32_t flags)
{
    f->loop_flags[f->n_loops] = flags;
    f->pen[0] = f->start[0] = u;
    f->pen[1] = f->start[1] = v;
}

static gb_curve *next_curve(gb_face *f)
{
    return f->n_curves < GB_MAX_CURVES ? &f->c[f->n_curves++] : NULL;
}

static void line_to(gb_face *f, double u, double v)
{
    gb_curve *c = next_curve(f);
    if (!c)
        return;
    const double k[4] = {0, 0, 1, 1}, p[6] = {f->pen[0], f->pen[1], 1, u, v, 1};
    c->deg = 1, c->n = 2;
    memcpy(c->knots, k, sizeof k);
    memcpy(c->cpw, p, sizeof p);
    f->pen[0] = u, f->pen[1] = v;
}

/* nq quarter arcs around (cu, cv) from the pen, which lies on the circle at quadrant q0 (0: +u,
 * 1: +v, ...), counter-clockwise for dir = +1, clockwise for -1. */
static void arcs(gb_face *f, double cu, double cv, double r, int q0, int dir, int nq)
{
    static const double du[4] = {1, 0, -1, 0}, dv[4] = {0, 1, 0, -1};
    for (int s = 0; s < nq; ++s) {
        gb_curve *c = next_curve(f);
        if (!c)
            return;
        const int a = (q0 + dir * s) & 3, b = (q0 + dir * (s + 1)) & 3;
        const double h = M_SQRT1_2;
        const double mu = cu + r * (du[a] + du[b]), mv = cv + r * (dv[a] + dv[b]);
        const double eu = cu + r * du[b], ev = cv + r * dv[b];
        const double k[6] = {0, 0, 0, 1, 1, 1};
        const double p[9] = {f->pen[0], f->pen[1], 1, h * mu, h * mv, h, eu, ev, 1};
        c->deg = 2, c->n = 3;
        memcpy(c->knots, k, sizeof k);
        memcpy(c->cpw, p, sizeof p);
        f->pen[0] = eu, f->pen[1] = ev;
    }
}

/* Closes the loop: a line back to its start unless the pen is there already. */
static void loop_end(gb_face *f)
{
    if (f->pen[0] != f->start[0] || f->pen[1] != f->start[1])
        line_to(f, f->start[0], f->start[1]);
    f->loop_first[++f->n_loops] = f->n_curves;
    if (f->n_loops > 1 || f->n_curves != 4)
        f->flags |= SW_SG_FACE_TRIMMED;
}

static void outer_rect(gb_face *f, double l, double h)
{
    loop_begin(f, 0, 0, SW_SG_LOOP_OUTER);
    line_to(f, l, 0);
    line_to(f, l, h);
    line_to(f, 0, h);
    loop_end(f);
}

/* A clockwise rectangular hole [u0, u1] x [v0, v1]. */
static void hole_rect(gb_face *f, double u0, double v0, double u1, double v1)
{
    if (f->n_loops >= GB_MAX_LOOPS)
        return;
    loop_begin(f, u0, v0, 0);
    line_to(f, u0, v1);
    line_to(f, u1, v1);
    line_to(f, u1, v0);
    loop_end(f);
}

/* A clockwise hole: jambs up to v1, a semicircle over [u0, u1] on top. */
static void hole_arched(gb_face *f, double u0, double v0, double u1, double v1)
{
    if (f->n_loops >= GB_MAX_LOOPS)
        return;
    loop_begin(f, u0, v0, 0);
    line_to(f, u0, v1);
    arcs(f, 0.5 * (u0 + u1), v1, 0.5 * (u1 - u0), 2, -1, 2);
    line_to(f, u1, v0);
    loop_end(f);
}

/* ---- the generator's state ------------------------------------------------------------------- */

typedef struct gb {
    sw_sg_builder *b; /* NULL: a dry run, counting only */
    const sw_sg_building_desc *d;
    uint32_t nx, ny;
    uint32_t n_nodes;                            /* nodes in b (or that would be) */
    uint64_t occ, unique;                        /* face occurrences; faces stored */
    uint64_t instanced;                          /* occurrences drawn through instance nodes */
    uint32_t proto[SW_SG_BUILDING_N_MODELS + 1]; /* the stair is the last; SW_SG_NONE: not yet */
    uint64_t model_occ[SW_SG_BUILDING_N_MODELS];
    double model_box[SW_SG_BUILDING_N_MODELS][6];
    uint32_t floor_node, floor_of_node, roof_node;
    int oom;
    sw_sg_building_report rep;
    gb_face *face; /* scratch, shared by dry-run copies */
} gb;

static uint64_t mix64(uint64_t x)
{
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

/* The random stream of one (room, salt): independent of the order rooms are built in. */
static uint64_t stream(const gb *g, uint64_t room, uint64_t salt)
{
    return mix64(g->d->seed ^ mix64(room * 16 + salt + 1));
}

static uint32_t pick(uint64_t *s, uint32_t n)
{
    *s = mix64(*s);
    return (uint32_t)((*s >> 33) % n);
}

static uint32_t add_node(gb *g, sw_sg_node_kind kind, uint32_t parent, uint32_t ref,
                         const double xf[12], const float col[4], const char *name)
{
    const uint32_t want = g->n_nodes++;
    if (g->b && !g->oom && sw_sg_builder_add_node(g->b, kind, parent, ref, xf, col, name) != want)
        g->oom = 1;
    return want;
}

static uint64_t push(gb *g, const double *v, size_t n)
{
    const uint64_t off = sw_sg_builder_push_doubles(g->b, v, n);
    g->oom |= off == UINT64_MAX;
    return off;
}

static void uv_box(const gb_face *f, double box[4])
{
    box[0] = box[2] = HUGE_VAL, box[1] = box[3] = -HUGE_VAL;
    for (int k = 0; k < f->n_curves; ++k)
        for (int i = 0; i < f->c[k].n; ++i) {
            const double *p = f->c[k].cpw + 3 * i;
            box[0] = fmin(box[0], p[0] / p[2]), box[1] = fmax(box[1], p[0] / p[2]);
            box[2] = fmin(box[2], p[1] / p[2]), box[3] = fmax(box[3], p[1] / p[2]);
        }
    const double lo[2] = {f->ku[f->deg_u], f->kv[f->deg_v]}, hi[2] = {f->ku[f->n_u], f->kv[f->n_v]};
    for (int a = 0; a < 2; ++a) {
        box[2 * a] = fmax(box[2 * a], lo[a]);
        box[2 * a + 1] = fmin(box[2 * a + 1], hi[a]);
    }
}

static uint32_t store_face(gb *g, const gb_face *f)
{
    sw_sg_face_rec rec;
    memset(&rec, 0, sizeof rec);
    rec.deg_u = (uint32_t)f->deg_u, rec.deg_v = (uint32_t)f->deg_v;
    rec.n_u = (uint32_t)f->n_u, rec.n_v = (uint32_t)f->n_v;
    rec.knots_u = push(g, f->ku, (size_t)(f->n_u + f->deg_u + 1));
    rec.knots_v = push(g, f->kv, (size_t)(f->n_v + f->deg_v + 1));
    rec.cpw = push(g, f->cpw, (size_t)f->n_u * f->n_v * 4);
    rec.kind = f->kind;
    rec.flags = f->flags;
    rec.tolerance = 1e-7;
    uv_box(f, rec.uv_box);
    for (int l = 0; l < f->n_loops; ++l) {
        sw_sg_loop_rec lr = {SW_SG_NONE, (uint32_t)(f->loop_first[l + 1] - f->loop_first[l]),
                             f->loop_flags[l], 0};
        for (int k = f->loop_first[l]; k < f->loop_first[l + 1]; ++k) {
            sw_sg_curve_rec cr = {(uint32_t)f->c[k].deg, (uint32_t)f->c[k].n, 0, 0};
            cr.knots = push(g, f->c[k].knots, (size_t)(f->c[k].n + f->c[k].deg + 1));
            cr.cpw = push(g, f->c[k].cpw, (size_t)f->c[k].n * 3);
            const uint32_t ci = sw_sg_builder_add_curve(g->b, &cr);
            g->oom |= ci == SW_SG_NONE;
            if (lr.first_curve == SW_SG_NONE)
                lr.first_curve = ci;
        }
        const uint32_t li = sw_sg_builder_add_loop(g->b, &lr);
        g->oom |= li == SW_SG_NONE;
        if (l == 0)
            rec.first_loop = li;
    }
    rec.n_loops = (uint32_t)f->n_loops;
    const uint32_t fi = sw_sg_builder_add_face(g->b, &rec);
    g->oom |= fi == SW_SG_NONE;
    return fi;
}

/* Stores the scratch face and draws it under `parent` (drawn = 0: a prototype's face). */
static void emit(gb *g, uint32_t parent, const float col[4], int drawn)
{
    const gb_face *f = g->face;
    g->unique++;
    g->occ += drawn != 0;
    uint32_t fi = 0;
    if (g->b && !g->oom)
        fi = store_face(g, f);
    add_node(g, SW_SG_NODE_SURFACE, parent, fi, NULL, col, NULL);
}

/* A planar face o + u e + v g, [0, l] x [0, h]; reversed: its normal is -(e x g). */
static void plane(gb *g, const double o[3], const double e[3], const double f3[3], double l,
                  double h, int reversed)
{
    face_reset(g->face, SW_SG_KIND_PLANE);
    plane_surface(g->face, o, e, f3, l, h);
    outer_rect(g->face, l, h);
    if (reversed)
        g->face->flags |= SW_SG_FACE_REVERSED;
}

static void cylinder(gb *g, const double c[3], const double e1[3], const double e2[3],
                     const double axis[3], double r, int nq, double len, int reversed)
{
    face_reset(g->face, SW_SG_KIND_CYLINDER);
    cylinder_surface(g->face, c, e1, e2, axis, r, nq, len);
    outer_rect(g->face, nq, len);
    if (reversed)
        g->face->flags |= SW_SG_FACE_REVERSED;
}

static void column(gb *g, uint32_t parent, double x, double y, double z0, double r, double h)
{
    const double c[3] = {x, y, z0};
    cylinder(g, c, k_x, k_y, k_z, r, 4, h, 0);
    emit(g, parent, k_column_col, 1);
    g->rep.columns++;
}

/* ---- walls ----------------------------------------------------------------------------------- */

typedef struct wall_plan {
    int door, door_arched, n_win, win_arched[3];
    double door_u0, door_u1, win_w, win_h;
} wall_plan;

static wall_plan plan_wall(const gb *g, uint64_t room, int side, int exterior, int entrance)
{
    uint64_t s = stream(g, room, (uint64_t)side);
    wall_plan w;
    memset(&w, 0, sizeof w);
    w.door = entrance || (!exterior && pick(&s, 2));
    w.door_arched = (int)pick(&s, 2);
    const double centre = 140.0 + 20.0 * pick(&s, 7);
    w.door_u0 = centre - 50.0, w.door_u1 = centre + 50.0;
    if (exterior && !entrance) {
        w.n_win = 1 + (int)pick(&s, 3);
        w.win_w = 60.0 + 20.0 * pick(&s, w.n_win == 3 ? 2 : 3);
        w.win_h = 120.0 + 10.0 * pick(&s, 4);
        for (int i = 0; i < w.n_win; ++i)
            w.win_arched[i] = (int)pick(&s, 2);
    }
    return w;
}

/* The wall's trim in its (u along, v up) parameters: a door as a notch of the outer loop,
 * windows as holes. */
static void wall_trim(gb_face *f, const wall_plan *w)
{
    loop_begin(f, 0, 0, SW_SG_LOOP_OUTER);
    if (w->door) {
        line_to(f, w->door_u0, 0);
        const double r = 0.5 * (w->door_u1 - w->door_u0);
        if (w->door_arched) {
            line_to(f, w->door_u0, DOOR_H - r);
            arcs(f, w->door_u0 + r, DOOR_H - r, r, 2, -1, 2);
        } else {
            line_to(f, w->door_u0, DOOR_H);
            line_to(f, w->door_u1, DOOR_H);
        }
        line_to(f, w->door_u1, 0);
    }
    line_to(f, ROOM, 0);
    line_to(f, ROOM, CLEAR);
    line_to(f, 0, CLEAR);
    loop_end(f);
    for (int i = 0; i < w->n_win; ++i) {
        const double c = floor(ROOM * (i + 1) / (w->n_win + 1));
        const double u0 = c - 0.5 * w->win_w, u1 = c + 0.5 * w->win_w;
        if (w->win_arched[i])
            hole_arched(f, u0, SILL, u1, SILL + w->win_h - 0.5 * w->win_w);
        else
            hole_rect(f, u0, SILL, u1, SILL + w->win_h);
    }
}

/* The door's reveals across the wall: jambs facing the opening, a lintel or a soffit. */
static void door_reveals(gb *g, uint32_t parent, const wall_plan *w, const double o[3],
                         const double e[3], const double n[3])
{
    const double r = 0.5 * (w->door_u1 - w->door_u0);
    const double jamb = w->door_arched ? DOOR_H - r : DOOR_H;
    double p[3], back[3];
    v3(back, o, -0.5 * WALL, n, 0.0, n);
    v3(p, back, w->door_u0, e, 0.0, e);
    plane(g, p, n, k_z, WALL, jamb, 1); /* n x z = -e: the left jamb faces +e */
    emit(g, parent, k_reveal_col, 1);
    v3(p, back, w->door_u1, e, 0.0, e);
    plane(g, p, n, k_z, WALL, jamb, 0);
    emit(g, parent, k_reveal_col, 1);
    if (w->door_arched) {
        v3(p, back, w->door_u0 + r, e, jamb, k_z);
        cylinder(g, p, e, k_z, n, r, 2, WALL, 1); /* inward, towards the opening */
        g->rep.arches++;
    } else {
        v3(p, back, w->door_u0, e, DOOR_H, k_z);
        plane(g, p, e, n, 2.0 * r, WALL, 0); /* e x n = -z: faces down */
    }
    emit(g, parent, k_reveal_col, 1);
}

/* A wall of one room side from `o` (its foot, on the axis) along `e`: two faces WALL apart. */
static void wall(gb *g, uint32_t parent, uint64_t room, int side, int exterior, int entrance,
                 const double o[3], const double e[3])
{
    const wall_plan w = plan_wall(g, room, side, exterior, entrance);
    double n[3], p[3];
    cross(e, k_z, n);
    for (int s = 0; s < 2; ++s) {
        face_reset(g->face, SW_SG_KIND_PLANE);
        v3(p, o, s ? -0.5 * WALL : 0.5 * WALL, n, 0.0, n);
        plane_surface(g->face, p, e, k_z, ROOM, CLEAR);
        wall_trim(g->face, &w);
        if (s)
            g->face->flags |= SW_SG_FACE_REVERSED;
        emit(g, parent, k_wall_col, 1);
    }
    g->rep.windows += (uint32_t)w.n_win;
    for (int i = 0; i < w.n_win; ++i)
        g->rep.arches += (uint32_t)w.win_arched[i];
    if (w.door) {
        g->rep.doors++;
        door_reveals(g, parent, &w, o, e, n);
    }
}

/* ---- rooms ----------------------------------------------------------------------------------- */

typedef struct room_at {
    uint32_t f, ix, iy;
    double x0, y0, z0;
    int stair;
} room_at;

static room_at locate(const gb *g, uint64_t k)
{
    const uint64_t per = (uint64_t)g->nx * g->ny, rem = k % per;
    room_at a = {(uint32_t)(k / per), (uint32_t)(rem % g->nx), (uint32_t)(rem / g->nx), 0, 0, 0, 0};
    a.x0 = a.ix * ROOM, a.y0 = a.iy * ROOM, a.z0 = a.f * STOREY;
    a.stair = a.ix == 0 && a.iy == 0;
    return a;
}

/* A slab face over the room at height z (the stair room's with the stairwell cut out). */
static void slab_face(gb *g, uint32_t parent, const room_at *a, double z, int hole, int down,
                      const float col[4])
{
    const double o[3] = {a->x0, a->y0, z};
    plane(g, o, k_x, k_y, ROOM, ROOM, down);
    if (hole)
        hole_rect(g->face, STAIR_X0, STAIR_Y0, STAIR_X0 + STEPS * GOING, STAIR_Y0 + STAIR_W);
    emit(g, parent, col, 1);
}

static void model_instance(gb *g, uint32_t parent, int m, const double xf[12])
{
    if (g->proto[m] == SW_SG_NONE) {
        const sw_sg_scene_view *v = sw_sg_scene_view_ptr(g->d->models[m]);
        if (g->b && !g->oom && sw__sg_append_model(g->b, v, g->n_nodes, &g->proto[m], NULL))
            g->oom = 1;
        if (!g->b)
            g->proto[m] = 0;
        g->n_nodes += v->n_nodes;
        g->unique += v->n_faces;
    }
    add_node(g, SW_SG_NODE_INSTANCE, parent, g->proto[m], xf, k_fur_col, NULL);
    g->occ += g->model_occ[m];
    g->instanced += g->model_occ[m];
    g->rep.instances++;
}

/* A model with its box's minimum corner at (x, y, z). */
static void place(gb *g, uint32_t parent, int m, double x, double y, double z)
{
    const double *b = g->model_box[m];
    const double xf[12] = {1, 0, 0, x - b[0], 0, 1, 0, y - b[1], 0, 0, 1, z - b[2]};
    model_instance(g, parent, m, xf);
}

/* The MODERN_* models share one kitchen frame (origin in a room corner, cm): they are placed
 * as they are, shifted to the room; a second chair faces the first across the table. */
static void furnish(gb *g, uint32_t parent, const room_at *a, uint64_t room)
{
    static const int sets[5][4] = {{M_FRIDGE, M_MVCOOKER, M_COOKER, M_EXHAUST},
                                   {M_TABLE, M_CHAIR, -1, -1},
                                   {M_SINK, -1, -1, -1},
                                   {M_MOTOR, M_CRANK, M_NUT, -1},
                                   {M_FRIDGE, M_MVCOOKER, -1, -1}};
    uint64_t s = stream(g, room, SALT_ROOM);
    const int k = (int)pick(&s, 5);
    uint64_t cost = k == 1 ? g->model_occ[M_CHAIR] : 0;
    for (int i = 0; i < 4; ++i)
        cost += sets[k][i] >= 0 ? g->model_occ[sets[k][i]] : 0;
    if (a->stair || g->instanced + cost > FURNITURE_RATIO * g->unique)
        return;
    const double z = a->z0 + SLAB;
    g->rep.furnished++;
    if (k == 3) {
        place(g, parent, M_MOTOR, a->x0 + 60, a->y0 + 60, z);
        place(g, parent, M_CRANK, a->x0 + 220, a->y0 + 260, z);
        place(g, parent, M_NUT, a->x0 + 260, a->y0 + 80, z);
        return;
    }
    const double xf[12] = {1, 0, 0, a->x0, 0, 1, 0, a->y0, 0, 0, 1, z};
    for (int i = 0; i < 4 && sets[k][i] >= 0; ++i)
        model_instance(g, parent, sets[k][i], xf);
    if (k == 1) { /* half a turn about the table's centre */
        const double *t = g->model_box[M_TABLE];
        const double cx = 0.5 * (t[0] + t[3]), cy = 0.5 * (t[1] + t[4]);
        const double rot[12] = {-1, 0, 0, a->x0 + 2 * cx, 0, -1, 0, a->y0 + 2 * cy, 0, 0, 1, z};
        model_instance(g, parent, M_CHAIR, rot);
    }
}

/* The stair prototype (room coordinates, z from the room's storey), built on first use. */
static uint32_t stair_proto(gb *g)
{
    uint32_t *p = &g->proto[SW_SG_BUILDING_N_MODELS];
    if (*p != SW_SG_NONE)
        return *p;
    *p = add_node(g, SW_SG_NODE_GROUP, SW_SG_NONE, 0, NULL, k_stair_col, "stair");
    for (int k = 0; k < STEPS; ++k) {
        const double riser[3] = {STAIR_X0 + GOING * k, STAIR_Y0, SLAB + RISE * k};
        plane(g, riser, k_y, k_z, STAIR_W, RISE, 1); /* y x z = +x; a riser faces -x */
        emit(g, *p, NULL, 0);
        const double tread[3] = {STAIR_X0 + GOING * k, STAIR_Y0, SLAB + RISE * (k + 1)};
        plane(g, tread, k_x, k_y, GOING, STAIR_W, 0);
        emit(g, *p, NULL, 0);
    }
    return *p;
}

static uint32_t floor_group(gb *g, uint32_t f)
{
    if (g->floor_node == SW_SG_NONE || g->floor_of_node != f) {
        char name[32];
        snprintf(name, sizeof name, "storey %u", f);
        g->floor_node = add_node(g, SW_SG_NODE_GROUP, 0, 0, NULL, NULL, name);
        g->floor_of_node = f;
        g->rep.floors = f + 1;
    }
    return g->floor_node;
}

static void room(gb *g, uint64_t k)
{
    const room_at a = locate(g, k);
    char name[48];
    snprintf(name, sizeof name, "room %u.%u.%u", a.f, a.iy, a.ix);
    const uint32_t rn = add_node(g, SW_SG_NODE_GROUP, floor_group(g, a.f), 0, NULL, NULL, name);
    slab_face(g, rn, &a, a.z0 + SLAB, a.stair && a.f > 0, 0, k_floor_col);
    slab_face(g, rn, &a, a.z0 + STOREY, a.stair, 1, k_ceiling_col);
    const double foot[3] = {a.x0, a.y0, a.z0 + SLAB};
    const int entrance = a.f == 0 && a.iy == 0 && a.ix == g->nx / 2;
    wall(g, rn, k, SIDE_S, a.iy == 0, entrance, foot, k_x);
    wall(g, rn, k, SIDE_W, a.ix == 0, 0, foot, k_y);
    if (a.ix == g->nx - 1) {
        const double o[3] = {a.x0 + ROOM, a.y0, a.z0 + SLAB};
        wall(g, rn, k, SIDE_E, 1, 0, o, k_y);
    }
    if (a.iy == g->ny - 1) {
        const double o[3] = {a.x0, a.y0 + ROOM, a.z0 + SLAB};
        wall(g, rn, k, SIDE_N, 1, 0, o, k_x);
    }
    column(g, rn, a.x0, a.y0, a.z0 + SLAB, COLUMN_R, CLEAR);
    if (a.ix == g->nx - 1)
        column(g, rn, a.x0 + ROOM, a.y0, a.z0 + SLAB, COLUMN_R, CLEAR);
    if (a.iy == g->ny - 1)
        column(g, rn, a.x0, a.y0 + ROOM, a.z0 + SLAB, COLUMN_R, CLEAR);
    if (a.ix == g->nx - 1 && a.iy == g->ny - 1)
        column(g, rn, a.x0 + ROOM, a.y0 + ROOM, a.z0 + SLAB, COLUMN_R, CLEAR);
    if (a.stair) {
        const uint32_t sp = stair_proto(g);
        const double xf[12] = {1, 0, 0, a.x0, 0, 1, 0, a.y0, 0, 0, 1, a.z0};
        add_node(g, SW_SG_NODE_INSTANCE, rn, sp, xf, NULL, NULL);
        g->occ += 2 * STEPS;
        g->instanced += 2 * STEPS;
        g->rep.instances++;
        g->rep.stairs++;
    }
    furnish(g, rn, &a, k);
    g->rep.rooms++;
}

/* The roof over room k: the slab's top, then a dome, a barrel vault or nothing. */
static void roof(gb *g, uint64_t k)
{
    const room_at a = locate(g, k);
    if (g->roof_node == SW_SG_NONE)
        g->roof_node = add_node(g, SW_SG_NODE_GROUP, 0, 0, NULL, k_roof_col, "roof");
    const uint32_t p = g->roof_node;
    const double zr = a.z0 + STOREY + SLAB;
    slab_face(g, p, &a, zr, a.stair, 0, NULL);
    uint64_t s = stream(g, k, SALT_ROOF);
    const uint32_t kind = a.stair ? 0 : pick(&s, 3);
    const double cx = a.x0 + 0.5 * ROOM, cy = a.y0 + 0.5 * ROOM;
    if (kind == 1) {
        const double c[3] = {cx, cy, zr};
        face_reset(g->face, SW_SG_KIND_SPHERE);
        dome_surface(g->face, c, CUPOLA_R);
        outer_rect(g->face, 4, 1);
        emit(g, p, NULL, 1);
        g->rep.domes++;
    } else if (kind == 2) {
        const double y0 = cy - CUPOLA_R, len = 2 * CUPOLA_R;
        const double c[3] = {cx, y0, zr};
        cylinder(g, c, k_x, k_z, k_y, CUPOLA_R, 2, len, 1); /* x z-plane; x x z = -y */
        emit(g, p, NULL, 1);
        for (int end = 0; end < 2; ++end) { /* semicircular gables */
            const double o[3] = {cx - CUPOLA_R, y0 + end * len, zr};
            face_reset(g->face, SW_SG_KIND_PLANE);
            plane_surface(g->face, o, k_x, k_z, 2 * CUPOLA_R, CUPOLA_R);
            loop_begin(g->face, 0, 0, SW_SG_LOOP_OUTER);
            line_to(g->face, 2 * CUPOLA_R, 0);
            arcs(g->face, CUPOLA_R, 0, CUPOLA_R, 0, 1, 2);
            loop_end(g->face);
            if (end)
                g->face->flags |= SW_SG_FACE_REVERSED; /* x x z = -y faces out at y0 only */
            emit(g, p, NULL, 1);
        }
        g->rep.vaults++;
    }
}

/* The walls a partial top storey leaves open: north of its last row, east of its last room. */
static void closure(gb *g, uint64_t k, uint64_t rooms)
{
    const room_at a = locate(g, k);
    const double z = a.z0 + SLAB;
    if (a.iy + 1 < g->ny && k + g->nx >= rooms) {
        const double o[3] = {a.x0, a.y0 + ROOM, z};
        wall(g, floor_group(g, a.f), k, SIDE_N, 1, 0, o, k_x);
    }
    if (a.ix + 1 < g->nx && k + 1 == rooms) {
        const double o[3] = {a.x0 + ROOM, a.y0, z};
        wall(g, floor_group(g, a.f), k, SIDE_E, 1, 0, o, k_y);
    }
}

static void bollards(gb *g, uint64_t n)
{
    const uint32_t p = n ? add_node(g, SW_SG_NODE_GROUP, 0, 0, NULL, k_column_col, "bollards") : 0;
    for (uint64_t i = 0; i < n; ++i) {
        const double x = 40.0 * (double)(i % 100), y = -100.0 - 40.0 * (double)(i / 100);
        column(g, p, x, y, 0.0, BOLLARD_R, BOLLARD_H);
        g->rep.columns--;
        g->rep.bollards++;
    }
}

/* ---- planning -------------------------------------------------------------------------------- */

/* Occurrences `fn` would add at the current state (a dry run on a copy). */
static uint64_t cost_of(const gb *g, void (*fn)(gb *, uint64_t, uint64_t), uint64_t k,
                        uint64_t rooms)
{
    gb t = *g;
    t.b = NULL;
    fn(&t, k, rooms);
    return t.occ - g->occ;
}

static void roof_fn(gb *g, uint64_t k, uint64_t rooms)
{
    (void)rooms;
    roof(g, k);
}

typedef struct plan {
    uint64_t rooms, total;
} plan;

/* The largest number of rooms R whose building (R rooms, the roofs over the rooms with none
 * above, k + nx*ny >= R, and the walls closing a partial storey) stays within `want` occurrences,
 * by a dry run room after room. Roof and wall costs depend on their room only (their random
 * streams are their own, and furniture, the only budgeted part, is placed with the rooms), so the
 * windows of rooms that need them slide along with R. */
static sw_result plan_rooms(gb *g, uint64_t want, plan *out, sw_status *status)
{
    const uint64_t per = (uint64_t)g->nx * g->ny;
    size_t cap = 1024;
    uint64_t *roofc = malloc(cap * sizeof *roofc), *northc = malloc(cap * sizeof *northc);
    uint64_t roof_sum = 0, north_sum = 0;
    out->rooms = out->total = 0;
    int oom = !roofc || !northc;
    for (uint64_t k = 0; !oom; ++k) {
        if (k == cap) {
            cap *= 2;
            uint64_t *a = realloc(roofc, cap * sizeof *roofc);
            roofc = a ? a : roofc;
            uint64_t *b = a ? realloc(northc, cap * sizeof *northc) : NULL;
            northc = b ? b : northc;
            if (!a || !b) {
                oom = 1;
                break;
            }
        }
        room(g, k);
        if (g->occ > want)
            break;
        const room_at a = locate(g, k);
        roofc[k] = cost_of(g, roof_fn, k, 0);
        /* closure(k, k + nx) builds k's north wall only; closure(k, k + 1) also its east one */
        northc[k] = a.iy + 1 < g->ny ? cost_of(g, closure, k, k + g->nx) : 0;
        const uint64_t east = a.ix + 1 < g->nx ? cost_of(g, closure, k, k + 1) - northc[k] : 0;
        roof_sum += roofc[k] - (k >= per ? roofc[k - per] : 0);
        north_sum += northc[k] - (k >= g->nx ? northc[k - g->nx] : 0);
        const uint64_t total = g->occ + roof_sum + north_sum + east;
        if (total <= want)
            out->rooms = k + 1, out->total = total;
        if (g->d->progress && (k & 0x3fffu) == 0)
            g->d->progress(g->d->user_data, 0.2 * (double)g->occ / (double)want, "planning");
    }
    free(roofc);
    free(northc);
    if (oom)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "building: out of memory while planning");
    return SW_OK;
}

/* Each model's occurrences and control-net box (its BVH's root, as the grid measures). */
static sw_result measure_models(gb *g, sw_status *status)
{
    for (int m = 0; m < SW_SG_BUILDING_N_MODELS; ++m) {
        sw_sg_bvh *t = NULL;
        if (!g->d->models[m])
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "building: model %s missing",
                            sw_sg_building_model_files[m]);
        sw_result r = sw_sg_bvh_build(g->d->models[m], &t, status);
        if (r != SW_OK)
            return r;
        g->model_occ[m] = t->n_items;
        if (t->n_items)
            memcpy(g->model_box[m], t->nodes[0].box, sizeof g->model_box[m]);
        sw_sg_bvh_free(t);
        if (!g->model_occ[m])
            return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "building: model %s draws no faces",
                            sw_sg_building_model_files[m]);
    }
    return SW_OK;
}

/* Storeys and rooms per storey for N: about 40 occurrences a room, a building about half as
 * many storeys as a side of its floor plan has rooms (a compact block). */
static void layout(gb *g, uint64_t n)
{
    const double rooms = fmax(1.0, (double)n / 40.0);
    const double storeys = fmax(1.0, round(cbrt(rooms / 4.0)));
    g->nx = g->ny = (uint32_t)fmax(1.0, ceil(sqrt(rooms / storeys)));
}

static void build(gb *g, const plan *pl)
{
    const uint64_t per = (uint64_t)g->nx * g->ny, n = pl->rooms;
    for (uint64_t k = 0; k < n && !g->oom; ++k) {
        room(g, k);
        if (g->d->progress && (k & 0x3ffu) == 0)
            g->d->progress(g->d->user_data, 0.2 + 0.6 * (double)k / (double)n, "rooms");
    }
    for (uint64_t k = n > per ? n - per : 0; k < n; ++k)
        roof(g, k);
    for (uint64_t k = n > g->nx ? n - g->nx : 0; k < n; ++k)
        closure(g, k, n);
    bollards(g, g->d->surfaces - g->occ);
}

sw_result sw_sg_generate_building(const sw_sg_building_desc *desc, sw_sg_scene **out,
                                  sw_sg_building_report *report, sw_status *status)
{
    *out = NULL;
    if (desc->surfaces < SW_SG_BUILDING_MIN_SURFACES ||
        desc->surfaces > SW_SG_BUILDING_MAX_SURFACES)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "building: %llu surfaces outside %u..%u",
                        (unsigned long long)desc->surfaces, (unsigned)SW_SG_BUILDING_MIN_SURFACES,
                        (unsigned)SW_SG_BUILDING_MAX_SURFACES);
    if (!desc->models)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "building: no furniture models");
    gb g;
    memset(&g, 0, sizeof g);
    g.d = desc;
    g.floor_node = g.roof_node = SW_SG_NONE;
    for (int m = 0; m <= SW_SG_BUILDING_N_MODELS; ++m)
        g.proto[m] = SW_SG_NONE;
    sw_result r = measure_models(&g, status);
    if (r != SW_OK)
        return r;
    layout(&g, desc->surfaces);
    g.face = malloc(sizeof *g.face);
    gb dry = g;
    plan pl = {0, 0};
    r = g.face ? plan_rooms(&dry, desc->surfaces, &pl, status)
               : sw__fail(status, SW_ERR_OUT_OF_MEMORY, "building: out of memory");
    if (r == SW_OK && pl.rooms == 0)
        r = sw__fail(status, SW_ERR_INVALID_ARGUMENT, "building: %llu surfaces hold no room",
                     (unsigned long long)desc->surfaces);
    if (r == SW_OK) {
        g.b = sw_sg_builder_create();
        g.n_nodes = 1; /* the builder's root */
        g.oom = !g.b;
        if (g.b)
            build(&g, &pl);
        if (!g.oom && g.occ != desc->surfaces)
            r = sw__fail(status, SW_ERR_INTERNAL, "building: %llu occurrences built, %llu planned",
                         (unsigned long long)g.occ, (unsigned long long)desc->surfaces);
        else if (g.oom)
            r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "building: out of memory");
    }
    free(g.face);
    if (r != SW_OK) {
        sw_sg_builder_free(g.b);
        return r;
    }
    if (desc->progress)
        desc->progress(desc->user_data, 0.8, "validating");
    r = sw_sg_builder_finish(g.b, out, status);
    if (desc->progress)
        desc->progress(desc->user_data, 1.0, "done");
    g.rep.nx = g.nx, g.rep.ny = g.ny;
    g.rep.occurrences = g.occ, g.rep.unique_faces = g.unique;
    if (r == SW_OK && report)
        *report = g.rep;
    return r;
}
