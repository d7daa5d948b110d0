/* The sheet technique's kernel (src/kernel/sheet.h), each sampler against the pdf beside it.
 *
 * On a grid of importances a (0.7104 = z_e, where the walk holds a; 1; 2.5; 10; 200) and cosines
 * mu (both ends, grazing on either side, 0 exactly, +-1e-6):
 * - the cosine sampler against dwvk_sheet_cosine_pdf: chi-square on 64 equal bins of [-1, 1]
 *   whose probabilities come from integrating the pdf (never from the sampler), for beta =
 *   dwvk_sheet_beta(a) and beta in {0, 0.75}; samples in [-1, 1]; u = 0 and u = 1 - 2^-53 give
 *   -1 and 1; the pdf integrates to 1;
 * - the flight sampler against dwvk_sheet_flight_pdf: chi-square on 64 bins equiprobable under
 *   the tail (edges by bisection on dwvk_sheet_flight_tail), their probabilities from integrating
 *   the pdf; every sample finite, >= 0, at most tau_max = a / |mu| for mu < 0, and of pdf > 0 (the
 *   walk divides by it); the inversion 1 - tail(tau(u)) = u to 1e-9 on a grid of u down to 1e-300
 *   and up to 1 - 2^-24 (the walk's largest float) and 1 - 2^-53, and around the u where
 *   y = c - u N changes sign (mu < 0 < a + mu: the sampler's start changes there); monotone in u;
 * - the tail against the integral of the pdf from tau on, relative 1e-9 (absolute 1e-15 at the
 *   few points so close to tau_max that the formula's rounding alone exceeds 1e-10 relative, see
 *   below), tail(0) = 1; the normalisation against the integral of exp(-t) (a + mu t)_+ written
 *   out here, relative 1e-12; the _scaled functions times exp(-tau) equal the others;
 * - no NaN or infinity anywhere, also at mu = 0, -0, +-1e-300, tau at and around tau_max, tau up
 *   to 1e300;
 * - near tau_max (mu < 0) the tail is a difference of terms of size a that cancel to
 *   |mu| (T - tau)^2 / 2: measured against a long double closed form in the distance to tau_max
 *   and held to absolute 1e-15 (what the inversion needs), its relative error printed.
 * Planted errors, each caught by the same check as the honest case: a cosine pdf of beta 5% off,
 * a flight pdf of a 2% off (same samples, same bins), a pdf 2% too large, a reference pdf 1e-8
 * later in the tail check, a sampled flight moved by 1e-8 in the inversion check, a normalisation
 * 1e-9 off, and near tau_max the closed form exp(delta) - 1 - delta (right to first order).
 *
 * Deterministic: counter-based random numbers (kernel/rng.h), fixed seed; no timing. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "check.h"
#include "kernel/rng.h"
#include "kernel/sheet.h"
#include "stats.h"

#define SEED 0x5eee7c0de5ull
#define BINS 64
#define SAMPLES 200000
#define TAIL_RELATIVE 1e-9
#define INVERSION_ABSOLUTE 1e-9
#define NORM_RELATIVE 1e-12
#define NEAR_MAX_ABSOLUTE 1e-15
#define REACH 80.0 /* the integrals stop here past their start: exp(-80) ~ 2e-35 of the rest */

static const double importances[] = {DWVK_SHEET_EXTRAPOLATION, 1.0, 2.5, 10.0, 200.0};
#define IMPORTANCE_COUNT ((int)(sizeof importances / sizeof importances[0]))
static const double cosines[] = {-1.0, -0.999, -0.5, -0.05, -1e-6, 0.0, 1e-6, 0.3, 1.0};
#define COSINE_COUNT ((int)(sizeof cosines / sizeof cosines[0]))
/* The walk's uniforms are floats (multiples of 2^-24 below 1); the double generator's largest is
 * 1 - 2^-53. */
static const double u_grid[] = {0.0,  1e-300, 1e-12, 1e-9,  1e-6,     1e-3,          0.1,           0.25,
                                0.5,  0.75,   0.9,   0.99,  0.999,    1.0 - 1e-6,    1.0 - 0x1p-24, 1.0 - 0x1p-40,
                                0x1.fffffffffffffp-1};
#define U_COUNT ((int)(sizeof u_grid / sizeof u_grid[0]))

static double tau_max(double a, double mu)
{
    return mu < 0.0 ? a / -mu : INFINITY;
}

/* ---- integration ------------------------------------------------------------------------------ */

typedef struct flight {
    double a, mu;
} flight;

