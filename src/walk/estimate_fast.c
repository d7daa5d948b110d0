/* The estimator's fast paths: one walk at a time, for grey media whose guided part is one
 * component about a fixed axis (dwvw_estimate_walker). */
#include <math.h>

#include "estimate_walkers.h"
#include "geometry.h"
#include "step.h"

/* ---- the fast paths -------------------------------------------------------------------------
 * They draw the same random numbers as dwvw_walk_sample / dwvw_walk_complete (same dimensions,
 * same kernels, same arithmetic for directions and distances), so they make the same walks; only
 * the weight is formed differently. Grey medium, one component, weight 1 in its one channel.
 *
 * Classical alone: f / p = alpha sigma p_phase e^(-sigma t) / (p_phase sigma e^(-sigma t)) = alpha
 * per scattering event and 1 for the exit, so the weight is alpha^events: no pdf, no exponential.
 *
 * One guided component about a fixed unit axis n, isotropic phase 1/(4 pi), at a scattering event
 * after a sampled direction w (mu = w.n, stretch s = 1 - kappa mu, a = 2 kappa / L):
 *   f = alpha (1/(4 pi)) sigma e^(-sigma t)
 *   p = (a / (4 pi s)) sigma s e^(-sigma s t)               (direction pdf x stretched flight)
 *   f / p = (alpha / a) e^(-sigma (1 - s) t) = (alpha / a) e^(-sigma kappa (t w).n):
 * the stretch cancels, and t w is the event's displacement. The first step keeps the entry
 * direction (pdf 1 for every technique, phase 1): f / p = (alpha / s0) e^(-sigma kappa (t w).n).
 * The exit step has no albedo and no sigma: (s / a) e^(-sigma kappa (t w).n), or for an exit on
 * the first step e^(-sigma kappa (t w).n). Summed over the steps, the displacements add up to the
 * position less the entry point, so
 *   log weight = sum of the log constants - sigma kappa (x - x_entry).n,
 * one multiply-add per event for the Russian roulette test (weight < threshold, in logs), and one
 * exponential per walk (or per roulette below the threshold). */
/* dwvw_guided_direction_turned for an aligned plan: the same values (dwvk_frame_direction's
 * products with the frame's zeros and ones left out). */
static inline dwvu_vec3 aligned_guided_direction(const dwvw_fast_plan *plan, const dwvk_dwivedi_event_f *d,
                                                 dwvk_uniform_pair_f u)
{
    dwvk_dwivedi_event_cosine_f s = dwvk_dwivedi_event_sample_f(d, u.a);
    int32_t q;
    dwvk_unit2_f azimuth = dwvk_azimuth_quadrant_f(u.b, &q);
    double sin_theta = s.sin_theta;
    double values[3] = {(double)azimuth.c * sin_theta, (double)azimuth.s * sin_theta, (double)s.cos_theta};
    dwvu_vec3 w = dwvu_v(plan->sign[q][0] * values[plan->index[q][0]], plan->sign[q][1] * values[plan->index[q][1]],
                         plan->sign[q][2] * values[plan->index[q][2]]);
    return dwvu_scale(w, 1.5 - 0.5 * dwvu_dot(w, w));
}

/* The walkers below are inlined with a constant `kind`, so that each shape gets its own loop with
 * its exit test written out. Plain `inline` left GCC 12 one copy per walker that tests the kind at
 * every event, and the sphere's registers in the half-space's loop (a position spilled to the
 * stack): forced, the classical walker takes 2-4% fewer instructions per walk (callgrind). */
static DWVW_ALWAYS_INLINE void classical_walk_in(const dwvw_estimate_setup *setup, dwvw_shape_kind kind,
                                                 uint64_t key, dwvw_walk_end *end)
{
    const dwvw_medium *m = &setup->medium;
    const double sigma = m->sigma_t[0], albedo = m->albedo[0];
    const float g = (float)m->g;
    dwvu_vec3 position = DWVW_ENTRY_POINT, direction = dwvw_entry_direction(setup, key), normal;
    double weight = 1.0;
    uint32_t events = 0;
    for (;;) {
        uint32_t dim = dwvw_event_dim(events);
        if (events > 0)
            direction = dwvw_classical_direction(direction, g, dwvk_rng_uniform_pair_f(key, dim + DWVW_DIM_DIRECTION));
        double t = dwvw_flight(sigma, dwvk_rng_uniform_f(key, dim + DWVW_DIM_DISTANCE));
        double hit = dwvw_shape_exit_inline(&setup->shape, kind, position, direction, &normal);
        if (dwvw_leaves(hit, t)) {
            end->status = DWVW_EXITED;
            break;
        }
        position = dwvu_madd(position, direction, t);
        ++events;
        weight *= albedo;
        if (!dwvw_grey_goes_on(key, events, setup->max_events, &weight, &end->status)) break;
    }
    dwvw_grey_end(end, events, weight);
    end->exit_normal = normal;
}

