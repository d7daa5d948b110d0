#include "material.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define FOUR_PI 12.566370614359172954
#define PI 3.14159265358979323846

static dwvu_vec3 cross3(dwvu_vec3 a, dwvu_vec3 b)
{
    return dwvu_v(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

/* Linear interpolation of a table over mu in [0, 1] (DWVB_SPEC_MU points). */
static double spec_table(const double *t, double mu)
{
    double x = fmin(fmax(mu, 0.0), 1.0) * (DWVB_SPEC_MU - 1);
    int i = (int)x;
    if (i >= DWVB_SPEC_MU - 1) return t[DWVB_SPEC_MU - 1];
    double f = x - i;
    return t[i] * (1.0 - f) + t[i + 1] * f;
}

/* Horner evaluation of c[0] + c[1] g + ... + c[7] g^7. */
static double poly7(const double c[8], double g)
{
    double r = c[7];
    for (int i = 6; i >= 0; --i) r = r * g + c[i];
    return r;
}

double dwvb_albedo_inversion(double A, double g)
{
    /* The fit of Cycles' subsurface_random_walk_remap (after Chiang, Kutz and Burley 2016,
     * extended to anisotropy), coefficients as Cycles publishes them. */
    static const double cA[8] = {1.8260523782, -1.28451056436, -1.79904629312, 9.19393289202,
                                 -22.8215585862, 32.0234874259, -23.6264803333, 7.21067002658};
    static const double cB[8] = {0.0, 31.1491581433, -201.847017512, 841.576016723,
                                 -2018.09288505, 2731.71560286, -1935.41424244, 559.009054474};
    static const double cC[8] = {1.09686102424, -0.394704063468, 1.05258115941, -8.83963712726,
                                 28.8643230661, -46.8802913581, 38.5402837518, -12.7181042538};
    static const double cD[8] = {0.496310210422, 0.360146581622, -2.15139309747, 17.8896899217,
                                 -55.2984010333, 82.065982243, -58.5106008578, 15.8478295021};
    static const double cE[8] = {0.0, 76.7316253952, -594.356773233, 2448.8834203,
                                 -5576.68528998, 7116.60171912, -4763.54467887, 1303.5318055};
    static const double cF[8] = {2.40602999408, -2.51814844609, 9.18494908356, -79.2191708682,
                                 259.082868209, -403.613804597, 302.85712436, -87.4370473567};
    double a = poly7(cA, g);
    double b = 4.98511194385 + 0.127355959438 * exp(poly7(cB, g));
    double c = poly7(cC, g);
    double d = poly7(cD, g);
    double e = 4.23190299701 + 0.00310603949088 * exp(poly7(cE, g));
    double f = poly7(cF, g);
    double blend = pow(A, 0.25);
    double alpha = (1.0 - blend) * a * pow(atan(b * A), c) + blend * d * pow(atan(e * A), f);
    return fmin(fmax(alpha, 0.0), 0.999999);
}

double dwvb_schlick_weight(double cos_theta)
{
    double m = fmin(fmax(1.0 - cos_theta, 0.0), 1.0);
    double m2 = m * m;
    return m2 * m2 * m;
}

double dwvb_principled_exit_factor(double cos_light)
{
    return 1.0 - 0.5 * dwvb_schlick_weight(cos_light);
}

double dwvb_principled_retro_factor(double cos_light, double cos_view, double light_dot_view, double roughness)
{
    double fl = dwvb_schlick_weight(cos_light), fv = dwvb_schlick_weight(cos_view);
    double rr = roughness * (1.0 + light_dot_view);
    return rr * (fl + fv + fl * fv * (rr - 1.0));
}

double dwvb_principled_diffuse_factor(double cos_light, double cos_view, double light_dot_view, double roughness)
{
    double lambert = (1.0 - 0.5 * dwvb_schlick_weight(cos_light)) * (1.0 - 0.5 * dwvb_schlick_weight(cos_view));
    return lambert + dwvb_principled_retro_factor(cos_light, cos_view, light_dot_view, roughness);
}

double dwvb_fresnel_dielectric(double c, double eta)
{
    c = fabs(c);
    double g = eta * eta - 1.0 + c * c;
    if (!(g > 0.0)) return 1.0; /* total internal reflection */
    g = sqrt(g);
    double a = (g - c) / (g + c);
    double b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    return 0.5 * a * a * (1.0 + b * b);
}

double dwvb_ggx_D(double alpha2, double cos_h)
{
    double c2 = fmin(cos_h * cos_h, 1.0);
    double t = (1.0 - c2) + alpha2 * c2;
    return alpha2 / (PI * t * t);
}

double dwvb_ggx_lambda(double alpha2, double cos_theta)
{
    double c2 = cos_theta * cos_theta;
    double tan2 = fmax((1.0 - c2) / c2, 0.0);
    return 0.5 * (sqrt(1.0 + alpha2 * tan2) - 1.0);
}

dwvu_vec3 dwvb_ggx_sample_vndf(dwvu_vec3 wi, double alpha, double u1, double u2)
{
    /* Stretch to the hemisphere configuration, sample its projected disk, unstretch. */
    dwvu_vec3 vh = dwvu_normalize(dwvu_v(alpha * wi.x, alpha * wi.y, wi.z));
    double lensq = vh.x * vh.x + vh.y * vh.y;
    dwvu_vec3 t1 = lensq > 0.0 ? dwvu_scale(dwvu_v(-vh.y, vh.x, 0.0), 1.0 / sqrt(lensq)) : dwvu_v(1.0, 0.0, 0.0);
    dwvu_vec3 t2 = cross3(vh, t1);
    double r = sqrt(u1), phi = 2.0 * PI * u2;
    double p1 = r * cos(phi), p2 = r * sin(phi);
    double sh = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - sh) * sqrt(fmax(0.0, 1.0 - p1 * p1)) + sh * p2;
    double pz = sqrt(fmax(0.0, 1.0 - p1 * p1 - p2 * p2));
    dwvu_vec3 nh = dwvu_add(dwvu_add(dwvu_scale(t1, p1), dwvu_scale(t2, p2)), dwvu_scale(vh, pz));
    return dwvu_normalize(dwvu_v(alpha * nh.x, alpha * nh.y, fmax(1e-12, nh.z)));
}

double dwvb_ggx_vndf_pdf(dwvu_vec3 wi, dwvu_vec3 h, double alpha)
{
    double cos_ih = dwvu_dot(wi, h);
    if (!(wi.z > 0.0) || !(h.z > 0.0) || !(cos_ih > 0.0)) return 0.0;
    double a2 = alpha * alpha;
    double g1 = 1.0 / (1.0 + dwvb_ggx_lambda(a2, wi.z));
    return g1 * cos_ih * dwvb_ggx_D(a2, h.z) / wi.z;
}

int dwvb_entry_refract_sample(dwvu_vec3 wi, double alpha, double ior, double u1, double u2, dwvu_vec3 *wo)
{
    if (!(wi.z > 0.0)) return 0;
    dwvu_vec3 h = dwvb_ggx_sample_vndf(wi, alpha, u1, u2);
    double neta = 1.0 / ior, cos_hi = dwvu_dot(h, wi);
    /* Snell through h: wo = -neta wi + (neta cos_hi - cos_t) h, cos_t = sqrt(1 - neta^2 sin_i^2). */
    double arg = 1.0 - neta * neta * (1.0 - cos_hi * cos_hi);
    double cos_t = sqrt(fmax(arg, 1e-14));
    *wo = dwvu_normalize(dwvu_add(dwvu_scale(wi, -neta), dwvu_scale(h, neta * cos_hi - cos_t)));
    return 1;
}

double dwvb_entry_refract_pdf(dwvu_vec3 wi, dwvu_vec3 wo, double alpha, double ior)
{
    if (!(wi.z > 0.0) || !(wo.z < 0.0)) return 0.0;
    dwvu_vec3 sum = dwvu_add(wi, dwvu_scale(wo, ior));
    double len = dwvu_length(sum);
    if (!(len > 0.0)) return 0.0;
    dwvu_vec3 h = dwvu_scale(sum, -1.0 / len);
    if (!(h.z > 0.0)) return 0.0;
    double cos_oh = dwvu_dot(wo, h), cos_ih = dwvu_dot(wi, h);
    if (!(cos_oh < 0.0) || !(cos_ih > 0.0)) return 0.0;
    double denom = cos_ih + ior * cos_oh;
    return dwvb_ggx_vndf_pdf(wi, h, alpha) * ior * ior * fabs(cos_oh) / (denom * denom);
}

int dwvb_entry_sample(const dwvb_material *m, dwvu_vec3 wi, double u1, double u2, dwvu_vec3 *wo)
{
    if (m->entry == DWVB_ENTRY_SKIN) {
        /* Cycles' Skin: the first number picks the technique and is reused, stretched. */
        if (u1 < 0.5) {
            double mu = sqrt(2.0 * u1), phi = 2.0 * PI * u2, st = sqrt(fmax(0.0, 1.0 - mu * mu));
            *wo = dwvu_v(st * cos(phi), st * sin(phi), -mu);
            return 1;
        }
        u1 = 2.0 * (u1 - 0.5);
    } else if (m->entry == DWVB_ENTRY_DIFFUSE) {
        double mu = sqrt(u1), phi = 2.0 * PI * u2, st = sqrt(fmax(0.0, 1.0 - mu * mu));
        *wo = dwvu_v(st * cos(phi), st * sin(phi), -mu);
        return 1;
    }
    return dwvb_entry_refract_sample(wi, m->entry_alpha, m->entry_ior, u1, u2, wo);
}

double dwvb_entry_pdf(const dwvb_material *m, dwvu_vec3 wi, dwvu_vec3 wo)
{
    double diffuse = wo.z < 0.0 ? -wo.z / PI : 0.0;
    if (m->entry == DWVB_ENTRY_DIFFUSE) return diffuse;
    double refract = dwvb_entry_refract_pdf(wi, wo, m->entry_alpha, m->entry_ior);
    return m->entry == DWVB_ENTRY_SKIN ? 0.5 * diffuse + 0.5 * refract : refract;
}

/* Jensen et al. 2001's dipole diffuse reflectance, as Cycles' bssrdf_dipole_compute_Rd. */
static double dipole_rd(double alpha_prime, double four_thirds_A)
{
    double s = sqrt(3.0 * (1.0 - alpha_prime));
    return 0.5 * alpha_prime * (1.0 + exp(-four_thirds_A * s)) * exp(-s);
}

double dwvb_dipole_alpha_prime(double A, double eta)
{
    /* Fdr: the polynomial fit in 1/eta of Cycles' bssrdf_setup_radius (after Jensen 2001). */
    double inv = 1.0 / eta;
    double fdr = inv * (-1.440 * inv + 0.710) + 0.668 + 0.0636 * eta;
    double four_thirds_A = (4.0 / 3.0) * (1.0 + fdr) / (1.0 - fdr);
    if (A < 1e-4) return 0.0;
    if (A >= 0.995) return 0.999999;
    double x0 = 0.0, x1 = 1.0, mid = 0.5;
    for (int i = 0; i < 12; ++i) {
        mid = 0.5 * (x0 + x1);
        if (dipole_rd(mid, four_thirds_A) < A) x0 = mid;
        else x1 = mid;
    }
    return mid;
}

double dwvb_albedo_van_de_hulst(double A, double g)
{
    double t = 4.20863 * A - sqrt(9.59217 + 41.6808 * A + 17.7126 * A * A) + 4.09712;
    double s2 = t * t;
    double den = 1.0 - g * s2;
    double alpha = den != 0.0 ? (1.0 - s2) / den : 0.0;
    return fmin(fmax(alpha, 0.0), 0.999999);
}

/* F of the v2 layer: f0 + (1 - f0) s, s the real Fresnel curve's share between F0 and 1
 * (Cycles' generalized Schlick with a negative exponent). */
static double v2_share(double cos_hi, double eta, double F0)
{
    double s = (dwvb_fresnel_dielectric(cos_hi, eta) - F0) / (1.0 - F0);
    return fmin(fmax(s, 0.0), 1.0);
}

void dwvb_ggx_albedo_etas(double alpha, const double *etas, int count, double mu, int n, double *E, double *s)
{
    double a2 = alpha * alpha;
    mu = fmin(fmax(mu, 1e-4), 1.0);
    dwvu_vec3 wi = dwvu_v(sqrt(fmax(0.0, 1.0 - mu * mu)), 0.0, mu);
    double F0[DWVB_SPEC_GRID];
    for (int k = 0; k < count; ++k) F0[k] = dwvb_fresnel_dielectric(1.0, etas[k]), s[k] = 0.0;
    double lambda_i = dwvb_ggx_lambda(a2, mu);
    double sum_e = 0.0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            dwvu_vec3 h = dwvb_ggx_sample_vndf(wi, alpha, (i + 0.5) / n, (j + 0.5) / n);
            double c = dwvu_dot(wi, h);
            dwvu_vec3 wo = dwvu_sub(dwvu_scale(h, 2.0 * c), wi);
            if (!(wo.z > 0.0)) continue;
            /* eval / pdf of VNDF sampling: G2 / G1(wi) = (1 + Lambda_i) / (1 + Lambda_i + Lambda_o). */
            sum_e += (1.0 + lambda_i) / (1.0 + lambda_i + dwvb_ggx_lambda(a2, wo.z));
            for (int k = 0; k < count; ++k) s[k] += v2_share(c, etas[k], F0[k]);
        }
    *E = sum_e / ((double)n * n);
    for (int k = 0; k < count; ++k) s[k] /= (double)n * n;
}

