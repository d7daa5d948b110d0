/* capi entry points that build a scene: every argument checked and copied, nothing kept from the
 * caller, nothing changed once the scene is committed. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake/scene.h"
#include <dwivedi.h>
#include "util/error.h"
#include "geom/mesh.h"
#include "scene_handle.h"

dwv_result_t dwv_scene_create(dwv_scene_t **scene)
{
    DWV_TRY(dwv_check_pointer("dwv_scene_create", "scene", scene));
    dwvb_scene *made = dwvb_scene_new();
    *scene = made ? dwv_scene_handle(made) : NULL;
    if (!made) return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "dwv_scene_create: out of memory");
    return DWV_SUCCESS;
}

dwv_result_t dwv_scene_retain(dwv_scene_t *scene)
{
    DWV_TRY(dwv_check_pointer("dwv_scene_retain", "scene", scene));
    atomic_fetch_add(&dwv_scene_object(scene)->references, 1u);
    return DWV_SUCCESS;
}

void dwv_scene_release(dwv_scene_t *scene)
{
    if (!scene) return;
    dwvb_scene *s = dwv_scene_object(scene);
    if (atomic_fetch_sub(&s->references, 1u) == 1u) dwvb_scene_free(s);
}

/* The scene, still open for additions. */
static dwv_result_t open_scene(const char *fn, dwv_scene_t *scene, dwvb_scene **out)
{
    DWV_TRY(dwv_check_pointer(fn, "scene", scene));
    *out = dwv_scene_object(scene);
    if ((*out)->committed)
        return dwv_fail(DWV_ERROR_INVALID_STATE, "%s: the scene is committed and can no longer change", fn);
    return DWV_SUCCESS;
}

/* Each of `count` values finite and in [lo, hi]; `name` is an array, reported with its index. */
static dwv_result_t check_array(const char *fn, const char *name, const double *values, int count, double lo,
                                double hi)
{
    for (int i = 0; i < count; ++i) {
        char label[64];
        snprintf(label, sizeof label, "%s[%d]", name, i);
        DWV_TRY(dwv_check_range(fn, label, values[i], lo, hi));
    }
    return DWV_SUCCESS;
}

/* A row-major 3 x 4 transform: finite, and its linear part invertible (|det| not negligible
 * against the cube of its largest entry, so that normals and inverses stay meaningful). */
static dwv_result_t check_transform(const char *fn, const char *name, const double m[12])
{
    double largest = 0.0;
    for (int i = 0; i < 12; ++i) {
        char label[64];
        snprintf(label, sizeof label, "%s[%d]", name, i);
        DWV_TRY(dwv_check_finite(fn, label, m[i]));
        if (i % 4 != 3) largest = fmax(largest, fabs(m[i]));
    }
    double det = dwvg_transform_determinant(m);
    if (!(fabs(det) > 1e-12 * largest * largest * largest) || !isfinite(det))
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: %s is singular (determinant %.6g)", fn, name, det);
    return DWV_SUCCESS;
}

/* Columns 0 and 1 of the linear part orthogonal (to 1e-4 of their lengths): no shear. With
 * `unit`, all three columns orthonormal (rotation only) to 1e-4. */
static dwv_result_t check_rigid(const char *fn, const char *name, const double m[12], int unit)
{
    double len[3], dot01 = m[0] * m[1] + m[4] * m[5] + m[8] * m[9];
    double dot02 = m[0] * m[2] + m[4] * m[6] + m[8] * m[10], dot12 = m[1] * m[2] + m[5] * m[6] + m[9] * m[10];
    for (int j = 0; j < 3; ++j) len[j] = sqrt(m[j] * m[j] + m[4 + j] * m[4 + j] + m[8 + j] * m[8 + j]);
    int sheared = fabs(dot01) > 1e-4 * len[0] * len[1] || fabs(dot02) > 1e-4 * len[0] * len[2] ||
                  fabs(dot12) > 1e-4 * len[1] * len[2];
    if (sheared) return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: %s has shear (its axes are not orthogonal)", fn, name);
    if (unit) {
        for (int j = 0; j < 3; ++j)
            if (fabs(len[j] - 1.0) > 1e-4)
                return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                                "%s: %s must be a rotation and translation (axis %d has length %.6g)", fn, name, j,
                                len[j]);
        if (dwvg_transform_determinant(m) < 0.0)
            return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: %s mirrors (a rotation has determinant +1)", fn, name);
    }
    return DWV_SUCCESS;
}

