/* SPDX-License-Identifier: MIT */
/* bench/peers: the GLU peer (see peer_glu.h). */
#include "peer_glu.h"
#include "sw_hooks.h"

#include "../tessellation/glu_nurbs.h"
#include "../tessellation/vbo_draw.h"
#include "sw_gpu.h"
#include "sw_gpu_internal.h"
#include "sw_rt.h"
#include "sw_sg_scene.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

/* A face in GLU's terms: float knots, trim curves and loops, prepared once. */
typedef struct glu_face {
    float *knots_u, *knots_v;
    float *curve_floats;
    bt_glu_curve *curves;
    bt_glu_loop *loops;
    int32_t n_loops;
    int refused; /* 0, or how GLU failed on it: REFUSED_* */
} glu_face;

enum { REFUSED_ERROR = 1, REFUSED_CRASH = 2 };

typedef struct glu_occurrence {
    uint32_t face;
    size_t cpw; /* offset of its world-space homogeneous control points in world_cpw */
} glu_occurrence;

typedef struct glu_run {
    const bp_job *job;
    const sw_sg_scene *sg;
    glu_face *faces;
    uint32_t n_faces;
    glu_occurrence *occ;
    size_t n_occ, cap_occ;
    double *world_cpw;
    size_t n_world, cap_world;
    float *scratch; /* one face's eye-relative control points */
    size_t cap_scratch;
    bt_glu *glu;
    bt_draw *draw;
    bt_glu_mesh face_mesh, frame_mesh;
    uint64_t refused_occ, gl_errors;
    uint32_t crashed_faces, screen_children;
    double screen_ms;
    char first_error[160], first_crash[160];
    int oom;
} glu_run;

static float *to_floats(const double *d, size_t n)
{
    float *f = malloc((n ? n : 1) * sizeof *f);
    if (f)
        for (size_t i = 0; i < n; ++i)
            f[i] = (float)d[i];
    return f;
}

/* GLU keeps the region left of each loop: outer loops counter-clockwise, holes clockwise — the
 * convention the scene's loops follow (export_occt.cpp). A trimmed face whose loops are all holes
 * gets its trim box as an outer loop. */
static int prepare_loops(glu_run *r, uint32_t fi, glu_face *gf)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(r->sg);
    const sw_sg_face_rec *fr = &v->faces[fi];
    if (!(fr->flags & SW_SG_FACE_TRIMMED) || fr->n_loops == 0)
        return 0;
    uint32_t n_curves = 0, outer = 0;
    size_t n_floats = 10; /* the box loop: 5 (u, v) points */
    for (uint32_t l = 0; l < fr->n_loops; ++l) {
        const sw_sg_loop_rec *lr = &v->loops[fr->first_loop + l];
        outer += (lr->flags & SW_SG_LOOP_OUTER) != 0;
        for (uint32_t c = 0; c < lr->n_curves; ++c) {
            const sw_sg_curve_rec *cr = &v->curves[lr->first_curve + c];
            n_floats += (size_t)cr->n + cr->degree + 1 + (size_t)cr->n * 3;
        }
        n_curves += lr->n_curves;
    }
    gf->curve_floats = malloc(n_floats * sizeof(float));
    gf->curves = calloc(n_curves + 1, sizeof *gf->curves);
    gf->loops = calloc(fr->n_loops + 1, sizeof *gf->loops);
    if (!gf->curve_floats || !gf->curves || !gf->loops)
        return -1;
    float *f = gf->curve_floats;
    bt_glu_curve *cv = gf->curves;
    if (outer == 0) {
        const double *b = fr->uv_box; /* u0, u1, v0, v1 */
        const double box[10] = {b[0], b[2], b[1], b[2], b[1], b[3], b[0], b[3], b[0], b[2]};
        for (int k = 0; k < 10; ++k)
            f[k] = (float)box[k];
        *cv = (bt_glu_curve){0, 5, NULL, f};
        gf->loops[gf->n_loops++] = (bt_glu_loop){cv, 1};
        f += 10;
        cv++;
    }
    for (uint32_t l = 0; l < fr->n_loops; ++l) {
        const sw_sg_loop_rec *lr = &v->loops[fr->first_loop + l];
        gf->loops[gf->n_loops++] = (bt_glu_loop){cv, (int32_t)lr->n_curves};
        for (uint32_t c = 0; c < lr->n_curves; ++c, ++cv) {
            sw_sg_curve sc;
            sw_sg_scene_curve(r->sg, lr->first_curve + c, &sc);
            size_t nk = (size_t)sc.n + (size_t)sc.degree + 1, np = (size_t)sc.n * 3;
            for (size_t k = 0; k < nk; ++k)
                f[k] = (float)sc.knots[k];
            for (size_t k = 0; k < np; ++k)
                f[nk + k] = (float)sc.cpw[k];
            *cv = (bt_glu_curve){sc.degree + 1, sc.n, f, f + nk};
            f += nk + np;
        }
    }
    return 0;
}

