/* The diffusion length v0 = 1/kappa0 by its four methods, and the eigenfunction, through the public
 * API only. The reference is tests/data/v0_reference.csv, made with mpmath by
 * tools/gen_v0_reference.py: the root of supplemental Eq. 8 and independent evaluations of Eqs. 10
 * and 11 (`case`) and of d'Eon and Krivanek 2020 (`deon`), each for the exact double albedo. */
#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include <dwivedi.h>

/* ---- the reference table ------------------------------------------------------------------- */

typedef struct kappa_triple_t {
    double kappa;
    double one_minus_kappa;
    double log_one_minus_kappa;
} kappa_triple_t;

typedef struct reference_row_t {
    double albedo;
    kappa_triple_t exact; /* the root of Eq. 8 */
    kappa_triple_t case_series;
    kappa_triple_t deon;
} reference_row_t;

enum { MAX_ROWS = 512, COLUMN_COUNT = 10 };

static const char EXPECTED_COLUMNS[] =
    "albedo,kappa,one_minus_kappa,log_one_minus_kappa,case_kappa,case_one_minus_kappa,deon_kappa,"
    "deon_one_minus_kappa,case_log_one_minus_kappa,deon_log_one_minus_kappa";

static reference_row_t rows[MAX_ROWS];
static int row_count;

/* Parses the CSV; values below the double range parse to 0 or a subnormal, above it to +-inf, as
 * the generator intends (strtod's ERANGE is expected there). */
static void load_reference(const char *path)
{
    FILE *file = fopen(path, "r");
    CHECK(file != NULL, "cannot open %s", path);
    if (file == NULL) return;
    char line[8192];
    bool columns_seen = false;
    while (fgets(line, sizeof line, file) != NULL) {
        size_t length = strlen(line);
        CHECK(length > 0 && line[length - 1] == '\n', "line longer than %zu characters in %s",
              sizeof line, path);
        while (length > 0 && (line[length - 1] == '\n' || line[length - 1] == '\r')) line[--length] = '\0';
        if (line[0] == '#' || length == 0) continue;
        if (!columns_seen) {
            CHECK(strcmp(line, EXPECTED_COLUMNS) == 0, "unexpected columns '%s'", line);
            columns_seen = true;
            continue;
        }
        double values[COLUMN_COUNT];
        char *cursor = line;
        int parsed = 0;
        for (; parsed < COLUMN_COUNT; ++parsed) {
            char *end;
            values[parsed] = strtod(cursor, &end);
            if (end == cursor) break;
            cursor = end;
            if (parsed + 1 < COLUMN_COUNT) {
                if (*cursor != ',') break;
                ++cursor;
            }
        }
        CHECK(parsed == COLUMN_COUNT && *cursor == '\0', "row %d of %s does not parse: '%.80s'",
              row_count + 1, path, line);
        if (parsed != COLUMN_COUNT || row_count == MAX_ROWS) continue;
        reference_row_t *row = &rows[row_count++];
        row->albedo = values[0];
        row->exact = (kappa_triple_t){values[1], values[2], values[3]};
        row->case_series = (kappa_triple_t){values[4], values[5], values[8]};
        row->deon = (kappa_triple_t){values[6], values[7], values[9]};
    }
    fclose(file);
    CHECK(columns_seen, "no column line in %s", path);
}

static const reference_row_t *find_row(double albedo)
{
    for (int i = 0; i < row_count; ++i)
        if (rows[i].albedo == albedo) return &rows[i];
    return NULL;
}

/* The table holds the albedos the task names, at least 60 in all, sorted. */
static void test_table(void)
{
    static const double required[] = {0.0,    1e-300, 1e-12,        1e-3, 0.0028, 0.01,
                                      0.5,    0.5599999999, 0.56, 0.9,    0.9999, 0.99999,
                                      1 - 1e-7, 1 - 1e-12, 1.0};
    CHECK(row_count >= 60, "only %d rows", row_count);
    for (size_t i = 0; i < sizeof required / sizeof required[0]; ++i)
        CHECK(find_row(required[i]) != NULL, "the table lacks alpha = %.17g", required[i]);
    for (int i = 1; i < row_count; ++i)
        CHECK(rows[i].albedo > rows[i - 1].albedo, "rows %d and %d are not in order", i - 1, i);
}

/* ---- the comparison harness ------------------------------------------------------------------ */

/* |got - reference| / |reference|; 0 only for equal values (so also for equal infinities), +inf
 * where the reference is 0 or infinite and got differs, NaN if got is NaN. */
static double relative_error(double got, double reference)
{
    if (got == reference) return 0.0;
    if (isnan(got)) return NAN;
    if (reference == 0.0 || isinf(reference)) return INFINITY;
    return fabs(got - reference) / fabs(reference);
}

typedef struct worst_t {
    double error;
    double albedo;
} worst_t;

typedef struct method_summary_t {
    worst_t kappa, one_minus_kappa, log_one_minus_kappa;
} method_summary_t;

static void note_worst(worst_t *worst, double error, double albedo)
{
    if (worst == NULL || isnan(worst->error)) return;
    if (isnan(error) || error > worst->error) {
        worst->error = error;
        worst->albedo = albedo;
    }
}

typedef struct tolerance_t {
    double kappa;               /* relative, everywhere */
    double one_minus_kappa;     /* relative, where the reference is a normal double */
    double log_one_minus_kappa; /* relative, where the reference is finite (equal where it is
                                   infinite); negative: not checked */
} tolerance_t;

/* How many of kappa, 1 - kappa and log(1 - kappa) in `got` miss `reference` by more than
 * `tolerance`; each miss is printed when `verbose`. */
