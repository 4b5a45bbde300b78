/* The six-point quadratic field of a face (field.h): a face and the far
 * vertices of its three neighbours unfolded into its plane, T fitted by a
 * quadratic (six values, six coefficients; Kimmel & Sethian 1998, section
 * 5), the linear gradient where that fit is ill-posed. */
#include <math.h>
#include <string.h>

#include "base/error.h"
#include "field.h"
#include "mesh/order.h"
#include "surface.h"

/* Reads T[v], refusing NaN. */
int mfmm_path_read_T(tracer *t, int32_t v, double *out)
{
    double x = t->T[v];
    if (isnan(x)) {
        v = mfmm_vertex_out(t->m, v); /* the caller's id */
        t->st = mfmm_fail(t->err, MFMM_ERR_BAD_ARGUMENT, v, "distances[%d] is NaN", (int)v);
        return 0;
    }
    *out = x;
    return 1;
}

/* F at barycentric b of face f (1 without cost; the costs were checked
 * when the call began, mfmm_check_cost). */
double mfmm_path_cost_at(const tracer *t, int32_t f, const double b[3])
{
    if (!t->cost)
        return 1.0;
    if (t->cost_loc == MFMM_COST_PER_FACE)
        return t->cost[f];
    double s = 0.0;
    for (int k = 0; k < 3; k++)
        s += b[k] * t->cost[t->m->face_records[f].v[k]];
    return s;
}

/* Gaussian elimination with partial pivoting; 0 when ill-conditioned. */
static int solve6(double A[6][6], double r[6], double x[6])
{
    double pmax = 0.0, pmin = INFINITY;
    for (int col = 0; col < 6; col++) {
        int piv = col;
        for (int i = col + 1; i < 6; i++)
            if (fabs(A[i][col]) > fabs(A[piv][col]))
                piv = i;
        if (piv != col) {
            for (int j = 0; j < 6; j++) {
                double s = A[col][j]; A[col][j] = A[piv][j]; A[piv][j] = s;
            }
            double s = r[col]; r[col] = r[piv]; r[piv] = s;
        }
        double p = fabs(A[col][col]);
        if (!(p > 0.0))
            return 0;
        if (p > pmax) pmax = p;
        if (p < pmin) pmin = p;
        for (int i = col + 1; i < 6; i++) {
            double q = A[i][col] / A[col][col];
            for (int j = col; j < 6; j++)
                A[i][j] -= q * A[col][j];
            r[i] -= q * r[col];
        }
    }
    if (pmin < PIVOT_RATIO * pmax)
        return 0;
    for (int i = 5; i >= 0; i--) {
        double s = r[i];
        for (int j = i + 1; j < 6; j++)
            s -= A[i][j] * x[j];
        x[i] = s / A[i][i];
        if (!isfinite(x[i]))
            return 0;
    }
    return 1;
}

/* Unfolds the far vertex w of the neighbour across the edge opposite corner k
 * into the face's plane: the point at its 3D distances from the edge's ends,
 * on the other side of the edge from corner k. */
static void unfold_far(const mfmm_mesh *m, const frame *fr, int k, int32_t w, double out[2])
{
    int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
    const double *X1 = m->xyz + 3 * (size_t)fr->v[k1], *X2 = m->xyz + 3 * (size_t)fr->v[k2];
    const double *W = m->xyz + 3 * (size_t)w;
    double d1 = mfmm_dist3(W, X1), d2 = mfmm_dist3(W, X2);
    double ex = fr->P[k2][0] - fr->P[k1][0], ey = fr->P[k2][1] - fr->P[k1][1];
    double L = sqrt(ex * ex + ey * ey);
    ex /= L;
    ey /= L;
    double a = (d1 * d1 - d2 * d2 + L * L) / (2.0 * L);
    double h2 = d1 * d1 - a * a;
    double h = h2 > 0.0 ? sqrt(h2) : 0.0;
    double nx = -ey, ny = ex; /* normal to the edge, pointed away from corner k */
    if ((fr->P[k][0] - fr->P[k1][0]) * nx + (fr->P[k][1] - fr->P[k1][1]) * ny > 0.0) {
        nx = -nx;
        ny = -ny;
    }
    out[0] = fr->P[k1][0] + a * ex + h * nx;
    out[1] = fr->P[k1][1] + a * ey + h * ny;
}

