/* No NaN, no infinity, every output in its documented range, for the sampling entry points at
 * the ends of their domains: albedos from 0 to 1 by every v0 method (including the clamp region
 * and both sides of Case's switch at 0.56), u at 0, 1e-300, 1/2, 1 - 2^-53 and 1 (float: the same
 * cast, so 1e-300 -> 0 and 1 - 2^-53 -> 1.0f), Henyey-Greenstein with |g| up to the largest below
 * 1, exponential flights with sigma from 1e-6 to 1e6. Ranges from capi/dwivedi.h: cos in [-1, 1],
 * 1 -+ cos in [0, 2], pdf > 0 and finite, stretch in (0, 2], distance >= 0 and finite.
 * Public API only, and no libm (the unit tests' link line has none). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "check.h"
#include <dwivedi.h>

static const double albedos[] = {0.0, 1e-300, 1e-12, 1e-3, 0.5599999999, 0.56, 0.9999, 1.0 - 1e-12, 1.0};
#define ALBEDO_COUNT ((int)(sizeof albedos / sizeof albedos[0]))
static const dwv_v0_method_t methods[] = {DWV_V0_EXACT, DWV_V0_CASE, DWV_V0_DEON, DWV_V0_FAST};
static const double us[] = {0.0, 1e-300, 0.5, 1.0 - 0x1p-53, 1.0};
#define U_COUNT ((int)(sizeof us / sizeof us[0]))
static const double mus[] = {-1.0, -0.5, 0.0, 0.5, 1.0 - 1e-7, 1.0};
#define MU_COUNT ((int)(sizeof mus / sizeof mus[0]))

static int in(double x, double lo, double hi)
{
    return x >= lo && x <= hi; /* false for NaN */
}

static int positive_finite(double x)
{
    return x > 0.0 && isfinite(x);
}

static int stretch_ok(double x)
{
    return x > 0.0 && x <= 2.0;
}

/* ---- Dwivedi --------------------------------------------------------------------------------- */

static void check_dwivedi_double(const dwv_dwivedi_t *dist, const char *name)
{
    for (int i = 0; i < U_COUNT; ++i) {
        double u = us[i], cos_only = NAN;
        dwv_dwivedi_sample_t s = DWV_DWIVEDI_SAMPLE_INIT;
        int ok = dwv_dwivedi_sample_pdf(dist, u, &s) == DWV_SUCCESS &&
                 dwv_dwivedi_sample(dist, u, &cos_only) == DWV_SUCCESS;
        CHECK(ok && in(s.cos_theta, -1.0, 1.0) && in(s.one_minus_cos, 0.0, 2.0) && in(s.one_plus_cos, 0.0, 2.0) &&
                  positive_finite(s.pdf) && stretch_ok(s.stretch) && cos_only == s.cos_theta,
              "double %s u=%a: ok %d cos %.17g 1-cos %.17g 1+cos %.17g pdf %.17g stretch %.17g sample() %.17g", name,
              u, ok, s.cos_theta, s.one_minus_cos, s.one_plus_cos, s.pdf, s.stretch, cos_only);
        /* The inverse CDF's ends are exact: mu(0) = v - (v + 1) = -1 and mu(1) = 1. */
        if (u == 0.0)
            CHECK(s.cos_theta == -1.0 && s.one_plus_cos == 0.0, "double %s u=0: cos %.17g, 1+cos %.17g", name,
                  s.cos_theta, s.one_plus_cos);
        if (u == 1.0)
            CHECK(s.cos_theta == 1.0 && s.one_minus_cos == 0.0, "double %s u=1: cos %.17g, 1-cos %.17g", name,
                  s.cos_theta, s.one_minus_cos);
    }
    for (int i = 0; i < MU_COUNT; ++i) {
        double pdf = NAN, stretch = NAN;
        int ok = dwv_dwivedi_pdf(dist, mus[i], &pdf) == DWV_SUCCESS &&
                 dwv_dwivedi_stretch(dist, mus[i], &stretch) == DWV_SUCCESS;
        CHECK(ok && positive_finite(pdf) && stretch_ok(stretch), "double %s mu=%.17g: ok %d pdf %.17g stretch %.17g",
              name, mus[i], ok, pdf, stretch);
    }
}

