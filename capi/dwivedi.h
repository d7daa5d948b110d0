/* dwivedi: Dwivedi-guided random-walk subsurface scattering.
 *
 * The public C API. This is the only header a user compiles against.
 *
 * ABI rules (see DESIGN.md): fields and enumerators are only ever added, never reordered or removed;
 * structs that the caller allocates begin with their own size (set it with the *_INIT macros) so
 * that old callers keep working when fields are added; every fallible call returns a dwv_result_t
 * and keeps a message for the calling thread (dwv_last_error_message); the library never prints,
 * aborts or exits.
 *
 * Thread safety: every function in this header is pure or touches only the objects passed to it
 * and the calling thread's error message, so any function may be called from any number of
 * threads at once, as long as no two threads write the same object. In particular:
 *   - The kernels (diffusion length, eigenfunction, sampling, pdfs, random numbers) are pure: any
 *     number of threads may share one const dwv_dwivedi_t; results do not depend on threads.
 *   - Error messages are per thread: a failing call sets only the calling thread's message, and
 *     the pointer from dwv_last_error_message is valid in that thread until its next failing call.
 *   - dwv_estimate may run on several threads at once; each run starts worker threads of its own
 *     and its result is the same for any thread count (fixed blocks, counter-based numbers).
 *   - Handles (walks, scenes, bakes, images) count references atomically: retain and release may be
 *     called from any thread. A walk handle changes at every step: one thread at a time per walk
 *     (use one handle per thread). Images are read-only once made, and committed scenes may be
 *     baked from any number of threads at once; a bake's wait, progress and cancel may be called
 *     from any thread while it runs.
 * (tests/unit/test_thread_safety.c checks the kernels, messages, estimates and handles.)
 */
#ifndef DWIVEDI_H
#define DWIVEDI_H

#include <stddef.h> /* NULL, in the *_INIT macros */
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(DWV_BUILDING_LIBRARY) && defined(__GNUC__)
#define DWV_API __attribute__((visibility("default")))
#else
#define DWV_API
#endif

/* ---------------------------------------------------------------------------------------------
 * Version
 * ------------------------------------------------------------------------------------------- */
#define DWV_VERSION_MAJOR 0
#define DWV_VERSION_MINOR 1
#define DWV_VERSION_PATCH 0
/* The ABI generation: the SONAME is libdwivedi.so.<DWV_ABI_VERSION>. */
#define DWV_ABI_VERSION 1
/* One number that orders releases: major * 10000 + minor * 100 + patch. */
#define DWV_VERSION (DWV_VERSION_MAJOR * 10000 + DWV_VERSION_MINOR * 100 + DWV_VERSION_PATCH)

/* The library's DWV_VERSION (which may be newer than the header a program was built with). */
DWV_API uint32_t dwv_version(void);
/* The library's version as "major.minor.patch"; a static string. */
DWV_API const char *dwv_version_string(void);

/* ---------------------------------------------------------------------------------------------
 * Results and errors
 * ------------------------------------------------------------------------------------------- */
typedef int32_t dwv_result_t;
enum {
    DWV_SUCCESS = 0,
    DWV_ERROR_NULL_POINTER = 1,     /* a required pointer argument was NULL */
    DWV_ERROR_INVALID_ARGUMENT = 2, /* an argument is NaN, infinite, or of the wrong kind */
    DWV_ERROR_OUT_OF_RANGE = 3,     /* an argument is a number outside its allowed range */
    DWV_ERROR_STRUCT_SIZE = 4,      /* a struct's struct_size is smaller than this call needs */
    DWV_ERROR_UNKNOWN_NAME = 5,     /* a name (method, technique...) is not known */
    DWV_ERROR_OUT_OF_MEMORY = 6,
    DWV_ERROR_INTERNAL = 7,         /* a bug in dwivedi: please report it with the message */
    DWV_ERROR_INVALID_STATE = 8,    /* a call out of order (e.g. a walk step before dwv_walk_begin) */
    DWV_ERROR_CANCELLED = 9,        /* the caller cancelled a bake */
    DWV_ERROR_IO = 10,              /* a file could not be read or written (the message says why) */
    DWV_ERROR_FORMAT = 11           /* a scene file or mesh file is malformed (the message says where) */
};

/* A static, constant description of a result code ("invalid argument"); never NULL. */
DWV_API const char *dwv_result_string(dwv_result_t result);
/* The message of the last failed call on the calling thread ("" if none failed yet); valid until
 * that thread's next failing call. */
DWV_API const char *dwv_last_error_message(void);

/* ---------------------------------------------------------------------------------------------
 * Diffusion length (the discrete eigenvalue v0 of the one-speed transport equation)
 *
 * kappa0 = 1/v0 is the root in [0, 1] of  alpha * atanh(kappa) = kappa  (Meng et al. 2016,
 * supplemental Eq. 8), alpha being the single-scattering albedo in [0, 1]. alpha = 0 gives v0 = 1,
 * alpha = 1 gives v0 = infinity (kappa0 = 0).
 * ------------------------------------------------------------------------------------------- */
typedef int32_t dwv_v0_method_t;
enum {
    DWV_V0_EXACT = 0, /* the root to double precision (safeguarded Newton) */
    DWV_V0_CASE = 1,  /* Case et al.'s series, supplemental Eqs. 10 (alpha < 0.56) and 11, with
                         v0(0.9999) for alpha >= 0.9999, exactly as the supplemental writes them */
    DWV_V0_DEON = 2,  /* d'Eon and Krivanek 2020's fit, used by Cycles:
                         v0 = 1 / sqrt(1 - alpha^(2.44294 - 0.0215813 alpha + 0.578637 / alpha)) */
    DWV_V0_FAST = 3   /* dwivedi's own approximation for render time: relative error <= 1e-6 in
                         kappa0 and <= 1e-4 in 1 - kappa0 for alpha in [0.01, 1 - 1e-6] */
};

/* The method's lower-case name ("exact", "case", "deon", "fast"), or NULL for an unknown value. */
DWV_API const char *dwv_v0_method_name(dwv_v0_method_t method);
/* The method called `name`; DWV_ERROR_UNKNOWN_NAME if there is none. */
DWV_API dwv_result_t dwv_v0_method_from_name(const char *name, dwv_v0_method_t *method);

/* Per-medium constants of the diffusion length, built once from alpha.
 * 1 - kappa0 underflows to 0 for alpha below about 0.0028 (it is about 2 exp(-2/alpha)), so its
 * logarithm is kept too and nothing needs it as a number. */
typedef struct dwv_diffusion_length_t {
    uint32_t struct_size;       /* sizeof(dwv_diffusion_length_t): set by DWV_DIFFUSION_LENGTH_INIT */
    dwv_v0_method_t method;     /* the method that made these constants */
    double albedo;              /* alpha */
    double kappa;               /* kappa0 = 1/v0, in [0, 1] */
    double one_minus_kappa;     /* 1 - kappa0, in [0, 1], without cancellation */
    double log_one_minus_kappa; /* log(1 - kappa0), about log 2 - 2/alpha for small alpha: finite
                                   down to alpha ~ 1.1e-308, -infinity below (and at 0) */
    double v0;                  /* 1/kappa0, in [1, +infinity] */
    double log_ratio;           /* L = log((v0 + 1)/(v0 - 1)) = 2 atanh(kappa0), in [0, +infinity];
                                   equal to 2 kappa0 / alpha where kappa0 is the exact root */
} dwv_diffusion_length_t;
#define DWV_DIFFUSION_LENGTH_INIT {sizeof(dwv_diffusion_length_t), 0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0}

/* Fills *out for albedo in [0, 1] by the given method. */
DWV_API dwv_result_t dwv_diffusion_length(double albedo, dwv_v0_method_t method,
                                          dwv_diffusion_length_t *out);

/* The eigenfunction phi(v, mu) = (alpha/2) v / (v - mu) of supplemental Eq. 7, for |v| > 1 and
 * mu in [-1, 1], evaluated as (alpha/2) / (1 - mu/v) (finite for v = +-infinity). */
DWV_API dwv_result_t dwv_eigenfunction(double albedo, double v, double mu, double *phi);
/* The integral of phi(v, .) over mu in [-1, 1], alpha v atanh(1/v): 1 exactly when v = +-v0
 * (supplemental Eqs. 6 and 8). */
DWV_API dwv_result_t dwv_eigenfunction_integral(double albedo, double v, double *integral);

/* ---------------------------------------------------------------------------------------------
 * Dwivedi direction sampling about an axis
 *
 * The cosine mu between a direction and the axis (the normal pointing out of the medium) has the
 * pdf p(mu) = 1 / (L (v - mu)) on [-1, 1], the normalised eigenfunction (supplemental Eq. 7), and
 * is sampled by the inverse CDF mu = v - (v + 1) exp(-u L). The distance along such a direction
 * is sampled with the stretched extinction sigma_t (1 - mu / v).
 *
 * v is v0 of the medium, except that it is kept at least 1 + 2^-20 (alpha below about 0.137 with
 * the exact method): there guiding no longer pays and the exact distribution becomes a delta
 * whose pdf overflows. Sample, pdf and stretch all use the same v, so estimators stay unbiased.
 * ------------------------------------------------------------------------------------------- */
typedef struct dwv_dwivedi_t {
    uint32_t struct_size;   /* sizeof(dwv_dwivedi_t): set by DWV_DWIVEDI_INIT */
    dwv_v0_method_t method; /* the v0 method the distribution was built with */
    double albedo;          /* the medium's alpha */
    double kappa;           /* 1/v of the sampling distribution, in [0, 1) */
    double one_minus_kappa; /* 1 - kappa, in (0, 1] */
    double log_ratio;       /* L = 2 atanh(kappa) = log((v + 1)/(v - 1)), in [0, 14.6] */
    double albedo_eff;      /* 2 kappa / L, in (0.13, 1]: alpha itself for the exact method */
    float kappa_f;          /* the same four, rounded, for the single-precision calls */
    float one_minus_kappa_f;
    float log_ratio_f;
    float albedo_eff_f;
} dwv_dwivedi_t;
#define DWV_DWIVEDI_INIT {sizeof(dwv_dwivedi_t), 0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0f, 1.0f, 0.0f, 1.0f}

/* One sampled cosine with everything an estimator needs, computed without cancellation. */
typedef struct dwv_dwivedi_sample_t {
    uint32_t struct_size;  /* sizeof(dwv_dwivedi_sample_t): set by DWV_DWIVEDI_SAMPLE_INIT */
    uint32_t reserved;     /* 0 */
    double cos_theta;      /* mu, in [-1, 1] */
    double one_minus_cos;  /* 1 - mu, in [0, 2] */
    double one_plus_cos;   /* 1 + mu, in [0, 2] */
    double pdf;            /* p(mu), per unit cosine; divide by 2 pi for per steradian */
    double stretch;        /* 1 - mu / v: the distance is sampled with sigma_t * stretch */
} dwv_dwivedi_sample_t;
#define DWV_DWIVEDI_SAMPLE_INIT {sizeof(dwv_dwivedi_sample_t), 0, 0.0, 0.0, 0.0, 0.0, 0.0}

typedef struct dwv_dwivedi_sample_f_t {
    uint32_t struct_size; /* sizeof(dwv_dwivedi_sample_f_t): set by DWV_DWIVEDI_SAMPLE_F_INIT */
    float cos_theta;
    float one_minus_cos;
    float one_plus_cos;
    float pdf;
    float stretch;
} dwv_dwivedi_sample_f_t;
#define DWV_DWIVEDI_SAMPLE_F_INIT {sizeof(dwv_dwivedi_sample_f_t), 0.0f, 0.0f, 0.0f, 0.0f, 0.0f}

/* Builds the sampling distribution for albedo in [0, 1] with v0 from the given method. */
DWV_API dwv_result_t dwv_dwivedi_init(dwv_dwivedi_t *dist, double albedo, dwv_v0_method_t method);

