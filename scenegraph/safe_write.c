/* SPDX-License-Identifier: MIT */
/* Output files that are replaced whole or not at all (sw_safe_write.h). */
#define _GNU_SOURCE /* O_TMPFILE, linkat's AT_SYMLINK_FOLLOW */
#include "sw_safe_write.h"

#include "sw_hooks.h"
#include "sw_status_util.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

ssize_t (*sw__out_write_hook)(int fd, const void *data, size_t n);
int (*sw__out_fsync_hook)(int fd);
int sw__out_no_tmpfile;

enum {
    KIND_TMPFILE = 1, /* unnamed O_TMPFILE in the target's directory, linked at commit */
    KIND_NAMED,       /* NAME.tmp-PID from the start */
    KIND_DIRECT,      /* a character device or FIFO, written in place */
    KIND_STDOUT,      /* "-": file descriptor 1, not closed */
};

static ssize_t do_write(int fd, const void *data, size_t n)
{
    return sw__out_write_hook ? sw__out_write_hook(fd, data, n) : write(fd, data, n);
}

static int do_fsync(int fd)
{
    return sw__out_fsync_hook ? sw__out_fsync_hook(fd) : fsync(fd);
}

static char *dup_str(const char *s)
{
    char *d = sw__strdup(s);
    if (!d)
        errno = ENOMEM; /* the callers tell an allocation failure by errno */
    return d;
}

static char *join(const char *dir, size_t dir_len, const char *name)
{
    const size_t n = strlen(name);
    char *p = sw__malloc(dir_len + 1 + n + 1);
    if (!p) {
        errno = ENOMEM;
        return NULL;
    }
    memcpy(p, dir, dir_len);
    p[dir_len] = '/';
    memcpy(p + dir_len + 1, name, n + 1);
    return p;
}

/* The directory part of `path` ("." when it has none) into a fresh string. */
static char *dir_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        return dup_str(".");
    const size_t n = slash == path ? 1 : (size_t)(slash - path);
    char *d = sw__malloc(n + 1);
    if (d) {
        memcpy(d, path, n);
        d[n] = '\0';
    }
    return d;
}

static const char *base_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

/* The file a write to `path` replaces: `path` itself unless it is a symbolic link, else what the
 * link chain ends at (which may not exist yet: a dangling link is written through too). NULL with
 * errno set on failure. */
static char *resolve_target(const char *path)
{
    struct stat ls;
    if (lstat(path, &ls) != 0 || !S_ISLNK(ls.st_mode))
        return dup_str(path);
    char *real = realpath(path, NULL);
    if (real) {
        char *r = dup_str(real);
        free(real); /* libc's */
        return r;
    }
    if (errno != ENOENT)
        return NULL;
    /* dangling: follow the chain by hand, at most as far as the kernel would (ELOOP) */
    char *p = dup_str(path);
    for (int hops = 0; p && hops < 40; hops++) {
        if (lstat(p, &ls) != 0 || !S_ISLNK(ls.st_mode))
            return p;
        char link[PATH_MAX];
        const ssize_t n = readlink(p, link, sizeof link - 1);
        if (n < 0) {
            sw__free(p);
            return NULL;
        }
        link[n] = '\0';
        char *next;
        if (link[0] == '/') {
            next = dup_str(link);
        } else {
            const char *slash = strrchr(p, '/');
            next = slash ? join(p, (size_t)(slash - p), link) : dup_str(link);
        }
        sw__free(p);
        p = next;
    }
    sw__free(p);
    errno = p ? ELOOP : ENOMEM;
    return NULL;
}

