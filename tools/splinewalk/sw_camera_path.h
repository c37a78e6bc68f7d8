/* SPDX-License-Identifier: MIT */
/* Camera paths (never installed): keyframed cameras for profiling runs and, later, the viewer's
 * recordings. The text format is specified in docs/camera-path.md; this module parses it, then
 * validates it as a separate step (CONVENTIONS.md: files are hostile), evaluates it at any time,
 * writes it back, and generates the two stock paths of `splinewalk path` (an orbit around a
 * bounding box and a low fly-through).
 *
 * Interpolation: eye and target by a cubic Hermite spline with Catmull-Rom tangents taken over the
 * key times (m_i = (p[i+1] - p[i-1]) / (t[i+1] - t[i-1]); one-sided at the ends of an open path,
 * wrapped around on a closed one), so the path passes through every key and its velocity is
 * continuous; the up vector by normalized linear interpolation between neighbouring keys; fovy
 * linearly (a cubic could overshoot out of (0°, 180°)).
 */
#ifndef SW_CAMERA_PATH_H
#define SW_CAMERA_PATH_H

#include <splinewalk/splinewalk.h>

#include <stddef.h>
#include <stdint.h>

#define SW_RT_PATH_VERSION 1
#define SW_RT_PATH_MAX_KEYS 1000000u
#define SW_RT_PATH_MAX_FRAMES 1000000u
#define SW_RT_PATH_MAX_BYTES ((size_t)64 << 20)

typedef struct sw_rt_path_key {
    double t; /* seconds; strictly increasing along the path */
    sw_camera camera;
    uint32_t line; /* source line (0 for generated keys), for validation messages */
} sw_rt_path_key;

typedef struct sw_rt_camera_path {
    sw_rt_path_key *keys;
    uint32_t n_keys;
    int closed;      /* the last key repeats the first; tangents wrap around */
    uint32_t frames; /* suggested frame count for a run along the path; 0 = none given */
} sw_rt_camera_path;

/* Parses and validates `len` bytes of `text` (need not be NUL-terminated); `name` prefixes every
 * message ("name:line: what was expected, what was found"). On failure *out is left empty.
 * Errors: SW_ERR_FORMAT (syntax, or a key that makes a degenerate camera), SW_ERR_VERSION,
 * SW_ERR_TRUNCATED (the text ends inside a record), SW_ERR_LIMIT, SW_ERR_OUT_OF_MEMORY. */
sw_result sw_rt_path_parse(const char *text, size_t len, const char *name, sw_rt_camera_path *out,
                           sw_status *status);
/* Reads a regular file of at most SW_RT_PATH_MAX_BYTES, refused by its size before it is read
 * (sw_safe_read.h: a FIFO or device cannot block it), and parses it. Adds SW_ERR_NOT_FOUND,
 * SW_ERR_NOT_REGULAR_FILE, SW_ERR_IO. */
sw_result sw_rt_path_load(const char *file, sw_rt_camera_path *out, sw_status *status);
/* Writes the path (17 significant digits: it reads back bit-identical) to `file` through the
 * project's one writer (sw_safe_write.h: replaced whole or left as it was); flags
 * SW__OUT_DASH_STDOUT makes "-" standard output. The text is parsed back first: a path that
 * sw_rt_path_parse would refuse is never written (SW_ERR_FORMAT, its message as the parser's,
 * "FILE (not written):LINE: ..."). Errors also: SW_ERR_IO (a full disk too; nothing is left
 * behind), SW_ERR_NOT_FOUND, SW_ERR_NOT_REGULAR_FILE, SW_ERR_OUT_OF_MEMORY. */
sw_result sw_rt_path_save(const sw_rt_camera_path *path, const char *file, unsigned flags,
                          sw_status *status);
void sw_rt_path_free(sw_rt_camera_path *path);

/* Start and end time of the path (equal for a single key). */
double sw_rt_path_t0(const sw_rt_camera_path *path);
double sw_rt_path_t1(const sw_rt_camera_path *path);
/* The time of frame i of n spread evenly over the path: an open path's first and last frames sit
 * on its first and last keys; a closed path's frames are period / n apart, so the seam is not
 * shown twice. Requires i < n. */
double sw_rt_path_frame_time(const sw_rt_camera_path *path, uint32_t i, uint32_t n);
/* The camera at time t (clamped to the path's span). The path must have been validated. */
void sw_rt_path_eval(const sw_rt_camera_path *path, double t, sw_camera *out);

/* Stock paths for a world box (min xyz, max xyz; +Z up, as the view presets assume), of
 * `seconds` (> 0) duration and `frames` suggested frames. Orbit: 16 keys on a closed circle
 * around the box centre, 25° above its horizontal plane, at the preset fit distance, looking at
 * the centre. Fly: a low pass through the box along its longer horizontal side, eye at 30 % of its
 * height weaving sideways, looking ahead along the path. Walk: the same pass with the eye
 * eye_height above the box's bottom (through the rooms of a building). Errors:
 * SW_ERR_OUT_OF_MEMORY. */
sw_result sw_rt_path_orbit(const double bbox[6], double seconds, uint32_t frames,
                           sw_rt_camera_path *out, sw_status *status);
sw_result sw_rt_path_fly(const double bbox[6], double seconds, uint32_t frames,
                         sw_rt_camera_path *out, sw_status *status);
sw_result sw_rt_path_walk(const double bbox[6], double eye_height, double seconds, uint32_t frames,
                          sw_rt_camera_path *out, sw_status *status);

#endif
