/* SPDX-License-Identifier: MIT */
/* Imported surfaces against OCCT's evaluation of the same converted faces (Foundation issue).
 *
 * (1) sw_sg_surface_eval_d2 on every imported face vs Geom_BSplineSurface::D2 of OCCT's NURBS
 *     conversion of that face, at >= 1,000 random (u, v): value error <= 1e-10 x the surface's
 *     bbox diagonal; each derivative's error <= 1e-10 x its largest magnitude over the samples
 *     (floored for derivatives that vanish identically). Where we disagree, a reference in
 *     quadruple precision decides: a sample passes only if OCCT is off it by more than 1e-11 and
 *     we are within 1e-10 of it (check_eval); such samples are counted and printed.
 *     This checks the importer's pole/weight/knot layout and the evaluator together.
 * (2) Bézier extraction (knot insertion to full multiplicity, sw_sg_surface_extract_bezier)
 *     leaves every surface unchanged: each of >= 10,000 random (u, v), evaluated in the patch that
 *     holds it, within 1e-10 x diagonal of Geom_BSplineSurface::D0.
 * Usage: import_geom_test FILE...
 */
#include "occt_test_util.hpp"

#include <BRep_Tool.hxx>
#include <GeomConvert.hxx>
#include <Geom_BSplineSurface.hxx>

#include <TColStd_Array1OfReal.hxx>

#include <algorithm>
#include <cmath>
#include <vector>

namespace
{

const int kEvalSamples = 1000, kBezierSamples = 10000;
const double kRel = 1e-10, kRelOcct = 1e-11;

struct stats {
    long faces = 0, eval_samples = 0, bezier_samples = 0, patches = 0, failures = 0;
    long arbitrated = 0, arbitrated_faces = 0; /* samples where OCCT is off the wide reference */
    double worst_value = 0, worst_deriv = 0, worst_bezier = 0; /* relative errors */
    double worst_occt_off = 0, worst_ours_there = 0; /* OCCT and ours vs the wide reference */
};

double net_diagonal(const sw_sg_surface &s)
{
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (int32_t i = 0; i < s.n_u * s.n_v; i++)
        for (int c = 0; c < 3; c++) {
            double x = s.cpw[4 * i + c] / s.cpw[4 * i + 3];
            lo[c] = std::min(lo[c], x), hi[c] = std::max(hi[c], x);
        }
    return std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
}

void domain(const sw_sg_surface &s, double d[4])
{
    sw_sg_knots_domain(s.knots_u, s.deg_u, s.n_u, &d[0], &d[1]);
    sw_sg_knots_domain(s.knots_v, s.deg_v, s.n_v, &d[2], &d[3]);
}

#if defined(__SIZEOF_FLOAT128__)
typedef __float128 wide; /* 113-bit significand: margin for (1/h)^2 on spans of 4e-8 */
#else
typedef long double wide;
#endif

/* The arbiter where we and OCCT disagree: OCCT's own surface (its poles, weights and knots, a
 * periodic one unrolled) evaluated in `wide` precision by the textbook formulas — basis functions
 * and their derivatives by Cox-de Boor (The NURBS Book A2.3) summed over the poles, then the
 * quotient rule — an algorithm unlike ours (pole differences, no basis derivatives), whose
 * cancellation the extra 60 bits absorb. It evaluates the input each evaluator really works on:
 * the homogeneous poles with w*P rounded to double, as our importer stores them and as BSplSLib
 * forms them (PrepareEval) — except where the weights of the span's poles are all equal, where
 * BSplSLib drops them and evaluates P itself, the exact polynomial. */
struct wide_surface {
    int p = 0, q = 0, nu = 0, nv = 0;
    std::vector<wide> ku, kv;
    std::vector<wide> exact, rounded; /* (w x, w y, w z, w) per pole, u fastest */
    std::vector<double> weights;

