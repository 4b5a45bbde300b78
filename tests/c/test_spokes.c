/* The march over spokes (march.h, spokes.c: F = 1, unfolding on) against
 * the face walk it replaces there (mfmm_march_loop), bit for bit: the same
 * candidates with the same operands, offered in the same order, so equal
 * rows and equal settled counts. Real meshes with boundaries, a
 * non-manifold one with two components (beetle), unreferenced vertices
 * (bunny), skinny and obtuse faces, and generated ones; plain starts, fixed
 * seeds (the exact start's MFMM_FIXED), max_distance and targets. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "mesh/mesh.h"
#include "mesh/spokes.h"
#include "testutil.h"

typedef struct ws {
    int32_t nv;
    double *T, *key;
    int32_t *vert, *pos;
    uint8_t *label;
} ws;

static ws ws_make(int32_t nv)
{
    ws w = {nv, malloc(nv * sizeof(double)), malloc(nv * sizeof(double)),
            malloc(nv * sizeof(int32_t)), malloc(nv * sizeof(int32_t)), malloc((size_t)nv)};
    assert_non_null(w.T);
    assert_non_null(w.key);
    assert_non_null(w.vert);
    assert_non_null(w.pos);
    assert_non_null(w.label);
    return w;
}

static void ws_free(ws *w)
{
    free(w->T);
    free(w->key);
    free(w->vert);
    free(w->pos);
    free(w->label);
}

/* Case k of a march from internal vertex v: 0 plain; 1 the source and its
 * neighbours fixed at the face walk's values (ref); 2 max_distance; 3
 * targets. Returns the vertices settled; T in w->T. */
static int32_t march(ws *w, const mfmm_march_mesh *m, int32_t v, int k, const double *ref,
                     double max_distance, const int32_t *targets, int n_targets)
{
    mfmm_march_state s;
    memset(&s, 0, sizeof s);
    s.T = w->T;
    s.label = w->label;
    s.heap_key = w->key;
    s.heap_vertex = w->vert;
    s.heap_pos = w->pos;
    s.max_distance = k == 2 ? max_distance : INFINITY;
    s.unfolding = 1;
    mfmm_march_reset(&s, w->nv);
    if (k == 3)
        for (int i = 0; i < n_targets; i++)
            if (!(w->label[targets[i]] & MFMM_TARGET)) {
                w->label[targets[i]] |= MFMM_TARGET;
                s.targets_left++;
            }
    if (k == 1) {
        mfmm_march_seed_fixed(&s, v, 0.0);
        for (int32_t j = m->wedge_offset[v]; j < m->wedge_offset[v + 1]; j++) {
            const mfmm_face *fr = m->faces + MFMM_WEDGE_FACE(m->wedge[j]);
            for (int i = 0; i < 3; i++)
                if (!(w->label[fr->v[i]] & MFMM_FIXED) && isfinite(ref[fr->v[i]]))
                    mfmm_march_seed_fixed(&s, fr->v[i], ref[fr->v[i]]);
        }
    } else {
        mfmm_march_seed(&s, v, 0.0);
    }
    return mfmm_march_run(&s, m);
}

static void check_mesh(const mfmm_mesh *mesh, const char *name)
{
    int32_t nv = mesh->nv;
    mfmm_march_mesh walk = mfmm_mesh_march_view(mesh), sp = walk;
    assert_int_equal(mfmm_mesh_spokes_of(mesh, 1, &sp.spoke_offset, &sp.spokes), MFMM_OK);
    assert_non_null(sp.spokes);
    ws a = ws_make(nv), b = ws_make(nv);
    double *ref = malloc(nv * sizeof *ref);
    assert_non_null(ref);
    int32_t targets[3];
    for (int q = 0; q < 4; q++) {
        int32_t v = (int32_t)(((int64_t)nv * (2 * q + 1)) / 8);
        for (int i = 0; i < 3; i++)
            targets[i] = (v + (i + 1) * nv / 5) % nv;
        /* the plain march's row: the fixed seeds' values, and max_distance */
        march(&a, &walk, v, 0, NULL, 0.0, NULL, 0);
        memcpy(ref, a.T, nv * sizeof *ref);
        double maxd = 0.0;
        for (int32_t i = 0; i < nv; i++)
            if (isfinite(ref[i]) && ref[i] > maxd)
                maxd = ref[i];
        for (int k = 0; k < 4; k++) {
            int32_t na = march(&a, &walk, v, k, ref, 0.4 * maxd, targets, 3);
            int32_t nb = march(&b, &sp, v, k, ref, 0.4 * maxd, targets, 3);
            if (na != nb)
                fail_msg("%s source %d case %d: settled %d (face walk) vs %d (spokes)", name,
                         (int)v, k, (int)na, (int)nb);
            for (int32_t i = 0; i < nv; i++)
                if (memcmp(a.T + i, b.T + i, sizeof(double)) != 0)
                    fail_msg("%s source %d case %d vertex %d: %.17g (face walk) vs %.17g "
                             "(spokes)", name, (int)v, k, (int)i, a.T[i], b.T[i]);
        }
    }
    free(ref);
    ws_free(&a);
    ws_free(&b);
}

