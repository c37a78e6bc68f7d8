/* SPDX-License-Identifier: MIT */
/* Import + trim classification against OCCT (Foundation issue, "Import of Motor-c.brep ...").
 *
 * Each file is imported; for >= 2,000 random (u, v) per trimmed face, drawn inside the face's
 * uv_box, the even-odd parity of the flattened, snapped loops (sw_sg_trim_classify) must agree with
 * BRepClass_FaceClassifier on OCCT's converted face at every sample farther than a band from the
 * boundary, and >= 98 % of the samples must lie outside the band. Two bands, both plus the
 * flattening tolerance:
 *  - the tolerance band: the face's largest edge tolerance mapped to parameter space at the
 *    nearest boundary point (tolerance over the smallest singular value of [Su Sv]); >= 98 % of
 *    all samples of the run outside it (a sloppy model, MODERN_Sink_1 with 0.17 edge tolerances
 *    on a 9-unit face, keeps a single file below that);
 *  - the gap band: the largest parameter-space gap between consecutive pcurves of the face (what
 *    snapping can move a loop by); >= 98 % of each file's samples outside it.
 * Parity must agree with OCCT at every sample outside both. Also prints the import times (read vs
 * convert). Usage: import_classify_test FILE...
 */
#include "occt_test_util.hpp"

#include "sw_sg_trim.h"

#include <BRepAdaptor_Surface.hxx>
#include <BRepClass_FaceClassifier.hxx>
#include <BRepClass_FaceExplorer.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRep_Tool.hxx>
#include <Geom2d_Curve.hxx>
#include <TopoDS_Iterator.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>

#include <algorithm>
#include <cmath>

namespace
{

const int kSamples = 2000;
const double kFlatRel = 1e-6; /* flattening tolerance, relative to the uv_box diagonal */

struct totals {
    long faces = 0, samples = 0, outside[2] = {0, 0}, disagree = 0;
    double pct(int b) const
    {
        return samples ? 100.0 * outside[b] / samples : 100.0;
    }
};

/* Largest parameter-space gap between consecutive pcurves of the face's wires (OCCT's loops are
 * closed only to within tolerance; the importer snaps them, moving each by half a gap). */
double closure_gap(const TopoDS_Face &f)
{
    double worst = 0.0;
    for (TopoDS_Iterator it(f); it.More(); it.Next()) {
        if (it.Value().ShapeType() != TopAbs_WIRE)
            continue;
        std::vector<gp_Pnt2d> ends; /* start, end of each edge along the wire */
        for (BRepTools_WireExplorer ex(TopoDS::Wire(it.Value()), f); ex.More(); ex.Next()) {
            double a, b;
            Handle(Geom2d_Curve) c = BRep_Tool::CurveOnSurface(ex.Current(), f, a, b);
            if (ex.Current().Orientation() == TopAbs_REVERSED)
                std::swap(a, b);
            ends.push_back(c->Value(a));
            ends.push_back(c->Value(b));
        }
        for (size_t k = 0; k + 1 < ends.size(); k += 2)
            worst = std::max(worst, ends[k + 1].Distance(ends[(k + 2) % ends.size()]));
    }
    return worst;
}

double face_tolerance(const TopoDS_Face &f)
{
    double t = 0.0;
    for (TopExp_Explorer ex(f, TopAbs_EDGE); ex.More(); ex.Next())
        t = std::max(t, BRep_Tool::Tolerance(TopoDS::Edge(ex.Current())));
    return t;
}

/* Nearest point of the polylines to (u, v) and its distance. */
double nearest(const std::vector<sw_sg_polyline> &pl, double u, double v, double q[2])
{
    double best = HUGE_VAL;
    for (const sw_sg_polyline &p : pl)
        for (uint32_t i = 0; i < p.count; i++) {
            const double *a = p.uv + 2 * i, *b = p.uv + 2 * ((i + 1) % p.count);
            double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
            double t = l2 > 0 ? ((u - a[0]) * dx + (v - a[1]) * dy) / l2 : 0.0;
            t = std::clamp(t, 0.0, 1.0);
            double x = a[0] + t * dx - u, y = a[1] + t * dy - v, d2 = x * x + y * y;
            if (d2 < best)
                best = d2, q[0] = x + u, q[1] = y + v;
        }
    return std::sqrt(best);
}

/* tol3 mapped to parameter distance at (u, v). */
double uv_reach(const BRepAdaptor_Surface &s, double u, double v, double tol3, double cap)
{
    u = std::clamp(u, s.FirstUParameter(), s.LastUParameter());
    v = std::clamp(v, s.FirstVParameter(), s.LastVParameter());
    gp_Pnt p;
    gp_Vec su, sv;
    s.D1(u, v, p, su, sv);
    double e = su.Dot(su), f = su.Dot(sv), g = sv.Dot(sv);
    double lmin = 0.5 * (e + g - std::sqrt((e - g) * (e - g) + 4 * f * f));
    double smin = std::sqrt(std::max(lmin, 0.0));
    return smin * cap > tol3 ? tol3 / smin : cap;
}

bool classify_face(const sw_sg_scene *scene, uint32_t fi, const TopoDS_Face &cf, ot::rng &rng,
                   totals &tot)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(scene);
    const sw_sg_face_rec &f = v->faces[fi];
    const double *bx = f.uv_box;
    const double diag = std::hypot(bx[1] - bx[0], bx[3] - bx[2]);
    const double flat = kFlatRel * diag;
    std::vector<sw_sg_polyline> pl(f.n_loops);
    for (uint32_t l = 0; l < f.n_loops; l++) {
        sw_status st{};
        if (sw_sg_trim_flatten_loop(scene, f.first_loop + l, flat, 1u << 22, &pl[l], &st) !=
            SW_OK) {
            std::printf("FAIL face %u loop %u: %s\n", fi, l, st.message);
            return false;
        }
    }
    const double tol3 = face_tolerance(cf), gap = closure_gap(cf);
    BRepAdaptor_Surface surf(cf, Standard_False);
    BRepClass_FaceExplorer fx(cf);
    BRepClass_FaceClassifier fc;
    long in_band[2] = {0, 0}, dis = 0;
    for (int k = 0; k < kSamples; k++) {
        double u = rng.uniform(bx[0], bx[1]), w = rng.uniform(bx[2], bx[3]), q[2] = {u, w};
        int mine = sw_sg_trim_classify(pl.data(), f.n_loops, u, w);
        double d = nearest(pl, u, w, q);
        const double band[2] = {flat + uv_reach(surf, q[0], q[1], tol3, diag), flat + gap};
        in_band[0] += d <= band[0], in_band[1] += d <= band[1];
        if (d <= std::min(band[0], band[1]))
            continue;
        fc.BRepClass_FClassifier::Perform(fx, gp_Pnt2d(u, w), 1e-9);
        TopAbs_State s = fc.State();
        if (mine != (s == TopAbs_IN)) {
            if (dis < 3)
                std::printf("  face %u: (%.17g, %.17g) parity %d, OCCT state %d, distance %.3g, "
                            "bands %.3g %.3g\n",
                            fi, u, w, mine, (int)s, d, band[0], band[1]);
            dis++;
        }
    }
    for (sw_sg_polyline &p : pl)
        sw_sg_polyline_free(&p);
    if (in_band[0] > kSamples / 20)
        std::printf("  face %u (%s): %ld samples in the tolerance band, %ld in the gap band; "
                    "edge tolerance %.3g, closure gap %.3g, uv_box diagonal %.3g\n",
                    fi, sw_sg_surface_kind_str(f.kind), in_band[0], in_band[1], tol3, gap, diag);
    tot.faces++, tot.samples += kSamples, tot.disagree += dis;
    tot.outside[0] += kSamples - in_band[0], tot.outside[1] += kSamples - in_band[1];
    return true;
}

