/* JSON scene files (docs/scene-format.md) into a committed scene, through the public dwv_scene_*
 * API only: every value is checked for its type here, its range by the capi call it goes to (whose
 * message is then prefixed with the value's JSON path), so the file format and the C API cannot
 * disagree about what is allowed.
 *
 * Hostile text is met in two stages. A first pass over the bytes checks what cJSON does not:
 * UTF-8 validity (RFC 8259 section 8.1), no NUL bytes or \u0000 escapes (which would cut C
 * strings short), a nesting depth limit (cJSON recurses once per level) and a cap on the number
 * of values (its memory, about 64 bytes each). Then cJSON parses, and the schema walk (read_scene
 * below and the section readers of scene_json_*.c) rejects unknown keys, duplicate keys, wrong
 * types and numbers that overflowed to infinity. */
#define _POSIX_C_SOURCE 200809L
#include "scenefile/scene_json.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "scenefile/scene_json_internal.h"
#include "util/error.h"

#define FORMAT_VERSION 1

/* ---- the first pass over the bytes ----------------------------------------------------------- */

/* Line and column (1-based, in bytes) of byte `offset`. */
static void line_column(const unsigned char *s, size_t offset, size_t *line, size_t *column)
{
    size_t l = 1, start = 0;
    for (size_t i = 0; i < offset; ++i)
        if (s[i] == '\n') {
            ++l;
            start = i + 1;
        }
    *line = l;
    *column = offset - start + 1;
}

#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static dwv_result_t fail_text(const unsigned char *s, size_t offset, const char *format, ...)
{
    char message[MESSAGE_SIZE];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    size_t line, column;
    line_column(s, offset, &line, &column);
    return dwv_fail(DWV_ERROR_FORMAT, "line %zu, column %zu: %s", line, column, message);
}

/* The length of the well-formed UTF-8 sequence at s (Unicode 15, table 3-7: no overlong forms,
 * no surrogates, nothing above U+10FFFF), or 0. */
static size_t utf8_sequence(const unsigned char *s, size_t available)
{
    unsigned char c = s[0];
    size_t length;
    unsigned char lo = 0x80u, hi = 0xbfu;
    if (c < 0x80u) return 1;
    if (c >= 0xc2u && c <= 0xdfu) length = 2;
    else if (c >= 0xe0u && c <= 0xefu) {
        length = 3;
        if (c == 0xe0u) lo = 0xa0u;
        if (c == 0xedu) hi = 0x9fu;
    } else if (c >= 0xf0u && c <= 0xf4u) {
        length = 4;
        if (c == 0xf0u) lo = 0x90u;
        if (c == 0xf4u) hi = 0x8fu;
    } else
        return 0;
    if (available < length) return 0;
    if (s[1] < lo || s[1] > hi) return 0;
    for (size_t i = 2; i < length; ++i)
        if (s[i] < 0x80u || s[i] > 0xbfu) return 0;
    return length;
}

/* Also says whether the text ends inside a string or with brackets still open (*unclosed). */
static dwv_result_t prescan(const unsigned char *s, size_t n, int *unclosed)
{
    size_t depth = 0, values = 1;
    int in_string = 0;
    for (size_t i = 0; i < n;) {
        unsigned char c = s[i];
        if (c == 0) return fail_text(s, i, "a NUL byte: this is not JSON text");
        if (c >= 0x80u) {
            size_t length = utf8_sequence(s + i, n - i);
            if (!length) return fail_text(s, i, "invalid UTF-8 (byte 0x%02X); scene files are UTF-8 text", c);
            i += length;
            continue;
        }
        if (in_string) {
            if (c == '"') in_string = 0;
            if (c == '\\' && i + 1 < n && s[i + 1] < 0x80u) {
                if (s[i + 1] == 'u' && n - i >= 6 && memcmp(s + i + 2, "0000", 4) == 0)
                    return fail_text(s, i, "\\u0000 (a NUL character) in a string");
                i += 2;
                continue;
            }
            ++i;
            continue;
        }
        switch (c) {
        case '"': in_string = 1; break;
        case '[':
        case '{':
            if (++depth > DWVS_SCENE_MAX_DEPTH)
                return fail_text(s, i, "arrays and objects nested deeper than %u levels", DWVS_SCENE_MAX_DEPTH);
            ++values;
            break;
        case ']':
        case '}':
            if (depth) --depth;
            break;
        case ',':
            if (++values > DWVS_SCENE_MAX_VALUES)
                return fail_text(s, i, "more than %u values; large meshes belong in OBJ or PLY files",
                                 DWVS_SCENE_MAX_VALUES);
            break;
        default: break;
        }
        ++i;
    }
    *unclosed = in_string || depth > 0;
    return DWV_SUCCESS;
}

/* A few characters of the text at `offset`, printable ASCII only, for a syntax-error message. */
static void snippet(const unsigned char *s, size_t n, size_t offset, char out[24])
{
    size_t k = 0;
    for (size_t i = offset; i < n && k < 16; ++i) {
        if (s[i] == '\n' || s[i] == '\r') break;
        out[k++] = (s[i] >= 0x20u && s[i] < 0x7fu) ? (char)s[i] : '?';
    }
    out[k] = '\0';
}

