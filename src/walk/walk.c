#include "walk.h"

#include <math.h>
#include <string.h>

#include "kernel/exp_batch.h"
#include "kernel/sheet.h"
#include "step.h"

/* The loops over a mixture's components and a guide's patches (incident_shares,
 * component_stretches, grey_denominator) are written for a compiler to vectorise, their
 * exponentials by dwvk_exp_fast_inner (src/kernel/exp_batch.h); on x86-64 they are compiled
 * three times, for the baseline (SSE2: two doubles a vector), x86-64-v3 (AVX2: four) and
 * x86-64-v4 (AVX-512: eight), and the first call picks the copy the processor runs (GCC's
 * target_clones, an ifunc).
 * Every copy does the same IEEE operations in the same order: this file is compiled with
 * -ffp-contract=off (no fused multiply-add, which rounds differently) and -fno-trapping-math
 * (which lets a select be computed on both sides, changing no value), so a walk is the same to
 * the last bit on every processor, and the same as before these loops were vectorised (all of
 * tools/behaviour_hashes.py's hashes; tests/internal/test_exp_batch.c checks the exponentials in
 * each copy the processor runs), as the lanes' are (src/walk/estimate_lanes.c). */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && __GNUC__ >= 12
#define DWVW_MIXTURE_CLONES __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4")))
#else
#define DWVW_MIXTURE_CLONES
#endif

/* Two axes whose cosine is at least this are one component's (add_component). */
#define DWVW_SAME_AXIS_COSINE (1.0 - 1e-12)
_Static_assert(DWVW_MAX_COMPONENTS >= 1 + DWVW_MAX_PATCHES,
               "the classical component and every patch fit (add_incident_components)");

void dwvw_medium_init(dwvw_medium *medium, int channels, const double *sigma_t, const double *albedo, double g)
{
    medium->channels = channels;
    medium->guide_channel = 0;
    for (int c = 0; c < DWVW_MAX_CHANNELS; ++c) {
        int source = c < channels ? c : 0;
        medium->sigma_t[c] = sigma_t[source];
        medium->albedo[c] = albedo[source];
        if (c < channels && albedo[c] > albedo[medium->guide_channel]) medium->guide_channel = c;
    }
    medium->g = g;
    medium->dwivedi = dwvk_dwivedi_from_kappa(dwvk_kappa_exact(albedo[medium->guide_channel]));
    medium->dwivedi_f = dwvk_dwivedi_to_float(medium->dwivedi);
    medium->dwivedi_event = dwvk_dwivedi_event_from(medium->dwivedi);
    medium->guided_pdf_scale = medium->dwivedi.albedo_eff * DWVK_INV_FOUR_PI;
}

/* The auto heuristic. Guiding pays where walks are long (high albedo) and the Dwivedi
 * eigenfunction describes the medium (isotropic scattering). Below albedo 0.2 the guided
 * distribution is clamped to a near-delta, and classical sampling is left alone. Otherwise:
 * - A small classical share, min(0.01, 0.1 sqrt(1 - alpha)), is kept as a defensive component.
 *   A half-space walk has about 1.4/sqrt(1 - alpha) events, so this keeps the classical steps
 *   per walk at about 0.14 or fewer, where they add 3% or less to the variance.
 * - For anisotropic media the classical share is raised to |g|, because there the ratio of the
 *   phase function to the Dwivedi pdf grows with |g|. (Cycles' rule, max(0.5, |g|^(1/8)), gives up
 *   half the guiding even at g = 0.)
 * - The guided rest goes to the lit patches (incident) when light is known, else to the closest
 *   surface point.
 *
 * Closest is left out whenever patches exist: on back-lit shapes it aims at the nearer, often
 * unlit, face (variance x1.07 to x1.36), and on the half-space it only adds cost.
 * Measured in one run by tools/walk_report.py on half-spaces (0.5 to 0.999), back-lit slabs
 * (1, 4, 16 mfp) and a back-lit sphere: 0.91 to 0.99 of the best single technique, against
 * 0.67 to 0.82 for classical 0.02 with incident:closest 9:1 (docs/walk.md). */
void dwvw_auto_weights(const dwvw_medium *medium, int patch_count, double *q_classical, double *q_closest,
                       double *q_incident)
{
    double alpha = medium->albedo[medium->guide_channel];
    double classical = alpha < 0.2 ? 1.0 : fmax(fabs(medium->g), fmin(0.01, 0.1 * sqrt(1.0 - alpha)));
    double guided = 1.0 - classical;
    *q_classical = classical;
    *q_incident = patch_count > 0 ? guided : 0.0;
    *q_closest = patch_count > 0 ? 0.0 : guided;
}

