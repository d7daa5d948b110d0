/* Mirror-sharp specular (issue 18 item 4): a Principled specular layer of Roughness 0 reflects
 * the world, the lights and the other surfaces through its singular lobe, as Cycles' singular
 * microfacet does (eval / pdf = the Fresnel at H = N, no MIS: the whole emission a reflected
 * ray meets).
 *
 * The scenes are exact: a black-based (pure glossy) plane seen by an orthographic camera at 60
 * degrees from its normal, so every camera ray meets it at the same cosine and reflects along
 * one direction. With the diffuse lobes black the mixture draws the mirror every time (p_s = 1)
 * and every sample weighs F(mu) x what the reflected ray meets: each pixel is that, up to
 * float rounding (bound: 1e-6 relative), independent of the samples. Checked:
 * - a constant world: F L_world per channel, for Blender 3.x's Principled v1 (cspec0 (1 - FH) +
 *   FH) and 4.x+'s v2 (f0 + (1 - f0) s, tinted), also with max_bounces 0 and with glossy_bounces
 *   0 (Cycles traces the bounce that exceeds a limit for its emission: a mirror shows the world
 *   whatever the limits), and in the Glossy Direct pass, Glossy Indirect being 0;
 * - an area light where the reflection points (world black): F L_area, L_area = P / (4 A); a
 *   sun of angle 10 degrees there: F S / (pi sin^2(5 degrees)); a sun just outside its own
 *   cone: 0;
 * - a white diffuse box standing on the plane and lit by a sun, seen in the mirror: the pixels
 *   that see it agree with its own direct light at F x (same samples, so compared by mean within
 *   6 standard errors + 1e-6) and lie in Glossy Indirect;
 * - the same image from 1 and 2 threads; the stats count path rays (none with the one bounce of
 *   a diffuse scene, some here).
 * On the library before the singular lobe every mirror pixel was 0 (this test fails there). */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake_scenes.h"
#include "check.h"
#include <dwivedi.h>

#define PI 3.14159265358979323846
#define VIEW_ANGLE (PI / 3.0) /* between the camera's view and the plane's normal */

/* The dielectric Fresnel reflectance for cosine c and relative IOR eta (unpolarised). */
static double fresnel(double c, double eta)
{
    double g2 = eta * eta - 1.0 + c * c;
    if (g2 < 0.0) return 1.0;
    double g = sqrt(g2), a = (g - c) / (g + c), b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    return 0.5 * a * a * (1.0 + b * b);
}

/* The mirror's reflectance at cosine mu per channel, from the materials' definitions in
 * capi/dwivedi.h (DWV_SPECULAR_PRINCIPLED_V1 / _V2) with tint as set below. */
static void mirror_reflectance(const dwv_material_t *m, double mu, double f[3])
{
    if (m->specular_model == DWV_SPECULAR_PRINCIPLED_V1) {
        double eta = 2.0 / (1.0 - sqrt(0.08 * m->specular)) - 1.0, F0 = fresnel(1.0, eta);
        double fh = (fresnel(mu, eta) - F0) / (1.0 - F0);
        for (int c = 0; c < 3; ++c) f[c] = 0.08 * m->specular * (1.0 - fh) + fh; /* tint 0 */
        return;
    }
    double r = (m->ior - 1.0) / (m->ior + 1.0), F0 = r * r * 2.0 * m->specular;
    double q = sqrt(F0), eta = (1.0 + q) / (1.0 - q);
    double s = (fresnel(mu, eta) - F0) / (1.0 - F0);
    s = s < 0.0 ? 0.0 : s > 1.0 ? 1.0 : s;
    for (int c = 0; c < 3; ++c) f[c] = F0 * m->specular_tint[c] + (1.0 - F0 * m->specular_tint[c]) * s;
}

static dwv_material_t mirror_material(int model)
{
    dwv_material_t m = DWV_MATERIAL_INIT;
    m.kind = DWV_MATERIAL_DIFFUSE;
    m.base_color[0] = m.base_color[1] = m.base_color[2] = 0.0;
    m.roughness = 0.0;
    m.specular_model = model;
    if (model == DWV_SPECULAR_PRINCIPLED_V1) {
        m.specular = 1.0;
        m.specular_tint[0] = 0.0;
    } else {
        m.ior = 2.5;
        m.specular = 0.8;
        m.specular_tint[0] = 1.0, m.specular_tint[1] = 0.7, m.specular_tint[2] = 0.4;
    }
    return m;
}

