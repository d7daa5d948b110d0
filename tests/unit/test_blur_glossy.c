/* Cycles' Filter Glossy (dwv_bake_options_t.blur_glossy, issue 18): a specular layer met after a
 * path's bounces of smallest pdf p has its GGX alpha raised to 0.5 sqrt(1 - p / blur_glossy)
 * where p / blur_glossy < 1, and a mirror-sharp layer turns GGX.
 *
 * The scene: a white diffuse box standing on a mirror-sharp floor (Blender 3.x Principled v1,
 * Roughness 0, black base: the specular layer alone), a sun that lights the box's face and, in
 * the mirror, would light it again, a constant world. An orthographic camera looks straight at the
 * face: it never sees the floor, so every floor vertex comes after the face's diffuse bounce (p =
 * cos / pi <= 1 / pi), never at the camera (which Cycles never blurs). Checked:
 * - blur_glossy 1e9: p / blur_glossy < 4e-10, so the floor is GGX of alpha 0.5 (to 1e-10) at
 *   every path vertex: the image equals, pixel by pixel (the same random numbers), the one of the
 *   same scene with a floor of Roughness sqrt(0.5) (alpha 0.5) and no blur, to 1e-6 relative.
 *   v1's BRDF depends on alpha alone (no albedo tables), so nothing else may differ. On the
 *   library before Filter Glossy the floor stayed a mirror (the sun's reflection, a delta, never
 *   reached the face by a path): its image is 2.0% darker in the mean and up to 10% per pixel
 *   (checked to be more than 1% apart), and this check fails there.
 * - blur_glossy 1e-4: p / blur_glossy >= 1 but for directions within 3e-4 of grazing, so no
 *   vertex of these samples is blurred: the image is the one of blur_glossy 0 (to 1e-6) — the
 *   blur is relative to the pdf of the path's bounce, not on for any blur_glossy > 0.
 * - an options struct that ends before blur_glossy (an older header) bakes as blur_glossy 0,
 *   bit for bit; 1 and 2 threads give the same bits with blur_glossy 1; NaN, infinity and -0.5
 *   are refused (DWV_ERROR_OUT_OF_RANGE, naming blur_glossy), and so is a scene file's negative
 *   "blur_glossy"; a scene file loads into an older struct without writing past its end. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake_scenes.h"
#include "check.h"
#include <dwivedi.h>

static dwv_material_t floor_material(double roughness)
{
    dwv_material_t m = DWV_MATERIAL_INIT;
    m.kind = DWV_MATERIAL_DIFFUSE;
    m.base_color[0] = m.base_color[1] = m.base_color[2] = 0.0;
    m.roughness = roughness;
    m.specular_model = DWV_SPECULAR_PRINCIPLED_V1;
    m.specular = 1.0;
    m.specular_tint[0] = 0.0;
    return m;
}

static dwv_scene_t *box_on_floor(double floor_roughness)
{
    dwv_scene_t *scene;
    dwv_scene_create(&scene);
    dwv_material_t floor = floor_material(floor_roughness);
    test_mesh slab = test_box(-20.0, -20.0, -1.0, 20.0, 20.0, 0.0);
    test_add(scene, &slab, &floor);
    test_mesh_free(&slab);
    dwv_material_t white = DWV_MATERIAL_INIT;
    white.kind = DWV_MATERIAL_DIFFUSE;
    white.base_color[0] = white.base_color[1] = white.base_color[2] = 0.8;
    test_mesh box = test_box(-3.0, 2.0, 0.0, 3.0, 3.0, 6.0);
    test_add(scene, &box, &white);
    test_mesh_free(&box);
    /* Looking along +y at the face y = 2, 1 m across about z = 1.5: rotation about x by 90
     * degrees takes the camera's -z to +y. */
    dwv_camera_t camera = test_ortho_camera(0.0, -10.0, 1.5, 1.0);
    double rotation[9] = {1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) camera.transform[4 * i + j] = rotation[3 * i + j];
    dwv_scene_set_camera(scene, &camera);
    dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
    sun.strength = 3.0;
    sun.direction[0] = 0.1, sun.direction[1] = 1.0, sun.direction[2] = -0.3;
    dwv_scene_add_light(scene, &sun);
    double world[3] = {0.2, 0.3, 0.4};
    dwv_scene_set_world(scene, world, 1.0);
    CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit: %s", dwv_last_error_message());
    return scene;
}

