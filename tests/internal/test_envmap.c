/* The environment map (src/light/envmap.c): its equirectangular lookup against hand-computed
 * texels, its sampler against its pdf by a chi-square histogram (with a planted error the
 * harness must catch), their agreement sample by sample, the rotation, and a uniform map
 * against the constant world in next-event estimation. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "kernel/rng.h"
#include "light/direct.h"
#include "light/envmap.h"
#include "stats.h"

#define PI 3.14159265358979323846

static dwvu_vec3 direction(double theta, double phi)
{
    return dwvu_v(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
}

static dwv_environment_t environment(uint32_t w, uint32_t h, const float *texels, dwv_environment_interpolation_t interpolation)
{
    dwv_environment_t e = DWV_ENVIRONMENT_INIT;
    e.width = w;
    e.height = h;
    e.texels = texels;
    e.interpolation = interpolation;
    return e;
}

/* Closest lookup: texel (c, r) holds c + 100 r in red; directions whose (u, v) are worked out by
 * hand from u = 0.5 - atan2(y, x) / (2 pi), v = 1 - acos(z) / pi. */
static void test_lookup_convention(void)
{
    enum { W = 8, H = 4 };
    float texels[3 * W * H];
    for (int r = 0; r < H; ++r)
        for (int c = 0; c < W; ++c) {
            texels[3 * (r * W + c)] = (float)(c + 100 * r);
            texels[3 * (r * W + c) + 1] = texels[3 * (r * W + c) + 2] = 0.0f;
        }
    dwv_environment_t e = environment(W, H, texels, DWV_ENVIRONMENT_CLOSEST);
    e.strength = 2.0;
    dwvl_envmap map;
    CHECK(dwvl_envmap_init(&map, &e) == 0, "init");
    struct { dwvu_vec3 d; int c, r; } cases[] = {
        {{1.0, 0.0, 0.01}, 4, 2},   /* +x: u = 0.5, just above the horizon: v = 0.503 */
        {{1.0, 0.0, -0.01}, 4, 1},  /* just below it: v = 0.497 */
        {{0.0, 1.0, 0.01}, 2, 2},   /* +y: u = 0.25 */
        {{0.0, -1.0, 0.01}, 6, 2},  /* -y: u = 0.75 */
        {{-1.0, 1e-3, 0.01}, 0, 2}, /* -x, a little toward +y: atan2 = pi - 1e-3, u = 1.6e-4 */
        {{-1.0, -1e-3, 0.01}, 7, 2},/* toward -y: atan2 = -pi + 1e-3, u = 1 - 1.6e-4 */
        {{0.3, 0.0, 0.9539392}, 4, 3},  /* high: theta = 17.5 deg, v = 0.903 */
        {{0.3, 0.0, -0.9539392}, 4, 0}, /* low: v = 0.097 */
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        double rgb[3];
        dwvl_envmap_radiance(&map, dwvu_normalize(cases[i].d), rgb);
        double want = 2.0 * (cases[i].c + 100 * cases[i].r);
        CHECK(rgb[0] == want, "case %zu: radiance %g, want texel (%d, %d) x 2 = %g", i, rgb[0], cases[i].c, cases[i].r,
              want);
    }
    dwvl_envmap_free(&map);
}

/* Linear and cubic lookups: at a texel centre the bilinear lookup is the texel; half-way between
 * two centres their mean; the cubic B-spline reproduces a function linear in u (away from the
 * periodic seam) and a constant. */
