/* SPDX-License-Identifier: MIT */
/* Frame-time profiles: rows, summary statistics, and the CSV / JSON / SVG / HTML files of a
 * `splinewalk profile` run (docs/camera-path.md and the README describe what they hold). */
#include "sw_profile_report.h"
#include "sw_hooks.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct col_info {
    const char *name;
    sw_rt_prof_kind kind;
    const char *what;
} col_info;

static const col_info k_cols[SW_RT_COL_COUNT] = {
#define SW_RT__COL_INFO(id, name, kind, what) {name, SW_RT_KIND_##kind, what},
    SW_RT_PROFILE_COLUMNS(SW_RT__COL_INFO)
#undef SW_RT__COL_INFO
};

/* Stage colours, in stacking order (waiting for the visibility thread at the bottom, other on
 * top). */
static const char *const k_stage_colour[] = {"#8e6bbf", "#4c8bd6", "#edc948", "#76b7b2",
                                             "#59a14f", "#f28e2b", "#a0a0a0"};
#define FIRST_STAGE SW_RT_COL_WAIT_VISIBILITY_MS
#define N_STAGES (SW_RT_COL_OTHER_MS - FIRST_STAGE + 1)
/* The pool's columns come from one table of task kinds: one ms and one tasks column per kind, in
 * the kinds' order. */
#define SW_RT_COL_POOL_FIRST_MS SW_RT_COL_POOL_OTHER_MS
#define SW_RT_COL_POOL_FIRST_TASKS SW_RT_COL_POOL_OTHER_TASKS
_Static_assert(SW_RT_COL_POOL_FIRST_TASKS - SW_RT_COL_POOL_FIRST_MS == SW_RT_POOL_KIND_COUNT &&
                   SW_RT_COL_POOL_QUEUED - SW_RT_COL_POOL_FIRST_TASKS == SW_RT_POOL_KIND_COUNT,
               "one ms and one tasks column per pool task kind, in order");
/* Pool kinds' colours (same order as the kinds). */
static const char *const k_pool_colour[] = {"#a0a0a0", "#4c8bd6", "#9ecae9", "#8e6bbf", "#59a14f",
                                            "#edc948", "#f28e2b", "#ff9da7", "#e15759", "#76b7b2"};
_Static_assert(sizeof k_pool_colour / sizeof k_pool_colour[0] == SW_RT_POOL_KIND_COUNT,
               "one colour per pool task kind");

_Static_assert(sizeof k_stage_colour / sizeof k_stage_colour[0] == N_STAGES,
               "one colour per stage");

const char *sw_rt_prof_col_name(sw_rt_prof_col col)
{
    return k_cols[col].name;
}

const char *sw_rt_prof_col_what(sw_rt_prof_col col)
{
    return k_cols[col].what;
}

sw_rt_prof_kind sw_rt_prof_col_kind(sw_rt_prof_col col)
{
    return k_cols[col].kind;
}