/* Whether `name` is BASE.tmp-PID or BASE.tmp-PID.N of a process that no longer exists. */
static int is_stale_temp(const char *name, const char *base, size_t base_len)
{
    if (strncmp(name, base, base_len) != 0 || strncmp(name + base_len, ".tmp-", 5) != 0)
        return 0;
    const char *d = name + base_len + 5;
    char *end;
    errno = 0;
    const long pid = strtol(d, &end, 10);
    if (end == d || (*end && *end != '.') || errno || pid <= 0 || pid == (long)getpid())
        return 0;
    if (*end == '.') {
        for (const char *q = end + 1; *q; q++)
            if (*q < '0' || *q > '9')
                return 0;
    }
    return kill((pid_t)pid, 0) != 0 && errno == ESRCH;
}

/* Removes the temporaries that writers of `target` left when they were killed. */
static void remove_stale_temps(const char *dir, const char *base)
{
    DIR *d = opendir(dir);
    if (!d)
        return;
    const size_t base_len = strlen(base);
    const struct dirent *e;
    while ((e = readdir(d)) != NULL)
        if (is_stale_temp(e->d_name, base, base_len))
            unlinkat(dirfd(d), e->d_name, 0);
    closedir(d);
}

/* BASE.tmp-PID, or BASE.tmp-PID.N for the n-th retry (another thread of this process). */
static char *temp_name(const char *target, int n)
{
    char suffix[48];
    if (n == 0)
        snprintf(suffix, sizeof suffix, ".tmp-%ld", (long)getpid());
    else
        snprintf(suffix, sizeof suffix, ".tmp-%ld.%d", (long)getpid(), n);
    const size_t t = strlen(target), s = strlen(suffix);
    char *p = sw__malloc(t + s + 1);
    if (p) {
        memcpy(p, target, t);
        memcpy(p + t, suffix, s + 1);
    }
    return p;
}

static int have_proc_fd(void)
{
    return access("/proc/self/fd", X_OK) == 0;
}

static const char *kind_str(mode_t m)
{
    return S_ISDIR(m)    ? "is a directory"
           : S_ISBLK(m)  ? "is a block device"
           : S_ISSOCK(m) ? "is a socket"
                         : "is not a regular file";
}

static void release(sw__out *out)
{
    sw__free(out->target);
    sw__free(out->tmp);
    sw__free(out->shown);
    out->target = out->tmp = out->shown = NULL;
    out->fd = -1;
    out->kind = 0;
}

static sw_result open_direct(sw__out *out, const char *path, unsigned flags, sw_status *status)
{
    if (flags & SW__OUT_DASH_STDOUT && !strcmp(path, "-")) {
        fflush(stdout); /* what stdio printed comes first */
        out->fd = STDOUT_FILENO;
        out->kind = KIND_STDOUT;
        return SW_OK;
    }
    /* A FIFO without a reader blocks here, as `cat > fifo` does: the caller named it. */
    out->fd = open(path, O_WRONLY | O_CLOEXEC | O_NOCTTY);
    if (out->fd < 0)
        return sw__fail(status, SW_ERR_IO, "%s: cannot open for writing: %s", path,
                        strerror(errno));
    out->kind = KIND_DIRECT;
    return SW_OK;
}

/* Creates the temporary of a regular-file target (existing with `st`, or not: st NULL). */
static sw_result open_temp(sw__out *out, const struct stat *st, sw_status *status)
{
    char *dir = dir_of(out->target);
    if (!dir)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", out->shown);
    remove_stale_temps(dir, base_of(out->target));
    const mode_t mode = st ? (st->st_mode & 07777) : 0666;
    out->fd = -1;
    if (!sw__out_no_tmpfile && have_proc_fd()) {
        out->fd = open(dir, O_TMPFILE | O_WRONLY | O_CLOEXEC, mode);
        if (out->fd >= 0)
            out->kind = KIND_TMPFILE;
    }
    for (int n = 0; out->fd < 0 && n < 100; n++) {
        sw__free(out->tmp);
        out->tmp = temp_name(out->target, n);
        if (!out->tmp)
            break;
        out->fd = open(out->tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, mode);
        if (out->fd >= 0)
            out->kind = KIND_NAMED;
        else if (errno != EEXIST)
            break;
    }
    const int err = errno;
    sw_result r = SW_OK;
    if (out->fd < 0) {
        sw__free(out->tmp);
        out->tmp = NULL;
        r = err == ENOMEM ? sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", out->shown)
            : err == ENOENT || err == ENOTDIR
                ? sw__fail(status, SW_ERR_NOT_FOUND, "%s: directory %s does not exist", out->shown,
                           dir)
                : sw__fail(status, SW_ERR_IO, "%s: cannot create a file in %s: %s", out->shown, dir,
                           strerror(err));
    } else if (st) {
        /* the replacement keeps the old file's permissions (umask applied to a new file only) */
        (void)fchmod(out->fd, st->st_mode & 07777);
    }
    sw__free(dir);
    return r;
}

