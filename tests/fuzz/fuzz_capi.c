/* libFuzzer target: the capi argument surface of the kernels, walks and estimates.
 *
 * The input is read as a program: each operation takes one byte to choose an entry point, then
 * its arguments from the following bytes (doubles as raw bits half of the time, so NaN, infinities,
 * subnormals and every sign come up, else from a table of edge values; enums and sizes as raw
 * integers). Walk counts are tiny and event caps small, so that one input runs in milliseconds.
 * Beside ASan/UBSan's own findings, the target aborts on a broken contract: a refused call without
 * a known result code or a message, an accepted call with a NaN or an out-of-range output.
 * Built by DWV_BUILD_FUZZERS with clang (scripts/fuzz.sh); tests/fuzz/replay.c replays the
 * corpus and the regressions in every build. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <dwivedi.h>

typedef struct reader {
    const uint8_t *data;
    size_t size, at;
} reader;

static uint8_t byte(reader *r)
{
    return r->at < r->size ? r->data[r->at++] : 0u;
}

static uint64_t u64(reader *r)
{
    uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v = v << 8 | byte(r);
    return v;
}

static uint32_t u32(reader *r)
{
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v = v << 8 | byte(r);
    return v;
}

static const double edges[] = {0.0, -0.0, 1.0, -1.0, 0.5, 0.56, 0.5599999999, 0.9999, 0.99999, 1.0 - 1e-12, 1e-12,
                               1e-300, 1e-3, 2.0, 1e-30, 1e30, 1e-9, 1e6, 1e-6, 1e100, 1e-100, INFINITY, -INFINITY,
                               NAN, 4.9406564584124654e-324, 1.7976931348623157e308, 0.9, 0.99, 1.0 + 1e-15, 0.3};
#define EDGE_COUNT (sizeof edges / sizeof edges[0])

static double real(reader *r)
{
    uint8_t how = byte(r);
    if (how & 1u) {
        uint64_t bits = u64(r);
        double d;
        memcpy(&d, &bits, sizeof d);
        return d;
    }
    return edges[(how >> 1) % EDGE_COUNT];
}

/* A number meant to be valid most of the time: in [0, 1] from a byte, else anything. */
static double unit(reader *r)
{
    uint8_t b = byte(r);
    return b < 250u ? b / 249.0 : real(r);
}

static void fail(const char *what, dwv_result_t code)
{
    fprintf(stderr, "fuzz_capi: broken contract: %s (code %d, message '%s')\n", what, (int)code,
            dwv_last_error_message());
    abort();
}

#define SENTINEL "fuzz-capi-sentinel"

/* A refused call has a known code and a fresh (not the sentinel's), non-empty message naming a
 * dwv_ function. */
static int check_message(dwv_result_t code, const char *what, int fresh)
{
    if (code == DWV_SUCCESS) return 1;
    const char *message = dwv_last_error_message();
    if (code < 0 || code > DWV_ERROR_FORMAT || message == NULL || strncmp(message, "dwv_", 4) != 0 ||
        (fresh && strstr(message, SENTINEL) != NULL))
        fail(what, code);
    return 0;
}

static int check(dwv_result_t code, const char *what)
{
    return check_message(code, what, 1);
}

/* Leaves a message that names the sentinel, so that check() tells a stale message from a new one. */
static void prime(void)
{
    dwv_technique_t t;
    (void)dwv_technique_from_name(SENTINEL, &t);
}

static void require(int ok, const char *what)
{
    if (!ok) fail(what, DWV_SUCCESS);
}

static void medium_from(reader *r, dwv_medium_t *m)
{
    *m = (dwv_medium_t)DWV_MEDIUM_INIT;
    uint8_t flags = byte(r);
    if (flags & 0x80u) m->struct_size = u32(r);
    m->channels = flags & 0x40u ? u32(r) : (flags & 1u ? 3u : 1u);
    for (int c = 0; c < 3; ++c) {
        m->albedo[c] = unit(r);
        m->sigma_t[c] = flags & 2u ? real(r) : 0.25 + 4.0 * unit(r);
    }
    m->anisotropy = flags & 4u ? real(r) : 1.8 * unit(r) - 0.9;
}

