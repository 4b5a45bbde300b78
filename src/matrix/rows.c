/* Handing finished rows to the caller, shared by every row engine
 * (matrix.c's serial and thread engines, opencl_host.c). */
#include <string.h>

#include "rows.h"

int mfmm_rows_deliver(const mfmm_rows_job *job, int32_t first, int32_t n, const void *rows)
{
    const mfmm_matrix_options *o = job->opt;
    size_t row_bytes = (size_t)job->mesh->nv * job->elem_size;
    if (o->out) {
        char *dst = (char *)o->out + (size_t)first * row_bytes;
        if (dst != (const char *)rows)
            memcpy(dst, rows, (size_t)n * row_bytes);
        rows = dst;
    }
    if (o->on_rows)
        return o->on_rows(o->user, first, n, rows);
    return 0;
}
