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
#include <string.h>

#include "check.h"
#include "dwivedi.h"

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

static void load_references(void)
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
static const reference_t *find_reference(const char *quantity, const char *shape, const char *incidence,
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

/* ---- estimates ----------------------------------------------------------------------------- */

/* Every run has a seed of its own, so that estimates compared with each other are independent. */
static uint64_t next_seed = 0x5eed0001u;

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

enum { PILOT_WALKS = 10000, MIN_WALKS = 20000, MAX_WALKS = 3000000 };
#define TARGET_RELATIVE_ERROR 0.002

/* A run whose standard error is about TARGET_RELATIVE_ERROR of its mean: the walk count comes from
 * the variance per walk of an independent pilot run. */
static dwv_estimate_result_t estimate_to_precision(dwv_estimate_options_t options)
{
    dwv_estimate_result_t pilot = estimate(options, PILOT_WALKS);
    double target = TARGET_RELATIVE_ERROR * pilot.mean[0];
    double walks = target > 0.0 ? ceil(pilot.variance[0] / (target * target)) : MIN_WALKS;
    walks = fmin(fmax(walks, MIN_WALKS), MAX_WALKS);
    return estimate(options, (uint64_t)walks);
}

/* ---- the harness --------------------------------------------------------------------------- */

#define SIGMAS 5.0
#define RELATIVE_BOUND 0.01

/* The z-score of `mean` against a reference interval [value, value + bound]: its distance outside
 * the interval in standard errors (0 inside); the estimate agrees when |z| <= SIGMAS. */
static double interval_z(double mean, double std_error, double value, double bound)
{
    double below = value - mean, above = mean - (value + bound);
    double outside = below > 0.0 ? -below : above > 0.0 ? above : 0.0;
    return outside == 0.0 ? 0.0 : outside / std_error;
}

static const double ALBEDOS[] = {0.3, 0.5, 0.9, 0.99, 0.999};

typedef struct incidence_case_t {
    dwv_incidence_t incidence;
    double cosine;        /* for DWV_INCIDENCE_COSINE */
    const char *csv_name; /* the reference table's incidence column */
    double csv_cosine;    /* the reference table's cosine column */
    const char *label;
} incidence_case_t;

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
                dwv_estimate_result_t r = estimate_to_precision(options);
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
