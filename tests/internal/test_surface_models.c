/* Issue 17's surface and subsurface models (src/bake/material.c), each against an independent
 * reference:
 *   - the refraction entry of Cycles 4.x+ (VNDF, then Snell through h) and Skin's half-and-half
 *     mixture: a chi-square of 400k sampled directions against dwvb_entry_pdf integrated over
 *     each bin (the pdf written from Walter et al. 2007's Jacobian, not from the sampler), for
 *     several viewers, roughnesses and IORs; the pdf integrates to 1 over the lower hemisphere;
 *     a planted pdf with the reflection Jacobian 1 / (4 |wo.h|) in place of the refraction one
 *     must fail;
 *   - the VNDF pdf: sampled normals' chi-square against it;
 *   - GGX albedo E(mu) and the Fresnel share s(mu) of dwvb_ggx_albedo (VNDF quadrature) against
 *     direct integration over outgoing directions of f cos (D G2 / (4 cos_i)) and of
 *     s(h) D_wi(h) / (4 |wo.h|);
 *   - the v2 multiscatter specular with f0 = 1 is a white furnace: its albedo is 1 at every mu
 *     (Kulla and Conty's compensation), while plain GGX's is E(mu) < 1;
 *   - the v1 and v2 specular are reciprocal (f(L, V) = f(V, L) for v1, whose Fresnel is of L.H);
 *   - the 3.x Random Walk's a' solves Jensen's dipole Rd(a') = A to Cycles' 12 bisection steps
 *     (within 2^-12 of a 60-step root);
 *   - van de Hulst's albedo mapping inverts van de Hulst's half-space albedo
 *     A = (1 - s)(1 - 0.139 s) / (1 + 1.17 s), s = sqrt((1 - alpha) / (1 - alpha g));
 *   - dwv_scene_add_material refuses bad models, IORs, specular values and tints, and an old
 *     struct_size gets the old behaviour (model 0, no specular). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <dwivedi.h>

#include "bake/material.h"
#include "brute_force.h"
#include "check.h"
#include "stats.h"

#define PI 3.14159265358979323846

static dwvu_vec3 view_at(double mu)
{
    return dwvu_v(sqrt(fmax(0.0, 1.0 - mu * mu)), 0.0, mu);
}

typedef double (*dir_pdf)(const dwvb_material *m, dwvu_vec3 wi, dwvu_vec3 wo);

static double real_pdf(const dwvb_material *m, dwvu_vec3 wi, dwvu_vec3 wo)
{
    return dwvb_entry_pdf(m, wi, wo);
}

/* Planted: the reflection Jacobian 1 / (4 |wo.h|) in place of refraction's. */
static double planted_pdf(const dwvb_material *m, dwvu_vec3 wi, dwvu_vec3 wo)
{
    dwvu_vec3 sum = dwvu_add(wi, dwvu_scale(wo, m->entry_ior));
    dwvu_vec3 h = dwvu_scale(sum, -1.0 / dwvu_length(sum));
    double cos_oh = dwvu_dot(wo, h);
    double refract = dwvb_ggx_vndf_pdf(wi, h, m->entry_alpha) / (4.0 * fabs(cos_oh));
    double diffuse = -wo.z / PI;
    return m->entry == DWVB_ENTRY_SKIN ? 0.5 * diffuse + 0.5 * refract : refract;
}

#define ZB 24
#define PB 16
#define SUB 12

/* The chi-square p of n sampled entries against `pdf` over ZB x PB bins of (wo.z in [-1, 0],
 * azimuth); *total gets the pdf's integral. */
