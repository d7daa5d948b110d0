/* capi entry points of scene files and the default scene. They are clients of the public
 * dwv_scene_* calls (src/scenefile builds scenes only through them), plus the checks of their own
 * arguments and the reading of the file. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <dwivedi.h>
#include "util/error.h"
#include "scenefile/default_scene.h"
#include "scenefile/scene_json.h"

#define MESSAGE_SIZE 400

/* Re-fails with the last message prefixed by `what` (e.g. the scene file's path). */
static dwv_result_t prefixed(dwv_result_t code, const char *what)
{
    char message[MESSAGE_SIZE];
    snprintf(message, sizeof message, "%s", dwv_last_error_message());
    return dwv_fail(code, "%s: %s", what, message);
}

/* The caller's options as a whole struct in *full (NULL where the caller passed none): a struct
 * of an older header (ending at sample_first or later, as dwv_bake_start takes) gets 0 in the
 * fields it has not, and gets back only its own bytes (options_done). */
static dwv_result_t check_options(const char *fn, dwv_bake_options_t *options, dwv_bake_options_t *full,
                                  dwv_bake_options_t **use)
{
    *use = NULL;
    if (!options) return DWV_SUCCESS;
    DWV_TRY(dwv_check_struct(fn, "options", options, (uint32_t)offsetof(dwv_bake_options_t, sample_first)));
    memset(full, 0, sizeof *full);
    memcpy(full, options, options->struct_size < sizeof *full ? options->struct_size : sizeof *full);
    *use = full;
    return DWV_SUCCESS;
}

static dwv_result_t options_done(dwv_result_t r, dwv_bake_options_t *options, const dwv_bake_options_t *full)
{
    if (r != DWV_SUCCESS || !options) return r;
    uint32_t size = options->struct_size;
    memcpy(options, full, size < sizeof *full ? size : sizeof *full);
    options->struct_size = size;
    return r;
}

dwv_result_t dwv_scene_load_json(const char *json, uint64_t size, const char *base_dir, dwv_scene_t **scene,
                                 dwv_bake_options_t *options)
{
    static const char fn[] = "dwv_scene_load_json";
    DWV_TRY(dwv_check_pointer(fn, "scene", scene));
    *scene = NULL;
    DWV_TRY(dwv_check_pointer(fn, "json", json));
    dwv_bake_options_t full, *use;
    DWV_TRY(check_options(fn, options, &full, &use));
    if (size > DWVS_SCENE_MAX_BYTES)
        return dwv_fail(DWV_ERROR_FORMAT, "%s: the scene text is %llu bytes, more than %u", fn,
                        (unsigned long long)size, DWVS_SCENE_MAX_BYTES);
    return options_done(dwvs_scene_from_json(json, (size_t)size, base_dir ? base_dir : ".", scene, use), options, &full);
}

/* The folder of `path` ("." if it names none), for relative mesh paths. */
static char *folder_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash) return strdup(".");
    size_t n = slash == path ? 1u : (size_t)(slash - path);
    char *folder = malloc(n + 1u);
    if (!folder) return NULL;
    memcpy(folder, path, n);
    folder[n] = '\0';
    return folder;
}

/* Reads at most DWVS_SCENE_MAX_BYTES + 1 bytes (so a larger file, or a pipe that never ends,
 * is refused without reading it all). */
static dwv_result_t read_text(const char *path, char **text, size_t *size)
{
    *text = NULL;
    *size = 0;
    struct stat st;
    if (stat(path, &st) != 0) return dwv_fail(DWV_ERROR_IO, "cannot open it: %s", strerror(errno));
    if (S_ISDIR(st.st_mode)) return dwv_fail(DWV_ERROR_IO, "it is a folder, not a file");
    FILE *file = fopen(path, "rb");
    if (!file) return dwv_fail(DWV_ERROR_IO, "cannot open it: %s", strerror(errno));
    size_t capacity = 1u << 16, n = 0;
    char *buffer = malloc(capacity);
    dwv_result_t result = DWV_SUCCESS;
    while (buffer) {
        if (n == capacity) {
            size_t grown = capacity * 2u;
            char *bigger = realloc(buffer, grown);
            if (!bigger) {
                free(buffer);
                buffer = NULL;
                break;
            }
            buffer = bigger;
            capacity = grown;
        }
        size_t got = fread(buffer + n, 1, capacity - n, file);
        n += got;
        if (n > DWVS_SCENE_MAX_BYTES) {
            result = dwv_fail(DWV_ERROR_FORMAT, "the file is larger than %u bytes", DWVS_SCENE_MAX_BYTES);
            break;
        }
        if (got == 0) {
            if (ferror(file)) result = dwv_fail(DWV_ERROR_IO, "cannot read it: %s", strerror(errno));
            break;
        }
    }
    fclose(file);
    if (!buffer) return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "no memory to read it");
    if (result != DWV_SUCCESS) {
        free(buffer);
        return result;
    }
    *text = buffer;
    *size = n;
    return DWV_SUCCESS;
}

dwv_result_t dwv_scene_load(const char *path, dwv_scene_t **scene, dwv_bake_options_t *options)
{
    static const char fn[] = "dwv_scene_load";
    DWV_TRY(dwv_check_pointer(fn, "scene", scene));
    *scene = NULL;
    DWV_TRY(dwv_check_pointer(fn, "path", path));
    dwv_bake_options_t full, *use;
    DWV_TRY(check_options(fn, options, &full, &use));
    if (!path[0]) return dwv_fail(DWV_ERROR_IO, "%s: the path is empty", fn);
    char *text;
    size_t size;
    dwv_result_t r = read_text(path, &text, &size);
    if (r != DWV_SUCCESS) return prefixed(r, path);
    char *folder = folder_of(path);
    if (!folder) {
        free(text);
        return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: out of memory", fn);
    }
    r = dwvs_scene_from_json(text, size, folder, scene, use);
    free(folder);
    free(text);
    return r == DWV_SUCCESS ? options_done(r, options, &full) : prefixed(r, path);
}

dwv_result_t dwv_scene_create_default(dwv_scene_t **scene, dwv_bake_options_t *options)
{
    static const char fn[] = "dwv_scene_create_default";
    DWV_TRY(dwv_check_pointer(fn, "scene", scene));
    *scene = NULL;
    dwv_bake_options_t full, *use;
    DWV_TRY(check_options(fn, options, &full, &use));
    dwv_result_t r = dwvs_default_scene(scene, use);
    return r == DWV_SUCCESS ? options_done(r, options, &full) : prefixed(r, fn);
}