static int prepare_faces(glu_run *r)
{
    const sw_sg_scene_view *v = sw_sg_scene_view_ptr(r->sg);
    r->n_faces = v->n_faces;
    r->faces = calloc(v->n_faces ? v->n_faces : 1, sizeof *r->faces);
    if (!r->faces)
        return -1;
    for (uint32_t i = 0; i < v->n_faces; ++i) {
        sw_sg_surface s;
        sw_sg_scene_face_surface(r->sg, i, &s);
        glu_face *gf = &r->faces[i];
        gf->knots_u = to_floats(s.knots_u, (size_t)s.n_u + s.deg_u + 1);
        gf->knots_v = to_floats(s.knots_v, (size_t)s.n_v + s.deg_v + 1);
        if (!gf->knots_u || !gf->knots_v || prepare_loops(r, i, gf) != 0)
            return -1;
    }
    return 0;
}

/* Each occurrence's control points in world space (row-major 3x4 on the homogeneous point). */
static int visit(void *ctx, uint32_t face, const double m[12], const float color[4])
{
    (void)color;
    glu_run *r = ctx;
    sw_sg_surface s;
    sw_sg_scene_face_surface(r->sg, face, &s);
    size_t n = (size_t)s.n_u * (size_t)s.n_v;
    if (!sw__grow((void **)&r->occ, &r->cap_occ, r->n_occ + 1, sizeof *r->occ) ||
        !sw__grow((void **)&r->world_cpw, &r->cap_world, r->n_world + 4 * n, sizeof(double))) {
        r->oom = 1;
        return 1;
    }
    r->occ[r->n_occ++] = (glu_occurrence){face, r->n_world};
    double *o = r->world_cpw + r->n_world;
    for (size_t i = 0; i < n; ++i) {
        const double *p = s.cpw + 4 * i;
        for (int k = 0; k < 3; ++k)
            o[4 * i + k] =
                m[4 * k] * p[0] + m[4 * k + 1] * p[1] + m[4 * k + 2] * p[2] + m[4 * k + 3] * p[3];
        o[4 * i + 3] = p[3];
    }
    r->n_world += 4 * n;
    return 0;
}

static int append_face(bt_glu_mesh *dst, const bt_glu_mesh *src)
{
    size_t base = dst->n_v;
    if (!sw__grow((void **)&dst->v, &dst->cap_v, (dst->n_v + src->n_v) * BT_GLU_VERTEX_FLOATS,
                  sizeof(float)) ||
        !sw__grow((void **)&dst->idx, &dst->cap_idx, dst->n_idx + src->n_idx, sizeof(uint32_t)))
        return -1;
    memcpy(dst->v + base * BT_GLU_VERTEX_FLOATS, src->v,
           src->n_v * BT_GLU_VERTEX_FLOATS * sizeof(float));
    for (size_t i = 0; i < src->n_idx; ++i)
        dst->idx[dst->n_idx + i] = (uint32_t)(src->idx[i] + base);
    dst->n_v += src->n_v;
    dst->n_idx += src->n_idx;
    return 0;
}

