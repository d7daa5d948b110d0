/* The shadow terminator offset of smooth-shaded triangles (src/light/terminator.c) and its use by
 * next-event estimation (src/light/direct.c):
 *   - a flat triangle (every vertex normal the geometric one) is not lifted anywhere;
 *   - the corners of a convex triangle are not lifted;
 *   - a patch curved about one axis (normals (-s, 0, c), (s, 0, c), (-s, 0, c) at (0,0,0),
 *     (1,0,0), (0,1,0)) is lifted by the hand-computed h = s min(b1, 1 - b1) along the
 *     interpolated normal (s (2 b1 - 1), 0, c): the tangent planes' envelope (s b1, s (1 - b1),
 *     s b1 at the three corners) is above the parabola s b1 (1 - b1) there;
 *   - random convex triangles (on a sphere) and random normals are lifted outward, never inward
 *     (lift . ng >= 0), and reversing the stored normals (the side is ng's) changes nothing;
 *   - the share a ray takes, against hand-computed values of Cycles' blend, its continuity at
 *     cos_n = cutoff, and that it never grows as the flat triangle turns toward the light;
 *   - on a smooth-shaded low-poly sphere lit by a sun, the points whose shading normal faces the
 *     sun but whose triangle does not are dark without the offset and lit with it (as in Cycles),
 *     and points well inside the lit side are unchanged;
 *   - on that sphere, points whose smooth normal faces away from the sun but whose lobe normal (a
 *     normal map's, tilted toward it) faces it are dark: Cycles' shadow ray leaves from the side
 *     the smooth normal gives (shadow_ray_offset's sd->N), under the triangle, and meets the
 *     sphere's far side (the lift about the lobe normal, main's code before nmap18, lit 441 of
 *     916 of them: Blender 3.4's normal-mapped glossy sphere was +2.5% from that band).
 * Planting errors by hand (the envelope's min taken as a max; the parabola alone without the
 * envelope) makes the concave, outward and (the latter) the curved patch's checks fail. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "brute_force.h"
#include "check.h"
#include "geom/embree.h"
#include "geom/mesh.h"
#include "light/direct.h"
#include "light/light.h"
#include "light/terminator.h"

/* Cycles' default "Shadow Terminator > Geometry Offset". */
static const double CYCLES_GEOMETRY_OFFSET = 0.1;

static dwvu_vec3 unit_vector(uint64_t *state)
{
    double z = 2.0 * brute_uniform(state) - 1.0, r = sqrt(fmax(0.0, 1.0 - z * z)), phi = 6.283185307179586 * brute_uniform(state);
    return dwvu_v(r * cos(phi), r * sin(phi), z);
}

static void random_barycentrics(uint64_t *state, double b[3])
{
    double su = sqrt(brute_uniform(state)), v = brute_uniform(state);
    b[1] = su * (1.0 - v);
    b[2] = su * v;
    b[0] = 1.0 - b[1] - b[2];
}

static double distance(dwvu_vec3 a, dwvu_vec3 b)
{
    return dwvu_length(dwvu_sub(a, b));
}

static void test_flat(void)
{
    uint64_t state = 1u;
    for (int trial = 0; trial < 200; ++trial) {
        dwvu_vec3 v[3] = {unit_vector(&state), unit_vector(&state), unit_vector(&state)};
        dwvu_vec3 ng = dwvu_normalize(
            dwvu_v((v[1].y - v[0].y) * (v[2].z - v[0].z) - (v[1].z - v[0].z) * (v[2].y - v[0].y),
                   (v[1].z - v[0].z) * (v[2].x - v[0].x) - (v[1].x - v[0].x) * (v[2].z - v[0].z),
                   (v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[1].y - v[0].y) * (v[2].x - v[0].x)));
        dwvu_vec3 flat[3] = {ng, ng, ng};
        double b[3];
        random_barycentrics(&state, b);
        dwvu_vec3 lift = dwvl_terminator_lift(v, flat, b, ng);
        CHECK(dwvu_length(lift) < 1e-12, "trial %d: a flat triangle is lifted by %g", trial, dwvu_length(lift));
    }
}

