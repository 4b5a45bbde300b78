/* The OpenCL backend against mfmm_solve rows: float64 bit for bit (memcmp),
 * float32 = (float)float64, on generated meshes and on meshes from
 * tests/data/meshes (with boundary, with many obtuse corners), with costs and
 * max_distance; the program cache cold, warm and corrupt; device selection;
 * cancellation. Skipped when this machine has no OpenCL device. */
#include <dirent.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>
#ifdef MESHFMM_TEST_HAVE_CL
#include <dlfcn.h>
#include <sys/stat.h>
#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>
#endif

#include "testutil.h"

static char cache_dir[64] = "/tmp/mfmm_clcache_XXXXXX";
static int have_device = -1;

/* Whether the default OpenCL device is a CPU (PoCL names its CPU devices
 * "pthread-..." or "cpu-..."): auto leaves such a device to threads. */
static int device_is_cpu(void)
{
    mfmm_opencl_context *ctx = NULL;
    mfmm_error err;
    if (mfmm_opencl_context_create(NULL, &ctx, &err) != MFMM_OK)
        return 0;
    const char *name = mfmm_opencl_context_device_name(ctx);
    int cpu = strncmp(name, "pthread", 7) == 0 || strncmp(name, "cpu", 3) == 0;
    mfmm_opencl_context_destroy(ctx);
    return cpu;
}

/* OpenCL rows (into out, or by callback with a small memory limit: many
 * batches) compared with ref. Returns 0 when there is no device (skip). */
static int check_opencl(const mfmm_mesh *mesh, const int32_t *src, int32_t n, const double *ref,
                        mfmm_dtype dtype, int use_cb, size_t memory_limit,
                        const mfmm_solve_options *so)
{
    int32_t nv = mfmm_mesh_vertex_count(mesh);
    size_t esz = dtype == MFMM_FLOAT64 ? 8 : 4;
    size_t total = (size_t)n * (size_t)nv;
    tm_collect c = {malloc(total * esz), (size_t)nv * esz, 0, 0, -1};
    assert_non_null(c.buf);
    mfmm_matrix_options o;
    mfmm_matrix_info oi = {.struct_size = sizeof oi};
    mfmm_matrix_options_init(&o);
    o.backend = MFMM_BACKEND_OPENCL;
    o.dtype = dtype;
    o.memory_limit = memory_limit;
    if (use_cb) {
        o.on_rows = tm_collect_rows;
        o.user = &c;
    } else {
        o.out = c.buf;
    }
    if (so) {
        o.cost = so->cost;
        o.cost_location = so->cost_location;
        o.max_distance = so->max_distance;
        o.unfolding = so->unfolding;
        o.exact_start_radius = so->exact_start_radius;
    }
    mfmm_error err;
    mfmm_status st = mfmm_distance_matrix(mesh, src, n, &o, &oi, &err);
    if (st == MFMM_ERR_NO_OPENCL) {
        free(c.buf);
        return 0;
    }
    if (st != MFMM_OK)
        fail_msg("opencl: %s", err.message);
    assert_int_equal(oi.backend_used, MFMM_BACKEND_OPENCL);
    if (dtype == MFMM_FLOAT64) {
        const double *d = (const double *)c.buf;
        for (size_t i = 0; i < total; i++)
            if (memcmp(&d[i], &ref[i], 8) != 0)
                fail_msg("row %zu vertex %zu: opencl %.17g != serial %.17g", i / (size_t)nv,
                         i % (size_t)nv, d[i], ref[i]);
    } else {
        tm_assert_float32_of(c.buf, ref, total);
    }
    if (use_cb)
        assert_int_equal(c.next, n);
    free(c.buf);
    return 1;
}

static int count_files(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        if (strstr(e->d_name, ".bin"))
            n++;
    closedir(d);
    return n;
}

