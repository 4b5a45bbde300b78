/* The exact start's patch: exact distances of the vertices near a source
 * (the exact solver run to a radius), and their check against bounds that
 * any correct distance meets (patch.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "exact/run.h"
#include "exact/state.h"
#include "mesh/check.h"
#include "patch.h"

/* Sources in internal ids (mfmm_check_source_internal): the input ids'
 * check would read the area of the input face of the same number, and
 * refuse the pieces of faces cut at T-junctions. */
static mfmm_status patch_check_sources(const mfmm_exact_ws *ws, const mfmm_source *sources,
                                       int32_t n_sources)
{
    for (int32_t i = 0; i < n_sources; i++) {
        mfmm_status st = mfmm_check_source_internal(ws->mesh, sources + i, i, NULL);
        if (st != MFMM_OK)
            return st;
    }
    return MFMM_OK;
}

mfmm_status mfmm_exact_patch(mfmm_exact_ws *ws, const mfmm_source *sources, int32_t n_sources,
                             double radius, size_t memory_limit, int32_t *n_vertices,
                             const int32_t **vertices, const double **distances,
                             mfmm_exact_info *info)
{
    if (!ws || !sources || !n_vertices || !vertices || !distances)
        return MFMM_ERR_NULL_POINTER;
    *n_vertices = 0;
    *vertices = ws->touched;
    *distances = ws->patch_d;
    if (n_sources < 1)
        return MFMM_ERR_BAD_COUNT;
    if (isnan(radius) || radius < 0.0)
        return MFMM_ERR_BAD_ARGUMENT;
    mfmm_status st = patch_check_sources(ws, sources, n_sources);
    if (st != MFMM_OK)
        return st;
    st = ex_run(ws, sources, n_sources, radius, memory_limit);
    ex_fill_info(ws, info);
    if (st != MFMM_OK)
        return st;
    /* the vertices whose distances are final, moved to the front of touched
     * (the rest stay behind them, so the next reset still clears them):
     * those within the radius, and those beyond it by less than their
     * least height h over the opposite edges of their faces. A path to v
     * ends with a segment in one of v's faces from the opposite edge (or
     * along an edge from a neighbour u, |u v| >= h), so it crosses that
     * edge (or passes u) at a distance <= d(v) - h <= radius: every window
     * and pseudo-source on it was propagated, and d(v) is exact (d is an
     * upper bound, the length of a real path, so d(v) - h <= radius holds
     * for the true distance too). That ring is free and, seeded with the
     * rest, lowers the march's mean error
     * (docs/performance.md#design-measurements). */
    int32_t n = 0;
    for (int32_t i = 0; i < ws->n_touched; i++) {
        int32_t v = ws->touched[i];
        double dv = ws->d[v];
        int final = dv <= radius;
        if (!final && dv < INFINITY)
            final = dv - ws->height[v] <= radius;
        if (final) {
            ws->in_patch[v] = 1;
            ws->touched[i] = ws->touched[n];
            ws->touched[n] = v;
            ws->patch_d[n] = ws->d[v];
            n++;
        }
    }
    *n_vertices = n;
    return MFMM_OK;
}

mfmm_status mfmm_exact_patch_check(mfmm_exact_ws *ws, const mfmm_source *src, int32_t *n_vertices,
                                   int32_t *n_rejected)
{
    if (!ws || !src || !n_vertices || !n_rejected)
        return MFMM_ERR_NULL_POINTER;
    *n_rejected = 0;
    int32_t n = *n_vertices;
    if (n <= 0)
        return MFMM_OK;
    const double *X = ws->mesh->xyz;
    /* the source's point, and the real paths that start the edge paths:
     * to the vertex itself, or straight to its face's corners */
    double p[3];
    double *up = ws->emitted; /* edge-path lengths (ex_reset clears them) */
    for (int32_t i = 0; i < n; i++)
        up[ws->touched[i]] = INFINITY;
    if (src->face < 0) {
        memcpy(p, X + 3 * (size_t)src->vertex, sizeof p);
        if (ws->in_patch[src->vertex])
            up[src->vertex] = src->value;
    } else {
        const int32_t *fv = ws->mesh->face_records[src->face].v;
        double w[3], sum = 0.0;
        for (int k = 0; k < 3; k++) {
            w[k] = src->bary[k] > 0.0 ? src->bary[k] : 0.0;
            sum += w[k];
        }
        for (int k = 0; k < 3; k++)
            w[k] /= sum;
        mfmm_bary_to_xyz(ws->mesh, src->face, w, p);
        for (int k = 0; k < 3; k++)
            if (ws->in_patch[fv[k]])
                up[fv[k]] = fmin(up[fv[k]], src->value + vdist(p, X + 3 * (size_t)fv[k]));
    }
    /* edge paths through the patch, each the length of a real path, in one
     * sweep in the order the propagation reached the vertices (about the
     * order of their distances): a vertex reached before its best neighbour
     * gets a longer path, a looser bound (a second sweep, or a Dijkstra's
     * sort, would cost more than bounds that need only be real are worth) */
    for (int32_t i = 0; i < n; i++) {
        int32_t v = ws->touched[i];
        double uv = up[v];
        if (uv == INFINITY)
            continue;
        for (int32_t j = ws->vf_offset[v]; j < ws->vf_offset[v + 1]; j++) {
            int32_t c = ex_corner(ws->vf_corner, ws->face_in, j);
            const ex_face *r = ws->fr + c / 3;
            int k = c % 3;
            int32_t a = r->v[ex_next[k]], b = r->v[ex_prev[k]];
            if (ws->in_patch[a])
                up[a] = fmin(up[a], uv + r->len[ex_prev[k]]);
            if (ws->in_patch[b])
                up[b] = fmin(up[b], uv + r->len[ex_next[k]]);
        }
    }
    /* keep, in their order, the vertices within both bounds (to rounding
     * relative to the distance, or to an edge next to the source) */
    double edge = ws->mesh->info.mean_edge_length;
    int32_t kept = 0;
    for (int32_t i = 0; i < n; i++) {
        int32_t v = ws->touched[i];
        double d = ws->patch_d[i];
        double lo = src->value + vdist(p, X + 3 * (size_t)v), hi = up[v];
        double tol = EX_PATCH_TOL * (fmax(fabs(d), fabs(lo)) + edge);
        if (d >= lo - tol && (hi == INFINITY || d <= hi + tol)) {
            ws->touched[i] = ws->touched[kept];
            ws->touched[kept] = v;
            ws->patch_d[kept++] = d;
        } else {
            ws->in_patch[v] = 0;
        }
    }
    *n_rejected = n - kept;
    *n_vertices = kept;
    return MFMM_OK;
}

int mfmm_exact_in_patch(const mfmm_exact_ws *ws, int32_t v)
{
    return ws->in_patch[v];
}
