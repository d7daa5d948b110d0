/* The rays and clearances of a walk's shading (src/geom/embree.c, src/geom/clearance.[ch],
 * src/bake/shade.c run_walk), each against the plain way it stands for.
 *
 * 1. The probe past its entry triangle (dwvg_intersect_mesh_leaving, one ray with a context
 *    filter) gives what the loop of rays from just past each hit on that triangle gives, bit for
 *    bit (found, triangle, distance, barycentrics), for inward rays from random points of a box's
 *    and a sphere's triangles, over (0, +inf) and cut at random distances; without the filter (the
 *    loop itself) likewise; and with one ray where the loop needed two (the count can fail).
 * 2. A world of one mesh traces camera and shadow rays in the mesh's scene: the same hits, bit for
 *    bit, as a world where that mesh is instanced beside a second one far away, for random rays
 *    and for rays along the axes (zero direction components).
 * 3. A box's clearance is its 6 planes (no grid): never above the brute-force distance to its
 *    triangles at random points in and around it, equal to it inside (a convex mesh); a sphere
 *    and a mesh with a zero-area triangle get no planes; a grid's largest bound is no less than
 *    any lookup and is reached by one of its cells; a lookup above a floor gives the bound where
 *    it exceeds the floor and 0 elsewhere.
 * 4. Bakes of a thin back-lit box (the leaf) with ray-free steps from its planes equal bakes with
 *    a ray at every step bit for bit, and in checked mode no ray-free step's ray meets the box.
 * 5. Next-event estimates that skip the shadow rays known to meet nothing (dwvg_world_top) equal
 *    those that cast every one, bit for bit, on a box, a sphere and a box with a post on it, with
 *    suns down to grazing; the tops are the faces' planes on the convex meshes only.
 * 6. A sun that dwvl_light_below puts below a normal's horizon (so next-event estimation draws no
 *    sample of it) has no sample above it, for suns of 0, 14 and 29 degrees.
 * 7. The ball's radius (dwvg_clear_radius, inline) equals its fmax form bit for bit.
 * 8. dwvg_mesh_closed: a box and a sphere are closed; with a triangle missing, flipped or twice,
 *    of zero area, or a vertex split, a box is not (those walks keep the full probe).
 * 9. A thin box is a polytope: its walk rays, probes and camera rays (from around it and from
 *    inside) by its planes agree with Embree's (the same hits, distances to 1e-6, the exit inside
 *    its triangle); a sphere, an open box and a box with vertex normals are none. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/image_handle.h"
#include "api/scene_handle.h"
#include "bake/scene.h"
#include "bake_scenes.h"
#include "brute_force.h"
#include "check.h"
#include <dwivedi.h>
#include "geom/embree.h"
#include "light/direct.h"

static const double identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};

static dwvg_mesh make_mesh(const test_mesh *m)
{
    dwvg_mesh mesh;
    if (dwvg_mesh_init(&mesh, m->vertex_count, m->triangle_count, 0u, m->positions, m->indices, NULL, NULL, identity))
        exit(2);
    return mesh;
}

static int same_hit(int found_a, const dwvg_hit *a, int found_b, const dwvg_hit *b)
{
    if (found_a != found_b) return 0;
    return !found_a || (a->mesh == b->mesh && a->prim == b->prim && a->t == b->t && a->u == b->u && a->v == b->v);
}

/* A unit direction about unit n, cosine-weighted (as the entry's). */
static dwvu_vec3 about(dwvu_vec3 n, uint64_t *state)
{
    double mu = sqrt(brute_uniform(state));
    return dwvk_direction_about(n, mu, 1.0 - mu, 1.0 + mu, brute_uniform(state));
}

/* --- 1. the probe ------------------------------------------------------------------------- */

