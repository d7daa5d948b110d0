/* Energy bookkeeping of the random walks.
 *   albedo 1   nothing is absorbed: every walk that enters a slab leaves it, so with light = both
 *              (every exit scores 1) the estimate of R + T is 1, within 5 standard errors, with no
 *              walk truncated. Isotropic scattering makes every weight 1 (the eigenfunction is
 *              uniform at albedo 1); Henyey-Greenstein g = 0.5 and -0.3 do not, and test the MIS
 *              weights of every technique against the phase function. Those run on slabs of at most
 *              1 mean free path: a purely guided technique weights each event by 4 pi p_HG(mu) (up
 *              to (1 + g)/(1 - g)^2), and over the ~d^2 events of a thicker slab the product has so
 *              heavy a tail (E[w^2] = 2.2 per event at g = 0.5) that the sample standard error no
 *              longer bounds the error: poe at g = 0.5, d = 4 gives 0.80, 0.89, 0.94 with 2e4, 2e5,
 *              2e6 walks, creeping up to 1 as heavy tails do.
 *              A half-space returns every walk too, after a heavy-tailed number of events (a
 *              recurrent one-dimensional walk): with a cap of MAX_EVENTS_HALFSPACE events, each walk's
 *              weight is either scored or reported as truncated, so mean + truncated_weight = 1.
 *   albedo < 1 light = both scores exits through either face, so its estimate is the sum of the
 *              front-lit and back-lit estimates (each run independent): within 5 sigma,
 *              sigma^2 = se_both^2 + se_front^2 + se_back^2. On the sphere, front and back scores are
 *              max(0, -n_z) and max(0, n_z), which add up as well. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#define WALK_SEED_BASE 0xe4e60001u
#include "walk_harness.h"

#define SIGMAS 5.0
/* Weights are products of per-event ratios, each rounded; where they are all 1 in exact arithmetic
 * (isotropic scattering at albedo 1) the sample variance is 0 and the mean is 1 up to rounding. */
#define ROUNDING 1e-9

enum { TECHNIQUES = DWV_TECHNIQUE_CYCLES + 1 };

/* ---- albedo 1: R + T = 1 ------------------------------------------------------------------- */

enum { CONSERVATIVE_WALKS = 20000 };
typedef struct conservative_case_t { double anisotropy, thickness; } conservative_case_t;
static const conservative_case_t CONSERVATIVE_CASES[] = {
    {0.0, 0.1}, {0.0, 1.0}, {0.0, 4.0}, {0.0, 10.0}, {0.5, 0.1}, {0.5, 1.0}, {-0.3, 0.1}, {-0.3, 1.0},
};

static void test_conservative_slabs(void)
{
    printf("albedo 1, slab, light = both: R + T = 1 (|mean - 1| <= %.0f std errors + %.0e)\n", SIGMAS, ROUNDING);
    for (size_t k = 0; k < sizeof CONSERVATIVE_CASES / sizeof CONSERVATIVE_CASES[0]; ++k) {
        double d = CONSERVATIVE_CASES[k].thickness, g = CONSERVATIVE_CASES[k].anisotropy;
        printf("  g %4g  d %4g:", g, d);
        for (dwv_technique_t t = 0; t < TECHNIQUES; ++t) {
            dwv_estimate_options_t options = DWV_ESTIMATE_OPTIONS_INIT;
            options.shape = DWV_SHAPE_SLAB;
            options.thickness = d;
            options.medium.albedo[0] = 1.0;
            options.medium.anisotropy = g;
            options.light = DWV_LIGHT_BOTH;
            options.technique = t;
            dwv_estimate_result_t r = estimate(options, CONSERVATIVE_WALKS);
            double z = r.std_error[0] > 0.0 ? (r.mean[0] - 1.0) / r.std_error[0] : 0.0;
            printf("  %s %.6f (z %.2f)", dwv_technique_name(t), r.mean[0], z);
            CHECK(fabs(r.mean[0] - 1.0) <= SIGMAS * r.std_error[0] + ROUNDING,
                  "albedo 1, g %g, d %g, %s: R + T = %.12f +- %.3e", g, d, dwv_technique_name(t), r.mean[0],
                  r.std_error[0]);
            CHECK(r.truncated_walks == 0 && r.truncated_weight[0] == 0.0,
                  "albedo 1, g %g, d %g, %s: %llu walks truncated, weight %g", g, d, dwv_technique_name(t),
                  (unsigned long long)r.truncated_walks, r.truncated_weight[0]);
        }
        printf("\n");
    }
}

enum { HALFSPACE_WALKS = 10000, MAX_EVENTS_HALFSPACE = 2000 };

