/* The scene file's meshes: OBJ or PLY files or inline arrays, transforms, unique names. */
#include "scenefile/scene_json_internal.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scenefile/mesh_file.h"
#include "util/error.h"


static const double identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};

dwv_result_t dwvs_read_floats(const cJSON *item, const char *path, size_t group, size_t *count, float **out)
{
    if (!cJSON_IsArray(item))
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "expected an array of numbers, found %s", dwvs_type_name(item));
    size_t n = 0;
    for (const cJSON *e = item->child; e; e = e->next) ++n;
    if (n == 0 || n % group)
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "%zu numbers: expected a non-zero multiple of %zu", n, group);
    float *values = malloc(n * sizeof *values);
    if (!values) return dwvs_fail_at(DWV_ERROR_OUT_OF_MEMORY, path, "no memory for %zu numbers", n);
    size_t i = 0;
    for (const cJSON *e = item->child; e; e = e->next, ++i) {
        char p[PATH_SIZE];
        double v = 0.0;
        dwvs_path_index(p, path, i);
        dwv_result_t r = dwvs_read_number(e, p, &v);
        if (r == DWV_SUCCESS && fabs(v) > FLT_MAX)
            r = dwvs_fail_at(DWV_ERROR_OUT_OF_RANGE, p, "%.17g does not fit a float", v);
        if (r != DWV_SUCCESS) {
            free(values);
            return r;
        }
        values[i] = (float)v;
    }
    *count = n;
    *out = values;
    return DWV_SUCCESS;
}

static dwv_result_t read_indices(const cJSON *item, const char *path, size_t *count, uint32_t **out)
{
    if (!cJSON_IsArray(item))
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "expected an array of whole numbers, found %s", dwvs_type_name(item));
    size_t n = 0;
    for (const cJSON *e = item->child; e; e = e->next) ++n;
    if (n == 0 || n % 3u)
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "%zu indices: expected a non-zero multiple of 3 (triangles)", n);
    uint32_t *values = malloc(n * sizeof *values);
    if (!values) return dwvs_fail_at(DWV_ERROR_OUT_OF_MEMORY, path, "no memory for %zu indices", n);
    size_t i = 0;
    for (const cJSON *e = item->child; e; e = e->next, ++i) {
        char p[PATH_SIZE];
        dwvs_path_index(p, path, i);
        dwv_result_t r = dwvs_read_u32(e, p, 0u, UINT32_MAX, &values[i]);
        if (r != DWV_SUCCESS) {
            free(values);
            return r;
        }
    }
    *count = n;
    *out = values;
    return DWV_SUCCESS;
}

dwv_result_t dwvs_resolve_path(const char *base_dir, const char *file, const char *path, char out[MAX_FILE_PATH])
{
    int n;
    if (file[0] == '/' || !base_dir || !base_dir[0])
        n = snprintf(out, MAX_FILE_PATH, "%s", file);
    else
        n = snprintf(out, MAX_FILE_PATH, "%s/%s", base_dir, file);
    if (n < 0 || n >= MAX_FILE_PATH)
        return dwvs_fail_at(DWV_ERROR_OUT_OF_RANGE, path, "the path is longer than %d bytes", MAX_FILE_PATH - 1);
    return DWV_SUCCESS;
}

/* A mesh's UV layers beyond its first ("uv_layers": [{"name", "uvs", "tangents"}]) and the
 * tangents of each ("tangents" beside "uvs" for the first), read once the triangle count is
 * known: 6 numbers a triangle for UVs, 12 for tangents (xyz and the bitangent's sign per corner). */
#define MAX_EXTRA_LAYERS 64u
typedef struct mesh_layers {
    uint32_t count;
    float *uvs[MAX_EXTRA_LAYERS];
    float *tangents[MAX_EXTRA_LAYERS + 1u];
    const char *names[MAX_EXTRA_LAYERS + 1u];
} mesh_layers;

static void mesh_layers_free(mesh_layers *l)
{
    for (uint32_t i = 0; i < MAX_EXTRA_LAYERS; ++i) free(l->uvs[i]);
    for (uint32_t i = 0; i <= MAX_EXTRA_LAYERS; ++i) free(l->tangents[i]);
}

