/* JSON scene files (docs/scene-format.md), built into a scene through the public dwv_scene_* API
 * only: the parser knows nothing of how the scene store keeps or traces its meshes. */
#ifndef DWV_SCENEFILE_SCENE_JSON_H
#define DWV_SCENEFILE_SCENE_JSON_H

#include <stddef.h>

#include <dwivedi.h>

/* The largest scene text read (bytes); meshes of any size belong in OBJ or PLY files. */
#define DWVS_SCENE_MAX_BYTES (64u << 20)
/* The deepest nesting of arrays and objects accepted (the format itself needs 4). */
#define DWVS_SCENE_MAX_DEPTH 64u
/* The most JSON values in one text: bounds the parser's memory (about 64 bytes a value). */
#define DWVS_SCENE_MAX_VALUES (1u << 22)

/* Parses `size` bytes of UTF-8 JSON text into a new committed scene (*scene, reference count 1;
 * NULL on failure). Relative mesh paths resolve against base_dir. The file's bake settings are
 * written into *options (if not NULL) only on success. The message of a failure starts with the
 * JSON path of the offending value ("meshes[2].material: unknown material 'wax'") or with the
 * line and column of a syntax error. */
dwv_result_t dwvs_scene_from_json(const char *json, size_t size, const char *base_dir, dwv_scene_t **scene,
                                   dwv_bake_options_t *options);

#endif
