/* Closing T-junctions left by needle faces (tjunction.c; private to the
 * library). */
#ifndef MFMM_MESH_TJUNCTION_H
#define MFMM_MESH_TJUNCTION_H

#include "mesh.h"

/* Closes the T-junctions of *mesh, built from (vertices, nv, faces, nf), in
 * place (tjunction.c): where a zero-area face is a needle A-M-B with M
 * inside edge AB and one face A-B-C across AB, the needle stands for M
 * lying on AB, and the march (no triangle update through zero area) and the
 * paths would go round through A or B. The needle is dropped and A-B-C
 * split at M into two pieces that keep its corner order, rebuilding the
 * mesh until no such needle is left; input face ids, per-face costs,
 * points and paths map through face_to_internal/external and the pieces
 * (order.h). A mesh with none is left as it is. MFMM_OK or an error (the
 * mesh then destroyed and *mesh NULL). */
mfmm_status mfmm_mesh_close_t_junctions(mfmm_mesh **mesh, const double *vertices, int32_t nv,
                                        const int32_t *faces, int32_t nf,
                                        const mfmm_mesh_options *opt, mfmm_error *err);

#endif
