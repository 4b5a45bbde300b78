/* Probe (issue 13.2, session 14): the march over per-vertex neighbour
 * records, against the library's face walk (src/core/march.h), F = 1,
 * plain start, same heap, sources and vertex order. Not the library's code;
 * it measures what a layout would give before anyone builds it.
 *
 * Records: for each vertex x, one record per neighbour c that x updates:
 * c, |xc| and the (up to) two triangles through x that update c, each with
 * its other vertex y (the fan neighbour, or V where c's obtuse corner has a
 * virtual edge, section 4.2), |yc| and the cosine at c, oriented as
 * mfmm_triangle_interior takes them; first, a record per virtual edge that
 * ends at x (y: A and B). 56 bytes. A missing triangle names vertex nv,
 * which is never Alive. The walk has no case for virtual stencils and
 * offers each neighbour once: the face walk's offers (its merge of a face's
 * q with the next face's p), in its order where x's fan is closed (at a
 * break the face walk offers the next p before the pending q: equal keys
 * could then leave the heap in another order). The rows are compared bit
 * for bit on every run.
 * Indexed (unfolding off only): the same records as two 4-byte face slots
 * (16 f + 4 jc + jx) that the walk resolves through the face records.
 *
 * Measured (session 14, --repeats 5 --sources 3, march medians; Dijkstra:
 * bench_solve's ceiling in the same run):
 *   mesh        nv     unfolding on: walk -> records (x)    off: walk -> records, indexed
 *   hand        810    0.080 -> 0.060 ms (0.75x)             0.067 -> 0.053 (0.79x), 0.99x
 *   spot        2930   0.285 -> 0.223 ms (0.78x)             0.278 -> 0.207 (0.75x), 0.92x
 *   camelhead   11k    1.351 -> 1.026 ms (0.76x)             1.068 -> 0.797 (0.75x), 0.92x
 *   nefertiti   35k    4.790 -> 3.717 ms (0.78x)             3.734 -> 3.144 (0.84x), 0.99x
 *   sine 500    251k   42.7 -> 31.3 ms (0.73x)               29.7 -> 29.0 (0.98x), 1.01x
 *   sine 1000   1M     171 -> 136 ms (0.79x)                 125 -> 126 (1.01x), 1.04x
 * Against Dijkstra (unfolding on): records 1.64x camelhead, 1.65x nefertiti,
 * 1.50x sine 500, 1.38x sine 1000 (face walk 2.0-2.15x, 1.74x at 1M).
 * All rows bit-identical (also hand, beetle, wingnut, fertility,
 * decimated-max, bunny, icosphere 5, lattice 100, grid 100, torus 100).
 * cachegrind (camelhead, unfolding on / off, per settled vertex; the
 * alternating runs inflate both): face walk 1089 / 992 instructions and
 * 14.5 / 11.5 mispredictions; records 763 / 702 and 8.2 / 5.8.
 * The cost: 408-447 B/vertex of records (72-byte records measured 0.77-0.87x
 * with unfolding, 56 bytes 0.73-0.79x: smaller is faster), against a built mesh of ~266
 * B/vertex and issue 13's limit of 300. Without unfolding on meshes past
 * the cache the records are no faster (each face's data is read from three
 * records instead of one shared line). The indexed layout, which fits the
 * limit, is no faster: its dependent loads and orientation selects cost
 * what the single offer saves.
 *
 *   bench_neighbour_probe [--repeats R] [--sources S] [--unfolding 0|1] MESH... */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "meshfmm.h"
#include "core/mesh.h"

typedef struct nrec {
    int32_t c;
    int32_t y[2];      /* nv: no triangle (a vertex never Alive) */
    uint32_t x_is_a;   /* bit s: x is the triangle's A in slot s */
    double len;        /* |xc| */
    double ly[2], cs[2]; /* |yc| and the cosine at c, slot s */
} nrec;

typedef struct nmesh {
    int32_t nv;
    int32_t *off;
    nrec *rec;
} nmesh;

/* variant B: a record is two slots, each 16 f + 4 jc + jx (face f, the
 * target's corner jc, x's corner jx); face nf is a sentinel whose vertices
 * are nv (never Alive). No unfolding. */
typedef struct imesh {
    int32_t nv;
    int32_t *off;
    int32_t *w; /* 2 per record */
    mfmm_face *faces; /* nf + 1 */
} imesh;

typedef struct slot {
    int32_t c, y, x_is_a;
    double len, la, lb, cs;
} slot;

/* Puts slot q into r's slot s; 0 if its |xc| is not r's (the record
 * stores |xc| once). */