/* ---- rows and statistics --------------------------------------------------------------------- */
void sw_rt_profile_row(const sw_frame_stats *st, uint32_t index, double t, double frame_ms,
                       double prepare_ms, double resident_bytes, int captured, sw_rt_prof_row *out)
{
    double *v = out->v;
    memset(out, 0, sizeof *out);
    v[SW_RT_COL_FRAME] = index;
    v[SW_RT_COL_T] = t;
    v[SW_RT_COL_FRAME_MS] = frame_ms;
    v[SW_RT_COL_VIS_HIERARCHY_MS] = st->ms_hierarchy;
    v[SW_RT_COL_VIS_TESSELLATE_MS] = st->ms_tessellate;
    v[SW_RT_COL_VIS_MS] = st->ms_visibility;
    v[SW_RT_COL_VIS_JOIN_MS] = st->ms_join;
    v[SW_RT_COL_WAIT_VISIBILITY_MS] = st->ms_wait_visibility;
    v[SW_RT_COL_PREPARE_MS] = prepare_ms;
    v[SW_RT_COL_TRIM_MS] = st->ms_trim;
    v[SW_RT_COL_DRAW_MS] = st->ms_draw;
    v[SW_RT_COL_READBACK_MS] = st->ms_readback;
    v[SW_RT_COL_WRITE_MS] = st->ms_write;
    double measured = 0.0;
    for (int s = FIRST_STAGE; s < SW_RT_COL_OTHER_MS; s++)
        measured += v[s];
    v[SW_RT_COL_OTHER_MS] = frame_ms - measured;
    v[SW_RT_COL_PATCHES] = (double)(st->patches_trimmed + st->patches_untrimmed);
    v[SW_RT_COL_PATCHES_TRIMMED] = (double)st->patches_trimmed;
    v[SW_RT_COL_PATCHES_CULLED] = (double)st->patches_culled;
    v[SW_RT_COL_FACES_DRAWN] = (double)st->faces_drawn;
    v[SW_RT_COL_FACES_CULLED] = (double)st->faces_culled;
    v[SW_RT_COL_HIERARCHY_NODES] = (double)st->hierarchy_nodes;
    v[SW_RT_COL_REFINE_ROUNDS] = (double)st->refine_rounds;
    v[SW_RT_COL_TRIANGLES] = (double)st->triangles;
    v[SW_RT_COL_BORDER_TRIANGLES] = (double)st->border_triangles;
    v[SW_RT_COL_BORDER_LOOPS_KEPT] = (double)st->border_loops_kept;
    v[SW_RT_COL_BORDER_LOOPS_MADE] = (double)st->border_loops_made;
    v[SW_RT_COL_BORDER_QUADS_AWAY] = (double)st->border_quads_away;
    v[SW_RT_COL_TRIM_TEXTURES] = (double)st->trim_textures;
    v[SW_RT_COL_TRIM_EXACT] = (double)st->trim_exact;
    v[SW_RT_COL_TRIM_TEXELS] = (double)st->trim_texels;
    v[SW_RT_COL_TRIM_REUSED] = (double)st->trim_reused;
    v[SW_RT_COL_ATLAS_PAGES] = (double)st->atlas_pages;
    v[SW_RT_COL_FALLBACK_DRAWS] = (double)st->fallback_draws;
    v[SW_RT_COL_POOL_WAITS] = (double)st->pool_waits;
    v[SW_RT_COL_GPU_MS] = st->ms_gpu;
    v[SW_RT_COL_STATIC_DRAWN] = (double)st->static_drawn;
    v[SW_RT_COL_STATIC_FACES] = (double)st->static_faces;
    v[SW_RT_COL_STATIC_TRIANGLES] = (double)st->static_triangles;
    v[SW_RT_COL_STATIC_REQUESTS] = (double)st->static_requests;
    v[SW_RT_COL_PROXIES_DRAWN] = (double)st->proxies_drawn;
    v[SW_RT_COL_PROXY_INSTANCES] = (double)st->proxy_instances;
    v[SW_RT_COL_PROXY_TRIANGLES] = (double)st->proxy_triangles;
    v[SW_RT_COL_BOUND_EXCEEDED] = (double)st->bound_exceeded;
    v[SW_RT_COL_BUDGET_COARSENED] = (double)st->budget_coarsened;
    v[SW_RT_COL_BOUND_EXCESS_PX] = st->bound_excess_px;
    v[SW_RT_COL_OCCLUSION_TESTS] = (double)st->occlusion_tests;
    v[SW_RT_COL_NODES_OCCLUDED] = (double)st->nodes_occluded;
    v[SW_RT_COL_FACES_OCCLUDED] = (double)st->faces_occluded;
    v[SW_RT_COL_RESIDENT_TRIANGLES] = (double)st->resident_triangles;
    v[SW_RT_COL_UPLOAD_BYTES] = (double)st->upload_bytes;
    v[SW_RT_COL_GRID_HITS] = (double)st->grid_hits;
    v[SW_RT_COL_GRID_MISSES] = (double)st->grid_misses;
    v[SW_RT_COL_RESIDENT_BYTES] = resident_bytes;
    v[SW_RT_COL_CAPTURED] = captured ? 1.0 : 0.0;
}

const char *sw_rt_pool_kind_name(int kind)
{
    static const char *const names[SW_RT_POOL_KIND_COUNT] = {
#define SW_RT__POOL_KIND_NAME(a, id, name, what) name,
        SW_RT_POOL_KINDS(SW_RT__POOL_KIND_NAME, ~)
#undef SW_RT__POOL_KIND_NAME
    };
    return kind >= 0 && kind < SW_RT_POOL_KIND_COUNT ? names[kind] : "?";
}

/* The profile column of a registered pool kind: the one of its name, else "other". */
static int pool_column(sw_th_task_kind kind)
{
    const char *name = sw_th_task_kind_name(kind);
    for (int c = 0; c < SW_RT_POOL_KIND_COUNT; c++)
        if (!strcmp(name, sw_rt_pool_kind_name(c)))
            return c;
    return SW_RT_POOL_KIND_OTHER;
}

void sw_rt_profile_row_pool(const sw_th_pool_stats *before, const sw_th_pool_stats *now,
                            int64_t queued, int64_t inject_peak, sw_rt_prof_row *row)
{
    for (int c = 0; c < SW_RT_POOL_KIND_COUNT; c++)
        row->v[SW_RT_COL_POOL_FIRST_MS + c] = row->v[SW_RT_COL_POOL_FIRST_TASKS + c] = 0.0;
    const uint32_t n = sw_th_task_kind_count();
    for (uint32_t k = 0; k < n && k < SW_TH_TASK_KIND_MAX; k++) {
        const int c = pool_column(k);
        row->v[SW_RT_COL_POOL_FIRST_MS + c] +=
            1e-6 * (double)(now->ns_by_kind[k] - before->ns_by_kind[k]);
        row->v[SW_RT_COL_POOL_FIRST_TASKS + c] +=
            (double)(now->executed_by_kind[k] - before->executed_by_kind[k]);
    }
    row->v[SW_RT_COL_POOL_QUEUED] = (double)queued;
    row->v[SW_RT_COL_POOL_INJECT_PEAK] = (double)inject_peak;
}