    explicit wide_surface(const Geom_BSplineSurface &g)
    {
        Handle(Geom_BSplineSurface) s = Handle(Geom_BSplineSurface)::DownCast(g.Copy());
        if (s->IsUPeriodic())
            s->SetUNotPeriodic();
        if (s->IsVPeriodic())
            s->SetVNotPeriodic();
        p = s->UDegree(), q = s->VDegree(), nu = s->NbUPoles(), nv = s->NbVPoles();
        TColStd_Array1OfReal fu(1, nu + p + 1), fv(1, nv + q + 1);
        s->UKnotSequence(fu);
        s->VKnotSequence(fv);
        ku.assign(fu.begin(), fu.end());
        kv.assign(fv.begin(), fv.end());
        for (int j = 1; j <= nv; j++)
            for (int i = 1; i <= nu; i++) {
                const gp_Pnt &x = s->Pole(i, j);
                const double w = s->Weight(i, j), c[3] = {x.X(), x.Y(), x.Z()};
                for (int d = 0; d < 3; d++) {
                    exact.push_back((wide)c[d] * w);
                    rounded.push_back(c[d] * w);
                }
                exact.push_back(w);
                rounded.push_back(w);
                weights.push_back(w);
            }
    }

    /* Span k with knots[k] <= t < knots[k+1] inside [knots[deg], knots[n]], the last one closed. */
    static int span(const std::vector<wide> &k, int deg, int n, wide t)
    {
        int s = deg;
        while (s + 1 < n && k[s + 1] <= t)
            s++;
        return s;
    }

    /* ders[k][r] = d^k N_{span-deg+r, deg}(t), k <= 2 (A2.3). */
    static void basis(const std::vector<wide> &kn, int deg, int sp, wide t, wide ders[3][32])
    {
        wide ndu[32][32], left[32], right[32], a[2][32];
        ndu[0][0] = 1;
        for (int j = 1; j <= deg; j++) {
            left[j] = t - kn[sp + 1 - j], right[j] = kn[sp + j] - t;
            wide saved = 0;
            for (int r = 0; r < j; r++) {
                ndu[j][r] = right[r + 1] + left[j - r];
                wide tmp = ndu[r][j - 1] / ndu[j][r];
                ndu[r][j] = saved + right[r + 1] * tmp;
                saved = left[j - r] * tmp;
            }
            ndu[j][j] = saved;
        }
        for (int r = 0; r <= deg; r++) {
            ders[0][r] = ndu[r][deg];
            ders[1][r] = ders[2][r] = 0;
        }
        for (int r = 0; r <= deg; r++) {
            int s1 = 0, s2 = 1;
            a[0][0] = 1;
            for (int k = 1; k <= std::min(2, deg); k++) {
                wide d = 0;
                const int rk = r - k, pk = deg - k;
                if (r >= k) {
                    a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
                    d = a[s2][0] * ndu[rk][pk];
                }
                const int j1 = rk >= -1 ? 1 : -rk, j2 = r - 1 <= pk ? k - 1 : deg - r;
                for (int j = j1; j <= j2; j++) {
                    a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j];
                    d += a[s2][j] * ndu[rk + j][pk];
                }
                if (r <= pk) {
                    a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
                    d += a[s2][k] * ndu[r][pk];
                }
                ders[k][r] = d * (k == 1 ? deg : deg * (deg - 1));
                std::swap(s1, s2);
            }
        }
    }

    /* BSplSLib's test for a locally non-rational span: every weight within Epsilon of the first. */
    bool equal_weights(double u, double v) const
    {
        const int su = span(ku, p, nu, u), sv = span(kv, q, nv, v);
        const double w0 = weights[(size_t)(sv - q) * nu + su - p];
        for (int j = sv - q; j <= sv; j++)
            for (int i = su - p; i <= su; i++)
                if (std::fabs(weights[(size_t)j * nu + i] - w0) > Epsilon(w0))
                    return false;
        return true;
    }

