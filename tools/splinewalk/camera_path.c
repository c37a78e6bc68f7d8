/* SPDX-License-Identifier: MIT */
/* Camera paths: the text format of docs/camera-path.md (parse, then validate), evaluation by a
 * Catmull-Rom-tangent Hermite spline over the key times, and the stock orbit and fly-through. */
#include "sw_camera_path.h"
#include "sw_hooks.h"

#include "sw_decimal.h"
#include "sw_rt.h"
#include "sw_safe_read.h"
#include "sw_safe_write.h"
#include "sw_status_util.h"

#include <assert.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

enum {
    MAX_TOKEN = 64,  /* the longest number written with %.17g is 24 characters */
    MAX_FIELDS = 16, /* a key has 12; more is an error, not a reason to read on */
    KEY_FIELDS = 12,
    CHECK_SAMPLES = 32, /* interpolated cameras checked per segment */
};

/* ---- small vector helpers -------------------------------------------------------------------- */
static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double norm3(const double a[3])
{
    return sqrt(dot3(a, a));
}

/* ---- lines and fields ------------------------------------------------------------------------ */
typedef struct lexer {
    const char *p, *end;
    uint32_t line;
    int unterminated; /* the current line is the text's last and has no newline: possibly cut */
    const char *name;
    sw_status *status;
    int n;                         /* fields of the current line */
    char f[MAX_FIELDS][MAX_TOKEN]; /* NUL-terminated; printable (others shown as '?') */
} lexer;

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r';
}

/* Splits the current line [s, e) into fields. Returns SW_OK or a format error for an overlong
 * field or line. */
static sw_result split_fields(lexer *lx, const char *s, const char *e)
{
    lx->n = 0;
    while (s < e) {
        while (s < e && is_space(*s))
            s++;
        if (s >= e)
            break;
        const char *b = s;
        while (s < e && !is_space(*s))
            s++;
        const size_t len = (size_t)(s - b);
        if (lx->n == MAX_FIELDS)
            return sw__fail(lx->status, SW_ERR_FORMAT, "%s:%u: more than %d fields on one line",
                            lx->name, lx->line, MAX_FIELDS);
        if (len >= MAX_TOKEN)
            return sw__fail(lx->status, SW_ERR_FORMAT,
                            "%s:%u: field %d is %zu characters long (at most %d expected)",
                            lx->name, lx->line, lx->n + 1, len, MAX_TOKEN - 1);
        char *out = lx->f[lx->n++];
        for (size_t k = 0; k < len; k++) {
            const unsigned char ch = (unsigned char)b[k];
            out[k] = ch >= 32 && ch <= 126 ? (char)ch : '?';
        }
        out[len] = '\0';
    }
    return SW_OK;
}

/* Advances to the next line holding a field. Returns 1 with the fields in lx->f, 0 at the end of
 * the text, -1 on an error (status filled). */
static int next_record(lexer *lx)
{
    while (lx->p < lx->end) {
        const char *s = lx->p;
        const char *e = memchr(s, '\n', (size_t)(lx->end - s));
        if (!e)
            e = lx->end;
        lx->p = e < lx->end ? e + 1 : e;
        lx->unterminated = e == lx->end;
        if (lx->line == UINT32_MAX) {
            sw__fail(lx->status, SW_ERR_LIMIT, "%s: more than %u lines", lx->name, UINT32_MAX - 1);
            return -1;
        }
        lx->line++;
        const char *hash = memchr(s, '#', (size_t)(e - s));
        if (split_fields(lx, s, hash ? hash : e) != SW_OK)
            return -1;
        if (lx->n > 0)
            return 1;
    }
    return 0;
}

/* A record with the wrong number of fields: too few on an unterminated last line means the file
 * was cut short. */
static sw_result wrong_count(lexer *lx, const char *record, int expected)
{
    if (lx->n < expected && lx->unterminated)
        return sw__fail(lx->status, SW_ERR_TRUNCATED,
                        "%s:%u: the file ends inside a '%s' record (%d of %d fields)", lx->name,
                        lx->line, record, lx->n, expected);
    return sw__fail(lx->status, SW_ERR_FORMAT, "%s:%u: a '%s' record has %d fields, found %d",
                    lx->name, lx->line, record, expected, lx->n);
}

