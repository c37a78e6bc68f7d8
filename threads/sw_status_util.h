/* SPDX-License-Identifier: MIT */
/* Internal helpers for filling an optional sw_status (never installed). */
#ifndef SW_STATUS_UTIL_H
#define SW_STATUS_UTIL_H

#include "sw_module_abi.h"

#include <splinewalk/sw_result.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Fills `status` (may be NULL) with `result` and a printf-style message; returns `result` so a
 * caller can write `return sw__fail(status, SW_ERR_FORMAT, "%s: offset %zu: ...", ...)`. */
SW_MODULE_ABI sw_result sw__fail(sw_status *status, sw_result result, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Marks `status` (may be NULL) as SW_OK with an empty message. */
SW_MODULE_ABI void sw__status_ok(sw_status *status);

#ifdef __cplusplus
}
#endif
#endif
