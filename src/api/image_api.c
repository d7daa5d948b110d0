/* capi entry points of images: handles, pixels and what their bake measured. Writing them out
 * (EXR, display images) lives in image_io_api.c. */
#include <stddef.h>
#include <string.h>

#include "bake/image.h"
#include <dwivedi.h>
#include "util/error.h"
#include "image_handle.h"

#define MAX_SIDE 16384u
#define MAX_PIXELS (1u << 26)

dwv_result_t dwv_image_create(uint32_t width, uint32_t height, const float *rgba, dwv_image_t **image)
{
    static const char fn[] = "dwv_image_create";
    DWV_TRY(dwv_check_pointer(fn, "image", image));
    *image = NULL;
    DWV_TRY(dwv_check_pointer(fn, "rgba", rgba));
    if (width < 1u || height < 1u || width > MAX_SIDE || height > MAX_SIDE ||
        (uint64_t)width * height > MAX_PIXELS)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE,
                        "%s: %u x %u pixels: each side must be 1 to %u and the image at most %u pixels", fn,
                        width, height, MAX_SIDE, MAX_PIXELS);
    size_t values = (size_t)width * height * 4u;
    for (size_t i = 0; i < values; ++i) {
        if (!(rgba[i] - rgba[i] == 0.0f))
            return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: rgba[%zu] (pixel %zu, channel %zu) is not finite", fn,
                            i, i / 4u, i % 4u);
    }
    dwvb_image *made = dwvb_image_new(width, height);
    if (!made) return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: no memory for %u x %u pixels", fn, width, height);
    memcpy(made->rgba, rgba, values * sizeof *rgba);
    *image = dwv_image_handle(made);
    return DWV_SUCCESS;
}

dwv_result_t dwv_image_info(const dwv_image_t *image, dwv_image_info_t *info)
{
    static const char fn[] = "dwv_image_info";
    DWV_TRY(dwv_check_pointer(fn, "image", image));
    DWV_TRY(dwv_check_struct(fn, "info", info, (uint32_t)sizeof(dwv_image_info_t)));
    const dwvb_image *img = dwv_image_object(image);
    info->width = img->width;
    info->height = img->height;
    info->rgba = img->rgba;
    info->variance = img->variance;
    info->samples = img->samples;
    return DWV_SUCCESS;
}

dwv_result_t dwv_image_stats(const dwv_image_t *image, dwv_bake_stats_t *stats)
{
    static const char fn[] = "dwv_image_stats";
    DWV_TRY(dwv_check_pointer(fn, "image", image));
    /* A caller's struct that ends before path_rays (an older header) gets the fields it has. */
    DWV_TRY(dwv_check_struct(fn, "stats", stats, (uint32_t)offsetof(dwv_bake_stats_t, path_rays)));
    uint32_t size = stats->struct_size;
    dwv_bake_stats_t whole = dwv_image_object(image)->stats;
    memcpy(stats, &whole, size < sizeof whole ? size : sizeof whole);
    stats->struct_size = size;
    return DWV_SUCCESS;
}

dwv_result_t dwv_image_error_vs_time(const dwv_image_t *image, dwv_error_point_t *points, uint32_t capacity,
                                     uint32_t *count)
{
    static const char fn[] = "dwv_image_error_vs_time";
    DWV_TRY(dwv_check_pointer(fn, "image", image));
    DWV_TRY(dwv_check_pointer(fn, "count", count));
    if (capacity > 0u) DWV_TRY(dwv_check_pointer(fn, "points", points));
    const dwvb_image *img = dwv_image_object(image);
    uint32_t total = img->stats.error_vs_time_count;
    uint32_t copied = capacity < total ? capacity : total;
    if (copied > 0u) memcpy(points, img->error_vs_time, (size_t)copied * sizeof *points);
    *count = total;
    return DWV_SUCCESS;
}

dwv_result_t dwv_image_retain(dwv_image_t *image)
{
    DWV_TRY(dwv_check_pointer("dwv_image_retain", "image", image));
    atomic_fetch_add(&dwv_image_object(image)->references, 1u);
    return DWV_SUCCESS;
}

void dwv_image_release(dwv_image_t *image)
{
    if (!image) return;
    dwvb_image *img = dwv_image_object(image);
    if (atomic_fetch_sub(&img->references, 1u) == 1u) dwvb_image_free(img);
}
