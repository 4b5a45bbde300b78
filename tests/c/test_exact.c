/* mfmm_solve_exact and mfmm_exact_patch: exact polyhedral distances on
 * surfaces whose distances are known in closed form (planes with needle and
 * obtuse triangles, a cube, a prism, a saddle cone, an L-shaped domain),
 * face, edge and corner sources, several sources with values, max_distance,
 * walls at non-manifold edges and other components, the memory limit, the
 * patch API, and every bad input. */
#include <math.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "testutil.h"
#include "exact/exact.h"
#include "exact/nonmanifold.h"
#include "start/patch.h"
#include "mesh/mesh.h"

/* ---------------------------------------------------------------- helpers */

typedef struct ex_fx {
    mfmm_gen_mesh g;
    mfmm_mesh *mesh;
    mfmm_exact_solver *solver;
    double *d;
} ex_fx;

static ex_fx ex_make(mfmm_gen_mesh g)
{
    ex_fx fx;
    fx.g = g;
    fx.mesh = tm_make(&g);
    assert_int_equal(mfmm_exact_solver_create(fx.mesh, &fx.solver), MFMM_OK);
    fx.d = malloc((size_t)g.nv * sizeof *fx.d);
    assert_non_null(fx.d);
    return fx;
}

static void ex_free(ex_fx *fx)
{
    free(fx->d);
    mfmm_exact_solver_destroy(fx->solver);
    mfmm_mesh_destroy(fx->mesh);
    mfmm_gen_free(&fx->g);
}

static void ex_solve(ex_fx *fx, const mfmm_source *s, int32_t n, const mfmm_exact_options *o)
{
    mfmm_error err;
    mfmm_status st = mfmm_solve_exact(fx->solver, s, n, o, fx->d, NULL, &err);
    if (st != MFMM_OK)
        fail_msg("mfmm_solve_exact: %s", err.message);
}

static mfmm_gen_mesh ex_alloc(int32_t nv, int32_t nf)
{
    mfmm_gen_mesh m = {nv, nf, malloc((size_t)nv * 3 * sizeof(double)),
                       malloc((size_t)nf * 3 * sizeof(int32_t))};
    assert_true(m.V && m.F);
    return m;
}

static double dist3(const double *p, const double *q)
{
    return sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                (p[2] - q[2]) * (p[2] - q[2]));
}

/* A rectangle [0, X] x [0, Y] cut by the columns xs[0..nx] and rows
 * ys[0..ny], each cell split along a diagonal chosen by `pattern`; the
 * inner vertices of odd rows moved right by `shift` of their cell. Thin
 * columns make needles; short rows with shifted vertices obtuse corners. */
static mfmm_gen_mesh ex_plane(const double *xs, int nx, const double *ys, int ny, int pattern,
                              double shift)
{
    mfmm_gen_mesh m = ex_alloc((nx + 1) * (ny + 1), 2 * nx * ny);
    for (int j = 0; j <= ny; j++)
        for (int i = 0; i <= nx; i++) {
            double *p = m.V + 3 * (j * (nx + 1) + i);
            p[0] = xs[i] + (i > 0 && i < nx && j % 2 ? shift * (xs[i + 1] - xs[i]) : 0.0);
            p[1] = ys[j];
            p[2] = 0.0;
        }
    int32_t *f = m.F;
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            int32_t a = j * (nx + 1) + i, b = a + 1, c = a + nx + 1, d = c + 1;
            int diag = pattern == 0 ? 0 : pattern == 1 ? (i + j) % 2 : (i * 7 + j * 3) % 5 < 2;
            if (diag) {
                int32_t t[6] = {a, b, d, a, d, c};
                memcpy(f, t, sizeof t);
            } else {
                int32_t t[6] = {a, b, c, b, d, c};
                memcpy(f, t, sizeof t);
            }
            f += 6;
        }
    return m;
}

/* ------------------------------------------------------------------ plane */

/* Every planar triangulation of a convex domain: distances are Euclidean,
 * to 1e-12, from a vertex and from points in a face, on an edge and at a
 * corner, with needles (columns 1e-6 wide) and obtuse corners (up to
 * about 179 degrees). */
static void test_plane_exact(void **state)
{
    (void)state;
    double xs[32], ys[32];
    for (int layout = 0; layout < 3; layout++) {
        int nx = 24, ny = layout == 2 ? 6 : 20;
        double x = 0.0;
        for (int i = 0; i <= nx; i++) {
            xs[i] = x;
            /* layout 1: needle columns; layout 2: wide cells, short rows */
            double w = layout == 1 && i % 5 == 2 ? 1e-6 : 1.0 / nx * (1.0 + 0.3 * sin(3.0 * i));
            x += w;
        }
        for (int j = 0; j <= ny; j++)
            ys[j] = layout == 2 ? 0.01 * j + 0.002 * (j % 2) : (double)j / ny;
        ex_fx fx = ex_make(ex_plane(xs, nx, ys, ny, layout, layout == 2 ? 0.45 : 0.0));
        mfmm_mesh_info mi = {.struct_size = sizeof mi};
        mfmm_mesh_get_info(fx.mesh, &mi);
        if (layout == 2 && mi.n_obtuse_corners < nx * ny)
            fail_msg("%d obtuse corners", (int)mi.n_obtuse_corners);
        int32_t src_v = (ny / 2) * (nx + 1) + nx / 3;
        mfmm_source s = tm_vertex_source(src_v);
        ex_solve(&fx, &s, 1, NULL);
        for (int32_t v = 0; v < fx.g.nv; v++)
            tm_assert_close(fx.d[v], dist3(fx.g.V + 3 * v, fx.g.V + 3 * src_v), 1e-12);
        /* points in a face, on an edge, at a corner */
        const double bary[4][3] = {{0.2, 0.3, 0.5}, {0.0, 0.25, 0.75}, {0.6, 0.0, 0.4}, {1.0, 0.0, 0.0}};
        for (int b = 0; b < 4; b++) {
            int32_t f = fx.g.nf / 2 + 3 * b + 1;
            mfmm_source fs = {0, f, {bary[b][0], bary[b][1], bary[b][2]}, 0.0};
            double p[3] = {0.0, 0.0, 0.0};
            for (int k = 0; k < 3; k++)
                for (int e = 0; e < 3; e++)
                    p[e] += bary[b][k] * fx.g.V[3 * fx.g.F[3 * f + k] + e];
            ex_solve(&fx, &fs, 1, NULL);
            for (int32_t v = 0; v < fx.g.nv; v++)
                tm_assert_close(fx.d[v], dist3(fx.g.V + 3 * v, p), 1e-12);
        }
        ex_free(&fx);
    }
}

/* Faces of mixed orientation (a third of a grid's faces reversed) change
 * nothing: edges are matched by their vertices, not their direction. */
static void test_mixed_orientation(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_grid(12);
    for (int32_t f = 0; f < g.nf; f += 3) {
        int32_t t = g.F[3 * f + 1];
        g.F[3 * f + 1] = g.F[3 * f + 2];
        g.F[3 * f + 2] = t;
    }
    ex_fx fx = ex_make(g);
    for (int32_t src = 0; src < fx.g.nv; src += 37) {
        mfmm_source s = tm_vertex_source(src);
        ex_solve(&fx, &s, 1, NULL);
        for (int32_t v = 0; v < fx.g.nv; v++)
            tm_assert_close(fx.d[v], dist3(fx.g.V + 3 * v, fx.g.V + 3 * src), 1e-12);
    }
    ex_free(&fx);
}

/* Several sources with initial values: T = min_i (value_i + |x - s_i|). */
static void test_several_sources(void **state)
{
    (void)state;
    ex_fx fx = ex_make(mfmm_gen_grid(16));
    mfmm_source s[3] = {tm_vertex_source(0), tm_vertex_source(17 * 17 - 1),
                        {0, 100, {0.5, 0.25, 0.25}, 0.3}};
    s[1].value = 0.5;
    double p[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < 3; k++)
        for (int e = 0; e < 3; e++)
            p[e] += s[2].bary[k] * fx.g.V[3 * fx.g.F[300 + k] + e];
    ex_solve(&fx, s, 3, NULL);
    for (int32_t v = 0; v < fx.g.nv; v++) {
        double want = fmin(dist3(fx.g.V + 3 * v, fx.g.V), 0.5 + dist3(fx.g.V + 3 * v, fx.g.V + 3 * (17 * 17 - 1)));
        want = fmin(want, 0.3 + dist3(fx.g.V + 3 * v, p));
        tm_assert_close(fx.d[v], want, 1e-12);
    }
    ex_free(&fx);
}

/* Values far apart (negative, huge) and meshes scaled by 1e-30 and 1e+30:
 * the same distances, scaled. */
