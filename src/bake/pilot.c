/* Auto's pilot (pilot.h): the candidates, their counted cost, the pilot's run and the choice. */
#include "bake/pilot.h"

#include <math.h>
#include <stdlib.h>

#include "bake/guides.h"
#include "kernel/rng.h"
#include "util/vec3.h"

/* ---- auto: the technique that pays, per mesh --------------------------------------------------
 * Guiding lowers a walk's variance but costs work per event (a mixture of components, each with
 * a pdf and an exponential per channel pair); where the image's variance hardly moves that work
 * is wasted, and auto's small defensive classical share doubles the mixture's terms where guiding
 * alone would do (thin back-lit sheets). Before the first pass, a pilot shades the same pixel
 * samples with each candidate and keeps, per mesh, the one with the largest efficiency
 * 1 / (variance x cost) (Veach 1997, Sec. 2.4: the efficiency of an estimator; Hammersley and
 * Handscomb 1964). The candidates:
 * - classical sampling;
 * - Dwivedi sampling about the entry normal, toward the opposite interface where the first step
 *   found one (the backward technique; with no opposite interface it is the entry-normal
 *   technique, poe): on thick front-lit media its walks need 30% fewer events than classical ones
 *   at equal or lower variance (report's sphere: 17.4 against 24.3 events per walk), and on thin
 *   sheets it aims at the far face as well as the near one (slab: variance 0.61x poe's);
 * - the guided part of auto's mixture alone: toward the lit patches (incident), or the closest
 *   surface point where no light reaches the mesh;
 * - the sheet walk (walk.h, src/kernel/sheet.h), where light reaches some deciding mesh: toward
 *   the strongest lit patch with an importance linear in depth, the zero-variance walk of a thin
 *   sheet of albedo near 1, where Dwivedi's exponential is flat (the report's leaf: 7.5x less
 *   image variance than classical walks at equal samples, efficiency 3.3x-4.4x auto's earlier pick);
 * - each of these four with one walk per colour channel (channel walks, shade.h), where the
 *   medium's channels differ and the option leaves it to auto. A shared walk weighs every channel
 *   by the spectral MIS of all three; over many events the channels' weights then carry each
 *   other's pdfs and scatter widely. On the report's wax sphere (extinctions 2x and 5x apart) the
 *   image's variance per sample was 10x lower with one backward walk per channel, for 1.6x the
 *   time per sample (docs/speed.md); on the leaf (one extinction, albedos apart) it was not worth
 *   its cost. The pilot's variance is the three channels' together, as the image's RMSE over RGB
 *   counts it: the luminance hides the colour noise of shared walks. Candidates are ranked with
 *   one walk per channel; a channel-walk winner then gets the walks per sample of each channel
 *   that suit it (candidate_work).
 * Auto's mixture itself (the guided part plus a classical share of 1% or less) is no candidate:
 * its variance was that of the guided part alone within the pilot's noise and its cost above it,
 * so it won none of the pilots on the report's sphere, slab, leaf and default scene (both meshes)
 * and the example scenes (20 pilots, seeds 1-3 or 1-2); it stays the technique of meshes the pilot
 * cannot decide (too few samples). Every candidate is unbiased, so the choice moves noise, never
 * the mean.
 * The cost is counted, not timed, so that the choice (and the image) depends on the seed only:
 * instructions per sample (camera ray, shading), per walk (its probe, exit and exit lighting),
 * per walk event (the event's
 * sampling and weight), more per event of a walk with a guided component (every candidate but
 * classical: a Dwivedi direction's frame, sampling and pdf; 1.5x a classical event in the fit;
 * the sheet's events are priced so too, with its two components' mixture terms: 1.54x a
 * classical event on the leaf in the model, 1.37x per event in callgrind, walks included),
 * per Embree ray the walk casts (steps inside a ball clear of the mesh cast
 * none: shade.c run_walk), per closest-point query and per mixture term (see dwvb_tally). They
 * are a least-squares fit (relative residuals, coefficients >= 0) of callgrind's instruction
 * counts in the bake's workers, one thread, 32 x 32 pixels, 16 spp, over the report's sphere,
 * slab, leaf and default scene x classical, poe, backward, incident, closest and cycles, and
 * classical, backward and incident with channel walks: tools/fit_pilot_cost.py, which refits
 * them (rms residual 18.8%; the worst: closest, whose query's cost grows with the mesh, -40% and
 * -53% on the sphere and the default scene, and incident on the sphere, whose lit patches are
 * weighed per event, -28% shared and -46% with channel walks; docs/speed.md). Rays come out at
 * 0: with the ray-free steps and the box's plane exits they are about 0.5-0.7 per event in every
 * technique, so the event's cost holds theirs. One-thread bake times agreed where the machine was
 * quiet enough to measure (report's sphere, 32 x 32 pixels, 16 spp, best of 6: backward and poe
 * 1.3% and 5.4% faster than classical, instructions 5.0% and 7.1%, two refits ago); under load a
 * timed fit (--measure time) is not usable (rms 32%). Only their ratios matter. */
#define PILOT_COST_SAMPLE 4514.0
#define PILOT_COST_WALK 545.5
#define PILOT_COST_EVENT 754.1
#define PILOT_COST_GUIDED_EVENT 306.1
#define PILOT_COST_RAY 0.0
#define PILOT_COST_QUERY 6028.0
#define PILOT_COST_TERM 25.22
/* A ray of a path after the first scattering (indirect light, dwvb_tally.path_rays): its
 * intersection, the hit's direct light and what else a path vertex does beyond the walks counted
 * above. Not in the fit above, whose scenes trace no paths (tools/fit_pilot_cost.py holds it);
 * fitted alone (the other coefficients held) to the worker's instructions in callgrind on the
 * benchmark's bowl, 32 x 32 pixels, 16 spp, classical / backward / incident shared and classical /
 * backward with channel walks: 7,700-9,400 per path ray with channel walks, least squares 7,900
 * over the five. Without it the pilot priced channel walks, which send one path per channel where a
 * shared walk sends one, too low on concave scenes with indirect light: on the bowl 0.52-0.66 path
 * rays per sample with channel walks against 0.21-0.24 shared, and its model put backward with
 * channel walks at 8,774 instructions per sample where callgrind counted 13,851 (incident shared
 * 8,684 against 10,532). */
