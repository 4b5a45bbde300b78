/* One run of the exact solver (run.h): reset, the sources started, the
 * queue drained through propagate.c, redone with non-manifold edges as walls
 * past a budget, and edge paths where it stalls. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "mesh/check.h"
#include "mesh/order.h"
#include "nonmanifold.h"
#include "propagate.h"
#include "queue.h"
#include "run.h"

/* Clears the previous run's vertex state (only what it touched). */
static void ex_reset(mfmm_exact_ws *ws)
{
    for (int32_t i = 0; i < ws->n_touched; i++) {
        int32_t v = ws->touched[i];
        ws->d[v] = INFINITY;
        ws->emitted[v] = INFINITY;
        ws->in_patch[v] = 0;
    }
    ws->n_touched = 0;
    for (int32_t i = 0; i < ws->rec_n; i++)
        if (ws->rec[i].slot >= 0)
            ws->nm_head[ws->rec[i].slot] = -1;
    ws->rec_n = 0;
    ex_pass_reset(ws);
    /* a run that emptied its queue left every bucket empty: only a failed
     * one (out of memory) needs them cleared (48 KB, a patch uses ~30) */
    if (ws->heap_n != 0)
        for (int32_t i = 0; i < 3 * EX_NB; i++)
            ws->bhead[i] = -1;
    ws->heap_n = 0;
    ws->heap_used = 0;
    ws->qfree = -1;
    ws->over = -1;
    ws->n_in = 0;
    ws->cur = -((int64_t)1 << 62);
    ws->redist = ws->cur;
    ws->failed = 0;
    ws->over_budget = 0;
    ws->stalled = 0;
    ws->n_windows = ws->n_propagated = ws->n_pseudo = ws->peak_windows = 0;
    ws->peak_bytes = ex_bytes(ws, ws->heap_cap);
}

/* Sets d to +inf on tile T's vertices (ex_tiles_visit). */
static void ex_clear_tile(void *ctx, int32_t T)
{
    mfmm_exact_ws *ws = ctx;
    int32_t v1 = (T + 1) * EX_TILE < ws->nv ? (T + 1) * EX_TILE : ws->nv;
    for (int32_t v = T * EX_TILE; v < v1; v++)
        ws->d[v] = INFINITY;
}

/* Whether the windows created so far are past what the vertices reached
 * so far can need: budget (1 + sqrt(n) / 8) a vertex, n vertices reached
 * (plus 64 budget), budget 64: 12-20 times what a solve needs on camelhead
 * (78 windows a vertex) and beetle (17). Past it, windows are going round
 * without getting farther, which degenerate folded fans (coincident
 * vertices) allowed, and ties kept at coincident vertices. */
static int ex_over_budget(const mfmm_exact_ws *ws)
{
    double n = (double)ws->n_touched;
    return (double)ws->n_windows > ws->budget * (64.0 + n * (1.0 + sqrt(n) / 8.0));
}

static void ex_heap_up(const double *d, int32_t *heap, int32_t *pos, int32_t i)
{
    int32_t v = heap[i];
    while (i > 0) {
        int32_t p = (i - 1) / 2;
        if (!(d[v] < d[heap[p]]))
            break;
        heap[i] = heap[p];
        pos[heap[i]] = i;
        i = p;
    }
    heap[i] = v;
    pos[v] = i;
}

static void ex_heap_down(const double *d, int32_t *heap, int32_t *pos, int32_t n, int32_t i)
{
    int32_t v = heap[i];
    for (;;) {
        int32_t c = 2 * i + 1;
        if (c >= n)
            break;
        if (c + 1 < n && d[heap[c + 1]] < d[heap[c]])
            c++;
        if (!(d[heap[c]] < d[v]))
            break;
        heap[i] = heap[c];
        pos[heap[i]] = i;
        i = c;
    }
    heap[i] = v;
    pos[v] = i;
}

/* After a stalled run: every distance lowered to the shortest path along
 * edges from the distances found, d(v) <= d(u) + |u v| (Dijkstra), each
 * the length of a real path, so that no vertex a path reaches is left at
 * +inf; within max_d. */
