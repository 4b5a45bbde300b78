/* The march's spokes of a mesh (spokes.c; private to the library). */
#ifndef MFMM_MESH_SPOKES_H
#define MFMM_MESH_SPOKES_H

#include "mesh.h"

/* Building the spokes costs about what they save seven full marches
 * (docs/performance.md, Memory): marches go without them until they have
 * settled this many times nv vertices, so that a program that asks a few
 * fields never pays for them, and one that asks many pays at most about
 * twice the least it could (rent or buy). */
#define MFMM_SPOKES_AFTER 8

/* The mesh's spokes for the march (march.h: F = 1, unfolding on), built
 * under the mesh's lock when `eager` (a job of many rows) or once the
 * marches counted by mfmm_mesh_spokes_count reach MFMM_SPOKES_AFTER nv
 * settled vertices, and kept until mfmm_mesh_destroy: *offset (nv+1) and
 * *spokes. MFMM_ERR_OUT_OF_MEMORY (both NULL: the face walk gives the
 * same rows) or MFMM_OK (both NULL while not built, and always when the
 * mesh was made with mfmm_mesh_options.spokes = 0). */
mfmm_status mfmm_mesh_spokes_of(const mfmm_mesh *mesh, int eager, const int32_t **offset,
                                const mfmm_spoke **spokes);

/* Counts a march that could have read the spokes and did not: `settled`
 * vertices toward building them. */
void mfmm_mesh_spokes_count(const mfmm_mesh *mesh, int64_t settled);

#endif
