/* dwv_estimate's argument checks (each refusal with its result code and a message of its own that
 * names the offending argument), an RGB run, and the technique names, through the public API. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "api_checks.h"
#include "check.h"
#include <dwivedi.h>

/* Small valid options: every refusal below changes exactly one thing. */
static dwv_estimate_options_t valid_options(void)
{
    dwv_estimate_options_t o = DWV_ESTIMATE_OPTIONS_INIT;
    o.walks = 100u;
    o.threads = 1u;
    return o;
}

static void expect_refused(const char *what, const dwv_estimate_options_t *o, dwv_result_t code, const char *keyword)
{
    dwv_estimate_result_t r = DWV_ESTIMATE_RESULT_INIT;
    prime_message();
    dwv_result_t result = dwv_estimate(o, &r);
    CHECK(result == code && fresh_message_with("dwv_estimate") && fresh_message_with(keyword),
          "%s: result %d (%s), expected %d; message '%s' should name '%s'", what, (int)result,
          dwv_result_string(result), (int)code, dwv_last_error_message(), keyword);
}

static void test_refusals(void)
{
    dwv_estimate_options_t o = valid_options();
    dwv_estimate_result_t r = DWV_ESTIMATE_RESULT_INIT;

    /* The valid options themselves run, so each refusal is the one change's doing. */
    CHECK(dwv_estimate(&o, &r) == DWV_SUCCESS && r.walks == 100u, "valid options: %s", dwv_last_error_message());

    prime_message();
    dwv_result_t result = dwv_estimate(NULL, &r);
    CHECK(result == DWV_ERROR_NULL_POINTER && fresh_message_with("options"), "NULL options: %d '%s'", (int)result,
          dwv_last_error_message());
    prime_message();
    result = dwv_estimate(&o, NULL);
    CHECK(result == DWV_ERROR_NULL_POINTER && fresh_message_with("result"), "NULL result: %d '%s'", (int)result,
          dwv_last_error_message());
    dwv_estimate_result_t small = DWV_ESTIMATE_RESULT_INIT;
    small.struct_size = 0u;
    prime_message();
    result = dwv_estimate(&o, &small);
    CHECK(result == DWV_ERROR_STRUCT_SIZE && fresh_message_with("struct_size"), "result struct_size 0: %d '%s'",
          (int)result, dwv_last_error_message());

    o = valid_options(), o.struct_size = 0u;
    expect_refused("options struct_size 0", &o, DWV_ERROR_STRUCT_SIZE, "struct_size");
    o = valid_options(), o.struct_size = (uint32_t)sizeof o - 8u;
    expect_refused("options struct_size short by 8", &o, DWV_ERROR_STRUCT_SIZE, "struct_size");
    o = valid_options(), o.shape = 7;
    expect_refused("shape 7", &o, DWV_ERROR_OUT_OF_RANGE, "shape");
    o = valid_options(), o.shape = -1;
    expect_refused("shape -1", &o, DWV_ERROR_OUT_OF_RANGE, "shape");
    o = valid_options(), o.shape = DWV_SHAPE_SLAB, o.thickness = 0.0;
    expect_refused("slab thickness 0", &o, DWV_ERROR_OUT_OF_RANGE, "thickness");
    o = valid_options(), o.shape = DWV_SHAPE_SLAB, o.thickness = NAN;
    expect_refused("slab thickness NaN", &o, DWV_ERROR_INVALID_ARGUMENT, "thickness");
    o = valid_options(), o.shape = DWV_SHAPE_SLAB, o.thickness = INFINITY;
    expect_refused("slab thickness inf", &o, DWV_ERROR_INVALID_ARGUMENT, "thickness");
    o = valid_options(), o.shape = DWV_SHAPE_SPHERE, o.radius = -1.0;
    expect_refused("sphere radius -1", &o, DWV_ERROR_OUT_OF_RANGE, "radius");
    o = valid_options(), o.shape = DWV_SHAPE_SPHERE, o.radius = NAN;
    expect_refused("sphere radius NaN", &o, DWV_ERROR_INVALID_ARGUMENT, "radius");
    o = valid_options(), o.incidence = 5;
    expect_refused("incidence 5", &o, DWV_ERROR_OUT_OF_RANGE, "incidence");
    o = valid_options(), o.incidence_cosine = 0.0;
    expect_refused("incidence_cosine 0", &o, DWV_ERROR_OUT_OF_RANGE, "incidence_cosine");
    o = valid_options(), o.incidence_cosine = 1.5;
    expect_refused("incidence_cosine 1.5", &o, DWV_ERROR_OUT_OF_RANGE, "incidence_cosine");
    o = valid_options(), o.incidence_cosine = NAN;
    expect_refused("incidence_cosine NaN", &o, DWV_ERROR_INVALID_ARGUMENT, "incidence_cosine");
    o = valid_options(), o.light = 0;
    expect_refused("light 0", &o, DWV_ERROR_OUT_OF_RANGE, "light");
    o = valid_options(), o.light = 4;
    expect_refused("light 4", &o, DWV_ERROR_OUT_OF_RANGE, "light");
    o = valid_options(), o.light = DWV_LIGHT_BACK;
    expect_refused("half-space lit from the back", &o, DWV_ERROR_INVALID_ARGUMENT, "back");
    o = valid_options(), o.light = DWV_LIGHT_BOTH;
    expect_refused("half-space lit from both sides", &o, DWV_ERROR_INVALID_ARGUMENT, "back");
    o = valid_options(), o.technique = 99;
    expect_refused("technique 99", &o, DWV_ERROR_OUT_OF_RANGE, "technique");
    o = valid_options(), o.technique = -1;
    expect_refused("technique -1", &o, DWV_ERROR_OUT_OF_RANGE, "technique");
    o = valid_options(), o.walks = 0u;
    expect_refused("walks 0", &o, DWV_ERROR_OUT_OF_RANGE, "walks = 0");
    o = valid_options(), o.walks = 1u;
    expect_refused("walks 1", &o, DWV_ERROR_OUT_OF_RANGE, "walks = 1");
    o = valid_options(), o.walks = 10000000000000ull;
    expect_refused("walks 10^13", &o, DWV_ERROR_OUT_OF_RANGE, "walks = 10000000000000");
    o = valid_options(), o.threads = 1000u;
    expect_refused("threads 1000", &o, DWV_ERROR_OUT_OF_RANGE, "threads");

    /* The medium, checked as dwv_walk_create checks it. */
    o = valid_options(), o.medium.channels = 2u;
    expect_refused("medium channels 2", &o, DWV_ERROR_OUT_OF_RANGE, "channels");
    o = valid_options(), o.medium.struct_size = 0u;
    expect_refused("medium struct_size 0", &o, DWV_ERROR_STRUCT_SIZE, "struct_size");
    o = valid_options(), o.medium.sigma_t[0] = 0.0;
    expect_refused("sigma_t 0", &o, DWV_ERROR_OUT_OF_RANGE, "sigma_t");
    o = valid_options(), o.medium.sigma_t[0] = -1.0;
    expect_refused("sigma_t -1", &o, DWV_ERROR_OUT_OF_RANGE, "sigma_t");
    o = valid_options(), o.medium.sigma_t[0] = NAN;
    expect_refused("sigma_t NaN", &o, DWV_ERROR_INVALID_ARGUMENT, "sigma_t");
    o = valid_options(), o.medium.sigma_t[0] = INFINITY;
    expect_refused("sigma_t inf", &o, DWV_ERROR_INVALID_ARGUMENT, "sigma_t");
    /* Beyond single precision, where free flights are sampled. */
    o = valid_options(), o.medium.sigma_t[0] = 1e31;
    expect_refused("sigma_t 1e31", &o, DWV_ERROR_OUT_OF_RANGE, "sigma_t");
    o = valid_options(), o.medium.sigma_t[0] = 1e-31;
    expect_refused("sigma_t 1e-31", &o, DWV_ERROR_OUT_OF_RANGE, "sigma_t");
    o = valid_options(), o.medium.channels = 3u, o.medium.sigma_t[1] = 0.0;
    expect_refused("rgb sigma_t[1] 0", &o, DWV_ERROR_OUT_OF_RANGE, "sigma_t[1]");
    o = valid_options(), o.medium.albedo[0] = 1.5;
    expect_refused("albedo 1.5", &o, DWV_ERROR_OUT_OF_RANGE, "albedo");
    o = valid_options(), o.medium.albedo[0] = NAN;
    expect_refused("albedo NaN", &o, DWV_ERROR_INVALID_ARGUMENT, "albedo");
    o = valid_options(), o.medium.channels = 3u, o.medium.albedo[2] = -0.5;
    expect_refused("rgb albedo[2] -0.5", &o, DWV_ERROR_OUT_OF_RANGE, "albedo[2]");
    o = valid_options(), o.medium.anisotropy = 1.0;
    expect_refused("anisotropy 1", &o, DWV_ERROR_OUT_OF_RANGE, "anisotropy");
    o = valid_options(), o.medium.anisotropy = -1.0;
    expect_refused("anisotropy -1", &o, DWV_ERROR_OUT_OF_RANGE, "anisotropy");
    o = valid_options(), o.medium.anisotropy = NAN;
    expect_refused("anisotropy NaN", &o, DWV_ERROR_INVALID_ARGUMENT, "anisotropy");

    /* The edges of the ranges are accepted: 2 walks, 256 threads, a grazing cosine, albedo 0 and 1. */
    const struct {
        const char *what;
        uint64_t walks;
        uint32_t threads;
        double cosine, albedo;
    } edges[] = {
        {"walks 2", 2u, 1u, 1.0, 0.5},
        {"threads 256", 300u, 256u, 1.0, 0.5},
        {"incidence_cosine 1e-6", 100u, 1u, 1e-6, 0.5},
        {"albedo 0", 100u, 1u, 1.0, 0.0},
        {"albedo 1", 100u, 1u, 1.0, 1.0},
    };
    for (size_t i = 0; i < sizeof edges / sizeof edges[0]; ++i) {
        o = valid_options();
        o.walks = edges[i].walks;
        o.threads = edges[i].threads;
        o.incidence_cosine = edges[i].cosine;
        o.medium.albedo[0] = edges[i].albedo;
        o.max_events = 10000u; /* albedo 1 in a half-space: a few walks wander for long */
        r = (dwv_estimate_result_t)DWV_ESTIMATE_RESULT_INIT;
        result = dwv_estimate(&o, &r);
        CHECK(result == DWV_SUCCESS && r.walks == edges[i].walks && isfinite(r.mean[0]) && r.mean[0] >= 0.0,
              "%s: result %d, walks %llu, mean %g: %s", edges[i].what, (int)result, (unsigned long long)r.walks,
              r.mean[0], dwv_last_error_message());
    }
}

