#include "estimate.h"

#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "kernel/rng.h"
#include "step.h"
#include "util/clock.h"
#include "util/parallel.h"

#define MAX_BLOCKS 65536u
#define MAX_THREADS 256u

int dwvw_estimate_light_patches(const dwvw_shape *shape, int light, dwvw_light_patch *patches)
{
    int count = 0;
    for (int side = 0; side < 2; ++side) {
        if (!(light & (side == 0 ? DWVW_LIGHT_FRONT : DWVW_LIGHT_BACK))) continue;
        double toward_light = side == 0 ? -1.0 : 1.0; /* z of the direction toward the light */
        if (shape->kind == DWVW_SPHERE) {
            /* The lit hemisphere as one patch at its pole: the irradiance-weighted mean of its
             * normals. Measured against the pole and a ring of six at 60 degrees (docs/walk.md):
             * lower variance (0.0077 against 0.0109 back-lit, radius 4, albedo 0.99) at a fraction
             * of the cost per event, which grows with every patch. */
            double R = shape->radius;
            dwvw_light_patch p = {.point = dwvu_v(0.0, 0.0, R + R * toward_light),
                                  .normal = dwvu_v(0.0, 0.0, toward_light), .power = 1.0, .is_plane = 0};
            patches[count++] = p;
        } else if (side == 0 || shape->kind == DWVW_SLAB) {
            double z = side == 0 ? 0.0 : shape->thickness;
            dwvw_light_patch p = {.point = dwvu_v(0.0, 0.0, z), .normal = dwvu_v(0.0, 0.0, toward_light), .power = 1.0,
                                  .is_plane = 1};
            patches[count++] = p;
        }
    }
    return count;
}

static double exit_score(const dwvw_estimate_setup *setup, dwvu_vec3 n)
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

typedef struct block_totals {
    double sum[DWVW_MAX_CHANNELS], sum_squares[DWVW_MAX_CHANNELS], truncated_weight[DWVW_MAX_CHANNELS];
    double m2[DWVW_MAX_CHANNELS]; /* squared deviations from the block's mean (Welford) */
    uint64_t events, truncated_walks, walks;
} block_totals;

static const dwvu_vec3 ENTRY_POINT = {0.0, 0.0, 0.0}, ENTRY_NORMAL = {0.0, 0.0, -1.0}; /* outward */

/* The entry direction of a walk: dimensions 0 and 1 of its key. */
static dwvu_vec3 entry_direction(const dwvw_estimate_setup *setup, uint64_t key)
{
    if (setup->incidence_diffuse) {
        /* Cosine-weighted: mu = sqrt(u). */
        double u = dwvk_rng_uniform_d(key, 0), mu = sqrt(u);
        return dwvk_direction_about(dwvu_v(0.0, 0.0, 1.0), mu, 1.0 - mu, 1.0 + mu, dwvk_rng_uniform_d(key, 1));
    }
    double mu = setup->incidence_cosine;
    return dwvu_v(sqrt((1.0 - mu) * (1.0 + mu)), 0.0, mu);
}

static void general_walk(const dwvw_estimate_setup *setup, uint64_t key, dwvw_walk_end *end)
{
    dwvw_walk walk;
    dwvw_walk_begin(&walk, &setup->medium, &setup->guide, key, setup->max_events, ENTRY_POINT,
                    entry_direction(setup, key), ENTRY_NORMAL);
    int needs_closest = dwvw_guide_needs_closest(&setup->guide);
    while (walk.status == DWVW_RUNNING) {
        if (needs_closest) {
            dwvu_vec3 n;
            dwvw_shape_closest(&setup->shape, walk.position, &n);
            dwvw_walk_set_closest(&walk, n);
        }
        dwvw_walk_sample(&walk);
        dwvu_vec3 hit_normal;
        double hit = dwvw_shape_exit(&setup->shape, walk.position, walk.direction, &hit_normal);
        dwvw_walk_complete(&walk, hit, hit_normal);
    }
    end->status = walk.status;
    end->events = walk.events;
    for (int c = 0; c < DWVW_MAX_CHANNELS; ++c) end->weight[c] = walk.weight[c];
    end->exit_normal = walk.exit_normal;
}

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

/* What a run's fast path needs, worked out once per run. */
typedef struct fast_plan {
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
} fast_plan;

static void add_flight(dwvu_vec3 *position, dwvu_vec3 direction, double t)
{
    *position = dwvu_madd(*position, direction, t);
}

static double component(dwvu_vec3 v, int i)
{
    return i == 0 ? v.x : i == 1 ? v.y : v.z;
}

/* Fills plan->aligned and its tables if the turned frames are signed permutations. */
static void plan_alignment(fast_plan *plan)
{
    plan->aligned = 0;
    for (int q = 0; q < 4; ++q) {
        const dwvu_frame *f = &plan->turned[q];
        for (int i = 0; i < 3; ++i) {
            double parts[3] = {component(f->t, i), component(f->s, i), component(f->n, i)};
            int nonzero = 0;
            for (int j = 0; j < 3; ++j) {
                if (parts[j] == 0.0) continue;
                if (parts[j] != 1.0 && parts[j] != -1.0) return;
                ++nonzero;
                plan->index[q][i] = j;
                plan->sign[q][i] = parts[j];
            }
            if (nonzero != 1) return;
        }
    }
    int nonzero = 0;
    for (int i = 0; i < 3; ++i) {
        double a = component(plan->axis, i);
        if (a == 0.0) continue;
        if (a != 1.0 && a != -1.0) return;
        ++nonzero;
        plan->axis_index = i;
        plan->axis_sign = a;
    }
    plan->aligned = nonzero == 1;
}

/* dwvw_guided_direction_turned for an aligned plan: the same values (dwvk_frame_direction's
 * products with the frame's zeros and ones left out). */
