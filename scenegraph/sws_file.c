/* SPDX-License-Identifier: MIT */
/* The native scene file, .sws: the scene's record arrays written as they are in memory, so that
 * opening one is an mmap plus a check of the header and section table, and each section is
 * checksummed on first use (ARCHITECTURE.md, "Rules that keep the pipeline sane").
 *
 * Layout, version 1 (all integers little-endian; docs/sws-format.md says the same at length):
 *
 *   offset  size  field
 *   0       8     magic "SWSCENE\0"
 *   8       4     version = 1
 *   12      4     flags = 0
 *   16      4     section count = 8, 9 with the optional LODS section, 11 with meshes, 12 with
 *                 shapes
 *   20      4     header size = 64
 *   24      8     total file size in bytes
 *   32      8     offset of the section table (16-byte aligned, >= 64)
 *   40      4     size of a section-table entry = 40
 *   44      16    reserved, zero
 *   60      4     header checksum: CRC-32C of bytes [0, 60) followed by the whole section table
 *
 *   section table entry (40 bytes):
 *   0  u32 id (0 FACES, 1 LOOPS, 2 CURVES, 3 NODES, 4 ADJACENCY, 5 POOL, 6 STRINGS, 7 META,
 *            8 LODS: optional, the static-LOD cache, opaque bytes with their own format owned by
 *            lod/static/static_lod_io.c; only when the count is 9 or more, and may be empty with
 *            11 or 12; 9 MESHES, 10 INDICES: triangle meshes, only when the count is 11 or 12 (may
 *            be empty with 12); 11 SHAPES: planar outlines, only when the count is 12)
 *   4  u32 reserved, zero
 *   8  u64 offset of the section (16-byte aligned, after the table, sections do not overlap)
 *   16 u64 size in bytes = element count * record size
 *   24 u64 element count
 *   32 u32 CRC-32C of the section's bytes
 *   36 u32 reserved, zero
 *
 *   record sizes: FACES 96 (sw_sg_face_rec), LOOPS 16, CURVES 24, NODES 136, ADJACENCY 8,
 *   POOL 8 (double), STRINGS 1 (char; the last one NUL), META 16 (u32 root node, 12 zero bytes),
 *   MESHES 88 (sw_sg_mesh_rec), INDICES 4 (u32), SHAPES 56 (sw_sg_shape_rec). A scene without
 *   shapes is written with 8, 9 or 11 sections, and one without meshes either with 8 or 9, byte
 *   for byte as before those sections existed.
 *   Padding between sections is zero. The file ends where its last section ends.
 *
 * Open checks everything up to the section table (and META, 16 bytes) and that the file is as
 * long as the header says, before any section body is read: a mapping shorter than that would
 * raise SIGBUS. sw_sg_scene_require() then verifies section checksums once each and, when all
 * are verified, validates the records (scene_validate.c). Open accepts a regular file only and
 * cannot block (sw_safe_read.h). Save goes through the project's one writer (sw_safe_write.h: a
 * temporary, fsync'd and renamed over PATH), so a reader sees either the old file or the new
 * one, also on a full disk. */
#include "sw_crc32c.h"
#include "sw_hooks.h"
#include "sw_safe_read.h"
#include "sw_safe_write.h"
#include "sw_sg_scene_internal.h"
#include "sw_status_util.h"

#include <errno.h>
#include <fcntl.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

_Static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, ".sws records are little-endian");
_Static_assert(sizeof(sw_sg_face_rec) == 96 && offsetof(sw_sg_face_rec, uv_box) == 56,
               "face record layout is part of the .sws format");
_Static_assert(sizeof(sw_sg_loop_rec) == 16, "loop record layout is part of the .sws format");
_Static_assert(sizeof(sw_sg_curve_rec) == 24, "curve record layout is part of the .sws format");
_Static_assert(sizeof(sw_sg_node_rec) == 136 && offsetof(sw_sg_node_rec, xform) == 40,
               "node record layout is part of the .sws format");
_Static_assert(sizeof(sw_sg_adjacency_rec) == 8, "adjacency layout is part of the .sws format");
_Static_assert(sizeof(sw_sg_mesh_rec) == 88 && offsetof(sw_sg_mesh_rec, box) == 40,
               "mesh record layout is part of the .sws format");
