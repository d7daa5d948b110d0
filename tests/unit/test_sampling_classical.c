/* Henyey-Greenstein, isotropic and exponential samplers against their pdfs, double and float,
 * through capi only: chi-square of sampled histograms against bin probabilities integrated from
 * the pdf functions (exponential: also against the closed-form CDF 1 - exp(-sigma t)), the pdfs'
 * normalisation by quadrature, the sample means (HG: g; exponential: 1/sigma) within 5 standard
 * errors, and planted errors (g + 0.02, sigma * 1.02) that the same checks must catch.
 *
 * Public API only. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include <dwivedi.h>
#include "stats.h"

#define SEED 0xc1a55ec5ull
#define BINS 100
#define SAMPLES 400000
#define TWO_PI 6.283185307179586477

/* A sample mean is accepted within this many standard errors of its expected value. */
#define MEAN_SIGMAS 5.0

static const double hg_gs[] = {-0.9, -0.3, 0.0, 1e-4, 0.3, 0.9, 0.99};
#define HG_G_COUNT ((int)(sizeof hg_gs / sizeof hg_gs[0]))
static const double sigmas[] = {1e-3, 1.0, 1e3};

enum precision { DOUBLE, FLOAT };

static const char *precision_name(enum precision precision)
{
    return precision == DOUBLE ? "double" : "float";
}

/* ---- Henyey-Greenstein and isotropic -------------------------------------------------------- */

/* The phase functions in one variable: s = 1 - mu for g >= 0 and 1 + mu for g < 0, so that the
 * forward (backward) peak sits at s = 0 where the quadrature's geometric panels resolve it. */
typedef struct phase {
    int isotropic;
    double g;   /* the g the sampler sees (for float, the float g widened) */
    double side; /* +1: s = 1 - mu; -1: s = 1 + mu */
} phase;

static phase make_phase(int isotropic, double g)
{
    phase p = {isotropic, g, g >= 0.0 ? 1.0 : -1.0};
    return p;
}

/* The cosine density 2 pi p(mu) at s, from the library's double pdf. */
static double phase_density(double s, void *context)
{
    const phase *p = context;
    double mu = p->side * (1.0 - s), pdf = NAN;
    dwv_result_t result = p->isotropic ? dwv_isotropic_pdf(&pdf) : dwv_hg_pdf(p->g, mu, &pdf);
    return result == DWV_SUCCESS ? TWO_PI * pdf : NAN;
}

static double phase_density_times_mu(double s, void *context)
{
    const phase *p = context;
    return p->side * (1.0 - s) * phase_density(s, context);
}

/* Edges in s equiprobable under the textbook HG inverse CDF
 * mu = (1 + g^2 - ((1 - g^2) / (1 - g + 2 g u))^2) / (2 g) (isotropic and g = 0: 2u - 1). The bins
 * only need to be roughly equiprobable; their probabilities come from integrating the pdf. */
static void phase_edges(const phase *p, double *edges)
{
    edges[0] = 0.0;
    for (int k = 1; k < BINS; ++k) {
        double u = (double)k / BINS, g = p->g, mu;
        if (p->isotropic || g == 0.0) {
            mu = 2.0 * u - 1.0;
        } else {
            double q = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
            mu = (1.0 + g * g - q * q) / (2.0 * g);
        }
        /* s increases with u for g >= 0 (s = 1 - mu), with 1 - u for g < 0 (s = 1 + mu). */
        if (p->side > 0.0) edges[BINS - k] = 1.0 - mu; else edges[k] = 1.0 + mu;
    }
    edges[BINS] = 2.0;
}

typedef struct moments { double sum, sum_squares; int failures, outside; } moments;

/* Draws SAMPLES cosines from the sampler of `sampled` (HG of its g, or isotropic) in one
 * precision and bins s against the edges of `binning`. */
