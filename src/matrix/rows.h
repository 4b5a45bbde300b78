/* Internal: a validated many-source job and the delivery of its rows
 * (rows.c), shared by the CPU engines (matrix.c) and the OpenCL backend
 * (opencl_host.c). */
#ifndef MFMM_MATRIX_ROWS_H
#define MFMM_MATRIX_ROWS_H

#include "core/mesh.h"

/* A validated matrix job. */
typedef struct mfmm_rows_job {
    const mfmm_mesh *mesh;
    const int32_t *sources;   /* n_sources vertex ids (never NULL here) */
    int32_t n_sources;
    const mfmm_matrix_options *opt;
    const double *cost;       /* NULL when F = 1 */
    int cost_location;        /* 0 none, 1 per vertex, 2 per face */
    size_t elem_size;         /* 4 or 8 */
    size_t budget;            /* bytes for workspaces and blocks in flight */
    int full_batches;         /* OpenCL under AUTO: refuse (MFMM_ERR_NO_OPENCL, before any
                                 row) when a batch cannot hold a row per compute unit */
} mfmm_rows_job;

/* Default budget when memory_limit is 0. */
#define MFMM_DEFAULT_BUDGET ((size_t)16 << 20)

/* Hands rows [first, first + n) to the caller: copies them into opt->out
 * (unless rows already point there) and calls opt->on_rows. Returns non-zero
 * when the callback asks to cancel. */
int mfmm_rows_deliver(const mfmm_rows_job *job, int32_t first, int32_t n, const void *rows);

/* Runs rows [start, n_sources) on an OpenCL device: opt->opencl, else a
 * context made from opt->opencl_options for the call. *rows_done receives the
 * rows delivered (from start) even on failure, so a fallback can go on from
 * there. MFMM_ERR_NO_OPENCL when built without OpenCL or no device works. */
mfmm_status mfmm_opencl_rows(const mfmm_rows_job *job, int32_t start, int32_t *rows_done,
                             mfmm_error *err);

#endif
