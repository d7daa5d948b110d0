/* The unbiasedness harness catches a wrong pdf. The walk is driven here step by step through the
 * internal API (src/walk/walk.h), exactly as dwv_estimate's run_walk drives it, on the front-lit
 * half-space at normal incidence, and its mean total diffuse reflectance is judged by the same
 * rule as tests/unit/test_walk_halfspace.c: within 5 standard errors of Chandrasekhar's
 * R(1) = 1 - H(1) sqrt(1 - alpha) from tests/data/walk_reference.csv. Then the same walks are run
 * with a planted error: between dwvw_walk_sample and dwvw_walk_complete the direction pdf of every
 * guided component (k >= 1) is multiplied by 1.05, the kind of slip (a pdf that does not match its
 * sampler) that made a renderer's images "slightly brighter", and by 1.005, to show the margin.
 * Asserted both ways: the honest walks pass, the tampered ones are rejected, for auto (MIS with a
 * classical component) and poe (guided only) at two albedos. The honest loop is also checked against dwv_estimate itself (same seed:
 * same walks, same mean up to summation order), so what passes is the shipped estimator. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include <dwivedi.h>
#include "kernel/rng.h"
#include "walk/estimate.h"
#include "walk/geometry.h"
#include "walk/walk.h"

/* ---- the reference ------------------------------------------------------------------------- */

typedef struct reference_t { double value, remainder_bound; } reference_t;

/* R(1) of the half-space at `albedo` from the reference table (the exact value lies in [value,
 * value + remainder_bound]); value NaN after a failed check. */
static reference_t halfspace_reference(double albedo)
{
    const char *path = DWV_TEST_DATA_DIR "/walk_reference.csv";
    FILE *file = fopen(path, "r");
    reference_t found = {NAN, NAN};
    CHECK(file != NULL, "cannot open %s", path);
    if (file == NULL) return found;
    char line[1024];
    while (fgets(line, sizeof line, file) != NULL) {
        char quantity[32], shape[32], incidence[32];
        double cosine, a, thickness, value, bound;
        if (sscanf(line, "%31[^,],%31[^,],%31[^,],%lf,%lf,%lf,%lf,%lf", quantity, shape, incidence, &cosine, &a,
                   &thickness, &value, &bound) != 8)
            continue;
        if (strcmp(quantity, "reflectance") == 0 && strcmp(shape, "halfspace") == 0 &&
            strcmp(incidence, "cosine") == 0 && cosine == 1.0 && a == albedo)
            found.value = value, found.remainder_bound = bound;
    }
    fclose(file);
    CHECK(!isnan(found.value), "no half-space R(1) reference for albedo %g in %s", albedo, path);
    return found;
}

/* ---- the harness (the rule of tests/unit/test_walk_halfspace.c) ----------------------------- */

#define SIGMAS 5.0

/* The z-score of `mean` against a reference interval [value, value + bound]: its distance outside
 * the interval in standard errors (0 inside). */
static double interval_z(double mean, double std_error, double value, double bound)
{
    double below = value - mean, above = mean - (value + bound);
    double outside = below > 0.0 ? -below : above > 0.0 ? above : 0.0;
    return outside == 0.0 ? 0.0 : outside / std_error;
}

static int agrees_with_reference(double z)
{
    return fabs(z) <= SIGMAS;
}

/* ---- the walks ----------------------------------------------------------------------------- */

typedef struct run_result {
    double mean, std_error;
    uint64_t events;
} run_result;

/* `walks` walks of dwv_estimate's seed `seed` on the front-lit half-space at normal incidence,
 * with the guided components' direction pdfs multiplied by `pdf_factor` before each step is
 * weighted (1: the honest walk). */
static run_result run_walks(const dwvw_medium *medium, const dwvw_guide *guide, uint64_t seed, uint64_t walks,
                            double pdf_factor)
{
    const dwvw_shape halfspace = {DWVW_HALFSPACE, 0.0, 0.0};
    const dwvu_vec3 origin = {0.0, 0.0, 0.0}, inward = {0.0, 0.0, 1.0}, outward = {0.0, 0.0, -1.0};
    int needs_closest = dwvw_guide_needs_closest(guide);
    double sum = 0.0, sum_squares = 0.0;
    run_result result = {0.0, 0.0, 0u};
    for (uint64_t i = 0; i < walks; ++i) {
        dwvw_walk walk;
        dwvw_walk_begin(&walk, medium, guide, dwvk_rng_key(seed, i, 0), 1000000u, origin, inward, outward);
        while (walk.status == DWVW_RUNNING) {
            if (needs_closest) {
                dwvu_vec3 n;
                dwvw_shape_closest(&halfspace, walk.position, &n);
                dwvw_walk_set_closest(&walk, n);
            }
            dwvw_walk_sample(&walk);
            dwvu_vec3 hit_normal;
            double hit = dwvw_shape_exit(&halfspace, walk.position, walk.direction, &hit_normal);
            for (int k = 1; k < walk.component_count; ++k) walk.component_pdf[k] *= pdf_factor;
            dwvw_walk_complete(&walk, hit, hit_normal);
        }
        double score = walk.status == DWVW_EXITED && walk.exit_normal.z < 0.0 ? walk.weight[0] : 0.0;
        sum += score;
        sum_squares += score * score;
        result.events += walk.events;
    }
    double n = (double)walks;
    result.mean = sum / n;
    result.std_error = sqrt(fmax(0.0, (sum_squares - n * result.mean * result.mean) / (n - 1.0)) / n);
    return result;
}

