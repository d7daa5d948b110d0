/* Small scenes for the bake tests: an axis-aligned box and a UV sphere as closed triangle meshes
 * (counter-clockwise seen from outside), and a scene builder that fails loudly. */
#ifndef DWV_TESTS_BAKE_SCENES_H
#define DWV_TESTS_BAKE_SCENES_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <dwivedi.h>

typedef struct test_mesh {
    uint32_t vertex_count, triangle_count;
    float *positions;
    uint32_t *indices;
    float *uvs;
} test_mesh;

static inline void test_mesh_free(test_mesh *m)
{
    free(m->positions);
    free(m->indices);
    free(m->uvs);
}

/* The box [x0, x1] x [y0, y1] x [z0, z1]: 8 vertices, 12 triangles, UVs per corner (each face
 * a rectangle inside its own cell of a 3 x 2 grid, with gaps between them). */
static inline test_mesh test_box(double x0, double y0, double z0, double x1, double y1, double z1)
{
    test_mesh m = {8u, 12u, malloc(24 * sizeof(float) + sizeof(float)), malloc(36 * sizeof(uint32_t)),
                   malloc(72 * sizeof(float))};
    for (int i = 0; i < 8; ++i) {
        m.positions[3 * i] = (float)(i & 1 ? x1 : x0);
        m.positions[3 * i + 1] = (float)(i & 2 ? y1 : y0);
        m.positions[3 * i + 2] = (float)(i & 4 ? z1 : z0);
    }
    /* Faces as quads (a, b, c, d) counter-clockwise from outside. */
    static const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                         {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int f = 0; f < 6; ++f) {
        const uint32_t *q = quads[f];
        uint32_t tri[2][3] = {{q[0], q[1], q[2]}, {q[0], q[2], q[3]}};
        double cu = (f % 3) / 3.0, cv = (f / 3) / 2.0;
        double corner_uv[4][2] = {{cu + 0.05, cv + 0.05}, {cu + 0.28, cv + 0.05}, {cu + 0.28, cv + 0.45},
                                  {cu + 0.05, cv + 0.45}};
        int corner_of[2][3] = {{0, 1, 2}, {0, 2, 3}};
        for (int t = 0; t < 2; ++t) {
            for (int k = 0; k < 3; ++k) {
                m.indices[3 * (2 * f + t) + k] = tri[t][k];
                m.uvs[6 * (2 * f + t) + 2 * k] = (float)corner_uv[corner_of[t][k]][0];
                m.uvs[6 * (2 * f + t) + 2 * k + 1] = (float)corner_uv[corner_of[t][k]][1];
            }
        }
    }
    return m;
}

/* A UV sphere of `radius` about `centre` with `rings` x `segments` quads (poles as fans). */
static inline test_mesh test_sphere(double cx, double cy, double cz, double radius, uint32_t rings, uint32_t segments)
{
    test_mesh m;
    m.vertex_count = 2u + (rings - 1u) * segments;
    m.triangle_count = 2u * segments * (rings - 1u);
    m.positions = malloc((3u * m.vertex_count + 1u) * sizeof(float));
    m.indices = malloc(3u * m.triangle_count * sizeof(uint32_t));
    m.uvs = NULL;
    const double pi = 3.14159265358979323846;
    m.positions[0] = (float)cx;
    m.positions[1] = (float)cy;
    m.positions[2] = (float)(cz + radius);
    uint32_t south = m.vertex_count - 1u;
    m.positions[3 * south] = (float)cx;
    m.positions[3 * south + 1] = (float)cy;
    m.positions[3 * south + 2] = (float)(cz - radius);
    for (uint32_t r = 1; r < rings; ++r) {
        double theta = pi * r / rings;
        for (uint32_t s = 0; s < segments; ++s) {
            double phi = 2.0 * pi * s / segments;
            uint32_t v = 1u + (r - 1u) * segments + s;
            m.positions[3 * v] = (float)(cx + radius * sin(theta) * cos(phi));
            m.positions[3 * v + 1] = (float)(cy + radius * sin(theta) * sin(phi));
            m.positions[3 * v + 2] = (float)(cz + radius * cos(theta));
        }
    }
    uint32_t t = 0;
    for (uint32_t s = 0; s < segments; ++s) {
        uint32_t s1 = (s + 1u) % segments;
        uint32_t *i = m.indices + 3u * t++;
        i[0] = 0; i[1] = 1u + s; i[2] = 1u + s1;
        for (uint32_t r = 1; r + 1u < rings; ++r) {
            uint32_t a = 1u + (r - 1u) * segments + s, b = 1u + (r - 1u) * segments + s1;
            uint32_t c = a + segments, d = b + segments;
            i = m.indices + 3u * t++;
            i[0] = a; i[1] = c; i[2] = d;
            i = m.indices + 3u * t++;
            i[0] = a; i[1] = d; i[2] = b;
        }
        i = m.indices + 3u * t++;
        i[0] = south; i[1] = 1u + (rings - 2u) * segments + s1; i[2] = 1u + (rings - 2u) * segments + s;
    }
    return m;
}

