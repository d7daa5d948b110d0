/* Hostile input on every implemented entry point of capi/dwivedi.h (kernels, walks, estimates,
 * images): NULL pointers, NaN, infinities, negatives, subnormals, out-of-range enums, struct_size
 * 0 / short / garbage, overwritten structs, absurd sizes (walks 10^13, 2^64 - 1, 10^6 x 10^6
 * images, 2^32 - 1 patches). Required of every call (capi/dwivedi.h, "Results and errors"):
 *   - no crash, no hang, no huge allocation (ASan and valgrind run this test too);
 *   - a refused call returns the documented code (NULL -> DWV_ERROR_NULL_POINTER, NaN or infinite
 *     -> DWV_ERROR_INVALID_ARGUMENT, a number outside its range or an unknown enumerator ->
 *     DWV_ERROR_OUT_OF_RANGE, struct_size too small -> DWV_ERROR_STRUCT_SIZE) with a message of
 *     its own (a primer call leaves a known message first; afterwards the message must be
 *     non-empty, new, and name the function);
 *   - an accepted call writes finite outputs in their documented ranges.
 * Beside the hand-written cases, each double argument of the kernels sweeps a list of hostile
 * values with the others valid: accepted or refused-with-message, never NaN out.
 * Public API only. */
#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api_checks.h"
#include "check.h"
#include <dwivedi.h>

static const dwv_result_t NULLP = DWV_ERROR_NULL_POINTER, INVALID = DWV_ERROR_INVALID_ARGUMENT,
                          RANGE = DWV_ERROR_OUT_OF_RANGE, SIZE = DWV_ERROR_STRUCT_SIZE,
                          STATE = DWV_ERROR_INVALID_STATE, NAME = DWV_ERROR_UNKNOWN_NAME;

/* The refused call returned `expected` and left a fresh message naming `function`. */
static void expect_refused(dwv_result_t got, dwv_result_t expected, const char *function, const char *call, int line)
{
    CHECK(got == expected && fresh_message_with(function),
          "line %d: %s returned %d (%s), expected %d (%s); message '%s' should name %s", line, call, (int)got,
          dwv_result_string(got), (int)expected, dwv_result_string(expected), dwv_last_error_message(), function);
}
#define REFUSED(function, call, expected) expect_refused((prime_message(), (call)), (expected), #function, #call, __LINE__)

/* Accepted or refused, never silently wrong: refused calls have a known code and a fresh message. */
static int accepted_or_explained(dwv_result_t got, const char *what, int line)
{
    if (got == DWV_SUCCESS) return 1;
    CHECK(got > 0 && got <= DWV_ERROR_FORMAT && fresh_message_with("dwv_"), "line %d: %s: code %d, message '%s'", line,
          what, (int)got, dwv_last_error_message());
    return 0;
}

static const double hostile[] = {NAN, -NAN, INFINITY, -INFINITY, -0.0, 0.0, 4.9406564584124654e-324,
                                  -4.9406564584124654e-324, DBL_MIN, DBL_MAX, -DBL_MAX, -1.0, -1e-300,
                                  1.0 + DBL_EPSILON, -1.0 - DBL_EPSILON, 1e300, -1e300, 2.0, 0.5, 1.0};
#define HOSTILE_COUNT ((int)(sizeof hostile / sizeof hostile[0]))

/* ---- names, versions, results ------------------------------------------------------------------ */

static void test_names(void)
{
    static const int32_t enums[] = {INT32_MIN, -1, 4, 7, 100, INT32_MAX};
    for (size_t i = 0; i < sizeof enums / sizeof enums[0]; ++i) {
        const char *s = dwv_result_string(enums[i]);
        CHECK(s != NULL && s[0] != '\0', "dwv_result_string(%d) is empty", (int)enums[i]);
        CHECK(enums[i] < 4 || enums[i] > 3 ? 1 : 0, "unreachable");
        if (enums[i] < 0 || enums[i] > 3) CHECK(dwv_v0_method_name(enums[i]) == NULL, "v0 method %d has a name", (int)enums[i]);
        if (enums[i] < 0 || enums[i] > 7) CHECK(dwv_technique_name(enums[i]) == NULL, "technique %d has a name", (int)enums[i]);
    }
    CHECK(dwv_version() == DWV_VERSION && dwv_version_string() != NULL, "version");
    dwv_v0_method_t method = 0;
    dwv_technique_t technique = 0;
    REFUSED(dwv_v0_method_from_name, dwv_v0_method_from_name(NULL, &method), NULLP);
    REFUSED(dwv_v0_method_from_name, dwv_v0_method_from_name("exact", NULL), NULLP);
    REFUSED(dwv_v0_method_from_name, dwv_v0_method_from_name("", &method), NAME);
    REFUSED(dwv_technique_from_name, dwv_technique_from_name(NULL, &technique), NULLP);
    REFUSED(dwv_technique_from_name, dwv_technique_from_name("auto", NULL), NULLP);
    REFUSED(dwv_technique_from_name, dwv_technique_from_name("AUTO", &technique), NAME);
    REFUSED(dwv_technique_from_name, dwv_technique_from_name("auto ", &technique), NAME);
    /* A megabyte-long name and invalid UTF-8: refused, and the message stays bounded. */
    size_t long_size = 1u << 20;
    char *long_name = malloc(long_size);
    CHECK(long_name != NULL, "malloc");
    if (long_name) {
        memset(long_name, 'x', long_size - 1);
        long_name[long_size - 1] = '\0';
        REFUSED(dwv_technique_from_name, dwv_technique_from_name(long_name, &technique), NAME);
        CHECK(strlen(dwv_last_error_message()) < 1024, "message of %zu bytes", strlen(dwv_last_error_message()));
        REFUSED(dwv_v0_method_from_name, dwv_v0_method_from_name(long_name, &method), NAME);
        free(long_name);
    }
    REFUSED(dwv_v0_method_from_name, dwv_v0_method_from_name("\xff\xfe\xc3\x28%s%n", &method), NAME);
}

/* ---- diffusion length and eigenfunction -------------------------------------------------------- */

