/* A virtual stencil (section 4.2) under a cost. An obtuse
 * corner's virtual edge and triangles lie over other faces than the corner's;
 * with a cost they are used only where the cost is the same over that
 * footprint, else the plain stencil. Checked against a solve on the same mesh
 * split 1-to-4 (edge midpoints; per-face costs inherited by the four
 * children, per-vertex costs interpolated at the midpoints), which resolves
 * the cost twice as finely.
 *
 * Tolerance: a first-order solve on the coarse mesh may lie below the
 * subdivided solve by its discretisation error. That error is measured here
 * with the plain stencil (unfolding off) on the same case against the same
 * subdivided solve; the default solve (unfolding on) must not go below the
 * subdivided solve by more than that plus 0.5 % of T. Measured, min over the
 * vertices of (T - T_sub) / T_sub, default / plain stencil:
 *   lattice           per face   0.0 % /  0.0 %  (before the fix: -98 %, T(91) = 1.73)
 *                     per vertex 0.0 % /  0.0 %  (before the trapezoid costs of
 *                                march.h: -96 %, F(C) = 1 charged over triangles
 *                                whose other corners cost 100)
 *   camelhead band x  per face  -6.8 % / -6.8 %  (off the band; on it -0.1 %)
 *                     per vertex -4.9 % / -4.9 % (on the band -0.1 %)
 *   camelhead band y  per face  -9.6 % / -9.6 %  (on the band 0.0 %)
 *                     per vertex -4.5 % / -4.5 % (on the band 0.0 %; before:
 *                                2 of 366 band vertices > 20 % low, worst -36 %)
 * Off the band the coarse solves lie below the subdivided ones where the
 * subdivided mesh keeps the plain stencil at obtuse corners next to the band
 * (it does not converge there); further 1-to-4 splits raise those values.
 * The camelhead band first reported (76 of 553 vertices > 20 % low) could not be
 * rebuilt exactly; planes x, y, z at 0.3, 0.5, 0.7 of the box and two
 * iso-distance bands, sources on and off the band, give 0 band vertices
 * > 20 % low now (bench/studies/sweep_cost_bands.py). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "testutil.h"

typedef struct edge_key {
    int32_t lo, hi, at; /* at: index into the (3 nf) corner-edges */
} edge_key;

static int edge_cmp(const void *pa, const void *pb)
{
    const edge_key *a = pa, *b = pb;
    if (a->lo != b->lo)
        return a->lo < b->lo ? -1 : 1;
    return (a->hi > b->hi) - (a->hi < b->hi);
}

/* A mesh and its costs, subdivided 1-to-4; the first nv vertices are kept. */
typedef struct sub_mesh {
    double *V;
    int32_t *F;
    int32_t nv, nf;
    double *face_cost, *vertex_cost;
} sub_mesh;

