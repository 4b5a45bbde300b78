/* The checks of a solve's arguments, shared by the rooms above the mesh
 * (src/solve, src/exact) and the matrix jobs (private to the library). */
#ifndef MFMM_CHECK_H
#define MFMM_CHECK_H

#include "mesh.h"

/* Checks a cost array (NULL is fine): every entry finite and > 0. */
mfmm_status mfmm_check_cost(const mfmm_mesh *mesh, const double *cost,
                            mfmm_cost_location where, mfmm_error *err);

/* An upper bound on every finite distance a solve can give from sources of
 * value 0 (the march's and the exact solver's values are at most those of
 * paths along edges): the sum of the edge lengths times the largest cost
 * (1 without one; cost checked). */
double mfmm_distance_bound(const mfmm_mesh *mesh, const double *cost, mfmm_cost_location where);

/* Checks source i: ids in range, face not degenerate, barycentric valid.
 * _internal: the same for ids in the mesh's internal order (mesh/order.h),
 * whose faces include the pieces of faces cut at T-junctions. */
mfmm_status mfmm_check_source(const mfmm_mesh *mesh, const mfmm_source *src, int32_t i,
                              mfmm_error *err);
mfmm_status mfmm_check_source_internal(const mfmm_mesh *mesh, const mfmm_source *src, int32_t i,
                                       mfmm_error *err);

/* For the march's virtual stencils under a cost (march.h): uniform[v] = the
 * cost every face around v has (per face), or that v and every neighbour
 * has (per vertex); -1 where they differ; 0 for vertices in no face.
 * cost_location 1 per vertex, 2 per face. */
void mfmm_uniform_cost(const mfmm_mesh *mesh, const double *cost, int cost_location,
                       double *uniform);

#endif