/* The mirror direction of every camera ray: the view (0, sin, -cos) reflected about +z. */
static void reflected(double d[3])
{
    d[0] = 0.0, d[1] = sin(VIEW_ANGLE), d[2] = cos(VIEW_ANGLE);
}

/* A 40 x 40 m plane of `mirror` (the top of a slab at z = 0), optionally a 1 m white box standing
 * on it in the reflection's way, an orthographic camera 1 m across looking at the origin at
 * VIEW_ANGLE. Lights and world are the caller's (before commit). */
static dwv_scene_t *mirror_scene(const dwv_material_t *mirror, int with_box)
{
    dwv_scene_t *scene;
    dwv_scene_create(&scene);
    test_mesh slab = test_box(-20.0, -20.0, -1.0, 20.0, 20.0, 0.0);
    test_add(scene, &slab, mirror);
    test_mesh_free(&slab);
    if (with_box) {
        dwv_material_t white = DWV_MATERIAL_INIT;
        white.kind = DWV_MATERIAL_DIFFUSE;
        white.base_color[0] = white.base_color[1] = white.base_color[2] = 0.8;
        test_mesh box = test_box(-3.0, 2.0, 0.0, 3.0, 3.0, 6.0);
        test_add(scene, &box, &white);
        test_mesh_free(&box);
    }
    double s = sin(VIEW_ANGLE), c = cos(VIEW_ANGLE);
    dwv_camera_t camera = test_ortho_camera(0.0, -10.0 * s, 10.0 * c, 1.0);
    /* Rotation about x by VIEW_ANGLE: the camera's -z (its view) becomes (0, s, -c). */
    double rotation[9] = {1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) camera.transform[4 * i + j] = rotation[3 * i + j];
    dwv_scene_set_camera(scene, &camera);
    return scene;
}

static dwv_bake_options_t options(void)
{
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = o.height = 8;
    o.samples = 4;
    o.seed = 18;
    o.threads = 1;
    o.technique = DWV_TECHNIQUE_CLASSICAL;
    /* The exact mirror at every vertex (Filter Glossy would roughen it after the box's diffuse
     * bounce, which the black plane of the reflected view has not: unit.test_blur_glossy). */
    o.blur_glossy = 0.0;
    return o;
}

/* Largest relative difference of the image's RGB (or of pass `pass`, if not combined) from
 * `expect` over the pixels. */
static double worst_difference(dwv_image_t *image, dwv_pass_t pass, const double expect[3])
{
    dwv_image_t *view = image;
    if (pass != DWV_PASS_COMBINED && dwv_image_pass(image, pass, &view) != DWV_SUCCESS) {
        CHECK(0, "pass %d: %s", (int)pass, dwv_last_error_message());
        return INFINITY;
    }
    dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
    dwv_image_info(view, &info);
    double worst = 0.0;
    for (size_t i = 0; i < (size_t)info.width * info.height; ++i)
        for (int c = 0; c < 3; ++c) {
            double scale = fmax(fabs(expect[c]), 1e-30);
            double d = fabs(info.rgba[4 * i + c] - expect[c]) / scale;
            worst = isfinite(d) ? fmax(worst, d) : INFINITY;
        }
    if (view != image) dwv_image_release(view);
    return worst;
}

static dwv_image_t *bake(dwv_scene_t *scene, const dwv_bake_options_t *o)
{
    dwv_image_t *image = NULL;
    CHECK(dwv_bake(scene, o, &image) == DWV_SUCCESS, "bake: %s", dwv_last_error_message());
    return image;
}

