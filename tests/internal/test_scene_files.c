/* What scene files and the default scene put into the scene store: counts, transforms (Blender's
 * XYZ Euler order, look-at frames), meshes from OBJ and PLY files, and the procedural shapes of
 * the default scene (closed, wound outward, the volume and thickness they are built to have). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "api/scene_handle.h"
#include "check.h"
#include <dwivedi.h>
#include "scenefile/default_scene.h"

#define EXAMPLES DWV_TEST_DATA_DIR "/../../examples/scenes"
#define PI 3.14159265358979323846

static const dwvb_scene *store(const dwv_scene_t *scene)
{
    return dwv_scene_object(scene);
}

static int compare(const void *x, const void *y)
{
    uint64_t a = *(const uint64_t *)x, b = *(const uint64_t *)y;
    return a < b ? -1 : a > b;
}

/* Closed and consistently wound: each directed edge once, and its reverse once. */
static int closed_manifold(const dwvs_mesh_data *m)
{
    size_t edges = 3u * (size_t)m->triangle_count;
    uint64_t *keys = malloc(edges * sizeof *keys), *reverse = malloc(edges * sizeof *reverse);
    for (size_t t = 0; t < m->triangle_count; ++t)
        for (int k = 0; k < 3; ++k) {
            uint64_t a = m->indices[3u * t + k], b = m->indices[3u * t + (k + 1) % 3];
            keys[3u * t + k] = a << 32 | b;
            reverse[3u * t + k] = b << 32 | a;
        }
    qsort(keys, edges, sizeof *keys, compare);
    qsort(reverse, edges, sizeof *reverse, compare);
    int ok = 1;
    for (size_t i = 0; i < edges; ++i) {
        if (i > 0 && keys[i] == keys[i - 1u]) ok = 0;   /* a directed edge twice: wound inconsistently */
        if (keys[i] != reverse[i]) ok = 0;              /* an edge without its opposite: a hole */
    }
    free(keys);
    free(reverse);
    return ok;
}

/* Signed volume by the divergence theorem: sum over triangles of a . (b x c) / 6. */
static double signed_volume(const dwvs_mesh_data *m)
{
    double volume = 0.0;
    for (size_t t = 0; t < m->triangle_count; ++t) {
        const float *a = m->positions + 3u * m->indices[3u * t], *b = m->positions + 3u * m->indices[3u * t + 1],
                    *c = m->positions + 3u * m->indices[3u * t + 2];
        volume += (a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) + a[1] * ((double)b[2] * c[0] - (double)b[0] * c[2]) +
                   a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0])) / 6.0;
    }
    return volume;
}

/* The smallest triangle area (float positions, as the scene keeps them). */
static double smallest_area(const dwvs_mesh_data *m)
{
    double smallest = HUGE_VAL;
    for (size_t t = 0; t < m->triangle_count; ++t) {
        const uint32_t *tri = m->indices + 3u * t;
        const float *a = m->positions + 3u * tri[0], *b = m->positions + 3u * tri[1], *c = m->positions + 3u * tri[2];
        double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        smallest = fmin(smallest, 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]));
    }
    return smallest;
}

/* Vertex normals unit and on the outer side of every face around them. */
static int normals_outward(const dwvs_mesh_data *m, double *worst)
{
    *worst = 1.0;
    for (size_t t = 0; t < m->triangle_count; ++t) {
        const uint32_t *tri = m->indices + 3u * t;
        const float *a = m->positions + 3u * tri[0], *b = m->positions + 3u * tri[1], *c = m->positions + 3u * tri[2];
        double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; ++k) {
            const float *v = m->normals + 3u * tri[k];
            double vl = sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]);
            if (fabs(vl - 1.0) > 1e-5) return 0;
            double cosine = (v[0] * n[0] + v[1] * n[1] + v[2] * n[2]) / len;
            if (cosine < *worst) *worst = cosine;
        }
    }
    return *worst > 0.0;
}

static int uvs_in_unit_square(const dwvs_mesh_data *m)
{
    for (size_t i = 0; i < 6u * (size_t)m->triangle_count; ++i)
        if (!(m->uvs[i] >= 0.0f && m->uvs[i] <= 1.0f)) return 0;
    return 1;
}

