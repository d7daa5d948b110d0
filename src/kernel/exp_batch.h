/* dwvk_exp_fast (src/kernel/fastmath.h) over an array, bit for bit the same values, in loops a
 * compiler vectorises: the loops that take one exponential per mixture component or light patch
 * (src/walk/walk.c) call it in copies for AVX2 and AVX-512. */
#ifndef DWV_KERNEL_EXP_BATCH_H
#define DWV_KERNEL_EXP_BATCH_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "kernel/fastmath.h"

/* y[i] = dwvk_exp_fast(x[i]) for i < n, the same operations in the same order, with two changes
 * that keep every value: k is read from the bits of the shifted product (x N/ln2 + 1.5 2^52 lies
 * in [2^52, 2^53) for |k| < 2^51, where the ulp is 1, so its bits are those of 1.5 2^52 plus k: no
 * packed double -> int64 conversion is needed, which AVX2 lacks), and the arguments beyond
 * |x| <= 708.39 are formed as the others (unsigned arithmetic on garbage bits, no trap) and then
 * replaced by dwvk_exp_fast_edges in a second loop, run only where there is one. Built with
 * -ffp-contract=off where this must match the scalar function across targets (a fused
 * multiply-add rounds once where the scalar code rounds twice). */
static inline void dwvk_exp_fast_batch(const double *restrict x, double *restrict y, int n)
{
    const double shift = 0x1.8p52;
    uint64_t shift_bits;
    memcpy(&shift_bits, &shift, sizeof shift_bits);
    int edges = 0;
    for (int i = 0; i < n; ++i) {
        double shifted = x[i] * DWVK_EXP_N_OVER_LN2 + shift;
        double kd = shifted - shift;
        double r = (x[i] - kd * DWVK_EXP_LN2_N_HI) - kd * DWVK_EXP_LN2_N_LO;
        double p = 1.0 + r * (1.0 + r * (0.5 + r * (1.6666666666666666e-1 + r * (4.1666666666666664e-2 +
                   r * 8.3333333333333332e-3))));
        uint64_t shifted_bits;
        memcpy(&shifted_bits, &shifted, sizeof shifted_bits);
        uint64_t k = shifted_bits - shift_bits + ((uint64_t)1 << 17); /* k + 2^17, as in dwvk_exp_fast */
        uint64_t e = (k >> DWVK_EXP_TABLE_BITS) - ((uint64_t)1 << (17 - DWVK_EXP_TABLE_BITS));
        uint64_t bits = DWVK_EXP_TABLE[k & (DWVK_EXP_TABLE_SIZE - 1)] + (e << 52);
        double scale;
        memcpy(&scale, &bits, sizeof scale);
        y[i] = p * scale;
        edges |= !(fabs(x[i]) <= 708.39);
    }
    if (edges)
        for (int i = 0; i < n; ++i)
            if (!(fabs(x[i]) <= 708.39)) y[i] = dwvk_exp_fast_edges(x[i]);
}

#endif
