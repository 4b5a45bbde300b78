/* Window propagation: a window crossing a face updates the vertices it
 * reaches and goes on as at most two children on the face's other edges
 * (trimmed against the vertices' distances), through zero-area faces
 * (ex_pass) and into every face on a non-manifold edge (ex_fan_out); a
 * source or pseudo-source starts windows on the edges around it. The
 * algorithm and its sources: solver.c. */
#include <math.h>
#include <string.h>

#include "nonmanifold.h"
#include "propagate.h"
#include "queue.h"

/* Lowers d(v) to dist if that is less. Returns 1 when v is then a
 * pseudo-source to start, with a known fan, and the new distance is less
 * by more than rounding: the caller then gives the direction it came from
 * (ex_set_in). A gain within rounding keeps the direction of the path it
 * ties with: rays that graze a vertex along an edge reach it again from
 * faces they do not cross, with directions that are not theirs. */
int ex_update(mfmm_exact_ws *ws, int32_t v, double dist, int force)
{
    double old = ws->d[v];
    if (!(dist < old))
        return 0;
    if (old == INFINITY) {
        ws->touched[ws->n_touched++] = v;
        ws->emitted[v] = INFINITY;
    }
    ws->d[v] = dist;
    int gain = old == INFINITY || !(dist >= old - EX_TIE * old);
    if (gain)
        ws->in_angle[v] = NAN;
    if ((ws->pseudo[v] || force) && dist <= ws->max_d) {
        int32_t e = ex_new(ws);
        if (e < 0)
            return 0;
        ws->heap[e].key = dist;
        ws->heap[e].he = -v - 1;
        ex_queue(ws, e);
        return gain && !force && ws->fan_total[v] == ws->fan_total[v];
    }
    return 0;
}

/* in_angle of v = corner c's vertex from the angle psi inside the corner,
 * measured from the direction to the corner's first vertex; r: the length of
 * the path's last straight piece (from its pseudo-source to v), L: an edge
 * length of the face. */
static void ex_set_in(mfmm_exact_ws *ws, int32_t v, int32_t c, double psi, double r, double L)
{
    /* a pseudo-source (a point source) almost at v: the windows passing
     * beside v then tie with the paths through v to rounding and are trimmed
     * away near the straight-on direction, wider than the shadow's margin
     * (a point 1e-9 beside a saddle of hand left vertices at +inf): v starts
     * windows all around, as a source does (sound: they are real paths) */
    if (r < EX_NEAR * L || ws->fr[c / 3].skip)
        return;
    /* a direction outside the corner (rounding at a grazing ray) is not
     * trusted: in_angle stays NaN and v starts windows all around */
    if (!(psi >= -1e-9 && psi <= ws->fr[c / 3].angle[c % 3] + 1e-9))
        return;
    if (psi < 0.0)
        psi = 0.0;
    if (psi > ws->fr[c / 3].angle[c % 3])
        psi = ws->fr[c / 3].angle[c % 3];
    ws->in_angle[v] = ws->fan_a0[c] + ws->fr[c / 3].sgn[c % 3] * psi;
}

/* The distance from x to the interval [s0, s1] (s0 <= s1), as maxima
 * (no branch) */
static double ex_gap(double x, double s0, double s1)
{
    double lo = s0 - x, hi = x - s1;
    double g = lo > hi ? lo : hi;
    return g > 0.0 ? g : 0.0;
}

static void ex_emit(mfmm_exact_ws *ws, int32_t h, double s0, double s1, double ix, double iy,
                    double sigma, int known);

/* A window about to enter zero-area face hd / 3 at pass depth EX_MAX_PASS
 * (ex_pass's arguments) is queued there and passed on from depth 0 when
 * popped (ex_propagate), so that the recursion stays bounded while a longer
 * strip of such faces still carries it; it is trimmed against the windows
 * queued at hd before, so that one come round a loop of them ends. */
