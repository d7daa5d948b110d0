/* Indirect light (issue 18 item 4): Cycles' light-path limits and Russian roulette.
 *
 * - One bounce kept: max_bounces = 0, and an options struct that ends before the light-path fields
 *   (an older caller), bake a sphere-on-ground scene to exactly the image the library made before
 *   indirect light existed (its FNV-1a hash, taken from that library's bake of the same options).
 * - Furnace: the inside of a sphere of albedo a around a point light at its centre. On a sphere
 *   the form factor between two surface elements is dA / (4 pi R^2), the same for every pair, so
 *   one diffuse bounce turns any radiosity into a uniform a x its mean: with the direct light
 *   (nearly) uniform, the radiance after N diffuse bounces is L_0 (1 + a + ... + a^N). Bounds:
 *   5 standard errors plus 0.05% for the UV sphere's facets (measured: -0.005% to -0.007%). Limited by diffuse_bounces and by max_bounces alike.
 * - Russian roulette is unbiased: 6 bounces with roulette from the second bounce (Cycles' default)
 *   against none (min_light_bounces 1024) within 5 standard errors of the difference.
 * - Glossy and diffuse bounces limited apart (a limit of 0 for the only kind a scene scatters is
 *   the one-bounce image, bit for bit).
 * - The same image for 1 and 2 threads with indirect light; no NaN anywhere; bad limits refused. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake_scenes.h"
#include "check.h"
#include <dwivedi.h>

typedef struct baked {
    double mean, sigma; /* red channel over the pixels, and the standard error of that mean */
    uint64_t hash;      /* FNV-1a of the RGBA floats */
    float *rgba;
    size_t pixels;
    int finite;
} baked;

static baked bake(dwv_scene_t *scene, const dwv_bake_options_t *o)
{
    baked b = {0.0, 0.0, 0xcbf29ce484222325ull, NULL, 0, 1};
    dwv_image_t *image = NULL;
    dwv_result_t r = dwv_bake(scene, o, &image);
    CHECK(r == DWV_SUCCESS, "bake: %s", dwv_last_error_message());
    if (r != DWV_SUCCESS) return b;
    dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
    dwv_image_info(image, &info);
    b.pixels = (size_t)info.width * info.height;
    b.rgba = malloc(4 * b.pixels * sizeof(float));
    memcpy(b.rgba, info.rgba, 4 * b.pixels * sizeof(float));
    const unsigned char *bytes = (const unsigned char *)info.rgba;
    for (size_t i = 0; i < 4 * b.pixels * sizeof(float); ++i) b.hash = (b.hash ^ bytes[i]) * 0x100000001b3ull;
    double sum = 0.0, variance = 0.0;
    for (size_t i = 0; i < b.pixels; ++i) {
        for (int c = 0; c < 4; ++c) b.finite &= isfinite(info.rgba[4 * i + c]) != 0;
        sum += info.rgba[4 * i];
        variance += info.variance[3 * i];
    }
    b.mean = sum / (double)b.pixels;
    b.sigma = sqrt(variance) / (double)b.pixels;
    dwv_image_release(image);
    return b;
}

/* A wax sphere (the default subsurface material) resting on a white diffuse ground, a sun from
 * above and a dim world, seen from above at an angle: ground and sphere light each other. */
static dwv_scene_t *sphere_on_ground(void)
{
    const double ground[6] = {-4.0, -4.0, -0.5, 4.0, 4.0, 0.0}, sun[3] = {0.5, 0.0, -1.0}, world[3] = {0.05, 0.06, 0.08};
    return test_wax_and_white_box(0.0, 0.0, 1.0, 1.0, ground, sun, world);
}

static dwv_bake_options_t small_options(void)
{
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = o.height = 16;
    o.samples = 8;
    o.seed = 18;
    o.threads = 1;
    o.technique = DWV_TECHNIQUE_CLASSICAL;
    return o;
}

/* The hash of sphere_on_ground baked with small_options by the library before indirect light
 * (main at b7e7fea, whose dwv_bake_options_t ended at `reserved`). */
#define ONE_BOUNCE_HASH 0x0391e2e61a59dbb2ull