static sub_mesh subdivide(const double *V, int32_t nv, const int32_t *F, int32_t nf,
                          const double *face_cost, const double *vertex_cost)
{
    size_t nc = 3 * (size_t)nf;
    edge_key *e = malloc(nc * sizeof *e);
    int32_t *mid = malloc(nc * sizeof *mid); /* midpoint of the edge opposite corner c */
    assert_non_null(e);
    assert_non_null(mid);
    for (size_t c = 0; c < nc; c++) {
        int32_t u = F[3 * (c / 3) + (c % 3 + 1) % 3], w = F[3 * (c / 3) + (c % 3 + 2) % 3];
        e[c].lo = u < w ? u : w;
        e[c].hi = u < w ? w : u;
        e[c].at = (int32_t)c;
    }
    qsort(e, nc, sizeof *e, edge_cmp);
    int32_t n_new = 0;
    for (size_t i = 0; i < nc; i++) {
        if (i > 0 && e[i].lo == e[i - 1].lo && e[i].hi == e[i - 1].hi)
            mid[e[i].at] = mid[e[i - 1].at];
        else
            mid[e[i].at] = nv + n_new++;
    }
    sub_mesh s;
    s.nv = nv + n_new;
    s.nf = 4 * nf;
    s.V = malloc(3 * (size_t)s.nv * sizeof *s.V);
    s.F = malloc(3 * (size_t)s.nf * sizeof *s.F);
    s.face_cost = malloc((size_t)s.nf * sizeof *s.face_cost);
    s.vertex_cost = malloc((size_t)s.nv * sizeof *s.vertex_cost);
    assert_true(s.V && s.F && s.face_cost && s.vertex_cost);
    memcpy(s.V, V, 3 * (size_t)nv * sizeof *V);
    memcpy(s.vertex_cost, vertex_cost, (size_t)nv * sizeof *vertex_cost);
    for (size_t c = 0; c < nc; c++) {
        int32_t u = F[3 * (c / 3) + (c % 3 + 1) % 3], w = F[3 * (c / 3) + (c % 3 + 2) % 3];
        int32_t m = mid[c];
        for (int d = 0; d < 3; d++)
            s.V[3 * (size_t)m + d] = 0.5 * (V[3 * (size_t)u + d] + V[3 * (size_t)w + d]);
        s.vertex_cost[m] = 0.5 * (vertex_cost[u] + vertex_cost[w]);
    }
    for (int32_t f = 0; f < nf; f++) {
        int32_t a = F[3 * f], b = F[3 * f + 1], c = F[3 * f + 2];
        int32_t ma = mid[3 * f], mb = mid[3 * f + 1], mc = mid[3 * f + 2];
        int32_t t[4][3] = {{a, mc, mb}, {mc, b, ma}, {mb, ma, c}, {ma, mb, mc}};
        for (int k = 0; k < 4; k++) {
            memcpy(s.F + 3 * (size_t)(k * nf + f), t[k], sizeof t[k]);
            s.face_cost[k * nf + f] = face_cost[f];
        }
    }
    free(e);
    free(mid);
    return s;
}

static void sub_free(sub_mesh *s)
{
    free(s->V);
    free(s->F);
    free(s->face_cost);
    free(s->vertex_cost);
}

static void solve(const mfmm_mesh *mesh, int32_t source, const double *cost,
                  mfmm_cost_location loc, int unfolding, double *d)
{
    mfmm_solver *solver = NULL;
    assert_int_equal(mfmm_solver_create(mesh, &solver), MFMM_OK);
    mfmm_solve_options o;
    mfmm_solve_options_init(&o);
    o.cost = cost;
    o.cost_location = loc;
    o.unfolding = unfolding;
    mfmm_source s = tm_vertex_source(source);
    mfmm_error err;
    if (mfmm_solve(solver, &s, 1, &o, d, &err) != MFMM_OK)
        fail_msg("mfmm_solve: %s", err.message);
    mfmm_solver_destroy(solver);
}

/* min over coarse vertices of (T - T_sub) / T_sub */
static double min_rel(const double *d, const double *d_sub, int32_t nv, const int32_t *only,
                      int32_t n_only, int32_t *n_below20)
{
    double worst = INFINITY;
    int32_t below = 0;
    for (int32_t i = 0; i < (only ? n_only : nv); i++) {
        int32_t v = only ? only[i] : i;
        if (!(d_sub[v] > 0.0) || !isfinite(d_sub[v]))
            continue;
        double r = (d[v] - d_sub[v]) / d_sub[v];
        worst = r < worst ? r : worst;
        below += r < -0.2;
    }
    if (n_below20)
        *n_below20 = below;
    return worst;
}

/* Default solve against the subdivided solve, per face and per vertex; the
 * tolerance is the plain stencil's own measured error (see the top). */
