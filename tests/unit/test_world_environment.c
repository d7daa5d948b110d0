/* The world environment and spot lights through the public API: bad input refused with a message
 * and nothing changed; a 1 x 1 image is the constant world bit for bit; a 100000 x 1 image bakes;
 * a black image is a black world; a uniform map agrees with the constant world within the noise;
 * camera rays that miss see the map; a spot light over a diffuse plane gives the radiance worked
 * out by hand per pixel; a light described by the struct before the spot fields still works. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake_scenes.h"
#include "check.h"
#include <dwivedi.h>

#define PI 3.14159265358979323846

static int message_has(const char *part)
{
    return strstr(dwv_last_error_message(), part) != NULL;
}

static void test_bad_environments(void)
{
    dwv_scene_t *scene = NULL;
    dwv_scene_create(&scene);
    float texels[3 * 8 * 4];
    for (int i = 0; i < 3 * 8 * 4; ++i) texels[i] = 0.5f;
    dwv_environment_t e = DWV_ENVIRONMENT_INIT;
    e.width = 8;
    e.height = 4;
    e.texels = texels;
    CHECK(dwv_scene_set_world_environment(NULL, &e) == DWV_ERROR_NULL_POINTER, "NULL scene");
    CHECK(dwv_scene_set_world_environment(scene, NULL) == DWV_ERROR_NULL_POINTER, "NULL environment");
    dwv_environment_t bad = e;
    bad.struct_size = 8;
    CHECK(dwv_scene_set_world_environment(scene, &bad) == DWV_ERROR_STRUCT_SIZE, "struct size");
    bad = e;
    bad.width = 0;
    CHECK(dwv_scene_set_world_environment(scene, &bad) == DWV_ERROR_OUT_OF_RANGE && message_has("0 x 4"), "0 wide: %s",
          dwv_last_error_message());
    bad = e;
    bad.height = 0;
    CHECK(dwv_scene_set_world_environment(scene, &bad) == DWV_ERROR_OUT_OF_RANGE, "0 high");
    bad = e;
    bad.width = 100000;
    bad.height = 100000; /* 10^10 texels: refused before anything is read */
    CHECK(dwv_scene_set_world_environment(scene, &bad) == DWV_ERROR_OUT_OF_RANGE, "too many texels");
    bad = e;
    bad.width = DWV_ENVIRONMENT_MAX_SIDE + 1u;
    bad.height = 1;
    CHECK(dwv_scene_set_world_environment(scene, &bad) == DWV_ERROR_OUT_OF_RANGE, "too wide");
    bad = e;
    bad.texels = NULL;
    CHECK(dwv_scene_set_world_environment(scene, &bad) == DWV_ERROR_NULL_POINTER, "NULL texels");
    bad = e;
    bad.interpolation = 7;
    CHECK(dwv_scene_set_world_environment(scene, &bad) == DWV_ERROR_INVALID_ARGUMENT, "interpolation");
    bad = e;
    bad.strength = NAN;
    CHECK(dwv_scene_set_world_environment(scene, &bad) != DWV_SUCCESS, "NaN strength");
    bad.strength = -1.0;
    CHECK(dwv_scene_set_world_environment(scene, &bad) == DWV_ERROR_OUT_OF_RANGE, "negative strength");
    bad = e;
    bad.rotation[0] = 2.0;
    CHECK(dwv_scene_set_world_environment(scene, &bad) == DWV_ERROR_INVALID_ARGUMENT && message_has("not a rotation"),
          "scaled rotation: %s", dwv_last_error_message());
    bad = e;
    bad.rotation[8] = -1.0;
    CHECK(dwv_scene_set_world_environment(scene, &bad) == DWV_ERROR_INVALID_ARGUMENT && message_has("mirrors"),
          "mirror: %s", dwv_last_error_message());
    const float poison[3] = {NAN, INFINITY, -1e-3f};
    const char *names[3] = {"NaN", "inf", "-0.001"};
    for (int k = 0; k < 3; ++k) {
        float saved = texels[3 * (2 * 8 + 5) + 1];
        texels[3 * (2 * 8 + 5) + 1] = poison[k];
        CHECK(dwv_scene_set_world_environment(scene, &e) == DWV_ERROR_INVALID_ARGUMENT &&
                  message_has("texel (5, 2)") && message_has("green"),
              "%s texel: %s", names[k], dwv_last_error_message());
        texels[3 * (2 * 8 + 5) + 1] = saved;
    }
    bad = e;
    bad.strength = 1e300;
    texels[0] = 1e30f;
    CHECK(dwv_scene_set_world_environment(scene, &bad) == DWV_ERROR_OUT_OF_RANGE, "overflow");
    texels[0] = 0.5f;
    /* Nothing was changed by the refusals: the world is still black. */
    CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit");
    CHECK(dwv_scene_set_world_environment(scene, &e) == DWV_ERROR_INVALID_STATE, "committed");
    dwv_scene_release(scene);
}