static void test_real_meshes(void **state)
{
    (void)state;
    const char *files[] = {"meshes/hand_lowres.obj", "meshes/beetle.obj", "meshes/spot.obj",
                           "meshes/wingnut.obj", "meshes/fertility_FE_10k.off",
                           "meshes/decimated-max.obj", "meshes/camelhead.off",
                           "meshes/stanford-bunny.obj"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        mfmm_mesh *mesh = tm_load_data(files[i], NULL, NULL, NULL);
        check_mesh(mesh, files[i]);
        mfmm_mesh_destroy(mesh);
    }
}

static void test_generated_meshes(void **state)
{
    (void)state;
    mfmm_gen_mesh g[] = {mfmm_gen_grid(30), mfmm_gen_lattice(30, 3.0), mfmm_gen_icosphere(3),
                         mfmm_gen_torus(40, 16, 1.0, 0.3), mfmm_gen_sine(40)};
    const char *names[] = {"grid", "lattice", "icosphere", "torus", "sine"};
    for (size_t i = 0; i < sizeof g / sizeof g[0]; i++) {
        mfmm_mesh *mesh = tm_make(g + i);
        check_mesh(mesh, names[i]);
        mfmm_mesh_destroy(mesh);
        mfmm_gen_free(g + i);
    }
}

/* The memory report's entry for the spokes (the test fails if it has none). */
static size_t spoke_bytes(const mfmm_mesh *mesh)
{
    return tm_memory_entry(mesh, "spokes (once built)");
}

/* The memory report names the spokes once the marches have built them
 * (MFMM_SPOKES_AFTER full marches). */
static void test_memory_report(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_icosphere(2);
    mfmm_mesh *mesh = tm_make(&g);
    assert_int_equal(spoke_bytes(mesh), 0);
    double *d = malloc((size_t)g.nv * sizeof *d);
    mfmm_solver *solver = NULL;
    assert_int_equal(mfmm_solver_create(mesh, &solver), MFMM_OK);
    mfmm_source src = tm_vertex_source(0);
    for (int q = 0; q <= MFMM_SPOKES_AFTER; q++) {
        assert_int_equal(spoke_bytes(mesh), 0);
        assert_int_equal(mfmm_solve(solver, &src, 1, NULL, d, NULL), MFMM_OK);
    }
    /* a closed fan's wrap shares its spoke, so a closed genus-0 mesh holds
     * one spoke per neighbour, 2E = 6 nv - 12 (Euler), one per virtual
     * edge, and the offsets (nv + 1) */
    size_t n_spokes = 6 * (size_t)g.nv - 12 + (size_t)mesh->n_virts;
    assert_int_equal(spoke_bytes(mesh),
                     n_spokes * sizeof(mfmm_spoke) + ((size_t)g.nv + 1) * sizeof(int32_t));
    mfmm_solver_destroy(solver);
    free(d);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

/* A mesh made with spokes = 0 (memory first) never builds them, and its
 * solves (public API, default exact start) equal the default mesh's bit for
 * bit: the face walk is the same march. */
static void test_spokes_off(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_sine(40);
    mfmm_mesh_options mo;
    mfmm_mesh_options_init(&mo);
    assert_int_equal(mo.spokes, 1);
    mo.spokes = 0;
    mfmm_mesh *on = tm_make(&g), *off = NULL;
    assert_int_equal(mfmm_mesh_create(g.V, g.nv, g.F, g.nf, &mo, &off, NULL), MFMM_OK);
    const int32_t *offset = (const int32_t *)1;
    const mfmm_spoke *spokes = (const mfmm_spoke *)1;
    assert_int_equal(mfmm_mesh_spokes_of(off, 1, &offset, &spokes), MFMM_OK);
    assert_null(offset);
    assert_null(spokes);
    double *d_on = malloc((size_t)g.nv * sizeof *d_on), *d_off = malloc((size_t)g.nv * sizeof *d_off);
    assert_non_null(d_on);
    assert_non_null(d_off);
    mfmm_solver *s_on = NULL, *s_off = NULL;
    assert_int_equal(mfmm_solver_create(on, &s_on), MFMM_OK);
    assert_int_equal(mfmm_solver_create(off, &s_off), MFMM_OK);
    /* the default mesh marches without its spokes until MFMM_SPOKES_AFTER
     * full marches, then builds them: rows equal throughout */
    for (int q = 0; q < MFMM_SPOKES_AFTER + 3; q++) {
        mfmm_source src = tm_vertex_source((int32_t)(((int64_t)g.nv * (2 * q + 1)) / 24));
        assert_int_equal(mfmm_solve(s_on, &src, 1, NULL, d_on, NULL), MFMM_OK);
        assert_int_equal(mfmm_solve(s_off, &src, 1, NULL, d_off, NULL), MFMM_OK);
        assert_memory_equal(d_on, d_off, (size_t)g.nv * sizeof *d_on);
        if (q == 0)
            assert_int_equal(spoke_bytes(on), 0);
    }
    assert_int_equal(spoke_bytes(off), 0);
    assert_true(spoke_bytes(on) > 0);
    assert_int_equal(mfmm_mesh_spokes_of(on, 1, &offset, &spokes), MFMM_OK);
    assert_non_null(spokes);
    mfmm_solver_destroy(s_on);
    mfmm_solver_destroy(s_off);
    free(d_on);
    free(d_off);
    mfmm_mesh_destroy(on);
    mfmm_mesh_destroy(off);
    mfmm_gen_free(&g);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_real_meshes),
        cmocka_unit_test(test_generated_meshes),
        cmocka_unit_test(test_memory_report),
        cmocka_unit_test(test_spokes_off),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