    /* Point and derivatives in the order of check_eval: S, Su, Sv, Suu, Suv, Svv. */
    void d2(bool use_exact, double u, double v, double out[6][3]) const
    {
        const int su = span(ku, p, nu, u), sv = span(kv, q, nv, v);
        wide bu[3][32], bv[3][32], a[3][3][4] = {};
        basis(ku, p, su, u, bu);
        basis(kv, q, sv, v, bv);
        const std::vector<wide> &poles = use_exact ? exact : rounded;
        for (int j = 0; j <= q; j++)
            for (int i = 0; i <= p; i++) {
                const wide *c = &poles[((size_t)(sv - q + j) * nu + su - p + i) * 4];
                for (int k = 0; k <= 2; k++)
                    for (int l = 0; k + l <= 2; l++)
                        for (int d = 0; d < 4; d++)
                            a[k][l][d] += bu[k][i] * bv[l][j] * c[d];
            }
        const wide w = a[0][0][3], wu = a[1][0][3], wv = a[0][1][3];
        for (int d = 0; d < 3; d++) {
            const wide s = a[0][0][d] / w, s_u = (a[1][0][d] - wu * s) / w;
            const wide s_v = (a[0][1][d] - wv * s) / w;
            out[0][d] = (double)s, out[1][d] = (double)s_u, out[2][d] = (double)s_v;
            out[3][d] = (double)((a[2][0][d] - 2 * wu * s_u - a[2][0][3] * s) / w);
            out[4][d] = (double)((a[1][1][d] - wu * s_v - wv * s_u - a[1][1][3] * s) / w);
            out[5][d] = (double)((a[0][2][d] - 2 * wv * s_v - a[0][2][3] * s) / w);
        }
    }
};

