/* Argument validation of the sampling and random-number entry points: every bad argument gets
 * its result code (capi/dwivedi.h: NULL -> DWV_ERROR_NULL_POINTER, NaN or infinite ->
 * DWV_ERROR_INVALID_ARGUMENT, a number outside its range -> DWV_ERROR_OUT_OF_RANGE, a struct_size
 * too small -> DWV_ERROR_STRUCT_SIZE, a dwv_dwivedi_t that dwv_dwivedi_init cannot have made ->
 * DWV_ERROR_INVALID_ARGUMENT) and a message of its own: before each call a failing call with a
 * sentinel name sets the thread's message, and afterwards the message must be non-empty and new.
 * The edges of each domain are accepted. Public API only, no libm. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include <dwivedi.h>

#define SENTINEL "sentinel-no-such-method"

/* Sets the thread's message to one that names SENTINEL. */
static int arm(void)
{
    dwv_v0_method_t method;
    return dwv_v0_method_from_name(SENTINEL, &method);
}

static void expect(dwv_result_t got, dwv_result_t expected, const char *call, int line)
{
    const char *message = dwv_last_error_message();
    CHECK(got == expected, "line %d: %s returned %d (%s), expected %d (%s)", line, call, (int)got,
          dwv_result_string(got), (int)expected, dwv_result_string(expected));
    if (expected != DWV_SUCCESS)
        CHECK(message != NULL && message[0] != '\0' && strstr(message, SENTINEL) == NULL,
              "line %d: %s left no message of its own: \"%s\"", line, call, message != NULL ? message : "(null)");
}

/* The sentinel call runs before `call` (the comma operator sequences them). */
#define EXPECT(call, expected) expect((arm(), (call)), (expected), #call, __LINE__)

static const dwv_result_t NULLP = DWV_ERROR_NULL_POINTER, INVALID = DWV_ERROR_INVALID_ARGUMENT,
                          RANGE = DWV_ERROR_OUT_OF_RANGE, SIZE = DWV_ERROR_STRUCT_SIZE, OK = DWV_SUCCESS;

/* ---- dwv_dwivedi_init ----------------------------------------------------------------------- */

static void test_init(void)
{
    dwv_dwivedi_t dist = DWV_DWIVEDI_INIT;
    EXPECT(dwv_dwivedi_init(NULL, 0.5, DWV_V0_EXACT), NULLP);
    EXPECT(dwv_dwivedi_init(&dist, NAN, DWV_V0_EXACT), INVALID);
    EXPECT(dwv_dwivedi_init(&dist, INFINITY, DWV_V0_EXACT), INVALID);
    EXPECT(dwv_dwivedi_init(&dist, -INFINITY, DWV_V0_EXACT), INVALID);
    EXPECT(dwv_dwivedi_init(&dist, -1e-300, DWV_V0_EXACT), RANGE);
    EXPECT(dwv_dwivedi_init(&dist, 1.0 + 0x1p-52, DWV_V0_EXACT), RANGE);
    EXPECT(dwv_dwivedi_init(&dist, 0.5, -1), RANGE);
    EXPECT(dwv_dwivedi_init(&dist, 0.5, 4), RANGE);
    dwv_dwivedi_t zero = {0};
    EXPECT(dwv_dwivedi_init(&zero, 0.5, DWV_V0_EXACT), SIZE);
    dwv_dwivedi_t short_size = DWV_DWIVEDI_INIT;
    short_size.struct_size = (uint32_t)sizeof(dwv_dwivedi_t) - 1u;
    EXPECT(dwv_dwivedi_init(&short_size, 0.5, DWV_V0_EXACT), SIZE);
    /* Accepted: both ends of [0, 1], and a struct from a newer header (larger struct_size). */
    EXPECT(dwv_dwivedi_init(&dist, 0.0, DWV_V0_CASE), OK);
    EXPECT(dwv_dwivedi_init(&dist, 1.0, DWV_V0_DEON), OK);
    struct { dwv_dwivedi_t dist; double added_later[2]; } newer = {DWV_DWIVEDI_INIT, {0.0, 0.0}};
    newer.dist.struct_size = (uint32_t)sizeof newer;
    EXPECT(dwv_dwivedi_init(&newer.dist, 0.5, DWV_V0_FAST), OK);
    float u_f = 0.25f, cos_f;
    EXPECT(dwv_dwivedi_sample_f(&newer.dist, u_f, &cos_f), OK);
}

/* ---- per-event Dwivedi calls ---------------------------------------------------------------- */

