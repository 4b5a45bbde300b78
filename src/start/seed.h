/* The exact start of a march (private to the library): the
 * exact distances of the vertices near a point source seed the march in
 * place of the paper's start, which creates most of a first-order march's
 * error at the source's point singularity. Shared by the solver (solve.c)
 * and the OpenCL host (matrix/opencl/rows.c), which computes each row's
 * seeds and uploads them, so that every backend seeds alike. */
#ifndef MFMM_SOLVE_SEED_H
#define MFMM_SOLVE_SEED_H

#include "mesh/mesh.h"
#include "straight.h"
#include "exact/exact.h"
#include "patch.h"

/* Validates an exact_start_radius option (MFMM_EXACT_START_AUTO, or finite
 * and >= 0). */
mfmm_status mfmm_check_exact_start(double radius, mfmm_error *err);

/* Whether a checked exact_start_radius asks for the exact start. */
static inline int mfmm_exact_start_on(double radius)
{
    return radius != 0.0;
}

/* The radius in mean edge lengths that a checked exact_start_radius gives a
 * march with this max_distance (MFMM_EXACT_START_AUTO's rule, meshfmm.h). */
double mfmm_exact_start_edges(const mfmm_mesh *mesh, double radius, double max_distance);

/* The exact start of one checked source: the vertices within `radius` mean
 * edge lengths of it (at least its own faces' corners) and their exact
 * distances d; the march is seeded with value + F * d at each, in this
 * order. Applies only where the cost is one F over the patch: uniform (see
 * mfmm_uniform_cost, NULL when cost is NULL) equal at every patch vertex;
 * elsewhere, and for radius 0, *n is 0 and the caller takes the straight
 * start (start/straight.h). The patch ends at max_distance (T beyond it is
 * +inf in the row), so that a local row costs its reach and is exact where
 * it is finite within the radius. *ws is the exact workspace, made here on first use
 * (the caller frees it with mfmm_exact_ws_destroy).
 *   n, vertices, distances: the patch (arrays of *ws, valid until its next
 *   use); F: the cost there (1 without a cost).
 *   n_fallback: receives the number of patch vertices whose exact distance
 *   failed its bounds (mfmm_exact_patch_check) and which the march computes
 *   instead; 0 unless the exact solver erred.
 * MFMM_ERR_OUT_OF_MEMORY when the workspace or its queue cannot grow. */
mfmm_status mfmm_exact_start(const mfmm_mesh *mesh, mfmm_exact_ws **ws, const mfmm_source *src,
                             double radius, double max_distance, const double *cost,
                             const double *uniform, int32_t *n, const int32_t **vertices,
                             const double **distances, double *F, int32_t *n_fallback);

/* Seeds one checked source into a reset march state (cost fields set): its
 * exact start (mfmm_exact_start, uniform as there) where that applies, at
 * value + F * d, final where `fixed` (one source: the march never lowers
 * them); for a point, also the straight start's vertices (start/straight.h)
 * beyond the patch, which the march may lower. Elsewhere the straight
 * start alone. n_fallback as for mfmm_exact_start. MFMM_ERR_OUT_OF_MEMORY as
 * mfmm_exact_start. */
mfmm_status mfmm_exact_start_seed(const mfmm_mesh *mesh, mfmm_exact_ws **ws,
                                  mfmm_march_state *st, const mfmm_source *src, double radius,
                                  const double *uniform, int fixed, int32_t *n_fallback);

/* Bytes the exact start takes per thread (a workspace's state; the queue
 * of a patch is small), for memory budgets; the read-only tables (exact.h)
 * are the mesh's, built on first use and kept with it. */
size_t mfmm_exact_start_bytes(const mfmm_mesh *mesh);

#endif
