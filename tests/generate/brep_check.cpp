/* SPDX-License-Identifier: MIT */
/* OCCT's own verdict on a BREP file: its faces, and how many BRepCheck_Analyzer finds invalid. */
#include <BRepCheck_Analyzer.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Shape.hxx>

#include <cstdint>

/* Returns 0 when the file was read; faces = distinct faces (TShapes), invalid = those failing. */
extern "C" int sw_test_brep_check(const char *path, uint32_t *faces, uint32_t *invalid)
{
    try {
        TopoDS_Shape s;
        BRep_Builder b;
        if (!BRepTools::Read(s, path, b) || s.IsNull())
            return 1;
        TopTools_IndexedMapOfShape map;
        TopExp::MapShapes(s, TopAbs_FACE, map);
        *faces = (uint32_t)map.Extent();
        *invalid = 0;
        for (int i = 1; i <= map.Extent(); ++i)
            *invalid += !BRepCheck_Analyzer(map(i)).IsValid();
        return 0;
    } catch (const Standard_Failure &) {
        return 2;
    }
}
