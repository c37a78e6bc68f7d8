/* SPDX-License-Identifier: MIT */
/* The outline text format (outline_text.h; docs/outlines.md): `outline` lines with placement
 * options, SVG path data (a subset: M L H V Q C A Z, absolute and relative, implicit repeats),
 * `end`. Each subpath is one closed loop of the outline (an open one is closed by a line, as SVG
 * fills it); lines, quadratic and cubic Béziers stay what they are, elliptical arcs become
 * rational quadratic pieces of at most 90 degrees (exact conics, Santana §3.2's kind), so nothing
 * is flattened. Numbers follow SVG's grammar (no hex, inf or nan; "1-2" is two numbers). */
#include "outline_text.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A curve while parsing: offsets into the number pool (pointers come at the end). */
typedef struct curve_rec {
    uint32_t degree;
    size_t points;  /* 2 * (degree + 1) numbers */
    size_t knots;   /* 2 * (degree + 1) numbers */
    size_t weights; /* degree + 1 numbers, or SIZE_MAX: all 1 */
} curve_rec;

typedef struct loop_rec {
    size_t first_curve, n_curves;
} loop_rec;

typedef struct item_rec {
    sw_outline_item item;
    size_t first_loop, n_loops;
    size_t text, font; /* a label's strings: offsets into the parser's chars, or SIZE_MAX */
} item_rec;

typedef struct parser {
    const char *text, *file;
    size_t len, pos;
    int line;
    size_t line_start;
    char *err;
    size_t err_size;
    int failed;
    double *nums;
    size_t n_nums, cap_nums;
    curve_rec *curves;
    size_t n_curves, cap_curves;
    loop_rec *loops;
    size_t n_loops, cap_loops;
    item_rec *items;
    size_t n_items, cap_items;
    char *chars; /* labels' text and font paths, NUL-terminated back to back */
    size_t n_chars, cap_chars;
    /* the path being read */
    int in_item;
    char cmd; /* the last command letter (0: none yet) */
    double cur[2], start[2];
    int subpath_open; /* curves were added since the subpath began */
    size_t loop_first;
    size_t item_curves;
} parser;

static int fail(parser *p, const char *fmt, ...)
{
    if (p->failed)
        return 0;
    p->failed = 1;
    int n =
        snprintf(p->err, p->err_size, "%s:%d:%zu: ", p->file, p->line, p->pos - p->line_start + 1);
    va_list ap;
    va_start(ap, fmt);
    if (n >= 0 && (size_t)n < p->err_size)
        vsnprintf(p->err + n, p->err_size - (size_t)n, fmt, ap);
    va_end(ap);
    return 0;
}

static int grow(parser *p, void **arr, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 1;
    size_t c = *cap ? *cap : 64;
    while (c < need)
        c *= 2;
    void *q = realloc(*arr, c * elem);
    if (!q)
        return fail(p, "out of memory");
    *arr = q;
    *cap = c;
    return 1;
}

/* ---- lexing -------------------------------------------------------------------------------- */

static int at_end_of_line(const parser *p)
{
    return p->pos >= p->len || p->text[p->pos] == '\n';
}

/* Skips spaces, tabs, carriage returns and (in path data) commas. */
static void skip_space(parser *p, int commas)
{
    while (p->pos < p->len) {
        char c = p->text[p->pos];
        if (c == ' ' || c == '\t' || c == '\r' || (commas && c == ','))
            p->pos++;
        else
            break;
    }
}

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

/* SVG's number: [+-]? (digits [. digits?] | . digits) ([eE] [+-]? digits)? */
static int number_span(const parser *p, size_t *end)
{
    size_t i = p->pos, n = p->len;
    const char *t = p->text;
    if (i < n && (t[i] == '+' || t[i] == '-'))
        i++;
    size_t digits = 0;
    while (i < n && is_digit(t[i]))
        i++, digits++;
    if (i < n && t[i] == '.') {
        i++;
        while (i < n && is_digit(t[i]))
            i++, digits++;
    }
    if (digits == 0)
        return 0;
    if (i < n && (t[i] == 'e' || t[i] == 'E')) {
        size_t j = i + 1;
        if (j < n && (t[j] == '+' || t[j] == '-'))
            j++;
        if (j < n && is_digit(t[j])) {
            while (j < n && is_digit(t[j]))
                j++;
            i = j;
        }
    }
    *end = i;
    return 1;
}

