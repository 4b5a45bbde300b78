/*
 * The walk of a minimal geodesic path (Kimmel & Sethian 1998, section 5):
 * backtrack from a target along dX/ds = -grad T with Heun's second-order
 * method, switching to a first-order (Euler) step at sonic points, grad T
 * being the face's field (field.c). The path moves face to face through
 * edges and vertices and records a surface point at each crossing; between
 * two points it is straight (a geodesic inside a flat face is). It ends at
 * a source: a vertex, a face source's face, or along the straight start's
 * segment (start/straight.h).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "field.h"
#include "mesh/check.h"
#include "mesh/order.h"
#include "mesh/unfold.h"
#include "start/straight.h"
#include "surface.h"
#include "trace.h"

/* Appends a point; the segment to it ran through face f. */
int mfmm_path_emit(tracer *t, int32_t f, const double b[3])
{
    double x[3], F = mfmm_path_cost_at(t, f, b);
    mfmm_bary_to_xyz(t->m, f, b, x);
    if (t->n > 0) {
        double d = mfmm_dist3(x, t->last_xyz);
        t->len += d;
        t->wlen += d * (t->cost && t->cost_loc == MFMM_COST_PER_VERTEX ? 0.5 * (F + t->last_F) : F);
    }
    if (t->n >= t->max_points) {
        t->st = mfmm_fail(t->err, MFMM_ERR_PATH_STALLED, t->n,
                          "the path needs more than max_points = %d points", (int)t->max_points);
        return 0;
    }
    if (t->n >= t->cap && t->grow) {
        int32_t nc = t->cap > t->max_points / 2 ? t->max_points : (t->cap > 32 ? 2 * t->cap : 64);
        mfmm_surface_point *q = realloc(t->pts, (size_t)nc * sizeof *q);
        if (!q) {
            t->st = mfmm_fail(t->err, MFMM_ERR_OUT_OF_MEMORY, t->n, "no memory for %d path points",
                              (int)nc);
            return 0;
        }
        t->pts = q;
        t->cap = nc;
    }
    if (t->n < t->cap) {
        mfmm_surface_point *p = &t->pts[t->n];
        p->face = f;
        for (int i = 0; i < 3; i++) {
            p->bary[i] = b[i];
            p->xyz[i] = x[i];
        }
    }
    t->n++;
    memcpy(t->last_xyz, x, sizeof x);
    t->last_F = F;
    return 1;
}

int mfmm_path_key_cmp(const void *a, const void *b)
{
    const src_key *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return x->idx < y->idx ? -1 : x->idx > y->idx;
}

