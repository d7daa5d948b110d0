/* UV rasterisation and margin (src/bake/uv_raster.c), checked against independent computations:
 * exact coverage of tilings (two triangles, fans and strips whose edges pass through texel
 * centres, with mixed windings), each covered centre inside its triangle and each uncovered one
 * outside (to the 1/512-texel snapping), lattice-point counts against area (Nosarzewska's bound),
 * barycentrics that give back the centre's UV, skipped triangles counted, a margin that fills
 * exactly the texels within Chebyshev distance k from a covered texel at that distance, and sizes
 * refused before any allocation (in a child under an address-space limit). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bake/uv_raster.h"
#include "check.h"

static uint64_t rng_state = 0x853c49e6748fea9bull;
static double uniform(void) /* xorshift64*, top 53 bits: reproducible and platform-independent */
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ull) >> 11) * 0x1p-53;
}

static void set_triangle(float *uvs, size_t t, double u0, double v0, double u1, double v1, double u2, double v2)
{
    float *p = uvs + 6 * t;
    p[0] = (float)u0; p[1] = (float)v0; p[2] = (float)u1; p[3] = (float)v1; p[4] = (float)u2; p[5] = (float)v2;
}

/* The UV of texel (x, row)'s centre (row 0 at the top). */
static void centre_uv(const dwvb_uv_raster *r, uint32_t x, uint32_t row, double *u, double *v)
{
    *u = (x + 0.5) / r->width;
    *v = 1.0 - (row + 0.5) / r->height;
}

/* Signed distance, in texels, of point (x, y) from the triangle's boundary (positive inside). */
static double inside_distance(const float *t, uint32_t width, uint32_t height, double x, double y)
{
    double px[3], py[3];
    for (int k = 0; k < 3; ++k) { px[k] = t[2 * k] * (double)width; py[k] = t[2 * k + 1] * (double)height; }
    double area = (px[1] - px[0]) * (py[2] - py[0]) - (px[2] - px[0]) * (py[1] - py[0]);
    double sign = area > 0 ? 1.0 : -1.0, d = INFINITY;
    for (int k = 0; k < 3; ++k) {
        int a = (k + 1) % 3, b = (k + 2) % 3;
        double ex = px[b] - px[a], ey = py[b] - py[a];
        double e = sign * (ex * (y - py[a]) - ey * (x - px[a])) / hypot(ex, ey);
        d = fmin(d, e);
    }
    return d;
}

/* Rasterises and checks the tiling invariants: every texel once, no overwrites, nothing skipped
 * but (if `slivers`) triangles that snapping to 1/256 texel flattens, which cover no centre. */
static void check_tiling(const char *what, const float *uvs, uint32_t n, uint32_t w, uint32_t h, int slivers)
{
    dwvb_uv_raster r;
    dwv_result_t res = dwvb_uv_rasterize(uvs, n, w, h, &r);
    CHECK(res == DWV_SUCCESS, "%s %ux%u: result %d (%s)", what, w, h, res, dwv_last_error_message());
    if (res != DWV_SUCCESS) return;
    uint64_t holes = 0;
    for (size_t i = 0; i < (size_t)w * h; ++i) holes += r.texels[i].triangle < 0;
    CHECK(r.covered == (uint64_t)w * h && holes == 0, "%s %ux%u: %llu of %llu covered, %llu holes", what, w, h,
          (unsigned long long)r.covered, (unsigned long long)w * h, (unsigned long long)holes);
    CHECK(r.overwritten == 0, "%s %ux%u: %llu texels covered twice", what, w, h, (unsigned long long)r.overwritten);
    CHECK((slivers || r.skipped_degenerate == 0) && r.skipped_nonfinite + r.skipped_far == 0,
          "%s %ux%u: triangles skipped (%u degenerate)", what, w, h, r.skipped_degenerate);
    if (slivers) printf("%s %ux%u: %u triangles, %u flattened by snapping\n", what, w, h, n, r.skipped_degenerate);
    dwvb_uv_raster_free(&r);
}

