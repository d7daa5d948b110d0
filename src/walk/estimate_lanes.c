/* The estimator's guided and mixture walkers in lock-step lanes: the walks of guided_walk_in and
 * mixture_walk_in (estimate_fast.c), DWVW_LANES (16) at a time. Their step pieces are step.h's and
 * estimate_walkers.h's, as there; what is written out here is the lanes' form of a step (a loop
 * over the lanes per stage, selects for branches). */
#include <float.h>
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "estimate_walkers.h"
#include "geometry.h"
#include "kernel/exp_batch.h"
#include "step.h"

/* ---- lock-step: several walks advanced together ---------------------------------------------
 * One event of guided_walk_in is a long chain of dependent operations (hash, expm1, square root,
 * direction, stretch, log, two divisions): a core that runs one walk waits on it. DWVW_LANES walks
 * in lanes (structure of arrays) take their events together, one loop over the lanes per stage,
 * so that the lanes' chains interleave (and a compiler may vectorise a stage). Each lane does
 * exactly what guided_walk_in (or mixture_walk_in, for the mixture walker in an isotropic medium)
 * does for its walk, with the same random numbers (the walk's key and dimensions), the same
 * kernels and the same double arithmetic in the same order, so each walk ends as it does there,
 * weight for weight to the last bit (tests/internal/test_walk_fast_path.c compares them walk by
 * walk). What changes is only which walks run at the same time: the branches that end a walk
 * (exit, Russian roulette, event cap) are taken for a lane after the step, and a lane whose walk
 * ended takes the next walk of its thread's blocks. Results are added to their block in walk
 * order (lane_feed), so the totals equal the one-walk-at-a-time path's. */

/* The lane steps' loops are written for a compiler to vectorise; on x86-64 each step is compiled
 * three times, for the baseline (SSE2: two doubles a vector), x86-64-v3 (AVX2: four) and
 * x86-64-v4 (AVX-512: eight), and the first call picks the copy the processor runs (GCC's
 * target_clones, an ifunc). All copies do the same IEEE operations in the same order: this file is compiled with -ffp-contract=off (no
 * fused multiply-add, which would round differently) and -fno-trapping-math (which lets the
 * selects be computed on both sides, changing no value), so the walks are the same to the last
 * bit on every processor (tests/internal/test_walk_fast_path.c compares them with the one-walk
 * path, which is not cloned). */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && __GNUC__ >= 12
#define DWVW_LANE_CLONES __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4")))
#else
#define DWVW_LANE_CLONES
#endif

_Static_assert(DWVW_LANES <= 32, "the flagged lanes are a 32-bit mask (lanes_run_in)");

/* The log table's rows {1/c, log c} for 16 lanes' indices. On x86-64 processors with AVX-512 the
 * table's 32 rows are held as columns in registers (lane_log_columns, four vectors of 8 doubles
 * each) and read by two-source permutes (vpermi2pd): 2 permutes and a blend per 8 lanes and column,
 * where the scalar loop extracts each index and loads each entry (the lookups were about a seventh
 * of the poe step's instructions). The permutes are GCC's vector extensions, compiled into every
 * copy of a step, but only the AVX-512 copy makes them vpermi2pd (the others lower them to scalar
 * code, slower than the loop), so the steps choose by the processor at run time (lane_state.permute,
 * the test the clones' resolver makes for the AVX-512 copy). The same table entries either way: no
 * value depends on the path. */
_Static_assert(DWVK_LOG_TABLE_SIZE == 32, "the permuted lookup holds 32 rows in four 8-double vectors");

typedef struct lane_log_columns {
    double invc[DWVK_LOG_TABLE_SIZE], logc[DWVK_LOG_TABLE_SIZE];
} lane_log_columns;

static void lane_log_columns_fill(lane_log_columns *columns)
{
    for (int i = 0; i < DWVK_LOG_TABLE_SIZE; ++i) {
        columns->invc[i] = DWVK_LOG_TABLE[i][0];
        columns->logc[i] = DWVK_LOG_TABLE[i][1];
    }
}

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && __GNUC__ >= 12
#define DWVW_LANE_PERMUTE 1
typedef double lane_v8d __attribute__((vector_size(64)));
typedef int64_t lane_v8l __attribute__((vector_size(64)));
typedef int32_t lane_v8i __attribute__((vector_size(32)));

/* Entry `index` (0 .. 31) of 8 lanes from a 32-entry column held as four vectors: the lower or
 * upper 16 by bit 4 of the index (the permute reads bits 0-3). Written to memory, not returned (a
 * vector return would change the ABI between the clones). */
static DWVW_ALWAYS_INLINE void lane_permute32(const lane_v8d column[4], lane_v8l index, double *out)
{
    lane_v8l upper = -((index >> 4) & 1);
    lane_v8l low = (lane_v8l)__builtin_shuffle(column[0], column[1], index);
    lane_v8l high = (lane_v8l)__builtin_shuffle(column[2], column[3], index);
    lane_v8l entry = (low & ~upper) | (high & upper);
    memcpy(out, &entry, sizeof entry);
}

static DWVW_ALWAYS_INLINE void lanes_log_rows_permute(const lane_log_columns *columns, const int32_t *index,
                                                   double *invc, double *logc)
{
    lane_v8d invc_column[4], logc_column[4];
    memcpy(invc_column, columns->invc, sizeof invc_column);
    memcpy(logc_column, columns->logc, sizeof logc_column);
    for (int h = 0; h < DWVW_LANES; h += 8) {
        lane_v8i narrow; /* widened by one conversion (an element at a time, it took ~20 shuffles) */
        memcpy(&narrow, index + h, sizeof narrow);
        lane_v8l lanes_index = __builtin_convertvector(narrow, lane_v8l);
        lane_permute32(invc_column, lanes_index, invc + h);
        lane_permute32(logc_column, lanes_index, logc + h);
    }
}

