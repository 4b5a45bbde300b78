/* The OpenCL backend of mfmm_distance_matrix: device selection, the program
 * (kernels/fmm_rows.cl, embedded at build time) with its binary cached on
 * disk, batches of rows, one work-item per source. Without OpenCL at build
 * time it reports MFMM_ERR_NO_OPENCL. The device and the built program live
 * in an mfmm_opencl_context (the caller's, or one made for the call); a call's
 * queue, kernel and buffers are its own, so a context serves many threads. */
#include "rows.h"

#ifndef MESHFMM_HAVE_OPENCL

mfmm_status mfmm_opencl_context_create(mfmm_opencl_context **out, mfmm_error *err)
{
    mfmm_ok(err);
    if (!out)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "out (the context pointer) is NULL");
    *out = NULL;
    return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1,
                     "meshfmm was built without OpenCL (MESHFMM_WITH_OPENCL=OFF or not found)");
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
                     "meshfmm was built without OpenCL (MESHFMM_WITH_OPENCL=OFF or not found)");
}

#else

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <CL/cl.h>

extern const char mfmm_kernel_fmm_rows[];
extern const size_t mfmm_kernel_fmm_rows_len;

/* Program build options: no -cl-mad-enable, no -cl-fast-relaxed-math (the
 * kernel's FP_CONTRACT OFF keeps a*b+c unfused, like -ffp-contract=off).
 * Tunables of march.h get the C side's values, so both march alike. */
#define MFMM_STR2(x) #x
#define MFMM_STR(x) MFMM_STR2(x)
#ifdef MFMM_HEAP_ARITY
#define MFMM_CL_ARITY " -DMFMM_HEAP_ARITY=" MFMM_STR(MFMM_HEAP_ARITY)
#else
#define MFMM_CL_ARITY ""
#endif
static const char build_options[] = "-cl-std=CL1.2" MFMM_CL_ARITY;

static const char *cl_error_name(cl_int e)
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
    case CL_INVALID_KERNEL_ARGS: return "CL_INVALID_KERNEL_ARGS";
    case CL_INVALID_WORK_GROUP_SIZE: return "CL_INVALID_WORK_GROUP_SIZE";
    case CL_INVALID_BUFFER_SIZE: return "CL_INVALID_BUFFER_SIZE";
    case -1001: return "CL_PLATFORM_NOT_FOUND_KHR";
    default: return "an OpenCL error";
    }
}

/* ---- device selection ---- */

typedef struct ocl {
    cl_device_id device;
    cl_context context;
    cl_command_queue queue;
    cl_program program;
    cl_kernel kernel;
    char name[256];
    cl_ulong global_mem, max_alloc;
    cl_uint compute_units;
} ocl;