void dwvb_ggx_albedo(double alpha, double eta, double mu, int n, double *E, double *s)
{
    dwvb_ggx_albedo_etas(alpha, &eta, 1, mu, n, E, s);
}

void dwvb_specular_factor(const dwvb_material *m, dwvu_vec3 n, dwvu_vec3 L, dwvu_vec3 V, double f[3])
{
    f[0] = f[1] = f[2] = 0.0;
    double a2 = m->spec_alpha * m->spec_alpha;
    double cos_l = dwvu_dot(n, L), cos_v = dwvu_dot(n, V);
    if (!m->specular || dwvb_specular_singular(m) || !(cos_l > 0.0) || !(cos_v > 0.0)) return;
    dwvu_vec3 h = dwvu_add(L, V);
    double len = dwvu_length(h);
    if (!(len > 0.0)) return;
    h = dwvu_scale(h, 1.0 / len);
    double cos_hv = dwvu_dot(h, V);
    double D = dwvb_ggx_D(a2, dwvu_dot(n, h));
    double li = dwvb_ggx_lambda(a2, cos_v), lo = dwvb_ggx_lambda(a2, cos_l);
    if (m->specular == DWV_SPECULAR_PRINCIPLED_V1) {
        /* Separable Smith G1(V) G1(L) and F = cspec0 (1 - FH) + FH (Cycles 3.x reflection_color). */
        double G = 1.0 / ((1.0 + li) * (1.0 + lo));
        double fh = (dwvb_fresnel_dielectric(cos_hv, m->spec_eta) - m->spec_F0) / (1.0 - m->spec_F0);
        double common = PI * D * G / (4.0 * cos_l * cos_v);
        for (int c = 0; c < 3; ++c) f[c] = common * (m->spec_f0[c] * (1.0 - fh) + fh);
        return;
    }
    double G = 1.0 / (1.0 + li + lo);
    double s = v2_share(cos_hv, m->spec_eta, m->spec_F0);
    double common = PI * D * G / (4.0 * cos_l * cos_v);
    double scale[3] = {1.0, 1.0, 1.0};
    if (m->spec_multiscatter) {
        /* Energy compensation 1 + Fms (1 - E) / E at the viewer's E (Kulla and Conty 2017). */
        double E = spec_table(m->spec_E, cos_v);
        for (int c = 0; c < 3; ++c) scale[c] = 1.0 + m->spec_Fms[c] * (1.0 - E) / E;
    }
    for (int c = 0; c < 3; ++c) f[c] = common * (m->spec_f0[c] + (1.0 - m->spec_f0[c]) * s) * scale[c];
}