static moments draw_phase(const phase *sampled, enum precision precision, uint64_t stream, const double *edges,
                          double *observed)
{
    moments m = {0.0, 0.0, 0, 0};
    for (int k = 0; k < BINS; ++k) observed[k] = 0.0;
    for (int i = 0; i < SAMPLES; ++i) {
        double mu = NAN;
        if (precision == DOUBLE) {
            double u;
            m.failures += dwv_random_uniform(SEED, stream, (uint64_t)i, 0, &u) != DWV_SUCCESS;
            m.failures += (sampled->isotropic ? dwv_isotropic_sample(u, &mu) : dwv_hg_sample(sampled->g, u, &mu)) !=
                          DWV_SUCCESS;
        } else {
            float u, mu_f = NAN;
            m.failures += dwv_random_uniform_f(SEED, stream, (uint64_t)i, 0, &u) != DWV_SUCCESS;
            m.failures += dwv_hg_sample_f((float)sampled->g, u, &mu_f) != DWV_SUCCESS;
            mu = (double)mu_f;
        }
        m.sum += mu;
        m.sum_squares += mu * mu;
        int k = stats_bin(edges, BINS, 1.0 - sampled->side * mu);
        if (k < 0) ++m.outside; else observed[k] += 1.0;
    }
    return m;
}

static void expected_counts(const phase *model, const double *edges, double *expected)
{
    for (int k = 0; k < BINS; ++k)
        expected[k] = SAMPLES * stats_integrate_from_zero(phase_density, (void *)model, edges[k], edges[k + 1]);
}

/* |mean - expected| in standard errors of the mean. */
static double mean_deviation(moments m, double expected_mean)
{
    double mean = m.sum / SAMPLES;
    double variance = m.sum_squares / SAMPLES - mean * mean;
    return fabs(mean - expected_mean) / sqrt(variance / SAMPLES);
}

static void test_phase_chi_square(void)
{
    printf("phase functions, %d samples, %d bins, reject when p < %g or the mean cosine is off by > %g sigma:\n",
           SAMPLES, BINS, STATS_P_REJECT, MEAN_SIGMAS);
    double edges[BINS + 1], observed[BINS], expected[BINS];
    char label[128];
    uint64_t stream = 0;
    for (int precision = DOUBLE; precision <= FLOAT; ++precision) {
        for (int i = -1; i < HG_G_COUNT; ++i) {
            int isotropic = i < 0;
            if (isotropic && precision == FLOAT) continue; /* no float isotropic sampler */
            double g = isotropic ? 0.0 : precision == FLOAT ? (double)(float)hg_gs[i] : hg_gs[i];
            phase p = make_phase(isotropic, g);
            phase_edges(&p, edges);
            expected_counts(&p, edges, expected);
            moments m = draw_phase(&p, (enum precision)precision, stream++, edges, observed);
            stats_chi_square_t r = stats_chi_square(observed, expected, BINS);
            double deviation = mean_deviation(m, g);
            if (isotropic) snprintf(label, sizeof label, "%s isotropic", precision_name(precision));
            else snprintf(label, sizeof label, "%s HG g=%g", precision_name(precision), hg_gs[i]);
            stats_print(label, r);
            printf("  %-58s mean cos = %.6f, %.2f standard errors from g\n", "", m.sum / SAMPLES, deviation);
            CHECK(m.failures == 0 && m.outside == 0, "%s: %d failed calls, %d cosines outside [-1, 1]", label,
                  m.failures, m.outside);
            CHECK(r.p >= STATS_P_REJECT, "%s: chi2 = %.2f, dof %d, p = %.3g: sampler and pdf disagree", label, r.x2,
                  r.dof, r.p);
            CHECK(deviation <= MEAN_SIGMAS, "%s: mean cosine %.8f is %.2f standard errors from g = %.8f", label,
                  m.sum / SAMPLES, deviation, g);
        }
    }
}