bool run_file(const std::string &path, ot::rng &rng, totals &all)
{
    ot::imported im;
    if (!ot::import(path, im))
        return false;
    const sw_sg_import_report &r = im.report;
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(im.scene);
    uint32_t instances = 0;
    for (uint32_t i = 0; i < v->n_nodes; i++)
        instances += v->nodes[i].kind == SW_SG_NODE_INSTANCE;
    std::printf("%s: read %.1f ms, convert %.1f ms; faces %u read, %u converted, %u failed; "
                "%u nodes (%u instances), %u loops, %u curves, %u adjacent pairs\n",
                ot::base(path).c_str(), r.ms_read, r.ms_convert, r.faces_read, r.faces_converted,
                r.faces_failed, v->n_nodes, instances, v->n_loops, v->n_curves, v->n_adjacency);
    bool ok = true;
    if (r.faces_failed != im.warnings.size()) {
        std::printf("FAIL %u faces failed but %zu warnings\n", r.faces_failed, im.warnings.size());
        ok = false;
    }
    totals t;
    for (uint32_t fi = 0; fi < v->n_faces; fi++)
        if (v->faces[fi].flags & SW_SG_FACE_TRIMMED)
            ok &= classify_face(im.scene, fi, im.faces.converted.at(fi), rng, t);
    std::printf("  %ld trimmed faces, %ld samples, outside the tolerance band %.2f %%, outside the "
                "gap band %.2f %%, %ld disagreements\n",
                t.faces, t.samples, t.pct(0), t.pct(1), t.disagree);
    if (t.disagree > 0 || t.pct(1) < 98.0) {
        std::printf("FAIL %s\n", path.c_str());
        ok = false;
    }
    all.faces += t.faces, all.samples += t.samples, all.disagree += t.disagree;
    all.outside[0] += t.outside[0], all.outside[1] += t.outside[1];
    return ok;
}

} // namespace

int main(int argc, char **argv)
{
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s FILE...\n", argv[0]);
        return 2;
    }
    ot::rng rng(ot::seed());
    totals all;
    bool ok = true;
    for (int i = 1; i < argc; i++)
        ok &= run_file(argv[i], rng, all);
    std::printf(
        "total: %ld trimmed faces, %ld samples, outside the tolerance band %.2f %%, outside "
        "the gap band %.2f %%, %ld disagreements\n",
        all.faces, all.samples, all.pct(0), all.pct(1), all.disagree);
    if (all.pct(0) < 98.0)
        ok = false;
    std::printf(ok ? "PASS\n" : "FAIL\n");
    return ok ? 0 : 1;
}
