/* dwvb_pilot_group_variance (src/bake/pilot.c), the variance auto's pilot ranks its candidates by:
 * that of a pixel's mean over its stratified samples, as the image has it, not that of one sample.
 * Two integrands stand in for two candidates, drawn as a bake draws a pixel's samples (sample s
 * of a pixel in replicate s mod 2 with its own scramble, index s / 2: dwvb_bake_sample) from the
 * pixel's first stratified pair (kernel/sampler.h), GROUP samples per pixel, PIXELS pixels:
 * - smooth: 4 u0 u1, whose one-sample variance is 7/9 but which the (0,2)-sequence integrates well
 *   (the pixel position, entry and light points of a bake are such dimensions);
 * - noisy: 1 + a (2 r - 1) with r an independent uniform (the walk's later events), of variance
 *   a^2 / 3 = NOISY_VARIANCE, which stratification cannot lower.
 * Checked:
 *   1. The groups' mean estimate is the variance per sample in the image: for the smooth one
 *      against GROUP x the pixel means' squared error (both means are exactly 1, so that is
 *      unbiased too) over other pixels, within SIGMAS standard errors of the difference; for the
 *      noisy one against a^2 / 3, within SIGMAS standard errors. Planted: the two replicates drawn
 *      with the same scramble (one stratified set, not two independent ones) must fail the first
 *      comparison (checked in every run: the estimate then measures the spread between the two
 *      halves of one net, 1.22 against the image's 0.110, over 100 standard errors off).
 *   2. The ranking: the groups put the smooth integrand's variance below the noisy one's (it is,
 *      in the image: 0.110 against 0.3), while the one-sample variance, what the pilot took
 *      before (docs/speed.md: the benchmark's bowl), puts it above (7/9 against 0.3), which is the
 *      case an i.i.d. pilot gets wrong.
 * Run time: about 0.15 s. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "bake/pilot.h"
#include "check.h"
#include "kernel/rng.h"
#include "kernel/sampler.h"

#define PIXELS 20000u
#define GROUP 8u
#define SIGMAS 5.0
#define NOISY_VARIANCE 0.3
#define SEED 11u

enum { SMOOTH, NOISY };

/* Sample s of pixel `pixel` (scramble `salt` apart from other runs) of the integrand `kind`. */
static double integrand(int kind, uint64_t salt, uint32_t pixel, uint32_t s, int planted)
{
    uint32_t replicate = planted ? 0u : s % 2u;
    dwvk_sampler sampler = {.key = dwvk_rng_key(SEED, salt | pixel, replicate), .index = planted ? s : s / 2u, .stratified = 1};
    double u[2];
    dwvk_sampler_pair(&sampler, 0u, u);
    if (kind == SMOOTH) return 4.0 * u[0] * u[1];
    double r = dwvk_rng_uniform_d(dwvk_rng_key(SEED, (salt | pixel) ^ 0x8000000000000000ull, s), 0u);
    return 1.0 + sqrt(3.0 * NOISY_VARIANCE) * (2.0 * r - 1.0);
}

typedef struct mean_error {
    double mean, error; /* the mean over pixels and its standard error */
} mean_error;

static mean_error summarise(double sum, double squares, double n)
{
    double mean = sum / n;
    return (mean_error){mean, sqrt(fmax(squares / n - mean * mean, 0.0) / (n - 1.0))};
}

/* The groups' estimate (dwvb_pilot_group_variance, averaged over pixels), GROUP x the squared
 * error of other pixels' means (the image's variance per sample), and the one-sample variance. */
static void measure(int kind, int planted, mean_error *groups, mean_error *image, double *one_sample)
{
    double sum = 0.0, squares = 0.0, image_sum = 0.0, image_squares = 0.0, all = 0.0, all_squares = 0.0;
    for (uint32_t p = 0; p < PIXELS; ++p) {
        double replicate_sums[2] = {0.0, 0.0}, pixel = 0.0;
        for (uint32_t s = 0; s < GROUP; ++s) {
            double x = integrand(kind, 0x100000000ull, p, s, planted);
            replicate_sums[s % 2u] += x;
            all += x;
            all_squares += x * x;
            pixel += integrand(kind, 0x200000000ull, p, s, 0) / GROUP; /* other pixels, the bake's way */
        }
        double v = dwvb_pilot_group_variance(replicate_sums, GROUP);
        sum += v;
        squares += v * v;
        double e = GROUP * (pixel - 1.0) * (pixel - 1.0);
        image_sum += e;
        image_squares += e * e;
    }
    *groups = summarise(sum, squares, PIXELS);
    *image = summarise(image_sum, image_squares, PIXELS);
    double n = (double)PIXELS * GROUP, mean = all / n;
    *one_sample = (all_squares / n - mean * mean) * n / (n - 1.0);
}

int main(void)
{
    mean_error smooth, smooth_image, noisy, noisy_image, planted, planted_image;
    double smooth_one, noisy_one, planted_one;
    measure(SMOOTH, 0, &smooth, &smooth_image, &smooth_one);
    measure(NOISY, 0, &noisy, &noisy_image, &noisy_one);
    measure(SMOOTH, 1, &planted, &planted_image, &planted_one);
    printf("smooth: groups %.4f +- %.4f, image %.4f +- %.4f, one sample %.4f\n", smooth.mean, smooth.error, smooth_image.mean,
           smooth_image.error, smooth_one);
    printf("noisy: groups %.4f +- %.4f, image %.4f +- %.4f, one sample %.4f (exact %.4f)\n", noisy.mean, noisy.error,
           noisy_image.mean, noisy_image.error, noisy_one, NOISY_VARIANCE);
    printf("planted (one scramble for both replicates): groups %.4f +- %.4f against the image's %.4f\n", planted.mean,
           planted.error, planted_image.mean);
    double bound = SIGMAS * hypot(smooth.error, smooth_image.error);
    CHECK(fabs(smooth.mean - smooth_image.mean) < bound, "smooth: groups %g, image %g (bound %g)", smooth.mean,
          smooth_image.mean, bound);
    CHECK(fabs(noisy.mean - NOISY_VARIANCE) < SIGMAS * noisy.error, "noisy: groups %g +- %g, exact %g", noisy.mean,
          noisy.error, NOISY_VARIANCE);
    CHECK(fabs(noisy_image.mean - NOISY_VARIANCE) < SIGMAS * noisy_image.error, "noisy: image %g +- %g, exact %g",
          noisy_image.mean, noisy_image.error, NOISY_VARIANCE);
    double planted_bound = SIGMAS * hypot(planted.error, planted_image.error);
    CHECK(!(fabs(planted.mean - planted_image.mean) < planted_bound),
          "planted: the rule should reject replicates sharing one scramble (groups %g, image %g, bound %g)", planted.mean,
          planted_image.mean, planted_bound);
    /* The ranking, each side well apart (their standard errors are a few percent of them). */
    CHECK(smooth.mean + SIGMAS * smooth.error < noisy.mean - SIGMAS * noisy.error,
          "groups should rank the smooth integrand first: %g against %g", smooth.mean, noisy.mean);
    CHECK(smooth_one > 1.5 * noisy_one, "one sample should rank the noisy integrand first: %g against %g", smooth_one,
          noisy_one);
    return check_report("test_pilot_groups");
}
