/* Radiance RGBE (.hdr) input, for environment worlds. */
#ifndef DWV_OUTPUT_RADIANCE_READER_H
#define DWV_OUTPUT_RADIANCE_READER_H

#include <stddef.h>
#include <stdint.h>

#include <dwivedi.h>

/* 1 when the file at `path` starts as a Radiance picture does ("#?"), else 0. */
int dwvo_file_is_radiance(const char *path);

/* Reads the Radiance picture at `path` (Greg Ward's format: "#?" header lines, FORMAT
 * 32-bit_rle_rgbe, the standard orientation "-Y height +X width", scanlines flat or
 * run-length encoded) as RGB floats, row 0 at the BOTTOM (as Blender's Image.pixels). A texel of
 * mantissas m and exponent byte e is (m + 0.5) 2^(e - 136), or 0 for e = 0: Radiance's own
 * decoding, which Blender's loader uses too. EXPOSURE lines are ignored (as Blender does). Sizes
 * beyond max_side / max_texels are refused before anything is allocated; XYZE pictures, other
 * orientations, damaged or truncated files are refused (DWV_ERROR_FORMAT, saying which); a
 * missing file is DWV_ERROR_IO. *pixels (3 x width x height) is malloc'd. */
dwv_result_t dwvo_read_radiance(const char *path, uint32_t max_side, uint64_t max_texels, uint32_t *width,
                                uint32_t *height, float **pixels, char *message, size_t size);

#endif
