/* SPDX-License-Identifier: MIT */
/* make_assembly: a large assembly of real parts for bench_peers, as a CAD user's would be: many
 * located copies (instances) of a few parts. The parts are read once; every copy is the same
 * TopoDS_Shape under a TopLoc_Location (a rotation about z and a translation on a grid), so the
 * written BREP shares each part's geometry, `splinewalk import` turns the copies into INSTANCE
 * nodes of one prototype each, and OCCT's mesher meshes each part once. Copies are added, the
 * parts taken in turn, until the compound holds --faces faces. Deterministic: the same inputs
 * and options write the same file. */
#include "sw_sg_import_occt.hpp"

#include <BRepBndLib.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <Bnd_Box.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <gp_Ax1.hxx>
#include <gp_Trsf.hxx>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace
{

struct part {
    std::string path;
    TopoDS_Shape shape;
    size_t faces = 0;
    double centre[3] = {0, 0, 0};
    double diagonal = 0.0;
};

const char *usage = "usage: make_assembly PART... -o OUT.brep [--faces N] [--spacing F]\n"
                    "\n"
                    "Writes a BREP compound of located copies of the given parts (BREP, STEP or\n"
                    "IGES files), the parts taken in turn, each copy rotated about z and placed\n"
                    "on a square grid, until the compound holds at least N faces (default\n"
                    "50000). Copies share their part's geometry: `splinewalk import` makes\n"
                    "them instances.\n"
                    "The grid's pitch is F (default 1.2) times the largest part's box diagonal.\n";

bool load_part(const std::string &path, part &p)
{
    p.path = path;
    p.shape = sw__occt_read_plain(path.c_str());
    if (p.shape.IsNull()) {
        std::fprintf(stderr, "make_assembly: %s: not a readable BREP, STEP or IGES file\n",
                     path.c_str());
        return false;
    }
    for (TopExp_Explorer ex(p.shape, TopAbs_FACE); ex.More(); ex.Next())
        p.faces++;
    Bnd_Box box;
    BRepBndLib::Add(p.shape, box);
    if (p.faces == 0 || box.IsVoid()) {
        std::fprintf(stderr, "make_assembly: %s: no faces\n", path.c_str());
        return false;
    }
    double lo[3], hi[3];
    box.Get(lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
    for (int k = 0; k < 3; ++k)
        p.centre[k] = 0.5 * (lo[k] + hi[k]);
    p.diagonal = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                           (hi[2] - lo[2]) * (hi[2] - lo[2]));
    return true;
}

/* Copy i of part p: its box centre moved to the grid cell's centre, turned about z by a
 * multiple of 37 degrees so that neighbouring copies are seen from different sides. */
TopLoc_Location copy_location(const part &p, size_t i, size_t columns, double pitch)
{
    gp_Trsf to_origin, turn, to_cell;
    to_origin.SetTranslation(gp_Vec(-p.centre[0], -p.centre[1], -p.centre[2]));
    turn.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)),
                     (double)(i * 37 % 360) * M_PI / 180.0);
    const double x = (double)(i % columns) * pitch, y = (double)(i / columns) * pitch;
    to_cell.SetTranslation(gp_Vec(x, y, 0.0));
    return TopLoc_Location(to_cell * turn * to_origin);
}

int parse_options(int argc, char **argv, std::vector<std::string> &inputs, std::string &out,
                  size_t &faces, double &spacing)
{
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i];
        char *end = nullptr;
        if (!std::strcmp(a, "-h") || !std::strcmp(a, "--help")) {
            std::fputs(usage, stdout);
            return 0;
        } else if (!std::strcmp(a, "-o") && i + 1 < argc) {
            out = argv[++i];
        } else if (!std::strcmp(a, "--faces") && i + 1 < argc) {
            unsigned long long v = std::strtoull(argv[++i], &end, 10);
            if (*end || v == 0 || v > 100000000ull) {
                std::fprintf(stderr, "make_assembly: --faces: a count 1..1e8, got '%s'\n", argv[i]);
                return 2;
            }
            faces = (size_t)v;
        } else if (!std::strcmp(a, "--spacing") && i + 1 < argc) {
            spacing = std::strtod(argv[++i], &end);
            if (*end || !(spacing >= 1.0 && spacing <= 100.0)) {
                std::fprintf(stderr, "make_assembly: --spacing: a factor 1..100, got '%s'\n",
                             argv[i]);
                return 2;
            }
        } else if (a[0] == '-') {
            std::fprintf(stderr, "make_assembly: unknown option '%s'\n%s", a, usage);
            return 2;
        } else {
            inputs.emplace_back(a);
        }
    }
    if (inputs.empty() || out.empty()) {
        std::fputs(usage, stderr);
        return 2;
    }
    return -1;
}

} // namespace

int main(int argc, char **argv)
{
    std::vector<std::string> inputs;
    std::string out;
    size_t target = 50000;
    double spacing = 1.2;
    int rc = parse_options(argc, argv, inputs, out, target, spacing);
    if (rc >= 0)
        return rc;
    std::vector<part> parts(inputs.size());
    double largest = 0.0;
    for (size_t k = 0; k < inputs.size(); ++k) {
        if (!load_part(inputs[k], parts[k]))
            return 1;
        largest = std::max(largest, parts[k].diagonal);
    }
    /* Copies needed if the parts are taken in turn; the grid is as square as it can be. */
    size_t per_round = 0;
    for (const part &p : parts)
        per_round += p.faces;
    const size_t rounds = (target + per_round - 1) / per_round;
    const size_t copies = rounds * parts.size();
    const size_t columns = (size_t)std::ceil(std::sqrt((double)copies));
    BRep_Builder builder;
    TopoDS_Compound compound;
    builder.MakeCompound(compound);
    std::vector<size_t> used(parts.size(), 0);
    size_t faces = 0;
    for (size_t i = 0; i < copies; ++i) {
        const part &p = parts[i % parts.size()];
        builder.Add(compound, p.shape.Moved(copy_location(p, i, columns, spacing * largest)));
        used[i % parts.size()]++;
        faces += p.faces;
    }
    if (!BRepTools::Write(compound, out.c_str())) {
        std::fprintf(stderr, "make_assembly: %s: cannot be written\n", out.c_str());
        return 1;
    }
    for (size_t k = 0; k < parts.size(); ++k)
        std::printf("%s: %zu faces, box diagonal %.4g, %zu copies\n", parts[k].path.c_str(),
                    parts[k].faces, parts[k].diagonal, used[k]);
    std::printf("%s: %zu copies of %zu parts, %zu faces, grid %zu x %zu\n", out.c_str(), copies,
                parts.size(), faces, columns, (copies + columns - 1) / columns);
    return 0;
}
