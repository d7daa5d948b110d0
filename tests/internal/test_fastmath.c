/* The walk's per-event single-precision kernels against double-precision libm, over their whole
 * domains where that is feasible (every 24-bit uniform the walk can draw), and the error bounds
 * their comments state (src/kernel/fastmath.h, src/kernel/dwivedi_sampling.h):
 *   dwvk_expm1_fast_f       relative error < 2.4e-7 on [-80, 80]
 *   dwvk_exp_fast (double)  relative error < 5e-16 on [-708, 709.78] against long double's expl
 *                           (the table-driven fast part and the edge path beyond |x| = 708.39);
 *                           overflow, underflow, subnormal results, NaN, exp(0) = 1
 *   dwvk_log_fast           absolute < 1e-9 on [1/2, 2], relative < 1e-9 elsewhere and < 2e-8
 *                           on [0.984375, 1)
 *   dwvk_free_flight        relative < 2e-8 at every 24-bit u
 *   dwvk_azimuth_f          at every 24-bit u: the point (c, s) is at angle 2 pi u - pi/4 within
 *                           3e-7 rad, |c^2 + s^2 - 1| < 3e-7, so the azimuth is uniform
 *   dwvk_dwivedi_event_sample_f  against dwvk_dwivedi_sample_pdf_d (double, the exact forms):
 *                           the cosine to an absolute DWIVEDI_TOLERANCE; the smaller of 1 -+ mu
 *                           (`nearer`), sin theta and the stretch each to a relative
 *                           DWIVEDI_TOLERANCE (x max(1, L) for the smaller of 1 -+ mu and the
 *                           stretch: the float argument (1 - u) L carries a relative error that
 *                           the exponential multiplies by up to L), mu monotone in u.
 * A planted error (the azimuth's quarter turns in the wrong sense, an expm1 with a coefficient
 * off by 1%) shows each check can fail. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "check.h"
#include "kernel/dwivedi_sampling.h"
#include "kernel/fastmath.h"

#define EXPM1_TOLERANCE 2.4e-7
#define LOG_TOLERANCE 1e-9
#define LOG_NEAR_ONE_TOLERANCE 2e-8
#define AZIMUTH_ANGLE_TOLERANCE 3e-7
#define AZIMUTH_NORM_TOLERANCE 3e-7
#define DWIVEDI_TOLERANCE 1e-6

static const double TWO_PI = 6.283185307179586477;
static const double PI = 3.141592653589793238;

/* ---- expm1 --------------------------------------------------------------------------------- */

static double expm1_worst(float (*f)(float), float lo, float hi, int steps, double *at)
{
    double worst = 0.0;
    for (int i = 0; i <= steps; ++i) {
        float x = (float)(lo + (hi - lo) * ((double)i / steps));
        double exact = expm1((double)x);
        double error = exact == 0.0 ? fabs((double)f(x)) : fabs(((double)f(x) - exact) / exact);
        if (error > worst) worst = error, *at = x;
    }
    return worst;
}

/* The kernel with its r^2 coefficient 1% off: a plausible slip. */
static float expm1_planted(float x)
{
    const float shift = 0x1.8p23f;
    float k = (x * 1.44269504088896341f + shift) - shift;
    float r = (x - k * 0.693359375f) - k * -2.12194440e-4f;
    float p = r * (1.0f + r * (0.505f + r * (1.66666672e-1f + r * (4.16666679e-2f + r * (8.33333377e-3f +
                                                                                       r * (1.38888892e-3f + r * 1.98412701e-4f))))));
    float scale = dwvk_bits_float((uint32_t)((int32_t)k + 127) << 23);
    return scale * p + (scale - 1.0f);
}

static void test_expm1(void)
{
    double at = 0.0, worst = 0.0;
    /* Dense near 0 (where only k = 0 acts) and over the whole domain, plus the tiny arguments. */
    const float ranges[][2] = {{-1.5f, 1.5f}, {-20.0f, 20.0f}, {-80.0f, 80.0f}, {-1e-6f, 1e-6f}};
    for (size_t r = 0; r < sizeof ranges / sizeof ranges[0]; ++r) {
        double a = 0.0, w = expm1_worst(dwvk_expm1_fast_f, ranges[r][0], ranges[r][1], 2000000, &a);
        if (w > worst) worst = w, at = a;
    }
    const float tiny[] = {0x1p-126f, -0x1p-126f, 0x1p-100f, -0x1p-124f, 1e-30f};
    for (size_t i = 0; i < sizeof tiny / sizeof tiny[0]; ++i) {
        double exact = expm1((double)tiny[i]), error = fabs(((double)dwvk_expm1_fast_f(tiny[i]) - exact) / exact);
        if (error > worst) worst = error, at = tiny[i];
    }
    CHECK(dwvk_expm1_fast_f(0.0f) == 0.0f, "expm1(0) = %a", (double)dwvk_expm1_fast_f(0.0f));
    printf("expm1_fast_f: worst relative error %.3g at x = %.9g (bound %.3g)\n", worst, at, EXPM1_TOLERANCE);
    CHECK(worst < EXPM1_TOLERANCE, "expm1_fast_f: relative error %.3g at %.9g", worst, at);

    double planted = expm1_worst(expm1_planted, -20.0f, 20.0f, 200000, &at);
    printf("  planted (r^2 coefficient 0.505): %.3g, rejected\n", planted);
    CHECK(planted >= EXPM1_TOLERANCE, "the planted expm1 passes: %.3g", planted);
}

