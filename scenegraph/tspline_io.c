/* SPDX-License-Identifier: MIT */
/* The .tsm text format for T-meshes (docs/tspline-format.md): parsing, then validation, as two
 * separate steps (CONVENTIONS.md, Errors: files are hostile).
 *
 * A T-mesh is given in index space (Sederberg et al. 2003 §2-§3): global knot values per index
 * column (sknots) and row (tknots), the mesh's edges as index segments, and control points
 * anchored at mesh vertices. Each anchored point's local knot vectors are inferred by casting
 * rays from its anchor in +-s and +-t and taking the knots of the first two perpendicular edges
 * met (Sederberg 2003 §3, Figure 3); points may also carry explicit local knot vectors
 * (a point-based spline, §2). Every message names the file and line and what was expected.
 */
#include "sw_decimal.h"
#include "sw_sg_tspline.h"
#include "sw_hooks.h"
#include "sw_safe_read.h"
#include "sw_status_util.h"

#include <assert.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum {
    MAX_KNOTS = 65536,  /* index columns or rows */
    MAX_GRID = 1 << 24, /* columns * rows */
    MAX_EDGES = 1 << 22,
    MAX_TOKEN = 64,
    MAX_NAME = 256,
};
#define MAX_FILE_BYTES ((size_t)1 << 30)

typedef struct tsm_edge {
    uint32_t line;
    int vertical; /* 0: h J I0 I1, 1: v I J0 J1 */
    uint32_t at, from, to;
} tsm_edge;

typedef struct tsm_point {
    uint32_t line;
    uint32_t i, j;       /* anchor (anchored points only) */
    double p[4];         /* x y z w */
    double ku[5], kv[5]; /* explicit points only */
} tsm_point;

struct sw_sg_tsm_doc {
    char name[MAX_NAME];
    double *sk, *tk;
    uint32_t n_sk, n_tk, sk_line, tk_line;
    int has_domain;
    double domain[4];
    uint32_t domain_line, end_line;
    tsm_edge *edges;
    uint32_t n_edges;
    tsm_point *anchored, *explicit_pts;
    uint32_t n_anchored, n_explicit;
};

/* ---- lines and tokens ------------------------------------------------------------------------ */

typedef struct lexer {
    const char *p, *end; /* rest of the text */
    const char *lp, *le; /* current line, comment stripped */
    uint32_t line;
    int unterminated; /* the current line is the text's last and has no newline: cut short */
    const char *name;
    sw_status *status;
} lexer;

/* Advances to the next line holding a token; 0 at the end of the text. */
static int next_line(lexer *lx)
{
    while (lx->p < lx->end) {
        const char *s = lx->p;
        const char *e = memchr(s, '\n', (size_t)(lx->end - s));
        if (!e)
            e = lx->end;
        lx->p = e < lx->end ? e + 1 : e;
        lx->unterminated = e == lx->end;
        lx->line++;
        const char *hash = memchr(s, '#', (size_t)(e - s));
        lx->lp = s;
        lx->le = hash ? hash : e;
        while (lx->lp < lx->le && (*lx->lp == ' ' || *lx->lp == '\t' || *lx->lp == '\r'))
            lx->lp++;
        if (lx->lp < lx->le)
            return 1;
    }
    return 0;
}

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r';
}

/* Next token of the current line into tok (NUL-terminated, at most MAX_TOKEN - 1 characters, a
 * longer one is cut and flagged by *len >= MAX_TOKEN); 0 when the line has no more tokens. */
static int next_token(lexer *lx, char tok[MAX_TOKEN], size_t *len)
{
    while (lx->lp < lx->le && is_space(*lx->lp))
        lx->lp++;
    if (lx->lp >= lx->le)
        return 0;
    const char *s = lx->lp;
    while (lx->lp < lx->le && !is_space(*lx->lp))
        lx->lp++;
    *len = (size_t)(lx->lp - s);
    const size_t n = *len < MAX_TOKEN - 1 ? *len : MAX_TOKEN - 1;
    memcpy(tok, s, n);
    tok[n] = '\0';
    for (size_t k = 0; k < n; k++)
        if ((unsigned char)tok[k] < 32 || (unsigned char)tok[k] > 126)
            tok[k] = '?'; /* keep messages printable */
    return 1;
}

