/*
 * The local update of the Fast Marching Method on triangles (Kimmel &
 * Sethian 1998, section 4), written once for the C core and the OpenCL
 * kernel: both include this file, so their rows cannot drift apart.
 *
 * OpenCL C 1.2 and C99. Compile without floating-point contraction
 * (-ffp-contract=off; OpenCL: no -cl-mad-enable, FP_CONTRACT OFF) so that both
 * paths round identically.
 */
#ifndef MFMM_LOCAL_UPDATE_H
#define MFMM_LOCAL_UPDATE_H

#ifdef __OPENCL_VERSION__
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#pragma OPENCL FP_CONTRACT OFF
#define MFMM_GLOBAL __global
#define MFMM_INLINE inline __attribute__((always_inline)) /* PoCL makes calls of plain inline */
#define MFMM_COLD MFMM_INLINE
#define MFMM_INF ((double)INFINITY)
typedef int mfmm_i32;
typedef uint mfmm_u32;
typedef uchar mfmm_u8;
#else
#include <math.h>
#include <stdint.h>
#define MFMM_GLOBAL
#if defined(__GNUC__) || defined(__clang__)
/* the march's per-face steps are called from two places, and GCC would
 * leave them as calls that spill the march's registers */
#define MFMM_INLINE static inline __attribute__((always_inline))
/* a march step off the common path (a cost, a virtual stencil): kept out
 * of line so that the common path keeps its values in registers */
#define MFMM_COLD static __attribute__((noinline))
#else
#define MFMM_INLINE static inline
#define MFMM_COLD static inline
#endif
#define MFMM_INF ((double)INFINITY)
typedef int32_t mfmm_i32;
typedef uint32_t mfmm_u32;
typedef uint8_t mfmm_u8;
#endif

/* A corner is obtuse (section 4.2) when cos theta is below this. */
#define MFMM_OBTUSE_COS (-1e-9)

/* One face as the march reads it: its vertices, the length of the edge
 * opposite each corner and the cosine of each corner's angle (section 4.1),
 * and its obtuse corner's virtual edge (section 4.2), if it has one. When a
 * vertex x settles the march walks x's faces (march.h): in face (x, y, c)
 * every length and angle that updating c from x (and y) needs is in this
 * one record. 64 bytes, one cache line, C and OpenCL C. cosv is NaN on a
 * zero-area face (no triangle update: Eq. 4 then yields +inf, at no cost). */
typedef struct mfmm_face {
    mfmm_i32 v[3];   /* internal vertex ids */
    mfmm_i32 virt;   /* its obtuse corner k's virtual edge: 4 V + k; 3: none */
    double len[3];   /* len[k]: the edge opposite corner k */
    double cosv[3];  /* cos of the angle at corner k (NaN: zero area) */
} mfmm_face;

/* The virtual edge C -> V of an obtuse corner (section 4.2): the corner
 * 3 f + k it splits, its vertex C, |CV| in the unfolded plane and the
 * cosines of the two angles it splits theta into (A-C-V and V-C-B, A and B
 * the face's vertices after C). Stored sorted by V (the march offers these
 * when V settles; the face names V). 32 bytes, C and OpenCL C. */
typedef struct mfmm_virt {
    mfmm_i32 corner;
    mfmm_i32 c;      /* the corner's vertex C */
    double len;   /* |CV| */
    double cos_a; /* cos of angle A-C-V */
    double cos_b; /* cos of angle V-C-B */
} mfmm_virt;

/* A spoke: what vertex x's settling offers one neighbour c at F = 1 with
 * unfolding (march.h, the spoke walk; built by src/mesh/spokes.c): |xc| and
 * the (up to) two triangles through x that update c, each with its third
 * vertex y, |yc| and the cosine at c, oriented for mfmm_triangle_interior
 * (bit s of x_is_a: x is the triangle's A, so a = |yc| and b = |xc|).
 * Where c's obtuse corner has a virtual edge (section 4.2) y is its V, with
 * the virtual edge's length and cosine. A missing triangle names y = c,
 * which is never Alive when c is updated. x's spokes: first one per virtual
 * edge that ends at x (c its corner, y its A and B), then x's neighbours in
 * fan order, a face's q and the next face's p in one spoke, the first
 * face's p last (around a closed fan, with the last face's q). 56 bytes, C
 * and OpenCL C; one per neighbour and per virtual edge (6.4-7 per vertex). */
typedef struct mfmm_spoke {
    mfmm_i32 c;
    mfmm_i32 y[2];
    mfmm_u32 x_is_a;
    double len;   /* |xc| */
    double ly[2]; /* |yc| */
    double cs[2]; /* cos of the angle at c */
} mfmm_spoke;

/* An entry of a vertex's face list (mfmm_march_mesh.wedge): face f where
 * the vertex is corner k, packed as 16 f + 4 ((k + 2) mod 3) + (k + 1) mod 3,
 * so that the march reads the face and the corners after k by shifts and
 * masks rather than a division and two table lookups
 * (docs/march-measurements.md). Hence at most MFMM_MAX_FACES faces. */
#define MFMM_MAX_FACES (0x7fffffff / 16)
#define MFMM_WEDGE(f, k) (16 * (f) + 4 * (((k) + 2) % 3) + ((k) + 1) % 3)
#define MFMM_WEDGE_FACE(w) ((mfmm_i32)((mfmm_u32)(w) >> 4))
#define MFMM_WEDGE_NEXT(w) ((w) & 3)        /* k + 1 mod 3 */
#define MFMM_WEDGE_PREV(w) (((w) >> 2) & 3) /* k + 2 mod 3 */
#define MFMM_WEDGE_K(w) (3 - MFMM_WEDGE_NEXT(w) - MFMM_WEDGE_PREV(w))
#define MFMM_WEDGE_CORNER(w) (3 * MFMM_WEDGE_FACE(w) + MFMM_WEDGE_K(w))