static dwv_result_t read_per_corner(const cJSON *item, const char *path, size_t per_triangle, uint32_t triangles,
                                    const char *what, float **out)
{
    size_t n = 0;
    DWV_TRY(dwvs_read_floats(item, path, per_triangle, &n, out));
    if (n != per_triangle * triangles) {
        free(*out);
        *out = NULL;
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "%zu numbers for %u triangles: %s per triangle corner", n,
                            triangles, what);
    }
    return DWV_SUCCESS;
}

static dwv_result_t read_mesh_layers(const cJSON *item, const char *path, uint32_t triangles, int has_uvs,
                                     mesh_layers *l)
{
    char p[PATH_SIZE];
    const cJSON *tangents = dwvs_member(item, "tangents");
    if (tangents) {
        dwvs_path_key(p, path, "tangents");
        if (!has_uvs) return dwvs_fail_at(DWV_ERROR_FORMAT, p, "tangents need the mesh's UVs");
        DWV_TRY(read_per_corner(tangents, p, 12u, triangles, "4 (x, y, z, sign)", &l->tangents[0]));
    }
    const cJSON *layers = dwvs_member(item, "uv_layers");
    if (!layers) return DWV_SUCCESS;
    char q[PATH_SIZE];
    dwvs_path_key(q, path, "uv_layers");
    if (!cJSON_IsArray(layers))
        return dwvs_fail_at(DWV_ERROR_FORMAT, q, "expected an array of UV layers, found %s", dwvs_type_name(layers));
    if (!has_uvs) return dwvs_fail_at(DWV_ERROR_FORMAT, q, "extra UV layers need the mesh's first ('uvs')");
    static const char *const keys[] = {"name", "uvs", "tangents"};
    size_t index = 0;
    for (const cJSON *e = layers->child; e; e = e->next, ++index) {
        dwvs_path_index(p, q, index);
        if (index >= MAX_EXTRA_LAYERS)
            return dwvs_fail_at(DWV_ERROR_OUT_OF_RANGE, p, "a mesh has at most %u extra UV layers", MAX_EXTRA_LAYERS);
        if (!cJSON_IsObject(e)) return dwvs_fail_at(DWV_ERROR_FORMAT, p, "expected an object, found %s", dwvs_type_name(e));
        DWV_TRY(dwvs_check_keys(e, p, keys, 3));
        char r[PATH_SIZE];
        if (!dwvs_member(e, "name") || !dwvs_member(e, "uvs"))
            return dwvs_fail_at(DWV_ERROR_FORMAT, p, "a UV layer needs 'name' and 'uvs'");
        dwvs_path_key(r, p, "name");
        DWV_TRY(dwvs_read_string(dwvs_member(e, "name"), r, &l->names[index + 1u]));
        dwvs_path_key(r, p, "uvs");
        DWV_TRY(read_per_corner(dwvs_member(e, "uvs"), r, 6u, triangles, "one (u, v)", &l->uvs[index]));
        l->count = (uint32_t)index + 1u;
        if (dwvs_member(e, "tangents")) {
            dwvs_path_key(r, p, "tangents");
            DWV_TRY(read_per_corner(dwvs_member(e, "tangents"), r, 12u, triangles, "4 (x, y, z, sign)",
                                    &l->tangents[index + 1u]));
        }
    }
    return DWV_SUCCESS;
}

/* Points `mesh` at the layers (names default to the numbers the C API gives when none is named). */
static void attach_layers(dwv_mesh_t *mesh, mesh_layers *l, const char *first_name)
{
    mesh->uv_layer_count = l->count;
    mesh->uv_layers = l->count ? (const float *const *)l->uvs : NULL;
    if (l->count || first_name) {
        static const char *const numbers[] = {"0"};
        l->names[0] = first_name ? first_name : numbers[0];
        mesh->uv_layer_names = l->names;
    }
    int any_tangents = 0;
    for (uint32_t i = 0; i <= l->count; ++i) any_tangents |= l->tangents[i] != NULL;
    mesh->tangents = any_tangents ? (const float *const *)l->tangents : NULL;
}

