/* Image files as textures and environment worlds (issue 18): OpenEXR (half and float; R G B A,
 * R G B and Y; scanline with ZIP and tiled, written here by OpenEXR itself) and Radiance pictures
 * (flat and run-length encoded, written byte by byte here). Each file's bake is compared bit for
 * bit with the same texels given in memory (a wrong texel, row order or channel changes the
 * image; a planted wrong texel shows it), and the bad files are refused with their reason and the
 * scene left as it was: missing, truncated, 0 x 0 and oversized (a data window patched in the
 * header: refused before anything is read), NaN and negative texels, a multi-layer EXR, an sRGB
 * format for an EXR, a Radiance picture of another orientation. A 1 x 1 environment file is the
 * constant world, and a 100000 x 1 one is accepted (as in memory). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <openexr.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include <dwivedi.h>

static char folder[] = "/tmp/dwv_image_files_XXXXXX";

static const char *in_folder(const char *name)
{
    static char path[4][256];
    static int next;
    char *p = path[next++ % 4];
    snprintf(p, 256, "%s/%s", folder, name);
    return p;
}

/* Writes `texels` (bottom row first, `n` interleaved channels named `names`) with OpenEXR: ZIP
 * scanlines, or 3 x 2 tiles; the channels' type is `type` (the encoder converts from float). */
static int write_exr(const char *path, uint32_t w, uint32_t h, uint32_t n, const char *const *names,
                     exr_pixel_type_t type, int tiled, const float *texels)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_context_t c = NULL;
    int part = 0, failed = 0;
    float *top = malloc((size_t)w * h * n * sizeof *top); /* top row first, as EXR stores it */
    for (uint32_t y = 0; y < h; ++y)
        memcpy(top + (size_t)y * w * n, texels + (size_t)(h - 1 - y) * w * n, (size_t)w * n * sizeof *top);
    if (exr_start_write(&c, path, EXR_WRITE_FILE_DIRECTLY, &init) ||
        exr_add_part(c, "image", tiled ? EXR_STORAGE_TILED : EXR_STORAGE_SCANLINE, &part) ||
        exr_initialize_required_attr_simple(c, part, (int32_t)w, (int32_t)h, EXR_COMPRESSION_ZIP))
        failed = 1;
    if (!failed && tiled && exr_set_tile_descriptor(c, part, 3, 2, EXR_TILE_ONE_LEVEL, EXR_TILE_ROUND_DOWN)) failed = 1;
    for (uint32_t k = 0; k < n && !failed; ++k)
        if (exr_add_channel(c, part, names[k], type, EXR_PERCEPTUALLY_LINEAR, 1, 1)) failed = 1;
    if (!failed && exr_write_header(c)) failed = 1;
    exr_encode_pipeline_t encoder;
    memset(&encoder, 0, sizeof encoder);
    int ready = 0;
    int32_t lines = 1;
    if (!failed && !tiled && exr_get_scanlines_per_chunk(c, part, &lines)) failed = 1;
    uint32_t across = tiled ? (w + 2u) / 3u : 1u, down = tiled ? (h + 1u) / 2u : (h + (uint32_t)lines - 1u) / (uint32_t)lines;
    for (uint32_t ty = 0; ty < down && !failed; ++ty)
        for (uint32_t tx = 0; tx < across && !failed; ++tx) {
            /* OpenEXR 3.1's tile chunks give start_x / start_y as tile numbers: the pixel is ours. */
            uint32_t x0 = tiled ? 3u * tx : 0u, y0 = tiled ? 2u * ty : ty * (uint32_t)lines;
            exr_chunk_info_t chunk;
            if (tiled ? exr_write_tile_chunk_info(c, part, (int)tx, (int)ty, 0, 0, &chunk)
                      : exr_write_scanline_chunk_info(c, part, (int)(ty * (uint32_t)lines), &chunk)) {
                failed = 1;
                break;
            }
            if (ready ? exr_encoding_update(c, part, &chunk, &encoder) : exr_encoding_initialize(c, part, &chunk, &encoder)) {
                failed = 1;
                break;
            }
            for (int16_t k = 0; k < encoder.channel_count; ++k) {
                exr_coding_channel_info_t *ch = &encoder.channels[k];
                uint32_t slot = 0;
                for (uint32_t s = 0; s < n; ++s)
                    if (strcmp(names[s], ch->channel_name) == 0) slot = s;
                ch->user_pixel_stride = (int32_t)(n * 4u);
                ch->user_line_stride = (int32_t)(w * n * 4u);
                ch->user_bytes_per_element = 4;
                ch->user_data_type = EXR_PIXEL_FLOAT;
                ch->encode_from_ptr =
                    (const uint8_t *)(top + ((size_t)y0 * w + (size_t)x0) * n + slot);
            }
            if (!ready && exr_encoding_choose_default_routines(c, part, &encoder)) failed = 1;
            ready = 1;
            if (!failed && exr_encoding_run(c, part, &encoder)) failed = 1;
        }
    if (ready) exr_encoding_destroy(c, &encoder);
    if (c && exr_finish(&c)) failed = 1;
    free(top);
    return failed ? -1 : 0;
}