static void test_diffusion_length(void)
{
    dwv_diffusion_length_t out = DWV_DIFFUSION_LENGTH_INIT;
    REFUSED(dwv_diffusion_length, dwv_diffusion_length(0.5, DWV_V0_EXACT, NULL), NULLP);
    REFUSED(dwv_diffusion_length, dwv_diffusion_length(NAN, DWV_V0_EXACT, &out), INVALID);
    REFUSED(dwv_diffusion_length, dwv_diffusion_length(INFINITY, DWV_V0_EXACT, &out), INVALID);
    REFUSED(dwv_diffusion_length, dwv_diffusion_length(-INFINITY, DWV_V0_EXACT, &out), INVALID);
    REFUSED(dwv_diffusion_length, dwv_diffusion_length(-1e-300, DWV_V0_EXACT, &out), RANGE);
    REFUSED(dwv_diffusion_length, dwv_diffusion_length(1.0 + DBL_EPSILON, DWV_V0_EXACT, &out), RANGE);
    REFUSED(dwv_diffusion_length, dwv_diffusion_length(0.5, -1, &out), RANGE);
    REFUSED(dwv_diffusion_length, dwv_diffusion_length(0.5, 4, &out), RANGE);
    REFUSED(dwv_diffusion_length, dwv_diffusion_length(0.5, INT32_MIN, &out), RANGE);
    REFUSED(dwv_diffusion_length, dwv_diffusion_length(0.5, INT32_MAX, &out), RANGE);
    out.struct_size = 0u;
    REFUSED(dwv_diffusion_length, dwv_diffusion_length(0.5, DWV_V0_EXACT, &out), SIZE);
    out.struct_size = (uint32_t)sizeof out - 1u;
    REFUSED(dwv_diffusion_length, dwv_diffusion_length(0.5, DWV_V0_EXACT, &out), SIZE);

    double phi = 0.0, integral = 0.0;
    REFUSED(dwv_eigenfunction, dwv_eigenfunction(0.5, 2.0, 0.0, NULL), NULLP);
    REFUSED(dwv_eigenfunction, dwv_eigenfunction(0.5, NAN, 0.0, &phi), INVALID);
    REFUSED(dwv_eigenfunction, dwv_eigenfunction(0.5, 1.0, 0.0, &phi), RANGE);
    REFUSED(dwv_eigenfunction, dwv_eigenfunction(0.5, -1.0, 0.0, &phi), RANGE);
    REFUSED(dwv_eigenfunction, dwv_eigenfunction(0.5, 0.0, 0.0, &phi), RANGE);
    REFUSED(dwv_eigenfunction, dwv_eigenfunction(0.5, 2.0, NAN, &phi), INVALID);
    REFUSED(dwv_eigenfunction, dwv_eigenfunction(0.5, 2.0, 1.0 + DBL_EPSILON, &phi), RANGE);
    REFUSED(dwv_eigenfunction, dwv_eigenfunction(-0.5, 2.0, 0.0, &phi), RANGE);
    REFUSED(dwv_eigenfunction_integral, dwv_eigenfunction_integral(0.5, 2.0, NULL), NULLP);
    REFUSED(dwv_eigenfunction_integral, dwv_eigenfunction_integral(0.5, -NAN, &integral), INVALID);
    REFUSED(dwv_eigenfunction_integral, dwv_eigenfunction_integral(0.5, 0.999, &integral), RANGE);
    REFUSED(dwv_eigenfunction_integral, dwv_eigenfunction_integral(INFINITY, 2.0, &integral), INVALID);

    /* Sweeps: albedo x method, and the eigenfunction's v and mu. */
    for (int i = 0; i < HOSTILE_COUNT; ++i) {
        for (dwv_v0_method_t m = DWV_V0_EXACT; m <= DWV_V0_FAST; ++m) {
            dwv_diffusion_length_t d = DWV_DIFFUSION_LENGTH_INIT;
            prime_message();
            if (accepted_or_explained(dwv_diffusion_length(hostile[i], m, &d), "dwv_diffusion_length", __LINE__))
                CHECK(d.kappa >= 0.0 && d.kappa <= 1.0 && d.one_minus_kappa >= 0.0 && d.one_minus_kappa <= 1.0 &&
                          d.v0 >= 1.0 && !isnan(d.log_ratio) && d.log_ratio >= 0.0 && !isnan(d.log_one_minus_kappa),
                      "diffusion length albedo %g method %d: kappa %g 1-kappa %g v0 %g L %g", hostile[i], (int)m, d.kappa,
                      d.one_minus_kappa, d.v0, d.log_ratio);
        }
        for (int j = 0; j < HOSTILE_COUNT; ++j) {
            prime_message();
            phi = NAN;
            if (accepted_or_explained(dwv_eigenfunction(0.9, hostile[i], hostile[j], &phi), "dwv_eigenfunction", __LINE__))
                CHECK(isfinite(phi) && phi >= 0.0, "eigenfunction v %g mu %g: %g", hostile[i], hostile[j], phi);
        }
        prime_message();
        integral = NAN;
        if (accepted_or_explained(dwv_eigenfunction_integral(0.9, hostile[i], &integral), "dwv_eigenfunction_integral",
                                  __LINE__))
            CHECK(isfinite(integral) && integral >= 0.0, "eigenfunction integral v %g: %g", hostile[i], integral);
    }
}

/* ---- Dwivedi sampling -------------------------------------------------------------------------- */