static dwv_result_t read_mesh(dwvs_parser *ps, const cJSON *item, const char *path, dwvs_named *record)
{
    static const char *const keys[] = {"name",    "material", "transform", "file", "positions",
                                       "indices", "normals",  "uvs",       "shadow_terminator_geometry_offset",
                                       "uv_name", "uv_layers", "tangents"};
    DWV_TRY(dwvs_check_keys(item, path, keys, sizeof keys / sizeof keys[0]));
    char p[PATH_SIZE], name[SHOWN_SIZE];
    const cJSON *name_item = dwvs_member(item, "name");
    record->name = NULL;
    if (name_item) {
        dwvs_path_key(p, path, "name");
        DWV_TRY(dwvs_read_string(name_item, p, &record->name));
    }

    const cJSON *material_item = dwvs_member(item, "material");
    if (!material_item) return dwvs_fail_at(DWV_ERROR_FORMAT, path, "missing key 'material'");
    const char *material_name = NULL;
    dwvs_path_key(p, path, "material");
    DWV_TRY(dwvs_read_string(material_item, p, &material_name));
    dwvs_named key = {material_name, 0u, 0u};
    const dwvs_named *material = ps->material_count
                                ? bsearch(&key, ps->materials, ps->material_count, sizeof key, dwvs_compare_named)
                                : NULL;
    if (!material) return dwvs_fail_at(DWV_ERROR_UNKNOWN_NAME, p, "unknown material '%s'", dwvs_shown(material_name, name));

    dwv_mesh_t mesh = DWV_MESH_INIT;
    mesh.material_id = material->id;
    memcpy(mesh.transform, identity, sizeof identity);
    DWV_TRY(dwvs_opt_transform(item, path, mesh.transform));
    DWV_TRY(dwvs_opt_number(item, path, "shadow_terminator_geometry_offset", &mesh.shadow_terminator_geometry_offset));
    /* The name of the mesh's UV layer, which texture bindings name ("Textures"). */
    const char *uv_name = NULL;
    if (dwvs_member(item, "uv_name")) {
        dwvs_path_key(p, path, "uv_name");
        DWV_TRY(dwvs_read_string(dwvs_member(item, "uv_name"), p, &uv_name));
    }
    mesh_layers layers;
    memset(&layers, 0, sizeof layers);

    const cJSON *file = dwvs_member(item, "file");
    int inline_data = dwvs_member(item, "positions") || dwvs_member(item, "indices") || dwvs_member(item, "normals") ||
                      dwvs_member(item, "uvs");
    if (file && inline_data)
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "give either 'file' or 'positions'/'indices'/'normals'/'uvs'");
    if (!file && !(dwvs_member(item, "positions") && dwvs_member(item, "indices")))
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "needs 'file', or 'positions' and 'indices'");

    dwv_result_t r;
    uint32_t mesh_id = 0;
    if (file) {
        const char *file_name = NULL;
        char resolved[MAX_FILE_PATH];
        dwvs_path_key(p, path, "file");
        DWV_TRY(dwvs_read_string(file, p, &file_name));
        DWV_TRY(dwvs_resolve_path(ps->base_dir, file_name, p, resolved));
        dwvs_mesh_data data;
        r = dwvs_mesh_file_read(resolved, &data);
        if (r != DWV_SUCCESS) return dwvs_prefix_capi(r, p);
        mesh.vertex_count = data.vertex_count;
        mesh.triangle_count = data.triangle_count;
        mesh.positions = data.positions;
        mesh.indices = data.indices;
        mesh.normals = data.normals;
        mesh.uvs = data.uvs;
        r = read_mesh_layers(item, path, mesh.triangle_count, data.uvs != NULL, &layers);
        attach_layers(&mesh, &layers, uv_name);
        if (r == DWV_SUCCESS) {
            r = dwv_scene_add_mesh(ps->scene, &mesh, &mesh_id);
            if (r != DWV_SUCCESS) {
                char where[PATH_SIZE + MAX_FILE_PATH / 16];
                snprintf(where, sizeof where, "%s ('%s')", path, dwvs_shown(file_name, name));
                r = dwvs_prefix_capi(r, where);
            }
        }
        record->has_uvs = data.uvs != NULL;
        dwvs_mesh_data_free(&data);
    } else {
        float *positions = NULL, *normals = NULL, *uvs = NULL;
        uint32_t *indices = NULL;
        size_t np = 0, ni = 0, nn = 0, nu = 0;
        dwvs_path_key(p, path, "positions");
        r = dwvs_read_floats(dwvs_member(item, "positions"), p, 3, &np, &positions);
        if (r == DWV_SUCCESS) {
            dwvs_path_key(p, path, "indices");
            r = read_indices(dwvs_member(item, "indices"), p, &ni, &indices);
        }
        if (r == DWV_SUCCESS && dwvs_member(item, "normals")) {
            dwvs_path_key(p, path, "normals");
            r = dwvs_read_floats(dwvs_member(item, "normals"), p, 3, &nn, &normals);
            if (r == DWV_SUCCESS && nn != np)
                r = dwvs_fail_at(DWV_ERROR_FORMAT, p, "%zu numbers for %zu positions: one normal per vertex", nn,
                                 np / 3u);
        }
        if (r == DWV_SUCCESS && dwvs_member(item, "uvs")) {
            dwvs_path_key(p, path, "uvs");
            r = dwvs_read_floats(dwvs_member(item, "uvs"), p, 2, &nu, &uvs);
            if (r == DWV_SUCCESS && nu != 2u * ni)
                r = dwvs_fail_at(DWV_ERROR_FORMAT, p, "%zu numbers for %zu triangles: one (u, v) per triangle corner",
                                 nu, ni / 3u);
        }
        if (r == DWV_SUCCESS) {
            mesh.vertex_count = (uint32_t)(np / 3u);
            mesh.triangle_count = (uint32_t)(ni / 3u);
            mesh.positions = positions;
            mesh.indices = indices;
            mesh.normals = normals;
            mesh.uvs = uvs;
            r = read_mesh_layers(item, path, mesh.triangle_count, uvs != NULL, &layers);
            attach_layers(&mesh, &layers, uv_name);
            if (r == DWV_SUCCESS) {
                r = dwv_scene_add_mesh(ps->scene, &mesh, &mesh_id);
                if (r != DWV_SUCCESS) r = dwvs_prefix_capi(r, path);
            }
        }
        record->has_uvs = uvs != NULL;
        free(positions);
        free(indices);
        free(normals);
        free(uvs);
    }
    mesh_layers_free(&layers);
    record->id = mesh_id;
    return r;
}

