/* SPDX-License-Identifier: MIT */
/* The vehicle generator (sw_sg_generate.h): a parking lot of cars, in millimetres, z up, each car
 * along +x from its rear. Every car is unique (its length, width, height and trims come from its
 * own random stream): per side a lower body surface, a bicubic B-spline lofted through four cubic
 * section curves (its control rows), cut into four panels — rear quarter, rear door, front door,
 * front fender — by door gaps, the quarter and the fender trimmed by their wheel arches (exact
 * semicircles in 3D: the surface's x and z are linear in u and v, control points at the Greville
 * abscissae, so a circle in (x, z) is an exact rational ellipse in (u, v)); a cabin side trimmed
 * by its window holes (rounded rectangles); a roof (with a sunroof hole on some cars), a
 * windscreen, a rear window, a bonnet, a boot lid and two bumpers (with an intake or a number
 * plate recess as a hole). Parts are instances: four wheels of one prototype (tyre and hub exact
 * rational cylinders, a disc trimmed by circles) on every car, and under some bonnets OCCT's
 * Motor-c, CrankArm and Pump_Nut — while the occurrences drawn through instances stay within 3x
 * the unique faces. Parking bollards make up the exact count.
 */
#include "generate_common.h"
#include "sw_hooks.h"

#include "sw_status_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *const sw_sg_vehicle_model_files[SW_SG_VEHICLE_N_MODELS] = {
    "occ/Motor-c.brep", "occ/CrankArm.brep", "occ/Pump_Nut.brep"};
enum { V_MOTOR, V_CRANK, V_NUT, V_WHEEL = SW_SG_VEHICLE_N_MODELS };

#define SILL_Z 320.0  /* wheel centres and the lower body's bottom edge */
#define BELT_Z 1000.0 /* the lower body's top edge, the cabin's bottom */
#define WHEEL_R 320.0
#define ARCH_R 380.0
#define TYRE_W 200.0
#define HUB_R 60.0
#define GAP 4.0 /* door gaps */
#define LOT_DY 2600.0
#define LOT_DX 6500.0
#define LOT_ROW 20
#define PARTS_RATIO 3

static const float k_body_col[4][4] = {{0.60f, 0.05f, 0.05f, 1},
                                       {0.10f, 0.20f, 0.50f, 1},
                                       {0.75f, 0.75f, 0.78f, 1},
                                       {0.10f, 0.35f, 0.15f, 1}};
static const float k_glass_col[4] = {0.15f, 0.20f, 0.25f, 1},
                   k_tyre_col[4] = {0.05f, 0.05f, 0.05f, 1};
static const float k_part_col[4] = {0.45f, 0.45f, 0.48f, 1};

typedef struct car {
    double l, w, h;         /* length, width, roof height */
    double x_rear, x_front; /* wheel centres */
    int sunroof, reversed_yaw, colour;
} car;

typedef struct gveh {
    sw__gen c;
    const sw_sg_vehicle_desc *d;
    uint32_t bollard_node;
    sw_sg_vehicle_report rep;
} gveh;

static uint64_t stream(const gveh *g, uint64_t k, uint64_t salt)
{
    return sw__gen_mix64(g->d->seed ^ sw__gen_mix64(k * 8 + salt + 1));
}

/* ---- lofted bicubic surfaces ----------------------------------------------------------------- */

/* A clamped uniform cubic knot vector on [0, 1] and the Greville abscissae of its n poles, where a
 * B-spline reproduces linear functions: poles at (i, greville) give x(u) = u exactly. */
static void cubic_knots(int n, double *k, double *greville)
{
    const int m = n + 4, spans = n - 3;
    for (int i = 0; i < m; ++i)
        k[i] = i < 4 ? 0.0 : i >= n ? 1.0 : (double)(i - 3) / spans;
    for (int i = 0; i < n; ++i)
        greville[i] = (k[i + 1] + k[i + 2] + k[i + 3]) / 3.0;
}

typedef void (*pole_fn)(const void *ctx, double gu, double gw, double p[3]);

/* A non-rational bicubic surface lofted through n_v cubic sections (its pole rows), each pole
 * placed by fn at the Greville abscissae (gu, gv). */
