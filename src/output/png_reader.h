/* PNG input through libpng's simplified API (for textures). */
#ifndef DWV_OUTPUT_PNG_READER_H
#define DWV_OUTPUT_PNG_READER_H

#include <stddef.h>
#include <stdint.h>

#include <dwivedi.h>

/* Reads `path` as 8-bit values (16-bit files are reduced to 8 bits, palettes expanded, no colour
 * conversion: the stored sRGB or data values): 1 channel for a grey image without alpha, 3 for
 * colour without alpha, 4 otherwise, interleaved, row 0 at the BOTTOM (v = 0, as textures).
 * *pixels is malloc'd (the caller frees it). Images above 2^28 pixels are refused. */
dwv_result_t dwvo_read_png8(const char *path, uint32_t *width, uint32_t *height, uint32_t *channels,
                            uint8_t **pixels, char *message, size_t size);

#endif
