/* The OpenCL backend of mfmm_distance_matrix: OpenCL loaded at run time
 * (opencl_loader.c), device selection, the program (kernels/fmm_rows.cl,
 * embedded at build time) with its binary cached on disk, batches of rows,
 * one work-item per source. Without the OpenCL headers at build time it
 * reports MFMM_ERR_NO_OPENCL. The loader's table, the device and the built
 * program live in an mfmm_opencl_context (the caller's, or one made for the
 * call); a call's queue, kernel and buffers are its own, so a context serves
 * many threads. */
#include <string.h>

#include "base/error.h"
#include "matrix/rows.h"
#include "loader.h"
#include "mesh/check.h"
#include "mesh/spokes.h"
#include "start/seed.h"

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

/* mfmm_opencl_context_create's argument checks, with or without OpenCL. */
static mfmm_status check_create_args(const mfmm_opencl_options *options,
                                     mfmm_opencl_context **out, mfmm_error *err)
{
    mfmm_ok(err);
    if (!out)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "out (the context pointer) is NULL");
    *out = NULL;
    if (options && mfmm_check_struct_size(options, sizeof *options, "mfmm_opencl_options",
                                          err) != MFMM_OK)
        return MFMM_ERR_BAD_ARGUMENT;
    return MFMM_OK;
}

#ifndef MESHFMM_HAVE_OPENCL

mfmm_status mfmm_opencl_context_create(const mfmm_opencl_options *options,
                                       mfmm_opencl_context **out, mfmm_error *err)
{
    mfmm_status st = check_create_args(options, out, err);
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

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

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
    case CL_INVALID_KERNEL_NAME: return "CL_INVALID_KERNEL_NAME";
    case CL_INVALID_KERNEL_ARGS: return "CL_INVALID_KERNEL_ARGS";
    case CL_INVALID_WORK_GROUP_SIZE: return "CL_INVALID_WORK_GROUP_SIZE";
    case CL_INVALID_BUFFER_SIZE: return "CL_INVALID_BUFFER_SIZE";
    case -1001: return "CL_PLATFORM_NOT_FOUND_KHR";
    default: return "an OpenCL error";
    }
}

/* ---- device selection ---- */

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

static void device_string(const ocl *cl, cl_device_info what, char *buf, size_t n)
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

/* `want` (options, else MESHFMM_OPENCL_DEVICE): an index into all devices of
 * all platforms, or a substring of a device's name; default the first CPU
 * device, else the first. */
static mfmm_status select_device(ocl *cl, const char *want, mfmm_error *err)
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
                         e != CL_SUCCESS ? cl_error_name(e) : "0 platforms");
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
        for (cl_uint i = 0; i < nd && pick < 0; i++) {
            cl_device_type t = 0;
            if (api->clGetDeviceInfo(devs[i], CL_DEVICE_TYPE, sizeof t, &t, NULL) ==
                    CL_SUCCESS &&
                (t & CL_DEVICE_TYPE_CPU))
                pick = (int)i;
        }
        if (pick < 0)
            pick = 0;
    }
    cl->device = devs[pick];
    device_string(cl, CL_DEVICE_NAME, cl->name, sizeof cl->name);
    cl_device_type type = 0;
    cl->cpu = api->clGetDeviceInfo(cl->device, CL_DEVICE_TYPE, sizeof type, &type, NULL) ==
                  CL_SUCCESS &&
              (type & CL_DEVICE_TYPE_CPU) != 0;
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

/* ---- the program, with its binary cached on disk ----
 * An entry is fmm_rows-<hash>.bin, <hash> the FNV-1a of its key: a text
 * naming everything the binary depends on (library version, kernel source,
 * build options, platform, device, driver). The file holds the key itself,
 * the binary and a checksum; a binary is used only when its key text equals
 * ours, and only after a self-test on a small mesh against the serial core.
 * The checksum is keyed with a random secret kept in the folder (file
 * `secret`, mode 0600): drivers parse binaries without checks (PoCL 3.1
 * crashes in clCreateProgramWithBinary on a binary with bytes changed inside),
 * so an entry altered by anything but this library, its plain checksum
 * recomputed or not, never reaches the driver. Whatever fails (read, checksum,
 * key, load, build, self-test) makes the program be built from source and the
 * entry be replaced. Files are written to a temporary file made exclusively
 * beside them and renamed (the secret: linked) into place. */

static uint64_t fnv1a(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 1099511628211ull;
    }
    return h;
}

#define MFMM_FNV_BASIS 14695981039346656037ull

/* The key text of ocl's device; 0 when it does not fit. */
static int program_key(const ocl *cl, char *key, size_t n)
{
    char dev_ver[256], drv_ver[256], plat_name[256], plat_ver[256];
    device_string(cl, CL_DEVICE_VERSION, dev_ver, sizeof dev_ver);
    device_string(cl, CL_DRIVER_VERSION, drv_ver, sizeof drv_ver);
    plat_name[0] = plat_ver[0] = '\0';
    cl_platform_id plat = NULL;
    if (cl->api->clGetDeviceInfo(cl->device, CL_DEVICE_PLATFORM, sizeof plat, &plat, NULL) ==
        CL_SUCCESS) {
        if (cl->api->clGetPlatformInfo(plat, CL_PLATFORM_NAME, sizeof plat_name, plat_name,
                                       NULL) != CL_SUCCESS)
            plat_name[0] = '\0';
        if (cl->api->clGetPlatformInfo(plat, CL_PLATFORM_VERSION, sizeof plat_ver, plat_ver,
                                       NULL) != CL_SUCCESS)
            plat_ver[0] = '\0';
        plat_name[sizeof plat_name - 1] = plat_ver[sizeof plat_ver - 1] = '\0';
    }
    uint64_t src = fnv1a(MFMM_FNV_BASIS, mfmm_kernel_fmm_rows, mfmm_kernel_fmm_rows_len);
    int k = snprintf(key, n,
                     "meshfmm %s\nkernel fmm_rows.cl %zu bytes fnv1a %016llx\n"
                     "build options %s\nplatform %s | %s\ndevice %s | %s\ndriver %s\n",
                     mfmm_version(), mfmm_kernel_fmm_rows_len, (unsigned long long)src,
                     build_options, plat_name, plat_ver, cl->name, dev_ver, drv_ver);
    return k > 0 && (size_t)k < n;
}

