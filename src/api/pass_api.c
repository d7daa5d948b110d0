/* capi entry points of bake passes (issue 18): Blender's pass names, its bake types and pass
 * filter turned into passes, and a baked image's passes as Blender shows them. */
#include <stdlib.h>
#include <string.h>

#include "bake/image.h"
#include <dwivedi.h>
#include "util/error.h"
#include "image_handle.h"
#include "pass_pixels.h"

/* Blender's pass names (its render passes: RE_PASSNAME_COMBINED "Combined", RE_PASSNAME_DIFFUSE_DIRECT
 * "DiffDir", ..., RE_PASSNAME_EMIT "Emit", RE_PASSNAME_ENVIRONMENT "Env"), indexed by dwv_pass_t. */
static const char *const pass_names[DWV_PASS_COUNT] = {"Combined", "DiffDir",  "DiffInd",  "DiffCol",
                                                       "GlossDir", "GlossInd", "GlossCol", "TransDir",
                                                       "TransInd", "TransCol", "Emit",     "Env"};

const char *dwv_pass_name(dwv_pass_t pass)
{
    return (uint32_t)pass < DWV_PASS_COUNT ? pass_names[pass] : NULL;
}

dwv_result_t dwv_pass_from_name(const char *name, dwv_pass_t *pass)
{
    static const char fn[] = "dwv_pass_from_name";
    DWV_TRY(dwv_check_pointer(fn, "name", name));
    DWV_TRY(dwv_check_pointer(fn, "pass", pass));
    for (uint32_t p = 0; p < DWV_PASS_COUNT; ++p) {
        if (strcmp(name, pass_names[p]) == 0) {
            *pass = (dwv_pass_t)p;
            return DWV_SUCCESS;
        }
    }
    return dwv_fail(DWV_ERROR_UNKNOWN_NAME,
                    "%s: unknown pass '%.64s' (Blender's names: Combined, DiffDir, DiffInd, DiffCol, GlossDir, "
                    "GlossInd, GlossCol, TransDir, TransInd, TransCol, Emit, Env)", fn, name);
}

/* The direct, indirect and colour passes of lobe `lobe` (0 diffuse, 1 glossy, 2 transmission). */
static dwv_pass_t lobe_pass(uint32_t lobe, uint32_t kind)
{
    return (dwv_pass_t)(1u + 3u * lobe + kind);
}

#define ALL_FILTERS 127u

dwv_result_t dwv_bake_type_passes(dwv_bake_type_t type, uint32_t filter, uint32_t *passes)
{
    static const char fn[] = "dwv_bake_type_passes";
    DWV_TRY(dwv_check_pointer(fn, "passes", passes));
    *passes = 0u;
    if (filter & ~ALL_FILTERS)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: filter 0x%x has bits beyond DWV_BAKE_FILTER_EMIT (0x40)", fn, filter);
    int direct = (filter & DWV_BAKE_FILTER_DIRECT) != 0, indirect = (filter & DWV_BAKE_FILTER_INDIRECT) != 0;
    uint32_t mask = 0u;
    switch (type) {
    case DWV_BAKE_TYPE_COMBINED: {
        const uint32_t lobes[3] = {DWV_BAKE_FILTER_DIFFUSE, DWV_BAKE_FILTER_GLOSSY, DWV_BAKE_FILTER_TRANSMISSION};
        for (uint32_t l = 0; l < 3u; ++l) {
            if (!(filter & lobes[l])) continue;
            if (direct) mask |= DWV_PASS_BIT(lobe_pass(l, 0u));
            if (indirect) mask |= DWV_PASS_BIT(lobe_pass(l, 1u));
        }
        if (filter & DWV_BAKE_FILTER_EMIT) mask |= DWV_PASS_BIT(DWV_PASS_EMISSION);
        if (!mask)
            return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                            "%s: a Combined bake's filter 0x%x selects nothing: it needs Direct or Indirect with one of "
                            "Diffuse, Glossy, Transmission, or Emit", fn, filter);
        break;
    }
    case DWV_BAKE_TYPE_DIFFUSE:
    case DWV_BAKE_TYPE_GLOSSY:
    case DWV_BAKE_TYPE_TRANSMISSION: {
        uint32_t lobe = (uint32_t)type - 1u;
        if (direct) mask |= DWV_PASS_BIT(lobe_pass(lobe, 0u));
        if (indirect) mask |= DWV_PASS_BIT(lobe_pass(lobe, 1u));
        /* With colour the light is the result; without it the light divided by the colour, which
         * it needs all the same. */
        if (mask || (filter & DWV_BAKE_FILTER_COLOR)) mask |= DWV_PASS_BIT(lobe_pass(lobe, 2u));
        else
            return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                            "%s: a %s bake's filter 0x%x selects nothing: it needs Direct, Indirect or Color "
                            "(as Blender: \"Bake pass requires Direct, Indirect, or Color contributions to be enabled\")",
                            fn, type == DWV_BAKE_TYPE_DIFFUSE ? "Diffuse" : type == DWV_BAKE_TYPE_GLOSSY ? "Glossy" : "Transmission",
                            filter);
        break;
    }
    case DWV_BAKE_TYPE_EMIT: mask = DWV_PASS_BIT(DWV_PASS_EMISSION); break;
    case DWV_BAKE_TYPE_ENVIRONMENT: mask = DWV_PASS_BIT(DWV_PASS_ENVIRONMENT); break;
    default:
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: bake type %d is not one this library bakes (0 Combined, 1 Diffuse, 2 Glossy, "
                        "3 Transmission, 4 Emit, 5 Environment)", fn, (int)type);
    }
    *passes = mask;
    return DWV_SUCCESS;
}

