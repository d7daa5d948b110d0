/* What a bake's per-pixel sums (dwvb_pixel_sums, bake_internal.h) give: the image's estimated
 * relative error after each pass, and at the end the image with its stats. The same functions
 * serve a merge of chunks (dwvb_sums_*), which has the sums but no bake. */
#ifndef DWV_BAKE_PIXEL_SUMS_H
#define DWV_BAKE_PIXEL_SUMS_H

#include "bake/bake_internal.h"

/* The sums of an image and what says which pixels are covered: UV texels of the islands (texels
 * non-NULL), else camera pixels that saw a surface (all when none did). */
typedef struct dwvb_sums_view {
    uint32_t width, height;
    const dwvb_uv_texel *texels; /* UV bakes; NULL for camera bakes */
    const dwvb_pixel_sums *sums;
    const uint32_t *counts;
} dwvb_sums_view;

/* The image's relative RMSE against its converged self (pixel_sums.c says how it is measured). */
double dwvb_sums_estimate_error(const dwvb_sums_view *view);
/* Fills image->rgba, variance, samples and stats' mean_rgb, samples and samples_per_pixel. */
void dwvb_sums_fill_image(const dwvb_sums_view *view, dwvb_image *image);

double dwvb_bake_estimate_error(const dwvb_bake *bake);
/* Turns the sums into bake->image and its stats (`seconds`: the bake's time); DWV_SUCCESS, or
 * the code of the UV margin's dilation (out of memory). A chunk's image keeps a copy of the sums
 * (image->partial). */
dwv_result_t dwvb_bake_make_image(dwvb_bake *bake, double seconds);

#endif