static int count_misses(const char *method, double albedo, kappa_triple_t got, kappa_triple_t reference,
                        tolerance_t tolerance, method_summary_t *summary, bool verbose)
{
    int misses = 0;
    double error = relative_error(got.kappa, reference.kappa);
    note_worst(summary ? &summary->kappa : NULL, error, albedo);
    if (!(error <= tolerance.kappa)) {
        ++misses;
        if (verbose)
            fprintf(stderr, "%s: alpha = %.17g: kappa = %.17g, reference %.17g, relative error %.3g > %.3g\n",
                    method, albedo, got.kappa, reference.kappa, error, tolerance.kappa);
    }
    if (reference.one_minus_kappa >= DBL_MIN) {
        error = relative_error(got.one_minus_kappa, reference.one_minus_kappa);
        note_worst(summary ? &summary->one_minus_kappa : NULL, error, albedo);
        if (!(error <= tolerance.one_minus_kappa)) {
            ++misses;
            if (verbose)
                fprintf(stderr,
                        "%s: alpha = %.17g: 1 - kappa = %.17g, reference %.17g, relative error %.3g > %.3g\n",
                        method, albedo, got.one_minus_kappa, reference.one_minus_kappa, error,
                        tolerance.one_minus_kappa);
        }
    }
    if (tolerance.log_one_minus_kappa >= 0.0) {
        error = relative_error(got.log_one_minus_kappa, reference.log_one_minus_kappa);
        if (isfinite(reference.log_one_minus_kappa))
            note_worst(summary ? &summary->log_one_minus_kappa : NULL, error, albedo);
        if (!(error <= tolerance.log_one_minus_kappa)) {
            ++misses;
            if (verbose)
                fprintf(stderr,
                        "%s: alpha = %.17g: log(1 - kappa) = %.17g, reference %.17g, relative error %.3g > %.3g\n",
                        method, albedo, got.log_one_minus_kappa, reference.log_one_minus_kappa, error,
                        tolerance.log_one_minus_kappa);
        }
    }
    return misses;
}

/* How many members of a diffusion-length record are out of their documented ranges, or are
 * inconsistent with each other: kappa, 1 - kappa in [0, 1]; log(1 - kappa) <= 0, -inf only where
 * `log_may_be_infinite`; v0 = 1/kappa in [1, inf]; L in [0, inf]; nothing NaN. */
static int count_range_violations(const char *method, const dwv_diffusion_length_t *d,
                                  bool log_may_be_infinite, bool verbose)
{
    bool in_range = d->kappa >= 0.0 && d->kappa <= 1.0 && d->one_minus_kappa >= 0.0 &&
                    d->one_minus_kappa <= 1.0 && d->log_one_minus_kappa <= 0.0 &&
                    (log_may_be_infinite || isfinite(d->log_one_minus_kappa)) && d->v0 >= 1.0 &&
                    d->v0 == (d->kappa > 0.0 ? 1.0 / d->kappa : INFINITY) && d->log_ratio >= 0.0;
    if (!in_range && verbose)
        fprintf(stderr,
                "%s: alpha = %.17g: out of range: kappa %.17g, 1 - kappa %.17g, log(1 - kappa) %.17g, v0 %.17g, L %.17g\n",
                method, d->albedo, d->kappa, d->one_minus_kappa, d->log_one_minus_kappa, d->v0,
                d->log_ratio);
    return in_range ? 0 : 1;
}

/* Adjacent pairs out of order: direction +1 wants values[i] >= values[i-1], -1 the opposite; a NaN
 * is out of order with anything. The first offence is reported through `first`. */
static long count_order_violations(const double *values, long n, int direction, long *first)
{
    long violations = 0;
    *first = -1;
    for (long i = 1; i < n; ++i) {
        bool in_order = direction > 0 ? values[i] >= values[i - 1] : values[i] <= values[i - 1];
        if (!in_order) {
            if (violations++ == 0) *first = i;
        }
    }
    return violations;
}

static kappa_triple_t triple_of(const dwv_diffusion_length_t *d)
{
    return (kappa_triple_t){d->kappa, d->one_minus_kappa, d->log_one_minus_kappa};
}

/* Calls dwv_diffusion_length, which must succeed for albedo in [0, 1]. */
static dwv_diffusion_length_t diffusion_length(double albedo, dwv_v0_method_t method)
{
    dwv_diffusion_length_t d = DWV_DIFFUSION_LENGTH_INIT;
    dwv_result_t result = dwv_diffusion_length(albedo, method, &d);
    CHECK(result == DWV_SUCCESS, "dwv_diffusion_length(%.17g, %d) returned %d: %s", albedo, (int)method,
          (int)result, dwv_last_error_message());
    CHECK(d.method == method && d.albedo == albedo, "the record says method %d, alpha %.17g", (int)d.method,
          d.albedo);
    return d;
}

static void print_summary(const char *method, const method_summary_t *summary)
{
    printf("%-5s worst relative error: kappa %.3g (alpha %.17g), 1 - kappa %.3g (alpha %.17g), "
           "log(1 - kappa) %.3g (alpha %.17g)\n",
           method, summary->kappa.error, summary->kappa.albedo, summary->one_minus_kappa.error,
           summary->one_minus_kappa.albedo, summary->log_one_minus_kappa.error,
           summary->log_one_minus_kappa.albedo);
}

/* ---- exact ----------------------------------------------------------------------------------- */

/* The header promises kappa0 to double precision: these bounds are a few ulps. */
static const tolerance_t EXACT_TOLERANCE = {1e-14, 1e-12, 1e-12};

