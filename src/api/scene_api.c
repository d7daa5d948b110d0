/* capi entry points that build a scene: every argument checked and copied, nothing kept from the
 * caller, nothing changed once the scene is committed. */
#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake/scene.h"
#include <dwivedi.h>
#include "util/error.h"
#include "geom/mesh.h"
#include "output/exr_reader.h"
#include "output/png_reader.h"
#include "output/radiance_reader.h"
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

#define MAX_UV_LAYERS 64u
#define MAX_LAYER_NAME 1024u

/* The mesh's extra UV layers, names and tangents: present where counted, finite, names unique. */
static dwv_result_t check_layers(const char *fn, const dwv_mesh_t *mesh)
{
    size_t nt = mesh->triangle_count;
    uint32_t count = mesh->uv_layer_count;
    if (mesh->reserved_uv != 0u)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: reserved_uv must be 0", fn);
    if (count > MAX_UV_LAYERS)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: uv_layer_count = %u is above %u", fn, count, MAX_UV_LAYERS);
    if (count > 0u) DWV_TRY(dwv_check_pointer(fn, "mesh->uv_layers", mesh->uv_layers));
    for (uint32_t k = 0; k < count; ++k) {
        if (!mesh->uv_layers[k])
            return dwv_fail(DWV_ERROR_NULL_POINTER, "%s: uv_layers[%u] is NULL", fn, k);
        for (size_t i = 0; i < 6u * nt; ++i)
            if (!isfinite(mesh->uv_layers[k][i]))
                return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: uv_layers[%u][%zu] (triangle %zu) is not finite", fn,
                                k, i, i / 6u);
    }
    if (mesh->uv_layer_names)
        for (uint32_t k = 0; k <= count; ++k) {
            const char *name = mesh->uv_layer_names[k];
            if (!name) return dwv_fail(DWV_ERROR_NULL_POINTER, "%s: uv_layer_names[%u] is NULL", fn, k);
            if (!*name || strlen(name) > MAX_LAYER_NAME)
                return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: uv_layer_names[%u] is empty or longer than %u bytes",
                                fn, k, MAX_LAYER_NAME);
            for (uint32_t j = 0; j < k; ++j)
                if (strcmp(mesh->uv_layer_names[j], name) == 0)
                    return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: UV layers %u and %u are both named \"%s\"", fn, j,
                                    k, name);
        }
    if (mesh->tangents)
        for (uint32_t k = 0; k <= count; ++k) {
            const float *t = mesh->tangents[k];
            if (!t) continue;
            if (k == 0u && !mesh->uvs)
                return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: tangents[0] given for a mesh without uvs", fn);
            for (size_t i = 0; i < 12u * nt; ++i)
                if (!isfinite(t[i]) || (i % 4u == 3u && t[i] != 1.0f && t[i] != -1.0f))
                    return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                                    "%s: tangents[%u][%zu] (triangle %zu) is %s", fn, k, i, i / 12u,
                                    i % 4u == 3u ? "a sign other than +1 or -1" : "not finite");
        }
    return DWV_SUCCESS;
}

/* Copies the extra layers in the stored corner order (a mirroring transform swaps corners 1 and
 * 2, as dwvg_mesh_init does) and the given tangents to world space (the normals' transform, the
 * inverse transpose, whose orientation the sign takes on: exact for rotations, uniform scales and
 * mirrors, as Cycles' object_normal_transform of the mapped normal). 0, or -1 out of memory. */
