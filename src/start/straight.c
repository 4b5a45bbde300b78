/* The straight start around a point source (straight.h). Seeding only
 * the source face's corners and the far vertices across its edges made T
 * depend on which face names a point on an edge and jump when the point
 * moves off the edge. Here the faces holding the point are all start faces,
 * and the walk goes on through edges while they are near: the set of
 * vertices reached, and their values, are the limits of those of nearby
 * points on either side of an edge (hand: a 1e-9 move changes T by at most
 * the move). At a corner the limit depends on the direction the point comes
 * from; where the corner's angle sum exceeds 2 pi, the start from the corner
 * reaches vertices behind it (through it) that a point beside it does not,
 * and T jumps by the march's own error there; the exact start (seed.c)
 * removes that where it applies. */
#include <math.h>
#include <string.h>

#include "straight.h"

typedef struct v2 {
    double x, y;
} v2;

static double cross2(v2 a, v2 b)
{
    return a.x * b.y - a.y * b.x;
}

static v2 sub2(v2 a, v2 b)
{
    v2 r = {a.x - b.x, a.y - b.y};
    return r;
}

static double norm2(v2 a)
{
    return sqrt(a.x * a.x + a.y * a.y);
}

void mfmm_source_locate(const mfmm_mesh *mesh, const mfmm_source *src, mfmm_source_loc *loc)
{
    const int32_t *fv = mesh->face_records[src->face].v;
    int n_zero = 0, zero = -1, top = 0;
    for (int k = 0; k < 3; k++) {
        if (src->bary[k] <= 0.0) {
            n_zero++;
            zero = k;
        }
        if (src->bary[k] > src->bary[top])
            top = k;
    }
    loc->vertex = fv[top];
    loc->zero = -1;
    loc->across = -1;
    if (n_zero >= 2) {
        loc->kind = MFMM_AT_VERTEX;
        memcpy(loc->p, mesh->xyz + 3 * (size_t)fv[top], sizeof loc->p);
        return;
    }
    if (n_zero == 0) {
        /* on an edge's line to rounding, as start_face tests it (2e-12 here
         * against its 1e-12, so that every edge it does not cross because
         * the point lies on it is this one): a point of both faces, whose
         * neighbour then starts too (a point on the line a T-junction's face
         * was split along seeded one piece, and the other's far corner got
         * its distance round the junction, 1.559 for 0.559) */
        int k = 0;
        for (int j = 1; j < 3; j++)
            if (src->bary[j] < src->bary[k])
                k = j;
        const double *xa = mesh->xyz + 3 * (size_t)fv[(k + 1) % 3],
                     *xb = mesh->xyz + 3 * (size_t)fv[(k + 2) % 3];
        double p[3] = {0.0, 0.0, 0.0}, u[3], v[3];
        for (int j = 0; j < 3; j++)
            for (int c = 0; c < 3; c++)
                p[c] += src->bary[j] * mesh->xyz[3 * (size_t)fv[j] + c];
        for (int c = 0; c < 3; c++) {
            u[c] = xa[c] - p[c];
            v[c] = xb[c] - p[c];
        }
        double cr[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                        u[0] * v[1] - u[1] * v[0]};
        double nu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]),
               nv = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]) <= 2e-12 * nu * nv) {
            n_zero = 1;
            zero = k;
        }
    }
    loc->kind = n_zero == 1 ? MFMM_ON_EDGE : MFMM_IN_FACE;
    if (n_zero == 1) {
        loc->zero = zero;
        loc->across = mesh->face_neighbor[3 * (size_t)src->face + zero];
    }
    for (int c = 0; c < 3; c++)
        loc->p[c] = 0.0;
    for (int k = 0; k < 3; k++) {
        double bk = src->bary[k] > 0.0 ? src->bary[k] : 0.0;
        for (int c = 0; c < 3; c++)
            loc->p[c] += bk * mesh->xyz[3 * (size_t)fv[k] + c];
    }
}

/* Distance from the origin to the segment [x, y]. */
static double seg_dist(v2 x, v2 y)
{
    v2 d = sub2(y, x);
    double dd = d.x * d.x + d.y * d.y;
    double s = dd > 0.0 ? -(x.x * d.x + x.y * d.y) / dd : 0.0;
    s = s < 0.0 ? 0.0 : s > 1.0 ? 1.0 : s;
    v2 c = {x.x + s * d.x, x.y + s * d.y};
    return norm2(c);
}

