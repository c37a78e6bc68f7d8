/* SPDX-License-Identifier: MIT */
/* The project's one writer and its guarded inputs (scenegraph/
 * sw_safe_write.h, sw_safe_read.h), format by format.
 *
 * Full disk, simulated: the writer's failure-injection hook makes the k-th write(2) fail with
 * ENOSPC, for every k a clean write of that format makes, and then the fsync; each time the call
 * must return an error, the pre-existing target must be byte-identical and no temporary may be
 * left (catches: a writer that ignores a failed write or fsync, renames a partial temporary over
 * the target — the 0-byte old.png — or forgets to remove its temporary). The formats:
 * PNG, EXR, .sws, LOD cache (the .sws LODS section), camera path, BREP, and profile reports
 * (a whole `splinewalk profile` run, in process).
 * Full disk, real: a 64 KiB tmpfs filled to ENOSPC, where mount(2) is permitted (root with
 * CAP_SYS_ADMIN); else the test says it skipped.
 * Short writes: the hook writes at most 1000 bytes per call; the file must still be complete
 * (catches: a writer that takes a short write for the whole).
 * Targets: /dev/null written in place and still a character device; a symbolic link written
 * through and still a link (also a dangling one); a directory refused with
 * SW_ERR_NOT_REGULAR_FILE; a dead writer's NAME.tmp-PID removed by the next write and a live
 * one's kept.
 * Inputs: a FIFO, a directory and a character device refused without blocking, each with
 * SW_ERR_NOT_REGULAR_FILE, by the .sws, camera-path, .tsm and CAD readers; a sparse 2 GiB .tsm and
 * a 65 MiB camera path refused by size before they are read (SW_ERR_LIMIT, well under a second);
 * an image name without an extension says so.
 * Reproducible EXR: with SOURCE_DATE_EPOCH set, two writes of one image a second apart give the
 * same bytes and carry that date (catches: the encoder's capture date taken from the clock,
 * which made the short-write comparison above fail whenever the second changed between its two
 * writes); with it malformed, the real date stays.
 * usage: test_io WORKDIR */
#define _GNU_SOURCE
#include <splinewalk/sw_image.h>
#include "cli.h"
#include "sw_camera_path.h"
#include "sw_gpu.h"
#include "sw_safe_read.h"
#include "sw_safe_write.h"
#include "sw_sg_export.h"
#include "sw_sg_import.h"
#include "sw_sg_tspline.h"
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wunused-variable"
#include "sws_test_scene.h"
#pragma GCC diagnostic pop
#include "test_check.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static char g_dir[1024];

/* ---- the failure-injection hooks ------------------------------------------------------------ */
static long g_writes;       /* write(2) calls through the hook since the last reset */
static long g_fail_at = -1; /* the index of the call that fails with ENOSPC; -1: none */
static int g_fail_fsync;
static size_t g_short; /* nonzero: at most this many bytes per call */

static ssize_t hook_write(int fd, const void *data, size_t n)
{
    if (g_writes++ == g_fail_at) {
        errno = ENOSPC;
        return -1;
    }
    return write(fd, data, g_short && n > g_short ? g_short : n);
}

static int hook_fsync(int fd)
{
    if (g_fail_fsync) {
        errno = ENOSPC;
        return -1;
    }
    return fsync(fd);
}

static void hooks_reset(void)
{
    g_writes = 0;
    g_fail_at = -1;
    g_fail_fsync = 0;
    g_short = 0;
}

/* ---- files ---------------------------------------------------------------------------------- */
static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static unsigned char *read_all(const char *path, size_t *n)
{
    *n = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    unsigned char *buf = NULL;
    size_t cap = 0;
    for (;;) {
        if (*n == cap) {
            cap = cap ? cap * 2 : 4096;
            buf = realloc(buf, cap);
        }
        size_t got = fread(buf + *n, 1, cap - *n, f);
        *n += got;
        if (!got)
            break;
    }
    fclose(f);
    return buf;
}

static void write_bytes(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (f) {
        fwrite(data, 1, n, f);
        fclose(f);
    }
}

static int same_bytes(const char *path, const void *data, size_t n)
{
    size_t m;
    unsigned char *d = read_all(path, &m);
    const int same = d && m == n && !memcmp(d, data, n);
    free(d);
    return same;
}

