/* The fuzz harnesses' input reader: bytes one at a time, zeros past the end. */
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

#endif
