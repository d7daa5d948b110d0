#include "util/error.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static _Thread_local char last_message[512];

dwv_result_t dwv_fail(dwv_result_t result, const char *format, ...)
{
    va_list args;
    va_start(args, format);
    vsnprintf(last_message, sizeof last_message, format, args);
    va_end(args);
    return result;
}

const char *dwv_last_error_message(void)
{
    return last_message;
}

const char *dwv_result_string(dwv_result_t result)
{
    switch (result) {
    case DWV_SUCCESS: return "success";
    case DWV_ERROR_NULL_POINTER: return "null pointer";
    case DWV_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case DWV_ERROR_OUT_OF_RANGE: return "argument out of range";
    case DWV_ERROR_STRUCT_SIZE: return "struct_size too small";
    case DWV_ERROR_UNKNOWN_NAME: return "unknown name";
    case DWV_ERROR_OUT_OF_MEMORY: return "out of memory";
    case DWV_ERROR_INTERNAL: return "internal error";
    case DWV_ERROR_INVALID_STATE: return "call out of order";
    case DWV_ERROR_CANCELLED: return "cancelled";
    case DWV_ERROR_IO: return "input/output error";
    case DWV_ERROR_FORMAT: return "malformed file";
    default: return "unknown result code";
    }
}

dwv_result_t dwv_check_pointer(const char *function, const char *name, const void *pointer)
{
    if (pointer == NULL) return dwv_fail(DWV_ERROR_NULL_POINTER, "%s: %s is NULL", function, name);
    return DWV_SUCCESS;
}

dwv_result_t dwv_check_finite(const char *function, const char *name, double value)
{
    if (isnan(value)) return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: %s is NaN", function, name);
    if (isinf(value))
        return dwv_fail(DWV_ERROR_INVALID_ARGUMENT, "%s: %s is infinite", function, name);
    return DWV_SUCCESS;
}

dwv_result_t dwv_check_range(const char *function, const char *name, double value, double lo, double hi)
{
    DWV_TRY(dwv_check_finite(function, name, value));
    if (value < lo || value > hi)
        return dwv_fail(DWV_ERROR_OUT_OF_RANGE, "%s: %s = %.17g is outside [%.17g, %.17g]", function,
                        name, value, lo, hi);
    return DWV_SUCCESS;
}

dwv_result_t dwv_check_struct(const char *function, const char *name, const void *pointer, uint32_t needed)
{
    DWV_TRY(dwv_check_pointer(function, name, pointer));
    uint32_t size;
    memcpy(&size, pointer, sizeof size);
    if (size < needed)
        return dwv_fail(DWV_ERROR_STRUCT_SIZE,
                        "%s: %s->struct_size is %u, needs at least %u (initialise it with the *_INIT macro)",
                        function, name, size, needed);
    return DWV_SUCCESS;
}