static void ex_pass_later(mfmm_exact_ws *ws, int32_t hd, int flip, double L, double s0,
                          double s1, double ix, double iy, double sigma)
{
    double dx = ex_gap(ix, s0, s1);
    double key = sigma + (dx > 0.0 ? sqrt(dx * dx + iy * iy) : iy);
    if (key > ws->max_d)
        return;
    /* in hd's frame */
    double b0 = flip ? L - s1 : s0, b1 = flip ? L - s0 : s1, px = flip ? L - ix : ix;
    /* (without a slot, memory being short, it goes on untrimmed) */
    int32_t slot = ex_pass_slot(ws, hd);
    if (slot != -1) {
        if (!ex_dominate(ws, slot, L, &b0, &b1, px, -iy, sigma))
            return;
        ex_keep(ws, slot, b0, b1, px, -iy, sigma);
    }
    int32_t wi = ex_new(ws);
    if (wi < 0)
        return;
    ex_entry *w = ws->heap + wi;
    w->b0 = b0;
    w->b1 = b1;
    w->px = px;
    w->py = -iy;
    w->sigma = sigma;
    w->he = hd;
    w->key = key;
    ex_queue(ws, wi);
    ws->n_windows++;
}

/* A window entering a zero-area face D through D's half-edge hd (flip: hd
 * runs the other way from the window's frame, an edge of length L). D's
 * corners lie on one line, so the points of the edge crossed are points of
 * D's other edges where their spans overlap it: a T-junction closed by a
 * needle (m on the segment ab, faces on ab one side and on am, mb the
 * other) joins the faces on both sides along the line. The window goes on,
 * in the same plane, from each overlap into the face across it (ex_emit):
 * the same straight paths. As a wall, D would make a shortest path
 * across the junction go round through a vertex. */
static void ex_pass(mfmm_exact_ws *ws, int32_t hd, int flip, double L, double s0, double s1,
                    double ix, double iy, double sigma)
{
    if (ws->pass_depth >= EX_MAX_PASS) {
        ex_pass_later(ws, hd, flip, L, s0, s1, ix, iy, sigma);
        return;
    }
    if (flip) {
        double t0 = L - s1;
        s1 = L - s0;
        s0 = t0;
        ix = L - ix;
    }
    const ex_face *r = ws->fr + hd / 3;
    int k = hd % 3;
    /* D's corners on the line, in hd's frame (v[k+1] at 0, v[k+2] at L) */
    double t[3];
    t[ex_next[k]] = 0.0;
    t[ex_prev[k]] = L;
    t[k] = r->cx[k];
    if (!isfinite(t[k]))
        return;
    ws->pass_face[ws->pass_depth++] = hd / 3;
    for (int j = 0; j < 3; j++) {
        if (j == k)
            continue;
        /* half-edge 3D + j runs from its corner v[j+1] to v[j+2] */
        double u0 = t[ex_next[j]], u1 = t[ex_prev[j]];
        double lo = fmax(s0, fmin(u0, u1)), hi = fmin(s1, fmax(u0, u1));
        if (!(hi > lo))
            continue;
        double dir = u1 >= u0 ? 1.0 : -1.0, a0 = (lo - u0) * dir, a1 = (hi - u0) * dir;
        ex_emit(ws, hd - k + j, fmin(a0, a1), fmax(a0, a1), (ix - u0) * dir, iy, sigma, 0);
    }
    ws->pass_depth--;
}

/* ex_emit_inline's last step: the window [s0, s1] of an edge va -> vb of
 * length L (pseudo-source (ix, iy), iy >= 0), queued to cross the face of
 * half-edge g (fl: g runs from vb to va), trimmed against the edge's
 * ends. */
