/* Windows at non-manifold edges: a window fanned out into the other faces
 * on such an edge (propagate.c, ex_fan_out) is kept, per face entered, and
 * trims the windows that enter that face there later (nonmanifold.h); so
 * is a window queued where a pass was cut (ex_pass_later), per zero-area
 * half-edge. */
#include <math.h>
#include <stdlib.h>

#include "nonmanifold.h"
#include "queue.h"

/* The head of slot's list in rec: a non-manifold half-edge's (slot >= 0)
 * or a cut pass's (-2 - j, ex_pass_slot). */
static int32_t *ex_head(const mfmm_exact_ws *ws, int32_t slot)
{
    return slot >= 0 ? ws->nm_head + slot : ws->pass_slot + 2 * (-2 - slot) + 1;
}

/* A half-edge's bucket in pass_hash (mask: its size - 1). */
static uint32_t ex_pass_bucket(int32_t h, int32_t mask)
{
    return ((uint32_t)h * 2654435761u) & (uint32_t)mask;
}

/* Doubles the cut passes' slots, within memory_limit: 0 when they cannot
 * grow. */
static int ex_pass_grow(mfmm_exact_ws *ws)
{
    int32_t cap = ws->pass_cap;
    if (cap >= INT32_MAX / 4)
        return 0;
    int32_t ncap = cap ? 2 * cap : 16;
    size_t more = (size_t)(ncap - cap) * 4 * sizeof(int32_t);
    if (ws->memory_limit && ex_bytes(ws, ws->heap_cap) + more > ws->memory_limit)
        return 0;
    int32_t *slot = realloc(ws->pass_slot, 2 * (size_t)ncap * sizeof *slot);
    if (!slot)
        return 0;
    ws->pass_slot = slot;
    int32_t *hash = malloc(2 * (size_t)ncap * sizeof *hash);
    if (!hash)
        return 0;
    free(ws->pass_hash);
    ws->pass_hash = hash;
    ws->pass_cap = ncap;
    int32_t mask = 2 * ncap - 1;
    for (int32_t i = 0; i <= mask; i++)
        hash[i] = -1;
    for (int32_t j = 0; j < ws->pass_n; j++) {
        uint32_t b = ex_pass_bucket(slot[2 * j], mask);
        while (hash[b] >= 0)
            b = (b + 1) & (uint32_t)mask;
        hash[b] = j;
    }
    if (ex_bytes(ws, ws->heap_cap) > ws->peak_bytes)
        ws->peak_bytes = ex_bytes(ws, ws->heap_cap);
    return 1;
}

int32_t ex_pass_slot(mfmm_exact_ws *ws, int32_t h)
{
    int32_t mask = 2 * ws->pass_cap - 1;
    if (ws->pass_cap > 0)
        for (uint32_t b = ex_pass_bucket(h, mask); ws->pass_hash[b] >= 0;
             b = (b + 1) & (uint32_t)mask)
            if (ws->pass_slot[2 * ws->pass_hash[b]] == h)
                return -2 - ws->pass_hash[b];
    if (ws->pass_n == ws->pass_cap && !ex_pass_grow(ws))
        return -1;
    mask = 2 * ws->pass_cap - 1;
    uint32_t b = ex_pass_bucket(h, mask);
    while (ws->pass_hash[b] >= 0)
        b = (b + 1) & (uint32_t)mask;
    int32_t j = ws->pass_n++;
    ws->pass_slot[2 * j] = h;
    ws->pass_slot[2 * j + 1] = -1;
    ws->pass_hash[b] = j;
    return -2 - j;
}

void ex_pass_reset(mfmm_exact_ws *ws)
{
    if (ws->pass_n == 0)
        return;
    for (int32_t i = 0; i < 2 * ws->pass_cap; i++)
        ws->pass_hash[i] = -1;
    ws->pass_n = 0;
}