static void device_string(cl_device_id d, cl_device_info what, char *buf, size_t n)
{
    buf[0] = '\0';
    if (clGetDeviceInfo(d, what, n, buf, NULL) != CL_SUCCESS)
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

/* MESHFMM_OPENCL_DEVICE: an index into all devices of all platforms, or a
 * substring of a device's name; default the first CPU device, else the first. */
static mfmm_status select_device(ocl *cl, mfmm_error *err)
{
    cl_uint np = 0;
    cl_int e = clGetPlatformIDs(0, NULL, &np);
    if (e != CL_SUCCESS || np == 0)
        return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1, "no OpenCL platform (clGetPlatformIDs: %s)",
                         e != CL_SUCCESS ? cl_error_name(e) : "0 platforms");
    if (np > 16)
        np = 16;
    cl_platform_id plats[16];
    if (clGetPlatformIDs(np, plats, NULL) != CL_SUCCESS)
        return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1, "clGetPlatformIDs failed");
    cl_device_id devs[64];
    cl_uint nd = 0;
    for (cl_uint p = 0; p < np && nd < 64; p++) {
        cl_uint k = 0;
        if (clGetDeviceIDs(plats[p], CL_DEVICE_TYPE_ALL, 64 - nd, devs + nd, &k) == CL_SUCCESS)
            nd += k < 64 - nd ? k : 64 - nd;
    }
    if (nd == 0)
        return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1, "no OpenCL device on %u platform(s)",
                         (unsigned)np);
    const char *want = getenv("MESHFMM_OPENCL_DEVICE");
    int pick = -1;
    char name[256];
    if (want && *want) {
        char *end = NULL;
        long idx = strtol(want, &end, 10);
        if (end && *end == '\0') {
            if (idx < 0 || idx >= (long)nd)
                return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1,
                                 "MESHFMM_OPENCL_DEVICE=%s, but there are %u device(s)", want,
                                 (unsigned)nd);
            pick = (int)idx;
        } else {
            for (cl_uint i = 0; i < nd && pick < 0; i++) {
                device_string(devs[i], CL_DEVICE_NAME, name, sizeof name);
                if (ci_contains(name, want))
                    pick = (int)i;
            }
            if (pick < 0)
                return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1,
                                 "no OpenCL device name contains MESHFMM_OPENCL_DEVICE=%s", want);
        }
    } else {
        for (cl_uint i = 0; i < nd && pick < 0; i++) {
            cl_device_type t = 0;
            if (clGetDeviceInfo(devs[i], CL_DEVICE_TYPE, sizeof t, &t, NULL) == CL_SUCCESS &&
                (t & CL_DEVICE_TYPE_CPU))
                pick = (int)i;
        }
        if (pick < 0)
            pick = 0;
    }
    cl->device = devs[pick];
    device_string(cl->device, CL_DEVICE_NAME, cl->name, sizeof cl->name);
    cl_device_fp_config fp64 = 0;
    if (clGetDeviceInfo(cl->device, CL_DEVICE_DOUBLE_FP_CONFIG, sizeof fp64, &fp64, NULL) !=
            CL_SUCCESS ||
        fp64 == 0)
        return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1,
                         "OpenCL device '%s' has no float64 support", cl->name);
    cl_bool ok = CL_FALSE;
    if (clGetDeviceInfo(cl->device, CL_DEVICE_COMPILER_AVAILABLE, sizeof ok, &ok, NULL) !=
            CL_SUCCESS ||
        !ok)
        return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1, "OpenCL device '%s' has no compiler",
                         cl->name);
    if (clGetDeviceInfo(cl->device, CL_DEVICE_GLOBAL_MEM_SIZE, sizeof cl->global_mem,
                        &cl->global_mem, NULL) != CL_SUCCESS ||
        clGetDeviceInfo(cl->device, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof cl->max_alloc,
                        &cl->max_alloc, NULL) != CL_SUCCESS ||
        clGetDeviceInfo(cl->device, CL_DEVICE_MAX_COMPUTE_UNITS, sizeof cl->compute_units,
                        &cl->compute_units, NULL) != CL_SUCCESS)
        return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1, "cannot query OpenCL device '%s'",
                         cl->name);
    if (cl->compute_units < 1)
        cl->compute_units = 1;
    return MFMM_OK;
}

/* ---- the program, with its binary cached on disk ---- */

static uint64_t fnv1a(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 1099511628211ull;
    }
    return h;
}

static uint64_t fnv_str(uint64_t h, const char *s)
{
    return fnv1a(h, s, strlen(s) + 1);
}

/* Key of a binary: kernel source, device, driver and build options. */
static uint64_t program_key(const ocl *cl)
{
    char buf[512];
    uint64_t h = 14695981039346656037ull;
    h = fnv1a(h, mfmm_kernel_fmm_rows, mfmm_kernel_fmm_rows_len);
    h = fnv_str(h, build_options);
    h = fnv_str(h, cl->name);
    device_string(cl->device, CL_DEVICE_VERSION, buf, sizeof buf);
    h = fnv_str(h, buf);
    device_string(cl->device, CL_DRIVER_VERSION, buf, sizeof buf);
    h = fnv_str(h, buf);
    cl_platform_id plat = NULL;
    if (clGetDeviceInfo(cl->device, CL_DEVICE_PLATFORM, sizeof plat, &plat, NULL) ==
            CL_SUCCESS &&
        clGetPlatformInfo(plat, CL_PLATFORM_VERSION, sizeof buf, buf, NULL) == CL_SUCCESS) {
        buf[sizeof buf - 1] = '\0';
        h = fnv_str(h, buf);
    }
    return h;
}

