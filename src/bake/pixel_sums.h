/* What a bake's per-pixel sums (dwvb_pixel_sums, bake_internal.h) give: the image's estimated
 * relative error after each pass, and at the end the image with its stats. */
#ifndef DWV_BAKE_PIXEL_SUMS_H
#define DWV_BAKE_PIXEL_SUMS_H

#include "bake/bake_internal.h"

/* The image's relative RMSE against its converged self (pixel_sums.c says how it is measured). */
double dwvb_bake_estimate_error(const dwvb_bake *bake);
/* Turns the sums into bake->image and its stats (`seconds`: the bake's time); DWV_SUCCESS, or
 * the code of the UV margin's dilation (out of memory). */
dwv_result_t dwvb_bake_make_image(dwvb_bake *bake, double seconds);

#endif
