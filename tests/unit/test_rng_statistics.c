/* The counter-based generator through capi: range and resolution of dwv_random_uniform[_f],
 * uniformity (chi-square on 1000 bins), independence of consecutive dimensions, adjacent samples,
 * streams and seeds (chi-square on a 32 x 32 grid of pairs, and Pearson's correlation within 5
 * standard errors), bit balance, distinct values over a grid of counters, determinism; and planted
 * errors (a skewed and a correlated generator) that the same checks must catch.
 *
 * Public API only. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include <dwivedi.h>
#include "stats.h"

#define SEED 0x243f6a8885a308d3ull
#define UNIFORM_BINS 1000
#define UNIFORM_SAMPLES 1000000
#define GRID 32
#define PAIRS 500000
#define CORRELATION_SIGMAS 5.0

static double uniform(uint64_t seed, uint64_t stream, uint64_t sample, uint32_t dimension, int *failures)
{
    double u = NAN;
    *failures += dwv_random_uniform(seed, stream, sample, dimension, &u) != DWV_SUCCESS;
    return u;
}

static float uniform_f(uint64_t seed, uint64_t stream, uint64_t sample, uint32_t dimension, int *failures)
{
    float u = NAN;
    *failures += dwv_random_uniform_f(seed, stream, sample, dimension, &u) != DWV_SUCCESS;
    return u;
}

/* ---- range, resolution, uniformity ---------------------------------------------------------- */

/* Chi-square of n values against UNIFORM_BINS equal bins of [0, 1). */
static stats_chi_square_t uniformity(const double *values, int n, int *outside)
{
    static double observed[UNIFORM_BINS], expected[UNIFORM_BINS];
    for (int k = 0; k < UNIFORM_BINS; ++k) {
        observed[k] = 0.0;
        expected[k] = (double)n / UNIFORM_BINS;
    }
    *outside = 0;
    for (int i = 0; i < n; ++i) {
        double x = values[i];
        if (!(x >= 0.0 && x < 1.0)) {
            ++*outside;
            continue;
        }
        observed[(int)(x * UNIFORM_BINS)] += 1.0;
    }
    return stats_chi_square(observed, expected, UNIFORM_BINS);
}

static void test_uniform(double *values)
{
    printf("uniformity, %d draws, %d bins, reject when p < %g:\n", UNIFORM_SAMPLES, UNIFORM_BINS, STATS_P_REJECT);
    int failures = 0, off_grid = 0, off_grid_f = 0, outside;
    /* Double: 53 bits, a multiple of 2^-53 in [0, 1). Draws walk samples and dimensions both. */
    for (int i = 0; i < UNIFORM_SAMPLES; ++i) {
        double u = uniform(SEED, 7, (uint64_t)(i / 8), (uint32_t)(i % 8), &failures);
        off_grid += !(u * 0x1p53 == floor(u * 0x1p53));
        values[i] = u;
    }
    stats_chi_square_t r = uniformity(values, UNIFORM_SAMPLES, &outside);
    stats_print("double dwv_random_uniform", r);
    CHECK(failures == 0, "%d failed calls", failures);
    CHECK(outside == 0, "%d double uniforms outside [0, 1)", outside);
    CHECK(off_grid == 0, "%d double uniforms not multiples of 2^-53", off_grid);
    CHECK(r.p >= STATS_P_REJECT, "double uniforms not uniform: chi2 = %.2f, dof %d, p = %.3g", r.x2, r.dof, r.p);

    /* Float: 24 bits, a multiple of 2^-24 in [0, 1): never 1.0f (the largest is 1 - 2^-24). */
    float largest = 0.0f;
    for (int i = 0; i < UNIFORM_SAMPLES; ++i) {
        float u = uniform_f(SEED, 8, (uint64_t)(i / 8), (uint32_t)(i % 8), &failures);
        off_grid_f += !((double)u * 0x1p24 == floor((double)u * 0x1p24));
        largest = u > largest ? u : largest;
        values[i] = (double)u;
    }
    r = uniformity(values, UNIFORM_SAMPLES, &outside);
    stats_print("float dwv_random_uniform_f", r);
    printf("  largest float of %d: 1 - %.3g\n", UNIFORM_SAMPLES, 1.0 - (double)largest);
    CHECK(failures == 0, "%d failed calls", failures);
    CHECK(outside == 0, "%d float uniforms outside [0, 1) (1.0f included)", outside);
    CHECK(off_grid_f == 0, "%d float uniforms not multiples of 2^-24", off_grid_f);
    CHECK(r.p >= STATS_P_REJECT, "float uniforms not uniform: chi2 = %.2f, dof %d, p = %.3g", r.x2, r.dof, r.p);

    /* Planted: u^1.05 (density ~ u^-0.05 / 1.05, 5% off at most of [0, 1)) must be rejected. */
    for (int i = 0; i < UNIFORM_SAMPLES; ++i) values[i] = pow(values[i], 1.05);
    r = uniformity(values, UNIFORM_SAMPLES, &outside);
    stats_print("planted: u^1.05 (must be rejected)", r);
    CHECK(r.p < STATS_P_REJECT, "planted skew not caught: chi2 = %.2f, p = %.3g", r.x2, r.p);
}