static int next_is_number(parser *p)
{
    skip_space(p, 1);
    size_t end;
    return !at_end_of_line(p) && number_span(p, &end);
}

static int read_number(parser *p, const char *what, double *out)
{
    skip_space(p, 1);
    size_t end;
    if (at_end_of_line(p) || !number_span(p, &end))
        return fail(p, "expected a number (%s)", what);
    char buf[64];
    size_t k = end - p->pos;
    if (k >= sizeof buf)
        return fail(p, "number too long (%s)", what);
    memcpy(buf, p->text + p->pos, k);
    buf[k] = '\0';
    double v = strtod(buf, NULL);
    if (!isfinite(v) || fabs(v) > 1e15)
        return fail(p, "number %s out of range (%s: at most 1e15 in magnitude)", buf, what);
    p->pos = end;
    *out = v;
    return 1;
}

/* An arc flag: '0' or '1', with or without separators after it (SVG). */
static int read_flag(parser *p, const char *what, int *out)
{
    skip_space(p, 1);
    if (at_end_of_line(p) || (p->text[p->pos] != '0' && p->text[p->pos] != '1'))
        return fail(p, "expected a flag 0 or 1 (%s)", what);
    *out = p->text[p->pos++] == '1';
    return 1;
}

/* A word of letters, digits, '-' and '_'. */
static size_t read_word(parser *p, char *buf, size_t size)
{
    skip_space(p, 0);
    size_t k = 0;
    while (p->pos < p->len) {
        char c = p->text[p->pos];
        int ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || is_digit(c) || c == '-' ||
                 c == '_' || c == '.';
        if (!ok)
            break;
        if (k + 1 < size)
            buf[k++] = c;
        p->pos++;
    }
    buf[k] = '\0';
    return k;
}

/* ---- curves --------------------------------------------------------------------------------- */

static int push_nums(parser *p, const double *v, size_t n, size_t *at)
{
    if (!grow(p, (void **)&p->nums, &p->cap_nums, p->n_nums + n, sizeof *p->nums))
        return 0;
    *at = p->n_nums;
    memcpy(p->nums + p->n_nums, v, n * sizeof *v);
    p->n_nums += n;
    return 1;
}

/* A Bézier curve of degree d (control points pts, weights w or NULL) from the current point. */
static int add_bezier(parser *p, uint32_t d, const double *pts, const double *w)
{
    if (p->item_curves >= SW_OUTLINE_MAX_CURVES)
        return fail(p, "more than %u curves in one outline", SW_OUTLINE_MAX_CURVES);
    double knots[8];
    for (uint32_t k = 0; k <= d; k++) {
        knots[k] = 0.0;
        knots[d + 1 + k] = 1.0;
    }
    curve_rec c = {d, 0, 0, SIZE_MAX};
    if (!push_nums(p, pts, 2 * (size_t)(d + 1), &c.points) ||
        !push_nums(p, knots, 2 * (size_t)(d + 1), &c.knots) ||
        (w && !push_nums(p, w, d + 1, &c.weights)) ||
        !grow(p, (void **)&p->curves, &p->cap_curves, p->n_curves + 1, sizeof *p->curves))
        return 0;
    p->curves[p->n_curves++] = c;
    p->item_curves++;
    p->subpath_open = 1;
    p->cur[0] = pts[2 * d];
    p->cur[1] = pts[2 * d + 1];
    return 1;
}

static int add_line(parser *p, double x, double y)
{
    if (x == p->cur[0] && y == p->cur[1])
        return 1; /* no length: nothing to draw */
    const double pts[4] = {p->cur[0], p->cur[1], x, y};
    return add_bezier(p, 1, pts, NULL);
}

