#define _POSIX_C_SOURCE 200809L
#include "bake.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bake/shade.h"
#include "bake/uv_raster.h"
#include "kernel/rng.h"
#include "util/clock.h"
#include "util/parallel.h"

/* The walk's random numbers come from a stream of their own: bit 63 of the stream marks it. The
 * per-pixel scrambles of the stratified pairs (kernel/sampler.h) come from bit 62's stream. */
#define WALK_STREAM 0x8000000000000000ull
#define PIXEL_STREAM 0x4000000000000000ull
/* The pilot that chooses auto's technique per mesh draws from bit 61's streams. */
#define PILOT_STREAM 0x2000000000000000ull
#define PROGRESS_PERIOD 0.1 /* seconds between progress callbacks */

/* A pixel's samples form two independent replicates (sample_with): even samples and odd ones. */
#define REPLICATES 2u

typedef struct pixel_sums {
    double sum[3], sum_squares[3];
    double sum_alpha, sum_luminance_squares;
    double replicate_luminance[REPLICATES]; /* the sum of each replicate's luminances */
} pixel_sums;

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
    int *auto_choice; /* per mesh: auto's technique is chosen by the pilot (choose_auto) */
    uint32_t features;
    /* camera */
    dwvu_vec3 eye, right, up, forward; /* right/up scaled to the image's half extents */
    /* UV */
    dwvb_uv_raster raster;
    /* accumulation */
    pixel_sums *sums;
    uint32_t *counts;
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

static double elapsed(const dwvb_bake *bake)
{
    return dwvu_clock_seconds() - bake->start;
}

static double luminance(const double rgb[3])
{
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
}

/* The uniform pair of a sample that places it in its pixel (camera bakes); shading takes the next. */
#define PIXEL_PAIR 0u

/* One camera sample through pixel (x, row). Blender's camera: local -z forward, +y up, the
 * sensor (or ortho_scale) across the larger image side; a box filter over the pixel. */
static void camera_sample(const dwvb_bake *bake, uint32_t x, uint32_t row, const dwvk_sampler *sampler,
                          dwvu_vec3 *origin, dwvu_vec3 *direction)
{
    double u[2];
    dwvk_sampler_pair(sampler, PIXEL_PAIR, u);
    double sx = 2.0 * ((double)x + u[0]) / bake->width - 1.0;
    double sy = 1.0 - 2.0 * ((double)row + u[1]) / bake->height;
    dwvu_vec3 offset = dwvu_add(dwvu_scale(bake->right, sx), dwvu_scale(bake->up, sy));
    if (bake->scene->camera.kind == DWV_CAMERA_PERSPECTIVE) {
        *origin = bake->eye;
        *direction = dwvu_normalize(dwvu_add(bake->forward, offset));
    } else {
        *origin = dwvu_add(bake->eye, offset);
        *direction = bake->forward;
    }
}


/* Sample s of pixel `index` shaded by `shader`, with the random streams `stream` (pixel
 * position, entry, lights and the walk's first events) and `stream | WALK_STREAM` (the rest of
 * the walk); the mesh it saw (or UINT32_MAX) in *mesh_seen. */
static void sample_with(const dwvb_bake *bake, const dwvb_shader *shader, uint64_t stream, uint32_t index, uint64_t s,
                        double rgb[3], double *alpha, uint32_t *mesh_seen, dwvb_tally *tally)
{
    /* Pixel position, entry direction, light points and the walk's first events (shade.h,
     * DWVB_STRATIFIED_EVENTS): stratified per pixel (kernel/sampler.h), in REPLICATES independent
     * stratified sets, sample s in replicate s mod REPLICATES with its own scrambling: the spread
     * between the replicates' means measures the pixel's error, stratification included
     * (estimate_error). */
    dwvk_sampler sampler = {.key = dwvk_rng_key(bake->options.seed, stream | PIXEL_STREAM | index, s % REPLICATES),
                            .index = s / REPLICATES, .stratified = 1};
    uint64_t key_walk = dwvk_rng_key(bake->options.seed, stream | WALK_STREAM | index, s);
    *mesh_seen = UINT32_MAX;
    uint32_t x = index % bake->width, row = index / bake->width;
    dwvg_hit hit;
    dwvu_vec3 view;
    if (bake->options.target == DWV_BAKE_CAMERA) {
        dwvu_vec3 origin;
        camera_sample(bake, x, row, &sampler, &origin, &view);
        if (!(bake->scene->mesh_count > 0 && dwvg_intersect(&bake->scene->geometry, origin, view, 0.0, INFINITY, &hit))) {
            for (int c = 0; c < 3; ++c) rgb[c] = bake->scene->world[c];
            *alpha = 0.0;
            return;
        }
    } else {
        /* The texel centre's surface point, seen along its normal: the radiance leaving along n. */
        const dwvb_uv_texel *texel = &bake->raster.texels[index];
        hit.mesh = bake->options.uv_mesh;
        hit.prim = (uint32_t)texel->triangle;
        hit.u = texel->b1;
        hit.v = texel->b2;
        hit.t = 0.0;
        const dwvg_mesh *mesh = &bake->scene->meshes[hit.mesh];
        view = dwvu_scale(dwvg_geometric_normal(mesh, hit.prim), -1.0);
    }
    *mesh_seen = hit.mesh;
    dwvb_shade(shader, &hit, view, &sampler, PIXEL_PAIR + 1u, key_walk, rgb, tally);
    *alpha = 1.0;
    if (!(isfinite(rgb[0]) && isfinite(rgb[1]) && isfinite(rgb[2]))) {
        ++tally->warnings;
        rgb[0] = rgb[1] = rgb[2] = 0.0;
    }
}

static void sample_pixel(dwvb_bake *bake, uint32_t index, uint64_t s, double rgb[3], double *alpha, dwvb_tally *tally)
{
    uint32_t mesh_seen;
    sample_with(bake, &bake->shader, 0u, index, s, rgb, alpha, &mesh_seen, tally);
}

static int pixel_active(const dwvb_bake *bake, uint32_t index)
{
    return bake->options.target == DWV_BAKE_CAMERA || bake->raster.texels[index].triangle >= 0;
}

/* Whether the worker must stop: cancelled, or (with a time limit) out of time. The time limit
 * cuts only once the first pass is done (spp_done is written between passes, while no worker
 * runs), so that a budget shorter than auto's pilot and the first pass ends the bake right after
 * them with that pass's samples (2 per pixel, 1 where 1 is asked), not with an empty image; as
 * Cycles, which renders at least one sample. */
static int must_stop(dwvb_bake *bake)
{
    if (atomic_load_explicit(&bake->cancelled, memory_order_relaxed)) return 1;
    if (bake->options.time_limit > 0.0 && bake->spp_done > 0 && elapsed(bake) >= bake->options.time_limit) {
        atomic_store(&bake->time_up, 1);
        return 1;
    }
    return 0;
}

