/* Image output against outside references:
 *   - the EXR reads back through OpenEXR's own core read API bit for bit (every channel) and its
 *     header through OpenEXR's `exrheader` tool (channels, chromaticities, dwivedi metadata);
 *   - the display bytes (and the PNG, decoded by libpng) equal OpenColorIO's own `ocioconvert
 *     --view` of the same pixels with the same config, within one 8-bit level (our rounding against
 *     OpenImageIO's), for the built-in config and an explicit path, Standard and Filmic views;
 *   - exposure, gamma and a look against closed forms (Raw view: identity; sRGB curve, IEC 61966-2-1);
 *   - premultiplied colour becomes straight colour before the view (Blender's save_render);
 *   - atomic writes: a write that fails part way (a file-size limit, RLIMIT_FSIZE) leaves the good
 *     file byte-identical and no temporary file; a successful one replaces it and keeps its mode;
 *   - argument checks, unknown names, NaN and infinite pixels.
 * Internal (static archive) because it builds images with NaN, variance and stats, which the
 * public dwv_image_create refuses or does not take. */
#define _POSIX_C_SOURCE 200809L

#include <dirent.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <openexr.h>
#include <png.h>
#include <pthread.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "api/image_handle.h"
#include "check.h"
#include <dwivedi.h>

#define W 37 /* not a multiple of anything: partial ZIP chunks (16 lines) and odd rows */
#define H 23

static char work[512];
static char config_path[1024];

static void path_in(char *out, size_t size, const char *name)
{
    snprintf(out, size, "%s/%s", work, name);
}

/* ---- small helpers ------------------------------------------------------------------------- */

static unsigned char *read_all(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *data = malloc((size_t)n + 1u);
    if (data && fread(data, 1, (size_t)n, f) != (size_t)n) {
        free(data);
        data = NULL;
    }
    fclose(f);
    if (data) data[n] = 0;
    *size = (size_t)n;
    return data;
}

static int same_file(const char *path, const unsigned char *bytes, size_t size)
{
    size_t n = 0;
    unsigned char *now = read_all(path, &n);
    int same = now && n == size && memcmp(now, bytes, size) == 0;
    free(now);
    return same;
}

/* Files in the work folder whose names end in ".tmp" (the helper's temporary names). */
static int temp_files(void)
{
    DIR *dir = opendir(work);
    if (!dir) return -1;
    int count = 0;
    struct dirent *entry;
    while ((entry = readdir(dir))) {
        size_t n = strlen(entry->d_name);
        if (n > 4 && strcmp(entry->d_name + n - 4, ".tmp") == 0) ++count;
    }
    closedir(dir);
    return count;
}

static char *run(const char *command)
{
    FILE *p = popen(command, "r");
    if (!p) return NULL;
    size_t cap = 1 << 16, used = 0;
    char *out = malloc(cap);
    size_t n;
    while (out && (n = fread(out + used, 1, cap - 1 - used, p)) > 0) used += n;
    int status = pclose(p);
    if (!out) return NULL;
    out[used] = 0;
    if (status != 0) {
        fprintf(stderr, "command failed (%d): %s\n%s\n", status, command, out);
        free(out);
        return NULL;
    }
    return out;
}

/* An image with every channel varied: colours from negative to far above 1, alpha in [0, 1],
 * variance and sample counts, stats and an error series. */
static dwvb_image *make_image(void)
{
    dwvb_image *img = dwvb_image_new(W, H);
    for (uint32_t y = 0; y < H; ++y)
        for (uint32_t x = 0; x < W; ++x) {
            size_t i = (size_t)y * W + x;
            float t = (float)i / (W * H);
            img->rgba[4 * i + 0] = 8.0f * t * t;                       /* 0 .. 8 */
            img->rgba[4 * i + 1] = 0.18f * (float)(x % 7) / 3.0f;      /* 0 .. 0.36 */
            img->rgba[4 * i + 2] = (float)y / H - 0.05f;               /* slightly negative .. 0.9 */
            img->rgba[4 * i + 3] = (float)(x % 5) / 4.0f;              /* 0 .. 1 */
            img->variance[3 * i + 0] = 1e-4f * t;
            img->variance[3 * i + 1] = 2e-4f * (1.0f - t);
            img->variance[3 * i + 2] = 1e-30f * (float)x;              /* tiny values too */
            img->samples[i] = (uint32_t)(i * 2654435761u);             /* all 32 bits used */
        }
    img->stats.technique = DWV_TECHNIQUE_INCIDENT;
    img->stats.samples_per_pixel = 64;
    img->stats.samples = 64u * W * H;
    img->stats.events = 12345678901234ull;
    img->stats.seconds = 1.25;
    img->stats.estimated_relative_error = 0.0123;
    /* Every name from dwv_feature_name (the sheet's too), and a bit no version names yet. */
    img->stats.features = DWV_FEATURE_EMBREE | DWV_FEATURE_SUBSURFACE | DWV_FEATURE_GUIDED | DWV_FEATURE_SHEET | (1u << 20);
    dwv_error_point_t p1 = {0.5, 0.05, 16}, p2 = {1.25, 0.0123, 64};
    dwvb_image_add_error_point(img, p1);
    dwvb_image_add_error_point(img, p2);
    return img;
}

/* ---- reading EXR through OpenEXR's core API -------------------------------------------------- */

typedef struct exr_channels {
    int count;
    char names[16][32];
    int types[16];
    void *data[16]; /* width x height, 4 bytes each (FLOAT as float, UINT as uint32) */
    int width, height;
} exr_channels;

static void silent(exr_const_context_t c, exr_result_t code, const char *msg)
{
    (void)c, (void)code, (void)msg;
}

