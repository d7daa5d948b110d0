/* The mixture that indirect light draws a surface point's path rays from (src/bake/shade.h,
 * dwvb_surface_sample / dwvb_surface_pdf): a chi-square of 400k sampled directions against the
 * pdf integrated over (cos, azimuth) bins of the upper hemisphere, plus one bin for directions
 * the specular lobe reflects below the horizon (expected: n x (1 - the pdf's integral above)),
 * for 4.x+ and 3.x specular layers, several roughnesses and viewers; the diffuse-only case
 * (p_s = 0) integrates to 1; a planted pdf (the specular part not weighted by p_s) must fail.
 * Bound: p > 1e-5 per case (the planted one gives p < 1e-12). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <dwivedi.h>

#include "bake/material.h"
#include "bake/shade.h"
#include "brute_force.h"
#include "check.h"
#include "stats.h"

#define PI 3.14159265358979323846
#define ZB 16
#define PB 16
#define SUB 10
#define SAMPLES 400000

typedef double (*mixture_pdf)(const dwvb_material *m, double p_specular, dwvu_vec3 n, dwvu_vec3 to_view, dwvu_vec3 w);

/* Planted: the specular part at full weight (its mixture probability left out). */
static double planted_pdf(const dwvb_material *m, double p_specular, dwvu_vec3 n, dwvu_vec3 to_view, dwvu_vec3 w)
{
    double cosine = (1.0 - p_specular) * dwvb_surface_pdf(m, 0.0, n, to_view, w);
    double specular = dwvb_surface_pdf(m, p_specular, n, to_view, w) - cosine;
    return cosine + specular / p_specular;
}

static void material_of(dwvb_material *out, int model, double roughness)
{
    dwv_material_t in = DWV_MATERIAL_INIT;
    in.kind = DWV_MATERIAL_DIFFUSE;
    in.base_color[0] = 0.5, in.base_color[1] = 0.4, in.base_color[2] = 0.3;
    in.roughness = roughness;
    in.specular_model = model;
    in.specular = 0.5;
    in.ior = 1.5;
    dwvb_material_init(out, &in);
}

static double chi_square(const dwvb_material *m, double p_specular, dwvu_vec3 to_view, mixture_pdf pdf, double *total)
{
    static double observed[ZB * PB + 1], expected[ZB * PB + 1];
    memset(observed, 0, sizeof observed);
    dwvu_vec3 n = dwvu_v(0.0, 0.0, 1.0);
    uint64_t state = 1812u;
    for (int i = 0; i < SAMPLES; ++i) {
        double u0 = brute_uniform(&state), u1 = brute_uniform(&state), choice = brute_uniform(&state);
        dwvu_vec3 w;
        int lobe;
        if (!dwvb_surface_sample(m, p_specular, n, to_view, u0, u1, choice, &w, &lobe)) {
            observed[ZB * PB] += 1.0; /* none drawn: counted with those below the horizon */
            continue;
        }
        if (!(w.z > 0.0)) {
            observed[ZB * PB] += 1.0;
            continue;
        }
        int zb = (int)floor(w.z * ZB);
        double phi = atan2(w.y, w.x);
        if (phi < 0.0) phi += 2.0 * PI;
        int pb = (int)floor(phi / (2.0 * PI) * PB);
        zb = zb >= ZB ? ZB - 1 : zb;
        pb = pb >= PB ? PB - 1 : pb;
        observed[zb * PB + pb] += 1.0;
    }
    *total = 0.0;
    for (int zb = 0; zb < ZB; ++zb)
        for (int pb = 0; pb < PB; ++pb) {
            double sum = 0.0, dz = 1.0 / ZB / SUB, dp = 2.0 * PI / PB / SUB;
            for (int a = 0; a < SUB; ++a)
                for (int b = 0; b < SUB; ++b) {
                    double z = (zb + (a + 0.5) / SUB) / ZB;
                    double phi = 2.0 * PI * (pb + (b + 0.5) / SUB) / PB;
                    double r = sqrt(fmax(0.0, 1.0 - z * z));
                    sum += pdf(m, p_specular, n, to_view, dwvu_v(r * cos(phi), r * sin(phi), z)) * dz * dp;
                }
            expected[zb * PB + pb] = sum * SAMPLES;
            *total += sum;
        }
    expected[ZB * PB] = fmax(1.0 - *total, 0.0) * SAMPLES;
    return stats_chi_square(observed, expected, ZB * PB + 1).p;
}

int main(void)
{
    static const struct { int model; double roughness, mu; } cases[] = {
        {DWV_SPECULAR_PRINCIPLED_V2, 0.3, 0.9}, {DWV_SPECULAR_PRINCIPLED_V2, 0.3, 0.3},
        {DWV_SPECULAR_PRINCIPLED_V2, 0.7, 0.6}, {DWV_SPECULAR_PRINCIPLED_V1, 0.4, 0.8},
        {DWV_SPECULAR_PRINCIPLED_V1, 0.5, 0.2}};
    const double diffuse[3] = {0.5, 0.4, 0.3};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        dwvb_material m;
        material_of(&m, cases[k].model, cases[k].roughness);
        dwvu_vec3 to_view = dwvu_v(sqrt(1.0 - cases[k].mu * cases[k].mu), 0.0, cases[k].mu);
        double p_specular = dwvb_surface_specular_probability(&m, diffuse, cases[k].mu);
        CHECK(p_specular > 0.0 && p_specular < 1.0, "case %zu: p_s = %g", k, p_specular);
        double total, planted_total;
        double p = chi_square(&m, p_specular, to_view, dwvb_surface_pdf, &total);
        double planted = chi_square(&m, p_specular, to_view, planted_pdf, &planted_total);
        printf("case %zu (model %d, roughness %.1f, mu %.1f): p_s %.4f, pdf above the horizon %.5f, chi-square p %.3g; "
               "planted p %.3g\n", k, cases[k].model, cases[k].roughness, cases[k].mu, p_specular, total, p, planted);
        CHECK(p > 1e-5, "case %zu: chi-square p = %g", k, p);
        CHECK(total <= 1.0 + 1e-3, "case %zu: the pdf integrates to %g above the horizon", k, total);
        CHECK(planted < 1e-12, "case %zu: the planted pdf passes (p = %g)", k, planted);
    }
    /* No specular layer: the cosine alone, which integrates to 1. */
    dwvb_material plain;
    material_of(&plain, DWV_SPECULAR_NONE, 0.5);
    double p_none = dwvb_surface_specular_probability(&plain, diffuse, 0.7), total;
    CHECK(p_none == 0.0, "no layer: p_s = %g", p_none);
    double p = chi_square(&plain, p_none, dwvu_v(0.6, 0.0, 0.8), dwvb_surface_pdf, &total);
    CHECK(p > 1e-5 && fabs(total - 1.0) < 2e-3, "cosine: p = %g, integral %g", p, total);
    const double black[3] = {0.0, 0.0, 0.0};
    CHECK(dwvb_surface_specular_probability(&plain, black, 0.7) < 0.0, "nothing scatters: a mixture");
    return check_report("test_surface_paths");
}