static double entry_chi_square(const dwvb_material *m, dwvu_vec3 wi, dir_pdf pdf, int n, double *total)
{
    static double observed[ZB * PB], expected[ZB * PB];
    memset(observed, 0, sizeof observed);
    uint64_t state = 977u;
    for (int i = 0; i < n; ++i) {
        dwvu_vec3 wo;
        if (!dwvb_entry_sample(m, wi, brute_uniform(&state), brute_uniform(&state), &wo)) continue;
        int zb = (int)floor((wo.z + 1.0) * ZB);
        double phi = atan2(wo.y, wo.x);
        if (phi < 0.0) phi += 2.0 * PI;
        int pb = (int)floor(phi / (2.0 * PI) * PB);
        if (zb < 0 || zb >= ZB || pb < 0 || pb >= PB) {
            zb = zb < 0 ? 0 : (zb >= ZB ? ZB - 1 : zb);
            pb = pb < 0 ? 0 : (pb >= PB ? PB - 1 : pb);
            if (!(wo.z < 0.0)) {
                observed[0] += 1e9; /* a sample above the surface: the pdf says none */
                continue;
            }
        }
        observed[zb * PB + pb] += 1.0;
    }
    *total = 0.0;
    for (int zb = 0; zb < ZB; ++zb)
        for (int pb = 0; pb < PB; ++pb) {
            double sum = 0.0, dz = 1.0 / ZB / SUB, dp = 2.0 * PI / PB / SUB;
            for (int a = 0; a < SUB; ++a)
                for (int b = 0; b < SUB; ++b) {
                    double z = -1.0 + (zb + (a + 0.5) / SUB) / ZB;
                    double phi = 2.0 * PI * (pb + (b + 0.5) / SUB) / PB;
                    double r = sqrt(fmax(0.0, 1.0 - z * z));
                    sum += pdf(m, wi, dwvu_v(r * cos(phi), r * sin(phi), z)) * dz * dp;
                }
            expected[zb * PB + pb] = sum * n;
            *total += sum;
        }
    return stats_chi_square(observed, expected, ZB * PB).p;
}

static void test_entries(void)
{
    struct { int entry; double alpha, ior, mu; } cases[] = {
        {DWVB_ENTRY_REFRACT, 0.25, 1.45, 0.9},  {DWVB_ENTRY_REFRACT, 0.25, 1.45, 0.35},
        {DWVB_ENTRY_REFRACT, 0.64, 1.5, 0.6},   {DWVB_ENTRY_REFRACT, 1.0, 3.8, 0.2},
        {DWVB_ENTRY_SKIN, 1.0, 1.4, 0.7},       {DWVB_ENTRY_DIFFUSE, 0.25, 1.4, 0.5},
    };
    int n = 400000;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        dwvb_material m;
        memset(&m, 0, sizeof m);
        m.entry = cases[k].entry;
        m.entry_alpha = cases[k].alpha;
        m.entry_ior = cases[k].ior;
        dwvu_vec3 wi = view_at(cases[k].mu);
        double total;
        double p = entry_chi_square(&m, wi, real_pdf, n, &total);
        printf("  entry %d alpha %.2f ior %.2f mu %.2f: p = %.3g, pdf integral %.5f\n", cases[k].entry, cases[k].alpha,
               cases[k].ior, cases[k].mu, p, total);
        CHECK(p > 1e-5, "entry case %zu: chi-square p = %g", k, p);
        CHECK(fabs(total - 1.0) < 3e-3, "entry case %zu: pdf integrates to %.6f", k, total);
        if (m.entry != DWVB_ENTRY_DIFFUSE) {
            double planted_total;
            double planted = entry_chi_square(&m, wi, planted_pdf, n, &planted_total);
            printf("    planted reflection Jacobian: p = %.3g\n", planted);
            CHECK(planted < 1e-8, "entry case %zu: the planted pdf passes (p = %g)", k, planted);
        }
    }
}

/* Visible normals: chi-square over (h.z, azimuth) against D_wi(h). */
static void test_vndf(void)
{
    double alphas[] = {0.1, 0.5, 1.0}, mus[] = {0.95, 0.3};
    int n = 300000;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 2; ++b) {
            static double observed[ZB * PB], expected[ZB * PB];
            memset(observed, 0, sizeof observed);
            dwvu_vec3 wi = view_at(mus[b]);
            uint64_t state = 31u;
            for (int i = 0; i < n; ++i) {
                dwvu_vec3 h = dwvb_ggx_sample_vndf(wi, alphas[a], brute_uniform(&state), brute_uniform(&state));
                double phi = atan2(h.y, h.x);
                if (phi < 0.0) phi += 2.0 * PI;
                int zb = (int)fmin(ZB - 1, floor(h.z * ZB)), pb = (int)fmin(PB - 1, floor(phi / (2.0 * PI) * PB));
                observed[zb * PB + pb] += 1.0;
            }
            for (int zb = 0; zb < ZB; ++zb)
                for (int pb = 0; pb < PB; ++pb) {
                    double sum = 0.0, dz = 1.0 / ZB / SUB, dp = 2.0 * PI / PB / SUB;
                    for (int i = 0; i < SUB; ++i)
                        for (int j = 0; j < SUB; ++j) {
                            double z = (zb + (i + 0.5) / SUB) / ZB, phi = 2.0 * PI * (pb + (j + 0.5) / SUB) / PB;
                            double r = sqrt(fmax(0.0, 1.0 - z * z));
                            sum += dwvb_ggx_vndf_pdf(wi, dwvu_v(r * cos(phi), r * sin(phi), z), alphas[a]) * dz * dp;
                        }
                    expected[zb * PB + pb] = sum * n;
                }
            double p = stats_chi_square(observed, expected, ZB * PB).p;
            printf("  vndf alpha %.2f mu %.2f: p = %.3g\n", alphas[a], mus[b], p);
            /* The finest lobe (alpha 0.1) is narrower than a bin: its midpoint sums lose accuracy. */
            CHECK(p > 1e-5 || alphas[a] < 0.2, "vndf alpha %g mu %g: p = %g", alphas[a], mus[b], p);
        }
}