/* D(x) - D'(x) of two windows on one edge, in units of the edge */
static double ex_diff(double x, double px, double py, double dsig, double pa, double qa)
{
    return dsig + sqrt((x - px) * (x - px) + py * py) - sqrt((x - pa) * (x - pa) + qa * qa);
}

/* Trims the window [*s0, *s1] (pseudo-source (px, py), sigma; the frame of
 * a half-edge of length L) against the windows kept at that half-edge's
 * slot: the part where a kept window gives no more is dropped, as MMP does
 * with the windows of an edge (Surazhsky et al. 2005, section 3.3), here
 * only from the ends, so that it stays one interval. Sound in any order:
 * kept windows are never removed, and a kept window trimmed later against
 * a vertex is beaten there by a path through that vertex. Returns 0 when
 * nothing is left. Without it, folded fans of 5-8 faces on one edge passed
 * windows round without bound (fuzz input nonmanifold-fans-window-blowup). */
int ex_dominate(const mfmm_exact_ws *ws, int32_t slot, double L, double *s0p,
                       double *s1p, double px, double py, double sigma)
{
    double il = 1.0 / L, s0 = *s0p * il, s1 = *s1p * il;
    double pw = px * il, qw = py * il;
    if (fabs(qw) <= EX_POS_TOL) {
        /* I on the edge (a needle's middle vertex, ex_start_vertex): its
         * rays leave from I and cross the edge nowhere else, so [s0, s1]
         * holds directions, not points, and cutting it point by point drops
         * rays that no kept window carries (a fuzzed mesh's needle lost the
         * half of its fan that gave d(20) 4.24, not 4.41). Nor may a kept
         * window that reaches I as soon drop it: the paths that bend at I
         * are this window's alone. It goes only when it is a kept one come
         * round again (alike to rounding, as below) over no more than that
         * one's interval, whose directions alone are carried already. */
        for (int32_t i = *ex_head(ws, slot); i >= 0; i = ws->rec[i].next) {
            const ex_rec *a = ws->rec + i;
            double ds = (sigma - a->sigma) * il, pa = a->px * il, qa = a->py * il;
            if (fabs(ds) + fabs(pw - pa) + fabs(qw - qa) <=
                    EX_TIE * (1.0 + fabs(sigma * il) + fabs(pw) + fabs(qw)) &&
                a->b0 * il <= s0 + EX_POS_TOL && a->b1 * il >= s1 - EX_POS_TOL)
                return 0;
        }
        return 1;
    }
    for (int32_t i = *ex_head(ws, slot); i >= 0; i = ws->rec[i].next) {
        const ex_rec *a = ws->rec + i;
        double a0 = a->b0 * il, a1 = a->b1 * il;
        int left = a0 <= s0, right = a1 >= s1;
        if (!left && !right)
            continue; /* inside the new window: its ends stay */
        double lo = left ? s0 : a0, hi = right ? s1 : a1;
        if (!(hi > lo))
            continue;
        double pa = a->px * il, qa = a->py * il, ds = (sigma - a->sigma) * il;
        double k0 = INFINITY, k1 = -INFINITY;
        /* |D - D_a| <= |ds| + |pw - pa| + |qw - qa| everywhere: windows
         * alike to rounding (the same window come round a fan of folded
         * faces, which otherwise went round without end) are ties, and the
         * kept one stays */
        if (fabs(ds) + fabs(pw - pa) + fabs(qw - qa) <=
            EX_TIE * (1.0 + fabs(sigma * il) + fabs(pw) + fabs(qw)))
            goto trim;
        /* D = D_a squared twice: a quadratic whose roots hold the zeros of
         * D - D_a, which keeps its sign between them */
        double al = 2.0 * (pw - pa), be = pa * pa - pw * pw + qa * qa - qw * qw + ds * ds;
        double d4 = 4.0 * ds * ds;
        double A = d4 - al * al, B = -2.0 * (d4 * pa + al * be);
        double C = d4 * (pa * pa + qa * qa) - be * be;
        double r[2];
        int nr = 0;
        double disc = B * B - 4.0 * A * C;
        if (A != 0.0 && disc >= 0.0) {
            double q = -0.5 * (B + (B >= 0.0 ? sqrt(disc) : -sqrt(disc)));
            r[nr++] = q / A;
            if (q != 0.0)
                r[nr++] = C / q;
        } else if (A != 0.0) {
            /* equal sigmas make the quadratic a line squared (the
             * bisector of the two pseudo-sources), whose double root
             * rounding can leave complex: its vertex is taken as a root,
             * harmless where there is none, as the signs are tested
             * between the splits below */
            r[nr++] = -B / (2.0 * A);
        } else if (B != 0.0) {
            r[nr++] = -C / B;
        }
        double x[4];
        int n = 0;
        x[n++] = lo;
        for (int j = 0; j < nr; j++) {
            /* Newton on D - D_a itself: the squared form loses digits when
             * the two windows are alike */
            double t = r[j];
            for (int it = 0; it < 2; it++) {
                double rw = sqrt((t - pw) * (t - pw) + qw * qw);
                double ra = sqrt((t - pa) * (t - pa) + qa * qa);
                double tn = t - (ds + rw - ra) / ((t - pw) / rw - (t - pa) / ra);
                if (!(fabs(tn - t) < 1.0))
                    break;
                t = tn;
            }
            if (t > lo && t < hi) {
                if (n == 2 && t < x[1]) {
                    x[2] = x[1];
                    x[1] = t;
                    n = 3;
                } else {
                    x[n++] = t;
                }
            }
        }
        x[n++] = hi;
        /* the hull of the part of [lo, hi] where the new window is shorter */
        for (int j = 0; j + 1 < n; j++) {
            if (!(ex_diff(0.5 * (x[j] + x[j + 1]), pw, qw, ds, pa, qa) >= 0.0)) {
                if (k0 > x[j])
                    k0 = x[j];
                k1 = x[j + 1];
            }
        }
    trim:
        if (left && right) {
            if (!(k1 >= k0))
                return 0;
            s0 = k0;
            s1 = k1;
        } else if (left) {
            s0 = k1 >= k0 ? k0 : hi;
        } else {
            s1 = k1 >= k0 ? k1 : lo;
        }
        if (!(s1 - s0 > EX_MIN_WIDTH))
            return 0;
    }
    *s0p = s0 * L;
    *s1p = s1 * L;
    return 1;
}

