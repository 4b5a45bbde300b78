/* One serial solve, timed: median of repeats on a built mesh, in vertices per
 * second, against its ceiling: a plain Dijkstra over the march's own edge
 * graph (every vertex's update list, each neighbour once, edge lengths
 * precomputed), with the same 8-ary heap, vertex order and per-solve reset.
 * ratio = march time / Dijkstra time. With unfolding (the march over
 * spokes) it also times the spoke walk with its edge updates alone, which
 * splits the ratio in two: the spoke records against the graph's edges
 * (records = edges-only walk / Dijkstra) and the triangles' updates
 * (updates = march / edges-only walk). It also prints the built mesh's
 * bytes per vertex, each array's share.
 *
 *   bench_solve [--repeats R] [--sources S] [--exact-start R] [MESH...]
 *
 * The march starts plain (the paper's start) unless --exact-start R > 0.
 * Each repeat runs every source in turn, as the rows of a job alternate (one
 * source repeated back to back runs small meshes faster than any job sees
 * them). With no MESH, the larger meshes of tests/data/meshes and generated
 * spheres. bench/micro/ab_solve.py compares two builds of it in alternating
 * rounds. Findings: docs/march-measurements.md. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_util.h"
#include "meshfmm.h"
#include "mesh/mesh.h"
#include "mesh/spokes.h"
#include "io/generate.h"

/* The march's edge graph as CSR with lengths, in the mesh's internal order. */
typedef struct graph {
    int32_t nv;
    int32_t *off, *nbr;
    double *len;
} graph;

static int graph_build(const mfmm_mesh *m, graph *g)
{
    int32_t nv = m->nv;
    /* at most: 2 per face corner, 1 per virtual edge */
    size_t cap = 2 * (size_t)m->vertex_face_offset[nv] + (size_t)m->n_virts + 1;
    g->nv = nv;
    g->off = malloc(((size_t)nv + 1) * sizeof *g->off);
    g->nbr = malloc(cap * sizeof *g->nbr);
    g->len = malloc(cap * sizeof *g->len);
    if (!g->off || !g->nbr || !g->len)
        return 0;
    int32_t k = 0;
    for (int32_t x = 0; x < nv; x++) {
        g->off[x] = k;
        /* x's face neighbours and the corners whose virtual edge ends at x */
        int32_t nw = m->vertex_face_offset[x + 1] - m->vertex_face_offset[x];
        for (int32_t j = 0; j < 2 * nw + m->virt_first[x + 1] - m->virt_first[x]; j++) {
            int32_t c, dup = 0;
            if (j < 2 * nw) {
                int32_t w = m->vertex_wedge[m->vertex_face_offset[x] + j / 2];
                c = m->face_records[MFMM_WEDGE_FACE(w)].v[j % 2 ? MFMM_WEDGE_PREV(w) : MFMM_WEDGE_NEXT(w)];
            } else {
                c = m->virts[m->virt_first[x] + j - 2 * nw].c;
            }
            for (int32_t i = g->off[x]; i < k && !dup; i++)
                dup = g->nbr[i] == c;
            if (dup || c == x)
                continue;
            const double *a = m->xyz + 3 * (size_t)x, *b = m->xyz + 3 * (size_t)c;
            g->nbr[k] = c;
            g->len[k++] = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                               (a[2] - b[2]) * (a[2] - b[2]));
        }
    }
    g->off[nv] = k;
    return 1;
}

/* Dijkstra from v (internal order) over graph g_ with march.h's heap and
 * reset; returns vertices settled. The workspace and graph are read through
 * local copies, as the march reads its own (march.h, mfmm_march_loop): a
 * label store may alias anything, and through pointers every field would
 * be reloaded after it (measured: 8 % slower, sine 316), so the ceiling
 * does not depend on where it is inlined. */
static int32_t dijkstra(const void *g_, mfmm_march_state *s, int32_t v)
{
    graph g = *(const graph *)g_;
    mfmm_march_reset(s, g.nv);
    mfmm_march_seed(s, v, 0.0);
    mfmm_march_state w = *s;
    int32_t settled = 0;
    while (w.heap_size > 0) {
        int32_t x = mfmm_heap_pop(&w);
        w.label[x] = MFMM_ALIVE;
        settled++;
        double tx = w.T[x];
        for (int32_t i = g.off[x]; i < g.off[x + 1]; i++) {
            int32_t c = g.nbr[i];
            uint8_t st = w.label[c];
            if (st == MFMM_ALIVE)
                continue;
            double t = tx + g.len[i];
            if (t < w.T[c]) {
                w.T[c] = t;
                mfmm_heap_push_or_decrease(&w, c, t, st == MFMM_CLOSE);
                w.label[c] = MFMM_CLOSE;
            }
        }
    }
    for (int32_t u = 0; u < g.nv; u++) /* the march's closing pass, for a like count */
        if (w.label[u] != MFMM_ALIVE)
            w.T[u] = MFMM_INF;
    return settled;
}

