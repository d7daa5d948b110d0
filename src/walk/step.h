/* The pieces of a walk's step, written once for every walker: the general engine (walk.c: one
 * step at a time, dwvw_walk_sample / dwvw_walk_complete, which the baker and the step-by-step API
 * drive) and the estimator's fast paths (estimate_fast.c) and lock-step lanes
 * (estimate_lanes.c). Those must make the same walks from the same random numbers, weight for
 * weight to the last bit (tests/internal/test_walk_fast_path.c), so they share these functions
 * rather than copies of them: each is the same operations in the same order wherever it is used.
 * Internal to src/walk. */
#ifndef DWV_WALK_STEP_H
#define DWV_WALK_STEP_H

#include <float.h>
#include <math.h>
#include <stdint.h>

#include "kernel/classical.h"
#include "kernel/direction.h"
#include "kernel/dwivedi_sampling.h"
#include "kernel/rng.h"
#include "util/vec3.h"
#include "walk.h"

/* For the walkers whose per-shape copies must be inlined whole (GCC and Clang otherwise judge a
 * lane step too large to inline three times). */
#if defined(__GNUC__)
#define DWVW_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define DWVW_ALWAYS_INLINE inline
#endif

/* ---- random numbers ------------------------------------------------------------------------- */

static inline uint32_t dwvw_event_dim(uint32_t events)
{
    return 2u + DWVW_DIMS_PER_EVENT * events;
}

/* The RNG counter (dwvk_rng_counter) moves by this from one event's dimension to the next
 * event's same dimension: walkers that step the counter by additions instead of hashing
 * key + dimension x gamma anew. */
#define DWVW_EVENT_COUNTER_STEP ((uint64_t)DWVW_DIMS_PER_EVENT * DWVK_GOLDEN_GAMMA)
/* ... and by this from an event's dimension `from` to its dimension `to` (>= from). */
#define DWVW_DIM_COUNTER_OFFSET(from, to) ((uint64_t)((to) - (from)) * DWVK_GOLDEN_GAMMA)

/* dwvk_rng_uniform_d, _f and _pair_f at a counter: the same bits. */
static inline double dwvw_counter_uniform_d(uint64_t counter)
{
    return (double)(dwvk_mix64(counter) >> 11) * 0x1.0p-53;
}

static inline float dwvw_counter_uniform_f(uint64_t counter)
{
    return dwvk_uniform_f_from_bits(dwvk_mix64(counter));
}

static inline dwvk_uniform_pair_f dwvw_counter_uniform_pair_f(uint64_t counter)
{
    return dwvk_uniform_pair_f_from_bits(dwvk_mix64(counter));
}

/* ---- directions ----------------------------------------------------------------------------- */

/* A classical direction: the cosine to `previous` from the phase function (isotropic at g = 0),
 * the azimuth uniform. u.a drives the cosine, u.b the azimuth. */
static inline dwvu_vec3 dwvw_classical_direction(dwvu_vec3 previous, float g, dwvk_uniform_pair_f u)
{
    float mu = g == 0.0f ? dwvk_isotropic_sample_f(u.a) : dwvk_hg_sample_f(g, u.a);
    float sin2 = (1.0f - mu) * (1.0f + mu);
    dwvu_frame frame = dwvu_frame_about(previous);
    return dwvk_frame_direction(&frame, mu, sqrtf(sin2 > 0.0f ? sin2 : 0.0f), dwvk_azimuth_f(u.b));
}

/* A guided direction about frame->n (Dwivedi's cosine distribution). */
static inline dwvu_vec3 dwvw_guided_direction(const dwvu_frame *frame, const dwvk_dwivedi_event_f *d,
                                              dwvk_uniform_pair_f u)
{
    dwvk_dwivedi_event_cosine_f s = dwvk_dwivedi_event_sample_f(d, u.a);
    return dwvk_frame_direction(frame, s.cos_theta, s.sin_theta, dwvk_azimuth_f(u.b));
}

/* The same about a fixed axis, with its frame's four quarter turns made in advance
 * (turned[q] = dwvu_frame_turned(frame, q)): bit for bit dwvw_guided_direction, without turning
 * the azimuth per event. */
static inline dwvu_vec3 dwvw_guided_direction_turned(const dwvu_frame turned[4], const dwvk_dwivedi_event_f *d,
                                                     dwvk_uniform_pair_f u)
{
    dwvk_dwivedi_event_cosine_f s = dwvk_dwivedi_event_sample_f(d, u.a);
    int32_t q;
    dwvk_unit2_f azimuth = dwvk_azimuth_quadrant_f(u.b, &q);
    return dwvk_frame_direction(&turned[q], s.cos_theta, s.sin_theta, azimuth);
}

/* A cosine of unit vectors held in [-1, 1] (rounding may leave a dot product just outside, where
 * the stretch and the pdfs are not defined). */
static inline double dwvw_clamp_cosine(double mu)
{
    return mu < -1.0 ? -1.0 : mu > 1.0 ? 1.0 : mu;
}

/* The cosine of unit `direction` to unit `axis`, held in [-1, 1]. */
static inline double dwvw_cosine(dwvu_vec3 direction, dwvu_vec3 axis)
{
    return dwvw_clamp_cosine(dwvu_dot(direction, axis));
}

/* The phase function's value for a step from `previous` to `direction`: Henyey-Greenstein, or at
 * g = 0 the isotropic 1/(4 pi) (which skips its square root and division). */
static inline double dwvw_phase_value(float g, dwvu_vec3 previous, dwvu_vec3 direction)
{
    return g == 0.0f ? DWVK_INV_FOUR_PI : dwvk_hg_pdf_f(g, (float)dwvw_cosine(previous, direction));
}