static sw_result field_double(lexer *lx, int i, const char *what, double *out)
{
    const char *end;
    double x = 0.0;
    const int got = sw__parse_decimal(lx->f[i], &end, &x);
    if (got == SW_DECIMAL_NOT_A_NUMBER || *end != '\0')
        return sw__fail(lx->status, SW_ERR_FORMAT,
                        "%s:%u: expected %s (a decimal number), found '%s'", lx->name, lx->line,
                        what, lx->f[i]);
    if (got != SW_DECIMAL_OK)
        return sw__fail(lx->status, SW_ERR_FORMAT, "%s:%u: %s is '%s', beyond a double's range",
                        lx->name, lx->line, what, lx->f[i]);
    *out = x;
    return SW_OK;
}

static sw_result field_count(lexer *lx, int i, const char *what, unsigned long hi,
                             unsigned long *out)
{
    const char *s = lx->f[i];
    char *end = NULL;
    errno = 0;
    const unsigned long v = (*s >= '0' && *s <= '9') ? strtoul(s, &end, 10) : 0;
    if (!end || *end != '\0' || errno == ERANGE || v < 1 || v > hi)
        return sw__fail(lx->status, SW_ERR_FORMAT,
                        "%s:%u: expected %s (an integer in 1..%lu), "
                        "found '%s'",
                        lx->name, lx->line, what, hi, s);
    *out = v;
    return SW_OK;
}

/* ---- parsing --------------------------------------------------------------------------------- */
static sw_result parse_header(lexer *lx)
{
    const int got = next_record(lx);
    if (got < 0)
        return lx->status ? lx->status->result : SW_ERR_FORMAT;
    if (got == 0)
        return sw__fail(lx->status, SW_ERR_FORMAT, "%s:%u: empty; expected 'splinewalk-path %d'",
                        lx->name, lx->line ? lx->line : 1, SW_RT_PATH_VERSION);
    if (strcmp(lx->f[0], "splinewalk-path") != 0)
        return sw__fail(lx->status, SW_ERR_FORMAT,
                        "%s:%u: expected 'splinewalk-path %d' as the first record, found '%s'",
                        lx->name, lx->line, SW_RT_PATH_VERSION, lx->f[0]);
    if (lx->n != 2)
        return wrong_count(lx, "splinewalk-path", 2);
    unsigned long v;
    if (field_count(lx, 1, "the format version", 1000000ul, &v) != SW_OK)
        return SW_ERR_FORMAT;
    if (v != SW_RT_PATH_VERSION)
        return sw__fail(lx->status, SW_ERR_VERSION,
                        "%s:%u: format version %lu; this program reads version %d", lx->name,
                        lx->line, v, SW_RT_PATH_VERSION);
    return SW_OK;
}

static sw_result parse_key(lexer *lx, sw_rt_path_key *k)
{
    static const char *const what[KEY_FIELDS - 1] = {
        "the key time", "eye x", "eye y", "eye z", "target x",      "target y",
        "target z",     "up x",  "up y",  "up z",  "fovy (degrees)"};
    if (lx->n != KEY_FIELDS)
        return wrong_count(lx, "key", KEY_FIELDS);
    double v[KEY_FIELDS - 1];
    for (int i = 0; i < KEY_FIELDS - 1; i++)
        if (field_double(lx, i + 1, what[i], &v[i]) != SW_OK)
            return SW_ERR_FORMAT;
    memset(k, 0, sizeof *k);
    k->t = v[0];
    for (int c = 0; c < 3; c++) {
        k->camera.eye[c] = v[1 + c];
        k->camera.target[c] = v[4 + c];
        k->camera.up[c] = v[7 + c];
    }
    k->camera.fovy_deg = v[10];
    k->line = lx->line;
    return SW_OK;
}

