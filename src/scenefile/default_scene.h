/* The built-in default scene (dwv_scene_create_default): made procedurally through the public
 * dwv_scene_* API, no files. */
#ifndef DWV_SCENEFILE_DEFAULT_SCENE_H
#define DWV_SCENEFILE_DEFAULT_SCENE_H

#include <dwivedi.h>
#include "scenefile/mesh_file.h"

/* The shapes, in metres (their object space; the scene places them with a transform). */
#define DWVS_LEAF_HALF_WIDTH 0.038   /* the leaf's outline: an ellipse of these half-axes */
#define DWVS_LEAF_HALF_HEIGHT 0.055
#define DWVS_LEAF_THICKNESS 0.003    /* at its middle, tapering to a rounded rim */
#define DWVS_LEAF_BEND_RADIUS 0.07   /* cupped about its vertical axis, toward the viewer */
#define DWVS_BLOCK_HALF_SIZE_X 0.036 /* the wax block: a rounded box |x/a|^4+|y/b|^4+|z/c|^4 = 1 */
#define DWVS_BLOCK_HALF_SIZE_Y 0.030
#define DWVS_BLOCK_HALF_SIZE_Z 0.034

/* The meshes of the default scene, for tests: closed, outward-wound, with smooth normals and
 * per-corner UVs in non-overlapping islands. 0 on success, -1 out of memory. */
int dwvs_default_leaf(dwvs_mesh_data *mesh);
int dwvs_default_block(dwvs_mesh_data *mesh);

/* Builds and commits the default scene; fills *options (if not NULL) with its width, height and
 * samples. */
dwv_result_t dwvs_default_scene(dwv_scene_t **scene, dwv_bake_options_t *options);

/* Its mesh, material and light counts (the test checks them against the scene). */
#define DWVS_DEFAULT_MESHES 3u
#define DWVS_DEFAULT_MATERIALS 3u
#define DWVS_DEFAULT_LIGHTS 2u

#endif
