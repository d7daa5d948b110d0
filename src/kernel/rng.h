/* Counter-based random numbers: value = mix(key + dimension * gamma), the SplitMix64 generator
 * (Steele, Lea and Flood 2014) indexed by dimension instead of stepped, with the key a hash of
 * (seed, stream, sample). Pure functions: no state, so results do not depend on threads. */
#ifndef DWV_KERNEL_RNG_H
#define DWV_KERNEL_RNG_H

#include <stdint.h>

#define DWVK_GOLDEN_GAMMA 0x9e3779b97f4a7c15ull

/* Stafford's "Mix13" finaliser, the output function of SplitMix64: a bijection on 64 bits. */
static inline uint64_t dwvk_mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* The first stage of dwvk_rng_key (below): a function of the seed alone. */
static inline uint64_t dwvk_rng_seed_base(uint64_t seed)
{
    return dwvk_mix64(seed + DWVK_GOLDEN_GAMMA);
}

/* The later stages alone, from dwvk_rng_seed_base(seed): for loops over many keys of one seed
 * (two hashes per key instead of three). */
static inline uint64_t dwvk_rng_key_from_base(uint64_t seed_base, uint64_t stream, uint64_t sample)
{
    return dwvk_mix64(dwvk_mix64(seed_base ^ stream) + sample * DWVK_GOLDEN_GAMMA);
}

/* One key per (seed, stream, sample): chained bijections, so distinct triples give distinct
 * inputs to each stage. Hoist it out of the per-dimension loop. */
static inline uint64_t dwvk_rng_key(uint64_t seed, uint64_t stream, uint64_t sample)
{
    return dwvk_rng_key_from_base(dwvk_rng_seed_base(seed), stream, sample);
}

/* The counter that dimension `dimension` of `key` mixes; dimension d + j is this + j gamma, so a
 * loop over dimensions can step it by additions. */
static inline uint64_t dwvk_rng_counter(uint64_t key, uint32_t dimension)
{
    return key + (uint64_t)(dimension + 1u) * DWVK_GOLDEN_GAMMA;
}

static inline uint64_t dwvk_rng_u64(uint64_t key, uint32_t dimension)
{
    return dwvk_mix64(dwvk_rng_counter(key, dimension));
}

/* The top 53 (24) bits as a multiple of 2^-53 (2^-24): uniform on [0, 1), never 1. */
static inline double dwvk_rng_uniform_d(uint64_t key, uint32_t dimension)
{
    return (double)(dwvk_rng_u64(key, dimension) >> 11) * 0x1.0p-53;
}

/* The top 24 bits of a draw as a float uniform; through int32_t: one signed conversion, exact. */
static inline float dwvk_uniform_f_from_bits(uint64_t bits)
{
    return (float)(int32_t)(bits >> 40) * 0x1.0p-24f;
}

static inline float dwvk_rng_uniform_f(uint64_t key, uint32_t dimension)
{
    return dwvk_uniform_f_from_bits(dwvk_rng_u64(key, dimension));
}

/* Two 24-bit uniforms from one 64-bit draw: bits 63..40 and 39..16 (each uniform on [0, 1) in
 * steps of 2^-24, never 1, independent: SplitMix64's output bits are). One hash for two numbers. */
typedef struct dwvk_uniform_pair_f { float a, b; } dwvk_uniform_pair_f;

static inline dwvk_uniform_pair_f dwvk_uniform_pair_f_from_bits(uint64_t bits)
{
    dwvk_uniform_pair_f pair = {dwvk_uniform_f_from_bits(bits), (float)(int32_t)((bits >> 16) & 0xffffffu) * 0x1.0p-24f};
    return pair;
}

static inline dwvk_uniform_pair_f dwvk_rng_uniform_pair_f(uint64_t key, uint32_t dimension)
{
    return dwvk_uniform_pair_f_from_bits(dwvk_rng_u64(key, dimension));
}

#endif