_Static_assert(sizeof(sw_sg_shape_rec) == 56 && offsetof(sw_sg_shape_rec, px_size) == 48,
               "shape record layout is part of the .sws format");
_Static_assert(sizeof(double) == 8 && sizeof(float) == 4, "IEEE 754 binary64/binary32");

#define SWS_MAGIC "SWSCENE"
#define SWS_VERSION 1u
#define SWS_HEADER_SIZE 64u
#define SWS_ENTRY_SIZE 40u
#define SWS_ALIGN 16u
#define SWS_HEADER_CRC_AT 60u
#define SWS_SEC_LODS SW__SG_SEC_LODS      /* id of the optional cache section */
#define SWS_CORE_SECTIONS 8u              /* FACES .. META: every file has them */
#define SWS_LODS_SECTIONS 9u              /* and LODS */
#define SWS_MESH_SECTIONS 11u             /* and MESHES, INDICES (LODS then possibly empty) */
#define SWS_MAX_SECTIONS SW__SG_SEC_COUNT /* and SHAPES (the others possibly empty) */
_Static_assert(SWS_MAX_SECTIONS == 12, "a new section needs a new section count here");

typedef struct sws_header {
    uint32_t version, flags, section_count, header_size;
    uint64_t file_size, table_offset;
    uint32_t entry_size, header_crc;
    int reserved_zero;
} sws_header;

static uint32_t rd32(const unsigned char *p)
{
    uint32_t x;
    memcpy(&x, p, 4);
    return x;
}

static uint64_t rd64(const unsigned char *p)
{
    uint64_t x;
    memcpy(&x, p, 8);
    return x;
}

static void wr32(unsigned char *p, uint32_t x)
{
    memcpy(p, &x, 4);
}

static void wr64(unsigned char *p, uint64_t x)
{
    memcpy(p, &x, 8);
}

static uint64_t align16(uint64_t x)
{
    return (x + (SWS_ALIGN - 1)) & ~(uint64_t)(SWS_ALIGN - 1);
}

/* ---- require --------------------------------------------------------------------------------- */

sw_result sw_sg_scene_require(sw_sg_scene *scene, uint32_t sections, sw_status *status)
{
    if (!scene->map) {
        sw__status_ok(status);
        return SW_OK;
    }
    for (int s = 0; s < SW__SG_SEC_COUNT; s++) {
        uint32_t bit = 1u << s;
        if (!sw__sg_is_array_section(s) || !(sections & bit) || (scene->verified & bit))
            continue;
        const sw__sg_section_info *e = &scene->sec[s];
        uint32_t crc = sw__crc32c(0, (const unsigned char *)scene->map + e->offset, e->size);
        if (crc != e->checksum)
            return sw__fail(status, SW_ERR_CHECKSUM,
                            "%s: section %s at offset %llu: checksum mismatch (stored 0x%08x, "
                            "computed 0x%08x)",
                            scene->path, sw__sg_section_names[s], (unsigned long long)e->offset,
                            e->checksum, crc);
        scene->verified |= bit;
    }
    if (scene->verified == SW_SG_SEC_ALL && scene->validated == 0) {
        sw_status st = {0};
        sw_result r = sw__sg_scene_validate_at(&scene->view, scene->path, scene->sec, &st);
        if (r == SW_ERR_OUT_OF_MEMORY) /* not a property of the file: may pass next time */
            return sw__fail(status, r, "%s", st.message);
        scene->validated = r == SW_OK ? 1 : -1;
        scene->validate_status = st;
    }
    if (scene->validated < 0) {
        if (status)
            *status = scene->validate_status;
        return scene->validate_status.result;
    }
    sw__status_ok(status);
    return SW_OK;
}

/* ---- open ------------------------------------------------------------------------------------ */