static void check_leaving(const char *name, const test_mesh *m)
{
    dwvg_mesh mesh = make_mesh(m);
    dwvg_world world;
    char message[256];
    if (dwvg_world_build(&world, &mesh, 1u, message, sizeof message)) {
        CHECK(0, "%s: world: %s", name, message);
        dwvg_mesh_free(&mesh);
        return;
    }
    CHECK(world.leaving_filter, "%s: Embree runs no context filters here", name);
    /* Embree's rays (a box is otherwise intersected by its planes: section 9). */
    world.polytopes[0].plane_count = 0;
    uint64_t state = 5u;
    int walks = 4000, same = 0, same_unfiltered = 0, found_count = 0, same_cut = 0, found_within = 0;
    uint64_t rays_loop = 0, rays_one = 0;
    for (int i = 0; i < walks; ++i) {
        uint32_t prim = (uint32_t)(brute_uniform(&state) * mesh.triangle_count);
        double u = brute_uniform(&state), v = brute_uniform(&state);
        if (u + v > 1.0) {
            u = 1.0 - u;
            v = 1.0 - v;
        }
        dwvu_vec3 x = dwvg_point(&mesh, prim, u, v);
        dwvu_vec3 d = about(dwvu_scale(dwvg_geometric_normal(&mesh, prim), -1.0), &state);
        /* The loop, as run_walk cast it before. */
        dwvg_hit loop;
        int found_loop;
        double tnear = 0.0;
        for (;;) {
            ++rays_loop;
            found_loop = dwvg_intersect_mesh(&world, 0u, x, d, tnear, INFINITY, &loop);
            if (!(found_loop && loop.prim == prim)) break;
            tnear = nextafterf((float)loop.t, INFINITY);
        }
        /* Cut at a random distance, against the loop cut there. */
        double tfar = 0.3 * brute_uniform(&state);
        dwvg_hit cut_loop, cut;
        int found_cut_loop;
        tnear = 0.0;
        for (;;) {
            found_cut_loop = dwvg_intersect_mesh(&world, 0u, x, d, tnear, tfar, &cut_loop);
            if (!(found_cut_loop && cut_loop.prim == prim)) break;
            tnear = nextafterf((float)cut_loop.t, INFINITY);
        }
        uint32_t rays_cut = 0;
        int found_cut = dwvg_intersect_mesh_leaving(&world, 0u, x, d, prim, tfar, &cut, &rays_cut);
        same_cut += same_hit(found_cut, &cut, found_cut_loop, &cut_loop);
        found_within += found_cut;
        dwvg_hit one, unfiltered;
        uint32_t rays = 0, rays_unfiltered = 0;
        int found_one = dwvg_intersect_mesh_leaving(&world, 0u, x, d, prim, INFINITY, &one, &rays);
        world.leaving_filter = 0;
        int found_unfiltered = dwvg_intersect_mesh_leaving(&world, 0u, x, d, prim, INFINITY, &unfiltered, &rays_unfiltered);
        world.leaving_filter = 1;
        rays_one += rays;
        same += same_hit(found_one, &one, found_loop, &loop);
        same_unfiltered += same_hit(found_unfiltered, &unfiltered, found_loop, &loop);
        found_count += found_loop;
    }
    CHECK(same == walks && same_unfiltered == walks && found_count == walks,
          "%s: %d of %d probes as the loop's (%d without the filter), %d found the far side", name, same, walks,
          same_unfiltered, found_count);
    CHECK(same_cut == walks && found_within > 0 && found_within < walks,
          "%s: %d of %d probes cut short as the loop's (%d met the surface)", name, same_cut, walks, found_within);
    /* The loop needs a second ray wherever rounding leaves the origin on the entry triangle. */
    CHECK(rays_one < rays_loop && rays_one >= (uint64_t)walks, "%s: %llu rays against the loop's %llu", name,
          (unsigned long long)rays_one, (unsigned long long)rays_loop);
    printf("%s: %d probes as the loop's, %llu rays against %llu\n", name, walks, (unsigned long long)rays_one,
           (unsigned long long)rays_loop);
    dwvg_world_free(&world);
    dwvg_mesh_free(&mesh);
}

/* --- 2. one mesh, no instance ------------------------------------------------------------- */

static void check_one_mesh(void)
{
    test_mesh s = test_sphere(0.0, 0.0, 0.0, 1.0, 12, 24), far = test_box(50.0, 50.0, 50.0, 51.0, 51.0, 51.0);
    dwvg_mesh meshes[2] = {make_mesh(&s), make_mesh(&far)};
    dwvg_world one, two;
    char message[256];
    if (dwvg_world_build(&one, meshes, 1u, message, sizeof message) ||
        dwvg_world_build(&two, meshes, 2u, message, sizeof message)) {
        CHECK(0, "world: %s", message);
        return;
    }
    uint64_t state = 9u;
    int rays = 6000, same = 0, same_occluded = 0, hits = 0, occluded = 0;
    for (int i = 0; i < rays; ++i) {
        /* From a shell around the sphere, aimed at it or past it; every fourth along an axis. */
        dwvu_vec3 o = dwvu_scale(about(dwvu_v(0.0, 0.0, 1.0), &state), 1.2 + 2.0 * brute_uniform(&state));
        if (brute_uniform(&state) < 0.5) o = dwvu_scale(o, -1.0);
        dwvu_vec3 d = dwvu_normalize(dwvu_sub(dwvu_scale(about(dwvu_v(1.0, 0.0, 0.0), &state), 1.6 * brute_uniform(&state)), o));
        if (i % 4 == 0) {
            int axis = (i / 4) % 3;
            double sign = (i / 12) % 2 ? 1.0 : -1.0;
            d = dwvu_v(axis == 0 ? sign : -0.0, axis == 1 ? sign : 0.0, axis == 2 ? sign : -0.0);
            o = dwvu_v(axis == 0 ? -2.0 * sign : 1.4 * brute_uniform(&state), axis == 1 ? -2.0 * sign : 0.0,
                       axis == 2 ? -2.0 * sign : -1.4 * brute_uniform(&state));
        }
        double tfar = 4.0 * brute_uniform(&state);
        dwvg_hit a, b;
        int found_a = dwvg_intersect(&one, o, d, 0.0, INFINITY, &a), found_b = dwvg_intersect(&two, o, d, 0.0, INFINITY, &b);
        same += same_hit(found_a, &a, found_b, &b);
        hits += found_a;
        int blocked = dwvg_occluded(&one, o, d, 0.0, tfar);
        same_occluded += blocked == dwvg_occluded(&two, o, d, 0.0, tfar);
        occluded += blocked;
    }
    CHECK(same == rays && same_occluded == rays && hits > rays / 4 && hits < rays && occluded > rays / 8 && occluded < rays,
          "%d of %d hits and %d occlusions as with the instance (%d hits, %d occluded)", same, rays, same_occluded, hits,
          occluded);
    dwvg_world_free(&one);
    dwvg_world_free(&two);
    dwvg_mesh_free(&meshes[0]);
    dwvg_mesh_free(&meshes[1]);
    test_mesh_free(&s);
    test_mesh_free(&far);
}