/* Builds face f's frame and interpolants. 0 on a bad input value. */
int mfmm_path_frame_build(tracer *t, int32_t f, frame *fr)
{
    const mfmm_mesh *m = t->m;
    memset(fr, 0, sizeof *fr);
    fr->f = f;
    for (int k = 0; k < 3; k++) {
        fr->v[k] = m->face_records[f].v[k];
        if (!mfmm_path_read_T(t, fr->v[k], &fr->T[k]))
            return 0;
    }
    double b1[3] = {1.0 / 3, 1.0 / 3, 1.0 / 3};
    fr->F = mfmm_path_cost_at(t, f, b1);
    const double *A = m->xyz + 3 * (size_t)fr->v[0], *B = m->xyz + 3 * (size_t)fr->v[1],
                 *C = m->xyz + 3 * (size_t)fr->v[2];
    double u[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]};
    double w[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]};
    double L = sqrt(mfmm_dot3(u, u));
    fr->max_edge = fmax(L, fmax(sqrt(mfmm_dot3(w, w)), mfmm_dist3(B, C)));
    double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    double n2 = sqrt(mfmm_dot3(n, n));
    if (mfmm_mesh_degenerate(m, f) || !(L > 0.0) || !(n2 > 1e-14 * fr->max_edge * fr->max_edge)) {
        fr->degenerate = 1;
        return 1;
    }
    for (int i = 0; i < 3; i++) {
        fr->e1[i] = u[i] / L;
        n[i] /= n2;
    }
    fr->e2[0] = n[1] * fr->e1[2] - n[2] * fr->e1[1];
    fr->e2[1] = n[2] * fr->e1[0] - n[0] * fr->e1[2];
    fr->e2[2] = n[0] * fr->e1[1] - n[1] * fr->e1[0];
    fr->P[1][0] = L;
    fr->P[2][0] = mfmm_dot3(w, fr->e1);
    fr->P[2][1] = mfmm_dot3(w, fr->e2);
    double twoA = fr->P[1][0] * fr->P[2][1] - fr->P[1][1] * fr->P[2][0];
    for (int k = 0; k < 3; k++) {
        const double *p1 = fr->P[(k + 1) % 3], *p2 = fr->P[(k + 2) % 3];
        fr->gb[k][0] = (p1[1] - p2[1]) / twoA;
        fr->gb[k][1] = (p2[0] - p1[0]) / twoA;
    }
    fr->lin_ok = isfinite(fr->T[0]) && isfinite(fr->T[1]) && isfinite(fr->T[2]);
    if (!fr->lin_ok)
        return 1;
    for (int d = 0; d < 2; d++)
        fr->glin[d] = fr->T[0] * fr->gb[0][d] + fr->T[1] * fr->gb[1][d] + fr->T[2] * fr->gb[2][d];

    /* Section 5: the second-order fit over the face and its three neighbours. */
    double pts[6][2], vals[6];
    for (int k = 0; k < 3; k++) {
        pts[k][0] = fr->P[k][0];
        pts[k][1] = fr->P[k][1];
        vals[k] = fr->T[k];
    }
    double Fmin = fr->F, Fmax = fr->F;
    for (int k = 0; k < 3; k++) {
        int32_t g = m->face_neighbor[3 * f + k];
        if (g < 0 || mfmm_mesh_degenerate(m, g))
            return 1; /* boundary or degenerate neighbour: linear */
        int32_t a1 = fr->v[(k + 1) % 3], a2 = fr->v[(k + 2) % 3], far = -1;
        for (int j = 0; j < 3; j++) {
            int32_t x = m->face_records[g].v[j];
            if (x != a1 && x != a2)
                far = x;
        }
        if (far < 0 || far == fr->v[k])
            return 1;
        if (!mfmm_path_read_T(t, far, &vals[3 + k]))
            return 0;
        if (!isfinite(vals[3 + k]))
            return 1;
        unfold_far(m, fr, k, far, pts[3 + k]);
        if (t->cost) {
            double Fg = t->cost[t->cost_loc == MFMM_COST_PER_FACE ? g : far];
            Fmin = fmin(Fmin, Fg);
            Fmax = fmax(Fmax, Fg);
        }
    }
    /* T has a kink where the cost jumps (refraction): no smooth fit there. */
    if (t->cost && (t->cost_loc == MFMM_COST_PER_FACE ? Fmax != Fmin : Fmax > 1.1 * Fmin))
        return 1;
    fr->ox = (fr->P[0][0] + fr->P[1][0] + fr->P[2][0]) / 3.0;
    fr->oy = (fr->P[0][1] + fr->P[1][1] + fr->P[2][1]) / 3.0;
    fr->scale = fr->max_edge;
    double M[6][6], r[6];
    for (int i = 0; i < 6; i++) {
        double x = (pts[i][0] - fr->ox) / fr->scale, y = (pts[i][1] - fr->oy) / fr->scale;
        M[i][0] = 1.0;
        M[i][1] = x;
        M[i][2] = y;
        M[i][3] = x * x;
        M[i][4] = x * y;
        M[i][5] = y * y;
        r[i] = vals[i] - fr->T[0];
    }
    fr->quad_ok = solve6(M, r, fr->c);
    return 1;
}

/* grad T at plane point p: the quadratic where usable and descending like
 * the linear gradient, else the linear one. 0 when there is none. */
int mfmm_path_field_grad(const frame *fr, const double p[2], double g[2])
{
    if (!fr->lin_ok) {
        /* a corner is unreached: head for the lowest finite corner */
        int best = -1;
        for (int k = 0; k < 3; k++)
            if (isfinite(fr->T[k]) && (best < 0 || fr->T[k] < fr->T[best]))
                best = k;
        if (best < 0)
            return 0;
        g[0] = p[0] - fr->P[best][0];
        g[1] = p[1] - fr->P[best][1];
        return g[0] != 0.0 || g[1] != 0.0;
    }
    g[0] = fr->glin[0];
    g[1] = fr->glin[1];
    if (fr->quad_ok) {
        double x = (p[0] - fr->ox) / fr->scale, y = (p[1] - fr->oy) / fr->scale;
        double qx = (fr->c[1] + 2.0 * fr->c[3] * x + fr->c[4] * y) / fr->scale;
        double qy = (fr->c[2] + fr->c[4] * x + 2.0 * fr->c[5] * y) / fr->scale;
        if (qx * g[0] + qy * g[1] > 0.0) {
            g[0] = qx;
            g[1] = qy;
        }
    }
    return isfinite(g[0]) && isfinite(g[1]) && (g[0] != 0.0 || g[1] != 0.0);
}

void mfmm_path_bary_to_plane(const frame *fr, const double b[3], double p[2])
{
    p[0] = b[0] * fr->P[0][0] + b[1] * fr->P[1][0] + b[2] * fr->P[2][0];
    p[1] = b[0] * fr->P[0][1] + b[1] * fr->P[1][1] + b[2] * fr->P[2][1];
}

double mfmm_path_frame_T(const frame *fr, const double b[3])
{
    double s = 0.0;
    for (int k = 0; k < 3; k++)
        if (b[k] > 0.0)
            s += b[k] * fr->T[k];
    return s;
}
