/* A built mesh's memory: at most 300 bytes per vertex on every
 * shared mesh and on generated sine and sphere meshes, counted array by
 * array (mfmm_mesh_memory); and the virtual edges' strips, which the mesh
 * keeps only as their vertices (mesh.h), re-walked (mfmm_strip_next) to the
 * same virtual edge the build found; the public report's contract. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "testutil.h"
#include "mesh/mesh.h"
#include "mesh/spokes.h"
#include "mesh/unfold.h"
#include "io/generate.h"

static double bytes_per_vertex(const mfmm_mesh *mesh)
{
    const char *names[32];
    size_t bytes[32];
    int n = mfmm_mesh_memory(mesh, names, bytes, 32);
    assert_true(n <= 32);
    size_t total = 0;
    for (int i = 0; i < n; i++)
        total += bytes[i];
    return (double)total / mesh->nv;
}

static void check_budget(const mfmm_mesh *mesh, const char *what)
{
    double b = bytes_per_vertex(mesh);
    if (!(b <= 300.0))
        fail_msg("%s: %.1f bytes per vertex > 300", what, b);
}

static void test_shared_meshes_within_budget(void **state)
{
    (void)state;
    static const char *files[] = {
        "meshes/beetle.obj",           "meshes/camelhead.off",     "meshes/decimated-max.obj",
        "meshes/fertility_FE_10k.off", "meshes/hand_lowres.obj",   "meshes/igea.ply",
        "meshes/nefertiti-lowres.obj", "meshes/spot.obj",          "meshes/stanford-bunny.obj",
        "meshes/wingnut.obj",
    };
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        mfmm_mesh *mesh = tm_load_data(files[i], NULL, NULL, NULL);
        check_budget(mesh, files[i]);
        mfmm_mesh_destroy(mesh);
    }
}

static void test_generated_meshes_within_budget(void **state)
{
    (void)state;
    mfmm_gen_mesh g[] = {mfmm_gen_sine(30), mfmm_gen_sine(100), mfmm_gen_sine(200),
                         mfmm_gen_icosphere(3), mfmm_gen_icosphere(5)};
    const char *what[] = {"sine 30", "sine 100", "sine 200", "sphere 3", "sphere 5"};
    for (size_t i = 0; i < sizeof g / sizeof g[0]; i++) {
        mfmm_mesh *mesh = tm_make(&g[i]);
        check_budget(mesh, what[i]);
        mfmm_mesh_destroy(mesh);
        mfmm_gen_free(&g[i]);
    }
}

static int face_has(const mfmm_mesh *m, int32_t f, int32_t v)
{
    const mfmm_face *fr = m->face_records + f;
    return fr->v[0] == v || fr->v[1] == v || fr->v[2] == v;
}

/* Every virtual edge's re-walked strip: as many steps as its stored
 * vertices, those vertices, faces that follow each other across the edge
 * crossed, crossings inside each edge, V at the end, and |CV| in the
 * unfolded plane equal, bit for bit, to the |CV| the build stored. */
static void check_strips(const mfmm_mesh *m, const char *what)
{
    int32_t n_steps = 0;
    for (int32_t j = 0; j < m->n_virts; j++) {
        const mfmm_virt *vr = m->virts + j;
        int32_t f = vr->corner / 3, k = vr->corner % 3;
        const mfmm_face *fr = m->face_records + f;
        assert_int_equal(fr->virt & 3, k);
        assert_int_equal(fr->v[k], vr->c);
        assert_int_equal(mfmm_mesh_virt_index(m, vr->corner), j);
        int32_t V = fr->virt >> 2, at = m->virt_strip[j], n = m->virt_strip[j + 1] - at + 1;
        mfmm_strip_walk w;
        mfmm_virt_step st;
        mfmm_strip_begin(&w, m, j);
        if (sqrt(w.pv.x * w.pv.x + w.pv.y * w.pv.y) != vr->len)
            fail_msg("%s: virtual edge %d re-walked to |CV| %.17g, built %.17g", what, (int)j,
                     sqrt(w.pv.x * w.pv.x + w.pv.y * w.pv.y), vr->len);
        int32_t i = 0, prev = f, far = -1;
        while (mfmm_strip_next(&w, &st)) {
            assert_true(i < n);
            assert_int_equal(st.far, i < n - 1 ? m->strip[at + i] : V);
            assert_true(face_has(m, prev, st.e1) && face_has(m, prev, st.e2));
            assert_true(face_has(m, st.face, st.e1) && face_has(m, st.face, st.e2));
            assert_true(face_has(m, st.face, st.far) && st.far != st.e1 && st.far != st.e2);
            assert_true(st.face != prev);
            assert_true(st.t >= 0.0 && st.t <= 1.0);
            prev = st.face;
            far = st.far;
            i++;
        }
        assert_int_equal(i, n);
        assert_int_equal(far, V);
        n_steps += n - 1;
    }
    assert_int_equal(n_steps, m->virt_strip[m->n_virts]);
    /* and a corner without a virtual edge has no index */
    for (int32_t c = 0; c < 3 * m->nf; c++)
        if ((m->face_records[c / 3].virt & 3) != c % 3)
            assert_int_equal(mfmm_mesh_virt_index(m, c), -1);
}