int sw_rt_profile_push(sw_rt_profile *p, const sw_rt_prof_row *row)
{
    if (p->n_rows == p->cap_rows) {
        const uint32_t cap = p->cap_rows ? p->cap_rows * 2 : 256;
        sw_rt_prof_row *g =
            cap > p->cap_rows ? sw__realloc(p->rows, (size_t)cap * sizeof *g) : NULL;
        if (!g)
            return -1;
        p->rows = g;
        p->cap_rows = cap;
    }
    p->rows[p->n_rows++] = *row;
    return 0;
}

void sw_rt_profile_free(sw_rt_profile *p)
{
    sw__free(p->rows);
    p->rows = NULL;
    p->n_rows = p->cap_rows = 0;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Percentile q in [0, 1] of sorted x[0..n-1], n >= 1. */
static double percentile(const double *x, uint32_t n, double q)
{
    const double pos = q * (n - 1);
    const uint32_t lo = (uint32_t)pos;
    if (lo + 1 >= n)
        return x[n - 1];
    return x[lo] + (pos - lo) * (x[lo + 1] - x[lo]);
}

int sw_rt_profile_summarize(sw_rt_profile *p)
{
    memset(p->summary, 0, sizeof p->summary);
    if (p->n_rows == 0)
        return 0;
    double *x = sw__malloc((size_t)p->n_rows * sizeof *x);
    if (!x)
        return -1;
    for (int c = 0; c < SW_RT_COL_COUNT; c++) {
        double sum = 0.0;
        for (uint32_t i = 0; i < p->n_rows; i++) {
            x[i] = p->rows[i].v[c];
            sum += x[i];
        }
        qsort(x, p->n_rows, sizeof *x, cmp_double);
        sw_rt_prof_stat *s = &p->summary[c];
        s->median = percentile(x, p->n_rows, 0.5);
        s->p90 = percentile(x, p->n_rows, 0.9);
        s->p99 = percentile(x, p->n_rows, 0.99);
        s->max = x[p->n_rows - 1];
        s->mean = sum / p->n_rows;
    }
    sw__free(x);
    return 0;
}

/* The frame whose frame_ms is the median (the lower middle for an even count). */
static uint32_t median_frame(const sw_rt_profile *p)
{
    uint32_t best = 0;
    double best_d = INFINITY;
    const double m = p->summary[SW_RT_COL_FRAME_MS].median;
    for (uint32_t i = 0; i < p->n_rows; i++) {
        const double d = fabs(p->rows[i].v[SW_RT_COL_FRAME_MS] - m);
        if (d < best_d) {
            best_d = d;
            best = i;
        }
    }
    return best;
}

static double share(const sw_rt_prof_row *r, sw_rt_prof_col c)
{
    const double f = r->v[SW_RT_COL_FRAME_MS];
    return f > 0.0 ? r->v[c] / f : 0.0;
}

void sw_rt_profile_capture_name(uint32_t frame, char *buf, size_t size)
{
    snprintf(buf, size, "frame-%04u.png", frame);
}

/* ---- CSV and JSON ---------------------------------------------------------------------------- */
static void put_number(FILE *f, sw_rt_prof_kind kind, double v)
{
    if (kind == SW_RT_KIND_INDEX || kind == SW_RT_KIND_COUNT)
        fprintf(f, "%.0f", v);
    else if (kind == SW_RT_KIND_SECONDS)
        fprintf(f, "%.6f", v);
    else
        fprintf(f, "%.4f", v);
}

int sw_rt_profile_write_csv(FILE *f, const sw_rt_profile *p)
{
    for (int c = 0; c < SW_RT_COL_COUNT; c++)
        fprintf(f, "%s%s", c ? "," : "", k_cols[c].name);
    fputc('\n', f);
    for (uint32_t i = 0; i < p->n_rows; i++) {
        for (int c = 0; c < SW_RT_COL_COUNT; c++) {
            if (c)
                fputc(',', f);
            put_number(f, k_cols[c].kind, p->rows[i].v[c]);
        }
        fputc('\n', f);
    }
    return ferror(f) ? -1 : 0;
}

static void json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; s && *s; s++) {
        const unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20)
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

static const char *kind_name(sw_rt_prof_kind k)
{
    static const char *const names[] = {"index", "seconds", "frame",  "stage", "visibility stage",
                                        "gpu",   "pool",    "pixels", "count"};
    _Static_assert(sizeof names / sizeof names[0] == SW_RT_KIND_COUNT + 1,
                   "a name per kind (SW_RT_KIND_COUNT, the count kind, is the last)");
    return names[k];
}

static int summarized(sw_rt_prof_col c)
{
    return c != SW_RT_COL_FRAME && c != SW_RT_COL_T && c != SW_RT_COL_CAPTURED;
}