static int put(nrec *r, int s, const slot *q)
{
    r->y[s] = q->y;
    /* x is A: a = |BC| = |yc|, b = |xc|; x is B: a = |xc|, b = |yc| */
    r->ly[s] = q->x_is_a ? q->la : q->lb;
    r->cs[s] = q->cs;
    if (q->x_is_a)
        r->x_is_a |= 1u << s;
    return (q->x_is_a ? q->lb : q->la) == r->len;
}

static int32_t max_faces(const mfmm_march_mesh *m)
{
    int32_t most = 0;
    for (int32_t x = 0; x < m->nv; x++)
        if (m->wedge_offset[x + 1] - m->wedge_offset[x] > most)
            most = m->wedge_offset[x + 1] - m->wedge_offset[x];
    return most;
}

static int build(const mfmm_mesh *mesh, nmesh *n, int unfolding)
{
    mfmm_march_mesh m = mfmm_mesh_march_view(mesh);
    int32_t nv = m.nv;
    size_t cap = 2 * (size_t)m.wedge_offset[nv] + (size_t)mesh->n_virts;
    n->nv = nv;
    n->off = malloc(((size_t)nv + 1) * sizeof *n->off);
    void *mem = NULL;
    if (posix_memalign(&mem, 64, cap * sizeof(nrec) + 64))
        return 0;
    n->rec = mem;
    slot *sl = malloc((2 * (size_t)max_faces(&m) + 1) * sizeof *sl);
    if (!n->off || !n->rec || !sl)
        return 0;
    int ok = 1;
    int32_t k = 0;
    for (int32_t x = 0; x < nv; x++) {
        n->off[x] = k;
        for (int32_t j = m.virt_first[x]; unfolding && j < m.virt_first[x + 1]; j++) {
            const mfmm_virt *vr = m.virts + j;
            int32_t fc = vr->corner / 3, jc = vr->corner % 3;
            const mfmm_face *fr = m.faces + fc;
            int32_t ja = (jc + 1) % 3, jb = (ja + 1) % 3;
            nrec *r = n->rec + k++;
            memset(r, 0, sizeof *r);
            r->c = vr->c;
            r->len = vr->len;
            slot a = {vr->c, fr->v[ja], 0, vr->len, vr->len, fr->len[jb], vr->cos_a};
            slot b = {vr->c, fr->v[jb], 1, vr->len, fr->len[ja], vr->len, vr->cos_b};
            ok &= put(r, 0, &a) & put(r, 1, &b);
        }
        int32_t ns = 0;
        for (int32_t j = m.wedge_offset[x]; j < m.wedge_offset[x + 1]; j++) {
            int32_t wc = m.wedge[j], f_id = MFMM_WEDGE_FACE(wc);
            const mfmm_face *fr = m.faces + f_id;
            int32_t jp = MFMM_WEDGE_NEXT(wc), jq = MFMM_WEDGE_PREV(wc), kk = 3 - jp - jq;
            int32_t p = fr->v[jp], q = fr->v[jq], jv = unfolding ? fr->virt & 3 : 3;
            slot sp = {p, q, 0, fr->len[jq], fr->len[jq], fr->len[kk], fr->cosv[jp]};
            slot sq = {q, p, 1, fr->len[jp], fr->len[kk], fr->len[jp], fr->cosv[jq]};
            if (jv == jp || jv == jq) {
                int32_t iv = fr->virt >> 2;
                const mfmm_virt *vr = mfmm_march_virt_of(&m, iv, 3 * f_id + jv);
                if (jv == jp) {
                    sp.y = iv;
                    sp.lb = vr->len;
                    sp.cs = vr->cos_b;
                } else {
                    sq.y = iv;
                    sq.la = vr->len;
                    sq.cs = vr->cos_a;
                }
            }
            sl[ns++] = sp;
            sl[ns++] = sq;
        }
        for (int32_t i = 0; i < ns;) {
            nrec *r = n->rec + k++;
            memset(r, 0, sizeof *r);
            r->c = sl[i].c;
            r->len = sl[i].len;
            r->y[1] = nv;
            r->ly[1] = 1.0;
            r->cs[1] = 0.0;
            ok &= put(r, 0, sl + i);
            if (i + 1 < ns && sl[i + 1].c == sl[i].c) {
                ok &= put(r, 1, sl + i + 1);
                i += 2;
            } else {
                i += 1;
            }
        }
    }
    n->off[nv] = k;
    free(sl);
    return ok;
}

