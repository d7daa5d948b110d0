/* Single-precision transcendentals for the per-event path of the walk, inline and branch-free, so
 * that a scattering event calls no libm function. Each states its domain and its error bound; the
 * bounds are measured against double-precision libm in tests/internal/test_fastmath.c.
 *
 * The polynomials of expm1 and the azimuth are Cephes' single-precision ones (S. L. Moshier,
 * Cephes Math Library 2.2, expf.c / sinf.c), with the range reductions written here; log and the
 * double exp are table-driven, with tables from tools/gen_log_table.py and tools/gen_exp_table.py.
 * Plain C: no
 * compiler extension, no reliance on -ffast-math (the reductions depend on IEEE rounding). */
#ifndef DWV_KERNEL_FASTMATH_H
#define DWV_KERNEL_FASTMATH_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "exp_table.h"
#include "log_table.h"

static inline uint32_t dwvk_float_bits(float x)
{
    uint32_t bits;
    memcpy(&bits, &x, sizeof bits);
    return bits;
}

static inline float dwvk_bits_float(uint32_t bits)
{
    float x;
    memcpy(&x, &bits, sizeof x);
    return x;
}

/* exp(x) - 1 for x in [-80, 80], relative error below 4 float ulps (2.4e-7; measured 1.6e-7).
 * x = k ln2 + r with |r| <= ln2/2 (Cody-Waite, ln2 in two parts so that k ln2 is exact for
 * |k| <= 2^9); expm1(r) by its Taylor series to r^7 (truncation r^8/8! <= 2.6e-9 |r| relative);
 * then expm1(x) = 2^k expm1(r) + (2^k - 1), in which 2^k - 1 is exact for |k| <= 24 and the two
 * terms have the same sign for k >= 0 (no cancellation) and cancel by at most a factor of 3 for
 * k < 0 (x in [-1.04, -0.35] at k = -1). k = 0 returns expm1(r) itself: no cancellation near 0.
 * The rounding to the nearest k uses the 1.5 x 2^23 shift, exact in IEEE single precision. */
static inline float dwvk_expm1_fast_f(float x)
{
    const float shift = 0x1.8p23f;
    float k = (x * 1.44269504088896341f + shift) - shift;
    float r = (x - k * 0.693359375f) - k * -2.12194440e-4f;
    float p = r * (1.0f +
                   r * (0.5f + r * (1.66666672e-1f +
                                    r * (4.16666679e-2f + r * (8.33333377e-3f + r * (1.38888892e-3f + r * 1.98412701e-4f))))));
    float scale = dwvk_bits_float((uint32_t)((int32_t)k + 127) << 23); /* 2^k */
    return scale * p + (scale - 1.0f);
}

/* 2^e as a double, e integer in [-1022, 1023]: its bits. */
static inline double dwvk_pow2i(int64_t e)
{
    uint64_t bits = (uint64_t)(e + 1023) << 52;
    double scale;
    memcpy(&scale, &bits, sizeof scale);
    return scale;
}

/* The part of dwvk_exp_fast outside |x| <= 708.39: +infinity above 709.78, NaN for NaN, 0 below
 * -745.2, and in between 2^k exp(r) with 2^k split in two where it is not a normal double (as
 * libm, subnormal results from -708.4 on). exp(r) by its Taylor series to r^12 on |r| <= ln2/2
 * (truncation r^13/13! < 2e-16). */
static inline double dwvk_exp_fast_edges(double x)
{
    if (!(x < 709.782712893384)) return x > 0.0 ? INFINITY : x; /* +inf, or NaN */
    if (x < -745.2) return 0.0;
    const double shift = 0x1.8p52;
    double k = (x * 1.4426950408889634 + shift) - shift;
    double r = (x - k * 0x1.62e42fee00000p-1) - k * 0x1.a39ef35793c76p-33;
    double p = 1.0 + r * (1.0 + r * (0.5 + r * (1.6666666666666666e-1 + r * (4.1666666666666664e-2 +
               r * (8.3333333333333332e-3 + r * (1.3888888888888889e-3 + r * (1.9841269841269841e-4 +
               r * (2.4801587301587302e-5 + r * (2.7557319223985893e-6 + r * (2.7557319223985888e-7 +
               r * (2.5052108385441720e-8 + r * 2.0876756987868100e-9)))))))))));
    int64_t ki = (int64_t)k;
    if (ki < -1022) return p * dwvk_pow2i(ki + 1000) * 0x1p-1000; /* 2^k = 2^(k + 1000) 2^-1000 */
    if (ki > 1023) return p * dwvk_pow2i(ki - 1) * 2.0;            /* x in (709.09, 709.78) */
    return p * dwvk_pow2i(ki);
}

