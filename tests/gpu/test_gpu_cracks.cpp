/* SPDX-License-Identifier: MIT */
/* Cracks between faces (Guthe et al. 2005 §7.1; gpu/crack_fill.c): faces are tessellated
 * independently, so along a shared edge each face's drawn border may miss the exact edge by up to
 * ε_img and sub-pixel cracks open between them. A crack pixel is a background pixel of our frame
 * where the independent reference covers the pixel and its 8 neighbours (so that silhouettes,
 * which may move by ε_img, are not counted):
 *  - B-rep files: the reference is OCCT's BRepMesh of the same file (1e-4 x the diagonal, drawn
 *    by sw_gpu_render_triangles with the same camera); closed solids only, so that no view looks
 *    through a gap the model really has;
 *  - .tsm T-splines (one surface without holes): the reference is the filled outline of our own
 *    frame (background pixels not connected to the image border through background).
 * Each view is rendered with crack filling off (the count is reported: it shows what the fat
 * borders close) and on (the count must be 0).
 *
 * With --hierarchy faces are drawn from their bicubic hierarchies (§6-§7): neighbouring nodes of
 * one face are then different bicubics at different densities, and their own fat borders must
 * close those cracks too.
 *
 * With --static (implies --hierarchy) the scene's static LODs (Kumar §4, gpu/frame_static.c) are
 * forced: super-surface i at level (i + K) mod (levels + 1), the last value meaning the per-frame
 * trim-texture path, for K = 1 and 2 in every view — neighbouring super-surfaces at different
 * levels, and static beside per-frame, so every kind of join shows.
 *
 * Usage: test_gpu_cracks [--hierarchy | --static] OUTDIR FILE...   (.brep / .step / .tsm)
 */
#include "occt_reference.hpp" /* tests/support */

#include <cstring>
#include "hierarchy_support.h"
#include "sw_gpu_internal.h"
#include "sw_lod_face_cones.h"
#include "sw_sg_bvh.h"
#include "sw_sg_import.h"
#include "sw_sg_tspline.h"

#include <cmath>
#include <cstdio>
#include <vector>

