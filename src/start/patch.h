/* The exact start's patch (patch.c; private to the library): the exact
 * solver run on a workspace to a radius around a source, and the check of
 * its distances. */
#ifndef MFMM_START_PATCH_H
#define MFMM_START_PATCH_H

#include "exact/exact.h"

/* Exact distances from point sources near them: the "exact start" of a
 * march. Propagation stops once every window and pseudo-source left is
 * farther than radius, so the cost grows with the patch, not the mesh
 * (docs/performance.md, "The cost of the exact start").
 * Sources as for mfmm_solve_exact, but in internal ids (mesh/order.h:
 * vertices, and faces cut at T-junctions), checked as it checks its own
 * (MFMM_ERR_BAD_SOURCE and the like); T = value + distance. The patch:
 * every vertex with T <= radius, and the ring of those beyond it by less
 * than their least height in their faces, whose T the propagation has also
 * made final (start/patch.c).
 *   n_vertices: receives the number of vertices in the patch.
 *   vertices, distances: receive arrays of that length owned by ws, valid
 *   until its next call (vertex ids, and their exact T), in no particular
 *   order.
 *   memory_limit: bytes ws may hold in all (0: no limit).
 *   info: may be NULL.
 * Reuses ws's buffers: after the first calls have grown them, a call
 * allocates nothing and touches only the patch (plus its queue). */
mfmm_status mfmm_exact_patch(mfmm_exact_ws *ws, const mfmm_source *sources, int32_t n_sources,
                             double radius, size_t memory_limit, int32_t *n_vertices,
                             const int32_t **vertices, const double **distances,
                             mfmm_exact_info *info);

/* Checks the patch of ws's last mfmm_exact_patch from the one source src
 * against two bounds that any correct distance meets: at least the
 * straight-line distance from the source's point, at most the shortest edge
 * path to the vertex through the patch (both lengths of real paths, to
 * 1e-9 of the distance plus a mean edge length). A vertex outside them is a defect of the exact solver: it
 * leaves the patch, so that the march computes it instead.
 *   n_vertices: in, the patch's size; out, the vertices kept, first in the
 *   arrays of mfmm_exact_patch and in their order.
 *   n_rejected: receives the number of vertices taken out.
 * MFMM_ERR_OUT_OF_MEMORY when its scratch (the patch's size) cannot grow. */
mfmm_status mfmm_exact_patch_check(mfmm_exact_ws *ws, const mfmm_source *src, int32_t *n_vertices,
                                   int32_t *n_rejected);

/* Whether vertex v is in the patch of ws's last mfmm_exact_patch. */
int mfmm_exact_in_patch(const mfmm_exact_ws *ws, int32_t v);

#endif