/* A field missing at the end of a line: the text was cut there if that line is unterminated. */
static sw_result fail_at(lexer *lx, sw_result r, const char *expected, const char *found)
{
    if (lx->unterminated && !strcmp(found, "the end of the line"))
        return sw__fail(lx->status, SW_ERR_TRUNCATED, "%s:%u: the file ends; expected %s", lx->name,
                        lx->line, expected);
    return sw__fail(lx->status, r, "%s:%u: expected %s, found %s", lx->name, lx->line, expected,
                    found);
}

static sw_result read_double(lexer *lx, const char *what, double *out)
{
    char tok[MAX_TOKEN];
    size_t len;
    if (!next_token(lx, tok, &len))
        return fail_at(lx, SW_ERR_FORMAT, what, "the end of the line");
    const char *end = tok;
    double x = 0.0;
    const int got = len < MAX_TOKEN ? sw__parse_decimal(tok, &end, &x) : SW_DECIMAL_NOT_A_NUMBER;
    if (got == SW_DECIMAL_NOT_A_NUMBER || *end != '\0')
        return sw__fail(lx->status, SW_ERR_FORMAT,
                        "%s:%u: expected %s (a decimal number), found '%s'", lx->name, lx->line,
                        what, tok);
    if (got != SW_DECIMAL_OK)
        return sw__fail(lx->status, SW_ERR_FORMAT, "%s:%u: %s is '%s', beyond a double's range",
                        lx->name, lx->line, what, tok);
    *out = x;
    return SW_OK;
}

static sw_result read_uint(lexer *lx, const char *what, uint32_t max, uint32_t *out)
{
    char tok[MAX_TOKEN];
    size_t len;
    if (!next_token(lx, tok, &len))
        return fail_at(lx, SW_ERR_FORMAT, what, "the end of the line");
    uint64_t x = 0;
    int ok = len > 0 && len < 12;
    for (size_t k = 0; ok && k < len; k++) {
        ok = tok[k] >= '0' && tok[k] <= '9';
        x = x * 10 + (uint64_t)(tok[k] - '0');
    }
    if (!ok)
        return sw__fail(lx->status, SW_ERR_FORMAT,
                        "%s:%u: expected %s (a non-negative integer), found '%s'", lx->name,
                        lx->line, what, tok);
    if (x > max)
        return sw__fail(lx->status, SW_ERR_FORMAT, "%s:%u: %s is %llu, more than the limit %u",
                        lx->name, lx->line, what, (unsigned long long)x, max);
    *out = (uint32_t)x;
    return SW_OK;
}

static sw_result expect_line_end(lexer *lx, const char *record)
{
    char tok[MAX_TOKEN];
    size_t len;
    if (next_token(lx, tok, &len))
        return sw__fail(lx->status, SW_ERR_FORMAT,
                        "%s:%u: expected the end of the %s record, found extra field '%s'",
                        lx->name, lx->line, record, tok);
    return SW_OK;
}

static sw_result read_doubles(lexer *lx, const char *what, double *out, uint32_t n)
{
    for (uint32_t k = 0; k < n; k++) {
        sw_result r = read_double(lx, what, &out[k]);
        if (r != SW_OK)
            return r;
    }
    return SW_OK;
}

/* ---- records --------------------------------------------------------------------------------- */

