/* The cost of the exact start's patch: mfmm_exact_patch (start/patch.h)
 * from many vertex sources with a radius of a few edges, against one full
 * mfmm_solve_exact on the same mesh (the peer: what the patch saves over
 * solving exactly everywhere). Prints per mesh: mean patch size (vertices,
 * windows), mean time per patch, the full solve's time, and the
 * workspace's peak bytes.
 *
 *   bench_exact_patch [--edges K] [--sources S] MESH...
 *
 * radius = K mean edge lengths (default MFMM_EXACT_START_RADIUS, the
 * library's base radius); S sources spread over the mesh (default 200).
 * Findings and their commands: docs/march-measurements.md. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_util.h"
#include "meshfmm.h"
#include "start/patch.h"

static int bench(const char *path, double edges, int n_sources)
{
    double *V = NULL;
    int32_t *F = NULL, nv = 0, nf = 0;
    mfmm_error err;
    if (mfmm_load_mesh(path, &V, &nv, &F, &nf, &err) != MFMM_OK) {
        fprintf(stderr, "%s: %s\n", path, err.message);
        return 1;
    }
    mfmm_mesh *mesh = NULL;
    mfmm_exact_solver *ws = NULL;
    double *d = malloc((size_t)nv * sizeof *d);
    if (!d || mfmm_mesh_create(V, nv, F, nf, NULL, &mesh, &err) != MFMM_OK ||
        mfmm_exact_solver_create(mesh, &ws) != MFMM_OK) {
        fprintf(stderr, "%s: cannot build the mesh or solver\n", path);
        return 1;
    }
    mfmm_mesh_info mi = {.struct_size = sizeof mi};
    mfmm_mesh_get_info(mesh, &mi);
    double radius = edges * mi.mean_edge_length;
    /* sources: referenced vertices, spread evenly */
    int32_t first = F[0];
    mfmm_source full_src = {first, -1, {0, 0, 0}, 0.0};
    mfmm_exact_info info = {.struct_size = sizeof info};
    double t0 = now();
    mfmm_solve_exact(ws, &full_src, 1, NULL, d, &info, NULL);
    double t_full = now() - t0;
    long long total = 0, windows = 0;
    size_t peak = 0;
    int done = 0;
    t0 = now();
    for (int i = 0; i < n_sources; i++) {
        int32_t f = (int32_t)((int64_t)i * nf / n_sources);
        mfmm_source s = {F[3 * (size_t)f], -1, {0, 0, 0}, 0.0};
        int32_t n = 0;
        const int32_t *vs;
        const double *ds;
        if (mfmm_exact_patch(ws, &s, 1, radius, 0, &n, &vs, &ds, &info) != MFMM_OK)
            return 1;
        total += n;
        windows += info.n_windows;
        if (info.peak_bytes > peak)
            peak = info.peak_bytes;
        done++;
    }
    double t_patch = (now() - t0) / done;
    printf("%s: nv %d, radius %.3g (%.1f edges): %.1f vertices and %.0f windows a patch, "
           "%.1f us a patch; full solve %.1f ms (%.0f patches); peak %.2f MB\n",
           path, (int)nv, radius, edges, (double)total / done, (double)windows / done,
           1e6 * t_patch, 1e3 * t_full, t_full / t_patch, peak / 1048576.0);
    mfmm_exact_solver_destroy(ws);
    mfmm_mesh_destroy(mesh);
    mfmm_free(V);
    mfmm_free(F);
    free(d);
    return 0;
}

int main(int argc, char **argv)
{
    double edges = MFMM_EXACT_START_RADIUS;
    int n_sources = 200, rc = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--edges") && i + 1 < argc)
            edges = atof(argv[++i]);
        else if (!strcmp(argv[i], "--sources") && i + 1 < argc)
            n_sources = atoi(argv[++i]);
        else
            rc |= bench(argv[i], edges, n_sources);
    }
    return rc;
}