static void lofted_surface(sw__gen_face *f, int n_u, int n_v, pole_fn fn, const void *ctx)
{
    double gu[SW__GEN_MAX_NU], gw[SW__GEN_MAX_NV];
    f->deg_u = f->deg_v = 3;
    f->n_u = n_u, f->n_v = n_v;
    cubic_knots(n_u, f->ku, gu);
    cubic_knots(n_v, f->kv, gw);
    for (int j = 0; j < n_v; ++j)
        for (int i = 0; i < n_u; ++i) {
            double *q = f->cpw + ((size_t)j * n_u + i) * 4;
            fn(ctx, gu[i], gw[j], q);
            q[3] = 1.0;
        }
}

typedef struct side_ctx {
    const car *c;
    double s; /* +1: the side at +y, -1: its mirror */
} side_ctx;

/* Lower body: x = l u, z linear in v; the side bulges out at a third of its height and draws in
 * at both ends. */
static void lower_pole(const void *ctx, double gu, double gw, double p[3])
{
    const side_ctx *sc = ctx;
    const double e = 2.0 * gu - 1.0;
    p[0] = sc->c->l * gu;
    p[1] = sc->s * (0.5 * sc->c->w - 60.0 * (gw - 0.35) * (gw - 0.35) - 90.0 * e * e * e * e);
    p[2] = SILL_Z + (BELT_Z - SILL_Z) * gw;
}

/* Cabin side: from the belt to the roof, drawn in (tumblehome) and shorter at the top (the
 * raked pillars). */
static void cabin_pole(const void *ctx, double gu, double gw, double p[3])
{
    const side_ctx *sc = ctx;
    const double l = sc->c->l;
    const double x0 = 0.26 * l + gw * 0.06 * l, x1 = 0.74 * l - gw * 0.08 * l;
    p[0] = x0 + (x1 - x0) * gu;
    p[1] = sc->s * (0.5 * sc->c->w - 50.0 - 140.0 * gw * gw);
    p[2] = BELT_Z + (sc->c->h - BELT_Z) * gw;
}

/* The roof, windscreen, rear window, bonnet, boot lid and bumpers: patches over an x range and
 * the car's width, z from a profile with a crown across. */
typedef struct top_ctx {
    const car *c;
    double x0, x1, z0, z1, half_w, crown;
    int across_x; /* the patch's u runs across the car (y), v along x */
} top_ctx;

static void top_pole(const void *ctx, double gu, double gw, double p[3])
{
    const top_ctx *t = ctx;
    const double a = t->across_x ? gw : gu, b = t->across_x ? gu : gw; /* a along x, b across */
    const double e = 2.0 * b - 1.0;
    p[0] = t->x0 + (t->x1 - t->x0) * a;
    p[1] = t->half_w * e;
    p[2] = t->z0 + (t->z1 - t->z0) * a + t->crown * (1.0 - e * e);
}

/* A clockwise rounded rectangle hole, corner radii (ru, rv) in parameters (quarter ellipses). */
static void hole_rounded(sw__gen_face *f, double u0, double v0, double u1, double v1, double ru,
                         double rv)
{
    if (f->n_loops >= SW__GEN_MAX_LOOPS)
        return;
    sw__gen_loop_begin(f, u0, v0 + rv, 0);
    sw__gen_line_to(f, u0, v1 - rv);
    sw__gen_ellipse_arcs(f, u0 + ru, v1 - rv, ru, rv, 2, -1, 1);
    sw__gen_line_to(f, u1 - ru, v1);
    sw__gen_ellipse_arcs(f, u1 - ru, v1 - rv, ru, rv, 1, -1, 1);
    sw__gen_line_to(f, u1, v0 + rv);
    sw__gen_ellipse_arcs(f, u1 - ru, v0 + rv, ru, rv, 0, -1, 1);
    sw__gen_line_to(f, u0 + ru, v0);
    sw__gen_ellipse_arcs(f, u0 + ru, v0 + rv, ru, rv, 3, -1, 1);
    sw__gen_loop_end(f);
}

/* ---- one car --------------------------------------------------------------------------------- */

static car plan_car(const gveh *g, uint64_t k)
{
    uint64_t s = stream(g, k, 0);
    car c;
    c.l = 4200.0 + 100.0 * sw__gen_pick(&s, 8);
    c.w = 1750.0 + 50.0 * sw__gen_pick(&s, 4);
    c.h = 1400.0 + 50.0 * sw__gen_pick(&s, 4);
    c.x_rear = 0.2 * c.l, c.x_front = 0.83 * c.l;
    c.sunroof = (int)sw__gen_pick(&s, 2);
    c.reversed_yaw = (int)sw__gen_pick(&s, 2);
    c.colour = (int)sw__gen_pick(&s, 4);
    return c;
}

