/* The exact solver (mfmm_exact_solver, mfmm_solve_exact) and its workspaces:
 * exact polyhedral geodesic distances. The files of src/exact: state.h (the
 * types), tables.c (per-mesh tables), queue.c, propagate.c, nonmanifold.c,
 * run.c (one run), this file (the API); the exact start's patch is
 * start/patch.c.
 *
 * Algorithm: window propagation of Chen & Han ("Shortest paths on a
 * polyhedron", SoCG 1990 / IJCGA 1996) with the pruning of Xin & Wang
 * ("Improving Chen and Han's algorithm on the discrete geodesic problem",
 * ACM TOG 28(4), 2009; "ICH"). Windows are not kept on edges and never
 * intersected with each other (unlike Mitchell, Mount & Papadimitriou /
 * Surazhsky et al. 2005, "MMP", which Kirsanov's library -- libigl's
 * exact_geodesic, gdist -- implements); instead every window is checked
 * against the best distances known at the vertices of its triangle and
 * trimmed or dropped where a path through one of them is shorter. Windows
 * and vertex events share one queue ordered by least distance (ICH's
 * priority queue, kept here as buckets: see the queue below).
 *
 * A window lies on an edge, seen from the face it is about to cross: an
 * interval [b0, b1] of the edge, its pseudo-source I unfolded into the
 * edge's plane (px, py), py <= 0 on the far side from that face, and sigma,
 * the distance from the sources to I. The distance it gives a point X of
 * the interval is D(X) = sigma + |I X|. Crossing the face it may see the
 * opposite vertex C (then d(C) <= sigma + |I C|) and splits into at most two
 * children on the face's other edges. A vertex through which a shortest
 * path may bend (a source, a saddle with angle sum > 2 pi, a boundary or
 * non-manifold vertex, a vertex of a zero-area face) becomes a
 * pseudo-source when its distance improves: it starts windows on the
 * opposite edges of the faces around it.
 *
 * Pruning and trimming (sound; derived for this code). For a new window on
 * edge PQ of the face PQR it leaves:
 *   - |I X| - |P X| does not increase as X moves away from P along the
 *     edge, so the part where D(X) > d(P) + |P X| is an interval at P's
 *     end, found by solving one quadratic: the window is trimmed to the
 *     rest (likewise from Q); ICH drops the whole window when its far end
 *     is beaten, this keeps the part that is not;
 *   - (ICH's third rule, dropping the window when min D > d(R) + max(|R E0|,
 *     |R E1|), is not applied: with the trims and the queue's order it
 *     drops almost nothing for the time its test takes;
 *     docs/performance.md#design-measurements.)
 * Dropping or trimming is safe in any order: every point removed has a
 * shorter path through a vertex, so no shortest path crosses it.
 *
 * Saddle shadows (from the geometry of geodesics through a vertex, as in
 * Mitchell-Mount-Papadimitriou and Surazhsky et al.): a shortest path that
 * reaches an interior saddle v from direction th can go on through v only
 * into directions at angle >= pi from th on both sides, the "shadow"
 * [th + pi, th + total - pi]; every other direction is reached more briefly
 * by the windows passing beside v. So an interior saddle starts windows only
 * in its shadow (with 1e-7 rad to spare), th being the direction of the path
 * that gave v its distance (any one of several equal ones will do; a gain
 * within rounding keeps the earlier direction, since rays grazing a vertex
 * along an edge report directions that are not theirs). Sources, boundary,
 * non-manifold and zero-area-face vertices start windows all around. This
 * is what makes the method fast: about a third of ICH's windows remain.
 *
 * Queue: buckets a quarter of a mean edge wide (the "fast wavefront
 * propagation" idea of Xu et al. 2015), windows first in first out inside a
 * bucket, then the bucket's vertex events. Pops come in order to within a
 * bucket; pruning tolerates it, and a saddle started before its distance
 * was final is started again when it improves, so the result does not
 * depend on it.
 *
 * Sources: a vertex source is a pseudo-source with its value; a point in a
 * face (on an edge too) starts a window on each edge of its face; a point
 * within 1e-12 of a corner is that corner. Boundary edges are walls; a
 * window reaching a non-manifold edge goes on into every other face on it
 * (ex_fan_out), each unfolded across the edge and trimmed against the
 * windows that entered that face there before (ex_dominate), and the edge's
 * ends are pseudo-sources; copies of a face are no part of the surface
 * (skip 2); a zero-area face (skip 1, its corners on one line) is passed
 * through along that line (ex_pass; past EX_MAX_PASS in a row, from the
 * queue), its edges relax their ends, and a
 * vertex on its longest edge starts windows across that edge. An edge
 * almost a point next to the faces at its ends (a vertex split in two 1e-15
 * apart) is a wall whose ends start windows all around: no frame can be
 * unfolded onto it (ex_wall_short_edges). max_distance
 * (and the radius of mfmm_exact_patch) drops every window and event beyond
 * it, so the work grows with the area reached.
 *
 * Geometry: each face's corners are laid out in the frame of each of its
 * edges from the 3D vectors (dot and cross products); the law of cosines
 * loses (L / height)^2 eps of a needle's height.
 *
 * Memory: per-mesh tables (a 128-byte record per face with its edges'
 * lengths, each corner in the frame of the opposite edge, the edges across
 * and the vertices; corner and fan angles: about 160 bytes per face; per
 * vertex its flags, angle sum and least height, 17 bytes; 8 bytes per
 * half-edge of a non-manifold edge), the queue's entries (windows and vertex
 * events, 56 bytes each) and the windows kept at non-manifold edges (56
 * bytes each, ex_keep), grown by doubling within memory_limit. No
 * recursion. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "exact.h"
#include "mesh/check.h"
#include "mesh/order.h"
#include "queue.h"
#include "run.h"
#include "state.h"

void mfmm_exact_options_init(mfmm_exact_options *options)
{
    if (!options)
        return;
    memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
    options->max_distance = INFINITY;
    options->memory_limit = 0;
    options->interrupt = NULL;
    options->user = NULL;
}

void mfmm_exact_ws_destroy(mfmm_exact_ws *ws)
{
    if (!ws)
        return;
    free(ws->in_angle);
    free(ws->d);
    free(ws->emitted);
    free(ws->touched);
    free(ws->patch_d);
    free(ws->in_patch);
    free(ws->tile_init);
    free(ws->group_init_left);
    free(ws->heap);
    free(ws->bhead);
    free(ws->nm_head);
    free(ws->rec);
    free(ws->pass_slot);
    free(ws->pass_hash);
    free(ws);
}

void mfmm_exact_solver_destroy(mfmm_exact_solver *solver)
{
    mfmm_exact_ws_destroy(solver);
}

size_t mfmm_exact_ws_bytes(const mfmm_mesh *mesh)
{
    size_t n_tiles = ((size_t)mesh->nv + EX_TILE - 1) / EX_TILE;
    return sizeof(mfmm_exact_ws) + (size_t)mesh->nv * (4 * sizeof(double) + sizeof(int32_t) + 1) +
           3 * EX_NB * sizeof(int32_t) + n_tiles +
           (n_tiles + EX_GROUP - 1) / EX_GROUP * sizeof(int32_t);
}

mfmm_status mfmm_exact_ws_create_shared(const mfmm_exact_tables *t, mfmm_exact_ws **out)
{
    if (!out)
        return MFMM_ERR_NULL_POINTER;
    *out = NULL;
    if (!t)
        return MFMM_ERR_NULL_POINTER;
    mfmm_exact_ws *ws = calloc(1, sizeof *ws);
    if (!ws)
        return MFMM_ERR_OUT_OF_MEMORY;
    size_t nv = (size_t)t->nv;
    ws->t = t;
    ws->budget = 64.0;
    ws->mesh = t->mesh;
    ws->nv = t->nv;
    ws->nf = t->nf;
    ws->vf_offset = t->vf_offset;
    ws->vf_corner = t->vf_corner;
    ws->face_in = t->face_in;
    ws->fr = t->fr;
    ws->pseudo = t->pseudo;
    ws->fan_a0 = t->fan_a0;
    ws->fan_total = t->fan_total;
    ws->height = t->height;
    ws->nm_he = t->nm_he;
    ws->nm_next = t->nm_next;
    ws->n_nm = t->n_nm;
    ws->inv_w = t->inv_w;
    ws->d = malloc((nv ? nv : 1) * sizeof *ws->d);
    ws->emitted = malloc((nv ? nv : 1) * sizeof *ws->emitted);
    ws->touched = malloc((nv ? nv : 1) * sizeof *ws->touched);
    ws->patch_d = malloc((nv ? nv : 1) * sizeof *ws->patch_d);
    ws->in_angle = malloc((nv ? nv : 1) * sizeof *ws->in_angle);
    ws->in_patch = calloc(nv ? nv : 1, sizeof *ws->in_patch);
    ws->bhead = malloc(3 * EX_NB * sizeof *ws->bhead);
    ws->nm_head = malloc((ws->n_nm ? (size_t)ws->n_nm : 1) * sizeof *ws->nm_head);
    ws->tile_init = calloc(t->n_tiles ? (size_t)t->n_tiles : 1, 1);
    ws->group_init_left =
        malloc((t->n_groups ? (size_t)t->n_groups : 1) * sizeof *ws->group_init_left);
    if (!ws->d || !ws->emitted || !ws->touched || !ws->patch_d || !ws->in_angle ||
        !ws->in_patch || !ws->bhead || !ws->nm_head || !ws->tile_init || !ws->group_init_left) {
        mfmm_exact_ws_destroy(ws);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
#if MFMM_POISON_UNBUILT
    /* NaN: a run that reads a vertex outside the tiles it set never lowers it */
    memset(ws->d, 0xff, (nv ? nv : 1) * sizeof *ws->d);
    memset(ws->emitted, 0xff, (nv ? nv : 1) * sizeof *ws->emitted);
    memset(ws->in_angle, 0xff, (nv ? nv : 1) * sizeof *ws->in_angle);
