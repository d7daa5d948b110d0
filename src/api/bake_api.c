/* capi entry points of bakes: options checked against the committed scene, the bake handle
 * holding a reference to its scene while it lives. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bake/bake.h"
#include <dwivedi.h>
#include "util/error.h"
#include "image_handle.h"
#include "scene_handle.h"
#include "partial.h"

#define MAX_SIDE 16384u
#define MAX_PIXELS (1u << 26)
#define MAX_SAMPLES (1ull << 24)
#define MAX_THREADS 1024u
#define MAX_MARGIN 64u
#define DEFAULT_TILE 32u
#define SMALLEST_DEFAULT_TILE 8u
#define TILES_PER_THREAD 16u /* enough that the last tiles of a pass even out between workers */
#define DEFAULT_MAX_EVENTS 1000000u
#define MAX_BOUNCES 1024u /* Blender's Light Paths fields stop there */
#define MIN_FILTER_WIDTH 0.01 /* pixels: Blender's Film > Pixel Filter > Width */
#define MAX_FILTER_WIDTH 10.0

static const char *const channel_walks_names[] = {"auto", "shared", "separate"};
#define CHANNEL_WALKS_COUNT ((uint32_t)(sizeof channel_walks_names / sizeof channel_walks_names[0]))

const char *dwv_channel_walks_name(dwv_channel_walks_t channel_walks)
{
    return channel_walks < CHANNEL_WALKS_COUNT ? channel_walks_names[channel_walks] : NULL;
}

dwv_result_t dwv_channel_walks_from_name(const char *name, dwv_channel_walks_t *channel_walks)
{
    DWV_TRY(dwv_check_pointer("dwv_channel_walks_from_name", "name", name));
    DWV_TRY(dwv_check_pointer("dwv_channel_walks_from_name", "channel_walks", channel_walks));
    for (uint32_t i = 0; i < CHANNEL_WALKS_COUNT; ++i) {
        if (strcmp(name, channel_walks_names[i]) == 0) {
            *channel_walks = i;
            return DWV_SUCCESS;
        }
    }
    return dwv_fail(DWV_ERROR_UNKNOWN_NAME,
                    "dwv_channel_walks_from_name: unknown channel walks '%.64s' (auto, shared or separate)", name);
}

/* Indexed by DWV_PIXEL_FILTER_*: the one spelling of the names (scene file, CLI, shim). */
static const char *const pixel_filter_names[] = {"box", "gaussian", "blackman_harris"};
#define PIXEL_FILTER_COUNT ((int32_t)(sizeof pixel_filter_names / sizeof pixel_filter_names[0]))

const char *dwv_pixel_filter_name(dwv_pixel_filter_t pixel_filter)
{
    return pixel_filter >= 0 && pixel_filter < PIXEL_FILTER_COUNT ? pixel_filter_names[pixel_filter] : NULL;
}

/* The filters' names for a message, "box, gaussian or blackman_harris", each after its value
 * when numbered ("0 box, 1 gaussian or 2 blackman_harris"). */
static const char *pixel_filter_list(char *out, size_t size, int numbered)
{
    size_t used = 0;
    out[0] = '\0';
    for (int32_t i = 0; i < PIXEL_FILTER_COUNT && used < size; ++i) {
        const char *separator = i == 0 ? "" : i + 1 == PIXEL_FILTER_COUNT ? " or " : ", ";
        int n = numbered ? snprintf(out + used, size - used, "%s%d %s", separator, (int)i, pixel_filter_names[i])
                         : snprintf(out + used, size - used, "%s%s", separator, pixel_filter_names[i]);
        if (n < 0) break;
        used += (size_t)n;
    }
    return out;
}

dwv_result_t dwv_pixel_filter_from_name(const char *name, dwv_pixel_filter_t *pixel_filter)
{
    DWV_TRY(dwv_check_pointer("dwv_pixel_filter_from_name", "name", name));
    DWV_TRY(dwv_check_pointer("dwv_pixel_filter_from_name", "pixel_filter", pixel_filter));
    for (int32_t i = 0; i < PIXEL_FILTER_COUNT; ++i) {
        if (strcmp(name, pixel_filter_names[i]) == 0) {
            *pixel_filter = i;
            return DWV_SUCCESS;
        }
    }
    char known[64];
    return dwv_fail(DWV_ERROR_UNKNOWN_NAME, "dwv_pixel_filter_from_name: unknown pixel filter '%.64s' (%s)", name,
                    pixel_filter_list(known, sizeof known, 0));
}