/* u in [0, 1] -> the cosine mu (inverse CDF). */
DWV_API dwv_result_t dwv_dwivedi_sample(const dwv_dwivedi_t *dist, double u, double *cos_theta);
/* p(mu) per unit cosine, for mu in [-1, 1]. */
DWV_API dwv_result_t dwv_dwivedi_pdf(const dwv_dwivedi_t *dist, double cos_theta, double *pdf);
/* Both at once: the sample for u in [0, 1] and its pdf, 1 -+ mu and the stretch. */
DWV_API dwv_result_t dwv_dwivedi_sample_pdf(const dwv_dwivedi_t *dist, double u,
                                            dwv_dwivedi_sample_t *sample);
/* The stretch factor 1 - mu / v for any mu in [-1, 1], in (0, 2]. */
DWV_API dwv_result_t dwv_dwivedi_stretch(const dwv_dwivedi_t *dist, double cos_theta,
                                         double *stretch);
/* The same four in single precision (the per-event path). */
DWV_API dwv_result_t dwv_dwivedi_sample_f(const dwv_dwivedi_t *dist, float u, float *cos_theta);
DWV_API dwv_result_t dwv_dwivedi_pdf_f(const dwv_dwivedi_t *dist, float cos_theta, float *pdf);
DWV_API dwv_result_t dwv_dwivedi_sample_pdf_f(const dwv_dwivedi_t *dist, float u,
                                              dwv_dwivedi_sample_f_t *sample);
DWV_API dwv_result_t dwv_dwivedi_stretch_f(const dwv_dwivedi_t *dist, float cos_theta,
                                           float *stretch);

/* ---------------------------------------------------------------------------------------------
 * Classical sampling: phase functions and free-flight distances
 *
 * Cosines of the phase functions are between the direction of travel before and after the
 * scattering event; pdfs are per steradian. Henyey-Greenstein takes g in (-1, 1), g > 0 scattering
 * forward; its sampler has no special case at g = 0 (it is exact there). Uniform numbers u are in
 * [0, 1]; u = 1 is taken as the largest number below 1 where that matters (free flights).
 * ------------------------------------------------------------------------------------------- */
DWV_API dwv_result_t dwv_isotropic_sample(double u, double *cos_theta);
DWV_API dwv_result_t dwv_isotropic_pdf(double *pdf);
DWV_API dwv_result_t dwv_hg_sample(double g, double u, double *cos_theta);
DWV_API dwv_result_t dwv_hg_pdf(double g, double cos_theta, double *pdf);
DWV_API dwv_result_t dwv_hg_sample_pdf(double g, double u, double *cos_theta, double *pdf);
DWV_API dwv_result_t dwv_hg_sample_f(float g, float u, float *cos_theta);
DWV_API dwv_result_t dwv_hg_pdf_f(float g, float cos_theta, float *pdf);

/* Free-flight distance with pdf sigma exp(-sigma t): t = -log(1 - u) / sigma, for sigma > 0
 * finite and u in [0, 1]; DWV_ERROR_OUT_OF_RANGE where sigma is so small that t would overflow. */
DWV_API dwv_result_t dwv_exponential_sample(double sigma, double u, double *distance);
DWV_API dwv_result_t dwv_exponential_pdf(double sigma, double distance, double *pdf);
DWV_API dwv_result_t dwv_exponential_sample_f(float sigma, float u, float *distance);
DWV_API dwv_result_t dwv_exponential_pdf_f(float sigma, float distance, float *pdf);

/* ---------------------------------------------------------------------------------------------
 * Counter-based random numbers
 *
 * A pure function of (seed, stream, sample, dimension): a pixel's or walk's numbers do not depend
 * on which thread draws them or in which order, so results are the same for any thread count.
 * ------------------------------------------------------------------------------------------- */
DWV_API dwv_result_t dwv_random_u64(uint64_t seed, uint64_t stream, uint64_t sample,
                                    uint32_t dimension, uint64_t *value);
/* Uniform in [0, 1): 53 random bits (double) or 24 (float). */
DWV_API dwv_result_t dwv_random_uniform(uint64_t seed, uint64_t stream, uint64_t sample,
                                        uint32_t dimension, double *u);
DWV_API dwv_result_t dwv_random_uniform_f(uint64_t seed, uint64_t stream, uint64_t sample,
                                          uint32_t dimension, float *u);

/* ---------------------------------------------------------------------------------------------
 * Random walks in a homogeneous medium (src/walk)
 *
 * A walk enters through the surface, scatters, and ends when it leaves (its weight is then the
 * estimate it carries), when Russian roulette ends it, or when the cap on events ends it (its
 * remaining weight is reported as truncated, never dropped silently). Each step samples a
 * one-sample MIS mixture (balance heuristic) of the technique's components x colour channels.
 * ------------------------------------------------------------------------------------------- */
typedef int32_t dwv_technique_t;
enum {
    DWV_TECHNIQUE_AUTO = 0,      /* small classical share + incident (closest without light) */
    DWV_TECHNIQUE_CLASSICAL = 1, /* analog phase-function and free-flight sampling */
    DWV_TECHNIQUE_POE = 2,       /* Dwivedi about the entry point's normal (Krivanek, d'Eon 2014) */
    DWV_TECHNIQUE_CLOSEST = 3,   /* Dwivedi about the closest surface point's normal (Meng 2016) */
    DWV_TECHNIQUE_INCIDENT = 4,  /* Dwivedi toward lit surface patches (Meng 2016) */
    DWV_TECHNIQUE_BACKWARD = 5,  /* entry normal or, by depth, an opposite interface (Cycles) */
    DWV_TECHNIQUE_CYCLES = 6,    /* Cycles' mixture: classical 1/2 + backward 1/2 */
    DWV_TECHNIQUE_SHEET = 7      /* toward the lit side through a thin sheet: an importance linear
                                    in the height (zero-variance theory), classical share max(1%, |g|) */
};
DWV_API const char *dwv_technique_name(dwv_technique_t technique);
DWV_API dwv_result_t dwv_technique_from_name(const char *name, dwv_technique_t *technique);

/* A homogeneous medium: 1 (grey) or 3 (RGB) channels. */
typedef struct dwv_medium_t {
    uint32_t struct_size; /* sizeof(dwv_medium_t): set by DWV_MEDIUM_INIT */
    uint32_t channels;    /* 1 or 3 */
    double sigma_t[3];    /* extinction per unit length, in [1e-30, 1e30] */
    double albedo[3];     /* single-scattering albedo in [0, 1] */
    double anisotropy;    /* Henyey-Greenstein g in (-1, 1) */
} dwv_medium_t;
#define DWV_MEDIUM_INIT {sizeof(dwv_medium_t), 1u, {1.0, 1.0, 1.0}, {0.5, 0.5, 0.5}, 0.0}

typedef int32_t dwv_shape_t;
enum { DWV_SHAPE_HALFSPACE = 0, DWV_SHAPE_SLAB = 1, DWV_SHAPE_SPHERE = 2 };
typedef int32_t dwv_incidence_t;
enum {
    DWV_INCIDENCE_COSINE = 0, /* a fixed entry direction: incidence_cosine to the inward normal */
    DWV_INCIDENCE_DIFFUSE = 1 /* cosine-weighted diffuse transmission, as Cycles' random walk */
};
typedef int32_t dwv_light_t; /* which exits score */
enum { DWV_LIGHT_FRONT = 1, DWV_LIGHT_BACK = 2, DWV_LIGHT_BOTH = 3 };

/* dwv_estimate: walks on an analytic shape with a known scoring. The walk enters at the origin,
 * the front point, with outward normal (0, 0, -1): half-space z >= 0, slab 0 <= z <= thickness,
 * sphere of `radius` about (0, 0, radius). An exit scores 1 through a lit face of the half-space
 * or slab, and max(0, cosine of its normal to the light) on the sphere, lit along -z (front)
 * and/or +z (back). So a front-lit half-space with normal incidence estimates its total diffuse
 * reflectance, a back-lit slab its total transmittance. The incident technique (and auto) aims
 * at the lit faces: the planes z = 0 (normal -z) and z = thickness (normal +z), each with power 1;
 * on the sphere, one patch per lit side at its pole (normal -z or +z, power 1); front first. */
typedef struct dwv_estimate_options_t {
    uint32_t struct_size; /* sizeof(dwv_estimate_options_t): set by DWV_ESTIMATE_OPTIONS_INIT */
    dwv_shape_t shape;
    double thickness;         /* slab, in the units of 1/sigma_t, finite and > 0 */
    double radius;            /* sphere, in [1e-100, 1e100] */
    dwv_medium_t medium;
    dwv_incidence_t incidence;
    double incidence_cosine;  /* in (0, 1] */
    dwv_light_t light;
    dwv_technique_t technique;
    uint64_t walks;           /* 2 to 10^12 */
    uint64_t seed;
    uint32_t threads;         /* 0: all cores */
    uint32_t max_events;      /* the cap on scattering events per walk; 0: 10^6 */
} dwv_estimate_options_t;
#define DWV_ESTIMATE_OPTIONS_INIT                                                                   \
    {sizeof(dwv_estimate_options_t), DWV_SHAPE_HALFSPACE, 1.0, 1.0, DWV_MEDIUM_INIT,                 \
     DWV_INCIDENCE_COSINE, 1.0, DWV_LIGHT_FRONT, DWV_TECHNIQUE_AUTO, 10000u, 0u, 0u, 0u}

typedef struct dwv_estimate_result_t {
    uint32_t struct_size; /* sizeof(dwv_estimate_result_t): set by DWV_ESTIMATE_RESULT_INIT */
    uint32_t channels;
    double mean[3];       /* the estimate per channel */
    double std_error[3];  /* its standard error, sqrt(variance / walks) */
    double variance[3];   /* the variance of one walk's score */
    uint64_t walks;
    uint64_t events;      /* scattering events, all walks together */
    double seconds;       /* wall-clock time of the run */
    double efficiency;    /* 1 / (variance x seconds per walk), of channel 0 */
    double truncated_weight[3]; /* weight of walks ended by the cap, per walk (as `mean`) */
    uint64_t truncated_walks;
} dwv_estimate_result_t;
#define DWV_ESTIMATE_RESULT_INIT                                                                    \
    {sizeof(dwv_estimate_result_t), 0u, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, 0u, 0u, \
     0.0, 0.0, {0.0, 0.0, 0.0}, 0u}

DWV_API dwv_result_t dwv_estimate(const dwv_estimate_options_t *options, dwv_estimate_result_t *result);

/* Walks driven one step at a time by a host renderer that traces its own rays:
 *   dwv_walk_begin(walk, index, point, direction, normal)
 *   loop: [dwv_walk_set_closest(walk, n) if dwv_walk_needs_closest]
 *         dwv_walk_sample(walk, direction, &distance)
 *         trace from the walk's position along direction; on the first step report the full
 *         distance to the surface (it locates an opposite interface), then the hit if within
 *         `distance`, or INFINITY
 *         dwv_walk_report(walk, hit_distance, hit_normal, &state) until state.status != RUNNING.
 * hit_normal may be NULL when hit_distance is INFINITY. A failed call leaves the walk as it was;
 * a failed dwv_walk_create leaves *walk NULL. A walk handle is not thread-safe; use one per thread. */
typedef struct dwv_walk_s dwv_walk_t;
typedef int32_t dwv_walk_status_t;
enum {
    DWV_WALK_RUNNING = 0,   /* scattered inside: sample the next step */
    DWV_WALK_EXITED = 1,    /* left the medium: state.weight is its estimate per channel */
    DWV_WALK_ABSORBED = 2,  /* ended by Russian roulette (weight 0) */
    DWV_WALK_TRUNCATED = 3  /* ended by the event cap: state.weight is the weight it still had */
};
typedef struct dwv_walk_state_t {
    uint32_t struct_size; /* sizeof(dwv_walk_state_t): set by DWV_WALK_STATE_INIT */
    dwv_walk_status_t status;
    uint32_t events;
    uint32_t reserved;
    double position[3];
    double weight[3];
    double exit_normal[3];
} dwv_walk_state_t;
#define DWV_WALK_STATE_INIT {sizeof(dwv_walk_state_t), 0, 0u, 0u, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}}

/* A lit part of the surface for the incident technique: a point and its outward normal with the
 * light it receives (power > 0); is_plane makes it the whole plane through the point. */
