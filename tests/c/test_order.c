/* Vertex and face renumbering: the library numbers vertices
 * internally by position, and faces along that order, so a mesh given with
 * its vertices and faces in another order is the same mesh inside. Per input
 * vertex, every public result (distances with and without costs, per vertex
 * and per face, from vertex and face sources, matrix rows dense / float32 /
 * targets / sparse / per-face cost, paths and their face ids, exact
 * distances) must then equal the unshuffled mesh's, permuted back, bit for
 * bit; and the renumbering must not depend on anything but the input. */
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
#include "io/generate.h"

/* g's vertices, plus one unreferenced vertex, and its faces in a shuffled
 * order (each face's corners kept in order): shuffled vertex i is original
 * vertex perm[i], shuffled face i original face fperm[i]; inv, finv the
 * inverses. */
typedef struct shuffled {
    mfmm_gen_mesh orig, shuf;
    int32_t *perm, *inv, *fperm, *finv;
} shuffled;

static void shuffle_ids(int32_t *perm, int32_t n, uint32_t seed)
{
    for (int32_t i = 0; i < n; i++)
        perm[i] = i;
    for (int32_t i = n - 1; i > 0; i--) { /* Fisher-Yates, a fixed LCG */
        seed = seed * 1664525u + 1013904223u;
        int32_t j = (int32_t)((seed >> 8) % (uint32_t)(i + 1));
        int32_t t = perm[i];
        perm[i] = perm[j];
        perm[j] = t;
    }
}

static shuffled shuffle(mfmm_gen_mesh g, uint32_t seed)
{
    shuffled s;
    int32_t nv = g.nv + 1;
    s.orig.nv = nv;
    s.orig.nf = g.nf;
    s.orig.V = malloc(3 * (size_t)nv * sizeof(double));
    s.orig.F = g.F;
    s.shuf.nv = nv;
    s.shuf.nf = g.nf;
    s.shuf.V = malloc(3 * (size_t)nv * sizeof(double));
    s.shuf.F = malloc(3 * (size_t)g.nf * sizeof(int32_t));
    s.perm = malloc((size_t)nv * sizeof(int32_t));
    s.inv = malloc((size_t)nv * sizeof(int32_t));
    s.fperm = malloc((size_t)g.nf * sizeof(int32_t));
    s.finv = malloc((size_t)g.nf * sizeof(int32_t));
    assert_true(s.orig.V && s.shuf.V && s.shuf.F && s.perm && s.inv && s.fperm && s.finv);
    memcpy(s.orig.V, g.V, 3 * (size_t)g.nv * sizeof(double));
    s.orig.V[3 * g.nv] = 0.25, s.orig.V[3 * g.nv + 1] = 0.5, s.orig.V[3 * g.nv + 2] = 2.0;
    free(g.V);
    shuffle_ids(s.perm, nv, seed);
    shuffle_ids(s.fperm, g.nf, seed ^ 0x5eedu);
    for (int32_t i = 0; i < nv; i++) {
        s.inv[s.perm[i]] = i;
        memcpy(s.shuf.V + 3 * i, s.orig.V + 3 * s.perm[i], 3 * sizeof(double));
    }
    for (int32_t f = 0; f < g.nf; f++) {
        s.finv[s.fperm[f]] = f;
        for (int k = 0; k < 3; k++)
            s.shuf.F[3 * f + k] = s.inv[s.orig.F[3 * s.fperm[f] + k]];
    }
    return s;
}

static void shuffled_free(shuffled *s)
{
    mfmm_gen_free(&s->orig);
    mfmm_gen_free(&s->shuf);
    free(s->perm);
    free(s->inv);
    free(s->fperm);
    free(s->finv);
}

/* Path a (original ids) equals path b (shuffled ids): faces mapped, the
 * rest bit for bit. */
static void assert_same_path(const shuffled *s, const mfmm_surface_point *a,
                             const mfmm_surface_point *b, int32_t n)
{
    for (int32_t i = 0; i < n; i++) {
        if (a[i].face != s->fperm[b[i].face])
            fail_msg("path point %d: face %d, shuffled %d (original %d)", (int)i, (int)a[i].face,
                     (int)b[i].face, (int)s->fperm[b[i].face]);
        assert_memory_equal(a[i].bary, b[i].bary, sizeof a[i].bary);
        assert_memory_equal(a[i].xyz, b[i].xyz, sizeof a[i].xyz);
    }
}