struct dwv_bake_s {
    dwvb_bake *bake;
    dwv_scene_t *scene;
};

static dwv_result_t check_options(const char *fn, const dwvb_scene *s, const dwv_bake_options_t *o)
{
    if (o->target != DWV_BAKE_CAMERA && o->target != DWV_BAKE_UV)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: target %d is neither camera (0) nor UV (1)", fn, (int)o->target);
    if (o->width < 1u || o->height < 1u || o->width > MAX_SIDE || o->height > MAX_SIDE ||
        (uint64_t)o->width * o->height > MAX_PIXELS)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: %u x %u pixels: each side must be 1 to %u and at most %u pixels",
                        fn, o->width, o->height, MAX_SIDE, MAX_PIXELS);
    if (o->technique < DWV_TECHNIQUE_AUTO || o->technique > DWV_TECHNIQUE_SHEET)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: technique %d is not known", fn, (int)o->technique);
    if (o->channel_walks > DWV_CHANNEL_WALKS_SEPARATE)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: channel_walks %u is not known (0 auto, 1 shared, 2 separate)", fn, o->channel_walks);
    if (o->samples < 1u || o->samples > MAX_SAMPLES)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: samples = %llu is outside [1, %llu]", fn,
                        (unsigned long long)o->samples, MAX_SAMPLES);
    if (o->sample_count > 0u) {
        if (o->sample_first >= o->samples || o->sample_count > o->samples - o->sample_first)
            return dwv_fail(DWV_ERROR_OUT_OF_RANGE,
                            "%s: the sample range %llu:%llu (first:count) does not lie within the bake's %llu samples",
                            fn, (unsigned long long)o->sample_first, (unsigned long long)o->sample_count,
                            (unsigned long long)o->samples);
        if (o->time_limit != 0.0 || o->target_error != 0.0)
            return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                            "%s: a chunk (sample_count > 0) bakes its whole range: time_limit and target_error must be 0", fn);
        if (o->target != DWV_BAKE_CAMERA)
            return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: split bakes (sample_count > 0) are camera bakes only so far", fn);
    } else if (o->sample_first != 0u) {
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: sample_first = %llu needs sample_count > 0", fn,
                        (unsigned long long)o->sample_first);
    }
    if (o->transparent_background != 0 && o->transparent_background != 1)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: transparent_background = %d is neither 0 nor 1", fn,
                        (int)o->transparent_background);
    if (o->reserved != 0u) return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: reserved = %u must be 0", fn, o->reserved);
    if (o->reserved2 != 0u) return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: reserved2 = %u must be 0", fn, o->reserved2);
    if (o->passes >> DWV_PASS_COUNT)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: passes = 0x%x has bits beyond DWV_PASS_ENVIRONMENT (the mask is DWV_PASS_BIT of dwv_pass_t "
                        "values 0 to %u)", fn, o->passes, DWV_PASS_COUNT - 1u);
    if (o->sample_count > 0u && (o->passes & ~DWV_PASS_BIT(DWV_PASS_COMBINED)))
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: a chunk of a split bake (sample_count > 0) cannot bake passes (passes = 0x%x): partial "
                        "files carry the combined image's sums only; bake the passes whole", fn, o->passes);
    const uint32_t limits[] = {o->max_bounces, o->diffuse_bounces, o->glossy_bounces, o->transmission_bounces,
                               o->min_light_bounces};
    static const char *const limit_names[] = {"max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces",
                                              "min_light_bounces"};
    for (int i = 0; i < 5; ++i)
        if (limits[i] > MAX_BOUNCES)
            return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: %s = %u is above %u (Blender's largest)", fn, limit_names[i],
                            limits[i], MAX_BOUNCES);
    if (o->subsurface_after_diffuse > DWV_SUBSURFACE_AFTER_DIFFUSE_WALK)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: subsurface_after_diffuse %u is not known (0 by model, 1 Lambert, 2 walk)", fn,
                        (unsigned)o->subsurface_after_diffuse);
    if (!isfinite(o->blur_glossy) || o->blur_glossy < 0.0)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE,
                        "%s: blur_glossy = %.17g must be finite and >= 0 (Cycles' Filter Glossy; 0: no blur)", fn,
                        o->blur_glossy);
    if (!dwv_pixel_filter_name(o->pixel_filter)) {
        char known[64];
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: pixel_filter %d is not known (%s)", fn, (int)o->pixel_filter,
                        pixel_filter_list(known, sizeof known, 1));
    }
    if (o->reserved3 != 0u) return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: reserved3 = %u must be 0", fn, o->reserved3);
    if (!(o->filter_width == 0.0 || (o->filter_width >= MIN_FILTER_WIDTH && o->filter_width <= MAX_FILTER_WIDTH)))
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE,
                        "%s: filter_width = %.17g pixels must be 0 (one pixel) or in [%g, %g] (Blender's range)", fn,
                        o->filter_width, MIN_FILTER_WIDTH, MAX_FILTER_WIDTH);
    if (o->uv_jitter != DWV_UV_JITTER_RETRY && o->uv_jitter != DWV_UV_JITTER_MIRROR)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: uv_jitter %d is not known (0 retry, Cycles 3.5+; 1 mirror, Cycles up to 3.4)", fn,
                        (int)o->uv_jitter);
    if (o->reserved4 != 0u) return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: reserved4 = %u must be 0", fn, o->reserved4);
    DWV_TRY(dwv_check_range(fn, "time_limit", o->time_limit, 0.0, HUGE_VAL));
    DWV_TRY(dwv_check_range(fn, "target_error", o->target_error, 0.0, HUGE_VAL));
    if (o->threads > MAX_THREADS)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: threads = %u is above %u", fn, o->threads, MAX_THREADS);
    if (o->target == DWV_BAKE_CAMERA) {
        if (!s->have_camera)
            return dwv_fail(DWV_ERROR_INVALID_STATE, "%s: a camera bake needs a camera (dwv_scene_set_camera)", fn);
    } else {
        if (o->uv_mesh >= s->mesh_count)
            return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: uv_mesh = %u but the scene has %u mesh(es)", fn, o->uv_mesh,
                            s->mesh_count);
        if (!s->meshes[o->uv_mesh].uvs)
            return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: uv_mesh %u has no UVs", fn, o->uv_mesh);
        if (o->uv_margin > MAX_MARGIN)
            return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: uv_margin = %u is above %u", fn, o->uv_margin, MAX_MARGIN);
    }
    return DWV_SUCCESS;
}

