/* The image's error estimate and the image itself, from a bake's per-pixel sums (pixel_sums.h). */
#include "bake/pixel_sums.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Whether pixel `index` counts in the image's error and mean: UV texels of the islands; camera
 * pixels that saw a surface (all pixels when none did). */
static int covered(const dwvb_sums_view *view, uint32_t index, int any_surface)
{
    if (view->texels) return view->texels[index].triangle >= 0;
    return !any_surface || view->sums[index].sum_alpha > 0;
}

static int any_surface_seen(const dwvb_sums_view *view)
{
    if (view->texels) return 1;
    size_t pixels = (size_t)view->width * view->height;
    for (size_t i = 0; i < pixels; ++i)
        if (view->sums[i].sum_alpha > 0) return 1;
    return 0;
}

static dwvb_sums_view bake_view(const dwvb_bake *bake)
{
    dwvb_sums_view view = {bake->width, bake->height,
                           bake->options.target == DWV_BAKE_UV ? bake->raster.texels : NULL, bake->sums,
                           bake->counts};
    return view;
}

/* The variance of a pixel's mean from its sums: (sum x^2 - (sum x)^2 / n) / (n (n - 1)); 0 below
 * two samples (unknown, see dwvb_bake_estimate_error). */
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
 * A pixel's variance is measured by its two replicates (dwvb_bake_sample): means m0, m1 of n0, n1
 * samples are independent and unbiased, so E[(m0 - m1)^2] = V0 + V1, and with V_r = c / n_r the
 * variance of the pixel's mean, c / n, is E[(m0 - m1)^2] n0 n1 / n^2. The samples' own variance
 * (x^2 sums) would treat a pixel's samples as independent, while stratified ones are negatively
 * correlated, and overstate the error: 1.1x to 1.4x with shared walks, 2.2x with channel walks,
 * which share a sample's stratified numbers over three walks (docs/speed.md). It is used below
 * REPLICATE_MIN_PIXELS covered pixels, where the replicates' spread is too noisy. */
double dwvb_sums_estimate_error(const dwvb_sums_view *view)
{
    int any = any_surface_seen(view);
    size_t pixels = (size_t)view->width * view->height;
    double spread = 0.0, own = 0.0, total = 0.0, count = 0.0;
    for (size_t i = 0; i < pixels; ++i) {
        if (!covered(view, (uint32_t)i, any)) continue;
        count += 1.0;
        uint32_t n = view->counts[i];
        if (n < 2u) return INFINITY;
        const dwvb_pixel_sums *p = &view->sums[i];
        double rgb[3] = {dwvb_from_fixed(p->sum[0]), dwvb_from_fixed(p->sum[1]), dwvb_from_fixed(p->sum[2])};
        double l = dwvb_luminance(rgb);
        total += l / n;
        own += mean_variance(l, dwvb_from_fixed(p->sum_luminance_squares), n);
        double n0 = (double)((n + 1u) / 2u), n1 = (double)(n / 2u);
        double d = dwvb_from_fixed(p->replicate_luminance[0]) / n0 - dwvb_from_fixed(p->replicate_luminance[1]) / n1;
        spread += d * d * n0 * n1 / ((double)n * (double)n);
    }
    double variance = count >= REPLICATE_MIN_PIXELS ? spread : own;
    if (variance == 0.0) return 0.0;
    return total > 0.0 ? sqrt(count * variance) / total : INFINITY;
}

double dwvb_bake_estimate_error(const dwvb_bake *bake)
{
    dwvb_sums_view view = bake_view(bake);
    return dwvb_sums_estimate_error(&view);
}

