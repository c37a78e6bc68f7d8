/* SPDX-License-Identifier: MIT */
/* splinewalk scene: faces (trimmed NURBS surfaces), trim loops of 2D rational B-spline curves,
 * triangle meshes, planar outlines (shapes), a node tree (group, transform, instance, surface,
 * mesh, shape) with colours, and face adjacency.
 *
 * The scene is a set of flat arrays of fixed-size records that reference one pool of doubles by
 * offset. The same arrays are built in memory (sw_sg_builder, used by importers and generators) or
 * mapped straight from a .sws file (sws_file.c) without parsing every surface up front: records
 * are plain data, 8-byte aligned, little-endian, with no pointers inside.
 *
 * Threads: a finished scene is immutable and may be read from any thread. A builder belongs to
 * one thread. sw_sg_scene_require() must be called (once, by one thread) before the sections it
 * names are read; after it returned SW_OK they may be read concurrently.
 */
#ifndef SW_SG_SCENE_H
#define SW_SG_SCENE_H

#include "sw_module_abi.h"

#include "sw_sg_geom.h"

#include <splinewalk/sw_result.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SW_SG_NONE UINT32_MAX

/* The geometry a face had in its source file, before conversion to NURBS (for `info`). */
#define SW_SG_SURFACE_KIND_XMACRO(X)                                                               \
    X(SW_SG_KIND_PLANE, "plane")                                                                   \
    X(SW_SG_KIND_CYLINDER, "cylinder")                                                             \
    X(SW_SG_KIND_CONE, "cone")                                                                     \
    X(SW_SG_KIND_SPHERE, "sphere")                                                                 \
    X(SW_SG_KIND_TORUS, "torus")                                                                   \
    X(SW_SG_KIND_REVOLUTION, "revolution")                                                         \
    X(SW_SG_KIND_EXTRUSION, "extrusion")                                                           \
    X(SW_SG_KIND_BSPLINE, "bspline")                                                               \
    X(SW_SG_KIND_BEZIER, "bezier")                                                                 \
    X(SW_SG_KIND_OFFSET, "offset")                                                                 \
    X(SW_SG_KIND_OTHER, "other")                                                                   \
    X(SW_SG_KIND_TSPLINE, "tspline") /* a Bézier patch extracted from a T-spline (.tsm) */

typedef enum sw_sg_surface_kind {
#define SW__KIND_ENUM(id, text) id,
    SW_SG_SURFACE_KIND_XMACRO(SW__KIND_ENUM)
#undef SW__KIND_ENUM
        SW_SG_KIND_COUNT
} sw_sg_surface_kind;
const char *sw_sg_surface_kind_str(uint32_t kind);

enum sw_sg_face_flags {
    SW_SG_FACE_REVERSED = 1u << 0, /* the B-rep face's normal is opposite to Su x Sv */
    SW_SG_FACE_TRIMMED = 1u << 1,  /* its loops cut the domain (not just the domain's rectangle) */
    /* Every occurrence of the face bounds a closed, consistently oriented shell whose outward
     * side is the face's normal (Su x Sv, negated with REVERSED): it can be seen only from
     * outside, so back-patch culling may drop it (Kumar et al. 1997 §4.4). Set only when sure. */
    SW_SG_FACE_CLOSED_SHELL = 1u << 2,
    SW_SG_FACE_FLAGS_ALL = (1u << 3) - 1,
};

/* One face: a NURBS surface and its trim loops. Offsets are indices into the double pool. */
typedef struct sw_sg_face_rec {
    uint32_t deg_u, deg_v, n_u, n_v;
    uint64_t knots_u, knots_v, cpw; /* pool offsets: n_u+deg_u+1, n_v+deg_v+1, n_u*n_v*4 doubles */
    uint32_t first_loop, n_loops;   /* loops [first_loop, first_loop + n_loops) */
    uint32_t kind;                  /* sw_sg_surface_kind of the source geometry */
    uint32_t flags;                 /* sw_sg_face_flags */
    double uv_box[4];               /* u0, u1, v0, v1: trim region's box (domain if untrimmed) */
    double tolerance;               /* largest 3D edge tolerance of the face in the source */
} sw_sg_face_rec;

enum sw_sg_loop_flags { SW_SG_LOOP_OUTER = 1u << 0 };

/* A closed trim loop: curves [first_curve, first_curve + n_curves), each one's end equal to the
 * next one's start bit for bit (the builder snaps them), the last one's end to the first start. */
typedef struct sw_sg_loop_rec {
    uint32_t first_curve, n_curves;
    uint32_t flags;
    uint32_t reserved; /* zero */
} sw_sg_loop_rec;

