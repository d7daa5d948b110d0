/* The expected exit (dwvw_walk_exit_factor, dwvw_walk_stay_inside in src/walk/walk.c), the
 * estimator of src/bake/shade.c run_walk_expected_exit, driven here in an analytic slab
 * 0 <= z <= D (no Embree: the surface distance along a direction is (D - z) / w_z or z / -w_z).
 *
 * 1. The factor against its direct evaluation: after each sampled step of walks with classical,
 *    incident and mixed directions in a coloured medium, factor_c must equal
 *        (weight dwvw_walk_complete gives on leaving at s) x P(exit | w),
 *        P(exit | w) = sum_k Q_k p_k(w) sum_c P_c exp(-sigma_c s_k s) / sum_k Q_k p_k(w),
 *    written out in long double; dwvw_walk_stay_inside must return the same P(exit | w), scale
 *    the weights by 1 - P(exit | w) and put the flight inside.
 * 2. Unbiasedness: the slab's transmittance (walks enter at the top, a light below: back-lit) and
 *    reflectance (front-lit), scored by the exit the walk makes and by the expected exit (at the
 *    first event only, and at every event), agree within Z_MAX standard errors of the difference,
 *    per channel, for a grey thin slab, a coloured one and a thick front-lit one, with classical
 *    and incident directions.
 * 3. Variance: on the thin back-lit grey slab (1 mean free path, albedo 0.95), the expected exit
 *    at every event must have less than VARIANCE_RATIO_MAX of the sampled exit's variance per walk
 *    (measured 0.34 classical, 0.40 incident, see the output); at the first event only, less than
 *    FIRST_RATIO_MAX (measured 0.58 and 0.64).
 * A planted error (the factor without the 1 / p_dir of the direction) must break check 2. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "kernel/rng.h"
#include "walk/walk.h"

#define FACTOR_TOLERANCE 1e-11
#define WALKS 100000u
#define Z_MAX 4.5
#define VARIANCE_RATIO_MAX 0.6
#define FIRST_RATIO_MAX 0.8
#define ALL_EVENTS 1000000u

typedef struct slab_setup {
    dwvw_medium medium;
    dwvw_guide guide;
    double depth;
    int back_lit; /* score exits through the bottom (z = 0), else through the top */
} slab_setup;

static double surface_distance(const slab_setup *slab, dwvw_vec3 p, dwvw_vec3 w, dwvw_vec3 *normal)
{
    if (w.z < 0.0) {
        *normal = dwvw_v(0.0, 0.0, -1.0);
        return fmax(p.z, 0.0) / -w.z;
    }
    *normal = dwvw_v(0.0, 0.0, 1.0);
    return w.z > 0.0 ? fmax(slab->depth - p.z, 0.0) / w.z : INFINITY;
}

static void begin(const slab_setup *slab, dwvw_walk *walk, uint64_t key)
{
    /* Cosine-weighted entry about -z at the top, as dwvb_shade's diffuse transmission. */
    double u1 = dwvk_rng_uniform_d(key, 1000u), u2 = dwvk_rng_uniform_d(key, 1001u);
    double mu = sqrt(u1), sine = sqrt(1.0 - u1), phi = 6.283185307179586 * u2;
    dwvw_vec3 inward = dwvw_v(sine * cos(phi), sine * sin(phi), -mu);
    dwvw_walk_begin(walk, &slab->medium, &slab->guide, key, 100000u, dwvw_v(0.0, 0.0, slab->depth), inward,
                    dwvw_v(0.0, 0.0, 1.0));
}

static int lit(const slab_setup *slab, dwvw_vec3 normal)
{
    return slab->back_lit ? normal.z < 0.0 : normal.z > 0.0;
}

/* One walk's score per channel: the first `expected_events` events score the expected exit
 * through the lit face and keep the flight inside, later ones the exit the walk makes.
 * planted: the factor is off by p_dir (for the planted-error check). */
static void walk_score(const slab_setup *slab, uint64_t key, uint32_t expected_events, int planted, double score[3])
{
    dwvw_walk walk;
    begin(slab, &walk, key);
    score[0] = score[1] = score[2] = 0.0;
    while (walk.status == DWVW_RUNNING) {
        dwvw_walk_sample(&walk);
        dwvw_vec3 normal;
        double s = surface_distance(slab, walk.position, walk.direction, &normal);
        if (walk.events < expected_events && s < INFINITY) {
            double factor[DWVW_MAX_CHANNELS];
            dwvw_walk_exit_factor(&walk, s, factor);
            double p_dir = 0.0;
            for (int k = 0; k < walk.component_count; ++k) p_dir += walk.component_q[k] * walk.component_pdf[k];
            if (lit(slab, normal))
                for (int c = 0; c < 3; ++c) score[c] += factor[c] * (planted ? p_dir * 4.0 * 3.14159265358979 : 1.0);
            dwvw_walk_stay_inside(&walk, s);
        }
        dwvw_walk_complete(&walk, s, normal);
        if (walk.status == DWVW_EXITED && lit(slab, walk.exit_normal))
            for (int c = 0; c < 3; ++c) score[c] += walk.weight[c];
    }
}