MFMM_INLINE void ex_enqueue(mfmm_exact_ws *ws, int32_t g, int fl, int32_t va, int32_t vb,
                            double L, double s0, double s1, double ix, double iy, double sigma,
                            int tie_a, int tie_b)
{
    double iy2 = iy * iy;
#ifdef __GNUC__
    /* the face the window will cross, read when it is popped: after a
     * march has run through the mesh its record is far from the core */
    __builtin_prefetch((const char *)(ws->fr + g / 3));
    __builtin_prefetch((const char *)(ws->fr + g / 3) + 64);
#endif
    /* the least distance: at the foot of I, or at the nearer end. Taken
     * before the trims, which can only raise it: the key is then a lower
     * bound, as good for the queue's order and the cut at max_d, and taking
     * it again after a trim costs time for the same windows
     * (docs/performance.md#design-measurements) */
    double dx = ex_gap(ix, s0, s1);
    double key = sigma + (dx > 0.0 ? sqrt(dx * dx + iy2) : iy);
    if (key > ws->max_d)
        return;
    /* pruning against the ends of the edge */
    /* a tie with a path through an end that starts no windows keeps the
     * window (ex_trim); an end that does start them carries that path on */
    double da = ws->d[va], db = ws->d[vb];
    da += tie_a ? EX_TIE * da : 0.0;
    db += tie_b ? EX_TIE * db : 0.0;
    if (!ex_trim(ix, -iy, sigma, L, da, db, &s0, &s1))
        return;
    int32_t wi = ex_new(ws);
    if (wi < 0)
        return;
    ex_entry *w = ws->heap + wi;
    /* the edge as the face across sees it (selected, not branched on) */
    double e0[2] = {s0, L - s1}, e1[2] = {s1, L - s0}, ex[2] = {ix, L - ix};
    w->b0 = e0[fl];
    w->b1 = e1[fl];
    w->px = ex[fl];
    w->py = -iy;
    w->sigma = sigma;
    w->he = g;
    w->key = key;
    ex_queue(ws, wi);
    ws->n_windows++;
}

static void ex_fan_out(mfmm_exact_ws *ws, int32_t h, int32_t va, int32_t vb, double L,
                       double s0, double s1, double ix, double iy, double sigma);

/* A window on half-edge h = 3f+k in f's frame (I on f's side: iy >= 0),
 * interval [s0, s1], leaving f: updates the vertices it reaches, trims it
 * against the edge's ends, and queues it in the face across, in that face's
 * frame. known: its ends at a vertex whose distance through this window
 * is already set (bit 0: at s = 0, bit 1: at s = L; see ex_propagate).
 * Inlined where it is called (MFMM_INLINE): as a call it spilled the
 * window's doubles (docs/performance.md#design-measurements). */
MFMM_INLINE void ex_emit_inline(mfmm_exact_ws *ws, int32_t h, double s0, double s1, double ix,
                                double iy, double sigma, int known)
{
    const ex_face *r = ws->fr + h / 3;
    int k = h % 3;
    int k1 = ex_next[k], k2 = ex_prev[k];
    int32_t va = r->v[k1], vb = r->v[k2];
    double L = r->len[k];
    if (s0 < 0.0)
        s0 = 0.0;
    if (s1 > L)
        s1 = L;
    double iy2 = iy * iy;
    if (s0 <= EX_POS_TOL * L && !(known & 1)) {
        double ra = sqrt(ix * ix + iy2);
        if (ex_update(ws, va, sigma + ra, 0))
            ex_set_in(ws, va, h - k + k1, atan2(iy, ix), ra, L);
    }
    if (s1 >= L - EX_POS_TOL * L && !(known & 2)) {
        double rb = sqrt((ix - L) * (ix - L) + iy2);
        if (ex_update(ws, vb, sigma + rb, 0)) {
            int32_t c = h - k + k2;
            ex_set_in(ws, vb, c, ws->fr[c / 3].angle[c % 3] - atan2(iy, L - ix), rb, L);
        }
    }
    int32_t g = r->across[k];
    if (g < 0 || !(s1 - s0 > EX_MIN_WIDTH * L)) {
        if (g < -1 && s1 - s0 > EX_MIN_WIDTH * L)
            ex_pass(ws, -2 - g, r->flip[k], L, s0, s1, ix, iy, sigma);
        else if (r->flip[k] == 2 && s1 - s0 > EX_MIN_WIDTH * L)
            ex_fan_out(ws, h, va, vb, L, s0, s1, ix, iy, sigma);
        return;
    }
    ex_enqueue(ws, g, r->flip[k], va, vb, L, s0, s1, ix, iy, sigma, (r->tie >> k1) & 1,
               (r->tie >> k2) & 1);
}

