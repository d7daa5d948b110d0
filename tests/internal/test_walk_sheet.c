/* The sheet technique's walk (DWVW_SHEET: src/walk/walk.c, its kernel src/kernel/sheet.h, which
 * tests/internal/test_sheet_kernel.c tests alone), driven step by step through dwvw_walk_begin,
 * dwvw_walk_sample and dwvw_walk_complete, and through the estimator.
 *
 * 1. The weight update against its formula written out in long double (as test_walk_weight.c does
 *    for the other techniques): one-sample MIS, balance heuristic over channels (P_c =
 *    walk->channel_p[c]) and the two components,
 *      weight_c' *= f_c' / D,
 *      D = sum_c P_c [ q_cl phase pdist_cl,c(t) + q_sheet dir_pdf pdist_sheet,c(t) ],
 *      pdist_cl = sigma_c exp(-sigma_c t) (a scattering event at t) or exp(-sigma_c t) (leaving at t),
 *      pdist_sheet = sigma_c p(a_c, mu, sigma_c t) (event) or P(T > sigma_c t) (leaving), with the
 *        flight pdf exp(-tau) max(a + mu tau, f) / N(a, mu) (f = FLOOR, a quarter of z_e) and its
 *        tail written out here in closed form, piece by piece,
 *      dir_pdf = (1 + s mu) / (2 pi Z), s = up for mu >= 0, down below, Z = 2 + (up - down) / 2,
 *        the chords of N(a_guide, mu) either side of 0: up = min(N(a, 1) / N(a, 0) - 1, 1 / z_e),
 *        down = 1 - N(a, -1) / N(a, 0),
 *      a_c = sigma_c h + z_e, h the height above the entry point along the walk's sheet axis (of
 *        either sign): the entry face's inward normal where that face looks away from the light
 *        (entry normal . lit normal < -DWVW_SHEET_LOCAL_COSINE), else the lit normal (walk.h); mu
 *        the cosine to the same axis. Main's walk before the entry-face axis (the lit normal for
 *        every walk) fails here in the cases of a tilted far face, about half of them,
 *      f_c' = phase sigma_c' alpha_c' exp(-sigma_c' t) (event) or phase exp(-sigma_c' t) (leaving),
 *      phase = dir_pdf = 1 on the first step; q_cl = max(0.01, |g|), q_sheet = 1 - q_cl,
 *    for random states (grey and RGB media, equal and unequal extinctions, channels of P = 0, first
 *    and later steps, g = 0 and not, every cosine, heights above and below the entry, the sampled
 *    distance or another, up to and past where the flight meets the floor), relative 1e-11. The
 *    phase value the walk keeps (single precision) is checked against HG apart, to 1e-5; the channel
 *    probabilities against throughput x albedo. Planted: one extinction 1e-6 off in the direct form.
 * 1b. The Russian roulette after a scattering event, on the largest weight times
 *    max(a_guide(new position), f) / z_e below DWVW_ROULETTE_THRESHOLD: the fate (the walk's roulette
 *    number against the survival probability) and the survivors' weights. Planted: no importance
 *    factor (the fates that would change are counted).
 * 2. What the walk samples against the pdf it divides by: from a fixed state (grey medium, lit
 *    normal (0, 0, 1), the walk at a chosen height after a first scattering event at a chosen
 *    distance), many steps, each a walk begun anew with its own key. Chi-square of the cosine to
 *    the lit normal against q_cl (phase marginal) + q_sheet (1 + s mu) / Z, and of the joint
 *    (cosine, optical flight) on a 16 x 16 grid against the cell integrals of
 *    q_cl p_cl(mu) exp(-tau) + q_sheet p_sheet(mu) p(a, mu, tau); the first step's flight along
 *    the entry direction. Isotropic (phase marginal 1/2) and g = 0.5 with the previous direction
 *    along the lit normal (then the classical cosine is HG's). Planted: both slopes 10% off, a 15% off.
 * 3. The lit-side rule: a sheet walk whose entry normal faces the lit normal (dot > 0) is the
 *    classical walk of the same key, bit for bit (positions, directions, weights, events, status),
 *    step by step in a slab, grey and RGB, g = 0 and not; in the estimator (general path) its
 *    totals equal classical's. Control: entering on the far side, most walks differ.
 * 4. Means: the estimator's transmittance of a back-lit slab of 2.5 mean free paths (diffuse
 *    incidence) at albedo 0.9995, 0.95, 0.85 and in an RGB medium of unequal extinctions: sheet
 *    and classical agree within SIGMAS combined standard errors; a planted bias of PLANTED_BIAS is
 *    resolved; at albedo 0.9995 the sheet's variance per walk is below VARIANCE_RATIO_BOUND times
 *    classical's.
 *
 * Deterministic: counter-based random numbers (kernel/rng.h), fixed seeds. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "kernel/rng.h"
#include "kernel/sheet.h"
#include "stats.h"
#include "walk/estimate.h"
#include "walk/geometry.h"
#include "walk/step.h"
#include "walk/walk.h"

#define SEED 0x5ee7a1cull
#define PI_L 3.141592653589793238462643383279502884L

/* 1 */
#define CASES 20000
#define RELATIVE_TOLERANCE 1e-11
#define PHASE_TOLERANCE 1e-5
#define START_WEIGHT 1e120 /* far above the roulette threshold, whatever the ratio */
#define ROULETTE_CASES 8000

/* 2 */
#define STEP_SAMPLES 300000
#define COSINE_BINS 64
#define GRID 16

/* 4 */
#define SLAB_MFP 2.5
#define SLAB_WALKS 600000u
#define SIGMAS 4.5
#define PLANTED_BIAS 0.02
#define VARIANCE_RATIO_BOUND 0.25
#define THREADS 2u

/* ---- references, in long double ------------------------------------------------------------- */

/* Whether long double reaches below double's range at run time (x87 extended precision does;
 * under valgrind, which computes it as double, it does not). */
static int long_double_has_range(void)
{
    volatile long double tiny = 1e-300L;
    return tiny * tiny != 0.0L;
}

#define FLOOR (0.25L * 0.7104L) /* the importance's floor, a quarter of z_e (src/kernel/sheet.h) */

/* The integral of exp(-s) psi(s), psi = max(a + mu s, f), over [x, y] (y may be infinite) where
 * psi has one form: exp(-x) (a + mu + mu x) - exp(-y) (a + mu + mu y) on a line, f (exp(-x) -
 * exp(-y)) on the floor. */
static long double ref_piece(long double a, long double mu, long double x, long double y)
{
    long double middle = isinf(y) ? x + 1.0L : 0.5L * (x + y);
    if (a + mu * middle >= FLOOR)
        return expl(-x) * (a + mu + mu * x) - (isinf(y) ? 0.0L : expl(-y) * (a + mu + mu * y));
    return FLOOR * (expl(-x) - (isinf(y) ? 0.0L : expl(-y)));
}

/* The integral of exp(-s) psi(s) over s > tau, in the pieces either side of t0 = (f - a) / mu. */
static long double ref_tail_integral(long double a, long double mu, long double tau)
{
    if (isinf(tau)) return 0.0L;
    long double t0 = mu != 0.0L ? (FLOOR - a) / mu : -1.0L;
    if (t0 > tau) return ref_piece(a, mu, tau, t0) + ref_piece(a, mu, t0, INFINITY);
    return ref_piece(a, mu, tau, INFINITY);
}

static long double ref_norm(long double a, long double mu)
{
    return ref_tail_integral(a, mu, 0.0L);
}