static void check_dwivedi_float(const dwv_dwivedi_t *dist, const char *name)
{
    for (int i = 0; i < U_COUNT; ++i) {
        float u = (float)us[i], cos_only = NAN;
        dwv_dwivedi_sample_f_t s = DWV_DWIVEDI_SAMPLE_F_INIT;
        int ok = dwv_dwivedi_sample_pdf_f(dist, u, &s) == DWV_SUCCESS &&
                 dwv_dwivedi_sample_f(dist, u, &cos_only) == DWV_SUCCESS;
        CHECK(ok && in(s.cos_theta, -1.0, 1.0) && in(s.one_minus_cos, 0.0, 2.0) && in(s.one_plus_cos, 0.0, 2.0) &&
                  positive_finite(s.pdf) && stretch_ok(s.stretch) && cos_only == s.cos_theta,
              "float %s u=%a: ok %d cos %.9g 1-cos %.9g 1+cos %.9g pdf %.9g stretch %.9g sample_f() %.9g", name,
              (double)u, ok, (double)s.cos_theta, (double)s.one_minus_cos, (double)s.one_plus_cos, (double)s.pdf,
              (double)s.stretch, (double)cos_only);
        if (u == 0.0f)
            CHECK(s.cos_theta == -1.0f && s.one_plus_cos == 0.0f, "float %s u=0: cos %.9g, 1+cos %.9g", name,
                  (double)s.cos_theta, (double)s.one_plus_cos);
        if (u == 1.0f)
            CHECK(s.cos_theta == 1.0f && s.one_minus_cos == 0.0f, "float %s u=1: cos %.9g, 1-cos %.9g", name,
                  (double)s.cos_theta, (double)s.one_minus_cos);
    }
    for (int i = 0; i < MU_COUNT; ++i) {
        float mu = (float)mus[i], pdf = NAN, stretch = NAN;
        int ok = dwv_dwivedi_pdf_f(dist, mu, &pdf) == DWV_SUCCESS &&
                 dwv_dwivedi_stretch_f(dist, mu, &stretch) == DWV_SUCCESS;
        CHECK(ok && positive_finite(pdf) && stretch_ok(stretch), "float %s mu=%.9g: ok %d pdf %.9g stretch %.9g", name,
              (double)mu, ok, (double)pdf, (double)stretch);
    }
}

static void test_dwivedi(void)
{
    char name[64];
    for (int m = 0; m < 4; ++m) {
        for (int i = 0; i < ALBEDO_COUNT; ++i) {
            snprintf(name, sizeof name, "alpha=%.17g %s", albedos[i], dwv_v0_method_name(methods[m]));
            dwv_dwivedi_t dist = DWV_DWIVEDI_INIT;
            dwv_result_t result = dwv_dwivedi_init(&dist, albedos[i], methods[m]);
            CHECK(result == DWV_SUCCESS, "%s: init %d: %s", name, (int)result, dwv_last_error_message());
            /* The struct's documented ranges: kappa in [0, 1), 1 - kappa in (0, 1], L in [0, 14.6],
             * albedo_eff in (0.13, 1], and the float copies finite. */
            CHECK(in(dist.kappa, 0.0, 1.0) && dist.kappa < 1.0 && dist.one_minus_kappa > 0.0 &&
                      dist.one_minus_kappa <= 1.0 && in(dist.log_ratio, 0.0, 14.6) && dist.albedo_eff > 0.13 &&
                      dist.albedo_eff <= 1.0 && isfinite(dist.kappa_f) && isfinite(dist.one_minus_kappa_f) &&
                      isfinite(dist.log_ratio_f) && isfinite(dist.albedo_eff_f),
                  "%s: kappa %.17g 1-kappa %.17g L %.17g a %.17g (float %.9g %.9g %.9g %.9g)", name, dist.kappa,
                  dist.one_minus_kappa, dist.log_ratio, dist.albedo_eff, (double)dist.kappa_f,
                  (double)dist.one_minus_kappa_f, (double)dist.log_ratio_f, (double)dist.albedo_eff_f);
            check_dwivedi_double(&dist, name);
            check_dwivedi_float(&dist, name);
        }
    }
}

/* ---- Henyey-Greenstein and isotropic ---------------------------------------------------------- */