/* The cache folder: the option, else $MESHFMM_CACHE_DIR, else
 * $XDG_CACHE_HOME/meshfmm, else $HOME/.cache/meshfmm. 0 when there is none
 * (the option is "", or nothing names one). */
static int cache_dir(const char *option, char *out, size_t n)
{
    const char *d;
    int k;
    if (option)
        k = *option ? snprintf(out, n, "%s", option) : -1;
    else if ((d = getenv("MESHFMM_CACHE_DIR")) && *d)
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
            mkdir(buf, 0700); /* errors show up when the file is written */
            buf[i] = c;
        }
    }
}

/* The folder's secret (16 bytes), made on first use; 0 when it can be
 * neither read nor made (no disk cache then). */
static int cache_secret(const char *dir, unsigned char secret[16])
{
    char path[1100], tmp[1200];
    if (snprintf(path, sizeof path, "%s/secret", dir) >= (int)sizeof path ||
        snprintf(tmp, sizeof tmp, "%s.XXXXXX", path) >= (int)sizeof tmp)
        return 0;
    for (int attempt = 0; attempt < 2; attempt++) {
        FILE *f = fopen(path, "rb");
        if (f) {
            int ok = fread(secret, 1, 16, f) == 16 && fgetc(f) == EOF;
            fclose(f);
            return ok;
        }
        if (attempt > 0)
            return 0;
        make_dirs(dir);
        FILE *r = fopen("/dev/urandom", "rb");
        if (!r)
            return 0;
        int got = fread(secret, 1, 16, r) == 16;
        fclose(r);
        int fd = got ? mkstemp(tmp) : -1; /* mode 0600 */
        if (fd < 0)
            return 0;
        int ok = write(fd, secret, 16) == 16;
        ok = close(fd) == 0 && ok;
        /* link, unlike rename, keeps a secret another process made first */
        if (ok && link(tmp, path) == 0) {
            unlink(tmp);
            return 1;
        }
        unlink(tmp);
    }
    return 0;
}

/* The entry's checksum: FNV-1a over secret, key text, binary, secret. */
static uint64_t cache_sum(const unsigned char secret[16], const char *key, size_t key_len,
                          const unsigned char *bin, size_t n)
{
    uint64_t h = fnv1a(MFMM_FNV_BASIS, secret, 16);
    h = fnv1a(h, key, key_len);
    h = fnv1a(h, bin, n);
    return fnv1a(h, secret, 16);
}

/* File: magic, key length, key text, binary length, binary, cache_sum.
 * All integers uint64 in host order. */
static const char cache_magic[8] = {'M', 'F', 'M', 'M', 'C', 'L', 'B', '2'};
#define MFMM_CACHE_MAX_BINARY ((uint64_t)1 << 30)

static unsigned char *cache_load(const char *path, const unsigned char secret[16],
                                 const char *key, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char magic[8];
    size_t key_len = strlen(key);
    uint64_t klen = 0, n = 0, sum = 0;
    unsigned char *bin = NULL;
    char *k = NULL;
    if (fread(magic, 1, 8, f) != 8 || memcmp(magic, cache_magic, 8) != 0 ||
        fread(&klen, sizeof klen, 1, f) != 1 || klen != key_len)
        goto bad;
    k = malloc(key_len + 1);
    if (!k || fread(k, 1, key_len, f) != key_len || memcmp(k, key, key_len) != 0 ||
        fread(&n, sizeof n, 1, f) != 1 || n == 0 || n > MFMM_CACHE_MAX_BINARY)
        goto bad;
    bin = malloc((size_t)n);
    if (!bin || fread(bin, 1, (size_t)n, f) != (size_t)n || fread(&sum, sizeof sum, 1, f) != 1 ||
        fgetc(f) != EOF || sum != cache_sum(secret, key, key_len, bin, (size_t)n))
        goto bad;
    free(k);
    fclose(f);
    *size = (size_t)n;
    return bin;
bad:
    free(k);
    free(bin);
    fclose(f);
    return NULL;
}

/* Best effort: an unwritable cache is not an error. */
static void cache_store(const char *path, const unsigned char secret[16], const char *key,
                        const unsigned char *bin, size_t n)
{
    char tmp[1200];
    if (snprintf(tmp, sizeof tmp, "%s.XXXXXX", path) >= (int)sizeof tmp)
        return;
    int fd = mkstemp(tmp); /* a new, unique file (O_CREAT | O_EXCL) */
    if (fd < 0)
        return;
    FILE *f = fdopen(fd, "wb");
    if (!f) {
        close(fd);
        remove(tmp);
        return;
    }
    uint64_t klen = strlen(key), len = n;
    uint64_t sum = cache_sum(secret, key, (size_t)klen, bin, n);
    int ok = fwrite(cache_magic, 1, 8, f) == 8 && fwrite(&klen, sizeof klen, 1, f) == 1 &&
             fwrite(key, 1, (size_t)klen, f) == (size_t)klen &&
             fwrite(&len, sizeof len, 1, f) == 1 && fwrite(bin, 1, n, f) == n &&
             fwrite(&sum, sizeof sum, 1, f) == 1;
    ok = fflush(f) == 0 && ok;
    ok = fchmod(fd, 0644) == 0 && ok;
    ok = (fclose(f) == 0) && ok;
    if (!ok || rename(tmp, path) != 0)
        remove(tmp);
}