static void test_values_and_scale(void **state)
{
    (void)state;
    const double scales[3] = {1.0, 1e-30, 1e30};
    for (int k = 0; k < 3; k++) {
        mfmm_gen_mesh g = mfmm_gen_sine(12);
        for (int32_t i = 0; i < 3 * g.nv; i++)
            g.V[i] *= scales[k];
        ex_fx fx = ex_make(g);
        double *ref = malloc((size_t)fx.g.nv * sizeof *ref);
        assert_non_null(ref);
        mfmm_source s = tm_vertex_source(40);
        ex_solve(&fx, &s, 1, NULL);
        memcpy(ref, fx.d, (size_t)fx.g.nv * sizeof *ref);
        if (k == 0) {
            /* a negative value, and a second source too far behind to matter */
            mfmm_source two[2] = {tm_vertex_source(40), tm_vertex_source(100)};
            two[0].value = -2.0;
            two[1].value = 1e12;
            ex_solve(&fx, two, 2, NULL);
            for (int32_t v = 0; v < fx.g.nv; v++)
                tm_assert_close(fx.d[v], ref[v] - 2.0, 1e-12);
        } else {
            mfmm_gen_mesh g1 = mfmm_gen_sine(12);
            ex_fx one = ex_make(g1);
            ex_solve(&one, &s, 1, NULL);
            for (int32_t v = 0; v < fx.g.nv; v++)
                tm_assert_close(ref[v] / scales[k], one.d[v], 1e-12 * (1.0 + one.d[v]));
            ex_free(&one);
        }
        free(ref);
        ex_free(&fx);
    }
}

/* ------------------------------------------------------------ cube, prism */

/* The surface of [0,1]^3, n x n squares a side. */
static mfmm_gen_mesh ex_cube(int n)
{
    int w = n + 1;
    int32_t *id = malloc((size_t)w * w * w * sizeof *id);
    assert_non_null(id);
    int32_t nv = 0;
    for (int i = 0; i < w * w * w; i++) {
        int x = i % w, y = (i / w) % w, z = i / (w * w);
        id[i] = (x == 0 || x == n || y == 0 || y == n || z == 0 || z == n) ? nv++ : -1;
    }
    mfmm_gen_mesh m = ex_alloc(nv, 12 * n * n);
    for (int i = 0; i < w * w * w; i++)
        if (id[i] >= 0) {
            m.V[3 * id[i]] = (double)(i % w) / n;
            m.V[3 * id[i] + 1] = (double)((i / w) % w) / n;
            m.V[3 * id[i] + 2] = (double)(i / (w * w)) / n;
        }
    int32_t *f = m.F;
    for (int axis = 0; axis < 3; axis++)
        for (int side = 0; side <= n; side += n)
            for (int a = 0; a < n; a++)
                for (int b = 0; b < n; b++) {
                    int32_t q[4];
                    for (int c = 0; c < 4; c++) {
                        int u = a + (c == 1 || c == 2), v = b + (c >= 2);
                        int xyz[3];
                        xyz[axis] = side;
                        xyz[(axis + 1) % 3] = u;
                        xyz[(axis + 2) % 3] = v;
                        q[c] = id[xyz[0] + w * (xyz[1] + w * xyz[2])];
                    }
                    int32_t t[6] = {q[0], q[1], q[2], q[0], q[2], q[3]};
                    memcpy(f, t, sizeof t);
                    f += 6;
                }
    free(id);
    return m;
}

/* From the centre of the top face: Euclidean on the top, unfolded across
 * the edge on the sides, 2 at the centre of the bottom. */
static void test_cube(void **state)
{
    (void)state;
    int n = 6;
    ex_fx fx = ex_make(ex_cube(n));
    int32_t src = -1, bottom = -1;
    for (int32_t v = 0; v < fx.g.nv; v++) {
        const double *p = fx.g.V + 3 * v;
        if (fabs(p[0] - 0.5) < 1e-12 && fabs(p[1] - 0.5) < 1e-12)
            *(p[2] > 0.5 ? &src : &bottom) = v;
    }
    assert_true(src >= 0 && bottom >= 0);
    mfmm_source s = tm_vertex_source(src);
    ex_solve(&fx, &s, 1, NULL);
    int checked = 0;
    for (int32_t v = 0; v < fx.g.nv; v++) {
        const double *p = fx.g.V + 3 * v;
        double want = NAN;
        if (p[2] == 1.0)
            want = hypot(p[0] - 0.5, p[1] - 0.5);
        else if (p[1] == 0.0 && p[0] > 0.0 && p[0] < 1.0)
            want = hypot(p[0] - 0.5, 1.5 - p[2]);
        else if (p[0] == 1.0 && p[1] > 0.0 && p[1] < 1.0)
            want = hypot(p[1] - 0.5, 1.5 - p[2]);
        if (want == want) {
            tm_assert_close(fx.d[v], want, 1e-12);
            checked++;
        }
    }
    assert_true(checked > 60);
    tm_assert_close(fx.d[bottom], 2.0, 1e-12);
    ex_free(&fx);
}

/* An open prism over a regular m-gon (a polyhedral cylinder), rows of
 * height 1/rows: it unrolls into a flat strip, so the distance is
 * Euclidean in the strip, going around the shorter way. */
static void test_cylinder(void **state)
{
    (void)state;
    int m = 16, rows = 7;
    double r = 0.4, chord = 2.0 * r * sin(TM_PI / m);
    mfmm_gen_mesh g = ex_alloc(m * (rows + 1), 2 * m * rows);
    for (int j = 0; j <= rows; j++)
        for (int i = 0; i < m; i++) {
            double *p = g.V + 3 * (j * m + i);
            p[0] = r * cos(2.0 * TM_PI * i / m);
            p[1] = r * sin(2.0 * TM_PI * i / m);
            p[2] = (double)j / rows;
        }
    int32_t *f = g.F;
    for (int j = 0; j < rows; j++)
        for (int i = 0; i < m; i++) {
            int32_t a = j * m + i, b = j * m + (i + 1) % m, c = a + m, d = b + m;
            int32_t t[6] = {a, b, d, a, d, c};
            if ((i + j) % 2) {
                int32_t u[6] = {a, b, c, b, d, c};
                memcpy(t, u, sizeof t);
            }
            memcpy(f, t, sizeof t);
            f += 6;
        }
    ex_fx fx = ex_make(g);
    int32_t src = 2 * m + 3;
    mfmm_source s = tm_vertex_source(src);
    ex_solve(&fx, &s, 1, NULL);
    for (int32_t v = 0; v < fx.g.nv; v++) {
        int di = abs(v % m - src % m);
        if (m - di < di)
            di = m - di;
        double dz = fx.g.V[3 * v + 2] - fx.g.V[3 * src + 2];
        tm_assert_close(fx.d[v], hypot(di * chord, dz), 1e-12);
    }
    ex_free(&fx);
}

/* ------------------------------------------------------------------ saddle */

/* A cone of total angle 6 x 70 = 420 degrees (a saddle: the six faces at
 * the apex alternate up and down), two rings, each outer triangle in the
 * plane of its apex triangle. Unrolled, a vertex is at polar (rho, phi); two
 * points apart by less than 180 degrees (the shorter way round) see each
 * other, others are joined through the apex: rho1 + rho2. */
static void test_saddle(void **state)
{
    (void)state;
    double c70 = cos(70.0 * TM_PI / 180.0), h = sqrt((0.5 - c70) / (1.0 + c70));
    mfmm_gen_mesh g = ex_alloc(13, 18);
    g.V[0] = g.V[1] = g.V[2] = 0.0;
    for (int ring = 1; ring <= 2; ring++)
        for (int i = 0; i < 6; i++) {
            double *p = g.V + 3 * (1 + (ring - 1) * 6 + i);
            p[0] = ring * cos(TM_PI / 3.0 * i);
            p[1] = ring * sin(TM_PI / 3.0 * i);
            p[2] = ring * (i % 2 ? -h : h);
        }
    int32_t *f = g.F;
    for (int i = 0; i < 6; i++) {
        int32_t a = 1 + i, b = 1 + (i + 1) % 6, c = 7 + i, d = 7 + (i + 1) % 6;
        int32_t t[9] = {0, a, b, a, c, d, a, d, b};
        memcpy(f, t, sizeof t);
        f += 9;
    }
    for (int variant = 0; variant < 2; variant++) {
        /* variant 1: every other face reversed (the fans are walked by vertex) */
        mfmm_gen_mesh gv = ex_alloc(13, 18);
        memcpy(gv.V, g.V, 13 * 3 * sizeof(double));
        memcpy(gv.F, g.F, 18 * 3 * sizeof(int32_t));
        for (int32_t k = 0; variant && k < 18; k += 2) {
            int32_t t = gv.F[3 * k];
            gv.F[3 * k] = gv.F[3 * k + 1];
            gv.F[3 * k + 1] = t;
        }
        ex_fx fx = ex_make(gv);
        double rho[13], phi[13];
        rho[0] = phi[0] = 0.0;
        for (int v = 1; v < 13; v++) {
            rho[v] = dist3(fx.g.V, fx.g.V + 3 * v);
            phi[v] = 70.0 * ((v - 1) % 6);
        }
        int sources[3] = {1, 8, 10};
        for (int k = 0; k < 3; k++) {
            int s = sources[k];
            mfmm_source src = tm_vertex_source(s);
            ex_solve(&fx, &src, 1, NULL);
            for (int v = 0; v < 13; v++) {
                double a = fabs(phi[v] - phi[s]);
                if (420.0 - a < a)
                    a = 420.0 - a;
                double want = a < 180.0 ? sqrt(rho[s] * rho[s] + rho[v] * rho[v] -
                                               2.0 * rho[s] * rho[v] * cos(a * TM_PI / 180.0))
                                        : rho[s] + rho[v];
                tm_assert_close(fx.d[v], want, 1e-12);
            }
        }
        ex_free(&fx);
    }
    mfmm_gen_free(&g);
}

