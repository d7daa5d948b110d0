/* A scene material turned into what shading needs, by Cycles' conventions for the Principled
 * BSDF with subsurface method "Random Walk (Fixed Radius)" (Blender 3.4, intern/cycles):
 *
 *   kernel/svm/closure.h     g = clamp(subsurface_anisotropy, 0, 0.9)
 *   kernel/closure/bssrdf.h  a channel with radius < BSSRDF_MIN_RADIUS = 1e-8 becomes Lambertian
 *                            diffuse (weight: that channel of the subsurface colour); otherwise
 *                            bssrdf_setup_radius: d = radius / (4 pi) for the fixed-radius method
 *   kernel/integrator/subsurface_random_walk.h, subsurface_random_walk_remap:
 *                            sigma_t = 1 / (max(d, 1e-16) (1 - g))   (1/d is the reduced extinction)
 *                            alpha = (1 - A^(1/4)) P(g) atan(Q(g) A)^R(g)
 *                                    + A^(1/4) S(g) atan(T(g) A)^U(g), clamped to [0, 0.999999],
 *                            A the subsurface colour (multiple-scattering albedo), P..U fitted
 *                            polynomials (and exponentials) in g (the coefficients of Cycles' fit)
 *   subsurface_random_walk_coefficients: the closure weight (which holds the colour A) is divided
 *                            by A, and where alpha < 0.2 the walk runs with alpha = 0.2 and its
 *                            throughput is scaled by alpha / 0.2.
 *   entry: cosine-weighted diffuse transmission about -N (rejected where it would not enter below
 *          the geometric normal); exit: a Lambertian (diffuse) BSDF at the exit point.
 *   kernel/closure/bssrdf.h bssrdf_setup, kernel/integrator/subsurface.h (Blender 3.x Principled,
 *          whose closure carries its roughness): a retro-reflection BSDF of the BSSRDF's weight
 *          beside it, and an exit BSDF PRINCIPLED_DIFFUSE_LAMBERT_EXIT
 *          (kernel/closure/bsdf_principled_diffuse.h); see dwvb_principled_*_factor.
 * The "mean free path = radius x scale / (4 pi)" holds for g = 0 only: Cycles' 1/(4 pi)
 * scaling gives the reduced mean free path d, and the walk's mean free path is d (1 - g). */
#ifndef DWV_BAKE_MATERIAL_H
#define DWV_BAKE_MATERIAL_H

#include <dwivedi.h>
#include "walk/walk.h"

#define DWVB_MIN_RADIUS 1e-8
#define DWVB_MIN_ALPHA 0.2
#define DWVB_SPEC_MU 33

/* The 4.x+ (v2) specular layer's albedo tables over the values a texture can give its Roughness
 * and Specular IOR Level (issue 18): spec_E and spec_s at DWVB_SPEC_GRID roughness nodes k / (N - 1)
 * (one node, the material's roughness, when it is not textured) and, for spec_s, at DWVB_SPEC_GRID
 * nodes of q = sqrt(f0) = j / (N - 1) sqrt(0.99), eta = (1 + q) / (1 - q) (one node, the material's
 * eta, when the level is not textured). A textured point interpolates them linearly (exact at the
 * nodes: a texture of a node's value gives the constant material's tables). */
#define DWVB_SPEC_GRID 17
typedef struct dwvb_spec_grid {
    uint32_t roughness_nodes, q_nodes; /* 1 or DWVB_SPEC_GRID each */
    double *E;                         /* roughness_nodes x DWVB_SPEC_MU */
    double *s;                         /* roughness_nodes x q_nodes x DWVB_SPEC_MU */
} dwvb_spec_grid;