/* ---- exp (double) ------------------------------------------------------------------------- */

#define EXP_TOLERANCE 5e-16

/* |dwvk_exp_fast(x) / exp(x) - 1| with the reference in long double (64-bit significand: its own
 * error, about 1e-19, is far below the bound). */
static double exp_error(double x)
{
    long double exact = expl((long double)x);
    return (double)fabsl((long double)dwvk_exp_fast(x) / exact - 1.0L);
}

static void test_exp(void)
{
    double worst = 0.0, at = 0.0;
    for (long i = -2000000; i <= 2000000; ++i) {
        double x = 709.78 * (double)i / 2000000.0;
        if (x < -708.0) continue;
        double e = exp_error(x);
        if (e > worst) worst = e, at = x;
    }
    for (long i = -1000000; i <= 1000000; ++i) { /* dense where the walk's exponents live */
        double e = exp_error(40.0 * (double)i / 1000000.0);
        if (e > worst) worst = e, at = 40.0 * (double)i / 1000000.0;
    }
    for (long i = -100000; i <= 100000; ++i) { /* across the switch to the edge path at |x| = 708.39 */
        double x = 708.39 + 1e-6 * (double)i, e = fmax(exp_error(x), exp_error(-x));
        if (e > worst) worst = e, at = x;
    }
    printf("exp_fast: worst relative error %.3g at x = %.17g (bound %.3g)\n", worst, at, EXP_TOLERANCE);
    CHECK(worst < EXP_TOLERANCE, "exp_fast: relative error %.3g at %.17g", worst, at);
    CHECK(dwvk_exp_fast(0.0) == 1.0, "exp(0) = %a", dwvk_exp_fast(0.0));
    CHECK(dwvk_exp_fast(710.0) == INFINITY && dwvk_exp_fast(INFINITY) == INFINITY, "exp overflow");
    CHECK(dwvk_exp_fast(-746.0) == 0.0 && dwvk_exp_fast(-INFINITY) == 0.0, "exp underflow");
    CHECK(isnan(dwvk_exp_fast(NAN)), "exp(NaN) = %g", dwvk_exp_fast(NAN));
    /* Subnormal results: within an absolute 2^-1074 x a few of libm's. */
    const double tiny[] = {-710.0, -730.5, -744.0};
    for (size_t i = 0; i < sizeof tiny / sizeof tiny[0]; ++i)
        CHECK(fabs(dwvk_exp_fast(tiny[i]) - exp(tiny[i])) <= 4.0 * 0x1p-1074 + 4e-16 * exp(tiny[i]),
              "exp(%g) = %a, libm %a", tiny[i], dwvk_exp_fast(tiny[i]), exp(tiny[i]));
}

/* ---- log and the free flight --------------------------------------------------------------- */

