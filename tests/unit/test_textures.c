/* Textures through the public API: refused inputs (0 x 0, NaN and infinite texels, bad ids, a
 * colour input given one channel, a UV layer the mesh lacks, a second normal map), and bakes
 * whose answer is known: a diffuse quad under a sun of irradiance pi seen straight on is its
 * albedo, so a 2 x 2 texture bakes to its texels' mean, a constant normal map tilted by 30
 * degrees gives cos 30 of it (60 degrees: sqrt(0.505), Cycles' ensure_valid_reflection; at
 * Strength 1.5 the normal each Blender release's rule gives, 3.x's and 4.0+'s) and a
 * height ramp of slope s through a bump of distance d gives 1 / sqrt(1 + (d s)^2); and a subsurface slab whose colour texture is A on one half and B on
 * the other bakes each half as the slab of constant colour A or B does (the medium is the entry
 * point's: pixel differences within 5 standard errors, often bit-identical as the same numbers
 * drive the same walks), while the other colour is far off (the harness can fail). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bake_compare.h"
#include "bake_scenes.h"
#include "check.h"

#define NEAR_MEAN(x, y) (fabs((x) - (y)) < 1e-4)

static dwv_scene_t *new_scene(void)
{
    dwv_scene_t *scene = NULL;
    if (dwv_scene_create(&scene) != DWV_SUCCESS) exit(2);
    return scene;
}

/* A sun of irradiance pi straight down and an orthographic camera at z = 5 seeing [-1, 1]^2. */
static void sun_and_camera(dwv_scene_t *scene)
{
    dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
    sun.strength = 3.14159265358979323846;
    dwv_scene_add_light(scene, &sun);
    dwv_camera_t camera = DWV_CAMERA_INIT;
    camera.kind = DWV_CAMERA_ORTHOGRAPHIC;
    camera.transform[11] = 5.0;
    camera.ortho_scale = 2.0;
    dwv_scene_set_camera(scene, &camera);
}

/* The quad [-1, 1]^2 at z = 0 facing +z, u = (x + 1) / 2, v = (y + 1) / 2, seen from above by an
 * orthographic camera that fills the image with it, lit straight down by a sun of irradiance pi. */
static void quad_scene(dwv_scene_t *scene, uint32_t material_id, const char *const *names, uint32_t extra_layers,
                       const float *const *layers)
{
    static const float positions[13] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0, 0};
    static const uint32_t indices[6] = {0, 1, 2, 0, 2, 3};
    static const float uvs[12] = {0, 0, 1, 0, 1, 1, 0, 0, 1, 1, 0, 1};
    dwv_mesh_t mesh = DWV_MESH_INIT;
    mesh.vertex_count = 4, mesh.triangle_count = 2, mesh.material_id = material_id;
    mesh.positions = positions, mesh.indices = indices, mesh.uvs = uvs;
    mesh.uv_layer_count = extra_layers, mesh.uv_layers = layers, mesh.uv_layer_names = names;
    uint32_t id;
    CHECK(dwv_scene_add_mesh(scene, &mesh, &id) == DWV_SUCCESS, "quad: %s", dwv_last_error_message());
    sun_and_camera(scene);
}

static uint32_t add_texture(dwv_scene_t *scene, uint32_t w, uint32_t h, uint32_t channels, dwv_texture_interpolation_t interp,
                            dwv_texture_extension_t extension, const float *texels)
{
    dwv_texture_desc_t d = DWV_TEXTURE_DESC_INIT;
    d.width = w, d.height = h, d.channels = channels, d.interpolation = interp, d.extension = extension, d.texels = texels;
    uint32_t id = 0;
    CHECK(dwv_scene_add_texture(scene, &d, &id) == DWV_SUCCESS, "texture: %s", dwv_last_error_message());
    return id;
}