static void test_exact_against_reference(void)
{
    method_summary_t summary = {{0, 0}, {0, 0}, {0, 0}};
    worst_t log_ratio_identity = {0, 0};
    for (int i = 0; i < row_count; ++i) {
        const reference_row_t *row = &rows[i];
        dwv_diffusion_length_t d = diffusion_length(row->albedo, DWV_V0_EXACT);
        int misses = count_misses("exact", row->albedo, triple_of(&d), row->exact, EXACT_TOLERANCE,
                                  &summary, true);
        CHECK(misses == 0, "exact: %d values off at alpha = %.17g", misses, row->albedo);
        CHECK(count_range_violations("exact", &d, isinf(row->exact.log_one_minus_kappa), true) == 0,
              "exact: out of range at alpha = %.17g", row->albedo);
        if (row->albedo > 0.0 && row->albedo < 1.0) {
            /* L = 2 atanh(kappa0) = 2 kappa0 / alpha at the root of Eq. 8. */
            double identity = 2.0 * d.kappa / row->albedo;
            double error = relative_error(d.log_ratio, identity);
            note_worst(&log_ratio_identity, error, row->albedo);
            CHECK(error <= 1e-13, "exact: alpha = %.17g: L = %.17g, 2 kappa/alpha = %.17g (error %.3g)",
                  row->albedo, d.log_ratio, identity, error);
            /* L = log((v0 + 1)/(v0 - 1)) directly, where v0 - 1 >= 1e-3 keeps the rounding of v0
             * from being amplified more than 1000-fold (alpha above about 0.33). */
            if (isfinite(d.v0) && d.v0 - 1.0 >= 1e-3) {
                double direct = log1p(2.0 / (d.v0 - 1.0));
                error = relative_error(d.log_ratio, direct);
                CHECK(error <= 1e-13, "exact: alpha = %.17g: L = %.17g, log((v0+1)/(v0-1)) = %.17g (error %.3g)",
                      row->albedo, d.log_ratio, direct, error);
            }
        }
    }
    print_summary("exact", &summary);
    printf("exact worst relative error of L against 2 kappa/alpha: %.3g (alpha %.17g)\n",
           log_ratio_identity.error, log_ratio_identity.albedo);
}

static void test_exact_endpoints(void)
{
    dwv_diffusion_length_t zero = diffusion_length(0.0, DWV_V0_EXACT);
    CHECK(zero.kappa == 1.0 && zero.one_minus_kappa == 0.0 && zero.v0 == 1.0 &&
              zero.log_one_minus_kappa == -INFINITY && zero.log_ratio == INFINITY,
          "alpha = 0: kappa %.17g, 1 - kappa %.17g, v0 %.17g, log(1 - kappa) %.17g, L %.17g", zero.kappa,
          zero.one_minus_kappa, zero.v0, zero.log_one_minus_kappa, zero.log_ratio);
    dwv_diffusion_length_t negative_zero = diffusion_length(-0.0, DWV_V0_EXACT);
    CHECK(negative_zero.kappa == 1.0 && negative_zero.v0 == 1.0, "alpha = -0: kappa %.17g, v0 %.17g",
          negative_zero.kappa, negative_zero.v0);
    dwv_diffusion_length_t one = diffusion_length(1.0, DWV_V0_EXACT);
    CHECK(one.kappa == 0.0 && one.one_minus_kappa == 1.0 && one.v0 == INFINITY &&
              one.log_one_minus_kappa == 0.0 && one.log_ratio == 0.0,
          "alpha = 1: kappa %.17g, 1 - kappa %.17g, v0 %.17g, log(1 - kappa) %.17g, L %.17g", one.kappa,
          one.one_minus_kappa, one.v0, one.log_one_minus_kappa, one.log_ratio);
}

/* v0 non-decreasing and kappa non-increasing in alpha (so 1 - kappa and its log non-decreasing),
 * and v0 = 1/kappa, on a grid of n + 1 albedos alpha(i). */
static void check_exact_monotone(const char *grid, long n, double (*albedo_at)(long i, long n))
{
    double *v0 = malloc((size_t)(n + 1) * sizeof *v0);
    double *kappa = malloc((size_t)(n + 1) * sizeof *kappa);
    double *log_one_minus_kappa = malloc((size_t)(n + 1) * sizeof *log_one_minus_kappa);
    CHECK(v0 != NULL && kappa != NULL && log_one_minus_kappa != NULL, "out of memory (%ld)", n);
    if (v0 == NULL || kappa == NULL || log_one_minus_kappa == NULL) {
        free(v0), free(kappa), free(log_one_minus_kappa);
        return;
    }
    long failed_calls = 0, not_reciprocal = 0, first_not_reciprocal = -1;
    for (long i = 0; i <= n; ++i) {
        dwv_diffusion_length_t d = DWV_DIFFUSION_LENGTH_INIT;
        if (dwv_diffusion_length(albedo_at(i, n), DWV_V0_EXACT, &d) != DWV_SUCCESS) ++failed_calls;
        v0[i] = d.v0;
        kappa[i] = d.kappa;
        log_one_minus_kappa[i] = d.log_one_minus_kappa;
        if (!(d.v0 == (d.kappa > 0.0 ? 1.0 / d.kappa : INFINITY)) && not_reciprocal++ == 0)
            first_not_reciprocal = i;
    }
    CHECK(failed_calls == 0, "%s grid: %ld calls failed", grid, failed_calls);
    CHECK(not_reciprocal == 0, "%s grid: v0 != 1/kappa at %ld albedos, first alpha = %.17g (v0 %.17g, kappa %.17g)",
          grid, not_reciprocal, first_not_reciprocal < 0 ? 0.0 : albedo_at(first_not_reciprocal, n),
          first_not_reciprocal < 0 ? 0.0 : v0[first_not_reciprocal],
          first_not_reciprocal < 0 ? 0.0 : kappa[first_not_reciprocal]);
    struct {
        const char *name;
        const double *values;
        int direction;
    } sequences[] = {{"v0", v0, +1}, {"kappa", kappa, -1}, {"log(1 - kappa)", log_one_minus_kappa, +1}};
    for (size_t s = 0; s < sizeof sequences / sizeof sequences[0]; ++s) {
        long first;
        long violations = count_order_violations(sequences[s].values, n + 1, sequences[s].direction, &first);
        CHECK(violations == 0, "%s grid: %s out of order at %ld albedos, first alpha = %.17g: %.17g after %.17g",
              grid, sequences[s].name, violations, first < 0 ? 0.0 : albedo_at(first, n),
              first < 0 ? 0.0 : sequences[s].values[first], first < 0 ? 0.0 : sequences[s].values[first - 1]);
    }
    free(v0), free(kappa), free(log_one_minus_kappa);
}

