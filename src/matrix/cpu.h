/* The CPU engines of a matrix job (cpu.c; private to the library). */
#ifndef MFMM_MATRIX_CPU_H
#define MFMM_MATRIX_CPU_H

#include "rows.h"

/* Rows [start, n_sources) of a validated job on one solver, in order. */
mfmm_status mfmm_rows_serial(const mfmm_rows_job *job, int32_t start, mfmm_error *err);

/* Rows [start, n_sources) of a validated job on opt->n_threads solvers (0:
 * one per processor), delivered in order by the calling thread. */
mfmm_status mfmm_rows_threads(const mfmm_rows_job *job, int32_t start, mfmm_error *err);

#endif
