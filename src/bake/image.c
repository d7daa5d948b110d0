#include "image.h"

#include <stdint.h>
#include <stdlib.h>

dwvb_image *dwvb_image_new(uint32_t width, uint32_t height)
{
    dwvb_image *image = calloc(1, sizeof *image);
    if (!image) return NULL;
    size_t pixels = (size_t)width * height;
    image->rgba = calloc(pixels * 4, sizeof *image->rgba);
    image->variance = calloc(pixels * 3, sizeof *image->variance);
    image->samples = calloc(pixels, sizeof *image->samples);
    if (!image->rgba || !image->variance || !image->samples) {
        dwvb_image_free(image);
        return NULL;
    }
    atomic_init(&image->references, 1u);
    image->width = width;
    image->height = height;
    dwv_bake_stats_t stats = DWV_BAKE_STATS_INIT;
    image->stats = stats;
    image->passes = DWV_PASS_BIT(DWV_PASS_COMBINED);
    return image;
}

int dwvb_image_add_passes(dwvb_image *image, uint32_t passes)
{
    uint32_t count = 0u;
    for (uint32_t pass = 1u; pass < DWV_PASS_COUNT; ++pass) count += (passes >> pass) & 1u;
    image->passes = DWV_PASS_BIT(DWV_PASS_COMBINED);
    image->pass_count = 0u;
    if (count == 0u) return 0;
    size_t values = (size_t)count * image->width * image->height * 3u;
    image->pass_mean = calloc(values, sizeof *image->pass_mean);
    image->pass_variance = calloc(values, sizeof *image->pass_variance);
    if (!image->pass_mean || !image->pass_variance) return -1;
    image->passes |= passes & ((1u << DWV_PASS_COUNT) - 1u);
    image->pass_count = count;
    return 0;
}

int dwvb_image_pass_rank(const dwvb_image *image, uint32_t pass)
{
    if (pass == DWV_PASS_COMBINED || pass >= DWV_PASS_COUNT || !(image->passes & DWV_PASS_BIT(pass))) return -1;
    int rank = 0;
    for (uint32_t p = 1u; p < pass; ++p) rank += (int)((image->passes >> p) & 1u);
    return rank;
}

int dwvb_image_add_error_point(dwvb_image *image, dwv_error_point_t point)
{
    uint32_t count = image->stats.error_vs_time_count;
    if (count == image->error_vs_time_capacity) {
        if (count > UINT32_MAX / 2u) return -1;
        uint32_t capacity = count ? 2u * count : 16u;
        dwv_error_point_t *grown = realloc(image->error_vs_time, (size_t)capacity * sizeof *grown);
        if (!grown) return -1;
        image->error_vs_time = grown;
        image->error_vs_time_capacity = capacity;
    }
    image->error_vs_time[count] = point;
    image->stats.error_vs_time_count = count + 1u;
    return 0;
}

void dwvb_image_free(dwvb_image *image)
{
    if (!image) return;
    free(image->rgba);
    free(image->variance);
    free(image->samples);
    free(image->pass_mean);
    free(image->pass_variance);
    free(image->error_vs_time);
    if (image->partial) {
        free(image->partial->sums);
        free(image->partial->counts);
        free(image->partial);
    }
    free(image);
}