static void test_unit_square(void)
{
    const uint32_t sizes[][2] = {{1, 1}, {7, 5}, {64, 64}, {5, 7}, {2, 1}, {128, 3}};
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; ++s) {
        float uvs[12];
        /* The diagonal runs through texel centres whenever w and h share a factor. */
        set_triangle(uvs, 0, 0, 0, 1, 0, 1, 1);
        set_triangle(uvs, 1, 0, 0, 1, 1, 0, 1);
        check_tiling("square", uvs, 2, sizes[s][0], sizes[s][1], 0);
        set_triangle(uvs, 1, 0, 0, 0, 1, 1, 1); /* the second one clockwise (mirrored) */
        check_tiling("square, mixed winding", uvs, 2, sizes[s][0], sizes[s][1], 0);
        set_triangle(uvs, 0, 1, 0, 0, 1, 0, 0); /* the other diagonal, both clockwise */
        set_triangle(uvs, 1, 1, 0, 1, 1, 0, 1);
        check_tiling("square, other diagonal", uvs, 2, sizes[s][0], sizes[s][1], 0);
    }
    /* Which texel goes where: with the diagonal from (0,0) to (1,1), the lower-right triangle
     * holds the texels whose centre has u > v, and v = 1 at the top row (row 0). */
    float uvs[12];
    set_triangle(uvs, 0, 0, 0, 1, 0, 1, 1);
    set_triangle(uvs, 1, 0, 0, 1, 1, 0, 1);
    dwvb_uv_raster r;
    if (dwvb_uv_rasterize(uvs, 2, 8, 4, &r) == DWV_SUCCESS) {
        int wrong = 0;
        for (uint32_t row = 0; row < 4; ++row)
            for (uint32_t x = 0; x < 8; ++x) {
                double u, v;
                centre_uv(&r, x, row, &u, &v);
                int32_t t = r.texels[row * 8 + x].triangle;
                if (u != v) wrong += t != (u > v ? 0 : 1);
            }
        CHECK(wrong == 0, "square 8x4: %d texels in the wrong triangle", wrong);
        CHECK(r.texels[0].triangle == 1 && r.texels[7].triangle == 0, "square 8x4: corners %d %d (row 0 is v = 1)",
              r.texels[0].triangle, r.texels[7].triangle);
        dwvb_uv_raster_free(&r);
    } else {
        CHECK(0, "square 8x4: %s", dwv_last_error_message());
    }
}

/* A point on the unit square's perimeter at arc length s in [0, 4), counter-clockwise from (0,0). */
static void perimeter(double s, double *u, double *v)
{
    if (s < 1) { *u = s; *v = 0; }
    else if (s < 2) { *u = 1; *v = s - 1; }
    else if (s < 3) { *u = 3 - s; *v = 1; }
    else { *u = 0; *v = 4 - s; }
}

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* A fan of many thin triangles tiling the unit square around (cu, cv), windings mixed at random:
 * its spokes include the horizontal, vertical and diagonal ones through the centre and spokes to
 * texel-centre positions on the border, so many edges and the shared vertex hit texel centres. */
static void test_fan(uint32_t w, uint32_t h, double cu, double cv, int spokes)
{
    double *s = malloc(sizeof *s * (size_t)(spokes + 64));
    float *uvs = malloc(sizeof *uvs * 6 * (size_t)(spokes + 64));
    int n = 0;
    for (int k = 0; k < 4; ++k) s[n++] = k;                      /* the corners */
    s[n++] = cu; s[n++] = 1 + cv; s[n++] = 3 - cu; s[n++] = 4 - cv; /* axis spokes */
    for (uint32_t k = 0; k < 16 && k < w; ++k) s[n++] = (k + 0.5) / w; /* texel-centre positions */
    for (uint32_t k = 0; k < 16 && k < h; ++k) s[n++] = 1 + (k + 0.5) / h;
    while (n < spokes) s[n++] = 4.0 * uniform();
    qsort(s, (size_t)n, sizeof *s, compare_double);
    int m = 0;
    for (int k = 0; k < n; ++k) {
        double u0, v0, u1, v1;
        perimeter(s[k], &u0, &v0);
        perimeter(k + 1 < n ? s[k + 1] : s[0], &u1, &v1);
        if (u0 == u1 && v0 == v1) continue;
        if (uniform() < 0.5)
            set_triangle(uvs, (size_t)m++, cu, cv, u0, v0, u1, v1);
        else
            set_triangle(uvs, (size_t)m++, cu, cv, u1, v1, u0, v0);
    }
    check_tiling("fan", uvs, (uint32_t)m, w, h, 1);
    free(s);
    free(uvs);
}

