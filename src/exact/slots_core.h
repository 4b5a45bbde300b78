/* The window method (MFMM_METHOD_WINDOWS): window propagation keeping K
 * windows (2 by default) in place on each half-edge, in distance order
 * (docs/windows.md). Written once for the C core (slots.c, slots.h) and the
 * OpenCL kernel (kernels/windows_rows.cl): both include this file, so their
 * rows are the same bits. OpenCL C 1.2 and C99; a solve's arrays are
 * fixed-size (no queue grows) and nothing recurses.
 *
 * - Slots. Half-edge h = 3f+k (the edge opposite corner k of face f, in the
 *   exact tables' frame: corner k+1 at 0, k+2 at L, corner k at (cx, cy),
 *   cy > 0) holds at most K windows entering f through that edge: a
 *   pseudo-source (px, py), py <= 0, unfolded into h's frame, its distance
 *   sigma, the interval [b0, b1] of the edge its rays cross (the exact
 *   solver's fields) and the interval [g0, g1] of the rays traced with it.
 *   No queue entry per window.
 * - Order. A heap of vertices keyed by their current distance (the march's
 *   heap, march/march.h) and a heap of half-edges keyed by the least value
 *   of the windows they hold; the lower top goes first. A vertex that
 *   settles offers a window to the opposite edge of each of its faces
 *   (itself as pseudo-source, sigma = d(v), the whole edge), which also
 *   lowers the edge's ends to d(v) + |edge| (so every reached vertex has a
 *   path). A half-edge that comes off its heap passes its windows across
 *   its face: each lowers the far corner (by its ray where the corner is in
 *   its interval, else over the interval's nearer end and across the face)
 *   and offers its children to the half-edges across the face's other two
 *   edges. Passing half-edges by their windows' least value, not when their
 *   ends settle, crosses a window before an obtuse face's far corner
 *   settles on an edge-relaxed value whose offers would evict it. A window
 *   kept in a half-edge already passed is crossed at once.
 * - Offers where needed. A vertex reached by a window's ray whose
 *   neighbourhood unfolds flat (angle sum 2 pi, or a wall's vertex of pi or
 *   less) offers nothing: the windows beside it carry its paths on. Saddles,
 *   wall vertices and convex vertices offer (on curved meshes the convex
 *   vertices' offers make up for windows lost to the slots). A ray wins a
 *   tie (1e-12) with a vertex's value: a straight wall is reached by a
 *   window's end and by the edge relaxation at once.
 * - Joining. An offer with a slot's pseudo-source and sigma (to SL_SAME)
 *   whose traced rays meet the slot's is joined to it: the pieces of one
 *   window that went round a vertex by both sides. Pieces whose traced
 *   rays do not meet stay apart (they may have passed a hole on both
 *   sides; the rays between would cross it).
 * - Keeping K. An offer is trimmed against the current distances of the
 *   edge's ends as the exact solver trims (ex_trim; ties kept within
 *   EX_TIE). When K + 1 windows compete, the one whose loss raises the
 *   least the lower envelope (the least value at SL_NS points of the edge,
 *   summed) is dropped.
 * - Every value is sigma + a straight segment in a strip unfolded through
 *   the faces the window crossed (possibly ending with a segment from the
 *   interval's end across one face), sigma itself a value, or d(u) + |uv|:
 *   the length of a path on the surface, never below the geodesic distance.
 * - A cost (per face, or per vertex: a face whose corners' costs are
 *   equal has that cost, else it is of mixed cost): a window lies in faces
 *   of one cost c, its values sigma + c |segment| and its trims ex_trim's
 *   inequality divided by c; it stops at an edge into a face of another
 *   cost (as at a wall; the edge's ends are relaxed). A settled vertex
 *   offers windows into faces of one cost, and into a face of mixed cost
 *   does the march's update instead (sl_fmm_corner; Kimmel & Sethian 1998,
 *   section 4.1): refraction where the cost changes is the march's. Values
 *   from those updates are no path lengths and may lie below the weighted
 *   distance, as the march's. Without a cost c is 1.0 (x * 1.0 and x / 1.0
 *   are exact): the same bits as with no cost code at all.
 * - Walls and zero-area faces stop windows (the edge relaxation goes on);
 *   at a non-manifold edge a window goes on into every other face on it
 *   (as the exact solver's ex_fan_out); copies of a face are skipped. */
#ifndef MFMM_EXACT_SLOTS_CORE_H
#define MFMM_EXACT_SLOTS_CORE_H

#include "face_frame.h"
#include "march/march.h"

/* pseudo-sources this close (relative to the edge, its distance and
 * sigma) are the same */