/* a[perm[i]] == b[i] bit for bit, n values of `size` bytes */
static void assert_permuted(const void *a, const void *b, const int32_t *perm, int32_t n,
                            size_t size, const char *what)
{
    for (int32_t i = 0; i < n; i++)
        if (memcmp((const char *)a + (size_t)perm[i] * size, (const char *)b + (size_t)i * size,
                   size) != 0)
            fail_msg("%s: shuffled vertex %d (original %d) differs", what, (int)i, (int)perm[i]);
}

static void check_mesh(mfmm_gen_mesh g, uint32_t seed)
{
    shuffled s = shuffle(g, seed);
    int32_t nv = s.orig.nv, nf = s.orig.nf;
    mfmm_mesh *ma = tm_make(&s.orig), *mb = tm_make(&s.shuf);
    mfmm_solver *sa = NULL, *sb = NULL;
    assert_int_equal(mfmm_solver_create(ma, &sa), MFMM_OK);
    assert_int_equal(mfmm_solver_create(mb, &sb), MFMM_OK);
    double *da = malloc((size_t)nv * sizeof *da), *db = malloc((size_t)nv * sizeof *db);
    double *ca = malloc((size_t)nv * sizeof *ca), *cb = malloc((size_t)nv * sizeof *cb);
    double *fc = malloc((size_t)nf * sizeof *fc), *fcb = malloc((size_t)nf * sizeof *fcb);
    assert_true(da && db && ca && cb && fc && fcb);
    for (int32_t v = 0; v < nv; v++)
        ca[v] = 1.0 + 0.5 * sin(3.0 * s.orig.V[3 * v] + 2.0 * s.orig.V[3 * v + 1]);
    for (int32_t i = 0; i < nv; i++)
        cb[i] = ca[s.perm[i]];
    for (int32_t f = 0; f < nf; f++)
        fc[f] = 1.0 + (f % 3);
    for (int32_t f = 0; f < nf; f++)
        fcb[f] = fc[s.fperm[f]];

    /* single solves: a vertex source with targets, a face source, costs */
    int32_t src = s.orig.F[3 * (nf / 2)], tgt[2] = {s.orig.F[0], s.orig.F[3 * nf - 1]};
    int32_t tgt_b[2] = {s.inv[tgt[0]], s.inv[tgt[1]]};
    mfmm_source va[2] = {tm_vertex_source(src), {0, nf / 3, {0.2, 0.3, 0.5}, 0.1}};
    mfmm_source vb[2] = {tm_vertex_source(s.inv[src]), va[1]};
    vb[1].face = s.finv[va[1].face];
    for (int variant = 0; variant < 5; variant++) {
        mfmm_solve_options oa, ob;
        mfmm_solve_options_init(&oa);
        if (variant == 1)
            oa.cost = ca, oa.cost_location = MFMM_COST_PER_VERTEX;
        if (variant == 2)
            oa.cost = fc, oa.cost_location = MFMM_COST_PER_FACE;
        if (variant == 3)
            oa.targets = tgt, oa.n_targets = 2, oa.unfolding = 0;
        if (variant == 4)
            oa.max_distance = 0.3;
        ob = oa;
        if (variant == 1)
            ob.cost = cb;
        if (variant == 2)
            ob.cost = fcb;
        if (variant == 3)
            ob.targets = tgt_b;
        assert_int_equal(mfmm_solve(sa, va, 2, &oa, da, NULL), MFMM_OK);
        assert_int_equal(mfmm_solve(sb, vb, 2, &ob, db, NULL), MFMM_OK);
        assert_permuted(da, db, s.perm, nv, sizeof *da, "mfmm_solve");
        assert_true(isinf(da[nv - 1])); /* the unreferenced vertex */

        /* a path to a vertex, with the sources and the cost */
        mfmm_path_options pa, pb;
        mfmm_path_options_init(&pa);
        pa.sources = va, pa.n_sources = 2;
        pa.cost = oa.cost, pa.cost_location = oa.cost_location;
        pb = pa;
        pb.sources = vb, pb.cost = ob.cost;
        int32_t t = tgt[1];
        if (!(da[t] < INFINITY))
            t = src;
        mfmm_source ta = tm_vertex_source(t), tb = tm_vertex_source(s.inv[t]);
        mfmm_surface_point pts_a[4096], pts_b[4096];
        int32_t na = 0, nb = 0;
        double la = 0, lb = 0;
        assert_int_equal(mfmm_trace_path(ma, da, &ta, &pa, pts_a, 4096, &na, &la, NULL), MFMM_OK);
        assert_int_equal(mfmm_trace_path(mb, db, &tb, &pb, pts_b, 4096, &nb, &lb, NULL), MFMM_OK);
        assert_int_equal(na, nb);
        assert_same_path(&s, pts_a, pts_b, na);
        assert_memory_equal(&la, &lb, sizeof la);

        /* and to a point inside a face (face ids in and out) */
        int32_t ft = s.orig.F[3 * (nf - 1)] == t ? nf - 1 : 0;
        mfmm_source fa = {0, ft, {0.3, 0.3, 0.4}, 0.0}, fb = fa;
        fb.face = s.finv[ft];
        mfmm_status sta = mfmm_trace_path(ma, da, &fa, &pa, pts_a, 4096, &na, &la, NULL);
        mfmm_status stb = mfmm_trace_path(mb, db, &fb, &pb, pts_b, 4096, &nb, &lb, NULL);
        assert_int_equal(sta, stb);
        if (sta == MFMM_OK) {
            assert_int_equal(na, nb);
            assert_same_path(&s, pts_a, pts_b, na);
            assert_memory_equal(&la, &lb, sizeof la);
        }
    }

    /* exact distances */
    mfmm_exact_solver *ea = NULL, *eb = NULL;
    assert_int_equal(mfmm_exact_solver_create(ma, &ea), MFMM_OK);
    assert_int_equal(mfmm_exact_solver_create(mb, &eb), MFMM_OK);
    assert_int_equal(mfmm_solve_exact(ea, va, 2, NULL, da, NULL, NULL), MFMM_OK);
    assert_int_equal(mfmm_solve_exact(eb, vb, 2, NULL, db, NULL, NULL), MFMM_OK);
    assert_permuted(da, db, s.perm, nv, sizeof *da, "mfmm_solve_exact");
    mfmm_exact_solver_destroy(ea);
    mfmm_exact_solver_destroy(eb);

    /* matrix rows: float64 and float32 full rows, target columns, serial
     * and threads (rows in the caller's order, columns permuted back) */
    enum { NS = 7 };
    int32_t rs_a[NS], rs_b[NS];
    for (int i = 0; i < NS; i++) {
        rs_a[i] = (int32_t)(((int64_t)i * 7919) % (nv - 1));
        rs_b[i] = s.inv[rs_a[i]];
    }
    double *ra = malloc((size_t)NS * nv * sizeof *ra), *rb = malloc((size_t)NS * nv * sizeof *rb);
    assert_true(ra && rb);
    for (int kind = 0; kind < 6; kind++) {
        mfmm_matrix_options oa, ob;
        mfmm_matrix_options_init(&oa);
        oa.backend = kind == 1 ? MFMM_BACKEND_THREADS : MFMM_BACKEND_SERIAL;
        oa.n_threads = 2;
        oa.dtype = kind == 2 ? MFMM_FLOAT32 : MFMM_FLOAT64;
        if (kind == 3)
            oa.targets = tgt, oa.n_targets = 2;
        if (kind == 4)
            oa.cost = ca, oa.cost_location = MFMM_COST_PER_VERTEX;
        if (kind == 5)
            oa.cost = fc, oa.cost_location = MFMM_COST_PER_FACE;
        ob = oa;
        if (kind == 3)
            ob.targets = tgt_b;
        if (kind == 4)
            ob.cost = cb;
        if (kind == 5)
            ob.cost = fcb;
        oa.out = ra;
        ob.out = rb;
        assert_int_equal(mfmm_distance_matrix(ma, rs_a, NS, &oa, NULL, NULL), MFMM_OK);
        assert_int_equal(mfmm_distance_matrix(mb, rs_b, NS, &ob, NULL, NULL), MFMM_OK);
        size_t esz = kind == 2 ? sizeof(float) : sizeof(double);
        for (int i = 0; i < NS; i++) {
            if (kind == 3) {
                assert_memory_equal((char *)ra + (size_t)i * 2 * esz,
                                    (char *)rb + (size_t)i * 2 * esz, 2 * esz);
                continue;
            }
            assert_permuted((char *)ra + (size_t)i * nv * esz, (char *)rb + (size_t)i * nv * esz,
                            s.perm, nv, esz, "matrix row");
        }
    }
    free(ra);
    free(rb);

    mfmm_solver_destroy(sa);
    mfmm_solver_destroy(sb);
    mfmm_mesh_destroy(ma);
    mfmm_mesh_destroy(mb);
    free(da);
    free(db);
    free(ca);
    free(cb);
    free(fc);
    free(fcb);
    shuffled_free(&s);
}

