/* Geodesic Voronoi labels (mfmm_voronoi_labels): which source a
 * many-source distance field came from, by one pass over the vertices'
 * edges (each vertex's parent: the lower neighbour u minimizing
 * T(u) + |uv|, or its own source) and a walk up the parents. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "mesh/check.h"
#include "mesh/mesh.h"
#include "mesh/order.h"

static double dist3(const double *a, const double *b)
{
    double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
    return sqrt(x * x + y * y + z * z);
}

mfmm_status mfmm_voronoi_labels(const mfmm_mesh *mesh, const double *distances,
                                const mfmm_source *sources, int32_t n_sources,
                                int32_t *labels, mfmm_error *err)
{
    mfmm_ok(err);
    if (!mesh || !distances || !sources || !labels)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "%s is NULL",
                         !mesh ? "mesh" : !distances ? "distances" : !sources ? "sources"
                                                                              : "labels");
    if (n_sources < 1)
        return mfmm_fail(err, MFMM_ERR_BAD_COUNT, -1, "n_sources must be >= 1 (got %ld)",
                         (long)n_sources);
    int32_t nv = mesh->nv;
    for (int32_t v = 0; v < nv; v++)
        if (isnan(distances[v]))
            return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, v, "distances[%ld] is NaN", (long)v);
    for (int32_t i = 0; i < n_sources; i++) {
        mfmm_status st = mfmm_check_source(mesh, sources + i, i, err);
        if (st != MFMM_OK)
            return st;
    }
    double *T = malloc((size_t)nv * sizeof *T);
    double *key = malloc((size_t)nv * sizeof *key);
    int32_t *parent = malloc((size_t)nv * sizeof *parent); /* >= 0: a vertex; -1 - s: source s */
    int32_t *lab = malloc((size_t)nv * sizeof *lab);
    double *pos = malloc(3 * (size_t)n_sources * sizeof *pos);
    if (!T || !key || !parent || !lab || !pos) {
        free(T);
        free(key);
        free(parent);
        free(lab);
        free(pos);
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory");
    }
    mfmm_order_values_in(mesh, distances, T);
    for (int32_t v = 0; v < nv; v++) {
        key[v] = INFINITY;
        parent[v] = INT32_MIN; /* none */
        lab[v] = -2;           /* unresolved */
    }
    /* the sources: a vertex source names its vertex (where its value is
     * T there); a point in a face names the corners of its face, at
     * value + the straight distance (the distance inside the face) */
    for (int32_t i = 0; i < n_sources; i++) {
        const mfmm_source *s = sources + i;
        if (s->face == -1) {
            int32_t v = mesh->to_internal[s->vertex];
            memcpy(pos + 3 * (size_t)i, mesh->xyz + 3 * (size_t)v, 3 * sizeof *pos);
            if (s->value <= T[v] && s->value < key[v]) {
                key[v] = s->value;
                parent[v] = -1 - i;
            }
            continue;
        }
        int32_t f = mesh->face_to_internal[s->face];
        const int32_t *c = mesh->face_records[f].v;
        double *p = pos + 3 * (size_t)i;
        p[0] = p[1] = p[2] = 0.0;
        /* (a face split at a T-junction: its first piece's corners) */
        for (int k = 0; k < 3; k++)
            for (int d = 0; d < 3; d++)
                p[d] += s->bary[k] * mesh->xyz[3 * (size_t)c[k] + d];
        for (int k = 0; k < 3; k++) {
            double x = s->value + dist3(p, mesh->xyz + 3 * (size_t)c[k]);
            if (x < key[c[k]]) {
                key[c[k]] = x;
                parent[c[k]] = -1 - i;
            }
        }
    }
    /* each vertex's parent: its own source, or the lower neighbour that
     * explains T best (a vertex source wins a tie) */
    for (int32_t v = 0; v < nv; v++) {
        if (!(T[v] < INFINITY)) {
            lab[v] = -1;
            continue;
        }
        const double *xv = mesh->xyz + 3 * (size_t)v;
        for (int32_t j = mesh->vertex_face_offset[v]; j < mesh->vertex_face_offset[v + 1]; j++) {
            int32_t w = mesh->vertex_wedge[j];
            const int32_t *c = mesh->face_records[MFMM_WEDGE_FACE(w)].v;
            int32_t nb[2] = {c[MFMM_WEDGE_NEXT(w)], c[MFMM_WEDGE_PREV(w)]};
            for (int e = 0; e < 2; e++) {
                int32_t u = nb[e];
                if (!(T[u] < T[v]))
                    continue;
                double x = T[u] + dist3(xv, mesh->xyz + 3 * (size_t)u);
                if (x < key[v] || (x == key[v] && parent[v] >= 0 && u < parent[v])) {
                    key[v] = x;
                    parent[v] = u;
                }
            }
        }
        if (parent[v] == INT32_MIN) {
            /* no lower neighbour and no source here (a degenerate fan):
             * the source nearest in a straight line */
            double best = INFINITY;
            for (int32_t i = 0; i < n_sources; i++) {
                double x = sources[i].value + dist3(xv, pos + 3 * (size_t)i);
                if (x < best) {
                    best = x;
                    parent[v] = -1 - i;
                }
            }
        }
    }
    /* labels: up the parents (T strictly decreases along them: no circle),
     * then down again; `key` is reused as the stack */
    int32_t *stack = (int32_t *)(void *)key;
    for (int32_t v = 0; v < nv; v++) {
        int32_t n = 0, u = v;
        while (lab[u] == -2 && parent[u] >= 0) {
            stack[n++] = u;
            u = parent[u];
        }
        int32_t l = lab[u] != -2 ? lab[u] : -1 - parent[u];
        lab[u] = l;
        while (n > 0)
            lab[stack[--n]] = l;
    }
    for (int32_t v = 0; v < nv; v++)
        labels[mesh->to_external[v]] = lab[v];
    free(T);
    free(key);
    free(parent);
    free(lab);
    free(pos);
    return MFMM_OK;
}
