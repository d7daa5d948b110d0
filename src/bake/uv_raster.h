/* UV bakes: which triangle (and where in it) each texel of a mesh's UV layout belongs to, and the
 * margin that extends the islands outward, like Cycles' bake to image with margin type "Extend".
 *
 * Conventions (Blender's): UV (0, 0) is the bottom-left corner of the image and (1, 1) the
 * top-right; image row 0 is the top (as in dwvb_image), so texel (x, row) has its centre at
 * UV ((x + 0.5) / width, 1 - (row + 0.5) / height). A texel belongs to a triangle when its centre
 * lies inside the triangle's UV footprint, with a top-left fill rule: triangles that share an edge
 * (or a fan that shares a vertex) cover every texel centre on it exactly once. */
#ifndef DWV_BAKE_UV_RASTER_H
#define DWV_BAKE_UV_RASTER_H

#include <stddef.h>
#include <stdint.h>

#include "bake/image.h"
#include <dwivedi.h>

/* The sizes a UV bake accepts (those of dwv_bake_options_t): each side 1 to 16384, at most 2^26
 * texels, so that a raster is at most 768 MiB and indices fit in 32 bits. */
#define DWVB_UV_MAX_SIDE 16384u
#define DWVB_UV_MAX_TEXELS (1u << 26)
/* UVs are snapped to 1/2^8 of a texel (as GPU rasterisers do) so that every edge function is an
 * exact integer in double; see uv_raster.c. Vertices farther than 2^17 texels from the image's
 * corner cannot be represented so; a triangle with one that reaches into the image is skipped. */
#define DWVB_UV_SUBPIXEL_BITS 8
#define DWVB_UV_MAX_COORDINATE 131072.0 /* texels, = 2^25 / 2^8 */

typedef struct dwvb_uv_texel {
    int32_t triangle; /* the triangle whose footprint holds the texel centre; -1: none */
    float b1, b2;     /* barycentric weights of the triangle's corners 1 and 2 at the centre
                         (corner 0: 1 - b1 - b2), in the corners' order in `uvs` */
} dwvb_uv_texel;

typedef struct dwvb_uv_raster {
    uint32_t width, height;
    dwvb_uv_texel *texels;          /* width x height, row 0 at the top */
    uint64_t covered;               /* texels with triangle >= 0 */
    uint64_t overwritten;           /* texel writes that replaced an earlier triangle (overlapping
                                       UV islands; 0 for a layout without overlaps) */
    uint32_t skipped_degenerate;    /* triangles of zero UV area (or, for those reaching into the
                                       image, zero once snapped to 1/256 texel) */
    uint32_t skipped_nonfinite;     /* triangles with a NaN or infinite UV */
    uint32_t skipped_far;           /* triangles reaching into the image from beyond
                                       DWVB_UV_MAX_COORDINATE texels */
} dwvb_uv_raster;

/* Rasterises triangle_count triangles whose corner UVs are uvs[6 t + 2 k + {0, 1}] (corner k of
 * triangle t, as dwv_mesh_t.uvs) into a new width x height raster, which *raster receives
 * (release it with dwvb_uv_raster_free; on failure *raster is left empty and owns nothing).
 * Where UV islands overlap, the last triangle in index order wins, as in Blender's bake
 * (bake_pixels_populate stores each rasterised triangle over what was there); `overwritten`
 * counts such texels. Triangles of zero area or with non-finite UVs are skipped and counted.
 * Fails with DWV_ERROR_OUT_OF_RANGE for a size outside the limits above or triangle_count above
 * INT32_MAX (before allocating anything), DWV_ERROR_NULL_POINTER, DWV_ERROR_OUT_OF_MEMORY. */
dwv_result_t dwvb_uv_rasterize(const float *uvs, uint32_t triangle_count, uint32_t width,
                               uint32_t height, dwvb_uv_raster *raster);
void dwvb_uv_raster_free(dwvb_uv_raster *raster);

/* A texel's frame on its triangle, as Blender hands a UV bake's texels to Cycles
 * (RE_bake_pixels_populate, bake_differentials; Cycles' integrator_init_from_bake):
 * d[k][a] = 1/2 d b_k / d x_a, half the change of the barycentric b_k (k = 0: corner 1's, k = 1:
 * corner 2's, as dwvb_uv_texel) per texel along image axis a (0: x, to the right; 1: y, up in UV).
 * Blender's differentials are 0.5 / A times the edge terms, A twice the triangle's area in texels:
 * half a texel's step, which Cycles then takes as the ray's differential. All zero where
 * |A| <= FLT_EPSILON texels^2 (Blender's test). uv: the triangle's six UVs (as dwv_mesh_t.uvs). */
