/* Ray-free walk steps (src/bake/shade.c run_walk, src/geom/clearance.[ch]).
 *
 * 1. The clearance grid is a lower bound: at random points, dwvg_clearance_at never exceeds the
 *    distance to the nearest triangle found by brute force (zero-area triangles by their edges), on
 *    a sphere, an open mesh and a mesh with tiny features (a 4 mm box, a 1 mm sliver, a zero-area
 *    triangle inside a sphere); rays of length dwvg_clear_radius from those points, in random
 *    directions and straight at the nearest surface point, meet nothing, while rays 1% past the
 *    nearest point do meet them (so the check can fail). The bound is also tight enough to pay:
 *    within three cells of the distance deep inside.
 * 2. Bakes with ray-free steps equal bakes with a ray at every step bit for bit (classical,
 *    closest, backward, auto on the report-like sphere), and the tallies add up: the same events,
 *    rays with + ray-free steps = rays without, the same closest-point queries.
 * 3. In checked mode (every ray-free step's ray cast anyway) no ray-free step's ray meets the
 *    surface, on the sphere, the open mesh and the tiny-feature mesh.
 * 4. A scene's grids stop at 2^24 cells, in mesh order.
 * 5. Kept balls (a closest-point query's ball kept over later steps, where a mesh has no grid: its
 *    medium is too thin against its size): on the sphere, the open sphere and the tiny-feature
 *    sphere with mean free paths 20x shorter (2 mm against 1 m), bakes equal those without
 *    ray-free steps bit for bit, the tallies add up, no ray-free step's ray meets the surface in
 *    checked mode, and a query spares many rays. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/image_handle.h"
#include "api/scene_handle.h"
#include "bake/bake.h"
#include "bake/scene.h"
#include "bake_scenes.h"
#include "brute_force.h"
#include "check.h"
#include <dwivedi.h>
#include "geom/embree.h"
#include "kernel/rng.h"

/* --- meshes -------------------------------------------------------------------------------- */

/* Appends b's triangles to a (b's vertices renumbered). */
static void append(test_mesh *a, const test_mesh *b)
{
    uint32_t vertices = a->vertex_count + b->vertex_count, triangles = a->triangle_count + b->triangle_count;
    a->positions = realloc(a->positions, (3u * vertices + 1u) * sizeof(float));
    a->indices = realloc(a->indices, 3u * triangles * sizeof(uint32_t));
    if (!a->positions || !a->indices) exit(2);
    memcpy(a->positions + 3u * a->vertex_count, b->positions, 3u * b->vertex_count * sizeof(float));
    for (uint32_t i = 0; i < 3u * b->triangle_count; ++i) a->indices[3u * a->triangle_count + i] = b->indices[i] + a->vertex_count;
    a->vertex_count = vertices;
    a->triangle_count = triangles;
}

static test_mesh triangle_mesh(const float p[9])
{
    test_mesh m = {3u, 1u, malloc(10u * sizeof(float)), malloc(3u * sizeof(uint32_t)), NULL};
    if (!m.positions || !m.indices) exit(2);
    memcpy(m.positions, p, 9u * sizeof(float));
    for (uint32_t i = 0; i < 3u; ++i) m.indices[i] = i;
    return m;
}

enum { MESH_SPHERE, MESH_OPEN, MESH_TINY, MESH_KINDS };
static const char *const mesh_names[MESH_KINDS] = {"sphere", "open sphere", "sphere with tiny features"};

