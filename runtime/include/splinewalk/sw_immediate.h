/* SPDX-License-Identifier: MIT */
/* splinewalk — the immediate API: trimmed NURBS objects drawn by handle, without a scene, and
 * host shaders around the library's GPU evaluation and trimming.
 *
 * The modern form of Guthe et al. 2005 §8 ("OpenGL API Integration", Figure 8): where the paper
 * proposes gluGenNurbsObjectsEXT / gluControlPoints4fvEXT / gluKnotVectorfvEXT /
 * gluAddTrimmingLoopEXT, here an sw_nurbs is created from one sw_nurbs_desc (sw_nodes.h: degrees,
 * knots, control points, weights, trim loops) and replaced whole by sw_nurbs_update; where it has
 * gluDrawNurbsObjectsEXT(first, count, error), sw_renderer_draw_nurbs draws a list of objects,
 * each with its model matrix and colour, at an error in pixels through a camera; and where it has
 * gluGetNurbsEvaluateShader / gluGetNurbsTrimmingShader / gluNurbsSpecialProgram,
 * sw_glsl_source_ptr hands out the library's GLSL and sw_renderer_set_shading links a host's
 * shading function into the programs the immediate draws use.
 *
 * The draw is the frame path scenes take (sw_renderer_draw): the objects are gathered into a
 * scene of their own (kept by the renderer while the same objects, unchanged, are drawn again;
 * only their model matrices and colours may change between draws), each face drawn from its
 * bicubic hierarchy (§6-§7, built in the renderer's pool) on predefined grids evaluated in the
 * vertex shader (§4.2), trimmed by trim textures (§4, atlas §4.4), cracks closed (§7.1).
 *
 * Handles: sw_nurbs is a pool index and a 16-bit generation, {0} never valid, as in
 * splinewalk.h. Threads: sw_nurbs_* may be called from any thread (one lock serialises them and
 * the draws' copies of the objects); sw_renderer_draw_nurbs and sw_renderer_set_shading only on
 * the renderer's owner thread (another thread: SW_ERR_INVALID_ARGUMENT, nothing done).
 * Ownership: descs and arrays are read during the call only.
 *
 * Host shading. sw_renderer_set_shading(renderer, source) takes GLSL (#version 430 core, no
 * #version line of its own) that defines
 *
 *     vec4 sw_shade(vec3 pos, vec3 normal, vec2 uv, vec4 color);
 *
 * and may declare its own uniforms, samplers and helper functions. It is compiled between the
 * library's fragment parts (SW_GLSL_FRAGMENT_INTERFACE, SW_GLSL_FRAGMENT_LIBRARY before it,
 * SW_GLSL_FRAGMENT_MAIN after it) and linked with each of the library's vertex stages (Bézier
 * evaluation, exact evaluation, plain meshes), so every fragment it shades was evaluated and
 * trimmed by the library. Its arguments, per fragment:
 *   pos    the surface point relative to the eye, in world axes and units (the eye is at 0:
 *          the view vector is normalize(-pos)); float
 *   normal the unit surface normal in world axes (the face's orientation: reversed faces and
 *          mirroring model matrices flipped), or 0 where it is undefined (a pole)
 *   uv     the surface's parameters (u, v) in its knot domain (exact for the vertex-shader
 *          paths, which draw every patch of degree <= 3 and every hierarchy node; on the fat
 *          borders that close cracks along trim loops, the loop's parameters to first order)
 *   color  the draw's linear RGBA colour (sw_nurbs_draw.color)
 * and it returns the fragment's colour, written as is (the library's own shading returns
 * gamma-encoded colour). SW_GLSL_FRAGMENT_LIBRARY gives it two functions to call:
 *     bool sw_trim_inside(sampler2DArray atlas, vec2 st, vec4 rect, float layer);
 *     vec4 sw_shade_library(vec3 pos, vec3 normal, vec2 uv, vec4 color);
 * (the trim lookup of §4.3 — a trim texture, or with sw_frame_desc.trim_edges exact edges read
 * from storage buffers — which main has already applied, and the library's headlight shading).
 * Names starting with sw_, u_, v_ and o_ (and the GLSL blocks SwEdge*) are the library's.
 * Bindings: the library uses texture unit 0 (the trim atlas, sampler u_trim) and shader storage
 * bindings 0-8; a host shader samples its own textures from units 1 and up, bound by the host
 * before the draw (the library does not touch other units, and gives the active unit back).
 * Host uniforms are set with glProgramUniform* on the programs sw_renderer_shading_programs
 * lists; they keep their values across draws until the shading is replaced. Other GL state
 * (program, vertex array, buffers, depth and blend state) is the renderer's after a draw, as
 * after sw_renderer_draw: set yours again; the framebuffer bindings and viewport are restored.
 */
