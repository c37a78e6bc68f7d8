/* SPDX-License-Identifier: MIT */
/* tests/api: misuse of the public API in both kinds of build, from one source.
 *
 *   test_api_misuse SCENE.tsm [CASE]
 *
 * Each case runs in a forked child that makes one programming mistake: a NULL desc, a stale
 * handle after destroy, a double destroy (scene, renderer, node), a call from a thread that does
 * not own the renderer's GL context, sw_setup after the library allocated. Built against a library
 * with SW_MISUSE_ASSERT (SW_TEST_MISUSE_ASSERTS=1 here) the child must die of SIGABRT with the
 * misuse's message on stderr (death tests); against one without, the call must return the
 * documented sw_result, the child then finishes its work (the renderer or scene still usable)
 * and exits 0, and the message is on stderr too (the default logger, at SW_LOG_ERROR). Under
 * ASan (CI) either must come without a memory error. With CASE, only that case runs, in the
 * process itself (to debug it). */
#include <splinewalk/splinewalk.h>

#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#ifndef SW_TEST_MISUSE_ASSERTS
#define SW_TEST_MISUSE_ASSERTS 0
#endif

static const char *g_scene_path;

/* In a child: a wrong result exits 3 (the parent says which case). */
static void want(sw_result got, sw_result expected, const char *what)
{
    if (got != expected) {
        fprintf(stderr, "%s returned %s, expected %s\n", what, sw_result_id_str(got),
                sw_result_id_str(expected));
        exit(3);
    }
}

static sw_scene load(void)
{
    sw_scene scene = {0};
    sw_scene_load_desc desc = {.path = g_scene_path};
    want(sw_scene_load(&desc, &scene, NULL), SW_OK, "sw_scene_load");
    return scene;
}

/* ---- the cases: each returns after the misuse (and what follows it) without asserts --------- */
static void null_desc_load(void)
{
    sw_scene scene = {77};
    sw_status status = {0};
    want(sw_scene_load(NULL, &scene, &status), SW_ERR_INVALID_ARGUMENT, "sw_scene_load(NULL)");
    want(scene.id == 0 ? SW_OK : SW_ERR_INTERNAL, SW_OK, "*out zeroed");
    want(status.result, SW_ERR_INVALID_ARGUMENT, "status.result");
}

static void null_desc_setup(void)
{
    want(sw_setup(NULL, NULL), SW_ERR_INVALID_ARGUMENT, "sw_setup(NULL)");
}

static void setup_after_use(void)
{
    sw_scene scene = load();
    want(sw_scene_destroy(scene), SW_OK, "sw_scene_destroy");
    sw_setup_desc desc = {0};
    want(sw_setup(&desc, NULL), SW_ERR_INVALID_ARGUMENT, "sw_setup after a load");
}

static void stale_scene(void)
{
    sw_scene scene = load();
    want(sw_scene_destroy(scene), SW_OK, "sw_scene_destroy");
    sw_scene_info info;
    want(sw_scene_get_info(scene, &info, NULL), SW_ERR_STALE_HANDLE, "sw_scene_get_info(stale)");
}

static void double_destroy_scene(void)
{
    sw_scene scene = load();
    want(sw_scene_destroy(scene), SW_OK, "sw_scene_destroy");
    want(sw_scene_destroy(scene), SW_ERR_STALE_HANDLE, "sw_scene_destroy (again)");
    /* the slot is reused by a new scene; the old handle stays stale for it */
    sw_scene again = load();
    want(sw_scene_destroy(scene), SW_ERR_STALE_HANDLE, "sw_scene_destroy (old handle)");
    want(sw_scene_destroy(again), SW_OK, "sw_scene_destroy (new)");
}

static void double_remove_node(void)
{
    sw_scene scene = {0};
    want(sw_scene_create(NULL, &scene, NULL), SW_OK, "sw_scene_create");
    sw_node_desc desc = {.kind = SW_NODE_GROUP};
    sw_node node = {0};
    want(sw_node_add(scene, &desc, &node, NULL), SW_OK, "sw_node_add");
    want(sw_node_remove(scene, node, NULL), SW_OK, "sw_node_remove");
    want(sw_node_remove(scene, node, NULL), SW_ERR_STALE_HANDLE, "sw_node_remove (again)");
    want(sw_scene_destroy(scene), SW_OK, "sw_scene_destroy");
}

static sw_renderer make_renderer(void)
{
    sw_renderer r = {0};
    sw_renderer_desc desc = {.worker_threads = 1};
    sw_status status = {0};
    sw_result res = sw_renderer_create(&desc, &r, &status);
    if (res != SW_OK) {
        fprintf(stderr, "sw_renderer_create: %s\n", status.message);
        exit(3);
    }
    return r;
}

static void null_frame_desc(void)
{
    sw_renderer r = make_renderer();
    want(sw_renderer_draw(r, NULL, NULL, NULL), SW_ERR_INVALID_ARGUMENT, "sw_renderer_draw(NULL)");
    want(sw_renderer_destroy(r), SW_OK, "sw_renderer_destroy");
}

