/* The camera vertex's path rays from the pixel's stratified sampler (src/bake/shade.h, past the
 * walks' pairs) are unbiased: one hit point on a wax sphere that faces a sunlit diffuse wall (nearly
 * all its light is indirect, and depends on where its walks' exits send their paths: toward the
 * wall or away), shaded by dwvb_shade with a bake's own shader, G x N times:
 * - stratified (G pixel keys, N sample indices each, as a bake's pixel) against independent draws
 *   (G x N counter-based samplers), shared walks: stratification adds no bias;
 * - shared walks against channel walks (one per channel, their exits at pairs of their own),
 *   both stratified: a collision of the exits' pairs with another use in one layout (which ties the
 *   direction to the walk) would show as a difference.
 * Bounds: the means of the indirect light, the direct light and their sum within 5 standard errors
 * of their difference (each from the spread of its G group means, independent across keys); the
 * stratified indirect variance per sample below the independent one (measured 0.61x). Shown once to
 * catch a planted error: the shared walk's exit direction drawn from the walk's first pair puts
 * shared and channel walks' indirect means 7 standard errors apart (docs/speed.md, "The bowl's
 * variance"); with independent draws that collision is in both estimators of the first check, which
 * cannot see it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "api/scene_handle.h"
#include "bake/bake.h"
#include "bake/bake_internal.h"
#include "bake/shade.h"
#include "bake_scenes.h"
#include "check.h"
#include "kernel/rng.h"
#include <dwivedi.h>

#define GROUPS 4096u
#define PER_GROUP 16u

static dwv_scene_t *sphere_by_wall(void)
{
    /* The sun from the upper left lights the wall's face toward the sphere. */
    const double wall[6] = {1.3, -3.0, -3.0, 1.8, 3.0, 3.0}, sun[3] = {1.0, 0.0, -1.0}, world[3] = {0.02, 0.02, 0.02};
    return test_wax_and_white_box(0.0, 0.0, 0.0, 1.0, wall, sun, world);
}

typedef struct estimate {
    double mean[3], se[3]; /* of the indirect light, the direct light, their sum (RGB summed) */
    double per_sample[3];  /* the variance of a group's mean times its samples */
} estimate;

/* Shades `hit` GROUPS x PER_GROUP times: stratified (each group a pixel's key, its samples the
 * indices 0..PER_GROUP-1) or independent (each sample its own counter-based key). */
static estimate shade_many(const dwvb_shader *shader, const dwvg_hit *hit, dwvu_vec3 view, int stratified)
{
    double group_sum[3] = {0.0}, group_square[3] = {0.0};
    dwvb_tally tally = {0};
    for (uint32_t g = 0; g < GROUPS; ++g) {
        double sum[3] = {0.0};
        for (uint32_t i = 0; i < PER_GROUP; ++i) {
            uint64_t n = (uint64_t)g * PER_GROUP + i;
            dwvk_sampler sampler = stratified ? (dwvk_sampler){dwvk_rng_key(20u, g, 1u), i, 1}
                                              : (dwvk_sampler){dwvk_rng_key(20u, n, 2u), 0u, 0};
            uint64_t key_walk = dwvk_rng_key(20u, n, 3u + (uint64_t)stratified);
            dwvb_shade_parts parts;
            dwvb_shade(shader, hit, view, &sampler, 1u, key_walk, &parts, &tally);
            double v[3] = {0.0, 0.0, 0.0};
            for (int l = 0; l < DWVB_LOBE_COUNT; ++l)
                for (int c = 0; c < 3; ++c) {
                    v[0] += parts.indirect[l][c];
                    v[1] += parts.direct[l][c];
                }
            v[2] = v[0] + v[1];
            for (int k = 0; k < 3; ++k) sum[k] += v[k];
        }
        for (int k = 0; k < 3; ++k) {
            double m = sum[k] / PER_GROUP;
            group_sum[k] += m;
            group_square[k] += m * m;
        }
    }
    estimate e;
    for (int k = 0; k < 3; ++k) {
        e.mean[k] = group_sum[k] / GROUPS;
        double spread = (group_square[k] - GROUPS * e.mean[k] * e.mean[k]) / (GROUPS - 1.0);
        e.se[k] = sqrt(fmax(spread, 0.0) / GROUPS);
        /* The variance per sample of a pixel's estimate, stratification included. */
        e.per_sample[k] = spread * PER_GROUP;
    }
    return e;
}