static void *worker(void *arg)
{
    dwvb_bake *bake = arg;
    uint32_t tile_size = bake->options.tile_size;
    int stop = 0;
    while (!stop && !must_stop(bake)) {
        uint32_t slot = atomic_fetch_add(&bake->next_tile, 1u);
        if (slot >= bake->tile_count) break;
        uint32_t tile = bake->tile_order[slot];
        double tile_start = dwvu_clock_seconds();
        uint32_t x0 = (tile % bake->tiles_x) * tile_size, y0 = (tile / bake->tiles_x) * tile_size;
        uint32_t x1 = x0 + tile_size < bake->width ? x0 + tile_size : bake->width;
        uint32_t y1 = y0 + tile_size < bake->height ? y0 + tile_size : bake->height;
        dwvb_tally *tally = &bake->tile_tallies[tile];
        uint64_t events_before = tally->events;
        for (uint32_t y = y0; y < y1 && !stop; ++y) {
            for (uint32_t x = x0; x < x1 && !stop; ++x) {
                uint32_t index = y * bake->width + x;
                if (!pixel_active(bake, index)) continue;
                pixel_sums *p = &bake->sums[index];
                for (uint64_t s = bake->pass_first; s < bake->pass_end; ++s) {
                    /* Checked per sample, which ends within max_events: cancel is quick and a
                     * time limit cuts where the clock says (pixels keep the samples they got). */
                    if ((stop = must_stop(bake))) break;
                    double rgb[3], alpha;
                    sample_pixel(bake, index, s, rgb, &alpha, tally);
                    for (int c = 0; c < 3; ++c) {
                        p->sum[c] += rgb[c];
                        p->sum_squares[c] += rgb[c] * rgb[c];
                    }
                    double l = luminance(rgb);
                    p->sum_luminance_squares += l * l;
                    p->replicate_luminance[s % REPLICATES] += l;
                    p->sum_alpha += alpha;
                    ++bake->counts[index];
                }
            }
        }
        atomic_fetch_add(&bake->events, tally->events - events_before);
        bake->tile_seconds[tile] = dwvu_clock_seconds() - tile_start;
        if (!stop) atomic_fetch_add(&bake->tiles_done, 1u);
    }
    pthread_mutex_lock(&bake->lock);
    --bake->workers_running;
    pthread_cond_broadcast(&bake->changed);
    pthread_mutex_unlock(&bake->lock);
    return NULL;
}

/* Whether pixel `index` counts in the image's error and mean: UV texels of the islands; camera
 * pixels that saw a surface (all pixels when none did). */
static int covered(const dwvb_bake *bake, uint32_t index, int any_surface)
{
    if (bake->options.target == DWV_BAKE_UV) return bake->raster.texels[index].triangle >= 0;
    return !any_surface || bake->sums[index].sum_alpha > 0.0;
}

static int any_surface_seen(const dwvb_bake *bake)
{
    if (bake->options.target != DWV_BAKE_CAMERA) return 1;
    size_t pixels = (size_t)bake->width * bake->height;
    for (size_t i = 0; i < pixels; ++i)
        if (bake->sums[i].sum_alpha > 0.0) return 1;
    return 0;
}

/* The variance of a pixel's mean from its sums: (sum x^2 - (sum x)^2 / n) / (n (n - 1)); 0 below
 * two samples (unknown, see dwvb_estimate_error). */
static double mean_variance(double sum, double sum_squares, uint32_t n)
{
    if (n < 2u) return 0.0;
    double v = (sum_squares - sum * sum / n) / ((double)n * (n - 1u));
    return v > 0.0 ? v : 0.0;
}

/* Below this many covered pixels the image's error comes from the samples' own variance instead
 * of the replicates' spread: with N pixels the spread has N degrees of freedom, its relative
 * standard error sqrt(2 / N) in the variance (18% at 64), and one of a few pixels could by chance
 * say the image is done long before it is. */
#define REPLICATE_MIN_PIXELS 64.0

/* The image's relative RMSE against its converged self: sqrt(mean over the covered pixels of the
 * variance of the pixel's mean luminance) / (mean of the pixels' mean luminances) =
 * sqrt(N sum var) / sum luminance for N covered pixels. This is the "relative RMSE" of an image
 * against a reference (RMSE / mean), so a target of 0.01 means noise of 1% of the image's
 * brightness per pixel. +inf while a covered pixel has fewer than two samples, 0 for an image that
 * is black with no variance.
 * A pixel's variance is measured by its two replicates (sample_with): means m0, m1 of n0, n1
 * samples are independent and unbiased, so E[(m0 - m1)^2] = V0 + V1, and with V_r = c / n_r the
 * variance of the pixel's mean, c / n, is E[(m0 - m1)^2] n0 n1 / n^2. The samples' own variance
 * (x^2 sums) would treat a pixel's samples as independent, while stratified ones are negatively
 * correlated, and overstate the error: 1.1x to 1.4x with shared walks, 2.2x with channel walks,
 * which share a sample's stratified numbers over three walks (docs/speed.md). It is used below
 * REPLICATE_MIN_PIXELS covered pixels, where the replicates' spread is too noisy. */
static double estimate_error(const dwvb_bake *bake)
{
    int any = any_surface_seen(bake);
    size_t pixels = (size_t)bake->width * bake->height;
    double spread = 0.0, own = 0.0, total = 0.0, count = 0.0;
    for (size_t i = 0; i < pixels; ++i) {
        if (!covered(bake, (uint32_t)i, any)) continue;
        count += 1.0;
        uint32_t n = bake->counts[i];
        if (n < 2u) return INFINITY;
        const pixel_sums *p = &bake->sums[i];
        double l = luminance(p->sum);
        total += l / n;
        own += mean_variance(l, p->sum_luminance_squares, n);
        double n0 = (double)((n + 1u) / 2u), n1 = (double)(n / 2u);
        double d = p->replicate_luminance[0] / n0 - p->replicate_luminance[1] / n1;
        spread += d * d * n0 * n1 / ((double)n * (double)n);
    }
    double variance = count >= REPLICATE_MIN_PIXELS ? spread : own;
    if (variance == 0.0) return 0.0;
    return total > 0.0 ? sqrt(count * variance) / total : INFINITY;
}

static double fraction_done(dwvb_bake *bake)
{
    double pass_share = bake->tile_count ? (double)atomic_load(&bake->tiles_done) / bake->tile_count : 0.0;
    double spp = (double)bake->spp_done + pass_share * (double)(bake->pass_end - bake->pass_first);
    double f = spp / (double)bake->options.samples;
    if (bake->options.time_limit > 0.0) f = fmax(f, elapsed(bake) / bake->options.time_limit);
    /* The error falls as 1/sqrt(samples): (target / error)^2 is the share of samples done. */
    if (bake->options.target_error > 0.0 && isfinite(bake->error) && bake->error > 0.0)
        f = fmax(f, (bake->options.target_error / bake->error) * (bake->options.target_error / bake->error));
    return fmin(fmax(f, 0.0), 1.0);
}

/* Refreshes the shared progress and calls the callback (outside the lock). */
static void report(dwvb_bake *bake, int done)
{
    dwv_bake_progress_t p = DWV_BAKE_PROGRESS_INIT;
    p.done = (uint32_t)done;
    p.fraction = done && bake->result == DWV_SUCCESS ? 1.0 : fraction_done(bake);
    p.seconds = elapsed(bake);
    p.estimated_relative_error = bake->error;
    p.samples_per_pixel = bake->spp_done;
    p.events = (uint64_t)atomic_load(&bake->events);
    pthread_mutex_lock(&bake->lock);
    bake->progress = p;
    pthread_mutex_unlock(&bake->lock);
    if (bake->options.progress && bake->options.progress(bake->options.progress_user, &p) != 0)
        atomic_store(&bake->cancelled, 1);
}

static void timed_wait(dwvb_bake *bake, double seconds)
{
    struct timespec until = dwvu_clock_after(seconds);
    pthread_cond_timedwait(&bake->changed, &bake->lock, &until);
}

typedef struct timed_tile {
    double seconds;
    uint32_t tile;
} timed_tile;

