/* libFuzzer harness: the exact solver (mfmm_solve_exact, the patch of the
 * exact start) and the march from the exact start, on small meshes decoded
 * from the input. Properties checked (abort on a break): no NaN, no negative
 * distance; a vertex source at its value; the patch
 * (mfmm_exact_patch) equal to the full solve within its radius (at most
 * it where the full solve fell back to walls at non-manifold edges); the march
 * from the exact start without NaN or negative values.
 *
 * Bounds on every vertex, for the exact solve and for the march (each source
 * k a 3D point p_k with its value t_k; tests/python/oracles.py checks the
 * same on random flat, slit and book meshes):
 *   lower: min_k t_k + |x_v - p_k|, the Euclidean distance (any path on the
 *          surface is at least as long as the straight segment, whatever the
 *          faces: zero-area, folded, coincident vertices);
 *   upper: the shortest path along edges of faces of nonzero area (with a
 *          margin over the library's zero-area test, so that a face it drops
 *          is never used), from each source vertex, or from a face source
 *          through its corners (t_k + |c - p_k| to corner c): a path on the
 *          surface the solvers must not exceed;
 *   reach: where that path is finite the distance is finite, unless
 *          max_distance is set and the path is longer than it; a finite
 *          distance is at most max_distance.
 * The exact solve must meet both to rounding (1e-12 relative, 1e-13 of the
 * mesh size). Where it fell back to walls at non-manifold edges its values
 * are upper bounds of the geodesic distance, still paths on the surface: the
 * bounds hold there too. The march must meet the upper one to rounding
 * too, and from one source come within MARCH_UNDER_REL of the lower one, a
 * check for gross shortcuts (a virtual edge beside its strip gave 60 %
 * below): the planar update of a virtual triangle (section 4.2), which need
 * not lie on the surface, can fall below a front curved across it (4.6 %
 * on an 8-vertex flat mesh, 3 % found here with a 2-edge exact start), and
 * from two sources with values a triangle's planar update may be below the
 * Euclidean distance from either (the lower bound, a minimum of two cones, is
 * not convex). bench/studies/oracle_sweep.py holds the default march to 1e-8.
 * The window method (MFMM_METHOD_WINDOWS) must meet both bounds to rounding
 * and never fall below the exact solve (1e-9 relative).
 *
 * Symmetry: from vertex sources, the exact distance to a vertex v (the
 * target byte's, and the farthest one reached) equals the one solved back
 * from v, min_k t_k + d(v, s_k), to 1e-12 relative, unless either solve
 * fell back to walls (upper bounds): a path missed one way shows there (on
 * folded non-manifold fans a window dropped by a lost root of ex_dominate
 * gave 2.8015 one way and 2.7901 the other; a needle on a non-manifold edge
 * reached from a pass, 1 + sqrt 2 and sqrt 5).
 *
 * Face sources (no max_distance): the exact distance from a point p in a
 * face equals the one from a vertex at p on the surface cut there: the
 * mesh's own faces (T-junctions closed: a point of an input face may lie on
 * a cut between its pieces) with the face holding p and its copies split in
 * three at p, or where p lies on an edge, every face on that edge split in
 * two (a zero-area one too: its two pieces join the same points of the
 * line its corners lie on as it did); solved from that vertex (and the
 * second source at its value) to 1e-12 relative at every vertex, unless
 * either solve fell back to walls.
 * With the vertex symmetry above this makes a face source's distances
 * symmetric too. Splitting the input face alone is not the same surface:
 * a point on an edge, or on a cut that is an edge of other faces (a
 * T-junction's piece on a non-manifold edge), then loses the faces across
 * it.
 *
 * Input layout (all optional past the end: zeros):
 *   byte 0: nv - 3 (3..66)      byte 1: nf - 1 (1..128)
 *   byte 2: flags: 1 face source, 2 max_distance, 4 memory_limit, 8 two sources
 *   byte 3: radius of the exact start, in eighths of a mean edge (0..31)
 *   then nv * 3 int8 coordinates / 8, nf * 3 vertex bytes (mod nv),
 *   the source bytes, a max_distance byte, a memory_limit byte, the target
 *   byte (mod nv). */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "meshfmm.h"