/* exp(-tau) max(a + mu tau, f) / N */
static long double ref_flight_pdf(long double a, long double mu, long double tau)
{
    return expl(-tau) * fmaxl(a + mu * tau, FLOOR) / ref_norm(a, mu);
}

/* P(T > tau) */
static long double ref_flight_tail(long double a, long double mu, long double tau)
{
    return ref_tail_integral(a, mu, tau) / ref_norm(a, mu);
}

static long double ref_hg(long double g, long double mu)
{
    long double base = 1.0L + g * g - 2.0L * g * mu;
    return (1.0L - g * g) / (4.0L * PI_L * base * sqrtl(base));
}

/* The sheet cosine's pdf per unit cosine at linear importance a: linear either side of 0 through
 * the chords of N(a, mu), slopes times `plant`. */
static long double ref_cosine_pdf(long double a, long double mu, long double plant)
{
    long double n0 = ref_norm(a, 0.0L);
    long double up = plant * fminl(ref_norm(a, 1.0L) / n0 - 1.0L, 1.0L / 0.7104L);
    long double down = plant * (1.0L - ref_norm(a, -1.0L) / n0);
    return (1.0L + (mu >= 0.0L ? up : down) * mu) / (2.0L + 0.5L * (up - down));
}

/* ---- small helpers -------------------------------------------------------------------------- */

static double uniform(uint64_t key, uint32_t *dim)
{
    return dwvk_rng_uniform_d(key, (*dim)++);
}

static dwvu_vec3 random_unit(uint64_t key, uint32_t *dim)
{
    double z = 2.0 * uniform(key, dim) - 1.0, phi = 2.0 * 3.14159265358979323846 * uniform(key, dim);
    double r = sqrt(fmax(0.0, 1.0 - z * z));
    return dwvu_v(r * cos(phi), r * sin(phi), z);
}

static long double dot_l(dwvu_vec3 a, dwvu_vec3 b)
{
    return (long double)a.x * b.x + (long double)a.y * b.y + (long double)a.z * b.z;
}

