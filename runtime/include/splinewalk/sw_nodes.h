/* SPDX-License-Identifier: MIT */
/* splinewalk — scenes built from nodes: the scene-graph part of the embedding API.
 *
 * A node scene is an sw_scene like a loaded one (sw_renderer_draw, sw_scene_save, sw_scene_pick,
 * sw_scene_get_info and sw_camera_fit take its handle), whose content the host builds and edits:
 * groups, transforms, instances of node subtrees, trimmed NURBS surfaces, T-splines, triangle
 * meshes, planar outlines (shapes: floor plans, markings), cameras, and files imported under a
 * node (OpenCASCADE for STEP / IGES / BREP, or .sws / .tsm).
 *
 * Versions. The node tree is the mutable model; what is drawn is an immutable compiled version
 * (the scene graph's own scene, its BVH and its back-patch cones), made in the scene's worker
 * thread and published by one atomic pointer exchange. Every edit advances the scene's revision
 * and asks for a new version; edits made while one compiles are gathered into the next. The
 * version replaced stays alive until no frame, pick or save uses it any more (a grace period for
 * readers of the pointer, then reference counts). What reads the scene sees one version:
 *  - a walkthrough frame (sw_frame_desc.walkthrough = 1) draws the version published when it
 *    starts and never waits for a compilation;
 *  - a converged frame, sw_scene_save, sw_scene_pick, sw_scene_get_info and sw_camera_fit wait
 *    until every edit made before the call is compiled, and then use that version.
 * sw_scene_flush waits the same way; sw_scene_get_revisions tells what is published. Split
 * frames (sw_renderer_prepare) prepared while others wait draw the version those draw. A version
 * is compiled whole (every node copied, validated, boxed), so its cost grows with the scene; a
 * renderer switching to a new version builds that version's hierarchies again in its pool (the
 * faces are drawn from their Bézier patches meanwhile, within the same error bound).
 *
 * Handles. sw_node is a pool index and a 16-bit generation per scene, {0} never valid; a node
 * handle is only meaningful with the scene that made it. After sw_node_remove every copy of the
 * handle (and those of the removed subtree) is stale: calls return SW_ERR_STALE_HANDLE.
 *
 * Threads. Every function here may be called from any thread; calls on one scene are serialised
 * by the scene's edit lock, which a compilation also holds while it copies the tree (not while it
 * validates and boxes it); no call waits for a compilation to finish but those documented to.
 * The renderer's thread rules are those of splinewalk.h.
 *
 * Colours. A node's own colour wins over its parent's and over the colour of an instance that
 * draws it; a node with color[3] == 0 takes the colour of what draws it.
 *
 * Ownership. Descs and the arrays they point at are read during the call only (copied).
 *
 * Meshes. A MESH node's triangles are drawn as given (the renderer's triangle path, the one its
 * static LODs take): depth-tested with the surfaces, coloured and lit like them, culled by their
 * box, but with no screen-space error bound of their own — a mesh is as exact as its author made
 * it. sw_scene_save writes them into the .sws file (docs/sws-format.md, sections MESHES and
 * INDICES), sw_scene_pick hits them (the triangle and its barycentric weights).
 *
 * Shapes. A SHAPE node is a filled outline in the plane z = 0 of its node's frame: closed loops of
 * lines and rational NURBS curves of any degree, filled by even-odd parity in the node's colour
 * (its alpha blends it). It is drawn after the opaque scene with exact edges at any zoom,
 * anti-aliased (Santana's implicit curves, gpu/sw_curves.h: the loops are mapped through the
 * perspective exactly, cut at the near plane), and hidden by what lies in front of it; an outline
 * laid on a surface (less than 1/4096 of its distance behind it) shows on that surface. It has no
 * thickness: seen edge-on it covers nothing; it is not an occluder and not hit by sw_scene_pick.
 * sw_scene_save writes it (section SHAPES).
 *
 * Labels. A LABEL node is a line of text drawn as its glyphs' outlines (a TrueType or OpenType
 * font through FreeType: the text module, libsplinewalk_text, sw_text.h; without it a label is
 * refused with SW_ERR_UNSUPPORTED), with the shapes' exact edges at any zoom: fixed in the world
 * (in the plane z = 0 of its node's frame, the baseline along x) or billboarded at its node's
 * origin with a constant size on screen. Saved as a shape (its glyphs' outlines, section SHAPES):
 * a saved scene needs no font to be drawn again.
 */
