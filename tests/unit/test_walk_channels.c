/* Spectral MIS: a three-channel medium must give, per channel, what a grey medium with that
 * channel's extinction and albedo gives. In a three-channel walk the distance is sampled for one
 * channel (picked in proportion to throughput x albedo) and the direction guide is built from the
 * largest albedo, so every other channel is estimated through the mixture's pdf alone: a wrong
 * term in it shows as a channel that parts from its grey run. Within 5 sigma,
 * sigma = sqrt(se_rgb^2 + se_grey^2) (independent runs), for every technique on a front-lit
 * half-space, a back-lit slab and a front-lit sphere. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#define WALK_SEED_BASE 0xc4a10001u
#include "walk_harness.h"

#define SIGMAS 5.0
enum { WALKS = 60000, TECHNIQUES = DWV_TECHNIQUE_CYCLES + 1 };

/* Channels that differ in both: the guide comes from channel 0 (albedo 0.99), channel 1 scatters
 * twice as often, channel 2 half as often with a quarter of the walks' lifetime. */
static const double SIGMA_T[3] = {1.0, 2.0, 0.5};
static const double ALBEDO[3] = {0.99, 0.9, 0.6};

static const scene_t SCENES[] = {
    {"half-space, front", DWV_SHAPE_HALFSPACE, 0.0, DWV_LIGHT_FRONT},
    {"slab 2, back", DWV_SHAPE_SLAB, 2.0, DWV_LIGHT_BACK},
    {"sphere 2, front", DWV_SHAPE_SPHERE, 2.0, DWV_LIGHT_FRONT},
};

int main(void)
{
    printf("three channels (sigma_t %g %g %g, albedo %g %g %g) against grey runs (|z| <= %.0f)\n", SIGMA_T[0],
           SIGMA_T[1], SIGMA_T[2], ALBEDO[0], ALBEDO[1], ALBEDO[2], SIGMAS);
    printf("  %-18s %-9s %-2s %12s %10s %12s %10s %8s\n", "scene", "technique", "c", "rgb", "std error", "grey",
           "std error", "z");
    for (size_t s = 0; s < sizeof SCENES / sizeof SCENES[0]; ++s) {
        for (dwv_technique_t t = 0; t < TECHNIQUES; ++t) {
            dwv_estimate_options_t rgb = scene_options(&SCENES[s], t);
            rgb.medium.channels = 3;
            for (int c = 0; c < 3; ++c) rgb.medium.sigma_t[c] = SIGMA_T[c], rgb.medium.albedo[c] = ALBEDO[c];
            dwv_estimate_result_t r = estimate(rgb, WALKS);
            CHECK(r.channels == 3, "%s %s: %u channels", SCENES[s].name, dwv_technique_name(t), r.channels);
            for (int c = 0; c < 3; ++c) {
                dwv_estimate_options_t grey = scene_options(&SCENES[s], t);
                grey.medium.sigma_t[0] = SIGMA_T[c];
                grey.medium.albedo[0] = ALBEDO[c];
                dwv_estimate_result_t g = estimate(grey, WALKS);
                double z = difference_z(r.mean[c], r.std_error[c], g.mean[0], g.std_error[0]);
                printf("  %-18s %-9s %-2d %12.8f %10.3e %12.8f %10.3e %8.2f\n", SCENES[s].name, dwv_technique_name(t), c,
                       r.mean[c], r.std_error[c], g.mean[0], g.std_error[0], z);
                CHECK(fabs(z) <= SIGMAS, "%s %s channel %d: rgb %.8f +- %.3e, grey %.8f +- %.3e: z = %.2f",
                      SCENES[s].name, dwv_technique_name(t), c, r.mean[c], r.std_error[c], g.mean[0], g.std_error[0], z);
            }
        }
    }
    return check_report("test_walk_channels");
}
