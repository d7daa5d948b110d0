#define _POSIX_C_SOURCE 200809L
#include "bake/bake.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "bake/bake_internal.h"
#include "bake/guides.h"
#include "bake/pilot.h"
#include "bake/pixel_sums.h"
#include "kernel/rng.h"

#define PROGRESS_PERIOD 0.1 /* seconds between progress callbacks */

/* The uniform pair of a sample that places it in its pixel (camera bakes); shading takes the next. */
#define PIXEL_PAIR 0u

/* One camera sample through pixel (x, row). Blender's camera: local -z forward, +y up, the
 * sensor (or ortho_scale) across the larger image side; the sample's place by the pixel filter
 * (pixel_filter.h: filter importance sampling, as Cycles' camera_sample), the stratified pair
 * through the filter's inverse distribution per axis. */
static void camera_sample(const dwvb_bake *bake, uint32_t x, uint32_t row, const dwvk_sampler *sampler,
                          dwvu_vec3 *origin, dwvu_vec3 *direction)
{
    double u[2];
    dwvk_sampler_pair(sampler, PIXEL_PAIR, u);
    const dwvb_pixel_filter *filter = &bake->pixel_filter;
    double px = filter->unit_box ? (double)x + u[0] : (double)x + 0.5 + dwvb_pixel_filter_sample(filter, u[0]);
    double py = filter->unit_box ? (double)row + u[1] : (double)row + 0.5 + dwvb_pixel_filter_sample(filter, u[1]);
    double sx = 2.0 * px / bake->width - 1.0;
    double sy = 1.0 - 2.0 * py / bake->height;
    dwvu_vec3 offset = dwvu_add(dwvu_scale(bake->right, sx), dwvu_scale(bake->up, sy));
    if (bake->scene->camera.kind == DWV_CAMERA_PERSPECTIVE) {
        *origin = bake->eye;
        *direction = dwvu_normalize(dwvu_add(bake->forward, offset));
    } else {
        *origin = dwvu_add(bake->eye, offset);
        *direction = bake->forward;
    }
}

/* The salt of the counter-based numbers of a texel sample's further tries (texel_sample). */
#define TEXEL_RETRY_SALT 0x9e6c63d0676a9a99ull

/* A UV bake's sample s of texel `index`: its triangle and the point of it the sample shades, and
 * the shader it shades with. As Cycles (integrator_init_from_bake), the texel centre moved by the
 * sampler's pair PIXEL_PAIR (unused otherwise in UV bakes: stratified over the texel's samples)
 * over a box of the texel's differentials, by the bake's uv_jitter rule (capi's dwv_uv_jitter_t):
 * - RETRY (3.5+, dwvb_uv_jitter): where that point is not inside the triangle, up to
 *   DWVB_UV_JITTER_TRIES - 1 further tries from counter-based numbers of the sample, then the
 *   centre. (Cycles shades its sample 0 at the centre; here every sample is jittered: the box
 *   filter's mean, to 1 / samples of it.)
 * - MIRROR (up to 3.4, dwvb_uv_fold): sample 0 at the centre, as Cycles; the others' points
 *   folded back into the triangle.
 * The shader is `shader` with the texel's footprint on the surface (dwvb_uv_texel_footprint) as a
 * constant one: Cycles' ray differential for Cycles 4.0-4.3's quarter-footprint rule
 * (dwvb_material.min_footprint). */
