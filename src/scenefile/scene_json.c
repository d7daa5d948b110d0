/* JSON scene files (docs/scene-format.md) into a committed scene, through the public dwv_scene_*
 * API only: every value is checked for its type here, its range by the capi call it goes to (whose
 * message is then prefixed with the value's JSON path), so the file format and the C API cannot
 * disagree about what is allowed.
 *
 * Hostile text is met in two stages. A first pass over the bytes checks what cJSON does not:
 * UTF-8 validity (RFC 8259 section 8.1), no NUL bytes or \u0000 escapes (which would cut C
 * strings short), a nesting depth limit (cJSON recurses once per level) and a cap on the number
 * of values (its memory, about 64 bytes each). Then cJSON parses, and the schema walk below
 * rejects unknown keys, duplicate keys, wrong types and numbers that overflowed to infinity. */
#define _POSIX_C_SOURCE 200809L
#include "scenefile/scene_json.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "util/error.h"
#include "scenefile/mesh_file.h"
#include "scenefile/transform.h"

#define PATH_SIZE 192  /* a JSON path in a message */
#define SHOWN_BYTES 40 /* of a user's string shown in a message, before "..." */
#define SHOWN_SIZE (SHOWN_BYTES + 8)
#define MESSAGE_SIZE 400
#define MAX_FILE_PATH 4096
#define FORMAT_VERSION 1

/* ---- messages ----------------------------------------------------------------------------- */

/* A user's string as a message shows it: at most SHOWN_BYTES bytes, cut at a character boundary
 * (the text is valid UTF-8 by then), control characters as '?', "..." if cut. */
static const char *shown(const char *s, char out[SHOWN_SIZE])
{
    size_t n = 0;
    for (; s[n] && n < SHOWN_BYTES; ++n) {
        unsigned char c = (unsigned char)s[n];
        out[n] = (c < 0x20u || c == 0x7fu) ? '?' : (char)c;
    }
    if (!s[n]) {
        out[n] = '\0';
        return out;
    }
    /* Cut before the character that straddles the limit (s[n] would continue it). */
    while (n > 0 && ((unsigned char)s[n] & 0xc0u) == 0x80u) --n;
    memcpy(out + n, "...", 4);
    return out;
}

/* A path cut short ends in "..." (paths only ever appear in messages). */
static void path_cut(char out[PATH_SIZE], int written)
{
    if (written < 0 || written >= PATH_SIZE) memcpy(out + PATH_SIZE - 4, "...", 4);
}

static void path_key(char out[PATH_SIZE], const char *parent, const char *key)
{
    char k[SHOWN_SIZE];
    if (parent[0])
        path_cut(out, snprintf(out, PATH_SIZE, "%s.%s", parent, shown(key, k)));
    else
        path_cut(out, snprintf(out, PATH_SIZE, "%s", shown(key, k)));
}

static void path_index(char out[PATH_SIZE], const char *parent, size_t index)
{
    path_cut(out, snprintf(out, PATH_SIZE, "%s[%zu]", parent, index));
}

#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static dwv_result_t fail_at(dwv_result_t code, const char *path, const char *format, ...)
{
    char message[MESSAGE_SIZE];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    return dwv_fail(code, "%s: %s", path[0] ? path : "(top level)", message);
}

/* A capi call failed: keep its code and message, prefixed with the JSON path it came from. */
static dwv_result_t prefix_capi(dwv_result_t code, const char *path)
{
    char message[MESSAGE_SIZE];
    snprintf(message, sizeof message, "%s", dwv_last_error_message());
    return dwv_fail(code, "%s: %s", path, message);
}

static const char *type_name(const cJSON *item)
{
    if (cJSON_IsNull(item)) return "null";
    if (cJSON_IsBool(item)) return "a boolean";
    if (cJSON_IsNumber(item)) return "a number";
    if (cJSON_IsString(item)) return "a string";
    if (cJSON_IsArray(item)) return "an array";
    if (cJSON_IsObject(item)) return "an object";
    return "an invalid value";
}

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

/* ---- typed readers -------------------------------------------------------------------------- */

/* The object's keys must come from `keys`, each at most once. */
static dwv_result_t check_keys(const cJSON *object, const char *path, const char *const *keys, size_t count)
{
    if (!cJSON_IsObject(object))
        return fail_at(DWV_ERROR_FORMAT, path, "expected an object, found %s", type_name(object));
    unsigned char seen[32] = {0};
    for (const cJSON *child = object->child; child; child = child->next) {
        size_t k = 0;
        while (k < count && strcmp(child->string, keys[k]) != 0) ++k;
        char name[SHOWN_SIZE];
        if (k == count) {
            char known[MESSAGE_SIZE / 2] = "";
            size_t used = 0;
            for (size_t j = 0; j < count && used < sizeof known; ++j)
                used += (size_t)snprintf(known + used, sizeof known - used, "%s%s", j ? ", " : "", keys[j]);
            return fail_at(DWV_ERROR_FORMAT, path, "unknown key '%s' (expected %s)", shown(child->string, name),
                           known);
        }
        if (k < sizeof seen && seen[k])
            return fail_at(DWV_ERROR_FORMAT, path, "the key '%s' appears twice", keys[k]);
        if (k < sizeof seen) seen[k] = 1;
    }
    return DWV_SUCCESS;
}