/* Ends the subpath: closed by a line to its start when it does not end there. */
static int end_subpath(parser *p)
{
    if (!p->subpath_open)
        return 1;
    if (!add_line(p, p->start[0], p->start[1]))
        return 0;
    /* the closing line ends exactly at the start: the loop's joins are bit-exact */
    if (!grow(p, (void **)&p->loops, &p->cap_loops, p->n_loops + 1, sizeof *p->loops))
        return 0;
    p->loops[p->n_loops++] = (loop_rec){p->loop_first, p->n_curves - p->loop_first};
    p->loop_first = p->n_curves;
    p->subpath_open = 0;
    return 1;
}

/* SVG's elliptical arc (SVG 1.1 F.6.5, endpoint to centre parameterization) from the current point
 * to (x2, y2) as rational quadratic pieces of at most 90 degrees: on the unit circle a piece
 * from a0 to a1 = a0 + 2h has end points on the circle, the middle control point at the tangents'
 * meeting point (cos(a0 + h), sin(a0 + h)) / cos h with weight cos h (exact); the ellipse is an
 * affine image of the circle, which keeps weights. */
static int add_arc(parser *p, double rx, double ry, double rot_deg, int large, int sweep, double x2,
                   double y2)
{
    const double x1 = p->cur[0], y1 = p->cur[1];
    if (x1 == x2 && y1 == y2)
        return 1; /* SVG: the arc is omitted */
    rx = fabs(rx);
    ry = fabs(ry);
    if (rx == 0.0 || ry == 0.0)
        return add_line(p, x2, y2); /* SVG: a straight line */
    const double phi = rot_deg * M_PI / 180.0, cp = cos(phi), sp = sin(phi);
    const double hx = 0.5 * (x1 - x2), hy = 0.5 * (y1 - y2);
    const double xp = cp * hx + sp * hy, yp = -sp * hx + cp * hy;
    const double lambda = xp * xp / (rx * rx) + yp * yp / (ry * ry);
    if (lambda > 1.0) { /* SVG: radii too small are scaled up to just reach */
        rx *= sqrt(lambda);
        ry *= sqrt(lambda);
    }
    const double num = rx * rx * ry * ry - rx * rx * yp * yp - ry * ry * xp * xp;
    const double den = rx * rx * yp * yp + ry * ry * xp * xp;
    double sq = den > 0.0 ? sqrt(fmax(0.0, num / den)) : 0.0;
    if (large == sweep)
        sq = -sq;
    const double cxp = sq * rx * yp / ry, cyp = -sq * ry * xp / rx;
    const double cx = cp * cxp - sp * cyp + 0.5 * (x1 + x2),
                 cy = sp * cxp + cp * cyp + 0.5 * (y1 + y2);
    const double ux = (xp - cxp) / rx, uy = (yp - cyp) / ry, vx = (-xp - cxp) / rx,
                 vy = (-yp - cyp) / ry;
    const double a0 = atan2(uy, ux);
    double delta = atan2(ux * vy - uy * vx, ux * vx + uy * vy);
    if (!sweep && delta > 0.0)
        delta -= 2.0 * M_PI;
    else if (sweep && delta < 0.0)
        delta += 2.0 * M_PI;
    int n = (int)ceil(fabs(delta) / (0.5 * M_PI) - 1e-9);
    n = n < 1 ? 1 : n > 4 ? 4 : n;
    const double h = 0.5 * delta / n, wm = cos(h);
    for (int k = 0; k < n; k++) {
        const double s = a0 + 2.0 * h * k, m = s + h, e = s + 2.0 * h;
        const double unit[3][2] = {{cos(s), sin(s)}, {cos(m) / wm, sin(m) / wm}, {cos(e), sin(e)}};
        double pts[6];
        for (int j = 0; j < 3; j++) {
            const double u = rx * unit[j][0], v = ry * unit[j][1];
            pts[2 * j] = cx + cp * u - sp * v;
            pts[2 * j + 1] = cy + sp * u + cp * v;
        }
        pts[0] = p->cur[0]; /* joins bit-exact: the pieces start where the last one ended */
        pts[1] = p->cur[1];
        if (k == n - 1) {
            pts[4] = x2;
            pts[5] = y2;
        }
        const double w[3] = {1.0, wm, 1.0};
        if (!add_bezier(p, 2, pts, w))
            return 0;
    }
    return 1;
}