/* Magic and version, reading no byte past `size`. */
static sw_result check_ident(const char *path, const unsigned char *p, uint64_t size,
                             sw_status *status)
{
    size_t have = size < 8 ? (size_t)size : 8;
    if (memcmp(p, SWS_MAGIC, have) != 0)
        return sw__fail(status, SW_ERR_FORMAT, "%s: offset 0: not a .sws file (bad magic)", path);
    if (size < 12)
        return sw__fail(status, SW_ERR_TRUNCATED,
                        "%s: header at offset 0: file is %llu bytes, the header %u", path,
                        (unsigned long long)size, SWS_HEADER_SIZE);
    if (rd32(p + 8) != SWS_VERSION)
        return sw__fail(status, SW_ERR_VERSION,
                        "%s: offset 8: format version %u, this program reads version %u", path,
                        rd32(p + 8), SWS_VERSION);
    if (size < SWS_HEADER_SIZE)
        return sw__fail(status, SW_ERR_TRUNCATED,
                        "%s: header at offset 0: file is %llu bytes, the header %u", path,
                        (unsigned long long)size, SWS_HEADER_SIZE);
    return SW_OK;
}

static void read_header(const unsigned char *p, sws_header *h)
{
    h->version = rd32(p + 8);
    h->flags = rd32(p + 12);
    h->section_count = rd32(p + 16);
    h->header_size = rd32(p + 20);
    h->file_size = rd64(p + 24);
    h->table_offset = rd64(p + 32);
    h->entry_size = rd32(p + 40);
    h->header_crc = rd32(p + SWS_HEADER_CRC_AT);
    h->reserved_zero = rd32(p + 44) == 0 && rd64(p + 48) == 0 && rd32(p + 56) == 0;
}

/* The table's place in the file, the header checksum (before the other fields, so a flipped
 * header byte reads as corruption), the fields, then the file size. */
static int section_count_ok(uint32_t n)
{
    return n == SWS_CORE_SECTIONS || n == SWS_LODS_SECTIONS || n == SWS_MESH_SECTIONS ||
           n == SWS_MAX_SECTIONS;
}

static sw_result check_header(const char *path, const unsigned char *p, uint64_t size,
                              const sws_header *h, sw_status *status)
{
    const uint32_t n_sec =
        section_count_ok(h->section_count) ? h->section_count : SWS_CORE_SECTIONS;
    const uint64_t table_bytes = (uint64_t)n_sec * SWS_ENTRY_SIZE;
    if (h->table_offset < SWS_HEADER_SIZE || h->table_offset % SWS_ALIGN ||
        h->table_offset > h->file_size || table_bytes > h->file_size - h->table_offset)
        return sw__fail(status, SW_ERR_FORMAT,
                        "%s: offset 32: section table at offset %llu does not fit in the %llu "
                        "bytes the header declares",
                        path, (unsigned long long)h->table_offset,
                        (unsigned long long)h->file_size);
    if (h->table_offset > size || table_bytes > size - h->table_offset)
        return sw__fail(status, SW_ERR_TRUNCATED,
                        "%s: section table at offset %llu: file is %llu bytes, header says %llu",
                        path, (unsigned long long)h->table_offset, (unsigned long long)size,
                        (unsigned long long)h->file_size);
    uint32_t crc = sw__crc32c(0, p, SWS_HEADER_CRC_AT);
    crc = sw__crc32c(crc, p + h->table_offset, table_bytes);
    if (crc != h->header_crc)
        return sw__fail(status, SW_ERR_CHECKSUM,
                        "%s: header at offset 0: checksum mismatch (stored 0x%08x, computed "
                        "0x%08x)",
                        path, h->header_crc, crc);
    if (h->flags != 0 || h->header_size != SWS_HEADER_SIZE || h->entry_size != SWS_ENTRY_SIZE ||
        !section_count_ok(h->section_count) || !h->reserved_zero)
        return sw__fail(status, SW_ERR_FORMAT,
                        "%s: header at offset 12: flags 0x%x, %u sections, header size %u, entry "
                        "size %u (expected 0, %u, %u, %u or %u, %u, %u, reserved zero)",
                        path, h->flags, h->section_count, h->header_size, h->entry_size,
                        SWS_CORE_SECTIONS, SWS_LODS_SECTIONS, SWS_MESH_SECTIONS, SWS_MAX_SECTIONS,
                        SWS_HEADER_SIZE, SWS_ENTRY_SIZE);
    if (h->file_size > size)
        return sw__fail(status, SW_ERR_TRUNCATED,
                        "%s: offset %llu: file is %llu bytes, its section table says %llu", path,
                        (unsigned long long)size, (unsigned long long)size,
                        (unsigned long long)h->file_size);
    if (h->file_size < size)
        return sw__fail(
            status, SW_ERR_FORMAT, "%s: offset %llu: %llu bytes after the end the header declares",
            path, (unsigned long long)h->file_size, (unsigned long long)(size - h->file_size));
    return SW_OK;
}