static dwv_scene_t *sphere_scene(void)
{
    dwv_scene_t *scene = NULL;
    dwv_scene_create(&scene);
    test_mesh sphere = test_sphere(0.0, 0.0, 0.0, 1.0, 12, 24);
    dwv_material_t m = DWV_MATERIAL_INIT;
    m.kind = DWV_MATERIAL_DIFFUSE;
    test_add(scene, &sphere, &m);
    test_mesh_free(&sphere);
    dwv_camera_t camera = test_ortho_camera(0.0, 0.0, 5.0, 3.0);
    dwv_scene_set_camera(scene, &camera);
    return scene;
}

static dwv_image_t *bake(dwv_scene_t *scene, uint32_t size, uint64_t samples)
{
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = o.height = size;
    o.samples = samples;
    o.threads = 2;
    o.seed = 5;
    dwv_image_t *image = NULL;
    CHECK(dwv_bake(scene, &o, &image) == DWV_SUCCESS, "bake: %s", dwv_last_error_message());
    return image;
}

static void mean_and_error(const dwv_image_t *image, double mean[3], double error[3])
{
    dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
    dwv_image_info(image, &info);
    size_t n = (size_t)info.width * info.height;
    for (int c = 0; c < 3; ++c) {
        double sum = 0.0, variance = 0.0;
        for (size_t i = 0; i < n; ++i) {
            sum += info.rgba[4 * i + (size_t)c];
            variance += info.variance[3 * i + (size_t)c];
        }
        mean[c] = sum / (double)n;
        error[c] = sqrt(variance) / (double)n;
    }
}

/* 1 x 1 is the constant world exactly; a uniform 16 x 8 map agrees with it within the noise. */
static void test_constant_equivalents(void)
{
    const double strength = 1.5;
    const float texel[3] = {0.6f, 0.5f, 0.3f};
    dwv_scene_t *constant = sphere_scene(), *one = sphere_scene(), *uniform = sphere_scene();
    dwv_scene_set_world(constant, (const double[3]){texel[0], texel[1], texel[2]}, strength);
    dwv_environment_t e = DWV_ENVIRONMENT_INIT;
    e.width = e.height = 1;
    e.texels = texel;
    e.strength = strength;
    CHECK(dwv_scene_set_world_environment(one, &e) == DWV_SUCCESS, "1 x 1: %s", dwv_last_error_message());
    static float texels[3 * 16 * 8];
    for (int i = 0; i < 16 * 8; ++i) memcpy(texels + 3 * i, texel, sizeof texel);
    e.width = 16;
    e.height = 8;
    e.texels = texels;
    CHECK(dwv_scene_set_world_environment(uniform, &e) == DWV_SUCCESS, "16 x 8: %s", dwv_last_error_message());
    dwv_scene_commit(constant);
    dwv_scene_commit(one);
    dwv_scene_commit(uniform);
    dwv_image_t *a = bake(constant, 24, 32), *b = bake(one, 24, 32), *c = bake(uniform, 24, 32);
    if (a && b && c) {
        dwv_image_info_t ia = DWV_IMAGE_INFO_INIT, ib = DWV_IMAGE_INFO_INIT;
        dwv_image_info(a, &ia);
        dwv_image_info(b, &ib);
        CHECK(memcmp(ia.rgba, ib.rgba, 4u * 24u * 24u * sizeof(float)) == 0, "1 x 1 differs from the constant world");
        double ma[3], ea[3], mc[3], ec[3];
        mean_and_error(a, ma, ea);
        mean_and_error(c, mc, ec);
        for (int k = 0; k < 3; ++k) {
            printf("  channel %d: constant world %.5f +- %.2g, uniform map %.5f +- %.2g\n", k, ma[k], ea[k], mc[k], ec[k]);
            CHECK(fabs(ma[k] - mc[k]) < 4.0 * sqrt(ea[k] * ea[k] + ec[k] * ec[k]), "channel %d: %.5f vs %.5f", k, ma[k],
                  mc[k]);
        }
    }
    dwv_image_release(a);
    dwv_image_release(b);
    dwv_image_release(c);
    dwv_scene_release(constant);
    dwv_scene_release(one);
    dwv_scene_release(uniform);
}