/* A 2D rational B-spline trim curve in the face's (u, v) domain: cpw holds (w*u, w*v, w). */
typedef struct sw_sg_curve_rec {
    uint32_t degree, n;
    uint64_t knots, cpw; /* pool offsets: n+degree+1 and n*3 doubles */
} sw_sg_curve_rec;

/* A triangle mesh given as such (the mesh nodes): drawn as it is, not tessellated, so it has
 * no error bound of its own. Offsets: positions and normals in the double pool, indices in the
 * INDICES section (u32 each). */
#define SW_SG_NO_NORMALS UINT64_MAX
typedef struct sw_sg_mesh_rec {
    uint32_t n_vertices, n_triangles;
    uint64_t positions; /* pool offset of n_vertices * 3 doubles (x, y, z) */
    uint64_t normals;   /* pool offset of n_vertices * 3 doubles, or SW_SG_NO_NORMALS: each
                           triangle is shaded flat with its own normal */
    uint64_t indices;   /* INDICES offset of n_triangles * 3 vertex indices, each < n_vertices;
                           counter-clockwise seen from the front */
    uint32_t flags;     /* zero (none is defined) */
    uint32_t reserved;  /* zero */
    double box[6];      /* min xyz, max xyz of the positions, exactly (validated) */
} sw_sg_mesh_rec;

/* A filled planar outline (shape and label nodes): loops [first_loop, first_loop + n_loops) of 2D
 * rational B-spline curves in the plane z = 0 of its node's frame, filled by even-odd parity, drawn
 * with exact anti-aliased edges over the scene (gpu/sw_curves.h). */
enum sw_sg_shape_flags {
    /* Billboarded at its node's origin, constant size on screen: the plane faces the camera
     * (x right, y up on the screen) and one unit of it is px_size pixels (a label); the node's
     * rotation and scale are not used. */
    SW_SG_SHAPE_SCREEN = 1u << 0,
    SW_SG_SHAPE_FLAGS_ALL = (1u << 1) - 1,
};
#define SW_SG_SHAPE_MAX_PX 16384.0 /* px_size at most */
typedef struct sw_sg_shape_rec {
    uint32_t first_loop, n_loops; /* n_loops >= 1 */
    uint32_t flags;               /* sw_sg_shape_flags */
    uint32_t reserved;            /* zero */
    double box[4];                /* x0, y0, x1, y1 of its curves' control points, exactly
                                     (validated): the curves lie inside it */
    double px_size; /* SCREEN: pixels per unit, in (0, SW_SG_SHAPE_MAX_PX]; otherwise 0 */
} sw_sg_shape_rec;

typedef enum sw_sg_node_kind {
    SW_SG_NODE_GROUP = 0,     /* children, identity transform */
    SW_SG_NODE_TRANSFORM = 1, /* children under xform */
    SW_SG_NODE_INSTANCE = 2,  /* draws the subtree of node `ref` under xform */
    SW_SG_NODE_SURFACE = 3,   /* draws face `ref` under xform */
    SW_SG_NODE_MESH = 4,      /* draws mesh `ref` under xform */
    SW_SG_NODE_SHAPE = 5,     /* draws shape `ref` under xform */
} sw_sg_node_kind;

typedef struct sw_sg_node_rec {
    uint32_t kind;
    uint32_t parent, first_child, next_sibling; /* SW_SG_NONE when absent */
    uint32_t ref; /* face (SURFACE), prototype node (INSTANCE), mesh (MESH) or shape (SHAPE) */
    uint32_t name;                              /* byte offset into strings, SW_SG_NONE if none */
    float color[4];   /* linear RGBA; color[3] < 0 inherits the parent's */
    double xform[12]; /* row-major 3x4 local-to-parent */
} sw_sg_node_rec;

/* Two faces sharing a B-rep edge (for super-surface clustering later). */
typedef struct sw_sg_adjacency_rec {
    uint32_t face_a, face_b;
} sw_sg_adjacency_rec;

/* Sections of a scene, as stored in .sws files; used as bit masks in sw_sg_scene_require. */
typedef enum sw_sg_section {
    SW_SG_SEC_FACES = 1u << 0,
    SW_SG_SEC_LOOPS = 1u << 1,
    SW_SG_SEC_CURVES = 1u << 2,
    SW_SG_SEC_NODES = 1u << 3,
    SW_SG_SEC_ADJACENCY = 1u << 4,
    SW_SG_SEC_POOL = 1u << 5,
    SW_SG_SEC_STRINGS = 1u << 6,
    /* bits 7 and 8 are META and LODS, which have none */
    SW_SG_SEC_MESHES = 1u << 9,
    SW_SG_SEC_INDICES = 1u << 10,
    SW_SG_SEC_SHAPES = 1u << 11,
    SW_SG_SEC_ALL = ((1u << 7) - 1) | SW_SG_SEC_MESHES | SW_SG_SEC_INDICES | SW_SG_SEC_SHAPES,
} sw_sg_section;

