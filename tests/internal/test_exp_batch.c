/* dwvk_exp_fast_inner (src/kernel/exp_batch.h) in a vectorised loop, with dwvk_exp_fast where
 * dwvk_exp_fast_is_edge says so (as walk.c's mixture loops take them), against dwvk_exp_fast, bit
 * for bit, in every copy this processor runs: the baseline (SSE2), and on x86-64 with GCC the
 * x86-64-v3 (AVX2) and x86-64-v4 (AVX-512) copies, the targets walk.c's mixture loops are cloned
 * for. Arguments: 4 M
 * random ones over the whole range and near the walk's, the edges (+-708.39 where the edge path
 * takes over, overflow at 709.78, underflow at -745.2, subnormal results, +-0, +-infinity, NaN),
 * in batches of every length from 0 to 37 (so that every vector loop's remainder is run). A
 * planted error (one result one ulp off) shows the comparison can fail. About 0.4 s. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "kernel/exp_batch.h"

#define LONGEST 37

typedef void (*batch_fn)(const double *x, double *y, int n);

/* The loop each copy compiles: the inner form for every element, vectorised, then the edges. */
static inline void exp_batch(const double *restrict x, double *restrict y, int n)
{
    int edges = 0;
    for (int i = 0; i < n; ++i) {
        y[i] = dwvk_exp_fast_inner(x[i]);
        edges |= dwvk_exp_fast_is_edge(x[i]);
    }
    if (edges)
        for (int i = 0; i < n; ++i)
            if (dwvk_exp_fast_is_edge(x[i])) y[i] = dwvk_exp_fast(x[i]);
}

static void batch_baseline(const double *x, double *y, int n)
{
    exp_batch(x, y, n);
}

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && __GNUC__ >= 12
#define HAVE_COPIES 1
__attribute__((target("arch=x86-64-v3"))) static void batch_v3(const double *x, double *y, int n)
{
    exp_batch(x, y, n);
}
__attribute__((target("arch=x86-64-v4"))) static void batch_v4(const double *x, double *y, int n)
{
    exp_batch(x, y, n);
}
#else
#define HAVE_COPIES 0
#endif

static uint64_t next_bits(uint64_t *state) /* splitmix64 */
{
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static double uniform(uint64_t *state, double lo, double hi)
{
    return lo + (hi - lo) * ((double)(next_bits(state) >> 11) * 0x1p-53);
}

static int same_bits(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

/* Mismatches of batch(x[0..n)) against dwvk_exp_fast, the first's argument in *at; `plant`
 * puts one result one ulp off (the planted error) where n > 0. */
static long mismatches(batch_fn batch, const double *x, int n, int plant, double *at)
{
    double y[LONGEST];
    batch(x, y, n);
    if (plant && n > 0) y[n / 2] = nextafter(y[n / 2], INFINITY);
    long wrong = 0;
    for (int i = 0; i < n; ++i) {
        if (!same_bits(y[i], dwvk_exp_fast(x[i]))) {
            if (wrong == 0) *at = x[i];
            ++wrong;
        }
    }
    return wrong;
}

/* Every batch length 0 .. LONGEST over `rounds` rounds of random arguments, with the special
 * values mixed in. */
static long check_copy(batch_fn batch, int plant, double *at)
{
    static const double special[] = {0.0, -0.0, 708.39, -708.39, 708.3900000000001, -708.3900000000001,
                                     709.782712893384, 709.7827128933841, 709.5, -745.2, -745.3, -710.0,
                                     -730.5, -744.9, 1e-300, -1e-300, INFINITY, -INFINITY, NAN, 5e-324};
    const int specials = (int)(sizeof special / sizeof special[0]);
    uint64_t state = 20;
    long wrong = 0;
    for (int round = 0; round < 6000; ++round) {
        for (int n = 0; n <= LONGEST; ++n) {
            double x[LONGEST];
            for (int i = 0; i < n; ++i) {
                uint64_t pick = next_bits(&state) % 16u;
                x[i] = pick == 0   ? special[next_bits(&state) % (uint64_t)specials]
                       : pick < 6  ? uniform(&state, -760.0, 760.0)
                       : pick < 12 ? uniform(&state, -40.0, 1.0) /* the walk's arguments */
                                   : uniform(&state, -7.0, 0.0); /* the patch weights' */
            }
            wrong += mismatches(batch, x, n, plant, at);
        }
    }
    return wrong;
}

static void check_named(const char *name, batch_fn batch)
{
    double at = 0.0;
    long wrong = check_copy(batch, 0, &at);
    printf("exp_fast_batch (%s): %ld mismatches\n", name, wrong);
    CHECK(wrong == 0, "%s: %ld results differ from dwvk_exp_fast, the first at x = %.17g", name, wrong, at);
}

int main(void)
{
    double at = 0.0;
    CHECK(check_copy(batch_baseline, 1, &at) > 0, "the planted one-ulp error was not seen");
    check_named("baseline", batch_baseline);
#if HAVE_COPIES
    __builtin_cpu_init();
    if (__builtin_cpu_supports("x86-64-v3")) check_named("x86-64-v3", batch_v3);
    else printf("exp_fast_batch (x86-64-v3): not run, the processor lacks it\n");
    if (__builtin_cpu_supports("x86-64-v4")) check_named("x86-64-v4", batch_v4);
    else printf("exp_fast_batch (x86-64-v4): not run, the processor lacks it\n");
#endif
    return check_report("test_exp_batch");
}
