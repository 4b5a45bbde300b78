/* Isolines of a per-vertex field (mfmm_isolines): one pass over the faces
 * for all the values (each vertex's rank among the sorted values, each
 * face's least and greatest corner rank: the values it crosses), then per
 * value its segments, joined into polylines through a hash map from each
 * edge to the segment ends on it. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "mesh/mesh.h"
#include "mesh/order.h"

typedef struct sorted_value {
    double x;
    int32_t i;
} sorted_value;

static int cmp_value(const void *a, const void *b)
{
    const sorted_value *p = a, *q = b;
    if (p->x != q->x)
        return p->x < q->x ? -1 : 1;
    return (p->i > q->i) - (p->i < q->i);
}

/* The count of sv[0..n) <= x (sv ascending, n >= 1), without branches on
 * the data (a field's ranks are not predictable). */
static int32_t rank_of(const double *sv, int32_t n, double x)
{
    const double *base = sv;
    while (n > 1) {
        int32_t half = n / 2;
        base = base[half] <= x ? base + half : base;
        n -= half;
    }
    return (int32_t)(base - sv) + (*base <= x);
}

/* The segment of internal face p at level c: its two ends (the crossed
 * edges in ascending order, edge k opposite corner k), each interpolated
 * from its edge's lower input vertex id, so that the faces on an edge give
 * the point bit for bit, with its edge as key (lower id * nv + higher);
 * faces and coordinates as given (a piece of a face split at a T-junction
 * mapped to that face; a face not split keeps them as computed, -0.0
 * included). */
static void segment(const mfmm_mesh *mesh, const double *field, int32_t p, double c,
                    mfmm_surface_point end[2], int64_t key[2])
{
    const int32_t *v = mesh->face_records[p].v;
    int32_t F[3] = {mesh->to_external[v[0]], mesh->to_external[v[1]], mesh->to_external[v[2]]};
    int A0 = field[F[0]] >= c, A1 = field[F[1]] >= c, A2 = field[F[2]] >= c;
    /* the edge not crossed: 0 when corners 1 and 2 agree, ... */
    int quiet = A1 == A2 ? 0 : A0 == A2 ? 1 : 2;
    int32_t face = mesh->face_to_external[p];
    const double *K = NULL; /* a piece's corners in its face's coordinates */
    if (mesh->piece_bary && (mesh->piece_next[p] >= 0 || mesh->face_to_internal[face] != p))
        K = mesh->piece_bary + 9 * (size_t)p;
    for (int e = 0; e < 2; e++) {
        int edge = quiet == 0 ? 1 + e : quiet == 1 ? 2 * e : e;
        int klo = (edge + 1) % 3, khi = (edge + 2) % 3;
        if (F[klo] > F[khi]) {
            int k = klo;
            klo = khi;
            khi = k;
        }
        int32_t lo = F[klo], hi = F[khi];
        double dl = field[lo], dh = field[hi];
        double t = (c - dl) / (dh - dl);
        const double *P = mesh->xyz + 3 * (size_t)v[klo], *Q = mesh->xyz + 3 * (size_t)v[khi];
        mfmm_surface_point *out = end + e;
        for (int i = 0; i < 3; i++)
            out->xyz[i] = P[i] + t * (Q[i] - P[i]);
        double *b = out->bary;
        b[0] = b[1] = b[2] = 0.0;
        b[klo] = 1.0 - t;
        b[khi] = t;
        if (K) {
            double x[3];
            for (int k = 0; k < 3; k++)
                x[k] = b[0] * K[k] + b[1] * K[3 + k] + b[2] * K[6 + k];
            memcpy(b, x, sizeof x);
        }
        out->face = face;
        key[e] = (int64_t)lo * mesh->nv + hi;
    }
}

/* Sorts n internal face ids by their input face id, stably (pieces of one
 * input face keep their internal order): an LSD radix sort, tmp of n. */
static void sort_by_input_face(const mfmm_mesh *mesh, int32_t *f, int32_t *tmp, int64_t n)
{
    enum { BITS = 11, BUCKETS = 1 << BITS };
    int64_t count[BUCKETS];
    uint32_t top = (uint32_t)mesh->nf_in - 1; /* the largest key */
    for (int shift = 0; shift < 32 && (top >> shift) != 0; shift += BITS) {
        memset(count, 0, sizeof count);
        for (int64_t i = 0; i < n; i++)
            count[((uint32_t)mesh->face_to_external[f[i]] >> shift) & (BUCKETS - 1)]++;
        int64_t sum = 0;
        for (int b = 0; b < BUCKETS; b++) {
            int64_t c = count[b];
            count[b] = sum;
            sum += c;
        }
        for (int64_t i = 0; i < n; i++)
            tmp[count[((uint32_t)mesh->face_to_external[f[i]] >> shift) & (BUCKETS - 1)]++] = f[i];
        memcpy(f, tmp, (size_t)n * sizeof *f);
    }
}