static int lanes_can_permute(void)
{
    return __builtin_cpu_supports("x86-64-v4") != 0;
}
#else
#define DWVW_LANE_PERMUTE 0
static int lanes_can_permute(void)
{
    return 0;
}
#endif

_Static_assert(DWVW_LANES % 8 == 0, "the permuted lookup takes the lanes 8 at a time");

/* The lanes' state. p: position; d: the direction of the last step (a step forms its own; at
 * events = 0 it is the entry direction, entry_*). log_constants and exponent as in guided_walk_in,
 * weight as in mixture_walk_in. */
typedef struct lane_state {
    double px[DWVW_LANES], py[DWVW_LANES], pz[DWVW_LANES];
    double dx[DWVW_LANES], dy[DWVW_LANES], dz[DWVW_LANES];
    double log_constants[DWVW_LANES], exponent[DWVW_LANES], log_weight[DWVW_LANES], stretch[DWVW_LANES];
    double first_constant[DWVW_LANES]; /* the first step's log(alpha / s0) */
    double entry_x[DWVW_LANES], entry_y[DWVW_LANES], entry_z[DWVW_LANES]; /* the entry direction */
    uint64_t key[DWVW_LANES], counter[DWVW_LANES];
    uint32_t events[DWVW_LANES];
    int exited[DWVW_LANES];
    double weight[DWVW_LANES];         /* the mixture's throughput (mixture_lanes_step_in) */
    lane_log_columns log_columns;      /* the log table by columns, and whether to permute it */
    int permute;                       /*   (lanes_unit_flights) */
} lane_state;

/* What every walk of a run starts from, worked out once per run: the key's first hash (a
 * function of the seed alone), and, where every walk enters the same way, its entry direction
 * (a fixed incidence: a square root per walk before). */
typedef struct lane_template {
    uint64_t seed_base;
    uint64_t counter_offset;       /* the key's counter of event 0's stepped dimension, less the key */
    int same_entry;
    dwvu_vec3 direction;           /* same_entry: the entry direction */
    double first_constant;         /* plan->first_known: log(alpha / s0) */
} lane_template;

static lane_template lane_template_for(const dwvw_estimate_setup *setup, const dwvw_fast_plan *plan)
{
    lane_template t;
    t.seed_base = dwvk_rng_seed_base(setup->seed);
    /* The guided walk steps the counter of an event's direction dimension, the mixture that of its
     * first (channel) dimension. */
    uint32_t dimension = plan->walker == DWVW_WALKER_MIXTURE ? DWVW_DIM_CHANNEL : DWVW_DIM_DIRECTION;
    t.counter_offset = dwvk_rng_counter(0, dwvw_event_dim(0) + dimension);
    t.same_entry = !setup->incidence_diffuse;
    t.direction = dwvw_entry_direction(setup, 0); /* the key is not read for a fixed incidence */
    t.first_constant = plan->log_first;
    return t;
}

/* What a fixed incidence makes the same for every walk, put into every lane once per run: the
 * entry direction and the first step's constant (lane_begin then leaves them; the steps only read
 * them). */
static void lanes_fill_template(lane_state *L, const lane_template *t)
{
    for (int l = 0; l < DWVW_LANES; ++l) {
        L->entry_x[l] = t->direction.x;
        L->entry_y[l] = t->direction.y;
        L->entry_z[l] = t->direction.z;
        L->first_constant[l] = t->first_constant;
    }
}

/* The entry of a walk in lane l where the incidence is diffuse (each walk its own, from its key). */
static void lane_begin_entry(lane_state *L, int l, const dwvw_estimate_setup *setup, const dwvw_fast_plan *plan,
                             uint64_t key)
{
    dwvu_vec3 direction = dwvw_entry_direction(setup, key);
    L->entry_x[l] = direction.x;
    L->entry_y[l] = direction.y;
    L->entry_z[l] = direction.z;
    double stretch = dwvk_dwivedi_stretch_d(&setup->medium.dwivedi, dwvw_aligned_cosine(plan, direction));
    L->first_constant[l] = log(setup->medium.albedo[0] / stretch);
}

/* Puts walk `index` into lane l at its entry, as guided_walk_in starts it. Only what a step reads
 * before it writes it: a step forms the direction (the entry one at events = 0) and the log weight
 * itself, and a fixed incidence's entry is in every lane already (lanes_fill_template). Inlined
 * into the refill, as feed_next is (the two calls took 5% of the time for poe on the half-space). */
static DWVW_ALWAYS_INLINE void lane_begin(lane_state *L, int l, const dwvw_estimate_setup *setup,
                                          const dwvw_fast_plan *plan, const lane_template *t, uint64_t index)
{
    uint64_t key = dwvk_rng_key_from_base(t->seed_base, index, 0); /* = dwvk_rng_key(seed, index, 0) */
    L->key[l] = key;
    L->counter[l] = key + t->counter_offset; /* dwvk_rng_counter: the same sum mod 2^64 */
    L->px[l] = DWVW_ENTRY_POINT.x;
    L->py[l] = DWVW_ENTRY_POINT.y;
    L->pz[l] = DWVW_ENTRY_POINT.z;
    L->events[l] = 0;
    L->log_constants[l] = L->exponent[l] = 0.0;
    L->weight[l] = 1.0;
    if (!t->same_entry) lane_begin_entry(L, l, setup, plan, key); /* same_entry = plan->first_known */
}

/* The lanes' unit free flights dwvk_free_flight(u) = -log(1 - u), bit for bit, in three loops: the
 * logarithm's arithmetic before and after its table lookups (vectorised), and the lookups between
 * (gathers, which keep a loop from being vectorised, or the permutes above). Apart from the step's
 * main loop for the same reason. */