static void json_meta(FILE *f, const sw_rt_profile *p)
{
    const sw_rt_prof_meta *m = &p->meta;
    fputs("{\n  \"format\": \"splinewalk-profile\",\n  \"version\": 1,\n  \"scene\": ", f);
    json_string(f, m->scene);
    fputs(",\n  \"path\": ", f);
    json_string(f, m->path);
    fputs(",\n  \"renderer\": ", f);
    json_string(f, m->renderer);
    fputs(",\n  \"mode\": ", f);
    json_string(f, m->mode);
    fputs(",\n  \"eval\": ", f);
    json_string(f, m->eval);
    fprintf(f,
            ",\n  \"width\": %d,\n  \"height\": %d,\n  \"error_px\": %.17g,\n"
            "  \"worker_threads\": %u,\n  \"sequential\": %s,\n  \"lp_num_threads\": ",
            m->width, m->height, m->error_px, m->worker_threads, m->sequential ? "true" : "false");
    if (m->lp_num_threads)
        json_string(f, m->lp_num_threads);
    else
        fputs("null", f);
    fprintf(f, ",\n  \"wall_s\": %.6f,\n  \"frame_count\": %u,\n", m->wall_s, p->n_rows);
}

static void json_columns(FILE *f)
{
    fputs("  \"columns\": [", f);
    for (int c = 0; c < SW_RT_COL_COUNT; c++) {
        fprintf(f, "%s\n    {\"name\": \"%s\", \"kind\": \"%s\", \"what\": ", c ? "," : "",
                k_cols[c].name, kind_name(k_cols[c].kind));
        json_string(f, k_cols[c].what);
        fputc('}', f);
    }
    fputs("\n  ],\n  \"captures\": [", f);
}

static void json_summary(FILE *f, const sw_rt_profile *p)
{
    fputs("  \"summary\": {", f);
    int first = 1;
    for (int c = 0; c < SW_RT_COL_COUNT; c++) {
        if (!summarized((sw_rt_prof_col)c))
            continue;
        const sw_rt_prof_stat *s = &p->summary[c];
        fprintf(f,
                "%s\n    \"%s\": {\"median\": %.9g, \"p90\": %.9g, \"p99\": %.9g, "
                "\"max\": %.9g, \"mean\": %.9g}",
                first ? "" : ",", k_cols[c].name, s->median, s->p90, s->p99, s->max, s->mean);
        first = 0;
    }
    const uint32_t mf = p->n_rows ? median_frame(p) : 0;
    const double other_median = p->n_rows ? share(&p->rows[mf], SW_RT_COL_OTHER_MS) : 0.0;
    fprintf(f, "\n  },\n  \"median_frame\": %u,\n  \"median_frame_other_share\": %.6f,\n", mf,
            other_median);
}

int sw_rt_profile_write_json(FILE *f, const sw_rt_profile *p)
{
    json_meta(f, p);
    json_columns(f);
    for (uint32_t i = 0; i < p->n_captures; i++) {
        char name[64];
        sw_rt_profile_capture_name(p->captures[i], name, sizeof name);
        fprintf(f, "%s{\"frame\": %u, \"file\": \"%s\"}", i ? ", " : "", p->captures[i], name);
    }
    fputs("],\n", f);
    json_summary(f, p);
    fputs("  \"frames\": [", f);
    for (uint32_t i = 0; i < p->n_rows; i++) {
        fputs(i ? ",\n    {" : "\n    {", f);
        for (int c = 0; c < SW_RT_COL_COUNT; c++) {
            fprintf(f, "%s\"%s\": ", c ? ", " : "", k_cols[c].name);
            put_number(f, k_cols[c].kind, p->rows[i].v[c]);
        }
        fputc('}', f);
    }
    fputs("\n  ]\n}\n", f);
    return ferror(f) ? -1 : 0;
}

/* ---- SVG ------------------------------------------------------------------------------------- */
static void xml_text(FILE *f, const char *s)
{
    for (; s && *s; s++) {
        switch (*s) {
        case '&':
            fputs("&amp;", f);
            break;
        case '<':
            fputs("&lt;", f);
            break;
        case '>':
            fputs("&gt;", f);
            break;
        case '"':
            fputs("&quot;", f);
            break;
        case '\'':
            fputs("&apos;", f);
            break;
        default:
            /* XML 1.0 forbids most control characters even escaped: show them as '?' */
            fputc((unsigned char)*s < 0x20 && *s != '\t' && *s != '\n' ? '?' : *s, f);
        }
    }
}

/* The smallest of 1, 2, 5 x 10^k at or above v (> 0). */
static double nice_step(double v)
{
    if (!(v > 0.0) || !isfinite(v))
        return 1.0;
    const double e = pow(10.0, floor(log10(v)));
    const double m = v / e;
    return (m <= 1.0 ? 1.0 : m <= 2.0 ? 2.0 : m <= 5.0 ? 5.0 : 10.0) * e;
}

typedef struct plot {
    double left, top, width, height; /* plot area in SVG units */
    double ymax;
    uint32_t n;
} plot;

static double px(const plot *pl, uint32_t i)
{
    return pl->left + (pl->n > 1 ? pl->width * i / (pl->n - 1) : 0.5 * pl->width);
}

static double py(const plot *pl, double ms)
{
    return pl->top + pl->height * (1.0 - fmin(fmax(ms, 0.0), pl->ymax) / pl->ymax);
}

