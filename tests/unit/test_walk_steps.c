/* The step-by-step walk API (dwv_walk_*) driven the way a host renderer drives it: the test traces
 * its own rays against a half-space, a slab and a sphere with intersections and closest points
 * written here (not those of src/walk/geometry.c), and scores exits as dwv_estimate documents.
 * Walk i of a handle made with seed s draws the same random numbers as walk i of dwv_estimate with
 * seed s, so the mean exit score over walks 0..N-1 must equal dwv_estimate's mean up to rounding
 * (the two sum in different orders, and the two geometries round differently), and the event
 * counts must be equal. Then the handle's state machine, argument checks and reference count. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "api_checks.h"
#include "check.h"
#include <dwivedi.h>

enum { WALKS = 3000 };
/* Sampled directions are unit only to single precision (the per-event path runs in float): within
 * the API's own tolerance for unit vectors. The sphere's exit distance, like dwv_estimate's, takes
 * the direction as unit, so positions are on (or inside) the surface only to that relative error. */
#define UNIT_TOLERANCE 1e-6
/* Rounding only: the step loop and dwv_estimate add the same walk scores in a different order and
 * meet the surface at distances that differ in the last bits. test_planted_deviations_are_caught
 * shows that a loop drawing other random numbers, or breaking the protocol, lands far outside it. */
#define MEAN_RELATIVE_TOLERANCE 1e-9
#define SEED 0x5eedc0ffeeull

static const double ORIGIN[3] = {0.0, 0.0, 0.0};
static const double FRONT_NORMAL[3] = {0.0, 0.0, -1.0}; /* outward at the entry point */
static const double INTO_MEDIUM[3] = {0.0, 0.0, 1.0};   /* normal incidence */

/* ---- the test's own geometry (the shapes of dwv_estimate, dwivedi.h) ------------------------- */

typedef enum shape_kind_t { HALFSPACE, SLAB, SPHERE } shape_kind_t;

typedef struct shape_t {
    shape_kind_t kind;
    double thickness; /* slab: 0 <= z <= thickness */
    double radius;    /* sphere about (0, 0, radius) */
} shape_t;

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void set3(double out[3], double x, double y, double z)
{
    out[0] = x, out[1] = y, out[2] = z;
}

/* The distance along unit d from p (inside) to where the ray leaves the shape (INFINITY if it
 * never does) and the outward normal there. */
static double shape_exit(const shape_t *shape, const double p[3], const double d[3], double normal[3])
{
    switch (shape->kind) {
    case HALFSPACE:
        /* The plane z = 0 is met only going up (d.z < 0), at t = p.z / -d.z. */
        set3(normal, 0.0, 0.0, -1.0);
        return d[2] < 0.0 ? p[2] / -d[2] : INFINITY;
    case SLAB:
        if (d[2] < 0.0) {
            set3(normal, 0.0, 0.0, -1.0);
            return p[2] / -d[2];
        }
        set3(normal, 0.0, 0.0, 1.0);
        return d[2] > 0.0 ? (shape->thickness - p[2]) / d[2] : INFINITY;
    case SPHERE: {
        /* |q + t d|^2 = R^2 with q = p - centre: t^2 + 2 b t + c = 0, b = q.d, c = |q|^2 - R^2 <= 0
         * inside; the larger root, in the form without cancellation for each sign of b. */
        double R = shape->radius;
        double q[3] = {p[0], p[1], p[2] - R};
        double b = dot3(q, d), c = dot3(q, q) - R * R;
        double root = sqrt(fmax(b * b - c, 0.0));
        double t = b > 0.0 ? -c / (b + root) : root - b;
        t = fmax(t, 0.0); /* a point rounded onto or just past the surface leaves at once */
        double hit[3] = {q[0] + t * d[0], q[1] + t * d[1], q[2] + t * d[2]};
        double length = sqrt(dot3(hit, hit));
        set3(normal, hit[0] / length, hit[1] / length, hit[2] / length);
        return t;
    }
    }
    return INFINITY;
}

/* The outward normal at the surface point closest to p. */
static void shape_closest_normal(const shape_t *shape, const double p[3], double normal[3])
{
    switch (shape->kind) {
    case HALFSPACE: set3(normal, 0.0, 0.0, -1.0); return;
    case SLAB: set3(normal, 0.0, 0.0, p[2] <= 0.5 * shape->thickness ? -1.0 : 1.0); return;
    case SPHERE: {
        double q[3] = {p[0], p[1], p[2] - shape->radius};
        double r = sqrt(dot3(q, q));
        if (r > 0.0) set3(normal, q[0] / r, q[1] / r, q[2] / r);
        else set3(normal, 0.0, 0.0, -1.0); /* every surface point is closest at the centre */
        return;
    }
    }
}

/* How far p is outside the shape (<= 0 inside), for checking the walk's reported positions. */
static double shape_outside_by(const shape_t *shape, const double p[3])
{
    switch (shape->kind) {
    case HALFSPACE: return -p[2];
    case SLAB: return fmax(-p[2], p[2] - shape->thickness);
    case SPHERE: {
        double q[3] = {p[0], p[1], p[2] - shape->radius};
        return sqrt(dot3(q, q)) - shape->radius;
    }
    }
    return 0.0;
}

/* dwv_estimate's scoring (dwivedi.h): 1 through a lit face of the half-space or slab, the exit
 * normal's cosine to the light on the sphere, lit along -z (front) and/or +z (back). */
static double exit_score(const shape_t *shape, dwv_light_t light, const double n[3])
{
    double score = 0.0;
    if (shape->kind == SPHERE) {
        if (light & DWV_LIGHT_FRONT) score += fmax(0.0, -n[2]);
        if (light & DWV_LIGHT_BACK) score += fmax(0.0, n[2]);
    } else {
        if ((light & DWV_LIGHT_FRONT) && n[2] < 0.0) score += 1.0;
        if ((light & DWV_LIGHT_BACK) && n[2] > 0.0) score += 1.0;
    }
    return score;
}

/* The lit patches dwv_estimate aims incident (and auto) at, in its order, which matters: the
 * random number that picks a mixture component picks by position in the list. The header does
 * header lists them (dwv_estimate): the lit plane of a half-space or slab face, and a sphere's lit
 * pole, in the order front, back. */
