/* T-junctions closed by zero-area needle faces (src/mesh/tjunction.c): the
 * library splits the face across the needle's long edge at the needle's
 * middle vertex and drops the needle. The reference is the same surface
 * given resolved by hand (those pieces, no needle): every result per input
 * vertex equals its bit for bit (distances with and without the exact start
 * and with a per-face cost, matrix rows), face ids and points map back to
 * the input's faces, and paths and exact distances match the flat square's
 * Euclidean distance (analytic). Before, from vertex 1 the march reached M =
 * (.25, .25) at 1.0607 (round through (.5, .5)) where the surface gives
 * 0.7906. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "testutil.h"

/* The unit square, fanned around (.5, .5) = 4. Square: M = 5 = (.25, .25)
 * lies on edge 0-4 of face 0, closed by the needle 5 (0, 4, 5). Chain: two
 * vertices on that edge, 5 = (1/6, 1/6) and 6 = (1/3, 1/3), closed by the
 * needles 6 (0, 4, 5) and 7 (5, 4, 6), which take two rounds. */
static const double V[7 * 3] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, 0,
                                0.25, 0.25, 0, 0, 0, 0};
static const double VC[7 * 3] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, 0,
                                 1.0 / 6, 1.0 / 6, 0, 1.0 / 3, 1.0 / 3, 0};
static const int32_t F_SQ[6 * 3] = {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 5, 3, 5, 4, 0, 4, 5};
/* by hand: face 0 (0, 1, 4) cut at 5 into (0, 1, 5) and (5, 1, 4) */
static const int32_t H_SQ[6 * 3] = {0, 1, 5, 5, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 5, 3, 5, 4};
static const int32_t F_CH[8 * 3] = {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 5,
                                    3, 5, 6, 3, 6, 4, 0, 4, 5, 5, 4, 6};
static const int32_t H_CH[8 * 3] = {0, 1, 5, 5, 1, 6, 6, 1, 4, 1, 2, 4,
                                    2, 3, 4, 3, 0, 5, 3, 5, 6, 3, 6, 4};

/* A needle 1 (0, 1, 2) on a non-manifold edge 0-2 with two pages, 4 flat
 * and 6 upright, a face (0, 3, 1) below and (0, 4, 5) beyond page 4: every
 * page is split at 1 (tests/python/test_exact.py has its distances). */
static const double VB[7 * 3] = {0, 0, 0, 1, 0, 0, 2, 0, 0, 3, -1, 0,
                                 1, 1, 0, -0.5, 1.5, 0, 1, 0, 1};
static const int32_t F_BK[5 * 3] = {0, 3, 1, 0, 1, 2, 0, 2, 4, 0, 4, 5, 0, 6, 2};
static const int32_t H_BK[6 * 3] = {0, 3, 1, 0, 1, 4, 1, 2, 4, 0, 4, 5, 0, 6, 1, 1, 6, 2};

static mfmm_mesh *make(const double *v, int32_t nv, const int32_t *f, int32_t nf)
{
    mfmm_mesh *m = NULL;
    assert_int_equal(mfmm_mesh_create(v, nv, f, nf, NULL, &m, NULL), MFMM_OK);
    return m;
}

static void solve(mfmm_mesh *m, const mfmm_source *s, const mfmm_solve_options *o, double *d)
{
    mfmm_solver *solver = NULL;
    assert_int_equal(mfmm_solver_create(m, &solver), MFMM_OK);
    assert_int_equal(mfmm_solve(solver, s, 1, o, d, NULL), MFMM_OK);
    mfmm_solver_destroy(solver);
}

/* Rows from every vertex, plain and exact start, equal the hand-resolved
 * mesh's bit for bit; the counts stay the input's. */
static void check_rows(const double *v, int32_t nv, const int32_t *f, int32_t nf,
                       const int32_t *h, int32_t nh, int32_t n_needles)
{
    mfmm_mesh *m = make(v, nv, f, nf), *r = make(v, nv, h, nh);
    mfmm_mesh_info info = {.struct_size = sizeof info};
    assert_int_equal(mfmm_mesh_get_info(m, &info), MFMM_OK);
    assert_int_equal(info.n_faces, nf);
    assert_int_equal(mfmm_mesh_face_count(m), nf);
    assert_int_equal(info.n_degenerate_faces, n_needles);
    for (int start = 0; start < 2; start++) {
        mfmm_solve_options o;
        mfmm_solve_options_init(&o);
        o.exact_start_radius = start ? MFMM_EXACT_START_AUTO : 0.0;
        for (int32_t s = 0; s < nv; s++) {
            double a[8], b[8];
            mfmm_source src = tm_vertex_source(s);
            solve(m, &src, &o, a);
            solve(r, &src, &o, b);
            assert_memory_equal(a, b, (size_t)nv * sizeof *a);
        }
    }
    mfmm_mesh_destroy(m);
    mfmm_mesh_destroy(r);
}