static void test_conservative_halfspace(void)
{
    printf("albedo 1, half-space, at most %d events: mean + truncated_weight = 1 (within %.0e)\n",
           MAX_EVENTS_HALFSPACE, ROUNDING);
    for (dwv_technique_t t = 0; t < TECHNIQUES; ++t) {
        dwv_estimate_options_t options = DWV_ESTIMATE_OPTIONS_INIT;
        options.medium.albedo[0] = 1.0;
        options.technique = t;
        options.max_events = MAX_EVENTS_HALFSPACE;
        dwv_estimate_result_t r = estimate(options, HALFSPACE_WALKS);
        printf("  %-9s mean %.8f  truncated weight %.8f  (%llu walks truncated)  sum - 1 = %.3g\n",
               dwv_technique_name(t), r.mean[0], r.truncated_weight[0], (unsigned long long)r.truncated_walks,
               r.mean[0] + r.truncated_weight[0] - 1.0);
        CHECK(fabs(r.mean[0] + r.truncated_weight[0] - 1.0) <= ROUNDING,
              "albedo 1 half-space %s: mean %.12f + truncated %.12f != 1", dwv_technique_name(t), r.mean[0],
              r.truncated_weight[0]);
        /* The cap must have been met (P(N > n) ~ n^(-1/2)): otherwise this checks nothing. */
        CHECK(r.truncated_walks > 0 && r.truncated_weight[0] > 0.0,
              "albedo 1 half-space %s: no walk reached %d events", dwv_technique_name(t), MAX_EVENTS_HALFSPACE);
    }
}

/* ---- albedo < 1: both = front + back ------------------------------------------------------- */

enum { SUM_WALKS = 40000 };

typedef struct sum_scene_t {
    const char *name;
    dwv_shape_t shape;
    double size;
} sum_scene_t;

static const sum_scene_t SUM_SCENES[] = {
    {"slab 1", DWV_SHAPE_SLAB, 1.0},
    {"slab 4", DWV_SHAPE_SLAB, 4.0},
    {"sphere 2", DWV_SHAPE_SPHERE, 2.0},
};
static const double SUM_ALBEDOS[] = {0.9, 0.99};

static void test_both_is_sum(void)
{
    printf("light = both against front + back (|z| <= %.0f)\n", SIGMAS);
    printf("  %-9s %-5s %-9s %12s %12s %12s %12s %8s\n", "scene", "alb", "technique", "front", "back", "front+back",
           "both", "z");
    for (size_t s = 0; s < sizeof SUM_SCENES / sizeof SUM_SCENES[0]; ++s) {
        for (size_t a = 0; a < sizeof SUM_ALBEDOS / sizeof SUM_ALBEDOS[0]; ++a) {
            for (dwv_technique_t t = 0; t < TECHNIQUES; ++t) {
                dwv_estimate_options_t options = DWV_ESTIMATE_OPTIONS_INIT;
                options.shape = SUM_SCENES[s].shape;
                options.thickness = SUM_SCENES[s].size;
                options.radius = SUM_SCENES[s].size;
                options.medium.albedo[0] = SUM_ALBEDOS[a];
                options.technique = t;
                dwv_estimate_result_t r[3];
                for (int light = DWV_LIGHT_FRONT; light <= DWV_LIGHT_BOTH; ++light) {
                    options.light = light;
                    r[light - 1] = estimate(options, SUM_WALKS);
                }
                const dwv_estimate_result_t *front = &r[0], *back = &r[1], *both = &r[2];
                double sum = front->mean[0] + back->mean[0];
                double sigma = sqrt(front->std_error[0] * front->std_error[0] + back->std_error[0] * back->std_error[0] +
                                    both->std_error[0] * both->std_error[0]);
                double z = (both->mean[0] - sum) / sigma;
                printf("  %-9s %-5g %-9s %12.8f %12.8f %12.8f %12.8f %8.2f\n", SUM_SCENES[s].name, SUM_ALBEDOS[a],
                       dwv_technique_name(t), front->mean[0], back->mean[0], sum, both->mean[0], z);
                CHECK(fabs(z) <= SIGMAS, "%s albedo %g %s: both %.8f vs front + back %.8f, sigma %.3e: z = %.2f",
                      SUM_SCENES[s].name, SUM_ALBEDOS[a], dwv_technique_name(t), both->mean[0], sum, sigma, z);
            }
        }
    }
}

int main(void)
{
    test_conservative_slabs();
    test_conservative_halfspace();
    test_both_is_sum();
    return check_report("test_walk_energy");
}
