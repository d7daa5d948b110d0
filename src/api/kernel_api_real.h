/* Body of src/api/kernel_api.c for one precision: the per-event entry points, named by API_NAME,
 * calling the kernels named by API_KERNEL, in API_REAL. */

dwv_result_t API_NAME(dwv_dwivedi_sample)(const dwv_dwivedi_t *dist, API_REAL u, API_REAL *cos_theta)
{
    static const char fn[] = DWVU_STRINGIFY(API_NAME(dwv_dwivedi_sample));
    DWV_TRY(check_dwivedi(fn, dist));
    DWV_TRY(dwv_check_range(fn, "u", u, 0.0, 1.0));
    DWV_TRY(dwv_check_pointer(fn, "cos_theta", cos_theta));
    API_KERNEL(dwvk_dwivedi) d = API_DIST(dist);
    *cos_theta = API_KERNEL(dwvk_dwivedi_sample_pdf)(&d, u).cos_theta;
    return DWV_SUCCESS;
}

dwv_result_t API_NAME(dwv_dwivedi_pdf)(const dwv_dwivedi_t *dist, API_REAL cos_theta, API_REAL *pdf)
{
    static const char fn[] = DWVU_STRINGIFY(API_NAME(dwv_dwivedi_pdf));
    DWV_TRY(check_dwivedi(fn, dist));
    DWV_TRY(dwv_check_range(fn, "cos_theta", cos_theta, -1.0, 1.0));
    DWV_TRY(dwv_check_pointer(fn, "pdf", pdf));
    API_KERNEL(dwvk_dwivedi) d = API_DIST(dist);
    *pdf = API_KERNEL(dwvk_dwivedi_pdf)(&d, cos_theta);
    return DWV_SUCCESS;
}

dwv_result_t API_NAME(dwv_dwivedi_sample_pdf)(const dwv_dwivedi_t *dist, API_REAL u, API_SAMPLE_T *sample)
{
    static const char fn[] = DWVU_STRINGIFY(API_NAME(dwv_dwivedi_sample_pdf));
    DWV_TRY(check_dwivedi(fn, dist));
    DWV_TRY(dwv_check_range(fn, "u", u, 0.0, 1.0));
    DWV_TRY(dwv_check_struct(fn, "sample", sample, (uint32_t)sizeof(API_SAMPLE_T)));
    API_KERNEL(dwvk_dwivedi) d = API_DIST(dist);
    API_KERNEL(dwvk_dwivedi_sample) s = API_KERNEL(dwvk_dwivedi_sample_pdf)(&d, u);
    sample->cos_theta = s.cos_theta;
    sample->one_minus_cos = s.one_minus_cos;
    sample->one_plus_cos = s.one_plus_cos;
    sample->pdf = s.pdf;
    sample->stretch = s.stretch;
    return DWV_SUCCESS;
}

dwv_result_t API_NAME(dwv_dwivedi_stretch)(const dwv_dwivedi_t *dist, API_REAL cos_theta, API_REAL *stretch)
{
    static const char fn[] = DWVU_STRINGIFY(API_NAME(dwv_dwivedi_stretch));
    DWV_TRY(check_dwivedi(fn, dist));
    DWV_TRY(dwv_check_range(fn, "cos_theta", cos_theta, -1.0, 1.0));
    DWV_TRY(dwv_check_pointer(fn, "stretch", stretch));
    API_KERNEL(dwvk_dwivedi) d = API_DIST(dist);
    *stretch = API_KERNEL(dwvk_dwivedi_stretch)(&d, cos_theta);
    return DWV_SUCCESS;
}

dwv_result_t API_NAME(dwv_hg_sample)(API_REAL g, API_REAL u, API_REAL *cos_theta)
{
    static const char fn[] = DWVU_STRINGIFY(API_NAME(dwv_hg_sample));
    DWV_TRY(dwv_check_finite(fn, "g", g));
    if (!(fabs(g) < 1.0)) return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: g = %.9g must be in (-1, 1)", fn, (double)g);
    DWV_TRY(dwv_check_range(fn, "u", u, 0.0, 1.0));
    DWV_TRY(dwv_check_pointer(fn, "cos_theta", cos_theta));
    *cos_theta = API_KERNEL(dwvk_hg_sample)(g, u);
    return DWV_SUCCESS;
}

dwv_result_t API_NAME(dwv_hg_pdf)(API_REAL g, API_REAL cos_theta, API_REAL *pdf)
{
    static const char fn[] = DWVU_STRINGIFY(API_NAME(dwv_hg_pdf));
    DWV_TRY(dwv_check_finite(fn, "g", g));
    if (!(fabs(g) < 1.0)) return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: g = %.9g must be in (-1, 1)", fn, (double)g);
    DWV_TRY(dwv_check_range(fn, "cos_theta", cos_theta, -1.0, 1.0));
    DWV_TRY(dwv_check_pointer(fn, "pdf", pdf));
    *pdf = API_KERNEL(dwvk_hg_pdf)(g, cos_theta);
    return DWV_SUCCESS;
}

dwv_result_t API_NAME(dwv_exponential_sample)(API_REAL sigma, API_REAL u, API_REAL *distance)
{
    static const char fn[] = DWVU_STRINGIFY(API_NAME(dwv_exponential_sample));
    DWV_TRY(dwv_check_finite(fn, "sigma", sigma));
    if (!(sigma > 0)) return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: sigma = %.9g must be > 0", fn, (double)sigma);
    DWV_TRY(dwv_check_range(fn, "u", u, 0.0, 1.0));
    DWV_TRY(dwv_check_pointer(fn, "distance", distance));
    API_REAL t = API_KERNEL(dwvk_exponential_sample)(sigma, u);
    if (!isfinite(t))
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: sigma = %.9g is so small that the distance overflows", fn,
                        (double)sigma);
    *distance = t;
    return DWV_SUCCESS;
}

dwv_result_t API_NAME(dwv_exponential_pdf)(API_REAL sigma, API_REAL distance, API_REAL *pdf)
{
    static const char fn[] = DWVU_STRINGIFY(API_NAME(dwv_exponential_pdf));
    DWV_TRY(dwv_check_finite(fn, "sigma", sigma));
    if (!(sigma > 0)) return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: sigma = %.9g must be > 0", fn, (double)sigma);
    DWV_TRY(dwv_check_finite(fn, "distance", distance));
    if (distance < 0) return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: distance = %.9g must be >= 0", fn, (double)distance);
    DWV_TRY(dwv_check_pointer(fn, "pdf", pdf));
    *pdf = API_KERNEL(dwvk_exponential_pdf)(sigma, distance);
    return DWV_SUCCESS;
}
