/* The estimator's fast paths (src/walk/estimate_fast.c: classical alone, one guided component about a
 * fixed axis, and that component mixed with classical) against the general walk (dwvw_walk_sample / dwvw_walk_complete) from the same random
 * numbers:
 *   - dwvw_estimate_walker picks the fast path exactly where it applies (grey medium; classical
 *     alone; one guided component with a fixed axis, alone in an isotropic medium, else mixed with
 *     classical) and the general one elsewhere (colour, two lit patches, closest and backward off
 *     the half-space);
 *   - walk by walk, the fast path ends the same way (status, events, exit normal) with the same
 *     weight up to rounding: WEIGHT_TOLERANCE relative. The guided and classical paths form the
 *     weight differently (they cancel the stretch and sum the exponents in logs; the general path
 *     multiplies ratios of double pdfs), so equality to the last bit is not expected there (the
 *     mixture path repeats the general arithmetic and is bit-identical); a weight off by one
 *     step's factor is off by far more than this;
 *   - dwvw_estimate_run gives the same mean (to WEIGHT_TOLERANCE) and the same event and truncation
 *     counts either way, and the fast path is bit-identical for 1, 2 and 3 threads;
 *   - the lock-step lanes (dwvw_estimate_walks_lanes: the guided walker, and the mixture in an
 *     isotropic medium) end every walk exactly as the same walker one walk at a time, weight
 *     bit for bit, and a run's totals are bit-identical with and without lanes;
 *   - planted: a fast-path weight without the first step's 1/s0 (a plausible slip when cancelling
 *     terms) is caught by the walk-by-walk comparison.
 * The estimates themselves are judged against references by tests/unit/test_walk_*.c, which now
 * run through the fast paths wherever these apply. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "walk/estimate.h"

#define WEIGHT_TOLERANCE 1e-12
enum { WALKS = 4000 };

typedef struct fast_case {
    const char *label;
    dwvw_shape_kind shape;
    double size; /* slab thickness or sphere radius */
    dwvw_technique technique;
    double albedo, g;
    int light, diffuse;
    dwvw_walker expected;
    uint32_t max_events; /* 0: 10^6 */
} fast_case;

