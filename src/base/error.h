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

/* Checks a public option struct's struct_size (its first field) against the
 * layout this library knows, `known` = sizeof; MFMM_ERR_BAD_ARGUMENT naming
 * `type` when they differ (a struct not filled by its _init function, or
 * compiled against another header version). */
mfmm_status mfmm_check_struct_size(const void *options, size_t known, const char *type,
                                   mfmm_error *err);

#endif