/* ---- path data --------------------------------------------------------------------------------
 */

static int read_point(parser *p, int rel, const char *what, double out[2])
{
    if (!read_number(p, what, &out[0]) || !read_number(p, what, &out[1]))
        return 0;
    if (rel) {
        out[0] += p->cur[0];
        out[1] += p->cur[1];
    }
    return 1;
}

/* One set of arguments of command c (relative when lower case). */
static int path_step(parser *p, char c)
{
    const int rel = c >= 'a' && c <= 'z';
    const char C = (char)(rel ? c - 'a' + 'A' : c);
    double a[2], b[2], e[2];
    switch (C) {
    case 'M':
        if (!end_subpath(p) || !read_point(p, rel, "M: x y", a))
            return 0;
        p->cur[0] = p->start[0] = a[0];
        p->cur[1] = p->start[1] = a[1];
        p->cmd = rel ? 'l' : 'L'; /* SVG: further pairs are line-tos */
        return 1;
    case 'L':
        return read_point(p, rel, "L: x y", a) && add_line(p, a[0], a[1]);
    case 'H':
        return read_number(p, "H: x", &a[0]) &&
               add_line(p, a[0] + (rel ? p->cur[0] : 0.0), p->cur[1]);
    case 'V':
        return read_number(p, "V: y", &a[1]) &&
               add_line(p, p->cur[0], a[1] + (rel ? p->cur[1] : 0.0));
    case 'Q': {
        if (!read_point(p, rel, "Q: x1 y1 x y", a) || !read_point(p, rel, "Q: x1 y1 x y", e))
            return 0;
        const double pts[6] = {p->cur[0], p->cur[1], a[0], a[1], e[0], e[1]};
        return add_bezier(p, 2, pts, NULL);
    }
    case 'C': {
        if (!read_point(p, rel, "C: x1 y1 x2 y2 x y", a) ||
            !read_point(p, rel, "C: x1 y1 x2 y2 x y", b) ||
            !read_point(p, rel, "C: x1 y1 x2 y2 x y", e))
            return 0;
        const double pts[8] = {p->cur[0], p->cur[1], a[0], a[1], b[0], b[1], e[0], e[1]};
        return add_bezier(p, 3, pts, NULL);
    }
    case 'A': {
        double rx, ry, rot;
        int large, sweep;
        const char *w = "A: rx ry rotation large-arc sweep x y";
        return read_number(p, w, &rx) && read_number(p, w, &ry) && read_number(p, w, &rot) &&
               read_flag(p, w, &large) && read_flag(p, w, &sweep) && read_point(p, rel, w, e) &&
               add_arc(p, rx, ry, rot, large, sweep, e[0], e[1]);
    }
    case 'Z':
        if (!end_subpath(p))
            return 0;
        p->cur[0] = p->start[0];
        p->cur[1] = p->start[1];
        return 1;
    default:
        return fail(p, "unsupported path command '%c' (M L H V Q C A Z, either case)", c);
    }
}

static int is_command(char c)
{
    return strchr("MmLlHhVvQqCcAaZzSsTt", c) != NULL && c != '\0';
}

/* The path data on the rest of the line; the command state carries over to the next line. */
static int path_line(parser *p)
{
    for (;;) {
        skip_space(p, 1);
        if (at_end_of_line(p) || p->text[p->pos] == '#')
            return 1;
        char c = p->text[p->pos];
        if (is_command(c)) {
            p->pos++;
            if (!p->cmd && c != 'M' && c != 'm')
                return fail(p, "path data must begin with M (moveto)");
            p->cmd = c;
            if (!path_step(p, c))
                return 0;
            if (c == 'Z' || c == 'z')
                continue;
        } else if (!p->cmd || p->cmd == 'Z' || p->cmd == 'z') {
            return fail(p, "expected a path command, found '%c'", c);
        } else if (!path_step(p, p->cmd)) { /* an implicit repeat of the last command */
            return 0;
        }
    }
}

