/* dwvb_mesh_mean_chord (src/bake/pilot.c), which keeps auto's pilot from running the sheet walk on
 * meshes far thicker than a mean free path: 4 V / A of closed outward-facing meshes against closed
 * forms (a box 2 a b c / (a b + b c + c a) x 2, a UV sphere's polyhedron against its own volume
 * and area summed here in another order, and 4 r / 3 as the facets get fine), a box moved far from
 * the origin (the volume does not depend on it), and -1 for what it must refuse: a box with a face
 * missing, the box turned inside out, a NaN position, an empty mesh. */
#include <math.h>

#include "bake/pilot.h"
#include "check.h"
#include "geom/mesh.h"

#define PI 3.14159265358979323846

static const double IDENTITY[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};

/* A box [0, a] x [0, b] x [0, c] moved by `offset`, outward-facing (counter-clockwise from
 * outside), its first `faces` of 6 faces (2 triangles each), `flip`: inward-facing. */
static double box_chord(double a, double b, double c, double offset, int faces, int flip, int nan_corner)
{
    float p[8 * 3];
    for (int i = 0; i < 8; ++i) {
        p[3 * i + 0] = (float)((i & 1 ? a : 0.0) + offset);
        p[3 * i + 1] = (float)((i & 2 ? b : 0.0) + offset);
        p[3 * i + 2] = (float)((i & 4 ? c : 0.0) + offset);
    }
    if (nan_corner) p[5] = NAN;
    static const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    uint32_t indices[12 * 3];
    for (int f = 0; f < faces; ++f) {
        const uint32_t *q = quads[f];
        uint32_t t[6] = {q[0], q[1], q[2], q[0], q[2], q[3]};
        for (int k = 0; k < 6; ++k) indices[6 * f + k] = t[flip ? 5 - k : k];
    }
    dwvg_mesh mesh;
    if (dwvg_mesh_init(&mesh, 8, (uint32_t)(2 * faces), 0, p, indices, NULL, NULL, IDENTITY) != 0) return -2.0;
    double chord = dwvb_mesh_mean_chord(&mesh);
    dwvg_mesh_free(&mesh);
    return chord;
}

/* A UV sphere of radius r (segments x rings); its 4 V / A summed here as cones from the centre. */
static double sphere_chord(double r, int segments, int rings, double *expected)
{
    enum { MAX_SEG = 96, MAX_RING = 48 };
    static float p[(MAX_SEG * (MAX_RING - 1) + 2) * 3];
    static uint32_t idx[MAX_SEG * MAX_RING * 2 * 3];
    uint32_t v = 0, t = 0;
    for (int j = 1; j < rings; ++j)
        for (int i = 0; i < segments; ++i, ++v) {
            double th = PI * j / rings, ph = 2.0 * PI * i / segments;
            p[3 * v] = (float)(r * sin(th) * cos(ph)), p[3 * v + 1] = (float)(r * sin(th) * sin(ph)), p[3 * v + 2] = (float)(r * cos(th));
        }
    uint32_t top = v++, bottom = v++;
    p[3 * top] = p[3 * top + 1] = 0.0f, p[3 * top + 2] = (float)r;
    p[3 * bottom] = p[3 * bottom + 1] = 0.0f, p[3 * bottom + 2] = (float)-r;
    for (int i = 0; i < segments; ++i) {
        uint32_t i1 = (uint32_t)((i + 1) % segments);
        uint32_t tri[3] = {top, (uint32_t)i, i1};
        for (int k = 0; k < 3; ++k) idx[3 * t + k] = tri[k];
        ++t;
        uint32_t last = (uint32_t)((rings - 2) * segments);
        uint32_t tri2[3] = {bottom, last + i1, last + (uint32_t)i};
        for (int k = 0; k < 3; ++k) idx[3 * t + k] = tri2[k];
        ++t;
        for (int j = 0; j < rings - 2; ++j) {
            uint32_t a = (uint32_t)(j * segments + i), b = (uint32_t)(j * segments) + i1, c = a + (uint32_t)segments, d = b + (uint32_t)segments;
            uint32_t q[6] = {a, c, d, a, d, b};
            for (int k = 0; k < 6; ++k) idx[3 * t + (uint32_t)k % 3 + 3 * ((uint32_t)k / 3)] = q[k];
            t += 2;
        }
    }
    double volume = 0.0, area = 0.0;
    for (uint32_t k = 0; k < t; ++k) { /* each facet a cone from the centre: V += A h / 3 */
        const float *x = &p[3 * idx[3 * k]], *y = &p[3 * idx[3 * k + 1]], *z = &p[3 * idx[3 * k + 2]];
        double e1[3] = {y[0] - x[0], y[1] - x[1], y[2] - x[2]}, e2[3] = {z[0] - x[0], z[1] - x[1], z[2] - x[2]};
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        area += 0.5 * len;
        volume += 0.5 * len * ((n[0] * x[0] + n[1] * x[1] + n[2] * x[2]) / len) / 3.0;
    }
    *expected = 4.0 * volume / area;
    dwvg_mesh mesh;
    if (dwvg_mesh_init(&mesh, v, t, 0, p, idx, NULL, NULL, IDENTITY) != 0) return -2.0;
    double chord = dwvb_mesh_mean_chord(&mesh);
    dwvg_mesh_free(&mesh);
    return chord;
}

int main(void)
{
    double a = 0.3, b = 0.2, c = 0.01; /* a thin plate: chord near 2 c */
    double box = 4.0 * a * b * c / (2.0 * (a * b + b * c + c * a));
    double got = box_chord(a, b, c, 0.0, 6, 0, 0);
    CHECK(fabs(got / box - 1.0) < 1e-6, "plate chord %.9g, expected %.9g", got, box);
    double cube = 2.0 / 3.0; /* 4 s^3 / 6 s^2 */
    got = box_chord(1.0, 1.0, 1.0, 0.0, 6, 0, 0);
    CHECK(fabs(got - cube) < 1e-6, "cube chord %.9g, expected %.9g", got, cube);
    got = box_chord(1.0, 1.0, 1.0, 100.0, 6, 0, 0);
    CHECK(fabs(got - cube) < 1e-4, "cube far from the origin: %.9g, expected %.9g", got, cube);
    got = box_chord(1.0, 1.0, 1.0, 0.0, 5, 0, 0);
    CHECK(got == -1.0, "a box with a face missing is open: %g", got);
    got = box_chord(1.0, 1.0, 1.0, 0.0, 6, 1, 0);
    CHECK(got == -1.0, "an inside-out box has no positive volume: %g", got);
    got = box_chord(1.0, 1.0, 1.0, 0.0, 6, 0, 1);
    CHECK(got == -1.0, "a NaN corner: %g", got);
    got = box_chord(1.0, 1.0, 1.0, 0.0, 0, 0, 0);
    CHECK(got == -1.0, "an empty mesh: %g", got);
    double expected;
    got = sphere_chord(0.2, 48, 24, &expected);
    CHECK(fabs(got / expected - 1.0) < 1e-6, "UV sphere chord %.9g, its polyhedron's %.9g", got, expected);
    got = sphere_chord(0.2, 96, 48, &expected);
    CHECK(fabs(got / (4.0 * 0.2 / 3.0) - 1.0) < 2e-3, "fine UV sphere chord %.9g, 4 r / 3 = %.9g", got, 4.0 * 0.2 / 3.0);
    return check_report("test_mesh_chord");
}
