/* SPDX-License-Identifier: MIT */
/* The command line's numbers: sizes, counts, decimal values, cameras and seeds (cli_numbers.h). */
#include "cli_numbers.h"
#include "sw_decimal.h"
#include "sw_rt.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>

/* Why the last sw_cli_parse_* call refused its text, when more than "not of the form" ("" else):
 * the command-line tools are single-threaded. */
static char g_parse_reason[160];

static int refuse(const char *why)
{
    snprintf(g_parse_reason, sizeof g_parse_reason, "%s", why);
    return -1;
}

int sw_cli_bad_value(const char *cmd, const char *arg, const char *val, const char *usage)
{
    fprintf(stderr, "splinewalk %s: bad value '%s' for %s%s%s\n%s", cmd, val, arg,
            g_parse_reason[0] ? ": " : "", g_parse_reason, usage ? usage : "");
    return 2;
}

/* The unsigned decimal integer at the start of text: digits only (strtol and strtoull would also
 * take leading space and a sign, and strtoull wraps "-1" to 2^64 - 1). *end: the first character
 * after the digits. Returns -1 when there is no digit or the value exceeds max. */
static int parse_digits(const char *text, const char **end, unsigned long long max,
                        unsigned long long *out)
{
    unsigned long long v = 0;
    const char *p = text;
    for (; *p >= '0' && *p <= '9'; p++) {
        const unsigned d = (unsigned)(*p - '0');
        if (v > max / 10 || (v == max / 10 && d > max % 10))
            return -1;
        v = 10 * v + d;
    }
    *end = p;
    if (p == text)
        return -1;
    *out = v;
    return 0;
}

int sw_cli_parse_size(const char *text, int32_t *w, int32_t *h)
{
    g_parse_reason[0] = '\0';
    const char *end;
    unsigned long long a, b;
    if (parse_digits(text, &end, 16384, &a) != 0 || (*end != 'x' && *end != 'X'))
        return -1;
    if (parse_digits(end + 1, &end, 16384, &b) != 0 || *end != '\0' || a < 1 || b < 1)
        return -1;
    *w = (int32_t)a;
    *h = (int32_t)b;
    return 0;
}

int sw_cli_parse_camera(const char *text, sw_camera *out)
{
    g_parse_reason[0] = '\0';
    double v[10];
    const char *p = text;
    for (int i = 0; i < 10; i++) {
        const char *end;
        if (sw__parse_decimal(p, &end, &v[i]) != SW_DECIMAL_OK)
            return -1;
        if (i < 9 && *end != ',')
            return -1;
        if (i == 9 && *end != '\0')
            return -1;
        p = end + 1;
    }
    for (int k = 0; k < 3; k++) {
        out->eye[k] = v[k];
        out->target[k] = v[3 + k];
        out->up[k] = v[6 + k];
    }
    out->fovy_deg = v[9];
    const char *problem = sw_rt_camera_problem(out); /* every frame's check (fovy given here) */
    return problem ? refuse(problem) : 0;
}

int sw_cli_parse_count(const char *text, int lo, int hi, int *out)
{
    g_parse_reason[0] = '\0';
    const char *end;
    unsigned long long v;
    if (hi < 0 || parse_digits(text, &end, (unsigned long long)hi, &v) != 0 || *end != '\0' ||
        (long long)v < lo)
        return -1;
    *out = (int)v;
    return 0;
}

int sw_cli_parse_positive(const char *text, double *out)
{
    g_parse_reason[0] = '\0';
    const char *end;
    double v;
    if (sw__parse_decimal(text, &end, &v) != SW_DECIMAL_OK || *end != '\0' || !(v > 0.0))
        return -1;
    *out = v;
    return 0;
}

int sw_cli_parse_error_px(const char *text, double *out)
{
    double v;
    if (sw_cli_parse_positive(text, &v) != 0)
        return -1;
    if (!(v >= SW_ERROR_MIN_PX))
        return refuse("a screen-space error must be at least 0.01 px (SW_ERROR_MIN_PX)");
    *out = v;
    return 0;
}

int sw_cli_parse_seed(const char *text, unsigned long long *out)
{
    g_parse_reason[0] = '\0';
    const char *end;
    unsigned long long v;
    if (parse_digits(text, &end, ULLONG_MAX, &v) != 0 || *end != '\0')
        return -1;
    *out = v;
    return 0;
}

/* One byte count: digits with an optional binary suffix K, M, G or T (case-insensitive). */
static int parse_bytes(const char *text, const char **end, uint64_t *out)
{
    unsigned long long v;
    if (parse_digits(text, end, ULLONG_MAX, &v) != 0)
        return -1;
    int shift = 0;
    switch (**end) {
    case 'k':
    case 'K':
        shift = 10;
        break;
    case 'm':
    case 'M':
        shift = 20;
        break;
    case 'g':
    case 'G':
        shift = 30;
        break;
    case 't':
    case 'T':
        shift = 40;
        break;
    default:
        break;
    }
    if (shift) {
        if (v > (ULLONG_MAX >> shift))
            return refuse("more bytes than 2^64");
        v <<= shift;
        ++*end;
    }
    *out = v;
    return 0;
}

int sw_cli_parse_memory_budget(const char *text, uint64_t *host, uint64_t *gpu)
{
    g_parse_reason[0] = '\0';
    const char *end;
    uint64_t h, g = 0;
    if (parse_bytes(text, &end, &h) != 0)
        return -1;
    if (*end == ',' && parse_bytes(end + 1, &end, &g) != 0)
        return -1;
    if (*end != '\0')
        return -1;
    *host = h;
    *gpu = g;
    return 0;
}
