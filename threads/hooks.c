/* SPDX-License-Identifier: MIT */
/* The allocator and log hooks behind sw_setup (sw_hooks.h). */
#include "sw_hooks.h"

#include <stdalign.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* g_state: FRESH until the first allocation (USED) or sw_setup (HOOKED). The hooks below are
 * written before the release CAS that sets HOOKED and read after an acquire load that sees it, so
 * a thread that allocates through them sees the whole desc. Once USED, sw_setup is refused: a
 * block from malloc must never reach the host's free. */
enum { STATE_FRESH, STATE_USED, STATE_HOOKED };
static atomic_int g_state;
static sw_setup_desc g_desc;

/* Host blocks carry this header before the caller's bytes: the block's size (to emulate a
 * missing realloc) and, for aligned blocks, where the host's block begins. 16 bytes keep
 * malloc's alignment for what follows. */
typedef struct header {
    alignas(16) size_t size;
    void *base; /* aligned blocks: the host's pointer; NULL for the others */
} header;
#define HEADER_SIZE sizeof(header)

static int hooked(void)
{
    int state = atomic_load_explicit(&g_state, memory_order_acquire); /* pairs with install */
    if (state == STATE_FRESH) {
        int expected = STATE_FRESH;
        /* Only marks that malloc has been used; nothing is published by it. */
        atomic_compare_exchange_strong_explicit(&g_state, &expected, STATE_USED,
                                                memory_order_relaxed, memory_order_relaxed);
        return 0;
    }
    return state == STATE_HOOKED;
}

static header *header_of(void *ptr)
{
    return (header *)((char *)ptr - HEADER_SIZE);
}

static void *host_alloc(size_t size)
{
    if (size > SIZE_MAX - HEADER_SIZE)
        return NULL;
    header *h = g_desc.allocator.alloc(g_desc.allocator.user_data, size + HEADER_SIZE);
    if (!h)
        return NULL;
    h->size = size;
    h->base = NULL;
    return h + 1;
}

void *sw__malloc(size_t size)
{
    if (!hooked())
        return malloc(size);
    return host_alloc(size);
}

void *sw__calloc(size_t count, size_t size)
{
    if (!hooked())
        return calloc(count, size);
    if (size && count > SIZE_MAX / size)
        return NULL;
    void *p = host_alloc(count * size);
    if (p)
        memset(p, 0, count * size);
    return p;
}

void sw__free(void *ptr)
{
    if (!hooked()) {
        free(ptr);
        return;
    }
    if (ptr)
        g_desc.allocator.free(g_desc.allocator.user_data, header_of(ptr));
}

void *sw__realloc(void *ptr, size_t size)
{
    if (!hooked())
        return realloc(ptr, size);
    if (!ptr)
        return host_alloc(size);
    if (size > SIZE_MAX - HEADER_SIZE)
        return NULL;
    header *old = header_of(ptr);
    if (g_desc.allocator.realloc) {
        header *h = g_desc.allocator.realloc(g_desc.allocator.user_data, old, size + HEADER_SIZE);
        if (!h)
            return NULL;
        h->size = size;
        return h + 1;
    }
    void *fresh = host_alloc(size);
    if (!fresh)
        return NULL;
    memcpy(fresh, ptr, old->size < size ? old->size : size);
    g_desc.allocator.free(g_desc.allocator.user_data, old);
    return fresh;
}

int sw__grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 1;
    size_t c = *cap ? *cap : 64;
    while (c < need)
        c = c > SIZE_MAX / 2 ? need : 2 * c;
    if (elem && c > SIZE_MAX / elem)
        return 0;
    void *q = sw__realloc(*p, c * elem);
    if (!q)
        return 0;
    *p = q;
    *cap = c;
    return 1;
}

char *sw__strdup(const char *text)
{
    size_t n = strlen(text) + 1;
    char *copy = sw__malloc(n);
    if (copy)
        memcpy(copy, text, n);
    return copy;
}

void *sw__aligned_alloc(size_t align, size_t size)
{
    if (!hooked()) {
        /* C11 wants a multiple of the alignment. */
        if (size > SIZE_MAX - align)
            return NULL;
        return aligned_alloc(align, (size + align - 1) / align * align);
    }
    if (size > SIZE_MAX - HEADER_SIZE - align)
        return NULL;
    char *base = g_desc.allocator.alloc(g_desc.allocator.user_data, size + HEADER_SIZE + align);
    if (!base)
        return NULL;
    uintptr_t first = (uintptr_t)base + HEADER_SIZE;
    char *p = base + ((first + align - 1) / align * align - (uintptr_t)base);
    header *h = header_of(p);
    h->size = size;
    h->base = base;
    return p;
}

void sw__aligned_free(void *ptr)
{
    if (!hooked()) {
        free(ptr);
        return;
    }
    if (ptr)
        g_desc.allocator.free(g_desc.allocator.user_data, header_of(ptr)->base);
}

/* ---- log ------------------------------------------------------------------------------------- */
static sw_log_level min_level(void)
{
    if (!hooked() || g_desc.logger.min_level == SW_LOG_DEFAULT)
        return SW_LOG_WARN;
    return g_desc.logger.min_level;
}

int sw__log_enabled(sw_log_level level)
{
    return level >= min_level();
}

static const char *level_name(sw_log_level level)
{
    switch (level) {
    case SW_LOG_DEBUG:
        return "debug";
    case SW_LOG_INFO:
        return "info";
    case SW_LOG_WARN:
        return "warning";
    case SW_LOG_ERROR:
        return "error";
    default:
        return "log";
    }
}

void sw__log(sw_log_level level, const char *fmt, ...)
{
    if (!sw__log_enabled(level))
        return;
    char line[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    size_t n = strlen(line); /* one line: a message's own newline (OCCT's) goes */
    while (n > 0 && (line[n - 1] == '\n' || line[n - 1] == '\r'))
        line[--n] = '\0';
    if (hooked() && g_desc.logger.fn)
        g_desc.logger.fn(g_desc.logger.user_data, level, line);
    else
        fprintf(stderr, "splinewalk: %s: %s\n", level_name(level), line);
}

static void *libc_alloc(void *user_data, size_t size)
{
    (void)user_data;
    return malloc(size);
}

static void *libc_realloc(void *user_data, void *ptr, size_t size)
{
    (void)user_data;
    return realloc(ptr, size);
}

static void libc_free(void *user_data, void *ptr)
{
    (void)user_data;
    free(ptr);
}

int sw__hooks_install(const sw_setup_desc *desc, const char **why)
{
    if (!desc->allocator.alloc != !desc->allocator.free) {
        *why = "allocator: alloc and free must be given together";
        return -1;
    }
    if ((unsigned)desc->logger.min_level > SW_LOG_ERROR) {
        *why = "logger.min_level out of range";
        return -1;
    }
    if (atomic_load_explicit(&g_state, memory_order_relaxed) != STATE_FRESH) {
        *why = "sw_setup must come once, before any call that allocates";
        return -1;
    }
    g_desc = *desc;
    if (!g_desc.allocator.alloc) /* a logger only: malloc and free behind the same header */
        g_desc.allocator = (sw_allocator){libc_alloc, libc_realloc, libc_free, NULL};
    int expected = STATE_FRESH;
    /* Release: publishes g_desc to every thread that reads HOOKED (acquire in hooked()). */
    if (!atomic_compare_exchange_strong_explicit(&g_state, &expected, STATE_HOOKED,
                                                 memory_order_release, memory_order_relaxed)) {
        *why = "sw_setup must come once, before any call that allocates";
        return -1;
    }
    return 0;
}