/* An L-shaped plane: around the reflex corner (a boundary vertex of angle
 * 270 degrees) the geodesic bends at the corner. */
static void test_reflex_corner(void **state)
{
    (void)state;
    int n = 8; /* [0,2]^2 minus (1,2]^2, cells of 1/4 */
    double xs[9], ys[9];
    for (int i = 0; i <= n; i++)
        xs[i] = ys[i] = 2.0 * i / n;
    mfmm_gen_mesh full = ex_plane(xs, n, ys, n, 1, 0.0);
    /* keep the faces whose centroid is outside (1,2]^2 */
    int32_t nf = 0;
    for (int32_t f = 0; f < full.nf; f++) {
        double cx = 0.0, cy = 0.0;
        for (int k = 0; k < 3; k++) {
            cx += full.V[3 * full.F[3 * f + k]] / 3.0;
            cy += full.V[3 * full.F[3 * f + k] + 1] / 3.0;
        }
        if (!(cx > 1.0 && cy > 1.0)) {
            memmove(full.F + 3 * nf, full.F + 3 * f, 3 * sizeof(int32_t));
            nf++;
        }
    }
    full.nf = nf;
    ex_fx fx = ex_make(full); /* the unreferenced vertices of (1,2]^2 stay +inf */
    int32_t src = 1 * (n + 1) + 7; /* (1.75, 0.25) */
    const double corner[2] = {1.0, 1.0};
    const double *s = fx.g.V + 3 * src;
    mfmm_source so = tm_vertex_source(src);
    ex_solve(&fx, &so, 1, NULL);
    for (int32_t v = 0; v < fx.g.nv; v++) {
        const double *p = fx.g.V + 3 * v;
        if (p[0] > 1.0 && p[1] > 1.0) {
            assert_true(isinf(fx.d[v]));
            continue;
        }
        /* visible when the segment stays out of (1,2]^2: it does unless it
         * crosses the line y = 1 at x > 1 going up into x < 1 ... i.e. the
         * corner is to the left of s -> p */
        double cr = (p[0] - s[0]) * (corner[1] - s[1]) - (p[1] - s[1]) * (corner[0] - s[0]);
        int hidden = p[1] > 1.0 && cr > 0.0;
        double want = hidden ? hypot(s[0] - 1.0, s[1] - 1.0) + hypot(p[0] - 1.0, p[1] - 1.0)
                             : hypot(p[0] - s[0], p[1] - s[1]);
        tm_assert_close(fx.d[v], want, 1e-12);
    }
    ex_free(&fx);
}

/* ------------------------------------------------- limits and components */

static void test_max_distance(void **state)
{
    (void)state;
    ex_fx fx = ex_make(mfmm_gen_grid(20));
    mfmm_exact_options o;
    mfmm_exact_options_init(&o);
    o.max_distance = 0.3;
    int32_t c = 10 * 21 + 10;
    mfmm_source s = tm_vertex_source(c);
    mfmm_exact_info full = {.struct_size = sizeof full}, part = {.struct_size = sizeof part};
    mfmm_error err;
    assert_int_equal(mfmm_solve_exact(fx.solver, &s, 1, NULL, fx.d, &full, &err), MFMM_OK);
    assert_int_equal(mfmm_solve_exact(fx.solver, &s, 1, &o, fx.d, &part, &err), MFMM_OK);
    for (int32_t v = 0; v < fx.g.nv; v++) {
        double e = dist3(fx.g.V + 3 * v, fx.g.V + 3 * c);
        if (e <= 0.3 - 1e-12)
            tm_assert_close(fx.d[v], e, 1e-12);
        else if (e > 0.3 + 1e-12)
            assert_true(isinf(fx.d[v]) && fx.d[v] > 0);
    }
    assert_true(part.n_windows < full.n_windows / 2);
    assert_true(full.peak_bytes > 0 && full.peak_windows > 0 && full.n_pseudo_sources >= 1);
    ex_free(&fx);
}

static int ex_stop_at(void *user)
{
    int *calls = user;
    return ++*calls >= 2;
}

/* interrupt is called as the propagation goes on, and its non-zero answer
 * stops the solve with MFMM_ERR_CANCELLED; the next solve on the solver
 * gives the full row (the plane's Euclidean distances). */
static void test_interrupt(void **state)
{
    (void)state;
    ex_fx fx = ex_make(mfmm_gen_grid(150));
    mfmm_exact_options o;
    mfmm_exact_options_init(&o);
    assert_null(o.interrupt);
    int calls = 0;
    o.interrupt = ex_stop_at;
    o.user = &calls;
    mfmm_source s = tm_vertex_source(0);
    mfmm_error err;
    assert_int_equal(mfmm_solve_exact(fx.solver, &s, 1, &o, fx.d, NULL, &err),
                     MFMM_ERR_CANCELLED);
    assert_int_equal(calls, 2);
    assert_non_null(strstr(err.message, "interrupted"));
    ex_solve(&fx, &s, 1, NULL);
    for (int32_t v = 0; v < fx.g.nv; v++)
        tm_assert_close(fx.d[v], dist3(fx.g.V + 3 * v, fx.g.V), 1e-12);
    ex_free(&fx);
}

/* A run past its window budget (made tiny here) stops and edge paths finish
 * it: the solve returns, every vertex finite, between the straight line and
 * the shortest path along edges (Dijkstra here, by scanning the faces; the
 * budget is checked every 4096 queue pops, which a 2601-vertex grid passes). */
static void test_stalled_run_ends_within_bounds(void **state)
{
    (void)state;
    ex_fx fx = ex_make(mfmm_gen_grid(50));
    int32_t nv = fx.g.nv, src = 25 * 51 + 3;
    mfmm_exact_ws_set_budget(fx.solver, 0.05);
    mfmm_source s = tm_vertex_source(src);
    mfmm_exact_info info = {.struct_size = sizeof info};
    mfmm_error err;
    assert_int_equal(mfmm_solve_exact(fx.solver, &s, 1, NULL, fx.d, &info, &err), MFMM_OK);
    double *g = malloc((size_t)nv * sizeof *g);
    char *done = calloc((size_t)nv, 1);
    assert_true(g && done);
    for (int32_t v = 0; v < nv; v++)
        g[v] = INFINITY;
    g[src] = 0.0;
    for (;;) {
        int32_t u = -1;
        for (int32_t v = 0; v < nv; v++)
            if (!done[v] && isfinite(g[v]) && (u < 0 || g[v] < g[u]))
                u = v;
        if (u < 0)
            break;
        done[u] = 1;
        for (int32_t f = 0; f < fx.g.nf; f++)
            for (int k = 0; k < 3; k++)
                if (fx.g.F[3 * f + k] == u)
                    for (int j = 1; j < 3; j++) {
                        int32_t w = fx.g.F[3 * f + (k + j) % 3];
                        double l = g[u] + dist3(fx.g.V + 3 * u, fx.g.V + 3 * w);
                        if (l < g[w])
                            g[w] = l;
                    }
    }
    int longer = 0;
    for (int32_t v = 0; v < nv; v++) {
        double e = dist3(fx.g.V + 3 * v, fx.g.V + 3 * src);
        assert_true(isfinite(fx.d[v]));
        assert_true(fx.d[v] >= e * (1.0 - 1e-12));
        assert_true(fx.d[v] <= g[v] * (1.0 + 1e-12) + 1e-15);
        longer += fx.d[v] > e * (1.0 + 1e-12);
    }
    assert_true(longer > 0); /* the run did stop early */
    free(g);
    free(done);
    mfmm_exact_ws_set_budget(fx.solver, 64.0);
    ex_solve(&fx, &s, 1, NULL);
    for (int32_t v = 0; v < nv; v++)
        tm_assert_close(fx.d[v], dist3(fx.g.V + 3 * v, fx.g.V + 3 * src), 1e-12);
    ex_free(&fx);
}