static double flight_pdf_at(double t, void *context)
{
    const flight *f = context;
    return dwvk_sheet_flight_pdf(f->a, f->mu, t);
}

/* exp(-t) (a + mu t)_+, written out here: the normalisation's integrand. */
static double unnormalised_at(double t, void *context)
{
    const flight *f = context;
    double psi = f->a + f->mu * t;
    return psi > 0.0 ? exp(-t) * psi : 0.0;
}

/* The integral over [lo, hi] on Gauss-Legendre panels no wider than 1: a polynomial of degree 1
 * times exp(-t) is integrated to rounding on each. */
static double integrate(stats_function f, void *context, double lo, double hi)
{
    if (!(hi > lo)) return 0.0;
    int panels = (int)ceil(hi - lo);
    if (panels < 1) panels = 1;
    double width = (hi - lo) / panels, sum = 0.0;
    for (int i = 0; i < panels; ++i) {
        double b = i + 1 == panels ? hi : lo + (i + 1) * width;
        sum += stats_gl_panel(f, context, lo + i * width, b);
    }
    return sum;
}

/* Where an integral from lo over the flight's support stops: tau_max, or REACH further on. */
static double support_end(double a, double mu, double lo)
{
    return fmin(tau_max(a, mu), lo + REACH);
}

/* ---- 1. the cosine ----------------------------------------------------------------------------- */

static double cosine_pdf_at(double mu, void *context)
{
    return dwvk_sheet_cosine_pdf(*(const double *)context, mu);
}

/* Chi-square of a histogram on BINS equal bins of [-1, 1] against the bin integrals of the cosine
 * pdf of slope beta_model. */
static stats_chi_square_t cosine_chi_square(const double *observed, double beta_model)
{
    double expected[BINS];
    for (int k = 0; k < BINS; ++k) {
        double lo = -1.0 + 2.0 * k / BINS, hi = -1.0 + 2.0 * (k + 1) / BINS;
        expected[k] = SAMPLES * stats_gl_panel(cosine_pdf_at, &beta_model, lo, hi);
    }
    return stats_chi_square(observed, expected, BINS);
}

static void cosine_histogram(double beta, uint64_t stream, double *observed, int *outside)
{
    uint64_t key = dwvk_rng_key(SEED, 1u, stream);
    double edges[BINS + 1];
    for (int k = 0; k <= BINS; ++k) edges[k] = -1.0 + 2.0 * k / BINS;
    for (int k = 0; k < BINS; ++k) observed[k] = 0.0;
    *outside = 0;
    for (uint32_t i = 0; i < SAMPLES; ++i) {
        double mu = dwvk_sheet_cosine_sample(beta, dwvk_rng_uniform_d(key, i));
        int k = stats_bin(edges, BINS, mu);
        if (k < 0) ++*outside; else observed[k] += 1.0;
    }
}

