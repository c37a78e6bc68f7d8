/* SPDX-License-Identifier: MIT */
/* sw_setup: the host's allocator and log hooks (splinewalk/sw_setup.h; the hooks themselves are
 * threads/hooks.c, below every library that allocates). */
#include "sw_hooks.h"
#include "sw_rt.h"
#include "sw_rt_misuse.h"
#include "sw_status_util.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

sw_result sw_setup(const sw_setup_desc *desc, sw_status *status)
{
    if (!desc)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_setup: desc is NULL");
    const char *why = NULL;
    if (sw__hooks_install(desc, &why) != 0)
        return SW__MISUSE(status, SW_ERR_INVALID_ARGUMENT, "sw_setup: %s", why);
    sw__status_ok(status);
    return SW_OK;
}

sw_result sw__misuse(int abort_after, sw_status *status, sw_result result, const char *fmt, ...)
{
    char message[sizeof status->message];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(message, sizeof message, fmt, ap);
    va_end(ap);
    sw__log(SW_LOG_ERROR, "misuse: %s", message);
    if (abort_after) {
        fprintf(stderr, "splinewalk: misuse: %s (%s; aborting: built with SW_MISUSE_ASSERT)\n",
                message, sw_result_id_str(result));
        abort();
    }
    if (status) {
        status->result = result;
        snprintf(status->message, sizeof status->message, "%s", message);
    }
    return result;
}