/* Vertical strips, each two triangles, with strip borders on texel-centre columns. */
static void test_strips(uint32_t w, uint32_t h)
{
    float *uvs = malloc(sizeof *uvs * 6 * 2 * (size_t)w);
    uint32_t m = 0;
    double left = 0;
    for (uint32_t k = 0; k < w; ++k) {
        double right = k + 1 < w ? (k + 0.5) / w : 1.0;
        if (k % 2)
            set_triangle(uvs, m++, left, 0, right, 0, right, 1);
        else
            set_triangle(uvs, m++, right, 1, right, 0, left, 0);
        set_triangle(uvs, m++, left, 0, right, 1, left, 1);
        left = right;
    }
    check_tiling("strips", uvs, m, w, h, 0);
    free(uvs);
}

/* Random triangles: every covered centre within the triangle (to the snapping) and every uncovered
 * centre outside it; the count against the area; barycentrics give back the centre's UV. */
static void test_random_triangles(uint32_t w, uint32_t h, int on_grid)
{
    int bad_inside = 0, bad_count = 0, bad_uv = 0, bad_bary = 0;
    double worst_uv = 0;
    for (int trial = 0; trial < 300; ++trial) {
        float t[6];
        for (int k = 0; k < 6; ++k) {
            double c = -0.05 + 1.1 * uniform();
            /* On the snapping grid (1/256 texel) the raster is exact and so are barycentrics. */
            if (on_grid) c = floor(c * (k % 2 ? h : w) * 256.0) / ((k % 2 ? h : w) * 256.0);
            t[k] = (float)c;
        }
        dwvb_uv_raster r;
        if (dwvb_uv_rasterize(t, 1, w, h, &r) != DWV_SUCCESS) {
            CHECK(0, "random triangle: %s", dwv_last_error_message());
            return;
        }
        /* Lattice points of a convex set: A - P/2 < N <= A + P/2 + 1 (Nosarzewska 1948), with
         * the image border as part of the set when the triangle is clipped: checked only for
         * triangles inside the image, plus a texel for the snapping. */
        double px[3], py[3], perim = 0;
        int inside_image = 1;
        for (int k = 0; k < 3; ++k) {
            px[k] = t[2 * k] * (double)w;
            py[k] = t[2 * k + 1] * (double)h;
            inside_image &= px[k] >= 0 && px[k] <= w && py[k] >= 0 && py[k] <= h;
        }
        for (int k = 0; k < 3; ++k) perim += hypot(px[(k + 1) % 3] - px[k], py[(k + 1) % 3] - py[k]);
        double area = 0.5 * fabs((px[1] - px[0]) * (py[2] - py[0]) - (px[2] - px[0]) * (py[1] - py[0]));
        if (inside_image && fabs((double)r.covered - area) > perim / 2 + 2) {
            ++bad_count;
            fprintf(stderr, "triangle %d: %llu texels, area %.3f, perimeter %.3f\n", trial,
                    (unsigned long long)r.covered, area, perim);
        }
        double tolerance = on_grid ? 1e-9 : 1.0 / 256.0;
        for (uint32_t row = 0; row < h; ++row)
            for (uint32_t x = 0; x < w; ++x) {
                const dwvb_uv_texel *texel = &r.texels[(size_t)row * w + x];
                double d = inside_distance(t, w, h, x + 0.5, h - row - 0.5);
                if ((texel->triangle == 0 && d < -tolerance) || (texel->triangle < 0 && d > tolerance)) {
                    if (++bad_inside < 5)
                        fprintf(stderr, "trial %d texel (%u, %u): triangle %d at distance %g\n", trial, x, row,
                                texel->triangle, d);
                }
                if (texel->triangle != 0) continue;
                double b1 = texel->b1, b2 = texel->b2, b0 = 1.0 - b1 - b2;
                bad_bary += !(b1 >= 0 && b2 >= 0 && b0 >= -1e-7);
                double u = b0 * t[0] + b1 * t[2] + b2 * t[4], v = b0 * t[1] + b1 * t[3] + b2 * t[5], cu, cv;
                centre_uv(&r, x, row, &cu, &cv);
                double error = fmax(fabs(u - cu), fabs(v - cv));
                worst_uv = fmax(worst_uv, error);
                /* Off the grid, clamping moves centres let in by snapping by up to 1/512 texel. */
                bad_uv += error > (on_grid ? 1e-6 : 1e-6 + 1.0 / (256.0 * (w < h ? w : h)));
            }
        dwvb_uv_raster_free(&r);
    }
    CHECK(bad_inside == 0, "%ux%u%s: %d texels on the wrong side of their triangle", w, h, on_grid ? " grid" : "", bad_inside);
    CHECK(bad_count == 0, "%ux%u: %d triangles with a texel count far from their area", w, h, bad_count);
    CHECK(bad_bary == 0, "%ux%u: %d texels with barycentrics outside the triangle", w, h, bad_bary);
    CHECK(bad_uv == 0, "%ux%u%s: %d texels whose barycentrics miss the centre's UV (worst %g)", w, h,
          on_grid ? " grid" : "", bad_uv, worst_uv);
}

