/* Random walks in a homogeneous medium bounded by a surface, one step at a time.
 *
 * Every step is one sample of a mixture (one-sample MIS, balance heuristic, Veach 1997 Sec. 9.2)
 * over components x colour channels. A component is either the classical (analog) technique or
 * a guided one: Dwivedi sampling about an axis (Krivanek and d'Eon 2014; Meng et al. 2016), its
 * free flight stretched by 1 - mu/v. The techniques differ only in which components a step has:
 *   classical  classical only
 *   poe        the entry point's outward normal
 *   closest    the outward normal of the closest surface point, found again at every event
 *   incident   the outward normals of lit surface patches, weighted by the light they receive
 *              and by exp(-sigma_t distance / v) to the walk (Meng et al. 2016, Sec. 4.3)
 *   backward   the entry normal or its opposite, the latter with probability
 *              1 / (1 + exp(sigma_t (D - 2x) / v)) at depth x below the entry plane when a probe
 *              along the entry direction found an opposite interface at depth D (as Cycles does,
 *              after d'Eon and Krivanek 2020; Cycles mixes world units and mean free paths there)
 *   cycles     Cycles' own mixture: classical 1/2 + backward 1/2 (isotropic media)
 *   sheet      toward the strongest lit patch through a thin sheet, its direction and flight
 *              drawn from an importance linear in the height (src/kernel/sheet.h), with a
 *              classical share max(1%, |g|); classical alone where no light is known
 *   auto       a small classical share + incident (closest where no light is known)
 * The colour channel that drives the distance is chosen with probability proportional to
 * throughput x albedo, as Cycles does; the direction pdfs do not depend on it (v comes from the
 * largest albedo), so a step's pdf is sum_k Q_k p_k(w) sum_c P_c pdist_{k,c}(t). */
#ifndef DWV_WALK_WALK_H
#define DWV_WALK_WALK_H

#include <dwivedi.h>
#include <stdint.h>

#include "kernel/classical.h"
#include "kernel/direction.h"
#include "kernel/dwivedi_sampling.h"
#include "kernel/rng.h"
#include "kernel/sampler.h"
#include "util/vec3.h"

#define DWVW_MAX_CHANNELS 3
#define DWVW_MAX_PATCHES 16
#define DWVW_MAX_COMPONENTS (4 + DWVW_MAX_PATCHES)
#define DWVW_FRAME_CACHE 4 /* a walk's frames kept: backward's two axes and a patch's, with room */
/* Random-number dimensions of event e start at 2 + 6e (0 and 1 are the entry's): +0 the channel,
 * +1 the component (each drawn only where there is a choice), +2 the cosine and the azimuth (one
 * 64-bit draw, two 24-bit uniforms), +4 the distance, +5 the Russian roulette after the event;
 * +3 is unused. */
#define DWVW_DIMS_PER_EVENT 6
#define DWVW_DIM_CHANNEL 0u
#define DWVW_DIM_COMPONENT 1u
#define DWVW_DIM_DIRECTION 2u
#define DWVW_DIM_DISTANCE 4u
#define DWVW_DIM_ROULETTE 5u
#define DWVW_ROULETTE_THRESHOLD 0.5
/* A stratified walk (dwvw_walk_stratify) draws its first events from a pixel's sampler instead:
 * event e takes pairs first + 2e and first + 2e + 1,
 *   +0 (the free flight's uniform, the choice): the choice picks the channel, and its remainder
 *      within the channel's interval, (u - P(below)) / P(channel), uniform again and independent
 *      of the channel, picks the component (one stratified number for the two discrete choices,
 *      as Cycles folds its channel choice into the distance's number; here the distance keeps
 *      all its bits);
 *   +1 (the cosine, the azimuth), unused by event 0, whose direction is the entry's.
 * The distance and the channel share a pair because together they set the step's length; the
 * cosine and azimuth because together they are a point on the sphere of directions. The
 * roulette keeps its counter-based number: it acts only once the throughput is below the
 * threshold, after the first events. */
#define DWVW_PAIRS_PER_EVENT 2u
#define DWVW_PAIR_FLIGHT 0u
#define DWVW_PAIR_DIRECTION 1u

