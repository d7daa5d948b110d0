/* The per-event weight update of a coloured walk (dwvw_walk_complete, src/walk/walk.c) against its
 * formula written out directly in long double:
 *
 *   weight_c' *= f_c' exp(-sigma_c' t) / sum_k Q_k p_k sum_c P_c pdist_{k,c}(t),
 *   pdist_{k,c}(t) = sigma_c s_k exp(-sigma_c s_k t) (a scattering event at t) or exp(-sigma_c s_k t)
 *   (leaving through the surface at t); f_c' = phase sigma_c' alpha_c' (event) or phase (exit).
 *
 * The walk factors the exponentials (one shared sum, one factor per channel) so that nothing
 * overflows; long double's range (exponents to -11000) lets the direct form be evaluated as is,
 * also on stiff steps (sigma t of hundreds) where doubles would underflow. Random states: 1 to
 * DWVW_MAX_COMPONENTS components, stretches of Dwivedi sampling's range, channels with P = 0,
 * channels of equal extinction, and one component alone (the walk's single-component path).
 * A planted change (one sigma 1e-6 off in the direct form) must be caught by the same bound. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "kernel/rng.h"
#include "walk/walk.h"

#define CASES 20000
#define RELATIVE_TOLERANCE 1e-11
#define START_WEIGHT 1e120 /* far above the roulette threshold, whatever the ratio */

typedef struct step_case {
    dwvw_medium medium;
    dwvw_guide guide;
    dwvw_walk walk;
    double t;
    int exited;
} step_case;

static double uniform(uint64_t key, uint32_t *dim)
{
    return dwvk_rng_uniform_d(key, (*dim)++);
}

static void make_case(uint64_t index, step_case *s)
{
    uint64_t key = dwvk_rng_key(0x77e16u, 0u, index);
    uint32_t dim = 0;
    double sigma[3], albedo[3];
    /* extinctions over 3 decades, so channels differ a lot (stiff for the direct form) */
    for (int c = 0; c < 3; ++c) {
        sigma[c] = pow(10.0, 3.0 * uniform(key, &dim) - 1.0);
        albedo[c] = uniform(key, &dim);
    }
    /* now and then equal extinctions in some channels (a leaf: grey extinction, coloured albedo),
     * whose exponentials the walk shares */
    double shape = uniform(key, &dim);
    if (shape < 0.15) sigma[1] = sigma[2] = sigma[0];
    else if (shape < 0.25) sigma[2] = sigma[1];
    else if (shape < 0.3) sigma[2] = sigma[0];
    memset(s, 0, sizeof *s);
    dwvw_medium_init(&s->medium, 3, sigma, albedo, 0.0);
    s->guide.q_classical = 1.0; /* q_backward = 0: no first-step probe */
    dwvw_walk *w = &s->walk;
    w->medium = &s->medium;
    w->guide = &s->guide;
    w->key = key;
    w->max_events = 1000000u;
    w->events = 1u;
    w->status = DWVW_RUNNING;
    w->direction = dwvu_v(0.0, 0.0, 1.0);
    w->component_count = 1 + (int)(uniform(key, &dim) * DWVW_MAX_COMPONENTS);
    if (w->component_count > DWVW_MAX_COMPONENTS) w->component_count = DWVW_MAX_COMPONENTS;
    w->single_component = -1;
    for (int k = 0; k < w->component_count; ++k) {
        /* a component with Q = 0 now and then, as techniques that leave one out */
        w->component_q[k] = uniform(key, &dim) < 0.1 ? 0.0 : uniform(key, &dim);
        w->component_pdf[k] = 0.01 + uniform(key, &dim);
        /* Dwivedi stretches 1 / (1 - mu / v0) lie in [1 / (1 + 1/v0), 1 / (1 - 1/v0)] */
        w->component_stretch[k] = k == 0 ? 1.0 : 0.05 + 4.0 * uniform(key, &dim);
    }
    w->component_q[0] = 0.05 + uniform(key, &dim); /* at least one component with Q > 0 */
    if (uniform(key, &dim) < 0.4) {
        /* one component alone (classical, or one guided axis), as dwvw_walk_sample marks it: the
         * walk's single-component path */
        int only = (int)(uniform(key, &dim) * w->component_count) % w->component_count;
        for (int k = 0; k < w->component_count; ++k) w->component_q[k] = k == only ? 0.05 + uniform(key, &dim) : 0.0;
        w->single_component = only;
    }
    for (int c = 0; c < 3; ++c) {
        w->channel_p[c] = uniform(key, &dim) < 0.1 ? 0.0 : uniform(key, &dim);
        w->weight[c] = START_WEIGHT;
    }
    w->channel_p[(int)(3.0 * uniform(key, &dim)) % 3] = 0.5;
    w->phase = 1.0 / (4.0 * 3.14159265358979323846);
    /* steps up to a few hundred mean free paths of the thinnest channel */
    s->t = -log(1.0 - uniform(key, &dim)) * pow(10.0, 2.5 * uniform(key, &dim) - 1.0) / s->medium.sigma_t[0];
    s->exited = uniform(key, &dim) < 0.3;
    w->step_distance = s->exited ? 2.0 * s->t : s->t;
}

