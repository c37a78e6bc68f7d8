/* SPDX-License-Identifier: MIT */
/* libFuzzer harness for .sws loading: every input is opened from memory (sw_sg_scene_open_bytes:
 * the header and table checks of a file's open, on a copy of the bytes; the file system's part of
 * an open is the malformed corpus's) and, if that succeeds, fully required (checksums +
 * validation), then traversed. Each input is tried twice: as given, and with its checksums
 * recomputed ("resealed") where the table allows, so mutations reach the record validation behind
 * the checksums. A scene that validates is saved to a scratch file (SW_FUZZ_SCRATCH, else one per
 * process in /dev/shm or /tmp) and opened from it: every record array, the string table and the
 * LOD cache must come back byte for byte (the writer loses nothing the reader accepted), through
 * the file open the in-memory one stands for. Planted: the writer dropping the last adjacency
 * record → the round trip aborts on the committed corpus. */
#include "../support/fuzz_scratch.h"
#include "sw_crc32c.h"
#include "sw_sg_scene.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { HDR_TABLE = 32, HDR_CRC = 60, ENTRY = 40, N_SEC = 8, TABLE_BYTES = ENTRY * N_SEC };

static const char k_name[] = "fuzz input";

static int count_visit(void *ctx, uint32_t face, const double world[12], const float color[4])
{
    (void)face, (void)world, (void)color;
    return ++*(uint64_t *)ctx > 100000; /* instances can multiply occurrences exponentially */
}

static const char *scratch_file(void)
{
    return sw_fuzz_scratch("sw_fuzz_sws.sws");
}

static int same_bytes(const void *a, const void *b, size_t n)
{
    return n == 0 || (a && b && !memcmp(a, b, n));
}

static int same_view(const sw_sg_scene_view *a, const sw_sg_scene_view *b)
{
    return a->n_faces == b->n_faces && a->n_loops == b->n_loops && a->n_curves == b->n_curves &&
           a->n_nodes == b->n_nodes && a->n_adjacency == b->n_adjacency && a->n_pool == b->n_pool &&
           a->n_strings == b->n_strings && a->root == b->root && a->n_meshes == b->n_meshes &&
           a->n_indices == b->n_indices &&
           same_bytes(a->faces, b->faces, a->n_faces * sizeof *a->faces) &&
           same_bytes(a->loops, b->loops, a->n_loops * sizeof *a->loops) &&
           same_bytes(a->curves, b->curves, a->n_curves * sizeof *a->curves) &&
           same_bytes(a->nodes, b->nodes, a->n_nodes * sizeof *a->nodes) &&
           same_bytes(a->adjacency, b->adjacency, a->n_adjacency * sizeof *a->adjacency) &&
           same_bytes(a->pool, b->pool, a->n_pool * sizeof *a->pool) &&
           same_bytes(a->strings, b->strings, a->n_strings) &&
           same_bytes(a->meshes, b->meshes, a->n_meshes * sizeof *a->meshes) &&
           same_bytes(a->indices, b->indices, a->n_indices * sizeof *a->indices);
}

/* The LOD cache of a scene: NULL/0 when it has none; a damaged one compares as absent. */
static void lods_of(const sw_sg_scene *s, const void **data, size_t *size)
{
    *data = NULL, *size = 0;
    if (sw_sg_scene_lods(s, data, size, NULL) != SW_OK)
        *data = NULL, *size = 0;
}

static void round_trip(sw_sg_scene *s)
{
    sw_status st = {0};
    if (sw_sg_scene_save(s, scratch_file(), &st) != SW_OK) {
        /* saving keeps a LOD cache only once verified: a damaged one refuses the save */
        const void *d;
        size_t n;
        if (sw_sg_scene_lods(s, &d, &n, NULL) == SW_ERR_CHECKSUM)
            return;
        abort();
    }
    sw_sg_scene *back = NULL;
    if (sw_sg_scene_open(scratch_file(), &back, &st) != SW_OK ||
        sw_sg_scene_require(back, SW_SG_SEC_ALL, &st) != SW_OK)
        abort();
    const void *la, *lb;
    size_t na, nb;
    lods_of(s, &la, &na);
    lods_of(back, &lb, &nb);
    if (!same_view(sw_sg_scene_view_ptr(s), sw_sg_scene_view_ptr(back)) || na != nb ||
        !same_bytes(la, lb, na))
        abort();
    sw_sg_scene_free(back);
}

static void try_bytes(const uint8_t *data, size_t size)
{
    sw_sg_scene *s = NULL;
    sw_status st = {0};
    if (sw_sg_scene_open_bytes(data, size, k_name, &s, &st) != SW_OK) {
        if (s || st.result == SW_OK || !strstr(st.message, k_name))
            abort(); /* a failure must come with no scene and a message naming the input */
        return;
    }
    if (sw_sg_scene_require(s, SW_SG_SEC_ALL, &st) == SW_OK) {
        uint64_t n = 0;
        sw_sg_scene_traverse(s, count_visit, &n);
        if (sw_sg_scene_view_ptr(s)->n_nodes <= 40) {
            sw_sg_scene_stats stats;
            sw_sg_scene_compute_stats(s, &stats);
        }
        round_trip(s);
    }
    sw_sg_scene_free(s);
}

static uint64_t rd64(const uint8_t *p)
{
    uint64_t x;
    memcpy(&x, p, 8);
    return x;
}

/* Recomputes section and header checksums in a copy, reading only inside the input. */
static int reseal(uint8_t *d, size_t size)
{
    if (size < 64)
        return 0;
    uint64_t table = rd64(d + HDR_TABLE);
    if (table > size || TABLE_BYTES > size - table)
        return 0;
    for (int i = 0; i < N_SEC; i++) {
        uint8_t *e = d + table + (size_t)i * ENTRY;
        uint64_t off = rd64(e + 8), len = rd64(e + 16);
        if (off <= size && len <= size - off) {
            uint32_t crc = sw__crc32c(0, d + off, len);
            memcpy(e + 32, &crc, 4);
        }
    }
    uint32_t crc = sw__crc32c(sw__crc32c(0, d, HDR_CRC), d + table, TABLE_BYTES);
    memcpy(d + HDR_CRC, &crc, 4);
    return 1;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    try_bytes(data, size);
    uint8_t *copy = malloc(size ? size : 1);
    if (!copy)
        return 0;
    memcpy(copy, data, size);
    if (reseal(copy, size))
        try_bytes(copy, size);
    free(copy);
    return 0;
}
