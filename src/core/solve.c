/* The serial solver: a reusable workspace and the checks around one march
 * (src/march.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mesh.h"
#include "solve.h"
#include "start.h"

struct mfmm_solver {
    const mfmm_mesh *mesh;
    double *heap_key;
    int32_t *heap_vertex;
    int32_t *heap_pos;
    uint8_t *label;
    double *uniform; /* for the virtual stencils under a cost (march.h) */
};

mfmm_status mfmm_solver_create(const mfmm_mesh *mesh, mfmm_solver **out)
{
    if (!out)
        return MFMM_ERR_NULL_POINTER;
    *out = NULL;
    if (!mesh)
        return MFMM_ERR_NULL_POINTER;
    mfmm_solver *s = calloc(1, sizeof *s);
    if (!s)
        return MFMM_ERR_OUT_OF_MEMORY;
    size_t n = (size_t)mesh->nv;
    s->mesh = mesh;
    s->heap_key = malloc(n * sizeof *s->heap_key);
    s->heap_vertex = malloc(n * sizeof *s->heap_vertex);
    s->heap_pos = malloc(n * sizeof *s->heap_pos);
    s->label = malloc(n * sizeof *s->label);
    s->uniform = malloc(n * sizeof *s->uniform);
    if (!s->heap_key || !s->heap_vertex || !s->heap_pos || !s->label || !s->uniform) {
        mfmm_solver_destroy(s);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    *out = s;
    return MFMM_OK;
}

void mfmm_solver_destroy(mfmm_solver *solver)
{
    if (!solver)
        return;
    free(solver->heap_key);
    free(solver->heap_vertex);
    free(solver->heap_pos);
    free(solver->label);
    free(solver->uniform);
    free(solver);
}

void mfmm_solve_options_init(mfmm_solve_options *options)
{
    if (!options)
        return;
    memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
    options->cost = NULL;
    options->cost_location = MFMM_COST_NONE;
    options->max_distance = INFINITY;
    options->targets = NULL;
    options->n_targets = 0;
    options->unfolding = 1;
}

mfmm_status mfmm_check_cost(const mfmm_mesh *mesh, const double *cost,
                            mfmm_cost_location where, mfmm_error *err)
{
    if (!cost)
        return MFMM_OK;
    if (where != MFMM_COST_PER_VERTEX && where != MFMM_COST_PER_FACE)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1,
                         "a cost array was given without a cost location (per vertex or per face)");
    int32_t n = where == MFMM_COST_PER_VERTEX ? mesh->nv : mesh->nf;
    for (int32_t i = 0; i < n; i++)
        if (!isfinite(cost[i]) || !(cost[i] > 0.0))
            return mfmm_fail(err, MFMM_ERR_BAD_COST, i, "cost of %s %ld is %g; costs must be finite and > 0",
                             where == MFMM_COST_PER_VERTEX ? "vertex" : "face", (long)i, cost[i]);
    return MFMM_OK;
}

mfmm_status mfmm_check_source(const mfmm_mesh *mesh, const mfmm_source *src, int32_t i,
                              mfmm_error *err)
{
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
    if (src->face >= mesh->nf)
        return mfmm_fail(err, MFMM_ERR_BAD_SOURCE, i, "source %ld: face %ld is outside [0, %ld)",
                         (long)i, (long)src->face, (long)mesh->nf);
    if (mesh->degenerate[src->face])
        return mfmm_fail(err, MFMM_ERR_DEGENERATE_SOURCE, i,
                         "source %ld lies on face %ld, which has zero area", (long)i,
                         (long)src->face);
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
    return MFMM_OK;
}

typedef struct seed_ctx {
    mfmm_march_state *st;
    double value;
} seed_ctx;

static int seed_point_hit(void *user, const mfmm_start_hit *h)
{
    seed_ctx *c = user;
    mfmm_march_seed(c->st, h->vertex, c->value + h->cost_length);
    return 0;
}