static void test_skipped_and_overlaps(void)
{
    const double nan = NAN, inf = INFINITY;
    float uvs[6 * 11];
    set_triangle(uvs, 0, 0.1, 0.1, 0.4, 0.1, 0.1, 0.4);      /* valid */
    set_triangle(uvs, 1, 0.1, 0.1, 0.5, 0.5, 0.9, 0.9);      /* collinear */
    set_triangle(uvs, 2, 0.3, 0.7, 0.3, 0.7, 0.8, 0.2);      /* repeated corner */
    set_triangle(uvs, 3, nan, 0.1, 0.4, 0.1, 0.1, 0.4);      /* NaN */
    set_triangle(uvs, 4, 0.1, 0.1, inf, 0.1, 0.1, 0.4);      /* infinite */
    set_triangle(uvs, 5, 0.1, 0.1, 0.4, 0.1, 0.1, -inf);     /* minus infinite */
    set_triangle(uvs, 6, 2.0, 0.1, 3.0, 0.1, 2.0, 0.9);      /* beside the image: not drawn, not skipped */
    set_triangle(uvs, 7, -0.5, 0.5, 1e6, 0.5, 0.5, 0.9);     /* reaches in from too far */
    set_triangle(uvs, 8, 0.6, 0.6, 0.9, 0.6, 0.6, 0.9);      /* valid */
    set_triangle(uvs, 9, 0.05, 0.05, 0.35, 0.05, 0.05, 0.35); /* overlaps triangle 0: last wins */
    /* A sliver along the diagonal (through texel centres), 1/256 texel thick once snapped. */
    set_triangle(uvs, 10, 1.0 / 32, 1.0 / 32, 31.0 / 32, 31.0 / 32, 0.5, 0.5 + 2e-4);
    dwvb_uv_raster r;
    dwv_result_t res = dwvb_uv_rasterize(uvs, 10, 32, 32, &r);
    CHECK(res == DWV_SUCCESS, "skips: %s", dwv_last_error_message());
    if (res != DWV_SUCCESS) return;
    CHECK(r.skipped_degenerate == 2, "skips: %u degenerate, expected 2", r.skipped_degenerate);
    CHECK(r.skipped_nonfinite == 3, "skips: %u non-finite, expected 3", r.skipped_nonfinite);
    CHECK(r.skipped_far == 1, "skips: %u far, expected 1", r.skipped_far);
    uint64_t per[10] = {0}, total = 0;
    for (size_t i = 0; i < 32 * 32; ++i)
        if (r.texels[i].triangle >= 0) { ++per[r.texels[i].triangle]; ++total; }
    CHECK(per[1] + per[2] + per[3] + per[4] + per[5] + per[6] + per[7] == 0, "skips: skipped triangles drew texels");
    CHECK(per[0] > 0 && per[8] > 0 && per[9] > 0, "skips: valid triangles drew %llu %llu %llu texels",
          (unsigned long long)per[0], (unsigned long long)per[8], (unsigned long long)per[9]);
    CHECK(total == r.covered, "skips: covered %llu, counted %llu", (unsigned long long)r.covered, (unsigned long long)total);
    /* Triangle 9 holds the texels it shares with triangle 0 (no centre within 0.1 texel of an edge). */
    uint64_t overlap = 0;
    int wrong = 0;
    for (uint32_t row = 0; row < 32; ++row)
        for (uint32_t x = 0; x < 32; ++x) {
            double u, v;
            centre_uv(&r, x, row, &u, &v);
            int in0 = u > 0.1 && v > 0.1 && u + v < 0.5, in9 = u > 0.05 && v > 0.05 && u + v < 0.4;
            if (in0 && in9) ++overlap;
            if (in9 && r.texels[row * 32 + x].triangle != 9) ++wrong;
        }
    CHECK(wrong == 0 && overlap > 0 && r.overwritten == overlap, "overlap: %d texels not the last triangle's, "
          "%llu overwritten for %llu overlapping", wrong, (unsigned long long)r.overwritten, (unsigned long long)overlap);
    dwvb_uv_raster_free(&r);

    /* A triangle far larger than the image (within range), clipped to it: covers everything. */
    set_triangle(uvs, 0, -3, -3, 7, -3, -3, 7);
    check_tiling("huge triangle", uvs, 1, 16, 16, 0);
    /* The sliver: whatever it covers (centres on the diagonal), barycentrics stay inside and
     * put the point within the snapping (1/256 texel) of the centre. */
    if (dwvb_uv_rasterize(uvs + 60, 1, 16, 16, &r) == DWV_SUCCESS) {
        int bad = 0;
        const float *t = uvs + 60;
        for (uint32_t row = 0; row < 16; ++row)
            for (uint32_t x = 0; x < 16; ++x) {
                const dwvb_uv_texel *e = &r.texels[row * 16 + x];
                if (e->triangle < 0) continue;
                double b1 = e->b1, b2 = e->b2, b0 = 1.0 - b1 - b2, cu, cv;
                centre_uv(&r, x, row, &cu, &cv);
                double u = b0 * t[0] + b1 * t[2] + b2 * t[4], v = b0 * t[1] + b1 * t[3] + b2 * t[5];
                bad += !(b1 >= 0 && b2 >= 0 && b0 >= -1e-7) || hypot(u - cu, v - cv) * 16 > 1.0 / 256;
            }
        CHECK(bad == 0 && r.covered <= 16, "sliver: %llu covered, %d bad barycentrics", (unsigned long long)r.covered, bad);
        dwvb_uv_raster_free(&r);
    }
    /* No triangles: an empty raster. */
    res = dwvb_uv_rasterize(NULL, 0, 3, 3, &r);
    CHECK(res == DWV_SUCCESS && r.covered == 0 && r.texels && r.texels[4].triangle == -1, "empty: %d", res);
    dwvb_uv_raster_free(&r);
}

