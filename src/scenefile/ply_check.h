/* A structural check of a PLY file (header well formed, body as long as the header says) before
 * Assimp reads it: Assimp 5.2's PLY reader reads past its buffer on malformed files. */
#ifndef DWV_SCENEFILE_PLY_CHECK_H
#define DWV_SCENEFILE_PLY_CHECK_H

#include <dwivedi.h>

/* The largest PLY file read (bytes). */
#define DWVS_PLY_MAX_BYTES (1ull << 31)

/* DWV_SUCCESS, or DWV_ERROR_IO / DWV_ERROR_FORMAT with a message naming the path and the fault. */
dwv_result_t dwvs_ply_check(const char *path);

#endif
