/* Per-thread error messages and argument checks shared by every capi entry point. */
#ifndef DWV_UTIL_ERROR_H
#define DWV_UTIL_ERROR_H

#include <dwivedi.h>

/* Keeps a printf-formatted message for the calling thread and returns `result`. */
dwv_result_t dwv_fail(dwv_result_t result, const char *format, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Each check returns DWV_SUCCESS or fails with a message naming `function` and `name`. */
dwv_result_t dwv_check_pointer(const char *function, const char *name, const void *pointer);
dwv_result_t dwv_check_finite(const char *function, const char *name, double value);
/* value finite and in [lo, hi]. */
dwv_result_t dwv_check_range(const char *function, const char *name, double value, double lo, double hi);
/* *struct_size (the first member of a caller-allocated struct) at least `needed`. */
dwv_result_t dwv_check_struct(const char *function, const char *name, const void *pointer, uint32_t needed);

#define DWV_TRY(call)                                 \
    do {                                              \
        dwv_result_t dwv_try_result_ = (call);        \
        if (dwv_try_result_ != DWV_SUCCESS) return dwv_try_result_; \
    } while (0)

#endif