static sw_result push_key(lexer *lx, sw_rt_camera_path *p, uint32_t *cap, const sw_rt_path_key *k)
{
    if (p->n_keys == SW_RT_PATH_MAX_KEYS)
        return sw__fail(lx->status, SW_ERR_LIMIT, "%s:%u: more than %u keys", lx->name, lx->line,
                        SW_RT_PATH_MAX_KEYS);
    if (p->n_keys == *cap) {
        const uint32_t ncap = *cap ? *cap * 2 : 64;
        sw_rt_path_key *g = sw__realloc(p->keys, (size_t)ncap * sizeof *g);
        if (!g)
            return sw__fail(lx->status, SW_ERR_OUT_OF_MEMORY, "%s:%u: out of memory", lx->name,
                            lx->line);
        p->keys = g;
        *cap = ncap;
    }
    p->keys[p->n_keys++] = *k;
    return SW_OK;
}

/* One record after the header. */
static sw_result parse_record(lexer *lx, sw_rt_camera_path *p, uint32_t *cap, uint32_t *closed_line,
                              uint32_t *frames_line)
{
    if (!strcmp(lx->f[0], "key")) {
        sw_rt_path_key k;
        sw_result r = parse_key(lx, &k);
        return r == SW_OK ? push_key(lx, p, cap, &k) : r;
    }
    if (!strcmp(lx->f[0], "closed")) {
        if (*closed_line)
            return sw__fail(lx->status, SW_ERR_FORMAT,
                            "%s:%u: 'closed' given twice (first on line %u)", lx->name, lx->line,
                            *closed_line);
        if (lx->n != 1)
            return wrong_count(lx, "closed", 1);
        *closed_line = lx->line;
        p->closed = 1;
        return SW_OK;
    }
    if (!strcmp(lx->f[0], "frames")) {
        if (*frames_line)
            return sw__fail(lx->status, SW_ERR_FORMAT,
                            "%s:%u: 'frames' given twice (first on line %u)", lx->name, lx->line,
                            *frames_line);
        if (lx->n != 2)
            return wrong_count(lx, "frames", 2);
        unsigned long v;
        if (field_count(lx, 1, "the frame count", SW_RT_PATH_MAX_FRAMES, &v) != SW_OK)
            return SW_ERR_FORMAT;
        *frames_line = lx->line;
        p->frames = (uint32_t)v;
        return SW_OK;
    }
    if (!strcmp(lx->f[0], "splinewalk-path"))
        return sw__fail(lx->status, SW_ERR_FORMAT, "%s:%u: a second 'splinewalk-path' header",
                        lx->name, lx->line);
    return sw__fail(lx->status, SW_ERR_FORMAT,
                    "%s:%u: expected a record 'key', 'closed' or 'frames', found '%s'", lx->name,
                    lx->line, lx->f[0]);
}

static sw_result parse_text(const char *text, size_t len, const char *name, sw_rt_camera_path *p,
                            sw_status *status)
{
    lexer lx;
    memset(&lx, 0, sizeof lx);
    lx.p = text;
    lx.end = text + len;
    lx.name = name;
    lx.status = status;
    sw_result r = parse_header(&lx);
    uint32_t cap = 0, closed_line = 0, frames_line = 0;
    while (r == SW_OK) {
        const int got = next_record(&lx);
        if (got == 0)
            break;
        r = got < 0 ? status->result : parse_record(&lx, p, &cap, &closed_line, &frames_line);
    }
    if (r == SW_OK && p->n_keys == 0)
        r = sw__fail(status, SW_ERR_FORMAT,
                     "%s:%u: the path has no 'key' record (at least one "
                     "expected)",
                     name, lx.line);
    return r;
}