/* --- 3. planes and the grid's largest bound ------------------------------------------------ */

static void check_planes(void)
{
    test_mesh b = test_box(-2.0, -1.0, -0.01, 2.0, 1.0, 0.01);
    dwvg_mesh box = make_mesh(&b);
    dwvg_clearance c;
    CHECK(dwvg_clearance_build(&c, &box, 0.001, 0.004) == 0 && c.plane_count == 6u && c.lower == NULL &&
              c.largest == INFINITY,
          "box: %u planes, grid %p", c.plane_count, (void *)c.lower);
    uint64_t state = 3u;
    int points = 20000, below = 0, inside = 0, exact_inside = 0;
    for (int i = 0; i < points; ++i) {
        dwvu_vec3 p = dwvu_v(-2.2 + 4.4 * brute_uniform(&state), -1.2 + 2.4 * brute_uniform(&state),
                             -0.03 + 0.06 * brute_uniform(&state));
        double exact = INFINITY;
        for (uint32_t t = 0; t < box.triangle_count; ++t) exact = fmin(exact, brute_triangle_distance(&box, t, p, NULL));
        double bound = dwvg_clearance_at(&c, p), floor = 0.02 * brute_uniform(&state);
        below += bound <= exact && dwvg_clearance_above(&c, p, floor) == (bound > floor ? bound : 0.0);
        if (fabs(p.x) < 2.0 && fabs(p.y) < 1.0 && fabs(p.z) < 0.01) {
            ++inside;
            exact_inside += fabs(bound - exact) <= 1e-12;
        }
    }
    CHECK(below == points && inside > 1000 && exact_inside == inside,
          "box: the planes' bound %d of %d times at most the distance (and above a floor as asked), exact at %d of %d inside", below, points,
          exact_inside, inside);
    CHECK(dwvg_clearance_at(&c, dwvu_v(NAN, 0.0, 0.0)) == 0.0 && dwvg_clearance_at(&c, dwvu_v(0.0, INFINITY, 0.0)) == 0.0,
          "box: a point not finite has clearance 0");
    dwvg_clearance_free(&c);
    dwvg_mesh_free(&box);

    /* A zero-area triangle (a ray may graze it) leaves the box to a grid. */
    b.indices[3] = b.indices[4] = b.indices[5];
    box = make_mesh(&b);
    CHECK(dwvg_clearance_build(&c, &box, 0.05, 1.0) == 0 && c.plane_count == 0u && c.lower != NULL,
          "box with a zero-area triangle: %u planes", c.plane_count);
    dwvg_clearance_free(&c);
    dwvg_mesh_free(&box);
    test_mesh_free(&b);

    test_mesh s = test_sphere(0.0, 0.0, 0.0, 1.0, 12, 24);
    dwvg_mesh sphere = make_mesh(&s);
    CHECK(dwvg_clearance_build(&c, &sphere, 0.05, 1.0) == 0 && c.plane_count == 0u && c.lower != NULL,
          "sphere: %u planes", c.plane_count);
    if (c.lower) {
        int reached = 0, above = 0;
        size_t cells = (size_t)c.n[0] * c.n[1] * c.n[2];
        for (size_t i = 0; i < cells; ++i) reached += (double)c.lower[i] == c.largest;
        for (int i = 0; i < points; ++i) {
            dwvu_vec3 p = dwvu_v(-1.2 + 2.4 * brute_uniform(&state), -1.2 + 2.4 * brute_uniform(&state),
                                 -1.2 + 2.4 * brute_uniform(&state));
            double bound = dwvg_clearance_at(&c, p), floor = 0.3 * brute_uniform(&state);
            above += bound > c.largest || dwvg_clearance_above(&c, p, floor) != (bound > floor ? bound : 0.0);
        }
        CHECK(reached > 0 && above == 0 && c.largest > 0.5,
              "sphere: largest bound %g held by %d cells, %d lookups above it or wrong above a floor",
              c.largest, reached, above);
    }
    dwvg_clearance_free(&c);
    dwvg_mesh_free(&sphere);
    test_mesh_free(&s);
}