static int same_vec(dwvu_vec3 a, dwvu_vec3 b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

/* ==== 1. the weight update ==================================================================== */

typedef struct step_case {
    dwvw_medium medium;
    dwvw_guide guide;
    dwvw_walk walk;
    dwvu_vec3 normal;   /* the lit normal expected (the strongest patch's) */
    dwvu_vec3 axis;     /* the walk's sheet axis expected: the entry face's inward normal or the lit one */
    dwvu_vec3 previous; /* the direction before the step */
    double t;
    int exited, overridden_p, overridden_t;
} step_case;

/* Sets up a state by the public internal functions; 0 if the guide or the walk is not as expected
 * (each reported). */
static int make_case(uint64_t index, step_case *s)
{
    uint64_t key = dwvk_rng_key(SEED, 1u, index);
    uint32_t dim = 0;
    memset(s, 0, sizeof *s);
    int channels = uniform(key, &dim) < 0.3 ? 1 : 3;
    double sigma[3], albedo[3];
    for (int c = 0; c < 3; ++c) {
        sigma[c] = pow(10.0, 3.0 * uniform(key, &dim) - 1.5);
        albedo[c] = uniform(key, &dim);
        if (channels == 3 && uniform(key, &dim) < 0.08) albedo[c] = 0.0; /* P = 0 by itself */
    }
    double shape = uniform(key, &dim);
    if (shape < 0.15) sigma[1] = sigma[2] = sigma[0];
    else if (shape < 0.25) sigma[2] = sigma[1];
    else if (shape < 0.3) sigma[2] = sigma[0];
    else if (shape < 0.35) sigma[1] = sigma[0];
    if (albedo[0] == 0.0 && albedo[1] == 0.0 && albedo[2] == 0.0) albedo[0] = 0.5;
    double g = uniform(key, &dim) < 0.4 ? 0.0 : 1.8 * uniform(key, &dim) - 0.9;
    dwvw_medium_init(&s->medium, channels, sigma, albedo, g);

    /* 1 to 3 lit patches, the strongest one's normal the lit one */
    dwvw_light_patch patches[3];
    int patch_count = 1 + (int)(3.0 * uniform(key, &dim)) % 3, strongest = 0;
    for (int i = 0; i < patch_count; ++i) {
        patches[i].point = dwvu_v(uniform(key, &dim), uniform(key, &dim), uniform(key, &dim));
        patches[i].normal = random_unit(key, &dim);
        patches[i].power = 0.1 + uniform(key, &dim);
        patches[i].log_power = 0.0;
        patches[i].is_plane = uniform(key, &dim) < 0.5;
        if (patches[i].power > patches[strongest].power) strongest = i;
    }
    s->normal = patches[strongest].normal;
    dwvw_guide_init(&s->guide, DWVW_SHEET, &s->medium, patches, patch_count);
    double q_classical = fmax(0.01, fabs(g));
    int guide_ok = same_vec(s->guide.sheet_normal, s->normal) && s->guide.q_classical == q_classical &&
                   fabs(s->guide.q_sheet - (1.0 - q_classical)) <= 1e-16 && s->guide.q_poe == 0.0 &&
                   s->guide.q_closest == 0.0 && s->guide.q_incident == 0.0 && s->guide.q_backward == 0.0;
    CHECK(guide_ok, "case %llu: sheet guide q_classical %g q_sheet %g (expected %g), normal (%g %g %g) vs (%g %g %g)",
          (unsigned long long)index, s->guide.q_classical, s->guide.q_sheet, q_classical, s->guide.sheet_normal.x,
          s->guide.sheet_normal.y, s->guide.sheet_normal.z, s->normal.x, s->normal.y, s->normal.z);
    if (!guide_ok) return 0;

    /* an entry on the far side (entry normal . lit normal < 0), heading in */
    dwvu_vec3 entry_normal = random_unit(key, &dim);
    double facing = dwvu_dot(entry_normal, s->normal);
    if (fabs(facing) < 1e-3) entry_normal = dwvu_normalize(dwvu_madd(entry_normal, s->normal, -0.5));
    if (dwvu_dot(entry_normal, s->normal) > 0.0) entry_normal = dwvu_scale(entry_normal, -1.0);
    /* the axis: the entry face's inward normal where it looks away from the light, else the lit
     * normal (a rim): both kinds occur */
    s->axis = dwvu_dot(entry_normal, s->normal) < -DWVW_SHEET_LOCAL_COSINE ? dwvu_scale(entry_normal, -1.0) : s->normal;
    dwvu_vec3 entry_direction = random_unit(key, &dim);
    if (dwvu_dot(entry_direction, entry_normal) > 0.0) entry_direction = dwvu_scale(entry_direction, -1.0);
    dwvu_vec3 entry_point = dwvu_v(10.0 * uniform(key, &dim) - 5.0, 10.0 * uniform(key, &dim) - 5.0,
                                   10.0 * uniform(key, &dim) - 5.0);
    dwvw_walk *w = &s->walk;
    dwvw_walk_begin(w, &s->medium, &s->guide, dwvk_rng_key(SEED, 2u, index), 1000000u, entry_point, entry_direction,
                    entry_normal);
    CHECK(w->guide == &s->guide, "case %llu: a walk entering on the far side does not run the sheet",
          (unsigned long long)index);
    if (w->guide != &s->guide) return 0;
    CHECK(same_vec(w->sheet_normal, s->axis), "case %llu: the walk's sheet axis (%g %g %g), expected (%g %g %g)",
          (unsigned long long)index, w->sheet_normal.x, w->sheet_normal.y, w->sheet_normal.z, s->axis.x, s->axis.y,
          s->axis.z);
    for (int c = 0; c < channels; ++c) w->weight[c] = START_WEIGHT * (0.25 + uniform(key, &dim));

    if (uniform(key, &dim) >= 0.35) {
        /* a later event: somewhere above or below the entry (in optical heights of the guide channel),
         * after a direction of any kind */
        w->events = 1u + (uint32_t)(40.0 * uniform(key, &dim));
        double optical = uniform(key, &dim) < 0.2 ? -3.0 * uniform(key, &dim) : 12.0 * uniform(key, &dim);
        double h = optical / s->medium.sigma_t[s->medium.guide_channel];
        dwvu_vec3 lateral = random_unit(key, &dim);
        lateral = dwvu_sub(lateral, dwvu_scale(s->axis, dwvu_dot(lateral, s->axis)));
        w->position = dwvu_add(dwvu_madd(entry_point, s->axis, h), dwvu_scale(lateral, 3.0 * uniform(key, &dim)));
        w->direction = random_unit(key, &dim);
    }
    s->previous = w->direction;
    double sampled = dwvw_walk_sample(w);
    CHECK(isfinite(sampled) && sampled >= 0.0 && sampled == w->step_distance, "case %llu: sampled distance %g (%g)",
          (unsigned long long)index, sampled, w->step_distance);

    /* P_c: throughput x albedo, normalised (1 in a grey medium) */
    double total = 0.0;
    for (int c = 0; c < channels; ++c) total += w->weight[c] * s->medium.albedo[c];
    for (int c = 0; c < channels; ++c) {
        double expected = channels == 1 ? 1.0 : w->weight[c] * s->medium.albedo[c] / total;
        CHECK(fabs(w->channel_p[c] - expected) <= 1e-15 * (1.0 + expected), "case %llu: P_%d %.17g, expected %.17g",
              (unsigned long long)index, c, w->channel_p[c], expected);
    }
    if (channels == 3 && uniform(key, &dim) < 0.2) {
        /* other channel probabilities, one of them 0 (the update uses whatever P the step had) */
        s->overridden_p = 1;
        int off = (int)(3.0 * uniform(key, &dim)) % 3;
        for (int c = 0; c < 3; ++c) w->channel_p[c] = c == off ? 0.0 : 0.05 + uniform(key, &dim);
    }

    /* the distance: as sampled, or another (as test_walk_weight), or about where a channel's
     * flight meets the floor, where the direction points down */
    double t = sampled, choice = uniform(key, &dim);
    double mu = dwvw_cosine(w->direction, s->axis);
    if (choice < 0.3) {
        s->overridden_t = 1;
        t = -log(1.0 - uniform(key, &dim)) * pow(10.0, 2.5 * uniform(key, &dim) - 1.0) /
            s->medium.sigma_t[(int)(channels * uniform(key, &dim)) % channels];
    } else if (choice < 0.45 && mu < -1e-3) {
        s->overridden_t = 1;
        int c = (int)(channels * uniform(key, &dim)) % channels;
        double h = dwvu_dot(dwvu_sub(w->position, w->entry_point), s->axis);
        double a = s->medium.sigma_t[c] * h + DWVK_SHEET_EXTRAPOLATION;
        t = fabs(a - (double)FLOOR) / -mu / s->medium.sigma_t[c] * (1.0 + 1e-3 * (2.0 * uniform(key, &dim) - 1.0));
    }
    s->t = t;
    s->exited = uniform(key, &dim) < 0.35;
    w->step_distance = t;
    return 1;
}

/* The direct form of channel cw's ratio; sigma_plant multiplies channel `planted`'s extinction in D. */
static long double direct_ratio(const step_case *s, int cw, int planted, long double sigma_plant)
{
    const dwvw_walk *w = &s->walk;
    const dwvw_medium *m = &s->medium;
    long double t = s->t;
    long double h = dot_l(dwvu_sub(w->position, w->entry_point), s->axis);
    long double mu = dot_l(w->direction, s->axis);
    mu = mu < -1.0L ? -1.0L : mu > 1.0L ? 1.0L : mu;
    long double a_guide = (long double)m->sigma_t[m->guide_channel] * h + DWVK_SHEET_EXTRAPOLATION;
    long double first = w->events == 0;
    long double phase = first ? 1.0L : (long double)w->phase;
    long double dir_pdf = first ? 1.0L : ref_cosine_pdf(a_guide, mu, 1.0L) / (2.0L * PI_L);
    long double q_classical = fmaxl(0.01L, fabsl((long double)m->g)), q_sheet = 1.0L - q_classical;
    long double denominator = 0.0L;
    for (int c = 0; c < m->channels; ++c) {
        long double p = m->channels == 1 ? 1.0L : (long double)w->channel_p[c];
        if (!(p > 0.0L)) continue;
        long double sigma = (long double)m->sigma_t[c] * (c == planted ? sigma_plant : 1.0L);
        long double a = sigma * h + DWVK_SHEET_EXTRAPOLATION, tau = sigma * t;
        long double classical = (s->exited ? 1.0L : sigma) * expl(-tau);
        long double sheet = s->exited ? ref_flight_tail(a, mu, tau) : sigma * ref_flight_pdf(a, mu, tau);
        denominator += p * (q_classical * phase * classical + q_sheet * dir_pdf * sheet);
    }
    long double sigma_w = m->sigma_t[cw];
    long double f = phase * (s->exited ? 1.0L : sigma_w * m->albedo[cw]) * expl(-sigma_w * t);
    return f / denominator;
}

static void test_weight_update(void)
{
    double worst = 0.0, worst_phase = 0.0;
    int compared = 0, exact_zero = 0, underflowed = 0, skipped = 0, planted_cases = 0, planted_caught = 0;
    int kinds[2][2] = {{0, 0}, {0, 0}}, below = 0, past_end = 0, negative_mu = 0, grey = 0, anisotropic = 0;
    int p_zero = 0, equal_sigma = 0, other_t = 0;
    for (uint64_t i = 0; i < CASES; ++i) {
        step_case s;
        if (!make_case(i, &s)) continue;
        dwvw_walk *w = &s.walk;
        const int channels = s.medium.channels;
        /* the phase the walk keeps (single precision for HG) against HG written out */
        if (w->events > 0) {
            long double cosine = dot_l(s.previous, w->direction);
            long double expected = ref_hg((long double)(float)s.medium.g, fmaxl(-1.0L, fminl(1.0L, cosine)));
            double error = (double)fabsl((long double)w->phase / expected - 1.0L);
            CHECK(error <= PHASE_TOLERANCE, "case %llu: phase %.9g, HG %.9Lg (g %g)", (unsigned long long)i, w->phase,
                  expected, s.medium.g);
            worst_phase = fmax(worst_phase, error);
        } else {
            CHECK(w->phase == 1.0, "case %llu: first step's phase %g, not 1", (unsigned long long)i, w->phase);
        }
        int planted_channel = channels == 3 ? 1 : 0;
        long double expected[3] = {0.0L, 0.0L, 0.0L}, largest = 0.0L;
        for (int c = 0; c < channels; ++c) {
            expected[c] = direct_ratio(&s, c, -1, 1.0L);
            largest = fmaxl(largest, expected[c]);
        }
        /* as test_walk_weight: ratios the walk can carry from START_WEIGHT without overflow and
         * without Russian roulette */
        if (!(largest <= 1e150L) || largest * START_WEIGHT < 1.0L) {
            ++skipped;
            continue;
        }
        long double mu = dot_l(w->direction, s.axis);
        long double h = dot_l(dwvu_sub(w->position, w->entry_point), s.axis);
        ++kinds[w->events > 0][s.exited];
        below += h < 0.0L;
        negative_mu += mu < 0.0L;
        grey += channels == 1;
        anisotropic += s.medium.g != 0.0;
        other_t += s.overridden_t;
        if (channels == 3) {
            p_zero += !(w->channel_p[0] > 0.0) || !(w->channel_p[1] > 0.0) || !(w->channel_p[2] > 0.0);
            equal_sigma += s.medium.sigma_t[0] == s.medium.sigma_t[1] || s.medium.sigma_t[1] == s.medium.sigma_t[2] ||
                           s.medium.sigma_t[0] == s.medium.sigma_t[2];
        }
        for (int c = 0; c < channels; ++c) {
            long double a = s.medium.sigma_t[c] * h + DWVK_SHEET_EXTRAPOLATION;
            if (mu < 0.0L && a > FLOOR && (long double)s.medium.sigma_t[c] * s.t > (a - FLOOR) / -mu) {
                ++past_end;
                break;
            }
        }
        double start[3] = {w->weight[0], w->weight[1], w->weight[2]};
        dwvu_vec3 expected_position = dwvu_madd(w->position, w->direction, s.t);
        uint32_t events = w->events;
        double hit = s.exited ? s.t : (i & 1u) ? INFINITY : 2.0 * s.t + 1.0;
        dwvw_status status = dwvw_walk_complete(w, hit, dwvu_v(0.0, 0.0, 1.0));
        CHECK(status == (s.exited ? DWVW_EXITED : DWVW_RUNNING), "case %llu: status %d", (unsigned long long)i,
              (int)status);
        CHECK(same_vec(w->position, expected_position) && w->events == events + !s.exited,
              "case %llu: the walk did not move by t along its direction", (unsigned long long)i);
        double planted_error = 0.0;
        for (int c = 0; c < channels; ++c) {
            double got = w->weight[c] / start[c];
            CHECK(isfinite(got) && got >= 0.0, "case %llu channel %d: ratio %g", (unsigned long long)i, c, got);
            if (expected[c] == 0.0L) {
                /* Where long double has only double's range (valgrind computes it so), the direct
                 * form underflows to 0 where the walk's factored form keeps a ratio below 1e-250. */
                CHECK(got == 0.0 || (!long_double_has_range() && got < 1e-250),
                      "case %llu channel %d: ratio %g where the formula gives 0", (unsigned long long)i, c, got);
                ++exact_zero;
                continue;
            }
            if (expected[c] < 1e-280L) {
                CHECK(got < 1e-250, "case %llu channel %d: %g where the ratio is %Lg", (unsigned long long)i, c, got,
                      expected[c]);
                ++underflowed;
                continue;
            }
            double error = (double)fabsl((long double)got / expected[c] - 1.0L);
            CHECK(error <= RELATIVE_TOLERANCE,
                  "case %llu channel %d: ratio %.17g, direct form %.17Lg (channels %d, events %u, exited %d, t %g, "
                  "mu %.6Lf, h %.4Lg, g %g, P %g %g %g)",
                  (unsigned long long)i, c, got, expected[c], channels, events, s.exited, s.t, mu, h, s.medium.g,
                  w->channel_p[0], w->channel_p[1], w->channel_p[2]);
            worst = fmax(worst, error);
            long double planted = direct_ratio(&s, c, planted_channel, 1.0L + 1e-6L);
            planted_error = fmax(planted_error, (double)fabsl((long double)got / planted - 1.0L));
            ++compared;
        }
        if (channels == 1 || w->channel_p[planted_channel] > 0.0) {
            ++planted_cases;
            planted_caught += planted_error > RELATIVE_TOLERANCE;
        }
    }
    printf("1. weight update: %d ratios in %d states (%d grey; RGB: %d with a channel of P = 0, %d with equal "
           "extinctions; %d with g != 0; first step: %d scatter, %d exit; later: %d scatter, %d exit; %d below the "
           "entry, %d cosines < 0, %d distances not the sampled one, %d past where a channel's flight meets the floor), worst relative "
           "difference %.2g from the direct form; %d exact zeros, %d far below double's range, %d states beyond it "
           "skipped; phase within %.2g of HG; a 1e-6 change of one extinction caught in %d of %d states\n",
           compared, CASES - skipped, grey, p_zero, equal_sigma, anisotropic, kinds[0][0], kinds[0][1], kinds[1][0],
           kinds[1][1], below, negative_mu, other_t, past_end, worst, exact_zero, underflowed, skipped, worst_phase,
           planted_caught, planted_cases);
    CHECK(compared > CASES, "compared only %d ratios", compared);
    CHECK(kinds[0][0] > CASES / 20 && kinds[0][1] > CASES / 20 && kinds[1][0] > CASES / 20 && kinds[1][1] > CASES / 20,
          "too few states of some kind");
    CHECK(below > CASES / 50 && negative_mu > CASES / 10 && past_end > CASES / 50 && p_zero > CASES / 20 &&
              equal_sigma > CASES / 10 && anisotropic > CASES / 5,
          "too few states of some kind: below the entry %d, going down %d, onto the floor %d, P = 0 %d, equal "
          "extinctions %d, g != 0 %d", below, negative_mu, past_end, p_zero, equal_sigma, anisotropic);
    CHECK(planted_caught > planted_cases * 3 / 4, "a planted 1e-6 change caught in only %d of %d states", planted_caught,
          planted_cases);
}

/* The Russian roulette after a scattering event: with the weights scaled so that the largest new
 * weight times a_guide(new position) / z_e, L, falls below DWVW_ROULETTE_THRESHOLD, the walk
 * survives iff its roulette number u < L / threshold, its weights then divided by that; else it is
 * absorbed with weight 0. Planted: the same rule without the importance factor. */
static void test_roulette(void)
{
    int cases = 0, rouletted = 0, survived = 0, absorbed = 0, untouched = 0, planted_differ = 0, near = 0;
    double worst = 0.0;
    for (uint64_t i = 0; i < ROULETTE_CASES; ++i) {
        step_case s;
        if (!make_case(CASES + i, &s) || s.exited) continue;
        dwvw_walk *w = &s.walk;
        const dwvw_medium *m = &s.medium;
        long double ratio[3] = {0.0L, 0.0L, 0.0L}, largest = 0.0L;
        for (int c = 0; c < m->channels; ++c) {
            ratio[c] = direct_ratio(&s, c, -1, 1.0L) * w->weight[c];
            largest = fmaxl(largest, ratio[c]);
        }
        if (!(largest > 1e-250L && largest < 1e250L)) continue;
        dwvu_vec3 moved = dwvu_madd(w->position, w->direction, s.t);
        long double h = dot_l(dwvu_sub(moved, w->entry_point), s.axis);
        long double importance =
            fmaxl((long double)m->sigma_t[m->guide_channel] * h + DWVK_SHEET_EXTRAPOLATION, FLOOR) / DWVK_SHEET_EXTRAPOLATION;
        /* scale the weights so that L = largest x importance is uniform in (0, 0.7) */
        long double target = 0.7L * dwvk_rng_uniform_d(dwvk_rng_key(SEED, 5u, i), 0u) + 1e-6L;
        long double scale = target / (largest * importance);
        for (int c = 0; c < m->channels; ++c) w->weight[c] = (double)(w->weight[c] * scale);
        long double product = target; /* the largest new weight x importance, as set */
        uint32_t events = w->events;
        double u = dwvk_rng_uniform_d(w->key, dwvw_event_dim(events) + DWVW_DIM_ROULETTE);
        long double survive = product / DWVW_ROULETTE_THRESHOLD;
        long double survive_planted = largest * scale / DWVW_ROULETTE_THRESHOLD;
        if (fabsl((long double)u - survive) < 1e-9L || fabsl(product - DWVW_ROULETTE_THRESHOLD) < 1e-9L) {
            ++near; /* too close to call in long double against the walk's doubles */
            continue;
        }
        dwvw_status status = dwvw_walk_complete(w, INFINITY, dwvu_v(0.0, 0.0, 1.0));
        ++cases;
        int expect_survive = !(product < DWVW_ROULETTE_THRESHOLD) || (long double)u < survive;
        int planted_survive = !(largest * scale < DWVW_ROULETTE_THRESHOLD) || (long double)u < survive_planted;
        planted_differ += planted_survive != expect_survive;
        if (product < DWVW_ROULETTE_THRESHOLD) ++rouletted;
        else ++untouched;
        if (!expect_survive) {
            ++absorbed;
            int zero = 1;
            for (int c = 0; c < DWVW_MAX_CHANNELS; ++c) zero &= w->weight[c] == 0.0;
            CHECK(status == DWVW_ABSORBED && zero, "roulette case %llu: status %d, weight %g, where u %.17g >= %.17Lg",
                  (unsigned long long)i, (int)status, w->weight[0], u, survive);
            continue;
        }
        ++survived;
        CHECK(status == DWVW_RUNNING, "roulette case %llu: status %d where u %.17g < %.17Lg", (unsigned long long)i,
              (int)status, u, survive);
        long double divide = product < DWVW_ROULETTE_THRESHOLD ? survive : 1.0L;
        for (int c = 0; c < m->channels; ++c) {
            long double expected = ratio[c] * scale / divide;
            if (expected < 1e-280L) continue;
            double error = (double)fabsl((long double)w->weight[c] / expected - 1.0L);
            CHECK(error <= RELATIVE_TOLERANCE, "roulette case %llu channel %d: weight %.17g, expected %.17Lg",
                  (unsigned long long)i, c, w->weight[c], expected);
            worst = fmax(worst, error);
        }
    }
    printf("1b. roulette: %d scattering states (%d below the threshold: %d survived, %d absorbed; %d above; %d too "
           "close to call skipped), survivors' weights within %.2g of the formula; without the importance factor "
           "%d fates would differ\n",
           cases, rouletted, survived - untouched, absorbed, untouched, near, worst, planted_differ);
    CHECK(rouletted > ROULETTE_CASES / 4 && absorbed > ROULETTE_CASES / 10 && survived - untouched > ROULETTE_CASES / 20,
          "too few roulette states: %d below the threshold, %d absorbed", rouletted, absorbed);
    CHECK(planted_differ > ROULETTE_CASES / 50, "a roulette without the importance factor differs in %d states only",
          planted_differ);
}

/* ==== 2. sampling against the pdf ============================================================== */

typedef struct sample_state {
    const char *name;
    double g;
    double optical_height; /* sigma h of the walk's position */
    double entry_cosine;   /* the entry direction's cosine to the lit normal (the first step's) */
    int first_step;        /* 1: the entry's step (events 0), its flight alone */
} sample_state;

#define SAMPLE_SIGMA 2.0

typedef struct cosine_context {
    double g, a, plant;
    int sheet; /* 1: the sheet's cosine pdf, 0: the classical one */
} cosine_context;

/* The classical cosine's pdf to the lit normal (the previous direction is the lit normal): HG, or
 * 1/2 where isotropic. */
static double classical_cosine_pdf(double g, double mu)
{
    return g == 0.0 ? 0.5 : (double)(2.0L * PI_L * ref_hg((long double)(float)g, mu));
}

static double cosine_integrand(double mu, void *context)
{
    const cosine_context *k = context;
    return k->sheet ? (double)ref_cosine_pdf(k->a, mu, k->plant) : classical_cosine_pdf(k->g, mu);
}

typedef struct cell_context {
    double a, a_direction, tau_lo, tau_hi;
} cell_context;

/* The sheet's density in mu times its flight's probability in [tau_lo, tau_hi] given mu. */
static double cell_integrand(double mu, void *context)
{
    const cell_context *k = context;
    long double in_bin = ref_flight_tail(k->a, mu, k->tau_lo) - ref_flight_tail(k->a, mu, k->tau_hi);
    return (double)(ref_cosine_pdf(k->a_direction, mu, 1.0L) * in_bin);
}

/* The integral over [m0, m1] with panels split where a flight meets the floor at tau_lo or tau_hi,
 * at mu = (f - a) / tau (the tail has a kink in its second derivative there); tau_lo < tau_hi puts
 * the two cuts in order. */
static double cell_sheet(const cell_context *k, double m0, double m1)
{
    double cut[4] = {m0, m1, m1, m1};
    int n = 1;
    const double floor_gap = (double)FLOOR - k->a; /* < 0: the states start above the floor */
    const double ends[2] = {floor_gap / k->tau_lo, floor_gap / k->tau_hi}; /* -inf at tau 0, -0 at tau inf */
    for (int e = 0; e < 2; ++e)
        if (ends[e] > m0 && ends[e] < m1) cut[n++] = ends[e];
    cut[n] = m1;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) sum += stats_gl_panel(cell_integrand, (void *)k, cut[i], cut[i + 1]);
    return sum;
}