/* A stack of areas: columns first .. first + n - 1 (stage or pool-kind times), a colour each. */
typedef struct stack {
    int first, n;
    const char *const *colour;
} stack;

static const stack k_stages = {FIRST_STAGE, N_STAGES, k_stage_colour};
static const stack k_pool = {SW_RT_COL_POOL_FIRST_MS, SW_RT_POOL_KIND_COUNT, k_pool_colour};

/* Cumulative top of a stack up to its layer s (inclusive) at frame i; negative values (a clock's
 * rounding in "other") count as 0. */
static double stack_top(const sw_rt_profile *p, uint32_t i, const stack *st, int s)
{
    double sum = 0.0;
    for (int k = 0; k <= s; k++)
        sum += fmax(0.0, p->rows[i].v[st->first + k]);
    return sum;
}

static double stack_max(const sw_rt_profile *p, const stack *st)
{
    double m = 0.0;
    for (uint32_t i = 0; i < p->n_rows; i++)
        m = fmax(m, stack_top(p, i, st, st->n - 1));
    return m;
}

static void svg_axes(FILE *f, const sw_rt_profile *p, const plot *pl, double ystep,
                     const char *ylabel)
{
    fprintf(f, "<g font-family=\"sans-serif\" font-size=\"11\" fill=\"#333\">\n");
    for (double y = 0.0; y <= pl->ymax + 1e-9 * pl->ymax; y += ystep) {
        const double yy = py(pl, y);
        fprintf(f,
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>"
                "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">%g</text>\n",
                pl->left, yy, pl->left + pl->width, yy, pl->left - 6, yy + 4, y);
    }
    const double xstep = fmax(1.0, nice_step(pl->n > 1 ? (pl->n - 1) / 8.0 : 1.0));
    for (double x = 0.0; x <= pl->n - 1 + 1e-9; x += xstep) {
        const uint32_t i = (uint32_t)x;
        const double xx = px(pl, i);
        fprintf(f,
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#999\"/>"
                "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%u</text>\n",
                xx, pl->top + pl->height, xx, pl->top + pl->height + 4, xx,
                pl->top + pl->height + 17, i);
        if (pl->n <= 1)
            break;
    }
    fprintf(f,
            "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">frame along the path "
            "(t = %.3g to %.3g s)</text>\n",
            pl->left + 0.5 * pl->width, pl->top + pl->height + 36, p->rows[0].v[SW_RT_COL_T],
            p->rows[p->n_rows - 1].v[SW_RT_COL_T]);
    fprintf(f,
            "<text x=\"14\" y=\"%.1f\" text-anchor=\"middle\" transform=\"rotate(-90 14 %.1f)\">"
            "%s</text>\n",
            pl->top + 0.5 * pl->height, pl->top + 0.5 * pl->height, ylabel);
    fprintf(f,
            "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" "
            "stroke=\"#666\"/>\n</g>\n",
            pl->left, pl->top, pl->width, pl->height);
}

static void svg_areas(FILE *f, const sw_rt_profile *p, const plot *pl, const stack *st)
{
    for (int s = 0; s < st->n; s++) {
        fprintf(f, "<polygon fill=\"%s\" fill-opacity=\"0.85\" stroke=\"none\" points=\"",
                st->colour[s]);
        for (uint32_t i = 0; i < p->n_rows; i++)
            fprintf(f, "%.2f,%.2f ", px(pl, i), py(pl, stack_top(p, i, st, s)));
        for (uint32_t i = p->n_rows; i-- > 0;)
            fprintf(f, "%.2f,%.2f ", px(pl, i), py(pl, s ? stack_top(p, i, st, s - 1) : 0.0));
        fputs("\"/>\n", f);
    }
}

/* A column as a line, scaled so that `vmax` is the plot's top. */
static void svg_line(FILE *f, const sw_rt_profile *p, const plot *pl, sw_rt_prof_col c, double vmax,
                     const char *style)
{
    fprintf(f, "<polyline fill=\"none\" %s points=\"", style);
    for (uint32_t i = 0; i < p->n_rows; i++)
        fprintf(f, "%.2f,%.2f ", px(pl, i), py(pl, p->rows[i].v[c] * pl->ymax / vmax));
    fputs("\"/>\n", f);
}

static void svg_captures(FILE *f, const sw_rt_profile *p, const plot *pl)
{
    for (uint32_t c = 0; c < p->n_captures; c++) {
        const double xx = px(pl, p->captures[c]);
        fprintf(f,
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#333\" "
                "stroke-dasharray=\"3,3\"/>\n",
                xx, pl->top, xx, pl->top + pl->height);
    }
}

/* Legend keys: a swatch of an area's colour, or a stretch of a line's style. */
static void svg_swatch(FILE *f, double x, double y, const char *fill)
{
    fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"14\" height=\"10\" fill=\"%s\"/>", x, y - 5,
            fill);
}

static void svg_line_key(FILE *f, double x, double y, const char *style)
{
    fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" %s/>", x, y, x + 14, y,
            style);
}