dwv_result_t dwv_scene_add_material(dwv_scene_t *scene, const dwv_material_t *material_in, uint32_t *material_id)
{
    static const char fn[] = "dwv_scene_add_material";
    dwvb_scene *s;
    DWV_TRY(open_scene(fn, scene, &s));
    /* The struct as of 0.1.0 ended at subsurface_ior: such callers keep working, with the later
     * fields' defaults. Only the caller's struct_size bytes are read. */
    DWV_TRY(dwv_check_struct(fn, "material", material_in, (uint32_t)offsetof(dwv_material_t, subsurface_exit)));
    DWV_TRY(dwv_check_pointer(fn, "material_id", material_id));
    dwv_material_t resolved = DWV_MATERIAL_INIT;
    size_t given = material_in->struct_size < sizeof resolved ? material_in->struct_size : sizeof resolved;
    memcpy(&resolved, material_in, given);
    resolved.struct_size = (uint32_t)sizeof resolved;
    const dwv_material_t *material = &resolved;
    if (material->kind != DWV_MATERIAL_SUBSURFACE && material->kind != DWV_MATERIAL_DIFFUSE)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: material kind %d is neither subsurface (0) nor diffuse (1)",
                        fn, (int)material->kind);
    DWV_TRY(check_array(fn, "base_color", material->base_color, 3, 0.0, 1.0));
    DWV_TRY(dwv_check_range(fn, "subsurface_weight", material->subsurface_weight, 0.0, 1.0));
    DWV_TRY(check_array(fn, "subsurface_color", material->subsurface_color, 3, 0.0, 1.0));
    DWV_TRY(check_array(fn, "subsurface_radius", material->subsurface_radius, 3, 0.0, HUGE_VAL));
    DWV_TRY(dwv_check_range(fn, "subsurface_scale", material->subsurface_scale, 0.0, HUGE_VAL));
    DWV_TRY(dwv_check_finite(fn, "subsurface_anisotropy", material->subsurface_anisotropy));
    if (!(fabs(material->subsurface_anisotropy) < 1.0))
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: subsurface_anisotropy = %.17g is outside (-1, 1)", fn,
                        material->subsurface_anisotropy);
    DWV_TRY(dwv_check_range(fn, "subsurface_ior", material->subsurface_ior, 1.0, 4.0));
    if (material->subsurface_exit != DWV_SUBSURFACE_EXIT_LAMBERT &&
        material->subsurface_exit != DWV_SUBSURFACE_EXIT_PRINCIPLED_V1)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: subsurface_exit %d is neither Lambert (0) nor Principled v1 (1)", fn,
                        (int)material->subsurface_exit);
    DWV_TRY(dwv_check_range(fn, "roughness", material->roughness, 0.0, 1.0));
    if (material->subsurface_model < DWV_SUBSURFACE_MODEL_FIXED_RADIUS ||
        material->subsurface_model > DWV_SUBSURFACE_MODEL_BLENDER52_SKIN)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: subsurface_model %d is not a DWV_SUBSURFACE_MODEL_* value (0 to 6)", fn,
                        (int)material->subsurface_model);
    if (material->specular_model < DWV_SPECULAR_NONE || material->specular_model > DWV_SPECULAR_PRINCIPLED_V2)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: specular_model %d is not a DWV_SPECULAR_* value (none 0, Principled v1 1, v2 2)", fn,
                        (int)material->specular_model);
    DWV_TRY(dwv_check_range(fn, "ior", material->ior, 1.0, 4.0));
    DWV_TRY(dwv_check_range(fn, "specular", material->specular, 0.0, HUGE_VAL));
    DWV_TRY(check_array(fn, "specular_tint", material->specular_tint, 3, 0.0, 1.0));
    if (material->specular_multiscatter != 0 && material->specular_multiscatter != 1)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: specular_multiscatter = %d is neither 0 (GGX) nor 1", fn,
                        (int)material->specular_multiscatter);
    DWV_TRY(dwv_check_range(fn, "subsurface_min_footprint", material->subsurface_min_footprint, 0.0, 1e6));
    if (material->specular_model == DWV_SPECULAR_PRINCIPLED_V1 && !(material->specular < 12.5))
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE,
                        "%s: specular = %.17g: the 3.x Principled v1 specular needs Specular below 12.5 (its IOR "
                        "2 / (1 - sqrt(0.08 Specular)) - 1 is infinite there)", fn, material->specular);
    if (material->specular_multiscatter && material->specular_model == DWV_SPECULAR_PRINCIPLED_V1)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: Multiscatter GGX is not modelled for the 3.x Principled v1 specular (Cycles 3.x walks "
                        "the microsurface); use GGX (specular_multiscatter 0)", fn);
    if (s->material_count >= DWVB_MAX_MATERIALS)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: a scene holds at most %u materials", fn, DWVB_MAX_MATERIALS);
    if (dwvb_scene_push_material(s, material)) return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: out of memory", fn);
    *material_id = s->material_count - 1u;
    return DWV_SUCCESS;
}