static void texel_sample(const dwvb_bake *bake, const dwvg_mesh *mesh, uint32_t index, uint64_t s,
                         const dwvk_sampler *sampler, uint64_t key_walk, dwvg_hit *hit, dwvb_shader *texel_shader,
                         const dwvb_shader *shader)
{
    const dwvb_uv_texel *texel = &bake->raster.texels[index];
    hit->prim = (uint32_t)texel->triangle;
    hit->u = texel->b1;
    hit->v = texel->b2;
    hit->t = 0.0;
    dwvb_uv_steps step;
    dwvb_uv_texel_steps(mesh->uvs + 6u * (size_t)hit->prim, bake->width, bake->height, &step);
    double r[2];
    dwvk_sampler_pair(sampler, PIXEL_PAIR, r);
    if (bake->options.uv_jitter == DWV_UV_JITTER_MIRROR) {
        if (s > 0u) dwvb_uv_fold(&step, texel->b1, texel->b2, r[0], r[1], &hit->u, &hit->v);
    } else {
        dwvk_sampler retry = {dwvk_mix64(key_walk ^ TEXEL_RETRY_SALT), 0u, 0};
        for (uint32_t k = 1; !dwvb_uv_jitter(&step, texel->b1, texel->b2, r[0], r[1], &hit->u, &hit->v); ++k) {
            if (k == DWVB_UV_JITTER_TRIES) break; /* the centre, set above */
            dwvk_sampler_pair(&retry, k - 1u, r);
        }
    }
    dwvu_vec3 p0 = dwvg_point(mesh, hit->prim, 0.0, 0.0);
    dwvu_vec3 e1 = dwvu_sub(dwvg_point(mesh, hit->prim, 1.0, 0.0), p0);
    dwvu_vec3 e2 = dwvu_sub(dwvg_point(mesh, hit->prim, 0.0, 1.0), p0);
    double edge1[3] = {e1.x, e1.y, e1.z}, edge2[3] = {e2.x, e2.y, e2.z};
    *texel_shader = *shader;
    texel_shader->footprint = DWVB_FOOTPRINT_CONSTANT;
    texel_shader->pixel = dwvb_uv_texel_footprint(edge1, edge2, &step);
}

void dwvb_bake_sample(const dwvb_bake *bake, const dwvb_shader *shader, uint64_t stream, uint32_t index, uint64_t s,
                      dwvb_shade_parts *parts, double rgb[3], double *alpha, uint32_t *mesh_seen, dwvb_tally *tally)
{
    /* Pixel position, entry direction, light points and the walk's first events (shade.h,
     * DWVB_STRATIFIED_EVENTS): stratified per pixel (kernel/sampler.h), in REPLICATES independent
     * stratified sets, sample s in replicate s mod REPLICATES with its own scrambling: the spread
     * between the replicates' means measures the pixel's error, stratification included
     * (dwvb_bake_estimate_error). */
    dwvk_sampler sampler = {.key = dwvk_rng_key(bake->options.seed, stream | PIXEL_STREAM | index, s % REPLICATES),
                            .index = s / REPLICATES, .stratified = 1};
    uint64_t key_walk = dwvk_rng_key(bake->options.seed, stream | WALK_STREAM | index, s);
    *mesh_seen = UINT32_MAX;
    dwvb_shader texel_shader;
    uint32_t x = index % bake->width, row = index / bake->width;
    dwvg_hit hit;
    dwvu_vec3 view;
    if (bake->options.target == DWV_BAKE_CAMERA) {
        dwvu_vec3 origin;
        camera_sample(bake, x, row, &sampler, &origin, &view);
        if (!(bake->scene->mesh_count > 0 && dwvg_intersect(&bake->scene->geometry, origin, view, 0.0, INFINITY, &hit))) {
            /* The world seen directly: the Env pass always (as Cycles writes its background
             * pass under a transparent film too), the combined image unless Film > Transparent. */
            *parts = (dwvb_shade_parts){0};
            if (bake->scene->envmap) dwvl_envmap_radiance(bake->scene->envmap, view, parts->environment);
            else for (int c = 0; c < 3; ++c) parts->environment[c] = bake->scene->world[c];
            for (int c = 0; c < 3; ++c) rgb[c] = bake->options.transparent_background ? 0.0 : parts->environment[c];
            *alpha = 0.0;
            return;
        }
    } else {
        /* A point of the texel on its triangle (texel_sample), seen along its normal: the radiance
         * leaving along n, the smooth normal where the mesh has normals (Cycles'
         * integrator_init_from_bake: ray.D = -N, N = triangle_smooth_normal for smooth-shaded
         * triangles; the view-dependent lobes, the specular layer above all, see the texel from
         * there). */
        hit.mesh = bake->options.uv_mesh;
        const dwvg_mesh *mesh = &bake->scene->meshes[hit.mesh];
        texel_sample(bake, mesh, index, s, &sampler, key_walk, &hit, &texel_shader, shader);
        shader = &texel_shader;
        dwvu_vec3 ng = dwvg_geometric_normal(mesh, hit.prim);
        view = dwvu_scale(dwvg_shading_normal(mesh, hit.prim, hit.u, hit.v, ng), -1.0);
    }
    *mesh_seen = hit.mesh;
    dwvb_shade(shader, &hit, view, &sampler, PIXEL_PAIR + 1u, key_walk, parts, tally);
    dwvb_shade_parts_combined(parts, rgb);
    *alpha = 1.0;
    if (!(isfinite(rgb[0]) && isfinite(rgb[1]) && isfinite(rgb[2]))) {
        ++tally->warnings;
        *parts = (dwvb_shade_parts){0};
        rgb[0] = rgb[1] = rgb[2] = 0.0;
    }
    if (bake->options.target == DWV_BAKE_UV && (bake->options.passes & DWV_PASS_BIT(DWV_PASS_ENVIRONMENT))) {
        /* Cycles' Environment bake: the world along the texel's position seen from the origin
         * (integrator_init_from_bake: ray.D = normalize(P)), not part of the combined image. */
        const dwvg_mesh *mesh = &bake->scene->meshes[hit.mesh];
        dwvu_vec3 p = dwvg_point(mesh, hit.prim, hit.u, hit.v);
        double length = dwvu_length(p);
        if (length > 0.0) {
            dwvu_vec3 d = dwvu_scale(p, 1.0 / length);
            if (bake->scene->envmap) dwvl_envmap_radiance(bake->scene->envmap, d, parts->environment);
            else for (int c = 0; c < 3; ++c) parts->environment[c] = bake->scene->world[c];
        }
    }
}