static int longer_first(const void *a, const void *b)
{
    const timed_tile *x = a, *y = b;
    if (x->seconds != y->seconds) return x->seconds > y->seconds ? -1 : 1;
    return x->tile < y->tile ? -1 : x->tile > y->tile;
}

/* Orders the tiles by the seconds they took in the previous pass, longest first; the first pass
 * keeps the raster order. Passes double in samples, so the previous pass predicts the next. */
static void order_tiles(dwvb_bake *bake)
{
    timed_tile *ranking = bake->tile_ranking;
    if (bake->spp_done == 0u) return;
    for (uint32_t t = 0; t < bake->tile_count; ++t) ranking[t] = (timed_tile){bake->tile_seconds[t], t};
    qsort(ranking, bake->tile_count, sizeof *ranking, longer_first);
    for (uint32_t t = 0; t < bake->tile_count; ++t) bake->tile_order[t] = ranking[t].tile;
}

/* Runs one pass on `threads` workers while reporting progress; 0, or -1 if threads could not start. */
static int run_pass(dwvb_bake *bake)
{
    order_tiles(bake);
    atomic_store(&bake->next_tile, 0u);
    atomic_store(&bake->tiles_done, 0u);
    pthread_mutex_lock(&bake->lock);
    bake->workers_running = bake->threads;
    pthread_mutex_unlock(&bake->lock);
    uint32_t started = dwvu_parallel_start(&bake->workers, bake->threads, worker, bake);
    pthread_mutex_lock(&bake->lock);
    bake->workers_running -= bake->threads - started;
    while (bake->workers_running > 0) {
        timed_wait(bake, PROGRESS_PERIOD);
        pthread_mutex_unlock(&bake->lock);
        report(bake, 0);
        pthread_mutex_lock(&bake->lock);
    }
    pthread_mutex_unlock(&bake->lock);
    dwvu_parallel_join(&bake->workers);
    return started == 0 ? -1 : 0;
}

static dwv_result_t fail(dwvb_bake *bake, dwv_result_t result, const char *message)
{
    snprintf(bake->message, sizeof bake->message, "%s", message);
    return result;
}

/* Turns the sums into the image and its stats. */
static dwv_result_t make_image(dwvb_bake *bake, double seconds)
{
    dwvb_image *image = bake->image;
    size_t pixels = (size_t)bake->width * bake->height;
    int any = any_surface_seen(bake);
    dwv_bake_stats_t *st = &image->stats;
    double mean[3] = {0.0, 0.0, 0.0};
    uint64_t covered_count = 0, samples = 0, largest = 0;
    for (size_t i = 0; i < pixels; ++i) {
        uint32_t n = bake->counts[i];
        const pixel_sums *p = &bake->sums[i];
        samples += n;
        if (n > largest) largest = n;
        if (n == 0u) continue;
        for (int c = 0; c < 3; ++c) {
            image->rgba[4 * i + c] = (float)(p->sum[c] / n);
            image->variance[3 * i + c] = (float)mean_variance(p->sum[c], p->sum_squares[c], n);
        }
        image->rgba[4 * i + 3] = (float)(p->sum_alpha / n);
        image->samples[i] = n;
        if (covered(bake, (uint32_t)i, any)) {
            ++covered_count;
            for (int c = 0; c < 3; ++c) mean[c] += p->sum[c] / n;
        }
    }
    dwvb_tally total = {0};
    for (uint32_t t = 0; t < bake->tile_count; ++t) {
        total.events += bake->tile_tallies[t].events;
        total.walks += bake->tile_tallies[t].walks;
        total.warnings += bake->tile_tallies[t].warnings;
        total.mixture_terms += bake->tile_tallies[t].mixture_terms;
        total.rays += bake->tile_tallies[t].rays;
        total.point_queries += bake->tile_tallies[t].point_queries;
        total.ray_free_steps += bake->tile_tallies[t].ray_free_steps;
        total.ray_free_misses += bake->tile_tallies[t].ray_free_misses;
        for (int c = 0; c < 3; ++c) total.truncated[c] += bake->tile_tallies[t].truncated[c];
    }
    st->technique = bake->options.technique;
    st->samples_per_pixel = largest;
    st->samples = samples;
    st->events = total.events;
    image->rays = total.rays;
    image->point_queries = total.point_queries;
    image->ray_free_steps = total.ray_free_steps;
    image->ray_free_misses = total.ray_free_misses;
    image->mixture_terms = total.mixture_terms;
    st->walks = total.walks;
    st->seconds = seconds;
    st->estimated_relative_error = bake->error;
    for (int c = 0; c < 3; ++c) {
        st->mean_rgb[c] = covered_count ? mean[c] / (double)covered_count : 0.0;
        st->truncated_weight[c] = samples ? total.truncated[c] / (double)samples : 0.0;
    }
    st->features = bake->features;
    st->threads = bake->threads;
    st->warnings = bake->scene->warnings + total.warnings;
    if (bake->options.target == DWV_BAKE_UV) {
        dwv_result_t r = dwvb_uv_dilate_image(&bake->raster, bake->options.uv_margin, image);
        if (r != DWV_SUCCESS) return fail(bake, r, "no memory for the UV margin");
    }
    return DWV_SUCCESS;
}

static int choose_auto(dwvb_bake *bake);

static dwv_result_t run(dwvb_bake *bake)
{
    uint64_t samples = bake->options.samples;
    int pilot = choose_auto(bake);
    if (pilot < 0) return fail(bake, DWV_ERROR_OUT_OF_MEMORY, "no memory for auto's pilot");
    if (atomic_load(&bake->cancelled)) return fail(bake, DWV_ERROR_CANCELLED, "the bake was cancelled");
    while (bake->spp_done < samples) {
        uint64_t pass = bake->spp_done == 0 ? 2u : bake->spp_done;
        if (pass > samples - bake->spp_done) pass = samples - bake->spp_done;
        bake->pass_first = bake->spp_done;
        bake->pass_end = bake->spp_done + pass;
        if (run_pass(bake)) return fail(bake, DWV_ERROR_INTERNAL, "could not start a worker thread");
        if (atomic_load(&bake->cancelled)) return fail(bake, DWV_ERROR_CANCELLED, "the bake was cancelled");
        int cut = atomic_load(&bake->time_up);
        if (!cut) bake->spp_done = bake->pass_end;
        bake->error = estimate_error(bake);
        dwv_error_point_t point = {elapsed(bake), bake->error, bake->spp_done};
        if (!cut && dwvb_image_add_error_point(bake->image, point))
            return fail(bake, DWV_ERROR_OUT_OF_MEMORY, "no memory for the error series");
        if (cut) break;
        if (bake->options.target_error > 0.0 && bake->error <= bake->options.target_error) break;
    }
    return make_image(bake, elapsed(bake));
}

static void *control(void *arg)
{
    dwvb_bake *bake = arg;
    dwv_result_t result = run(bake);
    if (result != DWV_SUCCESS && bake->image) {
        dwvb_image_free(bake->image);
        bake->image = NULL;
    }
    bake->result = result;
    report(bake, 1);
    pthread_mutex_lock(&bake->lock);
    bake->done = 1;
    pthread_cond_broadcast(&bake->changed);
    pthread_mutex_unlock(&bake->lock);
    return NULL;
}

static void release_parts(dwvb_bake *bake)
{
    free(bake->guides);
    free(bake->channel_guides);
    free(bake->channel_walks);
    free(bake->channel_counts);
    free(bake->needs_closest);
    free(bake->auto_choice);
    free(bake->sums);
    free(bake->counts);
    free(bake->tile_tallies);
    free(bake->tile_order);
    free(bake->tile_seconds);
    free(bake->tile_ranking);
    dwvb_uv_raster_free(&bake->raster);
    if (bake->image) dwvb_image_free(bake->image);
    pthread_mutex_destroy(&bake->lock);
    pthread_cond_destroy(&bake->changed);
    free(bake);
}

