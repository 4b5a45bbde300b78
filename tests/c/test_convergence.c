/* Convergence against analytic distances: flat grid (Euclidean), unit
 * icosphere (great circle), and the stretched lattice whose corners are all
 * 120 degrees, with and without the unfolding of section 4.2. The calibrated
 * orders are the paper's plain start's (exact_start_radius 0); the exact
 * start is checked against it on the same meshes, and the window method
 * against the great circle on the icospheres. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <cmocka.h>

#include "testutil.h"

/* Mean relative error (%) of a solve from the vertex nearest `src` against
 * Euclidean (sphere = 0) or great-circle (sphere = 1) distance. */
static double solve_error_m(mfmm_gen_mesh *g, const double src[3], int sphere, int unfolding,
                            double exact_r, mfmm_method method, double *max_err)
{
    mfmm_mesh *mesh = tm_make(g);
    mfmm_solver *solver = NULL;
    assert_int_equal(mfmm_solver_create(mesh, &solver), MFMM_OK);
    double *d = malloc((size_t)g->nv * sizeof *d), *e = malloc((size_t)g->nv * sizeof *e);
    assert_non_null(d);
    assert_non_null(e);
    int32_t s = tm_nearest_vertex(g, src);
    mfmm_source source = tm_vertex_source(s);
    mfmm_solve_options opt;
    mfmm_solve_options_init(&opt);
    opt.unfolding = unfolding;
    opt.exact_start_radius = exact_r;
    opt.method = method;
    assert_int_equal(mfmm_solve(solver, &source, 1, &opt, d, NULL), MFMM_OK);
    const double *p = g->V + 3 * (size_t)s;
    for (int32_t v = 0; v < g->nv; v++) {
        const double *q = g->V + 3 * (size_t)v;
        if (sphere) {
            double c = p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
            e[v] = acos(fmax(-1.0, fmin(1.0, c)));
        } else {
            e[v] = sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]));
        }
        assert_true(isfinite(d[v]));
    }
    double mre = tm_mean_rel_error(d, e, g->nv);
    if (max_err)
        *max_err = tm_max_error(d, e, g->nv, sphere ? TM_PI : 1.0);
    free(d);
    free(e);
    mfmm_solver_destroy(solver);
    mfmm_mesh_destroy(mesh);
    return mre;
}

static double solve_error_r(mfmm_gen_mesh *g, const double src[3], int sphere, int unfolding,
                            double exact_r, double *max_err)
{
    return solve_error_m(g, src, sphere, unfolding, exact_r, MFMM_METHOD_FMM, max_err);
}

/* The plain start (the paper's), whose orders the tests below calibrate. */
static double solve_error(mfmm_gen_mesh *g, const double src[3], int sphere, int unfolding,
                          double *max_err)
{
    return solve_error_r(g, src, sphere, unfolding, 0.0, max_err);
}

static void test_flat_grid_converges(void **state)
{
    (void)state;
    const double c[3] = {0.5, 0.5, 0.0};
    double h[4], err[4];
    for (int i = 0; i < 4; i++) {
        int n = 20 << i;
        mfmm_gen_mesh g = mfmm_gen_grid(n);
        h[i] = 1.0 / n;
        err[i] = solve_error(&g, c, 0, 1, NULL);
        print_message("grid n=%d: mean relative error %.4f%%\n", n, err[i]);
        if (i > 0)
            assert_true(err[i] < err[i - 1]);
        mfmm_gen_free(&g);
    }
    assert_true(tm_fitted_order(h, err, 4) >= 0.55);
}

/* Levels 4..7 (2.5k to 164k vertices), source at an icosahedron vertex, as
 * geometry-central's figures (1.46%, 0.96%, 0.61% at 2.5k, 10k, 41k). */
static void test_icosphere_converges(void **state)
{
    (void)state;
    double h[4], err[4];
    for (int i = 0; i < 4; i++) {
        mfmm_gen_mesh g = mfmm_gen_icosphere(4 + i);
        const double top[3] = {g.V[0], g.V[1], g.V[2]};
        h[i] = 1.0 / sqrt((double)g.nv);
        double mx;
        err[i] = solve_error(&g, top, 1, 1, &mx);
        print_message("icosphere nv=%d: mean relative error %.4f%%, max %.4f%% of pi\n", g.nv,
                      err[i], mx);
        if (g.nv == 10242)
            assert_true(err[i] < 1.0);
        mfmm_gen_free(&g);
    }
    double order = tm_fitted_order(h, err, 4);
    print_message("icosphere fitted order %.3f\n", order);
    assert_true(order >= 0.55);
}

/* Stretched 3x, the lattice's triangles have 120-degree corners: without
 * unfolding FMM does not converge there; with it, it does (section 4.2). */
static void test_obtuse_lattice_needs_unfolding(void **state)
{
    (void)state;
    double h[4], with[4], without[4];
    const double c[3] = {1.5, 0.43, 0.0};
    for (int i = 0; i < 4; i++) {
        int n = 20 << i;
        mfmm_gen_mesh g = mfmm_gen_lattice(n, 3.0);
        mfmm_mesh *mesh = tm_make(&g);
        mfmm_mesh_info info = {.struct_size = sizeof info};
        mfmm_mesh_get_info(mesh, &info);
        assert_true(info.n_obtuse_corners >= g.nf * 9 / 10);
        assert_true(info.n_virtual_edges >= info.n_obtuse_corners * 9 / 10);
        mfmm_mesh_destroy(mesh);
        h[i] = 1.0 / n;
        with[i] = solve_error(&g, c, 0, 1, NULL);
        without[i] = solve_error(&g, c, 0, 0, NULL);
        print_message("lattice n=%d: unfolding %.4f%%, plain %.4f%%\n", n, with[i], without[i]);
        assert_true(with[i] * 3.0 < without[i]);
        mfmm_gen_free(&g);
    }
    double order = tm_fitted_order(h, with, 4);
    double order_plain = tm_fitted_order(h, without, 4);
    print_message("lattice fitted order: unfolding %.3f, plain %.3f\n", order, order_plain);
    assert_true(order >= 0.5);
    assert_true(order_plain < 0.2);
}

