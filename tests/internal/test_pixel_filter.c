/* Cycles' pixel filters for camera bakes (src/bake/pixel_filter.c; capi's dwv_pixel_filter_t):
 * - the sampler against the filter: for box, Gaussian and Blackman-Harris at several widths, the
 *   offsets dwvb_pixel_filter_sample draws from 4096 evenly spread uniforms lie where this test's
 *   own cumulative integral of capi's formula reaches those uniforms (to 3e-4: the table's linear
 *   interpolation), the draws are symmetric, they end at the filter's radius, and the density the
 *   sampler states (dwvb_pixel_filter_pdf) integrates to 1 and follows the normalised shape (to
 *   1% where the shape is above a quarter of its peak: beyond, a table level spans more of the
 *   tail than the shape is constant over, as in Cycles' 1024-level table);
 * - the bake: a lit white plane over the left half of an orthographic view, its edge on a pixel
 *   boundary, baked with each filter (no indirect light, so each sample is the plane's radiance or
 *   0): the pixels across the edge are the radiance times the filter's share beyond the edge at
 *   their centre (1 - F(d), F this test's cumulative integral), to 0.01; the box of one pixel gives
 *   exactly 1 and 0; 1 and 2 threads give the same bits;
 * - the options: an unknown filter, a width below 0.01, above 10 or NaN, and a nonzero reserved3
 *   are refused (and named); an options struct that ends before pixel_filter (an older header)
 *   bakes the box of one pixel, bit for bit, whatever lies past its end. Runs in about a second. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake/pixel_filter.h"
#include "bake_scenes.h"
#include "check.h"
#include <dwivedi.h>

#define PI 3.14159265358979323846
#define REFERENCE_STEPS 200000

/* capi's formulas, written out again here (not the library's functions). */
static double reference_radius(int kind, double w)
{
    return kind == DWV_PIXEL_FILTER_GAUSSIAN ? 1.5 * w : kind == DWV_PIXEL_FILTER_BLACKMAN_HARRIS ? w : 0.5 * w;
}

static double reference_shape(int kind, double w, double x)
{
    if (fabs(x) > reference_radius(kind, w)) return 0.0;
    if (kind == DWV_PIXEL_FILTER_GAUSSIAN) return exp(-8.0 * x * x / (w * w));
    if (kind == DWV_PIXEL_FILTER_BLACKMAN_HARRIS) {
        double t = 2.0 * PI * (x / (2.0 * w) + 0.5);
        return 0.35875 - 0.48829 * cos(t) + 0.14128 * cos(2.0 * t) - 0.01168 * cos(3.0 * t);
    }
    return 1.0;
}

/* The share of the filter below x (midpoint rule, REFERENCE_STEPS steps over the support). */
static double reference_cdf(int kind, double w, double x)
{
    double r = reference_radius(kind, w), h = 2.0 * r / REFERENCE_STEPS, below = 0.0, total = 0.0;
    for (int k = 0; k < REFERENCE_STEPS; ++k) {
        double m = -r + (k + 0.5) * h, f = reference_shape(kind, w, m);
        total += f;
        if (m + 0.5 * h <= x) below += f;
        else if (m - 0.5 * h < x) below += f * (x - (m - 0.5 * h)) / h;
    }
    return below / total;
}

static void test_sampler(int kind, double w)
{
    dwvb_pixel_filter filter;
    dwvb_pixel_filter_init(&filter, kind, w);
    double r = reference_radius(kind, w);
    double worst_cdf = 0.0, worst_symmetry = 0.0;
    for (int i = 0; i < 4096; i += 37) { /* every 37th of 4096 (the reference integral is slow) */
        double u = (i + 0.5) / 4096.0, x = dwvb_pixel_filter_sample(&filter, u);
        worst_cdf = fmax(worst_cdf, fabs(reference_cdf(kind, w, x) - u));
        worst_symmetry = fmax(worst_symmetry, fabs(x + dwvb_pixel_filter_sample(&filter, 1.0 - u)) / r);
    }
    double low = dwvb_pixel_filter_sample(&filter, 0.0), high = dwvb_pixel_filter_sample(&filter, 1.0 - 1e-16);
    double peak = reference_shape(kind, w, 0.0), total = 0.0;
    for (int k = 0; k < REFERENCE_STEPS; ++k) total += reference_shape(kind, w, -r + (k + 0.5) * 2.0 * r / REFERENCE_STEPS);
    total *= 2.0 * r / REFERENCE_STEPS;
    double integral = 0.0, worst_pdf = 0.0;
    for (int k = 0; k < 20000; ++k) {
        double x = -r + (k + 0.5) * 2.0 * r / 20000.0, p = dwvb_pixel_filter_pdf(&filter, x);
        integral += p * 2.0 * r / 20000.0;
        double f = reference_shape(kind, w, x);
        if (f > 0.25 * peak) worst_pdf = fmax(worst_pdf, fabs(p * total / f - 1.0));
    }
    printf("filter %d width %.2f: sampler vs reference cdf %.2g, symmetry %.2g, ends %.6f %.6f (radius %.4f), "
           "pdf integral %.6f, pdf vs shape %.3g\n", kind, w, worst_cdf, worst_symmetry, low, high, r, integral, worst_pdf);
    CHECK(worst_cdf < 3e-4, "filter %d width %g: the draws' distribution is %.3g off the filter's", kind, w, worst_cdf);
    CHECK(worst_symmetry < 1e-9, "filter %d width %g: draws not symmetric (%.3g)", kind, w, worst_symmetry);
    CHECK(fabs(low + r) < 1e-12 * r && fabs(high - r) < 1e-9 * r, "filter %d width %g: ends %.17g %.17g, radius %.17g",
          kind, w, low, high, r);
    CHECK(fabs(integral - 1.0) < 1e-3, "filter %d width %g: the pdf integrates to %.6f", kind, w, integral);
    CHECK(worst_pdf < 0.01, "filter %d width %g: the pdf is %.3g off the normalised shape", kind, w, worst_pdf);
}

