/* Path straightening: see the block comment below. Used by path.c after a
 * path was traced (section 5); it reads the mesh only. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "straighten.h"
#include "surface.h"

/* What straightening reads: the mesh and an optional per-face cost. */
typedef struct strip_ctx {
    const mfmm_mesh *m;
    const double *cost;
} strip_ctx;

/* ------------------------------------------------------------ straightening
 * The traced path follows the gradient of a first-order T, whose direction
 * errors integrate along it. Its faces are a corridor: unfolded into a plane
 * (face by face across the shared edges, as in section 4.2's unfolding), the
 * shortest polyline inside the strip is found with the funnel algorithm
 * (Lee & Preparata 1984) over the shared edges (portals). The strip is split
 * where the path goes from a face to one that shares no edge with it (it
 * passed a vertex) or, with per-face cost, where the cost changes: those
 * points stay fixed. A piece is replaced only when the result is no longer. */

typedef struct sv2 {
    double x, y;
} sv2;

typedef struct apex_rec {
    sv2 p;
    int32_t v; /* vertex id, -1 for the piece's ends */
    int32_t k; /* funnel portal index */
} apex_rec;

typedef struct strip_scratch {
    int32_t cap;        /* most faces a strip may have */
    int32_t *fa, *fb;   /* the piece's faces in order, and a rerouted strip */
    int32_t na;         /* apexes of the last funnel */
    double (*P)[3][2];  /* their corners unfolded, by local index */
    sv2 (*por)[2];      /* funnel portals (left, right): 0 start, nf end */
    int32_t (*pv)[2];   /* portal vertex ids */
    apex_rec *apex;
    mfmm_surface_point *out;
    int32_t n_out, out_cap;
} strip_scratch;

