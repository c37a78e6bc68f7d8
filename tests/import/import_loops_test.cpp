/* SPDX-License-Identifier: MIT */
/* Every edge of a face's wires reaches the face's trim loops, at any scale: each file is scaled
 * about its box centre to each given bounding diagonal (BRepBuilderAPI_Transform with a gp_Trsf
 * scale, copy = true: a unit conversion, as scaled_iges does), written as BREP, imported, and
 * every imported face's loops are compared with its source face's wires as OCCT's topology lists
 * them (TopExp_Explorer): one loop per wire, one trim curve per edge. A loop missing an edge is
 * snapped closed over the gap and cuts the face wrong (shell1.brep at diagonal 10,000: triangular
 * holes, 38.9 px off the reference).
 * What it catches: the importer walking the wires of the converted face (the NURBS conversion
 * re-approximates pcurves and edge tolerances, and BRepTools_WireExplorer then stopped after the
 * first of four edges on 4 of shell1's 99 faces at 10,000: planted, "face 27: loop 0 has 1
 * curves, its wire 4 edges").
 * Usage: import_loops_test DIAGONAL[,DIAGONAL...] FILE...
 */
#include "occt_test_util.hpp"

#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Iterator.hxx>

#include <cmath>
#include <sstream>
#include <vector>

namespace
{

/* Edges of each wire of a face, in the face's order of wires. */
std::vector<int> wire_edges(const TopoDS_Face &f)
{
    std::vector<int> n;
    for (TopoDS_Iterator it(f); it.More(); it.Next()) {
        if (it.Value().ShapeType() != TopAbs_WIRE)
            continue;
        int k = 0;
        for (TopExp_Explorer ex(it.Value(), TopAbs_EDGE); ex.More(); ex.Next())
            k++;
        if (k > 0)
            n.push_back(k);
    }
    return n;
}

/* Compares every imported face's loops with its source wires; returns the faces that differ. */
long check_scene(const ot::imported &im, const std::string &name)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(im.scene);
    long bad = 0;
    for (uint32_t f = 0; f < v->n_faces && f < im.faces.source.size(); f++) {
        if (im.faces.source[f].IsNull())
            continue;
        const std::vector<int> edges = wire_edges(im.faces.source[f]);
        const sw_sg_face_rec &rec = v->faces[f];
        if (edges.empty()) /* bounded by its surface's domain */
            continue;
        std::ostringstream why;
        if (edges.size() != rec.n_loops)
            why << rec.n_loops << " loops, " << edges.size() << " wires";
        for (uint32_t l = 0; l < rec.n_loops && l < edges.size() && why.str().empty(); l++) {
            const uint32_t curves = v->loops[rec.first_loop + l].n_curves;
            if ((int)curves != edges[l])
                why << "loop " << l << " has " << curves << " curves, its wire " << edges[l]
                    << " edges";
        }
        if (!why.str().empty()) {
            std::printf("FAIL %s: face %u: %s\n", name.c_str(), f, why.str().c_str());
            bad++;
        }
    }
    return bad;
}

bool run(const std::string &path, double diagonal)
{
    TopoDS_Shape shape, big;
    BRep_Builder b;
    if (!BRepTools::Read(shape, path.c_str(), b) || !ot::scale_to_diagonal(shape, diagonal, big)) {
        std::printf("FAIL %s: cannot read or scale\n", path.c_str());
        return false;
    }
    std::ostringstream name;
    name << ot::base(path) << "@" << diagonal;
    const std::string copy = "import_loops_" + ot::base(path) + ".brep";
    if (!BRepTools::Write(big, copy.c_str())) {
        std::printf("FAIL %s: cannot write %s\n", name.str().c_str(), copy.c_str());
        return false;
    }
    ot::imported im;
    if (!ot::import(copy, im))
        return false;
    const long bad = check_scene(im, name.str());
    std::printf("%s: %u faces, %ld with loops that differ from their wires\n", name.str().c_str(),
                sw_sg_scene_view_ptr(im.scene)->n_faces, bad);
    std::remove(copy.c_str());
    return bad == 0;
}

} // namespace

int main(int argc, char **argv)
{
    if (argc < 3) {
        std::fprintf(stderr, "usage: %s DIAGONAL[,DIAGONAL...] FILE...\n", argv[0]);
        return 2;
    }
    std::vector<double> diagonals;
    std::stringstream list(argv[1]);
    for (std::string d; std::getline(list, d, ',');)
        diagonals.push_back(std::strtod(d.c_str(), nullptr));
    bool ok = true;
    for (int i = 2; i < argc; i++)
        for (double d : diagonals)
            ok = run(argv[i], d) && ok;
    std::puts(ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}