void dwvw_guide_init(dwvw_guide *guide, dwvw_technique technique, const dwvw_medium *medium,
                     const dwvw_light_patch *patches, int patch_count)
{
    guide->q_classical = guide->q_poe = guide->q_closest = guide->q_incident = guide->q_backward = 0.0;
    guide->q_sheet = 0.0;
    guide->sheet_normal = dwvu_v(0.0, 0.0, 1.0);
    guide->patch_count = patch_count < DWVW_MAX_PATCHES ? patch_count : DWVW_MAX_PATCHES;
    for (int i = 0; i < guide->patch_count; ++i) {
        guide->patches[i] = patches[i];
        guide->patches[i].log_power = log(patches[i].power);
        guide->patch_frames[i] = dwvu_frame_about(guide->patches[i].normal);
        const dwvu_vec3 point = guide->patches[i].point, normal = guide->patches[i].normal;
        guide->patch_point[0][i] = point.x, guide->patch_point[1][i] = point.y, guide->patch_point[2][i] = point.z;
        guide->patch_normal[0][i] = normal.x, guide->patch_normal[1][i] = normal.y, guide->patch_normal[2][i] = normal.z;
        guide->patch_log_power[i] = guide->patches[i].log_power;
        guide->patch_is_plane[i] = guide->patches[i].is_plane != 0;
    }
    /* The rest, up to DWVW_MAX_PATCHES, which incident_shares' loops run over: a plane through the
     * origin of log power -infinity, its weight's logarithm -infinity wherever a walk is. */
    for (int i = guide->patch_count; i < DWVW_MAX_PATCHES; ++i) {
        for (int c = 0; c < 3; ++c) guide->patch_point[c][i] = guide->patch_normal[c][i] = 0.0;
        guide->patch_log_power[i] = -INFINITY;
        guide->patch_is_plane[i] = 1;
    }
    guide->patches_distinct = 1;
    for (int i = 0; i < guide->patch_count; ++i)
        for (int j = i + 1; j < guide->patch_count; ++j)
            if (dwvu_dot(guide->patches[i].normal, guide->patches[j].normal) >= DWVW_SAME_AXIS_COSINE)
                guide->patches_distinct = 0;
    switch (technique) {
    case DWVW_CLASSICAL: guide->q_classical = 1.0; break;
    case DWVW_POE: guide->q_poe = 1.0; break;
    case DWVW_CLOSEST: guide->q_closest = 1.0; break;
    case DWVW_INCIDENT: guide->q_incident = 1.0; break;
    case DWVW_BACKWARD: guide->q_backward = 1.0; break;
    case DWVW_SHEET: {
        if (guide->patch_count == 0) { /* no lit side to aim at */
            guide->q_classical = 1.0;
            break;
        }
        int strongest = 0;
        for (int i = 1; i < guide->patch_count; ++i)
            if (guide->patches[i].power > guide->patches[strongest].power) strongest = i;
        guide->sheet_normal = guide->patches[strongest].normal;
        guide->q_classical = fmax(DWVW_SHEET_CLASSICAL_SHARE, fabs(medium->g));
        guide->q_sheet = 1.0 - guide->q_classical;
        break;
    }
    case DWVW_CYCLES: {
        /* Cycles: guided_fraction = 1 - max(0.5, |g|^(1/8)). */
        double guided = 1.0 - fmax(0.5, pow(fabs(medium->g), 0.125));
        guide->q_classical = 1.0 - guided;
        guide->q_backward = guided;
        break;
    }
    case DWVW_AUTO:
        dwvw_auto_weights(medium, guide->patch_count, &guide->q_classical, &guide->q_closest, &guide->q_incident);
        break;
    }
}

int dwvw_guide_needs_closest(const dwvw_guide *guide)
{
    return guide->q_closest > 0.0;
}

/* Classical sampling alone: the guide of sheet walks that enter on the lit side. */
static const dwvw_guide classical_guide = {.q_classical = 1.0, .sheet_normal = {0.0, 0.0, 1.0}};

/* The sheet's axis, along which its importance rises: the entry face's inward normal where that
 * face looks away from the light (DWVW_SHEET_LOCAL_COSINE), else the lit normal. On a flat sheet
 * the two are one; on a curved or tilted one the lit normal is not the sheet's local thickness
 * direction, and a walk moving along the sheet went below its entry's height along it, inside the
 * medium, where the importance max(a, f) has (K psi) / psi up to 2.4 per event (the floor's kink,
 * src/kernel/sheet.h): the weight x importance grew by that factor at every such event, a weight
 * of 5,491 after 31 of 46 events there on the bent sheet, whose faces tilt up to 34 degrees from
 * the lit normal (docs/speed.md). About the entry face's own normal the walk sees the sheet as
 * flat over its few mean free paths. */
static void sheet_axis(dwvw_walk *walk, dwvu_vec3 face_normal)
{
    const dwvw_guide *guide = walk->guide;
    walk->sheet_normal = guide->sheet_normal;
    if (guide->q_sheet > 0.0 && dwvu_dot(face_normal, guide->sheet_normal) < -DWVW_SHEET_LOCAL_COSINE)
        walk->sheet_normal = dwvu_scale(face_normal, -1.0);
}

void dwvw_walk_sheet_face(dwvw_walk *walk, dwvu_vec3 face_normal)
{
    sheet_axis(walk, face_normal);
}

void dwvw_walk_begin(dwvw_walk *walk, const dwvw_medium *medium, const dwvw_guide *guide, uint64_t key,
                     uint32_t max_events, dwvu_vec3 point, dwvu_vec3 direction, dwvu_vec3 normal)
{
    walk->medium = medium;
    /* The sheet's importance rises from the far face toward the lit one: a walk that enters on the
     * lit side (its entry faces the lit normal's way) has no far face to start from, and its
     * light leaves where it came in, which the linear importance does not describe (a front-lit
     * sphere's variance was 10^4 times classical's). Such a walk is classical. */
    if (guide->q_sheet > 0.0 && dwvu_dot(normal, guide->sheet_normal) > 0.0) guide = &classical_guide;
    walk->guide = guide;
    sheet_axis(walk, normal);
    walk->key = key;
    walk->sampler = NULL;
    walk->index_reversed = 0u;
    walk->first_pair = 0u;
    walk->stratified_events = 0u;
    walk->pair_cache = NULL;
    walk->max_events = max_events;
    walk->events = 0;
    walk->status = DWVW_RUNNING;
    walk->position = walk->entry_point = point;
    walk->direction = direction;
    walk->entry_normal = normal;
    walk->exit_normal = normal;
    for (int c = 0; c < DWVW_MAX_CHANNELS; ++c) walk->weight[c] = c < medium->channels ? 1.0 : 0.0;
    walk->have_opposite = 0;
    walk->opposite_depth = 0.0;
    walk->closest_known = 0;
    walk->closest_normal = normal;
    walk->step_distance = 0.0;
    walk->component_count = 0;
    /* every slot defined: grey_denominator's loop runs over all of them */
    for (int k = 0; k < DWVW_MAX_COMPONENTS; ++k) {
        walk->component_q[k] = 0.0;
        walk->component_pdf[k] = walk->component_stretch[k] = 1.0;
    }
    /* Closest aims at a new point, and several patches are weighed anew, at every event; backward
     * from the event after its probe found the opposite interface (dwvw_walk_complete). Otherwise
     * the components depend on nothing that moves: build_components gives the same at every event. */
    walk->components_vary = guide->q_closest > 0.0 || (guide->q_incident > 0.0 && guide->patch_count > 1);
    walk->single_component = -1;
    walk->frames_made = 0u;
}

void dwvw_walk_stratify(dwvw_walk *walk, const dwvk_sampler *sampler, uint32_t first_pair, uint32_t events)
{
    uint32_t room = (UINT32_MAX - first_pair) / DWVW_PAIRS_PER_EVENT; /* events whose pairs fit in 32 bits */
    walk->sampler = sampler;
    walk->index_reversed = sampler == NULL ? 0u : dwvk_sampler_index_reversed(sampler);
    walk->first_pair = first_pair;
    walk->stratified_events = sampler == NULL ? 0u : events < room ? events : room;
}