dwv_result_t dwv_scene_add_mesh(dwv_scene_t *scene, const dwv_mesh_t *mesh_in, uint32_t *mesh_id)
{
    static const char fn[] = "dwv_scene_add_mesh";
    dwvb_scene *s;
    DWV_TRY(open_scene(fn, scene, &s));
    /* The struct as of 0.1.0 ended at transform: such callers keep working, with the later
     * field's default. Only the caller's struct_size bytes are read. */
    DWV_TRY(dwv_check_struct(fn, "mesh", mesh_in,
                             (uint32_t)offsetof(dwv_mesh_t, shadow_terminator_geometry_offset)));
    DWV_TRY(dwv_check_pointer(fn, "mesh_id", mesh_id));
    dwv_mesh_t resolved = DWV_MESH_INIT;
    size_t given = mesh_in->struct_size < sizeof resolved ? mesh_in->struct_size : sizeof resolved;
    memcpy(&resolved, mesh_in, given);
    resolved.struct_size = (uint32_t)sizeof resolved;
    const dwv_mesh_t *mesh = &resolved;
    DWV_TRY(dwv_check_pointer(fn, "mesh->positions", mesh->positions));
    DWV_TRY(dwv_check_pointer(fn, "mesh->indices", mesh->indices));
    /* Sizes first: nothing is read or allocated for an absurd count. */
    if (mesh->vertex_count < 3u || mesh->vertex_count > DWVG_MAX_MESH_ELEMENTS)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: vertex_count = %u is outside [3, %u]", fn, mesh->vertex_count,
                        DWVG_MAX_MESH_ELEMENTS);
    if (mesh->triangle_count < 1u || mesh->triangle_count > DWVG_MAX_MESH_ELEMENTS)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: triangle_count = %u is outside [1, %u]", fn,
                        mesh->triangle_count, DWVG_MAX_MESH_ELEMENTS);
    if (mesh->material_id >= s->material_count)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: material_id = %u but the scene has %u material(s)", fn,
                        mesh->material_id, s->material_count);
    if (s->mesh_count >= DWVB_MAX_MESHES)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: a scene holds at most %u meshes", fn, DWVB_MAX_MESHES);
    DWV_TRY(check_transform(fn, "transform", mesh->transform));
    DWV_TRY(dwv_check_range(fn, "shadow_terminator_geometry_offset", mesh->shadow_terminator_geometry_offset, 0.0,
                            HUGE_VAL));
    size_t nv = mesh->vertex_count, nt = mesh->triangle_count;
    for (size_t i = 0; i < 3u * nv; ++i)
        if (!isfinite(mesh->positions[i]))
            return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: positions[%zu] (vertex %zu) is not finite", fn, i, i / 3u);
    for (size_t i = 0; i < 3u * nt; ++i)
        if (mesh->indices[i] >= mesh->vertex_count)
            return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: indices[%zu] = %u (triangle %zu) is not below vertex_count %u",
                            fn, i, mesh->indices[i], i / 3u, mesh->vertex_count);
    if (mesh->normals)
        for (size_t i = 0; i < 3u * nv; ++i)
            if (!isfinite(mesh->normals[i]))
                return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: normals[%zu] (vertex %zu) is not finite", fn, i,
                                i / 3u);
    if (mesh->uvs)
        for (size_t i = 0; i < 6u * nt; ++i)
            if (!isfinite(mesh->uvs[i]))
                return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: uvs[%zu] (triangle %zu) is not finite", fn, i, i / 6u);
    dwvg_mesh made;
    if (dwvg_mesh_init(&made, mesh->vertex_count, mesh->triangle_count, mesh->material_id, mesh->positions,
                       mesh->indices, mesh->normals, mesh->uvs, mesh->transform))
        return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: no memory for %u vertices and %u triangles", fn,
                        mesh->vertex_count, mesh->triangle_count);
    if (dwvb_scene_push_mesh(s, &made, mesh->shadow_terminator_geometry_offset)) {
        dwvg_mesh_free(&made);
        return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: out of memory", fn);
    }
    *mesh_id = s->mesh_count - 1u;
    return DWV_SUCCESS;
}

