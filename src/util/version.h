/* The library's version as text, from capi/dwivedi.h's numbers: what dwv_version_string() returns
 * and what the EXR and PNG writers record. */
#ifndef DWV_UTIL_VERSION_H
#define DWV_UTIL_VERSION_H

#include <dwivedi.h>

#define DWVU_STRINGIFY_(x) #x
#define DWVU_STRINGIFY(x) DWVU_STRINGIFY_(x)
#define DWVU_VERSION_STRING \
    DWVU_STRINGIFY(DWV_VERSION_MAJOR) "." DWVU_STRINGIFY(DWV_VERSION_MINOR) "." DWVU_STRINGIFY(DWV_VERSION_PATCH)

#endif