/* One table entry: known id, not seen before, aligned, inside the file, after the table, and
 * count * record size == size (all without overflow). */
static sw_result check_entry(const char *path, const unsigned char *ent, uint64_t ent_off,
                             uint64_t data_start, uint64_t file_size, uint32_t n_sec,
                             sw__sg_section_info *sec, uint32_t *seen, sw_status *status)
{
    uint32_t id = rd32(ent);
    uint64_t off = rd64(ent + 8), sz = rd64(ent + 16), count = rd64(ent + 24);
    /* ids below n_sec, each once: with 8 sections the core ones, with 9 also LODS, with 11 also
     * MESHES and INDICES, with 12 also SHAPES */
    if (id >= n_sec || (*seen & (1u << id)) || rd32(ent + 4) || rd32(ent + 36))
        return sw__fail(status, SW_ERR_FORMAT,
                        "%s: section table entry at offset %llu: unknown or repeated id %u", path,
                        (unsigned long long)ent_off, id);
    const int lods = id == SWS_SEC_LODS;
    const char *name = sw__sg_section_names[id];
    const uint64_t rec = sw__sg_section_record_size[id];
    if (off % SWS_ALIGN || off < data_start || off > file_size || sz > file_size - off)
        return sw__fail(status, SW_ERR_FORMAT,
                        "%s: section %s (table entry at offset %llu): offset %llu, size %llu "
                        "outside the data area [%llu, %llu) or not 16-byte aligned",
                        path, name, (unsigned long long)ent_off, (unsigned long long)off,
                        (unsigned long long)sz, (unsigned long long)data_start,
                        (unsigned long long)file_size);
    uint64_t max_count =
        id == SW__SG_SEC_POOL || id == SW__SG_SEC_STRINGS || id == SW__SG_SEC_INDICES || lods
            ? UINT64_MAX
        : id == SW__SG_SEC_META ? 1
                                : SW_SG_NONE - 1;
    if (count > max_count || count > UINT64_MAX / rec || count * rec != sz ||
        (id == SW__SG_SEC_META && count != 1))
        return sw__fail(status, SW_ERR_FORMAT,
                        "%s: section %s at offset %llu: %llu elements of %llu bytes do not make "
                        "its size %llu",
                        path, name, (unsigned long long)off, (unsigned long long)count,
                        (unsigned long long)rec, (unsigned long long)sz);
    *seen |= 1u << id;
    sec[id] = (sw__sg_section_info){off, sz, count, rd32(ent + 32)};
    return SW_OK;
}

static sw_result check_overlaps(const char *path, const sw__sg_section_info *sec, sw_status *status)
{
    for (int a = 0; a < SWS_MAX_SECTIONS; a++)
        for (int b = a + 1; b < SWS_MAX_SECTIONS; b++) {
            const sw__sg_section_info *x = &sec[a], *y = &sec[b];
            if (x->size && y->size && x->offset < y->offset + y->size &&
                y->offset < x->offset + x->size)
                return sw__fail(status, SW_ERR_FORMAT,
                                "%s: section %s at offset %llu overlaps section %s at offset %llu",
                                path, sw__sg_section_names[a], (unsigned long long)x->offset,
                                sw__sg_section_names[b], (unsigned long long)y->offset);
        }
    return SW_OK;
}

/* Every byte of the data area outside the sections is alignment padding: fewer than 16 bytes
 * before each section and after the last one, all zero (else a byte flipped there would be
 * covered by no checksum). Sections do not overlap (check_overlaps ran). */