/* All eight per-event calls on `dist` with valid other arguments must give `expected`. */
static void expect_all_calls(const dwv_dwivedi_t *dist, dwv_result_t expected, const char *what, int line)
{
    double x;
    float x_f;
    dwv_dwivedi_sample_t s = DWV_DWIVEDI_SAMPLE_INIT;
    dwv_dwivedi_sample_f_t s_f = DWV_DWIVEDI_SAMPLE_F_INIT;
    char call[160];
    snprintf(call, sizeof call, "dwv_dwivedi_sample(%s)", what);
    expect((arm(), dwv_dwivedi_sample(dist, 0.5, &x)), expected, call, line);
    snprintf(call, sizeof call, "dwv_dwivedi_pdf(%s)", what);
    expect((arm(), dwv_dwivedi_pdf(dist, 0.5, &x)), expected, call, line);
    snprintf(call, sizeof call, "dwv_dwivedi_sample_pdf(%s)", what);
    expect((arm(), dwv_dwivedi_sample_pdf(dist, 0.5, &s)), expected, call, line);
    snprintf(call, sizeof call, "dwv_dwivedi_stretch(%s)", what);
    expect((arm(), dwv_dwivedi_stretch(dist, 0.5, &x)), expected, call, line);
    snprintf(call, sizeof call, "dwv_dwivedi_sample_f(%s)", what);
    expect((arm(), dwv_dwivedi_sample_f(dist, 0.5f, &x_f)), expected, call, line);
    snprintf(call, sizeof call, "dwv_dwivedi_pdf_f(%s)", what);
    expect((arm(), dwv_dwivedi_pdf_f(dist, 0.5f, &x_f)), expected, call, line);
    snprintf(call, sizeof call, "dwv_dwivedi_sample_pdf_f(%s)", what);
    expect((arm(), dwv_dwivedi_sample_pdf_f(dist, 0.5f, &s_f)), expected, call, line);
    snprintf(call, sizeof call, "dwv_dwivedi_stretch_f(%s)", what);
    expect((arm(), dwv_dwivedi_stretch_f(dist, 0.5f, &x_f)), expected, call, line);
}

static void test_dwivedi_struct(void)
{
    dwv_dwivedi_t good = DWV_DWIVEDI_INIT;
    CHECK(dwv_dwivedi_init(&good, 0.8, DWV_V0_EXACT) == DWV_SUCCESS, "init: %s", dwv_last_error_message());
    expect_all_calls(&good, OK, "a valid dist", __LINE__);
    expect_all_calls(NULL, NULLP, "NULL", __LINE__);

    /* Never initialised: struct_size 0 (static or zeroed memory). */
    dwv_dwivedi_t zero = {0};
    expect_all_calls(&zero, SIZE, "struct_size 0", __LINE__);

    /* Garbage constants behind a valid struct_size: one field at a time, then whole bytes. */
    struct { const char *what; dwv_dwivedi_t dist; } garbage[13];
    for (int i = 0; i < 13; ++i) garbage[i].dist = good;
    garbage[0].what = "kappa NaN", garbage[0].dist.kappa = NAN;
    garbage[1].what = "kappa 1 (v = 1)", garbage[1].dist.kappa = 1.0;
    garbage[2].what = "kappa -0.5", garbage[2].dist.kappa = -0.5;
    garbage[3].what = "one_minus_kappa 0", garbage[3].dist.one_minus_kappa = 0.0;
    garbage[4].what = "one_minus_kappa 2", garbage[4].dist.one_minus_kappa = 2.0;
    garbage[5].what = "log_ratio infinite", garbage[5].dist.log_ratio = INFINITY;
    garbage[6].what = "log_ratio -1", garbage[6].dist.log_ratio = -1.0;
    garbage[7].what = "albedo_eff 0", garbage[7].dist.albedo_eff = 0.0;
    garbage[8].what = "albedo_eff NaN", garbage[8].dist.albedo_eff = NAN;
    garbage[9].what = "kappa_f NaN", garbage[9].dist.kappa_f = NAN;
    garbage[10].what = "one_minus_kappa_f 0", garbage[10].dist.one_minus_kappa_f = 0.0f;
    garbage[11].what = "log_ratio_f infinite", garbage[11].dist.log_ratio_f = INFINITY;
    garbage[12].what = "albedo_eff_f 2", garbage[12].dist.albedo_eff_f = 2.0f;
    for (int i = 0; i < 13; ++i) expect_all_calls(&garbage[i].dist, INVALID, garbage[i].what, __LINE__);
    const unsigned char patterns[] = {0xa5, 0xff, 0x7f, 0x3f};
    for (int i = 0; i < 4; ++i) {
        dwv_dwivedi_t bytes;
        memset(&bytes, patterns[i], sizeof bytes); /* struct_size huge, so only the constants can tell */
        char what[48];
        snprintf(what, sizeof what, "every byte 0x%02x", patterns[i]);
        expect_all_calls(&bytes, INVALID, what, __LINE__);
    }
}

