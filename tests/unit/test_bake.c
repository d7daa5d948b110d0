/* Bakes through the public API: energy conservation of a closed albedo-1 medium under a white
 * world, determinism across threads and tiles, progress, cancel, budgets, UV bakes, and refused
 * inputs. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "api_checks.h"
#include "bake_scenes.h"
#include "check.h"
#include <dwivedi.h>

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static dwv_material_t white_medium(double r0, double r1, double r2)
{
    dwv_material_t m = DWV_MATERIAL_INIT;
    for (int c = 0; c < 3; ++c) m.subsurface_color[c] = 1.0;
    m.subsurface_radius[0] = r0;
    m.subsurface_radius[1] = r1;
    m.subsurface_radius[2] = r2;
    m.subsurface_scale = 1.0;
    return m;
}

/* A committed scene: a sphere of radius 1 of `material` under a white world of radiance 1, seen
 * by an orthographic camera from +z. */
static dwv_scene_t *sphere_scene(const dwv_material_t *material)
{
    dwv_scene_t *scene;
    if (dwv_scene_create(&scene) != DWV_SUCCESS) exit(2);
    test_mesh sphere = test_sphere(0.0, 0.0, 0.0, 1.0, 24, 48);
    test_add(scene, &sphere, material);
    test_mesh_free(&sphere);
    double white[3] = {1.0, 1.0, 1.0};
    dwv_camera_t camera = test_ortho_camera(0.0, 0.0, 5.0, 2.4);
    if (dwv_scene_set_world(scene, white, 1.0) || dwv_scene_set_camera(scene, &camera) || dwv_scene_commit(scene)) {
        fprintf(stderr, "sphere scene: %s\n", dwv_last_error_message());
        exit(2);
    }
    return scene;
}

/* The mean of channel c over all pixels and its standard error from the variance layer (pixel
 * means are independent). */
static void image_mean(const dwv_image_t *image, int c, double *mean, double *sigma)
{
    dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
    dwv_image_info(image, &info);
    size_t n = (size_t)info.width * info.height;
    double sum = 0.0, variance = 0.0;
    for (size_t i = 0; i < n; ++i) {
        sum += info.rgba[4 * i + c];
        variance += info.variance[3 * i + c];
    }
    *mean = sum / (double)n;
    *sigma = sqrt(variance) / (double)n;
}

/* Energy: inside a closed medium of single-scattering albedo alpha every walk leaves unless
 * absorbed, and a convex exit sees the whole white world, so each pixel's expectation is
 * E[alpha^events] >= 1 - (1 - alpha) E[events] (Bernoulli), with alpha = 0.999999 (Cycles'
 * clamp of the inversion fit at colour 1). Every pixel, sphere or world, has expectation in
 * [1 - loss, 1]: each channel's image mean must lie within 5 standard errors (from the variance
 * layer) of that range. */