/* The camera's frame: right and up span the image's half extents at unit distance (perspective)
 * or in scene units (orthographic). */
static void setup_camera(dwvb_bake *bake)
{
    const dwv_camera_t *cam = &bake->scene->camera;
    const double *m = cam->transform;
    bake->eye = dwvu_v(m[3], m[7], m[11]);
    dwvu_vec3 x = dwvu_v(m[0], m[4], m[8]), y = dwvu_v(m[1], m[5], m[9]), z = dwvu_v(m[2], m[6], m[10]);
    double half = cam->kind == DWV_CAMERA_PERSPECTIVE ? 0.5 * cam->sensor_width / cam->focal_length
                                                      : 0.5 * cam->ortho_scale;
    double aspect = (double)bake->width / bake->height;
    double half_x = aspect >= 1.0 ? half : half * aspect, half_y = aspect >= 1.0 ? half / aspect : half;
    bake->right = dwvu_scale(x, half_x);
    bake->up = dwvu_scale(y, half_y);
    bake->forward = dwvu_scale(z, -1.0);
}

/* Which meshes' walks the bake can reach: all for a camera, the one mesh for a UV bake. */
static int mesh_used(const dwvb_bake *bake, uint32_t m)
{
    return bake->options.target == DWV_BAKE_CAMERA || m == bake->options.uv_mesh;
}

/* The features the bake's guides use, from those of the scene. */
static void update_features(dwvb_bake *bake)
{
    const dwvb_scene *scene = bake->scene;
    uint32_t features = scene->features & ~(uint32_t)(DWV_FEATURE_INCIDENT_PATCHES | DWV_FEATURE_CLOSEST_POINT |
                                                      DWV_FEATURE_SHEET);
    int rgb = 0;
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        const dwvb_material *material = &scene->shading[scene->meshes[m].material_id];
        if (!material->subsurface || !mesh_used(bake, m)) continue;
        if (bake->needs_closest[m]) features |= DWV_FEATURE_CLOSEST_POINT;
        const dwvw_guide *guides = bake->channel_walks[m] ? &bake->channel_guides[3u * m] : &bake->guides[m];
        for (int c = 0; c < (bake->channel_walks[m] ? 3 : 1); ++c) {
            if (bake->channel_walks[m] && !(material->walk_scale[c] > 0.0)) continue;
            if (guides[c].q_incident > 0.0 && guides[c].patch_count > 0) features |= DWV_FEATURE_INCIDENT_PATCHES;
            if (guides[c].q_classical < 1.0) features |= DWV_FEATURE_GUIDED;
            if (guides[c].q_sheet > 0.0) features |= DWV_FEATURE_SHEET;
        }
        if (bake->channel_walks[m]) features |= DWV_FEATURE_CHANNEL_WALKS;
        else if (!material->grey) rgb = 1;
    }
    /* Three-channel walks only where some mesh walks its channels together. */
    if (!rgb) features &= ~(uint32_t)DWV_FEATURE_RGB_WALKS;
    bake->features = features;
}

/* Whether mesh m's walks query the closest surface point, for the guides its samples use. */
static int mesh_needs_closest(const dwvb_material *material, int channel_walks, const dwvw_guide *guide,
                              const dwvw_guide *channel_guides)
{
    if (!channel_walks) return dwvw_guide_needs_closest(guide);
    int needs = 0;
    for (int c = 0; c < 3; ++c)
        if (material->walk_scale[c] > 0.0) needs |= dwvw_guide_needs_closest(&channel_guides[c]);
    return needs;
}

/* The technique of mesh m's walks in a medium whose largest albedo is `albedo`. */
static dwvw_technique medium_technique(const dwvb_bake *bake, uint32_t m, double albedo)
{
    dwvw_technique technique = (dwvw_technique)bake->options.technique;
    /* Incident guiding needs lit patches; where a mesh has none (no light reaches it) it
     * aims at the closest surface point instead, as auto does. */
    if (technique == DWVW_INCIDENT && bake->scene->patch_count[m] == 0) technique = DWVW_CLOSEST;
    /* Auto leaves media to classical sampling below albedo 0.2 (dwvw_auto_weights); Cycles'
     * floor raises every lower albedo to exactly 0.2, where walks average about 1.25 events
     * and guiding has nothing to gain, so those stay classical too. */
    if (technique == DWVW_AUTO && albedo <= DWVB_MIN_ALPHA) technique = DWVW_CLASSICAL;
    return technique;
}

static void setup_guides(dwvb_bake *bake)
{
    const dwvb_scene *scene = bake->scene;
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        const dwvb_material *material = &scene->shading[scene->meshes[m].material_id];
        if (!material->subsurface) continue;
        dwvw_technique technique = medium_technique(bake, m, material->medium.albedo[material->medium.guide_channel]);
        dwvw_guide_init(&bake->guides[m], technique, &material->medium, scene->patches[m], scene->patch_count[m]);
        /* Channel walks' guides: each channel's own medium, with the technique its albedo gets. */
        int auto_walks = technique == DWVW_AUTO;
        for (int c = 0; c < 3; ++c) {
            if (material->grey || !(material->walk_scale[c] > 0.0)) continue;
            const dwvw_medium *medium = &material->channel_medium[c];
            dwvw_technique own = medium_technique(bake, m, medium->albedo[0]);
            auto_walks |= own == DWVW_AUTO;
            dwvw_guide_init(&bake->channel_guides[3u * m + (uint32_t)c], own, medium, scene->patches[m],
                            scene->patch_count[m]);
        }
        bake->channel_walks[m] = !material->grey && bake->options.channel_walks == DWV_CHANNEL_WALKS_SEPARATE;
        bake->needs_closest[m] = mesh_needs_closest(material, bake->channel_walks[m], &bake->guides[m],
                                                    &bake->channel_guides[3u * m]);
        /* Above that albedo the pilot chooses (choose_auto) the technique and, unless the option
         * fixes it, whether the channels walk apart; the mixture stays where it cannot. */
        bake->auto_choice[m] = bake->options.technique == DWV_TECHNIQUE_AUTO && mesh_used(bake, m) &&
                               (auto_walks || (!material->grey && bake->options.channel_walks == DWV_CHANNEL_WALKS_AUTO));
    }
    update_features(bake);
}