/* Each of the 64 bits of dwv_random_u64 is set in half the draws, within 5 standard errors. */
static void test_bits(void)
{
    const int n = 200000;
    int counts[64] = {0}, failures = 0;
    for (int i = 0; i < n; ++i) {
        uint64_t value = 0;
        failures += dwv_random_u64(SEED, 9, (uint64_t)i, 3, &value) != DWV_SUCCESS;
        for (int b = 0; b < 64; ++b) counts[b] += (int)((value >> b) & 1u);
    }
    double worst = 0.0;
    for (int b = 0; b < 64; ++b) worst = fmax(worst, fabs(counts[b] - 0.5 * n) / sqrt(0.25 * n));
    printf("bit balance of dwv_random_u64 over %d draws: worst bit %.2f standard errors from 1/2 (bound %g)\n", n,
           worst, CORRELATION_SIGMAS);
    CHECK(failures == 0, "%d failed calls", failures);
    CHECK(worst <= CORRELATION_SIGMAS, "a bit of dwv_random_u64 is unbalanced by %.2f standard errors", worst);
}

/* ---- independence of neighbours ------------------------------------------------------------- */

typedef struct pair_result { stats_chi_square_t grid; double correlation_sigmas; } pair_result;

/* Chi-square on a GRID x GRID histogram of the pairs (x[i], y[i]) and Pearson's correlation in
 * standard errors (1/sqrt(n) for independent pairs). */
static pair_result independence(const double *x, const double *y, int n)
{
    static double observed[GRID * GRID], expected[GRID * GRID];
    double sx = 0.0, sy = 0.0, sxx = 0.0, syy = 0.0, sxy = 0.0;
    for (int k = 0; k < GRID * GRID; ++k) {
        observed[k] = 0.0;
        expected[k] = (double)n / (GRID * GRID);
    }
    for (int i = 0; i < n; ++i) {
        int a = (int)(x[i] * GRID), b = (int)(y[i] * GRID);
        observed[(a < GRID ? a : GRID - 1) * GRID + (b < GRID ? b : GRID - 1)] += 1.0;
        sx += x[i];
        sy += y[i];
        sxx += x[i] * x[i];
        syy += y[i] * y[i];
        sxy += x[i] * y[i];
    }
    double cov = sxy / n - (sx / n) * (sy / n);
    double r = cov / sqrt((sxx / n - (sx / n) * (sx / n)) * (syy / n - (sy / n) * (sy / n)));
    pair_result result = {stats_chi_square(observed, expected, GRID * GRID), fabs(r) * sqrt((double)n)};
    return result;
}

enum neighbour { DIMENSION, SAMPLE, STREAM, SEED_NEXT };

/* The i-th pair of neighbours: (u, u with one counter + 1). */
static void neighbours(enum neighbour kind, uint32_t base, int i, double *x, double *y, int *failures)
{
    uint64_t k = (uint64_t)i;
    switch (kind) {
    case DIMENSION:
        *x = uniform(SEED, 11, k, base, failures);
        *y = uniform(SEED, 11, k, base + 1u, failures);
        break;
    case SAMPLE:
        *x = uniform(SEED, 12, k, base, failures);
        *y = uniform(SEED, 12, k + 1, base, failures);
        break;
    case STREAM:
        *x = uniform(SEED, k, 13, base, failures);
        *y = uniform(SEED, k + 1, 13, base, failures);
        break;
    case SEED_NEXT:
        *x = uniform(SEED + k, 14, 0, base, failures);
        *y = uniform(SEED + k + 1, 14, 0, base, failures);
        break;
    }
}

static void check_independent(const char *label, pair_result r)
{
    stats_print(label, r.grid);
    printf("  %-58s correlation %.2f standard errors from 0\n", "", r.correlation_sigmas);
    CHECK(r.grid.p >= STATS_P_REJECT, "%s: pairs not independent: chi2 = %.2f, dof %d, p = %.3g", label, r.grid.x2,
          r.grid.dof, r.grid.p);
    CHECK(r.correlation_sigmas <= CORRELATION_SIGMAS, "%s: correlation %.2f standard errors from 0", label,
          r.correlation_sigmas);
}

