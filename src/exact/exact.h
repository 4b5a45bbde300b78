/* Exact polyhedral geodesic distances by window propagation (private to the
 * library; see solver.c for the algorithm and the papers; the exact start's
 * patch, a run to a radius: start/patch.h).
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

/* The mesh's own tables (mesh->exact_tables): made on first use under the
 * mesh's lock, then shared by every workspace on the mesh until the mesh is
 * destroyed. MFMM_ERR_OUT_OF_MEMORY when they cannot be made. */
mfmm_status mfmm_exact_tables_of(const mfmm_mesh *mesh, const mfmm_exact_tables **out);

/* Builds the tables where a run may read them (a tile at a time, under the
 * mesh's lock; what is built stays): within `radius` of any of the n
 * points (n, 3), internal coordinates, since no path shorter than radius
 * leaves that ball; points NULL or radius +inf: everywhere. The first
 * solve on a large mesh so builds only its patch's share. */
void mfmm_exact_tables_ensure(const mfmm_exact_tables *tables, const double *points, int32_t n,
                              double radius);

/* A workspace on shared tables (not freed with it). */
mfmm_status mfmm_exact_ws_create_shared(const mfmm_exact_tables *tables, mfmm_exact_ws **out);

/* A workspace on the mesh's tables (mfmm_exact_tables_of): the same as
 * mfmm_exact_solver_create / _destroy. */
mfmm_status mfmm_exact_ws_create(const mfmm_mesh *mesh, mfmm_exact_ws **out);
void mfmm_exact_ws_destroy(mfmm_exact_ws *ws);

/* For tests: the windows a reached vertex may cost before a run stops
 * (64 by default; run.c, ex_over_budget). */
void mfmm_exact_ws_set_budget(mfmm_exact_ws *ws, double windows_per_vertex);

#endif /* MFMM_EXACT_H */