static inline void lanes_unit_flights(const lane_state *L, const float *u, double *unit_flight)
{
    int32_t index[DWVW_LANES], k[DWVW_LANES];
    double z[DWVW_LANES], invc[DWVW_LANES], logc[DWVW_LANES];
    for (int l = 0; l < DWVW_LANES; ++l) index[l] = dwvk_log_fast_split(1.0f - u[l], &k[l], &z[l]);
#if DWVW_LANE_PERMUTE
    if (L->permute) {
        lanes_log_rows_permute(&L->log_columns, index, invc, logc);
    } else
#else
    (void)L; /* a build without the permuted lookup (not GCC 12+ on x86-64 Linux) */
#endif
    {
        for (int l = 0; l < DWVW_LANES; ++l) {
            invc[l] = DWVK_LOG_TABLE[index[l]][0];
            logc[l] = DWVK_LOG_TABLE[index[l]][1];
        }
    }
    for (int l = 0; l < DWVW_LANES; ++l) unit_flight[l] = -dwvk_log_fast_join(k[l], z[l], invc[l], logc[l]);
}

/* The distance along w from p to a plane face, as dwvw_shape_exit_inline gives it, with every
 * operation done whatever the sign (a lane's select, not a branch: the division's unused results
 * are discarded). */
static inline double lane_halfspace_exit(double pz, double wz)
{
    double toward_front = dwvw_front_plane_distance(pz, wz);
    return wz < 0.0 ? toward_front : INFINITY;
}

static inline double lane_slab_exit(double thickness, double pz, double wz)
{
    double toward_front = dwvw_front_plane_distance(pz, wz), toward_back = dwvw_back_plane_distance(thickness, pz, wz);
    return wz < 0.0 ? toward_front : wz > 0.0 ? toward_back : INFINITY;
}

/* One event of every lane (lanes whose walk ended compute on without effect until refilled).
 * Returns the flagged lanes (bit l: lane l), those where guided_walk_in would take a branch after
 * the step: the walk exited, its weight fell below the roulette threshold, or it reached the event
 * cap (a mask formed in the vector loop: lanes_run_in read an array of flags back one by one).
 * Each stage is a loop over the lanes without branches, for the compiler to vectorise. The plan's
 * frame is the one about a z axis (make_plan): direction (c, sz d, sz mu) for azimuth (c, d)
 * turned by its quarter turns (the same products as aligned_guided_direction's turned frame, signs
 * exact). */
/* Each shape's step gets its own copy of the loops, with its exit test (GCC and Clang otherwise
 * judge the function too large to inline three times). */

static DWVW_ALWAYS_INLINE uint32_t guided_lanes_step_in(lane_state *L, const dwvw_estimate_setup *setup,
                                                        const dwvw_fast_plan *plan, dwvw_shape_kind kind)
{
    const dwvw_medium *m = &setup->medium;
    const dwvk_dwivedi_event_f *d = &m->dwivedi_event;
    const double sigma = m->sigma_t[0], log_per_event = plan->log_per_event, thickness = setup->shape.thickness;
    const uint32_t max_events = setup->max_events;
    const uint64_t to_distance = DWVW_DIM_COUNTER_OFFSET(DWVW_DIM_DIRECTION, DWVW_DIM_DISTANCE);
    const double sy = plan->sign[0][1], sz = plan->sign[0][2], axis_sign = plan->axis_sign;
    const double kappa = m->dwivedi.kappa, one_minus_kappa = m->dwivedi.one_minus_kappa;
    float ua[DWVW_LANES], ub[DWVW_LANES], udist[DWVW_LANES];
    float cos_theta[DWVW_LANES], sin_theta[DWVW_LANES], azimuth_c[DWVW_LANES], azimuth_s[DWVW_LANES];
    for (int l = 0; l < DWVW_LANES; ++l) {
        dwvk_uniform_pair_f u = dwvw_counter_uniform_pair_f(L->counter[l]);
        ua[l] = u.a;
        ub[l] = u.b;
        udist[l] = dwvw_counter_uniform_f(L->counter[l] + to_distance);
        L->counter[l] += DWVW_EVENT_COUNTER_STEP;
    }
    double unit_flight[DWVW_LANES];
    lanes_unit_flights(L, udist, unit_flight);
    for (int l = 0; l < DWVW_LANES; ++l) {
        dwvk_dwivedi_event_cosine_f s = dwvk_dwivedi_event_sample_select_f(d, ua[l]);
        dwvk_unit2_f azimuth = dwvk_azimuth_f(ub[l]); /* turned by its quarter turns */
        cos_theta[l] = s.cos_theta;
        sin_theta[l] = s.sin_theta;
        azimuth_c[l] = azimuth.c;
        azimuth_s[l] = azimuth.s;
    }
    for (int l = 0; l < DWVW_LANES; ++l) {
        double wx = (double)azimuth_c[l] * (double)sin_theta[l];
        double wy = sy * ((double)azimuth_s[l] * (double)sin_theta[l]);
        double wz = sz * (double)cos_theta[l];
        double scale = 1.5 - 0.5 * (wx * wx + wy * wy + wz * wz);
        int fresh = L->events[l] == 0; /* the first step keeps the entry direction */
        double ex = L->entry_x[l], ey = L->entry_y[l], ez = L->entry_z[l];
        L->dx[l] = fresh ? ex : wx * scale;
        L->dy[l] = fresh ? ey : wy * scale;
        L->dz[l] = fresh ? ez : wz * scale;
    }
    uint32_t flagged_lanes = 0;
    for (int l = 0; l < DWVW_LANES; ++l) {
        double px = L->px[l], py = L->py[l], pz = L->pz[l], wx = L->dx[l], wy = L->dy[l], wz = L->dz[l];
        double mu = dwvw_clamp_cosine(axis_sign * wz);
        /* dwvk_dwivedi_stretch_d, its constants loaded before the loop and both sides formed. */
        double stretch_above = one_minus_kappa + kappa * (1.0 - mu), stretch_below = 1.0 - kappa * mu;
        double stretch = mu >= 0.0 ? stretch_above : stretch_below;
        double t = dwvw_unit_flight_scaled(unit_flight[l], sigma * stretch);
        double hit;
        if (kind == DWVW_HALFSPACE) hit = lane_halfspace_exit(pz, wz);
        else if (kind == DWVW_SLAB) hit = lane_slab_exit(thickness, pz, wz);
        else {
            dwvu_vec3 normal;
            hit = dwvw_shape_exit_inline(&setup->shape, kind, dwvu_v(px, py, pz), dwvu_v(wx, wy, wz), &normal);
        }
        int exited;
        double step = dwvw_step_length(hit, t, &exited);
        double exponent = dwvw_guided_exponent(L->exponent[l], stretch, step);
        double before = L->log_constants[l], first = L->first_constant[l]; /* loaded unconditionally */
        double later = before + log_per_event;
        double log_constants = exited ? before : L->events[l] > 0 ? later : first;
        uint32_t events = L->events[l] + (uint32_t)!exited;
        double log_weight = dwvw_guided_log_weight(log_constants, sigma, exponent);
        /* An exited lane keeps the position the step started from: the exit normal is found again
         * from it (guided_lane_end). */
        double flight = exited ? 0.0 : t; /* p + w 0 = p: a store in every lane, no conditional one */
        L->px[l] = px + wx * flight;
        L->py[l] = py + wy * flight;
        L->pz[l] = pz + wz * flight;
        L->exponent[l] = exponent;
        L->log_constants[l] = log_constants;
        L->log_weight[l] = log_weight;
        L->stretch[l] = stretch;
        L->events[l] = events;
        L->exited[l] = exited;
        uint32_t flagged = (uint32_t)(exited | (log_weight < DWVW_LOG_ROULETTE_THRESHOLD) | (events >= max_events));
        flagged_lanes |= flagged << l;
    }
    return flagged_lanes;
}

