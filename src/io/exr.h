/* OpenEXR output of a dwvb_image through the OpenEXR core C API (openexr.h). */
#ifndef DWV_IO_EXR_H
#define DWV_IO_EXR_H

#include <stddef.h>

#include "bake/image.h"
#include "dwivedi.h"

/* Writes `image` to `path` atomically (atomic_file.h): one scanline part, ZIP compression, FLOAT
 * channels R, G, B, A (scene-linear Rec.709, with the chromaticities attribute: Rec.709 primaries,
 * D65 white), variance_R/G/B (FLOAT: the variance of each pixel mean) and samples (UINT), and
 * the dwivedi:* metadata attributes listed in exr.c. On failure the message says why. */
dwv_result_t dwvio_write_exr(const dwvb_image *image, const char *path, char *message, size_t size);

#endif
