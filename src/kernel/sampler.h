/* Uniform numbers for the low dimensions of a pixel's samples, in pairs: either independent
 * counter-based draws (rng.h), or a stratified sequence, the first two dimensions of Sobol's
 * (0,2)-sequence in base 2 with a nested uniform (Owen) scramble per pixel, pair and coordinate.
 *
 * Why: a bake's pixel variance is mostly not the walk's. On the report's sphere, the pixel
 * position (silhouette coverage, shading across the pixel), the entry direction and area-light
 * points carry most of it (docs/speed.md), and those are low-dimensional integrands that a
 * stratified sequence integrates at a faster rate than 1/N. Cycles samples them the same way
 * (progressive multi-jittered or Sobol points per pixel).
 *
 * Unbiasedness: the scramble of a coordinate is a bijection x -> s(x) chosen by a 32-bit seed;
 * for a fixed x, seed -> s(x) is itself a bijection of 32-bit values (hash below), so with a
 * uniformly random seed every sample's coordinate is uniform on the 2^-32 grid, and coordinates
 * with independent seeds are independent: each sample has the distribution of an independent
 * one, only the samples of a pixel are correlated (negatively, for smooth integrands: Owen 1997,
 * "Scrambled net variance for integrals of smooth functions"). Pairs share the sequence; each
 * pair shuffles the sample index with a seed of its own (Burley 2020), as in the "padding" of
 * Kollig and Keller 2002, so that pairs do not reuse the same points in the same order.
 *
 * Prefixes: the sample indices of a pixel are 0, 1, 2, ... in order, so each power-of-two
 * prefix is a (0,m,2)-net in every pair; a bake cut by its time budget keeps an unbiased prefix.
 * Indices at or above 2^32 (beyond the sequence) fall back to independent draws. */
#ifndef DWV_KERNEL_SAMPLER_H
#define DWV_KERNEL_SAMPLER_H

#include <stdint.h>

#include "rng.h"

typedef struct dwvk_sampler {
    uint64_t key;   /* stratified: the pixel's key (the same for all its samples); else the sample's */
    uint64_t index; /* the sample's index within its pixel (stratified only) */
    int stratified;
} dwvk_sampler;

static inline uint32_t dwvk_reverse_bits32(uint32_t x)
{
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
#if defined(__GNUC__)
    return __builtin_bswap32(x); /* the byte swap is one instruction */
#else
    x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
    return (x >> 16) | (x << 16);
#endif
}

/* Sobol's second coordinate: the index's bits times the generator matrix whose columns are
 * v_1 = 2^31, v_k = v_{k-1} xor (v_{k-1} >> 1) (primitive polynomial x + 1, m_k = 1). */
static inline uint32_t dwvk_sobol_second(uint32_t index)
{
    uint32_t x = 0u;
    for (uint32_t v = 0x80000000u; index; index >>= 1, v ^= v >> 1)
        if (index & 1u) x ^= v;
    return x;
}

/* The same with its bits reversed, reverse(dwvk_sobol_second(index)), without a loop over the
 * bits: bit j of the product is the xor of the index's bits k whose positions contain j's
 * (k AND j = j): column k + 1 of the matrix holds binomial(k, j) mod 2 in digit j, which by
 * Lucas' theorem is 1 exactly then. That xor over supersets is five butterfly steps, one per bit
 * of the position, each folding the positions with that bit set onto those without. */
static inline uint32_t dwvk_sobol_second_reversed(uint32_t index)
{
    index ^= (index >> 1) & 0x55555555u;
    index ^= (index >> 2) & 0x33333333u;
    index ^= (index >> 4) & 0x0f0f0f0fu;
    index ^= (index >> 8) & 0x00ff00ffu;
    index ^= (index >> 16) & 0x0000ffffu;
    return index;
}

