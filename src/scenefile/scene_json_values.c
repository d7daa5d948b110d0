/* Typed JSON values: messages that name a value's JSON path, type-checked readers, transforms. */
#include "scenefile/scene_json_internal.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "scenefile/transform.h"
#include "util/error.h"

int dwvs_compare_named(const void *a, const void *b)
{
    return strcmp(((const dwvs_named *)a)->name, ((const dwvs_named *)b)->name);
}

/* ---- messages ----------------------------------------------------------------------------- */

const char *dwvs_shown(const char *s, char out[SHOWN_SIZE])
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

void dwvs_path_key(char out[PATH_SIZE], const char *parent, const char *key)
{
    char k[SHOWN_SIZE];
    if (parent[0])
        path_cut(out, snprintf(out, PATH_SIZE, "%s.%s", parent, dwvs_shown(key, k)));
    else
        path_cut(out, snprintf(out, PATH_SIZE, "%s", dwvs_shown(key, k)));
}

void dwvs_path_index(char out[PATH_SIZE], const char *parent, size_t index)
{
    path_cut(out, snprintf(out, PATH_SIZE, "%s[%zu]", parent, index));
}

dwv_result_t dwvs_fail_at(dwv_result_t code, const char *path, const char *format, ...)
{
    char message[MESSAGE_SIZE];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    return dwv_fail(code, "%s: %s", path[0] ? path : "(top level)", message);
}

dwv_result_t dwvs_prefix_capi(dwv_result_t code, const char *path)
{
    char message[MESSAGE_SIZE];
    snprintf(message, sizeof message, "%s", dwv_last_error_message());
    return dwv_fail(code, "%s: %s", path, message);
}

const char *dwvs_type_name(const cJSON *item)
{
    if (cJSON_IsNull(item)) return "null";
    if (cJSON_IsBool(item)) return "a boolean";
    if (cJSON_IsNumber(item)) return "a number";
    if (cJSON_IsString(item)) return "a string";
    if (cJSON_IsArray(item)) return "an array";
    if (cJSON_IsObject(item)) return "an object";
    return "an invalid value";
}

/* ---- typed readers -------------------------------------------------------------------------- */

dwv_result_t dwvs_check_keys(const cJSON *object, const char *path, const char *const *keys, size_t count)
{
    if (!cJSON_IsObject(object))
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "expected an object, found %s", dwvs_type_name(object));
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
            return dwvs_fail_at(DWV_ERROR_FORMAT, path, "unknown key '%s' (expected %s)", dwvs_shown(child->string, name),
                                known);
        }
        if (k < sizeof seen && seen[k])
            return dwvs_fail_at(DWV_ERROR_FORMAT, path, "the key '%s' appears twice", keys[k]);
        if (k < sizeof seen) seen[k] = 1;
    }
    return DWV_SUCCESS;
}

const cJSON *dwvs_member(const cJSON *object, const char *key)
{
    return cJSON_GetObjectItemCaseSensitive(object, key);
}

dwv_result_t dwvs_read_number(const cJSON *item, const char *path, double *out)
{
    if (!cJSON_IsNumber(item))
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "expected a number, found %s", dwvs_type_name(item));
    /* JSON has no NaN or infinity, but 1e999 parses to infinity: refuse it here. */
    if (!isfinite(item->valuedouble))
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "the number is too large (beyond %g)", DBL_MAX);
    *out = item->valuedouble;
    return DWV_SUCCESS;
}

dwv_result_t dwvs_read_integer(const cJSON *item, const char *path, double lo, double hi, uint64_t *out)
{
    double v = 0.0;
    DWV_TRY(dwvs_read_number(item, path, &v));
    if (v != floor(v)) return dwvs_fail_at(DWV_ERROR_FORMAT, path, "expected a whole number, found %.17g", v);
    if (v < lo || v > hi)
        return dwvs_fail_at(DWV_ERROR_OUT_OF_RANGE, path, "%.17g is outside [%.17g, %.17g]", v, lo, hi);
    *out = (uint64_t)v;
    return DWV_SUCCESS;
}