#define SL_SAME 1e-9
/* the run goes on past a stop's level by this much (relative), so that
 * every value written is as final as in a full solve (mfmm_slots_run) */
#define SL_STOP 1e-10
/* the points of an edge (ends included) its windows are weighed at */
#define SL_NS 9

/* A window: rays from pseudo-source (px, py) at distance sigma across
 * [b0, b1] of its edge; [g0, g1] (containing [b0, b1]) the rays traced
 * through the same faces, those the trims cut included: pieces of one
 * window join only where these meet (sl_keep). */
typedef struct sl_win {
    double b0, b1, px, py, sigma, g0, g1;
} sl_win;

#ifdef __OPENCL_VERSION__
typedef long sl_count;
#else
typedef int64_t sl_count;
#endif

/* Counters of a solve (mfmm_slots_info). */
typedef struct sl_counts {
    sl_count crossed, emitted, kept, late, late_vertex, settled, narrow, trimmed, evicted,
        merged;
} sl_counts;

/* A solve: the mesh's exact tables (exact/state.h) and one solve's arrays. */
typedef struct sl_state {
    mfmm_i32 nv, nf;
    MFMM_GLOBAL const ex_face *fr;
    MFMM_GLOBAL const mfmm_i32 *vf_offset, *vf_corner, *face_in;
    MFMM_GLOBAL const mfmm_i32 *nm_he, *nm_next;
    mfmm_i32 n_nm;
    /* (nv) offers redundant after a ray: a vertex whose neighbourhood
     * unfolds flat, or a wall's vertex of pi or less (mfmm_slots_create) */
    MFMM_GLOBAL const mfmm_u8 *flat;
    MFMM_GLOBAL sl_win *slot;   /* (K 3 nf) */
    MFMM_GLOBAL mfmm_u8 *n_slot; /* (3 nf) windows held */
    MFMM_GLOBAL mfmm_u8 *fresh;  /* (3 nf) bit i: slot i kept since the half-edge was passed */
    MFMM_GLOBAL double *d;       /* (nv) */
    MFMM_GLOBAL mfmm_u8 *ray;    /* (nv) d came from a window's straight ray (not an edge,
                                    not a window's end) */
    MFMM_GLOBAL mfmm_u8 *is_src; /* (nv) the vertex sources of the solve */
    MFMM_GLOBAL mfmm_u8 *is_tgt; /* (nv) targets not yet settled */
    /* (nf) each record's cost: the face's, or per vertex the corners' common
     * cost, or -1 where they differ; NULL with no cost (every face 1.0).
     * Costs relative to the least (the run's unit, mfmm_slots_run), so that
     * a constant cost runs at 1.0 */
    MFMM_GLOBAL const double *fcost;
    /* vertices (T unused); label 0 far, 1 close, 2 settled. With a cost per
     * vertex h.cost holds it (internal ids, relative as fcost) and
     * h.cost_location is 1, for the march's cost convention
     * (mfmm_march_cost) in faces of mixed cost */
    mfmm_march_state h;
    mfmm_march_state e; /* half-edges keyed by their windows' least distance */
    int K;              /* windows per half-edge */
    double tgt_level;   /* the largest value of the targets settled (sl_loop) */
    sl_counts info;
} sl_state;

/* fmin and fmax as glibc's (the second operand on ties, a NaN operand
 * ignored), inlined where libm's are calls on the baseline target */
MFMM_INLINE double sl_fmin(double a, double b)
{
    return a < b ? a : b == b ? b : a;
}

MFMM_INLINE double sl_fmax(double a, double b)
{
    return a > b ? a : b == b ? b : a;
}

MFMM_INLINE void sl_update(sl_state *s, mfmm_i32 v, double dist, int ray)
{
    if (!(dist < s->d[v])) {
        /* a ray as long as the value to rounding: the windows beside it
         * carry its paths on (a wall's straight side, relaxed along) */
        if (ray && dist <= s->d[v] + 1e-12 * s->d[v])
            s->ray[v] = 1;
        return;
    }
    /* a value lower only by rounding keeps the ray it had */
    s->ray[v] = (mfmm_u8)(ray | (s->ray[v] & (dist >= s->d[v] - 1e-12 * s->d[v])));
    s->d[v] = dist;
    mfmm_u8 lab = s->h.label[v];
    if (lab == 2) {
        s->info.late_vertex++;
        return;
    }
    mfmm_heap_push_or_decrease(&s->h, v, dist, lab == 1);
    s->h.label[v] = 1;
}

/* the cost of face record f: 1.0 with no cost (x * 1.0 and x / 1.0 are
 * exact, so the no-cost path keeps its bits), -1 where it is not uniform */
MFMM_INLINE double sl_cost(const sl_state *s, mfmm_i32 f)
{
    return s->fcost ? s->fcost[f] : 1.0;
}

