/* Mesh file readers (internal). Each parser reads a whole file held in
 * memory (data[size] == '\0' is guaranteed) and returns library-allocated
 * (malloc) arrays: V (nv,3) float64 and F (nf,3) int32, 0-based. Syntax is
 * validated, indices are range-checked and coordinates must be finite. */
#ifndef MFMM_IO_H
#define MFMM_IO_H

#include <stddef.h>
#include <stdint.h>
#include "meshfmm.h"

typedef struct mfmm_io_result {
    double *V;
    int32_t nv;
    int32_t *F;
    int32_t nf;
} mfmm_io_result;

mfmm_status mfmm_io_parse_obj(const char *data, size_t size, mfmm_io_result *out,
                              mfmm_error *err);
mfmm_status mfmm_io_parse_off(const char *data, size_t size, mfmm_io_result *out,
                              mfmm_error *err);
mfmm_status mfmm_io_parse_ply(const char *data, size_t size, mfmm_io_result *out,
                              mfmm_error *err);

/* A growable array of int32 triangles or doubles (internal helpers). */
typedef struct mfmm_io_vec {
    void *data;
    size_t len, cap; /* in elements */
    size_t elem;     /* bytes per element */
} mfmm_io_vec;

void mfmm_io_vec_init(mfmm_io_vec *v, size_t elem);
/* Ensures room for `extra` more elements; 0 on success, -1 when out of memory. */
int mfmm_io_vec_reserve(mfmm_io_vec *v, size_t extra);
void mfmm_io_vec_free(mfmm_io_vec *v);

/* Appends a triangle (a, b, c) to a vector of int32 triples. 0 or -1. */
int mfmm_io_push_tri(mfmm_io_vec *tris, int32_t a, int32_t b, int32_t c);

/* Text scanning helpers. `p` points into a NUL-terminated buffer. */
/* Parses a decimal integer (optional sign); returns 1 and advances *p on
 * success, 0 on malformed input or overflow of int64. */
int mfmm_io_scan_int(const char **p, int64_t *value);
/* Parses a floating-point number; 1 on success (the number may be any
 * strtod-accepted text, finiteness is checked by the caller). */
int mfmm_io_scan_double(const char **p, double *value);

/* Frees both vectors and returns st: a parser's way out on failure. */
mfmm_status mfmm_io_discard(mfmm_io_vec *verts, mfmm_io_vec *tris, mfmm_status st);

/* Moves the results into out (transfers ownership), checking counts. */
mfmm_status mfmm_io_finish(mfmm_io_vec *verts, mfmm_io_vec *tris, mfmm_io_result *out,
                           mfmm_error *err);

#endif /* MFMM_IO_H */