/* An entry at a node with no other entry (an end of a polyline), by edge. */
typedef struct end_entry {
    int64_t key;
    int32_t ent;
} end_entry;

static int cmp_end(const void *a, const void *b)
{
    const end_entry *p = a, *q = b;
    return (p->key > q->key) - (p->key < q->key);
}

/* One value's join: its segments' ends as entries 2 s + e, grouped by edge
 * (a node) through an open-addressing map; a node's entries in ascending
 * order. Sized for the value with the most segments, reused. */
typedef struct joiner {
    mfmm_surface_point *point; /* (2m,) each entry's point */
    int32_t *node_of;   /* (2m,) each entry's node */
    int32_t *next;      /* (2m,) the node's next entry, -1 after its last */
    int32_t *head;      /* (2m,) per node: its first entry, */
    int32_t *tail;      /* its last, */
    int32_t *deg;       /* its entry count, */
    int64_t *node_key;  /* its edge: lower input id * nv + higher */
    int32_t *table;     /* (table_size,) a node or -1 */
    uint8_t *used;      /* (m,) per segment */
    end_entry *ends;    /* (2m,) */
} joiner;

static void joiner_free(joiner *j)
{
    free(j->point);
    free(j->node_of);
    free(j->next);
    free(j->head);
    free(j->tail);
    free(j->deg);
    free(j->node_key);
    free(j->table);
    free(j->used);
    free(j->ends);
}

/* The map's size for m segments: a power of two >= 4 m (at most half
 * full), and the shift that takes a 64-bit hash to it. */
static size_t table_size(int32_t m, int *shift)
{
    size_t t = 4;
    int s = 62;
    while (t < 4 * (size_t)m) {
        t *= 2;
        s--;
    }
    *shift = s;
    return t;
}

static int joiner_alloc(joiner *j, int32_t m)
{
    int shift;
    size_t e = 2 * (size_t)m, t = table_size(m, &shift);
    j->point = malloc(e * sizeof *j->point);
    j->node_of = malloc(e * sizeof *j->node_of);
    j->next = malloc(e * sizeof *j->next);
    j->head = malloc(e * sizeof *j->head);
    j->tail = malloc(e * sizeof *j->tail);
    j->deg = malloc(e * sizeof *j->deg);
    j->node_key = malloc(e * sizeof *j->node_key);
    j->table = malloc(t * sizeof *j->table);
    j->used = malloc((size_t)m);
    j->ends = malloc(e * sizeof *j->ends);
    return j->point && j->node_of && j->next && j->head && j->tail && j->deg && j->node_key && j->table &&
           j->used && j->ends;
}

/* The arrays handed out, grown as polylines are found. */
typedef struct output {
    mfmm_surface_point *pts;
    int64_t n_pts, cap_pts;
    mfmm_isoline *lines;
    int64_t n_lines, cap_lines;
} output;

/* Room for `need` items of `size` bytes in *p (capacity *cap). 0: no memory. */
static int grow(void **p, int64_t *cap, int64_t need, size_t size)
{
    if (need <= *cap)
        return 1;
    int64_t c = *cap + *cap / 2 + 16;
    if (c < need)
        c = need;
    if ((uint64_t)c > SIZE_MAX / size)
        return 0;
    void *q = realloc(*p, (size_t)c * size);
    if (!q)
        return 0;
    *p = q;
    *cap = c;
    return 1;
}

static int add_point(const mfmm_surface_point *p, output *out)
{
    if (!grow((void **)&out->pts, &out->cap_pts, out->n_pts + 1, sizeof *out->pts))
        return 0;
    out->pts[out->n_pts++] = *p;
    return 1;
}

/* One polyline: entering segment s at its end e, through its other end to
 * the first segment not yet used at that edge, and on, until the edge it
 * started at (a loop) or an edge with no unused segment. 0: no memory. */
