/* OpenEXR output of an image's pixels, variance, sample counts and bake statistics through the
 * OpenEXR core C API (openexr.h). It knows the public types only, not the bake that made them. */
#ifndef DWV_OUTPUT_EXR_H
#define DWV_OUTPUT_EXR_H

#include <stddef.h>

#include <dwivedi.h>

/* What an EXR holds: interleaved pixels with row 0 at the top, and the metadata's values. */
typedef struct dwvo_exr_image {
    uint32_t width, height;
    const float *rgba;                   /* 4 x width x height */
    const float *variance;               /* 3 x width x height */
    const uint32_t *samples;             /* width x height */
    const dwv_bake_stats_t *stats;       /* stats->error_vs_time_count points in error_vs_time */
    const dwv_error_point_t *error_vs_time;
    const char *technique;               /* the technique's name ("none": caller-made pixels) */
    const char *features;                /* comma-separated feature names */
    /* Multilayer files (multilayer 1): channels Combined.R/G/B/A from rgba and, per layer (up to
     * DWVO_EXR_MAX_LAYERS), <name>.R/G/B from its 3 x width x height floats, instead of the
     * channels above. */
    int multilayer;
    uint32_t layer_count;
    const char *const *layer_names;
    const float *const *layer_rgb;
} dwvo_exr_image;

/* Writes `image` to `path` atomically (atomic_file.h): one scanline part, ZIP compression, FLOAT
 * channels R, G, B, A (scene-linear Rec.709, with the chromaticities attribute: Rec.709 primaries,
 * D65 white), variance_R/G/B (FLOAT: the variance of each pixel mean) and samples (UINT), and
 * the dwivedi:* metadata attributes listed in exr.c. On failure the message says why. */
dwv_result_t dwvo_write_exr(const dwvo_exr_image *image, const char *path, char *message, size_t size);
/* The layers a multilayer file holds at most beside Combined. */
#define DWVO_EXR_MAX_LAYERS 16u

#endif
