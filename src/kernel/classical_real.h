/* Body of src/kernel/classical.h for one precision (DWVK_REAL, DWVK_SUFFIX, DWVK_ONE_BELOW). */

/* Isotropic phase function: mu = 2u - 1, pdf 1/(4 pi) per steradian. */
static inline DWVK_REAL DWVK_SUFFIX(dwvk_isotropic_sample)(DWVK_REAL u)
{
    return (DWVK_REAL)2 * u - (DWVK_REAL)1;
}

/* Henyey-Greenstein, g in (-1, 1), mu the cosine between the directions of travel before and after.
 * The textbook inverse CDF mu = (1 + g^2 - ((1 - g^2)/(1 - g + 2gu))^2) / (2g) divides by g and
 * cancels for small |g|; multiplied out it is
 *   mu = (2u (1 + g^2)(1 - g + gu) - (1 - g)^2) / D^2,   D = 1 - g + 2gu,
 * exact at g = 0 (mu = 2u - 1), -1 at u = 0 and 1 at u = 1. */
static inline DWVK_REAL DWVK_SUFFIX(dwvk_hg_sample)(DWVK_REAL g, DWVK_REAL u)
{
    const DWVK_REAL one = (DWVK_REAL)1;
    DWVK_REAL one_minus_g = one - g;
    DWVK_REAL D = one_minus_g + (DWVK_REAL)2 * g * u;
    DWVK_REAL mu = ((DWVK_REAL)2 * u * (one + g * g) * (one_minus_g + g * u) - one_minus_g * one_minus_g) / (D * D);
    return mu < -one ? -one : mu > one ? one : mu;
}

/* HG pdf per steradian: (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^(3/2)), with the denominator's base
 * written as (1 - g)^2 + 2g (1 - mu) for g >= 0 and (1 + g)^2 - 2g (1 + mu) for g < 0: a sum of
 * non-negative terms either way. */
static inline DWVK_REAL DWVK_SUFFIX(dwvk_hg_pdf)(DWVK_REAL g, DWVK_REAL mu)
{
    const DWVK_REAL one = (DWVK_REAL)1, two = (DWVK_REAL)2;
    DWVK_REAL base = g >= (DWVK_REAL)0 ? (one - g) * (one - g) + two * g * (one - mu)
                                       : (one + g) * (one + g) - two * g * (one + mu);
    return (DWVK_REAL)DWVK_INV_FOUR_PI * (one - g) * (one + g) / (base * sqrt(base));
}

/* Exponential free flight: t = -log(1 - u) / sigma with pdf sigma exp(-sigma t); u is held below 1
 * so that t stays finite. */
static inline DWVK_REAL DWVK_SUFFIX(dwvk_exponential_sample)(DWVK_REAL sigma, DWVK_REAL u)
{
    return -log1p(-(u < DWVK_ONE_BELOW ? u : DWVK_ONE_BELOW)) / sigma;
}

static inline DWVK_REAL DWVK_SUFFIX(dwvk_exponential_pdf)(DWVK_REAL sigma, DWVK_REAL t)
{
    return sigma * exp(-sigma * t);
}