/* The exact start (default radius) against the plain start on the meshes
 * above: never worse in mean error; on the icospheres of 2.5k and 10k
 * vertices at most 0.6x. Prints the rows of the
 * convergence table of bench/RESULTS.md. */
static void test_exact_start_lowers_error(void **state)
{
    (void)state;
    double h[4], plain[4], exact[4];
    for (int i = 0; i < 4; i++) {
        mfmm_gen_mesh g = mfmm_gen_icosphere(4 + i);
        const double top[3] = {g.V[0], g.V[1], g.V[2]};
        h[i] = 1.0 / sqrt((double)g.nv);
        double mx_p, mx_e;
        plain[i] = solve_error_r(&g, top, 1, 1, 0.0, &mx_p);
        exact[i] = solve_error_r(&g, top, 1, 1, MFMM_EXACT_START_RADIUS, &mx_e);
        print_message("icosphere nv=%d: plain %.4f%% (max %.4f%% of pi), exact start %.4f%% "
                      "(max %.4f%%), ratio %.3f\n",
                      g.nv, plain[i], mx_p, exact[i], mx_e, exact[i] / plain[i]);
        assert_true(exact[i] <= plain[i]);
        assert_true(mx_e <= mx_p);
        if (i < 2)
            assert_true(exact[i] <= 0.6 * plain[i]);
        mfmm_gen_free(&g);
    }
    print_message("icosphere fitted order: plain %.3f, exact start %.3f\n",
                  tm_fitted_order(h, plain, 4), tm_fitted_order(h, exact, 4));
    const double c[3] = {1.5, 0.43, 0.0};
    for (int i = 0; i < 4; i++) {
        int n = 20 << i;
        mfmm_gen_mesh g = mfmm_gen_lattice(n, 3.0);
        h[i] = 1.0 / n;
        plain[i] = solve_error_r(&g, c, 0, 1, 0.0, NULL);
        exact[i] = solve_error_r(&g, c, 0, 1, MFMM_EXACT_START_RADIUS, NULL);
        print_message("lattice n=%d: plain %.4f%%, exact start %.4f%%, ratio %.3f\n", n, plain[i],
                      exact[i], exact[i] / plain[i]);
        assert_true(exact[i] <= plain[i]);
        mfmm_gen_free(&g);
    }
    print_message("lattice fitted order: plain %.3f, exact start %.3f\n",
                  tm_fitted_order(h, plain, 4), tm_fitted_order(h, exact, 4));
    const double cg[3] = {0.5, 0.5, 0.0};
    for (int i = 0; i < 4; i++) {
        int n = 20 << i;
        mfmm_gen_mesh g = mfmm_gen_grid(n);
        h[i] = 1.0 / n;
        plain[i] = solve_error_r(&g, cg, 0, 1, 0.0, NULL);
        exact[i] = solve_error_r(&g, cg, 0, 1, MFMM_EXACT_START_RADIUS, NULL);
        print_message("grid n=%d: plain %.4f%%, exact start %.4f%%, ratio %.3f\n", n, plain[i],
                      exact[i], exact[i] / plain[i]);
        assert_true(exact[i] <= plain[i]);
        mfmm_gen_free(&g);
    }
    print_message("grid fitted order: plain %.3f, exact start %.3f\n",
                  tm_fitted_order(h, plain, 4), tm_fitted_order(h, exact, 4));
}

/* The window method against great-circle distances on icospheres of 2.5k
 * to 41k vertices: a mean error a little above what it measures, at most a
 * quarter of the default march's, and a max error below the march's. */
static void test_windows_on_icospheres(void **state)
{
    (void)state;
    /* measured: 0.0426, 0.0315, 0.0379 % (max 0.120, 0.098, 0.081 % of pi;
     * the march from the exact start 0.204, 0.281, 0.258 %) */
    static const double bound[3] = {0.045, 0.034, 0.040};
    for (int i = 0; i < 3; i++) {
        mfmm_gen_mesh g = mfmm_gen_icosphere(4 + i);
        const double top[3] = {g.V[0], g.V[1], g.V[2]};
        double mx_m, mx_w;
        double m = solve_error_r(&g, top, 1, 1, MFMM_EXACT_START_RADIUS, &mx_m);
        double w = solve_error_m(&g, top, 1, 1, MFMM_EXACT_START_RADIUS, MFMM_METHOD_WINDOWS,
                                 &mx_w);
        print_message("icosphere nv=%d: windows %.4f%% (max %.4f%% of pi), march %.4f%% "
                      "(max %.4f%%)\n", g.nv, w, mx_w, m, mx_m);
        assert_true(w <= bound[i]);
        assert_true(w <= 0.25 * m);
        assert_true(mx_w <= mx_m);
        mfmm_gen_free(&g);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_flat_grid_converges),
        cmocka_unit_test(test_icosphere_converges),
        cmocka_unit_test(test_obtuse_lattice_needs_unfolding),
        cmocka_unit_test(test_exact_start_lowers_error),
        cmocka_unit_test(test_windows_on_icospheres),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
