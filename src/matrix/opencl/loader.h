/* Internal: the OpenCL entry points meshfmm uses, resolved at run time from
 * the ICD loader (dlopen), so that libmeshfmm does not link libOpenCL and
 * loads on machines without it. A table lives in each mfmm_opencl_context:
 * no global state. Needs only the OpenCL headers at build time. */
#ifndef MFMM_MATRIX_OPENCL_LOADER_H
#define MFMM_MATRIX_OPENCL_LOADER_H

#include "meshfmm.h"

#ifdef MESHFMM_HAVE_OPENCL
#include <CL/cl.h>

/* One member per entry point, named as the function. */
typedef struct mfmm_cl_api {
    void *handle; /* from dlopen; NULL when not loaded */
    cl_int (*clGetPlatformIDs)(cl_uint, cl_platform_id *, cl_uint *);
    cl_int (*clGetPlatformInfo)(cl_platform_id, cl_platform_info, size_t, void *, size_t *);
    cl_int (*clGetDeviceIDs)(cl_platform_id, cl_device_type, cl_uint, cl_device_id *,
                             cl_uint *);
    cl_int (*clGetDeviceInfo)(cl_device_id, cl_device_info, size_t, void *, size_t *);
    cl_context (*clCreateContext)(const cl_context_properties *, cl_uint, const cl_device_id *,
                                  void(CL_CALLBACK *)(const char *, const void *, size_t,
                                                      void *),
                                  void *, cl_int *);
    cl_int (*clReleaseContext)(cl_context);
    cl_program (*clCreateProgramWithSource)(cl_context, cl_uint, const char **, const size_t *,
                                            cl_int *);
    cl_program (*clCreateProgramWithBinary)(cl_context, cl_uint, const cl_device_id *,
                                            const size_t *, const unsigned char **, cl_int *,
                                            cl_int *);
    cl_int (*clBuildProgram)(cl_program, cl_uint, const cl_device_id *, const char *,
                             void(CL_CALLBACK *)(cl_program, void *), void *);
    cl_int (*clGetProgramBuildInfo)(cl_program, cl_device_id, cl_program_build_info, size_t,
                                    void *, size_t *);
    cl_int (*clGetProgramInfo)(cl_program, cl_program_info, size_t, void *, size_t *);
    cl_int (*clReleaseProgram)(cl_program);
    cl_command_queue (*clCreateCommandQueue)(cl_context, cl_device_id,
                                             cl_command_queue_properties, cl_int *);
    cl_int (*clReleaseCommandQueue)(cl_command_queue);
    cl_kernel (*clCreateKernel)(cl_program, const char *, cl_int *);
    cl_int (*clReleaseKernel)(cl_kernel);
    cl_mem (*clCreateBuffer)(cl_context, cl_mem_flags, size_t, void *, cl_int *);
    cl_int (*clReleaseMemObject)(cl_mem);
    cl_int (*clSetKernelArg)(cl_kernel, cl_uint, size_t, const void *);
    cl_int (*clEnqueueNDRangeKernel)(cl_command_queue, cl_kernel, cl_uint, const size_t *,
                                     const size_t *, const size_t *, cl_uint, const cl_event *,
                                     cl_event *);
    cl_int (*clEnqueueReadBuffer)(cl_command_queue, cl_mem, cl_bool, size_t, size_t, void *,
                                  cl_uint, const cl_event *, cl_event *);
    cl_int (*clFlush)(cl_command_queue);
    cl_int (*clFinish)(cl_command_queue);
    cl_int (*clWaitForEvents)(cl_uint, const cl_event *);
    cl_int (*clGetEventInfo)(cl_event, cl_event_info, size_t, void *, size_t *);
    cl_int (*clReleaseEvent)(cl_event);
} mfmm_cl_api;

/* Opens `library` (NULL: $MESHFMM_OPENCL_LIBRARY, else "libOpenCL.so.1") and
 * resolves every entry point. MFMM_ERR_NO_OPENCL, with dlerror's reason or
 * the missing symbol, when it cannot; *api is then empty. */
mfmm_status mfmm_cl_api_load(mfmm_cl_api *api, const char *library, mfmm_error *err);

/* Forgets the table (the library stays loaded; see loader.c). */
void mfmm_cl_api_unload(mfmm_cl_api *api);

#endif /* MESHFMM_HAVE_OPENCL */
#endif
