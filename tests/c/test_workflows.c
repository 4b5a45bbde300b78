/* Coincident vertices in mfmm_mesh_info and mfmm_weld_map, farthest-point sampling against a
 * loop of full solves, Voronoi labels against the argmin over single-source
 * solves, and isolines against analytic lines and each face's linear
 * interpolant. */
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

static void test_weld_map(void **state)
{
    (void)state;
    /* the square of test_coincident_counts: 4 and 5 repeat 1 and 2 (-0.0
     * as 0.0), 6 repeats 0 */
    double V[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 1, 0, 0, -0.0, 1, 0, 0, 0, 0};
    int32_t map[7], n = -1;
    mfmm_error err;
    assert_int_equal(mfmm_weld_map(V, 7, map, &n, &err), MFMM_OK);
    static const int32_t want[] = {0, 1, 2, 3, 1, 2, 0};
    assert_int_equal(n, 4);
    assert_memory_equal(map, want, sizeof want);
    /* nothing coincides: the numbering is kept */
    assert_int_equal(mfmm_weld_map(V, 4, map, &n, &err), MFMM_OK);
    assert_int_equal(n, 4);
    for (int32_t v = 0; v < 4; v++)
        assert_int_equal(map[v], v);
    assert_int_equal(mfmm_weld_map(V, 0, map, &n, &err), MFMM_OK);
    assert_int_equal(n, 0);
    assert_int_equal(mfmm_weld_map(NULL, 7, map, &n, &err), MFMM_ERR_NULL_POINTER);
    assert_int_equal(mfmm_weld_map(V, -1, map, &n, &err), MFMM_ERR_BAD_COUNT);
    V[3 * 5 + 2] = NAN;
    assert_int_equal(mfmm_weld_map(V, 7, map, &n, &err), MFMM_ERR_NONFINITE_VERTEX);
    assert_int_equal(err.index, 5);
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


/* Checks mfmm_isolines' result on mesh (V, F as given): the lines by
 * value, their points one after another; each point on its face (its
 * coordinates >= 0, one 0, summing to 1, its position their combination of
 * the corners) where the face's linear interpolant is the value (to 1e-12
 * of `scale`); a polyline's first point on its second's face; a loop's last
 * point at the first's position; and per value, one segment in each face
 * whose finite corners straddle it, no other. Returns the lines per value
 * in counts (n_values). */
static void check_isolines(const double *V, const int32_t *F, int32_t nf, const double *field,
                           const double *values, int32_t n_values, double scale,
                           const mfmm_surface_point *pts, int64_t n_pts,
                           const mfmm_isoline *lines, int64_t n_lines, int32_t *counts)
{
    int64_t next = 0;
    for (int32_t j = 0; j < n_values; j++)
        counts[j] = 0;
    for (int64_t l = 0; l < n_lines; l++) {
        const mfmm_isoline *L = lines + l;
        assert_int_equal(L->start, next);
        assert_true(L->n_points >= 2);
        assert_true(L->value >= 0 && L->value < n_values);
        assert_true(l == 0 || lines[l - 1].value <= L->value);
        assert_true(L->closed == 0 || L->closed == 1);
        next += L->n_points;
        counts[L->value]++;
        double c = values[L->value];
        const mfmm_surface_point *P = pts + L->start;
        assert_int_equal(P[0].face, P[1].face);
        if (L->closed)
            assert_memory_equal(P[0].xyz, P[L->n_points - 1].xyz, sizeof P[0].xyz);
        for (int64_t i = 0; i < L->n_points; i++) {
            int32_t f = P[i].face;
            assert_true(f >= 0 && f < nf);
            const double *b = P[i].bary;
            assert_true(b[0] >= 0.0 && b[1] >= 0.0 && b[2] >= 0.0);
            assert_true(b[0] == 0.0 || b[1] == 0.0 || b[2] == 0.0);
            tm_assert_close(b[0] + b[1] + b[2], 1.0, 1e-12);
            double val = 0.0, x[3] = {0.0, 0.0, 0.0};
            for (int k = 0; k < 3; k++) {
                int32_t v = F[3 * f + k];
                val += b[k] * field[v];
                for (int d = 0; d < 3; d++)
                    x[d] += b[k] * V[3 * v + d];
            }
            tm_assert_close(val, c, 1e-12 * scale);
            for (int d = 0; d < 3; d++)
                tm_assert_close(x[d], P[i].xyz[d], 1e-12);
        }
    }
    assert_int_equal(next, n_pts);
    /* the crossed faces, value by value */
    for (int32_t j = 0; j < n_values; j++) {
        int32_t *mine = calloc((size_t)nf, sizeof *mine);
        assert_non_null(mine);
        for (int64_t l = 0; l < n_lines; l++)
            if (lines[l].value == j)
                for (int64_t i = 1; i < lines[l].n_points; i++)
                    mine[pts[lines[l].start + i].face]++;
        for (int32_t f = 0; f < nf; f++) {
            int finite = 1, above = 0;
            for (int k = 0; k < 3; k++) {
                double x = field[F[3 * f + k]];
                finite &= isfinite(x) != 0;
                above += x >= values[j];
            }
            assert_int_equal(mine[f], finite && above > 0 && above < 3);
        }
        free(mine);
    }
}

static void test_isolines_of_a_linear_field_on_a_grid(void **state)
{
    (void)state;
    /* f = 8 x + 4 y on the unit square: i + j / 2 at vertex (i, j) / 8;
     * the levels 2.3, 5.25, 9.7 meet no vertex, 3 and 6.5 meet some, -1
     * and 13 none of the square */
    mfmm_gen_mesh g = mfmm_gen_grid(8);
    mfmm_mesh *mesh = tm_make(&g);
    double *f = malloc((size_t)g.nv * sizeof *f);
    assert_non_null(f);
    for (int32_t v = 0; v < g.nv; v++)
        f[v] = 8.0 * g.V[3 * v] + 4.0 * g.V[3 * v + 1];
    enum { NVAL = 7 };
    const double values[NVAL] = {5.25, 2.3, 13.0, 9.7, 3.0, -1.0, 6.5};
    mfmm_surface_point *pts = NULL;
    mfmm_isoline *lines = NULL;
    int64_t n_pts = -1, n_lines = -1;
    mfmm_error err;
    assert_int_equal(mfmm_isolines(mesh, f, values, NVAL, &pts, &n_pts, &lines, &n_lines, &err),
                     MFMM_OK);
    int32_t counts[NVAL];
    check_isolines(g.V, g.F, g.nf, f, values, NVAL, 12.0, pts, n_pts, lines, n_lines, counts);
    for (int64_t l = 0; l < n_lines; l++) {
        double c = values[lines[l].value];
        const mfmm_surface_point *P = pts + lines[l].start;
        int64_t n = lines[l].n_points;
        /* on the line 8 x + 4 y = c, in the plane */
        for (int64_t i = 0; i < n; i++) {
            tm_assert_close(8.0 * P[i].xyz[0] + 4.0 * P[i].xyz[1], c, 1e-12);
            assert_true(P[i].xyz[2] == 0.0);
        }
        if (c == 3.0 || c == 6.5)
            continue; /* through vertices: pieces between them */
        /* one open polyline across the square, boundary to boundary,
         * monotone along the line */
        assert_int_equal(lines[l].closed, 0);
        for (int e = 0; e < 2; e++) {
            const double *x = P[e ? n - 1 : 0].xyz;
            assert_true(x[0] == 0.0 || x[0] == 1.0 || x[1] == 0.0 || x[1] == 1.0);
        }
        double dir = P[n - 1].xyz[0] - P[0].xyz[0];
        for (int64_t i = 1; i < n; i++)
            assert_true((P[i].xyz[0] - P[i - 1].xyz[0]) * dir >= 0.0);
    }
    assert_int_equal(counts[0], 1);
    assert_int_equal(counts[1], 1);
    assert_int_equal(counts[2], 0);
    assert_int_equal(counts[3], 1);
    assert_true(counts[4] >= 1);
    assert_int_equal(counts[5], 0);
    assert_true(counts[6] >= 1);
    mfmm_free(pts);
    mfmm_free(lines);
    mfmm_mesh_destroy(mesh);
    free(f);
    mfmm_gen_free(&g);
}

static void test_isolines_loops_ends_and_errors(void **state)
{
    (void)state;
    /* f = |p - (.5, .5)|^2: a level of radius .3 is one loop */
    mfmm_gen_mesh g = mfmm_gen_grid(16);
    mfmm_mesh *mesh = tm_make(&g);
    double *f = malloc((size_t)g.nv * sizeof *f);
    assert_non_null(f);
    for (int32_t v = 0; v < g.nv; v++) {
        double x = g.V[3 * v] - 0.5, y = g.V[3 * v + 1] - 0.5;
        f[v] = x * x + y * y;
    }
    double c = 0.09;
    mfmm_surface_point *pts = NULL;
    mfmm_isoline *lines = NULL;
    int64_t n_pts = 0, n_lines = 0;
    int32_t count;
    mfmm_error err;
    assert_int_equal(mfmm_isolines(mesh, f, &c, 1, &pts, &n_pts, &lines, &n_lines, &err),
                     MFMM_OK);
    check_isolines(g.V, g.F, g.nf, f, &c, 1, 1.0, pts, n_pts, lines, n_lines, &count);
    assert_int_equal(n_lines, 1);
    assert_int_equal(lines[0].closed, 1);
    assert_int_equal(n_pts, lines[0].n_points);
    mfmm_free(pts);
    mfmm_free(lines);
    /* an unreached vertex on the loop's way: its faces hold none, the loop
     * opens there */
    int32_t v = 17 * 8 + 3; /* (3, 8) / 16: f = .0977 */
    f[v] = INFINITY;
    assert_int_equal(mfmm_isolines(mesh, f, &c, 1, &pts, &n_pts, &lines, &n_lines, &err),
                     MFMM_OK);
    check_isolines(g.V, g.F, g.nf, f, &c, 1, 1.0, pts, n_pts, lines, n_lines, &count);
    assert_int_equal(n_lines, 1);
    assert_int_equal(lines[0].closed, 0);
    for (int64_t i = 0; i < n_pts; i++)
        for (int k = 0; k < 3; k++)
            assert_true(g.F[3 * pts[i].face + k] != v);
    mfmm_free(pts);
    mfmm_free(lines);
    /* no value, or none crossed: nothing, and no arrays */
    double far = 5.0;
    assert_int_equal(mfmm_isolines(mesh, f, NULL, 0, &pts, &n_pts, &lines, &n_lines, &err),
                     MFMM_OK);
    assert_true(pts == NULL && lines == NULL && n_pts == 0 && n_lines == 0);
    assert_int_equal(mfmm_isolines(mesh, f, &far, 1, &pts, &n_pts, &lines, &n_lines, &err),
                     MFMM_OK);
    assert_true(pts == NULL && lines == NULL && n_pts == 0 && n_lines == 0);
    /* refusals: NULL, a negative count, a level not finite, a NaN */
    assert_int_equal(mfmm_isolines(NULL, f, &c, 1, &pts, &n_pts, &lines, &n_lines, &err),
                     MFMM_ERR_NULL_POINTER);
    assert_int_equal(mfmm_isolines(mesh, NULL, &c, 1, &pts, &n_pts, &lines, &n_lines, &err),
                     MFMM_ERR_NULL_POINTER);
    assert_int_equal(mfmm_isolines(mesh, f, NULL, 1, &pts, &n_pts, &lines, &n_lines, &err),
                     MFMM_ERR_NULL_POINTER);
    assert_int_equal(mfmm_isolines(mesh, f, &c, 1, NULL, &n_pts, &lines, &n_lines, &err),
                     MFMM_ERR_NULL_POINTER);
    assert_int_equal(mfmm_isolines(mesh, f, &c, 1, &pts, &n_pts, &lines, NULL, &err),
                     MFMM_ERR_NULL_POINTER);
    assert_int_equal(mfmm_isolines(mesh, f, &c, -1, &pts, &n_pts, &lines, &n_lines, &err),
                     MFMM_ERR_BAD_COUNT);
    double bad[2] = {0.1, NAN};
    assert_int_equal(mfmm_isolines(mesh, f, bad, 2, &pts, &n_pts, &lines, &n_lines, &err),
                     MFMM_ERR_BAD_ARGUMENT);
    assert_int_equal(err.index, 1);
    bad[1] = -INFINITY;
    assert_int_equal(mfmm_isolines(mesh, f, bad, 2, &pts, &n_pts, &lines, &n_lines, &err),
                     MFMM_ERR_BAD_ARGUMENT);
    assert_int_equal(err.index, 1);
    f[40] = NAN;
    assert_int_equal(mfmm_isolines(mesh, f, &c, 1, &pts, &n_pts, &lines, &n_lines, &err),
                     MFMM_ERR_BAD_ARGUMENT);
    assert_int_equal(err.index, 40);
    assert_true(pts == NULL && lines == NULL && n_pts == 0 && n_lines == 0);
    mfmm_mesh_destroy(mesh);
    free(f);
    mfmm_gen_free(&g);
}

static void test_isolines_across_a_t_junction(void **state)
{
    (void)state;
    /* tests/c/test_tjunction.c's square: M = 5 on edge 0-4 of face 0,
     * closed by the needle 5 (0, 4, 5), which the mesh drops after
     * splitting face 0 at M. A linear field's levels: one polyline each, on
     * the line, every point's face and coordinates those of the faces as
     * given (not the needle), through face 0's pieces */
    static const double V[7 * 3] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, 0,
                                    0.25, 0.25, 0, 0, 0, 0};
    static const int32_t F[6 * 3] = {0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 5, 3, 5, 4, 0, 4, 5};
    mfmm_mesh *mesh = NULL;
    assert_int_equal(mfmm_mesh_create(V, 7, F, 6, NULL, &mesh, NULL), MFMM_OK);
    double f[7];
    for (int v = 0; v < 7; v++)
        f[v] = V[3 * v] - 0.5 * V[3 * v + 1];
    const double values[2] = {0.2, -0.2};
    mfmm_surface_point *pts = NULL;
    mfmm_isoline *lines = NULL;
    int64_t n_pts = 0, n_lines = 0;
    mfmm_error err;
    assert_int_equal(mfmm_isolines(mesh, f, values, 2, &pts, &n_pts, &lines, &n_lines, &err),
                     MFMM_OK);
    assert_int_equal(n_lines, 2);
    for (int64_t l = 0; l < n_lines; l++) {
        assert_int_equal(lines[l].value, l);
        assert_int_equal(lines[l].closed, 0);
        const mfmm_surface_point *P = pts + lines[l].start;
        for (int64_t i = 0; i < lines[l].n_points; i++) {
            assert_true(P[i].face != 5);
            tm_assert_close(P[i].xyz[0] - 0.5 * P[i].xyz[1], values[l], 1e-12);
            double val = 0.0, x[3] = {0.0, 0.0, 0.0};
            for (int k = 0; k < 3; k++) {
                int32_t v = F[3 * P[i].face + k];
                assert_true(P[i].bary[k] >= -1e-15);
                val += P[i].bary[k] * f[v];
                for (int d = 0; d < 3; d++)
                    x[d] += P[i].bary[k] * V[3 * v + d];
            }
            tm_assert_close(val, values[l], 1e-12);
            for (int d = 0; d < 3; d++)
                tm_assert_close(x[d], P[i].xyz[d], 1e-12);
        }
    }
    /* level .2 crosses face 0 (0, 1, 4) in both pieces: a point inside it,
     * on M's edge 1-5 */
    int inside = 0;
    for (int64_t i = lines[0].start; i < lines[0].start + lines[0].n_points; i++)
        inside += pts[i].face == 0 && pts[i].bary[0] > 0 && pts[i].bary[1] > 0 &&
                  pts[i].bary[2] > 0;
    assert_int_equal(inside, 1);
    mfmm_free(pts);
    mfmm_free(lines);
    mfmm_mesh_destroy(mesh);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_coincident_counts),
        cmocka_unit_test(test_weld_map),
        cmocka_unit_test(test_fps_equals_full_solves),
        cmocka_unit_test(test_fps_errors),
        cmocka_unit_test(test_voronoi_argmin),
        cmocka_unit_test(test_isolines_of_a_linear_field_on_a_grid),
        cmocka_unit_test(test_isolines_loops_ends_and_errors),
        cmocka_unit_test(test_isolines_across_a_t_junction),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