/* The cache folder: $MESHFMM_CACHE_DIR, else $XDG_CACHE_HOME/meshfmm, else
 * $HOME/.cache/meshfmm. 0 when none can be named. */
static int cache_dir(char *out, size_t n)
{
    const char *d = getenv("MESHFMM_CACHE_DIR");
    int k;
    if (d && *d)
        k = snprintf(out, n, "%s", d);
    else if ((d = getenv("XDG_CACHE_HOME")) && *d)
        k = snprintf(out, n, "%s/meshfmm", d);
    else if ((d = getenv("HOME")) && *d)
        k = snprintf(out, n, "%s/.cache/meshfmm", d);
    else
        return 0;
    return k > 0 && (size_t)k < n;
}

static void make_dirs(const char *path)
{
    char buf[1024];
    size_t n = strlen(path);
    if (n >= sizeof buf)
        return;
    memcpy(buf, path, n + 1);
    for (size_t i = 1; i <= n; i++) {
        if (buf[i] == '/' || buf[i] == '\0') {
            char c = buf[i];
            buf[i] = '\0';
            mkdir(buf, 0755); /* errors show up when the file is written */
            buf[i] = c;
        }
    }
}

/* Cache file: magic, key, size, binary, FNV of the binary. */
static const char cache_magic[8] = {'M', 'F', 'M', 'M', 'C', 'L', 'B', '1'};

static unsigned char *cache_load(const char *path, uint64_t key, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char magic[8];
    uint64_t k = 0, n = 0, sum = 0;
    unsigned char *bin = NULL;
    if (fread(magic, 1, 8, f) != 8 || memcmp(magic, cache_magic, 8) != 0 ||
        fread(&k, sizeof k, 1, f) != 1 || k != key || fread(&n, sizeof n, 1, f) != 1 ||
        n == 0 || n > ((uint64_t)1 << 31))
        goto bad;
    bin = malloc((size_t)n);
    if (!bin || fread(bin, 1, (size_t)n, f) != (size_t)n || fread(&sum, sizeof sum, 1, f) != 1 ||
        sum != fnv1a(14695981039346656037ull, bin, (size_t)n))
        goto bad;
    fclose(f);
    *size = (size_t)n;
    return bin;
bad:
    free(bin);
    fclose(f);
    return NULL;
}

/* Best effort: an unwritable cache is not an error. Written to a temporary
 * name and renamed, so readers never see half a file. */
static void cache_store(const char *dir, const char *path, uint64_t key, const unsigned char *bin,
                        size_t n)
{
    char tmp[1200];
    make_dirs(dir);
    /* pid and a stack address: unique among processes and concurrent calls */
    if (snprintf(tmp, sizeof tmp, "%s.%ld.%p.tmp", path, (long)getpid(), (void *)tmp) >=
        (int)sizeof tmp)
        return;
    FILE *f = fopen(tmp, "wb");
    if (!f)
        return;
    uint64_t k = key, len = n, sum = fnv1a(14695981039346656037ull, bin, n);
    int ok = fwrite(cache_magic, 1, 8, f) == 8 && fwrite(&k, sizeof k, 1, f) == 1 &&
             fwrite(&len, sizeof len, 1, f) == 1 && fwrite(bin, 1, n, f) == n &&
             fwrite(&sum, sizeof sum, 1, f) == 1;
    ok = (fclose(f) == 0) && ok;
    if (!ok || rename(tmp, path) != 0)
        remove(tmp);
}