int dwvb_specular_singular(const dwvb_material *m)
{
    double a2 = m->spec_alpha * m->spec_alpha;
    return m->specular && !(a2 > (m->specular == DWV_SPECULAR_PRINCIPLED_V2 ? DWVB_GGX_MIN_ALPHA2_V2 : DWVB_GGX_MIN_ALPHA2));
}

void dwvb_specular_singular_weight(const dwvb_material *m, double mu, double f[3])
{
    f[0] = f[1] = f[2] = 0.0;
    if (!dwvb_specular_singular(m) || !(mu > 0.0)) return;
    if (m->specular == DWV_SPECULAR_PRINCIPLED_V1) {
        double fh = (dwvb_fresnel_dielectric(mu, m->spec_eta) - m->spec_F0) / (1.0 - m->spec_F0);
        for (int c = 0; c < 3; ++c) f[c] = m->spec_f0[c] * (1.0 - fh) + fh;
        return;
    }
    double s = v2_share(mu, m->spec_eta, m->spec_F0);
    double E = m->spec_multiscatter ? spec_table(m->spec_E, mu) : 1.0;
    for (int c = 0; c < 3; ++c) {
        double scale = m->spec_multiscatter ? 1.0 + m->spec_Fms[c] * (1.0 - E) / E : 1.0;
        f[c] = (m->spec_f0[c] + (1.0 - m->spec_f0[c]) * s) * scale;
    }
}