/* First call: a cold build that writes the cache; later calls load it. */
static void test_generated_meshes(void **state)
{
    (void)state;
    mfmm_gen_mesh g[3] = {mfmm_gen_lattice(12, 3.0), mfmm_gen_icosphere(3), mfmm_gen_torus(24, 12, 1.0, 0.3)};
    for (int m = 0; m < 3; m++) {
        mfmm_mesh *mesh = tm_make(&g[m]);
        int32_t nv = g[m].nv;
        int32_t n = nv < 40 ? nv : 40;
        int32_t *src = malloc((size_t)n * sizeof *src);
        assert_non_null(src);
        for (int32_t i = 0; i < n; i++)
            src[i] = (int32_t)(((int64_t)i * 7919) % nv);
        double *ref = tm_reference_rows(mesh, src, n, NULL);
        if (!check_opencl(mesh, src, n, ref, MFMM_FLOAT64, 0, 0, NULL)) {
            have_device = 0;
            free(ref);
            free(src);
            mfmm_mesh_destroy(mesh);
            for (int k = 0; k < 3; k++)
                mfmm_gen_free(&g[k]);
            skip();
        }
        have_device = 1;
        if (m == 0)
            assert_int_equal(count_files(cache_dir), 1);
        check_opencl(mesh, src, n, ref, MFMM_FLOAT32, 1, (size_t)nv * 60 * 3, NULL);
        free(ref);
        /* per-vertex cost (varied: the straight start), plain stencils (no
         * unfolding), the paper's plain start, a uniform cost (the exact
         * start at F = 2), a larger exact start */
        double *vcost = malloc((size_t)nv * sizeof *vcost), *ucost = malloc((size_t)nv * sizeof *ucost);
        assert_non_null(vcost);
        assert_non_null(ucost);
        for (int32_t v = 0; v < nv; v++) {
            vcost[v] = 0.5 + 0.1 * (double)(v % 13);
            ucost[v] = 2.0;
        }
        mfmm_solve_options so[5];
        for (int k = 0; k < 5; k++)
            mfmm_solve_options_init(&so[k]);
        so[0].cost = vcost;
        so[0].cost_location = MFMM_COST_PER_VERTEX;
        so[1].unfolding = 0;
        so[2].exact_start_radius = 0.0;
        so[3].cost = ucost;
        so[3].cost_location = MFMM_COST_PER_VERTEX;
        so[4].exact_start_radius = 12.0;
        for (int k = 0; k < 5; k++) {
            ref = tm_reference_rows(mesh, src, n, &so[k]);
            assert_true(check_opencl(mesh, src, n, ref, MFMM_FLOAT64, 0, 0, &so[k]));
            free(ref);
        }
        free(vcost);
        free(ucost);
        free(src);
        mfmm_mesh_destroy(mesh);
        mfmm_gen_free(&g[m]);
    }
}

/* hand_lowres (boundary) and wingnut (many obtuse corners): plain, per-face
 * cost, and max_distance. */
static void test_shared_meshes(void **state)
{
    (void)state;
    if (have_device == 0)
        skip();
    const char *names[2] = {"meshes/hand_lowres.obj", "meshes/wingnut.obj"};
    for (int m = 0; m < 2; m++) {
        int32_t nf = 0;
        mfmm_mesh *mesh = tm_load_data(names[m], NULL, &nf, NULL);
        mfmm_mesh_info info = {.struct_size = sizeof info};
        assert_int_equal(mfmm_mesh_get_info(mesh, &info), MFMM_OK);
        if (m == 0)
            assert_true(info.n_boundary_edges > 0);
        else
            assert_true(info.n_virtual_edges > 100);
        int32_t nv = info.n_vertices;
        enum { N = 24 };
        int32_t src[N];
        for (int32_t i = 0; i < N; i++)
            src[i] = (int32_t)(((int64_t)i * 104729 + 11) % nv);
        double *fcost = malloc((size_t)nf * sizeof *fcost);
        assert_non_null(fcost);
        for (int32_t f = 0; f < nf; f++)
            fcost[f] = f % 3 == 0 ? 2.5 : 1.0 + 0.01 * (f % 17);
        mfmm_solve_options so[3];
        for (int k = 0; k < 3; k++)
            mfmm_solve_options_init(&so[k]);
        so[1].cost = fcost;
        so[1].cost_location = MFMM_COST_PER_FACE;
        so[2].max_distance = 0.25 * info.bbox_diagonal;
        for (int k = 0; k < 3; k++) {
            double *ref = tm_reference_rows(mesh, src, N, &so[k]);
            int finite = 0, inf = 0;
            for (size_t i = 0; i < (size_t)N * (size_t)nv; i++) {
                if (isinf(ref[i]))
                    inf++;
                else
                    finite++;
            }
            assert_true(finite > N * 10);
            if (k == 2)
                assert_true(inf > 0);
            assert_true(check_opencl(mesh, src, N, ref, MFMM_FLOAT64, k == 1, 0, &so[k]));
            if (k == 0)
                assert_true(check_opencl(mesh, src, N, ref, MFMM_FLOAT32, 0, 0, &so[k]));
            free(ref);
        }
        free(fcost);
        mfmm_mesh_destroy(mesh);
    }
}