static void test_cosine(void)
{
    double betas[IMPORTANCE_COUNT + 2];
    int beta_count = 0;
    betas[beta_count++] = 0.0;
    betas[beta_count++] = DWVK_SHEET_BETA_MAX;
    for (int i = 0; i < IMPORTANCE_COUNT; ++i) {
        double a = importances[i], beta = dwvk_sheet_beta(a);
        double expected = fmin(1.0 / a, DWVK_SHEET_BETA_MAX);
        CHECK(beta == expected, "dwvk_sheet_beta(%g) = %.17g, expected min(1/a, 0.75) = %.17g", a, beta, expected);
        int seen = 0;
        for (int j = 0; j < beta_count; ++j) seen |= betas[j] == beta;
        if (!seen) betas[beta_count++] = beta;
    }
    printf("cosine: chi-square, %d samples, %d equal bins, reject when p < %g:\n", SAMPLES, BINS, STATS_P_REJECT);
    double worst_norm = 0.0, worst_end = 0.0;
    int monotone = 1;
    for (int j = 0; j < beta_count; ++j) {
        double beta = betas[j], observed[BINS];
        int outside;
        cosine_histogram(beta, (uint64_t)j, observed, &outside);
        stats_chi_square_t r = cosine_chi_square(observed, beta);
        char label[96];
        snprintf(label, sizeof label, "beta = %g", beta);
        stats_print(label, r);
        CHECK(outside == 0, "cosine beta = %g: %d samples outside [-1, 1]", beta, outside);
        CHECK(r.p >= STATS_P_REJECT, "cosine beta = %g: chi2 = %.2f, dof %d, p = %.3g: sampler and pdf disagree", beta,
              r.x2, r.dof, r.p);
        /* the ends of u: -1 and 1 */
        double lo = dwvk_sheet_cosine_sample(beta, 0.0), hi = dwvk_sheet_cosine_sample(beta, 0x1.fffffffffffffp-1);
        CHECK(fabs(lo + 1.0) <= 1e-12, "cosine beta = %g, u = 0: %.17g, expected -1", beta, lo);
        CHECK(fabs(hi - 1.0) <= 1e-12, "cosine beta = %g, u = 1 - 2^-53: %.17g, expected 1", beta, hi);
        worst_end = fmax(worst_end, fmax(fabs(lo + 1.0), fabs(hi - 1.0)));
        /* monotone in u and inside [-1, 1] over the u grid */
        double previous = -INFINITY;
        for (int k = 0; k < U_COUNT; ++k) {
            double mu = dwvk_sheet_cosine_sample(beta, u_grid[k]);
            CHECK(mu >= -1.0 && mu <= 1.0, "cosine beta = %g, u = %.17g: %.17g outside [-1, 1]", beta, u_grid[k], mu);
            monotone &= mu >= previous;
            previous = mu;
        }
        /* the pdf integrates to 1 (one panel: exact for a line) */
        double integral = stats_gl_panel(cosine_pdf_at, &beta, -1.0, 1.0);
        CHECK(fabs(integral - 1.0) <= 1e-14, "cosine beta = %g: pdf integrates to %.17g", beta, integral);
        worst_norm = fmax(worst_norm, fabs(integral - 1.0));
    }
    CHECK(monotone, "the cosine sampler is not monotone in u");
    printf("  ends: |mu(0) + 1|, |mu(1 - 2^-53) - 1| <= %.3g (bound 1e-12); |int p - 1| <= %.3g (bound 1e-14); "
           "monotone in u\n",
           worst_end, worst_norm);

    /* planted: the pdf of beta 5% off, against the same samples (beta = 0.75, the strongest slope) */
    double observed[BINS];
    int outside;
    cosine_histogram(DWVK_SHEET_BETA_MAX, 1u, observed, &outside);
    stats_chi_square_t r = cosine_chi_square(observed, 1.05 * DWVK_SHEET_BETA_MAX);
    stats_print("planted: samples of beta = 0.75 against the pdf of 0.7875", r);
    CHECK(r.p < STATS_P_REJECT, "planted beta 5%% off not caught: chi2 = %.2f, dof %d, p = %.3g", r.x2, r.dof, r.p);
    double planted_beta = 0.75;
    double planted_integral = 1.02 * stats_gl_panel(cosine_pdf_at, &planted_beta, -1.0, 1.0);
    CHECK(!(fabs(planted_integral - 1.0) <= 1e-14), "planted: a pdf 2%% too large integrates to %.17g", planted_integral);
}

/* ---- 2. the flight: chi-square ----------------------------------------------------------------- */

/* Edges equiprobable under the tail: tail(edges[k]) = 1 - k / BINS, by bisection; edges[BINS] =
 * tau_max (infinite for mu >= 0). Only the bins come from the tail; their probabilities come from
 * integrating the pdf. */
static void flight_edges(double a, double mu, double *edges)
{
    edges[0] = 0.0;
    edges[BINS] = tau_max(a, mu);
    for (int k = 1; k < BINS; ++k) {
        double target = 1.0 - (double)k / BINS, lo = edges[k - 1], hi;
        if (mu < 0.0) {
            hi = edges[BINS];
        } else {
            hi = lo + 1.0;
            while (dwvk_sheet_flight_tail(a, mu, hi) > target) hi = 2.0 * hi;
        }
        for (int i = 0; i < 200; ++i) {
            double middle = 0.5 * (lo + hi);
            if (!(middle > lo && middle < hi)) break;
            if (dwvk_sheet_flight_tail(a, mu, middle) > target) lo = middle; else hi = middle;
        }
        edges[k] = 0.5 * (lo + hi);
    }
}

/* Expected counts in the bins from the pdf of (a_model, mu); the last bin runs to that pdf's own
 * end of support. */
static stats_chi_square_t flight_chi_square(const double *edges, const double *observed, double a_model, double mu)
{
    double expected[BINS];
    flight model = {a_model, mu};
    for (int k = 0; k < BINS; ++k) {
        double hi = k + 1 < BINS ? edges[k + 1] : support_end(a_model, mu, edges[k]);
        expected[k] = SAMPLES * integrate(flight_pdf_at, &model, edges[k], hi);
    }
    return stats_chi_square(observed, expected, BINS);
}