/* ---- blocks ----------------------------------------------------------------------------------
 */

static int read_vec3(parser *p, const char *what, double out[3])
{
    return read_number(p, what, &out[0]) && read_number(p, what, &out[1]) &&
           read_number(p, what, &out[2]);
}

/* A double-quoted string ("\\" and "\"" escaped; no line break) into p->chars; *at its offset. */
static int read_quoted(parser *p, const char *what, size_t max, size_t *at)
{
    skip_space(p, 0);
    if (at_end_of_line(p) || p->text[p->pos] != '"')
        return fail(p, "expected a double-quoted %s", what);
    p->pos++;
    *at = p->n_chars;
    size_t n = 0;
    for (;;) {
        if (at_end_of_line(p))
            return fail(p, "the %s's closing '\"' is missing", what);
        char c = p->text[p->pos++];
        if (c == '"')
            break;
        if (c == '\\') {
            if (at_end_of_line(p) || (p->text[p->pos] != '"' && p->text[p->pos] != '\\'))
                return fail(p, "only \\\" and \\\\ are escapes in a %s", what);
            c = p->text[p->pos++];
        }
        if (++n > max)
            return fail(p, "the %s is longer than %zu bytes", what, max);
        if (!grow(p, (void **)&p->chars, &p->cap_chars, p->n_chars + 1, 1))
            return 0;
        p->chars[p->n_chars++] = c;
    }
    if (!grow(p, (void **)&p->chars, &p->cap_chars, p->n_chars + 1, 1))
        return 0;
    p->chars[p->n_chars++] = '\0';
    return 1;
}

/* `outline [name N] [color R G B [A]] [origin X Y Z] [x-axis X Y Z] [y-axis X Y Z]`, or
 * `label "TEXT" [size S] [screen] [align start|middle|end] [font "PATH"]` and the same options */
