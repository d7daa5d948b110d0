/* libFuzzer target: a triangle mesh made of arbitrary bytes, through dwv_scene_add_mesh, commit
 * and a tiny bake (camera or UV). Positions, normals, UVs and the transform's scale are raw floats
 * from the input (NaN, infinities, 1e38, subnormals all reach the library); indices are raw too
 * (out of range ones must be refused). Required: a refusal returns an error code with a message
 * and hands out nothing; an accepted mesh commits and bakes to an image whose every pixel and
 * variance is finite, and whose warnings count what it met; no crash, hang or leak.
 * Input layout (short inputs are padded with zeros):
 *   byte 0: vertex count - 3 (mod 13: 3 to 15)    byte 1: triangle count - 1 (mod 16: 1 to 16)
 *   byte 2: bit 0 normals, bit 1 UVs, bit 2 UV bake, bit 3 perspective camera, bit 4 diffuse
 *   byte 3: transform: bits 0-5 a power of two scale 2^(b - 32), bit 6 mirror x
 *   then 3 floats per vertex, 3 indices (uint8) per triangle, 3 normal floats per vertex, 6 UV
 *   floats per triangle. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <dwivedi.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

typedef struct reader {
    const uint8_t *data;
    size_t size, at;
} reader;

static uint8_t byte(reader *r)
{
    return r->at < r->size ? r->data[r->at++] : 0u;
}

static float raw_float(reader *r)
{
    uint8_t b[4] = {byte(r), byte(r), byte(r), byte(r)};
    float f;
    memcpy(&f, b, sizeof f);
    return f;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader r = {data, size, 0u};
    uint32_t nv = 3u + byte(&r) % 13u, nt = 1u + byte(&r) % 16u;
    uint8_t flags = byte(&r), shape = byte(&r);
    float positions[3 * 15], normals[3 * 15], uvs[6 * 16];
    uint32_t indices[3 * 16];
    for (uint32_t i = 0; i < 3u * nv; ++i) positions[i] = raw_float(&r);
    for (uint32_t i = 0; i < 3u * nt; ++i) indices[i] = byte(&r);
    for (uint32_t i = 0; i < 3u * nv; ++i) normals[i] = raw_float(&r);
    for (uint32_t i = 0; i < 6u * nt; ++i) uvs[i] = raw_float(&r);

    dwv_scene_t *scene = NULL;
    if (dwv_scene_create(&scene) != DWV_SUCCESS) __builtin_trap();
    dwv_material_t material = DWV_MATERIAL_INIT;
    if (flags & 16u) material.kind = DWV_MATERIAL_DIFFUSE;
    uint32_t material_id = 0, mesh_id = UINT32_MAX;
    if (dwv_scene_add_material(scene, &material, &material_id) != DWV_SUCCESS) __builtin_trap();
    dwv_mesh_t mesh = DWV_MESH_INIT;
    mesh.vertex_count = nv;
    mesh.triangle_count = nt;
    mesh.material_id = material_id;
    mesh.positions = positions;
    mesh.indices = indices;
    mesh.normals = flags & 1u ? normals : NULL;
    mesh.uvs = flags & 2u ? uvs : NULL;
    double scale = ldexp(1.0, (int)(shape & 63u) - 32);
    mesh.transform[0] = shape & 64u ? -scale : scale;
    mesh.transform[5] = mesh.transform[10] = scale;
    dwv_result_t added = dwv_scene_add_mesh(scene, &mesh, &mesh_id);
    if (added != DWV_SUCCESS) {
        const char *message = dwv_last_error_message();
        if (mesh_id != UINT32_MAX || !message[0] || strlen(message) >= 512u) __builtin_trap();
        dwv_scene_release(scene);
        return 0;
    }
    double white[3] = {1.0, 1.0, 1.0};
    dwv_camera_t camera = DWV_CAMERA_INIT;
    camera.kind = flags & 8u ? DWV_CAMERA_PERSPECTIVE : DWV_CAMERA_ORTHOGRAPHIC;
    camera.transform[11] = 4.0;
    camera.ortho_scale = 4.0;
    dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
    if (dwv_scene_set_world(scene, white, 0.5) || dwv_scene_set_camera(scene, &camera) ||
        dwv_scene_add_light(scene, &sun) || dwv_scene_commit(scene))
        __builtin_trap(); /* all valid: a mesh the scene accepted must not spoil its commit */
    dwv_bake_options_t options = DWV_BAKE_OPTIONS_INIT;
    options.width = options.height = 4u;
    options.samples = 2u;
    options.threads = 1u;
    options.max_events = 2000u;
    options.uv_margin = 1u;
    int uv = (flags & 4u) && mesh.uvs;
    if (uv) {
        options.target = DWV_BAKE_UV;
        options.uv_mesh = mesh_id;
    }
    dwv_image_t *image = NULL;
    if (dwv_bake(scene, &options, &image) != DWV_SUCCESS || !image) __builtin_trap();
    dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
    dwv_bake_stats_t stats = DWV_BAKE_STATS_INIT;
    if (dwv_image_info(image, &info) || dwv_image_stats(image, &stats)) __builtin_trap();
    for (uint32_t i = 0; i < 16u; ++i) {
        for (int c = 0; c < 4; ++c)
            if (!isfinite(info.rgba[4 * i + (uint32_t)c])) __builtin_trap();
        for (int c = 0; c < 3; ++c)
            if (!(info.variance[3 * i + (uint32_t)c] >= 0.0f) || !isfinite(info.variance[3 * i + (uint32_t)c]))
                __builtin_trap();
    }
    for (int c = 0; c < 3; ++c)
        if (!isfinite(stats.mean_rgb[c]) || !isfinite(stats.truncated_weight[c])) __builtin_trap();
    dwv_image_release(image);
    dwv_scene_release(scene);
    return 0;
}
