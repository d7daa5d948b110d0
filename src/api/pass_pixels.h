/* A baked image's passes turned into pixels as Blender shows them (pass_api.c, and the layers of
 * dwv_image_write_exr_layers in image_io_api.c). The image holds every pass asked for. */
#ifndef DWV_API_PASS_PIXELS_H
#define DWV_API_PASS_PIXELS_H

#include "bake/image.h"
#include <dwivedi.h>

/* Pass `pass` (held, or COMBINED) into rgb (3 x pixels) and, unless NULL, variance (3 x pixels):
 * direct and indirect divided by their lobe's colour (Cycles' DiffDir = light / DiffCol, 0 where
 * the colour is 0; the variance by the colour squared). */
void dwva_pass_pixels(const dwvb_image *img, dwv_pass_t pass, float *rgb, float *variance);

/* The RGB (into rgba's first three of four per pixel; A untouched) and variance of bake type
 * `type` with `filter`, from the passes `needed` (dwv_bake_type_passes), all held. Variances of
 * summed passes are summed (their covariance, from shared light samples, not counted). */
void dwva_bake_type_pixels(const dwvb_image *img, dwv_bake_type_t type, uint32_t filter, uint32_t needed, float *rgba,
                           float *variance);

#endif
