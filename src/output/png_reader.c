#include "png_reader.h"

#include <png.h>
#include <stdlib.h>
#include <string.h>

dwv_result_t dwvo_read_png8(const char *path, uint32_t *width, uint32_t *height, uint32_t *channels,
                            uint8_t **pixels, char *message, size_t size)
{
    *pixels = NULL;
    png_image image;
    memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&image, path)) {
        snprintf(message, size, "cannot read PNG '%s': %s", path, image.message);
        return strstr(image.message, "open") || strstr(image.message, "No such") ? DWV_ERROR_IO : DWV_ERROR_FORMAT;
    }
    if (image.width == 0 || image.height == 0 || (uint64_t)image.width * image.height > (1u << 28)) {
        snprintf(message, size, "PNG '%s' is %u x %u pixels (1 to 2^28 pixels)", path, image.width, image.height);
        png_image_free(&image);
        return DWV_ERROR_FORMAT;
    }
    int alpha = (image.format & PNG_FORMAT_FLAG_ALPHA) != 0, colour = (image.format & PNG_FORMAT_FLAG_COLOR) != 0;
    image.format = alpha ? PNG_FORMAT_RGBA : colour ? PNG_FORMAT_RGB : PNG_FORMAT_GRAY;
    uint32_t n = alpha ? 4u : colour ? 3u : 1u;
    size_t row = (size_t)image.width * n;
    uint8_t *data = malloc(row * image.height);
    if (!data) {
        png_image_free(&image);
        snprintf(message, size, "no memory for PNG '%s' (%u x %u)", path, image.width, image.height);
        return DWV_ERROR_OUT_OF_MEMORY;
    }
    /* A negative row stride stores the image bottom-up (libpng starts the top row at the end of
     * the buffer): row 0 of the buffer is the file's bottom row. */
    if (!png_image_finish_read(&image, NULL, data, -(png_int_32)row, NULL)) {
        snprintf(message, size, "cannot read PNG '%s': %s", path, image.message);
        free(data);
        png_image_free(&image);
        return DWV_ERROR_FORMAT;
    }
    *width = image.width;
    *height = image.height;
    *channels = n;
    *pixels = data;
    return DWV_SUCCESS;
}
