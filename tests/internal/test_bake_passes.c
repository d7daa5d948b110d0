/* Bake passes (dwv_bake_options_t.passes, dwv_image_pass, dwv_image_bake_type,
 * dwv_image_write_exr_layers):
 *   - the split against an outside reference: a 3.x material's diffuse light under its specular
 *     layer is the combined image of the same material without the layer (same random numbers),
 *     its glossy light the difference;
 *   - the parts add up to the combined image, pixel by pixel (camera bakes with misses and a
 *     subsurface object with a specular layer, 3.x and 4.x+ materials; a UV bake);
 *   - asking for passes changes no bit of the combined image, and a bake that asks for none holds
 *     no pass memory; passes are bit-identical across thread counts;
 *   - colours as Cycles' colour passes (a Lambertian's base colour; 3.x Principled subsurface: the
 *     BSSRDF's and the retro-reflection's weights; 4.x+: the specular layer's albedo), the
 *     environment where the camera misses, transmission and emission 0;
 *   - Blender's bake types from the passes (Diffuse with and without colour), invalid masks,
 *     filters and types refused with a message;
 *   - the multilayer EXR's channel names (Blender's) and pixels, read back with OpenEXR itself.
 * Internal (static archive) to see the image's pass memory. Runs in about 2 s. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <openexr.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "api/image_handle.h"
#include "bake_scenes.h"
#include "check.h"
#include <dwivedi.h>

#define ALL_PASSES ((1u << DWV_PASS_COUNT) - 1u)

static dwv_image_t *bake(dwv_scene_t *scene, dwv_bake_target_t target, uint32_t size, uint32_t passes, uint32_t threads)
{
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.target = target;
    o.width = o.height = size;
    o.samples = 8u;
    o.threads = threads;
    o.seed = 7u;
    o.passes = passes;
    o.technique = DWV_TECHNIQUE_CLASSICAL;
    dwv_image_t *image = NULL;
    if (dwv_bake(scene, &o, &image) != DWV_SUCCESS) {
        fprintf(stderr, "bake: %s\n", dwv_last_error_message());
        exit(2);
    }
    return image;
}

/* A sphere of material m (rings 12, segments 24, with UVs from its angles) in a world of 0.2, a
 * sun of 2 from the camera's side; the camera sees the sphere and the world around it. */
static dwv_scene_t *sphere_scene(const dwv_material_t *m)
{
    dwv_scene_t *scene;
    if (dwv_scene_create(&scene) != DWV_SUCCESS) exit(2);
    test_mesh sphere = test_sphere(0.0, 0.0, 0.0, 1.0, 12u, 24u);
    /* Per-corner UVs: a triangle's corners at its index in a grid, so that the UV bake covers texels. */
    sphere.uvs = malloc(6u * sphere.triangle_count * sizeof(float));
    uint32_t side = (uint32_t)ceil(sqrt((double)sphere.triangle_count));
    for (uint32_t t = 0; t < sphere.triangle_count; ++t) {
        float u0 = (float)(t % side) / (float)side, v0 = (float)(t / side) / (float)side, d = 0.9f / (float)side;
        float corner[6] = {u0, v0, u0 + d, v0, u0, v0 + d};
        memcpy(sphere.uvs + 6u * t, corner, sizeof corner);
    }
    test_add(scene, &sphere, m);
    test_mesh_free(&sphere);
    dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
    sun.strength = 2.0;
    sun.direction[0] = -0.4;
    sun.direction[2] = -0.9;
    double world[3] = {0.2, 0.25, 0.3};
    dwv_camera_t camera = test_ortho_camera(0.0, 0.0, 5.0, 3.0);
    if (dwv_scene_add_light(scene, &sun) || dwv_scene_set_world(scene, world, 1.0) || dwv_scene_set_camera(scene, &camera) ||
        dwv_scene_commit(scene)) {
        fprintf(stderr, "scene: %s\n", dwv_last_error_message());
        exit(2);
    }
    return scene;
}