void mfmm_seed_source(const mfmm_mesh *mesh, mfmm_march_state *st, const mfmm_source *src)
{
    if (src->face < 0) {
        mfmm_march_seed(st, src->vertex, src->value);
        return;
    }
    /* a point on the surface: every vertex a straight segment reaches near
     * it starts at that segment's cost (start.c) */
    seed_ctx c = {st, src->value};
    mfmm_start_walk(mesh, src, st->cost, st->cost_location, seed_point_hit, &c);
}

mfmm_status mfmm_solve(mfmm_solver *solver, const mfmm_source *sources, int32_t n_sources,
                       const mfmm_solve_options *options, double *distances, mfmm_error *err)
{
    mfmm_ok(err);
    if (!solver || !sources || !distances)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "%s is NULL",
                         !solver ? "solver" : !sources ? "sources" : "distances");
    if (n_sources < 1)
        return mfmm_fail(err, MFMM_ERR_BAD_COUNT, -1, "n_sources must be >= 1 (got %ld)",
                         (long)n_sources);
    const mfmm_mesh *mesh = solver->mesh;
    mfmm_solve_options opt;
    mfmm_solve_options_init(&opt);
    if (options) {
        if (mfmm_check_struct_size(options, sizeof opt, "mfmm_solve_options", err) != MFMM_OK)
            return MFMM_ERR_BAD_ARGUMENT;
        opt = *options;
    }
    if (!opt.cost)
        opt.cost_location = MFMM_COST_NONE;
    mfmm_status st = mfmm_check_cost(mesh, opt.cost, opt.cost_location, err);
    if (st != MFMM_OK)
        return st;
    if (isnan(opt.max_distance))
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1, "max_distance is NaN");
    if (opt.max_distance < 0.0)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1,
                         "max_distance is %g; it must be >= 0 (+inf: no limit)", opt.max_distance);
    if (opt.n_targets < 0 || (opt.n_targets > 0 && !opt.targets))
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1,
                         "n_targets is %ld but targets is %s", (long)opt.n_targets,
                         opt.targets ? "set" : "NULL");
    for (int32_t i = 0; i < opt.n_targets; i++)
        if (opt.targets[i] < 0 || opt.targets[i] >= mesh->nv)
            return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, i, "target %ld: vertex %ld is outside [0, %ld)",
                             (long)i, (long)opt.targets[i], (long)mesh->nv);
    for (int32_t i = 0; i < n_sources; i++) {
        st = mfmm_check_source(mesh, sources + i, i, err);
        if (st != MFMM_OK)
            return st;
    }
    mfmm_solve_checked(solver, sources, n_sources, &opt, distances);
    return MFMM_OK;
}

void mfmm_solve_checked(mfmm_solver *solver, const mfmm_source *sources, int32_t n_sources,
                        const mfmm_solve_options *options, double *distances)
{
    const mfmm_mesh *mesh = solver->mesh;
    mfmm_solve_options opt = *options;
    if (!opt.cost)
        opt.cost_location = MFMM_COST_NONE;
    mfmm_march_state s;
    s.T = distances;
    s.label = solver->label;
    s.heap_key = solver->heap_key;
    s.heap_vertex = solver->heap_vertex;
    s.heap_pos = solver->heap_pos;
    s.cost = opt.cost;
    s.cost_location = (int)opt.cost_location;
    s.max_distance = opt.max_distance;
    s.unfolding = opt.unfolding != 0;
    s.uniform = NULL;
    if (s.cost && s.unfolding) {
        mfmm_uniform_cost(mesh, s.cost, s.cost_location, solver->uniform);
        s.uniform = solver->uniform;
    }
    mfmm_march_reset(&s, mesh->nv);
    for (int32_t i = 0; i < opt.n_targets; i++) {
        uint8_t *l = s.label + opt.targets[i];
        if (!(*l & MFMM_TARGET)) {
            *l |= MFMM_TARGET;
            s.targets_left++;
        }
    }
    for (int32_t i = 0; i < n_sources; i++)
        mfmm_seed_source(mesh, &s, sources + i);
    mfmm_march_mesh mm = mfmm_mesh_march_view(mesh);
    mfmm_march_run(&s, &mm);
}