static void test_cylinder_patch(void)
{
    const double s = 0.6, c = 0.8;
    dwvu_vec3 v[3] = {dwvu_v(0.0, 0.0, 0.0), dwvu_v(1.0, 0.0, 0.0), dwvu_v(0.0, 1.0, 0.0)};
    dwvu_vec3 n[3] = {dwvu_v(-s, 0.0, c), dwvu_v(s, 0.0, c), dwvu_v(-s, 0.0, c)};
    dwvu_vec3 ng = dwvu_v(0.0, 0.0, 1.0);
    /* Hand-computed: (0.25, 0.5, 0.25): h = 0.5 s = 0.3, normal (0, 0, 0.8): lift (0, 0, 0.24);
     * (0.5, 0.25, 0.25): h = 0.25 s = 0.15, normal (-0.3, 0, 0.8): lift (-0.045, 0, 0.12). */
    double b1[3] = {0.25, 0.5, 0.25}, b2[3] = {0.5, 0.25, 0.25};
    dwvu_vec3 lift = dwvl_terminator_lift(v, n, b1, ng);
    CHECK(distance(lift, dwvu_v(0.0, 0.0, 0.24)) < 1e-12, "ridge: lift (%g, %g, %g), expected (0, 0, 0.24)", lift.x,
          lift.y, lift.z);
    lift = dwvl_terminator_lift(v, n, b2, ng);
    CHECK(distance(lift, dwvu_v(-0.045, 0.0, 0.12)) < 1e-12, "side: lift (%g, %g, %g), expected (-0.045, 0, 0.12)",
          lift.x, lift.y, lift.z);
    /* Everywhere on it: h = s min(b1, 1 - b1) along (s (2 b1 - 1), 0, c). */
    uint64_t state = 7u;
    double worst = 0.0;
    for (int trial = 0; trial < 1000; ++trial) {
        double b[3];
        random_barycentrics(&state, b);
        double h = s * fmin(b[1], 1.0 - b[1]);
        dwvu_vec3 expected = dwvu_scale(dwvu_v(s * (2.0 * b[1] - 1.0), 0.0, c), h);
        worst = fmax(worst, distance(dwvl_terminator_lift(v, n, b, ng), expected));
    }
    CHECK(worst < 1e-12, "the curved patch's lift is off its closed form by up to %g", worst);
    /* Concave (s < 0): the envelope's rises lift it as the convex one, never below the plane. */
    dwvu_vec3 concave[3] = {dwvu_v(s, 0.0, c), dwvu_v(-s, 0.0, c), dwvu_v(s, 0.0, c)};
    lift = dwvl_terminator_lift(v, concave, b1, ng);
    CHECK(lift.z >= 0.0, "concave patch: lift (%g, %g, %g) goes inward", lift.x, lift.y, lift.z);
}

