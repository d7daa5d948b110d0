/* The scene behind dwv_scene_t: what the dwv_scene_add_* calls stored (copied, validated, meshes
 * already in world space), and what dwv_scene_commit derived from it for bakes. */
#ifndef DWV_BAKE_SCENE_H
#define DWV_BAKE_SCENE_H

#include <stdatomic.h>
#include <stdint.h>

#include "dwivedi.h"
#include "geom/mesh.h"

/* Absurd counts are refused before anything is allocated. */
#define DWVB_MAX_MATERIALS (1u << 16)
#define DWVB_MAX_MESHES (1u << 16)
#define DWVB_MAX_LIGHTS (1u << 16)

typedef struct dwvb_scene {
    atomic_uint references;
    int committed;
    dwv_material_t *materials;
    uint32_t material_count, material_capacity;
    dwvg_mesh *meshes;
    uint32_t mesh_count, mesh_capacity;
    dwv_light_desc_t *lights;
    uint32_t light_count, light_capacity;
    double world[3];     /* constant world radiance: colour x strength */
    int have_camera;
    dwv_camera_t camera; /* validated; rotation columns orthonormal */
} dwvb_scene;

dwvb_scene *dwvb_scene_new(void);
void dwvb_scene_free(dwvb_scene *scene);
/* Append copies; 0 on success, -1 when out of memory (nothing appended). */
int dwvb_scene_push_material(dwvb_scene *scene, const dwv_material_t *material);
int dwvb_scene_push_mesh(dwvb_scene *scene, const dwvg_mesh *mesh);
int dwvb_scene_push_light(dwvb_scene *scene, const dwv_light_desc_t *light);

#endif