static const fast_case CASES[] = {
    {"halfspace poe 0.99", DWVW_HALFSPACE, 0.0, DWVW_POE, 0.99, 0.0, DWVW_LIGHT_FRONT, 0, DWVW_WALKER_GUIDED, 0},
    {"halfspace poe 0.3", DWVW_HALFSPACE, 0.0, DWVW_POE, 0.3, 0.0, DWVW_LIGHT_FRONT, 0, DWVW_WALKER_GUIDED, 0},
    {"halfspace poe 0.05 (clamped v)", DWVW_HALFSPACE, 0.0, DWVW_POE, 0.05, 0.0, DWVW_LIGHT_FRONT, 0,
     DWVW_WALKER_GUIDED, 0},
    {"halfspace poe 0", DWVW_HALFSPACE, 0.0, DWVW_POE, 0.0, 0.0, DWVW_LIGHT_FRONT, 0, DWVW_WALKER_GUIDED, 0},
    {"halfspace poe 1, cap 200", DWVW_HALFSPACE, 0.0, DWVW_POE, 1.0, 0.0, DWVW_LIGHT_FRONT, 0, DWVW_WALKER_GUIDED,
     200},
    {"halfspace poe 0.999 diffuse", DWVW_HALFSPACE, 0.0, DWVW_POE, 0.999, 0.0, DWVW_LIGHT_FRONT, 1,
     DWVW_WALKER_GUIDED, 0},
    {"halfspace closest 0.9", DWVW_HALFSPACE, 0.0, DWVW_CLOSEST, 0.9, 0.0, DWVW_LIGHT_FRONT, 0, DWVW_WALKER_GUIDED, 0},
    {"halfspace incident 0.9", DWVW_HALFSPACE, 0.0, DWVW_INCIDENT, 0.9, 0.0, DWVW_LIGHT_FRONT, 0, DWVW_WALKER_GUIDED,
     0},
    {"halfspace backward 0.9", DWVW_HALFSPACE, 0.0, DWVW_BACKWARD, 0.9, 0.0, DWVW_LIGHT_FRONT, 0, DWVW_WALKER_GUIDED,
     0},
    {"slab 4 poe 0.99 back-lit", DWVW_SLAB, 4.0, DWVW_POE, 0.99, 0.0, DWVW_LIGHT_BACK, 0, DWVW_WALKER_GUIDED, 0},
    {"slab 16 incident 0.99 back-lit", DWVW_SLAB, 16.0, DWVW_INCIDENT, 0.99, 0.0, DWVW_LIGHT_BACK, 1,
     DWVW_WALKER_GUIDED, 0},
    {"sphere 2 incident 0.9 back-lit", DWVW_SPHERE, 2.0, DWVW_INCIDENT, 0.9, 0.0, DWVW_LIGHT_BACK, 0,
     DWVW_WALKER_GUIDED, 0},
    {"sphere 2 poe 0.99", DWVW_SPHERE, 2.0, DWVW_POE, 0.99, 0.0, DWVW_LIGHT_FRONT | DWVW_LIGHT_BACK, 1, DWVW_WALKER_GUIDED, 0},
    {"halfspace classical 0.99", DWVW_HALFSPACE, 0.0, DWVW_CLASSICAL, 0.99, 0.0, DWVW_LIGHT_FRONT, 0,
     DWVW_WALKER_CLASSICAL, 0},
    {"slab 1 classical 0.9 g 0.5", DWVW_SLAB, 1.0, DWVW_CLASSICAL, 0.9, 0.5, DWVW_LIGHT_FRONT | DWVW_LIGHT_BACK, 1,
     DWVW_WALKER_CLASSICAL, 0},
    {"sphere 2 classical 0.99 g -0.3", DWVW_SPHERE, 2.0, DWVW_CLASSICAL, 0.99, -0.3, DWVW_LIGHT_BACK, 0,
     DWVW_WALKER_CLASSICAL, 0},
    {"halfspace classical 1, cap 50", DWVW_HALFSPACE, 0.0, DWVW_CLASSICAL, 1.0, 0.0, DWVW_LIGHT_FRONT, 0,
     DWVW_WALKER_CLASSICAL, 50},
    {"halfspace poe 0.9 g 0.3", DWVW_HALFSPACE, 0.0, DWVW_POE, 0.9, 0.3, DWVW_LIGHT_FRONT, 0, DWVW_WALKER_MIXTURE, 0},
    {"halfspace auto 0.99", DWVW_HALFSPACE, 0.0, DWVW_AUTO, 0.99, 0.0, DWVW_LIGHT_FRONT, 0, DWVW_WALKER_MIXTURE, 0},
    {"halfspace auto 0.999 diffuse", DWVW_HALFSPACE, 0.0, DWVW_AUTO, 0.999, 0.0, DWVW_LIGHT_FRONT, 1,
     DWVW_WALKER_MIXTURE, 0},
    {"halfspace auto 0.1 (classical)", DWVW_HALFSPACE, 0.0, DWVW_AUTO, 0.1, 0.0, DWVW_LIGHT_FRONT, 0,
     DWVW_WALKER_CLASSICAL, 0},
    {"halfspace cycles 0.9", DWVW_HALFSPACE, 0.0, DWVW_CYCLES, 0.9, 0.0, DWVW_LIGHT_FRONT, 0, DWVW_WALKER_MIXTURE, 0},
    {"halfspace cycles 1, cap 100", DWVW_HALFSPACE, 0.0, DWVW_CYCLES, 1.0, 0.0, DWVW_LIGHT_FRONT, 0, DWVW_WALKER_MIXTURE,
     100},
    {"slab 16 auto 0.99 back-lit", DWVW_SLAB, 16.0, DWVW_AUTO, 0.99, 0.0, DWVW_LIGHT_BACK, 0, DWVW_WALKER_MIXTURE, 0},
    {"slab 1 auto 0.9 g 0.5 back-lit", DWVW_SLAB, 1.0, DWVW_AUTO, 0.9, 0.5, DWVW_LIGHT_BACK, 1, DWVW_WALKER_MIXTURE,
     0},
    {"sphere 4 auto 0.99 back-lit", DWVW_SPHERE, 4.0, DWVW_AUTO, 0.99, 0.0, DWVW_LIGHT_BACK, 0, DWVW_WALKER_MIXTURE,
     0},
    {"sphere 2 auto 1 g -0.3, cap 300", DWVW_SPHERE, 2.0, DWVW_AUTO, 1.0, -0.3, DWVW_LIGHT_BACK, 0,
     DWVW_WALKER_MIXTURE, 300},
    /* The general path only. */
    {"slab 4 cycles 0.9", DWVW_SLAB, 4.0, DWVW_CYCLES, 0.9, 0.0, DWVW_LIGHT_BACK, 0, DWVW_WALKER_GENERAL, 0},
    {"slab 4 closest 0.9", DWVW_SLAB, 4.0, DWVW_CLOSEST, 0.9, 0.0, DWVW_LIGHT_BACK, 0, DWVW_WALKER_GENERAL, 0},
    {"slab 4 backward 0.9", DWVW_SLAB, 4.0, DWVW_BACKWARD, 0.9, 0.0, DWVW_LIGHT_BACK, 0, DWVW_WALKER_GENERAL, 0},
    {"slab 4 incident 0.9 both lit", DWVW_SLAB, 4.0, DWVW_INCIDENT, 0.9, 0.0, DWVW_LIGHT_FRONT | DWVW_LIGHT_BACK, 0, DWVW_WALKER_GENERAL,
     0},
};

