/* scaled_iges IN.brep|IN.step|IN.iges OUT.iges|OUT.brep DIAGONAL [brep]
 *
 * Writes a copy of a part as IGES, uniformly scaled about its bounding-box centre so that the box
 * diagonal becomes DIAGONAL, the way a unit conversion does it (BRepBuilderAPI_Transform with a
 * gp_Trsf scale, copy = true; IGESControl_Writer turns the trims into B-spline pcurves).
 * Such copies of real parts made the first frame's trim flattening recurse at a tolerance of
 * 1e-17; tests/cli/test_scaled_iges.sh renders them. A fifth argument `brep` writes the faces as
 * an IGES B-rep (write.iges.brep.mode 1) instead of trimmed surfaces. DIAGONAL 0 keeps the
 * part's size (a plain IGES export). OUT.brep writes the scaled
 * shape as an OCCT BREP file instead (the conformance harness's scaled copies in their own
 * format). Exit status 0 on success. */
#include "occt_test_util.hpp"

#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Writer.hxx>
#include <Standard_Failure.hxx>
#include <TopoDS_Shape.hxx>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

static bool ends_with(const std::string &s, const char *suffix)
{
    std::string x(suffix);
    return s.size() >= x.size() && s.compare(s.size() - x.size(), x.size(), x) == 0;
}

int main(int argc, char **argv)
{
    if (argc != 4 && !(argc == 5 && std::string(argv[4]) == "brep")) {
        std::fprintf(stderr, "usage: %s IN OUT.iges DIAGONAL [brep]\n", argv[0]);
        return 2;
    }
    const double target = std::strtod(argv[3], nullptr);
    if (!(target >= 0.0) || !std::isfinite(target)) {
        std::fprintf(stderr, "scaled_iges: bad diagonal %s\n", argv[3]);
        return 2;
    }
    try {
        const TopoDS_Shape shape = sw__occt_read_plain(argv[1]);
        if (shape.IsNull()) {
            std::fprintf(stderr, "scaled_iges: cannot read %s\n", argv[1]);
            return 1;
        }
        TopoDS_Shape scaled;
        double diag = 0.0, scale = 1.0; /* target 0: the part's own size */
        if (!ot::scale_to_diagonal(shape, target, scaled, &diag, &scale)) {
            std::fprintf(stderr, "scaled_iges: transform failed\n");
            return 1;
        }
        if (ends_with(argv[2], ".brep")) {
            if (!BRepTools::Write(scaled, argv[2])) {
                std::fprintf(stderr, "scaled_iges: cannot write %s\n", argv[2]);
                return 1;
            }
            std::printf("%s: diagonal %.6g -> %.6g (scale %.6g)\n", argv[2], diag, target, scale);
            return 0;
        }
        IGESControl_Controller::Init();
        /* the defaults a user gets: trimmed surfaces (type 144); or B-rep faces (MSBO) */
        IGESControl_Writer w("MM", argc == 5 ? 1 : 0);
        if (!w.AddShape(scaled) || (w.ComputeModel(), !w.Write(argv[2]))) {
            std::fprintf(stderr, "scaled_iges: cannot write %s\n", argv[2]);
            return 1;
        }
        std::printf("%s: diagonal %.6g -> %.6g (scale %.6g)\n", argv[2], diag, target, scale);
    } catch (const Standard_Failure &e) {
        std::fprintf(stderr, "scaled_iges: OCCT: %s\n", e.GetMessageString());
        return 1;
    }
    return 0;
}