void dwvb_sums_fill_image(const dwvb_sums_view *view, dwvb_image *image)
{
    size_t pixels = (size_t)view->width * view->height;
    int any = any_surface_seen(view);
    dwv_bake_stats_t *st = &image->stats;
    double mean[3] = {0.0, 0.0, 0.0};
    uint64_t covered_count = 0, samples = 0, largest = 0;
    for (size_t i = 0; i < pixels; ++i) {
        uint32_t n = view->counts[i];
        const dwvb_pixel_sums *p = &view->sums[i];
        samples += n;
        if (n > largest) largest = n;
        if (n == 0u) continue;
        for (int c = 0; c < 3; ++c) {
            double sum = dwvb_from_fixed(p->sum[c]);
            image->rgba[4 * i + c] = (float)(sum / n);
            image->variance[3 * i + c] = (float)mean_variance(sum, dwvb_from_fixed(p->sum_squares[c]), n);
        }
        image->rgba[4 * i + 3] = (float)(dwvb_from_fixed(p->sum_alpha) / n);
        image->samples[i] = n;
        if (covered(view, (uint32_t)i, any)) {
            ++covered_count;
            for (int c = 0; c < 3; ++c) mean[c] += dwvb_from_fixed(p->sum[c]) / n;
        }
    }
    st->samples_per_pixel = largest;
    st->samples = samples;
    for (int c = 0; c < 3; ++c) st->mean_rgb[c] = covered_count ? mean[c] / (double)covered_count : 0.0;
}

dwv_result_t dwvb_bake_make_image(dwvb_bake *bake, double seconds)
{
    dwvb_image *image = bake->image;
    size_t pixels = (size_t)bake->width * bake->height;
    dwv_bake_stats_t *st = &image->stats;
    dwvb_sums_view view = bake_view(bake);
    dwvb_sums_fill_image(&view, image);
    /* The passes: each pixel's mean and the variance of that mean, per channel (the combined
     * image's estimator, mean_variance). */
    for (uint32_t k = 0; k < bake->pass_count; ++k) {
        float *mean = image->pass_mean + (size_t)k * 3u * pixels, *variance = image->pass_variance + (size_t)k * 3u * pixels;
        for (size_t i = 0; i < pixels; ++i) {
            uint32_t n = bake->counts[i];
            if (n == 0u) continue;
            const dwvb_pass_sums *q = &bake->pass_sums[i * bake->pass_count + k];
            for (int c = 0; c < 3; ++c) {
                double sum = dwvb_from_fixed(q->sum[c]);
                mean[3 * i + c] = (float)(sum / n);
                variance[3 * i + c] = (float)mean_variance(sum, dwvb_from_fixed(q->sum_squares[c]), n);
            }
        }
    }
    uint64_t samples = st->samples;
    if (bake->options.sample_count > 0u) {
        /* A chunk: its image keeps the exact sums for dwv_image_write_partial. */
        image->partial = malloc(sizeof *image->partial);
        if (!image->partial) return DWV_ERROR_OUT_OF_MEMORY;
        dwvb_partial *part = image->partial;
        *part = (dwvb_partial){0};
        part->sums = malloc(pixels * sizeof(dwvb_pixel_sums));
        part->counts = malloc(pixels * sizeof *part->counts);
        if (!part->sums || !part->counts) return DWV_ERROR_OUT_OF_MEMORY;
        memcpy(part->sums, bake->sums, pixels * sizeof(dwvb_pixel_sums));
        memcpy(part->counts, bake->counts, pixels * sizeof *part->counts);
        part->uv = bake->options.target == DWV_BAKE_UV;
        part->first = bake->options.sample_first;
        part->count = bake->options.sample_count;
        part->total = bake->options.samples;
        part->seed = bake->options.seed;
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
        total.path_rays += bake->tile_tallies[t].path_rays;
        for (int c = 0; c < 3; ++c) total.truncated[c] += bake->tile_tallies[t].truncated[c];
    }
    st->technique = bake->options.technique;
    st->events = total.events;
    image->rays = total.rays;
    image->point_queries = total.point_queries;
    image->ray_free_steps = total.ray_free_steps;
    image->ray_free_misses = total.ray_free_misses;
    image->mixture_terms = total.mixture_terms;
    st->walks = total.walks;
    st->path_rays = total.path_rays;
    st->seconds = seconds;
    st->estimated_relative_error = bake->error;
    for (int c = 0; c < 3; ++c) st->truncated_weight[c] = samples ? total.truncated[c] / (double)samples : 0.0;
    st->features = bake->features;
    st->threads = bake->threads;
    st->warnings = bake->scene->warnings + total.warnings;
    if (bake->options.target == DWV_BAKE_UV) {
        dwv_result_t r = dwvb_uv_dilate_image(&bake->raster, bake->options.uv_margin, image);
        if (r != DWV_SUCCESS) return r;
    }
    return DWV_SUCCESS;
}
