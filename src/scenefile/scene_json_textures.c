/* The scene file's textures, by name, and the bindings of a material's "textures" array. */
#include "scenefile/scene_json_internal.h"

#include <stdlib.h>
#include <string.h>

#include <errno.h>
#include <stdio.h>

#include "util/error.h"
#include "util/sha256.h"

dwv_result_t dwvs_check_image_file(const char *path, const char *resolved, const char *sha256, int *is_exr)
{
    static const unsigned char exr_magic[4] = {0x76, 0x2f, 0x31, 0x01};
    char name[SHOWN_SIZE];
    FILE *f = fopen(resolved, "rb");
    if (!f)
        return dwvs_fail_at(DWV_ERROR_IO, path, "image file '%s': %s", dwvs_shown(resolved, name), strerror(errno));
    unsigned char chunk[65536], head[4] = {0, 0, 0, 0};
    size_t got, total = 0;
    dwvu_sha256 hash;
    dwvu_sha256_init(&hash);
    while ((got = fread(chunk, 1, sizeof chunk, f)) > 0) {
        if (total < 4u) memcpy(head + total, chunk, got < 4u - total ? got : 4u - total);
        total += got;
        if (!sha256) break;
        dwvu_sha256_add(&hash, chunk, got);
    }
    int failed = ferror(f);
    fclose(f);
    if (failed) return dwvs_fail_at(DWV_ERROR_IO, path, "image file '%s': read error", dwvs_shown(resolved, name));
    *is_exr = total >= 4u && memcmp(head, exr_magic, 4) == 0;
    if (sha256) {
        char digest[65];
        dwvu_sha256_hex(&hash, digest);
        if (strcmp(digest, sha256) != 0)
            return dwvs_fail_at(DWV_ERROR_FORMAT, path,
                                "image file '%s' has SHA-256 %.12s..., the scene file says %.12s...: it is not the "
                                "file the scene was written with", dwvs_shown(resolved, name), digest, sha256);
    }
    return DWV_SUCCESS;
}

dwv_result_t dwvs_read_image_file(dwvs_parser *ps, const cJSON *item, const char *path, char resolved[MAX_FILE_PATH],
                                  int *is_exr)
{
    char p[PATH_SIZE], q[PATH_SIZE];
    const char *file_name = NULL, *sha256 = NULL;
    dwvs_path_key(p, path, "file");
    DWV_TRY(dwvs_read_string(dwvs_member(item, "file"), p, &file_name));
    DWV_TRY(dwvs_resolve_path(ps->base_dir, file_name, p, resolved));
    if (dwvs_member(item, "sha256")) {
        dwvs_path_key(q, path, "sha256");
        DWV_TRY(dwvs_read_string(dwvs_member(item, "sha256"), q, &sha256));
        size_t n = strlen(sha256);
        int hex = n == 64u;
        for (size_t i = 0; hex && i < n; ++i) hex = (sha256[i] >= '0' && sha256[i] <= '9') || (sha256[i] >= 'a' && sha256[i] <= 'f');
        if (!hex) return dwvs_fail_at(DWV_ERROR_FORMAT, q, "expected 64 lower-case hexadecimal digits (SHA-256)");
    }
    return dwvs_check_image_file(p, resolved, sha256, is_exr);
}

static const char *const extensions[] = {"repeat", "extend", "clip", "mirror"};
static const char *const interpolations[] = {"linear", "closest", "cubic"};

/* A texture from a file ("file", "colorspace") or inline ("width", "height", "channels",
 * "texels": scene-linear floats). */