/* One lower panel over u in [ua, ub], with the wheel arch centred at x = xc when xc > 0. */
static void lower_panel(gveh *g, uint32_t parent, const car *c, const side_ctx *sc, double ua,
                        double ub, double xc, const float col[4])
{
    sw__gen_face *f = g->c.face;
    sw__gen_face_reset(f, SW_SG_KIND_BSPLINE);
    lofted_surface(f, 7, 4, lower_pole, sc);
    sw__gen_loop_begin(f, ua, 0.0, SW_SG_LOOP_OUTER);
    if (xc > 0.0) {
        const double ru = ARCH_R / c->l, rv = ARCH_R / (BELT_Z - SILL_Z);
        sw__gen_line_to(f, (xc - ARCH_R) / c->l, 0.0);
        sw__gen_ellipse_arcs(f, xc / c->l, 0.0, ru, rv, 2, -1, 2);
        g->rep.arches++;
    }
    sw__gen_line_to(f, ub, 0.0);
    sw__gen_line_to(f, ub, 1.0);
    sw__gen_line_to(f, ua, 1.0);
    sw__gen_loop_end(f);
    f->flags |= SW_SG_FACE_TRIMMED;
    if (sc->s > 0) /* Su x Sv = x x z = -y: outward on the -y side only */
        f->flags |= SW_SG_FACE_REVERSED;
    sw__gen_emit(&g->c, parent, col, 1);
    g->rep.panels++;
}

static void body_side(gveh *g, uint32_t parent, const car *c, double s, const float col[4])
{
    const side_ctx sc = {c, s};
    const double cut[5] = {0.0, 0.36, 0.55, 0.73, 1.0}, h = 0.5 * GAP / c->l;
    for (int p = 0; p < 4; ++p) {
        const double ua = p ? cut[p] + h : 0.0, ub = p < 3 ? cut[p + 1] - h : 1.0;
        lower_panel(g, parent, c, &sc, ua, ub, p == 0 ? c->x_rear : p == 3 ? c->x_front : 0.0, col);
    }
    g->rep.gaps += 3;
    sw__gen_face *f = g->c.face;
    sw__gen_face_reset(f, SW_SG_KIND_BSPLINE);
    lofted_surface(f, 4, 4, cabin_pole, &sc);
    sw__gen_outer_rect(f, 1.0, 1.0);
    hole_rounded(f, 0.06, 0.12, 0.47, 0.86, 0.04, 0.1);
    hole_rounded(f, 0.53, 0.12, 0.93, 0.86, 0.04, 0.1);
    g->rep.windows += 2;
    if (s > 0)
        f->flags |= SW_SG_FACE_REVERSED;
    sw__gen_emit(&g->c, parent, col, 1);
}

static void top_patch(gveh *g, uint32_t parent, const top_ctx *t, int hole, const float col[4])
{
    sw__gen_face *f = g->c.face;
    sw__gen_face_reset(f, SW_SG_KIND_BSPLINE);
    lofted_surface(f, 4, 4, top_pole, t);
    sw__gen_outer_rect(f, 1.0, 1.0);
    if (hole == 1)
        hole_rounded(f, 0.25, 0.2, 0.75, 0.7, 0.05, 0.05);
    else if (hole == 2)
        sw__gen_hole_rect(f, 0.3, 0.35, 0.7, 0.65);
    sw__gen_emit(&g->c, parent, col, 1);
    g->rep.panels++;
}

static void tops(gveh *g, uint32_t parent, const car *c, const float col[4])
{
    const double l = c->l, hw = 0.5 * c->w - 190.0;
    const top_ctx roof = {c, 0.32 * l, 0.66 * l, c->h, c->h, hw, 40.0, 0};
    top_patch(g, parent, &roof, c->sunroof, col);
    g->rep.windows += (uint32_t)c->sunroof;
    const top_ctx screen = {c, 0.66 * l, 0.74 * l, c->h, BELT_Z, hw + 60.0, 25.0, 0};
    top_patch(g, parent, &screen, 0, k_glass_col);
    const top_ctx rear = {c, 0.26 * l, 0.32 * l, BELT_Z, c->h, hw + 60.0, 25.0, 0};
    top_patch(g, parent, &rear, 0, k_glass_col);
    const top_ctx bonnet = {c, 0.74 * l, l, BELT_Z, BELT_Z - 120.0, 0.5 * c->w - 40.0, 30.0, 0};
    top_patch(g, parent, &bonnet, 0, col);
    const top_ctx boot = {c, 0.0, 0.26 * l, BELT_Z - 60.0, BELT_Z, 0.5 * c->w - 40.0, 30.0, 0};
    top_patch(g, parent, &boot, 0, col);
    /* bumpers: u across the car, v up, bowed out along x */
    const top_ctx front = {c, l, l + 60.0, 150.0, SILL_Z + 200.0, 0.5 * c->w - 20.0, 0.0, 1};
    top_patch(g, parent, &front, 2, k_tyre_col);
    const top_ctx back = {c, -60.0, 0.0, SILL_Z + 200.0, 150.0, 0.5 * c->w - 20.0, 0.0, 1};
    top_patch(g, parent, &back, 2, k_tyre_col);
}

