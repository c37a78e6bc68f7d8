/* SPDX-License-Identifier: MIT */
/* embed_minimal: a GLFW program that owns its window and GL context and lets splinewalk draw a
 * scene into it — the smallest host of the public API. The renderer runs on the window's context
 * (use_current_context); each frame is drawn in walkthrough mode (it never waits for the worker
 * pool) and presented into the window's framebuffer, then the host swaps.
 *
 * usage: embed_minimal SCENE [FRAMES]   (an orbit around the scene; FRAMES: stop after them)
 * build: cc embed_minimal.c $(pkg-config --cflags --libs splinewalk glfw3) -lm
 */
#include <splinewalk/splinewalk.h>

#include <GLFW/glfw3.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static int fail(const char *what, const sw_status *st)
{
    fprintf(stderr, "embed_minimal: %s: %s\n", what, st ? st->message : "failed");
    return 1;
}

/* The fitted iso camera turned about the scene's vertical axis through its target. */
static sw_camera orbit(const sw_camera *home, double angle)
{
    sw_camera c = *home;
    double dx = c.eye[0] - c.target[0], dy = c.eye[1] - c.target[1];
    c.eye[0] = c.target[0] + dx * cos(angle) - dy * sin(angle);
    c.eye[1] = c.target[1] + dx * sin(angle) + dy * cos(angle);
    return c;
}

int main(int argc, char **argv)
{
    if (argc < 2 || argc > 3)
        return fprintf(stderr, "usage: embed_minimal SCENE [FRAMES]\n"), 2;
    long frames = argc == 3 ? strtol(argv[2], NULL, 10) : -1;
    sw_status st = {0};
    sw_scene scene = {0};
    sw_scene_load_desc ld = {argv[1], NULL, NULL, NULL, NULL, 0};
    if (sw_scene_load(&ld, &scene, &st) != SW_OK)
        return fail(argv[1], &st);
    sw_camera home;
    if (sw_camera_fit(scene, SW_VIEW_ISO, &home, &st) != SW_OK)
        return fail("camera", &st);

    if (!glfwInit())
        return fail("no display (GLFW could not start)", NULL);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
    GLFWwindow *win = glfwCreateWindow(960, 540, "splinewalk: embed_minimal", NULL, NULL);
    if (!win)
        return fail("no OpenGL 4.5 core window", NULL);
    glfwMakeContextCurrent(win);

    sw_renderer renderer = {0};
    sw_renderer_desc rd = {.use_current_context = 1}; /* draw with the window's context */
    if (sw_renderer_create(&rd, &renderer, &st) != SW_OK)
        return fail("renderer", &st);

    int rc = 0;
    for (long i = 0; !glfwWindowShouldClose(win) && i != frames; ++i) {
        sw_frame_desc frame = {0};
        frame.scene = scene;
        frame.camera = orbit(&home, 0.02 * (double)i);
        glfwGetFramebufferSize(win, &frame.width, &frame.height);
        frame.walkthrough = 1; /* never wait for the worker pool */
        frame.present = 1;     /* into the window's framebuffer */
        sw_frame_stats stats;
        if (sw_renderer_draw(renderer, &frame, &stats, &st) != SW_OK) {
            rc = fail("frame", &st);
            break;
        }
        glfwSwapBuffers(win);
        glfwPollEvents();
        if (frames > 0 && i + 1 == frames)
            printf("embed_minimal: %ld frames, the last %.1f ms, %llu triangles\n", frames,
                   stats.ms_total, (unsigned long long)stats.triangles);
    }
    sw_renderer_destroy(renderer); /* while its context is current */
    glfwDestroyWindow(win);
    glfwTerminate();
    sw_scene_destroy(scene);
    return rc;
}
