/* Body of src/kernel/dwivedi_sampling.h for one precision: included with DWVK_REAL (double or float) and
 * DWVK_SUFFIX(name) defined. <tgmath.h> picks exp/expm1/... of that precision. */

typedef DWVK_REAL DWVK_SUFFIX(dwvk_real);

typedef struct DWVK_SUFFIX(dwvk_dwivedi_sample) {
    DWVK_REAL cos_theta, one_minus_cos, one_plus_cos, pdf, stretch;
} DWVK_SUFFIX(dwvk_dwivedi_sample);

/* (1 - exp(-x)) / x for x >= 0, 1 at x = 0. */
static inline DWVK_REAL DWVK_SUFFIX(dwvk_one_minus_exp_neg_over)(DWVK_REAL x)
{
    return x > (DWVK_REAL)0 ? -expm1(-x) / x : (DWVK_REAL)1;
}

/* (exp(x) - 1) / x for x >= 0, 1 at x = 0. */
static inline DWVK_REAL DWVK_SUFFIX(dwvk_exp_minus_one_over)(DWVK_REAL x)
{
    return x > (DWVK_REAL)0 ? expm1(x) / x : (DWVK_REAL)1;
}

/* Stretch 1 - mu/v = 1 - kappa mu, as (1 - kappa) + kappa (1 - mu) for mu >= 0 (both terms >= 0,
 * no cancellation as v -> 1) and 1 + kappa |mu| otherwise. In (0, 2]. */
static inline DWVK_REAL DWVK_SUFFIX(dwvk_dwivedi_stretch)(const DWVK_SUFFIX(dwvk_dwivedi) *d,
                                                         DWVK_REAL mu)
{
    return mu >= (DWVK_REAL)0 ? d->one_minus_kappa + d->kappa * ((DWVK_REAL)1 - mu)
                              : (DWVK_REAL)1 - d->kappa * mu;
}

/* pdf p(mu) = 1 / (L (v - mu)) = a / (2 (1 - kappa mu)), Eq. 7 normalised by Eq. 6 (a = 2 kappa/L
 * makes it exact for any v, finite for v = infinity, where it is 1/2). */
static inline DWVK_REAL DWVK_SUFFIX(dwvk_dwivedi_pdf)(const DWVK_SUFFIX(dwvk_dwivedi) *d, DWVK_REAL mu)
{
    return d->albedo_eff / ((DWVK_REAL)2 * DWVK_SUFFIX(dwvk_dwivedi_stretch)(d, mu));
}

/* Inverse CDF mu = v - (v + 1) exp(-u L), u in [0, 1], in the forms that keep every output exact:
 *   1 + mu = (v + 1)(1 - exp(-u L))        = (1 + kappa) u (2/a) (1 - exp(-uL))/(uL)
 *   1 - mu = (v - 1)(exp((1 - u) L) - 1)   = (1 - kappa)(1 - u)(2/a) (exp((1-u)L) - 1)/((1-u)L)
 *   1 - mu/v = (1 + kappa) exp(-u L),      pdf = a / (2 (1 - mu/v)).
 * (v - 1) exp(L) = v + 1 gives the second line; L/kappa = 2/a removes 1/kappa. */
static inline DWVK_SUFFIX(dwvk_dwivedi_sample) DWVK_SUFFIX(dwvk_dwivedi_sample_pdf)(
    const DWVK_SUFFIX(dwvk_dwivedi) *d, DWVK_REAL u)
{
    const DWVK_REAL one = (DWVK_REAL)1, two = (DWVK_REAL)2;
    DWVK_REAL two_over_a = two / d->albedo_eff;
    DWVK_REAL x = u * d->log_ratio, y = (one - u) * d->log_ratio;
    DWVK_SUFFIX(dwvk_dwivedi_sample) s;
    s.one_plus_cos = (one + d->kappa) * u * two_over_a * DWVK_SUFFIX(dwvk_one_minus_exp_neg_over)(x);
    s.one_minus_cos = d->one_minus_kappa * (one - u) * two_over_a * DWVK_SUFFIX(dwvk_exp_minus_one_over)(y);
    s.one_plus_cos = s.one_plus_cos < two ? s.one_plus_cos : two;
    s.one_minus_cos = s.one_minus_cos < two ? s.one_minus_cos : two;
    s.cos_theta = s.one_plus_cos < s.one_minus_cos ? s.one_plus_cos - one : one - s.one_minus_cos;
    s.stretch = (one + d->kappa) * exp(-x);
    s.pdf = d->albedo_eff / (two * s.stretch);
    return s;
}
