#include "envmap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

static double luminance(const float *rgb)
{
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
}

/* Periodic wrap of a texel index, as Cycles' EXTENSION_REPEAT. */
static uint32_t wrap(int64_t i, uint32_t n)
{
    int64_t m = i % (int64_t)n;
    return (uint32_t)(m < 0 ? m + (int64_t)n : m);
}

/* z_{r+1} - z_r = cos(pi r / h) - cos(pi (r + 1) / h) = 2 sin(pi (2r + 1) / (2h)) sin(pi / (2h)),
 * without the cancellation of the difference near the poles. */
static double row_dz(uint32_t r, uint32_t h)
{
    return 2.0 * sin(PI * (2.0 * r + 1.0) / (2.0 * h)) * sin(PI / (2.0 * h));
}

static double row_z(uint32_t r, uint32_t h)
{
    return -cos(PI * (double)r / (double)h);
}

void dwvl_envmap_free(dwvl_envmap *map)
{
    free(map->texels);
    free(map->column_cdf);
    free(map->row_cdf);
    map->texels = map->column_cdf = NULL;
    map->row_cdf = NULL;
}

size_t dwvl_envmap_bytes(const dwvl_envmap *map)
{
    size_t n = (size_t)map->width * map->height;
    return n * 3u * sizeof(float) + n * sizeof(float) + map->height * sizeof(double);
}

int dwvl_envmap_init(dwvl_envmap *map, const dwv_environment_t *desc)
{
    uint32_t w = desc->width, h = desc->height;
    size_t n = (size_t)w * h;
    memset(map, 0, sizeof *map);
    map->width = w;
    map->height = h;
    map->interpolation = desc->interpolation;
    map->strength = desc->strength;
    memcpy(map->rotation, desc->rotation, sizeof map->rotation);
    map->texels = malloc(3u * n * sizeof(float));
    map->column_cdf = malloc(n * sizeof(float));
    map->row_cdf = malloc(h * sizeof(double));
    float *row_max = malloc(n * sizeof(float));
    if (!map->texels || !map->column_cdf || !map->row_cdf || !row_max) {
        free(row_max);
        dwvl_envmap_free(map);
        return -1;
    }
    memcpy(map->texels, desc->texels, 3u * n * sizeof(float));
    /* The texels an interpolated lookup anywhere in cell (c, r) reads: within `reach` of it. */
    int reach = desc->interpolation == DWV_ENVIRONMENT_CLOSEST ? 0 : desc->interpolation == DWV_ENVIRONMENT_LINEAR ? 1 : 2;
    for (uint32_t r = 0; r < h; ++r)
        for (uint32_t c = 0; c < w; ++c) {
            double m = 0.0;
            for (int k = -reach; k <= reach; ++k) m = fmax(m, luminance(map->texels + 3u * ((size_t)r * w + wrap((int64_t)c + k, w))));
            row_max[(size_t)r * w + c] = (float)m;
        }
    double total = 0.0;
    for (uint32_t r = 0; r < h; ++r) {
        double omega = 2.0 * PI / w * row_dz(r, h), sum = 0.0;
        float *cdf = map->column_cdf + (size_t)r * w;
        for (uint32_t c = 0; c < w; ++c) {
            double m = 0.0;
            for (int k = -reach; k <= reach; ++k) m = fmax(m, row_max[(size_t)wrap((int64_t)r + k, h) * w + c]);
            sum += m;
            cdf[c] = (float)sum; /* normalised below */
        }
        for (uint32_t c = 0; c < w; ++c) cdf[c] = sum > 0.0 ? (float)(cdf[c] / sum) : 0.0f;
        if (sum > 0.0) cdf[w - 1u] = 1.0f;
        total += sum * omega;
        map->row_cdf[r] = total;
    }
    free(row_max);
    if (!(total > 0.0)) {
        /* Texels so small that no luminance is above 0 in single precision: a black world. */
        dwvl_envmap_free(map);
        return 1;
    }
    for (uint32_t r = 0; r < h; ++r) map->row_cdf[r] /= total;
    map->row_cdf[h - 1u] = 1.0;
    return 0;
}

static dwvu_vec3 to_map(const dwvl_envmap *map, dwvu_vec3 d)
{
    const double *m = map->rotation;
    return dwvu_v(m[0] * d.x + m[1] * d.y + m[2] * d.z, m[3] * d.x + m[4] * d.y + m[5] * d.z,
                  m[6] * d.x + m[7] * d.y + m[8] * d.z);
}

/* Cycles' direction_to_equirectangular of a map-space direction. */
static void map_uv(dwvu_vec3 b, double *u, double *v)
{
    double len = dwvu_length(b);
    double z = len > 0.0 ? fmin(1.0, fmax(-1.0, b.z / len)) : 1.0;
    *u = 0.5 - atan2(b.y, b.x) / (2.0 * PI);
    *v = 1.0 - acos(z) / PI;
}

static const float *texel(const dwvl_envmap *map, int64_t c, int64_t r)
{
    return map->texels + 3u * ((size_t)wrap(r, map->height) * map->width + wrap(c, map->width));
}

