/* dwvk_exp_fast (src/kernel/fastmath.h) in a form a compiler vectorises, bit for bit the same
 * values: the loops that take one exponential per mixture component or light patch
 * (src/walk/walk.c) use it in copies for AVX2 and AVX-512. */
#ifndef DWV_KERNEL_EXP_BATCH_H
#define DWV_KERNEL_EXP_BATCH_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "kernel/fastmath.h"

/* dwvk_exp_fast(x) for |x| <= 708.39 (dwvk_exp_fast_is_edge(x) false), the same operations in the
 * same order, with one change that keeps every value: k is read from the bits of the shifted
 * product (x N/ln2 + 1.5 2^52 lies in [2^52, 2^53) for |k| < 2^51, where the ulp is 1, so its bits
 * are those of 1.5 2^52 plus k), so no packed double -> int64 conversion is needed, which AVX2
 * lacks. For any other x it returns some value without a trap or undefined behaviour (unsigned
 * arithmetic on whatever bits), which the caller replaces by dwvk_exp_fast(x): a loop takes it for
 * every element, vectorised, and then dwvk_exp_fast where an element was an edge. Built with
 * -ffp-contract=off where this must match the scalar function across targets (a fused
 * multiply-add rounds once where the scalar code rounds twice). */
static inline double dwvk_exp_fast_inner(double x)
{
    const double shift = 0x1.8p52;
    double shifted = x * DWVK_EXP_N_OVER_LN2 + shift;
    double kd = shifted - shift;
    double r = (x - kd * DWVK_EXP_LN2_N_HI) - kd * DWVK_EXP_LN2_N_LO;
    double p = 1.0 + r * (1.0 + r * (0.5 + r * (1.6666666666666666e-1 + r * (4.1666666666666664e-2 +
               r * 8.3333333333333332e-3))));
    uint64_t shifted_bits, shift_bits;
    memcpy(&shifted_bits, &shifted, sizeof shifted_bits);
    memcpy(&shift_bits, &shift, sizeof shift_bits);
    uint64_t k = shifted_bits - shift_bits + ((uint64_t)1 << 17); /* k + 2^17, as in dwvk_exp_fast */
    uint64_t e = (k >> DWVK_EXP_TABLE_BITS) - ((uint64_t)1 << (17 - DWVK_EXP_TABLE_BITS));
    uint64_t bits = DWVK_EXP_TABLE[k & (DWVK_EXP_TABLE_SIZE - 1)] + (e << 52);
    double scale;
    memcpy(&scale, &bits, sizeof scale);
    return p * scale;
}

/* 1 where dwvk_exp_fast(x) takes dwvk_exp_fast_edges (and dwvk_exp_fast_inner(x) is not it). */
static inline int dwvk_exp_fast_is_edge(double x)
{
    return !(fabs(x) <= 708.39);
}

#endif