/* Keeps a fanned-out window (or one queued from a cut pass) at its slot
 * for ex_dominate, while memory allows (one not kept only trims nothing). */
void ex_keep(mfmm_exact_ws *ws, int32_t slot, double b0, double b1, double px, double py,
             double sigma)
{
    if (ws->rec_n == ws->rec_cap) {
        int32_t cap = ws->rec_cap;
        if (cap >= INT32_MAX / 2)
            return;
        int32_t ncap = cap ? 2 * cap : 256;
        if (ws->memory_limit &&
            ex_bytes(ws, ws->heap_cap) + (size_t)(ncap - cap) * sizeof(ex_rec) > ws->memory_limit)
            return;
        ex_rec *p = realloc(ws->rec, (size_t)ncap * sizeof *p);
        if (!p)
            return;
        ws->rec = p;
        ws->rec_cap = ncap;
        if (ex_bytes(ws, ws->heap_cap) > ws->peak_bytes)
            ws->peak_bytes = ex_bytes(ws, ws->heap_cap);
    }
    ex_rec *r = ws->rec + ws->rec_n;
    r->b0 = b0;
    r->b1 = b1;
    r->px = px;
    r->py = py;
    r->sigma = sigma;
    r->slot = slot;
    r->next = *ex_head(ws, slot);
    *ex_head(ws, slot) = ws->rec_n++;
}

