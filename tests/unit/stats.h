/* Statistics shared by the sampling tests: the chi-square p-value (regularised upper incomplete
 * gamma function), Gauss-Legendre quadrature on geometric panels, histograms and a binned
 * chi-square test. Independent of the library: nothing here calls dwivedi. Needs libm. */
#ifndef DWV_TESTS_STATS_H
#define DWV_TESTS_STATS_H

#include <math.h>
#include <stdio.h>

/* A sampler is rejected when its chi-square p-value is below this. Seeds are fixed, so a run is
 * reproducible; the threshold keeps the chance that a correct sampler fails on some other seed
 * below ~1e-4 over all the chi-square tests of the suite. */
#define STATS_P_REJECT 1e-6

/* Adjacent bins are merged until each expects at least this many samples (the chi-square
 * approximation of the statistic's distribution needs it; Cochran's rule asks for 5). */
#define STATS_MIN_EXPECTED 20.0

/* Q(a, x) = Gamma(a, x) / Gamma(a), by the series of P = 1 - Q for x < a + 1 (Abramowitz and
 * Stegun 6.5.29) and by the continued fraction of Q otherwise (A&S 6.5.31, modified Lentz), so
 * that small tail probabilities keep their relative accuracy. */
static inline double stats_gamma_q(double a, double x)
{
    if (!(x > 0.0)) return 1.0;
    double log_prefactor = a * log(x) - x - lgamma(a);
    if (x < a + 1.0) {
        double term = 1.0 / a, sum = term;
        for (int n = 1; n < 100000 && term > 1e-17 * sum; ++n) {
            term *= x / (a + n);
            sum += term;
        }
        return 1.0 - sum * exp(log_prefactor);
    }
    const double tiny = 1e-300;
    double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
    for (int i = 1; i < 100000; ++i) {
        double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (fabs(d) < tiny) d = tiny;
        c = b + an / c;
        if (fabs(c) < tiny) c = tiny;
        d = 1.0 / d;
        double delta = d * c;
        h *= delta;
        if (fabs(delta - 1.0) < 1e-16) break;
    }
    return exp(log_prefactor) * h;
}

/* P(chi^2_dof >= x2). */
static inline double stats_chi_square_p(double x2, int dof)
{
    return stats_gamma_q(0.5 * dof, 0.5 * x2);
}

/* ---- Gauss-Legendre quadrature -------------------------------------------------------------- */

#define STATS_GL_POINTS 20

typedef struct stats_gl_rule {
    double node[STATS_GL_POINTS], weight[STATS_GL_POINTS];
} stats_gl_rule;

