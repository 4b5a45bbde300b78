/*
 * The heap Fast Marching loop of section 2, over the arrays a mesh
 * precomputes. Shared by the C core (src/solve/solve.c) and the OpenCL
 * kernel (kernels/fmm_rows.cl), like local_update.h: one march, one result.
 *
 * Workspace per march (all of nv entries): T (double), label (u8), heap keys
 * (double), heap vertices (i32), heap positions (i32).
 */
#ifndef MFMM_MARCH_H
#define MFMM_MARCH_H

#include "local_update.h"

/* The arrays of a mesh that a march reads. */
typedef struct mfmm_march_mesh {
    mfmm_i32 nv;
    /* x's faces (x = face f's vertex k), as MFMM_WEDGE(f, k), at
     * wedge[wedge_offset[x]] .. wedge[wedge_offset[x + 1] - 1] */
    MFMM_GLOBAL const mfmm_i32 *wedge_offset;
    MFMM_GLOBAL const mfmm_i32 *wedge;
    MFMM_GLOBAL const mfmm_face *faces; /* (nf,) */
    /* the virtual edges, sorted by V: those ending at x are
     * virts[virt_first[x]] .. virts[virt_first[x + 1] - 1] */
    MFMM_GLOBAL const mfmm_virt *virts;
    MFMM_GLOBAL const mfmm_i32 *virt_first;
    /* the vertices each virtual edge's strip unfolds before V (A and B
     * aside): strip[strip_offset[j]] .. strip[strip_offset[j + 1] - 1] for
     * virts[j] */
    MFMM_GLOBAL const mfmm_i32 *strip_offset;
    MFMM_GLOBAL const mfmm_i32 *strip;
    /* x's spokes (F = 1 with unfolding), spokes[spoke_offset[x]] ..
     * spokes[spoke_offset[x + 1] - 1]; NULL: the face walk (spokes.c) */
    MFMM_GLOBAL const mfmm_i32 *spoke_offset;
    MFMM_GLOBAL const mfmm_spoke *spokes;
} mfmm_march_mesh;

/* A march's workspace, and the options it runs with. */
typedef struct mfmm_march_state {
    MFMM_GLOBAL double *T;
    MFMM_GLOBAL mfmm_u8 *label;
    MFMM_GLOBAL double *heap_key;
    MFMM_GLOBAL mfmm_i32 *heap_vertex;
    MFMM_GLOBAL mfmm_i32 *heap_pos; /* position of a Close vertex in the heap */
    mfmm_i32 heap_size;
    MFMM_GLOBAL const double *cost; /* NULL: F = 1 */
    int cost_location;              /* 0 none, 1 per vertex, 2 per face */
    double max_distance;
    int unfolding;
    mfmm_i32 targets_left;          /* early stop when it reaches 0 (if > 0 at start) */
    /* with a cost and unfolding: per vertex, the cost all around it, or -1
     * (mfmm_uniform_cost); read by mfmm_march_virt_ok */
    MFMM_GLOBAL const double *uniform;
    /* Optional touched list: NULL, or room for nv ids that receives every
     * vertex the march takes off Far, in that order (n_touched of them).
     * With a list the march only needs T = +inf and labels Far at the
     * vertices it touches (the caller resets those afterwards), so a row
     * costs in proportion to what it reaches, not to nv; without one (the
     * OpenCL kernel's per-item workspace) the final pass covers all nv. */
    MFMM_GLOBAL mfmm_i32 *touched;
    mfmm_i32 n_touched;
    /* vertices settled while seeding (mfmm_march_seed_patch), counted in the
     * march's total */
    mfmm_i32 n_preset;
} mfmm_march_state;

/* ---- indexed d-ary min-heap with decrease-key: a node's 8 children are
 * 8 keys in a row, and the tree is a third as deep as a binary one. Equal
 * keys settle in the order the heap's steps leave them (the sift-down takes
 * the first least child, the sift-up stops below an equal parent): set by
 * the sequence of pushes, which every backend runs alike. ---- */

#ifndef MFMM_HEAP_ARITY
/* 8 was the fastest arity, and bucket, radix and lazy heaps were slower
 * (docs/march-measurements.md); the arity also fixes the order in which
 * equal keys settle, so it cannot change without changing rows. */
#define MFMM_HEAP_ARITY 8
#endif

MFMM_INLINE void mfmm_heap_place(mfmm_march_state *s, mfmm_i32 i, double key, mfmm_i32 v)
{
    s->heap_key[i] = key;
    s->heap_vertex[i] = v;
    s->heap_pos[v] = i;
}

