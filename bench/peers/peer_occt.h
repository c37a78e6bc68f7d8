/* SPDX-License-Identifier: MIT */
/* bench/peers: OpenCASCADE's mesher as a peer, the C side of peer_occt.cpp (a thin C++ shim that
 * lets no exception through): reads a BREP (BRepTools::Read) and meshes it with
 * BRepMesh_IncrementalMesh at an absolute linear deflection (angular deflection 0.5 rad, OCCT's
 * default; in parallel, OCCT's TBB threads), then puts every face occurrence's triangulation, moved
 * by its location, into one array of vertices (position, normal: 6 floats) and triangle indices.
 */
#ifndef BP_PEER_OCCT_H
#define BP_PEER_OCCT_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

enum { BP_OCCT_VERTEX_FLOATS = 6 };

typedef struct bp_occt_mesh {
    float *v; /* n_v * BP_OCCT_VERTEX_FLOATS, world space; malloc'd, free with bp_occt_mesh_free */
    uint32_t *idx; /* n_idx */
    size_t n_v, n_idx;
    uint64_t faces, faces_unmeshed; /* face occurrences; of them, left without a triangulation */
    double ms_read, ms_mesh;
} bp_occt_mesh;

/* Returns 0, or -1 with the reason in err (the file unreadable, no faces, out of memory, an OCCT
 * exception, more than 2^32 vertices). */
int bp_occt_mesh_brep(const char *path, double deflection, bp_occt_mesh *out, char *err,
                      size_t err_size);
void bp_occt_mesh_free(bp_occt_mesh *m);

#ifdef __cplusplus
}
#endif
#endif