static void build_log(const ocl *cl, cl_program prog, char *out, size_t n)
{
    out[0] = '\0';
    size_t len = 0;
    if (clGetProgramBuildInfo(prog, cl->device, CL_PROGRAM_BUILD_LOG, 0, NULL, &len) !=
            CL_SUCCESS ||
        len == 0)
        return;
    char *log = malloc(len + 1);
    if (!log)
        return;
    if (clGetProgramBuildInfo(prog, cl->device, CL_PROGRAM_BUILD_LOG, len, log, NULL) ==
        CL_SUCCESS) {
        log[len] = '\0';
        /* first non-blank line */
        char *s = log;
        while (*s && isspace((unsigned char)*s))
            s++;
        size_t k = strcspn(s, "\n");
        if (k >= n)
            k = n - 1;
        memcpy(out, s, k);
        out[k] = '\0';
    }
    free(log);
}

/* Builds from the cached binary when there is a valid one, else from source
 * (then stores the binary). */
static mfmm_status build_program(ocl *cl, mfmm_error *err)
{
    char dir[1024], path[1100];
    uint64_t key = program_key(cl);
    int have_dir = cache_dir(dir, sizeof dir);
    if (have_dir && snprintf(path, sizeof path, "%s/fmm_rows-%016llx.bin", dir,
                             (unsigned long long)key) >= (int)sizeof path)
        have_dir = 0;
    cl_int e;
    if (have_dir) {
        size_t n = 0;
        unsigned char *bin = cache_load(path, key, &n);
        if (bin) {
            const unsigned char *bins[1] = {bin};
            cl_int bin_status = CL_SUCCESS;
            cl_program prog = clCreateProgramWithBinary(cl->context, 1, &cl->device, &n, bins,
                                                        &bin_status, &e);
            free(bin);
            if (e == CL_SUCCESS && bin_status == CL_SUCCESS &&
                clBuildProgram(prog, 1, &cl->device, build_options, NULL, NULL) == CL_SUCCESS) {
                cl->program = prog;
                return MFMM_OK;
            }
            if (prog)
                clReleaseProgram(prog);
            remove(path); /* corrupt or stale: rebuilt below */
        }
    }
    const char *src = mfmm_kernel_fmm_rows;
    size_t len = mfmm_kernel_fmm_rows_len;
    cl_program prog = clCreateProgramWithSource(cl->context, 1, &src, &len, &e);
    if (e != CL_SUCCESS)
        return mfmm_fail(err, MFMM_ERR_OPENCL_BUILD, -1, "clCreateProgramWithSource: %s",
                         cl_error_name(e));
    e = clBuildProgram(prog, 1, &cl->device, build_options, NULL, NULL);
    if (e != CL_SUCCESS) {
        char log[160];
        build_log(cl, prog, log, sizeof log);
        clReleaseProgram(prog);
        return mfmm_fail(err, MFMM_ERR_OPENCL_BUILD, -1, "building the kernel for '%s': %s%s%s",
                         cl->name, cl_error_name(e), log[0] ? ": " : "", log);
    }
    cl->program = prog;
    if (have_dir) {
        size_t n = 0;
        if (clGetProgramInfo(prog, CL_PROGRAM_BINARY_SIZES, sizeof n, &n, NULL) == CL_SUCCESS &&
            n > 0) {
            unsigned char *bin = malloc(n);
            unsigned char *bins[1] = {bin};
            if (bin && clGetProgramInfo(prog, CL_PROGRAM_BINARIES, sizeof bins, bins, NULL) ==
                           CL_SUCCESS)
                cache_store(dir, path, key, bin, n);
            free(bin);
        }
    }
    return MFMM_OK;
}

/* Releases what one call made (its queue and kernel). */
static void ocl_release_call(ocl *cl)
{
    if (cl->kernel)
        clReleaseKernel(cl->kernel);
    if (cl->queue)
        clReleaseCommandQueue(cl->queue);
    cl->kernel = NULL;
    cl->queue = NULL;
}

static void ocl_release(ocl *cl)
{
    ocl_release_call(cl);
    if (cl->program)
        clReleaseProgram(cl->program);
    if (cl->context)
        clReleaseContext(cl->context);
    memset(cl, 0, sizeof *cl);
}

