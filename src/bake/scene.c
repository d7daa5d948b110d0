#include "scene.h"

#include <stdlib.h>
#include <string.h>

dwvb_scene *dwvb_scene_new(void)
{
    dwvb_scene *scene = calloc(1, sizeof *scene);
    if (!scene) return NULL;
    atomic_init(&scene->references, 1u);
    return scene;
}

void dwvb_scene_free(dwvb_scene *scene)
{
    if (!scene) return;
    for (uint32_t i = 0; i < scene->mesh_count; ++i) dwvg_mesh_free(&scene->meshes[i]);
    free(scene->meshes);
    free(scene->materials);
    free(scene->lights);
    free(scene);
}

/* The array `items` of `size`-byte elements with room for one more (moved if it had to grow), or
 * NULL when out of memory (then `items` is untouched). */
static void *grow(void *items, uint32_t count, uint32_t *capacity, size_t size)
{
    if (count < *capacity) return items;
    uint32_t wanted = *capacity ? 2u * *capacity : 8u;
    void *grown = realloc(items, (size_t)wanted * size);
    if (grown) *capacity = wanted;
    return grown;
}

int dwvb_scene_push_material(dwvb_scene *scene, const dwv_material_t *material)
{
    void *grown = grow(scene->materials, scene->material_count, &scene->material_capacity, sizeof *material);
    if (!grown) return -1;
    scene->materials = grown;
    scene->materials[scene->material_count++] = *material;
    return 0;
}

int dwvb_scene_push_mesh(dwvb_scene *scene, const dwvg_mesh *mesh)
{
    void *grown = grow(scene->meshes, scene->mesh_count, &scene->mesh_capacity, sizeof *mesh);
    if (!grown) return -1;
    scene->meshes = grown;
    scene->meshes[scene->mesh_count++] = *mesh;
    return 0;
}

int dwvb_scene_push_light(dwvb_scene *scene, const dwv_light_desc_t *light)
{
    void *grown = grow(scene->lights, scene->light_count, &scene->light_capacity, sizeof *light);
    if (!grown) return -1;
    scene->lights = grown;
    scene->lights[scene->light_count++] = *light;
    return 0;
}
