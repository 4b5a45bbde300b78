/* The window method's C workspace and entry points (slots.h): the mesh's
 * exact tables, one solve's arrays, and the starts from vertex and face
 * sources. The propagation itself: slots_core.h, shared with the OpenCL
 * kernel. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "slots.h"
#include "slots_core.h"
#include "state.h"

struct mfmm_slots {
    const mfmm_exact_tables *t;
    const mfmm_mesh *mesh;
    sl_state c;
    char *block;   /* sl_state's per-solve arrays (sl_attach), as the kernel lays them out */
    uint8_t *flat; /* (nv) sl_state's, owned here */
    double *fcost; /* (nf) the records' costs of the last run with a cost, relative */
    double *vcost; /* (nv) the vertices' costs of the last run per vertex, relative */
};

void mfmm_slots_flat(const mfmm_exact_tables *t, uint8_t *flat)
{
    /* a vertex at a wall (two wall edges, no zero-area face or copy) whose
     * angle sum is pi or less bends no shortest path: it needs no offers;
     * flat: a vertex whose offers the windows beside it make
     * redundant once a ray reaches it: one whose neighbourhood unfolds flat
     * (an angle sum of 2 pi, no wall) or a wall's vertex of pi or less */
    for (int32_t v = 0; v < t->nv; v++) {
        double a = 0.0;
        int walls = 0, odd = 0;
        for (int32_t j = t->vf_offset[v]; j < t->vf_offset[v + 1]; j++) {
            int32_t c = ex_corner(t->vf_corner, t->face_in, j);
            const ex_face *r = t->fr + c / 3;
            int k = c % 3;
            odd |= r->skip != 0;
            a += r->angle[k];
            walls += (r->across[ex_next[k]] < 0) + (r->across[ex_prev[k]] < 0);
        }
        int need = t->pseudo[v] && (odd || walls != 2 || !(a <= EX_PI * (1.0 + 1e-9)));
        flat[v] = (uint8_t)(!need && !odd &&
                            ((walls == 0 && fabs(a - EX_TWO_PI) <= 1e-9 * EX_TWO_PI) ||
                             walls == 2));
    }
}

void mfmm_slots_flat_of(const mfmm_mesh *mesh, uint8_t *flat)
{
    const mfmm_exact_tables *t = NULL;
    if (mfmm_exact_tables_of(mesh, &t) == MFMM_OK)
        mfmm_slots_flat(t, flat);
}