#ifndef SPLINEWALK_SW_NODES_H
#define SPLINEWALK_SW_NODES_H

#include <splinewalk/splinewalk.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- node scenes ----------------------------------------------------------------------------- */
typedef struct sw_scene_desc {
    const char *name; /* NULL: none; copied; names the scene in compile failures */
} sw_scene_desc;

/* Creates an empty node scene (its root is an implicit group; {0} names it as a parent). desc may
 * be NULL (defaults). Any thread. The scene is the caller's: free it with sw_scene_destroy, which
 * frees its nodes too (a frame still drawing a version keeps that version alive). Starts one
 * worker thread for the scene's compilations on the first edit. *out = {0} on failure.
 * Errors: SW_ERR_INVALID_ARGUMENT (NULL out), SW_ERR_OUT_OF_MEMORY, SW_ERR_LIMIT (65,535 scenes).
 */
SW_API sw_result sw_scene_create(const sw_scene_desc *desc, sw_scene *out, sw_status *status);

typedef struct sw_scene_revisions {
    uint64_t latest;    /* revision of the last edit (0: none yet) */
    uint64_t published; /* revision the published version shows (<= latest) */
    uint64_t compiles;  /* versions compiled so far (edits are gathered, so <= latest + 1) */
} sw_scene_revisions;

/* Any thread; never waits. Errors: SW_ERR_INVALID_ARGUMENT (NULL out, or a scene loaded from a
 * file, which has no revisions), SW_ERR_STALE_HANDLE. */
SW_API sw_result sw_scene_get_revisions(sw_scene scene, sw_scene_revisions *out, sw_status *status);
/* Waits until every edit made before the call is published. Any thread. Errors:
 * SW_ERR_STALE_HANDLE, SW_ERR_INVALID_ARGUMENT (a scene loaded from a file), and what compiling
 * met (SW_ERR_OUT_OF_MEMORY, SW_ERR_INVALID_GEOMETRY, SW_ERR_LIMIT): the version before stays
 * published then. */
SW_API sw_result sw_scene_flush(sw_scene scene, sw_status *status);

/* ---- geometry descs -------------------------------------------------------------------------- */
/* A 2D rational B-spline curve in a surface's (u, v) domain, clamped (its ends are its first and
 * last control points). */
typedef struct sw_trim_curve {
    uint32_t degree;       /* 1..31 */
    uint32_t count;        /* control points, >= degree + 1 */
    const double *knots;   /* count + degree + 1, non-decreasing */
    const double *points;  /* count * 2: (u, v) */
    const double *weights; /* count, > 0; NULL: all 1 */
} sw_trim_curve;

/* A closed loop of curves, each one's end the next one's start (gaps up to 1e-6 of the domain's
 * size are closed by snapping; larger ones are SW_ERR_INVALID_GEOMETRY). */
typedef struct sw_trim_loop {
    const sw_trim_curve *curves;
    uint32_t curve_count; /* >= 1 */
} sw_trim_loop;

/* A planar outline: closed loops of 2D rational B-spline curves (sw_trim_curve, with (x, y) for
 * (u, v)) in the plane z = 0 of the node's frame; what is filled is inside an odd number of loops
 * (even-odd). Each loop closes as a trim loop does (gaps up to 1e-6 of the outline's size are
 * snapped) and must span an area. */
typedef struct sw_shape_desc {
    const sw_trim_loop *loops;
    uint32_t loop_count; /* >= 1 */
} sw_shape_desc;

/* A line of text. */
typedef struct sw_label_desc {
    const char *text;      /* UTF-8, one line (no control characters), 1..1024 bytes */
    const char *font_path; /* a .ttf / .otf file; NULL: the text module's default (DejaVu Sans) */
    double size;           /* the em height: pixels on screen when screen_size, else units of the
                              node's frame; (0, 16384] pixels or (0, 1e15] units */
    int32_t screen_size;   /* 1: billboarded at the node's origin (facing the camera, upright on
                              the screen), `size` pixels tall whatever its distance; the node's
                              rotation and scale are not used. 0: fixed in the world */
    int32_t align;         /* where the node's origin lies on the baseline: 0 the text's start,
                              1 its middle, 2 its end */
} sw_label_desc;

