/* Blender's cameras: a square of half-size 1.8 at distance 10, seen by a 50 mm lens on a 36 mm
 * sensor (half field tan = 18/50 = 0.36, so 3.6 at that distance) or an orthographic camera of
 * scale 7.2, covers half of the larger image side ("Auto" sensor fit) and all of the smaller one
 * when the image is 2:1, a quarter of the pixels when it is square. Coverage is read from alpha. */
#include <math.h>
#include <stdio.h>

#include "bake_scenes.h"
#include "check.h"
#include <dwivedi.h>

static double coverage(dwv_camera_kind_t kind, uint32_t width, uint32_t height)
{
    dwv_scene_t *scene;
    dwv_scene_create(&scene);
    dwv_material_t m = DWV_MATERIAL_INIT;
    m.kind = DWV_MATERIAL_DIFFUSE;
    test_mesh square = test_box(-1.8, -1.8, -1.0, 1.8, 1.8, 0.0);
    test_add(scene, &square, &m);
    test_mesh_free(&square);
    dwv_camera_t camera = test_ortho_camera(0.0, 0.0, 10.0, 7.2);
    camera.kind = kind;
    dwv_scene_set_camera(scene, &camera);
    CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit: %s", dwv_last_error_message());
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = width;
    o.height = height;
    o.samples = 16;
    dwv_image_t *image = NULL;
    CHECK(dwv_bake(scene, &o, &image) == DWV_SUCCESS, "bake: %s", dwv_last_error_message());
    double sum = 0.0;
    if (image) {
        dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
        dwv_image_info(image, &info);
        for (uint32_t i = 0; i < width * height; ++i) sum += info.rgba[4 * i + 3];
    }
    dwv_image_release(image);
    dwv_scene_release(scene);
    return sum / (width * height);
}

int main(void)
{
    static const dwv_camera_kind_t kinds[] = {DWV_CAMERA_PERSPECTIVE, DWV_CAMERA_ORTHOGRAPHIC};
    for (int k = 0; k < 2; ++k) {
        /* The square's edges fall on pixel boundaries (it spans exactly the middle half), and the
         * box's sides project inside the top face's outline, so the fractions are exact. */
        double square = coverage(kinds[k], 64, 64), wide = coverage(kinds[k], 64, 32), tall = coverage(kinds[k], 32, 64);
        printf("%s: square %.4f (0.25), 2:1 %.4f (0.5), 1:2 %.4f (0.5)\n", k ? "orthographic" : "perspective", square,
               wide, tall);
        CHECK(fabs(square - 0.25) < 0.004, "square image coverage %.4f", square);
        CHECK(fabs(wide - 0.5) < 0.004, "wide image coverage %.4f", wide);
        CHECK(fabs(tall - 0.5) < 0.004, "tall image coverage %.4f", tall);
    }
    return check_report("test_bake_camera");
}
