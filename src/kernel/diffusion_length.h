/* Diffusion length v0(alpha): the positive root of supplemental Eq. 8, by four methods.
 * Set-up code (once per medium), double precision, libm only. */
#ifndef DWV_KERNEL_DIFFUSION_LENGTH_H
#define DWV_KERNEL_DIFFUSION_LENGTH_H

/* kappa0 = 1/v0 with its complement and that complement's logarithm, each without cancellation:
 * one_minus_kappa underflows below alpha ~ 0.0028, log_one_minus_kappa only below ~1e-308. */
typedef struct dwvk_kappa_t {
    double kappa;
    double one_minus_kappa;
    double log_one_minus_kappa;
} dwvk_kappa_t;

/* Each takes alpha in [0, 1] (the caller validates). */
dwvk_kappa_t dwvk_kappa_exact(double alpha);
dwvk_kappa_t dwvk_kappa_case(double alpha);
dwvk_kappa_t dwvk_kappa_deon(double alpha);
dwvk_kappa_t dwvk_kappa_fast(double alpha);

/* L = log((v + 1)/(v - 1)) = 2 atanh(kappa) = log1p(kappa) - log(1 - kappa): finite wherever
 * log(1 - kappa) is, +infinity for kappa = 1. */
double dwvk_log_ratio(dwvk_kappa_t k);

#endif