MFMM_INLINE void mfmm_heap_sift_up(mfmm_march_state *s, mfmm_i32 i, double key, mfmm_i32 v)
{
    while (i > 0) {
        mfmm_i32 parent = (i - 1) / MFMM_HEAP_ARITY;
        double pk = s->heap_key[parent];
        if (!(key < pk))
            break;
        mfmm_heap_place(s, i, pk, s->heap_vertex[parent]);
        i = parent;
    }
    mfmm_heap_place(s, i, key, v);
}

/* Inserts v with key, or lowers its key if it is already in the heap. */
MFMM_INLINE void mfmm_heap_push_or_decrease(mfmm_march_state *s, mfmm_i32 v, double key,
                                            int in_heap)
{
    mfmm_i32 i = in_heap ? s->heap_pos[v] : s->heap_size++;
    mfmm_heap_sift_up(s, i, key, v);
}

/* Removes the minimum; returns its vertex. heap_size must be > 0. */
MFMM_INLINE mfmm_i32 mfmm_heap_pop(mfmm_march_state *s)
{
    mfmm_i32 top = s->heap_vertex[0];
    mfmm_i32 n = --s->heap_size;
    if (n > 0) {
        double key = s->heap_key[n];
        mfmm_i32 v = s->heap_vertex[n];
        mfmm_i32 i = 0;
        for (;;) {
            mfmm_i32 first = MFMM_HEAP_ARITY * i + 1;
            if (first >= n)
                break;
            mfmm_i32 child = first;
            double ck = s->heap_key[first];
            /* (a loop with a branch: faster than unrolled or branch-free
             * scans, docs/march-measurements.md) */
            mfmm_i32 last = first + MFMM_HEAP_ARITY < n ? first + MFMM_HEAP_ARITY : n;
            for (mfmm_i32 c = first + 1; c < last; c++)
                if (s->heap_key[c] < ck) {
                    child = c;
                    ck = s->heap_key[c];
                }
            if (!(ck < key))
                break;
            mfmm_heap_place(s, i, ck, s->heap_vertex[child]);
            i = child;
        }
        mfmm_heap_place(s, i, key, v);
    }
    return top;
}

/* ---- the march ---- */

/* Resets T to +inf and every label to Far, keeping target flags off. */
MFMM_INLINE void mfmm_march_reset(mfmm_march_state *s, mfmm_i32 nv)
{
    for (mfmm_i32 v = 0; v < nv; v++) {
        s->T[v] = MFMM_INF;
        s->label[v] = MFMM_FAR;
    }
    s->heap_size = 0;
    s->targets_left = 0;
    s->n_touched = 0;
    s->n_preset = 0;
}

/* Vertex v leaves Far: remember it when the march keeps a touched list. */
MFMM_INLINE void mfmm_march_touch(mfmm_march_state *s, mfmm_i32 v, mfmm_u8 st)
{
    if (st == MFMM_FAR && s->touched)
        s->touched[s->n_touched++] = v;
}

/* Offers value to vertex v as an initial condition (a source). Sources start
 * Close, not Alive, so that several sources with different values settle in
 * order of T. */
MFMM_INLINE void mfmm_march_seed(mfmm_march_state *s, mfmm_i32 v, double value)
{
    mfmm_u8 st = s->label[v] & MFMM_STATE_MASK;
    if (value < s->T[v]) {
        s->T[v] = value;
        mfmm_heap_push_or_decrease(s, v, value, st == MFMM_CLOSE);
        mfmm_march_touch(s, v, st);
        s->label[v] = (mfmm_u8)((s->label[v] & MFMM_TARGET) | MFMM_CLOSE);
    }
}

/* Section 2's loop head, for both marches: settles the heap's top x (the
 * heap is not empty) and returns it, or -1 when the march stops: x's T
 * passes max_distance (x stays Close), or x was the last target (x
 * settled and counted). */
MFMM_INLINE mfmm_i32 mfmm_march_settle(mfmm_march_state *w, mfmm_i32 *settled,
                                       int stop_at_targets)
{
    mfmm_i32 x = w->heap_vertex[0];
    if (w->T[x] > w->max_distance)
        return -1;
    mfmm_heap_pop(w);
    mfmm_u8 lx = w->label[x];
    w->label[x] = (mfmm_u8)((lx & MFMM_TARGET) | MFMM_ALIVE);
    (*settled)++;
    if (stop_at_targets && (lx & MFMM_TARGET) && --w->targets_left == 0)
        return -1;
    return x;
}

