/* What the random-walk tests of the public API (tests/unit/test_walk_*.c) share: a dwv_estimate
 * call that must succeed, runs with a seed of their own, a run's walk count chosen from a pilot
 * run, the transport references of tests/data/walk_reference.csv (tools/gen_walk_reference.py,
 * mpmath), and the z-scores that compare estimates with a reference or with each other.
 *
 * A test whose runs take their seeds from here defines WALK_SEED_BASE, the seed of its first run,
 * before including this header: every test file draws from seeds of its own, so that each test
 * draws the same random numbers however the others change. */
#ifndef DWV_TESTS_WALK_HARNESS_H
#define DWV_TESTS_WALK_HARNESS_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include <dwivedi.h>

/* ---- estimates ----------------------------------------------------------------------------- */

/* dwv_estimate with the options exactly as given. */
static inline dwv_estimate_result_t run_estimate(const dwv_estimate_options_t *options)
{
    dwv_estimate_result_t result = DWV_ESTIMATE_RESULT_INIT;
    dwv_result_t rc = dwv_estimate(options, &result);
    CHECK(rc == DWV_SUCCESS, "dwv_estimate: %s", dwv_last_error_message());
    return result;
}

#ifdef WALK_SEED_BASE

/* Every run has a seed of its own, so that estimates compared with each other are independent. */
static uint64_t next_seed = WALK_SEED_BASE;

/* A run of `walks` walks on 2 threads with the next seed. */
static inline dwv_estimate_result_t estimate(dwv_estimate_options_t options, uint64_t walks)
{
    options.walks = walks;
    options.seed = next_seed++;
    options.threads = 2;
    return run_estimate(&options);
}

/* How estimate_to_precision spends walks: a pilot run of pilot_walks gives the variance per walk,
 * and the final run takes the walks for a standard error of target_relative_error x the pilot
 * mean, held within [min_walks, max_walks]; a pilot mean of 0 sets no target, and the run takes
 * zero_mean_walks. */
typedef struct walk_budget_t {
    uint64_t pilot_walks, min_walks, max_walks, zero_mean_walks;
    double target_relative_error;
} walk_budget_t;

/* A run whose standard error is about budget->target_relative_error of its mean: the walk count
 * comes from the variance per walk of an independent pilot run. */
static inline dwv_estimate_result_t estimate_to_precision(dwv_estimate_options_t options, const walk_budget_t *budget)
{
    dwv_estimate_result_t pilot = estimate(options, budget->pilot_walks);
    double target = budget->target_relative_error * pilot.mean[0];
    double walks = target > 0.0 ? ceil(pilot.variance[0] / (target * target)) : (double)budget->zero_mean_walks;
    walks = fmin(fmax(walks, (double)budget->min_walks), (double)budget->max_walks);
    return estimate(options, (uint64_t)walks);
}

#endif /* WALK_SEED_BASE */

/* ---- scenes -------------------------------------------------------------------------------- */

typedef struct scene_t {
    const char *name;
    dwv_shape_t shape;
    double size; /* slab thickness or sphere radius, in the units of 1/sigma_t */
    dwv_light_t light;
} scene_t;

/* Default options but for the scene and the technique. */
static inline dwv_estimate_options_t scene_options(const scene_t *scene, dwv_technique_t technique)
{
    dwv_estimate_options_t options = DWV_ESTIMATE_OPTIONS_INIT;
    options.shape = scene->shape;
    options.thickness = scene->shape == DWV_SHAPE_SLAB ? scene->size : options.thickness;
    options.radius = scene->shape == DWV_SHAPE_SPHERE ? scene->size : options.radius;
    options.light = scene->light;
    options.technique = technique;
    return options;
}

/* ---- the reference table ------------------------------------------------------------------- */

typedef struct reference_t {
    char quantity[32], shape[32], incidence[32];
    double cosine, albedo, thickness;
    double value, remainder_bound; /* the exact value lies in [value, value + remainder_bound] */
} reference_t;

enum { MAX_REFERENCES = 128 };
static reference_t references[MAX_REFERENCES];
static int reference_count;

static const char REFERENCE_COLUMNS[] = "quantity,shape,incidence,cosine,albedo,thickness,value,remainder_bound";

static inline void load_references(void)
{
    const char *path = DWV_TEST_DATA_DIR "/walk_reference.csv";
    FILE *file = fopen(path, "r");
    CHECK(file != NULL, "cannot open %s", path);
    if (file == NULL) return;
    char line[1024];
    int columns_seen = 0;
    while (fgets(line, sizeof line, file) != NULL) {
        line[strcspn(line, "\r\n")] = '\0';
        if (line[0] == '#' || line[0] == '\0') continue;
        if (!columns_seen) {
            CHECK(strcmp(line, REFERENCE_COLUMNS) == 0, "unexpected columns '%s'", line);
            columns_seen = 1;
            continue;
        }
        CHECK(reference_count < MAX_REFERENCES, "more than %d references", MAX_REFERENCES);
        if (reference_count >= MAX_REFERENCES) break;
        reference_t *r = &references[reference_count];
        int fields = sscanf(line, "%31[^,],%31[^,],%31[^,],%lf,%lf,%lf,%lf,%lf", r->quantity, r->shape, r->incidence,
                            &r->cosine, &r->albedo, &r->thickness, &r->value, &r->remainder_bound);
        CHECK(fields == 8, "malformed reference line '%s'", line);
        if (fields == 8) ++reference_count;
    }
    fclose(file);
}

/* The reference for exactly these parameters (the CSV writes each double so that it parses back
 * to the same double as the literal here), or NULL after a failed check. */
static inline const reference_t *find_reference(const char *quantity, const char *shape, const char *incidence,
                                                double cosine, double albedo, double thickness)
{
    for (int i = 0; i < reference_count; ++i) {
        const reference_t *r = &references[i];
        if (strcmp(r->quantity, quantity) == 0 && strcmp(r->shape, shape) == 0 &&
            strcmp(r->incidence, incidence) == 0 && r->cosine == cosine && r->albedo == albedo &&
            r->thickness == thickness)
            return r;
    }
    CHECK(0, "no reference for %s %s %s cosine %g albedo %g thickness %g", quantity, shape, incidence, cosine, albedo,
          thickness);
    return NULL;
}

/* An incidence of the light and where the reference table lists it. */
typedef struct incidence_case_t {
    dwv_incidence_t incidence;
    double cosine;        /* for DWV_INCIDENCE_COSINE */
    const char *csv_name; /* the reference table's incidence column */
    double csv_cosine;    /* the reference table's cosine column */
    const char *label;
} incidence_case_t;

/* ---- z-scores ------------------------------------------------------------------------------ */

/* The z-score of `mean` against a reference interval [value, value + bound]: its distance outside
 * the interval in units of `sigma` (0 inside). */
static inline double interval_z(double mean, double sigma, double value, double bound)
{
    double below = value - mean, above = mean - (value + bound);
    double outside = below > 0.0 ? -below : above > 0.0 ? above : 0.0;
    return outside == 0.0 ? 0.0 : outside / sigma;
}

/* The z-score of the difference of two independent estimates, sigma = sqrt(se_a^2 + se_b^2). */
static inline double difference_z(double mean_a, double std_error_a, double mean_b, double std_error_b)
{
    double sigma = sqrt(std_error_a * std_error_a + std_error_b * std_error_b);
    return (mean_a - mean_b) / sigma;
}

#endif
