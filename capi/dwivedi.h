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
 * threads at once, as long as no two threads write the same object.
 */
#ifndef DWIVEDI_H
#define DWIVEDI_H

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
    DWV_ERROR_INVALID_STATE = 8     /* a call out of order (e.g. a walk step before dwv_walk_begin) */
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
    DWV_TECHNIQUE_CYCLES = 6     /* Cycles' mixture: classical 1/2 + backward 1/2 */
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
    double radius;            /* sphere, finite and > 0 */
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

#ifdef __cplusplus
}
#endif

#endif /* DWIVEDI_H */
