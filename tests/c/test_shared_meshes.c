/* Every mesh of tests/data/meshes (real, imperfect: boundaries, holes,
 * non-manifold edges, unreferenced vertices, needles) loads, and a solve
 * gives finite values on the source's component, +inf elsewhere, never NaN. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <cmocka.h>

#include "mesh/mesh.h"
#include "testutil.h"

static int32_t root(int32_t *parent, int32_t x)
{
    while (parent[x] != x)
        x = parent[x] = parent[parent[x]];
    return x;
}

/* comp[v] = a label shared by the vertices of one component (through the
 * input faces F); vertices in no face get labels of their own. */
static void components(const int32_t *F, int32_t nv, int32_t nf, int32_t *comp)
{
    for (int32_t v = 0; v < nv; v++)
        comp[v] = v;
    for (int32_t f = 0; f < nf; f++)
        for (int k = 1; k < 3; k++) {
            int32_t a = root(comp, F[3 * f]), b = root(comp, F[3 * f + k]);
            if (a != b)
                comp[b] = a;
        }
    for (int32_t v = 0; v < nv; v++)
        comp[v] = root(comp, v);
}

static void check_mesh(const char *file, int32_t want_components, int32_t want_unreferenced)
{
    int32_t *F = NULL, nv = 0, nf = 0;
    mfmm_mesh *mesh = tm_load_data(file, &nv, &nf, &F);
    mfmm_mesh_info info = {.struct_size = sizeof info};
    mfmm_mesh_get_info(mesh, &info);
    print_message("%-24s nv=%6d nf=%6d components=%d boundary=%d nonmanifold=%d unref=%d "
                  "obtuse=%d virtual=%d failed=%d degenerate=%d\n",
                  file, info.n_vertices, info.n_faces, info.n_components, info.n_boundary_edges,
                  info.n_nonmanifold_edges, info.n_unreferenced_vertices, info.n_obtuse_corners,
                  info.n_virtual_edges, info.n_unfold_failures, info.n_degenerate_faces);
    assert_int_equal(info.n_components, want_components);
    assert_int_equal(info.n_unreferenced_vertices, want_unreferenced);
    assert_int_equal(info.n_virtual_edges + info.n_unfold_failures, info.n_obtuse_corners);
    mfmm_solver *solver = NULL;
    assert_int_equal(mfmm_solver_create(mesh, &solver), MFMM_OK);
    double *d = malloc((size_t)nv * sizeof *d);
    int32_t *comp = malloc((size_t)nv * sizeof *comp);
    assert_true(d && comp);
    components(F, nv, nf, comp);
    for (int unfolding = 0; unfolding <= 1; unfolding++) {
        mfmm_source src = tm_vertex_source(F[3 * (nf / 2)]);
        mfmm_solve_options opt;
        mfmm_solve_options_init(&opt);
        opt.unfolding = unfolding;
        assert_int_equal(mfmm_solve(solver, &src, 1, &opt, d, NULL), MFMM_OK);
        int32_t here = comp[src.vertex];
        for (int32_t v = 0; v < nv; v++) {
            assert_false(isnan(d[v]));
            if (comp[v] == here)
                assert_true(isfinite(d[v]) && d[v] >= 0.0);
            else
                assert_true(isinf(d[v]) && d[v] > 0.0);
        }
        assert_true(d[src.vertex] == 0.0);
    }
    free(d);
    free(comp);
    mfmm_solver_destroy(solver);
    mfmm_mesh_destroy(mesh);
    mfmm_free(F);
}

static void test_hand(void **s) { (void)s; check_mesh("meshes/hand_lowres.obj", 1, 0); }
static void test_beetle(void **s) { (void)s; check_mesh("meshes/beetle.obj", 2, 0); }
static void test_spot(void **s) { (void)s; check_mesh("meshes/spot.obj", 1, 0); }
static void test_wingnut(void **s) { (void)s; check_mesh("meshes/wingnut.obj", 1, 0); }
static void test_fertility(void **s) { (void)s; check_mesh("meshes/fertility_FE_10k.off", 1, 0); }
static void test_max(void **s) { (void)s; check_mesh("meshes/decimated-max.obj", 1, 0); }
static void test_camelhead(void **s) { (void)s; check_mesh("meshes/camelhead.off", 1, 0); }
static void test_nefertiti(void **s) { (void)s; check_mesh("meshes/nefertiti-lowres.obj", 1, 0); }
static void test_bunny(void **s) { (void)s; check_mesh("meshes/stanford-bunny.obj", 1, 1113); }
static void test_igea(void **s) { (void)s; check_mesh("meshes/igea.ply", 1, 0); }

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hand),      cmocka_unit_test(test_beetle),
        cmocka_unit_test(test_spot),      cmocka_unit_test(test_wingnut),
        cmocka_unit_test(test_fertility), cmocka_unit_test(test_max),
        cmocka_unit_test(test_camelhead), cmocka_unit_test(test_nefertiti),
        cmocka_unit_test(test_bunny),     cmocka_unit_test(test_igea),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