/* Vertex v settled at dv updates corner jc of face record r (a face of mixed
 * cost, per vertex) as the march does when a vertex settles (march.h,
 * mfmm_march_corner without virtual edges): the edge from v at the march's
 * edge cost and, when the face's third vertex has settled, Kimmel &
 * Sethian's triangle update through the face's inside (1998, section 4.1)
 * with the march's cost across the face (mfmm_march_cost); the edge from
 * the third vertex was offered when it settled, at its edge cost. */
MFMM_INLINE void sl_fmm_corner(sl_state *s, MFMM_GLOBAL const ex_face *r, int jc, mfmm_i32 v,
                               double dv)
{
    mfmm_i32 c = r->v[jc];
    if (s->h.label[c] == 2)
        return; /* settled: the march updates only vertices not yet settled */
    int ja = ex_next[jc], jb = ex_prev[jc];
    mfmm_i32 ia = r->v[ja], ib = r->v[jb];
    double f_a, f_b, f_t;
    (void)mfmm_march_cost(&s->h, 0, c, ia, ib, &f_a, &f_b, &f_t);
    /* a = |BC| (len[ja]), b = |AC| (len[jb]); cos at C from the side lengths,
     * with + - * / only, so that C and OpenCL C round alike */
    double a = r->len[ja], b = r->len[jb], l = r->len[jc];
    double t = v == ia ? dv + b * f_b : dv + a * f_a;
    mfmm_i32 y = v == ia ? ib : ia;
    if (s->h.label[y] == 2) {
        double cs = (a * a + b * b - l * l) / (2.0 * a * b);
        double ta = v == ia ? dv : s->d[ia], tb = v == ia ? s->d[ib] : dv;
        t = mfmm_min(t, mfmm_triangle_interior(ta, tb, a, b, cs, f_t));
    }
    sl_update(s, c, t, 0);
}

/* the cost of the edge of face record f from u to w: the face's, or in a
 * face of mixed cost (per vertex) the mean of the ends' costs, as the
 * march's edge update (mfmm_march_cost) */
MFMM_INLINE double sl_edge_cost(const sl_state *s, mfmm_i32 f, mfmm_i32 u, mfmm_i32 w)
{
    double c = sl_cost(s, f);
    return c > 0.0 ? c : 0.5 * (s->h.cost[u] + s->h.cost[w]);
}

/* Whether the faces around v all have one cost (always without a cost): a
 * flat vertex's offers are redundant only then, since windows stop where
 * the cost changes. */
MFMM_INLINE int sl_one_cost(const sl_state *s, mfmm_i32 v)
{
    if (!s->fcost)
        return 1;
    mfmm_i32 i0 = s->vf_offset[v], i1 = s->vf_offset[v + 1];
    if (i0 == i1)
        return 1;
    double c = sl_cost(s, ex_corner(s->vf_corner, s->face_in, i0) / 3);
    for (mfmm_i32 i = i0 + 1; i < i1; i++)
        if (sl_cost(s, ex_corner(s->vf_corner, s->face_in, i) / 3) != c)
            return 0;
    return c > 0.0;
}

/* the distances a window gives at the SL_NS points x (ascending) of its
 * edge: over the nearer end of its interval, then along the edge, outside
 * it (each end's segment computed once for all the points beyond it) */
MFMM_INLINE void sl_vals(const double *x, double b0, double b1, double px, double py,
                           double sigma, double cost, double *v)
{
    int j = 0;
    if (x[0] < b0) {
        double e = sigma + cost * sqrt((b0 - px) * (b0 - px) + py * py);
        for (; j < SL_NS && x[j] < b0; j++)
            v[j] = e + cost * fabs(x[j] - b0);
    }
    for (; j < SL_NS && !(x[j] > b1); j++)
        v[j] = sigma + cost * sqrt((x[j] - px) * (x[j] - px) + py * py);
    if (j < SL_NS) {
        double e = sigma + cost * sqrt((b1 - px) * (b1 - px) + py * py);
        for (; j < SL_NS; j++)
            v[j] = e + cost * fabs(x[j] - b1);
    }
}

/* the lower of two values, NaN ignored (the envelope's loop) */
MFMM_INLINE double sl_lo(double a, double b)
{
    double lo = MFMM_INF;
    if (a < lo)
        lo = a;
    if (b < lo)
        lo = b;
    return lo;
}

/* half-edge g holds a window (a new one, or one kept since g was passed)
 * whose least value is sigma + cost times the distance from (px, py) to
 * [b0, b1] (cost: the face g enters, where the window lies): g
 * is passed (again) by then. Labels: 0 not queued, 1 queued, 2 passed,
 * 3 passed and queued again for the windows kept since (fresh). */