typedef struct dwv_light_patch_t {
    uint32_t struct_size; /* sizeof(dwv_light_patch_t): set by DWV_LIGHT_PATCH_INIT */
    uint32_t is_plane;
    double point[3];
    double normal[3];
    double power;
} dwv_light_patch_t;
#define DWV_LIGHT_PATCH_INIT {sizeof(dwv_light_patch_t), 0u, {0.0, 0.0, 0.0}, {0.0, 0.0, -1.0}, 1.0}

/* Creates a walk handle (reference count 1) for a medium and technique. `patches` (up to 16; may
 * be NULL with count 0) are needed by incident and used by auto. max_events 0 means 10^6. */
DWV_API dwv_result_t dwv_walk_create(const dwv_medium_t *medium, dwv_technique_t technique,
                                     const dwv_light_patch_t *patches, uint32_t patch_count,
                                     uint64_t seed, uint32_t max_events, dwv_walk_t **walk);
DWV_API dwv_result_t dwv_walk_retain(dwv_walk_t *walk);
/* Drops one reference; the last frees the walk. NULL is ignored. */
DWV_API void dwv_walk_release(dwv_walk_t *walk);
/* 1 if the technique needs dwv_walk_set_closest before every dwv_walk_sample. */
DWV_API dwv_result_t dwv_walk_needs_closest(const dwv_walk_t *walk, int32_t *needs);
/* Starts walk number `index` (its random numbers depend only on seed and index) at `point`,
 * heading along unit `direction` into the medium whose outward unit normal there is `normal`. */
DWV_API dwv_result_t dwv_walk_begin(dwv_walk_t *walk, uint64_t index, const double point[3],
                                    const double direction[3], const double normal[3]);
DWV_API dwv_result_t dwv_walk_set_closest(dwv_walk_t *walk, const double normal[3]);
DWV_API dwv_result_t dwv_walk_sample(dwv_walk_t *walk, double direction[3], double *distance);
DWV_API dwv_result_t dwv_walk_report(dwv_walk_t *walk, double hit_distance, const double hit_normal[3],
                                     dwv_walk_state_t *state);

/* ---------------------------------------------------------------------------------------------
 * Scenes: triangle meshes with Cycles' subsurface materials, lights, a world and a camera.
 *
 * Build a scene with the dwv_scene_add_* calls, then dwv_scene_commit freezes it (geometry
 * structures are built then, and the scene is analysed to leave out work it cannot use); a
 * committed scene can be baked any number of times, from any number of threads at once, and can
 * no longer be changed (DWV_ERROR_INVALID_STATE). Lengths are in scene units (Blender's metres);
 * transforms are row-major 3 x 4 object-to-world matrices (the last row 0 0 0 1 implied).
 * Every array passed in is copied; the caller may free it when the call returns.
 * ------------------------------------------------------------------------------------------- */
typedef struct dwv_scene_s dwv_scene_t;

/* Creates an empty scene (reference count 1): black world, no camera. */
DWV_API dwv_result_t dwv_scene_create(dwv_scene_t **scene);
DWV_API dwv_result_t dwv_scene_retain(dwv_scene_t *scene);
/* Drops one reference; the last frees the scene. NULL is ignored. */
DWV_API void dwv_scene_release(dwv_scene_t *scene);

typedef int32_t dwv_material_kind_t;
enum {
    DWV_MATERIAL_SUBSURFACE = 0, /* (1 - weight) diffuse base + weight subsurface random walk */
    DWV_MATERIAL_DIFFUSE = 1     /* Lambertian reflection of base_color only */
};

/* How light leaves a subsurface material's walk (dwv_material_t.subsurface_exit). */
typedef int32_t dwv_subsurface_exit_t;
enum {
    /* A Lambertian BSDF at the exit point: Cycles' Subsurface Scattering node and Blender 4.x's
     * Principled BSDF. */
    DWV_SUBSURFACE_EXIT_LAMBERT = 0,
    /* Blender 3.x's Principled BSDF (Cycles' PRINCIPLED_DIFFUSE_LAMBERT_EXIT and
     * PRINCIPLED_DIFFUSE_RETRO_REFLECTION): the exit's Lambertian BSDF weighted by
     * 1 - F_L / 2, and at the entry point a retro-reflection lobe of weight subsurface_weight x
     * subsurface_color, f = (1/pi) R_R (F_L + F_V + F_L F_V (R_R - 1)), with
     * F_x = (1 - cos theta_x)^5 (Schlick's weight; L the light, V the viewer, angles to the
     * shading normal) and R_R = roughness x (1 + L.V) (Burley 2015, "Extending the Disney BRDF
     * to a BSDF with Integrated Subsurface Scattering", section 5.3). On a material without a
     * walk (kind DWV_MATERIAL_DIFFUSE, or subsurface_weight 0) it selects Blender 3.x's Principled
     * diffuse instead (Cycles' PRINCIPLED_DIFFUSE_FULL): base_color x (1/pi)
     * ((1 - F_L/2)(1 - F_V/2) + R_R (F_L + F_V + F_L F_V (R_R - 1))). */
    DWV_SUBSURFACE_EXIT_PRINCIPLED_V1 = 1
};

/* Which Cycles subsurface model a material's walk follows (dwv_material_t.subsurface_model):
 * how the radius becomes the medium's extinction, the colour its single-scattering albedo, the
 * anisotropy's clamp, and how light enters. Every model: a channel whose radius x scale is below
 * 1e-8 is Lambertian diffuse; the walk's throughput is scaled by alpha / 0.2 where alpha < 0.2
 * (alpha raised to 0.2); the exit is subsurface_exit's. Cycles' source (bssrdf.h,
 * subsurface_random_walk.h, subsurface.h) per release; docs/blender-compatibility.md. */
typedef int32_t dwv_subsurface_model_t;
enum {
    /* Blender 3.x "Random Walk (Fixed Radius)" (and every material made before this field):
     * reduced mean free path d = radius x scale / (4 pi), sigma_t = 1 / (d (1 - g)), albedo by
     * Cycles' fit after Chiang et al. 2016, g clamped to [0, 0.9], entry cosine-weighted diffuse
     * transmission. */
    DWV_SUBSURFACE_MODEL_FIXED_RADIUS = 0,
    /* Blender 3.x "Random Walk": as above but d = radius x scale x sqrt(3 (1 - a')), a' the
     * albedo for which Jensen's dipole Rd(a') = a'/2 (1 + exp(-(4/3) A s)) exp(-s), s =
     * sqrt(3 (1 - a')), A = (1 + Fdr) / (1 - Fdr), Fdr(subsurface_ior clamped to [1.01, 3.8]), is
     * the colour (Cycles' 12 bisection steps); diffuse entry. */
    DWV_SUBSURFACE_MODEL_BLENDER3_RANDOM_WALK = 1,
    /* Blender 4.0-5.1 "Random Walk" (stored as the old Fixed Radius): the fixed-radius medium,
     * entered by GGX refraction (VNDF sampling with alpha = roughness^2, then refraction with ior
     * clamped to [1.01, 3.8]; unit weight: Cycles uses it as a direction distribution only). */
    DWV_SUBSURFACE_MODEL_BLENDER4_RANDOM_WALK = 2,
    /* Blender 4.0-5.1 "Random Walk (Skin)": the 3.x Random Walk's rescaled radius (with
     * subsurface_ior), entered half by diffuse transmission, half by GGX refraction with
     * subsurface_ior at alpha 1. */
    DWV_SUBSURFACE_MODEL_BLENDER4_SKIN = 3,
    /* Blender 5.2 "Random Walk": mean free path = radius x scale (sigma_t = 1 / mfp), albedo by van
     * de Hulst's mapping (d'Eon, "A Hitchhiker's Guide to Multiple Scattering", Eq. 53.7),
     * alpha = (1 - s^2) / (1 - g s^2), s = 4.20863 A - sqrt(9.59217 + 41.6808 A + 17.7126 A^2)
     * + 4.09712, g clamped to [-0.99, 0.99]; refraction entry as 4.x. */
    DWV_SUBSURFACE_MODEL_BLENDER52_RANDOM_WALK = 4,
    /* Blender 5.2 "Random Walk (Legacy)": the 4.x Random Walk with g clamped to [-0.99, 0.9] and,
     * for g < 0, van de Hulst's albedo with sigma_t = 1 / d. */
    DWV_SUBSURFACE_MODEL_BLENDER52_LEGACY = 5,
    /* Blender 5.2 "Random Walk (Skin)": the 4.x Skin with 5.2's Legacy anisotropy rule. */
    DWV_SUBSURFACE_MODEL_BLENDER52_SKIN = 6
};

/* The dielectric specular layer over the diffuse and subsurface (dwv_material_t.specular_model).
 * Lit by the lights and the world at the entry point (one bounce, as the rest of the surface). */
typedef int32_t dwv_specular_model_t;
enum {
    DWV_SPECULAR_NONE = 0,
    /* Blender 3.x Principled v1 (svm_closure.h, bsdf_microfacet.h): added on top (the diffuse and
     * subsurface keep their weight): GGX, f = F D G1(V) G1(L) / (4 cosL cosV), alpha = roughness^2,
     * F = cspec0 + (1 - cspec0) (F_d(L.H, eta) - F0) / (1 - F0), F_d the dielectric Fresnel,
     * eta = 2 / (1 - sqrt(0.08 specular)) - 1, F0 = F_d(1, eta), cspec0 = 0.08 specular
     * mix(1, base / lum(base), tint), lum = 0.3 r + 0.6 g + 0.1 b. */
    DWV_SPECULAR_PRINCIPLED_V1 = 1,
    /* Blender 4.x/5.x Principled v2: GGX, f = F D G2 / (4 cosL cosV), G2 = 1 / (1 + Lambda(V) +
     * Lambda(L)) (height-correlated Smith), F = f0 + (1 - f0) clamp((F_d(V.H, eta) - F0) / (1 -
     * F0)), F0 = ((ior - 1) / (ior + 1))^2 x 2 specular, f0 = F0 x specular_tint, eta from F0;
     * Multiscatter GGX scales it by 1 + Fms (1 - E) / E (Kulla and Conty 2017). The layers below
     * (diffuse and subsurface) are weighted by 1 - max over channels of its albedo toward the
     * viewer (Cycles' closure_layering_weight). */
    DWV_SPECULAR_PRINCIPLED_V2 = 2
};

/* A material in the terms of Cycles' Principled BSDF with subsurface method "Random Walk (Fixed
 * Radius)", Blender 4.x naming: the surface is (1 - subsurface_weight) Lambertian diffuse of
 * base_color plus subsurface_weight random-walk subsurface scattering whose multiple-scattering
 * albedo is subsurface_color (turned into single-scattering albedo by Cycles' inversion fit) and
 * whose per-channel radius is subsurface_radius x subsurface_scale (scene units). Blender 3.x's
 * inputs map as: subsurface_weight = 1 where "Subsurface" > 0 (else 0), subsurface_color =
 * mix(Base Color, Subsurface Color, Subsurface), subsurface_scale = "Subsurface",
 * subsurface_exit = DWV_SUBSURFACE_EXIT_PRINCIPLED_V1, roughness = "Roughness". Entry is
 * cosine-weighted diffuse transmission, exit as subsurface_exit says, as in Cycles. */
