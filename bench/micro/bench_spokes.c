/* The march over spokes against the face walk (src/core/march.h, issue
 * 13.2): F = 1, unfolding on, plain start, the same heap, sources and
 * vertex order, alternating repeats; every row compared bit for bit. Also
 * the spokes' size and the time to build them (once per mesh, on the first
 * march that uses them).
 *
 * Measured (session 15, --repeats 5 --sources 3, march medians, spokes /
 * face walk): hand 0.72x, spot 0.77x, camelhead 0.81x, nefertiti 0.81x,
 * sine 500 (251k) 0.79x; 7.3-8.0 spokes and 412-450 B per vertex, built in
 * 0.1 ms (hand) to 69 ms (251k); no entry differs. Session 14's probe of
 * the same records (bench history) measured 0.73-0.79x; 72-byte records
 * 0.77-0.87x; an indexed form (two 4-byte face slots per spoke) 0.92-1.04x.
 * Session 16: each triangle's 1/c^2 and sin theta stored in the spoke (88
 * bytes, the same rows bit for bit: no division and one sqrt fewer per
 * update) ran 0.82-0.86x against 0.80-0.83x for 56 bytes in the same run:
 * the march waits on memory, not on the divider. Prefetching six lines of a
 * vertex's spokes when it joins the front (march.h, mfmm_march_offer_to):
 * spokes nefertiti 4.00-4.15 -> 3.64-3.80 ms, sine 500 32.7-33.5 -> 27.9-28.1,
 * camelhead, spot, hand within noise; with a 64 MB write between runs (a
 * cold cache, a probe): camelhead 1.45-1.50 -> 1.16-1.24, nefertiti
 * 4.90-5.06 -> 4.20-4.32.
 * Session 17 probes (spokes march, two rounds against the same tree built
 * apart): the 8 children of a heap node scanned by SSE2 (4 minpd, a
 * movemask for the first least): camelhead 1.04-1.05 -> 1.06-1.08 ms,
 * nefertiti 3.76 -> 3.59-3.63, hand equal: not kept. A spoke loop in two
 * passes (the t of up to 16 spokes, then their offers in order: the same
 * rows): camelhead 1.06 -> 1.26 ms, nefertiti 3.80 -> 4.60, hand +20 %,
 * sine 316 (100k) +1 %: not kept. The update arithmetic replaced by a
 * multiply-add (wrong rows, bench_solve): camelhead -23 %, sine 316 -7 %:
 * on meshes that fit in cache a quarter of the march is the update's chain.
 * Session 18 (bench_solve's split, one run, --repeats 7 --sources 3;
 * records = the spoke walk with edge updates alone / Dijkstra, updates =
 * march / that walk): sine 316 (100k) 1.15 x 1.32, igea 1.04 x 1.30,
 * camelhead 1.23 x 1.41. So "the 100k gap is memory" (session 17) was
 * wrong: the triangles' updates are the larger share everywhere. Per
 * settled vertex (sine 316, cachegrind): 2.48 triangles evaluated (one per
 * face and per virtual triangle: the least any label-setting march can do),
 * +300 instructions and +2.8 mispredicted branches against the edges-only
 * walk (y Alive 1.5, the Eq. 5 test 1.4, the min 0.6). Probes, not kept
 * (same tree, a copy of the loop, min of 7): every triangle evaluated
 * without branches (+INF for a y not Alive, results by bit masks): the
 * same rows, 1.5-1.75x slower (7.8 evaluations instead of 2.5); only the
 * Eq. 5 test and the min without branches: -1.1 mispredictions a vertex
 * but +3-6 % time (the offer then waits on the square root's chain). The
 * spokes, T, labels and heap on 2 MB pages (madvise; AnonHugePages 66 MB):
 * sine 316 and igea within 1 %, sine 1000 (1M) -3 %.
 * Kept (session 18): around a closed fan the first face's p (alone in the
 * first spoke) is the last face's q (alone in the last): one spoke, the
 * face walk deferring that p to the fan's end likewise. 7.95 -> 6.96
 * spokes per vertex on sine 316 (445 -> 394 B), 7.87 -> 6.87 camelhead;
 * bench_solve ratio, two alternating rounds: camelhead 1.74-1.83 ->
 * 1.64-1.67, sine 316 1.53 -> 1.43-1.46, igea 1.36-1.38 -> 1.35-1.38; all
 * pairs (float64, serial, both starts) on two icospheres, hand, beetle,
 * spot and camelhead equal to the previous core's bit for bit. This run:
 * spokes / face walk hand 0.76x, spot 0.79x, camelhead 0.79x, nefertiti
 * 0.75x, sine 500 0.63x.
 * Session 19: each triangle's c^2, beta, alpha_A, alpha_B stored in the
 * spoke (120 bytes, no division or square root but the one on T; the same
 * rows bit for bit): 1.05-1.12x slower (camelhead, sine 316, igea; a copy
 * of the loop, min of 7), as session 16's 88 bytes were. Kept: Eq. 5's
 * bounds on u read before the root (local_update.h). Per settled vertex
 * (camelhead, sine 316, igea) 2.44, 2.48, 2.19 triangles are evaluated and
 * Eq. 5 rejects 1.43, 1.47, 1.19 of them: the bounds reject those same
 * ones (no other), before the division and both square roots, so that
 * their branch no longer waits on the root. Probe 0.91-0.95x of the spoke
 * march; bench_solve, two rounds against the tree before: camelhead ratio
 * 1.63-1.64 -> 1.49-1.50 (updates 1.35 -> 1.24), sine 316 1.43-1.46 ->
 * 1.34-1.38, igea 1.35-1.36 -> 1.25-1.26; sine 1000 (1M) 107-109 ms with
 * either tree (memory-bound); all pairs camelhead 2000 rows, 1 core,
 * 2.56-2.57 -> 2.35-2.38 s. Not kept: with the bounds first, every
 * triangle's y read without a branch (T(y), or +inf where y is not Alive,
 * by bit masks) so that one branch decides: 1.21-1.26x slower.
 *
 *   bench_spokes [--repeats R] [--sources S] MESH... */
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
    if (mfmm_mesh_spokes_of(mesh, &sp.spoke_offset, &sp.spokes) != MFMM_OK) {
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
