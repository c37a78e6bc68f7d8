/* SPDX-License-Identifier: MIT */
/* Test support: the independent reference of the image tests — OCCT's BRepMesh_IncrementalMesh of
 * a model file (BREP, STEP, IGES) at a given deflection, as world-space triangles (double xyz
 * positions + uint32 indices) ready for sw_gpu_render_triangles. The model is read once; each
 * mesh() call discards the previous triangulation, so a test can mesh the same model at a
 * different deflection per view, and can restrict meshing to the faces a view can see (by their
 * world-space bounding boxes) and cut them to the part of the view's frustum it shows. OCCT types
 * stay inside occt_reference.cpp.
 */
#ifndef SW_TEST_OCCT_REFERENCE_HPP
#define SW_TEST_OCCT_REFERENCE_HPP

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace sw_test
{

struct occt_triangles {
    std::vector<double> pos;   /* 3 per vertex, world space (face locations applied) */
    std::vector<uint32_t> idx; /* 3 per triangle */
    size_t faces_meshed = 0;
    /* Triangles of each face occurrence of the model (0 for faces not selected). */
    std::vector<uint32_t> triangles_per_face;
    double ms = 0.0; /* BRepMesh time */

    size_t n_vertices() const { return pos.size() / 3; }
    size_t n_triangles() const { return idx.size() / 3; }
    /* Box of the vertices (min xyz, max xyz); all zero when empty. */
    std::array<double, 6> box() const;
};

/* Is the B-rep closed, and how tightly? free_edges: non-degenerate edges bounding only one face
 * (a seam counts its face twice); max_tolerance: the largest edge or vertex tolerance, which
 * bounds how far the faces meeting there may stand apart (OCCT's tolerance model: each face's
 * boundary lies within the edge's tolerance of its 3D curve, so the gap is at most twice it). */
struct occt_closure {
    size_t edges = 0, free_edges = 0;
    double max_tolerance = 0.0;
};

/* The part of a view's frustum a reference is cut to: depths (along fwd from the eye) in
 * [z_near, z_far], and |right offset| <= tan_x depth, |up offset| <= tan_y depth (the view's
 * half-angles, with any margin). fwd, right, up: orthonormal, right = fwd x up. */
struct occt_clip_frustum {
    std::array<double, 3> eye, fwd, right, up;
    double tan_x, tan_y, z_near, z_far;
    /* Whether world point p lies inside. */
    bool contains(const double p[3]) const;
};

/* Selects a face by its world-space bounding box (min xyz, max xyz). */
using occt_face_filter = std::function<bool(const std::array<double, 6> &box)>;

class occt_model
{
  public:
    occt_model();
    ~occt_model();
    occt_model(const occt_model &) = delete;
    occt_model &operator=(const occt_model &) = delete;

    /* Reads .brep, .step/.stp or .iges/.igs (case-insensitive); false with *error set on
     * failure (error may be NULL). */
    bool read(const std::string &path, std::string *error = nullptr);
    /* Face occurrences (a face shared by two instances counts twice) and their world boxes. */
    size_t n_faces() const;
    const std::vector<std::array<double, 6>> &face_boxes() const;
    occt_closure closure() const;
    /* Box of all faces' boxes (OCCT's, which may be looser than the geometry). */
    std::array<double, 6> box() const;

    /* Meshes the selected faces (all when `keep` is empty) with BRepMesh_IncrementalMesh at an
     * absolute linear `deflection` and angular deflection `angle_rad`, in parallel, after
     * dropping any earlier triangulation, and appends nothing else: `out` is replaced. Faces
     * sharing an edge are meshed together, so their triangulations meet without cracks. With
     * `clip`, the selected faces' parts inside it (BRepAlgoAPI_Common), and triangles_per_face
     * stays 0. False when nothing could be meshed, or with `clip` when the cut fails, leaves no
     * face or leaves one BRepMesh cannot mesh (mesh the faces whole then). */
    bool mesh(double deflection, occt_triangles &out, const occt_face_filter &keep = {},
              double angle_rad = 0.5, const occt_clip_frustum *clip = nullptr);

  private:
    struct impl;
    std::unique_ptr<impl> p_;
};

/* One call: read `path` and mesh every face at `deflection` (the tests/gpu usage). */
bool occt_reference_mesh(const std::string &path, double deflection, occt_triangles &out,
                         std::string *error = nullptr);

} // namespace sw_test

#endif
