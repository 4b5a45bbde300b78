/* The march's spokes of a mesh (spokes.c; private to the library). */
#ifndef MFMM_MESH_SPOKES_H
#define MFMM_MESH_SPOKES_H

#include "mesh.h"

/* The mesh's spokes for the march (march.h: F = 1, unfolding on), built
 * on first use under the mesh's lock and kept until mfmm_mesh_destroy:
 * *offset (nv+1) and *spokes. MFMM_ERR_OUT_OF_MEMORY (both NULL: the
 * face walk gives the same rows) or MFMM_OK (both NULL when the mesh was
 * made with mfmm_mesh_options.spokes = 0). */
mfmm_status mfmm_mesh_spokes_of(const mfmm_mesh *mesh, const int32_t **offset,
                                const mfmm_spoke **spokes);

#endif