static void make_setup(const fast_case *c, int channels, dwvw_estimate_setup *setup)
{
    memset(setup, 0, sizeof *setup);
    setup->shape.kind = c->shape;
    setup->shape.thickness = c->size;
    setup->shape.radius = c->size;
    double sigma_t[3] = {1.0, 1.0, 1.0}, albedo[3] = {c->albedo, c->albedo, c->albedo};
    dwvw_medium_init(&setup->medium, channels, sigma_t, albedo, c->g);
    setup->incidence_diffuse = c->diffuse;
    setup->incidence_cosine = 1.0;
    setup->light = c->light;
    setup->walks = WALKS;
    setup->seed = 0xfa57u;
    setup->threads = 1;
    setup->max_events = c->max_events ? c->max_events : 1000000u;
    dwvw_light_patch patches[DWVW_MAX_PATCHES];
    int count = dwvw_estimate_light_patches(&setup->shape, c->light, patches);
    dwvw_guide_init(&setup->guide, c->technique, &setup->medium, patches, count);
}

static double relative_gap(double a, double b)
{
    double scale = fabs(a) > fabs(b) ? fabs(a) : fabs(b);
    return scale == 0.0 ? 0.0 : fabs(a - b) / scale;
}

typedef struct comparison {
    uint64_t differing_ends; /* status, events or exit normal differ */
    double worst_weight_gap;
    uint64_t events, exited, truncated;
} comparison;

/* Walk by walk, `walker` against the general walk; `planted` scales each fast weight by the first
 * step's stretch s0 (dropping its 1/s0). */
static comparison compare_walks(const dwvw_estimate_setup *setup, dwvw_walker walker, int planted)
{
    comparison r = {0u, 0.0, 0u, 0u, 0u};
    for (uint64_t i = 0; i < setup->walks; ++i) {
        dwvw_walk_end fast, general;
        dwvw_estimate_walk(setup, walker, i, &fast);
        dwvw_estimate_walk(setup, DWVW_WALKER_GENERAL, i, &general);
        if (planted && fast.events > 0) fast.weight[0] *= 1.0 + setup->medium.dwivedi.kappa; /* s0 at normal incidence */
        int same_end = fast.status == general.status && fast.events == general.events &&
                       (fast.status != DWVW_EXITED || (fast.exit_normal.x == general.exit_normal.x &&
                                                       fast.exit_normal.y == general.exit_normal.y &&
                                                       fast.exit_normal.z == general.exit_normal.z));
        r.differing_ends += !same_end;
        double gap = relative_gap(fast.weight[0], general.weight[0]);
        if (gap > r.worst_weight_gap) r.worst_weight_gap = gap;
        r.events += general.events;
        r.exited += general.status == DWVW_EXITED;
        r.truncated += general.status == DWVW_TRUNCATED;
    }
    return r;
}