static void test_leaf(void)
{
    dwvs_mesh_data leaf;
    CHECK(dwvs_default_leaf(&leaf) == 0, "leaf");
    CHECK(closed_manifold(&leaf), "the leaf is not a closed, consistently wound surface");
    const double a = DWVS_LEAF_HALF_WIDTH, b = DWVS_LEAF_HALF_HEIGHT, c = 0.5 * DWVS_LEAF_THICKNESS;
    /* The bend moves volume from one side of the middle surface to the other (Jacobian 1 - w/R,
     * odd in w): the ellipsoid's (4/3) pi a b c stays, up to the meshing (~1%). */
    double volume = signed_volume(&leaf), expected = 4.0 / 3.0 * PI * a * b * c;
    CHECK(fabs(volume / expected - 1.0) < 0.02, "leaf volume %.6g, expected %.6g", volume, expected);
    double worst;
    CHECK(normals_outward(&leaf, &worst), "leaf normals: worst cosine to a face %.3g", worst);
    CHECK(uvs_in_unit_square(&leaf), "leaf UVs outside [0, 1]");
    CHECK(smallest_area(&leaf) > 1e-10, "a leaf triangle of area %.3g m^2", smallest_area(&leaf));
    /* Thickness at the middle: the two poles (first and last vertices), along -y. */
    const float *front = leaf.positions, *back = leaf.positions + 3u * (leaf.vertex_count - 1u);
    CHECK(fabs(front[0]) < 1e-12 && fabs(back[0]) < 1e-12 && fabs((double)back[1] - front[1] - DWVS_LEAF_THICKNESS) < 1e-7,
          "leaf thickness %.6g", (double)back[1] - front[1]);
    CHECK(front[1] < 0.0f, "the leaf's front pole faces -y (the camera)");
    /* Cupped toward the viewer: the rim's sides come forward (more negative y) than the middle. */
    float min_x = 1, max_x = -1, y_at_min_x = 0;
    for (uint32_t v = 0; v < leaf.vertex_count; ++v) {
        const float *p = leaf.positions + 3u * v;
        if (p[0] < min_x) min_x = p[0], y_at_min_x = p[1];
        if (p[0] > max_x) max_x = p[0];
    }
    CHECK(y_at_min_x < -0.005f, "the leaf's edge is not bent toward the viewer (y %.4g)", (double)y_at_min_x);
    CHECK(max_x < a && max_x > 0.9 * a, "leaf half width %.4g", (double)max_x);
    /* The islands: the front's UVs in the left half, the back's in the right half. The front is
     * the side of the bent middle surface (the cylinder of radius R about x = 0, y = -R) nearer
     * its axis. */
    int sides_ok = 1;
    for (uint32_t t = 0; t < leaf.triangle_count; ++t) {
        double u = 0, centroid[3] = {0, 0, 0};
        for (int k = 0; k < 3; ++k) {
            u += leaf.uvs[6u * t + 2u * k] / 3.0;
            for (int d = 0; d < 3; ++d) centroid[d] += leaf.positions[3u * leaf.indices[3u * t + k] + d] / 3.0;
        }
        double R = DWVS_LEAF_BEND_RADIUS;
        int is_front = hypot(centroid[0], centroid[1] + R) < R;
        if ((u < 0.5) != is_front) sides_ok = 0;
    }
    CHECK(sides_ok, "leaf UV islands do not follow the front and back faces");
    dwvs_mesh_data_free(&leaf);
}

static void test_block(void)
{
    dwvs_mesh_data block;
    CHECK(dwvs_default_block(&block) == 0, "block");
    CHECK(closed_manifold(&block), "the block is not a closed, consistently wound surface");
    /* |x|^4 + |y|^4 + |z|^4 <= 1 has volume 8 Gamma(5/4)^3 / Gamma(7/4). */
    double abc = DWVS_BLOCK_HALF_SIZE_X * DWVS_BLOCK_HALF_SIZE_Y * DWVS_BLOCK_HALF_SIZE_Z;
    double expected = 8.0 * pow(tgamma(1.25), 3) / tgamma(1.75) * abc, volume = signed_volume(&block);
    CHECK(fabs(volume / expected - 1.0) < 0.01, "block volume %.6g, expected %.6g", volume, expected);
    double worst;
    CHECK(normals_outward(&block, &worst), "block normals: worst cosine to a face %.3g", worst);
    CHECK(uvs_in_unit_square(&block), "block UVs outside [0, 1]");
    CHECK(smallest_area(&block) > 1e-8, "a block triangle of area %.3g m^2", smallest_area(&block));
    CHECK(block.vertex_count == 6u * 24u * 24u + 2u, "welded block has %u vertices (a closed cube grid has 6 n^2 + 2)",
          block.vertex_count);
    dwvs_mesh_data_free(&block);
}