typedef struct moments {
    double sum[3], squares[3];
} moments;

static moments run(const slab_setup *slab, uint64_t stream, uint32_t expected_events, int planted)
{
    moments m;
    memset(&m, 0, sizeof m);
    for (uint32_t i = 0; i < WALKS; ++i) {
        double score[3];
        walk_score(slab, dwvk_rng_key(0xe417ull, stream, i), expected_events, planted, score);
        for (int c = 0; c < 3; ++c) {
            m.sum[c] += score[c];
            m.squares[c] += score[c] * score[c];
        }
    }
    return m;
}

static double mean_of(const moments *m, int c)
{
    return m->sum[c] / WALKS;
}

static double variance_of(const moments *m, int c)
{
    double mean = mean_of(m, c);
    return fmax(m->squares[c] / WALKS - mean * mean, 0.0) * WALKS / (WALKS - 1.0);
}

/* The largest |z| of the channels' mean differences. */
static double largest_z(const moments *a, const moments *b, int channels)
{
    double worst = 0.0;
    for (int c = 0; c < channels; ++c) {
        double se = sqrt((variance_of(a, c) + variance_of(b, c)) / WALKS);
        double z = se > 0.0 ? fabs(mean_of(a, c) - mean_of(b, c)) / se : (mean_of(a, c) == mean_of(b, c) ? 0.0 : INFINITY);
        worst = fmax(worst, z);
    }
    return worst;
}

static void make_slab(slab_setup *slab, int channels, const double *sigma, const double *albedo, double depth,
                      int back_lit, dwvw_technique technique)
{
    memset(slab, 0, sizeof *slab);
    dwvw_medium_init(&slab->medium, channels, sigma, albedo, 0.0);
    slab->depth = depth;
    slab->back_lit = back_lit;
    /* The lit face as an incident patch: a plane through it, its outward normal. */
    dwvw_light_patch patch = {dwvw_v(0.0, 0.0, back_lit ? 0.0 : depth), dwvw_v(0.0, 0.0, back_lit ? -1.0 : 1.0), 1.0,
                              0.0, 1};
    dwvw_guide_init(&slab->guide, technique, &slab->medium, &patch, 1);
}

/* 1. The factor and the cut flight against the direct evaluation. */
static void check_factor(void)
{
    const double sigma[3] = {1.0, 3.0, 10.0}, albedo[3] = {0.95, 0.8, 0.5};
    const dwvw_technique techniques[3] = {DWVW_CLASSICAL, DWVW_INCIDENT, DWVW_AUTO};
    double worst = 0.0, worst_stay = 0.0;
    uint64_t checked = 0;
    for (int t = 0; t < 3; ++t) {
        slab_setup slab;
        make_slab(&slab, 3, sigma, albedo, 2.0, 1, techniques[t]);
        for (uint32_t i = 0; i < 2000u; ++i) {
            dwvw_walk walk;
            begin(&slab, &walk, dwvk_rng_key(0xfac7ull, (uint64_t)t, i));
            while (walk.status == DWVW_RUNNING) {
                dwvw_walk_sample(&walk);
                dwvw_vec3 normal;
                double s = surface_distance(&slab, walk.position, walk.direction, &normal);
                double factor[DWVW_MAX_CHANNELS];
                dwvw_walk_exit_factor(&walk, s, factor);
                /* direct: the exit weight times P(exit | w) */
                dwvw_walk leaving = walk;
                leaving.step_distance = INFINITY;
                dwvw_walk_complete(&leaving, s, normal);
                CHECK(leaving.status == DWVW_EXITED, "the copy must leave");
                long double p = 0.0L, p_dir = 0.0L;
                for (int k = 0; k < walk.component_count; ++k) {
                    long double qp = (long double)walk.component_q[k] * walk.component_pdf[k];
                    p_dir += qp;
                    for (int c = 0; c < 3; ++c)
                        p += qp * walk.channel_p[c] * expl(-(long double)sigma[c] * walk.component_stretch[k] * s);
                }
                long double p_exit = p / p_dir;
                for (int c = 0; c < 3; ++c) {
                    long double direct = (long double)leaving.weight[c] * p_exit;
                    double scale = fmax(fabs((double)direct), 1e-300);
                    if (direct > 1e-250L || factor[c] > 1e-250) {
                        worst = fmax(worst, fabs((double)(factor[c] - direct)) / scale);
                        ++checked;
                    }
                }
                dwvw_walk inside = walk;
                double returned = dwvw_walk_stay_inside(&inside, s);
                worst_stay = fmax(worst_stay, fabs(returned - (double)p_exit));
                CHECK(inside.step_distance < s, "cut flight %.17g not inside %.17g", inside.step_distance, s);
                for (int c = 0; c < 3; ++c) {
                    double expected = walk.weight[c] * (1.0 - (double)p_exit);
                    CHECK(fabs(inside.weight[c] - expected) <= 1e-12 * fmax(fabs(expected), 1e-300) + 1e-300,
                          "stay-inside weight %.17g, expected %.17g", inside.weight[c], expected);
                }
                dwvw_walk_complete(&walk, s, normal);
            }
        }
    }
    printf("factor: %llu channel values, worst relative difference %.3g (bound %g); P(exit|w) worst %.3g\n",
           (unsigned long long)checked, worst, FACTOR_TOLERANCE, worst_stay);
    CHECK(checked > 10000u, "too few values checked (%llu)", (unsigned long long)checked);
    CHECK(worst <= FACTOR_TOLERANCE, "factor off its direct evaluation by %.3g", worst);
    CHECK(worst_stay <= 1e-13, "dwvw_walk_stay_inside's P(exit|w) off by %.3g", worst_stay);
}

