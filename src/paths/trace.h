/* The walk of a path down T (trace.c; private to src/paths). */
#ifndef MFMM_PATHS_TRACE_H
#define MFMM_PATHS_TRACE_H

#include "state.h"

/* Appends a point; the segment to it ran through face f. */
int mfmm_path_emit(tracer *t, int32_t f, const double b[3]);

/* qsort order of src_key by key. */
int mfmm_path_key_cmp(const void *a, const void *b);

/* Walks from the target (internal ids) down T to a source, appending the
 * points of the path to t (MFMM_OK, or the error also in t->st). */
mfmm_status mfmm_path_trace(tracer *t, const mfmm_source *target);

#endif
