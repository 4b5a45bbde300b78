/* The first solve on a fresh mesh against later ones: what a program that
 * asks one distance field pays for the tables the library builds on first
 * use (the exact start's, the march's spokes). Default options, vertex
 * sources spread over the mesh, each solve timed alone. Prints the mesh
 * build, the first, second and the median of the later solves, and the
 * mesh's bytes per vertex after the first and after the last solve, array
 * by array (mfmm_mesh_memory). The march's spokes are built by the solve
 * after MFMM_SPOKES_AFTER full marches (mesh/spokes.h): printed as the
 * slowest later solve; "steady" is the median of the last five.
 *
 *   bench_first_solve [--later K] [--sine N | MESH]
 *
 * --sine N: the paper's sine surface, N x N squares (default 1000: about a
 * million vertices); K later solves (default 16). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "io/generate.h"
#include "meshfmm.h"

static void print_memory(const mfmm_mesh *mesh, int32_t nv, const char *when)
{
    const char *names[32];
    size_t bytes[32];
    int n = mfmm_mesh_memory(mesh, names, bytes, 32);
    size_t total = 0;
    for (int i = 0; i < n && i < 32; i++)
        total += bytes[i];
    printf("memory %-12s %6.1f B/vertex:", when, (double)total / nv);
    for (int i = 0; i < n && i < 32; i++)
        if (bytes[i] >= (size_t)nv)
            printf(" %s %.0f;", names[i], (double)bytes[i] / nv);
    printf("\n");
}

int main(int argc, char **argv)
{
    int later = 16, sine = 1000;
    const char *path = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--later") && i + 1 < argc)
            later = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--sine") && i + 1 < argc)
            sine = atoi(argv[++i]);
        else
            path = argv[i];
    }
    if (later < 5)
        later = 5;
    mfmm_gen_mesh g = {0};
    double *V = NULL;
    int32_t *F = NULL, nv = 0, nf = 0;
    mfmm_error err;
    if (path) {
        if (mfmm_load_mesh(path, &V, &nv, &F, &nf, &err) != MFMM_OK) {
            fprintf(stderr, "%s: %s\n", path, err.message);
            return 1;
        }
    } else {
        g = mfmm_gen_sine(sine);
        V = g.V, F = g.F, nv = g.nv, nf = g.nf;
    }
    double t0 = now();
    mfmm_mesh *mesh = NULL;
    if (nv <= 0 || mfmm_mesh_create(V, nv, F, nf, NULL, &mesh, &err) != MFMM_OK) {
        fprintf(stderr, "cannot build the mesh\n");
        return 1;
    }
    double t_build = now() - t0;
    double *d = malloc((size_t)nv * sizeof *d), *t = malloc(((size_t)later + 2) * sizeof *t);
    if (!d || !t)
        return 1;
    t0 = now();
    mfmm_solver *solver = NULL;
    if (mfmm_solver_create(mesh, &solver) != MFMM_OK)
        return 1;
    printf("%s: %d vertices, mesh built in %.3f s, solver in %.4f s\n", path ? path : "sine",
           (int)nv, t_build, now() - t0);
    for (int k = 0; k < later + 2; k++) {
        /* sources spread over the mesh, none twice */
        mfmm_source s = {(int32_t)(((int64_t)k * 7919 + 13) % nv), -1, {0, 0, 0}, 0.0};
        t0 = now();
        if (mfmm_solve(solver, &s, 1, NULL, d, &err) != MFMM_OK) {
            fprintf(stderr, "solve: %s\n", err.message);
            return 1;
        }
        t[k] = now() - t0;
        if (k == 0)
            print_memory(mesh, nv, "after first");
    }
    print_memory(mesh, nv, "after last");
    printf("solves (s):");
    for (int k = 0; k < later + 2; k++)
        printf(" %.4f", t[k]);
    double slowest = 0.0;
    for (int k = 2; k < later + 2; k++)
        slowest = t[k] > slowest ? t[k] : slowest;
    qsort(t + later - 3, 5, sizeof *t, cmp_double);
    double steady = t[later - 1];
    printf("\nfirst/steady %.2f  second/steady %.2f  slowest later/steady %.2f (steady %.4f s)\n",
           t[0] / steady, t[1] / steady, slowest / steady, steady);
    free(d);
    free(t);
    mfmm_solver_destroy(solver);
    mfmm_mesh_destroy(mesh);
    if (path) {
        mfmm_free(V);
        mfmm_free(F);
    } else {
        mfmm_gen_free(&g);
    }
    return 0;
}