static double bin_integral(stats_function f, void *context, double m0, double m1)
{
    /* HG is smooth but peaked for larger g: four panels per bin */
    double sum = 0.0;
    for (int i = 0; i < 4; ++i) sum += stats_gl_panel(f, context, m0 + (m1 - m0) * i / 4.0, m0 + (m1 - m0) * (i + 1) / 4.0);
    return sum;
}

/* One step from the state: walk `index` begun anew (its own key). Returns the cosine of the step's
 * direction to the lit normal and its optical flight. */
static void state_step(const sample_state *st, const dwvw_medium *medium, const dwvw_guide *guide, uint64_t index,
                       double *mu, double *tau)
{
    const dwvu_vec3 origin = {0.0, 0.0, 0.0}, outward = {0.0, 0.0, -1.0};
    double c = st->entry_cosine;
    dwvu_vec3 direction = dwvu_v(sqrt((1.0 - c) * (1.0 + c)), 0.0, c);
    dwvw_walk walk;
    dwvw_walk_begin(&walk, medium, guide, dwvk_rng_key(SEED, 3u, index), 1000000u, origin, direction, outward);
    if (!st->first_step) {
        /* a first scattering event at the chosen distance, along the lit normal (entry_cosine 1) */
        dwvw_walk_sample(&walk);
        walk.step_distance = st->optical_height / medium->sigma_t[0];
        walk.weight[0] = START_WEIGHT;
        dwvw_walk_complete(&walk, INFINITY, dwvu_v(0.0, 0.0, 1.0));
    }
    double d = dwvw_walk_sample(&walk);
    *mu = walk.direction.z;
    *tau = d * medium->sigma_t[0];
}