static void test_dwivedi_arguments(void)
{
    dwv_dwivedi_t dist = DWV_DWIVEDI_INIT;
    CHECK(dwv_dwivedi_init(&dist, 0.8, DWV_V0_EXACT) == DWV_SUCCESS, "init: %s", dwv_last_error_message());
    double x;
    float x_f;
    dwv_dwivedi_sample_t s = DWV_DWIVEDI_SAMPLE_INIT, s_zero = {0};
    dwv_dwivedi_sample_f_t s_f = DWV_DWIVEDI_SAMPLE_F_INIT, s_f_zero = {0};

    /* NaN and infinities are invalid; the nearest numbers outside [0, 1] (u) or [-1, 1] (cos)
     * are out of range. */
    const dwv_result_t bad_result[] = {INVALID, INVALID, INVALID, RANGE, RANGE};
    const double bad_u[] = {NAN, INFINITY, -INFINITY, -0x1p-1074, 1.0 + 0x1p-52};
    const double bad_cos[] = {NAN, INFINITY, -INFINITY, -1.0 - 0x1p-52, 1.0 + 0x1p-52};
    const float bad_u_f[] = {NAN, INFINITY, -INFINITY, -0x1p-149f, 1.0f + 0x1p-23f};
    const float bad_cos_f[] = {NAN, INFINITY, -INFINITY, -1.0f - 0x1p-23f, 1.0f + 0x1p-23f};
    for (int i = 0; i < 5; ++i) {
        dwv_result_t r = bad_result[i];
        EXPECT(dwv_dwivedi_sample(&dist, bad_u[i], &x), r);
        EXPECT(dwv_dwivedi_sample_pdf(&dist, bad_u[i], &s), r);
        EXPECT(dwv_dwivedi_pdf(&dist, bad_cos[i], &x), r);
        EXPECT(dwv_dwivedi_stretch(&dist, bad_cos[i], &x), r);
        EXPECT(dwv_dwivedi_sample_f(&dist, bad_u_f[i], &x_f), r);
        EXPECT(dwv_dwivedi_sample_pdf_f(&dist, bad_u_f[i], &s_f), r);
        EXPECT(dwv_dwivedi_pdf_f(&dist, bad_cos_f[i], &x_f), r);
        EXPECT(dwv_dwivedi_stretch_f(&dist, bad_cos_f[i], &x_f), r);
    }
    EXPECT(dwv_dwivedi_sample(&dist, 0.5, NULL), NULLP);
    EXPECT(dwv_dwivedi_pdf(&dist, 0.5, NULL), NULLP);
    EXPECT(dwv_dwivedi_sample_pdf(&dist, 0.5, NULL), NULLP);
    EXPECT(dwv_dwivedi_stretch(&dist, 0.5, NULL), NULLP);
    EXPECT(dwv_dwivedi_sample_f(&dist, 0.5f, NULL), NULLP);
    EXPECT(dwv_dwivedi_pdf_f(&dist, 0.5f, NULL), NULLP);
    EXPECT(dwv_dwivedi_sample_pdf_f(&dist, 0.5f, NULL), NULLP);
    EXPECT(dwv_dwivedi_stretch_f(&dist, 0.5f, NULL), NULLP);
    EXPECT(dwv_dwivedi_sample_pdf(&dist, 0.5, &s_zero), SIZE);
    EXPECT(dwv_dwivedi_sample_pdf_f(&dist, 0.5f, &s_f_zero), SIZE);
    /* Accepted: u and cos at both ends, -0.0. */
    EXPECT(dwv_dwivedi_sample_pdf(&dist, 0.0, &s), OK);
    EXPECT(dwv_dwivedi_sample_pdf(&dist, 1.0, &s), OK);
    EXPECT(dwv_dwivedi_sample_pdf(&dist, -0.0, &s), OK);
    EXPECT(dwv_dwivedi_sample_pdf_f(&dist, 1.0f, &s_f), OK);
    EXPECT(dwv_dwivedi_pdf(&dist, -1.0, &x), OK);
    EXPECT(dwv_dwivedi_pdf(&dist, 1.0, &x), OK);
    EXPECT(dwv_dwivedi_stretch_f(&dist, -1.0f, &x_f), OK);
    EXPECT(dwv_dwivedi_stretch_f(&dist, 1.0f, &x_f), OK);
}

