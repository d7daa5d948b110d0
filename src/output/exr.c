/* OpenEXR output through the OpenEXR core C API (OpenEXR 3.1, openexr.h).
 *
 * One scanline part, ZIP compression (lossless, 16 lines per chunk), channels
 *   R, G, B, A                          FLOAT  scene-linear Rec.709 (the chromaticities attribute
 *                                              says which)
 *   variance_R, variance_G, variance_B  FLOAT  the estimated variance of each pixel's mean
 *   samples                             UINT   samples that went into each pixel
 * A multilayer file (bake passes, dwv_image_write_exr_layers) has instead Combined.R, .G, .B, .A
 * and <pass>.R, .G, .B per pass: Blender's layout of a render's passes (layer "<view layer>.
 * <pass>"), with no view layer name, which Blender reads as a render layer named "".
 * Otherwise no channel name has a dot: OpenEXR reads "x.R" as channel R of layer "x", and Blender 3.4 takes
 * a file with any layer (or with more than one part) as multilayer, whose pixels it loads only
 * into render passes (bpy.data.images.load then has no pixels: size 0 x 0). With dotless names
 * Blender loads the file as a plain RGBA image and ignores the extra channels.
 * and metadata (string unless said):
 *   dwivedi:version                  library version "major.minor.patch"
 *   dwivedi:technique                walk technique name ("none" for caller-made pixels)
 *   dwivedi:samples                  int, samples per pixel (the largest per-pixel count)
 *   dwivedi:total_samples, dwivedi:events   decimal uint64 (too large for an int attribute)
 *   dwivedi:seconds                  double, bake time
 *   dwivedi:estimated_relative_error double (inf when nothing was estimated)
 *   dwivedi:features                 comma-separated feature names ("" for none)
 *   dwivedi:feature_bits             int, the DWV_FEATURE_* bits
 *   dwivedi:error_vs_time            one line per completed pass: "seconds relative_error spp",
 *                                    %.17g so that the doubles read back exactly
 * The bytes go through the atomic file helper (a custom write function on its temporary file),
 * so OpenEXR never opens the target itself. */
#include "exr.h"

#include <inttypes.h>
#include <math.h>
#include <openexr.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "atomic_file.h"
#include "util/version.h"

/* What the error handler and the write function share for one file. */
typedef struct exr_sink {
    dwvo_atomic_file file;
} exr_sink;

/* OpenEXR's first message on this thread. OpenEXR delivers messages on the thread that caused
 * them, while it holds the context's lock (so the handler must not call back into the context). */
static _Thread_local char exr_message[256];

/* OpenEXR reports through this instead of printing to stderr (the library never prints). */
static void on_exr_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    (void)ctxt;
    if (exr_message[0] == '\0')
        snprintf(exr_message, sizeof exr_message, "%s (%s)", msg ? msg : "", exr_get_error_code_as_string(code));
}

static int64_t write_to_sink(exr_const_context_t ctxt, void *userdata, const void *buffer, uint64_t sz,
                             uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    exr_sink *sink = userdata;
    if (sz > (uint64_t)INT64_MAX || dwvo_atomic_pwrite(&sink->file, buffer, (size_t)sz, offset) != 0) {
        if (error_cb) error_cb(ctxt, EXR_ERR_WRITE_IO, "%s", sink->file.message);
        return -1;
    }
    return (int64_t)sz;
}

/* "seconds relative_error spp\n" per point; NULL when out of memory. */
static char *error_series_string(const dwvo_exr_image *image)
{
    uint32_t count = image->stats->error_vs_time_count;
    size_t size = (size_t)count * 72u + 1u;
    char *text = malloc(size);
    if (!text) return NULL;
    size_t used = 0u;
    text[0] = '\0';
    for (uint32_t i = 0; i < count; ++i) {
        const dwv_error_point_t *p = &image->error_vs_time[i];
        int n = snprintf(text + used, size - used, "%.17g %.17g %" PRIu64 "\n", p->seconds,
                         p->estimated_relative_error, p->samples_per_pixel);
        if (n < 0 || (size_t)n >= size - used) break;
        used += (size_t)n;
    }
    return text;
}

/* Runs one OpenEXR call; on failure formats the message and jumps to the cleanup. */
#define EXR_CHECK(call, what)                                                                         \
    do {                                                                                              \
        exr_result_t exr_check_rv_ = (call);                                                          \
        if (exr_check_rv_ != EXR_ERR_SUCCESS) {                                                       \
            snprintf(message, size, "cannot write '%s': %s: %s", path, what,                          \
                     sink->file.failed        ? sink->file.message                                    \
                     : exr_message[0]          ? exr_message                                         \
                                              : exr_get_default_error_message(exr_check_rv_));        \
            result = DWV_ERROR_IO;                                                                    \
            goto done;                                                                                \
        }                                                                                             \
    } while (0)

