/* SPDX-License-Identifier: MIT */
/* The one way the project writes an output file (never installed).
 *
 * A write either replaces the target completely or leaves it byte-identical: the bytes go to a
 * temporary in the target's directory — an unnamed O_TMPFILE file where the file system offers
 * one (linked to NAME.tmp-PID only once complete, so a killed writer leaves nothing), else
 * NAME.tmp-PID itself — every write(2) checked (short writes continued, EINTR retried), the file
 * fsync'd and closed (both checked), renamed over the target, and the directory fsync'd. The
 * temporaries of writers that died (NAME.tmp-PID whose PID no longer runs) are removed by the
 * next write to NAME.
 *
 * Targets: a regular file or a missing name is replaced as above; a symbolic link is written
 * through (the file it points to is replaced, the link stays a link); a character device or a
 * FIFO (`-o /dev/null`) is written directly, with no temporary; "-" is standard output when the
 * caller passes SW__OUT_DASH_STDOUT; a directory, block device or socket is refused with
 * SW_ERR_NOT_REGULAR_FILE naming the path.
 *
 * It lives in scenegraph/, the lowest layer every writer can reach (the .sws writer is here; lod,
 * gpu and runtime link it) that has the sw_status helpers (status.c); threads/ writes no file.
 * Results: SW_OK; SW_ERR_NOT_FOUND (the target's directory does not exist);
 * SW_ERR_NOT_REGULAR_FILE; SW_ERR_IO (any failing system call, with its errno text: a full disk
 * is "No space left on device"); SW_ERR_OUT_OF_MEMORY. */
#ifndef SW_SAFE_WRITE_H
#define SW_SAFE_WRITE_H

#include "sw_module_abi.h"

#include <splinewalk/sw_result.h>

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <sys/types.h>

#ifdef __cplusplus
extern "C" {
#endif

enum {
    SW__OUT_DASH_STDOUT = 1, /* the path "-" means standard output */
};

typedef struct sw__out {
    int fd;
    int kind;     /* how the bytes reach the target (safe_write.c) */
    char *target; /* the regular file renamed over: a symbolic link resolved */
    char *tmp;    /* the named temporary while it exists, else NULL */
    char *shown;  /* the path as the caller gave it, for messages */
    uint64_t written;
} sw__out;

/* Opens `path` for writing as described above. On failure `out` holds nothing to release. */
sw_result sw__out_open(sw__out *out, const char *path, unsigned flags, sw_status *status);
/* Whether a write to `path` would be accepted, creating nothing: for commands to refuse a bad
 * output (a directory, a missing directory) before their work rather than after it. The same
 * results as sw__out_open. */
sw_result sw__out_check(const char *path, unsigned flags, sw_status *status);
/* Appends n bytes (any n; data may be NULL when n is 0). On failure the caller still calls
 * sw__out_abandon. */
sw_result sw__out_write(sw__out *out, const void *data, size_t n, sw_status *status);
/* fsync, close, rename over the target, fsync the directory; releases `out` whatever happens
 * (on failure the temporary is removed and the target is untouched). */
sw_result sw__out_commit(sw__out *out, sw_status *status);
/* Drops what was written: the temporary is removed, the target untouched. NULL-safe fields. */
void sw__out_abandon(sw__out *out);

/* open + write + commit of one buffer. */
SW_MODULE_ABI sw_result sw__write_file(const char *path, const void *data, size_t n, unsigned flags,
                                       sw_status *status);

/* Writes what `fill` prints into a FILE (an in-memory stream: fill returns nonzero or leaves
 * the stream in error on failure) to `path` with sw__write_file. For the text writers (camera
 * paths, profile reports): the whole text is built first, so nothing reaches the disk unless it
 * is complete. */
typedef int (*sw__out_fill_fn)(FILE *f, const void *ctx);
sw_result sw__write_file_printed(const char *path, sw__out_fill_fn fill, const void *ctx,
                                 unsigned flags, sw_status *status);

/* Tests only (failure injection): every write(2) and fsync(2) of a temporary or direct target
 * goes through these; NULL (the default) means the system calls. A hook sets errno on failure. */
extern ssize_t (*sw__out_write_hook)(int fd, const void *data, size_t n);
extern int (*sw__out_fsync_hook)(int fd);
/* Tests only: nonzero makes every temporary a named NAME.tmp-PID, as where O_TMPFILE is missing. */
extern int sw__out_no_tmpfile;

#ifdef __cplusplus
}
#endif
#endif
