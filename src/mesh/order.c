/* Vertex renumbering along a space-filling curve over the bounding cube
 * (cells of about 64 vertices in Morton order, rows inside a cell), faces
 * along it, and the mapping of public arguments and results (order.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "order.h"

/* MFMM_VERTEX_ORDER, for A/B runs: 1 Morton cells, rows inside (default),
 * 0 the input order. Cells keep a march's neighbours near in memory on
 * large meshes; the variants compared with it (Morton at full resolution,
 * Hilbert, breadth-first) are in docs/performance.md#design-measurements. */
#ifndef MFMM_VERTEX_ORDER
#define MFMM_VERTEX_ORDER 1
#endif

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

/* 21 bits of x spread to every third bit */
static uint64_t spread3(uint64_t x)
{
    x &= 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffULL;
    x = (x | x << 16) & 0x1f0000ff0000ffULL;
    x = (x | x << 8) & 0x100f00f00f00f00fULL;
    x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
    x = (x | x << 2) & 0x1249249249249249ULL;
    return x;
}

/* The vertex keys' radix sort: 6 digits of 11 bits cover their 63. */
enum { RADIX_PASSES = 6 };

/* Sorts key (n,) ascending, carrying id along, stably: least significant
 * digit first, a pass skipped where every key has the same digit. key2,
 * id2: scratch of n; count: RADIX_PASSES tables; the result may end in
 * either pair, the one returned (0: key, id; 1: key2, id2). */
static int radix_sort(uint64_t *key, int32_t *id, uint64_t *key2, int32_t *id2, size_t n,
                      uint32_t (*count)[2048])
{
    enum { PASSES = RADIX_PASSES };
    memset(count, 0, PASSES * sizeof *count);
    for (size_t i = 0; i < n; i++)
        for (int p = 0; p < PASSES; p++)
            count[p][key[i] >> (11 * p) & 2047]++;
    int in2 = 0;
    for (int p = 0; p < PASSES; p++) {
        uint32_t *c = count[p];
        if (n == 0 || c[key[0] >> (11 * p) & 2047] == n)
            continue;
        uint32_t at = 0;
        for (int d = 0; d < 2048; d++) {
            uint32_t t = c[d];
            c[d] = at;
            at += t;
        }
        const uint64_t *k_in = in2 ? key2 : key;
        const int32_t *i_in = in2 ? id2 : id;
        uint64_t *k_out = in2 ? key : key2;
        int32_t *i_out = in2 ? id : id2;
        for (size_t i = 0; i < n; i++) {
            uint32_t to = c[k_in[i] >> (11 * p) & 2047]++;
            k_out[to] = k_in[i];
            i_out[to] = i_in[i];
        }
        in2 = !in2;
    }
    return in2;
}

