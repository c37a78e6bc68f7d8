/* SPDX-License-Identifier: MIT */
/* Decimal numbers as splinewalk's text formats (.tsm, camera paths) and its command line write
 * them. Never installed. */
#ifndef SW_DECIMAL_H
#define SW_DECIMAL_H

enum { SW_DECIMAL_OK = 0, SW_DECIMAL_NOT_A_NUMBER = -1, SW_DECIMAL_OUT_OF_RANGE = -2 };

/* The decimal number at the start of text ([+-] digits [. digits] [e [+-] digits]; no
 * hexadecimal, inf or nan) into *out; *end: the first character after it. An underflowing number
 * is kept (rounded toward 0, as strtod does), an overflowing one is out of range. Returns an
 * SW_DECIMAL_ code. Any thread. */
int sw__parse_decimal(const char *text, const char **end, double *out);

#endif