/* Adds a mesh with a material; exits the test on failure (the scene calls have their own tests). */
static inline uint32_t test_add(dwv_scene_t *scene, const test_mesh *m, const dwv_material_t *material)
{
    uint32_t material_id, mesh_id;
    dwv_mesh_t mesh = DWV_MESH_INIT;
    mesh.vertex_count = m->vertex_count;
    mesh.triangle_count = m->triangle_count;
    mesh.positions = m->positions;
    mesh.indices = m->indices;
    mesh.uvs = m->uvs;
    if (dwv_scene_add_material(scene, material, &material_id) != DWV_SUCCESS) goto fail;
    mesh.material_id = material_id;
    if (dwv_scene_add_mesh(scene, &mesh, &mesh_id) != DWV_SUCCESS) goto fail;
    return mesh_id;
fail:
    fprintf(stderr, "test scene: %s\n", dwv_last_error_message());
    exit(2);
}

/* A camera at `eye` looking down -z (no rotation), orthographic of the given scale. */
static inline dwv_camera_t test_ortho_camera(double x, double y, double z, double scale)
{
    dwv_camera_t camera = DWV_CAMERA_INIT;
    camera.kind = DWV_CAMERA_ORTHOGRAPHIC;
    camera.transform[3] = x;
    camera.transform[7] = y;
    camera.transform[11] = z;
    camera.ortho_scale = scale;
    return camera;
}

/* A wax sphere (the default subsurface material, 16 x 32 quads) of `radius` about (cx, cy, cz) and a
 * white diffuse box `box` (x0, y0, z0, x1, y1, z1), under a sun of 3 along `sun` and a world of
 * colour `world`, seen by test_ortho_camera(0, 0, 6, 4); committed (exits the test on failure). */
static inline dwv_scene_t *test_wax_and_white_box(double cx, double cy, double cz, double radius, const double box[6],
                                                  const double sun[3], const double world[3])
{
    dwv_scene_t *scene;
    dwv_scene_create(&scene);
    dwv_material_t wax = DWV_MATERIAL_INIT;
    test_mesh sphere = test_sphere(cx, cy, cz, radius, 16, 32);
    test_add(scene, &sphere, &wax);
    test_mesh_free(&sphere);
    dwv_material_t white = DWV_MATERIAL_INIT;
    white.kind = DWV_MATERIAL_DIFFUSE;
    test_mesh block = test_box(box[0], box[1], box[2], box[3], box[4], box[5]);
    test_add(scene, &block, &white);
    test_mesh_free(&block);
    dwv_light_desc_t light = DWV_LIGHT_DESC_INIT;
    light.strength = 3.0;
    for (int k = 0; k < 3; ++k) light.direction[k] = sun[k];
    dwv_scene_add_light(scene, &light);
    dwv_scene_set_world(scene, world, 1.0);
    dwv_camera_t camera = test_ortho_camera(0.0, 0.0, 6.0, 4.0);
    dwv_scene_set_camera(scene, &camera);
    if (dwv_scene_commit(scene) != DWV_SUCCESS) {
        fprintf(stderr, "test scene: %s\n", dwv_last_error_message());
        exit(2);
    }
    return scene;
}