static const cJSON *member(const cJSON *object, const char *key)
{
    return cJSON_GetObjectItemCaseSensitive(object, key);
}

static dwv_result_t read_number(const cJSON *item, const char *path, double *out)
{
    if (!cJSON_IsNumber(item))
        return fail_at(DWV_ERROR_FORMAT, path, "expected a number, found %s", type_name(item));
    /* JSON has no NaN or infinity, but 1e999 parses to infinity: refuse it here. */
    if (!isfinite(item->valuedouble))
        return fail_at(DWV_ERROR_FORMAT, path, "the number is too large (beyond %g)", DBL_MAX);
    *out = item->valuedouble;
    return DWV_SUCCESS;
}

/* A whole number in [lo, hi] (hi at most 2^53, where doubles still count by ones). */
static dwv_result_t read_integer(const cJSON *item, const char *path, double lo, double hi, uint64_t *out)
{
    double v = 0.0;
    DWV_TRY(read_number(item, path, &v));
    if (v != floor(v)) return fail_at(DWV_ERROR_FORMAT, path, "expected a whole number, found %.17g", v);
    if (v < lo || v > hi)
        return fail_at(DWV_ERROR_OUT_OF_RANGE, path, "%.17g is outside [%.17g, %.17g]", v, lo, hi);
    *out = (uint64_t)v;
    return DWV_SUCCESS;
}

static dwv_result_t read_u32(const cJSON *item, const char *path, uint32_t lo, uint32_t hi, uint32_t *out)
{
    uint64_t v = 0;
    DWV_TRY(read_integer(item, path, lo, hi, &v));
    *out = (uint32_t)v;
    return DWV_SUCCESS;
}

static dwv_result_t read_vector(const cJSON *item, const char *path, size_t n, double *out)
{
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != (int)n)
        return fail_at(DWV_ERROR_FORMAT, path, "expected an array of %zu numbers, found %s%s", n, type_name(item),
                       cJSON_IsArray(item) ? " of another length" : "");
    size_t i = 0;
    for (const cJSON *e = item->child; e; e = e->next, ++i) {
        char p[PATH_SIZE];
        path_index(p, path, i);
        DWV_TRY(read_number(e, p, &out[i]));
    }
    return DWV_SUCCESS;
}

static dwv_result_t read_string(const cJSON *item, const char *path, const char **out)
{
    if (!cJSON_IsString(item) || !item->valuestring)
        return fail_at(DWV_ERROR_FORMAT, path, "expected a string, found %s", type_name(item));
    if (!item->valuestring[0]) return fail_at(DWV_ERROR_FORMAT, path, "the string is empty");
    *out = item->valuestring;
    return DWV_SUCCESS;
}

/* One of `names` (in order of the values they stand for). */
static dwv_result_t read_choice(const cJSON *item, const char *path, const char *const *names, size_t count,
                                size_t *out)
{
    const char *s = NULL;
    DWV_TRY(read_string(item, path, &s));
    for (size_t i = 0; i < count; ++i)
        if (strcmp(s, names[i]) == 0) {
            *out = i;
            return DWV_SUCCESS;
        }
    char known[MESSAGE_SIZE / 2] = "", name[SHOWN_SIZE];
    size_t used = 0;
    for (size_t j = 0; j < count && used < sizeof known; ++j)
        used += (size_t)snprintf(known + used, sizeof known - used, "%s'%s'", j ? ", " : "", names[j]);
    return fail_at(DWV_ERROR_UNKNOWN_NAME, path, "unknown value '%s' (expected %s)", shown(s, name), known);
}

/* Optional members: each reader leaves *out alone when the key is absent. */
static dwv_result_t opt_number(const cJSON *object, const char *parent, const char *key, double *out)
{
    const cJSON *item = member(object, key);
    if (!item) return DWV_SUCCESS;
    char p[PATH_SIZE];
    path_key(p, parent, key);
    return read_number(item, p, out);
}

static dwv_result_t opt_vector(const cJSON *object, const char *parent, const char *key, size_t n, double *out)
{
    const cJSON *item = member(object, key);
    if (!item) return DWV_SUCCESS;
    char p[PATH_SIZE];
    path_key(p, parent, key);
    return read_vector(item, p, n, out);
}

static dwv_result_t opt_u32(const cJSON *object, const char *parent, const char *key, uint32_t lo, uint32_t hi,
                            uint32_t *out)
{
    const cJSON *item = member(object, key);
    if (!item) return DWV_SUCCESS;
    char p[PATH_SIZE];
    path_key(p, parent, key);
    return read_u32(item, p, lo, hi, out);
}

/* An array of numbers whose length is a multiple of `group`, as floats. */
static dwv_result_t read_floats(const cJSON *item, const char *path, size_t group, size_t *count, float **out)
{
    if (!cJSON_IsArray(item))
        return fail_at(DWV_ERROR_FORMAT, path, "expected an array of numbers, found %s", type_name(item));
    size_t n = 0;
    for (const cJSON *e = item->child; e; e = e->next) ++n;
    if (n == 0 || n % group)
        return fail_at(DWV_ERROR_FORMAT, path, "%zu numbers: expected a non-zero multiple of %zu", n, group);
    float *values = malloc(n * sizeof *values);
    if (!values) return fail_at(DWV_ERROR_OUT_OF_MEMORY, path, "no memory for %zu numbers", n);
    size_t i = 0;
    for (const cJSON *e = item->child; e; e = e->next, ++i) {
        char p[PATH_SIZE];
        double v = 0.0;
        path_index(p, path, i);
        dwv_result_t r = read_number(e, p, &v);
        if (r == DWV_SUCCESS && fabs(v) > FLT_MAX)
            r = fail_at(DWV_ERROR_OUT_OF_RANGE, p, "%.17g does not fit a float", v);
        if (r != DWV_SUCCESS) {
            free(values);
            return r;
        }
        values[i] = (float)v;
    }
    *count = n;
    *out = values;
    return DWV_SUCCESS;
}

