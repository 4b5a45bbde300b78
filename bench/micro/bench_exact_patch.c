/* The "exact start" of a march: mfmm_exact_patch (src/exact/exact.h) from
 * many vertex sources with a radius of a few edges, against one full
 * mfmm_solve_exact. Usage:
 *   bench_exact_patch [--edges K] [--sources S] MESH...
 * radius = K mean edge lengths (default MFMM_EXACT_START_RADIUS, the library's
 * base radius); S sources spread over the mesh (default 200). Prints per
 * mesh: mean patch size, mean time per patch, the full solve's time, and the
 * workspace's peak bytes.
 *
 * Session 28 (issue 13: the patch is 15-20 % of an all-pairs row on
 * camelhead, and doubles a row on meshes under 3k vertices):
 * - Cost against radius (--edges 3 / 5 / 7 / 10, 400 sources): camelhead
 *   80 / 179 / 308 / 561 vertices, 568 / 1818 / 4041 / 9757 windows,
 *   31 / 84 / 172 / 391 us a patch; nefertiti 19 / 56 / 124 / 308 us; hand
 *   19 / 38 / 66 / 127 us; beetle 29 / 71 / 128 / 248 us. Windows per
 *   vertex grow with r (camelhead 7, 10, 13, 17), so a patch costs about
 *   r^2.2. All pairs, camelhead, 2000 rows, serial, two rounds:
 *   r = 7 2.46-2.50 s, r = 5 2.16-2.17, r = 3 2.04-2.06, plain 1.95.
 * - Pruning is saturated. A probe (not kept) ran each patch twice, the
 *   second time trimming against the first run's final distances at every
 *   vertex (perfect upper bounds, ex_enqueue's ex_trim) and dropping a
 *   window that the far vertex of the face it enters beats at 9 points of
 *   its interval (ICH's third rule with perfect bounds): 200 sources, r = 7,
 *   windows hand 1213 -> 1202, camelhead 3926 -> 3924, nefertiti 2417 ->
 *   2417, the same patch distances. The queue's order already gives the
 *   edge ends their final distances when a window is trimmed; what is left
 *   are distinct unfoldings on the lower envelope of their edges (window
 *   against window dominance, MMP's, removed 5 %: session 23). Any exact
 *   method that carries these windows (VTP too) carries about as many: a
 *   faster patch has to come from cheaper windows, or a smaller radius. */
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
