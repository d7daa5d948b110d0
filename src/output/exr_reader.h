/* OpenEXR input through the OpenEXR core C API (for textures and environment worlds). */
#ifndef DWV_OUTPUT_EXR_READER_H
#define DWV_OUTPUT_EXR_READER_H

#include <stddef.h>
#include <stdint.h>

#include <dwivedi.h>

/* 1 when the file at `path` starts with OpenEXR's magic number (20000630 little-endian), else 0
 * (also when it cannot be opened: the caller's reader then says why). */
int dwvo_file_is_exr(const char *path);

/* Reads the first part of the EXR at `path` (scanline or tiled; of a tiled one its full-resolution
 * level) as 32-bit floats, converting half and uint channels, values as stored (no colour
 * conversion: Blender takes an EXR as scene-linear): channels R, G, B and A -> 4, R, G, B -> 3,
 * Y (luminance; an A beside it is dropped) -> 1, interleaved, row 0 at the BOTTOM (v = 0, as
 * textures and Blender's Image.pixels). Refused (DWV_ERROR_FORMAT) before anything is allocated:
 * an empty data window, a side above max_side or more than max_texels texels, deep or
 * sub-sampled data, a file with neither R, G, B nor Y (a multi-layer file: its channels are named
 * "layer.R"). A missing file is DWV_ERROR_IO; a damaged or truncated one DWV_ERROR_FORMAT with
 * OpenEXR's reason. *pixels is malloc'd (the caller frees it). Values are not checked here (NaN
 * and infinities come back as they are). */
dwv_result_t dwvo_read_exr_float(const char *path, uint32_t max_side, uint64_t max_texels, uint32_t *width,
                                 uint32_t *height, uint32_t *channels, float **pixels, char *message, size_t size);

#endif