typedef struct flight_draws {
    int outside, not_finite, negative, beyond_max, zero_pdf;
} flight_draws;

static flight_draws flight_histogram(double a, double mu, uint64_t stream, const double *edges, double *observed)
{
    flight_draws d = {0, 0, 0, 0, 0};
    uint64_t key = dwvk_rng_key(SEED, 2u, stream);
    double limit = tau_max(a, mu);
    for (int k = 0; k < BINS; ++k) observed[k] = 0.0;
    for (uint32_t i = 0; i < SAMPLES; ++i) {
        double tau = dwvk_sheet_flight_sample(a, mu, dwvk_rng_uniform_d(key, i));
        d.not_finite += !isfinite(tau);
        d.negative += tau < 0.0;
        d.beyond_max += tau > limit;
        d.zero_pdf += !(dwvk_sheet_flight_pdf_scaled(a, mu, tau) > 0.0);
        int k = stats_bin(edges, BINS, tau);
        if (k < 0) ++d.outside; else observed[k] += 1.0;
    }
    return d;
}

static void test_flight_chi_square(void)
{
    printf("flight: chi-square, %d samples, %d bins equiprobable under the tail, expected counts from the pdf:\n",
           SAMPLES, BINS);
    double worst_p = 1.0, largest_x2 = 0.0;
    int cases = 0;
    for (int i = 0; i < IMPORTANCE_COUNT; ++i) {
        for (int j = 0; j < COSINE_COUNT; ++j) {
            double a = importances[i], mu = cosines[j], edges[BINS + 1], observed[BINS];
            flight_edges(a, mu, edges);
            flight_draws d = flight_histogram(a, mu, (uint64_t)(i * COSINE_COUNT + j), edges, observed);
            stats_chi_square_t r = flight_chi_square(edges, observed, a, mu);
            char label[96];
            snprintf(label, sizeof label, "a = %-6g mu = %g", a, mu);
            stats_print(label, r);
            CHECK(d.not_finite == 0 && d.negative == 0, "flight %s: %d samples not finite, %d negative", label,
                  d.not_finite, d.negative);
            CHECK(d.beyond_max == 0, "flight %s: %d samples past tau_max = a/|mu|", label, d.beyond_max);
            CHECK(d.zero_pdf == 0, "flight %s: %d samples where the pdf is 0", label, d.zero_pdf);
            CHECK(d.outside == 0, "flight %s: %d samples outside the bins", label, d.outside);
            CHECK(r.p >= STATS_P_REJECT, "flight %s: chi2 = %.2f, dof %d, p = %.3g: sampler and pdf disagree", label,
                  r.x2, r.dof, r.p);
            worst_p = fmin(worst_p, r.p);
            largest_x2 = fmax(largest_x2, r.x2);
            ++cases;
        }
    }
    printf("  %d cases: smallest p = %.3g, largest chi2 = %.2f\n", cases, worst_p, largest_x2);

    /* planted: the pdf of a 2% off, against the same samples and bins. Resolvable where the flight
     * is shortest and its support ends at tau_max: a = z_e, mu = -1. */
    const double a = DWVK_SHEET_EXTRAPOLATION, mu = -1.0;
    double edges[BINS + 1], observed[BINS];
    flight_edges(a, mu, edges);
    flight_histogram(a, mu, 0u, edges, observed);
    stats_chi_square_t r = flight_chi_square(edges, observed, 1.02 * a, mu);
    stats_print("planted: samples of a = 0.7104, mu = -1 against a = 0.7246", r);
    CHECK(r.p < STATS_P_REJECT, "planted a 2%% off not caught: chi2 = %.2f, dof %d, p = %.3g", r.x2, r.dof, r.p);
}

/* ---- 2b. the flight: inversion ------------------------------------------------------------------ */

/* The u where the cdf's right side y = c - u N (c = a + mu) crosses 0, for mu < 0 and c > 0 (the
 * flight's start and its Newton function change there; around it y is a difference of near
 * equals), with its neighbours; the count written to u (up to 5), 0 where there is no crossing. */
static int crossing_u(double a, double mu, double *u)
{
    double c = a + mu, n = dwvk_sheet_flight_norm(a, mu);
    if (!(mu < 0.0 && c > 0.0 && c < n)) return 0;
    double star = c / n;
    u[0] = star;
    u[1] = nextafter(star, 0.0);
    u[2] = nextafter(star, 1.0);
    u[3] = star - 1e-12;
    u[4] = star + 1e-12;
    return 5;
}