static void test_interpolation(void)
{
    enum { W = 16, H = 8 };
    float texels[3 * W * H];
    for (int r = 0; r < H; ++r)
        for (int c = 0; c < W; ++c)
            for (int k = 0; k < 3; ++k) texels[3 * (r * W + c) + k] = (float)(1.0 + c) + (k == 2 ? 0.0f : 0.0f);
    for (int interpolation = DWV_ENVIRONMENT_LINEAR; interpolation <= DWV_ENVIRONMENT_CUBIC; interpolation += 2) {
        dwv_environment_t e = environment(W, H, texels, interpolation);
        dwvl_envmap map;
        CHECK(dwvl_envmap_init(&map, &e) == 0, "init");
        for (int c = 3; c < 12; ++c) {
            /* The centre of column c, and half-way to column c + 1, on row 5's centre. */
            for (int half = 0; half < 2; ++half) {
                double u = (c + 0.5 + 0.5 * half) / W, v = (5 + 0.5) / H;
                double rgb[3];
                dwvl_envmap_radiance(&map, direction(PI * (1.0 - v), PI * (1.0 - 2.0 * u)), rgb);
                double want = 1.0 + c + 0.5 * half;
                CHECK(fabs(rgb[0] - want) < 1e-9 * want, "%s column %d + %d/2: %.12g, want %.12g",
                      interpolation == DWV_ENVIRONMENT_LINEAR ? "linear" : "cubic", c, half, rgb[0], want);
            }
        }
        dwvl_envmap_free(&map);
    }
    /* Bilinear between rows: half-way between row centres 2 and 3 of a map whose rows differ. */
    for (int r = 0; r < H; ++r)
        for (int c = 0; c < W; ++c) texels[3 * (r * W + c)] = (float)(10 * r);
    dwv_environment_t e = environment(W, H, texels, DWV_ENVIRONMENT_LINEAR);
    dwvl_envmap map;
    CHECK(dwvl_envmap_init(&map, &e) == 0, "init");
    double rgb[3];
    dwvl_envmap_radiance(&map, direction(PI * (1.0 - 3.0 / H), 0.3), rgb);
    CHECK(fabs(rgb[0] - 25.0) < 1e-9, "between rows 2 and 3: %.12g, want 25", rgb[0]);
    dwvl_envmap_free(&map);
}

/* A map with structure: a bright spot near the zenith, a black band (where only the neighbours'
 * interpolation reaches), a gradient, a bright texel by the nadir. */
enum { HW = 24, HH = 12 };
static void structured_texels(float *texels)
{
    for (int r = 0; r < HH; ++r)
        for (int c = 0; c < HW; ++c) {
            float *t = texels + 3 * (r * HW + c);
            double base = 0.2 + 0.05 * c;
            if (r == 5 || r == 6) base = c < 12 ? 0.0 : base; /* a black band over half the horizon */
            if (r == HH - 2 && (c == 3 || c == 4)) base = 400.0;
            if (r == 0 && c == 17) base = 90.0;
            t[0] = (float)base;
            t[1] = (float)(0.5 * base);
            t[2] = (float)(0.25 * base);
        }
}

/* The cell of a direction in map space (identity rotation), split in S x S sub-cells of equal
 * z and phi extent: the bin index, or -1. */
#define SUB 3
static int histogram_bin(dwvu_vec3 d)
{
    double u = 0.5 - atan2(d.y, d.x) / (2.0 * PI);
    double z = fmin(1.0, fmax(-1.0, d.z));
    double v = 1.0 - acos(z) / PI;
    int c = (int)fmin(floor(u * HW), HW - 1), r = (int)fmin(floor(v * HH), HH - 1);
    double z0 = -cos(PI * r / HH), z1 = -cos(PI * (r + 1) / HH);
    int sz = (int)fmin(floor((z - z0) / (z1 - z0) * SUB), SUB - 1);
    int su = (int)fmin(floor((u * HW - c) * SUB), SUB - 1);
    if (sz < 0 || su < 0) return -1;
    return ((r * HW + c) * SUB + sz) * SUB + su;
}

/* A planted error for the harness: the sampler's directions moved within their cell so that theta,
 * not z = cos theta, is uniform in it (a sampler that forgets the sin theta Jacobian inside the
 * cell), the pdf left as it is. */
static dwvu_vec3 planted_theta_uniform(dwvu_vec3 d)
{
    double v = 1.0 - acos(fmin(1.0, fmax(-1.0, d.z))) / PI;
    int r = (int)fmin(floor(v * HH), HH - 1);
    double z0 = -cos(PI * r / HH), z1 = -cos(PI * (r + 1) / HH);
    double t = (d.z - z0) / (z1 - z0);
    double theta = PI * (1.0 - (r + t) / HH);
    double phi = atan2(d.y, d.x);
    return direction(theta, phi);
}

