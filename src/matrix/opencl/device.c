/* Picking an OpenCL device and opening a call's queue and kernel on it
 * (device.h). */
#ifdef MESHFMM_HAVE_OPENCL

#include <ctype.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "device.h"

const char *mfmm_cl_error_name(cl_int e)
{
    switch (e) {
    case CL_DEVICE_NOT_FOUND: return "CL_DEVICE_NOT_FOUND";
    case CL_DEVICE_NOT_AVAILABLE: return "CL_DEVICE_NOT_AVAILABLE";
    case CL_COMPILER_NOT_AVAILABLE: return "CL_COMPILER_NOT_AVAILABLE";
    case CL_MEM_OBJECT_ALLOCATION_FAILURE: return "CL_MEM_OBJECT_ALLOCATION_FAILURE";
    case CL_OUT_OF_RESOURCES: return "CL_OUT_OF_RESOURCES";
    case CL_OUT_OF_HOST_MEMORY: return "CL_OUT_OF_HOST_MEMORY";
    case CL_BUILD_PROGRAM_FAILURE: return "CL_BUILD_PROGRAM_FAILURE";
    case CL_INVALID_VALUE: return "CL_INVALID_VALUE";
    case CL_INVALID_BINARY: return "CL_INVALID_BINARY";
    case CL_INVALID_BUILD_OPTIONS: return "CL_INVALID_BUILD_OPTIONS";
    case CL_INVALID_KERNEL_NAME: return "CL_INVALID_KERNEL_NAME";
    case CL_INVALID_KERNEL_ARGS: return "CL_INVALID_KERNEL_ARGS";
    case CL_INVALID_WORK_GROUP_SIZE: return "CL_INVALID_WORK_GROUP_SIZE";
    case CL_INVALID_BUFFER_SIZE: return "CL_INVALID_BUFFER_SIZE";
    case -1001: return "CL_PLATFORM_NOT_FOUND_KHR";
    default: return "an OpenCL error";
    }
}

void mfmm_cl_device_string(const ocl *cl, cl_device_info what, char *buf, size_t n)
{
    buf[0] = '\0';
    if (cl->api->clGetDeviceInfo(cl->device, what, n, buf, NULL) != CL_SUCCESS)
        buf[0] = '\0';
    buf[n - 1] = '\0';
}

static int ci_contains(const char *hay, const char *needle)
{
    size_t n = strlen(needle);
    for (; *hay; hay++) {
        size_t i = 0;
        while (i < n && hay[i] &&
               tolower((unsigned char)hay[i]) == tolower((unsigned char)needle[i]))
            i++;
        if (i == n)
            return 1;
    }
    return n == 0;
}

/* Whether a device can run the program: float64 and a compiler. */
static int device_usable(const mfmm_cl_api *api, cl_device_id d)
{
    cl_device_fp_config fp64 = 0;
    cl_bool compiler = CL_FALSE;
    return api->clGetDeviceInfo(d, CL_DEVICE_DOUBLE_FP_CONFIG, sizeof fp64, &fp64, NULL) ==
               CL_SUCCESS &&
           fp64 != 0 &&
           api->clGetDeviceInfo(d, CL_DEVICE_COMPILER_AVAILABLE, sizeof compiler, &compiler,
                                NULL) == CL_SUCCESS &&
           compiler;
}

static int device_is_cpu(const mfmm_cl_api *api, cl_device_id d)
{
    cl_device_type t = 0;
    return api->clGetDeviceInfo(d, CL_DEVICE_TYPE, sizeof t, &t, NULL) == CL_SUCCESS &&
           (t & CL_DEVICE_TYPE_CPU) != 0;
}

