/* A UV bake texel's frame on its triangle (src/bake/uv_raster.c: dwvb_uv_texel_steps,
 * dwvb_uv_texel_footprint, dwvb_uv_jitter) against closed forms, and the bake's use of it:
 * - the footprint of a surface that is a linear map M of its UVs is 1/4 (|M e_u| / W + |M e_v| / H)
 *   (Cycles' compact differential of Blender's half-texel differentials), whatever the triangle;
 * - the jitter's points over an n x n grid of uniforms average to the centre exactly (the mean of
 *   a linear signal is its centre value) and reach +-1/4 texel (1 - 1/n) along x and y (the box of
 *   half a texel), points outside the triangle refused; a degenerate layout gives zero steps;
 * - a UV bake with subsurface_min_footprint 0.25 (Cycles 4.0-4.3) walks no channel whose radius
 *   is 10% below a quarter of the texel's footprint, and walks where it is 10% above (the box's
 *   faces: footprint 1/4 (L / (0.23 W) + L / (0.40 H))); the bake's jittered image is the same on
 *   1 and 2 threads;
 * - along a path the footprint is the first ray's grown as Cycles' differentials: with an
 *   orthographic camera it stays a pixel's width, so a cube whose radii are below a quarter of it,
 *   seen directly and in a rough glossy floor, never walks (it did at the floor's rays' hits before
 *   the rule applied along paths); with a perspective camera it is the path's length x the pixel's
 *   spread, so a cube seen only in the floor walks or not by that. Runs in about a second. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "bake/uv_raster.h"
#include "bake_scenes.h"
#include "check.h"
#include <dwivedi.h>

static uint64_t rng_state = 0x2545f4914f6cdd1dull;
static double uniform(void) /* xorshift64*, top 53 bits */
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ull) >> 11) * 0x1p-53;
}

/* Random triangles in UV and random linear maps P = M (u, v) + c: the footprint's closed form. */
static void test_footprint_closed_form(void)
{
    double worst = 0.0;
    for (int trial = 0; trial < 200; ++trial) {
        uint32_t w = 8u + (uint32_t)(uniform() * 500.0), h = 8u + (uint32_t)(uniform() * 500.0);
        float uv[6];
        for (int k = 0; k < 6; ++k) uv[k] = (float)uniform();
        double m[3][2], c[3];
        for (int i = 0; i < 3; ++i) {
            m[i][0] = 4.0 * uniform() - 2.0;
            m[i][1] = 4.0 * uniform() - 2.0;
            c[i] = uniform();
        }
        double p[3][3];
        for (int k = 0; k < 3; ++k)
            for (int i = 0; i < 3; ++i) p[k][i] = m[i][0] * uv[2 * k] + m[i][1] * uv[2 * k + 1] + c[i];
        double e1[3], e2[3];
        for (int i = 0; i < 3; ++i) {
            e1[i] = p[1][i] - p[0][i];
            e2[i] = p[2][i] - p[0][i];
        }
        double area2 = ((double)uv[2] - uv[0]) * w * (((double)uv[5] - uv[1]) * h) -
                       ((double)uv[4] - uv[0]) * w * (((double)uv[3] - uv[1]) * h);
        if (fabs(area2) < 1.0) continue; /* slivers: the closed form holds, but rounding grows */
        dwvb_uv_steps step;
        dwvb_uv_texel_steps(uv, w, h, &step);
        double mu = sqrt(m[0][0] * m[0][0] + m[1][0] * m[1][0] + m[2][0] * m[2][0]);
        double mv = sqrt(m[0][1] * m[0][1] + m[1][1] * m[1][1] + m[2][1] * m[2][1]);
        double expected = 0.25 * (mu / w + mv / h);
        double got = dwvb_uv_texel_footprint(e1, e2, &step);
        worst = fmax(worst, fabs(got - expected) / expected);
    }
    CHECK(worst < 1e-9, "footprint off its closed form by %.3g (relative)", worst);

    /* A degenerate layout (|A| <= FLT_EPSILON texels^2): no steps, no footprint, no jitter. */
    float flat[6] = {0.1f, 0.1f, 0.2f, 0.2f, 0.3f, 0.3f};
    dwvb_uv_steps step;
    dwvb_uv_texel_steps(flat, 64u, 64u, &step);
    CHECK(step.d[0][0] == 0.0 && step.d[0][1] == 0.0 && step.d[1][0] == 0.0 && step.d[1][1] == 0.0,
          "degenerate layout: steps %g %g %g %g", step.d[0][0], step.d[0][1], step.d[1][0], step.d[1][1]);
}