/* ---- auto: the technique that pays, per mesh --------------------------------------------------
 * Guiding lowers a walk's variance but costs work per event (a mixture of components, each with
 * a pdf and an exponential per channel pair); where the image's variance hardly moves that work
 * is wasted, and auto's small defensive classical share doubles the mixture's terms where guiding
 * alone would do (thin back-lit sheets). Before the first pass, a pilot shades the same pixel
 * samples with each candidate and keeps, per mesh, the one with the largest efficiency
 * 1 / (variance x cost) (Veach 1997, Sec. 2.4: the efficiency of an estimator; Hammersley and
 * Handscomb 1964). The candidates:
 * - classical sampling;
 * - Dwivedi sampling about the entry normal, toward the opposite interface where the first step
 *   found one (the backward technique; with no opposite interface it is the entry-normal
 *   technique, poe): on thick front-lit media its walks need 30% fewer events than classical ones
 *   at equal or lower variance (report's sphere: 17.4 against 24.3 events per walk), and on thin
 *   sheets it aims at the far face as well as the near one (slab: variance 0.61x poe's);
 * - the guided part of auto's mixture alone: toward the lit patches (incident), or the closest
 *   surface point where no light reaches the mesh;
 * - the sheet walk (walk.h, src/kernel/sheet.h), where light reaches some deciding mesh: toward
 *   the strongest lit patch with an importance linear in depth, the zero-variance walk of a thin
 *   sheet of albedo near 1, where Dwivedi's exponential is flat (the report's leaf: 7.5x less
 *   image variance than classical walks at equal samples, efficiency 3.3x-4.4x auto's earlier pick);
 * - each of these four with one walk per colour channel (channel walks, shade.h), where the
 *   medium's channels differ and the option leaves it to auto. A shared walk weighs every channel
 *   by the spectral MIS of all three; over many events the channels' weights then carry each
 *   other's pdfs and scatter widely. On the report's wax sphere (extinctions 2x and 5x apart) the
 *   image's variance per sample was 10x lower with one backward walk per channel, for 1.6x the
 *   time per sample (docs/speed.md); on the leaf (one extinction, albedos apart) it was not worth
 *   its cost. The pilot's variance is the three channels' together, as the image's RMSE over RGB
 *   counts it: the luminance hides the colour noise of shared walks. A channel-walk candidate
 *   also gets the walks per sample of each channel that suit it (candidate_work).
 * Auto's mixture itself (the guided part plus a classical share of 1% or less) is no candidate:
 * its variance was that of the guided part alone within the pilot's noise and its cost above it,
 * so it won none of the pilots on the report's sphere, slab, leaf and default scene (both meshes)
 * and the example scenes (20 pilots, seeds 1-3 or 1-2); it stays the technique of meshes the pilot
 * cannot decide (too few samples). Every candidate is unbiased, so the choice moves noise, never
 * the mean.
 * The cost is counted, not timed, so that the choice (and the image) depends on the seed only:
 * instructions per sample (camera ray, shading), per walk (its probe, exit and exit lighting),
 * per walk event (the event's
 * sampling and weight), more per event of a walk with a guided component (every candidate but
 * classical: a Dwivedi direction's frame, sampling and pdf; 1.5x a classical event in the fit;
 * the sheet's events are priced so too, with its two components' mixture terms: 1.54x a
 * classical event on the leaf in the model, 1.37x per event in callgrind, walks included),
 * per Embree ray the walk casts (steps inside a ball clear of the mesh cast
 * none: shade.c run_walk), per closest-point query and per mixture term (see dwvb_tally). They
 * are a least-squares fit (relative residuals, coefficients >= 0) of callgrind's instruction
 * counts in the bake's workers, one thread, 32 x 32 pixels, 16 spp, over the report's sphere,
 * slab, leaf and default scene x classical, poe, backward, incident, closest and cycles, and
 * classical, backward and incident with channel walks: tools/fit_pilot_cost.py, which refits
 * them (rms residual 18.8%; the worst: closest, whose query's cost grows with the mesh, -40% and
 * -53% on the sphere and the default scene, and incident on the sphere, whose lit patches are
 * weighed per event, -28% shared and -46% with channel walks; docs/speed.md). Rays come out at
 * 0: with the ray-free steps and the box's plane exits they are about 0.5-0.7 per event in every
 * technique, so the event's cost holds theirs. One-thread bake times agreed where the machine was
 * quiet enough to measure (report's sphere, 32 x 32 pixels, 16 spp, best of 6: backward and poe
 * 1.3% and 5.4% faster than classical, instructions 5.0% and 7.1%, two refits ago); under load a
 * timed fit (--measure time) is not usable (rms 32%). Only their ratios matter. */
#define PILOT_COST_SAMPLE 4514.0
#define PILOT_COST_WALK 545.5
#define PILOT_COST_EVENT 754.1
#define PILOT_COST_GUIDED_EVENT 306.1
#define PILOT_COST_RAY 0.0
#define PILOT_COST_QUERY 6028.0
#define PILOT_COST_TERM 25.22
/* Pilot samples per candidate: a sixteenth of the bake's samples, at most PILOT_MAX; below
 * PILOT_MIN the estimate is too noisy to act on and auto keeps its mixture. A mesh needs
 * PILOT_MESH_MIN of them to be decided. */
#define PILOT_MAX 4096u
#define PILOT_MIN 256u
#define PILOT_MESH_MIN 64.0

/* The candidates, in the order of the pilot (a tie keeps the earlier, cheaper one): the four
 * techniques with the channels walked together, then the same with one walk per channel. */
#define PILOT_TECHNIQUES 4
#define PILOT_CANDIDATES (2 * PILOT_TECHNIQUES)
enum { PILOT_CLASSICAL = 0, PILOT_ENTRY = 1, PILOT_GUIDED = 2, PILOT_SHEET = 3 };

/* Auto's classical share at or below which the guided candidates drop it: the isotropic
 * defensive share, min(0.01, 0.1 sqrt(1 - alpha)) (dwvw_auto_weights). Above it auto raised the
 * share to |g| for an anisotropic medium, where the Dwivedi pdf misses the phase function's peak
 * and a guided walk's weight per event, phase / pdf, grows without that share to bound it (it is
 * at most 1 / share: Hesterberg's defensive mixture). Measured on a thin back-lit slab with
 * g = 0.8, 2048 pilot samples: guided alone had sample variances of 0.003 to 380 over three seeds
 * against classical's 0.23, so the pilot's estimate would pick it by chance. */
#define PILOT_ISOTROPIC_SHARE 0.01

/* Technique `technique` (PILOT_*) of the pilot for a mesh of `medium` whose guide auto made
 * (`mixture`: auto's mixture, or classical where the albedo is too low to guide). */
static void pilot_guide(const dwvb_bake *bake, uint32_t m, int technique, const dwvw_medium *medium,
                        const dwvw_guide *mixture, dwvw_guide *guide)
{
    const dwvb_scene *scene = bake->scene;
    if (technique == PILOT_CLASSICAL || mixture->q_classical >= 1.0) {
        dwvw_guide_init(guide, DWVW_CLASSICAL, medium, NULL, 0);
        return;
    }
    if (technique == PILOT_SHEET) { /* its own classical share, at least auto's (walk.h) */
        dwvw_guide_init(guide, DWVW_SHEET, medium, scene->patches[m], scene->patch_count[m]);
        return;
    }
    if (technique == PILOT_ENTRY) dwvw_guide_init(guide, DWVW_BACKWARD, medium, NULL, 0);
    else if (mixture->q_incident > 0.0)
        dwvw_guide_init(guide, DWVW_INCIDENT, medium, scene->patches[m], scene->patch_count[m]);
    else dwvw_guide_init(guide, DWVW_CLOSEST, medium, NULL, 0);
    if (mixture->q_classical > PILOT_ISOTROPIC_SHARE) { /* keep auto's defensive classical share */
        double guided = 1.0 - mixture->q_classical;
        guide->q_classical = mixture->q_classical;
        guide->q_backward *= guided;
        guide->q_incident *= guided;
        guide->q_closest *= guided;
    }
}

/* Candidate `candidate` for mesh m (auto's guides in bake): its guide, its channel guides and
 * whether its channels walk apart (a grey medium's one-channel walks walk once either way). */
