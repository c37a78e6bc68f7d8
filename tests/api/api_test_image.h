/* SPDX-License-Identifier: MIT */
/* tests/api: frames read back for pixel comparisons (test_api_nodes_image_oiio.cpp, OpenImageIO).
 */
#ifndef SW_API_TEST_IMAGE_H
#define SW_API_TEST_IMAGE_H

#ifdef __cplusplus
extern "C" {
#endif

/* RGBA8, top row first; NULL when the file cannot be read. The caller frees it with free(). */
unsigned char *sw_test_read_rgba(const char *path, int *width, int *height);

/* Percentage of pixels whose RGBA differs at all between two image files; 100 when either cannot
 * be read or their sizes differ. */
double sw_test_differing_percent(const char *a, const char *b);

#ifdef __cplusplus
}
#endif
#endif
