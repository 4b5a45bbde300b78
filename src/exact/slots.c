/* The window method (MFMM_METHOD_WINDOWS): window propagation keeping K
 * windows (2 by default) in place on each half-edge, in distance order
 * (slots.h; docs/windows.md).
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
 * - Walls and zero-area faces stop windows (the edge relaxation goes on);
 *   at a non-manifold edge a window goes on into every other face on it
 *   (as the exact solver's ex_fan_out); copies of a face are skipped. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "slots.h"
#include "state.h"
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

struct mfmm_slots {
    const mfmm_exact_tables *t;
    const mfmm_mesh *mesh;
    int32_t nv, nf;
    const ex_face *fr;
    const int32_t *vf_offset, *vf_corner, *face_in;
    sl_win *slot;     /* (2 * 3 nf) */
    uint8_t *n_slot;  /* (3 nf) windows held */
    double *d;
    uint8_t *need;    /* (nv) a vertex that may bend a path: the exact tables' pseudo-source
                         flag, less vertices at a wall whose angle sum is pi or less */
    uint8_t *is_src;  /* (nv) the vertex sources of the solve */
    uint8_t *is_tgt;  /* (nv) targets of mfmm_slots_run not yet settled */
    uint8_t *flat;    /* (nv) offers redundant after a ray (mfmm_slots_create) */
    uint8_t *ray;     /* (nv) d came from a window's straight ray (not an edge, not a
                         window's end) */
    mfmm_march_state h; /* T unused; label 0 far, 1 close, 2 settled */
    mfmm_march_state e; /* half-edges keyed by their windows' least distance */
    int K; /* windows per half-edge (mfmm_slots_set_k), 2 by default */
    double tgt_level; /* the largest value of the targets settled (sl_loop) */
    mfmm_slots_info info;
};

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
    size_t nv = (size_t)t->nv, nf = (size_t)t->nf, nh = 3 * nf;
    s->t = t;
    s->mesh = mesh;
    s->nv = t->nv;
    s->nf = t->nf;
    s->fr = t->fr;
    s->vf_offset = t->vf_offset;
    s->vf_corner = t->vf_corner;
    s->face_in = t->face_in;
    s->K = 2;
    s->slot = malloc((2 * nh + 1) * sizeof *s->slot);
    s->n_slot = malloc(nh + 1);
    s->d = malloc((nv + 1) * sizeof *s->d);
    s->ray = malloc(nv + 1);
    s->need = malloc(nv + 1);
    s->flat = malloc(nv + 1);
    s->is_src = calloc(nv + 1, 1);
    s->is_tgt = calloc(nv + 1, 1);
    s->h.label = malloc(nv + 1);
    s->h.heap_key = malloc((nv + 1) * sizeof(double));
    s->h.heap_vertex = malloc((nv + 1) * sizeof(int32_t));
    s->h.heap_pos = malloc((nv + 1) * sizeof(int32_t));
    s->e.label = malloc(nh + 1);
    s->e.heap_key = malloc((nh + 1) * sizeof(double));
    s->e.heap_vertex = malloc((nh + 1) * sizeof(int32_t));
    s->e.heap_pos = malloc((nh + 1) * sizeof(int32_t));
    if (!s->e.label || !s->e.heap_key || !s->e.heap_vertex || !s->e.heap_pos ||
        !s->slot || !s->n_slot || !s->d || !s->ray || !s->need || !s->flat || !s->is_src || !s->is_tgt || !s->h.label ||
        !s->h.heap_key || !s->h.heap_vertex || !s->h.heap_pos) {
        mfmm_slots_destroy(s);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    /* a vertex at a wall (two wall edges, no zero-area face or copy) whose
     * angle sum is pi or less bends no shortest path: it needs no offers;
     * flat: a vertex whose offers the windows beside it make
     * redundant once a ray reaches it: one whose neighbourhood unfolds flat
     * (an angle sum of 2 pi, no wall) or a wall's vertex of pi or less */
    for (size_t v = 0; v < nv; v++) {
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
        s->need[v] = t->pseudo[v] && (odd || walls != 2 || !(a <= EX_PI * (1.0 + 1e-9)));
        s->flat[v] = !s->need[v] && !odd &&
                     ((walls == 0 && fabs(a - EX_TWO_PI) <= 1e-9 * EX_TWO_PI) || walls == 2);
    }
    *out = s;
    return MFMM_OK;
}

