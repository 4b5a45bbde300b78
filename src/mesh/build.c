/* The precomputation every solve reuses, from checked arrays: vertex and
 * face order (order.c), adjacency, edge lengths, corner angles (section
 * 4.1), virtual edges (section 4.2, in unfold.c) and the face records the
 * march reads; and the mesh's destruction. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "build.h"
#include "order.h"
#include "unfold.h"
#include "weld.h"

/* Smallest extent: lengths are squared once (1e-200 is far from
 * underflow). */
#define MFMM_MIN_DIAGONAL 1e-100

/* fmin and fmax of numbers (no NaN), inline: as calls they cost as much as
 * the loops over every edge and vertex that use them. */
static double min_d(double x, double y)
{
    return y < x ? y : x;
}

static double max_d(double x, double y)
{
    return y > x ? y : x;
}

void mfmm_mesh_destroy(mfmm_mesh *mesh)
{
    if (!mesh)
        return;
    free(mesh->to_internal);
    free(mesh->to_external);
    free(mesh->face_to_internal);
    free(mesh->face_to_external);
    free(mesh->piece_next);
    free(mesh->piece_bary);
    free(mesh->xyz);
    free(mesh->face_neighbor);
    free(mesh->vertex_face_offset);
    free(mesh->vertex_wedge);
    free(mesh->face_block);
    free(mesh->virts);
    free(mesh->virt_first);
    free(mesh->virt_strip);
    free(mesh->strip);
    if (mesh->exact_tables)
        mesh->exact_tables_free(mesh->exact_tables);
    free(mesh->spoke_offset);
    free(mesh->spoke_block);
    pthread_mutex_destroy(&mesh->cache_lock);
    free(mesh);
}

/* The face records' vertices in internal face order, from the mapped input
 * faces (face_neighbor, input order); which faces copy the one before
 * (mfmm_mesh_copy: *copy, malloc'd) and their count; the vertex -> corner
 * CSR, each vertex's corners ascending (so by face), and the most corners at
 * one vertex: one pass over the faces for all that reads them in order. */
