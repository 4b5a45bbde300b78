/* A mesh's read-only tables for the exact solver (exact.h): face records in
 * the frames of their edges, fans of corners around each vertex, least
 * heights, the half-edges of non-manifold edges; built once per mesh and
 * shared by every workspace. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "state.h"

void mfmm_exact_tables_destroy(mfmm_exact_tables *t)
{
    if (!t)
        return;
    free(t->face_in);
    free(t->fr_block);
    free(t->pseudo);
    free(t->fan_a0);
    free(t->fan_total);
    free(t->height);
    free(t->nm_he);
    free(t->nm_next);
    free(t);
}

/* A half-edge at a wall, by its edge's vertices (ex_link_nonmanifold). */
typedef struct ex_wall {
    int32_t lo, hi, h;
} ex_wall;

static int ex_wall_cmp(const void *pa, const void *pb)
{
    const ex_wall *a = pa, *b = pb;
    if (a->lo != b->lo)
        return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi)
        return a->hi < b->hi ? -1 : 1;
    return (a->h > b->h) - (a->h < b->h);
}

static int ex_i32_pair_cmp(const void *pa, const void *pb)
{
    const int32_t *a = pa, *b = pb;
    return (a[0] > b[0]) - (a[0] < b[0]);
}

/* Non-manifold edges (three or more faces, copies aside) join every face on
 * them: a shortest path may cross from any of them into any other. Their
 * half-edges (across -1) get flip 2 and a place in a cycle per edge
 * (nm_he, nm_next), which ex_fan_out walks. As walls, they would make a
 * path through one bend at a vertex, too long. 0, or
 * -1 when out of memory. */
static int ex_link_nonmanifold(mfmm_exact_tables *t)
{
    size_t n = 0;
    for (int32_t f = 0; f < t->nf; f++)
        for (int k = 0; k < 3; k++)
            n += t->fr[t->face_in[f]].across[k] == -1 && !mfmm_mesh_copy(t->mesh, f);
    if (n == 0)
        return 0;
    ex_wall *w = malloc(n * sizeof *w);
    if (!w)
        return -1;
    n = 0;
    /* copies aside, zero-area ones too (skip 1 then), as build_edges has it */
    for (int32_t f = 0; f < t->nf; f++) {
        const ex_face *r = t->fr + t->face_in[f];
        for (int k = 0; k < 3; k++) {
            if (r->across[k] != -1 || mfmm_mesh_copy(t->mesh, f))
                continue;
            int32_t a = r->v[ex_next[k]], b = r->v[ex_prev[k]];
            w[n].lo = a < b ? a : b;
            w[n].hi = a < b ? b : a;
            w[n].h = 3 * t->face_in[f] + k;
            n++;
        }
    }
    qsort(w, n, sizeof *w, ex_wall_cmp);
    size_t n_nm = 0;
    for (size_t i = 0, j; i < n; i = j) {
        for (j = i + 1; j < n && w[j].lo == w[i].lo && w[j].hi == w[i].hi; j++)
            ;
        if (j - i > 1)
            n_nm += j - i;
    }
    if (n_nm == 0) { /* boundary edges only */
        free(w);
        return 0;
    }
    int32_t *pairs = malloc(2 * n_nm * sizeof *pairs);
    t->nm_he = malloc(n_nm * sizeof *t->nm_he);
    t->nm_next = malloc(n_nm * sizeof *t->nm_next);
    if (!pairs || !t->nm_he || !t->nm_next) {
        free(w);
        free(pairs);
        return -1;
    }
    size_t q = 0;
    for (size_t i = 0, j; i < n; i = j) {
        for (j = i + 1; j < n && w[j].lo == w[i].lo && w[j].hi == w[i].hi; j++)
            ;
        if (j - i < 2)
            continue;
        for (size_t u = i; u < j; u++) {
            pairs[2 * q] = w[u].h;
            pairs[2 * q + 1] = w[u + 1 < j ? u + 1 : i].h;
            q++;
            t->fr[w[u].h / 3].flip[w[u].h % 3] = 2;
        }
    }
    free(w);
    qsort(pairs, n_nm, 2 * sizeof *pairs, ex_i32_pair_cmp);
    for (size_t i = 0; i < n_nm; i++) {
        t->nm_he[i] = pairs[2 * i];
        t->nm_next[i] = pairs[2 * i + 1];
    }
    free(pairs);
    t->n_nm = (int32_t)n_nm;
    t->bytes += 2 * n_nm * sizeof(int32_t);
    return 0;
}