static sw_result parse_knots(lexer *lx, sw_sg_tsm_doc *d, int is_t)
{
    double **k = is_t ? &d->tk : &d->sk;
    uint32_t *n = is_t ? &d->n_tk : &d->n_sk;
    const char *kw = is_t ? "tknots" : "sknots";
    if (*k)
        return sw__fail(lx->status, SW_ERR_FORMAT, "%s:%u: a second '%s' record", lx->name,
                        lx->line, kw);
    sw_result r = read_uint(lx, "the knot count", MAX_KNOTS, n);
    if (r != SW_OK)
        return r;
    if (*n < 2)
        return sw__fail(lx->status, SW_ERR_FORMAT, "%s:%u: '%s' needs at least 2 knots", lx->name,
                        lx->line, kw);
    if (d->n_sk && d->n_tk && (uint64_t)d->n_sk * d->n_tk > MAX_GRID)
        return sw__fail(lx->status, SW_ERR_FORMAT,
                        "%s:%u: index grid of %u x %u is larger than the limit %u", lx->name,
                        lx->line, d->n_sk, d->n_tk, MAX_GRID);
    *k = sw__malloc(sizeof(double) * *n);
    if (!*k)
        return sw__fail(lx->status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", lx->name);
    *(is_t ? &d->tk_line : &d->sk_line) = lx->line;
    r = read_doubles(lx, "a knot value", *k, *n);
    return r != SW_OK ? r : expect_line_end(lx, kw);
}

static sw_result parse_domain(lexer *lx, sw_sg_tsm_doc *d)
{
    if (d->has_domain)
        return sw__fail(lx->status, SW_ERR_FORMAT, "%s:%u: a second 'domain' record", lx->name,
                        lx->line);
    d->has_domain = 1;
    d->domain_line = lx->line;
    sw_result r = read_doubles(lx, "a domain bound (u0 u1 v0 v1)", d->domain, 4);
    return r != SW_OK ? r : expect_line_end(lx, "domain");
}

static sw_result parse_edge(lexer *lx, tsm_edge *e)
{
    char tok[MAX_TOKEN];
    size_t len = 0;
    if (!next_token(lx, tok, &len) || (strcmp(tok, "h") && strcmp(tok, "v")))
        return sw__fail(lx->status, SW_ERR_FORMAT,
                        "%s:%u: expected an edge record 'h J I0 I1' or 'v I J0 J1', found '%s'",
                        lx->name, lx->line, tok);
    e->line = lx->line;
    e->vertical = tok[0] == 'v';
    sw_result r = read_uint(lx, "the edge's row or column", MAX_KNOTS, &e->at);
    if (r == SW_OK)
        r = read_uint(lx, "the edge's first index", MAX_KNOTS, &e->from);
    if (r == SW_OK)
        r = read_uint(lx, "the edge's last index", MAX_KNOTS, &e->to);
    return r != SW_OK ? r : expect_line_end(lx, "edge");
}

static sw_result parse_point(lexer *lx, tsm_point *p, int is_explicit)
{
    p->line = lx->line;
    sw_result r = SW_OK;
    if (!is_explicit) {
        r = read_uint(lx, "the anchor column I", MAX_KNOTS, &p->i);
        if (r == SW_OK)
            r = read_uint(lx, "the anchor row J", MAX_KNOTS, &p->j);
    }
    if (r == SW_OK)
        r = read_doubles(lx, "a coordinate (x y z w)", p->p, 4);
    if (r == SW_OK && is_explicit)
        r = read_doubles(lx, "a local knot in u (s0..s4)", p->ku, 5);
    if (r == SW_OK && is_explicit)
        r = read_doubles(lx, "a local knot in v (t0..t4)", p->kv, 5);
    return r != SW_OK ? r : expect_line_end(lx, is_explicit ? "knotpoints" : "points");
}

static sw_result truncated(lexer *lx, const char *expected)
{
    return sw__fail(lx->status, SW_ERR_TRUNCATED, "%s:%u: the file ends; expected %s", lx->name,
                    lx->line, expected);
}

/* A block: `keyword COUNT` then COUNT lines of records of `size` bytes. */
static sw_result parse_block(lexer *lx, const char *kw, uint32_t max, void **arr, uint32_t *count,
                             size_t size, int kind)
{
    if (*arr)
        return sw__fail(lx->status, SW_ERR_FORMAT, "%s:%u: a second '%s' block", lx->name, lx->line,
                        kw);
    uint32_t n;
    sw_result r = read_uint(lx, "the record count", max, &n);
    if (r == SW_OK)
        r = expect_line_end(lx, kw);
    if (r != SW_OK)
        return r;
    uint32_t cap = n < 64 ? n : 64;
    *arr = sw__calloc(cap ? cap : 1, size);
    if (!*arr)
        return sw__fail(lx->status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", lx->name);
    for (uint32_t k = 0; k < n; k++) {
        if (!next_line(lx))
            return sw__fail(lx->status, SW_ERR_TRUNCATED,
                            "%s:%u: the file ends after %u of the %u '%s' records", lx->name,
                            lx->line, k, n, kw);
        if (k == cap) {
            cap = cap > n / 2 ? n : cap * 2; /* grows with what is really there */
            void *g = sw__realloc(*arr, size * cap);
            if (!g)
                return sw__fail(lx->status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", lx->name);
            *arr = g;
        }
        char *rec = (char *)*arr + size * k;
        memset(rec, 0, size);
        r = kind == 0 ? parse_edge(lx, (tsm_edge *)rec)
                      : parse_point(lx, (tsm_point *)rec, kind == 2);
        if (r != SW_OK)
            return r;
        *count = k + 1;
    }
    return SW_OK;
}

static sw_result parse_header(lexer *lx)
{
    char tok[MAX_TOKEN];
    size_t len;
    if (!next_line(lx))
        return truncated(lx, "the header 'tsm 1'");
    if (!next_token(lx, tok, &len) || strcmp(tok, "tsm"))
        return sw__fail(lx->status, SW_ERR_FORMAT, "%s:%u: expected the header 'tsm 1', found '%s'",
                        lx->name, lx->line, tok);
    uint32_t version;
    sw_result r = read_uint(lx, "the format version", 1000, &version);
    if (r != SW_OK)
        return r;
    if (version != 1)
        return sw__fail(lx->status, SW_ERR_VERSION, "%s:%u: format version %u (this reader: 1)",
                        lx->name, lx->line, version);
    return expect_line_end(lx, "header");
}

/* Structural rules checked once `end` is seen. */
static sw_result check_sections(lexer *lx, const sw_sg_tsm_doc *d)
{
    if ((d->n_edges || d->n_anchored) && (!d->sk || !d->tk))
        return sw__fail(lx->status, SW_ERR_FORMAT,
                        "%s:%u: 'edges' and 'points' need 'sknots' and 'tknots' records", lx->name,
                        lx->line);
    if (d->n_anchored && !d->n_edges)
        return sw__fail(lx->status, SW_ERR_FORMAT, "%s:%u: 'points' need an 'edges' block",
                        lx->name, lx->line);
    if (!d->sk && !d->has_domain)
        return sw__fail(lx->status, SW_ERR_FORMAT,
                        "%s:%u: without 'sknots'/'tknots' a 'domain' record is required", lx->name,
                        lx->line);
    if (d->n_anchored + d->n_explicit == 0)
        return sw__fail(lx->status, SW_ERR_FORMAT,
                        "%s:%u: no control points ('points' or "
                        "'knotpoints' with a count > 0)",
                        lx->name, lx->line);
    if ((uint64_t)d->n_anchored + d->n_explicit > SW_SG_TSPLINE_MAX_POINTS)
        return sw__fail(lx->status, SW_ERR_FORMAT, "%s:%u: more than %u control points", lx->name,
                        lx->line, SW_SG_TSPLINE_MAX_POINTS);
    return SW_OK;
}

static sw_result parse_record(lexer *lx, sw_sg_tsm_doc *d, const char *kw, int *done)
{
    if (!strcmp(kw, "sknots") || !strcmp(kw, "tknots"))
        return parse_knots(lx, d, kw[0] == 't');
    if (!strcmp(kw, "domain"))
        return parse_domain(lx, d);
    if (!strcmp(kw, "edges"))
        return parse_block(lx, kw, MAX_EDGES, (void **)&d->edges, &d->n_edges, sizeof(tsm_edge), 0);
    if (!strcmp(kw, "points"))
        return parse_block(lx, kw, SW_SG_TSPLINE_MAX_POINTS, (void **)&d->anchored, &d->n_anchored,
                           sizeof(tsm_point), 1);
    if (!strcmp(kw, "knotpoints"))
        return parse_block(lx, kw, SW_SG_TSPLINE_MAX_POINTS, (void **)&d->explicit_pts,
                           &d->n_explicit, sizeof(tsm_point), 2);
    if (!strcmp(kw, "end")) {
        *done = 1;
        d->end_line = lx->line;
        sw_result r = expect_line_end(lx, "end");
        return r != SW_OK ? r : check_sections(lx, d);
    }
    return sw__fail(lx->status, SW_ERR_FORMAT,
                    "%s:%u: expected a record (sknots, tknots, domain, edges, points, knotpoints, "
                    "end), found '%s'",
                    lx->name, lx->line, kw);
}

sw_result sw_sg_tsm_parse(const char *text, size_t len, const char *name, sw_sg_tsm_doc **out,
                          sw_status *status)
{
    assert(out && (text || !len));
    *out = NULL;
    sw_sg_tsm_doc *d = sw__calloc(1, sizeof *d);
    if (!d)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "out of memory");
    snprintf(d->name, sizeof d->name, "%s", name ? name : "<memory>");
    lexer lx = {text, text + len, NULL, NULL, 0, 0, d->name, status};
    sw_result r = parse_header(&lx);
    int done = 0;
    while (r == SW_OK && !done) {
        char kw[MAX_TOKEN];
        size_t kl;
        if (!next_line(&lx)) {
            r = truncated(&lx, "a record or 'end'");
            break;
        }
        next_token(&lx, kw, &kl);
        r = parse_record(&lx, d, kl < MAX_TOKEN ? kw : "(a long token)", &done);
    }
    if (r == SW_OK && next_line(&lx))
        r = sw__fail(status, SW_ERR_FORMAT, "%s:%u: expected nothing after 'end'", d->name,
                     lx.line);
    if (r != SW_OK) {
        sw_sg_tsm_doc_free(d);
        return r;
    }
    *out = d;
    sw__status_ok(status);
    return SW_OK;
}

void sw_sg_tsm_doc_free(sw_sg_tsm_doc *doc)
{
    if (!doc)
        return;
    sw__free(doc->sk);
    sw__free(doc->tk);
    sw__free(doc->edges);
    sw__free(doc->anchored);
    sw__free(doc->explicit_pts);
    sw__free(doc);
}

/* ---- validation: the T-mesh and ray casting ----------------------------------------------------
 */

typedef struct tmesh {
    uint32_t m, n;        /* columns, rows */
    unsigned char *h, *v; /* unit segments: h[J*(m-1)+I] (I,J)-(I+1,J); v[I*(n-1)+J] */
} tmesh;

/* Whether a vertical edge passes through or ends at (i, j). */
static int on_vertical(const tmesh *t, uint32_t i, uint32_t j)
{
    const unsigned char *col = t->v + (size_t)i * (t->n - 1);
    return (j > 0 && col[j - 1]) || (j + 1 < t->n && col[j]);
}

static int on_horizontal(const tmesh *t, uint32_t i, uint32_t j)
{
    const unsigned char *row = t->h + (size_t)j * (t->m - 1);
    return (i > 0 && row[i - 1]) || (i + 1 < t->m && row[i]);
}

static sw_result check_knots(const sw_sg_tsm_doc *d, sw_status *status)
{
    for (int is_t = 0; is_t < 2 && d->sk; is_t++) {
        const double *k = is_t ? d->tk : d->sk;
        const uint32_t n = is_t ? d->n_tk : d->n_sk;
        for (uint32_t j = 1; j < n; j++)
            if (k[j] < k[j - 1])
                return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                                "%s:%u: %s[%u] = %g is less than %s[%u] = %g: knots must not "
                                "decrease",
                                d->name, is_t ? d->tk_line : d->sk_line, is_t ? "tknots" : "sknots",
                                j, k[j], is_t ? "tknots" : "sknots", j - 1, k[j - 1]);
    }
    return SW_OK;
}

static sw_result rasterize_edges(const sw_sg_tsm_doc *d, tmesh *t, sw_status *status)
{
    t->m = d->n_sk, t->n = d->n_tk;
    t->h = sw__calloc((size_t)(t->m - 1) * t->n, 1);
    t->v = sw__calloc((size_t)t->m * (t->n - 1), 1);
    if (!t->h || !t->v)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", d->name);
    for (uint32_t k = 0; k < d->n_edges; k++) {
        const tsm_edge *e = &d->edges[k];
        const uint32_t at_max = e->vertical ? t->m : t->n, along = e->vertical ? t->n : t->m;
        if (e->at >= at_max || e->from >= e->to || e->to >= along)
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                            "%s:%u: edge %c %u %u %u: expected %s < %u and first < last < %u",
                            d->name, e->line, e->vertical ? 'v' : 'h', e->at, e->from, e->to,
                            e->vertical ? "column" : "row", at_max, along);
        for (uint32_t s = e->from; s < e->to; s++) {
            if (e->vertical)
                t->v[(size_t)e->at * (t->n - 1) + s] = 1;
            else
                t->h[(size_t)e->at * (t->m - 1) + s] = 1;
        }
    }
    return SW_OK;
}

