/* What the estimator's walkers share: estimate.c chooses the walker and drives the runs,
 * estimate_fast.c walks one walk at a time on the fast paths, estimate_lanes.c several in
 * lock-step. The entry of a walk, the fast paths' plan, the guided walker's pieces in the log
 * domain, and the blocks the walks are summed in. Internal to src/walk. */
#ifndef DWV_WALK_ESTIMATE_WALKERS_H
#define DWV_WALK_ESTIMATE_WALKERS_H

#include <math.h>
#include <stdatomic.h>
#include <stdint.h>

#include "estimate.h"
#include "kernel/fastmath.h"
#include "kernel/rng.h"
#include "step.h"

/* Every analytic shape is entered at the origin, its outward normal there -z (geometry.h). */
static const dwvu_vec3 DWVW_ENTRY_POINT = {0.0, 0.0, 0.0}, DWVW_ENTRY_NORMAL = {0.0, 0.0, -1.0};

/* The entry direction of a walk: dimensions 0 and 1 of its key. */
static inline dwvu_vec3 dwvw_entry_direction(const dwvw_estimate_setup *setup, uint64_t key)
{
    if (setup->incidence_diffuse) {
        /* Cosine-weighted: mu = sqrt(u). */
        double u = dwvk_rng_uniform_d(key, 0), mu = sqrt(u);
        return dwvk_direction_about(dwvu_v(0.0, 0.0, 1.0), mu, 1.0 - mu, 1.0 + mu, dwvk_rng_uniform_d(key, 1));
    }
    double mu = setup->incidence_cosine;
    return dwvu_v(sqrt((1.0 - mu) * (1.0 + mu)), 0.0, mu);
}

/* What a run's fast path needs, worked out once per run. */
typedef struct dwvw_fast_plan {
    dwvw_walker walker;
    dwvu_vec3 axis;          /* guided: the fixed axis */
    dwvu_frame turned[4];    /* its frame and the frame's quarter turns */
    /* Where the turned frames are signed permutations (an axis along x, y or z: every axis of the
     * analytic shapes), component i of a direction is sign[q][i] x (c, d, mu)[index[q][i]], and
     * the cosine to the axis is axis_sign x direction[axis_index]: the same values as the full
     * products, whose other terms are exact zeros. */
    int aligned;
    int index[4][3];
    double sign[4][3];
    int axis_index;
    double axis_sign;
    double log_per_event;    /* log(alpha / a) */
    double inv_albedo_eff;   /* 1 / a */
    int first_known;         /* the entry direction is the same for every walk: */
    double log_first;        /*   log(alpha / s0), s0 its stretch */
    double q_guided;         /* mixture: the guided component's weight (the rest is classical) */
    int lanes;               /* guided and aligned: runs in lock-step lanes (lanes_run) */
} dwvw_fast_plan;

/* Component i (0, 1, 2: x, y, z) of v. */
static inline double dwvw_vec3_component(dwvu_vec3 v, int i)
{
    return i == 0 ? v.x : i == 1 ? v.y : v.z;
}

/* dwvw_cosine(direction, plan->axis) for an aligned plan. */
static inline double dwvw_aligned_cosine(const dwvw_fast_plan *plan, dwvu_vec3 direction)
{
    return dwvw_clamp_cosine(plan->axis_sign * dwvw_vec3_component(direction, plan->axis_index));
}

/* ---- the guided walker's weight, in logs (estimate_fast.c, "the fast paths") ---------------- */

/* The Russian roulette of dwvw_walk_complete (dwvw_roulette_survives) on a weight
 * exp(log_weight) after `events` events: 0 if the walk ends (absorbed), 1 if it goes on
 * unchanged, 2 if it goes on with its weight raised to the threshold (*log_weight = its log). */
static inline int dwvw_guided_roulette(uint64_t key, uint32_t events, double *log_weight)
{
    if (!(*log_weight < DWVW_LOG_ROULETTE_THRESHOLD)) return 1;
    double weight = dwvk_exp_fast(*log_weight), survive;
    if (!(weight > 0.0) || !dwvw_roulette_survives(key, events, weight, &survive)) return 0;
    *log_weight = DWVW_LOG_ROULETTE_THRESHOLD; /* log(weight / survive) */
    return 2;
}

/* A guided walk's weight is exp(log constants - sigma x exponent) with exponent the sum over its
 * steps of (1 - s) t (estimate_fast.c, "the fast paths"): the exponent after a step of stretch s
 * and length t, the log weight, and the log constants that give a log weight the roulette set. */
static inline double dwvw_guided_exponent(double exponent, double stretch, double length)
{
    return exponent + (1.0 - stretch) * length;
}

static inline double dwvw_guided_log_weight(double log_constants, double sigma, double exponent)
{
    return log_constants - sigma * exponent;
}

static inline double dwvw_guided_constants_for(double log_weight, double sigma, double exponent)
{
    return log_weight + sigma * exponent;
}

/* The factor of a guided walk's exit step beyond the exponential: s / a, 1 if it leaves on the first
 * step (the entry direction's pdf is 1, and that step's constant is log(alpha / s0) only if it
 * scatters). */
