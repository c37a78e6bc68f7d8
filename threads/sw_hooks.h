/* SPDX-License-Identifier: MIT */
/* The library's one way to allocate and to log (never installed): the host's hooks from
 * sw_setup (splinewalk/sw_setup.h), else malloc / free and stderr. Every C allocation of the
 * library goes through sw__malloc & co., so that a host allocator sees them all and a failing one
 * can be tested; every diagnostic through sw__log. It lives in threads/, the lowest library,
 * because the worker pool allocates too.
 *
 * Blocks are freed by the function family that made them: sw__free for sw__malloc, sw__calloc,
 * sw__realloc and sw__strdup; sw__aligned_free for sw__aligned_alloc. Memory made by libc or
 * another library (getline, open_memstream, a C++ shim's new) is never given to sw__free. */
#ifndef SW_HOOKS_H
#define SW_HOOKS_H

#include "sw_module_abi.h"

#include <splinewalk/sw_setup.h>

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

SW_MODULE_ABI void *sw__malloc(size_t size);
SW_MODULE_ABI void *sw__calloc(size_t count, size_t size); /* NULL when count * size overflows */
SW_MODULE_ABI void *sw__realloc(void *ptr, size_t size); /* as C's realloc; ptr NULL: sw__malloc */
/* The one growable array: makes *p (sw__realloc'd, *cap elements of elem bytes) hold at least
 * `need`, doubling from 64; 1 on success, 0 when out of memory or the size overflows (*p and *cap
 * unchanged then). */
SW_MODULE_ABI int sw__grow(void **p, size_t *cap, size_t need, size_t elem);
SW_MODULE_ABI void sw__free(void *ptr);                  /* NULL: nothing */
char *sw__strdup(const char *text);
/* align: a power of two, at most 4096; size need not be a multiple of it. */
void *sw__aligned_alloc(size_t align, size_t size);
void sw__aligned_free(void *ptr);

/* One log line (printf format, no trailing newline) at `level`; not formatted below the
 * logger's min_level. Any thread. */
SW_MODULE_ABI void sw__log(sw_log_level level, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
/* Whether a line at `level` would be written (to skip building an expensive message). */
SW_MODULE_ABI int sw__log_enabled(sw_log_level level);

/* sw_setup's work: installs desc's hooks unless the library has already allocated or been set
 * up. Returns 0 on success, -1 when refused (see sw_setup); `why` says which. */
int sw__hooks_install(const sw_setup_desc *desc, const char **why);

#ifdef __cplusplus
}
#endif
#endif