static dwv_result_t read_indices(const cJSON *item, const char *path, size_t *count, uint32_t **out)
{
    if (!cJSON_IsArray(item))
        return fail_at(DWV_ERROR_FORMAT, path, "expected an array of whole numbers, found %s", type_name(item));
    size_t n = 0;
    for (const cJSON *e = item->child; e; e = e->next) ++n;
    if (n == 0 || n % 3u)
        return fail_at(DWV_ERROR_FORMAT, path, "%zu indices: expected a non-zero multiple of 3 (triangles)", n);
    uint32_t *values = malloc(n * sizeof *values);
    if (!values) return fail_at(DWV_ERROR_OUT_OF_MEMORY, path, "no memory for %zu indices", n);
    size_t i = 0;
    for (const cJSON *e = item->child; e; e = e->next, ++i) {
        char p[PATH_SIZE];
        path_index(p, path, i);
        dwv_result_t r = read_u32(e, p, 0u, UINT32_MAX, &values[i]);
        if (r != DWV_SUCCESS) {
            free(values);
            return r;
        }
    }
    *count = n;
    *out = values;
    return DWV_SUCCESS;
}

/* ---- transforms ----------------------------------------------------------------------------- */

static const double identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};

static dwv_result_t read_transform(const cJSON *item, const char *path, double m[12])
{
    static const char *const keys[] = {"matrix", "translate", "rotate", "scale", "look_at"};
    DWV_TRY(check_keys(item, path, keys, sizeof keys / sizeof keys[0]));
    char p[PATH_SIZE];
    const cJSON *matrix = member(item, "matrix"), *look = member(item, "look_at");
    int trs = member(item, "translate") || member(item, "rotate") || member(item, "scale");
    if ((matrix != NULL) + (look != NULL) + trs > 1)
        return fail_at(DWV_ERROR_FORMAT, path, "give one of 'matrix', 'look_at' or 'translate'/'rotate'/'scale'");
    if (matrix) {
        path_key(p, path, "matrix");
        int n = cJSON_IsArray(matrix) ? cJSON_GetArraySize(matrix) : 0;
        if (n != 12 && n != 16)
            return fail_at(DWV_ERROR_FORMAT, p, "expected 12 or 16 numbers (row-major), found %s%s",
                           type_name(matrix), cJSON_IsArray(matrix) ? " of another length" : "");
        double values[16];
        DWV_TRY(read_vector(matrix, p, (size_t)n, values));
        if (n == 16 && !(values[12] == 0.0 && values[13] == 0.0 && values[14] == 0.0 && values[15] == 1.0))
            return fail_at(DWV_ERROR_INVALID_ARGUMENT, p, "the last row must be 0 0 0 1 (no projection)");
        memcpy(m, values, 12 * sizeof *m);
        return DWV_SUCCESS;
    }
    if (look) {
        static const char *const look_keys[] = {"eye", "target", "up"};
        path_key(p, path, "look_at");
        DWV_TRY(check_keys(look, p, look_keys, 3));
        double eye[3], target[3], up[3] = {0.0, 0.0, 1.0};
        if (!member(look, "eye") || !member(look, "target"))
            return fail_at(DWV_ERROR_FORMAT, p, "needs 'eye' and 'target'");
        DWV_TRY(opt_vector(look, p, "eye", 3, eye));
        DWV_TRY(opt_vector(look, p, "target", 3, target));
        DWV_TRY(opt_vector(look, p, "up", 3, up));
        int bad = dwvs_transform_look_at(eye, target, up, m);
        if (bad == -1) return fail_at(DWV_ERROR_INVALID_ARGUMENT, p, "eye and target coincide");
        if (bad) return fail_at(DWV_ERROR_INVALID_ARGUMENT, p, "up is zero or parallel to the view direction");
        return DWV_SUCCESS;
    }
    double t[3] = {0, 0, 0}, r[3] = {0, 0, 0}, s[3] = {1, 1, 1};
    DWV_TRY(opt_vector(item, path, "translate", 3, t));
    DWV_TRY(opt_vector(item, path, "rotate", 3, r));
    const cJSON *scale = member(item, "scale");
    if (cJSON_IsNumber(scale)) {
        path_key(p, path, "scale");
        DWV_TRY(read_number(scale, p, &s[0]));
        s[1] = s[2] = s[0];
    } else {
        DWV_TRY(opt_vector(item, path, "scale", 3, s));
    }
    dwvs_transform_trs(t, r, s, m);
    return DWV_SUCCESS;
}

static dwv_result_t opt_transform(const cJSON *object, const char *parent, double m[12])
{
    const cJSON *item = member(object, "transform");
    if (!item) return DWV_SUCCESS;
    char p[PATH_SIZE];
    path_key(p, parent, "transform");
    return read_transform(item, p, m);
}

/* ---- the scene ------------------------------------------------------------------------------ */