/* Knots of the first two perpendicular edges met by the ray from the anchor in direction `dir`
 * (+1 / -1) along s (along_s) or t; 0 if the mesh ends first. */
static int cast_ray(const tmesh *t, const double *knots, uint32_t i, uint32_t j, int along_s,
                    int dir, double hit[2])
{
    int found = 0;
    int64_t c = along_s ? (int64_t)i : (int64_t)j;
    const int64_t lim = along_s ? t->m : t->n;
    for (c += dir; c >= 0 && c < lim && found < 2; c += dir) {
        const int crosses =
            along_s ? on_vertical(t, (uint32_t)c, j) : on_horizontal(t, i, (uint32_t)c);
        if (crosses)
            hit[found++] = knots[c];
    }
    return found == 2;
}

static sw_result infer_knots(const sw_sg_tsm_doc *d, const tmesh *t, const tsm_point *p,
                             double ku[5], double kv[5], sw_status *status)
{
    static const char *const dirs[4] = {"-s", "+s", "-t", "+t"};
    double hit[4][2];
    for (int r = 0; r < 4; r++)
        if (!cast_ray(t, r < 2 ? d->sk : d->tk, p->i, p->j, r < 2, r % 2 ? 1 : -1, hit[r]))
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                            "%s:%u: the ray in %s from anchor (%u, %u) meets fewer than 2 edges; "
                            "the T-mesh needs two more knot lines on that side",
                            d->name, p->line, dirs[r], p->i, p->j);
    const double k5[2][5] = {{hit[0][1], hit[0][0], d->sk[p->i], hit[1][0], hit[1][1]},
                             {hit[2][1], hit[2][0], d->tk[p->j], hit[3][0], hit[3][1]}};
    memcpy(ku, k5[0], sizeof k5[0]);
    memcpy(kv, k5[1], sizeof k5[1]);
    return SW_OK;
}

