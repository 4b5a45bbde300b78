/* Mesh file readers (internal). Each parser reads a whole file held in
 * memory (data[size] == '\0' is guaranteed) and returns library-allocated
 * (malloc) arrays: V (nv,3) float64 and F (nf,3) int32, 0-based. Syntax is
 * validated, indices are range-checked and coordinates must be finite. */
#ifndef MFMM_IO_H
#define MFMM_IO_H

#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>
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
mfmm_status mfmm_io_parse_stl(const char *data, size_t size, mfmm_io_result *out,
                              mfmm_error *err);
/* 1 when size is binary STL's 84 + 50 n for the count n at byte 80. */
int mfmm_io_stl_is_binary(const char *data, size_t size);

/* Formats (load.c). */
enum {
    MFMM_IO_FMT_UNKNOWN = 0, /* sniff the content */
    MFMM_IO_FMT_OBJ,
    MFMM_IO_FMT_OFF,
    MFMM_IO_FMT_PLY,
    MFMM_IO_FMT_STL,
    MFMM_IO_FMT_UNSUPPORTED /* a known format meshfmm does not read (glTF, FBX, ...) */
};
/* By the path's extension (case-insensitive); UNKNOWN when it says nothing. */
int mfmm_io_format_from_path(const char *path);
/* By the content: PLY magic, binary STL's size, OFF or 'solid' headers, an
 * OBJ keyword; UNSUPPORTED when nothing fits. */
int mfmm_io_format_from_content(const char *data, size_t size);
/* Parses data (data[size] == '\0') as `format` (UNKNOWN: sniffed): the
 * in-memory entry point of mfmm_load_mesh. */
mfmm_status mfmm_io_parse(const char *data, size_t size, int format, mfmm_io_result *out,
                          mfmm_error *err);

/* Opens path read-only without blocking on a FIFO and checks that it is a
 * regular file: the fd (blocking again) with *size from fstat; -1 when it
 * cannot be opened (*why: strerror), -2 when it is not a regular file
 * (*why: "a directory", "a FIFO (named pipe)", ...). */
int mfmm_io_open_regular(const char *path, off_t *size, const char **why);

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
/* Parses a floating-point number; 1 on success (decimal, inf or nan text as
 * mfmm_io_strtod reads it; finiteness is checked by the caller). */
int mfmm_io_scan_double(const char **p, double *value);

/* Locale-free strtod (number.c): [+-] digits [. digits] [e[+-]digits], or
 * inf, infinity, nan, nan(chars) in any case; no leading blanks, no hex.
 * Correctly rounded (ties to even); out of range gives +-inf or +-0. 1 with
 * *end past the number, 0 (nothing read) when s does not start one. */
int mfmm_io_strtod(const char *s, const char **end, double *value);
/* Writes x as "%.17g" would in the C locale (always '.'), whatever the
 * process's locale; the length, or -1 when buf (size bytes) is too small. */
int mfmm_io_format_double(char *buf, size_t size, double x);

/* Frees both vectors and returns st: a parser's way out on failure. */
mfmm_status mfmm_io_discard(mfmm_io_vec *verts, mfmm_io_vec *tris, mfmm_status st);

/* Moves the results into out (transfers ownership), checking counts. */
mfmm_status mfmm_io_finish(mfmm_io_vec *verts, mfmm_io_vec *tris, mfmm_io_result *out,
                           mfmm_error *err);

#endif /* MFMM_IO_H */
