/* SPDX-License-Identifier: MIT */
/* Writes a corrupted copy of a valid .sws: `make_bad_sws IN OUT CORRUPTION`. Layout per
 * docs/sws-format.md. Geometry corruptions (face 0) come with every checksum correct again, so
 * that only the geometry check can catch them:
 *   decreasing-knots  its first two u-knots swapped with a larger value
 *   nan-weight        its first weight NaN
 *   loop-index        its first loop index past the LOOPS section
 * Structural corruptions of the header, the section table and the layout, each with the header
 * checksum made right again (a reader must find the fault itself, not by the checksum):
 *   version-2, bad-magic, flags, reserved, section-count-7, section-count-13, table-misaligned,
 *   table-in-header, entry-size-48, size-field-long, size-field-short, section-overlap,
 *   section-past-end, section-misaligned, count-mismatch, duplicate-id, padding (a padding byte
 *   between two sections set), trailing (16 bytes appended, the size field updated)
 * and checksum faults, left wrong on purpose: header-crc (a reserved byte flipped), section-crc
 * (a byte of FACES flipped). */
#include "sw_crc32c.h"
#include "sw_sg_scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { HEADER = 64, ENTRY = 40, SEC_FACES = 0, SEC_POOL = 5 };

static uint64_t rd64(const unsigned char *p)
{
    uint64_t x;
    memcpy(&x, p, 8);
    return x;
}

static unsigned char *entry_of(unsigned char *file, uint32_t id)
{
    uint64_t table = rd64(file + 32);
    uint32_t count;
    memcpy(&count, file + 16, 4);
    for (uint32_t i = 0; i < count; i++) {
        unsigned char *e = file + table + (uint64_t)i * ENTRY;
        uint32_t eid;
        memcpy(&eid, e, 4);
        if (eid == id)
            return e;
    }
    return NULL;
}

/* Over the table of the header's section count, or of 8 sections when that count is not one a
 * file may have: the reader does the same (it cannot trust the count before the checksum). */
static void refresh_header(unsigned char *file)
{
    uint32_t count;
    memcpy(&count, file + 16, 4);
    if (count != 8 && count != 9 && count != 11)
        count = 8;
    uint32_t header_crc = sw__crc32c(0, file, 60);
    header_crc = sw__crc32c(header_crc, file + rd64(file + 32), (size_t)count * ENTRY);
    memcpy(file + 60, &header_crc, 4);
}

/* One section's checksum (its entry given) and the header's made right again. */
static void refresh_checksums(unsigned char *file, unsigned char *section_entry)
{
    uint32_t crc = sw__crc32c(0, file + rd64(section_entry + 8), rd64(section_entry + 16));
    memcpy(section_entry + 32, &crc, 4);
    refresh_header(file);
}

static void wr32(unsigned char *p, uint32_t x)
{
    memcpy(p, &x, 4);
}

static void wr64(unsigned char *p, uint64_t x)
{
    memcpy(p, &x, 8);
}

/* The gap after the section that ends first before another starts (its first padding byte), or
 * 0 when the sections are packed. */
static uint64_t padding_byte(const unsigned char *file, uint64_t size)
{
    uint32_t count;
    memcpy(&count, file + 16, 4);
    const unsigned char *table = file + rd64(file + 32);
    for (uint32_t i = 0; i < count; i++) {
        uint64_t end = rd64(table + i * ENTRY + 8) + rd64(table + i * ENTRY + 16);
        if (end % 16 != 0 && end < size)
            return end;
    }
    return 0;
}