static uint32_t light_patches(const shape_t *shape, dwv_light_t light, dwv_light_patch_t *patches)
{
    uint32_t count = 0;
    for (int side = 0; side < 2; ++side) {
        if (!(light & (side == 0 ? DWV_LIGHT_FRONT : DWV_LIGHT_BACK))) continue;
        double toward_light = side == 0 ? -1.0 : 1.0;
        if (shape->kind == SPHERE) {
            double R = shape->radius;
            dwv_light_patch_t p = DWV_LIGHT_PATCH_INIT;
            set3(p.normal, 0.0, 0.0, toward_light);
            set3(p.point, 0.0, 0.0, R + R * toward_light);
            patches[count++] = p;
        } else if (side == 0 || shape->kind == SLAB) {
            dwv_light_patch_t p = DWV_LIGHT_PATCH_INIT;
            p.is_plane = 1;
            set3(p.point, 0.0, 0.0, side == 0 ? 0.0 : shape->thickness);
            set3(p.normal, 0.0, 0.0, toward_light);
            patches[count++] = p;
        }
    }
    return count;
}

/* ---- one configuration, walked step by step and by dwv_estimate ------------------------------ */

typedef struct config_t {
    const char *label;
    shape_t shape;
    dwv_medium_t medium;
    dwv_technique_t technique;
    dwv_light_t light;
    uint32_t max_events; /* 0: the default cap */
} config_t;

typedef struct totals_t {
    double sum[3];              /* exit weight x score, over all walks */
    double truncated_weight[3]; /* weight held by walks the cap ended */
    uint64_t events, truncated_walks, exited, absorbed;
    int api_failures; /* calls that failed where they should not */
} totals_t;

/* How the host reports the first step's hit: as dwivedi.h asks, or (a planted error) like every
 * later step, cut at the sampled distance, which hides an opposite interface from backward. */
typedef enum first_report_t { FIRST_REPORT_FULL, FIRST_REPORT_CUT } first_report_t;

/* One walk as a host renderer drives it; adds to *totals. */
static void walk_steps(const config_t *config, dwv_walk_t *walk, int32_t needs_closest, uint64_t index,
                       first_report_t first_report, totals_t *totals)
{
    const uint32_t channels = config->medium.channels;
    dwv_result_t r = dwv_walk_begin(walk, index, ORIGIN, INTO_MEDIUM, FRONT_NORMAL);
    CHECK(r == DWV_SUCCESS, "%s walk %llu: dwv_walk_begin: %s", config->label, (unsigned long long)index,
          dwv_last_error_message());
    if (r != DWV_SUCCESS) {
        ++totals->api_failures;
        return;
    }
    double position[3] = {0.0, 0.0, 0.0};
    dwv_walk_state_t state = DWV_WALK_STATE_INIT;
    uint32_t expected_events = 0;
    double hit_normal[3];
    for (int first = 1;; first = 0) {
        if (needs_closest) {
            double closest[3];
            shape_closest_normal(&config->shape, position, closest);
            if (dwv_walk_set_closest(walk, closest) != DWV_SUCCESS) {
                CHECK(0, "%s walk %llu: dwv_walk_set_closest: %s", config->label, (unsigned long long)index,
                      dwv_last_error_message());
                ++totals->api_failures;
                return;
            }
        }
        double direction[3], distance;
        if (dwv_walk_sample(walk, direction, &distance) != DWV_SUCCESS) {
            CHECK(0, "%s walk %llu: dwv_walk_sample: %s", config->label, (unsigned long long)index,
                  dwv_last_error_message());
            ++totals->api_failures;
            return;
        }
        if (!(fabs(sqrt(dot3(direction, direction)) - 1.0) < UNIT_TOLERANCE && distance > 0.0)) {
            CHECK(0, "%s walk %llu: sampled |direction| = %.17g, distance %.17g", config->label,
                  (unsigned long long)index, sqrt(dot3(direction, direction)), distance);
            ++totals->api_failures;
            return;
        }
        double hit = shape_exit(&config->shape, position, direction, hit_normal);
        /* The protocol of dwivedi.h: the full distance on the first step (a probe that locates an
         * opposite interface), afterwards the hit only if it is within the sampled distance. */
        double reported = (first && first_report == FIRST_REPORT_FULL) || hit <= distance ? hit : INFINITY;
        if (dwv_walk_report(walk, reported, hit_normal, &state) != DWV_SUCCESS) {
            CHECK(0, "%s walk %llu: dwv_walk_report: %s", config->label, (unsigned long long)index,
                  dwv_last_error_message());
            ++totals->api_failures;
            return;
        }
        /* The walk moved to the hit or to the sampled distance, whichever came first. */
        double travelled = fmin(hit, distance);
        double moved_to[3] = {position[0] + travelled * direction[0], position[1] + travelled * direction[1],
                              position[2] + travelled * direction[2]};
        double scale = 1.0 + sqrt(dot3(moved_to, moved_to));
        int position_ok = 1;
        for (int i = 0; i < 3; ++i) position_ok &= fabs(state.position[i] - moved_to[i]) <= 1e-12 * scale;
        int weights_ok = 1;
        for (uint32_t c = 0; c < 3; ++c)
            weights_ok &= c < channels ? isfinite(state.weight[c]) && state.weight[c] >= 0.0 : state.weight[c] == 0.0;
        if (state.status == DWV_WALK_RUNNING || state.status == DWV_WALK_TRUNCATED || state.status == DWV_WALK_ABSORBED)
            ++expected_events;
        int inside_ok = state.status == DWV_WALK_EXITED ||
                        shape_outside_by(&config->shape, state.position) <= UNIT_TOLERANCE * scale;
        if (!(position_ok && weights_ok && inside_ok && state.events == expected_events)) {
            CHECK(0, "%s walk %llu: state after a step: position (%.17g %.17g %.17g) expected (%.17g %.17g %.17g), "
                  "weight (%.17g %.17g %.17g), events %u expected %u, status %d", config->label,
                  (unsigned long long)index, state.position[0], state.position[1], state.position[2], moved_to[0],
                  moved_to[1], moved_to[2], state.weight[0], state.weight[1], state.weight[2], state.events,
                  expected_events, (int)state.status);
            ++totals->api_failures;
            return;
        }
        memcpy(position, state.position, sizeof position);
        if (state.status != DWV_WALK_RUNNING) break;
    }
    totals->events += state.events;
    switch (state.status) {
    case DWV_WALK_EXITED: {
        /* It left where and as the host said: on the surface, through the normal reported last. */
        CHECK(memcmp(state.exit_normal, hit_normal, sizeof hit_normal) == 0 &&
                  fabs(shape_outside_by(&config->shape, state.position)) <= UNIT_TOLERANCE * (1.0 + sqrt(dot3(position, position))),
              "%s walk %llu: exit normal (%.17g %.17g %.17g) reported (%.17g %.17g %.17g), %.3g off the surface",
              config->label, (unsigned long long)index, state.exit_normal[0], state.exit_normal[1],
              state.exit_normal[2], hit_normal[0], hit_normal[1], hit_normal[2],
              shape_outside_by(&config->shape, state.position));
        double score = exit_score(&config->shape, config->light, state.exit_normal);
        for (uint32_t c = 0; c < channels; ++c) totals->sum[c] += state.weight[c] * score;
        ++totals->exited;
        break;
    }
    case DWV_WALK_ABSORBED: {
        int zero = 1;
        for (uint32_t c = 0; c < channels; ++c) zero &= state.weight[c] == 0.0;
        CHECK(zero, "%s walk %llu: absorbed with weight (%.17g %.17g %.17g)", config->label,
              (unsigned long long)index, state.weight[0], state.weight[1], state.weight[2]);
        ++totals->absorbed;
        break;
    }
    case DWV_WALK_TRUNCATED:
        CHECK(state.events == (config->max_events ? config->max_events : 1000000u),
              "%s walk %llu: truncated after %u events", config->label, (unsigned long long)index, state.events);
        for (uint32_t c = 0; c < channels; ++c) totals->truncated_weight[c] += state.weight[c];
        ++totals->truncated_walks;
        break;
    default:
        CHECK(0, "%s walk %llu: ended with status %d", config->label, (unsigned long long)index, (int)state.status);
        ++totals->api_failures;
    }
}

