/* SPDX-License-Identifier: MIT */
/* Assemblies: a part used twice at different locations must become one prototype subtree drawn by
 * two INSTANCE nodes with the locations' transforms, converted once. Checked for a BREP compound
 * (TopoDS sharing) and for a STEP assembly written by OCCT's own XCAF writer (names, colours).
 * The reference is OCCT: the files are made here with BRepPrimAPI and STEPCAFControl_Writer. */
#include "occt_test_util.hpp"

#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <Quantity_Color.hxx>
#include <STEPCAFControl_Writer.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopoDS_Compound.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>

#include <cmath>
#include <cstring>
#include <unistd.h>

namespace
{

int failures = 0;
#define CHECK(cond)                                                                                \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            std::printf("FAIL %s:%d: %s\n", __FILE__, __LINE__, #cond);                            \
            failures++;                                                                            \
        }                                                                                          \
    } while (0)

TopLoc_Location translation(double x, double y, double z)
{
    gp_Trsf t;
    t.SetTranslation(gp_Vec(x, y, z));
    return TopLoc_Location(t);
}

/* INSTANCE nodes, and the faces under each one's prototype. */
struct tree_stats {
    std::vector<uint32_t> instances;
    uint32_t surfaces = 0;
};

void walk(const sw_sg_scene_view *v, uint32_t n, tree_stats &ts)
{
    for (uint32_t c = v->nodes[n].first_child; c != SW_SG_NONE; c = v->nodes[c].next_sibling) {
        if (v->nodes[c].kind == SW_SG_NODE_INSTANCE)
            ts.instances.push_back(c);
        ts.surfaces += v->nodes[c].kind == SW_SG_NODE_SURFACE;
        walk(v, c, ts);
    }
}

/* The two instances share one prototype with `faces` faces, translated by the two offsets. */
void check_instances(const ot::imported &im, uint32_t faces, const double off[2][3])
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(im.scene);
    tree_stats ts;
    walk(v, v->root, ts);
    CHECK(ts.instances.size() == 2);
    CHECK(v->n_faces == faces + 6); /* the prototype's faces once, plus the lone box */
    CHECK(im.report.faces_read == faces + 6);
    if (ts.instances.size() != 2)
        return;
    const sw_sg_node_rec &a = v->nodes[ts.instances[0]], &b = v->nodes[ts.instances[1]];
    CHECK(a.ref == b.ref && a.ref < v->n_nodes);
    CHECK(v->nodes[a.ref].parent == SW_SG_NONE);
    tree_stats proto;
    walk(v, a.ref, proto);
    CHECK(proto.surfaces == faces);
    for (int k = 0; k < 2; k++) {
        const sw_sg_node_rec &n = v->nodes[ts.instances[k]];
        for (int c = 0; c < 3; c++)
            CHECK(std::fabs(n.xform[c * 4 + 3] - off[k][c]) < 1e-12);
        CHECK(n.xform[0] == 1 && n.xform[5] == 1 && n.xform[10] == 1);
    }
    /* the instanced faces are drawn twice by the traversal */
    long visits = 0;
    sw_sg_scene_traverse(
        im.scene,
        [](void *ctx, uint32_t, const double *, const float *) {
            ++*static_cast<long *>(ctx);
            return 0;
        },
        &visits);
    CHECK(visits == 2 * (long)faces + 6);
}