static test_mesh make_mesh(int kind)
{
    test_mesh m = test_sphere(0.0, 0.0, 0.0, 1.0, 24, 48);
    free(m.uvs);
    m.uvs = NULL;
    if (kind == MESH_OPEN) {
        /* Without the triangles above z = 0.7: a hole the walks can leave through into the void. */
        uint32_t kept = 0;
        for (uint32_t t = 0; t < m.triangle_count; ++t) {
            const uint32_t *i = m.indices + 3u * t;
            if (m.positions[3u * i[0] + 2u] > 0.7f && m.positions[3u * i[1] + 2u] > 0.7f && m.positions[3u * i[2] + 2u] > 0.7f)
                continue;
            memmove(m.indices + 3u * kept++, i, 3u * sizeof(uint32_t));
        }
        m.triangle_count = kept;
    } else if (kind == MESH_TINY) {
        /* Just under the surface the camera sees (y = -1): a 4 mm box, a sliver 1 m long and 1 mm
         * wide, and a zero-area triangle (three points on a line). */
        test_mesh box = test_box(-0.002, -0.902, -0.002, 0.002, -0.898, 0.002);
        append(&m, &box);
        test_mesh_free(&box);
        static const float sliver[9] = {-0.5f, -0.8f, 0.0f, 0.5f, -0.8f, 0.0f, 0.5f, -0.8f, 0.001f};
        static const float line[9] = {-0.3f, -0.85f, 0.1f, 0.0f, -0.85f, 0.1f, 0.3f, -0.85f, 0.1f};
        test_mesh s = triangle_mesh(sliver), l = triangle_mesh(line);
        append(&m, &s);
        append(&m, &l);
        test_mesh_free(&s);
        test_mesh_free(&l);
    }
    return m;
}

/* The report's wax sphere material (its radius times `scale`) and sun, a camera on -y (its front
 * face is the lit side). */
static dwv_scene_t *make_scene_scaled(int kind, double scale)
{
    dwv_scene_t *scene;
    dwv_scene_create(&scene);
    dwv_material_t material = DWV_MATERIAL_INIT;
    const double colour[3] = {0.9, 0.6, 0.4}, radius[3] = {0.5, 0.25, 0.1};
    for (int c = 0; c < 3; ++c) {
        material.base_color[c] = material.subsurface_color[c] = colour[c];
        material.subsurface_radius[c] = radius[c];
    }
    material.subsurface_scale = scale;
    test_mesh m = make_mesh(kind);
    test_add(scene, &m, &material);
    test_mesh_free(&m);
    dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
    sun.direction[0] = 0.3;
    sun.direction[1] = 1.0;
    sun.direction[2] = -0.6;
    sun.strength = 2.0;
    dwv_scene_add_light(scene, &sun);
    dwv_camera_t camera = DWV_CAMERA_INIT;
    const double transform[12] = {1, 0, 0, 0, 0, 0, -1, -3.5, 0, 1, 0, 0};
    memcpy(camera.transform, transform, sizeof transform);
    dwv_scene_set_camera(scene, &camera);
    if (dwv_scene_commit(scene) != DWV_SUCCESS) {
        fprintf(stderr, "commit: %s\n", dwv_last_error_message());
        exit(2);
    }
    return scene;
}

static dwv_scene_t *make_scene(int kind)
{
    return make_scene_scaled(kind, 1.0);
}

/* --- 1. the grid's bound ------------------------------------------------------------------- */