static dwv_result_t read_scene(dwvs_parser *ps, const cJSON *root)
{
    static const char *const keys[] = {"version", "description", "materials", "meshes",
                                       "lights",  "world",       "camera",    "bake", "textures"};
    if (!cJSON_IsObject(root))
        return dwvs_fail_at(DWV_ERROR_FORMAT, "", "expected an object, found %s", dwvs_type_name(root));
    DWV_TRY(dwvs_check_keys(root, "", keys, sizeof keys / sizeof keys[0]));
    const cJSON *version = dwvs_member(root, "version");
    if (!version) return dwvs_fail_at(DWV_ERROR_FORMAT, "", "missing key 'version' (this library reads version 1)");
    uint64_t v = 0;
    DWV_TRY(dwvs_read_integer(version, "version", 1.0, 9007199254740992.0, &v));
    if (v != FORMAT_VERSION)
        return dwvs_fail_at(DWV_ERROR_FORMAT, "version", "version %llu is newer than this library reads (%d)",
                            (unsigned long long)v, FORMAT_VERSION);
    const cJSON *description = dwvs_member(root, "description");
    if (description && !cJSON_IsString(description))
        return dwvs_fail_at(DWV_ERROR_FORMAT, "description", "expected a string, found %s", dwvs_type_name(description));

    const cJSON *materials = dwvs_member(root, "materials"), *meshes = dwvs_member(root, "meshes");
    const cJSON *textures = dwvs_member(root, "textures");
    if (textures) DWV_TRY(dwvs_read_textures(ps, textures));
    if (materials) DWV_TRY(dwvs_read_materials(ps, materials));
    if (!meshes) return dwvs_fail_at(DWV_ERROR_FORMAT, "", "missing key 'meshes'");
    DWV_TRY(dwvs_read_meshes(ps, meshes));
    const cJSON *lights = dwvs_member(root, "lights"), *world = dwvs_member(root, "world"), *camera = dwvs_member(root, "camera"),
                *bake = dwvs_member(root, "bake");
    if (lights) DWV_TRY(dwvs_read_lights(ps, lights));
    if (world) DWV_TRY(dwvs_read_world(ps, world));
    if (camera) DWV_TRY(dwvs_read_camera(ps, camera));
    if (bake) DWV_TRY(dwvs_read_bake(ps, bake));
    dwv_result_t r = dwv_scene_commit(ps->scene);
    return r == DWV_SUCCESS ? r : dwvs_prefix_capi(r, "scene");
}

dwv_result_t dwvs_scene_from_json(const char *json, size_t size, const char *base_dir, dwv_scene_t **scene,
                                   dwv_bake_options_t *options)
{
    *scene = NULL;
    const unsigned char *text = (const unsigned char *)json;
    if (size == 0) return dwv_fail(DWV_ERROR_FORMAT, "the scene text is empty");
    if (size > DWVS_SCENE_MAX_BYTES)
        return dwv_fail(DWV_ERROR_FORMAT, "the scene text is %zu bytes, more than %u", size, DWVS_SCENE_MAX_BYTES);
    size_t skip = 0;
    if (size >= 3 && text[0] == 0xefu && text[1] == 0xbbu && text[2] == 0xbfu) skip = 3; /* a UTF-8 BOM */
    int unclosed = 0;
    DWV_TRY(prescan(text, size, &unclosed));

    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(json + skip, size - skip, &end, 0);
    if (!root) {
        size_t at = end ? (size_t)(end - json) : size;
        if (at > size) at = size;
        char near[24];
        snippet(text, size, at, near);
        if (unclosed && at + 1 >= size)
            return fail_text(text, at, "not valid JSON: the text ends inside a string, array or object (near '%s')",
                             near);
        return fail_text(text, at, "not valid JSON (near '%s')", near);
    }
    /* cJSON stops after the first value; anything but white space after it is an error. */
    size_t rest = (size_t)(end - json);
    while (rest < size && (text[rest] == ' ' || text[rest] == '\t' || text[rest] == '\n' || text[rest] == '\r'))
        ++rest;
    if (rest < size) {
        cJSON_Delete(root);
        char near[24];
        snippet(text, size, rest, near);
        return fail_text(text, rest, "text after the end of the JSON value (near '%s')", near);
    }

    dwvs_parser ps;
    memset(&ps, 0, sizeof ps);
    ps.base_dir = base_dir;
    if (options) ps.options = *options;
    dwv_result_t r = dwv_scene_create(&ps.scene);
    if (r == DWV_SUCCESS) r = read_scene(&ps, root);
    free(ps.materials);
    free(ps.textures);
    free(ps.meshes);
    cJSON_Delete(root);
    if (r != DWV_SUCCESS) {
        dwv_scene_release(ps.scene);
        return r;
    }
    if (options) {
        uint32_t struct_size = options->struct_size;
        *options = ps.options;
        options->struct_size = struct_size;
    }
    *scene = ps.scene;
    return DWV_SUCCESS;
}