static inline dwvu_vec3 aligned_guided_direction(const fast_plan *plan, const dwvk_dwivedi_event_f *d,
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

/* dwvw_cosine(direction, plan->axis) for an aligned plan. */
static inline double aligned_cosine(const fast_plan *plan, dwvu_vec3 direction)
{
    return dwvw_clamp_cosine(plan->axis_sign * component(direction, plan->axis_index));
}

/* The Russian roulette of dwvw_walk_complete (dwvw_roulette_survives) on a weight
 * exp(log_weight) after `events` events: 0 if the walk ends (absorbed), 1 if it goes on
 * unchanged, 2 if it goes on with its weight raised to the threshold (*log_weight = its log). */
static int guided_roulette(uint64_t key, uint32_t events, double *log_weight)
{
    if (!(*log_weight < DWVW_LOG_ROULETTE_THRESHOLD)) return 1;
    double weight = exp(*log_weight), survive;
    if (!(weight > 0.0) || !dwvw_roulette_survives(key, events, weight, &survive)) return 0;
    *log_weight = DWVW_LOG_ROULETTE_THRESHOLD; /* log(weight / survive) */
    return 2;
}

/* Inline with a constant `kind`: each shape gets its own loop with its exit test inlined. */
static inline void classical_walk_in(const dwvw_estimate_setup *setup, dwvw_shape_kind kind, uint64_t key,
                                     dwvw_walk_end *end)
{
    const dwvw_medium *m = &setup->medium;
    const double sigma = m->sigma_t[0], albedo = m->albedo[0];
    const float g = (float)m->g;
    dwvu_vec3 position = ENTRY_POINT, direction = entry_direction(setup, key), normal;
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
        add_flight(&position, direction, t);
        ++events;
        weight *= albedo;
        if (!dwvw_grey_goes_on(key, events, setup->max_events, &weight, &end->status)) break;
    }
    end->events = events;
    end->weight[0] = end->status == DWVW_ABSORBED ? 0.0 : weight;
    end->weight[1] = end->weight[2] = 0.0;
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

/* The guided part of a setup when it is one component about an axis fixed for the whole walk:
 * its weight q (the rest is classical) and axis; 0 if the guided part is anything else. */
static double fixed_guide(const dwvw_estimate_setup *setup, dwvu_vec3 *axis)
{
    const dwvw_guide *guide = &setup->guide;
    int halfspace = setup->shape.kind == DWVW_HALFSPACE;
    int parts = (guide->q_poe > 0.0) + (guide->q_closest > 0.0) + (guide->q_incident > 0.0) + (guide->q_backward > 0.0);
    if (parts != 1) return 0.0;
    if (guide->q_poe > 0.0) {
        *axis = ENTRY_NORMAL;
        return guide->q_poe;
    }
    /* The half-space's closest point is always on its one plane, and the first step's probe into it
     * finds no opposite interface, so there closest and backward guide about the entry normal. */
    if (halfspace && guide->q_closest > 0.0) {
        *axis = ENTRY_NORMAL;
        return guide->q_closest;
    }
    if (halfspace && guide->q_backward > 0.0) {
        *axis = ENTRY_NORMAL;
        return guide->q_backward;
    }
    if (guide->q_incident > 0.0 && guide->patch_count == 1) {
        *axis = guide->patches[0].normal;
        return guide->q_incident;
    }
    return 0.0;
}

static inline void guided_walk_in(const dwvw_estimate_setup *setup, const fast_plan *plan, dwvw_shape_kind kind,
                                  uint64_t key, dwvw_walk_end *end)
{
    const dwvw_medium *m = &setup->medium;
    const double sigma = m->sigma_t[0], log_per_event = plan->log_per_event;
    const uint32_t max_events = setup->max_events;
    dwvu_vec3 position = ENTRY_POINT, direction = entry_direction(setup, key), normal;
    uint32_t events = 0;
    /* log weight = log_constants - sigma x exponent, exponent = sum over steps of (1 - s) t. */
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
        double mu = plan->aligned ? aligned_cosine(plan, direction) : dwvw_cosine(direction, plan->axis);
        double stretch = dwvk_dwivedi_stretch_d(&m->dwivedi, mu);
        double t = dwvw_flight(sigma * stretch, dwvw_counter_uniform_f(counter + to_distance));
        double hit = dwvw_shape_exit_inline(&setup->shape, kind, position, direction, &normal);
        if (dwvw_leaves(hit, t)) {
            add_flight(&position, direction, hit);
            exponent += (1.0 - stretch) * hit;
            log_weight = log_constants - sigma * exponent;
            if (events > 0) last_factor = stretch * plan->inv_albedo_eff; /* s / a */
            end->status = DWVW_EXITED;
            break;
        }
        add_flight(&position, direction, t);
        exponent += (1.0 - stretch) * t;
        if (events > 0) log_constants += log_per_event;
        else log_constants = plan->first_known ? plan->log_first : log(m->albedo[0] / stretch);
        ++events;
        log_weight = log_constants - sigma * exponent;
        if (log_weight < DWVW_LOG_ROULETTE_THRESHOLD) {
            int fate = guided_roulette(key, events, &log_weight);
            if (fate == 0) {
                end->status = DWVW_ABSORBED;
                break;
            }
            if (fate == 2) log_constants = log_weight + sigma * exponent;
        }
        if (events >= max_events) {
            end->status = DWVW_TRUNCATED;
            break;
        }
    }
    double weight = end->status == DWVW_ABSORBED ? 0.0 : exp(log_weight) * last_factor;
    end->events = events;
    end->weight[0] = isfinite(weight) ? weight : 0.0;
    end->weight[1] = end->weight[2] = 0.0;
    end->exit_normal = normal;
}

static void guided_walk(const dwvw_estimate_setup *setup, const fast_plan *plan, uint64_t key, dwvw_walk_end *end)
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
static inline void mixture_walk_in(const dwvw_estimate_setup *setup, const fast_plan *plan, dwvw_shape_kind kind,
                                   uint64_t key, dwvw_walk_end *end)
{
    const dwvw_medium *m = &setup->medium;
    const double sigma = m->sigma_t[0], albedo = m->albedo[0];
    const double q0 = setup->guide.q_classical, q1 = plan->q_guided, total = q0 + q1;
    const float g = (float)m->g;
    dwvu_vec3 position = ENTRY_POINT, direction = entry_direction(setup, key), normal;
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
        double stretch = dwvk_dwivedi_stretch_d(&m->dwivedi, plan->aligned ? aligned_cosine(plan, direction)
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
        add_flight(&position, direction, t);
        if (exited) {
            end->status = DWVW_EXITED;
            break;
        }
        ++events;
        if (!dwvw_grey_goes_on(key, events, setup->max_events, &weight, &end->status)) break;
    }
    end->events = events;
    end->weight[0] = end->status == DWVW_ABSORBED ? 0.0 : weight;
    end->weight[1] = end->weight[2] = 0.0;
    end->exit_normal = normal;
}