/* Vertex labels of section 2 (Far, Close, Alive), plus a flag for targets. */
#define MFMM_FAR 0
#define MFMM_CLOSE 1
#define MFMM_ALIVE 2
#define MFMM_STATE_MASK 3
#define MFMM_TARGET 4
#define MFMM_FIXED 8 /* a seed whose value is exact (the exact start): never lowered */

/* A hint to fetch memory early (the march is bound by cache misses); a
 * no-op where the compiler has no such builtin. PoCL compiles with clang. */
#if defined(__GNUC__) || defined(__clang__)
#define MFMM_PREFETCH(p) __builtin_prefetch(p)
#else
#define MFMM_PREFETCH(p) ((void)0)
#endif

/* min without libm's NaN rules (no NaN reaches here), so it inlines */
MFMM_INLINE double mfmm_min(double x, double y)
{
    return x < y ? x : y;
}

/* T(C) through the inside of triangle ABC, with T(A) = ta, T(B) = tb both
 * known; a = |BC|, b = |AC|, cos_c = cos theta at C; f = cost F. +inf when
 * the update does not come from within the triangle.
 * Eq. 4 gives t = T(C) - T(A) with u = T(B) - T(A) >= 0 (A the smaller); its
 * larger root, with c^2 = a^2 + b^2 - 2ab cos theta (= |AB|^2), is
 *   t = [b u (b - a cos theta) + a b sin theta sqrt(F^2 c^2 - u^2)] / c^2
 * (the discriminant of Eq. 4 is 4 a^2 b^2 sin^2 theta (F^2 c^2 - u^2)). No
 * power of a length above 2 appears, so nothing overflows or underflows
 * for lengths within 1e-100..1e100. It is accepted when u < t and the update
 * comes from within the triangle, Eq. 5: a cos theta < b(t-u)/t <
 * a / cos theta. That test is used multiplied through by cos theta (a cos
 * theta < x and x cos theta < a, x = b(t-u)/t), which is Eq. 5 for acute
 * theta and stays meaningful for obtuse theta (where the literal form
 * rejects everything).
 * Eq. 5 read before the root: the front crosses AB at angle phi with
 * u = F c cos phi, and its ray reaches C from inside AB iff phi lies between
 * the angles at A and at pi - the angle at B, i.e. (with c cos A = b - a cos
 * theta, c cos B = a - b cos theta)
 *   F (b cos theta - a) < u < F (b - a cos theta).
 * Outside these bounds, widened by 1e-8 (a + b), the update is +inf without
 * its division and two square roots, and its branch is taken before them;
 * inside them the test above decides. So the local update (with its edges)
 * is the same bit for bit (test_local_update), and most triangles are
 * rejected before the root (docs/march-measurements.md). (Alone, the test
 * after the root accepts some
 * u > F c on slivers, where no root exists, at values above the edge
 * update; where rounding would put a needle on the other side of a bound,
 * the update is within 1e-8 of the edge update it borders.) */
MFMM_INLINE double mfmm_triangle_interior(double ta, double tb, double a, double b,
                                          double cos_c, double f)
{
    /* let A be the vertex reached first: selects, not a branch (which of
     * the two is first is as good as random) */
    int swap = ta > tb;
    double t0 = swap ? tb : ta, u = swap ? ta - tb : tb - ta;
    double la = swap ? b : a, lb = swap ? a : b;
    /* Eq. 5's bounds on u (one branch; a zero-area face's NaN cosine fails
     * them) */
    double slack = 1e-8 * (la + lb);
    if (!(u < f * (lb - la * cos_c + slack)) | !(u > f * (lb * cos_c - la - slack)))
        return MFMM_INF;
    double c2 = a * a + b * b - 2.0 * a * b * cos_c;
    if (!(c2 > 0.0))
        return MFMM_INF;
    double inv = 1.0 / c2;
    double beta = a * b * sqrt((1.0 - cos_c) * (1.0 + cos_c)) * inv;
    double alpha_a = b * (b - a * cos_c) * inv, alpha_b = a * (a - b * cos_c) * inv;
    double fc2 = f * f * c2;
    double alpha = swap ? alpha_b : alpha_a;
    /* (b = 0 makes alpha = beta = 0, so t = 0 <= u: rejected below) */
    double d = fc2 - u * u;
    d = d > 0.0 ? d : 0.0; /* u > F c (within the bounds' slack): no root */
    double t = alpha * u + beta * sqrt(d);
    if (!(t > u)) /* also rejects NaN */
        return MFMM_INF;
    /* the test with x = CD = b (t - u) / t of section 4.1, multiplied by t > 0 */
    double xt = lb * (t - u);
    if (la * cos_c * t < xt && xt * cos_c < la * t)
        return t0 + t;
    return MFMM_INF;
}

/* The full local update of section 4.1 with one cost f: the inside of the
 * triangle when Eq. 5 accepts it, else the edge updates
 * min(T(A) + bF, T(B) + aF) (the paper prints cF, but BC has length a). */
MFMM_INLINE double mfmm_triangle_update(double ta, double tb, double a, double b,
                                        double cos_c, double f)
{
    double edge = mfmm_min(ta + b * f, tb + a * f);
    return mfmm_min(mfmm_triangle_interior(ta, tb, a, b, cos_c, f), edge);
}

#endif /* MFMM_LOCAL_UPDATE_H */