#define PILOT_COST_PATH_RAY 7900.0
/* Pilot samples per candidate: a sixteenth of the bake's samples, at most PILOT_MAX (the first
 * quarter of them for every candidate, the rest for those not clearly worse: pilot_survivors); below
 * PILOT_MIN the estimate is too noisy to act on and auto keeps its mixture. */
#define PILOT_MAX 4096u
#define PILOT_MIN 256u

/* The pilot's variance is the image's: that of a pixel's mean over its stratified samples, not
 * that of one sample. A pixel's samples are stratified (dwvb_bake_sample, kernel/sampler.h: pixel
 * position, entry, lights and the walk's first events), and stratification removes more variance
 * from some candidates than from others: on the benchmark's bowl, one sample per random pixel (the
 * pilot before) gave backward with channel walks 0.76x incident shared's variance, the 32-spp
 * images 1.10x, and auto took the wrong one (docs/speed.md). So the pilot shades pixel groups: a
 * random pixel's first G samples as the bake takes them (two stratified replicates, even and odd
 * samples, of G / 2 each, in a stream of the group's own), G the bake's samples per pixel up to
 * PILOT_GROUP_MAX; the group's variance per sample in the image is G / 4 (m0 - m1)^2 per channel,
 * m0 and m1 the replicates' means (their difference has twice a replicate mean's variance, the
 * pixel's mean half of it: as the bake's error estimate, pixel_sums.c), averaged over the groups.
 * Beyond PILOT_GROUP_MAX samples per pixel the pilot rates the variance at that many: a group's
 * estimate has one degree of freedom per channel, so the mean over groups is as noisy as their
 * count is small, and 8 samples (4 per replicate) caught most of what stratification moves in the
 * benchmark's 32-spp images (docs/speed.md: the relative efficiencies of the candidates within
 * about 0.1 of the images' on 11 scenes, where one sample per pixel had the shared walks 2x-4x too
 * high on the torus and the heads), at a quarter of the noise of 32 (with 32, test_bake_auto's
 * thin slab and wax sphere took their runner-up for seed 1). A group is at most a
 * PILOT_MIN_GROUPS-th of the pilot's samples, so that the mean over groups has some
 * PILOT_MIN_GROUPS terms; and a mesh needs PILOT_MESH_MIN_GROUPS groups that saw it to be decided
 * (in the first blocks where one candidate is left after them, which then is the pick).
 * Unlike one sample per pixel, the groups' estimate holds no spread of the pixels' means across the
 * image (the picture itself, the same for every candidate, which pulled the pilot's ratios toward
 * 1). */
#define PILOT_GROUP_MAX 8u
#define PILOT_MIN_GROUPS 64u
#define PILOT_MESH_MIN_GROUPS 16.0

/* The candidates, in the order of the pilot (a tie keeps the earlier, cheaper one): the four
 * techniques with the channels walked together, then the same with one walk per channel. */
#define PILOT_TECHNIQUES 4
#define PILOT_CANDIDATES (2 * PILOT_TECHNIQUES)
enum { PILOT_CLASSICAL = 0, PILOT_ENTRY = 1, PILOT_GUIDED = 2, PILOT_SHEET = 3 };

/* Auto's classical share at or below which the guided candidates drop it: the isotropic
 * defensive share, min(0.01, 0.1 sqrt(1 - alpha)) (dwvw_auto_weights). Above it auto raised the
 * share to |g| for an anisotropic medium, where the Dwivedi pdf misses the phase function's peak
 * and a guided walk's weight per event, phase / pdf, grows without that share to bound it (it is
 * at most 1 / share: Hesterberg's defensive mixture). Measured on a thin back-lit slab with
 * g = 0.8, 2048 pilot samples: guided alone had sample variances of 0.003 to 380 over three seeds
 * against classical's 0.23, so the pilot's estimate would pick it by chance. */
#define PILOT_ISOTROPIC_SHARE 0.01

/* The pilot's variance is a sample variance, and a heavy tail (rare samples of huge weight, where
 * the variance may be infinite) hides from it until its rare sample comes, which then makes most
 * of the sum of squares: the bent sheet's sheet walks before their fix had RMSE 0.38 against
 * classical's 0.008 in the bake, from one sample of weight 5,800, and won the pilot (docs/speed.md).
 * A candidate whose largest sample makes more than PILOT_TAIL_SHARE of its sum of squares (in any
 * channel), and more than PILOT_TAIL_RATIO times the share of classical's largest (classical
 * walks' weights are at most 1: a share that large in classical is the scene's, a bright pixel,
 * not the technique's), is not chosen. Only extreme tails: at 5% and 4x the test refused box_side's
 * backward walk (share 0.14 against classical's 0.014; the incident walk it took had 1.35x less
 * variance per sample) but at 48 px also the cylinder's pick, whose replacement had 5x more
 * (docs/speed.md); at 25% and 10x it changed no pick of the benchmark's sheet, box_side, bowl and
 * cylinder_front at 48 px, and refuses the sheet walk on the marble (shares 0.996 shared, 0.64
 * with channel walks, against classical's 0.001), where the variance estimate is one sample's. */
#define PILOT_TAIL_SHARE 0.25
#define PILOT_TAIL_RATIO 10.0