/* --- 5. shadow rays known to meet nothing ------------------------------------------------- */

/* Next-event estimates at random points of the world's triangles (the exit's Lambertian, a sun
 * at a random, often grazing, direction within its 10-degree disc and the world light) with the
 * triangle's top equal those without it (every shadow ray cast), bit for bit; the tops are the
 * faces' planes on a convex mesh (so rays are skipped) and above them where another mesh rises. */
static void check_tops(const char *name, const dwvg_mesh *meshes, uint32_t count, int convex)
{
    dwvg_world world;
    char message[256];
    if (dwvg_world_build(&world, meshes, count, message, sizeof message)) {
        CHECK(0, "%s: world: %s", name, message);
        return;
    }
    CHECK(world.tops != NULL, "%s: no tops", name);
    int on_plane = 0, triangles = 0;
    for (uint32_t t = 0; t < meshes[0].triangle_count; ++t) {
        dwvu_vec3 n = dwvg_geometric_normal(&meshes[0], t);
        const float *a = meshes[0].positions + 3u * meshes[0].indices[3u * t];
        double plane = dwvu_dot(n, dwvu_v(a[0], a[1], a[2]));
        on_plane += fabs(dwvg_world_top(&world, 0u, t) - plane) <= 1e-6;
        ++triangles;
    }
    CHECK(convex ? on_plane == triangles : on_plane < triangles, "%s: %d of %d tops on their planes", name, on_plane,
          triangles);
    uint64_t state = 17u;
    int points = 3000, same = 0, lit = 0;
    for (int i = 0; i < points; ++i) {
        const dwvg_mesh *mesh = &meshes[0];
        uint32_t prim = (uint32_t)(brute_uniform(&state) * mesh->triangle_count);
        double u = brute_uniform(&state), v = brute_uniform(&state);
        if (u + v > 1.0) {
            u = 1.0 - u;
            v = 1.0 - v;
        }
        dwvu_vec3 x = dwvg_point(mesh, prim, u, v), ng = dwvg_geometric_normal(mesh, prim);
        /* A sun whose disc reaches from the normal's side down to grazing and below. */
        dwvu_vec3 to_sun = about(ng, &state);
        double tilt = brute_uniform(&state);
        to_sun = dwvu_normalize(dwvu_madd(to_sun, ng, -tilt * dwvu_dot(to_sun, ng) * 1.1));
        dwv_light_desc_t desc = DWV_LIGHT_DESC_INIT;
        for (int k = 0; k < 3; ++k) desc.direction[k] = -(k == 0 ? to_sun.x : k == 1 ? to_sun.y : to_sun.z);
        desc.angle = 10.0 * 3.14159265358979323846 / 180.0;
        dwvl_light sun;
        dwvl_light_init(&sun, &desc);
        dwvl_environment env = {&sun, 1u, {0.2, 0.3, 0.4}, 1, &world, NULL};
        dwvk_sampler sampler = {.key = state, .index = 0u, .stratified = 0};
        double with[3], without[3];
        dwvl_direct(&env, x, ng, ng, NULL, dwvg_world_top(&world, 0u, prim), &sampler, 0u, with);
        dwvl_direct(&env, x, ng, ng, NULL, INFINITY, &sampler, 0u, without);
        same += memcmp(with, without, sizeof with) == 0;
        lit += with[0] > 0.2;
    }
    CHECK(same == points && lit > points / 4, "%s: %d of %d estimates as with every shadow ray cast (%d sunlit)", name,
          same, points, lit);
    dwvg_world_free(&world);
}