static void test_outward(void)
{
    uint64_t state = 3u;
    int interior_lifted = 0, convex = 0, trials = 2000;
    double worst_inward = 0.0, worst_mirror = 0.0, worst_corner = 0.0;
    for (int trial = 0; trial < trials; ++trial) {
        /* A small triangle on the unit sphere, its normals the sphere's. */
        dwvu_vec3 centre = unit_vector(&state);
        dwvu_vec3 v[3], n[3];
        for (int k = 0; k < 3; ++k) {
            n[k] = dwvu_normalize(dwvu_madd(centre, unit_vector(&state), 0.3));
            v[k] = n[k];
        }
        dwvu_vec3 e1 = dwvu_sub(v[1], v[0]), e2 = dwvu_sub(v[2], v[0]);
        dwvu_vec3 ng = dwvu_v(e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x);
        if (!(dwvu_length(ng) > 1e-6)) continue;
        ng = dwvu_normalize(ng);
        if (dwvu_dot(ng, centre) < 0.0) ng = dwvu_scale(ng, -1.0); /* outward */
        /* A sliver's plane cuts the sphere in a wide circle and its normal is far from the
         * vertices': keep the triangles the sphere's patches resemble. */
        if (fmin(fmin(dwvu_dot(n[0], ng), dwvu_dot(n[1], ng)), dwvu_dot(n[2], ng)) < 0.9) continue;
        ++convex;
        double b[3];
        random_barycentrics(&state, b);
        dwvu_vec3 lift = dwvl_terminator_lift(v, n, b, ng);
        worst_inward = fmin(worst_inward, dwvu_dot(lift, ng));
        interior_lifted += dwvu_dot(lift, ng) > 0.0;
        /* Its corners stay where they are (the triangle lies below every corner's tangent plane). */
        for (int k = 0; k < 3; ++k) {
            double corner[3] = {k == 0, k == 1, k == 2};
            worst_corner = fmax(worst_corner, dwvu_length(dwvl_terminator_lift(v, n, corner, ng)));
        }
        /* Random normals (not a convex patch): still never inward. */
        dwvu_vec3 m[3] = {unit_vector(&state), unit_vector(&state), unit_vector(&state)};
        lift = dwvl_terminator_lift(v, m, b, ng);
        worst_inward = fmin(worst_inward, dwvu_dot(lift, ng));
        /* Only the side being shaded matters, not which way the stored normals point. */
        dwvu_vec3 reversed[3] = {dwvu_scale(m[0], -1.0), dwvu_scale(m[1], -1.0), dwvu_scale(m[2], -1.0)};
        worst_mirror = fmax(worst_mirror, distance(dwvl_terminator_lift(v, reversed, b, ng), lift));
    }
    CHECK(worst_inward >= 0.0, "a lift goes inward by %g", -worst_inward);
    CHECK(worst_mirror < 1e-12, "reversed vertex normals change the lift by %g", worst_mirror);
    CHECK(worst_corner < 1e-12, "a convex triangle's corner is lifted by %g", worst_corner);
    CHECK(convex > trials / 2 && interior_lifted == convex, "only %d of %d points inside convex triangles are lifted",
          interior_lifted, convex);
    /* A zero vertex normal (no smooth normal there): no lift. */
    dwvu_vec3 v[3] = {dwvu_v(0.0, 0.0, 0.0), dwvu_v(1.0, 0.0, 0.0), dwvu_v(0.0, 1.0, 0.0)};
    dwvu_vec3 n[3] = {dwvu_v(-0.6, 0.0, 0.8), dwvu_v(0.0, 0.0, 0.0), dwvu_v(-0.6, 0.0, 0.8)};
    double b[3] = {1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0};
    dwvu_vec3 lift = dwvl_terminator_lift(v, n, b, dwvu_v(0.0, 0.0, 1.0));
    CHECK(dwvu_length(lift) == 0.0, "a zero vertex normal still lifts by %g", dwvu_length(lift));
}