static double uniform_albedo(long i, long n)
{
    return (double)i / (double)n;
}

/* 10^-300 to 1, log-spaced: the low albedos where 1 - kappa0 underflows. */
static double log_albedo(long i, long n)
{
    return pow(10.0, -300.0 + 300.0 * (double)i / (double)n);
}

/* 1 - 10^-1 to 1 - 10^-16, log-spaced in 1 - alpha: where kappa0 ~ sqrt(3 (1 - alpha)) -> 0. */
static double near_one_albedo(long i, long n)
{
    return 1.0 - pow(10.0, -1.0 - 15.0 * (double)i / (double)n);
}

static void test_exact_monotone(void)
{
    check_exact_monotone("uniform", 100000, uniform_albedo);
    check_exact_monotone("log", 30000, log_albedo);
    check_exact_monotone("near-one", 15000, near_one_albedo);
}

/* ---- fast ----------------------------------------------------------------------------------- */

/* The header's promise for alpha in [0.01, 1 - 1e-6]. */
static const tolerance_t FAST_TOLERANCE = {1e-6, 1e-4, -1.0};
static const double FAST_MIN_ALBEDO = 0.01, FAST_MAX_ALBEDO = 1.0 - 1e-6;

static void test_fast(void)
{
    method_summary_t summary = {{0, 0}, {0, 0}, {0, 0}};
    for (int i = 0; i < row_count; ++i) {
        const reference_row_t *row = &rows[i];
        dwv_diffusion_length_t d = diffusion_length(row->albedo, DWV_V0_FAST);
        CHECK(count_range_violations("fast", &d, isinf(row->exact.log_one_minus_kappa), true) == 0,
              "fast: out of range at alpha = %.17g", row->albedo);
        if (row->albedo >= FAST_MIN_ALBEDO && row->albedo <= FAST_MAX_ALBEDO) {
            int misses = count_misses("fast", row->albedo, triple_of(&d), row->exact, FAST_TOLERANCE,
                                      &summary, true);
            CHECK(misses == 0, "fast: %d values off at alpha = %.17g", misses, row->albedo);
        }
    }
    /* The endpoints of v0 itself: v0(0) = 1, v0(1) = infinity. */
    dwv_diffusion_length_t zero = diffusion_length(0.0, DWV_V0_FAST);
    dwv_diffusion_length_t one = diffusion_length(1.0, DWV_V0_FAST);
    CHECK(zero.kappa == 1.0 && zero.v0 == 1.0, "fast: alpha = 0: kappa %.17g, v0 %.17g", zero.kappa, zero.v0);
    CHECK(one.kappa == 0.0 && one.v0 == INFINITY, "fast: alpha = 1: kappa %.17g, v0 %.17g", one.kappa, one.v0);
    print_summary("fast", &summary);

    /* Between the table's albedos too: against the exact method (itself checked above to 1e-14
     * and 1e-12), on a uniform grid and one log-spaced toward alpha = 1 - 1e-6. */
    method_summary_t grid_summary = {{0, 0}, {0, 0}, {0, 0}};
    long misses = 0, out_of_range = 0;
    const long n = 50000;
    for (long i = 0; i <= 2 * n; ++i) {
        double albedo = i <= n ? FAST_MIN_ALBEDO + (FAST_MAX_ALBEDO - FAST_MIN_ALBEDO) * (double)i / (double)n
                               : 1.0 - pow(10.0, -1.0 - 5.0 * (double)(i - n) / (double)n);
        dwv_diffusion_length_t fast = DWV_DIFFUSION_LENGTH_INIT, exact = DWV_DIFFUSION_LENGTH_INIT;
        if (dwv_diffusion_length(albedo, DWV_V0_FAST, &fast) != DWV_SUCCESS ||
            dwv_diffusion_length(albedo, DWV_V0_EXACT, &exact) != DWV_SUCCESS) {
            ++misses;
            continue;
        }
        out_of_range += count_range_violations("fast (grid)", &fast, false, misses + out_of_range < 10);
        misses += count_misses("fast (grid)", albedo, triple_of(&fast), triple_of(&exact), FAST_TOLERANCE,
                               &grid_summary, misses < 10) != 0;
    }
    CHECK(misses == 0 && out_of_range == 0, "fast: %ld grid albedos miss the bounds, %ld out of range",
          misses, out_of_range);
    printf("fast  worst relative error against exact on %ld grid albedos in [0.01, 1 - 1e-6]: kappa %.3g "
           "(alpha %.17g), 1 - kappa %.3g (alpha %.17g)\n",
           2 * n + 1, grid_summary.kappa.error, grid_summary.kappa.albedo,
           grid_summary.one_minus_kappa.error, grid_summary.one_minus_kappa.albedo);
}

/* ---- case and deon: the approximations as published -------------------------------------- */

/* Both are closed forms evaluated in double precision; the reference evaluates the same forms
 * in mpmath, so they must agree to rounding. */
static const tolerance_t APPROXIMATION_TOLERANCE = {1e-13, 1e-13, 1e-13};

static void test_approximation(const char *name, dwv_v0_method_t method, size_t reference_offset)
{
    method_summary_t summary = {{0, 0}, {0, 0}, {0, 0}};
    for (int i = 0; i < row_count; ++i) {
        const reference_row_t *row = &rows[i];
        const kappa_triple_t *reference = (const kappa_triple_t *)((const char *)row + reference_offset);
        dwv_diffusion_length_t d = diffusion_length(row->albedo, method);
        int misses = count_misses(name, row->albedo, triple_of(&d), *reference, APPROXIMATION_TOLERANCE,
                                  &summary, true);
        CHECK(misses == 0, "%s: %d values off at alpha = %.17g", name, misses, row->albedo);
        CHECK(count_range_violations(name, &d, isinf(reference->log_one_minus_kappa), true) == 0,
              "%s: out of range at alpha = %.17g", name, row->albedo);
    }
    print_summary(name, &summary);
}

