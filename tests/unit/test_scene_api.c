/* The scene-building calls: every refused input gets its own code and a message, arrays are
 * copied (the caller may free them), and a committed scene refuses changes. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "api_checks.h"
#include "check.h"
#include <dwivedi.h>

static const float tetra_positions[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
static const uint32_t tetra_indices[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};

#define EXPECT(call, code, keyword)                                                                     \
    do {                                                                                                \
        prime_message();                                                                                \
        dwv_result_t r_ = (call);                                                                       \
        CHECK(r_ == (code), "%s gave %d (%s), wanted %d", #call, (int)r_, dwv_last_error_message(), (int)(code)); \
        CHECK(fresh_message_with(keyword), "%s: message \"%s\" lacks \"%s\"", #call, dwv_last_error_message(), \
              keyword);                                                                                 \
    } while (0)

static dwv_mesh_t tetra(uint32_t material)
{
    dwv_mesh_t mesh = DWV_MESH_INIT;
    mesh.vertex_count = 4;
    mesh.triangle_count = 4;
    mesh.material_id = material;
    mesh.positions = tetra_positions;
    mesh.indices = tetra_indices;
    return mesh;
}

static void test_lifecycle(void)
{
    dwv_scene_t *scene = NULL;
    EXPECT(dwv_scene_create(NULL), DWV_ERROR_NULL_POINTER, "scene");
    CHECK(dwv_scene_create(&scene) == DWV_SUCCESS && scene, "create: %s", dwv_last_error_message());
    CHECK(dwv_scene_retain(scene) == DWV_SUCCESS, "retain");
    dwv_scene_release(scene); /* back to one reference: still usable */
    uint32_t id = 99;
    dwv_material_t material = DWV_MATERIAL_INIT;
    CHECK(dwv_scene_add_material(scene, &material, &id) == DWV_SUCCESS && id == 0, "material id %u", id);
    CHECK(dwv_scene_add_material(scene, &material, &id) == DWV_SUCCESS && id == 1, "material id %u", id);
    dwv_mesh_t mesh = tetra(1);
    CHECK(dwv_scene_add_mesh(scene, &mesh, &id) == DWV_SUCCESS && id == 0, "mesh id %u: %s", id,
          dwv_last_error_message());
    dwv_light_desc_t light = DWV_LIGHT_DESC_INIT;
    CHECK(dwv_scene_add_light(scene, &light) == DWV_SUCCESS, "sun: %s", dwv_last_error_message());
    double white[3] = {1, 1, 1};
    CHECK(dwv_scene_set_world(scene, white, 0.5) == DWV_SUCCESS, "world");
    dwv_camera_t camera = DWV_CAMERA_INIT;
    CHECK(dwv_scene_set_camera(scene, &camera) == DWV_SUCCESS, "camera: %s", dwv_last_error_message());
    CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit: %s", dwv_last_error_message());
    EXPECT(dwv_scene_commit(scene), DWV_ERROR_INVALID_STATE, "committed");
    EXPECT(dwv_scene_add_material(scene, &material, &id), DWV_ERROR_INVALID_STATE, "committed");
    EXPECT(dwv_scene_add_mesh(scene, &mesh, &id), DWV_ERROR_INVALID_STATE, "committed");
    EXPECT(dwv_scene_add_light(scene, &light), DWV_ERROR_INVALID_STATE, "committed");
    EXPECT(dwv_scene_set_world(scene, white, 1.0), DWV_ERROR_INVALID_STATE, "committed");
    EXPECT(dwv_scene_set_camera(scene, &camera), DWV_ERROR_INVALID_STATE, "committed");
    dwv_scene_release(scene);
    dwv_scene_release(NULL);
    EXPECT(dwv_scene_retain(NULL), DWV_ERROR_NULL_POINTER, "scene");
    EXPECT(dwv_scene_commit(NULL), DWV_ERROR_NULL_POINTER, "scene");
}

