/* Helpers shared by the C benchmarks (bench/bench_*.c). */
#ifndef MFMM_BENCH_UTIL_H
#define MFMM_BENCH_UTIL_H

#include <time.h>

/* Wall-clock seconds (monotonic). */
static inline double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* qsort's comparison for doubles, ascending. */
static inline int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

#endif