static dwv_result_t set_metadata(exr_context_t ctxt, int part, const dwvo_exr_image *image, exr_sink *sink,
                                 const char *path, char *message, size_t size)
{
    dwv_result_t result = DWV_SUCCESS;
    const dwv_bake_stats_t *stats = image->stats;
    /* Rec.709 / sRGB primaries and the D65 white point (ITU-R BT.709-6, Table 1 items 1.3, 1.4). */
    const exr_attr_chromaticities_t rec709 = {0.640f, 0.330f, 0.300f, 0.600f, 0.150f, 0.060f, 0.3127f, 0.3290f};
    char number[32];
    char *series = NULL;
    EXR_CHECK(exr_attr_set_chromaticities(ctxt, part, "chromaticities", &rec709), "chromaticities");
    EXR_CHECK(exr_attr_set_string(ctxt, part, "dwivedi:version", DWVU_VERSION_STRING), "metadata");
    EXR_CHECK(exr_attr_set_string(ctxt, part, "dwivedi:technique", image->technique), "metadata");
    int32_t spp = stats->samples_per_pixel > (uint64_t)INT32_MAX ? INT32_MAX : (int32_t)stats->samples_per_pixel;
    EXR_CHECK(exr_attr_set_int(ctxt, part, "dwivedi:samples", spp), "metadata");
    snprintf(number, sizeof number, "%" PRIu64, stats->samples);
    EXR_CHECK(exr_attr_set_string(ctxt, part, "dwivedi:total_samples", number), "metadata");
    snprintf(number, sizeof number, "%" PRIu64, stats->events);
    EXR_CHECK(exr_attr_set_string(ctxt, part, "dwivedi:events", number), "metadata");
    EXR_CHECK(exr_attr_set_double(ctxt, part, "dwivedi:seconds", stats->seconds), "metadata");
    double error = stats->samples_per_pixel == 0u ? INFINITY : stats->estimated_relative_error;
    EXR_CHECK(exr_attr_set_double(ctxt, part, "dwivedi:estimated_relative_error", error), "metadata");
    EXR_CHECK(exr_attr_set_string(ctxt, part, "dwivedi:features", image->features), "metadata");
    EXR_CHECK(exr_attr_set_int(ctxt, part, "dwivedi:feature_bits", (int32_t)stats->features), "metadata");
    series = error_series_string(image);
    if (!series) {
        snprintf(message, size, "cannot write '%s': no memory for the error series", path);
        return DWV_ERROR_OUT_OF_MEMORY;
    }
    EXR_CHECK(exr_attr_set_string(ctxt, part, "dwivedi:error_vs_time", series), "metadata");
done:
    free(series);
    return result;
}

/* One channel's source: interleaved `stride` values per pixel starting at `first`. */
typedef struct channel_source {
    const char *name;
    exr_pixel_type_t type;
    exr_perceptual_treatment_t percept;
    const uint8_t *first;
    int32_t stride; /* bytes from one pixel to the next */
} channel_source;