/* 2 and 3 on one setup: returns the variance ratios (every event, first event) of channel 0. */
static void check_setup(const char *name, const slab_setup *slab, uint64_t stream, double ratio[2])
{
    int channels = slab->medium.channels;
    moments sampled = run(slab, 3u * stream, 0u, 0);
    moments every = run(slab, 3u * stream + 1u, ALL_EVENTS, 0);
    moments first = run(slab, 3u * stream + 2u, 1u, 0);
    double z_every = largest_z(&sampled, &every, channels), z_first = largest_z(&sampled, &first, channels);
    ratio[0] = variance_of(&every, 0) / variance_of(&sampled, 0);
    ratio[1] = variance_of(&first, 0) / variance_of(&sampled, 0);
    printf("%-28s mean R %.5f / %.5f / %.5f (sampled / every / first), |z| %.2f %.2f, variance ratio %.3f %.3f\n",
           name, mean_of(&sampled, 0), mean_of(&every, 0), mean_of(&first, 0), z_every, z_first, ratio[0], ratio[1]);
    CHECK(z_every <= Z_MAX, "%s: expected exit at every event differs by %.2f standard errors", name, z_every);
    CHECK(z_first <= Z_MAX, "%s: expected exit at the first event differs by %.2f standard errors", name, z_first);
}

int main(void)
{
    check_factor();
    const double grey_sigma[1] = {1.0}, grey_albedo[1] = {0.95};
    const double rgb_sigma[3] = {1.26, 2.5, 5.0}, rgb_albedo[3] = {0.99, 0.97, 0.9};
    const dwvw_technique techniques[2] = {DWVW_CLASSICAL, DWVW_INCIDENT};
    const char *names[2] = {"classical", "incident"};
    for (int t = 0; t < 2; ++t) {
        slab_setup slab;
        double ratio[2];
        char name[64];
        make_slab(&slab, 1, grey_sigma, grey_albedo, 1.0, 1, techniques[t]);
        snprintf(name, sizeof name, "grey 1 mfp back-lit %s", names[t]);
        check_setup(name, &slab, 10u + (uint64_t)t, ratio);
        CHECK(ratio[0] < VARIANCE_RATIO_MAX, "%s: variance ratio %.3f at every event", name, ratio[0]);
        CHECK(ratio[1] < FIRST_RATIO_MAX, "%s: variance ratio %.3f at the first event", name, ratio[1]);
        make_slab(&slab, 3, rgb_sigma, rgb_albedo, 1.0, 1, techniques[t]);
        snprintf(name, sizeof name, "coloured back-lit %s", names[t]);
        check_setup(name, &slab, 20u + (uint64_t)t, ratio);
        make_slab(&slab, 3, rgb_sigma, rgb_albedo, 8.0, 0, techniques[t]);
        snprintf(name, sizeof name, "coloured thick front-lit %s", names[t]);
        check_setup(name, &slab, 30u + (uint64_t)t, ratio);
    }
    /* Planted: without 1 / p_dir guided directions' expected exits are off, and must be caught. */
    slab_setup slab;
    make_slab(&slab, 1, grey_sigma, grey_albedo, 1.0, 1, DWVW_INCIDENT);
    moments sampled = run(&slab, 90u, 0u, 0), planted = run(&slab, 91u, ALL_EVENTS, 1);
    double z = largest_z(&sampled, &planted, 1);
    printf("planted (factor x p_dir x 4 pi): |z| %.1f\n", z);
    CHECK(z > Z_MAX, "the planted error was not caught (|z| %.2f)", z);
    return 0;
}
