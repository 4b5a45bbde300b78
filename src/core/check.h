/* The checks of a solve's arguments, shared by the solvers above core
 * (src/solve, src/exact) and the matrix jobs (private to the library). */
#ifndef MFMM_CHECK_H
#define MFMM_CHECK_H

#include "mesh.h"

/* Checks a cost array (NULL is fine): every entry finite and > 0. */
mfmm_status mfmm_check_cost(const mfmm_mesh *mesh, const double *cost,
                            mfmm_cost_location where, mfmm_error *err);

/* Checks source i: ids in range, face not degenerate, barycentric valid. */
mfmm_status mfmm_check_source(const mfmm_mesh *mesh, const mfmm_source *src, int32_t i,
                              mfmm_error *err);

#endif