/* The standard errors of a candidate's difference from the best (pilot_survivors) that drop it. The
 * choice among the candidates left takes the estimates themselves: taking an upper bound on each
 * variance instead (2 standard errors) changed no pick on the benchmark's scenes at 48 x 48 pixels,
 * 32 spp, seeds 1-4, with the one-sample pilot (docs/speed.md). */
#define PILOT_CONFIDENCE 2.0
/* Of the PILOT_BLOCKS blocks, the first that every candidate runs (pilot_survivors). */
#define PILOT_FIRST_BLOCKS 16u

/* A surface is closed (dwvb_mesh_mean_chord) where its vector area is at most this share of its area
 * (rounding of float positions in double sums: far below it on the benchmark's closed meshes). */
#define PILOT_CLOSED_SURFACE 1e-6
/* The sheet walk's importance is linear in depth from the lit side (src/kernel/sheet.h): the
 * zero-variance walk of a sheet thin against the mean free path. On a solid much thicker than that
 * the importance rises through the whole solid, its walks run thousands of events (the marble:
 * ~3,000 against classical's 188) and the sheet candidates, which never won there, took up to half
 * of the whole bake in the pilot (docs/speed.md). They are not run on a mesh whose mean chord
 * (dwvb_mesh_mean_chord) exceeds this many mean free paths of its most transparent channel (1 /
 * the least sigma_t). The benchmark's meshes, in those units: leaf_textured 4.0, disc_back 4.7,
 * sheet 9.7, bowl 13, candle 16, box_side 25, cylinder_front 27, torus 50, heads 69, marble 167;
 * the sheet candidates win on the first two and come nowhere near winning from the torus on
 * (docs/speed.md). */
#define PILOT_SHEET_MAX_CHORD 32.0

/* Technique `technique` (PILOT_*) of the pilot for a mesh of `medium` whose guide auto made
 * (`mixture`: auto's mixture, or classical where the albedo is too low to guide). */
static void pilot_guide(const dwvb_bake *bake, uint32_t m, int technique, const dwvw_medium *medium,
                        const dwvw_guide *mixture, dwvw_guide *guide)
{
    const dwvb_scene *scene = bake->scene;
    if (technique == PILOT_CLASSICAL || mixture->q_classical >= 1.0) {
        dwvw_guide_init(guide, DWVW_CLASSICAL, medium, NULL, 0);
        return;
    }
    if (technique == PILOT_SHEET) { /* its own classical share, at least auto's (walk.h) */
        dwvw_guide_init(guide, DWVW_SHEET, medium, scene->patches[m], scene->patch_count[m]);
        return;
    }
    if (technique == PILOT_ENTRY) dwvw_guide_init(guide, DWVW_BACKWARD, medium, NULL, 0);
    else if (mixture->q_incident > 0.0)
        dwvw_guide_init(guide, DWVW_INCIDENT, medium, scene->patches[m], scene->patch_count[m]);
    else dwvw_guide_init(guide, DWVW_CLOSEST, medium, NULL, 0);
    if (mixture->q_classical > PILOT_ISOTROPIC_SHARE) { /* keep auto's defensive classical share */
        double guided = 1.0 - mixture->q_classical;
        guide->q_classical = mixture->q_classical;
        guide->q_backward *= guided;
        guide->q_incident *= guided;
        guide->q_closest *= guided;
    }
}

/* Candidate `candidate` for mesh m (auto's guides in bake): its guide, its channel guides and
 * whether its channels walk apart (a grey medium's one-channel walks walk once either way). */
static void pilot_candidate(const dwvb_bake *bake, uint32_t m, int candidate, dwvw_guide *guide,
                            dwvw_guide channel_guides[3], int *channel_walks)
{
    const dwvb_material *material = &bake->scene->shading[bake->scene->meshes[m].material_id];
    int technique = candidate % PILOT_TECHNIQUES;
    pilot_guide(bake, m, technique, &material->medium, &bake->guides[m], guide);
    *channel_walks = candidate >= PILOT_TECHNIQUES && !material->grey;
    for (int c = 0; c < 3; ++c)
        if (!material->grey && material->walk_scale[c] > 0.0)
            pilot_guide(bake, m, technique, &material->channel_medium[c], &bake->channel_guides[3u * m + (uint32_t)c],
                        &channel_guides[c]);
}

/* The mean chord length of a mesh's solid (pilot.h), 4 V / A (V its volume, A its surface area: Cauchy's
 * formula, the mean length inside the solid of uniform isotropic random lines that meet it; for
 * a non-convex solid each segment of a line inside counts as a chord, Dirac's chord theorem), or
 * -1 where the mesh does not bound a solid the formula can be trusted on: a surface that is not
 * closed (its vector area, the sum of its triangles' area vectors, is zero only for a closed
 * surface), a volume that is not positive (inward-facing triangles) or coordinates that are not
 * finite. V is the divergence theorem's sum of signed tetrahedra from the origin, in double
 * precision; on a closed surface it does not depend on the origin. A slab of thickness d has
 * chord 2 d, a sphere of radius r 4 r / 3. */
double dwvb_mesh_mean_chord(const dwvg_mesh *mesh)
{
    double volume = 0.0, area = 0.0, vector_area[3] = {0.0, 0.0, 0.0};
    for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
        const uint32_t *i = &mesh->indices[3u * t];
        const float *a = &mesh->positions[3u * i[0]], *b = &mesh->positions[3u * i[1]], *c = &mesh->positions[3u * i[2]];
        dwvu_vec3 pa = dwvu_v(a[0], a[1], a[2]), pb = dwvu_v(b[0], b[1], b[2]), pc = dwvu_v(c[0], c[1], c[2]);
        dwvu_vec3 n = dwvu_cross(dwvu_sub(pb, pa), dwvu_sub(pc, pa)); /* twice the area vector */
        volume += dwvu_dot(pa, dwvu_cross(pb, pc)) / 6.0;
        area += 0.5 * dwvu_length(n);
        vector_area[0] += 0.5 * n.x;
        vector_area[1] += 0.5 * n.y;
        vector_area[2] += 0.5 * n.z;
    }
    double open = sqrt(vector_area[0] * vector_area[0] + vector_area[1] * vector_area[1] + vector_area[2] * vector_area[2]);
    if (!(area > 0.0) || !isfinite(volume) || !(volume > 0.0) || !(open <= PILOT_CLOSED_SURFACE * area)) return -1.0;
    return 4.0 * volume / area;
}

