/* The struct_size rules of meshfmm.h ("conventions and ABI policy"), as a
 * program built against an older, smaller struct meets them:
 *   - output structs: the library writes no more than the caller's
 *     struct_size (guard bytes after it stay untouched), fills that prefix
 *     as it fills the whole struct, and reports the bytes written;
 *   - option structs: a smaller struct_size is read (from a heap block of
 *     exactly that size, so a sanitizer build sees any read past it), and
 *     the fields past it take their defaults;
 *   - a struct_size below sizeof(size_t), or an option struct larger than
 *     the library's, is MFMM_ERR_BAD_ARGUMENT. */
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <setjmp.h>
#include <cmocka.h>

#include "testutil.h"
#include "io/generate.h"

#define GUARD 0xA5
#define PAD 64

/* A buffer holding an output struct of `size` bytes (struct_size = size)
 * followed by guard bytes, for a library struct of `known` bytes. */
typedef struct {
    unsigned char bytes[512];
} guarded;

static void guarded_init(guarded *g, size_t size)
{
    memset(g->bytes, GUARD, sizeof g->bytes);
    memcpy(g->bytes, &size, sizeof size);
}

/* Checks the guard after `written` bytes, that struct_size reads `written`,
 * and that the prefix after struct_size equals the full struct's. */
static void guarded_check(const guarded *g, size_t written, const void *full)
{
    size_t s;
    memcpy(&s, g->bytes, sizeof s);
    assert_int_equal(s, written);
    for (size_t i = written; i < sizeof g->bytes; i++)
        if (g->bytes[i] != GUARD)
            fail_msg("byte %zu past struct_size %zu was written", i, written);
    assert_memory_equal(g->bytes + sizeof s, (const unsigned char *)full + sizeof s,
                        written - sizeof s);
}

/* The sizes an older caller might have: struct_size alone, a field boundary
 * inside, the whole struct, and a newer caller's larger struct. */
static void sizes_of(size_t known, size_t middle, size_t out[4])
{
    out[0] = sizeof(size_t);
    out[1] = middle;
    out[2] = known;
    out[3] = known + 16;
}