/* A run past its window budget (made tiny here) that crossed non-manifold
 * edges is redone with them as walls, and says so: on a grid with a fin on
 * an edge by the source, every value finite and at least the exact one
 * (paths round the walls, or edge paths where that run stalls too), the
 * fallback no fuzzed mesh reaches once passes through needles on such
 * edges are trimmed like windows into faces. */
static void test_nonmanifold_walls_past_budget(void **state)
{
    (void)state;
    mfmm_gen_mesh grid = mfmm_gen_grid(50);
    int32_t src = 25 * 51 + 3, f0 = 0;
    while (grid.F[3 * f0] != src)
        f0++;
    mfmm_gen_mesh g = ex_alloc(grid.nv + 1, grid.nf + 1);
    memcpy(g.V, grid.V, (size_t)grid.nv * 3 * sizeof(double));
    memcpy(g.F, grid.F, (size_t)grid.nf * 3 * sizeof(int32_t));
    int32_t a = grid.F[3 * f0], b = grid.F[3 * f0 + 1];
    for (int k = 0; k < 3; k++)
        g.V[3 * grid.nv + k] = 0.5 * (g.V[3 * a + k] + g.V[3 * b + k]);
    g.V[3 * grid.nv + 2] += 0.02;
    g.F[3 * grid.nf] = a;
    g.F[3 * grid.nf + 1] = b;
    g.F[3 * grid.nf + 2] = grid.nv;
    mfmm_gen_free(&grid);
    ex_fx fx = ex_make(g);
    int32_t nv = fx.g.nv;
    mfmm_source s = tm_vertex_source(src);
    mfmm_exact_info info = {.struct_size = sizeof info};
    mfmm_error err;
    ex_solve(&fx, &s, 1, NULL);
    double *exact = malloc((size_t)nv * sizeof *exact);
    assert_non_null(exact);
    memcpy(exact, fx.d, (size_t)nv * sizeof *exact);
    mfmm_exact_ws_set_budget(fx.solver, 0.05);
    assert_int_equal(mfmm_solve_exact(fx.solver, &s, 1, NULL, fx.d, &info, &err), MFMM_OK);
    assert_int_equal(info.nonmanifold_walls, 1);
    for (int32_t v = 0; v < nv; v++) {
        assert_true(isfinite(fx.d[v]));
        assert_true(fx.d[v] >= exact[v] * (1.0 - 1e-12));
    }
    free(exact);
    ex_free(&fx);
}

/* Two components and a non-manifold edge: a unit square cut along its
 * diagonal (1,0)-(0,1), and a fin on that diagonal, and a copy of the
 * square far away. The diagonal, shared by three faces, joins each to the
 * other two: from (0,0) the far corner is straight across it (as a wall,
 * it gave 2, round an end), the fin's apex (0.5, 0.5, 1), 1 above
 * the diagonal's middle, is sqrt(1/2) + 1 away (the fin unfolded across
 * it), and from the fin's point (0.5, 0.5, 0.5) both corners off the
 * diagonal are 0.5 + sqrt(1/2) away (analytic). */
static void test_nonmanifold_components(void **state)
{
    (void)state;
    mfmm_gen_mesh g = ex_alloc(9, 5);
    const double V[27] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0.5, 0.5, 1,
                          5, 0, 0, 6, 0, 0, 5, 1, 0, 6, 1, 0};
    const int32_t F[15] = {0, 1, 2, 1, 3, 2, 1, 2, 4, 5, 6, 7, 6, 8, 7};
    memcpy(g.V, V, sizeof V);
    memcpy(g.F, F, sizeof F);
    ex_fx fx = ex_make(g);
    mfmm_source s = tm_vertex_source(0);
    ex_solve(&fx, &s, 1, NULL);
    tm_assert_close(fx.d[0], 0.0, 0.0);
    tm_assert_close(fx.d[1], 1.0, 1e-15);
    tm_assert_close(fx.d[2], 1.0, 1e-15);
    tm_assert_close(fx.d[3], sqrt(2.0), 1e-15);
    tm_assert_close(fx.d[4], 1.0 + sqrt(0.5), 1e-15);
    for (int v = 5; v < 9; v++)
        assert_true(isinf(fx.d[v]) && fx.d[v] > 0);
    /* a source inside the fin */
    mfmm_source fs = {0, 2, {0.25, 0.25, 0.5}, 0.0};
    ex_solve(&fx, &fs, 1, NULL);
    double p[3] = {0.25 + 0.25, 0.25 + 0.25, 0.5};
    tm_assert_close(fx.d[1], dist3(p, V + 3), 1e-15);
    tm_assert_close(fx.d[0], 0.5 + sqrt(0.5), 1e-15);
    tm_assert_close(fx.d[3], 0.5 + sqrt(0.5), 1e-15);
    for (int v = 5; v < 9; v++)
        assert_true(isinf(fx.d[v]));
    ex_free(&fx);
}

/* Two windows of equal sigma on a non-manifold edge (the same source
 * unfolded round both sides of a vertex): where they are equal is the
 * bisector of their pseudo-sources, a double root of ex_dominate's squared
 * equation that rounding made complex about half the time, and the later
 * window was then dropped whole, or kept whole, by the sign at the middle. */
static void test_dominate_equal_sigma(void **state)
{
    (void)state;
    mfmm_exact_ws ws;
    memset(&ws, 0, sizeof ws);
    int32_t head = 0;
    ex_rec kept;
    ws.nm_head = &head;
    ws.rec = &kept;
    uint64_t x = 88172645463325252u;
    int bisected = 0;
    for (int trial = 0; trial < 2000; trial++) {
        double u[5];
        for (int j = 0; j < 5; j++) {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            u[j] = (double)(x >> 11) / 9007199254740992.0;
        }
        double L = 0.5 + 2.0 * u[0], sigma = 3.0 * u[1];
        double pa = L * (2.0 * u[2] - 0.5), qa = -(0.1 + u[3]) * L;
        double pn = L * (2.0 * u[4] - 0.5), qn = -(0.1 + u[0] * u[3]) * L;
        kept = (ex_rec){0.0, L, pa, qa, sigma, 0, -1};
        /* where |X - N| = |X - K| on the edge (y = 0) */
        double xb = (pa * pa + qa * qa - pn * pn - qn * qn) / (2.0 * (pa - pn));
        double s0 = 0.0, s1 = L;
        int left = ex_dominate(&ws, 0, L, &s0, &s1, pn, qn, sigma);
        double eps = 1e-9 * L;
        if (!(xb > eps && xb < L - eps))
            continue;
        bisected++;
        /* the new window is the nearer on its own source's side */
        assert_true(left);
        if (pn < pa) {
            tm_assert_close(s0, 0.0, eps);
            tm_assert_close(s1, xb, eps);
        } else {
            tm_assert_close(s0, xb, eps);
            tm_assert_close(s1, L, eps);
        }
    }
    assert_true(bisected > 500);
}

/* A fuzzed mesh (tests/fuzz/regressions/exact/crash-7db1014c..., reduced
 * to the faces that keep it) of folded fans on non-manifold edges: the
 * distance between every two vertices is the same both ways. From 6 the
 * window round the far side of vertex 7 was dropped at edge 4-5 by the one
 * round the near side (ex_dominate's lost bisector), 2.510413 against
 * 2.509031 from 2; a graph of 200 points an edge, joined straight within
 * each face, gives 2.509055, a real path 2.4e-5 longer. */
static void test_nonmanifold_symmetric(void **state)
{
    (void)state;
    static const double V[39] = {
        4.125, 4, 3.25, 3.875, 4.75, 3.75, 3.25, 4.125, 3.125, 4.625, 4.5, 3.75,
        3.25, 4.25, 3.375, 4.75, 4.625, 3.875, 4.25, 4.125, 3.5, 4, 4.875, 3.875,
        4.5, 4.375, 3.625, 4.125, 5, 4, 3.625, 4.5, 3.5, 4.25, 5.125, 4.125,
        5, 4.875, 4.125};
    static const int32_t F[30] = {0, 1, 2, 1, 3, 0, 4, 5, 0, 5, 1, 4, 6, 7, 4,
                                  7, 5, 6, 8, 9, 10, 11, 12, 3, 0, 5, 1, 4, 7, 5};
    mfmm_gen_mesh g = ex_alloc(13, 10);
    memcpy(g.V, V, sizeof V);
    memcpy(g.F, F, sizeof F);
    ex_fx fx = ex_make(g);
    double D[13][13];
    for (int32_t a = 0; a < 13; a++) {
        mfmm_source s = tm_vertex_source(a);
        ex_solve(&fx, &s, 1, NULL);
        memcpy(D[a], fx.d, sizeof D[a]);
    }
    for (int a = 0; a < 13; a++)
        for (int b = a + 1; b < 13; b++) {
            if (isinf(D[a][b]) || isinf(D[b][a])) {
                assert_true(D[a][b] == D[b][a]);
                continue;
            }
            tm_assert_close(D[a][b], D[b][a], 1e-12 * D[a][b]);
        }
    tm_assert_close(D[6][2], 2.509031428195, 1e-9);
    ex_free(&fx);
}

