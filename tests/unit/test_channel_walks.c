/* Channel walks (dwv_bake_options_t.channel_walks, DWV_CHANNEL_WALKS_*): one walk per colour
 * channel in that channel's own medium, against one walk that carries the three by spectral MIS.
 * Both are unbiased estimates of the same image, so their means must agree within the noise,
 * whatever the technique; a grey medium walks once either way (the same pixels, bit for bit); the
 * bake's features say which ran; the option and its names are checked. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake_compare.h"
#include "bake_scenes.h"
#include "check.h"
#include <dwivedi.h>

/* bake_scenes.h's wax sphere at a coarser tessellation. */
static dwv_scene_t *wax_sphere(int flat_channel, int grey)
{
    return test_wax_sphere(flat_channel, grey, 16, 32);
}

/* The report's back-lit slab: 4 x 4 x 0.1 m, radius (1, 0.5, 0.25) (1.3, 2.5 and 5 mean free
 * paths thick), colour 0.8, a sun from below, seen from above (every pixel sees the slab). */
static dwv_scene_t *backlit_slab(void)
{
    dwv_material_t m = DWV_MATERIAL_INIT;
    static const double radius[3] = {1.0, 0.5, 0.25};
    for (int c = 0; c < 3; ++c) {
        m.base_color[c] = m.subsurface_color[c] = 0.8;
        m.subsurface_radius[c] = radius[c];
    }
    m.subsurface_scale = 1.0;
    return test_sunlit_box(&m, 0.1, 1.0);
}

typedef test_result result;

/* A 12 x 12 bake (bake_compare.h). */
static int bake(dwv_scene_t *scene, dwv_technique_t technique, dwv_channel_walks_t channel_walks, uint64_t samples,
                uint64_t seed, result *out)
{
    return test_bake_result(scene, technique, channel_walks, 12u, samples, seed, out);
}

/* Separate walks (two techniques) against shared ones: the same means within 4.5 standard errors. */
static void check_same_means(const char *name, dwv_scene_t *scene)
{
    result shared, separate;
    if (!bake(scene, DWV_TECHNIQUE_CLASSICAL, DWV_CHANNEL_WALKS_SHARED, 4096, 1, &shared)) return;
    CHECK(shared.features & DWV_FEATURE_RGB_WALKS && !(shared.features & DWV_FEATURE_CHANNEL_WALKS),
          "%s: shared walks' features %#x", name, shared.features);
    static const dwv_technique_t techniques[] = {DWV_TECHNIQUE_CLASSICAL, DWV_TECHNIQUE_BACKWARD,
                                                 DWV_TECHNIQUE_INCIDENT};
    for (size_t t = 0; t < sizeof techniques / sizeof techniques[0]; ++t) {
        if (!bake(scene, techniques[t], DWV_CHANNEL_WALKS_SEPARATE, 4096, 2, &separate)) continue;
        CHECK(separate.features & DWV_FEATURE_CHANNEL_WALKS && !(separate.features & DWV_FEATURE_RGB_WALKS),
              "%s: separate walks' features %#x", name, separate.features);
        for (int c = 0; c < 3; ++c) {
            double difference = separate.mean[c] - shared.mean[c];
            double error = hypot(separate.standard_error[c], shared.standard_error[c]);
            CHECK(shared.mean[c] > 0.0 && fabs(difference) < 4.5 * error,
                  "%s, %s, channel %d: separate %.6f, shared %.6f (%.1f standard errors apart)", name,
                  dwv_technique_name(techniques[t]), c, separate.mean[c], shared.mean[c], difference / error);
        }
        free(separate.rgba);
    }
    free(shared.rgba);
}

static void test_means_agree(void)
{
    dwv_scene_t *scene = wax_sphere(-1, 0);
    check_same_means("wax sphere", scene);
    dwv_scene_release(scene);
    /* Green does not walk: the separate bake walks red and blue only. */
    scene = wax_sphere(1, 0);
    check_same_means("wax sphere, green Lambertian", scene);
    dwv_scene_release(scene);
}

/* Separate walks are far less noisy than shared ones on the wax sphere (docs/speed.md): there a
 * shared walk's channels carry each other's pdfs over many events. */
static void test_separate_is_less_noisy(void)
{
    dwv_scene_t *scene = wax_sphere(-1, 0);
    result shared = {.rgba = NULL}, separate = {.rgba = NULL};
    if (bake(scene, DWV_TECHNIQUE_BACKWARD, DWV_CHANNEL_WALKS_SHARED, 256, 3, &shared) &&
        bake(scene, DWV_TECHNIQUE_BACKWARD, DWV_CHANNEL_WALKS_SEPARATE, 256, 3, &separate)) {
        double shared_variance = 0.0, separate_variance = 0.0;
        for (int c = 0; c < 3; ++c) {
            shared_variance += shared.standard_error[c] * shared.standard_error[c];
            separate_variance += separate.standard_error[c] * separate.standard_error[c];
        }
        CHECK(separate_variance < 0.5 * shared_variance, "variance of the image mean: separate %.3g, shared %.3g",
              separate_variance, shared_variance);
    }
    free(shared.rgba);
    free(separate.rgba);
    dwv_scene_release(scene);
}

