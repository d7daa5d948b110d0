/* Blender 3.x Principled BSDF's subsurface terms (src/bake/material.c) against their formulas and
 * closed forms, and their wiring into next-event estimation (src/light/direct.c):
 *   - Schlick's weight (1 - cos)^5 with cos clamped to [0, 1], against pow();
 *   - the exit factor 1 - F_L / 2 against the formula, and the exit BSDF's albedo
 *     int (1/pi) cos (1 - F_L/2) dw = 1 - B(2, 6) = 1 - 1/42 (B the Beta function:
 *     2 int_0^1 mu (1 - mu)^5 dmu = 2 / 42), by Gauss-Legendre quadrature;
 *   - the retro-reflection factor R_R (F_L + F_V + F_L F_V (R_R - 1)) against the same written
 *     with the half vector (R_R = 2 roughness (L.H)^2, Burley 2015 section 5.3), over random
 *     directions and roughnesses, and its values at normal and grazing incidence;
 *   - dwvl_direct_lobe: with one sun, the lobe is the Lambertian value times the factor at the
 *     sun's direction, and the Lambertian value is dwvl_direct's.
 * A planted error (an exponent of 4 in the exit factor) shows the albedo check can fail. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "bake/material.h"
#include "brute_force.h"
#include "check.h"
#include "stats.h"
#include "light/direct.h"
#include "light/light.h"

/* 1 - 1/42: the exit BSDF's albedo (see above). */
static const double EXIT_ALBEDO = 41.0 / 42.0;

/* A unit direction on the upper hemisphere (z > 0) from two uniforms. */
static dwvu_vec3 upper(double u1, double u2)
{
    double z = fmax(u1, 1e-6), r = sqrt(fmax(0.0, 1.0 - z * z)), phi = 6.283185307179586 * u2;
    return dwvu_v(r * cos(phi), r * sin(phi), z);
}

/* The cosine-weighted hemisphere albedo of a factor g(mu) of the Lambertian BSDF. */
typedef struct albedo_integrand {
    double (*g)(double);
} albedo_integrand;

static double albedo_term(double mu, void *context)
{
    const albedo_integrand *integrand = context;
    return 2.0 * mu * integrand->g(mu);
}

/* int_0^1 2 mu g(mu) dmu by one 20-point Gauss-Legendre panel (stats.h): exact for polynomials up
 * to degree 39, and the integrands here are polynomials of degree 7 at most. */
static double hemisphere_albedo(double (*g)(double))
{
    albedo_integrand integrand = {g};
    return stats_gl_panel(albedo_term, &integrand, 0.0, 1.0);
}

static double exit_of_mu(double mu)
{
    return dwvb_principled_exit_factor(mu);
}

static double planted_exit_of_mu(double mu)
{
    return 1.0 - 0.5 * pow(1.0 - mu, 4.0);
}

static void test_schlick_and_exit(void)
{
    double worst = 0.0;
    for (int i = 0; i <= 1000; ++i) {
        double c = i / 1000.0;
        worst = fmax(worst, fabs(dwvb_schlick_weight(c) - pow(1.0 - c, 5.0)));
        worst = fmax(worst, fabs(dwvb_principled_exit_factor(c) - (1.0 - 0.5 * pow(1.0 - c, 5.0))));
    }
    CHECK(worst < 1e-15, "Schlick weight and exit factor against pow(): off by %.3g", worst);
    CHECK(dwvb_schlick_weight(-0.5) == 1.0 && dwvb_schlick_weight(1.5) == 0.0, "cosines clamped to [0, 1]");
    CHECK(dwvb_principled_exit_factor(1.0) == 1.0 && dwvb_principled_exit_factor(0.0) == 0.5,
          "exit factor 1 at normal, 1/2 at grazing incidence");
    double albedo = hemisphere_albedo(exit_of_mu);
    printf("exit BSDF albedo %.17g, closed form 1 - 1/42 = %.17g\n", albedo, EXIT_ALBEDO);
    CHECK(fabs(albedo - EXIT_ALBEDO) < 1e-13, "exit BSDF albedo %.17g, want 1 - 1/42", albedo);
    double planted = hemisphere_albedo(planted_exit_of_mu);
    CHECK(fabs(planted - EXIT_ALBEDO) > 1e-3, "planted exponent 4 is caught (albedo %.6f)", planted);
}