/* A window on half-edge h (edge va -> vb, in h's face's frame) of a
 * non-manifold edge: it goes on into every other face on the edge, each
 * unfolded across the edge (ex_link_nonmanifold), trimmed against the
 * windows that went that way before (ex_dominate). */
static void ex_fan_out(mfmm_exact_ws *ws, int32_t h, int32_t va, int32_t vb, double L,
                       double s0, double s1, double ix, double iy, double sigma)
{
    /* (I on an end of the edge, within rounding: its rays run along the
     * edge, and carry nothing into the other faces; such windows went round
     * a folded fan without end) */
    double tol = EX_POS_TOL * L;
    if (ws->walls || (iy <= tol && (fabs(ix) <= tol || fabs(ix - L) <= tol)))
        return;
    int32_t i = ex_nm_find(ws->nm_he, ws->n_nm, h);
    for (int32_t n = 0; i >= 0 && n < ws->n_nm; n++) {
        int32_t g = ws->nm_next[i];
        if (g == h)
            return;
        i = ex_nm_find(ws->nm_he, ws->n_nm, g);
        const ex_face *q = ws->fr + g / 3;
        int fl = q->v[ex_next[g % 3]] != va;
        /* in g's frame (its ends swapped when it runs from vb to va) */
        double n0 = fl ? L - s1 : s0, n1 = fl ? L - s0 : s1, npx = fl ? L - ix : ix;
        if (q->skip == 1) {
            /* not into a face the window is passing through already: the
             * faces of a pass lie on one line, so that adds no path, and
             * zero-area faces meeting at such edges would pass a window
             * round among themselves */
            int in_pass = 0;
            for (int j = 0; j < ws->pass_depth; j++)
                in_pass |= ws->pass_face[j] == g / 3;
            /* trimmed against the windows kept there as into a face of
             * area (the pass goes on straight, in the same plane), so that
             * copies of one window reaching it by several passes do not
             * each go on */
            if (in_pass || i < 0 || !ex_dominate(ws, i, L, &n0, &n1, npx, -iy, sigma))
                continue;
            ex_keep(ws, i, n0, n1, npx, -iy, sigma);
            ex_pass(ws, g, fl, L, fl ? L - n1 : n0, fl ? L - n0 : n1, ix, iy, sigma);
            continue;
        }
        if (i < 0)
            return;
        if (!ex_dominate(ws, i, L, &n0, &n1, npx, -iy, sigma))
            continue;
        ex_keep(ws, i, n0, n1, npx, -iy, sigma);
        ex_enqueue(ws, g, fl, va, vb, L, fl ? L - n1 : n0, fl ? L - n0 : n1, ix, iy, sigma,
                   !ws->pseudo[va], !ws->pseudo[vb]);
    }
}

/* ex_emit_inline as a call, for the starts (ex_propagate inlines its own) */
static void ex_emit(mfmm_exact_ws *ws, int32_t h, double s0, double s1, double ix, double iy,
                    double sigma, int known)
{
    ex_emit_inline(ws, h, s0, s1, ix, iy, sigma, known);
}