/* 100000 x 1 (longitude only) bakes; an all-black map is a black world; camera rays that miss
 * see the map (closest: straight down is v = 0, row 0). */
static void test_odd_maps(void)
{
    dwv_scene_t *scene = sphere_scene();
    const uint32_t w = 100000u;
    float *texels = malloc(3u * w * sizeof(float));
    for (uint32_t i = 0; i < w; ++i)
        for (int k = 0; k < 3; ++k) texels[3u * i + (uint32_t)k] = (float)(1.0 + sin(2.0 * PI * i / w));
    dwv_environment_t e = DWV_ENVIRONMENT_INIT;
    e.width = w;
    e.height = 1;
    e.texels = texels;
    CHECK(dwv_scene_set_world_environment(scene, &e) == DWV_SUCCESS, "100000 x 1: %s", dwv_last_error_message());
    CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit");
    dwv_image_t *image = bake(scene, 8, 4);
    if (image) {
        double m[3], err[3];
        mean_and_error(image, m, err);
        CHECK(isfinite(m[0]) && m[0] > 0.0, "100000 x 1 mean %g", m[0]);
    }
    dwv_image_release(image);
    dwv_scene_release(scene);
    free(texels);

    float black[3 * 4 * 2] = {0};
    scene = sphere_scene();
    e.width = 4;
    e.height = 2;
    e.texels = black;
    CHECK(dwv_scene_set_world_environment(scene, &e) == DWV_SUCCESS, "black: %s", dwv_last_error_message());
    dwv_scene_commit(scene);
    image = bake(scene, 8, 2);
    if (image) {
        dwv_bake_stats_t st = DWV_BAKE_STATS_INIT;
        dwv_image_stats(image, &st);
        CHECK(!(st.features & DWV_FEATURE_WORLD_LIGHT), "a black map lights");
        CHECK(st.mean_rgb[0] == 0.0, "black world mean %g", st.mean_rgb[0]);
    }
    dwv_image_release(image);
    dwv_scene_release(scene);

    float coded[3 * 8 * 4];
    /* Straight down has no longitude (atan2 of zeros): row 0 is one value, the others differ. */
    for (int i = 0; i < 8 * 4; ++i) coded[3 * i] = coded[3 * i + 1] = coded[3 * i + 2] = (float)(i < 8 ? 7 : 1 + i);
    dwv_scene_create(&scene);
    dwv_camera_t camera = test_ortho_camera(0.0, 0.0, 5.0, 3.0);
    dwv_scene_set_camera(scene, &camera);
    e.width = 8;
    e.height = 4;
    e.texels = coded;
    e.interpolation = DWV_ENVIRONMENT_CLOSEST;
    e.strength = 0.5;
    CHECK(dwv_scene_set_world_environment(scene, &e) == DWV_SUCCESS, "coded: %s", dwv_last_error_message());
    dwv_scene_commit(scene);
    image = bake(scene, 4, 2);
    if (image) {
        dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
        dwv_image_info(image, &info);
        CHECK(info.rgba[0] == 0.5f * 7.0f, "a miss looking down sees %g, want row 0's 7 x 0.5 = 3.5", info.rgba[0]);
    }
    dwv_image_release(image);
    dwv_scene_release(scene);
}