static int32_t lower_bound(const src_key *k, int32_t n, int32_t key)
{
    int32_t lo = 0, hi = n;
    while (lo < hi) {
        int32_t mid = lo + (hi - lo) / 2;
        if (k[mid].key < key)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* The best source reachable straight inside face f from the point at b: the
 * one with the least value + F |x - source| that agrees with T(x) within half
 * a face (the distance came from it). Returns the source index or -1. */
static int32_t face_source(tracer *t, const frame *fr, const double b[3], double Tx,
                           double sb[3])
{
    const mfmm_mesh *m = t->m;
    double x[3];
    mfmm_bary_to_xyz(m, fr->f, b, x);
    double best = INFINITY;
    int32_t bi = -1;
    for (int k = 0; k < 4; k++) {
        const src_key *keys = k < 3 ? t->vkeys : t->fkeys;
        int32_t nk = k < 3 ? t->n_vkeys : t->n_fkeys;
        int32_t key = k < 3 ? fr->v[k] : fr->f;
        for (int32_t i = lower_bound(keys, nk, key); i < nk && keys[i].key == key; i++) {
            const mfmm_source *s = &t->src[keys[i].idx];
            double xs[3], bs[3] = {0.0, 0.0, 0.0};
            if (k < 3)
                bs[k] = 1.0;
            else
                memcpy(bs, s->bary, sizeof bs);
            mfmm_bary_to_xyz(m, fr->f, bs, xs);
            double c = s->value + fr->F * mfmm_dist3(x, xs);
            if (c < best) {
                best = c;
                bi = keys[i].idx;
                memcpy(sb, bs, sizeof bs);
            }
        }
    }
    if (bi >= 0 && !(best <= Tx + 0.5 * fr->F * fr->max_edge))
        bi = -1;
    return bi;
}

/* Barycentric coordinates in face f of the point (1 - s) x_u + s x_w on its
 * edge (u, w). */
static void edge_bary(const mfmm_mesh *m, int32_t f, int32_t u, int32_t w, double s, double b[3])
{
    for (int k = 0; k < 3; k++) {
        int32_t x = m->face_records[f].v[k];
        b[k] = x == u ? 1.0 - s : x == w ? s : 0.0;
    }
}

/* Where a virtual edge crosses the edge of its strip's step st. */
static void virt_crossing(const mfmm_mesh *m, const mfmm_virt_step *st, double x[3])
{
    const double *x1 = m->xyz + 3 * (size_t)st->e1, *x2 = m->xyz + 3 * (size_t)st->e2;
    for (int d = 0; d < 3; d++)
        x[d] = (1.0 - st->t) * x1[d] + st->t * x2[d];
}

/* Length on the surface of virtual edge j, C -> V (section 4.2): its pieces
 * between the edges it crosses, each inside one face of the strip. */
static double virt_length(const mfmm_mesh *m, int32_t j)
{
    double prev[3], x[3], len = 0.0;
    memcpy(prev, m->xyz + 3 * (size_t)m->virts[j].c, sizeof prev);
    mfmm_strip_walk w;
    mfmm_virt_step st;
    int32_t V = -1;
    mfmm_strip_begin(&w, m, j);
    while (mfmm_strip_next(&w, &st)) {
        virt_crossing(m, &st, x);
        len += mfmm_dist3(prev, x);
        memcpy(prev, x, sizeof x);
        V = st.far;
    }
    return len + mfmm_dist3(prev, m->xyz + 3 * (size_t)V);
}

/* The corner at v whose virtual edge descends most steeply (T(V) < T(v)), or
 * -1. A march value T(C) = T(V) + F |CV| can leave C below all its edge
 * neighbours: the way down from there is the virtual edge itself. */
static int32_t virt_descent(const tracer *t, int32_t v)
{
    const mfmm_mesh *m = t->m;
    double Tv = t->T[v], best = 0.0;
    int32_t bc = -1;
    for (int32_t i = m->vertex_face_offset[v]; i < m->vertex_face_offset[v + 1]; i++) {
        int32_t c = MFMM_WEDGE_CORNER(m->vertex_wedge[i]);
        const mfmm_face *fr = m->face_records + c / 3;
        if ((fr->virt & 3) != c % 3)
            continue;
        double TV = t->T[fr->virt >> 2];
        if (!(TV < Tv))
            continue;
        double L = virt_length(m, mfmm_mesh_virt_index(m, c)), slope = L > 0.0 ? (Tv - TV) / L : INFINITY;
        if (bc < 0 || slope > best) {
            best = slope;
            bc = c;
        }
    }
    return bc;
}

/* 1 when no edge or virtual-edge neighbour of v has a smaller T. */
static int local_min(const tracer *t, int32_t v)
{
    const mfmm_mesh *m = t->m;
    double Tv = t->T[v];
    for (int32_t i = m->vertex_face_offset[v]; i < m->vertex_face_offset[v + 1]; i++) {
        int32_t w = m->vertex_wedge[i];
        const int32_t *fv = m->face_records[MFMM_WEDGE_FACE(w)].v;
        if (t->T[fv[MFMM_WEDGE_NEXT(w)]] < Tv || t->T[fv[MFMM_WEDGE_PREV(w)]] < Tv)
            return 0;
    }
    return virt_descent(t, v) < 0;
}

/* Ends the path inside face f from the point at b when f holds the end: a
 * source the distance came from, or (without sources) a local-minimum
 * corner. 1: ended; 0: go on; -1: error. */
static int try_finish(tracer *t, const frame *fr, const double b[3], double Tx)
{
    double eb[3] = {0.0, 0.0, 0.0};
    if (t->n_src > 0) {
        if (face_source(t, fr, b, Tx, eb) < 0)
            return 0;
    } else {
        /* without sources, the path ends only where T reaches 0 at a local
         * minimum (a vertex source); else it is not at a source */
        int best = -1;
        for (int k = 0; k < 3; k++)
            if (fr->T[k] <= Tx && fr->T[k] <= 0.0 && local_min(t, fr->v[k]) &&
                (best < 0 || fr->T[k] < fr->T[best]))
                best = k;
        if (best < 0)
            return 0;
        eb[best] = 1.0;
    }
    if (eb[0] == b[0] && eb[1] == b[1] && eb[2] == b[2])
        return 1; /* already there */
    return mfmm_path_emit(t, fr->f, eb) ? 1 : -1;
}

/* Where a ray from b along plane direction d leaves face fr: the largest
 * step t <= hmax inside, and the edge (opposite corner) it leaves through or
 * -1. t = 0 when it leaves at once through an edge b lies on. */
static double ray_exit(const frame *fr, const double b[3], const double d[2], double hmax,
                       int *edge)
{
    double t = hmax;
    *edge = -1;
    for (int k = 0; k < 3; k++) {
        double rate = fr->gb[k][0] * d[0] + fr->gb[k][1] * d[1];
        if (!(rate < 0.0))
            continue;
        if (b[k] <= ON_EDGE) {
            double gn = sqrt(fr->gb[k][0] * fr->gb[k][0] + fr->gb[k][1] * fr->gb[k][1]);
            if (rate < -OUTWARD_COS * gn) {
                *edge = k;
                return 0.0;
            }
            continue; /* moving along the edge */
        }
        double tk = b[k] / -rate;
        if (tk <= t) {
            t = tk;
            *edge = k;
        }
    }
    return t;
}

static void advance(const frame *fr, double b[3], const double d[2], double s, int edge)
{
    double sum = 0.0;
    for (int k = 0; k < 3; k++) {
        b[k] += s * (fr->gb[k][0] * d[0] + fr->gb[k][1] * d[1]);
        if (b[k] < ON_EDGE || k == edge)
            b[k] = 0.0;
        sum += b[k];
    }
    for (int k = 0; k < 3; k++)
        b[k] /= sum;
}

/* Face g's barycentric coordinates of a point on its edge shared with f. */
static void map_bary(const mfmm_mesh *m, const frame *fr, const double b[3], int32_t g, double bg[3])
{
    for (int j = 0; j < 3; j++) {
        bg[j] = 0.0;
        int32_t x = m->face_records[g].v[j];
        for (int k = 0; k < 3; k++)
            if (fr->v[k] == x)
                bg[j] = b[k];
    }
}

typedef struct pos {
    int32_t f;      /* current face */
    double b[3];    /* barycentric in f */
    int32_t vertex; /* >= 0: the point is this vertex */
    int32_t from;   /* face just crossed from at this position, or -1 */
} pos;

static void set_vertex(pos *p, const mfmm_mesh *m, int32_t f, int32_t v)
{
    p->f = f;
    p->vertex = v;
    p->from = -1;
    for (int k = 0; k < 3; k++)
        p->b[k] = m->face_records[f].v[k] == v ? 1.0 : 0.0;
}

/* At vertex v: steepest descent among the incident faces (a face whose
 * -grad T at v points into its corner) and edges. 1: moved on (p updated,
 * possibly to another vertex); 0: no descent; -1: error. */
static int leave_vertex(tracer *t, pos *p, frame *fr, double *d_out)
{
    const mfmm_mesh *m = t->m;
    int32_t v = p->vertex;
    double Tv = t->T[v], best = 0.0;
    int kind = 0; /* 1 face, 2 edge */
    int32_t bf = -1, bw = -1;
    double bd[2] = {0.0, 0.0};
    for (int32_t i = m->vertex_face_offset[v]; i < m->vertex_face_offset[v + 1]; i++) {
        int32_t c = MFMM_WEDGE_CORNER(m->vertex_wedge[i]), f = c / 3, k = c % 3;
        frame cf;
        if (!mfmm_path_frame_build(t, f, &cf))
            return -1;
        for (int j = 1; j <= 2; j++) {
            int32_t w = cf.v[(k + j) % 3];
            double Tw = cf.T[(k + j) % 3];
            double L = mfmm_dist3(m->xyz + 3 * (size_t)v, m->xyz + 3 * (size_t)w);
            if (kind != 1 && isfinite(Tw) && L > 0.0 && (Tv - Tw) / L > best * (1.0 + 1e-9)) {
                best = (Tv - Tw) / L;
                kind = 2;
                bf = f;
                bw = w;
            }
        }
        if (cf.degenerate)
            continue;
        double g[2];
        if (!mfmm_path_field_grad(&cf, cf.P[k], g))
            continue;
        double gn = sqrt(g[0] * g[0] + g[1] * g[1]);
        double d[2] = {-g[0] / gn, -g[1] / gn};
        /* d = alpha (P1 - Pk) + beta (P2 - Pk) with alpha, beta >= 0: into the corner */
        const double *P0 = cf.P[k], *P1 = cf.P[(k + 1) % 3], *P2 = cf.P[(k + 2) % 3];
        double ax = P1[0] - P0[0], ay = P1[1] - P0[1], cx = P2[0] - P0[0], cy = P2[1] - P0[1];
        double det = ax * cy - ay * cx;
        double alpha = (d[0] * cy - d[1] * cx) / det, beta = (ax * d[1] - ay * d[0]) / det;
        double la = sqrt(ax * ax + ay * ay), lc = sqrt(cx * cx + cy * cy);
        if (alpha * la >= -1e-12 && beta * lc >= -1e-12 && (kind != 1 || gn > best)) {
            best = gn;
            kind = 1;
            bf = f;
            bd[0] = d[0];
            bd[1] = d[1];
        }
    }
    if (kind == 0)
        return 0;
    if (kind == 2) {
        pos q;
        set_vertex(&q, m, bf, bw);
        if (!mfmm_path_emit(t, bf, q.b))
            return -1;
        *p = q;
        return 1;
    }
    set_vertex(p, m, bf, v);
    p->vertex = -1;
    if (!mfmm_path_frame_build(t, bf, fr))
        return -1;
    d_out[0] = bd[0];
    d_out[1] = bd[1];
    return 1;
}

/* Moves along the edge opposite corner k of the current face (a boundary, or
 * a valley both faces descend into) in the direction of d's tangential
 * part, at most hmax. Returns 1, or 0 when d is across the edge (no way on). */
static int slide(tracer *t, pos *p, const frame *fr, int k, const double d[2], double hmax)
{
    int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
    double ex = fr->P[k2][0] - fr->P[k1][0], ey = fr->P[k2][1] - fr->P[k1][1];
    double L = sqrt(ex * ex + ey * ey);
    double s = (d[0] * ex + d[1] * ey) / L;
    /* T along an edge is linear in its ends: down is toward the lower end
     * (d's tangential part, from the quadratic, can point up the edge, and
     * the two faces of a valley then send the path back and forth) */
    int toward;
    if (fr->T[k1] != fr->T[k2])
        toward = fr->T[k1] < fr->T[k2] ? k1 : k2;
    else if (fabs(s) > 1e-6)
        toward = s > 0.0 ? k2 : k1;
    else
        return 0;
    int other = toward == k1 ? k2 : k1;
    double left = p->b[other] * L; /* distance to the corner `toward` */
    if (left <= hmax) {
        int32_t v = fr->v[toward];
        set_vertex(p, t->m, fr->f, v);
        return mfmm_path_emit(t, fr->f, p->b) ? 1 : -1;
    }
    double q = hmax / L;
    p->b[other] -= q;
    p->b[toward] += q;
    p->b[k] = 0.0;
    p->from = -1;
    return 1;
}

/* Follows corner c's virtual edge from its vertex C straight through its
 * strip to V (a point on each edge crossed), and stands at V. 1, or -1. */
static int follow_virt(tracer *t, pos *p, int32_t c)
{
    const mfmm_mesh *m = t->m;
    int32_t f = c / 3, V = -1;
    mfmm_strip_walk w;
    mfmm_virt_step st;
    mfmm_strip_begin(&w, m, mfmm_mesh_virt_index(m, c));
    while (mfmm_strip_next(&w, &st)) {
        double b[3];
        edge_bary(m, f, st.e1, st.e2, st.t, b);
        if (!mfmm_path_emit(t, f, b)) /* the piece to it ran through f */
            return -1;
        f = st.face;
        V = st.far;
    }
    set_vertex(p, m, f, V);
    return mfmm_path_emit(t, f, p->b) ? 1 : -1;
}

/* The best straight way from a point source to one vertex (start/straight.c). */
typedef struct walk_find {
    int32_t target;
    double value, best;
    int32_t depth;
    int32_t a[MFMM_START_DEPTH], b[MFMM_START_DEPTH], face[MFMM_START_DEPTH + 1];
    double t[MFMM_START_DEPTH];
} walk_find;

static int walk_find_hit(void *user, const mfmm_start_hit *h)
{
    walk_find *w = user;
    if (h->vertex != w->target || !(w->value + h->cost_length < w->best))
        return 0;
    w->best = w->value + h->cost_length;
    w->depth = h->depth;
    memcpy(w->face, h->face, (size_t)(h->depth + 1) * sizeof *w->face);
    memcpy(w->a, h->a, (size_t)h->depth * sizeof *w->a);
    memcpy(w->b, h->b, (size_t)h->depth * sizeof *w->b);
    memcpy(w->t, h->t, (size_t)h->depth * sizeof *w->t);
    return 0;
}

/* At vertex v, which T does not descend from: a face source that seeded v
 * by a straight segment (solve.c starts a point source's march so, through
 * the faces near it), when that segment's cost is T(v). Ends the path along
 * it: a point on each edge crossed, then the source. 1: ended; 0: none;
 * -1: error. */
static int finish_straight(tracer *t, int32_t v)
{
    const mfmm_mesh *m = t->m;
    double Tv = t->T[v];
    walk_find best;
    memset(&best, 0, sizeof best); /* (GCC cannot see that depth < 0 skips it) */
    best.best = INFINITY;
    int32_t bs = -1;
    for (int32_t j = 0; j < t->n_fkeys; j++) {
        const mfmm_source *s = &t->src[t->fkeys[j].idx];
        walk_find w;
        w.target = v;
        w.value = s->value;
        w.best = INFINITY;
        w.depth = -1;
        mfmm_start_walk(m, s, t->cost, (int)t->cost_loc, walk_find_hit, &w);
        if (w.depth >= 0 && w.best < best.best) {
            best = w;
            bs = t->fkeys[j].idx;
        }
    }
    if (bs < 0 || !(best.best <= Tv + 1e-9 * (fabs(Tv) + fabs(best.best))))
        return 0;
    for (int32_t i = best.depth - 1; i >= 0; i--) {
        double b[3];
        edge_bary(m, best.face[i + 1], best.a[i], best.b[i], best.t[i], b);
        if (!mfmm_path_emit(t, best.face[i + 1], b)) /* the piece to it ran through face[i + 1] */
            return -1;
    }
    /* the source, named in the start face the segment left */
    const mfmm_source *s = &t->src[bs];
    int32_t f0 = best.face[0];
    double b[3];
    for (int k = 0; k < 3; k++) {
        int32_t x = m->face_records[f0].v[k];
        b[k] = 0.0;
        for (int j = 0; j < 3; j++)
            if (m->face_records[s->face].v[j] == x)
                b[k] = s->bary[j] > 0.0 ? s->bary[j] : 0.0;
    }
    double sum = b[0] + b[1] + b[2];
    if (!(sum > 0.0)) /* at a vertex of f0 that the source face does not share: cannot be */
        return 0;
    for (int k = 0; k < 3; k++)
        b[k] /= sum;
    return mfmm_path_emit(t, f0, b) ? 1 : -1;
}

mfmm_status mfmm_path_trace(tracer *t, const mfmm_source *target)
{
    const mfmm_mesh *m = t->m;
    pos p;
    frame fr;
    int have_frame = 0;
    double T0;
    if (target->face == -1) {
        int32_t v = target->vertex;
        if (m->vertex_face_offset[v] == m->vertex_face_offset[v + 1])
            return mfmm_fail(t->err, MFMM_ERR_UNREACHED, mfmm_vertex_out(m, v),
                             "target vertex %d is in no face", (int)mfmm_vertex_out(m, v));
        if (!mfmm_path_read_T(t, v, &T0))
            return t->st;
        set_vertex(&p, m, MFMM_WEDGE_FACE(m->vertex_wedge[m->vertex_face_offset[v]]), v);
    } else {
        p.f = target->face;
        p.vertex = -1;
        p.from = -1;
        memcpy(p.b, target->bary, sizeof p.b);
        if (!mfmm_path_frame_build(t, p.f, &fr))
            return t->st;
        have_frame = 1;
        T0 = mfmm_path_frame_T(&fr, p.b);
        if (!fr.lin_ok)
            for (int k = 0; k < 3; k++)
                if (p.b[k] > 0.0 && !isfinite(fr.T[k]))
                    T0 = INFINITY;
    }
    if (!(T0 < INFINITY))
        return mfmm_fail(t->err, MFMM_ERR_UNREACHED,
                         target->face == -1 ? mfmm_vertex_out(m, target->vertex)
                                            : mfmm_face_out(m, target->face),
                         "the target's distance is infinite (not reached)");
    if (!mfmm_path_emit(t, p.f, p.b))
        return t->st;

    double best = T0;
    int64_t stall = 0, steps = 0, max_steps = 16 * (int64_t)t->max_points + 64;
    for (;;) {
        if (++steps > max_steps || stall > STALL_STEPS)
            return mfmm_fail(t->err, MFMM_ERR_PATH_STALLED, t->n,
                             "T stopped decreasing at %.17g after %d points", best, (int)t->n);
        double Tcur, d[2] = {0.0, 0.0};
        int have_dir = 0;
        if (p.vertex >= 0) {
            int32_t v = p.vertex;
            Tcur = t->T[v];
            /* the end may lie in any face around the vertex */
            for (int32_t i = m->vertex_face_offset[v]; i < m->vertex_face_offset[v + 1]; i++) {
                int32_t f = MFMM_WEDGE_FACE(m->vertex_wedge[i]);
                frame cf;
                if (!mfmm_path_frame_build(t, f, &cf))
                    return t->st;
                double b[3];
                for (int k = 0; k < 3; k++)
                    b[k] = cf.v[k] == v ? 1.0 : 0.0;
                int r = try_finish(t, &cf, b, Tcur);
                if (r < 0)
                    return t->st;
                if (r > 0)
                    return MFMM_OK;
            }
            int r = leave_vertex(t, &p, &fr, d);
            if (r < 0)
                return t->st;
            if (r == 0) {
                /* no way down over faces and edges: a virtual edge, or a
                 * face source seeded across an edge */
                int32_t c = virt_descent(t, v);
                if (c >= 0)
                    r = follow_virt(t, &p, c);
                else if ((r = finish_straight(t, v)) > 0)
                    return MFMM_OK;
                if (r < 0)
                    return t->st;
            }
            if (r == 0)
                return mfmm_fail(t->err, MFMM_ERR_PATH_STALLED, mfmm_vertex_out(m, v),
                                 t->n_src > 0 ? "T has a local minimum %.17g at vertex %d, not at a source"
                                              : "T has a local minimum %.17g at vertex %d, not 0 "
                                                "(pass the sources to end at a point source or "
                                                "one with a value)",
                                 Tcur, (int)mfmm_vertex_out(m, v));
            if (p.vertex >= 0) { /* went down an edge to another vertex */
                have_frame = 0;
                if (t->T[p.vertex] < best) {
                    best = t->T[p.vertex];
                    stall = 0;
                } else {
                    stall++;
                }
                continue;
            }
            have_frame = 1;
            have_dir = 1;
        } else if (!have_frame || fr.f != p.f) {
            if (!mfmm_path_frame_build(t, p.f, &fr))
                return t->st;
            have_frame = 1;
        }
        Tcur = mfmm_path_frame_T(&fr, p.b);
        if (!have_dir) {
            int r = try_finish(t, &fr, p.b, Tcur);
            if (r < 0)
                return t->st;
            if (r > 0)
                return MFMM_OK;
        }
        if (fr.degenerate || !fr.lin_ok) {
            /* no plane or an unreached corner: go straight to the lowest corner */
            int lo = -1;
            for (int k = 0; k < 3; k++)
                if (isfinite(fr.T[k]) && (lo < 0 || fr.T[k] < fr.T[lo]))
                    lo = k;
            if (lo < 0)
                return mfmm_fail(t->err, MFMM_ERR_PATH_STALLED, p.f,
                                 "face %d has no reached corner", (int)p.f);
            set_vertex(&p, m, fr.f, fr.v[lo]);
            if (!mfmm_path_emit(t, fr.f, p.b))
                return t->st;
            if (fr.T[lo] < best) {
                best = fr.T[lo];
                stall = 0;
            } else {
                stall++;
            }
            continue;
        }

        /* Heun's step (section 5), at most a third of the face's longest edge. */
        double h = fr.max_edge / 3.0, x0[2];
        mfmm_path_bary_to_plane(&fr, p.b, x0);
        if (!have_dir) {
            double g[2];
            if (!mfmm_path_field_grad(&fr, x0, g))
                return mfmm_fail(t->err, MFMM_ERR_PATH_STALLED, p.f,
                                 "grad T vanishes in face %d", (int)p.f);
            double gn = sqrt(g[0] * g[0] + g[1] * g[1]);
            d[0] = -g[0] / gn;
            d[1] = -g[1] / gn;
        }
        int edge;
        double s1 = ray_exit(&fr, p.b, d, h, &edge);
        if (s1 > 0.0) {
            double x1[2] = {x0[0] + s1 * d[0], x0[1] + s1 * d[1]}, g2[2];
            if (mfmm_path_field_grad(&fr, x1, g2)) {
                double gn = sqrt(g2[0] * g2[0] + g2[1] * g2[1]);
                double d2[2] = {-g2[0] / gn, -g2[1] / gn};
                /* a sonic point (gradient jump): keep the first-order step */
                if (d[0] * d2[0] + d[1] * d2[1] >= SONIC_COS) {
                    double a[2] = {d[0] + d2[0], d[1] + d2[1]};
                    double an = sqrt(a[0] * a[0] + a[1] * a[1]);
                    a[0] /= an;
                    a[1] /= an;
                    int e2;
                    double s2 = ray_exit(&fr, p.b, a, h, &e2);
                    if (s2 > 0.0) {
                        d[0] = a[0];
                        d[1] = a[1];
                        s1 = s2;
                        edge = e2;
                    }
                }
            }
            advance(&fr, p.b, d, s1, edge);
            p.from = -1;
        }
        Tcur = mfmm_path_frame_T(&fr, p.b);
        if (Tcur < best - 1e-14 * (1.0 + fabs(best))) {
            best = Tcur;
            stall = 0;
        } else {
            stall++;
        }
        if (edge < 0)
            continue;

        /* on the edge opposite corner `edge`: at a vertex, across, or along it */
        int corner = -1;
        for (int k = 0; k < 3; k++)
            if (k != edge && p.b[k] <= SNAP_BARY)
                corner = 3 - k - edge;
        if (corner >= 0) {
            set_vertex(&p, m, fr.f, fr.v[corner]);
            if (!mfmm_path_emit(t, fr.f, p.b))
                return t->st;
            continue;
        }
        int32_t g = m->face_neighbor[3 * fr.f + edge];
        if (g >= 0 && g != p.from) {
            if (s1 > 0.0 && !mfmm_path_emit(t, fr.f, p.b))
                return t->st;
            double bg[3];
            map_bary(m, &fr, p.b, g, bg);
            p.from = fr.f;
            p.f = g;
            memcpy(p.b, bg, sizeof bg);
            continue;
        }
        /* a boundary, or a valley: both faces descend into this edge */
        if (s1 > 0.0)
            continue; /* came to a boundary edge: decide from there */
        int r = slide(t, &p, &fr, edge, d, h);
        if (r < 0)
            return t->st;
        if (r == 0)
            return mfmm_fail(t->err, MFMM_ERR_PATH_STALLED, p.f,
                             "the path runs into an edge of face %d and stops", (int)p.f);
        if (p.vertex < 0) {
            double Tn = mfmm_path_frame_T(&fr, p.b);
            if (Tn < best) {
                best = Tn;
                stall = 0;
            }
        }
    }
}
