/* SPDX-License-Identifier: MIT */
/* The splinewalk command-line tool's subcommands (runtime/src/cli_*.c). Each returns the process
 * exit status: 0 success, 1 a failure reported on stderr, 2 a usage error. */
#ifndef SW_CLI_H
#define SW_CLI_H

#include <splinewalk/splinewalk.h>

#include "sw_clock.h"
#include "cli_numbers.h"

#include <stdio.h>

int sw_cli_import(int argc, char **argv);
int sw_cli_outline(int argc, char **argv);
int sw_cli_info(int argc, char **argv);
int sw_cli_render(int argc, char **argv);
int sw_cli_demo(int argc, char **argv);
int sw_cli_check_osd(int argc, char **argv);
int sw_cli_path(int argc, char **argv);
int sw_cli_profile(int argc, char **argv);
int sw_cli_view(int argc, char **argv);
int sw_cli_generate(int argc, char **argv);
int sw_cli_build_lod(int argc, char **argv);

/* Installs the import, image and LOD-building modules into the core (cli_modules.c): the tool,
 * the benchmarks and in-tree tests that read CAD files, write .exr or build static LODs through
 * the runtime call it first. */
void sw_cli_install_modules(void);

/* ---- shared helpers (cli_common.c) ---------------------------------------------------------- */
int sw_cli_is_help(const char *arg);
/* When any argument asks for help: prints usage on stdout and returns 1 (the command exits 0). */
int sw_cli_print_help(int argc, char **argv, const char *usage);
/* Prints "splinewalk <cmd>: <result>: <message>" to stderr; returns 1. */
int sw_cli_report(const char *cmd, const sw_status *status);
/* Refuses an output path before the command's work (sw__out_check: a directory, a missing
 * directory): 0 when it can be written, else reports it like sw_cli_report and returns 1.
 * flags: SW__OUT_DASH_STDOUT where the command writes "-" to standard output. */
int sw_cli_check_output(const char *cmd, const char *path, unsigned flags);
/* A progress bar on stderr: redrawn in place on a terminal, else a line per quarter and stage. */
void sw_cli_progress(void *user_data, double fraction, const char *stage);
void sw_cli_progress_end(void);
void sw_cli_warning(void *user_data, const char *message);
/* Loads a scene with the progress bar and warnings on stderr (each skipped or repaired face of a
 * CAD import among them); flags: sw_scene_load_desc.flags (SW_LOAD_PARTIAL for --partial). */
sw_result sw_cli_load_scene(const char *path, uint32_t flags, sw_scene *out, sw_status *status);
/* The faces the last sw_cli_load_scene skipped or repaired, as its face_problem records gave them
 * (strings copied; valid until the next load). */
typedef struct sw_cli_face_note {
    uint32_t face, entity;
    sw_face_action action;
    sw_result reason;
    char name[128];
} sw_cli_face_note;
size_t sw_cli_face_notes(const sw_cli_face_note **out);
/* After a load that imported a CAD file: "N faces skipped, M repaired, ..." on `f` when any
 * face was skipped or repaired or the file was imported in part; nothing otherwise. */
void sw_cli_print_import_notes(FILE *f, const char *cmd, const sw_scene_info *info);
/* sw_cli_report, with a hint at --partial for a truncated file (commands that take it). */
int sw_cli_report_load(const char *cmd, const sw_status *status);
/* Keeps freed memory in the process's heap (glibc's trim and mmap thresholds raised): llvmpipe
 * allocates and frees megabytes every frame, and with the defaults the submitting thread faulted
 * them in again each frame (a quarter of its time on a 10^4-surface building's orbit;
 * docs/performance.md). Process-wide, so the command line and the benchmarks call it for
 * themselves; the library leaves its host's malloc alone (docs/embedding.md). */
void sw_cli_keep_freed_memory(void);
void sw_cli_print_frame_stats(const char *label, const sw_frame_stats *s);
/* "memory budget: host X GiB, GPU Y GiB (what the driver reports)\n" into buf ("" for a renderer
 * the caller does not own). */
void sw_cli_memory_budget_line(sw_renderer renderer, char *buf, size_t size);
/* The help line of --memory-budget, shared by render, profile and view. */
#define SW_CLI_MEMORY_BUDGET_HELP                                                                  \
    "  --memory-budget HOST[,GPU]\n"                                                               \
    "                      bytes the renderer may keep between frames (suffix K, M, G or T):\n"    \
    "                      hierarchies and fat borders in host memory, resident levels and\n"      \
    "                      trim textures on the GPU; over it the picture coarsens and says\n"      \
    "                      so. Default: half of physical memory, half of the GPU's (1 GiB\n"       \
    "                      where the driver reports none, as llvmpipe)\n"

/* What a bundle ships beside its bin/ (share/splinewalk/REL; scripts/bundle): its path in buf, or
 * NULL when this program is not in a bundle that has it. */
const char *sw_cli_bundle_path(const char *rel, char *buf, size_t size);

#endif
