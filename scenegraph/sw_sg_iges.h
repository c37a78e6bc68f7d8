/* SPDX-License-Identifier: MIT */
/* The structure of a fixed-format IGES file (IGES 5.3, §2.1: 80-column records, the section
 * letter S, G, D, P or T in column 73 and a sequence number in columns 74-80), read before OCCT
 * reads the file, because OCCT's IGES reader neither reports a file cut short nor guards the
 * entities whose parameter data is missing: a file cut in half imported about a fifth of its
 * faces silently, and a cut IGES B-rep file crashed its transfer (IGESSolid_Face::NbLoops on a
 * face that was never filled in).
 *
 * A file is truncated when its Terminate record is missing, when the counts the Terminate record
 * declares for S, G, D and P differ from the records present, or when a section's sequence numbers
 * skip. Each entity (a pair of D records) is whole when its parameter data (the P records its
 * directory entry points at, §2.2.4.4 fields 2 and 14) is present and ends with the record
 * delimiter. Which entities point at which is OCCT's to say (its graph of the file, built from
 * the whole entities' data); the importer hands OCCT only roots whose every entity is whole.
 */
#ifndef SW_SG_IGES_H
#define SW_SG_IGES_H

#include "sw_module_abi.h"

#include <splinewalk/sw_result.h>

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sw_sg_iges_scan {
    uint32_t records[5];  /* S, G, D, P, T records present */
    uint32_t declared[4]; /* S, G, D, P counts of the Terminate record; 0 without one */
    int32_t truncated;    /* 1: see above; `why` says how */
    uint32_t entities;    /* directory entries present (D records / 2) */
    uint32_t incomplete;  /* entities whose parameter data is missing or cut */
    uint8_t *entity_incomplete; /* [entities]: 1 = incomplete; entity k has DE number 2k + 1 */
    char why[200];          /* when truncated: what is missing, in words */
} sw_sg_iges_scan;

/* Scans `len` bytes of IGES text. On SW_OK *out is filled (free it with sw_sg_iges_scan_free);
 * a truncated file is SW_OK with out->truncated = 1. Errors: SW_ERR_UNSUPPORTED (not fixed-format
 * ASCII IGES — compressed or binary form, records not in 80-column lines — about which nothing is
 * said; *out is zero), SW_ERR_OUT_OF_MEMORY. `text` need not be NUL-terminated. Any thread. */
SW_MODULE_ABI sw_result sw_sg_iges_scan_text(const char *text, size_t len, sw_sg_iges_scan *out,
                                             sw_status *status);
SW_MODULE_ABI void sw_sg_iges_scan_free(sw_sg_iges_scan *scan);

#ifdef __cplusplus
}
#endif
#endif