dwv_result_t dwvs_read_meshes(dwvs_parser *ps, const cJSON *item)
{
    if (!cJSON_IsArray(item))
        return dwvs_fail_at(DWV_ERROR_FORMAT, "meshes", "expected an array of meshes, found %s", dwvs_type_name(item));
    size_t n = 0;
    for (const cJSON *c = item->child; c; c = c->next) ++n;
    ps->meshes = calloc(n ? n : 1u, sizeof *ps->meshes);
    if (!ps->meshes) return dwvs_fail_at(DWV_ERROR_OUT_OF_MEMORY, "meshes", "no memory for %zu meshes", n);
    size_t i = 0;
    for (const cJSON *c = item->child; c; c = c->next, ++i) {
        char p[PATH_SIZE];
        dwvs_path_index(p, "meshes", i);
        DWV_TRY(read_mesh(ps, c, p, &ps->meshes[i]));
        ps->mesh_count = i + 1;
    }
    /* Names must be unique (a UV bake picks a mesh by name). */
    dwvs_named *sorted = malloc((n ? n : 1u) * sizeof *sorted);
    if (!sorted) return dwvs_fail_at(DWV_ERROR_OUT_OF_MEMORY, "meshes", "no memory for %zu names", n);
    size_t k = 0;
    for (size_t j = 0; j < ps->mesh_count; ++j)
        if (ps->meshes[j].name) sorted[k++] = ps->meshes[j];
    qsort(sorted, k, sizeof *sorted, dwvs_compare_named);
    dwv_result_t r = DWV_SUCCESS;
    for (size_t j = 1; j < k && r == DWV_SUCCESS; ++j)
        if (strcmp(sorted[j - 1].name, sorted[j].name) == 0) {
            char name[SHOWN_SIZE];
            r = dwvs_fail_at(DWV_ERROR_FORMAT, "meshes", "the name '%s' is given to two meshes", dwvs_shown(sorted[j].name, name));
        }
    free(sorted);
    return r;
}