static void test_log(void)
{
    /* Every float in [2^-24, 4) is too many; every 24-bit uniform's 1 - u covers (0, 1]
     * exhaustively below, so here a dense sweep of [2^-126, 2^127] in ratio steps. */
    double worst_abs = 0.0, worst_rel = 0.0, at_abs = 0.0, at_rel = 0.0, worst_near_one = 0.0, at_near_one = 0.0;
    for (double x = 0x1p-126; x < 0x1p127; x *= 1.0000173) {
        float xf = (float)x;
        double exact = log((double)xf), got = dwvk_log_fast(xf);
        if (xf >= 0.984375f && xf < 1.0f) {
            double e = fabs((got - exact) / exact);
            if (e > worst_near_one) worst_near_one = e, at_near_one = xf;
        }
        if (xf >= 0.5f && xf <= 2.0f) {
            double e = fabs(got - exact);
            if (e > worst_abs) worst_abs = e, at_abs = xf;
        } else {
            double e = fabs((got - exact) / exact);
            if (e > worst_rel) worst_rel = e, at_rel = xf;
        }
    }
    CHECK(fabs(dwvk_log_fast(1.0f)) < 1e-9, "log(1) = %a", dwvk_log_fast(1.0f));
    printf("log_fast: worst absolute error on [1/2, 2] %.3g at %.9g, relative elsewhere %.3g at %.9g (bound %.3g)\n",
           worst_abs, at_abs, worst_rel, at_rel, LOG_TOLERANCE);
    printf("  relative on [0.984375, 1) %.3g at %.9g (bound %.3g)\n", worst_near_one, at_near_one, LOG_NEAR_ONE_TOLERANCE);
    CHECK(worst_near_one < LOG_NEAR_ONE_TOLERANCE, "log_fast near 1: relative error %.3g at %.9g", worst_near_one,
          at_near_one);
    CHECK(worst_abs < LOG_TOLERANCE, "log_fast: absolute error %.3g at %.9g", worst_abs, at_abs);
    CHECK(worst_rel < LOG_TOLERANCE, "log_fast: relative error %.3g at %.9g", worst_rel, at_rel);

    /* The free flight at every 24-bit uniform. */
    double worst = 0.0, at = 0.0, largest = 0.0;
    for (uint32_t i = 0; i < (1u << 24); ++i) {
        float u = (float)i * 0x1.0p-24f;
        double exact = -log1p(-(double)u), got = dwvk_free_flight(u);
        double e = exact == 0.0 ? fabs(got) : fabs((got - exact) / exact);
        if (e > worst) worst = e, at = u;
        if (got > largest) largest = got;
    }
    printf("free_flight: worst relative error %.3g at u = %.9g over all 2^24 uniforms; largest flight %.6g\n",
           worst, at, largest);
    CHECK(worst < LOG_NEAR_ONE_TOLERANCE, "free_flight: relative error %.3g at u = %.9g", worst, at);
    CHECK(isfinite(largest) && largest <= 24.0 * log(2.0) * (1.0 + LOG_TOLERANCE), "largest flight %.9g", largest);
}

/* ---- azimuth ------------------------------------------------------------------------------- */

/* The distance between angles a and b on the circle. */
static double angle_gap(double a, double b)
{
    double d = fmod(fabs(a - b), TWO_PI);
    return d > PI ? TWO_PI - d : d;
}

typedef struct azimuth_errors { double angle, norm; } azimuth_errors;

static azimuth_errors azimuth_worst(int planted)
{
    azimuth_errors worst = {0.0, 0.0};
    for (uint32_t i = 0; i < (1u << 24); ++i) {
        float u = (float)i * 0x1.0p-24f;
        dwvk_unit2_f p = dwvk_azimuth_f(u);
        if (planted) { /* quarter turns the other way: (c, s) -> (s, -c) for q = 1, and so on */
            float four_u = 4.0f * u;
            if (((int32_t)four_u & 1) != 0) p.c = -p.c, p.s = -p.s;
        }
        double expected = TWO_PI * (double)u - 0.25 * PI;
        double angle = angle_gap(atan2((double)p.s, (double)p.c), expected);
        double norm = fabs((double)p.c * p.c + (double)p.s * p.s - 1.0);
        if (angle > worst.angle) worst.angle = angle;
        if (norm > worst.norm) worst.norm = norm;
    }
    return worst;
}

static void test_azimuth(void)
{
    azimuth_errors worst = azimuth_worst(0);
    printf("azimuth_f over all 2^24 uniforms: angle error %.3g rad (bound %.3g), |c^2 + s^2 - 1| %.3g (bound %.3g)\n",
           worst.angle, AZIMUTH_ANGLE_TOLERANCE, worst.norm, AZIMUTH_NORM_TOLERANCE);
    CHECK(worst.angle < AZIMUTH_ANGLE_TOLERANCE, "azimuth angle error %.3g", worst.angle);
    CHECK(worst.norm < AZIMUTH_NORM_TOLERANCE, "azimuth norm error %.3g", worst.norm);
    /* u = 1 (not drawn by the walk, but valid input) is the same point as u = 0. */
    dwvk_unit2_f zero = dwvk_azimuth_f(0.0f), one = dwvk_azimuth_f(1.0f);
    CHECK(zero.c == one.c && zero.s == one.s, "azimuth(1) = (%g, %g) is not azimuth(0) = (%g, %g)", (double)one.c,
          (double)one.s, (double)zero.c, (double)zero.s);
    azimuth_errors planted = azimuth_worst(1);
    printf("  planted (odd quarter turns reversed): angle error %.3g rad, rejected\n", planted.angle);
    CHECK(planted.angle >= AZIMUTH_ANGLE_TOLERANCE, "the planted azimuth passes: %.3g", planted.angle);
}

