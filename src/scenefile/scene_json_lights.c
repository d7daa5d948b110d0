/* The scene file's lights, world and camera. */
#include "scenefile/scene_json_internal.h"

#include "util/error.h"
#include "scenefile/transform.h"

#include <stdlib.h>

static dwv_result_t read_light(dwvs_parser *ps, const cJSON *item, const char *path)
{
    static const char *const kinds[] = {"sun", "point", "area", "spot"};
    static const char *const shapes[] = {"rectangle", "disk"};
    static const char *const sun_keys[] = {"kind", "color", "strength", "direction", "angle"};
    static const char *const point_keys[] = {"kind", "color", "strength", "position", "radius", "point_shape"};
    static const char *const area_keys[] = {"kind", "shape", "color", "strength", "transform", "size_x", "size_y"};
    static const char *const spot_keys[] = {"kind",       "color",      "strength", "position",    "radius",
                                            "direction",  "spot_size",  "spot_blend", "spot_falloff",
                                            "point_shape"};
    static const char *const falloffs[] = {"cycles3", "cycles4"};
    static const char *const point_shapes[] = {"disc", "sphere"}; /* DWV_POINT_SHAPE_* in order */
    if (!cJSON_IsObject(item))
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "expected an object, found %s", dwvs_type_name(item));
    const cJSON *kind_item = dwvs_member(item, "kind");
    if (!kind_item)
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "missing key 'kind' ('sun', 'point', 'area' or 'spot')");
    char p[PATH_SIZE];
    size_t kind = 0;
    dwvs_path_key(p, path, "kind");
    DWV_TRY(dwvs_read_choice(kind_item, p, kinds, 4, &kind));
    if (kind == 0)
        DWV_TRY(dwvs_check_keys(item, path, sun_keys, sizeof sun_keys / sizeof sun_keys[0]));
    else if (kind == 1)
        DWV_TRY(dwvs_check_keys(item, path, point_keys, sizeof point_keys / sizeof point_keys[0]));
    else if (kind == 2)
        DWV_TRY(dwvs_check_keys(item, path, area_keys, sizeof area_keys / sizeof area_keys[0]));
    else
        DWV_TRY(dwvs_check_keys(item, path, spot_keys, sizeof spot_keys / sizeof spot_keys[0]));
    dwv_light_desc_t light = DWV_LIGHT_DESC_INIT;
    DWV_TRY(dwvs_opt_vector(item, path, "color", 3, light.color));
    DWV_TRY(dwvs_opt_number(item, path, "strength", &light.strength));
    if (kind == 0) {
        light.kind = DWV_LIGHT_SUN;
        DWV_TRY(dwvs_opt_vector(item, path, "direction", 3, light.direction));
        double degrees = 0.0;
        DWV_TRY(dwvs_opt_number(item, path, "angle", &degrees));
        light.angle = degrees * (3.14159265358979323846 / 180.0);
    } else if (kind == 1) {
        light.kind = DWV_LIGHT_POINT;
        DWV_TRY(dwvs_opt_vector(item, path, "position", 3, light.position));
        DWV_TRY(dwvs_opt_number(item, path, "radius", &light.radius));
        size_t point_shape = 0;
        DWV_TRY(dwvs_opt_choice(item, path, "point_shape", point_shapes, 2, &point_shape));
        light.point_shape = (int32_t)point_shape;
    } else if (kind == 3) {
        light.kind = DWV_LIGHT_SPOT;
        DWV_TRY(dwvs_opt_vector(item, path, "position", 3, light.position));
        DWV_TRY(dwvs_opt_number(item, path, "radius", &light.radius));
        DWV_TRY(dwvs_opt_vector(item, path, "direction", 3, light.direction));
        double degrees = 45.0;
        DWV_TRY(dwvs_opt_number(item, path, "spot_size", &degrees));
        light.spot_size = degrees * (3.14159265358979323846 / 180.0);
        DWV_TRY(dwvs_opt_number(item, path, "spot_blend", &light.spot_blend));
        size_t falloff = 0;
        DWV_TRY(dwvs_opt_choice(item, path, "spot_falloff", falloffs, 2, &falloff));
        light.spot_falloff = falloff == 0 ? DWV_SPOT_FALLOFF_CYCLES3 : DWV_SPOT_FALLOFF_CYCLES4;
        size_t point_shape = 0;
        DWV_TRY(dwvs_opt_choice(item, path, "point_shape", point_shapes, 2, &point_shape));
        light.point_shape = (int32_t)point_shape;
    } else {
        size_t shape = 0;
        DWV_TRY(dwvs_opt_choice(item, path, "shape", shapes, 2, &shape));
        light.kind = shape == 0 ? DWV_LIGHT_AREA_RECTANGLE : DWV_LIGHT_AREA_DISK;
        DWV_TRY(dwvs_opt_transform(item, path, light.transform));
        DWV_TRY(dwvs_opt_number(item, path, "size_x", &light.size_x));
        light.size_y = light.size_x; /* a square or a circle unless size_y says otherwise */
        DWV_TRY(dwvs_opt_number(item, path, "size_y", &light.size_y));
    }
    dwv_result_t r = dwv_scene_add_light(ps->scene, &light);
    return r == DWV_SUCCESS ? r : dwvs_prefix_capi(r, path);
}