/* A corrupt cache entry is rebuilt; an unwritable cache folder is no error. */
static void test_cache_corrupt_and_unwritable(void **state)
{
    (void)state;
    if (have_device == 0)
        skip();
    mfmm_gen_mesh g = mfmm_gen_grid(6);
    mfmm_mesh *mesh = tm_make(&g);
    int32_t src[5] = {0, 10, 20, 30, 48};
    double *ref = tm_reference_rows(mesh, src, 5, NULL);
    DIR *d = opendir(cache_dir);
    assert_non_null(d);
    struct dirent *e;
    char path[512] = "";
    while ((e = readdir(d)) != NULL)
        if (strstr(e->d_name, ".bin"))
            snprintf(path, sizeof path, "%s/%s", cache_dir, e->d_name);
    closedir(d);
    assert_true(path[0] != '\0');
    FILE *f = fopen(path, "r+b");
    assert_non_null(f);
    fseek(f, 200, SEEK_SET);
    fputs("garbage garbage garbage", f);
    fclose(f);
    assert_true(check_opencl(mesh, src, 5, ref, MFMM_FLOAT64, 0, 0, NULL));
    assert_int_equal(count_files(cache_dir), 1); /* rewritten */

    setenv("MESHFMM_CACHE_DIR", "/proc/mfmm-not-writable/cache", 1);
    assert_true(check_opencl(mesh, src, 5, ref, MFMM_FLOAT64, 0, 0, NULL));
    setenv("MESHFMM_CACHE_DIR", cache_dir, 1);
    free(ref);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

#ifdef MESHFMM_TEST_HAVE_CL
/* The cache file format of src/matrix/opencl/cache.c: magic, key length, key, binary
 * length, binary, checksum: FNV-1a of the folder's secret, key, binary and
 * secret (uint64 in host order). */
static uint64_t fnv1a(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 1099511628211ull;
    }
    return h;
}

/* Reads the only entry of cache_dir: its path, key and binary. */
static void read_entry(char *path, size_t path_n, char **key, uint64_t *klen,
                       unsigned char **bin, uint64_t *n)
{
    DIR *d = opendir(cache_dir);
    assert_non_null(d);
    struct dirent *e;
    path[0] = '\0';
    while ((e = readdir(d)) != NULL)
        if (strstr(e->d_name, ".bin"))
            snprintf(path, path_n, "%s/%s", cache_dir, e->d_name);
    closedir(d);
    assert_true(path[0] != '\0');
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    char magic[8];
    assert_int_equal(fread(magic, 1, 8, f), 8);
    assert_int_equal(fread(klen, 8, 1, f), 1);
    *key = malloc(*klen);
    assert_non_null(*key);
    assert_int_equal(fread(*key, 1, *klen, f), *klen);
    assert_int_equal(fread(n, 8, 1, f), 1);
    *bin = malloc(*n);
    assert_non_null(*bin);
    assert_int_equal(fread(*bin, 1, *n, f), *n);
    fclose(f);
}

/* Writes an entry with `bin` under the key, the checksum recomputed: with
 * the folder's secret (keyed), or as a plain FNV-1a of key and binary. */
static void write_entry(const char *path, const char *key, uint64_t klen,
                        const unsigned char *bin, uint64_t n, int keyed)
{
    uint64_t sum = fnv1a(fnv1a(14695981039346656037ull, key, klen), bin, n);
    if (keyed) {
        char sp[512];
        unsigned char secret[16];
        snprintf(sp, sizeof sp, "%s/secret", cache_dir);
        FILE *s = fopen(sp, "rb");
        assert_non_null(s);
        assert_int_equal(fread(secret, 1, 16, s), 16);
        fclose(s);
        sum = fnv1a(fnv1a(fnv1a(fnv1a(14695981039346656037ull, secret, 16), key, klen), bin, n),
                    secret, 16);
    }
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fwrite("MFMMCLB2", 1, 8, f);
    fwrite(&klen, 8, 1, f);
    fwrite(key, 1, klen, f);
    fwrite(&n, 8, 1, f);
    fwrite(bin, 1, n, f);
    fwrite(&sum, 8, 1, f);
    assert_int_equal(fclose(f), 0);
}

extern const char mfmm_kernel_fmm_rows[];
extern const size_t mfmm_kernel_fmm_rows_len;

/* A program binary for the first CPU device (else the first device), built
 * from `src` with `options`, through the system's OpenCL loader. NULL (with
 * *n = 0) when it cannot be built here. */