static int build_indexed(const mfmm_mesh *mesh, imesh *n)
{
    mfmm_march_mesh m = mfmm_mesh_march_view(mesh);
    int32_t nv = m.nv, nf = mesh->nf;
    size_t cap = 2 * (size_t)m.wedge_offset[nv];
    n->nv = nv;
    n->off = malloc(((size_t)nv + 1) * sizeof *n->off);
    n->w = malloc(2 * cap * sizeof *n->w);
    void *mem = NULL;
    if (posix_memalign(&mem, 64, ((size_t)nf + 1) * sizeof(mfmm_face)))
        return 0;
    n->faces = mem;
    if (!n->off || !n->w)
        return 0;
    memcpy(n->faces, m.faces, (size_t)nf * sizeof(mfmm_face));
    mfmm_face *z = n->faces + nf;
    z->v[0] = z->v[1] = z->v[2] = nv;
    z->virt = 3;
    for (int i = 0; i < 3; i++) {
        z->len[i] = 1.0;
        z->cosv[i] = 0.0;
    }
    int32_t k = 0, sent = 16 * nf; /* jc 0, jx 0: y = v[0] = nv */
    int32_t *cs = malloc((2 * (size_t)max_faces(&m) + 1) * 2 * sizeof *cs);
    if (!cs)
        return 0;
    int32_t *ws = cs + 2 * max_faces(&m) + 1;
    for (int32_t x = 0; x < nv; x++) {
        n->off[x] = k;
        int32_t ns = 0;
        for (int32_t j = m.wedge_offset[x]; j < m.wedge_offset[x + 1]; j++) {
            int32_t wc = m.wedge[j], f_id = MFMM_WEDGE_FACE(wc);
            int32_t jp = MFMM_WEDGE_NEXT(wc), jq = MFMM_WEDGE_PREV(wc), kk = 3 - jp - jq;
            cs[ns] = m.faces[f_id].v[jp];
            ws[ns++] = 16 * f_id + 4 * jp + kk;
            cs[ns] = m.faces[f_id].v[jq];
            ws[ns++] = 16 * f_id + 4 * jq + kk;
        }
        for (int32_t i = 0; i < ns;) {
            n->w[2 * k] = ws[i];
            if (i + 1 < ns && cs[i + 1] == cs[i]) {
                n->w[2 * k + 1] = ws[i + 1];
                i += 2;
            } else {
                n->w[2 * k + 1] = sent;
                i += 1;
            }
            k++;
        }
    }
    n->off[nv] = k;
    free(cs);
    return 1;
}

/* Section 2's loop head: settles the heap's top and returns it. */
MFMM_INLINE mfmm_i32 settle_top(mfmm_march_state *w)
{
    mfmm_i32 x = w->heap_vertex[0];
    mfmm_heap_pop(w);
    w->label[x] = (mfmm_u8)((w->label[x] & MFMM_TARGET) | MFMM_ALIVE);
    return x;
}

static void indexed_march(mfmm_march_state *s, const imesh *nm)
{
    mfmm_march_state w = *s;
    imesh n = *nm;
    while (w.heap_size > 0) {
        mfmm_i32 x = settle_top(&w);
        if (w.heap_size > 0) {
            mfmm_i32 y = w.heap_vertex[0];
            for (mfmm_i32 j = n.off[y]; j < n.off[y + 1]; j++)
                MFMM_PREFETCH(n.faces + (n.w[2 * j] >> 4));
        }
        double tx = w.T[x];
        for (mfmm_i32 j = n.off[x]; j < n.off[x + 1]; j++) {
            mfmm_i32 w0 = n.w[2 * j], w1 = n.w[2 * j + 1];
            const mfmm_face *f0 = n.faces + (w0 >> 4), *f1 = n.faces + (w1 >> 4);
            mfmm_i32 jc0 = (w0 >> 2) & 3, jx0 = w0 & 3, jc1 = (w1 >> 2) & 3, jx1 = w1 & 3;
            mfmm_i32 jy0 = 3 - jc0 - jx0, jy1 = 3 - jc1 - jx1;
            mfmm_i32 c = f0->v[jc0];
            mfmm_u8 lc = w.label[c];
            if ((lc & MFMM_STATE_MASK) == MFMM_ALIVE || (lc & MFMM_FIXED))
                continue;
            double t = tx + f0->len[jy0];
            mfmm_i32 y0 = f0->v[jy0], y1 = f1->v[jy1];
            if ((w.label[y0] & MFMM_STATE_MASK) == MFMM_ALIVE) {
                double ty = w.T[y0];
                int xa = jx0 == ((0x09 >> (2 * jc0)) & 3);
                double ta = xa ? tx : ty, tb = xa ? ty : tx;
                double la = xa ? f0->len[jx0] : f0->len[jy0], lb = xa ? f0->len[jy0] : f0->len[jx0];
                t = mfmm_min(t, mfmm_triangle_interior(ta, tb, la, lb, f0->cosv[jc0], 1.0));
            }
            if ((w.label[y1] & MFMM_STATE_MASK) == MFMM_ALIVE) {
                double ty = w.T[y1];
                int xa = jx1 == ((0x09 >> (2 * jc1)) & 3);
                double ta = xa ? tx : ty, tb = xa ? ty : tx;
                double la = xa ? f1->len[jx1] : f1->len[jy1], lb = xa ? f1->len[jy1] : f1->len[jx1];
                t = mfmm_min(t, mfmm_triangle_interior(ta, tb, la, lb, f1->cosv[jc1], 1.0));
            }
            if (t < w.T[c]) {
                mfmm_u8 st = lc & MFMM_STATE_MASK;
                if (st == MFMM_FAR)
                    MFMM_PREFETCH(n.w + 2 * n.off[c]);
                w.T[c] = t;
                mfmm_heap_push_or_decrease(&w, c, t, st == MFMM_CLOSE);
                w.label[c] = (mfmm_u8)((lc & MFMM_TARGET) | MFMM_CLOSE);
            }
        }
    }
    s->heap_size = w.heap_size;
}