typedef enum dwvw_technique {
    DWVW_AUTO = 0,
    DWVW_CLASSICAL = 1,
    DWVW_POE = 2,
    DWVW_CLOSEST = 3,
    DWVW_INCIDENT = 4,
    DWVW_BACKWARD = 5,
    DWVW_CYCLES = 6,
    DWVW_SHEET = 7
} dwvw_technique;
#define DWVW_TECHNIQUE_COUNT 8
/* The API passes dwv_technique_t values through as dwvw_technique: the same numbers. */
_Static_assert((int)DWVW_AUTO == DWV_TECHNIQUE_AUTO && (int)DWVW_CLASSICAL == DWV_TECHNIQUE_CLASSICAL &&
                   (int)DWVW_POE == DWV_TECHNIQUE_POE && (int)DWVW_CLOSEST == DWV_TECHNIQUE_CLOSEST &&
                   (int)DWVW_INCIDENT == DWV_TECHNIQUE_INCIDENT && (int)DWVW_BACKWARD == DWV_TECHNIQUE_BACKWARD &&
                   (int)DWVW_CYCLES == DWV_TECHNIQUE_CYCLES && (int)DWVW_SHEET == DWV_TECHNIQUE_SHEET &&
                   (int)DWVW_TECHNIQUE_COUNT == DWV_TECHNIQUE_SHEET + 1,
               "dwvw_technique must equal dwv_technique_t (capi/dwivedi.h)");
/* The sheet technique's classical share in isotropic media (|g| where that is larger): its
 * direction pdf ignores the phase function's peak, and its flight reaches no farther below the
 * walk than the importance stays positive, so the classical share covers every path
 * (Hesterberg's defensive mixture: the weight per event is at most 1 / share). */
#define DWVW_SHEET_CLASSICAL_SHARE 0.01
/* A sheet walk whose entry normal makes a cosine below minus this with the lit normal (its entry
 * face within 60 degrees of facing away from the light: a far face) takes the entry face's inward
 * normal as its axis; other far-side entries (a sheet's rim, faces nearly along the light) keep the
 * lit normal (dwvw_walk_begin). */
#define DWVW_SHEET_LOCAL_COSINE 0.5

typedef struct dwvw_medium {
    int channels;                        /* 1 (grey) or 3 */
    double sigma_t[DWVW_MAX_CHANNELS];   /* extinction, > 0 */
    double albedo[DWVW_MAX_CHANNELS];    /* single-scattering albedo in [0, 1] */
    double g;                            /* Henyey-Greenstein anisotropy in (-1, 1) */
    int guide_channel;                   /* the channel with the largest albedo */
    dwvk_dwivedi_d dwivedi;              /* the direction distribution, from that albedo */
    dwvk_dwivedi_f dwivedi_f;            /* the same in single precision */
    dwvk_dwivedi_event_f dwivedi_event;  /* the per-event sampler's constants */
    double guided_pdf_scale;             /* a / (4 pi): a guided direction pdf is this / stretch */
} dwvw_medium;

/* A lit part of the surface: an infinite plane (distance measured to the plane) or a patch
 * around a point; `power` is the light it receives (irradiance x area), > 0. */
typedef struct dwvw_light_patch {
    dwvu_vec3 point, normal;
    double power;
    double log_power; /* log(power), kept by dwvw_guide_init */
    int is_plane;
} dwvw_light_patch;

/* What a technique mixes, fixed for a walk. */
typedef struct dwvw_guide {
    double q_classical, q_poe, q_closest, q_incident, q_backward; /* sum to 1 with q_sheet */
    double q_sheet;
    dwvu_vec3 sheet_normal; /* the sheet technique's lit normal: the strongest patch's */
    int patch_count;
    dwvw_light_patch patches[DWVW_MAX_PATCHES];
    int patches_distinct; /* no two patch normals as close as a component's merge (dwvw_guide_init) */
    dwvu_frame patch_frames[DWVW_MAX_PATCHES]; /* dwvu_frame_about of each patch's normal, made once */
    /* The patches' points, normals, log powers and kinds again, by coordinate (copied by
     * dwvw_guide_init), for the patch weights' loop over patches, which a compiler vectorises
     * (walk.c, incident_weights). */
    double patch_point[3][DWVW_MAX_PATCHES], patch_normal[3][DWVW_MAX_PATCHES];
    double patch_log_power[DWVW_MAX_PATCHES];
    int64_t patch_is_plane[DWVW_MAX_PATCHES]; /* 64 bits, as the doubles it selects between */
} dwvw_guide;

