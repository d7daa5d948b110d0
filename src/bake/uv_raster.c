/* UV rasterisation and margin for UV bakes (see uv_raster.h for the conventions).
 *
 * Exactness. A texel is in a triangle when the three edge functions
 *     E_ab(p) = (b_x - a_x)(p_y - a_y) - (b_y - a_y)(p_x - a_x)      (twice a signed area)
 * of its centre p are positive, or zero on a top-left edge. Two triangles sharing the edge a-b
 * cover each centre on it exactly once only if they see E_ab(p) = -E_ba(p) exactly, zero included,
 * which rounding breaks. So corners are snapped to integers in units of 2^-8 texel (an error of at
 * most 1/512 texel, below what a bake can show) and texel centres, at (256 x + 128, 256 j + 128),
 * are integers too. With |corner| <= 2^25 units (DWVB_UV_MAX_COORDINATE texels) and centres in
 * [0, 2^22] units (16384 texels), each product is below 2^26 * 1.125 * 2^25 and E below
 * 1.125 * 2^52 < 2^53: every edge function, and every step of its incremental evaluation along a
 * row (E += -(b_y - a_y) 256), is an integer exactly held by a double.
 *
 * Fill rule (Direct3D's top-left rule, in UV space where y points up): with the triangle turned
 * counter-clockwise, a centre on an edge belongs to it when the edge is a left edge (going down,
 * d_y < 0) or a top edge (horizontal, going left: d_y = 0, d_x < 0). Of the two directions of a
 * shared edge exactly one is top-left, so exactly one of the two triangles takes the centre; at a
 * vertex shared by a fan the same holds because every centre is decided edge by edge.
 *
 * Barycentrics are computed from the unsnapped UVs (so they reproduce the centre's UV to float
 * precision); a centre that snapping let in from just outside (within 1/512 texel) is moved to the
 * nearest point of the triangle, so the surface point always lies on the triangle.
 *
 * Margin ("Extend"). Cycles' bake margin of type Extend (Blender's IMB_filter_extend) grows the
 * islands one texel per pass by averaging already-filled 8-neighbours. We grow the same region,
 * pass by pass over 8-neighbours so pass d fills the texels at Chebyshev distance d, but a texel
 * copies ONE covered texel instead of a blend: of its neighbours filled by the previous pass, the
 * one whose source lies nearest (Euclidean; ties to the first in a fixed neighbour order), which
 * approximates the nearest covered texel. Copying keeps a margin texel an honest estimate: its
 * value, variance and sample count are those of one real texel (a blend's variance would be
 * neither the average of the variances nor known without the weights), it works for any layer
 * type (uint32 sample counts too), and it does not depend on the order texels are visited in. */
#include "bake/uv_raster.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util/error.h"

#define UNIT 256.0 /* 2^DWVB_UV_SUBPIXEL_BITS: snapped units per texel */
#define HALF 128.0 /* a texel centre's offset in units */

/* A centre on an edge with direction (dx, dy) of a counter-clockwise triangle belongs to it. */
static int top_left(double dx, double dy)
{
    return dy < 0.0 || (dy == 0.0 && dx < 0.0);
}

static double min3(const double v[3])
{
    return fmin(v[0], fmin(v[1], v[2]));
}

static double max3(const double v[3])
{
    return fmax(v[0], fmax(v[1], v[2]));
}

/* The first texel index whose centre (index * UNIT + HALF) is >= lo and the last <= hi, clipped to
 * [0, n - 1]; first > last when none. lo, hi are integers in units, so this is exact. */
static void centre_range(double lo, double hi, uint32_t n, int64_t *first, int64_t *last)
{
    double a = ceil((lo - HALF) / UNIT), b = floor((hi - HALF) / UNIT);
    *first = a < 0.0 ? 0 : (int64_t)a;
    *last = b > (double)n - 1.0 ? (int64_t)n - 1 : (int64_t)b;
}

/* The parameter in [0, 1] of the point of segment t * (dx, dy) nearest to (qx, qy), and the squared
 * distance to it. */