enum { TARGET_STDOUT = 1, TARGET_STREAM, TARGET_FILE };

/* What a write to `path` would do (*kind: TARGET_*), or why it is refused. *st is filled for an
 * existing target, *exists says whether there is one. */
static sw_result classify(const char *path, unsigned flags, int *kind, struct stat *st, int *exists,
                          sw_status *status)
{
    *exists = 0;
    *kind = TARGET_FILE;
    if (flags & SW__OUT_DASH_STDOUT && !strcmp(path, "-")) {
        *kind = TARGET_STDOUT;
        return SW_OK;
    }
    if (stat(path, st) == 0) { /* follows symbolic links */
        *exists = 1;
        if (S_ISCHR(st->st_mode) || S_ISFIFO(st->st_mode))
            *kind = TARGET_STREAM;
        else if (!S_ISREG(st->st_mode))
            return sw__fail(
                status, SW_ERR_NOT_REGULAR_FILE,
                "%s: %s: only a regular file, a character device or a FIFO can be written", path,
                kind_str(st->st_mode));
        return SW_OK;
    }
    const int err = errno;
    if (err == ENOENT)
        return SW_OK;
    return sw__fail(status, err == ENOTDIR ? SW_ERR_NOT_FOUND : SW_ERR_IO, "%s: %s", path,
                    strerror(err));
}

sw_result sw__out_check(const char *path, unsigned flags, sw_status *status)
{
    struct stat st;
    int kind, exists;
    sw_result r = classify(path, flags, &kind, &st, &exists, status);
    if (r != SW_OK || kind != TARGET_FILE || exists)
        return r;
    /* a new file: its directory must exist (a dangling link's target directory included) */
    char *target = resolve_target(path);
    char *dir = target ? dir_of(target) : NULL;
    if (!dir)
        r = sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    else if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        r = sw__fail(status, SW_ERR_NOT_FOUND, "%s: directory %s does not exist", path, dir);
    sw__free(target);
    sw__free(dir);
    return r;
}

sw_result sw__out_open(sw__out *out, const char *path, unsigned flags, sw_status *status)
{
    memset(out, 0, sizeof *out);
    out->fd = -1;
    out->shown = dup_str(path);
    if (!out->shown)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    struct stat st;
    int kind, exists;
    sw_result r = classify(path, flags, &kind, &st, &exists, status);
    if (r != SW_OK) {
        /* refused */
    } else if (kind != TARGET_FILE) {
        r = open_direct(out, path, flags, status);
    } else {
        out->target = resolve_target(path);
        if (!out->target)
            r = errno == ENOMEM ? sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", path)
                                : sw__fail(status, SW_ERR_IO, "%s: cannot resolve the link: %s",
                                           path, strerror(errno));
        else
            r = open_temp(out, exists ? &st : NULL, status);
    }
    if (r != SW_OK)
        release(out);
    return r;
}