static void test_case_and_deon(void)
{
    test_approximation("case", DWV_V0_CASE, offsetof(reference_row_t, case_series));
    test_approximation("deon", DWV_V0_DEON, offsetof(reference_row_t, deon));
    /* Eq. 11 is used with v0(0.9999) from alpha = 0.9999 on, up to and including alpha = 1. */
    dwv_diffusion_length_t clamp = diffusion_length(0.9999, DWV_V0_CASE);
    dwv_diffusion_length_t one = diffusion_length(1.0, DWV_V0_CASE);
    CHECK(one.kappa == clamp.kappa && one.v0 == clamp.v0, "case: v0(1) = %.17g, v0(0.9999) = %.17g", one.v0,
          clamp.v0);
}

/* ---- the eigenfunction -------------------------------------------------------------------- */

enum { GAUSS_POINTS = 10 };
static long double gauss_nodes[GAUSS_POINTS], gauss_weights[GAUSS_POINTS];

/* Gauss-Legendre nodes on [-1, 1]: Newton on P_n from the usual cosine guesses. */
static void make_gauss_legendre(void)
{
    const long double pi = acosl(-1.0L);
    const int n = GAUSS_POINTS;
    for (int i = 0; i < n; ++i) {
        long double z = cosl(pi * ((long double)i + 0.75L) / ((long double)n + 0.5L)), derivative = 0.0L;
        for (int iteration = 0; iteration < 100; ++iteration) {
            long double p_previous = 1.0L, p = z;
            for (int k = 2; k <= n; ++k) {
                long double p_next = ((2 * k - 1) * z * p - (k - 1) * p_previous) / k;
                p_previous = p;
                p = p_next;
            }
            derivative = n * (z * p - p_previous) / (z * z - 1.0L);
            long double step = p / derivative;
            z -= step;
            if (fabsl(step) <= 1e-19L) break;
        }
        gauss_nodes[i] = z;
        gauss_weights[i] = 2.0L / ((1.0L - z * z) * derivative * derivative);
    }
}

/* The integral over mu in [-1, 1] of an integrand that peaks like 1/(v - mu) at mu = sign(v):
 * composite Gauss-Legendre on panels equally spaced in log(|v - mu|), so that each panel sees a
 * nearly linear integrand however close |v| is to 1. */
typedef struct eigen_integrand_t {
    double albedo, v;
    bool use_library; /* true: dwv_eigenfunction; false: the closed form 1/(v - mu) */
    long failed_calls;
} eigen_integrand_t;

static long double eigen_integrand(eigen_integrand_t *f, double mu)
{
    if (!f->use_library) return 1.0L / ((long double)f->v - (long double)mu);
    double phi = NAN;
    if (dwv_eigenfunction(f->albedo, f->v, mu, &phi) != DWV_SUCCESS) ++f->failed_calls;
    return phi;
}

static long double graded_quadrature(eigen_integrand_t *f, int panels)
{
    double sign = f->v > 0.0 ? 1.0 : -1.0, speed = fabs(f->v);
    long double log_near = logl((long double)speed - 1.0L), log_far = logl((long double)speed + 1.0L);
    long double sum = 0.0L;
    double previous = sign; /* the peak end, mu = sign(v) */
    for (int panel = 1; panel <= panels; ++panel) {
        double next = panel == panels
                          ? -sign
                          : sign * (double)((long double)speed -
                                            expl(log_near + (log_far - log_near) * panel / panels));
        long double middle = 0.5L * ((long double)previous + next), half = 0.5L * fabsl((long double)next - previous);
        for (int j = 0; j < GAUSS_POINTS; ++j) {
            double mu = (double)(middle + half * gauss_nodes[j]);
            if (mu > 1.0) mu = 1.0;
            if (mu < -1.0) mu = -1.0;
            sum += gauss_weights[j] * half * eigen_integrand(f, mu);
        }
        previous = next;
    }
    return sum;
}

