/* SPDX-License-Identifier: MIT */
/* Shared helpers of the import tests: importing a file while keeping OCCT's converted face of
 * every scene face (the independent reference), a seeded generator, and pass/fail bookkeeping. */
#ifndef OCCT_TEST_UTIL_HPP
#define OCCT_TEST_UTIL_HPP

#include "sw_sg_import_occt.hpp"

#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <Bnd_Box.hxx>
#include <TopoDS_Shape.hxx>
#include <gp_Trsf.hxx>

#include <cmath>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace ot
{

/* splitmix64, seeded from SW_TEST_SEED (printed) so a failure can be replayed. */
struct rng {
    uint64_t s;
    explicit rng(uint64_t seed) : s(seed) {}
    uint64_t next()
    {
        uint64_t z = (s += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    double uniform(double lo, double hi)
    {
        return lo + (hi - lo) * (double)(next() >> 11) * 0x1.0p-53;
    }
};

inline uint64_t seed()
{
    const char *e = std::getenv("SW_TEST_SEED");
    uint64_t s = e ? std::strtoull(e, nullptr, 0) : 20260501u;
    std::printf("seed %llu (set SW_TEST_SEED to replay)\n", (unsigned long long)s);
    return s;
}

struct keep_faces : sw__occt_face_observer {
    std::vector<TopoDS_Face> source, converted;
    void on_face(uint32_t face, const TopoDS_Face &src, const TopoDS_Face &conv) override
    {
        if (face >= converted.size())
            source.resize(face + 1), converted.resize(face + 1);
        source[face] = src;
        converted[face] = conv;
    }
};

struct imported {
    sw_sg_scene *scene = nullptr;
    keep_faces faces;
    sw_sg_import_report report{};
    std::vector<std::string> warnings;
    ~imported()
    {
        sw_sg_scene_free(scene);
    }
};

inline void collect_warning(void *ctx, const char *msg)
{
    static_cast<imported *>(ctx)->warnings.push_back(msg);
}

/* Imports `path`; prints the failure and returns false when it does not succeed. */
inline bool import(const std::string &path, imported &out, sw_result *result = nullptr)
{
    sw_sg_import_desc desc{};
    desc.path = path.c_str();
    desc.warning = collect_warning;
    desc.user_data = &out;
    sw_status st{};
    sw_result r = sw__occt_import_file(&desc, &out.scene, &out.report, &st, &out.faces);
    if (result)
        *result = r;
    for (const std::string &w : out.warnings)
        std::printf("  warning: %s\n", w.c_str());
    if (r != SW_OK) {
        std::printf("%s import %s: %s: %s\n", result ? "no" : "FAIL", path.c_str(),
                    sw_result_str(r), st.message);
        return false;
    }
    return true;
}

/* The shape scaled about its bounding box's centre so that the box's diagonal becomes
 * `diagonal` (0: its own size), as a unit conversion does it: BRepBuilderAPI_Transform with a
 * gp_Trsf scale, copy = true. *from gets the diagonal before, *scale the factor. */
inline bool scale_to_diagonal(const TopoDS_Shape &shape, double diagonal, TopoDS_Shape &out,
                              double *from = nullptr, double *scale = nullptr)
{
    Bnd_Box box;
    BRepBndLib::Add(shape, box);
    double x0, y0, z0, x1, y1, z1;
    box.Get(x0, y0, z0, x1, y1, z1);
    const double diag =
        std::sqrt((x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0) + (z1 - z0) * (z1 - z0));
    const double k = diagonal > 0.0 ? diagonal / diag : 1.0;
    gp_Trsf t;
    t.SetScale(gp_Pnt(0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.5 * (z0 + z1)), k);
    BRepBuilderAPI_Transform xf(shape, t, Standard_True);
    if (!xf.IsDone())
        return false;
    out = xf.Shape();
    if (from)
        *from = diag;
    if (scale)
        *scale = k;
    return true;
}

inline std::string base(const std::string &p)
{
    size_t s = p.find_last_of('/');
    return s == std::string::npos ? p : p.substr(s + 1);
}

} // namespace ot

#endif
