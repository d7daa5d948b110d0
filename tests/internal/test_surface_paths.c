/* The mixture that indirect light draws a surface point's path rays from (src/bake/shade.h,
 * dwvb_surface_sample / dwvb_surface_pdf): a chi-square of 400k sampled directions against the
 * pdf integrated over (cos, azimuth) bins of the upper hemisphere of the diffuse normal n, plus
 * one bin for directions below it and a mirror's draws (expected: n x (1 - the pdf's integral
 * above)), for 4.x+ and 3.x specular layers, several roughnesses and viewers, and the specular
 * layer's own normal tilted from n (a normal-mapped 4.x+ surface: specular_n kept valid for
 * reflection); the diffuse-only case (p_s = 0) integrates to 1. Mirrors (Roughness 0, 3.x and
 * 4.x+): the draws flagged singular are the mirror direction about specular_n, their count
 * binomial(n, p_s) within 5 sigma, the rest chi-square against the continuous part. Planted
 * pdfs must fail: the specular part not weighted by p_s; and, tilted, the specular part about n
 * (the pdf before the lobes took their own normals). Bound: p > 1e-5 per case (the planted ones
 * give p < 1e-12). Filter Glossy: two mirrors roughened as after a bounce of pdf 0.6 / pi at
 * blur_glossy 1 (dwvb_blur_alpha: alpha 0.5 sqrt(1 - 0.6 / pi) = 0.45, v2 keeping its alpha-0
 * tables as Cycles keeps its energy terms), one of them tilted: GGX lobes now, no singular draw;
 * and dwvb_blur_alpha's values where it applies and where not. */
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

typedef double (*mixture_pdf)(const dwvb_material *m, double p_specular, dwvu_vec3 n, dwvu_vec3 specular_n,
                              dwvu_vec3 to_view, dwvu_vec3 w);

/* Planted: the specular part at full weight (its mixture probability left out). */
static double planted_pdf(const dwvb_material *m, double p_specular, dwvu_vec3 n, dwvu_vec3 specular_n, dwvu_vec3 to_view,
                          dwvu_vec3 w)
{
    double cosine = (1.0 - p_specular) * dwvb_surface_pdf(m, 0.0, n, specular_n, to_view, w);
    double specular = dwvb_surface_pdf(m, p_specular, n, specular_n, to_view, w) - cosine;
    return cosine + specular / p_specular;
}