static dwv_material_t subsurface_material(int principled_v1)
{
    dwv_material_t m = DWV_MATERIAL_INIT;
    static const double color[3] = {0.9, 0.6, 0.4}, radius[3] = {0.3, 0.15, 0.0}; /* blue: Lambertian */
    for (int c = 0; c < 3; ++c) {
        m.base_color[c] = 0.5;
        m.subsurface_color[c] = color[c];
        m.subsurface_radius[c] = radius[c];
    }
    m.subsurface_weight = 0.8;
    m.subsurface_scale = 1.0;
    m.roughness = 0.4;
    if (principled_v1) {
        m.subsurface_exit = DWV_SUBSURFACE_EXIT_PRINCIPLED_V1;
        m.specular_model = DWV_SPECULAR_PRINCIPLED_V1;
    } else {
        m.subsurface_model = DWV_SUBSURFACE_MODEL_BLENDER4_RANDOM_WALK;
        m.specular_model = DWV_SPECULAR_PRINCIPLED_V2;
        m.ior = 1.45;
    }
    m.specular = 0.5;
    return m;
}

static const dwvb_image *object(const dwv_image_t *image)
{
    return dwv_image_object(image);
}

/* The largest |a - b| / (|b| + 1e-6) over the RGB of two RGBA images. */
static double largest_difference(const float *a, const float *b, size_t pixels)
{
    double worst = 0.0;
    for (size_t i = 0; i < pixels; ++i)
        for (int c = 0; c < 3; ++c) worst = fmax(worst, fabs((double)a[4 * i + c] - b[4 * i + c]) / (fabs(b[4 * i + c]) + 1e-6));
    return worst;
}

/* Sum of parts == combined; the combined image is that of a bake without passes, bit for bit;
 * passes bit-identical on 1 and 2 threads. */