/* Makes every edge shorter than EX_SHORT_EDGE times the longest edge of a
 * face at either end a wall, its ends pseudo-sources that start windows all
 * around (their fans are then open: ex_build_fans). A window crossing a face
 * goes on in the frame of the edge it leaves, whose direction comes from
 * the corners' positions in the face's frame, exact to rounding of the
 * face's longest edge: for an edge 2e-15 long in a face 0.06 long that is a
 * turn of a few per cent, and distances below the straight line beyond it.
 * A path through the short edge is then one through an end of it, longer by
 * at most twice its length. */
static void ex_wall_short_edges(mfmm_exact_tables *t)
{
    double *reach = t->height; /* scratch (nv), filled later */
    for (int32_t v = 0; v < t->nv; v++) {
        double m = 0.0;
        for (int32_t i = t->vf_offset[v]; i < t->vf_offset[v + 1]; i++) {
            const ex_face *r = t->fr + ex_corner(t->vf_corner, t->face_in, i) / 3;
            m = fmax(m, fmax(r->len[0], fmax(r->len[1], r->len[2])));
        }
        reach[v] = m;
    }
    for (int32_t f = 0; f < t->nf; f++) {
        ex_face *r = t->fr + f;
        if (r->skip == 2)
            continue;
        for (int k = 0; k < 3; k++) {
            int32_t a = r->v[ex_next[k]], b = r->v[ex_prev[k]];
            if (r->len[k] >= EX_SHORT_EDGE * fmax(reach[a], reach[b]))
                continue;
            r->across[k] = -1;
            r->flip[k] = 0;
            t->pseudo[a] = 1;
            t->pseudo[b] = 1;
        }
    }
}

/* Walks the fan of every vertex through the faces across its edges, giving
 * each corner its angles (fan_a0, fan_sgn) and each vertex its angle sum;
 * NaN for vertices whose corners do not form one closed disk. */
static void ex_build_fans(mfmm_exact_tables *t)
{
    for (int32_t v = 0; v < t->nv; v++) {
        /* copies (skip 2) apart; a zero-area face (skip 1) ends the fan */
        int32_t n_c = 0, c0 = -1;
        int ok = 1;
        t->fan_total[v] = NAN;
        for (int32_t i = t->vf_offset[v]; i < t->vf_offset[v + 1]; i++) {
            int32_t c = ex_corner(t->vf_corner, t->face_in, i);
            if (t->fr[c / 3].skip == 1)
                ok = 0;
            if (t->fr[c / 3].skip == 0) {
                c0 = c0 < 0 ? c : c0;
                n_c++;
            }
        }
        if (!ok || n_c < 3)
            continue;
        int32_t f = c0 / 3, k = c0 % 3;
        int32_t ent = t->fr[f].v[(k + 1) % 3];
        double e = 0.0;
        int32_t steps = 0;
        for (;;) {
            const int32_t *fv = t->fr[f].v;
            int32_t c = 3 * f + k, far;
            int kent;
            if (fv[(k + 1) % 3] == ent) {
                t->fan_a0[c] = e;
                t->fr[f].sgn[k] = 1;
                far = fv[(k + 2) % 3];
                kent = (k + 1) % 3;
            } else {
                t->fan_a0[c] = e + t->fr[f].angle[k];
                t->fr[f].sgn[k] = -1;
                far = fv[(k + 1) % 3];
                kent = (k + 2) % 3;
            }
            e += t->fr[f].angle[k];
            steps++;
            int32_t nx = t->fr[f].across[kent];
            if (nx < 0 || steps > n_c) {
                ok = 0;
                break;
            }
            f = nx / 3;
            k = ex_corner_of(t->fr[f].v, v);
            ent = far;
            if (k < 0) {
                ok = 0;
                break;
            }
            if (3 * f + k == c0) {
                ok = steps == n_c && t->fr[f].v[(k + 1) % 3] == ent;
                break;
            }
        }
        if (ok)
            t->fan_total[v] = e;
    }
}