/* ---- validation ------------------------------------------------------------------------------ */
static int same_camera(const sw_camera *a, const sw_camera *b)
{
    double scale = 1.0;
    for (int k = 0; k < 3; k++)
        scale = fmax(scale, fmax(fmax(fabs(a->eye[k]), fabs(a->target[k])), fabs(a->up[k])));
    const double tol = 1e-9 * scale;
    for (int k = 0; k < 3; k++)
        if (fabs(a->eye[k] - b->eye[k]) > tol || fabs(a->target[k] - b->target[k]) > tol ||
            fabs(a->up[k] - b->up[k]) > tol)
            return 0;
    return fabs(a->fovy_deg - b->fovy_deg) <= 1e-9 * fmax(1.0, a->fovy_deg);
}

static sw_result validate_keys(const sw_rt_camera_path *p, const char *name, sw_status *status)
{
    for (uint32_t i = 0; i < p->n_keys; i++) {
        const sw_rt_path_key *k = &p->keys[i];
        const char *problem = sw_rt_camera_problem(&k->camera);
        if (problem)
            return sw__fail(status, SW_ERR_FORMAT, "%s:%u: %s", name, k->line, problem);
        if (i == 0)
            continue;
        const sw_rt_path_key *prev = &p->keys[i - 1];
        if (!(k->t > prev->t))
            return sw__fail(status, SW_ERR_FORMAT,
                            "%s:%u: key time %g is not after the previous key's %g (line %u); "
                            "times must increase strictly",
                            name, k->line, k->t, prev->t, prev->line);
        const double c =
            dot3(k->camera.up, prev->camera.up) / (norm3(k->camera.up) * norm3(prev->camera.up));
        if (c < -0.99)
            return sw__fail(status, SW_ERR_FORMAT,
                            "%s:%u: the up vector is nearly opposite to the previous key's (line "
                            "%u): the camera's roll between them is undefined",
                            name, k->line, prev->line);
    }
    if (p->closed) {
        const sw_rt_path_key *last = &p->keys[p->n_keys - 1];
        if (p->n_keys < 3)
            return sw__fail(status, SW_ERR_FORMAT,
                            "%s:%u: a closed path needs at least 3 keys "
                            "(the last repeating the first), found %u",
                            name, last->line, p->n_keys);
        if (!same_camera(&last->camera, &p->keys[0].camera))
            return sw__fail(status, SW_ERR_FORMAT,
                            "%s:%u: the path is 'closed' but its last key "
                            "differs from its first (line %u)",
                            name, last->line, p->keys[0].line);
    }
    return SW_OK;
}

/* Keys can each be fine while the spline between them passes the eye through the target (or the
 * view through the up vector): sample every segment so that the run does not fail half way. */
static sw_result validate_segments(const sw_rt_camera_path *p, const char *name, sw_status *status)
{
    for (uint32_t i = 0; i + 1 < p->n_keys; i++) {
        const double a = p->keys[i].t, b = p->keys[i + 1].t;
        for (int s = 1; s < CHECK_SAMPLES; s++) {
            const double t = a + (b - a) * s / CHECK_SAMPLES;
            sw_camera c;
            sw_rt_path_eval(p, t, &c);
            const char *problem = sw_rt_camera_problem(&c);
            if (problem)
                return sw__fail(status, SW_ERR_FORMAT,
                                "%s:%u: between this key and the next "
                                "(line %u), at t = %g, %s",
                                name, p->keys[i].line, p->keys[i + 1].line, t, problem);
        }
    }
    return SW_OK;
}

sw_result sw_rt_path_parse(const char *text, size_t len, const char *name, sw_rt_camera_path *out,
                           sw_status *status)
{
    assert(text || len == 0);
    assert(name && out);
    sw_status local = {0};
    if (!status)
        status = &local; /* the lexer reads back the result it reported */
    memset(out, 0, sizeof *out);
    sw_rt_camera_path p = {0};
    sw_result r = parse_text(text ? text : "", len, name, &p, status);
    if (r == SW_OK)
        r = validate_keys(&p, name, status);
    if (r == SW_OK)
        r = validate_segments(&p, name, status);
    if (r != SW_OK) {
        sw_rt_path_free(&p);
        return r;
    }
    *out = p;
    sw__status_ok(status);
    return SW_OK;
}

