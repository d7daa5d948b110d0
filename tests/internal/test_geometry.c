/* The Embree world: closest points (rtcPointQuery + our point-triangle distance) agree with a
 * brute-force search over all triangles, rays find the surface a sphere formula predicts,
 * degenerate and overflowing triangles are counted as warnings, and the memory Embree holds per
 * triangle is reported. */
#include <math.h>
#include <stdio.h>

#include "bake/bake.h"
#include "bake/scene.h"
#include "bake_scenes.h"
#include "brute_force.h"
#include "check.h"
#include "geom/embree.h"
#include "kernel/rng.h"

static dwvb_scene *commit_meshes(const test_mesh *meshes, int count, const double *transform)
{
    dwvb_scene *scene = dwvb_scene_new();
    dwv_material_t m = DWV_MATERIAL_INIT;
    dwvb_scene_push_material(scene, &m);
    static const double identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    for (int i = 0; i < count; ++i) {
        dwvg_mesh mesh;
        dwvg_mesh_init(&mesh, meshes[i].vertex_count, meshes[i].triangle_count, 0, meshes[i].positions,
                       meshes[i].indices, NULL, NULL, transform ? transform : identity);
        dwvb_scene_push_mesh(scene, &mesh, 0.1, NULL);
    }
    char message[256];
    dwv_result_t r = dwvb_scene_commit(scene, message, sizeof message);
    CHECK(r == DWV_SUCCESS, "commit: %s", message);
    return scene;
}

static void test_closest_and_rays(void)
{
    test_mesh sphere = test_sphere(0.3, -0.2, 0.1, 1.0, 12, 24);
    dwvb_scene *scene = commit_meshes(&sphere, 1, NULL);
    const dwvg_mesh *mesh = &scene->meshes[0];
    int agree = 0;
    for (uint32_t i = 0; i < 500; ++i) {
        uint64_t key = dwvk_rng_key(1, i, 0);
        dwvu_vec3 p = dwvu_v(0.3 + 2.4 * (dwvk_rng_uniform_d(key, 0) - 0.5), -0.2 + 2.4 * (dwvk_rng_uniform_d(key, 1) - 0.5),
                             0.1 + 2.4 * (dwvk_rng_uniform_d(key, 2) - 0.5));
        double best = INFINITY;
        for (uint32_t t = 0; t < mesh->triangle_count; ++t) best = fmin(best, brute_triangle_distance(mesh, t, p, NULL));
        dwvg_hit hit;
        int found = dwvg_closest_mesh(&scene->geometry, 0, p, &hit);
        double d = found ? dwvu_length(dwvu_sub(dwvg_point(mesh, hit.prim, hit.u, hit.v), p)) : INFINITY;
        agree += found && fabs(d - best) <= 1e-6 && fabs(hit.t - best) <= 1e-6;
    }
    CHECK(agree == 500, "closest point agrees with brute force at %d of 500 points", agree);
    /* Rays from inside along random directions meet the surface where the polygonised sphere
     * is: between the inscribed radius cos(pi/12) cos(pi/24)... and 1 from the centre. */
    int on_surface = 0;
    for (uint32_t i = 0; i < 500; ++i) {
        uint64_t key = dwvk_rng_key(2, i, 0);
        double mu = 2.0 * dwvk_rng_uniform_d(key, 0) - 1.0;
        dwvu_vec3 d = dwvk_direction_about(dwvu_v(0, 0, 1), mu, 1.0 - mu, 1.0 + mu, dwvk_rng_uniform_d(key, 1));
        dwvu_vec3 c = dwvu_v(0.3, -0.2, 0.1);
        dwvg_hit a, b;
        int fa = dwvg_intersect_mesh(&scene->geometry, 0, c, d, 0.0, INFINITY, &a);
        int fb = dwvg_intersect(&scene->geometry, c, d, 0.0, INFINITY, &b);
        double inner = cos(3.14159265358979 / 12.0) * cos(3.14159265358979 / 24.0);
        on_surface += fa && fb && a.prim == b.prim && b.mesh == 0 && a.t >= inner - 1e-5 && a.t <= 1.0 + 1e-5 &&
                      dwvu_dot(dwvg_geometric_normal(mesh, a.prim), d) > 0.0 &&
                      dwvg_occluded(&scene->geometry, c, d, 0.0, INFINITY) && !dwvg_occluded(&scene->geometry, c, d, 0.0, 0.5 * inner);
    }
    CHECK(on_surface == 500, "rays meet the sphere from inside at %d of 500", on_surface);
    CHECK(scene->warnings == 0, "a clean sphere has no warnings (%llu)", (unsigned long long)scene->warnings);
    dwvb_scene_free(scene);
    test_mesh_free(&sphere);
}