void ex_propagate(mfmm_exact_ws *ws, const ex_entry *w)
{
    int32_t h = w->he;
    int32_t f = h / 3;
    int m = h % 3;
    const ex_face *r = ws->fr + f;
    int32_t vc = r->v[m];
    double L = r->len[m], cx = r->cx[m], cy = r->cy[m];
    double b0 = w->b0, b1 = w->b1, px = w->px, py = w->py, sigma = w->sigma;
    if (r->skip == 1) {
        /* a pass cut at EX_MAX_PASS, going on (ex_pass_later) */
        ex_pass(ws, h, 0, L, b0, b1, px, -py, sigma);
        return;
    }
    /* (the window is not checked again here, against the face it crosses
     * with the distances known by now: that drops almost nothing for its
     * cost, docs/performance.md#design-measurements) */
    ws->n_propagated++;
    /* where the ray from I through C crosses the edge */
    double tc = px + (cx - px) * (-py) / (cy - py);
    double tol = EX_POS_TOL * L;
    if (tc >= b0 - tol && tc <= b1 + tol) {
        double ex = cx - px, ey = cy - py;
        double rc = sqrt(ex * ex + ey * ey);
        if (ex_update(ws, vc, sigma + rc, 0)) {
            /* angle at C between C -> A = (-cx, -cy) and C -> I = (-ex, -ey) */
            double cr = cx * ey - cy * ex, dt = cx * ex + cy * ey;
            ex_set_in(ws, vc, h, atan2(fabs(cr), dt), rc, L);
        }
    } else if (tc >= b0 - EX_GRAZE * L && tc <= b1 + EX_GRAZE * L) {
        /* C just outside the window: the rays to it may have been in a
         * window dropped as too narrow, or missed by rounding (without this,
         * on a flat mesh whose straight paths graze vertices, C is left far
         * too long). The path
         * over the window's nearer end is a real one, within rounding of the
         * straight one. */
        double e = tc < b0 ? b0 : b1;
        double ie = sqrt((e - px) * (e - px) + py * py), ec = sqrt((cx - e) * (cx - e) + cy * cy);
        ex_update(ws, vc, sigma + ie + ec, 0);
    }
    int m1 = ex_next[m], m2 = ex_prev[m];
    if (b0 < tc) {
        /* left child: edge C -> A (half-edge 3f+m2), rays through [b0, min(b1, tc)] */
        int32_t hl = 3 * f + m2;
        ex_child c = ex_child_left(r, m);
        double s_hi = b0 <= 0.0 ? c.len : ex_child_hit(&c, px, py, b0);
        double s_lo = tc <= b1 ? 0.0 : ex_child_hit(&c, px, py, b1);
        double ix, iy;
        ex_child_source(&c, px, py, &ix, &iy);
        /* its end at C when the window holds C (C updated above), at A
         * when the window starts at A (A updated where it was emitted):
         * the same distance again, in another frame */
        ex_emit_inline(ws, hl, s_lo, s_hi, ix, iy, sigma, (tc <= b1) | (b0 <= 0.0) << 1);
    }
    if (b1 > tc) {
        /* right child: edge B -> C (half-edge 3f+m1), rays through [max(b0, tc), b1] */
        int32_t hr = 3 * f + m1;
        ex_child c = ex_child_right(r, m);
        double s_lo = b1 >= L ? 0.0 : ex_child_hit(&c, px, py, b1);
        double s_hi = tc >= b0 ? c.len : ex_child_hit(&c, px, py, b0);
        double ix, iy;
        ex_child_source(&c, px, py, &ix, &iy);
        /* (likewise at B and at C) */
        ex_emit_inline(ws, hr, s_lo, s_hi, ix, iy, sigma, (b1 >= L) | (tc >= b0) << 1);
    }
}

/* Where the ray from C = (cx, cy) at angle psi from C -> (0,0), turning
 * towards (L, 0), meets the x axis, clamped to [0, L]. */
static double ex_ray_x(double cx, double cy, double psi, double L)
{
    double r = sqrt(cx * cx + cy * cy);
    double ux = -cx / r, uy = -cy / r, c = cos(psi), sn = sin(psi);
    double dx = ux * c - uy * sn, dy = ux * sn + uy * c;
    if (!(dy < 0.0))
        return dx < 0.0 ? 0.0 : L;
    double x = cx + (-cy / dy) * dx;
    return x < 0.0 ? 0.0 : x > L ? L : x;
}

/* A pseudo-source at v with distance dv: a window on the far edge of every
 * face around v. */