typedef struct named {
    const char *name;
    uint32_t id;
    uint32_t has_uvs;
} named;

typedef struct parser {
    dwv_scene_t *scene;
    const char *base_dir;
    named *materials;
    size_t material_count;
    named *meshes; /* in file order; names may be NULL */
    size_t mesh_count;
    int has_camera;
    dwv_bake_options_t options;
} parser;

static int compare_named(const void *a, const void *b)
{
    return strcmp(((const named *)a)->name, ((const named *)b)->name);
}

static dwv_result_t read_material(parser *ps, const cJSON *item, const char *path)
{
    static const char *const keys[] = {"kind", "base_color", "subsurface_weight", "subsurface_color",
                                       "subsurface_radius", "subsurface_scale", "subsurface_anisotropy",
                                       "subsurface_ior", "subsurface_exit", "roughness"};
    static const char *const kinds[] = {"subsurface", "diffuse"};
    static const char *const exits[] = {"lambert", "principled_v1"};
    DWV_TRY(check_keys(item, path, keys, sizeof keys / sizeof keys[0]));
    dwv_material_t m = DWV_MATERIAL_INIT;
    const cJSON *kind = member(item, "kind");
    if (kind) {
        char p[PATH_SIZE];
        size_t k = 0;
        path_key(p, path, "kind");
        DWV_TRY(read_choice(kind, p, kinds, 2, &k));
        m.kind = k == 0 ? DWV_MATERIAL_SUBSURFACE : DWV_MATERIAL_DIFFUSE;
    }
    DWV_TRY(opt_vector(item, path, "base_color", 3, m.base_color));
    DWV_TRY(opt_number(item, path, "subsurface_weight", &m.subsurface_weight));
    DWV_TRY(opt_vector(item, path, "subsurface_color", 3, m.subsurface_color));
    DWV_TRY(opt_vector(item, path, "subsurface_radius", 3, m.subsurface_radius));
    DWV_TRY(opt_number(item, path, "subsurface_scale", &m.subsurface_scale));
    DWV_TRY(opt_number(item, path, "subsurface_anisotropy", &m.subsurface_anisotropy));
    DWV_TRY(opt_number(item, path, "subsurface_ior", &m.subsurface_ior));
    const cJSON *exit = member(item, "subsurface_exit");
    if (exit) {
        char p[PATH_SIZE];
        size_t k = 0;
        path_key(p, path, "subsurface_exit");
        DWV_TRY(read_choice(exit, p, exits, 2, &k));
        m.subsurface_exit = k == 0 ? DWV_SUBSURFACE_EXIT_LAMBERT : DWV_SUBSURFACE_EXIT_PRINCIPLED_V1;
    }
    DWV_TRY(opt_number(item, path, "roughness", &m.roughness));
    uint32_t id;
    dwv_result_t r = dwv_scene_add_material(ps->scene, &m, &id);
    if (r != DWV_SUCCESS) return prefix_capi(r, path);
    ps->materials[ps->material_count].name = item->string;
    ps->materials[ps->material_count].id = id;
    ++ps->material_count;
    return DWV_SUCCESS;
}

static dwv_result_t read_materials(parser *ps, const cJSON *item)
{
    if (!cJSON_IsObject(item))
        return fail_at(DWV_ERROR_FORMAT, "materials", "expected an object of materials by name, found %s",
                       type_name(item));
    size_t n = 0;
    for (const cJSON *c = item->child; c; c = c->next) ++n;
    ps->materials = calloc(n ? n : 1u, sizeof *ps->materials);
    if (!ps->materials) return fail_at(DWV_ERROR_OUT_OF_MEMORY, "materials", "no memory for %zu names", n);
    for (const cJSON *c = item->child; c; c = c->next) {
        char p[PATH_SIZE];
        path_key(p, "materials", c->string);
        if (!c->string[0]) return fail_at(DWV_ERROR_FORMAT, "materials", "a material has an empty name");
        DWV_TRY(read_material(ps, c, p));
    }
    qsort(ps->materials, ps->material_count, sizeof *ps->materials, compare_named);
    for (size_t i = 1; i < ps->material_count; ++i)
        if (strcmp(ps->materials[i - 1].name, ps->materials[i].name) == 0) {
            char name[SHOWN_SIZE];
            return fail_at(DWV_ERROR_FORMAT, "materials", "the name '%s' appears twice",
                           shown(ps->materials[i].name, name));
        }
    return DWV_SUCCESS;
}

static dwv_result_t resolve_path(const char *base_dir, const char *file, const char *path, char out[MAX_FILE_PATH])
{
    int n;
    if (file[0] == '/' || !base_dir || !base_dir[0])
        n = snprintf(out, MAX_FILE_PATH, "%s", file);
    else
        n = snprintf(out, MAX_FILE_PATH, "%s/%s", base_dir, file);
    if (n < 0 || n >= MAX_FILE_PATH)
        return fail_at(DWV_ERROR_OUT_OF_RANGE, path, "the path is longer than %d bytes", MAX_FILE_PATH - 1);
    return DWV_SUCCESS;
}

