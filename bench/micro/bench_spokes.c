/* The march over spokes (mfmm_march_spoke_loop, src/march/march.h) against
 * the face walk it replaces, its peer: F = 1, unfolding on, plain start, the
 * same heap, sources and vertex order, alternating repeats; every row
 * compared bit for bit. Also the spokes' size and the time to build them
 * (once per mesh, on the first march that uses them). Prints march medians
 * and their ratio, spokes / face walk.
 *
 *   bench_spokes [--repeats R] [--sources S] MESH...
 *
 * Findings and the variants measured with it: docs/march-measurements.md. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "meshfmm.h"
#include "mesh/mesh.h"
#include "mesh/spokes.h"

static double median(double *x, int n)
{
    qsort(x, (size_t)n, sizeof *x, cmp_double);
    return x[n / 2];
}

static void bench(const char *name, const double *V, int32_t nv, const int32_t *F, int32_t nf,
                  int repeats, int n_sources)
{
    mfmm_mesh *mesh = NULL;
    mfmm_error err;
    if (mfmm_mesh_create(V, nv, F, nf, NULL, &mesh, &err) != MFMM_OK) {
        fprintf(stderr, "%s: %s\n", name, err.message);
        return;
    }
    mfmm_march_mesh walk = mfmm_mesh_march_view(mesh), sp = walk;
    double t0 = now();
    if (mfmm_mesh_spokes_of(mesh, 1, &sp.spoke_offset, &sp.spokes) != MFMM_OK) {
        fprintf(stderr, "%s: out of memory for the spokes\n", name);
        mfmm_mesh_destroy(mesh);
        return;
    }
    double t_build = now() - t0;
    mfmm_march_state s;
    int have_state = bench_state_alloc(&s, (size_t)nv);
    double *ref = malloc((size_t)nv * sizeof *ref);
    size_t nt = (size_t)repeats * n_sources;
    double *t_walk = malloc(nt * sizeof(double)), *t_sp = malloc(nt * sizeof(double));
    if (!have_state || !ref || !t_walk || !t_sp) {
        fprintf(stderr, "out of memory\n");
        exit(1);
    }
    s.unfolding = 1;
    int k = 0;
    long differ = 0;
    for (int q = 0; q < n_sources; q++) {
        int32_t v = mesh->to_internal[((int64_t)nv * (2 * q + 1)) / (2 * n_sources)];
        for (int r = 0; r < repeats; r++, k++) {
            mfmm_march_reset(&s, nv);
            mfmm_march_seed(&s, v, 0.0);
            double t1 = now();
            mfmm_march_run(&s, &walk);
            t_walk[k] = now() - t1;
            memcpy(ref, s.T, (size_t)nv * sizeof *ref);
            mfmm_march_reset(&s, nv);
            mfmm_march_seed(&s, v, 0.0);
            t1 = now();
            mfmm_march_run(&s, &sp);
            t_sp[k] = now() - t1;
            for (int32_t i = 0; i < nv; i++)
                differ += memcmp(ref + i, s.T + i, sizeof *ref) != 0;
        }
    }
    double tw = median(t_walk, k), ts = median(t_sp, k);
    int32_t n = sp.spoke_offset[nv];
    printf("%-22s nv=%8d  face walk %9.3f ms | spokes %9.3f ms = %.3fx  (%.2f spokes/vertex, "
           "%.0f B/vertex, built in %.1f ms)  entries differing %ld\n",
           name, nv, 1e3 * tw, 1e3 * ts, ts / tw, (double)n / nv,
           ((double)n * sizeof(mfmm_spoke) + (nv + 1.0) * sizeof(int32_t)) / nv, 1e3 * t_build,
           differ);
    bench_state_free(&s);
    free(ref);
    free(t_walk);
    free(t_sp);
    mfmm_mesh_destroy(mesh);
}

int main(int argc, char **argv)
{
    int repeats = 5, n_sources = 3, first = 1;
    while (first + 1 < argc && argv[first][0] == '-') {
        if (!strcmp(argv[first], "--repeats"))
            repeats = atoi(argv[first + 1]);
        else if (!strcmp(argv[first], "--sources"))
            n_sources = atoi(argv[first + 1]);
        else {
            fprintf(stderr, "usage: bench_spokes [--repeats R] [--sources S] MESH...\n");
            return 2;
        }
        first += 2;
    }
    if (repeats < 1 || n_sources < 1) {
        fprintf(stderr, "repeats and sources must be >= 1\n");
        return 2;
    }
    bench_mesh_files((const char *const *)(argv + first), argc - first, bench, repeats, n_sources);
    return 0;
}