void dwvw_walk_set_closest(dwvw_walk *walk, dwvu_vec3 normal)
{
    walk->closest_normal = normal;
    walk->closest_known = 1;
}

static dwvu_vec3 component_axis(const dwvw_walk *walk, int k)
{
    return dwvu_v(walk->component_axis[0][k], walk->component_axis[1][k], walk->component_axis[2][k]);
}

/* Appends component `q`, `axis`, taking patch `patch`'s frame (or -1). */
static void append_component(dwvw_walk *walk, double q, dwvu_vec3 axis, int patch)
{
    const int k = walk->component_count++;
    walk->component_q[k] = q;
    walk->component_axis[0][k] = axis.x, walk->component_axis[1][k] = axis.y, walk->component_axis[2][k] = axis.z;
    walk->component_patch[k] = patch;
}

/* Adds a guided component, or its weight to one with the same axis: the mixture is the same, and
 * every component costs a pdf and an exponential per channel at every event. */
static void add_component(dwvw_walk *walk, double q, dwvu_vec3 axis)
{
    if (!(q > 0.0)) return;
    for (int k = 1; k < walk->component_count; ++k) {
        if (dwvu_dot(component_axis(walk, k), axis) >= DWVW_SAME_AXIS_COSINE) {
            walk->component_q[k] += q;
            return;
        }
    }
    if (walk->component_count >= DWVW_MAX_COMPONENTS) return;
    append_component(walk, q, axis, -1);
}

/* Patches whose weight is below this share of the largest patch's are left out of a step's
 * mixture (add_incident_components). */
#define DWVW_PATCH_PRUNE_LOG (-6.931471805599453) /* log(1e-3) */

/* The incident technique's patch weights w_j = power_j exp(-sigma_t d_j / v), normalised in the
 * log domain so that distant patches do not underflow all at once, and their shares
 * q w_j / sum w of the incident weight q (add_incident_components).
 *
 * A patch whose weight is below 1e-3 of the largest one's is left out (its weight 0, no
 * component made): each component costs a stretch, a pdf and three exponentials per channel at every
 * event, and inside a thick mesh most patches are many mean free paths farther than the nearest
 * (exp(-sigma_t d / v) below 1e-3 is 6.9 / kappa mean free paths farther), guiding a share below
 * 1e-3 of the incident weight each. The estimate stays unbiased: the step samples the mixture it
 * then weighs by (the pruned patches are out of both), and the classical component, which covers
 * every direction and distance, keeps its weight, so the bound it sets on a step's ratio f / p is
 * the same as with every patch (exp underflowing to 0 already left out patches at 1e-308). The
 * weights' exponentials are fastmath.h's (5e-16 relative: they only set the mixture's shares),
 * about half libm's instructions. */
static DWVW_MIXTURE_CLONES void incident_shares(const dwvw_guide *guide, dwvu_vec3 position, double decay, double q,
                                                 double share[DWVW_MAX_PATCHES])
{
    /* The loops without a sum run over every slot, the guide's unused ones too (dwvw_guide_init
     * fills them), and are vectorised without a remainder; the sums over the patches alone. */
    const int n = guide->patch_count;
    double log_w[DWVW_MAX_PATCHES], w[DWVW_MAX_PATCHES], largest = -INFINITY;
    for (int j = 0; j < DWVW_MAX_PATCHES; ++j) {
        /* the plane's and the point's distances both formed, one taken (the same bits as a branch) */
        double x = position.x - guide->patch_point[0][j], y = position.y - guide->patch_point[1][j],
               z = position.z - guide->patch_point[2][j];
        double along = fabs(x * guide->patch_normal[0][j] + y * guide->patch_normal[1][j] + z * guide->patch_normal[2][j]);
        double length = sqrt(x * x + y * y + z * z);
        log_w[j] = guide->patch_log_power[j] - decay * (guide->patch_is_plane[j] ? along : length);
    }
    for (int j = 0; j < n; ++j) largest = log_w[j] > largest ? log_w[j] : largest; /* not NaN: no libm fmax */
    /* Every patch's exponential taken (a pruned one's too, and not used), then dwvk_exp_fast where
     * a kept patch's argument was beyond the fast range (a NaN: the value the scalar loop gave). */
    int edges = 0;
    for (int j = 0; j < DWVW_MAX_PATCHES; ++j) {
        double relative = log_w[j] - largest;
        double e = dwvk_exp_fast_inner(relative);
        int pruned = relative < DWVW_PATCH_PRUNE_LOG;
        edges |= dwvk_exp_fast_is_edge(relative) & !pruned & (j < n);
        w[j] = pruned ? 0.0 : e;
    }
    if (edges)
        for (int j = 0; j < n; ++j) {
            double relative = log_w[j] - largest;
            w[j] = relative < DWVW_PATCH_PRUNE_LOG ? 0.0 : dwvk_exp_fast(relative);
        }
    double sum = 0.0;
    for (int j = 0; j < n; ++j) sum += w[j];
    for (int j = 0; j < DWVW_MAX_PATCHES; ++j) share[j] = q * w[j] / sum;
}

static void add_incident_components(dwvw_walk *walk, double q)
{
    const dwvw_guide *guide = walk->guide;
    const dwvw_medium *m = walk->medium;
    if (guide->patch_count == 1) { /* one patch takes all: no weights to compute */
        add_component(walk, q, guide->patches[0].normal);
        return;
    }
    double decay = m->sigma_t[m->guide_channel] * m->dwivedi.kappa; /* sigma_t / v */
    double share[DWVW_MAX_PATCHES];
    incident_shares(guide, walk->position, decay, q, share);
    if (guide->patches_distinct && walk->component_count == 1) {
        /* Only the classical component before them, and no two patches merge: add_component's
         * search for a component of the same axis (all patches against all, per event) would find
         * none, so each patch of weight > 0 takes the next component, as there, and its frame is
         * the guide's. */
        for (int j = 0; j < guide->patch_count; ++j) {
            if (share[j] > 0.0) append_component(walk, share[j], guide->patches[j].normal, j);
        }
        return;
    }
    for (int j = 0; j < guide->patch_count; ++j) add_component(walk, share[j], guide->patches[j].normal);
}