#include "byte_reader.h"
#include "mesh/order.h"
#include "exact/exact.h"
#include "start/patch.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Relative and absolute (of the mesh size) rounding allowed on the bounds,
 * and the march's undershoot of the Euclidean distance (tests/python/oracles.py). */
#define BOUND_REL 1e-12
#define BOUND_ABS 1e-13
#define MARCH_UNDER_REL 0.25

static double dist3(const double *a, const double *b)
{
    double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
    return sqrt(x * x + y * y + z * z);
}

/* A face of nonzero area with a factor 4 over the library's zero-area test
 * (src/mesh/build.c: the sine between two unit edge vectors above
 * 64 eps (lmax / l0) (lmax / l1)). */
static int solid_face(const double *V, const int32_t *f)
{
    double e[3][3], len[3];
    for (int k = 0; k < 3; k++) {
        const double *a = V + 3 * f[(k + 1) % 3], *b = V + 3 * f[(k + 2) % 3];
        for (int d = 0; d < 3; d++)
            e[k][d] = b[d] - a[d];
        len[k] = sqrt(e[k][0] * e[k][0] + e[k][1] * e[k][1] + e[k][2] * e[k][2]);
    }
    if (!(len[0] > 0.0 && len[1] > 0.0))
        return 0;
    double lmax = fmax(len[0], fmax(len[1], len[2])), u[3], w[3];
    for (int d = 0; d < 3; d++) {
        u[d] = e[0][d] / len[0];
        w[d] = e[1][d] / len[1];
    }
    double c0 = u[1] * w[2] - u[2] * w[1], c1 = u[2] * w[0] - u[0] * w[2],
           c2 = u[0] * w[1] - u[1] * w[0];
    double sine = sqrt(c0 * c0 + c1 * c1 + c2 * c2);
    return sine > 4.0 * 64.0 * DBL_EPSILON * (lmax / len[0]) * (lmax / len[1]);
}

/* The bounds of every vertex (header comment): lo the Euclidean one, hi the
 * edge-graph path (+inf where none reaches), by Dijkstra on a dense matrix
 * (nv <= 66). Returns 0 when out of memory. */
static int bounds(const double *V, int32_t nv, const int32_t *F, int32_t nf,
                  const mfmm_source *src, int n_src, double *lo, double *hi)
{
    double *W = malloc((size_t)nv * nv * sizeof *W);
    char *done = calloc((size_t)nv, 1), *solid = calloc((size_t)nv, 1);
    if (!W || !done || !solid) {
        free(W);
        free(done);
        free(solid);
        return 0;
    }
    for (int32_t i = 0; i < nv * nv; i++)
        W[i] = INFINITY;
    for (int32_t f = 0; f < nf; f++) {
        if (!solid_face(V, F + 3 * f))
            continue;
        for (int k = 0; k < 3; k++) {
            solid[F[3 * f + k]] = 1;
            int32_t p = F[3 * f + k], q = F[3 * f + (k + 1) % 3];
            double len = dist3(V + 3 * p, V + 3 * q);
            if (len < W[p * nv + q])
                W[p * nv + q] = W[q * nv + p] = len;
        }
    }
    for (int32_t v = 0; v < nv; v++) {
        lo[v] = hi[v] = INFINITY;
    }
    for (int k = 0; k < n_src; k++) {
        double p[3];
        if (src[k].face < 0) {
            memcpy(p, V + 3 * src[k].vertex, sizeof p);
            /* a vertex on no face of nonzero area may be +inf */
            if (solid[src[k].vertex])
                hi[src[k].vertex] = fmin(hi[src[k].vertex], src[k].value);
        } else {
            const int32_t *f = F + 3 * src[k].face;
            for (int d = 0; d < 3; d++)
                p[d] = src[k].bary[0] * V[3 * f[0] + d] + src[k].bary[1] * V[3 * f[1] + d] +
                       src[k].bary[2] * V[3 * f[2] + d];
            /* the segment from p to a corner lies in the face (solid or not:
             * then the path may be longer, never shorter, which keeps hi an
             * upper bound only where the face is solid) */
            if (solid_face(V, f))
                for (int c = 0; c < 3; c++)
                    hi[f[c]] = fmin(hi[f[c]], src[k].value + dist3(p, V + 3 * f[c]));
        }
        for (int32_t v = 0; v < nv; v++)
            lo[v] = fmin(lo[v], src[k].value + dist3(V + 3 * v, p));
    }
    for (;;) {
        int32_t u = -1;
        for (int32_t v = 0; v < nv; v++)
            if (!done[v] && isfinite(hi[v]) && (u < 0 || hi[v] < hi[u]))
                u = v;
        if (u < 0)
            break;
        done[u] = 1;
        for (int32_t v = 0; v < nv; v++)
            if (hi[u] + W[u * nv + v] < hi[v])
                hi[v] = hi[u] + W[u * nv + v];
    }
    free(W);
    free(done);
    free(solid);
    return 1;
}