static void test_energy(void)
{
    static const dwv_technique_t techniques[] = {DWV_TECHNIQUE_AUTO, DWV_TECHNIQUE_CLASSICAL, DWV_TECHNIQUE_POE,
                                                 DWV_TECHNIQUE_CLOSEST, DWV_TECHNIQUE_INCIDENT,
                                                 DWV_TECHNIQUE_BACKWARD, DWV_TECHNIQUE_CYCLES};
    dwv_material_t grey = white_medium(0.5, 0.5, 0.5), rgb = white_medium(0.5, 0.35, 0.25);
    for (int which = 0; which < 2; ++which) {
        dwv_scene_t *scene = sphere_scene(which ? &rgb : &grey);
        for (size_t t = 0; t < sizeof techniques / sizeof *techniques; ++t) {
            dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
            o.width = o.height = 16;
            o.samples = which ? 32 : 16;
            o.technique = techniques[t];
            o.seed = 7;
            dwv_image_t *image = NULL;
            dwv_result_t r = dwv_bake(scene, &o, &image);
            CHECK(r == DWV_SUCCESS, "bake: %s", dwv_last_error_message());
            if (r != DWV_SUCCESS) continue;
            dwv_bake_stats_t st = DWV_BAKE_STATS_INIT;
            dwv_image_stats(image, &st);
            double loss = 1e-6 * (double)st.events / (double)(st.walks ? st.walks : 1u);
            CHECK(st.walks > 0 && (st.features & DWV_FEATURE_SUBSURFACE), "walks %llu features %x",
                  (unsigned long long)st.walks, st.features);
            /* Coloured media walk their channels together (rgb walks) or, where auto's pilot
             * chooses so, apart (channel walks); grey ones walk once. */
            int rgb_walks = (st.features & DWV_FEATURE_RGB_WALKS) != 0,
                channel_walks = (st.features & DWV_FEATURE_CHANNEL_WALKS) != 0;
            CHECK(which == 1 ? rgb_walks + channel_walks == 1 && (!channel_walks || techniques[t] == DWV_TECHNIQUE_AUTO)
                             : !rgb_walks && !channel_walks,
                  "rgb walks feature %x", st.features);
            double mean[3], sigma[3];
            for (int c = 0; c < 3; ++c) {
                image_mean(image, c, &mean[c], &sigma[c]);
                CHECK(mean[c] >= 1.0 - loss - 5.0 * sigma[c] - 1e-12 && mean[c] <= 1.0 + 5.0 * sigma[c] + 1e-12,
                      "%s %s channel %d: mean %.9f, loss bound %.3g, sigma %.3g", which ? "rgb" : "grey",
                      dwv_technique_name(techniques[t]), c, mean[c], loss, sigma[c]);
            }
            printf("energy %s %-9s mean %.6f %.6f %.6f  sigma %.1e %.1e %.1e  events/walk %.1f\n", which ? "rgb " : "grey",
                   dwv_technique_name(techniques[t]), mean[0], mean[1], mean[2], sigma[0], sigma[1], sigma[2],
                   (double)st.events / (double)st.walks);
            dwv_image_release(image);
        }
        dwv_scene_release(scene);
    }
}

/* A scene with everything: an RGB medium sphere, a diffuse floor, point, area and sun lights. */
static dwv_scene_t *mixed_scene(void)
{
    dwv_scene_t *scene;
    if (dwv_scene_create(&scene) != DWV_SUCCESS) exit(2);
    dwv_material_t skin = white_medium(0.3, 0.15, 0.08);
    skin.subsurface_color[0] = 0.9;
    skin.subsurface_color[1] = 0.6;
    skin.subsurface_color[2] = 0.4;
    skin.subsurface_weight = 0.8;
    test_mesh sphere = test_sphere(0.0, 0.0, 1.0, 1.0, 16, 32);
    test_add(scene, &sphere, &skin);
    test_mesh_free(&sphere);
    dwv_material_t floor_material = DWV_MATERIAL_INIT;
    floor_material.kind = DWV_MATERIAL_DIFFUSE;
    test_mesh floor = test_box(-4.0, -4.0, -0.1, 4.0, 4.0, 0.0);
    test_add(scene, &floor, &floor_material);
    test_mesh_free(&floor);
    dwv_light_desc_t point = DWV_LIGHT_DESC_INIT, area = DWV_LIGHT_DESC_INIT;
    point.kind = DWV_LIGHT_POINT;
    point.position[0] = 2.0;
    point.position[2] = 3.0;
    point.strength = 400.0;
    point.radius = 0.2;
    area.kind = DWV_LIGHT_AREA_DISK;
    area.transform[3] = -1.0;
    area.transform[11] = 4.0;
    area.strength = 300.0;
    double sky[3] = {0.2, 0.3, 0.5};
    dwv_camera_t camera = DWV_CAMERA_INIT;
    camera.transform[7] = -0.5;
    camera.transform[11] = 8.0;
    if (dwv_scene_add_light(scene, &point) || dwv_scene_add_light(scene, &area) ||
        dwv_scene_set_world(scene, sky, 1.0) || dwv_scene_set_camera(scene, &camera) || dwv_scene_commit(scene)) {
        fprintf(stderr, "mixed scene: %s\n", dwv_last_error_message());
        exit(2);
    }
    return scene;
}