static void check_shadow_tops(void)
{
    test_mesh b = test_box(-2.0, -2.0, -0.05, 2.0, 2.0, 0.05), s = test_sphere(0.0, 0.0, 0.0, 1.0, 24, 48);
    test_mesh post = test_box(0.5, 0.5, 0.05, 0.7, 0.7, 1.0);
    dwvg_mesh box = make_mesh(&b), sphere = make_mesh(&s), with_post[2] = {make_mesh(&b), make_mesh(&post)};
    check_tops("box", &box, 1u, 1);
    check_tops("sphere", &sphere, 1u, 1);
    check_tops("box with a post", with_post, 2u, 0);
    dwvg_mesh_free(&box);
    dwvg_mesh_free(&sphere);
    dwvg_mesh_free(&with_post[0]);
    dwvg_mesh_free(&with_post[1]);
    test_mesh_free(&b);
    test_mesh_free(&s);
    test_mesh_free(&post);
}

/* --- 7. the ball's radius ---------------------------------------------------------------- */

/* dwvg_clear_radius as it was written with fmax: equal bit for bit at finite centres (ties,
 * zeros and signs included), 0 for a centre with a NaN coordinate. */
static void check_clear_radius(void)
{
    dwvg_world world;
    memset(&world, 0, sizeof world);
    world.epsilon = 0x1p-17 * 2.0;
    uint64_t state = 29u;
    int points = 20000, same = 0, positive = 0;
    for (int i = 0; i < points; ++i) {
        double c[3];
        for (int a = 0; a < 3; ++a) {
            double u = brute_uniform(&state);
            /* Now and then equal magnitudes, zeros of either sign. */
            c[a] = u < 0.1 ? (a ? c[0] : 0.5) : u < 0.2 ? (u < 0.15 ? 0.0 : -0.0) : 4.0 * brute_uniform(&state) - 2.0;
            if (brute_uniform(&state) < 0.5) c[a] = -c[a];
        }
        double clearance = 0.2 * brute_uniform(&state);
        double largest = fmax(fabs(c[0]), fmax(fabs(c[1]), fabs(c[2]))) + clearance;
        double radius = clearance - (world.epsilon + 0x1p-17 * largest);
        double reference = radius > 0.0 && radius < INFINITY ? radius : 0.0;
        double got = dwvg_clear_radius(&world, dwvu_v(c[0], c[1], c[2]), clearance);
        same += memcmp(&got, &reference, sizeof got) == 0;
        positive += got > 0.0;
    }
    CHECK(same == points && positive > points / 2, "clear radius: %d of %d as with fmax (%d positive)", same, points,
          positive);
    CHECK(dwvg_clear_radius(&world, dwvu_v(0.0, NAN, 0.0), 0.1) == 0.0 &&
              dwvg_clear_radius(&world, dwvu_v(0.0, 0.0, NAN), 0.1) == 0.0 &&
              dwvg_clear_radius(&world, dwvu_v(INFINITY, 0.0, 0.0), 0.1) == 0.0,
          "clear radius: a centre not finite gets 0");
}

/* --- 8. closed meshes --------------------------------------------------------------------- */

static int closed_of(const test_mesh *m)
{
    dwvg_mesh mesh = make_mesh(m);
    int closed = dwvg_mesh_closed(&mesh);
    dwvg_mesh_free(&mesh);
    return closed;
}

/* A box and a sphere are closed; without a triangle, with one flipped, with a face twice, with a
 * zero-area triangle or with a vertex split in two they are not. */
static void check_closed(void)
{
    test_mesh box = test_box(-1.0, -1.0, -1.0, 1.0, 1.0, 1.0), sphere = test_sphere(0.0, 0.0, 0.0, 1.0, 12, 24);
    CHECK(closed_of(&box) == 1 && closed_of(&sphere) == 1, "box %d and sphere %d closed", closed_of(&box), closed_of(&sphere));
    test_mesh m = test_box(-1.0, -1.0, -1.0, 1.0, 1.0, 1.0);
    m.triangle_count = 11u;
    int without = closed_of(&m);
    m.triangle_count = 12u;
    uint32_t keep = m.indices[1];
    m.indices[1] = m.indices[2];
    m.indices[2] = keep;
    int flipped = closed_of(&m);
    m.indices[2] = m.indices[1];
    m.indices[1] = keep;
    memcpy(m.indices + 3, m.indices, 3u * sizeof(uint32_t));
    int twice = closed_of(&m);
    test_mesh_free(&m);
    m = test_box(-1.0, -1.0, -1.0, 1.0, 1.0, 1.0);
    m.positions[3] = m.positions[0]; /* vertex 1 onto vertex 0: the triangles with both lose their area */
    m.positions[4] = m.positions[1];
    m.positions[5] = m.positions[2];
    int flat = closed_of(&m);
    test_mesh_free(&m);
    m = test_box(-1.0, -1.0, -1.0, 1.0, 1.0, 1.0);
    m.positions = realloc(m.positions, 28u * sizeof(float));
    if (!m.positions) exit(2);
    memcpy(m.positions + 24, m.positions, 3u * sizeof(float)); /* vertex 8: a copy of vertex 0 */
    m.vertex_count = 9u;
    m.indices[0] = 8u;
    int split = closed_of(&m);
    test_mesh_free(&m);
    CHECK(without == 0 && flipped == 0 && twice == 0 && flat == 0 && split == 0,
          "not closed: without a triangle %d, flipped %d, a face twice %d, zero area %d, a split vertex %d", without,
          flipped, twice, flat, split);
    test_mesh_free(&box);
    test_mesh_free(&sphere);
}