typedef struct dwv_material_t {
    uint32_t struct_size;         /* sizeof(dwv_material_t): set by DWV_MATERIAL_INIT */
    dwv_material_kind_t kind;
    double base_color[3];         /* in [0, 1] */
    double subsurface_weight;     /* in [0, 1] */
    double subsurface_color[3];   /* in [0, 1] */
    double subsurface_radius[3];  /* >= 0, finite; a channel whose radius x scale is below 1e-8 is
                                     Lambertian diffuse of subsurface_color instead (as Cycles) */
    double subsurface_scale;      /* >= 0, finite */
    double subsurface_anisotropy; /* Henyey-Greenstein g in (-1, 1); used clamped to [0, 0.9], as Cycles */
    double subsurface_ior;        /* in [1, 4]; kept for compatibility (Cycles' walk ignores it) */
    /* Added after 0.1.0. A caller whose struct_size ends before them gets the defaults
     * (DWV_SUBSURFACE_EXIT_LAMBERT, roughness 0.5): its materials bake as they always did. */
    dwv_subsurface_exit_t subsurface_exit; /* DWV_SUBSURFACE_EXIT_* */
    uint32_t reserved;            /* 0 */
    double roughness;             /* in [0, 1]: the retro-reflection lobe's (DWV_SUBSURFACE_EXIT_PRINCIPLED_V1),
                                     the specular layer's and the refraction entry's (Principled Roughness) */
    /* Added after 0.2 (issue 17). A caller whose struct_size ends before them gets the defaults
     * (DWV_SUBSURFACE_MODEL_FIXED_RADIUS, DWV_SPECULAR_NONE): its materials bake as they did. */
    dwv_subsurface_model_t subsurface_model; /* DWV_SUBSURFACE_MODEL_* */
    dwv_specular_model_t specular_model;     /* DWV_SPECULAR_* */
    double ior;                   /* in [1, 4]: Principled "IOR" (4.x+: specular layer and refraction entry) */
    double specular;              /* >= 0, finite: 3.x "Specular" (DWV_SPECULAR_PRINCIPLED_V1) or 4.x+
                                     "Specular IOR Level" (DWV_SPECULAR_PRINCIPLED_V2; 0.5 keeps ior's F0) */
    double specular_tint[3];      /* in [0, 1]: 4.x+ "Specular Tint" colour; 3.x's Specular Tint factor is
                                     specular_tint[0] (the others are ignored) */
    int32_t specular_multiscatter; /* 0: GGX; 1: Multiscatter GGX (4.x+: energy-compensated; refused with
                                     DWV_SPECULAR_PRINCIPLED_V1, whose multiscatter is a stochastic walk) */
    uint32_t reserved2;           /* 0 */
    /* >= 0, finite: a channel whose radius x scale is below this many times the ray's footprint at
     * a hit (Cycles' ray differentials sd->dP: for a camera ray distance x the pixel's angular
     * spread, or the pixel's width for an orthographic camera; for a UV bake the texel's footprint
     * on the surface, from the UV layout; along a path the first ray's, grown by the path's length
     * x the camera ray's spread) is Lambertian there: Cycles 4.0-4.3's "fall back to diffuse if the
     * radius is smaller than a quarter pixel" (0.25; removed in 4.4). 0: never. */
    double subsurface_min_footprint;
} dwv_material_t;
#define DWV_MATERIAL_INIT                                                                           \
    {sizeof(dwv_material_t), DWV_MATERIAL_SUBSURFACE, {0.8, 0.8, 0.8}, 1.0, {0.8, 0.8, 0.8},         \
     {1.0, 0.2, 0.1}, 0.05, 0.0, 1.4, DWV_SUBSURFACE_EXIT_LAMBERT, 0u, 0.5,                          \
     DWV_SUBSURFACE_MODEL_FIXED_RADIUS, DWV_SPECULAR_NONE, 1.5, 0.5, {1.0, 1.0, 1.0}, 0, 0u, 0.0}

/* Adds a material; *material_id numbers them from 0 in order. */
DWV_API dwv_result_t dwv_scene_add_material(dwv_scene_t *scene, const dwv_material_t *material,
                                            uint32_t *material_id);

/* A triangle mesh. Positions (and normals) are in object space; `transform` takes them to the
 * world. UVs are per triangle corner (Blender's loops), so seams need no split vertices. */
typedef struct dwv_mesh_t {
    uint32_t struct_size;     /* sizeof(dwv_mesh_t): set by DWV_MESH_INIT */
    uint32_t vertex_count;    /* >= 3 */
    uint32_t triangle_count;  /* >= 1 */
    uint32_t material_id;     /* from dwv_scene_add_material */
    const float *positions;   /* 3 x vertex_count, finite */
    const uint32_t *indices;  /* 3 x triangle_count, each < vertex_count */
    const float *normals;     /* optional (NULL: flat shading): 3 x vertex_count, per vertex */
    const float *uvs;         /* optional (NULL: no UV bake): 2 x 3 x triangle_count, per corner */
    double transform[12];     /* row-major 3 x 4 object-to-world, invertible */
    /* Added after 0.1.0. A caller whose struct_size ends before it gets the default, 0.1. */
    double shadow_terminator_geometry_offset; /* >= 0, finite: Cycles' object setting "Shadow
                                 Terminator > Geometry Offset" (Blender 3.x:
                                 Object.cycles.shadow_terminator_geometry_offset, default 0.1).
                                 With normals, shadow rays toward light within this cosine of the
                                 flat triangle's horizon leave from a smooth surface above it, as
                                 in Cycles; 0: from the flat triangle. No effect without normals. */
    /* Added after 0.2 (issue 18: textures). A caller whose struct_size ends before them has one UV
     * layer (uvs, unnamed) and no tangents. UV layer 0 is `uvs`; layers 1 to uv_layer_count are
     * uv_layers[0 .. uv_layer_count - 1], each 2 x 3 x triangle_count per corner like `uvs`. */
    uint32_t uv_layer_count;          /* extra UV layers, <= 64 */
    uint32_t reserved_uv;             /* 0 */
    const float *const *uv_layers;    /* uv_layer_count arrays (NULL when the count is 0) */
    /* Optional: uv_layer_count + 1 names (Blender's UV map names), [0] for `uvs`; what a texture
     * binding's uv_layer names. NULL: layer k is named by its number ("0", "1", ...). */
    const char *const *uv_layer_names;
    /* Optional: uv_layer_count + 1 pointers (each may be NULL), per layer the tangents of its
     * normal maps: 4 x 3 x triangle_count per corner, xyz (object space) and the bitangent's sign
     * (+1 or -1), as Blender's MikkTSpace tangents (MeshLoop.tangent, bitangent_sign after
     * Mesh.calc_tangents). A layer without them gets tangents made at commit from the UV
     * gradients (docs/scene-format.md, "Tangents": MikkTSpace's result on meshes whose UV
     * charts are smooth, not bit for bit). */
    const float *const *tangents;
} dwv_mesh_t;
#define DWV_MESH_INIT                                                                               \
    {sizeof(dwv_mesh_t), 0u, 0u, 0u, NULL, NULL, NULL, NULL,                                        \
     {1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0}, 0.1, 0u, 0u, NULL, NULL, NULL}

/* Adds a mesh; *mesh_id numbers meshes from 0 in order (the id a UV bake names). Open meshes,
 * zero-area or duplicate triangles are accepted and counted in the bake's warnings. */
DWV_API dwv_result_t dwv_scene_add_mesh(dwv_scene_t *scene, const dwv_mesh_t *mesh, uint32_t *mesh_id);

typedef int32_t dwv_light_kind_t;
enum {
    DWV_LIGHT_SUN = 0,   /* direction, strength (irradiance, W/m^2), angle (angular diameter) */
    DWV_LIGHT_POINT = 1, /* position, power (W, Blender's convention), radius, point_shape */
    DWV_LIGHT_AREA_RECTANGLE = 2, /* transform, size_x x size_y in its local xy plane, power */
    DWV_LIGHT_AREA_DISK = 3,      /* transform, diameter size_x (size_y for an ellipse), power */
    DWV_LIGHT_SPOT = 4            /* position, direction (of its axis), power, radius, spot_size,
                                     spot_blend, spot_falloff, point_shape: a point light within a cone */
};
/* Lights in Blender's units and conventions; an area light emits along its local -z. */
typedef struct dwv_light_desc_t {
    uint32_t struct_size; /* sizeof(dwv_light_desc_t): set by DWV_LIGHT_DESC_INIT */
    dwv_light_kind_t kind;
    double color[3];      /* in [0, infinity) */
    double strength;      /* sun: irradiance W/m^2; point and area: power in W; >= 0 */
    double direction[3];  /* sun: the direction the light travels (need not be unit) */
    double angle;         /* sun: angular diameter in radians, [0, pi] */
    double position[3];   /* point */
    double radius;        /* point: >= 0 */
    double transform[12]; /* area: row-major 3 x 4 light-to-world (no shear) */
    double size_x, size_y;/* area: > 0 */
    /* Added after 0.2 (issue 18; a caller whose struct_size ends before them gets the defaults,
     * which only spot lights read). Spot lights: `position`, `radius` and `strength` (power in W)
     * as a point light's, `direction` the way its axis points (need not be unit; Blender's local
     * -z), radiance P c / (4 pi) x 1 / (pi r^2) times the spot attenuation of the direction w from
     * the light toward the shaded point: with c = cos(angle between w and the axis),
     * c_h = cos(spot_size / 2) and the smoothstep s(t) = 3t^2 - 2t^3 on [0, 1] (0 below, 1 above),
     *   DWV_SPOT_FALLOFF_CYCLES3: c x s((c - c_h) / ((1 - c_h) spot_blend)) for c > c_h, else 0
     *     (Cycles 3.x spot_light_attenuation: the cosine of the axis stays in);
     *   DWV_SPOT_FALLOFF_CYCLES4: s((c - c_h) / ((1 - c_h) spot_blend)) (Cycles 4.0 onward);
     * spot_blend 0 is a hard edge (s is 1 inside the cone). */
    double spot_size;     /* spot: the cone's full angle in radians, (0, pi] (Blender's Spot Size) */
    double spot_blend;    /* spot: [0, 1] (Blender's Spot Blend) */
    int32_t spot_falloff; /* spot: DWV_SPOT_FALLOFF_* */
    uint32_t reserved;    /* 0 */
    /* Added after the spot fields (issue 18; a caller whose struct_size ends before it gets the
     * disc). Point and spot lights of radius > 0: DWV_POINT_SHAPE_*. */
    int32_t point_shape;
    uint32_t reserved_shape; /* 0 */
} dwv_light_desc_t;
typedef int32_t dwv_spot_falloff_t;
enum {
    DWV_SPOT_FALLOFF_CYCLES3 = 0, /* Blender 3.x: the axis cosine x the smoothstep */
    DWV_SPOT_FALLOFF_CYCLES4 = 1  /* Blender 4.0 onward: the smoothstep alone */
};
/* The emitting shape of a point or spot light of radius r > 0; both have the radiance
 * P c / (4 pi^2 r^2) (times a spot's attenuation), so both give the intensity P c / (4 pi) far
 * away, and differ near the light: */
typedef int32_t dwv_point_shape_t;
enum {
    /* A disc of radius r about the centre facing the shaded point (Cycles 3.x; 4.0 onward with
     * the light's Soft Falloff, Blender's default): irradiance P / (4 pi (d^2 + r^2)) facing it
     * at distance d from the centre. */
    DWV_POINT_SHAPE_DISC = 0,
    /* A sphere of radius r (Cycles 4.0 onward without Soft Falloff): P / (4 pi d^2) facing it;
     * a point inside the sphere sees its radiance from every direction (a spot's without its
     * attenuation). */
    DWV_POINT_SHAPE_SPHERE = 1
};
#define DWV_LIGHT_DESC_INIT                                                                         \
    {sizeof(dwv_light_desc_t), DWV_LIGHT_SUN, {1.0, 1.0, 1.0}, 1.0, {0.0, 0.0, -1.0}, 0.0,          \
     {0.0, 0.0, 0.0}, 0.0, {1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0}, 1.0, 1.0,   \
     0.78539816339744830962, 0.15, DWV_SPOT_FALLOFF_CYCLES3, 0u, DWV_POINT_SHAPE_DISC, 0u}

DWV_API dwv_result_t dwv_scene_add_light(dwv_scene_t *scene, const dwv_light_desc_t *light);

/* A constant world: radiance color x strength from every direction (default black). */
DWV_API dwv_result_t dwv_scene_set_world(dwv_scene_t *scene, const double color[3], double strength);

/* ---- World environment (issue 18) ----------------------------------------------------------
 * An equirectangular image world as Blender's Environment Texture node into a Background node:
 * the radiance toward direction d (world space, unit) is strength x texture(u, v) with, for the
 * looked-up direction b = rotation d (Cycles' direction_to_equirectangular),
 *   u = 0.5 - atan2(b.y, b.x) / (2 pi),   v = 1 - acos(b.z) / pi,
 * so +x is the image's centre column, +z (up) its top row. The texture is looked up as Cycles'
 * image textures with periodic wrap: closest (texel floor(u w), floor(v h)), linear (bilinear
 * between texel centres at (i + 0.5) / w) or cubic (the uniform cubic B-spline over 4 x 4 texels;
 * Blender's "Smart" is cubic). Lights are sampled from a piecewise-constant distribution of the
 * texels' luminance (Rec. 709 Y, each taken as the largest over the texels its interpolation
 * reads) times their solid angle, combined with the surfaces' cosine sampling by multiple
 * importance sampling (balance heuristic); camera rays that miss see the world. The scene holds
 * 16 bytes a texel (the RGB copy and the distribution) and 8 a row; making it takes 4 more a
 * texel for the call's duration. */