static int read_exr(const char *path, exr_channels *out, exr_context_t *keep)
{
    memset(out, 0, sizeof *out);
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = silent;
    exr_context_t c = NULL;
    if (exr_start_read(&c, path, &init) != EXR_ERR_SUCCESS) return -1;
    exr_attr_box2i_t dw;
    const exr_attr_chlist_t *list = NULL;
    int32_t lines = 0;
    if (exr_get_data_window(c, 0, &dw) || exr_get_channels(c, 0, &list) || exr_get_scanlines_per_chunk(c, 0, &lines))
        return -1;
    out->width = dw.max.x - dw.min.x + 1;
    out->height = dw.max.y - dw.min.y + 1;
    out->count = list->num_channels < 16 ? list->num_channels : 16;
    for (int k = 0; k < out->count; ++k) {
        snprintf(out->names[k], sizeof out->names[k], "%s", list->entries[k].name.str);
        out->types[k] = list->entries[k].pixel_type;
        out->data[k] = calloc((size_t)out->width * out->height, 4);
    }
    exr_decode_pipeline_t decoder;
    memset(&decoder, 0, sizeof decoder);
    int ready = 0, failed = 0;
    for (int y = dw.min.y; y <= dw.max.y && !failed; y += lines) {
        exr_chunk_info_t chunk;
        if (exr_read_scanline_chunk_info(c, 0, y, &chunk)) failed = 1;
        else if (!ready ? exr_decoding_initialize(c, 0, &chunk, &decoder) : exr_decoding_update(c, 0, &chunk, &decoder))
            failed = 1;
        if (failed) break;
        for (int k = 0; k < decoder.channel_count; ++k) {
            exr_coding_channel_info_t *ch = &decoder.channels[k];
            int slot = -1;
            for (int s = 0; s < out->count; ++s)
                if (strcmp(out->names[s], ch->channel_name) == 0) slot = s;
            ch->user_bytes_per_element = 4;
            ch->user_data_type = ch->data_type == EXR_PIXEL_UINT ? EXR_PIXEL_UINT : EXR_PIXEL_FLOAT;
            ch->user_pixel_stride = 4;
            ch->user_line_stride = 4 * out->width;
            ch->decode_to_ptr = (uint8_t *)out->data[slot] + (size_t)(chunk.start_y - dw.min.y) * out->width * 4;
        }
        if (!ready && exr_decoding_choose_default_routines(c, 0, &decoder)) failed = 1;
        ready = 1;
        if (!failed && exr_decoding_run(c, 0, &decoder)) failed = 1;
    }
    if (ready) exr_decoding_destroy(c, &decoder);
    if (keep && !failed) *keep = c;
    else exr_finish(&c);
    return failed ? -1 : 0;
}

static void free_channels(exr_channels *ch)
{
    for (int k = 0; k < ch->count; ++k) free(ch->data[k]);
}

static const void *channel(const exr_channels *ch, const char *name, int *type)
{
    for (int k = 0; k < ch->count; ++k)
        if (strcmp(ch->names[k], name) == 0) {
            if (type) *type = ch->types[k];
            return ch->data[k];
        }
    return NULL;
}


/* A plain RGBA FLOAT EXR written here with OpenEXR's core API (ocioconvert processes only files
 * whose channels are exactly RGB or RGBA). Returns 0 on success. */
static int write_plain_exr(const char *path, const float *rgba, int width, int height)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = silent;
    exr_context_t c = NULL;
    int part = 0, failed = 0;
    if (exr_start_write(&c, path, EXR_WRITE_FILE_DIRECTLY, &init)) return -1;
    const char *names[4] = {"R", "G", "B", "A"};
    failed |= exr_add_part(c, NULL, EXR_STORAGE_SCANLINE, &part) != 0;
    failed |= exr_initialize_required_attr_simple(c, part, width, height, EXR_COMPRESSION_NONE) != 0;
    for (int k = 0; k < 4 && !failed; ++k)
        failed |= exr_add_channel(c, part, names[k], EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1) != 0;
    failed |= !failed && exr_write_header(c) != 0;
    int32_t lines = 1;
    if (!failed) failed |= exr_get_scanlines_per_chunk(c, part, &lines) != 0;
    exr_encode_pipeline_t encoder;
    memset(&encoder, 0, sizeof encoder);
    int ready = 0;
    for (int y = 0; y < height && !failed; y += lines) {
        exr_chunk_info_t chunk;
        failed |= exr_write_scanline_chunk_info(c, part, y, &chunk) != 0;
        if (failed) break;
        failed |= (!ready ? exr_encoding_initialize(c, part, &chunk, &encoder)
                          : exr_encoding_update(c, part, &chunk, &encoder)) != 0;
        if (failed) break;
        for (int k = 0; k < encoder.channel_count; ++k) {
            exr_coding_channel_info_t *ch = &encoder.channels[k];
            int index = ch->channel_name[0] == 'R' ? 0 : ch->channel_name[0] == 'G' ? 1 : ch->channel_name[0] == 'B' ? 2 : 3;
            ch->user_pixel_stride = 16;
            ch->user_line_stride = 16 * width;
            ch->user_bytes_per_element = 4;
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->encode_from_ptr = (const uint8_t *)(rgba + (size_t)chunk.start_y * width * 4 + index);
        }
        if (!ready) failed |= exr_encoding_choose_default_routines(c, part, &encoder) != 0;
        ready = 1;
        if (!failed) failed |= exr_encoding_run(c, part, &encoder) != 0;
    }
    if (ready) exr_encoding_destroy(c, &encoder);
    failed |= exr_finish(&c) != 0;
    return failed ? -1 : 0;
}

