/* Coincident vertices in mfmm_mesh_info, farthest-point sampling against a
 * loop of full solves, and Voronoi labels against the argmin over
 * single-source solves. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "io/generate.h"
#include "meshfmm.h"
#include "testutil.h"

static void test_coincident_counts(void **state)
{
    (void)state;
    /* a unit square as two triangles that share no vertex id: vertices 4
     * and 5 repeat 1 and 2 (a seam), and an unreferenced copy of 0 */
    double V[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 1, 0, 0, -0.0, 1, 0, 0, 0, 0};
    int32_t F[] = {0, 1, 2, 4, 3, 5};
    mfmm_mesh *mesh = NULL;
    assert_int_equal(mfmm_mesh_create(V, 7, F, 2, NULL, &mesh, NULL), MFMM_OK);
    mfmm_mesh_info info = {.struct_size = sizeof info};
    assert_int_equal(mfmm_mesh_get_info(mesh, &info), MFMM_OK);
    assert_int_equal(info.n_components, 2);
    assert_int_equal(info.n_unreferenced_vertices, 1);
    assert_int_equal(info.n_coincident_vertices, 2); /* -0.0 equals 0.0 */
    assert_int_equal(info.n_welded_components, 1);
    mfmm_mesh_destroy(mesh);
    /* welded, nothing coincides */
    int32_t G[] = {0, 1, 2, 1, 3, 2};
    assert_int_equal(mfmm_mesh_create(V, 4, G, 2, NULL, &mesh, NULL), MFMM_OK);
    assert_int_equal(mfmm_mesh_get_info(mesh, &info), MFMM_OK);
    assert_int_equal(info.n_coincident_vertices, 0);
    assert_int_equal(info.n_welded_components, 1);
    mfmm_mesh_destroy(mesh);
}

/* The reference: k full solves, the running minimum, the farthest vertex
 * not chosen (ties to the lowest id). */
static void brute_fps(mfmm_mesh *mesh, int32_t nv, int32_t start, int32_t k, int32_t *pts,
                      double *radii, double *dmin)
{
    mfmm_solver *s = NULL;
    assert_int_equal(mfmm_solver_create(mesh, &s), MFMM_OK);
    double *d = malloc((size_t)nv * sizeof *d);
    uint8_t *chosen = calloc((size_t)nv, 1);
    for (int32_t v = 0; v < nv; v++)
        dmin[v] = INFINITY;
    int32_t next = start;
    double reach = INFINITY;
    for (int32_t i = 0; i < k; i++) {
        pts[i] = next;
        radii[i] = reach;
        chosen[next] = 1;
        mfmm_source src = tm_vertex_source(next);
        assert_int_equal(mfmm_solve(s, &src, 1, NULL, d, NULL), MFMM_OK);
        for (int32_t v = 0; v < nv; v++)
            if (d[v] < dmin[v])
                dmin[v] = d[v];
        reach = -1.0;
        for (int32_t v = 0; v < nv; v++)
            if (!chosen[v] && dmin[v] > reach) {
                reach = dmin[v];
                next = v;
            }
    }
    for (int32_t i = 0; i < k; i++)
        dmin[pts[i]] = 0.0;
    free(d);
    free(chosen);
    mfmm_solver_destroy(s);
}

