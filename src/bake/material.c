#include "material.h"

#include <math.h>

#define FOUR_PI 12.566370614359172954

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

void dwvb_material_init(dwvb_material *out, const dwv_material_t *in)
{
    out->subsurface = 0;
    out->grey = 0;
    out->principled_v1 = 0;
    out->principled_diffuse = 0;
    out->roughness = 0.0;
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
    double g = fmin(fmax(in->subsurface_anisotropy, 0.0), 0.9);
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
        double d = fmax(radius / FOUR_PI, 1e-16);
        /* Kept inside the walk's range of extinctions [1e-30, 1e30]. */
        sigma_t[c] = fmin(fmax(1.0 / (d * (1.0 - g)), 1e-30), 1e30);
        alpha[c] = dwvb_albedo_inversion(in->subsurface_color[c], g);
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
        if (!out->grey && out->walk_scale[c] > 0.0) dwvw_medium_init(&out->channel_medium[c], 1, &sigma_t[c], &alpha[c], g);
}