static double segment_nearest(double qx, double qy, double dx, double dy, double *d2)
{
    double t = (qx * dx + qy * dy) / (dx * dx + dy * dy);
    t = t > 0.0 ? (t < 1.0 ? t : 1.0) : 0.0; /* NaN (a zero-length edge) goes to 0 */
    double rx = qx - t * dx, ry = qy - t * dy;
    *d2 = rx * rx + ry * ry;
    return t;
}

/* The barycentrics of the point of triangle (0, e1, e2) nearest to q, for a centre just outside
 * it: the nearest of the three edges' nearest points. Snapping lets in only centres within 1/512
 * texel, so this moves a centre that little whatever the triangle's shape (a rescaling of b1, b2
 * would slide it along a sliver instead). */
static void closest_on_triangle(double qx, double qy, double e1x, double e1y, double e2x, double e2y,
                                double *b1, double *b2)
{
    double d01, d02, d12;
    double t01 = segment_nearest(qx, qy, e1x, e1y, &d01);
    double t02 = segment_nearest(qx, qy, e2x, e2y, &d02);
    double t12 = segment_nearest(qx - e1x, qy - e1y, e2x - e1x, e2y - e1y, &d12);
    if (d01 <= d02 && d01 <= d12) {
        *b1 = t01;
        *b2 = 0.0;
    } else if (d02 <= d12) {
        *b1 = 0.0;
        *b2 = t02;
    } else {
        *b1 = 1.0 - t12;
        *b2 = t12;
    }
}

/* One triangle's footprint written into the raster: px, py are its corners in texels (y up). */
static void raster_triangle(dwvb_uv_raster *raster, int32_t triangle, const double px[3], const double py[3])
{
    const uint32_t width = raster->width, height = raster->height;
    double X[3], Y[3];
    for (int k = 0; k < 3; ++k) {
        X[k] = nearbyint(px[k] * UNIT); /* exact product: a power of two times a double */
        Y[k] = nearbyint(py[k] * UNIT);
    }
    double area = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]); /* exact */
    if (area == 0.0) {
        ++raster->skipped_degenerate;
        return;
    }
    if (area < 0.0) { /* mirrored island: turn it counter-clockwise, corners keep their names */
        double t = X[1]; X[1] = X[2]; X[2] = t;
        t = Y[1]; Y[1] = Y[2]; Y[2] = t;
    }
    int64_t x0, x1, j0, j1;
    centre_range(min3(X), max3(X), width, &x0, &x1);
    centre_range(min3(Y), max3(Y), height, &j0, &j1);
    if (x0 > x1 || j0 > j1) return;

    /* Edge k runs from corner k+1 to corner k+2 (opposite corner k). */
    double ax[3], ay[3], dx[3], dy[3], step[3];
    int tl[3];
    for (int k = 0; k < 3; ++k) {
        int a = (k + 1) % 3, b = (k + 2) % 3;
        ax[k] = X[a];
        ay[k] = Y[a];
        dx[k] = X[b] - X[a];
        dy[k] = Y[b] - Y[a];
        step[k] = -dy[k] * UNIT; /* E at the next centre to the right */
        tl[k] = top_left(dx[k], dy[k]);
    }

    /* Barycentrics from the true corners: centre - P0 = b1 (P1 - P0) + b2 (P2 - P0), Cramer. */
    double e1x = px[1] - px[0], e1y = py[1] - py[0], e2x = px[2] - px[0], e2y = py[2] - py[0];
    double inverse = 1.0 / (e1x * e2y - e2x * e1y); /* nonzero: checked by the caller */

    for (int64_t j = j0; j <= j1; ++j) {
        double cy = (double)j * UNIT + HALF, cx = (double)x0 * UNIT + HALF;
        double e[3];
        for (int k = 0; k < 3; ++k) e[k] = dx[k] * (cy - ay[k]) - dy[k] * (cx - ax[k]);
        dwvb_uv_texel *row = raster->texels + (size_t)(height - 1u - (uint32_t)j) * width;
        double qy = (double)j + 0.5 - py[0];
        for (int64_t x = x0; x <= x1; ++x) {
            if ((e[0] > 0.0 || (e[0] == 0.0 && tl[0])) && (e[1] > 0.0 || (e[1] == 0.0 && tl[1])) &&
                (e[2] > 0.0 || (e[2] == 0.0 && tl[2]))) {
                double qx = (double)x + 0.5 - px[0];
                double b1 = (qx * e2y - qy * e2x) * inverse, b2 = (e1x * qy - e1y * qx) * inverse;
                if (!(b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0)) /* also NaN, which must not leak */
                    closest_on_triangle(qx, qy, e1x, e1y, e2x, e2y, &b1, &b2);
                dwvb_uv_texel *texel = row + x;
                if (texel->triangle >= 0)
                    ++raster->overwritten;
                else
                    ++raster->covered;
                texel->triangle = triangle;
                texel->b1 = (float)b1;
                texel->b2 = (float)b2;
            }
            for (int k = 0; k < 3; ++k) e[k] += step[k];
        }
    }
}

