/* OpenEXR input through the OpenEXR core C API (OpenEXR 3.1, openexr.h): the decoder converts
 * half and uint channels to float into an interleaved buffer, chunk by chunk (scanline blocks or
 * tiles of the full-resolution level). */
#include "exr_reader.h"

#include <errno.h>
#include <openexr.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int dwvo_file_is_exr(const char *path)
{
    static const unsigned char magic[4] = {0x76, 0x2f, 0x31, 0x01};
    unsigned char head[4];
    FILE *f = fopen(path, "rb");
    if (!f) return 0;
    size_t got = fread(head, 1, sizeof head, f);
    fclose(f);
    return got == sizeof head && memcmp(head, magic, sizeof magic) == 0;
}

/* OpenEXR's first message on this thread (it reports through the context's handler, never prints). */
static _Thread_local char exr_message[256];

static void on_exr_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    (void)ctxt;
    if (exr_message[0] == '\0')
        snprintf(exr_message, sizeof exr_message, "%s (%s)", msg ? msg : "", exr_get_error_code_as_string(code));
}

/* The channel slots a file's channel names fill: R G B A, or Y alone. */
typedef struct channel_plan {
    uint32_t count;  /* 1, 3 or 4 */
    int rgb;         /* 1: R, G, B (+ A); 0: Y */
} channel_plan;

static int slot_of(const channel_plan *plan, const char *name)
{
    if (plan->rgb) {
        if (strcmp(name, "R") == 0) return 0;
        if (strcmp(name, "G") == 0) return 1;
        if (strcmp(name, "B") == 0) return 2;
        if (strcmp(name, "A") == 0 && plan->count == 4u) return 3;
        return -1;
    }
    return strcmp(name, "Y") == 0 ? 0 : -1;
}

/* Decodes one chunk into the top-down interleaved buffer `out` of `width` texels a row, its first
 * texel at column x0, row y0 of the data window (OpenEXR 3.1 gives a tile's start_x / start_y as
 * tile numbers, not pixels: the caller says where it goes), through
 * `scratch` (one plane per channel slot, *scratch_size bytes, grown as needed). Each channel is
 * decoded into its own plane and interleaved here: OpenEXR 3.1's fast paths for interleaved
 * half channels write them in the file's (sorted) order whatever the pointers say. */
static exr_result_t decode_chunk(exr_context_t ctxt, const exr_chunk_info_t *chunk, exr_decode_pipeline_t *decoder,
                                 int *ready, const channel_plan *plan, size_t x0, size_t y0, float *out,
                                 uint32_t width, float **scratch, size_t *scratch_size)
{
    exr_result_t rv = *ready ? exr_decoding_update(ctxt, 0, chunk, decoder)
                             : exr_decoding_initialize(ctxt, 0, chunk, decoder);
    if (rv != EXR_ERR_SUCCESS) return rv;
    *ready = 1;
    size_t cw = (size_t)chunk->width, ch = (size_t)chunk->height, plane = cw * ch;
    size_t need = plane * plan->count * sizeof(float);
    if (need > *scratch_size) {
        float *grown = realloc(*scratch, need);
        if (!grown) return EXR_ERR_OUT_OF_MEMORY;
        *scratch = grown;
        *scratch_size = need;
    }
    for (int16_t c = 0; c < decoder->channel_count; ++c) {
        exr_coding_channel_info_t *channel = &decoder->channels[c];
        int slot = slot_of(plan, channel->channel_name);
        channel->user_bytes_per_element = 4;
        channel->user_data_type = EXR_PIXEL_FLOAT;
        channel->user_pixel_stride = (int32_t)sizeof(float);
        channel->user_line_stride = (int32_t)(cw * sizeof(float));
        channel->decode_to_ptr = slot < 0 ? NULL : (uint8_t *)(*scratch + (size_t)slot * plane);
    }
    /* The routines depend on the pointers' layout: chosen again for every chunk (cheap). */
    rv = exr_decoding_choose_default_routines(ctxt, 0, decoder);
    if (rv == EXR_ERR_SUCCESS) rv = exr_decoding_run(ctxt, 0, decoder);
    if (rv != EXR_ERR_SUCCESS) return rv;
    for (size_t y = 0; y < ch; ++y)
        for (size_t x = 0; x < cw; ++x)
            for (uint32_t k = 0; k < plan->count; ++k)
                out[((y0 + y) * width + x0 + x) * plan->count + k] = (*scratch)[k * plane + y * cw + x];
    return EXR_ERR_SUCCESS;
}

