/* What dwv_estimate reports besides the mean:
 *   determinism  walks are summed in blocks fixed by the walk count, so the same options give
 *                bit-identical results (means, errors, variances, event counts, truncation) with 1,
 *                2 or 3 threads;
 *   truncation   walks ended by the event cap report the weight they still had: with at most 5
 *                events at albedo 0.99 many walks are cut, truncated_walks > 0 and
 *                truncated_weight > 0. A capped walk's weight w would have gone on to score
 *                w V, V <= 1 the probability that the rest of the walk leaves through a lit face,
 *                so in expectation mean_capped <= mean_full <= mean_capped + truncated_weight:
 *                checked within 5 sigma (sigma from the two means' standard errors; the bound on
 *                the right has slack 1 - V, which is large after 5 events). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* Every run here sets its own seed and thread count: no WALK_SEED_BASE. */
#include "walk_harness.h"

/* ---- determinism --------------------------------------------------------------------------- */

static int same_bits(const double *a, const double *b, int n)
{
    return memcmp(a, b, (size_t)n * sizeof *a) == 0;
}

static void check_identical(const char *what, const dwv_estimate_result_t *a, const dwv_estimate_result_t *b,
                            uint32_t threads)
{
    int channels = (int)a->channels;
    CHECK(a->channels == b->channels, "%s, %u threads: channels %u vs %u", what, threads, a->channels, b->channels);
    CHECK(same_bits(a->mean, b->mean, channels), "%s, %u threads: mean %.17g vs %.17g", what, threads, a->mean[0],
          b->mean[0]);
    CHECK(same_bits(a->std_error, b->std_error, channels), "%s, %u threads: std error %.17g vs %.17g", what, threads,
          a->std_error[0], b->std_error[0]);
    CHECK(same_bits(a->variance, b->variance, channels), "%s, %u threads: variance %.17g vs %.17g", what, threads,
          a->variance[0], b->variance[0]);
    CHECK(same_bits(a->truncated_weight, b->truncated_weight, channels), "%s, %u threads: truncated weight %.17g vs %.17g",
          what, threads, a->truncated_weight[0], b->truncated_weight[0]);
    CHECK(a->walks == b->walks && a->events == b->events && a->truncated_walks == b->truncated_walks,
          "%s, %u threads: walks %llu/%llu, events %llu/%llu, truncated %llu/%llu", what, threads,
          (unsigned long long)a->walks, (unsigned long long)b->walks, (unsigned long long)a->events,
          (unsigned long long)b->events, (unsigned long long)a->truncated_walks,
          (unsigned long long)b->truncated_walks);
}

static void test_determinism(void)
{
    printf("determinism: 1, 2 and 3 threads give bit-identical results\n");
    for (dwv_technique_t t = DWV_TECHNIQUE_AUTO; t <= DWV_TECHNIQUE_SHEET; ++t) {
        /* A three-channel slab lit from both sides with a cap that some walks meet: every field of
         * the result is exercised. The walk count is not a multiple of the block size. */
        dwv_estimate_options_t options = DWV_ESTIMATE_OPTIONS_INIT;
        options.shape = DWV_SHAPE_SLAB;
        options.thickness = 3.0;
        options.medium.channels = 3;
        options.medium.sigma_t[1] = 1.5;
        options.medium.albedo[0] = 0.95, options.medium.albedo[1] = 0.99, options.medium.albedo[2] = 0.7;
        options.medium.anisotropy = 0.3;
        options.light = DWV_LIGHT_BOTH;
        options.technique = t;
        options.walks = 30001;
        options.seed = 77;
        options.max_events = 40;
        options.threads = 1;
        dwv_estimate_result_t one = run_estimate(&options);
        CHECK(one.truncated_walks > 0, "%s: no walk met the cap of %u events", dwv_technique_name(t), options.max_events);
        for (uint32_t threads = 2; threads <= 3; ++threads) {
            options.threads = threads;
            dwv_estimate_result_t many = run_estimate(&options);
            check_identical(dwv_technique_name(t), &one, &many, threads);
        }
        printf("  %-9s mean %.17g %.17g %.17g  events %llu  truncated %llu\n", dwv_technique_name(t), one.mean[0],
               one.mean[1], one.mean[2], (unsigned long long)one.events, (unsigned long long)one.truncated_walks);
    }
}

/* ---- truncation ---------------------------------------------------------------------------- */

#define SIGMAS 5.0
enum { TRUNCATION_WALKS = 100000, CAP = 5 };

static void test_truncation(void)
{
    printf("truncation at %d events, half-space, albedo 0.99 (within %.0f sigma)\n", CAP, SIGMAS);
    printf("  %-9s %12s %12s %12s %10s %10s\n", "technique", "capped", "truncated", "full", "sigma", "cut walks");
    for (dwv_technique_t t = DWV_TECHNIQUE_AUTO; t <= DWV_TECHNIQUE_SHEET; ++t) {
        dwv_estimate_options_t options = DWV_ESTIMATE_OPTIONS_INIT;
        options.medium.albedo[0] = 0.99;
        options.technique = t;
        options.walks = TRUNCATION_WALKS;
        options.threads = 2;
        options.seed = 1000u + (uint64_t)t;
        options.max_events = CAP;
        dwv_estimate_result_t capped = run_estimate(&options);
        options.seed = 2000u + (uint64_t)t; /* independent of the capped run */
        options.max_events = 0;
        dwv_estimate_result_t full = run_estimate(&options);
        double sigma = sqrt(capped.std_error[0] * capped.std_error[0] + full.std_error[0] * full.std_error[0]);
        printf("  %-9s %12.8f %12.8f %12.8f %10.3e %10llu\n", dwv_technique_name(t), capped.mean[0],
               capped.truncated_weight[0], full.mean[0], sigma, (unsigned long long)capped.truncated_walks);
        CHECK(capped.truncated_walks > 0 && capped.truncated_weight[0] > 0.0,
              "%s: %llu walks truncated with weight %g at a cap of %d events", dwv_technique_name(t),
              (unsigned long long)capped.truncated_walks, capped.truncated_weight[0], CAP);
        CHECK(full.truncated_walks == 0 && full.truncated_weight[0] == 0.0, "%s: %llu walks truncated at 10^6 events",
              dwv_technique_name(t), (unsigned long long)full.truncated_walks);
        CHECK(capped.mean[0] <= full.mean[0] + SIGMAS * sigma, "%s: capped mean %.8f above the full mean %.8f + %.0f sigma",
              dwv_technique_name(t), capped.mean[0], full.mean[0], SIGMAS);
        CHECK(full.mean[0] <= capped.mean[0] + capped.truncated_weight[0] + SIGMAS * sigma,
              "%s: full mean %.8f above capped mean %.8f + truncated weight %.8f + %.0f sigma", dwv_technique_name(t),
              full.mean[0], capped.mean[0], capped.truncated_weight[0], SIGMAS);
    }
}

int main(void)
{
    test_determinism();
    test_truncation();
    return check_report("test_walk_bookkeeping");
}
