/* Point and spot lights of radius r > 0 as a disc facing the shaded point (Cycles 3.x; 4.0+ with
 * Soft Falloff) and as a sphere (4.0+ without it), src/light/light.c: each sample's value times
 * dwvl_light_pdf is the light's radiance I / (pi r^2) (times a spot's attenuation) exactly, and
 * Monte Carlo means over N samples match closed forms within 5 standard errors:
 *   E[1 / pdf] = the solid angle the sampler covers (disc: 2 pi (1 - d / sqrt(d^2 + r^2)); sphere:
 *     2 pi (1 - cos theta_max) outside, 4 pi inside): the pdf integrates to 1 over the samples;
 *   E[value cos] = the irradiance on a surface facing the centre: I / (d^2 + r^2) for the disc,
 *     I / d^2 for the sphere (the sphere's irradiance is its point light's, Cycles 4.x). */
#include <math.h>
#include <stdio.h>

#include "check.h"
#include "light/light.h"

#define PI 3.14159265358979323846

static double halton(unsigned i, unsigned base)
{
    double f = 1.0, r = 0.0;
    for (; i > 0; i /= base) {
        f /= base;
        r += f * (double)(i % base);
    }
    return r;
}

static void check_shape(int shape, double d, double r)
{
    dwv_light_desc_t desc = DWV_LIGHT_DESC_INIT;
    desc.kind = DWV_LIGHT_POINT;
    desc.strength = 4.0 * PI; /* intensity 1 */
    desc.radius = r;
    desc.point_shape = shape;
    desc.position[2] = d;
    dwvl_light light;
    dwvl_light_init(&light, &desc);
    dwvu_vec3 x = dwvu_v(0.0, 0.0, 0.0), up = dwvu_v(0.0, 0.0, 1.0);
    const unsigned n = 200000;
    double s1 = 0.0, s2 = 0.0, e1 = 0.0, e2 = 0.0, worst = 0.0;
    double radiance = 1.0 / (PI * r * r);
    for (unsigned i = 0; i < n; ++i) {
        dwvl_sample sm;
        dwvl_light_sample(&light, x, halton(i + 1, 2), halton(i + 1, 3), &sm);
        double pdf = dwvl_light_pdf(&light, x, sm.direction);
        double inv = pdf > 0.0 ? 1.0 / pdf : 0.0;
        worst = fmax(worst, fabs(sm.value[0] * pdf / radiance - 1.0));
        double cosine = fmax(dwvu_dot(sm.direction, up), 0.0);
        s1 += inv, s2 += inv * inv;
        e1 += sm.value[0] * cosine, e2 += sm.value[0] * cosine * sm.value[0] * cosine;
    }
    double m = s1 / n, se = sqrt(fmax(s2 / n - m * m, 0.0) / n) + 1e-12;
    double em = e1 / n, ee = sqrt(fmax(e2 / n - em * em, 0.0) / n) + 1e-12;
    double covered, irradiance;
    if (shape == DWV_POINT_SHAPE_DISC) {
        covered = 2.0 * PI * (1.0 - d / sqrt(d * d + r * r));
        irradiance = 1.0 / (d * d + r * r);
    } else {
        covered = d > r ? 2.0 * PI * (1.0 - sqrt(1.0 - r * r / (d * d))) : 4.0 * PI;
        irradiance = d > r ? 1.0 / (d * d) : PI / (PI * r * r); /* inside: L pi */
    }
    const char *name = shape == DWV_POINT_SHAPE_DISC ? "disc" : "sphere";
    CHECK(worst < 1e-9, "%s d %g r %g: value x pdf is the radiance (worst relative %.3g)", name, d, r, worst);
    CHECK(fabs(m - covered) < 5.0 * se + 1e-9 * covered, "%s d %g r %g: E[1/pdf] %.6g, solid angle %.6g (se %.2g)",
          name, d, r, m, covered, se);
    CHECK(fabs(em - irradiance) < 5.0 * ee + 1e-9 * irradiance, "%s d %g r %g: irradiance %.6g, want %.6g (se %.2g)",
          name, d, r, em, irradiance, ee);
}

int main(void)
{
    /* Blender's default lamp (r = 0.1) near a small object, far, and a point inside the sphere. */
    static const double cases[][2] = {{0.15, 0.1}, {0.4, 0.1}, {3.0, 0.1}, {0.5, 0.45}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        check_shape(DWV_POINT_SHAPE_DISC, cases[i][0], cases[i][1]);
        check_shape(DWV_POINT_SHAPE_SPHERE, cases[i][0], cases[i][1]);
    }
    check_shape(DWV_POINT_SHAPE_SPHERE, 0.05, 0.1); /* inside */
    /* The two shapes differ near the light by d^2 / (d^2 + r^2) (0.69 at d = 0.15, r = 0.1). */
    dwv_light_desc_t desc = DWV_LIGHT_DESC_INIT;
    desc.kind = DWV_LIGHT_SPOT;
    desc.direction[2] = 1.0; /* from (0, 0, -1) up toward x = 0 */
    desc.position[2] = -1.0;
    desc.radius = 0.2;
    desc.spot_size = 1.0;
    desc.spot_blend = 0.5;
    desc.spot_falloff = DWV_SPOT_FALLOFF_CYCLES4;
    desc.point_shape = DWV_POINT_SHAPE_SPHERE;
    dwvl_light spot;
    dwvl_light_init(&spot, &desc);
    for (unsigned i = 1; i < 50; ++i) {
        dwvu_vec3 x = dwvu_v(0.02 * i, 0.0, 0.0);
        dwvl_sample sm;
        dwvl_light_sample(&spot, x, halton(i, 2), halton(i, 3), &sm);
        double att = dwvl_spot_attenuation(&spot, -dwvu_dot(spot.spot_axis, sm.direction));
        double want = att * spot.emission[0] / (PI * 0.04);
        CHECK(fabs(sm.value[0] * dwvl_light_pdf(&spot, x, sm.direction) - want) <= 1e-9 * (want + 1e-30),
              "sphere spot at x %g: value x pdf = radiance x attenuation", x.x);
    }
    return check_report("test_point_shape");
}
