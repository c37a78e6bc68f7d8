/* SPDX-License-Identifier: MIT */
/* The OCCT importer's readers: STEP and IGES through XCAF (assembly tree, instances, names,
 * colours), a truncated IGES file in part, BREP files, and the walk of an XCAF document's labels
 * into the part tree; what they read is converted by import_occt.cpp.
 *
 * This is a C++ shim: no exception leaves it. Reader failures become SW_ERR_FORMAT (or
 * SW_ERR_TRUNCATED), anything else SW_ERR_INTERNAL.
 */
#include "import_occt_importer.hpp"
#include "sw_sg_trim.h"
#include "sw_status_util.h"
#include "sw_hooks.h"
#include "sw_safe_read.h"
#include "sw_sg_iges.h"
#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepGProp.hxx>
#include <BRepBuilderAPI_NurbsConvert.hxx>
#include <BRepTools.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <Geom2dConvert.hxx>
#include <Geom2d_BSplineCurve.hxx>
#include <Geom2d_TrimmedCurve.hxx>
#include <GeomConvert.hxx>
#include <GProp_GProps.hxx>
#include <Geom_BSplineSurface.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESCAFControl_Reader.hxx>
#include <IGESControl_Reader.hxx>
#include <IGESData_IGESEntity.hxx>
#include <IGESData_IGESModel.hxx>
#include <IGESGeom_BoundedSurface.hxx>
#include <IGESGeom_TrimmedSurface.hxx>
#include <IGESSolid_Face.hxx>
#include <Interface_Check.hxx>
#include <Interface_CheckIterator.hxx>
#include <Interface_EntityIterator.hxx>
#include <Interface_Graph.hxx>
#include <Interface_InterfaceModel.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_Printer.hxx>
#include <NCollection_DataMap.hxx>
#include <Quantity_ColorRGBA.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <STEPControl_Reader.hxx>
#include <StepGeom_Surface.hxx>
#include <StepShape_Face.hxx>
#include <StepShape_FaceSurface.hxx>
#include <TCollection_HAsciiString.hxx>
#include <Transfer_TransientProcess.hxx>
#include <XSControl_TransferReader.hxx>
#include <XSControl_WorkSession.hxx>
#include <Standard_Failure.hxx>
#include <TDF_LabelMapHasher.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopTools_ShapeMapHasher.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Iterator.hxx>
#include <TopoDS_Shell.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <algorithm>
#include <cctype>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <new>
#include <set>
#include <string>
#include <sys/stat.h>
#include <unordered_map>
#include <unordered_set>
#include <vector>

using namespace sw_occt;

namespace
{

std::string lower_ext(const std::string &path)
{
    size_t dot = path.find_last_of('.');
    size_t slash = path.find_last_of('/');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
        return "";
    std::string e = path.substr(dot + 1);
    for (char &c : e)
        c = (char)std::tolower((unsigned char)c);
    return e;
}

/* OCCT's readers report through the process-wide default messenger, whose printer writes to
 * stdout ("Total number of loaded entities ..." in colour) — which would corrupt `info --json` and
 * any host's output. While a file is read, the default printers are set aside and replaced by one
 * that forwards warnings and failures to the import's warning callback, and everything (the
 * chatter too) to the log hook's debug lines.
 * The messenger is global: concurrent imports share the swap (each restores what it saw). */
class forward_printer : public Message_Printer
{
  public:
    forward_printer(sw_sg_warning_fn fn, void *user, std::string prefix)
        : fn_(fn), user_(user), prefix_(std::move(prefix))
    {
        /* The chatter only when the host's logger wants debug lines (sw_setup.h). */
        myTraceLevel = sw__log_enabled(SW_LOG_DEBUG) ? Message_Info : Message_Warning;
    }

  protected:
    void send(const TCollection_AsciiString &text, const Message_Gravity gravity) const override
    {
        if (fn_ && gravity >= Message_Warning)
            fn_(user_, (prefix_ + ": OCCT: " + text.ToCString()).c_str());
        sw__log(SW_LOG_DEBUG, "%s: OCCT: %s", prefix_.c_str(), text.ToCString());
    }

  private:
    sw_sg_warning_fn fn_;
    void *user_;
    std::string prefix_;
};

class quiet_messenger
{
  public:
    quiet_messenger(sw_sg_warning_fn fn, void *user, const std::string &path)
        : messenger_(Message::DefaultMessenger()), saved_(messenger_->Printers())
    {
        messenger_->ChangePrinters().Clear();
        messenger_->AddPrinter(new forward_printer(fn, user, path));
    }
    ~quiet_messenger()
    {
        messenger_->ChangePrinters() = saved_;
    }
    quiet_messenger(const quiet_messenger &) = delete;
    quiet_messenger &operator=(const quiet_messenger &) = delete;

