/* Sampling toward the lit side of a thin sheet (the `sheet` technique), each function with its pdf.
 * Pure and inline: the walk calls these per scattering event.
 *
 * Zero-variance random walks (Hoogenboom 2008; d'Eon and Krivanek 2020, who derive Dwivedi
 * sampling this way): a walk that draws each step from the transport kernel times the importance
 * psi of where the step lands carries the answer itself, whatever path it takes, when psi is
 * exact; with an approximate psi its variance shrinks as psi improves. Dwivedi sampling takes psi
 * from the half-space's asymptotic solution, exp(-kappa x); for a thin sheet of albedo near 1,
 * kappa is near 0 and that psi has no slope, so it guides nothing (docs/speed.md: the leaf's green
 * walked alone or shared had the same variance). There the light that leaves by the lit face
 * has, by diffusion theory between extrapolated boundaries, an importance linear in the optical
 * height z above the far face:
 *
 *   psi(z) ~ z + z_e,  z_e = 0.7104 (the Milne extrapolation length of an index-matched boundary,
 *   in mean free paths; Case and Zweifel 1967).
 *
 * A step from a point of linear importance a = z + z_e (z the optical height above the entry
 * point, of either sign: a curved sheet's walk goes below its entry's height inside the medium)
 * and importance psi = max(a, f), f = DWVK_SHEET_FLOOR = z_e / 4, then draws
 *   the cosine mu to the lit face's outward normal:   p(mu) = (1 + s mu) / Z, linear either side
 *       of 0 (s = up or down, Z = 2 + (up - down) / 2) through the chords of the exact marginal
 *       N(a, mu) of the kernel x psi (dwvk_sheet_slopes: up = 1 / a above the floor, held at
 *       1 / z_e);
 *   the optical flight tau given mu:                  p(tau) = exp(-tau) max(a + mu tau, f) / N(a, mu),
 *       N the integral of the same (dwvk_sheet_tail_integral at 0);
 *   and leaves through a surface at tau with the tail P(T > tau). The floor keeps the flight's pdf
 *   at least f / N times the exponential's wherever the walk can land, so that the weight x
 *   importance a walk keeps changes by a bounded factor per step. Before it (psi = (a + mu tau)_+,
 *   the walk's a held at z_e below the entry's height, one slope min(1 / a, 0.75)) a flat sheet's
 *   walks never met psi = 0 inside the medium (the far face is at z = 0), but a bent sheet's did:
 *   flights past a / |mu| were the classical share's alone, a weight factor of 1 / q_classical =
 *   100 at such a step, and a bake with one sample of weight ~5,800 (docs/speed.md, the bent
 *   sheet). The floor costs the flat sheet a little: its far face's exits (importance 0 in the
 *   zero-variance walk) get the floor's share, variance per walk +13% on the 2.5-mfp slab at albedo
 *   0.9995 (a floor of z_e / 2: +34%, z_e: +100%; z_e / 10: +5% but 1.2x the bent sheet's noise).
 *   The first version's measurements, one-dimensional model of the report's leaf (2.5 mean free
 *   paths, walks entering the far face), held for the linear part:
 * variance x events per walk 7x below classical sampling's at albedo 0.9995, 7x at 0.951 and 4.7x
 * at 0.851. */
#ifndef DWV_KERNEL_SHEET_H
#define DWV_KERNEL_SHEET_H

#include <math.h>

#include "fastmath.h"

#define DWVK_SHEET_EXTRAPOLATION 0.7104
#define DWVK_SHEET_FLOOR (0.25 * DWVK_SHEET_EXTRAPOLATION)
#define DWVK_SHEET_NEWTON_STEPS 100
#define DWVK_SHEET_INV_TWO_PI 0.15915494309189533577

/* The importance at a point of linear importance a = z_e + sigma h (h the height above the entry,
 * of any sign): psi = max(a, DWVK_SHEET_FLOOR). */
static inline double dwvk_sheet_importance(double a)
{
    return a > DWVK_SHEET_FLOOR ? a : DWVK_SHEET_FLOOR;
}

