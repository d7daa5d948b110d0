/* Dwivedi sampling of the cosine to an axis, with its pdf, in double and single precision.
 * Pure and inline: the walk calls these per scattering event. */
#ifndef DWV_KERNEL_DWIVEDI_H
#define DWV_KERNEL_DWIVEDI_H

#include <math.h>
#include <tgmath.h>

#include "diffusion_length.h"

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
#include "dwivedi_real.h"
#undef DWVK_REAL
#undef DWVK_SUFFIX

#define DWVK_REAL float
#define DWVK_SUFFIX(name) name##_f
#include "dwivedi_real.h"
#undef DWVK_REAL
#undef DWVK_SUFFIX

#endif