static sw_result check_anchor(const sw_sg_tsm_doc *d, const tmesh *t, unsigned char *used,
                              const tsm_point *p, sw_status *status)
{
    if (p->i >= t->m || p->j >= t->n)
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                        "%s:%u: anchor (%u, %u) outside the index grid %u x %u", d->name, p->line,
                        p->i, p->j, t->m, t->n);
    if (!on_vertical(t, p->i, p->j) || !on_horizontal(t, p->i, p->j))
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                        "%s:%u: anchor (%u, %u) is not a vertex of the T-mesh (expected edges "
                        "along both s and t through it)",
                        d->name, p->line, p->i, p->j);
    unsigned char *u = used + (size_t)p->j * t->m + p->i;
    if (*u)
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                        "%s:%u: a second control point at anchor (%u, %u)", d->name, p->line, p->i,
                        p->j);
    *u = 1;
    return SW_OK;
}

static sw_result check_point_values(const sw_sg_tsm_doc *d, const tsm_point *p, const double ku[5],
                                    const double kv[5], sw_status *status)
{
    if (!(p->p[3] > 0.0))
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                        "%s:%u: weight %g: expected a positive weight", d->name, p->line, p->p[3]);
    for (int k = 1; k < 5; k++)
        if (ku[k] < ku[k - 1] || kv[k] < kv[k - 1])
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                            "%s:%u: local knot vector decreases at knot %d", d->name, p->line, k);
    if (!(ku[0] < ku[4]) || !(kv[0] < kv[4]))
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                        "%s:%u: local knot vector with five equal knots (empty support)", d->name,
                        p->line);
    return SW_OK;
}

