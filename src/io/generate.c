/* Generated meshes with known geometry (see generate.h). */
#include "generate.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const double PI = 3.14159265358979323846;

void mfmm_gen_free(mfmm_gen_mesh *m)
{
    if (!m)
        return;
    free(m->V);
    free(m->F);
    m->V = NULL;
    m->F = NULL;
    m->nv = m->nf = 0;
}

static mfmm_gen_mesh gen_alloc(int64_t nv, int64_t nf)
{
    mfmm_gen_mesh m = {0, 0, NULL, NULL};
    if (nv <= 0 || nf <= 0 || nv > INT32_MAX / 3 || nf > INT32_MAX / 3)
        return m;
    m.V = malloc((size_t)nv * 3 * sizeof *m.V);
    m.F = malloc((size_t)nf * 3 * sizeof *m.F);
    if (!m.V || !m.F) {
        mfmm_gen_free(&m);
        return m;
    }
    m.nv = (int32_t)nv;
    m.nf = (int32_t)nf;
    return m;
}

static void set_face(int32_t *f, int32_t a, int32_t b, int32_t c)
{
    f[0] = a;
    f[1] = b;
    f[2] = c;
}

/* (n+1)^2 vertices on [0,1]^2 with z = height(x, y); squares split along
 * alternating diagonals. */
static mfmm_gen_mesh gen_heightfield(int n, int sine)
{
    mfmm_gen_mesh m = {0, 0, NULL, NULL};
    if (n < 1 || n > 20000)
        return m;
    int64_t w = n + 1;
    m = gen_alloc(w * w, 2 * (int64_t)n * n);
    if (!m.V)
        return m;
    for (int64_t j = 0; j < w; j++)
        for (int64_t i = 0; i < w; i++) {
            double *p = m.V + 3 * (j * w + i);
            p[0] = (double)i / n;
            p[1] = (double)j / n;
            p[2] = sine ? 0.45 * sin(2 * PI * p[0]) * sin(2 * PI * p[1]) : 0.0;
        }
    int32_t *f = m.F;
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = 0; i < n; i++) {
            int32_t v00 = (int32_t)(j * w + i), v10 = v00 + 1;
            int32_t v01 = (int32_t)(v00 + w), v11 = v01 + 1;
            if ((i + j) % 2 == 0) {
                set_face(f, v00, v10, v11);
                set_face(f + 3, v00, v11, v01);
            } else {
                set_face(f, v00, v10, v01);
                set_face(f + 3, v10, v11, v01);
            }
            f += 6;
        }
    return m;
}

mfmm_gen_mesh mfmm_gen_grid(int n)
{
    return gen_heightfield(n, 0);
}

mfmm_gen_mesh mfmm_gen_sine(int n)
{
    return gen_heightfield(n, 1);
}

mfmm_gen_mesh mfmm_gen_lattice(int n, double stretch)
{
    mfmm_gen_mesh m = {0, 0, NULL, NULL};
    if (n < 1 || n > 20000 || !(stretch > 0.0) || !isfinite(stretch))
        return m;
    int64_t w = n + 1;
    m = gen_alloc(w * w, 2 * (int64_t)n * n);
    if (!m.V)
        return m;
    double h = sqrt(3.0) / 2.0 / n;
    for (int64_t j = 0; j < w; j++)
        for (int64_t i = 0; i < w; i++) {
            double *p = m.V + 3 * (j * w + i);
            p[0] = stretch * ((double)i + (j % 2 ? 0.5 : 0.0)) / n;
            p[1] = (double)j * h;
            p[2] = 0.0;
        }
    int32_t *f = m.F;
    for (int64_t j = 0; j < n; j++)
        for (int64_t i = 0; i < n; i++) {
            int32_t v00 = (int32_t)(j * w + i), v10 = v00 + 1;
            int32_t v01 = (int32_t)(v00 + w), v11 = v01 + 1;
            if (j % 2 == 0) { /* row above is shifted right */
                set_face(f, v00, v10, v01);
                set_face(f + 3, v10, v11, v01);
            } else { /* this row is shifted right */
                set_face(f, v00, v11, v01);
                set_face(f + 3, v00, v10, v11);
            }
            f += 6;
        }
    return m;
}

mfmm_gen_mesh mfmm_gen_torus(int nu, int nv, double R, double r)
{
    mfmm_gen_mesh m = {0, 0, NULL, NULL};
    if (nu < 3 || nv < 3 || nu > 20000 || nv > 20000 || !(r > 0.0) || !(R > r))
        return m;
    m = gen_alloc((int64_t)nu * nv, 2 * (int64_t)nu * nv);
    if (!m.V)
        return m;
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            double u = 2 * PI * i / nu, v = 2 * PI * j / nv;
            double *p = m.V + 3 * ((int64_t)i * nv + j);
            p[0] = (R + r * cos(v)) * cos(u);
            p[1] = (R + r * cos(v)) * sin(u);
            p[2] = r * sin(v);
        }
    int32_t *f = m.F;
    for (int i = 0; i < nu; i++)
        for (int j = 0; j < nv; j++) {
            int32_t a = i * nv + j, b = ((i + 1) % nu) * nv + j;
            int32_t c = ((i + 1) % nu) * nv + (j + 1) % nv, d = i * nv + (j + 1) % nv;
            set_face(f, a, b, c);
            set_face(f + 3, a, c, d);
            f += 6;
        }
    return m;
}

