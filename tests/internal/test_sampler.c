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
 * 4. Beyond 2^32 samples, and for unstratified samplers, the pairs are rng.h's draws. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "check.h"
#include "kernel/sampler.h"

static int is_net(const dwvk_sampler *base, uint32_t pair, int m)
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
            dwvk_sampler_pair(&s, pair, u);
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
            for (int m = 1; m <= 10; ++m) CHECK(is_net(&s, pair, m), "pixel %llu pair %u: 2^%d points are not a net", (unsigned long long)pixel, pair, m);
    }

    /* Planted: independent draws (an unstratified sampler keyed per sample index) are no net. */
    dwvk_sampler independent = {.key = dwvk_rng_key(1u, 0u, 0u), .index = 0, .stratified = 0};
    CHECK(!is_net(&independent, 0u, 10), "independent points passed the net check");

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
    return check_report("test_sampler");
}