MFMM_INLINE void sl_key(sl_state *s, mfmm_i32 g, double b0, double b1, double px, double py,
                        double sigma, double cost)
{
    double c = px < b0 ? b0 : px > b1 ? b1 : px;
    double m = sigma + cost * sqrt((c - px) * (c - px) + py * py);
    mfmm_u8 lab = s->e.label[g];
    int queued = lab == 1 || lab == 3;
    if (queued && !(m < s->e.heap_key[s->e.heap_pos[g]]))
        return;
    mfmm_heap_push_or_decrease(&s->e, g, m, queued);
    s->e.label[g] = (mfmm_u8)(lab == 0 ? 1 : lab == 2 ? 3 : lab);
}

/* Window [s0, s1] from pseudo-source (ix, iy) (the frame of the half-edge
 * it leaves through, iy >= 0 on the face's side) into the slots of half-edge
 * g across the edge, whose frame runs the other way when fl is set; cost:
 * the faces it lies in (g's face's, as the face it leaves). */
MFMM_INLINE void sl_keep(sl_state *s, mfmm_i32 g, int fl, double L, double s0, double s1, double t0,
                    double t1, double ix, double iy, double sigma, double cost)
{
    double b0 = fl ? L - s1 : s0, b1 = fl ? L - s0 : s1, px = fl ? L - ix : ix, py = -iy;
    double g0 = fl ? L - t1 : t0, g1 = fl ? L - t0 : t1;
    MFMM_GLOBAL sl_win *w = s->slot + (size_t)s->K * g;
    int n = s->n_slot[g], at;
    /* the same pseudo-source (to rounding) as a slot's, with traced rays
     * that meet the slot's: the pieces of one window that went round a
     * vertex by its two sides, one window together (the rays between them,
     * cut by trims, are paths too). Pieces whose traced rays do not meet
     * stay apart: they may have come round a hole, whose rays are no paths. */
    double tol = SL_SAME * (L + fabs(px) - py + (cost != 1.0 ? sigma / cost : sigma));
    for (int i = 0; i < n; i++) {
        if (fabs(w[i].px - px) > tol || fabs(w[i].py - py) > tol ||
            fabs(w[i].sigma - sigma) > tol || g0 > w[i].g1 + tol || g1 < w[i].g0 - tol)
            continue;
        w[i].g0 = sl_fmin(g0, w[i].g0);
        w[i].g1 = sl_fmax(g1, w[i].g1);
        if (b0 >= w[i].b0 - tol && b1 <= w[i].b1 + tol)
            return; /* nothing new */
        double u0 = sl_fmin(b0, w[i].b0), u1 = sl_fmax(b1, w[i].b1);
        w[i].b0 = u0;
        w[i].b1 = u1;
        s->info.merged++;
        sl_key(s, g, b0, b1, px, py, sigma, cost);
        if (s->e.label[g] == 3) {
            /* g was passed: the joined window crosses again (what it
             * crossed before gives the same values) */
            s->info.late++;
            s->fresh[g] = (mfmm_u8)(s->fresh[g] | 1 << i);
        }
        return;
    }
    if (n < s->K) {
        at = n;
        s->n_slot[g] = (mfmm_u8)(n + 1);
    } else {
        /* the envelope: of the K + 1 windows (the new one
         * included) drop the one whose loss raises the least least, the
         * sum over SL_NS points of the edge of the lowest value there */
        double x[SL_NS], val[9][SL_NS];
        for (int j = 0; j < SL_NS; j++)
            x[j] = L * j / (SL_NS - 1);
        for (int i = 0; i < n; i++)
            sl_vals(x, w[i].b0, w[i].b1, w[i].px, w[i].py, w[i].sigma, cost, val[i]);
        sl_vals(x, b0, b1, px, py, sigma, cost, val[n]);
        double best = MFMM_INF;
        at = n;
        if (n == 2) {
            /* the three sums at once, each in the order of the loop below */
            double sum2 = 0.0, sum1 = 0.0, sum0 = 0.0;
            for (int j = 0; j < SL_NS; j++) {
                sum2 += sl_lo(val[0][j], val[1][j]);
                sum1 += sl_lo(val[0][j], val[2][j]);
                sum0 += sl_lo(val[1][j], val[2][j]);
            }
            if (sum2 < best) {
                best = sum2;
                at = 2;
            }
            if (sum1 < best) {
                best = sum1;
                at = 1;
            }
            if (sum0 < best)
                at = 0;
        } else {
            for (int q = n; q >= 0; q--) {
                double sum = 0.0;
                for (int j = 0; j < SL_NS; j++) {
                    double lo = MFMM_INF;
                    for (int i = 0; i <= n; i++)
                        if (i != q && val[i][j] < lo)
                            lo = val[i][j];
                    sum += lo;
                }
                if (sum < best) {
                    best = sum;
                    at = q;
                }
            }
        }
        s->info.evicted++;
        if (at == n)
            return;
    }
    sl_win nw = {b0, b1, px, py, sigma, g0, g1};
    w[at] = nw;
    s->info.kept++;
    sl_key(s, g, b0, b1, px, py, sigma, cost);
    if (s->e.label[g] == 3) {
        /* kept after g was passed: g is queued again, to cross it (no
         * recursion, which OpenCL C has not) */
        s->info.late++;
        s->fresh[g] = (mfmm_u8)(s->fresh[g] | 1 << at);
    }
}