static int64_t chebyshev(uint32_t w, size_t a, size_t b)
{
    int64_t dx = llabs((int64_t)(a % w) - (int64_t)(b % w)), dy = llabs((int64_t)(a / w) - (int64_t)(b / w));
    return dx > dy ? dx : dy;
}

static void test_margin(void)
{
    const uint32_t w = 41, h = 29;
    float uvs[6 * 4];
    set_triangle(uvs, 0, 0.1, 0.1, 0.3, 0.15, 0.15, 0.4);
    set_triangle(uvs, 1, 0.6, 0.5, 0.95, 0.55, 0.7, 0.97);
    set_triangle(uvs, 2, 0.5, 0.02, 0.53, 0.02, 0.5, 0.05); /* a one-texel sliver island */
    set_triangle(uvs, 3, 0.0, 0.0, 0.03, 0.0, 0.0, 0.04);   /* at the image's corner */
    dwvb_uv_raster r;
    if (dwvb_uv_rasterize(uvs, 4, w, h, &r) != DWV_SUCCESS) {
        CHECK(0, "margin raster: %s", dwv_last_error_message());
        return;
    }
    const size_t n = (size_t)w * h;
    /* Brute force: each texel's Chebyshev distance to the nearest covered texel. */
    int64_t *distance = malloc(sizeof *distance * n);
    for (size_t i = 0; i < n; ++i) {
        distance[i] = INT64_MAX;
        for (size_t j = 0; j < n; ++j)
            if (r.texels[j].triangle >= 0) {
                int64_t d = chebyshev(w, i, j);
                if (d < distance[i]) distance[i] = d;
            }
    }
    const uint32_t margins[] = {0, 1, 2, 3, 7, 64, 100000};
    for (size_t m = 0; m < sizeof margins / sizeof margins[0]; ++m) {
        uint32_t k = margins[m];
        dwvb_uv_margin plan;
        if (dwvb_uv_margin_build(&r, k, &plan) != DWV_SUCCESS) {
            CHECK(0, "margin %u: %s", k, dwv_last_error_message());
            continue;
        }
        int wrong = 0;
        uint64_t expected_filled = 0;
        for (size_t i = 0; i < n; ++i) {
            uint32_t s = plan.source[i];
            if (distance[i] == 0) {
                wrong += s != i;
            } else if (distance[i] <= (int64_t)k) {
                ++expected_filled;
                wrong += s == DWVB_UV_NO_SOURCE || r.texels[s].triangle < 0 || chebyshev(w, i, s) != distance[i];
            } else {
                wrong += s != DWVB_UV_NO_SOURCE;
            }
        }
        CHECK(wrong == 0, "margin %u: %d texels with a wrong source", k, wrong);
        CHECK(plan.filled == expected_filled, "margin %u: filled %llu, expected %llu", k,
              (unsigned long long)plan.filled, (unsigned long long)expected_filled);

        /* On an image: covered texels as they were, margin texels a copy of their source in all
         * three layers, the rest untouched (alpha 0). */
        dwvb_image *image = dwvb_image_new(w, h);
        for (size_t i = 0; i < n; ++i)
            if (r.texels[i].triangle >= 0) {
                for (int c = 0; c < 4; ++c) image->rgba[4 * i + c] = c == 3 ? 1.0f : (float)(i * 4 + c) * 0.25f;
                for (int c = 0; c < 3; ++c) image->variance[3 * i + c] = (float)(i + c) * 1e-3f;
                image->samples[i] = (uint32_t)(i + 7);
            }
        dwvb_image *before = dwvb_image_new(w, h);
        memcpy(before->rgba, image->rgba, sizeof(float) * 4 * n);
        memcpy(before->variance, image->variance, sizeof(float) * 3 * n);
        memcpy(before->samples, image->samples, sizeof(uint32_t) * n);
        dwv_result_t res = dwvb_uv_dilate_image(&r, k, image);
        CHECK(res == DWV_SUCCESS, "dilate %u: %s", k, dwv_last_error_message());
        int changed_covered = 0, bad_margin = 0, bad_outside = 0;
        for (size_t i = 0; i < n; ++i) {
            size_t s = plan.source[i];
            if (distance[i] == 0) {
                changed_covered += memcmp(image->rgba + 4 * i, before->rgba + 4 * i, 16) != 0 ||
                                   memcmp(image->variance + 3 * i, before->variance + 3 * i, 12) != 0 ||
                                   image->samples[i] != before->samples[i];
            } else if (distance[i] <= (int64_t)k) {
                bad_margin += memcmp(image->rgba + 4 * i, before->rgba + 4 * s, 16) != 0 ||
                              memcmp(image->variance + 3 * i, before->variance + 3 * s, 12) != 0 ||
                              image->samples[i] != before->samples[s] || image->rgba[4 * i + 3] != 1.0f;
            } else {
                bad_outside += image->rgba[4 * i + 3] != 0.0f || image->rgba[4 * i] != 0.0f ||
                               image->variance[3 * i] != 0.0f || image->samples[i] != 0;
            }
        }
        CHECK(changed_covered == 0 && bad_margin == 0 && bad_outside == 0,
              "dilate %u: %d covered texels changed, %d margin texels not their source's, %d outside written", k,
              changed_covered, bad_margin, bad_outside);
        dwvb_image_free(image);
        dwvb_image_free(before);
        dwvb_uv_margin_free(&plan);
    }
    free(distance);

    /* The source is the nearest covered texel when there is a single one. */
    dwvb_uv_margin plan;
    float one[6];
    set_triangle(one, 0, 0.51, 0.51, 0.53, 0.51, 0.51, 0.53);
    dwvb_uv_raster dot;
    if (dwvb_uv_rasterize(one, 1, 40, 40, &dot) == DWV_SUCCESS && dwvb_uv_margin_build(&dot, 3, &plan) == DWV_SUCCESS) {
        CHECK(dot.covered == 1 && plan.filled == 48, "single texel: %llu covered, margin 3 filled %llu (expected 48)",
              (unsigned long long)dot.covered, (unsigned long long)plan.filled);
        dwvb_uv_margin_free(&plan);
    } else {
        CHECK(0, "single texel: %s", dwv_last_error_message());
    }
    /* Nothing covered: nothing filled. */
    dwvb_uv_raster_free(&dot);
    if (dwvb_uv_rasterize(NULL, 0, 9, 9, &dot) == DWV_SUCCESS && dwvb_uv_margin_build(&dot, 5, &plan) == DWV_SUCCESS) {
        int any = 0;
        for (size_t i = 0; i < 81; ++i) any += plan.source[i] != DWVB_UV_NO_SOURCE;
        CHECK(any == 0 && plan.filled == 0, "empty margin: %d texels given a source", any);
        dwvb_uv_margin_free(&plan);
    }
    dwvb_uv_raster_free(&dot);
    /* A mismatched image is refused. */
    dwvb_image *small = dwvb_image_new(w, h - 1);
    CHECK(dwvb_uv_dilate_image(&r, 2, small) == DWV_ERROR_INVALID_ARGUMENT, "a mismatched image was accepted");
    dwvb_image_free(small);
    dwvb_uv_raster_free(&r);
}