/* A structural corruption; 0 when `what` names none. *size may change (trailing bytes). */
static int corrupt_structure(unsigned char *file, uint64_t *size, const char *what)
{
    unsigned char *table = file + rd64(file + 32);
    unsigned char *faces = entry_of(file, SEC_FACES), *loops = entry_of(file, 1);
    if (!strcmp(what, "version-2"))
        wr32(file + 8, 2);
    else if (!strcmp(what, "bad-magic"))
        file[0] = 'X';
    else if (!strcmp(what, "flags"))
        wr32(file + 12, 1);
    else if (!strcmp(what, "reserved"))
        file[50] = 7;
    else if (!strcmp(what, "section-count-7"))
        wr32(file + 16, 7);
    else if (!strcmp(what, "section-count-13"))
        wr32(file + 16, 13); /* 8, 9, 11 and 12 are counts of the format */
    else if (!strcmp(what, "table-misaligned"))
        wr64(file + 32, rd64(file + 32) + 8);
    else if (!strcmp(what, "table-in-header"))
        wr64(file + 32, 16);
    else if (!strcmp(what, "entry-size-48"))
        wr32(file + 40, 48);
    else if (!strcmp(what, "size-field-long"))
        wr64(file + 24, *size + 4096);
    else if (!strcmp(what, "size-field-short"))
        wr64(file + 24, *size - 16);
    else if (!strcmp(what, "section-overlap"))
        wr64(loops + 8, rd64(faces + 8));
    else if (!strcmp(what, "section-past-end"))
        wr64(loops + 8, (*size + 4096) & ~(uint64_t)15);
    else if (!strcmp(what, "section-misaligned"))
        wr64(loops + 8, rd64(loops + 8) + 4);
    else if (!strcmp(what, "count-mismatch"))
        wr64(faces + 24, rd64(faces + 24) + 1);
    else if (!strcmp(what, "duplicate-id"))
        wr32(table + ENTRY, 0); /* the second entry claims FACES too */
    else if (!strcmp(what, "padding")) {
        const uint64_t at = padding_byte(file, *size);
        if (!at)
            return fprintf(stderr, "no padding between sections\n"), -1;
        file[at] = 0x5a;
        return 1; /* no checksum covers padding: nothing to refresh */
    } else if (!strcmp(what, "trailing")) {
        memset(file + *size, 0, 16);
        *size += 16;
        wr64(file + 24, *size);
    } else
        return 0;
    refresh_header(file);
    return 1;
}

int main(int argc, char **argv)
{
    if (argc != 4)
        return fprintf(stderr, "usage: make_bad_sws IN OUT CORRUPTION (the file's top comment "
                               "lists them)\n"),
               2;
    FILE *f = fopen(argv[1], "rb");
    if (!f)
        return perror(argv[1]), 1;
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *file = malloc((size_t)size + 16); /* room for "trailing" */
    if (!file || fread(file, 1, (size_t)size, f) != (size_t)size)
        return fprintf(stderr, "cannot read %s\n", argv[1]), 1;
    fclose(f);

    unsigned char *faces = entry_of(file, SEC_FACES), *pool_e = entry_of(file, SEC_POOL);
    if (!faces || !pool_e || rd64(faces + 24) == 0)
        return fprintf(stderr, "%s: no faces\n", argv[1]), 1;
    uint64_t out_size = (uint64_t)size;
    const int structural = corrupt_structure(file, &out_size, argv[3]);
    if (structural < 0)
        return 1;
    sw_sg_face_rec face;
    memcpy(&face, file + rd64(faces + 8), sizeof face);
    double *pool = (double *)(file + rd64(pool_e + 8));
    if (structural) {
    } else if (!strcmp(argv[3], "decreasing-knots")) {
        /* knots_u[deg_u] > knots_u[deg_u + 1]: the domain's first span runs backwards */
        pool[face.knots_u + face.deg_u] = pool[face.knots_u + face.deg_u + 1] + 1.0;
        refresh_checksums(file, pool_e);
    } else if (!strcmp(argv[3], "nan-weight")) {
        pool[face.cpw + 3] = NAN;
        refresh_checksums(file, pool_e);
    } else if (!strcmp(argv[3], "loop-index")) {
        const unsigned char *loops = entry_of(file, 1);
        face.first_loop = (uint32_t)rd64(loops + 24) + 5;
        face.n_loops = face.n_loops ? face.n_loops : 1;
        memcpy(file + rd64(faces + 8), &face, sizeof face);
        refresh_checksums(file, faces);
    } else if (!strcmp(argv[3], "header-crc")) {
        file[45] ^= 0x40; /* a reserved byte, the header checksum left as it was */
    } else if (!strcmp(argv[3], "section-crc")) {
        file[rd64(faces + 8) + 3] ^= 0x40; /* FACES' checksum left as it was */
    } else {
        return fprintf(stderr, "unknown corruption %s\n", argv[3]), 2;
    }
    f = fopen(argv[2], "wb");
    if (!f || fwrite(file, 1, (size_t)out_size, f) != (size_t)out_size || fclose(f))
        return fprintf(stderr, "cannot write %s\n", argv[2]), 1;
    free(file);
    return 0;
}