/* Whether the sheet candidates may run for mesh m (PILOT_SHEET_MAX_CHORD): a lit side to aim at
 * (else they are classical walks) and a solid not far thicker than a mean free path, or one whose
 * thickness dwvb_mesh_mean_chord cannot tell. */
static int sheet_may_win(const dwvb_scene *scene, uint32_t m)
{
    if (scene->patch_count[m] <= 0) return 0;
    const dwvw_medium *medium = &scene->shading[scene->meshes[m].material_id].medium;
    double sigma_t = INFINITY;
    for (int c = 0; c < medium->channels; ++c) sigma_t = fmin(sigma_t, medium->sigma_t[c]);
    return !(dwvb_mesh_mean_chord(&scene->meshes[m]) * sigma_t > PILOT_SHEET_MAX_CHORD);
}

typedef struct pilot_sums {
    double count, sum_squares[3], largest[3], cost; /* over the samples that saw the mesh */
    double channel_cost[3]; /* of the cost, the channel walks' own, by channel */
    /* Over the pixel groups that saw the mesh: their count, and per channel the sum of their
     * variances per sample (dwvb_pilot_group_variance). */
    double groups, variance_sum[3];
} pilot_sums;

static uint64_t active_pixels(const dwvb_bake *bake)
{
    uint64_t pixels = (uint64_t)bake->width * bake->height, active = 0;
    for (uint64_t i = 0; i < pixels; ++i) active += (uint64_t)dwvb_bake_pixel_active(bake, (uint32_t)i);
    return active;
}

/* The pilot's pixel groups are cut into PILOT_BLOCKS fixed blocks that the bake's threads share;
 * each block sums its groups in order and the blocks are added in block order, so the sums, the
 * choice and the image are the same for any thread count. On one thread the pilot would be serial
 * work beside the passes (a few percent of a short bake: Amdahl's law on the 1 -> 2 thread
 * speed-up). */
#define PILOT_BLOCKS 64u

typedef struct pilot_run {
    dwvb_bake *bake;
    const dwvb_shader *shaders; /* indexed by candidate */
    const int *candidates;      /* the candidates run (PILOT_*), candidate_count of them */
    int candidate_count;
    pilot_sums *block_sums;     /* [block][candidate][mesh] */
    uint32_t groups, group_size, meshes; /* pixel groups of group_size samples (even, <= PILOT_GROUP_MAX) */
    /* Of the first blocks' groups (first_groups of them), each group's parts as kept for the
     * paired comparison of pilot_survivors: their meshes [group][part] (UINT32_MAX past the last)
     * and each candidate's variances [candidate][group][part][channel]; the parts are the same
     * for every candidate (the same camera rays). */
    uint32_t first_groups;
    uint32_t *first_meshes;
    double *first_variances;
    uint32_t end_block;         /* the blocks run: next_block's first value to end_block - 1 */
    atomic_uint next_block;
    atomic_int stopped;
} pilot_run;

/* A mesh's share of one pixel group: the sums of its samples' values in each replicate (samples
 * that saw another mesh or none add 0 to it: the mesh's part of the pixel's mean). */
typedef struct group_part {
    uint32_t mesh;
    double replicate_sum[3][REPLICATES]; /* [channel][replicate] */
} group_part;

/* pilot.h. size x the variance of the pixel's mean, estimated by (m0 - m1)^2 / 4 with m0, m1 the
 * replicates' means: they are independent with the same mean, so E (m0 - m1)^2 = 2 Var m_r, and
 * the mean of both has half Var m_r. */
double dwvb_pilot_group_variance(const double replicate_sums[REPLICATES], uint32_t size)
{
    double replicate = 0.5 * size, difference = (replicate_sums[0] - replicate_sums[1]) / replicate;
    return 0.25 * size * difference * difference;
}