/* Refusals, with the raster left empty. */
static int refusals(void)
{
    int failures = 0;
    float uvs[6] = {0, 0, 1, 0, 0, 1};
    const uint32_t bad[][2] = {{0, 5}, {5, 0}, {16385, 1}, {1, 16385}, {16384, 16384}, {8193, 8192}, {UINT32_MAX, UINT32_MAX}};
    for (size_t b = 0; b < sizeof bad / sizeof bad[0]; ++b) {
        dwvb_uv_raster r;
        dwv_result_t res = dwvb_uv_rasterize(uvs, 1, bad[b][0], bad[b][1], &r);
        if (res != DWV_ERROR_OUT_OF_RANGE || r.texels) {
            fprintf(stderr, "size %ux%u: result %d\n", bad[b][0], bad[b][1], res);
            ++failures;
        }
    }
    dwvb_uv_raster r;
    /* Refused before the UVs are read (the buffer holds one triangle). */
    if (dwvb_uv_rasterize(uvs, (uint32_t)INT32_MAX + 1u, 4, 4, &r) != DWV_ERROR_OUT_OF_RANGE || r.texels) ++failures;
    if (dwvb_uv_rasterize(NULL, 1, 4, 4, &r) != DWV_ERROR_NULL_POINTER || r.texels) ++failures;
    if (dwvb_uv_rasterize(uvs, 1, 4, 4, NULL) != DWV_ERROR_NULL_POINTER) ++failures;
    return failures;
}

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer) || __has_feature(thread_sanitizer)
#define SHADOW_MEMORY 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define SHADOW_MEMORY 1
#endif