/* Every per-event call on `dist` refuses with `code`. */
static void all_dwivedi_calls_refuse(const dwv_dwivedi_t *dist, dwv_result_t code, const char *what)
{
    double x = 0.0;
    float xf = 0.0f;
    dwv_dwivedi_sample_t s = DWV_DWIVEDI_SAMPLE_INIT;
    dwv_dwivedi_sample_f_t sf = DWV_DWIVEDI_SAMPLE_F_INIT;
    dwv_result_t got[8];
    const char *names[8] = {"sample", "pdf", "sample_pdf", "stretch", "sample_f", "pdf_f", "sample_pdf_f", "stretch_f"};
    prime_message(), got[0] = dwv_dwivedi_sample(dist, 0.5, &x);
    CHECK(fresh_message_with("dwv_dwivedi_sample"), "%s: %s message '%s'", what, names[0], dwv_last_error_message());
    prime_message(), got[1] = dwv_dwivedi_pdf(dist, 0.5, &x);
    CHECK(fresh_message_with("dwv_dwivedi_pdf"), "%s: %s message '%s'", what, names[1], dwv_last_error_message());
    prime_message(), got[2] = dwv_dwivedi_sample_pdf(dist, 0.5, &s);
    CHECK(fresh_message_with("dwv_dwivedi_sample_pdf"), "%s: %s message", what, names[2]);
    prime_message(), got[3] = dwv_dwivedi_stretch(dist, 0.5, &x);
    CHECK(fresh_message_with("dwv_dwivedi_stretch"), "%s: %s message", what, names[3]);
    prime_message(), got[4] = dwv_dwivedi_sample_f(dist, 0.5f, &xf);
    CHECK(fresh_message_with("dwv_dwivedi_sample_f"), "%s: %s message", what, names[4]);
    prime_message(), got[5] = dwv_dwivedi_pdf_f(dist, 0.5f, &xf);
    CHECK(fresh_message_with("dwv_dwivedi_pdf_f"), "%s: %s message", what, names[5]);
    prime_message(), got[6] = dwv_dwivedi_sample_pdf_f(dist, 0.5f, &sf);
    CHECK(fresh_message_with("dwv_dwivedi_sample_pdf_f"), "%s: %s message", what, names[6]);
    prime_message(), got[7] = dwv_dwivedi_stretch_f(dist, 0.5f, &xf);
    CHECK(fresh_message_with("dwv_dwivedi_stretch_f"), "%s: %s message", what, names[7]);
    for (int i = 0; i < 8; ++i)
        CHECK(got[i] == code, "%s: dwv_dwivedi_%s returned %d (%s), expected %d", what, names[i], (int)got[i],
              dwv_result_string(got[i]), (int)code);
}

static void test_dwivedi(void)
{
    dwv_dwivedi_t dist = DWV_DWIVEDI_INIT;
    REFUSED(dwv_dwivedi_init, dwv_dwivedi_init(NULL, 0.5, DWV_V0_EXACT), NULLP);
    REFUSED(dwv_dwivedi_init, dwv_dwivedi_init(&dist, NAN, DWV_V0_EXACT), INVALID);
    REFUSED(dwv_dwivedi_init, dwv_dwivedi_init(&dist, 1.5, DWV_V0_EXACT), RANGE);
    REFUSED(dwv_dwivedi_init, dwv_dwivedi_init(&dist, 0.5, 99), RANGE);
    dist.struct_size = 3u;
    REFUSED(dwv_dwivedi_init, dwv_dwivedi_init(&dist, 0.5, DWV_V0_EXACT), SIZE);

    all_dwivedi_calls_refuse(NULL, NULLP, "NULL dist");
    dwv_dwivedi_t garbage;
    memset(&garbage, 0xff, sizeof garbage); /* struct_size 2^32 - 1, every double NaN */
    all_dwivedi_calls_refuse(&garbage, INVALID, "0xff bytes");
    memset(&garbage, 0, sizeof garbage);
    all_dwivedi_calls_refuse(&garbage, SIZE, "zero bytes");
    garbage.struct_size = (uint32_t)sizeof garbage;
    all_dwivedi_calls_refuse(&garbage, INVALID, "zero constants");
    dwv_dwivedi_t tampered = DWV_DWIVEDI_INIT;
    CHECK(dwv_dwivedi_init(&tampered, 0.9, DWV_V0_EXACT) == DWV_SUCCESS, "init");
    tampered.kappa = INFINITY;
    all_dwivedi_calls_refuse(&tampered, INVALID, "kappa infinite");
    CHECK(dwv_dwivedi_init(&tampered, 0.9, DWV_V0_EXACT) == DWV_SUCCESS, "init");
    tampered.log_ratio_f = NAN;
    all_dwivedi_calls_refuse(&tampered, INVALID, "log_ratio_f NaN");

    dist = (dwv_dwivedi_t)DWV_DWIVEDI_INIT;
    CHECK(dwv_dwivedi_init(&dist, 0.99, DWV_V0_FAST) == DWV_SUCCESS, "init");
    double x = 0.0;
    float xf = 0.0f;
    dwv_dwivedi_sample_t s = DWV_DWIVEDI_SAMPLE_INIT;
    dwv_dwivedi_sample_f_t sf = DWV_DWIVEDI_SAMPLE_F_INIT;
    REFUSED(dwv_dwivedi_sample, dwv_dwivedi_sample(&dist, 0.5, NULL), NULLP);
    REFUSED(dwv_dwivedi_sample_pdf, dwv_dwivedi_sample_pdf(&dist, 0.5, NULL), NULLP);
    REFUSED(dwv_dwivedi_sample_pdf_f, dwv_dwivedi_sample_pdf_f(&dist, 0.5f, NULL), NULLP);
    REFUSED(dwv_dwivedi_pdf_f, dwv_dwivedi_pdf_f(&dist, 0.5f, NULL), NULLP);
    REFUSED(dwv_dwivedi_stretch_f, dwv_dwivedi_stretch_f(&dist, 0.5f, NULL), NULLP);
    s.struct_size = 0u;
    REFUSED(dwv_dwivedi_sample_pdf, dwv_dwivedi_sample_pdf(&dist, 0.5, &s), SIZE);
    sf.struct_size = 4u;
    REFUSED(dwv_dwivedi_sample_pdf_f, dwv_dwivedi_sample_pdf_f(&dist, 0.5f, &sf), SIZE);
    s.struct_size = (uint32_t)sizeof s;
    sf.struct_size = (uint32_t)sizeof sf;

    /* Sweeps of u and mu through every call, double and float. */
    for (int i = 0; i < HOSTILE_COUNT; ++i) {
        double h = hostile[i];
        float hf = (float)h;
        prime_message();
        if (accepted_or_explained(dwv_dwivedi_sample(&dist, h, &x), "dwivedi_sample", __LINE__))
            CHECK(x >= -1.0 && x <= 1.0, "sample(u %g) = %g", h, x);
        prime_message();
        if (accepted_or_explained(dwv_dwivedi_pdf(&dist, h, &x), "dwivedi_pdf", __LINE__))
            CHECK(x > 0.0 && isfinite(x), "pdf(mu %g) = %g", h, x);
        prime_message();
        if (accepted_or_explained(dwv_dwivedi_sample_pdf(&dist, h, &s), "dwivedi_sample_pdf", __LINE__))
            CHECK(s.cos_theta >= -1.0 && s.cos_theta <= 1.0 && s.pdf > 0.0 && isfinite(s.pdf) && s.stretch > 0.0 &&
                      s.stretch <= 2.0, "sample_pdf(u %g): cos %g pdf %g stretch %g", h, s.cos_theta, s.pdf, s.stretch);
        prime_message();
        if (accepted_or_explained(dwv_dwivedi_stretch(&dist, h, &x), "dwivedi_stretch", __LINE__))
            CHECK(x > 0.0 && x <= 2.0, "stretch(mu %g) = %g", h, x);
        prime_message();
        if (accepted_or_explained(dwv_dwivedi_sample_f(&dist, hf, &xf), "dwivedi_sample_f", __LINE__))
            CHECK(xf >= -1.0f && xf <= 1.0f, "sample_f(u %g) = %g", (double)hf, (double)xf);
        prime_message();
        if (accepted_or_explained(dwv_dwivedi_pdf_f(&dist, hf, &xf), "dwivedi_pdf_f", __LINE__))
            CHECK(xf > 0.0f && isfinite(xf), "pdf_f(mu %g) = %g", (double)hf, (double)xf);
        prime_message();
        if (accepted_or_explained(dwv_dwivedi_sample_pdf_f(&dist, hf, &sf), "dwivedi_sample_pdf_f", __LINE__))
            CHECK(sf.cos_theta >= -1.0f && sf.cos_theta <= 1.0f && sf.pdf > 0.0f && isfinite(sf.pdf) &&
                      sf.stretch > 0.0f && sf.stretch <= 2.0f, "sample_pdf_f(u %g)", (double)hf);
        prime_message();
        if (accepted_or_explained(dwv_dwivedi_stretch_f(&dist, hf, &xf), "dwivedi_stretch_f", __LINE__))
            CHECK(xf > 0.0f && xf <= 2.0f, "stretch_f(mu %g) = %g", (double)hf, (double)xf);
    }
}