static void op_kernels(reader *r)
{
    double albedo = unit(r), a = real(r), b = real(r), x = 0.0, y = 0.0;
    dwv_v0_method_t method = (dwv_v0_method_t)(byte(r) % 6u) - 1;
    float xf = 0.0f;
    dwv_diffusion_length_t d = DWV_DIFFUSION_LENGTH_INIT;
    prime();
    if (check(dwv_diffusion_length(albedo, method, &d), "dwv_diffusion_length"))
        require(d.kappa >= 0.0 && d.kappa <= 1.0 && d.v0 >= 1.0 && d.log_ratio >= 0.0 && !isnan(d.log_one_minus_kappa),
                "diffusion length output");
    prime();
    if (check(dwv_eigenfunction(albedo, a, b, &x), "dwv_eigenfunction")) require(x >= 0.0 && isfinite(x), "phi");
    prime();
    if (check(dwv_eigenfunction_integral(albedo, a, &x), "dwv_eigenfunction_integral"))
        require(x >= 0.0 && isfinite(x), "integral");
    dwv_dwivedi_t dist = DWV_DWIVEDI_INIT;
    prime();
    int have = check(dwv_dwivedi_init(&dist, albedo, method), "dwv_dwivedi_init");
    if (!have && (byte(r) & 1u)) {
        /* Hand the per-event calls a struct the fuzzer wrote. */
        for (size_t i = 0; i < sizeof dist; ++i) ((uint8_t *)&dist)[i] = byte(r);
    }
    dwv_dwivedi_sample_t s = DWV_DWIVEDI_SAMPLE_INIT;
    dwv_dwivedi_sample_f_t sf = DWV_DWIVEDI_SAMPLE_F_INIT;
    prime();
    if (check(dwv_dwivedi_sample_pdf(&dist, a, &s), "dwv_dwivedi_sample_pdf"))
        require(s.cos_theta >= -1.0 && s.cos_theta <= 1.0 && s.pdf > 0.0 && isfinite(s.pdf) && s.stretch > 0.0 &&
                    s.stretch <= 2.0, "dwivedi sample");
    prime();
    if (check(dwv_dwivedi_sample_pdf_f(&dist, (float)a, &sf), "dwv_dwivedi_sample_pdf_f"))
        require(sf.cos_theta >= -1.0f && sf.cos_theta <= 1.0f && sf.pdf > 0.0f && isfinite(sf.pdf) &&
                    sf.stretch > 0.0f && sf.stretch <= 2.0f, "dwivedi sample_f");
    prime();
    if (check(dwv_dwivedi_pdf(&dist, b, &x), "dwv_dwivedi_pdf")) require(x > 0.0 && isfinite(x), "dwivedi pdf");
    prime();
    if (check(dwv_dwivedi_pdf_f(&dist, (float)b, &xf), "dwv_dwivedi_pdf_f")) require(xf > 0.0f && isfinite(xf), "pdf_f");
    prime();
    if (check(dwv_dwivedi_stretch(&dist, b, &x), "dwv_dwivedi_stretch")) require(x > 0.0 && x <= 2.0, "stretch");
    prime();
    if (check(dwv_dwivedi_stretch_f(&dist, (float)b, &xf), "dwv_dwivedi_stretch_f"))
        require(xf > 0.0f && xf <= 2.0f, "stretch_f");
    prime();
    if (check(dwv_dwivedi_sample(&dist, b, &x), "dwv_dwivedi_sample")) require(x >= -1.0 && x <= 1.0, "sample");
    prime();
    if (check(dwv_dwivedi_sample_f(&dist, (float)b, &xf), "dwv_dwivedi_sample_f"))
        require(xf >= -1.0f && xf <= 1.0f, "sample_f");
    prime();
    if (check(dwv_hg_sample_pdf(a, b, &x, &y), "dwv_hg_sample_pdf"))
        require(x >= -1.0 && x <= 1.0 && y > 0.0 && isfinite(y), "hg");
    prime();
    if (check(dwv_hg_pdf_f((float)a, (float)b, &xf), "dwv_hg_pdf_f")) require(xf > 0.0f && isfinite(xf), "hg pdf_f");
    prime();
    if (check(dwv_hg_sample_f((float)a, (float)b, &xf), "dwv_hg_sample_f")) require(xf >= -1.0f && xf <= 1.0f, "hg_f");
    prime();
    if (check(dwv_exponential_sample(a, b, &x), "dwv_exponential_sample")) require(x >= 0.0 && isfinite(x), "flight");
    prime();
    if (check(dwv_exponential_pdf(a, b, &x), "dwv_exponential_pdf")) require(x >= 0.0 && isfinite(x), "flight pdf");
    prime();
    if (check(dwv_exponential_sample_f((float)a, (float)b, &xf), "dwv_exponential_sample_f"))
        require(xf >= 0.0f && isfinite(xf), "flight_f");
    prime();
    if (check(dwv_exponential_pdf_f((float)a, (float)b, &xf), "dwv_exponential_pdf_f"))
        require(xf >= 0.0f && isfinite(xf), "flight pdf_f");
    prime();
    if (check(dwv_isotropic_sample(a, &x), "dwv_isotropic_sample")) require(x >= -1.0 && x <= 1.0, "isotropic");
}