static dwv_bake_options_t options(double blur_glossy)
{
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = o.height = 8;
    o.samples = 16;
    o.seed = 18;
    o.threads = 1;
    o.technique = DWV_TECHNIQUE_CLASSICAL;
    o.blur_glossy = blur_glossy;
    return o;
}

static dwv_image_t *bake(dwv_scene_t *scene, const dwv_bake_options_t *o)
{
    dwv_image_t *image = NULL;
    CHECK(dwv_bake(scene, o, &image) == DWV_SUCCESS, "bake: %s", dwv_last_error_message());
    return image;
}

/* The largest relative difference of two images' RGB over the pixels (of the larger value), and
 * the ratio of their means (b over a, all channels). */
static double worst_difference(dwv_image_t *a, dwv_image_t *b, double *mean_ratio)
{
    dwv_image_info_t ia = DWV_IMAGE_INFO_INIT, ib = DWV_IMAGE_INFO_INIT;
    dwv_image_info(a, &ia);
    dwv_image_info(b, &ib);
    double worst = 0.0, sum_a = 0.0, sum_b = 0.0;
    for (size_t i = 0; i < (size_t)ia.width * ia.height; ++i)
        for (int c = 0; c < 3; ++c) {
            double x = ia.rgba[4 * i + c], y = ib.rgba[4 * i + c];
            double d = fabs(x - y) / fmax(fmax(fabs(x), fabs(y)), 1e-30);
            worst = isfinite(d) ? fmax(worst, d) : INFINITY;
            sum_a += x, sum_b += y;
        }
    *mean_ratio = sum_b / sum_a;
    return worst;
}

static int same_bits(dwv_image_t *a, dwv_image_t *b)
{
    dwv_image_info_t ia = DWV_IMAGE_INFO_INIT, ib = DWV_IMAGE_INFO_INIT;
    dwv_image_info(a, &ia);
    dwv_image_info(b, &ib);
    return memcmp(ia.rgba, ib.rgba, 4u * ia.width * ia.height * sizeof(float)) == 0;
}

static void test_blurred_mirror(void)
{
    dwv_scene_t *mirror = box_on_floor(0.0), *rough = box_on_floor(sqrt(0.5));
    dwv_bake_options_t full = options(1e9), none = options(0.0), tiny = options(1e-4), blender = options(1.0);
    dwv_image_t *blurred = bake(mirror, &full), *reference = bake(rough, &none), *sharp = bake(mirror, &none);
    dwv_image_t *almost_sharp = bake(mirror, &tiny);
    if (blurred && reference && sharp && almost_sharp) {
        double ratio = 0.0, sharp_ratio = 0.0, tiny_ratio = 0.0;
        double worst = worst_difference(reference, blurred, &ratio);
        double sharp_worst = worst_difference(reference, sharp, &sharp_ratio);
        double tiny_worst = worst_difference(sharp, almost_sharp, &tiny_ratio);
        printf("blur_glossy 1e9 against a floor of alpha 0.5: worst pixel %.3g, means %.9f; the mirror unblurred: "
               "worst pixel %.3g, means %.5f; blur_glossy 1e-4 against 0: worst pixel %.3g\n",
               worst, ratio, sharp_worst, sharp_ratio, tiny_worst);
        CHECK(worst < 1e-6, "the blurred mirror differs from GGX of alpha 0.5 by %.3g", worst);
        /* What the first check tells apart (the library without the blur bakes `sharp`). */
        CHECK(sharp_worst > 0.01 && fabs(sharp_ratio - 1.0) > 0.01,
              "the unblurred mirror is within 1%% of the blurred floor (%.3g, %.5f)", sharp_worst, sharp_ratio);
        CHECK(tiny_worst < 1e-6, "blur_glossy 1e-4 differs from 0 by %.3g", tiny_worst);
    }
    /* An older header's struct (ending before blur_glossy): no blur, the same bits as 0. */
    dwv_bake_options_t old = options(1.0);
    old.struct_size = (uint32_t)offsetof(dwv_bake_options_t, blur_glossy);
    dwv_image_t *older = bake(mirror, &old);
    if (older && sharp) CHECK(same_bits(older, sharp), "an older options struct does not bake as blur_glossy 0");
    dwv_image_t *one = bake(mirror, &blender);
    blender.threads = 2;
    dwv_image_t *two = bake(mirror, &blender);
    if (one && two) CHECK(same_bits(one, two), "blur_glossy 1: 1 and 2 threads differ");
    /* Refused values. */
    const double bad[] = {NAN, INFINITY, -0.5};
    for (int i = 0; i < 3; ++i) {
        dwv_bake_options_t o = options(bad[i]);
        dwv_image_t *image = NULL;
        dwv_result_t r = dwv_bake(mirror, &o, &image);
        CHECK(r == DWV_ERROR_OUT_OF_RANGE && !image && strstr(dwv_last_error_message(), "blur_glossy"),
              "blur_glossy %g: result %d, '%s'", bad[i], (int)r, dwv_last_error_message());
    }
    dwv_image_release(blurred);
    dwv_image_release(reference);
    dwv_image_release(sharp);
    dwv_image_release(almost_sharp);
    dwv_image_release(older);
    dwv_image_release(one);
    dwv_image_release(two);
    dwv_scene_release(mirror);
    dwv_scene_release(rough);
}

