/* SPDX-License-Identifier: MIT */
/* embed_nodes: a scene built from nodes instead of a file, edited live. It makes a node scene
 * with a trimmed bicubic NURBS sheet (a round hole cut by four rational quarter circles), two
 * instances of it and a floor under them given as a triangle mesh, draws walkthrough frames
 * while it moves the sheet's control points (each edit is compiled in the scene's worker while
 * the frames keep drawing the version before), then picks a point of the first instance and one
 * of the floor and writes the last frame, converged, as PNG. Written only against the installed
 * public API:
 *
 *   cc embed_nodes.c $(pkg-config --cflags --libs splinewalk) -lm
 *
 * Exit status: 0 success, 1 a failure (reported on stderr). */
#include <splinewalk/splinewalk.h>

#include <math.h>
#include <stdio.h>

enum { N = 5 }; /* control points per direction */

static const double knots[N + 4] = {0, 0, 0, 0, 0.5, 1, 1, 1, 1};
static double points[N * N * 3];

static void wave(double phase)
{
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            double *p = points + 3 * (N * j + i);
            p[0] = 2.5 * i, p[1] = 2.5 * j, p[2] = 1.5 * sin(phase + i) * cos(0.8 * j);
        }
}

/* The outer loop is the domain's boundary; the hole is a circle of radius 0.2 at (0.5, 0.5),
 * four rational quadratic quarter arcs (weights 1, 1/sqrt 2, 1). */
static const double square_knots[7] = {0, 0, 1, 2, 3, 4, 4};
static const double square[10] = {0, 0, 1, 0, 1, 1, 0, 1, 0, 0};
static const double arc_knots[6] = {0, 0, 0, 1, 1, 1};
static const double arc_w[3] = {1, 0.70710678118654752, 1};
static const double arcs[4][6] = {{0.7, 0.5, 0.7, 0.3, 0.5, 0.3},
                                  {0.5, 0.3, 0.3, 0.3, 0.3, 0.5},
                                  {0.3, 0.5, 0.3, 0.7, 0.5, 0.7},
                                  {0.5, 0.7, 0.7, 0.7, 0.7, 0.5}};

static sw_nurbs_desc sheet(sw_trim_curve curves[5], sw_trim_loop loops[2])
{
    curves[0] = (sw_trim_curve){1, 5, square_knots, square, NULL};
    for (int k = 0; k < 4; k++)
        curves[1 + k] = (sw_trim_curve){2, 3, arc_knots, arcs[k], arc_w};
    loops[0] = (sw_trim_loop){curves, 1};
    loops[1] = (sw_trim_loop){curves + 1, 4};
    sw_nurbs_desc d = {3, 3, N, N, knots, knots, points, NULL, loops, 2, 0};
    return d;
}

/* The floor: two triangles below the sheets, shaded flat (no normals given). */
static const double floor_points[12] = {-3, -3, -2.5, 37, -3, -2.5, 37, 13, -2.5, -3, 13, -2.5};
static const uint32_t floor_triangles[6] = {0, 1, 2, 0, 2, 3};

static int fail(const char *what, const sw_status *st)
{
    fprintf(stderr, "embed_nodes: %s: %s\n", what, st->message);
    return 1;
}

int main(void)
{
    sw_status st = {0};
    sw_scene scene;
    sw_renderer renderer;
    sw_node surface, copy, ground;
    sw_trim_curve curves[5];
    sw_trim_loop loops[2];
    wave(0.0);
    sw_nurbs_desc nd = sheet(curves, loops);
    if (sw_scene_create(NULL, &scene, &st) != SW_OK)
        return fail("scene", &st);
    /* No colour of its own (color[3] = 0): it takes its parent's, and each instance's. */
    sw_node_desc s = {.kind = SW_NODE_NURBS, .nurbs = &nd};
    if (sw_node_add(scene, &s, &surface, &st) != SW_OK)
        return fail("surface", &st);
    for (int k = 1; k <= 2; k++) {
        sw_node_desc c = {.kind = SW_NODE_INSTANCE,
                          .instance_of = surface,
                          .transform = {1, 0, 0, 11.0 * k, 0, 1, 0, 0, 0, 0, 1, 0},
                          .color = {0.2f, 0.4f * k, 0.8f, 1}};
        if (sw_node_add(scene, &c, &copy, &st) != SW_OK)
            return fail("instance", &st);
    }
    sw_mesh_desc floor_mesh = {4, floor_points, NULL, 2, floor_triangles};
    sw_node_desc f = {.color = {0.55f, 0.55f, 0.5f, 1}}; /* under the root, identity */
    if (sw_node_add_mesh(scene, &f, &floor_mesh, &ground, &st) != SW_OK)
        return fail("floor", &st);
    if (sw_renderer_create(NULL, &renderer, &st) != SW_OK)
        return fail("renderer", &st);
    sw_camera cam = {{16, -22, 18}, {16, 5, 0}, {0, 0, 1}, 45};
    sw_frame_desc frame = {.scene = scene, .camera = cam, .width = 640, .height = 360};
    uint64_t waits = 0;
    for (int i = 1; i <= 120; i++) {
        wave(0.05 * i);
        if (sw_node_set_nurbs(scene, surface, &nd, &st) != SW_OK)
            return fail("edit", &st);
        frame.walkthrough = 1; /* never waits: draws the latest published version */
        sw_frame_stats stats;
        if (sw_renderer_draw(renderer, &frame, &stats, &st) != SW_OK)
            return fail("frame", &st);
        waits += stats.pool_waits;
    }
    frame.walkthrough = 0; /* converged: waits for the last edit and every refinement */
    frame.output_path = "embed_nodes.png";
    if (sw_renderer_draw(renderer, &frame, NULL, &st) != SW_OK)
        return fail("last frame", &st);
    /* A ray from the eye towards (13.5, 2.5, 0): the first instance, off its hole. */
    double dir[3] = {13.5 - cam.eye[0], 2.5 - cam.eye[1], 0.0 - cam.eye[2]};
    sw_pick_hit hit;
    if (sw_scene_pick(scene, cam.eye, dir, &hit, &st) != SW_OK)
        return fail("pick", &st);
    printf("120 live edits, pool waits %llu; wrote embed_nodes.png; the ray to (13.5, 2.5, 0): "
           "%s node %#x (u, v) = (%.3f, %.3f)\n",
           (unsigned long long)waits, hit.hit ? "hit" : "no hit", hit.node.id, hit.uv[0],
           hit.uv[1]);
    /* A ray towards (35, -2, -2.5), in front of the sheets: the floor mesh. */
    double down[3] = {35 - cam.eye[0], -2 - cam.eye[1], -2.5 - cam.eye[2]};
    if (sw_scene_pick(scene, cam.eye, down, &hit, &st) != SW_OK)
        return fail("pick", &st);
    printf("the ray to (35, -2, -2.5): %s node %#x (the floor: %#x), triangle %u\n",
           hit.hit ? "hit" : "no hit", hit.node.id, ground.id, hit.triangle);
    if (!hit.hit || hit.node.id != ground.id) {
        fprintf(stderr, "embed_nodes: the ray to the floor missed it\n");
        return 1;
    }
    sw_renderer_destroy(renderer);
    sw_scene_destroy(scene);
    return 0;
}