sw_result sw_rt_path_load(const char *file, sw_rt_camera_path *out, sw_status *status)
{
    assert(file && out);
    memset(out, 0, sizeof *out);
    char *buf = NULL;
    size_t n = 0;
    /* non-blocking, regular files only, the size refused before a byte is read */
    sw_result r = sw__in_read_all(file, SW_RT_PATH_MAX_BYTES, "camera path", &buf, &n, status);
    if (r == SW_OK)
        r = sw_rt_path_parse(buf, n, file, out, status);
    sw__free(buf);
    return r;
}

static int write_path(FILE *f, const void *ctx)
{
    const sw_rt_camera_path *p = ctx;
    fprintf(f,
            "splinewalk-path %d\n"
            "# camera path (docs/camera-path.md): eye and target on a Catmull-Rom spline over "
            "the key times,\n# up by normalized lerp, fovy linearly\n",
            SW_RT_PATH_VERSION);
    if (p->closed)
        fputs("closed\n", f);
    if (p->frames)
        fprintf(f, "frames %u\n", p->frames);
    fputs("# key  t  eye_x eye_y eye_z  target_x target_y target_z  up_x up_y up_z  fovy\n", f);
    for (uint32_t i = 0; i < p->n_keys; i++) {
        const sw_rt_path_key *k = &p->keys[i];
        const sw_camera *c = &k->camera;
        fprintf(f, "key %.17g  %.17g %.17g %.17g  %.17g %.17g %.17g  %.17g %.17g %.17g  %.17g\n",
                k->t, c->eye[0], c->eye[1], c->eye[2], c->target[0], c->target[1], c->target[2],
                c->up[0], c->up[1], c->up[2], c->fovy_deg);
    }
    return ferror(f) ? -1 : 0;
}

/* The path's text, read back through the parser before anything is written: a path with keys
 * the parser would refuse (a time that overflowed, a degenerate camera) is never written. */
static sw_result path_text(const sw_rt_camera_path *path, const char *file, char **text,
                           size_t *len, sw_status *status)
{
    FILE *f = open_memstream(text, len);
    if (!f)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", file);
    const int bad = write_path(f, path);
    if (fclose(f) != 0 || bad) {
        free(*text); /* open_memstream's buffer: the C library's malloc */
        *text = NULL;
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", file);
    }
    char name[4200];
    snprintf(name, sizeof name, "%s (not written)", file);
    sw_rt_camera_path back;
    sw_result r = sw_rt_path_parse(*text, *len, name, &back, status);
    sw_rt_path_free(&back);
    if (r != SW_OK) {
        free(*text);
        *text = NULL;
    }
    return r;
}

sw_result sw_rt_path_save(const sw_rt_camera_path *path, const char *file, unsigned flags,
                          sw_status *status)
{
    assert(path && file);
    char *text = NULL;
    size_t len = 0;
    sw_result r = path_text(path, file, &text, &len, status);
    if (r == SW_OK)
        r = sw__write_file(file, text, len, flags, status);
    free(text);
    if (r == SW_OK)
        sw__status_ok(status);
    return r;
}

void sw_rt_path_free(sw_rt_camera_path *path)
{
    if (!path)
        return;
    sw__free(path->keys);
    memset(path, 0, sizeof *path);
}

/* ---- evaluation ------------------------------------------------------------------------------ */
double sw_rt_path_t0(const sw_rt_camera_path *path)
{
    return path->keys[0].t;
}

double sw_rt_path_t1(const sw_rt_camera_path *path)
{
    return path->keys[path->n_keys - 1].t;
}

double sw_rt_path_frame_time(const sw_rt_camera_path *path, uint32_t i, uint32_t n)
{
    assert(i < n);
    const double t0 = sw_rt_path_t0(path), span = sw_rt_path_t1(path) - t0;
    if (path->closed)
        return t0 + span * i / n;
    return n > 1 ? t0 + span * i / (n - 1) : t0;
}