typedef struct sw_sg_scene sw_sg_scene; /* opaque; arrays read through the accessors below */

/* Read-only view of a scene's arrays (borrowed; valid until sw_sg_scene_free). */
typedef struct sw_sg_scene_view {
    const sw_sg_face_rec *faces;
    const sw_sg_loop_rec *loops;
    const sw_sg_curve_rec *curves;
    const sw_sg_node_rec *nodes;
    const sw_sg_adjacency_rec *adjacency;
    const double *pool;
    const char *strings;
    uint32_t n_faces, n_loops, n_curves, n_nodes, n_adjacency;
    uint64_t n_pool, n_strings;
    uint32_t root; /* node the scene is drawn from */
    const sw_sg_mesh_rec *meshes;
    const uint32_t *indices;
    uint32_t n_meshes;
    uint64_t n_indices;
    const sw_sg_shape_rec *shapes;
    uint32_t n_shapes;
} sw_sg_scene_view;

SW_MODULE_ABI const sw_sg_scene_view *sw_sg_scene_view_ptr(const sw_sg_scene *scene);
/* Path of the file the scene was loaded from, or "" for one built in memory. */
const char *sw_sg_scene_path_ptr(const sw_sg_scene *scene);
/* A number no other scene of the process has had (1, 2, ...): what caches keyed by a scene hold
 * instead of its address, which the allocator gives to a later scene once this one is freed. */
uint64_t sw_sg_scene_serial(const sw_sg_scene *scene);

/* Verifies (once) the checksums of the named sections of a mapped scene and, the first time all of
 * them have been verified, validates every index and offset (sw_sg_scene_validate). In-memory
 * scenes return SW_OK at once. Errors: SW_ERR_CHECKSUM, SW_ERR_FORMAT, SW_ERR_INVALID_GEOMETRY. */
sw_result sw_sg_scene_require(sw_sg_scene *scene, uint32_t sections, sw_status *status);

/* Checks every index, offset and count against the array sizes, the node tree for cycles (also
 * through instances), and each face's and curve's geometry (sw_sg_surface_validate). */
sw_result sw_sg_scene_validate(const sw_sg_scene_view *view, const char *what, sw_status *status);

/* Borrowed geometry views of face `face` and curve `curve` (indices must be valid). */
SW_MODULE_ABI void sw_sg_scene_face_surface(const sw_sg_scene *scene, uint32_t face,
                                            sw_sg_surface *out);
SW_MODULE_ABI void sw_sg_scene_curve(const sw_sg_scene *scene, uint32_t curve, sw_sg_curve *out);

/* Bytes the scene occupies (arrays, pool, strings, bookkeeping; mapped bytes counted). */
size_t sw_sg_scene_memory(const sw_sg_scene *scene);

void sw_sg_scene_free(sw_sg_scene *scene); /* NULL allowed */

/* ---- traversal ------------------------------------------------------------------------------- */
/* Called once per drawn face occurrence with its world transform (row-major 3x4, double) and its
 * resolved colour. Instances are expanded. Returning non-zero stops the traversal. */
typedef int (*sw_sg_visit_fn)(void *ctx, uint32_t face, const double world[12],
                              const float color[4]);
/* Walks the tree from the root. Precondition: SW_SG_SEC_NODES required and validated. Returns
 * SW_OK (also when the visitor stopped it) or SW_ERR_OUT_OF_MEMORY when its stack could not grow,
 * in which case some occurrences were not visited. */
sw_result sw_sg_scene_traverse(const sw_sg_scene *scene, sw_sg_visit_fn visit, void *ctx);
/* The same walk for mesh occurrences: `node` is the MESH node drawing mesh `mesh`. Returns as
 * sw_sg_scene_traverse. Costs a walk of every node: callers skip it when n_meshes is 0. */
typedef int (*sw_sg_mesh_visit_fn)(void *ctx, uint32_t mesh, uint32_t node, const double world[12],
                                   const float color[4]);
sw_result sw_sg_scene_traverse_meshes(const sw_sg_scene *scene, sw_sg_mesh_visit_fn visit,
                                      void *ctx);