/* Walks first_index .. first_index + WALKS - 1 of a configuration, step by step; 0 if a call failed. */
static int run_steps(const config_t *config, uint64_t first_index, first_report_t first_report, totals_t *steps)
{
    memset(steps, 0, sizeof *steps);
    dwv_light_patch_t patches[16];
    uint32_t patch_count = light_patches(&config->shape, config->light, patches);
    dwv_walk_t *walk = NULL;
    dwv_result_t r = dwv_walk_create(&config->medium, config->technique, patches, patch_count, SEED,
                                     config->max_events, &walk);
    CHECK(r == DWV_SUCCESS && walk != NULL, "%s: dwv_walk_create: %s", config->label, dwv_last_error_message());
    if (r != DWV_SUCCESS) return 0;
    int32_t needs_closest = -1;
    CHECK(dwv_walk_needs_closest(walk, &needs_closest) == DWV_SUCCESS && (needs_closest == 0 || needs_closest == 1),
          "%s: dwv_walk_needs_closest gave %d", config->label, (int)needs_closest);
    for (uint64_t i = first_index; i < first_index + WALKS && steps->api_failures == 0; ++i)
        walk_steps(config, walk, needs_closest, i, first_report, steps);
    dwv_walk_release(walk);
    return steps->api_failures == 0;
}

/* dwv_estimate of the same configuration and walks 0 .. WALKS - 1; 0 if it failed. */
static int run_estimate(const config_t *config, dwv_estimate_result_t *e)
{
    dwv_estimate_options_t o = DWV_ESTIMATE_OPTIONS_INIT;
    o.shape = config->shape.kind == HALFSPACE ? DWV_SHAPE_HALFSPACE
              : config->shape.kind == SLAB    ? DWV_SHAPE_SLAB
                                              : DWV_SHAPE_SPHERE;
    o.thickness = config->shape.thickness;
    o.radius = config->shape.radius;
    o.medium = config->medium;
    o.incidence = DWV_INCIDENCE_COSINE;
    o.incidence_cosine = 1.0;
    o.light = config->light;
    o.technique = config->technique;
    o.walks = WALKS;
    o.seed = SEED;
    o.threads = 1;
    o.max_events = config->max_events;
    dwv_estimate_result_t fresh = DWV_ESTIMATE_RESULT_INIT;
    *e = fresh;
    dwv_result_t r = dwv_estimate(&o, e);
    CHECK(r == DWV_SUCCESS, "%s: dwv_estimate: %s", config->label, dwv_last_error_message());
    CHECK(r != DWV_SUCCESS || e->channels == config->medium.channels, "%s: dwv_estimate channels %u", config->label,
          e->channels);
    return r == DWV_SUCCESS;
}

static double relative_difference(double a, double b)
{
    return a == b ? 0.0 : fabs(a - b) / fmax(fabs(a), fabs(b));
}

static void compare_with_estimate(const config_t *config)
{
    totals_t steps;
    dwv_estimate_result_t e;
    if (!run_steps(config, 0u, FIRST_REPORT_FULL, &steps) || !run_estimate(config, &e)) return;
    for (uint32_t c = 0; c < config->medium.channels; ++c) {
        double mean = steps.sum[c] / WALKS;
        CHECK(relative_difference(mean, e.mean[c]) <= MEAN_RELATIVE_TOLERANCE,
              "%s channel %u: step mean %.17g, dwv_estimate mean %.17g (relative difference %.3g)", config->label, c,
              mean, e.mean[c], relative_difference(mean, e.mean[c]));
        double truncated = steps.truncated_weight[c] / WALKS;
        CHECK(relative_difference(truncated, e.truncated_weight[c]) <= MEAN_RELATIVE_TOLERANCE,
              "%s channel %u: step truncated weight %.17g, dwv_estimate %.17g", config->label, c, truncated,
              e.truncated_weight[c]);
    }
    CHECK(steps.events == e.events, "%s: step events %llu, dwv_estimate events %llu", config->label,
          (unsigned long long)steps.events, (unsigned long long)e.events);
    CHECK(steps.truncated_walks == e.truncated_walks, "%s: step truncated walks %llu, dwv_estimate %llu",
          config->label, (unsigned long long)steps.truncated_walks, (unsigned long long)e.truncated_walks);
    /* A comparison of nothing would pass: every configuration must have walks that score. */
    CHECK(steps.exited > 0 && steps.sum[0] > 0.0, "%s: no walk scored (%llu exited)", config->label,
          (unsigned long long)steps.exited);
    printf("%-34s mean %.12f  events %llu  exited %llu  absorbed %llu  truncated %llu\n", config->label,
           steps.sum[0] / WALKS, (unsigned long long)steps.events, (unsigned long long)steps.exited,
           (unsigned long long)steps.absorbed, (unsigned long long)steps.truncated_walks);
}

