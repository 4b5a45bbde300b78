/* The two-slot window prototype (src/exact/slots.c, internal): every value is
 * a path's length (never below the exact solver's beyond 1e-9 relative) and
 * every vertex the exact solver reaches is reached, on flat, curved,
 * non-manifold and boundary meshes and under each rule measured in
 * bench/micro/bench_slots.c. The main rule (SL_RULE_MAIN) equals the
 * Euclidean distances on triangulations of convex planar regions (random
 * Delaunay points in a square and a disc, stretched to needles and obtuse
 * corners) to 1e-12 relative, and the exact solver's on the obtuse
 * lattice, at K = 2 and 3. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>

#include "exact/slots.h"
#include "io/generate.h"
#include "mesh/mesh.h"
#include "mesh/order.h"
#include "meshfmm.h"

static const int rules[] = {SL_RULE_MAIN, 0, 2, 66, 194, 322, 450, 67, 74, 78};

/* max |slots - exact| over three sources, with the lower-bound and reach
 * checks asserted */
static double check_mesh(const double *V, int32_t nv, const int32_t *F, int32_t nf, int rule)
{
    mfmm_mesh *mesh = NULL;
    mfmm_exact_solver *ex = NULL;
    mfmm_slots *sl = NULL;
    mfmm_error err;
    assert_int_equal(mfmm_mesh_create(V, nv, F, nf, NULL, &mesh, &err), MFMM_OK);
    assert_int_equal(mfmm_exact_solver_create(mesh, &ex), MFMM_OK);
    assert_int_equal(mfmm_slots_create(mesh, &sl), MFMM_OK);
    mfmm_slots_set_rule(sl, rule);
    double *e = malloc((size_t)nv * sizeof *e), *d = malloc((size_t)nv * sizeof *d);
    assert_non_null(e);
    assert_non_null(d);
    double worst = 0.0;
    int32_t srcs[3] = {F[0], F[3 * (nf / 2) + 1], F[3 * (nf - 1) + 2]};
    for (int q = 0; q < 3; q++) {
        mfmm_source s0 = {srcs[q], -1, {0, 0, 0}, 0.0};
        assert_int_equal(mfmm_solve_exact(ex, &s0, 1, NULL, e, NULL, NULL), MFMM_OK);
        mfmm_slots_solve(sl, mfmm_vertex_in(mesh, srcs[q]), d);
        for (int32_t i = 0; i < nv; i++) {
            int32_t v = mfmm_vertex_out(mesh, i);
            if (!isfinite(e[v]))
                continue;
            assert_true(isfinite(d[i]));
            assert_true(d[i] >= e[v] - 1e-9 * e[v] - 1e-300);
            worst = fmax(worst, fabs(d[i] - e[v]));
        }
    }
    free(e);
    free(d);
    mfmm_slots_destroy(sl);
    mfmm_exact_solver_destroy(ex);
    mfmm_mesh_destroy(mesh);
    return worst;
}

static void gen_check(mfmm_gen_mesh g, int flat)
{
    assert_true(g.nv > 0);
    for (size_t r = 0; r < sizeof rules / sizeof *rules; r++) {
        double worst = check_mesh(g.V, g.nv, g.F, g.nf, rules[r]);
        if (flat && (rules[r] == 194 || rules[r] == SL_RULE_MAIN) && !(worst <= 1e-12))
            print_message("flat nv %d rule %d: max abs diff %.3e\n", (int)g.nv, rules[r], worst);
        if (flat && (rules[r] == 194 || rules[r] == SL_RULE_MAIN))
            assert_true(worst <= 1e-12);
    }
    mfmm_gen_free(&g);
}

/* Rule SL_RULE_MAIN from five vertex sources on a planar mesh: every
 * distance equals the Euclidean one to 1e-12 relative (convex: 1) or the
 * exact solver's (not convex), K windows per half-edge */