/* The same walk for shape occurrences (`mesh` is then the shape's index). Callers skip it when
 * n_shapes is 0. */
sw_result sw_sg_scene_traverse_shapes(const sw_sg_scene *scene, sw_sg_mesh_visit_fn visit,
                                      void *ctx);
/* The box (x0, y0, x1, y1) of the control points of a shape's curves; none: an empty box. */
void sw_sg_shape_box(const sw_sg_scene_view *v, uint32_t first_loop, uint32_t n_loops,
                     double box[4]);
/* The box (min xyz, max xyz) of n points (3 doubles each); n = 0 gives an empty box (min > max). */
void sw_sg_mesh_box(const double *positions, uint32_t n, double box[6]);
/* Borrowed arrays of mesh `mesh` (index valid): positions (3 per vertex), normals (NULL: flat)
 * and its 3 * n_triangles indices. */
void sw_sg_scene_mesh(const sw_sg_scene *scene, uint32_t mesh, const double **positions,
                      const double **normals, const uint32_t **indices);

/* ---- building -------------------------------------------------------------------------------- */
typedef struct sw_sg_builder sw_sg_builder;

SW_MODULE_ABI sw_sg_builder *sw_sg_builder_create(void); /* NULL when out of memory */
SW_MODULE_ABI void sw_sg_builder_free(sw_sg_builder *b); /* NULL allowed */
/* Appends doubles to the pool; returns their offset, or UINT64_MAX when out of memory. */
SW_MODULE_ABI uint64_t sw_sg_builder_push_doubles(sw_sg_builder *b, const double *values,
                                                  size_t count);
/* Appends a NUL-terminated string; returns its byte offset, or SW_SG_NONE on failure. */
uint32_t sw_sg_builder_push_string(sw_sg_builder *b, const char *s);
/* Append records; each returns the new index, or SW_SG_NONE when out of memory. */
SW_MODULE_ABI uint32_t sw_sg_builder_add_face(sw_sg_builder *b, const sw_sg_face_rec *face);
SW_MODULE_ABI uint32_t sw_sg_builder_add_loop(sw_sg_builder *b, const sw_sg_loop_rec *loop);
SW_MODULE_ABI uint32_t sw_sg_builder_add_curve(sw_sg_builder *b, const sw_sg_curve_rec *curve);
SW_MODULE_ABI uint32_t sw_sg_builder_add_adjacency(sw_sg_builder *b, uint32_t face_a,
                                                   uint32_t face_b);
/* Appends vertex indices to the INDICES section; returns their offset, or UINT64_MAX. */
uint64_t sw_sg_builder_push_indices(sw_sg_builder *b, const uint32_t *indices, size_t count);
/* A mesh whose arrays were pushed: its box is computed here from the positions (rec->box is
 * ignored). Returns the new index, or SW_SG_NONE when out of memory. Offsets are checked by
 * sw_sg_builder_finish (precondition here: the positions lie inside the pool). */
uint32_t sw_sg_builder_add_mesh(sw_sg_builder *b, const sw_sg_mesh_rec *mesh);
/* A shape whose loops were added: its box is computed here from their curves (rec->box is
 * ignored; precondition: the loops and their curves are in the builder). Returns the new index,
 * or SW_SG_NONE when out of memory. */
uint32_t sw_sg_builder_add_shape(sw_sg_builder *b, const sw_sg_shape_rec *shape);
/* Adds a node as the last child of `parent` (SW_SG_NONE: a detached node, e.g. a prototype);
 * links parent/first_child/next_sibling itself. xform NULL = identity, color NULL = inherit. */
SW_MODULE_ABI uint32_t sw_sg_builder_add_node(sw_sg_builder *b, sw_sg_node_kind kind,
                                              uint32_t parent, uint32_t ref, const double xform[12],
                                              const float color[4], const char *name);
/* Mutable access while building (valid until the next add/push call). */
double *sw_sg_builder_pool_ptr(sw_sg_builder *b);
SW_MODULE_ABI sw_sg_face_rec *sw_sg_builder_face_ptr(sw_sg_builder *b, uint32_t face);
uint32_t sw_sg_builder_face_count(const sw_sg_builder *b);
/* Sets the root node (default: node 0, created by sw_sg_builder_create as a group). */
void sw_sg_builder_set_root(sw_sg_builder *b, uint32_t node);
/* Validates and turns the builder into an immutable scene; the builder is consumed (freed) in all
 * cases. Errors: SW_ERR_INVALID_GEOMETRY / SW_ERR_FORMAT with the offending record. */
SW_MODULE_ABI sw_result sw_sg_builder_finish(sw_sg_builder *b, sw_sg_scene **out,
                                             sw_status *status);