dwv_result_t dwvo_write_exr(const dwvo_exr_image *image, const char *path, char *message, size_t size)
{
    exr_sink *sink = calloc(1, sizeof *sink);
    if (!sink) {
        snprintf(message, size, "cannot write '%s': out of memory", path);
        return DWV_ERROR_OUT_OF_MEMORY;
    }
    exr_message[0] = '\0';
    dwv_result_t result = dwvo_atomic_open(&sink->file, path, message, size);
    if (result != DWV_SUCCESS) {
        free(sink);
        return result;
    }
    const int32_t width = (int32_t)image->width, height = (int32_t)image->height;
    const channel_source plain_sources[] = {
        /* The perceptual flag only steers lossy codecs; colour is "logarithmic" by convention. */
        {"R", EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, (const uint8_t *)(image->rgba + 0), 16},
        {"G", EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, (const uint8_t *)(image->rgba + 1), 16},
        {"B", EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, (const uint8_t *)(image->rgba + 2), 16},
        {"A", EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LINEAR, (const uint8_t *)(image->rgba + 3), 16},
        {"variance_R", EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LINEAR, (const uint8_t *)(image->variance + 0), 12},
        {"variance_G", EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LINEAR, (const uint8_t *)(image->variance + 1), 12},
        {"variance_B", EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LINEAR, (const uint8_t *)(image->variance + 2), 12},
        {"samples", EXR_PIXEL_UINT, EXR_PERCEPTUALLY_LINEAR, (const uint8_t *)image->samples, 4},
    };
    /* Multilayer: Combined.RGBA and 3 channels per layer, names kept in `names`. */
    channel_source layered[4u + 3u * DWVO_EXR_MAX_LAYERS];
    char names[4u + 3u * DWVO_EXR_MAX_LAYERS][64];
    const channel_source *sources = plain_sources;
    size_t source_count = sizeof plain_sources / sizeof *plain_sources;
    if (image->multilayer) {
        static const char rgba_names[4] = {'R', 'G', 'B', 'A'};
        uint32_t layers = image->layer_count < DWVO_EXR_MAX_LAYERS ? image->layer_count : DWVO_EXR_MAX_LAYERS;
        source_count = 0u;
        for (uint32_t layer = 0; layer <= layers; ++layer) {
            int channels = layer == 0u ? 4 : 3;
            for (int c = 0; c < channels; ++c) {
                channel_source *source = &layered[source_count];
                snprintf(names[source_count], sizeof names[source_count], "%s.%c",
                         layer == 0u ? "Combined" : image->layer_names[layer - 1u], rgba_names[c]);
                source->name = names[source_count];
                source->type = EXR_PIXEL_FLOAT;
                source->percept = c == 3 ? EXR_PERCEPTUALLY_LINEAR : EXR_PERCEPTUALLY_LOGARITHMIC;
                source->first = layer == 0u ? (const uint8_t *)(image->rgba + c)
                                            : (const uint8_t *)(image->layer_rgb[layer - 1u] + c);
                source->stride = 4 * channels;
                ++source_count;
            }
        }
        sources = layered;
    }

    exr_context_t ctxt = NULL;
    exr_encode_pipeline_t encoder;
    int encoder_ready = 0;
    memset(&encoder, 0, sizeof encoder);
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = on_exr_error;
    init.user_data = sink;
    init.write_fn = write_to_sink;
    int part = 0;
    EXR_CHECK(exr_start_write(&ctxt, path, EXR_WRITE_FILE_DIRECTLY, &init), "starting");
    /* "dwivedi:estimated_relative_error" has 32 characters: the long-name flag (OpenEXR >= 1.7
     * readers) allows up to 255. */
    EXR_CHECK(exr_set_longname_support(ctxt, 1), "long names");
    EXR_CHECK(exr_add_part(ctxt, "rgba", EXR_STORAGE_SCANLINE, &part), "adding the part");
    EXR_CHECK(exr_initialize_required_attr_simple(ctxt, part, width, height, EXR_COMPRESSION_ZIP), "header");
    for (size_t c = 0; c < source_count; ++c)
        EXR_CHECK(exr_add_channel(ctxt, part, sources[c].name, sources[c].type, sources[c].percept, 1, 1), "channels");
    result = set_metadata(ctxt, part, image, sink, path, message, size);
    if (result != DWV_SUCCESS) goto done;
    EXR_CHECK(exr_write_header(ctxt), "header");

    int32_t lines_per_chunk = 1;
    EXR_CHECK(exr_get_scanlines_per_chunk(ctxt, part, &lines_per_chunk), "chunk layout");
    for (int32_t y = 0; y < height; y += lines_per_chunk) {
        exr_chunk_info_t chunk;
        EXR_CHECK(exr_write_scanline_chunk_info(ctxt, part, y, &chunk), "chunk");
        if (!encoder_ready) {
            EXR_CHECK(exr_encoding_initialize(ctxt, part, &chunk, &encoder), "encoder");
            encoder_ready = 1;
        } else {
            EXR_CHECK(exr_encoding_update(ctxt, part, &chunk, &encoder), "encoder");
        }
        /* The encoder lists channels sorted by name; find each one's source by name. */
        for (int16_t c = 0; c < encoder.channel_count; ++c) {
            exr_coding_channel_info_t *channel = &encoder.channels[c];
            const channel_source *source = NULL;
            for (size_t s = 0; s < source_count; ++s)
                if (strcmp(channel->channel_name, sources[s].name) == 0) source = &sources[s];
            if (!source) {
                snprintf(message, size, "cannot write '%s': OpenEXR listed an unknown channel '%s'", path,
                         channel->channel_name);
                result = DWV_ERROR_INTERNAL;
                goto done;
            }
            channel->user_pixel_stride = source->stride;
            channel->user_line_stride = source->stride * width;
            channel->user_bytes_per_element = 4;
            channel->user_data_type = (uint16_t)source->type;
            channel->encode_from_ptr = source->first + (size_t)chunk.start_y * (size_t)width * (size_t)source->stride;
        }
        if (y == 0) EXR_CHECK(exr_encoding_choose_default_routines(ctxt, part, &encoder), "encoder");
        EXR_CHECK(exr_encoding_run(ctxt, part, &encoder), "encoding pixels");
    }

done:
    if (encoder_ready) exr_encoding_destroy(ctxt, &encoder);
    if (ctxt) {
        /* exr_finish writes the chunk offset table: its failure is a failed file too. */
        exr_result_t finished = exr_finish(&ctxt);
        if (result == DWV_SUCCESS && finished != EXR_ERR_SUCCESS) {
            snprintf(message, size, "cannot write '%s': finishing: %s", path,
                     sink->file.failed ? sink->file.message : exr_get_default_error_message(finished));
            result = DWV_ERROR_IO;
        }
    }
    if (result == DWV_SUCCESS)
        result = dwvo_atomic_commit(&sink->file, message, size);
    else
        dwvo_atomic_abort(&sink->file);
    free(sink);
    return result;
}