typedef int32_t dwv_environment_interpolation_t;
enum {
    DWV_ENVIRONMENT_LINEAR = 0,
    DWV_ENVIRONMENT_CLOSEST = 1,
    DWV_ENVIRONMENT_CUBIC = 2
};
typedef struct dwv_environment_t {
    uint32_t struct_size;  /* sizeof(dwv_environment_t): set by DWV_ENVIRONMENT_INIT */
    uint32_t width;        /* texels per row, 1 to DWV_ENVIRONMENT_MAX_SIDE */
    uint32_t height;       /* rows, 1 to DWV_ENVIRONMENT_MAX_SIDE; width x height <= DWV_ENVIRONMENT_MAX_TEXELS */
    dwv_environment_interpolation_t interpolation; /* DWV_ENVIRONMENT_* */
    /* 3 x width x height scene-linear Rec. 709 RGB, each finite and >= 0; row 0 at the bottom
     * (v = 0, the nadir: the order of Blender's Image.pixels); copied by the call. */
    const float *texels;
    double strength;       /* >= 0, finite: the Background node's Strength */
    /* Row-major 3 x 3 rotation (orthonormal, determinant +1) taking world directions to the
     * directions the texture is looked up with: Blender's Mapping node (Point or Vector type)
     * rotation on the Environment Texture's Vector, Euler XYZ as Blender composes it. */
    double rotation[9];
} dwv_environment_t;
#define DWV_ENVIRONMENT_MAX_SIDE 131072u
#define DWV_ENVIRONMENT_MAX_TEXELS (1u << 27)
#define DWV_ENVIRONMENT_INIT                                                                        \
    {sizeof(dwv_environment_t), 0u, 0u, DWV_ENVIRONMENT_LINEAR, NULL, 1.0,                          \
     {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}}

/* Makes the world the environment (replacing a constant world or an earlier environment; a later
 * dwv_scene_set_world replaces it in turn). Texels that are NaN, infinite or negative are refused
 * with their place in the message. A 1 x 1 image is accepted: it is a constant world, which is
 * what Blender renders for it, and is stored as exactly that (dwv_scene_set_world's colour x
 * strength). Any other size within the limits is accepted too (a 100000 x 1 image is a world that
 * varies with longitude only); an all-black image or strength 0 is a black world. */
DWV_API dwv_result_t dwv_scene_set_world_environment(dwv_scene_t *scene, const dwv_environment_t *environment);
/* The environment from an image file: OpenEXR (half or float; R, G, B with or without A, whose
 * alpha is dropped, or Y, taken as grey; the first part, scanline or tiled; values as stored,
 * scene-linear as Blender takes EXRs) or a Radiance picture (.hdr, RGBE; Radiance's decoding
 * (m + 0.5) 2^(e - 136), as Blender's loader). The file's size and texels replace `settings`'
 * width, height and texels (ignored); interpolation, strength and rotation come from it, checked
 * as dwv_scene_set_world_environment checks them, and so are the texels (the message names the
 * file and the texel). A missing file: DWV_ERROR_IO; another kind of file, a damaged or truncated
 * one, a side beyond DWV_ENVIRONMENT_MAX_SIDE or more than DWV_ENVIRONMENT_MAX_TEXELS texels
 * (refused before its texels are read): DWV_ERROR_FORMAT. The scene is unchanged on failure. */
DWV_API dwv_result_t dwv_scene_set_world_environment_file(dwv_scene_t *scene, const char *path,
                                                          const dwv_environment_t *settings);
/* ---- end of the world environment ---------------------------------------------------------- */

typedef int32_t dwv_camera_kind_t;
enum { DWV_CAMERA_PERSPECTIVE = 0, DWV_CAMERA_ORTHOGRAPHIC = 1 };
/* A camera as Blender's: it looks along its local -z with +y up; the sensor fits the larger image
 * side (Blender's "Auto" sensor fit). */
typedef struct dwv_camera_t {
    uint32_t struct_size; /* sizeof(dwv_camera_t): set by DWV_CAMERA_INIT */
    dwv_camera_kind_t kind;
    double transform[12]; /* row-major 3 x 4 camera-to-world, rotation and translation only */
    double focal_length;  /* perspective: mm, > 0 */
    double sensor_width;  /* perspective: mm, > 0 */
    double ortho_scale;   /* orthographic: the larger image side in scene units, > 0 */
} dwv_camera_t;
#define DWV_CAMERA_INIT                                                                             \
    {sizeof(dwv_camera_t), DWV_CAMERA_PERSPECTIVE,                                                  \
     {1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0}, 50.0, 36.0, 1.0}

DWV_API dwv_result_t dwv_scene_set_camera(dwv_scene_t *scene, const dwv_camera_t *camera);

/* Freezes the scene: builds its ray-tracing structures and analyses which work it needs. */
DWV_API dwv_result_t dwv_scene_commit(dwv_scene_t *scene);

/* Scene-level work that a committed scene leaves out or keeps (the "features" of its bakes). */
enum {
    DWV_FEATURE_EMBREE = 1u << 0,            /* triangle meshes traced with Embree */
    DWV_FEATURE_SUBSURFACE = 1u << 1,        /* random walks (some material scatters) */
    DWV_FEATURE_CLOSEST_POINT = 1u << 2,     /* closest-point queries during walks */
    DWV_FEATURE_INCIDENT_PATCHES = 1u << 3,  /* lit patches for incident-illumination guiding */
    DWV_FEATURE_RGB_WALKS = 1u << 4,         /* walks carrying three colour channels together */
    DWV_FEATURE_GUIDED = 1u << 5,            /* Dwivedi guiding (else classical: albedo too low) */
    DWV_FEATURE_WORLD_LIGHT = 1u << 6,       /* the world is sampled (not black) */
    DWV_FEATURE_DIRECT_LIGHTS = 1u << 7,     /* next-event estimation to lights */
    DWV_FEATURE_DIFFUSE_SURFACES = 1u << 8,  /* plain diffuse surfaces shaded */
    DWV_FEATURE_CHANNEL_WALKS = 1u << 9,     /* one walk per colour channel (DWV_CHANNEL_WALKS_SEPARATE) */
    DWV_FEATURE_SHEET = 1u << 10             /* walks toward a thin sheet's lit side (DWV_TECHNIQUE_SHEET) */
};
/* The lower-case name of one feature bit ("embree", "closest_point"...), or NULL. */
DWV_API const char *dwv_feature_name(uint32_t feature);

/* ---------------------------------------------------------------------------------------------
 * Textures (issue 18): images owned by the scene, bound to material inputs through a mesh's UV
 * layer, looked up as Blender's Image Texture node (Cycles' kernel image lookup) at each surface
 * point. The subsurface inputs are looked up once, at the walk's entry point, and the walk goes
 * through the homogeneous medium they make there, as Cycles does. Add textures and bindings
 * before dwv_scene_commit; the commit checks that every mesh of a textured material has the UV
 * layers its bindings name.
 * ------------------------------------------------------------------------------------------- */
/* How texels are stored. 8-bit data is kept as bytes (1 byte per channel in memory), float as
 * float (4 bytes). */
typedef int32_t dwv_texel_format_t;
enum {
    DWV_TEXEL_FLOAT32 = 0,   /* scene-linear (or non-colour) float, finite */
    DWV_TEXEL_SRGB8 = 1,     /* 8-bit sRGB-encoded colour (Blender's "sRGB" colour space): decoded
                                to linear after interpolation, as Cycles does for byte images;
                                a fourth channel (alpha) is linear */
    DWV_TEXEL_LINEAR8 = 2    /* 8-bit data taken as value / 255 ("Non-Color", or "Linear") */
};
/* Blender's Image Texture "Extension": what lies outside [0, 1) of UV. */
typedef int32_t dwv_texture_extension_t;
enum {
    DWV_EXTENSION_REPEAT = 0, /* tiles */
    DWV_EXTENSION_EXTEND = 1, /* the edge texels go on */
    DWV_EXTENSION_CLIP = 2,   /* zero outside (texels outside the image count as 0 when filtering) */
    DWV_EXTENSION_MIRROR = 3  /* tiles, every other tile mirrored */
};
/* Blender's Image Texture "Interpolation". */
typedef int32_t dwv_texture_interpolation_t;
enum {
    DWV_INTERPOLATION_LINEAR = 0,  /* bilinear between the four nearest texel centres */
    DWV_INTERPOLATION_CLOSEST = 1, /* the texel under the point */
    DWV_INTERPOLATION_CUBIC = 2    /* uniform cubic B-spline over the 4 x 4 nearest texels (Cycles'
                                      "Cubic": smooth, it does not pass through the texels) */
};
typedef struct dwv_texture_desc_t {
    uint32_t struct_size;  /* sizeof(dwv_texture_desc_t): set by DWV_TEXTURE_DESC_INIT */
    uint32_t width, height;/* 1 to 65536 each, at most 2^28 texels */
    uint32_t channels;     /* 1, 3 or 4 */
    dwv_texel_format_t format;
    dwv_texture_extension_t extension;
    dwv_texture_interpolation_t interpolation;
    uint32_t reserved;     /* 0 */
    /* channels x width x height values (float for DWV_TEXEL_FLOAT32, uint8_t otherwise),
     * interleaved, row 0 at v = 0 (the bottom, as Blender's Image.pixels); copied at the call. */
    const void *texels;
} dwv_texture_desc_t;
#define DWV_TEXTURE_DESC_INIT                                                                       \
    {sizeof(dwv_texture_desc_t), 0u, 0u, 4u, DWV_TEXEL_FLOAT32, DWV_EXTENSION_REPEAT,               \
     DWV_INTERPOLATION_LINEAR, 0u, NULL}
/* Adds a texture; *texture_id numbers them from 0 in order. NaN or infinite float texels are
 * refused (the message names the first). */
DWV_API dwv_result_t dwv_scene_add_texture(dwv_scene_t *scene, const dwv_texture_desc_t *texture,
                                           uint32_t *texture_id);

/* A texture from a PNG file (8 bits per channel; 16-bit files are reduced to 8): its size and
 * channels (1 grey, 3 colour, 4 with alpha) come from the file, extension and interpolation from
 * `settings`, whose format says what the bytes are (DWV_TEXEL_SRGB8 or DWV_TEXEL_LINEAR8; other
 * fields ignored). A missing file: DWV_ERROR_IO; not a PNG: DWV_ERROR_FORMAT; the message names it.
 * Or from an OpenEXR file (told by its magic number; added after 0.2): float texels as stored
 * (half converted; scene-linear, as Blender takes EXRs), channels R G B A -> 4, R G B -> 3, Y -> 1
 * (an alpha beside Y is dropped), the first part (scanline, or a tiled one's full resolution);
 * settings->format must then be DWV_TEXEL_FLOAT32. A multi-layer or deep file, sub-sampled
 * channels, an empty data window, sizes beyond the limits (refused before the texels are read),
 * a damaged or truncated file: DWV_ERROR_FORMAT; NaN or infinite texels are refused as
 * dwv_scene_add_texture refuses them, the file named. The scene is unchanged on failure. */
DWV_API dwv_result_t dwv_scene_add_texture_file(dwv_scene_t *scene, const char *path,
                                                const dwv_texture_desc_t *settings, uint32_t *texture_id);