dwv_result_t dwvb_uv_rasterize(const float *uvs, uint32_t triangle_count, uint32_t width,
                               uint32_t height, dwvb_uv_raster *raster)
{
    static const char fn[] = "dwvb_uv_rasterize";
    DWV_TRY(dwv_check_pointer(fn, "raster", raster));
    memset(raster, 0, sizeof *raster);
    if (width < 1u || width > DWVB_UV_MAX_SIDE || height < 1u || height > DWVB_UV_MAX_SIDE)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: image size %ux%u, each side must be 1 to %u", fn,
                        width, height, DWVB_UV_MAX_SIDE);
    if ((uint64_t)width * height > DWVB_UV_MAX_TEXELS)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: image size %ux%u is more than %u texels", fn, width,
                        height, DWVB_UV_MAX_TEXELS);
    if (triangle_count > (uint32_t)INT32_MAX)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: %u triangles, at most %d", fn, triangle_count,
                        INT32_MAX);
    if (triangle_count > 0u) DWV_TRY(dwv_check_pointer(fn, "uvs", uvs));

    size_t count = (size_t)width * height;
    dwvb_uv_texel *texels = malloc(count * sizeof *texels); /* <= 2^26 * 12 bytes: no overflow */
    if (!texels)
        return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: no memory for a %ux%u raster", fn, width, height);
    for (size_t i = 0; i < count; ++i) texels[i] = (dwvb_uv_texel){-1, 0.0f, 0.0f};
    raster->width = width;
    raster->height = height;
    raster->texels = texels;

    for (uint32_t t = 0; t < triangle_count; ++t) {
        const float *uv = uvs + 6u * (size_t)t;
        double px[3], py[3];
        int finite = 1;
        for (int k = 0; k < 3; ++k) {
            finite &= isfinite(uv[2 * k]) && isfinite(uv[2 * k + 1]);
            px[k] = (double)uv[2 * k] * width; /* exact: 24-bit mantissa times 15 bits */
            py[k] = (double)uv[2 * k + 1] * height;
        }
        if (!finite) {
            ++raster->skipped_nonfinite;
            continue;
        }
        if ((px[1] - px[0]) * (py[2] - py[0]) - (px[2] - px[0]) * (py[1] - py[0]) == 0.0) {
            ++raster->skipped_degenerate;
            continue;
        }
        /* Entirely beside the image (with a texel to spare for snapping): nothing to draw. */
        if (max3(px) < 0.0 || min3(px) > (double)width || max3(py) < 0.0 || min3(py) > (double)height)
            continue;
        if (fmax(fabs(min3(px)), fabs(max3(px))) > DWVB_UV_MAX_COORDINATE ||
            fmax(fabs(min3(py)), fabs(max3(py))) > DWVB_UV_MAX_COORDINATE) {
            ++raster->skipped_far;
            continue;
        }
        raster_triangle(raster, (int32_t)t, px, py);
    }
    return DWV_SUCCESS;
}