/* ---- screening: Mesa's GLU 9.0.2 crashes (SIGSEGV, or aborts while allocating gigabytes) on some
 * faces that it accepts without an error — 15 of the 2,244 faces of the occt-misc samples, all
 * with trim curves of degree 3 to 8, while most such faces pass: no rule on degrees predicts it.
 * So every face is tessellated once, before the timed frames, in a child process of the peer's
 * own (a view fitting the face's control net into 1024 px); a face that kills the child is
 * refused (counted, with its signal), and the screening goes on in a new child after it. */

/* The face's control points moved and scaled so that its control-net box spans about [-1, 1]. */
static int fitted_points(glu_run *r, const sw_sg_surface *s)
{
    size_t n = (size_t)s->n_u * (size_t)s->n_v;
    if (!sw__grow((void **)&r->scratch, &r->cap_scratch, 4 * n, sizeof(float)))
        return -1;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
            double x = s->cpw[4 * i + k] / s->cpw[4 * i + 3];
            lo[k] = fmin(lo[k], x);
            hi[k] = fmax(hi[k], x);
        }
    double c[3], extent = 0.0;
    for (int k = 0; k < 3; ++k) {
        c[k] = 0.5 * (lo[k] + hi[k]);
        extent = fmax(extent, 0.5 * (hi[k] - lo[k]));
    }
    extent = extent > 0.0 ? extent : 1.0;
    for (size_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k)
            r->scratch[4 * i + k] =
                (float)((s->cpw[4 * i + k] - s->cpw[4 * i + 3] * c[k]) / extent);
        r->scratch[4 * i + 3] = (float)s->cpw[4 * i + 3];
    }
    return 0;
}

/* GLU's result for face f in the fitted view: 0, a GLU error code, or -1 (out of memory). */
static int screen_one(glu_run *r, uint32_t f)
{
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    static const float ortho[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0.5f, 0, 0, 0, 0, 1};
    static const int32_t vp[4] = {0, 0, 1024, 1024};
    sw_sg_surface s;
    sw_sg_scene_face_surface(r->sg, f, &s);
    if (fitted_points(r, &s) != 0)
        return -1;
    const glu_face *gf = &r->faces[f];
    bt_glu_surface bs = {s.deg_u + 1, s.deg_v + 1, s.n_u,     s.n_v,      gf->knots_u,
                         gf->knots_v, r->scratch,  gf->loops, gf->n_loops};
    return bt_glu_tessellate(r->glu, &bs, identity, ortho, vp, &r->face_mesh);
}

/* The screening child: for each face from `first` on, writes its index, tessellates it, writes
 * the result. 20 s and 2 GB per child at most: a hang or a runaway allocation is a crash too. */
static void screen_child(glu_run *r, uint32_t first, int fd)
{
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
    /* Under a sanitizer the shadow memory is address space: a limit would break its allocator
     * ("Failed to mmap"); its own allocation limit then stops a runaway GLU instead. */
    struct rlimit lim = {(rlim_t)2 << 30, (rlim_t)2 << 30};
    setrlimit(RLIMIT_AS, &lim);
#endif
    for (uint32_t f = first; f < r->n_faces; ++f) {
        alarm(20);
        int32_t msg[2] = {(int32_t)f, 0};
        if (write(fd, msg, sizeof msg[0]) != sizeof msg[0])
            _exit(1);
        msg[1] = screen_one(r, f);
        if (write(fd, &msg[1], sizeof msg[1]) != sizeof msg[1])
            _exit(1);
    }
    _exit(0);
}

static void refuse(glu_run *r, uint32_t f, int how, const char *why)
{
    sw_sg_surface s;
    sw_sg_scene_face_surface(r->sg, f, &s);
    r->faces[f].refused = how;
    char *first = how == REFUSED_CRASH ? r->first_crash : r->first_error;
    if (!first[0])
        snprintf(first, sizeof r->first_error, "face %u (degree %d x %d): %s", f, s.deg_u, s.deg_v,
                 why);
    r->crashed_faces += how == REFUSED_CRASH;
}