size_t mfmm_slots_bytes(const mfmm_mesh *mesh)
{
    size_t nv = (size_t)mesh->nv, nh = 3 * (size_t)mesh->nf;
    /* slots, count, label and heap per half-edge; distances, flags and heap per vertex */
    return nh * (2 * sizeof(sl_win) + 2 + sizeof(double) + 2 * sizeof(int32_t)) +
           nv * (sizeof(double) + 6 + sizeof(double) + 2 * sizeof(int32_t));
}

void mfmm_slots_destroy(mfmm_slots *s)
{
    if (!s)
        return;
    free(s->slot);
    free(s->n_slot);
    free(s->d);
    free(s->ray);
    free(s->need);
    free(s->flat);
    free(s->is_src);
    free(s->is_tgt);
    free(s->h.label);
    free(s->h.heap_key);
    free(s->h.heap_vertex);
    free(s->h.heap_pos);
    free(s->e.label);
    free(s->e.heap_key);
    free(s->e.heap_vertex);
    free(s->e.heap_pos);
    free(s);
}

int mfmm_slots_set_k(mfmm_slots *s, int K)
{
    if (K < 1 || K > 8)
        return 0;
    sl_win *w = malloc(((size_t)K * 3 * (size_t)s->nf + 1) * sizeof *w);
    if (!w)
        return 0;
    free(s->slot);
    s->slot = w;
    s->K = K;
    return 1;
}

void mfmm_slots_get_info(const mfmm_slots *s, mfmm_slots_info *info)
{
    *info = s->info;
}

/* fmin and fmax as glibc's (the second operand on ties, a NaN operand
 * ignored), inlined where libm's are calls on the baseline target */
static inline double sl_fmin(double a, double b)
{
    return a < b ? a : b == b ? b : a;
}

static inline double sl_fmax(double a, double b)
{
    return a > b ? a : b == b ? b : a;
}

static inline void sl_update(mfmm_slots *s, int32_t v, double dist, int ray)
{
    if (!(dist < s->d[v])) {
        /* a ray as long as the value to rounding: the windows beside it
         * carry its paths on (a wall's straight side, relaxed along) */
        if (ray && dist <= s->d[v] + 1e-12 * s->d[v])
            s->ray[v] = 1;
        return;
    }
    /* a value lower only by rounding keeps the ray it had */
    s->ray[v] = (uint8_t)(ray | (s->ray[v] & (dist >= s->d[v] - 1e-12 * s->d[v])));
    s->d[v] = dist;
    uint8_t lab = s->h.label[v];
    if (lab == 2) {
        s->info.late_vertex++;
        return;
    }
    mfmm_heap_push_or_decrease(&s->h, v, dist, lab == 1);
    s->h.label[v] = 1;
}

/* the distances a window gives at the SL_NS points x (ascending) of its
 * edge: over the nearer end of its interval, then along the edge, outside
 * it (each end's segment computed once for all the points beyond it) */
static inline void sl_vals(const double *x, double b0, double b1, double px, double py,
                           double sigma, double *v)
{
    int j = 0;
    if (x[0] < b0) {
        double e = sigma + sqrt((b0 - px) * (b0 - px) + py * py);
        for (; j < SL_NS && x[j] < b0; j++)
            v[j] = e + fabs(x[j] - b0);
    }
    for (; j < SL_NS && !(x[j] > b1); j++)
        v[j] = sigma + sqrt((x[j] - px) * (x[j] - px) + py * py);
    if (j < SL_NS) {
        double e = sigma + sqrt((b1 - px) * (b1 - px) + py * py);
        for (; j < SL_NS; j++)
            v[j] = e + fabs(x[j] - b1);
    }
}