typedef struct walk {
    const mfmm_mesh *m;
    const double *cost;
    int loc;
    double fp; /* per vertex: F at the point, interpolated in its face */
    double radius;
    mfmm_start_fn fn;
    void *user;
    int stop;
    /* the chain of edges crossed: 2D ends, vertex ids, faces */
    v2 pa[MFMM_START_DEPTH], pb[MFMM_START_DEPTH];
    int32_t a[MFMM_START_DEPTH], b[MFMM_START_DEPTH], face[MFMM_START_DEPTH + 1];
    double t[MFMM_START_DEPTH];
} walk;

/* Reports vertex v at plane point w, reached across `depth` edges. */
static void hit(walk *w, int32_t v, v2 pw, int depth)
{
    mfmm_start_hit h;
    double len = norm2(pw), prev = 0.0, weighted = 0.0;
    for (int i = 0; i < depth; i++) {
        v2 d = sub2(w->pb[i], w->pa[i]);
        double den = cross2(pw, d);
        /* the segment 0 -> pw meets edge i at pa + t (pb - pa) */
        double ti = den != 0.0 ? cross2(pw, w->pa[i]) / -den : 0.5;
        w->t[i] = ti < 0.0 ? 0.0 : ti > 1.0 ? 1.0 : ti;
        if (w->loc == 2) {
            double s = den != 0.0 ? len * cross2(w->pa[i], d) / den : prev;
            s = s < prev ? prev : s > len ? len : s;
            weighted += w->cost[w->face[i]] * (s - prev);
            prev = s;
        }
    }
    if (w->loc == 2)
        weighted += w->cost[w->face[depth]] * (len - prev);
    else
        weighted = w->loc == 1 ? 0.5 * (w->fp + w->cost[v]) * len : len;
    h.vertex = v;
    h.length = len;
    h.cost_length = weighted;
    h.depth = depth;
    h.a = w->a;
    h.b = w->b;
    h.face = w->face;
    h.t = w->t;
    if (w->fn(w->user, &h))
        w->stop = 1;
}

static int in_cone(v2 d, v2 R, v2 L)
{
    return cross2(R, d) >= 0.0 && cross2(d, L) >= 0.0;
}

static void enter(walk *w, int depth, int32_t g, int32_t ia, int32_t ib, v2 pa, v2 pb, v2 R, v2 L);

/* Enters every face across the edge (ia, ib) opposite corner k of face f:
 * its neighbour, or, at a non-manifold edge of a start face, each other
 * face on it, copies apart (a straight path from the point goes on into
 * each; a T-junction's split can leave one, and without this the straight
 * start misses the far corner of the face it split); none at a
 * boundary. Only from a start face: at every depth, fans of coincident
 * faces multiplied the walks beyond any time limit. */
static void enter_across(walk *w, int depth, int32_t f, int k, int32_t ia, int32_t ib, v2 pa,
                         v2 pb, v2 R, v2 L)
{
    const mfmm_mesh *m = w->m;
    int32_t g = m->face_neighbor[3 * (size_t)f + k];
    if (g >= 0 || depth > 1) {
        enter(w, depth, g, ia, ib, pa, pb, R, L);
        return;
    }
    for (int32_t i = m->vertex_face_offset[ia]; i < m->vertex_face_offset[ia + 1] && !w->stop; i++) {
        int32_t h = MFMM_WEDGE_FACE(m->vertex_wedge[i]);
        const int32_t *hv = m->face_records[h].v;
        if (h == f || mfmm_mesh_copy(m, h) || (hv[0] != ib && hv[1] != ib && hv[2] != ib))
            continue;
        enter(w, depth, h, ia, ib, pa, pb, R, L);
    }
}

/* Enters face g across the edge (ia at pa, ib at pb), the `depth`-th edge
 * crossed, with the rays from the origin in the cone from R counterclockwise
 * to L still straight. */
