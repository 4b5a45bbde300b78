/* The self-test of an OpenCL program (selftest.c; private to the library). */
#ifndef MFMM_OPENCL_SELFTEST_H
#define MFMM_OPENCL_SELFTEST_H

#ifdef MESHFMM_HAVE_OPENCL

#include "device.h"

/* All rows of a small mesh with obtuse corners, in float64 and float32, on
 * cl's program, against mfmm_solve, bit for bit: MFMM_OK, or the first row
 * that differs (err may be NULL). */
mfmm_status mfmm_cl_self_test(ocl *cl, mfmm_error *err);

#endif /* MESHFMM_HAVE_OPENCL */
#endif
