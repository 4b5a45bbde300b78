/* mfmm_trace_path: a geodesic path from a target down the distances T to
 * the sources (trace.c walks it, straighten.c straightens it), in the
 * caller's ids. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "mesh/check.h"
#include "mesh/order.h"
#include "straighten.h"
#include "surface.h"
#include "trace.h"

static int validate_point(const mfmm_mesh *m, const mfmm_source *s, const char *what, int64_t idx,
                          mfmm_error *err)
{
    if (s->face == -1) {
        if (s->vertex < 0 || s->vertex >= m->nv)
            return mfmm_fail(err, MFMM_ERR_BAD_SOURCE, idx, "%s vertex %d is out of range [0, %d)",
                             what, (int)s->vertex, (int)m->nv);
        return MFMM_OK;
    }
    if (s->face < 0 || s->face >= m->nf_in)
        return mfmm_fail(err, MFMM_ERR_BAD_SOURCE, idx, "%s face %d is out of range [0, %d)", what,
                         (int)s->face, (int)m->nf_in);
    double sum = 0.0;
    for (int k = 0; k < 3; k++) {
        if (!isfinite(s->bary[k]) || s->bary[k] < 0.0)
            return mfmm_fail(err, MFMM_ERR_BAD_BARYCENTRIC, idx,
                             "%s barycentric coordinate %d = %g is not finite and >= 0", what, k,
                             s->bary[k]);
        sum += s->bary[k];
    }
    if (fabs(sum - 1.0) > 1e-9)
        return mfmm_fail(err, MFMM_ERR_BAD_BARYCENTRIC, idx,
                         "%s barycentric coordinates sum to %.17g, not 1", what, sum);
    /* as mfmm_solve refuses a source there: the walk reads T in the face's
     * plane, which a zero-area face does not span (a target there went round
     * through a corner: 1.20 long where the straight path is 0.86) */
    if (mfmm_order_point_degenerate(m, s->face, s->bary))
        return mfmm_fail(err, MFMM_ERR_DEGENERATE_SOURCE, idx,
                         "%s lies on face %d, which has zero area: give the same point on a face "
                         "beside it",
                         what, (int)s->face);
    return MFMM_OK;
}

void mfmm_path_options_init(mfmm_path_options *options)
{
    if (!options)
        return;
    memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
    options->max_points = 100000;
    options->cost_location = MFMM_COST_NONE;
    options->straighten = 1;
}

