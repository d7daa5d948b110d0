/* The thread-safety contract of capi/dwivedi.h (its top comment), tested:
 *   kernels      many threads calling every kernel at once get bit-identical results to one
 *                thread calling them alone;
 *   messages     each thread keeps its own last error message: threads fail with messages of
 *                their own, wait until all have failed, and each still reads its own;
 *   estimates    dwv_estimate runs on several threads at once (each with worker threads of its
 *                own) equal the same runs made one at a time with one worker thread (every
 *                field but the timings, bit for bit);
 *   walk handles one handle per thread: concurrent step-by-step walks equal single-threaded
 *                ones; retain/release of one shared handle (and of one shared image) from many
 *                threads at once neither frees it early nor leaks it (ASan, valgrind).
 * Public API only. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include <dwivedi.h>

enum { THREADS = 4, KERNEL_INPUTS = 2000, REFCOUNT_ROUNDS = 20000, WALK_STEPS_WALKS = 200 };

/* ---- kernels ------------------------------------------------------------------------------------ */

typedef struct kernel_out {
    dwv_diffusion_length_t length[4];
    dwv_dwivedi_sample_t sample;
    dwv_dwivedi_sample_f_t sample_f;
    double pdf, stretch, hg_cos, hg_pdf, distance, phi, integral;
    float pdf_f, stretch_f, hg_cos_f, distance_f;
    uint64_t bits;
    int32_t codes;
} kernel_out;

/* Every kernel at input i; the inputs come from the counter-based generator. */
static void kernel_calls(int i, kernel_out *out)
{
    memset(out, 0, sizeof *out);
    double albedo = 0.0, u = 0.0, mu = 0.0, g = 0.0;
    dwv_random_uniform(7, (uint64_t)i, 0, 0, &albedo);
    dwv_random_uniform(7, (uint64_t)i, 0, 1, &u);
    dwv_random_uniform(7, (uint64_t)i, 0, 2, &mu);
    dwv_random_uniform(7, (uint64_t)i, 0, 3, &g);
    mu = 2.0 * mu - 1.0;
    g = 1.8 * g - 0.9;
    int32_t codes = 0;
    for (int m = 0; m < 4; ++m) {
        out->length[m] = (dwv_diffusion_length_t)DWV_DIFFUSION_LENGTH_INIT;
        codes += dwv_diffusion_length(albedo, m, &out->length[m]);
    }
    dwv_dwivedi_t dist = DWV_DWIVEDI_INIT;
    codes += dwv_dwivedi_init(&dist, albedo, (dwv_v0_method_t)(i % 4));
    out->sample = (dwv_dwivedi_sample_t)DWV_DWIVEDI_SAMPLE_INIT;
    out->sample_f = (dwv_dwivedi_sample_f_t)DWV_DWIVEDI_SAMPLE_F_INIT;
    codes += dwv_dwivedi_sample_pdf(&dist, u, &out->sample);
    codes += dwv_dwivedi_sample_pdf_f(&dist, (float)u, &out->sample_f);
    codes += dwv_dwivedi_pdf(&dist, mu, &out->pdf);
    codes += dwv_dwivedi_stretch(&dist, mu, &out->stretch);
    codes += dwv_dwivedi_pdf_f(&dist, (float)mu, &out->pdf_f);
    codes += dwv_dwivedi_stretch_f(&dist, (float)mu, &out->stretch_f);
    codes += dwv_hg_sample_pdf(g, u, &out->hg_cos, &out->hg_pdf);
    codes += dwv_hg_sample_f((float)g, (float)u, &out->hg_cos_f);
    codes += dwv_exponential_sample(1.0 + albedo, u, &out->distance);
    codes += dwv_exponential_sample_f((float)(1.0 + albedo), (float)u, &out->distance_f);
    codes += dwv_eigenfunction(albedo, 1.5, mu, &out->phi);
    codes += dwv_eigenfunction_integral(albedo, 1.5, &out->integral);
    codes += dwv_random_u64((uint64_t)i, 1, 2, 3, &out->bits);
    out->codes = codes;
}

static kernel_out kernel_reference[KERNEL_INPUTS];
static pthread_barrier_t barrier;

typedef struct thread_arg {
    int index;
    int kernel_mismatches, kernel_failures;
    int message_ok;
    char message[600];
} thread_arg;