static uint32_t diffuse_material(dwv_scene_t *scene)
{
    dwv_material_t m = DWV_MATERIAL_INIT;
    m.kind = DWV_MATERIAL_DIFFUSE;
    uint32_t id;
    dwv_scene_add_material(scene, &m, &id);
    return id;
}

static void bind(dwv_scene_t *scene, uint32_t material, dwv_material_input_t input, uint32_t texture, double distance)
{
    dwv_texture_binding_t b = DWV_TEXTURE_BINDING_INIT;
    b.input = input, b.texture_id = texture, b.distance = distance;
    CHECK(dwv_scene_bind_texture(scene, material, &b) == DWV_SUCCESS, "bind: %s", dwv_last_error_message());
}

static test_result bake(dwv_scene_t *scene, uint32_t size, uint64_t samples)
{
    test_result r;
    memset(&r, 0, sizeof r);
    if (dwv_scene_commit(scene) != DWV_SUCCESS) {
        CHECK(0, "commit: %s", dwv_last_error_message());
        return r;
    }
    test_bake_result(scene, DWV_TECHNIQUE_AUTO, DWV_CHANNEL_WALKS_AUTO, size, samples, 7u, &r);
    return r;
}

static void refusals(void)
{
    dwv_scene_t *scene = new_scene();
    uint32_t material = diffuse_material(scene), id;
    float texels[12] = {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f};
    dwv_texture_desc_t d = DWV_TEXTURE_DESC_INIT;
    d.width = 0, d.height = 0, d.channels = 3, d.texels = texels;
    CHECK(dwv_scene_add_texture(scene, &d, &id) == DWV_ERROR_OUT_OF_RANGE &&
              strstr(dwv_last_error_message(), "0 x 0"), "0 x 0: %s", dwv_last_error_message());
    d.width = 2, d.height = 2, d.channels = 2;
    CHECK(dwv_scene_add_texture(scene, &d, &id) == DWV_ERROR_INVALID_ARGUMENT, "2 channels");
    d.channels = 3;
    texels[7] = NAN;
    CHECK(dwv_scene_add_texture(scene, &d, &id) == DWV_ERROR_INVALID_ARGUMENT &&
              strstr(dwv_last_error_message(), "texel (0, 1) channel 1 is NaN"), "NaN: %s", dwv_last_error_message());
    texels[7] = INFINITY;
    CHECK(dwv_scene_add_texture(scene, &d, &id) == DWV_ERROR_INVALID_ARGUMENT &&
              strstr(dwv_last_error_message(), "infinite"), "inf: %s", dwv_last_error_message());
    texels[7] = 0.5f;
    d.texels = NULL;
    CHECK(dwv_scene_add_texture(scene, &d, &id) == DWV_ERROR_NULL_POINTER, "no texels");
    d.texels = texels;
    d.extension = 7;
    CHECK(dwv_scene_add_texture(scene, &d, &id) == DWV_ERROR_INVALID_ARGUMENT, "extension 7");
    d.extension = DWV_EXTENSION_REPEAT;
    uint32_t colour = add_texture(scene, 2, 2, 3, DWV_INTERPOLATION_LINEAR, DWV_EXTENSION_REPEAT, texels);
    uint32_t grey = add_texture(scene, 2, 2, 1, DWV_INTERPOLATION_LINEAR, DWV_EXTENSION_REPEAT, texels);
    dwv_texture_binding_t b = DWV_TEXTURE_BINDING_INIT;
    b.texture_id = 9;
    CHECK(dwv_scene_bind_texture(scene, material, &b) == DWV_ERROR_OUT_OF_RANGE &&
              strstr(dwv_last_error_message(), "texture_id = 9"), "bad texture id: %s", dwv_last_error_message());
    b.texture_id = colour;
    CHECK(dwv_scene_bind_texture(scene, 5, &b) == DWV_ERROR_OUT_OF_RANGE, "bad material id");
    b.texture_id = grey;
    CHECK(dwv_scene_bind_texture(scene, material, &b) == DWV_ERROR_INVALID_ARGUMENT &&
              strstr(dwv_last_error_message(), "1 channel"), "mismatch: %s", dwv_last_error_message());
    b.input = DWV_INPUT_NORMAL_MAP;
    CHECK(dwv_scene_bind_texture(scene, material, &b) == DWV_ERROR_INVALID_ARGUMENT, "grey normal map");
    b.input = 42;
    CHECK(dwv_scene_bind_texture(scene, material, &b) == DWV_ERROR_INVALID_ARGUMENT, "input 42");
    b.input = DWV_INPUT_ROUGHNESS;
    b.blend = 1.5;
    CHECK(dwv_scene_bind_texture(scene, material, &b) == DWV_ERROR_OUT_OF_RANGE, "blend 1.5");
    b.blend = 1.0;
    b.input = DWV_INPUT_NORMAL_MAP;
    b.texture_id = colour;
    CHECK(dwv_scene_bind_texture(scene, material, &b) == DWV_SUCCESS, "normal map");
    CHECK(dwv_scene_bind_texture(scene, material, &b) == DWV_ERROR_INVALID_ARGUMENT &&
              strstr(dwv_last_error_message(), "already"), "second normal map: %s", dwv_last_error_message());
    b.input = DWV_INPUT_BASE_COLOR;
    b.uv_layer = "Detail";
    CHECK(dwv_scene_bind_texture(scene, material, &b) == DWV_SUCCESS, "named layer");
    /* The mesh has layers "UVMap" and "Other" only: the commit names the missing one. */
    static const float layer[12] = {0, 0, 1, 0, 1, 1, 0, 0, 1, 1, 0, 1};
    const float *layers[1] = {layer};
    const char *names[2] = {"UVMap", "Other"};
    quad_scene(scene, material, names, 1, layers);
    CHECK(dwv_scene_commit(scene) == DWV_ERROR_INVALID_ARGUMENT && strstr(dwv_last_error_message(), "\"Detail\""),
          "absent layer: %s", dwv_last_error_message());
    dwv_scene_release(scene);

    /* v2 specular: textured roughness accepted (v2_specular_textures bakes it); a mesh without
     * UVs for a textured material. */
    scene = new_scene();
    dwv_material_t m = DWV_MATERIAL_INIT;
    m.specular_model = DWV_SPECULAR_PRINCIPLED_V2;
    dwv_scene_add_material(scene, &m, &material);
    grey = add_texture(scene, 2, 2, 1, DWV_INTERPOLATION_LINEAR, DWV_EXTENSION_REPEAT, texels);
    b = (dwv_texture_binding_t)DWV_TEXTURE_BINDING_INIT;
    b.input = DWV_INPUT_ROUGHNESS, b.texture_id = grey;
    CHECK(dwv_scene_bind_texture(scene, material, &b) == DWV_SUCCESS, "v2 roughness: %s", dwv_last_error_message());
    b.input = DWV_INPUT_SUBSURFACE_SCALE;
    CHECK(dwv_scene_bind_texture(scene, material, &b) == DWV_SUCCESS, "scale: %s", dwv_last_error_message());
    test_mesh box = test_box(-1, -1, -1, 1, 1, 1);
    dwv_mesh_t mesh = DWV_MESH_INIT;
    mesh.vertex_count = box.vertex_count, mesh.triangle_count = box.triangle_count;
    mesh.positions = box.positions, mesh.indices = box.indices, mesh.material_id = material;
    CHECK(dwv_scene_add_mesh(scene, &mesh, &id) == DWV_SUCCESS, "box");
    CHECK(dwv_scene_commit(scene) == DWV_ERROR_INVALID_ARGUMENT && strstr(dwv_last_error_message(), "has no UVs"),
          "no UVs: %s", dwv_last_error_message());
    uint64_t bytes = 0, count = 0;
    CHECK(dwv_scene_texture_memory(scene, &bytes, &count) == DWV_SUCCESS && bytes == 16u && count == 4u,
          "memory %llu bytes for %llu texels", (unsigned long long)bytes, (unsigned long long)count);
    test_mesh_free(&box);
    dwv_scene_release(scene);
}