static double inversion_error(double a, double mu, double u, double tau_shift)
{
    double tau = dwvk_sheet_flight_sample(a, mu, u) + tau_shift;
    return fabs((1.0 - dwvk_sheet_flight_tail(a, mu, tau)) - u);
}

static void test_flight_inversion(void)
{
    double worst = 0.0, worst_u = 0.0, worst_a = 0.0, worst_mu = 0.0;
    double worst_crossing = 0.0;
    int monotone = 1, planted_caught = 0, cases = 0, crossings = 0;
    for (int i = 0; i < IMPORTANCE_COUNT; ++i) {
        for (int j = 0; j < COSINE_COUNT; ++j) {
            double a = importances[i], mu = cosines[j], previous = -INFINITY, planted_worst = 0.0;
            for (int k = 0; k < U_COUNT; ++k) {
                double u = u_grid[k], tau = dwvk_sheet_flight_sample(a, mu, u);
                double error = inversion_error(a, mu, u, 0.0);
                CHECK(error <= INVERSION_ABSOLUTE, "flight a = %g, mu = %g, u = %.17g: tau = %.17g, 1 - tail = %.17g", a,
                      mu, u, tau, 1.0 - dwvk_sheet_flight_tail(a, mu, tau));
                if (!(error <= worst)) {
                    worst = error;
                    worst_u = u;
                    worst_a = a;
                    worst_mu = mu;
                }
                monotone &= tau >= previous;
                previous = tau;
                /* planted: the answer moved by 1e-8 (the pdf is >= ~1e-2 at some u of every case) */
                planted_worst = fmax(planted_worst, inversion_error(a, mu, u, 1e-8));
            }
            planted_caught += planted_worst > INVERSION_ABSOLUTE;
            ++cases;
            double crossing[5];
            int crossing_count = crossing_u(a, mu, crossing);
            for (int k = 0; k < crossing_count; ++k) {
                double u = crossing[k], tau = dwvk_sheet_flight_sample(a, mu, u), error = inversion_error(a, mu, u, 0.0);
                CHECK(error <= INVERSION_ABSOLUTE, "flight a = %g, mu = %g, u = %.17g (y = 0 near): tau = %.17g, 1 - tail = %.17g",
                      a, mu, u, tau, 1.0 - dwvk_sheet_flight_tail(a, mu, tau));
                CHECK(isfinite(tau) && tau >= 0.0 && dwvk_sheet_flight_pdf_scaled(a, mu, tau) > 0.0,
                      "flight a = %g, mu = %g, u = %.17g (y = 0 near): tau = %.17g", a, mu, u, tau);
                worst_crossing = fmax(worst_crossing, error);
                ++crossings;
            }
        }
    }
    CHECK(monotone, "the flight sampler is not monotone in u");
    printf("flight inversion: max |1 - tail(tau(u)) - u| = %.3g (bound %g; at a = %g, mu = %g, u = %.17g) over %d "
           "cases x %d u; monotone in u; planted tau + 1e-8 caught in %d of %d cases\n",
           worst, INVERSION_ABSOLUTE, worst_a, worst_mu, worst_u, cases, U_COUNT, planted_caught, cases);
    printf("  and at %d u around the sign change of y = c - u N (mu < 0, c > 0): max |1 - tail(tau(u)) - u| = %.3g\n",
           crossings, worst_crossing);
    CHECK(planted_caught == cases, "a flight moved by 1e-8 caught in only %d of %d cases", planted_caught, cases);
}

/* ---- 3. the tail and the normalisation ---------------------------------------------------------- */

/* The relative rounding error to expect of the tail from its formula: for mu < 0 its terms, of
 * size a + |mu| (2 + tau), cancel to |mu| (delta - 1 + exp(-delta)), delta = tau_max - tau
 * (~ |mu| delta^2 / 2 near tau_max); for mu >= 0 they are all positive. */
static double cancellation(double a, double mu, double tau)
{
    if (!(mu < 0.0)) return DBL_EPSILON;
    double delta = a / -mu - tau;
    return DBL_EPSILON * (a - mu * (2.0 + tau)) / (-mu * (delta - 1.0 + exp(-delta)));
}

