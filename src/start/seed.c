/* The exact start of a march (seed.h). */
#include <math.h>

#include "base/error.h"
#include "seed.h"

mfmm_status mfmm_check_exact_start(double radius, mfmm_error *err)
{
    if (radius != MFMM_EXACT_START_AUTO && (!isfinite(radius) || radius < 0.0))
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1,
                         "exact_start_radius is %g; it must be finite and >= 0 (0: the plain "
                         "start) or MFMM_EXACT_START_AUTO (-1, the default)",
                         radius);
    return MFMM_OK;
}

double mfmm_exact_start_edges(const mfmm_mesh *mesh, double radius, double max_distance)
{
    if (radius != MFMM_EXACT_START_AUTO)
        return radius;
    double r = MFMM_EXACT_START_RADIUS;
    if (isinf(max_distance) && mesh->nv > MFMM_EXACT_START_AUTO_VERTICES)
        r *= sqrt((double)mesh->nv / MFMM_EXACT_START_AUTO_VERTICES);
    return r;
}

size_t mfmm_exact_start_bytes(const mfmm_mesh *mesh)
{
    return mfmm_exact_ws_bytes(mesh);
}

/* The longest distance from p to a corner of a face around vertex v. */
static double reach_around(const mfmm_mesh *m, int32_t v, const double *p)
{
    double r = 0.0;
    for (int32_t i = m->vertex_face_offset[v]; i < m->vertex_face_offset[v + 1]; i++) {
        const int32_t *f = m->face_records[MFMM_WEDGE_FACE(m->vertex_wedge[i])].v;
        for (int k = 0; k < 3; k++)
            r = fmax(r, mfmm_dist3(p, m->xyz + 3 * (size_t)f[k]));
    }
    return r;
}

/* mfmm_exact_start, and in *patch_radius the patch's radius (0 when *n is 0). */
static mfmm_status exact_start(const mfmm_mesh *mesh, mfmm_exact_ws **ws, const mfmm_source *src,
                               double radius, double max_d, const double *cost,
                               const double *uniform, int32_t *n, const int32_t **vertices,
                               const double **distances, double *F, double *patch_radius,
                               int32_t *n_fallback)
{
    *n = 0;
    *n_fallback = 0;
    *patch_radius = 0.0;
    *F = 1.0;
    radius = mfmm_exact_start_edges(mesh, radius, max_d);
    if (!(radius > 0.0))
        return MFMM_OK;
    /* the patch around the source at value 0; a point at a corner is that
     * vertex, whichever face names it */
    mfmm_source s = *src;
    s.value = 0.0;
    int32_t center = s.vertex;
    double reach = 0.0;
    if (s.face >= 0) {
        mfmm_source_loc at;
        mfmm_source_locate(mesh, &s, &at);
        const int32_t *fv = mesh->face_records[s.face].v;
        int32_t g = at.across;
        center = at.vertex;
        if (at.kind == MFMM_AT_VERTEX) {
            s.face = -1;
            s.vertex = center;
        } else if (g >= 0 && g < s.face && !mfmm_mesh_degenerate(mesh, g)) {
            /* on an edge: named by the lower of its two faces, so that the
             * patch does not depend on which face names the point */
            const int32_t *gv = mesh->face_records[g].v;
            double b[3] = {0.0, 0.0, 0.0};
            for (int k = 0; k < 3; k++)
                for (int j = 0; j < 3; j++)
                    if (gv[j] == fv[k] && k != at.zero)
                        b[j] = s.bary[k];
            s.face = g;
            s.bary[0] = b[0];
            s.bary[1] = b[1];
            s.bary[2] = b[2];
            return exact_start(mesh, ws, &s, radius, max_d, cost, uniform, n, vertices,
                               distances, F, patch_radius, n_fallback);
        } else {
            /* its own faces' corners (both faces of an edge it lies on) */
            for (int k = 0; k < 3; k++)
                reach = fmax(reach, mfmm_dist3(at.p, mesh->xyz + 3 * (size_t)fv[k]));
            const int32_t *gv = g >= 0 ? mesh->face_records[g].v : NULL;
            for (int k = 0; gv && k < 3; k++)
                reach = fmax(reach, mfmm_dist3(at.p, mesh->xyz + 3 * (size_t)gv[k]));
        }
    }
    if (s.face < 0)
        reach = reach_around(mesh, center, mesh->xyz + 3 * (size_t)center);
    double f = 1.0;
    if (cost) {
        f = uniform[center];
        if (!(f > 0.0))
            return MFMM_OK; /* costs differ around the source: straight start */
    }
    if (!*ws) {
        mfmm_status st = mfmm_exact_ws_create(mesh, ws);
        if (st != MFMM_OK)
            return st;
    }
    double R = radius * mesh->info.mean_edge_length;
    /* past max_d the row is +inf: a local row needs no more, and
     * is then exact where it is finite */
    if (max_d < R * f)
        R = max_d / f * (1.0 + 1e-9);
    R = fmax(R, reach * (1.0 + 1e-12));
    int32_t np = 0;
    const int32_t *pv = NULL;
    const double *pd = NULL;
    mfmm_status st = mfmm_exact_patch(*ws, &s, 1, R, 0, &np, &pv, &pd, NULL);
    if (st == MFMM_ERR_OUT_OF_MEMORY || st == MFMM_ERR_MEMORY_LIMIT)
        return MFMM_ERR_OUT_OF_MEMORY;
    if (st != MFMM_OK) /* a face the exact solver skips: straight start */
        return MFMM_OK;
    /* a distance the exact solver got wrong is left to the march */
    st = mfmm_exact_patch_check(*ws, &s, &np, n_fallback);
    if (st != MFMM_OK)
        return st;
    if (cost)
        for (int32_t i = 0; i < np; i++)
            if (uniform[pv[i]] != f)
                return MFMM_OK;
    *n = np;
    *vertices = pv;
    *distances = pd;
    *F = f;
    *patch_radius = R;
    return MFMM_OK;
}

