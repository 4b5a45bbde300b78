/* An OpenCL device as the backend holds it: the loader's table, the device
 * picked, its context, program, and a call's queue and kernel (device.c;
 * private to the library). */
#ifndef MFMM_OPENCL_DEVICE_H
#define MFMM_OPENCL_DEVICE_H

#ifdef MESHFMM_HAVE_OPENCL

#include "loader.h"

typedef struct ocl {
    const mfmm_cl_api *api; /* the context's loader table */
    cl_device_id device;
    cl_context context;
    cl_command_queue queue;
    cl_program program;
    cl_kernel kernel;
    char name[256];
    cl_ulong global_mem, max_alloc;
    cl_uint compute_units;
    int cpu;   /* the device is a CPU (PoCL's, say) */
    int named; /* the caller named it (option or MESHFMM_OPENCL_DEVICE) */
} ocl;

/* The name of an OpenCL error code, for messages. */
const char *mfmm_cl_error_name(cl_int e);

/* `want` (options, else MESHFMM_OPENCL_DEVICE): an index into all devices of
 * all platforms, or a substring of a device's name; default the first usable
 * (float64, compiler) device that is not a CPU, else the first usable CPU
 * device, else the first. Fills cl's device fields (cl->api set). */
mfmm_status mfmm_cl_select_device(ocl *cl, const char *want, mfmm_error *err);

/* A string of cl's device (CL_DEVICE_NAME, say) into buf (n bytes; "" on
 * failure). */
void mfmm_cl_device_string(const ocl *cl, cl_device_info what, char *buf, size_t n);

/* A call's own queue and kernel on an open context: the march's rows
 * (fmm_rows_*) or, with windows set, the window method's (windows_rows_*),
 * float64 or float32. */
mfmm_status mfmm_cl_open_call(ocl *cl, int f64, int windows, mfmm_error *err);

/* Releases what one call made (its queue and kernel). */
void mfmm_cl_release_call(ocl *cl);

/* Releases the call's objects, the program and the context. */
void mfmm_cl_release(ocl *cl);

#endif /* MESHFMM_HAVE_OPENCL */
#endif