static void flat_exact(mfmm_gen_mesh g, int convex, int K)
{
    assert_true(g.nv > 0);
    mfmm_mesh *mesh = NULL;
    mfmm_exact_solver *ex = NULL;
    mfmm_slots *sl = NULL;
    mfmm_error err;
    assert_int_equal(mfmm_mesh_create(g.V, g.nv, g.F, g.nf, NULL, &mesh, &err), MFMM_OK);
    assert_int_equal(mfmm_exact_solver_create(mesh, &ex), MFMM_OK);
    assert_int_equal(mfmm_slots_create(mesh, &sl), MFMM_OK);
    assert_true(mfmm_slots_set_k(sl, K));
    double *e = malloc((size_t)g.nv * sizeof *e), *d = malloc((size_t)g.nv * sizeof *d);
    assert_non_null(e);
    assert_non_null(d);
    int32_t srcs[5] = {0, g.nv / 5, g.nv / 2, g.nv - 1 - g.nv / 7, g.nv - 1};
    for (int q = 0; q < 5; q++) {
        int32_t s = srcs[q];
        if (!convex) {
            mfmm_source s0 = {s, -1, {0, 0, 0}, 0.0};
            assert_int_equal(mfmm_solve_exact(ex, &s0, 1, NULL, e, NULL, NULL), MFMM_OK);
        }
        mfmm_slots_solve(sl, mfmm_vertex_in(mesh, s), d);
        for (int32_t i = 0; i < g.nv; i++) {
            int32_t v = mfmm_vertex_out(mesh, i);
            double ref = convex ? hypot(g.V[3 * v] - g.V[3 * s], g.V[3 * v + 1] - g.V[3 * s + 1])
                                : e[v];
            double tol = 1e-12 * ref + 1e-15;
            if (!(fabs(d[i] - ref) <= tol))
                print_message("nv %d K %d source %d vertex %d: %.17g, reference %.17g\n",
                              (int)g.nv, K, (int)s, (int)v, d[i], ref);
            assert_true(fabs(d[i] - ref) <= tol);
        }
    }
    free(e);
    free(d);
    mfmm_slots_destroy(sl);
    mfmm_exact_solver_destroy(ex);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

/* triangulations of convex planar regions: random Delaunay points in a
 * square and a disc, stretched 1, 8 and 30 times (needles, obtuse
 * corners); the grid; the obtuse lattice (not convex: against the exact
 * solver) */
static void test_flat_exact(void **state)
{
    (void)state;
    static const double stretch[3] = {1.0, 8.0, 30.0};
    for (int K = 2; K <= 3; K++) {
        for (int disc = 0; disc < 2; disc++)
            for (int si = 0; si < 3; si++)
                for (uint64_t seed = 1; seed <= 3; seed++)
                    flat_exact(mfmm_gen_delaunay(300, disc, stretch[si], seed), 1, K);
        flat_exact(mfmm_gen_delaunay(1500, 0, 8.0, 7), 1, K);
        flat_exact(mfmm_gen_delaunay(1500, 1, 30.0, 7), 1, K);
        flat_exact(mfmm_gen_grid(24), 1, K);
        flat_exact(mfmm_gen_lattice(8, 3.0), 0, K);
        flat_exact(mfmm_gen_lattice(20, 3.0), 0, K);
    }
}

/* Three vertex sources with values, and a point in a face: on a planar
 * convex mesh (flat 1) the Euclidean distances to 1e-12 relative (the
 * multi-source field also equals the min of the single-source ones plus
 * their values); on any mesh never below the exact solver's. */
static void sources_check(mfmm_gen_mesh g, int flat)
{
    assert_true(g.nv > 0);
    mfmm_mesh *mesh = NULL;
    mfmm_exact_solver *ex = NULL;
    mfmm_slots *sl = NULL;
    mfmm_error err;
    assert_int_equal(mfmm_mesh_create(g.V, g.nv, g.F, g.nf, NULL, &mesh, &err), MFMM_OK);
    assert_int_equal(mfmm_exact_solver_create(mesh, &ex), MFMM_OK);
    assert_int_equal(mfmm_slots_create(mesh, &sl), MFMM_OK);
    size_t nv = (size_t)g.nv;
    double *e = malloc(nv * sizeof *e), *d = malloc(nv * sizeof *d), *m = malloc(nv * sizeof *m);
    double *one = malloc(nv * sizeof *one);
    assert_non_null(e);
    assert_non_null(d);
    assert_non_null(m);
    assert_non_null(one);
    int32_t src[3] = {g.nv / 9, g.nv / 2, g.nv - 1 - g.nv / 5}, in[3];
    double val[3] = {0.0, 0.1, 0.35};
    mfmm_source es[3];
    for (int q = 0; q < 3; q++) {
        in[q] = mfmm_vertex_in(mesh, src[q]);
        es[q] = (mfmm_source){src[q], -1, {0, 0, 0}, val[q]};
    }
    /* vertex sources */
    for (size_t i = 0; i < nv; i++)
        m[i] = INFINITY;
    for (int q = 0; q < 3; q++) {
        mfmm_slots_solve(sl, in[q], one);
        for (size_t i = 0; i < nv; i++)
            m[i] = fmin(m[i], val[q] + one[i]);
    }
    mfmm_slots_solve_multi(sl, 3, in, val, d);
    assert_int_equal(mfmm_solve_exact(ex, es, 3, NULL, e, NULL, NULL), MFMM_OK);
    /* flat: the Euclidean distances but for a few vertices where a
     * source's window, trimmed away across another source's region, comes
     * back as two pieces that may not join (sl_keep: their rays between
     * were not traced); measured 2 of 3567 vertices, 0.9 % over */
    int off = 0;
    for (int32_t i = 0; i < g.nv; i++) {
        int32_t v = mfmm_vertex_out(mesh, i);
        assert_true(d[i] >= e[v] - 1e-9 * e[v]);
        if (!flat)
            continue;
        double ref = INFINITY;
        for (int q = 0; q < 3; q++)
            ref = fmin(ref, val[q] + hypot(g.V[3 * v] - g.V[3 * src[q]],
                                           g.V[3 * v + 1] - g.V[3 * src[q] + 1]));
        assert_true(d[i] >= ref - 1e-12 * ref && d[i] <= ref * 1.01);
        off += d[i] > ref + 1e-12 * ref || fabs(m[i] - ref) > 1e-12 * ref;
    }
    assert_true(off <= 2);
    /* a point in a face */
    for (int32_t fi = 0; fi < g.nf; fi += g.nf / 3 + 1) {
        double w[3] = {0.2, 0.5, 0.3};
        mfmm_source fs = {-1, fi, {w[0], w[1], w[2]}, 0.0};
        int32_t f = mfmm_face_in(mesh, fi), fv[3];
        for (int j = 0; j < 3; j++)
            fv[j] = mfmm_vertex_in(mesh, g.F[3 * fi + j]);
        mfmm_slots_solve_face(sl, f, fv, w, d);
        assert_int_equal(mfmm_solve_exact(ex, &fs, 1, NULL, e, NULL, NULL), MFMM_OK);
        double p[2] = {0.0, 0.0};
        for (int j = 0; j < 3; j++) {
            p[0] += w[j] * g.V[3 * g.F[3 * fi + j]];
            p[1] += w[j] * g.V[3 * g.F[3 * fi + j] + 1];
        }
        for (int32_t i = 0; i < g.nv; i++) {
            int32_t v = mfmm_vertex_out(mesh, i);
            if (!isfinite(e[v]))
                continue;
            assert_true(isfinite(d[i]));
            assert_true(d[i] >= e[v] - 1e-9 * e[v]);
            if (!flat)
                continue;
            double ref = hypot(g.V[3 * v] - p[0], g.V[3 * v + 1] - p[1]);
            if (!(fabs(d[i] - ref) <= 1e-12 * ref))
                print_message("face %d vertex %d: %.17g, euclid %.17g\n", (int)fi, (int)v, d[i],
                              ref);
            assert_true(fabs(d[i] - ref) <= 1e-12 * ref);
        }
    }
    free(e);
    free(d);
    free(m);
    free(one);
    mfmm_slots_destroy(sl);
    mfmm_exact_solver_destroy(ex);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

static void test_sources(void **state)
{
    (void)state;
    for (uint64_t seed = 1; seed <= 3; seed++) {
        sources_check(mfmm_gen_delaunay(300, 0, 1.0, seed), 1);
        sources_check(mfmm_gen_delaunay(300, 1, 8.0, seed), 1);
        sources_check(mfmm_gen_delaunay(300, 0, 30.0, seed), 1);
    }
    sources_check(mfmm_gen_grid(16), 1);
    sources_check(mfmm_gen_icosphere(3), 0);
    sources_check(mfmm_gen_sine(24), 0);
    sources_check(mfmm_gen_torus(24, 12, 1.0, 0.3), 0);
}

static void test_flat(void **state)
{
    (void)state;
    gen_check(mfmm_gen_grid(16), 1);
    gen_check(mfmm_gen_grid(7), 1);
    /* (not convex: its zigzag sides bend paths; rule 194 leaves the corner
     * (0, 0) 0.058 above the exact value from vertex 37 of lattice(8, 3),
     * so the lower bound only; the main rule: test_flat_exact) */
    gen_check(mfmm_gen_lattice(12, 3.0), 0);
}

static void test_curved(void **state)
{
    (void)state;
    gen_check(mfmm_gen_icosphere(3), 0);
    gen_check(mfmm_gen_sine(24), 0);
    gen_check(mfmm_gen_torus(24, 12, 1.0, 0.3), 0);
}

static void test_files(void **state)
{
    (void)state;
    static const char *const names[] = {"hand_lowres.obj", "beetle.obj", "wingnut.obj"};
    for (int i = 0; i < 3; i++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/meshes/%s", MESHFMM_TEST_DATA_DIR, names[i]);
        double *V = NULL;
        int32_t *F = NULL, nv = 0, nf = 0;
        mfmm_error err;
        assert_int_equal(mfmm_load_mesh(path, &V, &nv, &F, &nf, &err), MFMM_OK);
        for (size_t r = 0; r < sizeof rules / sizeof *rules; r++)
            check_mesh(V, nv, F, nf, rules[r]);
        mfmm_free(V);
        mfmm_free(F);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_flat),
        cmocka_unit_test(test_flat_exact),
        cmocka_unit_test(test_sources),
        cmocka_unit_test(test_curved),
        cmocka_unit_test(test_files),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