static void test_eigenfunction(void)
{
    /* phi(v, mu) = (alpha/2) v/(v - mu), Eq. 7, in long double (v - mu is exact there). The header
     * documents the evaluation (alpha/2)/(1 - mu/v), whose rounding of mu/v is amplified by
     * |mu/v| / |1 - mu/v| near the peak: the bound is 4 eps (1 + that factor). */
    static const double points[][3] = {{0.5, 1.5, 0.3},  {0.9, 2.0, -1.0},   {0.9, 2.0, 1.0},   {1.0, -3.0, 0.5},
                                       {0.7, 1.0001, 1.0}, {0.7, -1.0001, -1.0}, {0.25, 40.0, -0.75}, {0.0, 2.0, 0.5}};
    for (size_t i = 0; i < sizeof points / sizeof points[0]; ++i) {
        double albedo = points[i][0], v = points[i][1], mu = points[i][2], phi = NAN;
        long double expected = 0.5L * albedo * v / ((long double)v - mu);
        long double amplification = fabsl((long double)mu / v) / fabsl(1.0L - (long double)mu / v);
        long double bound = 4.0L * DBL_EPSILON * (1.0L + amplification) * fabsl(expected);
        dwv_result_t result = dwv_eigenfunction(albedo, v, mu, &phi);
        CHECK(result == DWV_SUCCESS && fabsl(phi - expected) <= bound,
              "phi(alpha %.17g, v %.17g, mu %.17g) = %.17g (result %d), expected %.17Lg within %.3Lg", albedo,
              v, mu, phi, (int)result, expected, bound);
    }
    double phi = NAN;
    CHECK(dwv_eigenfunction(0.3, INFINITY, 0.2, &phi) == DWV_SUCCESS && phi == 0.15,
          "phi(v = infinity) = %.17g, expected alpha/2", phi);

    /* The integral at v = v0 of the exact method is 1 (Eqs. 6 and 8). alpha atanh(k)/k, k = 1/v0,
     * amplifies a relative error in k by cond = k / ((1 - k^2) atanh(k)) - 1; v0 is a double and
     * the call takes 1/v0 again, so k carries about 2 ulps: where cond exceeds 200 (alpha below
     * about 0.28) the bound grows with cond, 4 eps (1 + cond), instead of 1e-13. */
    worst_t worst_at_v0 = {0, 0};
    int condition_bounded = 0;
    for (int i = 0; i < row_count; ++i) {
        double albedo = rows[i].albedo;
        if (!(albedo > 0.0 && albedo < 1.0)) continue;
        dwv_diffusion_length_t d = diffusion_length(albedo, DWV_V0_EXACT);
        double integral = NAN;
        dwv_result_t result = dwv_eigenfunction_integral(albedo, d.v0, &integral);
        if (!(d.v0 > 1.0)) {
            /* v0 rounds to 1 (alpha below about 0.05): not a valid |v| > 1. */
            CHECK(result == DWV_ERROR_OUT_OF_RANGE, "integral at v0 = %.17g (alpha %.17g) returned %d",
                  d.v0, albedo, (int)result);
            continue;
        }
        double k = 1.0 / d.v0;
        double condition = isinf(d.v0) ? 0.0 : k / ((1.0 - k * k) * atanh(k)) - 1.0;
        double bound = condition <= 200.0 ? 1e-13 : 4.0 * DBL_EPSILON * (1.0 + condition);
        condition_bounded += condition > 200.0;
        double error = fabs(integral - 1.0);
        note_worst(&worst_at_v0, condition <= 200.0 ? error : 0.0, albedo);
        CHECK(result == DWV_SUCCESS && error <= bound,
              "integral at v0 (alpha %.17g, v0 %.17g) = %.17g (result %d), 1 expected within %.3g", albedo,
              d.v0, integral, (int)result, bound);
    }
    printf("eigenfunction integral at v0: worst |I - 1| %.3g (alpha %.17g) where the bound is 1e-13; "
           "%d albedos with the condition-scaled bound\n",
           worst_at_v0.error, worst_at_v0.albedo, condition_bounded);

    /* The integral by quadrature of dwv_eigenfunction equals dwv_eigenfunction_integral, at v0 of
     * albedos 0.3 to 0.999 and at other |v| > 1. The quadrature itself is first checked on
     * 1/(v - mu), whose integral is log((v + 1)/(v - 1)). Its nodes are doubles (mu is a double),
     * which misplaces them by up to 2^-53 against a peak of width |v| - 1: hence |v| - 1 >= 1e-3. */
    make_gauss_legendre();
    long double weight_sum = 0.0L;
    for (int j = 0; j < GAUSS_POINTS; ++j) weight_sum += gauss_weights[j];
    CHECK(fabsl(weight_sum - 2.0L) <= 1e-17L, "Gauss-Legendre weights sum to %.21Lg", weight_sum);
    /* (albedo, v), v = 0 standing for v0 of that albedo by the exact method. */
    static const double cases[][2] = {{0.3, 0.0},  {0.4, 0.0},   {0.5, 0.0},   {0.56, 0.0},  {0.7, 0.0},
                                      {0.9, 0.0},  {0.99, 0.0},  {0.999, 0.0}, {0.8, 1.5},   {0.8, -2.0},
                                      {0.5, 1.001}, {1.0, 100.0}, {0.2, -1.25}};
    double worst_quadrature = 0.0;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        double albedo = cases[i][0];
        double v = cases[i][1] != 0.0 ? cases[i][1] : diffusion_length(albedo, DWV_V0_EXACT).v0;
        eigen_integrand_t closed_form = {albedo, v, false, 0};
        long double log_ratio = logl(((long double)v + 1.0L) / ((long double)v - 1.0L));
        long double quadrature_of_closed_form = graded_quadrature(&closed_form, 64);
        CHECK(fabsl(quadrature_of_closed_form - log_ratio) <= 1e-14L * fabsl(log_ratio),
              "quadrature of 1/(v - mu) at v = %.17g: %.17Lg, log((v+1)/(v-1)) = %.17Lg", v,
              quadrature_of_closed_form, log_ratio);
        eigen_integrand_t library = {albedo, v, true, 0};
        long double quadrature = graded_quadrature(&library, 64);
        double integral = NAN;
        dwv_result_t result = dwv_eigenfunction_integral(albedo, v, &integral);
        double error = (double)(fabsl(quadrature - integral) / fabsl(quadrature));
        if (error > worst_quadrature) worst_quadrature = error;
        CHECK(library.failed_calls == 0 && result == DWV_SUCCESS && error <= 1e-13,
              "alpha %.17g, v %.17g: quadrature %.17Lg, dwv_eigenfunction_integral %.17g (result %d, %ld failed calls)",
              albedo, v, quadrature, integral, (int)result, library.failed_calls);
    }
    printf("eigenfunction: worst relative difference quadrature vs dwv_eigenfunction_integral %.3g\n",
           worst_quadrature);
}

/* ---- argument validation ------------------------------------------------------------------ */

/* Leaves a message that names another function, so that the next message is known to be new. */
static void reset_message(void)
{
    dwv_v0_method_t method;
    (void)dwv_v0_method_from_name("no such method", &method);
}

static void check_failure(const char *call, dwv_result_t result, dwv_result_t expected, const char *function)
{
    CHECK(result == expected, "%s returned %d (%s), expected %d (%s)", call, (int)result,
          dwv_result_string(result), (int)expected, dwv_result_string(expected));
    const char *message = dwv_last_error_message();
    CHECK(message != NULL && message[0] != '\0' && strstr(message, function) != NULL,
          "%s: message '%s' does not name %s", call, message ? message : "(null)", function);
}