MFMM_INLINE void probe_offer(mfmm_march_state *s, const nmesh *n, mfmm_i32 c, mfmm_u8 lc,
                             double t)
{
    if (t < s->T[c]) {
        mfmm_u8 st = lc & MFMM_STATE_MASK;
        if (st == MFMM_FAR)
            MFMM_PREFETCH(n->rec + n->off[c]);
        s->T[c] = t;
        mfmm_heap_push_or_decrease(s, c, t, st == MFMM_CLOSE);
        s->label[c] = (mfmm_u8)((lc & MFMM_TARGET) | MFMM_CLOSE);
    }
}

static void probe_march(mfmm_march_state *s, const nmesh *nm)
{
    mfmm_march_state w = *s;
    nmesh n = *nm;
    while (w.heap_size > 0) {
        mfmm_i32 x = settle_top(&w);
        if (w.heap_size > 0) {
            mfmm_i32 y = w.heap_vertex[0];
            const char *b = (const char *)(n.rec + n.off[y]);
            const char *e = (const char *)(n.rec + n.off[y + 1]);
            for (; b < e; b += 64)
                MFMM_PREFETCH(b);
        }
        double tx = w.T[x];
        for (mfmm_i32 j = n.off[x]; j < n.off[x + 1]; j++) {
            const nrec *r = n.rec + j;
            mfmm_i32 c = r->c;
            mfmm_u8 lc = w.label[c];
            if ((lc & MFMM_STATE_MASK) == MFMM_ALIVE || (lc & MFMM_FIXED))
                continue;
            double t = tx + r->len;
            for (int q = 0; q < 2; q++) {
                mfmm_i32 y = r->y[q];
                if ((w.label[y] & MFMM_STATE_MASK) == MFMM_ALIVE) {
                    double ty = w.T[y];
                    int xa = (r->x_is_a >> q) & 1;
                    double ta = xa ? tx : ty, tb = xa ? ty : tx;
                    double la = xa ? r->ly[q] : r->len, lb = xa ? r->len : r->ly[q];
                    t = mfmm_min(t, mfmm_triangle_interior(ta, tb, la, lb, r->cs[q], 1.0));
                }
            }
            probe_offer(&w, &n, c, lc, t);
        }
    }
    s->heap_size = w.heap_size;
}

/* A march's row as the library returns it (+inf where not settled). */
static void row_of(const mfmm_march_state *s, int32_t nv, double *out)
{
    for (int32_t i = 0; i < nv; i++)
        out[i] = (s->label[i] & MFMM_STATE_MASK) == MFMM_ALIVE ? s->T[i] : MFMM_INF;
}

static long count_differing(const double *a, const double *b, int32_t nv)
{
    long n = 0;
    for (int32_t i = 0; i < nv; i++)
        n += memcmp(a + i, b + i, sizeof *a) != 0;
    return n;
}

static double median(double *x, int n)
{
    qsort(x, (size_t)n, sizeof *x, cmp_double);
    return x[n / 2];
}

static int only_unfolding = -1; /* --unfolding U: that setting only */