/* A window leaving face h / 3 through half-edge h: rays across [s0, s1]
 * of the edge, traced across [t0, t1] (sl_win), from (ix, iy) in h's frame
 * (iy >= 0, on the face's side); offer: 0 a window's child, 1 a vertex's
 * offer, 2 a vertex source's. Lowers the edge's ends it reaches, then goes
 * into the slots of the half-edge(s) across. With a cost the face h / 3 has
 * one cost c (the caller checks): values are sigma + c |segment|, trims
 * compare sigma / c with the ends' distances / c, and a window stops at an
 * edge into a face of another cost (refraction is the march's: its ends are
 * relaxed, and their vertices update the faces beyond). */
MFMM_INLINE void sl_emit(sl_state *s, mfmm_i32 h, double s0, double s1, double t0, double t1,
                    double ix, double iy, double sigma, int offer)
{
    MFMM_GLOBAL const ex_face *r = s->fr + h / 3;
    int k = h % 3;
    mfmm_i32 va = r->v[ex_next[k]], vb = r->v[ex_prev[k]];
    double L = r->len[k], cost = sl_cost(s, h / 3);
    if (s0 < 0.0)
        s0 = 0.0;
    if (s1 > L)
        s1 = L;
    t0 = sl_fmax(0.0, sl_fmin(t0, s0));
    t1 = sl_fmin(L, sl_fmax(t1, s1));
    if (!(s1 - s0 > EX_MIN_WIDTH * L)) {
        s->info.narrow++;
        return;
    }
    double iy2 = iy * iy;
    if (offer) {
        /* a vertex's offer: its ends at the face's edge lengths */
        sl_update(s, va, sigma + cost * r->len[ex_prev[k]], offer == 2);
        sl_update(s, vb, sigma + cost * r->len[ex_next[k]], offer == 2);
    } else {
        if (s0 <= EX_POS_TOL * L)
            sl_update(s, va, sigma + cost * sqrt(ix * ix + iy2), 1);
        if (s1 >= L - EX_POS_TOL * L)
            sl_update(s, vb, sigma + cost * sqrt((ix - L) * (ix - L) + iy2), 1);
    }
    mfmm_i32 g = r->across[k];
    if (g < 0 && r->flip[k] != 2)
        return; /* a wall, or a zero-area face (its edges relax; windows stop) */
    if (g >= 0 && sl_cost(s, g / 3) != cost)
        return; /* another cost across: the march's refraction, not a window */
    s->info.emitted++;
    double da = s->d[va], db = s->d[vb], sigma_l = sigma;
    da += EX_TIE * da;
    db += EX_TIE * db;
    if (cost != 1.0) {
        /* the trim's inequality divided by the cost: in lengths of this
         * face (skipped at 1.0, where it is exact: three divisions less) */
        sigma_l = sigma / cost;
        da /= cost;
        db /= cost;
    }
    if (!ex_trim(ix, -iy, sigma_l, L, da, db, &s0, &s1)) {
        s->info.trimmed++;
        return;
    }
    if (g >= 0) {
        sl_keep(s, g, r->flip[k], L, s0, s1, t0, t1, ix, iy, sigma, cost);
        return;
    }
    /* a non-manifold edge: on into every other face on it, each unfolded
     * across the edge (as the exact solver's ex_fan_out); a pseudo-source
     * on an end of the edge sends its rays along it, into no face */
    double tol = EX_POS_TOL * L;
    if (iy <= tol && (fabs(ix) <= tol || fabs(ix - L) <= tol))
        return;
    mfmm_i32 i = ex_nm_find(s->nm_he, s->n_nm, h);
    for (mfmm_i32 n = 0; i >= 0 && n < s->n_nm; n++) {
        mfmm_i32 q = s->nm_next[i];
        if (q == h)
            return;
        i = ex_nm_find(s->nm_he, s->n_nm, q);
        MFMM_GLOBAL const ex_face *rq = s->fr + q / 3;
        if (!rq->skip && sl_cost(s, q / 3) == cost)
            sl_keep(s, q, rq->v[ex_next[q % 3]] != va, L, s0, s1, t0, t1, ix, iy, sigma,
                    cost);
    }
}

