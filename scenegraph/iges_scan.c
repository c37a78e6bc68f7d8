/* SPDX-License-Identifier: MIT */
/* The structure of a fixed-format IGES file: records, the Terminate record's counts, whole and
 * safe entities (sw_sg_iges.h says what each means and why). */
#include "sw_sg_iges.h"

#include "sw_hooks.h"
#include "sw_status_util.h"

#include <stdio.h>
#include <string.h>

typedef struct record {
    const char *p;
    size_t len; /* >= 73 */
} record;

typedef struct rec_array {
    record *r;
    size_t n, cap;
} rec_array;

static int rec_push(rec_array *a, const char *p, size_t len)
{
    if (a->n == a->cap) {
        size_t cap = a->cap ? 2 * a->cap : 256;
        record *r = sw__realloc(a->r, cap * sizeof *r);
        if (!r)
            return -1;
        a->r = r, a->cap = cap;
    }
    a->r[a->n++] = (record){p, len};
    return 0;
}

static int is_blank(const char *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (p[i] != ' ' && p[i] != '\t' && p[i] != '\r' && p[i] != '\f' && p[i] != 0x1a)
            return 0;
    return 1;
}

/* An integer in p[0, n) surrounded by blanks; 0 when empty; -1 (with *ok = 0) when not one. */
static long field_int(const char *p, size_t n, int *ok)
{
    size_t i = 0;
    while (i < n && p[i] == ' ')
        i++;
    int neg = 0;
    if (i < n && (p[i] == '-' || p[i] == '+'))
        neg = p[i++] == '-';
    long v = 0;
    size_t digits = 0;
    while (i < n && p[i] >= '0' && p[i] <= '9') {
        if (v < 100000000L)
            v = v * 10 + (p[i] - '0');
        i++, digits++;
    }
    while (i < n && p[i] == ' ')
        i++;
    *ok = i == n;
    if (!*ok)
        return -1;
    return neg ? -v : v;
}

/* Field f (1-based, 8 columns each) of a D record, as an integer (0 when blank or malformed). */
static long de_field(const record *r, int f)
{
    int ok;
    long v = field_int(r->p + 8 * (f - 1), 8, &ok);
    return ok ? v : 0;
}

static const char k_letters[5] = {'S', 'G', 'D', 'P', 'T'};

static int section_of(char c)
{
    const char *s = memchr(k_letters, c, sizeof k_letters);
    return s ? (int)(s - k_letters) : -1;
}

/* The record delimiter of the Global section (§2.2.3.1, 2: "1H;" style; ';' when empty). */
static char record_delimiter(const rec_array *g)
{
    if (g->n == 0)
        return ';';
    const char *p = g->r[0].p; /* at least 73 columns */
    char pd = ',';
    size_t i = 0;
    if (p[0] == '1' && p[1] == 'H')
        pd = p[2], i = 3;
    if (p[i] != pd) /* the end of field 1 */
        return ';';
    i++;
    return p[i] == '1' && p[i + 1] == 'H' ? p[i + 2] : ';';
}

static sw_result oom(sw_sg_iges_scan *out, sw_status *status)
{
    sw_sg_iges_scan_free(out);
    return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "IGES scan: out of memory");
}