/* Under a 256 MiB address-space limit the refusals still come without allocating, and the
 * largest valid raster (2^26 texels, 768 MiB) fails cleanly as out of memory. In a child, since
 * the limit cannot be lifted again; not under sanitizers or valgrind, which need the room. */
static void test_sizes(void)
{
    CHECK(refusals() == 0, "refusals");
#ifdef SHADOW_MEMORY
    int limited = 0;
#else
    const char *preload = getenv("LD_PRELOAD");
    int limited = !(preload && strstr(preload, "vgpreload"));
#endif
    if (!limited) {
        printf("address-space limit test not run (sanitizer or valgrind)\n");
        return;
    }
    pid_t child = fork();
    if (child == 0) {
        struct rlimit limit = {256u << 20, 256u << 20};
        if (setrlimit(RLIMIT_AS, &limit) != 0) _exit(3);
        if (refusals() != 0) _exit(1);
        dwvb_uv_raster r;
        float uvs[6] = {0, 0, 1, 0, 0, 1};
        dwv_result_t res = dwvb_uv_rasterize(uvs, 1, 8192, 8192, &r);
        _exit(res == DWV_ERROR_OUT_OF_MEMORY && r.texels == NULL ? 0 : 2);
    }
    int status = 0;
    CHECK(child > 0 && waitpid(child, &status, 0) == child, "fork");
    CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0, "under a 256 MiB limit: child status %d (1: a refusal failed, "
          "2: no clean out-of-memory, 3: setrlimit)", status);
}

int main(void)
{
    test_unit_square();
    test_fan(64, 64, 0.5 + 0.5 / 64, 0.5 + 0.5 / 64, 600);
    test_fan(61, 47, 0.5, 0.5, 400);
    test_fan(7, 5, 0.3, 0.7, 200);
    test_fan(33, 90, 0.123456, 0.654321, 1000);
    test_strips(16, 9);
    test_strips(63, 64);
    test_random_triangles(64, 64, 1);
    test_random_triangles(16, 128, 1);
    test_random_triangles(64, 64, 0);
    test_random_triangles(13, 50, 0);
    test_skipped_and_overlaps();
    test_margin();
    test_sizes();
    return check_report("uv_raster");
}
