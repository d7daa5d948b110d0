/* capi entry points of the kernels: validate, then call src/kernel. */
#include <math.h>
#include <string.h>

#include <dwivedi.h>
#include "util/error.h"
#include "util/version.h"
#include "kernel/classical.h"
#include "kernel/diffusion_length.h"
#include "kernel/dwivedi_sampling.h"
#include "kernel/rng.h"

uint32_t dwv_version(void)
{
    return DWV_VERSION;
}


const char *dwv_version_string(void)
{
    return DWVU_VERSION_STRING;
}

/* ---- diffusion length ---------------------------------------------------------------------- */

static const char *const v0_method_names[] = {"exact", "case", "deon", "fast"};
#define V0_METHOD_COUNT ((int32_t)(sizeof v0_method_names / sizeof v0_method_names[0]))

const char *dwv_v0_method_name(dwv_v0_method_t method)
{
    return method >= 0 && method < V0_METHOD_COUNT ? v0_method_names[method] : NULL;
}

dwv_result_t dwv_v0_method_from_name(const char *name, dwv_v0_method_t *method)
{
    DWV_TRY(dwv_check_pointer("dwv_v0_method_from_name", "name", name));
    DWV_TRY(dwv_check_pointer("dwv_v0_method_from_name", "method", method));
    for (int32_t i = 0; i < V0_METHOD_COUNT; ++i) {
        if (strcmp(name, v0_method_names[i]) == 0) {
            *method = i;
            return DWV_SUCCESS;
        }
    }
    return dwv_fail(DWV_ERROR_UNKNOWN_NAME,
                    "dwv_v0_method_from_name: unknown method '%.64s' (exact, case, deon or fast)", name);
}

static dwv_result_t kappa_by_method(const char *function, double albedo, dwv_v0_method_t method,
                                    dwvk_kappa_t *out)
{
    DWV_TRY(dwv_check_range(function, "albedo", albedo, 0.0, 1.0));
    switch (method) {
    case DWV_V0_EXACT: *out = dwvk_kappa_exact(albedo); return DWV_SUCCESS;
    case DWV_V0_CASE: *out = dwvk_kappa_case(albedo); return DWV_SUCCESS;
    case DWV_V0_DEON: *out = dwvk_kappa_deon(albedo); return DWV_SUCCESS;
    case DWV_V0_FAST: *out = dwvk_kappa_fast(albedo); return DWV_SUCCESS;
    default:
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: method %d is not a dwv_v0_method_t (0 to %d)",
                        function, (int)method, (int)V0_METHOD_COUNT - 1);
    }
}

dwv_result_t dwv_diffusion_length(double albedo, dwv_v0_method_t method, dwv_diffusion_length_t *out)
{
    static const char fn[] = "dwv_diffusion_length";
    DWV_TRY(dwv_check_struct(fn, "out", out, (uint32_t)sizeof(dwv_diffusion_length_t)));
    dwvk_kappa_t k;
    DWV_TRY(kappa_by_method(fn, albedo, method, &k));
    out->method = method;
    out->albedo = albedo;
    out->kappa = k.kappa;
    out->one_minus_kappa = k.one_minus_kappa;
    out->log_one_minus_kappa = k.log_one_minus_kappa;
    out->v0 = k.kappa > 0.0 ? 1.0 / k.kappa : INFINITY;
    out->log_ratio = dwvk_log_ratio(k);
    return DWV_SUCCESS;
}

dwv_result_t dwv_eigenfunction(double albedo, double v, double mu, double *phi)
{
    static const char fn[] = "dwv_eigenfunction";
    DWV_TRY(dwv_check_range(fn, "albedo", albedo, 0.0, 1.0));
    DWV_TRY(dwv_check_range(fn, "mu", mu, -1.0, 1.0));
    DWV_TRY(dwv_check_pointer(fn, "phi", phi));
    if (isnan(v)) return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: v is NaN", fn);
    if (!(fabs(v) > 1.0))
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE,
                        "%s: v = %.17g is not a discrete eigenvalue candidate (|v| > 1 needed)", fn, v);
    *phi = 0.5 * albedo / (1.0 - mu / v); /* Eq. 7 */
    return DWV_SUCCESS;
}