/* The march over spokes with the edge updates alone, T(x) + |xc| (the
 * rows are Dijkstra's over the spokes' edges, not the march's: a split of
 * the march's time, not a solver): the march's reads of its spoke records,
 * heap and labels without the triangles. Returns vertices settled. */
static int32_t spoke_edges(const void *m_, mfmm_march_state *s, int32_t v)
{
    const mfmm_march_mesh *m = m_;
    mfmm_march_reset(s, m->nv);
    mfmm_march_seed(s, v, 0.0);
    /* local copies, as the march reads them (march.h, mfmm_march_loop) */
    mfmm_march_state w = *s;
    mfmm_march_mesh mm = *m;
    int32_t settled = 0;
    while (w.heap_size > 0) {
        int32_t x = mfmm_march_settle(&w, &settled, 0);
        if (w.heap_size > 0) {
            const char *b = (const char *)(mm.spokes + mm.spoke_offset[w.heap_vertex[0]]);
            const char *e = (const char *)(mm.spokes + mm.spoke_offset[w.heap_vertex[0] + 1]);
            for (; b < e; b += 64)
                MFMM_PREFETCH(b);
        }
        double tx = w.T[x];
        for (int32_t j = mm.spoke_offset[x]; j < mm.spoke_offset[x + 1]; j++) {
            const mfmm_spoke *r = mm.spokes + j;
            uint8_t lc = w.label[r->c];
            if ((lc & MFMM_STATE_MASK) != MFMM_ALIVE)
                mfmm_march_offer_to(&w, &mm, r->c, lc, tx + r->len, 1);
        }
    }
    for (int32_t u = 0; u < m->nv; u++) /* the march's closing pass, for a like count */
        if (w.label[u] != MFMM_ALIVE)
            w.T[u] = MFMM_INF;
    return settled;
}

/* A timed run from vertex v (internal order) on workspace s; ctx: its data. */
typedef int32_t timed_run(const void *ctx, mfmm_march_state *s, int32_t v);

/* Median time of run over the sources (the march's, in the mesh's internal
 * order) and repeats, on a workspace of its own; *min_out its least. */
static double time_runs(const mfmm_mesh *mesh, int repeats, int n_sources, timed_run *run,
                        const void *ctx, double *times, double *min_out)
{
    mfmm_march_state s;
    double med = NAN;
    if (bench_state_alloc(&s, (size_t)mesh->nv)) {
        int k = 0;
        for (int r = 0; r < repeats; r++)
            for (int q = 0; q < n_sources; q++) {
                int32_t v = mesh->to_internal[((int64_t)mesh->nv * (2 * q + 1)) / (2 * n_sources)];
                double t1 = now();
                run(ctx, &s, v);
                times[k++] = now() - t1;
            }
        qsort(times, (size_t)k, sizeof *times, cmp_double);
        med = times[k / 2];
        *min_out = times[0];
    }
    bench_state_free(&s);
    return med;
}

/* spoke_edges' time (NAN without spokes) */
static double spoke_edges_time(const mfmm_mesh *mesh, int repeats, int n_sources, double *times,
                               double *min_out)
{
    mfmm_march_mesh m = mfmm_mesh_march_view(mesh);
    if (mfmm_mesh_spokes_of(mesh, 1, &m.spoke_offset, &m.spokes) != MFMM_OK || !m.spokes)
        return NAN;
    return time_runs(mesh, repeats, n_sources, spoke_edges, &m, times, min_out);
}

/* the Dijkstra ceiling's time */
static double ceiling_time(const mfmm_mesh *mesh, int repeats, int n_sources, double *times,
                           double *min_out)
{
    graph g = {0, NULL, NULL, NULL};
    double med = NAN;
    if (graph_build(mesh, &g))
        med = time_runs(mesh, repeats, n_sources, dijkstra, &g, times, min_out);
    free(g.off);
    free(g.nbr);
    free(g.len);
    return med;
}

static double exact_start = 0.0; /* --exact-start R */