static unsigned char *other_binary(const char *src, size_t src_len, const char *options,
                                   size_t *n)
{
    *n = 0;
    void *h = dlopen("libOpenCL.so.1", RTLD_NOW | RTLD_LOCAL);
    if (!h)
        return NULL;
#define SYM(name) name##_fn name##_p; { void *p_ = dlsym(h, #name); assert_non_null(p_); memcpy(&name##_p, &p_, sizeof p_); }
    typedef cl_int (*clGetPlatformIDs_fn)(cl_uint, cl_platform_id *, cl_uint *);
    typedef cl_int (*clGetDeviceIDs_fn)(cl_platform_id, cl_device_type, cl_uint, cl_device_id *, cl_uint *);
    typedef cl_context (*clCreateContext_fn)(const cl_context_properties *, cl_uint, const cl_device_id *, void *, void *, cl_int *);
    typedef cl_program (*clCreateProgramWithSource_fn)(cl_context, cl_uint, const char **, const size_t *, cl_int *);
    typedef cl_int (*clBuildProgram_fn)(cl_program, cl_uint, const cl_device_id *, const char *, void *, void *);
    typedef cl_int (*clGetProgramInfo_fn)(cl_program, cl_program_info, size_t, void *, size_t *);
    typedef cl_int (*clReleaseProgram_fn)(cl_program);
    typedef cl_int (*clReleaseContext_fn)(cl_context);
    SYM(clGetPlatformIDs) SYM(clGetDeviceIDs) SYM(clCreateContext) SYM(clCreateProgramWithSource)
    SYM(clBuildProgram) SYM(clGetProgramInfo) SYM(clReleaseProgram) SYM(clReleaseContext)
#undef SYM
    cl_platform_id plat[8];
    cl_uint np = 0;
    cl_device_id dev = NULL;
    if (clGetPlatformIDs_p(8, plat, &np) == CL_SUCCESS)
        for (cl_uint p = 0; p < np && p < 8 && !dev; p++)
            if (clGetDeviceIDs_p(plat[p], CL_DEVICE_TYPE_CPU, 1, &dev, NULL) != CL_SUCCESS)
                dev = NULL;
    unsigned char *bin = NULL;
    cl_int e;
    cl_context ctx = dev ? clCreateContext_p(NULL, 1, &dev, NULL, NULL, &e) : NULL;
    cl_program prog = ctx ? clCreateProgramWithSource_p(ctx, 1, &src, &src_len, &e) : NULL;
    if (prog && clBuildProgram_p(prog, 1, &dev, options, NULL, NULL) == CL_SUCCESS &&
        clGetProgramInfo_p(prog, CL_PROGRAM_BINARY_SIZES, sizeof *n, n, NULL) == CL_SUCCESS &&
        *n > 0) {
        bin = malloc(*n);
        assert_non_null(bin);
        unsigned char *bins[1] = {bin};
        assert_int_equal(clGetProgramInfo_p(prog, CL_PROGRAM_BINARIES, sizeof bins, bins, NULL),
                         CL_SUCCESS);
    }
    if (prog)
        clReleaseProgram_p(prog);
    if (ctx)
        clReleaseContext_p(ctx);
    dlclose(h);
    if (!bin)
        *n = 0;
    return bin;
}

/* An altered cache entry (checksum recomputed) must not reach the driver:
 * PoCL crashes on such a binary. Each altered entry here must give
 * rows equal to the serial core's, and be replaced by a good one. */