static void diffuse_bakes(void)
{
    /* Base colour from a 2 x 2 closest texture: red 0.2 0.4 / 0.6 0.8, mean 0.5. */
    dwv_scene_t *scene = new_scene();
    uint32_t material = diffuse_material(scene);
    const float grid[12] = {0.2f, 0.1f, 0.0f, 0.4f, 0.1f, 0.0f, 0.6f, 0.1f, 0.0f, 0.8f, 0.1f, 0.0f};
    uint32_t t = add_texture(scene, 2, 2, 3, DWV_INTERPOLATION_CLOSEST, DWV_EXTENSION_REPEAT, grid);
    bind(scene, material, DWV_INPUT_BASE_COLOR, t, 1.0);
    quad_scene(scene, material, NULL, 0, NULL);
    test_result r = bake(scene, 16, 2);
    CHECK(r.rgba && NEAR_MEAN(r.mean[0], 0.5) && NEAR_MEAN(r.mean[1], 0.1) && fabs(r.mean[2]) < 1e-9,
          "textured albedo mean %g %g %g (0.5 0.1 0)", r.mean[0], r.mean[1], r.mean[2]);
    /* The bottom-left pixel reads texel (0, 0), the top-right texel (1, 1) (row 0 at the top). */
    if (r.rgba) CHECK(fabs(r.rgba[4u * (15u * 16u)] - 0.2f) < 1e-4 && fabs(r.rgba[4u * 15u] - 0.8f) < 1e-4,
                      "corners %g %g", r.rgba[4u * (15u * 16u)], r.rgba[4u * 15u]);
    free(r.rgba);
    dwv_scene_release(scene);

    /* A constant normal map tilted 30 degrees toward +x: cos 30 of the albedo 0.8. Tilted 60
     * degrees, the view's mirror reflection would point below the surface (2 cos^2 60 - 1 < 0):
     * Cycles' ensure_valid_reflection turns the normal back until that reflection is 0.01 above
     * it, 2 z^2 - 1 = 0.01 for a view along the geometric normal, so z = sqrt(0.505). */
    const double tilts[2] = {3.14159265358979323846 / 6.0, 3.14159265358979323846 / 3.0};
    const double cosines[2] = {cos(tilts[0]), sqrt(0.505)};
    for (int k = 0; k < 2; ++k) {
        scene = new_scene();
        material = diffuse_material(scene);
        const float tilt[3] = {(float)(0.5 + 0.5 * sin(tilts[k])), 0.5f, (float)(0.5 + 0.5 * cos(tilts[k]))};
        t = add_texture(scene, 1, 1, 3, DWV_INTERPOLATION_LINEAR, DWV_EXTENSION_REPEAT, tilt);
        bind(scene, material, DWV_INPUT_NORMAL_MAP, t, 1.0);
        quad_scene(scene, material, NULL, 0, NULL);
        r = bake(scene, 8, 2);
        CHECK(r.rgba && fabs(r.mean[0] - 0.8 * cosines[k]) < 2e-4, "normal map tilted %g: %g (%g)", tilts[k], r.mean[0],
              0.8 * cosines[k]);
        free(r.rgba);
        dwv_scene_release(scene);
    }

    /* Strength 1.5 of that 30-degree map (M = (sin 30, 0, cos 30) in the quad's frame), by each
     * release's rule (Cycles' svm_node_normal_map): 3.x extrapolates in world space,
     * normalize(n + 1.5 (M - n)); 4.0+ (Cycles d71e0f45d) scales the map's tangent part,
     * normalize(1.5 sin 30, 0, cos 30). The sun along n is at 0 degrees from the smooth normal:
     * no bump shadowing term dims it (Chiang's g >= 1, Conty's tan theta_i = 0). */
    const dwv_bump_shadowing_t releases[3] = {DWV_BUMP_SHADOWING_CHIANG2019, DWV_BUMP_SHADOWING_CHIANG2019_MAPPED,
                                              DWV_BUMP_SHADOWING_CONTY2019};
    const double sx = 1.5 * sin(tilts[0]), world_z = 1.0 + 1.5 * (cos(tilts[0]) - 1.0), tangent_z = cos(tilts[0]);
    const double strengthened[3] = {world_z / hypot(sx, world_z), tangent_z / hypot(sx, tangent_z),
                                    tangent_z / hypot(sx, tangent_z)};
    for (int k = 0; k < 3; ++k) {
        scene = new_scene();
        material = diffuse_material(scene);
        const float tilt[3] = {(float)(0.5 + 0.5 * sin(tilts[0])), 0.5f, (float)(0.5 + 0.5 * cos(tilts[0]))};
        t = add_texture(scene, 1, 1, 3, DWV_INTERPOLATION_LINEAR, DWV_EXTENSION_REPEAT, tilt);
        dwv_texture_binding_t b = DWV_TEXTURE_BINDING_INIT;
        b.input = DWV_INPUT_NORMAL_MAP, b.texture_id = t, b.strength = 1.5, b.bump_shadowing = releases[k];
        CHECK(dwv_scene_bind_texture(scene, material, &b) == DWV_SUCCESS, "bind: %s", dwv_last_error_message());
        quad_scene(scene, material, NULL, 0, NULL);
        r = bake(scene, 8, 2);
        CHECK(r.rgba && fabs(r.mean[0] - 0.8 * strengthened[k]) < 2e-4, "normal map strength 1.5, bump shadowing %d: %g (%g)",
              (int)releases[k], r.mean[0], 0.8 * strengthened[k]);
        free(r.rgba);
        dwv_scene_release(scene);
    }

    /* A height ramp h = u (texel centres (i + 1/2) / 64, linear, extend): slope 1/2 per unit x;
     * distance 1 makes grad h d = 1/2 along x: cos = 1 / sqrt(1.25). */
    scene = new_scene();
    material = diffuse_material(scene);
    float height[64];
    for (int i = 0; i < 64; ++i) height[i] = (float)((i + 0.5) / 64.0);
    t = add_texture(scene, 64, 1, 1, DWV_INTERPOLATION_LINEAR, DWV_EXTENSION_EXTEND, height);
    bind(scene, material, DWV_INPUT_BUMP, t, 1.0);
    quad_scene(scene, material, NULL, 0, NULL);
    r = bake(scene, 16, 2);
    /* Within half a texel of either edge (1/64 of the quad) the interpolated height is flat. */
    double flat = 1.0 / 64.0, expected = 0.8 * ((1.0 - flat) / sqrt(1.25) + flat);
    CHECK(r.rgba && fabs(r.mean[0] - expected) < 1e-3, "bump %g (%g)", r.mean[0], expected);
    free(r.rgba);
    dwv_scene_release(scene);
}

