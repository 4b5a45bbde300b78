/* Filling a mfmm_error, and checking an option struct's struct_size
 * (status.c; private to the library). */
#ifndef MFMM_BASE_ERROR_H
#define MFMM_BASE_ERROR_H

#include <stddef.h>
#include <stdint.h>

#include "meshfmm.h"

/* Fills err (if any) and returns status. */
mfmm_status mfmm_fail(mfmm_error *err, mfmm_status status, int64_t index, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* Marks err as success. */
void mfmm_ok(mfmm_error *err);

/* Reads a caller's option struct into dst (which holds the defaults, `known`
 * bytes): a struct_size (its first field) from sizeof(size_t) to `known` is
 * read, and that prefix copied, so fields beyond an older caller's struct
 * keep their defaults; dst's struct_size becomes known. Otherwise
 * MFMM_ERR_BAD_ARGUMENT naming `type` (a struct not filled by its _init
 * function, or from a newer header). */
mfmm_status mfmm_read_options(void *dst, const void *options, size_t known, const char *type,
                              mfmm_error *err);

/* A caller's output struct: MFMM_ERR_BAD_ARGUMENT when its struct_size is
 * below sizeof(size_t). */
mfmm_status mfmm_check_info_size(const void *info);

/* Copies the library's filled output struct `all` (`known` bytes) into the
 * caller's `info`, no more than info's struct_size bytes, and sets info's
 * struct_size to the bytes written. MFMM_ERR_BAD_ARGUMENT as above. */
mfmm_status mfmm_write_info(void *info, const void *all, size_t known);

#endif
