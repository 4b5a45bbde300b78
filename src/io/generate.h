/* Meshes the project generates itself (internal; used by the command line,
 * the tests and the benchmarks): shapes whose distances are known. */
#ifndef MFMM_GENERATE_H
#define MFMM_GENERATE_H

#include <stdint.h>

/* Arrays allocated with malloc; mfmm_gen_free releases them. On allocation
 * failure nv = nf = 0 and both pointers are NULL. */
typedef struct mfmm_gen_mesh {
    int32_t nv, nf;
    double *V;  /* (nv,3) */
    int32_t *F; /* (nf,3) */
} mfmm_gen_mesh;

void mfmm_gen_free(mfmm_gen_mesh *m);

/* Unit square [0,1]^2 (z = 0), n x n squares each cut into two right
 * triangles along alternating diagonals: (n+1)^2 vertices. */
mfmm_gen_mesh mfmm_gen_grid(int n);

/* Triangular lattice of equilateral triangles, n rows of n cells, edge 1/n,
 * then x multiplied by `stretch` (stretch 3 gives 120-degree corners in nearly
 * every triangle). z = 0. */
mfmm_gen_mesh mfmm_gen_lattice(int n, double stretch);

/* Unit icosphere: the icosahedron subdivided `level` times, projected to the
 * sphere (10*4^level + 2 vertices). */
mfmm_gen_mesh mfmm_gen_icosphere(int level);

/* Torus, nu x nv quads split in two: tube centre radius R, tube radius r. */
mfmm_gen_mesh mfmm_gen_torus(int nu, int nv, double R, double r);

/* The paper's Fig. 8a surface z = 0.45 sin(2 pi x) sin(2 pi y) on [0,1]^2,
 * n x n squares: (n+1)^2 vertices. */
mfmm_gen_mesh mfmm_gen_sine(int n);

/* A Delaunay triangulation of n points (z = 0): random points in the unit
 * square [0,1]^2 with points along its sides (disc 0), or in a disc with
 * points on its rim r = 1 + cos(3 a) / 20 (disc 1), then x multiplied by `stretch`
 * (needles and obtuse corners). A convex region; the same seed gives the
 * same mesh. */
mfmm_gen_mesh mfmm_gen_delaunay(int n, int disc, double stretch, uint64_t seed);

#endif
