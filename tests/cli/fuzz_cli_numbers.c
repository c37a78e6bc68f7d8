/* SPDX-License-Identifier: MIT */
/* libFuzzer harness for the command line's numbers (tools/splinewalk/cli_numbers.c) and the decimal
 * reader under them (scenegraph/decimal.c). The first byte picks the parser, the rest is its text.
 * Each accepted text must be what an independent reading says it is:
 * - the decimal reader consumes exactly the longest prefix a POSIX regular expression of its
 *   grammar matches (a reader that took "0x1", "inf" or " 1" would fail here), and its value is
 *   finite and survives a %.17g round trip;
 * - sizes, counts and seeds are digits only, read digit by digit here, within their limits;
 * - a camera's ten numbers are each a decimal number and the camera passes the frame's own
 *   check (sw_rt_camera_problem, inside sw_camera_check), so the command line accepts no camera
 *   a frame refuses.
 * A refused text must leave the output untouched.
 * Planted: counts read by strtol again (which takes a sign and leading space): it fails on "+3"
 * within seconds. */
#include "cli_numbers.h"
#include "sw_decimal.h"
#include "sw_rt.h"

#include <math.h>
#include <regex.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_TEXT = 512 };

static regex_t g_decimal;

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    if (regcomp(&g_decimal, "^[+-]?([0-9]+(\\.[0-9]*)?|\\.[0-9]+)([eE][+-]?[0-9]+)?",
                REG_EXTENDED) != 0)
        abort();
    return 0;
}

/* Length of the decimal number at the start of text by the regular expression, 0 if none. */
static size_t regex_decimal_length(const char *text)
{
    regmatch_t m;
    return regexec(&g_decimal, text, 1, &m, 0) == 0 ? (size_t)m.rm_eo : 0;
}

static void check_decimal(const char *text)
{
    const char *end = NULL;
    double v = -7.0;
    const int r = sw__parse_decimal(text, &end, &v);
    const size_t n = regex_decimal_length(text);
    if ((size_t)(end - text) != n) /* the grammar, read independently */
        abort();
    if (r == SW_DECIMAL_NOT_A_NUMBER && n != 0)
        abort();
    if (r != SW_DECIMAL_OK)
        return;
    char again[64];
    const char *end2;
    double w;
    snprintf(again, sizeof again, "%.17g", v);
    if (!isfinite(v) || sw__parse_decimal(again, &end2, &w) != SW_DECIMAL_OK || *end2 ||
        memcmp(&v, &w, sizeof v) != 0)
        abort();
}

/* Reads text as [0-9]+ with nothing after, independently of the parser: -1 when it is not, or
 * when it exceeds max. */
static int digits_only(const char *text, unsigned long long max, unsigned long long *out)
{
    if (!*text)
        return -1;
    long double v = 0; /* wide enough to see an overflow of max without wrapping */
    for (const char *p = text; *p; p++) {
        if (*p < '0' || *p > '9')
            return -1;
        v = 10 * v + (*p - '0');
        if (v > (long double)max)
            return -1;
    }
    *out = (unsigned long long)v;
    return 0;
}

static void check_size(const char *text)
{
    int32_t w = -1, h = -1;
    const int r = sw_cli_parse_size(text, &w, &h);
    const char *x = strpbrk(text, "xX");
    char first[MAX_TEXT];
    unsigned long long a = 0, b = 0;
    int expect = -1;
    if (x && (size_t)(x - text) < sizeof first) {
        memcpy(first, text, (size_t)(x - text));
        first[x - text] = '\0';
        expect = digits_only(first, 16384, &a) == 0 && digits_only(x + 1, 16384, &b) == 0 &&
                         a >= 1 && b >= 1
                     ? 0
                     : -1;
    }
    if (r != expect || (r == 0 && (w != (int32_t)a || h != (int32_t)b)) ||
        (r != 0 && (w != -1 || h != -1)))
        abort();
}

static void check_count(const char *text, int lo, int hi)
{
    int v = -1;
    unsigned long long ref = 0;
    const int r = sw_cli_parse_count(text, lo, hi, &v);
    const int expect =
        digits_only(text, (unsigned long long)hi, &ref) == 0 && ref >= (unsigned long long)lo ? 0
                                                                                              : -1;
    if (r != expect || (r == 0 && (unsigned long long)v != ref) || (r != 0 && v != -1))
        abort();
}

static void check_seed(const char *text)
{
    unsigned long long v = 7, ref = 0;
    const int r = sw_cli_parse_seed(text, &v);
    const int expect = digits_only(text, ~0ULL, &ref);
    if (r != expect || (r == 0 && v != ref) || (r != 0 && v != 7))
        abort();
}

static void check_positive(const char *text, int error_px)
{
    double v = -7.0;
    const int r = error_px ? sw_cli_parse_error_px(text, &v) : sw_cli_parse_positive(text, &v);
    const char *end;
    double ref;
    const int whole = sw__parse_decimal(text, &end, &ref) == SW_DECIMAL_OK && !*end;
    const double floor = error_px ? SW_ERROR_MIN_PX : 0.0;
    const int expect = whole && ref > 0.0 && ref >= floor ? 0 : -1;
    if (r != expect || (r == 0 && memcmp(&v, &ref, sizeof v) != 0) || (r != 0 && v != -7.0))
        abort();
}

static void check_camera(const char *text)
{
    sw_camera c;
    memset(&c, 0x5a, sizeof c);
    if (sw_cli_parse_camera(text, &c) != 0)
        return;
    /* ten comma-separated decimal numbers, the last one ending the text */
    const char *p = text;
    for (int i = 0; i < 10; i++) {
        const size_t n = regex_decimal_length(p);
        if (n == 0 || p[n] != (i < 9 ? ',' : '\0'))
            abort();
        p += n + 1;
    }
    if (sw_rt_camera_problem(&c) != NULL || !(c.fovy_deg >= SW_FOVY_MIN_DEG))
        abort();
}

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);
int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    if (size < 1 || size > MAX_TEXT)
        return 0;
    char text[MAX_TEXT + 1];
    memcpy(text, data + 1, size - 1);
    text[size - 1] = '\0'; /* a text with a NUL inside is read up to it, as argv would be */
    switch (data[0] % 8) {
    case 0:
        check_decimal(text);
        break;
    case 1:
        check_size(text);
        break;
    case 2:
        check_count(text, 1, 1 << 20);
        break;
    case 3:
        check_count(text, 2, 3);
        break;
    case 4:
        check_seed(text);
        break;
    case 5:
        check_positive(text, 0);
        break;
    case 6:
        check_positive(text, 1);
        break;
    default:
        check_camera(text);
        break;
    }
    return 0;
}