void dwvb_specular_color(const dwvb_material *m, double mu, double albedo[3])
{
    if (m->specular != DWV_SPECULAR_PRINCIPLED_V2) {
        albedo[0] = albedo[1] = albedo[2] = m->specular ? 1.0 : 0.0;
        return;
    }
    double s = spec_table(m->spec_s, mu), E = spec_table(m->spec_E, mu);
    for (int c = 0; c < 3; ++c) {
        albedo[c] = m->spec_f0[c] + (1.0 - m->spec_f0[c]) * s;
        /* Multiscatter: Cycles' darkening (1 + Fms (1 - E) / E) E scales the layer's weight. */
        if (m->spec_multiscatter) albedo[c] *= E + m->spec_Fms[c] * (1.0 - E);
    }
}

double dwvb_specular_layer_weight(const dwvb_material *m, double mu)
{
    if (m->specular != DWV_SPECULAR_PRINCIPLED_V2) return 1.0;
    double albedo[3];
    dwvb_specular_color(m, mu, albedo);
    double worst = fmax(albedo[0], fmax(albedo[1], albedo[2]));
    return fmin(fmax(1.0 - worst, 0.0), 1.0);
}

/* The specular layer's constants (svm_closure.h of each release, capi's DWV_SPECULAR_*). */
/* The v2 eta of Specular IOR Level `level` over IOR `ior` (specular_init's rule). */
static double v2_eta(double ior, double level)
{
    double r = (ior - 1.0) / (ior + 1.0), f0 = r * r, eta = ior;
    if (level != 0.5) {
        f0 *= 2.0 * level;
        double root = sqrt(fmin(fmax(f0, 0.0), 0.99));
        eta = (1.0 + root) / (1.0 - root);
    }
    return eta;
}