static void test_phase(void)
{
    const double gs[] = {-(1.0 - 0x1p-53), -0.999999, -0.5, -1e-300, 0.0, 1e-300, 1e-4, 0.999999, 1.0 - 0x1p-53};
    const float gs_f[] = {-(1.0f - 0x1p-24f), -0.999999f, -0.5f, -1e-38f, 0.0f, 1e-38f, 1e-4f, 0.999999f,
                          1.0f - 0x1p-24f};
    for (int j = 0; j < (int)(sizeof gs / sizeof gs[0]); ++j) {
        double g = gs[j];
        float g_f = gs_f[j];
        for (int i = 0; i < U_COUNT; ++i) {
            double cos_theta = NAN, pdf = NAN, cos_pair = NAN, pdf_pair = NAN;
            int ok = dwv_hg_sample(g, us[i], &cos_theta) == DWV_SUCCESS &&
                     dwv_hg_pdf(g, cos_theta, &pdf) == DWV_SUCCESS &&
                     dwv_hg_sample_pdf(g, us[i], &cos_pair, &pdf_pair) == DWV_SUCCESS;
            CHECK(ok && in(cos_theta, -1.0, 1.0) && positive_finite(pdf) && cos_pair == cos_theta && pdf_pair == pdf,
                  "HG g=%a u=%a: ok %d cos %.17g pdf %.17g (sample_pdf %.17g %.17g)", g, us[i], ok, cos_theta, pdf,
                  cos_pair, pdf_pair);
            float u_f = (float)us[i], cos_f = NAN, pdf_f = NAN;
            ok = dwv_hg_sample_f(g_f, u_f, &cos_f) == DWV_SUCCESS && dwv_hg_pdf_f(g_f, cos_f, &pdf_f) == DWV_SUCCESS;
            CHECK(ok && in(cos_f, -1.0, 1.0) && positive_finite(pdf_f), "HG float g=%a u=%a: ok %d cos %.9g pdf %.9g",
                  (double)g_f, (double)u_f, ok, (double)cos_f, (double)pdf_f);
        }
        for (int i = 0; i < MU_COUNT; ++i) {
            double pdf = NAN;
            float pdf_f = NAN;
            int ok = dwv_hg_pdf(g, mus[i], &pdf) == DWV_SUCCESS;
            CHECK(ok && positive_finite(pdf), "HG g=%a mu=%.17g: ok %d pdf %.17g", g, mus[i], ok, pdf);
            ok = dwv_hg_pdf_f(g_f, (float)mus[i], &pdf_f) == DWV_SUCCESS;
            CHECK(ok && positive_finite(pdf_f), "HG float g=%a mu=%.9g: ok %d pdf %.9g", (double)g_f,
                  (double)(float)mus[i], ok, (double)pdf_f);
        }
    }
    for (int i = 0; i < U_COUNT; ++i) {
        double cos_theta = NAN, pdf = NAN;
        int ok = dwv_isotropic_sample(us[i], &cos_theta) == DWV_SUCCESS && dwv_isotropic_pdf(&pdf) == DWV_SUCCESS;
        CHECK(ok && in(cos_theta, -1.0, 1.0) && positive_finite(pdf), "isotropic u=%a: ok %d cos %.17g pdf %.17g",
              us[i], ok, cos_theta, pdf);
    }
}

/* ---- exponential ------------------------------------------------------------------------------ */

static void test_exponential(void)
{
    const double sigmas[] = {1e-6, 1e-3, 1.0, 1e3, 1e6};
    for (int j = 0; j < 5; ++j) {
        double sigma = sigmas[j];
        float sigma_f = (float)sigma;
        for (int i = 0; i < U_COUNT; ++i) {
            /* u = 1 is taken as the largest number below 1: the distance stays finite, ~37/sigma
             * (double) or ~17/sigma (float), and its pdf positive. */
            double t = NAN, pdf = NAN;
            int ok = dwv_exponential_sample(sigma, us[i], &t) == DWV_SUCCESS &&
                     dwv_exponential_pdf(sigma, t, &pdf) == DWV_SUCCESS;
            CHECK(ok && t >= 0.0 && isfinite(t) && positive_finite(pdf),
                  "exponential sigma=%g u=%a: ok %d t %.17g pdf %.17g", sigma, us[i], ok, t, pdf);
            float u_f = (float)us[i], t_f = NAN, pdf_f = NAN;
            ok = dwv_exponential_sample_f(sigma_f, u_f, &t_f) == DWV_SUCCESS &&
                 dwv_exponential_pdf_f(sigma_f, t_f, &pdf_f) == DWV_SUCCESS;
            CHECK(ok && t_f >= 0.0f && isfinite(t_f) && positive_finite(pdf_f),
                  "exponential float sigma=%g u=%a: ok %d t %.9g pdf %.9g", (double)sigma_f, (double)u_f, ok,
                  (double)t_f, (double)pdf_f);
        }
    }
}

int main(void)
{
    test_dwivedi();
    test_phase();
    test_exponential();
    return check_report("test_sampling_robustness");
}