static int copy_layers(const dwv_mesh_t *mesh, dwvb_mesh_layers *layers)
{
    size_t nt = mesh->triangle_count;
    uint32_t count = mesh->uv_layer_count + 1u;
    layers->count = count;
    layers->uvs = calloc(count, sizeof *layers->uvs);
    layers->names = calloc(count, sizeof *layers->names);
    layers->tangents = calloc(count, sizeof *layers->tangents);
    if (!layers->uvs || !layers->names || !layers->tangents) goto fail;
    const double *m = mesh->transform;
    double det = dwvg_transform_determinant(m);
    int mirror = det < 0.0;
    /* The cofactor matrix is det x the inverse transpose: its sign-corrected form keeps direction. */
    double cof[9] = {m[5] * m[10] - m[6] * m[9], m[6] * m[8] - m[4] * m[10], m[4] * m[9] - m[5] * m[8],
                     m[2] * m[9] - m[1] * m[10], m[0] * m[10] - m[2] * m[8], m[1] * m[8] - m[0] * m[9],
                     m[1] * m[6] - m[2] * m[5], m[2] * m[4] - m[0] * m[6], m[0] * m[5] - m[1] * m[4]};
    double orient = mirror ? -1.0 : 1.0;
    for (uint32_t k = 0; k < count; ++k) {
        char number[16];
        snprintf(number, sizeof number, "%u", k);
        const char *name = mesh->uv_layer_names ? mesh->uv_layer_names[k] : number;
        layers->names[k] = malloc(strlen(name) + 1u);
        if (!layers->names[k]) goto fail;
        strcpy(layers->names[k], name);
        if (k > 0u) {
            const float *uv = mesh->uv_layers[k - 1u];
            layers->uvs[k] = malloc(6u * nt * sizeof(float));
            if (!layers->uvs[k]) goto fail;
            for (size_t t = 0; t < nt; ++t)
                for (int c = 0; c < 3; ++c) {
                    int from = mirror && c > 0 ? 3 - c : c;
                    layers->uvs[k][6 * t + 2 * (size_t)c] = uv[6 * t + 2 * (size_t)from];
                    layers->uvs[k][6 * t + 2 * (size_t)c + 1] = uv[6 * t + 2 * (size_t)from + 1];
                }
        }
        const float *given = mesh->tangents ? mesh->tangents[k] : NULL;
        if (!given) continue;
        layers->tangents[k] = malloc(12u * nt * sizeof(float));
        if (!layers->tangents[k]) goto fail;
        for (size_t t = 0; t < nt; ++t)
            for (int c = 0; c < 3; ++c) {
                int from = mirror && c > 0 ? 3 - c : c;
                const float *g = given + 12u * t + 4u * (size_t)from;
                double w[3];
                for (int r = 0; r < 3; ++r) w[r] = orient * (cof[3 * r] * g[0] + cof[3 * r + 1] * g[1] + cof[3 * r + 2] * g[2]);
                double length = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
                float *o = layers->tangents[k] + 12u * t + 4u * (size_t)c;
                for (int r = 0; r < 3; ++r) o[r] = length > 0.0 ? (float)(w[r] / length) : 0.0f;
                o[3] = (float)(g[3] * orient);
            }
    }
    return 0;
fail:
    dwvb_mesh_layers_free(layers);
    return -1;
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
    DWV_TRY(check_layers(fn, mesh));
    dwvb_mesh_layers layers;
    if (copy_layers(mesh, &layers))
        return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: no memory for the UV layers of %u triangles", fn, mesh->triangle_count);
    dwvg_mesh made;
    if (dwvg_mesh_init(&made, mesh->vertex_count, mesh->triangle_count, mesh->material_id, mesh->positions,
                       mesh->indices, mesh->normals, mesh->uvs, mesh->transform)) {
        dwvb_mesh_layers_free(&layers);
        return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: no memory for %u vertices and %u triangles", fn,
                        mesh->vertex_count, mesh->triangle_count);
    }
    if (dwvb_scene_push_mesh(s, &made, mesh->shadow_terminator_geometry_offset, &layers)) {
        dwvg_mesh_free(&made);
        dwvb_mesh_layers_free(&layers);
        return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: out of memory", fn);
    }
    *mesh_id = s->mesh_count - 1u;
    return DWV_SUCCESS;
}

static dwv_result_t check_point_shape(const char *fn, const dwv_light_desc_t *light)
{
    if (light->point_shape != DWV_POINT_SHAPE_DISC && light->point_shape != DWV_POINT_SHAPE_SPHERE)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: point_shape %d is neither the disc (0) nor the sphere (1)", fn,
                        (int)light->point_shape);
    return DWV_SUCCESS;
}