/* the lower of two values, NaN ignored (the envelope's loop) */
static inline double sl_lo(double a, double b)
{
    double lo = INFINITY;
    if (a < lo)
        lo = a;
    if (b < lo)
        lo = b;
    return lo;
}

/* half-edge g (not passed) holds a window whose least value is
 * sigma + the distance from (px, py) to [b0, b1]: g is passed by then */
static inline void sl_key(mfmm_slots *s, int32_t g, double b0, double b1, double px, double py,
                          double sigma)
{
    double c = px < b0 ? b0 : px > b1 ? b1 : px;
    double m = sigma + sqrt((c - px) * (c - px) + py * py);
    uint8_t lab = s->e.label[g];
    if (lab == 2 || (lab == 1 && !(m < s->e.heap_key[s->e.heap_pos[g]])))
        return;
    mfmm_heap_push_or_decrease(&s->e, g, m, lab == 1);
    s->e.label[g] = 1;
}

/* (sl_cross, below: a window entering face h / 3 through h crosses it) */
static void sl_cross(mfmm_slots *s, int32_t h, const sl_win *w);

/* Window [s0, s1] from pseudo-source (ix, iy) (the frame of the half-edge
 * it leaves through, iy >= 0 on the face's side) into the slots of half-edge
 * g across the edge, whose frame runs the other way when fl is set. */
static void sl_keep(mfmm_slots *s, int32_t g, int fl, double L, double s0, double s1, double t0,
                    double t1, double ix, double iy, double sigma)
{
    double b0 = fl ? L - s1 : s0, b1 = fl ? L - s0 : s1, px = fl ? L - ix : ix, py = -iy;
    double g0 = fl ? L - t1 : t0, g1 = fl ? L - t0 : t1;
    sl_win *w = s->slot + (size_t)s->K * g;
    int n = s->n_slot[g], at;
    /* the same pseudo-source (to rounding) as a slot's, with traced rays
     * that meet the slot's: the pieces of one window that went round a
     * vertex by its two sides, one window together (the rays between them,
     * cut by trims, are paths too). Pieces whose traced rays do not meet
     * stay apart: they may have come round a hole, whose rays are no paths. */
    double tol = SL_SAME * (L + fabs(px) - py + sigma);
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
        sl_key(s, g, b0, b1, px, py, sigma);
        if (s->e.label[g] == 2) {
            s->info.late++;
            sl_win c = {b0, b1, px, py, sigma, g0, g1};
            sl_cross(s, g, &c);
        }
        return;
    }
    if (n < s->K) {
        at = n;
        s->n_slot[g] = (uint8_t)(n + 1);
    } else {
        /* the envelope: of the K + 1 windows (the new one
         * included) drop the one whose loss raises the least least, the
         * sum over SL_NS points of the edge of the lowest value there */
        double x[SL_NS], val[9][SL_NS];
        for (int j = 0; j < SL_NS; j++)
            x[j] = L * j / (SL_NS - 1);
        for (int i = 0; i < n; i++)
            sl_vals(x, w[i].b0, w[i].b1, w[i].px, w[i].py, w[i].sigma, val[i]);
        sl_vals(x, b0, b1, px, py, sigma, val[n]);
        double best = INFINITY;
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
                    double lo = INFINITY;
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
    w[at] = (sl_win){b0, b1, px, py, sigma, g0, g1};
    s->info.kept++;
    sl_key(s, g, b0, b1, px, py, sigma);
    if (s->e.label[g] == 2) {
        /* kept after its half-edge was passed: crossed at once */
        s->info.late++;
        sl_win c = w[at];
        sl_cross(s, g, &c);
    }
}

/* A window leaving face h / 3 through half-edge h: rays across [s0, s1]
 * of the edge, traced across [t0, t1] (sl_win), from (ix, iy) in h's frame
 * (iy >= 0, on the face's side); offer: 0 a window's child, 1 a vertex's
 * offer, 2 a vertex source's. Lowers the edge's ends it reaches, then goes
 * into the slots of the half-edge(s) across. */