/* Open-addressing map from an edge (lo, hi) to its midpoint vertex. */
typedef struct edge_map {
    uint64_t *keys;
    int32_t *vals;
    size_t cap;
} edge_map;

static int32_t edge_midpoint(edge_map *em, mfmm_gen_mesh *m, int32_t *nv, int32_t a, int32_t b)
{
    int32_t lo = a < b ? a : b, hi = a < b ? b : a;
    uint64_t key = ((uint64_t)(uint32_t)lo << 32) | (uint32_t)hi;
    size_t i = (size_t)((key * 0x9E3779B97F4A7C15ull) >> 20) & (em->cap - 1);
    while (em->keys[i] != UINT64_MAX) {
        if (em->keys[i] == key)
            return em->vals[i];
        i = (i + 1) & (em->cap - 1);
    }
    int32_t v = (*nv)++;
    double *p = m->V + 3 * (int64_t)v;
    const double *pa = m->V + 3 * (int64_t)a, *pb = m->V + 3 * (int64_t)b;
    double s = 0.0;
    for (int k = 0; k < 3; k++) {
        p[k] = 0.5 * (pa[k] + pb[k]);
        s += p[k] * p[k];
    }
    s = sqrt(s);
    for (int k = 0; k < 3; k++)
        p[k] /= s;
    em->keys[i] = key;
    em->vals[i] = v;
    return v;
}

