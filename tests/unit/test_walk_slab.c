/* The random walks on a slab where transport theory gives the answer in closed form, against
 * tests/data/walk_reference.csv (tools/gen_walk_reference.py, mpmath):
 *   albedo 0     no light is scattered: the reflectance is exactly 0 for every technique, and the
 *                transmittance is exp(-d/mu0) at incidence cosine mu0, 2 E_3(d) for diffuse
 *                incidence (d in mean free paths), within 5 standard errors;
 *   small albedo the once-scattered light R_1 and exp(-d) + T_1 (normal incidence), with the
 *                generator's bound B on all higher orders: the estimate must lie within 5 standard
 *                errors of [R_1, R_1 + B] (B is 2 to 3 percent of R_1). Classical sampling and
 *                cycles, whose classical half bounds its weights (auto is classical sampling
 *                below albedo 0.2: the same estimator); a purely guided technique at albedo < 0.2
 *                samples a near-delta eigenfunction and its weights have no useful variance
 *                bound. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#define WALK_SEED_BASE 0x51ab0001u
#include "walk_harness.h"

/* ---- bounds and options -------------------------------------------------------------------- */

#define SIGMAS 5.0

/* An outcome of probability p is met by none of N walks with probability (1 - p)^N < exp(-p N):
 * below exp(-15) = 3e-7, the one-sided 5-sigma tail, for p >= 15/N. The sample variance cannot
 * see rarer outcomes; at albedo 0 the only other outcome is a collision, whose weight is 0, so
 * outcomes never met move the expected mean by at most (15/N) x the exit weight. This matters for
 * the incident technique, which at albedo 0 and normal incidence flies almost every walk straight
 * through (the eigenfunction's v is held at 1 + 2^-20) with one common weight: a sample variance
 * of 0. */
#define UNSEEN_OUTCOMES 15.0

static dwv_estimate_options_t slab_options(double thickness, double albedo, dwv_light_t light, dwv_technique_t technique)
{
    dwv_estimate_options_t options = DWV_ESTIMATE_OPTIONS_INIT;
    options.shape = DWV_SHAPE_SLAB;
    options.thickness = thickness;
    options.medium.albedo[0] = albedo;
    options.light = light;
    options.technique = technique;
    return options;
}

/* ---- albedo 0 ------------------------------------------------------------------------------ */

enum { UNSCATTERED_WALKS = 200000 };
static const double THICKNESSES[] = {0.1, 1.0, 4.0};

static const incidence_case_t INCIDENCES[] = {
    {DWV_INCIDENCE_COSINE, 1.0, "cosine", 1.0, "normal"},
    {DWV_INCIDENCE_COSINE, 0.5, "cosine", 0.5, "mu0=0.5"},
    {DWV_INCIDENCE_DIFFUSE, 1.0, "diffuse", 0.0, "diffuse"},
};