static void test_sum_of_parts(const char *label, dwv_scene_t *scene, dwv_bake_target_t target)
{
    const uint32_t size = 20u;
    dwv_image_t *plain = bake(scene, target, size, 0u, 2u);
    dwv_image_t *full = bake(scene, target, size, ALL_PASSES, 2u);
    dwv_image_t *single = bake(scene, target, size, ALL_PASSES, 1u);
    size_t pixels = (size_t)size * size;
    CHECK(object(plain)->pass_count == 0u && !object(plain)->pass_mean && !object(plain)->pass_variance,
          "%s: a bake without passes holds pass memory (%u passes)", label, object(plain)->pass_count);
    uint32_t held = 0u;
    CHECK(dwv_image_passes(plain, &held) == DWV_SUCCESS && held == DWV_PASS_BIT(DWV_PASS_COMBINED), "%s: 0x%x", label, held);
    CHECK(dwv_image_passes(full, &held) == DWV_SUCCESS && held == ALL_PASSES, "%s: all passes: 0x%x", label, held);
    CHECK(memcmp(object(plain)->rgba, object(full)->rgba, pixels * 4u * sizeof(float)) == 0 &&
              memcmp(object(plain)->variance, object(full)->variance, pixels * 3u * sizeof(float)) == 0,
          "%s: asking for passes changed the combined image", label);
    size_t values = (size_t)object(full)->pass_count * 3u * pixels;
    CHECK(memcmp(object(full)->pass_mean, object(single)->pass_mean, values * sizeof(float)) == 0 &&
              memcmp(object(full)->pass_variance, object(single)->pass_variance, values * sizeof(float)) == 0,
          "%s: the passes differ between 1 and 2 threads", label);
    /* Combined with every lobe, direct and indirect, and emission; plus the environment (camera). */
    dwv_image_t *sum = NULL;
    uint32_t every = DWV_BAKE_FILTER_DIRECT | DWV_BAKE_FILTER_INDIRECT | DWV_BAKE_FILTER_DIFFUSE | DWV_BAKE_FILTER_GLOSSY |
                     DWV_BAKE_FILTER_TRANSMISSION | DWV_BAKE_FILTER_EMIT;
    CHECK(dwv_image_bake_type(full, DWV_BAKE_TYPE_COMBINED, every, &sum) == DWV_SUCCESS, "%s", dwv_last_error_message());
    float *parts = malloc(pixels * 4u * sizeof *parts);
    memcpy(parts, object(sum)->rgba, pixels * 4u * sizeof *parts);
    const dwvb_image *f = object(full);
    int env = dwvb_image_pass_rank(f, DWV_PASS_ENVIRONMENT);
    double environment_seen = 0.0, glossy = 0.0, diffuse = 0.0, zero_passes = 0.0;
    int negative_indirect = 0;
    for (size_t i = 0; i < pixels; ++i) {
        for (int c = 0; c < 3; ++c) {
            if (target == DWV_BAKE_CAMERA) parts[4 * i + c] += f->pass_mean[(size_t)env * 3u * pixels + 3 * i + c];
            environment_seen += f->pass_mean[(size_t)env * 3u * pixels + 3 * i + c];
            glossy += f->pass_mean[(size_t)dwvb_image_pass_rank(f, DWV_PASS_GLOSSY_DIRECT) * 3u * pixels + 3 * i + c];
            diffuse += f->pass_mean[(size_t)dwvb_image_pass_rank(f, DWV_PASS_DIFFUSE_DIRECT) * 3u * pixels + 3 * i + c];
            /* No material transmits or emits; indirect light (once paths go on) only adds. */
            const uint32_t zeros[] = {DWV_PASS_TRANSMISSION_DIRECT, DWV_PASS_TRANSMISSION_INDIRECT,
                                      DWV_PASS_TRANSMISSION_COLOR, DWV_PASS_EMISSION};
            const uint32_t indirect[] = {DWV_PASS_DIFFUSE_INDIRECT, DWV_PASS_GLOSSY_INDIRECT};
            for (size_t k = 0; k < 2u; ++k) {
                float v = f->pass_mean[(size_t)dwvb_image_pass_rank(f, indirect[k]) * 3u * pixels + 3 * i + c];
                negative_indirect += !(v >= 0.0f);
            }
            for (size_t z = 0; z < sizeof zeros / sizeof *zeros; ++z)
                zero_passes += fabs(f->pass_mean[(size_t)dwvb_image_pass_rank(f, zeros[z]) * 3u * pixels + 3 * i + c]);
        }
    }
    /* Each sample's parts and its combined value are rounded to fixed point apart (2^-48 each):
     * the means agree to float rounding. */
    double worst = largest_difference(parts, object(full)->rgba, pixels);
    CHECK(worst < 1e-5, "%s: the parts add up to the combined image only within %.3g", label, worst);
    CHECK(glossy > 0.0 && diffuse > 0.0, "%s: glossy %g, diffuse %g: both lobes should have light", label, glossy, diffuse);
    CHECK(zero_passes == 0.0, "%s: transmission and emission are not 0 (%g)", label, zero_passes);
    CHECK(negative_indirect == 0, "%s: %d indirect values negative or NaN", label, negative_indirect);
    if (target == DWV_BAKE_CAMERA)
        CHECK(environment_seen > 0.0, "%s: the camera misses show no environment", label);
    /* Diffuse with Direct and Color is the light itself; with Direct alone it is the light divided
     * by the colour (= dwv_image_pass's DiffDir), the colour alone DiffCol. */
    dwv_image_t *with_colour = NULL, *without = NULL, *dir = NULL, *colour_only = NULL, *col = NULL;
    CHECK(dwv_image_bake_type(full, DWV_BAKE_TYPE_DIFFUSE, DWV_BAKE_FILTER_DIRECT | DWV_BAKE_FILTER_COLOR, &with_colour) ==
              DWV_SUCCESS, "%s", dwv_last_error_message());
    CHECK(dwv_image_bake_type(full, DWV_BAKE_TYPE_DIFFUSE, DWV_BAKE_FILTER_DIRECT, &without) == DWV_SUCCESS, "%s",
          dwv_last_error_message());
    CHECK(dwv_image_bake_type(full, DWV_BAKE_TYPE_DIFFUSE, DWV_BAKE_FILTER_COLOR, &colour_only) == DWV_SUCCESS, "%s",
          dwv_last_error_message());
    CHECK(dwv_image_pass(full, DWV_PASS_DIFFUSE_DIRECT, &dir) == DWV_SUCCESS, "%s", dwv_last_error_message());
    CHECK(dwv_image_pass(full, DWV_PASS_DIFFUSE_COLOR, &col) == DWV_SUCCESS, "%s", dwv_last_error_message());
    if (with_colour && without && dir && col && colour_only) {
        CHECK(largest_difference(object(without)->rgba, object(dir)->rgba, pixels) == 0.0, "%s: Diffuse Direct != DiffDir", label);
        CHECK(largest_difference(object(colour_only)->rgba, object(col)->rgba, pixels) == 0.0, "%s: Diffuse Color != DiffCol", label);
        float *product = malloc(pixels * 4u * sizeof *product);
        for (size_t i = 0; i < pixels; ++i)
            for (int c = 0; c < 4; ++c)
                product[4 * i + c] = c < 3 && object(col)->rgba[4 * i + c] > 0.0f
                                         ? object(dir)->rgba[4 * i + c] * object(col)->rgba[4 * i + c]
                                         : object(with_colour)->rgba[4 * i + c];
        worst = largest_difference(product, object(with_colour)->rgba, pixels);
        CHECK(worst < 1e-5, "%s: DiffDir x DiffCol differs from Diffuse Direct+Color by %.3g", label, worst);
        free(product);
    }
    dwv_image_t *none = NULL;
    CHECK(dwv_image_pass(plain, DWV_PASS_DIFFUSE_DIRECT, &none) == DWV_ERROR_INVALID_ARGUMENT && !none &&
              strstr(dwv_last_error_message(), "DiffDir"),
          "%s: a pass the image does not hold: %s", label, dwv_last_error_message());
    free(parts);
    dwv_image_release(sum);
    dwv_image_release(with_colour);
    dwv_image_release(without);
    dwv_image_release(colour_only);
    dwv_image_release(dir);
    dwv_image_release(col);
    dwv_image_release(plain);
    dwv_image_release(full);
    dwv_image_release(single);
}