static void test_materials(dwv_scene_t *scene)
{
    uint32_t id;
    dwv_material_t m = DWV_MATERIAL_INIT;
    EXPECT(dwv_scene_add_material(NULL, &m, &id), DWV_ERROR_NULL_POINTER, "scene");
    EXPECT(dwv_scene_add_material(scene, NULL, &id), DWV_ERROR_NULL_POINTER, "material");
    EXPECT(dwv_scene_add_material(scene, &m, NULL), DWV_ERROR_NULL_POINTER, "material_id");
    m.struct_size = 8;
    EXPECT(dwv_scene_add_material(scene, &m, &id), DWV_ERROR_STRUCT_SIZE, "material");
    m = (dwv_material_t)DWV_MATERIAL_INIT;
    m.kind = 7;
    EXPECT(dwv_scene_add_material(scene, &m, &id), DWV_ERROR_INVALID_ARGUMENT, "kind");
    m = (dwv_material_t)DWV_MATERIAL_INIT;
    m.base_color[1] = NAN;
    EXPECT(dwv_scene_add_material(scene, &m, &id), DWV_ERROR_INVALID_ARGUMENT, "base_color[1]");
    m = (dwv_material_t)DWV_MATERIAL_INIT;
    m.subsurface_color[2] = 1.5;
    EXPECT(dwv_scene_add_material(scene, &m, &id), DWV_ERROR_OUT_OF_RANGE, "subsurface_color[2]");
    m = (dwv_material_t)DWV_MATERIAL_INIT;
    m.subsurface_radius[0] = -1.0;
    EXPECT(dwv_scene_add_material(scene, &m, &id), DWV_ERROR_OUT_OF_RANGE, "subsurface_radius[0]");
    m = (dwv_material_t)DWV_MATERIAL_INIT;
    m.subsurface_radius[0] = INFINITY;
    EXPECT(dwv_scene_add_material(scene, &m, &id), DWV_ERROR_INVALID_ARGUMENT, "subsurface_radius[0]");
    m = (dwv_material_t)DWV_MATERIAL_INIT;
    m.subsurface_weight = 1.01;
    EXPECT(dwv_scene_add_material(scene, &m, &id), DWV_ERROR_OUT_OF_RANGE, "subsurface_weight");
    m = (dwv_material_t)DWV_MATERIAL_INIT;
    m.subsurface_anisotropy = 1.0;
    EXPECT(dwv_scene_add_material(scene, &m, &id), DWV_ERROR_OUT_OF_RANGE, "anisotropy");
    m = (dwv_material_t)DWV_MATERIAL_INIT;
    m.subsurface_ior = 0.5;
    EXPECT(dwv_scene_add_material(scene, &m, &id), DWV_ERROR_OUT_OF_RANGE, "subsurface_ior");
    m = (dwv_material_t)DWV_MATERIAL_INIT;
    m.subsurface_scale = -0.1;
    EXPECT(dwv_scene_add_material(scene, &m, &id), DWV_ERROR_OUT_OF_RANGE, "subsurface_scale");
    m = (dwv_material_t)DWV_MATERIAL_INIT;
    m.subsurface_exit = 2;
    EXPECT(dwv_scene_add_material(scene, &m, &id), DWV_ERROR_INVALID_ARGUMENT, "subsurface_exit");
    m = (dwv_material_t)DWV_MATERIAL_INIT;
    m.roughness = NAN;
    EXPECT(dwv_scene_add_material(scene, &m, &id), DWV_ERROR_INVALID_ARGUMENT, "roughness");
    m.roughness = 1.5;
    EXPECT(dwv_scene_add_material(scene, &m, &id), DWV_ERROR_OUT_OF_RANGE, "roughness");
    /* A 0.1.0 caller's struct ends at subsurface_ior: accepted, and what lies beyond its
     * struct_size (here garbage) is never read. */
    m = (dwv_material_t)DWV_MATERIAL_INIT;
    m.struct_size = (uint32_t)offsetof(dwv_material_t, subsurface_exit);
    m.subsurface_exit = 99;
    m.roughness = NAN;
    uint32_t old_id = 12345u;
    CHECK(dwv_scene_add_material(scene, &m, &old_id) == DWV_SUCCESS && old_id != 12345u, "a 0.1.0-sized material: %s",
          dwv_last_error_message());
    m.struct_size = (uint32_t)offsetof(dwv_material_t, subsurface_exit) - 8u;
    EXPECT(dwv_scene_add_material(scene, &m, &id), DWV_ERROR_STRUCT_SIZE, "material");
}