/* Runs one screening child from face `first`; returns the face to go on from (n_faces: done),
 * or UINT32_MAX when the child could not be started. */
static uint32_t screen_from(glu_run *r, uint32_t first)
{
    int fds[2];
    fflush(NULL);
    if (pipe(fds) != 0)
        return UINT32_MAX;
    pid_t pid = fork();
    if (pid < 0) {
        close(fds[0]);
        close(fds[1]);
        return UINT32_MAX;
    }
    if (pid == 0) {
        close(fds[0]);
        screen_child(r, first, fds[1]);
    }
    close(fds[1]);
    r->screen_children++;
    int32_t f = -1, rc = 0;
    uint32_t next = r->n_faces;
    for (;;) {
        ssize_t k = read(fds[0], &f, sizeof f);
        if (k < 0 && errno == EINTR)
            continue;
        if (k != sizeof f)
            break; /* the child is done */
        ssize_t m;
        while ((m = read(fds[0], &rc, sizeof rc)) < 0 && errno == EINTR)
            ;
        if (m != sizeof rc) { /* it died on face f */
            next = (uint32_t)f + 1;
            break;
        }
        if (rc != 0)
            refuse(r, (uint32_t)f, REFUSED_ERROR, bt_glu_error_str(rc));
    }
    close(fds[0]);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
        ;
    if (next < r->n_faces) {
        char why[96];
        int sig = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
        snprintf(why, sizeof why, "GLU's process died of signal %d (%s)", sig,
                 sig ? strsignal(sig) : "none");
        refuse(r, next - 1, REFUSED_CRASH, why);
    }
    return next;
}

static int screen_faces(glu_run *r)
{
    double t0 = bench_now_ms();
    for (uint32_t f = 0; f < r->n_faces;)
        if ((f = screen_from(r, f)) == UINT32_MAX)
            return -1;
    r->screen_ms = bench_now_ms() - t0;
    return 0;
}

/* ---- watchdog: GLU also hangs on some faces in some views (Bottom.brep, face occurrence 25 of the
 * orbit, over ten minutes in one call) that the screening's view passes. A frame longer than
 * BP_GLU_FRAME_LIMIT_S ends the peer with a message naming the face; the parent reports the
 * signal. */
enum { BP_GLU_FRAME_LIMIT_S = 120 };
static volatile sig_atomic_t g_face = -1, g_occurrence = -1;

static size_t put_uint(char *p, long v)
{
    char tmp[24];
    size_t n = 0, k = 0;
    do
        tmp[n++] = (char)('0' + v % 10);
    while ((v /= 10) > 0 && n < sizeof tmp);
    while (n > 0)
        p[k++] = tmp[--n];
    return k;
}

static void on_frame_timeout(int sig)
{
    (void)sig;
    static const char a[] = "bench_peers: glu: one frame took longer than 120 s, in GLU on face ";
    static const char b[] = " (occurrence ";
    static const char c[] = "); the glu peer stops\n";
    char msg[256];
    size_t n = 0;
    memcpy(msg, a, sizeof a - 1);
    n += sizeof a - 1;
    n += put_uint(msg + n, g_face);
    memcpy(msg + n, b, sizeof b - 1);
    n += sizeof b - 1;
    n += put_uint(msg + n, g_occurrence);
    memcpy(msg + n, c, sizeof c - 1);
    n += sizeof c - 1;
    ssize_t w = write(STDERR_FILENO, msg, n);
    (void)w;
    signal(SIGALRM, SIG_DFL);
    raise(SIGALRM);
}

