/* The public solver: a reusable workspace, the checks, and one march
 * (march/march.h) from the exact start (start/seed.h) or the straight
 * one (start/straight.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "mesh/check.h"
#include "mesh/mesh.h"
#include "mesh/order.h"
#include "exact/slots.h"
#include "mesh/spokes.h"
#include "start/straight.h"
#include "start/seed.h"
#include "solve.h"

struct mfmm_solver {
    const mfmm_mesh *mesh;
    double *heap_key;
    int32_t *heap_vertex;
    int32_t *heap_pos;
    uint8_t *label;  /* all Far between solves (but the pending touched list) */
    double *uniform; /* for the virtual stencils under a cost (march.h) */
    double *T;       /* own T, +inf between solves (but the pending list) */
    int32_t *touched;   /* the vertices the last march touched (march.h) */
    int32_t n_pending;  /* touched vertices still to reset to Far / +inf */
    /* a cost whose `uniform` is computed once for many solves (matrix jobs) */
    const double *fixed_cost;
    int fixed_location;
    mfmm_exact_ws *exact; /* the exact start's workspace, made on first use */
    mfmm_slots *windows;  /* MFMM_METHOD_WINDOWS's workspace, made on first use */
    int64_t start_fallbacks; /* the last solve's (mfmm_solve_info) */
    mfmm_mapped_args args; /* mfmm_solve's arguments in internal order (order.h) */
    /* the mesh's spokes (mfmm_mesh_spokes_of), asked for by each march at
     * F = 1 with unfolding until built (the face walk gives the same
     * rows); many_rows: build them at once (mfmm_solver_expect_rows) */
    const int32_t *spoke_offset;
    const mfmm_spoke *spokes;
    int many_rows;
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
    s->T = malloc(n * sizeof *s->T);
    s->touched = malloc(n * sizeof *s->touched);
    if (!s->heap_key || !s->heap_vertex || !s->heap_pos || !s->label || !s->uniform || !s->T ||
        !s->touched) {
        mfmm_solver_destroy(s);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    for (size_t v = 0; v < n; v++) {
        s->T[v] = INFINITY;
        s->label[v] = MFMM_FAR;
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
    free(solver->T);
    free(solver->touched);
    mfmm_exact_ws_destroy(solver->exact);
    mfmm_slots_destroy(solver->windows);
    free(solver->args.block);
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
    options->exact_start_radius = MFMM_EXACT_START_AUTO;
    options->method = MFMM_METHOD_FMM;
}

mfmm_status mfmm_check_method(int method, int has_cost, mfmm_error *err)
{
    if (method != MFMM_METHOD_FMM && method != MFMM_METHOD_WINDOWS)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1,
                         "method is %d; it must be MFMM_METHOD_FMM (0) or MFMM_METHOD_WINDOWS (1)",
                         method);
    (void)has_cost; /* both methods take a cost */
    return MFMM_OK;
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
        if (mfmm_read_options(&opt, options, sizeof opt, "mfmm_solve_options", err) != MFMM_OK)
            return MFMM_ERR_BAD_ARGUMENT;
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
    st = mfmm_check_exact_start(opt.exact_start_radius, err);
    if (st != MFMM_OK)
        return st;
    st = mfmm_check_method((int)opt.method, opt.cost != NULL, err);
    if (st != MFMM_OK)
        return st;
    for (int32_t i = 0; i < n_sources; i++) {
        st = mfmm_check_source(mesh, sources + i, i, err);
        if (st != MFMM_OK)
            return st;
    }
    return mfmm_solve_mapped(solver, sources, n_sources, &opt, distances, err);
}

/* Puts the vertices the last march touched back to Far (and the solver's
 * own T back to +inf): the cost of a reset is the previous row's reach. */