static void test_cache_altered_entries(void **state)
{
    (void)state;
    if (have_device == 0)
        skip();
    mfmm_gen_mesh g = mfmm_gen_lattice(9, 3.0);
    mfmm_mesh *mesh = tm_make(&g);
    int32_t src[6] = {0, 5, 17, 33, 50, 80};
    double *ref = tm_reference_rows(mesh, src, 6, NULL);
    assert_true(check_opencl(mesh, src, 6, ref, MFMM_FLOAT64, 0, 0, NULL)); /* fills the cache */
    char path[512];
    char *key;
    unsigned char *good;
    uint64_t klen, n;
    read_entry(path, sizeof path, &key, &klen, &good, &n);

    /* the kernel with other build options (another heap arity, relaxed math),
     * and another program whose kernels have the same names */
    static const char dummy[] =
        "__kernel void fmm_rows_f64(__global double *out) { out[get_global_id(0)] = 1.0; }\n"
        "__kernel void fmm_rows_f32(__global float *out) { out[get_global_id(0)] = 1.0f; }\n";
    size_t n_other = 0, n_dummy = 0;
    unsigned char *other = other_binary(mfmm_kernel_fmm_rows, mfmm_kernel_fmm_rows_len,
                                        "-cl-std=CL1.2 -DMFMM_HEAP_ARITY=2 -cl-fast-relaxed-math "
                                        "-cl-mad-enable", &n_other);
    unsigned char *dummy_bin = other_binary(dummy, sizeof dummy - 1, "-cl-std=CL1.2", &n_dummy);
    unsigned char *noise = malloc(n);
    assert_non_null(noise);
    uint64_t x = 88172645463325252ull;
    for (uint64_t i = 0; i < n; i++) {
        x ^= x << 13, x ^= x >> 7, x ^= x << 17;
        noise[i] = (unsigned char)x;
    }
    unsigned char *flipped = malloc(n);
    assert_non_null(flipped);
    memcpy(flipped, good, n);
    for (uint64_t i = n / 3; i < n; i += 61)
        flipped[i] ^= 0x5a;

    for (int k = 0; k < 7; k++) {
        switch (k) {
        case 0: /* truncated */
            assert_int_equal(truncate(path, (off_t)(klen + n / 2)), 0);
            break;
        case 1: /* random bytes, the plain checksum recomputed */
            write_entry(path, key, klen, noise, n, 0);
            break;
        case 2: /* the good binary with bytes changed after its first third, the
                 * plain checksum recomputed: PoCL 3.1 crashes on it in
                 * clCreateProgramWithBinary, the keyed checksum keeps it out */
            write_entry(path, key, klen, flipped, n, 0);
            break;
        case 3: /* random bytes with a valid (keyed) checksum: the driver refuses them */
            write_entry(path, key, klen, noise, n, 1);
            break;
        case 4: /* the kernel built with other options, valid checksum */
            if (!other)
                continue;
            write_entry(path, key, klen, other, n_other, 1);
            break;
        case 5: /* another program with kernels of the same names, valid checksum */
            if (!dummy_bin)
                continue;
            write_entry(path, key, klen, dummy_bin, n_dummy, 1);
            break;
        case 6: /* a good binary under the key of another driver, valid checksum */
            key[klen - 2] ^= 1;
            write_entry(path, key, klen, good, n, 1);
            key[klen - 2] ^= 1;
            break;
        }
        assert_true(check_opencl(mesh, src, 6, ref, MFMM_FLOAT64, 0, 0, NULL));
        assert_true(check_opencl(mesh, src, 6, ref, MFMM_FLOAT32, 0, 0, NULL));
        /* the entry was replaced by a working one */
        char path2[512];
        char *key2;
        unsigned char *bin2;
        uint64_t klen2, n2;
        read_entry(path2, sizeof path2, &key2, &klen2, &bin2, &n2);
        assert_string_equal(path2, path);
        assert_true(klen2 == klen && memcmp(key2, key, klen) == 0);
        assert_int_equal(count_files(cache_dir), 1);
        free(key2);
        free(bin2);
    }
    /* auto runs OpenCL on an altered entry too (a CPU device, named) */
    write_entry(path, key, klen, flipped, n, 0);
    setenv("MESHFMM_OPENCL_DEVICE", "0", 1);
    double *out = malloc(6 * (size_t)g.nv * sizeof *out);
    assert_non_null(out);
    mfmm_matrix_options o;
    mfmm_matrix_info oi = {.struct_size = sizeof oi};
    mfmm_matrix_options_init(&o);
    o.dtype = MFMM_FLOAT64;
    o.out = out;
    mfmm_error err;
    assert_int_equal(mfmm_distance_matrix(mesh, src, 6, &o, &oi, &err), MFMM_OK);
    unsetenv("MESHFMM_OPENCL_DEVICE");
    assert_int_equal(oi.backend_used, MFMM_BACKEND_OPENCL);
    assert_memory_equal(out, ref, 6 * (size_t)g.nv * sizeof *out);
    free(out);
    free(noise);
    free(flipped);
    free(other);
    free(dummy_bin);
    free(good);
    free(key);
    free(ref);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}
#endif

static int batch_first_n = 0;
static int first_batch(void *user, int32_t first, int32_t n, const void *rows)
{
    (void)user;
    (void)rows;
    if (first == 0)
        batch_first_n = n;
    return 0;
}

/* With the default memory budget (16 MiB) a batch could hold one row of a
 * mesh above ~227k vertices (37 bytes per vertex and row), and OpenCL ran on
 * one core. A batch now holds a row per compute unit (this machine's cores,
 * on PoCL); and auto runs threads, saying why, when memory_limit keeps
 * OpenCL from filling every compute unit, or when the device is a CPU the
 * caller did not name (threads run the same rows faster there). */
