/* SPDX-License-Identifier: MIT */
/* CRC-32C (Castagnoli, reflected polynomial 0x82F63B78): the per-section checksum of .sws files
 * (docs/sws-format.md). Internal to scenegraph/, never installed. */
#ifndef SW_CRC32C_H
#define SW_CRC32C_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Continues a CRC-32C: start with crc = 0; sw__crc32c(sw__crc32c(0, a, n), b, m) equals the CRC of
 * a followed by b. CRC-32C("123456789") = 0xE3069283. `data` may be NULL when n == 0. Thread-safe.
 */
uint32_t sw__crc32c(uint32_t crc, const void *data, size_t n);
/* The same through the portable table path only (tests compare it with the hardware path). */
uint32_t sw__crc32c_portable(uint32_t crc, const void *data, size_t n);

#ifdef __cplusplus
}
#endif
#endif