static void test_rows_equal_the_resolved_mesh(void **state)
{
    (void)state;
    check_rows(V, 6, F_SQ, 6, H_SQ, 6, 1);
    check_rows(VC, 7, F_CH, 8, H_CH, 8, 2);
    check_rows(VB, 7, F_BK, 5, H_BK, 6, 1);
    /* the case of the module's comment: vertex 1 to M */
    mfmm_mesh *m = make(V, 6, F_SQ, 6);
    mfmm_solve_options o;
    mfmm_solve_options_init(&o);
    o.exact_start_radius = 0.0;
    double d[6];
    mfmm_source src = tm_vertex_source(1);
    solve(m, &src, &o, d);
    tm_assert_close(d[5], hypot(0.75, 0.25), 1e-12);
    mfmm_mesh_destroy(m);
}

/* A per-face cost of the input (the needle's entry unused; the pieces take
 * their face's), in mfmm_solve and in matrix rows, equals the resolved
 * mesh's with its pieces costed alike. */
static void test_per_face_cost(void **state)
{
    (void)state;
    mfmm_mesh *m = make(V, 6, F_SQ, 6), *r = make(V, 6, H_SQ, 6);
    const double cost[6] = {1.5, 2.0, 1.0, 3.0, 1.25, 1000.0};
    const double cost_h[6] = {1.5, 1.5, 2.0, 1.0, 3.0, 1.25};
    mfmm_solve_options o, oh;
    mfmm_solve_options_init(&o);
    o.cost = cost;
    o.cost_location = MFMM_COST_PER_FACE;
    oh = o;
    oh.cost = cost_h;
    double a[6 * 6], b[6 * 6];
    for (int32_t s = 0; s < 6; s++) {
        mfmm_source src = tm_vertex_source(s);
        solve(m, &src, &o, a);
        solve(r, &src, &oh, b);
        assert_memory_equal(a, b, sizeof(double) * 6);
    }
    mfmm_matrix_options mo, moh;
    mfmm_matrix_options_init(&mo);
    mo.backend = MFMM_BACKEND_SERIAL;
    mo.dtype = MFMM_FLOAT64;
    mo.cost = cost;
    mo.cost_location = MFMM_COST_PER_FACE;
    moh = mo;
    moh.cost = cost_h;
    mo.out = a;
    moh.out = b;
    assert_int_equal(mfmm_distance_matrix(m, NULL, 6, &mo, NULL, NULL), MFMM_OK);
    assert_int_equal(mfmm_distance_matrix(r, NULL, 6, &moh, NULL, NULL), MFMM_OK);
    assert_memory_equal(a, b, sizeof a);
    /* a cost array is as long as the input's faces: a bad entry at the
     * needle is still refused */
    double bad[6];
    memcpy(bad, cost, sizeof bad);
    bad[5] = -1.0;
    o.cost = bad;
    mfmm_solver *solver = NULL;
    mfmm_error err;
    mfmm_source src = tm_vertex_source(0);
    assert_int_equal(mfmm_solver_create(m, &solver), MFMM_OK);
    assert_int_equal(mfmm_solve(solver, &src, 1, &o, a, &err), MFMM_ERR_BAD_COST);
    assert_int_equal(err.index, 5);
    mfmm_solver_destroy(solver);
    mfmm_mesh_destroy(m);
    mfmm_mesh_destroy(r);
    /* the book: more pieces than input faces (both pages split) */
    m = make(VB, 7, F_BK, 5);
    r = make(VB, 7, H_BK, 6);
    const double cost_b[5] = {1.5, 1000.0, 2.0, 1.25, 3.0};
    const double cost_bh[6] = {1.5, 2.0, 2.0, 1.25, 3.0, 3.0};
    o.cost = cost_b;
    oh.cost = cost_bh;
    for (int32_t s = 0; s < 7; s++) {
        mfmm_source src7 = tm_vertex_source(s);
        solve(m, &src7, &o, a);
        solve(r, &src7, &oh, b);
        assert_memory_equal(a, b, sizeof(double) * 7);
    }
    mfmm_mesh_destroy(m);
    mfmm_mesh_destroy(r);
}

/* A point of a split face solves as the same point given in its piece of
 * the resolved mesh; a point of the needle is refused (zero area). The
 * exact solver gives the Euclidean distance from it (flat square). */