dwv_result_t dwvs_read_u32(const cJSON *item, const char *path, uint32_t lo, uint32_t hi, uint32_t *out)
{
    uint64_t v = 0;
    DWV_TRY(dwvs_read_integer(item, path, lo, hi, &v));
    *out = (uint32_t)v;
    return DWV_SUCCESS;
}

dwv_result_t dwvs_read_vector(const cJSON *item, const char *path, size_t n, double *out)
{
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != (int)n)
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "expected an array of %zu numbers, found %s%s", n, dwvs_type_name(item),
                            cJSON_IsArray(item) ? " of another length" : "");
    size_t i = 0;
    for (const cJSON *e = item->child; e; e = e->next, ++i) {
        char p[PATH_SIZE];
        dwvs_path_index(p, path, i);
        DWV_TRY(dwvs_read_number(e, p, &out[i]));
    }
    return DWV_SUCCESS;
}

dwv_result_t dwvs_read_string(const cJSON *item, const char *path, const char **out)
{
    if (!cJSON_IsString(item) || !item->valuestring)
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "expected a string, found %s", dwvs_type_name(item));
    if (!item->valuestring[0]) return dwvs_fail_at(DWV_ERROR_FORMAT, path, "the string is empty");
    *out = item->valuestring;
    return DWV_SUCCESS;
}

dwv_result_t dwvs_read_choice(const cJSON *item, const char *path, const char *const *names, size_t count,
                              size_t *out)
{
    const char *s = NULL;
    DWV_TRY(dwvs_read_string(item, path, &s));
    for (size_t i = 0; i < count; ++i)
        if (strcmp(s, names[i]) == 0) {
            *out = i;
            return DWV_SUCCESS;
        }
    char known[MESSAGE_SIZE / 2] = "", name[SHOWN_SIZE];
    size_t used = 0;
    for (size_t j = 0; j < count && used < sizeof known; ++j)
        used += (size_t)snprintf(known + used, sizeof known - used, "%s'%s'", j ? ", " : "", names[j]);
    return dwvs_fail_at(DWV_ERROR_UNKNOWN_NAME, path, "unknown value '%s' (expected %s)", dwvs_shown(s, name), known);
}

dwv_result_t dwvs_opt_number(const cJSON *object, const char *parent, const char *key, double *out)
{
    const cJSON *item = dwvs_member(object, key);
    if (!item) return DWV_SUCCESS;
    char p[PATH_SIZE];
    dwvs_path_key(p, parent, key);
    return dwvs_read_number(item, p, out);
}

dwv_result_t dwvs_opt_vector(const cJSON *object, const char *parent, const char *key, size_t n, double *out)
{
    const cJSON *item = dwvs_member(object, key);
    if (!item) return DWV_SUCCESS;
    char p[PATH_SIZE];
    dwvs_path_key(p, parent, key);
    return dwvs_read_vector(item, p, n, out);
}

dwv_result_t dwvs_opt_u32(const cJSON *object, const char *parent, const char *key, uint32_t lo, uint32_t hi,
                          uint32_t *out)
{
    const cJSON *item = dwvs_member(object, key);
    if (!item) return DWV_SUCCESS;
    char p[PATH_SIZE];
    dwvs_path_key(p, parent, key);
    return dwvs_read_u32(item, p, lo, hi, out);
}

dwv_result_t dwvs_opt_choice(const cJSON *object, const char *parent, const char *key, const char *const *names,
                             size_t count, size_t *out)
{
    const cJSON *item = dwvs_member(object, key);
    if (!item) return DWV_SUCCESS;
    char p[PATH_SIZE];
    dwvs_path_key(p, parent, key);
    return dwvs_read_choice(item, p, names, count, out);
}

/* An array of numbers whose length is a multiple of `group`, as floats. */