static dwv_result_t read_mesh(parser *ps, const cJSON *item, const char *path, named *record)
{
    static const char *const keys[] = {"name",    "material", "transform", "file", "positions",
                                       "indices", "normals",  "uvs",       "shadow_terminator_geometry_offset"};
    DWV_TRY(check_keys(item, path, keys, sizeof keys / sizeof keys[0]));
    char p[PATH_SIZE], name[SHOWN_SIZE];
    const cJSON *name_item = member(item, "name");
    record->name = NULL;
    if (name_item) {
        path_key(p, path, "name");
        DWV_TRY(read_string(name_item, p, &record->name));
    }

    const cJSON *material_item = member(item, "material");
    if (!material_item) return fail_at(DWV_ERROR_FORMAT, path, "missing key 'material'");
    const char *material_name = NULL;
    path_key(p, path, "material");
    DWV_TRY(read_string(material_item, p, &material_name));
    named key = {material_name, 0u, 0u};
    const named *material = ps->material_count
                                ? bsearch(&key, ps->materials, ps->material_count, sizeof key, compare_named)
                                : NULL;
    if (!material) return fail_at(DWV_ERROR_UNKNOWN_NAME, p, "unknown material '%s'", shown(material_name, name));

    dwv_mesh_t mesh = DWV_MESH_INIT;
    mesh.material_id = material->id;
    memcpy(mesh.transform, identity, sizeof identity);
    DWV_TRY(opt_transform(item, path, mesh.transform));
    DWV_TRY(opt_number(item, path, "shadow_terminator_geometry_offset", &mesh.shadow_terminator_geometry_offset));

    const cJSON *file = member(item, "file");
    int inline_data = member(item, "positions") || member(item, "indices") || member(item, "normals") ||
                      member(item, "uvs");
    if (file && inline_data)
        return fail_at(DWV_ERROR_FORMAT, path, "give either 'file' or 'positions'/'indices'/'normals'/'uvs'");
    if (!file && !(member(item, "positions") && member(item, "indices")))
        return fail_at(DWV_ERROR_FORMAT, path, "needs 'file', or 'positions' and 'indices'");

    dwv_result_t r;
    uint32_t mesh_id = 0;
    if (file) {
        const char *file_name = NULL;
        char resolved[MAX_FILE_PATH];
        path_key(p, path, "file");
        DWV_TRY(read_string(file, p, &file_name));
        DWV_TRY(resolve_path(ps->base_dir, file_name, p, resolved));
        dwvs_mesh_data data;
        r = dwvs_mesh_file_read(resolved, &data);
        if (r != DWV_SUCCESS) return prefix_capi(r, p);
        mesh.vertex_count = data.vertex_count;
        mesh.triangle_count = data.triangle_count;
        mesh.positions = data.positions;
        mesh.indices = data.indices;
        mesh.normals = data.normals;
        mesh.uvs = data.uvs;
        r = dwv_scene_add_mesh(ps->scene, &mesh, &mesh_id);
        if (r != DWV_SUCCESS) {
            char where[PATH_SIZE + MAX_FILE_PATH / 16];
            snprintf(where, sizeof where, "%s ('%s')", path, shown(file_name, name));
            r = prefix_capi(r, where);
        }
        record->has_uvs = data.uvs != NULL;
        dwvs_mesh_data_free(&data);
    } else {
        float *positions = NULL, *normals = NULL, *uvs = NULL;
        uint32_t *indices = NULL;
        size_t np = 0, ni = 0, nn = 0, nu = 0;
        path_key(p, path, "positions");
        r = read_floats(member(item, "positions"), p, 3, &np, &positions);
        if (r == DWV_SUCCESS) {
            path_key(p, path, "indices");
            r = read_indices(member(item, "indices"), p, &ni, &indices);
        }
        if (r == DWV_SUCCESS && member(item, "normals")) {
            path_key(p, path, "normals");
            r = read_floats(member(item, "normals"), p, 3, &nn, &normals);
            if (r == DWV_SUCCESS && nn != np)
                r = fail_at(DWV_ERROR_FORMAT, p, "%zu numbers for %zu positions: one normal per vertex", nn,
                            np / 3u);
        }
        if (r == DWV_SUCCESS && member(item, "uvs")) {
            path_key(p, path, "uvs");
            r = read_floats(member(item, "uvs"), p, 2, &nu, &uvs);
            if (r == DWV_SUCCESS && nu != 2u * ni)
                r = fail_at(DWV_ERROR_FORMAT, p, "%zu numbers for %zu triangles: one (u, v) per triangle corner",
                            nu, ni / 3u);
        }
        if (r == DWV_SUCCESS) {
            mesh.vertex_count = (uint32_t)(np / 3u);
            mesh.triangle_count = (uint32_t)(ni / 3u);
            mesh.positions = positions;
            mesh.indices = indices;
            mesh.normals = normals;
            mesh.uvs = uvs;
            r = dwv_scene_add_mesh(ps->scene, &mesh, &mesh_id);
            if (r != DWV_SUCCESS) r = prefix_capi(r, path);
        }
        record->has_uvs = uvs != NULL;
        free(positions);
        free(indices);
        free(normals);
        free(uvs);
    }
    record->id = mesh_id;
    return r;
}

