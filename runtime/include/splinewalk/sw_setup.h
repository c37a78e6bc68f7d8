/* SPDX-License-Identifier: MIT */
/* splinewalk — process-wide setup: the host's allocator and log hooks (CONVENTIONS.md, API shape:
 * "Allocator and log hooks come in the setup desc with a user_data pointer"; like sokol's
 * sg_desc.allocator / sg_desc.logger).
 *
 * Without sw_setup the library allocates with malloc / realloc / free and writes its log lines
 * (warnings and errors) to stderr.
 *
 * What the allocator sees: every allocation the library's own C code makes (scenes, hierarchies,
 * trim atlases' CPU copies, static LODs, worker pools, handle tables, ...), each as one block of
 * the requested size plus a 16-byte header (the size, so that a missing realloc can be emulated
 * and aligned blocks found again).
 * What it does not see: memory the C++ shims allocate with operator new while they run
 * (OpenCASCADE's import and export, CGAL's triangulations and distance trees, OpenMesh's
 * decimation, OpenSubdiv, OpenImageIO's image writer), the GL driver's memory (Mesa, EGL),
 * glibc's own (threads' stacks, stdio buffers, mmap of .sws files: mapped, not allocated). Those
 * are freed by the time the call that made them returns, except the driver's, which lives with
 * the GL context.
 * The handle tables grow to the peak number of live scenes, renderers and nodes and stay
 * allocated (a few bytes per slot) until the process exits, so that a stale handle is still
 * recognised after its slot is reused.
 */
#ifndef SPLINEWALK_SW_SETUP_H
#define SPLINEWALK_SW_SETUP_H

#include <splinewalk/sw_result.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The host's allocator. alloc and free are both given or both NULL (NULL: malloc / free).
 * alloc returns memory aligned for any type (as malloc), or NULL: the library then fails the call
 * that needed it with SW_ERR_OUT_OF_MEMORY and frees what it had made. realloc may be NULL (then
 * alloc + copy + free); it keeps the contents as C's realloc does and returns NULL, leaving the
 * block as it was, on failure. free is never given NULL. The hooks are called from any thread,
 * also from the renderer's worker pool and visibility thread, concurrently: they must be
 * thread-safe. */
typedef struct sw_allocator {
    void *(*alloc)(void *user_data, size_t size);
    void *(*realloc)(void *user_data, void *ptr, size_t size);
    void (*free)(void *user_data, void *ptr);
    void *user_data;
} sw_allocator;

typedef enum sw_log_level {
    SW_LOG_DEFAULT = 0, /* as min_level: SW_LOG_WARN */
    SW_LOG_DEBUG = 1,   /* every failure a call reports, with its sw_status message */
    SW_LOG_INFO = 2,    /* renderers created (with their GL renderer and version) */
    SW_LOG_WARN = 3,
    SW_LOG_ERROR = 4, /* misuse: a NULL desc, a stale handle, a call from the wrong thread */
} sw_log_level;

/* One log line, without a trailing newline; message is valid during the call only. Called from
 * any thread, concurrently; must not call back into the library. */
typedef void (*sw_log_fn)(void *user_data, sw_log_level level, const char *message);

typedef struct sw_logger {
    sw_log_fn fn; /* NULL: stderr ("splinewalk: warning: ...") */
    void *user_data;
    sw_log_level min_level; /* lines below it are not formatted; 0 = SW_LOG_WARN */
} sw_logger;

typedef struct sw_setup_desc {
    sw_allocator allocator;
    sw_logger logger;
} sw_setup_desc;

/* Installs the hooks for the rest of the process. Call it once, before any other call of the
 * library that allocates (any create or load), on one thread, with no other call of the library
 * running. desc is copied. There is no teardown: the hooks stay in use until the process exits.
 * Errors: SW_ERR_INVALID_ARGUMENT (NULL desc; only one of alloc and free given; min_level out of
 * range; called a second time, or after the library has allocated: nothing changes). */
SW_API sw_result sw_setup(const sw_setup_desc *desc, sw_status *status);

#ifdef __cplusplus
}
#endif
#endif