static void test_sampling_state(const sample_state *st)
{
    const double sigma = SAMPLE_SIGMA, albedo = 0.99;
    dwvw_medium medium;
    dwvw_medium_init(&medium, 1, &sigma, &albedo, st->g);
    dwvw_light_patch patch = {.point = dwvu_v(0.0, 0.0, 1.25), .normal = dwvu_v(0.0, 0.0, 1.0), .power = 1.0,
                              .is_plane = 1};
    dwvw_guide guide;
    dwvw_guide_init(&guide, DWVW_SHEET, &medium, &patch, 1);
    const double q_classical = fmax(0.01, fabs(st->g)), q_sheet = 1.0 - q_classical;
    const double a = st->first_step ? DWVK_SHEET_EXTRAPOLATION : st->optical_height + DWVK_SHEET_EXTRAPOLATION;
    double up, down;
    dwvk_sheet_slopes(a, &up, &down);

    /* the state reached as intended */
    {
        const dwvu_vec3 origin = {0.0, 0.0, 0.0}, outward = {0.0, 0.0, -1.0};
        double c = st->entry_cosine;
        dwvw_walk walk;
        dwvw_walk_begin(&walk, &medium, &guide, 1u, 1000000u, origin, dwvu_v(sqrt((1.0 - c) * (1.0 + c)), 0.0, c),
                        outward);
        if (!st->first_step) {
            dwvw_walk_sample(&walk);
            walk.step_distance = st->optical_height / sigma;
            walk.weight[0] = START_WEIGHT;
            dwvw_status status = dwvw_walk_complete(&walk, INFINITY, dwvu_v(0.0, 0.0, 1.0));
            CHECK(status == DWVW_RUNNING && walk.events == 1u &&
                      fabs(walk.position.z - st->optical_height / sigma) <= 1e-15 &&
                      walk.position.x == 0.0 && walk.position.y == 0.0,
                  "%s: the state was not reached (status %d, events %u, z %g)", st->name, (int)status, walk.events,
                  walk.position.z);
        }
    }

    static double cosines[STEP_SAMPLES], flights[STEP_SAMPLES];
    for (uint64_t i = 0; i < STEP_SAMPLES; ++i) state_step(st, &medium, &guide, i, &cosines[i], &flights[i]);

    /* tau edges: the exponential's quantiles */
    double tau_edges[GRID + 1];
    for (int k = 0; k <= GRID; ++k) tau_edges[k] = k == GRID ? INFINITY : -log(1.0 - (double)k / GRID);

    if (st->first_step) {
        /* the flight along the entry direction: classical and sheet at mu = entry cosine */
        double observed[GRID] = {0}, expected[GRID], planted[GRID];
        int outside = 0;
        for (uint64_t i = 0; i < STEP_SAMPLES; ++i) {
            int k = stats_bin(tau_edges, GRID, flights[i]);
            if (k < 0 && flights[i] == INFINITY) k = GRID - 1;
            if (k < 0) ++outside;
            else observed[k] += 1.0;
        }
        for (int k = 0; k < GRID; ++k) {
            double lo = tau_edges[k], hi = tau_edges[k + 1];
            double cl = exp(-lo) - (isinf(hi) ? 0.0 : exp(-hi));
            double mu = st->entry_cosine;
            double sh = (double)(ref_flight_tail(a, mu, lo) - ref_flight_tail(a, mu, hi));
            double sh_planted = (double)(ref_flight_tail(1.15 * a, mu, lo) - ref_flight_tail(1.15 * a, mu, hi));
            expected[k] = STEP_SAMPLES * (q_classical * cl + q_sheet * sh);
            planted[k] = STEP_SAMPLES * (q_classical * cl + q_sheet * sh_planted);
        }
        stats_chi_square_t r = stats_chi_square(observed, expected, GRID);
        stats_chi_square_t rp = stats_chi_square(observed, planted, GRID);
        printf("2. %s (a %.4f, mu %.2f): first step's flight chi2 %.1f dof %d p %.3g; planted a +15%% p %.3g\n", st->name,
               a, st->entry_cosine, r.x2, r.dof, r.p, rp.p);
        CHECK(outside == 0, "%s: %d flights outside [0, inf]", st->name, outside);
        CHECK(r.p > STATS_P_REJECT, "%s: the first step's flight does not follow its pdf (p %.3g)", st->name, r.p);
        CHECK(rp.p < STATS_P_REJECT, "%s: a planted 15%% change of a was not caught (p %.3g)", st->name, rp.p);
        return;
    }

    /* the cosine to the lit normal */
    double edges[COSINE_BINS + 1];
    for (int k = 0; k <= COSINE_BINS; ++k) edges[k] = -1.0 + 2.0 * k / COSINE_BINS;
    double observed[COSINE_BINS] = {0}, expected[COSINE_BINS], planted[COSINE_BINS];
    int outside = 0;
    for (uint64_t i = 0; i < STEP_SAMPLES; ++i) {
        int k = stats_bin(edges, COSINE_BINS, cosines[i]);
        if (k < 0) ++outside;
        else observed[k] += 1.0;
    }
    double total = 0.0;
    for (int k = 0; k < COSINE_BINS; ++k) {
        cosine_context cl = {st->g, a, 1.0, 0}, sh = {st->g, a, 1.0, 1}, shp = {st->g, a, 1.10, 1};
        double p_cl = bin_integral(cosine_integrand, &cl, edges[k], edges[k + 1]);
        double p_sh = stats_gl_panel(cosine_integrand, &sh, edges[k], edges[k + 1]);
        double p_shp = stats_gl_panel(cosine_integrand, &shp, edges[k], edges[k + 1]);
        expected[k] = STEP_SAMPLES * (q_classical * p_cl + q_sheet * p_sh);
        planted[k] = STEP_SAMPLES * (q_classical * p_cl + q_sheet * p_shp);
        total += expected[k];
    }
    CHECK(fabs(total / STEP_SAMPLES - 1.0) < 1e-9, "%s: the cosine's bin probabilities sum to %.12f", st->name,
          total / STEP_SAMPLES);
    stats_chi_square_t r = stats_chi_square(observed, expected, COSINE_BINS);
    stats_chi_square_t rp = stats_chi_square(observed, planted, COSINE_BINS);

    /* the joint (cosine, optical flight) on a GRID x GRID grid */
    double mu_edges[GRID + 1];
    for (int k = 0; k <= GRID; ++k) mu_edges[k] = -1.0 + 2.0 * k / GRID;
    double joint_o[GRID * GRID] = {0}, joint_e[GRID * GRID], joint_p[GRID * GRID];
    int joint_outside = 0;
    for (uint64_t i = 0; i < STEP_SAMPLES; ++i) {
        int km = stats_bin(mu_edges, GRID, cosines[i]), kt = stats_bin(tau_edges, GRID, flights[i]);
        if (kt < 0 && flights[i] == INFINITY) kt = GRID - 1;
        if (km < 0 || kt < 0) ++joint_outside;
        else joint_o[km * GRID + kt] += 1.0;
    }
    double joint_total = 0.0;
    for (int km = 0; km < GRID; ++km) {
        cosine_context cl = {st->g, a, 1.0, 0};
        double p_cl = bin_integral(cosine_integrand, &cl, mu_edges[km], mu_edges[km + 1]);
        for (int kt = 0; kt < GRID; ++kt) {
            double lo = tau_edges[kt], hi = tau_edges[kt + 1];
            double cl_flight = exp(-lo) - (isinf(hi) ? 0.0 : exp(-hi));
            cell_context honest = {a, a, lo, hi}, wrong = {1.15 * a, a, lo, hi};
            double sh = cell_sheet(&honest, mu_edges[km], mu_edges[km + 1]);
            double shp = cell_sheet(&wrong, mu_edges[km], mu_edges[km + 1]);
            joint_e[km * GRID + kt] = STEP_SAMPLES * (q_classical * p_cl * cl_flight + q_sheet * sh);
            joint_p[km * GRID + kt] = STEP_SAMPLES * (q_classical * p_cl * cl_flight + q_sheet * shp);
            joint_total += joint_e[km * GRID + kt];
        }
    }
    CHECK(fabs(joint_total / STEP_SAMPLES - 1.0) < 1e-9, "%s: the joint's cell probabilities sum to %.12f", st->name,
          joint_total / STEP_SAMPLES);
    stats_chi_square_t j = stats_chi_square(joint_o, joint_e, GRID * GRID);
    stats_chi_square_t jp = stats_chi_square(joint_o, joint_p, GRID * GRID);
    printf("2. %s (a %.4f, slopes %.4f %.4f, q_cl %.2f): cosine chi2 %.1f dof %d p %.3g (planted slopes +10%% p %.3g); "
           "joint (cosine, flight) chi2 %.1f dof %d p %.3g (planted a +15%% p %.3g)\n",
           st->name, a, up, down, q_classical, r.x2, r.dof, r.p, rp.p, j.x2, j.dof, j.p, jp.p);
    CHECK(outside == 0 && joint_outside == 0, "%s: %d cosines, %d (cosine, flight) pairs outside their range", st->name,
          outside, joint_outside);
    CHECK(r.p > STATS_P_REJECT, "%s: the cosine does not follow its pdf (p %.3g)", st->name, r.p);
    CHECK(rp.p < STATS_P_REJECT, "%s: a planted 10%% change of the slopes was not caught (p %.3g)", st->name, rp.p);
    CHECK(j.p > STATS_P_REJECT, "%s: the (cosine, flight) pairs do not follow their pdf (p %.3g)", st->name, j.p);
    CHECK(jp.p < STATS_P_REJECT, "%s: a planted 15%% change of a was not caught (p %.3g)", st->name, jp.p);
}