/* ---- .sws files (sws_file.c) ----------------------------------------------------------------- */
/* Writes PATH through the project's one writer (sw_safe_write.h): replaced whole or left as it
 * was, nothing left behind on failure; a character device or FIFO is written directly, a
 * symbolic link written through. Errors: those of sw_sg_scene_require, SW_ERR_IO (a full disk
 * too), SW_ERR_NOT_FOUND (no such directory), SW_ERR_NOT_REGULAR_FILE (PATH is a directory),
 * SW_ERR_OUT_OF_MEMORY. */
sw_result sw_sg_scene_save(sw_sg_scene *scene, const char *path, sw_status *status);
/* As sw_sg_scene_save, with lods_size bytes at lods as the file's optional LODS section (the
 * static-LOD cache, lod/static/static_lod_io.c); lods NULL or lods_size 0 writes none.
 * sw_sg_scene_save keeps a mapped scene's LODS section (verified first). Same errors. */
sw_result sw_sg_scene_save_lods(sw_sg_scene *scene, const char *path, const void *lods,
                                size_t lods_size, sw_status *status);
/* The LODS section of a mapped scene, checked against its checksum on every call (it is read
 * once per renderer). *data stays valid while the scene lives. Errors: SW_ERR_NOT_FOUND (no such
 * section: a scene in memory or a file without one), SW_ERR_CHECKSUM. Any thread. */
sw_result sw_sg_scene_lods(const sw_sg_scene *scene, const void **data, size_t *size,
                           sw_status *status);
/* Hands the memory of the LODS section's pages back once its reader has decoded it (they are
 * read from the file again if it is read again: *data of sw_sg_scene_lods stays valid). The
 * checksum pass of sw_sg_scene_lods already does so behind itself. No-op for a scene in memory.
 * Any thread. */
void sw_sg_scene_lods_release(const sw_sg_scene *scene);
/* Maps a .sws file. Checks the header, version, the section table and that the file is as long as
 * the table says (a short mapping would raise SIGBUS); checksums are verified per section by
 * sw_sg_scene_require. Opens without blocking and accepts a regular file only
 * (sw_safe_read.h). Errors: SW_ERR_NOT_FOUND, SW_ERR_NOT_REGULAR_FILE (a directory, FIFO or
 * device), SW_ERR_IO, SW_ERR_FORMAT, SW_ERR_VERSION,
 * SW_ERR_TRUNCATED, SW_ERR_CHECKSUM (the header's own CRC over itself and the section table, or the
 * 16-byte META section, both checked at open); the message names the file and the byte offset. */
sw_result sw_sg_scene_open(const char *path, sw_sg_scene **out, sw_status *status);
/* The same checks on the bytes of a .sws file already in memory (copied: the caller keeps its
 * buffer); `name` stands for the path in messages and sw_sg_scene_path_ptr. The scene then
 * behaves as a mapped one. Errors: as sw_sg_scene_open's, but for those of the file system, and
 * SW_ERR_OUT_OF_MEMORY. */
sw_result sw_sg_scene_open_bytes(const void *data, size_t size, const char *name,
                                 sw_sg_scene **out, sw_status *status);

/* ---- statistics (scene_stats.c) -------------------------------------------------------------- */
typedef struct sw_sg_scene_stats {
    uint32_t faces, faces_by_kind[SW_SG_KIND_COUNT];
    uint32_t trimmed_faces, loops, curves;
    uint64_t bezier_patches; /* after extraction of every face */
    uint32_t max_deg_u, max_deg_v, max_curve_degree;
    uint64_t control_points;
    uint32_t nodes, instances;
    uint64_t face_occurrences; /* faces drawn after instance expansion */
    uint32_t adjacency;
    double bbox[6]; /* world box of the faces sampled over their trim boxes, and of
                       the meshes' vertices */
    size_t memory_bytes;
    uint32_t meshes;
    uint64_t mesh_triangles;       /* of the meshes, each counted once */
    uint64_t mesh_occurrences;     /* meshes drawn after instance expansion */
    uint64_t triangle_occurrences; /* their triangles, instances expanded */
    uint32_t shapes;
    uint64_t shape_occurrences; /* shapes drawn after instance expansion */
} sw_sg_scene_stats;
/* Precondition: SW_SG_SEC_ALL required. Returns SW_OK or SW_ERR_OUT_OF_MEMORY (traversal). */
sw_result sw_sg_scene_compute_stats(const sw_sg_scene *scene, sw_sg_scene_stats *out);

#ifdef __cplusplus
}
#endif
#endif