static sw_result check_padding(const char *path, const unsigned char *p, uint64_t data_start,
                               uint64_t file_size, const sw__sg_section_info *sec,
                               sw_status *status)
{
    uint64_t pos = data_start;
    for (;;) {
        /* the next non-empty section at or after pos */
        const sw__sg_section_info *next = NULL;
        for (int s = 0; s < SWS_MAX_SECTIONS; s++)
            if (sec[s].size && sec[s].offset >= pos && (!next || sec[s].offset < next->offset))
                next = &sec[s];
        const uint64_t end = next ? next->offset : file_size;
        if (end - pos >= SWS_ALIGN)
            return sw__fail(status, SW_ERR_FORMAT,
                            "%s: offset %llu: %llu bytes belong to no section (padding is under "
                            "%u bytes)",
                            path, (unsigned long long)pos, (unsigned long long)(end - pos),
                            SWS_ALIGN);
        for (uint64_t i = pos; i < end; i++)
            if (p[i])
                return sw__fail(status, SW_ERR_FORMAT,
                                "%s: offset %llu: padding byte 0x%02x, expected 0", path,
                                (unsigned long long)i, p[i]);
        if (!next)
            return SW_OK;
        pos = next->offset + next->size;
    }
}

static sw_result parse_table(sw_sg_scene *scene, const sws_header *h, sw_status *status)
{
    const unsigned char *p = scene->map;
    const uint32_t n_sec = h->section_count;
    const uint64_t data_start = h->table_offset + (uint64_t)n_sec * SWS_ENTRY_SIZE;
    uint32_t seen = 0;
    sw__sg_section_info sec[SWS_MAX_SECTIONS] = {{0}};
    for (uint32_t i = 0; i < n_sec; i++) {
        uint64_t ent_off = h->table_offset + (uint64_t)i * SWS_ENTRY_SIZE;
        sw_result r = check_entry(scene->path, p + ent_off, ent_off, data_start, h->file_size,
                                  n_sec, sec, &seen, status);
        if (r != SW_OK)
            return r;
    }
    sw_result r = check_overlaps(scene->path, sec, status);
    if (r == SW_OK)
        r = check_padding(scene->path, p, data_start, h->file_size, sec, status);
    if (r != SW_OK)
        return r;
    memcpy(scene->sec, sec, sizeof scene->sec);
    /* a file without meshes or shapes: the empty sections need no check */
    if (n_sec < SWS_MESH_SECTIONS)
        scene->verified |= SW_SG_SEC_MESHES | SW_SG_SEC_INDICES;
    if (n_sec < SWS_MAX_SECTIONS)
        scene->verified |= SW_SG_SEC_SHAPES;
    /* META is 16 bytes: verified here, as the root is part of the view. */
    const sw__sg_section_info *m = &scene->sec[SW__SG_SEC_META];
    uint32_t crc = sw__crc32c(0, p + m->offset, m->size);
    if (crc != m->checksum)
        return sw__fail(status, SW_ERR_CHECKSUM,
                        "%s: section META at offset %llu: checksum mismatch (stored 0x%08x, "
                        "computed 0x%08x)",
                        scene->path, (unsigned long long)m->offset, m->checksum, crc);
    if (rd32(p + m->offset + 4) || rd64(p + m->offset + 8))
        return sw__fail(status, SW_ERR_FORMAT, "%s: section META at offset %llu: reserved bytes",
                        scene->path, (unsigned long long)m->offset);
    scene->view.root = rd32(p + m->offset);
    return SW_OK;
}