/* Exact distances between every two vertices of mesh (V, F), both ways:
 * equal to 1e-12 relative, or both +inf. */
static void ex_assert_symmetric(const double *V, int32_t nv, const int32_t *F, int32_t nf,
                                double *D)
{
    mfmm_gen_mesh g = ex_alloc(nv, nf);
    memcpy(g.V, V, (size_t)nv * 3 * sizeof *V);
    memcpy(g.F, F, (size_t)nf * 3 * sizeof *F);
    ex_fx fx = ex_make(g);
    for (int32_t a = 0; a < nv; a++) {
        mfmm_source s = tm_vertex_source(a);
        ex_solve(&fx, &s, 1, NULL);
        memcpy(D + (size_t)a * nv, fx.d, (size_t)nv * sizeof *D);
    }
    for (int32_t a = 0; a < nv; a++)
        for (int32_t b = a + 1; b < nv; b++) {
            double x = D[(size_t)a * nv + b], y = D[(size_t)b * nv + a];
            if (isinf(x) || isinf(y))
                assert_true(x == y);
            else
                tm_assert_close(x, y, 1e-12 * x);
        }
    ex_free(&fx);
}

/* Needles (zero-area faces) on a non-manifold edge reached by a window that
 * is passing through another needle: the straight path from 3 through the
 * T-junction to 5 (on edge 1-2, the middle of needle 2 5 1, and of edge 1-4
 * of face 1 3 4, whose copy 3 4 1 keeps the mesh from splitting it) is
 * sqrt 5 from either end (from 3 it went round through 2, 1 + sqrt 2); and
 * a needle with two coincident corners (0 1 2) that passes a window from
 * face 1 4 2 onto edge 0-2, on which 5 is the middle of needle 5 0 2
 * (sqrt 5 one way, 2.5 the other). Fuzzed meshes, reduced. */
static void test_pass_into_needle_on_nonmanifold_edge(void **state)
{
    (void)state;
    static const double V1[18] = {2, 0, 2, 0, 3, 0, 3, 3, 0, 4, 2, 0, 4, 3, 0, 2, 3, 0};
    static const int32_t F1[15] = {0, 1, 2, 1, 3, 4, 1, 4, 2, 2, 5, 1, 3, 4, 1};
    double D[36];
    ex_assert_symmetric(V1, 6, F1, 5, D);
    tm_assert_close(D[3 * 6 + 5], sqrt(5.0), 1e-15);
    static const double V2[18] = {0, 0, 0, 0, 0, 0, 4.25, 0, 0, 4, 0, 5, 5, 0, 1, 3, 0, 0};
    static const int32_t F2[12] = {0, 1, 2, 0, 2, 3, 1, 4, 2, 5, 0, 2};
    ex_assert_symmetric(V2, 6, F2, 4, D);
    tm_assert_close(D[4 * 6 + 5], sqrt(5.0), 1e-15);
}

/* A strip of needles between two points each split into coincident
 * vertices (4-9 at one, 10-13 at the other), reached from 16 through face
 * 5 15 10 on its non-manifold edge 5-10: a window that came to needle 5 10 9
 * round two others had its pass cut at EX_MAX_PASS, and kept there it
 * dropped the window that came straight, so d(16, 14) was 40.955 for
 * 25.062 the other way (a graph of 128 points an edge, joined straight
 * within each face, gives 25.0626, a real path). A fuzzed mesh, reduced. */
static void test_pass_cut_at_depth_limit(void **state)
{
    (void)state;
    static const double V[57] = {
        0, 0, -1, 5, 0, -1, -1, 5, 0, -1, 0, 1,
        10.875, 10.875, 10.875, 10.875, 10.875, 10.875, 10.875, 10.875, 10.875,
        10.875, 10.875, 10.875, 10.875, 10.875, 10.875, 10.875, 10.875, 10.875,
        -6.25, -6.25, -6.25, -6.25, -6.25, -6.25, -6.25, -6.25, -6.25,
        -6.25, -6.25, -6.25, -6.25, 0.125, 4.375, 0.625, 0.5, 2, 0.25, 2, 2,
        0.875, 2, 3, 0.625, 1.625, 1.5};
    static const int32_t F[45] = {3, 1, 15, 0, 17, 2, 0, 1, 2, 4, 5, 10, 4, 10, 9,
                                  5, 6, 11, 5, 11, 10, 6, 7, 12, 6, 12, 11, 7, 8, 13,
                                  7, 13, 12, 8, 14, 13, 5, 15, 10, 5, 10, 9, 16, 18, 17};
    static double D[19 * 19];
    ex_assert_symmetric(V, 19, F, 15, D);
    tm_assert_close(D[16 * 19 + 14], 25.062132981489, 1e-9);
    assert_true(D[16 * 19 + 14] <= 25.0626);
}

/* Two faces joined only through a strip of 10 needles along the x axis
 * (each one's long edge the next one's short edge, so none closes a
 * T-junction): 0 = (0, 0, 1) above the line, 1 = (0, 1, 0) beside it, the
 * path through the origin 2 long, and 13 = (-0.5, 0, 0), the last needle's
 * middle vertex, at its Euclidean distance sqrt 1.25 from 0. With passes
 * cut at EX_MAX_PASS (8 in a row) d(0, 1) was 2.8284 and d(1, 0) 4.0322,
 * paths through vertices of the strip. */
static void test_pass_through_long_needle_strip(void **state)
{
    (void)state;
    static const double V[42] = {0, 0, 1, 0, 1, 0, -1, 0, 0, 1, 0, 0, -2, 0, 0, 2, 0, 0,
                                 -3, 0, 0, 3, 0, 0, -4, 0, 0, 4, 0, 0, -5, 0, 0, 5, 0, 0,
                                 -6, 0, 0, -0.5, 0, 0};
    static const int32_t F[36] = {2, 3, 0, 2, 3, 4, 4, 3, 5, 4, 5, 6, 6, 5, 7, 6, 7, 8,
                                  8, 7, 9, 8, 9, 10, 10, 9, 11, 10, 11, 12, 12, 11, 13,
                                  13, 11, 1};
    static double D[14 * 14];
    ex_assert_symmetric(V, 14, F, 12, D);
    tm_assert_close(D[1], 2.0, 1e-15);
    tm_assert_close(D[13], sqrt(1.25), 1e-15);
}

/* A zero-area face refuses a source; the rest is exact, and its vertex in
 * the middle of the edge it shares, reached through it (ex_pass), is at its
 * Euclidean distance too (it was +inf, behind a wall). */
static void test_degenerate_face(void **state)
{
    (void)state;
    mfmm_gen_mesh grid = mfmm_gen_grid(6);
    mfmm_gen_mesh g = ex_alloc(grid.nv + 1, grid.nf + 1);
    memcpy(g.V, grid.V, (size_t)grid.nv * 3 * sizeof(double));
    memcpy(g.F, grid.F, (size_t)grid.nf * 3 * sizeof(int32_t));
    /* a sliver on the boundary edge 0-1: its third vertex on the edge */
    g.V[3 * grid.nv] = 0.5 * (g.V[0] + g.V[3]);
    g.V[3 * grid.nv + 1] = 0.0;
    g.V[3 * grid.nv + 2] = 0.0;
    g.F[3 * grid.nf] = 0;
    g.F[3 * grid.nf + 1] = grid.nv;
    g.F[3 * grid.nf + 2] = 1;
    mfmm_gen_free(&grid);
    ex_fx fx = ex_make(g);
    mfmm_source s = tm_vertex_source(20);
    ex_solve(&fx, &s, 1, NULL);
    for (int32_t v = 0; v < fx.g.nv; v++)
        tm_assert_close(fx.d[v], dist3(fx.g.V + 3 * v, fx.g.V + 60), 1e-12);
    mfmm_source bad = {0, fx.g.nf - 1, {0.3, 0.3, 0.4}, 0.0};
    mfmm_error err;
    assert_int_equal(mfmm_solve_exact(fx.solver, &bad, 1, NULL, fx.d, NULL, &err),
                     MFMM_ERR_DEGENERATE_SOURCE);
    assert_int_equal(err.index, 0);
    ex_free(&fx);
}