void test_brep_compound(const std::string &dir)
{
    TopoDS_Shape cyl = BRepPrimAPI_MakeCylinder(1.0, 3.0).Shape();
    TopoDS_Shape box = BRepPrimAPI_MakeBox(gp_Pnt(-5, -5, -1), 2, 2, 2).Shape();
    TopoDS_Compound c;
    BRep_Builder bb;
    bb.MakeCompound(c);
    bb.Add(c, cyl.Located(translation(10, 0, 0)));
    bb.Add(c, cyl.Located(translation(0, 20, 5)));
    bb.Add(c, box);
    const std::string path = dir + "/shared.brep";
    CHECK(BRepTools::Write(c, path.c_str()));
    ot::imported im;
    CHECK(ot::import(path, im));
    if (im.scene) {
        const double off[2][3] = {{10, 0, 0}, {0, 20, 5}};
        check_instances(im, 3, off);
        std::printf("brep compound: %u faces, %u nodes, %u adjacent pairs\n",
                    sw_sg_scene_view_ptr(im.scene)->n_faces,
                    sw_sg_scene_view_ptr(im.scene)->n_nodes,
                    sw_sg_scene_view_ptr(im.scene)->n_adjacency);
        /* cylinder: 3 faces, each bounded by the seam or a circle shared with another */
        CHECK(sw_sg_scene_view_ptr(im.scene)->n_adjacency == 2 + 12);
    }
    unlink(path.c_str());
}

void test_step_assembly(const std::string &dir)
{
    Handle(XCAFApp_Application) app = XCAFApp_Application::GetApplication();
    Handle(TDocStd_Document) doc;
    app->NewDocument("MDTV-XCAF", doc);
    Handle(XCAFDoc_ShapeTool) st = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
    Handle(XCAFDoc_ColorTool) ct = XCAFDoc_DocumentTool::ColorTool(doc->Main());
    TDF_Label part = st->AddShape(BRepPrimAPI_MakeCylinder(1.0, 3.0).Shape(), Standard_False);
    TDataStd_Name::Set(part, "rod");
    ct->SetColor(part, Quantity_Color(0.8, 0.1, 0.1, Quantity_TOC_RGB), XCAFDoc_ColorSurf);
    TDF_Label lone =
        st->AddShape(BRepPrimAPI_MakeBox(gp_Pnt(-5, -5, -1), 2, 2, 2).Shape(), Standard_False);
    TDataStd_Name::Set(lone, "block");
    TDF_Label asm_ = st->NewShape();
    TDataStd_Name::Set(asm_, "frame");
    st->AddComponent(asm_, part, translation(10, 0, 0));
    st->AddComponent(asm_, part, translation(0, 20, 5));
    st->AddComponent(asm_, lone, TopLoc_Location());
    st->UpdateAssemblies();
    const std::string path = dir + "/assembly.step";
    STEPCAFControl_Writer w;
    CHECK(w.Transfer(doc, STEPControl_AsIs));
    CHECK(w.Write(path.c_str()) == IFSelect_RetDone);
    app->Close(doc);

    ot::imported im;
    CHECK(ot::import(path, im));
    if (im.scene) {
        const double off[2][3] = {{10, 0, 0}, {0, 20, 5}};
        check_instances(im, 3, off);
        const sw_sg_scene_view *v = sw_sg_scene_view_ptr(im.scene);
        bool rod = false, frame = false, red = false;
        for (uint32_t i = 0; i < v->n_nodes; i++) {
            const sw_sg_node_rec &n = v->nodes[i];
            if (n.name != SW_SG_NONE) {
                rod |= !std::strcmp(v->strings + n.name, "rod");
                frame |= !std::strcmp(v->strings + n.name, "frame");
            }
            red |= n.color[3] > 0 && std::fabs(n.color[0] - 0.8f) < 1e-3f &&
                   std::fabs(n.color[1] - 0.1f) < 1e-3f;
        }
        CHECK(rod && frame && red);
        std::printf("step assembly: %u faces, %u nodes, names %d %d, colour %d\n", v->n_faces,
                    v->n_nodes, rod, frame, red);
    }
    unlink(path.c_str());
}

} // namespace

int main()
{
    char tmpl[] = "/tmp/sw-import-asm-XXXXXX";
    if (!mkdtemp(tmpl))
        return 2;
    test_brep_compound(tmpl);
    test_step_assembly(tmpl);
    rmdir(tmpl);
    std::printf(failures ? "FAIL (%d)\n" : "PASS\n", failures);
    return failures ? 1 : 0;
}