/* The colour passes against the materials' closures, on UV bakes (every texel sees its own point). */
static void test_colours(void)
{
    /* A Lambertian of base colour b: DiffCol = b, GlossCol = 0 everywhere covered. */
    dwv_material_t lambert = DWV_MATERIAL_INIT;
    lambert.kind = DWV_MATERIAL_DIFFUSE;
    lambert.base_color[0] = 0.7, lambert.base_color[1] = 0.3, lambert.base_color[2] = 0.1;
    dwv_scene_t *scene = sphere_scene(&lambert);
    dwv_image_t *image = bake(scene, DWV_BAKE_UV, 32u, DWV_PASS_BIT(DWV_PASS_DIFFUSE_COLOR) | DWV_PASS_BIT(DWV_PASS_GLOSSY_COLOR), 2u);
    const dwvb_image *img = object(image);
    size_t pixels = 32u * 32u;
    int d = dwvb_image_pass_rank(img, DWV_PASS_DIFFUSE_COLOR), g = dwvb_image_pass_rank(img, DWV_PASS_GLOSSY_COLOR);
    int wrong = 0, covered = 0;
    for (size_t i = 0; i < pixels; ++i) {
        if (img->samples[i] == 0u) continue;
        ++covered;
        for (int c = 0; c < 3; ++c)
            wrong += fabsf(img->pass_mean[(size_t)d * 3u * pixels + 3 * i + c] - (float)lambert.base_color[c]) > 1e-6f ||
                     img->pass_mean[(size_t)g * 3u * pixels + 3 * i + c] != 0.0f;
    }
    CHECK(covered > 100 && wrong == 0, "Lambertian colours: %d of %d texels wrong", wrong, covered);
    dwv_image_release(image);
    dwv_scene_release(scene);
    /* 3.x Principled with subsurface (w 0.8, colour A; blue's radius 0: Lambertian): DiffCol =
     * (1 - w) base + w A (the BSSRDF, or blue's Lambertian) + w A (the retro-reflection BSDF,
     * every channel); GlossCol = 1 (the closure's weight). */
    dwv_material_t v1 = subsurface_material(1);
    scene = sphere_scene(&v1);
    image = bake(scene, DWV_BAKE_UV, 32u, DWV_PASS_BIT(DWV_PASS_DIFFUSE_COLOR) | DWV_PASS_BIT(DWV_PASS_GLOSSY_COLOR), 2u);
    img = object(image);
    wrong = covered = 0;
    for (size_t i = 0; i < pixels; ++i) {
        if (img->samples[i] == 0u) continue;
        ++covered;
        for (int c = 0; c < 3; ++c) {
            double w = v1.subsurface_weight, expected = (1.0 - w) * v1.base_color[c] + 2.0 * w * v1.subsurface_color[c];
            wrong += fabs(img->pass_mean[(size_t)d * 3u * pixels + 3 * i + c] - expected) > 1e-6 ||
                     img->pass_mean[(size_t)g * 3u * pixels + 3 * i + c] != 1.0f;
        }
    }
    CHECK(covered > 100 && wrong == 0, "3.x Principled colours: %d of %d texels wrong", wrong, covered);
    dwv_image_release(image);
    dwv_scene_release(scene);
}