static void test_determinism(void)
{
    dwv_scene_t *scene = mixed_scene();
    static const uint32_t threads[] = {1, 2, 3, 3};
    static const uint32_t tiles[] = {32, 7, 5, 16};
    dwv_image_info_t first = DWV_IMAGE_INFO_INIT;
    dwv_image_t *first_image = NULL;
    uint64_t first_events = 0;
    for (int i = 0; i < 4; ++i) {
        dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
        o.width = 24;
        o.height = 18;
        o.samples = 6;
        o.threads = threads[i];
        o.tile_size = tiles[i];
        o.seed = 42;
        dwv_image_t *image = NULL;
        CHECK(dwv_bake(scene, &o, &image) == DWV_SUCCESS, "bake: %s", dwv_last_error_message());
        if (!image) continue;
        dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
        dwv_image_info(image, &info);
        dwv_bake_stats_t st = DWV_BAKE_STATS_INIT;
        dwv_image_stats(image, &st);
        CHECK(st.threads == threads[i], "threads %u", st.threads);
        int finite = 1;
        for (size_t k = 0; k < 4u * 24u * 18u; ++k) finite &= isfinite(info.rgba[k]) && info.rgba[k] >= 0.0f;
        CHECK(finite, "pixels finite and non-negative");
        CHECK(st.features & DWV_FEATURE_DIRECT_LIGHTS && st.features & DWV_FEATURE_DIFFUSE_SURFACES &&
                  st.features & DWV_FEATURE_WORLD_LIGHT && st.features & DWV_FEATURE_RGB_WALKS,
              "features %x", st.features);
        if (i == 0) {
            first = info;
            first_image = image;
            first_events = st.events;
            continue;
        }
        CHECK(memcmp(first.rgba, info.rgba, 4u * 24u * 18u * sizeof(float)) == 0, "rgba differs with %u threads, tile %u",
              threads[i], tiles[i]);
        CHECK(memcmp(first.variance, info.variance, 3u * 24u * 18u * sizeof(float)) == 0, "variance differs (%u threads)",
              threads[i]);
        CHECK(memcmp(first.samples, info.samples, 24u * 18u * sizeof(uint32_t)) == 0, "samples differ");
        CHECK(st.events == first_events, "events %llu vs %llu", (unsigned long long)st.events,
              (unsigned long long)first_events);
        dwv_image_release(image);
    }
    /* A different seed gives a different image (the test above could not fail otherwise). */
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = 24;
    o.height = 18;
    o.samples = 6;
    o.seed = 43;
    dwv_image_t *other = NULL;
    CHECK(dwv_bake(scene, &o, &other) == DWV_SUCCESS, "bake: %s", dwv_last_error_message());
    if (other && first_image) {
        dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
        dwv_image_info(other, &info);
        CHECK(memcmp(first.rgba, info.rgba, 4u * 24u * 18u * sizeof(float)) != 0, "seed 43 gave seed 42's image");
    }
    dwv_image_release(other);
    dwv_image_release(first_image);
    dwv_scene_release(scene);
}

typedef struct progress_log {
    int calls, done_calls, cancel_after;
    double last_fraction;
} progress_log;

static int32_t on_progress(void *user, const dwv_bake_progress_t *p)
{
    progress_log *log = user;
    ++log->calls;
    if (p->done) ++log->done_calls;
    log->last_fraction = p->fraction;
    return log->cancel_after > 0 && log->calls >= log->cancel_after;
}