static void test_one_bounce_kept(void)
{
    dwv_scene_t *scene = sphere_on_ground();
    dwv_bake_options_t o = small_options();
    o.max_bounces = 0;
    baked zero = bake(scene, &o);
    dwv_bake_options_t old = small_options();
    old.struct_size = (uint32_t)offsetof(dwv_bake_options_t, max_bounces);
    baked before = bake(scene, &old);
    printf("one bounce: hash %016llx (old struct %016llx, reference %016llx)\n", (unsigned long long)zero.hash,
           (unsigned long long)before.hash, (unsigned long long)ONE_BOUNCE_HASH);
    CHECK(zero.hash == ONE_BOUNCE_HASH, "max_bounces 0: hash %016llx, the one-bounce image is %016llx",
          (unsigned long long)zero.hash, (unsigned long long)ONE_BOUNCE_HASH);
    CHECK(before.hash == ONE_BOUNCE_HASH, "an older options struct: hash %016llx, expected %016llx",
          (unsigned long long)before.hash, (unsigned long long)ONE_BOUNCE_HASH);
    /* Indirect light on (Blender's defaults): brighter where ground and sphere face each other,
     * and the same image from 1 and 2 threads. */
    dwv_bake_options_t on = small_options();
    baked one = bake(scene, &on);
    on.threads = 2;
    baked two = bake(scene, &on);
    /* (at 64 samples, where the difference is well above the noise) */
    o.samples = on.samples = 64;
    baked zero64 = bake(scene, &o), on64 = bake(scene, &on);
    CHECK(one.finite && two.finite && zero.finite, "NaN or infinity in an image");
    CHECK(one.rgba && two.rgba && memcmp(one.rgba, two.rgba, 4 * one.pixels * sizeof(float)) == 0,
          "indirect light: 1 and 2 threads differ");
    printf("sphere on ground: one bounce %.5f +- %.5f, with indirect light %.5f +- %.5f\n", zero64.mean, zero64.sigma,
           on64.mean, on64.sigma);
    CHECK(on64.finite && zero64.finite, "NaN or infinity in an image");
    CHECK(on64.mean > zero64.mean + 5.0 * hypot(on64.sigma, zero64.sigma), "indirect light adds nothing: %.5f vs %.5f",
          on64.mean, zero64.mean);
    free(zero.rgba), free(before.rgba), free(one.rgba), free(two.rgba), free(zero64.rgba), free(on64.rgba);
    dwv_scene_release(scene);
}

#define ALBEDO 0.6

/* The inside of a sphere (radius 1, `rings` x 2 `rings` quads) of material `wall` around a point
 * light at (light_x, 0, 0) of radius light_radius, seen from the centre toward +x. */
static dwv_scene_t *sphere_room(const dwv_material_t *wall, uint32_t rings, double light_x, double light_radius)
{
    dwv_scene_t *scene;
    dwv_scene_create(&scene);
    test_mesh sphere = test_sphere(0.0, 0.0, 0.0, 1.0, rings, 2u * rings);
    test_add(scene, &sphere, wall);
    test_mesh_free(&sphere);
    dwv_light_desc_t point = DWV_LIGHT_DESC_INIT;
    point.kind = DWV_LIGHT_POINT;
    point.strength = 100.0;
    point.position[0] = light_x;
    point.radius = light_radius;
    dwv_scene_add_light(scene, &point);
    dwv_camera_t camera = DWV_CAMERA_INIT;
    /* camera -z toward world +x */
    const double turn[12] = {0.0, 0.0, -1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0};
    memcpy(camera.transform, turn, sizeof turn);
    dwv_scene_set_camera(scene, &camera);
    CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit: %s", dwv_last_error_message());
    return scene;
}

/* The furnace: Lambertian walls of albedo ALBEDO, the light at the centre. */
static dwv_scene_t *furnace(void)
{
    dwv_material_t wall = DWV_MATERIAL_INIT;
    wall.kind = DWV_MATERIAL_DIFFUSE;
    wall.base_color[0] = wall.base_color[1] = wall.base_color[2] = ALBEDO;
    return sphere_room(&wall, 48, 0.0, 0.01);
}

static dwv_bake_options_t furnace_options(uint32_t max, uint32_t diffuse, uint32_t min_light)
{
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = o.height = 8;
    o.samples = 512;
    o.seed = 5;
    o.max_bounces = max;
    o.diffuse_bounces = diffuse;
    o.min_light_bounces = min_light;
    return o;
}