/* ---- the tests ------------------------------------------------------------------------------- */

static void test_exr_round_trip(void)
{
    dwvb_image *img = make_image();
    char path[600];
    path_in(path, sizeof path, "image.exr");
    dwv_result_t r = dwv_image_write_exr(dwv_image_handle(img), path);
    CHECK(r == DWV_SUCCESS, "write_exr: %s", dwv_last_error_message());

    exr_channels ch;
    exr_context_t c = NULL;
    CHECK(read_exr(path, &ch, &c) == 0, "OpenEXR's core API reads the file back");
    CHECK(ch.width == W && ch.height == H, "size %d x %d", ch.width, ch.height);
    CHECK(ch.count == 8, "8 channels, got %d", ch.count);
    /* A dot makes a layer ("x.R" is R of layer x), and Blender 3.4 loads a file with layers only
     * as render passes, with no pixels for bpy.data.images.load: see src/output/exr.c. */
    for (int k = 0; k < ch.count; ++k) CHECK(strchr(ch.names[k], '.') == NULL, "channel '%s' has no dot", ch.names[k]);
    const char *floats[] = {"R", "G", "B", "A", "variance_R", "variance_G", "variance_B"};
    for (int k = 0; k < 7; ++k) {
        int type = -1;
        const float *data = channel(&ch, floats[k], &type);
        CHECK(data && type == EXR_PIXEL_FLOAT, "channel %s is FLOAT", floats[k]);
        if (!data) continue;
        size_t mismatches = 0;
        for (size_t i = 0; i < (size_t)W * H; ++i) {
            float want = k < 4 ? img->rgba[4 * i + (size_t)k] : img->variance[3 * i + (size_t)(k - 4)];
            if (memcmp(&data[i], &want, 4) != 0) ++mismatches;
        }
        CHECK(mismatches == 0, "channel %s: %zu pixels differ in their bits", floats[k], mismatches);
    }
    int type = -1;
    const uint32_t *samples = channel(&ch, "samples", &type);
    CHECK(samples && type == EXR_PIXEL_UINT, "samples is UINT");
    if (samples) CHECK(memcmp(samples, img->samples, (size_t)W * H * 4) == 0, "samples equals the counts");

    if (c) {
        exr_attr_chromaticities_t chroma;
        CHECK(exr_attr_get_chromaticities(c, 0, "chromaticities", &chroma) == EXR_ERR_SUCCESS, "chromaticities");
        CHECK(chroma.red_x == 0.64f && chroma.red_y == 0.33f && chroma.green_x == 0.30f && chroma.green_y == 0.60f &&
                  chroma.blue_x == 0.15f && chroma.blue_y == 0.06f && chroma.white_x == 0.3127f &&
                  chroma.white_y == 0.3290f,
              "Rec.709 primaries and D65 white");
        const char *s = NULL;
        int32_t n = 0;
        CHECK(exr_attr_get_string(c, 0, "dwivedi:technique", &n, &s) == 0 && s && strncmp(s, "incident", (size_t)n) == 0,
              "technique %.*s", n, s ? s : "");
        CHECK(exr_attr_get_string(c, 0, "dwivedi:version", &n, &s) == 0 && s &&
                  strncmp(s, dwv_version_string(), (size_t)n) == 0,
              "version %.*s", n, s ? s : "");
        CHECK(exr_attr_get_string(c, 0, "dwivedi:features", &n, &s) == 0 && s &&
                  strncmp(s, "embree,subsurface,guided,sheet,bit20", (size_t)n) == 0 && n == 36,
              "features %.*s", n, s ? s : "");
        CHECK(exr_attr_get_string(c, 0, "dwivedi:events", &n, &s) == 0 && s && strncmp(s, "12345678901234", (size_t)n) == 0,
              "events %.*s", n, s ? s : "");
        CHECK(exr_attr_get_string(c, 0, "dwivedi:error_vs_time", &n, &s) == 0 && s &&
                  strncmp(s, "0.5 0.050000000000000003 16\n1.25 0.0123 64\n", (size_t)n) == 0,
              "error series '%.*s'", n, s ? s : "");
        int32_t spp = 0;
        double seconds = 0, error = 0;
        CHECK(exr_attr_get_int(c, 0, "dwivedi:samples", &spp) == 0 && spp == 64, "samples %d", spp);
        CHECK(exr_attr_get_double(c, 0, "dwivedi:seconds", &seconds) == 0 && seconds == 1.25, "seconds %g", seconds);
        CHECK(exr_attr_get_double(c, 0, "dwivedi:estimated_relative_error", &error) == 0 && error == 0.0123,
              "error %g", error);
        exr_compression_t compression;
        CHECK(exr_get_compression(c, 0, &compression) == 0 && compression == EXR_COMPRESSION_ZIP, "ZIP");
        exr_finish(&c);
    }
    free_channels(&ch);

    /* OpenEXR's own command-line reader. */
    char command[800];
    snprintf(command, sizeof command, "exrheader '%s' 2>&1", path);
    char *header = run(command);
    CHECK(header != NULL, "exrheader runs");
    if (header) {
        const char *expected[] = {"chromaticities", "red   (0.64 0.33)", "white (0.3127 0.329)", "    R, 32-bit floating-point",
                                  "    A, 32-bit floating-point", "    variance_G, 32-bit floating-point",
                                  "    samples, 32-bit unsigned integer", "zip", "dwivedi:technique (type string): \"incident\"",
                                  "dwivedi:samples (type int): 64", "dwivedi:seconds (type double): 1.25",
                                  "dwivedi:estimated_relative_error (type double)", "dwivedi:version (type string)",
                                  "dwivedi:features (type string): \"embree,subsurface,guided,sheet,bit20\"", "dwivedi:error_vs_time"};
        for (size_t k = 0; k < sizeof expected / sizeof *expected; ++k)
            CHECK(strstr(header, expected[k]) != NULL, "exrheader shows '%s':\n%s", expected[k], header);
        free(header);
    }
    dwv_image_release(dwv_image_handle(img));
}