/* A window entering face h / 3 through h crosses it (ex_propagate). */
MFMM_INLINE void sl_cross(sl_state *s, mfmm_i32 h, const sl_win *w)
{
    mfmm_i32 f = h / 3;
    int m = h % 3;
    MFMM_GLOBAL const ex_face *r = s->fr + f;
    mfmm_i32 vc = r->v[m];
    double L = r->len[m], cx = r->cx[m], cy = r->cy[m];
    double b0 = w->b0, b1 = w->b1, px = w->px, py = w->py, sigma = w->sigma;
    double g0 = w->g0, g1 = w->g1, cost = sl_cost(s, f);
    s->info.crossed++;
    double tc = px + (cx - px) * (-py) / (cy - py);
    double tol = EX_POS_TOL * L;
    if (tc >= b0 - tol && tc <= b1 + tol) {
        double ex = cx - px, ey = cy - py;
        sl_update(s, vc, sigma + cost * sqrt(ex * ex + ey * ey), 1);
    } else {
        /* C beside the window: the ray to the interval's nearer end, then
         * straight across the face (a path, wherever C is): a vertex at
         * the tip of thin faces otherwise gets only the edge relaxation, an
         * edge's length off */
        double e = tc < b0 ? b0 : b1;
        double ie = sqrt((e - px) * (e - px) + py * py), ec = sqrt((cx - e) * (cx - e) + cy * cy);
        sl_update(s, vc, sigma + cost * ie + cost * ec, 0);
    }
    int m1 = ex_next[m], m2 = ex_prev[m];
    if (b0 < tc) {
        mfmm_i32 hl = 3 * f + m2;
        ex_child c = ex_child_left(r, m);
        double s_hi = b0 <= 0.0 ? c.len : ex_child_hit(&c, px, py, b0);
        double s_lo = tc <= b1 ? 0.0 : ex_child_hit(&c, px, py, b1);
        double t_hi = g0 <= 0.0 ? c.len : ex_child_hit(&c, px, py, g0);
        double t_lo = tc <= g1 ? 0.0 : ex_child_hit(&c, px, py, g1);
        double ix, iy;
        ex_child_source(&c, px, py, &ix, &iy);
        sl_emit(s, hl, s_lo, s_hi, t_lo, t_hi, ix, iy, sigma, 0);
    }
    if (b1 > tc) {
        mfmm_i32 hr = 3 * f + m1;
        ex_child c = ex_child_right(r, m);
        double s_lo = b1 >= L ? 0.0 : ex_child_hit(&c, px, py, b1);
        double s_hi = tc >= b0 ? c.len : ex_child_hit(&c, px, py, b0);
        double t_lo = g1 >= L ? 0.0 : ex_child_hit(&c, px, py, g1);
        double t_hi = tc >= g0 ? c.len : ex_child_hit(&c, px, py, g0);
        double ix, iy;
        ex_child_source(&c, px, py, &ix, &iy);
        sl_emit(s, hr, s_lo, s_hi, t_lo, t_hi, ix, iy, sigma, 0);
    }
}

/* Half-edge h comes off its heap: its windows cross its face, all of them
 * the first time, those kept since (fresh) when it comes again. */
MFMM_INLINE void sl_pass(sl_state *s, mfmm_i32 h)
{
    int n = s->n_slot[h];
    int mask = s->e.label[h] == 3 ? s->fresh[h] : 0xff;
    s->e.label[h] = 2;
    s->fresh[h] = 0;
#if defined(__GNUC__) && !defined(__OPENCL_VERSION__)
    {
        /* what the children will read: the slots of the half-edges across
         * the face's other two edges, and the far corner's distance */
        MFMM_GLOBAL const ex_face *r = s->fr + h / 3;
        int m = h % 3;
        for (int c = 1; c <= 2; c++) {
            mfmm_i32 g = r->across[(m + c) % 3];
            if (g >= 0) {
                const char *p = (const char *)(s->slot + (size_t)s->K * g);
                __builtin_prefetch(p);
                __builtin_prefetch(p + 64);
                __builtin_prefetch(s->n_slot + g);
                __builtin_prefetch(s->e.label + g);
            }
        }
        __builtin_prefetch(s->d + r->v[m]);
    }
#endif
    /* (a window kept while another is crossed cannot land in the same slot:
     * the children go to the face's other edges) */
    for (int i = 0; i < n; i++) {
        if (!(mask >> i & 1))
            continue;
        sl_win w = s->slot[(size_t)s->K * h + i];
        sl_cross(s, h, &w);
    }
}