/* A slab [-1, 1]^2 x [-0.5, 0] with UVs projected from above, colour A (or B, or a texture of A on
 * u < 1/2 and B on u >= 1/2), seen from above under the sun. */
static test_result slab(const double colour[3], const float *texture_rgb)
{
    dwv_scene_t *scene = new_scene();
    dwv_material_t m = DWV_MATERIAL_INIT;
    for (int c = 0; c < 3; ++c) m.subsurface_color[c] = colour[c], m.subsurface_radius[c] = 0.3;
    m.subsurface_scale = 1.0;
    uint32_t material;
    dwv_scene_add_material(scene, &m, &material);
    if (texture_rgb) {
        uint32_t t = add_texture(scene, 2, 1, 3, DWV_INTERPOLATION_CLOSEST, DWV_EXTENSION_EXTEND, texture_rgb);
        bind(scene, material, DWV_INPUT_SUBSURFACE_COLOR, t, 1.0);
    }
    test_mesh box = test_box(-1, -1, -0.5, 1, 1, 0);
    for (uint32_t f = 0; f < box.triangle_count; ++f)
        for (int k = 0; k < 3; ++k) {
            uint32_t v = box.indices[3 * f + (uint32_t)k];
            box.uvs[6 * f + 2 * (uint32_t)k] = (box.positions[3 * v] + 1.0f) / 2.0f;
            box.uvs[6 * f + 2 * (uint32_t)k + 1] = (box.positions[3 * v + 1] + 1.0f) / 2.0f;
        }
    dwv_mesh_t mesh = DWV_MESH_INIT;
    mesh.vertex_count = box.vertex_count, mesh.triangle_count = box.triangle_count;
    mesh.positions = box.positions, mesh.indices = box.indices, mesh.uvs = box.uvs, mesh.material_id = material;
    uint32_t id;
    dwv_scene_add_mesh(scene, &mesh, &id);
    test_mesh_free(&box);
    sun_and_camera(scene);
    test_result r = bake(scene, 16, 32);
    dwv_scene_release(scene);
    return r;
}