static void build_components(dwvw_walk *walk)
{
    const dwvw_guide *guide = walk->guide;
    const dwvw_medium *m = walk->medium;
    /* Component 0 is always the classical one (possibly with weight 0), so its index is fixed. */
    walk->component_q[0] = guide->q_classical;
    walk->component_count = 1;
    double backward_fraction = 0.0;
    if (guide->q_backward > 0.0 && walk->have_opposite) {
        double depth = -dwvu_dot(dwvu_sub(walk->position, walk->entry_point), walk->entry_normal);
        depth = depth > 0.0 ? depth < walk->opposite_depth ? depth : walk->opposite_depth : 0.0;
        double x = m->sigma_t[m->guide_channel] * (walk->opposite_depth - 2.0 * depth) * m->dwivedi.kappa;
        backward_fraction = 1.0 / (1.0 + exp(x));
    }
    add_component(walk, guide->q_poe + guide->q_backward * (1.0 - backward_fraction), walk->entry_normal);
    add_component(walk, guide->q_backward * backward_fraction, dwvu_scale(walk->entry_normal, -1.0));
    if (guide->q_closest > 0.0) add_component(walk, guide->q_closest, walk->closest_normal);
    if (guide->q_incident > 0.0) add_incident_components(walk, guide->q_incident);
    /* With one component of weight > 0 there is nothing to draw: pick() would return it for any u. */
    walk->single_component = -1;
    for (int k = 0; k < walk->component_count; ++k) {
        if (!(walk->component_q[k] > 0.0)) continue;
        if (walk->single_component >= 0) {
            walk->single_component = -1;
            break;
        }
        walk->single_component = k;
    }
}

/* Picks i with probability p[i] / sum p by the uniform u. With `rest` non-NULL, also the position
 * of u within the picked interval, (u total - below) / p[i]: given the pick it is uniform on
 * [0, 1) and independent of the pick, so it can drive a further choice (held below 1 against
 * rounding). */
static int pick(const double *p, int n, double u, double *rest)
{
    double total = 0.0;
    for (int i = 0; i < n; ++i) total += p[i];
    double target = u * total, cumulative = 0.0, below = 0.0;
    int last = 0;
    for (int i = 0; i < n; ++i) {
        if (!(p[i] > 0.0)) continue;
        below = cumulative;
        cumulative += p[i];
        last = i;
        if (target < cumulative) break;
    }
    if (rest != NULL) {
        double r = (target - below) / p[last];
        *rest = r > 0.0 ? r < 1.0 ? r : 0x1.fffffffffffffp-1 : 0.0;
    }
    return last;
}

/* `x >= 0 ? a : b` for x not NaN, through the bits, without a branch: the sign bit of x + 0 (which
 * is +0 for x = -0) makes the mask (a comparison would be folded into the branches around it). */
static inline double select_nonnegative(double x, double a, double b)
{
    double signed_x = x + 0.0;
    uint64_t bits_x, bits_a, bits_b;
    memcpy(&bits_x, &signed_x, sizeof bits_x);
    uint64_t mask = (bits_x >> 63) - (uint64_t)1; /* all ones for x >= 0, else 0 */
    memcpy(&bits_a, &a, sizeof a);
    memcpy(&bits_b, &b, sizeof b);
    uint64_t bits = (bits_a & mask) | (bits_b & ~mask);
    double out;
    memcpy(&out, &bits, sizeof out);
    return out;
}