/* --- 9. polytopes ------------------------------------------------------------------------- */

/* A thin box's walk rays by its planes against Embree's: the same found or not, the same plane,
 * distances within 1e-6 (Embree's are floats), and a triangle that holds the exit point; the
 * probe past its entry triangle likewise. A sphere, an open box and a box with vertex normals
 * are no polytopes. */
static void check_polytopes(void)
{
    test_mesh b = test_box(-2.0, -2.0, -0.01, 2.0, 2.0, 0.01);
    dwvg_mesh box = make_mesh(&b);
    dwvg_world world;
    char message[256];
    if (dwvg_world_build(&world, &box, 1u, message, sizeof message)) {
        CHECK(0, "world: %s", message);
        return;
    }
    dwvg_polytope planes = world.polytopes[0];
    CHECK(planes.plane_count == 6u && planes.first[6] == 12u, "box: %u planes", planes.plane_count);
    uint64_t state = 31u;
    int rays = 20000, agree = 0, found = 0, inside = 0;
    for (int i = 0; i < rays; ++i) {
        dwvu_vec3 o = dwvu_v(-1.99 + 3.98 * brute_uniform(&state), -1.99 + 3.98 * brute_uniform(&state),
                             -0.0099 + 0.0198 * brute_uniform(&state));
        dwvu_vec3 d = about(dwvu_v(0.0, 0.0, brute_uniform(&state) < 0.5 ? 1.0 : -1.0), &state);
        if (i % 3 == 0) d = dwvu_normalize(dwvu_v(brute_uniform(&state) - 0.5, brute_uniform(&state) - 0.5, 1e-3 * (brute_uniform(&state) - 0.5)));
        double tfar = i % 2 ? INFINITY : 0.05 * brute_uniform(&state);
        dwvg_hit a, e;
        world.polytopes[0] = planes;
        int found_a = dwvg_intersect_mesh(&world, 0u, o, d, 0.0, tfar, &a);
        world.polytopes[0].plane_count = 0;
        int found_e = dwvg_intersect_mesh(&world, 0u, o, d, 0.0, tfar, &e);
        if (found_a != found_e) continue;
        found += found_a;
        if (!found_a) {
            ++agree;
            continue;
        }
        dwvu_vec3 na = dwvg_geometric_normal(&box, a.prim), ne = dwvg_geometric_normal(&box, e.prim);
        agree += na.x == ne.x && na.y == ne.y && na.z == ne.z && fabs(a.t - e.t) <= 1e-6 * (1.0 + e.t);
        inside += a.u >= -1e-9 && a.v >= -1e-9 && a.u + a.v <= 1.0 + 1e-9;
    }
    world.polytopes[0] = planes;
    CHECK(agree == rays && inside == found && found > rays / 4,
          "box: %d of %d rays by the planes as Embree's, %d of %d exits inside their triangle", agree, rays, inside, found);
    /* The probe from a point of a face, inward. */
    int probes = 2000, probes_agree = 0;
    for (int i = 0; i < probes; ++i) {
        uint32_t prim = (uint32_t)(brute_uniform(&state) * box.triangle_count);
        double u = brute_uniform(&state), v = brute_uniform(&state);
        if (u + v > 1.0) {
            u = 1.0 - u;
            v = 1.0 - v;
        }
        dwvu_vec3 x = dwvg_point(&box, prim, u, v);
        dwvu_vec3 d = about(dwvu_scale(dwvg_geometric_normal(&box, prim), -1.0), &state);
        dwvg_hit a, e;
        uint32_t count = 0;
        int found_a = dwvg_intersect_mesh_leaving(&world, 0u, x, d, prim, INFINITY, &a, &count);
        world.polytopes[0].plane_count = 0;
        int found_e = dwvg_intersect_mesh_leaving(&world, 0u, x, d, prim, INFINITY, &e, &count);
        world.polytopes[0] = planes;
        dwvu_vec3 na = dwvg_geometric_normal(&box, a.prim), ne = dwvg_geometric_normal(&box, e.prim);
        probes_agree += found_a && found_e && na.x == ne.x && na.y == ne.y && na.z == ne.z &&
                        fabs(a.t - e.t) <= 1e-6 * (1.0 + e.t);
    }
    CHECK(probes_agree == probes, "box: %d of %d probes by the planes as Embree's", probes_agree, probes);
    /* Camera rays (dwvg_intersect) from around the box and from inside it. */
    int cameras = 20000, cameras_agree = 0, cameras_hit = 0;
    for (int i = 0; i < cameras; ++i) {
        dwvu_vec3 o, d;
        if (i % 4) {
            o = dwvu_scale(about(dwvu_v(0.0, 0.0, 1.0), &state), 3.0);
            if (i % 2) o = dwvu_scale(o, -1.0);
            d = dwvu_normalize(dwvu_sub(dwvu_v(5.0 * brute_uniform(&state) - 2.5, 5.0 * brute_uniform(&state) - 2.5, 0.0), o));
        } else {
            o = dwvu_v(3.0 * brute_uniform(&state) - 1.5, 3.0 * brute_uniform(&state) - 1.5, 0.018 * brute_uniform(&state) - 0.009);
            d = about(dwvu_v(0.0, 0.0, 1.0), &state);
        }
        dwvg_hit a, e;
        int found_a = dwvg_intersect(&world, o, d, 0.0, INFINITY, &a);
        world.polytopes[0].plane_count = 0;
        int found_e = dwvg_intersect(&world, o, d, 0.0, INFINITY, &e);
        world.polytopes[0] = planes;
        dwvu_vec3 na = dwvg_geometric_normal(&box, found_a ? a.prim : 0u), ne = dwvg_geometric_normal(&box, found_e ? e.prim : 0u);
        cameras_agree += found_a == found_e && (!found_a || (na.x == ne.x && na.y == ne.y && na.z == ne.z &&
                                                            fabs(a.t - e.t) <= 1e-6 * (1.0 + e.t)));
        cameras_hit += found_a;
    }
    CHECK(cameras_agree == cameras && cameras_hit > cameras / 4 && cameras_hit < cameras,
          "box: %d of %d camera rays by the planes as Embree's (%d hit)", cameras_agree, cameras, cameras_hit);
    dwvg_world_free(&world);

    /* No polytopes: a sphere; a box without a triangle; a box with vertex normals. */
    test_mesh s = test_sphere(0.0, 0.0, 0.0, 1.0, 12, 24);
    dwvg_mesh sphere = make_mesh(&s), open = make_mesh(&b), smooth;
    open.triangle_count = 11u;
    float normals[24];
    for (int k = 0; k < 24; ++k) normals[k] = b.positions[k] / 2.0f;
    if (dwvg_mesh_init(&smooth, b.vertex_count, b.triangle_count, 0u, b.positions, b.indices, normals, NULL, identity))
        exit(2);
    const dwvg_mesh *others[3] = {&sphere, &open, &smooth};
    int none = 0;
    for (int k = 0; k < 3; ++k) {
        if (dwvg_world_build(&world, others[k], 1u, message, sizeof message)) continue;
        none += world.polytopes[0].plane_count == 0u;
        dwvg_world_free(&world);
    }
    CHECK(none == 3, "%d of 3 meshes not polytopes", none);
    open.triangle_count = 12u;
    dwvg_mesh_free(&sphere);
    dwvg_mesh_free(&open);
    dwvg_mesh_free(&smooth);
    dwvg_mesh_free(&box);
    test_mesh_free(&s);
    test_mesh_free(&b);
}

