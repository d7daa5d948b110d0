#include "util/parallel.h"

#include <stdlib.h>

uint32_t dwvu_parallel_start(dwvu_parallel *pool, uint32_t count, void *(*work)(void *), void *arg)
{
    if (count > DWVU_PARALLEL_MAX_THREADS) count = DWVU_PARALLEL_MAX_THREADS;
    pool->started = 0;
    for (; pool->started < count; ++pool->started)
        if (pthread_create(&pool->ids[pool->started], NULL, work, arg) != 0) break;
    return pool->started;
}

void dwvu_parallel_join(dwvu_parallel *pool)
{
    for (uint32_t i = 0; i < pool->started; ++i) pthread_join(pool->ids[i], NULL);
    pool->started = 0;
}

void dwvu_parallel_run(uint32_t threads, void *(*work)(void *), void *arg)
{
    /* On the heap: a pool's thread ids are 8 KiB, too much for a caller's small thread stack. */
    dwvu_parallel *pool = threads > 1u ? malloc(sizeof *pool) : NULL;
    if (pool) dwvu_parallel_start(pool, threads - 1u, work, arg);
    work(arg);
    if (pool) {
        dwvu_parallel_join(pool);
        free(pool);
    }
}
