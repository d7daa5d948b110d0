/* What the files of the JSON scene reader share (scene_json.c: the text's checks and the top
 * level; scene_json_values.c: typed values and messages; scene_json_materials.c,
 * scene_json_meshes.c, scene_json_lights.c, scene_json_bake.c: the sections): the parser's
 * state, the typed readers that check each value's type and name its JSON path in a failure,
 * and one reader per section of the file. */
#ifndef DWV_SCENEFILE_SCENE_JSON_INTERNAL_H
#define DWV_SCENEFILE_SCENE_JSON_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include <cjson/cJSON.h>

#include <dwivedi.h>

#define PATH_SIZE 192  /* a JSON path in a message */
#define SHOWN_BYTES 40 /* of a user's string shown in a message, before "..." */
#define SHOWN_SIZE (SHOWN_BYTES + 8)
#define MESSAGE_SIZE 400
#define MAX_FILE_PATH 4096 /* a mesh or image file's path, resolved */

/* A material or mesh of the file by name, with the id the scene gave it. */
typedef struct dwvs_named {
    const char *name;
    uint32_t id;
    uint32_t has_uvs;
} dwvs_named;

typedef struct dwvs_parser {
    dwv_scene_t *scene;
    const char *base_dir;
    dwvs_named *materials; /* sorted by name once read */
    size_t material_count;
    dwvs_named *textures; /* sorted by name once read */
    size_t texture_count;
    dwvs_named *meshes; /* in file order; names may be NULL */
    size_t mesh_count;
    int has_camera;
    dwv_bake_options_t options;
} dwvs_parser;

/* Orders dwvs_named by name (qsort, bsearch). */
int dwvs_compare_named(const void *a, const void *b);

/* ---- messages ---- */

/* A user's string as a message shows it: at most SHOWN_BYTES bytes, cut at a character boundary
 * (the text is valid UTF-8 by then), control characters as '?', "..." if cut. */
const char *dwvs_shown(const char *s, char out[SHOWN_SIZE]);
/* The JSON path of member `key` of `parent` ("" at the top level), or of element `index`. */
void dwvs_path_key(char out[PATH_SIZE], const char *parent, const char *key);
void dwvs_path_index(char out[PATH_SIZE], const char *parent, size_t index);
/* Fails with `code` and a message that starts with the JSON path ("(top level)" for ""). */
#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
dwv_result_t dwvs_fail_at(dwv_result_t code, const char *path, const char *format, ...);
/* A capi call failed: keep its code and message, prefixed with the JSON path it came from. */
dwv_result_t dwvs_prefix_capi(dwv_result_t code, const char *path);
/* "a number", "an object"...: what a message says it found. */
const char *dwvs_type_name(const cJSON *item);

/* ---- typed readers: each checks the value's type and writes *out only on success ---- */

/* The object's keys must come from `keys`, each at most once. */
dwv_result_t dwvs_check_keys(const cJSON *object, const char *path, const char *const *keys, size_t count);
/* The object's member `key` (case-sensitive), or NULL. */
const cJSON *dwvs_member(const cJSON *object, const char *key);
dwv_result_t dwvs_read_number(const cJSON *item, const char *path, double *out);
/* A whole number in [lo, hi] (hi at most 2^53, where doubles still count by ones). */
dwv_result_t dwvs_read_integer(const cJSON *item, const char *path, double lo, double hi, uint64_t *out);
dwv_result_t dwvs_read_u32(const cJSON *item, const char *path, uint32_t lo, uint32_t hi, uint32_t *out);
/* An array of exactly n numbers. */
dwv_result_t dwvs_read_vector(const cJSON *item, const char *path, size_t n, double *out);
/* A non-empty array of numbers whose length is a multiple of `group`, as floats (each must fit
 * one): *out is malloc'ed (the caller frees it), *count the numbers. */
dwv_result_t dwvs_read_floats(const cJSON *item, const char *path, size_t group, size_t *count, float **out);
/* A non-empty string (*out points into the parsed text). */
dwv_result_t dwvs_read_string(const cJSON *item, const char *path, const char **out);
/* One of `names` (in order of the values they stand for). */
dwv_result_t dwvs_read_choice(const cJSON *item, const char *path, const char *const *names, size_t count,
                              size_t *out);
/* Optional members: each reader leaves *out alone when the key is absent. */
dwv_result_t dwvs_opt_number(const cJSON *object, const char *parent, const char *key, double *out);
dwv_result_t dwvs_opt_vector(const cJSON *object, const char *parent, const char *key, size_t n, double *out);
dwv_result_t dwvs_opt_u32(const cJSON *object, const char *parent, const char *key, uint32_t lo, uint32_t hi,
                          uint32_t *out);
dwv_result_t dwvs_opt_choice(const cJSON *object, const char *parent, const char *key, const char *const *names,
                             size_t count, size_t *out);
/* The object's "transform" (a matrix, a look_at, or translate/rotate/scale) into the 3 x 4
 * row-major m; m is left alone when the key is absent. */
dwv_result_t dwvs_opt_transform(const cJSON *object, const char *parent, double m[12]);

/* `file` resolved against base_dir (absolute paths kept); `path` is the JSON path for a message. */
dwv_result_t dwvs_resolve_path(const char *base_dir, const char *file, const char *path, char out[MAX_FILE_PATH]);

/* ---- the sections of a scene file, in the order read_scene reads them ---- */

/* A texture or environment file that a scene file names ("file" at `path` in the JSON, resolved to
 * `resolved`): reads it whole; with `sha256` (the "sha256" key's 64 hexadecimal digits, or
 * NULL) refuses it unless its bytes hash to that (DWV_ERROR_FORMAT: a different file than the one
 * the scene was written with); *is_exr says whether it starts with OpenEXR's magic number. A
 * missing file: DWV_ERROR_IO. */
dwv_result_t dwvs_check_image_file(const char *path, const char *resolved, const char *sha256, int *is_exr);
/* "file" (+ "sha256") of `item` at `path`: resolved, checked as above. */
dwv_result_t dwvs_read_image_file(dwvs_parser *ps, const cJSON *item, const char *path, char resolved[MAX_FILE_PATH],
                                  int *is_exr);

dwv_result_t dwvs_read_textures(dwvs_parser *ps, const cJSON *item);
/* A material's "textures" array: its bindings (after dwvs_read_textures). */
dwv_result_t dwvs_read_material_textures(dwvs_parser *ps, const cJSON *item, const char *path, uint32_t material_id);
dwv_result_t dwvs_read_materials(dwvs_parser *ps, const cJSON *item);
dwv_result_t dwvs_read_meshes(dwvs_parser *ps, const cJSON *item);
dwv_result_t dwvs_read_lights(dwvs_parser *ps, const cJSON *item);
dwv_result_t dwvs_read_world(dwvs_parser *ps, const cJSON *item);
dwv_result_t dwvs_read_camera(dwvs_parser *ps, const cJSON *item);
/* The bake settings into ps->options; after the meshes (a UV bake names one) and the camera. */
dwv_result_t dwvs_read_bake(dwvs_parser *ps, const cJSON *item);

#endif
