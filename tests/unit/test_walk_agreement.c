/* Every random-walk technique estimates the same quantity: on each scene and albedo, the seven
 * techniques (auto, classical, poe, closest, incident, backward, cycles) must agree pairwise within
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

#include "check.h"
#include "dwivedi.h"

/* Every run has a seed of its own, so that the estimates compared are independent. */
static uint64_t next_seed = 0xa9ee0001u;

static dwv_estimate_result_t estimate(dwv_estimate_options_t options, uint64_t walks)
{
    options.walks = walks;
    options.seed = next_seed++;
    options.threads = 2;
    dwv_estimate_result_t result = DWV_ESTIMATE_RESULT_INIT;
    dwv_result_t rc = dwv_estimate(&options, &result);
    CHECK(rc == DWV_SUCCESS, "dwv_estimate: %s", dwv_last_error_message());
    return result;
}

/* Walk counts from a pilot run, for a standard error of about 0.35 percent of the mean, within
 * [MIN_WALKS, MAX_WALKS]: techniques that do not suit a scene (a guide toward the front of a
 * back-lit slab) have heavy-tailed weights and stop at MAX_WALKS with a larger error. */
enum { PILOT_WALKS = 5000, MIN_WALKS = 20000, MAX_WALKS = 250000 };
#define TARGET_RELATIVE_ERROR 0.0035

static dwv_estimate_result_t estimate_to_precision(dwv_estimate_options_t options)
{
    dwv_estimate_result_t pilot = estimate(options, PILOT_WALKS);
    double target = TARGET_RELATIVE_ERROR * pilot.mean[0];
    double walks = target > 0.0 ? ceil(pilot.variance[0] / (target * target)) : MAX_WALKS;
    walks = fmin(fmax(walks, MIN_WALKS), MAX_WALKS);
    return estimate(options, (uint64_t)walks);
}

#define SIGMAS 5.0

typedef struct scene_t {
    const char *name;
    dwv_shape_t shape;
    double size; /* slab thickness or sphere radius */
    dwv_light_t light;
} scene_t;

static const scene_t SCENES[] = {
    {"half-space, front", DWV_SHAPE_HALFSPACE, 0.0, DWV_LIGHT_FRONT},
    {"slab 4, back", DWV_SHAPE_SLAB, 4.0, DWV_LIGHT_BACK},
    {"slab 4, front", DWV_SHAPE_SLAB, 4.0, DWV_LIGHT_FRONT},
    {"sphere 2, front", DWV_SHAPE_SPHERE, 2.0, DWV_LIGHT_FRONT},
    {"sphere 2, back", DWV_SHAPE_SPHERE, 2.0, DWV_LIGHT_BACK},
};
static const double ALBEDOS[] = {0.3, 0.9, 0.99, 0.999};
enum { TECHNIQUES = DWV_TECHNIQUE_CYCLES + 1 };

int main(void)
{
    printf("pairwise agreement of the techniques (|z| <= %.0f, z = (m_a - m_b) / sqrt(se_a^2 + se_b^2))\n", SIGMAS);
    for (size_t s = 0; s < sizeof SCENES / sizeof SCENES[0]; ++s) {
        const scene_t *scene = &SCENES[s];
        for (size_t a = 0; a < sizeof ALBEDOS / sizeof ALBEDOS[0]; ++a) {
            dwv_estimate_result_t r[TECHNIQUES];
            printf("  %s, albedo %g\n", scene->name, ALBEDOS[a]);
            for (dwv_technique_t t = 0; t < TECHNIQUES; ++t) {
                dwv_estimate_options_t options = DWV_ESTIMATE_OPTIONS_INIT;
                options.shape = scene->shape;
                options.thickness = scene->shape == DWV_SHAPE_SLAB ? scene->size : options.thickness;
                options.radius = scene->shape == DWV_SHAPE_SPHERE ? scene->size : options.radius;
                options.medium.albedo[0] = ALBEDOS[a];
                options.light = scene->light;
                options.technique = t;
                r[t] = estimate_to_precision(options);
                CHECK(r[t].truncated_walks == 0, "%s albedo %g %s: %llu walks truncated", scene->name, ALBEDOS[a],
                      dwv_technique_name(t), (unsigned long long)r[t].truncated_walks);
            }
            for (dwv_technique_t t = 0; t < TECHNIQUES; ++t) {
                double worst = 0.0;
                dwv_technique_t worst_other = t;
                for (dwv_technique_t u = 0; u < TECHNIQUES; ++u) {
                    if (u == t) continue;
                    double sigma = sqrt(r[t].std_error[0] * r[t].std_error[0] + r[u].std_error[0] * r[u].std_error[0]);
                    double z = (r[t].mean[0] - r[u].mean[0]) / sigma;
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