static void check_bound(int kind)
{
    dwv_scene_t *handle = make_scene(kind);
    const dwvb_scene *scene = dwv_scene_object(handle);
    const dwvg_world *world = &scene->geometry;
    const dwvg_mesh *mesh = &scene->meshes[0];
    const dwvg_clearance *grid = &world->clearance[0];
    CHECK(grid->lower != NULL, "%s: no clearance grid", mesh_names[kind]);
    if (!grid->lower) {
        dwv_scene_release(handle);
        return;
    }
    const int points = 3000;
    int over = 0, positive = 0, deep = 0, tight = 0, blocked = 0, aimed = 0, reached = 0, degenerate_nearest = 0;
    double worst = -INFINITY;
    uint64_t key = dwvk_rng_key(41u + (uint64_t)kind, 0u, 0u);
    for (int i = 0; i < points; ++i) {
        /* Points over the grid's box, half of them near the surface features. */
        dwvu_vec3 p;
        if (i % 2 == 0) {
            p = dwvu_v(-1.05 + 2.1 * dwvk_rng_uniform_d(key, 8u * i), -1.05 + 2.1 * dwvk_rng_uniform_d(key, 8u * i + 1u),
                       -1.05 + 2.1 * dwvk_rng_uniform_d(key, 8u * i + 2u));
        } else {
            p = dwvu_v(-0.6 + 1.2 * dwvk_rng_uniform_d(key, 8u * i), -1.0 + 0.3 * dwvk_rng_uniform_d(key, 8u * i + 1u),
                       -0.1 + 0.2 * dwvk_rng_uniform_d(key, 8u * i + 2u));
        }
        double exact = INFINITY;
        dwvu_vec3 nearest = p;
        uint32_t nearest_prim = 0;
        for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
            dwvu_vec3 x = p;
            double d = brute_triangle_distance(mesh, t, p, &x);
            if (d < exact) {
                exact = d;
                nearest = x;
                nearest_prim = t;
            }
        }
        double bound = dwvg_clearance_at(grid, p);
        over += bound > exact;
        worst = fmax(worst, bound - exact);
        positive += bound > 0.0;
        int on_grid = 1;
        const double q[3] = {p.x, p.y, p.z};
        for (int a = 0; a < 3; ++a)
            on_grid &= q[a] > grid->origin[a] + grid->cell && q[a] < grid->origin[a] + (grid->n[a] - 1.0) * grid->cell;
        if (on_grid && exact > 4.0 * grid->cell) {
            ++deep;
            tight += bound > exact - 3.0 * grid->cell;
        }
        double radius = dwvg_clear_radius(world, p, bound);
        if (!(radius > 0.0)) continue;
        /* Random directions, and straight at the nearest point: nothing within the radius. */
        dwvg_hit hit;
        for (int k = 0; k < 4; ++k) {
            double z = 2.0 * dwvk_rng_uniform_d(key, 8u * i + 3u + (uint32_t)k) - 1.0, phi = 6.283185307179586 * dwvk_rng_uniform_d(key, 8u * i + 7u);
            double s = sqrt(fmax(0.0, 1.0 - z * z));
            dwvu_vec3 w = dwvu_v(s * cos(phi + k), s * sin(phi + k), z);
            blocked += dwvg_intersect_mesh(world, 0, p, w, 0.0, radius, &hit);
        }
        dwvu_vec3 toward = dwvu_sub(nearest, p);
        double length = dwvu_length(toward);
        if (!(length > 0.0)) continue;
        toward = dwvu_scale(toward, 1.0 / length);
        blocked += dwvg_intersect_mesh(world, 0, p, toward, 0.0, radius, &hit);
        if (dwvg_triangle_area(mesh, nearest_prim) > 0.0) {
            ++aimed;
            reached += dwvg_intersect_mesh(world, 0, p, toward, 0.0, 1.01 * length, &hit);
        } else {
            ++degenerate_nearest;
        }
    }
    CHECK(over == 0, "%s: the grid's bound exceeds the distance at %d of %d points (worst by %g)", mesh_names[kind], over,
          points, worst);
    CHECK(blocked == 0, "%s: %d rays within the clear radius met the surface", mesh_names[kind], blocked);
    /* The rays past the nearest point find it (the no-hit check above could fail); a few slip past
     * where the nearest point is on the edge of the open sliver or box corner. */
    CHECK(aimed > 100 && reached >= aimed - aimed / 5, "%s: rays 1%% past the nearest point met it %d of %d times",
          mesh_names[kind], reached, aimed);
    /* Useful: deep inside, a bound at most three cells under the distance (the transform loses up to
     * h sqrt(3)/2 from the point to its cell's centre, as much from a surface point to its cell's
     * centre, and up to that again where a triangle's box reaches past the triangle). */
    CHECK(deep > 100 && tight >= deep - deep / 50, "%s: tight at %d of %d points on the grid deeper than 4 cells", mesh_names[kind],
          tight, deep);
    CHECK(positive > points / 4, "%s: a positive bound at %d of %d points", mesh_names[kind], positive, points);
    printf("%s: cell %.4f, %d of %d points with a positive bound, tight at %d of %d deep ones, %d aimed rays reached "
           "%d, %d nearest on a zero-area triangle\n",
           mesh_names[kind], grid->cell, positive, points, tight, deep, aimed, reached, degenerate_nearest);
    dwv_scene_release(handle);
}

/* --- 2 and 3. bakes ------------------------------------------------------------------------ */

typedef struct bake_result {
    dwvb_image *image; /* held */
    uint64_t events, walks;
} bake_result;

