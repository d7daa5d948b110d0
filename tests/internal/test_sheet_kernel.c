/* The sheet technique's kernel (src/kernel/sheet.h), each sampler against the pdf beside it.
 *
 * The importance along a flight is psi(tau) = max(a + mu tau, f), a the linear importance at its
 * start (of any sign: below the entry's height it falls under z_e) and f the floor, FLOOR here
 * (written out, and checked against DWVK_SHEET_FLOOR). On a grid of linear importances a (-3 and
 * 0.1, below the floor; 0.2, just above it; 0.7104 = z_e, the entry's; 1; 2.5; 10; 200) and cosines
 * mu (both ends, grazing on either side, 0 exactly, +-1e-6):
 * - the cosine's slopes (dwvk_sheet_slopes) against the chords of N(a, mu) on either side of 0
 *   (the upward one held at 1 / z_e), N from integrating exp(-t) max(a + mu t, f), to 1e-12;
 * - the cosine sampler against dwvk_sheet_cosine_pdf: chi-square on 64 equal bins of [-1, 1]
 *   whose probabilities come from integrating the pdf (never from the sampler), for the slopes of
 *   every a and (up, down) in {(0, 0), (0.75, 0.75), (5.6, 0), (0, 0.95)}; samples in [-1, 1];
 *   u = 0 and u = 1 - 2^-53 give
 *   -1 and 1; the pdf integrates to 1;
 * - the flight sampler against dwvk_sheet_flight_pdf: chi-square on 64 bins equiprobable under
 *   the tail (edges by bisection on dwvk_sheet_flight_tail), their probabilities from integrating
 *   the pdf (the integrals split where psi changes form, t0 = (f - a) / mu); every sample finite,
 *   >= 0 and of pdf > 0 (the walk divides by it); the inversion 1 - tail(tau(u)) = u to 1e-9 on a
 *   grid of u down to 1e-300 and up to 1 - 2^-24 (the walk's largest float) and 1 - 2^-53, around
 *   the u where y = c - u N changes sign (mu < 0 < a + mu: the sampler's start changes there) and
 *   around the u of t0 (the sampler's piece changes there); monotone in u;
 * - the tail against the integral of the pdf from tau on, relative 1e-9, at and around t0 too,
 *   tail(0) = 1; the normalisation against the integral of exp(-t) max(a + mu t, f) written out
 *   here, relative 1e-12; the _scaled functions times exp(-tau) equal the others;
 * - the floor's bound: the scaled pdf is at least f / N at every tau (so the weight's ratio to
 *   the exponential flight is bounded wherever a walk lands: docs/speed.md, the bent sheet), and
 *   the tail is continuous at t0 (its two forms meet);
 * - no NaN or infinity anywhere, also at mu = 0, -0, +-1e-300, tau at and around t0, tau up to
 *   1e300.
 * Planted errors, each caught by the same check as the honest case: a cosine pdf of slopes 10% off,
 * a flight pdf of a 5% off (same samples, same bins), a pdf 2% too large, a reference pdf 1e-8
 * later in the tail check, a sampled flight moved by 1e-8 in the inversion check, a normalisation
 * 1e-9 off, and the floor's bound against a flight without a floor ((a + mu tau)_+).
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
#define FLOOR (0.25 * 0.7104) /* the floor of the importance: a quarter of z_e */
#define REACH 80.0 /* the integrals stop here past their start: exp(-80) ~ 2e-35 of the rest */

static const double importances[] = {-3.0, 0.1, 0.2, DWVK_SHEET_EXTRAPOLATION, 1.0, 2.5, 10.0, 200.0};
#define IMPORTANCE_COUNT ((int)(sizeof importances / sizeof importances[0]))
static const double cosines[] = {-1.0, -0.999, -0.5, -0.05, -1e-6, 0.0, 1e-6, 0.3, 1.0};
#define COSINE_COUNT ((int)(sizeof cosines / sizeof cosines[0]))
/* The walk's uniforms are floats (multiples of 2^-24 below 1); the double generator's largest is
 * 1 - 2^-53. */
