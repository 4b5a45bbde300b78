/* Status names, error details and the version string. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "error.h"

static const char *const status_strings[MFMM_STATUS_COUNT] = {
    [MFMM_OK] = "success",
    [MFMM_ERR_NULL_POINTER] = "a required pointer argument is NULL",
    [MFMM_ERR_BAD_COUNT] = "a count is out of range",
    [MFMM_ERR_NONFINITE_VERTEX] = "a vertex coordinate is NaN or infinite",
    [MFMM_ERR_INDEX_OUT_OF_RANGE] = "a face index is out of range",
    [MFMM_ERR_REPEATED_VERTEX] = "a face names one vertex twice",
    [MFMM_ERR_OUT_OF_MEMORY] = "out of memory",
    [MFMM_ERR_BAD_COST] = "a cost is not finite or not greater than 0",
    [MFMM_ERR_BAD_SOURCE] = "a source vertex or face id is out of range",
    [MFMM_ERR_DEGENERATE_SOURCE] = "a source lies on a zero-area face",
    [MFMM_ERR_BAD_BARYCENTRIC] =
        "barycentric coordinates are not finite, negative, or do not sum to 1",
    [MFMM_ERR_BAD_ARGUMENT] = "an argument is invalid",
    [MFMM_ERR_WRONG_MESH] = "the solver was created for another mesh",
    [MFMM_ERR_UNREACHED] = "the target was not reached (infinite distance)",
    [MFMM_ERR_PATH_STALLED] = "path tracing stopped descending or ran out of steps",
    [MFMM_ERR_NO_OPENCL] = "no OpenCL platform or device is available",
    [MFMM_ERR_OPENCL_BUILD] = "the OpenCL program failed to build",
    [MFMM_ERR_OPENCL_RUNTIME] = "an OpenCL call failed",
    [MFMM_ERR_CANCELLED] = "cancelled by the caller",
    [MFMM_ERR_IO] = "a file could not be opened, read or written",
    [MFMM_ERR_PARSE] = "the mesh file is malformed",
    [MFMM_ERR_MEMORY_LIMIT] = "the computation needed more memory than its memory limit",
};

const char *mfmm_status_string(mfmm_status status)
{
    if ((int)status < 0 || status >= MFMM_STATUS_COUNT)
        return "unknown status";
    return status_strings[status];
}

#define MFMM_STR2(x) #x
#define MFMM_STR(x) MFMM_STR2(x)

const char *mfmm_version(void)
{
    return MFMM_STR(MFMM_VERSION_MAJOR) "." MFMM_STR(MFMM_VERSION_MINOR) "." MFMM_STR(
        MFMM_VERSION_PATCH);
}

mfmm_status mfmm_fail(mfmm_error *err, mfmm_status status, int64_t index, const char *fmt, ...)
{
    if (err) {
        err->status = status;
        err->index = index;
        if (fmt) {
            va_list ap;
            va_start(ap, fmt);
            vsnprintf(err->message, sizeof err->message, fmt, ap);
            va_end(ap);
        } else {
            snprintf(err->message, sizeof err->message, "%s", mfmm_status_string(status));
        }
    }
    return status;
}

mfmm_status mfmm_read_options(void *dst, const void *options, size_t known, const char *type,
                              mfmm_error *err)
{
    size_t given;
    memcpy(&given, options, sizeof given);
    if (given < sizeof given || given > known)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1,
                         "%s.struct_size is %zu, but this library (meshfmm %s) reads %zu to %zu: "
                         "fill it with %s_init (a header of another version?)",
                         type, given, mfmm_version(), sizeof given, known, type);
    memcpy(dst, options, given); /* fields past the caller's struct keep dst's defaults */
    memcpy(dst, &known, sizeof known);
    return MFMM_OK;
}

mfmm_status mfmm_check_info_size(const void *info)
{
    size_t given;
    memcpy(&given, info, sizeof given);
    return given >= sizeof given ? MFMM_OK : MFMM_ERR_BAD_ARGUMENT;
}

mfmm_status mfmm_write_info(void *info, const void *all, size_t known)
{
    if (mfmm_check_info_size(info) != MFMM_OK)
        return MFMM_ERR_BAD_ARGUMENT;
    size_t given;
    memcpy(&given, info, sizeof given);
    size_t n = given < known ? given : known;
    memcpy(info, all, n);
    memcpy(info, &n, sizeof n);
    return MFMM_OK;
}

void mfmm_ok(mfmm_error *err)
{
    if (err) {
        err->status = MFMM_OK;
        err->index = -1;
        err->message[0] = '\0';
    }
}

void mfmm_free(void *pointer)
{
    free(pointer);
}