static bake_result bake(dwv_scene_t *handle, dwv_technique_t technique, dwvb_ball_mode mode)
{
    dwv_scene_object(handle)->ball_mode = mode;
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = o.height = 16;
    o.samples = 16;
    o.technique = technique;
    o.threads = 2;
    o.seed = 7;
    o.max_events = 4096;
    dwv_image_t *image = NULL;
    bake_result r = {NULL, 0u, 0u};
    if (dwv_bake(handle, &o, &image) != DWV_SUCCESS) {
        CHECK(0, "bake: %s", dwv_last_error_message());
        return r;
    }
    r.image = dwv_image_object(image);
    r.events = r.image->stats.events;
    r.walks = r.image->stats.walks;
    return r;
}

static void check_same_bakes(void)
{
    static const dwv_technique_t techniques[] = {DWV_TECHNIQUE_CLASSICAL, DWV_TECHNIQUE_CLOSEST, DWV_TECHNIQUE_BACKWARD,
                                                 DWV_TECHNIQUE_AUTO};
    dwv_scene_t *scene = make_scene(MESH_SPHERE);
    for (size_t t = 0; t < sizeof techniques / sizeof techniques[0]; ++t) {
        bake_result off = bake(scene, techniques[t], DWVB_BALL_OFF);
        bake_result on = bake(scene, techniques[t], DWVB_BALL_ON);
        bake_result checked = bake(scene, techniques[t], DWVB_BALL_CHECKED);
        if (!off.image || !on.image || !checked.image) break;
        size_t floats = 4u * (size_t)on.image->width * on.image->height;
        CHECK(memcmp(on.image->rgba, off.image->rgba, floats * sizeof(float)) == 0 &&
                  memcmp(checked.image->rgba, off.image->rgba, floats * sizeof(float)) == 0,
              "technique %d: the images with and without ray-free steps differ", (int)techniques[t]);
        CHECK(on.events == off.events && on.walks == off.walks && off.events > 1000u,
              "technique %d: events %llu / %llu, walks %llu / %llu", (int)techniques[t], (unsigned long long)on.events,
              (unsigned long long)off.events, (unsigned long long)on.walks, (unsigned long long)off.walks);
        /* Every step casts the same rays either way, except the ray-free ones, which cast none. */
        CHECK(on.image->rays + on.image->ray_free_steps == off.image->rays && off.image->ray_free_steps == 0u,
              "technique %d: rays %llu + ray-free %llu against %llu", (int)techniques[t], (unsigned long long)on.image->rays,
              (unsigned long long)on.image->ray_free_steps, (unsigned long long)off.image->rays);
        /* Every event follows a step, each step without balls casts a ray (the probe more where it
         * meets its entry triangle again), and a ray-free step always ends in an event. */
        CHECK(off.image->rays >= off.events && on.image->ray_free_steps <= on.events,
              "technique %d: %llu rays and %llu ray-free steps for %llu events", (int)techniques[t],
              (unsigned long long)off.image->rays, (unsigned long long)on.image->ray_free_steps,
              (unsigned long long)off.events);
        CHECK(checked.image->rays == off.image->rays && checked.image->ray_free_steps == on.image->ray_free_steps &&
                  checked.image->ray_free_misses == 0u,
              "technique %d: checked mode: %llu rays, %llu ray-free, %llu of them met the surface", (int)techniques[t],
              (unsigned long long)checked.image->rays, (unsigned long long)checked.image->ray_free_steps,
              (unsigned long long)checked.image->ray_free_misses);
        /* Closest-point queries: one per step for the closest technique, with or without. */
        CHECK(on.image->point_queries == off.image->point_queries, "technique %d: point queries %llu / %llu",
              (int)techniques[t], (unsigned long long)on.image->point_queries, (unsigned long long)off.image->point_queries);
        if (techniques[t] == DWV_TECHNIQUE_CLASSICAL)
            CHECK(on.image->point_queries == 0u && on.image->ray_free_steps * 2u > on.events,
                  "classical: %llu point queries, %llu of %llu events ray-free", (unsigned long long)on.image->point_queries,
                  (unsigned long long)on.image->ray_free_steps, (unsigned long long)on.events);
        if (techniques[t] == DWV_TECHNIQUE_CLOSEST)
            CHECK(on.image->point_queries >= on.events && on.image->point_queries <= off.image->rays,
                  "closest: %llu point queries for %llu events and %llu steps' rays", (unsigned long long)on.image->point_queries,
                  (unsigned long long)on.events, (unsigned long long)off.image->rays);
        printf("technique %d: %llu events, %llu walks; rays %llu -> %llu (%llu ray-free steps), %llu point queries\n",
               (int)techniques[t], (unsigned long long)on.events, (unsigned long long)on.walks,
               (unsigned long long)off.image->rays, (unsigned long long)on.image->rays,
               (unsigned long long)on.image->ray_free_steps, (unsigned long long)on.image->point_queries);
        dwv_image_release(dwv_image_handle(off.image));
        dwv_image_release(dwv_image_handle(on.image));
        dwv_image_release(dwv_image_handle(checked.image));
    }
    dwv_scene_release(scene);
}