static int begin_item(parser *p, int is_label)
{
    if (p->n_items >= SW_OUTLINE_MAX_ITEMS)
        return fail(p, "more than %u outlines in one file", SW_OUTLINE_MAX_ITEMS);
    item_rec it;
    memset(&it, 0, sizeof it);
    it.item.line = p->line;
    it.text = it.font = SIZE_MAX;
    it.item.is_label = is_label;
    it.item.label.size = 1.0;
    if (is_label && !read_quoted(p, "label text", 1024, &it.text))
        return 0;
    const float dark[4] = {0.05f, 0.05f, 0.05f, 1.0f};
    memcpy(it.item.color, dark, sizeof dark);
    double origin[3] = {0, 0, 0}, ax[3] = {1, 0, 0}, ay[3] = {0, 1, 0};
    char key[32];
    while (!(skip_space(p, 0), at_end_of_line(p)) && p->text[p->pos] != '#') {
        if (!read_word(p, key, sizeof key))
            return fail(p, "expected an option (name, color, origin, x-axis, y-axis)");
        if (!strcmp(key, "name")) {
            if (!read_word(p, it.item.name, sizeof it.item.name))
                return fail(p, "expected a name after 'name' (letters, digits, - _ .)");
        } else if (!strcmp(key, "color")) {
            double c[4] = {0, 0, 0, 1};
            if (!read_vec3(p, "color R G B [A]", c) ||
                (next_is_number(p) && !read_number(p, "color alpha", &c[3])))
                return 0;
            for (int k = 0; k < 4; k++) {
                if (!(c[k] >= 0.0 && c[k] <= 1.0))
                    return fail(p, "colour component %g outside [0, 1]", c[k]);
                it.item.color[k] = (float)c[k];
            }
        } else if (!strcmp(key, "origin")) {
            if (!read_vec3(p, "origin X Y Z", origin))
                return 0;
        } else if (!strcmp(key, "x-axis")) {
            if (!read_vec3(p, "x-axis X Y Z", ax))
                return 0;
        } else if (!strcmp(key, "y-axis")) {
            if (!read_vec3(p, "y-axis X Y Z", ay))
                return 0;
        } else if (is_label && !strcmp(key, "size")) {
            if (!read_number(p, "size S", &it.item.label.size))
                return 0;
            if (!(it.item.label.size > 0.0))
                return fail(p, "a label's size must be positive");
        } else if (is_label && !strcmp(key, "screen")) {
            it.item.label.screen_size = 1;
        } else if (is_label && !strcmp(key, "align")) {
            char a[16];
            read_word(p, a, sizeof a);
            it.item.label.align = !strcmp(a, "start")    ? 0
                                  : !strcmp(a, "middle") ? 1
                                  : !strcmp(a, "end")    ? 2
                                                         : -1;
            if (it.item.label.align < 0)
                return fail(p, "align '%s' (start, middle or end)", a);
        } else if (is_label && !strcmp(key, "font")) {
            if (!read_quoted(p, "font path", 4095, &it.font))
                return 0;
        } else {
            return fail(p, "unknown option '%s' (name, color, origin, x-axis, y-axis%s)", key,
                        is_label ? ", size, screen, align, font" : "");
        }
    }
    const double n[3] = {ax[1] * ay[2] - ax[2] * ay[1], ax[2] * ay[0] - ax[0] * ay[2],
                         ax[0] * ay[1] - ax[1] * ay[0]};
    const double nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(nl > 0.0) || !isfinite(nl))
        return fail(p, "x-axis and y-axis are parallel (or zero): they span no plane");
    for (int r = 0; r < 3; r++) {
        double *row = it.item.transform + 4 * r;
        row[0] = ax[r];
        row[1] = ay[r];
        row[2] = n[r] / nl;
        row[3] = origin[r];
    }
    it.first_loop = p->n_loops;
    if (!grow(p, (void **)&p->items, &p->cap_items, p->n_items + 1, sizeof *p->items))
        return 0;
    p->items[p->n_items++] = it;
    if (is_label)
        return 1; /* one line: no path, no `end` */
    p->in_item = 1;
    p->cmd = 0;
    p->subpath_open = 0;
    p->loop_first = p->n_curves;
    p->item_curves = 0;
    return 1;
}

static int end_item(parser *p)
{
    if (!end_subpath(p))
        return 0;
    item_rec *it = &p->items[p->n_items - 1];
    it->n_loops = p->n_loops - it->first_loop;
    if (it->n_loops == 0)
        return fail(p, "the outline begun on line %d has no path", it->item.line);
    p->in_item = 0;
    return 1;
}

static int parse_line(parser *p)
{
    skip_space(p, 0);
    if (at_end_of_line(p) || p->text[p->pos] == '#')
        return 1;
    size_t save = p->pos;
    char word[16];
    read_word(p, word, sizeof word);
    if (!strcmp(word, "outline") || !strcmp(word, "label")) {
        if (p->in_item)
            return fail(p, "'%s' inside the outline begun on line %d (missing 'end')", word,
                        p->items[p->n_items - 1].item.line);
        return begin_item(p, word[0] == 'l');
    }
    if (!strcmp(word, "end")) {
        if (!p->in_item)
            return fail(p, "'end' without 'outline'");
        skip_space(p, 0);
        if (!at_end_of_line(p) && p->text[p->pos] != '#')
            return fail(p, "nothing may follow 'end'");
        return end_item(p);
    }
    p->pos = save;
    if (!p->in_item)
        return fail(p, "path data outside an 'outline' ... 'end' block");
    return path_line(p);
}

/* ---- the document ---------------------------------------------------------------------------- */

typedef struct storage {
    sw_trim_curve *curves;
    sw_trim_loop *loops;
    double *nums;
    char *chars;
} storage;