static void bench(const char *name, const double *V, int32_t nv, const int32_t *F, int32_t nf,
                  int repeats, int n_sources)
{
    mfmm_mesh *mesh = NULL;
    mfmm_error err;
    double t0 = now();
    if (mfmm_mesh_create(V, nv, F, nf, NULL, &mesh, &err) != MFMM_OK) {
        fprintf(stderr, "%s: %s\n", name, err.message);
        return;
    }
    double t_build = now() - t0;
    /* bytes per vertex of the built mesh, each array's share */
    const char *names[32];
    size_t bytes[32], total = 0;
    int n_arrays = mfmm_mesh_memory(mesh, names, bytes, 32);
    for (int i = 0; i < n_arrays && i < 32; i++)
        total += bytes[i];
    printf("%-22s nv=%7d mesh %.1f bytes/vertex:", name, nv, (double)total / nv);
    for (int i = 0; i < n_arrays && i < 32; i++)
        printf(" %s %.1f%s", names[i], (double)bytes[i] / nv, i + 1 < n_arrays ? "," : "\n");
    mfmm_solver *solver = NULL;
    double *d = malloc((size_t)nv * sizeof *d);
    double *times = malloc((size_t)repeats * n_sources * sizeof *times);
    if (mfmm_solver_create(mesh, &solver) != MFMM_OK || !d || !times) {
        fprintf(stderr, "out of memory\n");
        exit(1);
    }
    for (int unfolding = 1; unfolding >= 0; unfolding--) {
        mfmm_solve_options opt;
        mfmm_solve_options_init(&opt);
        opt.unfolding = unfolding;
        opt.exact_start_radius = exact_start; /* 0: the march alone, as the ceiling */
        int k = 0;
        int32_t settled = 0;
        for (int r = 0; r < repeats; r++)
            for (int s = 0; s < n_sources; s++) {
                int32_t v = (int32_t)(((int64_t)nv * (2 * s + 1)) / (2 * n_sources));
                mfmm_source src = {v, -1, {0, 0, 0}, 0.0};
                double t1 = now();
                mfmm_solve(solver, &src, 1, &opt, d, NULL);
                times[k++] = now() - t1;
            }
        for (int32_t i = 0; i < nv; i++)
            settled += isfinite(d[i]) != 0;
        qsort(times, (size_t)k, sizeof *times, cmp_double);
        double med = times[k / 2];
        double min = times[0], ceil_min = NAN;
        double ceil_med = ceiling_time(mesh, repeats, n_sources, times, &ceil_min);
        /* min: the least disturbed run on a shared machine */
        printf("%-22s nv=%7d build=%7.1f ms  unfolding=%d  solve median=%8.3f ms  %6.2f M vertices/s"
               "  Dijkstra ceiling %8.3f ms  ratio %.2f  (min %8.3f / %8.3f ms, ratio %.2f)\n",
               name, nv, 1e3 * t_build, unfolding, 1e3 * med, settled / med / 1e6,
               1e3 * ceil_med, med / ceil_med, 1e3 * min, 1e3 * ceil_min, min / ceil_min);
        if (unfolding) {
            double edges_min = NAN;
            double edges_med = spoke_edges_time(mesh, repeats, n_sources, times, &edges_min);
            printf("%-22s nv=%7d   spokes, edge updates alone: median %8.3f ms  records %.2f  updates %.2f"
                   "  (min %8.3f ms: records %.2f, updates %.2f)\n",
                   name, nv, 1e3 * edges_med, edges_med / ceil_med, med / edges_med, 1e3 * edges_min,
                   edges_min / ceil_min, min / edges_min);
        }
    }
    free(d);
    free(times);
    mfmm_solver_destroy(solver);
    mfmm_mesh_destroy(mesh);
}

int main(int argc, char **argv)
{
    int repeats = 5, n_sources = 3, first = 1;
    while (first < argc && argv[first][0] == '-') {
        if (!strcmp(argv[first], "--repeats") && first + 1 < argc)
            repeats = atoi(argv[first + 1]);
        else if (!strcmp(argv[first], "--sources") && first + 1 < argc)
            n_sources = atoi(argv[first + 1]);
        else if (!strcmp(argv[first], "--exact-start") && first + 1 < argc)
            exact_start = atof(argv[first + 1]);
        else {
            fprintf(stderr, "usage: bench_solve [--repeats R] [--sources S] [--exact-start R] [MESH...]\n");
            return 2;
        }
        first += 2;
    }
    if (repeats < 1 || n_sources < 1) {
        fprintf(stderr, "repeats and sources must be >= 1\n");
        return 2;
    }
    static const char *defaults[] = {"tests/data/meshes/camelhead.off",
                                     "tests/data/meshes/nefertiti-lowres.obj",
                                     "tests/data/meshes/stanford-bunny.obj",
                                     "tests/data/meshes/igea.ply"};
    const char **paths = (const char **)(argv + first);
    int n_paths = argc - first;
    if (n_paths == 0) {
        paths = defaults;
        n_paths = 4;
        for (int level = 4; level <= 7; level += 1) {
            mfmm_gen_mesh g = mfmm_gen_icosphere(level);
            char name[32];
            snprintf(name, sizeof name, "icosphere-%d", level);
            bench(name, g.V, g.nv, g.F, g.nf, repeats, n_sources);
            mfmm_gen_free(&g);
        }
    }
    bench_mesh_files(paths, n_paths, bench, repeats, n_sources);
    return 0;
}
