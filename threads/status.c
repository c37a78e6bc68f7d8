/* SPDX-License-Identifier: MIT */
/* sw_result names and the sw_status helpers shared by every layer. */
#include "sw_status_util.h"
#include "sw_hooks.h"

#include <stdarg.h>
#include <stdio.h>

const char *sw_result_str(sw_result result)
{
    static const char *const names[] = {
#define SW__RESULT_TEXT(id, text) text,
        SW_RESULT_XMACRO(SW__RESULT_TEXT)
#undef SW__RESULT_TEXT
    };
    if ((unsigned)result >= (unsigned)SW_RESULT_COUNT)
        return "unknown result";
    return names[result];
}

const char *sw_result_id_str(sw_result result)
{
    static const char *const ids[] = {
#define SW__RESULT_ID(id, text) #id,
        SW_RESULT_XMACRO(SW__RESULT_ID)
#undef SW__RESULT_ID
    };
    if ((unsigned)result >= (unsigned)SW_RESULT_COUNT)
        return "SW_RESULT_UNKNOWN";
    return ids[result];
}

/* Every failure is also a debug line of the host's logger (sw_setup.h), when it asks for them. */
sw_result sw__fail(sw_status *status, sw_result result, const char *fmt, ...)
{
    int logged = sw__log_enabled(SW_LOG_DEBUG);
    if (status || logged) {
        char local[sizeof status->message];
        char *message = status ? status->message : local;
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(message, sizeof local, fmt, ap);
        va_end(ap);
        if (status)
            status->result = result;
        if (logged)
            sw__log(SW_LOG_DEBUG, "%s: %s", sw_result_id_str(result), message);
    }
    return result;
}

void sw__status_ok(sw_status *status)
{
    if (status) {
        status->result = SW_OK;
        status->message[0] = '\0';
    }
}