dwv_result_t dwvs_read_lights(dwvs_parser *ps, const cJSON *item)
{
    if (!cJSON_IsArray(item))
        return dwvs_fail_at(DWV_ERROR_FORMAT, "lights", "expected an array of lights, found %s", dwvs_type_name(item));
    size_t i = 0;
    for (const cJSON *c = item->child; c; c = c->next, ++i) {
        char p[PATH_SIZE];
        dwvs_path_index(p, "lights", i);
        DWV_TRY(read_light(ps, c, p));
    }
    return DWV_SUCCESS;
}

/* "world": {"environment": {...}}: an equirectangular map, its texels inline or from a file. */
static dwv_result_t read_environment(dwvs_parser *ps, const cJSON *item)
{
    static const char path[] = "world.environment";
    static const char *const keys[] = {"width", "height", "texels", "file", "sha256", "interpolation", "strength",
                                       "rotate", "rotation"};
    static const char *const interpolations[] = {"linear", "closest", "cubic"};
    if (!cJSON_IsObject(item))
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "expected an object, found %s", dwvs_type_name(item));
    DWV_TRY(dwvs_check_keys(item, path, keys, sizeof keys / sizeof keys[0]));
    int from_file = dwvs_member(item, "file") != NULL;
    int inline_texels = dwvs_member(item, "width") || dwvs_member(item, "height") || dwvs_member(item, "texels");
    if (from_file == inline_texels || (!from_file && !(dwvs_member(item, "width") && dwvs_member(item, "height") &&
                                                       dwvs_member(item, "texels"))))
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "needs either 'file' or 'width', 'height' and 'texels'");
    if (!from_file && dwvs_member(item, "sha256"))
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "'sha256' applies to a 'file'");
    dwv_environment_t e = DWV_ENVIRONMENT_INIT;
    size_t interpolation = 0;
    DWV_TRY(dwvs_opt_choice(item, path, "interpolation", interpolations, 3, &interpolation));
    e.interpolation = (dwv_environment_interpolation_t)interpolation;
    DWV_TRY(dwvs_opt_number(item, path, "strength", &e.strength));
    if (dwvs_member(item, "rotate") && dwvs_member(item, "rotation"))
        return dwvs_fail_at(DWV_ERROR_FORMAT, path, "give either 'rotate' (Euler degrees) or 'rotation' (a matrix)");
    if (dwvs_member(item, "rotation")) {
        /* The exact row-major 3 x 3 matrix (what the C API takes), so that a written scene gives
         * back the same doubles. */
        DWV_TRY(dwvs_opt_vector(item, path, "rotation", 9, e.rotation));
    } else {
        /* The Mapping node's rotation (degrees, Euler XYZ): the rotation part of a T R S transform. */
        double rotate[3] = {0.0, 0.0, 0.0}, zero[3] = {0.0, 0.0, 0.0}, one[3] = {1.0, 1.0, 1.0}, m[12];
        DWV_TRY(dwvs_opt_vector(item, path, "rotate", 3, rotate));
        dwvs_transform_trs(zero, rotate, one, m);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) e.rotation[3 * r + c] = m[4 * r + c];
    }
    char p[PATH_SIZE];
    if (from_file) {
        char resolved[MAX_FILE_PATH];
        int exr = 0;
        DWV_TRY(dwvs_read_image_file(ps, item, path, resolved, &exr));
        dwv_result_t r = dwv_scene_set_world_environment_file(ps->scene, resolved, &e);
        dwvs_path_key(p, path, "file");
        return r == DWV_SUCCESS ? r : dwvs_prefix_capi(r, p);
    }
    DWV_TRY(dwvs_opt_u32(item, path, "width", 1u, DWV_ENVIRONMENT_MAX_SIDE, &e.width));
    DWV_TRY(dwvs_opt_u32(item, path, "height", 1u, DWV_ENVIRONMENT_MAX_SIDE, &e.height));
    dwvs_path_key(p, path, "texels");
    size_t count = 0;
    float *texels = NULL;
    DWV_TRY(dwvs_read_floats(dwvs_member(item, "texels"), p, 3, &count, &texels));
    if (count != 3u * (size_t)e.width * e.height) {
        free(texels);
        return dwvs_fail_at(DWV_ERROR_FORMAT, p, "%zu numbers: a %u x %u image needs %zu (RGB per texel)", count,
                            e.width, e.height, 3u * (size_t)e.width * e.height);
    }
    e.texels = texels;
    dwv_result_t r = dwv_scene_set_world_environment(ps->scene, &e);
    free(texels);
    return r == DWV_SUCCESS ? r : dwvs_prefix_capi(r, path);
}