void dwvb_uv_raster_free(dwvb_uv_raster *raster)
{
    if (!raster) return;
    free(raster->texels);
    memset(raster, 0, sizeof *raster);
}

/* ---- a texel's frame on its triangle (uv_raster.h) ---------------------------------------- */

void dwvb_uv_texel_steps(const float *uv, uint32_t width, uint32_t height, dwvb_uv_steps *step)
{
    /* Corners in texels; centre - P0 = b1 (P1 - P0) + b2 (P2 - P0) inverted by Cramer's rule:
     * d b1 / dx = e2y / A, d b1 / dy = -e2x / A, d b2 / dx = -e1y / A, d b2 / dy = e1x / A. */
    double e1x = ((double)uv[2] - uv[0]) * width, e1y = ((double)uv[3] - uv[1]) * height;
    double e2x = ((double)uv[4] - uv[0]) * width, e2y = ((double)uv[5] - uv[1]) * height;
    double area2 = e1x * e2y - e2x * e1y;
    if (!(fabs(area2) > (double)FLT_EPSILON)) { /* also NaN */
        *step = (dwvb_uv_steps){{{0.0, 0.0}, {0.0, 0.0}}};
        return;
    }
    double half = 0.5 / area2;
    step->d[0][0] = e2y * half;
    step->d[0][1] = -e2x * half;
    step->d[1][0] = -e1y * half;
    step->d[1][1] = e1x * half;
}

double dwvb_uv_texel_footprint(const double e1[3], const double e2[3], const dwvb_uv_steps *step)
{
    double sum = 0.0;
    for (int a = 0; a < 2; ++a) {
        double d2 = 0.0;
        for (int i = 0; i < 3; ++i) {
            double d = e1[i] * step->d[0][a] + e2[i] * step->d[1][a];
            d2 += d * d;
        }
        sum += sqrt(d2);
    }
    return 0.5 * sum;
}

int dwvb_uv_jitter(const dwvb_uv_steps *step, double b1, double b2, double r0, double r1, double *j1, double *j2)
{
    double u = b1 + (r0 - 0.5) * step->d[0][0] + (r1 - 0.5) * step->d[0][1];
    double v = b2 + (r0 - 0.5) * step->d[1][0] + (r1 - 0.5) * step->d[1][1];
    if (!(u > 0.0 && v > 0.0 && u + v < 1.0)) return 0;
    *j1 = u;
    *j2 = v;
    return 1;
}

double dwvb_uv_mirror_repeat(double x, double m)
{
    if (!(m > 0.0)) return 0.0; /* [0, 0] holds one point (m = 1 - u' = 0: the point is corner 0) */
    double t = x / m, period = floor(t), f = t - period;
    return (fmod(period, 2.0) != 0.0 ? 1.0 - f : f) * m; /* odd periods run backwards */
}

void dwvb_uv_fold(const dwvb_uv_steps *step, double b1, double b2, double r0, double r1, double *j1, double *j2)
{
    /* Blender's u = b0 changes by -(d b1 + d b2), its v = b1 by d b1 (the weights sum to 1). */
    double du_dx = -(step->d[0][0] + step->d[1][0]), du_dy = -(step->d[0][1] + step->d[1][1]);
    double u = dwvb_uv_mirror_repeat(1.0 - b1 - b2 + (r0 - 0.5) * du_dx + (r1 - 0.5) * du_dy, 1.0);
    double v = dwvb_uv_mirror_repeat(b1 + (r0 - 0.5) * step->d[0][0] + (r1 - 0.5) * step->d[0][1], 1.0 - u);
    *j1 = v;
    *j2 = 1.0 - u - v; /* (1 - u') - v' >= 0 exactly: v' = f (1 - u') with f <= 1 */
}

/* ---- margin ---------------------------------------------------------------------------------- */

#define PENDING (UINT32_MAX - 1u) /* found by the current pass, source not yet chosen */

