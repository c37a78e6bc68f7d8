/* SPDX-License-Identifier: MIT */
/* The scene object shared by scene.c (builder, accessors, traversal), scene_validate.c and
 * sws_file.c (mapped scenes). Internal to scenegraph/, never installed. */
#ifndef SW_SG_SCENE_INTERNAL_H
#define SW_SG_SCENE_INTERNAL_H

#include "sw_sg_scene.h"

#include <stddef.h>
#include <stdint.h>

/* Sections in .sws order (the index is the file's section id); index i is bit (1 << i) of
 * sw_sg_section. META and LODS are no arrays of the view and have no bit: META is read at open,
 * LODS is an opaque cache (sws_file.c). */
enum {
    SW__SG_SEC_FACES,
    SW__SG_SEC_LOOPS,
    SW__SG_SEC_CURVES,
    SW__SG_SEC_NODES,
    SW__SG_SEC_ADJACENCY,
    SW__SG_SEC_POOL,
    SW__SG_SEC_STRINGS,
    SW__SG_SEC_META,
    SW__SG_SEC_LODS,
    SW__SG_SEC_MESHES,
    SW__SG_SEC_INDICES,
    SW__SG_SEC_SHAPES,
    SW__SG_SEC_COUNT
};

/* Whether section s is one of the view's arrays (all but META and LODS). */
static inline int sw__sg_is_array_section(int s)
{
    return s != SW__SG_SEC_META && s != SW__SG_SEC_LODS;
}

/* Names and record sizes of the sections, indexed as above. */
extern const char *const sw__sg_section_names[SW__SG_SEC_COUNT];
extern const uint32_t sw__sg_section_record_size[SW__SG_SEC_COUNT];

typedef struct sw__sg_section_info {
    uint64_t offset, size, count;
    uint32_t checksum;
} sw__sg_section_info;

struct sw_sg_scene {
    sw_sg_scene_view view;
    char *path;                    /* "" for a scene built in memory; always owned */
    void *owned[SW__SG_SEC_COUNT]; /* in-memory arrays (malloc), NULL when mapped */
    size_t owned_bytes;
    void *map; /* mapped file (or a heap copy of one: map_on_heap), NULL in memory */
    size_t map_size;
    int map_on_heap; /* map is sw__malloc'd (sw_sg_scene_open_bytes), not mmap'd */
    sw__sg_section_info sec[SW__SG_SEC_COUNT]; /* mapped only; sec[SW__SG_SEC_LODS] is the
                                                  optional LODS section (size 0: none) */
    uint32_t verified;         /* sections whose checksum matched (sw_sg_section bits) */
    int validated;             /* 1 once sw_sg_scene_validate passed, -1 once it failed */
    sw_status validate_status; /* the failure, repeated to later callers */
    uint64_t serial;           /* sw_sg_scene_serial */
};

/* The next scene serial (thread-safe). */
uint64_t sw__sg_next_serial(void);

/* sw_sg_scene_validate with byte offsets of each record in the messages: when `sec` is not NULL,
 * record i of section s is reported at sec[s].offset + i * record size. */
sw_result sw__sg_scene_validate_at(const sw_sg_scene_view *view, const char *what,
                                   const sw__sg_section_info *sec, sw_status *status);

/* Pointer and byte size of array section s of a view (sw__sg_is_array_section). */
const void *sw__sg_view_section(const sw_sg_scene_view *view, int s, uint64_t *bytes,
                                uint64_t *count);

#endif