/* A trimmed NURBS surface S(u, v) = sum w_ij P_ij N_i(u) N_j(v) / sum w_ij N_i(u) N_j(v). */
typedef struct sw_nurbs_desc {
    uint32_t degree_u, degree_v; /* 1..31 */
    uint32_t count_u, count_v;   /* control points in u and v, >= degree + 1; at most 2^20 in all */
    const double *knots_u;       /* count_u + degree_u + 1, non-decreasing, non-empty domain */
    const double *knots_v;       /* count_v + degree_v + 1 */
    const double *points;        /* count_u * count_v * 3 (x, y, z), u fastest */
    const double *weights;       /* count_u * count_v, > 0; NULL: all 1 (a B-spline surface) */
    const sw_trim_loop *loops;   /* what is kept is inside an odd number of loops (even-odd, the
                                    rule of the trim textures); loop 0 is the outer boundary */
    uint32_t loop_count;         /* 0: untrimmed, the whole domain */
    int32_t reversed;            /* 1: the surface's front is -(Su x Sv) */
} sw_nurbs_desc;

/* A bicubic T-spline (Sederberg et al. 2003): from a .tsm file (docs/tspline-format.md), or point
 * by point with each point's local knot vectors. */
typedef struct sw_tspline_desc {
    const char *tsm_path;  /* non-NULL: read this file; the arrays below are ignored */
    uint32_t point_count;  /* 1..2^20 */
    const double *points;  /* point_count * 3 */
    const double *weights; /* point_count, > 0; NULL: all 1 */
    const double *knots_u; /* point_count * 5: each point's local knot vector in u */
    const double *knots_v; /* point_count * 5 */
    double domain[4];      /* u0, u1, v0, v1 (u0 < u1, v0 < v1); required with the arrays */
} sw_tspline_desc;

/* A triangle mesh. Counter-clockwise triangles face their front (shading is two-sided: both sides
 * are lit alike). */
typedef struct sw_mesh_desc {
    uint32_t vertex_count;   /* 3..2^24 */
    const double *positions; /* vertex_count * 3 (x, y, z), finite */
    const double *normals;   /* vertex_count * 3, finite and non-zero (normalised when copied);
                                NULL: each triangle shaded flat with its own normal */
    uint32_t triangle_count; /* 1..2^24 */
    const uint32_t *indices; /* triangle_count * 3 vertex indices, each < vertex_count */
} sw_mesh_desc;

/* ---- nodes ----------------------------------------------------------------------------------- */
typedef enum sw_node_kind {
    SW_NODE_GROUP = 0,     /* children under the parent's frame */
    SW_NODE_TRANSFORM = 1, /* children under `transform` */
    SW_NODE_INSTANCE = 2,  /* draws the subtree of `instance_of` again, under `transform` */
    SW_NODE_NURBS = 3,     /* a trimmed NURBS surface (`nurbs`) under `transform` */
    SW_NODE_TSPLINE = 4,   /* a T-spline (`tspline`) under `transform` */
    SW_NODE_CAMERA = 5,    /* a camera (`camera`) in the parent's frame; draws nothing */
    SW_NODE_IMPORT = 6,    /* the content of `import_path` under `transform` */
    SW_NODE_MESH = 7,      /* a triangle mesh (`mesh`) under `transform` */
    SW_NODE_SHAPE = 8,     /* a filled planar outline (`shape`) under `transform` */
    SW_NODE_LABEL = 9,     /* a line of text (`label`) under `transform` */
    SW_NODE_KIND_COUNT
} sw_node_kind;