static void check_checked_mode(int kind)
{
    dwv_scene_t *scene = make_scene(kind);
    bake_result r = bake(scene, DWV_TECHNIQUE_CLASSICAL, DWVB_BALL_CHECKED);
    if (r.image) {
        CHECK(r.image->ray_free_misses == 0u && r.image->ray_free_steps > 1000u,
              "%s: %llu ray-free steps, %llu of them met the surface", mesh_names[kind],
              (unsigned long long)r.image->ray_free_steps, (unsigned long long)r.image->ray_free_misses);
        printf("%s, checked: %llu events, %llu ray-free steps, none met the surface\n", mesh_names[kind],
               (unsigned long long)r.events, (unsigned long long)r.image->ray_free_steps);
        dwv_image_release(dwv_image_handle(r.image));
    }
    dwv_scene_release(scene);
}

/* 4. A scene's grids stop at 2^24 cells (64 MiB): 76 unit spheres of the report's medium, each
 * with a grid of 62^3 cells (the medium asks for finer, the limit of 2^18 per mesh says no), get
 * grids in mesh order up to the 71st only. */
static void check_scene_limit(void)
{
    dwv_scene_t *handle;
    dwv_scene_create(&handle);
    dwv_material_t material = DWV_MATERIAL_INIT;
    material.subsurface_radius[0] = 0.5;
    material.subsurface_scale = 1.0;
    uint32_t material_id;
    dwv_scene_add_material(handle, &material, &material_id);
    enum { SPHERES = 76 };
    for (int i = 0; i < SPHERES; ++i) {
        test_mesh m = test_sphere(3.0 * i, 0.0, 0.0, 1.0, 6, 12);
        dwv_mesh_t mesh = DWV_MESH_INIT;
        mesh.vertex_count = m.vertex_count;
        mesh.triangle_count = m.triangle_count;
        mesh.positions = m.positions;
        mesh.indices = m.indices;
        mesh.material_id = material_id;
        uint32_t id;
        CHECK(dwv_scene_add_mesh(handle, &mesh, &id) == DWV_SUCCESS, "add: %s", dwv_last_error_message());
        test_mesh_free(&m);
    }
    CHECK(dwv_scene_commit(handle) == DWV_SUCCESS, "commit: %s", dwv_last_error_message());
    const dwvg_world *world = &dwv_scene_object(handle)->geometry;
    int with = 0, ordered = 1;
    uint64_t cells = 0;
    for (int i = 0; i < SPHERES; ++i) {
        const dwvg_clearance *grid = &world->clearance[i];
        if (grid->lower) {
            ordered &= with == i;
            ++with;
            cells += (uint64_t)grid->n[0] * grid->n[1] * grid->n[2];
        }
    }
    CHECK(ordered && with >= 64 && with < SPHERES && cells >= (1u << 24) && cells < (1u << 24) + (1u << 18),
          "%d grids (in mesh order: %d) of %llu cells in all", with, ordered, (unsigned long long)cells);
    dwv_scene_release(handle);
}

