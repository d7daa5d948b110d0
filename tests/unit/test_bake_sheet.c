/* The sheet technique (DWV_TECHNIQUE_SHEET, src/kernel/sheet.h) in bakes: walks guided toward a thin
 * sheet's lit side by an importance linear in the height. It is unbiased, so its images must
 * have the classical walks' means within the noise: on the report's leaf (one extinction, shared
 * and channel walks), on the back-lit slab (extinctions 2x and 4x apart) and on the front-lit wax
 * sphere (not a sheet: its walks enter on the lit side and run classical, but where the camera
 * sees the unlit side they do not). On the leaf it must be far less noisy than classical walks
 * (docs/speed.md: 7.8x less variance per sample); the bake's features say it ran; where every
 * walk enters on the lit side it is classical sampling, bit for bit. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake_compare.h"
#include "bake_scenes.h"
#include "check.h"
#include <dwivedi.h>

typedef test_result result;

static int bake(dwv_scene_t *scene, dwv_technique_t technique, dwv_channel_walks_t channel_walks, uint32_t size,
                uint64_t samples, uint64_t seed, result *out)
{
    return test_bake_result(scene, technique, channel_walks, size, samples, seed, out);
}

/* The sheet (shared and channel walks) against classical shared walks: the same means within
 * 4.5 standard errors, the sheet's feature set. */
static void check_means(const char *name, dwv_scene_t *scene, uint64_t samples)
{
    result classical, sheet;
    if (!bake(scene, DWV_TECHNIQUE_CLASSICAL, DWV_CHANNEL_WALKS_SHARED, 12, samples, 1, &classical)) return;
    static const dwv_channel_walks_t forms[2] = {DWV_CHANNEL_WALKS_SHARED, DWV_CHANNEL_WALKS_SEPARATE};
    for (int f = 0; f < 2; ++f) {
        if (!bake(scene, DWV_TECHNIQUE_SHEET, forms[f], 12, samples, 2 + (uint64_t)f, &sheet)) continue;
        CHECK(sheet.features & DWV_FEATURE_SHEET && sheet.features & DWV_FEATURE_GUIDED &&
                  !(classical.features & DWV_FEATURE_SHEET),
              "%s: features sheet %#x, classical %#x", name, sheet.features, classical.features);
        for (int c = 0; c < 3; ++c) {
            double difference = sheet.mean[c] - classical.mean[c];
            double error = hypot(sheet.standard_error[c], classical.standard_error[c]);
            CHECK(classical.mean[c] > 0.0 && fabs(difference) < 4.5 * error,
                  "%s, %s walks, channel %d: sheet %.6f, classical %.6f (%.1f standard errors apart)", name,
                  dwv_channel_walks_name(forms[f]), c, sheet.mean[c], classical.mean[c], difference / error);
        }
        printf("%-22s %-8s sheet (%.5f %.5f %.5f), classical (%.5f %.5f %.5f)\n", name, dwv_channel_walks_name(forms[f]),
               sheet.mean[0], sheet.mean[1], sheet.mean[2], classical.mean[0], classical.mean[1], classical.mean[2]);
        free(sheet.rgba);
    }
    free(classical.rgba);
}

static void test_means_agree(void)
{
    dwv_scene_t *scene = test_leaf();
    check_means("leaf", scene, 2048);
    dwv_scene_release(scene);
    scene = test_wax_sphere(-1, 0, 16, 32);
    check_means("front-lit wax sphere", scene, 1024);
    dwv_scene_release(scene);
}

/* On the leaf the sheet's image is far less noisy than classical walks' (7.8x less variance per
 * sample in docs/speed.md's runs; required here: 4x). */
static void test_leaf_is_less_noisy(void)
{
    dwv_scene_t *scene = test_leaf();
    result classical = {.rgba = NULL}, sheet = {.rgba = NULL};
    if (bake(scene, DWV_TECHNIQUE_CLASSICAL, DWV_CHANNEL_WALKS_SHARED, 16, 256, 7, &classical) &&
        bake(scene, DWV_TECHNIQUE_SHEET, DWV_CHANNEL_WALKS_SHARED, 16, 256, 7, &sheet)) {
        double classical_variance = 0.0, sheet_variance = 0.0;
        for (int c = 0; c < 3; ++c) {
            classical_variance += classical.standard_error[c] * classical.standard_error[c];
            sheet_variance += sheet.standard_error[c] * sheet.standard_error[c];
        }
        printf("leaf, 256 spp: variance of the image mean, sheet %.3g, classical %.3g (%.1fx)\n", sheet_variance,
               classical_variance, classical_variance / sheet_variance);
        CHECK(sheet_variance < 0.25 * classical_variance, "leaf: variance of the image mean, sheet %.3g, classical %.3g",
              sheet_variance, classical_variance);
    }
    free(classical.rgba);
    free(sheet.rgba);
    dwv_scene_release(scene);
}

/* A thin slab lit from the camera's side: every walk enters on the lit side, where the sheet has
 * no far face to start from, so its walks are classical ones, bit for bit. */
static void test_lit_side_is_classical(void)
{
    dwv_material_t m = DWV_MATERIAL_INIT;
    for (int c = 0; c < 3; ++c) {
        m.base_color[c] = m.subsurface_color[c] = 0.9;
        m.subsurface_radius[c] = 0.2 * (double)(c + 1);
    }
    m.subsurface_scale = 1.0;
    dwv_scene_t *scene = test_sunlit_box(&m, 0.1, -1.0);
    static const dwv_channel_walks_t forms[2] = {DWV_CHANNEL_WALKS_SHARED, DWV_CHANNEL_WALKS_SEPARATE};
    for (int f = 0; f < 2; ++f) {
        result classical = {.rgba = NULL}, sheet = {.rgba = NULL};
        if (bake(scene, DWV_TECHNIQUE_CLASSICAL, forms[f], 8, 16, 9, &classical) &&
            bake(scene, DWV_TECHNIQUE_SHEET, forms[f], 8, 16, 9, &sheet)) {
            CHECK(memcmp(classical.rgba, sheet.rgba, 4u * sheet.pixels * sizeof *sheet.rgba) == 0,
                  "front-lit slab, %s walks: the sheet's pixels differ from classical ones",
                  dwv_channel_walks_name(forms[f]));
        }
        free(classical.rgba);
        free(sheet.rgba);
    }
    dwv_scene_release(scene);
}

static void test_name(void)
{
    dwv_technique_t technique = -1;
    CHECK(dwv_technique_from_name("sheet", &technique) == DWV_SUCCESS && technique == DWV_TECHNIQUE_SHEET,
          "sheet's name: %d", (int)technique);
    CHECK(strcmp(dwv_technique_name(DWV_TECHNIQUE_SHEET), "sheet") == 0 &&
              strcmp(dwv_feature_name(DWV_FEATURE_SHEET), "sheet") == 0,
          "%s", "names");
}

int main(void)
{
    test_name();
    test_lit_side_is_classical();
    test_means_agree();
    test_leaf_is_less_noisy();
    return check_report("test_bake_sheet");
}