static void map_view(sw_sg_scene *scene)
{
    const unsigned char *p = scene->map;
    const sw__sg_section_info *s = scene->sec;
    sw_sg_scene_view *v = &scene->view;
    v->faces = (const sw_sg_face_rec *)(const void *)(p + s[SW__SG_SEC_FACES].offset);
    v->loops = (const sw_sg_loop_rec *)(const void *)(p + s[SW__SG_SEC_LOOPS].offset);
    v->curves = (const sw_sg_curve_rec *)(const void *)(p + s[SW__SG_SEC_CURVES].offset);
    v->nodes = (const sw_sg_node_rec *)(const void *)(p + s[SW__SG_SEC_NODES].offset);
    v->adjacency = (const sw_sg_adjacency_rec *)(const void *)(p + s[SW__SG_SEC_ADJACENCY].offset);
    v->pool = (const double *)(const void *)(p + s[SW__SG_SEC_POOL].offset);
    v->strings = (const char *)(p + s[SW__SG_SEC_STRINGS].offset);
    v->n_faces = (uint32_t)s[SW__SG_SEC_FACES].count;
    v->n_loops = (uint32_t)s[SW__SG_SEC_LOOPS].count;
    v->n_curves = (uint32_t)s[SW__SG_SEC_CURVES].count;
    v->n_nodes = (uint32_t)s[SW__SG_SEC_NODES].count;
    v->n_adjacency = (uint32_t)s[SW__SG_SEC_ADJACENCY].count;
    v->n_pool = s[SW__SG_SEC_POOL].count;
    v->n_strings = s[SW__SG_SEC_STRINGS].count;
    v->meshes = (const sw_sg_mesh_rec *)(const void *)(p + s[SW__SG_SEC_MESHES].offset);
    v->indices = (const uint32_t *)(const void *)(p + s[SW__SG_SEC_INDICES].offset);
    v->n_meshes = (uint32_t)s[SW__SG_SEC_MESHES].count;
    v->n_indices = s[SW__SG_SEC_INDICES].count;
    v->shapes = (const sw_sg_shape_rec *)(const void *)(p + s[SW__SG_SEC_SHAPES].offset);
    v->n_shapes = (uint32_t)s[SW__SG_SEC_SHAPES].count;
}

/* open (non-blocking: a FIFO must not hang) + fstat (regular files only) + mmap; the descriptor
 * is closed before returning. */
static sw_result map_file(sw_sg_scene *scene, sw_status *status)
{
    const char *path = scene->path;
    int fd;
    uint64_t size;
    sw_result r = sw__in_open(path, 0, "scene", &fd, &size, status);
    if (r != SW_OK)
        return r;
    if (size == 0)
        r = sw__fail(status, SW_ERR_TRUNCATED, "%s: offset 0: empty file", path);
    else if (size > SIZE_MAX)
        r = sw__fail(status, SW_ERR_LIMIT, "%s: %llu bytes do not fit in the address space", path,
                     (unsigned long long)size);
    if (r == SW_OK) {
        void *m = mmap(NULL, (size_t)size, PROT_READ, MAP_PRIVATE, fd, 0);
        if (m == MAP_FAILED)
            r = sw__fail(status, errno == ENOMEM ? SW_ERR_OUT_OF_MEMORY : SW_ERR_IO,
                         "%s: cannot map %llu bytes: %s", path, (unsigned long long)size,
                         strerror(errno));
        else {
            scene->map = m;
            scene->map_size = (size_t)size;
        }
    }
    close(fd);
    return r;
}

/* A scene shell named `name` (NULL when out of memory). */
static sw_sg_scene *scene_named(const char *name)
{
    sw_sg_scene *scene = sw__calloc(1, sizeof *scene);
    char *copy = sw__malloc(strlen(name) + 1);
    if (!scene || !copy) {
        sw__free(scene);
        sw__free(copy);
        return NULL;
    }
    scene->path = strcpy(copy, name);
    scene->serial = sw__sg_next_serial();
    return scene;
}

/* The checks of an open on the scene's bytes (scene->map), then its view; frees the scene and
 * clears *out on failure. */
static sw_result open_mapped(sw_sg_scene *scene, sw_result r, sw_sg_scene **out, sw_status *status)
{
    const char *path = scene->path;
    if (r == SW_OK)
        r = check_ident(path, scene->map, scene->map_size, status);
    sws_header h;
    if (r == SW_OK) {
        read_header(scene->map, &h);
        r = check_header(path, scene->map, scene->map_size, &h, status);
    }
    if (r == SW_OK)
        r = parse_table(scene, &h, status);
    if (r != SW_OK) {
        sw_sg_scene_free(scene);
        return r;
    }
    map_view(scene);
    *out = scene;
    sw__status_ok(status);
    return SW_OK;
}

sw_result sw_sg_scene_open(const char *path, sw_sg_scene **out, sw_status *status)
{
    *out = NULL;
    sw_sg_scene *scene = scene_named(path);
    if (!scene)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    return open_mapped(scene, map_file(scene, status), out, status);
}