static void test_shuffled_lattice(void **state)
{
    (void)state;
    check_mesh(mfmm_gen_lattice(12, 3.0), 12345u); /* obtuse corners: virtual edges */
}

static void test_shuffled_sine(void **state)
{
    (void)state;
    check_mesh(mfmm_gen_sine(16), 777u);
}

/* Sparse rows: column ids are the caller's, ascending, values permuted back. */
typedef struct sparse_rows {
    int32_t n[8];
    int32_t idx[8][400];
    double val[8][400];
} sparse_rows;

static int collect_sparse(void *user, int32_t first, int32_t n, const int64_t *indptr,
                          const int32_t *indices, const void *values)
{
    sparse_rows *r = user;
    for (int32_t i = 0; i < n; i++) {
        int32_t k = (int32_t)(indptr[i + 1] - indptr[i]);
        assert_true(first + i < 8 && k <= 400);
        r->n[first + i] = k;
        memcpy(r->idx[first + i], indices + indptr[i], (size_t)k * sizeof(int32_t));
        memcpy(r->val[first + i], (const double *)values + indptr[i], (size_t)k * sizeof(double));
        for (int32_t j = 1; j < k; j++)
            assert_true(r->idx[first + i][j - 1] < r->idx[first + i][j]);
    }
    return 0;
}

