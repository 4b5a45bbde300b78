/* Helpers shared by the C benchmarks (bench/bench_*.c). */
#ifndef MFMM_BENCH_UTIL_H
#define MFMM_BENCH_UTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "meshfmm.h"
#include "march/march.h"

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

/* A march workspace (core/march.h) of n entries, F = 1, no limit: 1, or 0
 * when out of memory (bench_state_free frees what was allocated). */
static inline int bench_state_alloc(mfmm_march_state *s, size_t n)
{
    memset(s, 0, sizeof *s);
    s->T = malloc(n * sizeof *s->T);
    s->label = malloc(n);
    s->heap_key = malloc(n * sizeof *s->heap_key);
    s->heap_vertex = malloc(n * sizeof *s->heap_vertex);
    s->heap_pos = malloc(n * sizeof *s->heap_pos);
    s->max_distance = MFMM_INF;
    return s->T && s->label && s->heap_key && s->heap_vertex && s->heap_pos;
}

static inline void bench_state_free(mfmm_march_state *s)
{
    free(s->T);
    free(s->label);
    free(s->heap_key);
    free(s->heap_vertex);
    free(s->heap_pos);
}

/* A benchmark of one mesh, named by its file name. */
typedef void bench_mesh_fn(const char *name, const double *V, int32_t nv, const int32_t *F,
                           int32_t nf, int repeats, int n_sources);

/* Loads each of the n mesh files and runs fn on it; a file that does not
 * load is reported on stderr and skipped. */
static inline void bench_mesh_files(const char *const *paths, int n, bench_mesh_fn *fn,
                                    int repeats, int n_sources)
{
    for (int i = 0; i < n; i++) {
        double *V = NULL;
        int32_t *F = NULL, nv = 0, nf = 0;
        mfmm_error err;
        if (mfmm_load_mesh(paths[i], &V, &nv, &F, &nf, &err) != MFMM_OK) {
            fprintf(stderr, "%s: %s\n", paths[i], err.message);
            continue;
        }
        const char *base = strrchr(paths[i], '/');
        fn(base ? base + 1 : paths[i], V, nv, F, nf, repeats, n_sources);
        mfmm_free(V);
        mfmm_free(F);
    }
}

#endif
