/* A mesh's read-only tables for the exact solver (exact.h): face records in
 * the frames of their edges, fans of corners around each vertex, least
 * heights, the half-edges of non-manifold edges; made once per mesh,
 * built tile by tile where runs need them, and shared by every workspace. */
#include <math.h>
#include <pthread.h>
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
    free(t->rec_face);
    free(t->tile_rec);
    free(t->tile_state);
    free(t->vertex_done);
    free(t->tile_box);
    free(t->group_box);
    free(t->group_left);
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

/* A face's skip flag from the mesh alone (ex_face.skip): 1 zero area, 2 a
 * copy. The records' own test also checks their frames, which the mesh's
 * test of zero area implies (mesh/build.c: twice the area above 64 eps
 * times the longest edge squared leaves every height above 60 eps times it). */
/* Record i's mesh face, and face f's record: the identity unless pieces
 * of faces cut at T-junctions moved them (rec_face NULL then; face_in's
 * entries are then set tile by tile, for the workspaces' reads). */
static int32_t ex_face_of(const mfmm_exact_tables *t, int32_t i)
{
    return t->rec_face ? t->rec_face[i] : i;
}

static int32_t ex_record_of(const mfmm_exact_tables *t, int32_t f)
{
    return t->rec_face ? t->face_in[f] : f;
}

/* ex_corner for the tables' builders, which read records not built yet. */
static int32_t ex_corner_of_entry(const mfmm_exact_tables *t, int32_t i)
{
    int32_t w = t->vf_corner[i];
    return 3 * ex_record_of(t, MFMM_WEDGE_FACE(w)) + MFMM_WEDGE_K(w);
}

static int ex_mesh_skip(const mfmm_mesh *mesh, int32_t f)
{
    return mfmm_mesh_degenerate(mesh, f) ? 1 : mfmm_mesh_copy(mesh, f) ? 2 : 0;
}

/* Non-manifold edges (three or more faces, copies aside) join every face on
 * them: a shortest path may cross from any of them into any other. Their
 * half-edges (no face across, ex_build_faces) get flip 2 and a place in a
 * cycle per edge (nm_he, nm_next), which ex_fan_out walks. As walls, they
 * would make a path through one bend at a vertex, too long. 0, or -1 when
 * out of memory. */