static void test_shuffled_sparse(void **state)
{
    (void)state;
    shuffled s = shuffle(mfmm_gen_sine(16), 99u);
    mfmm_mesh *ma = tm_make(&s.orig), *mb = tm_make(&s.shuf);
    int32_t src_a[8], src_b[8];
    for (int i = 0; i < 8; i++) {
        src_a[i] = (int32_t)((i * 37) % (s.orig.nv - 1));
        src_b[i] = s.inv[src_a[i]];
    }
    static sparse_rows ra, rb;
    mfmm_matrix_options oa, ob;
    mfmm_matrix_options_init(&oa);
    oa.dtype = MFMM_FLOAT64;
    oa.backend = MFMM_BACKEND_THREADS;
    oa.max_distance = 0.3;
    oa.on_sparse = collect_sparse;
    ob = oa;
    oa.user = &ra;
    ob.user = &rb;
    assert_int_equal(mfmm_distance_matrix(ma, src_a, 8, &oa, NULL, NULL), MFMM_OK);
    assert_int_equal(mfmm_distance_matrix(mb, src_b, 8, &ob, NULL, NULL), MFMM_OK);
    for (int i = 0; i < 8; i++) {
        assert_int_equal(ra.n[i], rb.n[i]);
        assert_true(ra.n[i] > 5);
        for (int32_t j = 0; j < rb.n[i]; j++) { /* find b's column in a's row */
            int32_t col = s.perm[rb.idx[i][j]], k = 0;
            while (k < ra.n[i] && ra.idx[i][k] != col)
                k++;
            assert_true(k < ra.n[i]);
            assert_memory_equal(&ra.val[i][k], &rb.val[i][j], sizeof(double));
        }
    }
    mfmm_mesh_destroy(ma);
    mfmm_mesh_destroy(mb);
    shuffled_free(&s);
}

