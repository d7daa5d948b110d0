#define _POSIX_C_SOURCE 200809L /* strnlen */

/* capi entry points that write images out: OpenEXR and colour-managed display images (PNG or
 * bytes in memory). They validate every argument, then hand over to src/output. */
#include <dwivedi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake/image.h"
#include "image_handle.h"
#include "util/error.h"
#include "output/atomic_file.h"
#include "output/display.h"
#include "output/exr.h"
#include "output/png_writer.h"
#include "pass_pixels.h"

/* The message of an io call, prefixed with the entry point's name. */
static dwv_result_t io_result(const char *fn, dwv_result_t result, const char *message)
{
    if (result == DWV_SUCCESS) return result;
    return dwv_fail(result, "%s: %s", fn, message);
}

static dwv_result_t check_path(const char *fn, const char *path)
{
    DWV_TRY(dwv_check_pointer(fn, "path", path));
    char message[512];
    return io_result(fn, dwvo_check_output_path(path, message, sizeof message), message);
}

static dwv_result_t check_name(const char *fn, const char *what, const char *name)
{
    if (!name) return DWV_SUCCESS;
    size_t length = strnlen(name, 1025u);
    if (length > 1024u) return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: display->%s is longer than 1024 bytes", fn, what);
    return DWV_SUCCESS;
}

static dwv_result_t check_display(const char *fn, const dwv_display_options_t *display)
{
    DWV_TRY(dwv_check_struct(fn, "display", display, (uint32_t)sizeof(dwv_display_options_t)));
    DWV_TRY(dwv_check_finite(fn, "display->exposure", display->exposure));
    /* 2^exposure must stay a finite, non-zero float gain. */
    DWV_TRY(dwv_check_range(fn, "display->exposure", display->exposure, -100.0, 100.0));
    DWV_TRY(dwv_check_finite(fn, "display->gamma", display->gamma));
    if (!(display->gamma > 0.0))
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: display->gamma = %.17g must be > 0", fn, display->gamma);
    if (display->gamma < 1e-3 || display->gamma > 1e3)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: display->gamma = %.17g is outside [0.001, 1000]", fn,
                        display->gamma);
    if (display->config_path && strnlen(display->config_path, 4096u) >= 4096u)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: display->config_path is longer than 4095 bytes", fn);
    DWV_TRY(check_name(fn, "display", display->display));
    DWV_TRY(check_name(fn, "view", display->view));
    DWV_TRY(check_name(fn, "look", display->look));
    return DWV_SUCCESS;
}

/* The DWV_FEATURE_* bits' names, comma-separated ("bitN" for a bit this version does not name). */
static void features_text(uint32_t bits, char *out, size_t size)
{
    size_t used = 0u;
    out[0] = '\0';
    for (uint32_t i = 0; i < 32u; ++i) {
        if (!(bits & (1u << i))) continue;
        const char *name = dwv_feature_name(1u << i);
        int n = name ? snprintf(out + used, size - used, "%s%s", used ? "," : "", name)
                     : snprintf(out + used, size - used, "%sbit%u", used ? "," : "", i);
        if (n < 0 || (size_t)n >= size - used) return;
        used += (size_t)n;
    }
}

/* What an EXR of `img` holds (single-layer; the caller sets the layers), its feature names
 * written into `features`. */
static dwvo_exr_image exr_image(const dwvb_image *img, char *features, size_t size)
{
    features_text(img->stats.features, features, size);
    const char *technique = dwv_technique_name(img->stats.technique);
    if (img->stats.samples_per_pixel == 0u) technique = "none"; /* caller-made pixels, not a bake */
    dwvo_exr_image exr = {img->width, img->height, img->rgba, img->variance, img->samples, &img->stats,
                          img->error_vs_time, technique ? technique : "unknown", features, 0, 0u, NULL, NULL};
    return exr;
}

dwv_result_t dwv_image_write_exr(const dwv_image_t *image, const char *path)
{
    static const char fn[] = "dwv_image_write_exr";
    DWV_TRY(dwv_check_pointer(fn, "image", image));
    DWV_TRY(check_path(fn, path));
    const dwvb_image *img = dwv_image_object(image);
    char features[512];
    dwvo_exr_image exr = exr_image(img, features, sizeof features);
    char message[512];
    return io_result(fn, dwvo_write_exr(&exr, path, message, sizeof message), message);
}