/* Laine and Karras' hash on reversed bits (the inside of dwvk_owen_scramble below). */
static inline uint32_t dwvk_laine_karras(uint32_t x, uint32_t seed)
{
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

/* A nested uniform scramble of the 32 binary digits of x (read as the fraction 0.x): each digit is
 * flipped by a hash of the digits before it. Done as Laine and Karras 2011 on the reversed bits,
 * where "before" becomes "below" and a multiply by an even constant carries only upward; the
 * constants are Burley's ("Practical Hash-based Owen Scrambling", JCGT 2020). Every step is a
 * bijection of x, and x + seed is a bijection of the seed. */
static inline uint32_t dwvk_owen_scramble(uint32_t x, uint32_t seed)
{
    return dwvk_reverse_bits32(dwvk_laine_karras(dwvk_reverse_bits32(x), seed));
}

/* dwvk_reverse_bits32 of both 32-bit halves of x at once, the halves swapped:
 * (reverse(low) << 32) | reverse(high), the 64-bit reversal (bit i goes to 63 - i). */
static inline uint64_t dwvk_reverse_bits32_pair(uint64_t x)
{
    x = ((x >> 1) & 0x5555555555555555ull) | ((x & 0x5555555555555555ull) << 1);
    x = ((x >> 2) & 0x3333333333333333ull) | ((x & 0x3333333333333333ull) << 2);
    x = ((x >> 4) & 0x0f0f0f0f0f0f0f0full) | ((x & 0x0f0f0f0f0f0f0f0full) << 4);
#if defined(__GNUC__)
    return __builtin_bswap64(x);
#else
    x = ((x >> 8) & 0x00ff00ff00ff00ffull) | ((x & 0x00ff00ff00ff00ffull) << 8);
    x = ((x >> 16) & 0x0000ffff0000ffffull) | ((x & 0x0000ffff0000ffffull) << 16);
    return (x >> 32) | (x << 32);
#endif
}

/* The reversed bits of a sample's index, the same for all its pairs: what dwvk_sampler_pair_at
 * takes, so that a caller drawing several pairs of one sample (a walk, two per event) reverses
 * the index once. */
static inline uint32_t dwvk_sampler_index_reversed(const dwvk_sampler *sampler)
{
    return dwvk_reverse_bits32((uint32_t)sampler->index);
}

/* The stratified pair's two 32-bit coordinates, first in the high half, where the sample is
 * stratified and its index below 2^32 (returns 1); else 0 and the pair is rng.h's
 * (dwvk_sampler_pair_at). index_reversed = dwvk_sampler_index_reversed(sampler). */
static inline int dwvk_sampler_pair_bits(const dwvk_sampler *sampler, uint32_t index_reversed, uint32_t pair,
                                         uint64_t *both)
{
    if (!(sampler->stratified && sampler->index < 0x100000000ull)) return 0;
    uint64_t seeds = dwvk_rng_u64(sampler->key, pair); /* two 32-bit scramble seeds */
    /* The index itself is shuffled per pair by the same nested scramble (Burley 2020, Sec. 4): the
     * first 2^m indices go to one aligned block of 2^m points of the sequence, still a net, but
     * to a different block and order for each pair. dwvk_owen_scramble(index, .) with the index's
     * reversal done by the caller. */
    uint32_t i = dwvk_reverse_bits32(dwvk_laine_karras(index_reversed, (uint32_t)dwvk_mix64(seeds)));
    /* The coordinates are owen_scramble(reverse(i)) and owen_scramble(sobol_second(i)); the
     * scramble reverses its input first, so the two reversals cancel (walks draw two pairs per
     * event: this is on their path), and the two output reversals are one 64-bit one. */
    uint64_t hashed = ((uint64_t)dwvk_laine_karras(dwvk_sobol_second_reversed(i), (uint32_t)(seeds >> 32)) << 32) |
                      dwvk_laine_karras(i, (uint32_t)seeds);
    *both = dwvk_reverse_bits32_pair(hashed);
    return 1;
}

/* The unstratified pair (independent draws of rng.h): the sample's own key, or for stratified
 * samples past 2^32 a key of their own. */
static inline void dwvk_sampler_pair_independent(const dwvk_sampler *sampler, uint32_t pair, double u[2])
{
    uint64_t key = sampler->stratified ? dwvk_rng_key(sampler->key, 0u, sampler->index) : sampler->key;
    u[0] = dwvk_rng_uniform_d(key, 2u * pair);
    u[1] = dwvk_rng_uniform_d(key, 2u * pair + 1u);
}

/* dwvk_sampler_pair with the index's reversed bits given (dwvk_sampler_index_reversed). */
static inline void dwvk_sampler_pair_at(const dwvk_sampler *sampler, uint32_t index_reversed, uint32_t pair, double u[2])
{
    uint64_t both;
    if (dwvk_sampler_pair_bits(sampler, index_reversed, pair, &both)) {
        u[0] = (double)(uint32_t)(both >> 32) * 0x1.0p-32;
        u[1] = (double)(uint32_t)both * 0x1.0p-32;
        return;
    }
    dwvk_sampler_pair_independent(sampler, pair, u);
}

/* The two uniforms on [0, 1) of pair `pair` (dimensions 2 pair and 2 pair + 1 of the sample). */
static inline void dwvk_sampler_pair(const dwvk_sampler *sampler, uint32_t pair, double u[2])
{
    dwvk_sampler_pair_at(sampler, dwvk_sampler_index_reversed(sampler), pair, u);
}

/* A uniform on [0, 1) as a float on the 2^-24 grid: its top 24 bits, truncated. */
static inline float dwvk_uniform_f_from_d(double u)
{
    return (float)(int32_t)(u * 0x1.0p24) * 0x1.0p-24f;
}

/* The same pair as single-precision uniforms on the 2^-24 grid (the walk's per-event sampling
 * runs in single precision): the top 24 bits, truncated, so that a uniform on a finer dyadic grid
 * stays uniform and never rounds up to 1 (a float conversion by rounding would). */
/* dwvk_sampler_pair_at_f from what dwvk_sampler_pair_bits gave for the pair: `have` its return
 * value, `both` its bits (used only where have is 1). */
static inline dwvk_uniform_pair_f dwvk_sampler_pair_given_f(const dwvk_sampler *sampler, uint32_t pair, int have,
                                                              uint64_t both)
{
    if (have) {
        /* dwvk_uniform_f_from_d of x 2^-32 is x's top 24 bits: (x >> 8) 2^-24, without the double */
        dwvk_uniform_pair_f f = {(float)(int32_t)(both >> 40) * 0x1.0p-24f,
                                 (float)(int32_t)((uint32_t)both >> 8) * 0x1.0p-24f};
        return f;
    }
    double u[2];
    dwvk_sampler_pair_independent(sampler, pair, u);
    dwvk_uniform_pair_f f = {dwvk_uniform_f_from_d(u[0]), dwvk_uniform_f_from_d(u[1])};
    return f;
}

static inline dwvk_uniform_pair_f dwvk_sampler_pair_at_f(const dwvk_sampler *sampler, uint32_t index_reversed,
                                                           uint32_t pair)
{
    uint64_t both = 0u;
    int have = dwvk_sampler_pair_bits(sampler, index_reversed, pair, &both);
    return dwvk_sampler_pair_given_f(sampler, pair, have, both);
}

/* The pair as the walk's flight takes it: the first number as dwvk_sampler_pair_at_f's (a float
 * on the 2^-24 grid), the second as dwvk_sampler_pair_at's (a double). */
static inline float dwvk_sampler_pair_given_fd(const dwvk_sampler *sampler, uint32_t pair, int have, uint64_t both,
                                               double *second)
{
    if (have) {
        *second = (double)(uint32_t)both * 0x1.0p-32;
        return (float)(int32_t)(both >> 40) * 0x1.0p-24f;
    }
    double u[2];
    dwvk_sampler_pair_independent(sampler, pair, u);
    *second = u[1];
    return dwvk_uniform_f_from_d(u[0]);
}

static inline float dwvk_sampler_pair_at_fd(const dwvk_sampler *sampler, uint32_t index_reversed, uint32_t pair,
                                            double *second)
{
    uint64_t both = 0u;
    int have = dwvk_sampler_pair_bits(sampler, index_reversed, pair, &both);
    return dwvk_sampler_pair_given_fd(sampler, pair, have, both, second);
}

static inline dwvk_uniform_pair_f dwvk_sampler_pair_f(const dwvk_sampler *sampler, uint32_t pair)
{
    return dwvk_sampler_pair_at_f(sampler, dwvk_sampler_index_reversed(sampler), pair);
}

#endif
