/* The ends of the uniform generator, reached on purpose: the kernel's output function
 * (SplitMix64's finaliser, src/kernel/rng.h) is a bijection, so inverting it gives the counters
 * (seed, stream, sample, dimension) whose 64 random bits are all ones or all zeros. There
 * dwv_random_uniform must give 1 - 2^-53 and dwv_random_uniform_f 1 - 2^-24, never 1 (a float
 * conversion of 64 or 53 bits that rounds would give 1.0f), and both 0 at all zeros. A random
 * search would need ~2^24 draws to see the float's largest value once, and could never see the
 * double's. */
#include <stdint.h>
#include <stdio.h>

#include "check.h"
#include <dwivedi.h>
#include "kernel/rng.h"

/* x = y ^ (y >> shift) solved for y (shift >= 1): y = x ^ (x >> shift) ^ (x >> 2 shift) ^ ... */
static uint64_t unxorshift(uint64_t x, int shift)
{
    uint64_t y = x;
    for (int s = shift; s < 64; s += shift) y ^= x >> s;
    return y;
}

/* The inverse of an odd number modulo 2^64, by Newton's iteration (each step doubles the bits). */
static uint64_t inverse_odd(uint64_t a)
{
    uint64_t x = a; /* correct to 3 bits for odd a */
    for (int i = 0; i < 6; ++i) x *= 2u - a * x;
    return x;
}

/* The inverse of dwvk_mix64: undo its three xorshifts and two multiplications in reverse. */
static uint64_t unmix64(uint64_t z)
{
    z = unxorshift(z, 31);
    z *= inverse_odd(0x94d049bb133111ebull);
    z = unxorshift(z, 27);
    z *= inverse_odd(0xbf58476d1ce4e5b9ull);
    return unxorshift(z, 30);
}

/* The sample number that makes (seed, stream, sample, dimension) produce `bits`: dimension's
 * output is mix64(key + (dimension + 1) gamma) and key = mix64(h + sample gamma), h depending on
 * seed and stream only (rng.h), so sample = (unmix(key) - h) / gamma modulo 2^64. */
static uint64_t sample_for(uint64_t seed, uint64_t stream, uint32_t dimension, uint64_t bits)
{
    uint64_t key = unmix64(bits) - (uint64_t)(dimension + 1u) * DWVK_GOLDEN_GAMMA;
    uint64_t h = dwvk_mix64(dwvk_mix64(seed + DWVK_GOLDEN_GAMMA) ^ stream);
    return (unmix64(key) - h) * inverse_odd(DWVK_GOLDEN_GAMMA);
}

int main(void)
{
    /* The inversion itself, on arbitrary values. */
    int wrong = 0;
    for (uint64_t i = 0; i < 10000; ++i) {
        uint64_t z = i * 0x9e3779b97f4a7c15ull ^ (i << 40);
        wrong += unmix64(dwvk_mix64(z)) != z || dwvk_mix64(unmix64(z)) != z;
    }
    CHECK(wrong == 0, "unmix64 is not the inverse of dwvk_mix64 on %d of 10000 values", wrong);

    /* A key from its seed's first stage (dwvk_rng_seed_base, once per run in the estimator's
     * lanes) is the key of the three chained stages written out, for every seed, stream and
     * sample tried (including the ends of their ranges). */
    const uint64_t spread[] = {0, 1, 2, 17, 0xdeadbeefull, 0x8000000000000000ull, UINT64_MAX - 1u, UINT64_MAX};
    int key_wrong = 0;
    for (int a = 0; a < 8; ++a)
        for (int b = 0; b < 8; ++b)
            for (int c = 0; c < 8; ++c) {
                uint64_t seed = spread[a], stream = spread[b], sample = spread[c];
                uint64_t chained = dwvk_mix64(dwvk_mix64(dwvk_mix64(seed + DWVK_GOLDEN_GAMMA) ^ stream) +
                                              sample * DWVK_GOLDEN_GAMMA);
                key_wrong += dwvk_rng_key_from_base(dwvk_rng_seed_base(seed), stream, sample) != chained;
                key_wrong += dwvk_rng_key(seed, stream, sample) != chained;
            }
    CHECK(key_wrong == 0, "a key from its seed base differs from the chained stages in %d of 1024 cases", key_wrong);

    const uint64_t seeds[] = {0, 1, 0xdeadbeefull};
    const uint32_t dimensions[] = {0, 1, 4000000000u};
    for (int i = 0; i < 3; ++i) {
        uint64_t seed = seeds[i], stream = 17u * (uint64_t)i;
        uint32_t dimension = dimensions[i];

        uint64_t top = sample_for(seed, stream, dimension, UINT64_MAX), bits = 0;
        double u = -1.0;
        float u_f = -1.0f;
        CHECK(dwv_random_u64(seed, stream, top, dimension, &bits) == DWV_SUCCESS && bits == UINT64_MAX,
              "counters (%llu, %llu, %llu, %u) were made to give all ones, gave %016llx", (unsigned long long)seed,
              (unsigned long long)stream, (unsigned long long)top, dimension, (unsigned long long)bits);
        CHECK(dwv_random_uniform(seed, stream, top, dimension, &u) == DWV_SUCCESS && u == 1.0 - 0x1p-53,
              "all ones: dwv_random_uniform = %a, expected 1 - 2^-53", u);
        CHECK(dwv_random_uniform_f(seed, stream, top, dimension, &u_f) == DWV_SUCCESS && u_f == 1.0f - 0x1p-24f,
              "all ones: dwv_random_uniform_f = %a, expected 1 - 2^-24 (never 1.0f)", (double)u_f);
        if (i == 0) printf("all ones at sample %llu: u = 1 - %.3g, u_f = 1 - %.3g\n", (unsigned long long)top, 1.0 - u,
                           1.0 - (double)u_f);

        uint64_t bottom = sample_for(seed, stream, dimension, 0);
        CHECK(dwv_random_u64(seed, stream, bottom, dimension, &bits) == DWV_SUCCESS && bits == 0,
              "counters were made to give all zeros, gave %016llx", (unsigned long long)bits);
        CHECK(dwv_random_uniform(seed, stream, bottom, dimension, &u) == DWV_SUCCESS && u == 0.0,
              "all zeros: dwv_random_uniform = %a, expected 0", u);
        CHECK(dwv_random_uniform_f(seed, stream, bottom, dimension, &u_f) == DWV_SUCCESS && u_f == 0.0f,
              "all zeros: dwv_random_uniform_f = %a, expected 0", (double)u_f);

        /* The top 25 bits ones, the rest zeros: halfway between 1 - 2^-24 and 1, where a
         * round-to-nearest-even conversion of the bits goes up to 1.0f; truncation to 24 bits
         * must give exactly 1 - 2^-24. */
        uint64_t edge = sample_for(seed, stream, dimension, 0xffffff8000000000ull);
        CHECK(dwv_random_uniform_f(seed, stream, edge, dimension, &u_f) == DWV_SUCCESS && u_f == 1.0f - 0x1p-24f,
              "bits ffffff8000000000: dwv_random_uniform_f = %a, expected 1 - 2^-24", (double)u_f);
    }
    return check_report("test_rng_boundaries");
}
