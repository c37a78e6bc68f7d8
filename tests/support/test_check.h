/* SPDX-License-Identifier: MIT */
/* tests/support: the failure counter and CHECK of the plain-C test programs. Include once, in the
 * program's main file; main returns g_failures != 0. */
#ifndef SW_TEST_CHECK_H
#define SW_TEST_CHECK_H

#include <stdio.h>

static int g_failures;

/* Counts and prints a failed condition with a printf-style message; the test goes on. */
#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            ++g_failures;                                                                          \
            printf("  FAIL: " __VA_ARGS__);                                                        \
            printf("\n");                                                                          \
        }                                                                                          \
    } while (0)

#endif