/* A white Lambertian plane over x < 0 (the left half of a 2 m orthographic view, 32 x 4 pixels:
 * its edge between columns 15 and 16), lit by a sun from the camera's side; a black world. */
static dwv_scene_t *half_plane(void)
{
    dwv_scene_t *scene;
    if (dwv_scene_create(&scene) != DWV_SUCCESS) exit(2);
    dwv_material_t white = DWV_MATERIAL_INIT;
    white.kind = DWV_MATERIAL_DIFFUSE;
    test_mesh plane = test_box(-4.0, -4.0, -1.0, 0.0, 4.0, 0.0);
    test_add(scene, &plane, &white);
    test_mesh_free(&plane);
    dwv_light_desc_t sun = DWV_LIGHT_DESC_INIT;
    sun.strength = 3.0;
    sun.direction[2] = -1.0;
    dwv_camera_t camera = test_ortho_camera(0.0, 0.0, 3.0, 2.0);
    double black[3] = {0.0, 0.0, 0.0};
    if (dwv_scene_add_light(scene, &sun) || dwv_scene_set_world(scene, black, 1.0) ||
        dwv_scene_set_camera(scene, &camera) || dwv_scene_commit(scene)) {
        fprintf(stderr, "test scene: %s\n", dwv_last_error_message());
        exit(2);
    }
    return scene;
}

static dwv_bake_options_t edge_options(int kind, double w, uint32_t threads)
{
    dwv_bake_options_t o = DWV_BAKE_OPTIONS_INIT;
    o.width = 32;
    o.height = 4;
    o.samples = 1024;
    o.seed = 5;
    o.threads = threads;
    o.max_bounces = 0;
    o.pixel_filter = kind;
    o.filter_width = w;
    return o;
}

static dwv_image_t *bake(dwv_scene_t *scene, const dwv_bake_options_t *o)
{
    dwv_image_t *image = NULL;
    CHECK(dwv_bake(scene, o, &image) == DWV_SUCCESS, "bake: %s", dwv_last_error_message());
    return image;
}

static int same_bits(dwv_image_t *a, dwv_image_t *b)
{
    dwv_image_info_t ia = DWV_IMAGE_INFO_INIT, ib = DWV_IMAGE_INFO_INIT;
    dwv_image_info(a, &ia);
    dwv_image_info(b, &ib);
    return memcmp(ia.rgba, ib.rgba, 4u * ia.width * ia.height * sizeof(float)) == 0;
}

static void test_edge(dwv_scene_t *scene, int kind, double w)
{
    dwv_bake_options_t o = edge_options(kind, w, 1);
    dwv_image_t *image = bake(scene, &o);
    if (!image) return;
    dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
    dwv_image_info(image, &info);
    double lit = 0.0; /* the plane's radiance: columns far from the edge */
    for (uint32_t row = 0; row < 4; ++row) lit += info.rgba[4 * (row * 32 + 2)] / 4.0;
    double worst = 0.0;
    printf("filter %d width %.2f across the edge:", kind, w);
    for (uint32_t col = 10; col < 22; ++col) {
        double value = 0.0;
        for (uint32_t row = 0; row < 4; ++row) value += info.rgba[4 * (row * 32 + col)] / 4.0;
        /* The share of the filter about the pixel's centre col + 0.5 that lies left of 16. */
        double expected = reference_cdf(kind, w == 0.0 ? 1.0 : w, 16.0 - (col + 0.5));
        worst = fmax(worst, fabs(value / lit - expected));
        printf(" %.4f/%.4f", value / lit, expected);
    }
    printf("\n");
    CHECK(lit > 0.1, "filter %d: the plane is not lit (%g)", kind, lit);
    CHECK(worst < 0.01, "filter %d width %g: pixels across the edge %.3g off the filter's share", kind, w, worst);
    if (kind == DWV_PIXEL_FILTER_BOX && (w == 1.0 || w == 0.0)) {
        double left = info.rgba[4 * 15] / lit, right = info.rgba[4 * 16];
        CHECK(fabs(left - 1.0) < 1e-6 && right == 0.0, "the box of one pixel: %.9f, %g beside the edge", left, right);
    }
    dwv_image_release(image);
}