static void op_names(reader *r)
{
    char name[24];
    size_t n = byte(r) % sizeof name;
    for (size_t i = 0; i < n; ++i) name[i] = (char)byte(r);
    name[n] = '\0';
    dwv_technique_t t = 0;
    dwv_v0_method_t m = 0;
    prime();
    if (check_message(dwv_technique_from_name(name, &t), "dwv_technique_from_name", 0))
        require(dwv_technique_name(t) != NULL && strcmp(dwv_technique_name(t), name) == 0, "technique round trip");
    prime();
    if (check_message(dwv_v0_method_from_name(name, &m), "dwv_v0_method_from_name", 0))
        require(dwv_v0_method_name(m) != NULL, "method round trip");
    int32_t any = (int32_t)u32(r);
    require(dwv_result_string(any) != NULL, "result string");
    (void)dwv_technique_name(any);
    (void)dwv_v0_method_name(any);
}

static void op_estimate(reader *r)
{
    dwv_estimate_options_t o = DWV_ESTIMATE_OPTIONS_INIT;
    uint8_t flags = byte(r);
    if (flags & 0x80u) o.struct_size = u32(r);
    o.shape = flags & 0x40u ? (dwv_shape_t)u32(r) : (dwv_shape_t)(byte(r) % 3u);
    o.thickness = flags & 1u ? real(r) : 0.01 + 8.0 * unit(r);
    o.radius = flags & 2u ? real(r) : 0.01 + 8.0 * unit(r);
    medium_from(r, &o.medium);
    o.incidence = flags & 4u ? (dwv_incidence_t)u32(r) : (dwv_incidence_t)(byte(r) & 1u);
    o.incidence_cosine = flags & 8u ? real(r) : unit(r);
    o.light = flags & 0x10u ? (dwv_light_t)u32(r) : (dwv_light_t)(1 + byte(r) % 3u);
    o.technique = flags & 0x20u ? (dwv_technique_t)u32(r) : (dwv_technique_t)(byte(r) % (DWV_TECHNIQUE_SHEET + 1u));
    /* Tiny runs, but the count itself may be absurd when it is refused: only valid counts run. */
    uint8_t count = byte(r);
    o.walks = count < 200u ? 2u + count % 24u : u64(r);
    if (o.walks > 64u && o.walks <= 1000000000000ull) o.walks = 64u;
    o.seed = u64(r);
    o.threads = byte(r) < 240u ? 1u + (byte(r) & 1u) : u32(r);
    if (o.threads > 2u && o.threads <= 256u) o.threads = 2u;
    o.max_events = 1u + byte(r) % 200u;
    dwv_estimate_result_t res = DWV_ESTIMATE_RESULT_INIT;
    prime();
    if (check(dwv_estimate(&o, &res), "dwv_estimate")) {
        for (uint32_t c = 0; c < res.channels; ++c)
            require(isfinite(res.mean[c]) && res.mean[c] >= 0.0 && isfinite(res.variance[c]) && res.variance[c] >= 0.0 &&
                        isfinite(res.truncated_weight[c]) && res.truncated_weight[c] >= 0.0,
                    "estimate output");
        require(res.walks == o.walks && (res.channels == 1u || res.channels == 3u), "estimate counts");
    }
}

