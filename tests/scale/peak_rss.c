/* SPDX-License-Identifier: MIT */
/* peak_rss: runs a command and prints its peak resident set (the kernel's ru_maxrss of the child,
 * what `/usr/bin/time -f %M` prints) so that a test can bound it without GNU time installed.
 *
 * usage: peak_rss OUT_FILE CMD [ARGS...]
 * Writes "peak_rss_kib N" to OUT_FILE and exits with the command's status (128 + signal when it
 * was killed, 127 when it could not be started). */
#define _GNU_SOURCE
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: peak_rss OUT_FILE CMD [ARGS...]\n");
        return 2;
    }
    pid_t pid = fork();
    if (pid < 0) {
        perror("peak_rss: fork");
        return 127;
    }
    if (pid == 0) {
        execvp(argv[2], argv + 2);
        fprintf(stderr, "peak_rss: %s: %s\n", argv[2], strerror(errno));
        _exit(127);
    }
    int status = 0;
    struct rusage ru;
    while (wait4(pid, &status, 0, &ru) < 0)
        if (errno != EINTR) {
            perror("peak_rss: wait4");
            return 127;
        }
    FILE *f = fopen(argv[1], "w");
    if (!f || fprintf(f, "peak_rss_kib %ld\n", ru.ru_maxrss) < 0 || fclose(f) != 0) {
        fprintf(stderr, "peak_rss: cannot write %s\n", argv[1]);
        return 127;
    }
    if (WIFSIGNALED(status))
        return 128 + WTERMSIG(status);
    return WEXITSTATUS(status);
}