/* Entries of `dir` that are temporaries: NAME.tmp-PID or a profile's .profile-XXXXXX. */
static int count_temps(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    const struct dirent *e;
    while (d && (e = readdir(d)))
        n += strstr(e->d_name, ".tmp-") != NULL || !strncmp(e->d_name, ".profile-", 9);
    if (d)
        closedir(d);
    return n;
}

static void path_in(char *out, size_t size, const char *name)
{
    snprintf(out, size, "%s/%s", g_dir, name);
}

/* ---- the formats ---------------------------------------------------------------------------- */
static sw_sg_scene *g_scene;
static sw_gpu_image g_img;
static sw_rt_camera_path g_path;
static char g_scene_file[1100], g_path_file[1100];

static sw_result write_png(const char *path, sw_status *st)
{
    return sw_gpu_image_write(&g_img, path, st);
}

static sw_result write_exr(const char *path, sw_status *st)
{
    return sw_gpu_image_write(&g_img, path, st); /* with depth: the Z channel too */
}

static sw_result write_sws(const char *path, sw_status *st)
{
    return sw_sg_scene_save(g_scene, path, st);
}

static sw_result write_lods(const char *path, sw_status *st)
{
    static unsigned char blob[3000];
    for (size_t i = 0; i < sizeof blob; i++)
        blob[i] = (unsigned char)(i * 7);
    return sw_sg_scene_save_lods(g_scene, path, blob, sizeof blob, st);
}

static sw_result write_path(const char *path, sw_status *st)
{
    return sw_rt_path_save(&g_path, path, 0, st);
}

static sw_sg_scene *g_plain; /* the test scene's faces without its scaled transforms (BREP) */

static sw_result write_brep(const char *path, sw_status *st)
{
    return sw_sg_export_brep(g_plain, path, NULL, st);
}

/* A whole profile run into the directory `path`; its profile.csv is the target. */
static sw_result write_profile(const char *path, sw_status *st)
{
    char *argv[] = {"profile",  g_scene_file, "--path", g_path_file, "--out",        (char *)path,
                    "--frames", "3",          "--size", "48x32",     "--sequential", NULL};
    fflush(stdout);
    /* its summary goes to stdout: keep the test's log short */
    const int saved = dup(STDOUT_FILENO), null = open("/dev/null", O_WRONLY);
    dup2(null, STDOUT_FILENO);
    const int rc = sw_cli_profile((int)(sizeof argv / sizeof argv[0]) - 1, argv);
    fflush(stdout);
    dup2(saved, STDOUT_FILENO);
    close(saved);
    close(null);
    if (rc == 0)
        return SW_OK;
    st->result = SW_ERR_IO;
    snprintf(st->message, sizeof st->message, "profile exit status %d", rc);
    return SW_ERR_IO;
}

typedef struct format {
    const char *name, *file; /* file: the target's name in g_dir */
    sw_result (*write)(const char *path, sw_status *st);
    int is_dir; /* the target is DIR/profile.csv of the directory written */
} format;

static const format k_formats[] = {
    {"PNG", "old.png", write_png, 0},          {"EXR", "old.exr", write_exr, 0},
    {".sws", "old.sws", write_sws, 0},         {"LOD cache", "lods.sws", write_lods, 0},
    {".path", "old.path", write_path, 0},      {"BREP", "old.brep", write_brep, 0},
    {"profile CSV", "prof", write_profile, 1},
};

/* Every write of a clean run failing in turn, then the fsync: error, old bytes, no temporary.
 * named: the temporaries are NAME.tmp-PID from the start (no O_TMPFILE). */