static void enter(walk *w, int depth, int32_t g, int32_t ia, int32_t ib, v2 pa, v2 pb, v2 R, v2 L)
{
    const mfmm_mesh *m = w->m;
    if (w->stop || g < 0 || mfmm_mesh_degenerate(m, g) || depth > MFMM_START_DEPTH)
        return;
    const int32_t *gv = m->face_records[g].v;
    int kq = -1;
    for (int k = 0; k < 3; k++)
        if (gv[k] != ia && gv[k] != ib)
            kq = k;
    if (kq < 0)
        return;
    int32_t q = gv[kq];
    /* q unfolded across the edge, on the side away from the origin */
    v2 d = sub2(pb, pa);
    double len = norm2(d);
    if (!(len > 0.0))
        return;
    const double *xq = m->xyz + 3 * (size_t)q;
    double r1 = mfmm_dist3(m->xyz + 3 * (size_t)ia, xq), r2 = mfmm_dist3(m->xyz + 3 * (size_t)ib, xq);
    double s = (len * len + r1 * r1 - r2 * r2) / (2.0 * len);
    double h2 = r1 * r1 - s * s, h = h2 > 0.0 ? sqrt(h2) : 0.0;
    v2 e = {d.x / len, d.y / len}, n = {-e.y, e.x};
    if (n.x * pa.x + n.y * pa.y < 0.0) {
        n.x = -n.x;
        n.y = -n.y;
    }
    v2 pq = {pa.x + s * e.x + h * n.x, pa.y + s * e.y + h * n.y};
    w->pa[depth - 1] = pa;
    w->pb[depth - 1] = pb;
    w->a[depth - 1] = ia;
    w->b[depth - 1] = ib;
    w->face[depth] = g;
    if (in_cone(pq, R, L))
        hit(w, q, pq, depth);
    /* on through the two other edges (the one opposite ib, then opposite ia) */
    for (int side = 0; side < 2 && !w->stop; side++) {
        v2 x = side ? pq : pa, y = side ? pb : pq;
        int32_t ix = side ? q : ia, iy = side ? ib : q;
        if (!(seg_dist(x, y) < w->radius))
            continue;
        v2 Re = x, Le = y;
        if (cross2(x, y) < 0.0) {
            Re = y;
            Le = x;
        }
        v2 R2 = cross2(R, Re) > 0.0 ? Re : R, L2 = cross2(Le, L) > 0.0 ? Le : L;
        if (!(cross2(R2, L2) > 0.0))
            continue;
        int kopp = -1; /* the corner of g opposite edge (ix, iy) */
        for (int k = 0; k < 3; k++)
            if (gv[k] != ix && gv[k] != iy)
                kopp = k;
        enter_across(w, depth + 1, g, kopp, ix, iy, x, y, R2, L2);
        /* the chain's slot `depth` was overwritten below: restore this level */
        w->face[depth] = g;
    }
}

/* One start face f holding point p: its corners, then through each edge
 * that does not hold p. */
static void start_face(walk *w, int32_t f, const double *p)
{
    const mfmm_mesh *m = w->m;
    const int32_t *fv = m->face_records[f].v;
    const double *X[3];
    double r[3];
    int far = 0;
    for (int k = 0; k < 3; k++) {
        X[k] = m->xyz + 3 * (size_t)fv[k];
        r[k] = mfmm_dist3(X[k], p);
        if (r[k] > r[far])
            far = k;
    }
    /* a plane frame with p at the origin */
    double ex[3], nn[3], ey[3], u[3], v[3];
    for (int c = 0; c < 3; c++) {
        ex[c] = (X[far][c] - p[c]) / r[far];
        u[c] = X[1][c] - X[0][c];
        v[c] = X[2][c] - X[0][c];
    }
    nn[0] = u[1] * v[2] - u[2] * v[1];
    nn[1] = u[2] * v[0] - u[0] * v[2];
    nn[2] = u[0] * v[1] - u[1] * v[0];
    ey[0] = nn[1] * ex[2] - nn[2] * ex[1];
    ey[1] = nn[2] * ex[0] - nn[0] * ex[2];
    ey[2] = nn[0] * ex[1] - nn[1] * ex[0];
    double ny = sqrt(ey[0] * ey[0] + ey[1] * ey[1] + ey[2] * ey[2]);
    if (!(ny > 0.0))
        return;
    v2 P[3];
    for (int k = 0; k < 3; k++) {
        double dx = 0.0, dy = 0.0;
        for (int c = 0; c < 3; c++) {
            dx += (X[k][c] - p[c]) * ex[c];
            dy += (X[k][c] - p[c]) * ey[c] / ny;
        }
        P[k].x = dx;
        P[k].y = dy;
    }
    w->face[0] = f;
    for (int k = 0; k < 3 && !w->stop; k++) {
        mfmm_start_hit h;
        double t0 = 0.0;
        h.vertex = fv[k];
        h.length = r[k];
        h.cost_length = w->loc == 2   ? w->cost[f] * r[k]
                        : w->loc == 1 ? 0.5 * (w->fp + w->cost[fv[k]]) * r[k]
                                      : r[k];
        h.depth = 0;
        h.a = h.b = fv;
        h.face = w->face;
        h.t = &t0;
        if (w->fn(w->user, &h))
            w->stop = 1;
    }
    for (int k = 0; k < 3 && !w->stop; k++) {
        v2 x = P[(k + 1) % 3], y = P[(k + 2) % 3];
        double c = cross2(x, y);
        if (!(seg_dist(x, y) < w->radius))
            continue;
        /* p on this edge (or its line): the neighbour is a start face itself */
        if (!(fabs(c) > 1e-12 * norm2(x) * norm2(y)) || r[(k + 1) % 3] == 0.0 || r[(k + 2) % 3] == 0.0)
            continue;
        v2 R = c > 0.0 ? x : y, L = c > 0.0 ? y : x;
        enter_across(w, 1, f, k, fv[(k + 1) % 3], fv[(k + 2) % 3], x, y, R, L);
        w->face[0] = f;
    }
}