static void test_batches_fill_compute_units(void **state)
{
    (void)state;
    if (have_device == 0)
        skip();
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    if (cores < 2)
        skip();
    mfmm_gen_mesh g = mfmm_gen_grid(500); /* 251001 vertices */
    mfmm_mesh *mesh = tm_make(&g);
    int32_t src[4] = {0, 1000, 125000, 250000};
    mfmm_matrix_options o;
    mfmm_matrix_info oi = {.struct_size = sizeof oi};
    mfmm_matrix_options_init(&o);
    o.backend = MFMM_BACKEND_OPENCL;
    o.max_distance = 1e-9; /* each row stops at its source: the batch size is what counts */
    o.on_rows = first_batch;
    mfmm_error err;
    if (mfmm_distance_matrix(mesh, src, 4, &o, &oi, &err) != MFMM_OK)
        fail_msg("%s", err.message);
    assert_true(batch_first_n >= 2);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);

    g = mfmm_gen_grid(20);
    mesh = tm_make(&g);
    int32_t nv = g.nv;
    src[1] = 200;
    double *ref = tm_reference_rows(mesh, src, 2, NULL);
    double *out = malloc(2 * (size_t)nv * sizeof *out);
    assert_non_null(out);
    mfmm_matrix_options_init(&o);
    o.dtype = MFMM_FLOAT64;
    o.out = out;
    int cpu = device_is_cpu();
    if (cpu) { /* a CPU device, not named: threads, saying why */
        assert_int_equal(mfmm_distance_matrix(mesh, src, 2, &o, &oi, &err), MFMM_OK);
        assert_int_equal(oi.backend_used, MFMM_BACKEND_THREADS);
        assert_non_null(strstr(oi.backend_reason, "is a CPU"));
        assert_memory_equal(out, ref, 2 * (size_t)nv * sizeof *out);
        setenv("MESHFMM_OPENCL_DEVICE", "0", 1); /* named: auto may take it */
    }
    o.memory_limit = (size_t)nv * 40; /* one row at a time */
    assert_int_equal(mfmm_distance_matrix(mesh, src, 2, &o, &oi, &err), MFMM_OK);
    assert_int_equal(oi.backend_used, MFMM_BACKEND_THREADS);
    assert_non_null(strstr(oi.backend_reason, "compute units"));
    assert_memory_equal(out, ref, 2 * (size_t)nv * sizeof *out);
    o.memory_limit = 0; /* the default: OpenCL, no reason */
    assert_int_equal(mfmm_distance_matrix(mesh, src, 2, &o, &oi, &err), MFMM_OK);
    assert_int_equal(oi.backend_used, MFMM_BACKEND_OPENCL);
    assert_string_equal(oi.backend_reason, "");
    assert_memory_equal(out, ref, 2 * (size_t)nv * sizeof *out);
    unsetenv("MESHFMM_OPENCL_DEVICE");
    free(out);
    free(ref);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

/* The device and cache folder through mfmm_opencl_options (they win over the
 * environment); a wrong struct_size is refused. */
/* Target columns on OpenCL (the kernel marches to its targets and writes
 * their columns) equal the serial backend's bit for bit, with and
 * without a cost, into out and by callback over many batches. Sparse rows
 * are refused with a reason. */