static void build_log(const ocl *cl, cl_program prog, char *out, size_t n)
{
    out[0] = '\0';
    size_t len = 0;
    if (cl->api->clGetProgramBuildInfo(prog, cl->device, CL_PROGRAM_BUILD_LOG, 0, NULL, &len) !=
            CL_SUCCESS ||
        len == 0)
        return;
    char *log = malloc(len + 1);
    if (!log)
        return;
    if (cl->api->clGetProgramBuildInfo(prog, cl->device, CL_PROGRAM_BUILD_LOG, len, log, NULL) ==
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

static mfmm_status self_test(ocl *cl, mfmm_error *err);

/* A program from a cached binary, built and self-tested; NULL when any step
 * fails. */
static cl_program program_from_cache(ocl *cl, const char *path,
                                     const unsigned char secret[16], const char *key)
{
    size_t n = 0;
    unsigned char *bin = cache_load(path, secret, key, &n);
    if (!bin)
        return NULL;
    const unsigned char *bins[1] = {bin};
    cl_int bin_status = CL_SUCCESS, e = CL_SUCCESS;
    cl_program prog =
        cl->api->clCreateProgramWithBinary(cl->context, 1, &cl->device, &n, bins, &bin_status, &e);
    free(bin);
    if (e != CL_SUCCESS || bin_status != CL_SUCCESS || !prog ||
        cl->api->clBuildProgram(prog, 1, &cl->device, build_options, NULL, NULL) != CL_SUCCESS) {
        if (prog)
            cl->api->clReleaseProgram(prog);
        return NULL;
    }
    cl->program = prog;
    if (self_test(cl, NULL) != MFMM_OK) {
        cl->program = NULL;
        cl->api->clReleaseProgram(prog);
        return NULL;
    }
    cl->program = NULL;
    return prog;
}

/* Builds from the cached binary when there is a valid one, else from source
 * (then stores the binary, replacing a bad entry). */
static mfmm_status build_program(ocl *cl, const char *cache_option, mfmm_error *err)
{
    char dir[1024], path[1100], key[2048];
    unsigned char secret[16];
    int have_dir = program_key(cl, key, sizeof key) && cache_dir(cache_option, dir, sizeof dir) &&
                   cache_secret(dir, secret);
    if (have_dir && snprintf(path, sizeof path, "%s/fmm_rows-%016llx.bin", dir,
                             (unsigned long long)fnv1a(MFMM_FNV_BASIS, key, strlen(key))) >=
                        (int)sizeof path)
        have_dir = 0;
    if (have_dir) {
        cl_program prog = program_from_cache(cl, path, secret, key);
        if (prog) {
            cl->program = prog;
            return MFMM_OK;
        }
    }
    cl_int e;
    const char *src = mfmm_kernel_fmm_rows;
    size_t len = mfmm_kernel_fmm_rows_len;
    cl_program prog = cl->api->clCreateProgramWithSource(cl->context, 1, &src, &len, &e);
    if (e != CL_SUCCESS)
        return mfmm_fail(err, MFMM_ERR_OPENCL_BUILD, -1, "clCreateProgramWithSource: %s",
                         cl_error_name(e));
    e = cl->api->clBuildProgram(prog, 1, &cl->device, build_options, NULL, NULL);
    if (e != CL_SUCCESS) {
        char log[160];
        build_log(cl, prog, log, sizeof log);
        cl->api->clReleaseProgram(prog);
        return mfmm_fail(err, MFMM_ERR_OPENCL_BUILD, -1, "building the kernel for '%s': %s%s%s",
                         cl->name, cl_error_name(e), log[0] ? ": " : "", log);
    }
    cl->program = prog;
    /* only a program that passes the self-test is cached (a cached one must pass it) */
    if (have_dir && self_test(cl, NULL) == MFMM_OK) {
        size_t n = 0;
        if (cl->api->clGetProgramInfo(prog, CL_PROGRAM_BINARY_SIZES, sizeof n, &n, NULL) ==
                CL_SUCCESS &&
            n > 0 && n <= MFMM_CACHE_MAX_BINARY) {
            unsigned char *bin = malloc(n);
            unsigned char *bins[1] = {bin};
            if (bin && cl->api->clGetProgramInfo(prog, CL_PROGRAM_BINARIES, sizeof bins, bins,
                                                 NULL) == CL_SUCCESS)
                cache_store(path, secret, key, bin, n);
            free(bin);
        }
    }
    return MFMM_OK;
}

/* Releases what one call made (its queue and kernel). */
static void ocl_release_call(ocl *cl)
{
    if (cl->kernel)
        cl->api->clReleaseKernel(cl->kernel);
    if (cl->queue)
        cl->api->clReleaseCommandQueue(cl->queue);
    cl->kernel = NULL;
    cl->queue = NULL;
}

static void ocl_release(ocl *cl)
{
    if (!cl->api)
        return;
    ocl_release_call(cl);
    if (cl->program)
        cl->api->clReleaseProgram(cl->program);
    if (cl->context)
        cl->api->clReleaseContext(cl->context);
    cl->program = NULL;
    cl->context = NULL;
}

/* Device, context and built program. */
/* Under auto: a CPU device the caller did not name is left to the threads
 * backend, which runs the same rows on the same cores faster (measured:
 * camelhead 2000 rows, wall 0.86-0.93x of OpenCL's; README "Command line"). */
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
    mfmm_status st = select_device(cl, o ? o->device : NULL, err);
    if (st == MFMM_OK && job)
        st = auto_refuses(cl, job, err);
    if (st != MFMM_OK)
        return st;
    cl_int e;
    cl->context = cl->api->clCreateContext(NULL, 1, &cl->device, NULL, NULL, &e);
    if (e != CL_SUCCESS)
        return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1, "clCreateContext on '%s': %s", cl->name,
                         cl_error_name(e));
    return build_program(cl, o ? o->cache_dir : NULL, err);
}