dwv_result_t dwvo_read_exr_float(const char *path, uint32_t max_side, uint64_t max_texels, uint32_t *width,
                                 uint32_t *height, uint32_t *channels, float **pixels, char *message, size_t size)
{
    *pixels = NULL;
    FILE *probe = fopen(path, "rb");
    if (!probe) {
        snprintf(message, size, "cannot read EXR '%s': %s", path, strerror(errno));
        return DWV_ERROR_IO;
    }
    fclose(probe);
    exr_message[0] = '\0';
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = on_exr_error;
    exr_context_t ctxt = NULL;
    dwv_result_t result = DWV_SUCCESS;
    float *data = NULL, *scratch = NULL;
    size_t scratch_size = 0;
    exr_decode_pipeline_t decoder;
    memset(&decoder, 0, sizeof decoder);
    int ready = 0;
    exr_result_t rv = exr_start_read(&ctxt, path, &init);
#define EXR_FAIL(what)                                                                                      \
    do {                                                                                                    \
        snprintf(message, size, "cannot read EXR '%s': %s: %s", path, what,                                 \
                 exr_message[0] ? exr_message : exr_get_default_error_message(rv));                         \
        result = DWV_ERROR_FORMAT;                                                                          \
        goto done;                                                                                          \
    } while (0)
    if (rv != EXR_ERR_SUCCESS) EXR_FAIL("header");
    exr_storage_t storage;
    exr_attr_box2i_t window;
    const exr_attr_chlist_t *list = NULL;
    if ((rv = exr_get_storage(ctxt, 0, &storage)) != EXR_ERR_SUCCESS) EXR_FAIL("storage");
    if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED) {
        snprintf(message, size, "cannot read EXR '%s': it holds deep data (not an image of one value a pixel)", path);
        result = DWV_ERROR_FORMAT;
        goto done;
    }
    if ((rv = exr_get_data_window(ctxt, 0, &window)) != EXR_ERR_SUCCESS) EXR_FAIL("data window");
    if ((rv = exr_get_channels(ctxt, 0, &list)) != EXR_ERR_SUCCESS) EXR_FAIL("channels");
    int64_t w = (int64_t)window.max.x - window.min.x + 1, h = (int64_t)window.max.y - window.min.y + 1;
    if (w < 1 || h < 1 || w > (int64_t)max_side || h > (int64_t)max_side || (uint64_t)w * (uint64_t)h > max_texels) {
        snprintf(message, size, "EXR '%s' is %lld x %lld pixels (1 to %u a side, at most %llu in all)", path,
                 (long long)(w > 0 ? w : 0), (long long)(h > 0 ? h : 0), max_side, (unsigned long long)max_texels);
        result = DWV_ERROR_FORMAT;
        goto done;
    }
    int have[5] = {0, 0, 0, 0, 0}; /* R G B A Y */
    static const char *const wanted[5] = {"R", "G", "B", "A", "Y"};
    for (int c = 0; c < list->num_channels; ++c) {
        const exr_attr_chlist_entry_t *e = &list->entries[c];
        for (int k = 0; k < 5; ++k)
            if (strcmp(e->name.str, wanted[k]) == 0) {
                if (e->x_sampling != 1 || e->y_sampling != 1) {
                    snprintf(message, size, "cannot read EXR '%s': channel %s is sub-sampled (%d x %d)", path,
                             wanted[k], e->x_sampling, e->y_sampling);
                    result = DWV_ERROR_FORMAT;
                    goto done;
                }
                have[k] = 1;
            }
    }
    channel_plan plan;
    if (have[0] && have[1] && have[2]) plan = (channel_plan){have[3] ? 4u : 3u, 1};
    else if (have[4]) plan = (channel_plan){1u, 0};
    else {
        snprintf(message, size, "EXR '%s' has no R, G, B channels and no Y channel (its first is '%s'%s)", path,
                 list->num_channels ? list->entries[0].name.str : "",
                 list->num_channels && strchr(list->entries[0].name.str, '.') ? ": a multi-layer file" : "");
        result = DWV_ERROR_FORMAT;
        goto done;
    }
    data = calloc((size_t)w * (size_t)h * plan.count, sizeof *data);
    if (!data) {
        snprintf(message, size, "no memory for EXR '%s' (%lld x %lld)", path, (long long)w, (long long)h);
        result = DWV_ERROR_OUT_OF_MEMORY;
        goto done;
    }
    if (storage == EXR_STORAGE_SCANLINE) {
        int32_t lines = 1;
        if ((rv = exr_get_scanlines_per_chunk(ctxt, 0, &lines)) != EXR_ERR_SUCCESS) EXR_FAIL("chunk layout");
        for (int64_t y = window.min.y; y <= window.max.y; y += lines) {
            exr_chunk_info_t chunk;
            if ((rv = exr_read_scanline_chunk_info(ctxt, 0, (int)y, &chunk)) != EXR_ERR_SUCCESS) EXR_FAIL("scanlines");
            if ((rv = decode_chunk(ctxt, &chunk, &decoder, &ready, &plan, 0u, (size_t)(y - window.min.y), data,
                                   (uint32_t)w, &scratch, &scratch_size)) != EXR_ERR_SUCCESS)
                EXR_FAIL("decoding scanlines");
        }
    } else {
        int32_t tile_w = 0, tile_h = 0;
        if ((rv = exr_get_tile_sizes(ctxt, 0, 0, 0, &tile_w, &tile_h)) != EXR_ERR_SUCCESS || tile_w < 1 || tile_h < 1)
            EXR_FAIL("tile sizes");
        int64_t across = (w + tile_w - 1) / tile_w, down = (h + tile_h - 1) / tile_h;
        for (int64_t ty = 0; ty < down; ++ty)
            for (int64_t tx = 0; tx < across; ++tx) {
                exr_chunk_info_t chunk;
                if ((rv = exr_read_tile_chunk_info(ctxt, 0, (int)tx, (int)ty, 0, 0, &chunk)) != EXR_ERR_SUCCESS)
                    EXR_FAIL("tiles");
                if ((rv = decode_chunk(ctxt, &chunk, &decoder, &ready, &plan, (size_t)(tx * tile_w),
                                       (size_t)(ty * tile_h), data, (uint32_t)w, &scratch, &scratch_size)) !=
                    EXR_ERR_SUCCESS)
                    EXR_FAIL("decoding tiles");
            }
    }
#undef EXR_FAIL
    /* EXR rows run top-down; textures are bottom-up. */
    size_t row = (size_t)w * plan.count;
    for (int64_t y = 0; y < h / 2; ++y) {
        float *a = data + (size_t)y * row, *b = data + (size_t)(h - 1 - y) * row;
        for (size_t i = 0; i < row; ++i) {
            float t = a[i];
            a[i] = b[i];
            b[i] = t;
        }
    }
    *width = (uint32_t)w;
    *height = (uint32_t)h;
    *channels = plan.count;
    *pixels = data;
    data = NULL;
done:
    if (ready) exr_decoding_destroy(ctxt, &decoder);
    if (ctxt) exr_finish(&ctxt);
    free(data);
    free(scratch);
    return result;
}