static void test_memory_limit(void **state)
{
    (void)state;
    ex_fx fx = ex_make(mfmm_gen_grid(30));
    mfmm_source s = tm_vertex_source(15 * 31 + 15);
    mfmm_exact_info info = {.struct_size = sizeof info};
    mfmm_error err;
    assert_int_equal(mfmm_solve_exact(fx.solver, &s, 1, NULL, fx.d, &info, &err), MFMM_OK);
    size_t need = info.peak_bytes;
    mfmm_exact_options o;
    mfmm_exact_options_init(&o);
    o.memory_limit = need / 2;
    /* a fresh solver: the first keeps the buffers it grew */
    mfmm_exact_solver *small = NULL;
    assert_int_equal(mfmm_exact_solver_create(fx.mesh, &small), MFMM_OK);
    assert_int_equal(mfmm_solve_exact(small, &s, 1, &o, fx.d, NULL, &err), MFMM_ERR_MEMORY_LIMIT);
    assert_int_equal(err.status, MFMM_ERR_MEMORY_LIMIT);
    assert_true(strstr(err.message, "memory_limit") != NULL);
    for (int32_t v = 0; v < fx.g.nv; v++)
        assert_true(isinf(fx.d[v]));
    o.memory_limit = 1000; /* less than the tables */
    assert_int_equal(mfmm_solve_exact(small, &s, 1, &o, fx.d, NULL, &err), MFMM_ERR_MEMORY_LIMIT);
    o.memory_limit = need;
    mfmm_exact_solver_destroy(small);
    assert_int_equal(mfmm_exact_solver_create(fx.mesh, &small), MFMM_OK);
    assert_int_equal(mfmm_solve_exact(small, &s, 1, &o, fx.d, &info, &err), MFMM_OK);
    assert_true(info.peak_bytes <= need);
    mfmm_exact_solver_destroy(small);
    /* a solver whose queue grew in an unlimited solve gives it back for a
     * limited one that needs less: a source in a corner, within 0.2 */
    o.memory_limit = need - need / 8;
    o.max_distance = 0.2;
    mfmm_source corner = tm_vertex_source(0);
    assert_int_equal(mfmm_solve_exact(fx.solver, &corner, 1, &o, fx.d, &info, &err), MFMM_OK);
    assert_true(info.peak_bytes <= o.memory_limit);
    tm_assert_close(fx.d[1], 1.0 / 30.0, 1e-15);
    ex_free(&fx);
}

/* ---------------------------------------------------------------- threads */

typedef struct ex_job {
    const mfmm_mesh *mesh;
    int32_t nv, first;
    double *out; /* 4 rows of nv */
    int ok;
} ex_job;

static void *ex_worker(void *arg)
{
    ex_job *job = arg;
    mfmm_exact_solver *solver = NULL;
    job->ok = mfmm_exact_solver_create(job->mesh, &solver) == MFMM_OK;
    for (int i = 0; job->ok && i < 4; i++) {
        mfmm_source s = tm_vertex_source(job->first + 13 * i);
        job->ok = mfmm_solve_exact(solver, &s, 1, NULL, job->out + (size_t)i * job->nv, NULL,
                                   NULL) == MFMM_OK;
    }
    mfmm_exact_solver_destroy(solver);
    return NULL;
}

/* Solvers of one mesh in several threads at once (no shared mutable state):
 * the same rows as one thread alone. */
static void test_threads(void **state)
{
    (void)state;
    ex_fx fx = ex_make(mfmm_gen_sine(24));
    enum { NT = 3 };
    pthread_t th[NT];
    ex_job jobs[NT];
    for (int t = 0; t < NT; t++) {
        jobs[t].mesh = fx.mesh;
        jobs[t].nv = fx.g.nv;
        jobs[t].first = 5 + 101 * t;
        jobs[t].out = malloc(4 * (size_t)fx.g.nv * sizeof(double));
        assert_non_null(jobs[t].out);
        assert_int_equal(pthread_create(&th[t], NULL, ex_worker, &jobs[t]), 0);
    }
    for (int t = 0; t < NT; t++)
        assert_int_equal(pthread_join(th[t], NULL), 0);
    for (int t = 0; t < NT; t++) {
        assert_true(jobs[t].ok);
        for (int i = 0; i < 4; i++) {
            mfmm_source s = tm_vertex_source(jobs[t].first + 13 * i);
            ex_solve(&fx, &s, 1, NULL);
            assert_memory_equal(fx.d, jobs[t].out + (size_t)i * fx.g.nv,
                                (size_t)fx.g.nv * sizeof(double));
        }
        free(jobs[t].out);
    }
    ex_free(&fx);
}

/* ------------------------------------------------------------ patch API */

static void test_patch(void **state)
{
    (void)state;
    ex_fx fx = ex_make(mfmm_gen_grid(40));
    mfmm_exact_info full = {.struct_size = sizeof full}, part = {.struct_size = sizeof part};
    int32_t c = 20 * 41 + 20;
    mfmm_source s = tm_vertex_source(c);
    assert_int_equal(mfmm_solve_exact(fx.solver, &s, 1, NULL, fx.d, &full, NULL), MFMM_OK);
    for (int round = 0; round < 3; round++) {
        int32_t src = round == 1 ? 3 * 41 + 5 : c;
        /* mfmm_exact_patch is internal: the mesh's internal vertex ids */
        mfmm_source ps = tm_vertex_source(fx.mesh->to_internal[src]);
        int32_t n = -1;
        const int32_t *vs = NULL;
        const double *ds = NULL;
        double r = 0.1;
        assert_int_equal(mfmm_exact_patch(fx.solver, &ps, 1, r, 0, &n, &vs, &ds, &part), MFMM_OK);
        /* every vertex within r, and a ring beyond it of at most a
         * face's height (1/40 here), all exact */
        int32_t want = 0, most = 0;
        for (int32_t v = 0; v < fx.g.nv; v++) {
            double dv = dist3(fx.g.V + 3 * v, fx.g.V + 3 * src);
            want += dv <= r + 1e-12;
            most += dv <= r + 1.0 / 40 + 1e-12;
        }
        assert_true(n >= want - 4 && n <= most + 4); /* ties at the radius */
        assert_true(n > want + 4);
        int32_t inside = 0;
        for (int32_t i = 0; i < n; i++) {
            tm_assert_close(ds[i], dist3(fx.g.V + 3 * fx.mesh->to_external[vs[i]], fx.g.V + 3 * src),
                            1e-12);
            assert_true(ds[i] <= r + 1.0 / 40);
            inside += ds[i] <= r;
            assert_true(mfmm_exact_in_patch(fx.solver, vs[i]));
        }
        assert_true(inside >= want - 4 && inside <= want + 4);
        assert_true(part.n_windows * 10 < full.n_windows);
    }
    /* NULLs and bad counts */
    int32_t n;
    const int32_t *vs;
    const double *ds;
    assert_int_equal(mfmm_exact_patch(NULL, &s, 1, 0.1, 0, &n, &vs, &ds, NULL), MFMM_ERR_NULL_POINTER);
    assert_int_equal(mfmm_exact_patch(fx.solver, &s, 0, 0.1, 0, &n, &vs, &ds, NULL), MFMM_ERR_BAD_COUNT);
    assert_int_equal(mfmm_exact_patch(fx.solver, &s, 1, NAN, 0, &n, &vs, &ds, NULL), MFMM_ERR_BAD_ARGUMENT);
    mfmm_source bad = tm_vertex_source(fx.g.nv);
    assert_int_equal(mfmm_exact_patch(fx.solver, &bad, 1, 0.1, 0, &n, &vs, &ds, NULL), MFMM_ERR_BAD_SOURCE);
    /* a point source in a face, with a value: T = value + distance <= radius */
    mfmm_source fs = {0, 1000, {0.2, 0.3, 0.5}, 0.05};
    fs.face = fx.mesh->face_to_internal[1000]; /* internal, as the vertex ids above */
    double p[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < 3; k++)
        for (int e = 0; e < 3; e++)
            p[e] += fs.bary[k] * fx.g.V[3 * fx.g.F[3000 + k] + e];
    assert_int_equal(mfmm_exact_patch(fx.solver, &fs, 1, 0.15, 0, &n, &vs, &ds, NULL), MFMM_OK);
    assert_true(n > 10);
    for (int32_t i = 0; i < n; i++)
        tm_assert_close(ds[i], 0.05 + dist3(fx.g.V + 3 * fx.mesh->to_external[vs[i]], p), 1e-12);
    ex_free(&fx);
}

/* A sine heightfield and a zero-area face apart from it, the latter at
 * input index `at` (the others in order, the source face `*src` moved past
 * it), and the mesh built. */
static mfmm_mesh *ex_sine_and_needle(mfmm_gen_mesh *g, int32_t at, int32_t *src)
{
    mfmm_gen_mesh s = mfmm_gen_sine(12);
    assert_non_null(s.V);
    *g = ex_alloc(s.nv + 3, s.nf + 1);
    memcpy(g->V, s.V, 3 * (size_t)s.nv * sizeof(double));
    double needle[9] = {5.0, 5.0, 0.0, 5.5, 5.0, 0.0, 6.0, 5.0, 0.0};
    memcpy(g->V + 3 * s.nv, needle, sizeof needle);
    int32_t was = *src;
    for (int32_t f = 0, o = 0; o < g->nf; o++) {
        int32_t *t = g->F + 3 * o;
        if (o == at) {
            t[0] = s.nv;
            t[1] = s.nv + 1;
            t[2] = s.nv + 2;
            continue;
        }
        memcpy(t, s.F + 3 * f, 3 * sizeof *t);
        if (f++ == was)
            *src = o;
    }
    mfmm_gen_free(&s);
    return tm_make(g);
}