static void test_warnings(void)
{
    test_mesh box = test_box(0, 0, 0, 1, 1, 1);
    box.indices[4] = box.indices[3]; /* triangle 1 degenerate: a repeated corner */
    dwvb_scene *scene = commit_meshes(&box, 1, NULL);
    CHECK(scene->warnings == 1, "one degenerate triangle, %llu warnings", (unsigned long long)scene->warnings);
    dwvb_scene_free(scene);
    /* Finite input that overflows float in world space: every triangle touching vertex 7 (the
     * corner 1e30 x 1e10 away) becomes non-finite and is skipped by Embree, counted here. The
     * other corners stay within 1e10, inside Embree's range (1.844e18). */
    test_mesh_free(&box);
    box = test_box(0, 0, 0, 1, 1, 1);
    box.positions[21] = box.positions[22] = box.positions[23] = 1e30f;
    static const double huge[12] = {1e10, 0, 0, 0, 0, 1e10, 0, 0, 0, 0, 1e10, 0};
    scene = commit_meshes(&box, 1, huge);
    CHECK(scene->warnings == 6, "six triangles touch the overflowing corner, %llu warnings",
          (unsigned long long)scene->warnings);
    dwvb_scene_free(scene);
    /* Finite in float but beyond Embree's range: a box 1e30 across, all 12 triangles left out. */
    static const double far[12] = {1e30, 0, 0, 0, 0, 1e30, 0, 0, 0, 0, 1e30, 0};
    box.positions[21] = box.positions[22] = box.positions[23] = 1.0f;
    scene = commit_meshes(&box, 1, far);
    CHECK(scene->warnings == 12, "a box 1e30 across: %llu warnings, expected 12", (unsigned long long)scene->warnings);
    dwvb_scene_free(scene);
    test_mesh_free(&box);
}

static void test_memory(void)
{
    test_mesh sphere = test_sphere(0, 0, 0, 1, 256, 512);
    dwvb_scene *scene = commit_meshes(&sphere, 1, NULL);
    long long bytes = dwvb_scene_geometry_bytes(scene);
    double per_triangle = (double)bytes / sphere.triangle_count;
    /* Our own arrays: 12 bytes per vertex and 12 per triangle (indices), about 18 per triangle. */
    printf("Embree holds %lld bytes for %u triangles: %.1f bytes per triangle (plus ~18 of our own arrays)\n", bytes,
           sphere.triangle_count, per_triangle);
    CHECK(per_triangle > 8.0 && per_triangle < 512.0, "%.1f bytes per triangle", per_triangle);
    dwvb_scene_free(scene);
    test_mesh_free(&sphere);
}

/* dwvg_mesh_closed (a radix sort of the directed edges against their reverses since issue 20,
 * qsort and bsearch before): a tetrahedron is closed; one face left out, a face twice, a face
 * turned over, an edge from a vertex to itself or a face of zero area make it not. A UV sphere
 * of 36,480 triangles (vertex numbers past 2^16: every radix pass sorts) is closed, and open
 * with one triangle taken out. */
static int closed_of(const float *positions, uint32_t vertex_count, const uint32_t *indices, uint32_t triangles)
{
    static const double identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    dwvg_mesh mesh;
    CHECK(dwvg_mesh_init(&mesh, vertex_count, triangles, 0, positions, indices, NULL, NULL, identity) == 0,
          "mesh init");
    int closed = dwvg_mesh_closed(&mesh);
    dwvg_mesh_free(&mesh);
    return closed;
}

static void test_closed(void)
{
    static const float p[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
    static const uint32_t tetra[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    CHECK(closed_of(p, 4, tetra, 4) == 1, "a tetrahedron is closed");
    CHECK(closed_of(p, 4, tetra, 3) == 0, "a tetrahedron without a face is open");
    static const uint32_t twice[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3, 1, 2, 3};
    CHECK(closed_of(p, 4, twice, 5) == 0, "a face twice is not closed");
    static const uint32_t turned[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 3, 2};
    CHECK(closed_of(p, 4, turned, 4) == 0, "a face turned over is not closed");
    static const uint32_t self_edge[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3, 4, 4, 4, 4, 4, 4};
    CHECK(closed_of(p, 5, self_edge, 6) == 0, "an edge from a vertex to itself is not closed");
    static const float flat[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.5f, 0, 0}; /* face 0, 1, 3 on a line */
    CHECK(closed_of(flat, 4, tetra, 4) == 0, "a face of zero area: not closed");
    test_mesh sphere = test_sphere(0.0, 0.0, 0.0, 1.0, 96, 192);
    CHECK(closed_of(sphere.positions, sphere.vertex_count, sphere.indices, sphere.triangle_count) == 1,
          "a UV sphere of %u triangles is closed", sphere.triangle_count);
    CHECK(closed_of(sphere.positions, sphere.vertex_count, sphere.indices + 3, sphere.triangle_count - 1) == 0,
          "the UV sphere without its first triangle is open");
    test_mesh_free(&sphere);
}

int main(void)
{
    test_closed();
    test_closest_and_rays();
    test_warnings();
    test_memory();
    return check_report("test_geometry");
}