/* Planted: samples of g, expected counts and mean of g + 0.02. */
static void test_phase_catches_wrong_g(void)
{
    printf("planted: HG samples of g against the pdf and mean of g + 0.02 (each must be rejected):\n");
    const double gs[] = {-0.3, 0.3, 0.9};
    double edges[BINS + 1], observed[BINS], expected[BINS];
    char label[128];
    uint64_t stream = 1000;
    for (int precision = DOUBLE; precision <= FLOAT; ++precision) {
        for (int i = 0; i < 3; ++i) {
            phase sampled = make_phase(0, precision == FLOAT ? (double)(float)gs[i] : gs[i]);
            phase wrong = make_phase(0, sampled.g + 0.02);
            wrong.side = sampled.side; /* bins and expected counts in the same variable s */
            phase_edges(&sampled, edges);
            expected_counts(&wrong, edges, expected);
            moments m = draw_phase(&sampled, (enum precision)precision, stream++, edges, observed);
            stats_chi_square_t r = stats_chi_square(observed, expected, BINS);
            double deviation = mean_deviation(m, wrong.g);
            snprintf(label, sizeof label, "%s HG g=%g against g + 0.02", precision_name(precision), gs[i]);
            stats_print(label, r);
            printf("  %-58s mean cos %.2f standard errors from g + 0.02\n", "", deviation);
            CHECK(m.failures == 0 && m.outside == 0, "%s: %d failed calls, %d outside", label, m.failures, m.outside);
            CHECK(r.p < STATS_P_REJECT, "%s: planted error not caught by chi-square: chi2 = %.2f, p = %.3g", label,
                  r.x2, r.p);
            CHECK(deviation > MEAN_SIGMAS, "%s: planted error not caught by the mean: %.2f sigma", label, deviation);
        }
    }
}

/* Normalisation int 2 pi p dmu = 1 and mean cosine int mu 2 pi p dmu = g, by quadrature (double),
 * to 1e-9; at |g| = 0.999999 to 1e-6 only: there the mass sits within ~1e-12 of mu = +-1, where
 * the double cosine the pdf takes is spaced 1.1e-16, so the pdf cannot be sampled at the
 * quadrature's nodes to better than ~1e-4 relative near the peak (measured: 4.5e-8 overall).
 * Also the float pdf against the double one at float cosines. */
