/* Single-precision transcendentals for the per-event path of the walk, inline and branch-free, so
 * that a scattering event calls no libm function. Each states its domain and its error bound; the
 * bounds are measured against double-precision libm in tests/internal/test_fastmath.c.
 *
 * The polynomials are Cephes' single-precision ones (S. L. Moshier, Cephes Math Library 2.2,
 * expf.c / logf.c / sinf.c / cosf.c), with the range reductions written here. Plain C: no
 * compiler extension, no reliance on -ffast-math (the reductions depend on IEEE rounding). */
#ifndef DWV_KERNEL_FASTMATH_H
#define DWV_KERNEL_FASTMATH_H

#include <math.h>
#include <stdint.h>
#include <string.h>

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

/* log(x) for positive normal x, absolute error below 1.5e-7 for x in [1/2, 2] and relative error
 * below 1.5e-7 elsewhere (measured 9e-8 and 7e-8). x = 2^e m with m in [sqrt(1/2), sqrt(2)), read
 * from the bits; f = m - 1 is exact (Sterbenz), so log(1 - u) keeps full relative accuracy for
 * small u where 1 - u is exact; log(m) = f - f^2/2 + f^3 P(f) with Cephes' degree-8 P, and
 * e ln2 added in two parts. */
static inline float dwvk_log_fast_f(float x)
{
    uint32_t bits = dwvk_float_bits(x);
    /* The exponent field of x / sqrt(1/2), biased by 128 so that the shift is of an unsigned
     * value (x positive normal: no wrap-around). */
    int32_t e = (int32_t)((bits - 0x3f3504f3u + 0x40000000u) >> 23) - 128;
    float m = dwvk_bits_float(bits - ((uint32_t)e << 23));
    float f = m - 1.0f, z = f * f, fe = (float)e;
    float y = (((((((( 7.0376836292e-2f * f - 1.1514610310e-1f) * f + 1.1676998740e-1f) * f - 1.2420140846e-1f) * f +
                   1.4249322787e-1f) * f - 1.6668057665e-1f) * f + 2.0000714765e-1f) * f - 2.4999993993e-1f) * f +
               3.3333331174e-1f) * f * z;
    y += -2.12194440e-4f * fe;
    y += -0.5f * z;
    return (f + y) + 0.693359375f * fe;
}

/* An exponential free flight in units of 1/sigma: -log(1 - u) for u = i 2^-24, i in [0, 2^24)
 * (the walk's 24-bit uniforms), where 1 - u is exact and at least 2^-24, so the result is finite,
 * at most 24 ln 2 = 16.6, with the relative error of dwvk_log_fast_f. */
static inline float dwvk_free_flight_f(float u)
{
    return -dwvk_log_fast_f(1.0f - u);
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