static void check_against_subdivided(const char *name, const double *V, int32_t nv,
                                     const int32_t *F, int32_t nf, const double *face_cost,
                                     const double *vertex_cost, int32_t source,
                                     const int32_t *band, int32_t n_band, double *worst_out)
{
    mfmm_error err;
    mfmm_mesh *coarse = NULL, *fine = NULL;
    assert_int_equal(mfmm_mesh_create(V, nv, F, nf, NULL, &coarse, &err), MFMM_OK);
    sub_mesh s = subdivide(V, nv, F, nf, face_cost, vertex_cost);
    assert_int_equal(mfmm_mesh_create(s.V, s.nv, s.F, s.nf, NULL, &fine, &err), MFMM_OK);
    double *d = malloc((size_t)nv * sizeof *d), *dp = malloc((size_t)nv * sizeof *dp);
    double *ds = malloc((size_t)s.nv * sizeof *ds);
    assert_true(d && dp && ds);
    for (int per_vertex = 0; per_vertex < 2; per_vertex++) {
        mfmm_cost_location loc = per_vertex ? MFMM_COST_PER_VERTEX : MFMM_COST_PER_FACE;
        solve(fine, source, per_vertex ? s.vertex_cost : s.face_cost, loc, 1, ds);
        solve(coarse, source, per_vertex ? vertex_cost : face_cost, loc, 1, d);
        solve(coarse, source, per_vertex ? vertex_cost : face_cost, loc, 0, dp);
        int32_t below = 0, below_plain = 0;
        double r = min_rel(d, ds, nv, NULL, 0, NULL);
        double rp = min_rel(dp, ds, nv, NULL, 0, NULL);
        double rb = band ? min_rel(d, ds, nv, band, n_band, &below) : 0.0;
        if (band)
            min_rel(dp, ds, nv, band, n_band, &below_plain);
        print_message("%s per %s: min (T - T_sub) / T_sub = %+.4f (plain stencil %+.4f)%s", name,
                      per_vertex ? "vertex" : "face", r, rp, band ? "" : "\n");
        if (band)
            print_message("; band: %d of %d vertices > 20 %% low (plain %d), worst %+.4f\n",
                          (int)below, (int)n_band, (int)below_plain, rb);
        if (!(r >= rp - 0.005))
            fail_msg("%s per %s: the default solve is %.4f below the subdivided one, the plain "
                     "stencil only %.4f",
                     name, per_vertex ? "vertex" : "face", -r, -rp);
        if (band) { /* no band vertex > 20 % low */
            assert_true(below <= below_plain);
            assert_int_equal(below, 0);
        }
        worst_out[per_vertex] = r;
    }
    free(d);
    free(dp);
    free(ds);
    sub_free(&s);
    mfmm_mesh_destroy(coarse);
    mfmm_mesh_destroy(fine);
}

/* The first reproducer, exactly: a 30-30-120 lattice. */
#define LN 13
static void lattice(double *V, int32_t *F)
{
    for (int j = 0; j < LN; j++)
        for (int i = 0; i < LN; i++) {
            double *x = V + 3 * (j * LN + i);
            x[0] = 3.0 * (i + 0.5 * (j % 2));
            x[1] = j * sqrt(3.0) / 2.0;
            x[2] = 0.0;
        }
    int32_t n = 0;
    for (int j = 0; j < LN - 1; j++)
        for (int i = 0; i < LN - 1; i++) {
            int32_t a = LN * j + i, b = a + 1, c = a + LN, d = c + 1;
            int32_t t[2][3] = {{a, b, c}, {b, d, c}}, u[2][3] = {{a, d, c}, {a, b, d}};
            for (int k = 0; k < 2; k++, n++)
                memcpy(F + 3 * n, j % 2 == 0 ? t[k] : u[k], 3 * sizeof(int32_t));
        }
}

