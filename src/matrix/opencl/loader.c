/* The OpenCL ICD loader, opened at run time (see loader.h). */
#include "base/error.h"
#include "loader.h"

#ifdef MESHFMM_HAVE_OPENCL

#include <dlfcn.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#define MFMM_CL_ENTRY(name) {#name, offsetof(mfmm_cl_api, name)}

static const struct {
    const char *name;
    size_t offset;
} entries[] = {
    MFMM_CL_ENTRY(clGetPlatformIDs),       MFMM_CL_ENTRY(clGetPlatformInfo),
    MFMM_CL_ENTRY(clGetDeviceIDs),         MFMM_CL_ENTRY(clGetDeviceInfo),
    MFMM_CL_ENTRY(clCreateContext),        MFMM_CL_ENTRY(clReleaseContext),
    MFMM_CL_ENTRY(clCreateProgramWithSource), MFMM_CL_ENTRY(clCreateProgramWithBinary),
    MFMM_CL_ENTRY(clBuildProgram),         MFMM_CL_ENTRY(clGetProgramBuildInfo),
    MFMM_CL_ENTRY(clGetProgramInfo),       MFMM_CL_ENTRY(clReleaseProgram),
    MFMM_CL_ENTRY(clCreateCommandQueue),   MFMM_CL_ENTRY(clReleaseCommandQueue),
    MFMM_CL_ENTRY(clCreateKernel),         MFMM_CL_ENTRY(clReleaseKernel),
    MFMM_CL_ENTRY(clCreateBuffer),         MFMM_CL_ENTRY(clReleaseMemObject),
    MFMM_CL_ENTRY(clSetKernelArg),         MFMM_CL_ENTRY(clEnqueueNDRangeKernel),
    MFMM_CL_ENTRY(clEnqueueReadBuffer),    MFMM_CL_ENTRY(clFlush),
    MFMM_CL_ENTRY(clFinish),               MFMM_CL_ENTRY(clWaitForEvents),
    MFMM_CL_ENTRY(clGetEventInfo),         MFMM_CL_ENTRY(clReleaseEvent),
};

/* The system's OpenCL loader: a framework on macOS, the ICD loader's soname
 * elsewhere. */
#ifdef __APPLE__
#define MFMM_CL_DEFAULT_LIBRARY "/System/Library/Frameworks/OpenCL.framework/OpenCL"
#else
#define MFMM_CL_DEFAULT_LIBRARY "libOpenCL.so.1"
#endif

mfmm_status mfmm_cl_api_load(mfmm_cl_api *api, const char *library, mfmm_error *err)
{
    memset(api, 0, sizeof *api);
    if (!library || !*library)
        library = getenv("MESHFMM_OPENCL_LIBRARY");
    if (!library || !*library)
        library = MFMM_CL_DEFAULT_LIBRARY;
    void *h = dlopen(library, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        const char *why = dlerror();
        return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1,
                         "cannot load the OpenCL library %s (install an OpenCL ICD loader and "
                         "driver, e.g. ocl-icd-libopencl1 and pocl-opencl-icd): %s",
                         library, why ? why : "dlopen failed");
    }
    for (size_t i = 0; i < sizeof entries / sizeof entries[0]; i++) {
        void *p = dlsym(h, entries[i].name);
        if (!p) {
            dlclose(h);
            return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1, "the OpenCL library %s has no %s",
                             library, entries[i].name);
        }
        /* a data pointer to a function pointer, as POSIX dlsym requires */
        memcpy((char *)api + entries[i].offset, &p, sizeof p);
    }
    api->handle = h;
    return MFMM_OK;
}

/* The loader is not dlclose'd: drivers (PoCL) keep worker threads and
 * allocations for the life of the process, which must not outlive their code.
 * A later dlopen of the loaded library only counts a reference. */
void mfmm_cl_api_unload(mfmm_cl_api *api)
{
    memset(api, 0, sizeof *api);
}

#else

typedef int mfmm_opencl_loader_unused; /* ISO C: no empty translation unit */

#endif