static void test_mesh_info(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_grid(6);
    mfmm_mesh *mesh = tm_make(&g);
    mfmm_mesh_info full = {.struct_size = sizeof full};
    assert_int_equal(mfmm_mesh_get_info(mesh, &full), MFMM_OK);
    assert_int_equal(full.struct_size, sizeof full);
    assert_int_equal(full.n_vertices, g.nv);
    size_t sizes[4];
    sizes_of(sizeof full, offsetof(mfmm_mesh_info, n_obtuse_corners), sizes);
    for (int i = 0; i < 4; i++) {
        guarded b;
        guarded_init(&b, sizes[i]);
        assert_int_equal(mfmm_mesh_get_info(mesh, (mfmm_mesh_info *)(void *)b.bytes), MFMM_OK);
        guarded_check(&b, sizes[i] < sizeof full ? sizes[i] : sizeof full, &full);
    }
    /* a caller compiled before the coincident-vertex counts: up to bbox_diagonal */
    {
        size_t old = offsetof(mfmm_mesh_info, n_coincident_vertices);
        guarded o;
        guarded_init(&o, old);
        assert_int_equal(mfmm_mesh_get_info(mesh, (mfmm_mesh_info *)(void *)o.bytes), MFMM_OK);
        guarded_check(&o, old, &full);
    }
    assert_int_equal(full.n_coincident_vertices, 0);
    assert_int_equal(full.n_welded_components, full.n_components);
    guarded b;
    guarded_init(&b, 4);
    assert_int_equal(mfmm_mesh_get_info(mesh, (mfmm_mesh_info *)(void *)b.bytes),
                     MFMM_ERR_BAD_ARGUMENT);
    for (size_t i = sizeof(size_t); i < sizeof b.bytes; i++)
        assert_int_equal(b.bytes[i], GUARD);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

static void test_solve_info(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_grid(6);
    mfmm_mesh *mesh = tm_make(&g);
    mfmm_solver *solver = NULL;
    assert_int_equal(mfmm_solver_create(mesh, &solver), MFMM_OK);
    double *d = malloc((size_t)g.nv * sizeof *d);
    mfmm_source s = tm_vertex_source(0);
    assert_int_equal(mfmm_solve(solver, &s, 1, NULL, d, NULL), MFMM_OK);
    mfmm_solve_info full = {.struct_size = sizeof full};
    assert_int_equal(mfmm_solver_get_info(solver, &full), MFMM_OK);
    size_t sizes[4];
    sizes_of(sizeof full, sizeof(size_t), sizes);
    for (int i = 0; i < 4; i++) {
        guarded b;
        guarded_init(&b, sizes[i]);
        assert_int_equal(mfmm_solver_get_info(solver, (mfmm_solve_info *)(void *)b.bytes),
                         MFMM_OK);
        guarded_check(&b, sizes[i] < sizeof full ? sizes[i] : sizeof full, &full);
    }
    guarded b;
    guarded_init(&b, 0);
    assert_int_equal(mfmm_solver_get_info(solver, (mfmm_solve_info *)(void *)b.bytes),
                     MFMM_ERR_BAD_ARGUMENT);
    free(d);
    mfmm_solver_destroy(solver);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

static void test_exact_info(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_grid(6);
    mfmm_mesh *mesh = tm_make(&g);
    mfmm_exact_solver *solver = NULL;
    assert_int_equal(mfmm_exact_solver_create(mesh, &solver), MFMM_OK);
    double *d = malloc((size_t)g.nv * sizeof *d);
    mfmm_source s = tm_vertex_source(3);
    mfmm_exact_info full = {.struct_size = sizeof full};
    assert_int_equal(mfmm_solve_exact(solver, &s, 1, NULL, d, &full, NULL), MFMM_OK);
    assert_true(full.n_windows > 0);
    size_t sizes[4];
    sizes_of(sizeof full, offsetof(mfmm_exact_info, peak_windows), sizes);
    for (int i = 0; i < 4; i++) {
        guarded b;
        guarded_init(&b, sizes[i]);
        assert_int_equal(
            mfmm_solve_exact(solver, &s, 1, NULL, d, (mfmm_exact_info *)(void *)b.bytes, NULL),
            MFMM_OK);
        guarded_check(&b, sizes[i] < sizeof full ? sizes[i] : sizeof full, &full);
    }
    guarded b;
    guarded_init(&b, 3);
    mfmm_error err;
    assert_int_equal(
        mfmm_solve_exact(solver, &s, 1, NULL, d, (mfmm_exact_info *)(void *)b.bytes, &err),
        MFMM_ERR_BAD_ARGUMENT);
    assert_non_null(strstr(err.message, "struct_size"));
    for (size_t i = sizeof(size_t); i < sizeof b.bytes; i++)
        assert_int_equal(b.bytes[i], GUARD);
    free(d);
    mfmm_exact_solver_destroy(solver);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

static void test_matrix_info(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_grid(6);
    mfmm_mesh *mesh = tm_make(&g);
    int32_t src[3] = {0, 7, 20};
    float *out = malloc(3 * (size_t)g.nv * sizeof *out);
    mfmm_matrix_options o;
    mfmm_matrix_options_init(&o);
    o.backend = MFMM_BACKEND_SERIAL;
    o.out = out;
    mfmm_matrix_info full = {.struct_size = sizeof full};
    assert_int_equal(mfmm_distance_matrix(mesh, src, 3, &o, &full, NULL), MFMM_OK);
    assert_int_equal(full.backend_used, MFMM_BACKEND_SERIAL);
    assert_string_equal(full.backend_reason, "");
    assert_true(full.vertices_settled >= 3 * (int64_t)g.nv);
    /* NULL: no info */
    assert_int_equal(mfmm_distance_matrix(mesh, src, 3, &o, NULL, NULL), MFMM_OK);
    size_t sizes[4];
    sizes_of(sizeof full, offsetof(mfmm_matrix_info, vertices_settled), sizes);
    for (int i = 0; i < 4; i++) {
        guarded b;
        guarded_init(&b, sizes[i]);
        assert_int_equal(
            mfmm_distance_matrix(mesh, src, 3, &o, (mfmm_matrix_info *)(void *)b.bytes, NULL),
            MFMM_OK);
        guarded_check(&b, sizes[i] < sizeof full ? sizes[i] : sizeof full, &full);
    }
    /* on failure too, within the caller's size */
    guarded b;
    guarded_init(&b, offsetof(mfmm_matrix_info, backend_reason));
    assert_int_equal(
        mfmm_distance_matrix(mesh, src, 0, &o, (mfmm_matrix_info *)(void *)b.bytes, NULL),
        MFMM_ERR_BAD_COUNT);
    for (size_t i = offsetof(mfmm_matrix_info, backend_reason); i < sizeof b.bytes; i++)
        assert_int_equal(b.bytes[i], GUARD);
    guarded_init(&b, 1);
    assert_int_equal(
        mfmm_distance_matrix(mesh, src, 3, &o, (mfmm_matrix_info *)(void *)b.bytes, NULL),
        MFMM_ERR_BAD_ARGUMENT);
    free(out);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

/* A copy of an initialised option struct cut to its first `size` bytes, in
 * a heap block of exactly that size. */
static void *older(const void *full, size_t size)
{
    void *p = malloc(size);
    assert_non_null(p);
    memcpy(p, full, size);
    memcpy(p, &size, sizeof size);
    return p;
}

static void test_smaller_option_structs(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_grid(8);
    mfmm_error err;

    /* mesh options: spokes past the caller's struct keeps its default */
    mfmm_mesh_options mo;
    mfmm_mesh_options_init(&mo);
    mo.max_unfold_steps = 3;
    void *mo_old = older(&mo, offsetof(mfmm_mesh_options, spokes));
    mfmm_mesh *mesh = NULL;
    assert_int_equal(mfmm_mesh_create(g.V, g.nv, g.F, g.nf, mo_old, &mesh, &err), MFMM_OK);
    free(mo_old);
    mfmm_mesh_destroy(mesh);
    mesh = tm_make(&g);
    int32_t nv = g.nv;
    double *ref = malloc((size_t)nv * sizeof *ref), *d = malloc((size_t)nv * sizeof *d);

    /* solve options without exact_start_radius: the default radius */
    mfmm_solver *solver = NULL;
    assert_int_equal(mfmm_solver_create(mesh, &solver), MFMM_OK);
    mfmm_source s = tm_vertex_source(10);
    assert_int_equal(mfmm_solve(solver, &s, 1, NULL, ref, NULL), MFMM_OK);
    mfmm_solve_options so;
    mfmm_solve_options_init(&so);
    so.exact_start_radius = 0.0; /* not in the older struct: not read */
    void *so_old = older(&so, offsetof(mfmm_solve_options, exact_start_radius));
    assert_int_equal(mfmm_solve(solver, &s, 1, so_old, d, &err), MFMM_OK);
    assert_memory_equal(d, ref, (size_t)nv * sizeof *d);
    free(so_old);
    /* without method: the march, whatever the newer field would say */
    mfmm_solve_options_init(&so);
    so.method = MFMM_METHOD_WINDOWS;
    so_old = older(&so, offsetof(mfmm_solve_options, method));
    assert_int_equal(mfmm_solve(solver, &s, 1, so_old, d, &err), MFMM_OK);
    assert_memory_equal(d, ref, (size_t)nv * sizeof *d);
    free(so_old);
    so_old = older(&so, sizeof(size_t)); /* struct_size alone: every default */
    assert_int_equal(mfmm_solve(solver, &s, 1, so_old, d, &err), MFMM_OK);
    assert_memory_equal(d, ref, (size_t)nv * sizeof *d);
    free(so_old);
    mfmm_solve_options_init(&so);
    so.struct_size = sizeof so + 8;
    assert_int_equal(mfmm_solve(solver, &s, 1, &so, d, &err), MFMM_ERR_BAD_ARGUMENT);
    so.struct_size = 2;
    assert_int_equal(mfmm_solve(solver, &s, 1, &so, d, &err), MFMM_ERR_BAD_ARGUMENT);

    /* path options without straighten: straightened, as by default */
    assert_int_equal(mfmm_solve(solver, &s, 1, NULL, ref, NULL), MFMM_OK);
    mfmm_source target = tm_vertex_source(nv - 1);
    mfmm_surface_point pa[256], pb[256];
    int32_t na = 0, nb = 0;
    double la = 0, lb = 0;
    assert_int_equal(mfmm_trace_path(mesh, ref, &target, NULL, pa, 256, &na, &la, &err), MFMM_OK);
    mfmm_path_options po;
    mfmm_path_options_init(&po);
    po.straighten = 0;
    void *po_old = older(&po, offsetof(mfmm_path_options, straighten));
    assert_int_equal(mfmm_trace_path(mesh, ref, &target, po_old, pb, 256, &nb, &lb, &err),
                     MFMM_OK);
    assert_int_equal(na, nb);
    assert_true(la == lb);
    free(po_old);
    mfmm_solver_destroy(solver);

    /* exact options without interrupt and user */
    mfmm_exact_solver *ex = NULL;
    assert_int_equal(mfmm_exact_solver_create(mesh, &ex), MFMM_OK);
    assert_int_equal(mfmm_solve_exact(ex, &s, 1, NULL, ref, NULL, NULL), MFMM_OK);
    mfmm_exact_options eo;
    mfmm_exact_options_init(&eo);
    void *eo_old = older(&eo, offsetof(mfmm_exact_options, interrupt));
    assert_int_equal(mfmm_solve_exact(ex, &s, 1, eo_old, d, NULL, &err), MFMM_OK);
    assert_memory_equal(d, ref, (size_t)nv * sizeof *d);
    free(eo_old);
    mfmm_exact_solver_destroy(ex);

    /* matrix options without opencl and opencl_options, then without method */
    int32_t src[2] = {0, 33};
    double *rows = malloc(2 * (size_t)nv * sizeof *rows);
    double *rref = malloc(2 * (size_t)nv * sizeof *rref);
    mfmm_matrix_options o;
    mfmm_matrix_options_init(&o);
    o.backend = MFMM_BACKEND_SERIAL;
    o.dtype = MFMM_FLOAT64;
    o.out = rref;
    assert_int_equal(mfmm_distance_matrix(mesh, src, 2, &o, NULL, &err), MFMM_OK);
    o.out = rows;
    void *o_old = older(&o, offsetof(mfmm_matrix_options, opencl));
    mfmm_matrix_info info = {.struct_size = sizeof info};
    assert_int_equal(mfmm_distance_matrix(mesh, src, 2, o_old, &info, &err), MFMM_OK);
    assert_int_equal(info.backend_used, MFMM_BACKEND_SERIAL);
    assert_memory_equal(rows, rref, 2 * (size_t)nv * sizeof *rows);
    free(o_old);
    o.method = MFMM_METHOD_WINDOWS; /* not in the older struct: the march */
    o_old = older(&o, offsetof(mfmm_matrix_options, method));
    assert_int_equal(mfmm_distance_matrix(mesh, src, 2, o_old, &info, &err), MFMM_OK);
    assert_memory_equal(rows, rref, 2 * (size_t)nv * sizeof *rows);
    free(o_old);
    o.method = MFMM_METHOD_FMM;
    o.struct_size = sizeof o + 8;
    assert_int_equal(mfmm_distance_matrix(mesh, src, 2, &o, &info, &err), MFMM_ERR_BAD_ARGUMENT);
    assert_non_null(strstr(err.message, "mfmm_matrix_options.struct_size"));

    /* OpenCL options: struct_size alone is read (the defaults); whether a
     * context comes of it depends on the machine, but it is not refused */
    mfmm_opencl_options co;
    mfmm_opencl_options_init(&co);
    void *co_old = older(&co, sizeof(size_t));
    mfmm_opencl_context *ctx = NULL;
    mfmm_status cst = mfmm_opencl_context_create(co_old, &ctx, &err);
    assert_int_not_equal(cst, MFMM_ERR_BAD_ARGUMENT);
    mfmm_opencl_context_destroy(ctx);
    free(co_old);

    free(rows);
    free(rref);
    free(ref);
    free(d);
    mfmm_mesh_destroy(mesh);
    mfmm_gen_free(&g);
}

int main(void)
{
    /* an empty vendors folder: no OpenCL platform in this process */
    char dir[] = "/tmp/mfmm_abi_icd_XXXXXX";
    if (!mkdtemp(dir))
        return 1;
    setenv("OCL_ICD_VENDORS", dir, 1);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mesh_info),
        cmocka_unit_test(test_solve_info),
        cmocka_unit_test(test_exact_info),
        cmocka_unit_test(test_matrix_info),
        cmocka_unit_test(test_smaller_option_structs),
    };
    int rc = cmocka_run_group_tests(tests, NULL, NULL);
    rmdir(dir);
    return rc;
}