/* The mean of pixel differences p - q of channel c over the columns [x0, x1) of two 16-pixel-wide
 * results, and its standard error from the differences' spread (paired: both images have the
 * same structure, so only the noise is left in the differences). */
static void paired_difference(const test_result *p, const test_result *q, int c, uint32_t x0, uint32_t x1,
                              double *mean, double *error)
{
    double sum = 0.0, sum2 = 0.0;
    uint32_t n = 0;
    for (uint32_t y = 0; y < 16; ++y)
        for (uint32_t x = x0; x < x1; ++x, ++n) {
            size_t i = 4u * (16u * y + x) + (uint32_t)c;
            double d = (double)p->rgba[i] - q->rgba[i];
            sum += d;
            sum2 += d * d;
        }
    *mean = sum / n;
    *error = sqrt(fmax(sum2 / n - *mean * *mean, 0.0) / (n - 1u));
}

static void subsurface_halves(void)
{
    const double a[3] = {0.9, 0.35, 0.1}, b[3] = {0.15, 0.5, 0.9};
    const float texels[6] = {(float)a[0], (float)a[1], (float)a[2], (float)b[0], (float)b[1], (float)b[2]};
    double af[3], bf[3];
    for (int c = 0; c < 3; ++c) af[c] = texels[c], bf[c] = texels[3 + c];
    test_result ra = slab(af, NULL), rb = slab(bf, NULL), rt = slab(af, texels);
    if (!ra.rgba || !rb.rgba || !rt.rgba) return;
    for (int c = 0; c < 3; ++c) {
        double d, e;
        paired_difference(&rt, &ra, c, 0, 8, &d, &e);
        CHECK(fabs(d) <= 5.0 * e, "left half, channel %d: textured - colour A = %g +- %g", c, d, e);
        paired_difference(&rt, &rb, c, 0, 8, &d, &e);
        CHECK(fabs(d) > 5.0 * e, "left half, channel %d: textured - colour B = %g +- %g should be far from 0", c, d, e);
        paired_difference(&rt, &rb, c, 8, 16, &d, &e);
        CHECK(fabs(d) <= 5.0 * e, "right half, channel %d: textured - colour B = %g +- %g", c, d, e);
    }
    free(ra.rgba);
    free(rb.rgba);
    free(rt.rgba);
}