/* The jitter over an n x n grid of uniforms about a centre deep inside a triangle. */
static void test_jitter_box(void)
{
    const uint32_t w = 40u, h = 24u, n = 16u;
    float uv[6] = {0.1f, 0.2f, 0.9f, 0.15f, 0.4f, 0.95f};
    dwvb_uv_steps step;
    dwvb_uv_texel_steps(uv, w, h, &step);
    double b1 = 0.3, b2 = 0.35; /* the centre, in barycentrics */
    double cu = uv[0] + b1 * ((double)uv[2] - uv[0]) + b2 * ((double)uv[4] - uv[0]);
    double cv = uv[1] + b1 * ((double)uv[3] - uv[1]) + b2 * ((double)uv[5] - uv[1]);
    double sum_signal = 0.0, largest_x = 0.0, largest_y = 0.0;
    int refused = 0;
    for (uint32_t i = 0; i < n; ++i) {
        for (uint32_t j = 0; j < n; ++j) {
            double j1, j2;
            if (!dwvb_uv_jitter(&step, b1, b2, (i + 0.5) / n, (j + 0.5) / n, &j1, &j2)) {
                ++refused;
                continue;
            }
            double u = uv[0] + j1 * ((double)uv[2] - uv[0]) + j2 * ((double)uv[4] - uv[0]);
            double v = uv[1] + j1 * ((double)uv[3] - uv[1]) + j2 * ((double)uv[5] - uv[1]);
            sum_signal += 3.0 * u - 2.0 * v + 0.25; /* a linear signal of the UV position */
            largest_x = fmax(largest_x, fabs(u - cu) * w);
            largest_y = fmax(largest_y, fabs(v - cv) * h);
        }
    }
    double mean = sum_signal / (n * n), centre = 3.0 * cu - 2.0 * cv + 0.25;
    CHECK(refused == 0, "%d grid points refused deep inside the triangle", refused);
    CHECK(fabs(mean - centre) < 1e-12, "jittered mean %.15g, centre value %.15g", mean, centre);
    double edge = 0.25 * (1.0 - 1.0 / n); /* the grid's outermost points in a box of +-1/4 texel */
    CHECK(fabs(largest_x - edge) < 1e-9 && fabs(largest_y - edge) < 1e-9,
          "jitter reaches %.12g, %.12g texels, the half-texel box's grid %.12g", largest_x, largest_y, edge);

    /* Near corner 0 the box reaches outside: those points are refused, the inside ones kept. */
    double j1 = -1.0, j2 = -1.0;
    double near1 = 0.25 * fabs(step.d[0][0]) * 0.1, near2 = 0.25 * fabs(step.d[1][1]) * 0.1;
    int inside = 0, outside = 0;
    for (uint32_t i = 0; i < n; ++i)
        for (uint32_t j = 0; j < n; ++j) {
            if (dwvb_uv_jitter(&step, near1, near2, (i + 0.5) / n, (j + 0.5) / n, &j1, &j2)) {
                ++inside;
                CHECK(j1 > 0.0 && j2 > 0.0 && j1 + j2 < 1.0, "kept point (%g, %g) outside", j1, j2);
            } else {
                ++outside;
            }
        }
    CHECK(inside > 0 && outside > 0, "near a corner: %d kept, %d refused", inside, outside);
}

/* Bakes `scene` (target, size x size, `samples`, `threads`, classical walks) and releases it; the
 * walks the bake ran, and its image in *kept where kept is not NULL (else released). */
