#include "diffusion_length.h"

#include <math.h>

static const double LN2 = 0.69314718055994530942;

static dwvk_kappa_t kappa_from_complement(double one_minus_kappa, double log_one_minus_kappa)
{
    dwvk_kappa_t k = {1.0 - one_minus_kappa, one_minus_kappa, log_one_minus_kappa};
    return k;
}

static dwvk_kappa_t kappa_from_value(double kappa)
{
    dwvk_kappa_t k = {kappa, 1.0 - kappa, log1p(-kappa)};
    return k;
}

static const dwvk_kappa_t KAPPA_ALPHA_ZERO = {1.0, 0.0, -INFINITY}; /* v0 = 1 */
static const dwvk_kappa_t KAPPA_ALPHA_ONE = {0.0, 1.0, 0.0};        /* v0 = infinity */

double dwvk_log_ratio(dwvk_kappa_t k)
{
    return log1p(k.kappa) - k.log_one_minus_kappa;
}

/* ---- exact ------------------------------------------------------------------------------- */

/* (atanh(k) - k) / k = sum_{n>=1} k^(2n) / (2n+1), and its derivative in k, by the series for
 * k < 0.5 (no cancellation) and by the closed forms above. */
static void atanh_excess(double k, double *value, double *derivative)
{
    if (k < 0.5) {
        double k2 = k * k, term = k2, sum = 0.0, dsum = 0.0;
        for (int n = 1; n <= 64 && term > 1e-19 * sum; ++n) {
            sum += term / (2 * n + 1);
            dsum += term * (2.0 * n / (2 * n + 1));
            term *= k2;
        }
        *value = sum;
        *derivative = dsum / k;
    } else {
        double at = atanh(k);
        *value = (at - k) / k;
        *derivative = 1.0 / (k * (1.0 - k * k)) - at / (k * k);
    }
}

/* High albedo (alpha > 0.5, kappa < 0.9576): Eq. 8 as (atanh(k) - k)/k = (1 - alpha)/alpha,
 * which keeps its accuracy as alpha -> 1 (1 - alpha is exact there). Safeguarded Newton on the
 * increasing function k -> (atanh(k) - k)/k, started from Case's Eq. 11 to first order. */
static double kappa_exact_high(double alpha)
{
    double target = (1.0 - alpha) / alpha;
    double lo = 0.0, hi = 0.9576; /* kappa0(0.5) = 0.95750402... */
    double k = sqrt(3.0 * (1.0 - alpha)) * (1.0 - 0.4 * (1.0 - alpha));
    if (!(k > lo && k < hi)) k = 0.5 * (lo + hi);
    for (int iteration = 0; iteration < 100; ++iteration) {
        double value, derivative;
        atanh_excess(k, &value, &derivative);
        double residual = value - target;
        if (residual > 0.0) hi = k; else lo = k;
        double next = k - residual / derivative;
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        double step = fabs(next - k);
        k = next;
        if (step <= 1e-17 * k || hi - lo <= 1e-17 * k) break;
    }
    return k;
}

/* Low albedo (alpha <= 0.5): with 1 - k = 2 E exp(d), E = exp(-2/alpha), Eq. 8 becomes
 * d = log1p(-e/2) + 2 e / alpha (e = 1 - k), whose root d >= 0 is small. The function
 * K(d) = d - log1p(-e/2) - 2e/alpha is increasing and concave there, so Newton from d = 0 climbs
 * monotonically to it. 2/alpha is carried as a double-double so that exp(-2/alpha) and
 * log(1 - k) = log 2 - 2/alpha + d keep full relative accuracy even where 2/alpha ~ 700. */
static dwvk_kappa_t kappa_exact_low(double alpha)
{
    double q = 2.0 / alpha;
    if (isinf(q)) return KAPPA_ALPHA_ZERO; /* subnormal alpha: log(1 - kappa) < -DBL_MAX */
    double q_low = fma(-q, alpha, 2.0) / alpha; /* 2/alpha = q + q_low exactly to ~2^-106 */
    /* 2 exp(-2/alpha); where exp(-q) underflows, |q_low| may exceed 709 and must not meet it. */
    double two_e = q > 746.0 ? 0.0 : 2.0 * exp(-q) * exp(-q_low); /* here |q_low| < 1e-13 */
    double d = 0.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
        double e = two_e * exp(d);
        double residual = d - log1p(-0.5 * e) - e * q;
        double derivative = 1.0 + e / (2.0 - e) - e * q;
        double step = residual / derivative;
        d -= step;
        if (fabs(step) <= 1e-17) break;
    }
    double one_minus_kappa = two_e * exp(d);
    double log_one_minus_kappa = ((LN2 + d) - q) - q_low;
    return kappa_from_complement(one_minus_kappa, log_one_minus_kappa);
}

dwvk_kappa_t dwvk_kappa_exact(double alpha)
{
    if (alpha <= 0.0) return KAPPA_ALPHA_ZERO;
    if (alpha >= 1.0) return KAPPA_ALPHA_ONE;
    if (alpha <= 0.5) return kappa_exact_low(alpha);
    return kappa_from_value(kappa_exact_high(alpha));
}

/* ---- case: supplemental Eqs. 10 and 11, as written --------------------------------------- */

dwvk_kappa_t dwvk_kappa_case(double alpha)
{
    if (alpha <= 0.0) return KAPPA_ALPHA_ZERO;
    if (alpha < 0.56) {
        /* Eq. 10; the powers of e^(-2/alpha)/alpha are formed as q^n so that nothing overflows
         * as alpha -> 0 (q underflows to 0 instead). */
        double a = alpha, E = exp(-2.0 / a), q = E / a;
        double bracket_minus_one = (4.0 - a) * q + (24.0 - 12.0 * a + a * a) * q * q +
                                   (512.0 - 384.0 * a + 72.0 * a * a - 3.0 * a * a * a) * q * q * q;
        double one_minus_kappa = 2.0 * E * (1.0 + bracket_minus_one);
        double log_one_minus_kappa = LN2 - 2.0 / a + log1p(bracket_minus_one);
        return kappa_from_complement(one_minus_kappa, log_one_minus_kappa);
    }
    /* Eq. 11, with v0(0.9999) used for every alpha >= 0.9999. */
    double s = 1.0 - (alpha >= 0.9999 ? 0.9999 : alpha);
    double k = sqrt(3.0 * s) * (1.0 - 2.0 / 5.0 * s - 12.0 / 175.0 * s * s - 2.0 / 125.0 * s * s * s -
                                166.0 / 67375.0 * s * s * s * s);
    return kappa_from_value(k);
}

/* ---- deon: d'Eon and Krivanek 2020 -------------------------------------------------------- */

/* kappa = sqrt(1 - x), x = alpha^p, with 1 - x = -expm1(p log(alpha)) exact as alpha -> 1;
 * 1 - kappa = x / (1 + kappa) and log(1 - kappa) = p log(alpha) - log1p(kappa) stay exact where x
 * is tiny or underflows. */
dwvk_kappa_t dwvk_kappa_deon(double alpha)
{
    if (alpha <= 0.0) return KAPPA_ALPHA_ZERO;
    if (alpha >= 1.0) return KAPPA_ALPHA_ONE;
    double p = 2.44294 - 0.0215813 * alpha + 0.578637 / alpha;
    double log_x = p * log(alpha);
    double x = exp(log_x);
    double k = sqrt(-expm1(log_x));
    dwvk_kappa_t out = {k, x / (1.0 + k), log_x - log1p(k)};
    return out;
}