/* The cosine's pdf per unit cosine (per steradian: divide by 2 pi), linear on either side of 0:
 * p(mu) = (1 + slope mu) / Z, slope = up for mu >= 0 and down for mu < 0, Z = 2 + (up - down) / 2
 * (down < 1, so p > 0 on [-1, 1]). */
static inline double dwvk_sheet_cosine_pdf(double up, double down, double mu)
{
    return (1.0 + (mu >= 0.0 ? up : down) * mu) / (2.0 + 0.5 * (up - down));
}

/* The cosine from u in [0, 1): the side by its mass (1 - down / 2) / Z below 0, then the inverse
 * of the side's cdf: on [0, 1] mu + up mu^2 / 2 = v (1 + up / 2), mu = 2 w / (1 + sqrt(1 + 2 up w)),
 * w = v (1 + up / 2); on [-1, 0] with x = mu + 1, (1 - down) x + down x^2 / 2 = v (1 - down / 2),
 * x = 2 w / ((1 - down) + sqrt((1 - down)^2 + 2 down w)) (the roots rationalised: no 0/0 at a slope
 * of 0). */
static inline double dwvk_sheet_cosine_sample(double up, double down, double u)
{
    double below = (1.0 - 0.5 * down) / (2.0 + 0.5 * (up - down));
    double mu;
    if (u < below) {
        double w = u / below * (1.0 - 0.5 * down), r = 1.0 - down;
        mu = 2.0 * w / (r + sqrt(r * r + 2.0 * down * w)) - 1.0;
        if (mu > 0.0) mu = 0.0;
    } else {
        double v = (u - below) / (1.0 - below), w = v * (1.0 + 0.5 * up);
        mu = 2.0 * w / (1.0 + sqrt(1.0 + 2.0 * up * w));
        if (mu < 0.0) mu = 0.0;
    }
    return mu < -1.0 ? -1.0 : mu > 1.0 ? 1.0 : mu;
}

/* Where the flight's line a + mu tau meets the floor f, t0 = (f - a) / mu, if the importance
 * changes form along the flight (mu < 0 from above the floor: linear, then flat; mu > 0 from below
 * it: flat, then linear); else 0 (one form all the way). */
static inline double dwvk_sheet_switch(double a, double mu)
{
    return (mu < 0.0 && a > DWVK_SHEET_FLOOR) || (mu > 0.0 && a < DWVK_SHEET_FLOOR) ? (DWVK_SHEET_FLOOR - a) / mu : 0.0;
}

/* The integral of exp(-s) psi(s) over s > tau, psi(s) = max(a + mu s, f), without its factor
 * exp(-tau) (at tau = 0 it is the normalisation N). On a linear piece that runs to infinity it is
 * a + mu + mu tau; a flat one to infinity, f; a linear piece (mu < 0) that meets the floor at t0
 * adds the floor's f exp(-t0) and takes away the line's part past t0, (a + mu + mu t0) exp(-t0),
 * together -mu exp(-(t0 - tau)) (a + mu t0 = f); a flat piece before the line (mu > 0) up to t0:
 * f (1 - exp(-(t0 - tau))) + (f + mu) exp(-(t0 - tau)) = f + mu exp(-(t0 - tau)). Every form is
 * >= f (mu < 0: f + |mu| (exp(-(t0 - tau)) - 1 + (t0 - tau)) with t0 - tau >= 0), so nothing
 * cancels. */
static inline double dwvk_sheet_tail_integral(double a, double mu, double tau)
{
    const double f = DWVK_SHEET_FLOOR;
    double t0 = dwvk_sheet_switch(a, mu);
    if (t0 > 0.0) {
        if (mu < 0.0) return tau < t0 ? a + mu + mu * tau - mu * dwvk_exp_fast(tau - t0) : f;
        return tau < t0 ? f + mu * dwvk_exp_fast(tau - t0) : a + mu + mu * tau;
    }
    return mu >= 0.0 && a >= f ? a + mu + mu * tau : f;
}

/* N(a, mu): the flight's normalisation, the integral of exp(-tau) max(a + mu tau, f) over
 * tau >= 0. */
static inline double dwvk_sheet_flight_norm(double a, double mu)
{
    return dwvk_sheet_tail_integral(a, mu, 0.0);
}

