#include "scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "kernel/rng.h"
#include "bake/textured.h"
#include "light/direct.h"

static dwv_result_t uncommit(dwvb_scene *scene, dwv_result_t result);
static dwv_result_t commit_bindings(dwvb_scene *scene, char *message, size_t size);

/* The clearance grids of a scene stop once they hold this many cells (64 MiB): a scene of many
 * large subsurface meshes keeps rays at every step in the later ones (in mesh order, so the same
 * scene always gets the same grids). */
#define CLEARANCE_SCENE_CELLS (1u << 24)

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
    uncommit(scene, DWV_SUCCESS);
    for (uint32_t i = 0; i < scene->mesh_count; ++i) {
        dwvg_mesh_free(&scene->meshes[i]);
        dwvb_mesh_layers_free(&scene->layers[i]);
    }
    free(scene->meshes);
    free(scene->layers);
    for (uint32_t i = 0; i < scene->texture_count; ++i) dwvb_texture_free(&scene->textures[i]);
    free(scene->textures);
    for (uint32_t i = 0; i < scene->binding_count; ++i) free(scene->bindings[i].uv_layer);
    free(scene->bindings);
    free(scene->terminator_offsets);
    free(scene->materials);
    free(scene->lights);
    dwvb_scene_set_envmap(scene, NULL);
    free(scene);
}

