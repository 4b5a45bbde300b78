/* Exact polyhedral geodesic distances by window propagation (private to the
 * library; see exact.c for the algorithm and the papers).
 *
 * The public face is mfmm_exact_solver / mfmm_solve_exact in meshfmm.h; the
 * workspace here is the same object. It reads from the mesh only nv, nf,
 * xyz, the faces' vertices (face records), face_neighbor, the vertex ->
 * face CSR (MFMM_WEDGE entries) and zero-area faces (mfmm_mesh_degenerate), and builds its own
 * edge geometry once. */
#ifndef MFMM_EXACT_H
#define MFMM_EXACT_H

#include "meshfmm.h"

typedef struct mfmm_exact_solver mfmm_exact_ws;

/* A mesh's read-only tables (face records, fans, pseudo-source flags): built
 * once and shared by the workspaces of any number of threads, which keep
 * only a solve's state (a thread building its own held ~430 B/vertex).
 * The mesh must outlive them, and they every workspace made from them.
 * mfmm_exact_tables_bytes: their size; mfmm_exact_ws_bytes: a workspace's
 * (per vertex state, without the queue, which grows with the patch). */
typedef struct mfmm_exact_tables mfmm_exact_tables;
mfmm_status mfmm_exact_tables_create(const mfmm_mesh *mesh, mfmm_exact_tables **out);
void mfmm_exact_tables_destroy(mfmm_exact_tables *tables);
size_t mfmm_exact_tables_bytes(const mfmm_mesh *mesh);
size_t mfmm_exact_ws_bytes(const mfmm_mesh *mesh);

/* The mesh's own tables (mesh->exact_tables): built on first use under the
 * mesh's lock, then shared by every workspace on the mesh until the mesh is
 * destroyed. MFMM_ERR_OUT_OF_MEMORY when they cannot be built. */
mfmm_status mfmm_exact_tables_of(const mfmm_mesh *mesh, const mfmm_exact_tables **out);

/* A workspace on shared tables (not freed with it). */
mfmm_status mfmm_exact_ws_create_shared(const mfmm_exact_tables *tables, mfmm_exact_ws **out);

/* A workspace on the mesh's tables (mfmm_exact_tables_of): the same as
 * mfmm_exact_solver_create / _destroy. */
mfmm_status mfmm_exact_ws_create(const mfmm_mesh *mesh, mfmm_exact_ws **out);
void mfmm_exact_ws_destroy(mfmm_exact_ws *ws);

/* Exact distances from point sources near them: the "exact start" of a
 * march. Propagation stops once every window and pseudo-source left is
 * farther than radius, so the cost grows with the patch, not the mesh
 * (about 0.2 ms for 150 vertices on the 35k-vertex test meshes).
 * Sources as for mfmm_solve_exact (checked: MFMM_ERR_BAD_SOURCE and the
 * like); T = value + distance. The patch: every vertex with T <= radius,
 * and the ring of those beyond it by less than their least height in their
 * faces, whose T the propagation has also made final (exact.c).
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

/* For tests: the windows a reached vertex may cost before a run stops
 * (64 by default; exact.c, ex_over_budget). */
void mfmm_exact_ws_set_budget(mfmm_exact_ws *ws, double windows_per_vertex);

/* Whether vertex v is in the patch of ws's last mfmm_exact_patch. */
int mfmm_exact_in_patch(const mfmm_exact_ws *ws, int32_t v);

#endif /* MFMM_EXACT_H */