dwv_result_t dwv_image_passes(const dwv_image_t *image, uint32_t *passes)
{
    static const char fn[] = "dwv_image_passes";
    DWV_TRY(dwv_check_pointer(fn, "image", image));
    DWV_TRY(dwv_check_pointer(fn, "passes", passes));
    *passes = dwv_image_object(image)->passes;
    return DWV_SUCCESS;
}

/* A new image of the same size, samples, stats and alpha as `img`, its RGB and variance to be
 * filled by the caller; NULL out of memory. */
static dwvb_image *image_like(const dwvb_image *img)
{
    dwvb_image *made = dwvb_image_new(img->width, img->height);
    if (!made) return NULL;
    size_t pixels = (size_t)img->width * img->height;
    memcpy(made->samples, img->samples, pixels * sizeof *made->samples);
    made->stats = img->stats;
    made->stats.error_vs_time_count = 0u; /* the series is the combined image's */
    for (size_t i = 0; i < pixels; ++i) made->rgba[4 * i + 3] = img->rgba[4 * i + 3];
    return made;
}

static dwv_result_t check_pass(const char *fn, const dwvb_image *img, dwv_pass_t pass)
{
    if ((uint32_t)pass >= DWV_PASS_COUNT)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: pass %d is not known (0 to %u)", fn, (int)pass, DWV_PASS_COUNT - 1u);
    if (!(img->passes & DWV_PASS_BIT(pass)))
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: the image holds no %s pass (bake with dwv_bake_options_t.passes including DWV_PASS_BIT(%d))",
                        fn, pass_names[pass], (int)pass);
    return DWV_SUCCESS;
}

dwv_result_t dwv_image_pass(const dwv_image_t *image, dwv_pass_t pass, dwv_image_t **pass_image)
{
    static const char fn[] = "dwv_image_pass";
    DWV_TRY(dwv_check_pointer(fn, "pass_image", pass_image));
    *pass_image = NULL;
    DWV_TRY(dwv_check_pointer(fn, "image", image));
    const dwvb_image *img = dwv_image_object(image);
    DWV_TRY(check_pass(fn, img, pass));
    dwvb_image *made = image_like(img);
    if (!made) return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: no memory for %u x %u pixels", fn, img->width, img->height);
    size_t pixels = (size_t)img->width * img->height;
    float *rgb = malloc(pixels * 3u * sizeof *rgb);
    if (!rgb) {
        dwvb_image_free(made);
        return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: no memory for %u x %u pixels", fn, img->width, img->height);
    }
    dwva_pass_pixels(img, pass, rgb, made->variance);
    for (size_t i = 0; i < pixels; ++i)
        for (int c = 0; c < 3; ++c) made->rgba[4 * i + c] = rgb[3 * i + c];
    free(rgb);
    *pass_image = dwv_image_handle(made);
    return DWV_SUCCESS;
}

dwv_result_t dwv_image_bake_type(const dwv_image_t *image, dwv_bake_type_t type, uint32_t filter, dwv_image_t **result)
{
    static const char fn[] = "dwv_image_bake_type";
    DWV_TRY(dwv_check_pointer(fn, "result", result));
    *result = NULL;
    DWV_TRY(dwv_check_pointer(fn, "image", image));
    uint32_t needed = 0u;
    DWV_TRY(dwv_bake_type_passes(type, filter, &needed));
    const dwvb_image *img = dwv_image_object(image);
    for (uint32_t pass = 1u; pass < DWV_PASS_COUNT; ++pass)
        if (needed & DWV_PASS_BIT(pass)) DWV_TRY(check_pass(fn, img, (dwv_pass_t)pass));
    dwvb_image *made = image_like(img);
    if (!made) return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: no memory for %u x %u pixels", fn, img->width, img->height);
    dwva_bake_type_pixels(img, type, filter, needed, made->rgba, made->variance);
    *result = dwv_image_handle(made);
    return DWV_SUCCESS;
}
