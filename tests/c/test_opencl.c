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

#include "testutil.h"

static char cache_dir[64] = "/tmp/mfmm_clcache_XXXXXX";
static int have_device = -1;

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
    }
    mfmm_error err;
    mfmm_status st = mfmm_distance_matrix(mesh, src, n, &o, &err);
    if (st == MFMM_ERR_NO_OPENCL) {
        free(c.buf);
        return 0;
    }
    if (st != MFMM_OK)
        fail_msg("opencl: %s", err.message);
    assert_int_equal(o.backend_used, MFMM_BACKEND_OPENCL);
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
        /* per-vertex cost, and plain stencils (no unfolding) */
        double *vcost = malloc((size_t)nv * sizeof *vcost);
        assert_non_null(vcost);
        for (int32_t v = 0; v < nv; v++)
            vcost[v] = 0.5 + 0.1 * (double)(v % 13);
        mfmm_solve_options so[2];
        mfmm_solve_options_init(&so[0]);
        mfmm_solve_options_init(&so[1]);
        so[0].cost = vcost;
        so[0].cost_location = MFMM_COST_PER_VERTEX;
        so[1].unfolding = 0;
        for (int k = 0; k < 2; k++) {
            ref = tm_reference_rows(mesh, src, n, &so[k]);
            assert_true(check_opencl(mesh, src, n, ref, MFMM_FLOAT64, 0, 0, &so[k]));
            free(ref);
        }
        free(vcost);
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
        mfmm_mesh_info info;
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
    mfmm_matrix_options_init(&o);
    o.backend = MFMM_BACKEND_OPENCL;
    o.out = out;
    mfmm_error err;
    setenv("MESHFMM_OPENCL_DEVICE", "0", 1);
    assert_int_equal(mfmm_distance_matrix(mesh, NULL, nv, &o, &err), MFMM_OK);
    setenv("MESHFMM_OPENCL_DEVICE", "999", 1);
    assert_int_equal(mfmm_distance_matrix(mesh, NULL, nv, &o, &err), MFMM_ERR_NO_OPENCL);
    assert_non_null(strstr(err.message, "MESHFMM_OPENCL_DEVICE"));
    setenv("MESHFMM_OPENCL_DEVICE", "no-such-device-name", 1);
    assert_int_equal(mfmm_distance_matrix(mesh, NULL, nv, &o, &err), MFMM_ERR_NO_OPENCL);
    o.backend = MFMM_BACKEND_AUTO;
    assert_int_equal(mfmm_distance_matrix(mesh, NULL, nv, &o, &err), MFMM_OK);
    assert_int_equal(o.backend_used, MFMM_BACKEND_THREADS);
    unsetenv("MESHFMM_OPENCL_DEVICE");
    assert_int_equal(mfmm_distance_matrix(mesh, NULL, nv, &o, &err), MFMM_OK);
    assert_int_equal(o.backend_used, MFMM_BACKEND_OPENCL);

    /* cancel after the second batch */
    tm_collect c = {(char *)out, (size_t)nv * 4, 0, 0, 2};
    o.out = NULL;
    o.on_rows = tm_collect_rows;
    o.user = &c;
    o.memory_limit = (size_t)nv * 60 * 4; /* a few rows per batch */
    assert_int_equal(mfmm_distance_matrix(mesh, NULL, nv, &o, &err), MFMM_ERR_CANCELLED);
    assert_int_equal(o.backend_used, MFMM_BACKEND_OPENCL); /* no fallback after a cancel */
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
        mfmm_matrix_options_init(&o);
        o.backend = MFMM_BACKEND_OPENCL;
        o.dtype = MFMM_FLOAT64;
        o.opencl = ctx;
        o.out = out;
        memset(out, 0, 7 * (size_t)g.nv * sizeof *out);
        if (mfmm_distance_matrix(mesh, src, 7, &o, &err) != MFMM_OK)
            fail_msg("call %d: %s", call, err.message);
        assert_int_equal(o.backend_used, MFMM_BACKEND_OPENCL);
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
        cmocka_unit_test(test_device_selection_and_cancel),
        cmocka_unit_test(test_reused_context),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    remove_cache();
    return rc;
}