static int finish(parser *p, sw_outline_doc *out)
{
    storage *s = calloc(1, sizeof *s);
    sw_outline_item *items = calloc(p->n_items ? p->n_items : 1, sizeof *items);
    if (s) {
        s->curves = malloc((p->n_curves ? p->n_curves : 1) * sizeof *s->curves);
        s->loops = malloc((p->n_loops ? p->n_loops : 1) * sizeof *s->loops);
    }
    if (!s || !items || !s->curves || !s->loops) {
        if (s) {
            free(s->curves);
            free(s->loops);
        }
        free(s);
        free(items);
        return fail(p, "out of memory");
    }
    s->nums = p->nums; /* moved */
    p->nums = NULL;
    s->chars = p->chars;
    p->chars = NULL;
    for (size_t i = 0; i < p->n_curves; i++) {
        const curve_rec *c = &p->curves[i];
        s->curves[i] =
            (sw_trim_curve){c->degree, c->degree + 1, s->nums + c->knots, s->nums + c->points,
                            c->weights == SIZE_MAX ? NULL : s->nums + c->weights};
    }
    for (size_t l = 0; l < p->n_loops; l++)
        s->loops[l] =
            (sw_trim_loop){s->curves + p->loops[l].first_curve, (uint32_t)p->loops[l].n_curves};
    for (size_t i = 0; i < p->n_items; i++) {
        items[i] = p->items[i].item;
        items[i].shape.loops = s->loops + p->items[i].first_loop;
        items[i].shape.loop_count = (uint32_t)p->items[i].n_loops;
        if (items[i].is_label) {
            items[i].shape = (sw_shape_desc){NULL, 0};
            items[i].label.text = s->chars + p->items[i].text;
            items[i].label.font_path =
                p->items[i].font == SIZE_MAX ? NULL : s->chars + p->items[i].font;
        }
    }
    out->items = items;
    out->n_items = p->n_items;
    out->storage = s;
    return 1;
}

int sw_outline_parse(const char *text, size_t len, const char *file, sw_outline_doc *out, char *err,
                     size_t err_size)
{
    memset(out, 0, sizeof *out);
    parser p;
    memset(&p, 0, sizeof p);
    p.text = text;
    p.len = len;
    p.file = file ? file : "outlines";
    p.err = err;
    p.err_size = err_size;
    p.line = 1;
    if (err_size)
        err[0] = '\0';
    if (len > SW_OUTLINE_MAX_TEXT)
        fail(&p, "the text is %zu bytes (at most %u)", len, SW_OUTLINE_MAX_TEXT);
    else if (memchr(text, '\0', len))
        fail(&p, "the text holds a NUL byte (not a text file)");
    while (!p.failed && p.pos < p.len) {
        p.line_start = p.pos;
        if (parse_line(&p)) {
            skip_space(&p, 1);
            if (!at_end_of_line(&p) && p.text[p.pos] != '#')
                fail(&p, "unexpected '%c'", p.text[p.pos]);
        }
        while (p.pos < p.len && p.text[p.pos] != '\n')
            p.pos++;
        if (p.pos < p.len) {
            p.pos++;
            p.line++;
        }
    }
    if (!p.failed && p.in_item) {
        p.line_start = p.pos;
        fail(&p, "the outline begun on line %d has no 'end'", p.items[p.n_items - 1].item.line);
    }
    if (!p.failed && p.n_items == 0)
        fail(&p, "no outline in the text ('outline' ... path ... 'end', or 'label \"TEXT\"')");
    int ok = !p.failed && finish(&p, out);
    free(p.nums);
    free(p.chars);
    free(p.curves);
    free(p.loops);
    free(p.items);
    return ok ? 0 : 1;
}

void sw_outline_doc_free(sw_outline_doc *doc)
{
    if (!doc)
        return;
    storage *s = doc->storage;
    if (s) {
        free(s->curves);
        free(s->loops);
        free(s->nums);
        free(s->chars);
        free(s);
    }
    free(doc->items);
    memset(doc, 0, sizeof *doc);
}