/* A call's own queue and kernel on an open context. */
static mfmm_status ocl_open_call(ocl *cl, int f64, mfmm_error *err)
{
    cl_int e;
    cl->queue = cl->api->clCreateCommandQueue(cl->context, cl->device, 0, &e);
    if (e != CL_SUCCESS)
        return mfmm_fail(err, MFMM_ERR_OPENCL_RUNTIME, -1, "clCreateCommandQueue on '%s': %s",
                         cl->name, cl_error_name(e));
    cl->kernel = cl->api->clCreateKernel(cl->program, f64 ? "fmm_rows_f64" : "fmm_rows_f32", &e);
    if (e != CL_SUCCESS)
        return mfmm_fail(err, MFMM_ERR_OPENCL_BUILD, -1, "clCreateKernel: %s", cl_error_name(e));
    return MFMM_OK;
}

struct mfmm_opencl_context {
    mfmm_cl_api api; /* the loader's entry points */
    ocl cl;          /* device, context, program; no queue or kernel */
};

static mfmm_status context_create(const mfmm_opencl_options *options, const mfmm_rows_job *job,
                                  mfmm_opencl_context **out, mfmm_error *err)
{
    mfmm_status st = check_create_args(options, out, err);
    if (st != MFMM_OK)
        return st;
    mfmm_opencl_context *ctx = calloc(1, sizeof *ctx);
    if (!ctx)
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, NULL);
    st = mfmm_cl_api_load(&ctx->api, options ? options->library : NULL, err);
    if (st != MFMM_OK) {
        free(ctx);
        return st;
    }
    ctx->cl.api = &ctx->api;
    st = ocl_open(&ctx->cl, options, job, err);
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
    ocl_release(&context->cl);
    mfmm_cl_api_unload(&context->api);
    free(context);
}

const char *mfmm_opencl_context_device_name(const mfmm_opencl_context *context)
{
    return context ? context->cl.name : "";
}

/* ---- rows ---- */

enum { MB_OFFSET, MB_CORNER, MB_CORNERS, MB_COST, MB_SOURCES, MB_STRIP, MB_UNIFORM, MB_TARGETS, MB_ORDER, MB_VIRTS, MB_STRIPOFF, MB_VFIRST, MB_SPOKEOFF, MB_SPOKES, MB_LABEL, MB_KEY, MB_VERT,
       MB_POS, MB_T, MB_OUT, MB_COUNT };

/* Bytes per work-item on the device (workspace and output row), and on the
 * host (two blocks when rows are not read straight into the caller's buffer). */
static size_t item_bytes(const mfmm_rows_job *job, int direct)
{
    size_t nv = (size_t)job->mesh->nv, w = (size_t)job->width;
    /* label, heap key, vertex and position, T apart from the output row */
    size_t b = nv * (1 + 8 + 4 + 4 + 8) + w * job->elem_size;
    if (!direct)
        b += 2 * w * job->elem_size;
    return b;
}

/* Rows per batch: as many as the budget holds (at most 4096), in whole
 * rounds over the compute units. With the default budget (memory_limit 0) a
 * batch holds at least one row per compute unit, so that every core works
 * whatever the mesh size (a 16 MiB budget held one row of a 227k-vertex
 * mesh, and OpenCL ran on one core). */