static const char *const names[3] = {"indirect", "direct", "sum"};

/* Checks that two estimates agree within 5 standard errors of their difference. */
static void agree(const char *what, const estimate *a, const estimate *b)
{
    for (int k = 0; k < 3; ++k) {
        double z = (a->mean[k] - b->mean[k]) / sqrt(a->se[k] * a->se[k] + b->se[k] * b->se[k]);
        printf("%s, %-8s %.6f +- %.6f against %.6f +- %.6f: z %.2f, variance per sample ratio %.3f\n", what, names[k],
               a->mean[k], a->se[k], b->mean[k], b->se[k], z, a->per_sample[k] / b->per_sample[k]);
        CHECK(fabs(z) < 5.0, "%s, %s: means %.3f standard errors apart", what, names[k], z);
    }
}

/* The bake's shader for `scene` with classical walks, shared or one per channel. */
static dwvb_bake *start(dwvb_scene *scene, dwv_channel_walks_t walks)
{
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = o.height = 4;
    o.samples = 1;
    o.threads = 1;
    o.tile_size = 4;
    o.max_events = 100000;
    o.technique = DWV_TECHNIQUE_CLASSICAL;
    o.channel_walks = walks;
    dwvb_bake *bake = NULL;
    char message[256];
    if (dwvb_bake_start(scene, &o, &bake, message, sizeof message) != DWV_SUCCESS) {
        CHECK(0, "bake: %s", message);
        return NULL;
    }
    dwvb_bake_wait(bake, -1.0);
    return bake;
}

int main(void)
{
    dwv_scene_t *handle = sphere_by_wall();
    dwvb_scene *scene = dwv_scene_object(handle);
    dwvb_bake *shared = start(scene, DWV_CHANNEL_WALKS_SHARED), *separate = start(scene, DWV_CHANNEL_WALKS_SEPARATE);
    /* A point on the sphere's side toward the wall, seen from -y: no sun there (its normal
     * faces away from the sun), light from its walks and, through their exits, from the wall. */
    dwvu_vec3 origin = dwvu_v(0.85, -5.0, 0.2), view = dwvu_v(0.0, 1.0, 0.0);
    dwvg_hit hit;
    int found = dwvg_intersect(&scene->geometry, origin, view, 0.0, INFINITY, &hit);
    CHECK(found && hit.mesh == 0u, "the camera ray meets the sphere");
    if (shared && separate && found && hit.mesh == 0u) {
        CHECK(separate->shader.channel_walks && separate->shader.channel_walks[0], "the channels walk apart");
        estimate s = shade_many(&shared->shader, &hit, view, 1), d = shade_many(&shared->shader, &hit, view, 0);
        estimate c = shade_many(&separate->shader, &hit, view, 1);
        agree("stratified against independent", &s, &d);
        agree("shared against channel walks", &s, &c);
        CHECK(s.mean[0] > 10.0 * s.mean[1], "the point's light is mostly indirect (%g against direct %g)", s.mean[0],
              s.mean[1]);
        CHECK(s.per_sample[0] < d.per_sample[0], "stratified exits lower the indirect variance (%g against %g)",
              s.per_sample[0], d.per_sample[0]);
    }
    if (shared) dwvb_bake_free(shared);
    if (separate) dwvb_bake_free(separate);
    dwv_scene_release(handle);
    return check_report("test_stratified_paths");
}