static void solver_reset_pending(mfmm_solver *solver)
{
    int32_t nv = solver->mesh->nv;
    if (solver->n_pending >= nv / 8) { /* most of the mesh: sequential is cheaper */
        for (int32_t v = 0; v < nv; v++)
            solver->T[v] = INFINITY;
        memset(solver->label, MFMM_FAR, (size_t)nv);
        solver->n_pending = 0;
        return;
    }
    for (int32_t i = 0; i < solver->n_pending; i++) {
        int32_t v = solver->touched[i];
        solver->T[v] = INFINITY;
        solver->label[v] = MFMM_FAR;
    }
    solver->n_pending = 0;
}

const mfmm_mesh *mfmm_solver_mesh(const mfmm_solver *solver)
{
    return solver->mesh;
}

void mfmm_solver_fix_cost(mfmm_solver *solver, const double *cost, int cost_location)
{
    solver->fixed_cost = NULL;
    if (cost && cost_location != MFMM_COST_NONE) {
        mfmm_uniform_cost(solver->mesh, cost, cost_location, solver->uniform);
        solver->fixed_cost = cost;
        solver->fixed_location = cost_location;
    }
}

/* Seeds one source (seed.h). fixed: the exact values are final (one source;
 * with several, a vertex in one's patch may be nearer another, whose march
 * must be able to lower it). -1 when out of memory. */
static int seed_source(mfmm_solver *solver, mfmm_march_state *s, const mfmm_source *src,
                       double radius, int fixed)
{
    int32_t n_fallback = 0;
    mfmm_status st = mfmm_exact_start_seed(solver->mesh, &solver->exact, s, src, radius,
                                           solver->uniform, fixed, &n_fallback);
    solver->start_fallbacks += n_fallback;
    return st == MFMM_OK ? 0 : -1;
}

int64_t mfmm_solver_start_fallbacks(const mfmm_solver *solver)
{
    return solver->start_fallbacks;
}

mfmm_status mfmm_solver_get_info(const mfmm_solver *solver, mfmm_solve_info *info)
{
    if (!solver || !info)
        return MFMM_ERR_NULL_POINTER;
    mfmm_solve_info all;
    memset(&all, 0, sizeof all);
    all.struct_size = sizeof all;
    all.start_fallbacks = solver->start_fallbacks;
    return mfmm_write_info(info, &all, sizeof all);
}

/* One march into T (the caller's +inf-filled row, or the solver's own T);
 * leaves the touched list pending. Returns the vertices settled, -1 when out
 * of memory (nothing pending then). */
static int32_t solver_march(mfmm_solver *solver, const mfmm_source *sources, int32_t n_sources,
                            const mfmm_solve_options *options, double *T)
{
    const mfmm_mesh *mesh = solver->mesh;
    mfmm_solve_options opt = *options;
    if (!opt.cost)
        opt.cost_location = MFMM_COST_NONE;
    solver_reset_pending(solver);
    solver->start_fallbacks = 0;
    if (opt.method == MFMM_METHOD_WINDOWS) {
        if (!solver->windows && mfmm_slots_create(mesh, &solver->windows) != MFMM_OK)
            return -1;
        solver->n_pending = mfmm_slots_run(solver->windows, sources, n_sources, opt.max_distance,
                                           opt.targets, opt.n_targets, opt.cost,
                                           (int)opt.cost_location, T, solver->touched);
        return solver->n_pending;
    }
    mfmm_march_state s;
    memset(&s, 0, sizeof s);
    s.T = T;
    s.label = solver->label;
    s.heap_key = solver->heap_key;
    s.heap_vertex = solver->heap_vertex;
    s.heap_pos = solver->heap_pos;
    s.heap_size = 0;
    s.cost = opt.cost;
    s.cost_location = (int)opt.cost_location;
    s.max_distance = opt.max_distance;
    s.unfolding = opt.unfolding != 0;
    s.uniform = NULL;
    s.touched = solver->touched;
    s.n_touched = 0;
    s.targets_left = 0;
    int exact = mfmm_exact_start_on(opt.exact_start_radius);
    if (s.cost && (s.unfolding || exact)) {
        if (solver->fixed_cost != s.cost || solver->fixed_location != s.cost_location)
            mfmm_uniform_cost(mesh, s.cost, s.cost_location, solver->uniform);
        s.uniform = solver->uniform;
    }
    for (int32_t i = 0; i < opt.n_targets; i++) {
        uint8_t *l = s.label + opt.targets[i];
        if (!(*l & MFMM_TARGET)) {
            *l |= MFMM_TARGET;
            s.targets_left++;
        }
    }
    for (int32_t i = 0; i < n_sources; i++) {
        if (seed_source(solver, &s, sources + i, opt.exact_start_radius, n_sources == 1) < 0) {
            for (int32_t j = 0; j < opt.n_targets; j++)
                s.label[opt.targets[j]] &= (uint8_t)MFMM_STATE_MASK;
            for (int32_t j = 0; j < s.n_touched; j++) {
                s.T[s.touched[j]] = INFINITY;
                s.label[s.touched[j]] = MFMM_FAR;
            }
            return -1;
        }
    }
    mfmm_march_mesh mm = mfmm_mesh_march_view(mesh);
    int spoked = !s.cost && s.unfolding;
    if (spoked) {
        if (!solver->spokes)
            (void)mfmm_mesh_spokes_of(mesh, solver->many_rows, &solver->spoke_offset,
                                      &solver->spokes);
        mm.spoke_offset = solver->spoke_offset;
        mm.spokes = solver->spokes;
    }
    int32_t settled = mfmm_march_run(&s, &mm);
    if (spoked && !solver->spokes)
        mfmm_mesh_spokes_count(mesh, settled);
    /* target flags on vertices never touched (touched ones: reset below) */
    for (int32_t i = 0; i < opt.n_targets; i++)
        s.label[opt.targets[i]] &= (uint8_t)MFMM_STATE_MASK;
    solver->n_pending = s.n_touched;
    return settled;
}