static void *pilot_worker(void *arg)
{
    pilot_run *run = arg;
    dwvb_bake *bake = run->bake;
    uint64_t pixels = (uint64_t)bake->width * bake->height;
    group_part parts[PILOT_GROUP_MAX]; /* of one group, one per mesh its samples saw, in the order seen */
    /* The mesh each sample of the block counts for ([group - first][sample]; a block has at most
     * PILOT_MAX / 2 / PILOT_BLOCKS + 1 groups, of two samples or more). */
    uint32_t attributed[(PILOT_MAX / 2u / PILOT_BLOCKS + 1u) * PILOT_GROUP_MAX];
    for (;;) {
        uint32_t block = atomic_fetch_add(&run->next_block, 1u);
        if (block >= run->end_block || atomic_load(&run->stopped)) break;
        uint32_t first = (uint32_t)((uint64_t)run->groups * block / PILOT_BLOCKS);
        uint32_t end = (uint32_t)((uint64_t)run->groups * (block + 1u) / PILOT_BLOCKS);
        pilot_sums *sums = &run->block_sums[(size_t)block * PILOT_CANDIDATES * run->meshes];
        /* The same pixel samples for every candidate. */
        for (int k = 0; k < run->candidate_count; ++k) {
            int candidate = run->candidates[k];
            for (uint32_t g = first; g < end; ++g) {
                uint32_t index = (uint32_t)(dwvk_rng_u64(dwvk_rng_key(bake->options.seed, PILOT_STREAM, g), 0u) % pixels);
                if (!dwvb_bake_pixel_active(bake, index)) continue;
                /* A stream per group: a pixel drawn twice gets independent scrambles and walks.
                 * Bits 32-60, clear of the pixel index and the stream bits (g < PILOT_MAX). */
                uint64_t stream = PILOT_STREAM | (uint64_t)g << 32;
                uint32_t part_count = 0;
                for (uint32_t s = 0; s < run->group_size; ++s) {
                    if (dwvb_bake_must_stop(bake)) {
                        atomic_store(&run->stopped, 1);
                        return NULL;
                    }
                    double rgb[3], alpha;
                    dwvb_shade_parts shade_parts;
                    uint32_t mesh;
                    dwvb_tally tally = {0};
                    dwvb_bake_sample(bake, &run->shaders[candidate], stream, index, s, &shade_parts, rgb, &alpha, &mesh, &tally);
                    /* The sample counts for the deciding mesh its camera ray met, else for the one it
                     * walked first: a mirror's reflection of the mesh, the ground under it (on 5.2's
                     * test_indirect mirror scene the camera saw the sphere in 45 of 512 groups, and
                     * auto took classical shared in 6 of 8 seeds at 0.68 of incident separate's
                     * efficiency). As the first candidate run on the block found it, so that every
                     * candidate's groups have the same parts (pilot_survivors pairs them). */
                    uint32_t *counted = &attributed[(g - first) * run->group_size + s];
                    if (k == 0) {
                        uint32_t walked = tally.first_walk_mesh - 1u; /* UINT32_MAX: none */
                        *counted = mesh != UINT32_MAX && bake->auto_choice[mesh] ? mesh
                                   : walked != UINT32_MAX && bake->auto_choice[walked] ? walked : UINT32_MAX;
                    }
                    mesh = *counted;
                    if (mesh == UINT32_MAX) continue;
                    uint32_t j = 0;
                    while (j < part_count && parts[j].mesh != mesh) ++j;
                    if (j == part_count) parts[part_count++] = (group_part){.mesh = mesh};
                    pilot_sums *p = &sums[(size_t)candidate * run->meshes + mesh];
                    p->count += 1.0;
                    for (int c = 0; c < 3; ++c) {
                        parts[j].replicate_sum[c][s % REPLICATES] += rgb[c];
                        p->sum_squares[c] += rgb[c] * rgb[c];
                        p->largest[c] = fmax(p->largest[c], fabs(rgb[c]));
                    }
                    double event_cost = PILOT_COST_EVENT + (candidate % PILOT_TECHNIQUES == PILOT_CLASSICAL ? 0.0 : PILOT_COST_GUIDED_EVENT);
                    p->cost += PILOT_COST_SAMPLE + PILOT_COST_WALK * (double)tally.walks + event_cost * (double)tally.events +
                               PILOT_COST_RAY * (double)tally.rays +
                               PILOT_COST_QUERY * (double)tally.point_queries + PILOT_COST_TERM * (double)tally.mixture_terms +
                               PILOT_COST_PATH_RAY * (double)tally.path_rays;
                    for (int c = 0; c < 3; ++c)
                        p->channel_cost[c] += PILOT_COST_WALK * (double)tally.channel_walks[c] +
                                              event_cost * (double)tally.channel_events[c] +
                                              PILOT_COST_TERM * (double)tally.channel_terms[c];
                }
                for (uint32_t j = 0; j < part_count; ++j) {
                    pilot_sums *p = &sums[(size_t)candidate * run->meshes + parts[j].mesh];
                    p->groups += 1.0;
                    for (int c = 0; c < 3; ++c) {
                        double v = dwvb_pilot_group_variance(parts[j].replicate_sum[c], run->group_size);
                        p->variance_sum[c] += v;
                        if (g < run->first_groups)
                            run->first_variances[(((size_t)candidate * run->first_groups + g) * run->group_size + j) * 3u + (size_t)c] = v;
                    }
                    if (g < run->first_groups) run->first_meshes[(size_t)g * run->group_size + j] = parts[j].mesh;
                }
            }
        }
    }
    return NULL;
}

/* Runs blocks first_block to end_block - 1 of the pilot for `candidates` on the bake's threads,
 * into run->block_sums. 0 done, 1 stopped (cancel or time). */
static int run_blocks(pilot_run *run, const int *candidates, int candidate_count, uint32_t first_block,
                      uint32_t end_block)
{
    run->candidates = candidates;
    run->candidate_count = candidate_count;
    run->end_block = end_block;
    atomic_store(&run->next_block, first_block);
    dwvu_parallel_run(run->bake->threads < 64u ? run->bake->threads : 64u, pilot_worker, run);
    return atomic_load(&run->stopped) ? 1 : 0;
}

/* sums ([candidate][mesh]) = the totals of every block run so far, added in block order. */
static void merge_blocks(const pilot_run *run, pilot_sums *sums)
{
    size_t per_block = PILOT_CANDIDATES * (size_t)run->meshes;
    for (size_t k = 0; k < per_block; ++k) sums[k] = (pilot_sums){0};
    for (uint32_t block = 0; block < PILOT_BLOCKS; ++block)
        for (size_t k = 0; k < per_block; ++k) {
            const pilot_sums *b = &run->block_sums[block * per_block + k];
            sums[k].count += b->count;
            sums[k].groups += b->groups;
            for (int c = 0; c < 3; ++c) {
                sums[k].sum_squares[c] += b->sum_squares[c];
                sums[k].largest[c] = fmax(sums[k].largest[c], b->largest[c]); /* in any order */
                sums[k].variance_sum[c] += b->variance_sum[c];
            }
            sums[k].cost += b->cost;
            for (int c = 0; c < 3; ++c) sums[k].channel_cost[c] += b->channel_cost[c];
        }
}