static void test_world(int model)
{
    dwv_material_t mirror = mirror_material(model);
    dwv_scene_t *scene = mirror_scene(&mirror, 0);
    double world[3] = {0.2, 0.5, 1.0};
    dwv_scene_set_world(scene, world, 2.0);
    CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit: %s", dwv_last_error_message());
    double f[3], expect[3], zero[3] = {0.0, 0.0, 0.0};
    mirror_reflectance(&mirror, cos(VIEW_ANGLE), f);
    for (int c = 0; c < 3; ++c) expect[c] = f[c] * world[c] * 2.0;
    dwv_bake_options_t o = options();
    o.passes = DWV_PASS_BIT(DWV_PASS_GLOSSY_DIRECT) | DWV_PASS_BIT(DWV_PASS_GLOSSY_INDIRECT) |
               DWV_PASS_BIT(DWV_PASS_GLOSSY_COLOR);
    dwv_image_t *image = bake(scene, &o);
    if (image) {
        double combined = worst_difference(image, DWV_PASS_COMBINED, expect);
        /* Blender's Glossy Direct is divided by Glossy Color: compare the product. */
        dwv_image_t *direct = NULL, *color = NULL;
        dwv_image_pass(image, DWV_PASS_GLOSSY_DIRECT, &direct);
        dwv_image_pass(image, DWV_PASS_GLOSSY_COLOR, &color);
        double worst_pass = INFINITY;
        if (direct && color) {
            dwv_image_info_t di = DWV_IMAGE_INFO_INIT, ci = DWV_IMAGE_INFO_INIT;
            dwv_image_info(direct, &di);
            dwv_image_info(color, &ci);
            worst_pass = 0.0;
            for (size_t i = 0; i < (size_t)di.width * di.height; ++i)
                for (int c = 0; c < 3; ++c)
                    worst_pass = fmax(worst_pass, fabs(di.rgba[4 * i + c] * ci.rgba[4 * i + c] - expect[c]) / expect[c]);
        }
        dwv_image_release(direct), dwv_image_release(color);
        double indirect = worst_difference(image, DWV_PASS_GLOSSY_INDIRECT, zero);
        printf("model %d, world: F %.5f %.5f %.5f; combined off by %.2g, glossy direct x colour by %.2g, indirect %.2g\n",
               model, f[0], f[1], f[2], combined, worst_pass, indirect);
        CHECK(combined < 1e-6, "model %d: the mirror's world is off by %g", model, combined);
        CHECK(worst_pass < 1e-5, "model %d: Glossy Direct x Glossy Color off by %g", model, worst_pass);
        CHECK(indirect == 0.0, "model %d: Glossy Indirect is not 0 (%g)", model, indirect);
        dwv_image_release(image);
    }
    /* Past the limits the reflection is still traced for its emission (Cycles' kernel limits are
     * the scene's + 1). */
    dwv_bake_options_t limited = options();
    limited.max_bounces = 0;
    image = bake(scene, &limited);
    double at_zero = image ? worst_difference(image, DWV_PASS_COMBINED, expect) : INFINITY;
    dwv_image_release(image);
    limited = options();
    limited.glossy_bounces = 0;
    image = bake(scene, &limited);
    double glossy_zero = image ? worst_difference(image, DWV_PASS_COMBINED, expect) : INFINITY;
    dwv_image_release(image);
    CHECK(at_zero < 1e-6 && glossy_zero < 1e-6, "model %d: max_bounces 0 off by %g, glossy_bounces 0 by %g", model,
          at_zero, glossy_zero);
    dwv_scene_release(scene);
}