/* guided_lanes_step_in for each shape, its exit test written out. */
DWVW_LANE_CLONES static uint32_t guided_lanes_step_halfspace(lane_state *L, const dwvw_estimate_setup *setup,
                                                             const dwvw_fast_plan *plan)
{
    return guided_lanes_step_in(L, setup, plan, DWVW_HALFSPACE);
}

DWVW_LANE_CLONES static uint32_t guided_lanes_step_slab(lane_state *L, const dwvw_estimate_setup *setup,
                                                        const dwvw_fast_plan *plan)
{
    return guided_lanes_step_in(L, setup, plan, DWVW_SLAB);
}

DWVW_LANE_CLONES static uint32_t guided_lanes_step_sphere(lane_state *L, const dwvw_estimate_setup *setup,
                                                          const dwvw_fast_plan *plan)
{
    return guided_lanes_step_in(L, setup, plan, DWVW_SPHERE);
}

/* The branches of guided_walk_in after a flagged step of lane l: 1 if its walk ended, else 0 (the
 * walk goes on, its weight perhaps raised by the roulette). An ended walk's status, events and
 * exit normal are in *end, and its weight is exp(*log_weight) x *last_factor, 0 if absorbed
 * (dwvw_guided_end): left to the caller, which takes the exponentials of several ends together
 * (lanes_end_weights). */
static int guided_lane_end(lane_state *L, int l, const dwvw_estimate_setup *setup, const dwvw_fast_plan *plan,
                           dwvw_shape_kind kind, dwvw_walk_end *end, double *log_weight_out, double *last_factor_out)
{
    double last_factor = 1.0;
    uint32_t events = L->events[l];
    end->exit_normal = dwvu_v(0.0, 0.0, 0.0);
    if (L->exited[l]) {
        dwvu_vec3 normal;
        (void)dwvw_shape_exit_inline(&setup->shape, kind, dwvu_v(L->px[l], L->py[l], L->pz[l]),
                                     dwvu_v(L->dx[l], L->dy[l], L->dz[l]), &normal);
        last_factor = dwvw_guided_exit_factor(plan, events, L->stretch[l]);
        end->status = DWVW_EXITED;
        end->exit_normal = normal;
    } else {
        if (L->log_weight[l] < DWVW_LOG_ROULETTE_THRESHOLD) {
            double log_weight = L->log_weight[l];
            int fate = dwvw_guided_roulette(L->key[l], events, &log_weight);
            if (fate == 0) {
                end->status = DWVW_ABSORBED;
                goto done;
            }
            if (fate == 2) {
                L->log_weight[l] = log_weight;
                L->log_constants[l] = dwvw_guided_constants_for(log_weight, setup->medium.sigma_t[0], L->exponent[l]);
            }
        }
        if (events < setup->max_events) return 0;
        end->status = DWVW_TRUNCATED;
    }
done:
    end->events = events;
    *log_weight_out = L->log_weight[l];
    *last_factor_out = last_factor;
    return 1;
}

/* Where the lanes' walks come from and where their ends go: a thread's blocks of a run (walks are
 * numbered in the order the thread starts them, and a ring of ends adds them to their blocks in
 * that order, so a block's totals are summed in walk order as in worker()), or a range of walks
 * whose ends are all kept (dwvw_estimate_walks_lanes).
 * The ring holds the ends of the walks begun after the oldest one still running; when it is full,
 * lanes wait idle. Walk lengths have a long tail (at albedo 0.99 on the half-space a walk of a few
 * hundred events is common), and with DWVW_LANE_RING_SMALL (256) ends such a walk left lanes idle
 * for about 7% of the lane-steps of poe on the half-space (callgrind: steps x lanes less events and
 * ends); DWVW_LANE_RING (1024, allocated) leaves none measurable. Which ring a run has changes no
 * result: the blocks are summed in walk order either way. */