typedef struct sw_node_desc {
    sw_node_kind kind;    /* 0: GROUP */
    sw_node parent;       /* {0}: the root; else a GROUP or TRANSFORM node of the scene */
    int32_t detached;     /* 1: the node has no parent (parent is ignored) and is drawn only
                             through instances of it: a prototype */
    const char *name;     /* NULL: none; copied */
    int32_t hidden;       /* 1: the node and its subtree are not drawn, nor are instances of it */
    float color[4];       /* linear RGBA; color[3] == 0 (all zero): the parent's colour */
    double transform[12]; /* row-major 3x4, local to parent; all zero: identity. Read for
                             TRANSFORM, INSTANCE, NURBS, TSPLINE, IMPORT, MESH, SHAPE and LABEL */
    sw_node instance_of;  /* INSTANCE: the node whose subtree it draws (not one of its own
                             ancestors, nor a subtree that instances them) */
    const sw_nurbs_desc *nurbs;     /* NURBS: required */
    const sw_tspline_desc *tspline; /* TSPLINE: required */
    const sw_camera *camera;        /* CAMERA: required; in the parent's frame (non-degenerate) */
    const char *import_path;        /* IMPORT: .step/.stp, .iges/.igs, .brep (through OCCT), .sws
                                       or .tsm; read once, during sw_node_add */
    sw_warning_fn import_warning;   /* IMPORT: faces that could not be converted; NULL: none */
    void *user_data;                /* passed to import_warning, on the calling thread */
    const sw_mesh_desc *mesh;       /* MESH: required */
    const sw_shape_desc *shape;     /* SHAPE: required */
    const sw_label_desc *label;     /* LABEL: required */
} sw_node_desc;

/* Adds a node as the last child of desc->parent (or detached). Any thread; an IMPORT reads and
 * converts its file during the call (seconds for large models). *out = {0} on failure, and the
 * scene is unchanged. Errors: SW_ERR_INVALID_ARGUMENT (NULL desc or out; a loaded scene; a kind
 * out of range; a parent that is not a GROUP or TRANSFORM; a missing kind-specific pointer; an
 * instance that would draw itself; a non-finite transform, colour or camera),
 * SW_ERR_STALE_HANDLE (scene, parent or instance_of), SW_ERR_INVALID_GEOMETRY (the surface,
 * T-spline, trim loops or mesh, with the index at fault), SW_ERR_LIMIT (65,535 nodes per scene;
 * sizes), SW_ERR_OUT_OF_MEMORY, and those of sw_scene_load for IMPORT and a .tsm path. */
SW_API sw_result sw_node_add(sw_scene scene, const sw_node_desc *desc, sw_node *out,
                             sw_status *status);

/* Adds a MESH node: sw_node_add with desc->kind = SW_NODE_MESH and desc->mesh = mesh (node may be
 * NULL: a visible mesh under the root, identity transform, inherited colour; its kind and mesh
 * fields are ignored). Any thread. *out = {0} on failure, and the scene is unchanged. Errors: as
 * sw_node_add, and for the mesh: SW_ERR_INVALID_ARGUMENT (NULL mesh, positions or indices),
 * SW_ERR_LIMIT (vertex_count or triangle_count out of range), SW_ERR_INVALID_GEOMETRY (a
 * non-finite position, a non-finite or zero normal, an index >= vertex_count: the message names
 * the vertex or the index and its triangle). */
SW_API sw_result sw_node_add_mesh(sw_scene scene, const sw_node_desc *node,
                                  const sw_mesh_desc *mesh, sw_node *out, sw_status *status);

/* Removes the node and its subtree; their handles go stale. Any thread. Errors:
 * SW_ERR_STALE_HANDLE (scene or node: also a node removed before — a double remove),
 * SW_ERR_INVALID_ARGUMENT (a loaded scene; a node of the subtree is drawn by an INSTANCE outside
 * it: remove that instance first). */
SW_API sw_result sw_node_remove(sw_scene scene, sw_node node, sw_status *status);

/* Per-node appearance and placement; each is an edit (a new revision). Any thread. Errors:
 * SW_ERR_STALE_HANDLE, SW_ERR_INVALID_ARGUMENT (a loaded scene; NULL or non-finite values;
 * set_transform on a GROUP or CAMERA node). color NULL: inherit the parent's. */
SW_API sw_result sw_node_set_visible(sw_scene scene, sw_node node, int32_t visible,
                                     sw_status *status);
SW_API sw_result sw_node_set_color(sw_scene scene, sw_node node, const float color[4],
                                   sw_status *status);
SW_API sw_result sw_node_set_transform(sw_scene scene, sw_node node, const double transform[12],
                                       sw_status *status);