static void test_strips_rewalk(void **state)
{
    (void)state;
    mfmm_gen_mesh g[] = {mfmm_gen_lattice(20, 3.0), mfmm_gen_sine(40), mfmm_gen_torus(30, 20, 1.0, 0.4)};
    const char *what[] = {"lattice 20", "sine 40", "torus 30x20"};
    for (size_t i = 0; i < sizeof g / sizeof g[0]; i++) {
        mfmm_mesh *mesh = tm_make(&g[i]);
        assert_true(mesh->n_virts > 0);
        check_strips(mesh, what[i]);
        mfmm_mesh_destroy(mesh);
        mfmm_gen_free(&g[i]);
    }
    static const char *files[] = {"meshes/camelhead.off", "meshes/wingnut.obj", "meshes/beetle.obj"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        mfmm_mesh *mesh = tm_load_data(files[i], NULL, NULL, NULL);
        assert_true(mesh->n_virts > 0);
        check_strips(mesh, files[i]);
        mfmm_mesh_destroy(mesh);
    }
}

/* The public report's contract (meshfmm.h): the count alone, refusals,
 * a partial fill, sizes that follow from nv and nf alone (analytic), and
 * the tables built on first use counted 0 until the first solve builds them. */
static void test_public_report(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_sine(20);
    mfmm_mesh *mesh = tm_make(&g);
    size_t nv = (size_t)g.nv, nf = (size_t)g.nf;
    int n = mfmm_mesh_memory(mesh, NULL, NULL, 0);
    assert_true(n >= 12 && n <= 32);
    const char *names[32], *few[2] = {NULL, NULL};
    size_t bytes[32], few_bytes[2] = {0, 0};
    assert_int_equal(mfmm_mesh_memory(NULL, names, bytes, 32), -1);
    assert_int_equal(mfmm_mesh_memory(mesh, names, bytes, -1), -1);
    assert_int_equal(mfmm_mesh_memory(mesh, NULL, bytes, 32), -1);
    assert_int_equal(mfmm_mesh_memory(mesh, names, NULL, 32), -1);
    assert_int_equal(mfmm_mesh_memory(mesh, few, few_bytes, 1), n);
    assert_int_equal(mfmm_mesh_memory(mesh, names, bytes, 32), n);
    assert_string_equal(few[0], names[0]);
    assert_int_equal(few_bytes[0], bytes[0]);
    assert_null(few[1]);
    assert_int_equal(tm_memory_entry(mesh, "xyz"), 24 * nv);
    assert_int_equal(tm_memory_entry(mesh, "to_internal/to_external"), 8 * nv);
    assert_int_equal(tm_memory_entry(mesh, "face_to_internal/external"), 8 * nf);
    assert_int_equal(tm_memory_entry(mesh, "face_neighbor"), 12 * nf);
    assert_int_equal(tm_memory_entry(mesh, "spokes (once built)"), 0);
    assert_int_equal(tm_memory_entry(mesh, "exact tables (once built)"), 0);
    /* a default solve (exact start) builds the exact tables around its
     * source; the spokes wait for MFMM_SPOKES_AFTER full marches, then stay */
    double *d = malloc(nv * sizeof *d);
    assert_non_null(d);
    mfmm_solver *solver = NULL;
    assert_int_equal(mfmm_solver_create(mesh, &solver), MFMM_OK);
    mfmm_source src = tm_vertex_source(0);
    assert_int_equal(mfmm_solve(solver, &src, 1, NULL, d, NULL), MFMM_OK);
    assert_int_equal(mfmm_mesh_memory(mesh, names, bytes, 32), n);
    assert_int_equal(tm_memory_entry(mesh, "spokes (once built)"), 0);
    size_t first = tm_memory_entry(mesh, "exact tables (once built)");
    assert_true(first > 0);
    for (int q = 0; q < MFMM_SPOKES_AFTER; q++)
        assert_int_equal(mfmm_solve(solver, &src, 1, NULL, d, NULL), MFMM_OK);
    assert_true(tm_memory_entry(mesh, "spokes (once built)") > 0);
    assert_true(tm_memory_entry(mesh, "exact tables (once built)") == first);
    assert_int_equal(tm_memory_entry(mesh, "xyz"), 24 * nv);
    mfmm_solver_destroy(solver);
    free(d);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_strips_rewalk),
        cmocka_unit_test(test_public_report),
        cmocka_unit_test(test_shared_meshes_within_budget),
        cmocka_unit_test(test_generated_meshes_within_budget),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