#define DWVW_LANE_RING 1024u
#define DWVW_LANE_RING_SMALL 256u /* on the stack, where the allocation fails */
/* A guided run's ends are added to their blocks DWVW_END_BATCH at a time, their exponentials
 * taken together (lanes_end_weights): one vector of doubles in the AVX-512 copy. The rings hold
 * whole batches, so a batch never wraps around one. */
#define DWVW_END_BATCH 8u
_Static_assert(DWVW_LANE_RING % DWVW_END_BATCH == 0 && DWVW_LANE_RING_SMALL % DWVW_END_BATCH == 0,
               "the end batches tile the rings");
_Static_assert((DWVW_LANE_RING & (DWVW_LANE_RING - 1u)) == 0 && (DWVW_LANE_RING_SMALL & (DWVW_LANE_RING_SMALL - 1u)) == 0,
               "a ring's place is a mask of the sequence number");
typedef struct lane_slot {
    dwvw_walk_end end;
    dwvw_block_totals *block;
} lane_slot;

/* A run's ring of `size` ends (a power of two): its slots, and beside them by columns a guided
 * walk's log weight and exit factor (guided_lane_end), read as vectors by lanes_end_weights. */
typedef struct lane_ring {
    lane_slot *slot;
    double *log_weight, *factor;
    uint64_t size;
} lane_ring;

typedef struct lane_feed {
    dwvw_estimate_run_state *state;       /* a run's blocks, or NULL for a range */
    uint64_t next, stop;           /* the next walk index and the end of the current block / range */
    dwvw_block_totals *block;           /* the current block */
    uint64_t started, committed;   /* walks started by this thread, and added to their blocks */
    uint64_t ended;                /* a guided run: walks before this one have all ended */
    lane_ring ring;                /* a run's */
    uint64_t first;                /* a range: its first walk, and where its ends go */
    dwvw_walk_end *ends;
    int exhausted;                 /* a run: no block left */
} lane_feed;

/* Moves a run's feed to the next unclaimed block; 0 when none is left. */
static int claim_block(lane_feed *feed)
{
    dwvw_estimate_run_state *state = feed->state;
    if (feed->exhausted) return 0;
    unsigned block = atomic_fetch_add(&state->next_block, 1u);
    if (block >= state->block_count) {
        feed->exhausted = 1;
        return 0;
    }
    feed->next = (uint64_t)block * state->block_size;
    feed->stop = feed->next + state->block_size;
    if (feed->stop > state->setup->walks) feed->stop = state->setup->walks;
    feed->block = &state->blocks[block];
    return 1;
}

/* The next walk for a lane: its index and sequence number; 0 if there is none (for now: in a run,
 * the ring may be full until an earlier walk ends). */
static DWVW_ALWAYS_INLINE int feed_next(lane_feed *feed, uint64_t *index, uint64_t *sequence)
{
    if (!feed->state) {
        if (feed->next >= feed->stop) return 0;
        *sequence = feed->next - feed->first;
        *index = feed->next++;
        return 1;
    }
    if (feed->started - feed->committed >= feed->ring.size) return 0;
    if (feed->next >= feed->stop && !claim_block(feed)) return 0;
    lane_slot *slot = &feed->ring.slot[feed->started & (feed->ring.size - 1u)];
    slot->end.status = DWVW_RUNNING;
    slot->block = feed->block;
    *sequence = feed->started++;
    *index = feed->next++;
    return 1;
}

static void feed_done(lane_feed *feed, const dwvw_estimate_setup *setup, uint64_t sequence, const dwvw_walk_end *end)
{
    if (!feed->state) {
        feed->ends[sequence] = *end;
        return;
    }
    feed->ring.slot[sequence & (feed->ring.size - 1u)].end = *end;
    for (; feed->committed < feed->started; ++feed->committed) {
        lane_slot *slot = &feed->ring.slot[feed->committed & (feed->ring.size - 1u)];
        if (slot->end.status == DWVW_RUNNING) break;
        dwvw_block_add_walk(setup, &slot->end, slot->block);
    }
}

/* The weights of DWVW_END_BATCH guided ends, dwvw_guided_end's exp(log weight) x factor (0 where
 * not finite), bit for bit: dwvk_exp_fast_inner for every end, vectorised, and dwvk_exp_fast
 * itself where an argument is an edge (exp_batch.h). An absorbed walk's factor is 0, so that its
 * weight is +0 (or not finite, then 0), as dwvw_guided_end gives it. */
DWVW_LANE_CLONES static void lanes_end_weights(const double *log_weight, const double *factor, double *weight)
{
    int edges = 0;
    for (unsigned i = 0; i < DWVW_END_BATCH; ++i) {
        weight[i] = dwvk_exp_fast_inner(log_weight[i]);
        edges |= dwvk_exp_fast_is_edge(log_weight[i]);
    }
    if (edges) {
        for (unsigned i = 0; i < DWVW_END_BATCH; ++i)
            if (dwvk_exp_fast_is_edge(log_weight[i])) weight[i] = dwvk_exp_fast(log_weight[i]);
    }
    for (unsigned i = 0; i < DWVW_END_BATCH; ++i) {
        double w = weight[i] * factor[i];
        weight[i] = fabs(w) <= DBL_MAX ? w : 0.0; /* isfinite, as a select */
    }
}

/* A guided walk's end (guided_lane_end): in a range, its weight formed at once; in a run, put in
 * the ring, and every whole batch of ended walks at the ring's front added to its blocks. */