void mfmm_start_walk(const mfmm_mesh *mesh, const mfmm_source *src, const double *cost,
                     int cost_location, mfmm_start_fn fn, void *user)
{
    walk w;
    memset(&w, 0, sizeof w);
    w.m = mesh;
    w.cost = cost;
    w.loc = cost ? cost_location : 0;
    /* a mesh's constant, so that nearby points walk alike; at least the
     * longest edge, so that every start face's own edges are crossed */
    w.radius = fmax(MFMM_START_RADIUS * mesh->info.mean_edge_length, mesh->info.max_edge_length);
    w.fn = fn;
    w.user = user;
    const int32_t *fv = mesh->face_records[src->face].v;
    mfmm_source_loc at;
    mfmm_source_locate(mesh, src, &at);
    const double *p = at.p;
    if (at.kind == MFMM_AT_VERTEX) { /* every face around it */
        int32_t v = at.vertex;
        if (w.loc == 1)
            w.fp = cost[v];
        for (int32_t i = mesh->vertex_face_offset[v]; i < mesh->vertex_face_offset[v + 1] && !w.stop; i++) {
            int32_t f = MFMM_WEDGE_FACE(mesh->vertex_wedge[i]);
            if (!mfmm_mesh_degenerate(mesh, f))
                start_face(&w, f, p);
        }
        return;
    }
    if (w.loc == 1)
        for (int k = 0; k < 3; k++)
            w.fp += (src->bary[k] > 0.0 ? src->bary[k] : 0.0) * cost[fv[k]];
    int32_t g = at.across;
    if (g >= 0 && mfmm_mesh_degenerate(mesh, g))
        g = -1;
    if (at.kind == MFMM_ON_EDGE && at.across < 0) {
        /* on a non-manifold edge (or a boundary): every face on it, copies
         * and zero-area faces apart, in one order whichever face names the
         * point (else a point on the line a T-junction split a face along,
         * that edge on a third face too, starts one piece, and the other's
         * corner gets its distance round the junction, too long) */
        int32_t ia = fv[(at.zero + 1) % 3], ib = fv[(at.zero + 2) % 3];
        for (int32_t i = mesh->vertex_face_offset[ia]; i < mesh->vertex_face_offset[ia + 1] && !w.stop;
             i++) {
            int32_t h = MFMM_WEDGE_FACE(mesh->vertex_wedge[i]);
            const int32_t *hv = mesh->face_records[h].v;
            if ((h == src->face || (!mfmm_mesh_copy(mesh, h) && !mfmm_mesh_degenerate(mesh, h))) &&
                (hv[0] == ib || hv[1] == ib || hv[2] == ib))
                start_face(&w, h, p);
        }
        return;
    }
    /* on an edge: both faces, in the same order whichever names the point */
    int32_t first = g >= 0 && g < src->face ? g : src->face;
    int32_t second = g < 0 ? -1 : first == g ? src->face : g;
    start_face(&w, first, p);
    if (second >= 0 && !w.stop)
        start_face(&w, second, p);
}

typedef struct seed_ctx {
    mfmm_march_state *st;
    double value;
} seed_ctx;

static int seed_point_hit(void *user, const mfmm_start_hit *h)
{
    seed_ctx *c = user;
    mfmm_march_seed(c->st, h->vertex, c->value + h->cost_length);
    return 0;
}

void mfmm_start_seed(const mfmm_mesh *mesh, mfmm_march_state *st, const mfmm_source *src)
{
    if (src->face < 0) {
        mfmm_march_seed(st, src->vertex, src->value);
        return;
    }
    /* a point on the surface: every vertex a straight segment reaches near
     * it starts at that segment's cost */
    seed_ctx c = {st, src->value};
    mfmm_start_walk(mesh, src, st->cost, st->cost_location, seed_point_hit, &c);
}