static void full_disk_simulated(const format *f, int named)
{
    sw__out_no_tmpfile = named;
    const double t0 = now_s();
    char target[1200], file[1300], dir[1200];
    path_in(target, sizeof target, f->file);
    snprintf(file, sizeof file, f->is_dir ? "%s/profile.csv" : "%s", target);
    snprintf(dir, sizeof dir, "%s", f->is_dir ? target : g_dir);
    if (f->is_dir)
        mkdir(target, 0777);
    sw_status st = {0};
    /* a clean run in short writes must give the same file as one in whole writes; the second
     * counts the writes to fail in turn */
    hooks_reset();
    g_short = 1000;
    sw_result r = f->write(target, &st);
    CHECK(r == SW_OK, "%s: clean write in short writes: %s", f->name, st.message);
    size_t short_n, clean_n;
    unsigned char *in_short = read_all(file, &short_n);
    hooks_reset();
    r = f->write(target, &st);
    CHECK(r == SW_OK, "%s: clean write: %s", f->name, st.message);
    const long writes = g_writes;
    CHECK(writes > 0, "%s: no write went through the writer", f->name);
    unsigned char *clean = read_all(file, &clean_n);
    CHECK(clean && clean_n > 0, "%s: the clean write left no file", f->name);
    CHECK(f->is_dir || (in_short && short_n == clean_n && !memcmp(in_short, clean, clean_n)),
          "%s: written in short writes, %zu bytes instead of %zu or other bytes", f->name, short_n,
          clean_n);
    free(clean);
    free(in_short);

    const char old[] = "the previous contents, which a failed write must keep\n";
    int failures = 0;
    for (long k = 0; k <= writes; k++) {
        write_bytes(file, old, sizeof old);
        hooks_reset();
        if (k < writes)
            g_fail_at = k;
        else
            g_fail_fsync = 1;
        memset(&st, 0, sizeof st);
        r = f->write(target, &st);
        const int bad = r == SW_OK || !same_bytes(file, old, sizeof old) || count_temps(dir);
        failures += bad;
        CHECK(!bad, "%s: %s %ld of %ld failing: result %s, old bytes kept %d, %d temporaries (%s)",
              f->name, k < writes ? "write" : "fsync", k, writes, sw_result_id_str(r),
              same_bytes(file, old, sizeof old), count_temps(dir), st.message);
        CHECK(f->is_dir || r != SW_OK || strstr(st.message, "No space left"),
              "%s: the message does not say the disk is full: %s", f->name, st.message);
    }
    if (f->is_dir) {
        /* a killed run's staging folder is removed by the next run (catches: folders that pile
         * up in DIR) */
        const pid_t child = fork();
        if (child == 0)
            _exit(0);
        waitpid(child, NULL, 0);
        char stale[1400], staged[1500];
        snprintf(stale, sizeof stale, "%s/.profile-%ld-AbCdEf", target, (long)child);
        mkdir(stale, 0777);
        snprintf(staged, sizeof staged, "%s/profile.csv", stale);
        write_bytes(staged, "partial", 7);
        hooks_reset();
        CHECK(f->write(target, &st) == SW_OK, "%s: %s", f->name, st.message);
        CHECK(access(stale, F_OK) != 0, "%s: a killed run's staging folder was left", f->name);
    }
    hooks_reset();
    sw__out_no_tmpfile = 0;
    printf("%-12s %3ld writes, each failing in turn, then the fsync (%s): %d lost or left "
           "behind (%.2f s)\n",
           f->name, writes, named ? "NAME.tmp-PID" : "O_TMPFILE", failures, now_s() - t0);
}