static inline double dwvw_guided_exit_factor(const dwvw_fast_plan *plan, uint32_t events, double stretch)
{
    return events > 0 ? stretch * plan->inv_albedo_eff : 1.0;
}

/* A guided walk's end: weight exp(log weight) x its exit factor in its one channel (0 if it was
 * absorbed, or if the weight is not finite). The exponentials here and in dwvw_guided_roulette are
 * fastmath.h's (5e-16 relative, as the general walk's weights use): once per walk and per
 * roulette, libm's took 6% of the lanes' time for poe on the half-space. */
static inline void dwvw_guided_end(dwvw_walk_end *end, uint32_t events, double log_weight, double last_factor)
{
    double weight = end->status == DWVW_ABSORBED ? 0.0 : dwvk_exp_fast(log_weight) * last_factor;
    end->events = events;
    end->weight[0] = isfinite(weight) ? weight : 0.0;
    end->weight[1] = end->weight[2] = 0.0;
}

/* A classical or mixture walk's end: its weight in its one channel (0 if it was absorbed). */
static inline void dwvw_grey_end(dwvw_walk_end *end, uint32_t events, double weight)
{
    end->events = events;
    end->weight[0] = end->status == DWVW_ABSORBED ? 0.0 : weight;
    end->weight[1] = end->weight[2] = 0.0;
}

/* ---- the blocks a run's walks are summed in ------------------------------------------------ */

/* What an exit with outward normal n scores: 1 through a lit face of a half-space or slab, the
 * cosine to the light on a sphere (the irradiance a lit hemisphere receives there). */
static inline double dwvw_exit_score(const dwvw_estimate_setup *setup, dwvu_vec3 n)
{
    double score = 0.0;
    if (setup->shape.kind == DWVW_SPHERE) {
        if (setup->light & DWVW_LIGHT_FRONT) score += fmax(0.0, -n.z);
        if (setup->light & DWVW_LIGHT_BACK) score += fmax(0.0, n.z);
    } else {
        if ((setup->light & DWVW_LIGHT_FRONT) && n.z < 0.0) score += 1.0;
        if ((setup->light & DWVW_LIGHT_BACK) && n.z > 0.0) score += 1.0;
    }
    return score;
}

typedef struct dwvw_block_totals {
    double sum[DWVW_MAX_CHANNELS], sum_squares[DWVW_MAX_CHANNELS], truncated_weight[DWVW_MAX_CHANNELS];
    double m2[DWVW_MAX_CHANNELS]; /* squared deviations from the block's mean (Welford) */
    uint64_t events, truncated_walks, walks;
} dwvw_block_totals;

/* Adds a walk's end to its block. */
static inline void dwvw_block_add_walk(const dwvw_estimate_setup *setup, const dwvw_walk_end *end,
                                       dwvw_block_totals *out)
{
    out->events += end->events;
    double score = end->status == DWVW_EXITED ? dwvw_exit_score(setup, end->exit_normal) : 0.0;
    for (int c = 0; c < setup->medium.channels; ++c) {
        if (end->status == DWVW_TRUNCATED) out->truncated_weight[c] += end->weight[c];
        double x = end->weight[c] * score;
        /* Welford (Knuth TAOCP 2, 4.2.2): m2 += k/(k+1) (x - mean of the k before)^2. The variance
         * as sum_squares - n mean^2 cancels when scores agree to 8 digits (all near 1 in a thin
         * slab at albedo ~1): it came out 0 where it was ~1e-18 and the standard error was 0. */
        if (out->walks > 0) {
            double k = (double)out->walks, deviation = x - out->sum[c] / k;
            out->m2[c] += deviation * deviation * (k / (k + 1.0));
        }
        out->sum[c] += x;
        out->sum_squares[c] += x * x;
    }
    ++out->walks;
    if (end->status == DWVW_TRUNCATED) ++out->truncated_walks;
}

typedef struct dwvw_estimate_run_state {
    const dwvw_estimate_setup *setup;
    uint64_t block_size;
    uint32_t block_count;
    dwvw_fast_plan plan;
    atomic_uint next_block;
    dwvw_block_totals *blocks;
} dwvw_estimate_run_state;

/* Walk `key` by the plan's fast walker (classical, guided or mixture; estimate_fast.c). */
void dwvw_fast_walk(const dwvw_estimate_setup *setup, const dwvw_fast_plan *plan, uint64_t key, dwvw_walk_end *end);
/* A thread's share of a run in lock-step lanes: blocks claimed from `state` until none is left,
 * each block's walks added in walk order (estimate_lanes.c). */
void dwvw_lanes_run_blocks(dwvw_estimate_run_state *state);
/* Walks first .. first + count - 1 in lock-step lanes, their ends into ends[0 .. count - 1]. */
void dwvw_lanes_run_range(const dwvw_estimate_setup *setup, const dwvw_fast_plan *plan, uint64_t first,
                          uint64_t count, dwvw_walk_end *ends);

#endif