/* exp(x) in double precision, relative error below 5e-16 (measured 3.6e-16 against long double in
 * tests/internal/test_fastmath.c) for x in [-708, 709.78], 0 below -745.2 and +infinity above
 * 709.78, NaN for NaN; exp(0) = 1 exactly. Table-driven: x = k ln2/64 + r with |r| <= ln2/128
 * (plus rounding), ln2/64 in two parts (k ln2/64_hi exact for |k| < 2^17), then
 * exp(x) = 2^floor(k/64) 2^((k mod 64)/64) exp(r), the middle factor from a table of 64 doubles
 * (src/kernel/exp_table.h, tools/gen_exp_table.py) and exp(r) by its Taylor series to r^5
 * (truncation r^6/720 < 4e-17 relative). Errors: the table 0.5 ulp, the series' evaluation about
 * 0.5 ulp (1 + a sum below 0.006), the product 0.5 ulp. About half the instructions of a
 * series to r^12 on |r| <= ln2/2, the form it replaces (6e-16). For |x| <= 708.39 the power of
 * two is a normal double and goes into the table entry's exponent; the rest takes
 * dwvk_exp_fast_edges. The walk's weights and the estimator's fast path use this same function,
 * so their weights agree to the last bit. */
static inline double dwvk_exp_fast(double x)
{
    if (!(fabs(x) <= 708.39)) return dwvk_exp_fast_edges(x);
    const double shift = 0x1.8p52;
    double kd = (x * DWVK_EXP_N_OVER_LN2 + shift) - shift; /* |k| <= 65408 */
    double r = (x - kd * DWVK_EXP_LN2_N_HI) - kd * DWVK_EXP_LN2_N_LO;
    double p = 1.0 + r * (1.0 + r * (0.5 + r * (1.6666666666666666e-1 + r * (4.1666666666666664e-2 +
               r * 8.3333333333333332e-3))));
    /* k + 2^17 >= 0, so that floor(k / 64) is a shift of an unsigned number */
    uint64_t k = (uint64_t)((int64_t)kd + ((int64_t)1 << 17));
    int64_t e = (int64_t)(k >> DWVK_EXP_TABLE_BITS) - ((int64_t)1 << (17 - DWVK_EXP_TABLE_BITS)); /* in [-1022, 1022] */
    /* the table entry is in [1, 2): adding e to its exponent field multiplies it by 2^e (mod 2^64) */
    uint64_t bits = DWVK_EXP_TABLE[k & (DWVK_EXP_TABLE_SIZE - 1)] + ((uint64_t)e << 52);
    double scale;
    memcpy(&scale, &bits, sizeof scale);
    return p * scale;
}

/* dwvk_log_fast (below) in two parts, for loops over lanes that vectorise its arithmetic and read
 * the table in a loop of their own (its lookups are gathers): the table index of x, with k and z
 * of x = 2^k z. */
static inline int32_t dwvk_log_fast_split(float x, int32_t *k, double *z)
{
    uint32_t bits = dwvk_float_bits(x);
    uint32_t offset = bits - DWVK_LOG_TABLE_OFF;
    /* k = floor(offset / 2^23) as a signed number, biased by 128 so that the shift is unsigned
     * (x positive normal: no wrap-around). */
    *k = (int32_t)((offset + 0x40000000u) >> 23) - 128;
    *z = (double)dwvk_bits_float(bits - ((uint32_t)*k << 23));
    return (int32_t)((offset >> DWVK_LOG_TABLE_SHIFT) % DWVK_LOG_TABLE_SIZE);
}

/* ... and log x from k, z and the index's table row {1/c, log c}. */
static inline double dwvk_log_fast_join(int32_t k, double z, double invc, double logc)
{
    double r = z * invc - 1.0;
    double r2 = r * r;
    double log1p_r = r + r2 * (-0.5 + r * (0.33333333333333333 - 0.25 * r));
    return (double)k * 0.69314718055994531 + logc + log1p_r;
}

