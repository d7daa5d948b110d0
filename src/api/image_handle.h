/* dwv_image_t is the bake's image object itself; these casts are the only place that says so. */
#ifndef DWV_API_IMAGE_HANDLE_H
#define DWV_API_IMAGE_HANDLE_H

#include "bake/image.h"
#include <dwivedi.h>

struct dwv_image_s {
    dwvb_image image;
};

static inline dwv_image_t *dwv_image_handle(dwvb_image *image)
{
    return (dwv_image_t *)image;
}

static inline dwvb_image *dwv_image_object(const dwv_image_t *image)
{
    return (dwvb_image *)&((dwv_image_t *)image)->image;
}

#endif
