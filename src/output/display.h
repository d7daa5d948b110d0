/* Colour-managed display images through OpenColorIO (display.cpp, C++ behind a C interface: no
 * C++ exception ever leaves it). */
#ifndef DWV_OUTPUT_DISPLAY_H
#define DWV_OUTPUT_DISPLAY_H

#include <stddef.h>
#include <stdint.h>

#include <dwivedi.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Turns scene-linear Rec.709 premultiplied RGBA floats (4 x width x height, row 0 at the top) into
 * 8-bit straight-alpha display RGBA as Blender's colour management does (see display.cpp): colour
 * divided by alpha (where alpha is neither 0 nor 1), exposure, display/view/look through
 * OpenColorIO, gamma, then [0, 1] clamped and rounded to 8 bits. `options` was validated by the
 * caller (exposure finite, gamma > 0 and finite); the names are checked here against the config
 * (DWV_ERROR_UNKNOWN_NAME with the valid names in the message). Non-finite inputs never reach the
 * bytes as garbage: NaN becomes 0 and, after the exposure, values are clamped to +-65504 (the
 * largest half float), so +infinity shows as the brightest value the view makes. */
dwv_result_t dwvo_to_display(const float *rgba, uint32_t width, uint32_t height,
                              const dwv_display_options_t *options, uint8_t *out, char *message, size_t size);

/* The default config compiled into the library (data/ocio/config.ocio), NUL-terminated. */
extern const unsigned char dwvo_default_ocio_config[];
extern const size_t dwvo_default_ocio_config_size;

#ifdef __cplusplus
}
#endif

#endif