static void test_face_sources(void **state)
{
    (void)state;
    mfmm_mesh *m = make(V, 6, F_SQ, 6), *r = make(V, 6, H_SQ, 6);
    /* (.25, .05) = .7 V0 + .2 V1 + .1 V4 of face 0 (0, 1, 4) lies in piece
     * (0, 1, 5): .6 V0 + .2 V1 + .2 V5; (.6, .3) = .1 V0 + .3 V1 + .6 V4 in
     * piece (5, 1, 4): .2 V5 + .3 V1 + .5 V4 */
    const mfmm_source in[2] = {{0, 0, {0.7, 0.2, 0.1}, 0.0}, {0, 0, {0.1, 0.3, 0.6}, 0.0}};
    const mfmm_source hand[2] = {{0, 0, {0.6, 0.2, 0.2}, 0.0}, {0, 1, {0.2, 0.3, 0.5}, 0.0}};
    const double p[2][2] = {{0.25, 0.05}, {0.6, 0.3}};
    mfmm_exact_solver *ex = NULL;
    assert_int_equal(mfmm_exact_solver_create(m, &ex), MFMM_OK);
    for (int i = 0; i < 2; i++) {
        double a[6], b[6], e[6];
        solve(m, in + i, NULL, a);
        solve(r, hand + i, NULL, b);
        for (int v = 0; v < 6; v++)
            tm_assert_close(a[v], b[v], 1e-14);
        assert_int_equal(mfmm_solve_exact(ex, in + i, 1, NULL, e, NULL, NULL), MFMM_OK);
        for (int v = 0; v < 6; v++)
            tm_assert_close(e[v], hypot(V[3 * v] - p[i][0], V[3 * v + 1] - p[i][1]), 1e-12);
    }
    mfmm_exact_solver_destroy(ex);
    mfmm_source needle = {0, 5, {0.2, 0.3, 0.5}, 0.0};
    mfmm_solver *solver = NULL;
    mfmm_error err;
    double d[6];
    assert_int_equal(mfmm_solver_create(m, &solver), MFMM_OK);
    assert_int_equal(mfmm_solve(solver, &needle, 1, NULL, d, &err), MFMM_ERR_DEGENERATE_SOURCE);
    assert_non_null(strstr(err.message, "zero area"));
    mfmm_solver_destroy(solver);
    mfmm_mesh_destroy(m);
    mfmm_mesh_destroy(r);
}

/* Paths cross the junction straight: from vertex 1 to M and to a point of
 * the split face beyond it; every point names an input face (never the
 * needle) and its barycentric coordinates give its position there. */
static void test_paths(void **state)
{
    (void)state;
    mfmm_mesh *m = make(V, 6, F_SQ, 6);
    double d[6];
    mfmm_source src = tm_vertex_source(1);
    solve(m, &src, NULL, d);
    mfmm_path_options po;
    mfmm_path_options_init(&po);
    po.sources = &src;
    po.n_sources = 1;
    const mfmm_source targets[3] = {{5, -1, {0, 0, 0}, 0.0},
                                    {0, 0, {0.7, 0.2, 0.1}, 0.0},  /* (.25, .05) */
                                    {0, 3, {0.2, 0.6, 0.2}, 0.0}}; /* (.05, .25), beyond 0-5 */
    const double at[3][2] = {{0.25, 0.25}, {0.25, 0.05}, {0.05, 0.25}};
    for (int i = 0; i < 3; i++) {
        mfmm_surface_point pts[64];
        int32_t np = 0;
        double len = 0.0;
        assert_int_equal(mfmm_trace_path(m, d, targets + i, &po, pts, 64, &np, &len, NULL), MFMM_OK);
        tm_assert_close(len, hypot(1.0 - at[i][0], at[i][1]), 1e-12);
        for (int32_t k = 0; k < np; k++) {
            assert_true(pts[k].face >= 0 && pts[k].face < 5);
            double x[3] = {0, 0, 0}, sum = 0.0;
            for (int c = 0; c < 3; c++) {
                assert_true(pts[k].bary[c] >= 0.0);
                sum += pts[k].bary[c];
                for (int dd = 0; dd < 3; dd++)
                    x[dd] += pts[k].bary[c] * V[3 * F_SQ[3 * pts[k].face + c] + dd];
            }
            tm_assert_close(sum, 1.0, 1e-12);
            for (int dd = 0; dd < 3; dd++)
                tm_assert_close(x[dd], pts[k].xyz[dd], 1e-12);
        }
    }
    mfmm_mesh_destroy(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rows_equal_the_resolved_mesh),
        cmocka_unit_test(test_per_face_cost),
        cmocka_unit_test(test_face_sources),
        cmocka_unit_test(test_paths),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