/* The patch takes internal ids, faces too: its check must read the face the
 * source names, not the input face of that number (a zero-area one here),
 * or the march's exact start falls back to the plain start. */
static void test_patch_internal_face_ids(void **state)
{
    (void)state;
    int32_t src = 6 * 24 + 11, at;
    mfmm_gen_mesh g;
    mfmm_mesh *m0 = ex_sine_and_needle(&g, 2 * 144, &src);
    at = m0->face_to_internal[src];
    mfmm_mesh_destroy(m0);
    mfmm_gen_free(&g);
    src = 6 * 24 + 11;
    mfmm_mesh *mesh = ex_sine_and_needle(&g, at, &src);
    /* internal ids depend on the faces, not on their input order */
    assert_int_equal(mesh->face_to_internal[src], at);
    assert_true(mfmm_mesh_degenerate(mesh, mesh->face_to_internal[at]));
    assert_false(mfmm_mesh_degenerate(mesh, at));
    mfmm_exact_solver *ex = NULL;
    assert_int_equal(mfmm_exact_solver_create(mesh, &ex), MFMM_OK);
    double *e = malloc((size_t)g.nv * sizeof *e), *d = malloc((size_t)g.nv * sizeof *d);
    assert_true(e && d);
    mfmm_source fs = {0, src, {0.2, 0.3, 0.5}, 0.0};
    assert_int_equal(mfmm_solve_exact(ex, &fs, 1, NULL, e, NULL, NULL), MFMM_OK);
    mfmm_source ps = fs;
    ps.face = at;
    int32_t n = 0;
    const int32_t *vs = NULL;
    const double *ds = NULL;
    assert_int_equal(mfmm_exact_patch(ex, &ps, 1, 0.3, 0, &n, &vs, &ds, NULL), MFMM_OK);
    assert_true(n > 20);
    for (int32_t i = 0; i < n; i++)
        tm_assert_close(ds[i], e[mesh->to_external[vs[i]]], 1e-12);
    /* the march from an exact start of 6 mean edges: exact within 4 of
     * them, where the plain start's march is up to 5 % off */
    mfmm_solver *solver = NULL;
    assert_int_equal(mfmm_solver_create(mesh, &solver), MFMM_OK);
    mfmm_solve_options so;
    mfmm_solve_options_init(&so);
    so.exact_start_radius = 6.0;
    assert_int_equal(mfmm_solve(solver, &fs, 1, &so, d, NULL), MFMM_OK);
    int32_t near = 0;
    for (int32_t v = 0; v < g.nv; v++)
        if (e[v] <= 4.0 * mesh->info.mean_edge_length) {
            tm_assert_close(d[v], e[v], 1e-12);
            near++;
        }
    assert_true(near > 100);
    mfmm_solver_destroy(solver);
    mfmm_exact_solver_destroy(ex);
    free(e);
    free(d);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

/* ------------------------------------------------ igl.exact_geodesic data */

#ifdef MFMM_TEST_ZLIB
#include <stdio.h>
#include <zlib.h>

static uint32_t rd16(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8;
}

static uint32_t rd32(const unsigned char *p)
{
    return rd16(p) | rd16(p + 2) << 16;
}

/* The bytes of member `name` of the zip file `buf` (stored or deflated),
 * found through the central directory; NULL if absent or unreadable. */
static unsigned char *zip_member(const unsigned char *buf, size_t n, const char *name,
                                 size_t *out_n)
{
    if (n < 22)
        return NULL;
    size_t eocd = n - 22;
    while (eocd > 0 && rd32(buf + eocd) != 0x06054b50u)
        eocd--;
    if (rd32(buf + eocd) != 0x06054b50u)
        return NULL;
    size_t cd = rd32(buf + eocd + 16), entries = rd16(buf + eocd + 10);
    for (size_t i = 0; i < entries && cd + 46 <= n; i++) {
        const unsigned char *c = buf + cd;
        if (rd32(c) != 0x02014b50u)
            return NULL;
        uint32_t method = rd16(c + 10), csize = rd32(c + 20), usize = rd32(c + 24);
        size_t nlen = rd16(c + 28), elen = rd16(c + 30), klen = rd16(c + 32);
        size_t local = rd32(c + 42);
        if (nlen == strlen(name) && !memcmp(c + 46, name, nlen) && local + 30 <= n) {
            const unsigned char *l = buf + local;
            size_t data = local + 30 + rd16(l + 26) + rd16(l + 28);
            unsigned char *out = malloc(usize ? usize : 1);
            if (!out || data + csize > n) {
                free(out);
                return NULL;
            }
            if (method == 0 && csize == usize) {
                memcpy(out, buf + data, usize);
            } else if (method == 8) {
                z_stream z;
                memset(&z, 0, sizeof z);
                z.next_in = (unsigned char *)(uintptr_t)(buf + data);
                z.avail_in = csize;
                z.next_out = out;
                z.avail_out = usize;
                if (inflateInit2(&z, -MAX_WBITS) != Z_OK || inflate(&z, Z_FINISH) != Z_STREAM_END) {
                    inflateEnd(&z);
                    free(out);
                    return NULL;
                }
                inflateEnd(&z);
            } else {
                free(out);
                return NULL;
            }
            *out_n = usize;
            return out;
        }
        cd += 46 + nlen + elen + klen;
    }
    return NULL;
}

/* An .npy array of little-endian f8 (as double) or i4/i8 (converted to
 * double), C order: the values and the shape (up to 2 dimensions). */
static double *npy_values(const unsigned char *b, size_t n, int64_t shape[2])
{
    if (n < 10 || memcmp(b, "\x93NUMPY", 6))
        return NULL;
    size_t hlen = b[6] == 1 ? rd16(b + 8) : rd32(b + 8), off = b[6] == 1 ? 10 : 12;
    char hdr[512];
    if (hlen >= sizeof hdr || off + hlen > n)
        return NULL;
    memcpy(hdr, b + off, hlen);
    hdr[hlen] = 0;
    const char *descr = strstr(hdr, "'descr': '");
    const char *sh = strstr(hdr, "'shape': (");
    if (!descr || !sh || strstr(hdr, "'fortran_order': True"))
        return NULL;
    descr += 10;
    shape[0] = shape[1] = 1;
    char *end;
    shape[0] = strtoll(sh + 10, &end, 10);
    if (*end == ',' && end[1] == ' ' && end[2] != ')')
        shape[1] = strtoll(end + 2, &end, 10);
    size_t count = (size_t)(shape[0] * shape[1]), item = descr[2] == '8' ? 8 : 4;
    const unsigned char *data = b + off + hlen;
    if (descr[0] != '<' || off + hlen + count * item > n)
        return NULL;
    double *out = malloc(count * sizeof *out);
    if (!out)
        return NULL;
    for (size_t i = 0; i < count; i++) {
        if (descr[1] == 'f' && item == 8) {
            memcpy(out + i, data + 8 * i, 8);
        } else if (descr[1] == 'i' && item == 4) {
            int32_t v;
            memcpy(&v, data + 4 * i, 4);
            out[i] = v;
        } else if (descr[1] == 'i' && item == 8) {
            int64_t v;
            memcpy(&v, data + 8 * i, 8);
            out[i] = (double)v;
        } else {
            free(out);
            return NULL;
        }
    }
    return out;
}

static double *npz_array(const char *path, const char *member, int64_t shape[2])
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    unsigned char *buf = NULL;
    size_t n = 0, cap = 0, got;
    do {
        if (n == cap) {
            cap = cap ? 2 * cap : 1 << 16;
            unsigned char *nb = realloc(buf, cap);
            if (!nb)
                break;
            buf = nb;
        }
        got = fread(buf + n, 1, cap - n, f);
        n += got;
    } while (got > 0);
    fclose(f);
    size_t mn = 0;
    unsigned char *m = buf ? zip_member(buf, n, member, &mn) : NULL;
    double *out = m ? npy_values(m, mn, shape) : NULL;
    free(m);
    free(buf);
    return out;
}
#endif

/* tests/data/reference/NAME.npz: igl.exact_geodesic (Kirsanov's MMP) from
 * three vertices of tests/data/meshes/NAME; ours equal to 1e-12 relative. */