static dwv_result_t read_meshes(parser *ps, const cJSON *item)
{
    if (!cJSON_IsArray(item))
        return fail_at(DWV_ERROR_FORMAT, "meshes", "expected an array of meshes, found %s", type_name(item));
    size_t n = 0;
    for (const cJSON *c = item->child; c; c = c->next) ++n;
    ps->meshes = calloc(n ? n : 1u, sizeof *ps->meshes);
    if (!ps->meshes) return fail_at(DWV_ERROR_OUT_OF_MEMORY, "meshes", "no memory for %zu meshes", n);
    size_t i = 0;
    for (const cJSON *c = item->child; c; c = c->next, ++i) {
        char p[PATH_SIZE];
        path_index(p, "meshes", i);
        DWV_TRY(read_mesh(ps, c, p, &ps->meshes[i]));
        ps->mesh_count = i + 1;
    }
    /* Names must be unique (a UV bake picks a mesh by name). */
    named *sorted = malloc((n ? n : 1u) * sizeof *sorted);
    if (!sorted) return fail_at(DWV_ERROR_OUT_OF_MEMORY, "meshes", "no memory for %zu names", n);
    size_t k = 0;
    for (size_t j = 0; j < ps->mesh_count; ++j)
        if (ps->meshes[j].name) sorted[k++] = ps->meshes[j];
    qsort(sorted, k, sizeof *sorted, compare_named);
    dwv_result_t r = DWV_SUCCESS;
    for (size_t j = 1; j < k && r == DWV_SUCCESS; ++j)
        if (strcmp(sorted[j - 1].name, sorted[j].name) == 0) {
            char name[SHOWN_SIZE];
            r = fail_at(DWV_ERROR_FORMAT, "meshes", "the name '%s' is given to two meshes", shown(sorted[j].name, name));
        }
    free(sorted);
    return r;
}

static dwv_result_t read_light(parser *ps, const cJSON *item, const char *path)
{
    static const char *const kinds[] = {"sun", "point", "area"};
    static const char *const shapes[] = {"rectangle", "disk"};
    static const char *const sun_keys[] = {"kind", "color", "strength", "direction", "angle"};
    static const char *const point_keys[] = {"kind", "color", "strength", "position", "radius"};
    static const char *const area_keys[] = {"kind", "shape", "color", "strength", "transform", "size_x", "size_y"};
    if (!cJSON_IsObject(item))
        return fail_at(DWV_ERROR_FORMAT, path, "expected an object, found %s", type_name(item));
    const cJSON *kind_item = member(item, "kind");
    if (!kind_item) return fail_at(DWV_ERROR_FORMAT, path, "missing key 'kind' ('sun', 'point' or 'area')");
    char p[PATH_SIZE];
    size_t kind = 0;
    path_key(p, path, "kind");
    DWV_TRY(read_choice(kind_item, p, kinds, 3, &kind));
    if (kind == 0)
        DWV_TRY(check_keys(item, path, sun_keys, sizeof sun_keys / sizeof sun_keys[0]));
    else if (kind == 1)
        DWV_TRY(check_keys(item, path, point_keys, sizeof point_keys / sizeof point_keys[0]));
    else
        DWV_TRY(check_keys(item, path, area_keys, sizeof area_keys / sizeof area_keys[0]));
    dwv_light_desc_t light = DWV_LIGHT_DESC_INIT;
    DWV_TRY(opt_vector(item, path, "color", 3, light.color));
    DWV_TRY(opt_number(item, path, "strength", &light.strength));
    if (kind == 0) {
        light.kind = DWV_LIGHT_SUN;
        DWV_TRY(opt_vector(item, path, "direction", 3, light.direction));
        double degrees = 0.0;
        DWV_TRY(opt_number(item, path, "angle", &degrees));
        light.angle = degrees * (3.14159265358979323846 / 180.0);
    } else if (kind == 1) {
        light.kind = DWV_LIGHT_POINT;
        DWV_TRY(opt_vector(item, path, "position", 3, light.position));
        DWV_TRY(opt_number(item, path, "radius", &light.radius));
    } else {
        size_t shape = 0;
        const cJSON *shape_item = member(item, "shape");
        if (shape_item) {
            path_key(p, path, "shape");
            DWV_TRY(read_choice(shape_item, p, shapes, 2, &shape));
        }
        light.kind = shape == 0 ? DWV_LIGHT_AREA_RECTANGLE : DWV_LIGHT_AREA_DISK;
        DWV_TRY(opt_transform(item, path, light.transform));
        DWV_TRY(opt_number(item, path, "size_x", &light.size_x));
        light.size_y = light.size_x; /* a square or a circle unless size_y says otherwise */
        DWV_TRY(opt_number(item, path, "size_y", &light.size_y));
    }
    dwv_result_t r = dwv_scene_add_light(ps->scene, &light);
    return r == DWV_SUCCESS ? r : prefix_capi(r, path);
}

static dwv_result_t read_lights(parser *ps, const cJSON *item)
{
    if (!cJSON_IsArray(item))
        return fail_at(DWV_ERROR_FORMAT, "lights", "expected an array of lights, found %s", type_name(item));
    size_t i = 0;
    for (const cJSON *c = item->child; c; c = c->next, ++i) {
        char p[PATH_SIZE];
        path_index(p, "lights", i);
        DWV_TRY(read_light(ps, c, p));
    }
    return DWV_SUCCESS;
}

static dwv_result_t read_world(parser *ps, const cJSON *item)
{
    static const char *const keys[] = {"color", "strength"};
    DWV_TRY(check_keys(item, "world", keys, 2));
    double color[3] = {1.0, 1.0, 1.0}, strength = 1.0;
    DWV_TRY(opt_vector(item, "world", "color", 3, color));
    DWV_TRY(opt_number(item, "world", "strength", &strength));
    dwv_result_t r = dwv_scene_set_world(ps->scene, color, strength);
    return r == DWV_SUCCESS ? r : prefix_capi(r, "world");
}