dwv_result_t dwv_scene_add_light(dwv_scene_t *scene, const dwv_light_desc_t *light_in)
{
    static const char fn[] = "dwv_scene_add_light";
    dwvb_scene *s;
    DWV_TRY(open_scene(fn, scene, &s));
    /* The struct before issue 18 ended at size_y, then at `reserved` (before point_shape): such
     * callers keep working, with the later fields' defaults. Only the caller's struct_size bytes
     * are read. */
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
        DWV_TRY(check_point_shape(fn, light));
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
        DWV_TRY(check_point_shape(fn, light));
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

dwv_result_t dwv_scene_set_world_environment_file(dwv_scene_t *scene, const char *path,
                                                  const dwv_environment_t *settings)
{
    static const char fn[] = "dwv_scene_set_world_environment_file";
    dwvb_scene *s;
    DWV_TRY(open_scene(fn, scene, &s));
    DWV_TRY(dwv_check_pointer(fn, "path", path));
    DWV_TRY(dwv_check_struct(fn, "settings", settings, (uint32_t)sizeof(dwv_environment_t)));
    dwv_environment_t e = *settings;
    float *texels = NULL;
    uint32_t channels = 3u;
    char message[512];
    dwv_result_t r;
    if (dwvo_file_is_exr(path))
        r = dwvo_read_exr_float(path, DWV_ENVIRONMENT_MAX_SIDE, DWV_ENVIRONMENT_MAX_TEXELS, &e.width, &e.height,
                                &channels, &texels, message, sizeof message);
    else if (dwvo_file_is_radiance(path))
        r = dwvo_read_radiance(path, DWV_ENVIRONMENT_MAX_SIDE, DWV_ENVIRONMENT_MAX_TEXELS, &e.width, &e.height,
                               &texels, message, sizeof message);
    else {
        FILE *f = fopen(path, "rb");
        if (!f) return dwv_fail(DWV_ERROR_IO, "%s: cannot read '%s': %s", fn, path, strerror(errno));
        fclose(f);
        return dwv_fail(DWV_ERROR_FORMAT, "%s: '%s' is neither an OpenEXR file nor a Radiance picture (.hdr)", fn,
                        path);
    }
    if (r != DWV_SUCCESS) return dwv_fail(r, "%s: %s", fn, message);
    /* To RGB in place: an alpha channel is dropped (a world has none), Y is grey. */
    size_t n = (size_t)e.width * e.height;
    if (channels == 4u)
        for (size_t i = 0; i < n; ++i)
            for (int c = 0; c < 3; ++c) texels[3u * i + (size_t)c] = texels[4u * i + (size_t)c];
    if (channels == 1u) {
        float *rgb = realloc(texels, 3u * n * sizeof *rgb);
        if (!rgb) {
            free(texels);
            return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: no memory for '%s' (%u x %u)", fn, path, e.width, e.height);
        }
        texels = rgb;
        for (size_t i = n; i-- > 0;) texels[3u * i] = texels[3u * i + 1u] = texels[3u * i + 2u] = texels[i];
    }
    e.struct_size = (uint32_t)sizeof e;
    e.texels = texels;
    r = dwv_scene_set_world_environment(scene, &e);
    free(texels);
    if (r != DWV_SUCCESS) {
        char reason[768];
        snprintf(reason, sizeof reason, "%s", dwv_last_error_message());
        return dwv_fail(r, "%s: '%s': %s", fn, path, reason);
    }
    return DWV_SUCCESS;
}

dwv_result_t dwv_scene_add_texture(dwv_scene_t *scene, const dwv_texture_desc_t *texture, uint32_t *texture_id)
{
    static const char fn[] = "dwv_scene_add_texture";
    dwvb_scene *s;
    DWV_TRY(open_scene(fn, scene, &s));
    DWV_TRY(dwv_check_struct(fn, "texture", texture, (uint32_t)sizeof(dwv_texture_desc_t)));
    DWV_TRY(dwv_check_pointer(fn, "texture_id", texture_id));
    /* Sizes first: nothing is read for an absurd image. */
    if (texture->width < 1u || texture->height < 1u)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: the texture is %u x %u texels (an image needs at least 1 x 1)", fn,
                        texture->width, texture->height);
    if (texture->width > DWVB_MAX_TEXTURE_SIDE || texture->height > DWVB_MAX_TEXTURE_SIDE ||
        (uint64_t)texture->width * texture->height > DWVB_MAX_TEXTURE_TEXELS)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: the texture is %u x %u texels (at most %u per side and 2^28 in all)",
                        fn, texture->width, texture->height, DWVB_MAX_TEXTURE_SIDE);
    if (texture->channels != 1u && texture->channels != 3u && texture->channels != 4u)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: channels = %u (1, 3 or 4)", fn, texture->channels);
    if (texture->format != DWV_TEXEL_FLOAT32 && texture->format != DWV_TEXEL_SRGB8 && texture->format != DWV_TEXEL_LINEAR8)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: format %d is not float32 (0), sRGB 8-bit (1) or linear 8-bit (2)",
                        fn, (int)texture->format);
    if (texture->extension < DWV_EXTENSION_REPEAT || texture->extension > DWV_EXTENSION_MIRROR)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: extension %d is not repeat (0), extend (1), clip (2) or mirror (3)", fn, (int)texture->extension);
    if (texture->interpolation < DWV_INTERPOLATION_LINEAR || texture->interpolation > DWV_INTERPOLATION_CUBIC)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: interpolation %d is not linear (0), closest (1) or cubic (2)", fn,
                        (int)texture->interpolation);
    if (texture->reserved != 0u) return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: reserved must be 0", fn);
    DWV_TRY(dwv_check_pointer(fn, "texture->texels", texture->texels));
    if (texture->format == DWV_TEXEL_FLOAT32) {
        const float *texels = texture->texels;
        size_t n = (size_t)texture->width * texture->height * texture->channels;
        for (size_t i = 0; i < n; ++i)
            if (!isfinite(texels[i])) {
                size_t t = i / texture->channels;
                return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: texel (%zu, %zu) channel %zu is %s", fn,
                                t % texture->width, t / texture->width, i % texture->channels,
                                isnan(texels[i]) ? "NaN" : "infinite");
            }
    }
    if (s->texture_count >= DWVB_MAX_TEXTURES)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: a scene holds at most %u textures", fn, DWVB_MAX_TEXTURES);
    dwvb_texture made;
    if (dwvb_texture_init(&made, texture))
        return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: no memory for %u x %u texels", fn, texture->width, texture->height);
    if (dwvb_scene_push_texture(s, &made)) {
        dwvb_texture_free(&made);
        return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: out of memory", fn);
    }
    *texture_id = s->texture_count - 1u;
    return DWV_SUCCESS;
}