static int ex_link_nonmanifold(mfmm_exact_tables *t)
{
    const mfmm_mesh *mesh = t->mesh;
    /* an edge with two faces (copies aside) has them across each other */
    if (mesh->info.n_nonmanifold_edges == 0 && mesh->info.n_duplicate_faces == 0)
        return 0;
    size_t n = 0;
    for (int32_t f = 0; f < t->nf; f++)
        for (int k = 0; k < 3; k++)
            n += mesh->face_neighbor[3 * (size_t)f + k] < 0 && !mfmm_mesh_copy(mesh, f);
    if (n == 0)
        return 0;
    ex_wall *w = malloc(n * sizeof *w);
    if (!w)
        return -1;
    n = 0;
    /* copies aside, zero-area ones too, as build_edges has it */
    for (int32_t f = 0; f < t->nf; f++) {
        const int32_t *fv = mesh->face_records[f].v;
        for (int k = 0; k < 3; k++) {
            if (mesh->face_neighbor[3 * (size_t)f + k] >= 0 || mfmm_mesh_copy(mesh, f))
                continue;
            int32_t a = fv[ex_next[k]], b = fv[ex_prev[k]];
            w[n].lo = a < b ? a : b;
            w[n].hi = a < b ? b : a;
            w[n].h = 3 * ex_record_of(t, f) + k;
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
    return 0;
}

/* The longest edge of the faces at v, from the coordinates as the records
 * have them (ex_build_faces). */
static double ex_reach(const mfmm_exact_tables *t, int32_t v)
{
    const double *X = t->mesh->xyz;
    double m = 0.0;
    for (int32_t i = t->vf_offset[v]; i < t->vf_offset[v + 1]; i++) {
        const int32_t *fv = t->mesh->face_records[MFMM_WEDGE_FACE(t->vf_corner[i])].v;
        for (int k = 0; k < 3; k++)
            m = fmax(m, vdist(X + 3 * (size_t)fv[(k + 1) % 3], X + 3 * (size_t)fv[(k + 2) % 3]));
    }
    return m;
}

/* Makes an edge shorter than EX_SHORT_EDGE times the longest edge of a face
 * at either end a wall, its ends pseudo-sources that start windows all
 * around (their fans are then open: ex_build_fan). A window crossing a face
 * goes on in the frame of the edge it leaves, whose direction comes from
 * the corners' positions in the face's frame, exact to rounding of the
 * face's longest edge: for an edge 2e-15 long in a face 0.06 long that is a
 * turn of a few per cent, and distances below the straight line beyond it.
 * A path through the short edge is then one through an end of it, longer by
 * at most twice its length. */
static void ex_wall_short_edge(const mfmm_exact_tables *t, ex_face *r, int k)
{
    if (r->skip == 2 || r->len[k] >= t->short_len)
        return;
    int32_t a = r->v[ex_next[k]], b = r->v[ex_prev[k]];
    if (r->len[k] >= EX_SHORT_EDGE * fmax(ex_reach(t, a), ex_reach(t, b)))
        return;
    r->across[k] = -1;
    r->flip[k] = 0;
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

/* The first record of tile T (tile_rec), found once: faces are in the
 * order of their least vertex, their records too (mfmm_exact_tables_create). */
static int32_t ex_tile_first(mfmm_exact_tables *t, int32_t T)
{
    if (t->tile_rec[T] >= 0)
        return t->tile_rec[T];
    int32_t v0 = T * EX_TILE, lo = 0, hi = t->nf;
    while (lo < hi) {
        int32_t mid = lo + (hi - lo) / 2;
        const int32_t *fv = t->mesh->face_records[ex_face_of(t, mid)].v;
        int32_t least = fv[0] < fv[1] ? fv[0] : fv[1];
        if ((least < fv[2] ? least : fv[2]) < v0)
            lo = mid + 1;
        else
            hi = mid;
    }
    return t->tile_rec[T] = lo;
}

/* The tile of record i: its face's least vertex's. */
static int32_t ex_tile_of_record(const mfmm_exact_tables *t, int32_t i)
{
    const int32_t *fv = t->mesh->face_records[ex_face_of(t, i)].v;
    int32_t least = fv[0] < fv[1] ? fv[0] : fv[1];
    return (least < fv[2] ? least : fv[2]) / EX_TILE;
}

/* Tile T's face records: the corners in the frames of the opposite edges,
 * lengths and angles, the faces across, non-manifold and short edges. */
static void ex_build_faces(mfmm_exact_tables *t, int32_t T)
{
    if (t->tile_state[T] & EX_TILE_FACES)
        return;
    const mfmm_mesh *mesh = t->mesh;
    const double *X = mesh->xyz;
    const mfmm_face *F = mesh->face_records;
    int32_t i0 = ex_tile_first(t, T), i1 = T + 1 < t->n_tiles ? ex_tile_first(t, T + 1) : t->nf;
    for (int32_t i = i0; i < i1; i++) {
        int32_t f = ex_face_of(t, i);
        const int32_t *fv = F[f].v;
        if (!t->rec_face)
            t->face_in[f] = f;
        int bad = mfmm_mesh_degenerate(mesh, f);
        ex_face *r = t->fr + i;
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
        r->skip = (uint8_t)(bad ? 1 : mfmm_mesh_copy(mesh, f) ? 2 : 0);
        for (int k = 0; k < 3; k++) {
            int32_t g = mesh->face_neighbor[3 * (size_t)f + k];
            r->across[k] = -1;
            r->flip[k] = 0;
            int gskip = g < 0 ? 0 : ex_mesh_skip(mesh, g);
            if (g >= 0 && r->skip != 2 && gskip != 2) {
                int32_t a = fv[(k + 1) % 3], b = fv[(k + 2) % 3];
                const int32_t *gv = F[g].v;
                for (int m = 0; m < 3; m++) {
                    if (gv[m] != a && gv[m] != b) {
                        /* into a zero-area face: -2 - its half-edge (ex_pass) */
                        int32_t hg = 3 * ex_record_of(t, g) + m;
                        r->across[k] = gskip ? -2 - hg : hg;
                        r->flip[k] = gv[(m + 1) % 3] != a;
                    }
                }
            }
            if (r->across[k] == -1 && ex_nm_find(t->nm_he, t->n_nm, 3 * i + k) >= 0)
                r->flip[k] = 2;
            ex_wall_short_edge(t, r, k);
        }
        if (!r->skip)
            for (int k = 0; k < 3; k++) {
                /* angle at corner k, seen in the frame of the opposite edge */
                double x = r->cx[k], y = r->cy[k], L = r->len[k];
                r->angle[k] = atan2(y * L, y * y - x * (L - x));
            }
    }
    t->tile_state[T] |= EX_TILE_FACES;
    t->bytes += (size_t)(i1 - i0) *
                (sizeof(ex_face) + 3 * sizeof(double) + (t->rec_face ? 0 : sizeof(int32_t)));
}

/* Walks the fan of v through the faces across its edges, giving each
 * corner its angles (fan_a0, fan_sgn) and v its angle sum; NaN where v's
 * corners do not form one closed disk. */
static void ex_build_fan(mfmm_exact_tables *t, int32_t v)
{
    /* copies (skip 2) apart; a zero-area face (skip 1) ends the fan */
    int32_t n_c = 0, c0 = -1;
    int ok = 1;
    t->fan_total[v] = NAN;
    for (int32_t i = t->vf_offset[v]; i < t->vf_offset[v + 1]; i++) {
        int32_t c = ex_corner_of_entry(t, i);
        if (t->fr[c / 3].skip == 1)
            ok = 0;
        if (t->fr[c / 3].skip == 0) {
            c0 = c0 < 0 ? c : c0;
            n_c++;
        }
    }
    if (!ok || n_c < 3)
        return;
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

/* Vertex v's fan, least height, and whether it may bend a path (pseudo):
 * a saddle, at a wall or on a zero-area face, or where its faces are not
 * one closed fan (several fans meeting at it, as two copies of a face make
 * a closed fan of their own, join parts of the surface that share no edge:
 * only a pseudo-source there carries distances from one part to the
 * other). Builds the records of every face at v first. */
static void ex_build_vertex(mfmm_exact_tables *t, int32_t v)
{
    if (t->vertex_done[v])
        return;
    for (int32_t i = t->vf_offset[v]; i < t->vf_offset[v + 1]; i++)
        ex_build_faces(t, ex_tile_of_record(t, ex_corner_of_entry(t, i) / 3));
    int pseudo = 0;
    double sum = 0.0, h = INFINITY;
    for (int32_t i = t->vf_offset[v]; i < t->vf_offset[v + 1]; i++) {
        int32_t c = ex_corner_of_entry(t, i);
        const ex_face *r = t->fr + c / 3;
        int k = c % 3;
        if (r->skip == 1) {
            /* a path may reach v along a zero-area face's edge, or through
             * it from a face that has v on an edge (ex_pass): no height
             * bounds its last segment */
            pseudo = 1;
            h = 0.0;
        } else if (r->skip == 0) {
            sum += r->angle[k];
            pseudo |= r->across[ex_next[k]] < 0 || r->across[ex_prev[k]] < 0;
            h = fmin(h, r->cy[k]);
        }
    }
    ex_build_fan(t, v);
    if (sum > EX_TWO_PI + EX_SADDLE_TOL ||
        (t->vf_offset[v + 1] > t->vf_offset[v] && isnan(t->fan_total[v])))
        pseudo = 1;
    t->pseudo[v] = (uint8_t)pseudo;
    t->height[v] = h;
    t->vertex_done[v] = 1;
    t->bytes += 2 + 2 * sizeof(double);
}

/* Tile T ready to be read: its records, and the fans and flags of their
 * vertices (and so the records of every face at those). */
static void ex_build_tile(mfmm_exact_tables *t, int32_t T)
{
    int32_t i0 = ex_tile_first(t, T), i1 = T + 1 < t->n_tiles ? ex_tile_first(t, T + 1) : t->nf;
    ex_build_faces(t, T);
    for (int32_t i = i0; i < i1; i++)
        for (int k = 0; k < 3; k++)
            ex_build_vertex(t, t->fr[i].v[k]);
    for (int32_t i = i0; i < i1; i++) {
        ex_face *r = t->fr + i;
        r->tie = 0;
        for (int k = 0; k < 3; k++)
            r->tie |= (uint8_t)((t->pseudo[r->v[k]] ? 0 : 1) << k);
    }
}

size_t mfmm_exact_tables_bytes(const mfmm_mesh *mesh)
{
    size_t nv = (size_t)mesh->nv, nf = (size_t)mesh->nf;
    size_t n_tiles = (nv + EX_TILE - 1) / EX_TILE;
    return sizeof(mfmm_exact_tables) + nf * sizeof(ex_face) + 64 +
           nf * ((mesh->piece_next ? 2 : 1) * sizeof(int32_t) + 3 * sizeof(double)) +
           nv * (2 + 2 * sizeof(double)) + n_tiles * (sizeof(int32_t) + 1 + 6 * sizeof(double)) +
           (n_tiles / EX_GROUP + 1) * (sizeof(int32_t) + 6 * sizeof(double));
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
    t->vf_corner = mesh->vertex_wedge;
    t->n_tiles = (int32_t)((nv + EX_TILE - 1) / EX_TILE);
    size_t n_tiles = (size_t)t->n_tiles;
    /* the arrays that tiles fill are left untouched (their pages unused)
     * until a tile is built */
    t->fr_block = malloc((nf ? nf : 1) * sizeof(ex_face) + 64);
    if (t->fr_block) {
        uintptr_t a = (uintptr_t)t->fr_block;
        t->fr = (ex_face *)(void *)((char *)t->fr_block + ((64 - a % 64) % 64));
    }
    t->face_in = malloc((nf ? nf : 1) * sizeof *t->face_in);
    t->pseudo = malloc(nv ? nv : 1);
    t->fan_a0 = malloc((nh ? nh : 1) * sizeof *t->fan_a0);
    t->fan_total = malloc((nv ? nv : 1) * sizeof *t->fan_total);
    t->height = malloc((nv ? nv : 1) * sizeof *t->height);
    t->tile_rec = malloc((n_tiles + 1) * sizeof *t->tile_rec);
    t->tile_state = calloc(n_tiles ? n_tiles : 1, 1);
    t->vertex_done = calloc(nv ? nv : 1, 1);
    t->tile_box = malloc((n_tiles ? n_tiles : 1) * 6 * sizeof *t->tile_box);
    t->n_groups = (int32_t)((n_tiles + EX_GROUP - 1) / EX_GROUP);
    t->group_box = malloc((t->n_groups ? (size_t)t->n_groups : 1) * 6 * sizeof *t->group_box);
    t->group_left = malloc((t->n_groups ? (size_t)t->n_groups : 1) * sizeof *t->group_left);
    if (!t->fr_block || !t->face_in || !t->pseudo || !t->fan_a0 || !t->fan_total ||
        !t->height || !t->tile_rec || !t->tile_state || !t->vertex_done || !t->tile_box ||
        !t->group_box || !t->group_left) {
        mfmm_exact_tables_destroy(t);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
#if MFMM_POISON_UNBUILT
    /* vertex ids -1 and NaN lengths: a run that reads a tile it did not
     * build faults under the sanitizers instead of reading zeros */
    memset(t->fr_block, 0xff, (nf ? nf : 1) * sizeof(ex_face) + 64);
    memset(t->fan_a0, 0xff, (nh ? nh : 1) * sizeof *t->fan_a0);
    memset(t->pseudo, 0xff, nv ? nv : 1);
    memset(t->fan_total, 0xff, (nv ? nv : 1) * sizeof *t->fan_total);
    memset(t->height, 0xff, (nv ? nv : 1) * sizeof *t->height);
#endif
    const mfmm_face *F = mesh->face_records;
    for (size_t T = 0; T <= n_tiles; T++)
        t->tile_rec[T] = -1;
    if (!mesh->piece_next) {
        /* faces are in the order of their least vertex (order.h): records
         * in face order, found per tile when built (ex_tile_first) */
#if MFMM_POISON_UNBUILT
        memset(t->face_in, 0xff, (nf ? nf : 1) * sizeof *t->face_in);
#endif
    } else {
        /* pieces of faces cut at T-junctions follow the faces: a counting
         * sort of the faces by their least vertex, so that a patch's
         * records lie together in memory */
        int32_t *cnt = calloc(nv + 1, sizeof *cnt);
        t->rec_face = malloc((nf ? nf : 1) * sizeof *t->rec_face);
        if (!cnt || !t->rec_face) {
            free(cnt);
            mfmm_exact_tables_destroy(t);
            return MFMM_ERR_OUT_OF_MEMORY;
        }
        for (size_t f = 0; f < nf; f++) {
            const int32_t *fv = F[f].v;
            int32_t lo = fv[0] < fv[1] ? fv[0] : fv[1];
            cnt[(lo < fv[2] ? lo : fv[2]) + 1]++;
        }
        for (size_t v = 0; v < nv; v++)
            cnt[v + 1] += cnt[v];
        for (size_t T = 0; T < n_tiles; T++)
            t->tile_rec[T] = cnt[T * EX_TILE];
        for (size_t f = 0; f < nf; f++) {
            const int32_t *fv = F[f].v;
            int32_t lo = fv[0] < fv[1] ? fv[0] : fv[1];
            t->face_in[f] = cnt[lo < fv[2] ? lo : fv[2]]++;
            t->rec_face[t->face_in[f]] = (int32_t)f;
        }
        free(cnt);
    }
    for (size_t T = 0; T < n_tiles; T++) {
        /* comparisons, not fmin/fmax: those are calls (a third of the
         * first solve's set-up on a large mesh); coordinates are finite */
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t v = T * EX_TILE; v < (T + 1) * EX_TILE && v < nv; v++)
            for (int j = 0; j < 3; j++) {
                double x = mesh->xyz[3 * v + j];
                lo[j] = x < lo[j] ? x : lo[j];
                hi[j] = x > hi[j] ? x : hi[j];
            }
        memcpy(t->tile_box + 6 * T, lo, sizeof lo);
        memcpy(t->tile_box + 6 * T + 3, hi, sizeof hi);
    }
    for (int32_t G = 0; G < t->n_groups; G++) {
        double *b = t->group_box + 6 * G;
        int32_t T1 = (G + 1) * EX_GROUP < t->n_tiles ? (G + 1) * EX_GROUP : t->n_tiles;
        for (int j = 0; j < 3; j++) {
            b[j] = INFINITY;
            b[3 + j] = -INFINITY;
        }
        for (int32_t T = G * EX_GROUP; T < T1; T++)
            for (int j = 0; j < 3; j++) {
                double lo = t->tile_box[6 * T + j], hi = t->tile_box[6 * T + 3 + j];
                b[j] = lo < b[j] ? lo : b[j];
                b[3 + j] = hi > b[3 + j] ? hi : b[3 + j];
            }
        t->group_left[G] = T1 - G * EX_GROUP;
    }
    /* a tile's records lie within an edge of its vertices, the faces and
     * vertices they lead to within another, and a window may pass through
     * EX_MAX_PASS zero-area faces in a row (ex_pass) */
    double L = mesh->info.max_edge_length;
    t->pad = (3.0 + (mesh->info.n_degenerate_faces > 0 ? EX_MAX_PASS : 0)) * L;
    if (!isfinite(t->pad))
        t->pad = INFINITY;
    t->short_len = 2.0 * EX_SHORT_EDGE * L;
    if (!(t->short_len < INFINITY))
        t->short_len = INFINITY;
    double width = EX_BUCKET_WIDTH * mesh->info.mean_edge_length;
    t->inv_w = width > 0.0 && isfinite(1.0 / width) ? 1.0 / width : 1.0;
    if (ex_link_nonmanifold(t) != 0) {
        mfmm_exact_tables_destroy(t);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    t->full_bytes = mfmm_exact_tables_bytes(mesh) + 2 * (size_t)t->n_nm * sizeof(int32_t);
    t->bytes = t->full_bytes -
               nf * (sizeof(ex_face) + 3 * sizeof(double) + (t->rec_face ? 0 : sizeof(int32_t))) -
               nv * (2 + 2 * sizeof(double));
    *out = t;
    return MFMM_OK;
}

/* The distance from point p to tile T's box. */
static double ex_box_distance(const double *b, const double *p)
{
    double s = 0.0;
    for (int j = 0; j < 3; j++) {
        double d = fmax(b[j] - p[j], fmax(p[j] - b[3 + j], 0.0));
        s += d * d;
    }
    return sqrt(s);
}

int32_t ex_tiles_visit(const mfmm_exact_tables *t, uint8_t *state, uint8_t bit,
                       int32_t *group_left, const double *points, int32_t n, double reach,
                       void (*visit)(void *ctx, int32_t T), void *ctx)
{
    int all = !points || !(reach < INFINITY);
    int32_t visited = 0;
    for (int32_t G = 0; G < t->n_groups; G++) {
        int near = all;
        for (int32_t i = 0; i < n && !near && group_left[G] > 0; i++)
            near = ex_box_distance(t->group_box + 6 * G, points + 3 * i) <= reach;
        int32_t T1 = (G + 1) * EX_GROUP < t->n_tiles ? (G + 1) * EX_GROUP : t->n_tiles;
        for (int32_t T = G * EX_GROUP; near && group_left[G] > 0 && T < T1; T++) {
            if (state[T] & bit)
                continue;
            int in = all;
            for (int32_t i = 0; i < n && !in; i++)
                in = ex_box_distance(t->tile_box + 6 * T, points + 3 * i) <= reach;
            if (in) {
                visit(ctx, T);
                state[T] |= bit;
                group_left[G]--;
                visited++;
            }
        }
    }
    return visited;
}

static void ex_build_tile_visit(void *t, int32_t T)
{
    ex_build_tile(t, T);
}

void mfmm_exact_tables_ensure(const mfmm_exact_tables *tables, const double *points, int32_t n,
                              double radius)
{
    /* the tiles are the tables' one mutable part, guarded by the mesh's lock */
    mfmm_exact_tables *t = (mfmm_exact_tables *)(uintptr_t)tables;
    mfmm_mesh *m = (mfmm_mesh *)(uintptr_t)t->mesh;
    pthread_mutex_lock(&m->cache_lock);
    if (t->n_ready < t->n_tiles) {
        t->n_ready += ex_tiles_visit(t, t->tile_state, EX_TILE_READY, t->group_left, points, n,
                                     radius + t->pad, ex_build_tile_visit, t);
        if (m->exact_tables == t)
            m->exact_tables_bytes = t->bytes;
    }
    pthread_mutex_unlock(&m->cache_lock);
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
