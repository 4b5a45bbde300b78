/* Two windows in place per half-edge (src/exact/slots.c) against the
 * default solve (mfmm_solve, default options) and the exact solver
 * (mfmm_solve_exact, the reference). Per mesh and method: mean relative
 * error (%), max error (% of the bounding-box diagonal), the least
 * (d - exact) / exact and the count of non-finite values where the exact one
 * is finite (the lower-bound check), windows crossed per settled vertex,
 * late offers per vertex, and time per source over the default's (R
 * interleaved rounds, the least round). First, the flat checks: on a
 * triangulated square (gen grid 24) and an obtuse lattice (stretch 3) the
 * slots' distances against the Euclidean ones.
 *
 *   bench_slots [--repeats R] [--sources S] [--k K] [--flat] [MESH...]
 *
 * --flat: the flat checks only (also Delaunay triangulations of random
 * points in a square and a disc, stretched 1, 8 and 30 times in x).
 * --k: windows per half-edge (default 2).
 * MESH: a mesh file or gen:icosphere5 / gen:sine100; default the five real
 * meshes of docs/virtual-sources.md (branch wincap) and gen:icosphere5. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "exact/slots.h"
#include "io/generate.h"
#include "mesh/mesh.h"
#include "mesh/order.h"
#include "meshfmm.h"

#define NMETH 3 /* default, exact, the window method */
static int slot_k = 2;

static void slots_row(mfmm_slots *sl, const mfmm_mesh *mesh, int32_t v, double *tmp, double *d)
{
    mfmm_slots_solve(sl, mfmm_vertex_in(mesh, v), tmp);
    for (int32_t i = 0; i < mesh->nv; i++)
        d[mfmm_vertex_out(mesh, i)] = tmp[i];
}

static void flat_check(const char *name, mfmm_gen_mesh g)
{
    mfmm_mesh *mesh = NULL;
    mfmm_slots *sl = NULL;
    mfmm_error err;
    if (mfmm_mesh_create(g.V, g.nv, g.F, g.nf, NULL, &mesh, &err) != MFMM_OK ||
        mfmm_slots_create(mesh, &sl) != MFMM_OK || !mfmm_slots_set_k(sl, slot_k)) {
        fprintf(stderr, "%s: cannot build\n", name);
        exit(1);
    }
    double *tmp = malloc(g.nv * sizeof *tmp), *d = malloc(g.nv * sizeof *d);
    double *ed = malloc(g.nv * sizeof *ed);
    mfmm_exact_solver *ex = NULL;
    mfmm_exact_solver_create(mesh, &ex);
    {
        /* whether the region is convex here: the exact solver's distances
         * against the Euclidean ones */
        double worst = 0.0;
        int32_t srcs[3] = {0, g.nv / 2, g.nv - 1 - g.nv / 7};
        for (int q = 0; q < 3; q++) {
            mfmm_source s0 = {srcs[q], -1, {0, 0, 0}, 0.0};
            mfmm_solve_exact(ex, &s0, 1, NULL, ed, NULL, NULL);
            for (int32_t v = 0; v < g.nv; v++) {
                double e = hypot(g.V[3 * v] - g.V[3 * srcs[q]], g.V[3 * v + 1] - g.V[3 * srcs[q] + 1]);
                worst = fmax(worst, fabs(ed[v] - e));
            }
        }
        printf("flat %s exact solver: max |exact - euclid| %.3e\n", name, worst);
    }
    {
        double worst = 0.0;
        int nbad = 0;
        int32_t srcs[3] = {0, g.nv / 2, g.nv - 1 - g.nv / 7};
        double worst_ex = 0.0;
        for (int q = 0; q < 3; q++) {
            int32_t s = srcs[q];
            slots_row(sl, mesh, s, tmp, d);
            mfmm_source s0 = {s, -1, {0, 0, 0}, 0.0};
            mfmm_solve_exact(ex, &s0, 1, NULL, ed, NULL, NULL);
            for (int32_t v = 0; v < g.nv; v++)
                worst_ex = fmax(worst_ex, fabs(d[v] - ed[v]));
            for (int32_t v = 0; v < g.nv; v++) {
                double e = hypot(g.V[3 * v] - g.V[3 * s], g.V[3 * v + 1] - g.V[3 * s + 1]);
                double a = fabs(d[v] - e);
                if (a > worst)
                    worst = a;
                nbad += !(a <= 1e-12);
            }
        }
        printf("flat %s windows: max |d - euclid| %.3e over 3 sources, %d vertex values off by "
               "> 1e-12; max |d - exact| %.3e\n",
               name, worst, nbad, worst_ex);
    }
    free(tmp);
    free(d);
    free(ed);
    mfmm_exact_solver_destroy(ex);
    mfmm_slots_destroy(sl);
    mfmm_mesh_destroy(mesh);
}