sw_result sw_sg_iges_scan_text(const char *text, size_t len, sw_sg_iges_scan *out,
                               sw_status *status)
{
    memset(out, 0, sizeof *out);
    rec_array sec[5] = {{0}};
    int last = 0;           /* the section of the last record */
    size_t line_no = 0;     /* 1-based, of the current line */
    int cut = 0;            /* the last non-blank line is a record cut short */
    size_t gap_line = 0;    /* the first line whose sequence number skips */
    size_t order_line = 0;  /* the first record out of section order */
    sw_result r = SW_OK;
    for (size_t pos = 0; pos < len && r == SW_OK;) {
        const char *nl = memchr(text + pos, '\n', len - pos);
        size_t end = nl ? (size_t)(nl - text) : len, n = end - pos;
        const char *p = text + pos;
        pos = end + 1;
        line_no++;
        while (n > 0 && p[n - 1] == '\r')
            n--;
        if (is_blank(p, n))
            continue;
        if (cut) { /* a short record followed by more: not 80-column records */
            r = SW_ERR_UNSUPPORTED;
            break;
        }
        if (n < 73 || (n > 80 && !is_blank(p + 80, n - 80))) {
            cut = 1;
            continue;
        }
        int s = section_of(p[72]);
        if (s < 0) {
            r = SW_ERR_UNSUPPORTED; /* compressed ('C') or binary ('B', 'F') form, or not IGES */
            break;
        }
        if (s < last && !order_line)
            order_line = line_no;
        last = s > last ? s : last;
        int ok;
        long seq = field_int(p + 73, (n < 80 ? n : 80) - 73, &ok);
        if (ok && seq != (long)sec[s].n + 1 && !gap_line)
            gap_line = line_no;
        if (rec_push(&sec[s], p, n) != 0) {
            r = SW_ERR_OUT_OF_MEMORY;
            break;
        }
    }
    if (r == SW_OK && sec[0].n == 0)
        r = SW_ERR_UNSUPPORTED; /* no Start record: not fixed-format IGES */
    if (r != SW_OK) {
        for (int s = 0; s < 5; s++)
            sw__free(sec[s].r);
        if (r == SW_ERR_OUT_OF_MEMORY)
            return oom(out, status);
        return sw__fail(status, r, "not fixed-format ASCII IGES");
    }
    for (int s = 0; s < 5; s++)
        out->records[s] = (uint32_t)sec[s].n;

    /* The Terminate record and what it declares. */
    if (sec[4].n == 1) {
        const record *t = &sec[4].r[0];
        int fine = 1;
        for (int s = 0; s < 4 && fine; s++) {
            int ok;
            long v = field_int(t->p + 8 * s + 1, 7, &ok);
            fine = t->p[8 * s] == k_letters[s] && ok && v >= 0;
            out->declared[s] = fine ? (uint32_t)v : 0;
        }
        if (!fine)
            snprintf(out->why, sizeof out->why, "its Terminate record is malformed");
    }
    const char *sec_names[4] = {"Start", "Global", "Directory Entry", "Parameter Data"};
    if (out->why[0]) {
        /* said above */
    } else if (cut) {
        snprintf(out->why, sizeof out->why,
                 "it ends inside a record (a line of fewer than 73 columns) after %u D and %u P "
                 "records, with no Terminate record",
                 out->records[2], out->records[3]);
    } else if (order_line) {
        snprintf(out->why, sizeof out->why, "line %zu is out of section order", order_line);
    } else if (gap_line) {
        snprintf(out->why, sizeof out->why,
                 "the sequence numbers skip at line %zu: records are missing", gap_line);
    } else if (sec[4].n == 0) {
        snprintf(out->why, sizeof out->why,
                 "it has no Terminate record: it ends after %u D and %u P records", out->records[2],
                 out->records[3]);
    } else if (sec[4].n > 1) {
        snprintf(out->why, sizeof out->why, "it has %u Terminate records", out->records[4]);
    } else {
        for (int s = 0; s < 4; s++)
            if (out->declared[s] != out->records[s]) {
                snprintf(out->why, sizeof out->why,
                         "its Terminate record declares %u %s records, the file holds %u",
                         out->declared[s], sec_names[s], out->records[s]);
                break;
            }
    }
    if (!out->why[0] && (sec[2].n & 1u))
        snprintf(out->why, sizeof out->why, "its Directory Entry section has an odd number (%u) "
                                            "of records",
                 out->records[2]);
    out->truncated = out->why[0] != 0;

    /* Entities: whole when their parameter records are all present. After a sequence gap or a
     * record out of order no pointer can be trusted: none is. */
    out->entities = (uint32_t)(sec[2].n / 2);
    out->entity_incomplete = sw__calloc(out->entities ? out->entities : 1, 1);
    if (!out->entity_incomplete) {
        for (int s = 0; s < 5; s++)
            sw__free(sec[s].r);
        return oom(out, status);
    }
    const char rd = record_delimiter(&sec[1]);
    const size_t n_p = sec[3].n;
    for (uint32_t k = 0; k < out->entities; k++) {
        const record *d1 = &sec[2].r[2 * k], *d2 = &sec[2].r[2 * k + 1];
        long first = de_field(d1, 2), count = de_field(d2, 4);
        int whole = !gap_line && !order_line && first >= 1 && count >= 1 &&
                    (size_t)first - 1 <= n_p && (size_t)count <= n_p - ((size_t)first - 1);
        if (whole) { /* its last record holds the record delimiter (';' unless the Global
                        section names another) */
            const record *last_p = &sec[3].r[first - 1 + count - 1];
            whole = memchr(last_p->p, rd, 64) != NULL;
        }
        if (!whole) {
            out->entity_incomplete[k] = 1;
            out->incomplete++;
        }
    }
    for (int s = 0; s < 5; s++)
        sw__free(sec[s].r);
    sw__status_ok(status);
    return SW_OK;
}

void sw_sg_iges_scan_free(sw_sg_iges_scan *scan)
{
    if (!scan)
        return;
    sw__free(scan->entity_incomplete);
    memset(scan, 0, sizeof *scan);
}