size_t mfmm_exact_tables_bytes(const mfmm_mesh *mesh)
{
    size_t nv = (size_t)mesh->nv, nf = (size_t)mesh->nf;
    return sizeof(mfmm_exact_tables) + nf * sizeof(ex_face) + 64 +
           nf * (sizeof(int32_t) + 3 * sizeof(double)) +
           nv * (1 + 2 * sizeof(double));
}

/* A zero-area face's corners on one line (ex_pass): positions along its
 * longest edge, so that no corner lands on the others through the frame of
 * a short edge (a needle 2e-15 wide put its far corner on the near ones, a
 * path of length 0 across it). In the frame of edge k (corner k+1 at 0,
 * facing corner k+2), corner k is at cx[k]. */
static void ex_lay_on_line(const double *X, ex_face *r)
{
    int m = 0;
    for (int k = 1; k < 3; k++)
        if (r->len[k] > r->len[m])
            m = k;
    double L = r->len[m];
    if (!(L > 0.0) || !isfinite(L)) {
        /* all corners at one point: nothing passes through (ex_pass) */
        for (int k = 0; k < 3; k++)
            r->cx[k] = NAN;
        return;
    }
    const double *a = X + 3 * (size_t)r->v[ex_next[m]], *b = X + 3 * (size_t)r->v[ex_prev[m]];
    double u[3] = {(b[0] - a[0]) / L, (b[1] - a[1]) / L, (b[2] - a[2]) / L}, t[3];
    for (int j = 0; j < 3; j++) {
        const double *c = X + 3 * (size_t)r->v[j];
        t[j] = (c[0] - a[0]) * u[0] + (c[1] - a[1]) * u[1] + (c[2] - a[2]) * u[2];
    }
    for (int k = 0; k < 3; k++) {
        double t1 = t[ex_next[k]], t2 = t[ex_prev[k]];
        r->cx[k] = (t[k] - t1) * (t2 >= t1 ? 1.0 : -1.0);
        r->cy[k] = 0.0;
    }
}