enum { WALKS = 100000 };
static const double PLANTED_PDF_FACTORS[] = {1.05, 1.005};

static void test_case(dwvw_technique technique, dwv_technique_t api_technique, double albedo, uint64_t seed)
{
    reference_t reference = halfspace_reference(albedo);
    if (isnan(reference.value)) return;
    const double sigma_t = 1.0;
    dwvw_medium medium;
    dwvw_medium_init(&medium, 1, &sigma_t, &albedo, 0.0);
    const dwvw_shape halfspace = {DWVW_HALFSPACE, 0.0, 0.0};
    dwvw_light_patch patches[DWVW_MAX_PATCHES];
    int patch_count = dwvw_estimate_light_patches(&halfspace, DWVW_LIGHT_FRONT, patches);
    dwvw_guide guide;
    dwvw_guide_init(&guide, technique, &medium, patches, patch_count);

    run_result honest = run_walks(&medium, &guide, seed, WALKS, 1.0);

    dwv_estimate_options_t options = DWV_ESTIMATE_OPTIONS_INIT;
    options.medium.albedo[0] = albedo;
    options.technique = api_technique;
    options.walks = WALKS;
    options.seed = seed;
    options.threads = 2;
    dwv_estimate_result_t shipped = DWV_ESTIMATE_RESULT_INIT;
    CHECK(dwv_estimate(&options, &shipped) == DWV_SUCCESS, "dwv_estimate: %s", dwv_last_error_message());

    const char *name = dwv_technique_name(api_technique);
    double z_honest = interval_z(honest.mean, honest.std_error, reference.value, reference.remainder_bound);
    printf("  %-5s albedo %-5g reference %.8f  honest %.8f +- %.2e z %6.2f  dwv_estimate %.8f\n", name, albedo,
           reference.value, honest.mean, honest.std_error, z_honest, shipped.mean[0]);

    CHECK(fabs(honest.mean - shipped.mean[0]) <= 1e-12 * shipped.mean[0] && honest.events == shipped.events,
          "%s albedo %g: the internal loop (%.17g, %llu events) is not dwv_estimate (%.17g, %llu events)", name,
          albedo, honest.mean, (unsigned long long)honest.events, shipped.mean[0],
          (unsigned long long)shipped.events);
    CHECK(agrees_with_reference(z_honest), "%s albedo %g: the honest walks are rejected: %.8f +- %.2e vs %.8f, z = %.2f",
          name, albedo, honest.mean, honest.std_error, reference.value, z_honest);
    for (size_t f = 0; f < sizeof PLANTED_PDF_FACTORS / sizeof PLANTED_PDF_FACTORS[0]; ++f) {
        double factor = PLANTED_PDF_FACTORS[f];
        run_result planted = run_walks(&medium, &guide, seed, WALKS, factor);
        double z_planted = interval_z(planted.mean, planted.std_error, reference.value, reference.remainder_bound);
        printf("  %-5s albedo %-5g guided pdf x %-5g: %.8f +- %.2e z %8.2f  %s\n", name, albedo, factor, planted.mean,
               planted.std_error, z_planted, agrees_with_reference(z_planted) ? "ACCEPTED" : "rejected");
        CHECK(!agrees_with_reference(z_planted),
              "%s albedo %g: the planted pdf x %g is not caught: %.8f +- %.2e vs %.8f, z = %.2f", name, albedo, factor,
              planted.mean, planted.std_error, reference.value, z_planted);
    }
}

int main(void)
{
    printf("planted wrong pdf, judged against the half-space R(1) (|z| <= %.0f)\n", SIGMAS);
    test_case(DWVW_AUTO, DWV_TECHNIQUE_AUTO, 0.9, 11u);
    test_case(DWVW_AUTO, DWV_TECHNIQUE_AUTO, 0.99, 12u);
    test_case(DWVW_POE, DWV_TECHNIQUE_POE, 0.9, 13u);
    test_case(DWVW_POE, DWV_TECHNIQUE_POE, 0.99, 14u);
    return check_report("test_walk_planted");
}
