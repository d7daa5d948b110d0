/* A slab made of triangles (a 100 x 100 x T box) baked through the scene API matches the analytic
 * slab of dwv_estimate (a different code path: no Embree, no lights, no camera) for transmittance
 * and reflectance under diffuse (cosine-weighted) incidence.
 *
 * Setup: the camera looks down at the top face, so walks enter there by cosine-weighted diffuse
 * transmission; a sun of strength pi shines straight up (transmittance) or down (reflectance)
 * and the world is black. An exit through the lit face gathers (1/pi) x pi x cos 0 = 1 per unit
 * weight, through the other face 0: each pixel estimates the slab's T or R. The box's sides are
 * 50 mean free paths from the imaged centre, where the walks' lateral spread is far smaller. */
#include <math.h>
#include <stdio.h>

#include "bake/material.h"
#include "bake_scenes.h"
#include "check.h"
#include <dwivedi.h>

#define FOUR_PI 12.566370614359172

static void image_mean(const dwv_image_t *image, double *mean, double *sigma)
{
    dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
    dwv_image_info(image, &info);
    size_t n = (size_t)info.width * info.height;
    double sum = 0.0, variance = 0.0;
    for (size_t i = 0; i < n; ++i) {
        sum += info.rgba[4 * i];
        variance += info.variance[3 * i];
    }
    *mean = sum / (double)n;
    *sigma = sqrt(variance) / (double)n;
}

static void check_slab(double thickness, double colour, double g, int transmit, dwv_technique_t technique)
{
    /* Cycles: sigma_t = 1 / (d (1 - g)), d = radius x scale / (4 pi); radius 4 pi / (1 - g) gives 1. */
    dwv_material_t m = DWV_MATERIAL_INIT;
    for (int c = 0; c < 3; ++c) {
        m.subsurface_color[c] = colour;
        m.subsurface_radius[c] = FOUR_PI / (1.0 - g);
    }
    m.subsurface_scale = 1.0;
    m.subsurface_anisotropy = g;
    dwv_scene_t *scene;
    dwv_scene_create(&scene);
    test_mesh slab = test_box(-50.0, -50.0, 0.0, 50.0, 50.0, thickness);
    test_add(scene, &slab, &m);
    test_mesh_free(&slab);
    dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
    sun.strength = 3.14159265358979323846;
    sun.direction[2] = transmit ? 1.0 : -1.0;
    dwv_scene_add_light(scene, &sun);
    dwv_camera_t camera = test_ortho_camera(0.0, 0.0, thickness + 10.0, 2.0);
    dwv_scene_set_camera(scene, &camera);
    CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit: %s", dwv_last_error_message());
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = o.height = 16;
    o.samples = 256;
    o.technique = technique;
    o.seed = 3;
    dwv_image_t *image = NULL;
    CHECK(dwv_bake(scene, &o, &image) == DWV_SUCCESS, "bake: %s", dwv_last_error_message());
    double mean = 0.0, sigma = 0.0;
    if (image) image_mean(image, &mean, &sigma);

    dwv_estimate_options_t e = DWV_ESTIMATE_OPTIONS_INIT;
    e.shape = DWV_SHAPE_SLAB;
    e.thickness = thickness;
    e.medium.channels = 1;
    e.medium.sigma_t[0] = 1.0;
    double alpha = dwvb_albedo_inversion(colour, g);
    e.medium.albedo[0] = alpha;
    e.medium.anisotropy = g;
    e.incidence = DWV_INCIDENCE_DIFFUSE;
    e.light = transmit ? DWV_LIGHT_BACK : DWV_LIGHT_FRONT;
    e.technique = DWV_TECHNIQUE_CLASSICAL;
    e.walks = 400000;
    e.seed = 11;
    dwv_estimate_result_t ref = DWV_ESTIMATE_RESULT_INIT;
    CHECK(dwv_estimate(&e, &ref) == DWV_SUCCESS, "estimate: %s", dwv_last_error_message());
    double bound = 5.0 * sqrt(sigma * sigma + ref.std_error[0] * ref.std_error[0]);
    printf("slab T=%g colour %.2f (alpha %.5f) g %.1f %s %-9s: bake %.5f +- %.5f, estimate %.5f +- %.5f\n",
           thickness, colour, alpha, g, transmit ? "transmit" : "reflect ", dwv_technique_name(technique), mean,
           sigma, ref.mean[0], ref.std_error[0]);
    CHECK(alpha >= 0.2, "the test needs alpha >= 0.2 (no low-albedo rescaling), got %g", alpha);
    CHECK(sigma > 0.0 && fabs(mean - ref.mean[0]) < bound, "bake %.6f vs estimate %.6f (5 sigma %.6f)", mean,
          ref.mean[0], bound);
    dwv_image_release(image);
    dwv_scene_release(scene);
}

int main(void)
{
    check_slab(1.0, 0.8, 0.0, 1, DWV_TECHNIQUE_AUTO);
    check_slab(1.0, 0.8, 0.0, 0, DWV_TECHNIQUE_AUTO);
    check_slab(2.0, 0.9, 0.0, 1, DWV_TECHNIQUE_CLASSICAL);
    check_slab(2.0, 0.9, 0.0, 1, DWV_TECHNIQUE_INCIDENT);
    check_slab(0.5, 0.6, 0.5, 0, DWV_TECHNIQUE_CYCLES);
    check_slab(0.5, 0.6, 0.5, 1, DWV_TECHNIQUE_BACKWARD);
    return check_report("test_bake_slab");
}