static float srgb_encode(float v) /* IEC 61966-2-1 */
{
    if (v <= 0.0031308f) return 12.92f * v;
    return 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
}

/* Value i of premultiplied RGBA pixels as straight colour: colour / alpha where alpha is neither 0
 * nor 1 (Blender's rule, docs/output.md), alpha itself unchanged. */
static float straight_value(const float *rgba, size_t i)
{
    float alpha = rgba[i - i % 4 + 3];
    if (i % 4 == 3 || alpha == 0.0f || alpha == 1.0f) return rgba[i];
    return rgba[i] / alpha;
}

static int quantise(float v)
{
    if (!(v > 0.0f)) return 0;
    if (v >= 1.0f) return 255;
    return (int)(v * 255.0f + 0.5f);
}

/* dwv_image_to_display against ocioconvert --view of the same pixels (within one 8-bit level), and
 * the PNG (decoded by libpng) against dwv_image_to_display (exactly). */
static void test_display_against_ocioconvert(const char *view, int explicit_config)
{
    dwvb_image *img = make_image();
    dwv_image_t *image = dwv_image_handle(img);
    char exr[600], out[600], png[600], command[2600];
    path_in(exr, sizeof exr, "linear.exr");
    snprintf(out, sizeof out, "%s/ocio_%s.exr", work, view);
    path_in(png, sizeof png, "display.png");
    /* The display transform sees straight colour (rgb / alpha, as Blender's save_render), while
     * ocioconvert transforms the values as they are: give it the un-premultiplied pixels. */
    float *straight = malloc((size_t)W * H * 4 * sizeof *straight);
    for (size_t i = 0; i < (size_t)W * H * 4; ++i) straight[i] = straight_value(img->rgba, i);
    CHECK(write_plain_exr(exr, straight, W, H) == 0, "the test's own EXR writer");
    free(straight);
    snprintf(command, sizeof command, "OCIO='%s' ocioconvert --view '%s' 'Linear Rec.709' '%s' sRGB '%s' 2>&1",
             config_path, exr, out, view);
    char *log = run(command);
    CHECK(log != NULL, "ocioconvert runs: %s", command);
    free(log);

    dwv_display_options_t options = DWV_DISPLAY_OPTIONS_INIT;
    options.config_path = explicit_config ? config_path : NULL;
    options.display = "sRGB";
    options.view = view;
    unsetenv("OCIO");
    uint8_t *mine = malloc((size_t)W * H * 4);
    dwv_result_t r = dwv_image_to_display(image, &options, mine, (uint64_t)W * H * 4);
    CHECK(r == DWV_SUCCESS, "to_display %s: %s", view, dwv_last_error_message());

    exr_channels ch;
    if (read_exr(out, &ch, NULL) == 0 && ch.width == W && ch.height == H) {
        const char *names[] = {"R", "G", "B", "A"};
        int worst = 0;
        size_t worst_at = 0;
        for (int k = 0; k < 4; ++k) {
            const float *data = channel(&ch, names[k], NULL);
            CHECK(data != NULL, "ocioconvert's output has %s", names[k]);
            if (!data) continue;
            for (size_t i = 0; i < (size_t)W * H; ++i) {
                int d = abs(quantise(data[i]) - (int)mine[4 * i + (size_t)k]);
                if (d > worst) worst = d, worst_at = 4 * i + (size_t)k;
            }
        }
        printf("%s view, %s config: largest difference from ocioconvert %d of 255\n", view,
               explicit_config ? "explicit" : "built-in", worst);
        CHECK(worst <= 1, "%s view (%s config): differs from ocioconvert by %d levels at value %zu", view,
              explicit_config ? "explicit" : "built-in", worst, worst_at);
        /* Not a vacuous comparison: the view spreads the values over the 8-bit range. */
        int lo = 255, hi = 0;
        for (size_t i = 0; i < (size_t)W * H * 4; i += 4) {
            if (mine[i] < lo) lo = mine[i];
            if (mine[i] > hi) hi = mine[i];
        }
        CHECK(lo < 10 && hi > 200, "red spans %d..%d", lo, hi);
    } else {
        CHECK(0, "cannot read ocioconvert's output %s", out);
    }
    free_channels(&ch);

    r = dwv_image_write_display_png(image, png, &options);
    CHECK(r == DWV_SUCCESS, "write_display_png: %s", dwv_last_error_message());
    png_image decoded;
    memset(&decoded, 0, sizeof decoded);
    decoded.version = PNG_IMAGE_VERSION;
    if (png_image_begin_read_from_file(&decoded, png)) {
        CHECK(decoded.width == W && decoded.height == H, "PNG size %u x %u", decoded.width, decoded.height);
        decoded.format = PNG_FORMAT_RGBA;
        uint8_t *bytes = malloc(PNG_IMAGE_SIZE(decoded));
        CHECK(png_image_finish_read(&decoded, NULL, bytes, 0, NULL), "libpng decodes: %s", decoded.message);
        CHECK(memcmp(bytes, mine, (size_t)W * H * 4) == 0, "the PNG holds the display bytes");
        free(bytes);
    } else {
        CHECK(0, "libpng cannot open the PNG: %s", decoded.message);
    }
    png_image_free(&decoded);
    free(mine);
    dwv_image_release(image);
}

