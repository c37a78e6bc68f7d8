/* SPDX-License-Identifier: MIT */
/* Opening input files so that no input can block or flood the program (never installed; issue
 * 22 item 2): opened with O_NONBLOCK (a FIFO without a writer does not hang open()), O_CLOEXEC
 * and O_NOCTTY, then fstat'ed: only a regular file is accepted — a directory, FIFO, device or
 * socket is SW_ERR_NOT_REGULAR_FILE with what it is ("is a directory", "is a FIFO", ...), never
 * "not found" — and its size is checked against the caller's maximum before a byte is read.
 * Results: SW_OK; SW_ERR_NOT_FOUND (no such file or a path component is not a directory);
 * SW_ERR_NOT_REGULAR_FILE; SW_ERR_LIMIT (larger than max_bytes); SW_ERR_IO (any other failing
 * system call, with its errno text); SW_ERR_OUT_OF_MEMORY. Any thread. */
#ifndef SW_SAFE_READ_H
#define SW_SAFE_READ_H

#include "sw_module_abi.h"

#include <splinewalk/sw_result.h>

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Opens `path` (a regular file of at most max_bytes; 0: no limit) for reading; *fd is the caller's
 * to close and *size its size at open. `what` names the kind of file in the limit's message
 * ("camera path"). */
sw_result sw__in_open(const char *path, uint64_t max_bytes, const char *what, int *fd,
                      uint64_t *size, sw_status *status);

/* sw__in_open, then close: for paths handed to a library that opens them itself (OCCT). */
SW_MODULE_ABI sw_result sw__in_check(const char *path, uint64_t max_bytes, const char *what,
                                     sw_status *status);

/* Reads a whole regular file of at most max_bytes (nonzero) into *text (sw__malloc'd, one NUL
 * byte after the *len bytes; the caller sw__free's it). A file that grows past max_bytes while it
 * is read is refused too. */
SW_MODULE_ABI sw_result sw__in_read_all(const char *path, uint64_t max_bytes, const char *what,
                                        char **text, size_t *len, sw_status *status);

#ifdef __cplusplus
}
#endif
#endif