namespace
{

const int k_width = 1280, k_height = 720;
bool g_hierarchy = false; /* --hierarchy */
bool g_static = false;    /* --static */
sw_lod_cache *g_cache = nullptr;
sw_lod_static_set *g_statics = nullptr;
sw_lod_face_cones *g_cones = nullptr; /* the scene's, as the renderer passes them */
sw_sg_bvh *g_bvh = nullptr;           /* likewise */
uint64_t g_quads_away = 0;            /* ribbon quads left out on closed shells' backs */
uint32_t g_levels_seen = 0; /* --static: bit k level k drawn in some view, bit 31 per-frame */

sw_gpu_camera view_camera(const double b[6], const double dir_in[3], double far_factor)
{
    sw_gpu_camera c{};
    double diag =
        std::sqrt(std::pow(b[3] - b[0], 2) + std::pow(b[4] - b[1], 2) + std::pow(b[5] - b[2], 2));
    double dist = diag / (2.0 * std::tan(20.0 * M_PI / 180.0)) * 1.1 * far_factor;
    double n = std::sqrt(dir_in[0] * dir_in[0] + dir_in[1] * dir_in[1] + dir_in[2] * dir_in[2]);
    for (int k = 0; k < 3; ++k) {
        c.target[k] = 0.5 * (b[k] + b[3 + k]);
        c.eye[k] = c.target[k] + dir_in[k] / n * dist;
    }
    c.up[2] = 1.0;
    c.fovy_deg = 40.0;
    return c;
}

bool covered(const sw_gpu_image &img, int x, int y)
{
    return img.rgba[4 * ((size_t)y * (size_t)img.width + (size_t)x) + 3] != 0;
}

/* Pixel and its 8 neighbours covered. */
bool covered_core(const sw_gpu_image &img, int x, int y)
{
    if (x < 1 || y < 1 || x + 1 >= img.width || y + 1 >= img.height)
        return false;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
            if (!covered(img, x + dx, y + dy))
                return false;
    return true;
}

/* A crack shows what lies behind the surface: the background, or for a closed solid the inside
 * of its far side. Counted where the reference covers the pixel and its neighbours at one depth
 * (within tol, not at a depth edge), and our frame is background there or farther than tol. */
long cracks_against(const sw_gpu_image &ours, const sw_gpu_image &ref, double focal_px,
                    double deflection)
{
    long n = 0;
    for (int y = 0; y < ours.height; ++y)
        for (int x = 0; x < ours.width; ++x) {
            if (!covered_core(ref, x, y))
                continue;
            size_t i = (size_t)y * (size_t)ours.width + (size_t)x;
            double z = ref.depth[i], tol = 2.0 * z / focal_px + deflection;
            bool flat = true;
            for (int dy = -1; dy <= 1 && flat; ++dy)
                for (int dx = -1; dx <= 1 && flat; ++dx)
                    flat =
                        std::fabs(ref.depth[i + (size_t)((long)dy * ours.width + dx)] - z) <= tol;
            if (flat && (!covered(ours, x, y) || ours.depth[i] > z + tol))
                ++n;
        }
    return n;
}

/* Background pixels not reachable from the border through background (4-connected). */
long enclosed_background(const sw_gpu_image &img)
{
    int w = img.width, h = img.height;
    std::vector<unsigned char> seen((size_t)w * (size_t)h, 0);
    std::vector<int> stack;
    auto push = [&](int x, int y) {
        size_t i = (size_t)y * (size_t)w + (size_t)x;
        if (!seen[i] && !covered(img, x, y)) {
            seen[i] = 1;
            stack.push_back((int)i);
        }
    };
    for (int x = 0; x < w; ++x) {
        push(x, 0);
        push(x, h - 1);
    }
    for (int y = 0; y < h; ++y) {
        push(0, y);
        push(w - 1, y);
    }
    while (!stack.empty()) {
        int i = stack.back(), x = i % w, y = i / w;
        stack.pop_back();
        if (x > 0)
            push(x - 1, y);
        if (x + 1 < w)
            push(x + 1, y);
        if (y > 0)
            push(x, y - 1);
        if (y + 1 < h)
            push(x, y + 1);
    }
    long n = 0;
    for (size_t i = 0; i < seen.size(); ++i)
        n += !seen[i] && img.rgba[4 * i + 3] == 0;
    return n;
}

bool render(sw_gpu_context *ctx, const sw_sg_scene *scene, const sw_gpu_frame_desc &desc, int fill,
            sw_gpu_image &img, sw_gpu_frame_stats &fs)
{
    sw_status st{};
    sw__gpu_set_crack_fill(ctx, fill);
    sw_result r = sw_gpu_render_scene(ctx, scene, &desc, &img, &fs, &st);
    sw__gpu_set_crack_fill(ctx, 1);
    if (r != SW_OK)
        std::fprintf(stderr, "render: %s\n", st.message);
    return r == SW_OK;
}

const double k_dirs[4][3] = {{1, 1, 1}, {0, -1, 0.2}, {-1, 0.6, 0.5}, {0.7, -0.4, -0.8}};

bool run_view(sw_gpu_context *ctx, const sw_sg_scene *scene, const sw_test::occt_triangles *ref, double deflection,
              const double box[6], int view, int force, const std::string &prefix_in)
{
    const std::string prefix = force ? prefix_in + "_static" + std::to_string(force) : prefix_in;
    sw_gpu_frame_desc desc{};
    desc.static_lods = g_statics;
    desc.static_force = force;
    desc.width = k_width;
    desc.height = k_height;
    desc.want_depth = 1;
    /* static: 3x farther, so that several levels of a super-surface are good enough */
    desc.camera = view_camera(box, k_dirs[view], force ? 3.0 : 1.0);
    desc.hierarchies = g_cache;
    sw_gpu_image off{}, on{}, theirs{};
    sw_gpu_frame_stats fs_off{}, fs_on{};
    if (!render(ctx, scene, desc, 0, off, fs_off))
        return false;
    /* filled as the renderer draws: with the face cones and the BVH, closed shells' backs culled
     * and, the eye being outside the solids, their ribbons' backs left out: no crack may open */
    desc.face_cones = g_cones;
    desc.bvh = g_bvh;
    if (!render(ctx, scene, desc, 1, on, fs_on))
        return false;
    g_quads_away += fs_on.border_quads_away;
    long c_off, c_on;
    if (ref) {
        sw_status st{};
        if (sw_gpu_render_triangles(ctx, ref->pos.data(), (uint32_t)(ref->pos.size() / 3),
                                    ref->idx.data(), (uint32_t)ref->idx.size(), &desc, &theirs,
                                    &st) != SW_OK) {
            std::fprintf(stderr, "reference render: %s\n", st.message);
            return false;
        }
        double focal = k_height / (2.0 * std::tan(20.0 * M_PI / 180.0));
        c_off = cracks_against(off, theirs, focal, deflection);
        c_on = cracks_against(on, theirs, focal, deflection);
    } else {
        c_off = enclosed_background(off);
        c_on = enclosed_background(on);
    }
    std::printf("%s view %d: crack pixels without fat borders %ld, with %ld (%llu triangles, of "
                "which fat borders %llu, %llu ribbon quads facing away left out; draw %.1f ms vs "
                "%.1f ms)%s\n",
                prefix.c_str(), view, c_off, c_on, (unsigned long long)fs_on.triangles,
                (unsigned long long)fs_on.border_triangles,
                (unsigned long long)fs_on.border_quads_away, fs_on.ms_draw, fs_off.ms_draw,
                c_on ? "  <-- FAIL" : "");
    if (force)
        std::printf("%*s static: %llu super-surface instances (%llu faces, %llu triangles), %llu "
                    "faces per frame\n",
                    (int)prefix.size(), "", (unsigned long long)fs_on.static_units_drawn,
                    (unsigned long long)fs_on.static_faces,
                    (unsigned long long)fs_on.static_triangles,
                    (unsigned long long)(fs_on.faces_drawn - fs_on.static_faces));
    if (force)
        g_levels_seen |= fs_on.static_levels_used |
                         (fs_on.faces_drawn > fs_on.static_faces ? 1u << 31 : 0u);
    sw_status st{};
    std::string path = prefix + "_v" + std::to_string(view);
    sw_gpu_image_write(&off, (path + "_nofill.png").c_str(), &st);
    sw_gpu_image_write(&on, (path + ".png").c_str(), &st);
    sw_gpu_image_free(&off);
    sw_gpu_image_free(&on);
    sw_gpu_image_free(&theirs);
    return c_on == 0;
}

bool run_file(sw_gpu_context *ctx, const std::string &path, const std::string &outdir)
{
    sw_sg_scene *scene = nullptr;
    sw_status st{};
    bool tsm = path.size() >= 4 && path.compare(path.size() - 4, 4, ".tsm") == 0;
    sw_result r;
    if (tsm) {
        r = sw_sg_tspline_import_file(path.c_str(), &scene, &st);
    } else {
        sw_sg_import_desc id{};
        id.path = path.c_str();
        r = sw_sg_import_file(&id, &scene, nullptr, &st);
    }
    if (r != SW_OK) {
        std::fprintf(stderr, "import %s: %s\n", path.c_str(), st.message);
        return false;
    }
    if (sw_lod_face_cones_build(scene, &g_cones, &st) != SW_OK ||
        sw_sg_bvh_build(scene, &g_bvh, &st) != SW_OK) {
        std::fprintf(stderr, "face cones and BVH of %s: %s\n", path.c_str(), st.message);
        sw_lod_face_cones_free(g_cones);
        g_cones = nullptr;
        sw_sg_scene_free(scene);
        return false;
    }
    g_quads_away = 0;
    sw_sg_scene_stats ss{};
    sw_sg_scene_compute_stats(scene, &ss);
    double box[6];
    std::memcpy(box, ss.bbox, sizeof box);
    sw_test::occt_triangles ref;
    double deflection = 0.0;
    if (!tsm) {
        double diag = std::sqrt(std::pow(box[3] - box[0], 2) + std::pow(box[4] - box[1], 2) +
                                std::pow(box[5] - box[2], 2));
        deflection = 1e-4 * diag;
        if (!sw_test::occt_reference_mesh(path, deflection, ref)) {
            std::fprintf(stderr, "reference mesh of %s failed\n", path.c_str());
            sw_lod_face_cones_free(g_cones);
            g_cones = nullptr;
            sw_sg_bvh_free(g_bvh);
            g_bvh = nullptr;
            sw_sg_scene_free(scene);
            return false;
        }
        for (int k = 0; k < 3; ++k) { /* frame the geometry, not the control nets */
            box[k] = INFINITY;
            box[3 + k] = -INFINITY;
        }
        for (size_t i = 0; i < ref.pos.size(); ++i) {
            box[i % 3] = std::min(box[i % 3], ref.pos[i]);
            box[3 + i % 3] = std::max(box[3 + i % 3], ref.pos[i]);
        }
    }
    size_t slash = path.find_last_of('/');
    std::string prefix =
        outdir + "/cracks_" + (slash == std::string::npos ? path : path.substr(slash + 1));
    bool ok = true;
    sw_test_hierarchies *hier = g_hierarchy ? sw_test_hierarchies_create(scene) : nullptr;
    g_cache = sw_test_hierarchies_cache(hier);
    ok = !g_hierarchy || hier;
    g_statics = g_static && hier ? sw_test_hierarchies_statics(hier) : nullptr;
    ok = ok && (!g_static || g_statics);
    for (int v = 0; v < 4 && ok; ++v) {
        if (!g_static) {
            ok = run_view(ctx, scene, tsm ? nullptr : &ref, deflection, box, v, 0, prefix) && ok;
            continue;
        }
        for (int force = 1; force <= 2; ++force)
            ok = run_view(ctx, scene, tsm ? nullptr : &ref, deflection, box, v, force, prefix) &&
                 ok;
    }
    if (g_static) {
        /* the joins must have been shown: two static levels and the per-frame path at least */
        int levels = 0;
        for (int k = 0; k < 31; ++k)
            levels += (g_levels_seen >> k) & 1u;
        std::printf("%s: static levels drawn %d (mask 0x%x), per-frame faces beside them: %s\n",
                    prefix.c_str(), levels, g_levels_seen & 0x7fffffffu,
                    (g_levels_seen >> 31) ? "yes" : "no");
        if (levels < 2 || !(g_levels_seen >> 31)) {
            std::printf("FAIL: %s: the forced mix did not show the joins\n", prefix.c_str());
            ok = false;
        }
        g_levels_seen = 0;
    }
    /* the B-rep samples are closed solids: some ribbon must have faced away, or the views above
     * did not test leaving it out */
    std::printf("%s: ribbon quads facing away left out, all views: %llu\n", prefix.c_str(),
                (unsigned long long)g_quads_away);
    if (!tsm && g_quads_away == 0) {
        std::printf("FAIL: %s: no ribbon quad was left out on a closed solid\n", prefix.c_str());
        ok = false;
    }
    sw_lod_face_cones_free(g_cones);
    g_cones = nullptr;
    sw_sg_bvh_free(g_bvh);
    g_bvh = nullptr;
    g_statics = nullptr;
    sw_test_hierarchies_free(hier);
    g_cache = nullptr;
    sw_sg_scene_free(scene);
    return ok;
}

} // namespace

int main(int argc, char **argv)
{
    bool stat = argc > 1 && std::strcmp(argv[1], "--static") == 0;
    bool hierarchy = stat || (argc > 1 && std::strcmp(argv[1], "--hierarchy") == 0);
    argc -= hierarchy;
    argv += hierarchy;
    g_static = stat;
    if (argc < 3) {
        std::fprintf(stderr, "usage: %s [--hierarchy | --static] OUTDIR FILE...\n", argv[0]);
        return 2;
    }
    g_hierarchy = hierarchy;
    sw_gpu_context *ctx = nullptr;
    sw_status st{};
    if (sw_gpu_context_create_headless(&ctx, &st) != SW_OK) {
        std::fprintf(stderr, "FAIL: %s\n", st.message);
        return 1;
    }
    bool ok = true;
    for (int i = 2; i < argc; ++i)
        ok = run_file(ctx, argv[i], argv[1]) && ok;
    sw_gpu_context_free(ctx);
    std::puts(ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}