mfmm_status mfmm_cl_select_device(ocl *cl, const char *want, mfmm_error *err)
{
    const mfmm_cl_api *api = cl->api;
    const char *from = "device option";
    if (!want) {
        want = getenv("MESHFMM_OPENCL_DEVICE");
        from = "MESHFMM_OPENCL_DEVICE";
    }
    cl_uint np = 0;
    cl_int e = api->clGetPlatformIDs(0, NULL, &np);
    if (e != CL_SUCCESS || np == 0)
        return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1, "no OpenCL platform (clGetPlatformIDs: %s)",
                         e != CL_SUCCESS ? mfmm_cl_error_name(e) : "0 platforms");
    if (np > 16)
        np = 16;
    cl_platform_id plats[16];
    if (api->clGetPlatformIDs(np, plats, NULL) != CL_SUCCESS)
        return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1, "clGetPlatformIDs failed");
    cl_device_id devs[64];
    cl_uint nd = 0;
    for (cl_uint p = 0; p < np && nd < 64; p++) {
        cl_uint k = 0;
        if (api->clGetDeviceIDs(plats[p], CL_DEVICE_TYPE_ALL, 64 - nd, devs + nd, &k) ==
            CL_SUCCESS)
            nd += k < 64 - nd ? k : 64 - nd;
    }
    if (nd == 0)
        return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1, "no OpenCL device on %u platform(s)",
                         (unsigned)np);
    int pick = -1;
    char name[256];
    if (want && *want) {
        char *end = NULL;
        long idx = strtol(want, &end, 10);
        if (end && end != want && *end == '\0') {
            if (idx < 0 || idx >= (long)nd)
                return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1,
                                 "%s is %s, but there are %u OpenCL device(s)", from, want,
                                 (unsigned)nd);
            pick = (int)idx;
        } else {
            for (cl_uint i = 0; i < nd && pick < 0; i++) {
                name[0] = '\0';
                if (api->clGetDeviceInfo(devs[i], CL_DEVICE_NAME, sizeof name, name, NULL) !=
                    CL_SUCCESS)
                    name[0] = '\0';
                name[sizeof name - 1] = '\0';
                if (ci_contains(name, want))
                    pick = (int)i;
            }
            if (pick < 0)
                return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1,
                                 "no OpenCL device name contains '%s' (%s)", want, from);
        }
    } else {
        /* a usable GPU or accelerator first (on a CPU the threads backend is
         * faster), then a usable CPU device, then the first */
        for (int pass = 0; pass < 2 && pick < 0; pass++)
            for (cl_uint i = 0; i < nd && pick < 0; i++)
                if (device_is_cpu(api, devs[i]) == pass && device_usable(api, devs[i]))
                    pick = (int)i;
        if (pick < 0)
            pick = 0;
    }
    cl->device = devs[pick];
    mfmm_cl_device_string(cl, CL_DEVICE_NAME, cl->name, sizeof cl->name);
    cl->cpu = device_is_cpu(api, cl->device);
    cl->named = want && *want;
    cl_device_fp_config fp64 = 0;
    if (api->clGetDeviceInfo(cl->device, CL_DEVICE_DOUBLE_FP_CONFIG, sizeof fp64, &fp64, NULL) !=
            CL_SUCCESS ||
        fp64 == 0)
        return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1,
                         "OpenCL device '%s' has no float64 support", cl->name);
    cl_bool ok = CL_FALSE;
    if (api->clGetDeviceInfo(cl->device, CL_DEVICE_COMPILER_AVAILABLE, sizeof ok, &ok, NULL) !=
            CL_SUCCESS ||
        !ok)
        return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1, "OpenCL device '%s' has no compiler",
                         cl->name);
    if (api->clGetDeviceInfo(cl->device, CL_DEVICE_GLOBAL_MEM_SIZE, sizeof cl->global_mem,
                             &cl->global_mem, NULL) != CL_SUCCESS ||
        api->clGetDeviceInfo(cl->device, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof cl->max_alloc,
                             &cl->max_alloc, NULL) != CL_SUCCESS ||
        api->clGetDeviceInfo(cl->device, CL_DEVICE_MAX_COMPUTE_UNITS, sizeof cl->compute_units,
                             &cl->compute_units, NULL) != CL_SUCCESS)
        return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1, "cannot query OpenCL device '%s'",
                         cl->name);
    if (cl->compute_units < 1)
        cl->compute_units = 1;
    return MFMM_OK;
}

/* Releases what one call made (its queue and kernel). */
void mfmm_cl_release_call(ocl *cl)
{
    if (cl->kernel)
        cl->api->clReleaseKernel(cl->kernel);
    if (cl->queue)
        cl->api->clReleaseCommandQueue(cl->queue);
    cl->kernel = NULL;
    cl->queue = NULL;
}

void mfmm_cl_release(ocl *cl)
{
    if (!cl->api)
        return;
    mfmm_cl_release_call(cl);
    if (cl->program)
        cl->api->clReleaseProgram(cl->program);
    if (cl->context)
        cl->api->clReleaseContext(cl->context);
    cl->program = NULL;
    cl->context = NULL;
}

/* A call's own queue and kernel on an open context. */
mfmm_status mfmm_cl_open_call(ocl *cl, int f64, int windows, mfmm_error *err)
{
    cl_int e;
    cl->queue = cl->api->clCreateCommandQueue(cl->context, cl->device, 0, &e);
    if (e != CL_SUCCESS)
        return mfmm_fail(err, MFMM_ERR_OPENCL_RUNTIME, -1, "clCreateCommandQueue on '%s': %s",
                         cl->name, mfmm_cl_error_name(e));
    const char *name = windows ? (f64 ? "windows_rows_f64" : "windows_rows_f32")
                               : (f64 ? "fmm_rows_f64" : "fmm_rows_f32");
    cl->kernel = cl->api->clCreateKernel(cl->program, name, &e);
    if (e != CL_SUCCESS)
        return mfmm_fail(err, MFMM_ERR_OPENCL_BUILD, -1, "clCreateKernel: %s", mfmm_cl_error_name(e));
    return MFMM_OK;
}

#else
typedef int mfmm_opencl_device_unused; /* ISO C: no empty translation unit */
#endif /* MESHFMM_HAVE_OPENCL */
