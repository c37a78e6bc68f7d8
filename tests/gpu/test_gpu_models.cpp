/* SPDX-License-Identifier: MIT */
/* Rendering, real: imported CAD models rendered by sw_gpu_render_scene (trim textures,
 * Filip grids) against an independent reference — OCCT's BRepMesh_IncrementalMesh of the same
 * file at a deflection of 1e-4 x the box diagonal, drawn through sw_gpu_render_triangles with the
 * same camera. From the iso and front views: coverage masks differ in <= 0.1 % of the covered
 * pixels, not counting pixels within 1 px of the other image's coverage (an edge may move by
 * ε_img = 0.5 px, which flips a whole row of pixels along a silhouette that runs near pixel
 * centres), where both cover a pixel the depths agree within the surface error (2 pixels' worth of
 * object size at that depth plus the reference's deflection) for >= 99 % of them, and trim
 * textures were used (patches_trimmed > 0).
 *
 * Usage: test_gpu_models OUTDIR WIDTHxHEIGHT FILE...   (frames are written to OUTDIR)
 */
#include "sw_gpu.h"
#include "sw_sg_import.h"
#include "occt_reference.hpp" /* tests/support */

#include <BRepBndLib.hxx>
#include <Bnd_Box.hxx>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace
{

sw_gpu_camera preset(const double bbox[6], bool iso)
{
    sw_gpu_camera c{};
    double diag = std::sqrt(std::pow(bbox[3] - bbox[0], 2) + std::pow(bbox[4] - bbox[1], 2) +
                            std::pow(bbox[5] - bbox[2], 2));
    double dist = diag / (2.0 * std::tan(20.0 * M_PI / 180.0)) * 1.1;
    double dir[3] = {0.0, -1.0, 0.0};
    if (iso)
        dir[0] = dir[1] = dir[2] = 1.0 / std::sqrt(3.0);
    for (int k = 0; k < 3; ++k) {
        c.target[k] = 0.5 * (bbox[k] + bbox[3 + k]);
        c.eye[k] = c.target[k] + dir[k] * dist;
    }
    c.up[2] = 1.0;
    c.fovy_deg = 40.0;
    return c;
}

struct compare_result {
    long covered_a = 0, covered_b = 0, differ = 0, both = 0, depth_bad = 0;
    long far = 0; /* differing pixels with no pixel of the other image's coverage within 1 px */
};

bool covered_near(const sw_gpu_image &img, int x, int y)
{
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            int xx = x + dx, yy = y + dy;
            if (xx >= 0 && yy >= 0 && xx < img.width && yy < img.height &&
                img.rgba[4 * ((size_t)yy * (size_t)img.width + (size_t)xx) + 3] != 0)
                return true;
        }
    return false;
}

compare_result compare(const sw_gpu_image &a, const sw_gpu_image &b, double focal_px,
                       double deflection)
{
    compare_result r;
    size_t n = (size_t)a.width * (size_t)a.height;
    for (size_t i = 0; i < n; ++i) {
        bool ca = a.rgba[4 * i + 3] != 0, cb = b.rgba[4 * i + 3] != 0;
        r.covered_a += ca;
        r.covered_b += cb;
        r.differ += ca != cb;
        if (ca != cb) {
            int x = (int)(i % (size_t)a.width), y = (int)(i / (size_t)a.width);
            r.far += !covered_near(ca ? b : a, x, y);
        }
        if (ca && cb) {
            ++r.both;
            double z = std::min(a.depth[i], b.depth[i]);
            double tol = 2.0 * z / focal_px + deflection;
            r.depth_bad += std::fabs((double)a.depth[i] - (double)b.depth[i]) > tol;
        }
    }
    return r;
}

bool write(const sw_gpu_image &img, const std::string &path)
{
    sw_status st{};
    if (sw_gpu_image_write(&img, path.c_str(), &st) != SW_OK) {
        std::fprintf(stderr, "write %s: %s\n", path.c_str(), st.message);
        return false;
    }
    return true;
}

std::string base_name(const std::string &p)
{
    size_t s = p.find_last_of('/');
    std::string b = s == std::string::npos ? p : p.substr(s + 1);
    return b.substr(0, b.find_last_of('.'));
}