/* The direct form; sigma_plant multiplies channel 1's extinction in the denominator (1: honest). */
static long double direct_ratio(const step_case *s, int cw, long double sigma_plant)
{
    const dwvw_walk *w = &s->walk;
    const dwvw_medium *m = &s->medium;
    long double t = s->t, denominator = 0.0L;
    for (int k = 0; k < w->component_count; ++k) {
        long double qp = (long double)w->component_q[k] * w->component_pdf[k];
        if (!(qp > 0.0L)) continue;
        for (int c = 0; c < 3; ++c) {
            if (!(w->channel_p[c] > 0.0)) continue;
            long double sigma = (long double)m->sigma_t[c] * w->component_stretch[k] * (c == 1 ? sigma_plant : 1.0L);
            long double pdist = (s->exited ? 1.0L : sigma) * expl(-sigma * t);
            denominator += qp * w->channel_p[c] * pdist;
        }
    }
    long double f = (long double)w->phase * (s->exited ? 1.0L : (long double)m->sigma_t[cw] * m->albedo[cw]);
    return f * expl(-(long double)m->sigma_t[cw] * t) / denominator;
}

static void test_weight_update(void)
{
    double worst = 0.0;
    int compared = 0, underflowed = 0, skipped = 0, planted_cases = 0, planted_caught = 0;
    for (uint64_t i = 0; i < CASES; ++i) {
        step_case s;
        make_case(i, &s);
        long double expected[3];
        long double largest = 0.0L;
        for (int c = 0; c < 3; ++c) {
            expected[c] = direct_ratio(&s, c, 1.0L);
            largest = fmaxl(largest, expected[c]);
        }
        /* Within double's range: ratios the walk can carry from START_WEIGHT without overflow and
         * without Russian roulette (largest weight above its threshold). Beyond, the walk sets a
         * weight whose ratio is not finite to 0, as the direct form in doubles would. */
        if (largest > 1e150L || largest * START_WEIGHT < 1.0L) {
            ++skipped;
            continue;
        }
        double hit = s.exited ? s.t : INFINITY;
        dwvw_status status = dwvw_walk_complete(&s.walk, hit, dwvu_v(0.0, 0.0, 1.0));
        CHECK(status == (s.exited ? DWVW_EXITED : DWVW_RUNNING), "case %llu: status %d", (unsigned long long)i,
              (int)status);
        double planted_error = 0.0;
        for (int c = 0; c < 3; ++c) {
            long double planted = direct_ratio(&s, c, 1.0L + 1e-6L);
            double got = s.walk.weight[c] / START_WEIGHT;
            CHECK(isfinite(got) && got >= 0.0, "case %llu channel %d: weight %g", (unsigned long long)i, c, got);
            /* Ratios below 1e-280 are at the edge of double's range for the walk's own factors
             * (exp of -700 and less): they must be tiny, not exact. */
            if (expected[c] < 1e-280L) {
                CHECK(got < 1e-250, "case %llu channel %d: %g where the ratio is %Lg", (unsigned long long)i, c, got,
                      expected[c]);
                ++underflowed;
                continue;
            }
            double error = (double)fabsl((long double)got / expected[c] - 1.0L);
            CHECK(error <= RELATIVE_TOLERANCE, "case %llu channel %d: ratio %.17g, direct form %.17Lg (t %g, %d components)",
                  (unsigned long long)i, c, got, expected[c], s.t, s.walk.component_count);
            worst = fmax(worst, error);
            planted_error = fmax(planted_error, (double)fabsl((long double)got / planted - 1.0L));
            ++compared;
        }
        /* the planted form differs only where channel 1 enters the denominator */
        if (s.walk.channel_p[1] > 0.0) {
            ++planted_cases;
            planted_caught += planted_error > RELATIVE_TOLERANCE;
        }
    }
    printf("weight update: %d ratios, worst relative difference %.2g from the direct form (%d far below "
           "double's range; %d states beyond it skipped); a 1e-6 change of one extinction caught in %d of %d cases\n",
           compared, worst, underflowed, skipped, planted_caught, planted_cases);
    CHECK(compared > CASES, "compared only %d ratios", compared);
    CHECK(planted_caught > planted_cases * 3 / 4, "a planted 1e-6 change caught in only %d of %d cases", planted_caught,
          planted_cases);
}

int main(void)
{
    test_weight_update();
    return check_report("test_walk_weight");
}