static void test_unscattered(void)
{
    printf("albedo 0: R == 0 exactly; T against exp(-d/mu0) or 2 E_3(d) (|z| <= %.0f, sigma = std error + "
           "%.0f x mean / walks)\n", SIGMAS, UNSEEN_OUTCOMES);
    printf("  %-8s %-5s %-9s %12s %12s %10s %8s %12s\n", "incidence", "d", "technique", "reference T", "mean T",
           "std error", "z", "R");
    for (size_t i = 0; i < sizeof INCIDENCES / sizeof INCIDENCES[0]; ++i) {
        const incidence_case_t *inc = &INCIDENCES[i];
        for (size_t k = 0; k < sizeof THICKNESSES / sizeof THICKNESSES[0]; ++k) {
            double d = THICKNESSES[k];
            const reference_t *t_ref = find_reference("transmittance", "slab", inc->csv_name, inc->csv_cosine, 0.0, d);
            const reference_t *r_ref = find_reference("reflectance", "slab", inc->csv_name, inc->csv_cosine, 0.0, d);
            if (t_ref == NULL || r_ref == NULL) continue;
            for (dwv_technique_t t = DWV_TECHNIQUE_AUTO; t <= DWV_TECHNIQUE_CYCLES; ++t) {
                dwv_estimate_options_t back = slab_options(d, 0.0, DWV_LIGHT_BACK, t);
                back.incidence = inc->incidence;
                back.incidence_cosine = inc->cosine;
                dwv_estimate_options_t front = back;
                front.light = DWV_LIGHT_FRONT;
                dwv_estimate_result_t tr = estimate(back, UNSCATTERED_WALKS);
                dwv_estimate_result_t rr = estimate(front, UNSCATTERED_WALKS);
                double sigma = tr.std_error[0] + UNSEEN_OUTCOMES * tr.mean[0] / (double)tr.walks;
                double z = interval_z(tr.mean[0], sigma, t_ref->value, t_ref->remainder_bound);
                printf("  %-8s %-5g %-9s %12.8f %12.8f %10.3e %8.2f %12g\n", inc->label, d, dwv_technique_name(t),
                       t_ref->value, tr.mean[0], tr.std_error[0], z, rr.mean[0]);
                CHECK(fabs(z) <= SIGMAS, "albedo 0, %s, d %g, %s: T = %.8f, std error %.3e, reference %.8f: z = %.2f",
                      inc->label, d, dwv_technique_name(t), tr.mean[0], tr.std_error[0], t_ref->value, z);
                CHECK(rr.mean[0] == r_ref->value && r_ref->value == 0.0,
                      "albedo 0, %s, d %g, %s: R = %.17g, must be exactly 0", inc->label, d, dwv_technique_name(t),
                      rr.mean[0]);
                CHECK(rr.variance[0] == 0.0, "albedo 0, %s, d %g, %s: variance of R = %.17g, must be exactly 0",
                      inc->label, d, dwv_technique_name(t), rr.variance[0]);
            }
        }
    }
}

/* ---- single scattering --------------------------------------------------------------------- */

/* Walks per run: the standard error of R is then 0.35 to 0.45 percent of R_1. */
enum { SINGLE_SCATTERING_WALKS = 2000000 };

typedef struct single_case_t { double thickness, albedo; } single_case_t;
static const single_case_t SINGLE_CASES[] = {{0.1, 0.05}, {0.3, 0.02}, {1.0, 0.01}};
static const dwv_technique_t SINGLE_TECHNIQUES[] = {DWV_TECHNIQUE_CLASSICAL, DWV_TECHNIQUE_CYCLES};

static void test_single_scattering(void)
{
    printf("single scattering at normal incidence: estimate within %.0f std errors of [value, value + bound]\n", SIGMAS);
    printf("  %-3s %-4s %-5s %-9s %12s %10s %12s %10s %8s\n", "", "d", "alb", "technique", "value", "bound", "mean",
           "std error", "z");
    for (size_t i = 0; i < sizeof SINGLE_CASES / sizeof SINGLE_CASES[0]; ++i) {
        const single_case_t *c = &SINGLE_CASES[i];
        for (int side = 0; side < 2; ++side) {
            const char *quantity = side == 0 ? "reflectance" : "transmittance";
            const reference_t *ref = find_reference(quantity, "slab", "cosine", 1.0, c->albedo, c->thickness);
            if (ref == NULL) continue;
            for (size_t k = 0; k < sizeof SINGLE_TECHNIQUES / sizeof SINGLE_TECHNIQUES[0]; ++k) {
                dwv_technique_t t = SINGLE_TECHNIQUES[k];
                dwv_estimate_result_t r = estimate(
                    slab_options(c->thickness, c->albedo, side == 0 ? DWV_LIGHT_FRONT : DWV_LIGHT_BACK, t),
                    SINGLE_SCATTERING_WALKS);
                double z = interval_z(r.mean[0], r.std_error[0], ref->value, ref->remainder_bound);
                printf("  %-3s %-4g %-5g %-9s %12.8f %10.3e %12.8f %10.3e %8.2f\n", side == 0 ? "R" : "T",
                       c->thickness, c->albedo, dwv_technique_name(t), ref->value, ref->remainder_bound, r.mean[0],
                       r.std_error[0], z);
                CHECK(fabs(z) <= SIGMAS, "single scattering %s d %g albedo %g %s: mean %.8f, std error %.3e, "
                      "reference [%.8f, %.8f]: z = %.2f", quantity, c->thickness, c->albedo, dwv_technique_name(t),
                      r.mean[0], r.std_error[0], ref->value, ref->value + ref->remainder_bound, z);
            }
        }
    }
}

int main(void)
{
    load_references();
    test_unscattered();
    test_single_scattering();
    return check_report("test_walk_slab");
}