static void test_phase_quadrature(void)
{
    double worst_norm = 0.0, worst_mean = 0.0, worst_extreme = 0.0, worst_float = 0.0;
    const double extra_gs[] = {-0.999999, 0.999999};
    for (int i = -1; i < HG_G_COUNT + 2; ++i) {
        int isotropic = i < 0;
        double g = isotropic ? 0.0 : i < HG_G_COUNT ? hg_gs[i] : extra_gs[i - HG_G_COUNT];
        phase p = make_phase(isotropic, g);
        double norm = stats_integrate_from_zero(phase_density, &p, 0.0, 2.0);
        double mean = stats_integrate_from_zero(phase_density_times_mu, &p, 0.0, 2.0);
        double bound = fabs(g) <= 0.99 ? 1e-9 : 1e-6;
        if (fabs(g) <= 0.99) {
            worst_norm = fmax(worst_norm, fabs(norm - 1.0));
            worst_mean = fmax(worst_mean, fabs(mean - g));
        } else {
            worst_extreme = fmax(worst_extreme, fmax(fabs(norm - 1.0), fabs(mean - g)));
        }
        CHECK(fabs(norm - 1.0) <= bound, "%s g = %g: int 2 pi p dmu = %.17g", isotropic ? "isotropic" : "HG", g, norm);
        CHECK(fabs(mean - g) <= bound, "%s g = %g: int mu 2 pi p dmu = %.17g", isotropic ? "isotropic" : "HG", g,
              mean);
        if (isotropic) continue;
        float g_f = (float)g;
        int bad = 0;
        for (int j = 0; j <= 4096; ++j) {
            float mu = j < 4032 ? (float)(-1.0 + 2.0 * j / 4031.0) : (float)p.side * (1.0f - (float)(4096 - j) * 0x1p-24f);
            float pdf_f = NAN;
            double pdf = NAN;
            bad += dwv_hg_pdf_f(g_f, mu, &pdf_f) != DWV_SUCCESS;
            bad += dwv_hg_pdf((double)g_f, (double)mu, &pdf) != DWV_SUCCESS;
            double error = fabs(pdf_f / pdf - 1.0);
            worst_float = fmax(worst_float, error);
            bad += !(error <= 1e-5);
        }
        CHECK(bad == 0, "HG g = %g: %d float pdf values off the double pdf by > 1e-5", g, bad);
    }
    printf("phase quadrature: max |norm - 1| = %.3g, max |mean cos - g| = %.3g (bounds 1e-9); at |g| = 0.999999 "
           "%.3g (bound 1e-6); float pdf vs double %.3g (bound 1e-5)\n",
           worst_norm, worst_mean, worst_extreme, worst_float);
    /* Planted: the pdf of g + 0.02 still integrates to 1 but its mean cosine is g + 0.02. */
    phase wrong = make_phase(0, 0.32);
    double mean = stats_integrate_from_zero(phase_density_times_mu, &wrong, 0.0, 2.0);
    printf("  planted: the mean cosine of the pdf of g + 0.02 against g = 0.3: %.12f (must be rejected)\n", mean);
    CHECK(fabs(mean - 0.3) > 1e-9, "planted g error not caught by the mean cosine quadrature: %.17g", mean);
}

/* ---- exponential free flights --------------------------------------------------------------- */

typedef struct exponential { double sigma; } exponential;

static double exponential_density(double t, void *context)
{
    const exponential *e = context;
    double pdf = NAN;
    return dwv_exponential_pdf(e->sigma, t, &pdf) == DWV_SUCCESS ? pdf : NAN;
}

/* Equiprobable bins of the closed form: t_k = -log(1 - k/K) / sigma, the last one open. */
static void exponential_edges(double sigma, double *edges)
{
    for (int k = 0; k < BINS; ++k) edges[k] = -log1p(-(double)k / BINS) / sigma;
    edges[BINS] = INFINITY;
}

/* Distances of SAMPLES draws at `sigma`, binned; returns their moments. */
static moments draw_exponential(double sigma, enum precision precision, uint64_t stream, const double *edges,
                                double *observed)
{
    moments m = {0.0, 0.0, 0, 0};
    for (int k = 0; k < BINS; ++k) observed[k] = 0.0;
    for (int i = 0; i < SAMPLES; ++i) {
        double t = NAN;
        if (precision == DOUBLE) {
            double u;
            m.failures += dwv_random_uniform(SEED, stream, (uint64_t)i, 0, &u) != DWV_SUCCESS;
            m.failures += dwv_exponential_sample(sigma, u, &t) != DWV_SUCCESS;
        } else {
            float u, t_f = NAN;
            m.failures += dwv_random_uniform_f(SEED, stream, (uint64_t)i, 0, &u) != DWV_SUCCESS;
            m.failures += dwv_exponential_sample_f((float)sigma, u, &t_f) != DWV_SUCCESS;
            t = (double)t_f;
        }
        m.sum += t;
        m.sum_squares += t * t;
        int k = isfinite(t) ? stats_bin(edges, BINS, t) : -1;
        if (k < 0) ++m.outside; else observed[k] += 1.0;
    }
    return m;
}

