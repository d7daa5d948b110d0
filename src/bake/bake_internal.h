/* The state of a bake, shared by the files of the bake engine (bake.c: passes, tiles and workers;
 * guides.c: the guides per mesh; pilot.c: auto's pilot; pixel_sums.c: the error estimate and the
 * image), and the helpers more than one of them calls. bake.h keeps it opaque to the API. */
#ifndef DWV_BAKE_BAKE_INTERNAL_H
#define DWV_BAKE_BAKE_INTERNAL_H

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>

#include "bake/bake.h"
#include "bake/pixel_filter.h"
#include "bake/shade.h"
#include "bake/uv_raster.h"
#include "util/clock.h"
#include "util/parallel.h"

/* The walk's random numbers come from a stream of their own: bit 63 of the stream marks it. The
 * per-pixel scrambles of the stratified pairs (kernel/sampler.h) come from bit 62's stream. */
#define WALK_STREAM 0x8000000000000000ull
#define PIXEL_STREAM 0x4000000000000000ull
/* The pilot that chooses auto's technique per mesh draws from bit 61's streams. */
#define PILOT_STREAM 0x2000000000000000ull

/* A pixel's samples form two independent replicates (dwvb_bake_sample): even samples and odd ones. */
#define REPLICATES 2u

/* A pixel's sums are exact: each sample's values are rounded once to fixed point (units of
 * 2^-DWVB_FIXED_BITS, magnitudes clamped at DWVB_FIXED_LIMIT) and added as 128-bit integers, so
 * any split of a pixel's samples into chunks, added in any order, gives the same bits as one bake
 * (docs/farm.md). A double accumulated in sample order would not: (a + b) + c != a + (b + c).
 * 2^40 x 2^48 x 2^32 samples stays below 2^127. */
#define DWVB_FIXED_BITS 48
#define DWVB_FIXED_LIMIT 1099511627776.0 /* 2^40 */
__extension__ typedef __int128 dwvb_fixed;

static inline dwvb_fixed dwvb_to_fixed(double x)
{
    if (!(x > -DWVB_FIXED_LIMIT)) x = -DWVB_FIXED_LIMIT; /* NaN too (samples are checked finite) */
    if (x > DWVB_FIXED_LIMIT) x = DWVB_FIXED_LIMIT;
    return (dwvb_fixed)nearbyint(ldexp(x, DWVB_FIXED_BITS));
}

static inline double dwvb_from_fixed(dwvb_fixed x)
{
    return ldexp((double)x, -DWVB_FIXED_BITS);
}

typedef struct dwvb_pixel_sums {
    dwvb_fixed sum[3], sum_squares[3];
    dwvb_fixed sum_alpha, sum_luminance_squares;
    dwvb_fixed replicate_luminance[REPLICATES]; /* the sum of each replicate's luminances */
} dwvb_pixel_sums;
#define DWVB_PIXEL_SUM_FIELDS 10 /* fixed-point values per pixel, in the order above */

/* A bake pass's sums at a pixel (dwv_bake_options_t.passes): per channel the sum of the samples'
 * values and of their squares, exact as the combined image's (above); 96 bytes. */
typedef struct dwvb_pass_sums {
    dwvb_fixed sum[3], sum_squares[3];
} dwvb_pass_sums;

/* The value of pass `pass` (dwv_pass_t, not COMBINED) in one sample's parts. */
static inline const double *dwvb_pass_value(const dwvb_shade_parts *parts, uint32_t pass)
{
    if (pass == DWV_PASS_EMISSION) return parts->emission;
    if (pass == DWV_PASS_ENVIRONMENT) return parts->environment;
    uint32_t lobe = (pass - 1u) / 3u, kind = (pass - 1u) % 3u;
    return kind == 0u ? parts->direct[lobe] : kind == 1u ? parts->indirect[lobe] : parts->color[lobe];
}

