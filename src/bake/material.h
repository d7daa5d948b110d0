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
} dwvb_material;

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

#endif
