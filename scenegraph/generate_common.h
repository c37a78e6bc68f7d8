/* SPDX-License-Identifier: MIT */
/* Internal to the scene generators (generate_*.c): see generate_common.c. */
#ifndef SW_SG_GENERATE_COMMON_H
#define SW_SG_GENERATE_COMMON_H

#include "sw_sg_generate.h"

enum { SW__GEN_MAX_CURVES = 48, SW__GEN_MAX_LOOPS = 6, SW__GEN_MAX_NU = 9, SW__GEN_MAX_NV = 4 };

/* ---- a face under construction -------------------------------------------------------------- */

typedef struct sw__gen_curve {
    int deg, n;
    double knots[6], cpw[9];
} sw__gen_curve;

typedef struct sw__gen_face {
    int deg_u, deg_v, n_u, n_v;
    double ku[SW__GEN_MAX_NU + 4], kv[SW__GEN_MAX_NV + 4], cpw[SW__GEN_MAX_NU * SW__GEN_MAX_NV * 4];
    uint32_t kind, flags;
    int n_loops, loop_first[SW__GEN_MAX_LOOPS + 1];
    uint32_t loop_flags[SW__GEN_MAX_LOOPS];
    int n_curves;
    sw__gen_curve c[SW__GEN_MAX_CURVES];
    double pen[2], start[2]; /* the loop being drawn */
} sw__gen_face;

enum { SW__GEN_MAX_MODELS = 16 };

/* A generator's state: what is built (or would be, in a dry run) and the instanced models. */
typedef struct sw__gen {
    sw_sg_builder *b;     /* NULL: a dry run, counting only */
    uint32_t n_nodes;     /* nodes in b (or that would be) */
    uint64_t occ, unique; /* face occurrences; faces stored */
    uint64_t instanced;   /* occurrences drawn through instance nodes */
    uint64_t instances;   /* instance nodes */
    int oom;              /* a builder call failed */
    sw__gen_face *face;   /* scratch, shared by dry-run copies */
    const sw_sg_scene *const *models;
    int n_models;
    uint32_t proto[SW__GEN_MAX_MODELS + 2]; /* models' (then own) prototypes; SW_SG_NONE: not yet */
    uint64_t model_occ[SW__GEN_MAX_MODELS];
    double model_box[SW__GEN_MAX_MODELS][6];
} sw__gen;

static const double sw__gen_x[3] = {1, 0, 0}, sw__gen_y[3] = {0, 1, 0}, sw__gen_z[3] = {0, 0, 1};

void sw__gen_v3(double out[3], const double o[3], double a, const double e[3], double b,
                const double f[3]);
void sw__gen_cross(const double a[3], const double b[3], double out[3]);
uint64_t sw__gen_mix64(uint64_t x);
/* SW_OK when a requested surface count and its models are usable, else SW_ERR_INVALID_ARGUMENT
 * naming `what` ("building", "vehicle"). */
sw_result sw__gen_check_request(const char *what, uint64_t surfaces, const void *models,
                                sw_status *status);
uint32_t sw__gen_pick(uint64_t *s, uint32_t n); /* 0..n-1 from the stream s */

/* Surfaces of the scratch face. Planes: o + u e + v g over [0, l] x [0, h]. Cylinders:
 * c + r (cos t e1 + sin t e2) + v axis over nq quadrants from e1 (u in [0, nq]), v in [0, len];
 * Su x Sv points away from the axis when e1 x e2 = axis. Domes: the hemisphere of radius r on c,
 * z up (u in [0, 4] around, v in [0, 1] up the meridian). */
void sw__gen_face_reset(sw__gen_face *f, uint32_t kind);
void sw__gen_plane_surface(sw__gen_face *f, const double o[3], const double e[3], const double g[3],
                           double l, double h);
void sw__gen_cylinder_surface(sw__gen_face *f, const double c[3], const double e1[3],
                              const double e2[3], const double axis[3], double r, int nq,
                              double len);
void sw__gen_dome_surface(sw__gen_face *f, const double c[3], double r);

/* Trim loops as pen paths. Arcs: nq quarter arcs around (cu, cv) from the pen, which lies on the
 * circle (ellipse) at quadrant q0 (0: +u, 1: +v, ...), counter-clockwise for dir = +1, clockwise
 * for -1. loop_end closes the loop with a line unless the pen is back at its start. */
void sw__gen_loop_begin(sw__gen_face *f, double u, double v, uint32_t flags);
void sw__gen_line_to(sw__gen_face *f, double u, double v);
void sw__gen_arcs(sw__gen_face *f, double cu, double cv, double r, int q0, int dir, int nq);
void sw__gen_ellipse_arcs(sw__gen_face *f, double cu, double cv, double ru, double rv, int q0,
                          int dir, int nq);
void sw__gen_loop_end(sw__gen_face *f);
void sw__gen_outer_rect(sw__gen_face *f, double l, double h);
void sw__gen_hole_rect(sw__gen_face *f, double u0, double v0, double u1, double v1);   /* CW */
void sw__gen_hole_arched(sw__gen_face *f, double u0, double v0, double u1, double v1); /* CW */

/* Nodes and faces: counted always, stored when building. */
uint32_t sw__gen_node(sw__gen *g, sw_sg_node_kind kind, uint32_t parent, uint32_t ref,
                      const double xf[12], const float col[4], const char *name);
/* Stores the scratch face, drawn under `parent` (drawn = 0: a prototype's face). */
void sw__gen_emit(sw__gen *g, uint32_t parent, const float col[4], int drawn);
/* The scratch face as an untrimmed plane or cylinder (reversed: the normal is -(Su x Sv)). */
void sw__gen_plane(sw__gen *g, const double o[3], const double e[3], const double f3[3], double l,
                   double h, int reversed);
void sw__gen_cylinder(sw__gen *g, const double c[3], const double e1[3], const double e2[3],
                      const double axis[3], double r, int nq, double len, int reversed);
/* An instance of model m (its geometry appended on first use). */
void sw__gen_instance(sw__gen *g, uint32_t parent, int m, const double xf[12], const float col[4]);
/* Each model's occurrences and control-net box (its BVH's root, as the grid measures). */
sw_result sw__gen_measure(sw__gen *g, const char *const *names, sw_status *status);

#endif