/* The split against an outside reference: a 3.x material with its specular layer (whose diffuse
 * lobes keep weight 1 under it) and the same without the layer take the same random numbers, so
 * the first's diffuse light (DiffDir x DiffCol) is the second's combined image, and its glossy
 * light the difference of the two combined images, to float rounding. */
static void test_split_against_no_specular(void)
{
    dwv_material_t with = subsurface_material(1), without = with;
    without.specular = 0.0;
    dwv_scene_t *a = sphere_scene(&with), *b = sphere_scene(&without);
    const uint32_t size = 20u;
    size_t pixels = (size_t)size * size;
    dwv_image_t *layered = bake(a, DWV_BAKE_CAMERA, size, DWV_PASS_BIT(DWV_PASS_DIFFUSE_DIRECT) | DWV_PASS_BIT(DWV_PASS_GLOSSY_DIRECT), 2u);
    dwv_image_t *plain = bake(b, DWV_BAKE_CAMERA, size, 0u, 2u);
    const dwvb_image *l = object(layered), *p = object(plain);
    const float *diffuse = l->pass_mean + (size_t)dwvb_image_pass_rank(l, DWV_PASS_DIFFUSE_DIRECT) * 3u * pixels;
    const float *glossy = l->pass_mean + (size_t)dwvb_image_pass_rank(l, DWV_PASS_GLOSSY_DIRECT) * 3u * pixels;
    double worst_diffuse = 0.0, worst_glossy = 0.0, glossy_sum = 0.0;
    for (size_t i = 0; i < pixels; ++i) {
        if (p->rgba[4 * i + 3] != 1.0f) continue; /* every sample met the sphere (misses: the world in Combined) */
        for (int c = 0; c < 3; ++c) {
            double plain_value = p->rgba[4 * i + c], layered_value = l->rgba[4 * i + c];
            worst_diffuse = fmax(worst_diffuse, fabs(diffuse[3 * i + c] - plain_value) / (plain_value + 1e-3));
            worst_glossy = fmax(worst_glossy, fabs(glossy[3 * i + c] - (layered_value - plain_value)) / (layered_value + 1e-3));
            glossy_sum += glossy[3 * i + c];
        }
    }
    CHECK(worst_diffuse < 1e-4, "DiffDir of the layered material differs from the unlayered combined image by %.3g", worst_diffuse);
    CHECK(worst_glossy < 1e-4 && glossy_sum > 0.0, "GlossDir differs from the layer's share of Combined by %.3g (sum %g)",
          worst_glossy, glossy_sum);
    dwv_image_release(layered);
    dwv_image_release(plain);
    dwv_scene_release(a);
    dwv_scene_release(b);
}

