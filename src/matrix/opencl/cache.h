/* The backend's OpenCL program: built from the embedded kernel source, its
 * binary cached on disk and self-tested (cache.c; private to the library). */
#ifndef MFMM_OPENCL_CACHE_H
#define MFMM_OPENCL_CACHE_H

#ifdef MESHFMM_HAVE_OPENCL

#include "device.h"

/* Builds cl->program from the cached binary when there is a valid one, else
 * from source (then stores the binary, replacing a bad entry).
 * cache_option: mfmm_opencl_options.cache_dir, or NULL. */
mfmm_status mfmm_cl_build_program(ocl *cl, const char *cache_option, mfmm_error *err);

#endif /* MESHFMM_HAVE_OPENCL */
#endif