static void test_retro_reflection(void)
{
    uint64_t state = 12345u;
    double worst = 0.0;
    for (int i = 0; i < 100000; ++i) {
        dwvu_vec3 l = upper(brute_uniform(&state), brute_uniform(&state)), v = upper(brute_uniform(&state), brute_uniform(&state));
        double roughness = brute_uniform(&state);
        /* The half-vector form: R_R = 2 roughness cos^2 theta_d, theta_d between L and H. */
        dwvu_vec3 h = dwvu_add(l, v);
        double len = sqrt(dwvu_dot(h, h));
        double cos_d = dwvu_dot(l, h) / len;
        double rr = 2.0 * roughness * cos_d * cos_d;
        double fl = pow(1.0 - l.z, 5.0), fv = pow(1.0 - v.z, 5.0);
        double want = rr * (fl + fv + fl * fv * (rr - 1.0));
        double got = dwvb_principled_retro_factor(l.z, v.z, dwvu_dot(l, v), roughness);
        worst = fmax(worst, fabs(got - want));
    }
    CHECK(worst < 1e-13, "retro-reflection factor against the half-vector form: off by %.3g", worst);
    /* Normal light and view: no Fresnel weights, no retro-reflection. Grazing light, normal view:
     * F_L = 1, F_V = 0, L.V = 0, so R_R = roughness and the factor is the roughness. */
    CHECK(dwvb_principled_retro_factor(1.0, 1.0, 1.0, 0.7) == 0.0, "0 at normal incidence");
    CHECK(fabs(dwvb_principled_retro_factor(0.0, 1.0, 0.0, 0.3) - 0.3) < 1e-15, "roughness at grazing light");
    CHECK(dwvb_principled_retro_factor(0.2, 0.4, 0.1, 0.0) == 0.0, "0 for roughness 0");
}

/* The diffuse lobe without subsurface at normal view (F_V = 0, L.V = mu), roughness 1/2. */
static double full_diffuse_of_mu(double mu)
{
    return dwvb_principled_diffuse_factor(mu, 1.0, mu, 0.5);
}

/* Principled v1 without subsurface: (1 - F_L/2)(1 - F_V/2) + retro against pow(), its albedo at
 * normal view against the closed form, and which materials get it. */