void ex_start_vertex(mfmm_exact_ws *ws, int32_t v, double dv)
{
    ws->n_pseudo++;
    double th = ws->in_angle[v], total = ws->fan_total[v];
    if (!(th == th) || !(total == total)) {
        for (int32_t i = ws->vf_offset[v]; i < ws->vf_offset[v + 1]; i++) {
            int32_t c = ex_corner(ws->vf_corner, ws->face_in, i);
            const ex_face *r = ws->fr + c / 3;
            if (r->skip == 1) {
                /* a zero-area face's edges from v: real paths (an
                 * all-degenerate strip reached nothing) */
                int k = c % 3;
                ex_update(ws, r->v[ex_next[k]], dv + r->len[ex_prev[k]], 0);
                ex_update(ws, r->v[ex_prev[k]], dv + r->len[ex_next[k]], 0);
                /* v on the opposite edge (a needle's middle): v lies on the
                 * edge of the face across it, and starts windows there */
                if (r->cx[k] >= 0.0 && r->cx[k] <= r->len[k])
                    ex_emit(ws, c, 0.0, r->len[k], r->cx[k], 0.0, dv, 0);
            }
            if (r->skip)
                continue;
            ex_emit(ws, c, 0.0, r->len[c % 3], r->cx[c % 3], r->cy[c % 3], dv, 0);
        }
        return;
    }
    /* A shortest path that arrived from direction th can go on through v
     * only where both angles it makes there are >= pi (else cutting the
     * corner is shorter): the "shadow" [th + pi, th + total - pi], modulo
     * total. Elsewhere the windows passing v already carry the distance. */
    double lo = th + EX_PI - EX_SHADOW_MARGIN, hi = th + total - EX_PI + EX_SHADOW_MARGIN;
    if (!(hi > lo))
        return;
    for (int32_t i = ws->vf_offset[v]; i < ws->vf_offset[v + 1]; i++) {
        int32_t c = ex_corner(ws->vf_corner, ws->face_in, i);
        if (ws->fr[c / 3].skip) /* a copy: the fan holds no zero-area face */
            continue;
        double ang = ws->fr[c / 3].angle[c % 3];
        double f0 = ws->fr[c / 3].sgn[c % 3] > 0 ? ws->fan_a0[c] : ws->fan_a0[c] - ang, f1 = f0 + ang;
        for (int wrap = -1; wrap <= 1; wrap++) {
            double a = lo + wrap * total, b = hi + wrap * total;
            if (a < f0)
                a = f0;
            if (b > f1)
                b = f1;
            if (!(b > a))
                continue;
            /* psi: angles from the direction to the corner's first vertex */
            double p0, p1;
            if (ws->fr[c / 3].sgn[c % 3] > 0) {
                p0 = a - f0;
                p1 = b - f0;
            } else {
                p0 = f1 - b;
                p1 = f1 - a;
            }
            const ex_face *r = ws->fr + c / 3;
            double L = r->len[c % 3], cx = r->cx[c % 3], cy = r->cy[c % 3];
            double s0 = p0 <= 0.0 ? 0.0 : ex_ray_x(cx, cy, p0, L);
            double s1 = p1 >= ang ? L : ex_ray_x(cx, cy, p1, L);
            ex_emit(ws, c, s0, s1, cx, cy, dv, 0);
        }
    }
}

/* A point source in face f (barycentric w, not at a corner): a window on
 * each of f's edges. */
void ex_start_face(mfmm_exact_ws *ws, int32_t f, const double *w, double value)
{
    ws->n_pseudo++;
    for (int k = 0; k < 3; k++) {
        int32_t h = 3 * f + k;
        /* corners k+1 at (0,0), k+2 at (L,0), k at (cx,cy) */
        const ex_face *r = ws->fr + f;
        double ix = w[(k + 2) % 3] * r->len[k] + w[k] * r->cx[k];
        double iy = w[k] * r->cy[k];
        ex_emit(ws, h, 0.0, r->len[k], ix, iy, value, 0);
    }
}
