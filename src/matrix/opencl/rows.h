/* A matrix job's rows on an open OpenCL device (rows.c; private to the
 * library). */
#ifndef MFMM_OPENCL_ROWS_H
#define MFMM_OPENCL_ROWS_H

#ifdef MESHFMM_HAVE_OPENCL

#include "device.h"
#include "matrix/rows.h"

/* Rows [start, n_sources) of the job on `shared`'s device and program, with
 * this call's own queue, kernel and buffers: setup, upload of the mesh,
 * workspaces, then batches (enqueue k, download k - 1). *rows_done
 * receives the rows delivered, also on failure. */
mfmm_status mfmm_cl_run_rows(const ocl *shared, const mfmm_rows_job *job, int32_t start,
                             int32_t *rows_done, mfmm_error *err);

#endif /* MESHFMM_HAVE_OPENCL */
#endif
