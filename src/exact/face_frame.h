/* A face in the frames of its three half-edges, and the steps of a window
 * across it: shared by the exact solver (C only) and the window method,
 * whose OpenCL kernel (kernels/windows_rows.cl) includes this file, so the
 * two paths compute the same bits. OpenCL C 1.2 and C99, compiled without
 * floating-point contraction (march/local_update.h). */
#ifndef MFMM_EXACT_FACE_FRAME_H
#define MFMM_EXACT_FACE_FRAME_H

#include "march/local_update.h"

#ifdef __OPENCL_VERSION__
typedef char mfmm_i8;
#define MFMM_CONSTANT_TABLE __constant char
#else
typedef int8_t mfmm_i8;
#define MFMM_CONSTANT_TABLE static const int8_t
#endif

/* distances equal to this relative amount are ties */
#define EX_TIE 1e-12
/* a window narrower than this fraction of its edge is dropped */
#define EX_MIN_WIDTH 1e-13
/* a point of an edge this close (relative) to a window's end is in it */
#define EX_POS_TOL 1e-12
/* a face's edge shorter than this times the edge a window enters by gets
 * its direction normalised by the length of its own vector in that frame
 * (ex_propagate): its corners are placed to rounding of the longer edge, so
 * the table's length would scale the frame, and every distance in it */
#define EX_SHORT_CHILD 1e-3

/* k + 1 and k - 1 modulo 3, looked up: with k of a random window, a
 * comparison there is a branch mispredicted about half the time */
MFMM_CONSTANT_TABLE ex_next[3] = {1, 2, 0}, ex_prev[3] = {2, 0, 1};

/* A face: for each corner k, the edge opposite it (half-edge 3f+k, from
 * corner k+1 to k+2): its length, corner k in its frame (x along the edge,
 * y > 0), and the same edge in the face across it (3g+m, -1 at a wall) with
 * whether it runs the other way there; the corners' vertices and angles;
 * whether it is skipped (1: zero area, its vertices pseudo-sources; 2: a
 * copy of another face, mfmm_mesh_copy, no part of the surface). 128 bytes,
 * aligned to cache lines. */
typedef struct ex_face {
    double len[3], cx[3], cy[3];
    double angle[3]; /* the corners' angles */
    mfmm_i32 v[3], across[3];
    mfmm_u8 flip[3], skip;
    mfmm_i8 sgn[3];   /* the corners' fan_sgn (see mfmm_exact_tables) */
    mfmm_u8 tie;     /* bit k: corner k starts no windows, so a window tied with a
                        path through it is kept (ex_enqueue) */
} ex_face;

/* Entry i of the vertex -> face CSR, as corner 3 * record + k. */
MFMM_INLINE mfmm_i32 ex_corner(MFMM_GLOBAL const mfmm_i32 *vf_corner, MFMM_GLOBAL const mfmm_i32 *face_in, mfmm_i32 i)
{
    mfmm_i32 w = vf_corner[i];
    return 3 * face_in[MFMM_WEDGE_FACE(w)] + MFMM_WEDGE_K(w);
}

/* The slot of half-edge h in the sorted non-manifold half-edges nm_he
 * (n_nm of them), -1 where it is on no non-manifold edge. */
MFMM_INLINE mfmm_i32 ex_nm_find(MFMM_GLOBAL const mfmm_i32 *nm_he, mfmm_i32 n_nm, mfmm_i32 h)
{
    mfmm_i32 lo = 0, hi = n_nm - 1;
    while (lo < hi) {
        mfmm_i32 mid = lo + (hi - lo) / 2;
        if (nm_he[mid] < h)
            lo = mid + 1;
        else
            hi = mid;
    }
    return n_nm > 0 && nm_he[lo] == h ? lo : -1;
}