mfmm_status mfmm_slots_create(const mfmm_mesh *mesh, mfmm_slots **out)
{
    const mfmm_exact_tables *t = NULL;
    *out = NULL;
    mfmm_status st = mfmm_exact_tables_of(mesh, &t);
    if (st != MFMM_OK)
        return st;
    mfmm_exact_tables_ensure(t, NULL, 0, INFINITY);
    mfmm_slots *s = calloc(1, sizeof *s);
    if (!s)
        return MFMM_ERR_OUT_OF_MEMORY;
    size_t nv = (size_t)t->nv;
    sl_state *c = &s->c;
    s->t = t;
    s->mesh = mesh;
    c->nv = t->nv;
    c->nf = t->nf;
    c->fr = t->fr;
    c->vf_offset = t->vf_offset;
    c->vf_corner = t->vf_corner;
    c->face_in = t->face_in;
    c->nm_he = t->nm_he;
    c->nm_next = t->nm_next;
    c->n_nm = t->n_nm;
    c->K = 2;
    s->flat = malloc(nv + 1);
    c->flat = s->flat;
    s->fcost = malloc(((size_t)t->nf + 1) * sizeof *s->fcost);
    s->vcost = malloc((nv + 1) * sizeof *s->vcost);
    s->block = malloc(sl_block_bytes(t->nv, t->nf, c->K) + 8);
    if (!s->flat || !s->fcost || !s->vcost || !s->block) {
        mfmm_slots_destroy(s);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    sl_attach(c, s->block);
    mfmm_slots_flat(t, s->flat);
    *out = s;
    return MFMM_OK;
}

size_t mfmm_slots_bytes(const mfmm_mesh *mesh)
{
    size_t nv = (size_t)mesh->nv, nh = 3 * (size_t)mesh->nf;
    /* one solve's block (K = 2); the flat flags and a cost per vertex; a
     * cost per face */
    return sl_block_bytes(mesh->nv, mesh->nf, 2) + nv * (1 + sizeof(double)) +
           (nh / 3) * sizeof(double);
}

size_t mfmm_slots_block_bytes(const mfmm_mesh *mesh)
{
    return sl_block_bytes(mesh->nv, mesh->nf, 2);
}

mfmm_status mfmm_slots_tables_of(const mfmm_mesh *mesh, mfmm_slots_tables *out)
{
    const mfmm_exact_tables *t = NULL;
    mfmm_status st = mfmm_exact_tables_of(mesh, &t);
    if (st != MFMM_OK)
        return st;
    mfmm_exact_tables_ensure(t, NULL, 0, INFINITY);
    out->fr = t->fr;
    out->fr_size = sizeof(ex_face);
    out->vf_offset = t->vf_offset;
    out->vf_corner = t->vf_corner;
    out->face_in = t->face_in;
    out->nm_he = t->nm_he;
    out->nm_next = t->nm_next;
    out->n_nm = t->n_nm;
    return MFMM_OK;
}

void mfmm_slots_destroy(mfmm_slots *s)
{
    if (!s)
        return;
    free(s->flat);
    free(s->fcost);
    free(s->vcost);
    free(s->block);
    free(s);
}

int mfmm_slots_set_k(mfmm_slots *s, int K)
{
    if (K < 1 || K > 8)
        return 0;
    char *block = malloc(sl_block_bytes(s->c.nv, s->c.nf, K) + 8);
    if (!block)
        return 0;
    free(s->block);
    s->block = block;
    s->c.K = K;
    sl_attach(&s->c, block);
    return 1;
}

void mfmm_slots_get_info(const mfmm_slots *s, mfmm_slots_info *info)
{
    const sl_counts *n = &s->c.info;
    info->crossed = n->crossed;
    info->emitted = n->emitted;
    info->kept = n->kept;
    info->late = n->late;
    info->late_vertex = n->late_vertex;
    info->settled = n->settled;
    info->narrow = n->narrow;
    info->trimmed = n->trimmed;
    info->evicted = n->evicted;
    info->merged = n->merged;
}

/* the propagation to its end, every vertex's value to out */
static void sl_run(mfmm_slots *s, double *out)
{
    sl_loop(&s->c, INFINITY, 0);
    for (size_t v = 0; v < (size_t)s->c.nv; v++)
        out[v] = s->c.d[v];
}

/* No cost: every face 1.0 (the window method's own entry points). */
static void sl_no_cost(mfmm_slots *s)
{
    s->c.fcost = NULL;
    s->c.h.cost = NULL;
    s->c.h.cost_location = 0;
}

void mfmm_slots_solve(mfmm_slots *s, int32_t source, double *out)
{
    mfmm_slots_solve_multi(s, 1, &source, NULL, out);
}

void mfmm_slots_solve_multi(mfmm_slots *s, int32_t n, const int32_t *src, const double *value,
                            double *out)
{
    sl_no_cost(s);
    sl_reset(&s->c);
    for (int32_t i = 0; i < n; i++) {
        sl_update(&s->c, src[i], value ? value[i] : 0.0, 0);
        s->c.is_src[src[i]] = 1;
    }
    sl_run(s, out);
}

void mfmm_slots_solve_face(mfmm_slots *s, int32_t f, const int32_t fv[3], const double w[3],
                           double *out)
{
    sl_no_cost(s);
    sl_reset(&s->c);
    const ex_face *r = s->c.fr + f;
    double b[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < 3; k++)
        for (int j = 0; j < 3; j++)
            if (fv[j] == r->v[k])
                b[k] = w[j];
    double sum = b[0] + b[1] + b[2];
    if (r->skip || !(sum > 0.0)) {
        /* a face with no area (or no weights): nothing reached */
        sl_run(s, out);
        return;
    }
    for (int k = 0; k < 3; k++) {
        /* the point in half-edge 3f+k's frame (corner k+1 at 0, k+2 at L,
         * corner k at (cx, cy)): a window of the whole edge, sigma 0, that
         * also sets the edge's ends to their straight distances */
        double bk = b[k] / sum, b2 = b[ex_prev[k]] / sum, L = r->len[k];
        double ix = bk * r->cx[k] + b2 * L, iy = bk * r->cy[k];
        sl_emit(&s->c, 3 * f + k, 0.0, L, 0.0, L, ix, iy, 0.0, 0);
    }
    sl_run(s, out);
}

/* The cost of a straight segment from a point in face record r_id to its
 * corner v: the face's, or in a face of mixed cost (per vertex) the mean of
 * the cost at the point (fp, interpolated) and at v, as the march's
 * straight start (start/straight.c). */
static double sl_start_cost(const mfmm_slots *s, int32_t r_id, double fp, int32_t v)
{
    double c = sl_cost(&s->c, r_id);
    return c > 0.0 ? c : 0.5 * (fp + s->c.h.cost[v]);
}

/* A point in face record r at weights b (r's corners, summing to 1, none
 * 1): each edge gets a window of the whole edge from the point, which also
 * sets the edge's ends to their straight distances. In a face of mixed cost
 * the corners get the march's straight start instead (no window lies
 * there). */
static void sl_start_face(mfmm_slots *s, int32_t r_id, const double b[3], double value)
{
    const ex_face *r = s->c.fr + r_id;
    if (!(sl_cost(&s->c, r_id) > 0.0)) {
        double fp = 0.0;
        for (int k = 0; k < 3; k++)
            fp += b[k] * s->c.h.cost[r->v[k]];
        for (int k = 0; k < 3; k++) {
            /* |point corner k| in half-edge 3r+k's frame: corner k at
             * (cx, cy), the point at (ix, iy) */
            double L = r->len[k];
            double ix = b[k] * r->cx[k] + b[ex_prev[k]] * L, iy = b[k] * r->cy[k];
            double dx = r->cx[k] - ix, dy = r->cy[k] - iy;
            sl_update(&s->c, r->v[k], value + sl_start_cost(s, r_id, fp, r->v[k]) *
                                                  sqrt(dx * dx + dy * dy), 0);
        }
        return;
    }
    for (int k = 0; k < 3; k++) {
        /* the point in half-edge 3f+k's frame (corner k+1 at 0, k+2 at L,
         * corner k at (cx, cy)) */
        double L = r->len[k];
        double ix = b[k] * r->cx[k] + b[ex_prev[k]] * L, iy = b[k] * r->cy[k];
        sl_emit(&s->c, 3 * r_id + k, 0.0, L, 0.0, L, ix, iy, value, 0);
    }
}

static double sl_face_cost(const mfmm_exact_tables *t, const double *cost, int cost_location,
                           double *fout, double *vout)
{
    /* the scale: the least cost, so that a constant cost runs at 1.0, the
     * bits of no cost, and its values are the scale times those */
    int32_t n = cost_location == 2 ? t->nf : t->nv;
    double scale = cost[0];
    for (int32_t i = 1; i < n; i++)
        scale = cost[i] < scale ? cost[i] : scale;
    if (cost_location == 1)
        for (int32_t v = 0; v < t->nv; v++)
            vout[v] = cost[v] / scale;
    for (int32_t f = 0; f < t->nf; f++) {
        const ex_face *r = t->fr + t->face_in[f];
        double x = cost_location == 2 ? cost[f] : cost[r->v[0]];
        if (cost_location == 1 && (cost[r->v[1]] != x || cost[r->v[2]] != x))
            fout[t->face_in[f]] = -1.0;
        else
            fout[t->face_in[f]] = x / scale;
    }
    return scale;
}

double mfmm_slots_face_cost(const mfmm_mesh *mesh, const double *cost, int cost_location,
                            double *fout, double *vout)
{
    const mfmm_exact_tables *t = NULL;
    if (mfmm_exact_tables_of(mesh, &t) != MFMM_OK)
        return 1.0;
    return sl_face_cost(t, cost, cost_location, fout, vout);
}

/* Sets the records' costs (sl_state.fcost) of a cost in internal ids;
 * returns the scale they are relative to (1.0 with no cost). */
static double sl_set_cost(mfmm_slots *s, const double *cost, int cost_location)
{
    sl_no_cost(s);
    if (!cost || (cost_location != 1 && cost_location != 2))
        return 1.0;
    double scale = sl_face_cost(s->t, cost, cost_location, s->fcost, s->vcost);
    s->c.fcost = s->fcost;
    if (cost_location == 1) {
        s->c.h.cost = s->vcost;
        s->c.h.cost_location = 1;
    }
    return scale;
}

int32_t mfmm_slots_run(mfmm_slots *s, const mfmm_source *sources, int32_t n_sources,
                       double max_distance, const int32_t *targets, int32_t n_targets,
                       const double *cost, int cost_location, double *T, int32_t *settled)
{
    const mfmm_mesh *mesh = s->mesh;
    /* the run is in units of the scale (the least cost): values, sources'
     * values and the level divided by it, the values written times it */
    double scale = sl_set_cost(s, cost, cost_location), level = max_distance / scale;
    sl_reset(&s->c);
    int32_t n_tgt = sl_targets(&s->c, targets, n_targets);
    for (int32_t i = 0; i < n_sources; i++) {
        const mfmm_source *src = sources + i;
        if (src->face < 0) {
            sl_update(&s->c, src->vertex, src->value / scale, 0);
            s->c.is_src[src->vertex] = 1;
            continue;
        }
        /* a point of a copy is that point of its original; weights in the
         * record's corner order */
        int32_t face = mfmm_mesh_original(mesh, src->face);
        const ex_face *r = s->c.fr + s->c.face_in[face];
        const int32_t *sv = mesh->face_records[src->face].v;
        double b[3], sum = 0.0;
        for (int k = 0; k < 3; k++) {
            int j = sv[0] == r->v[k] ? 0 : sv[1] == r->v[k] ? 1 : 2;
            b[k] = src->bary[j] > 0.0 ? src->bary[j] : 0.0;
            sum += b[k];
        }
        int corner = -1;
        for (int k = 0; k < 3; k++) {
            b[k] /= sum;
            if (b[k] >= 1.0 - 1e-12)
                corner = k;
        }
        int32_t rec = s->c.face_in[face];
        double fp = 0.0; /* the cost at the point (per vertex) */
        if (s->c.h.cost)
            for (int k = 0; k < 3; k++)
                fp += b[k] * s->c.h.cost[r->v[k]];
        if (corner >= 0) {
            /* at a corner: a vertex source, offset by the (tiny) distance */
            double p[3], w[3];
            for (int k = 0; k < 3; k++) {
                const int32_t *fv = mesh->face_records[face].v;
                int j = fv[0] == r->v[k] ? 0 : fv[1] == r->v[k] ? 1 : 2;
                w[j] = b[k];
            }
            mfmm_bary_to_xyz(mesh, face, w, p);
            int32_t v = r->v[corner];
            sl_update(&s->c, v,
                      src->value / scale +
                          sl_start_cost(s, rec, fp, v) * vdist(p, mesh->xyz + 3 * (size_t)v),
                      0);
            s->c.is_src[v] = 1;
            continue;
        }
        sl_start_face(s, s->c.face_in[face], b, src->value / scale);
        if (mesh->piece_next) {
            /* a face cut at T-junctions: the segments from the point to
             * every piece's corners lie in the face as given (the edges
             * between pieces may be non-manifold, where windows stop) */
            double p[3];
            mfmm_bary_to_xyz(mesh, src->face, src->bary, p);
            for (int32_t q = mesh->face_to_internal[mesh->face_to_external[src->face]]; q >= 0;
                 q = mesh->piece_next[q])
                for (int k = 0; k < 3; k++) {
                    int32_t c = mesh->face_records[q].v[k];
                    sl_update(&s->c, c,
                              src->value / scale + sl_start_cost(s, rec, fp, c) *
                                               vdist(p, mesh->xyz + 3 * (size_t)c),
                              0);
                }
        }
    }
    sl_loop(&s->c, level, n_tgt);
    int32_t n = 0;
    for (int32_t v = 0; v < s->c.nv; v++) {
        if (s->c.h.label[v] == 2 && s->c.d[v] <= level) {
            T[v] = scale * s->c.d[v];
            if (settled)
                settled[n] = v;
            n++;
        }
    }
    return n;
}

