/* The stratified pairs of src/kernel/sampler.h:
 * 1. Stratification: the first 2^m samples of any pair form a (0,m,2)-net, i.e. every elementary
 *    interval [a 2^-k, (a+1) 2^-k) x [b 2^-(m-k), (b+1) 2^-(m-k)) holds exactly one point, for every
 *    k; a scramble that broke a digit's nesting would leave some interval with two (planted:
 *    independent points fail).
 * 2. Unbiasedness: across pixels (scramble seeds) a fixed sample index is uniform: the mean and the
 *    fraction below 1/4 of sample 5 over 2^16 pixels, in each coordinate, lie within 5 standard
 *    errors of 1/2 and 1/4, and the two coordinates are uncorrelated (within 5 standard errors).
 *    Planted error: without the scramble (seed 0 for every pixel) every pixel gives the same
 *    point, which the same check must reject.
 * 3. The two coordinates of different pairs of one pixel are not the same numbers.
 * 4. Beyond 2^32 samples, and for unstratified samplers, the pairs are rng.h's draws.
 * 5. The loop-free Sobol coordinate equals the definition (dwvk_sobol_second, reversed) for every
 *    index below 2^20 and for 2^20 hashed 32-bit ones; the paired 64-bit reversal equals two
 *    32-bit ones (2^20 hashed words); the pair equals the scrambles written out
 *    (owen_scramble(reverse(i)), owen_scramble(sobol_second(i))) for a sample of indices.
 * 6. The single-precision pairs the walk draws (dwvk_sampler_pair_f): the top 24 bits of the
 *    double pair, truncated (so they stay below 1 where rounding to float would give 1: planted,
 *    a rounded conversion of the largest uniform is 1), and still nets for 2^m points, m <= 10;
 *    the walk's other forms (dwvk_sampler_pair_at_f, _at_fd, _at with the index reversed once)
 *    equal the double pair's conversions, stratified, past 2^32 and unstratified. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "check.h"
#include "kernel/sampler.h"

static int is_net(const dwvk_sampler *base, uint32_t pair, int m, int single)
{
    uint32_t n = 1u << m;
    unsigned char *seen = malloc(n);
    int ok = seen != NULL;
    for (int k = 0; k <= m && ok; ++k) {
        for (uint32_t i = 0; i < n; ++i) seen[i] = 0;
        for (uint32_t i = 0; i < n && ok; ++i) {
            dwvk_sampler s = *base;
            s.index = i;
            double u[2];
            if (single) {
                dwvk_uniform_pair_f f = dwvk_sampler_pair_f(&s, pair);
                u[0] = f.a, u[1] = f.b;
            } else {
                dwvk_sampler_pair(&s, pair, u);
            }
            uint32_t a = (uint32_t)(u[0] * (double)(1u << k)), b = (uint32_t)(u[1] * (double)(1u << (m - k)));
            uint32_t cell = (a << (m - k)) | b;
            if (seen[cell]++) ok = 0;
        }
    }
    free(seen);
    return ok;
}

/* Uniformity of sample `index` across 2^16 pixel keys; `scrambled` 0 plants the unscrambled points. */
static int uniform_across_pixels(uint64_t index, int scrambled)
{
    const int n = 1 << 16;
    double sum[2] = {0, 0}, below[2] = {0, 0}, product = 0.0;
    for (int p = 0; p < n; ++p) {
        dwvk_sampler s = {.key = dwvk_rng_key(7u, (uint64_t)p, 0u), .index = index, .stratified = 1};
        double u[2];
        if (scrambled) {
            dwvk_sampler_pair(&s, 3u, u);
        } else {
            u[0] = dwvk_reverse_bits32((uint32_t)index) * 0x1.0p-32;
            u[1] = dwvk_sobol_second((uint32_t)index) * 0x1.0p-32;
        }
        for (int c = 0; c < 2; ++c) {
            sum[c] += u[c];
            below[c] += u[c] < 0.25;
        }
        product += (u[0] - 0.5) * (u[1] - 0.5);
    }
    int ok = 1;
    for (int c = 0; c < 2; ++c) {
        ok &= fabs(sum[c] / n - 0.5) < 5.0 * sqrt(1.0 / 12.0 / n);
        ok &= fabs(below[c] / n - 0.25) < 5.0 * sqrt(0.25 * 0.75 / n);
    }
    ok &= fabs(product / n) < 5.0 * (1.0 / 12.0) / sqrt((double)n);
    return ok;
}

