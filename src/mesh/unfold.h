/* Virtual edges of obtuse corners by unfolding (section 4.2), and the walk
 * that rebuilds a virtual edge's strip (unfold.c; private to the library). */
#ifndef MFMM_MESH_UNFOLD_H
#define MFMM_MESH_UNFOLD_H

#include "mesh.h"

/* An obtuse corner while the mesh is built (build.c, unfold.c): what
 * unfolding found for it. virt: V's id (the corner is split by the virtual
 * edge to V), or MFMM_VIRT_FAILED (the plain stencil); strip_at, strip_n:
 * its strip's steps in the build's buffer; len, cos_a, cos_b: as in
 * mfmm_virt. */
#define MFMM_VIRT_FAILED (-2)
typedef struct mfmm_obtuse {
    int32_t corner, virt;
    int32_t strip_at, strip_n;
    double len, cos_a, cos_b;
} mfmm_obtuse;

/* Finds the virtual edge of each of the n obtuse corners by unfolding
 * (section 4.2): fills their virt, len, cos_a, cos_b, strip_at and
 * strip_n, the counts in the mesh's info, and *strip_far (malloc'd, never
 * NULL): each strip's steps' vertices off the edge crossed, the last one V.
 * Needs the face records' vertices, lengths and cosines, xyz and
 * face_neighbor, as mesh creation has them then.
 * MFMM_ERR_OUT_OF_MEMORY or MFMM_OK. */
mfmm_status mfmm_mesh_unfold_obtuse(mfmm_mesh *mesh, int32_t max_steps, mfmm_obtuse *obtuse,
                                    int32_t n, int32_t **strip_far);

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