/* Fills one desc entry: homogeneous point and local knots. */
static void put_point(const tsm_point *p, const double ku[5], const double kv[5], double *cpw,
                      double *dku, double *dkv)
{
    for (int c = 0; c < 3; c++)
        cpw[c] = p->p[c] * p->p[3];
    cpw[3] = p->p[3];
    memcpy(dku, ku, sizeof(double) * 5);
    memcpy(dkv, kv, sizeof(double) * 5);
}

static sw_result default_domain(const sw_sg_tsm_doc *d, double dm[4], sw_status *status)
{
    if (d->has_domain) {
        memcpy(dm, d->domain, sizeof d->domain);
        if (!(dm[0] < dm[1]) || !(dm[2] < dm[3]))
            return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                            "%s:%u: empty domain: expected u0 < u1 and v0 < v1", d->name,
                            d->domain_line);
        return SW_OK;
    }
    /* Index-space domain of a bicubic T-mesh with a two-line frame: knots [3, count - 4]. */
    if (d->n_sk < 8 || d->n_tk < 8)
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                        "%s:%u: without a 'domain' record, sknots and tknots need at least 8 knots",
                        d->name, d->end_line);
    dm[0] = d->sk[3], dm[1] = d->sk[d->n_sk - 4], dm[2] = d->tk[3], dm[3] = d->tk[d->n_tk - 4];
    if (!(dm[0] < dm[1]) || !(dm[2] < dm[3]))
        return sw__fail(status, SW_ERR_INVALID_GEOMETRY,
                        "%s:%u: the default domain [sknots[3], sknots[%u]] x [tknots[3], "
                        "tknots[%u]] is empty",
                        d->name, d->end_line, d->n_sk - 4, d->n_tk - 4);
    return SW_OK;
}