sw_result sw_sg_scene_open_bytes(const void *data, size_t size, const char *name, sw_sg_scene **out,
                                 sw_status *status)
{
    *out = NULL;
    sw_sg_scene *scene = scene_named(name);
    void *copy = scene && size ? sw__malloc(size) : NULL;
    if (!scene || (size && !copy)) {
        sw__free(scene ? scene->path : NULL);
        sw__free(scene);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", name);
    }
    sw_result r = SW_OK;
    if (size == 0)
        r = sw__fail(status, SW_ERR_TRUNCATED, "%s: offset 0: empty file", name);
    else {
        memcpy(copy, data, size);
        scene->map = copy;
        scene->map_size = size;
        scene->map_on_heap = 1;
    }
    return open_mapped(scene, r, out, status);
}

/* ---- save ------------------------------------------------------------------------------------ */

/* Header, table and META for a scene's view and n_sec sections (the 9th: lods, lods_bytes, maybe
 * empty when there are 11 or 12);
 * fills the section offsets and the file size. */
static void build_header(const sw_sg_scene_view *v, uint32_t n_sec, const void *lods,
                         uint64_t lods_bytes, const void *ptr[SWS_MAX_SECTIONS],
                         unsigned char meta[16], unsigned char *head, uint64_t head_bytes,
                         uint64_t *file_size)
{
    memset(head, 0, head_bytes);
    memset(meta, 0, 16);
    wr32(meta, v->root);
    uint64_t off = head_bytes;
    unsigned char *table = head + SWS_HEADER_SIZE;
    for (int s = 0; s < (int)n_sec; s++) {
        uint64_t bytes = 16, count = 1;
        if (s == SW__SG_SEC_META)
            ptr[s] = meta;
        else if (s == SWS_SEC_LODS) {
            ptr[s] = lods;
            bytes = count = lods_bytes;
        } else
            ptr[s] = sw__sg_view_section(v, s, &bytes, &count);
        off = align16(off);
        unsigned char *e = table + (size_t)s * SWS_ENTRY_SIZE;
        wr32(e, (uint32_t)s);
        wr64(e + 8, off);
        wr64(e + 16, bytes);
        wr64(e + 24, count);
        wr32(e + 32, sw__crc32c(0, ptr[s], bytes));
        off += bytes;
    }
    *file_size = off;
    memcpy(head, SWS_MAGIC, 8);
    wr32(head + 8, SWS_VERSION);
    wr32(head + 16, n_sec);
    wr32(head + 20, SWS_HEADER_SIZE);
    wr64(head + 24, off);
    wr64(head + 32, SWS_HEADER_SIZE);
    wr32(head + 40, SWS_ENTRY_SIZE);
    uint32_t crc = sw__crc32c(0, head, SWS_HEADER_CRC_AT);
    crc = sw__crc32c(crc, table, (size_t)n_sec * SWS_ENTRY_SIZE);
    wr32(head + SWS_HEADER_CRC_AT, crc);
}

/* Writes the sections in table order with zero padding up to each 16-byte boundary. */
static sw_result write_body(sw__out *out, const unsigned char *head, uint64_t head_bytes,
                            uint32_t n_sec, const void *const ptr[SWS_MAX_SECTIONS],
                            sw_status *status)
{
    static const unsigned char zeros[SWS_ALIGN];
    sw_result r = sw__out_write(out, head, (size_t)head_bytes, status);
    uint64_t pos = head_bytes;
    for (int s = 0; s < (int)n_sec && r == SW_OK; s++) {
        const unsigned char *e = head + SWS_HEADER_SIZE + (size_t)s * SWS_ENTRY_SIZE;
        uint64_t off = rd64(e + 8), bytes = rd64(e + 16);
        r = sw__out_write(out, zeros, (size_t)(off - pos), status);
        if (r == SW_OK)
            r = sw__out_write(out, ptr[s], (size_t)bytes, status);
        pos = off + bytes;
    }
    return r;
}

/* Hands the whole pages of [p, p + n) of a mapped scene back to the kernel: a read-only
 * private file mapping reads them from the file again if they are touched again. */