/* ---- phase functions, free flights, random numbers --------------------------------------------- */

static void test_classical(void)
{
    double x = 0.0, y = 0.0;
    float xf = 0.0f;
    REFUSED(dwv_isotropic_sample, dwv_isotropic_sample(0.5, NULL), NULLP);
    REFUSED(dwv_isotropic_sample, dwv_isotropic_sample(NAN, &x), INVALID);
    REFUSED(dwv_isotropic_sample, dwv_isotropic_sample(-0.5, &x), RANGE);
    REFUSED(dwv_isotropic_pdf, dwv_isotropic_pdf(NULL), NULLP);
    REFUSED(dwv_hg_sample, dwv_hg_sample(1.0, 0.5, &x), RANGE);
    REFUSED(dwv_hg_sample, dwv_hg_sample(-1.0, 0.5, &x), RANGE);
    REFUSED(dwv_hg_sample, dwv_hg_sample(NAN, 0.5, &x), INVALID);
    REFUSED(dwv_hg_sample, dwv_hg_sample(0.5, 0.5, NULL), NULLP);
    REFUSED(dwv_hg_pdf, dwv_hg_pdf(0.5, 2.0, &x), RANGE);
    REFUSED(dwv_hg_pdf, dwv_hg_pdf(0.5, 0.5, NULL), NULLP);
    REFUSED(dwv_hg_pdf, dwv_hg_sample_pdf(0.5, 0.5, &x, NULL), NULLP);
    REFUSED(dwv_hg_sample, dwv_hg_sample_pdf(0.5, 0.5, NULL, &y), NULLP);
    REFUSED(dwv_hg_sample_f, dwv_hg_sample_f(1.0f, 0.5f, &xf), RANGE);
    REFUSED(dwv_hg_sample_f, dwv_hg_sample_f(0.5f, 0.5f, NULL), NULLP);
    REFUSED(dwv_hg_pdf_f, dwv_hg_pdf_f(-INFINITY, 0.5f, &xf), INVALID);
    REFUSED(dwv_exponential_sample, dwv_exponential_sample(0.0, 0.5, &x), RANGE);
    REFUSED(dwv_exponential_sample, dwv_exponential_sample(-1.0, 0.5, &x), RANGE);
    REFUSED(dwv_exponential_sample, dwv_exponential_sample(INFINITY, 0.5, &x), INVALID);
    REFUSED(dwv_exponential_sample, dwv_exponential_sample(4.9406564584124654e-324, 0.999, &x), RANGE);
    REFUSED(dwv_exponential_sample, dwv_exponential_sample(1.0, 0.5, NULL), NULLP);
    REFUSED(dwv_exponential_pdf, dwv_exponential_pdf(1.0, -1.0, &x), RANGE);
    REFUSED(dwv_exponential_pdf, dwv_exponential_pdf(1.0, NAN, &x), INVALID);
    REFUSED(dwv_exponential_pdf, dwv_exponential_pdf(1.0, INFINITY, &x), INVALID);
    REFUSED(dwv_exponential_sample_f, dwv_exponential_sample_f(1e-45f, 0.999f, &xf), RANGE);
    REFUSED(dwv_exponential_sample_f, dwv_exponential_sample_f(1.0f, 0.5f, NULL), NULLP);
    REFUSED(dwv_exponential_pdf_f, dwv_exponential_pdf_f(0.0f, 1.0f, &xf), RANGE);
    REFUSED(dwv_random_u64, dwv_random_u64(0, 0, 0, 0, NULL), NULLP);
    REFUSED(dwv_random_uniform, dwv_random_uniform(UINT64_MAX, UINT64_MAX, UINT64_MAX, UINT32_MAX, NULL), NULLP);
    REFUSED(dwv_random_uniform_f, dwv_random_uniform_f(0, 0, 0, 0, NULL), NULLP);
    float uf = 2.0f;
    CHECK(dwv_random_uniform_f(UINT64_MAX, UINT64_MAX, UINT64_MAX, UINT32_MAX, &uf) == DWV_SUCCESS && uf >= 0.0f &&
              uf < 1.0f, "random_uniform_f at the counters' ends: %g", (double)uf);

    /* Sweeps: each argument of each call through the hostile values, the other one valid. */
    for (int i = 0; i < HOSTILE_COUNT; ++i) {
        double h = hostile[i];
        float hf = (float)h;
        for (int j = 0; j < HOSTILE_COUNT; ++j) {
            double k = hostile[j];
            float kf = (float)k;
            prime_message();
            if (accepted_or_explained(dwv_hg_sample_pdf(h, k, &x, &y), "hg_sample_pdf", __LINE__))
                CHECK(x >= -1.0 && x <= 1.0 && y > 0.0 && isfinite(y), "hg g %g u %g: cos %g pdf %g", h, k, x, y);
            prime_message();
            if (accepted_or_explained(dwv_hg_pdf(h, k, &y), "hg_pdf", __LINE__))
                CHECK(y > 0.0 && isfinite(y), "hg_pdf g %g cos %g: %g", h, k, y);
            prime_message();
            if (accepted_or_explained(dwv_hg_sample_f(hf, kf, &xf), "hg_sample_f", __LINE__))
                CHECK(xf >= -1.0f && xf <= 1.0f, "hg_f g %g u %g: %g", (double)hf, (double)kf, (double)xf);
            prime_message();
            if (accepted_or_explained(dwv_hg_pdf_f(hf, kf, &xf), "hg_pdf_f", __LINE__))
                CHECK(xf > 0.0f && isfinite(xf), "hg_pdf_f g %g cos %g: %g", (double)hf, (double)kf, (double)xf);
            prime_message();
            if (accepted_or_explained(dwv_exponential_sample(h, k, &x), "exponential_sample", __LINE__))
                CHECK(x >= 0.0 && isfinite(x), "exponential sigma %g u %g: %g", h, k, x);
            prime_message();
            if (accepted_or_explained(dwv_exponential_pdf(h, k, &x), "exponential_pdf", __LINE__))
                CHECK(x >= 0.0 && isfinite(x), "exponential_pdf sigma %g t %g: %g", h, k, x);
            prime_message();
            if (accepted_or_explained(dwv_exponential_sample_f(hf, kf, &xf), "exponential_sample_f", __LINE__))
                CHECK(xf >= 0.0f && isfinite(xf), "exponential_f sigma %g u %g: %g", (double)hf, (double)kf, (double)xf);
            prime_message();
            if (accepted_or_explained(dwv_exponential_pdf_f(hf, kf, &xf), "exponential_pdf_f", __LINE__))
                CHECK(xf >= 0.0f && isfinite(xf), "exponential_pdf_f sigma %g t %g: %g", (double)hf, (double)kf,
                      (double)xf);
        }
        prime_message();
        if (accepted_or_explained(dwv_isotropic_sample(h, &x), "isotropic_sample", __LINE__))
            CHECK(x >= -1.0 && x <= 1.0, "isotropic u %g: %g", h, x);
    }
}