/* The costs for updating vertex c of face f from its other vertices a, b
 * (the face's vertices after c, in its order): f_a along edge CB, f_b along
 * CA, f_t across the triangle; returns F(C) (per face: the face's F), what
 * the virtual stencil's test compares.
 * Per face, F is constant on the face. Per vertex, F is taken as linear
 * along each path: the mean of its ends' F on an edge (trapezoid), and
 * across the triangle the mean of F(C) and F at the middle of AB, as a
 * characteristic from AB to C has it. (F(C) alone over the whole triangle,
 * the paper's F_ij, lets a cheap vertex pull T down through costly
 * neighbours, far below a finer mesh's T: docs/march-measurements.md.) */
MFMM_INLINE double mfmm_march_cost(const mfmm_march_state *s, mfmm_i32 f_id, mfmm_i32 c,
                                   mfmm_i32 a, mfmm_i32 b, double *f_a, double *f_b,
                                   double *f_t)
{
    double f = 1.0;
    if (s->cost_location == 1) {
        f = s->cost[c];
        double fa = s->cost[a], fb = s->cost[b];
        *f_b = 0.5 * (fa + f);
        *f_a = 0.5 * (fb + f);
        *f_t = 0.5 * f + 0.25 * (fa + fb);
        return f;
    }
    if (s->cost_location == 2)
        f = s->cost[f_id];
    *f_a = f;
    *f_b = f;
    *f_t = f;
    return f;
}

/* Whether the virtual stencil of virtual edge vr (its corner C, with the
 * face's other vertices a, b, and its V = iv) may be used under the march's
 * cost. Its virtual edge
 * and triangles charge the corner's own F over the unfolded strip between C
 * and V and over the virtual triangles A-C-V, V-C-B, which lie over faces
 * other than the corner's: it holds only where F is the same over that
 * footprint, the faces around the strip's vertices A, B and those up to V
 * (per face: their F; per vertex: F at each of their vertices), read from
 * s->uniform. Elsewhere the corner takes the plain stencil, as with
 * unfolding off (else a cost-1 face's virtual edge through cost-100
 * faces gives T far too low). */
MFMM_INLINE int mfmm_march_virt_ok(const mfmm_march_state *s, const mfmm_march_mesh *m,
                                   MFMM_GLOBAL const mfmm_virt *vr, mfmm_i32 a, mfmm_i32 b,
                                   mfmm_i32 iv, double f)
{
    MFMM_GLOBAL const double *U = s->uniform;
    if (U[a] != f || U[b] != f || U[iv] != f)
        return 0;
    mfmm_i32 j = (mfmm_i32)(vr - m->virts);
    for (mfmm_i32 i = m->strip_offset[j]; i < m->strip_offset[j + 1]; i++)
        if (U[m->strip[i]] != f)
            return 0;
    return 1;
}

/* Offers t to vertex c (label lc): lowers T(c) and its heap key if t is
 * less. */
MFMM_INLINE void mfmm_march_offer_to(mfmm_march_state *s, const mfmm_march_mesh *m, mfmm_i32 c,
                                     mfmm_u8 lc, double t, const int spokes)
{
    if (t < s->T[c]) {
        mfmm_u8 st = lc & MFMM_STATE_MASK;
        /* c joins the front: its own spokes or faces are read when it
         * settles. Its spokes (~7 lines) are fetched now, long before, so
         * that they are in cache when it settles
         * (docs/march-measurements.md) */
        if (st == MFMM_FAR) {
            if (spokes) {
                MFMM_GLOBAL const char *b = (MFMM_GLOBAL const char *)(m->spokes + m->spoke_offset[c]);
                MFMM_PREFETCH(b);
                MFMM_PREFETCH(b + 64);
                MFMM_PREFETCH(b + 128);
                MFMM_PREFETCH(b + 192);
                MFMM_PREFETCH(b + 256);
                MFMM_PREFETCH(b + 320);
            } else
                MFMM_PREFETCH(m->wedge + m->wedge_offset[c]);
        }
        s->T[c] = t;
        mfmm_heap_push_or_decrease(s, c, t, st == MFMM_CLOSE);
        mfmm_march_touch(s, c, st);
        s->label[c] = (mfmm_u8)((lc & MFMM_TARGET) | MFMM_CLOSE);
    }
}

/* The face walk's offer (mfmm_march_offer_to: it prefetches c's faces). */
MFMM_INLINE void mfmm_march_offer(mfmm_march_state *s, const mfmm_march_mesh *m, mfmm_i32 c,
                                  mfmm_u8 lc, double t)
{
    mfmm_march_offer_to(s, m, c, lc, t, 0);
}

/* The virtual edge of corner k = 3 f + k' that ends at V = iv: V's list
 * (virt_first) holds it. Read once V is Alive, when V's own settling has
 * just read that list (and under a cost for the footprint's test). */