static void pilot_candidate(const dwvb_bake *bake, uint32_t m, int candidate, dwvw_guide *guide,
                            dwvw_guide channel_guides[3], int *channel_walks)
{
    const dwvb_material *material = &bake->scene->shading[bake->scene->meshes[m].material_id];
    int technique = candidate % PILOT_TECHNIQUES;
    pilot_guide(bake, m, technique, &material->medium, &bake->guides[m], guide);
    *channel_walks = candidate >= PILOT_TECHNIQUES && !material->grey;
    for (int c = 0; c < 3; ++c)
        if (!material->grey && material->walk_scale[c] > 0.0)
            pilot_guide(bake, m, technique, &material->channel_medium[c], &bake->channel_guides[3u * m + (uint32_t)c],
                        &channel_guides[c]);
}

typedef struct pilot_sums {
    double count, sum[3], sum_squares[3], cost;
    double channel_cost[3]; /* of the cost, the channel walks' own, by channel */
} pilot_sums;

static uint64_t active_pixels(const dwvb_bake *bake)
{
    uint64_t pixels = (uint64_t)bake->width * bake->height, active = 0;
    for (uint64_t i = 0; i < pixels; ++i) active += (uint64_t)pixel_active(bake, (uint32_t)i);
    return active;
}

/* The pilot's samples are cut into PILOT_BLOCKS fixed blocks that the bake's threads share; each
 * block sums its samples in order and the blocks are added in block order, so the sums, the choice
 * and the image are the same for any thread count. On one thread the pilot would be serial work
 * beside the passes (a few percent of a short bake: Amdahl's law on the 1 -> 2 thread speed-up). */
#define PILOT_BLOCKS 64u

typedef struct pilot_run {
    dwvb_bake *bake;
    const dwvb_shader *shaders; /* indexed by candidate */
    const int *candidates;      /* the candidates run (PILOT_*), candidate_count of them */
    int candidate_count;
    pilot_sums *block_sums;     /* [block][candidate][mesh] */
    uint32_t samples, meshes;
    atomic_uint next_block;
    atomic_int stopped;
} pilot_run;

static void *pilot_worker(void *arg)
{
    pilot_run *run = arg;
    dwvb_bake *bake = run->bake;
    uint64_t pixels = (uint64_t)bake->width * bake->height;
    for (;;) {
        uint32_t block = atomic_fetch_add(&run->next_block, 1u);
        if (block >= PILOT_BLOCKS || atomic_load(&run->stopped)) break;
        uint32_t first = (uint32_t)((uint64_t)run->samples * block / PILOT_BLOCKS);
        uint32_t end = (uint32_t)((uint64_t)run->samples * (block + 1u) / PILOT_BLOCKS);
        pilot_sums *sums = &run->block_sums[(size_t)block * PILOT_CANDIDATES * run->meshes];
        /* The same pixel samples for every candidate. */
        for (int k = 0; k < run->candidate_count; ++k) {
            int candidate = run->candidates[k];
            for (uint32_t i = first; i < end; ++i) {
                if (must_stop(bake)) {
                    atomic_store(&run->stopped, 1);
                    return NULL;
                }
                uint32_t index = (uint32_t)(dwvk_rng_u64(dwvk_rng_key(bake->options.seed, PILOT_STREAM, i), 0u) % pixels);
                if (!pixel_active(bake, index)) continue;
                double rgb[3], alpha;
                uint32_t mesh;
                dwvb_tally tally = {0};
                sample_with(bake, &run->shaders[candidate], PILOT_STREAM, index, i, rgb, &alpha, &mesh, &tally);
                if (mesh == UINT32_MAX || !bake->auto_choice[mesh]) continue;
                pilot_sums *p = &sums[(size_t)candidate * run->meshes + mesh];
                p->count += 1.0;
                for (int c = 0; c < 3; ++c) {
                    p->sum[c] += rgb[c];
                    p->sum_squares[c] += rgb[c] * rgb[c];
                }
                double event_cost = PILOT_COST_EVENT + (candidate % PILOT_TECHNIQUES == PILOT_CLASSICAL ? 0.0 : PILOT_COST_GUIDED_EVENT);
                p->cost += PILOT_COST_SAMPLE + PILOT_COST_WALK * (double)tally.walks + event_cost * (double)tally.events +
                           PILOT_COST_RAY * (double)tally.rays +
                           PILOT_COST_QUERY * (double)tally.point_queries + PILOT_COST_TERM * (double)tally.mixture_terms;
                for (int c = 0; c < 3; ++c)
                    p->channel_cost[c] += PILOT_COST_WALK * (double)tally.channel_walks[c] +
                                          event_cost * (double)tally.channel_events[c] +
                                          PILOT_COST_TERM * (double)tally.channel_terms[c];
            }
        }
    }
    return NULL;
}

/* Runs the pilot on the bake's threads; sums gets [candidate][mesh] totals. 0 done, 1 stopped
 * (cancel or time), -1 out of memory or no thread. */
static int run_pilot(dwvb_bake *bake, const dwvb_shader *shaders, const int *candidates, int candidate_count,
                     uint32_t samples, pilot_sums *sums)
{
    uint32_t meshes = bake->scene->mesh_count;
    size_t per_block = PILOT_CANDIDATES * (size_t)meshes;
    pilot_run run = {bake, shaders, candidates, candidate_count, calloc(PILOT_BLOCKS * per_block, sizeof(pilot_sums)),
                     samples, meshes, 0u, 0};
    if (!run.block_sums) return -1;
    atomic_init(&run.next_block, 0u);
    atomic_init(&run.stopped, 0);
    dwvu_parallel_run(bake->threads < 64u ? bake->threads : 64u, pilot_worker, &run);
    for (uint32_t block = 0; block < PILOT_BLOCKS; ++block)
        for (size_t k = 0; k < per_block; ++k) {
            const pilot_sums *b = &run.block_sums[block * per_block + k];
            sums[k].count += b->count;
            for (int c = 0; c < 3; ++c) {
                sums[k].sum[c] += b->sum[c];
                sums[k].sum_squares[c] += b->sum_squares[c];
            }
            sums[k].cost += b->cost;
            for (int c = 0; c < 3; ++c) sums[k].channel_cost[c] += b->channel_cost[c];
        }
    free(run.block_sums);
    return atomic_load(&run.stopped) ? 1 : 0;
}

/* A candidate's variance x cost per sample that saw the mesh; the variance is the three channels'
 * together, as the image's RMSE over RGB counts it: the luminance would hide the colour noise of
 * shared walks, whose channels' weights move against each other. With channel walks, also how many
 * walks each walking channel takes per sample (counts, 1 to DWVB_MAX_CHANNEL_WALKS; else 1): the
 * optimal allocation of stratified sampling with a cost per stratum (Cochran 1977, Sampling
 * Techniques, ch. 5: n_c ~ sqrt(v_c / t_c)), searched exactly over the counts, some channel keeping
 * one walk (below). n walks of a channel divide its variance v_c by n and multiply
 * its walks' cost t_c by n; the rest of a sample's cost is shared. A channel whose walks are cheap
 * and noisy gets more of them: the back-lit slab's red, 1.3 mean free paths thick, against its
 * blue, 5 (docs/speed.md). Fewer than one walk per sample would cost the channel's squared mean
 * on top of its variance, more than it saves. */