/* A diffuse quad under the 4.x+ (v2) specular layer, its Roughness and / or Specular IOR Level
 * constant or from a 1 x 1 texture of value `rough` / `level` (negative: constant). */
static test_result v2_quad(double rough, double level, int textured_rough, int textured_level)
{
    dwv_scene_t *scene = new_scene();
    dwv_material_t m = DWV_MATERIAL_INIT;
    m.kind = DWV_MATERIAL_DIFFUSE;
    m.specular_model = DWV_SPECULAR_PRINCIPLED_V2;
    m.specular_multiscatter = 1;
    m.base_color[0] = 0.9, m.base_color[1] = 0.5, m.base_color[2] = 0.2;
    m.roughness = textured_rough ? 0.9 : rough; /* a texture's value replaces it */
    m.specular = textured_level ? 0.1 : level;
    uint32_t material = 0;
    dwv_scene_add_material(scene, &m, &material);
    float r = (float)rough, l = (float)level;
    if (textured_rough)
        bind(scene, material, DWV_INPUT_ROUGHNESS,
             add_texture(scene, 1, 1, 1, DWV_INTERPOLATION_CLOSEST, DWV_EXTENSION_REPEAT, &r), 1.0);
    if (textured_level)
        bind(scene, material, DWV_INPUT_SPECULAR,
             add_texture(scene, 1, 1, 1, DWV_INTERPOLATION_CLOSEST, DWV_EXTENSION_REPEAT, &l), 1.0);
    quad_scene(scene, material, NULL, 0, NULL);
    test_result out = bake(scene, 8, 4);
    dwv_scene_release(scene);
    return out;
}