static void svg_legend(FILE *f, const sw_rt_profile *p, const plot *pl)
{
    const double x = pl->left + pl->width + 16;
    fprintf(f,
            "<g font-family=\"sans-serif\" font-size=\"11\" fill=\"#333\">\n"
            "<text x=\"%.1f\" y=\"%.1f\" font-weight=\"bold\">median ms</text>\n",
            x, pl->top + 4);
    svg_line_key(f, x, pl->top + 22, "stroke=\"#111\" stroke-width=\"1.5\"");
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\">frame %.2f</text>\n", x + 20, pl->top + 26,
            p->summary[SW_RT_COL_FRAME_MS].median);
    for (int s = N_STAGES; s-- > 0;) { /* top of the stack first, as drawn */
        const double y = pl->top + 42 + 18 * (N_STAGES - 1 - s);
        const char *name = k_cols[FIRST_STAGE + s].name;
        const int len = (int)(strlen(name) - 3); /* without "_ms" */
        svg_swatch(f, x, y, k_stage_colour[s]);
        fprintf(f, "<text x=\"%.1f\" y=\"%.1f\">%.*s %.2f</text>\n", x + 20, y + 4, len, name,
                p->summary[FIRST_STAGE + s].median);
    }
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\">dashed: captured</text>\n</g>\n", x,
            pl->top + 60 + 18 * N_STAGES);
}

/* The pool panel's legend: each kind's time over the whole run (pool work is bursty: most
 * frames' median is 0), and the queue's largest length. */
static void svg_pool_legend(FILE *f, const sw_rt_profile *p, const plot *pl)
{
    const double x = pl->left + pl->width + 16;
    fprintf(f,
            "<g font-family=\"sans-serif\" font-size=\"11\" fill=\"#333\">\n"
            "<text x=\"%.1f\" y=\"%.1f\" font-weight=\"bold\">pool ms, whole run</text>\n",
            x, pl->top + 4);
    svg_line_key(f, x, pl->top + 22, "stroke=\"#111\" stroke-dasharray=\"5,2\"");
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\">queued at end, max %.0f</text>\n", x + 20, pl->top + 26,
            p->summary[SW_RT_COL_POOL_QUEUED].max);
    svg_line_key(f, x, pl->top + 40, "stroke=\"#d62728\" stroke-dasharray=\"1,2\"");
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\">inject peak, max %.0f</text>\n", x + 20, pl->top + 44,
            p->summary[SW_RT_COL_POOL_INJECT_PEAK].max);
    for (int k = SW_RT_POOL_KIND_COUNT; k-- > 0;) {
        const double y = pl->top + 60 + 14 * (SW_RT_POOL_KIND_COUNT - 1 - k);
        const sw_rt_prof_col c = (sw_rt_prof_col)(SW_RT_COL_POOL_FIRST_MS + k);
        svg_swatch(f, x, y, k_pool_colour[k]);
        fprintf(f, "<text x=\"%.1f\" y=\"%.1f\">%s %.1f</text>\n", x + 20, y + 4,
                sw_rt_pool_kind_name(k), p->summary[c].mean * p->n_rows);
    }
    fputs("</g>\n", f);
}

/* A plot's y range: a nice step for about five lines and the top at a multiple of it. */
static double fit_y(plot *pl, double maxv)
{
    const double ystep = nice_step(maxv / 5.0);
    pl->ymax = fmax(ystep, ystep * ceil(maxv / ystep));
    return ystep;
}

int sw_rt_profile_write_svg(FILE *f, const sw_rt_profile *p)
{
    enum { W = 960, H1 = 400, H2 = 300, H = H1 + H2 };
    plot pl = {64, 34, W - 64 - 180, H1 - 34 - 56, 1.0, p->n_rows};
    plot pool = {64, H1 + 30, W - 64 - 180, H2 - 30 - 56, 1.0, p->n_rows};
    double maxv = stack_max(p, &k_stages);
    for (uint32_t i = 0; i < p->n_rows; i++)
        maxv = fmax(maxv, p->rows[i].v[SW_RT_COL_FRAME_MS]);
    const double ystep = fit_y(&pl, maxv);
    const double pool_step = fit_y(&pool, stack_max(p, &k_pool));
    fprintf(f,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" "
            "viewBox=\"0 0 %d %d\">\n<rect width=\"%d\" height=\"%d\" fill=\"#fff\"/>\n"
            "<text x=\"%d\" y=\"20\" font-family=\"sans-serif\" font-size=\"13\" "
            "font-weight=\"bold\">frame time and stages: ",
            W, H, W, H, W, H, 64);
    xml_text(f, p->meta.scene);
    fprintf(f, " (%dx%d, %s, %u frames)</text>\n", p->meta.width, p->meta.height, p->meta.mode,
            p->n_rows);
    fprintf(f,
            "<text x=\"64\" y=\"%d\" font-family=\"sans-serif\" font-size=\"13\" "
            "font-weight=\"bold\">worker pool: its threads' ms per task kind (beside frame_ms, not "
            "in it); queue lengths (lines) on their own scale, max at the top</text>\n",
            H1 + 16);
    if (p->n_rows > 0) {
        svg_areas(f, p, &pl, &k_stages);
        svg_line(f, p, &pl, SW_RT_COL_FRAME_MS, pl.ymax, "stroke=\"#111\" stroke-width=\"1.5\"");
        svg_captures(f, p, &pl);
        svg_axes(f, p, &pl, ystep, "milliseconds");
        svg_legend(f, p, &pl);
        svg_areas(f, p, &pool, &k_pool);
        /* the queue on its own scale: its largest length at the top */
        const double qmax = fmax(1.0, fmax(p->summary[SW_RT_COL_POOL_QUEUED].max,
                                           p->summary[SW_RT_COL_POOL_INJECT_PEAK].max));
        svg_line(f, p, &pool, SW_RT_COL_POOL_QUEUED, qmax,
                 "stroke=\"#111\" stroke-dasharray=\"5,2\"");
        svg_line(f, p, &pool, SW_RT_COL_POOL_INJECT_PEAK, qmax,
                 "stroke=\"#d62728\" stroke-dasharray=\"1,2\"");
        svg_captures(f, p, &pool);
        svg_axes(f, p, &pool, pool_step, "pool milliseconds");
        svg_pool_legend(f, p, &pool);
    }
    fputs("</svg>\n", f);
    return ferror(f) ? -1 : 0;
}