static void test_cancel_and_budgets(void)
{
    dwv_scene_t *scene = mixed_scene();
    /* Cancel from another thread (this one) while it runs. */
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = o.height = 48;
    o.samples = 1u << 24;
    o.threads = 2;
    progress_log log = {0, 0, 0, 0.0};
    o.progress = on_progress;
    o.progress_user = &log;
    dwv_bake_t *bake = NULL;
    CHECK(dwv_bake_start(scene, &o, &bake) == DWV_SUCCESS, "start: %s", dwv_last_error_message());
    if (bake) {
        int32_t done = 1;
        CHECK(dwv_bake_wait(bake, 0.3, &done) == DWV_SUCCESS && done == 0, "still running after 0.3 s");
        dwv_bake_progress_t p = DWV_BAKE_PROGRESS_INIT;
        CHECK(dwv_bake_progress(bake, &p) == DWV_SUCCESS && p.done == 0 && p.fraction < 1.0, "progress %g", p.fraction);
        double t0 = now();
        CHECK(dwv_bake_cancel(bake) == DWV_SUCCESS, "cancel");
        CHECK(dwv_bake_wait(bake, 10.0, &done) == DWV_SUCCESS && done == 1, "ended after cancel");
        double latency = now() - t0;
        printf("cancel: ended %.1f ms after dwv_bake_cancel (%d progress calls)\n", 1e3 * latency, log.calls);
        dwv_image_t *image = (dwv_image_t *)&log;
        prime_message();
        CHECK(dwv_bake_finish(bake, &image) == DWV_ERROR_CANCELLED && image == NULL, "finish after cancel");
        CHECK(fresh_message_with("cancel"), "message %s", dwv_last_error_message());
        CHECK(log.done_calls == 1, "one final progress call, got %d", log.done_calls);
        dwv_bake_release(bake);
    }
    /* A callback that returns non-zero cancels. */
    log = (progress_log){0, 0, 2, 0.0};
    dwv_image_t *image = NULL;
    CHECK(dwv_bake(scene, &o, &image) == DWV_ERROR_CANCELLED && image == NULL, "callback cancel: %s",
          dwv_last_error_message());
    /* Time budget: stops long before the samples; pixels keep what they got. */
    o.progress = NULL;
    o.time_limit = 0.4;
    double t0 = now();
    CHECK(dwv_bake(scene, &o, &image) == DWV_SUCCESS, "time budget: %s", dwv_last_error_message());
    if (image) {
        dwv_bake_stats_t st = DWV_BAKE_STATS_INIT;
        dwv_image_stats(image, &st);
        CHECK(st.samples_per_pixel < (1u << 24) && st.samples > 0, "spp %llu", (unsigned long long)st.samples_per_pixel);
        printf("time budget 0.4 s: ended after %.3f s (%.3f s in stats), %llu spp\n", now() - t0, st.seconds,
               (unsigned long long)st.samples_per_pixel);
        uint32_t count;
        CHECK(dwv_image_error_vs_time(image, NULL, 0, &count) == DWV_SUCCESS && count == st.error_vs_time_count,
              "error points %u", count);
        dwv_image_release(image);
        image = NULL;
    }
    /* A budget shorter than the first pass: that pass completes, the next one is cut at once. */
    o.time_limit = 1e-9;
    CHECK(dwv_bake(scene, &o, &image) == DWV_SUCCESS, "tiny time budget: %s", dwv_last_error_message());
    if (image) {
        dwv_bake_stats_t st = DWV_BAKE_STATS_INIT;
        dwv_image_stats(image, &st);
        CHECK(st.samples_per_pixel == 2u && st.samples > 0 && st.samples % 2u == 0u,
              "tiny time budget: %llu spp, %llu samples (want the first pass's 2 per pixel)",
              (unsigned long long)st.samples_per_pixel, (unsigned long long)st.samples);
        dwv_image_release(image);
        image = NULL;
    }
    /* Target error: stops after the pass that reaches it. */
    o.time_limit = 0.0;
    o.target_error = 0.1;
    CHECK(dwv_bake(scene, &o, &image) == DWV_SUCCESS, "target error: %s", dwv_last_error_message());
    if (image) {
        dwv_bake_stats_t st = DWV_BAKE_STATS_INIT;
        dwv_image_stats(image, &st);
        CHECK(st.estimated_relative_error <= 0.1 && st.samples_per_pixel < (1u << 24), "error %g at %llu spp",
              st.estimated_relative_error, (unsigned long long)st.samples_per_pixel);
        dwv_error_point_t points[64];
        uint32_t count = 0;
        dwv_image_error_vs_time(image, points, 64, &count);
        CHECK(count >= 2 && count <= 64, "error points %u", count);
        for (uint32_t i = 1; i < count && i < 64; ++i)
            CHECK(points[i].seconds >= points[i - 1].seconds && points[i].samples_per_pixel > points[i - 1].samples_per_pixel,
                  "error point %u", i);
        printf("target error 0.1: %.4f at %llu spp in %.3f s (%u points)\n", st.estimated_relative_error,
               (unsigned long long)st.samples_per_pixel, st.seconds, count);
        dwv_image_release(image);
    }
    dwv_scene_release(scene);
}