typedef struct dwvb_uv_steps {
    double d[2][2];
} dwvb_uv_steps;
void dwvb_uv_texel_steps(const float *uv, uint32_t width, uint32_t height, dwvb_uv_steps *step);

/* Cycles' footprint of a UV bake's texel on the surface (the ray's compact differential sd->dP:
 * 0.5 (|dP/dx| + |dP/dy|) with dP/dx_a = e1 d[0][a] + e2 d[1][a]), e1, e2 the triangle's
 * edges from corner 0 to corners 1 and 2: a quarter of the sum of the lengths of one texel's
 * steps along x and y on the surface. */
double dwvb_uv_texel_footprint(const double e1[3], const double e2[3], const dwvb_uv_steps *step);

/* The texel's sample at uniforms (r0, r1) in [0, 1)^2: the centre's barycentrics (b1, b2) moved by
 * (r0 - 1/2, r1 - 1/2) differentials, Cycles' box filter of half a texel's width about the centre
 * (DWV_UV_JITTER_RETRY, Cycles 3.5+). Returns 1 and the moved point where it lies strictly
 * inside the triangle, else 0 (Cycles then tries new numbers, and after 10 tries the centre). */
int dwvb_uv_jitter(const dwvb_uv_steps *step, double b1, double b2, double r0, double r1, double *j1, double *j2);
/* Cycles' tries before it keeps the centre. */
#define DWVB_UV_JITTER_TRIES 10u

/* Cycles up to 3.4's sample (DWV_UV_JITTER_MIRROR, capi's dwv_uv_jitter_t): the same moved point,
 * but in Blender's barycentrics (u, v) = (b0, b1) = (1 - b1 - b2, b1), folded back into the
 * triangle coordinate by coordinate: u' = fold(u moved, 1), v' = fold(v moved, 1 - u'), with
 * fold(x, m) = m f(x / m), f the mirrored repeat of [0, 1] (fold(x, 0) = 0). Always a point of
 * the closed triangle: *j1 = v', *j2 = 1 - u' - v'. */
void dwvb_uv_fold(const dwvb_uv_steps *step, double b1, double b2, double r0, double r1, double *j1, double *j2);
/* The mirrored repeat of [0, m] (m >= 0) that dwvb_uv_fold applies to each coordinate. */
double dwvb_uv_mirror_repeat(double x, double m);

/* The margin: for every texel, the covered texel whose values it takes. A covered texel takes its
 * own; an uncovered texel at Chebyshev distance d in 1..margin from the covered ones takes those of
 * a covered texel at that distance (found by d passes over 8-neighbours, see uv_raster.c); the
 * others take none (DWVB_UV_NO_SOURCE) and are left as they are (alpha 0 in a fresh image). */
#define DWVB_UV_NO_SOURCE UINT32_MAX
typedef struct dwvb_uv_margin {
    uint32_t width, height;
    uint32_t *source;   /* width x height texel indices (row * width + x), or DWVB_UV_NO_SOURCE */
    uint64_t filled;    /* uncovered texels given a source */
} dwvb_uv_margin;

/* Builds the margin of `margin` texels around the raster's covered texels into *out (release it
 * with dwvb_uv_margin_free; left empty on failure). Any margin is accepted (one beyond the
 * image's larger side changes nothing more). Fails with DWV_ERROR_NULL_POINTER or
 * DWV_ERROR_OUT_OF_MEMORY. */
dwv_result_t dwvb_uv_margin_build(const dwvb_uv_raster *raster, uint32_t margin, dwvb_uv_margin *out);
/* Copies into every margin texel of `layer` (width x height texels of texel_bytes each, row 0 at
 * the top, any element type: RGBA floats, RGB variances, sample counts) its source texel. Covered
 * texels and texels outside the margin are not written. */
void dwvb_uv_margin_apply(const dwvb_uv_margin *margin, void *layer, size_t texel_bytes);
void dwvb_uv_margin_free(dwvb_uv_margin *margin);

/* dwvb_uv_margin_build + dwvb_uv_margin_apply on the image's rgba, variance and samples, so a
 * margin texel carries one real texel's estimate whole (value, variance and sample count agree).
 * The image must have the raster's size (else DWV_ERROR_INVALID_ARGUMENT). */
dwv_result_t dwvb_uv_dilate_image(const dwvb_uv_raster *raster, uint32_t margin, dwvb_image *image);

#endif