int32_t mfmm_solve_checked(mfmm_solver *solver, const mfmm_source *sources, int32_t n_sources,
                           const mfmm_solve_options *options, double *distances)
{
    int32_t nv = solver->mesh->nv;
    for (int32_t v = 0; v < nv; v++)
        distances[v] = INFINITY;
    int32_t settled = solver_march(solver, sources, n_sources, options, distances);
    if (settled < 0)
        return -1;
    /* the row was the caller's: only the labels need resetting */
    if (solver->n_pending >= nv / 8)
        memset(solver->label, MFMM_FAR, (size_t)nv);
    else
        for (int32_t i = 0; i < solver->n_pending; i++)
            solver->label[solver->touched[i]] = MFMM_FAR;
    solver->n_pending = 0;
    return settled;
}

int32_t mfmm_solve_local(mfmm_solver *solver, const mfmm_source *sources, int32_t n_sources,
                         const mfmm_solve_options *options, const double **T,
                         const int32_t **touched, int32_t *n_touched)
{
    int32_t settled = solver_march(solver, sources, n_sources, options, solver->T);
    *T = solver->T;
    *touched = solver->touched;
    *n_touched = solver->n_pending;
    return settled;
}

mfmm_status mfmm_solve_mapped(mfmm_solver *solver, const mfmm_source *sources, int32_t n_sources,
                              const mfmm_solve_options *options, double *distances,
                              mfmm_error *err)
{
    const mfmm_mesh *mesh = solver->mesh;
    mfmm_mapped_args *a = &solver->args;
    if (mfmm_order_map_args(mesh, sources, n_sources, options->targets, options->n_targets,
                            options->cost, (int)options->cost_location, NULL, a) != MFMM_OK)
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for the arguments");
    mfmm_solve_options opt = *options;
    opt.targets = a->targets;
    opt.cost = a->cost;
    const double *T;
    const int32_t *touched;
    int32_t n_touched;
    if (mfmm_solve_local(solver, a->sources, n_sources, &opt, &T, &touched, &n_touched) < 0)
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1,
                         "out of memory for the solver's workspace");
    /* the one pass over the row: gathered into input order */
    mfmm_order_values_out(mesh, T, distances);
    return MFMM_OK;
}

void mfmm_solver_expect_rows(mfmm_solver *solver, int64_t n_rows)
{
    solver->many_rows = n_rows >= MFMM_SPOKES_AFTER;
}