/* Exposure, gamma and a look against closed forms. The Raw view is the identity, so there the
 * bytes must be round(255 clamp(2^e v)^(1/gamma)); Standard is the sRGB curve; the High Contrast
 * look is 0.18 (v / 0.18)^1.25 before it. */
static void test_exposure_gamma_look(void)
{
    dwvb_image *img = make_image();
    dwv_image_t *image = dwv_image_handle(img);
    uint8_t *bytes = malloc((size_t)W * H * 4);
    dwv_display_options_t o = DWV_DISPLAY_OPTIONS_INIT;
    o.view = "Raw";
    o.exposure = -1.5;
    o.gamma = 2.2;
    unsetenv("OCIO");
    CHECK(dwv_image_to_display(image, &o, bytes, (uint64_t)W * H * 4) == DWV_SUCCESS, "%s", dwv_last_error_message());
    int worst = 0;
    for (size_t i = 0; i < (size_t)W * H * 4; ++i) {
        float v = straight_value(img->rgba, i);
        float want = (i % 4 == 3) ? v : powf(fmaxf(v * exp2f(-1.5f), 0.0f), 1.0f / 2.2f);
        int d = abs(quantise(want) - bytes[i]);
        if (d > worst) worst = d;
    }
    CHECK(worst <= 1, "exposure -1.5, gamma 2.2 through Raw: off by %d levels", worst);

    o.view = "Standard";
    o.exposure = 0.0;
    o.gamma = 1.0;
    o.look = "High Contrast";
    CHECK(dwv_image_to_display(image, &o, bytes, (uint64_t)W * H * 4) == DWV_SUCCESS, "%s", dwv_last_error_message());
    worst = 0;
    int changed = 0;
    for (size_t i = 0; i < (size_t)W * H * 4; ++i) {
        if (i % 4 == 3) continue;
        float v = fmaxf(straight_value(img->rgba, i), 0.0f);
        float want = srgb_encode(0.18f * powf(v / 0.18f, 1.25f));
        int d = abs(quantise(want) - bytes[i]);
        if (d > worst) worst = d;
        if (quantise(srgb_encode(v)) != bytes[i]) ++changed;
    }
    CHECK(worst <= 1, "High Contrast look through Standard: off by %d levels", worst);
    CHECK(changed > 100, "the look changes pixels (%d)", changed);

    /* Exposure by whole stops equals scaling the pixels (powers of two are exact in float). */
    uint8_t *scaled_bytes = malloc((size_t)W * H * 4);
    float *scaled = malloc((size_t)W * H * 4 * sizeof *scaled);
    for (size_t i = 0; i < (size_t)W * H * 4; ++i) scaled[i] = (i % 4 == 3) ? img->rgba[i] : img->rgba[i] * 4.0f;
    dwv_image_t *brighter = NULL;
    CHECK(dwv_image_create(W, H, scaled, &brighter) == DWV_SUCCESS, "%s", dwv_last_error_message());
    o.look = NULL;
    o.view = "Filmic";
    CHECK(dwv_image_to_display(brighter, &o, scaled_bytes, (uint64_t)W * H * 4) == DWV_SUCCESS, "%s",
          dwv_last_error_message());
    o.exposure = 2.0;
    CHECK(dwv_image_to_display(image, &o, bytes, (uint64_t)W * H * 4) == DWV_SUCCESS, "%s", dwv_last_error_message());
    worst = 0;
    for (size_t i = 0; i < (size_t)W * H * 4; ++i) {
        int d = abs((int)scaled_bytes[i] - bytes[i]);
        if (d > worst) worst = d;
    }
    CHECK(worst <= 1, "exposure +2 equals 4x the pixels through Filmic: off by %d", worst);
    dwv_image_release(brighter);
    free(scaled);
    free(scaled_bytes);
    free(bytes);
    dwv_image_release(image);
}

/* Views differ (so agreeing with ocioconvert view by view means something), and calls from two
 * threads at once (the built-in config is parsed once and shared) give the one-thread bytes. */
typedef struct job {
    dwv_image_t *image;
    const char *view;
    uint8_t *bytes;
    dwv_result_t result;
} job;

static void *run_job(void *arg)
{
    job *j = arg;
    for (int k = 0; k < 4 && j->result == DWV_SUCCESS; ++k) {
        dwv_display_options_t o = DWV_DISPLAY_OPTIONS_INIT;
        o.view = j->view;
        j->result = dwv_image_to_display(j->image, &o, j->bytes, (uint64_t)W * H * 4);
    }
    return NULL;
}

static void test_views_and_threads(void)
{
    dwvb_image *img = make_image();
    dwv_image_t *image = dwv_image_handle(img);
    unsetenv("OCIO");
    uint8_t *alone[2], *together[2];
    const char *views[2] = {"Standard", "Filmic"};
    for (int v = 0; v < 2; ++v) {
        alone[v] = malloc((size_t)W * H * 4);
        together[v] = malloc((size_t)W * H * 4);
        dwv_display_options_t o = DWV_DISPLAY_OPTIONS_INIT;
        o.view = views[v];
        CHECK(dwv_image_to_display(image, &o, alone[v], (uint64_t)W * H * 4) == DWV_SUCCESS, "%s",
              dwv_last_error_message());
    }
    int worst = 0;
    for (size_t i = 0; i < (size_t)W * H * 4; ++i) {
        int d = abs((int)alone[0][i] - (int)alone[1][i]);
        if (d > worst) worst = d;
    }
    CHECK(worst > 20, "Standard and Filmic differ (by up to %d levels)", worst);
    job jobs[2] = {{image, views[0], together[0], DWV_SUCCESS}, {image, views[1], together[1], DWV_SUCCESS}};
    pthread_t threads[2];
    for (int t = 0; t < 2; ++t) pthread_create(&threads[t], NULL, run_job, &jobs[t]);
    for (int t = 0; t < 2; ++t) pthread_join(threads[t], NULL);
    for (int v = 0; v < 2; ++v) {
        CHECK(jobs[v].result == DWV_SUCCESS, "thread %d: %d", v, jobs[v].result);
        CHECK(memcmp(alone[v], together[v], (size_t)W * H * 4) == 0, "%s: two threads give the one-thread bytes",
              views[v]);
        free(alone[v]);
        free(together[v]);
    }
    dwv_image_release(image);
}