/* Node k of n over [0, hi] and the linear weights of x between nodes k and k + 1 (exactly 0 or 1
 * at a node). */
static uint32_t grid_cell(double x, double hi, uint32_t n, double *t)
{
    if (n < 2u) {
        *t = 0.0;
        return 0u;
    }
    double position = fmin(fmax(x / hi, 0.0), 1.0) * (double)(n - 1u);
    uint32_t k = (uint32_t)position;
    if (k > n - 2u) k = n - 2u;
    *t = position - (double)k;
    return k;
}

#define SPEC_Q_MAX 0.99498743710661995 /* sqrt(0.99) */

static void spec_grid_lookup(const dwvb_spec_grid *g, double roughness, double q, double *E, double *s)
{
    double tr = 0.0, tq = 0.0;
    uint32_t kr = grid_cell(roughness, 1.0, g->roughness_nodes, &tr);
    uint32_t kq = grid_cell(q, SPEC_Q_MAX, g->q_nodes, &tq);
    uint32_t r1 = g->roughness_nodes > 1u ? kr + 1u : kr, q1 = g->q_nodes > 1u ? kq + 1u : kq;
    for (int i = 0; i < DWVB_SPEC_MU; ++i) {
        E[i] = (1.0 - tr) * g->E[kr * DWVB_SPEC_MU + (uint32_t)i] + tr * g->E[r1 * DWVB_SPEC_MU + (uint32_t)i];
#define S_AT(a, b) g->s[((a) * g->q_nodes + (b)) * DWVB_SPEC_MU + (uint32_t)i]
        s[i] = (1.0 - tr) * ((1.0 - tq) * S_AT(kr, kq) + tq * S_AT(kr, q1)) +
               tr * ((1.0 - tq) * S_AT(r1, kq) + tq * S_AT(r1, q1));
#undef S_AT
    }
}

dwvb_spec_grid *dwvb_spec_grid_make(const dwv_material_t *in, int textured_roughness, int textured_level)
{
    dwvb_spec_grid *g = calloc(1, sizeof *g);
    if (!g) return NULL;
    g->roughness_nodes = textured_roughness ? DWVB_SPEC_GRID : 1u;
    g->q_nodes = textured_level ? DWVB_SPEC_GRID : 1u;
    g->E = malloc((size_t)g->roughness_nodes * DWVB_SPEC_MU * sizeof *g->E);
    g->s = malloc((size_t)g->roughness_nodes * g->q_nodes * DWVB_SPEC_MU * sizeof *g->s);
    if (!g->E || !g->s) {
        dwvb_spec_grid_free(g);
        return NULL;
    }
    double material_eta = v2_eta(in->ior, in->specular);
    for (uint32_t k = 0; k < g->roughness_nodes; ++k) {
        /* The node's alpha as specular_init makes it from a roughness of that value. */
        double roughness = textured_roughness ? (double)k / (DWVB_SPEC_GRID - 1) : in->roughness;
        double alpha = roughness * roughness;
        /* One quadrature per (roughness, mu) for E and every eta's s (the same samples, summed
         * in the same order as dwvb_ggx_albedo: a node gives the constant material's bits). The
         * textured level's q = 0 node (eta 1: no layer) takes the next node's s (f0 below 0.1%
         * there); without a textured level an eta of 1 is never read. */
        double etas[DWVB_SPEC_GRID], shares[DWVB_SPEC_GRID];
        int first = 0, count = 0;
        for (uint32_t j = 0; j < g->q_nodes; ++j) {
            double q = (double)j / (DWVB_SPEC_GRID - 1) * SPEC_Q_MAX;
            etas[j] = textured_level ? (1.0 + q) / (1.0 - q) : material_eta;
        }
        first = textured_level ? 1 : 0;
        count = (int)g->q_nodes - first;
        for (int i = 0; i < DWVB_SPEC_MU; ++i) {
            double mu = (double)i / (DWVB_SPEC_MU - 1);
            dwvb_ggx_albedo_etas(alpha, etas + first, count, mu, 48, &g->E[k * DWVB_SPEC_MU + (uint32_t)i], shares);
            for (uint32_t j = 0; j < g->q_nodes; ++j) {
                int from = (int)j - first < 0 ? 0 : (int)j - first;
                g->s[(k * g->q_nodes + j) * DWVB_SPEC_MU + (uint32_t)i] = etas[j] > 1.0 || textured_level ? shares[from] : 0.0;
            }
        }
    }
    return g;
}