static double candidate_work(const pilot_sums *p, const dwvb_material *material, int channel_walks, uint8_t counts[3])
{
    double variance[3], walk_cost[3], shared_cost = p->cost / p->count;
    for (int c = 0; c < 3; ++c) {
        double mean = p->sum[c] / p->count;
        variance[c] = fmax(p->sum_squares[c] / p->count - mean * mean, 0.0) * p->count / (p->count - 1.0);
        walk_cost[c] = p->channel_cost[c] / p->count;
        shared_cost -= walk_cost[c];
        counts[c] = 1u;
    }
    double best = INFINITY;
    uint32_t most = channel_walks ? DWVB_MAX_CHANNEL_WALKS : 1u;
    for (uint32_t n0 = 1; n0 <= most; ++n0)
        for (uint32_t n1 = 1; n1 <= most; ++n1)
            for (uint32_t n2 = 1; n2 <= most; ++n2) {
                uint32_t n[3] = {n0, n1, n2};
                double v = 0.0, t = shared_cost;
                int useless = 0;
                uint32_t fewest = UINT32_MAX; /* of the walking channels' counts */
                for (int c = 0; c < 3; ++c) {
                    int walks = material->walk_scale[c] > 0.0;
                    useless |= n[c] > 1u && !walks; /* no walk to repeat */
                    if (walks && n[c] < fewest) fewest = n[c];
                    v += variance[c] / n[c];
                    t += walk_cost[c] * n[c];
                }
                /* Some channel keeps one walk: more walks for every channel would only spread the
                 * sample's shared cost, a gain the counted cost model cannot tell from its error
                 * (measured: the leaf's 2 to 3 walks per channel cost 4.4x the instructions for
                 * 4.3x less variance, where the model promised 1.4x). */
                if (useless || (fewest != UINT32_MAX && fewest > 1u) || !(v * t < best)) continue; /* a tie keeps the fewer walks */
                best = v * t;
                for (int c = 0; c < 3; ++c) counts[c] = (uint8_t)n[c];
            }
    return best;
}

/* Runs the pilot and narrows bake->guides; 0 done (or nothing to decide), 1 cancelled or out of
 * time, -1 out of memory. */
static int choose_auto(dwvb_bake *bake)
{
    const dwvb_scene *scene = bake->scene;
    uint32_t meshes = scene->mesh_count, deciding = 0;
    int separable = 0, lit = 0;
    for (uint32_t m = 0; m < meshes; ++m) {
        deciding += (uint32_t)bake->auto_choice[m];
        separable |= bake->auto_choice[m] && !scene->shading[scene->meshes[m].material_id].grey;
        lit |= bake->auto_choice[m] && scene->patch_count[m] > 0;
    }
    if (deciding == 0) return 0;
    uint64_t budget = active_pixels(bake) * bake->options.samples / 16u;
    if (budget < PILOT_MIN) return 0;
    uint32_t n = budget < PILOT_MAX ? (uint32_t)budget : PILOT_MAX;
    /* Which forms run: the option's, or both where some deciding mesh has channels that differ. */
    int candidates[PILOT_CANDIDATES], candidate_count = 0;
    int shared = bake->options.channel_walks != DWV_CHANNEL_WALKS_SEPARATE || !separable;
    int separate = separable && bake->options.channel_walks != DWV_CHANNEL_WALKS_SHARED;
    /* The sheet walks only where some deciding mesh has a lit side to aim at (else they are
     * classical ones). */
    for (int c = 0; c < PILOT_CANDIDATES; ++c)
        if ((c < PILOT_TECHNIQUES ? shared : separate) && (c % PILOT_TECHNIQUES != PILOT_SHEET || lit))
            candidates[candidate_count++] = c;
    size_t slots = PILOT_CANDIDATES * (size_t)meshes;
    dwvw_guide *trial = malloc(slots * sizeof *trial);
    dwvw_guide *trial_channels = malloc(3u * slots * sizeof *trial_channels);
    int *trial_closest = malloc(slots * sizeof *trial_closest);
    int *trial_walks = malloc(slots * sizeof *trial_walks);
    pilot_sums *sums = calloc(slots, sizeof *sums); /* [candidate][mesh] */
    int stopped = -1;
    if (!trial || !trial_channels || !trial_closest || !trial_walks || !sums) goto done;
    dwvb_shader shaders[PILOT_CANDIDATES];
    for (int k = 0; k < candidate_count; ++k) {
        int candidate = candidates[k];
        size_t base = (size_t)candidate * meshes;
        for (uint32_t m = 0; m < meshes; ++m) {
            const dwvb_material *material = &scene->shading[scene->meshes[m].material_id];
            if (bake->auto_choice[m]) {
                pilot_candidate(bake, m, candidate, &trial[base + m], &trial_channels[3u * (base + m)],
                                &trial_walks[base + m]);
            } else {
                trial[base + m] = bake->guides[m];
                for (int c = 0; c < 3; ++c) trial_channels[3u * (base + m) + (size_t)c] = bake->channel_guides[3u * m + (uint32_t)c];
                trial_walks[base + m] = bake->channel_walks[m];
            }
            trial_closest[base + m] = material->subsurface &&
                                      mesh_needs_closest(material, trial_walks[base + m], &trial[base + m],
                                                         &trial_channels[3u * (base + m)]);
        }
        shaders[candidate] = bake->shader;
        shaders[candidate].guides = &trial[base];
        shaders[candidate].channel_guides = &trial_channels[3u * base];
        shaders[candidate].channel_walks = &trial_walks[base];
        shaders[candidate].needs_closest = &trial_closest[base];
    }
    stopped = run_pilot(bake, shaders, candidates, candidate_count, n, sums);
    if (stopped == 0) {
        for (uint32_t m = 0; m < meshes; ++m) {
            /* Every candidate traced the same camera rays, so each saw the mesh equally often. */
            if (!bake->auto_choice[m] || sums[(size_t)candidates[0] * meshes + m].count < PILOT_MESH_MIN) continue;
            /* variance x cost, per sample that saw the mesh; the variance is the three channels'
             * together, as the image's RMSE over RGB counts it: the luminance would hide the
             * colour noise of shared walks, whose channels' weights move against each other. */
            const dwvb_material *material = &scene->shading[scene->meshes[m].material_id];
            int best = candidates[0];
            double best_work = INFINITY;
            uint8_t best_counts[3] = {1u, 1u, 1u};
            for (int k = 0; k < candidate_count; ++k) {
                const pilot_sums *p = &sums[(size_t)candidates[k] * meshes + m];
                uint8_t counts[3];
                double work = candidate_work(p, material, trial_walks[(size_t)candidates[k] * meshes + m], counts);
                if (work < best_work) {
                    best_work = work;
                    best = candidates[k];
                    for (int c = 0; c < 3; ++c) best_counts[c] = counts[c];
                }
            }
            for (int c = 0; c < 3; ++c) bake->channel_counts[3u * m + (uint32_t)c] = best_counts[c];
            size_t slot = (size_t)best * meshes + m;
            bake->guides[m] = trial[slot];
            for (int c = 0; c < 3; ++c) bake->channel_guides[3u * m + (uint32_t)c] = trial_channels[3u * slot + (size_t)c];
            bake->channel_walks[m] = trial_walks[slot];
            bake->needs_closest[m] = trial_closest[slot];
        }
        update_features(bake);
    }
done:
    free(trial);
    free(trial_channels);
    free(trial_closest);
    free(trial_walks);
    free(sums);
    return stopped;
}