/* ---- HTML ------------------------------------------------------------------------------------ */
static const char k_style[] = "body{font-family:sans-serif;margin:2em;color:#222;max-width:1100px}"
                              "table{border-collapse:collapse;margin:1em 0}"
                              "td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}"
                              "th:first-child,td:first-child{text-align:left}"
                              "figure{display:inline-block;margin:0 1em 1em 0}"
                              "figcaption{font-size:90%;max-width:420px}"
                              "img{border:1px solid #ccc;max-width:420px}";

static void html_head(FILE *f, const sw_rt_profile *p)
{
    const sw_rt_prof_meta *m = &p->meta;
    fputs("<!DOCTYPE html>\n<html xmlns=\"http://www.w3.org/1999/xhtml\" lang=\"en\">\n<head>\n"
          "<meta charset=\"utf-8\"/>\n<title>splinewalk profile: ",
          f);
    xml_text(f, m->scene);
    fprintf(f, "</title>\n<style>%s</style>\n</head>\n<body>\n<h1>splinewalk profile: ", k_style);
    xml_text(f, m->scene);
    fputs("</h1>\n<p>Path <code>", f);
    xml_text(f, m->path);
    fprintf(f,
            "</code>, %u frames at %dx%d, screen-space error %g px, %s mode, eval %s, "
            "%u pool worker%s%s, LP_NUM_THREADS=",
            p->n_rows, m->width, m->height, m->error_px, m->mode, m->eval, m->worker_threads,
            m->worker_threads == 1 ? "" : "s", m->sequential ? " (--sequential)" : "");
    xml_text(f, m->lp_num_threads ? m->lp_num_threads : "(unset)");
    fputs(". Renderer: ", f);
    xml_text(f, m->renderer);
    fprintf(f, ". Run: %.2f s.</p>\n", m->wall_s);
}

static void html_summary(FILE *f, const sw_rt_profile *p)
{
    fputs("<h2>Summary</h2>\n<table>\n<tr><th>column</th><th>median</th><th>p90</th><th>p99</th>"
          "<th>max</th><th>mean</th><th>what</th></tr>\n",
          f);
    for (int c = 0; c < SW_RT_COL_COUNT; c++) {
        if (!summarized((sw_rt_prof_col)c))
            continue;
        const sw_rt_prof_stat *s = &p->summary[c];
        const int ms = k_cols[c].kind == SW_RT_KIND_STAGE || k_cols[c].kind == SW_RT_KIND_FRAME ||
                       k_cols[c].kind == SW_RT_KIND_VSTAGE || k_cols[c].kind == SW_RT_KIND_GPU ||
                       k_cols[c].kind == SW_RT_KIND_POOL;
        const char *fmt = ms ? "<td>%.2f</td>" : "<td>%.0f</td>";
        fprintf(f, "<tr><td>%s</td>", k_cols[c].name);
        const double v[5] = {s->median, s->p90, s->p99, s->max, s->mean};
        for (int k = 0; k < 5; k++)
            fprintf(f, fmt, v[k]);
        fputs("<td style=\"text-align:left\">", f);
        xml_text(f, k_cols[c].what);
        fputs("</td></tr>\n", f);
    }
    const uint32_t mf = p->n_rows ? median_frame(p) : 0;
    fprintf(f,
            "</table>\n<p>Percentiles interpolate linearly between ranks. The median frame (%u) "
            "spends %.2f %% of its time outside the measured stages (other).</p>\n",
            mf, p->n_rows ? 100.0 * share(&p->rows[mf], SW_RT_COL_OTHER_MS) : 0.0);
}

