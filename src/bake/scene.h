/* The scene behind dwv_scene_t: what the dwv_scene_add_* calls stored (copied, validated, meshes
 * already in world space), and what dwv_scene_commit derived from it for bakes. */
#ifndef DWV_BAKE_SCENE_H
#define DWV_BAKE_SCENE_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "bake/material.h"
#include <dwivedi.h>
#include "geom/embree.h"
#include "geom/mesh.h"
#include "light/envmap.h"
#include "light/light.h"
#include "walk/walk.h"

/* Absurd counts are refused before anything is allocated. */
#define DWVB_MAX_MATERIALS (1u << 16)
#define DWVB_MAX_MESHES (1u << 16)
#define DWVB_MAX_LIGHTS (1u << 16)

/* Whether walks take ray-free steps inside balls clear of their mesh (run_walk in shade.c): on
 * (the default), off (a ray at every step), or checked (the ray is cast anyway and a hit on a
 * ray-free step counted: tests prove the balls never skip a hit). Only tests change it. */
typedef enum dwvb_ball_mode { DWVB_BALL_ON = 0, DWVB_BALL_OFF = 1, DWVB_BALL_CHECKED = 2 } dwvb_ball_mode;

typedef struct dwvb_scene {
    atomic_uint references;
    int committed;
    dwv_material_t *materials;
    uint32_t material_count, material_capacity;
    dwvg_mesh *meshes;
    uint32_t mesh_count, mesh_capacity;
    double *terminator_offsets; /* per mesh: dwv_mesh_t.shadow_terminator_geometry_offset */
    uint32_t terminator_capacity;
    dwv_light_desc_t *lights;
    uint32_t light_count, light_capacity;
    double world[3];     /* constant world radiance: colour x strength (0 with an envmap) */
    dwvl_envmap *envmap; /* the world's environment map, or NULL (dwv_scene_set_world_environment) */
    int have_camera;
    dwv_camera_t camera; /* validated; rotation columns orthonormal */

    /* Made by dwvb_scene_commit, read-only afterwards (bakes share them across threads). */
    dwvg_world geometry;       /* built when there is a mesh */
    dwvb_material *shading;    /* per material */
    dwvl_light *emitters;      /* per light */
    dwvw_light_patch (*patches)[DWVW_MAX_PATCHES]; /* per mesh: lit patches of subsurface meshes */
    int *patch_count;          /* per mesh */
    uint32_t features;         /* DWV_FEATURE_* the scene can use (bakes narrow it by technique) */
    uint64_t warnings;         /* degenerate or non-finite triangles */
    dwvb_ball_mode ball_mode;
} dwvb_scene;

dwvb_scene *dwvb_scene_new(void);
void dwvb_scene_free(dwvb_scene *scene);
/* Append copies; 0 on success, -1 when out of memory (nothing appended). */
int dwvb_scene_push_material(dwvb_scene *scene, const dwv_material_t *material);
int dwvb_scene_push_mesh(dwvb_scene *scene, const dwvg_mesh *mesh, double terminator_offset);
int dwvb_scene_push_light(dwvb_scene *scene, const dwv_light_desc_t *light);

/* Freezes the scene: builds the Embree world, the materials' media, the lights, the lit patches
 * of each subsurface mesh (for the incident technique) and the feature analysis. On failure
 * returns the code with a message in `message` and leaves the scene uncommitted. */
dwv_result_t dwvb_scene_commit(dwvb_scene *scene, char *message, size_t size);

/* Replaces the world by an environment map (taken over; NULL: the constant `world`). */
void dwvb_scene_set_envmap(dwvb_scene *scene, dwvl_envmap *envmap);

/* Whether the world (constant or environment map) gives light. */
int dwvb_scene_world_lit(const dwvb_scene *scene);

#endif