dwv_result_t dwv_scene_add_texture_file(dwv_scene_t *scene, const char *path, const dwv_texture_desc_t *settings,
                                        uint32_t *texture_id)
{
    static const char fn[] = "dwv_scene_add_texture_file";
    dwvb_scene *s;
    DWV_TRY(open_scene(fn, scene, &s));
    DWV_TRY(dwv_check_pointer(fn, "path", path));
    DWV_TRY(dwv_check_struct(fn, "settings", settings, (uint32_t)sizeof(dwv_texture_desc_t)));
    DWV_TRY(dwv_check_pointer(fn, "texture_id", texture_id));
    FILE *probe = fopen(path, "rb");
    if (!probe) return dwv_fail(DWV_ERROR_IO, "%s: cannot read '%s': %s", fn, path, strerror(errno));
    fclose(probe);
    int exr = dwvo_file_is_exr(path);
    if (exr && settings->format != DWV_TEXEL_FLOAT32)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: '%s' is an OpenEXR file, which holds scene-linear floats: format must be float32 (0), "
                        "not %d", fn, path, (int)settings->format);
    if (!exr && settings->format != DWV_TEXEL_SRGB8 && settings->format != DWV_TEXEL_LINEAR8)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: a PNG holds 8-bit values: format must be sRGB 8-bit (1) or linear 8-bit (2), not %d", fn,
                        (int)settings->format);
    dwv_texture_desc_t desc = *settings;
    void *pixels = NULL;
    char message[512];
    dwv_result_t r;
    if (exr) {
        float *values = NULL;
        r = dwvo_read_exr_float(path, DWVB_MAX_TEXTURE_SIDE, DWVB_MAX_TEXTURE_TEXELS, &desc.width, &desc.height,
                                &desc.channels, &values, message, sizeof message);
        pixels = values;
    } else {
        uint8_t *bytes = NULL;
        r = dwvo_read_png8(path, &desc.width, &desc.height, &desc.channels, &bytes, message, sizeof message);
        pixels = bytes;
    }
    if (r != DWV_SUCCESS) return dwv_fail(r, "%s: %s", fn, message);
    desc.struct_size = (uint32_t)sizeof desc;
    desc.texels = pixels;
    r = dwv_scene_add_texture(scene, &desc, texture_id);
    free(pixels);
    if (r != DWV_SUCCESS) {
        /* Name the file in front of dwv_scene_add_texture's reason (a NaN texel, say). */
        char reason[768];
        snprintf(reason, sizeof reason, "%s", dwv_last_error_message());
        return dwv_fail(r, "%s: '%s': %s", fn, path, reason);
    }
    return DWV_SUCCESS;
}