static void sl_emit(mfmm_slots *s, int32_t h, double s0, double s1, double t0, double t1,
                    double ix, double iy, double sigma, int offer)
{
    const ex_face *r = s->fr + h / 3;
    int k = h % 3;
    int32_t va = r->v[ex_next[k]], vb = r->v[ex_prev[k]];
    double L = r->len[k];
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
        sl_update(s, va, sigma + r->len[ex_prev[k]], offer == 2);
        sl_update(s, vb, sigma + r->len[ex_next[k]], offer == 2);
    } else {
        if (s0 <= EX_POS_TOL * L)
            sl_update(s, va, sigma + sqrt(ix * ix + iy2), 1);
        if (s1 >= L - EX_POS_TOL * L)
            sl_update(s, vb, sigma + sqrt((ix - L) * (ix - L) + iy2), 1);
    }
    int32_t g = r->across[k];
    if (g < 0 && r->flip[k] != 2)
        return; /* a wall, or a zero-area face (its edges relax; windows stop) */
    s->info.emitted++;
    double da = s->d[va], db = s->d[vb];
    da += EX_TIE * da;
    db += EX_TIE * db;
    if (!ex_trim(ix, -iy, sigma, L, da, db, &s0, &s1)) {
        s->info.trimmed++;
        return;
    }
    if (g >= 0) {
        sl_keep(s, g, r->flip[k], L, s0, s1, t0, t1, ix, iy, sigma);
        return;
    }
    /* a non-manifold edge: on into every other face on it, each unfolded
     * across the edge (as the exact solver's ex_fan_out); a pseudo-source
     * on an end of the edge sends its rays along it, into no face */
    double tol = EX_POS_TOL * L;
    if (iy <= tol && (fabs(ix) <= tol || fabs(ix - L) <= tol))
        return;
    const mfmm_exact_tables *t = s->t;
    int32_t i = ex_nm_find(t->nm_he, t->n_nm, h);
    for (int32_t n = 0; i >= 0 && n < t->n_nm; n++) {
        int32_t q = t->nm_next[i];
        if (q == h)
            return;
        i = ex_nm_find(t->nm_he, t->n_nm, q);
        const ex_face *rq = s->fr + q / 3;
        if (!rq->skip)
            sl_keep(s, q, rq->v[ex_next[q % 3]] != va, L, s0, s1, t0, t1, ix, iy, sigma);
    }
}

