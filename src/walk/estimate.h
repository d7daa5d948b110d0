/* Walk-level estimates with a known scoring on the analytic shapes (dwivedi estimate): many
 * walks on a thread pool, summed in fixed blocks so that the result is bit-identical for any
 * thread count. */
#ifndef DWV_WALK_ESTIMATE_H
#define DWV_WALK_ESTIMATE_H

#include "geometry.h"
#include "walk.h"

enum { DWVW_LIGHT_FRONT = 1, DWVW_LIGHT_BACK = 2 };

typedef struct dwvw_estimate_setup {
    dwvw_shape shape;
    dwvw_medium medium;
    dwvw_guide guide;
    int incidence_diffuse;   /* cosine-weighted diffuse transmission into the medium */
    double incidence_cosine; /* otherwise: the entry direction's cosine to the inward normal */
    int light;               /* DWVW_LIGHT_* bits: which exits score */
    uint64_t walks, seed;
    uint32_t threads, max_events;
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
/* Runs setup->walks walks; 0 on success, -1 if threads could not be started. */
int dwvw_estimate_run(const dwvw_estimate_setup *setup, dwvw_estimate_totals *totals);

#endif
