/* The checks of a solve's arguments (check.h). */
#include <float.h>
#include <math.h>

#include "base/error.h"
#include "check.h"
#include "order.h"

mfmm_status mfmm_check_cost(const mfmm_mesh *mesh, const double *cost,
                            mfmm_cost_location where, mfmm_error *err)
{
    if (!cost)
        return MFMM_OK;
    if (where != MFMM_COST_PER_VERTEX && where != MFMM_COST_PER_FACE)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1,
                         "a cost array was given without a cost location (per vertex or per face)");
    int32_t n = where == MFMM_COST_PER_VERTEX ? mesh->nv : mesh->nf_in, imax = 0;
    for (int32_t i = 0; i < n; i++) {
        if (!isfinite(cost[i]) || !(cost[i] > 0.0))
            return mfmm_fail(err, MFMM_ERR_BAD_COST, i, "cost of %s %ld is %g; costs must be finite and > 0",
                             where == MFMM_COST_PER_VERTEX ? "vertex" : "face", (long)i, cost[i]);
        imax = cost[i] > cost[imax] ? i : imax;
    }
    /* a distance overflowing to +inf would read as "not reached" (the
     * bound of mfmm_distance_bound) */
    if (!(cost[imax] * (mesh->info.mean_edge_length * mesh->info.n_edges) < DBL_MAX / 16))
        return mfmm_fail(err, MFMM_ERR_BAD_COST, imax,
                         "cost of %s %ld is %g: with edges %g long in all, distances may overflow "
                         "(rescale the costs)",
                         where == MFMM_COST_PER_VERTEX ? "vertex" : "face", (long)imax, cost[imax],
                         mesh->info.mean_edge_length * mesh->info.n_edges);
    return MFMM_OK;
}

double mfmm_distance_bound(const mfmm_mesh *mesh, const double *cost, mfmm_cost_location where)
{
    double fmax_ = 1.0;
    if (cost && (where == MFMM_COST_PER_VERTEX || where == MFMM_COST_PER_FACE)) {
        int32_t n = where == MFMM_COST_PER_VERTEX ? mesh->nv : mesh->nf_in;
        fmax_ = 0.0;
        for (int32_t i = 0; i < n; i++)
            fmax_ = cost[i] > fmax_ ? cost[i] : fmax_;
    }
    return fmax_ * (mesh->info.mean_edge_length * mesh->info.n_edges);
}

/* Source i in the caller's face ids (internal: the built faces, pieces of
 * faces cut at T-junctions included; else the input faces). */
static mfmm_status check_source(const mfmm_mesh *mesh, const mfmm_source *src, int32_t i,
                                int internal, mfmm_error *err)
{
    int32_t nf = internal ? mesh->nf : mesh->nf_in;
    if (!isfinite(src->value))
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, i, "source %ld has a value that is not finite",
                         (long)i);
    if (src->face < 0) {
        if (src->face != -1 || src->vertex < 0 || src->vertex >= mesh->nv)
            return mfmm_fail(err, MFMM_ERR_BAD_SOURCE, i,
                             "source %ld: vertex %ld is outside [0, %ld)", (long)i,
                             (long)src->vertex, (long)mesh->nv);
        return MFMM_OK;
    }
    if (src->face >= nf)
        return mfmm_fail(err, MFMM_ERR_BAD_SOURCE, i, "source %ld: face %ld is outside [0, %ld)",
                         (long)i, (long)src->face, (long)nf);
    double sum = 0.0;
    for (int k = 0; k < 3; k++) {
        double w = src->bary[k];
        if (!isfinite(w) || w < -1e-12)
            return mfmm_fail(err, MFMM_ERR_BAD_BARYCENTRIC, i,
                             "source %ld: barycentric coordinate %d is %g (must be >= 0)",
                             (long)i, k, w);
        sum += w;
    }
    if (fabs(sum - 1.0) > 1e-9)
        return mfmm_fail(err, MFMM_ERR_BAD_BARYCENTRIC, i,
                         "source %ld: barycentric coordinates sum to %.17g, not 1", (long)i, sum);
    if (internal ? mfmm_mesh_degenerate(mesh, src->face)
                 : mfmm_order_point_degenerate(mesh, src->face, src->bary))
        return mfmm_fail(err, MFMM_ERR_DEGENERATE_SOURCE, i,
                         "source %ld lies on face %ld, which has zero area", (long)i,
                         (long)src->face);
    return MFMM_OK;
}

mfmm_status mfmm_check_source(const mfmm_mesh *mesh, const mfmm_source *src, int32_t i,
                              mfmm_error *err)
{
    return check_source(mesh, src, i, 0, err);
}

mfmm_status mfmm_check_source_internal(const mfmm_mesh *mesh, const mfmm_source *src, int32_t i,
                                       mfmm_error *err)
{
    return check_source(mesh, src, i, 1, err);
}

void mfmm_uniform_cost(const mfmm_mesh *mesh, const double *cost, int cost_location,
                       double *uniform)
{
    for (int32_t v = 0; v < mesh->nv; v++)
        uniform[v] = 0.0;
    for (int32_t f = 0; f < mesh->nf; f++) {
        const int32_t *fv = mesh->face_records[f].v;
        double x;
        if (cost_location == 2) {
            x = cost[f];
        } else { /* the face's corners all alike, or -1 */
            x = cost[fv[0]];
            if (cost[fv[1]] != x || cost[fv[2]] != x)
                x = -1.0;
        }
        for (int k = 0; k < 3; k++) {
            double *u = uniform + fv[k];
            *u = *u == 0.0 || *u == x ? x : -1.0;
        }
    }
}