static void test_lights(void)
{
    dwv_material_t mirror = mirror_material(DWV_SPECULAR_PRINCIPLED_V1);
    double f[3], d[3];
    mirror_reflectance(&mirror, cos(VIEW_ANGLE), f);
    reflected(d);
    /* An area light 2 x 2 m facing the mirror, centred 8 m along the reflection. */
    dwv_scene_t *scene = mirror_scene(&mirror, 0);
    dwv_light_desc_t area = DWV_LIGHT_DESC_INIT;
    area.kind = DWV_LIGHT_AREA_RECTANGLE;
    area.strength = 100.0;
    area.color[1] = 0.5;
    area.size_x = area.size_y = 2.0;
    /* Its local -z (emission) along -d: local z = d, x = (1, 0, 0), y = z x x. */
    double y[3] = {0.0, d[2], -d[1]};
    for (int i = 0; i < 3; ++i) {
        area.transform[4 * i + 0] = i == 0 ? 1.0 : 0.0;
        area.transform[4 * i + 1] = y[i];
        area.transform[4 * i + 2] = d[i];
        area.transform[4 * i + 3] = 8.0 * d[i];
    }
    dwv_scene_add_light(scene, &area);
    CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit: %s", dwv_last_error_message());
    double expect[3];
    for (int c = 0; c < 3; ++c) expect[c] = f[c] * area.color[c] * area.strength / (4.0 * 4.0);
    dwv_bake_options_t o = options();
    dwv_image_t *image = bake(scene, &o);
    double area_off = image ? worst_difference(image, DWV_PASS_COMBINED, expect) : INFINITY;
    dwv_image_release(image);
    dwv_scene_release(scene);
    /* A sun of 10 degrees along the reflection, then one whose cone just misses it. */
    double sun_off[2];
    for (int k = 0; k < 2; ++k) {
        scene = mirror_scene(&mirror, 0);
        dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
        sun.strength = 3.0;
        sun.angle = 10.0 * PI / 180.0;
        double tilt = k ? 5.5 * PI / 180.0 : 1.0 * PI / 180.0; /* the sun's centre off the reflection */
        double toward[3] = {sin(tilt), d[1] * cos(tilt), d[2] * cos(tilt)};
        for (int i = 0; i < 3; ++i) sun.direction[i] = -toward[i];
        dwv_scene_add_light(scene, &sun);
        CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit: %s", dwv_last_error_message());
        double half = 0.5 * sun.angle, radiance = sun.strength / (PI * sin(half) * sin(half));
        for (int c = 0; c < 3; ++c) expect[c] = k ? 0.0 : f[c] * radiance;
        image = bake(scene, &o);
        double zero[3] = {0.0, 0.0, 0.0};
        sun_off[k] = image ? worst_difference(image, DWV_PASS_COMBINED, k ? zero : expect) : INFINITY;
        if (k && image) {
            /* (absolute: the expected value is 0) */
            dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
            dwv_image_info(image, &info);
            sun_off[k] = 0.0;
            for (size_t i = 0; i < (size_t)info.width * info.height; ++i) sun_off[k] = fmax(sun_off[k], fabs(info.rgba[4 * i]));
        }
        dwv_image_release(image);
        dwv_scene_release(scene);
    }
    printf("lights in the mirror: area off by %.2g, sun by %.2g, sun outside its cone gives %.2g\n", area_off, sun_off[0],
           sun_off[1]);
    CHECK(area_off < 1e-6, "the area light in the mirror is off by %g", area_off);
    CHECK(sun_off[0] < 1e-6, "the sun in the mirror is off by %g", sun_off[0]);
    CHECK(sun_off[1] == 0.0, "a sun outside the reflection shows in it: %g", sun_off[1]);
}

/* Mean of channel c over the pixels and its standard error. */
static void pixel_mean(dwv_image_t *image, int c, double *mean, double *sigma)
{
    dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
    dwv_image_info(image, &info);
    size_t n = (size_t)info.width * info.height;
    double sum = 0.0, variance = 0.0;
    for (size_t i = 0; i < n; ++i) sum += info.rgba[4 * i + c], variance += info.variance[3 * i + c];
    *mean = sum / (double)n;
    *sigma = sqrt(variance) / (double)n;
}