/* Planted: the specular part about the diffuse normal n (before each lobe took its own). */
static double planted_normal_pdf(const dwvb_material *m, double p_specular, dwvu_vec3 n, dwvu_vec3 specular_n,
                                 dwvu_vec3 to_view, dwvu_vec3 w)
{
    (void)specular_n;
    return dwvb_surface_pdf(m, p_specular, n, n, to_view, w);
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

/* The chi-square's p; *singular_draws counts the draws flagged singular, each of which must be
 * the mirror direction of to_view about specular_n (else the count is made negative). */
static double chi_square(const dwvb_material *m, double p_specular, dwvu_vec3 specular_n, dwvu_vec3 to_view,
                         mixture_pdf pdf, double *total, double *singular_draws)
{
    static double observed[ZB * PB + 1], expected[ZB * PB + 1];
    memset(observed, 0, sizeof observed);
    dwvu_vec3 n = dwvu_v(0.0, 0.0, 1.0);
    dwvu_vec3 mirror = dwvu_sub(dwvu_scale(specular_n, 2.0 * dwvu_dot(specular_n, to_view)), to_view);
    uint64_t state = 1812u;
    int wrong_mirror = 0;
    *singular_draws = 0.0;
    for (int i = 0; i < SAMPLES; ++i) {
        double u0 = brute_uniform(&state), u1 = brute_uniform(&state), choice = brute_uniform(&state);
        dwvu_vec3 w;
        int lobe, singular;
        if (!dwvb_surface_sample(m, p_specular, n, specular_n, to_view, u0, u1, choice, &w, &lobe, &singular)) {
            observed[ZB * PB] += 1.0; /* none drawn: counted with those below the horizon */
            continue;
        }
        if (singular) {
            /* A delta: in no bin of the pdf. */
            *singular_draws += 1.0;
            wrong_mirror |= lobe != DWVB_LOBE_GLOSSY || dwvu_length(dwvu_sub(w, mirror)) > 1e-12;
            observed[ZB * PB] += 1.0;
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
                    sum += pdf(m, p_specular, n, specular_n, to_view, dwvu_v(r * cos(phi), r * sin(phi), z)) * dz * dp;
                }
            expected[zb * PB + pb] = sum * SAMPLES;
            *total += sum;
        }
    expected[ZB * PB] = fmax(1.0 - *total, 0.0) * SAMPLES;
    if (wrong_mirror) *singular_draws = -1.0;
    return stats_chi_square(observed, expected, ZB * PB + 1).p;
}

int main(void)
{
    /* tilt: the specular layer's normal turned that many radians from n toward the viewer's side
     * (+x), as ensure_valid_reflection turns a mapped normal. */
    /* blur: the specular alpha roughened as after a bounce of pdf 0.6 / pi (Filter Glossy 1). */
    static const struct { int model; double roughness, mu, tilt; int blur; } cases[] = {
        {DWV_SPECULAR_PRINCIPLED_V2, 0.3, 0.9, 0.0, 0}, {DWV_SPECULAR_PRINCIPLED_V2, 0.3, 0.3, 0.0, 0},
        {DWV_SPECULAR_PRINCIPLED_V2, 0.7, 0.6, 0.0, 0}, {DWV_SPECULAR_PRINCIPLED_V1, 0.4, 0.8, 0.0, 0},
        {DWV_SPECULAR_PRINCIPLED_V1, 0.5, 0.2, 0.0, 0}, {DWV_SPECULAR_PRINCIPLED_V2, 0.3, 0.3, 0.35, 0},
        {DWV_SPECULAR_PRINCIPLED_V2, 0.6, 0.5, 0.5, 0}, {DWV_SPECULAR_PRINCIPLED_V2, 0.0, 0.5, 0.0, 0},
        {DWV_SPECULAR_PRINCIPLED_V1, 0.0, 0.3, 0.0, 0}, {DWV_SPECULAR_PRINCIPLED_V2, 0.0, 0.4, 0.3, 0},
        {DWV_SPECULAR_PRINCIPLED_V2, 0.0, 0.5, 0.0, 1}, {DWV_SPECULAR_PRINCIPLED_V1, 0.0, 0.4, 0.3, 1}};
    const double bounce_pdf = 0.6 / 3.14159265358979323846, blurred = 0.5 * sqrt(1.0 - bounce_pdf);
    CHECK(dwvb_blur_alpha(0.0, bounce_pdf, 1.0) == blurred && dwvb_blur_alpha(0.7, bounce_pdf, 1.0) == 0.7,
          "blur of a bounce of pdf 0.6 / pi: %g, %g", dwvb_blur_alpha(0.0, bounce_pdf, 1.0),
          dwvb_blur_alpha(0.7, bounce_pdf, 1.0));
    CHECK(dwvb_blur_alpha(0.0, 2.0, 1.0) == 0.0 && dwvb_blur_alpha(0.0, INFINITY, 1.0) == 0.0 &&
              dwvb_blur_alpha(0.0, bounce_pdf, 0.0) == 0.0 && dwvb_blur_alpha(0.0, 2.0, 4.0) == 0.5 * sqrt(0.5),
          "blur where p / blur_glossy >= 1, at the camera, with blur_glossy 0, and at p 2 / blur_glossy 4");
    const double diffuse[3] = {0.5, 0.4, 0.3};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        dwvb_material m;
        material_of(&m, cases[k].model, cases[k].roughness);
        if (cases[k].blur) m.spec_alpha = dwvb_blur_alpha(m.spec_alpha, bounce_pdf, 1.0);
        dwvu_vec3 to_view = dwvu_v(sqrt(1.0 - cases[k].mu * cases[k].mu), 0.0, cases[k].mu);
        dwvu_vec3 specular_n = dwvu_v(sin(cases[k].tilt), 0.0, cos(cases[k].tilt));
        int mirror = dwvb_specular_singular(&m);
        CHECK(mirror == (cases[k].roughness == 0.0 && !cases[k].blur), "case %zu: singular %d", k, mirror);
        double p_specular = dwvb_surface_specular_probability(&m, diffuse, dwvu_dot(specular_n, to_view));
        CHECK(p_specular > 0.0 && p_specular < 1.0, "case %zu: p_s = %g", k, p_specular);
        double total, planted_total, draws, planted_draws;
        double p = chi_square(&m, p_specular, specular_n, to_view, dwvb_surface_pdf, &total, &draws);
        double planted = mirror ? 0.0 : chi_square(&m, p_specular, specular_n, to_view, planted_pdf, &planted_total,
                                                   &planted_draws);
        double planted_normal = cases[k].tilt > 0.0 && !mirror
                                    ? chi_square(&m, p_specular, specular_n, to_view, planted_normal_pdf, &planted_total,
                                                 &planted_draws)
                                    : 0.0;
        printf("case %zu (model %d, roughness %.1f, mu %.1f, tilt %.2f, alpha %.3f): p_s %.4f, pdf above the horizon %.5f, "
               "chi-square p %.3g; mirror draws %.0f; planted p %.3g, planted normal p %.3g\n",
               k, cases[k].model, cases[k].roughness, cases[k].mu, cases[k].tilt, m.spec_alpha, p_specular, total, p, draws, planted,
               planted_normal);
        CHECK(p > 1e-5, "case %zu: chi-square p = %g", k, p);
        CHECK(total <= 1.0 + 1e-3, "case %zu: the pdf integrates to %g above the horizon", k, total);
        CHECK(planted < 1e-12, "case %zu: the planted pdf passes (p = %g)", k, planted);
        CHECK(planted_normal < 1e-12, "case %zu: the planted normal's pdf passes (p = %g)", k, planted_normal);
        double expect = mirror ? p_specular * SAMPLES : 0.0;
        double sigma = sqrt(SAMPLES * p_specular * (1.0 - p_specular));
        CHECK(draws >= 0.0 && fabs(draws - expect) <= 5.0 * sigma,
              "case %zu: %.0f mirror draws (expected %.0f, sigma %.0f; -1: not the mirror direction)", k, draws, expect,
              sigma);
    }
    /* No specular layer: the cosine alone, which integrates to 1. */
    dwvb_material plain;
    material_of(&plain, DWV_SPECULAR_NONE, 0.5);
    double p_none = dwvb_surface_specular_probability(&plain, diffuse, 0.7), total;
    CHECK(p_none == 0.0, "no layer: p_s = %g", p_none);
    double draws;
    double p = chi_square(&plain, p_none, dwvu_v(0.0, 0.0, 1.0), dwvu_v(0.6, 0.0, 0.8), dwvb_surface_pdf, &total, &draws);
    CHECK(p > 1e-5 && fabs(total - 1.0) < 2e-3, "cosine: p = %g, integral %g", p, total);
    const double black[3] = {0.0, 0.0, 0.0};
    CHECK(dwvb_surface_specular_probability(&plain, black, 0.7) < 0.0, "nothing scatters: a mixture");
    return check_report("test_surface_paths");
}