static int walk(int32_t jv, joiner *J, int32_t s, int e, output *out)
{
    if (!grow((void **)&out->lines, &out->cap_lines, out->n_lines + 1, sizeof *out->lines))
        return 0;
    int64_t start = out->n_pts;
    if (!add_point(J->point + 2 * s + e, out))
        return 0;
    int32_t first = J->node_of[2 * s + e];
    int32_t closed = 0;
    for (;;) {
        J->used[s] = 1;
        int o = 1 - e;
        if (!add_point(J->point + 2 * s + o, out))
            return 0;
        int32_t node = J->node_of[2 * s + o];
        if (node == first) {
            closed = 1;
            break;
        }
        int32_t next = -1;
        for (int32_t x = J->head[node]; x >= 0; x = J->next[x])
            if (!J->used[x >> 1]) {
                next = x;
                break;
            }
        if (next < 0)
            break;
        s = next >> 1;
        e = next & 1;
    }
    mfmm_isoline *L = out->lines + out->n_lines++;
    L->start = start;
    L->n_points = out->n_pts - start;
    L->value = jv;
    L->closed = closed;
    return 1;
}

/* The polylines of value jv (level c) from its m segments (internal faces
 * seg[0..m), ascending by input face), appended to out. 0: no memory. */
static int join_value(const mfmm_mesh *mesh, const double *field, const int32_t *seg,
                      int32_t m, double c, int32_t jv, joiner *J, output *out)
{
    int shift;
    size_t tsize = table_size(m, &shift);
    int32_t n_nodes = 0;
    memset(J->table, 0xff, tsize * sizeof *J->table);
    for (int32_t s = 0; s < m; s++) {
        int64_t keys[2];
        J->used[s] = 0;
        segment(mesh, field, seg[s], c, J->point + 2 * s, keys);
        for (int e = 0; e < 2; e++) {
            int64_t key = keys[e];
            int32_t ent = 2 * s + e, node;
            size_t h = (size_t)(((uint64_t)key * UINT64_C(0x9E3779B97F4A7C15)) >> shift);
            for (;;) {
                node = J->table[h];
                if (node < 0) {
                    node = n_nodes++;
                    J->table[h] = node;
                    J->node_key[node] = key;
                    J->head[node] = J->tail[node] = ent;
                    J->deg[node] = 1;
                    break;
                }
                if (J->node_key[node] == key) {
                    J->next[J->tail[node]] = ent;
                    J->tail[node] = ent;
                    J->deg[node]++;
                    break;
                }
                h = (h + 1) & (tsize - 1);
            }
            J->next[ent] = -1;
            J->node_of[ent] = node;
        }
    }
    /* first the polylines from their ends, by edge; then the rest (loops,
     * lines between non-manifold edges) from the first unused segment */
    int32_t n_ends = 0;
    for (int32_t node = 0; node < n_nodes; node++)
        if (J->deg[node] == 1) {
            J->ends[n_ends].key = J->node_key[node];
            J->ends[n_ends++].ent = J->head[node];
        }
    qsort(J->ends, (size_t)n_ends, sizeof *J->ends, cmp_end);
    for (int32_t i = 0; i < n_ends; i++) {
        int32_t ent = J->ends[i].ent;
        if (!J->used[ent >> 1] && !walk(jv, J, ent >> 1, ent & 1, out))
            return 0;
    }
    for (int32_t s = 0; s < m; s++)
        if (!J->used[s] && !walk(jv, J, s, 0, out))
            return 0;
    return 1;
}