MFMM_INLINE MFMM_GLOBAL const mfmm_virt *mfmm_march_virt_of(const mfmm_march_mesh *m,
                                                            mfmm_i32 iv, mfmm_i32 k)
{
    mfmm_i32 j = m->virt_first[iv];
    while (m->virts[j].corner != k)
        j++;
    return m->virts + j;
}

/* x has just settled (T(x) = tx); c is vertex jc of face fr (id f_id),
 * neither Alive nor fixed, and y the face's third vertex (alive_y: whether
 * it has settled). Returns what x newly makes possible for c in this face
 * (section 4.1), for the caller to offer: the edge update from x and, when
 * y is Alive, the triangle's inside;
 * at an obtuse corner with a virtual edge (section 4.2), instead of the
 * inside, the virtual triangle of x and V once V is Alive. Every other
 * update through this face was offered when its last vertex settled
 * (the edge from y when y did, the virtual edge's when V does), so c gets
 * the minimum over the same updates as recomputing the whole corner. */
MFMM_COLD double mfmm_march_corner(const mfmm_march_state *s, const mfmm_march_mesh *m,
                                     MFMM_GLOBAL const mfmm_face *fr, mfmm_i32 f_id, mfmm_i32 jc,
                                     mfmm_i32 c, mfmm_i32 x, double tx, int alive_y)
{
    mfmm_i32 ja = (0x09 >> (2 * jc)) & 3, jb = (0x12 >> (2 * jc)) & 3; /* jc + 1, jc + 2 mod 3 */
    mfmm_i32 ia = fr->v[ja], ib = fr->v[jb];
    int x_is_a = ia == x;
    double f_a = 1.0, f_b = 1.0, f_t = 1.0, f = 1.0;
    if (s->cost_location != 0)
        f = mfmm_march_cost(s, f_id, c, ia, ib, &f_a, &f_b, &f_t);
    /* |xc| is the edge opposite the third vertex */
    double best = x_is_a ? tx + fr->len[jb] * f_b : tx + fr->len[ja] * f_a;
    mfmm_i32 vi = fr->virt;
    int virt = (vi & 3) == jc && s->unfolding;
    if (virt) {
        mfmm_i32 iv = vi >> 2;
        int v_alive = (s->label[iv] & MFMM_STATE_MASK) == MFMM_ALIVE;
        /* (the footprint matters once V, or both A and B, have settled) */
        if ((v_alive || alive_y) && s->cost_location != 0 &&
            !mfmm_march_virt_ok(s, m, mfmm_march_virt_of(m, iv, 3 * f_id + jc), ia, ib, iv, f))
            virt = 0;
        else if (v_alive) {
            MFMM_GLOBAL const mfmm_virt *vr = mfmm_march_virt_of(m, iv, 3 * f_id + jc);
            double tv = s->T[iv];
            if (x_is_a)
                best = mfmm_min(best, mfmm_triangle_update(tx, tv, vr->len, fr->len[jb],
                                                           vr->cos_a, f_t));
            else
                best = mfmm_min(best, mfmm_triangle_update(tv, tx, fr->len[ja], vr->len,
                                                           vr->cos_b, f_t));
        }
    }
    if (!virt && alive_y)
        /* a zero-area face's NaN cosine makes this +inf */
        best = mfmm_min(best, mfmm_triangle_interior(s->T[ia], s->T[ib], fr->len[ja],
                                                     fr->len[jb], fr->cosv[jc], f_t));
    return best;
}

/* x has just settled and is the V of virtual edge vr (section 4.2): offers
 * its corner C the virtual edge and the virtual triangles with A and B that
 * have settled. */
MFMM_COLD void mfmm_march_virtual(mfmm_march_state *s, const mfmm_march_mesh *m,
                                    MFMM_GLOBAL const mfmm_virt *vr, double tx)
{
    mfmm_i32 c = vr->c;
    mfmm_u8 lc = s->label[c];
    if ((lc & MFMM_STATE_MASK) == MFMM_ALIVE || (lc & MFMM_FIXED))
        return;
    mfmm_i32 k = vr->corner, f_id = k / 3, jc = k - 3 * f_id;
    MFMM_GLOBAL const mfmm_face *fr = m->faces + f_id;
    mfmm_i32 ja = jc == 2 ? 0 : jc + 1, jb = ja == 2 ? 0 : ja + 1;
    mfmm_i32 ia = fr->v[ja], ib = fr->v[jb];
    double f_a = 1.0, f_b = 1.0, f_t = 1.0, f = 1.0;
    if (s->cost_location != 0) {
        f = mfmm_march_cost(s, f_id, c, ia, ib, &f_a, &f_b, &f_t);
        if (!mfmm_march_virt_ok(s, m, vr, ia, ib, fr->virt >> 2, f))
            return;
    }
    double best = tx + vr->len * f_t;
    if ((s->label[ia] & MFMM_STATE_MASK) == MFMM_ALIVE)
        best = mfmm_min(best, mfmm_triangle_update(s->T[ia], tx, vr->len, fr->len[jb],
                                                   vr->cos_a, f_t));
    if ((s->label[ib] & MFMM_STATE_MASK) == MFMM_ALIVE)
        best = mfmm_min(best, mfmm_triangle_update(tx, s->T[ib], fr->len[ja], vr->len,
                                                   vr->cos_b, f_t));
    mfmm_march_offer(s, m, c, lc, best);
}