/* The direction's slopes at linear importance a: the chords of the flight's normalisation
 * N(a, mu) (the marginal in mu of the kernel x psi, what a zero-variance step would draw the cosine
 * from) on each side of mu = 0, up = N(a, 1) / N(a, 0) - 1 and down = 1 - N(a, -1) / N(a, 0).
 * Above the floor N is linear for mu >= 0 (up = 1 / a, exact) and convex for mu < 0 (the chord
 * lies above it: the pdf divides by no less than the marginal's share there); below the floor N
 * is flat for mu < 0 (down = 0). A single slope min(1 / a, 0.75) on both sides, as before, drew
 * too few downward steps where a is near the floor (the marginal flat below 0, the line falling
 * to 1 - 0.75): a weight factor of up to 4 per such step, the curved sheet's remaining tail. The
 * upward slope is held at 1 / z_e, its value at the entry's height (a flat sheet's walks never
 * have less: there it is exact): between the floor and z_e, below the entry's height, 1 / a would
 * grow to 1 / f = 5.6, and sent a curved sheet's one-channel walks along the lit normal, out of
 * the sheet's own plane (the bent sheet's separate walks: RMSE 0.032 against 0.0054 held). */
static inline void dwvk_sheet_slopes(double a, double *up, double *down)
{
    double n0 = dwvk_sheet_flight_norm(a, 0.0);
    double chord = dwvk_sheet_flight_norm(a, 1.0) / n0 - 1.0; /* not NaN: a ternary, not libm's fmin call */
    *up = chord < 1.0 / DWVK_SHEET_EXTRAPOLATION ? chord : 1.0 / DWVK_SHEET_EXTRAPOLATION;
    *down = 1.0 - dwvk_sheet_flight_norm(a, -1.0) / n0;
}

/* The flight pdf without its factor exp(-tau): p(tau) = exp(-tau) x this (the walk factors the
 * exponentials of all its pdfs). Never 0: the floor keeps the flight's pdf at least f / N of the
 * exponential's wherever the walk may land. */
static inline double dwvk_sheet_flight_pdf_scaled(double a, double mu, double tau)
{
    return dwvk_sheet_importance(a + mu * tau) / dwvk_sheet_flight_norm(a, mu);
}

static inline double dwvk_sheet_flight_pdf(double a, double mu, double tau)
{
    return exp(-tau) * dwvk_sheet_flight_pdf_scaled(a, mu, tau);
}

/* The tail P(T > tau) without its factor exp(-tau). */
static inline double dwvk_sheet_flight_tail_scaled(double a, double mu, double tau)
{
    return dwvk_sheet_tail_integral(a, mu, tau) / dwvk_sheet_flight_norm(a, mu);
}

static inline double dwvk_sheet_flight_tail(double a, double mu, double tau)
{
    return exp(-tau) * dwvk_sheet_flight_tail_scaled(a, mu, tau);
}

/* The root in [lo, hi] of g(tau) = exp(-tau) (c + mu tau) - y, on a linear piece of the importance
 * (c = a + mu, psi = a + mu tau > 0 there): g is decreasing (its slope is -exp(-tau) psi) and
 * convex wherever psi > mu (g'' = exp(-tau) (psi - mu)). Halley's method inside the bracket, which
 * every iterate narrows (Newton's step where Halley's correction is large, bisection where a step
 * would leave the bracket), from tau_0 = log(c / y), the root at mu = 0 (left of the root for
 * mu >= 0, right of it for mu < 0; lo where it is out of the bracket or y <= 0): 2.8 exponentials
 * per flight for either sign (a random a in [z_e, 4.7], mu in [-1, 1]; 3.5 when it stopped only
 * after a step below 1e-12 (1 + tau)), where Newton on log g took 5.0 logarithms and, from 0, Newton
 * on g 5.4 exponentials. It stops where tau is within about 1e-12 (1 + tau) of the root, past the
 * float precision of the walk's distances: after a step of less than that, or after a Halley step
 * of less than 1e-5 (below: its error is cubic in the step; the roots move by at most 5.6e-15). */