static void feed_done_guided(lane_feed *feed, const dwvw_estimate_setup *setup, uint64_t sequence,
                             dwvw_walk_end *end, double log_weight, double factor)
{
    if (!feed->state) {
        dwvw_guided_end(end, end->events, log_weight, factor);
        feed->ends[sequence] = *end;
        return;
    }
    lane_ring *ring = &feed->ring;
    const uint64_t mask = ring->size - 1u;
    uint64_t at = sequence & mask;
    ring->slot[at].end = *end;
    ring->log_weight[at] = log_weight;
    ring->factor[at] = end->status == DWVW_ABSORBED ? 0.0 : factor;
    for (; feed->ended < feed->started; ++feed->ended)
        if (ring->slot[feed->ended & mask].end.status == DWVW_RUNNING) break;
    while (feed->ended - feed->committed >= DWVW_END_BATCH) {
        uint64_t first = feed->committed & mask; /* a multiple of the batch */
        double weight[DWVW_END_BATCH];
        lanes_end_weights(ring->log_weight + first, ring->factor + first, weight);
        for (unsigned i = 0; i < DWVW_END_BATCH; ++i) {
            lane_slot *slot = &ring->slot[first + i];
            slot->end.weight[0] = weight[i];
            slot->end.weight[1] = slot->end.weight[2] = 0.0;
            dwvw_block_add_walk(setup, &slot->end, slot->block);
        }
        feed->committed += DWVW_END_BATCH;
    }
}

/* The guided ends left in the ring when a thread's walks are done (less than a batch), one by one. */
static void feed_flush_guided(lane_feed *feed, const dwvw_estimate_setup *setup)
{
    if (!feed->state) return;
    lane_ring *ring = &feed->ring;
    for (; feed->committed < feed->started; ++feed->committed) {
        uint64_t at = feed->committed & (ring->size - 1u);
        lane_slot *slot = &ring->slot[at];
        double w = dwvk_exp_fast(ring->log_weight[at]) * ring->factor[at];
        slot->end.weight[0] = isfinite(w) ? w : 0.0;
        slot->end.weight[1] = slot->end.weight[2] = 0.0;
        dwvw_block_add_walk(setup, &slot->end, slot->block);
    }
}

/* One event of every lane of mixture_walk_in (isotropic medium: phase 1/(4 pi) for both
 * components), in the same arithmetic. The guided direction is formed in every lane; the lanes
 * that picked the classical component (a share q0 of 0.01 or less for auto) have theirs replaced
 * one by one. The weight is a product of ratios, as there: the mixture's denominator does not
 * cancel, so each event keeps its exponential. */