/* The estimated relative error is the relative RMSE the image has against the converged image: two
 * bakes with different seeds differ by sqrt(2) times that, pixel by pixel. Measured over the
 * covered pixels' luminance; the bound allows for the estimates' own noise at 64 spp. The
 * estimate comes from the spread between each pixel's two independent stratified replicates, so
 * stratification does not inflate it (with the samples' own variance it was 2.2x here, with the
 * channel walks auto picks; src/bake/pixel_sums.c). Seeds 11 and 12: 1.0x. */
static void test_error_estimate_is_the_rmse(void)
{
    dwv_scene_t *scene = mixed_scene();
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = 64;
    o.height = 48;
    o.samples = 64;
    dwv_image_t *images[2] = {NULL, NULL};
    dwv_bake_stats_t st[2] = {DWV_BAKE_STATS_INIT, DWV_BAKE_STATS_INIT};
    for (int k = 0; k < 2; ++k) {
        o.seed = 11u + (uint64_t)k;
        CHECK(dwv_bake(scene, &o, &images[k]) == DWV_SUCCESS, "bake: %s", dwv_last_error_message());
        if (images[k]) dwv_image_stats(images[k], &st[k]);
    }
    if (images[0] && images[1]) {
        dwv_image_info_t a = DWV_IMAGE_INFO_INIT, b = DWV_IMAGE_INFO_INIT;
        dwv_image_info(images[0], &a);
        dwv_image_info(images[1], &b);
        double squares = 0.0, total = 0.0, covered = 0.0;
        for (uint32_t i = 0; i < a.width * a.height; ++i) {
            if (a.rgba[4 * i + 3] <= 0.0f && b.rgba[4 * i + 3] <= 0.0f) continue;
            double la = 0.2126 * a.rgba[4 * i] + 0.7152 * a.rgba[4 * i + 1] + 0.0722 * a.rgba[4 * i + 2];
            double lb = 0.2126 * b.rgba[4 * i] + 0.7152 * b.rgba[4 * i + 1] + 0.0722 * b.rgba[4 * i + 2];
            squares += (la - lb) * (la - lb);
            total += 0.5 * (la + lb);
            covered += 1.0;
        }
        double measured = sqrt(squares / covered / 2.0) / (total / covered);
        double estimated = 0.5 * (st[0].estimated_relative_error + st[1].estimated_relative_error);
        printf("relative RMSE at 64 spp: estimated %.4f, measured from two seeds %.4f\n", estimated, measured);
        CHECK(estimated / measured > 0.85 && estimated / measured < 1.15, "estimated %.4f against measured %.4f",
              estimated, measured);
    }
    dwv_image_release(images[0]);
    dwv_image_release(images[1]);
    dwv_scene_release(scene);
}