static uint64_t bake_walks(dwv_scene_t *scene, dwv_bake_target_t target, uint32_t size, uint32_t samples,
                           uint32_t threads, dwv_image_t **kept)
{
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.target = target;
    o.width = o.height = size;
    o.samples = samples;
    o.threads = threads;
    o.seed = 3u;
    o.technique = DWV_TECHNIQUE_CLASSICAL;
    dwv_image_t *image = NULL;
    if (dwv_bake(scene, &o, &image) != DWV_SUCCESS) {
        fprintf(stderr, "bake: %s\n", dwv_last_error_message());
        exit(2);
    }
    dwv_bake_stats_t stats = DWV_BAKE_STATS_INIT;
    if (dwv_image_stats(image, &stats) != DWV_SUCCESS) exit(2);
    CHECK(stats.warnings == 0u, "bake met %llu warnings", (unsigned long long)stats.warnings);
    if (kept) *kept = image;
    else dwv_image_release(image);
    dwv_scene_release(scene);
    return stats.walks;
}

/* A 1 m box of a 4.x subsurface material whose radii are `factor` x a quarter of its faces'
 * texel footprint, UV-baked at 32 x 32 with min_footprint 0.25: the walks it ran. */
static uint64_t box_walks(double factor, uint32_t threads, dwv_image_t **kept)
{
    const uint32_t size = 32u;
    double footprint = 0.25 * (1.0 / (0.23 * size) + 1.0 / (0.40 * size)); /* the same on every face */
    dwv_material_t m = DWV_MATERIAL_INIT;
    m.subsurface_model = DWV_SUBSURFACE_MODEL_BLENDER4_RANDOM_WALK;
    m.subsurface_weight = 1.0;
    m.subsurface_scale = 1.0;
    m.subsurface_min_footprint = 0.25;
    m.specular = 0.0;
    for (int c = 0; c < 3; ++c) m.subsurface_radius[c] = factor * 0.25 * footprint * (1.0 + 0.02 * c);
    dwv_scene_t *scene;
    if (dwv_scene_create(&scene) != DWV_SUCCESS) exit(2);
    test_mesh box = test_box(0.0, 0.0, 0.0, 1.0, 1.0, 1.0);
    test_add(scene, &box, &m);
    test_mesh_free(&box);
    dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
    sun.strength = 3.0;
    sun.direction[0] = -0.3;
    sun.direction[1] = -0.5;
    sun.direction[2] = -0.8;
    double world[3] = {0.2, 0.2, 0.2};
    if (dwv_scene_add_light(scene, &sun) || dwv_scene_set_world(scene, world, 1.0) || dwv_scene_commit(scene)) {
        fprintf(stderr, "test scene: %s\n", dwv_last_error_message());
        exit(2);
    }
    return bake_walks(scene, DWV_BAKE_UV, size, 4u, threads, kept);
}

static void test_bake_footprint_rule(void)
{
    uint64_t below = box_walks(0.9, 2u, NULL), above = box_walks(1.1, 2u, NULL);
    CHECK(below == 0u, "radii 10%% below a quarter of the texel footprint still walked %llu times",
          (unsigned long long)below);
    CHECK(above > 0u, "radii 10%% above a quarter of the texel footprint never walked");
    dwv_image_t *one = NULL, *two = NULL;
    box_walks(1.1, 1u, &one);
    box_walks(1.1, 2u, &two);
    dwv_image_info_t a = DWV_IMAGE_INFO_INIT, b = DWV_IMAGE_INFO_INIT;
    int same = dwv_image_info(one, &a) == DWV_SUCCESS && dwv_image_info(two, &b) == DWV_SUCCESS &&
               a.width == b.width && a.height == b.height;
    for (size_t i = 0; same && i < 4u * (size_t)a.width * a.height; ++i) same = a.rgba[i] == b.rgba[i];
    CHECK(same, "the jittered UV bake differs between 1 and 2 threads");
    dwv_image_release(one);
    dwv_image_release(two);
}

/* Along a path (Cycles' compact differentials): `camera` over a rough glossy-only floor (no diffuse
 * lobe, so the floor's rays keep no diffuse ancestor) with a subsurface cube `cube` (x0, y0, x1,
 * y1, height) of radii `radius` standing on it, 4.0-4.3's rule on: the walks of a 16 x 16 camera
 * bake. */