static void mixture_walk(const dwvw_estimate_setup *setup, const fast_plan *plan, uint64_t key, dwvw_walk_end *end)
{
    switch (setup->shape.kind) {
    case DWVW_HALFSPACE: mixture_walk_in(setup, plan, DWVW_HALFSPACE, key, end); return;
    case DWVW_SLAB: mixture_walk_in(setup, plan, DWVW_SLAB, key, end); return;
    case DWVW_SPHERE: mixture_walk_in(setup, plan, DWVW_SPHERE, key, end); return;
    }
}

dwvw_walker dwvw_estimate_walker(const dwvw_estimate_setup *setup)
{
    dwvu_vec3 axis;
    if (setup->general_path || setup->medium.channels != 1) return DWVW_WALKER_GENERAL;
    const dwvw_guide *g = &setup->guide;
    if (g->q_classical == 1.0 && g->q_poe == 0.0 && g->q_closest == 0.0 && g->q_incident == 0.0 && g->q_backward == 0.0)
        return DWVW_WALKER_CLASSICAL;
    double q_guided = fixed_guide(setup, &axis);
    if (!(q_guided > 0.0)) return DWVW_WALKER_GENERAL;
    if (g->q_classical == 0.0 && q_guided == 1.0 && setup->medium.g == 0.0) return DWVW_WALKER_GUIDED;
    return DWVW_WALKER_MIXTURE; /* a classical share, or anisotropic scattering */
}

static void make_plan(const dwvw_estimate_setup *setup, dwvw_walker walker, fast_plan *plan)
{
    const dwvw_medium *m = &setup->medium;
    memset(plan, 0, sizeof *plan);
    plan->walker = walker;
    if (walker != DWVW_WALKER_GUIDED && walker != DWVW_WALKER_MIXTURE) return;
    plan->axis = ENTRY_NORMAL;
    plan->q_guided = fixed_guide(setup, &plan->axis);
    dwvu_frame frame = dwvu_frame_about(plan->axis);
    for (int q = 0; q < 4; ++q) plan->turned[q] = dwvu_frame_turned(&frame, q);
    plan_alignment(plan);
    plan->log_per_event = log(m->albedo[0] / m->dwivedi.albedo_eff);
    plan->inv_albedo_eff = 1.0 / m->dwivedi.albedo_eff;
    plan->first_known = !setup->incidence_diffuse;
    if (plan->first_known) {
        double s0 = dwvk_dwivedi_stretch_d(&m->dwivedi, dwvw_cosine(entry_direction(setup, 0u), plan->axis));
        plan->log_first = log(m->albedo[0] / s0);
    }
    /* Lanes take a frame about a z axis (every axis of the analytic shapes), the one case
     * lanes_step_in writes out: t = (1, 0, 0), s = (0, +-1, 0), n = (0, 0, +-1). */
    int z_frame = plan->aligned && plan->axis_index == 2 && plan->index[0][0] == 0 && plan->index[0][1] == 1 &&
                  plan->index[0][2] == 2 && plan->sign[0][0] == 1.0;
    /* The mixture in lanes for an isotropic medium (mixture_lanes_step_in); anisotropic media
     * take it one walk at a time. */
    int lane_walker = walker == DWVW_WALKER_GUIDED || (walker == DWVW_WALKER_MIXTURE && m->g == 0.0);
    plan->lanes = lane_walker && z_frame && !setup->single_lane;
}

static void walk_with_plan(const dwvw_estimate_setup *setup, const fast_plan *plan, uint64_t index,
                           dwvw_walk_end *end)
{
    uint64_t key = dwvk_rng_key(setup->seed, index, 0);
    switch (plan->walker) {
    case DWVW_WALKER_CLASSICAL: classical_walk(setup, key, end); return;
    case DWVW_WALKER_GUIDED: guided_walk(setup, plan, key, end); return;
    case DWVW_WALKER_MIXTURE: mixture_walk(setup, plan, key, end); return;
    case DWVW_WALKER_GENERAL: break;
    }
    general_walk(setup, key, end);
}

void dwvw_estimate_walk(const dwvw_estimate_setup *setup, dwvw_walker walker, uint64_t index, dwvw_walk_end *end)
{
    fast_plan plan;
    make_plan(setup, walker, &plan);
    walk_with_plan(setup, &plan, index, end);
}

