/* SPDX-License-Identifier: MIT */
/* The core's functions that its own modules call (import, image, LOD building: libraries above
 * libsplinewalk that link OpenCASCADE, OpenImageIO, CGAL or OpenMesh). Marked SW_MODULE_ABI,
 * they are exported by libsplinewalk.so under the version SPLINEWALK_PRIVATE_<version>
 * (cmake/splinewalk.map.in, the list read from these marks), so a module links the core's one
 * copy (one allocator, one log, one scene builder) and loads only into the core it was built
 * with. Not installed: hosts use the API of runtime/include. */
#ifndef SW_MODULE_ABI_H
#define SW_MODULE_ABI_H

#define SW_MODULE_ABI __attribute__((visibility("default")))

#endif