static void test_amount(void)
{
    const double cutoff = 0.1;
    struct { double cos_n, cos_g, amount; } cases[] = {
        {0.5, 0.05, 0.5},  /* 1 - 0.05 / 0.1 */
        {0.5, 0.2, 0.0},   /* the flat triangle faces the light by more than the cutoff */
        {0.5, -0.1, 1.0},  /* the light is below the flat triangle */
        {0.05, 0.02, 1.0}, /* 2 - 0.07 / 0.1 = 1.3, clamped */
        {0.08, 0.07, 0.5}, /* 2 - 0.15 / 0.1 */
        {0.09, 0.2, 0.0},  /* 2 - 2.9 clamped */
        {0.9, 0.9, 0.0},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        double a = dwvl_terminator_amount(cases[i].cos_n, cases[i].cos_g, cutoff);
        CHECK(fabs(a - cases[i].amount) < 1e-12, "cos_n %g, cos_g %g: amount %g, expected %g", cases[i].cos_n,
              cases[i].cos_g, a, cases[i].amount);
    }
    CHECK(dwvl_terminator_amount(0.01, 0.0, 0.0) == 0.0, "cutoff 0 takes no lift");
    double below = dwvl_terminator_amount(nextafter(cutoff, 0.0), 0.06, cutoff), at = dwvl_terminator_amount(cutoff, 0.06, cutoff);
    CHECK(fabs(below - at) < 1e-12, "discontinuous at cos_n = cutoff: %g and %g", below, at);
    uint64_t state = 11u;
    int rising = 0;
    for (int trial = 0; trial < 1000; ++trial) {
        double cos_n = brute_uniform(&state), g1 = 2.0 * brute_uniform(&state) - 1.0, g2 = 2.0 * brute_uniform(&state) - 1.0;
        double lo = fmin(g1, g2), hi = fmax(g1, g2);
        double a_lo = dwvl_terminator_amount(cos_n, lo, cutoff), a_hi = dwvl_terminator_amount(cos_n, hi, cutoff);
        rising += a_hi > a_lo || a_lo < 0.0 || a_lo > 1.0;
    }
    CHECK(rising == 0, "%d draws where the share grows with cos_g or leaves [0, 1]", rising);
}

/* A UV sphere of radius 1 with `segments` x `rings` quads (two triangles each), smooth normals. */
typedef struct sphere_mesh {
    float *positions, *normals;
    uint32_t *indices, vertex_count, triangle_count;
} sphere_mesh;

static int make_sphere(sphere_mesh *s, uint32_t segments, uint32_t rings)
{
    s->vertex_count = (rings + 1u) * segments;
    s->triangle_count = 2u * rings * segments;
    s->positions = malloc(3u * s->vertex_count * sizeof(float));
    s->normals = malloc(3u * s->vertex_count * sizeof(float));
    s->indices = malloc(3u * s->triangle_count * sizeof(uint32_t));
    if (!s->positions || !s->normals || !s->indices) return -1;
    for (uint32_t r = 0; r <= rings; ++r)
        for (uint32_t k = 0; k < segments; ++k) {
            double theta = 3.141592653589793 * r / rings, phi = 6.283185307179586 * k / segments;
            float *p = s->positions + 3u * (r * segments + k), *m = s->normals + 3u * (r * segments + k);
            p[0] = m[0] = (float)(sin(theta) * cos(phi));
            p[1] = m[1] = (float)(sin(theta) * sin(phi));
            p[2] = m[2] = (float)cos(theta);
        }
    uint32_t t = 0;
    for (uint32_t r = 0; r < rings; ++r)
        for (uint32_t k = 0; k < segments; ++k) {
            uint32_t a = r * segments + k, b = r * segments + (k + 1u) % segments, c = a + segments, d = b + segments;
            /* Counter-clockwise seen from outside (theta grows downward, phi eastward). */
            uint32_t tri[2][3] = {{a, c, d}, {a, d, b}};
            for (int h = 0; h < 2; ++h, ++t)
                for (int q = 0; q < 3; ++q) s->indices[3u * t + (uint32_t)q] = tri[h][q];
        }
    return 0;
}