void dwvb_scene_set_envmap(dwvb_scene *scene, dwvl_envmap *envmap)
{
    if (scene->envmap) {
        dwvl_envmap_free(scene->envmap);
        free(scene->envmap);
    }
    scene->envmap = envmap;
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

int dwvb_scene_push_mesh(dwvb_scene *scene, const dwvg_mesh *mesh, double terminator_offset,
                         const dwvb_mesh_layers *layers)
{
    void *offsets = grow(scene->terminator_offsets, scene->mesh_count, &scene->terminator_capacity,
                         sizeof *scene->terminator_offsets);
    if (!offsets) return -1;
    scene->terminator_offsets = offsets;
    void *tables = grow(scene->layers, scene->mesh_count, &scene->layer_capacity, sizeof *scene->layers);
    if (!tables) return -1;
    scene->layers = tables;
    dwvb_mesh_layers none = {0u, NULL, NULL, NULL};
    scene->layers[scene->mesh_count] = layers ? *layers : none;
    void *grown = grow(scene->meshes, scene->mesh_count, &scene->mesh_capacity, sizeof *mesh);
    if (!grown) return -1;
    scene->meshes = grown;
    scene->terminator_offsets[scene->mesh_count] = terminator_offset;
    scene->meshes[scene->mesh_count++] = *mesh;
    return 0;
}

void dwvb_mesh_layers_free(dwvb_mesh_layers *layers)
{
    for (uint32_t k = 0; k < layers->count; ++k) {
        if (layers->uvs) free(layers->uvs[k]);
        if (layers->names) free(layers->names[k]);
        if (layers->tangents) free(layers->tangents[k]);
    }
    free(layers->uvs);
    free(layers->names);
    free(layers->tangents);
    layers->uvs = NULL;
    layers->names = NULL;
    layers->tangents = NULL;
    layers->count = 0;
}

int dwvb_scene_push_texture(dwvb_scene *scene, const dwvb_texture *texture)
{
    void *grown = grow(scene->textures, scene->texture_count, &scene->texture_capacity, sizeof *texture);
    if (!grown) return -1;
    scene->textures = grown;
    scene->textures[scene->texture_count++] = *texture;
    return 0;
}

int dwvb_scene_push_binding(dwvb_scene *scene, const dwvb_binding *binding)
{
    void *grown = grow(scene->bindings, scene->binding_count, &scene->binding_capacity, sizeof *binding);
    if (!grown) return -1;
    scene->bindings = grown;
    scene->bindings[scene->binding_count++] = *binding;
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

int dwvb_scene_world_lit(const dwvb_scene *scene)
{
    return scene->envmap || scene->world[0] > 0.0 || scene->world[1] > 0.0 || scene->world[2] > 0.0;
}

/* Surface points per subsurface mesh whose irradiance makes its lit patches. */
#define PATCH_POINTS 1024u
#define PATCH_SEED 0x6c69745f70617463ull

static double luminance(const double rgb[3])
{
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
}

/* The lit patches of a mesh for the incident technique (Meng et al. 2016, Sec. 4.3): PATCH_POINTS
 * area-uniform surface points, each with its irradiance from the lights and the world (shadow
 * rays included), grouped by the dominant axis of their normal into at most six patches: power =
 * sum of irradiance x area per point, point and normal = their irradiance-weighted means. Returns
 * the count, or -1 out of memory. */
static int make_patches(const dwvb_scene *scene, const dwvl_environment *env, uint32_t mesh_id,
                        dwvw_light_patch *patches)
{
    const dwvg_mesh *mesh = &scene->meshes[mesh_id];
    double *cdf = malloc((size_t)mesh->triangle_count * sizeof *cdf);
    if (!cdf) return -1;
    double total = 0.0;
    for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
        total += dwvg_triangle_area(mesh, t);
        cdf[t] = total;
    }
    double power[6] = {0}, weight_sum[6] = {0};
    dwvu_vec3 point[6], normal[6];
    for (int b = 0; b < 6; ++b) point[b] = normal[b] = dwvu_v(0.0, 0.0, 0.0);
    if (total > 0.0 && isfinite(total)) {
        double area_per_point = total / PATCH_POINTS;
        for (uint32_t i = 0; i < PATCH_POINTS; ++i) {
            uint64_t key = dwvk_rng_key(PATCH_SEED, mesh_id, i);
            double target = dwvk_rng_uniform_d(key, 0) * total;
            uint32_t lo = 0, hi = mesh->triangle_count - 1u;
            while (lo < hi) {
                uint32_t mid = lo + (hi - lo) / 2u;
                if (cdf[mid] > target) hi = mid;
                else lo = mid + 1u;
            }
            double su = sqrt(dwvk_rng_uniform_d(key, 1)), v = dwvk_rng_uniform_d(key, 2);
            double b1 = su * (1.0 - v), b2 = su * v; /* uniform on the triangle */
            dwvu_vec3 ng = dwvg_geometric_normal(mesh, lo);
            if (ng.x == 0.0 && ng.y == 0.0 && ng.z == 0.0) continue;
            dwvu_vec3 x = dwvg_point(mesh, lo, b1, b2);
            double radiance[3];
            /* Independent draws; pairs from 2 on (dimensions 4, 5, ...) leave 0 to 2 to the point. */
            dwvk_sampler sampler = {.key = key, .index = 0u, .stratified = 0};
            dwvl_direct(env, x, ng, ng, NULL, INFINITY, &sampler, 2u, radiance);
            /* The Lambertian estimate is irradiance / pi. */
            double e = 3.14159265358979323846 * luminance(radiance);
            if (!(e > 0.0)) continue;
            double ax = fabs(ng.x), ay = fabs(ng.y), az = fabs(ng.z);
            int bin = ax >= ay && ax >= az ? (ng.x > 0.0 ? 0 : 1) : ay >= az ? (ng.y > 0.0 ? 2 : 3) : (ng.z > 0.0 ? 4 : 5);
            power[bin] += e * area_per_point;
            weight_sum[bin] += e;
            point[bin] = dwvu_madd(point[bin], x, e);
            normal[bin] = dwvu_madd(normal[bin], ng, e);
        }
    }
    free(cdf);
    double largest = 0.0;
    for (int b = 0; b < 6; ++b) largest = fmax(largest, power[b]);
    int count = 0;
    for (int b = 0; b < 6; ++b) {
        double length = dwvu_length(normal[b]);
        if (!(power[b] > 1e-6 * largest) || !(length > 0.0)) continue;
        dwvw_light_patch p = {.point = dwvu_scale(point[b], 1.0 / weight_sum[b]),
                              .normal = dwvu_scale(normal[b], 1.0 / length), .power = power[b], .is_plane = 0};
        patches[count++] = p;
    }
    return count;
}

static const char *input_name(dwv_material_input_t input)
{
    static const char *const names[] = {"base_color", "subsurface_color", "subsurface_weight", "subsurface_radius",
                                        "subsurface_scale", "subsurface_anisotropy", "roughness", "specular",
                                        "specular_tint", "normal_map", "bump"};
    return input >= 0 && input <= DWV_INPUT_BUMP ? names[input] : "?";
}

/* The index of the UV layer called `name` (NULL: 0) on mesh m, or -1. */
static int32_t find_layer(const dwvb_scene *scene, uint32_t m, const char *name)
{
    if (!name) return 0;
    const dwvb_mesh_layers *layers = &scene->layers[m];
    for (uint32_t k = 0; k < layers->count; ++k)
        if (strcmp(layers->names[k], name) == 0) return (int32_t)k;
    return -1;
}

/* The commit's view of the bindings: per material its run of bindings, its normal map and bump;
 * per mesh of a textured material the UV layer of each (which must be there, with UVs), and the
 * tangents of the layers normal maps use (made from the UVs where the caller gave none). */
static dwv_result_t commit_bindings(dwvb_scene *scene, char *message, size_t size)
{
    uint32_t nm = scene->material_count, nb = scene->binding_count, nmesh = scene->mesh_count;
    scene->material_textures = calloc(nm ? nm : 1u, sizeof *scene->material_textures);
    scene->binding_order = malloc((nb ? nb : 1u) * sizeof *scene->binding_order);
    scene->binding_layers = calloc(nmesh ? nmesh : 1u, sizeof *scene->binding_layers);
    if (!scene->material_textures || !scene->binding_order || !scene->binding_layers) {
        snprintf(message, size, "out of memory");
        return DWV_ERROR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < nm; ++i) scene->material_textures[i].normal_map = scene->material_textures[i].bump = -1;
    for (uint32_t b = 0; b < nb; ++b) ++scene->material_textures[scene->bindings[b].material_id].count;
    uint32_t first = 0;
    for (uint32_t i = 0; i < nm; ++i) {
        scene->material_textures[i].first = first;
        first += scene->material_textures[i].count;
        scene->material_textures[i].count = 0;
    }
    for (uint32_t b = 0; b < nb; ++b) {
        const dwvb_binding *binding = &scene->bindings[b];
        dwvb_material_textures *t = &scene->material_textures[binding->material_id];
        scene->binding_order[t->first + t->count++] = b;
        if (binding->input == DWV_INPUT_NORMAL_MAP) t->normal_map = (int32_t)b;
        else if (binding->input == DWV_INPUT_BUMP) t->bump = (int32_t)b;
        else t->inputs = 1;
        if (binding->input == DWV_INPUT_NORMAL_MAP || binding->input == DWV_INPUT_BUMP)
            if (binding->bump_shadowing) t->bump_shadowing = binding->bump_shadowing;
    }
    for (uint32_t m = 0; m < nmesh; ++m) {
        const dwvg_mesh *mesh = &scene->meshes[m];
        const dwvb_material_textures *t = &scene->material_textures[mesh->material_id];
        if (!t->count) continue;
        scene->binding_layers[m] = malloc(t->count * sizeof **scene->binding_layers);
        if (!scene->binding_layers[m]) {
            snprintf(message, size, "out of memory");
            return DWV_ERROR_OUT_OF_MEMORY;
        }
        if (!scene->layers[m].count) {
            snprintf(message, size, "mesh %u has no UV layer table (it was not added by dwv_scene_add_mesh)", m);
            return DWV_ERROR_INTERNAL;
        }
        for (uint32_t k = 0; k < t->count; ++k) {
            const dwvb_binding *binding = &scene->bindings[scene->binding_order[t->first + k]];
            int32_t layer = find_layer(scene, m, binding->uv_layer);
            if (layer < 0) {
                snprintf(message, size, "mesh %u has no UV layer \"%s\", which the %s texture of its material %u names",
                         m, binding->uv_layer, input_name(binding->input), mesh->material_id);
                return DWV_ERROR_INVALID_ARGUMENT;
            }
            if (layer == 0 && !mesh->uvs) {
                snprintf(message, size, "mesh %u has no UVs, which the %s texture of its material %u needs", m,
                         input_name(binding->input), mesh->material_id);
                return DWV_ERROR_INVALID_ARGUMENT;
            }
            scene->binding_layers[m][k] = (uint32_t)layer;
            if (binding->input != DWV_INPUT_NORMAL_MAP || scene->layers[m].tangents[layer]) continue;
            const float *uvs = layer == 0 ? mesh->uvs : scene->layers[m].uvs[layer];
            scene->layers[m].tangents[layer] = dwvb_make_tangents(mesh, uvs);
            if (!scene->layers[m].tangents[layer]) {
                snprintf(message, size, "out of memory while making the tangents of mesh %u", m);
                return DWV_ERROR_OUT_OF_MEMORY;
            }
        }
    }
    return DWV_SUCCESS;
}

/* Drops what a failed commit made, so that the scene is as before and may be committed again. */
static dwv_result_t uncommit(dwvb_scene *scene, dwv_result_t result)
{
    if (scene->geometry.device) dwvg_world_free(&scene->geometry);
    if (scene->spec_grids)
        for (uint32_t m = 0; m < scene->material_count; ++m) dwvb_spec_grid_free(scene->spec_grids[m]);
    free(scene->spec_grids);
    scene->spec_grids = NULL;
    free(scene->shading);
    free(scene->emitters);
    free(scene->patches);
    free(scene->patch_count);
    free(scene->material_textures);
    free(scene->binding_order);
    if (scene->binding_layers)
        for (uint32_t m = 0; m < scene->mesh_count; ++m) free(scene->binding_layers[m]);
    free(scene->binding_layers);
    scene->material_textures = NULL;
    scene->binding_order = NULL;
    scene->binding_layers = NULL;
    scene->shading = NULL;
    scene->emitters = NULL;
    scene->patches = NULL;
    scene->patch_count = NULL;
    return result;
}

dwv_result_t dwvb_scene_commit(dwvb_scene *scene, char *message, size_t size)
{
    uint32_t nm = scene->material_count, nl = scene->light_count, nmesh = scene->mesh_count;
    scene->shading = calloc(nm ? nm : 1u, sizeof *scene->shading);
    scene->spec_grids = calloc(nm ? nm : 1u, sizeof *scene->spec_grids);
    scene->emitters = calloc(nl ? nl : 1u, sizeof *scene->emitters);
    scene->patches = calloc(nmesh ? nmesh : 1u, sizeof *scene->patches);
    scene->patch_count = calloc(nmesh ? nmesh : 1u, sizeof *scene->patch_count);
    if (!scene->shading || !scene->spec_grids || !scene->emitters || !scene->patches || !scene->patch_count) {
        snprintf(message, size, "out of memory");
        return uncommit(scene, DWV_ERROR_OUT_OF_MEMORY);
    }
    dwv_result_t bound = commit_bindings(scene, message, size);
    if (bound != DWV_SUCCESS) return uncommit(scene, bound);
    for (uint32_t i = 0; i < nm; ++i) {
        /* A textured material is planned for with its inputs' largest texture values. */
        dwv_material_t planned = scene->materials[i];
        if (scene->material_textures[i].count) dwvb_textured_representative(scene, i, &planned);
        dwvb_material_init(&scene->shading[i], &planned);
        /* v2's albedo tables depend on Roughness and Specular IOR Level: over a texture's values
         * they come from a grid (material.h). */
        int rough = 0, level = 0;
        for (uint32_t k = 0; k < scene->material_textures[i].count; ++k) {
            dwv_material_input_t input = scene->bindings[scene->binding_order[scene->material_textures[i].first + k]].input;
            rough |= input == DWV_INPUT_ROUGHNESS;
            level |= input == DWV_INPUT_SPECULAR;
        }
        if (scene->materials[i].specular_model == DWV_SPECULAR_PRINCIPLED_V2 && (rough || level)) {
            scene->spec_grids[i] = dwvb_spec_grid_make(&scene->materials[i], rough, level);
            if (!scene->spec_grids[i]) {
                snprintf(message, size, "out of memory for material %u's specular tables", i);
                return uncommit(scene, DWV_ERROR_OUT_OF_MEMORY);
            }
            scene->shading[i].spec_grid = scene->spec_grids[i];
        }
    }
    for (uint32_t i = 0; i < nl; ++i) dwvl_light_init(&scene->emitters[i], &scene->lights[i]);
    uint32_t features = 0;
    if (nmesh > 0) {
        if (dwvg_world_build(&scene->geometry, scene->meshes, nmesh, message, size)) {
            /* dwvg_world_build freed its own part and says whether Embree or memory failed. */
            return uncommit(scene, strstr(message, "Embree") ? DWV_ERROR_INTERNAL : DWV_ERROR_OUT_OF_MEMORY);
        }
        scene->warnings = scene->geometry.warnings;
        features |= DWV_FEATURE_EMBREE;
    }
    int world_lit = dwvb_scene_world_lit(scene);
    if (world_lit) features |= DWV_FEATURE_WORLD_LIGHT;
    int lights_lit = 0;
    for (uint32_t i = 0; i < nl; ++i)
        for (int c = 0; c < 3; ++c) lights_lit |= scene->emitters[i].emission[c] > 0.0;
    if (lights_lit) features |= DWV_FEATURE_DIRECT_LIGHTS;
    dwvl_environment env = {.lights = scene->emitters, .light_count = nl, .world_lit = world_lit,
                            .geometry = nmesh > 0 ? &scene->geometry : NULL, .envmap = scene->envmap};
    for (int c = 0; c < 3; ++c) env.world[c] = scene->world[c];
    uint64_t grid_cells = 0; /* of the clearance grids made so far */
    for (uint32_t m = 0; m < nmesh; ++m) {
        const dwvb_material *material = &scene->shading[scene->meshes[m].material_id];
        if (material->diffuse_albedo[0] > 0.0 || material->diffuse_albedo[1] > 0.0 || material->diffuse_albedo[2] > 0.0)
            features |= DWV_FEATURE_DIFFUSE_SURFACES;
        if (!material->subsurface) continue;
        features |= DWV_FEATURE_SUBSURFACE;
        /* Ray-free walk steps (shade.c run_walk): cells of a quarter of the longest mean free
         * path, or coarser within the grid's size limit, but no grid where its cells would exceed
         * that path (a medium too thin for the grid to vouch for a step: the leaf). */
        double sigma_min = material->medium.sigma_t[0];
        for (int c = 1; c < material->medium.channels; ++c) sigma_min = fmin(sigma_min, material->medium.sigma_t[c]);
        if (grid_cells < CLEARANCE_SCENE_CELLS) {
            if (dwvg_world_build_clearance(&scene->geometry, m, 0.25 / sigma_min, 1.0 / sigma_min)) {
                snprintf(message, size, "out of memory while making the clearance grid of mesh %u", m);
                return uncommit(scene, DWV_ERROR_OUT_OF_MEMORY);
            }
            const dwvg_clearance *grid = &scene->geometry.clearance[m];
            if (grid->lower) grid_cells += (uint64_t)grid->n[0] * grid->n[1] * grid->n[2];
        }
        if (!material->grey || dwvb_textured_inputs(scene, m)) features |= DWV_FEATURE_RGB_WALKS;
        if (!lights_lit && !world_lit) continue;
        int count = make_patches(scene, &env, m, scene->patches[m]);
        if (count < 0) {
            snprintf(message, size, "out of memory while finding the lit patches of mesh %u", m);
            return uncommit(scene, DWV_ERROR_OUT_OF_MEMORY);
        }
        scene->patch_count[m] = count;
        if (count > 0) features |= DWV_FEATURE_INCIDENT_PATCHES;
    }
    scene->features = features;
    scene->committed = 1;
    return DWV_SUCCESS;
}