static uint64_t glossy_floor_walks(const dwv_camera_t *camera, const double cube[5], double radius)
{
    dwv_material_t floor = DWV_MATERIAL_INIT, wax = DWV_MATERIAL_INIT;
    floor.subsurface_weight = 0.0;
    floor.base_color[0] = floor.base_color[1] = floor.base_color[2] = 0.0;
    floor.specular_model = DWV_SPECULAR_PRINCIPLED_V2;
    floor.specular = 0.5;
    floor.roughness = 0.5;
    floor.ior = 1.5;
    wax.subsurface_model = DWV_SUBSURFACE_MODEL_BLENDER4_RANDOM_WALK;
    wax.subsurface_weight = 1.0;
    wax.subsurface_scale = 1.0;
    wax.subsurface_min_footprint = 0.25;
    wax.specular = 0.0;
    for (int c = 0; c < 3; ++c) wax.subsurface_radius[c] = radius;
    dwv_scene_t *scene;
    if (dwv_scene_create(&scene) != DWV_SUCCESS) exit(2);
    test_mesh ground = test_box(-6.0, -6.0, -0.1, 6.0, 6.0, 0.0);
    test_mesh box = test_box(cube[0], cube[1], 0.0, cube[2], cube[3], cube[4]);
    test_add(scene, &ground, &floor);
    test_add(scene, &box, &wax);
    test_mesh_free(&ground);
    test_mesh_free(&box);
    dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
    sun.strength = 3.0;
    sun.direction[0] = -0.5;
    sun.direction[2] = -0.8;
    if (dwv_scene_add_light(scene, &sun) || dwv_scene_set_camera(scene, camera) || dwv_scene_commit(scene)) {
        fprintf(stderr, "test scene: %s\n", dwv_last_error_message());
        exit(2);
    }
    return bake_walks(scene, DWV_BAKE_CAMERA, 16u, 8u, 2u, NULL);
}

static void test_path_footprint_rule(void)
{
    /* Orthographic (footprint a pixel's width 3 / 16 everywhere, dD = 0), the cube in view: its
     * camera hits and the floor's rays' hits on it obey the rule alike. */
    dwv_camera_t ortho = test_ortho_camera(0.0, 0.0, 5.0, 3.0);
    const double centre[5] = {-0.5, -0.5, 0.5, 0.5, 1.0}, quarter_pixel = 0.25 * 3.0 / 16.0;
    uint64_t below = glossy_floor_walks(&ortho, centre, 0.9 * quarter_pixel);
    uint64_t above = glossy_floor_walks(&ortho, centre, 1.1 * quarter_pixel);
    CHECK(below == 0u, "orthographic: radii 10%% below a quarter pixel walked %llu times", (unsigned long long)below);
    CHECK(above > 0u, "orthographic: radii 10%% above a quarter pixel never walked");
    /* Perspective 50 mm / 36 mm from 5 m up (the floor seen within |x|, |y| < 1.8 m, pixel spreads
     * 0.039-0.045), the cube out of view at x 2.5-3.5 m: seen only in the floor, at a footprint of
     * (t0 + t1) x spread > 6 x 0.041, a quarter of it > 0.06 on every path (the floor's segment
     * alone, t1 x spread, would be a quarter of at most 0.27, above 0.05 on most). Radii 0.05: no
     * walk; 0.2, above a quarter of any path's footprint: walks. */
    dwv_camera_t perspective = DWV_CAMERA_INIT;
    perspective.transform[11] = 5.0;
    const double aside[5] = {2.5, -0.5, 3.5, 0.5, 1.0};
    below = glossy_floor_walks(&perspective, aside, 0.05);
    above = glossy_floor_walks(&perspective, aside, 0.2);
    CHECK(below == 0u, "perspective: radii below a quarter of the paths' footprints walked %llu times",
          (unsigned long long)below);
    CHECK(above > 0u, "perspective: radii above a quarter of the paths' footprints never walked");
}

int main(void)
{
    test_footprint_closed_form();
    test_jitter_box();
    test_bake_footprint_rule();
    test_path_footprint_rule();
    return check_report("test_uv_texel");
}
