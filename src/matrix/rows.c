/* Handing finished rows to the caller, shared by every row engine
 * (cpu.c's serial and thread engines, opencl/rows.c). */
#include <stdlib.h>
#include <string.h>

#include "rows.h"

int mfmm_rows_deliver(const mfmm_rows_job *job, int32_t first, int32_t n, const void *rows)
{
    const mfmm_matrix_options *o = job->opt;
    size_t row_bytes = (size_t)job->width * job->elem_size;
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

void mfmm_sparse_rows_free(mfmm_sparse_row *rows, int32_t n)
{
    for (int32_t i = 0; i < n; i++) {
        free(rows[i].idx);
        free(rows[i].val);
        rows[i].idx = NULL;
        rows[i].val = NULL;
        rows[i].n = 0;
    }
}

int mfmm_rows_deliver_sparse(const mfmm_rows_job *job, int32_t first, int32_t n,
                             mfmm_sparse_row *rows, mfmm_status *st)
{
    *st = MFMM_OK;
    size_t nnz = 0;
    for (int32_t i = 0; i < n; i++)
        nnz += (size_t)rows[i].n;
    int64_t *indptr = malloc(((size_t)n + 1) * sizeof *indptr);
    int32_t *indices = malloc((nnz ? nnz : 1) * sizeof *indices);
    char *values = malloc((nnz ? nnz : 1) * job->elem_size);
    int r = 0;
    if (!indptr || !indices || !values) {
        *st = MFMM_ERR_OUT_OF_MEMORY;
        r = -1;
    } else {
        size_t k = 0;
        indptr[0] = 0;
        for (int32_t i = 0; i < n; i++) {
            size_t m = (size_t)rows[i].n;
            if (m) {
                memcpy(indices + k, rows[i].idx, m * sizeof *indices);
                memcpy(values + k * job->elem_size, rows[i].val, m * job->elem_size);
            }
            k += m;
            indptr[i + 1] = (int64_t)k;
        }
        r = job->opt->on_sparse(job->opt->user, first, n, indptr, indices, values);
    }
    free(indptr);
    free(indices);
    free(values);
    mfmm_sparse_rows_free(rows, n);
    return r;
}