static dwv_result_t read_camera(parser *ps, const cJSON *item)
{
    static const char *const kinds[] = {"perspective", "orthographic"};
    static const char *const perspective_keys[] = {"kind", "transform", "focal_length", "sensor_width"};
    static const char *const orthographic_keys[] = {"kind", "transform", "ortho_scale"};
    if (!cJSON_IsObject(item))
        return fail_at(DWV_ERROR_FORMAT, "camera", "expected an object, found %s", type_name(item));
    size_t kind = 0;
    const cJSON *kind_item = member(item, "kind");
    if (kind_item) DWV_TRY(read_choice(kind_item, "camera.kind", kinds, 2, &kind));
    if (kind == 0)
        DWV_TRY(check_keys(item, "camera", perspective_keys, sizeof perspective_keys / sizeof perspective_keys[0]));
    else
        DWV_TRY(check_keys(item, "camera", orthographic_keys, sizeof orthographic_keys / sizeof orthographic_keys[0]));
    if (!member(item, "transform"))
        return fail_at(DWV_ERROR_FORMAT, "camera", "missing key 'transform' (a 'matrix' or a 'look_at')");
    dwv_camera_t camera = DWV_CAMERA_INIT;
    camera.kind = kind == 0 ? DWV_CAMERA_PERSPECTIVE : DWV_CAMERA_ORTHOGRAPHIC;
    DWV_TRY(opt_transform(item, "camera", camera.transform));
    DWV_TRY(opt_number(item, "camera", "focal_length", &camera.focal_length));
    DWV_TRY(opt_number(item, "camera", "sensor_width", &camera.sensor_width));
    DWV_TRY(opt_number(item, "camera", "ortho_scale", &camera.ortho_scale));
    dwv_result_t r = dwv_scene_set_camera(ps->scene, &camera);
    if (r != DWV_SUCCESS) return prefix_capi(r, "camera");
    ps->has_camera = 1;
    return DWV_SUCCESS;
}

/* The ranges of dwv_bake_options_t as capi/dwivedi.h states them: checked here because the bake
 * only checks them when it starts, and a file should fail where the value is written. */
#define MAX_SIDE 16384u
#define MAX_PIXELS (1u << 26)
#define MAX_SAMPLES (1u << 24)
#define MAX_THREADS 1024u
#define MAX_MARGIN 64u

static dwv_result_t read_seed(const cJSON *item, uint64_t *seed)
{
    static const char path[] = "bake.seed";
    if (cJSON_IsString(item)) { /* all 64 bits, which a JSON number (a double) cannot carry */
        const char *s = item->valuestring;
        uint64_t v = 0;
        if (!s[0]) return fail_at(DWV_ERROR_FORMAT, path, "the string is empty");
        for (; *s; ++s) {
            char name[SHOWN_SIZE];
            if (*s < '0' || *s > '9')
                return fail_at(DWV_ERROR_FORMAT, path, "'%s' is not a decimal number",
                               shown(item->valuestring, name));
            unsigned d = (unsigned)(*s - '0');
            if (v > (UINT64_MAX - d) / 10u)
                return fail_at(DWV_ERROR_OUT_OF_RANGE, path, "'%s' is larger than 2^64 - 1",
                               shown(item->valuestring, name));
            v = 10u * v + d;
        }
        *seed = v;
        return DWV_SUCCESS;
    }
    return read_integer(item, path, 0.0, 9007199254740992.0, seed);
}