static void test_sampling(void)
{
    static const sample_state states[] = {
        {"isotropic, at the entry height", 0.0, 0.0, 1.0, 0},
        {"isotropic, 1.3 mfp up", 0.0, 1.3, 1.0, 0},
        {"g 0.5, 0.6 mfp up", 0.5, 0.6, 1.0, 0},
        {"isotropic, first step", 0.0, 0.0, 0.6, 1},
    };
    for (size_t i = 0; i < sizeof states / sizeof states[0]; ++i) test_sampling_state(&states[i]);
}

/* ==== 3. the lit-side rule ====================================================================== */

/* Two walks of the same key, one with each guide, stepped together in the slab; 1 if they agree bit
 * for bit at every step. */
static int walks_agree(const dwvw_medium *medium, const dwvw_guide *a, const dwvw_guide *b, const dwvw_shape *slab,
                       uint64_t key, dwvu_vec3 direction, dwvu_vec3 normal, uint32_t *steps)
{
    const dwvu_vec3 origin = {0.0, 0.0, 0.0};
    dwvw_walk wa, wb;
    dwvw_walk_begin(&wa, medium, a, key, 100000u, origin, direction, normal);
    dwvw_walk_begin(&wb, medium, b, key, 100000u, origin, direction, normal);
    int same = 1;
    while (same && wa.status == DWVW_RUNNING && wb.status == DWVW_RUNNING) {
        double da = dwvw_walk_sample(&wa), db = dwvw_walk_sample(&wb);
        same &= memcmp(&da, &db, sizeof da) == 0 && same_vec(wa.direction, wb.direction);
        dwvu_vec3 na, nb;
        double ha = dwvw_shape_exit(slab, wa.position, wa.direction, &na);
        double hb = dwvw_shape_exit(slab, wb.position, wb.direction, &nb);
        dwvw_walk_complete(&wa, ha, na);
        dwvw_walk_complete(&wb, hb, nb);
        same &= same_vec(wa.position, wb.position) && memcmp(wa.weight, wb.weight, sizeof wa.weight) == 0 &&
                wa.status == wb.status && wa.events == wb.events;
        ++*steps;
    }
    return same && wa.status == wb.status && same_vec(wa.exit_normal, wb.exit_normal);
}