  private:
    Handle(Message_Messenger) messenger_;
    Message_SequenceOfPrinters saved_;
};

} // namespace

namespace sw_occt
{

sw_result importer::read_brep(TopoDS_Shape &shape, sw_status *status)
{
    shape = sw__occt_read_plain(path_.c_str());
    if (shape.IsNull())
        return sw__fail(status, SW_ERR_FORMAT, "%s: not a readable OCCT BREP file", path_.c_str());
    return SW_OK;
}

/* An IGES file's structure, before OCCT reads it (sw_sg_iges.h): a truncated file is refused,
 * or with SW_SG_IMPORT_PARTIAL read in part. A file not in fixed format is left to OCCT. */
sw_result importer::check_iges(sw_sg_iges_scan &scan, sw_status *status)
{
    char *text = nullptr;
    size_t len = 0;
    sw_result r =
        sw__in_read_all(path_.c_str(), (uint64_t)1 << 36, "IGES file", &text, &len, status);
    if (r != SW_OK)
        return r;
    sw_status st{};
    r = sw_sg_iges_scan_text(text, len, &scan, &st);
    sw__free(text);
    if (r == SW_ERR_UNSUPPORTED)
        return SW_OK;
    if (r != SW_OK)
        return sw__fail(status, r, "%s: %s", path_.c_str(), st.message);
    if (!scan.truncated)
        return SW_OK;
    const uint32_t whole = scan.entities - scan.incomplete;
    if (!(desc_->flags & SW_SG_IMPORT_PARTIAL))
        return sw__fail(status, SW_ERR_TRUNCATED,
                        "%s: truncated IGES file: %s; the data of %u of its %u entities is whole "
                        "(a partial import keeps the shapes made of those only)",
                        path_.c_str(), scan.why, whole, scan.entities);
    rep_.truncated = 1;
    warn(path_ + ": truncated IGES file: " + scan.why + "; importing in part: the data of " +
         std::to_string(whole) + " of its " + std::to_string(scan.entities) + " entities is whole");
    return SW_OK;
}

/* What is whole of a truncated IGES file: only the roots that reach no incomplete entity
 * (sw_sg_iges.h) through OCCT's graph of the file (Interface_Graph::Shareds: parameter data and
 * directory entry pointers) are transferred — OCCT neither marks nor guards an entity whose data
 * is missing (its transfer of a cut IGES B-rep face dereferenced the face's missing loop list).
 * The plain reader: XCAF transfers every root. */
sw_result importer::read_iges_partial(const sw_sg_iges_scan &scan, TopoDS_Shape &shape,
                                      sw_status *status)
{
    IGESControl_Reader r;
    if (r.ReadFile(path_.c_str()) != IFSelect_RetDone)
        return sw__fail(status, SW_ERR_TRUNCATED,
                        "%s: truncated IGES file: OCCT cannot read what is left", path_.c_str());
    Handle(IGESData_IGESModel) model = Handle(IGESData_IGESModel)::DownCast(r.Model());
    /* OCCT also makes an entity of a directory entry cut after its first record: it is not
     * among the scan's entities, so it counts as unsafe below */
    if (model.IsNull() || (uint32_t)model->NbEntities() < scan.entities ||
        (uint32_t)model->NbEntities() > scan.entities + 1)
        return sw__fail(status, SW_ERR_TRUNCATED,
                        "%s: truncated IGES file: OCCT read %d entities where %u directory "
                        "entries are present, so none can be kept safely",
                        path_.c_str(), model.IsNull() ? 0 : model->NbEntities(), scan.entities);
    auto incomplete = [&](const Handle(Standard_Transient) & t) {
        Handle(IGESData_IGESEntity) e = Handle(IGESData_IGESEntity)::DownCast(t);
        const int dn = e.IsNull() ? 0 : model->DNum(e);
        return dn < 1 || (uint32_t)(dn - 1) / 2 >= scan.entities ||
               scan.entity_incomplete[(dn - 1) / 2];
    };
    const int roots = r.NbRootsForTransfer();
    const Interface_Graph &graph = r.WS()->Graph();
    /* 0 unknown, 1 whole with all it reaches, 2 not: memoized over the shared sub-graphs */
    std::vector<uint8_t> state((size_t)model->NbEntities() + 1, 0);
    std::vector<std::pair<int, bool>> stack; /* (entity number, children pushed) */
    auto reaches_only_whole = [&](const Handle(Standard_Transient) & root) {
        stack.assign(1, {model->Number(root), false});
        while (!stack.empty()) {
            auto [n, pushed] = stack.back();
            if (n < 1 || n > model->NbEntities()) {
                stack.pop_back();
                continue;
            }
            if (state[n] != 0 && state[n] != 3) {
                stack.pop_back();
                continue;
            }
            if (!pushed) {
                stack.back().second = true;
                if (incomplete(model->Value(n))) {
                    state[n] = 2;
                    stack.pop_back();
                    continue;
                }
                state[n] = 3; /* on the stack: a cycle back to it is not a defect */
                for (Interface_EntityIterator it = graph.Shareds(model->Value(n)); it.More();
                     it.Next())
                    stack.push_back({model->Number(it.Value()), false});
                continue;
            }
            uint8_t s = 1;
            for (Interface_EntityIterator it = graph.Shareds(model->Value(n)); it.More();
                 it.Next()) {
                const int c = model->Number(it.Value());
                if (c >= 1 && c <= model->NbEntities() && state[c] == 2)
                    s = 2;
            }
            state[n] = s;
            stack.pop_back();
        }
        const int n = model->Number(root);
        return n >= 1 && n <= model->NbEntities() && state[n] == 1;
    };
    /* A root that reaches an incomplete entity is opened where it is a container of shapes
     * (group 402, solid 186, shell 514, subfigure 308/408): its whole parts are kept. */
    uint32_t kept = 0, left = 0;
    std::vector<uint8_t> visited(state.size(), 0);
    std::vector<Handle(Standard_Transient)> todo;
    for (int i = 1; i <= roots; i++)
        if (!r.RootForTransfer(i).IsNull())
            todo.push_back(r.RootForTransfer(i));
    while (!todo.empty()) {
        const Handle(Standard_Transient) e = todo.back();
        todo.pop_back();
        const int n = model->Number(e);
        if (n < 1 || n > model->NbEntities() || visited[n])
            continue;
        visited[n] = 1;
        if (reaches_only_whole(e)) {
            kept += r.TransferEntity(e) ? 1u : 0u;
            continue;
        }
        Handle(IGESData_IGESEntity) ie = Handle(IGESData_IGESEntity)::DownCast(e);
        const int type = ie.IsNull() ? 0 : ie->TypeNumber();
        if (incomplete(e) ||
            !(type == 402 || type == 186 || type == 514 || type == 308 || type == 408)) {
            left++;
            continue;
        }
        for (Interface_EntityIterator it = graph.Shareds(e); it.More(); it.Next())
            todo.push_back(it.Value());
    }
    warn(path_ + ": partial import: " + std::to_string(kept) + " entities transferred whole; " +
         std::to_string(left) + " left out (their data, or data they point at, is missing)");
    if (r.NbShapes() > 0)
        shape = r.OneShape();
    if (shape.IsNull())
        return sw__fail(status, SW_ERR_TRUNCATED, "%s: truncated IGES file: nothing whole is left",
                        path_.c_str());
    report_dropped_faces(r.WS(), false);
    return SW_OK;
}

/* STEP and IGES through XCAF (assemblies, names, colours); plain readers as the fall-back. */
sw_result importer::read_cad(Handle(TDocStd_Document) & doc, TopoDS_Shape &shape, bool step,
                             sw_status *status)
{
    const char *fmt = step ? "STEP" : "IGES";
    IFSelect_ReturnStatus rs;
    bool ok;
    if (step) {
        STEPCAFControl_Reader r;
        r.SetColorMode(true), r.SetNameMode(true), r.SetLayerMode(false);
        rs = r.ReadFile(path_.c_str());
        ok = rs == IFSelect_RetDone && r.Transfer(doc);
        if (rs == IFSelect_RetDone)
            report_dropped_faces(r.ChangeReader().WS(), true);
    } else {
        IGESCAFControl_Reader r;
        r.SetColorMode(true), r.SetNameMode(true), r.SetLayerMode(false);
        rs = r.ReadFile(path_.c_str());
        ok = rs == IFSelect_RetDone && r.Transfer(doc);
        if (rs == IFSelect_RetDone)
            report_dropped_faces(r.WS(), false);
    }
    if (rs != IFSelect_RetDone)
        return sw__fail(status, SW_ERR_FORMAT, "%s: not a readable %s file (reader status %d)",
                        path_.c_str(), fmt, (int)rs);
    if (ok) {
        st_ = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
        ct_ = XCAFDoc_DocumentTool::ColorTool(doc->Main());
        TDF_LabelSequence free;
        st_->GetFreeShapes(free);
        if (free.Length() > 0)
            return SW_OK;
        st_.Nullify(), ct_.Nullify();
    }
    /* XCAF gave nothing: the plain reader, with the shape tree only. */
    shape = sw__occt_read_plain(path_.c_str());
    if (shape.IsNull())
        return sw__fail(status, SW_ERR_FORMAT, "%s: the %s file holds no shape", path_.c_str(),
                        fmt);
    return SW_OK;
}

/* Faces OCCT's transfer dropped before they became TopoDS faces — it reports them only in its
 * transfer process's checks (a STEP face: "a Face from Shell not mapped to TopoDS", its surface
 * "Surface has not been created", e.g. for a weight of 0) — reported as skipped faces with the
 * file's entity number. The plain-reader fall-back transfers again and is not looked at. */
void importer::report_dropped_faces(const Handle(XSControl_WorkSession) & ws, bool step)
{
    if (ws.IsNull() || ws->TransferReader().IsNull() ||
        ws->TransferReader()->TransientProcess().IsNull() || ws->Model().IsNull())
        return;
    const Handle(Transfer_TransientProcess) tp = ws->TransferReader()->TransientProcess();
    const Handle(Interface_InterfaceModel) model = ws->Model();
    const Interface_CheckIterator checks = tp->CheckList(Standard_False);
    auto first_message = [](const Handle(Interface_Check) & c) -> std::string {
        std::string m = c->NbFails() > 0 ? c->CFail(1) : c->NbWarnings() > 0 ? c->CWarning(1) : "";
        const size_t a = m.find_first_not_of(' '), b = m.find_last_not_of(' ');
        return a == std::string::npos ? "" : m.substr(a, b - a + 1);
    };
    auto label = [&model](const Handle(Standard_Transient) & e) -> std::string {
        Handle(TCollection_HAsciiString) l = model->StringLabel(e);
        return l.IsNull() ? std::string("?") : std::string(l->ToCString());
    };
    std::unordered_map<const Standard_Transient *, std::string> failed;
    /* the iterator's position is shared by its copies: each loop starts it */
    Interface_CheckIterator it = checks;
    for (it.Start(); it.More(); it.Next())
        if (!it.Value()->Entity().IsNull() && it.Value()->HasFailed())
            failed[it.Value()->Entity().get()] = first_message(it.Value());
    for (it.Start(); it.More(); it.Next()) {
        const Handle(Interface_Check) &c = it.Value();
        const Handle(Standard_Transient) ent = c->Entity();
        if (ent.IsNull())
            continue;
        std::string why = first_message(c);
        if (step) {
            if (!ent->IsKind(STANDARD_TYPE(StepShape_Face)) ||
                !(c->HasFailed() || why.find("not mapped") != std::string::npos))
                continue;
            Handle(StepShape_FaceSurface) fs = Handle(StepShape_FaceSurface)::DownCast(ent);
            if (!fs.IsNull() && !fs->FaceGeometry().IsNull()) {
                auto g = failed.find(fs->FaceGeometry().get());
                if (g != failed.end())
                    why += "; its surface " + label(fs->FaceGeometry()) + ": " + g->second;
            }
        } else if (!c->HasFailed() || !(ent->IsKind(STANDARD_TYPE(IGESSolid_Face)) ||
                                        ent->IsKind(STANDARD_TYPE(IGESGeom_TrimmedSurface)) ||
                                        ent->IsKind(STANDARD_TYPE(IGESGeom_BoundedSurface)))) {
            continue;
        }
        const std::string id = label(ent);
        const size_t digit = id.find_first_of("0123456789");
        const uint32_t number = digit == std::string::npos
                                    ? 0u
                                    : (uint32_t)std::strtoul(id.c_str() + digit, nullptr, 10);
        rep_.faces_failed++, rep_.faces_dropped++;
        problem(SW_SG_NONE, SW_SG_FACE_SKIPPED, SW_ERR_INVALID_GEOMETRY,
                path_ + ": face " + id + " (" + (step ? "STEP entity" : "IGES entity") +
                    ") skipped: OCCT did not transfer it: " + why,
                number);
    }
}

/* ---- XCAF assembly tree -----------------------------------------------------------------------
 */

bool importer::label_color(const TDF_Label &l, rgba &out) const
{
    Quantity_ColorRGBA c;
    if (ct_.IsNull() ||
        !(ct_->GetColor(l, XCAFDoc_ColorSurf, c) || ct_->GetColor(l, XCAFDoc_ColorGen, c)))
        return false;
    const Quantity_Color &rgb = c.GetRGB(); /* OCCT keeps linear RGB */
    out = {{(float)rgb.Red(), (float)rgb.Green(), (float)rgb.Blue(), c.Alpha()}};
    return true;
}

std::string importer::label_name(const TDF_Label &l) const
{
    Handle(TDataStd_Name) n;
    if (!l.FindAttribute(TDataStd_Name::GetID(), n))
        return "";
    return TCollection_AsciiString(n->Get()).ToCString();
}

void importer::count_label_uses(const TDF_Label &l)
{
    if (!st_->IsAssembly(l))
        return;
    TDF_LabelSequence comps;
    st_->GetComponents(l, comps);
    for (const TDF_Label &c : comps) {
        TDF_Label ref;
        if (!st_->GetReferredShape(c, ref))
            continue;
        if (int *k = label_uses_.ChangeSeek(ref)) {
            ++*k;
        } else {
            label_uses_.Bind(ref, 1);
            count_label_uses(ref);
        }
    }
}

/* An occurrence of shape label `ref` (through component `occurrence`, or a free shape). */
void importer::add_label(const TDF_Label &ref, const TDF_Label &occurrence, uint32_t parent,
                         const TopLoc_Location &loc)
{
    rgba col;
    bool has_col = label_color(occurrence, col);
    std::string nm = label_name(occurrence);
    if (nm.empty())
        nm = label_name(ref);
    double xf[12];
    xform_of(loc, xf);
    const int *uses = label_uses_.Seek(ref);
    if (uses && *uses > 1) {
        const uint32_t *p = label_protos_.Seek(ref);
        uint32_t proto;
        if (p) {
            proto = *p;
        } else {
            rgba pc;
            bool has_pc = label_color(ref, pc);
            proto = node(SW_SG_NODE_GROUP, SW_SG_NONE, 0, nullptr, has_pc ? pc.c : nullptr,
                         label_name(ref).c_str());
            label_protos_.Bind(ref, proto);
            fill_label(ref, proto);
        }
        node(SW_SG_NODE_INSTANCE, parent, proto, xf, has_col ? col.c : nullptr, nm.c_str());
        return;
    }
    if (!has_col)
        has_col = label_color(ref, col);
    const bool ident = is_identity(loc);
    uint32_t n =
        node(ident ? SW_SG_NODE_GROUP : SW_SG_NODE_TRANSFORM, parent, 0, ident ? nullptr : xf,
             has_col ? col.c : nullptr, nm.empty() ? nullptr : nm.c_str());
    fill_label(ref, n);
}

void importer::fill_label(const TDF_Label &l, uint32_t n)
{
    if (st_->IsAssembly(l)) {
        TDF_LabelSequence comps;
        st_->GetComponents(l, comps);
        for (const TDF_Label &c : comps) {
            TDF_Label ref;
            if (st_->GetReferredShape(c, ref))
                add_label(ref, c, n, st_->GetLocation(c));
        }
        return;
    }
    /* Colours of sub-shapes (faces, shells, solids) of a part, by the faces' TShape. */
    TDF_LabelSequence subs;
    st_->GetSubShapes(l, subs);
    for (const TDF_Label &sub : subs) {
        rgba col;
        if (!label_color(sub, col))
            continue;
        for (TopExp_Explorer ex(st_->GetShape(sub), TopAbs_FACE); ex.More(); ex.Next())
            face_colors_[ex.Current().TShape().get()] = col;
    }
    const std::string outer = part_name_;
    part_name_ = label_name(l);
    add_shape(st_->GetShape(l), n);
    part_name_ = outer;
}

sw_result importer::run(uint32_t parent, const double xform[12], sw_sg_import_report *report,
                        sw_status *status)
{
    if (report)
        *report = rep_;
    /* a regular file only, before OCCT opens it: a FIFO would block its reader, a directory or
     * a device with a CAD name must say what it is (SW_ERR_NOT_REGULAR_FILE), not "not found" */
    sw_result checked = sw__in_check(path_.c_str(), 0, "CAD file", status);
    if (checked != SW_OK)
        return checked;
    const std::string ext = lower_ext(path_);
    const bool step = ext == "step" || ext == "stp", iges = ext == "iges" || ext == "igs";
    if (!step && !iges && ext != "brep")
        return sw__fail(status, SW_ERR_UNSUPPORTED,
                        "%s: unknown extension (expected .step, .stp, .iges, .igs or .brep)",
                        path_.c_str());
    struct scan_guard { /* freed on every way out */
        sw_sg_iges_scan s{};
        ~scan_guard()
        {
            sw_sg_iges_scan_free(&s);
        }
    } scan;
    if (iges) {
        checked = check_iges(scan.s, status);
        if (checked != SW_OK)
            return checked;
    }

    progress(0.0, "read");
    double t0 = now_ms();
    TopoDS_Shape shape;
    struct doc_guard { /* the XCAF document is closed on every way out */
        Handle(TDocStd_Document) doc;
        ~doc_guard()
        {
            if (!doc.IsNull())
                XCAFApp_Application::GetApplication()->Close(doc);
        }
    } guard;
    Handle(TDocStd_Document) &doc = guard.doc;
    sw_result r;
    try {
        quiet_messenger quiet(desc_->warning, desc_->user_data, path_);
        if (rep_.truncated) {
            r = read_iges_partial(scan.s, shape, status);
        } else if (step || iges) {
            XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", doc);
            r = read_cad(doc, shape, step, status);
        } else {
            r = read_brep(shape, status);
        }
    } catch (const Standard_Failure &e) {
        r = sw__fail(status, SW_ERR_FORMAT, "%s: the reader failed: %s: %s", path_.c_str(),
                     e.DynamicType()->Name(), e.GetMessageString());
    }
    rep_.ms_read = now_ms() - t0;
    if (r == SW_OK)
        return run_shape(shape, parent, xform, report, status);
    if (report)
        *report = rep_;
    return r;
}

} // namespace sw_occt

