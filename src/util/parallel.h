/* Thread pools for the library's parallel loops: the walk estimator's blocks, the bake's tiles,
 * the auto pilot's blocks. Each loop's work function claims its items from a shared atomic
 * counter, so which thread runs an item never changes a result. */
#ifndef DWV_UTIL_PARALLEL_H
#define DWV_UTIL_PARALLEL_H

#include <pthread.h>
#include <stdint.h>

#define DWVU_PARALLEL_MAX_THREADS 1024u

typedef struct dwvu_parallel {
    uint32_t started;
    pthread_t ids[DWVU_PARALLEL_MAX_THREADS];
} dwvu_parallel;

/* Starts up to `count` (at most DWVU_PARALLEL_MAX_THREADS) threads running work(arg) and returns
 * how many started: fewer when the system refuses more. */
uint32_t dwvu_parallel_start(dwvu_parallel *pool, uint32_t count, void *(*work)(void *), void *arg);
/* Waits for every thread dwvu_parallel_start started. */
void dwvu_parallel_join(dwvu_parallel *pool);

/* Runs work(arg) on `threads` threads, the calling thread among them, and returns when all have
 * returned: the work is done even where no thread can be started. */
void dwvu_parallel_run(uint32_t threads, void *(*work)(void *), void *arg);

#endif