/* Whether distances d meet the bounds: d >= lo (1 - under) - tol (under
 * < 0: not checked), d <= hi (1 + over) + tol, finite where hi is (up to
 * max_distance), at most max_distance where finite. */
static int within(const double *d, const double *lo, const double *hi, int32_t nv,
                  double under, double over, double maxd, double tol)
{
    for (int32_t v = 0; v < nv; v++) {
        if (under >= 0.0 && !(d[v] >= lo[v] * (1.0 - under) - tol))
            return 0;
        if (isfinite(d[v])) {
            if (!(d[v] <= hi[v] * (1.0 + over) + tol) ||
                !(d[v] <= maxd * (1.0 + BOUND_REL) + tol))
                return 0;
        } else if (hi[v] * (1.0 + BOUND_REL) + tol < maxd) {
            return 0; /* a path shorter than max_distance, and no distance */
        }
    }
    return 1;
}

/* The mesh's surface cut at face source s (header comment), in internal
 * ids: vertices V2 (nv + 1, the point last: *P), faces F2 (room for 3 nf +
 * 3, nf the faces built). Returns the number of faces; 0 where the point
 * is in no face with an area, at a corner, or within 1e-6 of an edge
 * without being on it, where a cut would leave a sliver of a face. */
static int32_t split_at(const mfmm_mesh *mesh, const mfmm_source *s, double *V2, int32_t *F2,
                        int32_t *P)
{
    double beta[3];
    int32_t g = mfmm_order_point_in(mesh, s->face, s->bary, beta), nf2 = 0, nv = mesh->nv;
    if (g < 0 || mfmm_mesh_degenerate(mesh, g))
        return 0;
    /* a cut between pieces leaves rounding (4e-17) where the point is on it */
    int zk = -1, nzero = 0;
    for (int k = 0; k < 3; k++) {
        if (beta[k] <= 1e-12) {
            beta[k] = 0.0;
            zk = k;
            nzero++;
        } else if (beta[k] < 1e-6) {
            return 0;
        }
    }
    if (nzero > 1)
        return 0;
    const int32_t *pv = mesh->face_records[g].v;
    memcpy(V2, mesh->xyz, 3 * (size_t)nv * sizeof *V2);
    double sum = beta[0] + beta[1] + beta[2];
    for (int d = 0; d < 3; d++)
        V2[3 * nv + d] = (beta[0] * V2[3 * pv[0] + d] + beta[1] * V2[3 * pv[1] + d] +
                          beta[2] * V2[3 * pv[2] + d]) /
                         sum;
    *P = nv;
    for (int32_t f = 0; f < mesh->nf; f++) {
        const int32_t *t = mesh->face_records[f].v;
        int in[3], n_in = 0;
        for (int k = 0; k < 3; k++)
            n_in += in[k] = (t[k] == pv[0] && zk != 0) || (t[k] == pv[1] && zk != 1) ||
                            (t[k] == pv[2] && zk != 2);
        if (zk < 0 && n_in == 3) { /* the face or a copy: three faces round p */
            for (int k = 0; k < 3; k++) {
                int32_t *o = F2 + 3 * nf2++;
                o[0] = t[k];
                o[1] = t[(k + 1) % 3];
                o[2] = nv;
            }
        } else if (zk >= 0 && n_in == 2) { /* on the edge t[k] t[k+1]: two faces */
            int k = !in[0] ? 1 : !in[1] ? 2 : 0;
            int32_t a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3], *o = F2 + 3 * nf2;
            o[0] = a, o[1] = nv, o[2] = c, o[3] = nv, o[4] = b, o[5] = c;
            nf2 += 2;
        } else {
            memcpy(F2 + 3 * nf2++, t, 3 * sizeof *t);
        }
    }
    return nf2;
}