static void test_argument_validation(void)
{
    static const char dl[] = "dwv_diffusion_length";
    const struct {
        double albedo;
        dwv_result_t expected;
    } bad_albedos[] = {{NAN, DWV_ERROR_INVALID_ARGUMENT},  {INFINITY, DWV_ERROR_INVALID_ARGUMENT},
                       {-INFINITY, DWV_ERROR_INVALID_ARGUMENT}, {-0.1, DWV_ERROR_OUT_OF_RANGE},
                       {1.1, DWV_ERROR_OUT_OF_RANGE},      {-DBL_TRUE_MIN, DWV_ERROR_OUT_OF_RANGE},
                       {1.0 + DBL_EPSILON, DWV_ERROR_OUT_OF_RANGE}};
    char call[160];
    for (size_t i = 0; i < sizeof bad_albedos / sizeof bad_albedos[0]; ++i) {
        for (dwv_v0_method_t method = DWV_V0_EXACT; method <= DWV_V0_FAST; ++method) {
            dwv_diffusion_length_t d = DWV_DIFFUSION_LENGTH_INIT;
            reset_message();
            snprintf(call, sizeof call, "dwv_diffusion_length(%g, %s)", bad_albedos[i].albedo,
                     dwv_v0_method_name(method));
            check_failure(call, dwv_diffusion_length(bad_albedos[i].albedo, method, &d), bad_albedos[i].expected, dl);
            CHECK(strstr(dwv_last_error_message(), "albedo") != NULL, "%s: message '%s' does not name the albedo",
                  call, dwv_last_error_message());
        }
    }
    reset_message();
    check_failure("dwv_diffusion_length(0.5, exact, NULL)", dwv_diffusion_length(0.5, DWV_V0_EXACT, NULL),
                  DWV_ERROR_NULL_POINTER, dl);
    dwv_diffusion_length_t zero_size = DWV_DIFFUSION_LENGTH_INIT;
    zero_size.struct_size = 0;
    reset_message();
    check_failure("dwv_diffusion_length with struct_size 0", dwv_diffusion_length(0.5, DWV_V0_EXACT, &zero_size),
                  DWV_ERROR_STRUCT_SIZE, dl);
    /* A caller built against a later header, whose struct has grown, is served. */
    struct {
        dwv_diffusion_length_t d;
        double later_fields[2];
    } grown = {DWV_DIFFUSION_LENGTH_INIT, {0.0, 0.0}};
    grown.d.struct_size = (uint32_t)sizeof grown;
    CHECK(dwv_diffusion_length(0.5, DWV_V0_EXACT, &grown.d) == DWV_SUCCESS &&
              grown.d.kappa == diffusion_length(0.5, DWV_V0_EXACT).kappa,
          "a larger struct_size (%u) is refused", grown.d.struct_size);
    static const dwv_v0_method_t bad_methods[] = {99, -1, 4};
    for (size_t i = 0; i < sizeof bad_methods / sizeof bad_methods[0]; ++i) {
        dwv_diffusion_length_t d = DWV_DIFFUSION_LENGTH_INIT;
        reset_message();
        dwv_result_t result = dwv_diffusion_length(0.5, bad_methods[i], &d);
        CHECK(result != DWV_SUCCESS, "method %d accepted", (int)bad_methods[i]);
        const char *message = dwv_last_error_message();
        CHECK(strstr(message, dl) != NULL, "method %d: message '%s' does not name %s", (int)bad_methods[i],
              message, dl);
        CHECK(dwv_v0_method_name(bad_methods[i]) == NULL, "method %d has a name", (int)bad_methods[i]);
    }

    /* The method names. */
    for (dwv_v0_method_t method = DWV_V0_EXACT; method <= DWV_V0_FAST; ++method) {
        const char *name = dwv_v0_method_name(method);
        dwv_v0_method_t back = -1;
        CHECK(name != NULL && dwv_v0_method_from_name(name, &back) == DWV_SUCCESS && back == method,
              "method %d: name '%s' does not round-trip (%d)", (int)method, name ? name : "(null)", (int)back);
    }
    static const char *const expected_names[] = {"exact", "case", "deon", "fast"};
    for (int method = 0; method < 4; ++method)
        CHECK(dwv_v0_method_name(method) != NULL && strcmp(dwv_v0_method_name(method), expected_names[method]) == 0,
              "method %d is called '%s'", method, dwv_v0_method_name(method));
    static const char *const bad_names[] = {"EXACT", "", "exact ", "Case", "deon2"};
    for (size_t i = 0; i < sizeof bad_names / sizeof bad_names[0]; ++i) {
        dwv_v0_method_t method = 12345;
        dwv_result_t result = dwv_v0_method_from_name(bad_names[i], &method);
        CHECK(result == DWV_ERROR_UNKNOWN_NAME && method == 12345, "name '%s': result %d, method %d", bad_names[i],
              (int)result, (int)method);
        CHECK(strstr(dwv_last_error_message(), "dwv_v0_method_from_name") != NULL, "name '%s': message '%s'",
              bad_names[i], dwv_last_error_message());
    }
    dwv_v0_method_t method;
    check_failure("dwv_v0_method_from_name(NULL)", dwv_v0_method_from_name(NULL, &method), DWV_ERROR_NULL_POINTER,
                  "dwv_v0_method_from_name");
    check_failure("dwv_v0_method_from_name(\"exact\", NULL)", dwv_v0_method_from_name("exact", NULL),
                  DWV_ERROR_NULL_POINTER, "dwv_v0_method_from_name");

    /* The eigenfunction and its integral: albedo in [0, 1], mu in [-1, 1], |v| > 1; a NaN is an
     * invalid argument (the header's DWV_ERROR_INVALID_ARGUMENT: "NaN, infinite, ..."). */
    static const char ef[] = "dwv_eigenfunction", efi[] = "dwv_eigenfunction_integral";
    double value;
    reset_message();
    check_failure("dwv_eigenfunction(NaN albedo)", dwv_eigenfunction(NAN, 2.0, 0.0, &value), DWV_ERROR_INVALID_ARGUMENT, ef);
    reset_message();
    check_failure("dwv_eigenfunction(albedo 1.5)", dwv_eigenfunction(1.5, 2.0, 0.0, &value), DWV_ERROR_OUT_OF_RANGE, ef);
    reset_message();
    check_failure("dwv_eigenfunction(mu 1.5)", dwv_eigenfunction(0.5, 2.0, 1.5, &value), DWV_ERROR_OUT_OF_RANGE, ef);
    reset_message();
    check_failure("dwv_eigenfunction(mu NaN)", dwv_eigenfunction(0.5, 2.0, NAN, &value), DWV_ERROR_INVALID_ARGUMENT, ef);
    reset_message();
    check_failure("dwv_eigenfunction(v NaN)", dwv_eigenfunction(0.5, NAN, 0.0, &value), DWV_ERROR_INVALID_ARGUMENT, ef);
    static const double inside[] = {1.0, -1.0, 0.5, 0.0};
    for (size_t i = 0; i < sizeof inside / sizeof inside[0]; ++i) {
        reset_message();
        snprintf(call, sizeof call, "dwv_eigenfunction(v %g)", inside[i]);
        check_failure(call, dwv_eigenfunction(0.5, inside[i], 0.0, &value), DWV_ERROR_OUT_OF_RANGE, ef);
        reset_message();
        snprintf(call, sizeof call, "dwv_eigenfunction_integral(v %g)", inside[i]);
        check_failure(call, dwv_eigenfunction_integral(0.5, inside[i], &value), DWV_ERROR_OUT_OF_RANGE, efi);
    }
    reset_message();
    check_failure("dwv_eigenfunction(NULL)", dwv_eigenfunction(0.5, 2.0, 0.0, NULL), DWV_ERROR_NULL_POINTER, ef);
    reset_message();
    check_failure("dwv_eigenfunction_integral(NaN albedo)", dwv_eigenfunction_integral(NAN, 2.0, &value),
                  DWV_ERROR_INVALID_ARGUMENT, efi);
    reset_message();
    check_failure("dwv_eigenfunction_integral(albedo -0.1)", dwv_eigenfunction_integral(-0.1, 2.0, &value),
                  DWV_ERROR_OUT_OF_RANGE, efi);
    reset_message();
    check_failure("dwv_eigenfunction_integral(v NaN)", dwv_eigenfunction_integral(0.5, NAN, &value),
                  DWV_ERROR_INVALID_ARGUMENT, efi);
    reset_message();
    check_failure("dwv_eigenfunction_integral(NULL)", dwv_eigenfunction_integral(0.5, 2.0, NULL),
                  DWV_ERROR_NULL_POINTER, efi);
}