double dist(const double a[3], const double b[3])
{
    return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

double dist(const double a[3], const gp_XYZ &b)
{
    return std::hypot(a[0] - b.X(), a[1] - b.Y(), a[2] - b.Z());
}

struct sample {
    double u, v;
    double mine[6][3], theirs[6][3];
};

/* Each derivative must equal OCCT's to 1e-10 x its largest magnitude over the samples — except
 * where OCCT itself is off the wide reference by more than 1e-11 x that magnitude (OCCT
 * differences already contracted values, so knot spans of 1e-3 .. 4e-8 next to spans of 1 cost it
 * up to 1e-8 on hammer.brep, Top.brep and Bottom.brep): there ours must equal the reference to
 * 1e-10 instead. Such samples are counted and printed. */
bool check_eval(const sw_sg_surface &s, const Geom_BSplineSurface &ref, double diag, ot::rng &rng,
                const char *what, stats &st)
{
    double d[4];
    domain(s, d);
    const int order[6][2] = {{0, 0}, {1, 0}, {0, 1}, {2, 0}, {1, 1}, {0, 2}};
    std::vector<sample> sm((size_t)kEvalSamples);
    double maxmag[6] = {0};
    for (sample &x : sm) {
        x.u = rng.uniform(d[0], d[1]), x.v = rng.uniform(d[2], d[3]);
        sw_sg_surface_d2 e;
        sw_sg_surface_eval_d2(&s, x.u, x.v, &e);
        gp_Pnt p;
        gp_Vec du, dv, duu, dvv, duv;
        ref.D2(x.u, x.v, p, du, dv, duu, dvv, duv);
        const double *mine[6] = {e.p, e.du, e.dv, e.duu, e.duv, e.dvv};
        const gp_XYZ theirs[6] = {p.XYZ(), du.XYZ(), dv.XYZ(), duu.XYZ(), duv.XYZ(), dvv.XYZ()};
        for (int q = 0; q < 6; q++) {
            for (int c = 0; c < 3; c++)
                x.mine[q][c] = mine[q][c], x.theirs[q][c] = theirs[q].Coord(c + 1);
            if (q > 0)
                maxmag[q] = std::max(maxmag[q], theirs[q].Modulus());
        }
    }
    st.eval_samples += kEvalSamples;
    /* A derivative that vanishes identically (Suv of a cylinder) has a largest magnitude made of
     * rounding noise: floor it at 1 % of the size such a derivative has on a surface of this
     * extent over this domain (diag / length^order). */
    const double lu = d[1] - d[0], lv = d[3] - d[2];
    maxmag[0] = diag;
    for (int q = 1; q < 6; q++)
        maxmag[q] = std::max(maxmag[q],
                             1e-2 * diag / (std::pow(lu, order[q][0]) * std::pow(lv, order[q][1])));
    const wide_surface wref(ref);
    double worst[6] = {0};
    long arbitrated = 0, bad = 0;
    /* The arbiter itself, where it is not needed: at the first sample, wherever we and OCCT agree,
     * it must agree with OCCT too (so a broken reference cannot pass samples it arbitrates). */
    {
        const sample &x = sm[0];
        double rh[6][3];
        wref.d2(false, x.u, x.v, rh);
        for (int q = 0; q < 6; q++)
            if (dist(x.mine[q], x.theirs[q]) <= kRel * maxmag[q] &&
                !(dist(rh[q], x.theirs[q]) <= 2 * kRel * maxmag[q])) {
                std::printf("FAIL %s: the reference is off OCCT and us at (%.17g, %.17g)\n", what,
                            x.u, x.v);
                bad++;
            }
    }
    for (const sample &x : sm) {
        double rel[6];
        bool agree = true;
        for (int q = 0; q < 6; q++) {
            rel[q] = dist(x.mine[q], x.theirs[q]) / maxmag[q];
            agree &= rel[q] <= kRel;
        }
        if (agree) {
            for (int q = 0; q < 6; q++)
                worst[q] = std::max(worst[q], rel[q]);
            continue;
        }
        /* rh: what we evaluate; ro: what BSplSLib evaluates */
        double rh[6][3], ro[6][3];
        wref.d2(false, x.u, x.v, rh);
        wref.d2(wref.equal_weights(x.u, x.v), x.u, x.v, ro);
        bool occt_off = false;
        for (int q = 0; q < 6; q++) {
            if (rel[q] <= kRel)
                continue;
            const double occt_err = dist(x.theirs[q], ro[q]) / maxmag[q];
            const double ours_err = dist(x.mine[q], rh[q]) / maxmag[q];
            if (occt_err > kRelOcct && ours_err <= kRel) {
                occt_off = true;
                st.worst_occt_off = std::max(st.worst_occt_off, occt_err);
                st.worst_ours_there = std::max(st.worst_ours_there, ours_err);
            } else {
                bad++;
                worst[q] = std::max(worst[q], rel[q]);
            }
        }
        arbitrated += occt_off;
    }
    st.worst_value = std::max(st.worst_value, worst[0]);
    for (int q = 1; q < 6; q++)
        st.worst_deriv = std::max(st.worst_deriv, worst[q]);
    st.arbitrated += arbitrated;
    st.arbitrated_faces += arbitrated > 0;
    if (bad)
        std::printf("FAIL %s (deg %d x %d, %d x %d poles): %ld sample errors beyond the bounds; "
                    "worst relative errors %.3g %.3g %.3g %.3g %.3g %.3g\n",
                    what, s.deg_u, s.deg_v, s.n_u, s.n_v, bad, worst[0], worst[1], worst[2],
                    worst[3], worst[4], worst[5]);
    return bad == 0;
}

/* Index of the segment holding t among n segments whose starts are lo(i). */
template <class F> int segment_of(int n, double t, F lo)
{
    int a = 0, b = n - 1;
    while (a < b) {
        int m = (a + b + 1) / 2;
        if (lo(m) <= t)
            a = m;
        else
            b = m - 1;
    }
    return a;
}

bool check_bezier(const sw_sg_surface &s, const Geom_BSplineSurface &ref, double diag, ot::rng &rng,
                  const char *what, stats &st)
{
    sw_sg_bezier_set set{};
    sw_status status{};
    if (sw_sg_surface_extract_bezier(&s, &set, &status) != SW_OK) {
        std::printf("FAIL %s: extraction: %s\n", what, status.message);
        return false;
    }
    bool ok = true;
    const int nu = sw_sg_knots_segment_count(s.knots_u, s.deg_u, s.n_u);
    const int nv = sw_sg_knots_segment_count(s.knots_v, s.deg_v, s.n_v);
    if (set.n_u != nu || set.n_v != nv) {
        std::printf("FAIL %s: %d x %d patches, expected %d x %d\n", what, set.n_u, set.n_v, nu, nv);
        sw_sg_bezier_set_free(&set);
        return false;
    }
    double d[4];
    domain(s, d);
    double worst = 0;
    for (int k = 0; k < kBezierSamples; k++) {
        double u = rng.uniform(d[0], d[1]), v = rng.uniform(d[2], d[3]);
        int a = segment_of(set.n_u, u, [&](int i) { return set.patches[i].u0; });
        int b = segment_of(set.n_v, v, [&](int j) { return set.patches[j * set.n_u].v0; });
        const sw_sg_bezier_patch &p = set.patches[b * set.n_u + a];
        double out[3];
        sw_sg_bezier_patch_eval(&p, (u - p.u0) / (p.u1 - p.u0), (v - p.v0) / (p.v1 - p.v0), out);
        worst = std::max(worst, dist(out, ref.Value(u, v).XYZ()));
    }
    st.bezier_samples += kBezierSamples;
    st.patches += (long)set.n_u * set.n_v;
    st.worst_bezier = std::max(st.worst_bezier, worst / diag);
    if (worst > kRel * diag) {
        std::printf("FAIL %s (deg %d x %d, %d x %d patches): Bézier error %.3g, diag %.3g\n", what,
                    s.deg_u, s.deg_v, set.n_u, set.n_v, worst, diag);
        ok = false;
    }
    sw_sg_bezier_set_free(&set);
    return ok;
}

bool run_file(const std::string &path, ot::rng &rng, stats &st)
{
    ot::imported im;
    sw_result r;
    if (!ot::import(path, im, &r)) {
        /* edge.brep and asahi.brep hold wires only: the importer must say so */
        if (r == SW_ERR_FORMAT && im.report.faces_read == 0) {
            std::printf("%s: no faces, skipped\n", ot::base(path).c_str());
            return true;
        }
        std::printf("FAIL %s\n", path.c_str());
        return false;
    }
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(im.scene);
    bool ok = true;
    long fails = 0;
    for (uint32_t fi = 0; fi < v->n_faces; fi++) {
        Handle(Geom_Surface) g = BRep_Tool::Surface(im.faces.converted.at(fi));
        Handle(Geom_BSplineSurface) ref = Handle(Geom_BSplineSurface)::DownCast(g);
        if (ref.IsNull())
            ref = GeomConvert::SurfaceToBSplineSurface(g);
        sw_sg_surface s;
        sw_sg_scene_face_surface(im.scene, fi, &s);
        const double diag = net_diagonal(s);
        const std::string what = ot::base(path) + " face " + std::to_string(fi);
        bool f_ok = check_eval(s, *ref, diag, rng, what.c_str(), st);
        f_ok &= check_bezier(s, *ref, diag, rng, what.c_str(), st);
        fails += !f_ok;
        st.faces++;
    }
    std::printf("%s: %u faces, %ld failed\n", ot::base(path).c_str(), v->n_faces, fails);
    ok &= fails == 0;
    st.failures += fails;
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
    stats st;
    bool ok = true;
    for (int i = 1; i < argc; i++)
        ok &= run_file(argv[i], rng, st);
    std::printf("total: %ld faces; evaluation %ld samples, worst value error %.3g x diag, worst "
                "derivative error %.3g x max; %ld samples on %ld faces where OCCT is off the "
                "reference (by up to %.3g x max, ours by %.3g); Bézier %ld patches, %ld samples, "
                "worst %.3g x diag; %ld faces failed\n",
                st.faces, st.eval_samples, st.worst_value, st.worst_deriv, st.arbitrated,
                st.arbitrated_faces, st.worst_occt_off, st.worst_ours_there, st.patches,
                st.bezier_samples, st.worst_bezier, st.failures);
    std::printf(ok ? "PASS\n" : "FAIL\n");
    return ok ? 0 : 1;
}