static stats_chi_square_t histogram_test(const dwvl_envmap *map, int planted, uint64_t n, double *pdf_mismatch)
{
    int bins = HW * HH * SUB * SUB;
    double *observed = calloc((size_t)bins, sizeof(double)), *expected = calloc((size_t)bins, sizeof(double));
    uint64_t mismatched = 0;
    for (uint64_t i = 0; i < n; ++i) {
        uint64_t key = dwvk_rng_key(0x656e766d6170ull, (uint64_t)planted, i);
        dwvu_vec3 d;
        double pdf;
        dwvl_envmap_sample(map, dwvk_rng_uniform_d(key, 0), dwvk_rng_uniform_d(key, 1), &d, &pdf);
        if (planted) d = planted_theta_uniform(d);
        double again = dwvl_envmap_pdf(map, d);
        if (!(fabs(again - pdf) <= 1e-9 * pdf)) ++mismatched;
        int b = histogram_bin(d);
        if (b >= 0) observed[b] += 1.0;
    }
    /* The pdf is constant over a cell: each sub-cell expects n pdf x its solid angle. */
    for (int r = 0; r < HH; ++r) {
        double z0 = -cos(PI * r / HH), z1 = -cos(PI * (r + 1) / HH);
        double omega_sub = (2.0 * PI / HW) * (z1 - z0) / (SUB * SUB);
        for (int c = 0; c < HW; ++c) {
            double pdf = dwvl_envmap_pdf(map, direction(acos(0.5 * (z0 + z1)), PI * (1.0 - 2.0 * (c + 0.5) / HW)));
            for (int s = 0; s < SUB * SUB; ++s) expected[(r * HW + c) * SUB * SUB + s] = (double)n * pdf * omega_sub;
        }
    }
    stats_chi_square_t result = stats_chi_square(observed, expected, bins);
    *pdf_mismatch = (double)mismatched / (double)n;
    free(observed);
    free(expected);
    return result;
}

static void test_sample_against_pdf(void)
{
    float texels[3 * HW * HH];
    structured_texels(texels);
    for (int interpolation = DWV_ENVIRONMENT_LINEAR; interpolation <= DWV_ENVIRONMENT_CUBIC; ++interpolation) {
        dwv_environment_t e = environment(HW, HH, texels, interpolation);
        dwvl_envmap map;
        CHECK(dwvl_envmap_init(&map, &e) == 0, "init");
        /* The pdf integrates to 1: it is constant over each cell. */
        double integral = 0.0;
        for (int r = 0; r < HH; ++r) {
            double z0 = -cos(PI * r / HH), z1 = -cos(PI * (r + 1) / HH);
            for (int c = 0; c < HW; ++c)
                integral += dwvl_envmap_pdf(&map, direction(acos(0.5 * (z0 + z1)), PI * (1.0 - 2.0 * (c + 0.5) / HW))) *
                            (2.0 * PI / HW) * (z1 - z0);
        }
        CHECK(fabs(integral - 1.0) < 1e-6, "interpolation %d: the pdf integrates to %.9f", interpolation, integral);
        /* The pdf is above 0 wherever the radiance is (a fine grid of directions). */
        int uncovered = 0;
        for (int i = 0; i < 400; ++i)
            for (int j = 0; j < 200; ++j) {
                dwvu_vec3 d = direction(PI * (j + 0.5) / 200.0, 2.0 * PI * (i + 0.5) / 400.0);
                double rgb[3];
                dwvl_envmap_radiance(&map, d, rgb);
                if (rgb[0] + rgb[1] + rgb[2] > 0.0 && !(dwvl_envmap_pdf(&map, d) > 0.0)) ++uncovered;
            }
        CHECK(uncovered == 0, "interpolation %d: %d directions with radiance but pdf 0", interpolation, uncovered);
        double mismatch;
        stats_chi_square_t chi = histogram_test(&map, 0, 500000u, &mismatch);
        stats_print("sampled directions against the pdf (cells x 3 x 3)", chi);
        CHECK(chi.p > STATS_P_REJECT, "interpolation %d: chi2 %.1f dof %d p %.3g", interpolation, chi.x2, chi.dof, chi.p);
        /* Only samples within rounding of a cell boundary may read a neighbour's pdf. */
        CHECK(mismatch < 1e-4, "interpolation %d: %.3g of the samples' pdfs differ from dwvl_envmap_pdf", interpolation,
              mismatch);
        if (interpolation == DWV_ENVIRONMENT_LINEAR) {
            /* The harness catches a sampler with the sin theta Jacobian wrong inside the cells. */
            stats_chi_square_t wrong = histogram_test(&map, 1, 500000u, &mismatch);
            stats_print("planted error: theta uniform within cells", wrong);
            CHECK(wrong.p < STATS_P_REJECT, "the planted error passed: chi2 %.1f p %.3g", wrong.x2, wrong.p);
        }
        dwvl_envmap_free(&map);
    }
}

/* A rotated map is the same map seen through the rotation: samples, pdfs and radiance agree with
 * the unrotated map's at the rotated directions. */
