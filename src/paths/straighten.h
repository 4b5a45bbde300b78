/* Straightening a traced path inside its unfolded strip of faces (internal). */
#ifndef MFMM_PATHS_STRAIGHTEN_H
#define MFMM_PATHS_STRAIGHTEN_H

#include "mesh/mesh.h"

/* Straightens the traced path raw[0..n-1] (n > 1). face_cost: NULL, or a
 * per-face cost (pieces then break where it changes). Returns 1 with *out a
 * malloc'ed path of *n_out points (the caller frees it), 0 when out of
 * memory, -1 when the strip has no room (keep the raw path). */
int mfmm_path_straighten(const mfmm_mesh *mesh, const double *face_cost,
                         const mfmm_surface_point *raw, int32_t n,
                         mfmm_surface_point **out, int32_t *n_out);

#endif