static void classical_walk(const dwvw_estimate_setup *setup, uint64_t key, dwvw_walk_end *end)
{
    switch (setup->shape.kind) {
    case DWVW_HALFSPACE: classical_walk_in(setup, DWVW_HALFSPACE, key, end); return;
    case DWVW_SLAB: classical_walk_in(setup, DWVW_SLAB, key, end); return;
    case DWVW_SPHERE: classical_walk_in(setup, DWVW_SPHERE, key, end); return;
    }
}

static DWVW_ALWAYS_INLINE void guided_walk_in(const dwvw_estimate_setup *setup, const dwvw_fast_plan *plan,
                                              dwvw_shape_kind kind, uint64_t key, dwvw_walk_end *end)
{
    const dwvw_medium *m = &setup->medium;
    const double sigma = m->sigma_t[0], log_per_event = plan->log_per_event;
    const uint32_t max_events = setup->max_events;
    dwvu_vec3 position = DWVW_ENTRY_POINT, direction = dwvw_entry_direction(setup, key), normal;
    uint32_t events = 0;
    /* log weight = log_constants - sigma x exponent (dwvw_guided_log_weight). */
    double log_constants = 0.0, exponent = 0.0, log_weight = 0.0, last_factor = 1.0;
    /* The RNG counter of this event's direction dimension, stepped by additions (dwvk_rng_counter). */
    const uint64_t to_distance = DWVW_DIM_COUNTER_OFFSET(DWVW_DIM_DIRECTION, DWVW_DIM_DISTANCE);
    uint64_t counter = dwvk_rng_counter(key, dwvw_event_dim(0) + DWVW_DIM_DIRECTION);
    for (;; counter += DWVW_EVENT_COUNTER_STEP) {
        /* The first step (events = 0) keeps the entry direction: its constant is log(alpha / s0). */
        if (events > 0) {
            dwvk_uniform_pair_f u = dwvw_counter_uniform_pair_f(counter);
            direction = plan->aligned ? aligned_guided_direction(plan, &m->dwivedi_event, u)
                                      : dwvw_guided_direction_turned(plan->turned, &m->dwivedi_event, u);
        }
        double mu = plan->aligned ? dwvw_aligned_cosine(plan, direction) : dwvw_cosine(direction, plan->axis);
        double stretch = dwvk_dwivedi_stretch_d(&m->dwivedi, mu);
        double t = dwvw_flight(sigma * stretch, dwvw_counter_uniform_f(counter + to_distance));
        double hit = dwvw_shape_exit_inline(&setup->shape, kind, position, direction, &normal);
        if (dwvw_leaves(hit, t)) {
            position = dwvu_madd(position, direction, hit);
            exponent = dwvw_guided_exponent(exponent, stretch, hit);
            log_weight = dwvw_guided_log_weight(log_constants, sigma, exponent);
            last_factor = dwvw_guided_exit_factor(plan, events, stretch);
            end->status = DWVW_EXITED;
            break;
        }
        position = dwvu_madd(position, direction, t);
        exponent = dwvw_guided_exponent(exponent, stretch, t);
        if (events > 0) log_constants += log_per_event;
        else log_constants = plan->first_known ? plan->log_first : log(m->albedo[0] / stretch);
        ++events;
        log_weight = dwvw_guided_log_weight(log_constants, sigma, exponent);
        if (log_weight < DWVW_LOG_ROULETTE_THRESHOLD) {
            int fate = dwvw_guided_roulette(key, events, &log_weight);
            if (fate == 0) {
                end->status = DWVW_ABSORBED;
                break;
            }
            if (fate == 2) log_constants = dwvw_guided_constants_for(log_weight, sigma, exponent);
        }
        if (events >= max_events) {
            end->status = DWVW_TRUNCATED;
            break;
        }
    }
    dwvw_guided_end(end, events, log_weight, last_factor);
    end->exit_normal = normal;
}

static void guided_walk(const dwvw_estimate_setup *setup, const dwvw_fast_plan *plan, uint64_t key, dwvw_walk_end *end)
{
    switch (setup->shape.kind) {
    case DWVW_HALFSPACE: guided_walk_in(setup, plan, DWVW_HALFSPACE, key, end); return;
    case DWVW_SLAB: guided_walk_in(setup, plan, DWVW_SLAB, key, end); return;
    case DWVW_SPHERE: guided_walk_in(setup, plan, DWVW_SPHERE, key, end); return;
    }
}