static void test_independence(double *x, double *y)
{
    printf("independence of neighbours, %d pairs on a %d x %d grid, reject when p < %g or |r| > %g sigma:\n", PAIRS,
           GRID, GRID, STATS_P_REJECT, CORRELATION_SIGMAS);
    struct { enum neighbour kind; uint32_t base; const char *label; } cases[] = {
        {DIMENSION, 0, "dimensions 0 and 1 of one sample"},
        {DIMENSION, 1, "dimensions 1 and 2 of one sample"},
        {DIMENSION, 63, "dimensions 63 and 64 of one sample"},
        {SAMPLE, 0, "samples i and i + 1, dimension 0"},
        {SAMPLE, 5, "samples i and i + 1, dimension 5"},
        {STREAM, 0, "streams s and s + 1, dimension 0"},
        {SEED_NEXT, 0, "seeds s and s + 1, dimension 0"},
    };
    for (int c = 0; c < (int)(sizeof cases / sizeof cases[0]); ++c) {
        int failures = 0;
        for (int i = 0; i < PAIRS; ++i) neighbours(cases[c].kind, cases[c].base, i, &x[i], &y[i], &failures);
        CHECK(failures == 0, "%s: %d failed calls", cases[c].label, failures);
        check_independent(cases[c].label, independence(x, y, PAIRS));
    }
    /* Planted: 2% of the second coordinates replaced by the first (correlation 0.02). */
    for (int i = 0; i < PAIRS; i += 50) y[i] = x[i];
    pair_result r = independence(x, y, PAIRS);
    stats_print("planted: 2% of pairs equal (must be rejected)", r.grid);
    printf("  %-58s correlation %.2f standard errors from 0\n", "", r.correlation_sigmas);
    CHECK(r.grid.p < STATS_P_REJECT, "planted correlation not caught by the grid: chi2 = %.2f, p = %.3g", r.grid.x2,
          r.grid.p);
    CHECK(r.correlation_sigmas > CORRELATION_SIGMAS, "planted correlation not caught by r: %.2f sigma",
          r.correlation_sigmas);
}

/* ---- determinism and distinct counters ------------------------------------------------------ */

static int compare_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* The number of repeated values in v[0..n) (which it sorts). 64-bit values of distinct counters
 * collide by chance with probability ~ n^2 / 2^65 ~ 1e-10 for n = 90000. */
static int repeats(uint64_t *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, compare_u64);
    int count = 0;
    for (int i = 1; i < n; ++i) count += v[i] == v[i - 1];
    return count;
}

static void test_counters(uint64_t *v)
{
    const int side = 300;
    int failures = 0, n = 0;
    /* Stream and sample swapped, or summed, must not give the same numbers. */
    for (int s = 0; s < side; ++s)
        for (int k = 0; k < side; ++k) failures += dwv_random_u64(SEED, (uint64_t)s, (uint64_t)k, 0, &v[n++]) != 0;
    int stream_sample = repeats(v, n);
    n = 0;
    for (int s = 0; s < side; ++s)
        for (int d = 0; d < side; ++d) failures += dwv_random_u64(SEED, (uint64_t)s, 0, (uint32_t)d, &v[n++]) != 0;
    int stream_dimension = repeats(v, n);
    n = 0;
    for (int seed = 0; seed < side; ++seed)
        for (int k = 0; k < side; ++k) failures += dwv_random_u64((uint64_t)seed, 0, (uint64_t)k, 0, &v[n++]) != 0;
    int seed_sample = repeats(v, n);
    printf("distinct values over %d x %d counters: repeats stream/sample %d, stream/dimension %d, seed/sample %d\n",
           side, side, stream_sample, stream_dimension, seed_sample);
    CHECK(failures == 0, "%d failed calls", failures);
    CHECK(stream_sample == 0 && stream_dimension == 0 && seed_sample == 0,
          "repeated values: stream/sample %d, stream/dimension %d, seed/sample %d", stream_sample, stream_dimension,
          seed_sample);

    /* Determinism: the same counters give the same numbers, in any order of calls. */
    int differ = 0;
    for (int i = 0; i < 1000; ++i) {
        uint64_t seed = SEED ^ (uint64_t)i * 0x100000001ull, stream = (uint64_t)(i * 7), sample = (uint64_t)(999 - i);
        uint32_t dimension = (uint32_t)(i % 37);
        double a = NAN, b = NAN;
        float a_f = NAN, b_f = NAN;
        uint64_t a_u = 0, b_u = 1;
        failures += dwv_random_uniform(seed, stream, sample, dimension, &a) != DWV_SUCCESS;
        failures += dwv_random_uniform_f(seed, stream, sample, dimension, &a_f) != DWV_SUCCESS;
        failures += dwv_random_u64(seed, stream, sample, dimension, &a_u) != DWV_SUCCESS;
        failures += dwv_random_u64(seed + 1, stream, sample, dimension, &b_u) != DWV_SUCCESS; /* another counter between */
        failures += dwv_random_u64(seed, stream, sample, dimension, &b_u) != DWV_SUCCESS;
        failures += dwv_random_uniform_f(seed, stream, sample, dimension, &b_f) != DWV_SUCCESS;
        failures += dwv_random_uniform(seed, stream, sample, dimension, &b) != DWV_SUCCESS;
        differ += a != b || a_f != b_f || a_u != b_u;
    }
    CHECK(failures == 0, "%d failed calls", failures);
    CHECK(differ == 0, "%d of 1000 counters gave different numbers on a second call", differ);
}

int main(void)
{
    double *x = malloc(UNIFORM_SAMPLES * sizeof *x), *y = malloc(PAIRS * sizeof *y);
    uint64_t *v = malloc(300 * 300 * sizeof *v);
    if (x == NULL || y == NULL || v == NULL) {
        fprintf(stderr, "out of memory\n");
        return 1;
    }
    test_uniform(x);
    test_bits();
    test_independence(x, y);
    test_counters(v);
    free(x);
    free(y);
    free(v);
    return check_report("test_rng_statistics");
}