mfmm_status mfmm_order_build(const double *xyz, int32_t nv, int32_t **to_internal,
                             int32_t **to_external, uint64_t **sorted_keys)
{
    *sorted_keys = NULL;
    int32_t *in = malloc((size_t)nv * sizeof *in);
    int32_t *ex = malloc((size_t)nv * sizeof *ex);
    uint64_t *keys = MFMM_VERTEX_ORDER ? malloc(2 * (size_t)nv * sizeof *keys) : NULL;
    uint32_t(*count)[2048] = MFMM_VERTEX_ORDER ? malloc(RADIX_PASSES * sizeof *count) : NULL;
    if (!in || !ex || (MFMM_VERTEX_ORDER && (!keys || !count))) {
        free(in);
        free(ex);
        free(keys);
        free(count);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    if (!keys) {
        for (int32_t v = 0; v < nv; v++)
            ex[v] = v;
    } else {
        double lo[3] = {INFINITY, INFINITY, INFINITY}, ext = 0.0;
        for (int32_t v = 0; v < nv; v++)
            for (int k = 0; k < 3; k++)
                lo[k] = min_d(lo[k], xyz[3 * (size_t)v + k]);
        for (int32_t v = 0; v < nv; v++)
            for (int k = 0; k < 3; k++)
                ext = max_d(ext, xyz[3 * (size_t)v + k] - lo[k]);
        /* one cube (not a box per axis), so the curve keeps the shape's
         * proportions; 21 bits per axis */
        double scale = ext > 0.0 ? 2097151.0 / ext : 0.0;
        /* a subnormal extent makes the scale infinite, and 0 * inf NaN (the
         * mesh is refused later for its tiny diagonal; the order must not
         * fault before that) */
        if (!isfinite(scale))
            scale = 0.0;
        /* cells of ~64 vertices (a surface has about nv / 4^L cells at
         * level L) along the curve; inside a cell, rows by position (y,
         * then x, then z), which beat the curve's own order at that scale */
        int L = 0;
        while (L < 21 && ((double)nv / 64.0) > (double)(1u << L) * (double)(1u << L))
            L++;
        int shift = 21 - L;
        uint32_t low = (1u << shift) - 1;
        /* one key of 63 bits: the cell's 3 L curve bits above the 3 (21 -
         * L) bits the cell leaves, rows' order; ties in input order */
        for (int32_t v = 0; v < nv; v++) {
            uint32_t u[3];
            for (int k = 0; k < 3; k++) {
                double q = (xyz[3 * (size_t)v + k] - lo[k]) * scale;
                u[k] = !(q > 0.0) ? 0u : q > 2097151.0 ? 2097151u : (uint32_t)q;
            }
            uint64_t cell = spread3(u[0] >> shift) | spread3(u[1] >> shift) << 1 |
                            spread3(u[2] >> shift) << 2;
            uint64_t fine = (uint64_t)(u[1] & low) << (2 * shift) |
                            (uint64_t)(u[0] & low) << shift | (u[2] & low);
            keys[v] = cell << (3 * shift) | fine;
            in[v] = v;
        }
        if (!radix_sort(keys, in, keys + nv, ex, (size_t)nv, count))
            memcpy(ex, in, (size_t)nv * sizeof *ex);
        else
            memcpy(keys, keys + nv, (size_t)nv * sizeof *keys);
        free(count);
        /* (a failed shrink leaves the block as it was) */
        uint64_t *shrunk = realloc(keys, (size_t)nv * sizeof *keys);
        *sorted_keys = shrunk ? shrunk : keys;
    }
    for (int32_t i = 0; i < nv; i++)
        in[ex[i]] = i;
    *to_internal = in;
    *to_external = ex;
    return MFMM_OK;
}

/* A face's other two vertex ids (b < c) as b << 32 | c, with its input id. */
typedef struct face_key {
    uint64_t bc;
    int32_t id;
} face_key;

static int face_key_cmp(const void *pa, const void *pb)
{
    const face_key *a = pa, *b = pb;
    if (a->bc != b->bc)
        return a->bc < b->bc ? -1 : 1;
    return (a->id > b->id) - (a->id < b->id);
}

mfmm_status mfmm_order_faces(const int32_t *faces, int32_t nf, int32_t nv,
                             int32_t **to_internal, int32_t **to_external)
{
    size_t n = (size_t)nf;
    int32_t *in = malloc((n ? n : 1) * sizeof *in);
    int32_t *ex = malloc((n ? n : 1) * sizeof *ex);
    face_key *key = malloc((n ? n : 1) * sizeof *key);
    int32_t *count = calloc((size_t)nv + 1, sizeof *count);
    if (!in || !ex || !key || !count) {
        free(in);
        free(ex);
        free(key);
        free(count);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    /* by least vertex (a counting sort, stable), then within each least
     * vertex's few faces by the other two and the input id */
    for (size_t f = 0; f < n; f++) {
        int32_t a = faces[3 * f], b = faces[3 * f + 1], c = faces[3 * f + 2];
        int32_t lo = a < b ? a : b;
        count[(lo < c ? lo : c) + 1]++;
    }
    for (int32_t v = 0; v < nv; v++)
        count[v + 1] += count[v];
    for (size_t f = 0; f < n; f++) {
        int32_t a = faces[3 * f], b = faces[3 * f + 1], c = faces[3 * f + 2], t;
        if (a > b)
            t = a, a = b, b = t;
        if (b > c)
            t = b, b = c, c = t;
        if (a > b)
            t = a, a = b, b = t;
        int32_t to = count[a]++;
        key[to].bc = (uint64_t)b << 32 | (uint32_t)c;
        key[to].id = (int32_t)f;
    }
    for (int32_t v = 0, at = 0; v < nv; v++) {
        int32_t end = count[v], m = end - at;
        face_key *k = key + at;
        if (m > 32) {
            qsort(k, (size_t)m, sizeof *k, face_key_cmp);
        } else {
            /* ids ascend in a bucket (the scatter is stable): by bc alone */
            for (int32_t i = 1; i < m; i++) {
                face_key x = k[i];
                int32_t j = i;
                for (; j > 0 && k[j - 1].bc > x.bc; j--)
                    k[j] = k[j - 1];
                k[j] = x;
            }
        }
        at = end;
    }
    for (size_t i = 0; i < n; i++) {
        ex[i] = key[i].id;
        in[key[i].id] = (int32_t)i;
    }
    free(key);
    free(count);
    *to_internal = in;
    *to_external = ex;
    return MFMM_OK;
}

void mfmm_order_points_out(const mfmm_mesh *mesh, mfmm_surface_point *points, int32_t n)
{
    for (int32_t i = 0; i < n; i++) {
        int32_t f = points[i].face;
        points[i].face = mesh->face_to_external[f];
        if (!mesh->piece_bary)
            continue;
        const double *K = mesh->piece_bary + 9 * (size_t)f, *b = points[i].bary;
        double out[3];
        for (int c = 0; c < 3; c++)
            out[c] = b[0] * K[c] + b[1] * K[3 + c] + b[2] * K[6 + c];
        memcpy(points[i].bary, out, sizeof out);
    }
}

int32_t mfmm_order_point_in(const mfmm_mesh *mesh, int32_t f, const double b[3], double out[3])
{
    int32_t g = mesh->face_to_internal[f];
    if (!mesh->piece_bary || g < 0 || mesh->piece_next[g] < 0) {
        if (out != b)
            memcpy(out, b, 3 * sizeof *out);
        return g;
    }
    /* b = beta K (K's rows: the piece's corners in f's coordinates), solved
     * by the adjugate of K; the piece where min(beta) is largest */
    int32_t best = -1;
    double best_beta[3] = {0.0, 0.0, 0.0}, best_min = -INFINITY;
    for (int32_t p = g; p >= 0; p = mesh->piece_next[p]) {
        const double *K = mesh->piece_bary + 9 * (size_t)p;
        double adj[9];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) {
                int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (c + 1) % 3, c2 = (c + 2) % 3;
                /* inverse's (c, r) entry, times det */
                adj[3 * c + r] = K[3 * r1 + c1] * K[3 * r2 + c2] - K[3 * r1 + c2] * K[3 * r2 + c1];
            }
        double det = K[0] * adj[0] + K[1] * adj[3] + K[2] * adj[6];
        double beta[3];
        for (int j = 0; j < 3; j++)
            beta[j] = (b[0] * adj[j] + b[1] * adj[3 + j] + b[2] * adj[6 + j]) / det;
        double lo = fmin(beta[0], fmin(beta[1], beta[2]));
        if (best < 0 || lo > best_min) {
            best = p;
            best_min = lo;
            memcpy(best_beta, beta, sizeof beta);
        }
    }
    /* on a cut between pieces, rounding may leave -1e-17: none below 0 */
    double sum = 0.0;
    for (int j = 0; j < 3; j++)
        sum += (best_beta[j] = fmax(best_beta[j], 0.0));
    for (int j = 0; j < 3; j++)
        out[j] = best_beta[j] / sum;
    return best;
}

int mfmm_order_point_degenerate(const mfmm_mesh *mesh, int32_t f, const double b[3])
{
    double inner[3];
    int32_t g = mfmm_order_point_in(mesh, f, b, inner);
    return g < 0 || mfmm_mesh_degenerate(mesh, g);
}

void mfmm_order_face_values_in(const mfmm_mesh *mesh, const double *in, double *out)
{
    for (int32_t f = 0; f < mesh->nf; f++)
        out[f] = in[mesh->face_to_external[f]];
}

void mfmm_order_ids_in(const mfmm_mesh *mesh, const int32_t *ids, int32_t n, int32_t *out)
{
    for (int32_t i = 0; i < n; i++)
        out[i] = mesh->to_internal[ids[i]];
}

void mfmm_order_values_in(const mfmm_mesh *mesh, const double *in, double *out)
{
    for (int32_t v = 0; v < mesh->nv; v++)
        out[v] = in[mesh->to_external[v]];
}

void mfmm_order_values_out(const mfmm_mesh *mesh, const double *in, double *out)
{
    for (int32_t v = 0; v < mesh->nv; v++)
        out[v] = in[mesh->to_internal[v]];
}

/* bytes rounded up to a multiple of 8 (doubles follow) */
static size_t align8(size_t n)
{
    return (n + 7) & ~(size_t)7;
}

mfmm_status mfmm_order_map_args(const mfmm_mesh *mesh, const mfmm_source *sources,
                                int32_t n_sources, const int32_t *targets, int32_t n_targets,
                                const double *cost, int cost_location, const double *values,
                                mfmm_mapped_args *a)
{
    size_t nv = (size_t)mesh->nv;
    size_t b_src = sources ? (size_t)n_sources * sizeof(mfmm_source) : 0;
    size_t b_tgt = targets ? align8((size_t)n_targets * sizeof(int32_t)) : 0;
    size_t b_cost = !cost ? 0
                    : cost_location == 1 ? nv * sizeof(double)
                    : cost_location == 2 ? (size_t)mesh->nf * sizeof(double)
                                         : 0;
    size_t b_val = values ? nv * sizeof(double) : 0;
    size_t need = b_src + b_tgt + b_cost + b_val;
    if (need > a->capacity) {
        void *p = malloc(need);
        if (!p)
            return MFMM_ERR_OUT_OF_MEMORY;
        free(a->block);
        a->block = p;
        a->capacity = need;
    }
    char *at = a->block;
    a->sources = NULL;
    a->targets = NULL;
    a->cost = cost;
    a->values = NULL;
    if (b_src) {
        mfmm_source *s = (mfmm_source *)(void *)at;
        memcpy(s, sources, b_src);
        for (int32_t i = 0; i < n_sources; i++)
            if (s[i].face < 0)
                s[i].vertex = mesh->to_internal[s[i].vertex];
            else
                s[i].face = mfmm_order_point_in(mesh, s[i].face, s[i].bary, s[i].bary);
        a->sources = s;
        at += b_src;
    }
    if (b_tgt) {
        int32_t *t = (int32_t *)(void *)at;
        mfmm_order_ids_in(mesh, targets, n_targets, t);
        a->targets = t;
        at += b_tgt;
    }
    if (b_cost) {
        double *c = (double *)(void *)at;
        if (cost_location == 1)
            mfmm_order_values_in(mesh, cost, c);
        else
            mfmm_order_face_values_in(mesh, cost, c);
        a->cost = c;
        at += b_cost;
    }
    if (b_val) {
        double *t = (double *)(void *)at;
        mfmm_order_values_in(mesh, values, t);
        a->values = t;
    }
    return MFMM_OK;
}