static void test_surface_in_mirror(void)
{
    /* The box's face toward the camera, seen in the mirror at F, against the same face seen
     * directly by a camera along the reflected ray (the plane's reflection of the view), with
     * the mirror replaced by black: (1 / F) x the mirror's image is the direct one. */
    dwv_material_t mirror = mirror_material(DWV_SPECULAR_PRINCIPLED_V2);
    double f[3];
    mirror_reflectance(&mirror, cos(VIEW_ANGLE), f);
    dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
    sun.strength = 4.0;
    sun.direction[0] = 0.3, sun.direction[1] = 1.0, sun.direction[2] = -0.4;
    dwv_scene_t *scene = mirror_scene(&mirror, 1);
    dwv_scene_add_light(scene, &sun);
    CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit: %s", dwv_last_error_message());
    dwv_bake_options_t o = options();
    o.samples = 64;
    o.passes = DWV_PASS_BIT(DWV_PASS_GLOSSY_INDIRECT) | DWV_PASS_BIT(DWV_PASS_GLOSSY_DIRECT);
    dwv_image_t *one = bake(scene, &o);
    o.threads = 2;
    dwv_image_t *two = bake(scene, &o);
    if (one && two) {
        dwv_image_info_t a = DWV_IMAGE_INFO_INIT, b = DWV_IMAGE_INFO_INIT;
        dwv_image_info(one, &a);
        dwv_image_info(two, &b);
        CHECK(memcmp(a.rgba, b.rgba, 4u * a.width * a.height * sizeof(float)) == 0, "1 and 2 threads differ");
        dwv_bake_stats_t stats = DWV_BAKE_STATS_INIT;
        dwv_image_stats(one, &stats);
        printf("box in the mirror: %llu path rays for %llu samples\n", (unsigned long long)stats.path_rays,
               (unsigned long long)stats.samples);
        CHECK(stats.path_rays >= stats.samples, "path rays %llu for %llu samples", (unsigned long long)stats.path_rays,
              (unsigned long long)stats.samples);
    }
    /* The same face seen directly: the camera mirrored through the plane (z -> -z, the view
     * reflected), the plane black. */
    dwv_material_t black = DWV_MATERIAL_INIT;
    black.kind = DWV_MATERIAL_DIFFUSE;
    black.base_color[0] = black.base_color[1] = black.base_color[2] = 0.0;
    dwv_scene_t *direct_scene = mirror_scene(&black, 1);
    double s = sin(VIEW_ANGLE), c = cos(VIEW_ANGLE);
    /* The reflected camera's rays are the mirror's reflected rays; it is moved along them to
     * (0, s, c) so that its image plane lies above the slab. Its frame is a rotation with view
     * (0, s, c): the image is the mirror's upside down, which the mean does not see. */
    dwv_camera_t camera = test_ortho_camera(0.0, s, c, 1.0);
    double rotation[9] = {1.0, 0.0, 0.0, 0.0, -c, -s, 0.0, s, -c};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) camera.transform[4 * i + j] = rotation[3 * i + j];
    dwv_scene_set_camera(direct_scene, &camera);
    dwv_scene_add_light(direct_scene, &sun);
    CHECK(dwv_scene_commit(direct_scene) == DWV_SUCCESS, "commit: %s", dwv_last_error_message());
    o.threads = 1;
    o.passes = 0;
    o.seed = 19;
    dwv_image_t *seen = bake(direct_scene, &o);
    if (one && seen) {
        for (int ch = 0; ch < 3; ++ch) {
            double m, ms, d, ds, gi, gis;
            pixel_mean(one, ch, &m, &ms);
            pixel_mean(seen, ch, &d, &ds);
            dwv_image_t *indirect = NULL;
            dwv_image_pass(one, DWV_PASS_GLOSSY_INDIRECT, &indirect);
            pixel_mean(indirect, ch, &gi, &gis);
            dwv_image_release(indirect);
            double reflected_mean = m / f[ch], reflected_sigma = ms / f[ch];
            printf("channel %d: in the mirror / F %.5f +- %.5f, seen directly %.5f +- %.5f (glossy indirect / colour %.5f)\n",
                   ch, reflected_mean, reflected_sigma, d, ds, gi);
            CHECK(d > 0.05 && fabs(reflected_mean - d) < 6.0 * hypot(reflected_sigma, ds) + 1e-6 * d,
                  "channel %d: the box in the mirror %.5f, directly %.5f", ch, reflected_mean, d);
            CHECK(gi > 0.0, "channel %d: the box in the mirror is not in Glossy Indirect", ch);
        }
    }
    dwv_image_release(one), dwv_image_release(two), dwv_image_release(seen);
    dwv_scene_release(scene);
    dwv_scene_release(direct_scene);
}

int main(void)
{
    test_world(DWV_SPECULAR_PRINCIPLED_V1);
    test_world(DWV_SPECULAR_PRINCIPLED_V2);
    test_lights();
    test_surface_in_mirror();
    return check_report("test_mirror_paths");
}
