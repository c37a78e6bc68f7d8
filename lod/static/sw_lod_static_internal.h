/* SPDX-License-Identifier: MIT */
/* lod/ private: what the static-LOD builder (static_lod.c: level 0 and the chain), the face
 * domains it tessellates in (static_lod_domain.c) and the two-sided measurement of its levels
 * (static_lod_measure.c) share. Never installed. */
#ifndef SW_LOD_STATIC_INTERNAL_H
#define SW_LOD_STATIC_INTERNAL_H

#include "sw_module_abi.h"

#include "sw_lod_static.h"
#include "sw_sg_geom.h"
#include "sw_sg_trim.h"

#include <stdint.h>

#define STATIC_MAX_CELLS 4096 /* grid segments per patch side */

/* ---- even-odd classification against many loop segments, bucketed by v ----------------------
 * sw_sg_trim_classify walks every segment; a face with long loops and many grid points needs the
 * same rule (crossing a ray towards +u, half-open in v) restricted to the segments whose v-range
 * meets the point's strip. */
typedef struct strip_classifier {
    double v0, inv_h;
    uint32_t n_strips;
    uint32_t *start; /* n_strips + 1 */
    double *seg;     /* 4 per entry: ui, vi, uj, vj */
} strip_classifier;

/* ---- one face of the super-surface ---------------------------------------------------------- */
typedef struct face_dom {
    uint32_t face;
    sw_sg_surface s;
    int reversed;
    int has_loops;
    sw_sg_bezier_set set;
    int32_t pnu, pnv;  /* the Bézier grid */
    double *pub, *pvb; /* its patch rectangles' breakpoints (cut to uv_box): pnu + 1, pnv + 1 */
    uint8_t *psel;     /* pnu * pnv: patch selected */
    int32_t sub;       /* cells per patch side (face_dom_refine) */
    int32_t nu, nv;    /* the cell grid: sub x sub cells per patch */
    double *ub, *vb;   /* nu + 1, nv + 1 */
    uint8_t *sel;      /* nu * nv: the cell's patch is selected */
    uint32_t n_sel;
    int outside_sel; /* what lies beyond the grid counts as selected (full face with loops) */
    double *scale;   /* 2 per cell: A, B of the header comment */
    double grad;     /* G: |dS| per unit (du, dv), over the selected cells */
    double au, av;   /* max of A / (u length), B / (v length): scaled length per parameter */
    double box[6];   /* control points of the selected patches */
    sw_sg_polyline *loops;
    uint32_t n_loops;
    strip_classifier cls;
} face_dom;

/* The faces of a patch list, each with its patches: sorted copy, one face_dom per face. */
typedef struct patch_set {
    sw_lod_static_patch *p; /* sorted by (face, iv, iu), unique */
    uint32_t n;
    face_dom *faces;
    uint32_t n_faces;
    double box[6];
} patch_set;

/* ---- static_lod_domain.c -------------------------------------------------------------------- */
/* The strip of parameter v. */
uint32_t sw__sl_strip_of(const strip_classifier *c, double v);
/* Even-odd: (u, v) inside the classifier's loops. */
int sw__sl_strips_inside(const strip_classifier *c, double u, double v);
/* Cell (i, j) of the face's grid is selected (outside the grid: outside_sel). */
int sw__sl_sel_at(const face_dom *fd, int32_t i, int32_t j);
/* The last of the n cells of breakpoints b whose start is <= x (0 below the first). */
int32_t sw__sl_locate(const double *b, int32_t n, double x);
/* (u, v) lies in a selected cell and inside the face's loops. */
int sw__sl_in_domain(const face_dom *fd, double u, double v);
/* Splits the face's patches into 2, 4 or 8 cells per side while that saves at least 30 % of the
 * grid points at cell size c, and sets the cells' scalings; 0 when out of memory. */
int sw__sl_face_dom_refine(face_dom *fd, double c);
/* Flattens the face's loops within tol (parameter units) and builds the classifier. */
sw_result sw__sl_face_dom_flatten(const sw_sg_scene *scene, face_dom *fd, double tol,
                                  sw_status *status);
void sw__sl_patch_set_free(patch_set *ps);
/* qsort order of sw_lod_static_patch: by face, then iv, then iu. */
SW_MODULE_ABI int sw__sl_patch_cmp(const void *a, const void *b);
/* Frees a level's arrays and zeroes it. */
SW_MODULE_ABI void sw__sl_level_free(sw_lod_static_level *l);
/* The faces of a patch list, each with its selected patches and its cell grid. */
sw_result sw__sl_patch_set_init(const sw_sg_scene *scene, const sw_lod_static_patch *patches,
                                uint32_t n, patch_set *ps, sw_status *status);
/* The face_dom of `face`, NULL when the set has none. */
const face_dom *sw__sl_find_face(const patch_set *ps, uint32_t face);

#endif