static void bench_mesh(const char *name, const double *V, int32_t nv, const int32_t *F,
                       int32_t nf, int repeats, int ns)
{
    mfmm_mesh *mesh = NULL;
    mfmm_solver *solver = NULL;
    mfmm_exact_solver *ex = NULL;
    mfmm_slots *sl = NULL;
    mfmm_error err;
    if (mfmm_mesh_create(V, nv, F, nf, NULL, &mesh, &err) != MFMM_OK ||
        mfmm_solver_create(mesh, &solver) != MFMM_OK ||
        mfmm_exact_solver_create(mesh, &ex) != MFMM_OK || mfmm_slots_create(mesh, &sl) != MFMM_OK ||
        !mfmm_slots_set_k(sl, slot_k)) {
        fprintf(stderr, "%s: cannot build\n", name);
        exit(1);
    }
    unsigned char *ref = calloc((size_t)nv, 1);
    for (size_t i = 0; i < 3 * (size_t)nf; i++)
        ref[F[i]] = 1;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t v = 0; v < nv; v++)
        for (int k = 0; ref[v] && k < 3; k++) {
            lo[k] = fmin(lo[k], V[3 * (size_t)v + k]);
            hi[k] = fmax(hi[k], V[3 * (size_t)v + k]);
        }
    double diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                       (hi[2] - lo[2]) * (hi[2] - lo[2]));
    static const double frac[5] = {0.03, 0.18, 0.50, 0.67, 0.85};
    int32_t src[16];
    if (ns > 16)
        ns = 16;
    for (int i = 0; i < ns; i++) {
        int32_t v = (int32_t)(frac[i % 5] * nv) + i / 5;
        while (v < nv - 1 && !ref[v])
            v++;
        src[i] = v;
    }
    double *rows = malloc((size_t)NMETH * ns * nv * sizeof *rows);
    double *tmp = malloc((size_t)nv * sizeof *tmp);
    double t[NMETH];
    mfmm_slots_info inf[NMETH];
    memset(inf, 0, sizeof inf);
    for (int m = 0; m < NMETH; m++)
        t[m] = INFINITY;
    /* warm: the tables */
    {
        mfmm_source s0 = {src[0], -1, {0, 0, 0}, 0.0};
        mfmm_solve(solver, &s0, 1, NULL, rows, NULL);
        slots_row(sl, mesh, src[0], tmp, rows);
    }
    for (int r = 0; r < repeats; r++)
        for (int m = 0; m < NMETH; m++) {
            if (m == 1 && r > 0)
                continue; /* the exact rows once (not timed against) */
            mfmm_slots_info acc;
            memset(&acc, 0, sizeof acc);
            double t0 = now();
            for (int i = 0; i < ns; i++) {
                double *d = rows + ((size_t)m * ns + i) * nv;
                mfmm_source s0 = {src[i], -1, {0, 0, 0}, 0.0};
                if (m == 0)
                    mfmm_solve(solver, &s0, 1, NULL, d, NULL);
                else if (m == 1)
                    mfmm_solve_exact(ex, &s0, 1, NULL, d, NULL, NULL);
                else {
                    slots_row(sl, mesh, src[i], tmp, d);
                    mfmm_slots_info q;
                    mfmm_slots_get_info(sl, &q);
                    acc.crossed += q.crossed;
                    acc.emitted += q.emitted;
                    acc.kept += q.kept;
                    acc.late += q.late;
                    acc.late_vertex += q.late_vertex;
                    acc.settled += q.settled;
                    acc.trimmed += q.trimmed;
                    acc.evicted += q.evicted;
                    acc.merged += q.merged;
                }
            }
            double dt = now() - t0;
            if (dt < t[m])
                t[m] = dt;
            inf[m] = acc;
        }
    const double *E = rows + (size_t)ns * nv;
    printf("\n%s: nv %d, sources", name, (int)nv);
    for (int i = 0; i < ns; i++)
        printf(" %d", (int)src[i]);
    printf("; default %.3f ms/source, exact %.3f ms/source\n", 1e3 * t[0] / ns, 1e3 * t[1] / ns);
    printf("%-8s %9s %10s %11s %6s %8s %8s %8s %8s %8s %8s %7s %9s\n", "method", "mean %",
           "max %diag", "min rel", "nonfin", "cross/v", "offer/v", "trim/v", "full/v", "kept/v",
           "late/v", "ns/v", "t/default");
    for (int m = 0; m < NMETH; m++) {
        if (m == 1)
            continue;
        const double *D = rows + (size_t)m * ns * nv;
        double mean = 0.0, maxe = 0.0, minrel = INFINITY;
        long long nonfin = 0;
        for (int i = 0; i < ns; i++) {
            double sum = 0.0;
            long long n = 0;
            for (int32_t v = 0; v < nv; v++) {
                double e = E[(size_t)i * nv + v], d = D[(size_t)i * nv + v];
                if (!isfinite(e))
                    continue;
                if (!isfinite(d)) {
                    nonfin++;
                    continue;
                }
                double a = fabs(d - e);
                maxe = fmax(maxe, a);
                if (e > 0.0) {
                    sum += a / e;
                    n++;
                    minrel = fmin(minrel, (d - e) / e);
                }
            }
            mean += n ? sum / (double)n : 0.0;
        }
        double sv = inf[m].settled ? (double)inf[m].settled : 1.0;
        char label[16];
        if (m == 0)
            snprintf(label, sizeof label, "default");
        else
            snprintf(label, sizeof label, "windows");
        printf("%-8s %9.4f %10.4f %11.3e %6lld %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %7.0f %9.2f\n",
               label, 100.0 * mean / ns, 100.0 * maxe / diag, minrel, nonfin,
               inf[m].crossed / sv, inf[m].emitted / sv, inf[m].trimmed / sv,
               inf[m].evicted / sv, inf[m].kept / sv, inf[m].late / sv,
               1e9 * t[m] / (ns * (double)nv), t[m] / t[0]);
    }
    fflush(stdout);
    free(rows);
    free(tmp);
    free(ref);
    mfmm_slots_destroy(sl);
    mfmm_exact_solver_destroy(ex);
    mfmm_solver_destroy(solver);
    mfmm_mesh_destroy(mesh);
}