dwv_result_t dwv_eigenfunction_integral(double albedo, double v, double *integral)
{
    static const char fn[] = "dwv_eigenfunction_integral";
    DWV_TRY(dwv_check_range(fn, "albedo", albedo, 0.0, 1.0));
    DWV_TRY(dwv_check_pointer(fn, "integral", integral));
    if (isnan(v)) return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: v is NaN", fn);
    if (!(fabs(v) > 1.0)) return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: v = %.17g needs |v| > 1", fn, v);
    double k = 1.0 / fabs(v);
    /* alpha v atanh(1/v) = alpha atanh(k)/k (Eq. 8), even in v; -> alpha as v -> infinity. */
    *integral = k > 0.0 ? albedo * atanh(k) / k : albedo;
    return DWV_SUCCESS;
}

/* ---- Dwivedi sampling ---------------------------------------------------------------------- */

dwv_result_t dwv_dwivedi_init(dwv_dwivedi_t *dist, double albedo, dwv_v0_method_t method)
{
    static const char fn[] = "dwv_dwivedi_init";
    DWV_TRY(dwv_check_struct(fn, "dist", dist, (uint32_t)sizeof(dwv_dwivedi_t)));
    dwvk_kappa_t k;
    DWV_TRY(kappa_by_method(fn, albedo, method, &k));
    dwvk_dwivedi_d d = dwvk_dwivedi_from_kappa(k);
    dwvk_dwivedi_f f = dwvk_dwivedi_to_float(d);
    dist->method = method;
    dist->albedo = albedo;
    dist->kappa = d.kappa;
    dist->one_minus_kappa = d.one_minus_kappa;
    dist->log_ratio = d.log_ratio;
    dist->albedo_eff = d.albedo_eff;
    dist->kappa_f = f.kappa;
    dist->one_minus_kappa_f = f.one_minus_kappa;
    dist->log_ratio_f = f.log_ratio;
    dist->albedo_eff_f = f.albedo_eff;
    return DWV_SUCCESS;
}

/* A distribution that dwv_dwivedi_init could have made: guards every per-event call against an
 * uninitialised or overwritten struct. */
static dwv_result_t check_dwivedi(const char *function, const dwv_dwivedi_t *dist)
{
    DWV_TRY(dwv_check_struct(function, "dist", dist, (uint32_t)sizeof(dwv_dwivedi_t)));
    int ok = dist->kappa >= 0.0 && dist->kappa < 1.0 && dist->one_minus_kappa > 0.0 &&
             dist->one_minus_kappa <= 1.0 && dist->log_ratio >= 0.0 && dist->log_ratio < 16.0 &&
             dist->albedo_eff > 0.1 && dist->albedo_eff <= 1.0 && dist->kappa_f >= 0.0f &&
             dist->kappa_f < 1.0f && dist->one_minus_kappa_f > 0.0f && dist->log_ratio_f >= 0.0f &&
             dist->log_ratio_f < 16.0f && dist->albedo_eff_f > 0.1f && dist->albedo_eff_f <= 1.0f;
    /* Consistent too, by checks cheap enough for a per-event call (no transcendental): 1 - kappa
     * belongs to kappa, a L = 2 kappa, and the float copies round the doubles.
     * (DWV_DWIVEDI_INIT alone is the isotropic distribution, v = infinity.) */
    ok = ok && fabs(dist->kappa + dist->one_minus_kappa - 1.0) <= 1e-12 &&
         fabs(dist->albedo_eff * dist->log_ratio - 2.0 * dist->kappa) <= 1e-12 &&
         dist->kappa_f == (float)dist->kappa && dist->one_minus_kappa_f == (float)dist->one_minus_kappa &&
         dist->log_ratio_f == (float)dist->log_ratio && dist->albedo_eff_f == (float)dist->albedo_eff;
    if (!ok)
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT,
                        "%s: dist was not made by dwv_dwivedi_init (its constants are out of range or "
                        "inconsistent)", function);
    return DWV_SUCCESS;
}

