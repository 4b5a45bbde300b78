/* mfmm_distance_matrix on the CPU backends, against mfmm_solve rows (the
 * reference): serial and threads bit for bit, float32 = (float)float64,
 * blocks in order, cancellation, argument checks. This process has no
 * OpenCL device (OCL_ICD_VENDORS is an empty folder, set before any OpenCL
 * call), so auto must fall back to threads and opencl must say why. */
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

/* tm_collect_rows, and every block holds at least one row */
static int on_rows(void *user, int32_t first, int32_t n, const void *rows)
{
    assert_true(n >= 1);
    return tm_collect_rows(user, first, n, rows);
}

/* Runs one configuration and compares every row with ref. */
static void check_backend(const mfmm_mesh *mesh, const int32_t *src, int32_t n,
                          const double *ref, mfmm_backend backend, mfmm_dtype dtype,
                          int n_threads, size_t memory_limit, int use_out, int use_cb,
                          const mfmm_solve_options *so)
{
    int32_t nv = mfmm_mesh_vertex_count(mesh);
    size_t esz = dtype == MFMM_FLOAT64 ? 8 : 4;
    size_t total = (size_t)n * (size_t)nv;
    char *out = use_out ? malloc(total * esz) : NULL;
    tm_collect c = {use_cb ? malloc(total * esz) : NULL, nv * esz, 0, 0, -1};
    mfmm_matrix_options o;
    mfmm_matrix_info oi = {.struct_size = sizeof oi};
    mfmm_matrix_options_init(&o);
    o.backend = backend;
    o.dtype = dtype;
    o.n_threads = n_threads;
    o.memory_limit = memory_limit;
    o.out = out;
    if (use_cb) {
        o.on_rows = on_rows;
        o.user = &c;
    }
    if (so) {
        o.cost = so->cost;
        o.cost_location = so->cost_location;
        o.max_distance = so->max_distance;
    }
    mfmm_error err;
    mfmm_status st = mfmm_distance_matrix(mesh, src, n, &o, &oi, &err);
    if (st != MFMM_OK)
        fail_msg("%s: %s", mfmm_backend_name(backend), err.message);
    assert_int_equal(err.status, MFMM_OK);
    const char *bufs[2] = {out, c.buf};
    for (int k = 0; k < 2; k++) {
        if (!bufs[k])
            continue;
        if (dtype == MFMM_FLOAT64) {
            assert_memory_equal(bufs[k], ref, total * 8);
        } else {
            tm_assert_float32_of(bufs[k], ref, total);
        }
    }
    if (use_cb)
        assert_int_equal(c.next, n);
    free(out);
    free(c.buf);
}

static const int32_t some_sources[] = {0, 5, 17, 3, 3, 40, 99, 120, 7, 64, 1, 2, 77};
#define N_SOME ((int32_t)(sizeof some_sources / sizeof some_sources[0]))

static void test_cpu_backends_equal_solve(void **state)
{
    (void)state;
    mfmm_gen_mesh g[3] = {mfmm_gen_lattice(10, 3.0), mfmm_gen_icosphere(2), mfmm_gen_sine(12)};
    for (int m = 0; m < 3; m++) {
        mfmm_mesh *mesh = tm_make(&g[m]);
        int32_t nv = mfmm_mesh_vertex_count(mesh);
        double *ref = tm_reference_rows(mesh, some_sources, N_SOME, NULL);
        size_t row = (size_t)nv * 8;
        for (int dt = 0; dt < 2; dt++) {
            mfmm_dtype dtype = dt ? MFMM_FLOAT64 : MFMM_FLOAT32;
            check_backend(mesh, some_sources, N_SOME, ref, MFMM_BACKEND_SERIAL, dtype, 0, 0, 1, 0,
                          NULL);
            check_backend(mesh, some_sources, N_SOME, ref, MFMM_BACKEND_SERIAL, dtype, 0,
                          3 * row, 0, 1, NULL);
            for (int t = 2; t <= 3; t++) {
                /* small limits: many blocks, the ring of two in use */
                check_backend(mesh, some_sources, N_SOME, ref, MFMM_BACKEND_THREADS, dtype, t,
                              0, 1, 1, NULL);
                check_backend(mesh, some_sources, N_SOME, ref, MFMM_BACKEND_THREADS, dtype, t,
                              1, 0, 1, NULL);
                check_backend(mesh, some_sources, N_SOME, ref, MFMM_BACKEND_THREADS, dtype, t,
                              (size_t)t * (size_t)nv * 32 + 4 * row, 1, 0, NULL);
            }
        }
        free(ref);
        mfmm_mesh_destroy(mesh);
        mfmm_gen_free(&g[m]);
    }
}