static void test_scene_file(void)
{
#define SCENE_HEAD                                                                                       \
    "{\"version\": 1, \"materials\": {\"m\": {\"kind\": \"diffuse\", \"subsurface_weight\": 0}},"                \
    " \"meshes\": [{\"material\": \"m\", \"positions\": [0,0,0, 1,0,0, 0,1,0], \"indices\": [0,1,2]}],"      \
    " \"camera\": {\"transform\": {\"translate\": [0, 0, 5]}}, "
    static const char good[] = SCENE_HEAD "\"bake\": {\"blur_glossy\": 2.5}}";
    static const char negative[] = SCENE_HEAD "\"bake\": {\"blur_glossy\": -1}}";
    dwv_scene_t *scene = NULL;
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    dwv_result_t r = dwv_scene_load_json(good, sizeof good - 1u, NULL, &scene, &o);
    CHECK(r == DWV_SUCCESS && o.blur_glossy == 2.5, "scene file blur_glossy 2.5: %d, %g, '%s'", (int)r, o.blur_glossy,
          dwv_last_error_message());
    dwv_scene_release(scene);
    scene = NULL;
    /* An older header's struct, ending before blur_glossy: loaded, nothing written past its end. */
    o = (dwv_bake_options_t)DWV_BAKE_OPTIONS_INIT;
    o.struct_size = (uint32_t)offsetof(dwv_bake_options_t, blur_glossy);
    o.blur_glossy = -7.0; /* stands for the bytes beyond the caller's struct */
    r = dwv_scene_load_json(good, sizeof good - 1u, NULL, &scene, &o);
    CHECK(r == DWV_SUCCESS && o.blur_glossy == -7.0 && o.struct_size == offsetof(dwv_bake_options_t, blur_glossy),
          "older struct: %d, %g, '%s'", (int)r, o.blur_glossy, dwv_last_error_message());
    dwv_scene_release(scene);
    scene = NULL;
    o = (dwv_bake_options_t)DWV_BAKE_OPTIONS_INIT;
    CHECK(o.blur_glossy == 1.0, "DWV_BAKE_OPTIONS_INIT's blur_glossy is %g, not Blender's 1", o.blur_glossy);
    r = dwv_scene_load_json(negative, sizeof negative - 1u, NULL, &scene, &o);
    CHECK(r != DWV_SUCCESS && !scene && strstr(dwv_last_error_message(), "blur_glossy"),
          "scene file blur_glossy -1: %d, '%s'", (int)r, dwv_last_error_message());
    dwv_scene_release(scene);
}

int main(void)
{
    test_blurred_mirror();
    test_scene_file();
    return check_report("test_blur_glossy");
}