static void add_walk(const dwvw_estimate_setup *setup, const dwvw_walk_end *end, block_totals *out)
{
    out->events += end->events;
    double score = end->status == DWVW_EXITED ? exit_score(setup, end->exit_normal) : 0.0;
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

typedef struct run_state {
    const dwvw_estimate_setup *setup;
    uint64_t block_size;
    uint32_t block_count;
    fast_plan plan;
    atomic_uint next_block;
    block_totals *blocks;
} run_state;

/* ---- lock-step: several walks advanced together ---------------------------------------------
 * One event of guided_walk_in is a long chain of dependent operations (hash, expm1, square root,
 * direction, stretch, log, two divisions): a core that runs one walk waits on it. DWVW_LANES walks
 * in lanes (structure of arrays) take their events together, one loop over the lanes per stage,
 * so that the lanes' chains interleave (and a compiler may vectorise a stage). Each lane does
 * exactly what guided_walk_in (or mixture_walk_in, for the mixture walker in an isotropic medium)
 * does for its walk, with the same random numbers (the walk's key and dimensions), the same
 * kernels and the same double arithmetic in the same order, so each walk ends as it does there,
 * weight for weight to the last bit (tests/internal/test_walk_fast_path.c compares them walk by
 * walk). What changes is only which walks run at the same time: the branches that end a walk
 * (exit, Russian roulette, event cap) are taken for a lane after the step, and a lane whose walk
 * ended takes the next walk of its thread's blocks. Results are added to their block in walk
 * order (lane_feed), so the totals equal the one-walk-at-a-time path's. */

/* The lanes' state. p: position; d: the direction of the step being taken (for a lane at
 * events = 0, its entry direction). log_constants and exponent as in guided_walk_in, weight as in
 * mixture_walk_in. */
typedef struct guided_lanes {
    double px[DWVW_LANES], py[DWVW_LANES], pz[DWVW_LANES];
    double dx[DWVW_LANES], dy[DWVW_LANES], dz[DWVW_LANES];
    double log_constants[DWVW_LANES], exponent[DWVW_LANES], log_weight[DWVW_LANES], stretch[DWVW_LANES];
    double first_constant[DWVW_LANES]; /* the first step's log(alpha / s0) */
    double entry_x[DWVW_LANES], entry_y[DWVW_LANES], entry_z[DWVW_LANES]; /* the entry direction */
    uint64_t key[DWVW_LANES], counter[DWVW_LANES];
    uint32_t events[DWVW_LANES];
    int exited[DWVW_LANES], flagged[DWVW_LANES];
    double weight[DWVW_LANES];         /* the mixture's throughput (mixture_lanes_step_in) */
} guided_lanes;

/* Puts walk `index` into lane l at its entry, as guided_walk_in starts it. */
static void lane_begin(guided_lanes *L, int l, const dwvw_estimate_setup *setup, const fast_plan *plan,
                       uint64_t index)
{
    uint64_t key = dwvk_rng_key(setup->seed, index, 0);
    dwvu_vec3 direction = entry_direction(setup, key);
    L->key[l] = key;
    /* The guided walk steps the counter of an event's direction dimension, the mixture that of its
     * first (channel) dimension. */
    uint32_t dimension = plan->walker == DWVW_WALKER_MIXTURE ? DWVW_DIM_CHANNEL : DWVW_DIM_DIRECTION;
    L->counter[l] = dwvk_rng_counter(key, dwvw_event_dim(0) + dimension);
    L->px[l] = ENTRY_POINT.x;
    L->py[l] = ENTRY_POINT.y;
    L->pz[l] = ENTRY_POINT.z;
    L->dx[l] = L->entry_x[l] = direction.x;
    L->dy[l] = L->entry_y[l] = direction.y;
    L->dz[l] = L->entry_z[l] = direction.z;
    L->events[l] = 0;
    L->log_constants[l] = L->exponent[l] = L->log_weight[l] = 0.0;
    L->weight[l] = 1.0;
    if (plan->first_known) {
        L->first_constant[l] = plan->log_first;
    } else {
        double stretch = dwvk_dwivedi_stretch_d(&setup->medium.dwivedi, aligned_cosine(plan, direction));
        L->first_constant[l] = log(setup->medium.albedo[0] / stretch);
    }
}

/* The distance along w from p to a plane face, as dwvw_shape_exit_inline gives it, with every
 * operation done whatever the sign (a lane's select, not a branch: the division's unused results
 * are discarded). */
static inline double lane_halfspace_exit(double pz, double wz)
{
    double toward_front = dwvw_front_plane_distance(pz, wz);
    return wz < 0.0 ? toward_front : INFINITY;
}

static inline double lane_slab_exit(double thickness, double pz, double wz)
{
    double toward_front = dwvw_front_plane_distance(pz, wz), toward_back = dwvw_back_plane_distance(thickness, pz, wz);
    return wz < 0.0 ? toward_front : wz > 0.0 ? toward_back : INFINITY;
}

/* One event of every lane (lanes whose walk ended compute on without effect until refilled).
 * Sets flagged[l] where guided_walk_in would take a branch after the step: the walk exited, its
 * weight fell below the roulette threshold, or it reached the event cap. Each stage is a loop
 * over the lanes without branches, for the compiler to vectorise. The plan's frame is the one
 * about a z axis (make_plan): direction (c, sz d, sz mu) for azimuth (c, d) turned by its quarter
 * turns (the same products as aligned_guided_direction's turned frame, signs exact). */
/* Each shape's step gets its own copy of the loops, with its exit test (GCC and Clang otherwise
 * judge the function too large to inline three times). */

static DWVW_ALWAYS_INLINE int lanes_step_in(guided_lanes *L, const dwvw_estimate_setup *setup, const fast_plan *plan,
                                dwvw_shape_kind kind)
{
    const dwvw_medium *m = &setup->medium;
    const dwvk_dwivedi_event_f *d = &m->dwivedi_event;
    const double sigma = m->sigma_t[0], log_per_event = plan->log_per_event, thickness = setup->shape.thickness;
    const uint32_t max_events = setup->max_events;
    const uint64_t to_distance = DWVW_DIM_COUNTER_OFFSET(DWVW_DIM_DIRECTION, DWVW_DIM_DISTANCE);
    const double sy = plan->sign[0][1], sz = plan->sign[0][2], axis_sign = plan->axis_sign;
    const double kappa = m->dwivedi.kappa, one_minus_kappa = m->dwivedi.one_minus_kappa;
    float ua[DWVW_LANES], ub[DWVW_LANES], udist[DWVW_LANES];
    float cos_theta[DWVW_LANES], sin_theta[DWVW_LANES], azimuth_c[DWVW_LANES], azimuth_s[DWVW_LANES];
    for (int l = 0; l < DWVW_LANES; ++l) {
        dwvk_uniform_pair_f u = dwvw_counter_uniform_pair_f(L->counter[l]);
        ua[l] = u.a;
        ub[l] = u.b;
        udist[l] = dwvw_counter_uniform_f(L->counter[l] + to_distance);
        L->counter[l] += DWVW_EVENT_COUNTER_STEP;
    }
    for (int l = 0; l < DWVW_LANES; ++l) {
        dwvk_dwivedi_event_cosine_f s = dwvk_dwivedi_event_sample_select_f(d, ua[l]);
        dwvk_unit2_f azimuth = dwvk_azimuth_f(ub[l]); /* turned by its quarter turns */
        cos_theta[l] = s.cos_theta;
        sin_theta[l] = s.sin_theta;
        azimuth_c[l] = azimuth.c;
        azimuth_s[l] = azimuth.s;
    }
    for (int l = 0; l < DWVW_LANES; ++l) {
        double wx = (double)azimuth_c[l] * (double)sin_theta[l];
        double wy = sy * ((double)azimuth_s[l] * (double)sin_theta[l]);
        double wz = sz * (double)cos_theta[l];
        double scale = 1.5 - 0.5 * (wx * wx + wy * wy + wz * wz);
        int fresh = L->events[l] == 0; /* the first step keeps the entry direction */
        double ex = L->entry_x[l], ey = L->entry_y[l], ez = L->entry_z[l];
        L->dx[l] = fresh ? ex : wx * scale;
        L->dy[l] = fresh ? ey : wy * scale;
        L->dz[l] = fresh ? ez : wz * scale;
    }
    int any = 0;
    for (int l = 0; l < DWVW_LANES; ++l) {
        double px = L->px[l], py = L->py[l], pz = L->pz[l], wx = L->dx[l], wy = L->dy[l], wz = L->dz[l];
        double mu = dwvw_clamp_cosine(axis_sign * wz);
        /* dwvk_dwivedi_stretch_d, its constants loaded before the loop and both sides formed. */
        double stretch_above = one_minus_kappa + kappa * (1.0 - mu), stretch_below = 1.0 - kappa * mu;
        double stretch = mu >= 0.0 ? stretch_above : stretch_below;
        double t = dwvw_flight(sigma * stretch, udist[l]);
        double hit;
        if (kind == DWVW_HALFSPACE) hit = lane_halfspace_exit(pz, wz);
        else if (kind == DWVW_SLAB) hit = lane_slab_exit(thickness, pz, wz);
        else {
            dwvu_vec3 normal;
            hit = dwvw_shape_exit_inline(&setup->shape, kind, dwvu_v(px, py, pz), dwvu_v(wx, wy, wz), &normal);
        }
        int exited;
        double step = dwvw_step_length(hit, t, &exited);
        double exponent = L->exponent[l] + (1.0 - stretch) * step;
        double before = L->log_constants[l], first = L->first_constant[l]; /* loaded unconditionally */
        double later = before + log_per_event;
        double log_constants = exited ? before : L->events[l] > 0 ? later : first;
        uint32_t events = L->events[l] + (uint32_t)!exited;
        double log_weight = log_constants - sigma * exponent;
        /* An exited lane keeps the position the step started from: the exit normal is found again
         * from it (lane_end). */
        double flight = exited ? 0.0 : t; /* p + w 0 = p: a store in every lane, no conditional one */
        L->px[l] = px + wx * flight;
        L->py[l] = py + wy * flight;
        L->pz[l] = pz + wz * flight;
        L->exponent[l] = exponent;
        L->log_constants[l] = log_constants;
        L->log_weight[l] = log_weight;
        L->stretch[l] = stretch;
        L->events[l] = events;
        L->exited[l] = exited;
        int flagged = exited | (log_weight < DWVW_LOG_ROULETTE_THRESHOLD) | (events >= max_events);
        L->flagged[l] = flagged;
        any |= flagged;
    }
    return any;
}

/* lanes_step_in for each shape, its exit test written out. */
static int lanes_step_halfspace(guided_lanes *L, const dwvw_estimate_setup *setup, const fast_plan *plan)
{
    return lanes_step_in(L, setup, plan, DWVW_HALFSPACE);
}

static int lanes_step_slab(guided_lanes *L, const dwvw_estimate_setup *setup, const fast_plan *plan)
{
    return lanes_step_in(L, setup, plan, DWVW_SLAB);
}

static int lanes_step_sphere(guided_lanes *L, const dwvw_estimate_setup *setup, const fast_plan *plan)
{
    return lanes_step_in(L, setup, plan, DWVW_SPHERE);
}

/* The branches of guided_walk_in after a flagged step of lane l: 1 and *end filled if its walk
 * ended, else 0 (the walk goes on, its weight perhaps raised by the roulette). */
static int lane_end(guided_lanes *L, int l, const dwvw_estimate_setup *setup, const fast_plan *plan,
                    dwvw_shape_kind kind, dwvw_walk_end *end)
{
    double last_factor = 1.0;
    uint32_t events = L->events[l];
    end->exit_normal = dwvu_v(0.0, 0.0, 0.0);
    if (L->exited[l]) {
        dwvu_vec3 normal;
        (void)dwvw_shape_exit_inline(&setup->shape, kind, dwvu_v(L->px[l], L->py[l], L->pz[l]),
                                     dwvu_v(L->dx[l], L->dy[l], L->dz[l]), &normal);
        if (events > 0) last_factor = L->stretch[l] * plan->inv_albedo_eff; /* s / a */
        end->status = DWVW_EXITED;
        end->exit_normal = normal;
    } else {
        if (L->log_weight[l] < DWVW_LOG_ROULETTE_THRESHOLD) {
            double log_weight = L->log_weight[l];
            int fate = guided_roulette(L->key[l], events, &log_weight);
            if (fate == 0) {
                end->status = DWVW_ABSORBED;
                goto done;
            }
            if (fate == 2) {
                L->log_weight[l] = log_weight;
                L->log_constants[l] = log_weight + setup->medium.sigma_t[0] * L->exponent[l];
            }
        }
        if (events < setup->max_events) return 0;
        end->status = DWVW_TRUNCATED;
    }
done:;
    double weight = end->status == DWVW_ABSORBED ? 0.0 : exp(L->log_weight[l]) * last_factor;
    end->events = events;
    end->weight[0] = isfinite(weight) ? weight : 0.0;
    end->weight[1] = end->weight[2] = 0.0;
    return 1;
}

/* Where the lanes' walks come from and where their ends go: a thread's blocks of a run (walks are
 * numbered in the order the thread starts them, and a ring of DWVW_LANE_RING ends adds them to
 * their blocks in that order, so a block's totals are summed in walk order as in worker()), or a
 * range of walks whose ends are all kept (dwvw_estimate_walks_lanes). */
#define DWVW_LANE_RING 256u
typedef struct lane_slot {
    dwvw_walk_end end;
    block_totals *block;
} lane_slot;

typedef struct lane_feed {
    run_state *state;       /* a run's blocks, or NULL for a range */
    uint64_t next, stop;           /* the next walk index and the end of the current block / range */
    block_totals *block;           /* the current block */
    uint64_t started, committed;   /* walks started by this thread, and added to their blocks */
    lane_slot *ring;
    uint64_t first;                /* a range: its first walk, and where its ends go */
    dwvw_walk_end *ends;
    int exhausted;                 /* a run: no block left */
} lane_feed;

/* Moves a run's feed to the next unclaimed block; 0 when none is left. */
static int claim_block(lane_feed *feed)
{
    run_state *state = feed->state;
    if (feed->exhausted) return 0;
    unsigned block = atomic_fetch_add(&state->next_block, 1u);
    if (block >= state->block_count) {
        feed->exhausted = 1;
        return 0;
    }
    feed->next = (uint64_t)block * state->block_size;
    feed->stop = feed->next + state->block_size;
    if (feed->stop > state->setup->walks) feed->stop = state->setup->walks;
    feed->block = &state->blocks[block];
    return 1;
}

/* The next walk for a lane: its index and sequence number; 0 if there is none (for now: in a run,
 * the ring may be full until an earlier walk ends). */
static int feed_next(lane_feed *feed, uint64_t *index, uint64_t *sequence)
{
    if (!feed->state) {
        if (feed->next >= feed->stop) return 0;
        *sequence = feed->next - feed->first;
        *index = feed->next++;
        return 1;
    }
    if (feed->started - feed->committed >= DWVW_LANE_RING) return 0;
    if (feed->next >= feed->stop && !claim_block(feed)) return 0;
    lane_slot *slot = &feed->ring[feed->started % DWVW_LANE_RING];
    slot->end.status = DWVW_RUNNING;
    slot->block = feed->block;
    *sequence = feed->started++;
    *index = feed->next++;
    return 1;
}

static void feed_done(lane_feed *feed, const dwvw_estimate_setup *setup, uint64_t sequence, const dwvw_walk_end *end)
{
    if (!feed->state) {
        feed->ends[sequence] = *end;
        return;
    }
    feed->ring[sequence % DWVW_LANE_RING].end = *end;
    for (; feed->committed < feed->started; ++feed->committed) {
        lane_slot *slot = &feed->ring[feed->committed % DWVW_LANE_RING];
        if (slot->end.status == DWVW_RUNNING) break;
        add_walk(setup, &slot->end, slot->block);
    }
}

/* Runs every walk of the feed in lanes. */
/* One event of every lane of mixture_walk_in (isotropic medium: phase 1/(4 pi) for both
 * components), in the same arithmetic. The guided direction is formed in every lane; the lanes
 * that picked the classical component (a share q0 of 0.01 or less for auto) have theirs replaced
 * one by one. The weight is a product of ratios, as there: the mixture's denominator does not
 * cancel, so each event keeps its exponential. */
static DWVW_ALWAYS_INLINE int mixture_lanes_step_in(guided_lanes *L, const dwvw_estimate_setup *setup,
                                                    const fast_plan *plan, dwvw_shape_kind kind)
{
    const dwvw_medium *m = &setup->medium;
    const dwvk_dwivedi_event_f *d = &m->dwivedi_event;
    const double sigma = m->sigma_t[0], albedo = m->albedo[0], thickness = setup->shape.thickness;
    const double q0 = setup->guide.q_classical, q1 = plan->q_guided, total = q0 + q1;
    const double phase = DWVK_INV_FOUR_PI, pdf_scale = m->guided_pdf_scale;
    const uint32_t max_events = setup->max_events;
    const uint64_t to_component = DWVW_DIM_COUNTER_OFFSET(DWVW_DIM_CHANNEL, DWVW_DIM_COMPONENT);
    const uint64_t to_direction = DWVW_DIM_COUNTER_OFFSET(DWVW_DIM_CHANNEL, DWVW_DIM_DIRECTION);
    const uint64_t to_distance = DWVW_DIM_COUNTER_OFFSET(DWVW_DIM_CHANNEL, DWVW_DIM_DISTANCE);
    const double sy = plan->sign[0][1], sz = plan->sign[0][2], axis_sign = plan->axis_sign;
    const double kappa = m->dwivedi.kappa, one_minus_kappa = m->dwivedi.one_minus_kappa;
    float ua[DWVW_LANES], ub[DWVW_LANES], udist[DWVW_LANES];
    int guided[DWVW_LANES];
    /* The counter is that of the event's channel dimension (+0); component +1, direction +2,
     * distance +4. */
    for (int l = 0; l < DWVW_LANES; ++l) {
        uint64_t c = L->counter[l];
        guided[l] = !(dwvw_counter_uniform_d(c + to_component) * total < q0);
        dwvk_uniform_pair_f u = dwvw_counter_uniform_pair_f(c + to_direction);
        ua[l] = u.a;
        ub[l] = u.b;
        udist[l] = dwvw_counter_uniform_f(c + to_distance);
        L->counter[l] = c + DWVW_EVENT_COUNTER_STEP;
    }
    double wx[DWVW_LANES], wy[DWVW_LANES], wz[DWVW_LANES];
    for (int l = 0; l < DWVW_LANES; ++l) {
        dwvk_dwivedi_event_cosine_f s = dwvk_dwivedi_event_sample_select_f(d, ua[l]);
        dwvk_unit2_f azimuth = dwvk_azimuth_f(ub[l]);
        double x = (double)azimuth.c * (double)s.sin_theta, y = sy * ((double)azimuth.s * (double)s.sin_theta);
        double z = sz * (double)s.cos_theta;
        double scale = 1.5 - 0.5 * (x * x + y * y + z * z);
        wx[l] = x * scale;
        wy[l] = y * scale;
        wz[l] = z * scale;
    }
    for (int l = 0; l < DWVW_LANES; ++l) {
        if (L->events[l] == 0) { /* the first step keeps the entry direction */
            wx[l] = L->dx[l];
            wy[l] = L->dy[l];
            wz[l] = L->dz[l];
        } else if (!guided[l]) {
            dwvk_uniform_pair_f u = {ua[l], ub[l]};
            dwvu_vec3 w = dwvw_classical_direction(dwvu_v(L->dx[l], L->dy[l], L->dz[l]), 0.0f, u);
            wx[l] = w.x;
            wy[l] = w.y;
            wz[l] = w.z;
        }
    }
    /* Three loops, not one: each lane's chain from the flight's log through the exponential to
     * the weight is long, and short loops let the core run the lanes' chains side by side. */
    double stretch_of[DWVW_LANES], t_of[DWVW_LANES], decay_of[DWVW_LANES];
    int exited_of[DWVW_LANES];
    for (int l = 0; l < DWVW_LANES; ++l) {
        double pz = L->pz[l], z = wz[l];
        double mu = dwvw_clamp_cosine(axis_sign * z);
        double stretch_above = one_minus_kappa + kappa * (1.0 - mu), stretch_below = 1.0 - kappa * mu;
        double stretch = mu >= 0.0 ? stretch_above : stretch_below;
        double t = dwvw_flight(sigma * (guided[l] ? stretch : 1.0), udist[l]);
        double hit;
        if (kind == DWVW_HALFSPACE) hit = lane_halfspace_exit(pz, z);
        else if (kind == DWVW_SLAB) hit = lane_slab_exit(thickness, pz, z);
        else {
            dwvu_vec3 normal;
            hit = dwvw_shape_exit_inline(&setup->shape, kind, dwvu_v(L->px[l], L->py[l], pz), dwvu_v(wx[l], wy[l], z),
                                         &normal);
        }
        int exited;
        t_of[l] = dwvw_step_length(hit, t, &exited);
        stretch_of[l] = stretch;
        exited_of[l] = exited;
    }
    for (int l = 0; l < DWVW_LANES; ++l)
        decay_of[l] = dwvw_grey_decay(sigma, stretch_of[l], t_of[l]);
    int any = 0;
    for (int l = 0; l < DWVW_LANES; ++l) {
        double px = L->px[l], py = L->py[l], pz = L->pz[l], x = wx[l], y = wy[l], z = wz[l];
        int first = L->events[l] == 0, exited = exited_of[l];
        double stretch = stretch_of[l], t = t_of[l];
        double step_phase = first ? 1.0 : phase, pdf_guided = first ? 1.0 : pdf_scale / stretch;
        /* mixture_walk_in's denominator, term by term. */
        double qp0 = q0 * step_phase, qp1 = q1 * pdf_guided, denominator = 0.0;
        if (qp0 > 0.0) denominator += dwvw_grey_term(qp0, 1.0, 1.0, exited);
        if (qp1 > 0.0) denominator += dwvw_grey_term(qp1, stretch, decay_of[l], exited);
        double weight = L->weight[l] * dwvw_grey_ratio(step_phase, albedo, denominator, exited);
        uint32_t events = L->events[l] + (uint32_t)!exited;
        double flight = exited ? 0.0 : t; /* an exited lane keeps its position (lane_end) */
        L->px[l] = px + x * flight;
        L->py[l] = py + y * flight;
        L->pz[l] = pz + z * flight;
        L->dx[l] = x;
        L->dy[l] = y;
        L->dz[l] = z;
        L->weight[l] = weight;
        L->events[l] = events;
        L->exited[l] = exited;
        int flagged = exited | !(weight >= DWVW_ROULETTE_THRESHOLD) | (events >= max_events);
        L->flagged[l] = flagged;
        any |= flagged;
    }
    return any;
}

static int mixture_lanes_step_halfspace(guided_lanes *L, const dwvw_estimate_setup *setup, const fast_plan *plan)
{
    return mixture_lanes_step_in(L, setup, plan, DWVW_HALFSPACE);
}

static int mixture_lanes_step_slab(guided_lanes *L, const dwvw_estimate_setup *setup, const fast_plan *plan)
{
    return mixture_lanes_step_in(L, setup, plan, DWVW_SLAB);
}

static int mixture_lanes_step_sphere(guided_lanes *L, const dwvw_estimate_setup *setup, const fast_plan *plan)
{
    return mixture_lanes_step_in(L, setup, plan, DWVW_SPHERE);
}

/* The branches of mixture_walk_in after a flagged step of lane l, as lane_end for the guided walk. */
static int mixture_lane_end(guided_lanes *L, int l, const dwvw_estimate_setup *setup, dwvw_shape_kind kind,
                            dwvw_walk_end *end)
{
    uint32_t events = L->events[l];
    double weight = L->weight[l];
    end->exit_normal = dwvu_v(0.0, 0.0, 0.0);
    if (L->exited[l]) {
        dwvu_vec3 normal;
        (void)dwvw_shape_exit_inline(&setup->shape, kind, dwvu_v(L->px[l], L->py[l], L->pz[l]),
                                     dwvu_v(L->dx[l], L->dy[l], L->dz[l]), &normal);
        end->status = DWVW_EXITED;
        end->exit_normal = normal;
    } else {
        if (dwvw_grey_goes_on(L->key[l], events, setup->max_events, &weight, &end->status)) {
            L->weight[l] = weight; /* perhaps raised by the roulette */
            return 0;
        }
    }
    end->events = events;
    end->weight[0] = end->status == DWVW_ABSORBED ? 0.0 : weight;
    end->weight[1] = end->weight[2] = 0.0;
    return 1;
}

static inline int lanes_step(guided_lanes *L, const dwvw_estimate_setup *setup, const fast_plan *plan,
                             dwvw_shape_kind kind)
{
    if (plan->walker == DWVW_WALKER_MIXTURE) {
        switch (kind) {
        case DWVW_HALFSPACE: return mixture_lanes_step_halfspace(L, setup, plan);
        case DWVW_SLAB: return mixture_lanes_step_slab(L, setup, plan);
        case DWVW_SPHERE: return mixture_lanes_step_sphere(L, setup, plan);
        }
        return 0;
    }
    switch (kind) {
    case DWVW_HALFSPACE: return lanes_step_halfspace(L, setup, plan);
    case DWVW_SLAB: return lanes_step_slab(L, setup, plan);
    case DWVW_SPHERE: return lanes_step_sphere(L, setup, plan);
    }
    return 0;
}

static inline void lanes_run_in(const dwvw_estimate_setup *setup, const fast_plan *plan, dwvw_shape_kind kind,
                                lane_feed *feed)
{
    guided_lanes L;
    uint64_t sequence[DWVW_LANES];
    int live[DWVW_LANES], live_count = 0;
    for (int l = 0; l < DWVW_LANES; ++l) {
        uint64_t index;
        live[l] = feed_next(feed, &index, &sequence[l]);
        if (live[l]) lane_begin(&L, l, setup, plan, index);
        else lane_begin(&L, l, setup, plan, 0); /* an idle lane computes on a valid state */
        live_count += live[l];
    }
    while (live_count > 0) {
        if (!lanes_step(&L, setup, plan, kind)) continue;
        int freed = 0;
        for (int l = 0; l < DWVW_LANES; ++l) {
            if (!L.flagged[l] || !live[l]) continue;
            dwvw_walk_end end;
            int ended = plan->walker == DWVW_WALKER_MIXTURE ? mixture_lane_end(&L, l, setup, kind, &end)
                                                            : lane_end(&L, l, setup, plan, kind, &end);
            if (!ended) continue;
            feed_done(feed, setup, sequence[l], &end);
            live[l] = 0;
            --live_count;
            freed = 1;
        }
        if (!freed) continue;
        /* Refill every idle lane: a lane left idle by a full ring may go on once the ring drained. */
        for (int l = 0; l < DWVW_LANES; ++l) {
            uint64_t index;
            if (live[l] || !feed_next(feed, &index, &sequence[l])) continue;
            lane_begin(&L, l, setup, plan, index);
            live[l] = 1;
            ++live_count;
        }
    }
}

static void lanes_run(const dwvw_estimate_setup *setup, const fast_plan *plan, lane_feed *feed)
{
    switch (setup->shape.kind) {
    case DWVW_HALFSPACE: lanes_run_in(setup, plan, DWVW_HALFSPACE, feed); return;
    case DWVW_SLAB: lanes_run_in(setup, plan, DWVW_SLAB, feed); return;
    case DWVW_SPHERE: lanes_run_in(setup, plan, DWVW_SPHERE, feed); return;
    }
}

static void *worker(void *arg)
{
    run_state *state = arg;
    if (state->plan.lanes) {
        lane_slot ring[DWVW_LANE_RING];
        lane_feed feed = {.state = state, .ring = ring};
        lanes_run(state->setup, &state->plan, &feed);
        return NULL;
    }
    for (;;) {
        unsigned block = atomic_fetch_add(&state->next_block, 1u);
        if (block >= state->block_count) break;
        uint64_t first = (uint64_t)block * state->block_size;
        uint64_t end = first + state->block_size;
        if (end > state->setup->walks) end = state->setup->walks;
        block_totals *out = &state->blocks[block];
        for (uint64_t i = first; i < end; ++i) {
            dwvw_walk_end walk;
            walk_with_plan(state->setup, &state->plan, i, &walk);
            add_walk(state->setup, &walk, out);
        }
    }
    return NULL;
}

int dwvw_estimate_walks_lanes(const dwvw_estimate_setup *setup, uint64_t first, uint64_t count, dwvw_walk_end *ends)
{
    fast_plan plan;
    make_plan(setup, dwvw_estimate_walker(setup), &plan);
    if (!plan.lanes) return 0;
    lane_feed feed = {.state = NULL, .next = first, .stop = first + count, .first = first, .ends = ends};
    lanes_run(setup, &plan, &feed);
    return 1;
}

int dwvw_estimate_run(const dwvw_estimate_setup *setup, dwvw_estimate_totals *totals)
{
    double start = dwvu_clock_seconds();
    run_state state;
    state.setup = setup;
    make_plan(setup, dwvw_estimate_walker(setup), &state.plan);
    /* Blocks depend on the walk count only, never on the threads: fixed summation order. */
    state.block_size = (setup->walks + MAX_BLOCKS - 1) / MAX_BLOCKS;
    if (state.block_size < 256) state.block_size = 256;
    state.block_count = (uint32_t)((setup->walks + state.block_size - 1) / state.block_size);
    atomic_init(&state.next_block, 0u);
    state.blocks = calloc(state.block_count, sizeof *state.blocks);
    if (!state.blocks) return -1;

    uint32_t threads = setup->threads < 1 ? 1 : setup->threads > MAX_THREADS ? MAX_THREADS : setup->threads;
    if (threads > state.block_count) threads = state.block_count;
    dwvu_parallel_run(threads, worker, &state);

    memset(totals, 0, sizeof *totals);
    for (uint32_t b = 0; b < state.block_count; ++b) {
        for (int c = 0; c < DWVW_MAX_CHANNELS; ++c) {
            totals->sum[c] += state.blocks[b].sum[c];
            totals->sum_squares[c] += state.blocks[b].sum_squares[c];
            totals->truncated_weight[c] += state.blocks[b].truncated_weight[c];
        }
        totals->events += state.blocks[b].events;
        totals->truncated_walks += state.blocks[b].truncated_walks;
    }
    /* Blocks' squared deviations about the overall mean (Chan, Golub, LeVeque 1979): in block
     * order, so the result is the same for any thread count. */
    for (int c = 0; c < DWVW_MAX_CHANNELS; ++c) {
        double mean = setup->walks ? totals->sum[c] / (double)setup->walks : 0.0;
        totals->m2[c] = 0.0;
        for (uint32_t b = 0; b < state.block_count; ++b) {
            const block_totals *block = &state.blocks[b];
            double n = (double)block->walks, shift = block->walks ? block->sum[c] / n - mean : 0.0;
            totals->m2[c] += block->m2[c] + n * shift * shift;
        }
    }
    free(state.blocks);
    totals->seconds = dwvu_clock_seconds() - start;
    return 0;
}