typedef struct desc_arrays {
    double *cpw, *ku, *kv;
    unsigned char *used;
    tmesh mesh;
} desc_arrays;

static void free_arrays(desc_arrays *a)
{
    sw__free(a->cpw);
    sw__free(a->ku);
    sw__free(a->kv);
    sw__free(a->used);
    sw__free(a->mesh.h);
    sw__free(a->mesh.v);
}

static sw_result fill_points(const sw_sg_tsm_doc *d, desc_arrays *a, sw_status *status)
{
    sw_result r = SW_OK;
    for (uint32_t k = 0; k < d->n_anchored && r == SW_OK; k++) {
        const tsm_point *p = &d->anchored[k];
        double ku[5], kv[5];
        r = check_anchor(d, &a->mesh, a->used, p, status);
        if (r == SW_OK)
            r = infer_knots(d, &a->mesh, p, ku, kv, status);
        if (r == SW_OK)
            r = check_point_values(d, p, ku, kv, status);
        if (r == SW_OK)
            put_point(p, ku, kv, a->cpw + (size_t)k * 4, a->ku + (size_t)k * 5,
                      a->kv + (size_t)k * 5);
    }
    for (uint32_t k = 0; k < d->n_explicit && r == SW_OK; k++) {
        const tsm_point *p = &d->explicit_pts[k];
        const size_t at = (size_t)d->n_anchored + k;
        r = check_point_values(d, p, p->ku, p->kv, status);
        if (r == SW_OK)
            put_point(p, p->ku, p->kv, a->cpw + at * 4, a->ku + at * 5, a->kv + at * 5);
    }
    return r;
}

