/* The OpenCL backend's entry for a matrix job (context.c; private to the
 * library; the context API itself is public, meshfmm.h). */
#ifndef MFMM_OPENCL_CONTEXT_H
#define MFMM_OPENCL_CONTEXT_H

#include "matrix/rows.h"

/* Runs rows [start, n_sources) on an OpenCL device: opt->opencl, else a
 * context made from opt->opencl_options for the call. *rows_done receives the
 * rows delivered (from start) even on failure, so a fallback can go on from
 * there. MFMM_ERR_NO_OPENCL when built without OpenCL or no device works. */
mfmm_status mfmm_opencl_rows(const mfmm_rows_job *job, int32_t start, int32_t *rows_done,
                             mfmm_error *err);

#endif