/* The same input gives the same internal order and arrays, every time. */
static void test_deterministic(void **state)
{
    (void)state;
    mfmm_gen_mesh g = mfmm_gen_lattice(10, 3.0);
    mfmm_mesh *a = tm_make(&g), *b = tm_make(&g);
    assert_memory_equal(a->to_internal, b->to_internal, (size_t)g.nv * sizeof(int32_t));
    for (int32_t i = 0; i < g.nf; i++)
        assert_memory_equal(a->face_records[i].v, b->face_records[i].v, sizeof a->face_records[i].v);
    assert_memory_equal(a->xyz, b->xyz, 3 * (size_t)g.nv * sizeof(double));
    for (int32_t v = 0; v < g.nv; v++) {
        assert_int_equal(a->to_external[a->to_internal[v]], v);
        assert_memory_equal(a->xyz + 3 * a->to_internal[v], g.V + 3 * v, 3 * sizeof(double));
    }
    /* faces: a permutation along the vertex order, corners kept in order */
    for (int32_t f = 0; f < g.nf; f++) {
        int32_t i = a->face_to_internal[f];
        assert_int_equal(a->face_to_external[i], f);
        for (int k = 0; k < 3; k++)
            assert_int_equal(a->face_records[i].v[k], a->to_internal[g.F[3 * f + k]]);
        if (i > 0) {
            int32_t lo = a->face_records[i].v[0], lo_prev = a->face_records[i - 1].v[0];
            for (int k = 1; k < 3; k++) {
                lo = a->face_records[i].v[k] < lo ? a->face_records[i].v[k] : lo;
                lo_prev = a->face_records[i - 1].v[k] < lo_prev ? a->face_records[i - 1].v[k] : lo_prev;
            }
            assert_true(lo_prev <= lo);
        }
    }
    mfmm_mesh_destroy(a);
    mfmm_mesh_destroy(b);
    mfmm_gen_free(&g);
}

/* Each vertex's corner list in fan order (src/mesh/build.c, for the march): the list
 * holds exactly the vertex's corners, and face (x, p, q) is followed by a
 * face (x, q, r) except where a fan ends: never on a closed, consistently
 * oriented surface (and the last face closes the cycle), never on an open
 * one (each boundary vertex's fan starts at the boundary), once at a vertex
 * shared by two fans. */
static int32_t fan_breaks(const mfmm_mesh *m, int32_t v, int closed)
{
    int32_t lo = m->vertex_face_offset[v], hi = m->vertex_face_offset[v + 1], breaks = 0;
    int32_t first_p = -1, q_prev = -1;
    for (int32_t i = lo; i < hi; i++) {
        int32_t c = MFMM_WEDGE_CORNER(m->vertex_wedge[i]), f = c / 3, k = c % 3;
        const int32_t *fv = m->face_records[f].v;
        assert_int_equal(fv[k], v);
        for (int32_t j = lo; j < i; j++)
            assert_int_not_equal(MFMM_WEDGE_CORNER(m->vertex_wedge[j]), c);
        int32_t p = fv[(k + 1) % 3], q = fv[(k + 2) % 3];
        if (i == lo)
            first_p = p;
        else if (p != q_prev)
            breaks++;
        q_prev = q;
    }
    if (closed && hi > lo)
        assert_int_equal(q_prev, first_p);
    return breaks;
}

static void check_fans(mfmm_gen_mesh g, int closed)
{
    mfmm_mesh *m = tm_make(&g);
    int32_t corners = 0;
    for (int32_t v = 0; v < m->nv; v++) {
        assert_int_equal(fan_breaks(m, v, closed), 0);
        corners += m->vertex_face_offset[v + 1] - m->vertex_face_offset[v];
    }
    assert_int_equal(corners, 3 * m->nf);
    mfmm_mesh_destroy(m);
    mfmm_gen_free(&g);
}