/* ---- transforms ----------------------------------------------------------------------------- */

static dwv_result_t read_transform(const cJSON *item, const char *path, double m[12])
{
    static const char *const keys[] = {"matrix", "translate", "rotate", "scale", "look_at"};
    DWV_TRY(dwvs_check_keys(item, path, keys, sizeof keys / sizeof keys[0]));
    char p[PATH_SIZE];
    const cJSON *matrix = dwvs_member(item, "matrix"), *look = dwvs_member(item, "look_at");
    int trs = dwvs_member(item, "translate") || dwvs_member(item, "rotate") || dwvs_member(item, "scale");
    if ((matrix != NULL) + (look != NULL) + trs > 1)
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "give one of 'matrix', 'look_at' or 'translate'/'rotate'/'scale'");
    if (matrix) {
        dwvs_path_key(p, path, "matrix");
        int n = cJSON_IsArray(matrix) ? cJSON_GetArraySize(matrix) : 0;
        if (n != 12 && n != 16)
            return dwvs_fail_at(DWV_ERROR_FORMAT, p, "expected 12 or 16 numbers (row-major), found %s%s",
                                dwvs_type_name(matrix), cJSON_IsArray(matrix) ? " of another length" : "");
        double values[16];
        DWV_TRY(dwvs_read_vector(matrix, p, (size_t)n, values));
        if (n == 16 && !(values[12] == 0.0 && values[13] == 0.0 && values[14] == 0.0 && values[15] == 1.0))
            return dwvs_fail_at(DWV_ERROR_INVALID_ARGUMENT, p, "the last row must be 0 0 0 1 (no projection)");
        memcpy(m, values, 12 * sizeof *m);
        return DWV_SUCCESS;
    }
    if (look) {
        static const char *const look_keys[] = {"eye", "target", "up"};
        dwvs_path_key(p, path, "look_at");
        DWV_TRY(dwvs_check_keys(look, p, look_keys, 3));
        double eye[3], target[3], up[3] = {0.0, 0.0, 1.0};
        if (!dwvs_member(look, "eye") || !dwvs_member(look, "target"))
            return dwvs_fail_at(DWV_ERROR_FORMAT, p, "needs 'eye' and 'target'");
        DWV_TRY(dwvs_opt_vector(look, p, "eye", 3, eye));
        DWV_TRY(dwvs_opt_vector(look, p, "target", 3, target));
        DWV_TRY(dwvs_opt_vector(look, p, "up", 3, up));
        int bad = dwvs_transform_look_at(eye, target, up, m);
        if (bad == -1) return dwvs_fail_at(DWV_ERROR_INVALID_ARGUMENT, p, "eye and target coincide");
        if (bad) return dwvs_fail_at(DWV_ERROR_INVALID_ARGUMENT, p, "up is zero or parallel to the view direction");
        return DWV_SUCCESS;
    }
    double t[3] = {0, 0, 0}, r[3] = {0, 0, 0}, s[3] = {1, 1, 1};
    DWV_TRY(dwvs_opt_vector(item, path, "translate", 3, t));
    DWV_TRY(dwvs_opt_vector(item, path, "rotate", 3, r));
    const cJSON *scale = dwvs_member(item, "scale");
    if (cJSON_IsNumber(scale)) {
        dwvs_path_key(p, path, "scale");
        DWV_TRY(dwvs_read_number(scale, p, &s[0]));
        s[1] = s[2] = s[0];
    } else {
        DWV_TRY(dwvs_opt_vector(item, path, "scale", 3, s));
    }
    dwvs_transform_trs(t, r, s, m);
    return DWV_SUCCESS;
}

dwv_result_t dwvs_opt_transform(const cJSON *object, const char *parent, double m[12])
{
    const cJSON *item = dwvs_member(object, "transform");
    if (!item) return DWV_SUCCESS;
    char p[PATH_SIZE];
    dwvs_path_key(p, parent, "transform");
    return read_transform(item, p, m);
}
