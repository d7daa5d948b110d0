/* PNG output through libpng. */
#ifndef DWV_OUTPUT_PNG_WRITER_H
#define DWV_OUTPUT_PNG_WRITER_H

#include <stddef.h>
#include <stdint.h>

#include <dwivedi.h>

/* Writes 8-bit RGBA (4 x width x height bytes, row 0 at the top) to `path` atomically
 * (atomic_file.h), non-interlaced, with a tEXt Software chunk naming the dwivedi version. */
dwv_result_t dwvo_write_png_rgba8(const uint8_t *rgba, uint32_t width, uint32_t height, const char *path,
                                   char *message, size_t size);

#endif