/* A three-channel medium: three finite means, ordered as their albedos in a front-lit half-space
 * (more scattering, more light back out), each difference far beyond its standard error. */
static void test_rgb_run(void)
{
    dwv_estimate_options_t o = valid_options();
    o.medium.channels = 3u;
    o.medium.albedo[0] = 0.3, o.medium.albedo[1] = 0.6, o.medium.albedo[2] = 0.9;
    o.medium.sigma_t[0] = 1.0, o.medium.sigma_t[1] = 1.5, o.medium.sigma_t[2] = 2.0;
    o.technique = DWV_TECHNIQUE_AUTO;
    o.walks = 20000u;
    o.seed = 42u;
    dwv_estimate_result_t r = DWV_ESTIMATE_RESULT_INIT;
    dwv_result_t result = dwv_estimate(&o, &r);
    CHECK(result == DWV_SUCCESS, "rgb run: %s", dwv_last_error_message());
    CHECK(r.channels == 3u, "rgb run: channels %u", r.channels);
    for (int c = 0; c < 3; ++c) {
        CHECK(isfinite(r.mean[c]) && r.mean[c] > 0.0 && r.mean[c] < 1.0 && isfinite(r.std_error[c]) &&
                  r.std_error[c] > 0.0 && isfinite(r.variance[c]) && isfinite(r.truncated_weight[c]),
              "rgb channel %d: mean %g, std_error %g, variance %g, truncated %g", c, r.mean[c], r.std_error[c],
              r.variance[c], r.truncated_weight[c]);
        /* std_error is sqrt(variance / walks) (dwivedi.h). */
        CHECK(fabs(r.std_error[c] - sqrt(r.variance[c] / (double)r.walks)) <= 1e-12 * r.std_error[c],
              "rgb channel %d: std_error %.17g, sqrt(variance / walks) %.17g", c, r.std_error[c],
              sqrt(r.variance[c] / (double)r.walks));
    }
    for (int c = 0; c < 2; ++c)
        CHECK(r.mean[c + 1] - r.mean[c] > 5.0 * (r.std_error[c] + r.std_error[c + 1]),
              "rgb: mean[%d] = %g +- %g not below mean[%d] = %g +- %g", c, r.mean[c], r.std_error[c], c + 1,
              r.mean[c + 1], r.std_error[c + 1]);
    CHECK(r.walks == 20000u && r.events >= r.walks && r.truncated_walks == 0u && isfinite(r.seconds) &&
              r.seconds >= 0.0,
          "rgb: walks %llu, events %llu, truncated %llu, seconds %g", (unsigned long long)r.walks,
          (unsigned long long)r.events, (unsigned long long)r.truncated_walks, r.seconds);
}