static void check_reference(const char *mesh_file, const char *npz_file)
{
#ifdef MFMM_TEST_ZLIB
    char mpath[1024], rpath[1024];
    snprintf(mpath, sizeof mpath, "%s/meshes/%s", MESHFMM_TEST_DATA_DIR, mesh_file);
    snprintf(rpath, sizeof rpath, "%s/reference/%s", MESHFMM_TEST_DATA_DIR, npz_file);
    int64_t ss[2], ds[2];
    double *src = npz_array(rpath, "sources.npy", ss);
    double *ref = npz_array(rpath, "distances.npy", ds);
    double *V = NULL;
    int32_t *F = NULL, nv = 0, nf = 0;
    mfmm_error err;
    if (!src || !ref || mfmm_load_mesh(mpath, &V, &nv, &F, &nf, &err) != MFMM_OK) {
        free(src);
        free(ref);
        skip(); /* the data is not in this checkout */
    }
    assert_int_equal(ds[0], ss[0] * ss[1]);
    assert_int_equal(ds[1], nv);
    mfmm_gen_mesh g = {nv, nf, V, F};
    mfmm_mesh *mesh = tm_make(&g);
    mfmm_exact_solver *solver = NULL;
    assert_int_equal(mfmm_exact_solver_create(mesh, &solver), MFMM_OK);
    double *d = malloc((size_t)nv * sizeof *d);
    assert_non_null(d);
    for (int64_t i = 0; i < ds[0]; i++) {
        mfmm_source s = tm_vertex_source((int32_t)src[i]);
        assert_int_equal(mfmm_solve_exact(solver, &s, 1, NULL, d, NULL, &err), MFMM_OK);
        for (int32_t v = 0; v < nv; v++) {
            double r = ref[i * nv + v];
            if (isinf(r))
                assert_true(isinf(d[v]));
            else
                tm_assert_close(d[v], r, 1e-12 * r);
        }
    }
    free(d);
    mfmm_exact_solver_destroy(solver);
    mfmm_mesh_destroy(mesh);
    mfmm_free(V);
    mfmm_free(F);
    free(src);
    free(ref);
#else
    (void)mesh_file;
    (void)npz_file;
    skip(); /* built without zlib: the .npz cannot be read */
#endif
}

/* Saddles start once: among the saddles of the sine surface (half its
 * vertices near the centre), a saddle's windows are started after the
 * windows of its queue bucket, which can still lower it; started before
 * them (plain arrival order), 280 starts for 193 saddles on sine 100. */
static void test_saddles_start_once(void **state)
{
    (void)state;
    ex_fx fx = ex_make(mfmm_gen_sine(60));
    int32_t nv = fx.g.nv;
    double *sum = calloc((size_t)nv, sizeof *sum);
    assert_non_null(sum);
    tm_angle_sums(fx.g.V, fx.g.F, nv, fx.g.nf, sum);
    mfmm_mesh_info mi = {.struct_size = sizeof mi};
    mfmm_mesh_get_info(fx.mesh, &mi);
    int32_t c = 30 * 61 + 30; /* the centre, among saddles */
    mfmm_source ps = tm_vertex_source(fx.mesh->to_internal[c]);
    int32_t n = 0;
    const int32_t *vs = NULL;
    const double *ds = NULL;
    mfmm_exact_info info = {.struct_size = sizeof info};
    double r = MFMM_EXACT_START_RADIUS * mi.mean_edge_length;
    assert_int_equal(mfmm_exact_patch(fx.solver, &ps, 1, r, 0, &n, &vs, &ds, &info), MFMM_OK);
    /* every vertex that starts has d <= r, so it is in the patch */
    int32_t saddles = 0;
    for (int32_t i = 0; i < n; i++) {
        int32_t v = fx.mesh->to_external[vs[i]];
        double x = fx.g.V[3 * v], y = fx.g.V[3 * v + 1];
        int interior = x > 1e-9 && x < 1.0 - 1e-9 && y > 1e-9 && y < 1.0 - 1e-9;
        saddles += interior && ds[i] <= r && sum[v] > 2.0 * TM_PI + 1e-9;
    }
    print_message("sine 60, centre: %d saddles in the patch, %lld starts (with the source)\n",
                  (int)saddles, (long long)info.n_pseudo_sources);
    assert_true(saddles > 40);
    assert_true(info.n_pseudo_sources <= saddles + 1 + saddles / 50);
    free(sum);
    ex_free(&fx);
}

static void test_igl_reference_hand(void **state)
{
    (void)state;
    check_reference("hand_lowres.obj", "hand_lowres.npz");
}

static void test_igl_reference_spot(void **state)
{
    (void)state;
    check_reference("spot.obj", "spot.npz");
}

/* --------------------------------------------------------------- bad input */

static void test_bad_input(void **state)
{
    (void)state;
    ex_fx fx = ex_make(mfmm_gen_grid(4));
    mfmm_source ok = tm_vertex_source(0);
    mfmm_error err;
    mfmm_exact_solver *sv = (mfmm_exact_solver *)1;
    assert_int_equal(mfmm_exact_solver_create(NULL, &sv), MFMM_ERR_NULL_POINTER);
    assert_null(sv);
    assert_int_equal(mfmm_exact_solver_create(fx.mesh, NULL), MFMM_ERR_NULL_POINTER);
    mfmm_exact_solver_destroy(NULL);
    mfmm_exact_options_init(NULL);
    assert_int_equal(mfmm_solve_exact(NULL, &ok, 1, NULL, fx.d, NULL, &err), MFMM_ERR_NULL_POINTER);
    assert_int_equal(mfmm_solve_exact(fx.solver, NULL, 1, NULL, fx.d, NULL, &err), MFMM_ERR_NULL_POINTER);
    assert_int_equal(mfmm_solve_exact(fx.solver, &ok, 1, NULL, NULL, NULL, &err), MFMM_ERR_NULL_POINTER);
    assert_int_equal(mfmm_solve_exact(fx.solver, &ok, 0, NULL, fx.d, NULL, &err), MFMM_ERR_BAD_COUNT);
    mfmm_source s = tm_vertex_source(fx.g.nv);
    assert_int_equal(mfmm_solve_exact(fx.solver, &s, 1, NULL, fx.d, NULL, &err), MFMM_ERR_BAD_SOURCE);
    assert_int_equal(err.index, 0);
    mfmm_source two[2] = {ok, {0, fx.g.nf, {0.3, 0.3, 0.4}, 0.0}};
    assert_int_equal(mfmm_solve_exact(fx.solver, two, 2, NULL, fx.d, NULL, &err), MFMM_ERR_BAD_SOURCE);
    assert_int_equal(err.index, 1);
    two[1].face = 2;
    two[1].bary[0] = -0.2;
    two[1].bary[2] = 0.9;
    assert_int_equal(mfmm_solve_exact(fx.solver, two, 2, NULL, fx.d, NULL, &err),
                     MFMM_ERR_BAD_BARYCENTRIC);
    s = ok;
    s.value = INFINITY;
    assert_int_equal(mfmm_solve_exact(fx.solver, &s, 1, NULL, fx.d, NULL, &err), MFMM_ERR_BAD_ARGUMENT);
    mfmm_exact_options o;
    mfmm_exact_options_init(&o);
    o.max_distance = -1.0;
    assert_int_equal(mfmm_solve_exact(fx.solver, &ok, 1, &o, fx.d, NULL, &err), MFMM_ERR_BAD_ARGUMENT);
    for (int32_t v = 0; v < fx.g.nv; v++)
        assert_true(isinf(fx.d[v]));
    o.max_distance = NAN;
    assert_int_equal(mfmm_solve_exact(fx.solver, &ok, 1, &o, fx.d, NULL, &err), MFMM_ERR_BAD_ARGUMENT);
    assert_string_equal(mfmm_status_string(MFMM_ERR_MEMORY_LIMIT),
                        "the computation needed more memory than its memory limit");
    /* after errors the solver still works */
    ex_solve(&fx, &ok, 1, NULL);
    tm_assert_close(fx.d[fx.g.nv - 1], sqrt(2.0), 1e-15);
    ex_free(&fx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_plane_exact),
        cmocka_unit_test(test_mixed_orientation),
        cmocka_unit_test(test_several_sources),
        cmocka_unit_test(test_values_and_scale),
        cmocka_unit_test(test_cube),
        cmocka_unit_test(test_cylinder),
        cmocka_unit_test(test_saddle),
        cmocka_unit_test(test_reflex_corner),
        cmocka_unit_test(test_max_distance),
        cmocka_unit_test(test_interrupt),
        cmocka_unit_test(test_stalled_run_ends_within_bounds),
        cmocka_unit_test(test_nonmanifold_walls_past_budget),
        cmocka_unit_test(test_nonmanifold_components),
        cmocka_unit_test(test_dominate_equal_sigma),
        cmocka_unit_test(test_nonmanifold_symmetric),
        cmocka_unit_test(test_pass_into_needle_on_nonmanifold_edge),
        cmocka_unit_test(test_pass_cut_at_depth_limit),
        cmocka_unit_test(test_pass_through_long_needle_strip),
        cmocka_unit_test(test_degenerate_face),
        cmocka_unit_test(test_memory_limit),
        cmocka_unit_test(test_threads),
        cmocka_unit_test(test_patch),
        cmocka_unit_test(test_patch_internal_face_ids),
        cmocka_unit_test(test_saddles_start_once),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_igl_reference_hand),
        cmocka_unit_test(test_igl_reference_spot),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