static DWVW_ALWAYS_INLINE uint32_t mixture_lanes_step_in(lane_state *L, const dwvw_estimate_setup *setup,
                                                         const dwvw_fast_plan *plan, dwvw_shape_kind kind)
{
    const dwvw_medium *m = &setup->medium;
    const dwvk_dwivedi_event_f *d = &m->dwivedi_event;
    const double sigma = m->sigma_t[0], albedo = m->albedo[0], thickness = setup->shape.thickness;
    const double q0 = setup->guide.q_classical, q1 = plan->q_guided, total = q0 + q1;
    const double phase = DWVK_INV_FOUR_PI, pdf_scale = m->guided_pdf_scale;
    const uint32_t max_events = setup->max_events;
    const uint64_t to_component = DWVW_DIM_COUNTER_OFFSET(DWVW_DIM_CHANNEL, DWVW_DIM_COMPONENT);
    const uint64_t to_direction = DWVW_DIM_COUNTER_OFFSET(DWVW_DIM_CHANNEL, DWVW_DIM_DIRECTION);
    const uint64_t to_distance = DWVW_DIM_COUNTER_OFFSET(DWVW_DIM_CHANNEL, DWVW_DIM_DISTANCE);
    const double sy = plan->sign[0][1], sz = plan->sign[0][2], axis_sign = plan->axis_sign;
    const double kappa = m->dwivedi.kappa, one_minus_kappa = m->dwivedi.one_minus_kappa;
    float ua[DWVW_LANES], ub[DWVW_LANES], udist[DWVW_LANES];
    int guided[DWVW_LANES];
    /* The counter is that of the event's channel dimension (+0); component +1, direction +2,
     * distance +4. */
    for (int l = 0; l < DWVW_LANES; ++l) {
        uint64_t c = L->counter[l];
        guided[l] = !(dwvw_counter_uniform_d(c + to_component) * total < q0);
        dwvk_uniform_pair_f u = dwvw_counter_uniform_pair_f(c + to_direction);
        ua[l] = u.a;
        ub[l] = u.b;
        udist[l] = dwvw_counter_uniform_f(c + to_distance);
        L->counter[l] = c + DWVW_EVENT_COUNTER_STEP;
    }
    double wx[DWVW_LANES], wy[DWVW_LANES], wz[DWVW_LANES];
    for (int l = 0; l < DWVW_LANES; ++l) {
        dwvk_dwivedi_event_cosine_f s = dwvk_dwivedi_event_sample_select_f(d, ua[l]);
        dwvk_unit2_f azimuth = dwvk_azimuth_f(ub[l]);
        double x = (double)azimuth.c * (double)s.sin_theta, y = sy * ((double)azimuth.s * (double)s.sin_theta);
        double z = sz * (double)s.cos_theta;
        double scale = 1.5 - 0.5 * (x * x + y * y + z * z);
        wx[l] = x * scale;
        wy[l] = y * scale;
        wz[l] = z * scale;
    }
    for (int l = 0; l < DWVW_LANES; ++l) {
        if (L->events[l] == 0) { /* the first step keeps the entry direction */
            wx[l] = L->entry_x[l];
            wy[l] = L->entry_y[l];
            wz[l] = L->entry_z[l];
        } else if (!guided[l]) {
            dwvk_uniform_pair_f u = {ua[l], ub[l]};
            dwvu_vec3 w = dwvw_classical_direction(dwvu_v(L->dx[l], L->dy[l], L->dz[l]), 0.0f, u);
            wx[l] = w.x;
            wy[l] = w.y;
            wz[l] = w.z;
        }
    }
    /* Three loops, not one: each lane's chain from the flight's log through the exponential to
     * the weight is long, and short loops let the core run the lanes' chains side by side. */
    double stretch_of[DWVW_LANES], t_of[DWVW_LANES], decay_of[DWVW_LANES], unit_flight[DWVW_LANES];
    int exited_of[DWVW_LANES];
    lanes_unit_flights(L, udist, unit_flight);
    for (int l = 0; l < DWVW_LANES; ++l) {
        double pz = L->pz[l], z = wz[l];
        double mu = dwvw_clamp_cosine(axis_sign * z);
        double stretch_above = one_minus_kappa + kappa * (1.0 - mu), stretch_below = 1.0 - kappa * mu;
        double stretch = mu >= 0.0 ? stretch_above : stretch_below;
        double t = dwvw_unit_flight_scaled(unit_flight[l], sigma * (guided[l] ? stretch : 1.0));
        double hit;
        if (kind == DWVW_HALFSPACE) hit = lane_halfspace_exit(pz, z);
        else if (kind == DWVW_SLAB) hit = lane_slab_exit(thickness, pz, z);
        else {
            dwvu_vec3 normal;
            hit = dwvw_shape_exit_inline(&setup->shape, kind, dwvu_v(L->px[l], L->py[l], pz), dwvu_v(wx[l], wy[l], z),
                                         &normal);
        }
        int exited;
        t_of[l] = dwvw_step_length(hit, t, &exited);
        stretch_of[l] = stretch;
        exited_of[l] = exited;
    }
    for (int l = 0; l < DWVW_LANES; ++l)
        decay_of[l] = dwvw_grey_decay(sigma, stretch_of[l], t_of[l]);
    uint32_t flagged_lanes = 0;
    for (int l = 0; l < DWVW_LANES; ++l) {
        double px = L->px[l], py = L->py[l], pz = L->pz[l], x = wx[l], y = wy[l], z = wz[l];
        int first = L->events[l] == 0, exited = exited_of[l];
        double stretch = stretch_of[l], t = t_of[l];
        double step_phase = first ? 1.0 : phase, pdf_guided = first ? 1.0 : pdf_scale / stretch;
        /* mixture_walk_in's denominator, term by term. */
        double qp0 = q0 * step_phase, qp1 = q1 * pdf_guided, denominator = 0.0;
        if (qp0 > 0.0) denominator += dwvw_grey_term(qp0, 1.0, 1.0, exited);
        if (qp1 > 0.0) denominator += dwvw_grey_term(qp1, stretch, decay_of[l], exited);
        double weight = L->weight[l] * dwvw_grey_ratio(step_phase, albedo, denominator, exited);
        uint32_t events = L->events[l] + (uint32_t)!exited;
        double flight = exited ? 0.0 : t; /* an exited lane keeps its position (guided_lane_end) */
        L->px[l] = px + x * flight;
        L->py[l] = py + y * flight;
        L->pz[l] = pz + z * flight;
        L->dx[l] = x;
        L->dy[l] = y;
        L->dz[l] = z;
        L->weight[l] = weight;
        L->events[l] = events;
        L->exited[l] = exited;
        uint32_t flagged = (uint32_t)(exited | !(weight >= DWVW_ROULETTE_THRESHOLD) | (events >= max_events));
        flagged_lanes |= flagged << l;
    }
    return flagged_lanes;
}

DWVW_LANE_CLONES static uint32_t mixture_lanes_step_halfspace(lane_state *L, const dwvw_estimate_setup *setup,
                                                              const dwvw_fast_plan *plan)
{
    return mixture_lanes_step_in(L, setup, plan, DWVW_HALFSPACE);
}

DWVW_LANE_CLONES static uint32_t mixture_lanes_step_slab(lane_state *L, const dwvw_estimate_setup *setup,
                                                         const dwvw_fast_plan *plan)
{
    return mixture_lanes_step_in(L, setup, plan, DWVW_SLAB);
}

DWVW_LANE_CLONES static uint32_t mixture_lanes_step_sphere(lane_state *L, const dwvw_estimate_setup *setup,
                                                           const dwvw_fast_plan *plan)
{
    return mixture_lanes_step_in(L, setup, plan, DWVW_SPHERE);
}

/* The branches of mixture_walk_in after a flagged step of lane l, as guided_lane_end for the guided walk. */
static int mixture_lane_end(lane_state *L, int l, const dwvw_estimate_setup *setup, dwvw_shape_kind kind,
                            dwvw_walk_end *end)
{
    uint32_t events = L->events[l];
    double weight = L->weight[l];
    end->exit_normal = dwvu_v(0.0, 0.0, 0.0);
    if (L->exited[l]) {
        dwvu_vec3 normal;
        (void)dwvw_shape_exit_inline(&setup->shape, kind, dwvu_v(L->px[l], L->py[l], L->pz[l]),
                                     dwvu_v(L->dx[l], L->dy[l], L->dz[l]), &normal);
        end->status = DWVW_EXITED;
        end->exit_normal = normal;
    } else {
        if (dwvw_grey_goes_on(L->key[l], events, setup->max_events, &weight, &end->status)) {
            L->weight[l] = weight; /* perhaps raised by the roulette */
            return 0;
        }
    }
    dwvw_grey_end(end, events, weight);
    return 1;
}