static const double u_grid[] = {0.0,  1e-300, 1e-12, 1e-9,  1e-6,     1e-3,          0.1,           0.25,
                                0.5,  0.75,   0.9,   0.99,  0.999,    1.0 - 1e-6,    1.0 - 0x1p-24, 1.0 - 0x1p-40,
                                0x1.fffffffffffffp-1};
#define U_COUNT ((int)(sizeof u_grid / sizeof u_grid[0]))

/* Where psi changes form along the flight, t0 = (f - a) / mu, where that is after 0; else
 * infinity (one form all the way). */
static double switch_point(double a, double mu)
{
    double t0 = mu != 0.0 ? (FLOOR - a) / mu : INFINITY;
    return t0 > 0.0 ? t0 : INFINITY;
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

/* exp(-t) max(a + mu t, f), written out here: the normalisation's integrand. */
static double unnormalised_at(double t, void *context)
{
    const flight *f = context;
    return exp(-t) * fmax(f->a + f->mu * t, FLOOR);
}

/* The same without the floor, exp(-t) (a + mu t)_+: the planted flight of the floor's check. */
static double unfloored_at(double t, void *context)
{
    const flight *f = context;
    double psi = f->a + f->mu * t;
    return psi > 0.0 ? exp(-t) * psi : 0.0;
}

/* The integral over [lo, hi] on Gauss-Legendre panels no wider than 1: a polynomial of degree 1
 * times exp(-t) is integrated to rounding on each. */
static double integrate_smooth(stats_function f, void *context, double lo, double hi)
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

/* The integral of a flight's function over [lo, hi], in pieces either side of its switch point
 * (where psi has a kink, which a panel would not integrate exactly). */
static double integrate(stats_function f, void *context, double lo, double hi)
{
    const flight *g = context;
    double t0 = switch_point(g->a, g->mu);
    if (!(t0 > lo && t0 < hi)) return integrate_smooth(f, context, lo, hi);
    return integrate_smooth(f, context, lo, t0) + integrate_smooth(f, context, t0, hi);
}

/* Where an integral from lo over the flight's support stops: REACH further on. */
static double support_end(double lo)
{
    return lo + REACH;
}

static double integrated_norm(double a, double mu)
{
    flight f = {a, mu};
    return integrate(unnormalised_at, &f, 0.0, support_end(0.0));
}

/* ---- 1. the cosine ----------------------------------------------------------------------------- */

typedef struct slopes {
    double up, down;
} slopes;

static double cosine_pdf_at(double mu, void *context)
{
    const slopes *k = context;
    return dwvk_sheet_cosine_pdf(k->up, k->down, mu);
}

/* Chi-square of a histogram on BINS equal bins of [-1, 1] (0 is an edge: the pdf's kink) against
 * the bin integrals of the cosine pdf of slopes `model`. */
static stats_chi_square_t cosine_chi_square(const double *observed, slopes model)
{
    double expected[BINS];
    for (int k = 0; k < BINS; ++k) {
        double lo = -1.0 + 2.0 * k / BINS, hi = -1.0 + 2.0 * (k + 1) / BINS;
        expected[k] = SAMPLES * stats_gl_panel(cosine_pdf_at, &model, lo, hi);
    }
    return stats_chi_square(observed, expected, BINS);
}

static void cosine_histogram(slopes k, uint64_t stream, double *observed, int *outside)
{
    uint64_t key = dwvk_rng_key(SEED, 1u, stream);
    double edges[BINS + 1];
    for (int b = 0; b <= BINS; ++b) edges[b] = -1.0 + 2.0 * b / BINS;
    for (int b = 0; b < BINS; ++b) observed[b] = 0.0;
    *outside = 0;
    for (uint32_t i = 0; i < SAMPLES; ++i) {
        double mu = dwvk_sheet_cosine_sample(k.up, k.down, dwvk_rng_uniform_d(key, i));
        int b = stats_bin(edges, BINS, mu);
        if (b < 0) ++*outside; else observed[b] += 1.0;
    }
}

/* N(a, mu) by integration (the normalisation's integrand written out here). */
static double integrated_norm(double a, double mu);

static void test_cosine(void)
{
    slopes cases[IMPORTANCE_COUNT + 4];
    int count = 0;
    cases[count++] = (slopes){0.0, 0.0};
    cases[count++] = (slopes){0.75, 0.75};
    cases[count++] = (slopes){5.6, 0.0};
    cases[count++] = (slopes){0.0, 0.95};
    double worst_slope = 0.0;
    for (int i = 0; i < IMPORTANCE_COUNT; ++i) {
        double a = importances[i], up, down;
        dwvk_sheet_slopes(a, &up, &down);
        /* the chords of N(a, mu) on either side of 0, from the integrals */
        double n0 = integrated_norm(a, 0.0);
        double expected_up = fmin(integrated_norm(a, 1.0) / n0 - 1.0, 1.0 / 0.7104);
        double expected_down = 1.0 - integrated_norm(a, -1.0) / n0;
        double error = fmax(fabs(up - expected_up), fabs(down - expected_down));
        CHECK(error <= 1e-12, "dwvk_sheet_slopes(%g) = %.17g, %.17g; the chords of N: %.17g, %.17g", a, up, down,
              expected_up, expected_down);
        CHECK(down < 1.0 && up >= 0.0 && down >= 0.0, "slopes(%g) = %g, %g: the pdf is not > 0 on [-1, 1]", a, up, down);
        worst_slope = fmax(worst_slope, error);
        cases[count++] = (slopes){up, down};
    }
    printf("cosine: slopes = the chords of N(a, mu) on either side of 0 (up <= 1 / z_e) within %.3g (bound 1e-12); chi-square, %d "
           "samples, %d equal bins, reject when p < %g:\n",
           worst_slope, SAMPLES, BINS, STATS_P_REJECT);
    double worst_norm = 0.0, worst_end = 0.0;
    int monotone = 1;
    for (int j = 0; j < count; ++j) {
        slopes k = cases[j];
        double observed[BINS];
        int outside;
        cosine_histogram(k, (uint64_t)j, observed, &outside);
        stats_chi_square_t r = cosine_chi_square(observed, k);
        char label[96];
        snprintf(label, sizeof label, "up = %.4g, down = %.4g", k.up, k.down);
        stats_print(label, r);
        CHECK(outside == 0, "cosine %s: %d samples outside [-1, 1]", label, outside);
        CHECK(r.p >= STATS_P_REJECT, "cosine %s: chi2 = %.2f, dof %d, p = %.3g: sampler and pdf disagree", label, r.x2,
              r.dof, r.p);
        /* the ends of u: -1 and 1 */
        double lo = dwvk_sheet_cosine_sample(k.up, k.down, 0.0), hi = dwvk_sheet_cosine_sample(k.up, k.down, 0x1.fffffffffffffp-1);
        CHECK(fabs(lo + 1.0) <= 1e-12, "cosine %s, u = 0: %.17g, expected -1", label, lo);
        CHECK(fabs(hi - 1.0) <= 1e-12, "cosine %s, u = 1 - 2^-53: %.17g, expected 1", label, hi);
        worst_end = fmax(worst_end, fmax(fabs(lo + 1.0), fabs(hi - 1.0)));
        /* monotone in u and inside [-1, 1] over the u grid */
        double previous = -INFINITY;
        for (int b = 0; b < U_COUNT; ++b) {
            double mu = dwvk_sheet_cosine_sample(k.up, k.down, u_grid[b]);
            CHECK(mu >= -1.0 && mu <= 1.0, "cosine %s, u = %.17g: %.17g outside [-1, 1]", label, u_grid[b], mu);
            monotone &= mu >= previous;
            previous = mu;
        }
        /* the pdf integrates to 1 (one panel per side: exact for a line) */
        double integral = stats_gl_panel(cosine_pdf_at, &k, -1.0, 0.0) + stats_gl_panel(cosine_pdf_at, &k, 0.0, 1.0);
        CHECK(fabs(integral - 1.0) <= 1e-14, "cosine %s: pdf integrates to %.17g", label, integral);
        worst_norm = fmax(worst_norm, fabs(integral - 1.0));
    }
    CHECK(monotone, "the cosine sampler is not monotone in u");
    printf("  ends: |mu(0) + 1|, |mu(1 - 2^-53) - 1| <= %.3g (bound 1e-12); |int p - 1| <= %.3g (bound 1e-14); "
           "monotone in u\n",
           worst_end, worst_norm);

    /* planted: the pdf of both slopes 10% off, against the same samples (the entry's slopes) */
    double observed[BINS];
    int outside;
    slopes entry;
    dwvk_sheet_slopes(DWVK_SHEET_EXTRAPOLATION, &entry.up, &entry.down);
    cosine_histogram(entry, 1u, observed, &outside);
    slopes wrong = {1.10 * entry.up, 1.10 * entry.down};
    stats_chi_square_t r = cosine_chi_square(observed, wrong);
    stats_print("planted: samples of the entry's slopes against both 10% larger", r);
    CHECK(r.p < STATS_P_REJECT, "planted slopes 10%% off not caught: chi2 = %.2f, dof %d, p = %.3g", r.x2, r.dof, r.p);
    double planted_integral = 1.02 * (stats_gl_panel(cosine_pdf_at, &entry, -1.0, 0.0) + stats_gl_panel(cosine_pdf_at, &entry, 0.0, 1.0));
    CHECK(!(fabs(planted_integral - 1.0) <= 1e-14), "planted: a pdf 2%% too large integrates to %.17g", planted_integral);
}

/* ---- 2. the flight: chi-square ----------------------------------------------------------------- */

/* Edges equiprobable under the tail: tail(edges[k]) = 1 - k / BINS, by bisection; edges[BINS] =
 * infinity. Only the bins come from the tail; their probabilities come from integrating the pdf. */
static void flight_edges(double a, double mu, double *edges)
{
    edges[0] = 0.0;
    edges[BINS] = INFINITY;
    for (int k = 1; k < BINS; ++k) {
        double target = 1.0 - (double)k / BINS, lo = edges[k - 1], hi = lo + 1.0;
        while (dwvk_sheet_flight_tail(a, mu, hi) > target) hi = 2.0 * hi;
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
        double hi = k + 1 < BINS ? edges[k + 1] : support_end(edges[k]);
        expected[k] = SAMPLES * integrate(flight_pdf_at, &model, edges[k], hi);
    }
    return stats_chi_square(observed, expected, BINS);
}

typedef struct flight_draws {
    int outside, not_finite, negative, zero_pdf;
} flight_draws;

static flight_draws flight_histogram(double a, double mu, uint64_t stream, const double *edges, double *observed)
{
    flight_draws d = {0, 0, 0, 0};
    uint64_t key = dwvk_rng_key(SEED, 2u, stream);
    for (int k = 0; k < BINS; ++k) observed[k] = 0.0;
    for (uint32_t i = 0; i < SAMPLES; ++i) {
        double tau = dwvk_sheet_flight_sample(a, mu, dwvk_rng_uniform_d(key, i));
        d.not_finite += !isfinite(tau);
        d.negative += tau < 0.0;
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

    /* planted: the pdf of a 5% off, against the same samples and bins. Resolvable where the flight
     * is shortest: a = z_e, mu = -1 (2% was, before the floor took the flight's end). */
    const double a = DWVK_SHEET_EXTRAPOLATION, mu = -1.0;
    double edges[BINS + 1], observed[BINS];
    flight_edges(a, mu, edges);
    flight_histogram(a, mu, 0u, edges, observed);
    stats_chi_square_t r = flight_chi_square(edges, observed, 1.05 * a, mu);
    stats_print("planted: samples of a = 0.7104, mu = -1 against a = 0.7459", r);
    CHECK(r.p < STATS_P_REJECT, "planted a 5%% off not caught: chi2 = %.2f, dof %d, p = %.3g", r.x2, r.dof, r.p);
}

/* ---- 2b. the flight: inversion ------------------------------------------------------------------ */

/* The u where the cdf's right side y = c - u N (c = a + mu) crosses 0, for mu < 0 and c > 0 (the
 * flight's start and its Newton function change there; around it y is a difference of near
 * equals), and the u of the switch point t0, 1 - tail(t0) (the sampler's piece changes there),
 * each with its neighbours; the count written to u (up to 10). */
static int crossing_u(double a, double mu, double *u)
{
    double c = a + mu, n = dwvk_sheet_flight_norm(a, mu), stars[2];
    int star_count = 0, count = 0;
    if (mu < 0.0 && c > 0.0 && c < n) stars[star_count++] = c / n;
    double t0 = switch_point(a, mu);
    if (t0 < INFINITY) stars[star_count++] = 1.0 - dwvk_sheet_flight_tail(a, mu, t0);
    for (int k = 0; k < star_count; ++k) {
        double star = stars[k];
        if (!(star > 2e-12 && star < 1.0 - 2e-12)) continue;
        u[count++] = star;
        u[count++] = nextafter(star, 0.0);
        u[count++] = nextafter(star, 1.0);
        u[count++] = star - 1e-12;
        u[count++] = star + 1e-12;
    }
    return count;
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
            double crossing[10];
            int crossing_count = crossing_u(a, mu, crossing);
            for (int k = 0; k < crossing_count; ++k) {
                double u = crossing[k], tau = dwvk_sheet_flight_sample(a, mu, u), error = inversion_error(a, mu, u, 0.0);
                CHECK(error <= INVERSION_ABSOLUTE, "flight a = %g, mu = %g, u = %.17g (y = 0 or t0 near): tau = %.17g, 1 - tail = %.17g",
                      a, mu, u, tau, 1.0 - dwvk_sheet_flight_tail(a, mu, tau));
                CHECK(isfinite(tau) && tau >= 0.0 && dwvk_sheet_flight_pdf_scaled(a, mu, tau) > 0.0,
                      "flight a = %g, mu = %g, u = %.17g (y = 0 or t0 near): tau = %.17g", a, mu, u, tau);
                worst_crossing = fmax(worst_crossing, error);
                ++crossings;
            }
        }
    }
    CHECK(monotone, "the flight sampler is not monotone in u");
    printf("flight inversion: max |1 - tail(tau(u)) - u| = %.3g (bound %g; at a = %g, mu = %g, u = %.17g) over %d "
           "cases x %d u; monotone in u; planted tau + 1e-8 caught in %d of %d cases\n",
           worst, INVERSION_ABSOLUTE, worst_a, worst_mu, worst_u, cases, U_COUNT, planted_caught, cases);
    printf("  and at %d u around the sign change of y = c - u N (mu < 0, c > 0) and around t0: max |1 - tail(tau(u)) - u| = %.3g\n",
           crossings, worst_crossing);
    CHECK(planted_caught == cases, "a flight moved by 1e-8 caught in only %d of %d cases", planted_caught, cases);
}

