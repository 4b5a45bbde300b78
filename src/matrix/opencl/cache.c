/* The OpenCL program (kernels/fmm_rows.cl, embedded at build time), with its
 * binary cached on disk (cache.h). */
#ifdef MESHFMM_HAVE_OPENCL

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base/error.h"
#include "cache.h"
#include "selftest.h"

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
    mfmm_cl_device_string(cl, CL_DEVICE_VERSION, dev_ver, sizeof dev_ver);
    mfmm_cl_device_string(cl, CL_DRIVER_VERSION, drv_ver, sizeof drv_ver);
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
    if (mfmm_cl_self_test(cl, NULL) != MFMM_OK) {
        cl->program = NULL;
        cl->api->clReleaseProgram(prog);
        return NULL;
    }
    cl->program = NULL;
    return prog;
}

mfmm_status mfmm_cl_build_program(ocl *cl, const char *cache_option, mfmm_error *err)
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
                         mfmm_cl_error_name(e));
    e = cl->api->clBuildProgram(prog, 1, &cl->device, build_options, NULL, NULL);
    if (e != CL_SUCCESS) {
        char log[160];
        build_log(cl, prog, log, sizeof log);
        cl->api->clReleaseProgram(prog);
        return mfmm_fail(err, MFMM_ERR_OPENCL_BUILD, -1, "building the kernel for '%s': %s%s%s",
                         cl->name, mfmm_cl_error_name(e), log[0] ? ": " : "", log);
    }
    cl->program = prog;
    /* only a program that passes the self-test is cached (a cached one must pass it) */
    if (have_dir && mfmm_cl_self_test(cl, NULL) == MFMM_OK) {
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

#else
typedef int mfmm_opencl_cache_unused; /* ISO C: no empty translation unit */
#endif /* MESHFMM_HAVE_OPENCL */