static void *kernel_thread(void *p)
{
    thread_arg *arg = p;
    /* Start together, so that the calls overlap. */
    pthread_barrier_wait(&barrier);
    for (int k = 0; k < KERNEL_INPUTS; ++k) {
        int i = (k + arg->index * 397) % KERNEL_INPUTS; /* each thread in its own order */
        kernel_out out;
        kernel_calls(i, &out);
        arg->kernel_failures += out.codes != 0;
        arg->kernel_mismatches += memcmp(&out, &kernel_reference[i], sizeof out) != 0;
    }
    /* Each thread fails with a name of its own, waits until every thread has failed, and must
     * still read its own message. */
    char name[64];
    snprintf(name, sizeof name, "thread-%d-technique", arg->index);
    dwv_technique_t t;
    (void)dwv_technique_from_name(name, &t);
    pthread_barrier_wait(&barrier);
    double x;
    (void)dwv_isotropic_sample(0.5, &x); /* a success leaves the message alone */
    snprintf(arg->message, sizeof arg->message, "%s", dwv_last_error_message());
    arg->message_ok = strstr(arg->message, name) != NULL;
    return NULL;
}

static void test_kernels_and_messages(void)
{
    for (int i = 0; i < KERNEL_INPUTS; ++i) kernel_calls(i, &kernel_reference[i]);
    int failures = 0;
    for (int i = 0; i < KERNEL_INPUTS; ++i) failures += kernel_reference[i].codes != 0;
    CHECK(failures == 0, "%d of %d single-threaded kernel inputs failed", failures, KERNEL_INPUTS);

    pthread_t ids[THREADS];
    thread_arg args[THREADS];
    pthread_barrier_init(&barrier, NULL, THREADS);
    for (int t = 0; t < THREADS; ++t) {
        memset(&args[t], 0, sizeof args[t]);
        args[t].index = t;
        CHECK(pthread_create(&ids[t], NULL, kernel_thread, &args[t]) == 0, "pthread_create %d", t);
    }
    for (int t = 0; t < THREADS; ++t) pthread_join(ids[t], NULL);
    pthread_barrier_destroy(&barrier);
    for (int t = 0; t < THREADS; ++t) {
        CHECK(args[t].kernel_mismatches == 0 && args[t].kernel_failures == 0,
              "thread %d: %d of %d kernel results differ from one thread's, %d failed", t, args[t].kernel_mismatches,
              KERNEL_INPUTS, args[t].kernel_failures);
        CHECK(args[t].message_ok, "thread %d reads another thread's message: '%s'", t, args[t].message);
    }
    printf("kernels: %d threads x %d inputs, bit-identical to one thread; per-thread messages kept\n", THREADS,
           KERNEL_INPUTS);
}

/* ---- estimates ---------------------------------------------------------------------------------- */

enum { RUNS = 3 };

static dwv_estimate_options_t run_options(int which, uint32_t threads)
{
    dwv_estimate_options_t o = DWV_ESTIMATE_OPTIONS_INIT;
    o.threads = threads;
    o.seed = 1000u + (uint64_t)which;
    switch (which) {
    case 0:
        o.shape = DWV_SHAPE_HALFSPACE, o.medium.albedo[0] = 0.95, o.technique = DWV_TECHNIQUE_AUTO, o.walks = 4000;
        break;
    case 1:
        o.shape = DWV_SHAPE_SLAB, o.thickness = 2.0, o.medium.channels = 3, o.light = DWV_LIGHT_BOTH;
        o.medium.albedo[0] = 0.8, o.medium.albedo[1] = 0.95, o.medium.albedo[2] = 0.99;
        o.medium.sigma_t[1] = 0.5, o.incidence = DWV_INCIDENCE_DIFFUSE, o.technique = DWV_TECHNIQUE_BACKWARD;
        o.walks = 3000, o.max_events = 40;
        break;
    default:
        o.shape = DWV_SHAPE_SPHERE, o.radius = 1.5, o.medium.albedo[0] = 0.99, o.medium.anisotropy = 0.3;
        o.light = DWV_LIGHT_BACK, o.technique = DWV_TECHNIQUE_INCIDENT, o.walks = 3000;
        break;
    }
    return o;
}