/* The 20-point rule on [-1, 1], by Newton's method on the Legendre recurrence, computed once. */
static inline const stats_gl_rule *stats_gl(void)
{
    static stats_gl_rule rule;
    static int ready;
    if (ready) return &rule;
    const int n = STATS_GL_POINTS;
    const double pi = 3.14159265358979323846;
    for (int i = 0; i < n; ++i) {
        double x = cos(pi * (i + 0.75) / (n + 0.5)), derivative = 1.0;
        for (int iteration = 0; iteration < 100; ++iteration) {
            double p0 = 1.0, p1 = x;
            for (int k = 2; k <= n; ++k) {
                double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            derivative = n * (x * p1 - p0) / (x * x - 1.0);
            double step = p1 / derivative;
            x -= step;
            if (fabs(step) < 1e-16) break;
        }
        rule.node[i] = x;
        rule.weight[i] = 2.0 / ((1.0 - x * x) * derivative * derivative);
    }
    ready = 1;
    return &rule;
}

typedef double (*stats_function)(double t, void *context);

/* The integral of f over [a, b] by one Gauss-Legendre panel. */
static inline double stats_gl_panel(stats_function f, void *context, double a, double b)
{
    const stats_gl_rule *rule = stats_gl();
    double half = 0.5 * (b - a), middle = 0.5 * (a + b), sum = 0.0;
    for (int i = 0; i < STATS_GL_POINTS; ++i) sum += rule->weight[i] * f(middle + half * rule->node[i], context);
    return half * sum;
}

/* The integral of f over [lo, hi], 0 <= lo < hi, on panels [2^(e-1), 2^e] (one panel below
 * 2^-80): every panel spans a factor 2 in t, so a feature of any width w at t = 0 (a peak like
 * 1 / (w + t), or exp(-t / w)) is resolved without knowing w. A function analytic in the
 * half-plane Re t > -w/3 (say) gets relative accuracy ~ 1e-15 per panel. */
static inline double stats_integrate_from_zero(stats_function f, void *context, double lo, double hi)
{
    const double t_floor = 0x1p-80;
    double sum = 0.0, a = lo;
    if (a < t_floor) {
        double b = fmin(hi, t_floor);
        sum += stats_gl_panel(f, context, a, b);
        a = b;
    }
    while (a < hi) {
        int exponent;
        frexp(a, &exponent); /* 2^(exponent-1) <= a < 2^exponent */
        double b = fmin(ldexp(1.0, exponent), hi);
        sum += stats_gl_panel(f, context, a, b);
        a = b;
    }
    return sum;
}

/* ---- histograms and the chi-square test ----------------------------------------------------- */

/* The bin k with edges[k] <= x < edges[k + 1] (x == edges[bins] goes in the last bin), or -1 if x
 * is outside [edges[0], edges[bins]] or NaN. edges ascending. */
static inline int stats_bin(const double *edges, int bins, double x)
{
    if (!(x >= edges[0] && x <= edges[bins])) return -1;
    int lo = 0, hi = bins; /* edges[lo] <= x, and x < edges[hi] unless hi == bins */
    while (hi - lo > 1) {
        int middle = (lo + hi) / 2;
        if (x >= edges[middle]) lo = middle; else hi = middle;
    }
    return lo;
}

typedef struct stats_chi_square_t {
    double x2;  /* sum (O - E)^2 / E over the merged bins */
    int dof;    /* merged bins - 1 */
    double p;   /* P(chi^2_dof >= x2) */
} stats_chi_square_t;

/* Pearson's chi-square of observed against expected counts, adjacent bins merged from the left
 * until each expects STATS_MIN_EXPECTED (a short remainder joins the last group). The expected
 * counts are used as given: if they do not sum to the number of samples (a pdf that does not
 * integrate to 1), that shows in the statistic too. */
static inline stats_chi_square_t stats_chi_square(const double *observed, const double *expected, int bins)
{
    stats_chi_square_t result = {0.0, -1, 0.0};
    double group_o = 0.0, group_e = 0.0, last_o = 0.0, last_e = 0.0;
    int have_last = 0;
    for (int k = 0; k < bins; ++k) {
        group_o += observed[k];
        group_e += expected[k];
        if (group_e >= STATS_MIN_EXPECTED) {
            if (have_last) {
                result.x2 += (last_o - last_e) * (last_o - last_e) / last_e;
                ++result.dof;
            }
            last_o = group_o;
            last_e = group_e;
            have_last = 1;
            group_o = group_e = 0.0;
        }
    }
    last_o += group_o;
    last_e += group_e;
    if (last_e > 0.0) {
        result.x2 += (last_o - last_e) * (last_o - last_e) / last_e;
        ++result.dof;
    } else if (last_o > 0.0) {
        result.x2 = INFINITY; /* samples where the pdf says none can be */
        ++result.dof;
    }
    result.p = result.dof > 0 ? stats_chi_square_p(result.x2, result.dof) : 0.0;
    return result;
}

static inline void stats_print(const char *what, stats_chi_square_t r)
{
    printf("  %-58s chi2 = %9.2f  dof = %4d  p = %.3g\n", what, r.x2, r.dof, r.p);
}

#endif
