/* The scene behind dwv_scene_t: what the dwv_scene_add_* calls stored (copied, validated, meshes
 * already in world space), and what dwv_scene_commit derived from it for bakes. */
#ifndef DWV_BAKE_SCENE_H
#define DWV_BAKE_SCENE_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "bake/material.h"
#include "bake/texture.h"
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

/* A texture bound to a material input (dwv_texture_binding_t, validated, its name copied). */
typedef struct dwvb_binding {
    uint32_t material_id;
    dwv_material_input_t input;
    uint32_t texture_id;
    int invert;
    char *uv_layer;           /* NULL: layer 0 */
    double blend, strength, distance;
    int bump_shadowing;       /* DWV_BUMP_SHADOWING_* */
} dwvb_binding;

/* A mesh's UV layers beyond the first (dwv_mesh_t.uv_layers), their names and tangents, in the
 * stored corner order (mirroring transforms swap corners 1 and 2, as dwvg_mesh's uvs). */
typedef struct dwvb_mesh_layers {
    uint32_t count;           /* all layers, the first (dwvg_mesh.uvs) included */
    float **uvs;              /* count arrays; [0] unused (the mesh's own uvs) */
    char **names;             /* count names */
    float **tangents;         /* count arrays or NULL: 4 x 3 x triangle_count, world space, unit,
                                 the sign already holding the transform's orientation */
} dwvb_mesh_layers;

/* What a committed scene knows of one material's bindings. */
typedef struct dwvb_material_textures {
    uint32_t first, count;    /* its bindings: scene->binding_order[first .. first + count - 1] */
    int32_t normal_map, bump; /* binding index (in the scene), or -1 */
    int inputs;               /* 1 where a binding drives an input other than the normal */
    int bump_shadowing;       /* the normal map's or bump's DWV_BUMP_SHADOWING_* (either's, if on) */
} dwvb_material_textures;

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
    dwvb_texture *textures;
    uint32_t texture_count, texture_capacity;
    dwvb_binding *bindings;
    uint32_t binding_count, binding_capacity;
    dwvb_mesh_layers *layers;  /* per mesh */
    uint32_t layer_capacity;

    /* Made by dwvb_scene_commit, read-only afterwards (bakes share them across threads). */
    dwvg_world geometry;       /* built when there is a mesh */
    dwvb_material *shading;    /* per material */
    dwvb_spec_grid **spec_grids; /* per material: v2 specular tables over textured Roughness /
                                  Specular IOR Level values (shading[i].spec_grid), else NULL */
    dwvl_light *emitters;      /* per light */
    dwvw_light_patch (*patches)[DWVW_MAX_PATCHES]; /* per mesh: lit patches of subsurface meshes */
    int *patch_count;          /* per mesh */
    uint32_t features;         /* DWV_FEATURE_* the scene can use (bakes narrow it by technique) */
    uint64_t warnings;         /* degenerate or non-finite triangles */
    dwvb_material_textures *material_textures; /* per material */
    uint32_t *binding_order;   /* binding indices grouped by material, in the order they were made */
    uint32_t **binding_layers; /* per mesh of a textured material: the UV layer of each of its
                                  material's bindings (in binding_order), else NULL */
    dwvb_ball_mode ball_mode;
} dwvb_scene;

dwvb_scene *dwvb_scene_new(void);
void dwvb_scene_free(dwvb_scene *scene);
/* Append copies; 0 on success, -1 when out of memory (nothing appended). */
int dwvb_scene_push_material(dwvb_scene *scene, const dwv_material_t *material);
/* The mesh takes `layers` (moved in: the scene frees them; NULL: none, for meshes that no
 * texture reads). */
int dwvb_scene_push_mesh(dwvb_scene *scene, const dwvg_mesh *mesh, double terminator_offset,
                         const dwvb_mesh_layers *layers);
int dwvb_scene_push_light(dwvb_scene *scene, const dwv_light_desc_t *light);
int dwvb_scene_push_texture(dwvb_scene *scene, const dwvb_texture *texture);
int dwvb_scene_push_binding(dwvb_scene *scene, const dwvb_binding *binding);
void dwvb_mesh_layers_free(dwvb_mesh_layers *layers);

/* Freezes the scene: builds the Embree world, the materials' media, the lights, the lit patches
 * of each subsurface mesh (for the incident technique) and the feature analysis. On failure
 * returns the code with a message in `message` and leaves the scene uncommitted. */
dwv_result_t dwvb_scene_commit(dwvb_scene *scene, char *message, size_t size);

/* Replaces the world by an environment map (taken over; NULL: the constant `world`). */
void dwvb_scene_set_envmap(dwvb_scene *scene, dwvl_envmap *envmap);

/* Whether the world (constant or environment map) gives light. */
int dwvb_scene_world_lit(const dwvb_scene *scene);

#endif