bool run_view(sw_gpu_context *ctx, const sw_sg_scene *scene, const sw_test::occt_triangles &ref,
              const double bbox[6], double deflection, bool iso, int w, int h,
              const std::string &out_prefix)
{
    sw_gpu_frame_desc desc{};
    desc.width = w;
    desc.height = h;
    desc.want_depth = 1;
    desc.camera = preset(bbox, iso);
    sw_gpu_image ours{}, theirs{};
    sw_gpu_frame_stats fs{};
    sw_status st{};
    if (sw_gpu_render_scene(ctx, scene, &desc, &ours, &fs, &st) != SW_OK) {
        std::fprintf(stderr, "render: %s\n", st.message);
        return false;
    }
    if (sw_gpu_render_triangles(ctx, ref.pos.data(), (uint32_t)(ref.pos.size() / 3), ref.idx.data(),
                                (uint32_t)ref.idx.size(), &desc, &theirs, &st) != SW_OK) {
        std::fprintf(stderr, "reference render: %s\n", st.message);
        sw_gpu_image_free(&ours);
        return false;
    }
    double focal = h / (2.0 * std::tan(20.0 * M_PI / 180.0));
    compare_result c = compare(ours, theirs, focal, deflection);
    double cover_frac = (double)c.far / (double)std::max(1L, c.covered_b);
    double depth_frac = (double)c.depth_bad / (double)std::max(1L, c.both);
    std::printf("%s %s %dx%d: patches %llu trimmed / %llu untrimmed / %llu culled, %llu "
                "triangles (reference %zu), %llu trim textures; ms tessellate %.1f trim %.1f "
                "draw %.1f readback %.1f\n",
                out_prefix.c_str(), iso ? "iso" : "front", w, h,
                (unsigned long long)fs.patches_trimmed, (unsigned long long)fs.patches_untrimmed,
                (unsigned long long)fs.patches_culled, (unsigned long long)fs.triangles,
                ref.idx.size() / 3, (unsigned long long)fs.trim_textures, fs.ms_tessellate,
                fs.ms_trim, fs.ms_draw, fs.ms_readback);
    std::printf("  coverage: ours %ld, reference %ld, differ %ld, of which %ld (%.3f %% of "
                "covered) farther than 1 px from the other's coverage; depth outside tolerance at "
                "%ld of %ld common pixels (%.3f %%)\n",
                c.covered_a, c.covered_b, c.differ, c.far, 100.0 * cover_frac, c.depth_bad, c.both,
                100.0 * depth_frac);
    std::string tag = out_prefix + (iso ? "_iso" : "_front");
    bool ok = write(ours, tag + ".png") && write(theirs, tag + "_brepmesh.png");
    ok = ok && cover_frac <= 0.001 && depth_frac <= 0.01 && fs.patches_trimmed > 0;
    sw_gpu_image_free(&ours);
    sw_gpu_image_free(&theirs);
    return ok;
}

bool run_file(sw_gpu_context *ctx, const std::string &path, const std::string &outdir, int w, int h)
{
    sw_sg_import_desc id{};
    id.path = path.c_str();
    sw_sg_scene *scene = nullptr;
    sw_status st{};
    if (sw_sg_import_file(&id, &scene, nullptr, &st) != SW_OK) {
        std::fprintf(stderr, "import %s: %s\n", path.c_str(), st.message);
        return false;
    }
    sw_sg_scene_stats ss{};
    sw_sg_scene_compute_stats(scene, &ss);
    double diag =
        std::sqrt(std::pow(ss.bbox[3] - ss.bbox[0], 2) + std::pow(ss.bbox[4] - ss.bbox[1], 2) +
                  std::pow(ss.bbox[5] - ss.bbox[2], 2));
    sw_test::occt_triangles ref;
    double deflection = 1e-4 * diag;
    auto t0 = std::chrono::steady_clock::now();
    if (!sw_test::occt_reference_mesh(path, deflection, ref)) {
        std::fprintf(stderr, "reference mesh of %s failed\n", path.c_str());
        sw_sg_scene_free(scene);
        return false;
    }
    double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    /* The views frame the geometry's box (the mesh's), not the control nets' box: a plane's
     * control net may extend far beyond its trimmed face. */
    double box[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < ref.pos.size(); ++i) {
        box[i % 3] = std::min(box[i % 3], ref.pos[i]);
        box[3 + i % 3] = std::max(box[3 + i % 3], ref.pos[i]);
    }
    std::printf("%s: %u faces, BRepMesh %zu triangles in %.0f ms; box (%g %g %g)-(%g %g %g), "
                "control nets' box (%g %g %g)-(%g %g %g)\n",
                path.c_str(), ss.faces, ref.idx.size() / 3, ms, box[0], box[1], box[2], box[3],
                box[4], box[5], ss.bbox[0], ss.bbox[1], ss.bbox[2], ss.bbox[3], ss.bbox[4],
                ss.bbox[5]);
    std::string prefix = outdir + "/" + base_name(path);
    bool ok = run_view(ctx, scene, ref, box, deflection, true, w, h, prefix);
    ok = run_view(ctx, scene, ref, box, deflection, false, w, h, prefix) && ok;
    sw_sg_scene_free(scene);
    return ok;
}

} // namespace

int main(int argc, char **argv)
{
    if (argc < 4) {
        std::fprintf(stderr, "usage: %s OUTDIR WIDTHxHEIGHT FILE...\n", argv[0]);
        return 2;
    }
    int w = 0, h = 0;
    if (std::sscanf(argv[2], "%dx%d", &w, &h) != 2 || w < 16 || h < 16)
        return 2;
    sw_gpu_context *ctx = nullptr;
    sw_status st{};
    if (sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        std::fprintf(stderr, "FAIL: %s\n", st.message);
        return 1;
    }
    bool ok = true;
    for (int i = 3; i < argc; ++i)
        ok = run_file(ctx, argv[i], argv[1], w, h) && ok;
    sw_gpu_context_free(ctx);
    std::puts(ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}