/* Trims the interval [*b0, *b1] of an edge of length L (in the frame where
 * its pseudo-source is (px, py) at distance sigma) to the part where it is
 * shorter than the paths through the edge's ends, with distances dA (at 0)
 * and dB (at L). sigma + |I X| - (dA + t) does not increase with t, so the
 * part beaten by A is [0, t*), t* the root of
 * sigma + sqrt((t - px)^2 + py^2) = dA + t; likewise from B. The caller
 * raises dA by EX_TIE where A starts no windows (a flat vertex): where I, A
 * and the edge are almost on one line the two sides are equal to rounding,
 * and a window trimmed there left what lay behind A unreached (+inf, or
 * longer than a path along the edges). Not where A starts windows: those
 * carry the path on, and windows kept at ties there went round coincident
 * vertices without end. Returns 0 when too little is left. Without branches (an end not reached yet, d = +inf,
 * gives inf / inf = NaN, which moves nothing): whether an end moves is data
 * the branch predictor cannot guess. */
MFMM_INLINE int ex_trim(double px, double py, double sigma, double L, double dA,
                          double dB, double *b0, double *b1)
{
    double py2 = py * py;
    double a = dA - sigma, qx = L - px, c = dB - sigma;
    int ok = !(px + a <= 0.0) & !(qx + c <= 0.0);
    double t0 = (px * px + py2 - a * a) / (2.0 * (px + a));
    double t1 = L - (qx * qx + py2 - c * c) / (2.0 * (qx + c));
    double s0 = t0 > *b0 ? t0 : *b0, s1 = t1 < *b1 ? t1 : *b1;
    *b0 = s0;
    *b1 = s1;
    return ok & (s1 - s0 > EX_MIN_WIDTH * L);
}

/* Where the line from I through X = (x, 0) meets the line O + s u (s). */
MFMM_INLINE double ex_hit(double ox, double oy, double ux, double uy, double ix,
                            double iy, double x, double len)
{
    double xx = x - ox, xy = -oy, jx = ix - ox, jy = iy - oy;
    double num = xx * jy - xy * jx;
    double den = (xx - jx) * uy - (xy - jy) * ux;
    double s = num / den;
    if (!(s >= 0.0))
        s = 0.0;
    if (!(s <= len))
        s = len;
    return s;
}

/* A child edge of a window crossing a face through half-edge m (the
 * exact solver's ex_propagate and the window method's sl_cross): the edge
 * C -> A (left, half-edge 3f + ex_prev[m]) or B -> C (right, 3f + ex_next[m])
 * as the line O + s u, s in [0, len], in m's frame (A at 0, B at (L, 0),
 * C at (cx, cy)). A child shorter than EX_SHORT_CHILD of L takes its
 * direction from the corners' positions, not its own length. */
typedef struct ex_child {
    double ox, oy, ux, uy, len;
} ex_child;

MFMM_INLINE ex_child ex_child_left(MFMM_GLOBAL const ex_face *r, int m)
{
    double cx = r->cx[m], cy = r->cy[m], lac = r->len[ex_prev[m]];
    double il = 1.0 / (lac < EX_SHORT_CHILD * r->len[m] ? sqrt(cx * cx + cy * cy) : lac);
    ex_child c = {cx, cy, -cx * il, -cy * il, lac};
    return c;
}

MFMM_INLINE ex_child ex_child_right(MFMM_GLOBAL const ex_face *r, int m)
{
    double cx = r->cx[m], cy = r->cy[m], L = r->len[m], lbc = r->len[ex_next[m]];
    double il = 1.0 / (lbc < EX_SHORT_CHILD * L ? sqrt((cx - L) * (cx - L) + cy * cy) : lbc);
    ex_child c = {L, 0.0, (cx - L) * il, cy * il, lbc};
    return c;
}

/* Where the ray from (px, py) through (x, 0) crosses the child edge (ex_hit) */
MFMM_INLINE double ex_child_hit(const ex_child *c, double px, double py, double x)
{
    return ex_hit(c->ox, c->oy, c->ux, c->uy, px, py, x, c->len);
}

/* The pseudo-source (px, py) in the child edge's frame: (*ix, *iy), *iy
 * clamped to >= 0 (the side of the face it leaves) */
MFMM_INLINE void ex_child_source(const ex_child *c, double px, double py, double *ix,
                                   double *iy)
{
    double qx = px - c->ox, qy = py - c->oy;
    double y = c->ux * qy - c->uy * qx;
    *ix = qx * c->ux + qy * c->uy;
    *iy = y > 0.0 ? y : 0.0;
}

#endif