/* Seeds v at an exact value (the exact start, src/start/seed.h): as
 * mfmm_march_seed, and the march never lowers it, since an update from
 * first-order neighbours can only add error to an exact value. */
MFMM_INLINE void mfmm_march_seed_fixed(mfmm_march_state *s, mfmm_i32 v, double value)
{
    mfmm_march_seed(s, v, value);
    if (s->T[v] == value)
        s->label[v] = (mfmm_u8)(s->label[v] | MFMM_FIXED);
}

/* Seeds one source's exact patch (the exact start, src/start/seed.h): the
 * n vertices pv at values value + f * pd, final (mfmm_march_seed_fixed), in
 * this order. A patch vertex whose neighbours are all in the patch, as are
 * the corners of the virtual edges that end at it, settles here, off the
 * heap: settling it would offer nothing (its neighbours are fixed), and an
 * update of a vertex outside the patch never reads it (that vertex would be
 * its neighbour, or the corner of one of its virtual edges). So the rows are
 * those of seeding it, but for the order of equal keys in the heap. Not
 * with targets (the march stops at the last one: the vertices it has not
 * settled are +inf) nor past max_distance. */
MFMM_INLINE void mfmm_march_seed_patch(mfmm_march_state *s, const mfmm_march_mesh *m,
                                       MFMM_GLOBAL const mfmm_i32 *pv,
                                       MFMM_GLOBAL const double *pd, mfmm_i32 n, double value,
                                       double f)
{
    int settle = s->targets_left == 0;
    if (settle)
        for (mfmm_i32 i = 0; i < n; i++)
            s->label[pv[i]] = (mfmm_u8)(s->label[pv[i]] | MFMM_FIXED);
    for (mfmm_i32 i = 0; i < n; i++) {
        mfmm_i32 v = pv[i];
        double t = value + f * pd[i];
        int inside = settle && t <= s->max_distance && t < s->T[v];
        for (mfmm_i32 j = m->wedge_offset[v]; inside && j < m->wedge_offset[v + 1]; j++) {
            mfmm_i32 wc = m->wedge[j];
            MFMM_GLOBAL const mfmm_face *fr = m->faces + MFMM_WEDGE_FACE(wc);
            inside = (s->label[fr->v[MFMM_WEDGE_NEXT(wc)]] & MFMM_FIXED) &&
                     (s->label[fr->v[MFMM_WEDGE_PREV(wc)]] & MFMM_FIXED);
        }
        for (mfmm_i32 j = m->virt_first[v]; inside && s->unfolding && j < m->virt_first[v + 1]; j++)
            inside = (s->label[m->virts[j].c] & MFMM_FIXED) != 0;
        if (!inside) {
            mfmm_march_seed_fixed(s, v, t);
            continue;
        }
        s->T[v] = t;
        mfmm_march_touch(s, v, s->label[v] & MFMM_STATE_MASK);
        s->label[v] = (mfmm_u8)(MFMM_ALIVE | MFMM_FIXED);
        s->n_preset++;
    }
}

/* Section 2's loop, until the heap is empty, T passes max_distance or every
 * target is settled (mfmm_march_run). general: a cost (the updates of
 * mfmm_march_corner); 0: F = 1, inline. A constant where it is called, so
 * that each case compiles to a loop of its own. The workspace and the mesh
 * are read through local copies (w, mm): a label store is a byte store,
 * which may alias anything, and would make the compiler reload every field
 * of s and m after it; s and m themselves are only passed (synced) to the
 * out-of-line steps. */
