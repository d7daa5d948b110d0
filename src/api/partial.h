/* Split bakes: the hashes that tie a chunk to its scene and options (partial_api.c). */
#ifndef DWV_API_PARTIAL_H
#define DWV_API_PARTIAL_H

#include <stdint.h>

#include "bake/scene.h"
#include <dwivedi.h>

/* FNV-1a 64 of what a committed scene bakes from: materials, meshes (positions, indices, normals,
 * UVs, material ids, terminator offsets), lights, world, camera; field by field, no padding. */
uint64_t dwv_scene_hash(const dwvb_scene *scene);
/* The same of the options that change the pixels (not threads, tile size, the range or budgets). */
uint64_t dwv_options_hash(const dwv_bake_options_t *options);

#endif
