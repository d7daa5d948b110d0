/* Bakes whose images and means tests compare (test_channel_walks.c, test_bake_sheet.c). */
#ifndef DWV_TESTS_BAKE_COMPARE_H
#define DWV_TESTS_BAKE_COMPARE_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include <dwivedi.h>

/* A bake's image and figures, for tests that compare bakes. */
typedef struct test_result {
    double mean[3], standard_error[3]; /* over all pixels; the error from the pixels' variances */
    uint32_t features;
    uint64_t walks, samples;
    float *rgba; /* the pixels, to free */
    size_t pixels;
} test_result;

/* Bakes size x size pixels on 2 threads into out (out->rgba NULL on failure, which is a failed
 * CHECK); 1 if it baked. The mean's standard error comes from the pixel means' own variances (an
 * upper bound under stratification: an agreement test errs toward passing by at most that). */
static inline int test_bake_result(dwv_scene_t *scene, dwv_technique_t technique, dwv_channel_walks_t channel_walks,
                                   uint32_t size, uint64_t samples, uint64_t seed, test_result *out)
{
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = o.height = size;
    o.samples = samples;
    o.threads = 2;
    o.seed = seed;
    o.technique = technique;
    o.channel_walks = channel_walks;
    dwv_image_t *image = NULL;
    out->rgba = NULL;
    if (dwv_bake(scene, &o, &image) != DWV_SUCCESS) {
        CHECK(0, "bake: %s", dwv_last_error_message());
        return 0;
    }
    dwv_bake_stats_t st = DWV_BAKE_STATS_INIT;
    dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
    dwv_image_stats(image, &st);
    dwv_image_info(image, &info);
    out->features = st.features;
    out->walks = st.walks;
    out->samples = st.samples;
    out->pixels = (size_t)info.width * info.height;
    out->rgba = malloc(4u * out->pixels * sizeof *out->rgba);
    if (!out->rgba) exit(2);
    memcpy(out->rgba, info.rgba, 4u * out->pixels * sizeof *out->rgba);
    for (int c = 0; c < 3; ++c) {
        double sum = 0.0, variance = 0.0;
        for (size_t i = 0; i < out->pixels; ++i) {
            sum += info.rgba[4u * i + (size_t)c];
            variance += info.variance[3u * i + (size_t)c];
        }
        out->mean[c] = sum / (double)out->pixels;
        out->standard_error[c] = sqrt(variance) / (double)out->pixels;
    }
    dwv_image_release(image);
    return 1;
}

#endif