/* The material inputs a texture can drive (dwv_material_t's fields of those names). */
typedef int32_t dwv_material_input_t;
enum {
    DWV_INPUT_BASE_COLOR = 0,          /* colour: 3 or 4 channels (alpha ignored) */
    DWV_INPUT_SUBSURFACE_COLOR = 1,    /* colour */
    DWV_INPUT_SUBSURFACE_WEIGHT = 2,   /* scalar */
    DWV_INPUT_SUBSURFACE_RADIUS = 3,   /* colour (per-channel radius) */
    DWV_INPUT_SUBSURFACE_SCALE = 4,    /* scalar */
    DWV_INPUT_SUBSURFACE_ANISOTROPY = 5, /* scalar */
    DWV_INPUT_ROUGHNESS = 6,           /* scalar */
    DWV_INPUT_SPECULAR = 7,            /* scalar: 3.x Specular, 4.x+ Specular IOR Level */
    DWV_INPUT_SPECULAR_TINT = 8,       /* colour (3.x: its first channel is the tint factor) */
    DWV_INPUT_NORMAL_MAP = 9,          /* colour: Blender's Normal Map node, tangent space */
    DWV_INPUT_BUMP = 10                /* scalar height: Blender's Bump node */
};
/* A texture bound to one input of a material. Scalar inputs take a 1-channel texture's value, or
 * a colour texture's luminance 0.2126 R + 0.7152 G + 0.0722 B (Blender's colour-to-float socket
 * conversion); colour inputs and normal maps need 3 or 4 channels. The value met at a point is
 * clamped to the input's range (dwv_material_t) and mixed with what the input had:
 * input = (1 - blend) x input + blend x value; bindings apply in the order they were made (so
 * Blender 3.x's Subsurface Color = mix(Base Color, Subsurface Color, Subsurface) is a Base Color
 * texture bound to DWV_INPUT_SUBSURFACE_COLOR with blend 1 - Subsurface over the material's own
 * Subsurface Color). Normal map (Cycles' svm_node_normal_map): with (x, y, z) = 2 rgb - 1, T the
 * mesh's tangent for that UV layer and N_i the vertex normal, both interpolated and not
 * normalised, B = sign N_i x T and N_s the unit smooth normal, by the binding's bump_shadowing
 * release: Blender 3.x (DWV_BUMP_SHADOWING_CHIANG2019, and NONE) N = normalize(x T + y B + z N_i),
 * then normalize(N_s + strength (N - N_s)); Blender 4.0+ (CHIANG2019_MAPPED, CONTY2019) the
 * strength in tangent space, N = normalize(strength x T + strength y B + (1 + (z - 1)
 * min(strength, 1)) N_i). Bump (after a normal map, if both): N' = normalize(N - distance
 * grad h) with grad h the height's gradient along the surface, negated by `invert`, then
 * normalize(strength N' + (1 - strength) N) (Cycles' svm_node_set_bump in the limit of small
 * differentials). At most one normal map and one bump per material. */
/* How a Cycles release treats a normal that a normal map or bump tilted
 * (dwv_texture_binding_t.bump_shadowing of the normal map or bump). */
typedef int32_t dwv_bump_shadowing_t;
enum {
    DWV_BUMP_SHADOWING_NONE = 0, /* the mapped normal as it is */
    /* Blender 3.x: the closures' normal is kept such that the view's mirror reflection stays above
     * the surface (ensure_valid_reflection, at the camera's hit; at a walk's exit with the walk's
     * last direction as the view), and diffuse lobes are multiplied
     * by Chiang, Li and Burley 2019's term ("Taming the Shadow Terminator", bsdf.h
     * bump_shadowing_term): G = -g^3 + g^2 + g, g = (N_s . L) / ((N . L)(N_s . N)) clamped (1
     * from g >= 1, 0 below 0), N the mapped normal, N_s the smooth one; at the entry point and at
     * a walk's exit. */
    DWV_BUMP_SHADOWING_CHIANG2019 = 1,
    /* Blender 4.x: Chiang 2019's term as above; the diffuse lobe takes the mapped normal as is,
     * the specular layer and the subsurface entry and exit the normal kept valid for reflection
     * as above (4.x's maybe_ensure_valid_specular_reflection: specular closures and the BSSRDF). */
    DWV_BUMP_SHADOWING_CHIANG2019_MAPPED = 2,
    /* Blender 5.x (measured against 5.2): normals as 4.x (the diffuse lobe's the mapped one as
     * is, the specular layer's and the subsurface's kept valid for reflection); diffuse lobes are 0 where L is
     * on the other side of the smooth surface than N says ((N_s . L)(N_s . N)(N . L) < 0), else
     * times Conty Estevez, Lecocq and Stein 2019's microfacet shadowing ("A Microfacet-Based
     * Shadowing Function to Solve the Bump Terminator Problem"): the GGX G1 =
     * 2 / (1 + sqrt(1 + alpha^2 tan^2 theta_i)), alpha^2 = min(tan^2 theta_d / 8, 1), theta_d the
     * angle from N_s to N and theta_i from N_s to L. */
    DWV_BUMP_SHADOWING_CONTY2019 = 3
};
typedef struct dwv_texture_binding_t {
    uint32_t struct_size;        /* sizeof(dwv_texture_binding_t): set by DWV_TEXTURE_BINDING_INIT */
    dwv_material_input_t input;  /* DWV_INPUT_* */
    uint32_t texture_id;         /* from dwv_scene_add_texture */
    int32_t invert;              /* bump: 1 inverts the height (Blender's Invert) */
    const char *uv_layer;        /* the UV layer's name (dwv_mesh_t.uv_layer_names); NULL or "": layer 0;
                                    copied at the call */
    double blend;                /* in [0, 1], 1 by default */
    double strength;             /* normal map: >= 0 (1 by default); bump: in [0, 1] */
    double distance;             /* bump: finite, in scene units (Blender's Distance, 1 by default) */
    dwv_bump_shadowing_t bump_shadowing; /* normal map, bump: DWV_BUMP_SHADOWING_* (3.x's, Chiang 2019, by default) */
    uint32_t reserved;           /* 0 */
} dwv_texture_binding_t;
#define DWV_TEXTURE_BINDING_INIT                                                                    \
    {sizeof(dwv_texture_binding_t), DWV_INPUT_BASE_COLOR, 0u, 0, NULL, 1.0, 1.0, 1.0,              \
     DWV_BUMP_SHADOWING_CHIANG2019, 0u}
DWV_API dwv_result_t dwv_scene_bind_texture(dwv_scene_t *scene, uint32_t material_id,
                                            const dwv_texture_binding_t *binding);
/* The bytes the scene's textures hold in memory, and their texels (width x height summed): the
 * memory per texel is bytes / texels. */
DWV_API dwv_result_t dwv_scene_texture_memory(const dwv_scene_t *scene, uint64_t *bytes, uint64_t *texels);

/* ---------------------------------------------------------------------------------------------
 * Bakes: images of a committed scene, progressive, deterministic, cancellable.
 *
 * dwv_bake_start runs a bake on a pool of threads and returns at once; dwv_bake_wait,
 * dwv_bake_progress and dwv_bake_cancel may be called from any thread while it runs (cancel
 * returns within 100 ms); dwv_bake_finish waits and hands over the image. dwv_bake does all of
 * it in one call. With the same scene, options and seed, the image is bit-identical for any
 * thread count and tile order (time budgets aside, which cut a bake where the clock says).
 * Budgets: samples per pixel, wall time, target relative error; whichever is reached first.
 * ------------------------------------------------------------------------------------------- */
typedef int32_t dwv_bake_target_t;
enum {
    DWV_BAKE_CAMERA = 0, /* the camera's view: subsurface and diffuse surfaces, world behind */
    DWV_BAKE_UV = 1      /* one mesh's outgoing subsurface radiance laid out in its UVs */
};

typedef struct dwv_bake_progress_t {
    uint32_t struct_size;     /* sizeof(dwv_bake_progress_t): set by DWV_BAKE_PROGRESS_INIT */
    uint32_t done;            /* 1 once the bake has ended (finished, cancelled or failed) */
    double fraction;          /* of the larger of the budgets, in [0, 1] */
    double seconds;           /* since the start */
    double estimated_relative_error; /* of the image so far (see dwv_bake_stats_t); inf before */
    uint64_t samples_per_pixel;      /* completed passes' samples per pixel */
    uint64_t events;                 /* scattering events so far */
} dwv_bake_progress_t;
#define DWV_BAKE_PROGRESS_INIT {sizeof(dwv_bake_progress_t), 0u, 0.0, 0.0, 0.0, 0u, 0u}

/* Called from a bake thread (one at a time) about 10 times a second and once at the end; a
 * non-zero return cancels the bake. It must not call into the same bake but dwv_bake_cancel. */
typedef int32_t (*dwv_progress_callback_t)(void *user, const dwv_bake_progress_t *progress);

/* How a bake's walks carry the three colour channels of a medium whose channels differ.
 * SHARED: one walk carries them all; the channel that drives each free flight is drawn, and
 * every channel is weighted by spectral MIS (balance heuristic over the channels, as Cycles).
 * SEPARATE: one walk per channel, each in that channel's own medium and with that channel's own
 * Dwivedi distribution; no channel's weight carries another's pdf, at the cost of more walks.
 * AUTO (0, the default): SHARED for an explicit technique; with DWV_TECHNIQUE_AUTO the pilot
 * chooses per mesh, with the technique. Grey media (all channels alike) always walk once. */
typedef uint32_t dwv_channel_walks_t;
enum {
    DWV_CHANNEL_WALKS_AUTO = 0,
    DWV_CHANNEL_WALKS_SHARED = 1,
    DWV_CHANNEL_WALKS_SEPARATE = 2
};
DWV_API const char *dwv_channel_walks_name(dwv_channel_walks_t channel_walks);
DWV_API dwv_result_t dwv_channel_walks_from_name(const char *name, dwv_channel_walks_t *channel_walks);

/* What a subsurface surface that a path meets after a diffuse bounce does (issue 18). Cycles up
 * to 4.x makes it a Lambertian surface of the walk's colour there (bssrdf_setup: "always fall back
 * to diffuse after a diffuse ancestor"); 5.0 and later walk it (multi-bounce random walk). */
typedef enum dwv_subsurface_after_diffuse_t {
    /* by each material's subsurface_model: the BLENDER52_* models walk, the others fall back */
    DWV_SUBSURFACE_AFTER_DIFFUSE_BY_MODEL = 0,
    DWV_SUBSURFACE_AFTER_DIFFUSE_LAMBERT = 1,  /* Cycles 3.x, 4.x */
    DWV_SUBSURFACE_AFTER_DIFFUSE_WALK = 2      /* Cycles 5.0+ */
} dwv_subsurface_after_diffuse_t;

/* Cycles' pixel filters (film.cpp's filter table): a camera sample's offset from its pixel's
 * centre is drawn on each axis with density proportional to the filter, every sample of weight 1
 * (filter importance sampling, as Cycles' camera rays), so an image is the filter's convolution of
 * the radiance. With w the filter width in pixels and x the offset:
 *   box: uniform on |x| <= w / 2;
 *   Gaussian: exp(-8 x^2 / w^2) on |x| <= 1.5 w;
 *   Blackman-Harris (Blender's default, w = 1.5): 0.35875 - 0.48829 cos t + 0.14128 cos 2t
 *   - 0.01168 cos 3t, t = 2 pi (x / (2 w) + 1/2), on |x| <= w. */
typedef int32_t dwv_pixel_filter_t;
enum { DWV_PIXEL_FILTER_BOX = 0, DWV_PIXEL_FILTER_GAUSSIAN = 1, DWV_PIXEL_FILTER_BLACKMAN_HARRIS = 2 };
/* The filters' names, as the scene file (bake.pixel_filter), the CLI (--pixel-filter) and the
 * shim spell them: "box", "gaussian", "blackman_harris"; NULL for a value that is no filter. */
DWV_API const char *dwv_pixel_filter_name(dwv_pixel_filter_t pixel_filter);
DWV_API dwv_result_t dwv_pixel_filter_from_name(const char *name, dwv_pixel_filter_t *pixel_filter);