/* Catmull-Rom tangent of the eye (which = 0) or the target (which = 1) at key i, per second. */
static void tangent(const sw_rt_camera_path *p, uint32_t i, int which, double m[3])
{
    const uint32_t n = p->n_keys;
    uint32_t a = i > 0 ? i - 1 : 0, b = i + 1 < n ? i + 1 : n - 1;
    double dt = p->keys[b].t - p->keys[a].t;
    if (p->closed && (i == 0 || i == n - 1)) {
        a = n - 2; /* the neighbours across the seam; key n-1 repeats key 0 */
        b = 1;
        dt = (p->keys[1].t - p->keys[0].t) + (p->keys[n - 1].t - p->keys[n - 2].t);
    }
    const double *pa = which ? p->keys[a].camera.target : p->keys[a].camera.eye;
    const double *pb = which ? p->keys[b].camera.target : p->keys[b].camera.eye;
    for (int k = 0; k < 3; k++)
        m[k] = dt > 0.0 ? (pb[k] - pa[k]) / dt : 0.0;
}

/* Cubic Hermite between keys i and i+1 at s in [0, 1]. */
static void hermite(const sw_rt_camera_path *p, uint32_t i, double s, int which, double out[3])
{
    const double h = p->keys[i + 1].t - p->keys[i].t;
    double m0[3], m1[3];
    tangent(p, i, which, m0);
    tangent(p, i + 1, which, m1);
    const double *p0 = which ? p->keys[i].camera.target : p->keys[i].camera.eye;
    const double *p1 = which ? p->keys[i + 1].camera.target : p->keys[i + 1].camera.eye;
    const double s2 = s * s, s3 = s2 * s;
    const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2,
                 h11 = s3 - s2;
    for (int k = 0; k < 3; k++)
        out[k] = h00 * p0[k] + h10 * h * m0[k] + h01 * p1[k] + h11 * h * m1[k];
}

void sw_rt_path_eval(const sw_rt_camera_path *path, double t, sw_camera *out)
{
    assert(path->n_keys > 0);
    const sw_rt_path_key *k = path->keys;
    const uint32_t n = path->n_keys;
    if (n == 1 || !(t > k[0].t)) {
        *out = k[0].camera;
        return;
    }
    if (t >= k[n - 1].t) {
        *out = k[n - 1].camera;
        return;
    }
    uint32_t lo = 0, hi = n - 1; /* k[lo].t <= t < k[hi].t */
    while (hi - lo > 1) {
        const uint32_t mid = lo + (hi - lo) / 2;
        if (k[mid].t <= t)
            lo = mid;
        else
            hi = mid;
    }
    const double s = (t - k[lo].t) / (k[lo + 1].t - k[lo].t);
    hermite(path, lo, s, 0, out->eye);
    hermite(path, lo, s, 1, out->target);
    const double *u0 = k[lo].camera.up, *u1 = k[lo + 1].camera.up;
    const double n0 = norm3(u0), n1 = norm3(u1);
    double u[3];
    for (int c = 0; c < 3; c++)
        u[c] = (1.0 - s) * u0[c] / n0 + s * u1[c] / n1;
    const double un = norm3(u); /* > 0.1: validation keeps neighbouring ups within 172° */
    for (int c = 0; c < 3; c++)
        out->up[c] = u[c] / un;
    out->fovy_deg = (1.0 - s) * k[lo].camera.fovy_deg + s * k[lo + 1].camera.fovy_deg;
}

/* ---- stock paths ----------------------------------------------------------------------------- */
static sw_result alloc_keys(sw_rt_camera_path *out, uint32_t n, sw_status *status)
{
    memset(out, 0, sizeof *out);
    out->keys = sw__calloc(n, sizeof *out->keys);
    if (!out->keys)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "camera path: out of memory");
    out->n_keys = n;
    return SW_OK;
}

