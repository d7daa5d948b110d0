/* capi entry points of the random walks: validate, then call src/walk. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <dwivedi.h>
#include "util/error.h"
#include "kernel/rng.h"
#include "walk/estimate.h"

#define DEFAULT_MAX_EVENTS 1000000u
#define MAX_WALKS 1000000000000ull

static const char *const technique_names[] = {"auto", "classical", "poe", "closest", "incident", "backward", "cycles", "sheet"};
#define TECHNIQUE_COUNT ((int32_t)(sizeof technique_names / sizeof technique_names[0]))

const char *dwv_technique_name(dwv_technique_t technique)
{
    return technique >= 0 && technique < TECHNIQUE_COUNT ? technique_names[technique] : NULL;
}

dwv_result_t dwv_technique_from_name(const char *name, dwv_technique_t *technique)
{
    DWV_TRY(dwv_check_pointer("dwv_technique_from_name", "name", name));
    DWV_TRY(dwv_check_pointer("dwv_technique_from_name", "technique", technique));
    for (int32_t i = 0; i < TECHNIQUE_COUNT; ++i) {
        if (strcmp(name, technique_names[i]) == 0) {
            *technique = i;
            return DWV_SUCCESS;
        }
    }
    return dwv_fail(DWV_ERROR_UNKNOWN_NAME,
                    "dwv_technique_from_name: unknown technique '%.64s' (auto, classical, poe, closest, "
                    "incident, backward, cycles or sheet)", name);
}

static long sysconf_cores(void)
{
    return sysconf(_SC_NPROCESSORS_ONLN);
}

static dwv_result_t check_technique(const char *fn, dwv_technique_t technique)
{
    if (technique < 0 || technique >= TECHNIQUE_COUNT)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: technique %d is not a dwv_technique_t (0 to %d)", fn,
                        (int)technique, (int)TECHNIQUE_COUNT - 1);
    return DWV_SUCCESS;
}

static dwv_result_t check_positive(const char *fn, const char *name, double value)
{
    DWV_TRY(dwv_check_finite(fn, name, value));
    if (!(value > 0.0)) return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: %s = %.17g must be > 0", fn, name, value);
    return DWV_SUCCESS;
}

/* Validates a capi medium and converts it. */
static dwv_result_t medium_from_api(const char *fn, const dwv_medium_t *in, dwvw_medium *out)
{
    DWV_TRY(dwv_check_struct(fn, "medium", in, (uint32_t)sizeof(dwv_medium_t)));
    if (in->channels != 1 && in->channels != 3)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: medium channels = %u must be 1 or 3", fn, in->channels);
    static const char *const sigma_names[] = {"medium sigma_t[0]", "medium sigma_t[1]", "medium sigma_t[2]"};
    static const char *const albedo_names[] = {"medium albedo[0]", "medium albedo[1]", "medium albedo[2]"};
    for (uint32_t c = 0; c < in->channels; ++c) {
        DWV_TRY(check_positive(fn, sigma_names[c], in->sigma_t[c]));
        /* Free flights are sampled in single precision (stretched by as little as 2^-20): outside
         * this range sigma_t would round to 0 or infinity there. */
        if (in->sigma_t[c] < 1e-30 || in->sigma_t[c] > 1e30)
            return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: %s = %.17g is outside [1e-30, 1e30]", fn, sigma_names[c],
                            in->sigma_t[c]);
        DWV_TRY(dwv_check_range(fn, albedo_names[c], in->albedo[c], 0.0, 1.0));
    }
    DWV_TRY(dwv_check_finite(fn, "medium anisotropy", in->anisotropy));
    if (!(fabs(in->anisotropy) < 1.0))
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: medium anisotropy = %.17g must be in (-1, 1)", fn, in->anisotropy);
    dwvw_medium_init(out, (int)in->channels, in->sigma_t, in->albedo, in->anisotropy);
    return DWV_SUCCESS;
}

static dwv_result_t check_vector(const char *fn, const char *name, const double *v, int unit)
{
    DWV_TRY(dwv_check_pointer(fn, name, v));
    for (int i = 0; i < 3; ++i) DWV_TRY(dwv_check_finite(fn, name, v[i]));
    double length = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (unit && !(fabs(length - 1.0) < 1e-6))
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: %s has length %.17g, not 1", fn, name, length);
    return DWV_SUCCESS;
}

/* ---- estimate ------------------------------------------------------------------------------ */