/* The comparison can fail: walks N..2N-1 instead of 0..N-1, and a host that cuts the first step's hit
 * at the sampled distance (backward then never finds the slab's far face), both move the mean by
 * far more than MEAN_RELATIVE_TOLERANCE and change the event count. */
static void test_planted_deviations_are_caught(void)
{
    const dwv_medium_t grey = {sizeof(dwv_medium_t), 1u, {2.0, 2.0, 2.0}, {0.8, 0.8, 0.8}, 0.0};
    const config_t configs[2] = {
        {"planted: sphere closest, walks N..2N-1", {SPHERE, 0.0, 1.25}, grey, DWV_TECHNIQUE_CLOSEST, DWV_LIGHT_FRONT, 0u},
        {"planted: slab backward, first hit cut", {SLAB, 1.5, 0.0}, grey, DWV_TECHNIQUE_BACKWARD, DWV_LIGHT_FRONT, 0u},
    };
    for (int i = 0; i < 2; ++i) {
        totals_t steps;
        dwv_estimate_result_t e;
        if (!run_steps(&configs[i], i == 0 ? (uint64_t)WALKS : 0u, i == 0 ? FIRST_REPORT_FULL : FIRST_REPORT_CUT, &steps) ||
            !run_estimate(&configs[i], &e))
            continue;
        double difference = relative_difference(steps.sum[0] / WALKS, e.mean[0]);
        CHECK(difference > 1e3 * MEAN_RELATIVE_TOLERANCE && steps.events != e.events,
              "%s: the deviation went unseen (relative difference %.3g, events %llu and %llu)", configs[i].label,
              difference, (unsigned long long)steps.events, (unsigned long long)e.events);
        printf("%-40s relative difference %.3g, events %llu vs %llu\n", configs[i].label, difference,
               (unsigned long long)steps.events, (unsigned long long)e.events);
    }
}

static void test_steps_match_estimate(void)
{
    const dwv_medium_t grey = {sizeof(dwv_medium_t), 1u, {2.0, 2.0, 2.0}, {0.8, 0.8, 0.8}, 0.0};
    /* The driving channel is the blue one (largest albedo is red, shortest mean free path green):
     * exercises the per-channel distance mixture and the weights of the other channels. */
    const dwv_medium_t rgb = {sizeof(dwv_medium_t), 3u, {1.0, 2.0, 0.5}, {0.9, 0.6, 0.3}, 0.4};
    const shape_t shapes[3] = {{HALFSPACE, 0.0, 0.0}, {SLAB, 1.5, 0.0}, {SPHERE, 0.0, 1.25}};
    const char *const shape_names[3] = {"halfspace", "slab", "sphere"};
    const dwv_medium_t *const media[2] = {&grey, &rgb};
    const char *const medium_names[2] = {"grey", "rgb"};
    static const dwv_technique_t techniques[8] = {DWV_TECHNIQUE_CLASSICAL, DWV_TECHNIQUE_POE, DWV_TECHNIQUE_CLOSEST,
                                                  DWV_TECHNIQUE_BACKWARD, DWV_TECHNIQUE_CYCLES, DWV_TECHNIQUE_AUTO,
                                                  DWV_TECHNIQUE_INCIDENT, DWV_TECHNIQUE_SHEET};
    char label[64];
    for (int s = 0; s < 3; ++s) {
        for (int m = 0; m < 2; ++m) {
            for (int t = 0; t < 8; ++t) {
                snprintf(label, sizeof label, "%s %s %s", shape_names[s], medium_names[m],
                         dwv_technique_name(techniques[t]));
                config_t config = {label, shapes[s], *media[m], techniques[t], DWV_LIGHT_FRONT, 0u};
                compare_with_estimate(&config);
            }
        }
    }
    /* Both faces lit: two plane patches (incident aims at the far face too), the back-lit sphere's
     * hemisphere, and event caps small enough that many walks end truncated. */
    const struct {
        const char *label;
        int shape;
        dwv_technique_t technique;
        dwv_light_t light;
        uint32_t max_events;
    } extra[] = {
        {"slab grey incident light both", 1, DWV_TECHNIQUE_INCIDENT, DWV_LIGHT_BOTH, 0u},
        {"slab grey auto light both", 1, DWV_TECHNIQUE_AUTO, DWV_LIGHT_BOTH, 0u},
        {"sphere grey incident light back", 2, DWV_TECHNIQUE_INCIDENT, DWV_LIGHT_BACK, 0u},
        {"slab grey sheet light back", 1, DWV_TECHNIQUE_SHEET, DWV_LIGHT_BACK, 0u},
        {"sphere grey sheet light back", 2, DWV_TECHNIQUE_SHEET, DWV_LIGHT_BACK, 0u},
        {"halfspace grey classical cap 3", 0, DWV_TECHNIQUE_CLASSICAL, DWV_LIGHT_FRONT, 3u},
        {"sphere grey auto cap 4", 2, DWV_TECHNIQUE_AUTO, DWV_LIGHT_FRONT, 4u},
    };
    for (size_t i = 0; i < sizeof extra / sizeof extra[0]; ++i) {
        config_t config = {extra[i].label, shapes[extra[i].shape], grey, extra[i].technique, extra[i].light,
                           extra[i].max_events};
        compare_with_estimate(&config);
    }
}