int main(void)
{
    for (uint64_t pixel = 0; pixel < 4; ++pixel) {
        dwvk_sampler s = {.key = dwvk_rng_key(1u, pixel, 0u), .index = 0, .stratified = 1};
        for (uint32_t pair = 0; pair < 4; ++pair)
            for (int m = 1; m <= 10; ++m) {
                CHECK(is_net(&s, pair, m, 0), "pixel %llu pair %u: 2^%d points are not a net", (unsigned long long)pixel, pair, m);
                CHECK(is_net(&s, pair, m, 1), "pixel %llu pair %u: 2^%d single-precision points are not a net", (unsigned long long)pixel, pair, m);
            }
    }

    /* Planted: independent draws (an unstratified sampler keyed per sample index) are no net. */
    dwvk_sampler independent = {.key = dwvk_rng_key(1u, 0u, 0u), .index = 0, .stratified = 0};
    CHECK(!is_net(&independent, 0u, 10, 0), "independent points passed the net check");

    CHECK(uniform_across_pixels(5u, 1), "sample 5 is not uniform across pixels");
    CHECK(uniform_across_pixels(1000u, 1), "sample 1000 is not uniform across pixels");
    CHECK(!uniform_across_pixels(5u, 0), "the planted unscrambled points passed the uniformity check");

    dwvk_sampler s = {.key = dwvk_rng_key(3u, 9u, 0u), .index = 17u, .stratified = 1};
    double a[2], b[2];
    dwvk_sampler_pair(&s, 0u, a);
    dwvk_sampler_pair(&s, 1u, b);
    CHECK(a[0] != b[0] && a[1] != b[1], "pairs 0 and 1 share a coordinate");

    s.index = 0x100000000ull + 5u;
    dwvk_sampler_pair(&s, 2u, a);
    uint64_t key = dwvk_rng_key(s.key, 0u, s.index);
    CHECK(a[0] == dwvk_rng_uniform_d(key, 4u) && a[1] == dwvk_rng_uniform_d(key, 5u), "beyond 2^32 samples the pairs are not rng.h's");
    dwvk_sampler plain = {.key = 12345u, .index = 3u, .stratified = 0};
    dwvk_sampler_pair(&plain, 1u, a);
    CHECK(a[0] == dwvk_rng_uniform_d(12345u, 2u) && a[1] == dwvk_rng_uniform_d(12345u, 3u), "an unstratified sampler's pair is not rng.h's");
    for (uint32_t i = 0; i < 4096; ++i) {
        s.index = i;
        dwvk_sampler_pair(&s, 0u, a);
        if (!(a[0] >= 0.0 && a[0] < 1.0 && a[1] >= 0.0 && a[1] < 1.0)) {
            CHECK(0, "sample %u is outside [0, 1)", i);
            break;
        }
    }
    int same = 1;
    for (uint32_t i = 0; i < (1u << 20); ++i) {
        uint32_t hashed = (uint32_t)dwvk_mix64(i);
        same &= dwvk_sobol_second_reversed(i) == dwvk_reverse_bits32(dwvk_sobol_second(i));
        same &= dwvk_sobol_second_reversed(hashed) == dwvk_reverse_bits32(dwvk_sobol_second(hashed));
    }
    CHECK(same, "the loop-free Sobol coordinate differs from the definition");
    same = 1;
    for (uint32_t i = 0; i < (1u << 20); ++i) {
        uint64_t x = dwvk_mix64(i);
        uint64_t both = dwvk_reverse_bits32_pair(x);
        same &= (uint32_t)(both >> 32) == dwvk_reverse_bits32((uint32_t)x);
        same &= (uint32_t)both == dwvk_reverse_bits32((uint32_t)(x >> 32));
    }
    CHECK(same, "the paired reversal differs from two reversals");
    same = 1;
    for (uint32_t i = 0; i < 4096; ++i) {
        s.index = (uint64_t)i * 1048573u;
        double d[2];
        dwvk_sampler_pair(&s, 7u, d);
        uint64_t seeds = dwvk_rng_u64(s.key, 7u);
        uint32_t shuffled = dwvk_owen_scramble((uint32_t)s.index, (uint32_t)dwvk_mix64(seeds));
        same &= d[0] == dwvk_owen_scramble(dwvk_reverse_bits32(shuffled), (uint32_t)seeds) * 0x1.0p-32;
        same &= d[1] == dwvk_owen_scramble(dwvk_sobol_second(shuffled), (uint32_t)(seeds >> 32)) * 0x1.0p-32;
    }
    CHECK(same, "the pair is not the scrambles of the definition");

    /* The float conversion: exact on the 2^-24 grid, truncating below it. */
    const double largest = 1.0 - 0x1.0p-32; /* the largest stratified uniform */
    CHECK(dwvk_uniform_f_from_d(largest) == 1.0f - 0x1.0p-24f, "the largest uniform does not truncate to 1 - 2^-24");
    CHECK((float)largest == 1.0f, "planted: a rounded conversion does not reach 1 (the truncation would be moot)");
    CHECK(dwvk_uniform_f_from_d(0.0) == 0.0f && dwvk_uniform_f_from_d(0.5 + 0x1.0p-30) == 0.5f &&
              dwvk_uniform_f_from_d(0x1.0p-24) == 0x1.0p-24f,
          "the float conversion is not the truncation to 24 bits");
    for (uint32_t i = 0; i < 4096; ++i) {
        s.index = i;
        double d[2];
        dwvk_sampler_pair(&s, 5u, d);
        dwvk_uniform_pair_f f = dwvk_sampler_pair_f(&s, 5u);
        if (!(f.a == dwvk_uniform_f_from_d(d[0]) && f.b == dwvk_uniform_f_from_d(d[1]) && f.a < 1.0f && f.b < 1.0f)) {
            CHECK(0, "sample %u: the float pair is not the truncated double pair", i);
            break;
        }
    }
    /* The walk's forms (float pair, float-and-double pair, index reversed once) against the double
     * pair, stratified and past 2^32 and unstratified (rng.h's draws). */
    const dwvk_sampler forms[] = {{.key = dwvk_rng_key(3u, 9u, 0u), .index = 0, .stratified = 1},
                                  {.key = dwvk_rng_key(3u, 9u, 0u), .index = 0x100000000ull, .stratified = 1},
                                  {.key = 12345u, .index = 0, .stratified = 0}};
    for (size_t k = 0; k < sizeof forms / sizeof forms[0]; ++k) {
        int agree = 1;
        for (uint32_t i = 0; i < 4096; ++i) {
            dwvk_sampler f = forms[k];
            f.index += i;
            uint32_t reversed = dwvk_sampler_index_reversed(&f);
            double d[2], second;
            dwvk_sampler_pair(&f, 3u, d);
            dwvk_uniform_pair_f pf = dwvk_sampler_pair_at_f(&f, reversed, 3u);
            float first = dwvk_sampler_pair_at_fd(&f, reversed, 3u, &second);
            double again[2];
            dwvk_sampler_pair_at(&f, reversed, 3u, again);
            agree &= pf.a == dwvk_uniform_f_from_d(d[0]) && pf.b == dwvk_uniform_f_from_d(d[1]);
            agree &= first == dwvk_uniform_f_from_d(d[0]) && second == d[1];
            agree &= again[0] == d[0] && again[1] == d[1];
        }
        CHECK(agree, "sampler %zu: the walk's forms of the pair differ from the double pair", k);
    }
    return check_report("test_sampler");
}
