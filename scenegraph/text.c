/* SPDX-License-Identifier: MIT */
/* The text hook (sw_sg_text.h): the text module installs its outline function here; label nodes
 * call it. One atomic pointer: installing and calling may happen on any threads. */
#include "sw_sg_text.h"
#include "sw_hooks.h"
#include "sw_status_util.h"

#include <stdatomic.h>
#include <string.h>

static _Atomic(sw_sg_text_fn) g_text;

void sw_sg_text_install(sw_sg_text_fn fn)
{
    atomic_store_explicit(&g_text, fn, memory_order_release);
}

sw_result sw_sg_text_outline_make(const char *font_path, const char *utf8, size_t len,
                                  sw_sg_text_outline *out, sw_status *status)
{
    memset(out, 0, sizeof *out);
    sw_sg_text_fn fn = atomic_load_explicit(&g_text, memory_order_acquire);
    if (!fn)
        return sw__fail(status, SW_ERR_UNSUPPORTED,
                        "text: no text module installed (labels need libsplinewalk_text: call "
                        "sw_text_install)");
    sw_result r = fn(font_path, utf8, len, out, status);
    if (r != SW_OK)
        sw_sg_text_outline_free(out);
    return r;
}

void sw_sg_text_outline_free(sw_sg_text_outline *out)
{
    if (!out)
        return;
    sw__free(out->pieces);
    sw__free(out->contour_end);
    memset(out, 0, sizeof *out);
}