int main(int argc, char **argv)
{
    int repeats = 5, ns = 5, np = 0, flat_only = 0;
    const char *paths[64];
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--repeats") && i + 1 < argc)
            repeats = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--sources") && i + 1 < argc)
            ns = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--flat"))
            flat_only = 1;
        else if (!strcmp(argv[i], "--k") && i + 1 < argc)
            slot_k = atoi(argv[++i]);
        else if (np < 64)
            paths[np++] = argv[i];
    }
    if (np == 0) {
        static const char *const dflt[] = {
            "tests/data/meshes/hand_lowres.obj", "tests/data/meshes/spot.obj",
            "tests/data/meshes/camelhead.off", "tests/data/meshes/nefertiti-lowres.obj",
            "tests/data/meshes/stanford-bunny.obj", "gen:icosphere5"};
        for (int i = 0; i < 6; i++)
            paths[np++] = dflt[i];
    }
    mfmm_gen_mesh g = mfmm_gen_grid(24);
    flat_check("grid24", g);
    mfmm_gen_free(&g);
    g = mfmm_gen_lattice(20, 3.0);
    flat_check("lattice20x3", g);
    mfmm_gen_free(&g);
    {
        /* convex regions: Delaunay triangulations of random points in a
         * square and a disc, stretched to needles and obtuse corners */
        static const double stretch[3] = {1.0, 8.0, 30.0};
        for (int disc = 0; disc < 2; disc++)
            for (int si = 0; si < 3; si++)
                for (int seed = 1; seed <= 2; seed++) {
                    char nm[64];
                    snprintf(nm, sizeof nm, "delaunay-%s-x%g-s%d", disc ? "disc" : "square",
                             stretch[si], seed);
                    g = mfmm_gen_delaunay(300, disc, stretch[si], (uint64_t)seed);
                    flat_check(nm, g);
                    mfmm_gen_free(&g);
                }
    }
    if (flat_only)
        return 0;
    for (int i = 0; i < np; i++) {
        if (!strncmp(paths[i], "gen:", 4)) {
            mfmm_gen_mesh q = {0};
            if (!strcmp(paths[i], "gen:icosphere5"))
                q = mfmm_gen_icosphere(5);
            else if (!strcmp(paths[i], "gen:sine100"))
                q = mfmm_gen_sine(100);
            if (!q.nv)
                continue;
            bench_mesh(paths[i] + 4, q.V, q.nv, q.F, q.nf, repeats, ns);
            mfmm_gen_free(&q);
            continue;
        }
        double *V = NULL;
        int32_t *F = NULL, nv = 0, nf = 0;
        mfmm_error err;
        if (mfmm_load_mesh(paths[i], &V, &nv, &F, &nf, &err) != MFMM_OK) {
            fprintf(stderr, "%s: %s\n", paths[i], err.message);
            continue;
        }
        const char *base = strrchr(paths[i], '/');
        bench_mesh(base ? base + 1 : paths[i], V, nv, F, nf, repeats, ns);
        mfmm_free(V);
        mfmm_free(F);
    }
    return 0;
}