static dwv_result_t read_bake(parser *ps, const cJSON *item)
{
    static const char *const keys[] = {"target",  "width",       "height",  "samples",   "technique",
                                       "channel_walks", "time_limit", "target_error", "seed", "threads",
                                       "max_events", "tile_size", "uv_mesh",     "uv_margin"};
    static const char *const targets[] = {"camera", "uv"};
    DWV_TRY(check_keys(item, "bake", keys, sizeof keys / sizeof keys[0]));
    dwv_bake_options_t *o = &ps->options;
    const cJSON *target = member(item, "target");
    if (target) {
        size_t t = 0;
        DWV_TRY(read_choice(target, "bake.target", targets, 2, &t));
        o->target = t == 0 ? DWV_BAKE_CAMERA : DWV_BAKE_UV;
    }
    DWV_TRY(opt_u32(item, "bake", "width", 1u, MAX_SIDE, &o->width));
    DWV_TRY(opt_u32(item, "bake", "height", 1u, MAX_SIDE, &o->height));
    if ((uint64_t)o->width * o->height > MAX_PIXELS)
        return fail_at(DWV_ERROR_OUT_OF_RANGE, "bake", "%u x %u is more than %u pixels", o->width, o->height,
                       MAX_PIXELS);
    const cJSON *samples = member(item, "samples");
    if (samples) DWV_TRY(read_integer(samples, "bake.samples", 1.0, (double)MAX_SAMPLES, &o->samples));
    const cJSON *technique = member(item, "technique");
    if (technique) {
        const char *name = NULL;
        DWV_TRY(read_string(technique, "bake.technique", &name));
        dwv_result_t r = dwv_technique_from_name(name, &o->technique);
        if (r != DWV_SUCCESS) return prefix_capi(r, "bake.technique");
    }
    const cJSON *channel_walks = member(item, "channel_walks");
    if (channel_walks) {
        const char *name = NULL;
        DWV_TRY(read_string(channel_walks, "bake.channel_walks", &name));
        dwv_result_t r = dwv_channel_walks_from_name(name, &o->channel_walks);
        if (r != DWV_SUCCESS) return prefix_capi(r, "bake.channel_walks");
    }
    DWV_TRY(opt_number(item, "bake", "time_limit", &o->time_limit));
    if (o->time_limit < 0.0)
        return fail_at(DWV_ERROR_OUT_OF_RANGE, "bake.time_limit", "%.17g is negative (0 means no limit)",
                       o->time_limit);
    DWV_TRY(opt_number(item, "bake", "target_error", &o->target_error));
    if (o->target_error < 0.0)
        return fail_at(DWV_ERROR_OUT_OF_RANGE, "bake.target_error", "%.17g is negative (0 means none)",
                       o->target_error);
    const cJSON *seed = member(item, "seed");
    if (seed) DWV_TRY(read_seed(seed, &o->seed));
    DWV_TRY(opt_u32(item, "bake", "threads", 0u, MAX_THREADS, &o->threads));
    DWV_TRY(opt_u32(item, "bake", "max_events", 0u, UINT32_MAX, &o->max_events));
    DWV_TRY(opt_u32(item, "bake", "tile_size", 0u, MAX_SIDE, &o->tile_size));

    const cJSON *uv_mesh = member(item, "uv_mesh"), *uv_margin = member(item, "uv_margin");
    if (o->target != DWV_BAKE_UV) {
        if (uv_mesh || uv_margin)
            return fail_at(DWV_ERROR_FORMAT, "bake", "'uv_mesh' and 'uv_margin' need \"target\": \"uv\"");
        if (!ps->has_camera) return fail_at(DWV_ERROR_FORMAT, "bake", "a camera bake needs a 'camera'");
        return DWV_SUCCESS;
    }
    DWV_TRY(opt_u32(item, "bake", "uv_margin", 0u, MAX_MARGIN, &o->uv_margin));
    if (!uv_mesh) return fail_at(DWV_ERROR_FORMAT, "bake", "a UV bake needs 'uv_mesh' (a mesh's name)");
    const char *name = NULL;
    char shown_name[SHOWN_SIZE];
    DWV_TRY(read_string(uv_mesh, "bake.uv_mesh", &name));
    for (size_t i = 0; i < ps->mesh_count; ++i)
        if (ps->meshes[i].name && strcmp(ps->meshes[i].name, name) == 0) {
            if (!ps->meshes[i].has_uvs)
                return fail_at(DWV_ERROR_INVALID_ARGUMENT, "bake.uv_mesh", "the mesh '%s' has no UVs",
                               shown(name, shown_name));
            o->uv_mesh = ps->meshes[i].id;
            return DWV_SUCCESS;
        }
    return fail_at(DWV_ERROR_UNKNOWN_NAME, "bake.uv_mesh", "no mesh is named '%s'", shown(name, shown_name));
}

static dwv_result_t read_scene(parser *ps, const cJSON *root)
{
    static const char *const keys[] = {"version", "description", "materials", "meshes",
                                       "lights",  "world",       "camera",    "bake"};
    if (!cJSON_IsObject(root))
        return fail_at(DWV_ERROR_FORMAT, "", "expected an object, found %s", type_name(root));
    DWV_TRY(check_keys(root, "", keys, sizeof keys / sizeof keys[0]));
    const cJSON *version = member(root, "version");
    if (!version) return fail_at(DWV_ERROR_FORMAT, "", "missing key 'version' (this library reads version 1)");
    uint64_t v = 0;
    DWV_TRY(read_integer(version, "version", 1.0, 9007199254740992.0, &v));
    if (v != FORMAT_VERSION)
        return fail_at(DWV_ERROR_FORMAT, "version", "version %llu is newer than this library reads (%d)",
                       (unsigned long long)v, FORMAT_VERSION);
    const cJSON *description = member(root, "description");
    if (description && !cJSON_IsString(description))
        return fail_at(DWV_ERROR_FORMAT, "description", "expected a string, found %s", type_name(description));

    const cJSON *materials = member(root, "materials"), *meshes = member(root, "meshes");
    if (materials) DWV_TRY(read_materials(ps, materials));
    if (!meshes) return fail_at(DWV_ERROR_FORMAT, "", "missing key 'meshes'");
    DWV_TRY(read_meshes(ps, meshes));
    const cJSON *lights = member(root, "lights"), *world = member(root, "world"), *camera = member(root, "camera"),
                *bake = member(root, "bake");
    if (lights) DWV_TRY(read_lights(ps, lights));
    if (world) DWV_TRY(read_world(ps, world));
    if (camera) DWV_TRY(read_camera(ps, camera));
    if (bake) DWV_TRY(read_bake(ps, bake));
    dwv_result_t r = dwv_scene_commit(ps->scene);
    return r == DWV_SUCCESS ? r : prefix_capi(r, "scene");
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

    parser ps;
    memset(&ps, 0, sizeof ps);
    ps.base_dir = base_dir;
    if (options) ps.options = *options;
    dwv_result_t r = dwv_scene_create(&ps.scene);
    if (r == DWV_SUCCESS) r = read_scene(&ps, root);
    free(ps.materials);
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