/* ---- dwv_estimate -------------------------------------------------------------------------------- */

static dwv_estimate_options_t small_options(void)
{
    dwv_estimate_options_t o = DWV_ESTIMATE_OPTIONS_INIT;
    o.walks = 64u;
    o.threads = 1u;
    return o;
}

#define ESTIMATE_REFUSED(change, expected)                                                           \
    do {                                                                                            \
        dwv_estimate_options_t eo = small_options();                                                \
        dwv_estimate_result_t er = DWV_ESTIMATE_RESULT_INIT;                                        \
        change;                                                                                     \
        REFUSED(dwv_estimate, dwv_estimate(&eo, &er), expected);                                    \
    } while (0)

static void test_estimate(void)
{
    dwv_estimate_options_t o = small_options();
    dwv_estimate_result_t r = DWV_ESTIMATE_RESULT_INIT;
    CHECK(dwv_estimate(&o, &r) == DWV_SUCCESS, "the small options run: %s", dwv_last_error_message());
    REFUSED(dwv_estimate, dwv_estimate(NULL, &r), NULLP);
    REFUSED(dwv_estimate, dwv_estimate(&o, NULL), NULLP);
    REFUSED(dwv_estimate, dwv_estimate(NULL, NULL), NULLP);
    r.struct_size = 1u;
    REFUSED(dwv_estimate, dwv_estimate(&o, &r), SIZE);

    ESTIMATE_REFUSED(eo.struct_size = 0u, SIZE);
    ESTIMATE_REFUSED(eo.struct_size = 4u, SIZE);
    ESTIMATE_REFUSED(eo.shape = INT32_MIN, RANGE);
    ESTIMATE_REFUSED(eo.shape = 3, RANGE);
    ESTIMATE_REFUSED((eo.shape = DWV_SHAPE_SLAB, eo.thickness = 0.0), RANGE);
    ESTIMATE_REFUSED((eo.shape = DWV_SHAPE_SLAB, eo.thickness = -0.0), RANGE);
    ESTIMATE_REFUSED((eo.shape = DWV_SHAPE_SLAB, eo.thickness = -1.0), RANGE);
    ESTIMATE_REFUSED((eo.shape = DWV_SHAPE_SLAB, eo.thickness = NAN), INVALID);
    ESTIMATE_REFUSED((eo.shape = DWV_SHAPE_SLAB, eo.thickness = INFINITY), INVALID);
    ESTIMATE_REFUSED((eo.shape = DWV_SHAPE_SPHERE, eo.radius = 0.0), RANGE);
    ESTIMATE_REFUSED((eo.shape = DWV_SHAPE_SPHERE, eo.radius = -4.9406564584124654e-324), RANGE);
    ESTIMATE_REFUSED((eo.shape = DWV_SHAPE_SPHERE, eo.radius = -INFINITY), INVALID);
    /* Radii whose squares over- or underflow: exits used to score infinity (5e-324) or 0 (1e300). */
    ESTIMATE_REFUSED((eo.shape = DWV_SHAPE_SPHERE, eo.radius = 4.9406564584124654e-324), RANGE);
    ESTIMATE_REFUSED((eo.shape = DWV_SHAPE_SPHERE, eo.radius = 1e-200), RANGE);
    ESTIMATE_REFUSED((eo.shape = DWV_SHAPE_SPHERE, eo.radius = 1e300), RANGE);
    ESTIMATE_REFUSED(eo.medium.struct_size = 0u, SIZE);
    ESTIMATE_REFUSED(eo.medium.channels = 0u, RANGE);
    ESTIMATE_REFUSED(eo.medium.channels = 2u, RANGE);
    ESTIMATE_REFUSED(eo.medium.channels = UINT32_MAX, RANGE);
    ESTIMATE_REFUSED(eo.medium.sigma_t[0] = 0.0, RANGE);
    ESTIMATE_REFUSED(eo.medium.sigma_t[0] = -1.0, RANGE);
    ESTIMATE_REFUSED(eo.medium.sigma_t[0] = NAN, INVALID);
    ESTIMATE_REFUSED(eo.medium.sigma_t[0] = 1e-31, RANGE);
    ESTIMATE_REFUSED(eo.medium.sigma_t[0] = 1e31, RANGE);
    ESTIMATE_REFUSED((eo.medium.channels = 3u, eo.medium.sigma_t[2] = INFINITY), INVALID);
    ESTIMATE_REFUSED((eo.medium.channels = 3u, eo.medium.albedo[1] = -1e-300), RANGE);
    ESTIMATE_REFUSED((eo.medium.channels = 3u, eo.medium.albedo[2] = NAN), INVALID);
    ESTIMATE_REFUSED(eo.medium.albedo[0] = 1.0 + DBL_EPSILON, RANGE);
    ESTIMATE_REFUSED(eo.medium.anisotropy = 1.0, RANGE);
    ESTIMATE_REFUSED(eo.medium.anisotropy = -1.0, RANGE);
    ESTIMATE_REFUSED(eo.medium.anisotropy = NAN, INVALID);
    ESTIMATE_REFUSED(eo.incidence = -1, RANGE);
    ESTIMATE_REFUSED(eo.incidence = 2, RANGE);
    ESTIMATE_REFUSED(eo.incidence_cosine = 0.0, RANGE);
    ESTIMATE_REFUSED(eo.incidence_cosine = -0.5, RANGE);
    ESTIMATE_REFUSED(eo.incidence_cosine = 1.0 + DBL_EPSILON, RANGE);
    ESTIMATE_REFUSED(eo.incidence_cosine = NAN, INVALID);
    ESTIMATE_REFUSED(eo.light = 0, RANGE);
    ESTIMATE_REFUSED(eo.light = 4, RANGE);
    ESTIMATE_REFUSED(eo.light = -1, RANGE);
    ESTIMATE_REFUSED(eo.light = DWV_LIGHT_BACK, INVALID); /* a half-space has no back face */
    ESTIMATE_REFUSED(eo.technique = -1, RANGE);
    ESTIMATE_REFUSED(eo.technique = DWV_TECHNIQUE_SHEET + 1, RANGE);
    ESTIMATE_REFUSED(eo.technique = INT32_MAX, RANGE);
    ESTIMATE_REFUSED(eo.walks = 0u, RANGE);
    ESTIMATE_REFUSED(eo.walks = 1u, RANGE);
    ESTIMATE_REFUSED(eo.walks = 1000000000001ull, RANGE);
    ESTIMATE_REFUSED(eo.walks = 10000000000000ull, RANGE); /* 10^13 */
    ESTIMATE_REFUSED(eo.walks = UINT64_MAX, RANGE);
    ESTIMATE_REFUSED(eo.threads = 257u, RANGE);
    ESTIMATE_REFUSED(eo.threads = UINT32_MAX, RANGE);
    /* Several wrong at once: refused (whichever is named first). */
    ESTIMATE_REFUSED((eo.walks = 0u, eo.technique = 99, eo.medium.albedo[0] = NAN), INVALID);

    /* Accepted extremes: every output finite. A diffuse incidence ignores incidence_cosine. */
    static const struct {
        dwv_shape_t shape;
        double size, albedo, sigma, g, cosine;
        dwv_incidence_t incidence;
        dwv_light_t light;
    } extremes[] = {
        {DWV_SHAPE_HALFSPACE, 1.0, 1.0, 1e30, 0.0, 1.0, DWV_INCIDENCE_COSINE, DWV_LIGHT_FRONT},
        {DWV_SHAPE_HALFSPACE, 1.0, 0.0, 1e-30, 0.0, 4.9406564584124654e-324, DWV_INCIDENCE_COSINE, DWV_LIGHT_FRONT},
        {DWV_SHAPE_SLAB, 4.9406564584124654e-324, 0.99, 1.0, 0.0, 1.0, DWV_INCIDENCE_COSINE, DWV_LIGHT_BOTH},
        {DWV_SHAPE_SLAB, DBL_MAX, 0.5, 1e30, 0.9999, 1.0, DWV_INCIDENCE_DIFFUSE, DWV_LIGHT_BACK},
        {DWV_SHAPE_SPHERE, 1e-100, 0.9, 1.0, -0.9999, NAN, DWV_INCIDENCE_DIFFUSE, DWV_LIGHT_BOTH},
        {DWV_SHAPE_SPHERE, 1e100, 1.0, 1e-30, 0.0, 1e-9, DWV_INCIDENCE_COSINE, DWV_LIGHT_BACK},
        {DWV_SHAPE_SPHERE, 1e100, 0.9, 1e30, 0.5, 1.0, DWV_INCIDENCE_DIFFUSE, DWV_LIGHT_BOTH},
        {DWV_SHAPE_SPHERE, 1e-100, 0.9, 1e-30, 0.0, 1.0, DWV_INCIDENCE_DIFFUSE, DWV_LIGHT_FRONT},
    };
    for (size_t e = 0; e < sizeof extremes / sizeof extremes[0]; ++e) {
        for (dwv_technique_t t = DWV_TECHNIQUE_AUTO; t <= DWV_TECHNIQUE_CYCLES; ++t) {
            o = small_options();
            o.shape = extremes[e].shape;
            o.thickness = o.radius = extremes[e].size;
            o.medium.albedo[0] = extremes[e].albedo;
            o.medium.sigma_t[0] = extremes[e].sigma;
            o.medium.anisotropy = extremes[e].g;
            o.incidence = extremes[e].incidence;
            o.incidence_cosine = extremes[e].cosine;
            o.light = extremes[e].light;
            o.technique = t;
            o.max_events = 2000u; /* an albedo-1 half-space walk may be long */
            dwv_estimate_result_t res = DWV_ESTIMATE_RESULT_INIT;
            dwv_result_t rc = dwv_estimate(&o, &res);
            CHECK(rc == DWV_SUCCESS, "extreme %zu %s: %s", e, dwv_technique_name(t), dwv_last_error_message());
            if (rc == DWV_SUCCESS)
                CHECK(isfinite(res.mean[0]) && res.mean[0] >= 0.0 && isfinite(res.variance[0]) &&
                          isfinite(res.std_error[0]) && isfinite(res.truncated_weight[0]) && res.walks == o.walks,
                      "extreme %zu %s: mean %g variance %g truncated %g", e, dwv_technique_name(t), res.mean[0],
                      res.variance[0], res.truncated_weight[0]);
        }
    }
}