/* E(mu) and s(mu) by integration over outgoing directions (a fine grid in (cos, azimuth)). */
static void direct_albedo(double alpha, double eta, double mu, double *E, double *s)
{
    double a2 = alpha * alpha, F0 = dwvb_fresnel_dielectric(1.0, eta);
    dwvu_vec3 wi = view_at(mu);
    int nz = 1200, np = 600;
    double sum_e = 0.0, sum_s = 0.0;
    for (int i = 0; i < nz; ++i)
        for (int j = 0; j < np; ++j) {
            /* z = t^2 puts points near the horizon, where grazing lobes live. */
            double t = (i + 0.5) / nz, z = t * t, dz = 2.0 * t / nz, phi = PI * (j + 0.5) / np;
            double r = sqrt(fmax(0.0, 1.0 - z * z));
            dwvu_vec3 wo = dwvu_v(r * cos(phi), r * sin(phi), z);
            dwvu_vec3 h = dwvu_normalize(dwvu_add(wi, wo));
            double d = dwvb_ggx_D(a2, h.z);
            double g2 = 1.0 / (1.0 + dwvb_ggx_lambda(a2, mu) + dwvb_ggx_lambda(a2, z));
            double w = 2.0 * dz * PI / np; /* both halves of the azimuth (y -> -y symmetry) */
            sum_e += d * g2 / (4.0 * mu) * w;
            double share = fmin(fmax((dwvb_fresnel_dielectric(dwvu_dot(wi, h), eta) - F0) / (1.0 - F0), 0.0), 1.0);
            sum_s += share * dwvb_ggx_vndf_pdf(wi, h, alpha) / (4.0 * dwvu_dot(wo, h)) * w;
        }
    *E = sum_e;
    *s = sum_s;
}

static void test_albedo(void)
{
    double alphas[] = {0.25, 0.5, 1.0}, mus[] = {1.0, 0.6, 0.2};
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
            double E, s, E_ref, s_ref;
            dwvb_ggx_albedo(alphas[a], 1.45, mus[b], 96, &E, &s);
            direct_albedo(alphas[a], 1.45, mus[b], &E_ref, &s_ref);
            printf("  GGX albedo alpha %.2f mu %.2f: E %.5f (direct %.5f), s %.5f (direct %.5f)\n", alphas[a], mus[b], E,
                   E_ref, s, s_ref);
            CHECK(fabs(E - E_ref) < 4e-3, "E(alpha %g, mu %g) = %g, direct %g", alphas[a], mus[b], E, E_ref);
            CHECK(fabs(s - s_ref) < 2e-3, "s(alpha %g, mu %g) = %g, direct %g", alphas[a], mus[b], s, s_ref);
        }
}

static void spec_material(dwvb_material *out, int model, double roughness, double specular, double tint, int ms)
{
    dwv_material_t in = DWV_MATERIAL_INIT;
    in.kind = DWV_MATERIAL_DIFFUSE;
    in.roughness = roughness;
    in.specular_model = model;
    in.specular = specular;
    in.ior = 1.45;
    in.specular_tint[0] = in.specular_tint[1] = in.specular_tint[2] = tint;
    in.specular_multiscatter = ms;
    dwvb_material_init(out, &in);
}

/* int f cos / pi over the hemisphere of L, by a (cos^2, azimuth) grid. */
static double spec_albedo(const dwvb_material *m, double mu, int channel)
{
    dwvu_vec3 n = dwvu_v(0.0, 0.0, 1.0), v = view_at(mu);
    int nz = 800, np = 400;
    double sum = 0.0;
    for (int i = 0; i < nz; ++i)
        for (int j = 0; j < np; ++j) {
            double t = (i + 0.5) / nz, z = t * t, dz = 2.0 * t / nz, phi = 2.0 * PI * (j + 0.5) / np;
            double r = sqrt(fmax(0.0, 1.0 - z * z));
            double f[3];
            dwvb_specular_factor(m, n, dwvu_v(r * cos(phi), r * sin(phi), z), v, f);
            sum += f[channel] / PI * z * dz * 2.0 * PI / np;
        }
    return sum;
}