sw_result sw__out_write(sw__out *out, const void *data, size_t n, sw_status *status)
{
    const unsigned char *p = data;
    while (n) {
        const size_t chunk = n > ((size_t)1 << 30) ? ((size_t)1 << 30) : n;
        const ssize_t w = do_write(out->fd, p, chunk);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0) {
            const int err = w < 0 ? errno : EIO;
            return sw__fail(status, SW_ERR_IO, "%s: write failed after %llu bytes: %s", out->shown,
                            (unsigned long long)out->written, strerror(err));
        }
        p += w;
        n -= (size_t)w;
        out->written += (uint64_t)w;
    }
    return SW_OK;
}

void sw__out_abandon(sw__out *out)
{
    if (out->fd >= 0 && out->kind != KIND_STDOUT)
        close(out->fd);
    if (out->tmp)
        unlink(out->tmp);
    release(out);
}

/* Makes the rename durable; the target is already complete, so a failure is not reported. */
static void sync_dir_of(const char *path)
{
    char *dir = dir_of(path);
    if (!dir)
        return;
    const int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        (void)fsync(fd);
        close(fd);
    }
    sw__free(dir);
}

/* Gives the unnamed temporary its name BASE.tmp-PID[.N]; linkat cannot replace a file. */
static int link_tmpfile(sw__out *out)
{
    char proc[64];
    snprintf(proc, sizeof proc, "/proc/self/fd/%d", out->fd);
    for (int n = 0; n < 100; n++) {
        sw__free(out->tmp);
        out->tmp = temp_name(out->target, n);
        if (!out->tmp) {
            errno = ENOMEM;
            return -1;
        }
        if (linkat(AT_FDCWD, proc, AT_FDCWD, out->tmp, AT_SYMLINK_FOLLOW) == 0)
            return 0;
        if (errno != EEXIST)
            break;
    }
    const int err = errno;
    sw__free(out->tmp);
    out->tmp = NULL;
    errno = err;
    return -1;
}

sw_result sw__out_commit(sw__out *out, sw_status *status)
{
    const char *step = NULL;
    int err = 0;
    if (out->kind == KIND_STDOUT) {
        release(out);
        return SW_OK;
    }
    if (out->kind == KIND_DIRECT) {
        if (close(out->fd) != 0)
            step = "close", err = errno;
        out->fd = -1;
    } else {
        if (do_fsync(out->fd) != 0)
            step = "fsync", err = errno;
        else if (out->kind == KIND_TMPFILE && link_tmpfile(out) != 0)
            step = "link", err = errno;
        if (close(out->fd) != 0 && !step)
            step = "close", err = errno;
        out->fd = -1;
        if (!step && rename(out->tmp, out->target) != 0)
            step = "rename", err = errno;
        if (!step) {
            sw__free(out->tmp);
            out->tmp = NULL; /* it is the target now */
            sync_dir_of(out->target);
        }
    }
    sw_result r = SW_OK;
    if (step)
        r = sw__fail(status, SW_ERR_IO, "%s: %s failed after writing %llu bytes: %s", out->shown,
                     step, (unsigned long long)out->written, strerror(err));
    sw__out_abandon(out);
    return r;
}

sw_result sw__write_file(const char *path, const void *data, size_t n, unsigned flags,
                         sw_status *status)
{
    sw__out out;
    sw_result r = sw__out_open(&out, path, flags, status);
    if (r != SW_OK)
        return r;
    r = sw__out_write(&out, data, n, status);
    if (r != SW_OK) {
        sw__out_abandon(&out);
        return r;
    }
    return sw__out_commit(&out, status);
}

sw_result sw__write_file_printed(const char *path, sw__out_fill_fn fill, const void *ctx,
                                 unsigned flags, sw_status *status)
{
    char *text = NULL;
    size_t len = 0;
    FILE *mem = open_memstream(&text, &len);
    if (!mem)
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", path);
    int bad = fill(mem, ctx) != 0;
    bad |= ferror(mem) != 0;
    bad |= fclose(mem) != 0;
    sw_result r = bad ? sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory", path)
                      : sw__write_file(path, text, len, flags, status);
    free(text); /* open_memstream's: libc's free */
    return r;
}