/* ---- step-by-step walks -------------------------------------------------------------------------- */

static void test_walk(void)
{
    dwv_medium_t m = DWV_MEDIUM_INIT;
    dwv_light_patch_t patches[17];
    for (int i = 0; i < 17; ++i) patches[i] = (dwv_light_patch_t)DWV_LIGHT_PATCH_INIT;
    dwv_walk_t *w = (dwv_walk_t *)&m; /* must be set to NULL by a refused create */
    REFUSED(dwv_walk_create, dwv_walk_create(&m, DWV_TECHNIQUE_AUTO, NULL, 0, 0, 0, NULL), NULLP);
    REFUSED(dwv_walk_create, dwv_walk_create(NULL, DWV_TECHNIQUE_AUTO, NULL, 0, 0, 0, &w), NULLP);
    CHECK(w == NULL, "a refused dwv_walk_create left *walk %p", (void *)w);
    m.struct_size = 0u;
    REFUSED(dwv_walk_create, dwv_walk_create(&m, DWV_TECHNIQUE_AUTO, NULL, 0, 0, 0, &w), SIZE);
    m = (dwv_medium_t)DWV_MEDIUM_INIT;
    m.albedo[0] = -INFINITY;
    REFUSED(dwv_walk_create, dwv_walk_create(&m, DWV_TECHNIQUE_AUTO, NULL, 0, 0, 0, &w), INVALID);
    m = (dwv_medium_t)DWV_MEDIUM_INIT;
    REFUSED(dwv_walk_create, dwv_walk_create(&m, -7, NULL, 0, 0, 0, &w), RANGE);
    REFUSED(dwv_walk_create, dwv_walk_create(&m, 8, NULL, 0, 0, 0, &w), RANGE);
    REFUSED(dwv_walk_create, dwv_walk_create(&m, DWV_TECHNIQUE_AUTO, NULL, 1, 0, 0, &w), NULLP);
    REFUSED(dwv_walk_create, dwv_walk_create(&m, DWV_TECHNIQUE_AUTO, patches, 17, 0, 0, &w), RANGE);
    REFUSED(dwv_walk_create, dwv_walk_create(&m, DWV_TECHNIQUE_AUTO, patches, UINT32_MAX, 0, 0, &w), RANGE);
    REFUSED(dwv_walk_create, dwv_walk_create(&m, DWV_TECHNIQUE_INCIDENT, NULL, 0, 0, 0, &w), INVALID);
    patches[3].struct_size = 0u;
    REFUSED(dwv_walk_create, dwv_walk_create(&m, DWV_TECHNIQUE_INCIDENT, patches, 4, 0, 0, &w), SIZE);
    patches[3] = (dwv_light_patch_t)DWV_LIGHT_PATCH_INIT;
    patches[2].point[1] = NAN;
    REFUSED(dwv_walk_create, dwv_walk_create(&m, DWV_TECHNIQUE_INCIDENT, patches, 4, 0, 0, &w), INVALID);
    patches[2] = (dwv_light_patch_t)DWV_LIGHT_PATCH_INIT;
    patches[1].normal[2] = 0.0; /* zero vector */
    REFUSED(dwv_walk_create, dwv_walk_create(&m, DWV_TECHNIQUE_INCIDENT, patches, 4, 0, 0, &w), INVALID);
    patches[1].normal[2] = -2.0;
    REFUSED(dwv_walk_create, dwv_walk_create(&m, DWV_TECHNIQUE_INCIDENT, patches, 4, 0, 0, &w), INVALID);
    patches[1] = (dwv_light_patch_t)DWV_LIGHT_PATCH_INIT;
    patches[0].power = 0.0;
    REFUSED(dwv_walk_create, dwv_walk_create(&m, DWV_TECHNIQUE_INCIDENT, patches, 4, 0, 0, &w), RANGE);
    patches[0].power = INFINITY;
    REFUSED(dwv_walk_create, dwv_walk_create(&m, DWV_TECHNIQUE_INCIDENT, patches, 4, 0, 0, &w), INVALID);
    patches[0] = (dwv_light_patch_t)DWV_LIGHT_PATCH_INIT;
    CHECK(w == NULL, "refused creates left *walk set");

    dwv_walk_release(NULL);
    REFUSED(dwv_walk_retain, dwv_walk_retain(NULL), NULLP);
    int32_t needs = 0;
    REFUSED(dwv_walk_needs_closest, dwv_walk_needs_closest(NULL, &needs), NULLP);

    CHECK(dwv_walk_create(&m, DWV_TECHNIQUE_CLOSEST, NULL, 0, 1, 0, &w) == DWV_SUCCESS && w != NULL, "create: %s",
          dwv_last_error_message());
    if (!w) return;
    REFUSED(dwv_walk_needs_closest, dwv_walk_needs_closest(w, NULL), NULLP);
    double point[3] = {0.0, 0.0, 0.0}, inward[3] = {0.0, 0.0, 1.0}, outward[3] = {0.0, 0.0, -1.0};
    double bad[3] = {NAN, 0.0, 1.0}, long_vector[3] = {0.0, 0.0, 2.0}, zero[3] = {0.0, 0.0, 0.0};
    double huge[3] = {INFINITY, 0.0, 0.0};
    double direction[3], distance = 0.0;
    dwv_walk_state_t state = DWV_WALK_STATE_INIT;
    /* Out of order first: nothing begun. */
    REFUSED(dwv_walk_sample, dwv_walk_sample(w, direction, &distance), STATE);
    REFUSED(dwv_walk_report, dwv_walk_report(w, 1.0, outward, &state), STATE);
    REFUSED(dwv_walk_begin, dwv_walk_begin(NULL, 0, point, inward, outward), NULLP);
    REFUSED(dwv_walk_begin, dwv_walk_begin(w, 0, NULL, inward, outward), NULLP);
    REFUSED(dwv_walk_begin, dwv_walk_begin(w, 0, point, NULL, outward), NULLP);
    REFUSED(dwv_walk_begin, dwv_walk_begin(w, 0, point, inward, NULL), NULLP);
    REFUSED(dwv_walk_begin, dwv_walk_begin(w, 0, huge, inward, outward), INVALID);
    REFUSED(dwv_walk_begin, dwv_walk_begin(w, 0, point, bad, outward), INVALID);
    REFUSED(dwv_walk_begin, dwv_walk_begin(w, 0, point, long_vector, outward), INVALID);
    REFUSED(dwv_walk_begin, dwv_walk_begin(w, 0, point, zero, outward), INVALID);
    REFUSED(dwv_walk_begin, dwv_walk_begin(w, 0, point, inward, inward), INVALID); /* does not enter */
    CHECK(dwv_walk_begin(w, UINT64_MAX, point, inward, outward) == DWV_SUCCESS, "begin: %s", dwv_last_error_message());
    REFUSED(dwv_walk_sample, dwv_walk_sample(w, direction, &distance), STATE); /* closest first */
    REFUSED(dwv_walk_set_closest, dwv_walk_set_closest(NULL, outward), NULLP);
    REFUSED(dwv_walk_set_closest, dwv_walk_set_closest(w, NULL), NULLP);
    REFUSED(dwv_walk_set_closest, dwv_walk_set_closest(w, bad), INVALID);
    REFUSED(dwv_walk_set_closest, dwv_walk_set_closest(w, zero), INVALID);
    CHECK(dwv_walk_set_closest(w, outward) == DWV_SUCCESS, "set_closest");
    REFUSED(dwv_walk_sample, dwv_walk_sample(NULL, direction, &distance), NULLP);
    REFUSED(dwv_walk_sample, dwv_walk_sample(w, NULL, &distance), NULLP);
    REFUSED(dwv_walk_sample, dwv_walk_sample(w, direction, NULL), NULLP);
    CHECK(dwv_walk_sample(w, direction, &distance) == DWV_SUCCESS && isfinite(distance) && distance >= 0.0,
          "sample: %s", dwv_last_error_message());
    REFUSED(dwv_walk_report, dwv_walk_report(NULL, 1.0, outward, &state), NULLP);
    REFUSED(dwv_walk_report, dwv_walk_report(w, 1.0, outward, NULL), NULLP);
    state.struct_size = 8u;
    REFUSED(dwv_walk_report, dwv_walk_report(w, 1.0, outward, &state), SIZE);
    state.struct_size = (uint32_t)sizeof state;
    REFUSED(dwv_walk_report, dwv_walk_report(w, NAN, outward, &state), INVALID);
    REFUSED(dwv_walk_report, dwv_walk_report(w, -1.0, outward, &state), INVALID);
    REFUSED(dwv_walk_report, dwv_walk_report(w, -INFINITY, outward, &state), INVALID);
    REFUSED(dwv_walk_report, dwv_walk_report(w, 1.0, NULL, &state), NULLP);
    REFUSED(dwv_walk_report, dwv_walk_report(w, 1.0, bad, &state), INVALID);
    /* After all those refusals the step is still pending and completes normally. */
    CHECK(dwv_walk_report(w, INFINITY, NULL, &state) == DWV_SUCCESS && state.status == DWV_WALK_RUNNING &&
              isfinite(state.weight[0]), "report: %s (status %d)", dwv_last_error_message(), (int)state.status);
    REFUSED(dwv_walk_report, dwv_walk_report(w, INFINITY, NULL, &state), STATE); /* twice */
    dwv_walk_release(w);
}