struct dwvb_bake {
    const dwvb_scene *scene;
    dwv_bake_options_t options;
    uint32_t width, height, threads;
    dwvb_shader shader;
    dwvw_guide *guides;
    dwvw_guide *channel_guides; /* per mesh x 3 (shade.h) */
    int *channel_walks;         /* per mesh (shade.h) */
    uint8_t *channel_counts;    /* per mesh x 3 (shade.h) */
    int *needs_closest;
    int *auto_choice; /* per mesh: auto's technique is chosen by the pilot (dwvb_pilot_choose) */
    uint32_t features;
    /* camera */
    dwvu_vec3 eye, right, up, forward; /* right/up scaled to the image's half extents */
    dwvb_pixel_filter pixel_filter;
    /* UV */
    dwvb_uv_raster raster;
    /* accumulation */
    dwvb_pixel_sums *sums;
    uint32_t *counts;
    /* Bake passes beyond the combined image: how many, which (dwv_pass_t, ascending) and their
     * sums, pass_count per pixel (NULL when none is asked for). */
    uint32_t pass_count;
    uint32_t pass_list[DWV_PASS_COUNT];
    dwvb_pass_sums *pass_sums;
    uint32_t tiles_x, tile_count;
    dwvb_tally *tile_tallies;
    /* Tiles are handed out longest first, by the seconds each took in the previous pass, so that
     * no worker is left with one long tile at the end of a pass (longest-processing-time-first
     * scheduling). The order changes only timing: each pixel's samples are keyed by its index. */
    uint32_t *tile_order;
    double *tile_seconds;
    struct timed_tile *tile_ranking; /* scratch for the ordering */
    uint64_t pass_first, pass_end; /* sample indices of the running pass */
    atomic_uint next_tile;
    atomic_uint tiles_done;
    atomic_int time_up;
    atomic_int cancelled;
    atomic_uint_fast64_t events;
    double start; /* dwvu_clock_seconds() when the bake began */
    uint64_t spp_done;
    double error;
    /* control */
    pthread_t control;
    int control_started, joined;
    pthread_mutex_t lock;
    pthread_cond_t changed; /* workers finished, or the bake ended */
    uint32_t workers_running;
    dwvu_parallel workers; /* a pass's tile workers */
    int done;
    dwv_result_t result;
    char message[256];
    dwvb_image *image;
    dwv_bake_progress_t progress;
};

static inline double dwvb_bake_elapsed(const dwvb_bake *bake)
{
    return dwvu_clock_seconds() - bake->start;
}

static inline double dwvb_luminance(const double rgb[3])
{
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
}

static inline int dwvb_bake_pixel_active(const dwvb_bake *bake, uint32_t index)
{
    return bake->options.target == DWV_BAKE_CAMERA || bake->raster.texels[index].triangle >= 0;
}

/* Whether a worker (a pass's or the pilot's) must stop: cancelled, or (with a time limit) out of time. The time limit
 * cuts only once the first pass is done (spp_done is written between passes, while no worker
 * runs), so that a budget shorter than auto's pilot and the first pass ends the bake right after
 * them with that pass's samples (2 per pixel, 1 where 1 is asked), not with an empty image; as
 * Cycles, which renders at least one sample. */
static inline int dwvb_bake_must_stop(dwvb_bake *bake)
{
    if (atomic_load_explicit(&bake->cancelled, memory_order_relaxed)) return 1;
    if (bake->options.time_limit > 0.0 && bake->spp_done > 0 && dwvb_bake_elapsed(bake) >= bake->options.time_limit) {
        atomic_store(&bake->time_up, 1);
        return 1;
    }
    return 0;
}

/* Sample s of pixel `index` shaded by `shader`, with the random streams `stream` (pixel
 * position, entry, lights and the walk's first events) and `stream | WALK_STREAM` (the rest of
 * the walk): its passes in *parts, its combined radiance in rgb (dwvb_shade_parts_combined, less
 * the environment where the camera sees a transparent background or for UV bakes, whose
 * environment part is Cycles' Environment bake and is filled only when the bake asks for it);
 * the mesh it saw (or UINT32_MAX) in *mesh_seen. */
void dwvb_bake_sample(const dwvb_bake *bake, const dwvb_shader *shader, uint64_t stream, uint32_t index, uint64_t s,
                      dwvb_shade_parts *parts, double rgb[3], double *alpha, uint32_t *mesh_seen, dwvb_tally *tally);

#endif
