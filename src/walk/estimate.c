/* The estimator: the walker a setup takes and its plan, and the runs, on a thread pool in fixed
 * blocks. The walkers themselves: the general engine (walk.c) through general_walk below, the
 * fast paths (estimate_fast.c) and the lanes (estimate_lanes.c). */
#include "estimate.h"

#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "estimate_walkers.h"
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

/* A walk by the general engine (walk.c), driven as the baker drives it: closest point, sample,
 * ray, complete. */
static void general_walk(const dwvw_estimate_setup *setup, uint64_t key, dwvw_walk_end *end)
{
    dwvw_walk walk;
    dwvw_walk_begin(&walk, &setup->medium, &setup->guide, key, setup->max_events, DWVW_ENTRY_POINT,
                    dwvw_entry_direction(setup, key), DWVW_ENTRY_NORMAL);
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

/* The guided part of a setup when it is one component about an axis fixed for the whole walk:
 * its weight q (the rest is classical) and axis; 0 if the guided part is anything else. */
static double fixed_guide(const dwvw_estimate_setup *setup, dwvu_vec3 *axis)
{
    const dwvw_guide *guide = &setup->guide;
    int halfspace = setup->shape.kind == DWVW_HALFSPACE;
    int parts = (guide->q_poe > 0.0) + (guide->q_closest > 0.0) + (guide->q_incident > 0.0) + (guide->q_backward > 0.0);
    if (parts != 1) return 0.0;
    if (guide->q_poe > 0.0) {
        *axis = DWVW_ENTRY_NORMAL;
        return guide->q_poe;
    }
    /* The half-space's closest point is always on its one plane, and the first step's probe into it
     * finds no opposite interface, so there closest and backward guide about the entry normal. */
    if (halfspace && guide->q_closest > 0.0) {
        *axis = DWVW_ENTRY_NORMAL;
        return guide->q_closest;
    }
    if (halfspace && guide->q_backward > 0.0) {
        *axis = DWVW_ENTRY_NORMAL;
        return guide->q_backward;
    }
    if (guide->q_incident > 0.0 && guide->patch_count == 1) {
        *axis = guide->patches[0].normal;
        return guide->q_incident;
    }
    return 0.0;
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

/* Fills plan->aligned and its tables if the turned frames are signed permutations. */
static void plan_alignment(dwvw_fast_plan *plan)
{
    plan->aligned = 0;
    for (int q = 0; q < 4; ++q) {
        const dwvu_frame *f = &plan->turned[q];
        for (int i = 0; i < 3; ++i) {
            double parts[3] = {dwvw_vec3_component(f->t, i), dwvw_vec3_component(f->s, i),
                               dwvw_vec3_component(f->n, i)};
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
        double a = dwvw_vec3_component(plan->axis, i);
        if (a == 0.0) continue;
        if (a != 1.0 && a != -1.0) return;
        ++nonzero;
        plan->axis_index = i;
        plan->axis_sign = a;
    }
    plan->aligned = nonzero == 1;
}

/* What a run's walker needs, worked out once per run: for the guided and mixture walkers the axis,
 * its turned frames, the guided weight's constants and whether the run takes lanes. */
static void make_plan(const dwvw_estimate_setup *setup, dwvw_walker walker, dwvw_fast_plan *plan)
{
    const dwvw_medium *m = &setup->medium;
    memset(plan, 0, sizeof *plan);
    plan->walker = walker;
    if (walker != DWVW_WALKER_GUIDED && walker != DWVW_WALKER_MIXTURE) return;
    plan->axis = DWVW_ENTRY_NORMAL;
    plan->q_guided = fixed_guide(setup, &plan->axis);
    dwvu_frame frame = dwvu_frame_about(plan->axis);
    for (int q = 0; q < 4; ++q) plan->turned[q] = dwvu_frame_turned(&frame, q);
    plan_alignment(plan);
    plan->log_per_event = log(m->albedo[0] / m->dwivedi.albedo_eff);
    plan->inv_albedo_eff = 1.0 / m->dwivedi.albedo_eff;
    plan->first_known = !setup->incidence_diffuse;
    if (plan->first_known) {
        double s0 = dwvk_dwivedi_stretch_d(&m->dwivedi, dwvw_cosine(dwvw_entry_direction(setup, 0u), plan->axis));
        plan->log_first = log(m->albedo[0] / s0);
    }
    /* Lanes take a frame about a z axis (every axis of the analytic shapes), the one case
     * guided_lanes_step_in (estimate_lanes.c) writes out: t = (1, 0, 0), s = (0, +-1, 0),
     * n = (0, 0, +-1). */
    int z_frame = plan->aligned && plan->axis_index == 2 && plan->index[0][0] == 0 && plan->index[0][1] == 1 &&
                  plan->index[0][2] == 2 && plan->sign[0][0] == 1.0;
    /* The mixture in lanes for an isotropic medium (mixture_lanes_step_in, estimate_lanes.c);
     * anisotropic media take it one walk at a time. */
    int lane_walker = walker == DWVW_WALKER_GUIDED || (walker == DWVW_WALKER_MIXTURE && m->g == 0.0);
    plan->lanes = lane_walker && z_frame && !setup->single_lane;
}

/* Walk number `index` of a setup by its plan's walker. */
static void walk_with_plan(const dwvw_estimate_setup *setup, const dwvw_fast_plan *plan, uint64_t index,
                           dwvw_walk_end *end)
{
    uint64_t key = dwvk_rng_key(setup->seed, index, 0);
    if (plan->walker == DWVW_WALKER_GENERAL) general_walk(setup, key, end);
    else dwvw_fast_walk(setup, plan, key, end);
}

void dwvw_estimate_walk(const dwvw_estimate_setup *setup, dwvw_walker walker, uint64_t index, dwvw_walk_end *end)
{
    dwvw_fast_plan plan;
    make_plan(setup, walker, &plan);
    walk_with_plan(setup, &plan, index, end);
}

/* A thread of a run: blocks claimed one at a time until none is left, each block's walks added in
 * walk order (in lanes, dwvw_lanes_run_blocks keeps that order). */
static void *worker(void *arg)
{
    dwvw_estimate_run_state *state = arg;
    if (state->plan.lanes) {
        dwvw_lanes_run_blocks(state);
        return NULL;
    }
    for (;;) {
        unsigned block = atomic_fetch_add(&state->next_block, 1u);
        if (block >= state->block_count) break;
        uint64_t first = (uint64_t)block * state->block_size;
        uint64_t end = first + state->block_size;
        if (end > state->setup->walks) end = state->setup->walks;
        dwvw_block_totals *out = &state->blocks[block];
        for (uint64_t i = first; i < end; ++i) {
            dwvw_walk_end walk;
            walk_with_plan(state->setup, &state->plan, i, &walk);
            dwvw_block_add_walk(state->setup, &walk, out);
        }
    }
    return NULL;
}

int dwvw_estimate_walks_lanes(const dwvw_estimate_setup *setup, uint64_t first, uint64_t count, dwvw_walk_end *ends)
{
    dwvw_fast_plan plan;
    make_plan(setup, dwvw_estimate_walker(setup), &plan);
    if (!plan.lanes) return 0;
    dwvw_lanes_run_range(setup, &plan, first, count, ends);
    return 1;
}

int dwvw_estimate_run(const dwvw_estimate_setup *setup, dwvw_estimate_totals *totals)
{
    double start = dwvu_clock_seconds();
    dwvw_estimate_run_state state;
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
            const dwvw_block_totals *block = &state.blocks[b];
            double n = (double)block->walks, shift = block->walks ? block->sum[c] / n - mean : 0.0;
            totals->m2[c] += block->m2[c] + n * shift * shift;
        }
    }
    free(state.blocks);
    totals->seconds = dwvu_clock_seconds() - start;
    return 0;
}