sw_result sw_rt_path_orbit(const double bbox[6], double seconds, uint32_t frames,
                           sw_rt_camera_path *out, sw_status *status)
{
    enum { N = 16 };
    assert(seconds > 0.0);
    sw_result r = alloc_keys(out, N + 1, status);
    if (r != SW_OK)
        return r;
    sw_camera fit; /* the iso preset's distance and centre, so the orbit frames the whole box */
    sw_rt_camera_fit_box(bbox, SW_VIEW_ISO, &fit);
    double d[3];
    for (int k = 0; k < 3; k++)
        d[k] = fit.eye[k] - fit.target[k];
    const double dist = norm3(d), elev = 25.0 * M_PI / 180.0;
    const double az0 = atan2(d[1], d[0]); /* start where the iso view looks from */
    for (uint32_t i = 0; i < N; i++) {
        sw_rt_path_key *k = &out->keys[i];
        const double az = az0 + 2.0 * M_PI * i / N;
        k->t = seconds * i / N;
        for (int c = 0; c < 3; c++)
            k->camera.target[c] = fit.target[c];
        k->camera.eye[0] = fit.target[0] + dist * cos(elev) * cos(az);
        k->camera.eye[1] = fit.target[1] + dist * cos(elev) * sin(az);
        k->camera.eye[2] = fit.target[2] + dist * sin(elev);
        k->camera.up[2] = 1.0;
        k->camera.fovy_deg = fit.fovy_deg;
    }
    out->keys[N] = out->keys[0];
    out->keys[N].t = seconds;
    out->closed = 1;
    out->frames = frames;
    return SW_OK;
}

/* A straight pass through the box along its longer horizontal side, weaving sideways and looking
 * a quarter of the run ahead, the eye at height z above the box's bottom (fly and walk). */
static sw_result straight_pass(const double bbox[6], double z, double seconds, uint32_t frames,
                               sw_rt_camera_path *out, sw_status *status)
{
    enum { N = 9 };
    assert(seconds > 0.0);
    sw_result r = alloc_keys(out, N, status);
    if (r != SW_OK)
        return r;
    double e[3], c[3];
    for (int k = 0; k < 3; k++) {
        e[k] = bbox[3 + k] - bbox[k];
        c[k] = 0.5 * (bbox[k] + bbox[3 + k]);
    }
    double diag = norm3(e);
    if (!(diag > 0.0))
        diag = 1.0; /* a point-sized scene still gets a usable path */
    /* flat or thin boxes get a floor so the eye moves */
    const int a = e[0] >= e[1] ? 0 : 1, b = 1 - a;
    const double len = fmax(e[a], 0.1 * diag), wide = fmax(e[b], 0.1 * diag);
    const double start = c[a] - 0.45 * len, run = 0.9 * len, ahead = 0.25;
    for (uint32_t i = 0; i < N; i++) {
        sw_rt_path_key *k = &out->keys[i];
        const double s = (double)i / (N - 1), s2 = s + ahead;
        k->t = seconds * s;
        k->camera.eye[a] = start + run * s;
        k->camera.eye[b] = c[b] + 0.15 * wide * sin(2.0 * M_PI * s);
        k->camera.eye[2] = bbox[2] + z;
        k->camera.target[a] = start + run * s2; /* where the eye will be a quarter run later */
        k->camera.target[b] = c[b] + 0.15 * wide * sin(2.0 * M_PI * s2);
        k->camera.target[2] = k->camera.eye[2];
        k->camera.up[2] = 1.0;
        k->camera.fovy_deg = 60.0;
    }
    out->frames = frames;
    return SW_OK;
}

sw_result sw_rt_path_fly(const double bbox[6], double seconds, uint32_t frames,
                         sw_rt_camera_path *out, sw_status *status)
{
    double e[3];
    for (int k = 0; k < 3; k++)
        e[k] = bbox[3 + k] - bbox[k];
    double diag = norm3(e);
    if (!(diag > 0.0))
        diag = 1.0;
    /* thin boxes: the eye above the geometry's plane rather than in it */
    return straight_pass(bbox, 0.3 * fmax(e[2], 0.1 * diag), seconds, frames, out, status);
}

sw_result sw_rt_path_walk(const double bbox[6], double eye_height, double seconds, uint32_t frames,
                          sw_rt_camera_path *out, sw_status *status)
{
    return straight_pass(bbox, eye_height, seconds, frames, out, status);
}
