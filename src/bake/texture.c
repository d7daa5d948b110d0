#include "texture.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

double dwvb_srgb_to_linear(double c)
{
    if (c < 0.04045) return c < 0.0 ? 0.0 : c / 12.92;
    return pow((c + 0.055) / 1.055, 2.4);
}

uint32_t dwvb_texture_texel_bytes(const dwvb_texture *texture)
{
    return texture->channels * (texture->format == DWV_TEXEL_FLOAT32 ? 4u : 1u);
}

/* The stored value of channel c of texel (x, y), undecoded (bytes / 255). */
static double texel(const dwvb_texture *t, uint32_t x, uint32_t y, uint32_t c)
{
    size_t i = ((size_t)y * t->width + x) * t->channels + c;
    if (t->format == DWV_TEXEL_FLOAT32) return ((const float *)t->texels)[i];
    return ((const uint8_t *)t->texels)[i] * (1.0 / 255.0);
}

int dwvb_texture_init(dwvb_texture *texture, const dwv_texture_desc_t *desc)
{
    memset(texture, 0, sizeof *texture);
    texture->width = desc->width;
    texture->height = desc->height;
    texture->channels = desc->channels;
    texture->format = desc->format;
    texture->extension = desc->extension;
    texture->interpolation = desc->interpolation;
    size_t bytes = (size_t)desc->width * desc->height * dwvb_texture_texel_bytes(texture);
    texture->texels = malloc(bytes);
    if (!texture->texels) return -1;
    memcpy(texture->texels, desc->texels, bytes);
    for (uint32_t c = 0; c < texture->channels; ++c) {
        double largest = -INFINITY;
        for (uint32_t y = 0; y < texture->height; ++y)
            for (uint32_t x = 0; x < texture->width; ++x) largest = fmax(largest, texel(texture, x, y, c));
        int colour = texture->format == DWV_TEXEL_SRGB8 && c < 3u;
        texture->max[c] = colour ? dwvb_srgb_to_linear(largest) : largest;
    }
    return 0;
}

void dwvb_texture_free(dwvb_texture *texture)
{
    free(texture->texels);
    texture->texels = NULL;
}

/* A tap index i along a side of n texels as the extension says; -1 for clip outside. */
static int64_t wrap(int64_t i, int64_t n, dwv_texture_extension_t extension)
{
    switch (extension) {
    case DWV_EXTENSION_EXTEND: return i < 0 ? 0 : i >= n ? n - 1 : i;
    case DWV_EXTENSION_CLIP: return i < 0 || i >= n ? -1 : i;
    case DWV_EXTENSION_MIRROR: {
        int64_t m = i % (2 * n);
        if (m < 0) m += 2 * n;
        return m < n ? m : 2 * n - 1 - m;
    }
    default: {
        int64_t m = i % n;
        return m < 0 ? m + n : m;
    }
    }
}

/* Texture coordinates far outside [0, 1] (or not finite) are brought near it, keeping the
 * extension's answer: repeat and mirror are periodic (period 2), extend and clip are constant
 * beyond the edges. */
static double tame(double s, dwv_texture_extension_t extension)
{
    if (!isfinite(s)) return 0.0;
    if (fabs(s) < 1e6) return s;
    if (extension == DWV_EXTENSION_REPEAT || extension == DWV_EXTENSION_MIRROR) return s - 2.0 * floor(s / 2.0);
    return s < 0.0 ? -2.0 : 3.0;
}

/* Uniform cubic B-spline weights at fraction t (the taps floor - 1 .. floor + 2). */
static void bspline_weights(double t, double w[4])
{
    double t2 = t * t, t3 = t2 * t, s = 1.0 - t;
    w[0] = s * s * s / 6.0;
    w[1] = (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0;
    w[2] = (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0;
    w[3] = t3 / 6.0;
}

void dwvb_texture_lookup(const dwvb_texture *t, double u, double v, double out[4])
{
    uint32_t nc = t->channels;
    for (uint32_t c = 0; c < 4u; ++c) out[c] = 0.0;
    u = tame(u, t->extension);
    v = tame(v, t->extension);
    int64_t w = t->width, h = t->height;
    if (t->interpolation == DWV_INTERPOLATION_CLOSEST) {
        if (t->extension == DWV_EXTENSION_CLIP && !(u >= 0.0 && u < 1.0 && v >= 0.0 && v < 1.0)) return;
        int64_t x = wrap((int64_t)floor(u * (double)w), w, t->extension);
        int64_t y = wrap((int64_t)floor(v * (double)h), h, t->extension);
        if (x < 0 || y < 0) return;
        for (uint32_t c = 0; c < nc; ++c) out[c] = texel(t, (uint32_t)x, (uint32_t)y, c);
    } else {
        double fx = u * (double)w - 0.5, fy = v * (double)h - 0.5;
        double x0 = floor(fx), y0 = floor(fy);
        double wx[4], wy[4];
        int first, taps;
        if (t->interpolation == DWV_INTERPOLATION_CUBIC) {
            bspline_weights(fx - x0, wx);
            bspline_weights(fy - y0, wy);
            first = -1;
            taps = 4;
        } else {
            wx[0] = 1.0 - (fx - x0), wx[1] = fx - x0;
            wy[0] = 1.0 - (fy - y0), wy[1] = fy - y0;
            first = 0;
            taps = 2;
        }
        for (int j = 0; j < taps; ++j) {
            int64_t y = wrap((int64_t)y0 + first + j, h, t->extension);
            if (y < 0) continue;
            for (int i = 0; i < taps; ++i) {
                int64_t x = wrap((int64_t)x0 + first + i, w, t->extension);
                if (x < 0) continue;
                double weight = wx[i] * wy[j];
                for (uint32_t c = 0; c < nc; ++c) out[c] += weight * texel(t, (uint32_t)x, (uint32_t)y, c);
            }
        }
    }
    if (t->format == DWV_TEXEL_SRGB8)
        for (uint32_t c = 0; c < nc && c < 3u; ++c) out[c] = dwvb_srgb_to_linear(out[c]);
}

double dwvb_texture_scalar(const dwvb_texture *texture, const double value[4])
{
    if (texture->channels == 1u) return value[0];
    return 0.2126 * value[0] + 0.7152 * value[1] + 0.0722 * value[2];
}