/* 32 pixels, halved down to 8 while the image has fewer than TILES_PER_THREAD tiles per thread:
 * small images would otherwise leave one worker idle at the end of every pass. The tile size
 * changes only timing, never the pixels. */
static uint32_t default_tile_size(uint32_t width, uint32_t height, uint32_t threads)
{
    uint32_t tile = DEFAULT_TILE;
    while (tile > SMALLEST_DEFAULT_TILE &&
           (uint64_t)((width + tile - 1u) / tile) * ((height + tile - 1u) / tile) < (uint64_t)TILES_PER_THREAD * threads)
        tile /= 2u;
    return tile;
}

dwv_result_t dwv_bake_start(dwv_scene_t *scene, const dwv_bake_options_t *options, dwv_bake_t **bake)
{
    static const char fn[] = "dwv_bake_start";
    DWV_TRY(dwv_check_pointer(fn, "bake", bake));
    *bake = NULL;
    DWV_TRY(dwv_check_pointer(fn, "scene", scene));
    /* Callers whose struct ends before sample_first (older headers) get 0, 0: a whole bake. */
    DWV_TRY(dwv_check_struct(fn, "options", options, (uint32_t)offsetof(dwv_bake_options_t, sample_first)));
    dwvb_scene *s = dwv_scene_object(scene);
    if (!s->committed) return dwv_fail(DWV_ERROR_INVALID_STATE, "%s: the scene is not committed (dwv_scene_commit)", fn);
    dwv_bake_options_t resolved;
    memset(&resolved, 0, sizeof resolved);
    memcpy(&resolved, options, options->struct_size < sizeof resolved ? options->struct_size : sizeof resolved);
    resolved.struct_size = (uint32_t)sizeof resolved;
    DWV_TRY(check_options(fn, s, &resolved));
    if (resolved.threads == 0u) {
        long cores = sysconf(_SC_NPROCESSORS_ONLN);
        resolved.threads = cores < 1 ? 1u : cores > (long)MAX_THREADS ? MAX_THREADS : (uint32_t)cores;
    }
    if (resolved.tile_size == 0u) resolved.tile_size = default_tile_size(resolved.width, resolved.height, resolved.threads);
    if (resolved.max_events == 0u) resolved.max_events = DEFAULT_MAX_EVENTS;
    /* A direct or indirect pass is shown divided by its lobe's colour (dwv_image_pass): the
     * colour comes with it. */
    for (uint32_t lobe = 0; lobe < 3u; ++lobe)
        if (resolved.passes & (DWV_PASS_BIT(1u + 3u * lobe) | DWV_PASS_BIT(2u + 3u * lobe)))
            resolved.passes |= DWV_PASS_BIT(3u + 3u * lobe);
    dwv_bake_t *handle = calloc(1, sizeof *handle);
    if (!handle) return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: out of memory", fn);
    char message[256];
    dwv_result_t result = dwvb_bake_start(s, &resolved, &handle->bake, message, sizeof message);
    if (result != DWV_SUCCESS) {
        free(handle);
        return dwv_fail(result, "%s: %s", fn, message);
    }
    atomic_fetch_add(&s->references, 1u);
    handle->scene = scene;
    *bake = handle;
    return DWV_SUCCESS;
}