dwv_result_t dwv_scene_add_light(dwv_scene_t *scene, const dwv_light_desc_t *light_in)
{
    static const char fn[] = "dwv_scene_add_light";
    dwvb_scene *s;
    DWV_TRY(open_scene(fn, scene, &s));
    /* The struct before issue 18 ended at size_y: such callers keep working, with the spot
     * fields' defaults. Only the caller's struct_size bytes are read. */
    DWV_TRY(dwv_check_struct(fn, "light", light_in, (uint32_t)offsetof(dwv_light_desc_t, spot_size)));
    dwv_light_desc_t resolved = DWV_LIGHT_DESC_INIT;
    size_t given = light_in->struct_size < sizeof resolved ? light_in->struct_size : sizeof resolved;
    memcpy(&resolved, light_in, given);
    resolved.struct_size = (uint32_t)sizeof resolved;
    const dwv_light_desc_t *light = &resolved;
    DWV_TRY(check_array(fn, "color", light->color, 3, 0.0, HUGE_VAL));
    DWV_TRY(dwv_check_range(fn, "strength", light->strength, 0.0, HUGE_VAL));
    switch (light->kind) {
    case DWV_LIGHT_SUN: {
        DWV_TRY(check_array(fn, "direction", light->direction, 3, -HUGE_VAL, HUGE_VAL));
        const double *d = light->direction;
        double length = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(length > 0.0) || !isfinite(length))
            return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: the sun's direction has length %.6g", fn, length);
        DWV_TRY(dwv_check_range(fn, "angle", light->angle, 0.0, 3.14159265358979323846));
        break;
    }
    case DWV_LIGHT_POINT:
        DWV_TRY(check_array(fn, "position", light->position, 3, -HUGE_VAL, HUGE_VAL));
        DWV_TRY(dwv_check_range(fn, "radius", light->radius, 0.0, HUGE_VAL));
        break;
    case DWV_LIGHT_SPOT: {
        DWV_TRY(check_array(fn, "position", light->position, 3, -HUGE_VAL, HUGE_VAL));
        DWV_TRY(dwv_check_range(fn, "radius", light->radius, 0.0, HUGE_VAL));
        DWV_TRY(check_array(fn, "direction", light->direction, 3, -HUGE_VAL, HUGE_VAL));
        const double *d = light->direction;
        double length = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(length > 0.0) || !isfinite(length))
            return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: the spot light's direction has length %.6g", fn, length);
        DWV_TRY(dwv_check_range(fn, "spot_size", light->spot_size, 0.0, 3.14159265358979323846));
        if (!(light->spot_size > 0.0))
            return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: spot_size (the cone's full angle) must be > 0", fn);
        DWV_TRY(dwv_check_range(fn, "spot_blend", light->spot_blend, 0.0, 1.0));
        if (light->spot_falloff != DWV_SPOT_FALLOFF_CYCLES3 && light->spot_falloff != DWV_SPOT_FALLOFF_CYCLES4)
            return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                            "%s: spot_falloff %d is neither Cycles 3.x (0) nor Cycles 4.0 onward (1)", fn,
                            (int)light->spot_falloff);
        break;
    }
    case DWV_LIGHT_AREA_RECTANGLE:
    case DWV_LIGHT_AREA_DISK:
        DWV_TRY(check_transform(fn, "transform", light->transform));
        DWV_TRY(check_rigid(fn, "transform", light->transform, 0));
        DWV_TRY(dwv_check_range(fn, "size_x", light->size_x, 0.0, HUGE_VAL));
        DWV_TRY(dwv_check_range(fn, "size_y", light->size_y, 0.0, HUGE_VAL));
        if (!(light->size_x > 0.0 && light->size_y > 0.0))
            return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: an area light needs size_x and size_y > 0 (%.6g x %.6g)", fn,
                            light->size_x, light->size_y);
        break;
    default:
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: light kind %d is not sun (0), point (1), rectangle (2), disk (3) or spot (4)", fn,
                        (int)light->kind);
    }
    if (s->light_count >= DWVB_MAX_LIGHTS)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: a scene holds at most %u lights", fn, DWVB_MAX_LIGHTS);
    if (dwvb_scene_push_light(s, light)) return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: out of memory", fn);
    return DWV_SUCCESS;
}

