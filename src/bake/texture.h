/* Textures of a scene (capi's dwv_texture_desc_t) and their lookup as Blender's Image Texture node
 * does it in Cycles (kernel/device/cpu/image.h, kernel/svm/image.h of Blender 3.4, read for the
 * conventions; the code is ours):
 *   closest  the texel floor(u W), floor(v H);
 *   linear   bilinear between texel centres: x = u W - 1/2, taps floor(x) and floor(x) + 1;
 *   cubic    the uniform cubic B-spline over taps floor(x) - 1 .. floor(x) + 2 with weights
 *            (1 - t)^3 / 6, (3 t^3 - 6 t^2 + 4) / 6, (-3 t^3 + 3 t^2 + 3 t + 1) / 6, t^3 / 6;
 *   repeat   index mod W; extend: clamped; clip: a tap outside the image is 0 (closest: a point
 *            outside [0, 1)^2 is 0); mirror: index mod 2W, reflected in the upper half;
 *   sRGB     8-bit sRGB colour is decoded after interpolation (Cycles keeps such images as bytes
 *            and converts the filtered value): c < 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055)^2.4.
 * Row 0 is v = 0 (Blender's Image.pixels order). */
#ifndef DWV_BAKE_TEXTURE_H
#define DWV_BAKE_TEXTURE_H

#include <stdint.h>

#include <dwivedi.h>

#define DWVB_MAX_TEXTURE_SIDE 65536u
#define DWVB_MAX_TEXTURE_TEXELS (1u << 28)
#define DWVB_MAX_TEXTURES (1u << 16)
#define DWVB_MAX_BINDINGS (1u << 16)

typedef struct dwvb_texture {
    uint32_t width, height, channels;
    dwv_texel_format_t format;
    dwv_texture_extension_t extension;
    dwv_texture_interpolation_t interpolation;
    void *texels;     /* float (DWV_TEXEL_FLOAT32) or uint8_t, channels x width x height */
    double max[4];    /* the largest decoded value per channel (for the commit's analysis) */
} dwvb_texture;

/* Copies a validated description's texels; 0 on success, -1 out of memory. */
int dwvb_texture_init(dwvb_texture *texture, const dwv_texture_desc_t *desc);
void dwvb_texture_free(dwvb_texture *texture);
/* Bytes per texel in memory: channels x (4 for float, 1 for bytes). */
uint32_t dwvb_texture_texel_bytes(const dwvb_texture *texture);
/* The texture's value at (u, v), decoded (scene-linear), into out[0 .. channels - 1]. */
void dwvb_texture_lookup(const dwvb_texture *texture, double u, double v, double out[4]);
/* One value for a scalar input: a 1-channel texture's value, or a colour's luminance
 * 0.2126 R + 0.7152 G + 0.0722 B (Blender's colour-to-float conversion, Rec.709 scene linear). */
double dwvb_texture_scalar(const dwvb_texture *texture, const double value[4]);
/* sRGB decoding (IEC 61966-2-1), as Cycles' color_srgb_to_linear. */
double dwvb_srgb_to_linear(double c);

#endif