static void double_destroy_renderer(void)
{
    sw_renderer r = make_renderer();
    want(sw_renderer_destroy(r), SW_OK, "sw_renderer_destroy");
    want(sw_renderer_destroy(r), SW_ERR_STALE_HANDLE, "sw_renderer_destroy (again)");
    sw_scene scene = load();
    sw_frame_desc frame = {.scene = scene, .width = 64, .height = 48};
    want(sw_renderer_draw(r, &frame, NULL, NULL), SW_ERR_STALE_HANDLE, "sw_renderer_draw(stale)");
    want(sw_scene_destroy(scene), SW_OK, "sw_scene_destroy");
}

typedef struct foreign_call {
    sw_renderer renderer;
    sw_frame_desc frame;
    sw_result draw, destroy;
} foreign_call;

static void *draw_from_another_thread(void *arg)
{
    foreign_call *c = arg;
    c->draw = sw_renderer_draw(c->renderer, &c->frame, NULL, NULL);
    c->destroy = sw_renderer_destroy(c->renderer);
    return NULL;
}

static void wrong_thread(void)
{
    sw_renderer r = make_renderer();
    sw_scene scene = load();
    foreign_call c = {.renderer = r, .frame = {.scene = scene, .width = 64, .height = 48}};
    pthread_t t;
    if (pthread_create(&t, NULL, draw_from_another_thread, &c) != 0)
        exit(3);
    pthread_join(t, NULL);
    want(c.draw, SW_ERR_INVALID_ARGUMENT, "sw_renderer_draw (another thread)");
    want(c.destroy, SW_ERR_INVALID_ARGUMENT, "sw_renderer_destroy (another thread)");
    /* the owner still draws and destroys it */
    want(sw_renderer_draw(r, &c.frame, NULL, NULL), SW_OK, "sw_renderer_draw (owner)");
    want(sw_renderer_destroy(r), SW_OK, "sw_renderer_destroy (owner)");
    want(sw_scene_destroy(scene), SW_OK, "sw_scene_destroy");
}

typedef struct misuse_case {
    const char *name;
    void (*run)(void);
    const char *message; /* in the misuse's log line / abort message */
} misuse_case;

static const misuse_case k_cases[] = {
    {"null_desc_load", null_desc_load, "sw_scene_load: NULL desc"},
    {"null_desc_setup", null_desc_setup, "sw_setup: desc is NULL"},
    {"setup_after_use", setup_after_use, "sw_setup must come once"},
    {"stale_scene", stale_scene, "is stale or invalid"},
    {"double_destroy_scene", double_destroy_scene, "sw_scene_destroy: scene handle"},
    {"double_remove_node", double_remove_node, "sw_node_remove: node handle"},
    {"null_frame_desc", null_frame_desc, "sw_renderer_draw: NULL desc"},
    {"double_destroy_renderer", double_destroy_renderer, "sw_renderer_destroy: renderer handle"},
    {"wrong_thread", wrong_thread, "called from a thread that does not own the renderer"},
};
#define N_CASES (sizeof k_cases / sizeof k_cases[0])

/* Runs one case in a child with its stderr in a pipe; returns 0 when it behaved as this build
 * promises. */
static int run_case(const misuse_case *c)
{
    int fd[2];
    if (pipe(fd) != 0)
        return -1;
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        close(fd[0]);
        dup2(fd[1], STDERR_FILENO);
        c->run();
        fflush(NULL);
        _exit(0);
    }
    close(fd[1]);
    char err[16384];
    size_t n = 0;
    for (;;) {
        ssize_t got = read(fd[0], err + n, sizeof err - 1 - n);
        if (got < 0 && errno == EINTR)
            continue;
        if (got <= 0)
            break;
        n += (size_t)got;
        if (n == sizeof err - 1)
            break;
    }
    err[n] = '\0';
    close(fd[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    int has_message = strstr(err, c->message) != NULL && strstr(err, "misuse") != NULL;
    int ok;
    if (SW_TEST_MISUSE_ASSERTS)
        ok = WIFSIGNALED(status) && WTERMSIG(status) == SIGABRT && has_message &&
             strstr(err, "SW_MISUSE_ASSERT") != NULL;
    else
        ok = WIFEXITED(status) && WEXITSTATUS(status) == 0 && has_message;
    if (WIFSIGNALED(status))
        printf("%-24s killed by %s%s\n", c->name, strsignal(WTERMSIG(status)),
               ok ? "" : "  <-- FAILED");
    else
        printf("%-24s exit status %d%s\n", c->name, WEXITSTATUS(status), ok ? "" : "  <-- FAILED");
    if (!ok)
        fprintf(stderr, "%s: child's stderr:\n%s\n", c->name, err);
    return ok ? 0 : -1;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s SCENE.tsm [CASE]\n", argv[0]);
        return 2;
    }
    g_scene_path = argv[1];
    if (argc == 3) {
        for (size_t i = 0; i < N_CASES; i++)
            if (strcmp(k_cases[i].name, argv[2]) == 0) {
                k_cases[i].run();
                return 0;
            }
        return 2;
    }
    printf("misuse %s (library built %s SW_MISUSE_ASSERT)\n",
           SW_TEST_MISUSE_ASSERTS ? "aborts" : "returns its result",
           SW_TEST_MISUSE_ASSERTS ? "with" : "without");
    int failures = 0;
    for (size_t i = 0; i < N_CASES; i++)
        failures += run_case(&k_cases[i]) != 0;
    if (failures) {
        fprintf(stderr, "%d case(s) failed\n", failures);
        return 1;
    }
    printf("ok: %zu cases\n", N_CASES);
    return 0;
}