static void release_pages(const sw_sg_scene *scene, const unsigned char *p, size_t n)
{
    if (!scene->map || scene->map_on_heap || n == 0)
        return;
    const long ps = sysconf(_SC_PAGESIZE);
    const uintptr_t page = ps > 0 ? (uintptr_t)ps : 4096u;
    const uintptr_t a = ((uintptr_t)p + page - 1) & ~(page - 1);
    const uintptr_t b = ((uintptr_t)p + n) & ~(page - 1);
    if (b > a)
        (void)madvise((void *)a, b - a, MADV_DONTNEED); /* advice: a failure only keeps them */
}

void sw_sg_scene_lods_release(const sw_sg_scene *scene)
{
    const sw__sg_section_info *e = &scene->sec[SWS_SEC_LODS];
    if (scene->map && e->size)
        release_pages(scene, (const unsigned char *)scene->map + e->offset, (size_t)e->size);
}

sw_result sw_sg_scene_lods(const sw_sg_scene *scene, const void **data, size_t *size,
                           sw_status *status)
{
    *data = NULL;
    *size = 0;
    const sw__sg_section_info *e = &scene->sec[SWS_SEC_LODS];
    if (!scene->map || e->size == 0)
        return sw__fail(status, SW_ERR_NOT_FOUND, "%s: no LODS section", scene->path);
    const unsigned char *p = (const unsigned char *)scene->map + e->offset;
    /* in steps whose pages are handed back behind the sum: a cache of a million surfaces is
     * hundreds of MiB that its reader decodes into memory of its own right after */
    enum { STEP = 16u << 20 };
    uint32_t crc = 0;
    for (uint64_t at = 0; at < e->size; at += STEP) {
        const size_t n = (size_t)(e->size - at < STEP ? e->size - at : STEP);
        crc = sw__crc32c(crc, p + at, n);
        release_pages(scene, p + at, n);
    }
    if (crc != e->checksum)
        return sw__fail(status, SW_ERR_CHECKSUM,
                        "%s: section LODS at offset %llu: checksum mismatch (stored 0x%08x, "
                        "computed 0x%08x)",
                        scene->path, (unsigned long long)e->offset, e->checksum, crc);
    *data = p;
    *size = (size_t)e->size;
    sw__status_ok(status);
    return SW_OK;
}

sw_result sw_sg_scene_save(sw_sg_scene *scene, const char *path, sw_status *status)
{
    const void *lods = NULL;
    size_t lods_size = 0;
    if (scene->map && scene->sec[SWS_SEC_LODS].size) {
        sw_result r = sw_sg_scene_lods(scene, &lods, &lods_size, status);
        if (r != SW_OK)
            return r; /* a corrupt LODS section is not rewritten with a fresh checksum either */
    }
    return sw_sg_scene_save_lods(scene, path, lods, lods_size, status);
}

sw_result sw_sg_scene_save_lods(sw_sg_scene *scene, const char *path, const void *lods,
                                size_t lods_size, sw_status *status)
{
    /* A mapped scene is verified first: a corrupted section must not be rewritten with a fresh,
     * matching checksum. */
    sw_result r = sw_sg_scene_require(scene, SW_SG_SEC_ALL, status);
    if (r != SW_OK)
        return r;
    const uint32_t n_sec = scene->view.n_shapes   ? SWS_MAX_SECTIONS
                           : scene->view.n_meshes ? SWS_MESH_SECTIONS
                           : lods && lods_size    ? SWS_LODS_SECTIONS
                                                  : SWS_CORE_SECTIONS;
    enum { HEAD = SWS_HEADER_SIZE + SWS_MAX_SECTIONS * SWS_ENTRY_SIZE };
    const uint64_t head_bytes = SWS_HEADER_SIZE + (uint64_t)n_sec * SWS_ENTRY_SIZE;
    unsigned char head[HEAD], meta[16];
    const void *ptr[SWS_MAX_SECTIONS];
    uint64_t file_size;
    build_header(&scene->view, n_sec, lods, lods ? lods_size : 0, ptr, meta, head, head_bytes,
                 &file_size);

    sw__out out;
    r = sw__out_open(&out, path, 0, status);
    if (r != SW_OK)
        return r;
    r = write_body(&out, head, head_bytes, n_sec, ptr, status);
    if (r != SW_OK) {
        sw__out_abandon(&out);
        return r;
    }
    r = sw__out_commit(&out, status);
    if (r == SW_OK)
        sw__status_ok(status);
    return r;
}