static void test_all_vertices_costs_and_limit(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_lattice(8, 3.0);
    mfmm_mesh *mesh = tm_make(&g);
    int32_t nv = g.nv, nf = g.nf;
    double *fcost = malloc((size_t)nf * sizeof *fcost);
    double *vcost = malloc((size_t)nv * sizeof *vcost);
    assert_non_null(fcost);
    assert_non_null(vcost);
    for (int32_t f = 0; f < nf; f++)
        fcost[f] = 1.0 + 0.5 * sin(0.37 * f) * sin(0.37 * f) + (f % 7 == 0 ? 3.0 : 0.0);
    for (int32_t v = 0; v < nv; v++)
        vcost[v] = 0.5 + (double)(v % 5) * 0.25;
    mfmm_solve_options so[3];
    for (int k = 0; k < 3; k++)
        mfmm_solve_options_init(&so[k]);
    so[0].cost = fcost;
    so[0].cost_location = MFMM_COST_PER_FACE;
    so[1].cost = vcost;
    so[1].cost_location = MFMM_COST_PER_VERTEX;
    so[1].max_distance = 0.9;
    so[2].max_distance = 0.35;
    for (int k = 0; k < 3; k++) {
        double *ref = tm_reference_rows(mesh, NULL, nv, &so[k]);
        check_backend(mesh, NULL, nv, ref, MFMM_BACKEND_SERIAL, MFMM_FLOAT64, 0, 0, 1, 1, &so[k]);
        check_backend(mesh, NULL, nv, ref, MFMM_BACKEND_THREADS, MFMM_FLOAT64, 2, 0, 1, 1,
                      &so[k]);
        check_backend(mesh, NULL, nv, ref, MFMM_BACKEND_THREADS, MFMM_FLOAT32, 2, 50000, 0, 1,
                      &so[k]);
        free(ref);
    }
    free(fcost);
    free(vcost);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

/* A sparse collector: checks blocks in order, ascending columns, and each
 * entry against the dense reference (float64 bit-equal, float32 its
 * rounding); counts entries. */
typedef struct sp_check {
    const double *ref;
    int32_t width, next;
    size_t esz;
    int64_t nnz;
} sp_check;

static int on_sparse(void *user, int32_t first, int32_t n, const int64_t *indptr,
                     const int32_t *indices, const void *values)
{
    sp_check *c = user;
    assert_int_equal(first, c->next);
    assert_true(indptr[0] == 0);
    for (int32_t i = 0; i < n; i++) {
        const double *row = c->ref + (size_t)(first + i) * (size_t)c->width;
        int32_t finite = 0;
        for (int32_t j = 0; j < c->width; j++)
            finite += row[j] < INFINITY;
        assert_int_equal(indptr[i + 1] - indptr[i], finite);
        for (int64_t k = indptr[i]; k < indptr[i + 1]; k++) {
            if (k > indptr[i])
                assert_true(indices[k] > indices[k - 1]);
            double want = row[indices[k]];
            if (c->esz == 8)
                assert_true(((const double *)values)[k] == want);
            else
                assert_true(((const float *)values)[k] == (float)want);
        }
    }
    c->nnz += indptr[n];
    c->next += n;
    return 0;
}

/* Target columns (S x T, any order, duplicates) equal the full rows'
 * columns and settle fewer vertices; sparse rows equal the dense rows'
 * finite entries. Serial and threads, both dtypes. */
static void test_targets_and_sparse(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_sine(20);
    mfmm_mesh *mesh = tm_make(&g);
    int32_t nv = g.nv;
    int32_t targets[5] = {30, 2, 30, nv / 3, 11};
    double limits[2] = {INFINITY, 0.3};
    for (int li = 0; li < 2; li++) {
        mfmm_solve_options so;
        mfmm_solve_options_init(&so);
        so.max_distance = limits[li];
        double *ref = tm_reference_rows(mesh, some_sources, N_SOME, &so);
        double *tref = malloc((size_t)N_SOME * 5 * sizeof *tref);
        assert_non_null(tref);
        for (int32_t i = 0; i < N_SOME; i++)
            for (int j = 0; j < 5; j++)
                tref[i * 5 + j] = ref[(size_t)i * (size_t)nv + (size_t)targets[j]];
        for (int b = 0; b < 3; b++) {
            mfmm_backend be = b == 0 ? MFMM_BACKEND_SERIAL : MFMM_BACKEND_THREADS;
            for (int dt = 0; dt < 2; dt++) {
                size_t esz = dt ? 8 : 4;
                mfmm_matrix_options o;
                mfmm_matrix_info oi = {.struct_size = sizeof oi};
                mfmm_matrix_options_init(&o);
                o.backend = be;
                o.n_threads = b + 1;
                o.dtype = dt ? MFMM_FLOAT64 : MFMM_FLOAT32;
                o.max_distance = limits[li];
                o.memory_limit = b == 2 ? 1 : 0; /* blocks of one row per thread */
                /* full rows: the work */
                double *full = malloc((size_t)N_SOME * (size_t)nv * esz);
                assert_non_null(full);
                o.out = full;
                assert_int_equal(mfmm_distance_matrix(mesh, some_sources, N_SOME, &o, &oi, NULL), MFMM_OK);
                int64_t full_settled = oi.vertices_settled;
                assert_true(full_settled > 0);
                free(full);
                /* target columns */
                char *out = malloc((size_t)N_SOME * 5 * esz);
                assert_non_null(out);
                o.out = out;
                o.targets = targets;
                o.n_targets = 5;
                mfmm_error err;
                if (mfmm_distance_matrix(mesh, some_sources, N_SOME, &o, &oi, &err) != MFMM_OK)
                    fail_msg("%s", err.message);
                if (dt)
                    assert_memory_equal(out, tref, (size_t)N_SOME * 5 * 8);
                else
                    tm_assert_float32_of(out, tref, (size_t)N_SOME * 5);
                if (li == 0)
                    assert_true(oi.vertices_settled < full_settled);
                free(out);
                /* sparse, full width and target columns */
                for (int t = 0; t < 2; t++) {
                    sp_check c = {t ? tref : ref, t ? 5 : nv, 0, esz, 0};
                    o.out = NULL;
                    o.targets = t ? targets : NULL;
                    o.n_targets = t ? 5 : 0;
                    o.on_sparse = on_sparse;
                    o.user = &c;
                    if (mfmm_distance_matrix(mesh, some_sources, N_SOME, &o, &oi, &err) != MFMM_OK)
                        fail_msg("%s", err.message);
                    assert_int_equal(c.next, N_SOME);
                    assert_true(c.nnz >= N_SOME);
                }
                /* OpenCL refuses, auto runs threads */
                o.backend = MFMM_BACKEND_OPENCL;
                assert_int_equal(mfmm_distance_matrix(mesh, some_sources, N_SOME, &o, &oi, NULL),
                                 MFMM_ERR_BAD_ARGUMENT);
                sp_check c = {tref, 5, 0, esz, 0};
                o.user = &c;
                o.backend = MFMM_BACKEND_AUTO;
                assert_int_equal(mfmm_distance_matrix(mesh, some_sources, N_SOME, &o, &oi, NULL), MFMM_OK);
                assert_int_equal(oi.backend_used, MFMM_BACKEND_THREADS);
                assert_int_equal(c.next, N_SOME);
            }
        }
        free(tref);
        free(ref);
    }
    int32_t bad[1] = {nv};
    mfmm_matrix_options o;
    mfmm_matrix_info oi = {.struct_size = sizeof oi};
    mfmm_matrix_options_init(&o);
    double one[4];
    o.out = one;
    o.targets = bad;
    o.n_targets = 1;
    assert_int_equal(mfmm_distance_matrix(mesh, some_sources, 1, &o, &oi, NULL), MFMM_ERR_BAD_ARGUMENT);
    o.n_targets = 0;
    assert_int_equal(mfmm_distance_matrix(mesh, some_sources, 1, &o, &oi, NULL), MFMM_ERR_BAD_COUNT);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

/* No OpenCL platform here: auto runs threads (same rows), opencl says why. */
static void test_no_opencl_fallback(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_icosphere(2);
    mfmm_mesh *mesh = tm_make(&g);
    double *ref = tm_reference_rows(mesh, some_sources, N_SOME, NULL);
    size_t total = (size_t)N_SOME * (size_t)g.nv;
    double *out = malloc(total * sizeof *out);
    assert_non_null(out);
    mfmm_matrix_options o;
    mfmm_matrix_info oi = {.struct_size = sizeof oi};
    mfmm_matrix_options_init(&o);
    o.dtype = MFMM_FLOAT64;
    o.out = out;
    mfmm_error err;
    assert_int_equal(o.backend, MFMM_BACKEND_AUTO);
    assert_int_equal(mfmm_distance_matrix(mesh, some_sources, N_SOME, &o, &oi, &err), MFMM_OK);
    assert_int_equal(oi.backend_used, MFMM_BACKEND_THREADS);
    assert_memory_equal(out, ref, total * sizeof *out);

    o.backend = MFMM_BACKEND_OPENCL;
    assert_int_equal(mfmm_distance_matrix(mesh, some_sources, N_SOME, &o, &oi, &err),
                     MFMM_ERR_NO_OPENCL);
    assert_int_equal(err.status, MFMM_ERR_NO_OPENCL);
    assert_true(strlen(err.message) > 0);
    mfmm_opencl_context *ctx = (mfmm_opencl_context *)&o;
    assert_int_equal(mfmm_opencl_context_create(NULL, &ctx, &err), MFMM_ERR_NO_OPENCL);
    assert_null(ctx);
    assert_true(strlen(err.message) > 0);
    free(out);
    free(ref);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

static void test_cancel(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_grid(10);
    mfmm_mesh *mesh = tm_make(&g);
    int32_t nv = g.nv;
    mfmm_backend backends[2] = {MFMM_BACKEND_SERIAL, MFMM_BACKEND_THREADS};
    for (int b = 0; b < 2; b++) {
        tm_collect c = {malloc((size_t)nv * (size_t)nv * 4), (size_t)nv * 4, 0, 0, 2};
        assert_non_null(c.buf);
        mfmm_matrix_options o;
        mfmm_matrix_info oi = {.struct_size = sizeof oi};
        mfmm_matrix_options_init(&o);
        o.backend = backends[b];
        o.n_threads = 2;
        o.memory_limit = 2 * 32 * (size_t)nv + 8 * (size_t)nv * 4; /* small blocks */
        o.on_rows = on_rows;
        o.user = &c;
        mfmm_error err;
        assert_int_equal(mfmm_distance_matrix(mesh, NULL, nv, &o, &oi, &err), MFMM_ERR_CANCELLED);
        assert_int_equal(err.status, MFMM_ERR_CANCELLED);
        assert_int_equal(c.calls, 2); /* nothing after the callback said stop */
        assert_true(c.next < nv);
        free(c.buf);
    }
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

static int count_rows(void *user, int32_t first, int32_t n, const void *rows)
{
    (void)first;
    (void)rows;
    *(int32_t *)user += n;
    return 0;
}

static void test_bad_arguments(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_grid(4);
    mfmm_mesh *mesh = tm_make(&g);
    int32_t nv = g.nv;
    float *out = malloc((size_t)nv * (size_t)nv * sizeof *out);
    assert_non_null(out);
    int32_t got = 0;
    mfmm_matrix_options o;
    mfmm_matrix_info oi = {.struct_size = sizeof oi};
    mfmm_error err;
    int32_t src[3] = {0, 3, 2};

#define EXPECT(st, call)                                                                       \
    do {                                                                                       \
        err.status = MFMM_OK;                                                                  \
        assert_int_equal((call), (st));                                                        \
        assert_int_equal(err.status, (st));                                                    \
        assert_true(strlen(err.message) > 0);                                                  \
    } while (0)
#define RESET()                                                                                \
    do {                                                                                       \
        mfmm_matrix_options_init(&o);                                                          \
        o.backend = MFMM_BACKEND_SERIAL;                                                       \
        o.out = out;                                                                           \
    } while (0)

    RESET();
    EXPECT(MFMM_ERR_NULL_POINTER, mfmm_distance_matrix(NULL, src, 3, &o, &oi, &err));
    EXPECT(MFMM_ERR_NULL_POINTER, mfmm_distance_matrix(mesh, src, 3, NULL, &oi, &err));
    o.out = NULL;
    EXPECT(MFMM_ERR_BAD_ARGUMENT, mfmm_distance_matrix(mesh, src, 3, &o, &oi, &err));
    RESET();
    EXPECT(MFMM_ERR_BAD_COUNT, mfmm_distance_matrix(mesh, src, 0, &o, &oi, &err));
    EXPECT(MFMM_ERR_BAD_COUNT, mfmm_distance_matrix(mesh, src, -2, &o, &oi, &err));
    EXPECT(MFMM_ERR_BAD_COUNT, mfmm_distance_matrix(mesh, NULL, nv - 1, &o, &oi, &err));
    src[1] = nv;
    EXPECT(MFMM_ERR_BAD_SOURCE, mfmm_distance_matrix(mesh, src, 3, &o, &oi, &err));
    assert_int_equal(err.index, 1);
    src[1] = -1;
    EXPECT(MFMM_ERR_BAD_SOURCE, mfmm_distance_matrix(mesh, src, 3, &o, &oi, &err));
    src[1] = 3;
    double *cost = malloc((size_t)g.nf * sizeof *cost);
    assert_non_null(cost);
    for (int32_t f = 0; f < g.nf; f++)
        cost[f] = 1.0;
    cost[5] = NAN;
    o.cost = cost;
    o.cost_location = MFMM_COST_PER_FACE;
    EXPECT(MFMM_ERR_BAD_COST, mfmm_distance_matrix(mesh, src, 3, &o, &oi, &err));
    assert_int_equal(err.index, 5);
    cost[5] = 0.0;
    EXPECT(MFMM_ERR_BAD_COST, mfmm_distance_matrix(mesh, src, 3, &o, &oi, &err));
    cost[5] = 1.0;
    o.cost_location = MFMM_COST_NONE;
    EXPECT(MFMM_ERR_BAD_ARGUMENT, mfmm_distance_matrix(mesh, src, 3, &o, &oi, &err));
    o.cost_location = (mfmm_cost_location)7;
    EXPECT(MFMM_ERR_BAD_ARGUMENT, mfmm_distance_matrix(mesh, src, 3, &o, &oi, &err));
    RESET();
    o.dtype = (mfmm_dtype)3;
    EXPECT(MFMM_ERR_BAD_ARGUMENT, mfmm_distance_matrix(mesh, src, 3, &o, &oi, &err));
    RESET();
    o.backend = (mfmm_backend)9;
    EXPECT(MFMM_ERR_BAD_ARGUMENT, mfmm_distance_matrix(mesh, src, 3, &o, &oi, &err));
    RESET();
    o.max_distance = NAN;
    EXPECT(MFMM_ERR_BAD_ARGUMENT, mfmm_distance_matrix(mesh, src, 3, &o, &oi, &err));
    RESET();
    o.n_threads = -1;
    o.backend = MFMM_BACKEND_THREADS;
    EXPECT(MFMM_ERR_BAD_ARGUMENT, mfmm_distance_matrix(mesh, src, 3, &o, &oi, &err));
    /* a NULL err is fine; valid calls still run */
    RESET();
    assert_int_equal(mfmm_distance_matrix(mesh, src, -1, &o, &oi, NULL), MFMM_ERR_BAD_COUNT);
    o.out = NULL;
    o.on_rows = count_rows;
    o.user = &got;
    assert_int_equal(mfmm_distance_matrix(mesh, NULL, nv, &o, &oi, NULL), MFMM_OK);
    assert_int_equal(got, nv);
#undef EXPECT
#undef RESET
    free(cost);
    free(out);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

static void test_names_and_defaults(void **state)
{
    (void)state;
    assert_string_equal(mfmm_backend_name(MFMM_BACKEND_AUTO), "auto");
    assert_string_equal(mfmm_backend_name(MFMM_BACKEND_SERIAL), "serial");
    assert_string_equal(mfmm_backend_name(MFMM_BACKEND_THREADS), "threads");
    assert_string_equal(mfmm_backend_name(MFMM_BACKEND_OPENCL), "opencl");
    mfmm_matrix_options o;
    mfmm_matrix_info oi = {.struct_size = sizeof oi};
    mfmm_matrix_options_init(&o);
    assert_int_equal(o.backend, MFMM_BACKEND_AUTO);
    assert_int_equal(o.dtype, MFMM_FLOAT32);
    assert_true(isinf(o.max_distance) && o.max_distance > 0);
    assert_int_equal(o.unfolding, 1);
    assert_null(o.out);
    assert_null(o.on_rows);
    assert_null(o.cost);
}

/* No OpenCL loader at all (a loader name that does not exist, through the
 * options and through MESHFMM_OPENCL_LIBRARY): single solves never need
 * OpenCL, the opencl backend says why it cannot run, and auto runs threads
 * with that reason in fallback_reason. */
static void test_no_opencl_loader(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_icosphere(2);
    mfmm_mesh *mesh = tm_make(&g);
    mfmm_solver *solver = NULL;
    assert_int_equal(mfmm_solver_create(mesh, &solver), MFMM_OK);
    double *d = malloc((size_t)g.nv * sizeof *d);
    assert_non_null(d);
    mfmm_source s = tm_vertex_source(3);
    mfmm_error err;
    assert_int_equal(mfmm_solve(solver, &s, 1, NULL, d, &err), MFMM_OK);
    free(d);
    mfmm_solver_destroy(solver);

    mfmm_opencl_options co;
    mfmm_opencl_options_init(&co);
    co.library = "libmeshfmm-no-such-opencl.so.1";
    mfmm_opencl_context *ctx = (mfmm_opencl_context *)&co;
    assert_int_equal(mfmm_opencl_context_create(&co, &ctx, &err), MFMM_ERR_NO_OPENCL);
    assert_null(ctx);
#ifdef MESHFMM_TEST_HAVE_CL
    assert_non_null(strstr(err.message, "libmeshfmm-no-such-opencl.so.1"));
#endif

    double *ref = tm_reference_rows(mesh, some_sources, N_SOME, NULL);
    size_t total = (size_t)N_SOME * (size_t)g.nv;
    double *out = malloc(total * sizeof *out);
    assert_non_null(out);
    mfmm_matrix_options o;
    mfmm_matrix_info oi = {.struct_size = sizeof oi};
    mfmm_matrix_options_init(&o);
    o.dtype = MFMM_FLOAT64;
    o.out = out;
    o.opencl_options = &co;
    o.backend = MFMM_BACKEND_OPENCL;
    assert_int_equal(mfmm_distance_matrix(mesh, some_sources, N_SOME, &o, &oi, &err),
                     MFMM_ERR_NO_OPENCL);
    o.backend = MFMM_BACKEND_AUTO;
    assert_int_equal(mfmm_distance_matrix(mesh, some_sources, N_SOME, &o, &oi, &err), MFMM_OK);
    assert_int_equal(oi.backend_used, MFMM_BACKEND_THREADS);
    assert_memory_equal(out, ref, total * sizeof *out);
#ifdef MESHFMM_TEST_HAVE_CL
    assert_non_null(strstr(oi.backend_reason, "cannot load the OpenCL library"));
#else
    assert_true(strlen(oi.backend_reason) > 0);
#endif
    /* the environment names the loader when the options do not */
    setenv("MESHFMM_OPENCL_LIBRARY", "libmeshfmm-no-such-opencl.so.1", 1);
    o.opencl_options = NULL;
    memset(out, 0, total * sizeof *out);
    assert_int_equal(mfmm_distance_matrix(mesh, some_sources, N_SOME, &o, &oi, &err), MFMM_OK);
    assert_int_equal(oi.backend_used, MFMM_BACKEND_THREADS);
    assert_memory_equal(out, ref, total * sizeof *out);
    unsetenv("MESHFMM_OPENCL_LIBRARY");
    free(out);
    free(ref);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

/* Option structs carry their size: _init sets it, a wrong one is refused
 * with a message naming the struct. */
static void test_struct_size(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_icosphere(1);
    mfmm_mesh *mesh = tm_make(&g);
    mfmm_error err;
    mfmm_matrix_options o;
    mfmm_matrix_info oi = {.struct_size = sizeof oi};
    mfmm_matrix_options_init(&o);
    assert_int_equal(o.struct_size, sizeof o);
    double *out = malloc((size_t)g.nv * sizeof *out);
    assert_non_null(out);
    o.out = out;
    o.dtype = MFMM_FLOAT64;
    o.backend = MFMM_BACKEND_SERIAL;
    int32_t src = 0;
    o.struct_size = sizeof o + 8;
    assert_int_equal(mfmm_distance_matrix(mesh, &src, 1, &o, &oi, &err), MFMM_ERR_BAD_ARGUMENT);
    assert_non_null(strstr(err.message, "mfmm_matrix_options.struct_size"));
    o.struct_size = 0;
    assert_int_equal(mfmm_distance_matrix(mesh, &src, 1, &o, &oi, &err), MFMM_ERR_BAD_ARGUMENT);
    o.struct_size = sizeof o;
    assert_int_equal(mfmm_distance_matrix(mesh, &src, 1, &o, &oi, &err), MFMM_OK);

    mfmm_solve_options so;
    mfmm_solve_options_init(&so);
    assert_int_equal(so.struct_size, sizeof so);
    so.struct_size = 4;
    mfmm_solver *solver = NULL;
    assert_int_equal(mfmm_solver_create(mesh, &solver), MFMM_OK);
    mfmm_source s = tm_vertex_source(0);
    assert_int_equal(mfmm_solve(solver, &s, 1, &so, out, &err), MFMM_ERR_BAD_ARGUMENT);
    assert_non_null(strstr(err.message, "mfmm_solve_options.struct_size"));
    mfmm_solver_destroy(solver);

    mfmm_path_options po;
    mfmm_path_options_init(&po);
    assert_int_equal(po.struct_size, sizeof po);
    mfmm_mesh_options mo;
    mfmm_mesh_options_init(&mo);
    assert_int_equal(mo.struct_size, sizeof mo);
    mo.struct_size = 4; /* below sizeof(size_t) */
    mfmm_mesh *m2 = NULL;
    assert_int_equal(mfmm_mesh_create(g.V, g.nv, g.F, g.nf, &mo, &m2, &err),
                     MFMM_ERR_BAD_ARGUMENT);
    assert_non_null(strstr(err.message, "mfmm_mesh_options.struct_size"));
    assert_null(m2);
    free(out);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

int main(void)
{
    /* an empty vendors folder: no OpenCL platform in this process */
    char dir[] = "/tmp/mfmm_no_icd_XXXXXX";
    if (!mkdtemp(dir))
        return 1;
    setenv("OCL_ICD_VENDORS", dir, 1);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_names_and_defaults),
        cmocka_unit_test(test_bad_arguments),
        cmocka_unit_test(test_cpu_backends_equal_solve),
        cmocka_unit_test(test_all_vertices_costs_and_limit),
        cmocka_unit_test(test_targets_and_sparse),
        cmocka_unit_test(test_no_opencl_fallback),
        cmocka_unit_test(test_cancel),
        cmocka_unit_test(test_no_opencl_loader),
        cmocka_unit_test(test_struct_size),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    rmdir(dir);
    return rc;
}