/* A candidate's variance x cost per sample that saw the mesh; the variance is the three channels'
 * together, as the image's RMSE over RGB counts it: the luminance would hide the colour noise of
 * shared walks, whose channels' weights move against each other. With channel walks, also how many
 * walks each walking channel takes per sample (counts, 1 to DWVB_MAX_CHANNEL_WALKS; else 1): the
 * optimal allocation of stratified sampling with a cost per stratum (Cochran 1977, Sampling
 * Techniques, ch. 5: n_c ~ sqrt(v_c / t_c)), searched exactly over the counts, some channel keeping
 * one walk (below). n walks of a channel divide its variance v_c by n and multiply
 * its walks' cost t_c by n; the rest of a sample's cost is shared. A channel whose walks are cheap
 * and noisy gets more of them: the back-lit slab's red, 1.3 mean free paths thick, against its
 * blue, 5 (docs/speed.md). Fewer than one walk per sample would cost the channel's squared mean
 * on top of its variance, more than it saves. */
static double candidate_work(const pilot_sums *p, const dwvb_material *material, int channel_walks, uint8_t counts[3])
{
    double variance[3], walk_cost[3], shared_cost = p->cost / p->count;
    for (int c = 0; c < 3; ++c) {
        variance[c] = p->variance_sum[c] / p->groups;
        walk_cost[c] = p->channel_cost[c] / p->count;
        shared_cost -= walk_cost[c];
        counts[c] = 1u;
    }
    double best = INFINITY;
    uint32_t most = channel_walks ? DWVB_MAX_CHANNEL_WALKS : 1u;
    for (uint32_t n0 = 1; n0 <= most; ++n0)
        for (uint32_t n1 = 1; n1 <= most; ++n1)
            for (uint32_t n2 = 1; n2 <= most; ++n2) {
                uint32_t n[3] = {n0, n1, n2};
                double v = 0.0, t = shared_cost;
                int useless = 0;
                uint32_t fewest = UINT32_MAX; /* of the walking channels' counts */
                for (int c = 0; c < 3; ++c) {
                    int walks = material->walk_scale[c] > 0.0;
                    useless |= n[c] > 1u && !walks; /* no walk to repeat */
                    if (walks && n[c] < fewest) fewest = n[c];
                    v += variance[c] / n[c];
                    t += walk_cost[c] * n[c];
                }
                /* Some channel keeps one walk: more walks for every channel would only spread the
                 * sample's shared cost, a gain the counted cost model cannot tell from its error
                 * (measured: the leaf's 2 to 3 walks per channel cost 4.4x the instructions for
                 * 4.3x less variance, where the model promised 1.4x). */
                if (useless || (fewest != UINT32_MAX && fewest > 1u) || !(v * t < best)) continue; /* a tie keeps the fewer walks */
                best = v * t;
                for (int c = 0; c < 3; ++c) counts[c] = (uint8_t)n[c];
            }
    return best;
}

/* The largest share one sample makes of a candidate's sum of squares, over the channels: near 1 /
 * count where every sample weighs alike, near 1 where one sample makes the variance estimate. */
static double tail_share(const pilot_sums *p)
{
    double share = 0.0;
    for (int c = 0; c < 3; ++c)
        if (p->sum_squares[c] > 0.0) share = fmax(share, p->largest[c] * p->largest[c] / p->sum_squares[c]);
    return share;
}

/* The candidates still in the running after the first PILOT_FIRST_BLOCKS blocks (`sums`, and the
 * groups' own values in `run`), kept in their order in `candidates`; returns their count. A
 * candidate drops out where, on every deciding mesh the first blocks saw in PILOT_MESH_MIN_GROUPS
 * groups, its variance x cost is above the best candidate's by more than PILOT_CONFIDENCE standard
 * errors of the difference (successive elimination, Even-Dar, Mannor and Mansour 2006, "Action
 * elimination and stopping conditions for the multi-armed bandit and reinforcement learning
 * problems"). The difference is paired: per group, the candidate's variance x cost less the best's
 * on the same pixel's samples (the same camera rays, pixel positions and lights), so that what
 * the pixels share (a silhouette's or a bright patch's noise, alike for every candidate) cancels;
 * each candidate's variance is summed over the channels, with one walk per channel as the choice
 * ranks them, and its cost per sample held fixed; the groups are independent, so the standard
 * error is the differences' spread over the square root of their count. Bounds on
 * each candidate's own variance would not see that cancellation: with the groups' estimate they
 * kept 4-8 of 8 candidates on the benchmark's scenes (docs/speed.md). The rest of the pilot then
 * runs only the candidates left: on the benchmark's scenes the pilot had run all eight on as many
 * samples, up to half the bake's samples again at 32 spp. */