static void check_fps(mfmm_gen_mesh g, int32_t start, int32_t k)
{
    mfmm_mesh *mesh = tm_make(&g);
    mfmm_solver *s = NULL;
    assert_int_equal(mfmm_solver_create(mesh, &s), MFMM_OK);
    int32_t *pts = malloc((size_t)k * sizeof *pts), *ref = malloc((size_t)k * sizeof *ref);
    double *radii = malloc((size_t)k * sizeof *radii), *rref = malloc((size_t)k * sizeof *rref);
    double *d = malloc((size_t)g.nv * sizeof *d), *dref = malloc((size_t)g.nv * sizeof *dref);
    mfmm_error err;
    assert_int_equal(mfmm_farthest_points(s, start, k, NULL, pts, radii, d, &err), MFMM_OK);
    brute_fps(mesh, g.nv, start, k, ref, rref, dref);
    for (int32_t i = 0; i < k; i++) {
        assert_int_equal(pts[i], ref[i]);
        assert_true(radii[i] == rref[i]);
    }
    for (int32_t v = 0; v < g.nv; v++)
        assert_true(d[v] == dref[v]);
    free(pts);
    free(ref);
    free(radii);
    free(rref);
    free(d);
    free(dref);
    mfmm_solver_destroy(s);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

static void test_fps_equals_full_solves(void **state)
{
    (void)state;
    check_fps(mfmm_gen_grid(12), 0, 40);        /* many exact ties */
    check_fps(mfmm_gen_icosphere(3), 7, 60);
    check_fps(mfmm_gen_sine(16), 100, 50);
    check_fps(mfmm_gen_lattice(10, 3.0), 5, 121); /* every vertex */
}

static void test_fps_errors(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_grid(4);
    mfmm_mesh *mesh = tm_make(&g);
    mfmm_solver *s = NULL;
    assert_int_equal(mfmm_solver_create(mesh, &s), MFMM_OK);
    int32_t pts[32];
    mfmm_error err;
    assert_int_equal(mfmm_farthest_points(s, 0, 26, NULL, pts, NULL, NULL, &err),
                     MFMM_ERR_BAD_COUNT);
    assert_int_equal(mfmm_farthest_points(s, 0, 0, NULL, pts, NULL, NULL, &err),
                     MFMM_ERR_BAD_COUNT);
    assert_int_equal(mfmm_farthest_points(s, 25, 3, NULL, pts, NULL, NULL, &err),
                     MFMM_ERR_BAD_SOURCE);
    assert_int_equal(mfmm_farthest_points(s, 0, 3, NULL, NULL, NULL, NULL, &err),
                     MFMM_ERR_NULL_POINTER);
    mfmm_solve_options o;
    mfmm_solve_options_init(&o);
    o.max_distance = 1.0;
    assert_int_equal(mfmm_farthest_points(s, 0, 3, &o, pts, NULL, NULL, &err),
                     MFMM_ERR_BAD_ARGUMENT);
    /* all 25 vertices: each once */
    assert_int_equal(mfmm_farthest_points(s, 3, 25, NULL, pts, NULL, NULL, &err), MFMM_OK);
    int seen[25] = {0};
    for (int i = 0; i < 25; i++)
        seen[pts[i]]++;
    for (int i = 0; i < 25; i++)
        assert_int_equal(seen[i], 1);
    mfmm_solver_destroy(s);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

static void test_voronoi_argmin(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_icosphere(4);
    mfmm_mesh *mesh = tm_make(&g);
    mfmm_mesh_info info = {.struct_size = sizeof info};
    assert_int_equal(mfmm_mesh_get_info(mesh, &info), MFMM_OK);
    mfmm_solver *s = NULL;
    assert_int_equal(mfmm_solver_create(mesh, &s), MFMM_OK);
    enum { NS = 4 };
    mfmm_source src[NS] = {tm_vertex_source(0), tm_vertex_source(500), tm_vertex_source(1700),
                           {.vertex = -1, .face = 900, .bary = {0.2, 0.3, 0.5}}};
    size_t nv = (size_t)g.nv;
    double *all = malloc(nv * sizeof *all), *one = malloc(NS * nv * sizeof *one);
    int32_t *labels = malloc(nv * sizeof *labels);
    assert_int_equal(mfmm_solve(s, src, NS, NULL, all, NULL), MFMM_OK);
    for (int i = 0; i < NS; i++)
        assert_int_equal(mfmm_solve(s, src + i, 1, NULL, one + (size_t)i * nv, NULL), MFMM_OK);
    mfmm_error err;
    assert_int_equal(mfmm_voronoi_labels(mesh, all, src, NS, labels, &err), MFMM_OK);
    int mismatches = 0;
    for (size_t v = 0; v < nv; v++) {
        int best = 0, second = -1;
        for (int i = 1; i < NS; i++)
            if (one[i * nv + v] < one[best * nv + v])
                best = i;
        for (int i = 0; i < NS; i++)
            if (i != best && (second < 0 || one[i * nv + v] < one[second * nv + v]))
                second = i;
        if (labels[v] != best) {
            mismatches++;
            /* only on a cell's border: the two nearest within an edge */
            assert_int_equal(labels[v], second);
            assert_true(one[second * nv + v] - one[best * nv + v] < info.mean_edge_length);
        }
    }
    assert_true(mismatches < (int)nv / 100);
    for (int i = 0; i < 3; i++)
        assert_int_equal(labels[src[i].vertex], i);
    /* unreached vertices: -1; a NaN distance is refused */
    all[3] = INFINITY;
    assert_int_equal(mfmm_voronoi_labels(mesh, all, src, NS, labels, &err), MFMM_OK);
    assert_int_equal(labels[3], -1);
    all[3] = NAN;
    assert_int_equal(mfmm_voronoi_labels(mesh, all, src, NS, labels, &err),
                     MFMM_ERR_BAD_ARGUMENT);
    assert_int_equal(err.index, 3);
    free(all);
    free(one);
    free(labels);
    mfmm_solver_destroy(s);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_coincident_counts),
        cmocka_unit_test(test_fps_equals_full_solves),
        cmocka_unit_test(test_fps_errors),
        cmocka_unit_test(test_voronoi_argmin),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
