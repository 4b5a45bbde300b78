/* Building a mesh from checked arrays (build.c; private to the library). */
#ifndef MFMM_MESH_BUILD_H
#define MFMM_MESH_BUILD_H

#include "mesh.h"

/* Builds a mesh from checked arrays (mfmm_mesh_create's work, without its
 * argument checks and without closing T-junctions): *out, or an error. */
mfmm_status mfmm_mesh_build(const double *vertices, int32_t nv, const int32_t *faces,
                            int32_t nf, const mfmm_mesh_options *opt, mfmm_mesh **out,
                            mfmm_error *err);

#endif