/* ---- free flight and the exit test ---------------------------------------------------------- */

/* A free flight of extinction sigma (> 0) from a 24-bit uniform: for a guided component sigma is
 * the stretched extinction sigma_t (1 - mu / v). */
static inline double dwvw_flight(double sigma, float u)
{
    return dwvk_free_flight(u) / sigma;
}

/* dwvw_flight from its unit flight dwvk_free_flight(u), drawn apart (the lanes draw theirs in a
 * loop of their own): the same division, the same bits. */
static inline double dwvw_unit_flight_scaled(double unit_flight, double sigma)
{
    return unit_flight / sigma;
}

/* The exit test: the ray along the step meets the surface at distance `hit` (+INFINITY for none)
 * within the sampled `flight`, and the walk leaves there. */
static inline int dwvw_leaves(double hit, double flight)
{
    return hit <= flight;
}

/* The step's length: to the surface if the walk leaves (*exited = 1), else the flight. */
static inline double dwvw_step_length(double hit, double flight, int *exited)
{
    *exited = dwvw_leaves(hit, flight);
    return *exited ? hit : flight;
}

/* ---- the weight update (one-sample MIS, balance heuristic: weight *= f / sum_k Q_k p_k) ------ */

/* A grey step's factor exp(sigma (1 - s) t) = exp(-sigma s t) / exp(-sigma t) for a component of
 * stretch s: f and every pdf term share the factor exp(-sigma t), so the ratio is formed without
 * it and neither underflows alone. The classical component (s = 1) has exp(0) = 1: the call is
 * skipped. */
static inline double dwvw_grey_decay(double sigma, double stretch, double t)
{
    return stretch == 1.0 ? 1.0 : dwvk_exp_fast(sigma * (1.0 - stretch) * t);
}

/* A component's term Q p pdist of a grey step's pdf: qp = Q p (its weight and direction pdf),
 * pdist = sigma s exp(-sigma s t) for a scattering event and exp(-sigma s t) for leaving at t (the
 * flight's tail), both divided by what f shares with them (sigma exp(-sigma t), or exp(-sigma t)
 * on leaving); decay = dwvw_grey_decay. */
static inline double dwvw_grey_term(double qp, double stretch, double decay, int exited)
{
    return qp * (exited ? 1.0 : stretch) * decay;
}

/* f / p: the factor a step multiplies a weight by. The ratio is >= 0 or NaN (every factor is
 * >= 0): `ratio <= DBL_MAX` is isfinite(ratio), and a ratio that is not finite (a denominator
 * that underflowed) ends the walk's contribution. */
static inline double dwvw_weight_ratio(double numerator, double denominator)
{
    double ratio = numerator / denominator;
    return ratio <= DBL_MAX ? ratio : 0.0;
}

/* A grey step's f / p from the sum of its dwvw_grey_term terms: f = phase x sigma alpha
 * exp(-sigma t) for a scattering event, phase x exp(-sigma t) for leaving, divided as the terms
 * are. */
static inline double dwvw_grey_ratio(double phase, double albedo, double denominator, int exited)
{
    return dwvw_weight_ratio(phase * (exited ? 1.0 : albedo), denominator);
}

/* ---- Russian roulette ----------------------------------------------------------------------- */

/* log(DWVW_ROULETTE_THRESHOLD), for the walkers that keep their weight's log. */
#define DWVW_LOG_ROULETTE_THRESHOLD -0.69314718055994531

/* Russian roulette after event `events` (>= 1) of a walk whose throughput `largest` (its largest
 * channel, > 0) fell below the threshold: it survives with probability largest / threshold,
 * *survive, by which its weights are then divided (unbiased: E[weight] is unchanged). Returns 1 if
 * it survives.
 *
 * Guided walks carry weights near alpha exp(sigma kappa z)/(1 + kappa), just below 1 near the
 * surface; a threshold of 1 would kill them there for nothing but variance. At 0.5 (was 0.05) the
 * report's thick sphere takes 10% fewer events per walk for +0.5% variance (classical and poe
 * alike), thin slabs and leaves are unchanged (docs/speed.md). */
static inline int dwvw_roulette_survives(uint64_t key, uint32_t events, double largest, double *survive)
{
    *survive = largest / DWVW_ROULETTE_THRESHOLD;
    return !(dwvk_rng_uniform_d(key, dwvw_event_dim(events - 1u) + DWVW_DIM_ROULETTE) >= *survive);
}

/* What follows a scattering event (`events` counted) of a grey walk of throughput *weight: it is
 * absorbed at zero throughput or by the roulette (which may raise *weight), truncated at the event
 * cap, or goes on. dwvw_walk_complete's ending, for one channel. Returns 1 if the walk goes on,
 * else 0 with *status its end: each way out a constant, so that a caller's loop breaks on it
 * without testing a status again. */
static inline int dwvw_grey_goes_on(uint64_t key, uint32_t events, uint32_t max_events, double *weight,
                                    dwvw_status *status)
{
    if (!(*weight > 0.0)) {
        *status = DWVW_ABSORBED;
        return 0;
    }
    if (*weight < DWVW_ROULETTE_THRESHOLD) {
        double survive;
        if (!dwvw_roulette_survives(key, events, *weight, &survive)) {
            *status = DWVW_ABSORBED;
            return 0;
        }
        *weight /= survive;
    }
    if (events >= max_events) {
        *status = DWVW_TRUNCATED;
        return 0;
    }
    return 1;
}

#endif