mfmm_status mfmm_exact_tables_create(const mfmm_mesh *mesh, mfmm_exact_tables **out)
{
    if (!out)
        return MFMM_ERR_NULL_POINTER;
    *out = NULL;
    if (!mesh)
        return MFMM_ERR_NULL_POINTER;
    if (mesh->nf > INT32_MAX / 3 - 1 || (size_t)mesh->nf > (SIZE_MAX - 64) / sizeof(ex_face))
        return MFMM_ERR_BAD_COUNT;
    mfmm_exact_tables *t = calloc(1, sizeof *t);
    if (!t)
        return MFMM_ERR_OUT_OF_MEMORY;
    size_t nv = (size_t)mesh->nv, nf = (size_t)mesh->nf, nh = 3 * nf;
    t->mesh = mesh;
    t->nv = mesh->nv;
    t->nf = mesh->nf;
    t->vf_offset = mesh->vertex_face_offset;
    t->fr_block = malloc((nf ? nf : 1) * sizeof(ex_face) + 64);
    if (t->fr_block) {
        uintptr_t a = (uintptr_t)t->fr_block;
        t->fr = (ex_face *)(void *)((char *)t->fr_block + ((64 - a % 64) % 64));
    }
    t->vf_corner = mesh->vertex_wedge;
    t->face_in = malloc((nf ? nf : 1) * sizeof *t->face_in);
    t->pseudo = calloc(nv ? nv : 1, sizeof *t->pseudo);
    double *angle = calloc(nv ? nv : 1, sizeof *angle);
    /* counting sort of the faces by their least vertex: cnt (nv + 1) */
    int32_t *cnt = calloc(nv + 1, sizeof *cnt);
    t->fan_a0 = malloc((nh ? nh : 1) * sizeof *t->fan_a0);
    t->fan_total = malloc((nv ? nv : 1) * sizeof *t->fan_total);
    t->height = malloc((nv ? nv : 1) * sizeof *t->height);
    if (!t->fr_block || !t->face_in || !t->pseudo || !angle || !cnt ||
        !t->fan_a0 || !t->fan_total || !t->height) {
        free(angle);
        free(cnt);
        mfmm_exact_tables_destroy(t);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    t->bytes = mfmm_exact_tables_bytes(mesh);
    const double *X = mesh->xyz;
    const mfmm_face *F = mesh->face_records;
    for (size_t f = 0; f < nf; f++) {
        const int32_t *fv = F[f].v;
        int32_t lo = fv[0] < fv[1] ? fv[0] : fv[1];
        cnt[(lo < fv[2] ? lo : fv[2]) + 1]++;
    }
    for (size_t v = 0; v < nv; v++)
        cnt[v + 1] += cnt[v];
    for (size_t f = 0; f < nf; f++) {
        const int32_t *fv = F[f].v;
        int32_t lo = fv[0] < fv[1] ? fv[0] : fv[1];
        t->face_in[f] = cnt[lo < fv[2] ? lo : fv[2]]++;
    }
    free(cnt);
    for (size_t f = 0; f < nf; f++) {
        const int32_t *fv = F[f].v;
        int bad = mfmm_mesh_degenerate(mesh, (int32_t)f);
        ex_face *r = t->fr + t->face_in[f];
        memset(r, 0, sizeof *r);
        for (int k = 0; k < 3; k++) {
            r->len[k] = vdist(X + 3 * (size_t)fv[(k + 1) % 3], X + 3 * (size_t)fv[(k + 2) % 3]);
            r->v[k] = fv[k];
        }
        for (int k = 0; k < 3; k++) {
            /* corner k in the frame of the opposite edge, from the vectors
             * (not the law of cosines: that loses about (L / y)^2 eps of y
             * in a needle, 1e-7 for a 1e-6 wide one) */
            double L = r->len[k];
            const double *a = X + 3 * (size_t)fv[(k + 1) % 3], *b = X + 3 * (size_t)fv[(k + 2) % 3],
                         *c = X + 3 * (size_t)fv[k];
            /* e a unit vector, so that no product is a length to the 4th
             * power (which underflows at 1e-90 and overflows at 1e90) */
            double e[3] = {(b[0] - a[0]) / L, (b[1] - a[1]) / L, (b[2] - a[2]) / L};
            double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
            double cr[3] = {e[1] * w[2] - e[2] * w[1], e[2] * w[0] - e[0] * w[2],
                            e[0] * w[1] - e[1] * w[0]};
            double x = e[0] * w[0] + e[1] * w[1] + e[2] * w[2];
            double y = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
            r->cx[k] = x;
            r->cy[k] = y;
            if (!(L > 0.0) || !(y > 0.0) || !isfinite(x) || !isfinite(y))
                bad = 1;
        }
        if (bad)
            ex_lay_on_line(X, r);
        r->skip = (uint8_t)(bad ? 1 : mfmm_mesh_copy(mesh, (int32_t)f) ? 2 : 0);
    }
    for (size_t f = 0; f < nf; f++) {
        const int32_t *fv = F[f].v;
        ex_face *r = t->fr + t->face_in[f];
        for (int k = 0; k < 3; k++) {
            int32_t g = mesh->face_neighbor[3 * f + k];
            r->across[k] = -1;
            r->flip[k] = 0;
            if (g < 0 || r->skip == 2 || t->fr[t->face_in[g]].skip == 2)
                continue;
            int32_t a = fv[(k + 1) % 3], b = fv[(k + 2) % 3];
            const int32_t *gv = F[g].v;
            for (int m = 0; m < 3; m++) {
                if (gv[m] != a && gv[m] != b) {
                    /* into a zero-area face: -2 - its half-edge (ex_pass) */
                    int32_t hg = 3 * t->face_in[g] + m;
                    r->across[k] = t->fr[t->face_in[g]].skip ? -2 - hg : hg;
                    r->flip[k] = gv[(m + 1) % 3] != a;
                }
            }
        }
    }
    /* pseudo-source candidates: saddles, vertices at a wall, and vertices of
     * zero-area faces; unreferenced vertices have nothing to start */
    for (size_t f = 0; f < nf; f++) {
        const ex_face *r = t->fr + f;
        const int32_t *fv = r->v;
        if (r->skip) {
            for (int k = 0; k < 3 && r->skip == 1; k++)
                t->pseudo[fv[k]] = 1;
            continue;
        }
        for (int k = 0; k < 3; k++) {
            /* angle at corner k, seen in the frame of the opposite edge */
            double x = r->cx[k], y = r->cy[k], L = r->len[k];
            double a = atan2(y * L, y * y - x * (L - x));
            t->fr[f].angle[k] = a;
            angle[fv[k]] += a;
            if (r->across[k] < 0) { /* a wall, or a zero-area face */
                t->pseudo[fv[(k + 1) % 3]] = 1;
                t->pseudo[fv[(k + 2) % 3]] = 1;
            }
        }
    }
    for (size_t v = 0; v < nv; v++)
        if (angle[v] > EX_TWO_PI + EX_SADDLE_TOL)
            t->pseudo[v] = 1;
    free(angle);
    if (ex_link_nonmanifold(t) != 0) {
        mfmm_exact_tables_destroy(t);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    ex_wall_short_edges(t);
    double sum_len = 0.0;
    size_t n_len = 0;
    for (size_t hh = 0; hh < nh; hh++) {
        if (!t->fr[hh / 3].skip) {
            sum_len += t->fr[hh / 3].len[hh % 3];
            n_len++;
        }
    }
    double width = n_len ? EX_BUCKET_WIDTH * sum_len / (double)n_len : 1.0;
    t->inv_w = width > 0.0 && isfinite(1.0 / width) ? 1.0 / width : 1.0;
    ex_build_fans(t);
    /* a vertex whose faces are not one closed fan (several fans meeting at
     * it, as two copies of a face make a closed fan of their own) joins
     * parts of the surface that share no edge: only a pseudo-source there
     * carries distances from one part to the other (a fuzzed mesh's doubled
     * face left d(20) 0.10 above d(27) + |20 27|) */
    for (size_t v = 0; v < nv; v++)
        if (t->vf_offset[v + 1] > t->vf_offset[v] && isnan(t->fan_total[v]))
            t->pseudo[v] = 1;
    for (size_t v = 0; v < nv; v++) {
        double h = INFINITY;
        for (int32_t j = t->vf_offset[v]; j < t->vf_offset[v + 1]; j++) {
            int32_t c = ex_corner(t->vf_corner, t->face_in, j);
            const ex_face *r = t->fr + c / 3;
            if (r->skip == 1) {
                /* a path may reach v along a zero-area face's edge, or
                 * through it from a face that has v on an edge (ex_pass):
                 * no height bounds its last segment */
                h = 0.0;
                break;
            }
            if (!r->skip && r->cy[c % 3] < h)
                h = r->cy[c % 3];
        }
        t->height[v] = h;
    }
    for (int32_t f = 0; f < t->nf; f++) {
        ex_face *r = t->fr + f;
        r->tie = 0;
        for (int k = 0; k < 3; k++)
            r->tie |= (uint8_t)((t->pseudo[r->v[k]] ? 0 : 1) << k);
    }
    *out = t;
    return MFMM_OK;
}

static void tables_free(void *t)
{
    mfmm_exact_tables_destroy(t);
}

mfmm_status mfmm_exact_tables_of(const mfmm_mesh *mesh, const mfmm_exact_tables **out)
{
    if (!out)
        return MFMM_ERR_NULL_POINTER;
    *out = NULL;
    if (!mesh)
        return MFMM_ERR_NULL_POINTER;
    /* the mesh's cache is the one mutable part of a built mesh (mesh.h) */
    mfmm_mesh *m = (mfmm_mesh *)(uintptr_t)mesh;
    mfmm_status st = MFMM_OK;
    pthread_mutex_lock(&m->cache_lock);
    if (!m->exact_tables) {
        mfmm_exact_tables *t = NULL;
        st = mfmm_exact_tables_create(mesh, &t);
        if (st == MFMM_OK) {
            m->exact_tables = t;
            m->exact_tables_free = tables_free;
            m->exact_tables_bytes = t->bytes;
        }
    }
    *out = m->exact_tables;
    pthread_mutex_unlock(&m->cache_lock);
    return st;
}