static void vec(reader *r, double v[3], int unit_length)
{
    uint8_t how = byte(r);
    if (how < 200u && unit_length) {
        /* A valid unit vector most of the time: from two angles. */
        double z = 2.0 * (byte(r) / 255.0) - 1.0, phi = 6.283185307179586 * (byte(r) / 255.0);
        double s = sqrt(fmax(0.0, 1.0 - z * z));
        v[0] = s * cos(phi), v[1] = s * sin(phi), v[2] = z;
    } else if (how < 200u) {
        v[0] = 4.0 * unit(r) - 2.0, v[1] = 4.0 * unit(r) - 2.0, v[2] = 4.0 * unit(r);
    } else {
        v[0] = real(r), v[1] = real(r), v[2] = real(r);
    }
}

static void op_walk(reader *r)
{
    dwv_medium_t m;
    medium_from(r, &m);
    dwv_light_patch_t patches[17];
    uint32_t patch_count = byte(r) % 18u;
    for (uint32_t j = 0; j < patch_count; ++j) {
        patches[j] = (dwv_light_patch_t)DWV_LIGHT_PATCH_INIT;
        uint8_t how = byte(r);
        if (how & 1u) patches[j].struct_size = u32(r);
        patches[j].is_plane = how & 2u;
        vec(r, patches[j].point, 0);
        vec(r, patches[j].normal, 1);
        patches[j].power = how & 4u ? real(r) : 0.1 + unit(r);
    }
    uint8_t t = byte(r);
    dwv_technique_t technique = t < 240u ? (dwv_technique_t)(t % (DWV_TECHNIQUE_SHEET + 1u)) : (dwv_technique_t)u32(r);
    dwv_walk_t *walk = NULL;
    prime();
    if (!check(dwv_walk_create(&m, technique, patch_count ? patches : NULL, patch_count, u64(r), 1u + byte(r) % 50u,
                               &walk),
               "dwv_walk_create")) {
        require(walk == NULL, "refused create left a handle");
        return;
    }
    require(walk != NULL, "create without a handle");
    /* A fuzzed sequence of steps, in or out of order; at most 64 calls. */
    double position[3] = {0.0, 0.0, 0.0};
    for (int call = 0; call < 64 && r->at < r->size; ++call) {
        uint8_t what = byte(r) % 5u;
        double a[3], b[3], c[3], distance = 0.0;
        int32_t needs = 0;
        dwv_walk_state_t state = DWV_WALK_STATE_INIT;
        prime();
        switch (what) {
        case 0:
            vec(r, a, 0), vec(r, b, 1);
            c[0] = 0.0, c[1] = 0.0, c[2] = -1.0;
            if (byte(r) & 1u) vec(r, c, 1);
            if (check(dwv_walk_begin(walk, u64(r), a, b, c), "dwv_walk_begin")) memcpy(position, a, sizeof a);
            break;
        case 1:
            vec(r, a, 1);
            check(dwv_walk_set_closest(walk, a), "dwv_walk_set_closest");
            break;
        case 2:
            if (check(dwv_walk_sample(walk, a, &distance), "dwv_walk_sample"))
                require(distance >= 0.0 && !isnan(distance) && isfinite(a[0] + a[1] + a[2]), "walk sample");
            break;
        case 3: {
            double hit = byte(r) & 1u ? real(r) : 2.0 * unit(r);
            vec(r, a, 1);
            if (check(dwv_walk_report(walk, hit, byte(r) & 1u ? a : NULL, &state), "dwv_walk_report")) {
                require(state.status >= DWV_WALK_RUNNING && state.status <= DWV_WALK_TRUNCATED, "walk status");
                for (int k = 0; k < 3; ++k)
                    require(isfinite(state.weight[k]) && state.weight[k] >= 0.0 && !isnan(state.position[k]),
                            "walk state");
            }
            break;
        }
        default:
            check(dwv_walk_needs_closest(walk, &needs), "dwv_walk_needs_closest");
            if (byte(r) & 1u) {
                check(dwv_walk_retain(walk), "dwv_walk_retain");
                dwv_walk_release(walk);
            }
            break;
        }
    }
    dwv_walk_release(walk);
}