/* Device, context and built program. */
static mfmm_status ocl_open(ocl *cl, mfmm_error *err)
{
    memset(cl, 0, sizeof *cl);
    mfmm_status st = select_device(cl, err);
    if (st != MFMM_OK)
        return st;
    cl_int e;
    cl->context = clCreateContext(NULL, 1, &cl->device, NULL, NULL, &e);
    if (e != CL_SUCCESS)
        return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1, "clCreateContext on '%s': %s", cl->name,
                         cl_error_name(e));
    return build_program(cl, err);
}

/* A call's own queue and kernel on an open context. */
static mfmm_status ocl_open_call(ocl *cl, int f64, mfmm_error *err)
{
    cl_int e;
    cl->queue = clCreateCommandQueue(cl->context, cl->device, 0, &e);
    if (e != CL_SUCCESS)
        return mfmm_fail(err, MFMM_ERR_OPENCL_RUNTIME, -1, "clCreateCommandQueue on '%s': %s",
                         cl->name, cl_error_name(e));
    cl->kernel = clCreateKernel(cl->program, f64 ? "fmm_rows_f64" : "fmm_rows_f32", &e);
    if (e != CL_SUCCESS)
        return mfmm_fail(err, MFMM_ERR_OPENCL_BUILD, -1, "clCreateKernel: %s", cl_error_name(e));
    return MFMM_OK;
}

struct mfmm_opencl_context {
    ocl cl; /* device, context, program; no queue or kernel */
};

mfmm_status mfmm_opencl_context_create(mfmm_opencl_context **out, mfmm_error *err)
{
    mfmm_ok(err);
    if (!out)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "out (the context pointer) is NULL");
    *out = NULL;
    mfmm_opencl_context *ctx = calloc(1, sizeof *ctx);
    if (!ctx)
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, NULL);
    mfmm_status st = ocl_open(&ctx->cl, err);
    if (st != MFMM_OK) {
        ocl_release(&ctx->cl);
        free(ctx);
        return st;
    }
    *out = ctx;
    return MFMM_OK;
}

void mfmm_opencl_context_destroy(mfmm_opencl_context *context)
{
    if (!context)
        return;
    ocl_release(&context->cl);
    free(context);
}

const char *mfmm_opencl_context_device_name(const mfmm_opencl_context *context)
{
    return context ? context->cl.name : "";
}

/* ---- rows ---- */

enum { MB_OFFSET, MB_CORNER, MB_CORNERS, MB_COST, MB_SOURCES, MB_STRIP, MB_UNIFORM, MB_LABEL, MB_KEY, MB_VERT,
       MB_POS, MB_T, MB_OUT, MB_COUNT };

/* Bytes per work-item on the device (workspace and output row), and on the
 * host (two blocks when rows are not read straight into the caller's buffer). */
static size_t item_bytes(const mfmm_rows_job *job, int direct)
{
    size_t nv = (size_t)job->mesh->nv;
    size_t b = nv * (1 + 8 + 4 + 4) + nv * job->elem_size;
    if (job->elem_size != sizeof(double))
        b += nv * 8;
    if (!direct)
        b += 2 * nv * job->elem_size;
    return b;
}

static int32_t batch_rows(const ocl *cl, const mfmm_rows_job *job, int direct, int32_t rows)
{
    size_t nv = (size_t)job->mesh->nv;
    size_t budget = job->budget;
    if (budget > cl->global_mem / 2)
        budget = (size_t)(cl->global_mem / 2);
    size_t b = budget / item_bytes(job, direct);
    size_t by_alloc = (size_t)(cl->max_alloc / (nv * 8)); /* the largest buffer: 8 nv per item */
    if (b > by_alloc)
        b = by_alloc;
    if (b > 4096)
        b = 4096;
    size_t cu = cl->compute_units;
    if (b > cu)
        b -= b % cu; /* whole rounds over the compute units */
    if (b < 1)
        b = 1;
    if (b > (size_t)rows)
        b = (size_t)rows;
    return (int32_t)b;
}

