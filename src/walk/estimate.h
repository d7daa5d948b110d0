/* Walk-level estimates with a known scoring on the analytic shapes (dwivedi estimate): many
 * walks on a thread pool, summed in fixed blocks so that the result is bit-identical for any
 * thread count. */
#ifndef DWV_WALK_ESTIMATE_H
#define DWV_WALK_ESTIMATE_H

#include "geometry.h"
#include "walk.h"

enum { DWVW_LIGHT_FRONT = 1, DWVW_LIGHT_BACK = 2 };
/* The API passes DWV_LIGHT_FRONT / BACK / BOTH bits through: the same bits. */
_Static_assert((int)DWVW_LIGHT_FRONT == DWV_LIGHT_FRONT && (int)DWVW_LIGHT_BACK == DWV_LIGHT_BACK &&
                   (int)(DWVW_LIGHT_FRONT | DWVW_LIGHT_BACK) == DWV_LIGHT_BOTH,
               "DWVW_LIGHT_* must equal DWV_LIGHT_* (capi/dwivedi.h)");

typedef struct dwvw_estimate_setup {
    dwvw_shape shape;
    dwvw_medium medium;
    dwvw_guide guide;
    int incidence_diffuse;   /* cosine-weighted diffuse transmission into the medium */
    double incidence_cosine; /* otherwise: the entry direction's cosine to the inward normal */
    int light;               /* DWVW_LIGHT_* bits: which exits score */
    uint64_t walks, seed;
    uint32_t threads, max_events;
    int general_path;        /* 1: every walk through dwvw_walk_*, never the fast path (for tests) */
    int single_lane;         /* 1: the fast paths one walk at a time, never in lanes (for tests) */
} dwvw_estimate_setup;

typedef struct dwvw_estimate_totals {
    double sum[DWVW_MAX_CHANNELS], sum_squares[DWVW_MAX_CHANNELS];
    double truncated_weight[DWVW_MAX_CHANNELS]; /* weight held by walks the event cap ended */
    double m2[DWVW_MAX_CHANNELS]; /* sum of squared deviations of the scores from their mean */
    uint64_t events, truncated_walks;
    double seconds;
} dwvw_estimate_totals;

/* The lit patches the incident technique aims at, for a shape and its lighting; returns the count. */
int dwvw_estimate_light_patches(const dwvw_shape *shape, int light, dwvw_light_patch *patches);
/* How one walk ended: its status, scattering events, weight (0 unless exited or truncated) and
 * exit normal. */
typedef struct dwvw_walk_end {
    dwvw_status status;
    uint32_t events;
    double weight[DWVW_MAX_CHANNELS];
    dwvu_vec3 exit_normal;
} dwvw_walk_end;

/* Which walker dwvw_estimate_run uses for a setup. The fast paths are for grey media whose guided
 * part is one component about an axis fixed for the whole walk (poe; incident with one patch;
 * closest and backward on the half-space, where the closest normal is the entry normal and no
 * opposite interface exists): GUIDED for that component alone in an isotropic medium, MIXTURE for
 * it with a classical share (auto, cycles), CLASSICAL for classical alone. They make the same walks
 * as the general path from the same random numbers; GUIDED and CLASSICAL cancel the weight's
 * terms (see estimate_fast.c), MIXTURE forms it as the general path does. */
typedef enum dwvw_walker {
    DWVW_WALKER_GENERAL = 0,
    DWVW_WALKER_CLASSICAL = 1,
    DWVW_WALKER_GUIDED = 2,
    DWVW_WALKER_MIXTURE = 3
} dwvw_walker;
dwvw_walker dwvw_estimate_walker(const dwvw_estimate_setup *setup);
/* Walk number `index` of a setup, by the given walker (one that dwvw_estimate_walker allows, or
 * the general one). */
void dwvw_estimate_walk(const dwvw_estimate_setup *setup, dwvw_walker walker, uint64_t index, dwvw_walk_end *end);

/* How many walks the guided and mixture walkers advance in lock-step (estimate_lanes.c): 16, two
 * AVX-512 vectors of doubles (or four of AVX2) per stage, so that a step's fixed work (its call,
 * constants, the test for flagged lanes) is shared by more events: 1.18x the events per second
 * of 8 lanes for poe on the half-space, 32 lanes no faster (docs/speed.md). At most 32: the
 * flagged lanes are a 32-bit mask. */
#define DWVW_LANES 16
/* Walks first .. first + count - 1 of a setup in lock-step lanes, their ends into ends[0 ..
 * count - 1], as dwvw_estimate_run takes them; returns 1, or 0 (nothing written) where the run
 * takes no lanes (the general and classical walkers, the mixture in an anisotropic medium, an axis
 * not along z, or setup->single_lane). */
int dwvw_estimate_walks_lanes(const dwvw_estimate_setup *setup, uint64_t first, uint64_t count, dwvw_walk_end *ends);

/* Runs setup->walks walks; 0 on success, -1 if threads could not be started. */
int dwvw_estimate_run(const dwvw_estimate_setup *setup, dwvw_estimate_totals *totals);

#endif