static mfmm_status ex_relax_edges(mfmm_exact_ws *ws)
{
    int32_t nv = ws->nv, n = 0;
    int32_t *heap = malloc((size_t)(nv ? nv : 1) * sizeof *heap);
    int32_t *pos = malloc((size_t)(nv ? nv : 1) * sizeof *pos);
    if (!heap || !pos) {
        free(heap);
        free(pos);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    double *d = ws->d;
    for (int32_t v = 0; v < nv; v++)
        pos[v] = -1;
    for (int32_t i = 0; i < ws->n_touched; i++) {
        int32_t v = ws->touched[i];
        if (d[v] <= ws->max_d) {
            heap[n] = v;
            ex_heap_up(d, heap, pos, n++);
        }
    }
    while (n > 0) {
        int32_t u = heap[0];
        pos[u] = -2;
        heap[0] = heap[--n];
        if (n > 0)
            ex_heap_down(d, heap, pos, n, 0);
        for (int32_t j = ws->vf_offset[u]; j < ws->vf_offset[u + 1]; j++) {
            int32_t c = ex_corner(ws->vf_corner, ws->face_in, j);
            const ex_face *r = ws->fr + c / 3;
            int k = c % 3;
            for (int side = 0; side < 2; side++) {
                int32_t a = r->v[side ? ex_prev[k] : ex_next[k]];
                double da = d[u] + r->len[side ? ex_next[k] : ex_prev[k]];
                if (!(da < d[a]) || da > ws->max_d || pos[a] == -2)
                    continue;
                if (d[a] == INFINITY)
                    ws->touched[ws->n_touched++] = a;
                d[a] = da;
                if (pos[a] < 0) {
                    heap[n] = a;
                    ex_heap_up(d, heap, pos, n++);
                } else {
                    ex_heap_up(d, heap, pos, pos[a]);
                }
            }
        }
    }
    free(heap);
    free(pos);
    return MFMM_OK;
}

/* The propagation from checked sources; d[] holds the result for touched
 * vertices (values > max_d are not final). */
static mfmm_status ex_run_once(mfmm_exact_ws *ws, const mfmm_source *sources,
                               int32_t n_sources, double max_d, size_t memory_limit)
{
    ex_reset(ws);
    ws->max_d = max_d;
    ws->memory_limit = memory_limit;
    if (memory_limit && ws->fixed_bytes > memory_limit)
        return MFMM_ERR_MEMORY_LIMIT;
    if (memory_limit && ex_bytes(ws, ws->heap_cap) > memory_limit) {
        /* the queue an earlier solve grew is empty now: give it back */
        free(ws->heap);
        ws->heap = NULL;
        ws->heap_cap = 0;
        free(ws->rec);
        ws->rec = NULL;
        ws->rec_cap = 0;
        free(ws->pass_slot);
        free(ws->pass_hash);
        ws->pass_slot = ws->pass_hash = NULL;
        ws->pass_cap = 0;
        ws->peak_bytes = ex_bytes(ws, 0);
    }
    for (int32_t i = 0; i < n_sources; i++) {
        const mfmm_source *s = sources + i;
        if (s->face < 0) {
            ex_update(ws, s->vertex, s->value, 1);
            continue;
        }
        /* a point of a copy is that point of its original */
        int32_t face = mfmm_mesh_original(ws->mesh, s->face);
        const int32_t *fv = ws->mesh->face_records[face].v, *sv = ws->mesh->face_records[s->face].v;
        double w[3], sum = 0.0;
        for (int k = 0; k < 3; k++) {
            int j = sv[0] == fv[k] ? 0 : sv[1] == fv[k] ? 1 : 2;
            w[k] = s->bary[j] > 0.0 ? s->bary[j] : 0.0;
            sum += w[k];
        }
        int corner = -1;
        for (int k = 0; k < 3; k++) {
            w[k] /= sum;
            if (w[k] >= 1.0 - 1e-12)
                corner = k;
        }
        if (corner >= 0) {
            /* at a corner: a vertex source, offset by the (tiny) distance */
            double p[3];
            mfmm_bary_to_xyz(ws->mesh, face, w, p);
            ex_update(ws, fv[corner],
                      s->value + vdist(p, ws->mesh->xyz + 3 * (size_t)fv[corner]), 1);
            continue;
        }
        ex_start_face(ws, ws->face_in[face], w, s->value);
    }
    for (int64_t n = 1; ws->heap_n > 0 && !ws->failed; n++) {
        if (!(n & 4095) && ex_over_budget(ws)) {
            if (ws->n_nm > 0 && !ws->walls)
                ws->over_budget = 1;
            else
                ws->stalled = 1;
            break;
        }
        /* about every 5 ms */
        if (!(n & 65535) && ws->interrupt && ws->interrupt(ws->interrupt_user)) {
            ws->failed = MFMM_ERR_CANCELLED;
            break;
        }
        ex_entry e;
        ex_pop(ws, &e);
        if (e.he < 0) {
            int32_t v = -e.he - 1;
            if (e.key != ws->d[v] || !(ws->emitted[v] > e.key))
                continue;
            ws->emitted[v] = e.key;
            ex_start_vertex(ws, v, e.key);
        } else {
            ex_propagate(ws, &e);
        }
    }
    return ws->failed ? (mfmm_status)ws->failed : MFMM_OK;
}

/* ex_run_once across non-manifold edges; where its windows pass their
 * budget (ex_over_budget), again with those edges as walls: upper bounds
 * there, the solver's behaviour before it crossed them (mfmm_exact_info's
 * nonmanifold_walls says which). A run past its budget otherwise stops, and
 * paths along edges finish it (ex_relax_edges): a defect's values are then
 * too long, never too short, and the solve ends. */
mfmm_status ex_run(mfmm_exact_ws *ws, const mfmm_source *sources, int32_t n_sources,
                          double max_d, size_t memory_limit)
{
    /* the tables within max_d of the sources (no path it keeps goes farther) */
    double few[3 * 8] = {0}, *p = n_sources <= 8 ? few : malloc(3 * (size_t)n_sources * sizeof *p);
    double least = INFINITY;
    for (int32_t i = 0; p && i < n_sources; i++) {
        const mfmm_source *s = sources + i;
        least = fmin(least, s->value);
        if (s->face < 0) {
            memcpy(p + 3 * i, ws->mesh->xyz + 3 * (size_t)s->vertex, 3 * sizeof *p);
            continue;
        }
        double w[3], sum = 0.0;
        for (int k = 0; k < 3; k++)
            sum += w[k] = s->bary[k] > 0.0 ? s->bary[k] : 0.0;
        for (int k = 0; k < 3; k++)
            w[k] /= sum;
        mfmm_bary_to_xyz(ws->mesh, s->face, w, p + 3 * i);
    }
    double radius = p ? max_d - least : INFINITY;
    mfmm_exact_tables_ensure(ws->t, p, n_sources, radius);
    if (ws->n_init < ws->t->n_tiles)
        ws->n_init += ex_tiles_visit(ws->t, ws->tile_init, 1, ws->group_init_left, p, n_sources,
                                     radius + ws->t->pad, ex_clear_tile, ws);
    if (p != few)
        free(p);
    ws->walls = 0;
    mfmm_status st = ex_run_once(ws, sources, n_sources, max_d, memory_limit);
    if (st == MFMM_OK && ws->over_budget) {
        ws->walls = 1;
        st = ex_run_once(ws, sources, n_sources, max_d, memory_limit);
    }
    if (st == MFMM_OK && ws->stalled)
        st = ex_relax_edges(ws);
    return st;
}

void ex_fill_info(const mfmm_exact_ws *ws, mfmm_exact_info *info)
{
    if (!info)
        return;
    info->n_windows = ws->n_windows;
    info->n_propagated = ws->n_propagated;
    info->n_pseudo_sources = ws->n_pseudo;
    info->peak_windows = ws->peak_windows;
    info->peak_bytes = ws->peak_bytes;
    info->nonmanifold_walls = ws->walls;
}

/* Sources as mfmm_solve checks them, and not in a face this solver skips. */
mfmm_status ex_check_sources(const mfmm_exact_ws *ws, const mfmm_source *sources,
                                    int32_t n_sources, mfmm_error *err)
{
    for (int32_t i = 0; i < n_sources; i++) {
        mfmm_status st = mfmm_check_source(ws->mesh, sources + i, i, err);
        if (st != MFMM_OK)
            return st;
        double b[3];
        if (sources[i].face >= 0 &&
            mfmm_mesh_degenerate(ws->mesh,
                                 mfmm_order_point_in(ws->mesh, sources[i].face, sources[i].bary, b)))
            return mfmm_fail(err, MFMM_ERR_DEGENERATE_SOURCE, i,
                             "source %ld lies on face %ld, which has zero area", (long)i,
                             (long)sources[i].face);
    }
    return MFMM_OK;
}