/* ---- images -------------------------------------------------------------------------------------- */

static void test_images(void)
{
    float pixel[4] = {0.5f, 0.5f, 0.5f, 1.0f};
    dwv_image_t *image = (dwv_image_t *)pixel;
    REFUSED(dwv_image_create, dwv_image_create(1, 1, pixel, NULL), NULLP);
    REFUSED(dwv_image_create, dwv_image_create(1, 1, NULL, &image), NULLP);
    CHECK(image == NULL, "a refused dwv_image_create left *image set");
    /* Absurd sizes are refused before anything reads rgba (one pixel here) or allocates. */
    REFUSED(dwv_image_create, dwv_image_create(0, 1, pixel, &image), RANGE);
    REFUSED(dwv_image_create, dwv_image_create(1000000, 1000000, pixel, &image), RANGE);
    REFUSED(dwv_image_create, dwv_image_create(UINT32_MAX, UINT32_MAX, pixel, &image), RANGE);
    REFUSED(dwv_image_create, dwv_image_create(16384, 16384, pixel, &image), RANGE);
    pixel[2] = NAN;
    REFUSED(dwv_image_create, dwv_image_create(1, 1, pixel, &image), INVALID);
    pixel[2] = -INFINITY;
    REFUSED(dwv_image_create, dwv_image_create(1, 1, pixel, &image), INVALID);
    pixel[2] = 0.5f;
    CHECK(dwv_image_create(1, 1, pixel, &image) == DWV_SUCCESS && image != NULL, "create: %s", dwv_last_error_message());
    dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
    dwv_bake_stats_t stats = DWV_BAKE_STATS_INIT;
    uint32_t count = 7u;
    dwv_error_point_t points[2];
    REFUSED(dwv_image_info, dwv_image_info(NULL, &info), NULLP);
    REFUSED(dwv_image_info, dwv_image_info(image, NULL), NULLP);
    info.struct_size = 0u;
    REFUSED(dwv_image_info, dwv_image_info(image, &info), SIZE);
    REFUSED(dwv_image_stats, dwv_image_stats(NULL, &stats), NULLP);
    /* A struct of an older header (ending before path_rays) is filled as far as it goes; a
     * shorter one is refused. */
    stats.struct_size = (uint32_t)offsetof(dwv_bake_stats_t, path_rays);
    stats.path_rays = 12345u;
    CHECK(dwv_image_stats(image, &stats) == DWV_SUCCESS && stats.path_rays == 12345u,
          "stats of an older header's size: %s", dwv_last_error_message());
    stats.struct_size = (uint32_t)offsetof(dwv_bake_stats_t, path_rays) - 8u;
    REFUSED(dwv_image_stats, dwv_image_stats(image, &stats), SIZE);
    REFUSED(dwv_image_error_vs_time, dwv_image_error_vs_time(NULL, points, 2, &count), NULLP);
    REFUSED(dwv_image_error_vs_time, dwv_image_error_vs_time(image, points, 2, NULL), NULLP);
    REFUSED(dwv_image_error_vs_time, dwv_image_error_vs_time(image, NULL, UINT32_MAX, &count), NULLP);
    CHECK(dwv_image_error_vs_time(image, NULL, 0, &count) == DWV_SUCCESS && count == 0u, "error_vs_time count %u",
          count);
    REFUSED(dwv_image_retain, dwv_image_retain(NULL), NULLP);
    dwv_image_release(NULL);
    dwv_image_release(image);
}

int main(void)
{
    test_names();
    test_diffusion_length();
    test_dwivedi();
    test_classical();
    test_estimate();
    test_walk();
    test_images();
    return check_report("test_hostile_input");
}