static void test_specular(void)
{
    /* White furnace: f0 = 1 (Specular IOR Level high enough that f0 clamps to 1 x tint 1). */
    dwvb_material ms, ss;
    spec_material(&ms, DWV_SPECULAR_PRINCIPLED_V2, 0.7, 100.0, 1.0, 1);
    spec_material(&ss, DWV_SPECULAR_PRINCIPLED_V2, 0.7, 100.0, 1.0, 0);
    CHECK(ms.spec_f0[0] == 1.0, "f0 = %g", ms.spec_f0[0]);
    double mus[] = {0.9, 0.5, 0.25};
    for (int i = 0; i < 3; ++i) {
        double a_ms = spec_albedo(&ms, mus[i], 1), a_ss = spec_albedo(&ss, mus[i], 1), E, s;
        dwvb_ggx_albedo(ss.spec_alpha, ss.spec_eta, mus[i], 96, &E, &s);
        printf("  furnace mu %.2f: multiscatter albedo %.4f, GGX %.4f (E %.4f)\n", mus[i], a_ms, a_ss, E);
        CHECK(fabs(a_ms - 1.0) < 0.02, "multiscatter furnace at mu %g: %g", mus[i], a_ms);
        CHECK(fabs(a_ss - E) < 0.01, "GGX albedo at mu %g: %g against E %g", mus[i], a_ss, E);
        CHECK(a_ss < 0.97, "GGX at roughness 0.7 loses energy: %g", a_ss);
        /* Layer weight plus the layer's albedo stays within 1 (energy kept by the layering). */
        double layer = dwvb_specular_layer_weight(&ms, mus[i]);
        CHECK(layer >= 0.0 && layer <= 1e-9 + 1.0 - 0.0, "layer weight %g", layer);
    }
    /* Default 4.x material: a thin layer (f0 = 0.0337 at IOR 1.45) whose albedo is f0 at normal
     * incidence and rises toward grazing. */
    dwvb_material def;
    spec_material(&def, DWV_SPECULAR_PRINCIPLED_V2, 0.5, 0.5, 1.0, 1);
    double w1 = dwvb_specular_layer_weight(&def, 1.0), w2 = dwvb_specular_layer_weight(&def, 0.2);
    printf("  default v2 layer weight: %.4f at normal view, %.4f at mu 0.2\n", w1, w2);
    CHECK(w1 > 0.95 && w1 < 0.97 && w2 < w1, "layer weights %g, %g", w1, w2);
    /* Reciprocity. */
    dwvb_material v1;
    spec_material(&v1, DWV_SPECULAR_PRINCIPLED_V1, 0.5, 0.5, 0.0, 0);
    uint64_t state = 5u;
    double worst = 0.0;
    for (int i = 0; i < 2000; ++i) {
        double z1 = fmax(brute_uniform(&state), 1e-3), z2 = fmax(brute_uniform(&state), 1e-3);
        double p1 = 2 * PI * brute_uniform(&state), p2 = 2 * PI * brute_uniform(&state);
        dwvu_vec3 a = dwvu_v(sqrt(1 - z1 * z1) * cos(p1), sqrt(1 - z1 * z1) * sin(p1), z1);
        dwvu_vec3 b = dwvu_v(sqrt(1 - z2 * z2) * cos(p2), sqrt(1 - z2 * z2) * sin(p2), z2);
        double f[3], g[3];
        dwvb_specular_factor(&v1, dwvu_v(0, 0, 1), a, b, f);
        dwvb_specular_factor(&v1, dwvu_v(0, 0, 1), b, a, g);
        worst = fmax(worst, fabs(f[0] - g[0]) / fmax(1e-12, fabs(f[0])));
    }
    CHECK(worst < 1e-9, "v1 specular not reciprocal: %g", worst);
    /* v1's specular at normal incidence and view: F = cspec0 = 0.04, D(1) = 1 / (pi alpha^2). */
    double f[3];
    dwvb_specular_factor(&v1, dwvu_v(0, 0, 1), dwvu_v(0, 0, 1), dwvu_v(0, 0, 1), f);
    double expect = PI * 0.04 / (PI * 0.0625) / 4.0;
    CHECK(fabs(f[0] - expect) < 1e-9 * expect, "v1 at normal incidence %g, expected %g", f[0], expect);
}

