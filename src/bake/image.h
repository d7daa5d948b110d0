/* A baked (or caller-made) image with what its bake measured: the object behind dwv_image_t.
 * Written once by whoever makes it, read-only afterwards, shared by reference count. */
#ifndef DWV_BAKE_IMAGE_H
#define DWV_BAKE_IMAGE_H

#include <stdatomic.h>
#include <stdint.h>

#include <dwivedi.h>

struct dwvb_pixel_sums;

/* What a chunk of a split bake keeps beyond its image, for dwv_image_write_partial. */
typedef struct dwvb_partial {
    struct dwvb_pixel_sums *sums; /* width x height (bake_internal.h) */
    uint32_t *counts;             /* width x height */
    int uv;
    uint64_t first, count, total, seed;
    uint64_t scene_hash, options_hash; /* set by the API (dwv_bake_finish) */
} dwvb_partial;

typedef struct dwvb_image {
    atomic_uint references;
    uint32_t width, height;
    float *rgba;           /* 4 x width x height, row 0 at the top */
    float *variance;       /* 3 x width x height: variance of the pixel mean, per channel */
    uint32_t *samples;     /* width x height */
    dwv_bake_stats_t stats;            /* error_vs_time_count = the length of error_vs_time */
    dwv_error_point_t *error_vs_time;  /* one point per completed pass; may be NULL if count is 0 */
    uint32_t error_vs_time_capacity;
    /* The walks' work beyond the public stats (dwvb_tally): rays, closest-point queries, ray-free
     * steps, in checked ball mode the ray-free steps whose ray met the surface, and mixture terms
     * (what the auto pilot's cost model counts). */
    uint64_t rays, point_queries, ray_free_steps, ray_free_misses, mixture_terms;
    dwvb_partial *partial; /* chunks of split bakes only; else NULL */
    /* Bake passes (dwv_pass_t) beyond the combined RGBA: DWV_PASS_BIT of each held (COMBINED's
     * always set), and per pass held, in ascending order, 3 x width x height floats of its mean
     * (direct and indirect as the light itself, not yet divided by the colour) and of the
     * variance of that mean. NULL when it holds none. */
    uint32_t passes;
    uint32_t pass_count;
    float *pass_mean, *pass_variance;
} dwvb_image;

/* A zeroed image of the given size with reference count 1 (stats zeroed but struct_size set),
 * or NULL when out of memory; the caller checked the size. */
dwvb_image *dwvb_image_new(uint32_t width, uint32_t height);
/* Appends a point to the error-against-time series; 0 on success, -1 out of memory. */
int dwvb_image_add_error_point(dwvb_image *image, dwv_error_point_t point);
/* Makes room (zeroed) for the passes of mask `passes` (DWV_PASS_BIT, COMBINED's ignored); 0, or
 * -1 out of memory. */
int dwvb_image_add_passes(dwvb_image *image, uint32_t passes);
/* Where pass `pass`'s plane (3 floats per pixel) starts in pass_mean / pass_variance: its rank
 * among the passes held; -1 when it is not held (or is COMBINED). */
int dwvb_image_pass_rank(const dwvb_image *image, uint32_t pass);
void dwvb_image_free(dwvb_image *image);

#endif