static void test_targets(void **state)
{
    (void)state;
    if (have_device == 0)
        skip();
    mfmm_gen_mesh g = mfmm_gen_sine(24);
    mfmm_mesh *mesh = tm_make(&g);
    int32_t nv = g.nv, n = 30;
    int32_t src[30];
    for (int32_t i = 0; i < n; i++)
        src[i] = (int32_t)(((int64_t)i * 7919) % nv);
    int32_t tg[6] = {nv - 1, 3, 100, 3, nv / 2, 0};
    double *vcost = malloc((size_t)nv * sizeof *vcost);
    assert_non_null(vcost);
    for (int32_t v = 0; v < nv; v++)
        vcost[v] = 0.5 + 0.1 * (double)(v % 13);
    for (int k = 0; k < 3; k++) {
        for (int dt = 0; dt < 2; dt++) {
            size_t esz = dt ? 8 : 4, bytes = (size_t)n * 6 * esz;
            char *ref = malloc(bytes), *got = malloc(bytes);
            assert_true(ref && got);
            mfmm_matrix_options o;
            mfmm_matrix_info oi = {.struct_size = sizeof oi};
            mfmm_matrix_options_init(&o);
            o.dtype = dt ? MFMM_FLOAT64 : MFMM_FLOAT32;
            o.targets = tg;
            o.n_targets = 6;
            if (k == 1) {
                o.cost = vcost;
                o.cost_location = MFMM_COST_PER_VERTEX;
            }
            if (k == 2)
                o.max_distance = 0.5;
            o.backend = MFMM_BACKEND_SERIAL;
            o.out = ref;
            assert_int_equal(mfmm_distance_matrix(mesh, src, n, &o, &oi, NULL), MFMM_OK);
            o.backend = MFMM_BACKEND_OPENCL;
            tm_collect c = {got, 6 * esz, 0, 0, -1};
            if (k == 0) {
                o.out = NULL;
                o.on_rows = tm_collect_rows;
                o.user = &c;
                o.memory_limit = (size_t)nv * 60 * 3;
            } else {
                o.out = got;
            }
            mfmm_error err;
            mfmm_status st = mfmm_distance_matrix(mesh, src, n, &o, &oi, &err);
            if (st == MFMM_ERR_NO_OPENCL) {
                free(ref);
                free(got);
                free(vcost);
                mfmm_mesh_destroy(mesh);
                mfmm_gen_free(&g);
                skip();
            }
            if (st != MFMM_OK)
                fail_msg("opencl targets: %s", err.message);
            assert_int_equal(oi.backend_used, MFMM_BACKEND_OPENCL);
            assert_memory_equal(got, ref, bytes);
            free(ref);
            free(got);
        }
    }
    free(vcost);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

static void test_opencl_options(void **state)
{
    (void)state;
    if (have_device == 0)
        skip();
    char dir[64] = "/tmp/mfmm_clopt_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char sub[128];
    snprintf(sub, sizeof sub, "%s/a/b", dir);
    mfmm_opencl_options co;
    mfmm_opencl_options_init(&co);
    assert_int_equal(co.struct_size, sizeof co);
    co.cache_dir = sub;
    co.device = "0";
    setenv("MESHFMM_OPENCL_DEVICE", "no-such-device-name", 1);
    mfmm_opencl_context *ctx = NULL;
    mfmm_error err;
    if (mfmm_opencl_context_create(&co, &ctx, &err) != MFMM_OK)
        fail_msg("%s", err.message);
    unsetenv("MESHFMM_OPENCL_DEVICE");
    mfmm_opencl_context_destroy(ctx);
    char entry[512];
    DIR *d = opendir(sub);
    assert_non_null(d);
    int bins = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.')
            continue;
        bins += strstr(e->d_name, ".bin") != NULL;
        snprintf(entry, sizeof entry, "%s/%s", sub, e->d_name);
        remove(entry);
    }
    closedir(d);
    assert_int_equal(bins, 1);
    rmdir(sub);
    snprintf(sub, sizeof sub, "%s/a", dir);
    rmdir(sub);
    rmdir(dir);

    co.device = "no-such-device-name";
    assert_int_equal(mfmm_opencl_context_create(&co, &ctx, &err), MFMM_ERR_NO_OPENCL);
    assert_non_null(strstr(err.message, "no-such-device-name"));
    co.device = NULL;
    co.struct_size = sizeof co + 8; /* a newer header than the library */
    assert_int_equal(mfmm_opencl_context_create(&co, &ctx, &err), MFMM_ERR_BAD_ARGUMENT);
    assert_non_null(strstr(err.message, "struct_size"));
    assert_null(ctx);
}

/* MESHFMM_OPENCL_DEVICE: an index or a name substring; a wrong one is
 * MFMM_ERR_NO_OPENCL (auto then falls back to threads). */