/* Classical (weight q0) and one guided component about a fixed axis (weight q1): `auto` wherever
 * it has one lit patch (or none, on the half-space), `cycles` on the half-space. Each step's
 * weight is the general path's f / (q0 p_classical + q1 p_guided), formed with the same
 * arithmetic as dwvw_walk_complete (one exponential per step), for any anisotropy; what the fast
 * path saves is the per-event mixture bookkeeping. */
static DWVW_ALWAYS_INLINE void mixture_walk_in(const dwvw_estimate_setup *setup, const dwvw_fast_plan *plan,
                                               dwvw_shape_kind kind, uint64_t key, dwvw_walk_end *end)
{
    const dwvw_medium *m = &setup->medium;
    const double sigma = m->sigma_t[0], albedo = m->albedo[0];
    const double q0 = setup->guide.q_classical, q1 = plan->q_guided, total = q0 + q1;
    const float g = (float)m->g;
    dwvu_vec3 position = DWVW_ENTRY_POINT, direction = dwvw_entry_direction(setup, key), normal;
    double weight = 1.0;
    uint32_t events = 0;
    for (;;) {
        uint32_t dim = dwvw_event_dim(events);
        /* pick() of walk.c over {q0, q1}. */
        int guided = !(dwvk_rng_uniform_d(key, dim + DWVW_DIM_COMPONENT) * total < q0);
        double phase = 1.0, pdf_guided = 1.0;
        if (events > 0) {
            dwvk_uniform_pair_f u = dwvk_rng_uniform_pair_f(key, dim + DWVW_DIM_DIRECTION);
            dwvu_vec3 previous = direction;
            direction = !guided       ? dwvw_classical_direction(previous, g, u)
                        : plan->aligned ? aligned_guided_direction(plan, &m->dwivedi_event, u)
                                        : dwvw_guided_direction_turned(plan->turned, &m->dwivedi_event, u);
            phase = dwvw_phase_value(g, previous, direction);
        }
        double stretch = dwvk_dwivedi_stretch_d(&m->dwivedi, plan->aligned ? dwvw_aligned_cosine(plan, direction)
                                                                           : dwvw_cosine(direction, plan->axis));
        if (events > 0) pdf_guided = m->guided_pdf_scale / stretch;
        double t = dwvw_flight(sigma * (guided ? stretch : 1.0), dwvk_rng_uniform_f(key, dim + DWVW_DIM_DISTANCE));
        double hit = dwvw_shape_exit_inline(&setup->shape, kind, position, direction, &normal);
        int exited;
        t = dwvw_step_length(hit, t, &exited);
        /* dwvw_walk_complete's grey branch, term by term (the classical term's stretch and decay
         * are 1). */
        double qp0 = q0 * phase, qp1 = q1 * pdf_guided, denominator = 0.0;
        if (qp0 > 0.0) denominator += dwvw_grey_term(qp0, 1.0, 1.0, exited);
        if (qp1 > 0.0) denominator += dwvw_grey_term(qp1, stretch, dwvw_grey_decay(sigma, stretch, t), exited);
        weight *= dwvw_grey_ratio(phase, albedo, denominator, exited);
        position = dwvu_madd(position, direction, t);
        if (exited) {
            end->status = DWVW_EXITED;
            break;
        }
        ++events;
        if (!dwvw_grey_goes_on(key, events, setup->max_events, &weight, &end->status)) break;
    }
    dwvw_grey_end(end, events, weight);
    end->exit_normal = normal;
}

static void mixture_walk(const dwvw_estimate_setup *setup, const dwvw_fast_plan *plan, uint64_t key, dwvw_walk_end *end)
{
    switch (setup->shape.kind) {
    case DWVW_HALFSPACE: mixture_walk_in(setup, plan, DWVW_HALFSPACE, key, end); return;
    case DWVW_SLAB: mixture_walk_in(setup, plan, DWVW_SLAB, key, end); return;
    case DWVW_SPHERE: mixture_walk_in(setup, plan, DWVW_SPHERE, key, end); return;
    }
}

void dwvw_fast_walk(const dwvw_estimate_setup *setup, const dwvw_fast_plan *plan, uint64_t key, dwvw_walk_end *end)
{
    switch (plan->walker) {
    case DWVW_WALKER_CLASSICAL: classical_walk(setup, key, end); return;
    case DWVW_WALKER_GUIDED: guided_walk(setup, plan, key, end); return;
    case DWVW_WALKER_MIXTURE: mixture_walk(setup, plan, key, end); return;
    case DWVW_WALKER_GENERAL: break; /* not a fast walker: the caller takes general_walk */
    }
}