/* ---- 3. the tail and the normalisation ---------------------------------------------------------- */

static void test_tail_and_norm(void)
{
    static const double taus[] = {0.0, 1e-12, 1e-6, 1e-3, 0.1, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 300.0, 700.0};
    static const double fractions[] = {0.25, 0.5, 0.75, 0.9, 0.99, 1.0, 1.01, 1.5};
    const int tau_count = (int)(sizeof taus / sizeof taus[0]), fraction_count = (int)(sizeof fractions / sizeof fractions[0]);
    double worst_tail = 0.0, worst_norm = 0.0, worst_a = 0.0, worst_mu = 0.0, worst_tau = 0.0;
    int compared = 0, planted_cases = 0, planted_caught = 0, scaled_equal = 1, tail_at_zero = 1;
    CHECK(DWVK_SHEET_FLOOR == FLOOR, "DWVK_SHEET_FLOOR = %.17g, the test's floor %.17g", (double)DWVK_SHEET_FLOOR, FLOOR);
    for (int i = 0; i < IMPORTANCE_COUNT; ++i) {
        for (int j = 0; j < COSINE_COUNT; ++j) {
            double a = importances[i], mu = cosines[j], t0 = switch_point(a, mu);
            flight f = {a, mu};
            /* the normalisation against its integral */
            double norm = dwvk_sheet_flight_norm(a, mu);
            double integral = integrate(unnormalised_at, &f, 0.0, support_end(0.0));
            double norm_error = fabs(norm / integral - 1.0);
            CHECK(norm_error <= NORM_RELATIVE, "norm a = %g, mu = %g: %.17g, integral %.17g", a, mu, norm, integral);
            worst_norm = fmax(worst_norm, norm_error);
            CHECK(!(fabs(norm * (1.0 + 1e-9) / integral - 1.0) <= NORM_RELATIVE),
                  "planted: a normalisation 1e-9 off passes at a = %g, mu = %g", a, mu);
            tail_at_zero &= dwvk_sheet_flight_tail(a, mu, 0.0) == 1.0;
            /* the tail against the integral of the pdf: on the grid, and about the switch point */
            double points[40];
            int count = 0;
            for (int k = 0; k < tau_count; ++k) points[count++] = taus[k];
            if (t0 < INFINITY) {
                for (int k = 0; k < fraction_count; ++k)
                    if (fractions[k] * t0 <= 700.0) points[count++] = fractions[k] * t0;
                if (t0 <= 700.0) {
                    points[count++] = nextafter(t0, 0.0);
                    points[count++] = nextafter(t0, INFINITY);
                }
            }
            double planted_worst = 0.0;
            for (int k = 0; k < count; ++k) {
                double tau = points[k], tail = dwvk_sheet_flight_tail(a, mu, tau);
                double reference = integrate(flight_pdf_at, &f, tau, support_end(tau));
                /* the scaled forms, times exp(-tau) (to a few ulps: the same product) */
                double tail_scaled = exp(-tau) * dwvk_sheet_flight_tail_scaled(a, mu, tau);
                double pdf = dwvk_sheet_flight_pdf(a, mu, tau), pdf_scaled = exp(-tau) * dwvk_sheet_flight_pdf_scaled(a, mu, tau);
                scaled_equal &= fabs(tail_scaled - tail) <= 4.0 * DBL_EPSILON * tail;
                scaled_equal &= fabs(pdf_scaled - pdf) <= 4.0 * DBL_EPSILON * pdf;
                if (!(reference > 1e-290)) continue; /* both underflow */
                double error = fabs(tail / reference - 1.0);
                CHECK(error <= TAIL_RELATIVE, "tail a = %g, mu = %g, tau = %.17g: %.17g, integral of the pdf %.17g", a, mu,
                      tau, tail, reference);
                if (!(error <= worst_tail)) {
                    worst_tail = error;
                    worst_a = a;
                    worst_mu = mu;
                    worst_tau = tau;
                }
                /* planted: the reference of a pdf 1e-8 later (hazard >= ~0.2 makes that >= ~2e-9) */
                double wrong = integrate(flight_pdf_at, &f, tau + 1e-8, support_end(tau + 1e-8));
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
           "tau = %.17g); tail(0) = 1; scaled x exp(-tau) = unscaled; planted: a pdf 1e-8 later caught in %d of %d "
           "cases\n",
           compared, worst_tail, TAIL_RELATIVE, worst_a, worst_mu, worst_tau, planted_caught, planted_cases);
    printf("norm: max relative difference %.3g from the integral of exp(-t) max(a + mu t, f) (bound %g); planted "
           "1e-9 off caught\n",
           worst_norm, NORM_RELATIVE);
    CHECK(planted_caught == planted_cases, "a pdf 1e-8 later caught by the tail check in only %d of %d cases",
          planted_caught, planted_cases);
}

/* The floor's bound: the flight's pdf is at least f / N times the exponential flight's, at every
 * tau (what bounds a walk's weight wherever it lands), and the tail's two forms meet at t0.
 * Planted: the flight without a floor, (a + mu tau)_+ normalised by its own integral, fails the
 * bound (it vanishes past a / |mu|). */
static void test_floor(void)
{
    static const double taus[] = {0.0, 0.01, 0.1, 0.5, 1.0, 2.0, 4.0, 8.0, 30.0, 200.0};
    double worst_ratio = INFINITY, worst_jump = 0.0;
    int planted_caught = 0, planted_cases = 0;
    for (int i = 0; i < IMPORTANCE_COUNT; ++i) {
        for (int j = 0; j < COSINE_COUNT; ++j) {
            double a = importances[i], mu = cosines[j], t0 = switch_point(a, mu);
            double norm = dwvk_sheet_flight_norm(a, mu), bound = FLOOR / norm;
            flight f = {a, mu};
            double unfloored_norm = integrate(unfloored_at, &f, 0.0, support_end(0.0)), planted_worst = INFINITY;
            for (int k = 0; k < (int)(sizeof taus / sizeof taus[0]); ++k) {
                double tau = taus[k] + (t0 < INFINITY ? t0 : 0.0) * (k % 2);
                double scaled = dwvk_sheet_flight_pdf_scaled(a, mu, tau);
                CHECK(scaled >= bound * (1.0 - 1e-15), "floor: a = %g, mu = %g, tau = %g: scaled pdf %.17g < f / N = %.17g", a,
                      mu, tau, scaled, bound);
                worst_ratio = fmin(worst_ratio, scaled / bound);
                if (unfloored_norm > 0.0)
                    planted_worst = fmin(planted_worst, unfloored_at(tau, &f) * exp(tau) / unfloored_norm / bound);
            }
            if (mu < 0.0 && a > 0.0 && a / -mu < 100.0) {
                ++planted_cases;
                planted_caught += planted_worst < 1.0 - 1e-15;
            }
            if (t0 < 700.0) {
                double below = dwvk_sheet_tail_integral(a, mu, nextafter(t0, 0.0));
                double above = dwvk_sheet_tail_integral(a, mu, t0);
                double jump = fabs(below / above - 1.0);
                CHECK(jump <= 1e-12, "floor: a = %g, mu = %g: the tail's forms at t0 = %.17g differ: %.17g, %.17g", a, mu, t0,
                      below, above);
                worst_jump = fmax(worst_jump, jump);
            }
        }
    }
    printf("floor: scaled pdf >= f / N everywhere (smallest ratio %.6g); the tail's forms meet at t0 within %.3g "
           "(bound 1e-12); planted: no floor caught in %d of %d cases (mu < 0 < a)\n",
           worst_ratio, worst_jump, planted_caught, planted_cases);
    CHECK(planted_cases > 0 && planted_caught == planted_cases, "the flight without a floor passes the bound in %d of %d cases",
          planted_cases - planted_caught, planted_cases);
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
            double a = importances[i], mu = mus[j], limit = switch_point(a, mu);
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
                if (!(isfinite(tau) && tau >= 0.0 && dwvk_sheet_flight_pdf_scaled(a, mu, tau) > 0.0)) {
                    ++bad;
                    fprintf(stderr, "  a = %g, mu = %g, u = %.17g: flight %.17g (pdf %.17g)\n", a, mu, u_grid[k], tau,
                            dwvk_sheet_flight_pdf_scaled(a, mu, tau));
                }
            }
        }
    }
    static const double ups[] = {0.0, 0.005, 0.1, 1.4, 1e3}, downs[] = {0.0, 0.005, 0.4, 0.999};
    for (int j = 0; j < 5; ++j) {
        for (int d = 0; d < 4; ++d) {
            for (int k = 0; k < U_COUNT; ++k) {
                double mu = dwvk_sheet_cosine_sample(ups[j], downs[d], u_grid[k]);
                double pdf = dwvk_sheet_cosine_pdf(ups[j], downs[d], mu);
                ++evaluated;
                if (!(mu >= -1.0 && mu <= 1.0 && isfinite(pdf) && pdf > 0.0)) {
                    ++bad;
                    fprintf(stderr, "  up = %g, down = %g, u = %.17g: cosine %.17g, pdf %.17g\n", ups[j], downs[d],
                            u_grid[k], mu, pdf);
                }
            }
        }
    }
    printf("finite: %d values (a x mu with 0, -0, +-1e-300 x tau to 1e300 and at t0 x u), %d not finite, "
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
    test_floor();
    test_finite();
    return check_report("test_sheet_kernel");
}