mfmm_status mfmm_trace_path(const mfmm_mesh *mesh, const double *distances,
                            const mfmm_source *target, const mfmm_path_options *options,
                            mfmm_surface_point *points, int32_t capacity, int32_t *n_points,
                            double *length, mfmm_error *err)
{
    mfmm_path_options defaults;
    mfmm_path_options_init(&defaults);
    const mfmm_path_options *o = &defaults;
    if (n_points)
        *n_points = 0;
    if (length)
        *length = 0.0;
    if (!mesh)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "mesh is NULL");
    if (!distances)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "distances is NULL");
    if (!target)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "target is NULL");
    if (!n_points)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "n_points is NULL");
    if (options && mfmm_read_options(&defaults, options, sizeof defaults, "mfmm_path_options",
                                     err) != MFMM_OK)
        return MFMM_ERR_BAD_ARGUMENT;
    if (capacity < 0)
        return mfmm_fail(err, MFMM_ERR_BAD_COUNT, capacity, "capacity %d is negative",
                         (int)capacity);
    if (capacity > 0 && !points)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "points is NULL with capacity %d",
                         (int)capacity);
    if (o->max_points < 1)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, o->max_points,
                         "max_points %d is not >= 1", (int)o->max_points);
    if (o->n_sources < 0 || (o->n_sources > 0 && !o->sources))
        return mfmm_fail(err, o->n_sources < 0 ? MFMM_ERR_BAD_COUNT : MFMM_ERR_NULL_POINTER,
                         o->n_sources, "n_sources is %d with sources %s", (int)o->n_sources,
                         o->sources ? "given" : "NULL");
    /* the whole cost, as mfmm_solve checks it: not only the faces the path
     * happens to cross, and named by the caller's ids, not the mesh's
     * internal order that the walk reads */
    mfmm_status st = mfmm_check_cost(mesh, o->cost, o->cost_location, err);
    if (st != MFMM_OK)
        return st;
    st = validate_point(mesh, target, "target", -1, err);
    if (st != MFMM_OK)
        return st;
    for (int32_t i = 0; i < o->n_sources; i++) {
        if ((st = validate_point(mesh, &o->sources[i], "source", i, err)) != MFMM_OK)
            return st;
        if (!isfinite(o->sources[i].value))
            return mfmm_fail(err, MFMM_ERR_BAD_SOURCE, i, "source %d has value %g", (int)i,
                             o->sources[i].value);
    }

    /* the caller's T, target, sources and per-vertex cost in the mesh's
     * internal vertex order (mesh/order.h); points hold faces only */
    mfmm_mapped_args mapped = {0};
    mfmm_source target_in = *target;
    if (target_in.face == -1)
        target_in.vertex = mfmm_vertex_in(mesh, target_in.vertex);
    else
        target_in.face = mfmm_order_point_in(mesh, target_in.face, target_in.bary, target_in.bary);
    if (mfmm_order_map_args(mesh, o->sources, o->n_sources, NULL, 0, o->cost,
                            o->cost ? (int)o->cost_location : 0, distances, &mapped) != MFMM_OK)
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "no memory for the distances");
    tracer t;
    memset(&t, 0, sizeof t);
    t.m = mesh;
    t.T = mapped.values;
    t.src = mapped.sources;
    t.n_src = o->n_sources;
    t.cost = mapped.cost;
    t.cost_loc = o->cost ? o->cost_location : MFMM_COST_NONE;
    t.pts = points;
    t.cap = capacity;
    t.max_points = o->max_points;
    t.err = err;
    t.st = MFMM_OK;
    /* The only scratch: the sources sorted by vertex and by face. */
    if (t.n_src > 0) {
        t.vkeys = malloc(sizeof(src_key) * (size_t)t.n_src);
        t.fkeys = malloc(sizeof(src_key) * (size_t)t.n_src);
        if (!t.vkeys || !t.fkeys) {
            free(t.vkeys);
            free(t.fkeys);
            free(mapped.block);
            return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "no memory for %d sources",
                             (int)t.n_src);
        }
        for (int32_t i = 0; i < t.n_src; i++) {
            const mfmm_source *s = &t.src[i];
            if (s->face == -1)
                t.vkeys[t.n_vkeys++] = (src_key){s->vertex, i};
            else
                t.fkeys[t.n_fkeys++] = (src_key){s->face, i};
        }
        qsort(t.vkeys, (size_t)t.n_vkeys, sizeof(src_key), mfmm_path_key_cmp);
        qsort(t.fkeys, (size_t)t.n_fkeys, sizeof(src_key), mfmm_path_key_cmp);
    }
    /* straight pieces need the whole traced path: trace into our own buffer */
    /* with a cost, the optimal path refracts where the cost changes (Snell):
     * straight chords between the traced border crossings cost less than the
     * traced path but bend at the wrong angles (ratio 0.93 +- 0.15 instead of
     * 0.99 +- 0.01 on Fig. 8b), so weighted paths stay as traced */
    int straight = o->straighten && !t.cost;
    if (straight) {
        t.pts = NULL;
        t.cap = 0;
        t.grow = 1;
    }
    st = mfmm_path_trace(&t, &target_in);
    free(t.vkeys);
    free(t.fkeys);
    if (straight) {
        mfmm_surface_point *raw = t.pts;
        int32_t n_raw = t.n;
        mfmm_surface_point *sp = NULL;
        int32_t n_sp = 0;
        int r = st == MFMM_OK && n_raw > 1 ? mfmm_path_straighten(mesh, t.cost, raw, n_raw, &sp, &n_sp) : -1;
        if (r == 0)
            st = mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "no memory to straighten %d points",
                           (int)n_raw);
        if (st == MFMM_OK) {
            double raw_len = t.len, raw_wlen = t.wlen;
            const mfmm_surface_point *use = raw;
            int32_t n_use = n_raw;
            if (r > 0)
                use = sp, n_use = n_sp;
            /* re-emit into the caller's buffer (lengths recomputed) */
            for (int pass = 0; pass < 2; pass++) {
                t.pts = points;
                t.cap = capacity;
                t.grow = 0;
                t.n = 0;
                t.len = t.wlen = 0.0;
                for (int32_t i = 0; i < n_use && st == MFMM_OK; i++)
                    if (!mfmm_path_emit(&t, use[i].face, use[i].bary))
                        st = t.st;
                if (st == MFMM_OK && t.len <= raw_len && t.wlen <= raw_wlen * (1.0 + 1e-12))
                    break;
                /* never longer than the traced path: else the traced path */
                st = MFMM_OK;
                use = raw;
                n_use = n_raw;
            }
        } else {
            t.n = t.n > capacity ? capacity : t.n;
            if (t.n > 0 && points)
                memcpy(points, raw, (size_t)t.n * sizeof *points);
            t.n = n_raw;
        }
        free(raw);
        free(sp);
    }
    free(mapped.block);
    if (points) /* the points' faces in the caller's ids */
        mfmm_order_points_out(mesh, points, t.n < capacity ? t.n : capacity);
    *n_points = t.n;
    if (length)
        *length = t.len;
    if (o->weighted_length)
        *o->weighted_length = t.wlen;
    if (st == MFMM_OK && t.n > t.cap)
        st = mfmm_fail(err, MFMM_ERR_BAD_COUNT, t.n, "the path has %d points, capacity is %d",
                       (int)t.n, (int)t.cap);
    if (st == MFMM_OK)
        mfmm_ok(err);
    return st;
}