typedef struct dwvb_material {
    int subsurface;            /* walks run: some channel scatters with a non-zero weight */
    int principled_v1;         /* DWV_SUBSURFACE_EXIT_PRINCIPLED_V1: exit weighted by
                                  dwvb_principled_exit_factor, plus the retro-reflection lobe */
    double retro_albedo[3];    /* the retro-reflection lobe's weight (0 unless principled_v1) */
    double roughness;          /* its roughness (principled_v1 or principled_diffuse) */
    int principled_diffuse;    /* Blender 3.x Principled without subsurface: the diffuse lobe is
                                  dwvb_principled_diffuse_factor's, not Lambertian */
    double diffuse_albedo[3];  /* the Lambertian lobe: (1 - w) base colour, plus w x subsurface
                                  colour in channels whose radius is below DWVB_MIN_RADIUS */
    double walk_scale[3];      /* w x Cycles' low-albedo compensation; 0 where a channel does not walk */
    int grey;                  /* all three channels walk alike: one-channel walks */
    dwvw_medium medium;
    /* Each walking channel's own one-channel medium, for walks that carry one channel (channel
     * walks, shade.h); unset where walk_scale[c] is 0 or the material is grey. */
    dwvw_medium channel_medium[3];
    /* Issue 17: the Cycles subsurface model (dwv_subsurface_model_t), its entry, and the
     * Principled specular layer around the walk. */
    int model;
    int entry;                 /* DWVB_ENTRY_* */
    double entry_alpha;        /* GGX alpha of the refraction entry */
    double entry_ior;          /* its IOR, clamped to [1.01, 3.8] */
    int specular;              /* DWV_SPECULAR_*, 0 where the layer is absent (specular 0, eta 1) */
    int spec_multiscatter;
    double spec_alpha;         /* GGX alpha = roughness^2 */
    double spec_eta;           /* the Fresnel's IOR */
    double spec_F0;            /* F_d(1, eta) */
    double spec_f0[3];         /* v1: cspec0; v2: f0 x tint (both saturated) */
    double spec_E[DWVB_SPEC_MU];  /* v2: GGX albedo (F = 1) toward mu_i = i / (DWVB_SPEC_MU - 1) */
    double spec_s[DWVB_SPEC_MU];  /* v2: the albedo's interpolation factor between f0 and 1 */
    double spec_Fms[3];        /* v2 multiscatter: Kulla-Conty's multiple-bounce Fresnel */
    const dwvb_spec_grid *spec_grid; /* v2 with a textured Roughness or Specular IOR Level: the
                                  tables textured points interpolate (owned by the scene), else NULL */
    /* Cycles 4.0-4.3's footprint rule (dwv_material_t.subsurface_min_footprint): a walking channel
     * c whose radius[c] (radius x scale) is below min_footprint x the ray's footprint (camera pixel,
     * UV texel, grown along a path: shade.h dwvb_footprint) turns into a Lambertian lobe of
     * fallback_albedo[c] there. */
    double min_footprint;
    double radius[3];
    double fallback_albedo[3];
} dwvb_material;

/* Entries into the medium. */
enum { DWVB_ENTRY_DIFFUSE = 0, DWVB_ENTRY_REFRACT = 1, DWVB_ENTRY_SKIN = 2 };

/* GGX evaluation is skipped (a mirror: no light from sampled lights; its reflection is the
 * singular one, dwvb_specular_singular_weight) where alpha^2 is at most this: Cycles 3.x's
 * alpha_x alpha_y <= 1e-7 (bsdf_microfacet.h), for DWV_SPECULAR_PRINCIPLED_V1; 4.0+'s
 * BSDF_ROUGHNESS_SQ_THRESH = 2e-10 (svm/types.h; 5.x's roughness_is_almost_specular) for
 * DWV_SPECULAR_PRINCIPLED_V2. */
#define DWVB_GGX_MIN_ALPHA2 1e-7
#define DWVB_GGX_MIN_ALPHA2_V2 2e-10

/* Exact unpolarised Fresnel reflectance of a dielectric of relative IOR eta for the cosine c
 * (Cycles' fresnel_dielectric_cos form: g = sqrt(eta^2 - 1 + c^2), 1 past total reflection). */