dwv_result_t dwvb_bake_start(dwvb_scene *scene, const dwv_bake_options_t *options, dwvb_bake **out,
                             char *message, size_t size)
{
    dwvb_bake *bake = calloc(1, sizeof *bake);
    if (!bake) {
        snprintf(message, size, "out of memory");
        return DWV_ERROR_OUT_OF_MEMORY;
    }
    bake->scene = scene;
    bake->options = *options;
    bake->width = options->width;
    bake->height = options->height;
    bake->threads = options->threads;
    bake->error = INFINITY;
    pthread_mutex_init(&bake->lock, NULL);
    pthread_condattr_t attributes;
    pthread_condattr_init(&attributes);
    pthread_condattr_setclock(&attributes, CLOCK_MONOTONIC);
    pthread_cond_init(&bake->changed, &attributes);
    pthread_condattr_destroy(&attributes);
    atomic_init(&bake->next_tile, 0u);
    atomic_init(&bake->tiles_done, 0u);
    atomic_init(&bake->time_up, 0);
    atomic_init(&bake->cancelled, 0);
    atomic_init(&bake->events, 0u);
    bake->progress = (dwv_bake_progress_t)DWV_BAKE_PROGRESS_INIT;
    bake->progress.estimated_relative_error = INFINITY;

    size_t pixels = (size_t)bake->width * bake->height;
    uint32_t tile = options->tile_size;
    bake->tiles_x = (bake->width + tile - 1u) / tile;
    bake->tile_count = bake->tiles_x * ((bake->height + tile - 1u) / tile);
    uint32_t meshes = scene->mesh_count ? scene->mesh_count : 1u;
    bake->guides = calloc(meshes, sizeof *bake->guides);
    bake->channel_guides = calloc(3u * (size_t)meshes, sizeof *bake->channel_guides);
    bake->channel_walks = calloc(meshes, sizeof *bake->channel_walks);
    bake->channel_counts = malloc(3u * (size_t)meshes * sizeof *bake->channel_counts);
    bake->needs_closest = calloc(meshes, sizeof *bake->needs_closest);
    bake->auto_choice = calloc(meshes, sizeof *bake->auto_choice);
    bake->sums = calloc(pixels, sizeof *bake->sums);
    bake->counts = calloc(pixels, sizeof *bake->counts);
    bake->tile_tallies = calloc(bake->tile_count, sizeof *bake->tile_tallies);
    bake->tile_order = malloc(bake->tile_count * sizeof *bake->tile_order);
    bake->tile_seconds = calloc(bake->tile_count, sizeof *bake->tile_seconds);
    bake->tile_ranking = malloc(bake->tile_count * sizeof *bake->tile_ranking);
    bake->image = dwvb_image_new(bake->width, bake->height);
    if (!bake->guides || !bake->channel_guides || !bake->channel_walks || !bake->channel_counts || !bake->needs_closest || !bake->auto_choice || !bake->sums || !bake->counts ||
        !bake->tile_tallies || !bake->tile_order || !bake->tile_seconds || !bake->tile_ranking || !bake->image) {
        release_parts(bake);
        snprintf(message, size, "out of memory for a %u x %u bake", options->width, options->height);
        return DWV_ERROR_OUT_OF_MEMORY;
    }
    for (uint32_t t = 0; t < bake->tile_count; ++t) bake->tile_order[t] = t;
    for (size_t k = 0; k < 3u * (size_t)meshes; ++k) bake->channel_counts[k] = 1u;
    if (options->target == DWV_BAKE_UV) {
        const dwvg_mesh *mesh = &scene->meshes[options->uv_mesh];
        dwv_result_t r = dwvb_uv_rasterize(mesh->uvs, mesh->triangle_count, bake->width, bake->height, &bake->raster);
        if (r != DWV_SUCCESS) {
            release_parts(bake);
            snprintf(message, size, "could not lay out the UVs of mesh %u (%s)", options->uv_mesh, dwv_result_string(r));
            return r;
        }
    } else {
        setup_camera(bake);
    }
    setup_guides(bake);
    bake->shader.scene = scene;
    bake->shader.env.lights = scene->emitters;
    bake->shader.env.light_count = scene->light_count;
    for (int c = 0; c < 3; ++c) bake->shader.env.world[c] = scene->world[c];
    bake->shader.env.world_lit = dwvb_scene_world_lit(scene);
    bake->shader.env.geometry = scene->mesh_count ? &scene->geometry : NULL;
    bake->shader.guides = bake->guides;
    bake->shader.channel_guides = bake->channel_guides;
    bake->shader.channel_walks = bake->channel_walks;
    bake->shader.channel_counts = bake->channel_counts;
    bake->shader.needs_closest = bake->needs_closest;
    bake->shader.max_events = options->max_events;
    if (options->target == DWV_BAKE_CAMERA) {
        /* The pixel's footprint for Cycles 4.0-4.4's quarter-pixel rule (shade.h). */
        double px = 2.0 / bake->width, py = 2.0 / bake->height;
        bake->shader.footprint = scene->camera.kind == DWV_CAMERA_PERSPECTIVE ? 1 : 2;
        bake->shader.eye = bake->eye;
        bake->shader.forward = bake->forward;
        bake->shader.pixel_right = dwvu_scale(bake->right, px);
        bake->shader.pixel_up = dwvu_scale(bake->up, py);
        bake->shader.pixel = dwvu_length(bake->shader.pixel_right);
    }
    bake->start = dwvu_clock_seconds();
    if (pthread_create(&bake->control, NULL, control, bake) != 0) {
        release_parts(bake);
        snprintf(message, size, "could not start the bake's control thread");
        return DWV_ERROR_INTERNAL;
    }
    bake->control_started = 1;
    *out = bake;
    return DWV_SUCCESS;
}

int dwvb_bake_wait(dwvb_bake *bake, double seconds)
{
    pthread_mutex_lock(&bake->lock);
    if (seconds < 0.0) {
        while (!bake->done) pthread_cond_wait(&bake->changed, &bake->lock);
    } else if (!bake->done && seconds > 0.0) {
        double start = dwvu_clock_seconds();
        for (;;) {
            double left = seconds - (dwvu_clock_seconds() - start);
            if (bake->done || left <= 0.0) break;
            timed_wait(bake, left);
        }
    }
    int done = bake->done;
    pthread_mutex_unlock(&bake->lock);
    return done;
}

void dwvb_bake_progress(dwvb_bake *bake, dwv_bake_progress_t *progress)
{
    pthread_mutex_lock(&bake->lock);
    uint32_t size = progress->struct_size;
    *progress = bake->progress;
    progress->struct_size = size;
    progress->done = (uint32_t)bake->done;
    pthread_mutex_unlock(&bake->lock);
}

void dwvb_bake_cancel(dwvb_bake *bake)
{
    atomic_store(&bake->cancelled, 1);
}

static void join(dwvb_bake *bake)
{
    dwvb_bake_wait(bake, -1.0);
    pthread_mutex_lock(&bake->lock);
    int join_now = bake->control_started && !bake->joined;
    bake->joined = 1;
    pthread_mutex_unlock(&bake->lock);
    if (join_now) pthread_join(bake->control, NULL);
}

dwv_result_t dwvb_bake_finish(dwvb_bake *bake, dwvb_image **image, char *message, size_t size)
{
    join(bake);
    if (bake->result != DWV_SUCCESS) {
        snprintf(message, size, "%s", bake->message);
        return bake->result;
    }
    if (!bake->image) {
        snprintf(message, size, "the image was already handed over");
        return DWV_ERROR_INVALID_STATE;
    }
    *image = bake->image;
    bake->image = NULL;
    return DWV_SUCCESS;
}

void dwvb_bake_free(dwvb_bake *bake)
{
    if (!bake) return;
    dwvb_bake_cancel(bake);
    join(bake);
    release_parts(bake);
}

long long dwvb_scene_geometry_bytes(const dwvb_scene *scene)
{
    return scene->mesh_count ? (long long)atomic_load(&((dwvb_scene *)scene)->geometry.embree_bytes) : 0;
}