static void bench(const char *name, const double *V, int32_t nv, const int32_t *F, int32_t nf,
                  int repeats, int n_sources)
{
    mfmm_mesh *mesh = NULL;
    mfmm_error err;
    if (mfmm_mesh_create(V, nv, F, nf, NULL, &mesh, &err) != MFMM_OK) {
        fprintf(stderr, "%s: %s\n", name, err.message);
        return;
    }
    mfmm_march_mesh m = mfmm_mesh_march_view(mesh);
    size_t n = (size_t)nv + 1; /* + the never-Alive vertex nv */
    mfmm_march_state s;
    int have_state = bench_state_alloc(&s, n);
    double *ref = malloc(n * sizeof *ref), *row = malloc(n * sizeof *row);
    size_t nt = (size_t)repeats * n_sources;
    double *t_walk = malloc(nt * sizeof(double)), *t_rec = malloc(nt * sizeof(double)),
           *t_idx = malloc(nt * sizeof(double));
    if (!have_state || !ref || !row || !t_walk || !t_rec || !t_idx) {
        fprintf(stderr, "out of memory\n");
        exit(1);
    }
    s.label[nv] = MFMM_FAR;
    for (int unfolding = 1; unfolding >= 0; unfolding--) {
        if (only_unfolding >= 0 && unfolding != only_unfolding)
            continue;
        nmesh nm = {0, NULL, NULL};
        imesh im = {0, NULL, NULL, NULL};
        if (!build(mesh, &nm, unfolding) || (!unfolding && !build_indexed(mesh, &im))) {
            fprintf(stderr, "%s: out of memory, or a slot's |xc| is not its record's\n",
                    name);
            exit(1);
        }
        s.unfolding = unfolding;
        int k = 0;
        long differ_rec = 0, differ_idx = 0;
        for (int q = 0; q < n_sources; q++) {
            int32_t v = mesh->to_internal[((int64_t)nv * (2 * q + 1)) / (2 * n_sources)];
            for (int r = 0; r < repeats; r++, k++) {
                mfmm_march_reset(&s, nv);
                mfmm_march_seed(&s, v, 0.0);
                double t1 = now();
                mfmm_march_run(&s, &m);
                t_walk[k] = now() - t1;
                memcpy(ref, s.T, (size_t)nv * sizeof *ref);
                mfmm_march_reset(&s, nv);
                mfmm_march_seed(&s, v, 0.0);
                t1 = now();
                probe_march(&s, &nm);
                t_rec[k] = now() - t1;
                row_of(&s, nv, row);
                differ_rec += count_differing(row, ref, nv);
                if (unfolding)
                    continue;
                mfmm_march_reset(&s, nv);
                mfmm_march_seed(&s, v, 0.0);
                t1 = now();
                indexed_march(&s, &im);
                t_idx[k] = now() - t1;
                row_of(&s, nv, row);
                differ_idx += count_differing(row, ref, nv);
            }
        }
        double walk = median(t_walk, k), rec = median(t_rec, k);
        printf("%-22s nv=%7d unfolding=%d  face walk %8.3f ms | records (%.2f/vertex, "
               "%3.0f B/vertex) %8.3f ms = %.3fx, entries differing %ld",
               name, nv, unfolding, 1e3 * walk, (double)nm.off[nv] / nv,
               (double)nm.off[nv] * sizeof(nrec) / nv, 1e3 * rec, rec / walk, differ_rec);
        if (!unfolding) {
            double idx = median(t_idx, k);
            printf(" | indexed (%.0f B/vertex) %8.3f ms = %.3fx, differing %ld",
                   (double)im.off[nv] * 2 * sizeof(int32_t) / nv, 1e3 * idx, idx / walk,
                   differ_idx);
            free(im.off);
            free(im.w);
            free(im.faces);
        }
        printf("\n");
        free(nm.off);
        free(nm.rec);
    }
    bench_state_free(&s);
    free(ref);
    free(row);
    free(t_walk);
    free(t_rec);
    free(t_idx);
    mfmm_mesh_destroy(mesh);
}

int main(int argc, char **argv)
{
    int repeats = 5, n_sources = 3, first = 1;
    while (first + 1 < argc && argv[first][0] == '-') {
        if (!strcmp(argv[first], "--repeats"))
            repeats = atoi(argv[first + 1]);
        else if (!strcmp(argv[first], "--sources"))
            n_sources = atoi(argv[first + 1]);
        else if (!strcmp(argv[first], "--unfolding"))
            only_unfolding = atoi(argv[first + 1]);
        else {
            fprintf(stderr, "usage: bench_neighbour_probe [--repeats R] [--sources S] "
                            "[--unfolding 0|1] MESH...\n");
            return 2;
        }
        first += 2;
    }
    bench_mesh_files((const char *const *)(argv + first), argc - first, bench, repeats, n_sources);
    return 0;
}