static void test_lattice(void **state)
{
    (void)state;
    enum { NV = LN * LN, NF = 2 * (LN - 1) * (LN - 1) };
    double V[3 * NV], fcost[NF], vcost[NV], d[NV], dp[NV];
    int32_t F[3 * NF];
    lattice(V, F);
    for (int f = 0; f < NF; f++)
        fcost[f] = 100.0;
    fcost[144] = 1.0;
    for (int v = 0; v < NV; v++)
        vcost[v] = 100.0;
    for (int k = 0; k < 3; k++)
        vcost[F[3 * 144 + k]] = 1.0;
    mfmm_mesh *mesh = NULL;
    mfmm_error err;
    assert_int_equal(mfmm_mesh_create(V, NV, F, NF, NULL, &mesh, &err), MFMM_OK);
    /* face 144 is (78, 79, 91); its corner at 91 is obtuse with virtual vertex 65 */
    assert_int_equal(F[3 * 144 + 2], 91);
    solve(mesh, 65, fcost, MFMM_COST_PER_FACE, 1, d);
    /* every path from 65 to 91 crosses cost-100 faces for at least sqrt(3)/2 */
    print_message("lattice per face: T(91) = %.4f (unfolding off: ", d[91]);
    solve(mesh, 65, fcost, MFMM_COST_PER_FACE, 0, dp);
    print_message("%.4f)\n", dp[91]);
    assert_true(d[91] >= 100.0 * sqrt(3.0) / 2.0);
    /* per vertex: the corner at 91 (F = 1) no longer charges 1 over the strip */
    solve(mesh, 65, vcost, MFMM_COST_PER_VERTEX, 1, d);
    solve(mesh, 65, vcost, MFMM_COST_PER_VERTEX, 0, dp);
    print_message("lattice per vertex: T(91) = %.4f (unfolding off: %.4f)\n", d[91], dp[91]);
    assert_true(d[91] >= dp[91]);
    mfmm_mesh_destroy(mesh);
    double worst[2];
    int32_t band[3] = {78, 79, 91};
    check_against_subdivided("lattice", V, NV, F, NF, fcost, vcost, 65, band, 3, worst);
    assert_true(worst[0] >= -0.02); /* per face: the plain stencil's -0.97 %, rounded up */
    assert_true(worst[1] >= -0.02); /* per vertex: was -96 % with F(C) over the triangle */
}

/* camelhead with a one-face-wide band of cost 1 in cost 100: the faces that
 * the plane x (or y) = (bounding box centre) crosses (a corner strictly on each
 * side); per vertex, the band faces' vertices cost 1. Source: the band's
 * lowest vertex id. */
static void camelhead_band(int axis, int32_t expect_band)
{
    char path[1024];
    tm_data_path(path, sizeof path, "meshes/camelhead.off");
    double *V = NULL;
    int32_t *F = NULL, nv = 0, nf = 0;
    mfmm_error err;
    if (mfmm_load_mesh(path, &V, &nv, &F, &nf, &err) != MFMM_OK)
        fail_msg("%s: %s", path, err.message);
    double lo = INFINITY, hi = -INFINITY;
    for (int32_t v = 0; v < nv; v++) {
        lo = fmin(lo, V[3 * v + axis]);
        hi = fmax(hi, V[3 * v + axis]);
    }
    double x0 = 0.5 * (lo + hi);
    double *fcost = malloc((size_t)nf * sizeof *fcost), *vcost = malloc((size_t)nv * sizeof *vcost);
    int32_t *band = malloc((size_t)nv * sizeof *band), n_band = 0, source = -1;
    assert_true(fcost && vcost && band);
    for (int32_t v = 0; v < nv; v++)
        vcost[v] = 100.0;
    for (int32_t f = 0; f < nf; f++) {
        double a = V[3 * F[3 * f] + axis], b = V[3 * F[3 * f + 1] + axis],
               c = V[3 * F[3 * f + 2] + axis];
        int in = fmin(a, fmin(b, c)) < x0 && fmax(a, fmax(b, c)) > x0;
        fcost[f] = in ? 1.0 : 100.0;
        for (int k = 0; in && k < 3; k++)
            vcost[F[3 * f + k]] = 1.0;
    }
    for (int32_t v = 0; v < nv; v++)
        if (vcost[v] == 1.0) {
            band[n_band++] = v;
            if (source < 0)
                source = v;
        }
    assert_int_equal(n_band, expect_band);
    double worst[2];
    check_against_subdivided(axis == 0 ? "camelhead band x" : "camelhead band y", V, nv, F, nf, fcost, vcost, source, band, n_band,
                             worst);
    free(fcost);
    free(vcost);
    free(band);
    mfmm_free(V);
    mfmm_free(F);
}

static void test_camelhead_band_x(void **state)
{
    (void)state;
    camelhead_band(0, 488);
}

/* per vertex before the trapezoid costs: 2 band vertices > 20 % low, worst -36 % */
static void test_camelhead_band_y(void **state)
{
    (void)state;
    camelhead_band(1, 366);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lattice),
        cmocka_unit_test(test_camelhead_band_x),
        cmocka_unit_test(test_camelhead_band_y),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