static void test_case(const fast_case *c)
{
    dwvw_estimate_setup setup;
    make_setup(c, 1, &setup);
    dwvw_walker walker = dwvw_estimate_walker(&setup);
    CHECK(walker == c->expected, "%s: walker %d, expected %d", c->label, (int)walker, (int)c->expected);

    /* Colour always takes the general path; so does a setup that asks for it. */
    dwvw_estimate_setup colour;
    make_setup(c, 3, &colour);
    CHECK(dwvw_estimate_walker(&colour) == DWVW_WALKER_GENERAL, "%s: three channels take walker %d", c->label,
          (int)dwvw_estimate_walker(&colour));
    dwvw_estimate_setup forced = setup;
    forced.general_path = 1;
    CHECK(dwvw_estimate_walker(&forced) == DWVW_WALKER_GENERAL, "%s: general_path = 1 takes walker %d", c->label,
          (int)dwvw_estimate_walker(&forced));
    if (walker == DWVW_WALKER_GENERAL) {
        printf("  %-34s general path\n", c->label);
        return;
    }

    comparison r = compare_walks(&setup, walker, 0);
    printf("  %-34s %s: %llu walks, %llu events, %llu exited, %llu truncated; ends differ %llu, worst weight gap "
           "%.2e\n",
           c->label, walker == DWVW_WALKER_GUIDED ? "guided" : walker == DWVW_WALKER_MIXTURE ? "mixture" : "classical", (unsigned long long)setup.walks,
           (unsigned long long)r.events, (unsigned long long)r.exited, (unsigned long long)r.truncated,
           (unsigned long long)r.differing_ends, r.worst_weight_gap);
    CHECK(r.differing_ends == 0, "%s: %llu walks end differently on the fast path", c->label,
          (unsigned long long)r.differing_ends);
    CHECK(r.worst_weight_gap <= WEIGHT_TOLERANCE, "%s: weights differ by %.3g relative", c->label, r.worst_weight_gap);

    /* Lock-step lanes (the guided walker, and the mixture in an isotropic medium; every axis here is
     * along z) against the same walks one at a time: the same ends and weights to the last bit. */
    if (walker == DWVW_WALKER_GUIDED || (walker == DWVW_WALKER_MIXTURE && c->g == 0.0)) {
        static dwvw_walk_end lanes[WALKS];
        CHECK(dwvw_estimate_walks_lanes(&setup, 0, setup.walks, lanes) == 1, "%s: no lanes", c->label);
        uint64_t differing = 0;
        for (uint64_t i = 0; i < setup.walks; ++i) {
            dwvw_walk_end one;
            dwvw_estimate_walk(&setup, walker, i, &one);
            const dwvw_walk_end *l = &lanes[i];
            int same = one.status == l->status && one.events == l->events &&
                       memcmp(&one.weight[0], &l->weight[0], sizeof(double)) == 0 &&
                       (one.status != DWVW_EXITED ||
                        (one.exit_normal.x == l->exit_normal.x && one.exit_normal.y == l->exit_normal.y &&
                         one.exit_normal.z == l->exit_normal.z));
            differing += !same;
        }
        printf("  %-34s lanes of %d: %llu of %llu walks differ from one at a time\n", c->label, DWVW_LANES,
               (unsigned long long)differing, (unsigned long long)setup.walks);
        CHECK(differing == 0, "%s: %llu walks differ in lanes", c->label, (unsigned long long)differing);
        dwvw_estimate_setup single = setup;
        single.single_lane = 1;
        CHECK(dwvw_estimate_walks_lanes(&single, 0, setup.walks, lanes) == 0, "%s: single_lane still takes lanes",
              c->label);
    } else {
        dwvw_walk_end unused[1];
        CHECK(dwvw_estimate_walks_lanes(&setup, 0, 1, unused) == 0, "%s: lanes for walker %d", c->label, (int)walker);
    }

    /* Whole runs: fast (1, 2, 3 threads) against general. */
    dwvw_estimate_totals general, fast[3];
    CHECK(dwvw_estimate_run(&forced, &general) == 0, "%s: general run failed", c->label);
    for (uint32_t t = 0; t < 3; ++t) {
        dwvw_estimate_setup threaded = setup;
        threaded.threads = t + 1;
        CHECK(dwvw_estimate_run(&threaded, &fast[t]) == 0, "%s: fast run failed", c->label);
    }
    CHECK(relative_gap(fast[0].sum[0], general.sum[0]) <= WEIGHT_TOLERANCE && fast[0].events == general.events &&
              fast[0].truncated_walks == general.truncated_walks,
          "%s: run sums %.17g vs %.17g, events %llu vs %llu", c->label, fast[0].sum[0], general.sum[0],
          (unsigned long long)fast[0].events, (unsigned long long)general.events);
    /* Lanes or not, a run's totals are the same to the last bit (ends added in walk order). */
    dwvw_estimate_setup single = setup;
    single.single_lane = 1;
    single.threads = 2;
    dwvw_estimate_totals one_at_a_time;
    CHECK(dwvw_estimate_run(&single, &one_at_a_time) == 0, "%s: single-lane run failed", c->label);
    CHECK(memcmp(one_at_a_time.sum, fast[0].sum, sizeof fast[0].sum) == 0 &&
              memcmp(one_at_a_time.sum_squares, fast[0].sum_squares, sizeof fast[0].sum_squares) == 0 &&
              memcmp(one_at_a_time.m2, fast[0].m2, sizeof fast[0].m2) == 0 &&
              memcmp(one_at_a_time.truncated_weight, fast[0].truncated_weight, sizeof fast[0].truncated_weight) == 0 &&
              one_at_a_time.events == fast[0].events && one_at_a_time.truncated_walks == fast[0].truncated_walks,
          "%s: one walk at a time sums %.17g, the default run %.17g", c->label, one_at_a_time.sum[0], fast[0].sum[0]);
    for (int t = 1; t < 3; ++t)
        CHECK(memcmp(&fast[t].sum[0], &fast[0].sum[0], sizeof(double)) == 0 &&
                  memcmp(&fast[t].sum_squares[0], &fast[0].sum_squares[0], sizeof(double)) == 0 &&
                  fast[t].events == fast[0].events,
              "%s: %d threads give %.17g, 1 thread %.17g", c->label, t + 1, fast[t].sum[0], fast[0].sum[0]);
}

