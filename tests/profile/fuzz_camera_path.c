/* SPDX-License-Identifier: MIT */
/* libFuzzer harness for camera paths (tools/splinewalk/camera_path.c): every input is parsed and
 * validated; a failure must leave no path and name the input with a line; an accepted path must
 * evaluate to cameras the renderer accepts (finite, fovy in (0, 180)) at every frame time when its
 * numbers are moderate, and must write and read back bit-identical (sw_rt_path_save's promise);
 * the stock paths made for the box of its keys must either be refused with the writer's
 * "(not written)" or read back as written ("path never writes a key it would refuse to read").
 * The round trips go through a scratch file (SW_FUZZ_SCRATCH, else one per process in /dev/shm or
 * /tmp). Planted: the writer printing %.15g → the round trip aborts on the committed seeds. */
#include "../support/fuzz_scratch.h"
#include "sw_camera_path.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int moderate(const sw_rt_camera_path *p)
{
    for (uint32_t i = 0; i < p->n_keys; i++) {
        const sw_camera *c = &p->keys[i].camera;
        for (int k = 0; k < 3; k++)
            if (fabs(c->eye[k]) > 1e100 || fabs(c->target[k]) > 1e100 || fabs(c->up[k]) > 1e100)
                return 0;
        if (fabs(p->keys[i].t) > 1e100)
            return 0;
    }
    return 1;
}

static void exercise(const sw_rt_camera_path *p)
{
    const int check = moderate(p);
    for (uint32_t i = 0; i < 16; i++) {
        sw_camera c;
        sw_rt_path_eval(p, sw_rt_path_frame_time(p, i, 16), &c);
        if (!check)
            continue;
        for (int k = 0; k < 3; k++)
            if (!isfinite(c.eye[k]) || !isfinite(c.target[k]) || !isfinite(c.up[k]))
                abort();
        if (!(c.fovy_deg > 0.0 && c.fovy_deg < 180.0))
            abort();
    }
}

static const char *scratch_file(void)
{
    return sw_fuzz_scratch("sw_fuzz_path.path");
}

static int same_key(const sw_rt_path_key *a, const sw_rt_path_key *b)
{
    return !memcmp(&a->t, &b->t, sizeof a->t) && !memcmp(&a->camera, &b->camera, sizeof a->camera);
}

/* Saves `p` and loads it back: the same keys, bit for bit, and the same records. A refusal is
 * allowed only where `may_refuse` (a generated path) and only as the writer's own. */
static void round_trip(const sw_rt_camera_path *p, int may_refuse)
{
    sw_status st = {0};
    if (sw_rt_path_save(p, scratch_file(), 0, &st) != SW_OK) {
        if (!may_refuse || st.result != SW_ERR_FORMAT || !strstr(st.message, "(not written)"))
            abort();
        return;
    }
    sw_rt_camera_path back;
    if (sw_rt_path_load(scratch_file(), &back, &st) != SW_OK)
        abort();
    if (back.n_keys != p->n_keys || back.closed != p->closed || back.frames != p->frames)
        abort();
    for (uint32_t i = 0; i < p->n_keys; i++)
        if (!same_key(&back.keys[i], &p->keys[i]))
            abort();
    sw_rt_path_free(&back);
}

/* The three stock paths around the box of the path's eyes and targets. */
static void stock_paths(const sw_rt_camera_path *p)
{
    double box[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < p->n_keys; i++)
        for (int k = 0; k < 3; k++) {
            const double *pts[2] = {p->keys[i].camera.eye, p->keys[i].camera.target};
            for (int j = 0; j < 2; j++) {
                box[k] = fmin(box[k], pts[j][k]);
                box[3 + k] = fmax(box[3 + k], pts[j][k]);
            }
        }
    const double seconds = 1.0 + p->n_keys;
    const uint32_t frames = p->frames ? p->frames : 16;
    for (int which = 0; which < 3; which++) {
        sw_rt_camera_path g = {0};
        sw_status st = {0};
        sw_result r = which == 0   ? sw_rt_path_orbit(box, seconds, frames, &g, &st)
                      : which == 1 ? sw_rt_path_fly(box, seconds, frames, &g, &st)
                                   : sw_rt_path_walk(box, 0.25 * (box[5] - box[2]) + 1.0, seconds,
                                                     frames, &g, &st);
        if (r != SW_OK)
            abort(); /* the only documented error is running out of memory */
        round_trip(&g, 1);
        sw_rt_path_free(&g);
    }
}

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);
int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    sw_rt_camera_path p;
    sw_status st = {0};
    const sw_result r = sw_rt_path_parse((const char *)data, size, "fuzz", &p, &st);
    if (r != SW_OK) {
        if (p.keys || p.n_keys || st.result != r || strncmp(st.message, "fuzz:", 5) != 0)
            abort();
        return 0;
    }
    if (p.n_keys == 0 || !p.keys)
        abort();
    exercise(&p);
    round_trip(&p, 0);
    if (moderate(&p))
        stock_paths(&p);
    sw_rt_path_free(&p);
    return 0;
}