static void test_exponential(void)
{
    printf("exponential, %d samples, %d bins equiprobable under 1 - exp(-sigma t):\n", SAMPLES, BINS);
    double edges[BINS + 1], observed[BINS], expected[BINS];
    char label[128];
    uint64_t stream = 2000;
    double worst_bin = 0.0;
    for (int precision = DOUBLE; precision <= FLOAT; ++precision) {
        for (int i = 0; i < 3; ++i) {
            /* float: the sampler sees (float)sigma; all expectations use that value. */
            double sigma = precision == FLOAT ? (double)(float)sigmas[i] : sigmas[i];
            exponential e = {sigma};
            exponential_edges(sigma, edges);
            for (int k = 0; k < BINS; ++k) {
                expected[k] = (double)SAMPLES / BINS;
                /* The pdf integrated over each finite bin must give the closed form's 1/K (the last
                 * bin to 60/sigma, where exp(-60) ~ 1e-26 is left out). */
                if (precision == DOUBLE) {
                    double hi = k + 1 < BINS ? edges[k + 1] : 60.0 / sigma;
                    double probability = stats_integrate_from_zero(exponential_density, &e, edges[k], hi);
                    worst_bin = fmax(worst_bin, fabs(probability * BINS - 1.0));
                }
            }
            moments m = draw_exponential(sigma, (enum precision)precision, stream++, edges, observed);
            stats_chi_square_t r = stats_chi_square(observed, expected, BINS);
            double deviation = fabs(m.sum / SAMPLES - 1.0 / sigma) / (1.0 / (sigma * sqrt((double)SAMPLES)));
            snprintf(label, sizeof label, "%s exponential sigma=%g", precision_name(precision), sigmas[i]);
            stats_print(label, r);
            printf("  %-58s mean = %.6g, %.2f standard errors from 1/sigma\n", "", m.sum / SAMPLES, deviation);
            CHECK(m.failures == 0 && m.outside == 0, "%s: %d failed calls, %d non-finite or negative", label,
                  m.failures, m.outside);
            CHECK(r.p >= STATS_P_REJECT, "%s: chi2 = %.2f, dof %d, p = %.3g: sampler and CDF disagree", label, r.x2,
                  r.dof, r.p);
            CHECK(deviation <= MEAN_SIGMAS, "%s: mean %.8g is %.2f standard errors from 1/sigma", label,
                  m.sum / SAMPLES, deviation);
        }
    }
    printf("exponential pdf integrated over the closed form's bins: max |K p_k - 1| = %.3g (bound 1e-9)\n", worst_bin);
    CHECK(worst_bin <= 1e-9, "exponential pdf does not integrate to the closed-form bin probabilities: %.3g",
          worst_bin);

    /* Planted: samples of sigma against bins, expected counts and mean of sigma * 1.02. */
    printf("planted: exponential samples of sigma against sigma * 1.02 (each must be rejected):\n");
    for (int precision = DOUBLE; precision <= FLOAT; ++precision) {
        double sigma = 1.0, wrong = 1.02;
        exponential_edges(wrong, edges);
        for (int k = 0; k < BINS; ++k) expected[k] = (double)SAMPLES / BINS;
        moments m = draw_exponential(sigma, (enum precision)precision, stream++, edges, observed);
        stats_chi_square_t r = stats_chi_square(observed, expected, BINS);
        double deviation = fabs(m.sum / SAMPLES - 1.0 / wrong) / (1.0 / (wrong * sqrt((double)SAMPLES)));
        snprintf(label, sizeof label, "%s exponential sigma=1 against 1.02", precision_name(precision));
        stats_print(label, r);
        printf("  %-58s mean %.2f standard errors from 1/1.02\n", "", deviation);
        CHECK(r.p < STATS_P_REJECT, "%s: planted error not caught by chi-square: chi2 = %.2f, p = %.3g", label, r.x2,
              r.p);
        CHECK(deviation > MEAN_SIGMAS, "%s: planted error not caught by the mean: %.2f sigma", label, deviation);
    }
}

int main(void)
{
    test_phase_chi_square();
    test_phase_catches_wrong_g();
    test_phase_quadrature();
    test_exponential();
    return check_report("test_sampling_classical");
}