/* Premultiplied in, straight out: a pixel covered by a quarter with a quarter of an opaque pixel's
 * colour shows that opaque colour with alpha 64; alpha 0 keeps its colour as it is (a tiny alpha
 * must not overflow into NaN either). */
static void test_partly_covered_pixels(void)
{
    const float c[3] = {0.6f, 0.25f, 0.05f};
    const float pixels[20] = {c[0], c[1], c[2], 1.0f,
                              0.25f * c[0], 0.25f * c[1], 0.25f * c[2], 0.25f,
                              0.0f, 0.0f, 0.0f, 0.0f,
                              0.0f, 0.0f, 0.0f, 1.0f,
                              1.0f, 1.0f, 1.0f, 1e-40f};
    dwv_image_t *image = NULL;
    CHECK(dwv_image_create(5, 1, pixels, &image) == DWV_SUCCESS, "%s", dwv_last_error_message());
    const char *views[] = {"Standard", "Filmic"};
    for (int v = 0; v < 2 && image; ++v) {
        dwv_display_options_t o = DWV_DISPLAY_OPTIONS_INIT;
        o.view = views[v];
        o.exposure = 0.5;
        o.gamma = 1.2;
        uint8_t bytes[20];
        CHECK(dwv_image_to_display(image, &o, bytes, sizeof bytes) == DWV_SUCCESS, "%s", dwv_last_error_message());
        CHECK(abs(bytes[4] - bytes[0]) <= 1 && abs(bytes[5] - bytes[1]) <= 1 && abs(bytes[6] - bytes[2]) <= 1,
              "%s: quarter-covered %u %u %u shows the opaque colour %u %u %u", views[v], bytes[4], bytes[5],
              bytes[6], bytes[0], bytes[1], bytes[2]);
        CHECK(bytes[7] == 64 && bytes[3] == 255, "%s: alpha bytes %u, %u", views[v], bytes[7], bytes[3]);
        CHECK(bytes[8] == bytes[12] && bytes[9] == bytes[13] && bytes[10] == bytes[14] && bytes[11] == 0,
              "%s: alpha 0 keeps its (black) colour", views[v]);
        CHECK(bytes[16] > 200 && bytes[19] == 0, "%s: alpha 1e-40 divides to the brightest colour (%u)", views[v],
              bytes[16]);
    }
    dwv_image_release(image);
}

static void test_non_finite_pixels(void)
{
    dwvb_image *img = dwvb_image_new(4, 1);
    const float pixels[16] = {NAN, NAN, NAN, NAN,   INFINITY, INFINITY, INFINITY, 1.0f,
                              -INFINITY, 0.5f, NAN, 1.0f,   0.0f, 0.0f, 0.0f, 1.0f};
    memcpy(img->rgba, pixels, sizeof pixels);
    dwv_image_t *image = dwv_image_handle(img);
    uint8_t bytes[16];
    const char *views[] = {"Standard", "Filmic", "Raw"};
    for (int v = 0; v < 3; ++v) {
        dwv_display_options_t o = DWV_DISPLAY_OPTIONS_INIT;
        o.view = views[v];
        o.exposure = 3.0;
        o.gamma = 0.5;
        memset(bytes, 0x5a, sizeof bytes);
        CHECK(dwv_image_to_display(image, &o, bytes, sizeof bytes) == DWV_SUCCESS, "%s", dwv_last_error_message());
        /* NaN shows as 0 (like the black pixel), +inf as the brightest, -inf as 0. */
        CHECK(bytes[0] == bytes[12] && bytes[1] == bytes[13] && bytes[2] == bytes[14] && bytes[3] == 0,
              "%s: NaN pixel %u %u %u %u like black %u %u %u", views[v], bytes[0], bytes[1], bytes[2], bytes[3],
              bytes[12], bytes[13], bytes[14]);
        CHECK(bytes[4] > 200 && bytes[7] == 255, "%s: +inf pixel bright (%u)", views[v], bytes[4]);
        CHECK(bytes[8] == bytes[12] && bytes[10] == bytes[14], "%s: -inf and NaN components as 0", views[v]);
        char png[600];
        path_in(png, sizeof png, "nan.png");
        CHECK(dwv_image_write_display_png(image, png, &o) == DWV_SUCCESS, "%s", dwv_last_error_message());
    }
    dwv_image_release(image);
}