#endif
    for (int32_t G = 0; G < t->n_groups; G++) {
        int32_t T1 = (G + 1) * EX_GROUP < t->n_tiles ? (G + 1) * EX_GROUP : t->n_tiles;
        ws->group_init_left[G] = T1 - G * EX_GROUP;
    }
    for (int32_t i = 0; i < 3 * EX_NB; i++)
        ws->bhead[i] = -1;
    for (int32_t i = 0; i < ws->n_nm; i++)
        ws->nm_head[i] = -1;
    /* memory_limit counts the tables too, shared or not */
    ws->fixed_bytes = t->full_bytes + mfmm_exact_ws_bytes(t->mesh) + (size_t)ws->n_nm * sizeof(int32_t);
    ws->max_d = INFINITY;
    ws->peak_bytes = ws->fixed_bytes;
    *out = ws;
    return MFMM_OK;
}

mfmm_status mfmm_exact_ws_create(const mfmm_mesh *mesh, mfmm_exact_ws **out)
{
    if (!out)
        return MFMM_ERR_NULL_POINTER;
    *out = NULL;
    const mfmm_exact_tables *t = NULL;
    mfmm_status st = mfmm_exact_tables_of(mesh, &t);
    if (st != MFMM_OK)
        return st;
    return mfmm_exact_ws_create_shared(t, out);
}