MFMM_INLINE mfmm_i32 mfmm_march_loop(mfmm_march_state *s, const mfmm_march_mesh *m,
                                     const int general)
{
    mfmm_march_state w = *s;
    mfmm_march_mesh mm = *m;
    mfmm_i32 settled = w.n_preset;
    int stop_at_targets = w.targets_left > 0;
    mfmm_i32 no_virt = w.unfolding ? 0 : 3;
    while (w.heap_size > 0) {
        mfmm_i32 x = mfmm_march_settle(&w, &settled, stop_at_targets);
        if (x < 0)
            break;
        mfmm_i32 end = mm.wedge_offset[x + 1];
        /* The march waits on face records (cache misses). The next vertex
         * to settle is almost always the new heap top: ask for its faces
         * one iteration ahead (this vertex's were asked for last iteration). */
        if (w.heap_size > 0) {
            mfmm_i32 y = w.heap_vertex[0];
            for (mfmm_i32 j = mm.wedge_offset[y]; j < mm.wedge_offset[y + 1]; j++)
                MFMM_PREFETCH(mm.faces + MFMM_WEDGE_FACE(mm.wedge[j]));
            /* and the first virtual edge ending at y (its list is short) */
            if (w.unfolding)
                MFMM_PREFETCH(mm.virts + mm.virt_first[y]);
        }
        double tx = w.T[x];
        /* the virtual edges that end at x (section 4.2), before x's faces:
         * their records and C's face are loads of their own, which then
         * overlap with the face walk instead of waiting after it
         * (docs/march-measurements.md) */
        if (w.unfolding)
            for (mfmm_i32 j = mm.virt_first[x]; j < mm.virt_first[x + 1]; j++) {
                MFMM_GLOBAL const mfmm_virt *vr = mm.virts + j;
                if (general) {
                    s->heap_size = w.heap_size;
                    s->n_touched = w.n_touched;
                    mfmm_march_virtual(s, m, vr, tx);
                    w.heap_size = s->heap_size;
                    w.n_touched = s->n_touched;
                    continue;
                }
                /* F = 1 (as mfmm_march_virtual): the virtual edge, and the
                 * virtual triangles with A and B that have settled */
                mfmm_i32 c = vr->c;
                mfmm_u8 lc = w.label[c];
                if ((lc & MFMM_STATE_MASK) == MFMM_ALIVE || (lc & MFMM_FIXED))
                    continue;
                mfmm_i32 kc = vr->corner, fc = (mfmm_i32)((mfmm_u32)kc / 3u), jc = kc - 3 * fc;
                MFMM_GLOBAL const mfmm_face *fr = mm.faces + fc;
                mfmm_i32 ja = jc == 2 ? 0 : jc + 1, jb = ja == 2 ? 0 : ja + 1;
                mfmm_i32 ia = fr->v[ja], ib = fr->v[jb];
                double vlen = vr->len, t = tx + vlen;
                if ((w.label[ia] & MFMM_STATE_MASK) == MFMM_ALIVE) {
                    double ta = w.T[ia];
                    t = mfmm_min(t, ta + fr->len[jb]);
                    t = mfmm_min(t, mfmm_triangle_interior(ta, tx, vlen, fr->len[jb], vr->cos_a, 1.0));
                }
                if ((w.label[ib] & MFMM_STATE_MASK) == MFMM_ALIVE) {
                    double tb = w.T[ib];
                    t = mfmm_min(t, tb + fr->len[ja]);
                    t = mfmm_min(t, mfmm_triangle_interior(tx, tb, fr->len[ja], vlen, vr->cos_b, 1.0));
                }
                mfmm_march_offer(&w, &mm, c, lc, t);
            }
        /* section 2's update of x's neighbours, face by face. x's faces are
         * in fan order (mesh/build.c): face (x, p, q) is mostly followed by
         * (x, q, r), so q's value waits one face (pend) and is offered once
         * with what that face gives it: the min of the same values in fewer
         * offers. Around a closed fan the first face's p is the last face's
         * q: its value waits for the fan's end (first) and goes with the
         * last pend, one offer instead of two (docs/march-measurements.md) */
        mfmm_i32 pend = -1, first = -1, j0 = mm.wedge_offset[x];
        double pend_t = 0.0, first_t = 0.0;
        for (mfmm_i32 j = j0; j < end; j++) {
            mfmm_i32 wc = mm.wedge[j], f_id = MFMM_WEDGE_FACE(wc);
            MFMM_GLOBAL const mfmm_face *fr = mm.faces + f_id;
            /* the next corners, k + 1 and k + 2 mod 3, as the entry holds
             * them (k is as good as random, so a ?: on it compiles to a
             * branch that mispredicts: docs/march-measurements.md) */
            mfmm_i32 jp = MFMM_WEDGE_NEXT(wc), jq = MFMM_WEDGE_PREV(wc), k = 3 - jp - jq;
            mfmm_i32 p = fr->v[jp], q = fr->v[jq];
            /* at a break in x's fan the pending q goes first, so that the
             * offers come in the spokes' order (spokes.c) */
            if (pend >= 0 && pend != p) {
                mfmm_march_offer(&w, &mm, pend, w.label[pend], pend_t);
                pend = -1;
            }
            mfmm_u8 lp = w.label[p], lq = w.label[q];
            int alive_p = (lp & MFMM_STATE_MASK) == MFMM_ALIVE;
            int alive_q = (lq & MFMM_STATE_MASK) == MFMM_ALIVE;
            /* a cost: the general update. Else F = 1, inline: the edge from
             * x (|xp| = len[jq]) and one triangle through x, the plain one
             * once the third vertex is Alive or, at the face's obtuse corner
             * with its virtual edge (section 4.2), the virtual triangle of x
             * and V once V is Alive, with the virtual edge from V (V's
             * settling offered it too: equal, so min leaves it). The same
             * operands as mfmm_march_corner, so that both round alike.
             * (Branching on jv == jp, jq is faster than selecting:
             * docs/march-measurements.md.) */
            mfmm_i32 jv = (fr->virt | no_virt) & 3; /* 3: none */
            if (!alive_p && !(lp & MFMM_FIXED)) {
                double t;
                if (general) {
                    t = mfmm_march_corner(s, m, fr, f_id, jp, p, x, tx, alive_q);
                } else {
                    /* p = C, q = A, x = B */
                    double ta = 0.0, b = fr->len[k], cs = fr->cosv[jp];
                    t = tx + fr->len[jq];
                    int go = alive_q;
                    if (jv == jp) {
                        mfmm_i32 iv = fr->virt >> 2;
                        go = (w.label[iv] & MFMM_STATE_MASK) == MFMM_ALIVE;
                        if (go) {
                            MFMM_GLOBAL const mfmm_virt *vr = mfmm_march_virt_of(&mm, iv, 3 * f_id + jp);
                            ta = w.T[iv];
                            b = vr->len;
                            cs = vr->cos_b;
                            t = mfmm_min(t, ta + b);
                        }
                    } else if (go) {
                        ta = w.T[q];
                    }
                    if (go)
                        t = mfmm_min(t, mfmm_triangle_interior(ta, tx, fr->len[jq], b, cs, 1.0));
                }
                if (p == pend) {
                    t = mfmm_min(t, pend_t);
                    pend = -1;
                }
                if (j == j0) {
                    first = p;
                    first_t = t;
                } else
                    mfmm_march_offer(&w, &mm, p, lp, t);
            }
            /* (offers only turn Far into Close: alive_q and the fixed flag hold) */
            if (!alive_q && !(lq & MFMM_FIXED)) {
                double t;
                if (general) {
                    t = mfmm_march_corner(s, m, fr, f_id, jq, q, x, tx, alive_p);
                } else {
                    /* q = C, x = A, p = B */
                    double tb = 0.0, a = fr->len[k], cs = fr->cosv[jq];
                    t = tx + fr->len[jp];
                    int go = alive_p;
                    if (jv == jq) {
                        mfmm_i32 iv = fr->virt >> 2;
                        go = (w.label[iv] & MFMM_STATE_MASK) == MFMM_ALIVE;
                        if (go) {
                            MFMM_GLOBAL const mfmm_virt *vr = mfmm_march_virt_of(&mm, iv, 3 * f_id + jq);
                            tb = w.T[iv];
                            a = vr->len;
                            cs = vr->cos_a;
                            t = mfmm_min(t, tb + a);
                        }
                    } else if (go) {
                        tb = w.T[p];
                    }
                    if (go)
                        t = mfmm_min(t, mfmm_triangle_interior(tx, tb, a, fr->len[jp], cs, 1.0));
                }
                pend = q;
                pend_t = t;
            }
        }
        if (pend >= 0) {
            if (pend == first) {
                pend_t = mfmm_min(pend_t, first_t);
                first = -1;
            }
            mfmm_march_offer(&w, &mm, pend, w.label[pend], pend_t);
        }
        if (first >= 0)
            mfmm_march_offer(&w, &mm, first, w.label[first], first_t);
    }
    s->heap_size = w.heap_size;
    s->n_touched = w.n_touched;
    s->targets_left = w.targets_left;
    return settled;
}

