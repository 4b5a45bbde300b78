/* Internal helpers around one march, shared by the solver and the matrix
 * backends (private to the library). */
#ifndef MFMM_SOLVE_H
#define MFMM_SOLVE_H

#include "mesh.h"

/* Checks a cost array (NULL is fine): every entry finite and > 0. */
mfmm_status mfmm_check_cost(const mfmm_mesh *mesh, const double *cost,
                            mfmm_cost_location where, mfmm_error *err);

/* Checks source i: ids in range, face not degenerate, barycentric valid. */
mfmm_status mfmm_check_source(const mfmm_mesh *mesh, const mfmm_source *src, int32_t i,
                              mfmm_error *err);

/* Seeds a checked source into a reset march state (cost fields set). */
void mfmm_seed_source(const mfmm_mesh *mesh, mfmm_march_state *st, const mfmm_source *src);

/* The mesh a solver was made for. */
const mfmm_mesh *mfmm_solver_mesh(const mfmm_solver *solver);

#endif