static void test_default_scene(void)
{
    dwv_scene_t *scene = NULL;
    dwv_bake_options_t options = DWV_BAKE_OPTIONS_INIT;
    CHECK(dwv_scene_create_default(&scene, &options) == DWV_SUCCESS, "%s", dwv_last_error_message());
    if (!scene) return;
    const dwvb_scene *s = store(scene);
    CHECK(s->committed, "not committed");
    CHECK(s->mesh_count == DWVS_DEFAULT_MESHES && s->material_count == DWVS_DEFAULT_MATERIALS &&
              s->light_count == DWVS_DEFAULT_LIGHTS && s->have_camera,
          "counts: %u meshes, %u materials, %u lights, camera %d", s->mesh_count, s->material_count, s->light_count,
          s->have_camera);
    CHECK(s->lights[0].kind == DWV_LIGHT_SUN && s->lights[1].kind == DWV_LIGHT_AREA_RECTANGLE, "light kinds");
    CHECK(s->materials[0].kind == DWV_MATERIAL_SUBSURFACE && s->materials[1].kind == DWV_MATERIAL_SUBSURFACE &&
              s->materials[2].kind == DWV_MATERIAL_DIFFUSE,
          "material kinds");
    /* The leaf is thin: a few Cycles mean free paths (radius x scale / (4 pi)) thick. */
    for (int c = 0; c < 3; ++c) {
        double mfp = s->materials[0].subsurface_radius[c] * s->materials[0].subsurface_scale / (4.0 * PI);
        double paths = DWVS_LEAF_THICKNESS / mfp;
        CHECK(paths > 2.0 && paths < 8.0, "leaf channel %d: %.3g mean free paths thick", c, paths);
        double block_paths = 2.0 * DWVS_BLOCK_HALF_SIZE_Y / (s->materials[1].subsurface_radius[c] *
                                                               s->materials[1].subsurface_scale / (4.0 * PI));
        CHECK(block_paths > 5.0, "block channel %d: only %.3g mean free paths across", c, block_paths);
    }
    /* The sun shines through the leaf toward the camera: its travel direction and the camera's
     * viewing direction (-z of the camera frame) point the same way along y. */
    double view_y = -s->camera.transform[6];
    CHECK(s->lights[0].direction[1] < 0.0 && view_y > 0.0, "the sun does not back-light the leaf for the camera");
    /* The leaf is on the left (negative x), the block on the right, both above the ground. */
    double leaf_x = 0, block_x = 0, min_z = 1;
    for (uint32_t v = 0; v < s->meshes[0].vertex_count; ++v) {
        leaf_x += s->meshes[0].positions[3u * v] / s->meshes[0].vertex_count;
        if (s->meshes[0].positions[3u * v + 2] < min_z) min_z = s->meshes[0].positions[3u * v + 2];
    }
    for (uint32_t v = 0; v < s->meshes[1].vertex_count; ++v) {
        block_x += s->meshes[1].positions[3u * v] / s->meshes[1].vertex_count;
        if (s->meshes[1].positions[3u * v + 2] < min_z) min_z = s->meshes[1].positions[3u * v + 2];
    }
    CHECK(leaf_x < -0.03 && block_x > 0.03 && min_z > 0.0, "placement: leaf x %.3g, block x %.3g, lowest z %.3g",
          leaf_x, block_x, min_z);
    dwv_scene_release(scene);
}