mfmm_status mfmm_isolines(const mfmm_mesh *mesh, const double *field, const double *values,
                          int32_t n_values, mfmm_surface_point **points, int64_t *n_points,
                          mfmm_isoline **lines, int64_t *n_lines, mfmm_error *err)
{
    mfmm_ok(err);
    if (!mesh || !field || (!values && n_values > 0) || !points || !n_points || !lines ||
        !n_lines)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "%s is NULL",
                         !mesh     ? "mesh"
                         : !field  ? "field"
                         : !values && n_values > 0 ? "values"
                         : !points ? "points"
                         : !n_points ? "n_points"
                         : !lines    ? "lines"
                                     : "n_lines");
    *points = NULL;
    *n_points = 0;
    *lines = NULL;
    *n_lines = 0;
    if (n_values < 0)
        return mfmm_fail(err, MFMM_ERR_BAD_COUNT, -1, "n_values must be >= 0 (got %ld)",
                         (long)n_values);
    for (int32_t i = 0; i < n_values; i++)
        if (!isfinite(values[i]))
            return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, i,
                             "values[%ld] is %g: the levels must be finite", (long)i, values[i]);
    int32_t nv = mesh->nv, nf = mesh->nf;
    for (int32_t v = 0; v < nv; v++)
        if (isnan(field[v]))
            return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, v, "field[%ld] is NaN", (long)v);
    if (n_values == 0)
        return MFMM_OK;

    sorted_value *sorted = malloc((size_t)n_values * sizeof *sorted);
    double *sv = malloc((size_t)n_values * sizeof *sv);
    int32_t *order = malloc((size_t)n_values * sizeof *order);
    int64_t *first = calloc((size_t)n_values + 1, sizeof *first);
    int64_t *fill = malloc((size_t)n_values * sizeof *fill);
    int32_t *rank = malloc((size_t)nv * sizeof *rank);
    int32_t *cross = malloc((size_t)nf * sizeof *cross);
    int32_t *tmp = NULL, *seg = NULL;
    joiner J;
    memset(&J, 0, sizeof J);
    output out;
    memset(&out, 0, sizeof out);
    mfmm_status st = MFMM_OK;
    if (!sorted || !sv || !order || !first || !fill || !rank || !cross)
        goto oom;

    /* the values ascending (ties by index); each vertex's rank: the count
     * of values <= its value, -1 when not finite */
    for (int32_t i = 0; i < n_values; i++) {
        sorted[i].x = values[i];
        sorted[i].i = i;
    }
    qsort(sorted, (size_t)n_values, sizeof *sorted, cmp_value);
    for (int32_t i = 0; i < n_values; i++) {
        sv[i] = sorted[i].x;
        order[i] = sorted[i].i;
    }
    for (int32_t v = 0; v < nv; v++) {
        double x = field[mesh->to_external[v]];
        rank[v] = isfinite(x) ? rank_of(sv, n_values, x) : -1;
    }
    /* the pass over the faces: face p crosses the sorted values
     * k0 <= i < k1 of its corners' least and greatest rank */
    int64_t n_cross = 0;
    for (int32_t p = 0; p < nf; p++) {
        const int32_t *v = mesh->face_records[p].v;
        int32_t a = rank[v[0]], b = rank[v[1]], c = rank[v[2]];
        int32_t k0 = a < b ? a : b, k1 = a < b ? b : a;
        k0 = c < k0 ? c : k0;
        k1 = c > k1 ? c : k1;
        if (k0 < 0 || k1 == k0)
            continue;
        cross[n_cross++] = p;
        for (int32_t i = k0; i < k1; i++)
            first[order[i] + 1]++;
    }
    int64_t mmax = 0;
    for (int32_t j = 0; j < n_values; j++) {
        if (first[j + 1] > mmax)
            mmax = first[j + 1];
        first[j + 1] += first[j];
    }
    int64_t n_seg = first[n_values];
    if (n_seg == 0)
        goto done;
    if (mmax > INT32_MAX / 4 || (uint64_t)n_seg > SIZE_MAX / (2 * sizeof *out.pts))
        goto oom;
    /* each value's segments, by input face */
    tmp = malloc((size_t)n_cross * sizeof *tmp);
    seg = malloc((size_t)n_seg * sizeof *seg);
    if (!tmp || !seg || !joiner_alloc(&J, (int32_t)mmax))
        goto oom;
    sort_by_input_face(mesh, cross, tmp, n_cross);
    memcpy(fill, first, (size_t)n_values * sizeof *fill);
    for (int64_t q = 0; q < n_cross; q++) {
        int32_t p = cross[q];
        const int32_t *v = mesh->face_records[p].v;
        int32_t a = rank[v[0]], b = rank[v[1]], c = rank[v[2]];
        int32_t k0 = a < b ? a : b, k1 = a < b ? b : a;
        k0 = c < k0 ? c : k0;
        k1 = c > k1 ? c : k1;
        for (int32_t i = k0; i < k1; i++)
            seg[fill[order[i]]++] = p;
    }
    /* joined, value by value */
    out.cap_pts = n_seg + n_seg / 8 + 16;
    out.pts = malloc((size_t)out.cap_pts * sizeof *out.pts);
    if (!out.pts)
        goto oom;
    for (int32_t j = 0; j < n_values; j++) {
        int32_t m = (int32_t)(first[j + 1] - first[j]);
        if (m > 0 && !join_value(mesh, field, seg + first[j], m, values[j], j, &J, &out))
            goto oom;
    }
    /* no more room than the result needs */
    void *shrunk = realloc(out.pts, (size_t)out.n_pts * sizeof *out.pts);
    if (shrunk)
        out.pts = shrunk;
    shrunk = realloc(out.lines, (size_t)out.n_lines * sizeof *out.lines);
    if (shrunk)
        out.lines = shrunk;
    *points = out.pts;
    *n_points = out.n_pts;
    *lines = out.lines;
    *n_lines = out.n_lines;
    out.pts = NULL;
    out.lines = NULL;
    goto done;
oom:
    st = mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "no memory for the isolines");
done:
    free(sorted);
    free(sv);
    free(order);
    free(first);
    free(fill);
    free(rank);
    free(cross);
    free(tmp);
    free(seg);
    joiner_free(&J);
    free(out.pts);
    free(out.lines);
    return st;
}
