/* SPDX-License-Identifier: MIT */
/* Writes a corrupted copy of a valid .sws whose checksums are all correct again, so that only the
 * geometry check can catch it: `make_bad_sws IN OUT decreasing-knots|nan-weight`. The corruption
 * hits face 0: its first two u-knots are swapped with a larger value, or its first weight becomes
 * NaN. Layout per docs/sws-format.md. */
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

static void refresh_checksums(unsigned char *file, unsigned char *pool_entry)
{
    uint32_t crc = sw__crc32c(0, file + rd64(pool_entry + 8), rd64(pool_entry + 16));
    memcpy(pool_entry + 32, &crc, 4);
    uint32_t count;
    memcpy(&count, file + 16, 4);
    uint32_t header_crc = sw__crc32c(0, file, 60);
    header_crc = sw__crc32c(header_crc, file + rd64(file + 32), (size_t)count * ENTRY);
    memcpy(file + 60, &header_crc, 4);
}

int main(int argc, char **argv)
{
    if (argc != 4)
        return fprintf(stderr, "usage: make_bad_sws IN OUT decreasing-knots|nan-weight\n"), 2;
    FILE *f = fopen(argv[1], "rb");
    if (!f)
        return perror(argv[1]), 1;
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *file = malloc((size_t)size);
    if (!file || fread(file, 1, (size_t)size, f) != (size_t)size)
        return fprintf(stderr, "cannot read %s\n", argv[1]), 1;
    fclose(f);

    unsigned char *faces = entry_of(file, SEC_FACES), *pool_e = entry_of(file, SEC_POOL);
    if (!faces || !pool_e || rd64(faces + 24) == 0)
        return fprintf(stderr, "%s: no faces\n", argv[1]), 1;
    sw_sg_face_rec face;
    memcpy(&face, file + rd64(faces + 8), sizeof face);
    double *pool = (double *)(file + rd64(pool_e + 8));
    if (!strcmp(argv[3], "decreasing-knots")) {
        /* knots_u[deg_u] > knots_u[deg_u + 1]: the domain's first span runs backwards */
        pool[face.knots_u + face.deg_u] = pool[face.knots_u + face.deg_u + 1] + 1.0;
    } else if (!strcmp(argv[3], "nan-weight")) {
        pool[face.cpw + 3] = NAN;
    } else {
        return fprintf(stderr, "unknown corruption %s\n", argv[3]), 2;
    }
    refresh_checksums(file, pool_e);
    f = fopen(argv[2], "wb");
    if (!f || fwrite(file, 1, (size_t)size, f) != (size_t)size || fclose(f))
        return fprintf(stderr, "cannot write %s\n", argv[2]), 1;
    free(file);
    return 0;
}