dwv_result_t dwv_estimate(const dwv_estimate_options_t *options, dwv_estimate_result_t *result)
{
    static const char fn[] = "dwv_estimate";
    DWV_TRY(dwv_check_struct(fn, "options", options, (uint32_t)sizeof(dwv_estimate_options_t)));
    DWV_TRY(dwv_check_struct(fn, "result", result, (uint32_t)sizeof(dwv_estimate_result_t)));
    dwvw_estimate_setup setup;
    memset(&setup, 0, sizeof setup);
    switch (options->shape) {
    case DWV_SHAPE_HALFSPACE: setup.shape.kind = DWVW_HALFSPACE; break;
    case DWV_SHAPE_SLAB:
        DWV_TRY(check_positive(fn, "thickness", options->thickness));
        setup.shape.kind = DWVW_SLAB;
        setup.shape.thickness = options->thickness;
        break;
    case DWV_SHAPE_SPHERE:
        DWV_TRY(check_positive(fn, "radius", options->radius));
        /* The sphere's exit and closest-point distances square lengths of the order of the radius
         * (src/walk/geometry.c), and the incident technique measures distances to its poles: beyond
         * about 1e154 (and below 1e-154) those squares over- (under-)flow, which made exits score
         * 0 or infinity. [1e-100, 1e100] keeps a wide margin either way. */
        if (options->radius < 1e-100 || options->radius > 1e100)
            return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: radius = %.17g is outside [1e-100, 1e100]", fn,
                            options->radius);
        setup.shape.kind = DWVW_SPHERE;
        setup.shape.radius = options->radius;
        break;
    default:
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: shape %d is not a dwv_shape_t", fn, (int)options->shape);
    }
    DWV_TRY(medium_from_api(fn, &options->medium, &setup.medium));
    if (options->incidence == DWV_INCIDENCE_DIFFUSE) {
        setup.incidence_diffuse = 1;
    } else if (options->incidence == DWV_INCIDENCE_COSINE) {
        DWV_TRY(dwv_check_finite(fn, "incidence_cosine", options->incidence_cosine));
        if (!(options->incidence_cosine > 0.0 && options->incidence_cosine <= 1.0))
            return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: incidence_cosine = %.17g must be in (0, 1]", fn,
                            options->incidence_cosine);
        setup.incidence_cosine = options->incidence_cosine;
    } else {
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: incidence %d is not a dwv_incidence_t", fn, (int)options->incidence);
    }
    if (options->light < DWV_LIGHT_FRONT || options->light > DWV_LIGHT_BOTH)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: light %d is not a dwv_light_t (1 front, 2 back, 3 both)", fn,
                        (int)options->light);
    if (setup.shape.kind == DWVW_HALFSPACE && options->light != DWV_LIGHT_FRONT)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: a half-space has no back face: light it from the front", fn);
    setup.light = (int)options->light;
    DWV_TRY(check_technique(fn, options->technique));
    if (options->walks < 2 || options->walks > MAX_WALKS)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: walks = %llu must be in [2, 10^12]", fn,
                        (unsigned long long)options->walks);
    if (options->threads > 256)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: threads = %u must be at most 256 (0: all cores)", fn,
                        options->threads);
    setup.walks = options->walks;
    setup.seed = options->seed;
    setup.threads = options->threads;
    if (setup.threads == 0) {
        long cores = sysconf_cores();
        setup.threads = (uint32_t)(cores < 1 ? 1 : cores > 256 ? 256 : cores);
    }
    setup.max_events = options->max_events ? options->max_events : DEFAULT_MAX_EVENTS;

    dwvw_light_patch patches[DWVW_MAX_PATCHES];
    int patch_count = dwvw_estimate_light_patches(&setup.shape, setup.light, patches);
    dwvw_guide_init(&setup.guide, (dwvw_technique)options->technique, &setup.medium, patches, patch_count);

    dwvw_estimate_totals totals;
    if (dwvw_estimate_run(&setup, &totals) != 0)
        return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: could not allocate the run's block totals", fn);

    double n = (double)setup.walks;
    result->channels = (uint32_t)setup.medium.channels;
    for (int c = 0; c < 3; ++c) {
        int used = c < setup.medium.channels;
        double mean = used ? totals.sum[c] / n : 0.0;
        double variance = used ? totals.m2[c] / (n - 1.0) : 0.0;
        result->mean[c] = mean;
        result->variance[c] = variance;
        result->std_error[c] = sqrt(variance / n);
        result->truncated_weight[c] = used ? totals.truncated_weight[c] / n : 0.0;
    }
    result->walks = setup.walks;
    result->events = totals.events;
    result->seconds = totals.seconds;
    double seconds_per_walk = totals.seconds / n;
    result->efficiency = result->variance[0] > 0.0 && seconds_per_walk > 0.0
                             ? 1.0 / (result->variance[0] * seconds_per_walk) : INFINITY;
    result->truncated_walks = totals.truncated_walks;
    return DWV_SUCCESS;
}