/* --- 6. suns below the horizon ----------------------------------------------------------- */

/* Wherever dwvl_light_below says a sun's disc lies below a normal's horizon, none of many samples
 * of it rises above (and it says so for most normals that far below, so the check can fail). */
static void check_suns_below(void)
{
    uint64_t state = 23u;
    int normals = 3000, below = 0, far_below = 0, wrong = 0, rising = 0;
    for (int i = 0; i < normals; ++i) {
        dwv_light_desc_t desc = DWV_LIGHT_DESC_INIT;
        dwvu_vec3 d = about(dwvu_v(0.0, 0.0, brute_uniform(&state) < 0.5 ? 1.0 : -1.0), &state);
        desc.direction[0] = d.x;
        desc.direction[1] = d.y;
        desc.direction[2] = d.z;
        desc.angle = (i % 3) * 0.25; /* 0, 14 and 29 degrees across */
        dwvl_light sun;
        dwvl_light_init(&sun, &desc);
        dwvu_vec3 n = about(dwvu_v(1.0, 0.0, 0.0), &state);
        if (brute_uniform(&state) < 0.5) n = dwvu_scale(n, -1.0);
        int says = dwvl_light_below(&sun, n);
        below += says;
        /* Directions of the disc (half-angle angle / 2) are within the chord 2 sin(angle / 4) of
         * its centre: all below once the centre is that far below. */
        if (dwvu_dot(n, sun.direction) < -2.0 * sin(0.25 * desc.angle) - 1e-6) {
            ++far_below;
            wrong += !says;
        }
        if (!says) continue;
        for (int k = 0; k < 200; ++k) {
            dwvl_sample sample;
            dwvl_light_sample(&sun, dwvu_v(0.0, 0.0, 0.0), brute_uniform(&state), brute_uniform(&state), &sample);
            rising += dwvu_dot(n, sample.direction) >= 0.0;
        }
    }
    CHECK(rising == 0 && below > normals / 8 && wrong == 0 && far_below >= below,
          "suns below: said for %d of %d normals (%d well below, %d of them missed), %d samples rose", below, normals,
          far_below, wrong, rising);
}