static inline double dwvk_sheet_flight_solve(double c, double mu, double y, double lo, double hi)
{
    double tau = lo;
    if (y > 0.0) {
        double start = dwvk_log_fast((float)(c / y)); /* a start: its accuracy only saves steps */
        tau = start > lo && start < hi ? start : lo;
    }
    for (int i = 0; i < DWVK_SHEET_NEWTON_STEPS; ++i) {
        double e = dwvk_exp_fast(-tau), psi = c - mu + mu * tau;
        double g = e * (psi + mu) - y, slope = -e * psi;
        if (g > 0.0) lo = tau;
        else if (g < 0.0) hi = tau;
        else break;
        if (!(slope < 0.0)) break;
        double square = slope * slope, denominator = 2.0 * square - g * e * (psi - mu);
        int halley = denominator > square;
        double next = tau - (halley ? 2.0 * g * slope / denominator : g / slope);
        double step = fabs(next - tau);
        int inside = next > lo && next < hi;
        /* Converged: a step below 1e-12 (1 + tau) (one that rounds onto the bracket too), or a
         * Halley step below 1e-5 inside the bracket. Near the root Halley's error after a step s is
         * about C s^3, C = |g''' / (6 g') - (g'' / (2 g'))^2| <= 13.1 where psi >= f (g' = -e psi,
         * g'' = e (psi - mu), g''' = -e (psi - 2 mu), |mu| <= 1): below 1.4e-14 after such a step,
         * which then needs no step after it (one exponential less per flight). */
        if (step <= 1e-12 * (1.0 + tau) || (halley && inside && step <= 1e-5)) {
            tau = inside ? next : tau;
            break;
        }
        if (!inside) {
            if (!(hi < INFINITY)) break; /* not met: from the left a step always rises */
            next = 0.5 * (lo + hi);
        }
        tau = next;
    }
    return tau;
}

/* The optical flight from u in [0, 1), by inverting the cdf: the flight's tail integral I(tau)
 * (exp(-tau) x dwvk_sheet_tail_integral) equals (1 - u) N. On the linear piece from 0 (the line to
 * infinity, or to t0 for mu < 0) that is exp(-tau) (c + mu tau) = y, y = c - u N (the parts past
 * the piece are constants of I), solved by dwvk_sheet_flight_solve; on the flat piece after it
 * (I = f exp(-tau)), tau = log(f / ((1 - u) N)); on the flat piece before a line (mu > 0 from
 * below the floor, I = f exp(-tau) + mu exp(-t0)), tau = -log(1 - u N / f); on the line after it,
 * exp(-tau) (c + mu tau) = (1 - u) N from t0 on. A flat importance all the way is the exponential
 * flight -log(1 - u). n is N(a, mu). */
static inline double dwvk_sheet_flight_sample_normed(double a, double mu, double n, double u)
{
    const double f = DWVK_SHEET_FLOOR;
    double c = a + mu;
    double t0 = dwvk_sheet_switch(a, mu);
    if (t0 > 0.0) {
        double e0 = dwvk_exp_fast(-t0);
        if (mu < 0.0) {
            double y = c - u * n;
            if (y > (f + mu) * e0) return dwvk_sheet_flight_solve(c, mu, y, 0.0, t0);
            double tau = log(f / ((1.0 - u) * n));
            return tau > t0 ? tau : t0;
        }
        if ((1.0 - u) * n > (f + mu) * e0) {
            double tau = -log1p(-u * n / f);
            return tau < t0 ? tau : t0;
        }
        return dwvk_sheet_flight_solve(c, mu, (1.0 - u) * n, t0, INFINITY);
    }
    if (mu >= 0.0 && a >= f) return dwvk_sheet_flight_solve(c, mu, c - u * n, 0.0, INFINITY);
    return -log1p(-u);
}

/* dwvk_sheet_flight_sample_normed with its normalisation n = N(a, mu) (dwvk_sheet_flight_norm),
 * which the walk has already formed for the flight's pdf. */
static inline double dwvk_sheet_flight_sample(double a, double mu, double u)
{
    return dwvk_sheet_flight_sample_normed(a, mu, dwvk_sheet_flight_norm(a, mu), u);
}

#endif