/* ---- errors: a message from this call ------------------------------------------------------- */

/* The call fails with `code` and leaves a new message that names `keyword`. */
#define EXPECT_ERROR(call, code, keyword)                                                                    \
    do {                                                                                                     \
        prime_message();                                                                                     \
        dwv_result_t result_ = (call);                                                                       \
        CHECK(result_ == (code) && fresh_message_with(keyword), "%s gave %d (%s), expected %d; message '%s'", \
              #call, (int)result_, dwv_result_string(result_), (int)(code), dwv_last_error_message());        \
    } while (0)

/* ---- the state machine ---------------------------------------------------------------------- */

/* Steps a half-space walk of `walk` to its end with the test's geometry; returns its final state. */
static dwv_walk_state_t finish_halfspace_walk(dwv_walk_t *walk, int32_t needs_closest)
{
    dwv_walk_state_t state = DWV_WALK_STATE_INIT;
    int first = 1;
    do {
        if (needs_closest) CHECK(dwv_walk_set_closest(walk, FRONT_NORMAL) == DWV_SUCCESS, "%s", dwv_last_error_message());
        double direction[3], distance;
        if (dwv_walk_sample(walk, direction, &distance) != DWV_SUCCESS) {
            CHECK(0, "dwv_walk_sample: %s", dwv_last_error_message());
            break;
        }
        double hit = direction[2] < 0.0 ? state.position[2] / -direction[2] : INFINITY;
        if (dwv_walk_report(walk, first || hit <= distance ? hit : INFINITY, FRONT_NORMAL, &state) != DWV_SUCCESS) {
            CHECK(0, "dwv_walk_report: %s", dwv_last_error_message());
            break;
        }
        first = 0;
    } while (state.status == DWV_WALK_RUNNING);
    return state;
}

static void test_state_machine(void)
{
    const dwv_medium_t medium = DWV_MEDIUM_INIT;
    dwv_walk_t *walk = NULL;
    CHECK(dwv_walk_create(&medium, DWV_TECHNIQUE_CLOSEST, NULL, 0, 7u, 0u, &walk) == DWV_SUCCESS && walk,
          "dwv_walk_create: %s", dwv_last_error_message());
    if (!walk) return;
    int32_t needs = -1;
    CHECK(dwv_walk_needs_closest(walk, &needs) == DWV_SUCCESS && needs == 1, "closest needs_closest = %d", (int)needs);

    double direction[3], distance = -1.0, normal_in_use[3] = {0.0, 0.0, -1.0};
    dwv_walk_state_t state = DWV_WALK_STATE_INIT;
    /* Nothing is possible before dwv_walk_begin. */
    EXPECT_ERROR(dwv_walk_sample(walk, direction, &distance), DWV_ERROR_INVALID_STATE, "dwv_walk_begin");
    EXPECT_ERROR(dwv_walk_report(walk, 1.0, normal_in_use, &state), DWV_ERROR_INVALID_STATE, "dwv_walk_sample");

    CHECK(dwv_walk_begin(walk, 0u, ORIGIN, INTO_MEDIUM, FRONT_NORMAL) == DWV_SUCCESS, "%s", dwv_last_error_message());
    EXPECT_ERROR(dwv_walk_report(walk, INFINITY, NULL, &state), DWV_ERROR_INVALID_STATE, "dwv_walk_sample");
    /* closest needs the closest point before each step, the first included. */
    EXPECT_ERROR(dwv_walk_sample(walk, direction, &distance), DWV_ERROR_INVALID_STATE, "dwv_walk_set_closest");
    EXPECT_ERROR(dwv_walk_set_closest(walk, (const double[3]){0.0, 0.0, -2.0}), DWV_ERROR_INVALID_ARGUMENT, "length");
    EXPECT_ERROR(dwv_walk_set_closest(walk, (const double[3]){0.0, NAN, -1.0}), DWV_ERROR_INVALID_ARGUMENT, "NaN");
    EXPECT_ERROR(dwv_walk_set_closest(walk, NULL), DWV_ERROR_NULL_POINTER, "normal");
    CHECK(dwv_walk_set_closest(walk, FRONT_NORMAL) == DWV_SUCCESS, "%s", dwv_last_error_message());
    CHECK(dwv_walk_sample(walk, direction, &distance) == DWV_SUCCESS, "%s", dwv_last_error_message());
    CHECK(direction[0] == 0.0 && direction[1] == 0.0 && direction[2] == 1.0 && distance > 0.0,
          "the first step keeps the entry direction: (%g %g %g), distance %g", direction[0], direction[1],
          direction[2], distance);
    /* A bad report is refused and changes nothing: the step can still be reported. */
    EXPECT_ERROR(dwv_walk_report(walk, NAN, FRONT_NORMAL, &state), DWV_ERROR_INVALID_ARGUMENT, "hit_distance");
    EXPECT_ERROR(dwv_walk_report(walk, -1.0, FRONT_NORMAL, &state), DWV_ERROR_INVALID_ARGUMENT, "hit_distance");
    EXPECT_ERROR(dwv_walk_report(walk, 0.5 * distance, NULL, &state), DWV_ERROR_NULL_POINTER, "hit_normal");
    EXPECT_ERROR(dwv_walk_report(walk, 0.5 * distance, (const double[3]){0.0, 0.0, 0.5}, &state),
                 DWV_ERROR_INVALID_ARGUMENT, "hit_normal");
    dwv_walk_state_t small_state = DWV_WALK_STATE_INIT;
    small_state.struct_size = 8u;
    EXPECT_ERROR(dwv_walk_report(walk, INFINITY, NULL, &small_state), DWV_ERROR_STRUCT_SIZE, "struct_size");
    EXPECT_ERROR(dwv_walk_report(walk, INFINITY, NULL, NULL), DWV_ERROR_NULL_POINTER, "state");
    /* The half-space has no surface ahead of a step along +z: INFINITY, and no normal is needed. */
    CHECK(dwv_walk_report(walk, INFINITY, NULL, &state) == DWV_SUCCESS, "%s", dwv_last_error_message());
    CHECK(state.status == DWV_WALK_RUNNING && state.events == 1u && state.position[2] == distance,
          "after one scattering: status %d, events %u, z %.17g (distance %.17g)", (int)state.status, state.events,
          state.position[2], distance);
    /* One report per sample, and the closest point again before the next step. */
    EXPECT_ERROR(dwv_walk_report(walk, INFINITY, NULL, &state), DWV_ERROR_INVALID_STATE, "dwv_walk_sample");
    EXPECT_ERROR(dwv_walk_sample(walk, direction, &distance), DWV_ERROR_INVALID_STATE, "dwv_walk_set_closest");
    CHECK(dwv_walk_set_closest(walk, FRONT_NORMAL) == DWV_SUCCESS, "%s", dwv_last_error_message());
    EXPECT_ERROR(dwv_walk_sample(walk, NULL, &distance), DWV_ERROR_NULL_POINTER, "direction");
    EXPECT_ERROR(dwv_walk_sample(walk, direction, NULL), DWV_ERROR_NULL_POINTER, "distance");
    EXPECT_ERROR(dwv_walk_sample(NULL, direction, &distance), DWV_ERROR_NULL_POINTER, "walk");

    /* Run walk 0 to its end from the start, then walk 0 again: a finished walk accepts no step, a
     * new begin restarts it, and the same index repeats the same walk. */
    CHECK(dwv_walk_begin(walk, 0u, ORIGIN, INTO_MEDIUM, FRONT_NORMAL) == DWV_SUCCESS, "%s", dwv_last_error_message());
    dwv_walk_state_t first_run = finish_halfspace_walk(walk, 1);
    CHECK(first_run.status != DWV_WALK_RUNNING, "walk 0 status %d", (int)first_run.status);
    CHECK(dwv_walk_set_closest(walk, FRONT_NORMAL) == DWV_SUCCESS, "%s", dwv_last_error_message());
    EXPECT_ERROR(dwv_walk_sample(walk, direction, &distance), DWV_ERROR_INVALID_STATE, "not running");
    EXPECT_ERROR(dwv_walk_report(walk, INFINITY, NULL, &state), DWV_ERROR_INVALID_STATE, "dwv_walk_sample");
    CHECK(dwv_walk_begin(walk, 0u, ORIGIN, INTO_MEDIUM, FRONT_NORMAL) == DWV_SUCCESS, "%s", dwv_last_error_message());
    dwv_walk_state_t second_run = finish_halfspace_walk(walk, 1);
    CHECK(memcmp(&first_run, &second_run, sizeof first_run) == 0,
          "walk 0 twice: status %d/%d, events %u/%u, weight %.17g/%.17g", (int)first_run.status,
          (int)second_run.status, first_run.events, second_run.events, first_run.weight[0], second_run.weight[0]);
    dwv_walk_release(walk);
}

static void test_begin_arguments(void)
{
    const dwv_medium_t medium = DWV_MEDIUM_INIT;
    dwv_walk_t *walk = NULL;
    CHECK(dwv_walk_create(&medium, DWV_TECHNIQUE_CLASSICAL, NULL, 0, 7u, 0u, &walk) == DWV_SUCCESS && walk,
          "dwv_walk_create: %s", dwv_last_error_message());
    if (!walk) return;
    /* Not entering: along the outward normal, and tangent to the surface (dot = 0). */
    EXPECT_ERROR(dwv_walk_begin(walk, 0u, ORIGIN, (const double[3]){0.0, 0.0, -1.0}, FRONT_NORMAL),
                 DWV_ERROR_INVALID_ARGUMENT, "enter");
    EXPECT_ERROR(dwv_walk_begin(walk, 0u, ORIGIN, (const double[3]){1.0, 0.0, 0.0}, FRONT_NORMAL),
                 DWV_ERROR_INVALID_ARGUMENT, "enter");
    EXPECT_ERROR(dwv_walk_begin(walk, 0u, ORIGIN, (const double[3]){0.0, 0.6, -0.8}, FRONT_NORMAL),
                 DWV_ERROR_INVALID_ARGUMENT, "enter");
    /* Not unit. */
    EXPECT_ERROR(dwv_walk_begin(walk, 0u, ORIGIN, (const double[3]){0.0, 0.0, 2.0}, FRONT_NORMAL),
                 DWV_ERROR_INVALID_ARGUMENT, "direction");
    EXPECT_ERROR(dwv_walk_begin(walk, 0u, ORIGIN, (const double[3]){0.0, 0.0, 0.999}, FRONT_NORMAL),
                 DWV_ERROR_INVALID_ARGUMENT, "direction");
    EXPECT_ERROR(dwv_walk_begin(walk, 0u, ORIGIN, INTO_MEDIUM, (const double[3]){0.0, 0.0, -0.5}),
                 DWV_ERROR_INVALID_ARGUMENT, "normal");
    EXPECT_ERROR(dwv_walk_begin(walk, 0u, ORIGIN, INTO_MEDIUM, (const double[3]){0.0, 0.0, 0.0}),
                 DWV_ERROR_INVALID_ARGUMENT, "normal");
    /* NaN and infinity anywhere. */
    EXPECT_ERROR(dwv_walk_begin(walk, 0u, (const double[3]){NAN, 0.0, 0.0}, INTO_MEDIUM, FRONT_NORMAL),
                 DWV_ERROR_INVALID_ARGUMENT, "point");
    EXPECT_ERROR(dwv_walk_begin(walk, 0u, (const double[3]){0.0, 0.0, INFINITY}, INTO_MEDIUM, FRONT_NORMAL),
                 DWV_ERROR_INVALID_ARGUMENT, "point");
    EXPECT_ERROR(dwv_walk_begin(walk, 0u, ORIGIN, (const double[3]){0.0, NAN, 1.0}, FRONT_NORMAL),
                 DWV_ERROR_INVALID_ARGUMENT, "direction");
    EXPECT_ERROR(dwv_walk_begin(walk, 0u, ORIGIN, INTO_MEDIUM, (const double[3]){NAN, 0.0, -1.0}),
                 DWV_ERROR_INVALID_ARGUMENT, "normal");
    EXPECT_ERROR(dwv_walk_begin(walk, 0u, NULL, INTO_MEDIUM, FRONT_NORMAL), DWV_ERROR_NULL_POINTER, "point");
    EXPECT_ERROR(dwv_walk_begin(walk, 0u, ORIGIN, NULL, FRONT_NORMAL), DWV_ERROR_NULL_POINTER, "direction");
    EXPECT_ERROR(dwv_walk_begin(walk, 0u, ORIGIN, INTO_MEDIUM, NULL), DWV_ERROR_NULL_POINTER, "normal");
    EXPECT_ERROR(dwv_walk_begin(NULL, 0u, ORIGIN, INTO_MEDIUM, FRONT_NORMAL), DWV_ERROR_NULL_POINTER, "walk");
    /* None of the refused begins started a walk. */
    double direction[3], distance;
    EXPECT_ERROR(dwv_walk_sample(walk, direction, &distance), DWV_ERROR_INVALID_STATE, "dwv_walk_begin");
    /* An oblique entry away from the origin is accepted, and its first step keeps its direction. */
    CHECK(dwv_walk_begin(walk, 3u, (const double[3]){1.0, -2.0, 0.5}, (const double[3]){0.6, 0.0, 0.8},
                         (const double[3]){0.0, 0.0, -1.0}) == DWV_SUCCESS,
          "an oblique begin: %s", dwv_last_error_message());
    CHECK(dwv_walk_sample(walk, direction, &distance) == DWV_SUCCESS && direction[0] == 0.6 && direction[2] == 0.8,
          "the first step keeps an oblique entry direction: (%g %g %g)", direction[0], direction[1], direction[2]);
    int32_t needs = -1;
    CHECK(dwv_walk_needs_closest(walk, &needs) == DWV_SUCCESS && needs == 0, "classical needs_closest = %d", (int)needs);
    EXPECT_ERROR(dwv_walk_needs_closest(NULL, &needs), DWV_ERROR_NULL_POINTER, "walk");
    EXPECT_ERROR(dwv_walk_needs_closest(walk, NULL), DWV_ERROR_NULL_POINTER, "needs");
    dwv_walk_release(walk);
}

static void test_create_arguments(void)
{
    const dwv_medium_t good = DWV_MEDIUM_INIT;
    dwv_light_patch_t patch = DWV_LIGHT_PATCH_INIT;
    patch.is_plane = 1;
    dwv_walk_t *walk = NULL;

    struct {
        const char *what;
        dwv_medium_t medium;
        dwv_result_t code;
        const char *keyword;
    } media[] = {
        {"channels 2", good, DWV_ERROR_OUT_OF_RANGE, "channels"},
        {"channels 0", good, DWV_ERROR_OUT_OF_RANGE, "channels"},
        {"sigma_t 0", good, DWV_ERROR_OUT_OF_RANGE, "sigma_t"},
        {"sigma_t -1", good, DWV_ERROR_OUT_OF_RANGE, "sigma_t"},
        {"sigma_t NaN", good, DWV_ERROR_INVALID_ARGUMENT, "sigma_t"},
        {"sigma_t inf", good, DWV_ERROR_INVALID_ARGUMENT, "sigma_t"},
        {"rgb sigma_t[2] 0", good, DWV_ERROR_OUT_OF_RANGE, "sigma_t[2]"},
        {"albedo 1.5", good, DWV_ERROR_OUT_OF_RANGE, "albedo"},
        {"albedo -0.1", good, DWV_ERROR_OUT_OF_RANGE, "albedo"},
        {"albedo NaN", good, DWV_ERROR_INVALID_ARGUMENT, "albedo"},
        {"rgb albedo[1] 1.5", good, DWV_ERROR_OUT_OF_RANGE, "albedo[1]"},
        {"anisotropy 1", good, DWV_ERROR_OUT_OF_RANGE, "anisotropy"},
        {"anisotropy -1", good, DWV_ERROR_OUT_OF_RANGE, "anisotropy"},
        {"anisotropy NaN", good, DWV_ERROR_INVALID_ARGUMENT, "anisotropy"},
        {"struct_size 0", good, DWV_ERROR_STRUCT_SIZE, "struct_size"},
    };
    media[0].medium.channels = 2u;
    media[1].medium.channels = 0u;
    media[2].medium.sigma_t[0] = 0.0;
    media[3].medium.sigma_t[0] = -1.0;
    media[4].medium.sigma_t[0] = NAN;
    media[5].medium.sigma_t[0] = INFINITY;
    media[6].medium.channels = 3u, media[6].medium.sigma_t[2] = 0.0;
    media[7].medium.albedo[0] = 1.5;
    media[8].medium.albedo[0] = -0.1;
    media[9].medium.albedo[0] = NAN;
    media[10].medium.channels = 3u, media[10].medium.albedo[1] = 1.5;
    media[11].medium.anisotropy = 1.0;
    media[12].medium.anisotropy = -1.0;
    media[13].medium.anisotropy = NAN;
    media[14].medium.struct_size = 0u;
    for (size_t i = 0; i < sizeof media / sizeof media[0]; ++i) {
        for (dwv_technique_t t = DWV_TECHNIQUE_AUTO; t <= DWV_TECHNIQUE_SHEET; ++t) {
            walk = NULL;
            prime_message();
            dwv_result_t r = dwv_walk_create(&media[i].medium, t, &patch, 1u, 0u, 0u, &walk);
            CHECK(r == media[i].code && walk == NULL && fresh_message_with(media[i].keyword),
                  "medium %s, technique %s: result %d (expected %d), walk %p, message '%s'", media[i].what,
                  dwv_technique_name(t), (int)r, (int)media[i].code, (void *)walk, dwv_last_error_message());
        }
    }

    EXPECT_ERROR(dwv_walk_create(NULL, DWV_TECHNIQUE_AUTO, NULL, 0u, 0u, 0u, &walk), DWV_ERROR_NULL_POINTER, "medium");
    EXPECT_ERROR(dwv_walk_create(&good, DWV_TECHNIQUE_AUTO, NULL, 0u, 0u, 0u, NULL), DWV_ERROR_NULL_POINTER, "walk");
    EXPECT_ERROR(dwv_walk_create(&good, 99, NULL, 0u, 0u, 0u, &walk), DWV_ERROR_OUT_OF_RANGE, "technique");
    EXPECT_ERROR(dwv_walk_create(&good, -1, NULL, 0u, 0u, 0u, &walk), DWV_ERROR_OUT_OF_RANGE, "technique");
    EXPECT_ERROR(dwv_walk_create(&good, DWV_TECHNIQUE_INCIDENT, NULL, 0u, 0u, 0u, &walk), DWV_ERROR_INVALID_ARGUMENT,
                 "patch");

    dwv_light_patch_t patches[17];
    for (int i = 0; i < 17; ++i) patches[i] = patch;
    EXPECT_ERROR(dwv_walk_create(&good, DWV_TECHNIQUE_INCIDENT, patches, 17u, 0u, 0u, &walk), DWV_ERROR_OUT_OF_RANGE,
                 "patch_count");
    EXPECT_ERROR(dwv_walk_create(&good, DWV_TECHNIQUE_INCIDENT, NULL, 1u, 0u, 0u, &walk), DWV_ERROR_NULL_POINTER,
                 "patches");
    dwv_light_patch_t bad = patch;
    bad.power = 0.0;
    EXPECT_ERROR(dwv_walk_create(&good, DWV_TECHNIQUE_INCIDENT, &bad, 1u, 0u, 0u, &walk), DWV_ERROR_OUT_OF_RANGE,
                 "power");
    bad = patch;
    bad.normal[2] = -2.0;
    EXPECT_ERROR(dwv_walk_create(&good, DWV_TECHNIQUE_INCIDENT, &bad, 1u, 0u, 0u, &walk), DWV_ERROR_INVALID_ARGUMENT,
                 "normal");
    bad = patch;
    bad.point[1] = NAN;
    EXPECT_ERROR(dwv_walk_create(&good, DWV_TECHNIQUE_INCIDENT, &bad, 1u, 0u, 0u, &walk), DWV_ERROR_INVALID_ARGUMENT,
                 "point");
    bad = patch;
    bad.struct_size = 0u;
    EXPECT_ERROR(dwv_walk_create(&good, DWV_TECHNIQUE_INCIDENT, &bad, 1u, 0u, 0u, &walk), DWV_ERROR_STRUCT_SIZE,
                 "struct_size");
    /* The last of several patches is checked too. */
    patches[15] = bad;
    EXPECT_ERROR(dwv_walk_create(&good, DWV_TECHNIQUE_INCIDENT, patches, 16u, 0u, 0u, &walk), DWV_ERROR_STRUCT_SIZE,
                 "struct_size");
    CHECK(walk == NULL, "a failed create left a handle %p", (void *)walk);

    /* The largest patch list is accepted, by every technique. */
    patches[15] = patch;
    for (dwv_technique_t t = DWV_TECHNIQUE_AUTO; t <= DWV_TECHNIQUE_SHEET; ++t) {
        CHECK(dwv_walk_create(&good, t, patches, 16u, 0u, 0u, &walk) == DWV_SUCCESS && walk != NULL,
              "16 patches, technique %s: %s", dwv_technique_name(t), dwv_last_error_message());
        dwv_walk_release(walk);
        walk = NULL;
    }
}

/* The mean score of walks 0..count-1 on the front-lit half-space, stepped through `walk`. */
static double halfspace_mean(dwv_walk_t *walk, int32_t needs_closest, uint64_t count)
{
    double sum = 0.0;
    for (uint64_t i = 0; i < count; ++i) {
        if (dwv_walk_begin(walk, i, ORIGIN, INTO_MEDIUM, FRONT_NORMAL) != DWV_SUCCESS) {
            CHECK(0, "dwv_walk_begin: %s", dwv_last_error_message());
            return NAN;
        }
        dwv_walk_state_t state = finish_halfspace_walk(walk, needs_closest);
        if (state.status == DWV_WALK_EXITED) sum += state.weight[0];
    }
    return sum / (double)count;
}

static void test_reference_count(void)
{
    const dwv_medium_t medium = DWV_MEDIUM_INIT;
    dwv_walk_t *walk = NULL, *reference = NULL;
    CHECK(dwv_walk_create(&medium, DWV_TECHNIQUE_POE, NULL, 0u, 11u, 0u, &reference) == DWV_SUCCESS,
          "%s", dwv_last_error_message());
    CHECK(dwv_walk_create(&medium, DWV_TECHNIQUE_POE, NULL, 0u, 11u, 0u, &walk) == DWV_SUCCESS, "%s",
          dwv_last_error_message());
    if (!walk || !reference) return;
    double expected = halfspace_mean(reference, 0, 200u);

    /* create (1) + retain (2) - release (1): the handle lives. Were it freed, the next allocation
     * of the same size would very likely reuse its memory, and overwrite it with a classical walk. */
    CHECK(dwv_walk_retain(walk) == DWV_SUCCESS, "dwv_walk_retain: %s", dwv_last_error_message());
    dwv_walk_release(walk);
    dwv_walk_t *other = NULL;
    CHECK(dwv_walk_create(&medium, DWV_TECHNIQUE_CLASSICAL, NULL, 0u, 99u, 5u, &other) == DWV_SUCCESS, "%s",
          dwv_last_error_message());
    CHECK(other != walk, "a retained handle's memory was handed out again (%p)", (void *)other);
    double after_release = halfspace_mean(walk, 0, 200u);
    CHECK(after_release == expected, "a retained and once released handle: mean %.17g, expected %.17g", after_release,
          expected);
    /* The second release is the last: it frees the handle (glibc aborts on a double free). */
    dwv_walk_release(walk);
    dwv_walk_release(other);
    dwv_walk_release(reference);

    EXPECT_ERROR(dwv_walk_retain(NULL), DWV_ERROR_NULL_POINTER, "walk");
    dwv_walk_release(NULL); /* a no-op: reaching the next line is the test */
    CHECK(1, "%s", "dwv_walk_release(NULL) returned");
}

int main(void)
{
    test_steps_match_estimate();
    test_planted_deviations_are_caught();
    test_state_machine();
    test_begin_arguments();
    test_create_arguments();
    test_reference_count();
    return check_report("test_walk_steps");
}
