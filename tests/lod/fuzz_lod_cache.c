/* SPDX-License-Identifier: MIT */
/* libFuzzer harness for the LOD cache reader (lod/static/static_lod_io.c): the levels and the
 * cluster proxies of a .sws file's LODS section.
 *
 * A random byte string rarely gets past a cache's header (its key must match the scene's
 * super-surfaces, the proxies' key its instances), so each input is read two ways:
 *  - as it is, by the summary (`splinewalk info`: no scene needed);
 *  - as edits of a real cache — the scene's own, which SW_FUZZ_LOD_SCENE names (a .sws with a LOD
 *    cache holding proxies, from `splinewalk build-lod`): the input's first 4 bytes cut the cache
 *    (its length scaled by them, 0xffffffff: whole), then every 5 bytes flip a byte (u32 offset
 *    into the cache, u8 xor), half of them aimed into the proxies. The edited cache is summarized
 *    and loaded into the scene's static set.
 * Every read must end in SW_OK or a clear error (a message naming the cache), never a crash, a
 * leak or an unbounded allocation (ASan, UBSan, LeakSanitizer, libFuzzer's -rss_limit_mb). A
 * load that succeeds adopts into the one set the harness keeps (units already READY keep their
 * chains, proxies once adopted stay): later loads still parse everything before adopting.
 * Usage: SW_FUZZ_LOD_SCENE=CARPARK.sws fuzz_lod_cache [libFuzzer options] [CORPUS] */
#include "sw_lod_static_set.h"
#include "sw_sg_scene.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static sw_sg_scene *g_scene;
static sw_th_pool *g_pool;
static sw_lod_static_set *g_set;
static unsigned char *g_cache, *g_edit;
static size_t g_size, g_proxies_at;

static void fail(const char *what, const sw_status *st)
{
    fprintf(stderr, "fuzz_lod_cache: %s: %s\n", what, st ? st->message : "");
    abort();
}

/* Where the proxies start: the bytes a set without them writes, less its flag. */
static size_t proxies_offset(void)
{
    sw_lod_static_set_desc d = {.ignore_cached_proxies = 1};
    sw_lod_static_set *bare = NULL;
    sw_status st = {0};
    void *blob = NULL;
    size_t n = 0;
    if (sw_lod_static_set_create(g_scene, g_pool, &d, &bare, &st) != SW_OK ||
        sw_lod_static_set_load(bare, g_cache, g_size, "seed", NULL, &st) != SW_OK ||
        sw_lod_static_set_serialize(bare, &blob, &n, &st) != SW_OK)
        fail("the scene's own cache", &st);
    free(blob);
    sw_lod_static_set_destroy(bare);
    return n >= 4 && n <= g_size ? n - 4 : 0;
}

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    const char *path = getenv("SW_FUZZ_LOD_SCENE");
    sw_status st = {0};
    sw_th_pool_desc pd = {.worker_count = 1};
    const void *cache = NULL;
    if (!path)
        fail("SW_FUZZ_LOD_SCENE is not set (a .sws with a LOD cache)", NULL);
    if (sw_sg_scene_open(path, &g_scene, &st) != SW_OK ||
        sw_sg_scene_lods(g_scene, &cache, &g_size, &st) != SW_OK)
        fail(path, &st);
    if (sw_th_pool_create(&pd, &g_pool) != SW_OK)
        fail("pool", NULL);
    g_cache = malloc(g_size);
    g_edit = malloc(g_size);
    if (!g_cache || !g_edit)
        fail("out of memory", NULL);
    memcpy(g_cache, cache, g_size);
    if (sw_lod_static_set_create(g_scene, g_pool, NULL, &g_set, &st) != SW_OK)
        fail("set", &st);
    g_proxies_at = proxies_offset();
    return 0;
}

static void check_read(sw_result r, const sw_status *st, const char *what)
{
    if (r != SW_OK && (!st->message[0] || !strstr(st->message, what)))
        fail("an error that does not name the cache", st);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    sw_lod_static_cache_summary sum;
    sw_status st = {0};
    check_read(sw_lod_static_cache_summarize(data, size, "input", &sum, &st), &st, "input");
    if (size < 4)
        return 0;
    uint32_t cut;
    memcpy(&cut, data, 4);
    const size_t n =
        cut == UINT32_MAX ? g_size : (size_t)((double)cut / 4294967296.0 * (double)g_size);
    memcpy(g_edit, g_cache, g_size);
    for (size_t at = 4, k = 0; at + 5 <= size; at += 5, ++k) {
        uint32_t off;
        memcpy(&off, data + at, 4);
        const size_t span = k % 2 ? g_size - g_proxies_at : g_size;
        const size_t base = k % 2 ? g_proxies_at : 0;
        if (span)
            g_edit[base + off % span] ^= data[at + 4];
    }
    check_read(sw_lod_static_cache_summarize(g_edit, n, "edited", &sum, &st), &st, "edited");
    check_read(sw_lod_static_set_load(g_set, g_edit, n, "edited", NULL, &st), &st, "edited");
    return 0;
}
