/* SPDX-License-Identifier: MIT */
/* The command line's numbers (cli_numbers.c): every subcommand reads its sizes, counts, errors,
 * cameras and seeds through these, so that one grammar and one set of limits holds everywhere.
 * Pure functions of their text (no I/O but sw_cli_bad_value's message); the libFuzzer harness
 * tests/cli/fuzz_cli_numbers.c drives them. */
#ifndef SW_CLI_NUMBERS_H
#define SW_CLI_NUMBERS_H

#include <splinewalk/splinewalk.h>

#include <stdint.h>

/* "1280x720" → width, height (1..16384; digits only). Returns 0 on success. */
int sw_cli_parse_size(const char *text, int32_t *w, int32_t *h);
/* "ex,ey,ez,tx,ty,tz,ux,uy,uz,fovy" → camera, checked as every frame checks it (fovy given).
 * Returns 0 on success. */
int sw_cli_parse_camera(const char *text, sw_camera *out);
/* An integer in [lo, hi] (0 <= lo; digits only, no sign or space). Returns 0 on success. */
int sw_cli_parse_count(const char *text, int lo, int hi, int *out);
/* "splinewalk CMD: bad value 'VAL' for ARG" on stderr, with the reason the last sw_cli_parse_*
 * call gave when it gave one (": the field of view is outside ..."), then usage (NULL: none).
 * Returns 2, the exit status of a usage error. */
int sw_cli_bad_value(const char *cmd, const char *arg, const char *val, const char *usage);
/* A positive finite decimal number. Returns 0 on success. */
int sw_cli_parse_positive(const char *text, double *out);
/* A screen-space error in pixels: a decimal number of at least SW_ERROR_MIN_PX (what every frame
 * accepts), so that a run refuses it before it creates any output. Returns 0 on success. */
int sw_cli_parse_error_px(const char *text, double *out);
/* "HOST[,GPU]": the renderer's memory budget in bytes, each digits with an optional binary suffix
 * K, M, G or T ("8G,512M"); 0 or an absent GPU part = the default. Returns 0 on success. */
int sw_cli_parse_memory_budget(const char *text, uint64_t *host, uint64_t *gpu);
/* A random seed: decimal digits only (no sign, no space), at most 2^64 - 1. Returns 0 on success.
 */
int sw_cli_parse_seed(const char *text, unsigned long long *out);

#endif