dwv_result_t dwvs_read_world(dwvs_parser *ps, const cJSON *item)
{
    static const char *const keys[] = {"color", "strength", "environment"};
    DWV_TRY(dwvs_check_keys(item, "world", keys, 3));
    const cJSON *environment = dwvs_member(item, "environment");
    if (environment) {
        if (dwvs_member(item, "color") || dwvs_member(item, "strength"))
            return dwvs_fail_at(DWV_ERROR_FORMAT, "world",
                                "give either 'environment' (its own 'strength') or 'color'/'strength'");
        return read_environment(ps, environment);
    }
    double color[3] = {1.0, 1.0, 1.0}, strength = 1.0;
    DWV_TRY(dwvs_opt_vector(item, "world", "color", 3, color));
    DWV_TRY(dwvs_opt_number(item, "world", "strength", &strength));
    dwv_result_t r = dwv_scene_set_world(ps->scene, color, strength);
    return r == DWV_SUCCESS ? r : dwvs_prefix_capi(r, "world");
}

dwv_result_t dwvs_read_camera(dwvs_parser *ps, const cJSON *item)
{
    static const char *const kinds[] = {"perspective", "orthographic"};
    static const char *const perspective_keys[] = {"kind", "transform", "focal_length", "sensor_width"};
    static const char *const orthographic_keys[] = {"kind", "transform", "ortho_scale"};
    if (!cJSON_IsObject(item))
        return dwvs_fail_at(DWV_ERROR_FORMAT, "camera", "expected an object, found %s", dwvs_type_name(item));
    size_t kind = 0;
    DWV_TRY(dwvs_opt_choice(item, "camera", "kind", kinds, 2, &kind));
    if (kind == 0)
        DWV_TRY(dwvs_check_keys(item, "camera", perspective_keys, sizeof perspective_keys / sizeof perspective_keys[0]));
    else
        DWV_TRY(dwvs_check_keys(item, "camera", orthographic_keys, sizeof orthographic_keys / sizeof orthographic_keys[0]));
    if (!dwvs_member(item, "transform"))
        return dwvs_fail_at(DWV_ERROR_FORMAT, "camera", "missing key 'transform' (a 'matrix' or a 'look_at')");
    dwv_camera_t camera = DWV_CAMERA_INIT;
    camera.kind = kind == 0 ? DWV_CAMERA_PERSPECTIVE : DWV_CAMERA_ORTHOGRAPHIC;
    DWV_TRY(dwvs_opt_transform(item, "camera", camera.transform));
    DWV_TRY(dwvs_opt_number(item, "camera", "focal_length", &camera.focal_length));
    DWV_TRY(dwvs_opt_number(item, "camera", "sensor_width", &camera.sensor_width));
    DWV_TRY(dwvs_opt_number(item, "camera", "ortho_scale", &camera.ortho_scale));
    dwv_result_t r = dwv_scene_set_camera(ps->scene, &camera);
    if (r != DWV_SUCCESS) return dwvs_prefix_capi(r, "camera");
    ps->has_camera = 1;
    return DWV_SUCCESS;
}
