/* The scene file's materials, by name. */
#include "scenefile/scene_json_internal.h"

#include <stdlib.h>
#include <string.h>

#include "util/error.h"

static dwv_result_t read_material(dwvs_parser *ps, const cJSON *item, const char *path)
{
    static const char *const keys[] = {"kind", "base_color", "subsurface_weight", "subsurface_color",
                                       "subsurface_radius", "subsurface_scale", "subsurface_anisotropy",
                                       "subsurface_ior", "subsurface_exit", "roughness", "subsurface_model",
                                       "specular_model", "ior", "specular", "specular_tint",
                                       "specular_distribution", "subsurface_min_footprint", "textures"};
    static const char *const kinds[] = {"subsurface", "diffuse"};
    static const char *const exits[] = {"lambert", "principled_v1"};
    /* In the order of dwv_subsurface_model_t's and dwv_specular_model_t's values (0, 1, ...). */
    static const char *const models[] = {"fixed_radius",          "blender3_random_walk", "blender4_random_walk",
                                         "blender4_skin",         "blender52_random_walk", "blender52_legacy",
                                         "blender52_skin"};
    static const char *const speculars[] = {"none", "principled_v1", "principled_v2"};
    static const char *const distributions[] = {"ggx", "multiscatter_ggx"};
    DWV_TRY(dwvs_check_keys(item, path, keys, sizeof keys / sizeof keys[0]));
    dwv_material_t m = DWV_MATERIAL_INIT;
    size_t kind = 0, exit = 0; /* DWV_MATERIAL_INIT's: subsurface, lambert */
    DWV_TRY(dwvs_opt_choice(item, path, "kind", kinds, 2, &kind));
    m.kind = kind == 0 ? DWV_MATERIAL_SUBSURFACE : DWV_MATERIAL_DIFFUSE;
    DWV_TRY(dwvs_opt_vector(item, path, "base_color", 3, m.base_color));
    DWV_TRY(dwvs_opt_number(item, path, "subsurface_weight", &m.subsurface_weight));
    DWV_TRY(dwvs_opt_vector(item, path, "subsurface_color", 3, m.subsurface_color));
    DWV_TRY(dwvs_opt_vector(item, path, "subsurface_radius", 3, m.subsurface_radius));
    DWV_TRY(dwvs_opt_number(item, path, "subsurface_scale", &m.subsurface_scale));
    DWV_TRY(dwvs_opt_number(item, path, "subsurface_anisotropy", &m.subsurface_anisotropy));
    DWV_TRY(dwvs_opt_number(item, path, "subsurface_ior", &m.subsurface_ior));
    DWV_TRY(dwvs_opt_choice(item, path, "subsurface_exit", exits, 2, &exit));
    m.subsurface_exit = exit == 0 ? DWV_SUBSURFACE_EXIT_LAMBERT : DWV_SUBSURFACE_EXIT_PRINCIPLED_V1;
    DWV_TRY(dwvs_opt_number(item, path, "roughness", &m.roughness));
    size_t model = 0, specular = 0, distribution = 0; /* DWV_MATERIAL_INIT's: fixed radius, none, GGX */
    DWV_TRY(dwvs_opt_choice(item, path, "subsurface_model", models, sizeof models / sizeof models[0], &model));
    m.subsurface_model = (dwv_subsurface_model_t)model;
    DWV_TRY(dwvs_opt_choice(item, path, "specular_model", speculars, sizeof speculars / sizeof speculars[0],
                            &specular));
    m.specular_model = (dwv_specular_model_t)specular;
    DWV_TRY(dwvs_opt_number(item, path, "ior", &m.ior));
    DWV_TRY(dwvs_opt_number(item, path, "specular", &m.specular));
    DWV_TRY(dwvs_opt_vector(item, path, "specular_tint", 3, m.specular_tint));
    DWV_TRY(dwvs_opt_choice(item, path, "specular_distribution", distributions, 2, &distribution));
    m.specular_multiscatter = (int32_t)distribution;
    DWV_TRY(dwvs_opt_number(item, path, "subsurface_min_footprint", &m.subsurface_min_footprint));
    uint32_t id;
    dwv_result_t r = dwv_scene_add_material(ps->scene, &m, &id);
    if (r != DWV_SUCCESS) return dwvs_prefix_capi(r, path);
    const cJSON *textures = dwvs_member(item, "textures");
    if (textures) DWV_TRY(dwvs_read_material_textures(ps, textures, path, id));
    ps->materials[ps->material_count].name = item->string;
    ps->materials[ps->material_count].id = id;
    ++ps->material_count;
    return DWV_SUCCESS;
}

dwv_result_t dwvs_read_materials(dwvs_parser *ps, const cJSON *item)
{
    if (!cJSON_IsObject(item))
        return dwvs_fail_at(DWV_ERROR_FORMAT, "materials", "expected an object of materials by name, found %s",
                            dwvs_type_name(item));
    size_t n = 0;
    for (const cJSON *c = item->child; c; c = c->next) ++n;
    ps->materials = calloc(n ? n : 1u, sizeof *ps->materials);
    if (!ps->materials) return dwvs_fail_at(DWV_ERROR_OUT_OF_MEMORY, "materials", "no memory for %zu names", n);
    for (const cJSON *c = item->child; c; c = c->next) {
        char p[PATH_SIZE];
        dwvs_path_key(p, "materials", c->string);
        if (!c->string[0]) return dwvs_fail_at(DWV_ERROR_FORMAT, "materials", "a material has an empty name");
        DWV_TRY(read_material(ps, c, p));
    }
    qsort(ps->materials, ps->material_count, sizeof *ps->materials, dwvs_compare_named);
    for (size_t i = 1; i < ps->material_count; ++i)
        if (strcmp(ps->materials[i - 1].name, ps->materials[i].name) == 0) {
            char name[SHOWN_SIZE];
            return dwvs_fail_at(DWV_ERROR_FORMAT, "materials", "the name '%s' appears twice",
                                dwvs_shown(ps->materials[i].name, name));
        }
    return DWV_SUCCESS;
}