static void test_tail_and_norm(void)
{
    static const double taus[] = {0.0, 1e-12, 1e-6, 1e-3, 0.1, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 300.0, 700.0};
    static const double fractions[] = {0.25, 0.5, 0.75, 0.9, 0.99};
    const int tau_count = (int)(sizeof taus / sizeof taus[0]), fraction_count = (int)(sizeof fractions / sizeof fractions[0]);
    double worst_tail = 0.0, worst_norm = 0.0, worst_a = 0.0, worst_mu = 0.0, worst_tau = 0.0, worst_near = 0.0;
    int near = 0, compared = 0, planted_cases = 0, planted_caught = 0, scaled_equal = 1, tail_at_zero = 1;
    for (int i = 0; i < IMPORTANCE_COUNT; ++i) {
        for (int j = 0; j < COSINE_COUNT; ++j) {
            double a = importances[i], mu = cosines[j], limit = tau_max(a, mu);
            flight f = {a, mu};
            /* the normalisation against its integral */
            double norm = dwvk_sheet_flight_norm(a, mu);
            double integral = integrate(unnormalised_at, &f, 0.0, support_end(a, mu, 0.0));
            double norm_error = fabs(norm / integral - 1.0);
            CHECK(norm_error <= NORM_RELATIVE, "norm a = %g, mu = %g: %.17g, integral %.17g", a, mu, norm, integral);
            worst_norm = fmax(worst_norm, norm_error);
            CHECK(!(fabs(norm * (1.0 + 1e-9) / integral - 1.0) <= NORM_RELATIVE),
                  "planted: a normalisation 1e-9 off passes at a = %g, mu = %g", a, mu);
            tail_at_zero &= dwvk_sheet_flight_tail(a, mu, 0.0) == 1.0;
            /* the tail against the integral of the pdf */
            double points[32];
            int count = 0;
            for (int k = 0; k < tau_count; ++k)
                if (taus[k] < limit) points[count++] = taus[k];
            if (mu < 0.0) {
                for (int k = 0; k < fraction_count; ++k)
                    if (fractions[k] * limit <= 700.0) points[count++] = fractions[k] * limit;
                /* the far face, where the importance is z_e (the walk's exits through it) */
                double far_face = (a - DWVK_SHEET_EXTRAPOLATION) / -mu;
                if (far_face <= 700.0) points[count++] = far_face;
            }
            double planted_worst = 0.0;
            for (int k = 0; k < count; ++k) {
                double tau = points[k], tail = dwvk_sheet_flight_tail(a, mu, tau);
                double reference = integrate(flight_pdf_at, &f, tau, support_end(a, mu, tau));
                /* the scaled forms, times exp(-tau) (to a few ulps: the same product) */
                double tail_scaled = exp(-tau) * dwvk_sheet_flight_tail_scaled(a, mu, tau);
                double pdf = dwvk_sheet_flight_pdf(a, mu, tau), pdf_scaled = exp(-tau) * dwvk_sheet_flight_pdf_scaled(a, mu, tau);
                scaled_equal &= fabs(tail_scaled - tail) <= 4.0 * DBL_EPSILON * tail;
                scaled_equal &= fabs(pdf_scaled - pdf) <= 4.0 * DBL_EPSILON * pdf;
                if (cancellation(a, mu, tau) > 1e-10) {
                    /* close to tau_max: absolute, as in test_tail_near_max */
                    double absolute = fabs(tail - reference);
                    CHECK(absolute <= NEAR_MAX_ABSOLUTE, "tail a = %g, mu = %g, tau = %.17g: %.17g, integral of the pdf %.17g",
                          a, mu, tau, tail, reference);
                    worst_near = fmax(worst_near, absolute);
                    ++near;
                    continue;
                }
                double error = fabs(tail / reference - 1.0);
                CHECK(error <= TAIL_RELATIVE, "tail a = %g, mu = %g, tau = %.17g: %.17g, integral of the pdf %.17g", a, mu,
                      tau, tail, reference);
                if (!(error <= worst_tail)) {
                    worst_tail = error;
                    worst_a = a;
                    worst_mu = mu;
                    worst_tau = tau;
                }
                /* planted: the reference of a pdf 1e-8 later (hazard >= ~0.4 makes that >= ~4e-9) */
                double wrong = integrate(flight_pdf_at, &f, tau + 1e-8, support_end(a, mu, tau + 1e-8));
                planted_worst = fmax(planted_worst, fabs(tail / wrong - 1.0));
                ++compared;
            }
            ++planted_cases;
            planted_caught += planted_worst > TAIL_RELATIVE;
        }
    }
    CHECK(tail_at_zero, "tail(0) != 1 somewhere on the grid");
    CHECK(scaled_equal, "a _scaled function times exp(-tau) differs from its unscaled form");
    printf("tail: %d points, max relative difference %.3g from the integral of the pdf (bound %g; at a = %g, mu = %g, "
           "tau = %.17g); %d points close to tau_max within %.3g absolute (bound %g); tail(0) = 1; scaled x exp(-tau) "
           "= unscaled; planted: a pdf 1e-8 later caught in %d of %d cases\n",
           compared, worst_tail, TAIL_RELATIVE, worst_a, worst_mu, worst_tau, near, worst_near, NEAR_MAX_ABSOLUTE,
           planted_caught, planted_cases);
    printf("norm: max relative difference %.3g from the integral of exp(-t) (a + mu t)_+ (bound %g); planted 1e-9 "
           "off caught\n",
           worst_norm, NORM_RELATIVE);
    CHECK(planted_caught == planted_cases, "a pdf 1e-8 later caught by the tail check in only %d of %d cases",
          planted_caught, planted_cases);
}