static void test_device_selection_and_cancel(void **state)
{
    (void)state;
    if (have_device == 0)
        skip();
    mfmm_gen_mesh g = mfmm_gen_grid(8);
    mfmm_mesh *mesh = tm_make(&g);
    int32_t nv = g.nv;
    double *out = malloc((size_t)nv * (size_t)nv * sizeof *out);
    assert_non_null(out);
    mfmm_matrix_options o;
    mfmm_matrix_info oi = {.struct_size = sizeof oi};
    mfmm_matrix_options_init(&o);
    o.backend = MFMM_BACKEND_OPENCL;
    o.out = out;
    mfmm_error err;
    setenv("MESHFMM_OPENCL_DEVICE", "0", 1);
    assert_int_equal(mfmm_distance_matrix(mesh, NULL, nv, &o, &oi, &err), MFMM_OK);
    setenv("MESHFMM_OPENCL_DEVICE", "999", 1);
    assert_int_equal(mfmm_distance_matrix(mesh, NULL, nv, &o, &oi, &err), MFMM_ERR_NO_OPENCL);
    assert_non_null(strstr(err.message, "MESHFMM_OPENCL_DEVICE"));
    setenv("MESHFMM_OPENCL_DEVICE", "no-such-device-name", 1);
    assert_int_equal(mfmm_distance_matrix(mesh, NULL, nv, &o, &oi, &err), MFMM_ERR_NO_OPENCL);
    o.backend = MFMM_BACKEND_AUTO;
    assert_int_equal(mfmm_distance_matrix(mesh, NULL, nv, &o, &oi, &err), MFMM_OK);
    assert_int_equal(oi.backend_used, MFMM_BACKEND_THREADS);
    unsetenv("MESHFMM_OPENCL_DEVICE");
    assert_int_equal(mfmm_distance_matrix(mesh, NULL, nv, &o, &oi, &err), MFMM_OK);
    assert_int_equal(oi.backend_used,
                     device_is_cpu() ? MFMM_BACKEND_THREADS : MFMM_BACKEND_OPENCL);
    setenv("MESHFMM_OPENCL_DEVICE", "0", 1); /* named: auto takes it */
    assert_int_equal(mfmm_distance_matrix(mesh, NULL, nv, &o, &oi, &err), MFMM_OK);
    assert_int_equal(oi.backend_used, MFMM_BACKEND_OPENCL);

    /* cancel after the second batch */
    tm_collect c = {(char *)out, (size_t)nv * 4, 0, 0, 2};
    o.out = NULL;
    o.on_rows = tm_collect_rows;
    o.user = &c;
    o.memory_limit = (size_t)nv * 60 * 4; /* a few rows per batch */
    assert_int_equal(mfmm_distance_matrix(mesh, NULL, nv, &o, &oi, &err), MFMM_ERR_CANCELLED);
    assert_int_equal(oi.backend_used, MFMM_BACKEND_OPENCL); /* no fallback after a cancel */
    unsetenv("MESHFMM_OPENCL_DEVICE");
    assert_int_equal(c.calls, 2);
    assert_true(c.next < nv);
    free(out);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

static void remove_cache(void)
{
    DIR *d = opendir(cache_dir);
    if (d) {
        struct dirent *e;
        char path[512];
        while ((e = readdir(d)) != NULL) {
            if (e->d_name[0] == '.')
                continue;
            snprintf(path, sizeof path, "%s/%s", cache_dir, e->d_name);
            remove(path);
        }
        closedir(d);
    }
    rmdir(cache_dir);
}

/* A context made once serves several calls (and threads-free reuse): rows
 * still equal the serial core's; a context's device has a name. */
static void test_reused_context(void **state)
{
    (void)state;
    mfmm_opencl_context *ctx = NULL;
    mfmm_error err;
    mfmm_status st = mfmm_opencl_context_create(NULL, &ctx, &err);
    if (st == MFMM_ERR_NO_OPENCL) {
        assert_null(ctx);
        skip();
    }
    if (st != MFMM_OK)
        fail_msg("mfmm_opencl_context_create: %s", err.message);
    assert_true(strlen(mfmm_opencl_context_device_name(ctx)) > 0);
    mfmm_gen_mesh g = mfmm_gen_lattice(12, 3.0);
    mfmm_mesh *mesh = tm_make(&g);
    int32_t src[7] = {0, 3, 17, 40, 99, 150, 168};
    double *ref = tm_reference_rows(mesh, src, 7, NULL);
    double *out = malloc(7 * (size_t)g.nv * sizeof *out);
    assert_non_null(out);
    for (int call = 0; call < 3; call++) {
        mfmm_matrix_options o;
        mfmm_matrix_info oi = {.struct_size = sizeof oi};
        mfmm_matrix_options_init(&o);
        o.backend = MFMM_BACKEND_OPENCL;
        o.dtype = MFMM_FLOAT64;
        o.opencl = ctx;
        o.out = out;
        memset(out, 0, 7 * (size_t)g.nv * sizeof *out);
        if (mfmm_distance_matrix(mesh, src, 7, &o, &oi, &err) != MFMM_OK)
            fail_msg("call %d: %s", call, err.message);
        assert_int_equal(oi.backend_used, MFMM_BACKEND_OPENCL);
        assert_memory_equal(out, ref, 7 * (size_t)g.nv * sizeof *out);
    }
    free(out);
    free(ref);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
    mfmm_opencl_context_destroy(ctx);
    mfmm_opencl_context_destroy(NULL);
    assert_int_equal(mfmm_opencl_context_create(NULL, NULL, &err), MFMM_ERR_NULL_POINTER);
}

int main(void)
{
    /* a fresh program cache: the first build is cold, later ones warm */
    if (!mkdtemp(cache_dir))
        return 1;
    setenv("MESHFMM_CACHE_DIR", cache_dir, 1);
    unsetenv("MESHFMM_OPENCL_DEVICE");
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_generated_meshes),
        cmocka_unit_test(test_shared_meshes),
        cmocka_unit_test(test_cache_corrupt_and_unwritable),
#ifdef MESHFMM_TEST_HAVE_CL
        cmocka_unit_test(test_cache_altered_entries),
#endif
        cmocka_unit_test(test_device_selection_and_cancel),
        cmocka_unit_test(test_reused_context),
        cmocka_unit_test(test_batches_fill_compute_units),
        cmocka_unit_test(test_targets),
        cmocka_unit_test(test_opencl_options),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    remove_cache();
    return rc;
}