static void test_lit_side(void)
{
    const dwvw_shape slab = {DWVW_SLAB, SLAB_MFP, 0.0};
    const double grey_sigma = 1.0, grey_albedo = 0.99;
    const double rgb_sigma[3] = {1.0, 1.6, 2.5}, rgb_albedo[3] = {0.97, 0.999, 0.9};
    struct {
        const char *name;
        int channels;
        const double *sigma, *albedo;
        double g;
        dwvu_vec3 lit;    /* the lit patch's normal */
        dwvu_vec3 entry;  /* the entry's outward normal */
    } cases[] = {
        {"grey g 0, front-lit", 1, &grey_sigma, &grey_albedo, 0.0, {0.0, 0.0, -1.0}, {0.0, 0.0, -1.0}},
        {"grey g -0.4, front-lit", 1, &grey_sigma, &grey_albedo, -0.4, {0.0, 0.0, -1.0}, {0.0, 0.0, -1.0}},
        {"rgb g 0.3, front-lit", 3, rgb_sigma, rgb_albedo, 0.3, {0.0, 0.0, -1.0}, {0.0, 0.0, -1.0}},
        {"rgb g 0, lit normal at 89 degrees", 3, rgb_sigma, rgb_albedo, 0.0, {0.99984769515639, 0.0, -0.01745240643728},
         {0.0, 0.0, -1.0}},
    };
    int all_same = 1, walks = 0;
    uint32_t steps = 0;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        dwvw_medium medium;
        dwvw_medium_init(&medium, cases[i].channels, cases[i].sigma, cases[i].albedo, cases[i].g);
        dwvw_light_patch patch = {.point = dwvu_v(0.0, 0.0, 0.0), .normal = cases[i].lit, .power = 1.0, .is_plane = 1};
        dwvw_guide sheet, classical;
        dwvw_guide_init(&sheet, DWVW_SHEET, &medium, &patch, 1);
        dwvw_guide_init(&classical, DWVW_CLASSICAL, &medium, &patch, 1);
        CHECK(sheet.q_sheet > 0.0 && dwvu_dot(cases[i].entry, sheet.sheet_normal) > 0.0, "%s: not a lit-side entry",
              cases[i].name);
        int same = 0;
        for (uint64_t k = 0; k < 128; ++k) {
            uint64_t key = dwvk_rng_key(SEED, 4u + i, k);
            uint32_t dim = 0;
            dwvu_vec3 direction = k % 2 ? random_unit(key, &dim) : dwvu_v(0.0, 0.0, 1.0);
            if (direction.z < 0.0) direction.z = -direction.z;
            same += walks_agree(&medium, &sheet, &classical, &slab, dwvk_rng_key(SEED, 8u + i, k), direction,
                                cases[i].entry, &steps);
        }
        CHECK(same == 128, "%s: %d of 128 sheet walks entering on the lit side are the classical walk", cases[i].name,
              same);
        all_same &= same == 128;
        walks += 128;
    }

    /* control: entering on the far side the sheet acts, and the walks differ */
    int differ = 0;
    {
        dwvw_medium medium;
        dwvw_medium_init(&medium, 1, &grey_sigma, &grey_albedo, 0.0);
        dwvw_light_patch patch = {.point = dwvu_v(0.0, 0.0, SLAB_MFP), .normal = dwvu_v(0.0, 0.0, 1.0), .power = 1.0,
                                  .is_plane = 1};
        dwvw_guide sheet, classical;
        dwvw_guide_init(&sheet, DWVW_SHEET, &medium, &patch, 1);
        dwvw_guide_init(&classical, DWVW_CLASSICAL, &medium, &patch, 1);
        for (uint64_t k = 0; k < 128; ++k)
            differ += !walks_agree(&medium, &sheet, &classical, &slab, dwvk_rng_key(SEED, 12u, k), dwvu_v(0.0, 0.0, 1.0),
                                   dwvu_v(0.0, 0.0, -1.0), &steps);
    }
    CHECK(differ > 120, "control: only %d of 128 far-side sheet walks differ from classical ones", differ);

    /* the estimator, every walk through dwvw_walk_*: front-lit, the sheet's totals are classical's */
    dwvw_estimate_setup setup;
    memset(&setup, 0, sizeof setup);
    setup.shape = slab;
    dwvw_medium_init(&setup.medium, 3, rgb_sigma, rgb_albedo, 0.2);
    setup.incidence_diffuse = 1;
    setup.light = DWVW_LIGHT_FRONT;
    setup.walks = 20000u;
    setup.seed = SEED + 1u;
    setup.threads = THREADS;
    setup.max_events = 100000u;
    setup.general_path = 1;
    dwvw_light_patch patches[2];
    int count = dwvw_estimate_light_patches(&setup.shape, DWVW_LIGHT_FRONT, patches);
    dwvw_estimate_setup classical_setup = setup;
    dwvw_guide_init(&setup.guide, DWVW_SHEET, &setup.medium, patches, count);
    dwvw_guide_init(&classical_setup.guide, DWVW_CLASSICAL, &classical_setup.medium, patches, count);
    dwvw_estimate_totals ts, tc;
    int rs = dwvw_estimate_run(&setup, &ts), rc = dwvw_estimate_run(&classical_setup, &tc);
    int totals_same = rs == 0 && rc == 0 && ts.events == tc.events &&
                      memcmp(ts.sum, tc.sum, sizeof ts.sum) == 0 && memcmp(ts.m2, tc.m2, sizeof ts.m2) == 0;
    CHECK(setup.guide.q_sheet > 0.0, "front-lit slab: the sheet guide has no sheet share");
    CHECK(totals_same, "front-lit slab: sheet totals (%g %g %g, %llu events) differ from classical's (%g %g %g, %llu)",
          ts.sum[0], ts.sum[1], ts.sum[2], (unsigned long long)ts.events, tc.sum[0], tc.sum[1], tc.sum[2],
          (unsigned long long)tc.events);
    printf("3. lit-side rule: %d walks (%u steps) entering on the lit side equal classical walks bit for bit: %s; "
           "far-side control: %d of 128 differ; estimator front-lit slab (RGB, %llu walks): totals equal: %s\n",
           walks, steps, all_same ? "yes" : "NO", differ, (unsigned long long)setup.walks,
           totals_same ? "yes" : "NO");
}

