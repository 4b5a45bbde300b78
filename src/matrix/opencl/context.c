/* The OpenCL backend of mfmm_distance_matrix, its public face: the options,
 * an mfmm_opencl_context (the loader's table, the device and the built
 * program: the caller's, or one made for the call) and mfmm_opencl_rows,
 * which runs a job's rows on it (rows.c). A call's queue, kernel and
 * buffers are its own, so a context serves many threads. Without the OpenCL
 * headers at build time every entry reports MFMM_ERR_NO_OPENCL. */
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "context.h"

void mfmm_opencl_options_init(mfmm_opencl_options *options)
{
    if (!options)
        return;
    memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
    options->device = NULL;
    options->cache_dir = NULL;
    options->library = NULL;
}

/* mfmm_opencl_context_create's argument checks, with or without OpenCL;
 * opt receives the options (the defaults past the caller's struct_size). */
static mfmm_status check_create_args(const mfmm_opencl_options *options,
                                     mfmm_opencl_options *opt, mfmm_opencl_context **out,
                                     mfmm_error *err)
{
    mfmm_ok(err);
    mfmm_opencl_options_init(opt);
    if (!out)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "out (the context pointer) is NULL");
    *out = NULL;
    if (options && mfmm_read_options(opt, options, sizeof *opt, "mfmm_opencl_options", err) !=
                       MFMM_OK)
        return MFMM_ERR_BAD_ARGUMENT;
    return MFMM_OK;
}

#ifndef MESHFMM_HAVE_OPENCL

mfmm_status mfmm_opencl_context_create(const mfmm_opencl_options *options,
                                       mfmm_opencl_context **out, mfmm_error *err)
{
    mfmm_opencl_options opt;
    mfmm_status st = check_create_args(options, &opt, out, err);
    if (st != MFMM_OK)
        return st;
    return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1,
                     "meshfmm was built without OpenCL (MESHFMM_WITH_OPENCL=OFF or no "
                     "OpenCL headers)");
}

void mfmm_opencl_context_destroy(mfmm_opencl_context *context)
{
    (void)context;
}

const char *mfmm_opencl_context_device_name(const mfmm_opencl_context *context)
{
    (void)context;
    return "";
}

mfmm_status mfmm_opencl_rows(const mfmm_rows_job *job, int32_t start, int32_t *rows_done,
                             mfmm_error *err)
{
    (void)job;
    (void)start;
    if (rows_done)
        *rows_done = 0;
    return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1,
                     "meshfmm was built without OpenCL (MESHFMM_WITH_OPENCL=OFF or no "
                     "OpenCL headers)");
}

#else

#include "cache.h"
#include "device.h"
#include "loader.h"
#include "rows.h"

/* Device, context and built program. */
/* Under auto: a CPU device the caller did not name is left to the threads
 * backend, which runs the same rows on the same cores faster
 * (docs/performance.md, "Backends on a CPU"). */
static mfmm_status auto_refuses(const ocl *cl, const mfmm_rows_job *job, mfmm_error *err)
{
    if (!job->full_batches || !cl->cpu || cl->named)
        return MFMM_OK;
    return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1,
                     "OpenCL device '%s' is a CPU, where the threads backend runs the same rows "
                     "faster (name the device or ask for opencl to use it)",
                     cl->name);
}

/* Opens device, context and program; job: a job under auto (the device may
 * be refused before anything is built), or NULL. */
static mfmm_status ocl_open(ocl *cl, const mfmm_opencl_options *o, const mfmm_rows_job *job,
                            mfmm_error *err)
{
    mfmm_status st = mfmm_cl_select_device(cl, o ? o->device : NULL, err);
    if (st == MFMM_OK && job)
        st = auto_refuses(cl, job, err);
    if (st != MFMM_OK)
        return st;
    cl_int e;
    cl->context = cl->api->clCreateContext(NULL, 1, &cl->device, NULL, NULL, &e);
    if (e != CL_SUCCESS)
        return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1, "clCreateContext on '%s': %s", cl->name,
                         mfmm_cl_error_name(e));
    return mfmm_cl_build_program(cl, o ? o->cache_dir : NULL, err);
}

struct mfmm_opencl_context {
    mfmm_cl_api api; /* the loader's entry points */
    ocl cl;          /* device, context, program; no queue or kernel */
};

static mfmm_status context_create(const mfmm_opencl_options *options, const mfmm_rows_job *job,
                                  mfmm_opencl_context **out, mfmm_error *err)
{
    mfmm_opencl_options opt;
    mfmm_status st = check_create_args(options, &opt, out, err);
    if (st != MFMM_OK)
        return st;
    mfmm_opencl_context *ctx = calloc(1, sizeof *ctx);
    if (!ctx)
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, NULL);
    st = mfmm_cl_api_load(&ctx->api, opt.library, err);
    if (st != MFMM_OK) {
        free(ctx);
        return st;
    }
    ctx->cl.api = &ctx->api;
    st = ocl_open(&ctx->cl, &opt, job, err);
    if (st != MFMM_OK) {
        mfmm_opencl_context_destroy(ctx);
        return st;
    }
    *out = ctx;
    return MFMM_OK;
}

mfmm_status mfmm_opencl_context_create(const mfmm_opencl_options *options,
                                       mfmm_opencl_context **out, mfmm_error *err)
{
    return context_create(options, NULL, out, err);
}

void mfmm_opencl_context_destroy(mfmm_opencl_context *context)
{
    if (!context)
        return;
    mfmm_cl_release(&context->cl);
    mfmm_cl_api_unload(&context->api);
    free(context);
}

const char *mfmm_opencl_context_device_name(const mfmm_opencl_context *context)
{
    return context ? context->cl.name : "";
}

mfmm_status mfmm_opencl_rows(const mfmm_rows_job *job, int32_t start, int32_t *rows_done,
                             mfmm_error *err)
{
    *rows_done = 0;
    if (job->n_sources - start <= 0)
        return MFMM_OK;
    mfmm_opencl_context *own = NULL, *ctx = job->opt->opencl;
    if (!ctx) {
        mfmm_status cs = context_create(job->opt->opencl_options, job, &own, err);
        if (cs != MFMM_OK)
            return cs;
        ctx = own;
    } else if (auto_refuses(&ctx->cl, job, err) != MFMM_OK) {
        return MFMM_ERR_NO_OPENCL;
    }
    mfmm_status st = mfmm_cl_run_rows(&ctx->cl, job, start, rows_done, err);
    mfmm_opencl_context_destroy(own);
    return st;
}

#endif /* MESHFMM_HAVE_OPENCL */