static void test_fan_order(void **state)
{
    (void)state;
    check_fans(mfmm_gen_icosphere(2), 1);
    check_fans(mfmm_gen_torus(12, 8, 1.0, 0.3), 1);
    check_fans(mfmm_gen_sine(9), 0);
    check_fans(mfmm_gen_lattice(6, 3.0), 0);
    /* two fans at vertex 0 (a bowtie): one break there */
    double V[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0, 2, 2, 0};
    int32_t F[] = {0, 1, 2, 0, 3, 4, 1, 5, 2};
    mfmm_mesh *m = NULL;
    mfmm_error err;
    assert_int_equal(mfmm_mesh_create(V, 6, F, 3, NULL, &m, &err), MFMM_OK);
    int32_t total = 0;
    for (int32_t v = 0; v < m->nv; v++)
        total += fan_breaks(m, v, 0);
    assert_int_equal(total, 1);
    mfmm_mesh_destroy(m);
}

/* The build's sorts (src/mesh/order.c, build.c) against plain ones. The
 * vertex order: Morton cells' key, then rows inside the cell, then input
 * id, by qsort. */
typedef struct ref_vkey {
    uint64_t key, fine;
    int32_t id;
} ref_vkey;

static int ref_vkey_cmp(const void *pa, const void *pb)
{
    const ref_vkey *a = pa, *b = pb;
    if (a->key != b->key)
        return a->key < b->key ? -1 : 1;
    if (a->fine != b->fine)
        return a->fine < b->fine ? -1 : 1;
    return (a->id > b->id) - (a->id < b->id);
}

static uint64_t ref_spread3(uint64_t x)
{
    uint64_t r = 0;
    for (int b = 0; b < 21; b++)
        r |= (x >> b & 1) << (3 * b);
    return r;
}

static void ref_vertex_order(const double *xyz, int32_t nv, int32_t *ex)
{
    ref_vkey *keys = malloc((size_t)nv * sizeof *keys);
    assert_non_null(keys);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, ext = 0.0;
    for (int32_t v = 0; v < nv; v++)
        for (int k = 0; k < 3; k++)
            lo[k] = fmin(lo[k], xyz[3 * v + k]);
    for (int32_t v = 0; v < nv; v++)
        for (int k = 0; k < 3; k++)
            ext = fmax(ext, xyz[3 * v + k] - lo[k]);
    double scale = ext > 0.0 ? 2097151.0 / ext : 0.0;
    int L = 0;
    while (L < 21 && ((double)nv / 64.0) > (double)(1u << L) * (double)(1u << L))
        L++;
    for (int32_t v = 0; v < nv; v++) {
        uint32_t u[3];
        for (int k = 0; k < 3; k++) {
            double q = (xyz[3 * v + k] - lo[k]) * scale;
            u[k] = !(q > 0.0) ? 0u : q > 2097151.0 ? 2097151u : (uint32_t)q;
        }
        keys[v].fine = (uint64_t)u[1] << 42 | (uint64_t)u[0] << 21 | u[2];
        keys[v].key = ref_spread3(u[0] >> (21 - L)) | ref_spread3(u[1] >> (21 - L)) << 1 |
                      ref_spread3(u[2] >> (21 - L)) << 2;
        keys[v].id = v;
    }
    qsort(keys, (size_t)nv, sizeof *keys, ref_vkey_cmp);
    for (int32_t i = 0; i < nv; i++)
        ex[i] = keys[i].id;
    free(keys);
}

typedef struct ref_he {
    int32_t lo, hi, corner;
} ref_he;

static int ref_he_cmp(const void *pa, const void *pb)
{
    const ref_he *a = pa, *b = pb;
    if (a->lo != b->lo)
        return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi)
        return a->hi < b->hi ? -1 : 1;
    return (a->corner > b->corner) - (a->corner < b->corner);
}

/* Every half-edge sorted by (lo, hi, corner): each edge's two faces
 * neighbours (copies aside, and leading where their original does), -1 at
 * a boundary or non-manifold edge; the counts and the length statistics
 * summed in that order, bit for bit. */