/* A spot light of power P at height H over a diffuse plane of albedo rho, pointing down, seen
 * from above: the radiance at (x, y, 0) is rho / pi x P / (4 pi) x a(c) x c / d^2, with
 * d^2 = x^2 + y^2 + H^2, c = H / d (the cosine at the plane and to the axis alike) and the
 * attenuation a of the falloff (Cycles 3.x: c x smoothstep; 4.x: the smoothstep). Each pixel is
 * compared with that radiance averaged over it (8 x 8 points). */
static double attenuation(double c, double size, double blend, int falloff)
{
    double ch = cos(0.5 * size), width = (1.0 - ch) * blend;
    if (c <= ch) return 0.0;
    double s = fmin(1.0, (c - ch) / width);
    double smooth = 3.0 * s * s - 2.0 * s * s * s;
    return (falloff == DWV_SPOT_FALLOFF_CYCLES3 ? c : 1.0) * smooth;
}

static void test_spot_over_plane(void)
{
    const double H = 2.0, P = 1000.0, rho = 0.8, size = 70.0 * PI / 180.0, blend = 0.3, scale = 4.0;
    const uint32_t N = 32;
    for (int falloff = DWV_SPOT_FALLOFF_CYCLES3; falloff <= DWV_SPOT_FALLOFF_CYCLES4; ++falloff) {
        dwv_scene_t *scene = NULL;
        dwv_scene_create(&scene);
        test_mesh box = test_box(-4.0, -4.0, -1.0, 4.0, 4.0, 0.0);
        dwv_material_t m = DWV_MATERIAL_INIT;
        m.kind = DWV_MATERIAL_DIFFUSE;
        m.base_color[0] = m.base_color[1] = m.base_color[2] = rho;
        test_add(scene, &box, &m);
        test_mesh_free(&box);
        dwv_camera_t camera = test_ortho_camera(0.0, 0.0, 5.0, scale);
        dwv_scene_set_camera(scene, &camera);
        dwv_light_desc_t spot = DWV_LIGHT_DESC_INIT;
        spot.kind = DWV_LIGHT_SPOT;
        spot.position[2] = H;
        spot.direction[2] = -1.0;
        spot.strength = P;
        spot.spot_size = size;
        spot.spot_blend = blend;
        spot.spot_falloff = falloff;
        CHECK(dwv_scene_add_light(scene, &spot) == DWV_SUCCESS, "spot: %s", dwv_last_error_message());
        CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit");
        dwv_image_t *image = bake(scene, N, 16);
        if (image) {
            dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
            dwv_image_info(image, &info);
            double worst = 0.0, peak = rho / PI * P / (4.0 * PI) / (H * H);
            for (uint32_t row = 0; row < N; ++row)
                for (uint32_t col = 0; col < N; ++col) {
                    double want = 0.0;
                    for (int j = 0; j < 8; ++j)
                        for (int i = 0; i < 8; ++i) {
                            double x = scale * ((col + (i + 0.5) / 8.0) / N - 0.5);
                            double y = scale * (0.5 - (row + (j + 0.5) / 8.0) / N);
                            double d2 = x * x + y * y + H * H, c = H / sqrt(d2);
                            want += rho / PI * P / (4.0 * PI) * attenuation(c, size, blend, falloff) * c / d2 / 64.0;
                        }
                    double got = info.rgba[4u * (row * N + col)];
                    worst = fmax(worst, fabs(got - want) / peak);
                }
            printf("  falloff %d: the largest pixel difference is %.2g of the peak\n", falloff, worst);
            /* Stratified pixel positions (16) over the cone's soft edge: within 2% of the peak. */
            CHECK(worst < 0.02, "falloff %d: a pixel differs by %.3g of the peak", falloff, worst);
        }
        dwv_image_release(image);
        dwv_scene_release(scene);
    }
}