/* ---- step-by-step walks -------------------------------------------------------------------- */

struct dwv_walk_s {
    atomic_uint references;
    dwvw_medium medium;
    dwvw_guide guide;
    uint64_t seed;
    uint32_t max_events;
    int begun, sampled;
    dwvw_walk walk;
};

dwv_result_t dwv_walk_create(const dwv_medium_t *medium, dwv_technique_t technique,
                             const dwv_light_patch_t *patches, uint32_t patch_count, uint64_t seed,
                             uint32_t max_events, dwv_walk_t **walk)
{
    static const char fn[] = "dwv_walk_create";
    DWV_TRY(dwv_check_pointer(fn, "walk", walk));
    *walk = NULL;
    dwvw_medium m;
    DWV_TRY(medium_from_api(fn, medium, &m));
    DWV_TRY(check_technique(fn, technique));
    if (patch_count > DWVW_MAX_PATCHES)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: patch_count = %u exceeds %d", fn, patch_count, DWVW_MAX_PATCHES);
    if (patch_count > 0) DWV_TRY(dwv_check_pointer(fn, "patches", patches));
    if (technique == DWV_TECHNIQUE_INCIDENT && patch_count == 0)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: the incident technique needs at least one light patch", fn);
    dwvw_light_patch converted[DWVW_MAX_PATCHES];
    for (uint32_t j = 0; j < patch_count; ++j) {
        const dwv_light_patch_t *p = &patches[j];
        char name[4][32];
        snprintf(name[0], sizeof name[0], "patches[%u]", j);
        snprintf(name[1], sizeof name[1], "patches[%u].point", j);
        snprintf(name[2], sizeof name[2], "patches[%u].normal", j);
        snprintf(name[3], sizeof name[3], "patches[%u].power", j);
        DWV_TRY(dwv_check_struct(fn, name[0], p, (uint32_t)sizeof(dwv_light_patch_t)));
        DWV_TRY(check_vector(fn, name[1], p->point, 0));
        DWV_TRY(check_vector(fn, name[2], p->normal, 1));
        DWV_TRY(check_positive(fn, name[3], p->power));
        converted[j].point = dwvu_v(p->point[0], p->point[1], p->point[2]);
        converted[j].normal = dwvu_v(p->normal[0], p->normal[1], p->normal[2]);
        converted[j].power = p->power;
        converted[j].is_plane = p->is_plane != 0;
    }
    dwv_walk_t *w = calloc(1, sizeof *w);
    if (!w) return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: out of memory", fn);
    atomic_init(&w->references, 1u);
    w->medium = m;
    dwvw_guide_init(&w->guide, (dwvw_technique)technique, &w->medium, converted, (int)patch_count);
    w->seed = seed;
    w->max_events = max_events ? max_events : DEFAULT_MAX_EVENTS;
    *walk = w;
    return DWV_SUCCESS;
}

dwv_result_t dwv_walk_retain(dwv_walk_t *walk)
{
    DWV_TRY(dwv_check_pointer("dwv_walk_retain", "walk", walk));
    atomic_fetch_add(&walk->references, 1u);
    return DWV_SUCCESS;
}

void dwv_walk_release(dwv_walk_t *walk)
{
    if (walk && atomic_fetch_sub(&walk->references, 1u) == 1u) free(walk);
}

dwv_result_t dwv_walk_needs_closest(const dwv_walk_t *walk, int32_t *needs)
{
    DWV_TRY(dwv_check_pointer("dwv_walk_needs_closest", "walk", walk));
    DWV_TRY(dwv_check_pointer("dwv_walk_needs_closest", "needs", needs));
    *needs = dwvw_guide_needs_closest(&walk->guide);
    return DWV_SUCCESS;
}