/* ---- phase functions ------------------------------------------------------------------------ */

static void test_phase(void)
{
    double x, y;
    float x_f;
    const double bad_g[] = {NAN, INFINITY, -INFINITY, 1.0, -1.0, 1.5, -1e300};
    const float bad_g_f[] = {NAN, INFINITY, -INFINITY, 1.0f, -1.0f, 1.5f, -1e30f};
    const dwv_result_t bad_g_result[] = {INVALID, INVALID, INVALID, RANGE, RANGE, RANGE, RANGE};
    for (int i = 0; i < 7; ++i) {
        double g = bad_g[i];
        dwv_result_t r = bad_g_result[i];
        EXPECT(dwv_hg_sample(g, 0.5, &x), r);
        EXPECT(dwv_hg_pdf(g, 0.5, &x), r);
        EXPECT(dwv_hg_sample_pdf(g, 0.5, &x, &y), r);
        EXPECT(dwv_hg_sample_f(bad_g_f[i], 0.5f, &x_f), r);
        EXPECT(dwv_hg_pdf_f(bad_g_f[i], 0.5f, &x_f), r);
    }
    const double bad_x[] = {NAN, INFINITY, -INFINITY};
    for (int i = 0; i < 3; ++i) {
        EXPECT(dwv_hg_sample(0.5, bad_x[i], &x), INVALID);
        EXPECT(dwv_hg_pdf(0.5, bad_x[i], &x), INVALID);
        EXPECT(dwv_hg_sample_pdf(0.5, bad_x[i], &x, &y), INVALID);
        EXPECT(dwv_hg_sample_f(0.5f, (float)bad_x[i], &x_f), INVALID);
        EXPECT(dwv_hg_pdf_f(0.5f, (float)bad_x[i], &x_f), INVALID);
        EXPECT(dwv_isotropic_sample(bad_x[i], &x), INVALID);
    }
    EXPECT(dwv_hg_sample(0.5, -0x1p-1074, &x), RANGE);
    EXPECT(dwv_hg_sample(0.5, 1.0 + 0x1p-52, &x), RANGE);
    EXPECT(dwv_hg_sample_pdf(0.5, 1.0 + 0x1p-52, &x, &y), RANGE);
    EXPECT(dwv_hg_sample_f(0.5f, 1.0f + 0x1p-23f, &x_f), RANGE);
    EXPECT(dwv_hg_pdf(0.5, 1.0 + 0x1p-52, &x), RANGE);
    EXPECT(dwv_hg_pdf(0.5, -1.0 - 0x1p-52, &x), RANGE);
    EXPECT(dwv_hg_pdf_f(0.5f, -1.0f - 0x1p-23f, &x_f), RANGE);
    EXPECT(dwv_isotropic_sample(-0x1p-1074, &x), RANGE);
    EXPECT(dwv_isotropic_sample(1.0 + 0x1p-52, &x), RANGE);
    EXPECT(dwv_hg_sample(0.5, 0.5, NULL), NULLP);
    EXPECT(dwv_hg_pdf(0.5, 0.5, NULL), NULLP);
    EXPECT(dwv_hg_sample_pdf(0.5, 0.5, NULL, &y), NULLP);
    EXPECT(dwv_hg_sample_pdf(0.5, 0.5, &x, NULL), NULLP);
    EXPECT(dwv_hg_sample_f(0.5f, 0.5f, NULL), NULLP);
    EXPECT(dwv_hg_pdf_f(0.5f, 0.5f, NULL), NULLP);
    EXPECT(dwv_isotropic_sample(0.5, NULL), NULLP);
    EXPECT(dwv_isotropic_pdf(NULL), NULLP);
    /* Accepted: |g| just below 1, u and cos at both ends. */
    EXPECT(dwv_hg_sample_pdf(1.0 - 0x1p-53, 1.0, &x, &y), OK);
    EXPECT(dwv_hg_sample_pdf(-(1.0 - 0x1p-53), 0.0, &x, &y), OK);
    EXPECT(dwv_hg_sample_f(1.0f - 0x1p-24f, 1.0f, &x_f), OK);
    EXPECT(dwv_hg_pdf_f(-(1.0f - 0x1p-24f), -1.0f, &x_f), OK);
}

/* ---- exponential ---------------------------------------------------------------------------- */

