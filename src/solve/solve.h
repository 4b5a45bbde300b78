/* Internal helpers around one march, shared by the solver and the matrix
 * backends (private to the library). */
#ifndef MFMM_SOLVE_H
#define MFMM_SOLVE_H

#include "mesh/check.h"
#include "mesh/mesh.h"
#include "exact/exact.h"

/* mfmm_solve without the checks, for callers that checked the arguments
 * once for many solves (the matrix backends). options must not be NULL.
 * Returns the number of vertices settled, -1 when out of memory (the exact
 * start's workspace). */
int32_t mfmm_solve_checked(mfmm_solver *solver, const mfmm_source *sources, int32_t n_sources,
                           const mfmm_solve_options *options, double *distances);

/* A checked solve that costs in proportion to the vertices it reaches: T
 * stays in the solver's own (nv,) array, +inf except at the n_touched
 * vertices of `touched` (every vertex the march took off Far; settled ones
 * hold their T, the others +inf). Valid until the solver's next solve.
 * Returns the number of vertices settled, -1 when out of memory. */
int32_t mfmm_solve_local(mfmm_solver *solver, const mfmm_source *sources, int32_t n_sources,
                         const mfmm_solve_options *options, const double **T,
                         const int32_t **touched, int32_t *n_touched);

/* MFMM_ERR_BAD_ARGUMENT (with err's message) unless `method` is an
 * mfmm_method that can take the cost given (has_cost). */
mfmm_status mfmm_check_method(int method, int has_cost, mfmm_error *err);

/* Tells a solver how many solves a job will ask of it on this mesh: with
 * MFMM_SPOKES_AFTER or more, the first builds the march's spokes
 * (mesh/spokes.h) instead of waiting for the marches to pay for them. */
void mfmm_solver_expect_rows(mfmm_solver *solver, int64_t n_rows);

/* The mesh a solver was made for. */
const mfmm_mesh *mfmm_solver_mesh(const mfmm_solver *solver);

/* The vertices of the last solve's exact start that the march computed
 * instead (mfmm_solve_info.start_fallbacks). */
int64_t mfmm_solver_start_fallbacks(const mfmm_solver *solver);

/* For many solves with one cost array that does not change: computes the
 * virtual stencils' 'cost around each vertex' (march.h) once, instead of
 * per solve. NULL cost: forget it. */
void mfmm_solver_fix_cost(mfmm_solver *solver, const double *cost, int cost_location);

/* mfmm_solve after its checks: maps the sources, targets and a per-vertex
 * cost (input vertex ids) to internal order, marches, and writes
 * distances in input order. options must not be NULL. */
mfmm_status mfmm_solve_mapped(mfmm_solver *solver, const mfmm_source *sources, int32_t n_sources,
                              const mfmm_solve_options *options, double *distances,
                              mfmm_error *err);

#endif