mfmm_status mfmm_exact_solver_create(const mfmm_mesh *mesh, mfmm_exact_solver **out)
{
    return mfmm_exact_ws_create(mesh, out);
}

void mfmm_exact_ws_set_budget(mfmm_exact_ws *ws, double windows_per_vertex)
{
    ws->budget = windows_per_vertex;
}

mfmm_status mfmm_solve_exact(mfmm_exact_solver *solver, const mfmm_source *sources,
                             int32_t n_sources, const mfmm_exact_options *options,
                             double *distances, mfmm_exact_info *info, mfmm_error *err)
{
    mfmm_ok(err);
    mfmm_exact_info none;
    memset(&none, 0, sizeof none);
    none.struct_size = sizeof none;
    if (info && mfmm_write_info(info, &none, sizeof none) != MFMM_OK)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1,
                         "info->struct_size is below sizeof(size_t): set it to "
                         "sizeof(mfmm_exact_info)");
    if (!solver || !distances)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "%s is NULL",
                         !solver ? "solver" : "distances");
    for (int32_t v = 0; v < solver->nv; v++)
        distances[v] = INFINITY;
    if (!sources)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "sources is NULL");
    if (n_sources < 1)
        return mfmm_fail(err, MFMM_ERR_BAD_COUNT, -1, "n_sources is %ld; at least one is needed",
                         (long)n_sources);
    mfmm_exact_options opt;
    mfmm_exact_options_init(&opt);
    if (options &&
        mfmm_read_options(&opt, options, sizeof opt, "mfmm_exact_options", err) != MFMM_OK)
        return MFMM_ERR_BAD_ARGUMENT;
    options = &opt;
    double max_d = options->max_distance;
    if (isnan(max_d) || max_d < 0.0)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1, "max_distance is %g; it must be >= 0",
                         max_d);
    mfmm_status st = ex_check_sources(solver, sources, n_sources, err);
    if (st != MFMM_OK)
        return st;
    /* vertex sources in the mesh's internal order (mesh/order.h) */
    mfmm_mapped_args mapped = {0};
    if (mfmm_order_map_args(solver->mesh, sources, n_sources, NULL, 0, NULL, 0, NULL, &mapped) !=
        MFMM_OK)
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for the sources");
    solver->interrupt = options->interrupt;
    solver->interrupt_user = options->user;
    st = ex_run(solver, mapped.sources, n_sources, max_d, options->memory_limit);
    solver->interrupt = NULL;
    solver->interrupt_user = NULL;
    free(mapped.block);
    if (info) {
        mfmm_exact_info all;
        memset(&all, 0, sizeof all);
        ex_fill_info(solver, &all);
        all.struct_size = sizeof all;
        mfmm_write_info(info, &all, sizeof all);
    }
    if (st == MFMM_ERR_CANCELLED)
        return mfmm_fail(err, st, -1, "the exact solve was interrupted");
    if (st != MFMM_OK) {
        if (st == MFMM_ERR_MEMORY_LIMIT)
            return mfmm_fail(err, st, -1,
                             "the exact solve needed more than memory_limit = %zu bytes "
                             "(%lld windows queued)",
                             options->memory_limit, (long long)solver->heap_n);
        return mfmm_fail(err, st, -1, "out of memory for the window queue");
    }
    for (int32_t i = 0; i < solver->n_touched; i++) {
        int32_t v = solver->touched[i];
        double dv = solver->d[v];
        distances[mfmm_vertex_out(solver->mesh, v)] = dv <= max_d ? dv : INFINITY;
    }
    return MFMM_OK;
}