static double largest_relative_difference(const test_result *a, const test_result *b)
{
    double worst = 0.0;
    for (int c = 0; c < 3; ++c) worst = fmax(worst, fabs(a->mean[c] - b->mean[c]) / b->mean[c]);
    return worst;
}

/* v2's albedo tables over textured Roughness / Specular IOR Level (a grid, material.h): a
 * texture of a grid node's roughness (0.5 = node 8 of 17) bakes bit for bit as the constant;
 * between nodes (0.37) and for the level (whose nodes are in sqrt(f0)) within 0.2% of the
 * constant (the interpolation's error; the bakes are paired: same seed, same walks), while a
 * constant 0.1 away is far outside that (the comparison can fail). */
static void v2_specular_textures(void)
{
    test_result constant = v2_quad(0.5, 0.5, 0, 0), textured = v2_quad(0.5, 0.5, 1, 0);
    CHECK(constant.rgba && textured.rgba && memcmp(constant.rgba, textured.rgba, 4u * 64u * sizeof(float)) == 0,
          "roughness 0.5 from a texture differs from the constant");
    free(constant.rgba), free(textured.rgba);
    static const struct { double rough, level; int tr, tl; } cases[] = {
        {0.37, 0.5, 1, 0}, {0.37, 0.23, 0, 1}, {0.61, 0.8, 1, 1}, {0.05, 0.5, 1, 0}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        test_result c = v2_quad(cases[i].rough, cases[i].level, 0, 0);
        test_result t = v2_quad(cases[i].rough, cases[i].level, cases[i].tr, cases[i].tl);
        test_result off = v2_quad(cases[i].rough + (cases[i].tr ? 0.1 : 0.0), cases[i].level + (cases[i].tl ? 0.1 : 0.0),
                                  0, 0);
        double d = largest_relative_difference(&t, &c), planted = largest_relative_difference(&off, &c);
        CHECK(d < 2e-3, "v2 case %zu: textured vs constant %.3g%%", i, 100.0 * d);
        CHECK(planted > 4e-3, "v2 case %zu: a value 0.1 off changes the mean by only %.3g%%", i, 100.0 * planted);
        printf("v2 case %zu (roughness %.2f%s, level %.2f%s): textured vs constant %.4f%%, 0.1 off %.3f%%\n", i,
               cases[i].rough, cases[i].tr ? " textured" : "", cases[i].level, cases[i].tl ? " textured" : "", 100.0 * d,
               100.0 * planted);
        free(c.rgba), free(t.rgba), free(off.rgba);
    }
}

int main(void)
{
    refusals();
    v2_specular_textures();
    diffuse_bakes();
    subsurface_halves();
    return check_report("test_textures");
}