/* The uniform cubic B-spline's weights at fraction t (Cycles' bicubic image lookup). */
static void bspline_weights(double t, double wt[4])
{
    double t2 = t * t, t3 = t2 * t;
    wt[0] = (1.0 - t) * (1.0 - t) * (1.0 - t) / 6.0;
    wt[1] = (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0;
    wt[2] = (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0;
    wt[3] = t3 / 6.0;
}

void dwvl_envmap_radiance(const dwvl_envmap *map, dwvu_vec3 d, double rgb[3])
{
    double u, v;
    map_uv(to_map(map, d), &u, &v);
    rgb[0] = rgb[1] = rgb[2] = 0.0;
    if (map->interpolation == DWV_ENVIRONMENT_CLOSEST) {
        const float *t = texel(map, (int64_t)floor(u * map->width), (int64_t)floor(v * map->height));
        for (int k = 0; k < 3; ++k) rgb[k] = t[k];
    } else {
        /* Texel centres at (i + 0.5) / w. */
        double x = u * map->width - 0.5, y = v * map->height - 0.5;
        double fx = floor(x), fy = floor(y);
        int64_t ix = (int64_t)fx, iy = (int64_t)fy;
        double tx = x - fx, ty = y - fy;
        if (map->interpolation == DWV_ENVIRONMENT_LINEAR) {
            double wx[2] = {1.0 - tx, tx}, wy[2] = {1.0 - ty, ty};
            for (int j = 0; j < 2; ++j)
                for (int i = 0; i < 2; ++i) {
                    const float *t = texel(map, ix + i, iy + j);
                    for (int k = 0; k < 3; ++k) rgb[k] += wx[i] * wy[j] * t[k];
                }
        } else {
            double wx[4], wy[4];
            bspline_weights(tx, wx);
            bspline_weights(ty, wy);
            for (int j = 0; j < 4; ++j)
                for (int i = 0; i < 4; ++i) {
                    const float *t = texel(map, ix + i - 1, iy + j - 1);
                    for (int k = 0; k < 3; ++k) rgb[k] += wx[i] * wy[j] * t[k];
                }
        }
    }
    for (int k = 0; k < 3; ++k) rgb[k] *= map->strength;
}

/* The probability of texel (c, r) over its solid angle. */
static double cell_pdf(const dwvl_envmap *map, uint32_t c, uint32_t r)
{
    uint32_t w = map->width, h = map->height;
    double p_row = map->row_cdf[r] - (r ? map->row_cdf[r - 1u] : 0.0);
    const float *cdf = map->column_cdf + (size_t)r * w;
    double p_column = (double)cdf[c] - (c ? (double)cdf[c - 1u] : 0.0);
    double omega = 2.0 * PI / w * row_dz(r, h);
    return p_row * p_column / omega;
}

double dwvl_envmap_pdf(const dwvl_envmap *map, dwvu_vec3 d)
{
    double u, v;
    map_uv(to_map(map, d), &u, &v);
    uint32_t c = (uint32_t)fmin(floor(u * map->width), map->width - 1.0);
    uint32_t r = (uint32_t)fmin(floor(v * map->height), map->height - 1.0);
    return cell_pdf(map, c, r);
}

void dwvl_envmap_sample(const dwvl_envmap *map, double u1, double u2, dwvu_vec3 *d, double *pdf)
{
    uint32_t w = map->width, h = map->height;
    /* The first row whose CDF exceeds u1 (rows of probability 0 are never it). */
    uint32_t lo = 0, hi = h - 1u;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2u;
        if (map->row_cdf[mid] > u1) hi = mid;
        else lo = mid + 1u;
    }
    uint32_t r = lo;
    double row_lo = r ? map->row_cdf[r - 1u] : 0.0, row_hi = map->row_cdf[r];
    const float *cdf = map->column_cdf + (size_t)r * w;
    lo = 0;
    hi = w - 1u;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2u;
        if ((double)cdf[mid] > u2) hi = mid;
        else lo = mid + 1u;
    }
    uint32_t c = lo;
    double column_lo = c ? (double)cdf[c - 1u] : 0.0, column_hi = (double)cdf[c];
    if (!(row_hi > row_lo) || !(column_hi > column_lo)) {
        *d = dwvu_v(0.0, 0.0, 1.0);
        *pdf = 0.0;
        return;
    }
    /* The remainders of u1 and u2 within the chosen row and column place the direction in the
     * cell (z and phi uniform: uniform in its solid angle). */
    double t_row = fmin(1.0, (u1 - row_lo) / (row_hi - row_lo));
    double t_column = fmin(1.0, (u2 - column_lo) / (column_hi - column_lo));
    double z = row_z(r, h) + t_row * row_dz(r, h);
    z = fmin(1.0, fmax(-1.0, z));
    double sin_theta = sqrt(fmax(0.0, (1.0 - z) * (1.0 + z)));
    double phi = PI * (1.0 - 2.0 * ((c + t_column) / w));
    dwvu_vec3 b = dwvu_v(sin_theta * cos(phi), sin_theta * sin(phi), z);
    /* World direction: the rotation's transpose (its inverse) of b. */
    const double *m = map->rotation;
    *d = dwvu_normalize(dwvu_v(m[0] * b.x + m[3] * b.y + m[6] * b.z, m[1] * b.x + m[4] * b.y + m[7] * b.z,
                               m[2] * b.x + m[5] * b.y + m[8] * b.z));
    *pdf = (row_hi - row_lo) * (column_hi - column_lo) / (2.0 * PI / w * row_dz(r, h));
}
