/* The monotonic clock every budget, progress report and timing in the library reads. */
#ifndef DWV_UTIL_CLOCK_H
#define DWV_UTIL_CLOCK_H

#include <time.h>

/* Seconds on CLOCK_MONOTONIC from an arbitrary origin: differences are elapsed times. */
double dwvu_clock_seconds(void);

/* The CLOCK_MONOTONIC time `seconds` (>= 0) from now, as pthread_cond_timedwait wants it from a
 * condition variable set to that clock. */
struct timespec dwvu_clock_after(double seconds);

#endif
