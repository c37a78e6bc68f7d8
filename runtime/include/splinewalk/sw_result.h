/* SPDX-License-Identifier: MIT */
/* splinewalk — result codes and the caller-owned status that carries their message.
 *
 * Every layer (scenegraph, lod, gpu, runtime) reports bad data, I/O and driver failures with an
 * sw_result; a programming mistake by the caller is an assert instead (CONVENTIONS.md, Errors).
 * There is no global error state: a function that can fail takes an optional `sw_status *`
 * (NULL allowed) and fills its message with the file, the position and what was expected.
 * Tests compare the result id, never the text.
 */
#ifndef SPLINEWALK_SW_RESULT_H
#define SPLINEWALK_SW_RESULT_H

#ifdef __cplusplus
extern "C" {
#endif

#if defined(_WIN32)
#define SW_API __declspec(dllexport)
#else
#define SW_API __attribute__((visibility("default")))
#endif
/* The modules' entry points (sw_import.h, sw_image.h, sw_lod_build.h): exported by their own
 * libraries, not by libsplinewalk. */
#define SW_MODULE_API SW_API

/* One table generates the enum and its names (like sokol's _SG_LOGITEM_XMACRO). New ids go at
 * the end: the numbers of the others stay stable for a program built against an older library. */
#define SW_RESULT_XMACRO(X)                                                                        \
    X(SW_OK, "ok")                                                                                 \
    X(SW_ERR_IO, "input/output error")                                                             \
    X(SW_ERR_NOT_FOUND, "file not found")                                                          \
    X(SW_ERR_FORMAT, "malformed file")                                                             \
    X(SW_ERR_TRUNCATED, "file truncated")                                                          \
    X(SW_ERR_CHECKSUM, "checksum mismatch")                                                        \
    X(SW_ERR_VERSION, "unsupported file version")                                                  \
    X(SW_ERR_UNSUPPORTED, "unsupported input")                                                     \
    X(SW_ERR_INVALID_GEOMETRY, "invalid geometry")                                                 \
    X(SW_ERR_OUT_OF_MEMORY, "out of memory")                                                       \
    X(SW_ERR_LIMIT, "size limit exceeded")                                                         \
    X(SW_ERR_GL, "OpenGL error")                                                                   \
    X(SW_ERR_NO_CONTEXT, "no OpenGL context could be created")                                     \
    X(SW_ERR_INVALID_ARGUMENT, "invalid argument")                                                 \
    X(SW_ERR_STALE_HANDLE, "stale or invalid handle")                                              \
    X(SW_ERR_INTERNAL, "internal error")                                                           \
    X(SW_ERR_NOT_REGULAR_FILE, "not a regular file")

typedef enum sw_result {
#define SW__RESULT_ENUM(id, text) id,
    SW_RESULT_XMACRO(SW__RESULT_ENUM)
#undef SW__RESULT_ENUM
        SW_RESULT_COUNT
} sw_result;

/* Caller-owned; zero-initialise it. `message` is always NUL-terminated. */
typedef struct sw_status {
    sw_result result;
    char message[512];
} sw_status;

/* Short English name of a result; never NULL, also for out-of-range values ("unknown result").
 * A static string; any thread. */
SW_API const char *sw_result_str(sw_result result);
/* The identifier of a result ("SW_ERR_TRUNCATED"): stable, for scripts and tests;
 * "SW_RESULT_UNKNOWN" out of range. A static string; any thread. */
SW_API const char *sw_result_id_str(sw_result result);

#ifdef __cplusplus
}
#endif
#endif
