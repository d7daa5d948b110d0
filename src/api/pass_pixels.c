#include "pass_pixels.h"

#include <string.h>

/* The colour pass of a direct or indirect pass; the pass itself otherwise. */
static uint32_t colour_of(uint32_t pass)
{
    if (pass >= DWV_PASS_DIFFUSE_DIRECT && pass <= DWV_PASS_TRANSMISSION_COLOR) return 1u + 3u * ((pass - 1u) / 3u) + 2u;
    return pass;
}

static const float *plane(const float *base, const dwvb_image *img, uint32_t pass)
{
    return base + (size_t)dwvb_image_pass_rank(img, pass) * 3u * img->width * img->height;
}

/* Cycles' safe division of a pass by its colour: 0 where the colour is not above 0. */
static float divided(float value, float colour)
{
    return colour > 0.0f ? value / colour : 0.0f;
}

void dwva_pass_pixels(const dwvb_image *img, dwv_pass_t pass, float *rgb, float *variance)
{
    size_t pixels = (size_t)img->width * img->height;
    if (pass == DWV_PASS_COMBINED) {
        for (size_t i = 0; i < pixels; ++i)
            for (int c = 0; c < 3; ++c) rgb[3 * i + c] = img->rgba[4 * i + c];
        if (variance) memcpy(variance, img->variance, 3u * pixels * sizeof *variance);
        return;
    }
    const float *mean = plane(img->pass_mean, img, pass), *var = plane(img->pass_variance, img, pass);
    uint32_t colour_pass = colour_of(pass);
    if (colour_pass == (uint32_t)pass) {
        memcpy(rgb, mean, 3u * pixels * sizeof *rgb);
        if (variance) memcpy(variance, var, 3u * pixels * sizeof *variance);
        return;
    }
    const float *colour = plane(img->pass_mean, img, colour_pass);
    for (size_t k = 0; k < 3u * pixels; ++k) {
        rgb[k] = divided(mean[k], colour[k]);
        if (variance) variance[k] = divided(divided(var[k], colour[k]), colour[k]);
    }
}

void dwva_bake_type_pixels(const dwvb_image *img, dwv_bake_type_t type, uint32_t filter, uint32_t needed, float *rgba,
                           float *variance)
{
    size_t pixels = (size_t)img->width * img->height;
    for (size_t i = 0; i < pixels; ++i)
        for (int c = 0; c < 3; ++c) rgba[4 * i + c] = 0.0f;
    memset(variance, 0, 3u * pixels * sizeof *variance);
    /* The light passes summed as they are (not divided by colour). */
    uint32_t light = 0u, colour_pass = 0u;
    for (uint32_t pass = 1u; pass < DWV_PASS_COUNT; ++pass) {
        if (!(needed & DWV_PASS_BIT(pass))) continue;
        if (colour_of(pass) != pass || type == DWV_BAKE_TYPE_COMBINED || type == DWV_BAKE_TYPE_EMIT ||
            type == DWV_BAKE_TYPE_ENVIRONMENT)
            light |= DWV_PASS_BIT(pass);
        else
            colour_pass = pass;
    }
    for (uint32_t pass = 1u; pass < DWV_PASS_COUNT; ++pass) {
        if (!(light & DWV_PASS_BIT(pass))) continue;
        const float *mean = plane(img->pass_mean, img, pass), *var = plane(img->pass_variance, img, pass);
        for (size_t i = 0; i < pixels; ++i)
            for (int c = 0; c < 3; ++c) {
                rgba[4 * i + c] += mean[3 * i + c];
                variance[3 * i + c] += var[3 * i + c];
            }
    }
    if (!colour_pass) return;
    const float *colour = plane(img->pass_mean, img, colour_pass), *colour_var = plane(img->pass_variance, img, colour_pass);
    for (size_t i = 0; i < pixels; ++i)
        for (int c = 0; c < 3; ++c) {
            float k = colour[3 * i + c];
            if (!light) { /* the colour alone */
                rgba[4 * i + c] = k;
                variance[3 * i + c] = colour_var[3 * i + c];
            } else if (!(filter & DWV_BAKE_FILTER_COLOR)) { /* the light without its colour */
                rgba[4 * i + c] = divided(rgba[4 * i + c], k);
                variance[3 * i + c] = divided(divided(variance[3 * i + c], k), k);
            }
        }
}
