/* Direct light with each lobe about its own normal (src/light/direct.c dwvl_direct_lobes, wired in
 * src/bake/shade.c shade_point): a Blender 4.x+ specular layer whose mapped normal n was kept valid
 * for reflection (specular_n != n) takes its light with its own cosine and from above its own
 * horizon, as Cycles evaluates each closure about its own N (bsdf_eval, 4.3 and 5.2).
 *
 * Scene: a black-based (pure glossy) v2 quad with a constant normal map tilted 20 degrees toward +x
 * (Chiang 2019 mapped, 4.x's), seen by an orthographic camera at 60 degrees from the -x side: the
 * view's mirror reflection about n would point below the surface (60 + 2 x 20 > 90), so the
 * specular's normal is turned back (dwvb_valid_reflection). Every camera ray meets the quad at the
 * same angles, so each pixel is one number:
 * 1. A sun of angle 0 on the +x side, 15 degrees above the quad (above both horizons): each pixel
 *    is exactly S f_s (specular_n . L) / pi (float rounding: bound 1e-5 relative). Main's code gave
 *    S f_s (n . L) / pi, 1.157 times that (all three cases fail on main's code).
 * 2. A sun on the -x side between the two horizons (above specular_n's, below n's): the same
 *    expression, > 0; main's code gave exactly 0.
 * 3. A constant world (no sun): the mean over 16 x 16 pixels x 256 samples equals
 *    L (1/pi) integral f_s (specular_n . w)+ over the directions above the quad (a midpoint rule of
 *    1200 x 2400 cells, its error far below the bound) within 5 standard errors + 1e-4 relative.
 *    (here -1.2 standard errors of 0.3%). Main's code (the cosine about n and n's cosine) was
 *    +10.1%, 11 standard errors off.
 * 4. The same bake from 1 and 2 threads is bit-identical. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake/material.h"
#include "bake/textured.h"
#include "bake_compare.h"
#include "check.h"
#include <dwivedi.h>

#define PI 3.14159265358979323846
#define VIEW (PI / 3.0)   /* the view's angle from the quad's normal, from the -x side */
#define TILT (PI / 9.0)   /* the normal map's tilt toward +x */
#define SUN 2.0           /* the sun's strength (irradiance) */

static dwv_material_t glossy_material(void)
{
    dwv_material_t m = DWV_MATERIAL_INIT;
    m.kind = DWV_MATERIAL_DIFFUSE;
    m.base_color[0] = m.base_color[1] = m.base_color[2] = 0.0;
    m.specular_model = DWV_SPECULAR_PRINCIPLED_V2;
    m.roughness = 0.7;
    m.ior = 1.5;
    m.specular = 0.5;
    return m;
}

static dwvu_vec3 to_view(void) { return dwvu_v(-sin(VIEW), 0.0, cos(VIEW)); }
static dwvu_vec3 mapped_normal(void) { return dwvu_v(sin(TILT), 0.0, cos(TILT)); }
static dwvu_vec3 specular_normal(void) { return dwvb_valid_reflection(dwvu_v(0, 0, 1), to_view(), mapped_normal()); }

/* The quad [-1, 1]^2 at z = 0 with the normal map, a camera along to_view seeing its middle, and
 * a sun travelling along -toward (strength SUN) unless toward is 0, or a world of radiance `world`. */