/* A grey medium walks once whatever the option: the same pixels, and no channel walks. */
static void test_grey_walks_once(void)
{
    dwv_scene_t *scene = wax_sphere(-1, 1);
    result shared = {.rgba = NULL}, separate = {.rgba = NULL};
    if (bake(scene, DWV_TECHNIQUE_BACKWARD, DWV_CHANNEL_WALKS_SHARED, 16, 4, &shared) &&
        bake(scene, DWV_TECHNIQUE_BACKWARD, DWV_CHANNEL_WALKS_SEPARATE, 16, 4, &separate)) {
        CHECK(memcmp(shared.rgba, separate.rgba, 4u * shared.pixels * sizeof *shared.rgba) == 0,
              "grey: separate and shared pixels differ");
        CHECK(!(separate.features & (DWV_FEATURE_CHANNEL_WALKS | DWV_FEATURE_RGB_WALKS)), "grey: features %#x",
              separate.features);
    }
    free(shared.rgba);
    free(separate.rgba);
    dwv_scene_release(scene);
}

static void test_option_and_names(void)
{
    static const char *const names[] = {"auto", "shared", "separate"};
    for (uint32_t i = 0; i < 3; ++i) {
        dwv_channel_walks_t value = 99;
        CHECK(dwv_channel_walks_name(i) && strcmp(dwv_channel_walks_name(i), names[i]) == 0, "name of %u", i);
        CHECK(dwv_channel_walks_from_name(names[i], &value) == DWV_SUCCESS && value == i, "%s", names[i]);
    }
    CHECK(dwv_channel_walks_name(3) == NULL && dwv_channel_walks_name(UINT32_MAX) == NULL, "names past the end");
    dwv_channel_walks_t value = 7;
    CHECK(dwv_channel_walks_from_name("Separate", &value) == DWV_ERROR_UNKNOWN_NAME && value == 7, "case matters");
    CHECK(dwv_channel_walks_from_name("", &value) == DWV_ERROR_UNKNOWN_NAME, "empty name");
    CHECK(dwv_channel_walks_from_name(NULL, &value) == DWV_ERROR_NULL_POINTER, "NULL name");
    CHECK(dwv_channel_walks_from_name("auto", NULL) == DWV_ERROR_NULL_POINTER, "NULL result");

    dwv_scene_t *scene = wax_sphere(-1, 0);
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = o.height = 4;
    o.samples = 1;
    CHECK(o.channel_walks == DWV_CHANNEL_WALKS_AUTO, "the default is auto");
    o.channel_walks = 3;
    dwv_bake_t *handle = (dwv_bake_t *)&o;
    CHECK(dwv_bake_start(scene, &o, &handle) == DWV_ERROR_INVALID_ARGUMENT && handle == NULL,
          "channel_walks 3 accepted");
    CHECK(strstr(dwv_last_error_message(), "channel_walks") != NULL, "message: %s", dwv_last_error_message());
    dwv_scene_release(scene);
}

/* Auto's pilot gives a channel more walks per sample where they are cheap and its variance is
 * large: on the back-lit slab, red (1.3 mean free paths thick, walks of 2.4 events) against blue
 * (5, 11 events). The image keeps its mean (each of a channel's walks weighs 1 / count). */
static void test_walk_counts(void)
{
    dwv_scene_t *scene = backlit_slab();
    result shared = {.rgba = NULL}, counted = {.rgba = NULL};
    if (bake(scene, DWV_TECHNIQUE_INCIDENT, DWV_CHANNEL_WALKS_SHARED, 2048, 5, &shared) &&
        bake(scene, DWV_TECHNIQUE_AUTO, DWV_CHANNEL_WALKS_SEPARATE, 2048, 6, &counted)) {
        double walks_per_sample = (double)counted.walks / (double)counted.samples;
        CHECK(counted.features & DWV_FEATURE_CHANNEL_WALKS && walks_per_sample > 3.5,
              "slab: %.2f walks per sample with channel walks (features %#x): no channel got more than one",
              walks_per_sample, counted.features);
        for (int c = 0; c < 3; ++c) {
            double difference = counted.mean[c] - shared.mean[c];
            double error = hypot(counted.standard_error[c], shared.standard_error[c]);
            CHECK(fabs(difference) < 4.5 * error, "slab, channel %d: %.6f with counted walks, %.6f shared (%.1f standard errors)",
                  c, counted.mean[c], shared.mean[c], difference / error);
        }
    }
    free(shared.rgba);
    free(counted.rgba);
    dwv_scene_release(scene);
}

int main(void)
{
    test_option_and_names();
    test_grey_walks_once();
    test_means_agree();
    test_separate_is_less_noisy();
    test_walk_counts();
    return check_report("test_channel_walks");
}