static void test_technique_names(void)
{
    static const char *const expected[8] = {"auto", "classical", "poe", "closest", "incident", "backward", "cycles",
                                            "sheet"};
    static const dwv_technique_t values[8] = {DWV_TECHNIQUE_AUTO,     DWV_TECHNIQUE_CLASSICAL, DWV_TECHNIQUE_POE,
                                              DWV_TECHNIQUE_CLOSEST,  DWV_TECHNIQUE_INCIDENT,  DWV_TECHNIQUE_BACKWARD,
                                              DWV_TECHNIQUE_CYCLES,   DWV_TECHNIQUE_SHEET};
    for (int i = 0; i < 8; ++i) {
        const char *name = dwv_technique_name(values[i]);
        CHECK(name != NULL && strcmp(name, expected[i]) == 0, "dwv_technique_name(%d) = '%s', expected '%s'",
              (int)values[i], name ? name : "(null)", expected[i]);
        dwv_technique_t back = -1;
        dwv_result_t result = dwv_technique_from_name(expected[i], &back);
        CHECK(result == DWV_SUCCESS && back == values[i], "dwv_technique_from_name('%s') = %d (result %d)",
              expected[i], (int)back, (int)result);
    }
    CHECK(dwv_technique_name(-1) == NULL && dwv_technique_name(8) == NULL && dwv_technique_name(99) == NULL,
          "%s", "names of techniques that do not exist");

    static const char *const unknown[] = {"", "Auto", "AUTO", "auto ", " auto", "classic", "poe2", "cycle", "none"};
    for (size_t i = 0; i < sizeof unknown / sizeof unknown[0]; ++i) {
        dwv_technique_t untouched = DWV_TECHNIQUE_CYCLES;
        prime_message();
        dwv_result_t result = dwv_technique_from_name(unknown[i], &untouched);
        /* The message quotes the name; the primer's name never appears in it. */
        CHECK(result == DWV_ERROR_UNKNOWN_NAME && untouched == DWV_TECHNIQUE_CYCLES &&
                  strstr(dwv_last_error_message(), PRIMER_NAME) == NULL && strstr(dwv_last_error_message(), "technique"),
              "'%s': result %d, technique %d, message '%s'", unknown[i], (int)result, (int)untouched,
              dwv_last_error_message());
    }
    dwv_technique_t technique;
    prime_message();
    CHECK(dwv_technique_from_name(NULL, &technique) == DWV_ERROR_NULL_POINTER && fresh_message_with("name"),
          "NULL name: '%s'", dwv_last_error_message());
    prime_message();
    CHECK(dwv_technique_from_name("auto", NULL) == DWV_ERROR_NULL_POINTER && fresh_message_with("technique"),
          "NULL technique: '%s'", dwv_last_error_message());
}

int main(void)
{
    test_refusals();
    test_rgb_run();
    test_technique_names();
    return check_report("test_estimate_api");
}