static inline uint32_t lanes_step(lane_state *L, const dwvw_estimate_setup *setup, const dwvw_fast_plan *plan,
                                  dwvw_shape_kind kind)
{
    if (plan->walker == DWVW_WALKER_MIXTURE) {
        switch (kind) {
        case DWVW_HALFSPACE: return mixture_lanes_step_halfspace(L, setup, plan);
        case DWVW_SLAB: return mixture_lanes_step_slab(L, setup, plan);
        case DWVW_SPHERE: return mixture_lanes_step_sphere(L, setup, plan);
        }
        return 0;
    }
    switch (kind) {
    case DWVW_HALFSPACE: return guided_lanes_step_halfspace(L, setup, plan);
    case DWVW_SLAB: return guided_lanes_step_slab(L, setup, plan);
    case DWVW_SPHERE: return guided_lanes_step_sphere(L, setup, plan);
    }
    return 0;
}

static inline void lanes_run_in(const dwvw_estimate_setup *setup, const dwvw_fast_plan *plan, dwvw_shape_kind kind,
                                lane_feed *feed)
{
    lane_state L;
    lane_log_columns_fill(&L.log_columns);
    L.permute = lanes_can_permute();
    const lane_template start = lane_template_for(setup, plan);
    if (start.same_entry) lanes_fill_template(&L, &start);
    uint64_t sequence[DWVW_LANES];
    /* Bit l: lane l holds a walk. Masks, visited lowest lane first (the order of a scan over the
     * lanes), instead of a branch per lane: a lane's end is a coin toss, and per-lane tests were
     * the hottest lines of this loop in perf. */
    const uint32_t all_lanes = DWVW_LANES == 32 ? 0xffffffffu : (1u << (DWVW_LANES % 32)) - 1u;
    uint32_t live = 0;
    for (int l = 0; l < DWVW_LANES; ++l) {
        uint64_t index;
        int begun = feed_next(feed, &index, &sequence[l]);
        lane_begin(&L, l, setup, plan, &start, begun ? index : 0); /* an idle lane computes on a valid state */
        live |= (uint32_t)begun << l;
    }
    while (live) {
        /* The live flagged lanes: about half the steps flag a lane, seldom the same one. */
        uint32_t flagged = lanes_step(&L, setup, plan, kind);
        if (!flagged) continue;
        uint32_t freed = 0;
        for (uint32_t pending = flagged & live; pending; pending &= pending - 1u) {
            int l = __builtin_ctz(pending);
            dwvw_walk_end end;
            if (plan->walker == DWVW_WALKER_MIXTURE) {
                if (!mixture_lane_end(&L, l, setup, kind, &end)) continue;
                feed_done(feed, setup, sequence[l], &end);
            } else {
                double log_weight, factor;
                if (!guided_lane_end(&L, l, setup, plan, kind, &end, &log_weight, &factor)) continue;
                feed_done_guided(feed, setup, sequence[l], &end, log_weight, factor);
            }
            freed |= 1u << l;
        }
        if (!freed) continue;
        live &= ~freed;
        /* Refill every idle lane: a lane left idle by a full ring may go on once the ring drained.
         * Once feed_next has none, it has none for the lanes after it either (the ring and the
         * blocks do not move in between). */
        for (uint32_t idle = all_lanes & ~live; idle; idle &= idle - 1u) {
            int l = __builtin_ctz(idle);
            uint64_t index;
            if (!feed_next(feed, &index, &sequence[l])) break;
            lane_begin(&L, l, setup, plan, &start, index);
            live |= 1u << l;
        }
    }
    if (plan->walker != DWVW_WALKER_MIXTURE) feed_flush_guided(feed, setup);
}

/* Runs every walk of the feed in lanes. */
static void lanes_run(const dwvw_estimate_setup *setup, const dwvw_fast_plan *plan, lane_feed *feed)
{
    switch (setup->shape.kind) {
    case DWVW_HALFSPACE: lanes_run_in(setup, plan, DWVW_HALFSPACE, feed); return;
    case DWVW_SLAB: lanes_run_in(setup, plan, DWVW_SLAB, feed); return;
    case DWVW_SPHERE: lanes_run_in(setup, plan, DWVW_SPHERE, feed); return;
    }
}

void dwvw_lanes_run_blocks(dwvw_estimate_run_state *state)
{
    lane_slot small_slots[DWVW_LANE_RING_SMALL];
    double small_log_weight[DWVW_LANE_RING_SMALL], small_factor[DWVW_LANE_RING_SMALL];
    lane_ring ring = {.slot = malloc(DWVW_LANE_RING * sizeof *ring.slot),
                      .log_weight = malloc(DWVW_LANE_RING * sizeof *ring.log_weight),
                      .factor = malloc(DWVW_LANE_RING * sizeof *ring.factor),
                      .size = DWVW_LANE_RING};
    void *allocated[3] = {ring.slot, ring.log_weight, ring.factor};
    if (!ring.slot || !ring.log_weight || !ring.factor)
        ring = (lane_ring){.slot = small_slots, .log_weight = small_log_weight, .factor = small_factor,
                           .size = DWVW_LANE_RING_SMALL};
    lane_feed feed = {.state = state, .ring = ring};
    lanes_run(state->setup, &state->plan, &feed);
    for (int i = 0; i < 3; ++i) free(allocated[i]);
}

void dwvw_lanes_run_range(const dwvw_estimate_setup *setup, const dwvw_fast_plan *plan, uint64_t first,
                          uint64_t count, dwvw_walk_end *ends)
{
    lane_feed feed = {.state = NULL, .next = first, .stop = first + count, .first = first, .ends = ends};
    lanes_run(setup, plan, &feed);
}