static void test_example_meshes(void)
{
    dwv_scene_t *scene = NULL;
    CHECK(dwv_scene_load(EXAMPLES "/frontlit_sphere.json", &scene, NULL) == DWV_SUCCESS, "%s",
          dwv_last_error_message());
    if (scene) {
        const dwvb_scene *s = store(scene);
        const dwvg_mesh *sphere = &s->meshes[0];
        /* an icosphere of 3 subdivisions: 10 4^3 + 2 vertices, 20 4^3 triangles, joined by Assimp */
        CHECK(sphere->vertex_count == 642u && sphere->triangle_count == 1280u && sphere->normals && !sphere->uvs,
              "sphere.ply: %u vertices, %u triangles", sphere->vertex_count, sphere->triangle_count);
        double min_z = 1, max_z = -1;
        for (uint32_t v = 0; v < sphere->vertex_count; ++v) {
            min_z = fmin(min_z, sphere->positions[3u * v + 2]);
            max_z = fmax(max_z, sphere->positions[3u * v + 2]);
        }
        CHECK(fabs(min_z - 0.0005) < 1e-6 && fabs(max_z - 0.0605) < 1e-6, "sphere translated: z in [%.6g, %.6g]",
              min_z, max_z);
        CHECK(s->mesh_count == 2u && s->meshes[1].triangle_count == 2u && s->meshes[1].normals, "inline floor");
        CHECK(s->light_count == 2u && s->lights[0].kind == DWV_LIGHT_AREA_DISK && s->lights[0].size_y == 0.1 &&
                  s->lights[1].kind == DWV_LIGHT_POINT,
              "lights of the sphere scene");
        /* look_at: the camera's -z points from the eye to the target */
        const double *m = s->camera.transform;
        double d[3] = {0.0 - m[3], 0.0 - m[7], 0.03 - m[11]}, l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        CHECK(fabs(-m[2] - d[0] / l) < 1e-12 && fabs(-m[6] - d[1] / l) < 1e-12 && fabs(-m[10] - d[2] / l) < 1e-12,
              "camera look_at");
        CHECK(m[9] > 0.0, "camera +y leans up");
        dwv_scene_release(scene);
    }
    CHECK(dwv_scene_load(EXAMPLES "/backlit_slab.json", &scene, NULL) == DWV_SUCCESS, "%s", dwv_last_error_message());
    if (scene) {
        const dwvg_mesh *slab = &store(scene)->meshes[0];
        CHECK(slab->vertex_count == 8u && slab->triangle_count == 12u && !slab->normals && !slab->uvs,
              "slab.obj: %u vertices, %u triangles", slab->vertex_count, slab->triangle_count);
        CHECK(store(scene)->camera.kind == DWV_CAMERA_ORTHOGRAPHIC && store(scene)->camera.ortho_scale == 0.14,
              "orthographic camera");
        CHECK(fabs(store(scene)->lights[0].angle - PI / 180.0) < 1e-15, "sun angle in degrees");
        dwv_scene_release(scene);
    }
    CHECK(dwv_scene_load(EXAMPLES "/uv_tile.json", &scene, NULL) == DWV_SUCCESS, "%s", dwv_last_error_message());
    if (scene) {
        const dwvg_mesh *tile = &store(scene)->meshes[0];
        /* each face's corners have UVs of their own: 24 vertices after joining, 12 triangles */
        CHECK(tile->vertex_count == 24u && tile->triangle_count == 12u && tile->uvs && !tile->normals,
              "tile.obj: %u vertices, %u triangles", tile->vertex_count, tile->triangle_count);
        dwv_scene_release(scene);
    }
}

/* Blender's XYZ Euler: X applied first. (0, 1, 0) rotated by X 90 is (0, 0, 1), then by Y 90 is
 * (1, 0, 0); the other order would leave (0, 0, 1). */
static void test_euler_order(void)
{
    const char *json = "{\"version\": 1, \"materials\": {\"m\": {}}, \"meshes\": [{\"material\": \"m\", "
                       "\"positions\": [0,1,0, 0,0,0, 0,0,1], \"indices\": [0,1,2], "
                       "\"transform\": {\"rotate\": [90, 90, 0], \"translate\": [10, 20, 30], \"scale\": 2}}]}";
    dwv_scene_t *scene = NULL;
    CHECK(dwv_scene_load_json(json, strlen(json), NULL, &scene, NULL) == DWV_SUCCESS, "%s", dwv_last_error_message());
    if (!scene) return;
    const float *p = store(scene)->meshes[0].positions;
    CHECK(fabs(p[0] - 12.0) < 1e-5 && fabs(p[1] - 20.0) < 1e-5 && fabs(p[2] - 30.0) < 1e-5,
          "(0,1,0) went to (%.6g, %.6g, %.6g), wanted (12, 20, 30)", p[0], p[1], p[2]);
    dwv_scene_release(scene);
    /* A 16-number matrix is row-major: the translation is the last column. */
    json = "{\"version\": 1, \"materials\": {\"m\": {}}, \"meshes\": [{\"material\": \"m\", "
           "\"positions\": [0,0,0, 1,0,0, 0,1,0], \"indices\": [0,1,2], "
           "\"transform\": {\"matrix\": [0,-1,0,5, 1,0,0,6, 0,0,1,7, 0,0,0,1]}}]}";
    CHECK(dwv_scene_load_json(json, strlen(json), NULL, &scene, NULL) == DWV_SUCCESS, "%s", dwv_last_error_message());
    if (!scene) return;
    p = store(scene)->meshes[0].positions;
    CHECK(p[3] == 5.0f && p[4] == 7.0f && p[5] == 7.0f, "(1,0,0) went to (%.6g, %.6g, %.6g), wanted (5, 7, 7)", p[3],
          p[4], p[5]);
    dwv_scene_release(scene);
}

int main(void)
{
    test_leaf();
    test_block();
    test_default_scene();
    test_example_meshes();
    test_euler_order();
    return check_report("test_scene_files");
}