/* ---- the Dwivedi per-event sampler --------------------------------------------------------- */

static void test_dwivedi(void)
{
    const double albedos[] = {0.0, 1e-3, 0.05, 0.1, 0.137, 0.2, 0.3, 0.56, 0.9, 0.99, 0.999, 0.999999, 1.0 - 1e-12, 1.0};
    double worst_cos = 0.0, worst_small = 0.0, worst_sin = 0.0, worst_stretch = 0.0, at_albedo = 0.0, at_u = 0.0;
    int nonmonotone = 0;
    for (size_t a = 0; a < sizeof albedos / sizeof albedos[0]; ++a) {
        dwvk_dwivedi_d d = dwvk_dwivedi_from_kappa(dwvk_kappa_exact(albedos[a]));
        dwvk_dwivedi_event_f e = dwvk_dwivedi_event_from(d);
        double scale = d.log_ratio > 1.0 ? d.log_ratio : 1.0;
        float previous_mu = -2.0f;
        /* Every 2^6-th 24-bit uniform, plus the last ones before 1. */
        for (uint32_t i = 0; i < (1u << 24); i += (i < (1u << 24) - 64u) ? 64u : 1u) {
            float u = (float)i * 0x1.0p-24f;
            dwvk_dwivedi_event_cosine_f s = dwvk_dwivedi_event_sample_f(&e, u);
            dwvk_dwivedi_sample_d x = dwvk_dwivedi_sample_pdf_d(&d, (double)u);
            double exact_small = x.one_plus_cos < x.one_minus_cos ? x.one_plus_cos : x.one_minus_cos;
            double got_small = s.nearer;
            double e_cos = fabs((double)s.cos_theta - x.cos_theta);
            double exact_sin = sqrt(x.one_plus_cos * x.one_minus_cos);
            double e_small = exact_small == 0.0 ? fabs(got_small) : fabs(got_small - exact_small) / exact_small / scale;
            double e_sin = exact_sin == 0.0 ? fabs((double)s.sin_theta) : fabs(s.sin_theta - exact_sin) / exact_sin;
            double e_stretch = fabs(s.stretch - x.stretch) / x.stretch / scale;
            if (albedos[a] == 1.0) {
                /* The uniform limit: mu = 2u - 1, stretch 1. */
                exact_small = u <= 0.5f ? 2.0 * u : 2.0 - 2.0 * u;
                e_small = exact_small == 0.0 ? fabs(got_small) : fabs(got_small - exact_small) / exact_small;
                e_stretch = fabs(s.stretch - 1.0);
            }
            if (e_small > worst_small) worst_small = e_small, at_albedo = albedos[a], at_u = u;
            if (e_sin > worst_sin) worst_sin = e_sin;
            if (e_cos > worst_cos) worst_cos = e_cos;
            if (e_stretch > worst_stretch) worst_stretch = e_stretch;
            nonmonotone += s.cos_theta < previous_mu;
            previous_mu = s.cos_theta;
        }
    }
    printf("dwivedi_event_sample_f against the double sampler, %zu albedos: smaller of 1 -+ mu %.3g (worst at albedo "
           "%g, u %.9g), sin theta %.3g, stretch %.3g (relative, / max(1, L); bound %.3g); %d steps down in mu; cos theta absolute %.3g\n",
           sizeof albedos / sizeof albedos[0], worst_small, at_albedo, at_u, worst_sin, worst_stretch, DWIVEDI_TOLERANCE,
           nonmonotone, worst_cos);
    CHECK(worst_cos < DWIVEDI_TOLERANCE, "cos theta: absolute error %.3g", worst_cos);
    CHECK(worst_small < DWIVEDI_TOLERANCE, "1 -+ mu: relative error %.3g at albedo %g, u %.9g", worst_small, at_albedo,
          at_u);
    CHECK(worst_sin < DWIVEDI_TOLERANCE, "sin theta: relative error %.3g", worst_sin);
    CHECK(worst_stretch < DWIVEDI_TOLERANCE, "stretch: relative error %.3g", worst_stretch);
    CHECK(nonmonotone == 0, "mu is not monotone in u: %d steps down", nonmonotone);
}

int main(void)
{
    test_expm1();
    test_exp();
    test_log();
    test_azimuth();
    test_dwivedi();
    return check_report("test_fastmath");
}
