/* SPDX-License-Identifier: MIT */
/* The profile output shared by `profile` and `view --profile` (cli_profile_out.h). */
#include "cli_profile_out.h"

#include "sw_rt.h"
#include "sw_safe_write.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- output directory: written aside, renamed in at the end ---------------------------------- */

/* Removes the staging folders DIR/.profile-PID-XXXXXX of runs that were killed (their PID no
 * longer runs): they hold only the flat files a run stages. */
static void remove_stale_staging(const char *out)
{
    DIR *d = opendir(out);
    if (!d)
        return;
    const struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        char *end;
        if (strncmp(e->d_name, ".profile-", 9) != 0)
            continue;
        const long pid = strtol(e->d_name + 9, &end, 10);
        if (end == e->d_name + 9 || *end != '-' || pid <= 0 || pid == (long)getpid() ||
            kill((pid_t)pid, 0) == 0 || errno != ESRCH)
            continue;
        char sub[4200];
        snprintf(sub, sizeof sub, "%s/%s", out, e->d_name);
        DIR *s = opendir(sub);
        const struct dirent *f;
        while (s && (f = readdir(s)) != NULL) {
            if (strcmp(f->d_name, ".") != 0 && strcmp(f->d_name, "..") != 0)
                unlinkat(dirfd(s), f->d_name, 0);
        }
        if (s)
            closedir(s);
        rmdir(sub);
    }
    closedir(d);
}

sw_result sw_cli_staging_make(const char *out, sw_cli_staging *st, sw_status *status)
{
    struct stat sb;
    if (stat(out, &sb) != 0) {
        if (errno != ENOENT || mkdir(out, 0777) != 0)
            return sw__fail(status, SW_ERR_IO, "%s: %s", out, strerror(errno));
    } else if (!S_ISDIR(sb.st_mode)) {
        return sw__fail(status, SW_ERR_IO, "%s: exists and is not a directory", out);
    }
    remove_stale_staging(out);
    if (snprintf(st->dir, sizeof st->dir, "%s/.profile-%ld-XXXXXX", out, (long)getpid()) >=
        (int)sizeof st->dir)
        return sw__fail(status, SW_ERR_IO, "%s: path too long", out);
    if (!mkdtemp(st->dir))
        return sw__fail(status, SW_ERR_IO, "%s: %s", st->dir, strerror(errno));
    return SW_OK;
}

void sw_cli_staging_path(const sw_cli_staging *st, const char *name, char *buf, size_t size)
{
    snprintf(buf, size, "%s/%s", st->dir, name);
}

void sw_cli_staging_remember(sw_cli_staging *st, const char *name)
{
    if (st->n_names < (int)(sizeof st->names / sizeof st->names[0]))
        snprintf(st->names[st->n_names++], sizeof st->names[0], "%s", name);
}

void sw_cli_staging_abandon(sw_cli_staging *st)
{
    char p[4200];
    for (int i = 0; i < st->n_names; i++) {
        sw_cli_staging_path(st, st->names[i], p, sizeof p);
        remove(p);
    }
    rmdir(st->dir);
}

/* Moves every staged file into `out`, then removes the staging directory. */
sw_result sw_cli_staging_commit(sw_cli_staging *st, const char *out, sw_status *status)
{
    for (int i = 0; i < st->n_names; i++) {
        char from[4200], to[4200];
        sw_cli_staging_path(st, st->names[i], from, sizeof from);
        snprintf(to, sizeof to, "%s/%s", out, st->names[i]);
        if (rename(from, to) != 0)
            return sw__fail(status, SW_ERR_IO, "%s: %s", to, strerror(errno));
    }
    rmdir(st->dir);
    const int fd = open(out, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) { /* the renames made durable (the files were fsync'd when written) */
        (void)fsync(fd);
        close(fd);
    }
    return SW_OK;
}

typedef int (*report_fn)(FILE *f, const sw_rt_profile *p, const char *svg);

static int csv_fn(FILE *f, const sw_rt_profile *p, const char *svg)
{
    (void)svg;
    return sw_rt_profile_write_csv(f, p);
}

static int json_fn(FILE *f, const sw_rt_profile *p, const char *svg)
{
    (void)svg;
    return sw_rt_profile_write_json(f, p);
}

static int text_fn(FILE *f, const sw_rt_profile *p, const char *svg)
{
    (void)p;
    return fputs(svg, f) < 0 ? -1 : 0;
}

static int html_fn(FILE *f, const sw_rt_profile *p, const char *svg)
{
    return sw_rt_profile_write_html(f, p, svg);
}

