/* Every random-walk technique estimates the same quantity: on each scene and albedo, the eight
 * techniques (auto, classical, poe, closest, incident, backward, cycles, sheet) must agree pairwise within
 * 5 sigma, sigma = sqrt(se_a^2 + se_b^2) (independent runs: every run has a seed of its own).
 * Scenes: the front-lit half-space (total diffuse reflectance), a slab of 4 mean free paths lit from
 * the back (total transmittance) and from the front (reflectance), and a sphere of radius 2 mean
 * free paths lit from the front and from the back (exits scored by their cosine to the light);
 * normal incidence at the front point, isotropic scattering. Classical sampling, which has no
 * guide to get wrong, anchors each comparison; a technique that divides by the wrong pdf somewhere
 * separates from it. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#define WALK_SEED_BASE 0xa9ee0001u
#include "walk_harness.h"

/* Walk counts from a pilot run, for a standard error of about 0.35 percent of the mean, within
 * [min_walks, max_walks]: techniques that do not suit a scene (a guide toward the front of a
 * back-lit slab) have heavy-tailed weights and stop at max_walks with a larger error. */
static const walk_budget_t BUDGET = {
    .pilot_walks = 5000, .min_walks = 20000, .max_walks = 250000, .zero_mean_walks = 250000,
    .target_relative_error = 0.0035,
};

#define SIGMAS 5.0

static const scene_t SCENES[] = {
    {"half-space, front", DWV_SHAPE_HALFSPACE, 0.0, DWV_LIGHT_FRONT},
    {"slab 4, back", DWV_SHAPE_SLAB, 4.0, DWV_LIGHT_BACK},
    {"slab 4, front", DWV_SHAPE_SLAB, 4.0, DWV_LIGHT_FRONT},
    {"sphere 2, front", DWV_SHAPE_SPHERE, 2.0, DWV_LIGHT_FRONT},
    {"sphere 2, back", DWV_SHAPE_SPHERE, 2.0, DWV_LIGHT_BACK},
};
static const double ALBEDOS[] = {0.3, 0.9, 0.99, 0.999};
enum { TECHNIQUES = DWV_TECHNIQUE_SHEET + 1 };

int main(void)
{
    printf("pairwise agreement of the techniques (|z| <= %.0f, z = (m_a - m_b) / sqrt(se_a^2 + se_b^2))\n", SIGMAS);
    for (size_t s = 0; s < sizeof SCENES / sizeof SCENES[0]; ++s) {
        const scene_t *scene = &SCENES[s];
        for (size_t a = 0; a < sizeof ALBEDOS / sizeof ALBEDOS[0]; ++a) {
            dwv_estimate_result_t r[TECHNIQUES];
            printf("  %s, albedo %g\n", scene->name, ALBEDOS[a]);
            for (dwv_technique_t t = 0; t < TECHNIQUES; ++t) {
                dwv_estimate_options_t options = scene_options(scene, t);
                options.medium.albedo[0] = ALBEDOS[a];
                r[t] = estimate_to_precision(options, &BUDGET);
                CHECK(r[t].truncated_walks == 0, "%s albedo %g %s: %llu walks truncated", scene->name, ALBEDOS[a],
                      dwv_technique_name(t), (unsigned long long)r[t].truncated_walks);
            }
            for (dwv_technique_t t = 0; t < TECHNIQUES; ++t) {
                double worst = 0.0;
                dwv_technique_t worst_other = t;
                for (dwv_technique_t u = 0; u < TECHNIQUES; ++u) {
                    if (u == t) continue;
                    double z = difference_z(r[t].mean[0], r[t].std_error[0], r[u].mean[0], r[u].std_error[0]);
                    if (fabs(z) > fabs(worst)) worst = z, worst_other = u;
                    if (u > t)
                        CHECK(fabs(z) <= SIGMAS, "%s albedo %g: %s %.8f +- %.3e vs %s %.8f +- %.3e: z = %.2f",
                              scene->name, ALBEDOS[a], dwv_technique_name(t), r[t].mean[0], r[t].std_error[0],
                              dwv_technique_name(u), r[u].mean[0], r[u].std_error[0], z);
                }
                printf("    %-9s %12.8f +- %10.3e  (%7llu walks)  largest |z| %5.2f against %s\n", dwv_technique_name(t),
                       r[t].mean[0], r[t].std_error[0], (unsigned long long)r[t].walks, fabs(worst),
                       dwv_technique_name(worst_other));
            }
        }
    }
    return check_report("test_walk_agreement");
}