/* A real full file system: a 64 KiB tmpfs filled to ENOSPC (root with CAP_SYS_ADMIN only). */
static void full_disk_real(void)
{
    char mnt[1200];
    path_in(mnt, sizeof mnt, "tmpfs");
    mkdir(mnt, 0777);
    if (mount("tmpfs", mnt, "tmpfs", 0, "size=64k") != 0) {
        printf("real full disk: skipped, mount(tmpfs) failed: %s (needs root with "
               "CAP_SYS_ADMIN)\n",
               strerror(errno));
        rmdir(mnt);
        return;
    }
    const char old[] = "old contents\n";
    char filler[1300];
    snprintf(filler, sizeof filler, "%s/filler", mnt);
    int fd = open(filler, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    static const unsigned char block[4096];
    for (int i = 0; i < 64; i++)
        if (write(fd, block, sizeof block) < 0)
            break;
    /* the targets first, then fill the last bytes */
    int failures = 0;
    char targets[6][1300];
    for (size_t i = 0; i < 6; i++) {
        snprintf(targets[i], sizeof targets[i], "%s/%s", mnt, k_formats[i].file);
    }
    close(fd);
    unlink(filler);
    for (size_t i = 0; i < 6; i++)
        write_bytes(targets[i], old, sizeof old);
    fd = open(filler, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    while (write(fd, block, 1) == 1)
        ;
    close(fd);
    for (size_t i = 0; i < 6; i++) {
        sw_status st = {0};
        sw_result r = k_formats[i].write(targets[i], &st);
        const int bad = r == SW_OK || !same_bytes(targets[i], old, sizeof old) || count_temps(mnt);
        failures += bad;
        CHECK(!bad, "real full disk: %s: result %s (%s), %d temporaries", k_formats[i].name,
              sw_result_id_str(r), st.message, count_temps(mnt));
    }
    printf("real full disk (64 KiB tmpfs, filled): 6 formats, %d lost or left behind\n", failures);
    umount(mnt);
    rmdir(mnt);
}

/* ---- targets -------------------------------------------------------------------------------- */
static void targets(void)
{
    sw_status st = {0};
    /* /dev/null: written in place, still a character device (root turned it into a
     * regular file) */
    CHECK(write_sws("/dev/null", &st) == SW_OK, "/dev/null: %s", st.message);
    CHECK(write_path("/dev/null", &st) == SW_OK, "/dev/null: %s", st.message);
    struct stat sb;
    CHECK(stat("/dev/null", &sb) == 0 && S_ISCHR(sb.st_mode), "/dev/null is no longer a device");

    /* a symbolic link: the file it names is replaced, the link stays */
    char real[1200], link[1200], dangling[1200], sub[1200];
    path_in(real, sizeof real, "real.path");
    path_in(link, sizeof link, "link.path");
    write_bytes(real, "x", 1);
    CHECK(symlink("real.path", link) == 0, "symlink: %s", strerror(errno));
    CHECK(write_path(link, &st) == SW_OK, "through a link: %s", st.message);
    CHECK(lstat(link, &sb) == 0 && S_ISLNK(sb.st_mode), "the link was replaced by a file");
    sw_rt_camera_path back;
    CHECK(sw_rt_path_load(real, &back, &st) == SW_OK && back.n_keys == g_path.n_keys,
          "the link's file was not written: %s", st.message);
    sw_rt_path_free(&back);
    /* a dangling link: its file is created */
    path_in(dangling, sizeof dangling, "dangling.path");
    CHECK(symlink("made-through-link.path", dangling) == 0, "symlink: %s", strerror(errno));
    CHECK(write_path(dangling, &st) == SW_OK, "through a dangling link: %s", st.message);
    path_in(real, sizeof real, "made-through-link.path");
    CHECK(lstat(dangling, &sb) == 0 && S_ISLNK(sb.st_mode) && stat(real, &sb) == 0,
          "a dangling link was not written through");

    /* a directory: refused with its own id, naming the path */
    path_in(sub, sizeof sub, "a-directory.sws");
    mkdir(sub, 0777);
    CHECK(write_sws(sub, &st) == SW_ERR_NOT_REGULAR_FILE && strstr(st.message, sub) &&
              strstr(st.message, "is a directory"),
          "directory target: %s: %s", sw_result_id_str(st.result), st.message);
    CHECK(write_png("/dev/null/x.png", &st) != SW_OK, "a path under a device accepted");

    /* a dead writer's temporary is removed by the next write, a live one's is kept */
    const pid_t child = fork();
    if (child == 0)
        _exit(0);
    waitpid(child, NULL, 0);
    char target[1200], dead[1300], live[1300];
    path_in(target, sizeof target, "stale.sws");
    snprintf(dead, sizeof dead, "%s.tmp-%ld", target, (long)child);
    snprintf(live, sizeof live, "%s.tmp-%ld", target, (long)getppid());
    write_bytes(dead, "dead", 4);
    write_bytes(live, "live", 4);
    CHECK(write_sws(target, &st) == SW_OK, "stale: %s", st.message);
    CHECK(access(dead, F_OK) != 0, "a dead writer's temporary was left");
    CHECK(access(live, F_OK) == 0, "a live writer's temporary was removed");
    unlink(live);
    printf("targets: /dev/null, symbolic links, a directory, stale temporaries checked\n");
}

/* ---- inputs --------------------------------------------------------------------------------- */
static void expect_refusal(const char *what, sw_result r, const sw_status *st, sw_result want,
                           const char *says)
{
    CHECK(r == want && strstr(st->message, says), "%s: %s (%s), expected %s with '%s'", what,
          sw_result_id_str(r), st->message, sw_result_id_str(want), says);
}

static void inputs(void)
{
    /* every reader gets 10 s: a blocking open() is killed by the alarm and fails the test */
    alarm(10);
    char fifo[1200], dir[1200], big[1200], path[1200];
    path_in(fifo, sizeof fifo, "fifo.sws");
    path_in(dir, sizeof dir, "dir.step");
    mkfifo(fifo, 0666);
    mkdir(dir, 0777);
    sw_status st = {0};
    sw_sg_scene *s = NULL;
    expect_refusal(".sws FIFO", sw_sg_scene_open(fifo, &s, &st), &st, SW_ERR_NOT_REGULAR_FILE,
                   "FIFO");
    expect_refusal(".sws directory", sw_sg_scene_open(g_dir, &s, &st), &st, SW_ERR_NOT_REGULAR_FILE,
                   "is a directory");
    expect_refusal(".sws device", sw_sg_scene_open("/dev/zero", &s, &st), &st,
                   SW_ERR_NOT_REGULAR_FILE, "character device");
    sw_rt_camera_path p;
    expect_refusal("path FIFO", sw_rt_path_load(fifo, &p, &st), &st, SW_ERR_NOT_REGULAR_FILE,
                   "FIFO");
    expect_refusal("path device", sw_rt_path_load("/dev/zero", &p, &st), &st,
                   SW_ERR_NOT_REGULAR_FILE, "character device");
    sw_sg_tspline *ts = NULL;
    expect_refusal(".tsm device", sw_sg_tspline_load("/dev/zero", &ts, &st), &st,
                   SW_ERR_NOT_REGULAR_FILE, "character device");
    expect_refusal(".tsm directory", sw_sg_tspline_load(g_dir, &ts, &st), &st,
                   SW_ERR_NOT_REGULAR_FILE, "is a directory");
    sw_sg_import_desc d = {dir, NULL, NULL, NULL, NULL, 0};
    expect_refusal("CAD directory", sw_sg_import_file(&d, &s, NULL, &st), &st,
                   SW_ERR_NOT_REGULAR_FILE, "is a directory");
    d.path = fifo;
    expect_refusal("CAD FIFO", sw_sg_import_file(&d, &s, NULL, &st), &st, SW_ERR_NOT_REGULAR_FILE,
                   "FIFO");
    path_in(path, sizeof path, "none.step");
    d.path = path;
    expect_refusal("CAD missing", sw_sg_import_file(&d, &s, NULL, &st), &st, SW_ERR_NOT_FOUND,
                   "none.step");

    /* sizes refused before reading: sparse files read nothing */
    path_in(big, sizeof big, "big.tsm");
    int fd = open(big, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    CHECK(fd >= 0 && ftruncate(fd, (off_t)2 << 30) == 0, "sparse file: %s", strerror(errno));
    close(fd);
    double t0 = now_s();
    expect_refusal("sparse 2 GiB .tsm", sw_sg_tspline_load(big, &ts, &st), &st, SW_ERR_LIMIT,
                   "bytes");
    const double tsm_s = now_s() - t0;
    CHECK(tsm_s < 1.0, "the 2 GiB .tsm took %.2f s to refuse", tsm_s);
    unlink(big);
    path_in(big, sizeof big, "big.path");
    fd = open(big, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    CHECK(fd >= 0 && ftruncate(fd, (off_t)65 << 20) == 0, "sparse file: %s", strerror(errno));
    close(fd);
    t0 = now_s();
    expect_refusal("65 MiB camera path", sw_rt_path_load(big, &p, &st), &st, SW_ERR_LIMIT, "bytes");
    const double path_s = now_s() - t0;
    unlink(big);

    /* an image name without an extension */
    path_in(path, sizeof path, "frame");
    expect_refusal("image without extension", write_png(path, &st), &st, SW_ERR_UNSUPPORTED,
                   "no extension");
    alarm(0);
    printf("inputs: FIFO, directory and device refused without blocking; 2 GiB .tsm refused in "
           "%.4f s, 65 MiB path in %.4f s\n",
           tsm_s, path_s);
}

/* ---- setup ---------------------------------------------------------------------------------- */
static int setup(const char *work)
{
    char cmd[1200];
    /* a run that died with the tmpfs mounted must not make the next one fail */
    snprintf(cmd, sizeof cmd, "%s/tmpfs", work);
    (void)umount2(cmd, MNT_DETACH);
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s'", work, work);
    if (system(cmd) != 0)
        return -1;
    snprintf(g_dir, sizeof g_dir, "%s", work);
    sw_status st = {0};
    if (sw_sg_builder_finish(sws_test_builder(), &g_scene, &st) != SW_OK) {
        printf("test scene: %s\n", st.message);
        return -1;
    }
    sw_sg_builder *b = sw_sg_builder_create();
    sws_test_loops(b);
    sws_test_face(b, 5, 0.0, 0, 2, SW_SG_KIND_BSPLINE);
    sws_test_face(b, 4, 7.0, 0, 1, SW_SG_KIND_BEZIER);
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, 0, NULL, NULL, "face0");
    sw_sg_builder_add_node(b, SW_SG_NODE_SURFACE, 0, 1, NULL, NULL, "face1");
    if (sw_sg_builder_finish(b, &g_plain, &st) != SW_OK) {
        printf("plain scene: %s\n", st.message);
        return -1;
    }
    g_img.width = 64;
    g_img.height = 48;
    g_img.rgba = malloc(64 * 48 * 4);
    g_img.depth = malloc(64 * 48 * sizeof(float));
    for (int i = 0; i < 64 * 48; i++) {
        for (int c = 0; c < 4; c++)
            g_img.rgba[i * 4 + c] = (uint8_t)(i * (c + 3));
        g_img.depth[i] = (float)i;
    }
    const double box[6] = {-1, -1, -1, 1, 1, 1};
    if (sw_rt_path_orbit(box, 4.0, 3, &g_path, &st) != SW_OK) {
        printf("path: %s\n", st.message);
        return -1;
    }
    path_in(g_scene_file, sizeof g_scene_file, "scene.sws");
    path_in(g_path_file, sizeof g_path_file, "orbit.path");
    if (sw_sg_scene_save(g_scene, g_scene_file, &st) != SW_OK ||
        sw_rt_path_save(&g_path, g_path_file, 0, &st) != SW_OK) {
        printf("setup: %s\n", st.message);
        return -1;
    }
    sw__out_write_hook = hook_write;
    sw__out_fsync_hook = hook_fsync;
    return 0;
}

static void reproducible_exr(void)
{
    char first[1200], second[1200];
    path_in(first, sizeof first, "date-1.exr");
    path_in(second, sizeof second, "date-2.exr");
    sw_status st = {0};
    setenv("SOURCE_DATE_EPOCH", "1000000000", 1);
    CHECK(write_exr(first, &st) == SW_OK, "EXR with SOURCE_DATE_EPOCH: %s", st.message);
    nanosleep(&(struct timespec){1, 50000000}, NULL); /* the clock's second changes */
    CHECK(write_exr(second, &st) == SW_OK, "EXR with SOURCE_DATE_EPOCH: %s", st.message);
    size_t n1 = 0, n2 = 0;
    unsigned char *a = read_all(first, &n1), *b = read_all(second, &n2);
    CHECK(a && b && n1 == n2 && !memcmp(a, b, n1),
          "two EXR writes of one image a second apart differ with SOURCE_DATE_EPOCH set");
    static const char date[] = "2001:09:09 01:46:40"; /* 10^9 s after 1970, UTC */
    CHECK(a && memmem(a, n1, date, sizeof date - 1), "the EXR does not carry SOURCE_DATE_EPOCH");
    free(a);
    free(b);
    setenv("SOURCE_DATE_EPOCH", "12 o'clock", 1);
    CHECK(write_exr(first, &st) == SW_OK, "EXR with a malformed SOURCE_DATE_EPOCH: %s", st.message);
    a = read_all(first, &n1);
    CHECK(a && !memmem(a, n1, "1970:01:01", 10) && !memmem(a, n1, "0012:", 5),
          "a malformed SOURCE_DATE_EPOCH was taken for a date");
    free(a);
    setenv("SOURCE_DATE_EPOCH", "1000000000", 1);
    printf("reproducible EXR: same bytes a second apart with SOURCE_DATE_EPOCH\n");
}

int main(int argc, char **argv)
{
    (void)sw_image_install(); /* .exr frames */
    if (argc != 2) {
        fprintf(stderr, "usage: test_io WORKDIR\n");
        return 2;
    }
    setvbuf(stdout, NULL, _IOLBF, 0);
    /* the format checks compare two encodings of one image byte for byte */
    setenv("SOURCE_DATE_EPOCH", "1000000000", 1);
    if (setup(argv[1]) != 0)
        return 1;
    reproducible_exr();
    for (int named = 0; named < 2; named++)
        for (size_t i = 0; i < sizeof k_formats / sizeof k_formats[0]; i++)
            full_disk_simulated(&k_formats[i], named);
    full_disk_real();
    targets();
    inputs();
    sw__out_write_hook = NULL;
    sw__out_fsync_hook = NULL;
    sw_sg_scene_free(g_scene);
    sw_sg_scene_free(g_plain);
    sw_rt_path_free(&g_path);
    free(g_img.rgba);
    free(g_img.depth);
    printf("%s\n", g_failures ? "FAILED" : "all passed");
    return g_failures != 0;
}