/* Tessellates occurrence k for the view and appends its triangles to the frame's mesh. */
static int tessellate_occurrence(glu_run *r, size_t k, const sw__gpu_view *view)
{
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    const glu_occurrence *o = &r->occ[k];
    glu_face *gf = &r->faces[o->face];
    g_face = (sig_atomic_t)o->face;
    g_occurrence = (sig_atomic_t)k;
    if (gf->refused) {
        r->refused_occ++;
        return 0;
    }
    sw_sg_surface s;
    sw_sg_scene_face_surface(r->sg, o->face, &s);
    size_t n = (size_t)s.n_u * (size_t)s.n_v;
    if (!sw__grow((void **)&r->scratch, &r->cap_scratch, 4 * n, sizeof(float)))
        return -1;
    const double *w = r->world_cpw + o->cpw;
    for (size_t i = 0; i < n; ++i) { /* eye-relative: w * (x - eye) */
        for (int c = 0; c < 3; ++c)
            r->scratch[4 * i + c] = (float)(w[4 * i + c] - w[4 * i + 3] * view->eye[c]);
        r->scratch[4 * i + 3] = (float)w[4 * i + 3];
    }
    bt_glu_surface bs = {s.deg_u + 1, s.deg_v + 1, s.n_u,     s.n_v,      gf->knots_u,
                         gf->knots_v, r->scratch,  gf->loops, gf->n_loops};
    const int32_t vp[4] = {0, 0, r->job->width, r->job->height};
    int rc = bt_glu_tessellate(r->glu, &bs, identity, view->view_proj, vp, &r->face_mesh);
    if (rc == -1)
        return -1;
    if (rc != 0) { /* GLU refused the face: counted, named, and not drawn from now on */
        refuse(r, o->face, REFUSED_ERROR, bt_glu_error_str(rc));
        r->refused_occ++;
        return 0;
    }
    return append_face(&r->frame_mesh, &r->face_mesh);
}

static int frame(glu_run *r, uint32_t i, double *triangles)
{
    sw_camera cam;
    sw__gpu_view view;
    bp_frame_camera(r->job, i, &cam);
    if (bp_frame_view(r->job, &cam, &view) != 0)
        return -1;
    r->frame_mesh.n_v = r->frame_mesh.n_idx = 0;
    r->refused_occ = 0;
    signal(SIGALRM, on_frame_timeout);
    alarm(BP_GLU_FRAME_LIMIT_S);
    int rc = 0;
    for (size_t k = 0; k < r->n_occ && rc == 0; ++k)
        rc = tessellate_occurrence(r, k, &view);
    alarm(0);
    if (rc != 0)
        return -1;
    r->gl_errors += bt_draw_drain_errors();
    unsigned e = bt_draw_mesh(r->draw, view.view_proj, r->frame_mesh.v, r->frame_mesh.n_v,
                              BT_GLU_VERTEX_FLOATS, r->frame_mesh.idx, r->frame_mesh.n_idx);
    *triangles = (double)(r->frame_mesh.n_idx / 3);
    return e == 0 ? 0 : -1;
}

static int setup(glu_run *r, sw_gpu_context **ctx, char *err, size_t err_size)
{
    sw_status st;
    memset(&st, 0, sizeof st);
    r->glu = bt_glu_create((float)r->job->error_px);
    if (!r->glu) {
        snprintf(err, err_size, "gluNewNurbsRenderer failed");
        return -1;
    }
    if (prepare_faces(r) != 0 || sw_sg_scene_traverse(r->sg, visit, r) != SW_OK || r->oom) {
        snprintf(err, err_size, "out of memory preparing the faces");
        return -1;
    }
    if (screen_faces(r) != 0) {
        snprintf(err, err_size, "cannot start GLU's screening process: %s", strerror(errno));
        return -1;
    }
    if (sw_gpu_context_create_headless(ctx, &st) != SW_OK) {
        snprintf(err, err_size, "%s", st.message);
        return -1;
    }
    r->draw = bt_draw_create(r->job->width, r->job->height, err, err_size);
    if (r->draw) /* frame time: the interval between completions */
        bt_draw_set_pipelined(r->draw, 1);
    return r->draw ? 0 : -1;
}