mfmm_status mfmm_exact_start(const mfmm_mesh *mesh, mfmm_exact_ws **ws, const mfmm_source *src,
                             double radius, double max_distance, const double *cost,
                             const double *uniform, int32_t *n, const int32_t **vertices,
                             const double **distances, double *F, int32_t *n_fallback)
{
    double R;
    return exact_start(mesh, ws, src, radius, max_distance - src->value, cost, uniform, n,
                       vertices, distances, F, &R, n_fallback);
}

typedef struct beyond_ctx {
    mfmm_march_state *st;
    const mfmm_exact_ws *ws;
    double value, R;
} beyond_ctx;

/* A straight-start hit beyond the patch (see mfmm_exact_start_seed). */
static int seed_beyond(void *user, const mfmm_start_hit *h)
{
    beyond_ctx *c = user;
    /* not in the patch, whose exact values it must not undercut (the
     * straight walk can give less than the exact solver at the patch's
     * outer ring) */
    if (h->length > c->R && !mfmm_exact_in_patch(c->ws, h->vertex))
        mfmm_march_seed(c->st, h->vertex, c->value + h->cost_length);
    return 0;
}

mfmm_status mfmm_exact_start_seed(const mfmm_mesh *mesh, mfmm_exact_ws **ws,
                                  mfmm_march_state *st, const mfmm_source *src, double radius,
                                  const double *uniform, int fixed, int32_t *n_fallback)
{
    int32_t n = 0;
    const int32_t *pv = NULL;
    const double *pd = NULL;
    double f = 1.0, R = 0.0;
    mfmm_status status = exact_start(mesh, ws, src, radius, st->max_distance - src->value,
                                     st->cost, st->cost ? uniform : NULL, &n, &pv, &pd, &f, &R,
                                     n_fallback);
    if (status != MFMM_OK)
        return status;
    if (n == 0) {
        mfmm_start_seed(mesh, st, src);
        return MFMM_OK;
    }
    if (fixed) {
        mfmm_march_mesh mm = mfmm_mesh_march_view(mesh);
        mfmm_march_seed_patch(st, &mm, pv, pd, n, src->value, f);
    } else {
        for (int32_t i = 0; i < n; i++)
            mfmm_march_seed(st, pv[i], src->value + f * pd[i]);
    }
    if (src->face >= 0) {
        /* the straight start's vertices beyond the patch: its walk reaches
         * the mesh's longest edge (straight.c), exact where the surface is
         * flat; without them a face source can start worse than the plain
         * start (docs/performance.md#design-measurements) */
        beyond_ctx c = {st, *ws, src->value, R};
        mfmm_start_walk(mesh, src, st->cost, st->cost_location, seed_beyond, &c);
    }
    return MFMM_OK;
}