mfmm_gen_mesh mfmm_gen_icosphere(int level)
{
    mfmm_gen_mesh m = {0, 0, NULL, NULL};
    if (level < 0 || level > 10)
        return m;
    int64_t nf_final = 20 * ((int64_t)1 << (2 * level));
    m = gen_alloc(nf_final / 2 + 2, nf_final);
    int32_t *next = malloc((size_t)nf_final * 3 * sizeof *next);
    edge_map em = {NULL, NULL, 0};
    em.cap = 1;
    while (em.cap < (size_t)nf_final * 2)
        em.cap <<= 1;
    em.keys = malloc(em.cap * sizeof *em.keys);
    em.vals = malloc(em.cap * sizeof *em.vals);
    if (!m.V || !next || !em.keys || !em.vals) {
        mfmm_gen_free(&m);
        free(next);
        free(em.keys);
        free(em.vals);
        return m;
    }
    const double t = (1.0 + sqrt(5.0)) / 2.0;
    const double base[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    const int32_t faces[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                  {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                  {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                  {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    double s = sqrt(1.0 + t * t);
    for (int i = 0; i < 12; i++)
        for (int k = 0; k < 3; k++)
            m.V[3 * i + k] = base[i][k] / s;
    memcpy(m.F, faces, sizeof faces);
    int32_t nv = 12;
    int64_t nf = 20;
    for (int l = 0; l < level; l++) {
        for (size_t i = 0; i < em.cap; i++)
            em.keys[i] = UINT64_MAX;
        for (int64_t f = 0; f < nf; f++) {
            int32_t a = m.F[3 * f], b = m.F[3 * f + 1], c = m.F[3 * f + 2];
            int32_t ab = edge_midpoint(&em, &m, &nv, a, b);
            int32_t bc = edge_midpoint(&em, &m, &nv, b, c);
            int32_t ca = edge_midpoint(&em, &m, &nv, c, a);
            int32_t *o = next + 12 * f;
            set_face(o, a, ab, ca);
            set_face(o + 3, b, bc, ab);
            set_face(o + 6, c, ca, bc);
            set_face(o + 9, ab, bc, ca);
        }
        nf *= 4;
        memcpy(m.F, next, (size_t)nf * 3 * sizeof *m.F);
    }
    free(next);
    free(em.keys);
    free(em.vals);
    return m;
}

/* xorshift64*: the random points of mfmm_gen_delaunay */
static double gen_rand(uint64_t *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}

/* whether p lies strictly inside the circumcircle of the counter-clockwise
 * triangle (a, b, c) */
static int gen_incircle(const double *a, const double *b, const double *c, const double *p)
{
    double ax = a[0] - p[0], ay = a[1] - p[1], bx = b[0] - p[0], by = b[1] - p[1];
    double cx = c[0] - p[0], cy = c[1] - p[1];
    double det = (ax * ax + ay * ay) * (bx * cy - cx * by) -
                 (bx * bx + by * by) * (ax * cy - cx * ay) +
                 (cx * cx + cy * cy) * (ax * by - bx * ay);
    return det > 0.0;
}

mfmm_gen_mesh mfmm_gen_delaunay(int n, int disc, double stretch, uint64_t seed)
{
    mfmm_gen_mesh m = {0, 0, NULL, NULL};
    if (n < 4 || n > 20000 || !(stretch > 0.0) || !isfinite(stretch))
        return m;
    uint64_t st = seed * 0x9E3779B97F4A7C15ull + 1;
    int nb = disc ? (int)(2.0 * sqrt((double)n)) + 6 : 4 * ((int)sqrt((double)n) / 2 + 1);
    if (nb > n)
        nb = n;
    /* points, then three far corners of a triangle around them */
    double *P = malloc(((size_t)n + 3) * 2 * sizeof *P);
    int32_t cap = 2 * (n + 3) + 8;
    int32_t *T = malloc((size_t)cap * 3 * sizeof *T);
    int32_t *E = malloc((size_t)cap * 3 * 2 * sizeof *E);
    uint8_t *dead = malloc((size_t)cap);
    if (!P || !T || !E || !dead)
        goto done;
    for (int i = 0; i < nb; i++) {
        /* the boundary: on the circle, or around the square's sides */
        if (disc) {
            /* r = 1 + cos(3a) / 20: convex, and no four points on a
             * circle (the insertion needs none) */
            double a = 2.0 * PI * (i + 0.3 * gen_rand(&st)) / nb, r = 1.0 + 0.05 * cos(3.0 * a);
            P[2 * i] = r * cos(a);
            P[2 * i + 1] = r * sin(a);
        } else {
            int side = i % 4, q = i / 4, per = nb / 4;
            double u = (double)q / per;
            double xy[4][2] = {{u, 0.0}, {1.0, u}, {1.0 - u, 1.0}, {0.0, 1.0 - u}};
            P[2 * i] = xy[side][0];
            P[2 * i + 1] = xy[side][1];
        }
    }
    for (int i = nb; i < n; i++) {
        double x, y;
        do {
            x = gen_rand(&st);
            y = gen_rand(&st);
            if (disc) {
                x = 2.0 * x - 1.0;
                y = 2.0 * y - 1.0;
            }
        } while (disc ? x * x + y * y > 0.64 : (x < 0.02 || x > 0.98 || y < 0.02 || y > 0.98));
        P[2 * i] = x;
        P[2 * i + 1] = y;
    }
    P[2 * n] = -3e3;
    P[2 * n + 1] = -3e3;
    P[2 * n + 2] = 3e3;
    P[2 * n + 3] = -3e3;
    P[2 * n + 4] = 0.0;
    P[2 * n + 5] = 3e3;
    int32_t nt = 1;
    T[0] = n;
    T[1] = n + 1;
    T[2] = n + 2;
    dead[0] = 0;
    /* Bowyer-Watson, O(n^2): the cavity's boundary edges, then a fan */
    for (int32_t p = 0; p < n; p++) {
        int32_t ne = 0;
        for (int32_t t = 0; t < nt; t++) {
            if (dead[t] || !gen_incircle(P + 2 * T[3 * t], P + 2 * T[3 * t + 1],
                                         P + 2 * T[3 * t + 2], P + 2 * p))
                continue;
            dead[t] = 1;
            for (int k = 0; k < 3; k++) {
                int32_t a = T[3 * t + k], b = T[3 * t + (k + 1) % 3], j;
                for (j = 0; j < ne; j++)
                    if (E[2 * j] == b && E[2 * j + 1] == a)
                        break;
                if (j < ne) { /* shared by two cavity triangles: inside */
                    E[2 * j] = E[2 * (ne - 1)];
                    E[2 * j + 1] = E[2 * (ne - 1) + 1];
                    ne--;
                } else {
                    E[2 * ne] = a;
                    E[2 * ne + 1] = b;
                    ne++;
                }
            }
        }
        int32_t w = 0; /* compact */
        for (int32_t t = 0; t < nt; t++)
            if (!dead[t]) {
                memmove(T + 3 * w, T + 3 * t, 3 * sizeof *T);
                dead[w++] = 0;
            }
        nt = w;
        if (nt + ne > cap)
            goto done;
        for (int32_t j = 0; j < ne; j++) {
            T[3 * nt] = E[2 * j];
            T[3 * nt + 1] = E[2 * j + 1];
            T[3 * nt + 2] = p;
            dead[nt++] = 0;
        }
    }
    int32_t nf = 0;
    for (int32_t t = 0; t < nt; t++)
        nf += T[3 * t] < n && T[3 * t + 1] < n && T[3 * t + 2] < n;
    m = gen_alloc(n, nf);
    if (!m.V)
        goto done;
    for (int32_t i = 0; i < n; i++) {
        m.V[3 * i] = stretch * P[2 * i];
        m.V[3 * i + 1] = P[2 * i + 1];
        m.V[3 * i + 2] = 0.0;
    }
    nf = 0;
    for (int32_t t = 0; t < nt; t++)
        if (T[3 * t] < n && T[3 * t + 1] < n && T[3 * t + 2] < n) {
            set_face(m.F + 3 * nf, T[3 * t], T[3 * t + 1], T[3 * t + 2]);
            nf++;
        }
done:
    free(P);
    free(T);
    free(E);
    free(dead);
    return m;
}