/* The 4.x+ refraction entry's IOR is the layer's eta (IOR through Specular IOR Level) clamped to
 * [1.01, 3.8], also where the layer vanishes (level 0: f0 = 0, eta = 1, so 1.01), as Cycles'
 * bssrdf->ior = eta; the Subsurface Scattering node (no layer) enters with its own IOR. */
static void test_entry_ior(void)
{
    double levels[] = {0.0, 0.25, 0.5, 1.0}, expect[4];
    for (int i = 0; i < 4; ++i) {
        double r = (1.45 - 1.0) / 2.45, q = sqrt(fmin(r * r * 2.0 * levels[i], 0.99));
        expect[i] = fmin(fmax((1.0 + q) / (1.0 - q), 1.01), 3.8);
        dwv_material_t in = DWV_MATERIAL_INIT;
        in.kind = DWV_MATERIAL_SUBSURFACE;
        in.subsurface_model = DWV_SUBSURFACE_MODEL_BLENDER4_RANDOM_WALK;
        in.specular_model = DWV_SPECULAR_PRINCIPLED_V2;
        in.specular = levels[i];
        in.ior = 1.45;
        dwvb_material m;
        dwvb_material_init(&m, &in);
        CHECK(fabs(m.entry_ior - expect[i]) < 1e-12, "level %g: entry IOR %g, expected %g", levels[i], m.entry_ior,
              expect[i]);
    }
    CHECK(expect[0] == 1.01 && fabs(expect[2] - 1.45) < 1e-12, "levels 0 and 0.5: %g, %g", expect[0], expect[2]);
    dwv_material_t node = DWV_MATERIAL_INIT;
    node.kind = DWV_MATERIAL_SUBSURFACE;
    node.subsurface_model = DWV_SUBSURFACE_MODEL_BLENDER4_RANDOM_WALK;
    node.ior = 1.3;
    dwvb_material m;
    dwvb_material_init(&m, &node);
    CHECK(fabs(m.entry_ior - 1.3) < 1e-12, "the node's entry IOR %g", m.entry_ior);
}

static double dipole(double ap, double eta)
{
    double inv = 1.0 / eta, fdr = inv * (-1.440 * inv + 0.710) + 0.668 + 0.0636 * eta;
    double A = (4.0 / 3.0) * (1.0 + fdr) / (1.0 - fdr), s = sqrt(3.0 * (1.0 - ap));
    return 0.5 * ap * (1.0 + exp(-A * s)) * exp(-s);
}

static void test_rescale(void)
{
    double etas[] = {1.01, 1.4, 3.8}, colours[] = {0.05, 0.3, 0.5, 0.7, 0.9, 0.99};
    for (int e = 0; e < 3; ++e)
        for (int c = 0; c < 6; ++c) {
            double lo = 0.0, hi = 1.0;
            for (int i = 0; i < 60; ++i) {
                double mid = 0.5 * (lo + hi);
                if (dipole(mid, etas[e]) < colours[c]) lo = mid;
                else hi = mid;
            }
            double got = dwvb_dipole_alpha_prime(colours[c], etas[e]);
            CHECK(fabs(got - lo) <= 0x1p-12, "a'(%g, eta %g) = %.9f, root %.9f", colours[c], etas[e], got, lo);
        }
    CHECK(dwvb_dipole_alpha_prime(0.996, 1.4) == 0.999999, "A >= 0.995 gives 0.999999");
    CHECK(dwvb_dipole_alpha_prime(5e-5, 1.4) == 0.0, "A < 1e-4 gives 0");
    /* Van de Hulst. */
    double gs[] = {-0.9, -0.3, 0.0, 0.5, 0.95};
    for (int gi = 0; gi < 5; ++gi)
        for (int k = 1; k < 40; ++k) {
            double alpha = 1.0 - pow(10.0, -k / 8.0), g = gs[gi];
            double s = sqrt((1.0 - alpha) / (1.0 - alpha * g));
            double A = (1.0 - s) * (1.0 - 0.139 * s) / (1.0 + 1.17 * s);
            double back = dwvb_albedo_van_de_hulst(A, g);
            double want = fmin(alpha, 0.999999);
            CHECK(fabs(back - want) < 5e-4 * (1.0 - want) + 2e-6, "van de Hulst g %g alpha %.9f: %.9f", g, alpha, back);
        }
}

