/* Positions as hash keys, for finding coincident vertices (weld.c, build.c). */
#ifndef MFMM_MESH_WELD_H
#define MFMM_MESH_WELD_H

#include <stdint.h>
#include <string.h>

/* A position's hash: its coordinates' bits (-0.0 read as 0.0, so that the
 * two compare equal as they do with ==). */
static inline uint64_t mfmm_position_hash(const double *p)
{
    uint64_t h = 1469598103934665603u;
    for (int k = 0; k < 3; k++) {
        double x = p[k] + 0.0;
        uint64_t bits;
        memcpy(&bits, &x, sizeof bits);
        h = (h ^ bits) * 1099511628211u;
        h ^= h >> 29;
    }
    return h;
}

/* The size of an open-addressing table for n keys: a power of two >= 2n. */
static inline size_t mfmm_position_table_size(size_t n)
{
    size_t cap = 16;
    while (cap < 2 * n)
        cap *= 2;
    return cap;
}

#endif /* MFMM_MESH_WELD_H */