static dwvk_dwivedi_d dwivedi_d(const dwv_dwivedi_t *dist)
{
    dwvk_dwivedi_d d = {dist->kappa, dist->one_minus_kappa, dist->log_ratio, dist->albedo_eff};
    return d;
}

static dwvk_dwivedi_f dwivedi_f(const dwv_dwivedi_t *dist)
{
    dwvk_dwivedi_f f = {dist->kappa_f, dist->one_minus_kappa_f, dist->log_ratio_f, dist->albedo_eff_f};
    return f;
}

/* The entry points of one precision. */
#define API_REAL double
#define API_NAME(name) name
#define API_KERNEL(name) name##_d
#define API_DIST(dist) dwivedi_d(dist)
#define API_SAMPLE_T dwv_dwivedi_sample_t
#include "kernel_api_real.h"
#undef API_REAL
#undef API_NAME
#undef API_KERNEL
#undef API_DIST
#undef API_SAMPLE_T

#define API_REAL float
#define API_NAME(name) name##_f
#define API_KERNEL(name) name##_f
#define API_DIST(dist) dwivedi_f(dist)
#define API_SAMPLE_T dwv_dwivedi_sample_f_t
#include "kernel_api_real.h"
#undef API_REAL
#undef API_NAME
#undef API_KERNEL
#undef API_DIST
#undef API_SAMPLE_T

dwv_result_t dwv_isotropic_sample(double u, double *cos_theta)
{
    DWV_TRY(dwv_check_range("dwv_isotropic_sample", "u", u, 0.0, 1.0));
    DWV_TRY(dwv_check_pointer("dwv_isotropic_sample", "cos_theta", cos_theta));
    *cos_theta = dwvk_isotropic_sample_d(u);
    return DWV_SUCCESS;
}

dwv_result_t dwv_isotropic_pdf(double *pdf)
{
    DWV_TRY(dwv_check_pointer("dwv_isotropic_pdf", "pdf", pdf));
    *pdf = DWVK_INV_FOUR_PI;
    return DWV_SUCCESS;
}

dwv_result_t dwv_hg_sample_pdf(double g, double u, double *cos_theta, double *pdf)
{
    DWV_TRY(dwv_hg_sample(g, u, cos_theta));
    return dwv_hg_pdf(g, *cos_theta, pdf);
}

/* ---- random numbers ------------------------------------------------------------------------ */

dwv_result_t dwv_random_u64(uint64_t seed, uint64_t stream, uint64_t sample, uint32_t dimension,
                            uint64_t *value)
{
    DWV_TRY(dwv_check_pointer("dwv_random_u64", "value", value));
    *value = dwvk_rng_u64(dwvk_rng_key(seed, stream, sample), dimension);
    return DWV_SUCCESS;
}

dwv_result_t dwv_random_uniform(uint64_t seed, uint64_t stream, uint64_t sample, uint32_t dimension,
                                double *u)
{
    DWV_TRY(dwv_check_pointer("dwv_random_uniform", "u", u));
    *u = dwvk_rng_uniform_d(dwvk_rng_key(seed, stream, sample), dimension);
    return DWV_SUCCESS;
}

dwv_result_t dwv_random_uniform_f(uint64_t seed, uint64_t stream, uint64_t sample, uint32_t dimension,
                                  float *u)
{
    DWV_TRY(dwv_check_pointer("dwv_random_uniform_f", "u", u));
    *u = dwvk_rng_uniform_f(dwvk_rng_key(seed, stream, sample), dimension);
    return DWV_SUCCESS;
}