dwv_result_t dwv_scene_bind_texture(dwv_scene_t *scene, uint32_t material_id, const dwv_texture_binding_t *binding)
{
    static const char fn[] = "dwv_scene_bind_texture";
    dwvb_scene *s;
    DWV_TRY(open_scene(fn, scene, &s));
    DWV_TRY(dwv_check_struct(fn, "binding", binding, (uint32_t)sizeof(dwv_texture_binding_t)));
    if (material_id >= s->material_count)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: material_id = %u but the scene has %u material(s)", fn, material_id,
                        s->material_count);
    if (binding->texture_id >= s->texture_count)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: texture_id = %u but the scene has %u texture(s)", fn,
                        binding->texture_id, s->texture_count);
    dwv_material_input_t input = binding->input;
    if (input < DWV_INPUT_BASE_COLOR || input > DWV_INPUT_BUMP)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: input %d is not a DWV_INPUT_* value (0 to 10)", fn, (int)input);
    const dwvb_texture *texture = &s->textures[binding->texture_id];
    int colour = input == DWV_INPUT_BASE_COLOR || input == DWV_INPUT_SUBSURFACE_COLOR ||
                 input == DWV_INPUT_SUBSURFACE_RADIUS || input == DWV_INPUT_SPECULAR_TINT || input == DWV_INPUT_NORMAL_MAP;
    if (colour && texture->channels < 3u)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: input %d takes a colour (3 or 4 channels) but texture %u has %u channel", fn, (int)input,
                        binding->texture_id, texture->channels);
    DWV_TRY(dwv_check_range(fn, "blend", binding->blend, 0.0, 1.0));
    DWV_TRY(dwv_check_range(fn, "strength", binding->strength, 0.0, input == DWV_INPUT_BUMP ? 1.0 : 1e6));
    DWV_TRY(dwv_check_range(fn, "distance", binding->distance, -1e30, 1e30));
    if (binding->invert != 0 && binding->invert != 1)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: invert = %d is neither 0 nor 1", fn, (int)binding->invert);
    if (binding->bump_shadowing < DWV_BUMP_SHADOWING_NONE || binding->bump_shadowing > DWV_BUMP_SHADOWING_CONTY2019)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: bump_shadowing %d is not none (0), Chiang 2019 (1, Blender 3.x), Chiang 2019 with the "
                        "mapped normal (2, 4.x) or Conty 2019 (3, 5.x)", fn, (int)binding->bump_shadowing);
    if (binding->reserved != 0u) return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: reserved must be 0", fn);
    if (binding->uv_layer && strlen(binding->uv_layer) > MAX_LAYER_NAME)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: uv_layer is longer than %u bytes", fn, MAX_LAYER_NAME);
    for (uint32_t b = 0; b < s->binding_count; ++b)
        if (s->bindings[b].material_id == material_id && s->bindings[b].input == input &&
            (input == DWV_INPUT_NORMAL_MAP || input == DWV_INPUT_BUMP))
            return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: material %u already has a %s texture", fn, material_id,
                            input == DWV_INPUT_BUMP ? "bump" : "normal map");
    if (s->binding_count >= DWVB_MAX_BINDINGS)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: a scene holds at most %u bindings", fn, DWVB_MAX_BINDINGS);
    dwvb_binding made = {material_id, input, binding->texture_id, binding->invert, NULL,
                         binding->blend, binding->strength, binding->distance, binding->bump_shadowing};
    if (binding->uv_layer && *binding->uv_layer) {
        made.uv_layer = malloc(strlen(binding->uv_layer) + 1u);
        if (!made.uv_layer) return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: out of memory", fn);
        strcpy(made.uv_layer, binding->uv_layer);
    }
    if (dwvb_scene_push_binding(s, &made)) {
        free(made.uv_layer);
        return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: out of memory", fn);
    }
    return DWV_SUCCESS;
}

dwv_result_t dwv_scene_texture_memory(const dwv_scene_t *scene, uint64_t *bytes, uint64_t *texels)
{
    static const char fn[] = "dwv_scene_texture_memory";
    DWV_TRY(dwv_check_pointer(fn, "scene", scene));
    DWV_TRY(dwv_check_pointer(fn, "bytes", bytes));
    DWV_TRY(dwv_check_pointer(fn, "texels", texels));
    const dwvb_scene *s = dwv_scene_object(scene);
    *bytes = *texels = 0u;
    for (uint32_t i = 0; i < s->texture_count; ++i) {
        const dwvb_texture *t = &s->textures[i];
        uint64_t n = (uint64_t)t->width * t->height;
        *texels += n;
        *bytes += n * dwvb_texture_texel_bytes(t);
    }
    return DWV_SUCCESS;
}
