/* Internal: a validated many-source job and the delivery of its rows
 * (rows.c), shared by the CPU engines (matrix.c) and the OpenCL backend
 * (opencl/rows.c). */
#ifndef MFMM_MATRIX_ROWS_H
#define MFMM_MATRIX_ROWS_H

#include "mesh/mesh.h"

/* A validated matrix job. */
typedef struct mfmm_rows_job {
    const mfmm_mesh *mesh;
    const int32_t *sources;   /* n_sources vertex ids (never NULL here) */
    int32_t n_sources;
    const mfmm_matrix_options *opt; /* the options, all fields (defaults past the
                                       caller's struct_size) */
    mfmm_matrix_info *info;   /* the call's results, all fields */
    const double *cost;       /* NULL when F = 1 */
    int cost_location;        /* 0 none, 1 per vertex, 2 per face */
    size_t elem_size;         /* 4 or 8 */
    size_t budget;            /* bytes for workspaces and blocks in flight */
    const int32_t *targets;   /* the job's own copy of opt->targets, or NULL */
    int32_t width;            /* columns: n_targets, or nv */
    int sparse;               /* rows go to opt->on_sparse (slots are mfmm_sparse_row) */
    size_t slot_bytes;        /* bytes a row takes in a block: width * elem_size, or
                                 sizeof(mfmm_sparse_row) */
    int full_batches;         /* OpenCL under AUTO: refuse (MFMM_ERR_NO_OPENCL, before any
                                 row) when a batch cannot hold a row per compute unit */
} mfmm_rows_job;

/* A sparse row in flight: n entries, column ids ascending, values of the
 * job's dtype (malloc'd by the row's solver, freed after delivery). */
typedef struct mfmm_sparse_row {
    int32_t n;
    int32_t *idx;
    void *val;
} mfmm_sparse_row;

/* Default budget when memory_limit is 0. */
#define MFMM_DEFAULT_BUDGET ((size_t)16 << 20)

/* Hands rows [first, first + n) to the caller: copies them into opt->out
 * (unless rows already point there) and calls opt->on_rows. Returns non-zero
 * when the callback asks to cancel. */
int mfmm_rows_deliver(const mfmm_rows_job *job, int32_t first, int32_t n, const void *rows);

/* Hands n sparse rows (slots) to opt->on_sparse as one CSR block and frees
 * their arrays. Returns non-zero when the callback asks to cancel, and -1
 * (status OOM) when the block's CSR arrays cannot be allocated. */
int mfmm_rows_deliver_sparse(const mfmm_rows_job *job, int32_t first, int32_t n,
                             mfmm_sparse_row *rows, mfmm_status *st);

/* Frees the arrays of n sparse rows (after a failure). */
void mfmm_sparse_rows_free(mfmm_sparse_row *rows, int32_t n);

#endif