/* log(x) for positive normal float x, in double: absolute error below 1e-9 for x in [1/2, 2],
 * relative error below 1e-9 elsewhere, and for x in [0.984375, 1) (log(1 - u), u small) relative
 * error below 2e-8 (measured 1.9e-10, 2.7e-10 and 1.2e-8: tests/internal/test_fastmath.c). Table-driven (as
 * in ARM's optimized-routines logf, with a table of our own, tools/gen_log_table.py):
 * x = 2^k z, z in [0.703125, 1.40625) read from the bits, then log x = k ln2 + log c + log1p(r)
 * with r = z / c - 1 = z invc - 1 exact in double (invc has 21 significant bits) and |r| < 1/64,
 * so log1p(r) = r - r^2/2 + r^3/3 - r^4/4 to 1.2e-8 relative (r^4 / 5). The interval just below
 * 1 has invc = 1 (log c = 0), so log(1 - u) = log1p(-u) there keeps its relative accuracy. */
static inline double dwvk_log_fast(float x)
{
    int32_t k;
    double z;
    int32_t i = dwvk_log_fast_split(x, &k, &z);
    return dwvk_log_fast_join(k, z, DWVK_LOG_TABLE[i][0], DWVK_LOG_TABLE[i][1]);
}

/* An exponential free flight in units of 1/sigma: -log(1 - u) for u = i 2^-24, i in [0, 2^24)
 * (the walk's 24-bit uniforms), where 1 - u is exact and at least 2^-24, so the result is finite,
 * at most 24 ln 2 = 16.6, with the relative error of dwvk_log_fast. */
static inline double dwvk_free_flight(float u)
{
    return -dwvk_log_fast(1.0f - u);
}

typedef struct dwvk_unit2_f { float c, s; } dwvk_unit2_f;

/* A uniformly distributed azimuth from u in [0, 1], in two parts:
 *   phi = q pi/2 + theta,   4u = q + r, q integer (taken mod 4), r in [0, 1), theta = (r - 1/2) pi/2.
 * phi covers [-pi/4, 7 pi/4) uniformly: the usual 2 pi u turned by -pi/4, which an isotropic
 * azimuth does not see. This returns (cos theta, sin theta) and the quarter turns q; only theta in
 * [-pi/4, pi/4] meets a polynomial: Cephes' sinf, and cos theta = sqrt(1 - sin^2 theta) (at least
 * 1/sqrt(2): no cancellation), so c^2 + s^2 = 1 to rounding. Absolute error below 1.5e-7 in each
 * (measured 1.2e-7 in angle) and |c^2 + s^2 - 1| below 3e-7. */
static inline dwvk_unit2_f dwvk_azimuth_quadrant_f(float u, int32_t *quarter_turns)
{
    float four_u = 4.0f * u; /* exact */
    int32_t q = (int32_t)four_u;
    float theta = ((four_u - (float)q) - 0.5f) * 1.57079632679489662f;
    float z = theta * theta;
    dwvk_unit2_f out;
    out.s = theta + theta * z * ((-1.9515295891e-4f * z + 8.3321608736e-3f) * z - 1.6666654611e-1f);
    out.c = sqrtf(1.0f - out.s * out.s);
    *quarter_turns = q & 3;
    return out;
}

/* (c, s) turned by q quarter turns: (c, s), (-s, c), (-c, -s), (s, -c) for q = 0 .. 3. Exact. */
static inline dwvk_unit2_f dwvk_quarter_turns_f(dwvk_unit2_f p, int32_t q)
{
    int swap = q & 1, negate_c = ((q + 1) >> 1) & 1, negate_s = (q >> 1) & 1;
    dwvk_unit2_f out;
    out.c = swap ? p.s : p.c;
    out.s = swap ? p.c : p.s;
    out.c = negate_c ? -out.c : out.c;
    out.s = negate_s ? -out.s : out.s;
    return out;
}

/* The point (cos phi, sin phi) of the azimuth above. */
static inline dwvk_unit2_f dwvk_azimuth_f(float u)
{
    int32_t q;
    dwvk_unit2_f p = dwvk_azimuth_quadrant_f(u, &q);
    return dwvk_quarter_turns_f(p, q);
}

#endif