static int has_channel(const exr_attr_chlist_t *list, const char *name)
{
    for (int k = 0; k < list->num_channels; ++k)
        if (strcmp(list->entries[k].name.str, name) == 0) return 1;
    return 0;
}

static void test_exr_layers(dwv_scene_t *scene)
{
    uint32_t wanted = DWV_PASS_BIT(DWV_PASS_DIFFUSE_DIRECT) | DWV_PASS_BIT(DWV_PASS_GLOSSY_DIRECT) | DWV_PASS_BIT(DWV_PASS_ENVIRONMENT);
    dwv_image_t *image = bake(scene, DWV_BAKE_CAMERA, 12u, wanted, 2u);
    char path[] = "/tmp/dwv_passes_XXXXXX";
    int fd = mkstemp(path);
    if (fd >= 0) close(fd);
    CHECK(dwv_image_write_exr_layers(image, path) == DWV_SUCCESS, "%s", dwv_last_error_message());
    exr_context_t c = NULL;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    const exr_attr_chlist_t *list = NULL;
    if (exr_start_read(&c, path, &init) == EXR_ERR_SUCCESS && exr_get_channels(c, 0, &list) == EXR_ERR_SUCCESS) {
        /* Asking for DiffDir and GlossDir brings their colours. */
        static const char *const expected[] = {"Combined.R", "Combined.G", "Combined.B", "Combined.A", "DiffDir.R",
                                               "DiffDir.G",  "DiffDir.B",  "DiffCol.R",  "DiffCol.G",  "DiffCol.B",
                                               "GlossDir.R", "GlossDir.G", "GlossDir.B", "GlossCol.R", "GlossCol.G",
                                               "GlossCol.B", "Env.R",      "Env.G",      "Env.B"};
        size_t count = sizeof expected / sizeof *expected;
        int all = list->num_channels == (int)count;
        for (size_t k = 0; k < count; ++k) all = all && has_channel(list, expected[k]);
        CHECK(all, "the multilayer EXR has %d channels, not Blender's %zu layer channels", list->num_channels, count);
    } else {
        CHECK(0, "OpenEXR cannot read %s", path);
    }
    if (c) exr_finish(&c);
    unlink(path);
    /* Blender's names, and none for an unknown pass. */
    static const char *const names[DWV_PASS_COUNT] = {"Combined", "DiffDir",  "DiffInd",  "DiffCol", "GlossDir", "GlossInd",
                                                      "GlossCol", "TransDir", "TransInd", "TransCol", "Emit",    "Env"};
    int same = 1;
    for (uint32_t p = 0; p < DWV_PASS_COUNT; ++p) same = same && dwv_pass_name((dwv_pass_t)p) && strcmp(dwv_pass_name((dwv_pass_t)p), names[p]) == 0;
    CHECK(same && dwv_pass_name((dwv_pass_t)DWV_PASS_COUNT) == NULL, "pass names are not Blender's");
    dwv_image_release(image);
}