/* ==== 4. means ================================================================================== */

typedef struct run_result {
    double mean[3], se[3], variance[3], events_per_walk, seconds;
} run_result;

static run_result run(const dwvw_estimate_setup *setup)
{
    dwvw_estimate_totals totals;
    run_result r;
    memset(&r, 0, sizeof r);
    int rc = dwvw_estimate_run(setup, &totals);
    CHECK(rc == 0, "dwvw_estimate_run failed");
    CHECK(totals.truncated_walks == 0, "%llu walks truncated", (unsigned long long)totals.truncated_walks);
    double n = (double)setup->walks;
    for (int c = 0; c < setup->medium.channels; ++c) {
        r.mean[c] = totals.sum[c] / n;
        r.variance[c] = totals.m2[c] / (n - 1.0);
        r.se[c] = sqrt(r.variance[c] / n);
    }
    r.events_per_walk = (double)totals.events / n;
    r.seconds = totals.seconds;
    return r;
}

static void test_means_case(const char *name, int channels, const double *sigma, const double *albedo, int check_variance,
                            uint64_t seed)
{
    dwvw_estimate_setup setup;
    memset(&setup, 0, sizeof setup);
    setup.shape = (dwvw_shape){DWVW_SLAB, SLAB_MFP / sigma[0], 0.0};
    dwvw_medium_init(&setup.medium, channels, sigma, albedo, 0.0);
    setup.incidence_diffuse = 1; /* cosine-weighted, as light through a rough face */
    setup.light = DWVW_LIGHT_BACK;
    setup.walks = SLAB_WALKS;
    setup.threads = THREADS;
    setup.max_events = 1000000u;
    dwvw_light_patch patches[2];
    int count = dwvw_estimate_light_patches(&setup.shape, DWVW_LIGHT_BACK, patches);
    dwvw_estimate_setup classical = setup;
    dwvw_guide_init(&setup.guide, DWVW_SHEET, &setup.medium, patches, count);
    dwvw_guide_init(&classical.guide, DWVW_CLASSICAL, &classical.medium, patches, count);
    setup.seed = seed;
    classical.seed = seed + 1u;
    run_result s = run(&setup), c = run(&classical);
    for (int k = 0; k < channels; ++k) {
        double combined = sqrt(s.se[k] * s.se[k] + c.se[k] * c.se[k]);
        double z = (s.mean[k] - c.mean[k]) / combined;
        double planted = (s.mean[k] * (1.0 + PLANTED_BIAS) - c.mean[k]) /
                         sqrt(s.se[k] * s.se[k] * (1.0 + PLANTED_BIAS) * (1.0 + PLANTED_BIAS) + c.se[k] * c.se[k]);
        double ratio = s.variance[k] / c.variance[k];
        printf("4. %s%s%s: sheet %.6f +- %.2e, classical %.6f +- %.2e, z %+.2f (planted %+.0f%%: z %+.1f); variance "
               "per walk %.4g vs %.4g (ratio %.3f); events per walk %.2f vs %.2f; %.2f s vs %.2f s\n",
               name, channels > 1 ? " channel " : "", channels > 1 ? (k == 0 ? "0" : k == 1 ? "1" : "2") : "",
               s.mean[k], s.se[k], c.mean[k], c.se[k], z, 100.0 * PLANTED_BIAS, planted, s.variance[k], c.variance[k],
               ratio, s.events_per_walk, c.events_per_walk, s.seconds, c.seconds);
        CHECK(fabs(z) <= SIGMAS, "%s channel %d: sheet %.6f +- %.2e and classical %.6f +- %.2e differ by %.2f sigma",
              name, k, s.mean[k], s.se[k], c.mean[k], c.se[k], z);
        CHECK(fabs(planted) > SIGMAS, "%s channel %d: a %.0f%% bias was not resolved (z %.2f)", name, k,
              100.0 * PLANTED_BIAS, planted);
        if (check_variance)
            CHECK(ratio < VARIANCE_RATIO_BOUND, "%s: the sheet's variance per walk is %.3f of classical's (bound %.2f)",
                  name, ratio, VARIANCE_RATIO_BOUND);
    }
}

static void test_means(void)
{
    const double sigma = 1.0;
    const double albedos[] = {0.9995, 0.95, 0.85};
    for (int i = 0; i < 3; ++i) {
        char name[64];
        snprintf(name, sizeof name, "back-lit slab %.1f mfp, albedo %g", SLAB_MFP, albedos[i]);
        test_means_case(name, 1, &sigma, &albedos[i], i == 0, SEED + 100u + 2u * (uint64_t)i);
    }
    const double rgb_sigma[3] = {1.0, 1.3, 1.8}, rgb_albedo[3] = {0.99, 0.999, 0.95};
    test_means_case("back-lit slab, RGB sigma 1 1.3 1.8", 3, rgb_sigma, rgb_albedo, 0, SEED + 200u);
}

int main(void)
{
    test_weight_update();
    test_roulette();
    test_sampling();
    test_lit_side();
    test_means();
    return check_report("test_walk_sheet");
}