#include <splinewalk/sw_nodes.h>
/* Its body once sw_nodes.h is complete (it includes this header at its end): a program may include
 * splinewalk.h, sw_nodes.h or this header first. */
#if !defined(SPLINEWALK_SW_IMMEDIATE_H) && defined(SPLINEWALK_SW_NODES_COMPLETE)
#define SPLINEWALK_SW_IMMEDIATE_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sw_nurbs {
    uint32_t id;
} sw_nurbs;

/* ---- objects --------------------------------------------------------------------------------- */
/* Creates a trimmed NURBS object from desc (checked as sw_node_add checks a NURBS node: degrees,
 * counts, knots non-decreasing with a non-empty domain, finite control points, positive finite
 * weights, trim loops closed, inside the domain and enclosing an area). Any thread. *out = {0}
 * on failure. Errors: SW_ERR_INVALID_ARGUMENT (NULL desc or out, NULL arrays),
 * SW_ERR_INVALID_GEOMETRY (with the index at fault), SW_ERR_LIMIT (sizes; 65,535 objects alive),
 * SW_ERR_OUT_OF_MEMORY. */
SW_API sw_result sw_nurbs_create(const sw_nurbs_desc *desc, sw_nurbs *out, sw_status *status);
/* Replaces the object's surface (any sizes, degrees and loops); the next draw of it shows the new
 * one. Any thread. Errors: those of sw_nurbs_create, and SW_ERR_STALE_HANDLE; the object keeps
 * its surface on failure. */
SW_API sw_result sw_nurbs_update(sw_nurbs nurbs, const sw_nurbs_desc *desc, sw_status *status);
/* Frees the object; its handle goes stale (a renderer may keep a copy of it in its immediate
 * scene until it draws another set). Any thread. Errors: SW_ERR_STALE_HANDLE. */
SW_API sw_result sw_nurbs_destroy(sw_nurbs nurbs);

/* ---- drawing --------------------------------------------------------------------------------- */
typedef struct sw_nurbs_draw {
    sw_nurbs nurbs;
    double model[12]; /* row-major 3x4 object-to-world; all zero: identity */
    float color[4];   /* linear RGBA; all zero: the library's grey */
} sw_nurbs_draw;

typedef struct sw_immediate_desc {
    const sw_nurbs_draw *draws; /* draw_count entries; an object may appear several times */
    uint32_t draw_count;        /* 1..65,535 */
    sw_camera camera;           /* all zero: the iso preset fitted to the drawn objects */
    int32_t width, height;      /* 0 = 1280 x 720 */
    double error_px;            /* screen-space error ε_img in pixels; 0 = 0.5 */
    int32_t present;            /* 1: into the framebuffer bound to GL_DRAW_FRAMEBUFFER when the
                                   call began, at its origin (sw_frame_desc.present) */
    const char *output_path;    /* .png or .exr; NULL = none */
    int32_t walkthrough;        /* as sw_frame_desc.walkthrough (0: converged) */
    int32_t library_shading;    /* 1: the library's shading even when the renderer has a host's */
    int32_t eval_exact;         /* 1: evaluated from knots and control points in the vertex shader
                                   (sw_frame_desc.eval_exact; degree <= 15); host shading too */
    int32_t present_depth;      /* with present: composited by depth into the host's framebuffer
                                   (sw_frame_desc.present_depth; the matrices in the stats) */
    double near_plane;          /* > 0: the near plane; 0: from the objects' box
                                   (sw_frame_desc.near_plane) */
} sw_immediate_desc;