/* UV bake of a white-medium box under a white world: texels of the islands near 1, the margin a
 * copy, texels beyond it untouched (alpha 0). */
static void test_uv(void)
{
    dwv_scene_t *scene;
    dwv_scene_create(&scene);
    dwv_material_t m = white_medium(0.3, 0.3, 0.3);
    test_mesh box = test_box(-1.0, -1.0, -1.0, 1.0, 1.0, 1.0);
    uint32_t id = test_add(scene, &box, &m);
    test_mesh_free(&box);
    double white[3] = {1.0, 1.0, 1.0};
    dwv_scene_set_world(scene, white, 1.0);
    CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit: %s", dwv_last_error_message());
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.target = DWV_BAKE_UV;
    o.uv_mesh = id;
    o.width = o.height = 64;
    o.uv_margin = 2;
    o.samples = 8;
    dwv_image_t *image = NULL;
    CHECK(dwv_bake(scene, &o, &image) == DWV_SUCCESS, "uv bake: %s", dwv_last_error_message());
    if (image) {
        dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
        dwv_image_info(image, &info);
        dwv_bake_stats_t st = DWV_BAKE_STATS_INIT;
        dwv_image_stats(image, &st);
        uint32_t lit = 0, empty = 0;
        for (uint32_t i = 0; i < 64u * 64u; ++i) {
            if (info.rgba[4 * i + 3] > 0.0f) ++lit;
            else ++empty;
        }
        /* Each face is a 0.23 x 0.40 UV rectangle: about 14.7 x 25.6 texels, 6 faces, plus margins
         * of 2 texels; the gaps between faces are 6.4 texels wide, so some texels stay empty. */
        CHECK(lit > 6u * 14u * 25u && lit < 6u * 20u * 31u && empty > 0, "lit %u empty %u", lit, empty);
        /* The standard error of the mean of the island texels (at least 6 x 14 x 25 of them): the
         * estimated relative RMSE per texel over sqrt(texels). */
        double sigma = st.estimated_relative_error * st.mean_rgb[0] / sqrt(6.0 * 14.0 * 25.0);
        CHECK(fabs(st.mean_rgb[0] - 1.0) < 5.0 * sigma + 1e-3, "uv mean %.6f (sigma %.2g)", st.mean_rgb[0], sigma);
        dwv_image_release(image);
    }
    dwv_scene_release(scene);
}

/* Bad geometry is met and counted, never a crash or a non-finite pixel: a box without its top
 * face (the camera looks into it: it sees the inside of subsurface faces, and walks entering the
 * sides find no surface above) and a zero-area triangle. */
static void test_warnings(void)
{
    dwv_scene_t *scene;
    dwv_scene_create(&scene);
    dwv_material_t m = white_medium(0.3, 0.3, 0.3);
    test_mesh box = test_box(-1.0, -1.0, -1.0, 1.0, 1.0, 1.0);
    /* The top (+z) face is triangles 2 and 3: the last two (the +x face) take their place. */
    for (int k = 0; k < 6; ++k) box.indices[6 + k] = box.indices[30 + k];
    box.triangle_count = 10;
    box.indices[0] = box.indices[1]; /* triangle 0: zero area */
    test_add(scene, &box, &m);
    test_mesh_free(&box);
    double white[3] = {1.0, 1.0, 1.0};
    dwv_camera_t camera = test_ortho_camera(0.0, 0.0, 5.0, 3.0);
    dwv_scene_set_world(scene, white, 1.0);
    dwv_scene_set_camera(scene, &camera);
    CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit: %s", dwv_last_error_message());
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = o.height = 16;
    o.samples = 4;
    dwv_image_t *image = NULL;
    CHECK(dwv_bake(scene, &o, &image) == DWV_SUCCESS, "bake: %s", dwv_last_error_message());
    if (image) {
        dwv_bake_stats_t st = DWV_BAKE_STATS_INIT;
        dwv_image_stats(image, &st);
        dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
        dwv_image_info(image, &info);
        int finite = 1;
        for (int i = 0; i < 4 * 16 * 16; ++i) finite &= isfinite(info.rgba[i]);
        CHECK(finite, "finite pixels");
        CHECK(st.warnings > 1, "warnings %llu", (unsigned long long)st.warnings);
        printf("open box: %llu warnings\n", (unsigned long long)st.warnings);
        dwv_image_release(image);
    }
    dwv_scene_release(scene);
}