static int measure(glu_run *r, double t_start, bp_result *out)
{
    const bp_job *job = r->job;
    uint32_t n = job->frames * job->passes;
    double *ms = calloc(n, sizeof *ms), *tri = calloc(n, sizeof *tri);
    if (!ms || !tri) {
        free(ms);
        free(tri);
        return -1;
    }
    int rc = 0;
    double t_first = 0.0, scratch_tri;
    for (uint32_t p = 0; rc == 0 && p < job->warmup_passes + job->passes; ++p)
        for (uint32_t i = 0; rc == 0 && i < job->frames; ++i) {
            int counted = p >= job->warmup_passes;
            size_t at = (size_t)(p - (counted ? job->warmup_passes : 0)) * job->frames + i;
            double t0 = bench_now_ms();
            rc = frame(r, i, counted ? &tri[at] : &scratch_tri);
            double t1 = bench_now_ms();
            if (p == 0 && i == 0) /* the screening is GLU's fault, not its preprocessing */
                t_first = t1 - t_start - r->screen_ms;
            if (counted)
                ms[at] = t1 - t0;
        }
    if (rc == 0) {
        double tri_p99;
        out->frames = n;
        out->first_frame_ms = t_first;
        rc = bp_summarize(ms, n, &out->median_ms, &out->p99_ms) == 0 &&
                     bp_summarize(tri, n, &out->triangles, &tri_p99) == 0
                 ? 0
                 : -1;
    }
    free(ms);
    free(tri);
    return rc;
}

static void count_refused(glu_run *r, bp_result *out)
{
    out->faces = r->n_occ;
    out->refused_occurrences = r->refused_occ;
    for (uint32_t i = 0; i < r->n_faces; ++i)
        out->refused_faces += r->faces[i].refused != 0;
    out->gl_errors = r->gl_errors;
    out->crashed_faces = r->crashed_faces;
    out->screen_ms = r->screen_ms;
    snprintf(out->note, sizeof out->note,
             "screening %.0f ms in %u processes (not in first); refused: %llu faces (%llu "
             "occurrences per frame), %u of them crashing GLU%s%s%s%s",
             r->screen_ms, r->screen_children, (unsigned long long)out->refused_faces,
             (unsigned long long)out->refused_occurrences, r->crashed_faces,
             r->first_crash[0] ? "; first crash: " : "", r->first_crash,
             r->first_error[0] ? "; first GLU error: " : "", r->first_error);
}

static void release(glu_run *r)
{
    for (uint32_t i = 0; r->faces && i < r->n_faces; ++i) {
        free(r->faces[i].knots_u);
        free(r->faces[i].knots_v);
        free(r->faces[i].curve_floats);
        free(r->faces[i].curves);
        free(r->faces[i].loops);
    }
    free(r->faces);
    free(r->occ);
    free(r->world_cpw);
    free(r->scratch);
    bt_glu_mesh_free(&r->face_mesh);
    bt_glu_mesh_free(&r->frame_mesh);
    bt_draw_free(r->draw);
    bt_glu_free(r->glu);
}

int bp_peer_glu(const bp_job *job, bp_result *out)
{
    double t_start = bench_now_ms();
    sw_status st;
    memset(&st, 0, sizeof st);
    sw_scene_load_desc ld = {job->scene, NULL, NULL, NULL, NULL, 0};
    sw_scene scene = {0};
    sw_rt_scene *rs = NULL;
    if (sw_scene_load(&ld, &scene, &st) != SW_OK || sw_rt_scene_acquire(scene, &rs, &st) != SW_OK) {
        snprintf(out->note, sizeof out->note, "%s", st.message);
        if (scene.id)
            sw_scene_destroy(scene);
        return -1;
    }
    glu_run r;
    memset(&r, 0, sizeof r);
    r.job = job;
    r.sg = rs->sg;
    sw_gpu_context *ctx = NULL;
    int rc = setup(&r, &ctx, out->note, sizeof out->note);
    if (rc == 0) {
        rc = measure(&r, t_start, out);
        if (rc != 0)
            snprintf(out->note, sizeof out->note, "a frame failed (GL error or out of memory)");
        else {
            count_refused(&r, out);
            out->covered_px = (double)bt_draw_covered(r.draw);
        }
    }
    release(&r);
    sw_gpu_context_free(ctx);
    sw_rt_scene_release(rs);
    sw_scene_destroy(scene);
    return rc;
}
