/* Classical (analog) sampling: isotropic and Henyey-Greenstein phase functions, exponential free
 * flights. Pure, inline, in double and single precision. */
#ifndef DWV_KERNEL_CLASSICAL_H
#define DWV_KERNEL_CLASSICAL_H

#include <math.h>
#include <tgmath.h>

#define DWVK_INV_FOUR_PI 0.079577471545947667884

#define DWVK_REAL double
#define DWVK_SUFFIX(name) name##_d
#define DWVK_ONE_BELOW 0x1.fffffffffffffp-1 /* the largest double below 1 */
#include "classical_real.h"
#undef DWVK_REAL
#undef DWVK_SUFFIX
#undef DWVK_ONE_BELOW

#define DWVK_REAL float
#define DWVK_SUFFIX(name) name##_f
#define DWVK_ONE_BELOW 0x1.fffffep-1f /* the largest float below 1 */
#include "classical_real.h"
#undef DWVK_REAL
#undef DWVK_SUFFIX
#undef DWVK_ONE_BELOW

#endif