dwv_result_t dwv_scene_set_world(dwv_scene_t *scene, const double color[3], double strength)
{
    static const char fn[] = "dwv_scene_set_world";
    dwvb_scene *s;
    DWV_TRY(open_scene(fn, scene, &s));
    DWV_TRY(dwv_check_pointer(fn, "color", color));
    DWV_TRY(check_array(fn, "color", color, 3, 0.0, HUGE_VAL));
    DWV_TRY(dwv_check_range(fn, "strength", strength, 0.0, HUGE_VAL));
    double world[3];
    for (int c = 0; c < 3; ++c) {
        world[c] = color[c] * strength;
        if (!isfinite(world[c]))
            return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: color[%d] x strength overflows", fn, c);
    }
    memcpy(s->world, world, sizeof world);
    dwvb_scene_set_envmap(s, NULL);
    return DWV_SUCCESS;
}

dwv_result_t dwv_scene_set_world_environment(dwv_scene_t *scene, const dwv_environment_t *environment)
{
    static const char fn[] = "dwv_scene_set_world_environment";
    dwvb_scene *s;
    DWV_TRY(open_scene(fn, scene, &s));
    DWV_TRY(dwv_check_struct(fn, "environment", environment, (uint32_t)sizeof(dwv_environment_t)));
    const dwv_environment_t *e = environment;
    uint32_t w = e->width, h = e->height;
    if (w < 1u || h < 1u || w > DWV_ENVIRONMENT_MAX_SIDE || h > DWV_ENVIRONMENT_MAX_SIDE ||
        (uint64_t)w * h > DWV_ENVIRONMENT_MAX_TEXELS)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE,
                        "%s: the image is %u x %u; each side must be 1 to %u and the texels at most %u", fn, w, h,
                        DWV_ENVIRONMENT_MAX_SIDE, DWV_ENVIRONMENT_MAX_TEXELS);
    DWV_TRY(dwv_check_pointer(fn, "environment->texels", e->texels));
    if (e->interpolation != DWV_ENVIRONMENT_LINEAR && e->interpolation != DWV_ENVIRONMENT_CLOSEST &&
        e->interpolation != DWV_ENVIRONMENT_CUBIC)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: interpolation %d is not linear (0), closest (1) or cubic (2)", fn, (int)e->interpolation);
    DWV_TRY(dwv_check_range(fn, "strength", e->strength, 0.0, HUGE_VAL));
    DWV_TRY(check_array(fn, "rotation", e->rotation, 9, -HUGE_VAL, HUGE_VAL));
    const double *m = e->rotation;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double dot = m[3 * i] * m[3 * j] + m[3 * i + 1] * m[3 * j + 1] + m[3 * i + 2] * m[3 * j + 2];
            if (fabs(dot - (i == j ? 1.0 : 0.0)) > 1e-4)
                return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                                "%s: rotation is not a rotation (rows %d and %d have dot product %.6g)", fn, i, j, dot);
        }
    double det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) + m[2] * (m[3] * m[7] - m[4] * m[6]);
    if (!(det > 0.0))
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: rotation mirrors (determinant %.6g; a rotation has +1)", fn, det);
    size_t n = (size_t)w * h;
    double largest = 0.0;
    for (size_t i = 0; i < 3u * n; ++i) {
        float t = e->texels[i];
        if (!isfinite(t) || t < 0.0f) {
            size_t texel = i / 3u;
            return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                            "%s: texel (%zu, %zu) (column, row from the bottom) has %s = %g: texels must be finite "
                            "and >= 0", fn, texel % w, texel / w, i % 3u == 0 ? "red" : i % 3u == 1 ? "green" : "blue",
                            (double)t);
        }
        largest = fmax(largest, (double)t);
    }
    if (!isfinite(largest * e->strength))
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: a texel x strength overflows", fn);
    /* A 1 x 1 image is a constant world, as Blender renders it (the periodic lookup reads that
     * one texel for every direction): it is stored as one, exactly what dwv_scene_set_world
     * gives. Refusing it would refuse a world that Blender accepts and renders; a black image or
     * strength 0 is a black world for the same reason. */
    double constant[3] = {0.0, 0.0, 0.0};
    if (n == 1u || largest == 0.0 || e->strength == 0.0) {
        if (n == 1u)
            for (int c = 0; c < 3; ++c) constant[c] = (double)e->texels[c] * e->strength;
        memcpy(s->world, constant, sizeof constant);
        dwvb_scene_set_envmap(s, NULL);
        return DWV_SUCCESS;
    }
    dwvl_envmap *map = malloc(sizeof *map);
    int made = map ? dwvl_envmap_init(map, e) : -1;
    if (made < 0) {
        free(map);
        return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: no memory for a %u x %u environment", fn, w, h);
    }
    memcpy(s->world, constant, sizeof constant);
    if (made > 0) {
        free(map); /* no luminance above 0 in single precision: black */
        map = NULL;
    }
    dwvb_scene_set_envmap(s, map);
    return DWV_SUCCESS;
}