/* Neighbour offsets, orthogonal first: the order that breaks ties between equally near sources. */
static const int neighbour_dx[8] = {-1, 1, 0, 0, -1, 1, -1, 1};
static const int neighbour_dy[8] = {0, 0, -1, 1, -1, -1, 1, 1};

/* The indices of texel i's neighbours inside the image, in the order above; returns how many.
 * `offset` holds the index differences of the eight (dx + dy width, modulo 2^32). */
static inline int neighbours(uint32_t width, uint32_t height, const uint32_t offset[8], uint32_t i, uint32_t out[8])
{
    uint32_t x = i % width, y = i / width;
    int n = 0;
    if (x - 1u < width - 2u && y - 1u < height - 2u) { /* 0 < x < width - 1, 0 < y < height - 1 */
        for (int k = 0; k < 8; ++k) out[k] = i + offset[k];
        return 8;
    }
    for (int k = 0; k < 8; ++k) {
        int64_t nx = (int64_t)x + neighbour_dx[k], ny = (int64_t)y + neighbour_dy[k];
        if (nx >= 0 && ny >= 0 && nx < width && ny < height) out[n++] = (uint32_t)(ny * width + nx);
    }
    return n;
}

typedef struct index_list {
    uint32_t *items;
    size_t count, capacity;
} index_list;

/* Appends; the list never needs more than `limit` (the texel count) entries. 0, or -1 no memory. */
static int list_push(index_list *list, uint32_t item, size_t limit)
{
    if (list->count == list->capacity) {
        size_t capacity = list->capacity ? 2u * list->capacity : 1024u;
        if (capacity > limit) capacity = limit;
        uint32_t *grown = realloc(list->items, capacity * sizeof *grown);
        if (!grown) return -1;
        list->items = grown;
        list->capacity = capacity;
    }
    list->items[list->count++] = item;
    return 0;
}

dwv_result_t dwvb_uv_margin_build(const dwvb_uv_raster *raster, uint32_t margin, dwvb_uv_margin *out)
{
    static const char fn[] = "dwvb_uv_margin_build";
    DWV_TRY(dwv_check_pointer(fn, "out", out));
    memset(out, 0, sizeof *out);
    DWV_TRY(dwv_check_pointer(fn, "raster", raster));
    DWV_TRY(dwv_check_pointer(fn, "raster->texels", raster->texels));
    const uint32_t width = raster->width, height = raster->height;
    const size_t count = (size_t)width * height; /* <= 2^26: checked when the raster was made */
    uint32_t *source = malloc(count * sizeof *source);
    index_list frontier = {NULL, 0, 0}, next = {NULL, 0, 0}, chosen = {NULL, 0, 0};
    uint32_t near[8], offset[8];
    for (int k = 0; k < 8; ++k) offset[k] = (uint32_t)neighbour_dx[k] + (uint32_t)neighbour_dy[k] * width;
    if (!source) goto out_of_memory;
    for (size_t i = 0; i < count; ++i) source[i] = raster->texels[i].triangle >= 0 ? (uint32_t)i : DWVB_UV_NO_SOURCE;

    const uint32_t side = width > height ? width : height;
    const uint32_t passes = margin < side ? margin : side; /* no Chebyshev distance reaches side */
    /* The frontier before pass 1: covered texels with an uncovered neighbour. */
    for (uint32_t i = 0; passes > 0u && i < count; ++i) {
        if (source[i] == DWVB_UV_NO_SOURCE) continue;
        int n = neighbours(width, height, offset, i, near), edge = 0;
        for (int k = 0; k < n; ++k) edge |= source[near[k]] == DWVB_UV_NO_SOURCE;
        if (edge && list_push(&frontier, i, count)) goto out_of_memory;
    }
    for (uint32_t pass = 1; pass <= passes && frontier.count > 0; ++pass) {
        /* The texels this pass fills: the unfilled neighbours of the last pass's. */
        next.count = 0;
        for (size_t f = 0; f < frontier.count; ++f) {
            int n = neighbours(width, height, offset, frontier.items[f], near);
            for (int k = 0; k < n; ++k) {
                if (source[near[k]] != DWVB_UV_NO_SOURCE) continue;
                source[near[k]] = PENDING;
                if (list_push(&next, near[k], count)) goto out_of_memory;
            }
        }
        /* Each one's source, from neighbours filled before this pass only (so the visiting order
         * cannot matter): all chosen first, written after. */
        chosen.count = 0;
        for (size_t f = 0; f < next.count; ++f) {
            uint32_t t = next.items[f], best = DWVB_UV_NO_SOURCE;
            int64_t best_d2 = INT64_MAX, tx = t % width, ty = t / width;
            int n = neighbours(width, height, offset, t, near);
            for (int k = 0; k < n; ++k) {
                uint32_t s = source[near[k]];
                if (s >= PENDING) continue;
                int64_t sx = (int64_t)(s % width) - tx, sy = (int64_t)(s / width) - ty;
                int64_t d2 = sx * sx + sy * sy;
                if (d2 < best_d2) {
                    best_d2 = d2;
                    best = s;
                }
            }
            if (list_push(&chosen, best, count)) goto out_of_memory;
        }
        for (size_t f = 0; f < next.count; ++f) source[next.items[f]] = chosen.items[f];
        out->filled += next.count;
        index_list swap = frontier;
        frontier = next;
        next = swap;
    }
    free(frontier.items);
    free(next.items);
    free(chosen.items);
    out->width = width;
    out->height = height;
    out->source = source;
    return DWV_SUCCESS;

out_of_memory:
    free(source);
    free(frontier.items);
    free(next.items);
    free(chosen.items);
    memset(out, 0, sizeof *out);
    return dwv_fail(DWV_ERROR_OUT_OF_MEMORY, "%s: no memory for the margin of a %ux%u raster", fn, width,
                    height);
}

