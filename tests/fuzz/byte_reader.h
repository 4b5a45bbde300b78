/* The fuzz harnesses' input reader: bytes one at a time, zeros past the
 * end, and the small meshes the solve and exact harnesses decode. */
#ifndef MFMM_FUZZ_BYTE_READER_H
#define MFMM_FUZZ_BYTE_READER_H

#include <stddef.h>
#include <stdint.h>

typedef struct reader {
    const uint8_t *p;
    size_t n;
} reader;

static inline uint8_t next(reader *r)
{
    if (r->n == 0)
        return 0;
    r->n--;
    return *r->p++;
}

/* A small mesh: nv * 3 int8 coordinates / 8, then nf * 3 vertex bytes
 * (mod nv). */
static inline void read_mesh(reader *r, int32_t nv, int32_t nf, double *V, int32_t *F)
{
    for (int32_t i = 0; i < 3 * nv; i++)
        V[i] = (double)(int8_t)next(r) / 8.0;
    for (int32_t i = 0; i < 3 * nf; i++)
        F[i] = next(r) % nv;
}

#endif