dwv_result_t dwv_scene_set_camera(dwv_scene_t *scene, const dwv_camera_t *camera)
{
    static const char fn[] = "dwv_scene_set_camera";
    dwvb_scene *s;
    DWV_TRY(open_scene(fn, scene, &s));
    DWV_TRY(dwv_check_struct(fn, "camera", camera, (uint32_t)sizeof(dwv_camera_t)));
    if (camera->kind != DWV_CAMERA_PERSPECTIVE && camera->kind != DWV_CAMERA_ORTHOGRAPHIC)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: camera kind %d is neither perspective (0) nor orthographic (1)",
                        fn, (int)camera->kind);
    DWV_TRY(check_transform(fn, "transform", camera->transform));
    DWV_TRY(check_rigid(fn, "transform", camera->transform, 1));
    if (camera->kind == DWV_CAMERA_PERSPECTIVE) {
        DWV_TRY(dwv_check_range(fn, "focal_length", camera->focal_length, 0.0, HUGE_VAL));
        DWV_TRY(dwv_check_range(fn, "sensor_width", camera->sensor_width, 0.0, HUGE_VAL));
        if (!(camera->focal_length > 0.0 && camera->sensor_width > 0.0))
            return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: focal_length and sensor_width must be > 0", fn);
    } else {
        DWV_TRY(dwv_check_range(fn, "ortho_scale", camera->ortho_scale, 0.0, HUGE_VAL));
        if (!(camera->ortho_scale > 0.0))
            return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: ortho_scale must be > 0", fn);
    }
    s->camera = *camera;
    s->camera.struct_size = (uint32_t)sizeof(dwv_camera_t);
    s->have_camera = 1;
    return DWV_SUCCESS;
}

dwv_result_t dwv_scene_commit(dwv_scene_t *scene)
{
    static const char fn[] = "dwv_scene_commit";
    dwvb_scene *s;
    DWV_TRY(open_scene(fn, scene, &s));
    char message[256];
    dwv_result_t result = dwvb_scene_commit(s, message, sizeof message);
    if (result != DWV_SUCCESS) return dwv_fail(result, "%s: %s", fn, message);
    return DWV_SUCCESS;
}

const char *dwv_feature_name(uint32_t feature)
{
    switch (feature) {
    case DWV_FEATURE_EMBREE: return "embree";
    case DWV_FEATURE_SUBSURFACE: return "subsurface";
    case DWV_FEATURE_CLOSEST_POINT: return "closest_point";
    case DWV_FEATURE_INCIDENT_PATCHES: return "incident_patches";
    case DWV_FEATURE_RGB_WALKS: return "rgb_walks";
    case DWV_FEATURE_GUIDED: return "guided";
    case DWV_FEATURE_WORLD_LIGHT: return "world_light";
    case DWV_FEATURE_DIRECT_LIGHTS: return "direct_lights";
    case DWV_FEATURE_DIFFUSE_SURFACES: return "diffuse_surfaces";
    case DWV_FEATURE_CHANNEL_WALKS: return "channel_walks";
    case DWV_FEATURE_SHEET: return "sheet";
    default: return NULL;
    }
}