static double cross2(sv2 a, sv2 b, sv2 c)
{
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

static int sv2_eq(sv2 a, sv2 b)
{
    return a.x == b.x && a.y == b.y;
}

static int local_of(const mfmm_mesh *m, int32_t f, int32_t v)
{
    for (int k = 0; k < 3; k++)
        if (m->face_records[f].v[k] == v)
            return k;
    return -1;
}

/* Barycentric coordinates in face f of the point (g, b); 0 if it is not on f. */
static int rebary(const mfmm_mesh *m, int32_t g, const double b[3], int32_t f, double out[3])
{
    double s = 0.0;
    out[0] = out[1] = out[2] = 0.0;
    for (int k = 0; k < 3; k++) {
        if (b[k] <= ON_EDGE)
            continue;
        int l = local_of(m, f, m->face_records[g].v[k]);
        if (l < 0)
            return 0;
        out[l] += b[k];
        s += b[k];
    }
    if (!(s > 0.0))
        return 0;
    for (int k = 0; k < 3; k++)
        out[k] /= s;
    return 1;
}

/* The vertex a point is at, or -1. */
static int32_t point_vertex(const mfmm_mesh *m, const mfmm_surface_point *p)
{
    for (int k = 0; k < 3; k++)
        if (p->bary[k] == 1.0)
            return m->face_records[p->face].v[k];
    return -1;
}

/* Unfolds the strip's faces into the plane; 0 on a degenerate face. */
static int unfold_strip(const mfmm_mesh *m, const int32_t *faces, int32_t nf, double (*P)[3][2])
{
    for (int32_t j = 0; j < nf; j++) {
        int32_t f = faces[j];
        const int32_t *v = m->face_records[f].v;
        if (mfmm_mesh_degenerate(m, f))
            return 0;
        int ka, kb, kc;
        double A[2], B[2], away[2];
        if (j == 0) {
            ka = 0, kb = 1, kc = 2;
            A[0] = A[1] = 0.0;
            B[0] = mfmm_dist3(m->xyz + 3 * (size_t)v[0], m->xyz + 3 * (size_t)v[1]);
            B[1] = 0.0;
            away[0] = 0.0, away[1] = -1.0;
        } else {
            int32_t g = faces[j - 1];
            int lg[2], n = 0, og = -1;
            ka = kb = kc = -1;
            for (int k = 0; k < 3; k++) {
                int l = local_of(m, f, m->face_records[g].v[k]);
                if (l < 0)
                    og = k;
                else if (n < 2) {
                    lg[n] = k;
                    if (n == 0) ka = l; else kb = l;
                    n++;
                }
            }
            if (n != 2 || og < 0)
                return 0;
            kc = 3 - ka - kb;
            memcpy(A, P[j - 1][lg[0]], sizeof A);
            memcpy(B, P[j - 1][lg[1]], sizeof B);
            memcpy(away, P[j - 1][og], sizeof away);
        }
        const double *XA = m->xyz + 3 * (size_t)v[ka], *XB = m->xyz + 3 * (size_t)v[kb],
                     *XC = m->xyz + 3 * (size_t)v[kc];
        double r1 = mfmm_dist3(XC, XA), r2 = mfmm_dist3(XC, XB);
        double ex = B[0] - A[0], ey = B[1] - A[1], L = sqrt(ex * ex + ey * ey);
        if (!(L > 0.0))
            return 0;
        ex /= L;
        ey /= L;
        double a = (L * L + r1 * r1 - r2 * r2) / (2.0 * L), h2 = r1 * r1 - a * a;
        double emax = fmax(L, fmax(r1, r2));
        if (!(h2 > 1e-20 * emax * emax) || !isfinite(h2))
            return 0;
        double h = sqrt(h2), nx = -ey, ny = ex;
        if ((away[0] - A[0]) * nx + (away[1] - A[1]) * ny > 0.0)
            h = -h;
        memcpy(P[j][ka], A, sizeof A);
        memcpy(P[j][kb], B, sizeof B);
        P[j][kc][0] = A[0] + a * ex + h * nx;
        P[j][kc][1] = A[1] + a * ey + h * ny;
    }
    return 1;
}

/* Appends a point to the straightened list, dropping a repeat of a vertex.
 * 0 when the list is full. */
static int out_push(const mfmm_mesh *m, strip_scratch *s, int32_t f, const double b[3])
{
    mfmm_surface_point p;
    p.face = f;
    memcpy(p.bary, b, sizeof p.bary);
    mfmm_bary_to_xyz(m, f, b, p.xyz);
    if (s->n_out > 0) {
        const mfmm_surface_point *q = &s->out[s->n_out - 1];
        int32_t v = point_vertex(m, &p);
        if ((v >= 0 && v == point_vertex(m, q)) || mfmm_dist3(p.xyz, q->xyz) == 0.0)
            return 1;
    }
    if (s->n_out >= s->out_cap)
        return 0;
    s->out[s->n_out++] = p;
    return 1;
}

/* Walks around vertex v from face a, first across a's edge (v, w), to face
 * b; writes the faces strictly between into out (at most max). Returns their
 * count, or -1 (a boundary, a full turn, or too many faces). */
static int32_t fan_walk(const mfmm_mesh *m, int32_t a, int32_t v, int32_t w, int32_t b,
                        int32_t *out, int32_t max)
{
    int32_t f = a, n = 0;
    for (int step = 0; step < 64; step++) {
        int o = -1;
        for (int k = 0; k < 3; k++) {
            int32_t x = m->face_records[f].v[k];
            if (x != v && x != w)
                o = k;
        }
        int32_t g = o < 0 ? -1 : m->face_neighbor[3 * (size_t)f + o];
        if (g < 0 || g == a || local_of(m, g, v) < 0)
            return -1;
        if (g == b)
            return n;
        if (n >= max)
            return -1;
        out[n++] = g;
        int32_t z = -1;
        for (int k = 0; k < 3; k++) {
            int32_t x = m->face_records[g].v[k];
            if (x != v && x != w)
                z = x;
        }
        w = z;
        f = g;
    }
    return -1;
}

/* 1 when faces[0..n-1] all have cost c (or there is no cost). */
static int same_cost(const strip_ctx *t, const int32_t *faces, int32_t n, double c)
{
    for (int32_t i = 0; t->cost && i < n; i++)
        if (t->cost[faces[i]] != c)
            return 0;
    return 1;
}

/* Unfolds the strip faces[0..nf-1] and runs the funnel from raw point a to
 * raw point b. Fills s->por, s->pv, s->apex, s->na. Returns the length of
 * the shortest polyline in the strip, or -1 when it cannot be unfolded. */
static double funnel(const mfmm_mesh *m, const mfmm_surface_point *ra,
                     const mfmm_surface_point *rb, const int32_t *faces, int32_t nf,
                     strip_scratch *s)
{
    double bs[3], be[3];
    if (!rebary(m, ra->face, ra->bary, faces[0], bs) ||
        !rebary(m, rb->face, rb->bary, faces[nf - 1], be) || !unfold_strip(m, faces, nf, s->P))
        return -1.0;
    sv2 S = {0.0, 0.0}, E = {0.0, 0.0};
    for (int k = 0; k < 3; k++) {
        S.x += bs[k] * s->P[0][k][0];
        S.y += bs[k] * s->P[0][k][1];
        E.x += be[k] * s->P[nf - 1][k][0];
        E.y += be[k] * s->P[nf - 1][k][1];
    }
    /* portals: 0 the start, j = 1..nf-1 the edge from faces[j-1] to faces[j], nf the end */
    int32_t vs = point_vertex(m, ra), ve = point_vertex(m, rb);
    s->por[0][0] = s->por[0][1] = S;
    s->pv[0][0] = s->pv[0][1] = vs;
    s->por[nf][0] = s->por[nf][1] = E;
    s->pv[nf][0] = s->pv[nf][1] = ve;
    for (int32_t j = 1; j < nf; j++) {
        int32_t g = faces[j - 1];
        int ku = -1, kw = -1, ko = -1;
        for (int k = 0; k < 3; k++) {
            if (local_of(m, faces[j], m->face_records[g].v[k]) < 0)
                ko = k;
            else if (ku < 0)
                ku = k;
            else
                kw = k;
        }
        if (ko < 0 || kw < 0)
            return -1.0;
        sv2 U = {s->P[j - 1][ku][0], s->P[j - 1][ku][1]},
            W = {s->P[j - 1][kw][0], s->P[j - 1][kw][1]},
            O = {s->P[j - 1][ko][0], s->P[j - 1][ko][1]};
        int32_t vu = m->face_records[g].v[ku], vw = m->face_records[g].v[kw];
        /* walking away from O, the left end is W when O is left of U -> W */
        int w_left = cross2(U, W, O) > 0.0;
        s->por[j][0] = w_left ? W : U;
        s->por[j][1] = w_left ? U : W;
        s->pv[j][0] = w_left ? vw : vu;
        s->pv[j][1] = w_left ? vu : vw;
    }

    /* The funnel: apex, left and right rays; a portal end that crosses the
     * other ray makes that ray's end the next apex (a vertex of the path). */
    int32_t na = 0, ia = 0, il = 0, ir = 0;
    sv2 ap = S, lp = S, rp = S;
    s->apex[na++] = (apex_rec){S, vs, 0};
    for (int32_t i = 1; i <= nf; i++) {
        sv2 L = s->por[i][0], R = s->por[i][1];
        if (cross2(ap, rp, R) >= 0.0) {
            if (sv2_eq(ap, rp) || cross2(ap, lp, R) <= 0.0) {
                rp = R;
                ir = i;
            } else {
                ap = lp;
                ia = il;
                s->apex[na++] = (apex_rec){ap, s->pv[il][0], il};
                rp = lp = ap;
                ir = il = ia;
                i = ia;
                continue;
            }
        }
        if (cross2(ap, lp, L) <= 0.0) {
            if (sv2_eq(ap, lp) || cross2(ap, rp, L) >= 0.0) {
                lp = L;
                il = i;
            } else {
                ap = rp;
                ia = ir;
                s->apex[na++] = (apex_rec){ap, s->pv[ir][1], ir};
                rp = lp = ap;
                ir = il = ia;
                i = ia;
                continue;
            }
        }
    }
    s->apex[na++] = (apex_rec){E, ve, nf};
    s->na = na;
    double len = 0.0;
    for (int32_t i = 1; i < na; i++)
        len += hypot(s->apex[i].p.x - s->apex[i - 1].p.x, s->apex[i].p.y - s->apex[i - 1].p.y);
    return isfinite(len) ? len : -1.0;
}

/* Straightens the piece of raw points [a, b] in the strip s->fa[0..nf-1];
 * appends its points after a. 0: keep the raw piece. Where the shortest
 * polyline wraps around a strip vertex, the strip is rerouted around the
 * vertex's other side when that is shorter (until none is): the path then
 * no longer depends on which side of a vertex the traced path went. */
static int straighten_piece(const strip_ctx *t, const mfmm_surface_point *raw, int32_t a, int32_t b,
                            int32_t nf, strip_scratch *s)
{
    const mfmm_mesh *m = t->m;
    double c0 = t->cost ? t->cost[s->fa[0]] : 1.0;
    double len = funnel(m, &raw[a], &raw[b], s->fa, nf, s);
    if (len < 0.0)
        return 0;
    int64_t evals = 0, max_evals = 8 * (int64_t)nf + 64;
    for (int changed = 1; changed && evals < max_evals;) {
        changed = 0;
        for (int32_t ai = 1; ai + 1 < s->na && !changed && evals < max_evals; ai++) {
            int32_t v = s->apex[ai].v, k = s->apex[ai].k;
            if (v < 0 || k < 1 || k >= nf)
                continue;
            int32_t p = k - 1, q = k;
            while (p > 0 && local_of(m, s->fa[p - 1], v) >= 0)
                p--;
            while (q + 1 < nf && local_of(m, s->fa[q + 1], v) >= 0)
                q++;
            int32_t w = -1, fp = s->fa[p];
            for (int j = 0; j < 3; j++) {
                int32_t x = m->face_records[fp].v[j];
                if (x != v && local_of(m, s->fa[p + 1], x) < 0)
                    w = x;
            }
            int32_t room = s->cap - (p + 1) - (nf - q);
            int32_t r = w < 0 ? -1 : fan_walk(m, fp, v, w, s->fa[q], s->fb + p + 1, room);
            if (r < 0 || !same_cost(t, s->fb + p + 1, r, c0))
                continue;
            memcpy(s->fb, s->fa, (size_t)(p + 1) * sizeof *s->fb);
            memcpy(s->fb + p + 1 + r, s->fa + q, (size_t)(nf - q) * sizeof *s->fb);
            int32_t nb = p + 1 + r + nf - q;
            evals++;
            double lb = funnel(m, &raw[a], &raw[b], s->fb, nb, s);
            if (lb >= 0.0 && lb < len * (1.0 - 1e-12)) {
                int32_t *x = s->fa;
                s->fa = s->fb;
                s->fb = x;
                nf = nb;
                len = lb;
                changed = 1;
            } else if (funnel(m, &raw[a], &raw[b], s->fa, nf, s) < 0.0) {
                return 0;
            }
        }
    }

    /* The crossing of each portal, as a point of the face before it. */
    int32_t n0 = s->n_out, seg = 0;
    for (int32_t j = 1; j < nf; j++) {
        while (s->apex[seg + 1].k < j)
            seg++;
        const apex_rec *A0 = &s->apex[seg], *A1 = &s->apex[seg + 1];
        double tt;
        int fixed = -1;
        for (int e = 0; e < 2; e++)
            if ((s->pv[j][e] == A0->v && sv2_eq(s->por[j][e], A0->p)) ||
                (s->pv[j][e] == A1->v && sv2_eq(s->por[j][e], A1->p)))
                fixed = e;
        sv2 U = s->por[j][0], W = s->por[j][1];
        if (fixed >= 0) {
            tt = fixed == 0 ? 0.0 : 1.0;
        } else {
            double dx = A1->p.x - A0->p.x, dy = A1->p.y - A0->p.y;
            double ex = W.x - U.x, ey = W.y - U.y;
            tt = (dx * (A0->p.y - U.y) - dy * (A0->p.x - U.x)) / (dx * ey - dy * ex);
            if (!isfinite(tt)) {
                s->n_out = n0;
                return 0;
            }
            tt = tt < 0.0 ? 0.0 : tt > 1.0 ? 1.0 : tt;
        }
        int32_t g = s->fa[j - 1];
        double bg[3] = {0.0, 0.0, 0.0};
        bg[local_of(m, g, s->pv[j][0])] = 1.0 - tt;
        bg[local_of(m, g, s->pv[j][1])] = tt;
        if (!out_push(m, s, g, bg)) {
            s->n_out = n0;
            return 0;
        }
    }
    if (!out_push(m, s, raw[b].face, raw[b].bary)) {
        s->n_out = n0;
        return 0;
    }
    return 1;
}

/* Appends the raw points a+1..b; 0 when there is no room. */
static int keep_raw(const mfmm_surface_point *raw, int32_t a, int32_t b, strip_scratch *s)
{
    if (b - a > s->out_cap - s->n_out)
        return 0;
    memcpy(s->out + s->n_out, raw + a + 1, (size_t)(b - a) * sizeof *s->out);
    s->n_out += b - a;
    return 1;
}

/* Straightens the raw path raw[0..n-1] into s->out. 1: done; 0: out of
 * memory; -1: no room (keep the raw path). */
static int straighten(const strip_ctx *t, const mfmm_surface_point *raw, int32_t n, strip_scratch *s)
{
    const mfmm_mesh *m = t->m;
    s->cap = 4 * (n < (INT32_MAX - 256) / 8 ? n : (INT32_MAX - 256) / 8) + 256;
    size_t np = (size_t)s->cap + 2;
    s->fa = malloc(np * sizeof *s->fa);
    s->fb = malloc(np * sizeof *s->fb);
    s->P = malloc(np * sizeof *s->P);
    s->por = malloc(np * sizeof *s->por);
    s->pv = malloc(np * sizeof *s->pv);
    s->apex = malloc(np * sizeof *s->apex);
    s->out_cap = s->cap + n + 2;
    s->out = malloc((size_t)s->out_cap * sizeof *s->out);
    s->n_out = 0;
    if (!s->fa || !s->fb || !s->P || !s->por || !s->pv || !s->apex || !s->out)
        return 0;
    s->out[s->n_out++] = raw[0];
    int32_t a = 0, nf = 0;
    for (int32_t i = 1; i <= n; i++) {
        int32_t f = i < n ? raw[i].face : -1;
        if (nf > 0 && f == s->fa[nf - 1])
            continue;
        int join = 0;
        if (nf > 0 && f >= 0) {
            int32_t g = s->fa[nf - 1];
            double c0 = t->cost ? t->cost[g] : 1.0;
            for (int k = 0; k < 3; k++)
                join |= m->face_neighbor[3 * (size_t)g + k] == f;
            /* per-face cost: straight only where it is constant */
            if (t->cost && t->cost[f] != c0)
                join = 0;
            else if (!join) {
                /* passed a vertex: join the faces by the shorter fan around it */
                int32_t v = point_vertex(m, &raw[i - 1]), best = -1;
                for (int side = 0; side < 2 && v >= 0 && local_of(m, g, v) >= 0; side++) {
                    int32_t w = m->face_records[g].v[(local_of(m, g, v) + 1 + side) % 3];
                    int32_t room = s->cap - nf - 1 - (best >= 0 ? best : 0);
                    int32_t *dst = s->fa + nf + (best >= 0 ? best : 0);
                    int32_t r = fan_walk(m, g, v, w, f, dst, room);
                    if (r < 0 || !same_cost(t, dst, r, c0))
                        continue;
                    if (best < 0 || r < best) {
                        memmove(s->fa + nf, dst, (size_t)r * sizeof *s->fa);
                        best = r;
                    }
                }
                if (best >= 0) {
                    nf += best;
                    join = 1;
                }
            }
        }
        if (nf > 0 && !join) { /* the piece [a, i-1] ends */
            if (!straighten_piece(t, raw, a, i - 1, nf, s) && !keep_raw(raw, a, i - 1, s))
                return -1;
            a = i - 1;
            nf = 0;
        }
        if (f >= 0) {
            if (nf >= s->cap) { /* no room: end the piece here */
                if (!straighten_piece(t, raw, a, i - 1, nf, s) && !keep_raw(raw, a, i - 1, s))
                    return -1;
                a = i - 1;
                nf = 0;
            }
            s->fa[nf++] = f;
        }
    }
    return 1;
}

int mfmm_path_straighten(const mfmm_mesh *mesh, const double *face_cost,
                         const mfmm_surface_point *raw, int32_t n,
                         mfmm_surface_point **out, int32_t *n_out)
{
    strip_ctx t = {mesh, face_cost};
    strip_scratch s;
    memset(&s, 0, sizeof s);
    int r = straighten(&t, raw, n, &s);
    free(s.fa);
    free(s.fb);
    free(s.P);
    free(s.por);
    free(s.pv);
    free(s.apex);
    if (r > 0) {
        *out = s.out;
        *n_out = s.n_out;
    } else {
        free(s.out);
        *out = NULL;
        *n_out = 0;
    }
    return r;
}