double dwvb_fresnel_dielectric(double c, double eta);
/* GGX (Trowbridge-Reitz) normal distribution D(h) for alpha^2 and cos(n, h) (Walter et al. 2007, Eq. 33). */
double dwvb_ggx_D(double alpha2, double cos_h);
/* Smith's Lambda for GGX (Heitz 2014, Eq. 72): (sqrt(1 + alpha^2 tan^2) - 1) / 2. */
double dwvb_ggx_lambda(double alpha2, double cos_theta);
/* A visible normal of GGX for the local direction wi (z up, wi.z > 0), isotropic alpha, uniform
 * u1, u2 (Heitz 2018, "Sampling the GGX Distribution of Visible Normals", Listing 1), and its pdf
 * D_wi(h) = G1(wi) max(0, wi.h) D(h) / wi.z (Eq. 2 there). */
dwvu_vec3 dwvb_ggx_sample_vndf(dwvu_vec3 wi, double alpha, double u1, double u2);
double dwvb_ggx_vndf_pdf(dwvu_vec3 wi, dwvu_vec3 h, double alpha);
/* Cycles 4.x+'s refraction entry (subsurface.h, subsurface_entry_bounce): h from the visible
 * normals toward wi, wi refracted through h into a medium of IOR `ior` (> 1, so no total
 * reflection). Local frame, z the shading normal; returns 0 where wi.z <= 0. Its pdf over
 * directions (Walter et al. 2007, Eq. 17): D_wi(h) ior^2 |wo.h| / (wi.h + ior wo.h)^2, h =
 * -(wi + ior wo) / |...|; 0 where wo does not go down or h is not above the surface. */
int dwvb_entry_refract_sample(dwvu_vec3 wi, double alpha, double ior, double u1, double u2, dwvu_vec3 *wo);
double dwvb_entry_refract_pdf(dwvu_vec3 wi, dwvu_vec3 wo, double alpha, double ior);
/* The entry of a material: a unit direction into the medium (local frame, z the shading normal,
 * wi toward the viewer) from one uniform pair, and the pdf of every technique that could have
 * produced it (Skin: half cosine-weighted, half refraction). Returns 0 where no entry is drawn. */
int dwvb_entry_sample(const dwvb_material *m, dwvu_vec3 wi, double u1, double u2, dwvu_vec3 *wo);
double dwvb_entry_pdf(const dwvb_material *m, dwvu_vec3 wi, dwvu_vec3 wo);
/* Cycles' 3.x Random Walk / Skin radius rescaling: sqrt(3 (1 - a')) for colour A and IOR eta
 * (bisection of Jensen's dipole Rd as Cycles does: 12 steps from [0, 1], the last midpoint;
 * A < 1e-4 gives a' = 0 and A >= 0.995 gives 0.999999). */
double dwvb_dipole_alpha_prime(double A, double eta);
/* Van de Hulst's albedo mapping (d'Eon, Hitchhiker's Guide Eq. 53.7), clamped to [0, 0.999999]. */
double dwvb_albedo_van_de_hulst(double A, double g);
/* The specular layer's BRDF times pi for light L and viewer V (unit, world), shading normal n,
 * into f[3]; 0 below either horizon. */
void dwvb_specular_factor(const dwvb_material *m, dwvu_vec3 n, dwvu_vec3 L, dwvu_vec3 V, double f[3]);
/* Whether the specular layer is a mirror (alpha^2 at most its model's DWVB_GGX_MIN_ALPHA2*). */
int dwvb_specular_singular(const dwvb_material *m);
/* A mirror layer's reflection toward a viewer at cosine mu (> 0) to its normal: the weight eval /
 * pdf of Cycles' singular microfacet sample (H = N, so the Fresnel at L.H = mu) per channel:
 * v1 (3.x reflection_color) cspec0 (1 - FH) + FH, FH = (F_d(mu, eta) - F0) / (1 - F0); v2 (4.x+
 * generalized Schlick) f0 + (1 - f0) s(mu), times Multiscatter GGX's 1 + Fms (1 - E) / E. */
void dwvb_specular_singular_weight(const dwvb_material *m, double mu, double f[3]);
/* The weight of the layers below the specular toward a viewer at cosine mu to n: 1 for v1 and no
 * layer; v2: 1 - max_c (albedo of the layer, with its multiscatter darkening). */
