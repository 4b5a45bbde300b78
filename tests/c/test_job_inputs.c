/* What a job reads. max_distance negative or NaN is
 * refused (mfmm_solve, mfmm_distance_matrix); mfmm_distance_matrix re-reads
 * the sources and the cost for every row, so it works on its own copies: an
 * out buffer that holds the caller's sources array gives the same rows as a
 * separate one (serial, threads, OpenCL where a device works). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "testutil.h"

static void test_max_distance_refused(void **state)
{
    (void)state;
    tm_fixture fx = tm_fixture_make(mfmm_gen_grid(6), 0);
    const double bad[3] = {-1.0, -INFINITY, NAN};
    mfmm_source s = tm_vertex_source(0);
    for (int i = 0; i < 3; i++) {
        mfmm_solve_options so;
        mfmm_solve_options_init(&so);
        so.max_distance = bad[i];
        mfmm_error err;
        assert_int_equal(mfmm_solve(fx.solver, &s, 1, &so, fx.d, &err), MFMM_ERR_BAD_ARGUMENT);
        assert_non_null(strstr(err.message, "max_distance"));
        mfmm_matrix_options mo;
        mfmm_matrix_options_init(&mo);
        mo.backend = MFMM_BACKEND_SERIAL;
        mo.dtype = MFMM_FLOAT64;
        mo.out = fx.d;
        mo.max_distance = bad[i];
        int32_t src = 0;
        assert_int_equal(mfmm_distance_matrix(fx.mesh, &src, 1, &mo, NULL, &err), MFMM_ERR_BAD_ARGUMENT);
        assert_non_null(strstr(err.message, "max_distance"));
    }
    /* 0 is a limit like any other: only the sources settle */
    mfmm_solve_options so;
    mfmm_solve_options_init(&so);
    so.max_distance = 0.0;
    mfmm_error err;
    assert_int_equal(mfmm_solve(fx.solver, &s, 1, &so, fx.d, &err), MFMM_OK);
    assert_true(fx.d[0] == 0.0 && isinf(fx.d[1]));
    tm_fixture_free(&fx);
}

/* out (float64, n x nv) starts with the sources array itself, and (per
 * face) the cost array right after it: rows written over them must not
 * change the rows after. One row a block, so that every row is delivered
 * before the next is solved. */
static void check_alias(mfmm_backend backend)
{
    tm_fixture fx = tm_fixture_make(mfmm_gen_icosphere(2), 0);
    int32_t nv = mfmm_mesh_vertex_count(fx.mesh), nf = mfmm_mesh_face_count(fx.mesh);
    enum { N = 12 };
    int32_t src[N];
    for (int i = 0; i < N; i++)
        src[i] = (int32_t)((i * 37 + 5) % nv);
    double *cost = malloc((size_t)nf * sizeof *cost);
    assert_non_null(cost);
    for (int32_t f = 0; f < nf; f++)
        cost[f] = 1.0 + (f % 7) * 0.25;
    mfmm_solve_options so;
    mfmm_solve_options_init(&so);
    so.cost = cost;
    so.cost_location = MFMM_COST_PER_FACE;
    double *ref = tm_reference_rows(fx.mesh, src, N, &so);
    size_t total = (size_t)N * (size_t)nv;
    assert_true(total * sizeof(double) > sizeof src + (size_t)nf * sizeof(double));
    double *out = malloc(total * sizeof *out);
    assert_non_null(out);
    memcpy(out, src, sizeof src);
    double *cost_in_out = (double *)((char *)out + sizeof src);
    memcpy(cost_in_out, cost, (size_t)nf * sizeof *cost);
    mfmm_matrix_options mo;
    mfmm_matrix_options_init(&mo);
    mo.backend = backend;
    mo.dtype = MFMM_FLOAT64;
    mo.out = out;
    mo.cost = cost_in_out;
    mo.cost_location = MFMM_COST_PER_FACE;
    mo.n_threads = 2;
    mo.memory_limit = 1; /* as small as it goes: one row a block */
    mfmm_error err;
    mfmm_status st = mfmm_distance_matrix(fx.mesh, (const int32_t *)out, N, &mo, NULL, &err);
    if (backend == MFMM_BACKEND_OPENCL && st == MFMM_ERR_NO_OPENCL) {
        free(out);
        free(ref);
        free(cost);
        tm_fixture_free(&fx);
        skip();
    }
    if (st != MFMM_OK)
        fail_msg("%s: %s", mfmm_backend_name(backend), err.message);
    for (size_t i = 0; i < total; i++)
        if (!(out[i] == ref[i]))
            fail_msg("%s: row %d, vertex %d: %.17g, the row of source %d gives %.17g",
                     mfmm_backend_name(backend), (int)(i / (size_t)nv), (int)(i % (size_t)nv),
                     out[i], (int)src[i / (size_t)nv], ref[i]);
    free(out);
    free(ref);
    free(cost);
    tm_fixture_free(&fx);
}

static void test_alias_serial(void **state)
{
    (void)state;
    check_alias(MFMM_BACKEND_SERIAL);
}

static void test_alias_threads(void **state)
{
    (void)state;
    check_alias(MFMM_BACKEND_THREADS);
}

static void test_alias_opencl(void **state)
{
    (void)state;
    check_alias(MFMM_BACKEND_OPENCL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_max_distance_refused),
        cmocka_unit_test(test_alias_serial),
        cmocka_unit_test(test_alias_threads),
        cmocka_unit_test(test_alias_opencl),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