static dwv_result_t read_texture(dwvs_parser *ps, const cJSON *item, const char *path, uint32_t *id)
{
    static const char *const keys[] = {"file", "sha256", "colorspace", "width", "height", "channels", "texels",
                                       "extension", "interpolation"};
    static const char *const spaces[] = {"srgb", "non_color", "linear"};
    if (!cJSON_IsObject(item))
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "expected an object, found %s", dwvs_type_name(item));
    DWV_TRY(dwvs_check_keys(item, path, keys, sizeof keys / sizeof keys[0]));
    dwv_texture_desc_t desc = DWV_TEXTURE_DESC_INIT;
    size_t extension = 0, interpolation = 0;
    DWV_TRY(dwvs_opt_choice(item, path, "extension", extensions, 4, &extension));
    DWV_TRY(dwvs_opt_choice(item, path, "interpolation", interpolations, 3, &interpolation));
    desc.extension = (dwv_texture_extension_t)extension;
    desc.interpolation = (dwv_texture_interpolation_t)interpolation;
    char p[PATH_SIZE];
    const cJSON *file = dwvs_member(item, "file");
    if (file) {
        if (dwvs_member(item, "width") || dwvs_member(item, "height") || dwvs_member(item, "channels") ||
            dwvs_member(item, "texels"))
            return dwvs_fail_at(DWV_ERROR_FORMAT, path, "give either 'file' or 'width'/'height'/'channels'/'texels'");
        char resolved[MAX_FILE_PATH];
        int exr = 0;
        DWV_TRY(dwvs_read_image_file(ps, item, path, resolved, &exr));
        dwvs_path_key(p, path, "file");
        /* An EXR holds scene-linear floats ("linear" or "non_color": data as stored, the default);
         * a PNG 8-bit values, sRGB unless said. */
        size_t space = exr ? 2 : 0;
        DWV_TRY(dwvs_opt_choice(item, path, "colorspace", spaces, 3, &space));
        if (exr && space == 0)
            return dwvs_fail_at(DWV_ERROR_FORMAT, path, "an OpenEXR file holds scene-linear floats: its 'colorspace' "
                                "is 'linear' or 'non_color', not 'srgb'");
        desc.format = exr ? DWV_TEXEL_FLOAT32 : space == 0 ? DWV_TEXEL_SRGB8 : DWV_TEXEL_LINEAR8;
        dwv_result_t r = dwv_scene_add_texture_file(ps->scene, resolved, &desc, id);
        return r == DWV_SUCCESS ? r : dwvs_prefix_capi(r, p);
    }
    if (dwvs_member(item, "sha256"))
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "'sha256' applies to a 'file'");
    if (dwvs_member(item, "colorspace"))
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "'colorspace' applies to a 'file' (inline texels are scene-linear)");
    const char *need[] = {"width", "height", "channels", "texels"};
    for (int k = 0; k < 4; ++k)
        if (!dwvs_member(item, need[k])) return dwvs_fail_at(DWV_ERROR_FORMAT, path, "missing key '%s'", need[k]);
    dwvs_path_key(p, path, "width");
    DWV_TRY(dwvs_read_u32(dwvs_member(item, "width"), p, 0u, 65536u, &desc.width));
    dwvs_path_key(p, path, "height");
    DWV_TRY(dwvs_read_u32(dwvs_member(item, "height"), p, 0u, 65536u, &desc.height));
    dwvs_path_key(p, path, "channels");
    DWV_TRY(dwvs_read_u32(dwvs_member(item, "channels"), p, 1u, 4u, &desc.channels));
    const cJSON *texels = dwvs_member(item, "texels");
    dwvs_path_key(p, path, "texels");
    if (!cJSON_IsArray(texels))
        return dwvs_fail_at(DWV_ERROR_FORMAT, p, "expected an array of numbers, found %s", dwvs_type_name(texels));
    size_t n = (size_t)cJSON_GetArraySize(texels), wanted = (size_t)desc.width * desc.height * desc.channels;
    if (n != wanted)
        return dwvs_fail_at(DWV_ERROR_FORMAT, p, "%zu numbers; %u x %u x %u channels needs %zu", n, desc.width,
                            desc.height, desc.channels, wanted);
    float *values = malloc((n ? n : 1u) * sizeof *values);
    if (!values) return dwvs_fail_at(DWV_ERROR_OUT_OF_MEMORY, p, "no memory for %zu texels", n);
    size_t i = 0;
    for (const cJSON *c = texels->child; c; c = c->next, ++i) {
        char q[PATH_SIZE];
        double v;
        dwvs_path_index(q, p, i);
        dwv_result_t r = dwvs_read_number(c, q, &v);
        if (r != DWV_SUCCESS) {
            free(values);
            return r;
        }
        values[i] = (float)v;
    }
    desc.format = DWV_TEXEL_FLOAT32;
    desc.texels = values;
    dwv_result_t r = dwv_scene_add_texture(ps->scene, &desc, id);
    free(values);
    return r == DWV_SUCCESS ? r : dwvs_prefix_capi(r, path);
}

dwv_result_t dwvs_read_textures(dwvs_parser *ps, const cJSON *item)
{
    if (!cJSON_IsObject(item))
        return dwvs_fail_at(DWV_ERROR_FORMAT, "textures", "expected an object of textures by name, found %s",
                            dwvs_type_name(item));
    size_t n = 0;
    for (const cJSON *c = item->child; c; c = c->next) ++n;
    ps->textures = calloc(n ? n : 1u, sizeof *ps->textures);
    if (!ps->textures) return dwvs_fail_at(DWV_ERROR_OUT_OF_MEMORY, "textures", "no memory for %zu names", n);
    for (const cJSON *c = item->child; c; c = c->next) {
        char p[PATH_SIZE];
        dwvs_path_key(p, "textures", c->string);
        if (!c->string[0]) return dwvs_fail_at(DWV_ERROR_FORMAT, "textures", "a texture has an empty name");
        uint32_t id = 0;
        DWV_TRY(read_texture(ps, c, p, &id));
        ps->textures[ps->texture_count].name = c->string;
        ps->textures[ps->texture_count].id = id;
        ++ps->texture_count;
    }
    qsort(ps->textures, ps->texture_count, sizeof *ps->textures, dwvs_compare_named);
    for (size_t i = 1; i < ps->texture_count; ++i)
        if (strcmp(ps->textures[i - 1].name, ps->textures[i].name) == 0) {
            char name[SHOWN_SIZE];
            return dwvs_fail_at(DWV_ERROR_FORMAT, "textures", "the name '%s' appears twice",
                                dwvs_shown(ps->textures[i].name, name));
        }
    return DWV_SUCCESS;
}