dwv_result_t dwv_bake_wait(dwv_bake_t *bake, double timeout_seconds, int32_t *done)
{
    static const char fn[] = "dwv_bake_wait";
    DWV_TRY(dwv_check_pointer(fn, "bake", bake));
    DWV_TRY(dwv_check_pointer(fn, "done", done));
    if (isnan(timeout_seconds)) return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: timeout_seconds is NaN", fn);
    *done = dwvb_bake_wait(bake->bake, timeout_seconds);
    return DWV_SUCCESS;
}

dwv_result_t dwv_bake_progress(dwv_bake_t *bake, dwv_bake_progress_t *progress)
{
    static const char fn[] = "dwv_bake_progress";
    DWV_TRY(dwv_check_pointer(fn, "bake", bake));
    DWV_TRY(dwv_check_struct(fn, "progress", progress, (uint32_t)sizeof(dwv_bake_progress_t)));
    dwvb_bake_progress(bake->bake, progress);
    return DWV_SUCCESS;
}

dwv_result_t dwv_bake_cancel(dwv_bake_t *bake)
{
    DWV_TRY(dwv_check_pointer("dwv_bake_cancel", "bake", bake));
    dwvb_bake_cancel(bake->bake);
    return DWV_SUCCESS;
}

dwv_result_t dwv_bake_finish(dwv_bake_t *bake, dwv_image_t **image)
{
    static const char fn[] = "dwv_bake_finish";
    DWV_TRY(dwv_check_pointer(fn, "bake", bake));
    DWV_TRY(dwv_check_pointer(fn, "image", image));
    *image = NULL;
    dwvb_image *made = NULL;
    char message[256];
    dwv_result_t result = dwvb_bake_finish(bake->bake, &made, message, sizeof message);
    if (result != DWV_SUCCESS) return dwv_fail(result, "%s: %s", fn, message);
    if (made->partial) {
        made->partial->scene_hash = dwv_scene_hash(dwv_scene_object(bake->scene));
        made->partial->options_hash = dwv_options_hash(dwvb_bake_options(bake->bake));
    }
    *image = dwv_image_handle(made);
    return DWV_SUCCESS;
}

void dwv_bake_release(dwv_bake_t *bake)
{
    if (!bake) return;
    dwvb_bake_free(bake->bake);
    dwv_scene_release(bake->scene);
    free(bake);
}

dwv_result_t dwv_bake(dwv_scene_t *scene, const dwv_bake_options_t *options, dwv_image_t **image)
{
    static const char fn[] = "dwv_bake";
    DWV_TRY(dwv_check_pointer(fn, "image", image));
    *image = NULL;
    dwv_bake_t *bake;
    DWV_TRY(dwv_bake_start(scene, options, &bake));
    dwv_result_t result = dwv_bake_finish(bake, image);
    dwv_bake_release(bake);
    return result;
}