static void test_rotation(void)
{
    float texels[3 * HW * HH];
    structured_texels(texels);
    dwv_environment_t e = environment(HW, HH, texels, DWV_ENVIRONMENT_LINEAR);
    dwvl_envmap plain, turned;
    CHECK(dwvl_envmap_init(&plain, &e) == 0, "init");
    /* Euler XYZ (0.3, -0.5, 1.1) as Blender composes it: R = Rz Ry Rx. */
    double ax = 0.3, ay = -0.5, az = 1.1;
    double cx = cos(ax), sx = sin(ax), cy = cos(ay), sy = sin(ay), cz = cos(az), sz = sin(az);
    double m[9] = {cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx,
                   sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx,
                   -sy,     cy * sx,                cy * cx};
    memcpy(e.rotation, m, sizeof m);
    CHECK(dwvl_envmap_init(&turned, &e) == 0, "init");
    double worst = 0.0;
    for (int i = 0; i < 2000; ++i) {
        uint64_t key = dwvk_rng_key(7u, 0u, (uint64_t)i);
        double u1 = dwvk_rng_uniform_d(key, 0), u2 = dwvk_rng_uniform_d(key, 1);
        dwvu_vec3 d0, d1;
        double p0, p1;
        dwvl_envmap_sample(&plain, u1, u2, &d0, &p0);
        dwvl_envmap_sample(&turned, u1, u2, &d1, &p1);
        /* d0 = R d1 */
        dwvu_vec3 rd1 = dwvu_v(m[0] * d1.x + m[1] * d1.y + m[2] * d1.z, m[3] * d1.x + m[4] * d1.y + m[5] * d1.z,
                               m[6] * d1.x + m[7] * d1.y + m[8] * d1.z);
        worst = fmax(worst, dwvu_length(dwvu_sub(rd1, d0)));
        double a[3], b[3];
        dwvl_envmap_radiance(&plain, d0, a);
        dwvl_envmap_radiance(&turned, d1, b);
        CHECK(p0 == p1 && fabs(a[0] - b[0]) <= 1e-6 * (a[0] + 1e-3), "sample %d: pdf %g / %g, radiance %g / %g", i, p0,
              p1, a[0], b[0]);
    }
    CHECK(worst < 1e-12, "rotated samples differ by %.3g", worst);
    dwvl_envmap_free(&plain);
    dwvl_envmap_free(&turned);
}

/* Next-event estimation under a uniform map of radiance L equals the constant world L: the MIS
 * estimate of (1/pi) integral L cos over the hemisphere is L (no geometry: nothing shadows). The
 * bound is 5 standard errors of the mean of the samples. */
static void test_uniform_equals_constant(void)
{
    enum { W = 32, H = 16 };
    static float texels[3 * W * H];
    const double L[3] = {0.5, 0.25, 0.125};
    for (int i = 0; i < W * H; ++i)
        for (int k = 0; k < 3; ++k) texels[3 * i + k] = (float)L[k];
    dwv_environment_t e = environment(W, H, texels, DWV_ENVIRONMENT_LINEAR);
    dwvl_envmap map;
    CHECK(dwvl_envmap_init(&map, &e) == 0, "init");
    dwvl_environment env = {NULL, 0u, {0.0, 0.0, 0.0}, 1, NULL, &map};
    CHECK(dwvl_direct_pairs(&env) == 2u, "an envmap takes two pairs");
    dwvu_vec3 n = dwvu_normalize(dwvu_v(0.3, -0.2, 0.9));
    const uint64_t count = 200000u;
    double sum[3] = {0.0, 0.0, 0.0}, sum2[3] = {0.0, 0.0, 0.0};
    for (uint64_t i = 0; i < count; ++i) {
        dwvk_sampler sampler = {.key = dwvk_rng_key(11u, 0u, i), .index = 0u, .stratified = 0};
        double out[3];
        dwvl_direct(&env, dwvu_v(0.0, 0.0, 0.0), n, n, NULL, INFINITY, &sampler, 0u, out);
        for (int k = 0; k < 3; ++k) {
            sum[k] += out[k];
            sum2[k] += out[k] * out[k];
        }
    }
    for (int k = 0; k < 3; ++k) {
        double mean = sum[k] / count, se = sqrt((sum2[k] / count - mean * mean) / count);
        CHECK(fabs(mean - L[k]) < 5.0 * se + 1e-12, "channel %d: %.6f +- %.2g, want %.6f", k, mean, se, L[k]);
        printf("  uniform map, channel %d: %.6f +- %.2g (constant world %.6f)\n", k, mean, se, L[k]);
    }
    dwvl_envmap_free(&map);
}

int main(void)
{
    test_lookup_convention();
    test_interpolation();
    test_sample_against_pdf();
    test_rotation();
    test_uniform_equals_constant();
    return check_report("test_envmap");
}