sw_result sw_sg_tsm_validate(const sw_sg_tsm_doc *d, sw_sg_tspline **out, sw_status *status)
{
    assert(d && out);
    *out = NULL;
    sw_result r = check_knots(d, status);
    if (r != SW_OK)
        return r;
    desc_arrays a;
    memset(&a, 0, sizeof a);
    const size_t n = (size_t)d->n_anchored + d->n_explicit;
    a.cpw = sw__malloc(sizeof(double) * n * 4);
    a.ku = sw__malloc(sizeof(double) * n * 5);
    a.kv = sw__malloc(sizeof(double) * n * 5);
    if (d->sk)
        a.used = sw__calloc((size_t)d->n_sk * d->n_tk, 1);
    if (!a.cpw || !a.ku || !a.kv || (d->sk && !a.used))
        r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", d->name);
    if (r == SW_OK && d->sk)
        r = rasterize_edges(d, &a.mesh, status);
    if (r == SW_OK)
        r = fill_points(d, &a, status);
    sw_sg_tspline_desc desc = {(uint32_t)n, a.cpw, a.ku, a.kv, {0, 0, 0, 0}};
    if (r == SW_OK)
        r = default_domain(d, desc.domain, status);
    if (r == SW_OK)
        r = sw_sg_tspline_create(&desc, d->name, out, status);
    free_arrays(&a);
    return r;
}

/* ---- files and scenes -------------------------------------------------------------------------
 */

sw_result sw_sg_tspline_load_mem(const char *text, size_t len, const char *name,
                                 sw_sg_tspline **out, sw_status *status)
{
    sw_sg_tsm_doc *doc = NULL;
    sw_result r = sw_sg_tsm_parse(text, len, name, &doc, status);
    if (r == SW_OK)
        r = sw_sg_tsm_validate(doc, out, status);
    sw_sg_tsm_doc_free(doc);
    return r;
}

/* Reads a whole file; *text is NUL-terminated. Non-blocking open, regular files only, and the
 * size refused before a byte is read (a device or a sparse 2 GiB file is not read at all). */
static sw_result read_file(const char *path, char **text, size_t *len, sw_status *status)
{
    return sw__in_read_all(path, MAX_FILE_BYTES, ".tsm file", text, len, status);
}

sw_result sw_sg_tspline_load(const char *path, sw_sg_tspline **out, sw_status *status)
{
    assert(path && out);
    *out = NULL;
    char *text = NULL;
    size_t len = 0;
    sw_result r = read_file(path, &text, &len, status);
    if (r != SW_OK)
        return r;
    r = sw_sg_tspline_load_mem(text, len, path, out, status);
    sw__free(text);
    return r;
}

sw_result sw_sg_tspline_import_into(sw_sg_builder *b, uint32_t parent, const double xform[12],
                                    const char *path, sw_status *status)
{
    assert(b && path);
    sw_sg_tspline *ts;
    sw_result r = sw_sg_tspline_load(path, &ts, status);
    if (r != SW_OK)
        return r;
    const char *base = strrchr(path, '/');
    r = sw_sg_tspline_add_to_builder(b, ts, parent, xform, NULL, base ? base + 1 : path, NULL,
                                     status);
    sw_sg_tspline_free(ts);
    return r;
}

sw_result sw_sg_tspline_import_file(const char *path, sw_sg_scene **out, sw_status *status)
{
    assert(path && out);
    *out = NULL;
    sw_sg_builder *b = sw_sg_builder_create();
    if (!b)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    sw_result r = sw_sg_tspline_import_into(b, 0, NULL, path, status);
    if (r != SW_OK) {
        sw_sg_builder_free(b);
        return r;
    }
    return sw_sg_builder_finish(b, out, status);
}