static void test_refusals(void)
{
    dwv_scene_t *open_scene, *scene = mixed_scene();
    dwv_scene_create(&open_scene);
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    dwv_bake_t *bake = NULL;
    dwv_image_t *image = NULL;
#define REFUSE(call, code, keyword)                                                                           \
    do {                                                                                                      \
        prime_message();                                                                                      \
        dwv_result_t r_ = (call);                                                                             \
        CHECK(r_ == (code), "%s gave %d (%s)", #call, (int)r_, dwv_last_error_message());                     \
        CHECK(fresh_message_with(keyword), "%s: \"%s\" lacks \"%s\"", #call, dwv_last_error_message(), keyword); \
    } while (0)
    REFUSE(dwv_bake_start(scene, &o, NULL), DWV_ERROR_NULL_POINTER, "bake");
    REFUSE(dwv_bake_start(NULL, &o, &bake), DWV_ERROR_NULL_POINTER, "scene");
    REFUSE(dwv_bake_start(scene, NULL, &bake), DWV_ERROR_NULL_POINTER, "options");
    REFUSE(dwv_bake(scene, &o, NULL), DWV_ERROR_NULL_POINTER, "image");
    REFUSE(dwv_bake(open_scene, &o, &image), DWV_ERROR_INVALID_STATE, "committed");
    dwv_scene_commit(open_scene);
    REFUSE(dwv_bake(open_scene, &o, &image), DWV_ERROR_INVALID_STATE, "camera");
    o.struct_size = 16;
    REFUSE(dwv_bake(scene, &o, &image), DWV_ERROR_STRUCT_SIZE, "options");
    o = (dwv_bake_options_t)DWV_BAKE_OPTIONS_INIT;
    o.width = 0;
    REFUSE(dwv_bake(scene, &o, &image), DWV_ERROR_OUT_OF_RANGE, "pixels");
    o.width = 16384;
    o.height = 16384;
    REFUSE(dwv_bake(scene, &o, &image), DWV_ERROR_OUT_OF_RANGE, "pixels");
    o = (dwv_bake_options_t)DWV_BAKE_OPTIONS_INIT;
    o.samples = 0;
    REFUSE(dwv_bake(scene, &o, &image), DWV_ERROR_OUT_OF_RANGE, "samples");
    o.samples = (1u << 24) + 1u;
    REFUSE(dwv_bake(scene, &o, &image), DWV_ERROR_OUT_OF_RANGE, "samples");
    o = (dwv_bake_options_t)DWV_BAKE_OPTIONS_INIT;
    o.technique = 9;
    REFUSE(dwv_bake(scene, &o, &image), DWV_ERROR_INVALID_ARGUMENT, "technique");
    o = (dwv_bake_options_t)DWV_BAKE_OPTIONS_INIT;
    o.time_limit = NAN;
    REFUSE(dwv_bake(scene, &o, &image), DWV_ERROR_INVALID_ARGUMENT, "time_limit");
    o = (dwv_bake_options_t)DWV_BAKE_OPTIONS_INIT;
    o.target_error = -1.0;
    REFUSE(dwv_bake(scene, &o, &image), DWV_ERROR_OUT_OF_RANGE, "target_error");
    o = (dwv_bake_options_t)DWV_BAKE_OPTIONS_INIT;
    o.threads = 1025;
    REFUSE(dwv_bake(scene, &o, &image), DWV_ERROR_OUT_OF_RANGE, "threads");
    o = (dwv_bake_options_t)DWV_BAKE_OPTIONS_INIT;
    o.target = 5;
    REFUSE(dwv_bake(scene, &o, &image), DWV_ERROR_INVALID_ARGUMENT, "target");
    o.target = DWV_BAKE_UV;
    o.uv_mesh = 2;
    REFUSE(dwv_bake(scene, &o, &image), DWV_ERROR_OUT_OF_RANGE, "uv_mesh");
    o.uv_mesh = 0; /* the sphere has no UVs */
    REFUSE(dwv_bake(scene, &o, &image), DWV_ERROR_INVALID_ARGUMENT, "UVs");
    o.uv_mesh = 1;
    o.uv_margin = 65;
    REFUSE(dwv_bake(scene, &o, &image), DWV_ERROR_OUT_OF_RANGE, "uv_margin");
    CHECK(image == NULL, "no image from refused bakes");
    /* The handle calls. */
    int32_t done;
    dwv_bake_progress_t p = DWV_BAKE_PROGRESS_INIT;
    REFUSE(dwv_bake_wait(NULL, 0.0, &done), DWV_ERROR_NULL_POINTER, "bake");
    REFUSE(dwv_bake_progress(NULL, &p), DWV_ERROR_NULL_POINTER, "bake");
    REFUSE(dwv_bake_cancel(NULL), DWV_ERROR_NULL_POINTER, "bake");
    REFUSE(dwv_bake_finish(NULL, &image), DWV_ERROR_NULL_POINTER, "bake");
    o = (dwv_bake_options_t)DWV_BAKE_OPTIONS_INIT;
    o.width = o.height = 4;
    o.samples = 2;
    CHECK(dwv_bake_start(scene, &o, &bake) == DWV_SUCCESS, "start: %s", dwv_last_error_message());
    if (bake) {
        REFUSE(dwv_bake_wait(bake, NAN, &done), DWV_ERROR_INVALID_ARGUMENT, "timeout");
        REFUSE(dwv_bake_progress(bake, NULL), DWV_ERROR_NULL_POINTER, "progress");
        CHECK(dwv_bake_finish(bake, &image) == DWV_SUCCESS && image, "finish: %s", dwv_last_error_message());
        dwv_image_t *again = NULL;
        REFUSE(dwv_bake_finish(bake, &again), DWV_ERROR_INVALID_STATE, "handed over");
        CHECK(dwv_bake_progress(bake, &p) == DWV_SUCCESS && p.done == 1 && p.fraction == 1.0, "final progress %g",
              p.fraction);
        /* The scene outlives its handle while a bake holds it. */
        dwv_bake_release(bake);
        dwv_image_release(image);
    }
    dwv_bake_release(NULL);
    dwv_scene_release(open_scene);
    dwv_scene_release(scene);
#undef REFUSE
}

static void test_feature_names(void)
{
    int named = 0;
    for (uint32_t bit = 0; bit < 32; ++bit) {
        const char *name = dwv_feature_name(1u << bit);
        if (bit <= 10) {
            CHECK(name != NULL, "bit %u has no name", bit);
            ++named;
        } else {
            CHECK(name == NULL, "bit %u named %s", bit, name);
        }
    }
    CHECK(dwv_feature_name(0) == NULL && dwv_feature_name(3) == NULL, "not single bits");
    CHECK(named == 11 && strcmp(dwv_feature_name(DWV_FEATURE_CLOSEST_POINT), "closest_point") == 0, "names");
}

int main(void)
{
    test_feature_names();
    test_refusals();
    test_energy();
    test_determinism();
    test_cancel_and_budgets();
    test_error_estimate_is_the_rmse();
    test_uv();
    test_warnings();
    return check_report("test_bake");
}