static void test_meshes(dwv_scene_t *scene)
{
    uint32_t id;
    dwv_mesh_t m = tetra(0);
    EXPECT(dwv_scene_add_mesh(NULL, &m, &id), DWV_ERROR_NULL_POINTER, "scene");
    EXPECT(dwv_scene_add_mesh(scene, NULL, &id), DWV_ERROR_NULL_POINTER, "mesh");
    EXPECT(dwv_scene_add_mesh(scene, &m, NULL), DWV_ERROR_NULL_POINTER, "mesh_id");
    m.struct_size = (uint32_t)offsetof(dwv_mesh_t, shadow_terminator_geometry_offset) - 8u;
    EXPECT(dwv_scene_add_mesh(scene, &m, &id), DWV_ERROR_STRUCT_SIZE, "mesh");
    /* A 0.1.0 caller's struct ends at transform: accepted, and what lies beyond its struct_size
     * (here garbage) is never read. */
    m = tetra(0);
    m.struct_size = (uint32_t)offsetof(dwv_mesh_t, shadow_terminator_geometry_offset);
    m.shadow_terminator_geometry_offset = NAN;
    uint32_t old_id = 12345u;
    CHECK(dwv_scene_add_mesh(scene, &m, &old_id) == DWV_SUCCESS && old_id != 12345u, "a 0.1.0-sized mesh: %s",
          dwv_last_error_message());
    m = tetra(0);
    CHECK(m.shadow_terminator_geometry_offset == 0.1, "DWV_MESH_INIT's geometry offset is Cycles' default 0.1");
    m.shadow_terminator_geometry_offset = NAN;
    EXPECT(dwv_scene_add_mesh(scene, &m, &id), DWV_ERROR_INVALID_ARGUMENT, "shadow_terminator_geometry_offset");
    m.shadow_terminator_geometry_offset = -0.1;
    EXPECT(dwv_scene_add_mesh(scene, &m, &id), DWV_ERROR_OUT_OF_RANGE, "shadow_terminator_geometry_offset");
    m.shadow_terminator_geometry_offset = 0.0;
    CHECK(dwv_scene_add_mesh(scene, &m, &id) == DWV_SUCCESS, "geometry offset 0: %s", dwv_last_error_message());
    m = tetra(0);
    m.positions = NULL;
    EXPECT(dwv_scene_add_mesh(scene, &m, &id), DWV_ERROR_NULL_POINTER, "positions");
    m = tetra(0);
    m.indices = NULL;
    EXPECT(dwv_scene_add_mesh(scene, &m, &id), DWV_ERROR_NULL_POINTER, "indices");
    m = tetra(5);
    EXPECT(dwv_scene_add_mesh(scene, &m, &id), DWV_ERROR_OUT_OF_RANGE, "material_id");
    /* Absurd sizes are refused before the (short) arrays are read or anything is allocated. */
    m = tetra(0);
    m.triangle_count = (1u << 28) + 1u;
    EXPECT(dwv_scene_add_mesh(scene, &m, &id), DWV_ERROR_OUT_OF_RANGE, "triangle_count");
    m = tetra(0);
    m.vertex_count = 0xffffffffu;
    EXPECT(dwv_scene_add_mesh(scene, &m, &id), DWV_ERROR_OUT_OF_RANGE, "vertex_count");
    m = tetra(0);
    m.vertex_count = 2;
    EXPECT(dwv_scene_add_mesh(scene, &m, &id), DWV_ERROR_OUT_OF_RANGE, "vertex_count");
    m = tetra(0);
    m.triangle_count = 0;
    EXPECT(dwv_scene_add_mesh(scene, &m, &id), DWV_ERROR_OUT_OF_RANGE, "triangle_count");
    uint32_t bad_indices[12];
    memcpy(bad_indices, tetra_indices, sizeof bad_indices);
    bad_indices[7] = 4;
    m = tetra(0);
    m.indices = bad_indices;
    EXPECT(dwv_scene_add_mesh(scene, &m, &id), DWV_ERROR_OUT_OF_RANGE, "indices[7]");
    float bad_positions[12];
    memcpy(bad_positions, tetra_positions, sizeof bad_positions);
    bad_positions[5] = NAN;
    m = tetra(0);
    m.positions = bad_positions;
    EXPECT(dwv_scene_add_mesh(scene, &m, &id), DWV_ERROR_INVALID_ARGUMENT, "positions[5]");
    bad_positions[5] = INFINITY;
    EXPECT(dwv_scene_add_mesh(scene, &m, &id), DWV_ERROR_INVALID_ARGUMENT, "positions[5]");
    float normals[12] = {0, 0, -1, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    normals[10] = NAN;
    m = tetra(0);
    m.normals = normals;
    EXPECT(dwv_scene_add_mesh(scene, &m, &id), DWV_ERROR_INVALID_ARGUMENT, "normals[10]");
    float uvs[24] = {0};
    uvs[23] = INFINITY;
    m = tetra(0);
    m.uvs = uvs;
    EXPECT(dwv_scene_add_mesh(scene, &m, &id), DWV_ERROR_INVALID_ARGUMENT, "uvs[23]");
    m = tetra(0);
    m.transform[0] = 0.0;
    m.transform[5] = 0.0; /* rank 1: singular */
    EXPECT(dwv_scene_add_mesh(scene, &m, &id), DWV_ERROR_INVALID_ARGUMENT, "singular");
    m = tetra(0);
    m.transform[3] = NAN;
    EXPECT(dwv_scene_add_mesh(scene, &m, &id), DWV_ERROR_INVALID_ARGUMENT, "transform[3]");
    /* Copies: the caller's arrays may change or go after the call. */
    float *positions = malloc(sizeof tetra_positions);
    uint32_t *indices = malloc(sizeof tetra_indices);
    memcpy(positions, tetra_positions, sizeof tetra_positions);
    memcpy(indices, tetra_indices, sizeof tetra_indices);
    m = tetra(0);
    m.positions = positions;
    m.indices = indices;
    m.transform[0] = -2.0; /* mirroring and scaling are allowed */
    CHECK(dwv_scene_add_mesh(scene, &m, &id) == DWV_SUCCESS, "mirrored mesh: %s", dwv_last_error_message());
    free(positions);
    free(indices);
}

static void test_lights(dwv_scene_t *scene)
{
    dwv_light_desc_t l = DWV_LIGHT_DESC_INIT;
    EXPECT(dwv_scene_add_light(NULL, &l), DWV_ERROR_NULL_POINTER, "scene");
    EXPECT(dwv_scene_add_light(scene, NULL), DWV_ERROR_NULL_POINTER, "light");
    l.struct_size = 4;
    EXPECT(dwv_scene_add_light(scene, &l), DWV_ERROR_STRUCT_SIZE, "light");
    l = (dwv_light_desc_t)DWV_LIGHT_DESC_INIT;
    l.kind = 5; /* 4 is DWV_LIGHT_SPOT */
    EXPECT(dwv_scene_add_light(scene, &l), DWV_ERROR_INVALID_ARGUMENT, "kind");
    l = (dwv_light_desc_t)DWV_LIGHT_DESC_INIT;
    l.direction[0] = l.direction[1] = l.direction[2] = 0.0;
    EXPECT(dwv_scene_add_light(scene, &l), DWV_ERROR_INVALID_ARGUMENT, "direction");
    l = (dwv_light_desc_t)DWV_LIGHT_DESC_INIT;
    l.angle = 4.0;
    EXPECT(dwv_scene_add_light(scene, &l), DWV_ERROR_OUT_OF_RANGE, "angle");
    l = (dwv_light_desc_t)DWV_LIGHT_DESC_INIT;
    l.strength = -1.0;
    EXPECT(dwv_scene_add_light(scene, &l), DWV_ERROR_OUT_OF_RANGE, "strength");
    l = (dwv_light_desc_t)DWV_LIGHT_DESC_INIT;
    l.color[1] = NAN;
    EXPECT(dwv_scene_add_light(scene, &l), DWV_ERROR_INVALID_ARGUMENT, "color[1]");
    l = (dwv_light_desc_t)DWV_LIGHT_DESC_INIT;
    l.kind = DWV_LIGHT_POINT;
    l.radius = -0.5;
    EXPECT(dwv_scene_add_light(scene, &l), DWV_ERROR_OUT_OF_RANGE, "radius");
    l.radius = 0.1;
    l.position[2] = INFINITY;
    EXPECT(dwv_scene_add_light(scene, &l), DWV_ERROR_INVALID_ARGUMENT, "position[2]");
    l = (dwv_light_desc_t)DWV_LIGHT_DESC_INIT;
    l.kind = DWV_LIGHT_AREA_RECTANGLE;
    l.size_y = 0.0;
    EXPECT(dwv_scene_add_light(scene, &l), DWV_ERROR_OUT_OF_RANGE, "size_y");
    l.size_y = 1.0;
    l.transform[1] = 0.5; /* shear: x and y axes not orthogonal */
    EXPECT(dwv_scene_add_light(scene, &l), DWV_ERROR_INVALID_ARGUMENT, "shear");
    l = (dwv_light_desc_t)DWV_LIGHT_DESC_INIT;
    l.kind = DWV_LIGHT_AREA_DISK;
    CHECK(dwv_scene_add_light(scene, &l) == DWV_SUCCESS, "disk: %s", dwv_last_error_message());
    l.kind = DWV_LIGHT_POINT;
    CHECK(dwv_scene_add_light(scene, &l) == DWV_SUCCESS, "point: %s", dwv_last_error_message());
}

static void test_world_and_camera(dwv_scene_t *scene)
{
    double color[3] = {1, 1, 1};
    EXPECT(dwv_scene_set_world(NULL, color, 1.0), DWV_ERROR_NULL_POINTER, "scene");
    EXPECT(dwv_scene_set_world(scene, NULL, 1.0), DWV_ERROR_NULL_POINTER, "color");
    EXPECT(dwv_scene_set_world(scene, color, NAN), DWV_ERROR_INVALID_ARGUMENT, "strength");
    EXPECT(dwv_scene_set_world(scene, color, -1.0), DWV_ERROR_OUT_OF_RANGE, "strength");
    color[2] = 1e300;
    EXPECT(dwv_scene_set_world(scene, color, 1e300), DWV_ERROR_OUT_OF_RANGE, "overflows");
    dwv_camera_t c = DWV_CAMERA_INIT;
    EXPECT(dwv_scene_set_camera(NULL, &c), DWV_ERROR_NULL_POINTER, "scene");
    EXPECT(dwv_scene_set_camera(scene, NULL), DWV_ERROR_NULL_POINTER, "camera");
    c.struct_size = 4;
    EXPECT(dwv_scene_set_camera(scene, &c), DWV_ERROR_STRUCT_SIZE, "camera");
    c = (dwv_camera_t)DWV_CAMERA_INIT;
    c.kind = 2;
    EXPECT(dwv_scene_set_camera(scene, &c), DWV_ERROR_INVALID_ARGUMENT, "kind");
    c = (dwv_camera_t)DWV_CAMERA_INIT;
    c.focal_length = 0.0;
    EXPECT(dwv_scene_set_camera(scene, &c), DWV_ERROR_OUT_OF_RANGE, "focal_length");
    c = (dwv_camera_t)DWV_CAMERA_INIT;
    c.kind = DWV_CAMERA_ORTHOGRAPHIC;
    c.ortho_scale = -1.0;
    EXPECT(dwv_scene_set_camera(scene, &c), DWV_ERROR_OUT_OF_RANGE, "ortho_scale");
    c = (dwv_camera_t)DWV_CAMERA_INIT;
    c.transform[0] = 2.0; /* scaled: not a rotation */
    EXPECT(dwv_scene_set_camera(scene, &c), DWV_ERROR_INVALID_ARGUMENT, "rotation");
    c = (dwv_camera_t)DWV_CAMERA_INIT;
    c.transform[0] = -1.0; /* mirrored */
    EXPECT(dwv_scene_set_camera(scene, &c), DWV_ERROR_INVALID_ARGUMENT, "mirrors");
}

int main(void)
{
    test_lifecycle();
    dwv_scene_t *scene = NULL;
    CHECK(dwv_scene_create(&scene) == DWV_SUCCESS, "create");
    uint32_t id;
    dwv_material_t material = DWV_MATERIAL_INIT;
    CHECK(dwv_scene_add_material(scene, &material, &id) == DWV_SUCCESS, "material");
    test_materials(scene);
    test_meshes(scene);
    test_lights(scene);
    test_world_and_camera(scene);
    CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit: %s", dwv_last_error_message());
    dwv_scene_release(scene);
    return check_report("test_scene_api");
}