typedef enum dwvw_status {
    DWVW_RUNNING = 0,    /* scattered inside; take another step */
    DWVW_EXITED = 1,     /* left through the surface: exit_point, exit_normal, weight */
    DWVW_ABSORBED = 2,   /* ended by Russian roulette or zero throughput */
    DWVW_TRUNCATED = 3   /* ended by the event cap: its weight is reported, not dropped */
} dwvw_status;
/* dwv_walk_step reports a dwvw_status as a dwv_walk_status_t: the same numbers. */
_Static_assert((int)DWVW_RUNNING == DWV_WALK_RUNNING && (int)DWVW_EXITED == DWV_WALK_EXITED &&
                   (int)DWVW_ABSORBED == DWV_WALK_ABSORBED && (int)DWVW_TRUNCATED == DWV_WALK_TRUNCATED,
               "dwvw_status must equal dwv_walk_status_t (capi/dwivedi.h)");

/* The stratified pairs of walks that draw the same ones (the channel walks of one sample, which
 * share the sampler and first pair): each pair's bits are made once, by the first walk that needs
 * them, and read by the others. DWVW_PAIR_CACHE pairs from first_pair; `have` bit k: pair
 * first_pair + k is known, with dwvk_sampler_pair_bits's answer in `stratified` bit k (0: the pair
 * is not stratified, and its numbers are the counter-based ones) and its bits in bits[k]. */
#define DWVW_PAIR_CACHE 32u
typedef struct dwvw_pair_cache {
    uint32_t first_pair;
    uint32_t have, stratified;
    uint64_t bits[DWVW_PAIR_CACHE];
} dwvw_pair_cache;

typedef struct dwvw_walk {
    const dwvw_medium *medium;
    const dwvw_guide *guide;
    uint64_t key;          /* counter-based RNG key of this walk */
    const dwvk_sampler *sampler;  /* NULL, or the pixel's sampler for the first events */
    uint32_t index_reversed;      /* dwvk_sampler_index_reversed(sampler), once per walk */
    uint32_t first_pair;          /* the sampler's pair of event 0 (DWVW_PAIR_* above) */
    uint32_t stratified_events;   /* events 0 .. this - 1 are drawn from the sampler */
    dwvw_pair_cache *pair_cache;  /* NULL, or the pairs this walk shares with others */
    uint32_t max_events;
    uint32_t events;       /* scattering events so far */
    dwvw_status status;
    dwvu_vec3 position, direction;
    dwvu_vec3 entry_point, entry_normal; /* entry_normal points out of the medium */
    double weight[DWVW_MAX_CHANNELS];    /* throughput; on exit, the walk's estimate */
    dwvu_vec3 exit_normal;
    int have_opposite;
    double opposite_depth;
    /* the pending step, between dwvw_walk_sample and dwvw_walk_complete */
    dwvu_vec3 closest_normal;
    int closest_known;
    double step_distance;
    int component_count;                            /* 0 until the first step builds them */
    int components_vary;                            /* rebuilt at every event (else kept) */
    int single_component;                           /* the only component with q > 0, else -1 */
    double component_q[DWVW_MAX_COMPONENTS];
    /* the components' axes by coordinate (x, y, z), for the loop of cosines over components,
     * which a compiler vectorises (walk.c, component_stretches); unused for component 0 (classical) */
    double component_axis[3][DWVW_MAX_COMPONENTS];
    int component_patch[DWVW_MAX_COMPONENTS];      /* the patch whose frame it takes (the guide's), or -1 */
    double component_pdf[DWVW_MAX_COMPONENTS];     /* direction pdf per steradian */
    double component_stretch[DWVW_MAX_COMPONENTS];
    double channel_p[DWVW_MAX_CHANNELS];
    double phase;                                   /* phase function value of the step */
    /* the sheet technique's step: linear importance a per channel at its start (the importance is
     * max(a, DWVK_SHEET_FLOOR), src/kernel/sheet.h), its cosine to the lit
     * normal, the flight's normalisation N per channel, and its direction pdf per steradian (1 on
     * the first step) */
    double sheet_a[DWVW_MAX_CHANNELS], sheet_norm[DWVW_MAX_CHANNELS], sheet_mu, sheet_direction_pdf;
    dwvu_vec3 sheet_normal; /* the walk's sheet axis: the lit normal or its entry face's (dwvw_walk_begin) */
    /* Frames about the guided axes met so far (an axis repeats from event to event for every
     * technique but closest): dwvu_frame_about is a function of the axis's bits alone. */
    uint32_t frames_made;                           /* frames made so far; the slot of the next */
    dwvu_frame frames[DWVW_FRAME_CACHE];
} dwvw_walk;

