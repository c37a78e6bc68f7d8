/* SPDX-License-Identifier: MIT */
/* Decimal numbers as the text formats and the command line write them: strtod alone would also
 * take hexadecimal ("0x10"), "inf", "nan" and locale forms, which no file of ours contains and a
 * user never means. */
#include "sw_decimal.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>

/* Length of the decimal number at the start of s ([+-] digits [. digits] [e [+-] digits], digits
 * on at least one side of the point), 0 when there is none. */
static size_t decimal_length(const char *s)
{
    size_t i = 0, digits = 0;
    if (s[i] == '+' || s[i] == '-')
        i++;
    for (; s[i] >= '0' && s[i] <= '9'; i++)
        digits++;
    if (s[i] == '.')
        for (i++; s[i] >= '0' && s[i] <= '9'; i++)
            digits++;
    if (!digits)
        return 0;
    if (s[i] == 'e' || s[i] == 'E') {
        size_t j = i + 1;
        if (s[j] == '+' || s[j] == '-')
            j++;
        if (s[j] >= '0' && s[j] <= '9') {
            while (s[j] >= '0' && s[j] <= '9')
                j++;
            i = j;
        }
    }
    return i;
}

int sw__parse_decimal(const char *text, const char **end, double *out)
{
    const size_t n = decimal_length(text);
    *end = text + n;
    if (n == 0)
        return SW_DECIMAL_NOT_A_NUMBER;
    char *stop;
    errno = 0;
    const double x = strtod(text, &stop);
    /* an underflow (below DBL_MIN, e.g. 1e-310) is a tiny finite number, kept as strtod rounds
     * it; only an overflow is out of range */
    if (stop != *end || !isfinite(x))
        return SW_DECIMAL_OUT_OF_RANGE;
    *out = x;
    return SW_DECIMAL_OK;
}