TopoDS_Shape sw__occt_read_plain(const char *path)
{
    const std::string ext = lower_ext(path);
    TopoDS_Shape shape;
    if (ext == "brep") {
        BRep_Builder bb;
        if (!BRepTools::Read(shape, path, bb))
            shape.Nullify();
    } else if (ext == "step" || ext == "stp") {
        STEPControl_Reader r;
        if (r.ReadFile(path) == IFSelect_RetDone && r.TransferRoots() > 0)
            shape = r.OneShape();
    } else if (ext == "iges" || ext == "igs") {
        IGESControl_Reader r;
        if (r.ReadFile(path) == IFSelect_RetDone && r.TransferRoots() > 0)
            shape = r.OneShape();
    }
    return shape;
}

sw_result sw__occt_import_into(sw_sg_builder *b, uint32_t parent, const double xform[12],
                               const sw_sg_import_desc *desc, sw_sg_import_report *report,
                               sw_status *status, sw__occt_face_observer *observer)
{
    if (!b || !desc || !desc->path)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "import: no builder or no path");
    return guarded(desc->path, status, [&] {
        importer imp(b, desc, observer);
        return imp.run(parent, xform, report, status);
    });
}

sw_result sw__occt_import_file(const sw_sg_import_desc *desc, sw_sg_scene **out,
                               sw_sg_import_report *report, sw_status *status,
                               sw__occt_face_observer *observer)
{
    if (!out)
        return sw__fail(status, SW_ERR_INVALID_ARGUMENT, "import: no output scene");
    *out = nullptr;
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "import: out of memory");
    sw_result r = sw__occt_import_into(b, 0, nullptr, desc, report, status, observer);
    if (r != SW_OK) {
        sw_sg_builder_free(b);
        return r;
    }
    r = sw_sg_builder_finish(b, out, status);
    if (r != SW_OK && status) { /* the scene's checks name "scene": say which file it came from */
        const std::string m = status->message;
        sw__fail(status, r, "%s: %s", desc->path, m.c_str());
    }
    return r;
}

extern "C" sw_result sw_sg_import_file(const sw_sg_import_desc *desc, sw_sg_scene **out,
                                       sw_sg_import_report *report, sw_status *status)
{
    return sw__occt_import_file(desc, out, report, status, nullptr);
}

extern "C" sw_result sw_sg_import_into(sw_sg_builder *b, uint32_t parent, const double xform[12],
                                       const sw_sg_import_desc *desc, sw_sg_import_report *report,
                                       sw_status *status)
{
    return sw__occt_import_into(b, parent, xform, desc, report, status, nullptr);
}