void dwvb_spec_grid_free(dwvb_spec_grid *grid)
{
    if (!grid) return;
    free(grid->E);
    free(grid->s);
    free(grid);
}

static void specular_init(dwvb_material *out, const dwv_material_t *in, const dwvb_material *tables)
{
    out->specular = 0;
    out->spec_multiscatter = 0;
    out->spec_grid = NULL;
    out->spec_alpha = in->roughness * in->roughness;
    for (int c = 0; c < 3; ++c) out->spec_f0[c] = out->spec_Fms[c] = 0.0;
    for (int i = 0; i < DWVB_SPEC_MU; ++i) out->spec_E[i] = 1.0, out->spec_s[i] = 0.0;
    if (in->specular_model == DWV_SPECULAR_PRINCIPLED_V1) {
        if (!(in->specular > 1e-5)) return; /* CLOSURE_WEIGHT_CUTOFF */
        out->specular = DWV_SPECULAR_PRINCIPLED_V1;
        out->spec_eta = 2.0 / (1.0 - sqrt(0.08 * in->specular)) - 1.0;
        out->spec_F0 = dwvb_fresnel_dielectric(1.0, out->spec_eta);
        const double *b = in->base_color;
        double lum = 0.3 * b[0] + 0.6 * b[1] + 0.1 * b[2], t = in->specular_tint[0];
        for (int c = 0; c < 3; ++c) {
            double tint = lum > 0.0 ? b[c] / lum : 1.0;
            out->spec_f0[c] = fmin(fmax(in->specular * 0.08 * ((1.0 - t) + tint * t), 0.0), 1.0);
        }
        return;
    }
    if (in->specular_model != DWV_SPECULAR_PRINCIPLED_V2) return;
    /* Specular IOR Level: f0 = F0(ior) x 2 level, eta back from f0 (sqrt(f0) clamped to 0.99). */
    double r = (in->ior - 1.0) / (in->ior + 1.0), f0 = r * r, eta = in->ior;
    if (in->specular != 0.5) {
        f0 *= 2.0 * in->specular;
        double q = sqrt(fmin(fmax(f0, 0.0), 0.99));
        eta = (1.0 + q) / (1.0 - q);
    }
    /* Kept when the layer vanishes too (f0 = 0, eta = 1: Specular IOR Level 0): the refraction
     * entry still takes this eta (clamped to 1.01 there), not `ior`, as Cycles' bssrdf->ior. */
    out->spec_eta = eta;
    if (!(eta != 1.0)) return;
    out->specular = DWV_SPECULAR_PRINCIPLED_V2;
    out->spec_multiscatter = in->specular_multiscatter;
    double rr = (eta - 1.0) / (eta + 1.0);
    out->spec_F0 = rr * rr;
    for (int c = 0; c < 3; ++c) out->spec_f0[c] = fmin(fmax(f0 * in->specular_tint[c], 0.0), 1.0);
    /* The tables depend on roughness and eta only: a textured point copies its material's, or
     * interpolates them in its grid where a texture drives either. */
    if (tables && tables->spec_grid) {
        spec_grid_lookup(tables->spec_grid, in->roughness, sqrt(fmin(fmax(f0, 0.0), 0.99)), out->spec_E, out->spec_s);
    } else if (tables && tables->specular == DWV_SPECULAR_PRINCIPLED_V2) {
        memcpy(out->spec_E, tables->spec_E, sizeof out->spec_E);
        memcpy(out->spec_s, tables->spec_s, sizeof out->spec_s);
    } else {
        for (int i = 0; i < DWVB_SPEC_MU; ++i)
            dwvb_ggx_albedo(out->spec_alpha, eta, (double)i / (DWVB_SPEC_MU - 1), 48, &out->spec_E[i], &out->spec_s[i]);
    }
    if (!out->spec_multiscatter) return;
    /* E_avg = 2 int E(mu) mu dmu (Simpson on the table); Fss from Kulla and Conty's fit of
     * 2 int F_d(mu) mu dmu, (eta - 1) / (4.08567 + 1.00071 eta), as Cycles. */
    double e_avg = 0.0, h = 1.0 / (DWVB_SPEC_MU - 1);
    for (int i = 0; i < DWVB_SPEC_MU; ++i) {
        double w = (i == 0 || i == DWVB_SPEC_MU - 1) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        e_avg += w * out->spec_E[i] * i * h;
    }
    e_avg *= 2.0 * h / 3.0;
    double real_fss = (eta - 1.0) / (4.08567 + 1.00071 * eta);
    double share = fmin(fmax((real_fss - out->spec_F0) / (1.0 - out->spec_F0), 0.0), 1.0);
    for (int c = 0; c < 3; ++c) {
        double fss = out->spec_f0[c] + (1.0 - out->spec_f0[c]) * share;
        out->spec_Fms[c] = fss * e_avg / (1.0 - fss * (1.0 - e_avg));
    }
}