static int32_t batch_rows(const ocl *cl, const mfmm_rows_job *job, int direct, int32_t rows)
{
    size_t nv = (size_t)job->mesh->nv;
    size_t budget = job->budget;
    size_t per_round = (size_t)cl->compute_units * item_bytes(job, direct);
    if (job->opt->memory_limit == 0 && budget < per_round)
        budget = per_round;
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

/* OpenCL keeps fewer compute units busy than threads would cores: a batch
 * smaller than both the compute units and the rows left. */
static int starved(const ocl *cl, int32_t batch, int32_t rows)
{
    int32_t want = (int32_t)(cl->compute_units < (cl_uint)rows ? cl->compute_units : (cl_uint)rows);
    return batch < want;
}

/* A batch's exact-start seeds (solve/seed.h), as the kernel reads them:
 * idx[0 .. count] the rows' ranges [idx[i], idx[i + 1]) of idx (vertices)
 * and val (values; its first count + 1 entries unused); n entries used. */
typedef struct seed_buf {
    int32_t *idx;
    double *val;
    size_t cap, n;
    int64_t fallbacks; /* patch vertices left to the march (mfmm_exact_start) */
} seed_buf;

static int seed_room(seed_buf *b, size_t need)
{
    if (need <= b->cap)
        return 0;
    size_t cap = b->cap ? b->cap : 1024;
    while (cap < need)
        cap *= 2;
    int32_t *idx = realloc(b->idx, cap * sizeof *idx);
    if (idx)
        b->idx = idx;
    double *val = idx ? realloc(b->val, cap * sizeof *val) : NULL;
    if (val)
        b->val = val;
    if (!idx || !val)
        return -1;
    b->cap = cap;
    return 0;
}

/* The seeds of rows [first, first + count), computed as the serial solver
 * computes them (solve.c's seed_source with a vertex source at value 0). */
static mfmm_status batch_seeds(const mfmm_rows_job *job, mfmm_exact_ws **ws,
                               const double *uniform, int32_t first, int32_t count, seed_buf *b)
{
    size_t pos = (size_t)count + 1;
    if (seed_room(b, pos))
        return MFMM_ERR_OUT_OF_MEMORY;
    for (size_t i = 0; i < pos; i++)
        b->val[i] = 0.0;
    for (int32_t i = 0; i < count; i++) {
        mfmm_source src;
        memset(&src, 0, sizeof src);
        src.vertex = job->sources[first + i];
        src.face = -1;
        src.value = 0.0;
        int32_t n = 0;
        const int32_t *pv = NULL;
        const double *pd = NULL;
        double f = 1.0;
        int32_t n_fallback = 0;
        mfmm_status st = mfmm_exact_start(job->mesh, ws, &src, job->opt->exact_start_radius,
                                          job->opt->max_distance, job->cost,
                                          job->cost ? uniform : NULL, &n, &pv, &pd, &f,
                                          &n_fallback);
        if (st != MFMM_OK)
            return st;
        b->fallbacks += n_fallback;
        b->idx[i] = (int32_t)pos;
        if (seed_room(b, pos + (size_t)(n > 0 ? n : 1)))
            return MFMM_ERR_OUT_OF_MEMORY;
        if (n == 0) { /* the straight start of a vertex: the vertex */
            b->idx[pos] = src.vertex;
            b->val[pos++] = src.value;
        }
        for (int32_t j = 0; j < n; j++) {
            b->idx[pos] = pv[j];
            b->val[pos++] = src.value + f * pd[j];
        }
    }
    b->idx[count] = (int32_t)pos;
    b->n = pos;
    return MFMM_OK;
}

/* Rows [start, n_sources) of the job on `shared`'s device and program, with
 * this call's own queue, kernel and buffers. */
static mfmm_status run_rows(const ocl *shared, const mfmm_rows_job *job, int32_t start,
                            int32_t *rows_done, mfmm_error *err)
{
    *rows_done = 0;
    int32_t rows = job->n_sources - start;
    if (rows <= 0)
        return MFMM_OK;
    const mfmm_mesh *mesh = job->mesh;
    int f64 = job->elem_size == sizeof(double);
    int direct = job->opt->out != NULL;
    ocl cl = *shared; /* shared handles, plus this call's queue and kernel */
    const mfmm_cl_api *api = cl.api;
    mfmm_status st = ocl_open_call(&cl, f64, err);
    if (st != MFMM_OK) {
        ocl_release_call(&cl);
        return st;
    }
    cl_mem mem[MB_COUNT];
    memset(mem, 0, sizeof mem);
    char *host = NULL;
    double *uniform = NULL;
    cl_event ev[2] = {NULL, NULL};
    cl_int e = CL_SUCCESS;
    size_t nv = (size_t)mesh->nv;
    size_t row_bytes = (size_t)job->width * job->elem_size;
    double one = 1.0;
    int32_t no_target = 0;
    cl_int n_targets = job->targets ? (cl_int)job->width : 0;
    int exact = mfmm_exact_start_on(job->opt->exact_start_radius);
    mfmm_exact_ws *ews = NULL;
    seed_buf sb;
    memset(&sb, 0, sizeof sb);

    /* the mesh, read-only, used in place where the driver allows */
    cl_mem_flags ro = CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR;
    /* (the march's arrays, march.h: x's faces, face records, virtual edges) */
    size_t n_wedge = 3 * (size_t)mesh->nf;
    mem[MB_OFFSET] = api->clCreateBuffer(cl.context, ro, (nv + 1) * sizeof(int32_t),
                                    mesh->vertex_face_offset, &e);
    if (e == CL_SUCCESS)
        mem[MB_CORNER] = api->clCreateBuffer(cl.context, ro, n_wedge * sizeof(int32_t),
                                        mesh->vertex_wedge, &e);
    if (e == CL_SUCCESS)
        mem[MB_CORNERS] = api->clCreateBuffer(cl.context, ro,
                                         (size_t)mesh->nf * sizeof(mfmm_face),
                                         mesh->face_records, &e);
    if (e == CL_SUCCESS) {
        size_t nc = job->cost_location == 1 ? nv : job->cost_location == 2 ? (size_t)mesh->nf : 1;
        mem[MB_COST] = api->clCreateBuffer(cl.context, ro, nc * sizeof(double),
                                      job->cost ? (void *)job->cost : (void *)&one, &e);
    }
    if (e == CL_SUCCESS)
        mem[MB_SOURCES] = api->clCreateBuffer(cl.context, ro, (size_t)job->n_sources * sizeof(int32_t),
                                         (void *)job->sources, &e);
    /* each slot's corner, virtual edges' strips (march.h) */
    size_t n_strip = (size_t)mesh->virt_strip[mesh->n_virts];
    if (e == CL_SUCCESS)
        mem[MB_STRIP] = api->clCreateBuffer(cl.context, ro, (n_strip ? n_strip : 1) * sizeof(int32_t),
                                            mesh->strip, &e);
    if (e == CL_SUCCESS)
        mem[MB_VIRTS] = api->clCreateBuffer(cl.context, ro,
                                              (mesh->n_virts ? (size_t)mesh->n_virts : 1) *
                                                  sizeof(mfmm_virt),
                                              mesh->virts, &e);
    if (e == CL_SUCCESS)
        mem[MB_VFIRST] = api->clCreateBuffer(cl.context, ro, (nv + 1) * sizeof(int32_t),
                                             mesh->virt_first, &e);
    if (e == CL_SUCCESS)
        mem[MB_STRIPOFF] = api->clCreateBuffer(cl.context, ro,
                                               ((size_t)mesh->n_virts + 1) * sizeof(int32_t),
                                               mesh->virt_strip, &e);
    /* F = 1 with unfolding: the mesh's spokes (march.h), as the serial
     * solver reads them (solve.c); out of memory: the face walk, which
     * gives the same rows */
    const int32_t *spoke_offset = NULL;
    const mfmm_spoke *spokes = NULL;
    if (!job->cost && job->opt->unfolding)
        (void)mfmm_mesh_spokes_of(mesh, &spoke_offset, &spokes);
    cl_int use_spokes = spokes != NULL;
    if (e == CL_SUCCESS)
        mem[MB_SPOKEOFF] = api->clCreateBuffer(cl.context, ro, (use_spokes ? nv + 1 : 1) * sizeof(int32_t),
                                               use_spokes ? (void *)spoke_offset : (void *)&no_target, &e);
    if (e == CL_SUCCESS)
        mem[MB_SPOKES] = api->clCreateBuffer(cl.context, ro,
                                             use_spokes ? (size_t)spoke_offset[nv] * sizeof(mfmm_spoke)
                                                        : sizeof(double),
                                             use_spokes ? (void *)spokes : (void *)&one, &e);
    /* with a cost: the cost around each vertex, for the virtual stencils
     * (march.h), once for the job */
    if (e == CL_SUCCESS && job->cost && (job->opt->unfolding || exact)) {
        uniform = malloc(nv * sizeof *uniform);
        if (!uniform) {
            st = mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for %d costs", (int)nv);
            goto done;
        }
        mfmm_uniform_cost(mesh, job->cost, job->cost_location, uniform);
    }
    if (e == CL_SUCCESS)
        mem[MB_UNIFORM] = api->clCreateBuffer(cl.context, ro, (uniform ? nv : 1) * sizeof(double),
                                         uniform ? (void *)uniform : (void *)&one, &e);
    if (e == CL_SUCCESS)
        mem[MB_TARGETS] = api->clCreateBuffer(cl.context, ro,
                                              (job->targets ? (size_t)job->width : 1) * sizeof(int32_t),
                                              job->targets ? (void *)job->targets : (void *)&no_target,
                                              &e);
    if (e == CL_SUCCESS) /* rows gathered into the caller's vertex order */
        mem[MB_ORDER] = api->clCreateBuffer(cl.context, ro, nv * sizeof(int32_t),
                                            mesh->to_internal, &e);
    if (e != CL_SUCCESS) {
        st = runtime_fail(err, "uploading the mesh", e);
        goto done;
    }

    /* workspaces for a batch; halved until the device accepts them */
    int32_t batch = batch_rows(&cl, job, direct, rows);
    for (;;) {
        if (job->full_batches && starved(&cl, batch, rows)) {
            st = mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1,
                           "OpenCL would run %d row(s) at a time on %u compute units "
                           "(memory_limit %zu bytes, %zu per row); threads keep every core busy",
                           (int)batch, (unsigned)cl.compute_units, job->budget,
                           item_bytes(job, direct));
            goto done;
        }
        size_t b = (size_t)batch;
        mem[MB_LABEL] = api->clCreateBuffer(cl.context, CL_MEM_READ_WRITE, b * nv, NULL, &e);
        if (e == CL_SUCCESS)
            mem[MB_KEY] = api->clCreateBuffer(cl.context, CL_MEM_READ_WRITE, b * nv * 8, NULL, &e);
        if (e == CL_SUCCESS)
            mem[MB_VERT] = api->clCreateBuffer(cl.context, CL_MEM_READ_WRITE, b * nv * 4, NULL, &e);
        if (e == CL_SUCCESS)
            mem[MB_POS] = api->clCreateBuffer(cl.context, CL_MEM_READ_WRITE, b * nv * 4, NULL, &e);
        if (e == CL_SUCCESS)
            mem[MB_T] = api->clCreateBuffer(cl.context, CL_MEM_READ_WRITE, b * nv * 8, NULL, &e);
        if (e == CL_SUCCESS)
            mem[MB_OUT] = api->clCreateBuffer(cl.context, CL_MEM_READ_WRITE, b * row_bytes, NULL, &e);
        if (e == CL_SUCCESS && !direct) {
            host = malloc(2 * b * row_bytes);
            if (!host)
                e = CL_OUT_OF_HOST_MEMORY;
        }
        if (e == CL_SUCCESS)
            break;
        for (int i = MB_LABEL; i < MB_COUNT; i++)
            if (mem[i]) {
                api->clReleaseMemObject(mem[i]);
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
    e = api->clSetKernelArg(cl.kernel, 0, sizeof nvi, &nvi);
    e |= api->clSetKernelArg(cl.kernel, 1, sizeof(cl_mem), &mem[MB_OFFSET]);
    e |= api->clSetKernelArg(cl.kernel, 2, sizeof(cl_mem), &mem[MB_CORNER]);
    e |= api->clSetKernelArg(cl.kernel, 3, sizeof(cl_mem), &mem[MB_CORNERS]);
    e |= api->clSetKernelArg(cl.kernel, 4, sizeof(cl_mem), &mem[MB_COST]);
    e |= api->clSetKernelArg(cl.kernel, 5, sizeof cl_loc, &cl_loc);
    e |= api->clSetKernelArg(cl.kernel, 6, sizeof maxd, &maxd);
    e |= api->clSetKernelArg(cl.kernel, 7, sizeof unfold, &unfold);
    e |= api->clSetKernelArg(cl.kernel, 8, sizeof(cl_mem), &mem[MB_SOURCES]);
    e |= api->clSetKernelArg(cl.kernel, 11, sizeof(cl_mem), &mem[MB_LABEL]);
    e |= api->clSetKernelArg(cl.kernel, 12, sizeof(cl_mem), &mem[MB_KEY]);
    e |= api->clSetKernelArg(cl.kernel, 13, sizeof(cl_mem), &mem[MB_VERT]);
    e |= api->clSetKernelArg(cl.kernel, 14, sizeof(cl_mem), &mem[MB_POS]);
    /* the float32 kernel's last workspace is unused: any buffer stands in */
    cl_mem t_ws = mem[MB_T];
    if (f64) {
        e |= api->clSetKernelArg(cl.kernel, 15, sizeof(cl_mem), &mem[MB_OUT]);
        e |= api->clSetKernelArg(cl.kernel, 16, sizeof(cl_mem), &mem[MB_STRIP]);
        e |= api->clSetKernelArg(cl.kernel, 17, sizeof(cl_mem), &mem[MB_UNIFORM]);
        e |= api->clSetKernelArg(cl.kernel, 18, sizeof(cl_mem), &mem[MB_TARGETS]);
        e |= api->clSetKernelArg(cl.kernel, 19, sizeof n_targets, &n_targets);
        e |= api->clSetKernelArg(cl.kernel, 20, sizeof(cl_mem), &t_ws);
        e |= api->clSetKernelArg(cl.kernel, 21, sizeof(cl_mem), &mem[MB_ORDER]);
        e |= api->clSetKernelArg(cl.kernel, 22, sizeof(cl_mem), &mem[MB_VIRTS]);
        e |= api->clSetKernelArg(cl.kernel, 23, sizeof(cl_mem), &mem[MB_STRIPOFF]);
    } else {
        e |= api->clSetKernelArg(cl.kernel, 15, sizeof(cl_mem), &mem[MB_T]);
        e |= api->clSetKernelArg(cl.kernel, 16, sizeof(cl_mem), &mem[MB_OUT]);
        e |= api->clSetKernelArg(cl.kernel, 17, sizeof(cl_mem), &mem[MB_STRIP]);
        e |= api->clSetKernelArg(cl.kernel, 18, sizeof(cl_mem), &mem[MB_UNIFORM]);
        e |= api->clSetKernelArg(cl.kernel, 19, sizeof(cl_mem), &mem[MB_TARGETS]);
        e |= api->clSetKernelArg(cl.kernel, 20, sizeof n_targets, &n_targets);
        e |= api->clSetKernelArg(cl.kernel, 21, sizeof(cl_mem), &t_ws);
        e |= api->clSetKernelArg(cl.kernel, 22, sizeof(cl_mem), &mem[MB_ORDER]);
        e |= api->clSetKernelArg(cl.kernel, 23, sizeof(cl_mem), &mem[MB_VIRTS]);
        e |= api->clSetKernelArg(cl.kernel, 24, sizeof(cl_mem), &mem[MB_STRIPOFF]);
    }
    /* the seeds (set per batch with the exact start; else unused) */
    cl_uint seed_arg = f64 ? 24 : 25;
    cl_int n_seeds = exact;
    e |= api->clSetKernelArg(cl.kernel, seed_arg, sizeof n_seeds, &n_seeds);
    e |= api->clSetKernelArg(cl.kernel, seed_arg + 1, sizeof(cl_mem), &mem[MB_SOURCES]);
    e |= api->clSetKernelArg(cl.kernel, seed_arg + 2, sizeof(cl_mem), &mem[MB_COST]);
    e |= api->clSetKernelArg(cl.kernel, seed_arg + 3, sizeof(cl_mem), &mem[MB_VFIRST]);
    e |= api->clSetKernelArg(cl.kernel, seed_arg + 4, sizeof use_spokes, &use_spokes);
    e |= api->clSetKernelArg(cl.kernel, seed_arg + 5, sizeof(cl_mem), &mem[MB_SPOKEOFF]);
    e |= api->clSetKernelArg(cl.kernel, seed_arg + 6, sizeof(cl_mem), &mem[MB_SPOKES]);
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
            int kernel_queued = 0;
            e = api->clSetKernelArg(cl.kernel, 9, sizeof first, &first);
            e |= api->clSetKernelArg(cl.kernel, 10, sizeof count, &count);
            if (e != CL_SUCCESS) {
                st = runtime_fail(err, "clSetKernelArg", e);
                goto done;
            }
            if (exact) {
                seed_buf *b = &sb;
                st = batch_seeds(job, &ews, uniform, first, count, b);
                if (st != MFMM_OK) {
                    st = mfmm_fail(err, st, first, "out of memory for the exact start of rows "
                                                   "from %d", (int)first);
                    goto done;
                }
                /* copied at creation; released now, freed by OpenCL once the
                 * kernel that uses them is done */
                cl_mem m_idx = api->clCreateBuffer(cl.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                                   b->n * sizeof(int32_t), b->idx, &e);
                cl_mem m_val = NULL;
                if (e == CL_SUCCESS)
                    m_val = api->clCreateBuffer(cl.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                                b->n * sizeof(double), b->val, &e);
                if (e == CL_SUCCESS)
                    e = api->clSetKernelArg(cl.kernel, seed_arg + 1, sizeof(cl_mem), &m_idx);
                if (e == CL_SUCCESS)
                    e = api->clSetKernelArg(cl.kernel, seed_arg + 2, sizeof(cl_mem), &m_val);
                if (e == CL_SUCCESS) {
                    size_t global = (size_t)count, local = 1;
                    e = api->clEnqueueNDRangeKernel(cl.queue, cl.kernel, 1, NULL, &global, &local,
                                                    0, NULL, NULL);
                    kernel_queued = 1;
                }
                if (m_idx)
                    api->clReleaseMemObject(m_idx);
                if (m_val)
                    api->clReleaseMemObject(m_val);
                if (e != CL_SUCCESS) {
                    st = runtime_fail(err, "uploading the exact start's seeds", e);
                    goto done;
                }
            }
            if (!kernel_queued) {
                size_t global = (size_t)count, local = 1;
                e = api->clEnqueueNDRangeKernel(cl.queue, cl.kernel, 1, NULL, &global, &local, 0,
                                                NULL, NULL);
                if (e != CL_SUCCESS) {
                    st = runtime_fail(err, "clEnqueueNDRangeKernel", e);
                    goto done;
                }
            }
            void *dst = direct ? (char *)job->opt->out + (size_t)first * row_bytes
                               : host + (size_t)(k & 1) * (size_t)batch * row_bytes;
            e = api->clEnqueueReadBuffer(cl.queue, mem[MB_OUT], CL_FALSE, 0,
                                    (size_t)count * row_bytes, dst, 0, NULL, &ev[k & 1]);
            if (e != CL_SUCCESS) {
                st = runtime_fail(err, "clEnqueueReadBuffer", e);
                goto done;
            }
            api->clFlush(cl.queue);
        }
        if (k > 0) {
            int32_t j = k - 1;
            cl_event wait = ev[j & 1];
            ev[j & 1] = NULL;
            e = api->clWaitForEvents(1, &wait);
            cl_int status = CL_COMPLETE;
            if (e == CL_SUCCESS)
                e = api->clGetEventInfo(wait, CL_EVENT_COMMAND_EXECUTION_STATUS, sizeof status,
                                   &status, NULL);
            api->clReleaseEvent(wait);
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
        api->clFinish(cl.queue);
    for (int i = 0; i < 2; i++)
        if (ev[i])
            api->clReleaseEvent(ev[i]);
    for (int i = 0; i < MB_COUNT; i++)
        if (mem[i])
            api->clReleaseMemObject(mem[i]);
    free(host);
    free(uniform);
    job->opt->start_fallbacks += sb.fallbacks;
    free(sb.idx);
    free(sb.val);
    mfmm_exact_ws_destroy(ews);
    ocl_release_call(&cl);
    return st;
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
    mfmm_status st = run_rows(&ctx->cl, job, start, rows_done, err);
    mfmm_opencl_context_destroy(own);
    return st;
}

/* ---- the self-test of a program before it goes to or comes from the cache ----
 * All rows of a small mesh with obtuse corners (a sheared 7 x 6 grid, its
 * vertices jittered so that no two triangles are alike), in float64 and
 * float32, against mfmm_solve, bit for bit. A cached binary that fails to
 * make a kernel, to run or to give exactly these rows is not used. (A 5 x 4
 * grid without jitter let a binary built with -cl-fast-relaxed-math
 * -cl-mad-enable pass once the update was written in closed form: its rows
 * happened to round alike there.) */
static mfmm_status self_test(ocl *cl, mfmm_error *err)
{
    enum { NX = 7, NY = 6, NV = NX * NY, NF = 2 * (NX - 1) * (NY - 1) };
    double xyz[NV * 3];
    int32_t faces[NF * 3];
    for (int j = 0; j < NY; j++)
        for (int i = 0; i < NX; i++) {
            double *p = xyz + 3 * (j * NX + i);
            p[0] = i + 0.7 * j + 0.031 * ((i * 5 + j * 11) % 7);
            p[1] = 0.4 * j + 0.017 * ((i * 3 + j * 7) % 5);
            p[2] = 0.1 * ((i * 7 + j * 3) % 5);
        }
    int32_t *f = faces;
    for (int j = 0; j + 1 < NY; j++)
        for (int i = 0; i + 1 < NX; i++) {
            int32_t a = j * NX + i, b = a + 1, c = a + NX, d = c + 1;
            f[0] = a, f[1] = b, f[2] = d, f[3] = a, f[4] = d, f[5] = c;
            f += 6;
        }
    mfmm_mesh *mesh = NULL;
    mfmm_solver *solver = NULL;
    double ref[NV * NV];
    union {
        double d[NV * NV];
        float f[NV * NV];
    } got;
    int32_t sources[NV];
    mfmm_status st = mfmm_mesh_create(xyz, NV, faces, NF, NULL, &mesh, err);
    if (st == MFMM_OK)
        st = mfmm_solver_create(mesh, &solver);
    for (int32_t s = 0; st == MFMM_OK && s < NV; s++) {
        mfmm_source src;
        memset(&src, 0, sizeof src);
        src.vertex = s;
        sources[s] = mesh->to_internal[s]; /* a job's sources are internal ids */
        src.face = -1;
        st = mfmm_solve(solver, &src, 1, NULL, ref + (size_t)s * NV, err);
    }
    for (int f64 = 1; st == MFMM_OK && f64 >= 0; f64--) {
        mfmm_matrix_options o;
        mfmm_matrix_options_init(&o);
        o.out = &got;
        mfmm_rows_job job;
        memset(&job, 0, sizeof job);
        job.mesh = mesh;
        job.sources = sources;
        job.n_sources = NV;
        job.opt = &o;
        job.elem_size = f64 ? sizeof(double) : sizeof(float);
        job.budget = MFMM_DEFAULT_BUDGET;
        job.width = NV;
        job.slot_bytes = (size_t)NV * job.elem_size;
        int32_t done = 0;
        st = run_rows(cl, &job, 0, &done, err);
        for (int i = 0; st == MFMM_OK && i < NV * NV; i++) {
            double r = f64 ? got.d[i] : (double)got.f[i];
            double want = f64 ? ref[i] : (double)(float)ref[i];
            if (memcmp(&r, &want, sizeof r) != 0)
                st = mfmm_fail(err, MFMM_ERR_OPENCL_RUNTIME, i,
                               "OpenCL self-test: row %d vertex %d is %.17g, not %.17g",
                               i / NV, i % NV, r, want);
        }
    }
    mfmm_solver_destroy(solver);
    mfmm_mesh_destroy(mesh);
    return st;
}

#endif /* MESHFMM_HAVE_OPENCL */