/* ---- planted errors: the harness above catches what it is meant to catch ------------------ */

static void test_planted_errors(void)
{
    const reference_row_t *row = find_row(0.5);
    CHECK(row != NULL, "no row for alpha = %g", 0.5);
    if (row == NULL) return;
    dwv_diffusion_length_t d = diffusion_length(0.5, DWV_V0_EXACT);
    kappa_triple_t good = triple_of(&d);
    CHECK(count_misses("planted", 0.5, good, row->exact, EXACT_TOLERANCE, NULL, false) == 0,
          "the unperturbed exact value at alpha = %g is not accepted", 0.5);

    kappa_triple_t wrong = good;
    wrong.kappa *= 1.0 + 1e-12;
    CHECK(count_misses("planted", 0.5, wrong, row->exact, EXACT_TOLERANCE, NULL, false) == 1,
          "kappa off by %g relative is not caught", 1e-12);
    wrong = good;
    wrong.one_minus_kappa *= 1.0 + 1e-11;
    CHECK(count_misses("planted", 0.5, wrong, row->exact, EXACT_TOLERANCE, NULL, false) == 1,
          "1 - kappa off by %g relative is not caught", 1e-11);
    wrong = good;
    wrong.log_one_minus_kappa *= 1.0 + 1e-11;
    CHECK(count_misses("planted", 0.5, wrong, row->exact, EXACT_TOLERANCE, NULL, false) == 1,
          "log(1 - kappa) off by %g relative is not caught", 1e-11);
    wrong = good;
    wrong.kappa = NAN;
    CHECK(count_misses("planted", 0.5, wrong, row->exact, EXACT_TOLERANCE, NULL, false) == 1,
          "a NaN kappa is not caught (%d)", 0);
    wrong = good;
    wrong.kappa *= 1.0 + 2e-6;
    CHECK(count_misses("planted", 0.5, wrong, row->exact, FAST_TOLERANCE, NULL, false) == 1,
          "a fast kappa off by %g relative is not caught", 2e-6);
    /* 1 - kappa must be caught even where kappa is within bounds. */
    wrong = good;
    wrong.one_minus_kappa *= 1.0 + 2e-4;
    CHECK(count_misses("planted", 0.5, wrong, row->exact, FAST_TOLERANCE, NULL, false) == 1,
          "a fast 1 - kappa off by %g relative is not caught", 2e-4);

    /* The range check and the order check. */
    dwv_diffusion_length_t out_of_range = d;
    out_of_range.v0 = nextafter(out_of_range.v0, 0.0);
    CHECK(count_range_violations("planted", &out_of_range, false, false) == 1, "v0 != 1/kappa is not caught (%d)", 0);
    out_of_range = d;
    out_of_range.log_ratio = NAN;
    CHECK(count_range_violations("planted", &out_of_range, false, false) == 1, "a NaN L is not caught (%d)", 0);
    const double sequence[] = {1.0, 1.5, 2.0, nextafter(2.0, 0.0), 3.0};
    long first;
    CHECK(count_order_violations(sequence, 5, +1, &first) == 1 && first == 3, "a step down is not caught (%ld)", first);
    const double with_nan[] = {1.0, NAN, 2.0};
    CHECK(count_order_violations(with_nan, 3, +1, &first) == 2, "a NaN is not caught (%ld)", first);
}

int main(void)
{
    load_reference(DWV_TEST_DATA_DIR "/v0_reference.csv");
    test_table();
    if (row_count > 0) {
        test_planted_errors();
        test_exact_against_reference();
        test_exact_endpoints();
        test_exact_monotone();
        test_fast();
        test_case_and_deon();
        test_eigenfunction();
        test_argument_validation();
    }
    return check_report("test_v0");
}