/* 5. Kept balls, on a mesh without a grid. */
static void check_kept_balls(int kind)
{
    static const dwv_technique_t techniques[] = {DWV_TECHNIQUE_CLASSICAL, DWV_TECHNIQUE_BACKWARD, DWV_TECHNIQUE_AUTO};
    dwv_scene_t *scene = make_scene_scaled(kind, 0.05);
    const dwvg_clearance *grid = &dwv_scene_object(scene)->geometry.clearance[0];
    CHECK(!(grid->largest > 0.0), "%s: a grid or planes where none was expected (largest bound %g)", mesh_names[kind],
          grid->largest);
    /* Every technique on the sphere; classical on the open and the tiny-feature ones (time). */
    size_t count = kind == MESH_SPHERE ? sizeof techniques / sizeof techniques[0] : 1u;
    for (size_t t = 0; t < count; ++t) {
        bake_result off = bake(scene, techniques[t], DWVB_BALL_OFF);
        bake_result on = bake(scene, techniques[t], DWVB_BALL_ON);
        bake_result checked = bake(scene, techniques[t], DWVB_BALL_CHECKED);
        if (!off.image || !on.image || !checked.image) break;
        size_t floats = 4u * (size_t)on.image->width * on.image->height;
        /* Auto's pilot counts the rays and queries its candidates cost, which the balls change, and
         * may then choose otherwise: its bakes are compared between on and checked mode, whose
         * walks see the same balls (checked mode's pilot counts the extra rays too, yet chose alike
         * here: the images are compared). */
        int automatic = techniques[t] == DWV_TECHNIQUE_AUTO;
        const bake_result *base = automatic ? &on : &off;
        CHECK(memcmp(on.image->rgba, base->image->rgba, floats * sizeof(float)) == 0 &&
                  memcmp(checked.image->rgba, base->image->rgba, floats * sizeof(float)) == 0 &&
                  on.events == base->events && on.walks == base->walks && off.events > 10000u,
              "%s, technique %d: with and without kept balls: images differ, or events %llu / %llu", mesh_names[kind],
              (int)techniques[t], (unsigned long long)on.events, (unsigned long long)base->events);
        CHECK((automatic || on.image->rays + on.image->ray_free_steps == off.image->rays) &&
                  checked.image->rays == on.image->rays + on.image->ray_free_steps && off.image->ray_free_steps == 0u &&
                  off.image->point_queries == 0u,
              "%s, technique %d: rays %llu + ray-free %llu against %llu, %llu queries without balls", mesh_names[kind],
              (int)techniques[t], (unsigned long long)on.image->rays, (unsigned long long)on.image->ray_free_steps,
              (unsigned long long)off.image->rays, (unsigned long long)off.image->point_queries);
        CHECK(checked.image->ray_free_steps == on.image->ray_free_steps && checked.image->ray_free_misses == 0u,
              "%s, technique %d: checked mode: %llu ray-free steps, %llu of them met the surface", mesh_names[kind],
              (int)techniques[t], (unsigned long long)checked.image->ray_free_steps,
              (unsigned long long)checked.image->ray_free_misses);
        /* Deep walks (classical: some 70 events each): most steps ray-free; each query spares more
         * than 15 rays (about what it costs) for every technique. */
        CHECK((techniques[t] != DWV_TECHNIQUE_CLASSICAL || on.image->ray_free_steps * 2u > on.events) &&
                  on.image->point_queries * 15u < on.image->ray_free_steps,
              "%s, technique %d: %llu of %llu events ray-free for %llu queries", mesh_names[kind], (int)techniques[t],
              (unsigned long long)on.image->ray_free_steps, (unsigned long long)on.events,
              (unsigned long long)on.image->point_queries);
        printf("%s, technique %d, kept balls: %llu events, rays %llu -> %llu (%llu ray-free steps), %llu point queries\n",
               mesh_names[kind], (int)techniques[t], (unsigned long long)on.events, (unsigned long long)off.image->rays,
               (unsigned long long)on.image->rays, (unsigned long long)on.image->ray_free_steps,
               (unsigned long long)on.image->point_queries);
        dwv_image_release(dwv_image_handle(off.image));
        dwv_image_release(dwv_image_handle(on.image));
        dwv_image_release(dwv_image_handle(checked.image));
    }
    dwv_scene_release(scene);
}

int main(void)
{
    for (int kind = 0; kind < MESH_KINDS; ++kind) check_bound(kind);
    check_same_bakes();
    for (int kind = 0; kind < MESH_KINDS; ++kind) check_checked_mode(kind);
    check_scene_limit();
    for (int kind = 0; kind < MESH_KINDS; ++kind) check_kept_balls(kind);
    return check_report("test_ray_free_steps");
}