/* Bad spot lights, and a light struct that ends before the spot fields. */
static void test_spot_input(void)
{
    dwv_scene_t *scene = NULL;
    dwv_scene_create(&scene);
    dwv_light_desc_t spot = DWV_LIGHT_DESC_INIT;
    spot.kind = DWV_LIGHT_SPOT;
    dwv_light_desc_t bad = spot;
    bad.spot_size = 0.0;
    CHECK(dwv_scene_add_light(scene, &bad) == DWV_ERROR_OUT_OF_RANGE, "spot_size 0");
    bad.spot_size = 4.0;
    CHECK(dwv_scene_add_light(scene, &bad) == DWV_ERROR_OUT_OF_RANGE, "spot_size above pi");
    bad = spot;
    bad.spot_blend = 1.5;
    CHECK(dwv_scene_add_light(scene, &bad) == DWV_ERROR_OUT_OF_RANGE, "blend");
    bad = spot;
    bad.direction[0] = bad.direction[1] = bad.direction[2] = 0.0;
    CHECK(dwv_scene_add_light(scene, &bad) == DWV_ERROR_INVALID_ARGUMENT, "no direction");
    bad = spot;
    bad.spot_falloff = 2;
    CHECK(dwv_scene_add_light(scene, &bad) == DWV_ERROR_INVALID_ARGUMENT, "falloff");
    bad = spot;
    bad.radius = NAN;
    CHECK(dwv_scene_add_light(scene, &bad) != DWV_SUCCESS, "NaN radius");
    CHECK(dwv_scene_add_light(scene, &spot) == DWV_SUCCESS, "spot: %s", dwv_last_error_message());
    dwv_light_desc_t old = DWV_LIGHT_DESC_INIT;
    old.kind = DWV_LIGHT_POINT;
    old.struct_size = (uint32_t)offsetof(dwv_light_desc_t, spot_size);
    CHECK(dwv_scene_add_light(scene, &old) == DWV_SUCCESS, "an older light struct: %s", dwv_last_error_message());
    old.struct_size = (uint32_t)offsetof(dwv_light_desc_t, spot_size) - 8u;
    CHECK(dwv_scene_add_light(scene, &old) == DWV_ERROR_STRUCT_SIZE, "a truncated light struct");
    dwv_scene_release(scene);
}

/* Scene files: an environment and a spot light load to the scene the C calls make (bit-identical
 * bakes); malformed ones fail with their path in the message. */