/* Draws the objects through the renderer (owner thread; its context current — the host's with
 * use_current_context): the same frame as sw_renderer_draw of a scene holding these surfaces
 * under these transforms and colours, shaded by the renderer's host shading when set (see
 * sw_renderer_set_shading). Alternating with sw_renderer_draw of scenes rebuilds the renderer's
 * hierarchies each time (it keeps those of one scene). stats may be NULL; written on success.
 * Errors: SW_ERR_INVALID_ARGUMENT (NULL desc; no draws or more than 65,535; NULL draws; a
 * non-finite or singular model matrix; a non-finite or negative colour; prepared frames waiting;
 * another thread; the frame's size, error or camera as sw_renderer_draw), SW_ERR_STALE_HANDLE
 * (renderer or an object: then nothing is drawn), SW_ERR_UNSUPPORTED, SW_ERR_IO, SW_ERR_GL,
 * SW_ERR_LIMIT, SW_ERR_OUT_OF_MEMORY. */
SW_API sw_result sw_renderer_draw_nurbs(sw_renderer renderer, const sw_immediate_desc *desc,
                                        sw_frame_stats *stats, sw_status *status);

/* ---- GLSL for host shaders ------------------------------------------------------------------- */
typedef enum sw_glsl_kind {
    SW_GLSL_FRAGMENT_INTERFACE = 0,     /* #version 430 core, the inputs v_rel, v_nrm, v_st, v_uv,
                                           v_color, v_trim_rect, v_trim_layer, sampler u_trim, the
                                           exact trim edges' storage blocks (bindings 6-8), output
                                           o_color */
    SW_GLSL_FRAGMENT_LIBRARY = 1,       /* sw_trim_inside (§4.3) and sw_shade_library */
    SW_GLSL_FRAGMENT_DEFAULT_SHADE = 2, /* the sw_shade used without a host's */
    SW_GLSL_FRAGMENT_MAIN = 3,          /* main: trim (discard), then o_color = sw_shade(...) */
    SW_GLSL_VERTEX_BEZIER = 4, /* the rational bicubic Bézier evaluation on predefined grids
                                  (§4.2): patch records and homogeneous control points in
                                  storage buffers 0 and 1 */
    SW_GLSL_VERTEX_EXACT = 5,  /* NURBS evaluation from knots and control points (double) */
    SW_GLSL_KIND_COUNT
} sw_glsl_kind;

/* The library's GLSL source of one part, a static string (any thread); NULL out of range. */
SW_API const char *sw_glsl_source_ptr(sw_glsl_kind kind);

/* Links `shade_source` (see "Host shading" above) into the programs of the renderer's immediate
 * draws, replacing the host shading set before; NULL goes back to the library's shading. The
 * programs are compiled and linked during the call. Owner thread. Errors: SW_ERR_STALE_HANDLE,
 * SW_ERR_INVALID_ARGUMENT (another thread; the source does not compile or link: the GLSL log is
 * in the status; the shading set before stays), SW_ERR_GL. */
SW_API sw_result sw_renderer_set_shading(sw_renderer renderer, const char *shade_source,
                                         sw_status *status);

/* The GL program names of the host shading (meshes, Bézier evaluation, exact evaluation), for
 * glProgramUniform*; 0s without a host shading. Valid until the shading is replaced or the
 * renderer destroyed. Owner thread. Errors: SW_ERR_STALE_HANDLE, SW_ERR_INVALID_ARGUMENT (NULL
 * out, another thread). */
SW_API sw_result sw_renderer_shading_programs(sw_renderer renderer, uint32_t out[3],
                                              sw_status *status);

#ifdef __cplusplus
}
#endif
#endif