void dwvb_uv_margin_apply(const dwvb_uv_margin *margin, void *layer, size_t texel_bytes)
{
    unsigned char *bytes = layer;
    size_t count = (size_t)margin->width * margin->height;
    for (size_t i = 0; i < count; ++i) {
        uint32_t s = margin->source[i];
        /* Sources are covered texels, never written here: the order of the copies is free. */
        if (s != DWVB_UV_NO_SOURCE && s != i) memcpy(bytes + i * texel_bytes, bytes + (size_t)s * texel_bytes, texel_bytes);
    }
}

void dwvb_uv_margin_free(dwvb_uv_margin *margin)
{
    if (!margin) return;
    free(margin->source);
    memset(margin, 0, sizeof *margin);
}

dwv_result_t dwvb_uv_dilate_image(const dwvb_uv_raster *raster, uint32_t margin, dwvb_image *image)
{
    static const char fn[] = "dwvb_uv_dilate_image";
    DWV_TRY(dwv_check_pointer(fn, "raster", raster));
    DWV_TRY(dwv_check_pointer(fn, "image", image));
    if (image->width != raster->width || image->height != raster->height)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: image %ux%u, raster %ux%u", fn, image->width,
                        image->height, raster->width, raster->height);
    dwvb_uv_margin plan;
    DWV_TRY(dwvb_uv_margin_build(raster, margin, &plan));
    dwvb_uv_margin_apply(&plan, image->rgba, 4u * sizeof *image->rgba);
    dwvb_uv_margin_apply(&plan, image->variance, 3u * sizeof *image->variance);
    dwvb_uv_margin_apply(&plan, image->samples, sizeof *image->samples);
    size_t plane = 3u * (size_t)image->width * image->height;
    for (uint32_t k = 0; k < image->pass_count; ++k) {
        dwvb_uv_margin_apply(&plan, image->pass_mean + k * plane, 3u * sizeof *image->pass_mean);
        dwvb_uv_margin_apply(&plan, image->pass_variance + k * plane, 3u * sizeof *image->pass_variance);
    }
    dwvb_uv_margin_free(&plan);
    return DWV_SUCCESS;
}
