/* SPDX-License-Identifier: MIT */
/* Shared helpers of the import tests: importing a file while keeping OCCT's converted face of
 * every scene face (the independent reference), a seeded generator, and pass/fail bookkeeping. */
#ifndef OCCT_TEST_UTIL_HPP
#define OCCT_TEST_UTIL_HPP

#include "sw_sg_import_occt.hpp"

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

inline std::string base(const std::string &p)
{
    size_t s = p.find_last_of('/');
    return s == std::string::npos ? p : p.substr(s + 1);
}

} // namespace ot

#endif