/* Everything but the timings (seconds, efficiency). */
static int same_result(const dwv_estimate_result_t *a, const dwv_estimate_result_t *b)
{
    return a->channels == b->channels && memcmp(a->mean, b->mean, sizeof a->mean) == 0 &&
           memcmp(a->std_error, b->std_error, sizeof a->std_error) == 0 &&
           memcmp(a->variance, b->variance, sizeof a->variance) == 0 && a->walks == b->walks &&
           a->events == b->events && memcmp(a->truncated_weight, b->truncated_weight, sizeof a->truncated_weight) == 0 &&
           a->truncated_walks == b->truncated_walks;
}

static dwv_estimate_result_t estimate_reference[RUNS];

typedef struct estimate_arg {
    int index;
    int mismatches, failures;
} estimate_arg;

static void *estimate_thread(void *p)
{
    estimate_arg *arg = p;
    pthread_barrier_wait(&barrier);
    for (int k = 0; k < RUNS; ++k) {
        int which = (k + arg->index) % RUNS;
        dwv_estimate_options_t o = run_options(which, 2u);
        dwv_estimate_result_t r = DWV_ESTIMATE_RESULT_INIT;
        if (dwv_estimate(&o, &r) != DWV_SUCCESS) {
            ++arg->failures;
            continue;
        }
        arg->mismatches += !same_result(&r, &estimate_reference[which]);
    }
    return NULL;
}

static void test_estimates(void)
{
    for (int which = 0; which < RUNS; ++which) {
        dwv_estimate_options_t o = run_options(which, 1u);
        estimate_reference[which] = (dwv_estimate_result_t)DWV_ESTIMATE_RESULT_INIT;
        CHECK(dwv_estimate(&o, &estimate_reference[which]) == DWV_SUCCESS, "reference %d: %s", which,
              dwv_last_error_message());
        CHECK(estimate_reference[which].mean[0] > 0.0, "reference %d scored nothing", which);
    }
    pthread_t ids[THREADS];
    estimate_arg args[THREADS];
    pthread_barrier_init(&barrier, NULL, THREADS);
    for (int t = 0; t < THREADS; ++t) {
        memset(&args[t], 0, sizeof args[t]);
        args[t].index = t;
        CHECK(pthread_create(&ids[t], NULL, estimate_thread, &args[t]) == 0, "pthread_create %d", t);
    }
    for (int t = 0; t < THREADS; ++t) pthread_join(ids[t], NULL);
    pthread_barrier_destroy(&barrier);
    for (int t = 0; t < THREADS; ++t)
        CHECK(args[t].mismatches == 0 && args[t].failures == 0,
              "thread %d: %d of %d concurrent estimates differ from the single-threaded ones, %d failed", t,
              args[t].mismatches, RUNS, args[t].failures);
    printf("estimates: %d threads x %d runs (2 workers each) equal the one-worker runs\n", THREADS, RUNS);
}

/* ---- walk handles and images -------------------------------------------------------------------- */

/* Walks index 0..WALK_STEPS_WALKS-1 on a half-space (exit where z < 0), step by step; a checksum of
 * every reported state. */
static int walk_checksum(dwv_walk_t *walk, double *sum)
{
    const double point[3] = {0.0, 0.0, 0.0}, direction[3] = {0.0, 0.0, 1.0}, normal[3] = {0.0, 0.0, -1.0};
    *sum = 0.0;
    for (uint64_t index = 0; index < WALK_STEPS_WALKS; ++index) {
        if (dwv_walk_begin(walk, index, point, direction, normal) != DWV_SUCCESS) return -1;
        dwv_walk_state_t state = DWV_WALK_STATE_INIT;
        double position[3] = {0.0, 0.0, 0.0};
        do {
            double d[3], distance;
            if (dwv_walk_sample(walk, d, &distance) != DWV_SUCCESS) return -1;
            double hit = d[2] < 0.0 ? fmax(position[2], 0.0) / -d[2] : INFINITY;
            if (dwv_walk_report(walk, hit, normal, &state) != DWV_SUCCESS) return -1;
            memcpy(position, state.position, sizeof position);
        } while (state.status == DWV_WALK_RUNNING);
        *sum += state.weight[0] + 1e-3 * state.events + state.position[0];
    }
    return 0;
}

static dwv_walk_t *shared_walk;
static dwv_image_t *shared_image;
static double walk_reference;