/* Spoke r's triangle q (0 or 1, a constant where called) once its y has
 * settled: min(t, its update of c from x and y). */
MFMM_INLINE double mfmm_march_spoke_triangle(const mfmm_march_state *w,
                                             MFMM_GLOBAL const mfmm_spoke *r, const int q,
                                             double tx, double t)
{
    mfmm_i32 y = r->y[q];
    if ((w->label[y] & MFMM_STATE_MASK) != MFMM_ALIVE)
        return t;
    double ty = w->T[y];
    int xa = (int)((r->x_is_a >> q) & 1u);
    double ta = xa ? tx : ty, tb = xa ? ty : tx;
    double la = xa ? r->ly[q] : r->len, lb = xa ? r->len : r->ly[q];
    return mfmm_min(t, mfmm_triangle_interior(ta, tb, la, lb, r->cs[q], 1.0));
}

/* Section 2's loop over spokes (F = 1, unfolding on): the updates of the
 * face walk (mfmm_march_loop with general = 0), the same operands in the
 * same order of offers, so the same rows bit for bit, from records that
 * hold them ready: no case for virtual stencils, one offer per spoke, x's
 * spokes read in one sequence, faster than the face walk
 * (docs/march-measurements.md).
 * A virtual edge's own term (T(V) + |CV|) and the edges from A and B are
 * not in its spokes: V's, A's and B's settling offered them. */