/* The wheel prototype, axis y, centred at the origin: tyre, outer disc with the hub bore, hub. */
static uint32_t wheel_proto(gveh *g)
{
    uint32_t *p = &g->c.proto[V_WHEEL];
    if (*p != SW_SG_NONE)
        return *p;
    *p = sw__gen_node(&g->c, SW_SG_NODE_GROUP, SW_SG_NONE, 0, NULL, k_tyre_col, "wheel");
    const double tyre[3] = {0, -0.5 * TYRE_W, 0};
    sw__gen_cylinder(&g->c, tyre, sw__gen_x, sw__gen_z, sw__gen_y, WHEEL_R, 4, TYRE_W, 1);
    sw__gen_emit(&g->c, *p, NULL, 0); /* x x z = -y: the axis; reversed to face out */
    const double o[3] = {-WHEEL_R, 0.5 * TYRE_W, -WHEEL_R};
    sw__gen_face *f = g->c.face;
    sw__gen_face_reset(f, SW_SG_KIND_PLANE);
    sw__gen_plane_surface(f, o, sw__gen_x, sw__gen_z, 2 * WHEEL_R, 2 * WHEEL_R);
    sw__gen_loop_begin(f, 2 * WHEEL_R, WHEEL_R, SW_SG_LOOP_OUTER);
    sw__gen_arcs(f, WHEEL_R, WHEEL_R, WHEEL_R, 0, 1, 4);
    sw__gen_loop_end(f);
    sw__gen_loop_begin(f, WHEEL_R + HUB_R, WHEEL_R, 0);
    sw__gen_arcs(f, WHEEL_R, WHEEL_R, HUB_R, 0, -1, 4);
    sw__gen_loop_end(f);
    f->flags |= SW_SG_FACE_TRIMMED | SW_SG_FACE_REVERSED; /* x x z = -y; the disc faces +y */
    sw__gen_emit(&g->c, *p, NULL, 0);
    const double hub[3] = {0, 0.5 * TYRE_W, 0};
    sw__gen_cylinder(&g->c, hub, sw__gen_x, sw__gen_z, sw__gen_y, HUB_R, 4, 40.0, 1);
    sw__gen_emit(&g->c, *p, NULL, 0);
    return *p;
}

static void wheels(gveh *g, uint32_t parent, const car *c)
{
    const uint32_t w = wheel_proto(g);
    const double xs[2] = {c->x_rear, c->x_front}, y = 0.5 * c->w - 0.5 * TYRE_W - 20.0;
    for (int i = 0; i < 4; ++i) {
        const double s = (i & 1) ? -1.0 : 1.0; /* the -y wheels turned half a turn */
        const double xf[12] = {s, 0, 0, xs[i >> 1], 0, s, 0, s * y, 0, 0, 1, WHEEL_R};
        sw__gen_node(&g->c, SW_SG_NODE_INSTANCE, parent, w, xf, NULL, NULL);
        g->c.occ += 3, g->c.instanced += 3, g->c.instances++;
    }
}

/* The engine parts under the bonnet, each placed by its box's minimum corner. */
static void engine(gveh *g, uint32_t parent, const car *c)
{
    const int parts[3] = {V_MOTOR, V_CRANK, V_NUT};
    uint64_t cost = 0;
    for (int i = 0; i < 3; ++i)
        cost += g->c.model_occ[parts[i]];
    if (g->c.instanced + cost > PARTS_RATIO * g->c.unique)
        return;
    const double at[3][3] = {{0.8 * c->l, -150.0, 450.0},
                             {0.8 * c->l + 250.0, 150.0, 450.0},
                             {0.8 * c->l + 300.0, -250.0, 450.0}};
    for (int i = 0; i < 3; ++i) {
        const double *b = g->c.model_box[parts[i]];
        const double xf[12] = {1, 0, 0, at[i][0] - b[0], 0, 1, 0, at[i][1] - b[1],
                               0, 0, 1, at[i][2] - b[2]};
        sw__gen_instance(&g->c, parent, parts[i], xf, k_part_col);
    }
    g->rep.with_engine++;
}

