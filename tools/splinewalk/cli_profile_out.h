/* SPDX-License-Identifier: MIT */
/* What the CLI commands that record frame-time profiles share (`profile`, `view --profile`):
 * the output directory written aside and renamed in at the end, the report files, and the
 * per-frame samples beside the renderer's stats (resident memory, the worker pool's counters). */
#ifndef SW_CLI_PROFILE_OUT_H
#define SW_CLI_PROFILE_OUT_H

#include "sw_profile_report.h"
#include "sw_status_util.h"
#include "sw_th_pool.h"

#include <splinewalk/splinewalk.h>

#include <stddef.h>
#include <stdint.h>

/* ---- the output directory: written aside (DIR/.profile-PID-XXXXXX), renamed in at the end --- */
typedef struct sw_cli_staging {
    char dir[4096]; /* DIR/.profile-PID-XXXXXX */
    char names[8][64];
    int n_names;
} sw_cli_staging;

/* DIR made if missing (a stale staging folder of a killed run removed) and a staging folder in
 * it. Errors: SW_ERR_IO naming the path. */
sw_result sw_cli_staging_make(const char *out, sw_cli_staging *st, sw_status *status);
/* The staged path of file `name`. */
void sw_cli_staging_path(const sw_cli_staging *st, const char *name, char *buf, size_t size);
/* `name` is staged: committed or abandoned with the rest. */
void sw_cli_staging_remember(sw_cli_staging *st, const char *name);
/* Removes the staged files and the staging folder: DIR is left as it was. */
void sw_cli_staging_abandon(sw_cli_staging *st);
/* Moves every staged file into `out`, then removes the staging directory. */
sw_result sw_cli_staging_commit(sw_cli_staging *st, const char *out, sw_status *status);
/* The end of a run whose frames ended with `run`: on SW_OK the profile summarized and its
 * profile.csv, profile.json, frametime.svg and report.html staged, then everything staged moved
 * into `out`; on any failure the staged files removed, `out` as it was. Returns the first
 * failure. */
sw_result sw_cli_profile_finish(sw_cli_staging *st, const char *out, sw_rt_profile *p,
                                sw_result run, sw_status *status);

/* ---- per-frame samples ---------------------------------------------------------------------- */
/* Resident memory now (/proc/self/statm), in bytes; 0 when unknown. */
double sw_cli_resident_bytes(void);
typedef struct sw_cli_pool_sample {
    sw_th_pool_stats stats;
    int64_t queued, peak;
} sw_cli_pool_sample;
/* The renderer's pool counters now (with_queues: its queue and injection peak too); zeros
 * before the pool exists. */
void sw_cli_pool_read(sw_renderer renderer, int with_queues, sw_cli_pool_sample *out);
/* The pool columns of a frame's row from two reads inside its window. */
void sw_cli_pool_columns(const sw_cli_pool_sample *start, sw_cli_pool_sample *end,
                         sw_rt_prof_row *row);
/* The worker threads a renderer asked for `requested` (0: the default) gets. */
uint32_t sw_cli_pool_workers(uint32_t requested);

#endif
