/* SPDX-License-Identifier: MIT */
/* Misuse of the public API (never installed): a caller's programming mistake — a NULL desc or
 * out pointer, a stale handle (also a second destroy), a call from a thread that does not own the
 * renderer. CONVENTIONS.md (Errors) makes such a mistake an assert; the API asks for the
 * documented sw_result in release builds (never memory corruption) and an abort with the message
 * in debug builds. SW__MISUSE does both: it fills the status, writes the message to the log hook
 * at SW_LOG_ERROR and returns `result`, and where the library was built with SW_MISUSE_ASSERT=1
 * (CMake option SW_MISUSE_ASSERT, on for Debug builds) it then aborts. */
#ifndef SW_RT_MISUSE_H
#define SW_RT_MISUSE_H

#include <splinewalk/sw_result.h>

#ifndef SW_MISUSE_ASSERT
#define SW_MISUSE_ASSERT 0
#endif

/* Reports the misuse and, when abort_after, aborts (the message also on stderr, in case the
 * host's logger buffers). Returns result. */
sw_result sw__misuse(int abort_after, sw_status *status, sw_result result, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

#define SW__MISUSE(status, result, ...)                                                            \
    sw__misuse(SW_MISUSE_ASSERT, (status), (result), __VA_ARGS__)

#endif