/* Near tau_max (mu < 0) the tail's terms of size a cancel to |mu| delta^2 / 2, delta = tau_max -
 * tau: its absolute error stays at rounding (what the inversion needs), its relative error grows
 * as ~ a eps / (|mu| delta^2). The reference is the closed form in delta, in long double:
 * P(T > tau) = (1 / N) int_0^delta exp(-(tau_max - r)) |mu| r dr = |mu| exp(-tau_max) (1 + (delta - 1) exp(delta)) / N,
 * by its series sum_{n>=2} (n - 1) delta^n / n! (no cancellation). */
static void test_tail_near_max(void)
{
    static const double distances[] = {1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6};
    const int distance_count = (int)(sizeof distances / sizeof distances[0]);
    double worst_absolute = 0.0, worst_ratio = 0.0, relative_by_distance[6] = {0};
    int planted_caught = 0;
    for (int i = 0; i < IMPORTANCE_COUNT; ++i) {
        for (int j = 0; j < COSINE_COUNT; ++j) {
            double a = importances[i], mu = cosines[j];
            if (!(mu < 0.0) || a / -mu > 700.0) continue;
            long double t_max = (long double)a / -(long double)mu, m = -(long double)mu;
            long double norm = (long double)a - m + m * expl(-t_max);
            for (int k = 0; k < distance_count; ++k) {
                double tau = (double)(t_max - distances[k]);
                long double delta = t_max - tau;
                long double series = 0.0L, term = delta; /* term = delta^n / n! */
                for (int n = 2; n < 40; ++n) {
                    term *= delta / n;
                    series += (n - 1) * term;
                }
                long double reference = m * expl(-t_max) * series / norm;
                double tail = dwvk_sheet_flight_tail(a, mu, tau);
                /* planted: the integral of exp(-s) |mu| r taken as exp(-tau_max) |mu| (exp(delta) - 1 - delta),
                 * a slip that is right to first order in delta */
                long double wrong = m * expl(-t_max) * (expm1l(delta) - delta) / norm;
                planted_caught |= !(fabsl(tail - wrong) <= NEAR_MAX_ABSOLUTE);
                double absolute = (double)fabsl(tail - reference);
                CHECK(absolute <= NEAR_MAX_ABSOLUTE, "tail near tau_max, a = %g, mu = %g, tau = %.17g: %.17g, expected %.17Lg",
                      a, mu, tau, tail, reference);
                worst_absolute = fmax(worst_absolute, absolute);
                double relative = (double)fabsl(tail / reference - 1.0L);
                relative_by_distance[k] = fmax(relative_by_distance[k], relative);
                /* and the relative error is that of the cancellation, no worse */
                double expected = cancellation(a, mu, tau);
                CHECK(relative <= 4.0 * expected, "tail near tau_max, a = %g, mu = %g, tau = %.17g: relative error %.3g, "
                      "%.3g expected of rounding", a, mu, tau, relative, expected);
                worst_ratio = fmax(worst_ratio, relative / expected);
            }
        }
    }
    printf("tail near tau_max (mu < 0): max absolute error %.3g (bound %g); max relative error at tau_max - tau =", worst_absolute,
           NEAR_MAX_ABSOLUTE);
    for (int k = 0; k < distance_count; ++k) printf(" %g: %.2g,", distances[k], relative_by_distance[k]);
    printf(" at most %.2f x eps (a + |mu| (2 + tau)) / (|mu| (delta - 1 + exp(-delta))), the cancellation's; planted "
           "(exp(delta) - 1 - delta) %s\n",
           worst_ratio, planted_caught ? "caught" : "NOT caught");
    CHECK(planted_caught, "the planted closed form near tau_max passes the absolute bound");
}