static void test_atomic_writes(void)
{
    dwvb_image *img = make_image();
    dwv_image_t *image = dwv_image_handle(img);
    char exr[600], png[600];
    path_in(exr, sizeof exr, "good.exr");
    path_in(png, sizeof png, "good.png");
    dwv_display_options_t o = DWV_DISPLAY_OPTIONS_INIT;
    unsetenv("OCIO");
    CHECK(dwv_image_write_exr(image, exr) == DWV_SUCCESS, "%s", dwv_last_error_message());
    CHECK(dwv_image_write_display_png(image, png, &o) == DWV_SUCCESS, "%s", dwv_last_error_message());
    chmod(exr, 0640);
    size_t exr_size = 0, png_size = 0;
    unsigned char *good_exr = read_all(exr, &exr_size), *good_png = read_all(png, &png_size);
    CHECK(good_exr && exr_size > 3000 && good_png && png_size > 300, "good files %zu and %zu bytes", exr_size, png_size);

    /* A different, bigger image that cannot be written whole: files may not grow past 1000 bytes
     * (RLIMIT_FSIZE; writes past it fail with EFBIG once SIGXFSZ is ignored). */
    dwvb_image *big = dwvb_image_new(64, 64);
    for (size_t i = 0; i < 64u * 64u * 4u; ++i) big->rgba[i] = (float)((i * 2654435761u) % 1000u) / 999.0f;
    dwv_image_t *big_image = dwv_image_handle(big);
    struct rlimit saved, limit;
    getrlimit(RLIMIT_FSIZE, &saved);
    limit = saved;
    limit.rlim_cur = 1000;
    signal(SIGXFSZ, SIG_IGN);
    CHECK(setrlimit(RLIMIT_FSIZE, &limit) == 0, "setrlimit");
    dwv_result_t r = dwv_image_write_exr(big_image, exr);
    CHECK(r == DWV_ERROR_IO, "a write cut short fails (%d): %s", r, dwv_last_error_message());
    CHECK(strstr(dwv_last_error_message(), "good.exr") && strstr(dwv_last_error_message(), strerror(EFBIG)),
          "the message names the file and the reason: %s", dwv_last_error_message());
    r = dwv_image_write_display_png(big_image, png, &o);
    CHECK(r == DWV_ERROR_IO, "a PNG write cut short fails (%d): %s", r, dwv_last_error_message());
    setrlimit(RLIMIT_FSIZE, &saved);
    CHECK(same_file(exr, good_exr, exr_size), "the good EXR is untouched");
    CHECK(same_file(png, good_png, png_size), "the good PNG is untouched");
    CHECK(temp_files() == 0, "no temporary file left (%d)", temp_files());

    /* A successful write replaces the file and keeps its mode. */
    CHECK(dwv_image_write_exr(big_image, exr) == DWV_SUCCESS, "%s", dwv_last_error_message());
    CHECK(!same_file(exr, good_exr, exr_size), "replaced");
    struct stat info;
    CHECK(stat(exr, &info) == 0 && (info.st_mode & 0777) == 0640, "mode kept: %o", (unsigned)(info.st_mode & 0777));
    CHECK(temp_files() == 0, "no temporary file left");

    /* Targets that cannot be written: nothing created, clear messages. */
    char folder[600], bad[700];
    path_in(folder, sizeof folder, "a_folder");
    mkdir(folder, 0755);
    r = dwv_image_write_exr(image, folder);
    CHECK(r == DWV_ERROR_IO && strstr(dwv_last_error_message(), "a folder"), "target is a folder: %s",
          dwv_last_error_message());
    snprintf(bad, sizeof bad, "%s/missing/x.exr", work);
    r = dwv_image_write_exr(image, bad);
    CHECK(r == DWV_ERROR_IO && strstr(dwv_last_error_message(), "missing") &&
              strstr(dwv_last_error_message(), strerror(ENOENT)),
          "missing folder: %s", dwv_last_error_message());
    snprintf(bad, sizeof bad, "%s/x.exr", png); /* a file used as a folder */
    r = dwv_image_write_display_png(image, bad, &o);
    CHECK(r == DWV_ERROR_IO && strstr(dwv_last_error_message(), "not a folder"), "file as folder: %s",
          dwv_last_error_message());
    if (geteuid() != 0) { /* root writes anywhere */
        char locked[600];
        path_in(locked, sizeof locked, "locked");
        mkdir(locked, 0555);
        snprintf(bad, sizeof bad, "%s/x.exr", locked);
        r = dwv_image_write_exr(image, bad);
        CHECK(r == DWV_ERROR_IO && strstr(dwv_last_error_message(), strerror(EACCES)), "unwritable folder: %s",
              dwv_last_error_message());
    }
    CHECK(temp_files() == 0, "no temporary file left");
    free(good_exr);
    free(good_png);
    dwv_image_release(big_image);
    dwv_image_release(image);
}