double dwvb_specular_layer_weight(const dwvb_material *m, double mu);
/* The specular layer's colour as Cycles' Glossy Color pass has it toward a viewer at cosine mu:
 * 3.x, the closure's weight (1: its Fresnel colour lives in the BSDF, not the weight); 4.x+
 * (closure_albedo), v2's albedo per channel, the one dwvb_specular_layer_weight takes the largest
 * of; 0 without the layer. */
void dwvb_specular_color(const dwvb_material *m, double mu, double albedo[3]);
/* v2's GGX albedo with F = 1 and with the interpolation factor, by quadrature over visible
 * normals toward mu (what Cycles tabulates as ggx_E and ggx_gen_schlick_ior_s): the mean of
 * G2 / G1(wi) and of s(wi.h) x [wo above], over a midpoint grid of n x n uniform pairs. */
void dwvb_ggx_albedo(double alpha, double eta, double mu, int n, double *E, double *s);
/* The same for `count` (<= DWVB_SPEC_GRID) etas at once from one quadrature (s[k] for etas[k]). */
void dwvb_ggx_albedo_etas(double alpha, const double *etas, int count, double mu, int n, double *E, double *s);

/* Cycles' albedo inversion: the single-scattering albedo for multiple-scattering albedo A in
 * [0, 1] and anisotropy g in [0, 0.9] (before the clamps). */
double dwvb_albedo_inversion(double A, double g);
/* Schlick's weight (1 - cos)^5 for a cosine clamped to [0, 1] (Schlick 1994, Eq. 24). */
double dwvb_schlick_weight(double cos_theta);
/* Blender 3.x Principled BSDF's walk exit (Cycles' PRINCIPLED_DIFFUSE_LAMBERT_EXIT): the
 * Lambertian exit BSDF (1/pi) times 1 - F_L / 2, F_L the Schlick weight of the light direction's
 * cosine to the exit's shading normal (Burley 2015, "Extending the Disney BRDF to a BSDF with
 * Integrated Subsurface Scattering", section 5.3: its Lambertian part (1 - F_L/2)(1 - F_V/2)
 * with the view's term dropped, the walk having already chosen to leave). Returns that factor. */
double dwvb_principled_exit_factor(double cos_light);
/* Its retro-reflection lobe (Burley 2015, section 5.3; Cycles' PRINCIPLED_DIFFUSE_RETRO_REFLECTION):
 * f = (1/pi) R_R (F_L + F_V + F_L F_V (R_R - 1)), R_R = roughness (1 + L.V) (= 2 roughness
 * cos^2 of the half angle). Returns f pi for the light and view cosines to the shading normal and
 * L.V. */
double dwvb_principled_retro_factor(double cos_light, double cos_view, double light_dot_view, double roughness);
/* Blender 3.x Principled BSDF without subsurface (Subsurface = 0; Cycles'
 * PRINCIPLED_DIFFUSE_FULL, bsdf_principled_diffuse.h): f = (1/pi) ((1 - F_L/2)(1 - F_V/2) + retro),
 * the Lambertian part of Burley 2015 section 5.3 with both Fresnel terms, plus the
 * retro-reflection lobe above. Returns f pi. */
double dwvb_principled_diffuse_factor(double cos_light, double cos_view, double light_dot_view, double roughness);
/* Derives the shading of a validated material. */
void dwvb_material_init(dwvb_material *out, const dwv_material_t *in);
/* The same for a textured point of a material whose committed shading is `tables`: its channel
 * media are made for every walking channel (its mesh may walk channels apart while the point is
 * grey), and the v2 specular tables are copied from `tables`. */
void dwvb_material_init_like(dwvb_material *out, const dwv_material_t *in, const dwvb_material *tables);
/* The grid for material `in` (v2 specular) whose roughness and / or Specular IOR Level are
 * textured; NULL when out of memory. Measured 0.35 s (textured roughness), 0.07 s (level), 0.6-0.85 s (both)
 * (one quadrature of 48 x 48 directions per roughness node and mu, with DWVB_SPEC_GRID
 * Fresnel terms a direction for a textured level). */
dwvb_spec_grid *dwvb_spec_grid_make(const dwv_material_t *in, int textured_roughness, int textured_level);
void dwvb_spec_grid_free(dwvb_spec_grid *grid);

#endif