static void check_edges(const mfmm_mesh *m)
{
    int32_t nc = 3 * m->nf;
    ref_he *he = malloc((size_t)nc * sizeof *he);
    int32_t *fn = malloc((size_t)nc * sizeof *fn);
    assert_true(he && fn);
    for (int32_t c = 0; c < nc; c++) {
        const int32_t *fv = m->face_records[c / 3].v;
        int32_t u = fv[(c % 3 + 1) % 3], v = fv[(c % 3 + 2) % 3];
        he[c] = (ref_he){u < v ? u : v, u < v ? v : u, c};
    }
    qsort(he, (size_t)nc, sizeof *he, ref_he_cmp);
    double sum = 0.0, lmin = INFINITY, lmax = 0.0;
    int32_t n_edges = 0, n_boundary = 0, n_nonmanifold = 0;
    for (int32_t i = 0, j; i < nc; i = j) {
        for (j = i + 1; j < nc && he[j].lo == he[i].lo && he[j].hi == he[i].hi; j++)
            ;
        n_edges++;
        const double *p = m->xyz + 3 * he[i].lo, *q = m->xyz + 3 * he[i].hi;
        double len = sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                          (p[2] - q[2]) * (p[2] - q[2]));
        sum += len;
        lmin = fmin(lmin, len);
        lmax = fmax(lmax, len);
        int32_t real[2] = {0, 0}, n_real = 0;
        for (int32_t t = i; t < j; t++)
            if (!mfmm_mesh_copy(m, he[t].corner / 3) && n_real++ < 2)
                real[n_real - 1] = he[t].corner;
        for (int32_t t = i, s = i; t < j; t++) {
            int32_t c = he[t].corner;
            if (mfmm_mesh_copy(m, c / 3))
                fn[c] = fn[he[s].corner];
            else {
                s = t;
                fn[c] = n_real != 2 ? -1 : c == real[0] ? real[1] / 3 : real[0] / 3;
            }
        }
        n_boundary += n_real == 1;
        n_nonmanifold += n_real != 1 && n_real != 2;
    }
    assert_memory_equal(fn, m->face_neighbor, (size_t)nc * sizeof *fn);
    assert_int_equal(m->info.n_edges, n_edges);
    assert_int_equal(m->info.n_boundary_edges, n_boundary);
    assert_int_equal(m->info.n_nonmanifold_edges, n_nonmanifold);
    double mean = sum / n_edges;
    assert_memory_equal(&m->info.min_edge_length, &lmin, sizeof lmin);
    assert_memory_equal(&m->info.max_edge_length, &lmax, sizeof lmax);
    assert_memory_equal(&m->info.mean_edge_length, &mean, sizeof mean);
    free(he);
    free(fn);
}

/* The vertex order as the reference's (from the input positions, which
 * xyz holds in internal order), faces ascending by their sorted vertices
 * and then input id, and the edges as check_edges's. */
static void check_build(const mfmm_mesh *m, int32_t n_fan_at_0)
{
    double *V = malloc(3 * (size_t)m->nv * sizeof *V);
    int32_t *ex = malloc((size_t)m->nv * sizeof *ex);
    assert_true(V && ex);
    for (int32_t i = 0; i < m->nv; i++)
        memcpy(V + 3 * m->to_external[i], m->xyz + 3 * i, 3 * sizeof *V);
    ref_vertex_order(V, m->nv, ex);
    assert_memory_equal(ex, m->to_external, (size_t)m->nv * sizeof *ex);
    int32_t at_0 = 0, prev[4] = {-1, -1, -1, -1};
    for (int32_t f = 0; f < m->nf; f++) {
        int32_t t[4], *fv = m->face_records[f].v, x;
        memcpy(t, fv, 3 * sizeof *t);
        for (int a = 0; a < 2; a++)
            for (int b = 0; b < 2 - a; b++)
                if (t[b] > t[b + 1])
                    x = t[b], t[b] = t[b + 1], t[b + 1] = x;
        t[3] = m->face_to_external[f];
        assert_true(memcmp(t, prev, sizeof t) != 0);
        for (int k = 0; k < 4; k++)
            if (t[k] != prev[k]) {
                assert_true(t[k] > prev[k]);
                break;
            }
        memcpy(prev, t, sizeof t);
        at_0 += t[0] == 0;
    }
    assert_true(at_0 >= n_fan_at_0);
    check_edges(m);
    free(V);
    free(ex);
}