dwv_result_t dwvs_read_material_textures(dwvs_parser *ps, const cJSON *item, const char *path, uint32_t material_id)
{
    static const char *const keys[] = {"input", "texture", "uv_layer", "blend", "strength", "distance", "invert",
                                       "bump_shadowing"};
    static const char *const shadowings[] = {"none", "chiang2019", "chiang2019_mapped", "conty2019"};
    static const char *const inputs[] = {"base_color", "subsurface_color", "subsurface_weight", "subsurface_radius",
                                         "subsurface_scale", "subsurface_anisotropy", "roughness", "specular",
                                         "specular_tint", "normal_map", "bump"};
    char p[PATH_SIZE];
    dwvs_path_key(p, path, "textures");
    if (!cJSON_IsArray(item))
        return dwvs_fail_at(DWV_ERROR_FORMAT, p, "expected an array of bindings, found %s", dwvs_type_name(item));
    size_t index = 0;
    for (const cJSON *b = item->child; b; b = b->next, ++index) {
        char q[PATH_SIZE], r_path[PATH_SIZE], name[SHOWN_SIZE];
        dwvs_path_index(q, p, index);
        if (!cJSON_IsObject(b)) return dwvs_fail_at(DWV_ERROR_FORMAT, q, "expected an object, found %s", dwvs_type_name(b));
        DWV_TRY(dwvs_check_keys(b, q, keys, sizeof keys / sizeof keys[0]));
        dwv_texture_binding_t binding = DWV_TEXTURE_BINDING_INIT;
        size_t input = 0;
        if (!dwvs_member(b, "input")) return dwvs_fail_at(DWV_ERROR_FORMAT, q, "missing key 'input'");
        DWV_TRY(dwvs_opt_choice(b, q, "input", inputs, sizeof inputs / sizeof inputs[0], &input));
        binding.input = (dwv_material_input_t)input;
        const cJSON *texture = dwvs_member(b, "texture");
        if (!texture) return dwvs_fail_at(DWV_ERROR_FORMAT, q, "missing key 'texture'");
        const char *texture_name = NULL;
        dwvs_path_key(r_path, q, "texture");
        DWV_TRY(dwvs_read_string(texture, r_path, &texture_name));
        dwvs_named key = {texture_name, 0u, 0u};
        const dwvs_named *found =
            ps->texture_count ? bsearch(&key, ps->textures, ps->texture_count, sizeof key, dwvs_compare_named) : NULL;
        if (!found)
            return dwvs_fail_at(DWV_ERROR_UNKNOWN_NAME, r_path, "unknown texture '%s'", dwvs_shown(texture_name, name));
        binding.texture_id = found->id;
        if (dwvs_member(b, "uv_layer")) {
            dwvs_path_key(r_path, q, "uv_layer");
            DWV_TRY(dwvs_read_string(dwvs_member(b, "uv_layer"), r_path, &binding.uv_layer));
        }
        DWV_TRY(dwvs_opt_number(b, q, "blend", &binding.blend));
        DWV_TRY(dwvs_opt_number(b, q, "strength", &binding.strength));
        DWV_TRY(dwvs_opt_number(b, q, "distance", &binding.distance));
        const cJSON *invert = dwvs_member(b, "invert");
        if (invert) {
            dwvs_path_key(r_path, q, "invert");
            if (!cJSON_IsBool(invert))
                return dwvs_fail_at(DWV_ERROR_FORMAT, r_path, "expected true or false, found %s", dwvs_type_name(invert));
            binding.invert = cJSON_IsTrue(invert) ? 1 : 0;
        }
        size_t shadowing = (size_t)binding.bump_shadowing;
        DWV_TRY(dwvs_opt_choice(b, q, "bump_shadowing", shadowings, 4, &shadowing));
        binding.bump_shadowing = (dwv_bump_shadowing_t)shadowing;
        dwv_result_t r = dwv_scene_bind_texture(ps->scene, material_id, &binding);
        if (r != DWV_SUCCESS) return dwvs_prefix_capi(r, q);
    }
    return DWV_SUCCESS;
}