static void test_principled_diffuse(void)
{
    uint64_t state = 777u;
    double worst = 0.0;
    for (int i = 0; i < 10000; ++i) {
        dwvu_vec3 l = upper(brute_uniform(&state), brute_uniform(&state)), v = upper(brute_uniform(&state), brute_uniform(&state));
        double roughness = brute_uniform(&state);
        double fl = pow(1.0 - l.z, 5.0), fv = pow(1.0 - v.z, 5.0);
        double want = (1.0 - 0.5 * fl) * (1.0 - 0.5 * fv) +
                      dwvb_principled_retro_factor(l.z, v.z, dwvu_dot(l, v), roughness);
        worst = fmax(worst, fabs(dwvb_principled_diffuse_factor(l.z, v.z, dwvu_dot(l, v), roughness) - want));
    }
    CHECK(worst < 1e-13, "Principled diffuse factor against pow(): off by %.3g", worst);
    /* At normal view: 2 int mu ((1 - (1 - mu)^5 / 2) + r (1 + mu)(1 - mu)^5) dmu
     * = 1 - 1/42 + 2 r (B(2, 6) + B(3, 6)) = 41/42 + 2 r (1/42 + 1/168) = 41/42 + 5 r / 84. */
    double albedo = hemisphere_albedo(full_diffuse_of_mu), want = 41.0 / 42.0 + 5.0 * 0.5 / 84.0;
    CHECK(fabs(albedo - want) < 1e-13, "Principled diffuse albedo at normal view %.17g, want %.17g", albedo, want);

    dwv_material_t in = DWV_MATERIAL_INIT;
    dwvb_material out;
    in.subsurface_exit = DWV_SUBSURFACE_EXIT_PRINCIPLED_V1;
    in.roughness = 0.25;
    in.kind = DWV_MATERIAL_DIFFUSE;
    dwvb_material_init(&out, &in);
    CHECK(out.principled_diffuse && !out.subsurface && out.roughness == 0.25, "diffuse kind, Principled v1");
    in.kind = DWV_MATERIAL_SUBSURFACE;
    in.subsurface_weight = 0.0;
    dwvb_material_init(&out, &in);
    CHECK(out.principled_diffuse && !out.subsurface, "subsurface weight 0, Principled v1");
    in.subsurface_weight = 1.0;
    dwvb_material_init(&out, &in);
    CHECK(!out.principled_diffuse && out.principled_v1 && out.subsurface, "a walking Principled v1 material");
    in.subsurface_exit = DWV_SUBSURFACE_EXIT_LAMBERT;
    in.kind = DWV_MATERIAL_DIFFUSE;
    dwvb_material_init(&out, &in);
    CHECK(!out.principled_diffuse && !out.principled_v1, "a Lambert-exit diffuse material stays Lambertian");
}

typedef struct fixed_normal {
    dwvu_vec3 n;
} fixed_normal;

static double exit_lobe(const void *context, dwvu_vec3 light)
{
    const fixed_normal *f = context;
    return dwvb_principled_exit_factor(dwvu_dot(f->n, light));
}

static void test_direct_lobe(void)
{
    dwv_light_desc_t desc = DWV_LIGHT_DESC_INIT;
    desc.direction[0] = 0.6;
    desc.direction[1] = 0.0;
    desc.direction[2] = -0.8; /* light travels down and along +x: toward the sun is (-0.6, 0, 0.8) */
    desc.strength = 3.0;
    dwvl_light sun;
    dwvl_light_init(&sun, &desc);
    dwvl_environment env = {&sun, 1u, {0.0, 0.0, 0.0}, 0, NULL, NULL};
    dwvu_vec3 x = dwvu_v(0.0, 0.0, 0.0), n = dwvu_v(0.0, 0.0, 1.0);
    fixed_normal normal = {n};
    double plain[3], lambert[3], lobe[3];
    dwvk_sampler sampler = {.key = 99u, .index = 0u, .stratified = 0};
    dwvl_direct(&env, x, n, n, NULL, INFINITY, &sampler, 0u, plain);
    dwvl_direct_lobe(&env, x, n, n, NULL, INFINITY, &sampler, 0u, exit_lobe, &normal, lambert, lobe);
    double f = dwvb_principled_exit_factor(0.8);
    for (int c = 0; c < 3; ++c) {
        CHECK(plain[c] > 0.0 && lambert[c] == plain[c], "channel %d: Lambertian part %g equals dwvl_direct's %g", c,
              lambert[c], plain[c]);
        CHECK(fabs(lobe[c] - f * plain[c]) <= 1e-15 * plain[c], "channel %d: lobe %g is %g x %g", c, lobe[c], f,
              plain[c]);
    }
    CHECK(fabs(plain[0] - 3.0 * 0.8 / 3.141592653589793) < 1e-12, "sun of irradiance 3 at cos 0.8: %g", plain[0]);
}

int main(void)
{
    test_schlick_and_exit();
    test_retro_reflection();
    test_principled_diffuse();
    test_direct_lobe();
    return check_report("test_principled_v1");
}