/* The sorts' rare paths: a fan of 100 faces and a book of 40 pages on
 * vertex 0 (more faces and half-edges at one vertex than the insertion
 * sorts take), copies of faces, two more vertices at vertex 0's position
 * and one at a rim vertex's (ties of the vertex order), 20 referenced and 2
 * unreferenced at another's (a run of equal keys that coincident_vertices
 * hashes), an unreferenced vertex; then a sine surface and a shared mesh. */
static void test_build_against_reference(void **state)
{
    (void)state;
    enum { RIM = 101, PAGES = 40, STACK = 22 };
    int32_t nv = 1 + RIM + PAGES + 4 + STACK, nf = 0;
    double *V = malloc(3 * (size_t)nv * sizeof *V);
    int32_t *F = malloc(3 * 250 * sizeof *F);
    assert_true(V && F);
    memset(V, 0, 3 * (size_t)nv * sizeof *V);
    for (int32_t i = 0; i < RIM; i++) {
        double a = 1.5707963267948966 * i / (RIM - 1);
        V[3 * (1 + i)] = cos(a), V[3 * (1 + i) + 1] = sin(a), V[3 * (1 + i) + 2] = 0.05 * (i % 3);
    }
    for (int32_t j = 0; j < PAGES; j++) {
        double *p = V + 3 * (1 + RIM + j);
        p[0] = 0.5, p[1] = 0.5, p[2] = 0.1 + 0.05 * j;
    }
    int32_t z0 = 1 + RIM + PAGES, z1 = z0 + 1, q = z0 + 2, unref = z0 + 3;
    memcpy(V + 3 * q, V + 3 * (1 + 50), 3 * sizeof *V);
    V[3 * unref] = V[3 * unref + 1] = V[3 * unref + 2] = 0.3;
    int32_t stack = unref + 1;
    for (int32_t i = 0; i < STACK; i++)
        memcpy(V + 3 * (stack + i), V + 3 * (1 + 70), 3 * sizeof *V);
#define FACE(a, b, c) (F[3 * nf] = (a), F[3 * nf + 1] = (b), F[3 * nf + 2] = (c), nf++)
    for (int32_t i = 0; i + 1 < RIM; i++)
        FACE(0, 1 + i, 2 + i);
    for (int32_t j = 0; j < PAGES; j++)
        FACE(0, 1, 1 + RIM + j);
    FACE(11, 12, 0);  /* copies: rotated, flipped, twice */
    FACE(0, 22, 21);
    FACE(31, 0, 32);
    FACE(32, 31, 0);
    FACE(z0, 1 + RIM, 2 + RIM);
    FACE(z1, q, 1 + RIM + 5);
    FACE(q, 61, 1 + RIM + 7);
    for (int32_t i = 0; i < STACK - 2; i++)
        FACE(stack + i, 81, 1 + RIM + 10);
#undef FACE
    mfmm_mesh *m = NULL;
    mfmm_error err;
    assert_int_equal(mfmm_mesh_create(V, nv, F, nf, NULL, &m, &err), MFMM_OK);
    assert_int_equal(m->to_external[0], 0);
    assert_true(m->info.n_nonmanifold_edges > 0 && m->info.n_duplicate_faces == 4);
    assert_int_equal(m->info.n_coincident_vertices, 3 + STACK - 2);
    assert_int_equal(m->info.n_unreferenced_vertices, 3);
    check_build(m, RIM - 1 + PAGES);
    mfmm_mesh_destroy(m);
    free(V);
    free(F);
    mfmm_gen_mesh g = mfmm_gen_sine(40);
    m = tm_make(&g);
    check_build(m, 0);
    mfmm_mesh_destroy(m);
    mfmm_gen_free(&g);
    m = tm_load_data("meshes/camelhead.off", NULL, NULL, NULL);
    check_build(m, 0);
    mfmm_mesh_destroy(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shuffled_lattice),
        cmocka_unit_test(test_shuffled_sine),
        cmocka_unit_test(test_shuffled_sparse),
        cmocka_unit_test(test_deterministic),
        cmocka_unit_test(test_fan_order),
        cmocka_unit_test(test_build_against_reference),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
