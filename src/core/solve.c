/* The serial solver: a reusable workspace and the checks around one march
 * (src/march.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mesh.h"
#include "solve.h"

struct mfmm_solver {
    const mfmm_mesh *mesh;
    double *heap_key;
    int32_t *heap_vertex;
    int32_t *heap_pos;
    uint8_t *label;
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
    if (!s->heap_key || !s->heap_vertex || !s->heap_pos || !s->label) {
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

static double dist3(const double *p, const double *q)
{
    return sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                (p[2] - q[2]) * (p[2] - q[2]));
}

static double seed_cost(const mfmm_march_state *st, int32_t face, int32_t vertex)
{
    if (st->cost_location == MFMM_COST_PER_VERTEX)
        return st->cost[vertex];
    if (st->cost_location == MFMM_COST_PER_FACE)
        return st->cost[face];
    return 1.0;
}

/* The far vertex q of the face g across edge (e1, e2) of the source face,
 * unfolded into the source face's plane: if the straight segment from p to it
 * crosses that edge, it is a path on the surface, and q starts at its cost. */
static void seed_across_edge(const mfmm_mesh *mesh, mfmm_march_state *st, const mfmm_source *src,
                             const double *p, int k)
{
    int32_t f = src->face, g = mesh->face_neighbor[3 * (size_t)f + k];
    if (g < 0 || mesh->degenerate[g])
        return;
    const int32_t *fv = mesh->faces + 3 * (size_t)f;
    int32_t e1 = fv[(k + 1) % 3], e2 = fv[(k + 2) % 3], q = -1;
    for (int j = 0; j < 3; j++) {
        int32_t w = mesh->faces[3 * (size_t)g + j];
        if (w != e1 && w != e2)
            q = w;
    }
    const double *x1 = mesh->xyz + 3 * (size_t)e1, *x2 = mesh->xyz + 3 * (size_t)e2;
    const double *xc = mesh->xyz + 3 * (size_t)fv[k], *xq = mesh->xyz + 3 * (size_t)q;
    double len = dist3(x1, x2), r1 = dist3(x1, xq), r2 = dist3(x2, xq);
    double e[3], w[3], n[3];
    for (int d = 0; d < 3; d++) {
        e[d] = (x2[d] - x1[d]) / len;
        w[d] = xc[d] - x1[d];
    }
    /* n: in the face's plane, normal to the edge, away from the face */
    double we = w[0] * e[0] + w[1] * e[1] + w[2] * e[2];
    for (int d = 0; d < 3; d++)
        n[d] = -(w[d] - we * e[d]);
    double nn = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(nn > 0.0))
        return;
    double s = (len * len + r1 * r1 - r2 * r2) / (2.0 * len);
    double h2 = r1 * r1 - s * s, h = h2 > 0.0 ? sqrt(h2) : 0.0;
    /* p's offset from the edge line (towards the face: negative along n) */
    double pe = 0.0, pn = 0.0;
    for (int d = 0; d < 3; d++) {
        pe += (p[d] - x1[d]) * e[d];
        pn += (p[d] - x1[d]) * n[d] / nn;
    }
    if (!(pn < 0.0) || !(h > 0.0))
        return;
    double tcross = -pn / (h - pn); /* fraction of the way from p to q' */
    double ecross = pe + tcross * (s - pe);
    if (!(ecross > 0.0 && ecross < len))
        return;
    double first = sqrt((ecross - pe) * (ecross - pe) + pn * pn);
    double second = sqrt((s - ecross) * (s - ecross) + h * h);
    double cost = first * seed_cost(st, f, q) + second * seed_cost(st, g, q);
    mfmm_march_seed(st, q, src->value + cost);
}

void mfmm_seed_source(const mfmm_mesh *mesh, mfmm_march_state *st, const mfmm_source *src)
{
    if (src->face < 0) {
        mfmm_march_seed(st, src->vertex, src->value);
        return;
    }
    /* a point inside a face: its corners start at the in-plane distance times
     * F, and so do the far vertices of the three neighbouring faces that a
     * straight segment reaches through the shared edge (as a vertex source's
     * first ring is reached by its edges). */
    const int32_t *fv = mesh->faces + 3 * (size_t)src->face;
    double p[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < 3; k++)
        for (int d = 0; d < 3; d++)
            p[d] += src->bary[k] * mesh->xyz[3 * (size_t)fv[k] + d];
    for (int k = 0; k < 3; k++) {
        double dist = dist3(mesh->xyz + 3 * (size_t)fv[k], p);
        mfmm_march_seed(st, fv[k], src->value + dist * seed_cost(st, src->face, fv[k]));
    }
    for (int k = 0; k < 3; k++)
        seed_across_edge(mesh, st, src, p, k);
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
