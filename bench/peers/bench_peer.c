/* SPDX-License-Identifier: MIT */
/* bench/peers: the shared part of the side-by-side runs (see bench_peer.h). */
#define _GNU_SOURCE
#include "bench_peer.h"

#include "bench_stats.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

/* A "VmHWM:" or "VmRSS:" line of /proc/self/status, in bytes (0 if absent). */
static double proc_status_kb(const char *key)
{
    FILE *f = fopen("/proc/self/status", "r");
    if (!f)
        return 0.0;
    char line[256];
    double kb = 0.0;
    size_t n = strlen(key);
    while (fgets(line, sizeof line, f))
        if (!strncmp(line, key, n)) {
            kb = strtod(line + n, NULL);
            break;
        }
    fclose(f);
    return kb * 1024.0;
}

static int write_all(int fd, const void *p, size_t n)
{
    const char *c = p;
    while (n > 0) {
        ssize_t k = write(fd, c, n);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            return -1;
        c += k;
        n -= (size_t)k;
    }
    return 0;
}

static size_t read_all(int fd, void *p, size_t n)
{
    char *c = p;
    size_t got = 0;
    while (got < n) {
        ssize_t k = read(fd, c + got, n - got);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            break;
        got += (size_t)k;
    }
    return got;
}

int bp_run_in_child(bp_peer_fn fn, const bp_job *job, bp_result *out)
{
    memset(out, 0, sizeof *out);
    int fds[2];
    fflush(NULL); /* buffered output must not be written twice */
    if (pipe(fds) != 0) {
        snprintf(out->note, sizeof out->note, "pipe: %s", strerror(errno));
        return -1;
    }
    double t0 = bench_now_ms();
    pid_t pid = fork();
    if (pid < 0) {
        snprintf(out->note, sizeof out->note, "fork: %s", strerror(errno));
        close(fds[0]);
        close(fds[1]);
        return -1;
    }
    if (pid == 0) {
        close(fds[0]);
        /* The child's own peak: what it holds beyond what the fork gave it. */
        double rss0 = proc_status_kb("VmRSS:");
        bp_result r;
        memset(&r, 0, sizeof r);
        int rc = fn(job, &r);
        r.ok = rc == 0;
        r.peak_rss_bytes = proc_status_kb("VmHWM:") - rss0;
        int w = write_all(fds[1], &r, sizeof r);
        fflush(NULL);
        _exit(rc == 0 && w == 0 ? 0 : 1);
    }
    close(fds[1]);
    size_t got = read_all(fds[0], out, sizeof *out);
    close(fds[0]);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
        ;
    if (got == sizeof *out)
        out->wall_ms = bench_now_ms() - t0;
    if (got != sizeof *out) {
        memset(out, 0, sizeof *out);
        if (WIFSIGNALED(status))
            snprintf(out->note, sizeof out->note, "the peer's process died of signal %d (%s)",
                     WTERMSIG(status), strsignal(WTERMSIG(status)));
        else
            snprintf(out->note, sizeof out->note, "the peer's process exited with %d, no result",
                     WIFEXITED(status) ? WEXITSTATUS(status) : -1);
        return -1;
    }
    return out->ok ? 0 : -1;
}

int bp_summarize(const double *ms, uint32_t n, double *median, double *p99)
{
    double *v = malloc((size_t)n * sizeof *v); /* bench_quantile sorts */
    if (!v)
        return -1;
    memcpy(v, ms, (size_t)n * sizeof *v);
    *median = bench_quantile(v, (int)n, 0.5);
    *p99 = bench_quantile(v, (int)n, 0.99);
    free(v);
    return 0;
}

void bp_frame_camera(const bp_job *job, uint32_t i, sw_camera *out)
{
    sw_rt_path_eval(job->path, sw_rt_path_frame_time(job->path, i, job->frames), out);
    if (!(out->fovy_deg > 0.0))
        out->fovy_deg = 40.0;
}

int bp_frame_view(const bp_job *job, const sw_camera *cam, sw__gpu_view *out)
{
    sw_gpu_camera g;
    memcpy(g.eye, cam->eye, sizeof g.eye);
    memcpy(g.target, cam->target, sizeof g.target);
    memcpy(g.up, cam->up, sizeof g.up);
    g.fovy_deg = cam->fovy_deg;
    return sw__gpu_view_init(out, &g, job->width, job->height,
                             sw__gpu_near_plane(cam->eye, job->scene_box), NULL) == SW_OK
               ? 0
               : -1;
}

double bp_min_view_distance(const bp_job *job)
{
    double best = INFINITY;
    for (uint32_t i = 0; i < job->frames; ++i) {
        sw_camera cam;
        bp_frame_camera(job, i, &cam);
        double rel[6];
        for (int k = 0; k < 6; ++k)
            rel[k] = job->scene_box[k] - cam.eye[k % 3];
        best = fmin(best, sw__gpu_box_distance(rel));
    }
    return best;
}

int bp_probe_scene(const bp_job *job, bp_result *out)
{
    sw_status st;
    memset(&st, 0, sizeof st);
    sw_scene_load_desc ld = {job->scene, NULL, NULL, NULL, NULL, 0};
    sw_scene s = {0};
    sw_scene_info info;
    sw_result r = sw_scene_load(&ld, &s, &st);
    if (r == SW_OK)
        r = sw_scene_get_info(s, &info, &st);
    if (r == SW_OK) {
        for (int k = 0; k < 3; ++k) {
            out->box[k] = info.bbox_min[k];
            out->box[3 + k] = info.bbox_max[k];
        }
        out->faces = info.face_occurrences;
        out->scene_bytes = (double)info.memory_bytes;
    }
    if (s.id)
        sw_scene_destroy(s);
    if (r != SW_OK) {
        snprintf(out->note, sizeof out->note, "%s", st.message[0] ? st.message : "cannot load");
        return -1;
    }
    return 0;
}

int bp_job_path(bp_job *job, const char *path_file, sw_rt_camera_path *path, char *err,
                size_t err_size)
{
    bp_result probe;
    if (bp_run_in_child(bp_probe_scene, job, &probe) != 0) {
        snprintf(err, err_size, "%s", probe.note);
        return -1;
    }
    memcpy(job->scene_box, probe.box, sizeof job->scene_box);
    sw_status st;
    memset(&st, 0, sizeof st);
    sw_result r = path_file ? sw_rt_path_load(path_file, path, &st)
                            : sw_rt_path_orbit(job->scene_box, 10.0, job->frames, path, &st);
    if (r != SW_OK) {
        snprintf(err, err_size, "%s", st.message);
        return -1;
    }
    job->path = path;
    return 0;
}