static int pilot_survivors(const dwvb_bake *bake, const pilot_run *run, const pilot_sums *sums, int *candidates,
                           int candidate_count)
{
    const dwvb_scene *scene = bake->scene;
    uint32_t meshes = scene->mesh_count, size = run->group_size;
    int keep[PILOT_CANDIDATES] = {0}, seen = 0;
    for (uint32_t m = 0; m < meshes; ++m) {
        if (!bake->auto_choice[m] || sums[(size_t)candidates[0] * meshes + m].groups < PILOT_MESH_MIN_GROUPS) continue;
        const dwvb_material *material = &scene->shading[scene->meshes[m].material_id];
        double work[PILOT_CANDIDATES], cost[PILOT_CANDIDATES];
        uint8_t counts[3];
        int sheet = sheet_may_win(scene, m), best = -1;
        for (int k = 0; k < candidate_count; ++k) {
            size_t slot = (size_t)candidates[k] * meshes + m;
            work[k] = INFINITY; /* a sheet candidate the mesh leaves out (sheet_may_win) keeps nothing here */
            if (candidates[k] % PILOT_TECHNIQUES == PILOT_SHEET && !sheet) continue;
            work[k] = candidate_work(&sums[slot], material, 0, counts); /* one walk per channel: see the choice */
            cost[k] = sums[slot].cost / sums[slot].count;
            if (best < 0 || work[k] < work[best]) best = k;
        }
        if (best < 0) continue;
        keep[best] = 1;
        for (int k = 0; k < candidate_count; ++k) {
            if (k == best || !(work[k] < INFINITY)) continue;
            double n = 0.0, sum = 0.0, squares = 0.0;
            for (uint32_t g = 0; g < run->first_groups; ++g)
                for (uint32_t j = 0; j < size && run->first_meshes[(size_t)g * size + j] != UINT32_MAX; ++j) {
                    if (run->first_meshes[(size_t)g * size + j] != m) continue;
                    const double *own = &run->first_variances[(((size_t)candidates[k] * run->first_groups + g) * size + j) * 3u];
                    const double *top = &run->first_variances[(((size_t)candidates[best] * run->first_groups + g) * size + j) * 3u];
                    double difference = 0.0;
                    for (int c = 0; c < 3; ++c)
                        difference += cost[k] * own[c] - cost[best] * top[c];
                    n += 1.0;
                    sum += difference;
                    squares += difference * difference;
                }
            double error = n > 1.0 ? sqrt(fmax(squares - sum * sum / n, 0.0) / (n * (n - 1.0))) : INFINITY;
            keep[k] |= !(sum / n - PILOT_CONFIDENCE * error > 0.0);
        }
        seen = 1;
    }
    if (!seen) return candidate_count; /* nothing to go by: all stay */
    int left = 0;
    for (int k = 0; k < candidate_count; ++k)
        if (keep[k]) candidates[left++] = candidates[k];
    return left;
}