/* The exact distance from vertex sources to v solved from v (the least of
 * value + distance back to each source); NaN when that solve fails or fell
 * back to walls at non-manifold edges, whose values are upper bounds only
 * (work: nv doubles). */
static double reverse_exact(mfmm_exact_solver *ex, const mfmm_source *src, int n_src, int32_t v,
                            double *work)
{
    mfmm_source s = {v, -1, {0, 0, 0}, 0.0};
    mfmm_exact_info info = {.struct_size = sizeof info};
    if (mfmm_solve_exact(ex, &s, 1, NULL, work, &info, NULL) != MFMM_OK ||
        info.nonmanifold_walls)
        return NAN;
    double best = INFINITY;
    for (int k = 0; k < n_src; k++)
        best = fmin(best, src[k].value + work[src[k].vertex]);
    return best;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader r = {data, size};
    int32_t nv = 3 + next(&r) % 64, nf = 1 + next(&r) % 128;
    int flags = next(&r);
    double radius = (double)(next(&r) % 32) / 8.0;
    double V[66 * 3];
    int32_t F[128 * 3];
    read_mesh(&r, nv, nf, V, F);
    mfmm_mesh *mesh = NULL;
    mfmm_error err;
    if (mfmm_mesh_create(V, nv, F, nf, NULL, &mesh, &err) != MFMM_OK)
        return 0;
    mfmm_source src[2];
    int n_src = flags & 8 ? 2 : 1;
    for (int k = 0; k < n_src; k++) {
        memset(&src[k], 0, sizeof src[k]);
        src[k].face = -1;
        src[k].vertex = next(&r) % nv;
        src[k].value = k ? (double)(next(&r) % 8) / 8.0 : 0.0;
    }
    if (flags & 1) { /* the first source a point in a face (maybe on an edge or a corner) */
        src[0].face = next(&r) % nf;
        double w[3] = {next(&r) % 5, next(&r) % 5, next(&r) % 5};
        double s = w[0] + w[1] + w[2];
        if (s == 0) {
            w[0] = 1;
            s = 1;
        }
        for (int k = 0; k < 3; k++)
            src[0].bary[k] = w[k] / s;
    }
    mfmm_exact_options eo;
    mfmm_exact_options_init(&eo);
    if (flags & 2)
        eo.max_distance = (double)next(&r) / 16.0;
    if (flags & 4)
        eo.memory_limit = 4096 + 64 * (size_t)next(&r);
    int32_t target = next(&r) % nv;
    double *e = malloc((size_t)nv * sizeof *e), *d = malloc((size_t)nv * sizeof *d);
    double *lo = malloc((size_t)nv * sizeof *lo), *hi = malloc((size_t)nv * sizeof *hi);
    double *back = malloc((size_t)nv * sizeof *back);
    mfmm_exact_solver *ex = NULL;
    if (!e || !d || !lo || !hi || !back || mfmm_exact_solver_create(mesh, &ex) != MFMM_OK)
        goto done;
    mfmm_exact_info info = {.struct_size = sizeof info};
    mfmm_status st = mfmm_solve_exact(ex, src, n_src, &eo, e, &info, &err);
    if (st == MFMM_ERR_DEGENERATE_SOURCE || st == MFMM_ERR_MEMORY_LIMIT ||
        st == MFMM_ERR_BAD_BARYCENTRIC)
        goto done;
    if (st != MFMM_OK)
        abort();
    for (int32_t v = 0; v < nv; v++)
        if (isnan(e[v]) || e[v] < 0)
            abort();
    /* the Euclidean and edge-graph bounds (header comment), to rounding of
     * the mesh's size and the sources' values */
    double extent = 0.0, maxd = flags & 2 ? eo.max_distance : INFINITY;
    for (int32_t v = 0; v < nv; v++)
        extent = fmax(extent, dist3(V + 3 * v, V));
    for (int k = 0; k < n_src; k++)
        extent += src[k].value;
    double btol = BOUND_ABS * (2.0 * extent + 1.0);
    if (!bounds(V, nv, F, nf, src, n_src, lo, hi))
        goto done;
    if (!within(e, lo, hi, nv, BOUND_REL, BOUND_REL, maxd, btol))
        abort();
    /* a vertex source at its value (or less, from another source), unless it
     * is beyond max_distance or on no face of nonzero area (+inf) */
    for (int k = 0; k < n_src; k++)
        if (src[k].face < 0 && !(e[src[k].vertex] <= src[k].value) &&
            e[src[k].vertex] != INFINITY)
            abort();
    /* the triangle inequality along every edge of a face of nonzero area
     * (regressions/exact: a doubled face once broke it by 0.10) */
    for (int32_t f = 0; f < nf; f++) {
        const double *a = V + 3 * F[3 * f], *b = V + 3 * F[3 * f + 1], *c = V + 3 * F[3 * f + 2];
        double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double n2 = pow(u[1] * w[2] - u[2] * w[1], 2) + pow(u[2] * w[0] - u[0] * w[2], 2) +
                    pow(u[0] * w[1] - u[1] * w[0], 2);
        if (!(n2 > 0.0))
            continue;
        for (int k = 0; k < 3; k++) {
            int32_t p = F[3 * f + k], q = F[3 * f + (k + 1) % 3];
            const double *x = V + 3 * p, *y = V + 3 * q;
            double len = sqrt(pow(x[0] - y[0], 2) + pow(x[1] - y[1], 2) + pow(x[2] - y[2], 2));
            if (isfinite(e[p]) && isfinite(e[q]) &&
                !(fabs(e[p] - e[q]) <= len * (1.0 + 1e-9) + 1e-9 * (1.0 + fabs(e[p]))))
                abort();
        }
    }
    /* symmetry (header comment), from vertex sources without max_distance */
    int vertex_sources = 1;
    for (int k = 0; k < n_src; k++)
        vertex_sources &= src[k].face < 0;
    if (vertex_sources && !(flags & 2) && !info.nonmanifold_walls) {
        int32_t far = -1;
        for (int32_t v = 0; v < nv; v++)
            if (isfinite(e[v]) && (far < 0 || e[v] > e[far]))
                far = v;
        int32_t vs[2] = {target, far};
        for (int j = 0; j < 2; j++) {
            if (vs[j] < 0 || !isfinite(e[vs[j]]))
                continue;
            double rev = reverse_exact(ex, src, n_src, vs[j], back);
            if (!isnan(rev) && !(fabs(rev - e[vs[j]]) <= BOUND_REL * e[vs[j]] + btol))
                abort();
        }
    }
    /* a face source equals a vertex at its point (header comment), from the
     * second source too, in internal ids on the cut surface */
    if (src[0].face >= 0 && !(flags & 2) && !info.nonmanifold_walls) {
        int32_t nvi = mesh->nv, nfi = mesh->nf, P = -1;
        double *V2 = malloc(3 * ((size_t)nvi + 1) * sizeof *V2);
        double *s2 = malloc(((size_t)nvi + 1) * sizeof *s2);
        int32_t *F2 = malloc(3 * (3 * (size_t)nfi + 3) * sizeof *F2), nf2;
        mfmm_mesh *m2 = NULL;
        mfmm_exact_solver *ex2 = NULL;
        if (V2 && s2 && F2 && (nf2 = split_at(mesh, &src[0], V2, F2, &P)) > 0 &&
            mfmm_mesh_create(V2, nvi + 1, F2, nf2, NULL, &m2, NULL) == MFMM_OK &&
            mfmm_exact_solver_create(m2, &ex2) == MFMM_OK) {
            mfmm_source s2src[2] = {src[0], src[1]};
            s2src[0].face = -1;
            s2src[0].vertex = P;
            if (n_src == 2)
                s2src[1].vertex = mfmm_vertex_in(mesh, src[1].vertex);
            mfmm_exact_info info2 = {.struct_size = sizeof info2};
            if (mfmm_solve_exact(ex2, s2src, n_src, NULL, s2, &info2, NULL) == MFMM_OK &&
                !info2.nonmanifold_walls)
                for (int32_t v = 0; v < nvi; v++) {
                    double a = e[mfmm_vertex_out(mesh, v)], b = s2[v];
                    if (a != b && !(fabs(a - b) <= BOUND_REL * a + btol))
                        abort();
                }
        }
        mfmm_exact_solver_destroy(ex2);
        mfmm_mesh_destroy(m2);
        free(V2);
        free(s2);
        free(F2);
    }
    /* the patch of the exact start: the full solve's distances within radius */
    if (n_src == 1 && !(flags & 6)) {
        int32_t n = 0;
        const int32_t *pv = NULL;
        const double *pd = NULL;
        double R = radius * 0.5;
        mfmm_source isrc = src[0]; /* the patch API takes internal ids (src/mesh/order.h) */
        if (isrc.face < 0)
            isrc.vertex = mfmm_vertex_in(mesh, isrc.vertex);
        else /* faces are numbered internally too, and split at T-junctions */
            isrc.face = mfmm_order_point_in(mesh, isrc.face, isrc.bary, isrc.bary);
        if (mfmm_exact_patch(ex, &isrc, 1, R, 0, &n, &pv, &pd, NULL) == MFMM_OK) {
            int32_t inside = 0, in_r = 0;
            for (int32_t v = 0; v < nv; v++)
                inside += e[v] <= R;
            /* every value exact, those beyond R too (the ring of start/patch.c);
             * where the full solve fell back to walls at non-manifold edges
             * (its budget passed beyond R), the patch's values are at most
             * its upper bounds */
            for (int32_t i = 0; i < n; i++) {
                double ev = e[mfmm_vertex_out(mesh, pv[i])], tol = 1e-12 * (1.0 + ev);
                if (info.nonmanifold_walls ? !(pd[i] <= ev + tol) : !(fabs(pd[i] - ev) <= tol))
                    abort();
                in_r += pd[i] <= R;
            }
            n = in_r;
            /* ties at the radius itself may go either way */
            if (!info.nonmanifold_walls && (n > inside + 1 || n + 1 < inside)) {
                int32_t near = 0;
                for (int32_t v = 0; v < nv; v++)
                    near += fabs(e[v] - R) <= 1e-12 * (1.0 + R);
                if (abs(n - inside) > near)
                    abort();
            }
        }
    }
    /* the march from the exact start */
    mfmm_solver *solver = NULL;
    if (mfmm_solver_create(mesh, &solver) == MFMM_OK) {
        mfmm_solve_options so;
        mfmm_solve_options_init(&so);
        so.exact_start_radius = radius;
        st = mfmm_solve(solver, src, n_src, &so, d, &err);
        if (st == MFMM_OK) {
            for (int32_t v = 0; v < nv; v++)
                if (isnan(d[v]) || d[v] < 0)
                    abort();
            /* the lower bound from one source only: from two, the update
             * of a triangle fits a plane to both values (a front that is
             * neither circle), below the Euclidean distance from either
             * (0.2 % on one triangle with values 0 and 0.75 on an edge of
             * 0.77) */
            if (!within(d, lo, hi, nv, n_src == 1 ? MARCH_UNDER_REL : -1.0, BOUND_REL, INFINITY,
                        btol))
                abort();
        }
        /* the window method: paths' lengths, so both bounds to rounding and
         * never below the exact solve (unless that fell back to walls, whose
         * values are upper bounds); a stop at max_distance writes the full
         * solve's bits */
        mfmm_solve_options_init(&so);
        so.method = MFMM_METHOD_WINDOWS;
        st = mfmm_solve(solver, src, n_src, &so, d, &err);
        if (st == MFMM_OK) {
            if (!within(d, lo, hi, nv, BOUND_REL, BOUND_REL, INFINITY, btol))
                abort();
            for (int32_t v = 0; v < nv; v++)
                if (!info.nonmanifold_walls && isfinite(e[v]) && !(flags & 2) &&
                    !(d[v] >= e[v] * (1.0 - 1e-9) - btol))
                    abort();
            if (flags & 2) {
                so.max_distance = eo.max_distance;
                if (mfmm_solve(solver, src, n_src, &so, e, &err) != MFMM_OK)
                    abort();
                for (int32_t v = 0; v < nv; v++)
                    if (d[v] <= so.max_distance ? e[v] != d[v] : e[v] != INFINITY)
                        abort();
            }
        } else if (st != MFMM_ERR_DEGENERATE_SOURCE && st != MFMM_ERR_BAD_BARYCENTRIC) {
            abort();
        }
        mfmm_solver_destroy(solver);
    }
done:
    mfmm_exact_solver_destroy(ex);
    free(e);
    free(d);
    free(lo);
    free(hi);
    free(back);
    mfmm_mesh_destroy(mesh);
    return 0;
}