/* Every vertex unreached, every half-edge empty, no source or target. */
MFMM_INLINE void sl_reset(sl_state *s)
{
    sl_counts zero = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    s->info = zero;
    for (mfmm_i32 v = 0; v < s->nv; v++) {
        s->d[v] = MFMM_INF;
        s->h.label[v] = 0;
        s->ray[v] = 0;
        s->is_src[v] = 0;
        s->is_tgt[v] = 0;
    }
    for (mfmm_i32 g = 0; g < 3 * s->nf; g++) {
        s->n_slot[g] = 0;
        s->e.label[g] = 0;
    }
    s->h.heap_size = 0;
    s->e.heap_size = 0;
    s->tgt_level = -MFMM_INF;
}

/* The propagation from the sources seeded (is_src marks the vertex
 * sources) until both heaps are empty or their least key passes `level`;
 * n_tgt targets (is_tgt) left: once the last settles, the level comes down
 * to the largest target value (SL_STOP above). */
MFMM_INLINE void sl_loop(sl_state *s, double level, mfmm_i32 n_tgt)
{
    MFMM_GLOBAL const ex_face *fr = s->fr;
    double stop = level * (1.0 + SL_STOP);
    while (s->h.heap_size > 0 || s->e.heap_size > 0) {
        double top = s->h.heap_size > 0 ? s->h.heap_key[0] : MFMM_INF;
        if (s->e.heap_size > 0 && s->e.heap_key[0] < top)
            top = s->e.heap_key[0];
        if (top > stop)
            break;
        if (s->e.heap_size > 0 &&
            (s->h.heap_size == 0 || s->e.heap_key[0] <= s->h.heap_key[0])) {
            /* the half-edge whose windows come next */
            sl_pass(s, mfmm_heap_pop(&s->e));
            continue;
        }
        mfmm_i32 v = mfmm_heap_pop(&s->h);
        s->h.label[v] = 2;
#if defined(__GNUC__) && !defined(__OPENCL_VERSION__)
        if (s->h.heap_size > 0) {
            /* the face records of the vertex likely to settle next: they
             * are the solve's misses (a record is first read when a corner
             * settles) */
            mfmm_i32 nx = s->h.heap_vertex[0];
            for (mfmm_i32 i = s->vf_offset[nx]; i < s->vf_offset[nx + 1]; i++) {
                const char *p = (const char *)(fr + ex_corner(s->vf_corner, s->face_in, i) / 3);
                __builtin_prefetch(p);
                __builtin_prefetch(p + 64);
            }
        }
#endif
        s->info.settled++;
        double dv = s->d[v];
        /* flat: the windows beside v carry its paths on (one cost around) */
        int quiet = s->ray[v] && s->flat[v] && sl_one_cost(s, v);
        if (s->is_tgt[v]) {
            s->is_tgt[v] = 0;
            if (dv > s->tgt_level)
                s->tgt_level = dv;
            if (--n_tgt == 0 && s->tgt_level < level)
                stop = s->tgt_level * (1.0 + SL_STOP);
        }
        mfmm_i32 i0 = s->vf_offset[v], i1 = s->vf_offset[v + 1];
        for (mfmm_i32 i = i0; i < i1; i++) {
            mfmm_i32 c = ex_corner(s->vf_corner, s->face_in, i);
            MFMM_GLOBAL const ex_face *r = fr + c / 3;
            int k = c % 3;
            mfmm_i32 vn = r->v[ex_next[k]], vp = r->v[ex_prev[k]];
            if (r->skip) {
                if (r->skip == 1) { /* zero-area: the edges only */
                    sl_update(s, vn, dv + sl_edge_cost(s, c / 3, v, vn) * r->len[ex_prev[k]], 0);
                    sl_update(s, vp, dv + sl_edge_cost(s, c / 3, v, vp) * r->len[ex_next[k]], 0);
                }
                continue;
            }
            double cf = sl_cost(s, c / 3);
            if (!(cf > 0.0)) {
                /* a face of mixed cost (per vertex): no window can lie in
                 * it; the march's update of its other corners instead */
                sl_fmm_corner(s, r, ex_next[k], v, dv);
                sl_fmm_corner(s, r, ex_prev[k], v, dv);
                continue;
            }
            if (quiet) {
                /* not needed: a vertex reached by a window's ray whose
                 * neighbourhood unfolds flat has the windows beside it
                 * carry its paths on; the edges only */
                sl_update(s, vn, dv + cf * r->len[ex_prev[k]], 0);
                sl_update(s, vp, dv + cf * r->len[ex_next[k]], 0);
                if (!s->is_src[v])
                    continue;
            }
            sl_emit(s, c, 0.0, r->len[k], 0.0, r->len[k], r->cx[k], r->cy[k], dv,
                    s->is_src[v] ? 2 : 1);
        }
    }
}