/* Live edit: replaces the surface of a NURBS node (any sizes, degrees and loops). The call checks
 * the surface and returns; the new version is compiled in the scene's worker thread, while frames
 * keep drawing the version before (see Versions above). Any thread. Errors: SW_ERR_STALE_HANDLE,
 * SW_ERR_INVALID_ARGUMENT (NULL desc, a node that is not NURBS), SW_ERR_INVALID_GEOMETRY,
 * SW_ERR_LIMIT, SW_ERR_OUT_OF_MEMORY; the node keeps its surface then. */
SW_API sw_result sw_node_set_nurbs(sw_scene scene, sw_node node, const sw_nurbs_desc *desc,
                                   sw_status *status);
/* The same for a TSPLINE node: a new T-spline (points, knots, or another .tsm file, read during
 * the call) replaces its Bézier patches. Errors: as sw_node_set_nurbs (SW_ERR_INVALID_ARGUMENT
 * for a node that is not TSPLINE), and those of reading a .tsm file. */
SW_API sw_result sw_node_set_tspline(sw_scene scene, sw_node node, const sw_tspline_desc *desc,
                                     sw_status *status);
/* The same for a MESH node: new vertices and triangles (any counts). Errors: as
 * sw_node_set_nurbs (SW_ERR_INVALID_ARGUMENT for a node that is not MESH), and those of the mesh
 * as sw_node_add_mesh lists them; the node keeps its mesh then. */
SW_API sw_result sw_node_set_mesh(sw_scene scene, sw_node node, const sw_mesh_desc *desc,
                                  sw_status *status);
/* The same for a SHAPE node: new loops (any counts). Errors: as sw_node_set_nurbs
 * (SW_ERR_INVALID_ARGUMENT for a node that is not SHAPE, NULL loops or a loop without curves;
 * SW_ERR_INVALID_GEOMETRY for a curve, a loop that does not close or spans no area, with the
 * loop and curve named); the node keeps its outline then. */
SW_API sw_result sw_node_set_shape(sw_scene scene, sw_node node, const sw_shape_desc *desc,
                                   sw_status *status);
/* The same for a LABEL node: new text, font, size or placement. Errors: as sw_node_set_nurbs
 * (SW_ERR_INVALID_ARGUMENT for a node that is not LABEL, NULL or empty text, a size or align
 * out of range, text that is not UTF-8 or holds a control character (the byte named), text with
 * no glyph outline (spaces only)), SW_ERR_UNSUPPORTED (no text module), and the font's:
 * SW_ERR_NOT_FOUND, SW_ERR_NOT_REGULAR_FILE, SW_ERR_FORMAT (not a font FreeType reads). */
SW_API sw_result sw_node_set_label(sw_scene scene, sw_node node, const sw_label_desc *desc,
                                   sw_status *status);

typedef struct sw_node_info {
    sw_node_kind kind;
    sw_node parent;    /* {0}: the root, or detached */
    uint32_t children; /* direct children */
    int32_t detached, visible;
    float color[4];       /* as set; color[3] == 0: inherited */
    double transform[12]; /* local (identity for GROUP and CAMERA) */
    uint32_t faces;       /* surfaces the node holds itself (NURBS 1, TSPLINE its Bézier
                             patches, IMPORT the file's faces; 0 otherwise) */
    uint32_t triangles;   /* mesh triangles the node holds itself (MESH its mesh's, IMPORT a
                             .sws file's meshes'; 0 otherwise) */
} sw_node_info;

/* Any thread; never waits. Errors: SW_ERR_INVALID_ARGUMENT (NULL out, a loaded scene),
 * SW_ERR_STALE_HANDLE. */
SW_API sw_result sw_node_get_info(sw_scene scene, sw_node node, sw_node_info *out,
                                  sw_status *status);
/* The world camera of a CAMERA node: its eye, target and up mapped through its ancestors'
 * transforms (a scale changes no angle: fovy is kept). Any thread. Errors: as sw_node_get_info,
 * and SW_ERR_INVALID_ARGUMENT for a node that is not a CAMERA or is detached. */
SW_API sw_result sw_node_get_camera(sw_scene scene, sw_node node, sw_camera *out,
                                    sw_status *status);

#ifdef __cplusplus
}
#endif
/* sw_immediate.h needs this header's descs whichever of the headers a program includes first */
#define SPLINEWALK_SW_NODES_COMPLETE
#include <splinewalk/sw_immediate.h>
#endif
