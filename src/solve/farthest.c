/* Geodesic farthest-point sampling (mfmm_farthest_points): one solver, a
 * running minimum of the distances to the points chosen, and each march
 * bounded by the current farthest distance, past which it cannot lower
 * the minimum. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "mesh/check.h"
#include "mesh/mesh.h"
#include "mesh/order.h"
#include "start/seed.h"
#include "solve.h"

static int referenced(const mfmm_mesh *m, int32_t v)
{
    return m->vertex_face_offset[v] != m->vertex_face_offset[v + 1];
}

mfmm_status mfmm_farthest_points(mfmm_solver *solver, int32_t start, int32_t k,
                                 const mfmm_solve_options *options, int32_t *points,
                                 double *radii, double *distances, mfmm_error *err)
{
    mfmm_ok(err);
    if (!solver || !points)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "%s is NULL",
                         !solver ? "solver" : "points");
    const mfmm_mesh *mesh = mfmm_solver_mesh(solver);
    int32_t nv = mesh->nv;
    mfmm_solve_options opt;
    mfmm_solve_options_init(&opt);
    if (options &&
        mfmm_read_options(&opt, options, sizeof opt, "mfmm_solve_options", err) != MFMM_OK)
        return MFMM_ERR_BAD_ARGUMENT;
    if (!opt.cost)
        opt.cost_location = MFMM_COST_NONE;
    mfmm_status st = mfmm_check_cost(mesh, opt.cost, opt.cost_location, err);
    if (st != MFMM_OK)
        return st;
    if (!(opt.max_distance == INFINITY) || opt.n_targets != 0)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1,
                         "farthest-point sampling takes no max_distance or targets (each "
                         "march is bounded by the farthest distance itself)");
    st = mfmm_check_exact_start(opt.exact_start_radius, err);
    if (st != MFMM_OK)
        return st;
    st = mfmm_check_method((int)opt.method, opt.cost != NULL, err);
    if (st != MFMM_OK)
        return st;
    if (start < 0 || start >= nv)
        return mfmm_fail(err, MFMM_ERR_BAD_SOURCE, start,
                         "start vertex %ld is outside [0, %ld)", (long)start, (long)nv);
    int32_t n_ref = nv - mesh->info.n_unreferenced_vertices;
    if (k < 1 || k > n_ref)
        return mfmm_fail(err, MFMM_ERR_BAD_COUNT, -1,
                         "k is %ld; it must lie in [1, %ld], the vertices in faces", (long)k,
                         (long)n_ref);
    int32_t s_in = mesh->to_internal[start];
    if (!referenced(mesh, s_in))
        return mfmm_fail(err, MFMM_ERR_BAD_SOURCE, start, "start vertex %ld is in no face",
                         (long)start);

    mfmm_mapped_args a;
    memset(&a, 0, sizeof a);
    double *dmin = malloc((size_t)nv * sizeof *dmin);
    if (!dmin || mfmm_order_map_args(mesh, NULL, 0, NULL, 0, opt.cost, (int)opt.cost_location,
                                     NULL, &a) != MFMM_OK) {
        free(dmin);
        free(a.block);
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory");
    }
    opt.cost = a.cost;
    /* the radius of a full solve, so that every bounded march starts alike */
    opt.exact_start_radius = mfmm_exact_start_edges(mesh, opt.exact_start_radius, INFINITY);
    mfmm_solver_fix_cost(solver, opt.cost, (int)opt.cost_location);
    /* chosen and unreferenced vertices: -1, never the farthest */
    for (int32_t v = 0; v < nv; v++)
        dmin[v] = referenced(mesh, v) ? INFINITY : -1.0;
    int32_t next = s_in;
    double reach = INFINITY;
    st = MFMM_OK;
    for (int32_t i = 0; i < k; i++) {
        points[i] = mesh->to_external[next];
        if (radii)
            radii[i] = reach;
        mfmm_source src = {.vertex = next, .face = -1, .value = 0.0};
        opt.max_distance = reach;
        const double *T;
        const int32_t *touched;
        int32_t n_touched;
        if (mfmm_solve_local(solver, &src, 1, &opt, &T, &touched, &n_touched) < 0) {
            st = mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1,
                           "out of memory for the solver's workspace");
            break;
        }
        for (int32_t j = 0; j < n_touched; j++) {
            int32_t v = touched[j];
            if (T[v] < dmin[v])
                dmin[v] = T[v];
        }
        dmin[next] = -1.0;
        /* the farthest vertex not chosen; ties to the lowest input id */
        next = -1;
        reach = -1.0;
        for (int32_t v = 0; v < nv; v++) {
            double x = dmin[v];
            if (x > reach || (x == reach && x >= 0.0 &&
                              mesh->to_external[v] < mesh->to_external[next])) {
                reach = x;
                next = v;
            }
        }
    }
    mfmm_solver_fix_cost(solver, NULL, 0);
    if (st == MFMM_OK && distances) {
        /* chosen points back to 0 */
        for (int32_t i = 0; i < k; i++)
            dmin[mesh->to_internal[points[i]]] = 0.0;
        for (int32_t v = 0; v < nv; v++)
            if (dmin[v] < 0.0)
                dmin[v] = INFINITY; /* unreferenced */
        mfmm_order_values_out(mesh, dmin, distances);
    }
    free(dmin);
    free(a.block);
    return st;
}