int main(void)
{
    printf("fast paths against the general walk, walk by walk (weights within %.0e relative)\n", WEIGHT_TOLERANCE);
    for (size_t i = 0; i < sizeof CASES / sizeof CASES[0]; ++i) test_case(&CASES[i]);

    /* Planted: the guided fast path without the first step's 1/s0. */
    dwvw_estimate_setup setup;
    make_setup(&CASES[0], 1, &setup);
    comparison planted = compare_walks(&setup, DWVW_WALKER_GUIDED, 1);
    printf("  planted (first step's 1/s0 dropped): worst weight gap %.2e, rejected\n", planted.worst_weight_gap);
    CHECK(planted.worst_weight_gap > WEIGHT_TOLERANCE, "the planted weight passes: %.3g", planted.worst_weight_gap);
    /* Planted: lanes' ends compared with the walks one further on (a lane that took the wrong walk,
     * or ends filed under the wrong index) must differ almost everywhere. */
    static dwvw_walk_end lanes[WALKS];
    CHECK(dwvw_estimate_walks_lanes(&setup, 0, setup.walks, lanes) == 1, "planted: no lanes");
    uint64_t shifted_differ = 0;
    for (uint64_t i = 0; i + 1 < setup.walks; ++i) {
        dwvw_walk_end next;
        dwvw_estimate_walk(&setup, DWVW_WALKER_GUIDED, i + 1, &next);
        shifted_differ +=
            memcmp(&next.weight[0], &lanes[i].weight[0], sizeof(double)) != 0 || next.events != lanes[i].events;
    }
    printf("  planted (lanes against the next walk): %llu of %llu differ, rejected\n",
           (unsigned long long)shifted_differ, (unsigned long long)setup.walks - 1);
    CHECK(shifted_differ > setup.walks / 2, "the shifted lanes pass: only %llu differ",
          (unsigned long long)shifted_differ);
    return check_report("test_walk_fast_path");
}