static void test_exponential(void)
{
    double x;
    float x_f;
    const double bad_sigma[] = {NAN, INFINITY, -INFINITY, 0.0, -0.0, -1.0};
    const dwv_result_t bad_sigma_result[] = {INVALID, INVALID, INVALID, RANGE, RANGE, RANGE};
    for (int i = 0; i < 6; ++i) {
        double sigma = bad_sigma[i];
        dwv_result_t r = bad_sigma_result[i];
        EXPECT(dwv_exponential_sample(sigma, 0.5, &x), r);
        EXPECT(dwv_exponential_pdf(sigma, 0.5, &x), r);
        EXPECT(dwv_exponential_sample_f((float)sigma, 0.5f, &x_f), r);
        EXPECT(dwv_exponential_pdf_f((float)sigma, 0.5f, &x_f), r);
    }
    EXPECT(dwv_exponential_sample(1.0, NAN, &x), INVALID);
    EXPECT(dwv_exponential_sample(1.0, INFINITY, &x), INVALID);
    EXPECT(dwv_exponential_sample(1.0, -0x1p-1074, &x), RANGE);
    EXPECT(dwv_exponential_sample(1.0, 1.0 + 0x1p-52, &x), RANGE);
    EXPECT(dwv_exponential_sample_f(1.0f, NAN, &x_f), INVALID);
    EXPECT(dwv_exponential_sample_f(1.0f, 1.0f + 0x1p-23f, &x_f), RANGE);
    EXPECT(dwv_exponential_pdf(1.0, NAN, &x), INVALID);
    EXPECT(dwv_exponential_pdf(1.0, INFINITY, &x), INVALID);
    EXPECT(dwv_exponential_pdf(1.0, -0x1p-1074, &x), RANGE);
    EXPECT(dwv_exponential_pdf_f(1.0f, -1.0f, &x_f), RANGE);
    EXPECT(dwv_exponential_pdf_f(1.0f, NAN, &x_f), INVALID);
    EXPECT(dwv_exponential_sample(1.0, 0.5, NULL), NULLP);
    EXPECT(dwv_exponential_pdf(1.0, 0.5, NULL), NULLP);
    EXPECT(dwv_exponential_sample_f(1.0f, 0.5f, NULL), NULLP);
    EXPECT(dwv_exponential_pdf_f(1.0f, 0.5f, NULL), NULLP);
    /* A sigma so small that the distance overflows (header: DWV_ERROR_OUT_OF_RANGE)... */
    EXPECT(dwv_exponential_sample(0x1p-1074, 0.5, &x), RANGE);
    EXPECT(dwv_exponential_sample_f(0x1p-149f, 0.5f, &x_f), RANGE);
    /* ...but not at u = 0, where the distance is 0; and u = 1 is accepted. */
    EXPECT(dwv_exponential_sample(0x1p-1074, 0.0, &x), OK);
    EXPECT(dwv_exponential_sample(1.0, 1.0, &x), OK);
    EXPECT(dwv_exponential_sample_f(1.0f, 1.0f, &x_f), OK);
    EXPECT(dwv_exponential_pdf(1.0, 0.0, &x), OK);
}

/* ---- random numbers ------------------------------------------------------------------------- */

static void test_random(void)
{
    EXPECT(dwv_random_u64(1, 2, 3, 4, NULL), NULLP);
    EXPECT(dwv_random_uniform(1, 2, 3, 4, NULL), NULLP);
    EXPECT(dwv_random_uniform_f(1, 2, 3, 4, NULL), NULLP);
    uint64_t value;
    double u;
    float u_f;
    /* Every counter is valid, the largest included. */
    EXPECT(dwv_random_u64(UINT64_MAX, UINT64_MAX, UINT64_MAX, UINT32_MAX, &value), OK);
    EXPECT(dwv_random_uniform(UINT64_MAX, UINT64_MAX, UINT64_MAX, UINT32_MAX, &u), OK);
    EXPECT(dwv_random_uniform_f(UINT64_MAX, UINT64_MAX, UINT64_MAX, UINT32_MAX, &u_f), OK);
}

int main(void)
{
    CHECK(arm() == DWV_ERROR_UNKNOWN_NAME && strstr(dwv_last_error_message(), SENTINEL) != NULL,
          "the sentinel call must fail with a message naming it: \"%s\"", dwv_last_error_message());
    test_init();
    test_dwivedi_struct();
    test_dwivedi_arguments();
    test_phase();
    test_exponential();
    test_random();
    return check_report("test_sampling_validation");
}