static void test_sphere_terminator(void)
{
    sphere_mesh s = {0};
    if (make_sphere(&s, 12u, 6u)) {
        CHECK(0, "out of memory");
        return;
    }
    const double identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    dwvg_mesh mesh;
    CHECK(dwvg_mesh_init(&mesh, s.vertex_count, s.triangle_count, 0u, s.positions, s.indices, s.normals, NULL,
                         identity) == 0,
          "mesh");
    dwvg_world world;
    char message[256];
    CHECK(dwvg_world_build(&world, &mesh, 1u, message, sizeof message) == 0, "world: %s", message);
    /* A sun travelling along -x: toward it is +x. */
    dwv_light_desc_t desc = DWV_LIGHT_DESC_INIT;
    desc.direction[0] = -1.0;
    desc.direction[1] = 0.0;
    desc.direction[2] = 0.0;
    dwvl_light sun;
    dwvl_light_init(&sun, &desc);
    dwvl_environment env = {&sun, 1u, {0.0, 0.0, 0.0}, 0, &world, NULL};
    dwvu_vec3 to_sun = dwvu_v(1.0, 0.0, 0.0);
    int below = 0, below_lit_flat = 0, below_lit_smooth = 0, lit = 0, lit_changed = 0, beyond = 0, beyond_lit = 0;
    uint64_t state = 5u;
    dwvk_sampler sampler = {.key = 1u, .index = 0u, .stratified = 0};
    for (uint32_t prim = 0; prim < mesh.triangle_count; ++prim) {
        dwvu_vec3 ng = dwvg_geometric_normal(&mesh, prim);
        if (ng.x == 0.0 && ng.y == 0.0 && ng.z == 0.0) continue; /* the poles' degenerate triangles */
        for (int k = 0; k < 20; ++k) {
            double b[3];
            random_barycentrics(&state, b);
            dwvu_vec3 x = dwvg_point(&mesh, prim, b[1], b[2]);
            dwvu_vec3 n = dwvg_shading_normal(&mesh, prim, b[1], b[2], ng);
            double cos_n = dwvu_dot(n, to_sun), cos_g = dwvu_dot(ng, to_sun);
            dwvl_terminator terminator = {&mesh, prim, b[1], b[2], CYCLES_GEOMETRY_OFFSET, n};
            if (!(cos_n > 0.0)) {
                /* A lobe normal tilted toward the sun (a normal map's) at a point whose smooth
                 * normal faces away from it: Cycles' shadow ray leaves from under the triangle
                 * (shadow_ray_offset's side is sd->N's) and meets the sphere's far side. */
                dwvu_vec3 mapped = dwvu_normalize(dwvu_madd(n, to_sun, 0.6));
                if (!(dwvu_dot(mapped, to_sun) > 0.0)) continue;
                double mapped_light[3];
                dwvl_direct(&env, x, mapped, ng, &terminator, INFINITY, &sampler, 0u, mapped_light);
                ++beyond;
                beyond_lit += mapped_light[0] > 0.0;
                continue;
            }
            double flat[3], smooth[3];
            dwvl_direct(&env, x, n, ng, NULL, INFINITY, &sampler, 0u, flat);
            dwvl_direct(&env, x, n, ng, &terminator, INFINITY, &sampler, 0u, smooth);
            if (cos_g <= 0.0) {
                ++below;
                below_lit_flat += flat[0] > 0.0;
                below_lit_smooth += smooth[0] > 0.0;
            } else if (cos_g > 2.0 * CYCLES_GEOMETRY_OFFSET) {
                ++lit;
                lit_changed += flat[0] != smooth[0];
            }
        }
    }
    CHECK(below > 20, "only %d points past the flat terminator", below);
    CHECK(below_lit_flat == 0, "%d points past the flat terminator are lit without the offset", below_lit_flat);
    CHECK(below_lit_smooth > below / 4, "only %d of %d points past the flat terminator are lit with the offset",
          below_lit_smooth, below);
    CHECK(lit > 100 && lit_changed == 0, "%d of %d points well inside the lit side change", lit_changed, lit);
    CHECK(beyond > 20 && beyond_lit == 0, "%d of %d points past the smooth terminator are lit through a mapped normal",
          beyond_lit, beyond);
    printf("sphere 12 x 6: %d points past the flat terminator, %d lit with the offset; %d lit points unchanged; "
           "%d points past the smooth terminator, %d lit through a mapped normal\n",
           below, below_lit_smooth, lit, beyond, beyond_lit);
    dwvg_world_free(&world);
    dwvg_mesh_free(&mesh);
    free(s.positions);
    free(s.normals);
    free(s.indices);
}

int main(void)
{
    test_flat();
    test_cylinder_patch();
    test_outward();
    test_amount();
    test_sphere_terminator();
    return check_report("test_terminator");
}
