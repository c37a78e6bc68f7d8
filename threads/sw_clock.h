/* SPDX-License-Identifier: MIT */
/* The one clock every layer times with: CLOCK_MONOTONIC, unaffected by changes of the wall clock.
 * Any thread. */
#ifndef SW_CLOCK_H
#define SW_CLOCK_H

#include "sw_module_abi.h"

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Nanoseconds since an arbitrary fixed point. */
SW_MODULE_ABI uint64_t sw__clock_ns(void);
/* Milliseconds since the same point. */
SW_MODULE_ABI double sw__clock_ms(void);

#ifdef __cplusplus
}
#endif
#endif