static mfmm_status build_faces(mfmm_mesh *m, int32_t *dmax, uint8_t **copy_out)
{
    size_t nf = (size_t)m->nf;
    int32_t *off = calloc((size_t)m->nv + 1, sizeof *off);
    int32_t *list = malloc(3 * nf * sizeof *list);
    uint8_t *copy = malloc(nf);
    if (!off || !list || !copy) {
        free(off);
        free(list);
        free(copy);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    m->vertex_face_offset = off;
    m->vertex_wedge = list;
    int32_t n_copies = 0;
    for (size_t f = 0; f < nf; f++) {
        int32_t *fv = m->face_records[f].v;
        memcpy(fv, m->face_neighbor + 3 * (size_t)m->face_to_external[f], 3 * sizeof *fv);
        copy[f] = (uint8_t)mfmm_mesh_copy(m, (int32_t)f);
        n_copies += copy[f];
        for (int k = 0; k < 3; k++)
            off[fv[k] + 1]++;
    }
    int32_t d = 0;
    for (int32_t v = 0; v < m->nv; v++) {
        d = off[v + 1] > d ? off[v + 1] : d;
        off[v + 1] += off[v];
    }
    for (size_t f = 0; f < nf; f++)
        for (int k = 0; k < 3; k++)
            list[off[m->face_records[f].v[k]]++] = (int32_t)(3 * f + (size_t)k);
    for (int32_t v = m->nv; v > 0; v--)
        off[v] = off[v - 1];
    off[0] = 0;
    *dmax = d;
    *copy_out = copy;
    m->info.n_duplicate_faces = n_copies;
    return MFMM_OK;
}

static int u64_cmp(const void *pa, const void *pb)
{
    uint64_t a = *(const uint64_t *)pa, b = *(const uint64_t *)pb;
    return (a > b) - (a < b);
}

/* Ascending: insertion for the few keys of a typical vertex, qsort for a
 * large fan. */
static void sort_u64(uint64_t *key, int32_t n)
{
    if (n > 32) {
        qsort(key, (size_t)n, sizeof *key, u64_cmp);
        return;
    }
    for (int32_t i = 1; i < n; i++) {
        uint64_t x = key[i];
        int32_t j = i;
        for (; j > 0 && key[j - 1] > x; j--)
            key[j] = key[j - 1];
        key[j] = x;
    }
}

/* The corner of face f in x's corner list list[0..n) (sorted by face, as
 * build_faces makes it), or -1. */
static int32_t find_corner(const int32_t *list, int32_t n, int32_t f)
{
    int32_t lo = 0, hi = n;
    while (lo < hi) {
        int32_t mid = lo + (hi - lo) / 2;
        if (list[mid] / 3 < f)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < n && list[lo] / 3 == f ? lo : -1;
}

/* Puts vertex x's corners in fan order, as wedges (MFMM_WEDGE), once the
 * face_neighbor entries of its edges are set: face (x, p, q) is followed by
 * the face across edge xq when that face has x, q in the same orientation
 * (its vertex after x is q), so that consecutive faces share a neighbour of
 * x: the march (march.h) then meets x's settled neighbours in runs, which
 * its branches predict, and offers a shared neighbour once. Fans start at a
 * face with no predecessor (a boundary, non-manifold or flipped edge);
 * closed fans follow. Any order is correct: this one saves work. next,
 * has_prev, out: scratch of x's corner count. */
static void fan_vertex(mfmm_mesh *m, int32_t x, int32_t *next, int32_t *has_prev, int32_t *out)
{
    int32_t *list = m->vertex_wedge + m->vertex_face_offset[x];
    int32_t n = m->vertex_face_offset[x + 1] - m->vertex_face_offset[x];
    for (int32_t i = 0; i < n; i++)
        has_prev[i] = 0;
    for (int32_t i = 0; i < n; i++) {
        int32_t c = list[i], f = c / 3, k = c % 3;
        int32_t kp = k == 2 ? 0 : k + 1, kq = kp == 2 ? 0 : kp + 1;
        int32_t q = m->face_records[f].v[kq];
        int32_t g = m->face_neighbor[3 * f + kp]; /* across edge x q */
        int32_t j = g >= 0 ? find_corner(list, n, g) : -1;
        next[i] = -1;
        if (j >= 0 && j != i && !has_prev[j]) {
            int32_t kg = list[j] % 3;
            if (m->face_records[g].v[kg == 2 ? 0 : kg + 1] == q) {
                next[i] = j;
                has_prev[j] = 1;
            }
        }
    }
    int32_t n_out = 0;
    for (int pass = 0; pass < 2; pass++)
        for (int32_t i = 0; i < n; i++) {
            if (has_prev[i] == 2 || (pass == 0 && has_prev[i]))
                continue;
            for (int32_t j = i; j >= 0 && has_prev[j] != 2; j = next[j]) {
                out[n_out++] = MFMM_WEDGE(list[j] / 3, list[j] % 3);
                has_prev[j] = 2;
            }
        }
    memcpy(list, out, (size_t)n * sizeof *list);
}

/* Face adjacency across edges, boundary and non-manifold counts, edge-length
 * statistics, and each vertex's fan order (fan_vertex), from the vertex ->
 * corner CSR, the copy flags (build_faces) and the face records' lengths
 * (build_corners): the half-edges (lo, hi) of each vertex lo, by hi and
 * then by the corner opposite, from its own corners, so that no sort runs
 * over all of them; a vertex's fan once the edges of every vertex up to it
 * are done, which are all of its own. */
static mfmm_status build_edges(mfmm_mesh *m, int32_t dmax, const uint8_t *copy)
{
    /* per half-edge: hi << 33 | the corner opposite << 1 | its face a copy */
    uint64_t *key = malloc((2 * (size_t)dmax + 1) * sizeof *key);
    int32_t *next = malloc(((size_t)dmax + 1) * 3 * sizeof *next);
    if (!key || !next) {
        free(key);
        free(next);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    int32_t *has_prev = next + dmax + 1, *out = has_prev + dmax + 1;
    const int32_t *off = m->vertex_face_offset, *list = m->vertex_wedge;
    double sum = 0.0, lmin = INFINITY, lmax = 0.0;
    int32_t n_edges = 0, n_boundary = 0, n_nonmanifold = 0;
    for (int32_t x = 0; x < m->nv; x++) {
        int32_t n = 0;
        for (int32_t i = off[x]; i < off[x + 1]; i++) {
            int32_t f = list[i] / 3, k = list[i] % 3;
            int32_t k1 = k == 2 ? 0 : k + 1, k2 = k1 == 2 ? 0 : k1 + 1;
            const int32_t *fv = m->face_records[f].v;
            if (fv[k1] > x)
                key[n++] = (uint64_t)fv[k1] << 33 | (uint64_t)(3 * f + k2) << 1 | copy[f];
            if (fv[k2] > x)
                key[n++] = (uint64_t)fv[k2] << 33 | (uint64_t)(3 * f + k1) << 1 | copy[f];
        }
        sort_u64(key, n);
        for (int32_t i = 0; i < n;) {
            int32_t j = i + 1;
            while (j < n && key[j] >> 33 == key[i] >> 33)
                j++;
            n_edges++;
            /* the edge's length as build_corners measured it for the corner
             * opposite (the same sum of the same squares) */
            int32_t c0 = (int32_t)(key[i] >> 1 & 0xffffffffu);
            double len = m->face_records[c0 / 3].len[c0 % 3];
            sum += len;
            lmin = min_d(lmin, len);
            lmax = max_d(lmax, len);
            /* copies of a face stand aside: the edge is what the other faces
             * make it (two copies of a face made its edges walls) */
            int32_t real[2] = {0, 0}, n_real = 0;
            for (int32_t t = i; t < j; t++)
                if (!(key[t] & 1)) {
                    if (n_real < 2)
                        real[n_real] = (int32_t)(key[t] >> 1 & 0xffffffffu);
                    n_real++;
                }
            if (n_real == 2) {
                m->face_neighbor[real[0]] = real[1] / 3;
                m->face_neighbor[real[1]] = real[0] / 3;
            } else {
                /* boundary, or non-manifold: the walk of section 4.2 stops here */
                for (int32_t t = i; t < j; t++)
                    m->face_neighbor[key[t] >> 1 & 0xffffffffu] = -1;
                if (n_real == 1)
                    n_boundary++;
                else
                    n_nonmanifold++;
            }
            /* a copy's edge leads where its original's does: copies follow
             * their original in face order, hence in the group (O(faces), even
             * for a million copies of one face) */
            for (int32_t t = i, s = i; t < j; t++) {
                if (!(key[t] & 1))
                    s = t;
                else
                    m->face_neighbor[key[t] >> 1 & 0xffffffffu] =
                        m->face_neighbor[key[s] >> 1 & 0xffffffffu];
            }
            i = j;
        }
        fan_vertex(m, x, next, has_prev, out);
    }
    free(key);
    free(next);
    m->info.n_edges = n_edges;
    m->info.n_boundary_edges = n_boundary;
    m->info.n_nonmanifold_edges = n_nonmanifold;
    m->info.min_edge_length = lmin;
    m->info.max_edge_length = lmax;
    m->info.mean_edge_length = n_edges ? sum / n_edges : 0.0;
    return MFMM_OK;
}

static int32_t uf_find(int32_t *parent, int32_t x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

/* The referenced vertices in [a, b) at the position of an earlier one
 * there: their count, each joined in `parent` to the first at its
 * position; a table of cap (a power of two) slots, -1 when empty. */
static int32_t coincident_hashed(mfmm_mesh *m, int32_t *parent, int32_t a, int32_t b,
                                 int32_t *table, size_t cap)
{
    int32_t n = 0;
    for (int32_t v = a; v < b; v++) {
        if (m->vertex_face_offset[v] == m->vertex_face_offset[v + 1])
            continue; /* unreferenced: counted apart */
        const double *p = m->xyz + 3 * (size_t)v;
        size_t i = (size_t)mfmm_position_hash(p) & (cap - 1);
        for (;;) {
            int32_t w = table[i];
            if (w < 0) {
                table[i] = v;
                break;
            }
            const double *q = m->xyz + 3 * (size_t)w;
            if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) {
                n++;
                int32_t ra = uf_find(parent, v), rb = uf_find(parent, w);
                if (ra != rb)
                    parent[ra] = rb;
                break;
            }
            i = (i + 1) & (cap - 1);
        }
    }
    return n;
}

/* Referenced vertices at the position of another (texture seams, unmerged
 * STL corners): their count, and the components the surface would have
 * with each such group welded into one vertex. `parent` is the
 * union-find of the face components (build_components), reused. Vertices
 * at one position lie in one run of equal order keys (mfmm_order_build;
 * key NULL: all vertices one run), which is searched only when it holds
 * more than one vertex: pairwise when short, else by a hash table. */
static mfmm_status coincident_vertices(mfmm_mesh *m, int32_t *parent, const uint64_t *key)
{
    int32_t n_coincident = 0, *table = NULL;
    size_t table_cap = 0;
    for (int32_t a = 0, b; a < m->nv; a = b) {
        b = a + 1;
        while (b < m->nv && (!key || key[b] == key[a]))
            b++;
        if (b - a <= 16) {
            for (int32_t v = a + 1; v < b; v++) {
                if (m->vertex_face_offset[v] == m->vertex_face_offset[v + 1])
                    continue;
                const double *p = m->xyz + 3 * (size_t)v;
                for (int32_t w = a; w < v; w++) {
                    const double *q = m->xyz + 3 * (size_t)w;
                    if (m->vertex_face_offset[w] == m->vertex_face_offset[w + 1] ||
                        !(p[0] == q[0] && p[1] == q[1] && p[2] == q[2]))
                        continue;
                    n_coincident++;
                    int32_t ra = uf_find(parent, v), rb = uf_find(parent, w);
                    if (ra != rb)
                        parent[ra] = rb;
                    break;
                }
            }
            continue;
        }
        size_t cap = mfmm_position_table_size((size_t)(b - a));
        if (cap > table_cap) {
            free(table);
            table = malloc(cap * sizeof *table);
            table_cap = cap;
            if (!table)
                return MFMM_ERR_OUT_OF_MEMORY;
        }
        for (size_t i = 0; i < cap; i++)
            table[i] = -1;
        n_coincident += coincident_hashed(m, parent, a, b, table, cap);
    }
    free(table);
    int32_t n_welded = 0;
    for (int32_t v = 0; v < m->nv; v++)
        if (m->vertex_face_offset[v] != m->vertex_face_offset[v + 1] && uf_find(parent, v) == v)
            n_welded++;
    m->info.n_coincident_vertices = n_coincident;
    m->info.n_welded_components = n_welded;
    return MFMM_OK;
}

/* Connected components (through faces) of referenced vertices: their count
 * (the ids are not kept), as the roots of the faces' union-find (an
 * unreferenced vertex stays a root of its own); then coincident_vertices,
 * with the vertices' order keys. */
static mfmm_status build_components(mfmm_mesh *m, const uint64_t *key)
{
    int32_t *parent = malloc((size_t)m->nv * sizeof *parent);
    if (!parent)
        return MFMM_ERR_OUT_OF_MEMORY;
    for (int32_t v = 0; v < m->nv; v++)
        parent[v] = v;
    for (int32_t f = 0; f < m->nf; f++) {
        int32_t r0 = uf_find(parent, m->face_records[f].v[0]);
        for (int k = 1; k < 3; k++) {
            int32_t r = uf_find(parent, m->face_records[f].v[k]);
            if (r != r0)
                parent[r] = r0;
        }
    }
    int32_t n_comp = 0, n_unref = 0;
    for (int32_t v = 0; v < m->nv; v++) {
        if (m->vertex_face_offset[v] == m->vertex_face_offset[v + 1])
            n_unref++;
        else
            n_comp += uf_find(parent, v) == v;
    }
    m->info.n_components = n_comp;
    m->info.n_unreferenced_vertices = n_unref;
    mfmm_status st = coincident_vertices(m, parent, key);
    free(parent);
    return st;
}

static void sub3(double *o, const double *a, const double *b)
{
    o[0] = a[0] - b[0];
    o[1] = a[1] - b[1];
    o[2] = a[2] - b[2];
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* A growable list of the obtuse corners, in corner order. */
typedef struct obtuse_list {
    mfmm_obtuse *at;
    int32_t n, cap;
} obtuse_list;

static int obtuse_push(obtuse_list *l, int32_t corner)
{
    if (l->n == l->cap) {
        if (l->cap > INT32_MAX / 2)
            return 0;
        int32_t cap = l->cap ? 2 * l->cap : 1024;
        mfmm_obtuse *p = realloc(l->at, (size_t)cap * sizeof *p);
        if (!p)
            return 0;
        l->at = p;
        l->cap = cap;
    }
    l->at[l->n++].corner = corner;
    return 1;
}

/* The face records' lengths and cosines (NaN: zero area,
 * mfmm_mesh_degenerate), no virtual edge yet; degenerate faces; the obtuse
 * corners, listed in ob. */
static mfmm_status build_corners(mfmm_mesh *m, obtuse_list *ob)
{
    int32_t n_degenerate = 0;
    for (int32_t f = 0; f < m->nf; f++) {
        mfmm_face *r = m->face_records + f;
        const int32_t *fv = r->v;
        double e[3][3], len[3]; /* e[k]: edge opposite corner k, from k+1 to k+2 */
        for (int k = 0; k < 3; k++) {
            sub3(e[k], m->xyz + 3 * (size_t)fv[(k + 2) % 3], m->xyz + 3 * (size_t)fv[(k + 1) % 3]);
            len[k] = sqrt(dot3(e[k], e[k]));
        }
        /* zero area up to rounding (twice the area |e0 x e1| <= 64 eps lmax^2),
         * tested on unit vectors so that no length is squared twice: no
         * triangle update there, edges only */
        double lmax = max_d(len[0], max_d(len[1], len[2]));
        int degenerate = !(len[0] > 0.0 && len[1] > 0.0);
        if (!degenerate) {
            double u0[3], u1[3];
            for (int d = 0; d < 3; d++) {
                u0[d] = e[0][d] / len[0];
                u1[d] = e[1][d] / len[1];
            }
            double cr[3] = {u0[1] * u1[2] - u0[2] * u1[1], u0[2] * u1[0] - u0[0] * u1[2],
                            u0[0] * u1[1] - u0[1] * u1[0]};
            double sine = sqrt(dot3(cr, cr));
            degenerate = !(sine > 64.0 * DBL_EPSILON * (lmax / len[0]) * (lmax / len[1]));
        }
        n_degenerate += degenerate;
        r->virt = 3;
        for (int k = 0; k < 3; k++) {
            r->len[k] = len[k];
            if (degenerate) {
                r->cosv[k] = NAN;
                continue;
            }
            int ka = (k + 1) % 3, kb = (k + 2) % 3;
            /* cos at C from the edge vectors C->A = e[kb], C->B = -e[ka] */
            double cosv = -dot3(e[kb], e[ka]) / (len[kb] * len[ka]);
            /* (NaN, where the lengths' product underflows, to 1, as fmin) */
            cosv = cosv < 1.0 ? cosv : 1.0;
            r->cosv[k] = max_d(-1.0, cosv);
            /* until unfolding finds its virtual edge */
            if (r->cosv[k] < MFMM_OBTUSE_COS && !obtuse_push(ob, 3 * f + k))
                return MFMM_ERR_OUT_OF_MEMORY;
        }
    }
    m->info.n_degenerate_faces = n_degenerate;
    m->info.n_obtuse_corners = ob->n;
    return MFMM_OK;
}

/* The march's records from the obtuse corners (in corner order): each face
 * record's obtuse corner with a virtual edge (its vertices, lengths and
 * cosines are in place: mesh creation, build_corners), and one mfmm_virt per
 * obtuse corner whose virtual edge unfolding found, sorted by V (counting
 * sort, so by corner within one V), the face naming V (the march reads the
 * record from V's list once V is Alive). The strips' vertices (for the
 * virtual stencils' cost test) per virtual edge but V, in virts' order (the
 * strips' other fields are re-walked when needed, mfmm_strip_next), from
 * far, the strips' vertices as unfolding found them. */
static mfmm_status build_records(mfmm_mesh *m, const mfmm_obtuse *ob, int32_t n_ob,
                                 const int32_t *far)
{
    size_t n_steps = 0;
    size_t n_virts = 0;
    for (int32_t i = 0; i < n_ob; i++)
        if (ob[i].virt >= 0) {
            n_virts++;
            n_steps += (size_t)ob[i].strip_n - 1; /* (V aside) */
        }
    if (n_steps > (size_t)INT32_MAX)
        return MFMM_ERR_BAD_COUNT;
    if (n_virts > (size_t)INT32_MAX ||
        (n_virts > 0 && m->nv > INT32_MAX / 4)) /* (mfmm_face.virt packs 4 V + k) */
        return MFMM_ERR_BAD_COUNT;
    m->n_virts = (int32_t)n_virts;
    m->virts = malloc((n_virts ? n_virts : 1) * sizeof *m->virts);
    m->virt_first = calloc((size_t)m->nv + 1, sizeof *m->virt_first);
    m->virt_strip = malloc((n_virts + 1) * sizeof *m->virt_strip);
    m->strip = malloc((n_steps ? n_steps : 1) * sizeof *m->strip);
    /* each virtual edge's obtuse corner */
    int32_t *from = malloc((n_virts ? n_virts : 1) * sizeof *from);
    if (!m->virts || !m->virt_first || !m->virt_strip || !m->strip || !from) {
        free(from);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    int32_t *first = m->virt_first;
    for (int32_t i = 0; i < n_ob; i++)
        if (ob[i].virt >= 0)
            first[ob[i].virt + 1]++;
    for (int32_t v = 0; v < m->nv; v++)
        first[v + 1] += first[v];
    for (int32_t i = 0; i < n_ob; i++) {
        const mfmm_obtuse *x = ob + i;
        if (x->virt < 0)
            continue;
        int32_t f = x->corner / 3, k = x->corner % 3;
        int32_t at = first[x->virt]++;
        mfmm_virt *vr = m->virts + at;
        vr->corner = x->corner;
        vr->c = m->face_records[f].v[k];
        vr->len = x->len;
        vr->cos_a = x->cos_a;
        vr->cos_b = x->cos_b;
        m->face_records[f].virt = 4 * x->virt + k;
        m->virt_strip[at + 1] = x->strip_n - 1;
        from[at] = i;
    }
    for (int32_t v = m->nv; v > 0; v--)
        first[v] = first[v - 1];
    first[0] = 0;
    m->virt_strip[0] = 0;
    for (size_t j = 0; j < n_virts; j++) {
        const mfmm_obtuse *x = ob + from[j];
        int32_t at = m->virt_strip[j];
        for (int32_t i = 0; i < x->strip_n - 1; i++)
            m->strip[at + i] = far[x->strip_at + i];
        m->virt_strip[j + 1] += at;
    }
    free(from);
    return MFMM_OK;
}

mfmm_status mfmm_mesh_build(const double *vertices, int32_t nv, const int32_t *faces,
                            int32_t nf, const mfmm_mesh_options *options, mfmm_mesh **out,
                            mfmm_error *err)
{
    mfmm_mesh_options opt = *options;
    mfmm_status st;
    mfmm_mesh *m = calloc(1, sizeof *m);
    if (!m)
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, NULL);
    if (pthread_mutex_init(&m->cache_lock, NULL) != 0) {
        free(m);
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "cannot make the mesh's lock");
    }
    m->nv = nv;
    m->nf = nf;
    m->nf_in = nf;
    m->spokes_allowed = opt.spokes;
    size_t nc = (size_t)nf * 3;
    m->xyz = malloc((size_t)nv * 3 * sizeof *m->xyz);
    /* the face records, on cache-line boundaries (one record, one line):
     * their vertices once the faces are ordered, the rest once the corners
     * are known */
    m->face_block = malloc((size_t)nf * sizeof *m->face_records + 64);
    if (m->face_block)
        m->face_records = (mfmm_face *)(void *)((char *)m->face_block +
                                                (64 - (uintptr_t)m->face_block % 64) % 64);
    m->face_neighbor = malloc(nc * sizeof *m->face_neighbor);
    if (!m->xyz || !m->face_block || !m->face_neighbor) {
        mfmm_mesh_destroy(m);
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, NULL);
    }
    /* renumbered: coordinates in internal order, faces' vertex ids mapped
     * (face_neighbor holds them in input face order until the faces are
     * ordered by them and build_faces copies them) */
    uint64_t *vkey = NULL; /* the vertices' order keys, until build_components */
    st = mfmm_order_build(vertices, nv, &m->to_internal, &m->to_external, &vkey);
    if (st == MFMM_OK) {
        for (int32_t v = 0; v < nv; v++)
            memcpy(m->xyz + 3 * (size_t)v, vertices + 3 * (size_t)m->to_external[v],
                   3 * sizeof *m->xyz);
        for (size_t c = 0; c < nc; c++)
            m->face_neighbor[c] = m->to_internal[faces[c]];
        st = mfmm_order_faces(m->face_neighbor, nf, nv, &m->face_to_internal,
                              &m->face_to_external);
    }
    m->info.n_vertices = nv;
    m->info.n_faces = nf;

    int32_t dmax = 0;
    obtuse_list ob = {NULL, 0, 0};
    int32_t *far = NULL;
    uint8_t *copy = NULL;
    if (st == MFMM_OK)
        st = build_faces(m, &dmax, &copy);
    if (st == MFMM_OK)
        st = build_corners(m, &ob);
    if (st == MFMM_OK)
        st = build_edges(m, dmax, copy);
    free(copy);
    if (st == MFMM_OK)
        st = build_components(m, vkey);
    free(vkey);
    if (st == MFMM_OK)
        st = mfmm_mesh_unfold_obtuse(m, opt.max_unfold_steps, ob.at, ob.n, &far);
    if (st == MFMM_OK)
        st = build_records(m, ob.at, ob.n, far);
    free(ob.at);
    free(far);
    if (st != MFMM_OK) {
        mfmm_mesh_destroy(m);
        return mfmm_fail(err, st, -1, NULL);
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int32_t v = 0; v < nv; v++) {
        if (m->vertex_face_offset[v] == m->vertex_face_offset[v + 1])
            continue; /* unreferenced */
        for (int k = 0; k < 3; k++) {
            lo[k] = min_d(lo[k], m->xyz[3 * (size_t)v + k]);
            hi[k] = max_d(hi[k], m->xyz[3 * (size_t)v + k]);
        }
    }
    /* hypot: squares of 1e-200 underflow to 0 */
    m->info.bbox_diagonal = hypot(hypot(hi[0] - lo[0], hi[1] - lo[1]), hi[2] - lo[2]);
    /* below this, squared lengths underflow and every edge would measure 0 */
    if (!(m->info.bbox_diagonal >= MFMM_MIN_DIAGONAL)) {
        double diag = m->info.bbox_diagonal;
        mfmm_mesh_destroy(m);
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1,
                         "the mesh's bounding box diagonal is %g; it must be at least %g "
                         "(rescale the mesh)",
                         diag, MFMM_MIN_DIAGONAL);
    }
    *out = m;
    return MFMM_OK;
}