int dwvb_pilot_choose(dwvb_bake *bake)
{
    const dwvb_scene *scene = bake->scene;
    uint32_t meshes = scene->mesh_count, deciding = 0;
    int separable = 0, sheet_runs = 0;
    for (uint32_t m = 0; m < meshes; ++m) {
        deciding += (uint32_t)bake->auto_choice[m];
        separable |= bake->auto_choice[m] && !scene->shading[scene->meshes[m].material_id].grey;
        sheet_runs |= bake->auto_choice[m] && sheet_may_win(scene, m);
    }
    if (deciding == 0) return 0;
    uint64_t budget = active_pixels(bake) * bake->options.samples / 16u;
    if (budget < PILOT_MIN) return 0;
    uint32_t n = budget < PILOT_MAX ? (uint32_t)budget : PILOT_MAX;
    /* Which forms run: the option's, or both where some deciding mesh has channels that differ. */
    int candidates[PILOT_CANDIDATES], candidate_count = 0, ran[PILOT_CANDIDATES], ran_count = 0;
    int shared = bake->options.channel_walks != DWV_CHANNEL_WALKS_SEPARATE || !separable;
    int separate = separable && bake->options.channel_walks != DWV_CHANNEL_WALKS_SHARED;
    /* The sheet walks only where they may win on some deciding mesh (sheet_may_win). */
    for (int c = 0; c < PILOT_CANDIDATES; ++c)
        if ((c < PILOT_TECHNIQUES ? shared : separate) && (c % PILOT_TECHNIQUES != PILOT_SHEET || sheet_runs))
            candidates[candidate_count++] = c;
    size_t slots = PILOT_CANDIDATES * (size_t)meshes;
    dwvw_guide *trial = malloc(slots * sizeof *trial);
    dwvw_guide *trial_channels = malloc(3u * slots * sizeof *trial_channels);
    int *trial_closest = malloc(slots * sizeof *trial_closest);
    int *trial_walks = malloc(slots * sizeof *trial_walks);
    pilot_sums *sums = calloc(slots, sizeof *sums); /* [candidate][mesh] */
    int stopped = -1;
    /* Pixel groups of the bake's samples per pixel, at most PILOT_GROUP_MAX and a PILOT_MIN_GROUPS-th
     * of the pilot's samples (at least 4, as n >= PILOT_MIN), even: two replicates. */
    uint32_t group_size = bake->options.samples < PILOT_GROUP_MAX ? (uint32_t)bake->options.samples : PILOT_GROUP_MAX;
    if (group_size > n / PILOT_MIN_GROUPS) group_size = n / PILOT_MIN_GROUPS;
    group_size = group_size < 2u ? 2u : group_size & ~1u;
    pilot_run run = {.bake = bake, .groups = n / group_size, .group_size = group_size, .meshes = meshes, .block_sums = NULL};
    if (!trial || !trial_channels || !trial_closest || !trial_walks || !sums) goto done;
    dwvb_shader shaders[PILOT_CANDIDATES];
    for (int k = 0; k < candidate_count; ++k) {
        int candidate = candidates[k];
        size_t base = (size_t)candidate * meshes;
        for (uint32_t m = 0; m < meshes; ++m) {
            const dwvb_material *material = &scene->shading[scene->meshes[m].material_id];
            if (bake->auto_choice[m]) {
                pilot_candidate(bake, m, candidate, &trial[base + m], &trial_channels[3u * (base + m)],
                                &trial_walks[base + m]);
            } else {
                trial[base + m] = bake->guides[m];
                for (int c = 0; c < 3; ++c) trial_channels[3u * (base + m) + (size_t)c] = bake->channel_guides[3u * m + (uint32_t)c];
                trial_walks[base + m] = bake->channel_walks[m];
            }
            trial_closest[base + m] = material->subsurface &&
                                      dwvb_mesh_needs_closest(material, trial_walks[base + m], &trial[base + m],
                                                              &trial_channels[3u * (base + m)]);
        }
        shaders[candidate] = bake->shader;
        shaders[candidate].guides = &trial[base];
        shaders[candidate].channel_guides = &trial_channels[3u * base];
        shaders[candidate].channel_walks = &trial_walks[base];
        shaders[candidate].needs_closest = &trial_closest[base];
    }
    run.shaders = shaders;
    run.block_sums = calloc(PILOT_BLOCKS * slots, sizeof(pilot_sums));
    run.first_groups = (uint32_t)((uint64_t)run.groups * PILOT_FIRST_BLOCKS / PILOT_BLOCKS);
    run.first_meshes = malloc((size_t)run.first_groups * group_size * sizeof *run.first_meshes);
    run.first_variances = malloc((size_t)PILOT_CANDIDATES * run.first_groups * group_size * 3u * sizeof *run.first_variances);
    if (!run.block_sums || !run.first_meshes || !run.first_variances) goto done;
    for (size_t k = 0; k < (size_t)run.first_groups * group_size; ++k) run.first_meshes[k] = UINT32_MAX;
    atomic_init(&run.next_block, 0u);
    atomic_init(&run.stopped, 0);
    /* First every candidate on PILOT_FIRST_BLOCKS of the blocks, then the rest of the blocks for
     * those still in the running (pilot_survivors). */
    stopped = run_blocks(&run, candidates, candidate_count, 0u, PILOT_FIRST_BLOCKS);
    if (stopped == 0) {
        merge_blocks(&run, sums);
        for (int k = 0; k < candidate_count; ++k) ran[k] = candidates[k];
        ran_count = candidate_count;
        candidate_count = pilot_survivors(bake, &run, sums, candidates, candidate_count);
        /* A lone survivor is the pick: the rest of the blocks would only refine its walks per
         * channel, for up to three quarters of a candidate's pilot (the benchmark's head_point and
         * disc_back at 48 px, 32 spp: auto 1.8x the time of its pick's forced bake, docs/speed.md). */
        if (candidate_count > 1) {
            stopped = run_blocks(&run, candidates, candidate_count, PILOT_FIRST_BLOCKS, PILOT_BLOCKS);
        }
    }
    if (stopped == 0) {
        merge_blocks(&run, sums);
        for (uint32_t m = 0; m < meshes; ++m) {
            /* Every candidate traced the same camera rays, so each saw the mesh equally often. */
            if (!bake->auto_choice[m] || sums[(size_t)candidates[0] * meshes + m].groups < PILOT_MESH_MIN_GROUPS) continue;
            /* variance x cost, per sample that saw the mesh; the variance is the three channels'
             * together, as the image's RMSE over RGB counts it: the luminance would hide the
             * colour noise of shared walks, whose channels' weights move against each other. */
            const dwvb_material *material = &scene->shading[scene->meshes[m].material_id];
            int best = candidates[0];
            double best_work = INFINITY;
            uint8_t best_counts[3] = {1u, 1u, 1u};
            /* The tail test (PILOT_TAIL_SHARE): classical's share, the smallest of its forms run
             * (on the first blocks only where it dropped out) */
            double classical_share = INFINITY;
            for (int k = 0; k < ran_count; ++k)
                if (ran[k] % PILOT_TECHNIQUES == PILOT_CLASSICAL)
                    classical_share = fmin(classical_share, tail_share(&sums[(size_t)ran[k] * meshes + m]));
            int sheet = sheet_may_win(scene, m);
            for (int k = 0; k < candidate_count; ++k) {
                if (candidates[k] % PILOT_TECHNIQUES == PILOT_SHEET && !sheet) continue; /* ran for another mesh */
                const pilot_sums *p = &sums[(size_t)candidates[k] * meshes + m];
                uint8_t counts[3];
                /* Ranked as measured, with one walk per channel; the winner then gets the walks per
                 * channel that suit it (below). The pilot's samples never walk a channel twice, so
                 * what more walks save is the model's v_c / n_c, which assumes all of a channel's
                 * variance is its walk's: with it in the ranking, backward with channel walks took
                 * the benchmark's bowl in 5 of 8 seeds on a promised 1.6x (forced, with one walk
                 * per channel, 0.58 of incident shared's efficiency), and the leaf's sheet walk
                 * with channel walks in half the seeds (0.70 of the shared sheet walk's):
                 * docs/speed.md. */
                double work = candidate_work(p, material, 0, counts);
                double share = tail_share(p);
                int tailed = candidates[k] % PILOT_TECHNIQUES != PILOT_CLASSICAL && share > PILOT_TAIL_SHARE &&
                             share > PILOT_TAIL_RATIO * classical_share;
                if (!tailed && work < best_work) {
                    best_work = work;
                    best = candidates[k];
                    for (int c = 0; c < 3; ++c) best_counts[c] = counts[c];
                }
            }
            size_t slot = (size_t)best * meshes + m;
            if (best_work < INFINITY) candidate_work(&sums[slot], material, trial_walks[slot], best_counts);
            for (int c = 0; c < 3; ++c) bake->channel_counts[3u * m + (uint32_t)c] = best_counts[c];
            bake->guides[m] = trial[slot];
            for (int c = 0; c < 3; ++c) bake->channel_guides[3u * m + (uint32_t)c] = trial_channels[3u * slot + (size_t)c];
            bake->channel_walks[m] = trial_walks[slot];
            bake->needs_closest[m] = trial_closest[slot];
        }
        dwvb_bake_update_features(bake);
    }
done:
    free(run.block_sums);
    free(run.first_meshes);
    free(run.first_variances);
    free(trial);
    free(trial_channels);
    free(trial_closest);
    free(trial_walks);
    free(sums);
    return stopped;
}
