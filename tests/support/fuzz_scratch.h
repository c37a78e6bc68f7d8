/* SPDX-License-Identifier: MIT */
/* A fuzz harness's scratch file for round trips through the file system: SW_FUZZ_SCRATCH when set,
 * else one per process in /dev/shm (or /tmp), named with `stem`; removed at exit (a crash leaves
 * it, with the crash's input beside it). Header-only: each harness is a program of its own. */
#ifndef SW_FUZZ_SCRATCH_H
#define SW_FUZZ_SCRATCH_H

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

static char sw_fuzz_scratch_name[512];

static void sw_fuzz_scratch_remove(void)
{
    unlink(sw_fuzz_scratch_name);
}

static const char *sw_fuzz_scratch(const char *stem)
{
    if (!sw_fuzz_scratch_name[0]) {
        const char *env = getenv("SW_FUZZ_SCRATCH");
        if (env && *env)
            snprintf(sw_fuzz_scratch_name, sizeof sw_fuzz_scratch_name, "%s", env);
        else
            snprintf(sw_fuzz_scratch_name, sizeof sw_fuzz_scratch_name, "%s/%ld_%s",
                     access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp", (long)getpid(), stem);
        atexit(sw_fuzz_scratch_remove);
    }
    return sw_fuzz_scratch_name;
}

#endif