static void sample_pixel(dwvb_bake *bake, uint32_t index, uint64_t s, dwvb_shade_parts *parts, double rgb[3],
                         double *alpha, dwvb_tally *tally)
{
    uint32_t mesh_seen;
    dwvb_bake_sample(bake, &bake->shader, 0u, index, s, parts, rgb, alpha, &mesh_seen, tally);
}

static void *worker(void *arg)
{
    dwvb_bake *bake = arg;
    uint32_t tile_size = bake->options.tile_size;
    int stop = 0;
    while (!stop && !dwvb_bake_must_stop(bake)) {
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
                if (!dwvb_bake_pixel_active(bake, index)) continue;
                dwvb_pixel_sums *p = &bake->sums[index];
                for (uint64_t s = bake->pass_first; s < bake->pass_end; ++s) {
                    /* Checked per sample, which ends within max_events: cancel is quick and a
                     * time limit cuts where the clock says (pixels keep the samples they got). */
                    if ((stop = dwvb_bake_must_stop(bake))) break;
                    double rgb[3], alpha;
                    dwvb_shade_parts parts;
                    sample_pixel(bake, index, s, &parts, rgb, &alpha, tally);
                    for (uint32_t k = 0; k < bake->pass_count; ++k) {
                        dwvb_pass_sums *q = &bake->pass_sums[(size_t)index * bake->pass_count + k];
                        const double *v = dwvb_pass_value(&parts, bake->pass_list[k]);
                        for (int c = 0; c < 3; ++c) {
                            q->sum[c] += dwvb_to_fixed(v[c]);
                            q->sum_squares[c] += dwvb_to_fixed(v[c] * v[c]);
                        }
                    }
                    for (int c = 0; c < 3; ++c) {
                        p->sum[c] += dwvb_to_fixed(rgb[c]);
                        p->sum_squares[c] += dwvb_to_fixed(rgb[c] * rgb[c]);
                    }
                    double l = dwvb_luminance(rgb);
                    p->sum_luminance_squares += dwvb_to_fixed(l * l);
                    p->replicate_luminance[s % REPLICATES] += dwvb_to_fixed(l);
                    p->sum_alpha += dwvb_to_fixed(alpha);
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

static double fraction_done(dwvb_bake *bake)
{
    double pass_share = bake->tile_count ? (double)atomic_load(&bake->tiles_done) / bake->tile_count : 0.0;
    double spp = (double)bake->spp_done + pass_share * (double)(bake->pass_end - bake->pass_first);
    uint64_t total = bake->options.sample_count ? bake->options.sample_count : bake->options.samples;
    double f = spp / (double)total;
    if (bake->options.time_limit > 0.0) f = fmax(f, dwvb_bake_elapsed(bake) / bake->options.time_limit);
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
    p.seconds = dwvb_bake_elapsed(bake);
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

static dwv_result_t run(dwvb_bake *bake)
{
    /* A chunk (sample_count > 0) bakes sample_first .. + sample_count - 1; the pilot above used the
     * whole bake's samples, so it chooses the same in every chunk. */
    uint64_t first = bake->options.sample_first;
    uint64_t samples = bake->options.sample_count ? bake->options.sample_count : bake->options.samples;
    int pilot = dwvb_pilot_choose(bake);
    if (pilot < 0) return fail(bake, DWV_ERROR_OUT_OF_MEMORY, "no memory for auto's pilot");
    if (atomic_load(&bake->cancelled)) return fail(bake, DWV_ERROR_CANCELLED, "the bake was cancelled");
    while (bake->spp_done < samples) {
        uint64_t pass = bake->spp_done == 0 ? 2u : bake->spp_done;
        if (pass > samples - bake->spp_done) pass = samples - bake->spp_done;
        bake->pass_first = first + bake->spp_done;
        bake->pass_end = first + bake->spp_done + pass;
        if (run_pass(bake)) return fail(bake, DWV_ERROR_INTERNAL, "could not start a worker thread");
        if (atomic_load(&bake->cancelled)) return fail(bake, DWV_ERROR_CANCELLED, "the bake was cancelled");
        int cut = atomic_load(&bake->time_up);
        if (!cut) bake->spp_done = bake->pass_end - first;
        bake->error = dwvb_bake_estimate_error(bake);
        dwv_error_point_t point = {dwvb_bake_elapsed(bake), bake->error, bake->spp_done};
        if (!cut && dwvb_image_add_error_point(bake->image, point))
            return fail(bake, DWV_ERROR_OUT_OF_MEMORY, "no memory for the error series");
        if (cut) break;
        if (bake->options.target_error > 0.0 && bake->error <= bake->options.target_error) break;
    }
    dwv_result_t r = dwvb_bake_make_image(bake, dwvb_bake_elapsed(bake));
    return r == DWV_SUCCESS ? r : fail(bake, r, "no memory for the UV margin");
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
    free(bake->pass_sums);
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
    dwvb_pixel_filter_init(&bake->pixel_filter, bake->options.pixel_filter, bake->options.filter_width);
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
    for (uint32_t pass = 1u; pass < DWV_PASS_COUNT; ++pass)
        if (options->passes & DWV_PASS_BIT(pass)) bake->pass_list[bake->pass_count++] = pass;
    int passes_ready = 1;
    if (bake->pass_count > 0u) {
        bake->pass_sums = calloc(pixels * bake->pass_count, sizeof *bake->pass_sums);
        passes_ready = bake->pass_sums && bake->image && dwvb_image_add_passes(bake->image, options->passes) == 0;
    }
    if (!passes_ready || !bake->guides || !bake->channel_guides || !bake->channel_walks || !bake->channel_counts || !bake->needs_closest || !bake->auto_choice || !bake->sums || !bake->counts ||
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
    dwvb_bake_setup_guides(bake);
    bake->shader.scene = scene;
    bake->shader.env.lights = scene->emitters;
    bake->shader.env.light_count = scene->light_count;
    for (int c = 0; c < 3; ++c) bake->shader.env.world[c] = scene->world[c];
    bake->shader.env.world_lit = dwvb_scene_world_lit(scene);
    bake->shader.env.geometry = scene->mesh_count ? &scene->geometry : NULL;
    bake->shader.env.envmap = scene->envmap;
    bake->shader.guides = bake->guides;
    bake->shader.channel_guides = bake->channel_guides;
    bake->shader.channel_walks = bake->channel_walks;
    bake->shader.channel_counts = bake->channel_counts;
    bake->shader.needs_closest = bake->needs_closest;
    bake->shader.max_events = options->max_events;
    bake->shader.paths = (dwvb_light_paths){options->max_bounces,         options->diffuse_bounces,
                                            options->glossy_bounces,      options->transmission_bounces,
                                            options->min_light_bounces,   (int)options->subsurface_after_diffuse,
                                            options->blur_glossy};
    if (options->target == DWV_BAKE_CAMERA) {
        /* The pixel's footprint for Cycles 4.0-4.3's quarter-pixel rule (shade.h). */
        double px = 2.0 / bake->width, py = 2.0 / bake->height;
        bake->shader.footprint = scene->camera.kind == DWV_CAMERA_PERSPECTIVE ? DWVB_FOOTPRINT_PERSPECTIVE
                                                                              : DWVB_FOOTPRINT_CONSTANT;
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

const dwv_bake_options_t *dwvb_bake_options(const dwvb_bake *bake)
{
    return &bake->options;
}

long long dwvb_scene_geometry_bytes(const dwvb_scene *scene)
{
    return scene->mesh_count ? (long long)atomic_load(&((dwvb_scene *)scene)->geometry.embree_bytes) : 0;
}