static void test_refusals(dwv_scene_t *scene)
{
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = o.height = 8u;
    o.samples = 4u;
    dwv_image_t *image = NULL;
    o.passes = 1u << DWV_PASS_COUNT;
    CHECK(dwv_bake(scene, &o, &image) == DWV_ERROR_INVALID_ARGUMENT && !image && strstr(dwv_last_error_message(), "passes"),
          "a pass bit beyond the last: %s", dwv_last_error_message());
    o.passes = DWV_PASS_BIT(DWV_PASS_DIFFUSE_COLOR);
    o.reserved2 = 1u;
    CHECK(dwv_bake(scene, &o, &image) == DWV_ERROR_INVALID_ARGUMENT && strstr(dwv_last_error_message(), "reserved2"),
          "reserved2: %s", dwv_last_error_message());
    o.reserved2 = 0u;
    o.sample_count = 2u;
    CHECK(dwv_bake(scene, &o, &image) == DWV_ERROR_INVALID_ARGUMENT && strstr(dwv_last_error_message(), "split bake"),
          "passes in a chunk: %s", dwv_last_error_message());
    uint32_t passes = 99u;
    CHECK(dwv_bake_type_passes(DWV_BAKE_TYPE_DIFFUSE, 0u, &passes) == DWV_ERROR_INVALID_ARGUMENT && passes == 0u &&
              strstr(dwv_last_error_message(), "Direct, Indirect or Color"),
          "Diffuse with an empty filter: %s", dwv_last_error_message());
    CHECK(dwv_bake_type_passes(DWV_BAKE_TYPE_COMBINED, DWV_BAKE_FILTER_DIFFUSE, &passes) == DWV_ERROR_INVALID_ARGUMENT,
          "Combined with a lobe but neither direct nor indirect");
    CHECK(dwv_bake_type_passes((dwv_bake_type_t)6, DWV_BAKE_FILTER_DIRECT, &passes) == DWV_ERROR_INVALID_ARGUMENT &&
              strstr(dwv_last_error_message(), "bake type 6"), "an unknown type: %s", dwv_last_error_message());
    CHECK(dwv_bake_type_passes(DWV_BAKE_TYPE_GLOSSY, 0x80u, &passes) == DWV_ERROR_INVALID_ARGUMENT, "an unknown filter bit");
    CHECK(dwv_bake_type_passes(DWV_BAKE_TYPE_GLOSSY, DWV_BAKE_FILTER_DIRECT, &passes) == DWV_SUCCESS &&
              passes == (DWV_PASS_BIT(DWV_PASS_GLOSSY_DIRECT) | DWV_PASS_BIT(DWV_PASS_GLOSSY_COLOR)),
          "Glossy Direct: 0x%x", passes);
    CHECK(dwv_bake_type_passes(DWV_BAKE_TYPE_COMBINED, DWV_BAKE_FILTER_DIRECT | DWV_BAKE_FILTER_GLOSSY | DWV_BAKE_FILTER_EMIT,
                               &passes) == DWV_SUCCESS &&
              passes == (DWV_PASS_BIT(DWV_PASS_GLOSSY_DIRECT) | DWV_PASS_BIT(DWV_PASS_EMISSION)),
          "Combined glossy direct + emit: 0x%x", passes);
}

int main(void)
{
    dwv_material_t v1 = subsurface_material(1), v2 = subsurface_material(0);
    dwv_scene_t *scene_v1 = sphere_scene(&v1), *scene_v2 = sphere_scene(&v2);
    test_sum_of_parts("3.x camera", scene_v1, DWV_BAKE_CAMERA);
    test_sum_of_parts("4.x camera", scene_v2, DWV_BAKE_CAMERA);
    test_sum_of_parts("3.x UV", scene_v1, DWV_BAKE_UV);
    test_colours();
    test_split_against_no_specular();
    test_exr_layers(scene_v2);
    test_refusals(scene_v2);
    dwv_scene_release(scene_v1);
    dwv_scene_release(scene_v2);
    return check_report("test_bake_passes");
}