/* Flags the n targets (internal ids, repeats allowed) for sl_loop's stop;
 * returns how many distinct ones. */
MFMM_INLINE mfmm_i32 sl_targets(sl_state *s, MFMM_GLOBAL const mfmm_i32 *targets, mfmm_i32 n)
{
    mfmm_i32 n_tgt = 0;
    for (mfmm_i32 i = 0; i < n; i++)
        if (!s->is_tgt[targets[i]]) {
            s->is_tgt[targets[i]] = 1;
            n_tgt++;
        }
    return n_tgt;
}

/* The value a solve stopped at `level` writes for vertex v: its distance
 * once settled within the level, else +inf. */
MFMM_INLINE double sl_value(const sl_state *s, mfmm_i32 v, double level)
{
    return s->h.label[v] == 2 && s->d[v] <= level ? s->d[v] : MFMM_INF;
}

/* ---- one block per solve (the OpenCL kernel's per-item workspace) ---- */

/* n bytes rounded up to a multiple of 8, so that every array is aligned */
#define SL_ALIGN8(n) (((n) + 7) / 8 * 8)

/* The bytes of one solve's arrays (sl_attach) on nv vertices and nf faces,
 * K windows per half-edge. */
MFMM_INLINE size_t sl_block_bytes(mfmm_i32 nv, mfmm_i32 nf, int K)
{
    size_t v = (size_t)nv, h = 3 * (size_t)nf;
    return (size_t)K * h * sizeof(sl_win) + 8 * h + 16 * v + 2 * SL_ALIGN8(4 * h) +
           2 * SL_ALIGN8(4 * v) + 3 * SL_ALIGN8(h) + 4 * SL_ALIGN8(v);
}

/* Points s's per-solve arrays (s->nv, s->nf and s->K set) into the block at
 * base (sl_block_bytes of them, 8-aligned). */
MFMM_INLINE void sl_attach(sl_state *s, MFMM_GLOBAL char *base)
{
    size_t v = (size_t)s->nv, h = 3 * (size_t)s->nf;
    s->slot = (MFMM_GLOBAL sl_win *)base;
    base += (size_t)s->K * h * sizeof(sl_win);
    s->e.heap_key = (MFMM_GLOBAL double *)base;
    base += 8 * h;
    s->h.heap_key = (MFMM_GLOBAL double *)base;
    s->d = (MFMM_GLOBAL double *)(base + 8 * v);
    base += 16 * v;
    s->e.heap_vertex = (MFMM_GLOBAL mfmm_i32 *)base;
    base += SL_ALIGN8(4 * h);
    s->e.heap_pos = (MFMM_GLOBAL mfmm_i32 *)base;
    base += SL_ALIGN8(4 * h);
    s->h.heap_vertex = (MFMM_GLOBAL mfmm_i32 *)base;
    base += SL_ALIGN8(4 * v);
    s->h.heap_pos = (MFMM_GLOBAL mfmm_i32 *)base;
    base += SL_ALIGN8(4 * v);
    s->n_slot = (MFMM_GLOBAL mfmm_u8 *)base;
    base += SL_ALIGN8(h);
    s->fresh = (MFMM_GLOBAL mfmm_u8 *)base;
    base += SL_ALIGN8(h);
    s->e.label = (MFMM_GLOBAL mfmm_u8 *)base;
    base += SL_ALIGN8(h);
    s->ray = (MFMM_GLOBAL mfmm_u8 *)base;
    base += SL_ALIGN8(v);
    s->is_src = (MFMM_GLOBAL mfmm_u8 *)base;
    base += SL_ALIGN8(v);
    s->is_tgt = (MFMM_GLOBAL mfmm_u8 *)base;
    base += SL_ALIGN8(v);
    s->h.label = (MFMM_GLOBAL mfmm_u8 *)base;
}

/* A solve from the vertex source `source` (value 0), stopped at `level`
 * (+inf: none) or once the n_targets targets settle: what mfmm_slots_run
 * does for one vertex source, so that the kernel's rows are its rows. */
MFMM_INLINE void sl_solve_vertex(sl_state *s, mfmm_i32 source, double level,
                                 MFMM_GLOBAL const mfmm_i32 *targets, mfmm_i32 n_targets)
{
    sl_reset(s);
    mfmm_i32 n_tgt = sl_targets(s, targets, n_targets);
    sl_update(s, source, 0.0, 0);
    s->is_src[source] = 1;
    sl_loop(s, level, n_tgt);
}

#endif