static void test_arguments(void)
{
    dwvb_image *img = make_image();
    dwv_image_t *image = dwv_image_handle(img);
    char path[600];
    path_in(path, sizeof path, "args.png");
    dwv_display_options_t o = DWV_DISPLAY_OPTIONS_INIT;
    uint8_t *bytes = malloc((size_t)W * H * 4);
    const uint64_t size = (uint64_t)W * H * 4;
    unsetenv("OCIO");

    CHECK(dwv_image_write_exr(NULL, path) == DWV_ERROR_NULL_POINTER, "NULL image");
    CHECK(dwv_image_write_exr(image, NULL) == DWV_ERROR_NULL_POINTER, "NULL path");
    CHECK(dwv_image_write_exr(image, "") == DWV_ERROR_IO && strstr(dwv_last_error_message(), "empty"), "empty path: %s",
          dwv_last_error_message());
    char *long_path = malloc(5000);
    memset(long_path, 'a', 4999);
    long_path[4999] = 0;
    CHECK(dwv_image_write_exr(image, long_path) == DWV_ERROR_IO && strstr(dwv_last_error_message(), "long"),
          "long path: %s", dwv_last_error_message());
    free(long_path);
    CHECK(dwv_image_write_display_png(image, path, NULL) == DWV_ERROR_NULL_POINTER, "NULL display");
    dwv_display_options_t small = o;
    small.struct_size = 8;
    CHECK(dwv_image_write_display_png(image, path, &small) == DWV_ERROR_STRUCT_SIZE, "struct_size");
    dwv_display_options_t bad = o;
    bad.exposure = NAN;
    CHECK(dwv_image_to_display(image, &bad, bytes, size) == DWV_ERROR_INVALID_ARGUMENT, "exposure NaN");
    bad = o;
    bad.gamma = 0.0;
    CHECK(dwv_image_to_display(image, &bad, bytes, size) == DWV_ERROR_OUT_OF_RANGE, "gamma 0");
    bad.gamma = -1.0;
    CHECK(dwv_image_to_display(image, &bad, bytes, size) == DWV_ERROR_OUT_OF_RANGE, "gamma -1");
    bad.gamma = INFINITY;
    CHECK(dwv_image_to_display(image, &bad, bytes, size) == DWV_ERROR_INVALID_ARGUMENT, "gamma inf");
    CHECK(dwv_image_to_display(image, &o, bytes, size - 1) == DWV_ERROR_OUT_OF_RANGE, "buffer too small: %s",
          dwv_last_error_message());
    CHECK(dwv_image_to_display(image, &o, NULL, size) == DWV_ERROR_NULL_POINTER, "NULL bytes");

    /* Unknown names list the valid ones; nothing is written. */
    bad = o;
    bad.view = "Filmik";
    CHECK(dwv_image_write_display_png(image, path, &bad) == DWV_ERROR_UNKNOWN_NAME, "unknown view");
    const char *m = dwv_last_error_message();
    CHECK(strstr(m, "'Filmik'") && strstr(m, "'Standard'") && strstr(m, "'Filmic'") && strstr(m, "'Raw'"),
          "the message lists the views: %s", m);
    CHECK(access(path, F_OK) != 0, "no PNG after a failure");
    bad = o;
    bad.display = "P3";
    CHECK(dwv_image_to_display(image, &bad, bytes, size) == DWV_ERROR_UNKNOWN_NAME &&
              strstr(dwv_last_error_message(), "'sRGB'"),
          "unknown display: %s", dwv_last_error_message());
    bad = o;
    bad.look = "Punchy";
    CHECK(dwv_image_to_display(image, &bad, bytes, size) == DWV_ERROR_UNKNOWN_NAME &&
              strstr(dwv_last_error_message(), "'High Contrast'"),
          "unknown look: %s", dwv_last_error_message());
    bad = o;
    bad.look = "";
    CHECK(dwv_image_to_display(image, &bad, bytes, size) == DWV_SUCCESS, "empty look is none: %s",
          dwv_last_error_message());

    /* Configs: missing file, malformed file, $OCIO. */
    char cfg[600];
    path_in(cfg, sizeof cfg, "missing.ocio");
    bad = o;
    bad.config_path = cfg;
    CHECK(dwv_image_to_display(image, &bad, bytes, size) == DWV_ERROR_IO &&
              strstr(dwv_last_error_message(), "missing.ocio") && strstr(dwv_last_error_message(), strerror(ENOENT)),
          "missing config: %s", dwv_last_error_message());
    setenv("OCIO", cfg, 1);
    CHECK(dwv_image_to_display(image, &o, bytes, size) == DWV_ERROR_IO && strstr(dwv_last_error_message(), "$OCIO"),
          "missing $OCIO config: %s", dwv_last_error_message());
    path_in(cfg, sizeof cfg, "broken.ocio");
    FILE *f = fopen(cfg, "w");
    fputs("ocio_profile_version: 2\ncolorspaces: [oops\n", f);
    fclose(f);
    CHECK(dwv_image_to_display(image, &bad, bytes, size) == DWV_ERROR_FORMAT, "broken config: %s",
          dwv_last_error_message());
    setenv("OCIO", config_path, 1);
    uint8_t *from_env = malloc((size_t)size);
    CHECK(dwv_image_to_display(image, &o, from_env, size) == DWV_SUCCESS, "$OCIO config: %s", dwv_last_error_message());
    unsetenv("OCIO");
    CHECK(dwv_image_to_display(image, &o, bytes, size) == DWV_SUCCESS, "%s", dwv_last_error_message());
    CHECK(memcmp(bytes, from_env, (size_t)size) == 0, "$OCIO with the shipped file equals the built-in config");
    free(from_env);
    free(bytes);
    dwv_image_release(image);
}

int main(void)
{
    snprintf(work, sizeof work, "%s", "/tmp/dwv_image_io_XXXXXX");
    if (!mkdtemp(work)) {
        perror("mkdtemp");
        return 1;
    }
    snprintf(config_path, sizeof config_path, "%s/../../data/ocio/config.ocio", DWV_TEST_DATA_DIR);
    test_exr_round_trip();
    test_display_against_ocioconvert("Standard", 0);
    test_display_against_ocioconvert("Standard", 1);
    test_display_against_ocioconvert("Filmic", 0);
    test_display_against_ocioconvert("Filmic", 1);
    test_exposure_gamma_look();
    test_views_and_threads();
    test_partly_covered_pixels();
    test_non_finite_pixels();
    test_atomic_writes();
    test_arguments();
    char command[600];
    snprintf(command, sizeof command, "rm -rf '%s'", work);
    if (system(command) != 0) fprintf(stderr, "could not remove %s\n", work);
    return check_report("test_image_io");
}