typedef struct report_job {
    report_fn fn;
    const sw_rt_profile *p;
    const char *svg;
} report_job;

static int report_fill(FILE *f, const void *ctx)
{
    const report_job *job = ctx;
    return job->fn(f, job->p, job->svg);
}

/* Each report through the project's one writer (sw_safe_write.h): built in memory, every write
 * and the fsync checked, so a full disk fails the run instead of committing a short file. */
static sw_result write_staged(sw_cli_staging *st, const char *name, report_fn fn,
                              const sw_rt_profile *p, const char *svg, sw_status *status)
{
    char path[4200];
    sw_cli_staging_path(st, name, path, sizeof path);
    sw_cli_staging_remember(st, name);
    const report_job job = {fn, p, svg};
    return sw__write_file_printed(path, report_fill, &job, 0, status);
}

static sw_result write_reports(sw_cli_staging *st, const sw_rt_profile *p, sw_status *status)
{
    char *svg = NULL;
    size_t svg_len = 0;
    FILE *mem = open_memstream(&svg, &svg_len);
    if (!mem)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "frametime.svg: out of memory");
    int bad = sw_rt_profile_write_svg(mem, p);
    bad |= fclose(mem) != 0;
    sw_result r =
        bad ? sw__fail(status, SW_ERR_OUT_OF_MEMORY, "frametime.svg: out of memory") : SW_OK;
    if (r == SW_OK)
        r = write_staged(st, "profile.csv", csv_fn, p, NULL, status);
    if (r == SW_OK)
        r = write_staged(st, "profile.json", json_fn, p, NULL, status);
    if (r == SW_OK)
        r = write_staged(st, "frametime.svg", text_fn, p, svg, status);
    if (r == SW_OK)
        r = write_staged(st, "report.html", html_fn, p, svg, status);
    free(svg);
    return r;
}

sw_result sw_cli_profile_finish(sw_cli_staging *st, const char *out, sw_rt_profile *p,
                                sw_result run, sw_status *status)
{
    sw_result r = run;
    if (r == SW_OK && sw_rt_profile_summarize(p) != 0)
        r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "profile: out of memory");
    if (r == SW_OK)
        r = write_reports(st, p, status);
    if (r == SW_OK)
        r = sw_cli_staging_commit(st, out, status);
    if (r != SW_OK)
        sw_cli_staging_abandon(st);
    return r;
}

double sw_cli_resident_bytes(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    unsigned long size = 0, resident = 0;
    if (!f)
        return 0.0;
    const int got = fscanf(f, "%lu %lu", &size, &resident);
    fclose(f);
    return got == 2 ? (double)resident * (double)sysconf(_SC_PAGESIZE) : 0.0;
}

/* The pool's counters, queue and injection peak (since the previous read) at one moment; no pool
 * yet (nothing asked for one): zeros. */

void sw_cli_pool_read(sw_renderer renderer, int with_queues, sw_cli_pool_sample *out)
{
    sw_th_pool *pool = sw_rt_renderer_pool_ptr(renderer);
    memset(out, 0, sizeof *out);
    if (!pool)
        return;
    sw_th_pool_stats_get(pool, &out->stats);
    if (with_queues) {
        out->queued = sw_th_pool_queued(pool, NULL);
        out->peak = sw_th_pool_inject_peak_take(pool);
    }
}

/* The pool columns of frame `row`: what the pool did between two reads inside the frame's window
 * (just after its clock starts, just before it stops), so that in walkthrough mode the workers
 * cannot show more than workers x frame_ms however the threads are scheduled between frames;
 * its queue at the frame's end and its injection queue's peak since the previous frame. */
void sw_cli_pool_columns(const sw_cli_pool_sample *start, sw_cli_pool_sample *end,
                         sw_rt_prof_row *row)
{
    /* a running task's time may read a few ns ahead of what its end then records
     * (sw_th_pool_stats.ns_by_kind): the totals are kept from going back */
    for (int k = 0; k < SW_TH_TASK_KIND_MAX; k++)
        if (end->stats.ns_by_kind[k] < start->stats.ns_by_kind[k])
            end->stats.ns_by_kind[k] = start->stats.ns_by_kind[k];
    sw_rt_profile_row_pool(&start->stats, &end->stats, end->queued, end->peak, row);
}

uint32_t sw_cli_pool_workers(uint32_t requested)
{
    sw_th_pool_desc want = {0}, pool; /* resolves the default as the renderer's pool will */
    want.worker_count = requested;
    sw_th_pool_desc_defaults(&pool, &want);
    return pool.worker_count;
}