/* Fills a medium; the caller validated the values. */
void dwvw_medium_init(dwvw_medium *medium, int channels, const double *sigma_t, const double *albedo, double g);
/* The component weights of a technique for a medium and its lit patches (copied in). */
void dwvw_guide_init(dwvw_guide *guide, dwvw_technique technique, const dwvw_medium *medium,
                     const dwvw_light_patch *patches, int patch_count);
/* Which techniques need the closest surface point at every event, and which a first-step probe. */
int dwvw_guide_needs_closest(const dwvw_guide *guide);

/* Starts a walk at `point` heading along unit `direction` into the medium, whose outward normal
 * there is `normal`; weight 1 in every channel. */
void dwvw_walk_begin(dwvw_walk *walk, const dwvw_medium *medium, const dwvw_guide *guide, uint64_t key,
                     uint32_t max_events, dwvu_vec3 point, dwvu_vec3 direction, dwvu_vec3 normal);
/* After dwvw_walk_begin, for a sheet walk (else nothing changes): its axis by the entry triangle's
 * geometric normal (outward, unit or 0) instead of the entry normal, which begin takes: a smooth
 * normal near a sheet's rim blends the far face's with the rim's, tilted toward the rim, and the
 * walks entering there drew their importance along that tilt (the bent sheet's remaining tail). */
void dwvw_walk_sheet_face(dwvw_walk *walk, dwvu_vec3 face_normal);
/* After dwvw_walk_begin: draws the channel, component, direction and distance of events
 * 0 .. events - 1 from `sampler`'s pairs first_pair, first_pair + 1, ... (DWVW_PAIR_* above)
 * instead of from the walk's key; the sampler must outlive the walk. Every number is still a
 * uniform independent of the walk's others (kernel/sampler.h), so the walk's distribution is the
 * same; only the walks of one pixel are stratified against each other. Events whose pairs would
 * pass 2^32 - 1 stay counter-based. */
void dwvw_walk_stratify(dwvw_walk *walk, const dwvk_sampler *sampler, uint32_t first_pair, uint32_t events);
/* After dwvw_walk_stratify: the walk takes its stratified pairs from `cache`, making and keeping
 * there those it is the first to need (a cache whose first_pair is not the walk's is not used).
 * Walks that share a cache draw the same numbers they would draw without it, bit for bit. */
void dwvw_walk_share_pairs(dwvw_walk *walk, dwvw_pair_cache *cache);
/* Before dwvw_walk_sample, where the guide needs it: the closest surface point's outward normal. */
void dwvw_walk_set_closest(dwvw_walk *walk, dwvu_vec3 normal);
/* Samples the next step's direction (walk->direction) and tentative distance (return value). */
double dwvw_walk_sample(dwvw_walk *walk);
/* Reports what the ray along walk->direction met: the surface at `hit_distance` (+INFINITY for
 * none) with outward normal `hit_normal`. On the first step hit_distance is the probe's full
 * answer (not cut at the sampled distance), which locates the opposite interface. Returns the
 * new status. */
dwvw_status dwvw_walk_complete(dwvw_walk *walk, double hit_distance, dwvu_vec3 hit_normal);
/* After dwvw_walk_sample on the first step: the distance up to which the probe's answer is used,
 * the sampled distance (an exit) or, for the backward technique, the reach within which an
 * opposite interface counts if that is longer. A probe that looks no further and reports a hit
 * beyond it as none leaves the walk the same. */
double dwvw_walk_probe_reach(const dwvw_walk *walk);

/* The mixture weights `auto` uses for a medium: see the definition for the heuristic. */
void dwvw_auto_weights(const dwvw_medium *medium, int patch_count, double *q_classical, double *q_closest,
                       double *q_incident);

#endif