/* A window entering face h / 3 through h crosses it (ex_propagate). */
static void sl_cross(mfmm_slots *s, int32_t h, const sl_win *w)
{
    int32_t f = h / 3;
    int m = h % 3;
    const ex_face *r = s->fr + f;
    int32_t vc = r->v[m];
    double L = r->len[m], cx = r->cx[m], cy = r->cy[m];
    double b0 = w->b0, b1 = w->b1, px = w->px, py = w->py, sigma = w->sigma;
    double g0 = w->g0, g1 = w->g1;
    s->info.crossed++;
    double tc = px + (cx - px) * (-py) / (cy - py);
    double tol = EX_POS_TOL * L;
    if (tc >= b0 - tol && tc <= b1 + tol) {
        double ex = cx - px, ey = cy - py;
        sl_update(s, vc, sigma + sqrt(ex * ex + ey * ey), 1);
    } else {
        /* C beside the window: the ray to the interval's nearer end, then
         * straight across the face (a path, wherever C is): a vertex at
         * the tip of thin faces otherwise gets only the edge relaxation, an
         * edge's length off */
        double e = tc < b0 ? b0 : b1;
        double ie = sqrt((e - px) * (e - px) + py * py), ec = sqrt((cx - e) * (cx - e) + cy * cy);
        sl_update(s, vc, sigma + ie + ec, 0);
    }
    int m1 = ex_next[m], m2 = ex_prev[m];
    if (b0 < tc) {
        int32_t hl = 3 * f + m2;
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
        int32_t hr = 3 * f + m1;
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

static void sl_pass(mfmm_slots *s, int32_t h)
{
    int n = s->n_slot[h];
#ifdef __GNUC__
    {
        /* what the children will read: the slots of the half-edges across
         * the face's other two edges, and the far corner's distance */
        const ex_face *r = s->fr + h / 3;
        int m = h % 3;
        for (int c = 1; c <= 2; c++) {
            int32_t g = r->across[(m + c) % 3];
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
        sl_win w = s->slot[(size_t)s->K * h + i];
        sl_cross(s, h, &w);
    }
}

static void sl_reset(mfmm_slots *s)
{
    size_t nv = (size_t)s->nv, nh = 3 * (size_t)s->nf;
    memset(&s->info, 0, sizeof s->info);
    memset(s->n_slot, 0, nh);
    memset(s->h.label, 0, nv);
    memset(s->e.label, 0, nh);
    s->e.heap_size = 0;
    for (size_t v = 0; v < nv; v++)
        s->d[v] = INFINITY;
    s->h.heap_size = 0;
}

/* The propagation from the sources seeded (is_src marks the vertex
 * sources) until both heaps are empty or their least key passes `level`;
 * n_tgt targets (is_tgt) left: once the last settles, the level comes down
 * to the largest target value (SL_STOP above). */
static void sl_loop(mfmm_slots *s, double level, int32_t n_tgt)
{
    const ex_face *fr = s->fr;
    double stop = level * (1.0 + SL_STOP);
    while (s->h.heap_size > 0 || s->e.heap_size > 0) {
        double top = s->h.heap_size > 0 ? s->h.heap_key[0] : INFINITY;
        if (s->e.heap_size > 0 && s->e.heap_key[0] < top)
            top = s->e.heap_key[0];
        if (top > stop)
            break;
        if (s->e.heap_size > 0 &&
            (s->h.heap_size == 0 || s->e.heap_key[0] <= s->h.heap_key[0])) {
            /* the half-edge whose windows come next */
            int32_t g = mfmm_heap_pop(&s->e);
            s->e.label[g] = 2;
            sl_pass(s, g);
            continue;
        }
        int32_t v = mfmm_heap_pop(&s->h);
        s->h.label[v] = 2;
#ifdef __GNUC__
        if (s->h.heap_size > 0) {
            /* the face records of the vertex likely to settle next: they
             * are the solve's misses (a record is first read when a corner
             * settles) */
            int32_t nx = s->h.heap_vertex[0];
            for (int32_t i = s->vf_offset[nx]; i < s->vf_offset[nx + 1]; i++) {
                const char *p = (const char *)(fr + ex_corner(s->vf_corner, s->face_in, i) / 3);
                __builtin_prefetch(p);
                __builtin_prefetch(p + 64);
            }
        }
#endif
        s->info.settled++;
        double dv = s->d[v];
        if (s->is_tgt[v]) {
            s->is_tgt[v] = 0;
            if (dv > s->tgt_level)
                s->tgt_level = dv;
            if (--n_tgt == 0 && s->tgt_level < level)
                stop = s->tgt_level * (1.0 + SL_STOP);
        }
        int32_t i0 = s->vf_offset[v], i1 = s->vf_offset[v + 1];
        for (int32_t i = i0; i < i1; i++) {
            int32_t c = ex_corner(s->vf_corner, s->face_in, i);
            const ex_face *r = fr + c / 3;
            int k = c % 3;
            if (r->skip) {
                if (r->skip == 1) { /* zero-area: the edges only */
                    sl_update(s, r->v[ex_next[k]], dv + r->len[ex_prev[k]], 0);
                    sl_update(s, r->v[ex_prev[k]], dv + r->len[ex_next[k]], 0);
                }
                continue;
            }
            if (s->ray[v] && s->flat[v]) {
                /* not needed: a vertex reached by a window's ray whose
                 * neighbourhood unfolds flat has the windows beside it
                 * carry its paths on; the edges only */
                sl_update(s, r->v[ex_next[k]], dv + r->len[ex_prev[k]], 0);
                sl_update(s, r->v[ex_prev[k]], dv + r->len[ex_next[k]], 0);
                if (!s->is_src[v])
                    continue;
            }
            sl_emit(s, c, 0.0, r->len[k], 0.0, r->len[k], r->cx[k], r->cy[k], dv,
                    s->is_src[v] ? 2 : 1);
        }
    }
}

/* the propagation to its end, every vertex's value to out */
static void sl_run(mfmm_slots *s, double *out)
{
    sl_loop(s, INFINITY, 0);
    for (size_t v = 0; v < (size_t)s->nv; v++)
        out[v] = s->d[v];
}

void mfmm_slots_solve(mfmm_slots *s, int32_t source, double *out)
{
    mfmm_slots_solve_multi(s, 1, &source, NULL, out);
}

void mfmm_slots_solve_multi(mfmm_slots *s, int32_t n, const int32_t *src, const double *value,
                            double *out)
{
    sl_reset(s);
    for (int32_t i = 0; i < n; i++) {
        sl_update(s, src[i], value ? value[i] : 0.0, 0);
        s->is_src[src[i]] = 1;
    }
    sl_run(s, out);
    for (int32_t i = 0; i < n; i++)
        s->is_src[src[i]] = 0;
}

void mfmm_slots_solve_face(mfmm_slots *s, int32_t f, const int32_t fv[3], const double w[3],
                           double *out)
{
    sl_reset(s);
    const ex_face *r = s->fr + f;
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
        sl_emit(s, 3 * f + k, 0.0, L, 0.0, L, ix, iy, 0.0, 0);
    }
    sl_run(s, out);
}

/* A point in face record r at weights b (r's corners, summing to 1, none
 * 1): each edge gets a window of the whole edge from the point, which also
 * sets the edge's ends to their straight distances. */
static void sl_start_face(mfmm_slots *s, int32_t r_id, const double b[3], double value)
{
    const ex_face *r = s->fr + r_id;
    for (int k = 0; k < 3; k++) {
        /* the point in half-edge 3f+k's frame (corner k+1 at 0, k+2 at L,
         * corner k at (cx, cy)) */
        double L = r->len[k];
        double ix = b[k] * r->cx[k] + b[ex_prev[k]] * L, iy = b[k] * r->cy[k];
        sl_emit(s, 3 * r_id + k, 0.0, L, 0.0, L, ix, iy, value, 0);
    }
}

int32_t mfmm_slots_run(mfmm_slots *s, const mfmm_source *sources, int32_t n_sources,
                       double max_distance, const int32_t *targets, int32_t n_targets,
                       double *T, int32_t *settled)
{
    const mfmm_mesh *mesh = s->mesh;
    sl_reset(s);
    s->tgt_level = -INFINITY;
    int32_t n_tgt = 0;
    for (int32_t i = 0; i < n_targets; i++)
        if (!s->is_tgt[targets[i]]) {
            s->is_tgt[targets[i]] = 1;
            n_tgt++;
        }
    for (int32_t i = 0; i < n_sources; i++) {
        const mfmm_source *src = sources + i;
        if (src->face < 0) {
            sl_update(s, src->vertex, src->value, 0);
            s->is_src[src->vertex] = 1;
            continue;
        }
        /* a point of a copy is that point of its original; weights in the
         * record's corner order */
        int32_t face = mfmm_mesh_original(mesh, src->face);
        const ex_face *r = s->fr + s->face_in[face];
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
            sl_update(s, v, src->value + vdist(p, mesh->xyz + 3 * (size_t)v), 0);
            s->is_src[v] = 1;
            continue;
        }
        sl_start_face(s, s->face_in[face], b, src->value);
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
                    sl_update(s, c, src->value + vdist(p, mesh->xyz + 3 * (size_t)c), 0);
                }
        }
    }
    sl_loop(s, max_distance, n_tgt);
    int32_t n = 0;
    for (int32_t v = 0; v < s->nv; v++) {
        s->is_src[v] = 0;
        s->is_tgt[v] = 0;
        if (s->h.label[v] == 2 && s->d[v] <= max_distance) {
            T[v] = s->d[v];
            if (settled)
                settled[n] = v;
            n++;
        }
    }
    return n;
}