static void vehicle(gveh *g, uint64_t k)
{
    const car c = plan_car(g, k);
    const double ox = (double)(k / LOT_ROW) * LOT_DX, oy = (double)(k % LOT_ROW) * LOT_DY;
    const double s = c.reversed_yaw ? -1.0 : 1.0; /* half a turn about the car's centre */
    const double xf[12] = {s, 0, 0, ox + (s < 0 ? c.l : 0.0), 0, s, 0, oy, 0, 0, 1, 0};
    char name[32];
    snprintf(name, sizeof name, "car %llu", (unsigned long long)k);
    const uint32_t n = sw__gen_node(&g->c, SW_SG_NODE_TRANSFORM, 0, 0, xf, NULL, name);
    const float *col = k_body_col[c.colour];
    body_side(g, n, &c, 1.0, col);
    body_side(g, n, &c, -1.0, col);
    tops(g, n, &c, col);
    wheels(g, n, &c);
    engine(g, n, &c);
    g->rep.vehicles++;
}

static void bollards(gveh *g, uint64_t n, uint64_t cars)
{
    const uint32_t p =
        n ? sw__gen_node(&g->c, SW_SG_NODE_GROUP, 0, 0, NULL, k_part_col, "bollards") : 0;
    const double x0 = (double)((cars + LOT_ROW - 1) / LOT_ROW) * LOT_DX;
    for (uint64_t i = 0; i < n; ++i) {
        const double c[3] = {x0 + 400.0 * (double)(i / 100), 300.0 * (double)(i % 100), 0.0};
        sw__gen_cylinder(&g->c, c, sw__gen_x, sw__gen_y, sw__gen_z, 80.0, 4, 900.0, 0);
        sw__gen_emit(&g->c, p, NULL, 1);
        g->rep.bollards++;
    }
}

/* Occurrences vehicle k would add (a dry run on a copy). */
static uint64_t cost_of(const gveh *g, uint64_t k)
{
    gveh t = *g;
    t.c.b = NULL;
    vehicle(&t, k);
    return t.c.occ - g->c.occ;
}

sw_result sw_sg_generate_vehicle(const sw_sg_vehicle_desc *desc, sw_sg_scene **out,
                                 sw_sg_vehicle_report *report, sw_status *status)
{
    *out = NULL;
    sw_result checked = sw__gen_check_request("vehicle", desc->surfaces, desc->models, status);
    if (checked != SW_OK)
        return checked;
    gveh g;
    memset(&g, 0, sizeof g);
    g.d = desc;
    g.c.models = desc->models;
    g.c.n_models = SW_SG_VEHICLE_N_MODELS;
    for (int m = 0; m < SW__GEN_MAX_MODELS + 2; ++m)
        g.c.proto[m] = SW_SG_NONE;
    sw_result r = sw__gen_measure(&g.c, sw_sg_vehicle_model_files, status);
    if (r != SW_OK)
        return r;
    g.c.face = sw__malloc(sizeof *g.c.face);
    g.c.b = g.c.face ? sw_sg_builder_create() : NULL;
    if (!g.c.b) {
        sw__free(g.c.face);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "vehicle: out of memory");
    }
    g.c.n_nodes = 1; /* the builder's root */
    uint64_t k = 0;
    /* cars while the next one fits; the cost of a car depends on the state (the parts budget) */
    for (; !g.c.oom && g.c.occ + cost_of(&g, k) <= desc->surfaces; ++k) {
        vehicle(&g, k);
        if (desc->progress && (k & 0x3ffu) == 0)
            desc->progress(desc->user_data, 0.8 * (double)g.c.occ / (double)desc->surfaces, "cars");
    }
    bollards(&g, desc->surfaces - g.c.occ, k);
    sw__free(g.c.face);
    if (g.c.oom) {
        sw_sg_builder_free(g.c.b);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "vehicle: out of memory");
    }
    if (desc->progress)
        desc->progress(desc->user_data, 0.8, "validating");
    r = sw_sg_builder_finish(g.c.b, out, status);
    if (desc->progress)
        desc->progress(desc->user_data, 1.0, "done");
    g.rep.occurrences = g.c.occ, g.rep.unique_faces = g.c.unique, g.rep.instances = g.c.instances;
    if (r == SW_OK && report)
        *report = g.rep;
    return r;
}