static void test_furnace(void)
{
    dwv_scene_t *scene = furnace();
    dwv_bake_options_t o = furnace_options(12, 0, 1024);
    baked direct = bake(scene, &o);
    CHECK(direct.finite && direct.mean > 0.0, "furnace: no direct light");
    double series = 1.0, power = 1.0;
    for (uint32_t n = 1; n <= 3; ++n) {
        power *= ALBEDO;
        series += power;
        double want = direct.mean * series;
        for (int by_total = 0; by_total < 2; ++by_total) {
            dwv_bake_options_t limited = by_total ? furnace_options(n, 12, 1024) : furnace_options(12, n, 1024);
            baked b = bake(scene, &limited);
            double bound = 5.0 * hypot(b.sigma, series * direct.sigma) + 0.0005 * want;
            printf("furnace, %u %s bounces: %.6f +- %.6f, expected %.6f (%.3f%% off, bound %.3f%%)\n", n,
                   by_total ? "total" : "diffuse", b.mean, b.sigma, want, 100.0 * (b.mean / want - 1.0),
                   100.0 * bound / want);
            CHECK(b.finite, "furnace: NaN");
            CHECK(fabs(b.mean - want) < bound, "furnace %u bounces: %.6f, expected %.6f +- %.6f", n, b.mean, want, bound);
            free(b.rgba);
        }
    }
    /* Russian roulette from the second bounce (Cycles' default) against none. */
    dwv_bake_options_t rr = furnace_options(6, 6, 0), plain = furnace_options(6, 6, 1024);
    rr.samples = 4096;
    baked with = bake(scene, &rr), without = bake(scene, &plain);
    double bound = 5.0 * hypot(with.sigma, without.sigma);
    printf("furnace, 6 bounces: roulette %.6f +- %.6f, none %.6f +- %.6f (difference %.6f, bound %.6f)\n", with.mean,
           with.sigma, without.mean, without.sigma, with.mean - without.mean, bound);
    CHECK(with.finite && without.finite, "roulette: NaN");
    CHECK(fabs(with.mean - without.mean) < bound, "roulette biased: %.6f vs %.6f (bound %.6f)", with.mean,
          without.mean, bound);
    free(direct.rgba), free(with.rgba), free(without.rgba);
    dwv_scene_release(scene);
}

/* Each kind of bounce is counted and limited apart: the furnace's walls made a pure specular
 * layer (4.x+ Principled, black base colour, IOR 4 at Specular IOR Level 1, roughness 0.3)
 * scatter only glossy bounces, the Lambertian walls only diffuse ones. A limit of 0 for the kind they scatter leaves the one-bounce
 * image bit for bit (a path ray is drawn but ends before it is traced); 2 adds light. */
static void test_bounce_kinds(void)
{
    for (int glossy = 0; glossy < 2; ++glossy) {
        dwv_material_t wall = DWV_MATERIAL_INIT;
        wall.kind = DWV_MATERIAL_DIFFUSE;
        wall.base_color[0] = wall.base_color[1] = wall.base_color[2] = glossy ? 0.0 : ALBEDO;
        if (glossy) {
            wall.specular_model = DWV_SPECULAR_PRINCIPLED_V2;
            wall.specular = 1.0; /* F0 = 2 x ((4 - 1) / (4 + 1))^2 = 0.72: a bright glossy wall */
            wall.ior = 4.0;
            wall.roughness = 0.3;
        }
        dwv_scene_t *scene = sphere_room(&wall, 24, 0.3, 0.05);
        dwv_bake_options_t o = furnace_options(12, 4, 0);
        o.samples = 64;
        o.max_bounces = 0;
        baked one = bake(scene, &o);
        o.max_bounces = 12;
        if (glossy) o.glossy_bounces = 0;
        else o.diffuse_bounces = 0;
        baked none = bake(scene, &o);
        if (glossy) o.glossy_bounces = 2;
        else o.diffuse_bounces = 2;
        baked two = bake(scene, &o);
        const char *kind = glossy ? "glossy" : "diffuse";
        printf("%s walls: one bounce %.6f, %s_bounces 0 %.6f, 2 %.6f +- %.6f\n", kind, one.mean, kind, none.mean, two.mean,
               two.sigma);
        CHECK(one.hash == none.hash, "%s walls: %s_bounces 0 is not the one-bounce image", kind, kind);
        CHECK(two.finite && two.mean > one.mean + 5.0 * hypot(two.sigma, one.sigma), "%s walls: 2 %s bounces add nothing",
              kind, kind);
        free(one.rgba), free(none.rgba), free(two.rgba);
        dwv_scene_release(scene);
    }
}

static void test_bad_limits(void)
{
    dwv_scene_t *scene = furnace();
    dwv_image_t *image = NULL;
    dwv_bake_options_t o = furnace_options(1025, 4, 0);
    CHECK(dwv_bake(scene, &o, &image) == DWV_ERROR_OUT_OF_RANGE && !image, "max_bounces 1025 accepted");
    CHECK(strstr(dwv_last_error_message(), "max_bounces = 1025") != NULL, "message: %s", dwv_last_error_message());
    o = furnace_options(4, 4, 2000);
    CHECK(dwv_bake(scene, &o, &image) == DWV_ERROR_OUT_OF_RANGE && !image, "min_light_bounces 2000 accepted");
    o = furnace_options(4, 4, 0);
    o.subsurface_after_diffuse = (dwv_subsurface_after_diffuse_t)3;
    CHECK(dwv_bake(scene, &o, &image) == DWV_ERROR_INVALID_ARGUMENT && !image, "subsurface_after_diffuse 3 accepted");
    dwv_scene_release(scene);
}

int main(void)
{
    test_one_bounce_kept();
    test_furnace();
    test_bounce_kinds();
    test_bad_limits();
    return check_report("test_indirect_light");
}