dwv_result_t dwv_walk_begin(dwv_walk_t *walk, uint64_t index, const double point[3], const double direction[3],
                            const double normal[3])
{
    static const char fn[] = "dwv_walk_begin";
    DWV_TRY(dwv_check_pointer(fn, "walk", walk));
    DWV_TRY(check_vector(fn, "point", point, 0));
    DWV_TRY(check_vector(fn, "direction", direction, 1));
    DWV_TRY(check_vector(fn, "normal", normal, 1));
    dwvu_vec3 d = dwvu_v(direction[0], direction[1], direction[2]);
    dwvu_vec3 n = dwvu_v(normal[0], normal[1], normal[2]);
    if (!(dwvu_dot(d, n) < 0.0))
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: direction does not enter the medium (it must oppose the "
                        "outward normal)", fn);
    dwvw_walk_begin(&walk->walk, &walk->medium, &walk->guide, dwvk_rng_key(walk->seed, index, 0), walk->max_events,
                    dwvu_v(point[0], point[1], point[2]), d, n);
    walk->begun = 1;
    walk->sampled = 0;
    return DWV_SUCCESS;
}

dwv_result_t dwv_walk_set_closest(dwv_walk_t *walk, const double normal[3])
{
    static const char fn[] = "dwv_walk_set_closest";
    DWV_TRY(dwv_check_pointer(fn, "walk", walk));
    DWV_TRY(check_vector(fn, "normal", normal, 1));
    dwvw_walk_set_closest(&walk->walk, dwvu_v(normal[0], normal[1], normal[2]));
    return DWV_SUCCESS;
}

dwv_result_t dwv_walk_sample(dwv_walk_t *walk, double direction[3], double *distance)
{
    static const char fn[] = "dwv_walk_sample";
    DWV_TRY(dwv_check_pointer(fn, "walk", walk));
    DWV_TRY(dwv_check_pointer(fn, "direction", direction));
    DWV_TRY(dwv_check_pointer(fn, "distance", distance));
    if (!walk->begun || walk->walk.status != DWVW_RUNNING)
        return dwv_fail(DWV_ERROR_INVALID_STATE, "%s: the walk is not running (call dwv_walk_begin)", fn);
    if (dwvw_guide_needs_closest(&walk->guide) && !walk->walk.closest_known)
        return dwv_fail(DWV_ERROR_INVALID_STATE, "%s: this technique needs dwv_walk_set_closest before each step", fn);
    *distance = dwvw_walk_sample(&walk->walk);
    direction[0] = walk->walk.direction.x;
    direction[1] = walk->walk.direction.y;
    direction[2] = walk->walk.direction.z;
    walk->sampled = 1;
    return DWV_SUCCESS;
}

dwv_result_t dwv_walk_report(dwv_walk_t *walk, double hit_distance, const double hit_normal[3],
                             dwv_walk_state_t *state)
{
    static const char fn[] = "dwv_walk_report";
    DWV_TRY(dwv_check_pointer(fn, "walk", walk));
    DWV_TRY(dwv_check_struct(fn, "state", state, (uint32_t)sizeof(dwv_walk_state_t)));
    if (!walk->sampled) return dwv_fail(DWV_ERROR_INVALID_STATE, "%s: no step was sampled (call dwv_walk_sample)", fn);
    if (isnan(hit_distance) || hit_distance < 0.0)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: hit_distance = %.17g must be >= 0 or INFINITY", fn, hit_distance);
    dwvu_vec3 n = walk->walk.entry_normal;
    if (hit_distance < INFINITY) {
        DWV_TRY(check_vector(fn, "hit_normal", hit_normal, 1));
        n = dwvu_v(hit_normal[0], hit_normal[1], hit_normal[2]);
    }
    dwvw_status status = dwvw_walk_complete(&walk->walk, hit_distance, n);
    walk->sampled = 0;
    const dwvw_walk *w = &walk->walk;
    state->status = (dwv_walk_status_t)status;
    state->events = w->events;
    state->reserved = 0;
    state->position[0] = w->position.x, state->position[1] = w->position.y, state->position[2] = w->position.z;
    for (int c = 0; c < 3; ++c) state->weight[c] = c < w->medium->channels ? w->weight[c] : 0.0;
    state->exit_normal[0] = w->exit_normal.x, state->exit_normal[1] = w->exit_normal.y;
    state->exit_normal[2] = w->exit_normal.z;
    return DWV_SUCCESS;
}