static void test_options(dwv_scene_t *scene)
{
    struct { int kind; double width; uint32_t reserved3; dwv_result_t expected; const char *named; } bad[] = {
        {3, 1.5, 0u, DWV_ERROR_INVALID_ARGUMENT, "pixel_filter 3 is not known (0 box, 1 gaussian or 2 blackman_harris)"},
        {-1, 1.5, 0u, DWV_ERROR_INVALID_ARGUMENT, "pixel_filter -1 is not known (0 box"},
        {DWV_PIXEL_FILTER_GAUSSIAN, 0.005, 0u, DWV_ERROR_OUT_OF_RANGE, "filter_width"},
        {DWV_PIXEL_FILTER_GAUSSIAN, 10.5, 0u, DWV_ERROR_OUT_OF_RANGE, "filter_width"},
        {DWV_PIXEL_FILTER_BOX, NAN, 0u, DWV_ERROR_OUT_OF_RANGE, "filter_width"},
        {DWV_PIXEL_FILTER_BOX, -1.0, 0u, DWV_ERROR_OUT_OF_RANGE, "filter_width"},
        {DWV_PIXEL_FILTER_BOX, 1.0, 1u, DWV_ERROR_INVALID_ARGUMENT, "reserved3"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        dwv_bake_options_t o = edge_options(bad[i].kind, bad[i].width, 1);
        o.reserved3 = bad[i].reserved3;
        o.samples = 2;
        dwv_image_t *image = NULL;
        dwv_result_t r = dwv_bake(scene, &o, &image);
        CHECK(r == bad[i].expected && image == NULL && strstr(dwv_last_error_message(), bad[i].named),
              "case %zu: result %d, message '%s'", i, (int)r, dwv_last_error_message());
        if (image) dwv_image_release(image);
    }
    /* An older header's struct: pixel_filter and filter_width lie past its end. */
    dwv_bake_options_t older = edge_options(DWV_PIXEL_FILTER_BLACKMAN_HARRIS, 1.5, 1);
    older.struct_size = (uint32_t)offsetof(dwv_bake_options_t, pixel_filter);
    older.samples = 64;
    dwv_bake_options_t unit_box = edge_options(DWV_PIXEL_FILTER_BOX, 1.0, 1);
    unit_box.samples = 64;
    dwv_image_t *a = bake(scene, &older), *b = bake(scene, &unit_box);
    if (a && b) CHECK(same_bits(a, b), "an older options struct does not bake the box of one pixel");
    if (a) dwv_image_release(a);
    if (b) dwv_image_release(b);
    /* 1 and 2 threads: the same bits. */
    dwv_bake_options_t one = edge_options(DWV_PIXEL_FILTER_BLACKMAN_HARRIS, 1.5, 1), two = one;
    two.threads = 2;
    one.samples = two.samples = 64;
    a = bake(scene, &one);
    b = bake(scene, &two);
    if (a && b) CHECK(same_bits(a, b), "Blackman-Harris: 1 and 2 threads differ");
    if (a) dwv_image_release(a);
    if (b) dwv_image_release(b);
}

int main(void)
{
    const double widths[] = {0.5, 1.5, 4.0};
    for (int kind = DWV_PIXEL_FILTER_BOX; kind <= DWV_PIXEL_FILTER_BLACKMAN_HARRIS; ++kind)
        for (int k = 0; k < 3; ++k) test_sampler(kind, widths[k]);
    dwv_scene_t *scene = half_plane();
    test_edge(scene, DWV_PIXEL_FILTER_BOX, 1.0);
    test_edge(scene, DWV_PIXEL_FILTER_BOX, 0.0);
    test_edge(scene, DWV_PIXEL_FILTER_BOX, 2.5);
    test_edge(scene, DWV_PIXEL_FILTER_GAUSSIAN, 1.5);
    test_edge(scene, DWV_PIXEL_FILTER_BLACKMAN_HARRIS, 1.5);
    test_edge(scene, DWV_PIXEL_FILTER_BLACKMAN_HARRIS, 3.0);
    test_options(scene);
    dwv_scene_release(scene);
    return check_report("test_pixel_filter");
}