MFMM_INLINE mfmm_i32 mfmm_march_spoke_loop(mfmm_march_state *s, const mfmm_march_mesh *m)
{
    mfmm_march_state w = *s;
    mfmm_march_mesh mm = *m;
    mfmm_i32 settled = w.n_preset;
    int stop_at_targets = w.targets_left > 0;
    while (w.heap_size > 0) {
        mfmm_i32 x = mfmm_march_settle(&w, &settled, stop_at_targets);
        if (x < 0)
            break;
        /* the next vertex to settle is almost always the new heap top: ask
         * for its spokes one iteration ahead, as one range */
        if (w.heap_size > 0) {
            mfmm_i32 y = w.heap_vertex[0];
            MFMM_GLOBAL const char *b = (MFMM_GLOBAL const char *)(mm.spokes + mm.spoke_offset[y]);
            MFMM_GLOBAL const char *e = (MFMM_GLOBAL const char *)(mm.spokes + mm.spoke_offset[y + 1]);
            for (; b < e; b += 64)
                MFMM_PREFETCH(b);
        }
        double tx = w.T[x];
        for (mfmm_i32 j = mm.spoke_offset[x]; j < mm.spoke_offset[x + 1]; j++) {
            MFMM_GLOBAL const mfmm_spoke *r = mm.spokes + j;
            mfmm_i32 c = r->c;
            mfmm_u8 lc = w.label[c];
            if ((lc & MFMM_STATE_MASK) == MFMM_ALIVE || (lc & MFMM_FIXED))
                continue;
            /* the edge from x, and each triangle whose y has settled
             * (section 4.1; its virtual triangle at an obtuse corner,
             * section 4.2) */
            double t = tx + r->len;
            t = mfmm_march_spoke_triangle(&w, r, 0, tx, t);
            t = mfmm_march_spoke_triangle(&w, r, 1, tx, t);
            mfmm_march_offer_to(&w, &mm, c, lc, t, 1);
        }
    }
    s->heap_size = w.heap_size;
    s->n_touched = w.n_touched;
    s->targets_left = w.targets_left;
    return settled;
}

/* Section 2's loop: settle the Close vertex of least T, recompute its
 * neighbours from settled values, until the heap is empty, T passes
 * max_distance, or every target is settled. Vertices not settled are set
 * to +inf and target and fixed flags cleared (with a touched list: only at
 * the touched vertices; labels stay Close/Alive there for the caller to
 * reset; when every vertex settled, the labels keep their fixed flags:
 * callers reset labels before the next march, as solve.c and the kernel's
 * mfmm_march_reset do). Returns the number of vertices settled. */
MFMM_INLINE mfmm_i32 mfmm_march_run(mfmm_march_state *s, const mfmm_march_mesh *m)
{
    int targets = s->targets_left > 0;
    mfmm_i32 settled = s->cost_location != 0          ? mfmm_march_loop(s, m, 1)
                       : m->spokes && s->unfolding ? mfmm_march_spoke_loop(s, m)
                                                   : mfmm_march_loop(s, m, 0);
    /* every vertex settled and no target flags: nothing to reset (a full
     * row of a connected mesh) */
    if (settled == m->nv && !targets)
        return settled;
    /* a list is worth it for a local march; past nv/8 touched vertices a
     * sequential pass is cheaper than scattered ones
     * (docs/march-measurements.md) */
    if (s->touched && s->n_touched < m->nv / 8) {
        for (mfmm_i32 i = 0; i < s->n_touched; i++) {
            mfmm_i32 v = s->touched[i];
            if ((s->label[v] & MFMM_STATE_MASK) != MFMM_ALIVE)
                s->T[v] = MFMM_INF;
        }
        return settled;
    }
    for (mfmm_i32 v = 0; v < m->nv; v++) {
        if ((s->label[v] & MFMM_STATE_MASK) != MFMM_ALIVE)
            s->T[v] = MFMM_INF;
        s->label[v] &= (mfmm_u8)MFMM_STATE_MASK;
    }
    return settled;
}

#endif /* MFMM_MARCH_H */