static void material_init(dwvb_material *out, const dwv_material_t *in, const dwvb_material *tables);

void dwvb_material_init(dwvb_material *out, const dwv_material_t *in)
{
    material_init(out, in, NULL);
}

void dwvb_material_init_like(dwvb_material *out, const dwv_material_t *in, const dwvb_material *tables)
{
    material_init(out, in, tables);
}

static void material_init(dwvb_material *out, const dwv_material_t *in, const dwvb_material *tables)
{
    out->subsurface = 0;
    out->grey = 0;
    out->principled_v1 = 0;
    out->principled_diffuse = 0;
    out->roughness = 0.0;
    out->model = in->subsurface_model;
    out->entry = DWVB_ENTRY_DIFFUSE;
    out->entry_alpha = in->roughness * in->roughness;
    specular_init(out, in, tables);
    out->min_footprint = in->kind == DWV_MATERIAL_SUBSURFACE ? in->subsurface_min_footprint : 0.0;
    for (int c = 0; c < 3; ++c) {
        out->radius[c] = in->subsurface_radius[c] * in->subsurface_scale;
        out->fallback_albedo[c] = (in->kind == DWV_MATERIAL_SUBSURFACE ? in->subsurface_weight : 0.0) * in->subsurface_color[c];
    }
    /* The refraction entry's IOR is the specular layer's eta (4.x+ Principled: IOR adjusted by
     * Specular IOR Level), else `ior` (the Subsurface Scattering node's IOR); clamped as Cycles. */
    out->entry_ior = fmin(fmax(in->specular_model == DWV_SPECULAR_PRINCIPLED_V2 ? out->spec_eta : in->ior, 1.01), 3.8);
    for (int c = 0; c < 3; ++c) {
        out->diffuse_albedo[c] = in->base_color[c];
        out->walk_scale[c] = 0.0;
        out->retro_albedo[c] = 0.0;
    }
    double w = in->kind == DWV_MATERIAL_SUBSURFACE ? in->subsurface_weight : 0.0;
    if (in->subsurface_exit == DWV_SUBSURFACE_EXIT_PRINCIPLED_V1 && !(w > 0.0)) {
        /* Blender 3.x's Principled with Subsurface = 0: svm_node_closure_bsdf sets up its diffuse
         * as PRINCIPLED_DIFFUSE_FULL (base colour x (Lambertian with both Fresnel terms + retro)). */
        out->principled_diffuse = 1;
        out->roughness = in->roughness;
    }
    if (in->kind != DWV_MATERIAL_SUBSURFACE) return;
    if (in->subsurface_exit == DWV_SUBSURFACE_EXIT_PRINCIPLED_V1 && w > 0.0) {
        /* bssrdf_setup adds the retro-reflection BSDF with the BSSRDF's whole weight, before it
         * moves channels of too small a radius to a Lambertian BSDF: every channel has it. */
        out->principled_v1 = 1;
        out->roughness = in->roughness;
        for (int c = 0; c < 3; ++c) out->retro_albedo[c] = w * in->subsurface_color[c];
    }
    int model = in->subsurface_model;
    /* Anisotropy clamps (bssrdf_setup / svm_closure.h): [0, 0.9] up to 5.1, 5.2's Random Walk
     * [-0.99, 0.99], its Legacy and Skin [-0.99, 0.9]. */
    double g_lo = 0.0, g_hi = 0.9;
    if (model == DWV_SUBSURFACE_MODEL_BLENDER52_RANDOM_WALK) g_lo = -0.99, g_hi = 0.99;
    else if (model == DWV_SUBSURFACE_MODEL_BLENDER52_LEGACY || model == DWV_SUBSURFACE_MODEL_BLENDER52_SKIN)
        g_lo = -0.99;
    double g = fmin(fmax(in->subsurface_anisotropy, g_lo), g_hi);
    /* 5.2 maps the albedo by van de Hulst for its Random Walk, and for Legacy and Skin where g < 0. */
    int hulst = model == DWV_SUBSURFACE_MODEL_BLENDER52_RANDOM_WALK ||
                ((model == DWV_SUBSURFACE_MODEL_BLENDER52_LEGACY || model == DWV_SUBSURFACE_MODEL_BLENDER52_SKIN) && g < 0.0);
    int rescaled = model == DWV_SUBSURFACE_MODEL_BLENDER3_RANDOM_WALK || model == DWV_SUBSURFACE_MODEL_BLENDER4_SKIN ||
                   model == DWV_SUBSURFACE_MODEL_BLENDER52_SKIN;
    if (model == DWV_SUBSURFACE_MODEL_BLENDER4_RANDOM_WALK || model == DWV_SUBSURFACE_MODEL_BLENDER52_RANDOM_WALK ||
        model == DWV_SUBSURFACE_MODEL_BLENDER52_LEGACY)
        out->entry = DWVB_ENTRY_REFRACT;
    if (model == DWV_SUBSURFACE_MODEL_BLENDER4_SKIN || model == DWV_SUBSURFACE_MODEL_BLENDER52_SKIN) {
        /* Skin: refraction with Subsurface IOR at alpha 1; the radius rescaled with it too. */
        out->entry = DWVB_ENTRY_SKIN;
        out->entry_alpha = 1.0;
        out->entry_ior = fmin(fmax(in->subsurface_ior, 1.01), 3.8);
    }
    /* 3.x Random Walk rescales with Subsurface IOR (svm_closure.h clamps it to [1.01, 3.8]). */
    double rescale_ior = fmin(fmax(in->subsurface_ior, 1.01), 3.8);
    double sigma_t[3], alpha[3];
    int walking = -1;
    for (int c = 0; c < 3; ++c) {
        out->diffuse_albedo[c] = (1.0 - w) * in->base_color[c];
        double radius = in->subsurface_radius[c] * in->subsurface_scale;
        if (!(radius >= DWVB_MIN_RADIUS)) {
            out->diffuse_albedo[c] += w * in->subsurface_color[c];
            sigma_t[c] = alpha[c] = 0.0;
            continue;
        }
        double d;
        if (model == DWV_SUBSURFACE_MODEL_BLENDER52_RANDOM_WALK)
            d = radius; /* the mean free path itself */
        else if (rescaled)
            d = radius * sqrt(3.0 * (1.0 - dwvb_dipole_alpha_prime(in->subsurface_color[c], rescale_ior)));
        else
            d = radius / FOUR_PI;
        d = fmax(d, 1e-16);
        /* Kept inside the walk's range of extinctions [1e-30, 1e30]. Van de Hulst's mapping takes
         * d as the mean free path (sigma_t = 1 / d), Cycles' fit as the reduced one. */
        if (hulst) {
            sigma_t[c] = fmin(fmax(1.0 / d, 1e-30), 1e30);
            alpha[c] = dwvb_albedo_van_de_hulst(in->subsurface_color[c], g);
        } else {
            sigma_t[c] = fmin(fmax(1.0 / (d * (1.0 - g)), 1e-30), 1e30);
            alpha[c] = dwvb_albedo_inversion(in->subsurface_color[c], g);
        }
        double scale = 1.0;
        if (alpha[c] < DWVB_MIN_ALPHA) {
            scale = alpha[c] / DWVB_MIN_ALPHA;
            alpha[c] = DWVB_MIN_ALPHA;
        }
        out->walk_scale[c] = w * scale;
        if (out->walk_scale[c] > 0.0) walking = c;
    }
    if (walking < 0) return;
    /* Channels that do not walk copy a walking channel's extinction and get albedo 0: the walk
     * then never picks them for distances, and their weight is not used. */
    for (int c = 0; c < 3; ++c) {
        if (out->walk_scale[c] > 0.0) continue;
        sigma_t[c] = sigma_t[walking];
        alpha[c] = 0.0;
    }
    out->subsurface = 1;
    out->grey = sigma_t[0] == sigma_t[1] && sigma_t[1] == sigma_t[2] && alpha[0] == alpha[1] &&
                alpha[1] == alpha[2] && out->walk_scale[0] == out->walk_scale[1] &&
                out->walk_scale[1] == out->walk_scale[2];
    dwvw_medium_init(&out->medium, out->grey ? 1 : 3, sigma_t, alpha, g);
    for (int c = 0; c < 3; ++c)
        if ((!out->grey || tables) && out->walk_scale[c] > 0.0)
            dwvw_medium_init(&out->channel_medium[c], 1, &sigma_t[c], &alpha[c], g);
}