static void html_captures(FILE *f, const sw_rt_profile *p)
{
    fputs("<h2>Captured frames</h2>\n<div>\n", f);
    for (uint32_t c = 0; c < p->n_captures; c++) {
        const sw_rt_prof_row *r = &p->rows[p->captures[c]];
        char name[64];
        sw_rt_profile_capture_name(p->captures[c], name, sizeof name);
        fprintf(f,
                "<figure><img src=\"%s\" alt=\"frame %u\"/><figcaption>frame %u, t = %.3f s: "
                "%.2f ms (write %.2f ms), %.0f triangles, %.0f patches, %.0f fallback draws"
                "</figcaption></figure>\n",
                name, p->captures[c], p->captures[c], r->v[SW_RT_COL_T], r->v[SW_RT_COL_FRAME_MS],
                r->v[SW_RT_COL_WRITE_MS], r->v[SW_RT_COL_TRIANGLES], r->v[SW_RT_COL_PATCHES],
                r->v[SW_RT_COL_FALLBACK_DRAWS]);
    }
    fputs("</div>\n<p>Data: <a href=\"profile.csv\">profile.csv</a>, "
          "<a href=\"profile.json\">profile.json</a>, <a href=\"frametime.svg\">frametime.svg</a>."
          "</p>\n",
          f);
}

int sw_rt_profile_write_html(FILE *f, const sw_rt_profile *p, const char *svg)
{
    html_head(f, p);
    html_summary(f, p);
    fputs("<h2>Frame time along the path</h2>\n", f);
    fputs(svg ? svg : "", f);
    html_captures(f, p);
    fputs("</body>\n</html>\n", f);
    return ferror(f) ? -1 : 0;
}

/* The pool's rows of the summary: the kinds that ran at all, then the queue. */
static void print_pool_summary(FILE *f, const sw_rt_profile *p)
{
    fputs("pool, all threads (beside frame_ms):\n", f);
    for (int k = 0; k < SW_RT_POOL_KIND_COUNT; k++) {
        const sw_rt_prof_stat *s = &p->summary[SW_RT_COL_POOL_FIRST_MS + k];
        const double tasks = p->summary[SW_RT_COL_POOL_FIRST_TASKS + k].mean * p->n_rows;
        if (!(tasks > 0.0))
            continue;
        fprintf(f, "  %-14s %9.2f %9.2f %9.2f %9.2f %9.2f  %.0f tasks, %.1f ms in all\n",
                sw_rt_pool_kind_name(k), s->median, s->p90, s->p99, s->max, s->mean, tasks,
                s->mean * p->n_rows);
    }
    const sw_rt_prof_stat *q = &p->summary[SW_RT_COL_POOL_QUEUED];
    fprintf(f,
            "  %-14s %9.0f %9.0f %9.0f %9.0f %9.1f  tasks waiting at frame ends, %.0f at the "
            "last\n",
            "queued", q->median, q->p90, q->p99, q->max, q->mean,
            p->n_rows ? p->rows[p->n_rows - 1].v[SW_RT_COL_POOL_QUEUED] : 0.0);
    q = &p->summary[SW_RT_COL_POOL_INJECT_PEAK];
    fprintf(f, "  %-14s %9.0f %9.0f %9.0f %9.0f %9.1f  longest injection queue during a frame\n",
            "inject_peak", q->median, q->p90, q->p99, q->max, q->mean);
}

void sw_rt_profile_print_summary(FILE *f, const sw_rt_profile *p)
{
    fprintf(f, "%-16s %9s %9s %9s %9s %9s\n", "ms", "median", "p90", "p99", "max", "mean");
    for (int c = SW_RT_COL_FRAME_MS; c <= SW_RT_COL_VIS_JOIN_MS; c++) {
        const sw_rt_prof_stat *s = &p->summary[c];
        const char *name = k_cols[c].name;
        fprintf(f, "%s%-*.*s %9.2f %9.2f %9.2f %9.2f %9.2f\n", c == SW_RT_COL_FRAME_MS ? "" : "  ",
                c == SW_RT_COL_FRAME_MS ? 16 : 14, (int)strlen(name) - 3, name, s->median, s->p90,
                s->p99, s->max, s->mean);
    }
    print_pool_summary(f, p);
    double fallbacks = 0.0, waits = 0.0;
    for (uint32_t i = 0; i < p->n_rows; i++) {
        fallbacks += p->rows[i].v[SW_RT_COL_FALLBACK_DRAWS];
        waits += p->rows[i].v[SW_RT_COL_POOL_WAITS];
    }
    const uint32_t mf = p->n_rows ? median_frame(p) : 0;
    fprintf(f,
            "median frame %u: other %.2f %% of frame_ms; triangles median %.0f (max %.0f), "
            "patches median %.0f; fallback draws %.0f, pool waits %.0f in all; resident max "
            "%.1f MiB\n",
            mf, p->n_rows ? 100.0 * share(&p->rows[mf], SW_RT_COL_OTHER_MS) : 0.0,
            p->summary[SW_RT_COL_TRIANGLES].median, p->summary[SW_RT_COL_TRIANGLES].max,
            p->summary[SW_RT_COL_PATCHES].median, fallbacks, waits,
            p->summary[SW_RT_COL_RESIDENT_BYTES].max / (1024.0 * 1024.0));
}