static void test_scene_file(void)
{
    const char *json =
        "{\"version\": 1,"
        " \"materials\": {\"m\": {\"kind\": \"diffuse\", \"subsurface_weight\": 0}},"
        " \"meshes\": [{\"material\": \"m\", \"positions\": [-1,-1,0, 1,-1,0, 1,1,0, -1,1,0], \"indices\": [0,1,2, 0,2,3]}],"
        " \"lights\": [{\"kind\": \"spot\", \"position\": [0, 0, 1], \"direction\": [0, 0, -1], \"strength\": 50,"
        "   \"spot_size\": 60, \"spot_blend\": 0.2, \"spot_falloff\": \"cycles4\"}],"
        " \"world\": {\"environment\": {\"width\": 4, \"height\": 2, \"interpolation\": \"cubic\", \"strength\": 2,"
        "   \"rotate\": [0, 0, 90], \"texels\": [1,0,0, 0,1,0, 0,0,1, 1,1,1, 2,2,2, 3,3,3, 4,4,4, 0.5,0.5,0.5]}},"
        " \"camera\": {\"kind\": \"orthographic\", \"ortho_scale\": 3, \"transform\": {\"translate\": [0, 0, 3]}}}";
    dwv_scene_t *loaded = NULL;
    CHECK(dwv_scene_load_json(json, strlen(json), NULL, &loaded, NULL) == DWV_SUCCESS, "load: %s", dwv_last_error_message());
    dwv_scene_t *made = NULL;
    dwv_scene_create(&made);
    dwv_material_t m = DWV_MATERIAL_INIT;
    m.kind = DWV_MATERIAL_DIFFUSE;
    m.subsurface_weight = 0.0;
    uint32_t material_id, mesh_id;
    dwv_scene_add_material(made, &m, &material_id);
    const float positions[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    const uint32_t indices[] = {0, 1, 2, 0, 2, 3};
    dwv_mesh_t mesh = DWV_MESH_INIT;
    mesh.vertex_count = 4;
    mesh.triangle_count = 2;
    mesh.positions = positions;
    mesh.indices = indices;
    mesh.material_id = material_id;
    dwv_scene_add_mesh(made, &mesh, &mesh_id);
    dwv_light_desc_t spot = DWV_LIGHT_DESC_INIT;
    spot.kind = DWV_LIGHT_SPOT;
    spot.position[2] = 1.0;
    spot.strength = 50.0;
    spot.spot_size = 60.0 * (PI / 180.0);
    spot.spot_blend = 0.2;
    spot.spot_falloff = DWV_SPOT_FALLOFF_CYCLES4;
    dwv_scene_add_light(made, &spot);
    const float texels[] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4, 0.5f, 0.5f, 0.5f};
    dwv_environment_t e = DWV_ENVIRONMENT_INIT;
    e.width = 4;
    e.height = 2;
    e.texels = texels;
    e.interpolation = DWV_ENVIRONMENT_CUBIC;
    e.strength = 2.0;
    /* Rz(90 degrees) as the scene file's T R S makes it: cos(pi/2) is 6e-17, not 0. */
    double c = cos(0.5 * PI), s = sin(0.5 * PI);
    double rz[9] = {c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0};
    memcpy(e.rotation, rz, sizeof rz);
    dwv_scene_set_world_environment(made, &e);
    dwv_camera_t camera = test_ortho_camera(0.0, 0.0, 3.0, 3.0);
    dwv_scene_set_camera(made, &camera);
    dwv_scene_commit(made);
    if (loaded) {
        dwv_image_t *a = bake(loaded, 16, 4), *b = bake(made, 16, 4);
        if (a && b) {
            dwv_image_info_t ia = DWV_IMAGE_INFO_INIT, ib = DWV_IMAGE_INFO_INIT;
            dwv_image_info(a, &ia);
            dwv_image_info(b, &ib);
            CHECK(memcmp(ia.rgba, ib.rgba, 4u * 16u * 16u * sizeof(float)) == 0, "the file's scene bakes differently");
        }
        dwv_image_release(a);
        dwv_image_release(b);
    }
    dwv_scene_release(loaded);
    dwv_scene_release(made);
    static const struct { const char *json, *part; } bad[] = {
        {"{\"version\": 1, \"meshes\": [], \"world\": {\"environment\": {\"width\": 2, \"height\": 1, \"texels\": [1,1,1]}}}",
         "world.environment.texels: 3 numbers: a 2 x 1 image needs 6"},
        {"{\"version\": 1, \"meshes\": [], \"world\": {\"color\": [1,1,1], \"environment\": {}}}", "either 'environment'"},
        {"{\"version\": 1, \"meshes\": [], \"world\": {\"environment\": {\"width\": 2, \"height\": 1}}}", "needs either 'file' or 'width', 'height' and 'texels'"},
        {"{\"version\": 1, \"meshes\": [], \"world\": {\"environment\": {\"width\": 2, \"height\": 1, \"texels\": [1,1,1, 1,-1,1]}}}",
         "world.environment: dwv_scene_set_world_environment: texel (1, 0)"},
        {"{\"version\": 1, \"meshes\": [], \"world\": {\"environment\": {\"width\": 1, \"height\": 1, \"texels\": [1,1,1], \"interpolation\": \"smart\"}}}",
         "world.environment.interpolation"},
        {"{\"version\": 1, \"meshes\": [], \"lights\": [{\"kind\": \"spot\", \"spot_falloff\": \"cycles5\"}]}", "lights[0].spot_falloff"},
        {"{\"version\": 1, \"meshes\": [], \"lights\": [{\"kind\": \"spot\", \"spot_size\": 0}]}", "lights[0]: dwv_scene_add_light: spot_size"},
        {"{\"version\": 1, \"meshes\": [], \"lights\": [{\"kind\": \"spot\", \"angle\": 3}]}", "lights[0]: unknown key 'angle'"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        dwv_scene_t *scene = NULL;
        dwv_result_t r = dwv_scene_load_json(bad[i].json, strlen(bad[i].json), NULL, &scene, NULL);
        CHECK(r != DWV_SUCCESS && scene == NULL && message_has(bad[i].part), "bad file %zu: %s (%s)", i,
              dwv_last_error_message(), dwv_result_string(r));
        dwv_scene_release(scene);
    }
}

int main(void)
{
    test_scene_file();
    test_bad_environments();
    test_constant_equivalents();
    test_odd_maps();
    test_spot_over_plane();
    test_spot_input();
    return check_report("test_world_environment");
}
