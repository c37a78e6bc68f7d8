/* SPDX-License-Identifier: MIT */
/* Input files that cannot block or flood (sw_safe_read.h). */
#include "sw_safe_read.h"

#include "sw_hooks.h"
#include "sw_status_util.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *kind_str(mode_t m)
{
    return S_ISDIR(m)    ? "is a directory"
           : S_ISFIFO(m) ? "is a FIFO (named pipe)"
           : S_ISCHR(m)  ? "is a character device"
           : S_ISBLK(m)  ? "is a block device"
           : S_ISSOCK(m) ? "is a socket"
                         : "is not a regular file";
}

sw_result sw__in_open(const char *path, uint64_t max_bytes, const char *what, int *fd,
                      uint64_t *size, sw_status *status)
{
    *fd = -1;
    *size = 0;
    const int f = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (f < 0) {
        const int err = errno;
        return sw__fail(status, err == ENOENT || err == ENOTDIR ? SW_ERR_NOT_FOUND : SW_ERR_IO,
                        "%s: cannot open: %s", path, strerror(err));
    }
    struct stat st;
    sw_result r = SW_OK;
    if (fstat(f, &st) != 0)
        r = sw__fail(status, SW_ERR_IO, "%s: cannot stat: %s", path, strerror(errno));
    else if (!S_ISREG(st.st_mode))
        r = sw__fail(status, SW_ERR_NOT_REGULAR_FILE, "%s: %s, not a regular file", path,
                     kind_str(st.st_mode));
    else if (max_bytes && (uint64_t)st.st_size > max_bytes)
        r = sw__fail(status, SW_ERR_LIMIT, "%s: %llu bytes, more than a %s may have (%llu)", path,
                     (unsigned long long)st.st_size, what, (unsigned long long)max_bytes);
    if (r != SW_OK) {
        close(f);
        return r;
    }
    *fd = f;
    *size = (uint64_t)st.st_size;
    return SW_OK;
}

sw_result sw__in_check(const char *path, uint64_t max_bytes, const char *what, sw_status *status)
{
    int fd;
    uint64_t size;
    sw_result r = sw__in_open(path, max_bytes, what, &fd, &size, status);
    if (r == SW_OK)
        close(fd);
    return r;
}

sw_result sw__in_read_all(const char *path, uint64_t max_bytes, const char *what, char **text,
                          size_t *len, sw_status *status)
{
    *text = NULL;
    *len = 0;
    int fd;
    uint64_t size;
    sw_result r = sw__in_open(path, max_bytes, what, &fd, &size, status);
    if (r != SW_OK)
        return r;
    /* one byte more than fstat's size (and the NUL) tells a file that grew since */
    const size_t cap = (size_t)(size < max_bytes ? size : max_bytes) + 2;
    char *buf = sw__malloc(cap);
    if (!buf) {
        close(fd);
        return sw__fail(status, SW_ERR_OUT_OF_MEMORY, "%s: out of memory for %llu bytes", path,
                        (unsigned long long)size);
    }
    size_t n = 0;
    while (n < cap - 1) {
        const ssize_t got = read(fd, buf + n, cap - 1 - n);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            r = sw__fail(status, SW_ERR_IO, "%s: read failed after %zu bytes: %s", path, n,
                         strerror(errno));
            break;
        }
        if (got == 0)
            break;
        n += (size_t)got;
    }
    close(fd);
    if (r == SW_OK && n > max_bytes)
        r = sw__fail(status, SW_ERR_LIMIT, "%s: grew past the %llu bytes a %s may have", path,
                     (unsigned long long)max_bytes, what);
    else if (r == SW_OK && n > size)
        r = sw__fail(status, SW_ERR_IO, "%s: grew from %llu bytes while it was read", path,
                     (unsigned long long)size);
    if (r != SW_OK) {
        sw__free(buf);
        return r;
    }
    buf[n] = '\0';
    *text = buf;
    *len = n;
    return SW_OK;
}
