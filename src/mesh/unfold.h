/* Virtual edges of obtuse corners by unfolding (section 4.2), and the walk
 * that rebuilds a virtual edge's strip (unfold.c; private to the library). */
#ifndef MFMM_MESH_UNFOLD_H
#define MFMM_MESH_UNFOLD_H

#include "mesh.h"

/* Finds the virtual edge of every obtuse corner by unfolding (section 4.2);
 * fills full[].virt, virt_len, virt_cos_a, virt_cos_b, strip_at, strip_n, the
 * strips' steps (build_steps, corner order) and the counts.
 * Needs the face records' vertices, lengths and cosines, xyz, face_neighbor
 * and the corners (full, corner 3f+k), as mesh creation has them then.
 * MFMM_ERR_OUT_OF_MEMORY or MFMM_OK. */
mfmm_status mfmm_mesh_unfold_obtuse(mfmm_mesh *mesh, int32_t max_steps);

/* A walk along a virtual edge's strip, rebuilding its steps as the build
 * found them (bit for bit): mfmm_strip_begin, then mfmm_strip_next per step.
 * The fields are the walk's. */
typedef struct mfmm_vec2 {
    double x, y;
} mfmm_vec2;
typedef struct mfmm_strip_walk {
    const mfmm_mesh *m;
    int32_t corner, a, b, n, i;
    int32_t e1, e2, face, opposite, k1, k2;
    mfmm_vec2 pa, pb, p1, p2, away, pv;
} mfmm_strip_walk;

/* Starts the walk of virtual edge j's strip (j: index in virts). */
void mfmm_strip_begin(mfmm_strip_walk *w, const mfmm_mesh *mesh, int32_t j);

/* The walk's next step into *step: 1, or 0 past the last (whose far is V). */
int mfmm_strip_next(mfmm_strip_walk *w, mfmm_virt_step *step);

#endif
