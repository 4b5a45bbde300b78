/* mfmm_mesh_memory: the bytes each of a built mesh's arrays holds. */
#include <pthread.h>
#include <stdint.h>

#include "mesh.h"

int mfmm_mesh_memory(const mfmm_mesh *mesh, const char **names, size_t *bytes, int max)
{
    if (!mesh || max < 0 || (max > 0 && (!names || !bytes)))
        return -1;
    size_t nv = (size_t)mesh->nv, nf = (size_t)mesh->nf, nc = 3 * nf;
    size_t n_virts = (size_t)mesh->n_virts, n_steps = (size_t)mesh->virt_strip[n_virts];
    /* the exact tables may be built by another thread meanwhile (mesh.h) */
    pthread_mutex_t *lock = (pthread_mutex_t *)(uintptr_t)&mesh->cache_lock;
    pthread_mutex_lock(lock);
    size_t exact_bytes = mesh->exact_tables_bytes, spoke_bytes = mesh->spokes_bytes;
    pthread_mutex_unlock(lock);
    const struct {
        const char *name;
        size_t bytes;
    } a[] = {
        {"xyz", nv * 3 * sizeof(double)},
        {"face_neighbor", nc * sizeof(int32_t)},
        {"vertex_face (CSR)", (nv + 1 + nc) * sizeof(int32_t)},
        {"to_internal/to_external", 2 * nv * sizeof(int32_t)},
        {"face_to_internal/external", ((size_t)mesh->nf_in + nf) * sizeof(int32_t) +
                                          (mesh->piece_next ? nf * (sizeof(int32_t) + 9 * sizeof(double)) : 0)},
        {"face records", nf * sizeof(mfmm_face)},
        {"virtual edges", (size_t)mesh->n_virts * sizeof(mfmm_virt) + (nv + 1) * sizeof(int32_t)},
        {"strip", n_steps * sizeof(int32_t)},
        {"virt_strip", (n_virts + 1) * sizeof(int32_t)},
        {"mesh struct", sizeof *mesh},
        {"exact tables (once built)", exact_bytes},
        {"spokes (once built)", spoke_bytes},
    };
    int n = (int)(sizeof a / sizeof a[0]);
    for (int i = 0; i < n && i < max; i++) {
        names[i] = a[i].name;
        bytes[i] = a[i].bytes;
    }
    return n;
}
