/* Lights in Blender's units: a white Lambertian floor lit by one light, seen straight down by a
 * narrow orthographic camera at the light's foot, has radiance (rho / pi) E with the irradiance E
 * that Cycles' conventions give (see src/light/light.h):
 *   sun of strength S, straight down:              E = S
 *   point of power P at height h (radius r << h):   E = P / (4 pi h^2)
 *   disk or rectangle of power P, area A, facing down at height h: L = P / (4 A), and for A << h^2
 *                                                   E = L A / h^2 = P / (4 h^2) (to O(A / h^2))
 *   world of radiance W with nothing above:         E = pi W (the floor is lit by the upper hemisphere)
 * Each bake is checked against E within 5 standard errors plus the stated model error. */
#include <math.h>
#include <stdio.h>

#include "bake_scenes.h"
#include "check.h"
#include <dwivedi.h>

#define PI 3.14159265358979323846

static double floor_radiance(const dwv_light_desc_t *light, double world, double rho, double *sigma)
{
    dwv_scene_t *scene;
    dwv_scene_create(&scene);
    dwv_material_t m = DWV_MATERIAL_INIT;
    m.kind = DWV_MATERIAL_DIFFUSE;
    m.base_color[0] = m.base_color[1] = m.base_color[2] = rho;
    test_mesh floor = test_box(-100.0, -100.0, -1.0, 100.0, 100.0, 0.0);
    test_add(scene, &floor, &m);
    test_mesh_free(&floor);
    if (light) dwv_scene_add_light(scene, light);
    double w[3] = {world, world, world};
    dwv_scene_set_world(scene, w, 1.0);
    dwv_camera_t camera = test_ortho_camera(0.0, 0.0, 0.5, 1e-3);
    dwv_scene_set_camera(scene, &camera);
    CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit: %s", dwv_last_error_message());
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = o.height = 4;
    o.samples = 4096;
    dwv_image_t *image = NULL;
    CHECK(dwv_bake(scene, &o, &image) == DWV_SUCCESS, "bake: %s", dwv_last_error_message());
    double sum = 0.0, variance = 0.0;
    if (image) {
        dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
        dwv_image_info(image, &info);
        for (int i = 0; i < 16; ++i) {
            sum += info.rgba[4 * i];
            variance += info.variance[3 * i];
        }
    }
    dwv_image_release(image);
    dwv_scene_release(scene);
    *sigma = sqrt(variance) / 16.0;
    return sum / 16.0;
}

static void expect(const char *name, const dwv_light_desc_t *light, double world, double rho, double want,
                   double model_error)
{
    double sigma;
    double got = floor_radiance(light, world, rho, &sigma);
    printf("%-28s %.6f +- %.6f, expected %.6f\n", name, got, sigma, want);
    /* 1e-6 relative: pixels are single-precision floats. */
    CHECK(fabs(got - want) <= 5.0 * sigma + (model_error + 1e-6) * want + 1e-12, "%s: %.7f, expected %.7f", name, got, want);
}

int main(void)
{
    double rho = 0.5;
    dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
    sun.strength = 3.0;
    expect("sun, angle 0", &sun, 0.0, rho, rho / PI * 3.0, 0.0);
    /* A 10-degree sun: the irradiance of its cone is S cos-weighted over the cone, S exactly at the
     * centre direction by construction, within 1 - cos(5 deg) = 0.4% elsewhere. */
    sun.angle = 10.0 * PI / 180.0;
    expect("sun, angle 10 deg", &sun, 0.0, rho, rho / PI * 3.0, 0.004);
    dwv_light_desc_t point = DWV_LIGHT_DESC_INIT;
    point.kind = DWV_LIGHT_POINT;
    point.position[2] = 2.0;
    point.strength = 100.0;
    expect("point, radius 0", &point, 0.0, rho, rho / PI * 100.0 / (4.0 * PI * 4.0), 0.0);
    point.radius = 0.05; /* a disc of radius r facing the point: E changes by O((r/h)^2) = 6e-4 */
    expect("point, radius 0.05", &point, 0.0, rho, rho / PI * 100.0 / (4.0 * PI * 4.0),
           1e-3);
    dwv_light_desc_t area = DWV_LIGHT_DESC_INIT;
    area.kind = DWV_LIGHT_AREA_RECTANGLE;
    area.transform[11] = 2.0; /* local -z is world -z: it faces the floor */
    area.size_x = 0.1;
    area.size_y = 0.05;
    area.strength = 100.0;
    /* A/h^2 = 1.25e-3: the exact irradiance of a small rectangle differs by about that much. */
    expect("rectangle", &area, 0.0, rho, rho / PI * 100.0 / (4.0 * 4.0), 3e-3);
    area.kind = DWV_LIGHT_AREA_DISK;
    expect("disk (ellipse)", &area, 0.0, rho, rho / PI * 100.0 / (4.0 * 4.0), 3e-3);
    /* Turned away (local -z up): a one-sided area light does not light the floor. */
    area.transform[5] = -1.0;
    area.transform[10] = -1.0;
    expect("disk facing away", &area, 0.0, rho, 0.0, 0.0);
    expect("world", NULL, 0.7, rho, rho * 0.7, 0.0);
    return check_report("test_bake_lights");
}
