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

/* mfmm_solve without the checks, for callers that checked the arguments
 * once for many solves (the matrix backends). options must not be NULL. */
void mfmm_solve_checked(mfmm_solver *solver, const mfmm_source *sources, int32_t n_sources,
                        const mfmm_solve_options *options, double *distances);

#endif