/* Where a UV bake's samples sit in their texel (issue 18), as Cycles' bake places them
 * (integrator_init_from_bake). Blender hands each texel's centre to Cycles as barycentrics (u, v)
 * of its triangle's corners 0 and 1 (corner 2: 1 - u - v) and their half-texel differentials
 * du/dx, du/dy, dv/dx, dv/dy; a sample with uniforms (rx, ry) moves the centre to
 * u + du/dx (rx - 1/2) + du/dy (ry - 1/2), and v alike:
 *   RETRY (Cycles 3.5 and later, the default): the moved point where it lies strictly inside the
 *     triangle, else new uniforms, up to 10 tries, then the centre;
 *   MIRROR (Cycles up to 3.4): sample 0 at the centre; every other sample's point folded back into
 *     the triangle, u' = fold(u moved, 1) then v' = fold(v moved, 1 - u'), where
 *     fold(x, m) = m f(x / m), f(t) = t - floor(t) on even periods floor(t) and
 *     1 - (t - floor(t)) on odd ones (a mirrored repeat; fold(x, 0) = 0).
 * Camera bakes place their samples by the pixel filter whatever this says. */
typedef int32_t dwv_uv_jitter_t;
enum { DWV_UV_JITTER_RETRY = 0, DWV_UV_JITTER_MIRROR = 1 };

typedef struct dwv_bake_options_t {
    uint32_t struct_size;     /* sizeof(dwv_bake_options_t): set by DWV_BAKE_OPTIONS_INIT */
    dwv_bake_target_t target;
    uint32_t width, height;   /* 1 to 16384 each, at most 2^26 pixels */
    uint32_t uv_mesh;         /* UV bakes: the mesh id (it must have UVs) */
    uint32_t uv_margin;       /* UV bakes: pixels of dilation around islands, <= 64 */
    dwv_technique_t technique;
    uint64_t samples;         /* samples per pixel, 1 to 2^24; the bake stops there */
    double time_limit;        /* seconds, >= 0; 0: none; cuts only after the first pass (2 spp) */
    double target_error;      /* relative error of the image, >= 0; 0: none */
    uint32_t threads;         /* 0: all cores; at most 1024 */
    uint32_t max_events;      /* cap on scattering events per walk; 0: 10^6 */
    uint64_t seed;
    uint32_t tile_size;       /* pixels per tile side, 0: 32, or down to 8 on small images (16 tiles per thread) */
    uint32_t channel_walks;   /* dwv_channel_walks_t, DWV_CHANNEL_WALKS_*; a reserved 0 (AUTO) in older headers */
    dwv_progress_callback_t progress;  /* optional */
    void *progress_user;
    /* Added after 0.1.0 (a caller whose struct_size ends before them gets 0, 0: the whole bake).
     * A chunk of a split bake (docs/farm.md): sample_count > 0 bakes sample indices sample_first
     * to sample_first + sample_count - 1 of every pixel, exactly the samples those indices have
     * in a whole bake of `samples` per pixel (which stays the total: auto's pilot depends on it,
     * never on the range); sample_first + sample_count <= samples; no time_limit or
     * target_error. The image keeps its exact sums for dwv_image_write_partial. */
    uint64_t sample_first;
    uint64_t sample_count;
    /* Added after 0.2 (issue 19; a caller whose struct_size ends before it gets 0). Camera bakes:
     * 0, a camera ray that misses every surface sees the world (alpha 0 there); 1, it sees
     * nothing (RGBA 0), as Cycles' Film > Transparent: each pixel is then coverage x surface,
     * premultiplied by its alpha. The world lights the scene either way. */
    int32_t transparent_background;
    uint32_t reserved;        /* 0 */
    /* Added after 0.3 (issue 18; a caller whose struct_size ends before it gets 0). Bake passes
     * (docs/output.md): DWV_PASS_BIT(pass) for each dwv_pass_t the image should hold beside its
     * combined RGBA (DWV_PASS_BIT(DWV_PASS_COMBINED) may be set; it is always there). 0: the
     * combined image only, with no extra memory. Not with sample_count > 0 (split bakes' partial
     * files carry the combined sums only). Each pass costs 96 bytes per pixel while baking and 24
     * in the image. */
    uint32_t passes;
    uint32_t reserved2;       /* 0 */
    /* Added after 0.3 (issue 18; a caller whose struct_size ends before them gets 0s: the one-bounce
     * image it always got). Indirect light as Cycles' Light Paths (Blender's scene.cycles
     * max_bounces, diffuse_bounces, glossy_bounces, transmission_bounces, min_light_bounces):
     * a path goes on after a walk's exit and after the diffuse and specular lobes of a surface,
     * until its bounces of that kind or in total would exceed their limit, each 0 to 1024; after
     * min_light_bounces + 1 bounces, Russian roulette as Cycles (continuation probability
     * min(1, sqrt(max channel of the path's throughput))). max_bounces = 0: the one-bounce
     * image, bit for bit, but for mirror-sharp specular layers (Roughness 0, or nearly: Cycles'
     * singular reflection), whose reflected ray is traced for the lights and world it meets
     * whatever the limits, as Cycles' (its limits are the scene's + 1). dwivedi's materials have no transmission lobe (a walk's entry is no
     * transmission bounce in Cycles either): transmission_bounces never limits a path today. */
    uint32_t max_bounces, diffuse_bounces, glossy_bounces, transmission_bounces;
    uint32_t min_light_bounces;
    dwv_subsurface_after_diffuse_t subsurface_after_diffuse; /* DWV_SUBSURFACE_AFTER_DIFFUSE_* */
    /* Added after 0.3 (issue 18; a caller whose struct_size ends before it gets 0: no blur, the
     * image it always got). Cycles' Filter Glossy (Blender's scene.cycles.blur_glossy, default
     * 1.0), finite and >= 0: at a path's vertex after the camera's, with p the smallest pdf of
     * the path's non-singular bounces so far (its sampled direction's density under the surface
     * mixture that drew it; cos / pi for a walk's exit), every specular layer's GGX alpha becomes
     * max(alpha, 0.5 sqrt(1 - p / blur_glossy)) where p / blur_glossy < 1 (a mirror-sharp layer
     * turns GGX), for its direct light and its path ray alike. 0: none. */
    double blur_glossy;
    /* Added after 0.3 (issue 18; a caller whose struct_size ends before them gets 0, 0: the box
     * of one pixel, the image it always got). Cycles' pixel filter of camera bakes (Blender's
     * scene.cycles.pixel_filter_type and filter_width; UV bakes jitter over their texel as
     * Cycles' bake does, whatever the filter): DWV_PIXEL_FILTER_*, and its width in pixels, 0
     * (one pixel) or in [0.01, 10] (Blender's range). */
    dwv_pixel_filter_t pixel_filter;
    uint32_t reserved3;       /* 0 */
    double filter_width;
    /* Added after 0.3 (issue 18; a caller whose struct_size ends before it gets 0, RETRY: the
     * texel samples it always got). Where a UV bake's samples sit in their texel: DWV_UV_JITTER_*
     * (the add-on passes MIRROR from Blender 3.4 and earlier). */
    dwv_uv_jitter_t uv_jitter;
    uint32_t reserved4;       /* 0 */
} dwv_bake_options_t;
/* Blender's default Light Paths (12 total, 4 diffuse, 4 glossy, 12 transmission, min 0; Filter
 * Glossy 1); the box filter of one pixel (Blender's default is Blackman-Harris of 1.5 pixels: the
 * add-on passes the scene's); UV samples placed as Cycles 3.5+ places them. */
#define DWV_BAKE_OPTIONS_INIT                                                                       \
    {sizeof(dwv_bake_options_t), DWV_BAKE_CAMERA, 256u, 256u, 0u, 16u, DWV_TECHNIQUE_AUTO, 64u, 0.0,  \
     0.0, 0u, 0u, 0u, 0u, 0u, NULL, NULL, 0u, 0u, 0, 0u, 0u, 0u, 12u, 4u, 4u, 12u, 0u,                \
     DWV_SUBSURFACE_AFTER_DIFFUSE_BY_MODEL, 1.0, DWV_PIXEL_FILTER_BOX, 0u, 1.0, DWV_UV_JITTER_RETRY, 0u}

/* Bake passes as Cycles' (Blender's render passes and its bake types' pass filter). Direct:
 * light from the lights and the world at the first scattering, the one at the camera ray's hit
 * (or the texel): for a subsurface walk, at its exit; indirect: light that scattered again after
 * it; colour: the lobe's closures' weights (Blender 3.x) or albedos (4.x+) at that hit. Diffuse
 * holds the Lambertian, Principled diffuse, retro-reflection and subsurface lobes (Cycles 3.0+);
 * glossy the specular layer; transmission none of this library's materials (0). Emission: the
 * surfaces' own (0: no material emits). Environment: camera bakes, the world seen directly (where
 * the camera ray meets nothing; also with transparent_background); UV bakes, Cycles' Environment
 * bake: the world along the direction of the texel's position from the origin. Combined (the
 * image's RGBA) = the direct and indirect passes, emission and (camera bakes without a
 * transparent background) environment. dwv_image_pass gives each as Blender shows it: direct
 * and indirect divided by their colour (Cycles' DiffDir = light / DiffCol). */
typedef enum dwv_pass_t {
    DWV_PASS_COMBINED = 0,
    DWV_PASS_DIFFUSE_DIRECT = 1,
    DWV_PASS_DIFFUSE_INDIRECT = 2,
    DWV_PASS_DIFFUSE_COLOR = 3,
    DWV_PASS_GLOSSY_DIRECT = 4,
    DWV_PASS_GLOSSY_INDIRECT = 5,
    DWV_PASS_GLOSSY_COLOR = 6,
    DWV_PASS_TRANSMISSION_DIRECT = 7,
    DWV_PASS_TRANSMISSION_INDIRECT = 8,
    DWV_PASS_TRANSMISSION_COLOR = 9,
    DWV_PASS_EMISSION = 10,
    DWV_PASS_ENVIRONMENT = 11
} dwv_pass_t;
#define DWV_PASS_COUNT 12u
#define DWV_PASS_BIT(pass) (1u << (uint32_t)(pass))

/* Blender's name of the pass, its layer's name in a multilayer OpenEXR ("Combined", "DiffDir",
 * "DiffInd", "DiffCol", "GlossDir", ..., "Emit", "Env"); NULL for an unknown value. */
DWV_API const char *dwv_pass_name(dwv_pass_t pass);
/* The pass of Blender's name (dwv_pass_name); DWV_ERROR_UNKNOWN_NAME listing the names otherwise. */
DWV_API dwv_result_t dwv_pass_from_name(const char *name, dwv_pass_t *pass);

/* Blender's bake types (bpy: scene.cycles.bake_type) that this library bakes, and the pass filter
 * bits (scene.render.bake.use_pass_*). */
typedef enum dwv_bake_type_t {
    DWV_BAKE_TYPE_COMBINED = 0,
    DWV_BAKE_TYPE_DIFFUSE = 1,
    DWV_BAKE_TYPE_GLOSSY = 2,
    DWV_BAKE_TYPE_TRANSMISSION = 3,
    DWV_BAKE_TYPE_EMIT = 4,
    DWV_BAKE_TYPE_ENVIRONMENT = 5
} dwv_bake_type_t;
#define DWV_BAKE_FILTER_DIRECT 1u       /* use_pass_direct */
#define DWV_BAKE_FILTER_INDIRECT 2u     /* use_pass_indirect */
#define DWV_BAKE_FILTER_COLOR 4u        /* use_pass_color (Diffuse, Glossy, Transmission) */
#define DWV_BAKE_FILTER_DIFFUSE 8u      /* use_pass_diffuse (Combined) */
#define DWV_BAKE_FILTER_GLOSSY 16u      /* use_pass_glossy (Combined) */
#define DWV_BAKE_FILTER_TRANSMISSION 32u /* use_pass_transmission (Combined) */
#define DWV_BAKE_FILTER_EMIT 64u        /* use_pass_emit (Combined) */

/* The passes (for dwv_bake_options_t.passes) that bake type `type` with pass filter `filter`
 * needs. An unknown type, filter bits beyond DWV_BAKE_FILTER_EMIT, or a filter that selects
 * nothing (Diffuse with none of direct, indirect, colour; Combined with no lobe and no emission,
 * or with neither direct nor indirect and no emission) fail with a message, as Blender refuses them. */
DWV_API dwv_result_t dwv_bake_type_passes(dwv_bake_type_t type, uint32_t filter, uint32_t *passes);