dwv_result_t dwv_image_write_exr_layers(const dwv_image_t *image, const char *path)
{
    static const char fn[] = "dwv_image_write_exr_layers";
    DWV_TRY(dwv_check_pointer(fn, "image", image));
    DWV_TRY(check_path(fn, path));
    const dwvb_image *img = dwv_image_object(image);
    char features[512];
    dwvo_exr_image exr = exr_image(img, features, sizeof features);
    /* Each pass as Blender shows it (dwv_image_pass): direct and indirect divided by colour. */
    size_t plane = 3u * (size_t)img->width * img->height;
    const char *names[DWV_PASS_COUNT];
    const float *planes[DWV_PASS_COUNT];
    uint32_t layers = 0u;
    float *pixels = img->pass_count ? malloc((size_t)img->pass_count * plane * sizeof *pixels) : NULL;
    if (img->pass_count && !pixels)
        return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: no memory for %u pass layers", fn, img->pass_count);
    for (uint32_t pass = 1u; pass < DWV_PASS_COUNT; ++pass) {
        if (!(img->passes & DWV_PASS_BIT(pass))) continue;
        float *rgb = pixels + (size_t)layers * plane;
        dwva_pass_pixels(img, (dwv_pass_t)pass, rgb, NULL);
        names[layers] = dwv_pass_name((dwv_pass_t)pass);
        planes[layers++] = rgb;
    }
    /* Without passes the file is still multilayer, with its one Combined layer. */
    exr.multilayer = 1;
    exr.layer_count = layers;
    exr.layer_names = names;
    exr.layer_rgb = (const float *const *)planes;
    char message[512];
    dwv_result_t result = dwvo_write_exr(&exr, path, message, sizeof message);
    free(pixels);
    return io_result(fn, result, message);
}

/* The display bytes of `img` into `out` (4 x width x height). */
static dwv_result_t render_display(const char *fn, const dwvb_image *img, const dwv_display_options_t *display,
                                   uint8_t *out)
{
    char message[512];
    dwv_result_t result = dwvo_to_display(img->rgba, img->width, img->height, display, out, message, sizeof message);
    return io_result(fn, result, message);
}

dwv_result_t dwv_image_write_display_png(const dwv_image_t *image, const char *path,
                                         const dwv_display_options_t *display)
{
    static const char fn[] = "dwv_image_write_display_png";
    DWV_TRY(dwv_check_pointer(fn, "image", image));
    DWV_TRY(check_path(fn, path));
    DWV_TRY(check_display(fn, display));
    const dwvb_image *img = dwv_image_object(image);
    size_t bytes = (size_t)img->width * img->height * 4u;
    uint8_t *pixels = malloc(bytes);
    if (!pixels) return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: no memory for %zu bytes of display pixels", fn, bytes);
    dwv_result_t result = render_display(fn, img, display, pixels);
    if (result == DWV_SUCCESS) {
        char message[512];
        result = io_result(fn, dwvo_write_png_rgba8(pixels, img->width, img->height, path, message, sizeof message),
                           message);
    }
    free(pixels);
    return result;
}

dwv_result_t dwv_image_to_display(const dwv_image_t *image, const dwv_display_options_t *display, uint8_t *rgba8,
                                  uint64_t size)
{
    static const char fn[] = "dwv_image_to_display";
    DWV_TRY(dwv_check_pointer(fn, "image", image));
    DWV_TRY(check_display(fn, display));
    DWV_TRY(dwv_check_pointer(fn, "rgba8", rgba8));
    const dwvb_image *img = dwv_image_object(image);
    uint64_t needed = (uint64_t)img->width * img->height * 4u;
    if (size < needed)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: size is %llu bytes; %u x %u RGBA pixels need %llu", fn,
                        (unsigned long long)size, img->width, img->height, (unsigned long long)needed);
    return render_display(fn, img, display, rgba8);
}
