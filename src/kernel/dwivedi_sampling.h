/* Dwivedi sampling of the cosine to an axis, with its pdf, in double and single precision.
 * Pure and inline: the walk calls these per scattering event. */
#ifndef DWV_KERNEL_DWIVEDI_SAMPLING_H
#define DWV_KERNEL_DWIVEDI_SAMPLING_H

#include <math.h>
#include <tgmath.h>

#include "diffusion_length.h"
#include "fastmath.h"

/* The sampling distribution's v is held at v >= 1 + 2^-20, i.e. 1 - kappa >= 2^-20 / (1 + 2^-20):
 * below that (alpha < ~0.137) the eigenfunction is a near-delta whose pdf would overflow. */
#define DWVK_DWIVEDI_V_MINUS_ONE_MIN 9.5367431640625e-07 /* 2^-20 */

/* The distribution's constants: kappa = 1/v, 1 - kappa, L = 2 atanh(kappa) and the effective
 * albedo a = 2 kappa / L (alpha itself when kappa is the exact root: Eq. 8). */
typedef struct dwvk_dwivedi_d { double kappa, one_minus_kappa, log_ratio, albedo_eff; } dwvk_dwivedi_d;
typedef struct dwvk_dwivedi_f { float kappa, one_minus_kappa, log_ratio, albedo_eff; } dwvk_dwivedi_f;

/* From a medium's kappa0 (any method): clamp v, make the constants one distribution (an
 * approximation's kappa and 1 - kappa need not add up to 1: the smaller of the two is the accurate
 * one, the other is derived from it), then L by the stable log1p form. */
static inline dwvk_dwivedi_d dwvk_dwivedi_from_kappa(dwvk_kappa_t k)
{
    double v_minus_one_min = DWVK_DWIVEDI_V_MINUS_ONE_MIN;
    if (!(k.one_minus_kappa >= v_minus_one_min * k.kappa)) {
        k.kappa = 1.0 / (1.0 + v_minus_one_min);
        k.one_minus_kappa = v_minus_one_min / (1.0 + v_minus_one_min);
        k.log_one_minus_kappa = log(k.one_minus_kappa);
    } else if (k.kappa < 0.5) {
        k.one_minus_kappa = 1.0 - k.kappa;
        k.log_one_minus_kappa = log1p(-k.kappa);
    } else {
        k.kappa = 1.0 - k.one_minus_kappa;
        k.log_one_minus_kappa = log(k.one_minus_kappa);
    }
    dwvk_dwivedi_d d;
    d.kappa = k.kappa;
    d.one_minus_kappa = k.one_minus_kappa;
    d.log_ratio = dwvk_log_ratio(k);
    d.albedo_eff = k.kappa > 0.0 ? 2.0 * k.kappa / d.log_ratio : 1.0; /* k / atanh(k) -> 1 */
    return d;
}

static inline dwvk_dwivedi_f dwvk_dwivedi_to_float(dwvk_dwivedi_d d)
{
    dwvk_dwivedi_f f = {(float)d.kappa, (float)d.one_minus_kappa, (float)d.log_ratio, (float)d.albedo_eff};
    return f;
}

#define DWVK_REAL double
#define DWVK_SUFFIX(name) name##_d
#include "dwivedi_sampling_real.h"
#undef DWVK_REAL
#undef DWVK_SUFFIX

#define DWVK_REAL float
#define DWVK_SUFFIX(name) name##_f
#include "dwivedi_sampling_real.h"
#undef DWVK_REAL
#undef DWVK_SUFFIX

/* ---- the walk's per-event sampler ---------------------------------------------------------- */

/* Per-medium constants of dwvk_dwivedi_event_sample_f, in single precision. */
typedef struct dwvk_dwivedi_event_f {
    float log_ratio;                     /* L; 2^-100 for kappa = 0 (see below) */
    float u_split;                       /* the u at which mu = 0: log1p(kappa) / L */
    /* Per branch, [0] for u > u_split (mu > 0), [1] for u <= u_split (mu <= 0), indexed rather
     * than chosen by a branch: u decides it at random, so a branch would be mispredicted half the
     * time. */
    float offset[2];                     /* 1, 0: x = (offset - u) L */
    float v_pm_one[2];                   /* v - 1, v + 1 = (1 -+ kappa) / kappa */
    float one_mp_kappa[2];               /* 1 - kappa, 1 + kappa */
    float sign[2];                       /* -1, 1: mu = sign (small - 1) */
} dwvk_dwivedi_event_f;

/* cos_theta is exact only to float's absolute rounding near +-1; `nearer` = 1 - |mu| (the smaller
 * of 1 -+ mu) and sin_theta keep their relative accuracy there. */
typedef struct dwvk_dwivedi_event_cosine_f { float cos_theta, sin_theta, stretch, nearer; } dwvk_dwivedi_event_cosine_f;