/* ---- 4. no NaN or infinity ---------------------------------------------------------------------- */

static void test_finite(void)
{
    static const double extra_cosines[] = {-0.0, -1e-300, 1e-300};
    static const double taus[] = {0.0, 1e-300, 1e-12, 0.5, 1.0, 10.0, 700.0, 746.0, 1e3, 1e6, 1e300};
    double mus[COSINE_COUNT + 3];
    int mu_count = 0, evaluated = 0, bad = 0;
    for (int j = 0; j < COSINE_COUNT; ++j) mus[mu_count++] = cosines[j];
    for (int j = 0; j < 3; ++j) mus[mu_count++] = extra_cosines[j];
    for (int i = 0; i < IMPORTANCE_COUNT; ++i) {
        for (int j = 0; j < mu_count; ++j) {
            double a = importances[i], mu = mus[j], limit = tau_max(a, mu);
            double points[16];
            int count = 0;
            for (int k = 0; k < (int)(sizeof taus / sizeof taus[0]); ++k) points[count++] = taus[k];
            if (isfinite(limit)) {
                points[count++] = limit;
                points[count++] = nextafter(limit, 0.0);
                points[count++] = nextafter(limit, INFINITY);
            }
            double norm = dwvk_sheet_flight_norm(a, mu);
            ++evaluated;
            if (!(isfinite(norm) && norm > 0.0)) {
                ++bad;
                fprintf(stderr, "  norm(a = %g, mu = %g) = %.17g\n", a, mu, norm);
            }
            for (int k = 0; k < count; ++k) {
                double tau = points[k];
                double values[4] = {dwvk_sheet_flight_pdf(a, mu, tau), dwvk_sheet_flight_pdf_scaled(a, mu, tau),
                                    dwvk_sheet_flight_tail(a, mu, tau), dwvk_sheet_flight_tail_scaled(a, mu, tau)};
                for (int v = 0; v < 4; ++v) {
                    ++evaluated;
                    if (!(isfinite(values[v]) && values[v] >= 0.0)) {
                        ++bad;
                        fprintf(stderr, "  a = %g, mu = %g, tau = %.17g: function %d gives %.17g\n", a, mu, tau, v, values[v]);
                    }
                }
                ++evaluated;
                if (!(values[2] <= 1.0)) {
                    ++bad;
                    fprintf(stderr, "  a = %g, mu = %g, tau = %.17g: tail %.17g > 1\n", a, mu, tau, values[2]);
                }
            }
            for (int k = 0; k < U_COUNT; ++k) {
                double tau = dwvk_sheet_flight_sample(a, mu, u_grid[k]);
                ++evaluated;
                if (!(isfinite(tau) && tau >= 0.0 && tau <= limit && dwvk_sheet_flight_pdf_scaled(a, mu, tau) > 0.0)) {
                    ++bad;
                    fprintf(stderr, "  a = %g, mu = %g, u = %.17g: flight %.17g (pdf %.17g)\n", a, mu, u_grid[k], tau,
                            dwvk_sheet_flight_pdf_scaled(a, mu, tau));
                }
            }
        }
    }
    static const double betas[] = {0.0, 0.005, 0.1, 0.4, DWVK_SHEET_BETA_MAX};
    for (int j = 0; j < 5; ++j) {
        for (int k = 0; k < U_COUNT; ++k) {
            double mu = dwvk_sheet_cosine_sample(betas[j], u_grid[k]), pdf = dwvk_sheet_cosine_pdf(betas[j], mu);
            ++evaluated;
            if (!(mu >= -1.0 && mu <= 1.0 && isfinite(pdf) && pdf > 0.0)) {
                ++bad;
                fprintf(stderr, "  beta = %g, u = %.17g: cosine %.17g, pdf %.17g\n", betas[j], u_grid[k], mu, pdf);
            }
        }
    }
    printf("finite: %d values (a x mu with 0, -0, +-1e-300 x tau to 1e300 and at tau_max x u), %d not finite, "
           "negative or out of range\n",
           evaluated, bad);
    CHECK(bad == 0, "%d values not finite, negative or out of range", bad);
}

int main(void)
{
    test_cosine();
    test_flight_chi_square();
    test_flight_inversion();
    test_tail_and_norm();
    test_tail_near_max();
    test_finite();
    return check_report("test_sheet_kernel");
}