typedef struct handle_arg {
    int failures, mismatches;
} handle_arg;

static void *handle_thread(void *p)
{
    handle_arg *arg = p;
    pthread_barrier_wait(&barrier);
    for (int i = 0; i < REFCOUNT_ROUNDS; ++i) {
        arg->failures += dwv_walk_retain(shared_walk) != DWV_SUCCESS;
        arg->failures += dwv_image_retain(shared_image) != DWV_SUCCESS;
        dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
        if (i % 64 == 0)
            arg->failures += dwv_image_info(shared_image, &info) != DWV_SUCCESS || info.width != 2 || info.rgba[5] != 0.25f;
        dwv_walk_release(shared_walk);
        dwv_image_release(shared_image);
    }
    /* A walk handle of this thread's own, stepped while the other threads step theirs. */
    dwv_medium_t m = DWV_MEDIUM_INIT;
    m.albedo[0] = 0.9;
    dwv_walk_t *own = NULL;
    double sum = 0.0;
    if (dwv_walk_create(&m, DWV_TECHNIQUE_POE, NULL, 0, 5, 0, &own) != DWV_SUCCESS || walk_checksum(own, &sum) != 0)
        ++arg->failures;
    else
        arg->mismatches += sum != walk_reference;
    dwv_walk_release(own);
    return NULL;
}

static void test_handles(void)
{
    dwv_medium_t m = DWV_MEDIUM_INIT;
    m.albedo[0] = 0.9;
    dwv_walk_t *reference_walk = NULL;
    CHECK(dwv_walk_create(&m, DWV_TECHNIQUE_POE, NULL, 0, 5, 0, &reference_walk) == DWV_SUCCESS &&
              walk_checksum(reference_walk, &walk_reference) == 0,
          "reference walks: %s", dwv_last_error_message());
    dwv_walk_release(reference_walk);
    CHECK(dwv_walk_create(&m, DWV_TECHNIQUE_CLASSICAL, NULL, 0, 0, 0, &shared_walk) == DWV_SUCCESS, "create: %s",
          dwv_last_error_message());
    float pixels[8] = {0.0f, 0.0f, 0.0f, 1.0f, 0.5f, 0.25f, 0.125f, 1.0f};
    CHECK(dwv_image_create(2, 1, pixels, &shared_image) == DWV_SUCCESS, "image: %s", dwv_last_error_message());
    if (!shared_walk || !shared_image) return;

    pthread_t ids[THREADS];
    handle_arg args[THREADS];
    pthread_barrier_init(&barrier, NULL, THREADS);
    for (int t = 0; t < THREADS; ++t) {
        memset(&args[t], 0, sizeof args[t]);
        CHECK(pthread_create(&ids[t], NULL, handle_thread, &args[t]) == 0, "pthread_create %d", t);
    }
    for (int t = 0; t < THREADS; ++t) pthread_join(ids[t], NULL);
    pthread_barrier_destroy(&barrier);
    for (int t = 0; t < THREADS; ++t)
        CHECK(args[t].failures == 0 && args[t].mismatches == 0,
              "thread %d: %d failed calls, concurrent walk checksum differs: %d", t, args[t].failures,
              args[t].mismatches);
    /* Still alive with one reference each: usable, then freed by the last release. */
    double sum = 0.0;
    CHECK(dwv_walk_begin(shared_walk, 0, (const double[3]){0, 0, 0}, (const double[3]){0, 0, 1},
                         (const double[3]){0, 0, -1}) == DWV_SUCCESS && walk_checksum(shared_walk, &sum) == 0,
          "the shared walk after %d x %d retain/release pairs: %s", THREADS, REFCOUNT_ROUNDS, dwv_last_error_message());
    dwv_image_info_t info = DWV_IMAGE_INFO_INIT;
    CHECK(dwv_image_info(shared_image, &info) == DWV_SUCCESS && info.rgba[4] == 0.5f, "the shared image");
    dwv_walk_release(shared_walk);
    dwv_image_release(shared_image);
    printf("handles: %d threads x %d retain/release pairs on one walk and one image; concurrent walks on own "
           "handles equal one thread's\n", THREADS, REFCOUNT_ROUNDS);
}

int main(void)
{
    test_kernels_and_messages();
    test_estimates();
    test_handles();
    return check_report("test_thread_safety");
}