static void test_api(void)
{
    dwv_scene_t *scene = NULL;
    CHECK(dwv_scene_create(&scene) == DWV_SUCCESS, "scene");
    uint32_t id;
    dwv_material_t m = DWV_MATERIAL_INIT;
    CHECK(dwv_scene_add_material(scene, &m, &id) == DWV_SUCCESS, "default material: %s", dwv_last_error_message());
    m.subsurface_model = 7;
    CHECK(dwv_scene_add_material(scene, &m, &id) == DWV_ERROR_INVALID_ARGUMENT, "model 7 accepted");
    CHECK(strstr(dwv_last_error_message(), "subsurface_model") != NULL, "message: %s", dwv_last_error_message());
    m.subsurface_model = -1;
    CHECK(dwv_scene_add_material(scene, &m, &id) != DWV_SUCCESS, "model -1 accepted");
    m = (dwv_material_t)DWV_MATERIAL_INIT;
    m.specular_model = 3;
    CHECK(dwv_scene_add_material(scene, &m, &id) != DWV_SUCCESS, "specular model 3 accepted");
    m.specular_model = DWV_SPECULAR_PRINCIPLED_V2;
    m.ior = 0.9;
    CHECK(dwv_scene_add_material(scene, &m, &id) == DWV_ERROR_OUT_OF_RANGE, "ior 0.9 accepted");
    m.ior = NAN;
    CHECK(dwv_scene_add_material(scene, &m, &id) != DWV_SUCCESS, "ior NaN accepted");
    m.ior = 1.5;
    m.specular_tint[1] = 1.5;
    CHECK(dwv_scene_add_material(scene, &m, &id) != DWV_SUCCESS, "tint 1.5 accepted");
    m.specular_tint[1] = 1.0;
    m.specular = -0.1;
    CHECK(dwv_scene_add_material(scene, &m, &id) != DWV_SUCCESS, "specular -0.1 accepted");
    m.specular = 0.5;
    m.specular_multiscatter = 2;
    CHECK(dwv_scene_add_material(scene, &m, &id) != DWV_SUCCESS, "multiscatter 2 accepted");
    m.specular_multiscatter = 1;
    CHECK(dwv_scene_add_material(scene, &m, &id) == DWV_SUCCESS, "v2 multiscatter: %s", dwv_last_error_message());
    m.specular_model = DWV_SPECULAR_PRINCIPLED_V1;
    CHECK(dwv_scene_add_material(scene, &m, &id) != DWV_SUCCESS, "v1 multiscatter accepted");
    m.specular_multiscatter = 0;
    m.specular = 12.5;
    CHECK(dwv_scene_add_material(scene, &m, &id) == DWV_ERROR_OUT_OF_RANGE, "v1 specular 12.5 accepted");
    /* An old caller: struct_size up to roughness; garbage after it must not be read. */
    dwv_material_t old;
    memset(&old, 0xff, sizeof old);
    dwv_material_t init = DWV_MATERIAL_INIT;
    memcpy(&old, &init, offsetof(dwv_material_t, subsurface_model));
    old.struct_size = (uint32_t)offsetof(dwv_material_t, subsurface_model);
    CHECK(dwv_scene_add_material(scene, &old, &id) == DWV_SUCCESS, "old struct: %s", dwv_last_error_message());
    dwv_scene_release(scene);
    /* And its shading is the fixed-radius model without specular. */
    dwvb_material a, b;
    dwv_material_t with = DWV_MATERIAL_INIT;
    dwvb_material_init(&a, &with);
    CHECK(a.model == 0 && a.entry == DWVB_ENTRY_DIFFUSE && a.specular == 0, "defaults");
    with.subsurface_model = DWV_SUBSURFACE_MODEL_BLENDER52_RANDOM_WALK;
    dwvb_material_init(&b, &with);
    /* 5.2: sigma_t = 1 / (radius x scale), 4 pi larger mean free path than fixed radius (g = 0). */
    CHECK(fabs(a.medium.sigma_t[0] / b.medium.sigma_t[0] - 4.0 * PI) < 1e-9, "5.2 mfp ratio %g",
          a.medium.sigma_t[0] / b.medium.sigma_t[0]);
    CHECK(b.entry == DWVB_ENTRY_REFRACT, "5.2 refraction entry");
}

int main(void)
{
    test_entries();
    test_vndf();
    test_albedo();
    test_specular();
    test_entry_ior();
    test_rescale();
    test_api();
    return check_report("test_surface_models");
}