/* --- 4. bakes of the leaf ----------------------------------------------------------------- */

static dwvb_image *bake_leaf(dwv_scene_t *handle, dwvb_ball_mode mode)
{
    dwv_scene_object(handle)->ball_mode = mode;
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = o.height = 16;
    o.samples = 16;
    o.technique = DWV_TECHNIQUE_CLASSICAL;
    o.threads = 2;
    o.seed = 11;
    dwv_image_t *image = NULL;
    if (dwv_bake(handle, &o, &image) != DWV_SUCCESS) {
        CHECK(0, "bake: %s", dwv_last_error_message());
        return NULL;
    }
    return dwv_image_object(image);
}

static void check_leaf_bakes(void)
{
    dwv_scene_t *scene;
    dwv_scene_create(&scene);
    dwv_material_t material = DWV_MATERIAL_INIT;
    const double colour[3] = {0.6, 0.95, 0.4};
    for (int c = 0; c < 3; ++c) {
        material.base_color[c] = material.subsurface_color[c] = colour[c];
        material.subsurface_radius[c] = 0.1;
    }
    material.subsurface_scale = 1.0;
    test_mesh m = test_box(-2.0, -2.0, -0.01, 2.0, 2.0, 0.01);
    test_add(scene, &m, &material);
    test_mesh_free(&m);
    dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
    sun.direction[0] = 0.0;
    sun.direction[1] = 0.0;
    sun.direction[2] = 1.0;
    sun.strength = 3.0;
    dwv_scene_add_light(scene, &sun);
    dwv_camera_t camera = test_ortho_camera(0.0, 0.0, 3.0, 1.0);
    dwv_scene_set_camera(scene, &camera);
    CHECK(dwv_scene_commit(scene) == DWV_SUCCESS, "commit: %s", dwv_last_error_message());
    CHECK(dwv_scene_object(scene)->geometry.clearance[0].plane_count == 6u, "the leaf has %u planes",
          dwv_scene_object(scene)->geometry.clearance[0].plane_count);
    dwvb_image *off = bake_leaf(scene, DWVB_BALL_OFF), *on = bake_leaf(scene, DWVB_BALL_ON),
               *checked = bake_leaf(scene, DWVB_BALL_CHECKED);
    if (off && on && checked) {
        size_t floats = 4u * (size_t)on->width * on->height;
        CHECK(memcmp(on->rgba, off->rgba, floats * sizeof(float)) == 0 &&
                  memcmp(checked->rgba, off->rgba, floats * sizeof(float)) == 0,
              "leaf: the images with and without ray-free steps differ");
        CHECK(on->rays + on->ray_free_steps == off->rays && on->ray_free_steps * 10u > on->stats.events &&
                  checked->ray_free_misses == 0u && checked->ray_free_steps == on->ray_free_steps,
              "leaf: rays %llu + ray-free %llu against %llu for %llu events; checked: %llu met the surface",
              (unsigned long long)on->rays, (unsigned long long)on->ray_free_steps, (unsigned long long)off->rays,
              (unsigned long long)on->stats.events, (unsigned long long)checked->ray_free_misses);
        printf("leaf: %llu events, %llu ray-free steps, none met the surface\n", (unsigned long long)on->stats.events,
               (unsigned long long)on->ray_free_steps);
    }
    if (off) dwv_image_release(dwv_image_handle(off));
    if (on) dwv_image_release(dwv_image_handle(on));
    if (checked) dwv_image_release(dwv_image_handle(checked));
    dwv_scene_release(scene);
}

int main(void)
{
    test_mesh box = test_box(-2.0, -2.0, -0.05, 2.0, 2.0, 0.05), sphere = test_sphere(0.0, 0.0, 0.0, 1.0, 24, 48);
    check_leaving("box", &box);
    check_leaving("sphere", &sphere);
    test_mesh_free(&box);
    test_mesh_free(&sphere);
    check_one_mesh();
    check_planes();
    check_leaf_bakes();
    check_shadow_tops();
    check_suns_below();
    check_clear_radius();
    check_closed();
    check_polytopes();
    return check_report("test_shade_rays");
}