/* One entry point with one of its pointer arguments NULL (the others valid or fuzzed): refused. */
static void op_null(reader *r)
{
    uint8_t which = byte(r);
    double a = real(r), x = 0.0;
    float xf = 0.0f;
    dwv_dwivedi_t dist = DWV_DWIVEDI_INIT;
    (void)dwv_dwivedi_init(&dist, unit(r), DWV_V0_EXACT);
    dwv_estimate_options_t o = DWV_ESTIMATE_OPTIONS_INIT;
    dwv_estimate_result_t res = DWV_ESTIMATE_RESULT_INIT;
    dwv_medium_t m = DWV_MEDIUM_INIT;
    dwv_walk_t *walk = NULL;
    dwv_image_t *image = NULL;
    int32_t needs = 0;
    const double v[3] = {0.0, 0.0, 1.0};
    dwv_result_t code;
    prime();
    switch (which % 16u) {
    case 0: code = dwv_diffusion_length(a, DWV_V0_EXACT, NULL); break;
    case 1: code = dwv_dwivedi_sample(which & 16u ? &dist : NULL, a, which & 16u ? NULL : &x); break;
    case 2: code = dwv_dwivedi_pdf_f(which & 16u ? &dist : NULL, (float)a, which & 16u ? NULL : &xf); break;
    case 3: code = dwv_dwivedi_sample_pdf(which & 16u ? &dist : NULL, a, NULL); break;
    case 4: code = dwv_hg_sample_pdf(a, a, which & 16u ? &x : NULL, which & 16u ? NULL : &x); break;
    case 5: code = dwv_exponential_sample_f((float)a, (float)a, NULL); break;
    case 6: code = dwv_eigenfunction(a, a, a, NULL); break;
    case 7: code = dwv_estimate(which & 16u ? &o : NULL, which & 16u ? NULL : &res); break;
    case 8: code = dwv_walk_create(which & 16u ? &m : NULL, DWV_TECHNIQUE_AUTO, NULL, 1u, 0, 0,
                                   which & 32u ? &walk : NULL); break;
    case 9: code = dwv_walk_begin(NULL, 0, v, v, v); break;
    case 10: code = dwv_walk_sample(NULL, NULL, NULL); break;
    case 11: code = dwv_walk_report(NULL, a, NULL, NULL); break;
    case 12: code = dwv_walk_needs_closest(NULL, &needs); break;
    case 13: code = dwv_image_create(1u + byte(r), 1u + byte(r), NULL, which & 16u ? &image : NULL); break;
    case 14: code = dwv_random_uniform(u64(r), u64(r), u64(r), u32(r), NULL); break;
    default: code = dwv_technique_from_name(NULL, NULL); break;
    }
    require(code != DWV_SUCCESS && walk == NULL && image == NULL, "a NULL pointer was accepted");
    check(code, "a call with a NULL pointer");
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader r = {data, size, 0};
    for (int op = 0; op < 8 && r.at < r.size; ++op) {
        switch (byte(&r) % 5u) {
        case 0: op_kernels(&r); break;
        case 1: op_names(&r); break;
        case 2: op_estimate(&r); break;
        case 3: op_walk(&r); break;
        default: op_null(&r); break;
        }
    }
    return 0;
}