static mfmm_status runtime_fail(mfmm_error *err, const char *what, cl_int e)
{
    return mfmm_fail(err, MFMM_ERR_OPENCL_RUNTIME, -1, "%s: %s (%d)", what, cl_error_name(e),
                     (int)e);
}

mfmm_status mfmm_opencl_rows(const mfmm_rows_job *job, int32_t start, int32_t *rows_done,
                             mfmm_error *err)
{
    *rows_done = 0;
    int32_t rows = job->n_sources - start;
    if (rows <= 0)
        return MFMM_OK;
    const mfmm_mesh *mesh = job->mesh;
    int f64 = job->elem_size == sizeof(double);
    int direct = job->opt->out != NULL;
    mfmm_opencl_context *own = NULL, *ctx = job->opt->opencl;
    if (!ctx) {
        mfmm_status cs = mfmm_opencl_context_create(&own, err);
        if (cs != MFMM_OK)
            return cs;
        ctx = own;
    }
    ocl cl = ctx->cl; /* shared handles, plus this call's queue and kernel */
    mfmm_status st = ocl_open_call(&cl, f64, err);
    if (st != MFMM_OK) {
        ocl_release_call(&cl);
        mfmm_opencl_context_destroy(own);
        return st;
    }
    cl_mem mem[MB_COUNT];
    memset(mem, 0, sizeof mem);
    char *host = NULL;
    double *uniform = NULL;
    cl_event ev[2] = {NULL, NULL};
    cl_int e = CL_SUCCESS;
    size_t nv = (size_t)mesh->nv;
    size_t row_bytes = nv * job->elem_size;
    double one = 1.0;

    /* the mesh, read-only, used in place where the driver allows */
    cl_mem_flags ro = CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR;
    size_t n_upd = 2 * (size_t)mesh->update_offset[mesh->nv]; /* (corner, vertex) pairs */
    mem[MB_OFFSET] = clCreateBuffer(cl.context, ro, (nv + 1) * sizeof(int32_t),
                                    mesh->update_offset, &e);
    if (e == CL_SUCCESS)
        mem[MB_CORNER] = clCreateBuffer(cl.context, ro, (n_upd ? n_upd : 1) * sizeof(int32_t),
                                        n_upd ? (void *)mesh->update_corner : (void *)&one, &e);
    if (e == CL_SUCCESS)
        mem[MB_CORNERS] = clCreateBuffer(cl.context, ro,
                                         (size_t)mesh->nf * 3 * sizeof(mfmm_corner),
                                         mesh->corners, &e);
    if (e == CL_SUCCESS) {
        size_t nc = job->cost_location == 1 ? nv : job->cost_location == 2 ? (size_t)mesh->nf : 1;
        mem[MB_COST] = clCreateBuffer(cl.context, ro, nc * sizeof(double),
                                      job->cost ? (void *)job->cost : (void *)&one, &e);
    }
    if (e == CL_SUCCESS)
        mem[MB_SOURCES] = clCreateBuffer(cl.context, ro, (size_t)job->n_sources * sizeof(int32_t),
                                         (void *)job->sources, &e);
    if (e == CL_SUCCESS) /* virtual edges' strips (march.h) */
        mem[MB_STRIP] = clCreateBuffer(cl.context, ro,
                                       (size_t)mesh->strip[3 * (size_t)mesh->nf] * sizeof(int32_t),
                                       mesh->strip, &e);
    /* with a cost: the cost around each vertex, for the virtual stencils
     * (march.h), once for the job */
    if (e == CL_SUCCESS && job->cost && job->opt->unfolding) {
        uniform = malloc(nv * sizeof *uniform);
        if (!uniform) {
            st = mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for %d costs", (int)nv);
            goto done;
        }
        mfmm_uniform_cost(mesh, job->cost, job->cost_location, uniform);
    }
    if (e == CL_SUCCESS)
        mem[MB_UNIFORM] = clCreateBuffer(cl.context, ro, (uniform ? nv : 1) * sizeof(double),
                                         uniform ? (void *)uniform : (void *)&one, &e);
    if (e != CL_SUCCESS) {
        st = runtime_fail(err, "uploading the mesh", e);
        goto done;
    }

    /* workspaces for a batch; halved until the device accepts them */
    int32_t batch = batch_rows(&cl, job, direct, rows);
    for (;;) {
        size_t b = (size_t)batch;
        mem[MB_LABEL] = clCreateBuffer(cl.context, CL_MEM_READ_WRITE, b * nv, NULL, &e);
        if (e == CL_SUCCESS)
            mem[MB_KEY] = clCreateBuffer(cl.context, CL_MEM_READ_WRITE, b * nv * 8, NULL, &e);
        if (e == CL_SUCCESS)
            mem[MB_VERT] = clCreateBuffer(cl.context, CL_MEM_READ_WRITE, b * nv * 4, NULL, &e);
        if (e == CL_SUCCESS)
            mem[MB_POS] = clCreateBuffer(cl.context, CL_MEM_READ_WRITE, b * nv * 4, NULL, &e);
        if (e == CL_SUCCESS && !f64)
            mem[MB_T] = clCreateBuffer(cl.context, CL_MEM_READ_WRITE, b * nv * 8, NULL, &e);
        if (e == CL_SUCCESS)
            mem[MB_OUT] = clCreateBuffer(cl.context, CL_MEM_READ_WRITE, b * row_bytes, NULL, &e);
        if (e == CL_SUCCESS && !direct) {
            host = malloc(2 * b * row_bytes);
            if (!host)
                e = CL_OUT_OF_HOST_MEMORY;
        }
        if (e == CL_SUCCESS)
            break;
        for (int i = MB_LABEL; i < MB_COUNT; i++)
            if (mem[i]) {
                clReleaseMemObject(mem[i]);
                mem[i] = NULL;
            }
        free(host);
        host = NULL;
        if (batch == 1) {
            st = runtime_fail(err, "allocating workspaces for one row", e);
            goto done;
        }
        batch /= 2;
    }

    /* fixed kernel arguments */
    cl_int nvi = (cl_int)nv, cl_loc = job->cost_location, unfold = job->opt->unfolding != 0;
    cl_double maxd = job->opt->max_distance;
    e = clSetKernelArg(cl.kernel, 0, sizeof nvi, &nvi);
    e |= clSetKernelArg(cl.kernel, 1, sizeof(cl_mem), &mem[MB_OFFSET]);
    e |= clSetKernelArg(cl.kernel, 2, sizeof(cl_mem), &mem[MB_CORNER]);
    e |= clSetKernelArg(cl.kernel, 3, sizeof(cl_mem), &mem[MB_CORNERS]);
    e |= clSetKernelArg(cl.kernel, 4, sizeof(cl_mem), &mem[MB_COST]);
    e |= clSetKernelArg(cl.kernel, 5, sizeof cl_loc, &cl_loc);
    e |= clSetKernelArg(cl.kernel, 6, sizeof maxd, &maxd);
    e |= clSetKernelArg(cl.kernel, 7, sizeof unfold, &unfold);
    e |= clSetKernelArg(cl.kernel, 8, sizeof(cl_mem), &mem[MB_SOURCES]);
    e |= clSetKernelArg(cl.kernel, 11, sizeof(cl_mem), &mem[MB_LABEL]);
    e |= clSetKernelArg(cl.kernel, 12, sizeof(cl_mem), &mem[MB_KEY]);
    e |= clSetKernelArg(cl.kernel, 13, sizeof(cl_mem), &mem[MB_VERT]);
    e |= clSetKernelArg(cl.kernel, 14, sizeof(cl_mem), &mem[MB_POS]);
    if (f64) {
        e |= clSetKernelArg(cl.kernel, 15, sizeof(cl_mem), &mem[MB_OUT]);
        e |= clSetKernelArg(cl.kernel, 16, sizeof(cl_mem), &mem[MB_STRIP]);
        e |= clSetKernelArg(cl.kernel, 17, sizeof(cl_mem), &mem[MB_UNIFORM]);
    } else {
        e |= clSetKernelArg(cl.kernel, 15, sizeof(cl_mem), &mem[MB_T]);
        e |= clSetKernelArg(cl.kernel, 16, sizeof(cl_mem), &mem[MB_OUT]);
        e |= clSetKernelArg(cl.kernel, 17, sizeof(cl_mem), &mem[MB_STRIP]);
        e |= clSetKernelArg(cl.kernel, 18, sizeof(cl_mem), &mem[MB_UNIFORM]);
    }
    if (e != CL_SUCCESS) {
        st = runtime_fail(err, "clSetKernelArg", e);
        goto done;
    }

    /* Batch k runs while the host delivers batch k-1: in an in-order queue,
     * kernel k+1 is enqueued after the read of batch k. */
    int32_t n_batches = (rows + batch - 1) / batch;
    for (int32_t k = 0; k <= n_batches; k++) {
        if (k < n_batches) {
            cl_int first = start + k * batch;
            cl_int count = job->n_sources - first < batch ? job->n_sources - first : batch;
            size_t global = (size_t)count, local = 1;
            e = clSetKernelArg(cl.kernel, 9, sizeof first, &first);
            e |= clSetKernelArg(cl.kernel, 10, sizeof count, &count);
            if (e != CL_SUCCESS) {
                st = runtime_fail(err, "clSetKernelArg", e);
                goto done;
            }
            e = clEnqueueNDRangeKernel(cl.queue, cl.kernel, 1, NULL, &global, &local, 0, NULL,
                                       NULL);
            if (e != CL_SUCCESS) {
                st = runtime_fail(err, "clEnqueueNDRangeKernel", e);
                goto done;
            }
            void *dst = direct ? (char *)job->opt->out + (size_t)first * row_bytes
                               : host + (size_t)(k & 1) * (size_t)batch * row_bytes;
            e = clEnqueueReadBuffer(cl.queue, mem[MB_OUT], CL_FALSE, 0,
                                    (size_t)count * row_bytes, dst, 0, NULL, &ev[k & 1]);
            if (e != CL_SUCCESS) {
                st = runtime_fail(err, "clEnqueueReadBuffer", e);
                goto done;
            }
            clFlush(cl.queue);
        }
        if (k > 0) {
            int32_t j = k - 1;
            cl_event wait = ev[j & 1];
            ev[j & 1] = NULL;
            e = clWaitForEvents(1, &wait);
            cl_int status = CL_COMPLETE;
            if (e == CL_SUCCESS)
                e = clGetEventInfo(wait, CL_EVENT_COMMAND_EXECUTION_STATUS, sizeof status,
                                   &status, NULL);
            clReleaseEvent(wait);
            if (e == CL_SUCCESS && status < 0)
                e = status;
            if (e != CL_SUCCESS) {
                st = runtime_fail(err, "running the kernel", e);
                goto done;
            }
            int32_t first = start + j * batch;
            int32_t count = job->n_sources - first < batch ? job->n_sources - first : batch;
            const void *rowsp = direct ? (char *)job->opt->out + (size_t)first * row_bytes
                                       : host + (size_t)(j & 1) * (size_t)batch * row_bytes;
            if (mfmm_rows_deliver(job, first, count, rowsp)) {
                st = mfmm_fail(err, MFMM_ERR_CANCELLED, first, "cancelled by the row callback");
                goto done;
            }
            *rows_done += count;
        }
    }
    st = MFMM_OK;
done:
    if (cl.queue)
        clFinish(cl.queue);
    for (int i = 0; i < 2; i++)
        if (ev[i])
            clReleaseEvent(ev[i]);
    for (int i = 0; i < MB_COUNT; i++)
        if (mem[i])
            clReleaseMemObject(mem[i]);
    free(host);
    free(uniform);
    ocl_release_call(&cl);
    mfmm_opencl_context_destroy(own);
    return st;
}

#endif /* MESHFMM_HAVE_OPENCL */