/* The report's wax sphere, committed: unit radius (rings x segments), subsurface radius (0.5,
 * 0.25, 0.1) and colour (0.9, 0.6, 0.4) (extinctions 2x and 5x apart), lit by a sun of 2 from the
 * camera's side, seen from +z (orthographic, 2.4 across). A zero radius in `flat_channel` (0..2)
 * makes that channel Lambertian (it does not walk); -1 for none. `grey`: radius 0.25 and colour
 * 0.8 in every channel instead. Exits the test on failure. */
static inline dwv_scene_t *test_wax_sphere(int flat_channel, int grey, uint32_t rings, uint32_t segments)
{
    dwv_scene_t *scene;
    if (dwv_scene_create(&scene) != DWV_SUCCESS) exit(2);
    dwv_material_t m = DWV_MATERIAL_INIT;
    static const double color[3] = {0.9, 0.6, 0.4}, radius[3] = {0.5, 0.25, 0.1};
    for (int c = 0; c < 3; ++c) {
        m.base_color[c] = m.subsurface_color[c] = grey ? 0.8 : color[c];
        m.subsurface_radius[c] = grey ? 0.25 : c == flat_channel ? 0.0 : radius[c];
    }
    m.subsurface_scale = 1.0;
    test_mesh sphere = test_sphere(0.0, 0.0, 0.0, 1.0, rings, segments);
    test_add(scene, &sphere, &m);
    test_mesh_free(&sphere);
    dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
    sun.strength = 2.0;
    sun.direction[0] = -0.5;
    sun.direction[1] = -0.5;
    sun.direction[2] = -0.7071;
    dwv_camera_t camera = test_ortho_camera(0.0, 0.0, 5.0, 2.4);
    if (dwv_scene_add_light(scene, &sun) || dwv_scene_set_camera(scene, &camera) || dwv_scene_commit(scene)) {
        fprintf(stderr, "test scene: %s\n", dwv_last_error_message());
        exit(2);
    }
    return scene;
}

/* A 4 x 4 m box of material m and the given thickness centred on z = 0, under a sun of 3 that
 * shines along sun_z (+1: from below, the box back-lit; -1: from the camera's side), seen from +z
 * (orthographic, 1 m across: every pixel sees the top face), committed. Exits the test on failure. */
static inline dwv_scene_t *test_sunlit_box(const dwv_material_t *m, double thickness, double sun_z)
{
    dwv_scene_t *scene;
    if (dwv_scene_create(&scene) != DWV_SUCCESS) exit(2);
    test_mesh box = test_box(-2.0, -2.0, -0.5 * thickness, 2.0, 2.0, 0.5 * thickness);
    test_add(scene, &box, m);
    test_mesh_free(&box);
    dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
    sun.strength = 3.0;
    sun.direction[2] = sun_z;
    dwv_camera_t camera = test_ortho_camera(0.0, 0.0, 3.0, 1.0);
    if (dwv_scene_add_light(scene, &sun) || dwv_scene_set_camera(scene, &camera) || dwv_scene_commit(scene)) {
        fprintf(stderr, "test scene: %s\n", dwv_last_error_message());
        exit(2);
    }
    return scene;
}

/* The report's leaf: a box 2 cm thick, subsurface radius 0.1 m in every channel (one extinction,
 * 2.5 mean free paths across) and colour (0.6, 0.95, 0.4), lit from behind (test_sunlit_box). */
static inline dwv_scene_t *test_leaf(void)
{
    dwv_material_t m = DWV_MATERIAL_INIT;
    static const double color[3] = {0.6, 0.95, 0.4};
    for (int c = 0; c < 3; ++c) {
        m.base_color[c] = m.subsurface_color[c] = color[c];
        m.subsurface_radius[c] = 0.1;
    }
    m.subsurface_scale = 1.0;
    return test_sunlit_box(&m, 0.02, 1.0);
}

#endif
