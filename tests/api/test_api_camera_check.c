/* SPDX-License-Identifier: MIT */
/* tests/api: sw_camera_check, the one camera check behind every frame, camera paths and the
 * command line's --camera. No GL. Checked against hand-made cameras whose verdict follows from
 * the header's rules:
 *  - the all-zero camera (the fitted default) and fovy 0 (the default field of view) pass;
 *  - a field of view below SW_FOVY_MIN_DEG or at 180 is refused, naming the range (catches the
 *    floor dropped: fovy 1e-9 grew memory at ~600 MB/s in the frame);
 *  - a coordinate beyond SW_CAMERA_COORD_MAX is refused while one just inside passes (catches
 *    the limit dropped, and squares taken unscaled: 1e200 became "up parallel to the view");
 *  - eye = target relative to the coordinates' size, up zero or within ~4.5e-5 rad of the view,
 *    non-finite coordinates: refused, each with its own reason;
 *  - NULL: SW_ERR_INVALID_ARGUMENT (not a crash). */
#include <splinewalk/splinewalk.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

static int g_failures;

#define EXPECT(cond)                                                                               \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "FAIL %s:%d: %s\n", __FILE__, __LINE__, #cond);                        \
            g_failures++;                                                                          \
        }                                                                                          \
    } while (0)

static sw_camera good(void)
{
    sw_camera c = {{10.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 40.0};
    return c;
}

/* The camera is refused and the message holds `reason`. */
static int refused(const sw_camera *c, const char *reason)
{
    sw_status st = {0};
    return sw_camera_check(c, &st) == SW_ERR_INVALID_ARGUMENT && strstr(st.message, reason);
}

static int passes(const sw_camera *c)
{
    sw_status st = {0};
    return sw_camera_check(c, &st) == SW_OK;
}

int main(void)
{
    sw_camera c = good();
    EXPECT(passes(&c));
    sw_camera zero;
    memset(&zero, 0, sizeof zero);
    EXPECT(passes(&zero));
    c.fovy_deg = 0.0;
    EXPECT(passes(&c));

    c = good();
    c.fovy_deg = 1e-9;
    EXPECT(refused(&c, "180)"));
    c.fovy_deg = SW_FOVY_MIN_DEG;
    EXPECT(passes(&c));
    c.fovy_deg = 180.0;
    EXPECT(refused(&c, "180)"));

    c = good();
    c.eye[0] = 1e200;
    EXPECT(refused(&c, "SW_CAMERA_COORD_MAX"));
    c.eye[0] = 0.5 * SW_CAMERA_COORD_MAX; /* far out, but within: a valid view */
    EXPECT(passes(&c));
    c = good();
    c.up[2] = 2.0 * SW_CAMERA_COORD_MAX;
    EXPECT(refused(&c, "SW_CAMERA_COORD_MAX"));
    c = good();
    c.target[1] = NAN;
    EXPECT(refused(&c, "not finite"));
    c.target[1] = INFINITY;
    EXPECT(refused(&c, "not finite"));

    c = good();
    memcpy(c.target, c.eye, sizeof c.eye);
    EXPECT(refused(&c, "eye coincides"));
    c.eye[0] = 1e12; /* 1e-6 apart at 1e12: below the rounding of the coordinates */
    c.target[0] = 1e12 + 1e-3;
    EXPECT(refused(&c, "eye coincides"));
    c.target[0] = 1e12 + 1e4; /* 1e-8 relative: the view direction survives */
    EXPECT(passes(&c));

    c = good();
    c.up[2] = 0.0;
    EXPECT(refused(&c, "up vector is zero"));
    c.up[0] = 1.0; /* along the view */
    EXPECT(refused(&c, "along the view"));
    c.up[2] = 1e-6; /* 1e-6 rad off the view: the basis is lost in rounding */
    EXPECT(refused(&c, "along the view"));
    c.up[2] = 1e-3;
    EXPECT(passes(&c));

    sw_status st = {0};
    EXPECT(sw_camera_check(NULL, &st) == SW_ERR_INVALID_ARGUMENT);

    if (g_failures)
        fprintf(stderr, "%d failure(s)\n", g_failures);
    else
        printf("ok: sw_camera_check\n");
    return g_failures != 0;
}
