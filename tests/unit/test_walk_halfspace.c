/* Unbiasedness of every random-walk technique on the isotropically scattering half-space, against
 * transport theory: the total diffuse reflectance R(mu0) = 1 - H(mu0) sqrt(1 - alpha) of
 * Chandrasekhar's albedo problem at normal (mu0 = 1) and oblique (mu0 = 0.5) incidence, and R_d for
 * cosine-weighted diffuse incidence, from tests/data/walk_reference.csv (tools/gen_walk_reference.py,
 * mpmath). Each estimate must lie within 5 standard errors of the reference, and within 1 percent
 * of it as a sanity bound: walk counts are chosen from a pilot run so that the standard error is
 * about 0.2 percent of the mean, which makes 1 percent a 5-sigma bound as well. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#define WALK_SEED_BASE 0x5eed0001u
#include "walk_harness.h"

/* Walk counts from a pilot run, for a standard error of about 0.2 percent of the mean. */
static const walk_budget_t BUDGET = {
    .pilot_walks = 10000, .min_walks = 20000, .max_walks = 3000000, .zero_mean_walks = 20000,
    .target_relative_error = 0.002,
};

/* ---- bounds and cases ---------------------------------------------------------------------- */

#define SIGMAS 5.0
#define RELATIVE_BOUND 0.01

static const double ALBEDOS[] = {0.3, 0.5, 0.9, 0.99, 0.999};

static const incidence_case_t INCIDENCES[] = {
    {DWV_INCIDENCE_COSINE, 1.0, "cosine", 1.0, "R(1)"},
    {DWV_INCIDENCE_COSINE, 0.5, "cosine", 0.5, "R(0.5)"},
    {DWV_INCIDENCE_DIFFUSE, 1.0, "diffuse", 0.0, "R_d"},
};

int main(void)
{
    load_references();
    printf("half-space total diffuse reflectance against Chandrasekhar's H function (|z| <= %.0f, "
           "relative error < %.0f%%)\n", SIGMAS, 100.0 * RELATIVE_BOUND);
    printf("  %-7s %-6s %-9s %12s %12s %10s %8s %9s %9s\n", "case", "albedo", "technique", "reference", "mean",
           "std error", "z", "rel err", "walks");
    for (size_t i = 0; i < sizeof INCIDENCES / sizeof INCIDENCES[0]; ++i) {
        const incidence_case_t *inc = &INCIDENCES[i];
        for (size_t a = 0; a < sizeof ALBEDOS / sizeof ALBEDOS[0]; ++a) {
            const reference_t *ref =
                find_reference("reflectance", "halfspace", inc->csv_name, inc->csv_cosine, ALBEDOS[a], INFINITY);
            if (ref == NULL) continue;
            for (dwv_technique_t t = DWV_TECHNIQUE_AUTO; t <= DWV_TECHNIQUE_CYCLES; ++t) {
                dwv_estimate_options_t options = DWV_ESTIMATE_OPTIONS_INIT;
                options.shape = DWV_SHAPE_HALFSPACE;
                options.medium.albedo[0] = ALBEDOS[a];
                options.incidence = inc->incidence;
                options.incidence_cosine = inc->cosine;
                options.light = DWV_LIGHT_FRONT;
                options.technique = t;
                dwv_estimate_result_t r = estimate_to_precision(options, &BUDGET);
                double z = interval_z(r.mean[0], r.std_error[0], ref->value, ref->remainder_bound);
                double relative = (r.mean[0] - ref->value) / ref->value;
                printf("  %-7s %-6g %-9s %12.8f %12.8f %10.3e %8.2f %8.4f%% %9llu\n", inc->label, ALBEDOS[a],
                       dwv_technique_name(t), ref->value, r.mean[0], r.std_error[0], z, 100.0 * relative,
                       (unsigned long long)r.walks);
                CHECK(fabs(z) <= SIGMAS, "%s albedo %g %s: mean %.8f, std error %.3e, reference %.8f: z = %.2f",
                      inc->label, ALBEDOS[a], dwv_technique_name(t), r.mean[0], r.std_error[0], ref->value, z);
                CHECK(fabs(relative) < RELATIVE_BOUND, "%s albedo %g %s: relative error %.4f%% (mean %.8f, reference %.8f)",
                      inc->label, ALBEDOS[a], dwv_technique_name(t), 100.0 * relative, r.mean[0], ref->value);
                CHECK(r.truncated_walks == 0, "%s albedo %g %s: %llu walks truncated", inc->label, ALBEDOS[a],
                      dwv_technique_name(t), (unsigned long long)r.truncated_walks);
            }
        }
    }
    return check_report("test_walk_halfspace");
}