static long file_size(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return -1;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fclose(f);
    return n;
}

/* Overwrites the first dataWindow's max.x (the box2i after "dataWindow\0box2i\0" and its size). */
static int patch_data_window_max_x(const char *path, int32_t max_x)
{
    FILE *f = fopen(path, "r+b");
    if (!f) return -1;
    unsigned char head[4096];
    size_t n = fread(head, 1, sizeof head, f);
    static const char key[] = "dataWindow\0box2i";
    int done = -1;
    for (size_t i = 0; i + sizeof key + 4 + 16 <= n; ++i)
        if (memcmp(head + i, key, sizeof key) == 0) {
            fseek(f, (long)(i + sizeof key + 4 + 8), SEEK_SET); /* size, then min.x min.y */
            done = fwrite(&max_x, 4, 1, f) == 1 ? 0 : -1;
            break;
        }
    fclose(f);
    return done;
}

/* A diffuse quad filling an orthographic camera's view, lit by a sun, its base colour `texture`
 * (when set) and the world `world` (an environment when its texels are set). */
static dwv_scene_t *quad_scene(void)
{
    dwv_scene_t *scene = NULL;
    if (dwv_scene_create(&scene) != DWV_SUCCESS) exit(2);
    dwv_material_t m = DWV_MATERIAL_INIT;
    m.kind = DWV_MATERIAL_DIFFUSE;
    m.subsurface_exit = DWV_SUBSURFACE_EXIT_PRINCIPLED_V1; /* its retro-reflection reads Roughness */
    uint32_t id;
    dwv_scene_add_material(scene, &m, &id);
    static const float positions[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    static const uint32_t indices[6] = {0, 1, 2, 0, 2, 3};
    static const float uvs[12] = {0, 0, 1, 0, 1, 1, 0, 0, 1, 1, 0, 1};
    dwv_mesh_t mesh = DWV_MESH_INIT;
    mesh.vertex_count = 4, mesh.triangle_count = 2, mesh.positions = positions, mesh.indices = indices, mesh.uvs = uvs;
    dwv_scene_add_mesh(scene, &mesh, &id);
    dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
    sun.strength = 3.0;
    sun.direction[0] = 0.9, sun.direction[1] = 0.3, sun.direction[2] = -0.5; /* grazing: retro-reflection shows */
    dwv_scene_add_light(scene, &sun);
    dwv_camera_t camera = DWV_CAMERA_INIT;
    camera.kind = DWV_CAMERA_ORTHOGRAPHIC;
    camera.transform[11] = 5.0;
    camera.ortho_scale = 2.5; /* the quad and some world around it */
    dwv_scene_set_camera(scene, &camera);
    return scene;
}

/* Texture `texture` of `channels` channels on Base Color, or on Roughness with one channel. */
static void bind_texture(dwv_scene_t *scene, uint32_t texture, uint32_t channels)
{
    dwv_texture_binding_t b = DWV_TEXTURE_BINDING_INIT;
    b.texture_id = texture;
    b.input = channels == 1u ? DWV_INPUT_ROUGHNESS : DWV_INPUT_BASE_COLOR;
    CHECK(dwv_scene_bind_texture(scene, 0, &b) == DWV_SUCCESS, "bind: %s", dwv_last_error_message());
}

/* The baked pixels (12 x 12, 2 samples), malloc'd; NULL (a failed CHECK) if it failed. */
static float *bake(dwv_scene_t *scene)
{
    float *out = NULL;
    if (dwv_scene_commit(scene) != DWV_SUCCESS) {
        CHECK(0, "commit: %s", dwv_last_error_message());
        return NULL;
    }
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = o.height = 12;
    o.samples = 2;
    o.threads = 2;
    dwv_image_t *image = NULL;
    if (dwv_bake(scene, &o, &image) != DWV_SUCCESS) {
        CHECK(0, "bake: %s", dwv_last_error_message());
        return NULL;
    }
    dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
    dwv_image_info(image, &info);
    out = malloc(4u * 144u * sizeof *out);
    memcpy(out, info.rgba, 4u * 144u * sizeof *out);
    dwv_image_release(image);
    return out;
}

static int same_bake(dwv_scene_t *a, dwv_scene_t *b)
{
    float *x = bake(a), *y = bake(b);
    int same = x && y && memcmp(x, y, 4u * 144u * sizeof *x) == 0;
    free(x);
    free(y);
    dwv_scene_release(a);
    dwv_scene_release(b);
    return same;
}

/* Texels k / 16 (exact in half), different in every texel and channel. */
static void fill(float *t, size_t n)
{
    for (size_t i = 0; i < n; ++i) t[i] = (float)((i * 7u) % 16u) / 16.0f;
}

static void texture_from_file_bakes_as_in_memory(const char *what, uint32_t w, uint32_t h, uint32_t n,
                                                 const char *const *names, exr_pixel_type_t type, int tiled)
{
    const char *path = in_folder("texture.exr");
    float *t = malloc((size_t)w * h * n * sizeof *t);
    fill(t, (size_t)w * h * n);
    CHECK(write_exr(path, w, h, n, names, type, tiled, t) == 0, "%s: writing the EXR", what);
    dwv_scene_t *from_file = quad_scene(), *in_memory = quad_scene(), *planted = quad_scene();
    dwv_texture_desc_t d = DWV_TEXTURE_DESC_INIT;
    d.interpolation = DWV_INTERPOLATION_CLOSEST;
    uint32_t id = 9;
    uint32_t kept = n == 2u ? 1u : n; /* Y with A: Y alone */
    dwv_result_t r = dwv_scene_add_texture_file(from_file, path, &d, &id);
    CHECK(r == DWV_SUCCESS && id == 0, "%s: %s", what, dwv_last_error_message());
    bind_texture(from_file, 0, kept);
    uint64_t bytes = 0, texels = 0;
    dwv_scene_texture_memory(from_file, &bytes, &texels);

    CHECK(texels == (uint64_t)w * h && bytes == 4u * kept * texels, "%s: %llu bytes for %llu texels", what,
          (unsigned long long)bytes, (unsigned long long)texels);
    float *memory = malloc((size_t)w * h * kept * sizeof *memory);
    for (size_t i = 0; i < (size_t)w * h; ++i)
        for (uint32_t c = 0; c < kept; ++c) memory[i * kept + c] = t[i * n + c];
    d.width = w, d.height = h, d.channels = kept, d.texels = memory;
    dwv_scene_add_texture(in_memory, &d, &id);
    bind_texture(in_memory, 0, kept);
    /* Planted: the rows top-down (a reader that forgot EXR's row order). */
    float *flipped = malloc((size_t)w * h * kept * sizeof *flipped);
    for (uint32_t y = 0; y < h; ++y)
        memcpy(flipped + (size_t)y * w * kept, memory + (size_t)(h - 1u - y) * w * kept, (size_t)w * kept * sizeof *flipped);
    d.texels = flipped;
    dwv_scene_add_texture(planted, &d, &id);
    bind_texture(planted, 0, kept);
    dwv_scene_t *again = quad_scene();
    d.texels = NULL;
    dwv_scene_add_texture_file(again, path, &d, &id);
    bind_texture(again, 0, kept);
    CHECK(same_bake(from_file, in_memory), "%s: the file's bake differs from the same texels in memory", what);
    CHECK(!same_bake(planted, again), "%s: the planted row order changed nothing", what);
    free(flipped);
    free(memory);
    free(t);
}

static void check_refused(dwv_result_t r, dwv_result_t want, const char *text, const char *what)
{
    CHECK(r == want, "%s: result %d, wanted %d (%s)", what, (int)r, (int)want, dwv_last_error_message());
    CHECK(strstr(dwv_last_error_message(), text) != NULL, "%s: message '%s' lacks '%s'", what,
          dwv_last_error_message(), text);
}

static void bad_texture_files(void)
{
    static const char *const rgb[3] = {"R", "G", "B"};
    dwv_scene_t *scene = quad_scene();
    dwv_texture_desc_t d = DWV_TEXTURE_DESC_INIT;
    uint32_t id = 77;
    check_refused(dwv_scene_add_texture_file(scene, in_folder("missing.exr"), &d, &id), DWV_ERROR_IO, "missing.exr",
                  "missing file");
    float t[3 * 8 * 6];
    fill(t, sizeof t / sizeof *t);
    const char *path = in_folder("bad.exr");
    write_exr(path, 8, 6, 3, rgb, EXR_PIXEL_FLOAT, 0, t);
    d.format = DWV_TEXEL_SRGB8;
    check_refused(dwv_scene_add_texture_file(scene, path, &d, &id), DWV_ERROR_INVALID_ARGUMENT, "scene-linear floats",
                  "sRGB format for an EXR");
    d.format = DWV_TEXEL_FLOAT32;
    /* Truncated: the header and part of the pixels. */
    long size = file_size(path);
    CHECK(truncate(path, size / 2) == 0, "truncate");
    check_refused(dwv_scene_add_texture_file(scene, path, &d, &id), DWV_ERROR_FORMAT, "cannot read EXR", "truncated");
    /* 0 x 0 (max.x below min.x) and 70000 wide, patched into a valid header. */
    write_exr(path, 8, 6, 3, rgb, EXR_PIXEL_FLOAT, 0, t);
    patch_data_window_max_x(path, -1);
    dwv_result_t r = dwv_scene_add_texture_file(scene, path, &d, &id);
    CHECK(r == DWV_ERROR_FORMAT, "0 wide: %d %s", (int)r, dwv_last_error_message());
    write_exr(path, 8, 6, 3, rgb, EXR_PIXEL_FLOAT, 0, t);
    patch_data_window_max_x(path, 69999);
    check_refused(dwv_scene_add_texture_file(scene, path, &d, &id), DWV_ERROR_FORMAT, "70000 x 6", "70000 wide");
    /* NaN and infinite texels: the file and the texel named (row from the bottom). */
    t[3 * (8 * 4 + 2) + 1] = NAN;
    write_exr(path, 8, 6, 3, rgb, EXR_PIXEL_FLOAT, 0, t);
    check_refused(dwv_scene_add_texture_file(scene, path, &d, &id), DWV_ERROR_INVALID_ARGUMENT,
                  "texel (2, 4) channel 1 is NaN", "NaN texel");
    CHECK(strstr(dwv_last_error_message(), "bad.exr") != NULL, "NaN: the file is not named: %s", dwv_last_error_message());
    t[3 * (8 * 4 + 2) + 1] = INFINITY;
    write_exr(path, 8, 6, 3, rgb, EXR_PIXEL_HALF, 0, t);
    check_refused(dwv_scene_add_texture_file(scene, path, &d, &id), DWV_ERROR_INVALID_ARGUMENT, "infinite",
                  "infinite half texel");
    /* Blender's multi-layer files name their channels layer.pass.R. */
    static const char *const layered[3] = {"ViewLayer.Combined.R", "ViewLayer.Combined.G", "ViewLayer.Combined.B"};
    fill(t, sizeof t / sizeof *t);
    write_exr(path, 8, 6, 3, layered, EXR_PIXEL_FLOAT, 0, t);
    check_refused(dwv_scene_add_texture_file(scene, path, &d, &id), DWV_ERROR_FORMAT, "multi-layer", "multi-layer");
    /* Not an image at all. */
    FILE *f = fopen(path, "wb");
    fputs("not an image", f);
    fclose(f);
    d.format = DWV_TEXEL_SRGB8;
    check_refused(dwv_scene_add_texture_file(scene, path, &d, &id), DWV_ERROR_FORMAT, "PNG", "not an image");
    uint64_t bytes = 1, texels = 1;
    dwv_scene_texture_memory(scene, &bytes, &texels);
    CHECK(bytes == 0 && texels == 0 && id == 77, "a refused file left a texture (%llu texels) or an id",
          (unsigned long long)texels);
    dwv_scene_release(scene);
}

/* Radiance: header, the standard resolution line, then scanlines (flat, or "new" RLE). */
static void write_radiance(const char *path, const char *resolution, uint32_t w, uint32_t h, const unsigned char *rgbe,
                           int rle)
{
    FILE *f = fopen(path, "wb");
    fprintf(f, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=2.0\n\n%s\n", resolution);
    for (uint32_t y = 0; y < h; ++y) {
        const unsigned char *row = rgbe + 4u * w * y;
        if (!rle) {
            fwrite(row, 4, w, f);
            continue;
        }
        unsigned char head[4] = {2, 2, (unsigned char)(w >> 8), (unsigned char)(w & 255u)};
        fwrite(head, 1, 4, f);
        for (int c = 0; c < 4; ++c) {
            /* A run of the first value over the first 3 texels, then the rest literally. */
            unsigned char run[2] = {128 + 3, row[c]};
            fwrite(run, 1, 2, f);
            fputc((int)(w - 3u), f);
            for (uint32_t x = 3; x < w; ++x) fputc(row[4u * x + (uint32_t)c], f);
        }
    }
    fclose(f);
}

static void environments(void)
{
    static const char *const rgba[4] = {"R", "G", "B", "A"};
    static const char *const luminance[1] = {"Y"};
    enum { W = 12, H = 6 };
    float t[4 * W * H], rgb[3 * W * H];
    fill(t, sizeof t / sizeof *t);
    for (int i = 0; i < W * H; ++i)
        for (int c = 0; c < 3; ++c) rgb[3 * i + c] = t[4 * i + c];
    const char *path = in_folder("sky.exr");
    CHECK(write_exr(path, W, H, 4, rgba, EXR_PIXEL_HALF, 1, t) == 0, "writing the sky");
    dwv_environment_t e = DWV_ENVIRONMENT_INIT;
    e.strength = 0.8;
    e.rotation[0] = e.rotation[4] = 0.0, e.rotation[1] = -1.0, e.rotation[3] = 1.0; /* 90 degrees about z */
    dwv_scene_t *a = quad_scene(), *b = quad_scene();
    CHECK(dwv_scene_set_world_environment_file(a, path, &e) == DWV_SUCCESS, "sky: %s", dwv_last_error_message());
    e.width = W, e.height = H, e.texels = rgb;
    dwv_scene_set_world_environment(b, &e);
    CHECK(same_bake(a, b), "tiled half RGBA sky: the file's bake differs from the same texels in memory");

    /* Y: grey. */
    float y[W * H], grey[3 * W * H];
    for (int i = 0; i < W * H; ++i) y[i] = grey[3 * i] = grey[3 * i + 1] = grey[3 * i + 2] = t[i];
    write_exr(path, W, H, 1, luminance, EXR_PIXEL_FLOAT, 0, y);
    a = quad_scene(), b = quad_scene();
    e.texels = grey;
    CHECK(dwv_scene_set_world_environment_file(a, path, &e) == DWV_SUCCESS, "Y sky: %s", dwv_last_error_message());
    dwv_scene_set_world_environment(b, &e);
    CHECK(same_bake(a, b), "Y sky: the file's bake differs from grey texels in memory");

    /* Radiance, flat and RLE: texel (m + 0.5) 2^(e - 136), e = 0 black; the file's first
     * scanline is the top row. */
    unsigned char rgbe[4 * W * H];
    float decoded[3 * W * H];
    for (int i = 0; i < W * H; ++i) {
        int k = i % W < 3 ? i - i % W : i; /* each row's first 3 texels alike (the RLE run) */
        int exponent = k % 5 == 0 ? 0 : 120 + k % 16;
        for (int c = 0; c < 3; ++c) rgbe[4 * i + c] = (unsigned char)((k * 31 + c * 77) % 256);
        rgbe[4 * i + 3] = (unsigned char)exponent;
        int row = H - 1 - i / W, col = i % W;
        for (int c = 0; c < 3; ++c)
            decoded[3 * (row * W + col) + c] =
                exponent == 0 ? 0.0f : ((float)rgbe[4 * i + c] + 0.5f) * ldexpf(1.0f, exponent - 136);
    }
    for (int rle = 0; rle < 2; ++rle) {
        const char *hdr = in_folder("sky.hdr");
        write_radiance(hdr, "-Y 6 +X 12", W, H, rgbe, rle);
        a = quad_scene(), b = quad_scene();
        e.texels = decoded;
        CHECK(dwv_scene_set_world_environment_file(a, hdr, &e) == DWV_SUCCESS, "hdr %d: %s", rle,
              dwv_last_error_message());
        dwv_scene_set_world_environment(b, &e);
        CHECK(same_bake(a, b), "Radiance (%s): the file's bake differs from the decoded texels", rle ? "RLE" : "flat");
    }
    dwv_scene_t *s = quad_scene();
    const char *hdr = in_folder("sky.hdr");
    write_radiance(hdr, "+Y 6 +X 12", W, H, rgbe, 0);
    check_refused(dwv_scene_set_world_environment_file(s, hdr, &e), DWV_ERROR_FORMAT, "standard orientation",
                  "flipped Radiance");
    write_radiance(hdr, "-Y 6 +X 12", W, H, rgbe, 1);
    CHECK(truncate(hdr, file_size(hdr) - 20) == 0, "truncate");
    check_refused(dwv_scene_set_world_environment_file(s, hdr, &e), DWV_ERROR_FORMAT, "scanline 5 of 6", "truncated hdr");
    check_refused(dwv_scene_set_world_environment_file(s, in_folder("none.hdr"), &e), DWV_ERROR_IO, "none.hdr",
                  "missing hdr");
    write_radiance(hdr, "-Y 0 +X 0", 0, 0, rgbe, 0);
    check_refused(dwv_scene_set_world_environment_file(s, hdr, &e), DWV_ERROR_FORMAT, "0 x 0", "0 x 0 hdr");
    /* A negative and a NaN texel in an EXR sky. */
    t[4 * 13 + 2] = -1.0f;
    write_exr(path, W, H, 4, rgba, EXR_PIXEL_FLOAT, 0, t);
    check_refused(dwv_scene_set_world_environment_file(s, path, &e), DWV_ERROR_INVALID_ARGUMENT,
                  "texel (1, 1) (column, row from the bottom) has blue = -1", "negative sky texel");
    t[4 * 13 + 2] = NAN;
    write_exr(path, W, H, 4, rgba, EXR_PIXEL_FLOAT, 0, t);
    check_refused(dwv_scene_set_world_environment_file(s, path, &e), DWV_ERROR_INVALID_ARGUMENT, "nan", "NaN sky texel");
    /* 131073 wide, in the header only: refused before the texels are read. */
    fill(t, sizeof t / sizeof *t);
    write_exr(path, W, H, 4, rgba, EXR_PIXEL_FLOAT, 0, t);
    patch_data_window_max_x(path, 131072);
    check_refused(dwv_scene_set_world_environment_file(s, path, &e), DWV_ERROR_FORMAT, "131073 x 6", "oversized sky");
    dwv_scene_release(s);

    /* 1 x 1: the constant world, bit for bit. */
    float one[4] = {0.25f, 0.5f, 0.75f, 1.0f};
    write_exr(path, 1, 1, 4, rgba, EXR_PIXEL_FLOAT, 0, one);
    a = quad_scene(), b = quad_scene();
    CHECK(dwv_scene_set_world_environment_file(a, path, &e) == DWV_SUCCESS, "1 x 1: %s", dwv_last_error_message());
    double colour[3] = {0.25, 0.5, 0.75};
    dwv_scene_set_world(b, colour, 0.8);
    CHECK(same_bake(a, b), "a 1 x 1 sky file is not the constant world");
    /* 100000 x 1: accepted (a world that varies with longitude only). */
    float *wide = malloc(100000u * 4u * sizeof *wide);
    fill(wide, 400000u);
    write_exr(path, 100000, 1, 4, rgba, EXR_PIXEL_HALF, 0, wide);
    free(wide);
    s = quad_scene();
    CHECK(dwv_scene_set_world_environment_file(s, path, &e) == DWV_SUCCESS, "100000 x 1: %s", dwv_last_error_message());
    CHECK(dwv_scene_commit(s) == DWV_SUCCESS, "100000 x 1 commit: %s", dwv_last_error_message());
    dwv_scene_release(s);
}

int main(void)
{
    if (!mkdtemp(folder)) return 2;
    static const char *const rgba[4] = {"R", "G", "B", "A"}, *const rgb[3] = {"R", "G", "B"};
    static const char *const ya[2] = {"Y", "A"};
    texture_from_file_bakes_as_in_memory("float RGB scanlines", 7, 5, 3, rgb, EXR_PIXEL_FLOAT, 0);
    texture_from_file_bakes_as_in_memory("half RGBA tiles", 7, 5, 4, rgba, EXR_PIXEL_HALF, 1);
    texture_from_file_bakes_as_in_memory("half RGBA scan", 7, 5, 4, rgba, EXR_PIXEL_HALF, 0);
    texture_from_file_bakes_as_in_memory("float RGBA tiles", 7, 5, 4, rgba, EXR_PIXEL_FLOAT, 1);
    texture_from_file_bakes_as_in_memory("float RGB tiles", 7, 5, 3, rgb, EXR_PIXEL_FLOAT, 1);
    texture_from_file_bakes_as_in_memory("float Y + A", 41, 33, 2, ya, EXR_PIXEL_FLOAT, 0);
    bad_texture_files();
    environments();
    const char *names[] = {"texture.exr", "bad.exr", "sky.exr", "sky.hdr"};
    for (int i = 0; i < 4; ++i) remove(in_folder(names[i]));
    rmdir(folder);
    return check_report("test_image_files");
}