static dwv_scene_t *scene_with(dwvu_vec3 toward, double world)
{
    dwv_scene_t *scene = NULL;
    if (dwv_scene_create(&scene) != DWV_SUCCESS) exit(2);
    dwv_material_t m = glossy_material();
    uint32_t material = 0, texture = 0, id = 0;
    CHECK(dwv_scene_add_material(scene, &m, &material) == DWV_SUCCESS, "material: %s", dwv_last_error_message());
    const float tilt[3] = {(float)(0.5 + 0.5 * sin(TILT)), 0.5f, (float)(0.5 + 0.5 * cos(TILT))};
    dwv_texture_desc_t d = DWV_TEXTURE_DESC_INIT;
    d.width = d.height = 1, d.channels = 3, d.texels = tilt;
    CHECK(dwv_scene_add_texture(scene, &d, &texture) == DWV_SUCCESS, "texture: %s", dwv_last_error_message());
    dwv_texture_binding_t b = DWV_TEXTURE_BINDING_INIT;
    b.input = DWV_INPUT_NORMAL_MAP, b.texture_id = texture, b.bump_shadowing = DWV_BUMP_SHADOWING_CHIANG2019_MAPPED;
    CHECK(dwv_scene_bind_texture(scene, material, &b) == DWV_SUCCESS, "bind: %s", dwv_last_error_message());
    static const float positions[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    static const uint32_t indices[6] = {0, 1, 2, 0, 2, 3};
    static const float uvs[12] = {0, 0, 1, 0, 1, 1, 0, 0, 1, 1, 0, 1};
    dwv_mesh_t mesh = DWV_MESH_INIT;
    mesh.vertex_count = 4, mesh.triangle_count = 2, mesh.material_id = material;
    mesh.positions = positions, mesh.indices = indices, mesh.uvs = uvs;
    CHECK(dwv_scene_add_mesh(scene, &mesh, &id) == DWV_SUCCESS, "quad: %s", dwv_last_error_message());
    if (toward.x != 0.0 || toward.y != 0.0 || toward.z != 0.0) {
        dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
        sun.strength = SUN;
        sun.direction[0] = -toward.x, sun.direction[1] = -toward.y, sun.direction[2] = -toward.z;
        CHECK(dwv_scene_add_light(scene, &sun) == DWV_SUCCESS, "sun: %s", dwv_last_error_message());
    }
    const double white[3] = {1.0, 1.0, 1.0};
    if (world > 0.0) CHECK(dwv_scene_set_world(scene, white, world) == DWV_SUCCESS, "world");
    /* Camera axes: x (cos, 0, sin) of the view's plane, y up, z = to_view (it looks along -z). */
    dwvu_vec3 v = to_view();
    dwv_camera_t camera = DWV_CAMERA_INIT;
    camera.kind = DWV_CAMERA_ORTHOGRAPHIC;
    const double t[12] = {cos(VIEW), 0, v.x, 5.0 * v.x, 0, 1, 0, 0, sin(VIEW), 0, v.z, 5.0 * v.z};
    memcpy(camera.transform, t, sizeof t);
    camera.ortho_scale = 0.5;
    CHECK(dwv_scene_set_camera(scene, &camera) == DWV_SUCCESS, "camera: %s", dwv_last_error_message());
    CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit: %s", dwv_last_error_message());
    return scene;
}

/* The glossy BRDF's factor f_s (the BRDF is f_s / pi) for light along unit l, about specular_n. */
static void specular_factor(dwvu_vec3 l, double f[3])
{
    dwv_material_t desc = glossy_material();
    static dwvb_material m;
    static int made = 0;
    if (!made) dwvb_material_init(&m, &desc), made = 1;
    dwvb_specular_factor(&m, specular_normal(), l, to_view(), f);
}

static void check_sun(const char *name, dwvu_vec3 toward)
{
    double f[3];
    specular_factor(toward, f);
    double cos_s = dwvu_dot(specular_normal(), toward), expected = SUN * f[0] * cos_s / PI;
    CHECK(expected > 1e-4, "%s: the expected value is not small (%g)", name, expected);
    dwv_scene_t *scene = scene_with(toward, 0.0);
    test_result r;
    if (test_bake_result(scene, DWV_TECHNIQUE_AUTO, DWV_CHANNEL_WALKS_AUTO, 8, 2, 3u, &r)) {
        float lo = r.rgba[0], hi = r.rgba[0];
        for (size_t i = 0; i < r.pixels; ++i) lo = fminf(lo, r.rgba[4u * i]), hi = fmaxf(hi, r.rgba[4u * i]);
        CHECK(fabs(lo - expected) <= 1e-5 * expected && fabs(hi - expected) <= 1e-5 * expected,
              "%s: pixels in [%.9g, %.9g], expected %.9g (n's cosine would give %.9g)", name, lo, hi, expected,
              SUN * f[0] * fmax(dwvu_dot(mapped_normal(), toward), 0.0) / PI);
        printf("%s: %.9g (expected %.9g; cos to n %.4f, to specular_n %.4f)\n", name, r.rgba[0], expected,
               dwvu_dot(mapped_normal(), toward), cos_s);
        free(r.rgba);
    }
    dwv_scene_release(scene);
}

/* L (1/pi) integral over the upper hemisphere of f_s (specular_n . w)+ by the midpoint rule. */
static double world_expected(double world)
{
    const int rows = 1200, columns = 2400;
    double sum = 0.0;
    for (int i = 0; i < rows; ++i) {
        double theta = (i + 0.5) * (0.5 * PI / rows), st = sin(theta), ct = cos(theta);
        for (int j = 0; j < columns; ++j) {
            double phi = (j + 0.5) * (2.0 * PI / columns);
            dwvu_vec3 w = dwvu_v(st * cos(phi), st * sin(phi), ct);
            double cos_s = dwvu_dot(specular_normal(), w);
            if (!(cos_s > 0.0)) continue;
            double f[3];
            specular_factor(w, f);
            sum += f[0] * cos_s * st;
        }
    }
    return world * sum * (0.5 * PI / rows) * (2.0 * PI / columns) / PI;
}

static void check_world(void)
{
    const double world = 1.5;
    double expected = world_expected(world);
    dwv_scene_t *scene = scene_with(dwvu_v(0, 0, 0), world);
    test_result r;
    if (test_bake_result(scene, DWV_TECHNIQUE_AUTO, DWV_CHANNEL_WALKS_AUTO, 16, 256, 5u, &r)) {
        double z = (r.mean[0] - expected) / r.standard_error[0];
        CHECK(fabs(r.mean[0] - expected) <= 5.0 * r.standard_error[0] + 1e-4 * expected,
              "constant world: mean %.7g, expected %.7g (%.2f standard errors of %.3g)", r.mean[0], expected, z,
              r.standard_error[0]);
        printf("constant world: mean %.7g, expected %.7g, %.2f standard errors (%.3g relative)\n", r.mean[0], expected,
               z, r.standard_error[0] / expected);
        /* The same image from one thread. */
        dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
        o.width = o.height = 16, o.samples = 256, o.threads = 1, o.seed = 5u;
        dwv_image_t *image = NULL;
        if (dwv_bake(scene, &o, &image) == DWV_SUCCESS) {
            dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
            dwv_image_info(image, &info);
            CHECK(memcmp(info.rgba, r.rgba, 4u * r.pixels * sizeof *r.rgba) == 0, "1 and 2 threads differ");
            dwv_image_release(image);
        } else {
            CHECK(0, "one-thread bake: %s", dwv_last_error_message());
        }
        free(r.rgba);
    }
    dwv_scene_release(scene);
}

int main(void)
{
    dwvu_vec3 n = mapped_normal(), s = specular_normal();
    CHECK(dwvu_dot(n, s) < 1.0 - 1e-6, "the normal was corrected (specular_n %g %g %g)", s.x, s.y, s.z);
    /* 1. Above both horizons, 15 degrees over the quad on the +x side. */
    check_sun("sun above both", dwvu_v(cos(PI / 12.0), 0.0, sin(PI / 12.0)));
    /* 2. Between the horizons on the -x side: elevation halfway between specular_n's and n's. */
    double tilt_s = atan2(s.x, s.z), elevation = 0.5 * (tilt_s + TILT);
    dwvu_vec3 between = dwvu_v(-cos(elevation), 0.0, sin(elevation));
    CHECK(dwvu_dot(s, between) > 0.0 && dwvu_dot(n, between) < 0.0, "between the horizons");
    check_sun("sun between the horizons", between);
    check_world();
    return check_report("internal.test_lobe_normals");
}