static int same_bits(dwvu_vec3 a, dwvu_vec3 b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

/* dwvu_frame_about(axis), made once per walk and axis (kept in the walk's few slots, the oldest
 * replaced): the frame is a function of the axis's bits, so a kept one is the same bit for bit. */
static const dwvu_frame *frame_about_axis(dwvw_walk *walk, dwvu_vec3 axis)
{
    uint32_t kept = walk->frames_made < DWVW_FRAME_CACHE ? walk->frames_made : DWVW_FRAME_CACHE;
    for (uint32_t i = 0; i < kept; ++i)
        if (same_bits(walk->frames[i].n, axis)) return &walk->frames[i];
    dwvu_frame *slot = &walk->frames[walk->frames_made++ % DWVW_FRAME_CACHE];
    *slot = dwvu_frame_about(axis);
    return slot;
}

void dwvw_walk_share_pairs(dwvw_walk *walk, dwvw_pair_cache *cache)
{
    /* A cache of other pairs would hand out wrong numbers: the walk then makes its own. */
    walk->pair_cache = cache != NULL && cache->first_pair == walk->first_pair ? cache : NULL;
}

/* dwvk_sampler_pair_bits for the walk's pair `pair`, through its cache where it has one. */
static inline int walk_pair_bits(const dwvw_walk *walk, uint32_t pair, uint64_t *both)
{
    dwvw_pair_cache *cache = walk->pair_cache;
    uint32_t k = pair - walk->first_pair;
    if (cache == NULL || k >= DWVW_PAIR_CACHE)
        return dwvk_sampler_pair_bits(walk->sampler, walk->index_reversed, pair, both);
    uint32_t bit = 1u << k;
    if (!(cache->have & bit)) {
        uint64_t made = 0u;
        if (dwvk_sampler_pair_bits(walk->sampler, walk->index_reversed, pair, &made)) cache->stratified |= bit;
        cache->bits[k] = made;
        cache->have |= bit;
    }
    *both = cache->bits[k];
    return (cache->stratified & bit) != 0u;
}

/* The sheet technique's linear importance a = sigma_t h + z_e per channel at the walk's position,
 * h its height above the entry point along the walk's sheet axis (walk->sheet_normal, toward the
 * lit side), of either sign; the importance is
 * max(a, DWVK_SHEET_FLOOR) (src/kernel/sheet.h). Not held at h >= 0: a curved sheet's walk goes
 * below its entry's height inside the medium, and an importance held there would not be the one
 * its flight followed (the weight x importance a walk keeps then jumped by z_e / (a + mu tau),
 * up to 1 / q_classical, at every such step: docs/speed.md, the bent sheet). */
static void sheet_importance(const dwvw_walk *walk, double a[DWVW_MAX_CHANNELS])
{
    const dwvw_medium *m = walk->medium;
    double h = dwvu_dot(dwvu_sub(walk->position, walk->entry_point), walk->sheet_normal);
    for (int c = 0; c < m->channels; ++c) a[c] = m->sigma_t[c] * h + DWVK_SHEET_EXTRAPOLATION;
}

/* A step of the sheet technique (after the channel's pick): classical with probability
 * q_classical, else the sheet's cosine about the lit normal (its slope from the importance of the
 * channel that guides, so that the direction's pdf is the same for every channel) and the picked
 * channel's flight (src/kernel/sheet.h). The random numbers are those of dwvw_walk_sample. */
static double sheet_sample(dwvw_walk *walk, int channel, const double *choice, float u_flight, uint32_t dim,
                           uint32_t pair)
{
    const dwvw_medium *m = walk->medium;
    const dwvw_guide *guide = walk->guide;
    const dwvu_vec3 normal = walk->sheet_normal;
    /* two components for the tally of mixture terms (shade.c); the weight update is sheet_weight_update */
    walk->component_count = 2;
    walk->single_component = -1;
    walk->component_q[0] = guide->q_classical;
    walk->component_q[1] = guide->q_sheet;
    sheet_importance(walk, walk->sheet_a);
    double u_component = choice != NULL ? *choice : dwvk_rng_uniform_d(walk->key, dim + DWVW_DIM_COMPONENT);
    int classical = u_component < guide->q_classical;
    double up, down;
    dwvk_sheet_slopes(walk->sheet_a[m->guide_channel], &up, &down);
    dwvu_vec3 previous = walk->direction;
    float g = (float)m->g;
    if (walk->events > 0) {
        dwvk_uniform_pair_f u;
        if (choice != NULL) {
            uint64_t both = 0u;
            int have = walk_pair_bits(walk, pair + DWVW_PAIR_DIRECTION, &both);
            u = dwvk_sampler_pair_given_f(walk->sampler, pair + DWVW_PAIR_DIRECTION, have, both);
        } else {
            u = dwvk_rng_uniform_pair_f(walk->key, dim + DWVW_DIM_DIRECTION);
        }
        if (classical) {
            walk->direction = dwvw_classical_direction(previous, g, u);
        } else {
            double mu = dwvk_sheet_cosine_sample(up, down, (double)u.a);
            double sin2 = (1.0 - mu) * (1.0 + mu);
            walk->direction = dwvk_frame_direction(frame_about_axis(walk, normal), mu, sqrt(sin2 > 0.0 ? sin2 : 0.0),
                                                   dwvk_azimuth_f(u.b));
        }
        walk->phase = dwvw_phase_value(g, previous, walk->direction);
    } else {
        walk->phase = 1.0; /* the entry's direction: not sampled, pdf 1 for every component */
    }
    /* the cosine of the direction as it is, for the flight and both pdfs alike */
    walk->sheet_mu = dwvw_cosine(walk->direction, normal);
    walk->sheet_direction_pdf = walk->events > 0 ? dwvk_sheet_cosine_pdf(up, down, walk->sheet_mu) * DWVK_SHEET_INV_TWO_PI : 1.0;
    for (int c = 0; c < m->channels; ++c) /* channels of equal extinction have equal importance */
        walk->sheet_norm[c] = c > 0 && m->sigma_t[c] == m->sigma_t[c - 1]
                                  ? walk->sheet_norm[c - 1]
                                  : dwvk_sheet_flight_norm(walk->sheet_a[c], walk->sheet_mu);
    if (classical) walk->step_distance = dwvw_flight(m->sigma_t[channel], u_flight);
    else
        walk->step_distance = dwvk_sheet_flight_sample_normed(walk->sheet_a[channel], walk->sheet_mu, walk->sheet_norm[channel],
                                                              (double)u_flight) /
                              m->sigma_t[channel];
    return walk->step_distance;
}

/* Every guided component's stretch and direction pdf at the walk's sampled direction (the pdf is
 * 1 for all on the first step, whose direction was not sampled): p(mu) / (2 pi) = a / (4 pi
 * stretch). */
static DWVW_MIXTURE_CLONES void component_stretches(dwvw_walk *walk)
{
    const dwvw_medium *m = walk->medium;
    const double kappa = m->dwivedi.kappa, one_minus_kappa = m->dwivedi.one_minus_kappa;
    const double pdf_scale = m->guided_pdf_scale;
    const dwvu_vec3 d = walk->direction;
    const int count = walk->component_count;
    const double *restrict x = walk->component_axis[0], *restrict y = walk->component_axis[1],
                           *restrict z = walk->component_axis[2];
    double *restrict stretch = walk->component_stretch, *restrict pdf = walk->component_pdf;
    for (int k = 1; k < count; ++k) {
        /* dwvk_dwivedi_stretch_d, both sides formed and one taken by a bit mask (the same bits):
         * across a mixture's axes the cosine's sign is a coin toss, and as a branch (which GCC
         * makes of a select of doubles) it was mispredicted, the hottest spot of
         * dwvw_walk_sample on the benchmark's torus (perf). The pdf's division in a loop of its
         * own, without the first step's case in it: a division under a condition is control flow
         * the vectoriser leaves alone (it may not compute it where the condition is false). */
        double mu = dwvw_clamp_cosine(d.x * x[k] + d.y * y[k] + d.z * z[k]); /* dwvw_cosine's sum, in its order */
        stretch[k] = select_nonnegative(mu, one_minus_kappa + kappa * (1.0 - mu), 1.0 - kappa * mu);
    }
    if (walk->events > 0)
        for (int k = 1; k < count; ++k) pdf[k] = pdf_scale / stretch[k];
    else
        for (int k = 1; k < count; ++k) pdf[k] = 1.0;
}

double dwvw_walk_sample(dwvw_walk *walk)
{
    const dwvw_medium *m = walk->medium;
    const uint32_t dim = dwvw_event_dim(walk->events);
    /* A stratified event's flight pair: the distance's uniform and the choice (walk.h). */
    const int stratified = walk->events < walk->stratified_events;
    const uint32_t pair = walk->first_pair + DWVW_PAIRS_PER_EVENT * walk->events;
    double flight_choice = 0.0;
    float flight_distance = 0.0f;
    if (stratified) {
        uint64_t both = 0u;
        int have = walk_pair_bits(walk, pair + DWVW_PAIR_FLIGHT, &both);
        flight_distance = dwvk_sampler_pair_given_fd(walk->sampler, pair + DWVW_PAIR_FLIGHT, have, both, &flight_choice);
    }
    double *choice = stratified ? &flight_choice : NULL;

    /* Channel: proportional to throughput x albedo (Cycles), to throughput where all albedos are 0. */
    int channel = 0;
    if (m->channels > 1) {
        /* RGB (a medium has 1 or 3 channels): written for three, so that the loops unroll. */
        double p[DWVW_MAX_CHANNELS], total = 0.0;
        for (int c = 0; c < DWVW_MAX_CHANNELS; ++c) total += (p[c] = walk->weight[c] * m->albedo[c]);
        if (!(total > 0.0))
            for (int c = 0; c < DWVW_MAX_CHANNELS; ++c) total += (p[c] = walk->weight[c]);
        for (int c = 0; c < DWVW_MAX_CHANNELS; ++c) walk->channel_p[c] = p[c] /= total;
        channel = pick(p, DWVW_MAX_CHANNELS,
                       stratified ? *choice : dwvk_rng_uniform_d(walk->key, dim + DWVW_DIM_CHANNEL), choice);
    } else {
        walk->channel_p[0] = 1.0;
    }
    if (walk->guide->q_sheet > 0.0) {
        float u_flight = stratified ? flight_distance : dwvk_rng_uniform_f(walk->key, dim + DWVW_DIM_DISTANCE);
        return sheet_sample(walk, channel, choice, u_flight, dim, pair);
    }

    if (walk->component_count == 0 || walk->components_vary) build_components(walk);
    int chosen = walk->single_component >= 0
                     ? walk->single_component
                     : pick(walk->component_q, walk->component_count,
                            stratified ? *choice : dwvk_rng_uniform_d(walk->key, dim + DWVW_DIM_COMPONENT), NULL);
    /* Per-event sampling runs in single precision (src/kernel/fastmath.h); positions, directions,
     * pdfs, weights and their exponentials stay in double. */
    dwvu_vec3 previous = walk->direction;
    float g = (float)m->g;
    if (walk->events > 0) {
        /* The first step keeps the entry direction: only its distance is sampled. */
        dwvk_uniform_pair_f u;
        if (stratified) {
            uint64_t both = 0u;
            int have = walk_pair_bits(walk, pair + DWVW_PAIR_DIRECTION, &both);
            u = dwvk_sampler_pair_given_f(walk->sampler, pair + DWVW_PAIR_DIRECTION, have, both);
        } else {
            u = dwvk_rng_uniform_pair_f(walk->key, dim + DWVW_DIM_DIRECTION);
        }
        if (chosen == 0) {
            walk->direction = dwvw_classical_direction(previous, g, u);
        } else {
            /* a patch's frame is the guide's (the same bits: a frame is a function of its axis) */
            int patch = walk->component_patch[chosen];
            const dwvu_frame *frame = patch >= 0 ? &walk->guide->patch_frames[patch]
                                                 : frame_about_axis(walk, component_axis(walk, chosen));
            walk->direction = dwvw_guided_direction(frame, &m->dwivedi_event, u);
        }
        walk->phase = dwvw_phase_value(g, previous, walk->direction);
    } else {
        walk->phase = 1.0;
    }
    /* Every component's direction pdf and stretch at the sampled direction: the classical one's
     * the phase function's, the guided ones' component_stretches'. */
    walk->component_pdf[0] = walk->phase;
    walk->component_stretch[0] = 1.0;
    component_stretches(walk);
    float u_distance = stratified ? flight_distance : dwvk_rng_uniform_f(walk->key, dim + DWVW_DIM_DISTANCE);
    walk->step_distance = dwvw_flight(m->sigma_t[channel] * walk->component_stretch[chosen], u_distance);
    return walk->step_distance;
}

/* exp(x) where x equals 0 (then 1, as dwvk_exp_fast(0)) or an earlier argument (then its value):
 * `same` says which of those holds, `earlier` its value. */
static inline double exp_shared(double x, int zero, int same, double earlier)
{
    return zero ? 1.0 : same ? earlier : dwvk_exp_fast(x);
}

/* The channel factors f_c = exp((r - sigma_c) t) of rgb_weight_update (below), for rate r. */
static DWVW_ALWAYS_INLINE void channel_factors(const double sigma_t[3], double rate, double t, double f[3])
{
    f[0] = exp_shared((rate - sigma_t[0]) * t, sigma_t[0] == rate, 0, 0.0);
    f[1] = exp_shared((rate - sigma_t[1]) * t, sigma_t[1] == rate, sigma_t[1] == sigma_t[0], f[0]);
    f[2] = exp_shared((rate - sigma_t[2]) * t, sigma_t[2] == rate, sigma_t[2] == sigma_t[1], f[1]);
}

/* One component's terms of the shared sum D (rgb_weight_update), added to `denominator` in
 * channel order: Q p = qp, stretch s, the rate r and the channel factors f_c = exp((r - sigma_c) t)
 * (the classical component's decays). Only the active channels' exponentials are taken (an
 * inactive one's argument may be positive). */
static DWVW_ALWAYS_INLINE double add_component_terms(double denominator, const double sigma_t[3], const double p[3],
                                                     double qp, double stretch, double rate, const double f[3],
                                                     double t, int exited)
{
    const int on0 = p[0] > 0.0, on1 = p[1] > 0.0, on2 = p[2] > 0.0;
    const double x0 = sigma_t[0] * stretch, x1 = sigma_t[1] * stretch, x2 = sigma_t[2] * stretch;
    double d0 = f[0], d1 = f[1], d2 = f[2];
    if (stretch != 1.0) {
        d0 = on0 ? exp_shared((rate - x0) * t, x0 == rate, 0, 0.0) : 0.0;
        d1 = on1 ? exp_shared((rate - x1) * t, x1 == rate, on0 && x1 == x0, d0) : 0.0;
        d2 = on2 ? exp_shared((rate - x2) * t, x2 == rate, on1 && x2 == x1, d1) : 0.0;
    }
    if (on0) denominator += qp * p[0] * (exited ? 1.0 : x0) * d0;
    if (on1) denominator += qp * p[1] * (exited ? 1.0 : x1) * d1;
    if (on2) denominator += qp * p[2] * (exited ? 1.0 : x2) * d2;
    return denominator;
}

/* rgb_weight_update (below) for one component (Q p = qp, stretch s): the same operations in the
 * same order, without the loops over components and their arrays (which took ~35 instructions
 * more per event, callgrind, slab). */
static void rgb_weight_update_single(dwvw_walk *walk, double qp, double stretch, double t, int exited)
{
    const dwvw_medium *m = walk->medium;
    const double sigma_t[3] = {m->sigma_t[0], m->sigma_t[1], m->sigma_t[2]};
    const double p[3] = {walk->channel_p[0], walk->channel_p[1], walk->channel_p[2]};
    double rate = INFINITY;
    if (qp > 0.0) {
        for (int c = 0; c < 3; ++c) {
            double sigma = sigma_t[c] * stretch;
            if (p[c] > 0.0 && sigma < rate) rate = sigma;
        }
    }
    double f[3];
    channel_factors(sigma_t, rate, t, f);
    double denominator = 0.0;
    if (rate < INFINITY) denominator = add_component_terms(denominator, sigma_t, p, qp, stretch, rate, f, t, exited);
    /* A weight of 0 stays 0 whatever the ratio (0 x a finite ratio, or 0 x 0): it needs no test. */
    for (int c = 0; c < 3; ++c) {
        double numerator = walk->phase * (exited ? 1.0 : sigma_t[c] * m->albedo[c]);
        walk->weight[c] *= dwvw_weight_ratio(numerator * f[c], denominator);
    }
}

/* The weight update of an RGB walk (a medium has 1 or 3 channels) over components first .. end - 1,
 * qp[k] = Q_k p_k.
 *
 * exp((sigma_c' - sigma_c s_k) t) = exp((r - sigma_c s_k) t) exp((sigma_c' - r) t): with r the
 * smallest active sigma_c s_k, the sum D = sum_k,c Q_k p_k P_c pdist_{k,c} exp((r - sigma_c s_k) t)
 * is shared by every channel c' (its largest term has exp(0) = 1 and nothing overflows), and each
 * channel's ratio is f_c' exp((r - sigma_c') t) / D, which underflows to 0 only where the weight
 * is negligible. The classical component (s = 1) reuses those channel factors, so a classical
 * walk needs 3 exponentials per event, a mixture 3 more per guided component (components x 9
 * without the factoring).
 *
 * An argument of 0 (an extinction equal to the rate) has exp(0) = 1 exactly (dwvk_exp_fast(0) is
 * 1): the call is skipped, one of the 3 exponentials of a classical event. Channels with equal
 * extinctions (grey extinction, coloured albedo: a leaf) have equal arguments: one call serves
 * them all. Both leave every value as it was, bit for bit. */
static void rgb_weight_update(dwvw_walk *walk, const double *qp, int first, int end, double t, int exited)
{
    const dwvw_medium *m = walk->medium;
    const double sigma_t[3] = {m->sigma_t[0], m->sigma_t[1], m->sigma_t[2]};
    const double p[3] = {walk->channel_p[0], walk->channel_p[1], walk->channel_p[2]};
    double rate = INFINITY; /* (extinctions are finite and positive: no NaN to order) */
    for (int k = first; k < end; ++k) {
        if (!(qp[k] > 0.0)) continue;
        for (int c = 0; c < 3; ++c) {
            double sigma = sigma_t[c] * walk->component_stretch[k];
            if (p[c] > 0.0 && sigma < rate) rate = sigma;
        }
    }
    double f[3];
    channel_factors(sigma_t, rate, t, f);
    double denominator = 0.0;
    if (rate < INFINITY)
        for (int k = first; k < end; ++k)
            if (qp[k] > 0.0)
                denominator = add_component_terms(denominator, sigma_t, p, qp[k], walk->component_stretch[k], rate, f, t,
                                                  exited);
    /* as in rgb_weight_update_single: a weight of 0 stays 0 */
    for (int c = 0; c < 3; ++c) {
        double numerator = walk->phase * (exited ? 1.0 : sigma_t[c] * m->albedo[c]);
        walk->weight[c] *= dwvw_weight_ratio(numerator * f[c], denominator);
    }
}

/* The sheet technique's weight update, for any channel count: as rgb_weight_update, with the
 * sheet's flight pdf p(tau) = exp(-tau) x dwvk_sheet_flight_pdf_scaled (its tail on leaving) in
 * place of Dwivedi's, so that every term keeps its factor exp(-sigma_c t) and the sum is formed
 * relative to exp(-r t), r the smallest active extinction (nothing overflows; a channel's ratio
 * underflows only where its weight is negligible). */
static void sheet_weight_update(dwvw_walk *walk, double t, int exited)
{
    const dwvw_medium *m = walk->medium;
    const dwvw_guide *guide = walk->guide;
    double rate = INFINITY;
    for (int c = 0; c < m->channels; ++c)
        if (walk->channel_p[c] > 0.0 && m->sigma_t[c] < rate) rate = m->sigma_t[c];
    if (!(rate < INFINITY)) rate = m->sigma_t[0];
    double decay[DWVW_MAX_CHANNELS], denominator = 0.0, sheet = 0.0;
    for (int c = 0; c < m->channels; ++c) {
        double sigma = m->sigma_t[c];
        decay[c] = sigma == rate ? 1.0 : dwvk_exp_fast((rate - sigma) * t);
        if (!(walk->channel_p[c] > 0.0)) continue;
        /* the sheet's pdf depends on the extinction alone: channels of equal extinction share it */
        if (c == 0 || sigma != m->sigma_t[c - 1] || !(walk->channel_p[c - 1] > 0.0)) {
            double a = walk->sheet_a[c], mu = walk->sheet_mu, tau = sigma * t;
            double scaled = exited ? dwvk_sheet_tail_integral(a, mu, tau) : sigma * dwvk_sheet_importance(a + mu * tau);
            sheet = guide->q_sheet * walk->sheet_direction_pdf * scaled / walk->sheet_norm[c];
        }
        double classical = guide->q_classical * walk->phase * (exited ? 1.0 : sigma);
        denominator += walk->channel_p[c] * (classical + sheet) * decay[c];
    }
    for (int c = 0; c < m->channels; ++c) {
        double numerator = walk->phase * (exited ? 1.0 : m->sigma_t[c] * m->albedo[c]) * decay[c];
        walk->weight[c] *= dwvw_weight_ratio(numerator, denominator);
    }
}

/* The sum of a grey step's dwvw_grey_term over the walk's components (Q p formed as
 * mixture_weight_update forms it), in component order, the components of Q p = 0 left out: every
 * slot's term formed in a vectorised loop over all DWVW_MAX_COMPONENTS slots (dwvw_walk_begin
 * fills the unused ones; dwvw_grey_decay's exponential by dwvk_exp_fast_inner, taken where it is
 * not needed too, then dwvw_grey_decay itself where a used argument was beyond its fast range),
 * and the sum then formed in order (a left-out term adds +0 to a sum that is +0 or more: the same
 * bits as skipping it). */
static DWVW_MIXTURE_CLONES double grey_denominator(const dwvw_walk *walk, double sigma_t, double t, int exited)
{
    const int n = walk->component_count;
    const double *restrict q = walk->component_q, *restrict pdf = walk->component_pdf,
                           *restrict stretch = walk->component_stretch;
    double term[DWVW_MAX_COMPONENTS];
    int edges = 0;
    for (int k = 0; k < DWVW_MAX_COMPONENTS; ++k) {
        double qp = q[k] * pdf[k];
        double argument = sigma_t * (1.0 - stretch[k]) * t; /* dwvw_grey_decay's */
        double e = dwvk_exp_fast_inner(argument);
        double decay = stretch[k] == 1.0 ? 1.0 : e;
        int used = (k < n) & (qp > 0.0);
        edges |= dwvk_exp_fast_is_edge(argument) & used;
        term[k] = used ? dwvw_grey_term(qp, stretch[k], decay, exited) : 0.0;
    }
    if (edges)
        for (int k = 0; k < n; ++k) {
            double qp = q[k] * pdf[k];
            term[k] = qp > 0.0 ? dwvw_grey_term(qp, stretch[k], dwvw_grey_decay(sigma_t, stretch[k], t), exited) : 0.0;
        }
    double denominator = 0.0;
    for (int k = 0; k < n; ++k) denominator += term[k];
    return denominator;
}

/* The weight update of a step of Dwivedi and classical components (every technique but sheet). */
static void mixture_weight_update(dwvw_walk *walk, double t, int exited)
{
    const dwvw_medium *m = walk->medium;
    /* weight_c' *= f_c' / p with p = sum_k Q_k p_k sum_c P_c pdist_{k,c}(t); f_c' and each pdist
     * share the factor exp(-sigma t), so the ratio is formed from exp(sigma_c' t - sigma_c s_k t)
     * and neither underflows alone. pdist is sigma s exp(-sigma s t) for a scattering event and
     * exp(-sigma s t) for leaving at t. A walk with one component of weight > 0 has nothing to add
     * from the others (Q = 0): its sums run over that one. */
    int first = 0, end = walk->component_count;
    if (walk->single_component >= 0) {
        first = walk->single_component;
        end = first + 1;
    }
    if (m->channels == 1) {
        /* Grey medium: one channel, P = 1. */
        double denominator = 0.0;
        if (walk->single_component >= 0) {
            double qp = walk->component_q[first] * walk->component_pdf[first], stretch = walk->component_stretch[first];
            if (qp > 0.0) denominator = dwvw_grey_term(qp, stretch, dwvw_grey_decay(m->sigma_t[0], stretch, t), exited);
        } else {
            denominator = grey_denominator(walk, m->sigma_t[0], t, exited);
        }
        walk->weight[0] *= dwvw_grey_ratio(walk->phase, m->albedo[0], denominator, exited);
        return;
    }
    double qp[DWVW_MAX_COMPONENTS];
    for (int k = first; k < end; ++k) qp[k] = walk->component_q[k] * walk->component_pdf[k];
    if (walk->single_component >= 0) rgb_weight_update_single(walk, qp[first], walk->component_stretch[first], t, exited);
    else rgb_weight_update(walk, qp, first, end, t, exited);
}

double dwvw_walk_probe_reach(const dwvw_walk *walk)
{
    if (!(walk->guide->q_backward > 0.0)) return walk->step_distance;
    /* An opposite interface counts within 10 mean free paths of the thinnest channel (Cycles'
     * reach), or within the step. */
    const dwvw_medium *m = walk->medium;
    double sigma_min = m->sigma_t[0];
    for (int c = 1; c < m->channels; ++c) sigma_min = fmin(sigma_min, m->sigma_t[c]);
    return fmax(walk->step_distance, 10.0 / sigma_min);
}

dwvw_status dwvw_walk_complete(dwvw_walk *walk, double hit_distance, dwvu_vec3 hit_normal)
{
    const dwvw_medium *m = walk->medium;
    if (walk->events == 0 && walk->guide->q_backward > 0.0 && hit_distance < INFINITY) {
        /* The first step's probe: an opposite interface within its reach. */
        if (hit_distance <= dwvw_walk_probe_reach(walk)) {
            walk->have_opposite = 1;
            walk->components_vary = 1; /* the backward fraction now follows the depth */
            walk->opposite_depth = -hit_distance * dwvu_dot(walk->direction, walk->entry_normal);
        }
    }
    int exited;
    double t = dwvw_step_length(hit_distance, walk->step_distance, &exited);

    if (walk->guide->q_sheet > 0.0) sheet_weight_update(walk, t, exited);
    else mixture_weight_update(walk, t, exited);
    walk->position = dwvu_madd(walk->position, walk->direction, t);
    if (exited) {
        walk->exit_normal = hit_normal;
        return walk->status = DWVW_EXITED;
    }
    ++walk->events;
    walk->closest_known = 0;

    double largest = 0.0;
    for (int c = 0; c < m->channels; ++c) largest = walk->weight[c] > largest ? walk->weight[c] : largest;
    if (!(largest > 0.0)) return walk->status = DWVW_ABSORBED;
    if (walk->guide->q_sheet > 0.0) {
        /* A sheet walk's weight falls as its importance rises (weight x importance stays near the
         * answer): the roulette weighs that product, relative to the entry's importance z_e, so
         * that walks nearing the lit side are not ended for their small weights. */
        double a[DWVW_MAX_CHANNELS];
        sheet_importance(walk, a);
        largest *= dwvk_sheet_importance(a[m->guide_channel]) / DWVK_SHEET_EXTRAPOLATION;
    }
    if (largest < DWVW_ROULETTE_THRESHOLD) { /* Russian roulette (step.h) */
        double survive;
        if (!dwvw_roulette_survives(walk->key, walk->events, largest, &survive)) {
            for (int c = 0; c < m->channels; ++c) walk->weight[c] = 0.0;
            return walk->status = DWVW_ABSORBED;
        }
        for (int c = 0; c < m->channels; ++c) walk->weight[c] /= survive;
    }
    if (walk->events >= walk->max_events) return walk->status = DWVW_TRUNCATED;
    return walk->status = DWVW_RUNNING;
}
