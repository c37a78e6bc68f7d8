/* SPDX-License-Identifier: MIT */
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
 * Faces and loops are built with generate_common.c (OCCT's loop conventions, exact circles).
 *
 * The count is met exactly: a dry run (the same code, counting only) finds the largest number of
 * rooms whose scene stays within N face occurrences, the remainder is filled with bollards (small
 * columns) in front of the building. Furniture is placed only while the occurrences drawn through
 * instances stay within 3x the unique faces, so about a quarter of the faces are unique (the
 * stairs, instanced outside that budget, are 32 occurrences a storey).
 * Randomness comes from a hash of (seed, room, wall), never from the order of the calls.
 */
#include "generate_common.h"
#include "sw_hooks.h"

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

enum { SIDE_S, SIDE_W, SIDE_E, SIDE_N, SALT_ROOM = 7, SALT_ROOF = 9 };

static const float k_wall_col[4] = {0.80f, 0.74f, 0.62f, 1},
                   k_floor_col[4] = {0.45f, 0.33f, 0.22f, 1};
static const float k_ceiling_col[4] = {0.92f, 0.92f, 0.90f, 1},
                   k_column_col[4] = {0.70f, 0.70f, 0.75f, 1};
static const float k_roof_col[4] = {0.60f, 0.28f, 0.22f, 1},
                   k_stair_col[4] = {0.55f, 0.50f, 0.45f, 1};
static const float k_reveal_col[4] = {0.65f, 0.60f, 0.52f, 1},
                   k_fur_col[4] = {0.30f, 0.45f, 0.65f, 1};

/* ---- the generator's state ------------------------------------------------------------------- */

typedef struct gb {
    sw__gen c; /* proto[SW_SG_BUILDING_N_MODELS]: the stair */
    const sw_sg_building_desc *d;
    uint32_t nx, ny;
    uint32_t floor_node, floor_of_node, roof_node;
    sw_sg_building_report rep;
} gb;

/* The random stream of one (room, salt): independent of the order rooms are built in. */
static uint64_t stream(const gb *g, uint64_t room, uint64_t salt)
{
    return sw__gen_mix64(g->d->seed ^ sw__gen_mix64(room * 16 + salt + 1));
}

static void column(gb *g, uint32_t parent, double x, double y, double z0, double r, double h)
{
    const double c[3] = {x, y, z0};
    sw__gen_cylinder(&g->c, c, sw__gen_x, sw__gen_y, sw__gen_z, r, 4, h, 0);
    sw__gen_emit(&g->c, parent, k_column_col, 1);
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
    w.door = entrance || (!exterior && sw__gen_pick(&s, 2));
    w.door_arched = (int)sw__gen_pick(&s, 2);
    const double centre = 140.0 + 20.0 * sw__gen_pick(&s, 7);
    w.door_u0 = centre - 50.0, w.door_u1 = centre + 50.0;
    if (exterior && !entrance) {
        w.n_win = 1 + (int)sw__gen_pick(&s, 3);
        w.win_w = 60.0 + 20.0 * sw__gen_pick(&s, w.n_win == 3 ? 2 : 3);
        w.win_h = 120.0 + 10.0 * sw__gen_pick(&s, 4);
        for (int i = 0; i < w.n_win; ++i)
            w.win_arched[i] = (int)sw__gen_pick(&s, 2);
    }
    return w;
}

/* The wall's trim in its (u along, v up) parameters: a door as a notch of the outer loop,
 * windows as holes. */
static void wall_trim(sw__gen_face *f, const wall_plan *w)
{
    sw__gen_loop_begin(f, 0, 0, SW_SG_LOOP_OUTER);
    if (w->door) {
        sw__gen_line_to(f, w->door_u0, 0);
        const double r = 0.5 * (w->door_u1 - w->door_u0);
        if (w->door_arched) {
            sw__gen_line_to(f, w->door_u0, DOOR_H - r);
            sw__gen_arcs(f, w->door_u0 + r, DOOR_H - r, r, 2, -1, 2);
        } else {
            sw__gen_line_to(f, w->door_u0, DOOR_H);
            sw__gen_line_to(f, w->door_u1, DOOR_H);
        }
        sw__gen_line_to(f, w->door_u1, 0);
    }
    sw__gen_line_to(f, ROOM, 0);
    sw__gen_line_to(f, ROOM, CLEAR);
    sw__gen_line_to(f, 0, CLEAR);
    sw__gen_loop_end(f);
    for (int i = 0; i < w->n_win; ++i) {
        const double c = floor(ROOM * (i + 1) / (w->n_win + 1));
        const double u0 = c - 0.5 * w->win_w, u1 = c + 0.5 * w->win_w;
        if (w->win_arched[i])
            sw__gen_hole_arched(f, u0, SILL, u1, SILL + w->win_h - 0.5 * w->win_w);
        else
            sw__gen_hole_rect(f, u0, SILL, u1, SILL + w->win_h);
    }
}

/* The door's reveals across the wall: jambs facing the opening, a lintel or a soffit. */
static void door_reveals(gb *g, uint32_t parent, const wall_plan *w, const double o[3],
                         const double e[3], const double n[3])
{
    const double r = 0.5 * (w->door_u1 - w->door_u0);
    const double jamb = w->door_arched ? DOOR_H - r : DOOR_H;
    double p[3], back[3];
    sw__gen_v3(back, o, -0.5 * WALL, n, 0.0, n);
    sw__gen_v3(p, back, w->door_u0, e, 0.0, e);
    sw__gen_plane(&g->c, p, n, sw__gen_z, WALL, jamb, 1); /* n x z = -e: the left jamb faces +e */
    sw__gen_emit(&g->c, parent, k_reveal_col, 1);
    sw__gen_v3(p, back, w->door_u1, e, 0.0, e);
    sw__gen_plane(&g->c, p, n, sw__gen_z, WALL, jamb, 0);
    sw__gen_emit(&g->c, parent, k_reveal_col, 1);
    if (w->door_arched) {
        sw__gen_v3(p, back, w->door_u0 + r, e, jamb, sw__gen_z);
        sw__gen_cylinder(&g->c, p, e, sw__gen_z, n, r, 2, WALL,
                         1); /* inward, towards the opening */
        g->rep.arches++;
    } else {
        sw__gen_v3(p, back, w->door_u0, e, DOOR_H, sw__gen_z);
        sw__gen_plane(&g->c, p, e, n, 2.0 * r, WALL, 0); /* e x n = -z: faces down */
    }
    sw__gen_emit(&g->c, parent, k_reveal_col, 1);
}

/* A wall of one room side from `o` (its foot, on the axis) along `e`: two faces WALL apart. */
static void wall(gb *g, uint32_t parent, uint64_t room, int side, int exterior, int entrance,
                 const double o[3], const double e[3])
{
    const wall_plan w = plan_wall(g, room, side, exterior, entrance);
    double n[3], p[3];
    sw__gen_cross(e, sw__gen_z, n);
    for (int s = 0; s < 2; ++s) {
        sw__gen_face_reset(g->c.face, SW_SG_KIND_PLANE);
        sw__gen_v3(p, o, s ? -0.5 * WALL : 0.5 * WALL, n, 0.0, n);
        sw__gen_plane_surface(g->c.face, p, e, sw__gen_z, ROOM, CLEAR);
        wall_trim(g->c.face, &w);
        if (s)
            g->c.face->flags |= SW_SG_FACE_REVERSED;
        sw__gen_emit(&g->c, parent, k_wall_col, 1);
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
    sw__gen_plane(&g->c, o, sw__gen_x, sw__gen_y, ROOM, ROOM, down);
    if (hole)
        sw__gen_hole_rect(g->c.face, STAIR_X0, STAIR_Y0, STAIR_X0 + STEPS * GOING,
                          STAIR_Y0 + STAIR_W);
    sw__gen_emit(&g->c, parent, col, 1);
}

/* A model with its box's minimum corner at (x, y, z). */
static void place(gb *g, uint32_t parent, int m, double x, double y, double z)
{
    const double *b = g->c.model_box[m];
    const double xf[12] = {1, 0, 0, x - b[0], 0, 1, 0, y - b[1], 0, 0, 1, z - b[2]};
    sw__gen_instance(&g->c, parent, m, xf, k_fur_col);
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
    const int k = (int)sw__gen_pick(&s, 5);
    uint64_t cost = k == 1 ? g->c.model_occ[M_CHAIR] : 0;
    for (int i = 0; i < 4; ++i)
        cost += sets[k][i] >= 0 ? g->c.model_occ[sets[k][i]] : 0;
    if (a->stair || g->c.instanced + cost > FURNITURE_RATIO * g->c.unique)
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
        sw__gen_instance(&g->c, parent, sets[k][i], xf, k_fur_col);
    if (k == 1) { /* half a turn about the table's centre */
        const double *t = g->c.model_box[M_TABLE];
        const double cx = 0.5 * (t[0] + t[3]), cy = 0.5 * (t[1] + t[4]);
        const double rot[12] = {-1, 0, 0, a->x0 + 2 * cx, 0, -1, 0, a->y0 + 2 * cy, 0, 0, 1, z};
        sw__gen_instance(&g->c, parent, M_CHAIR, rot, k_fur_col);
    }
}

/* The stair prototype (room coordinates, z from the room's storey), built on first use. */
static uint32_t stair_proto(gb *g)
{
    uint32_t *p = &g->c.proto[SW_SG_BUILDING_N_MODELS];
    if (*p != SW_SG_NONE)
        return *p;
    *p = sw__gen_node(&g->c, SW_SG_NODE_GROUP, SW_SG_NONE, 0, NULL, k_stair_col, "stair");
    for (int k = 0; k < STEPS; ++k) {
        const double riser[3] = {STAIR_X0 + GOING * k, STAIR_Y0, SLAB + RISE * k};
        sw__gen_plane(&g->c, riser, sw__gen_y, sw__gen_z, STAIR_W, RISE,
                      1); /* y x z = +x; a riser faces -x */
        sw__gen_emit(&g->c, *p, NULL, 0);
        const double tread[3] = {STAIR_X0 + GOING * k, STAIR_Y0, SLAB + RISE * (k + 1)};
        sw__gen_plane(&g->c, tread, sw__gen_x, sw__gen_y, GOING, STAIR_W, 0);
        sw__gen_emit(&g->c, *p, NULL, 0);
    }
    return *p;
}

static uint32_t floor_group(gb *g, uint32_t f)
{
    if (g->floor_node == SW_SG_NONE || g->floor_of_node != f) {
        char name[32];
        snprintf(name, sizeof name, "storey %u", f);
        g->floor_node = sw__gen_node(&g->c, SW_SG_NODE_GROUP, 0, 0, NULL, NULL, name);
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
    const uint32_t rn =
        sw__gen_node(&g->c, SW_SG_NODE_GROUP, floor_group(g, a.f), 0, NULL, NULL, name);
    slab_face(g, rn, &a, a.z0 + SLAB, a.stair && a.f > 0, 0, k_floor_col);
    slab_face(g, rn, &a, a.z0 + STOREY, a.stair, 1, k_ceiling_col);
    const double foot[3] = {a.x0, a.y0, a.z0 + SLAB};
    const int entrance = a.f == 0 && a.iy == 0 && a.ix == g->nx / 2;
    wall(g, rn, k, SIDE_S, a.iy == 0, entrance, foot, sw__gen_x);
    wall(g, rn, k, SIDE_W, a.ix == 0, 0, foot, sw__gen_y);
    if (a.ix == g->nx - 1) {
        const double o[3] = {a.x0 + ROOM, a.y0, a.z0 + SLAB};
        wall(g, rn, k, SIDE_E, 1, 0, o, sw__gen_y);
    }
    if (a.iy == g->ny - 1) {
        const double o[3] = {a.x0, a.y0 + ROOM, a.z0 + SLAB};
        wall(g, rn, k, SIDE_N, 1, 0, o, sw__gen_x);
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
        sw__gen_node(&g->c, SW_SG_NODE_INSTANCE, rn, sp, xf, NULL, NULL);
        g->c.occ += 2 * STEPS;
        g->c.instanced += 2 * STEPS;
        g->c.instances++;
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
        g->roof_node = sw__gen_node(&g->c, SW_SG_NODE_GROUP, 0, 0, NULL, k_roof_col, "roof");
    const uint32_t p = g->roof_node;
    const double zr = a.z0 + STOREY + SLAB;
    slab_face(g, p, &a, zr, a.stair, 0, NULL);
    uint64_t s = stream(g, k, SALT_ROOF);
    const uint32_t kind = a.stair ? 0 : sw__gen_pick(&s, 3);
    const double cx = a.x0 + 0.5 * ROOM, cy = a.y0 + 0.5 * ROOM;
    if (kind == 1) {
        const double c[3] = {cx, cy, zr};
        sw__gen_face_reset(g->c.face, SW_SG_KIND_SPHERE);
        sw__gen_dome_surface(g->c.face, c, CUPOLA_R);
        sw__gen_outer_rect(g->c.face, 4, 1);
        sw__gen_emit(&g->c, p, NULL, 1);
        g->rep.domes++;
    } else if (kind == 2) {
        const double y0 = cy - CUPOLA_R, len = 2 * CUPOLA_R;
        const double c[3] = {cx, y0, zr};
        sw__gen_cylinder(&g->c, c, sw__gen_x, sw__gen_z, sw__gen_y, CUPOLA_R, 2, len,
                         1); /* x z-plane; x x z = -y */
        sw__gen_emit(&g->c, p, NULL, 1);
        for (int end = 0; end < 2; ++end) { /* semicircular gables */
            const double o[3] = {cx - CUPOLA_R, y0 + end * len, zr};
            sw__gen_face_reset(g->c.face, SW_SG_KIND_PLANE);
            sw__gen_plane_surface(g->c.face, o, sw__gen_x, sw__gen_z, 2 * CUPOLA_R, CUPOLA_R);
            sw__gen_loop_begin(g->c.face, 0, 0, SW_SG_LOOP_OUTER);
            sw__gen_line_to(g->c.face, 2 * CUPOLA_R, 0);
            sw__gen_arcs(g->c.face, CUPOLA_R, 0, CUPOLA_R, 0, 1, 2);
            sw__gen_loop_end(g->c.face);
            if (end)
                g->c.face->flags |= SW_SG_FACE_REVERSED; /* x x z = -y faces out at y0 only */
            sw__gen_emit(&g->c, p, NULL, 1);
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
        wall(g, floor_group(g, a.f), k, SIDE_N, 1, 0, o, sw__gen_x);
    }
    if (a.ix + 1 < g->nx && k + 1 == rooms) {
        const double o[3] = {a.x0 + ROOM, a.y0, z};
        wall(g, floor_group(g, a.f), k, SIDE_E, 1, 0, o, sw__gen_y);
    }
}

static void bollards(gb *g, uint64_t n)
{
    const uint32_t p =
        n ? sw__gen_node(&g->c, SW_SG_NODE_GROUP, 0, 0, NULL, k_column_col, "bollards") : 0;
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
    t.c.b = NULL;
    fn(&t, k, rooms);
    return t.c.occ - g->c.occ;
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
    uint64_t *roofc = sw__malloc(cap * sizeof *roofc), *northc = sw__malloc(cap * sizeof *northc);
    uint64_t roof_sum = 0, north_sum = 0;
    out->rooms = out->total = 0;
    int oom = !roofc || !northc;
    for (uint64_t k = 0; !oom; ++k) {
        if (k == cap) {
            cap *= 2;
            uint64_t *a = sw__realloc(roofc, cap * sizeof *roofc);
            roofc = a ? a : roofc;
            uint64_t *b = a ? sw__realloc(northc, cap * sizeof *northc) : NULL;
            northc = b ? b : northc;
            if (!a || !b) {
                oom = 1;
                break;
            }
        }
        room(g, k);
        if (g->c.occ > want)
            break;
        const room_at a = locate(g, k);
        roofc[k] = cost_of(g, roof_fn, k, 0);
        /* closure(k, k + nx) builds k's north wall only; closure(k, k + 1) also its east one */
        northc[k] = a.iy + 1 < g->ny ? cost_of(g, closure, k, k + g->nx) : 0;
        const uint64_t east = a.ix + 1 < g->nx ? cost_of(g, closure, k, k + 1) - northc[k] : 0;
        roof_sum += roofc[k] - (k >= per ? roofc[k - per] : 0);
        north_sum += northc[k] - (k >= g->nx ? northc[k - g->nx] : 0);
        const uint64_t total = g->c.occ + roof_sum + north_sum + east;
        if (total <= want)
            out->rooms = k + 1, out->total = total;
        if (g->d->progress && (k & 0x3fffu) == 0)
            g->d->progress(g->d->user_data, 0.2 * (double)g->c.occ / (double)want, "planning");
    }
    sw__free(roofc);
    sw__free(northc);
    if (oom)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "building: out of memory while planning");
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
    for (uint64_t k = 0; k < n && !g->c.oom; ++k) {
        room(g, k);
        if (g->d->progress && (k & 0x3ffu) == 0)
            g->d->progress(g->d->user_data, 0.2 + 0.6 * (double)k / (double)n, "rooms");
    }
    for (uint64_t k = n > per ? n - per : 0; k < n; ++k)
        roof(g, k);
    for (uint64_t k = n > g->nx ? n - g->nx : 0; k < n; ++k)
        closure(g, k, n);
    bollards(g, g->d->surfaces - g->c.occ);
}

sw_result sw_sg_generate_building(const sw_sg_building_desc *desc, sw_sg_scene **out,
                                  sw_sg_building_report *report, sw_status *status)
{
    *out = NULL;
    sw_result checked = sw__gen_check_request("building", desc->surfaces, desc->models, status);
    if (checked != SW_OK)
        return checked;
    gb g;
    memset(&g, 0, sizeof g);
    g.d = desc;
    g.floor_node = g.roof_node = SW_SG_NONE;
    for (int m = 0; m <= SW_SG_BUILDING_N_MODELS; ++m)
        g.c.proto[m] = SW_SG_NONE;
    g.c.models = desc->models;
    g.c.n_models = SW_SG_BUILDING_N_MODELS;
    sw_result r = sw__gen_measure(&g.c, sw_sg_building_model_files, status);
    if (r != SW_OK)
        return r;
    layout(&g, desc->surfaces);
    g.c.face = sw__malloc(sizeof *g.c.face);
    gb dry = g;
    plan pl = {0, 0};
    r = g.c.face ? plan_rooms(&dry, desc->surfaces, &pl, status)
                 : sw__fail(status, SW_ERR_OUT_OF_MEMORY, "building: out of memory");
    if (r == SW_OK && pl.rooms == 0)
        r = sw__fail(status, SW_ERR_INVALID_ARGUMENT, "building: %llu surfaces hold no room",
                     (unsigned long long)desc->surfaces);
    if (r == SW_OK) {
        g.c.b = sw_sg_builder_create();
        g.c.n_nodes = 1; /* the builder's root */
        g.c.oom = !g.c.b;
        if (g.c.b)
            build(&g, &pl);
        if (!g.c.oom && g.c.occ != desc->surfaces)
            r = sw__fail(status, SW_ERR_INTERNAL, "building: %llu occurrences built, %llu planned",
                         (unsigned long long)g.c.occ, (unsigned long long)desc->surfaces);
        else if (g.c.oom)
            r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "building: out of memory");
    }
    sw__free(g.c.face);
    if (r != SW_OK) {
        sw_sg_builder_free(g.c.b);
        return r;
    }
    if (desc->progress)
        desc->progress(desc->user_data, 0.8, "validating");
    r = sw_sg_builder_finish(g.c.b, out, status);
    if (desc->progress)
        desc->progress(desc->user_data, 1.0, "done");
    g.rep.nx = g.nx, g.rep.ny = g.ny;
    g.rep.occurrences = g.c.occ, g.rep.unique_faces = g.c.unique;
    g.rep.instances = g.c.instances;
    if (r == SW_OK && report)
        *report = g.rep;
    return r;
}