/* From the double constants. kappa = 0 (albedo 1, v infinite) is the uniform distribution
 * mu = 2u - 1; it is reached as the limit kappa -> 0 by taking L = 2^-100 and v +- 1 = 2 / L,
 * which gives 1 + mu = 2u (1 + O(L)) and stretch 1 to single precision. */
static inline dwvk_dwivedi_event_f dwvk_dwivedi_event_from(dwvk_dwivedi_d d)
{
    dwvk_dwivedi_event_f e;
    if (d.kappa > 0.0) {
        e.log_ratio = (float)d.log_ratio;
        e.u_split = (float)(log1p(d.kappa) / d.log_ratio);
        e.v_pm_one[1] = (float)((1.0 + d.kappa) / d.kappa);
        e.v_pm_one[0] = (float)(d.one_minus_kappa / d.kappa);
    } else {
        e.log_ratio = 0x1p-100f;
        e.u_split = 0.5f;
        e.v_pm_one[0] = e.v_pm_one[1] = 0x1p101f;
    }
    e.offset[0] = 1.0f;
    e.offset[1] = 0.0f;
    e.one_mp_kappa[0] = (float)d.one_minus_kappa;
    e.one_mp_kappa[1] = (float)(1.0 + d.kappa);
    e.sign[0] = -1.0f;
    e.sign[1] = 1.0f;
    return e;
}

/* The inverse CDF of dwvk_dwivedi_sample_pdf with one exponential in place of two. Of 1 + mu and
 * 1 - mu only the smaller needs its own form; the larger is 2 minus it, at least 1, exact to
 * rounding. With x = uL and (v - 1) exp(L) = v + 1:
 *   u <= u_split (mu <= 0):  1 + mu = (v + 1)(-expm1(-uL)),      stretch = (1 + kappa)(1 + expm1(-uL))
 *   u >  u_split (mu > 0):   1 - mu = (v - 1) expm1((1 - u)L),   stretch = (1 - kappa)(1 + expm1((1 - u)L))
 * where stretch = 1 - mu/v = (1 + kappa) exp(-uL). Each form is a product of non-negative terms
 * (1 + expm1 >= 1/2 on the first branch, >= 1 on the second): no cancellation anywhere, for any
 * albedo, and the stretch keeps its relative accuracy down to its floor 1 - kappa (2^-20 at the
 * clamp). Branch-free: the branch only indexes constants. u in [0, 1]; for the
 * walk's 24-bit uniforms 1 - u is exact. Measured against dwvk_dwivedi_sample_pdf_d in
 * tests/internal/test_fastmath.c. */
static inline dwvk_dwivedi_event_cosine_f dwvk_dwivedi_event_sample_f(const dwvk_dwivedi_event_f *d, float u)
{
    int low = u <= d->u_split;
    float x = (d->offset[low] - u) * d->log_ratio; /* -uL or (1 - u)L, both exact forms of u */
    float e = dwvk_expm1_fast_f(x);
    /* 1 + mu (low) or 1 - mu: at most 1 (at u_split), past it only by rounding, so 2 - small >= 1. */
    float small = d->v_pm_one[low] * fabsf(e);
    dwvk_dwivedi_event_cosine_f s;
    s.cos_theta = d->sign[low] * (small - 1.0f); /* small - 1 or 1 - small, exactly */
    s.sin_theta = sqrtf(small * (2.0f - small));
    s.nearer = small;
    s.stretch = d->one_mp_kappa[low] * (1.0f + e);
    return s;
}

/* dwvk_dwivedi_event_sample_f with the branch's constants picked by selects instead of an index:
 * the same arithmetic and the same values, bit for bit, in a form a compiler can vectorise over a
 * loop of independent samples (the estimator's lock-step lanes, src/walk/estimate_lanes.c). */
static inline dwvk_dwivedi_event_cosine_f dwvk_dwivedi_event_sample_select_f(const dwvk_dwivedi_event_f *d, float u)
{
    /* Both branches' constants loaded unconditionally, then selected (a conditional load would
     * keep the loop from being vectorised). */
    const float offset0 = d->offset[0], offset1 = d->offset[1], v_pm_one0 = d->v_pm_one[0], v_pm_one1 = d->v_pm_one[1];
    const float kappa0 = d->one_mp_kappa[0], kappa1 = d->one_mp_kappa[1], sign0 = d->sign[0], sign1 = d->sign[1];
    int low = u <= d->u_split;
    float offset = low ? offset1 : offset0, v_pm_one = low ? v_pm_one1 : v_pm_one0;
    float one_mp_kappa = low ? kappa1 : kappa0, sign = low ? sign1 : sign0;
    float e = dwvk_expm1_fast_f((offset - u) * d->log_ratio);
    float small = v_pm_one * fabsf(e);
    dwvk_dwivedi_event_cosine_f s;
    s.cos_theta = sign * (small - 1.0f);
    s.sin_theta = sqrtf(small * (2.0f - small));
    s.nearer = small;
    s.stretch = one_mp_kappa * (1.0f + e);
    return s;
}

#endif