typedef struct dwv_bake_s dwv_bake_t;
typedef struct dwv_image_s dwv_image_t;

/* Validates the options against the committed scene and starts the bake; *bake is the handle
 * (release it with dwv_bake_release, which cancels a running bake and waits for it). */
DWV_API dwv_result_t dwv_bake_start(dwv_scene_t *scene, const dwv_bake_options_t *options, dwv_bake_t **bake);
/* Waits up to timeout_seconds (0: just looks; negative: forever); *done is 1 once it ended. */
DWV_API dwv_result_t dwv_bake_wait(dwv_bake_t *bake, double timeout_seconds, int32_t *done);
DWV_API dwv_result_t dwv_bake_progress(dwv_bake_t *bake, dwv_bake_progress_t *progress);
/* Asks a running bake to stop; it ends within 100 ms. Any thread; harmless once it ended. */
DWV_API dwv_result_t dwv_bake_cancel(dwv_bake_t *bake);
/* Waits for the end and hands over the image (*image, reference count 1): DWV_ERROR_CANCELLED
 * and no image if it was cancelled; the bake's own error if it failed. */
DWV_API dwv_result_t dwv_bake_finish(dwv_bake_t *bake, dwv_image_t **image);
DWV_API void dwv_bake_release(dwv_bake_t *bake);
/* dwv_bake_start + dwv_bake_finish + dwv_bake_release. */
DWV_API dwv_result_t dwv_bake(dwv_scene_t *scene, const dwv_bake_options_t *options, dwv_image_t **image);

/* The pixels of an image: RGBA scene-linear Rec.709, row 0 at the top; the estimate's variance
 * (of the pixel mean, per channel RGB, from the samples' own variance as if they were independent:
 * stratified samples make it an upper bound) and each pixel's sample count. Pointers stay valid while
 * the image lives. UV bakes leave alpha 0 on texels outside every island and its margin. */
typedef struct dwv_image_info_t {
    uint32_t struct_size;   /* sizeof(dwv_image_info_t): set by DWV_IMAGE_INFO_INIT */
    uint32_t width, height;
    uint32_t reserved;
    const float *rgba;      /* 4 x width x height */
    const float *variance;  /* 3 x width x height */
    const uint32_t *samples;/* width x height */
} dwv_image_info_t;
#define DWV_IMAGE_INFO_INIT {sizeof(dwv_image_info_t), 0u, 0u, 0u, NULL, NULL, NULL}
DWV_API dwv_result_t dwv_image_info(const dwv_image_t *image, dwv_image_info_t *info);

/* What a bake did. The estimated relative error is the image's relative RMSE against its converged
 * self: sqrt(mean of the pixel-mean luminance variances) / mean pixel luminance, over the covered
 * pixels (target_error of the options is in the same terms). Each pixel's samples form two
 * independent stratified replicates, whose spread gives the variances; below 64 covered pixels the
 * samples' own variances do, which overstate it under stratification. */
typedef struct dwv_bake_stats_t {
    uint32_t struct_size;    /* sizeof(dwv_bake_stats_t): set by DWV_BAKE_STATS_INIT */
    dwv_technique_t technique;
    uint64_t samples_per_pixel;  /* the largest per-pixel count */
    uint64_t samples;            /* all camera or texel samples together */
    uint64_t events;             /* scattering events */
    uint64_t walks;
    double seconds;
    double estimated_relative_error;
    double mean_rgb[3];          /* the mean of the covered pixels */
    double truncated_weight[3];  /* weight of walks ended by the event cap, per covered pixel */
    uint32_t features;           /* DWV_FEATURE_* bits the bake used */
    uint32_t threads;
    uint64_t warnings;           /* degenerate geometry met (zero-area triangles, NaN hits...) */
    uint32_t error_vs_time_count;/* points in dwv_image_error_vs_time */
    uint32_t reserved;
    /* Added after 0.3 (issue 18; a caller whose struct_size ends before it gets the fields before
     * it). Rays the paths after the first scattering traced (indirect light and mirrors'
     * reflections; the walks' own rays are not counted). A merge of partial files: the sum of
     * its chunks' (partial format 2). */
    uint64_t path_rays;
} dwv_bake_stats_t;
#define DWV_BAKE_STATS_INIT                                                                         \
    {sizeof(dwv_bake_stats_t), 0, 0u, 0u, 0u, 0u, 0.0, 0.0, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, 0u,    \
     0u, 0u, 0u, 0u, 0u}
DWV_API dwv_result_t dwv_image_stats(const dwv_image_t *image, dwv_bake_stats_t *stats);
/* One point of the error-against-time series (one per completed pass). */
typedef struct dwv_error_point_t {
    double seconds;
    double estimated_relative_error;
    uint64_t samples_per_pixel;
} dwv_error_point_t;
/* Copies up to `capacity` points into `points`; *count gets how many there are in all. */
DWV_API dwv_result_t dwv_image_error_vs_time(const dwv_image_t *image, dwv_error_point_t *points,
                                             uint32_t capacity, uint32_t *count);
DWV_API dwv_result_t dwv_image_retain(dwv_image_t *image);
DWV_API void dwv_image_release(dwv_image_t *image);
/* An image made from caller pixels (RGBA, 4 x width x height), e.g. to colour-manage them. */
DWV_API dwv_result_t dwv_image_create(uint32_t width, uint32_t height, const float *rgba, dwv_image_t **image);

/* ---------------------------------------------------------------------------------------------
 * Output: OpenEXR and colour-managed display images. Files are written under a temporary name in
 * the same folder and renamed over the target only when complete: a failure never leaves a
 * partial file and never replaces a good one.
 * ------------------------------------------------------------------------------------------- */
/* Float RGBA, scene-linear Rec.709 with the chromaticities attribute, plus the variance channels
 * (variance_R/G/B) and the sample counts (samples), and metadata: technique, samples, seconds,
 * estimated error, features, library version, the error-against-time series. */
DWV_API dwv_result_t dwv_image_write_exr(const dwv_image_t *image, const char *path);

/* Added after 0.3 (issue 18): bake passes. *passes: DWV_PASS_BIT of every pass the image holds
 * (DWV_PASS_COMBINED always). */
DWV_API dwv_result_t dwv_image_passes(const dwv_image_t *image, uint32_t *passes);
/* A new image (release it) of one pass as Blender shows it: RGB the pass (direct and indirect
 * divided by their lobe's colour, 0 where the colour is 0), A the combined image's alpha,
 * variance that of the pass's mean (divided by the colour squared for direct and indirect, the
 * colour's own noise not counted), the same samples and stats. DWV_PASS_COMBINED gives a copy.
 * A pass the image does not hold: DWV_ERROR_INVALID_ARGUMENT. */
DWV_API dwv_result_t dwv_image_pass(const dwv_image_t *image, dwv_pass_t pass, dwv_image_t **pass_image);
/* The image of a Blender bake type and pass filter (dwv_bake_type_passes), as Cycles' bake makes
 * it: Combined, the sum of the filter's lobes' direct and / or indirect light plus emission;
 * Diffuse / Glossy / Transmission, (direct + indirect) with colour, their sum divided by the
 * colour without it, the colour alone with neither; Emit; Environment. A the combined image's
 * alpha. The image must hold the passes that dwv_bake_type_passes names. */
DWV_API dwv_result_t dwv_image_bake_type(const dwv_image_t *image, dwv_bake_type_t type, uint32_t filter,
                                         dwv_image_t **result);
/* Writes a multilayer OpenEXR as Blender's (one scanline part, ZIP, FLOAT): channels
 * Combined.R/G/B/A and, for every other pass the image holds, <name>.R/G/B (dwv_pass_name; as
 * dwv_image_pass gives it), and the metadata of dwv_image_write_exr. Blender opens it as a
 * multilayer image whose passes are these layers (an empty render layer name); dwv_image_write_exr's
 * variance and sample channels are not in it. Atomic as dwv_image_write_exr. */
DWV_API dwv_result_t dwv_image_write_exr_layers(const dwv_image_t *image, const char *path);

/* Blender's colour-management settings, applied through OpenColorIO: exposure (stops) in scene
 * linear, then the display/view/look transform, then gamma (display = display^(1/gamma)).
 * NULL strings mean the config's defaults ("" for look means none; "None", Blender's name for no
 * look, means what NULL does unless the config has a look of that name). The config comes from
 * `config_path`, else $OCIO, else the small default config dwivedi ships (sRGB display with
 * "Standard" and a filmic view). */
typedef struct dwv_display_options_t {
    uint32_t struct_size; /* sizeof(dwv_display_options_t): set by DWV_DISPLAY_OPTIONS_INIT */
    uint32_t reserved;
    const char *config_path;
    const char *display;
    const char *view;
    const char *look;
    double exposure;      /* stops, in [-100, 100] */
    double gamma;         /* in [0.001, 1000] */
} dwv_display_options_t;
#define DWV_DISPLAY_OPTIONS_INIT {sizeof(dwv_display_options_t), 0u, NULL, NULL, NULL, NULL, 0.0, 1.0}
/* Writes an 8-bit sRGB-encoded (as the display says) RGBA PNG of the image through the view. The
 * image's colour is premultiplied by alpha; the PNG's is straight (the view transform gets
 * rgb / alpha where alpha is neither 0 nor 1, as Blender's Image.save_render does). */
DWV_API dwv_result_t dwv_image_write_display_png(const dwv_image_t *image, const char *path,
                                                 const dwv_display_options_t *display);
/* The same pixels in memory: 4 x width x height bytes, as the PNG would hold them. */
DWV_API dwv_result_t dwv_image_to_display(const dwv_image_t *image, const dwv_display_options_t *display,
                                          uint8_t *rgba8, uint64_t size);

/* ---------------------------------------------------------------------------------------------
 * Split bakes (docs/farm.md): chunks of sample indices baked apart, merged into the bits of the
 * whole bake. A pixel's sums are exact (fixed point, 2^-48, in 128-bit integers), so they add in
 * any order to the same bits.
 * ------------------------------------------------------------------------------------------- */
/* Writes the image of a chunk bake (sample_count > 0) as a partial file: per pixel its counts and
 * exact sums, the error data, the scene's and options' hashes, the seed, the range, the library
 * version and a checksum; atomically (a killed writer leaves no file under `path`). */
DWV_API dwv_result_t dwv_image_write_partial(const dwv_image_t *image, const char *path);
/* Reads `count` partial files, checks that they come from one scene, options, seed and library
 * version and that their ranges tile 0 .. samples - 1 exactly once (the message names the file
 * at fault: missing range, duplicate, overlap, truncated or corrupt file, foreign chunk), and
 * makes the image a single bake would have made: the same pixels, variance, counts and estimated
 * error. Its error_vs_time has one point per chunk prefix in sample order; its seconds are the
 * chunks' bake seconds added up (the time one machine would have taken for them in turn). */
DWV_API dwv_result_t dwv_merge_partials(const char *const *paths, uint32_t count, dwv_image_t **image);

/* ---------------------------------------------------------------------------------------------
 * Scene files (JSON, docs/scene-format.md) and the built-in default scene.
 * ------------------------------------------------------------------------------------------- */
/* Reads a scene file and the meshes it references (OBJ, PLY) into a new committed scene; bake
 * settings in the file (resolution, samples, technique...) go into *options, which should
 * come in as DWV_BAKE_OPTIONS_INIT (it may be NULL; a struct of an older header, ending at
 * sample_first or later, gets the settings it has fields for, as dwv_bake_start reads it). */
DWV_API dwv_result_t dwv_scene_load(const char *path, dwv_scene_t **scene, dwv_bake_options_t *options);
/* The same from JSON text in memory; relative mesh paths resolve against base_dir (NULL: "."). */
DWV_API dwv_result_t dwv_scene_load_json(const char *json, uint64_t size, const char *base_dir,
                                         dwv_scene_t **scene, dwv_bake_options_t *options);
/* The default scene: a thin back-lit translucent leaf-like shell beside a thick front-lit
 * wax-like shape, committed; *options gets its resolution and samples. */
DWV_API dwv_result_t dwv_scene_create_default(dwv_scene_t **scene, dwv_bake_options_t *options);

#ifdef __cplusplus
}
#endif

#endif /* DWIVEDI_H */
