/* src/exact/README -- exact polyhedral geodesic distances.
 *
 * Algorithm: window propagation of Chen & Han ("Shortest paths on a
 * polyhedron", SoCG 1990 / IJCGA 1996) with the pruning of Xin & Wang
 * ("Improving Chen and Han's algorithm on the discrete geodesic problem",
 * ACM TOG 28(4), 2009; "ICH"). Windows are not kept on edges and never
 * intersected with each other (unlike Mitchell, Mount & Papadimitriou /
 * Surazhsky et al. 2005, "MMP", which Kirsanov's library -- libigl's
 * exact_geodesic, gdist -- implements); instead every window is checked
 * against the best distances known at the vertices of its triangle and
 * trimmed or dropped where a path through one of them is shorter. Windows
 * and vertex events share one queue ordered by least distance (ICH's
 * priority queue, kept here as buckets: see the queue below).
 *
 * A window lies on an edge, seen from the face it is about to cross: an
 * interval [b0, b1] of the edge, its pseudo-source I unfolded into the
 * edge's plane (px, py), py <= 0 on the far side from that face, and sigma,
 * the distance from the sources to I. The distance it gives a point X of
 * the interval is D(X) = sigma + |I X|. Crossing the face it may see the
 * opposite vertex C (then d(C) <= sigma + |I C|) and splits into at most two
 * children on the face's other edges. A vertex through which a shortest
 * path may bend (a source, a saddle with angle sum > 2 pi, a boundary or
 * non-manifold vertex, a vertex of a zero-area face) becomes a
 * pseudo-source when its distance improves: it starts windows on the
 * opposite edges of the faces around it.
 *
 * Pruning and trimming (sound; derived for this code). For a new window on
 * edge PQ of the face PQR it leaves:
 *   - |I X| - |P X| does not increase as X moves away from P along the
 *     edge, so the part where D(X) > d(P) + |P X| is an interval at P's
 *     end, found by solving one quadratic: the window is trimmed to the
 *     rest (likewise from Q); ICH drops the whole window when its far end
 *     is beaten, this keeps the part that is not;
 *   - (ICH's third rule, dropping the window when min D > d(R) + max(|R E0|,
 *     |R E1|), is not applied: with the trims and the queue's order it
 *     dropped 0-11 windows of 2,000-4,000 a patch on the test meshes, and
 *     its test cost 5-9 % of the patch's time.)
 * Dropping or trimming is safe in any order: every point removed has a
 * shorter path through a vertex, so no shortest path crosses it.
 *
 * Saddle shadows (from the geometry of geodesics through a vertex, as in
 * Mitchell-Mount-Papadimitriou and Surazhsky et al.): a shortest path that
 * reaches an interior saddle v from direction th can go on through v only
 * into directions at angle >= pi from th on both sides, the "shadow"
 * [th + pi, th + total - pi]; every other direction is reached more briefly
 * by the windows passing beside v. So an interior saddle starts windows only
 * in its shadow (with 1e-7 rad to spare), th being the direction of the path
 * that gave v its distance (any one of several equal ones will do; a gain
 * within rounding keeps the earlier direction, since rays grazing a vertex
 * along an edge report directions that are not theirs). Sources, boundary,
 * non-manifold and zero-area-face vertices start windows all around. This
 * is what makes the method fast: about a third of ICH's windows remain.
 *
 * Queue: buckets a quarter of a mean edge wide (the "fast wavefront
 * propagation" idea of Xu et al. 2015), windows first in first out inside a
 * bucket, then the bucket's vertex events. Pops come in order to within a
 * bucket; pruning tolerates it, and a saddle started before its distance
 * was final is started again when it improves, so the result does not
 * depend on it.
 *
 * Sources: a vertex source is a pseudo-source with its value; a point in a
 * face (on an edge too) starts a window on each edge of its face; a point
 * within 1e-12 of a corner is that corner. Boundary edges are walls; a
 * window reaching a non-manifold edge goes on into every other face on it
 * (ex_fan_out), each unfolded across the edge and trimmed against the
 * windows that entered that face there before (ex_dominate), and the edge's
 * ends are pseudo-sources; copies of a face are no part of the surface
 * (skip 2); a zero-area face (skip 1, its corners on one line) is passed
 * through along that line (ex_pass), its edges relax their ends, and a
 * vertex on its longest edge starts windows across that edge. An edge
 * almost a point next to the faces at its ends (a vertex split in two 1e-15
 * apart) is a wall whose ends start windows all around: no frame can be
 * unfolded onto it (ex_wall_short_edges). max_distance
 * (and the radius of mfmm_exact_patch) drops every window and event beyond
 * it, so the work grows with the area reached.
 *
 * Geometry: each face's corners are laid out in the frame of each of its
 * edges from the 3D vectors (dot and cross products); the law of cosines
 * loses (L / height)^2 eps of a needle's height.
 *
 * Memory: per-mesh tables (a 128-byte record per face with its edges'
 * lengths, each corner in the frame of the opposite edge, the edges across
 * and the vertices; corner and fan angles: about 160 bytes per face; per
 * vertex its flags, angle sum and least height, 17 bytes; 8 bytes per
 * half-edge of a non-manifold edge), the queue's entries (windows and vertex
 * events, 56 bytes each) and the windows kept at non-manifold edges (48
 * bytes each, ex_keep), grown by doubling within memory_limit. No
 * recursion. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "exact/exact.h"
#include "mesh/mesh.h"
#include "mesh/check.h"
#include "mesh/order.h"

#define EX_PI 3.14159265358979323846264338328
#define EX_TWO_PI 6.283185307179586476925286766559
/* the shadow of a saddle is widened by this angle on each side */
#define EX_SHADOW_MARGIN 1e-7
/* distances equal to this relative amount are ties */
#define EX_TIE 1e-12
/* buckets in the queue's window (a power of 2), and their width in mean
 * edge lengths */
#define EX_NB 4096
#define EX_BUCKET_WIDTH 0.25
/* a window narrower than this fraction of its edge is dropped */
#define EX_MIN_WIDTH 1e-13
/* a point of an edge this close (relative) to a window's end is in it */
#define EX_POS_TOL 1e-12
/* a vertex this near (in edge lengths) to the pseudo-source of the path
 * that reached it starts windows all around (ex_set_in) */
#define EX_NEAR 1e-3
/* a vertex this close (in edge lengths) outside a window's rays is
 * reached over the window's end (ex_propagate) */
#define EX_GRAZE 1e-6
/* a patch distance outside its bounds by more than this times (the
 * distance + a mean edge) is a defect (mfmm_exact_patch_check) */
#define EX_PATCH_TOL 1e-9
/* a face's edge shorter than this times the edge a window enters by gets
 * its direction normalised by the length of its own vector in that frame
 * (ex_propagate): its corners are placed to rounding of the longer edge, so
 * the table's length would scale the frame, and every distance in it */
#define EX_SHORT_CHILD 1e-3
/* an edge shorter than this times the longest edge of a face at its ends
 * is a wall (ex_wall_short_edges) */
#define EX_SHORT_EDGE 1e-6
/* zero-area faces one window may pass through in a row (ex_pass) */
#define EX_MAX_PASS 8
/* a vertex whose angle sum exceeds 2 pi by this much is a saddle */
#define EX_SADDLE_TOL 1e-12

/* k + 1 and k - 1 modulo 3, looked up: with k of a random window, a
 * comparison there is a branch mispredicted about half the time */
static const int8_t ex_next[3] = {1, 2, 0}, ex_prev[3] = {2, 0, 1};

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
    int32_t v[3], across[3];
    uint8_t flip[3], skip;
    int8_t sgn[3];   /* the corners' fan_sgn (see mfmm_exact_tables) */
    uint8_t tie;     /* bit k: corner k starts no windows, so a window tied with a
                        path through it is kept (ex_enqueue) */
} ex_face;

/* An entry of the queue: a window, or a vertex to start as a pseudo-source. */
typedef struct ex_entry {
    double key;      /* the least distance of the window; a vertex's distance */
    double b0, b1;   /* interval on the edge, from its first vertex */
    double px, py;   /* pseudo-source in the edge's frame, py <= 0 */
    double sigma;    /* distance at the pseudo-source */
    int32_t he;      /* >= 0: 3 f + k, the edge opposite corner k of face f, the
                        window about to cross f; < 0: vertex -he-1 */
    int32_t next;    /* the next entry in its bucket or in the free list */
} ex_entry;

/* A window queued into a face through a non-manifold edge (ex_fan_out),
 * kept to trim the later ones there (ex_dominate): its function and the
 * interval it crosses with, in that half-edge's frame. */
typedef struct ex_rec {
    double b0, b1, px, py, sigma;
    int32_t slot, next;
} ex_rec;

/* The read-only tables of a mesh (exact.h): built once, shared by the
 * workspaces of any number of threads. Faces are laid out in the order of
 * their least (internal, Morton-ordered: core/order.c) vertex, so that a
 * patch's faces lie together in memory: in the files' order the faces
 * around a vertex were 12,000 records apart on the bunny. */
struct mfmm_exact_tables {
    const mfmm_mesh *mesh;
    int32_t nv, nf;
    const int32_t *vf_offset;
    const int32_t *vf_corner; /* the mesh's vertex -> face CSR, MFMM_WEDGE entries (ex_corner) */
    int32_t *face_in;   /* (nf,) the mesh's face id -> its record */
    /* per face, its three half-edges 3f+k (the edge opposite corner k, from
     * corner k+1 to k+2) in one record, so that crossing a face reads one or
     * two cache lines: see ex_face */
    ex_face *fr;
    void *fr_block;    /* fr's allocation (fr is aligned to 64 bytes in it) */
    uint8_t *pseudo;   /* (nv,) vertices that may bend a path */
    /* the fan of corners around a vertex, by angle: corner 3f+k (at v = f[k])
     * spans the angles between fan_a0 (the direction to f[k+1]) and
     * fan_a0 + sgn * angle (to f[k+2], ex_face); fan_total (nv) is the angle sum,
     * NaN where the fan is not one closed disk (walls, zero-area faces,
     * non-manifold vertices): those start windows in every direction */
    double *fan_a0, *fan_total;
    /* (nv,) a vertex's least height over the opposite edges of its faces
     * (+inf with none): the patch's free ring (mfmm_exact_patch) */
    double *height;
    /* the half-edges of non-manifold edges (flip 2 in their record), sorted,
     * each with the next half-edge of the same edge (a cycle through the
     * edge's faces; ex_fan_out): n_nm of them */
    int32_t *nm_he, *nm_next;
    int32_t n_nm;
    double inv_w;      /* 1 / bucket width */
    size_t bytes;
};

/* A workspace: shared tables (the mesh's) and one solve's state. */
struct mfmm_exact_solver {
    const mfmm_exact_tables *t;
    const mfmm_mesh *mesh;
    int32_t nv, nf;
    /* the tables' arrays (see mfmm_exact_tables) */
    const int32_t *vf_offset, *vf_corner, *face_in;
    const ex_face *fr;
    const uint8_t *pseudo;
    const double *fan_a0, *fan_total, *height;
    const int32_t *nm_he, *nm_next;
    int32_t n_nm;
    double inv_w;
    double *in_angle;  /* (nv,) direction (fan angle) back along the path that gave d */
    double *d;         /* (nv,) best distance so far, +inf untouched */
    double *emitted;   /* (nv,) the distance a pseudo-source was started with */
    int32_t *touched;  /* vertices with finite d, in order of first touch */
    int32_t n_touched;
    double *patch_d;   /* (nv,) distances of mfmm_exact_patch */
    uint8_t *in_patch; /* (nv,) whether in the last patch (mfmm_exact_in_patch) */
    /* the queue */
    ex_entry *heap;    /* the entries of the bucket queue, linked by next */
    int32_t heap_cap, heap_n, heap_used, qfree;
    /* the buckets in the window: (3 EX_NB,) heads and tails of their FIFO
     * lists of windows, then heads of their lists of vertex events */
    int32_t *bhead;
    int32_t over;      /* entries beyond the window, unsorted */
    int64_t cur, redist; /* current bucket; where the window was last refilled */
    int32_t n_in;      /* entries in the window's buckets */
    size_t fixed_bytes, memory_limit, peak_bytes;
    double max_d;
    int failed; /* MFMM_ERR_MEMORY_LIMIT or MFMM_ERR_OUT_OF_MEMORY once a growth fails,
                   MFMM_ERR_CANCELLED once interrupt asked to stop */
    int (*interrupt)(void *user); /* mfmm_exact_options' (NULL for a patch) */
    void *interrupt_user;
    int pass_depth; /* zero-area faces a window is passing through (ex_pass) */
    /* with non-manifold edges crossed, windows past a budget (over_budget):
     * the run is redone with those edges as walls (walls; ex_run); past it
     * otherwise, the run stops (stalled) and edge paths finish it */
    int over_budget, walls, stalled;
    double budget; /* windows a reached vertex may cost (ex_over_budget) */
    int64_t n_windows, n_propagated, n_pseudo, peak_windows;
    /* the windows fanned out at non-manifold edges, by nm_he slot: (n_nm,)
     * heads of lists in rec, -1: none */
    int32_t *nm_head;
    ex_rec *rec;
    int32_t rec_n, rec_cap;
};

/* ------------------------------------------------------------- workspace */

void mfmm_exact_options_init(mfmm_exact_options *options)
{
    if (!options)
        return;
    memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
    options->cost = NULL;
    options->cost_location = MFMM_COST_NONE;
    options->max_distance = INFINITY;
    options->memory_limit = 0;
    options->interrupt = NULL;
    options->user = NULL;
}

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

void mfmm_exact_ws_destroy(mfmm_exact_ws *ws)
{
    if (!ws)
        return;
    free(ws->in_angle);
    free(ws->d);
    free(ws->emitted);
    free(ws->touched);
    free(ws->patch_d);
    free(ws->in_patch);
    free(ws->heap);
    free(ws->bhead);
    free(ws->nm_head);
    free(ws->rec);
    free(ws);
}

void mfmm_exact_solver_destroy(mfmm_exact_solver *solver)
{
    mfmm_exact_ws_destroy(solver);
}

static double vdist(const double *p, const double *q)
{
    double a = p[0] - q[0], b = p[1] - q[1], c = p[2] - q[2];
    return sqrt(a * a + b * b + c * c);
}

/* Entry i of the vertex -> face CSR, as corner 3 * record + k. */
static int32_t ex_corner(const int32_t *vf_corner, const int32_t *face_in, int32_t i)
{
    int32_t w = vf_corner[i];
    return 3 * face_in[MFMM_WEDGE_FACE(w)] + MFMM_WEDGE_K(w);
}

static int ex_corner_of(const int32_t *fv, int32_t v)
{
    return fv[0] == v ? 0 : fv[1] == v ? 1 : fv[2] == v ? 2 : -1;
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
 * (nm_he, nm_next), which ex_fan_out walks. Before, they were walls, and a
 * path through one bent at a vertex (beetle: up to 0.03, 5 %, too long). 0, or
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

size_t mfmm_exact_ws_bytes(const mfmm_mesh *mesh)
{
    return sizeof(mfmm_exact_ws) + (size_t)mesh->nv * (4 * sizeof(double) + sizeof(int32_t) + 1) +
           3 * EX_NB * sizeof(int32_t);
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

mfmm_status mfmm_exact_ws_create_shared(const mfmm_exact_tables *t, mfmm_exact_ws **out)
{
    if (!out)
        return MFMM_ERR_NULL_POINTER;
    *out = NULL;
    if (!t)
        return MFMM_ERR_NULL_POINTER;
    mfmm_exact_ws *ws = calloc(1, sizeof *ws);
    if (!ws)
        return MFMM_ERR_OUT_OF_MEMORY;
    size_t nv = (size_t)t->nv;
    ws->t = t;
    ws->budget = 64.0;
    ws->mesh = t->mesh;
    ws->nv = t->nv;
    ws->nf = t->nf;
    ws->vf_offset = t->vf_offset;
    ws->vf_corner = t->vf_corner;
    ws->face_in = t->face_in;
    ws->fr = t->fr;
    ws->pseudo = t->pseudo;
    ws->fan_a0 = t->fan_a0;
    ws->fan_total = t->fan_total;
    ws->height = t->height;
    ws->nm_he = t->nm_he;
    ws->nm_next = t->nm_next;
    ws->n_nm = t->n_nm;
    ws->inv_w = t->inv_w;
    ws->d = malloc((nv ? nv : 1) * sizeof *ws->d);
    ws->emitted = malloc((nv ? nv : 1) * sizeof *ws->emitted);
    ws->touched = malloc((nv ? nv : 1) * sizeof *ws->touched);
    ws->patch_d = malloc((nv ? nv : 1) * sizeof *ws->patch_d);
    ws->in_angle = malloc((nv ? nv : 1) * sizeof *ws->in_angle);
    ws->in_patch = calloc(nv ? nv : 1, sizeof *ws->in_patch);
    ws->bhead = malloc(3 * EX_NB * sizeof *ws->bhead);
    ws->nm_head = malloc((ws->n_nm ? (size_t)ws->n_nm : 1) * sizeof *ws->nm_head);
    if (!ws->d || !ws->emitted || !ws->touched || !ws->patch_d || !ws->in_angle ||
        !ws->in_patch || !ws->bhead || !ws->nm_head) {
        mfmm_exact_ws_destroy(ws);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    for (size_t v = 0; v < nv; v++) {
        ws->d[v] = INFINITY;
        ws->emitted[v] = INFINITY;
        ws->in_angle[v] = NAN;
    }
    for (int32_t i = 0; i < 3 * EX_NB; i++)
        ws->bhead[i] = -1;
    for (int32_t i = 0; i < ws->n_nm; i++)
        ws->nm_head[i] = -1;
    /* memory_limit counts the tables too, shared or not */
    ws->fixed_bytes = t->bytes + mfmm_exact_ws_bytes(t->mesh) + (size_t)ws->n_nm * sizeof(int32_t);
    ws->max_d = INFINITY;
    ws->peak_bytes = ws->fixed_bytes;
    *out = ws;
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

mfmm_status mfmm_exact_ws_create(const mfmm_mesh *mesh, mfmm_exact_ws **out)
{
    if (!out)
        return MFMM_ERR_NULL_POINTER;
    *out = NULL;
    const mfmm_exact_tables *t = NULL;
    mfmm_status st = mfmm_exact_tables_of(mesh, &t);
    if (st != MFMM_OK)
        return st;
    return mfmm_exact_ws_create_shared(t, out);
}

mfmm_status mfmm_exact_solver_create(const mfmm_mesh *mesh, mfmm_exact_solver **out)
{
    return mfmm_exact_ws_create(mesh, out);
}

/* ----------------------------------------------------------------- queue */

static size_t ex_bytes(const mfmm_exact_ws *ws, int32_t heap_cap)
{
    return ws->fixed_bytes + (size_t)heap_cap * sizeof(ex_entry) +
           (size_t)ws->rec_cap * sizeof(ex_rec);
}

/* Grows the entries by doubling, within memory_limit. */
static int ex_grow(mfmm_exact_ws *ws)
{
    int32_t cap = ws->heap_cap;
    if (cap >= INT32_MAX / 2) {
        ws->failed = MFMM_ERR_MEMORY_LIMIT;
        return 0;
    }
    int32_t ncap = cap ? 2 * cap : 1024;
    if (ws->memory_limit && ex_bytes(ws, ncap) > ws->memory_limit) {
        /* the largest size that fits, if it is any larger */
        size_t room = ws->memory_limit > ws->fixed_bytes ? ws->memory_limit - ws->fixed_bytes : 0;
        if (room / sizeof(ex_entry) <= (size_t)cap) {
            ws->failed = MFMM_ERR_MEMORY_LIMIT;
            return 0;
        }
        ncap = (int32_t)(room / sizeof(ex_entry));
    }
    ex_entry *p = realloc(ws->heap, (size_t)ncap * sizeof *p);
    if (!p) {
        ws->failed = MFMM_ERR_OUT_OF_MEMORY;
        return 0;
    }
    ws->heap = p;
    ws->heap_cap = ncap;
    if (ex_bytes(ws, ncap) > ws->peak_bytes)
        ws->peak_bytes = ex_bytes(ws, ncap);
    return 1;
}

/* The queue: buckets of keys (a quarter of a mean edge wide) in a
 * circular window of EX_NB buckets, entries beyond the window in one
 * overflow list that is sorted in when the window moves on. Pops come in
 * key order to within a bucket's width (as the "fast wavefront propagation"
 * of Xu et al. 2015 does for MMP and CH): enough for the pruning, and the
 * result does not depend on it (a pseudo-source started before its
 * distance was final is started again when it improves). Inside a bucket,
 * windows come first in first out: a third of the children fall in the
 * current bucket, and taken last in first out each of those was the next
 * pop, waiting on its parent (divisions, a square root); in arrival order
 * the next pop is an older entry the core can start on meanwhile.
 * Vertex events (pseudo-sources to start) come after the bucket's windows,
 * which can still lower them: a saddle started early is started again
 * (first in first out without this: 280 starts for 193 saddles). */
static int64_t ex_bucket(const mfmm_exact_ws *ws, double key)
{
    double b = key * ws->inv_w;
    /* keys are distances, >= 0 but for negative source values: truncation
     * is the floor there and needs no library call or rounding mode */
    if (b >= 0.0 && b < 1e18)
        return (int64_t)b;
    b = floor(b);
    if (!(b > -1e18))
        b = -1e18;
    if (b > 1e18)
        b = 1e18;
    return (int64_t)b;
}

static void ex_link(mfmm_exact_ws *ws, int32_t e)
{
    int64_t b = ex_bucket(ws, ws->heap[e].key);
    if (b < ws->cur)
        b = ws->cur;
    if (b >= ws->cur + EX_NB) {
        ws->heap[e].next = ws->over;
        ws->over = e;
        return;
    }
    int32_t i = (int32_t)(b & (EX_NB - 1));
    ws->n_in++;
    if (ws->heap[e].he < 0) {
        ws->heap[e].next = ws->bhead[2 * EX_NB + i];
        ws->bhead[2 * EX_NB + i] = e;
        return;
    }
    ws->heap[e].next = -1;
    if (ws->bhead[i] < 0)
        ws->bhead[i] = e;
    else
        ws->heap[ws->bhead[EX_NB + i]].next = e;
    ws->bhead[EX_NB + i] = e;
}

/* A free entry (its fields to be filled, then ex_queue), or -1. */
static int32_t ex_new(mfmm_exact_ws *ws)
{
    int32_t e = ws->qfree;
    if (e >= 0) {
        ws->qfree = ws->heap[e].next;
        return e;
    }
    if (ws->heap_used == ws->heap_cap && !ex_grow(ws))
        return -1;
    return ws->heap_used++;
}

static void ex_queue(mfmm_exact_ws *ws, int32_t e)
{
    ws->heap_n++;
    if (ws->heap_n > ws->peak_windows)
        ws->peak_windows = ws->heap_n;
    ex_link(ws, e);
}

/* Moves the overflow entries that now fall in the window into it; with
 * the window empty, first moves the window to the least of them. */
static void ex_refill(mfmm_exact_ws *ws)
{
    if (ws->n_in == 0) {
        int64_t lo = INT64_MAX;
        for (int32_t e = ws->over; e >= 0; e = ws->heap[e].next) {
            int64_t b = ex_bucket(ws, ws->heap[e].key);
            if (b < lo)
                lo = b;
        }
        if (lo > ws->cur)
            ws->cur = lo;
    }
    ws->redist = ws->cur;
    int32_t e = ws->over;
    ws->over = -1;
    while (e >= 0) {
        int32_t next = ws->heap[e].next;
        ex_link(ws, e);
        e = next;
    }
}

/* Takes the next entry out of the queue (which must not be empty) into *out. */
static void ex_pop(mfmm_exact_ws *ws, ex_entry *out)
{
    for (;;) {
        if (ws->n_in == 0 || ws->cur >= ws->redist + EX_NB)
            ex_refill(ws);
        int32_t i = (int32_t)(ws->cur & (EX_NB - 1));
        int32_t e = ws->bhead[i];
        if (e < 0) {
            /* the bucket's windows are done: its vertex events */
            i += 2 * EX_NB;
            e = ws->bhead[i];
            if (e < 0) {
                ws->cur++;
                continue;
            }
        }
        ws->bhead[i] = ws->heap[e].next;
#ifdef __GNUC__
        /* the next pop's record: a cold line when its bucket filled earlier */
        if (ws->bhead[i] >= 0)
            __builtin_prefetch(ws->heap + ws->bhead[i]);
#endif
        ws->n_in--;
        ws->heap_n--;
        *out = ws->heap[e];
        ws->heap[e].next = ws->qfree;
        ws->qfree = e;
        return;
    }
}

/* ------------------------------------------------------------ propagation */

/* Lowers d(v) to dist if that is less. Returns 1 when v is then a
 * pseudo-source to start, with a known fan, and the new distance is less
 * by more than rounding: the caller then gives the direction it came from
 * (ex_set_in). A gain within rounding keeps the direction of the path it
 * ties with: rays that graze a vertex along an edge reach it again from
 * faces they do not cross, with directions that are not theirs. */
static int ex_update(mfmm_exact_ws *ws, int32_t v, double dist, int force)
{
    double old = ws->d[v];
    if (!(dist < old))
        return 0;
    if (old == INFINITY)
        ws->touched[ws->n_touched++] = v;
    ws->d[v] = dist;
    int gain = !(dist >= old - EX_TIE * old);
    if (gain)
        ws->in_angle[v] = NAN;
    if ((ws->pseudo[v] || force) && dist <= ws->max_d) {
        int32_t e = ex_new(ws);
        if (e < 0)
            return 0;
        ws->heap[e].key = dist;
        ws->heap[e].he = -v - 1;
        ex_queue(ws, e);
        return gain && !force && ws->fan_total[v] == ws->fan_total[v];
    }
    return 0;
}

/* in_angle of v = corner c's vertex from the angle psi inside the corner,
 * measured from the direction to the corner's first vertex; r: the length of
 * the path's last straight piece (from its pseudo-source to v), L: an edge
 * length of the face. */
static void ex_set_in(mfmm_exact_ws *ws, int32_t v, int32_t c, double psi, double r, double L)
{
    /* a pseudo-source (a point source) almost at v: the windows passing
     * beside v then tie with the paths through v to rounding and are trimmed
     * away near the straight-on direction, wider than the shadow's margin
     * (a point 1e-9 beside a saddle of hand left vertices at +inf): v starts
     * windows all around, as a source does (sound: they are real paths) */
    if (r < EX_NEAR * L || ws->fr[c / 3].skip)
        return;
    /* a direction outside the corner (rounding at a grazing ray) is not
     * trusted: in_angle stays NaN and v starts windows all around */
    if (!(psi >= -1e-9 && psi <= ws->fr[c / 3].angle[c % 3] + 1e-9))
        return;
    if (psi < 0.0)
        psi = 0.0;
    if (psi > ws->fr[c / 3].angle[c % 3])
        psi = ws->fr[c / 3].angle[c % 3];
    ws->in_angle[v] = ws->fan_a0[c] + ws->fr[c / 3].sgn[c % 3] * psi;
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
static int ex_trim(double px, double py, double sigma, double L, double dA, double dB,
                   double *b0, double *b1)
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

/* The distance from x to the interval [s0, s1] (s0 <= s1), as maxima
 * (no branch) */
static double ex_gap(double x, double s0, double s1)
{
    double lo = s0 - x, hi = x - s1;
    double g = lo > hi ? lo : hi;
    return g > 0.0 ? g : 0.0;
}

static void ex_emit(mfmm_exact_ws *ws, int32_t h, double s0, double s1, double ix, double iy,
                    double sigma, int known);

/* A window entering a zero-area face D through D's half-edge hd (flip: hd
 * runs the other way from the window's frame, an edge of length L). D's
 * corners lie on one line, so the points of the edge crossed are points of
 * D's other edges where their spans overlap it: a T-junction closed by a
 * needle (m on the segment ab, faces on ab one side and on am, mb the
 * other) joins the faces on both sides along the line. The window goes on,
 * in the same plane, from each overlap into the face across it (ex_emit):
 * the same straight paths. Before, D was a wall, and a shortest path
 * across the junction went round through a vertex. */
static void ex_pass(mfmm_exact_ws *ws, int32_t hd, int flip, double L, double s0, double s1,
                    double ix, double iy, double sigma)
{
    if (ws->pass_depth >= EX_MAX_PASS)
        return;
    if (flip) {
        double t0 = L - s1;
        s1 = L - s0;
        s0 = t0;
        ix = L - ix;
    }
    const ex_face *r = ws->fr + hd / 3;
    int k = hd % 3;
    /* D's corners on the line, in hd's frame (v[k+1] at 0, v[k+2] at L) */
    double t[3];
    t[ex_next[k]] = 0.0;
    t[ex_prev[k]] = L;
    t[k] = r->cx[k];
    if (!isfinite(t[k]))
        return;
    ws->pass_depth++;
    for (int j = 0; j < 3; j++) {
        if (j == k)
            continue;
        /* half-edge 3D + j runs from its corner v[j+1] to v[j+2] */
        double u0 = t[ex_next[j]], u1 = t[ex_prev[j]];
        double lo = fmax(s0, fmin(u0, u1)), hi = fmin(s1, fmax(u0, u1));
        if (!(hi > lo))
            continue;
        double dir = u1 >= u0 ? 1.0 : -1.0, a0 = (lo - u0) * dir, a1 = (hi - u0) * dir;
        ex_emit(ws, hd - k + j, fmin(a0, a1), fmax(a0, a1), (ix - u0) * dir, iy, sigma, 0);
    }
    ws->pass_depth--;
}

/* ex_emit_inline's last step: the window [s0, s1] of an edge va -> vb of
 * length L (pseudo-source (ix, iy), iy >= 0), queued to cross the face of
 * half-edge g (fl: g runs from vb to va), trimmed against the edge's
 * ends. */
MFMM_INLINE void ex_enqueue(mfmm_exact_ws *ws, int32_t g, int fl, int32_t va, int32_t vb,
                            double L, double s0, double s1, double ix, double iy, double sigma,
                            int tie_a, int tie_b)
{
    double iy2 = iy * iy;
#ifdef __GNUC__
    /* the face the window will cross, read when it is popped: after a
     * march has run through the mesh its record is far from the core */
    __builtin_prefetch((const char *)(ws->fr + g / 3));
    __builtin_prefetch((const char *)(ws->fr + g / 3) + 64);
#endif
    /* the least distance: at the foot of I, or at the nearer end. Taken
     * before the trims, which can only raise it: the key is then a lower
     * bound, as good for the queue's order and the cut at max_d (taking it
     * again after the quarter of windows that are trimmed cost 4 % of a
     * patch, for the same windows) */
    double dx = ex_gap(ix, s0, s1);
    double key = sigma + (dx > 0.0 ? sqrt(dx * dx + iy2) : iy);
    if (key > ws->max_d)
        return;
    /* pruning against the ends of the edge */
    /* a tie with a path through an end that starts no windows keeps the
     * window (ex_trim); an end that does start them carries that path on */
    double da = ws->d[va], db = ws->d[vb];
    da += tie_a ? EX_TIE * da : 0.0;
    db += tie_b ? EX_TIE * db : 0.0;
    if (!ex_trim(ix, -iy, sigma, L, da, db, &s0, &s1))
        return;
    int32_t wi = ex_new(ws);
    if (wi < 0)
        return;
    ex_entry *w = ws->heap + wi;
    /* the edge as the face across sees it (selected, not branched on) */
    double e0[2] = {s0, L - s1}, e1[2] = {s1, L - s0}, ex[2] = {ix, L - ix};
    w->b0 = e0[fl];
    w->b1 = e1[fl];
    w->px = ex[fl];
    w->py = -iy;
    w->sigma = sigma;
    w->he = g;
    w->key = key;
    ex_queue(ws, wi);
    ws->n_windows++;
}

static void ex_fan_out(mfmm_exact_ws *ws, int32_t h, int32_t va, int32_t vb, double L,
                       double s0, double s1, double ix, double iy, double sigma);

/* A window on half-edge h = 3f+k in f's frame (I on f's side: iy >= 0),
 * interval [s0, s1], leaving f: updates the vertices it reaches, trims it
 * against the edge's ends, and queues it in the face across, in that face's
 * frame. known: its ends at a vertex whose distance through this window
 * is already set (bit 0: at s = 0, bit 1: at s = L; see ex_propagate).
 * Inlined where it is called (MFMM_INLINE): in ex_propagate that made a
 * patch 4-6 % faster (bench_exact_patch: hand, spot, camelhead), as a call
 * spilled the window's doubles; ex_link inlined too was no faster. */
MFMM_INLINE void ex_emit_inline(mfmm_exact_ws *ws, int32_t h, double s0, double s1, double ix,
                                double iy, double sigma, int known)
{
    const ex_face *r = ws->fr + h / 3;
    int k = h % 3;
    int k1 = ex_next[k], k2 = ex_prev[k];
    int32_t va = r->v[k1], vb = r->v[k2];
    double L = r->len[k];
    if (s0 < 0.0)
        s0 = 0.0;
    if (s1 > L)
        s1 = L;
    double iy2 = iy * iy;
    if (s0 <= EX_POS_TOL * L && !(known & 1)) {
        double ra = sqrt(ix * ix + iy2);
        if (ex_update(ws, va, sigma + ra, 0))
            ex_set_in(ws, va, h - k + k1, atan2(iy, ix), ra, L);
    }
    if (s1 >= L - EX_POS_TOL * L && !(known & 2)) {
        double rb = sqrt((ix - L) * (ix - L) + iy2);
        if (ex_update(ws, vb, sigma + rb, 0)) {
            int32_t c = h - k + k2;
            ex_set_in(ws, vb, c, ws->fr[c / 3].angle[c % 3] - atan2(iy, L - ix), rb, L);
        }
    }
    int32_t g = r->across[k];
    if (g < 0 || !(s1 - s0 > EX_MIN_WIDTH * L)) {
        if (g < -1 && s1 - s0 > EX_MIN_WIDTH * L)
            ex_pass(ws, -2 - g, r->flip[k], L, s0, s1, ix, iy, sigma);
        else if (r->flip[k] == 2 && s1 - s0 > EX_MIN_WIDTH * L)
            ex_fan_out(ws, h, va, vb, L, s0, s1, ix, iy, sigma);
        return;
    }
    ex_enqueue(ws, g, r->flip[k], va, vb, L, s0, s1, ix, iy, sigma, (r->tie >> k1) & 1,
               (r->tie >> k2) & 1);
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
static int ex_dominate(const mfmm_exact_ws *ws, int32_t slot, double L, double *s0p,
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
         * round again (alike to rounding, as below). */
        for (int32_t i = ws->nm_head[slot]; i >= 0; i = ws->rec[i].next) {
            const ex_rec *a = ws->rec + i;
            double ds = (sigma - a->sigma) * il, pa = a->px * il, qa = a->py * il;
            if (fabs(ds) + fabs(pw - pa) + fabs(qw - qa) <=
                EX_TIE * (1.0 + fabs(sigma * il) + fabs(pw) + fabs(qw)))
                return 0;
        }
        return 1;
    }
    for (int32_t i = ws->nm_head[slot]; i >= 0; i = ws->rec[i].next) {
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
        } else if (A == 0.0 && B != 0.0) {
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

/* Keeps a fanned-out window at its slot for ex_dominate, while memory
 * allows (one not kept only trims nothing). */
static void ex_keep(mfmm_exact_ws *ws, int32_t slot, double b0, double b1, double px, double py,
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
    r->next = ws->nm_head[slot];
    ws->nm_head[slot] = ws->rec_n++;
}

/* The slot of half-edge g in nm_he (binary search), -1 if none. */
static int32_t ex_nm_slot(const mfmm_exact_ws *ws, int32_t g)
{
    int32_t lo = 0, hi = ws->n_nm - 1;
    while (lo < hi) {
        int32_t mid = lo + (hi - lo) / 2;
        if (ws->nm_he[mid] < g)
            lo = mid + 1;
        else
            hi = mid;
    }
    return ws->n_nm > 0 && ws->nm_he[lo] == g ? lo : -1;
}

/* A window on half-edge h (edge va -> vb, in h's face's frame) of a
 * non-manifold edge: it goes on into every other face on the edge, each
 * unfolded across the edge (ex_link_nonmanifold), trimmed against the
 * windows that went that way before (ex_dominate). */
static void ex_fan_out(mfmm_exact_ws *ws, int32_t h, int32_t va, int32_t vb, double L,
                       double s0, double s1, double ix, double iy, double sigma)
{
    /* (I on an end of the edge, within rounding: its rays run along the
     * edge, and carry nothing into the other faces; such windows went round
     * a folded fan without end) */
    double tol = EX_POS_TOL * L;
    if (ws->walls || (iy <= tol && (fabs(ix) <= tol || fabs(ix - L) <= tol)))
        return;
    int32_t i = ex_nm_slot(ws, h);
    for (int32_t n = 0; i >= 0 && n < ws->n_nm; n++) {
        int32_t g = ws->nm_next[i];
        if (g == h)
            return;
        i = ex_nm_slot(ws, g);
        const ex_face *q = ws->fr + g / 3;
        int fl = q->v[ex_next[g % 3]] != va;
        if (q->skip == 1) {
            /* (not from within a pass: zero-area faces meeting at such
             * edges would pass a window round among themselves) */
            if (ws->pass_depth == 0)
                ex_pass(ws, g, fl, L, s0, s1, ix, iy, sigma);
            continue;
        }
        if (i < 0)
            return;
        /* in g's frame (its ends swapped when it runs from vb to va) */
        double n0 = fl ? L - s1 : s0, n1 = fl ? L - s0 : s1, npx = fl ? L - ix : ix;
        if (!ex_dominate(ws, i, L, &n0, &n1, npx, -iy, sigma))
            continue;
        ex_keep(ws, i, n0, n1, npx, -iy, sigma);
        ex_enqueue(ws, g, fl, va, vb, L, fl ? L - n1 : n0, fl ? L - n0 : n1, ix, iy, sigma,
                   !ws->pseudo[va], !ws->pseudo[vb]);
    }
}

/* ex_emit_inline as a call, for the starts (ex_propagate inlines its own) */
static void ex_emit(mfmm_exact_ws *ws, int32_t h, double s0, double s1, double ix, double iy,
                    double sigma, int known)
{
    ex_emit_inline(ws, h, s0, s1, ix, iy, sigma, known);
}

/* Where the line from I through X = (x, 0) meets the line O + s u (s). */
static double ex_hit(double ox, double oy, double ux, double uy, double ix, double iy, double x,
                     double len)
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

static void ex_propagate(mfmm_exact_ws *ws, const ex_entry *w)
{
    int32_t h = w->he;
    int32_t f = h / 3;
    int m = h % 3;
    const ex_face *r = ws->fr + f;
    int32_t vc = r->v[m];
    double L = r->len[m], cx = r->cx[m], cy = r->cy[m];
    double b0 = w->b0, b1 = w->b1, px = w->px, py = w->py, sigma = w->sigma;
    /* (checking the window again here, against the face it crosses with the
     * distances known by now, drops almost nothing: 1 window in 10^4 on the
     * bunny, for 15% of the time) */
    ws->n_propagated++;
    /* where the ray from I through C crosses the edge */
    double tc = px + (cx - px) * (-py) / (cy - py);
    double tol = EX_POS_TOL * L;
    if (tc >= b0 - tol && tc <= b1 + tol) {
        double ex = cx - px, ey = cy - py;
        double rc = sqrt(ex * ex + ey * ey);
        if (ex_update(ws, vc, sigma + rc, 0)) {
            /* angle at C between C -> A = (-cx, -cy) and C -> I = (-ex, -ey) */
            double cr = cx * ey - cy * ex, dt = cx * ex + cy * ey;
            ex_set_in(ws, vc, h, atan2(fabs(cr), dt), rc, L);
        }
    } else if (tc >= b0 - EX_GRAZE * L && tc <= b1 + EX_GRAZE * L) {
        /* C just outside the window: the rays to it may have been in a
         * window dropped as too narrow, or missed by rounding (a flat mesh
         * whose straight paths graze vertices was left 3x too long). The path
         * over the window's nearer end is a real one, within rounding of the
         * straight one. */
        double e = tc < b0 ? b0 : b1;
        double ie = sqrt((e - px) * (e - px) + py * py), ec = sqrt((cx - e) * (cx - e) + cy * cy);
        ex_update(ws, vc, sigma + ie + ec, 0);
    }
    int m1 = ex_next[m], m2 = ex_prev[m];
    if (b0 < tc) {
        /* left child: edge C -> A (half-edge 3f+m2), rays through [b0, min(b1, tc)] */
        int32_t hl = 3 * f + m2;
        double lac = r->len[m2], il = 1.0 / (lac < EX_SHORT_CHILD * L ? hypot(cx, cy) : lac);
        double ux = -cx * il, uy = -cy * il;
        double s_hi = b0 <= 0.0 ? lac : ex_hit(cx, cy, ux, uy, px, py, b0, lac);
        double s_lo = tc <= b1 ? 0.0 : ex_hit(cx, cy, ux, uy, px, py, b1, lac);
        double qx = px - cx, qy = py - cy;
        double ix = qx * ux + qy * uy, iy = ux * qy - uy * qx;
        /* its end at C when the window holds C (C updated above), at A
         * when the window starts at A (A updated where it was emitted):
         * the same distance again, in another frame */
        ex_emit_inline(ws, hl, s_lo, s_hi, ix, iy > 0.0 ? iy : 0.0, sigma,
                       (tc <= b1) | (b0 <= 0.0) << 1);
    }
    if (b1 > tc) {
        /* right child: edge B -> C (half-edge 3f+m1), rays through [max(b0, tc), b1] */
        int32_t hr = 3 * f + m1;
        double lbc = r->len[m1], il = 1.0 / (lbc < EX_SHORT_CHILD * L ? hypot(cx - L, cy) : lbc);
        double ux = (cx - L) * il, uy = cy * il;
        double s_lo = b1 >= L ? 0.0 : ex_hit(L, 0.0, ux, uy, px, py, b1, lbc);
        double s_hi = tc >= b0 ? lbc : ex_hit(L, 0.0, ux, uy, px, py, b0, lbc);
        double qx = px - L, qy = py;
        double ix = qx * ux + qy * uy, iy = ux * qy - uy * qx;
        /* (likewise at B and at C) */
        ex_emit_inline(ws, hr, s_lo, s_hi, ix, iy > 0.0 ? iy : 0.0, sigma,
                       (b1 >= L) | (tc >= b0) << 1);
    }
}

/* Where the ray from C = (cx, cy) at angle psi from C -> (0,0), turning
 * towards (L, 0), meets the x axis, clamped to [0, L]. */
static double ex_ray_x(double cx, double cy, double psi, double L)
{
    double r = sqrt(cx * cx + cy * cy);
    double ux = -cx / r, uy = -cy / r, c = cos(psi), sn = sin(psi);
    double dx = ux * c - uy * sn, dy = ux * sn + uy * c;
    if (!(dy < 0.0))
        return dx < 0.0 ? 0.0 : L;
    double x = cx + (-cy / dy) * dx;
    return x < 0.0 ? 0.0 : x > L ? L : x;
}

/* A pseudo-source at v with distance dv: a window on the far edge of every
 * face around v. */
static void ex_start_vertex(mfmm_exact_ws *ws, int32_t v, double dv)
{
    ws->n_pseudo++;
    double th = ws->in_angle[v], total = ws->fan_total[v];
    if (!(th == th) || !(total == total)) {
        for (int32_t i = ws->vf_offset[v]; i < ws->vf_offset[v + 1]; i++) {
            int32_t c = ex_corner(ws->vf_corner, ws->face_in, i);
            const ex_face *r = ws->fr + c / 3;
            if (r->skip == 1) {
                /* a zero-area face's edges from v: real paths (an
                 * all-degenerate strip reached nothing) */
                int k = c % 3;
                ex_update(ws, r->v[ex_next[k]], dv + r->len[ex_prev[k]], 0);
                ex_update(ws, r->v[ex_prev[k]], dv + r->len[ex_next[k]], 0);
                /* v on the opposite edge (a needle's middle): v lies on the
                 * edge of the face across it, and starts windows there */
                if (r->cx[k] >= 0.0 && r->cx[k] <= r->len[k])
                    ex_emit(ws, c, 0.0, r->len[k], r->cx[k], 0.0, dv, 0);
            }
            if (r->skip)
                continue;
            ex_emit(ws, c, 0.0, r->len[c % 3], r->cx[c % 3], r->cy[c % 3], dv, 0);
        }
        return;
    }
    /* A shortest path that arrived from direction th can go on through v
     * only where both angles it makes there are >= pi (else cutting the
     * corner is shorter): the "shadow" [th + pi, th + total - pi], modulo
     * total. Elsewhere the windows passing v already carry the distance. */
    double lo = th + EX_PI - EX_SHADOW_MARGIN, hi = th + total - EX_PI + EX_SHADOW_MARGIN;
    if (!(hi > lo))
        return;
    for (int32_t i = ws->vf_offset[v]; i < ws->vf_offset[v + 1]; i++) {
        int32_t c = ex_corner(ws->vf_corner, ws->face_in, i);
        if (ws->fr[c / 3].skip) /* a copy: the fan holds no zero-area face */
            continue;
        double ang = ws->fr[c / 3].angle[c % 3];
        double f0 = ws->fr[c / 3].sgn[c % 3] > 0 ? ws->fan_a0[c] : ws->fan_a0[c] - ang, f1 = f0 + ang;
        for (int wrap = -1; wrap <= 1; wrap++) {
            double a = lo + wrap * total, b = hi + wrap * total;
            if (a < f0)
                a = f0;
            if (b > f1)
                b = f1;
            if (!(b > a))
                continue;
            /* psi: angles from the direction to the corner's first vertex */
            double p0, p1;
            if (ws->fr[c / 3].sgn[c % 3] > 0) {
                p0 = a - f0;
                p1 = b - f0;
            } else {
                p0 = f1 - b;
                p1 = f1 - a;
            }
            const ex_face *r = ws->fr + c / 3;
            double L = r->len[c % 3], cx = r->cx[c % 3], cy = r->cy[c % 3];
            double s0 = p0 <= 0.0 ? 0.0 : ex_ray_x(cx, cy, p0, L);
            double s1 = p1 >= ang ? L : ex_ray_x(cx, cy, p1, L);
            ex_emit(ws, c, s0, s1, cx, cy, dv, 0);
        }
    }
}

/* A point source in face f (barycentric w, not at a corner): a window on
 * each of f's edges. */
static void ex_start_face(mfmm_exact_ws *ws, int32_t f, const double *w, double value)
{
    ws->n_pseudo++;
    for (int k = 0; k < 3; k++) {
        int32_t h = 3 * f + k;
        /* corners k+1 at (0,0), k+2 at (L,0), k at (cx,cy) */
        const ex_face *r = ws->fr + f;
        double ix = w[(k + 2) % 3] * r->len[k] + w[k] * r->cx[k];
        double iy = w[k] * r->cy[k];
        ex_emit(ws, h, 0.0, r->len[k], ix, iy, value, 0);
    }
}

/* Clears the previous run's vertex state (only what it touched). */
static void ex_reset(mfmm_exact_ws *ws)
{
    for (int32_t i = 0; i < ws->n_touched; i++) {
        int32_t v = ws->touched[i];
        ws->d[v] = INFINITY;
        ws->emitted[v] = INFINITY;
        ws->in_patch[v] = 0;
    }
    ws->n_touched = 0;
    for (int32_t i = 0; i < ws->rec_n; i++)
        ws->nm_head[ws->rec[i].slot] = -1;
    ws->rec_n = 0;
    /* a run that emptied its queue left every bucket empty: only a failed
     * one (out of memory) needs them cleared (48 KB, a patch uses ~30) */
    if (ws->heap_n != 0)
        for (int32_t i = 0; i < 3 * EX_NB; i++)
            ws->bhead[i] = -1;
    ws->heap_n = 0;
    ws->heap_used = 0;
    ws->qfree = -1;
    ws->over = -1;
    ws->n_in = 0;
    ws->cur = -((int64_t)1 << 62);
    ws->redist = ws->cur;
    ws->failed = 0;
    ws->over_budget = 0;
    ws->stalled = 0;
    ws->n_windows = ws->n_propagated = ws->n_pseudo = ws->peak_windows = 0;
    ws->peak_bytes = ex_bytes(ws, ws->heap_cap);
}

/* Whether the windows created so far are past what the vertices reached
 * so far can need: budget (1 + sqrt(n) / 8) a vertex, n vertices reached
 * (plus 64 budget), budget 64: 12-20 times what a solve needs on camelhead
 * (78 windows a vertex) and beetle (17). Past it, windows are going round
 * without getting farther, which degenerate folded fans (coincident
 * vertices) allowed, and ties kept at coincident vertices. */
static int ex_over_budget(const mfmm_exact_ws *ws)
{
    double n = (double)ws->n_touched;
    return (double)ws->n_windows > ws->budget * (64.0 + n * (1.0 + sqrt(n) / 8.0));
}

void mfmm_exact_ws_set_budget(mfmm_exact_ws *ws, double windows_per_vertex)
{
    ws->budget = windows_per_vertex;
}

static void ex_heap_up(const double *d, int32_t *heap, int32_t *pos, int32_t i)
{
    int32_t v = heap[i];
    while (i > 0) {
        int32_t p = (i - 1) / 2;
        if (!(d[v] < d[heap[p]]))
            break;
        heap[i] = heap[p];
        pos[heap[i]] = i;
        i = p;
    }
    heap[i] = v;
    pos[v] = i;
}

static void ex_heap_down(const double *d, int32_t *heap, int32_t *pos, int32_t n, int32_t i)
{
    int32_t v = heap[i];
    for (;;) {
        int32_t c = 2 * i + 1;
        if (c >= n)
            break;
        if (c + 1 < n && d[heap[c + 1]] < d[heap[c]])
            c++;
        if (!(d[heap[c]] < d[v]))
            break;
        heap[i] = heap[c];
        pos[heap[i]] = i;
        i = c;
    }
    heap[i] = v;
    pos[v] = i;
}

/* After a stalled run: every distance lowered to the shortest path along
 * edges from the distances found, d(v) <= d(u) + |u v| (Dijkstra), each
 * the length of a real path, so that no vertex a path reaches is left at
 * +inf; within max_d. */
static mfmm_status ex_relax_edges(mfmm_exact_ws *ws)
{
    int32_t nv = ws->nv, n = 0;
    int32_t *heap = malloc((size_t)(nv ? nv : 1) * sizeof *heap);
    int32_t *pos = malloc((size_t)(nv ? nv : 1) * sizeof *pos);
    if (!heap || !pos) {
        free(heap);
        free(pos);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    double *d = ws->d;
    for (int32_t v = 0; v < nv; v++)
        pos[v] = -1;
    for (int32_t i = 0; i < ws->n_touched; i++) {
        int32_t v = ws->touched[i];
        if (d[v] <= ws->max_d) {
            heap[n] = v;
            ex_heap_up(d, heap, pos, n++);
        }
    }
    while (n > 0) {
        int32_t u = heap[0];
        pos[u] = -2;
        heap[0] = heap[--n];
        if (n > 0)
            ex_heap_down(d, heap, pos, n, 0);
        for (int32_t j = ws->vf_offset[u]; j < ws->vf_offset[u + 1]; j++) {
            int32_t c = ex_corner(ws->vf_corner, ws->face_in, j);
            const ex_face *r = ws->fr + c / 3;
            int k = c % 3;
            for (int side = 0; side < 2; side++) {
                int32_t a = r->v[side ? ex_prev[k] : ex_next[k]];
                double da = d[u] + r->len[side ? ex_next[k] : ex_prev[k]];
                if (!(da < d[a]) || da > ws->max_d || pos[a] == -2)
                    continue;
                if (d[a] == INFINITY)
                    ws->touched[ws->n_touched++] = a;
                d[a] = da;
                if (pos[a] < 0) {
                    heap[n] = a;
                    ex_heap_up(d, heap, pos, n++);
                } else {
                    ex_heap_up(d, heap, pos, pos[a]);
                }
            }
        }
    }
    free(heap);
    free(pos);
    return MFMM_OK;
}

/* The propagation from checked sources; d[] holds the result for touched
 * vertices (values > max_d are not final). */
static mfmm_status ex_run_once(mfmm_exact_ws *ws, const mfmm_source *sources,
                               int32_t n_sources, double max_d, size_t memory_limit)
{
    ex_reset(ws);
    ws->max_d = max_d;
    ws->memory_limit = memory_limit;
    if (memory_limit && ws->fixed_bytes > memory_limit)
        return MFMM_ERR_MEMORY_LIMIT;
    if (memory_limit && ex_bytes(ws, ws->heap_cap) > memory_limit) {
        /* the queue an earlier solve grew is empty now: give it back */
        free(ws->heap);
        ws->heap = NULL;
        ws->heap_cap = 0;
        free(ws->rec);
        ws->rec = NULL;
        ws->rec_cap = 0;
        ws->peak_bytes = ex_bytes(ws, 0);
    }
    for (int32_t i = 0; i < n_sources; i++) {
        const mfmm_source *s = sources + i;
        if (s->face < 0) {
            ex_update(ws, s->vertex, s->value, 1);
            continue;
        }
        /* a point of a copy is that point of its original */
        int32_t face = mfmm_mesh_original(ws->mesh, s->face);
        const int32_t *fv = ws->mesh->face_records[face].v, *sv = ws->mesh->face_records[s->face].v;
        double w[3], sum = 0.0;
        for (int k = 0; k < 3; k++) {
            int j = sv[0] == fv[k] ? 0 : sv[1] == fv[k] ? 1 : 2;
            w[k] = s->bary[j] > 0.0 ? s->bary[j] : 0.0;
            sum += w[k];
        }
        int corner = -1;
        for (int k = 0; k < 3; k++) {
            w[k] /= sum;
            if (w[k] >= 1.0 - 1e-12)
                corner = k;
        }
        if (corner >= 0) {
            /* at a corner: a vertex source, offset by the (tiny) distance */
            const double *X = ws->mesh->xyz;
            double p[3] = {0.0, 0.0, 0.0};
            for (int k = 0; k < 3; k++)
                for (int e = 0; e < 3; e++)
                    p[e] += w[k] * X[3 * (size_t)fv[k] + e];
            ex_update(ws, fv[corner], s->value + vdist(p, X + 3 * (size_t)fv[corner]), 1);
            continue;
        }
        ex_start_face(ws, ws->face_in[face], w, s->value);
    }
    for (int64_t n = 1; ws->heap_n > 0 && !ws->failed; n++) {
        if (!(n & 4095) && ex_over_budget(ws)) {
            if (ws->n_nm > 0 && !ws->walls)
                ws->over_budget = 1;
            else
                ws->stalled = 1;
            break;
        }
        /* about every 5 ms */
        if (!(n & 65535) && ws->interrupt && ws->interrupt(ws->interrupt_user)) {
            ws->failed = MFMM_ERR_CANCELLED;
            break;
        }
        ex_entry e;
        ex_pop(ws, &e);
        if (e.he < 0) {
            int32_t v = -e.he - 1;
            if (e.key != ws->d[v] || !(ws->emitted[v] > e.key))
                continue;
            ws->emitted[v] = e.key;
            ex_start_vertex(ws, v, e.key);
        } else {
            ex_propagate(ws, &e);
        }
    }
    return ws->failed ? (mfmm_status)ws->failed : MFMM_OK;
}

/* ex_run_once across non-manifold edges; where its windows pass their
 * budget (ex_over_budget), again with those edges as walls: upper bounds
 * there, the solver's behaviour before it crossed them (mfmm_exact_info's
 * nonmanifold_walls says which). A run past its budget otherwise stops, and
 * paths along edges finish it (ex_relax_edges): a defect's values are then
 * too long, never too short, and the solve ends. */
static mfmm_status ex_run(mfmm_exact_ws *ws, const mfmm_source *sources, int32_t n_sources,
                          double max_d, size_t memory_limit)
{
    ws->walls = 0;
    mfmm_status st = ex_run_once(ws, sources, n_sources, max_d, memory_limit);
    if (st == MFMM_OK && ws->over_budget) {
        ws->walls = 1;
        st = ex_run_once(ws, sources, n_sources, max_d, memory_limit);
    }
    if (st == MFMM_OK && ws->stalled)
        st = ex_relax_edges(ws);
    return st;
}

static void ex_fill_info(const mfmm_exact_ws *ws, mfmm_exact_info *info)
{
    if (!info)
        return;
    info->n_windows = ws->n_windows;
    info->n_propagated = ws->n_propagated;
    info->n_pseudo_sources = ws->n_pseudo;
    info->peak_windows = ws->peak_windows;
    info->peak_bytes = ws->peak_bytes;
    info->nonmanifold_walls = ws->walls;
}

/* Sources as mfmm_solve checks them, and not in a face this solver skips. */
static mfmm_status ex_check_sources(const mfmm_exact_ws *ws, const mfmm_source *sources,
                                    int32_t n_sources, mfmm_error *err)
{
    for (int32_t i = 0; i < n_sources; i++) {
        mfmm_status st = mfmm_check_source(ws->mesh, sources + i, i, err);
        if (st != MFMM_OK)
            return st;
        double b[3];
        if (sources[i].face >= 0 &&
            ws->fr[ws->face_in[mfmm_order_point_in(ws->mesh, sources[i].face, sources[i].bary, b)]]
                    .skip == 1)
            return mfmm_fail(err, MFMM_ERR_DEGENERATE_SOURCE, i,
                             "source %ld lies on face %ld, which has zero area", (long)i,
                             (long)sources[i].face);
    }
    return MFMM_OK;
}

mfmm_status mfmm_solve_exact(mfmm_exact_solver *solver, const mfmm_source *sources,
                             int32_t n_sources, const mfmm_exact_options *options,
                             double *distances, mfmm_exact_info *info, mfmm_error *err)
{
    mfmm_ok(err);
    if (info)
        memset(info, 0, sizeof *info);
    if (!solver || !distances)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "%s is NULL",
                         !solver ? "solver" : "distances");
    for (int32_t v = 0; v < solver->nv; v++)
        distances[v] = INFINITY;
    if (!sources)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "sources is NULL");
    if (n_sources < 1)
        return mfmm_fail(err, MFMM_ERR_BAD_COUNT, -1, "n_sources is %ld; at least one is needed",
                         (long)n_sources);
    mfmm_exact_options defaults;
    if (!options) {
        mfmm_exact_options_init(&defaults);
        options = &defaults;
    }
    if (mfmm_check_struct_size(options, sizeof *options, "mfmm_exact_options", err) != MFMM_OK)
        return MFMM_ERR_BAD_ARGUMENT;
    if (options->cost)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1,
                         "mfmm_solve_exact computes geodesic distance (F = 1) and takes no cost; "
                         "use mfmm_solve for weighted distances");
    double max_d = options->max_distance;
    if (isnan(max_d) || max_d < 0.0)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1, "max_distance is %g; it must be >= 0",
                         max_d);
    mfmm_status st = ex_check_sources(solver, sources, n_sources, err);
    if (st != MFMM_OK)
        return st;
    /* vertex sources in the mesh's internal order (core/order.h) */
    mfmm_mapped_args mapped = {0};
    if (mfmm_order_map_args(solver->mesh, sources, n_sources, NULL, 0, NULL, 0, NULL, &mapped) !=
        MFMM_OK)
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for the sources");
    solver->interrupt = options->interrupt;
    solver->interrupt_user = options->user;
    st = ex_run(solver, mapped.sources, n_sources, max_d, options->memory_limit);
    solver->interrupt = NULL;
    solver->interrupt_user = NULL;
    free(mapped.block);
    ex_fill_info(solver, info);
    if (st == MFMM_ERR_CANCELLED)
        return mfmm_fail(err, st, -1, "the exact solve was interrupted");
    if (st != MFMM_OK) {
        if (st == MFMM_ERR_MEMORY_LIMIT)
            return mfmm_fail(err, st, -1,
                             "the exact solve needed more than memory_limit = %zu bytes "
                             "(%lld windows queued)",
                             options->memory_limit, (long long)solver->heap_n);
        return mfmm_fail(err, st, -1, "out of memory for the window queue");
    }
    for (int32_t i = 0; i < solver->n_touched; i++) {
        int32_t v = solver->touched[i];
        double dv = solver->d[v];
        distances[mfmm_vertex_out(solver->mesh, v)] = dv <= max_d ? dv : INFINITY;
    }
    return MFMM_OK;
}

mfmm_status mfmm_exact_patch(mfmm_exact_ws *ws, const mfmm_source *sources, int32_t n_sources,
                             double radius, size_t memory_limit, int32_t *n_vertices,
                             const int32_t **vertices, const double **distances,
                             mfmm_exact_info *info)
{
    if (!ws || !sources || !n_vertices || !vertices || !distances)
        return MFMM_ERR_NULL_POINTER;
    *n_vertices = 0;
    *vertices = ws->touched;
    *distances = ws->patch_d;
    if (n_sources < 1)
        return MFMM_ERR_BAD_COUNT;
    if (isnan(radius) || radius < 0.0)
        return MFMM_ERR_BAD_ARGUMENT;
    mfmm_status st = ex_check_sources(ws, sources, n_sources, NULL);
    if (st != MFMM_OK)
        return st;
    st = ex_run(ws, sources, n_sources, radius, memory_limit);
    ex_fill_info(ws, info);
    if (st != MFMM_OK)
        return st;
    /* the vertices whose distances are final, moved to the front of touched
     * (the rest stay behind them, so the next reset still clears them):
     * those within the radius, and those beyond it by less than their
     * least height h over the opposite edges of their faces. A path to v
     * ends with a segment in one of v's faces from the opposite edge (or
     * along an edge from a neighbour u, |u v| >= h), so it crosses that
     * edge (or passes u) at a distance <= d(v) - h <= radius: every window
     * and pseudo-source on it was propagated, and d(v) is exact (d is an
     * upper bound, the length of a real path, so d(v) - h <= radius holds
     * for the true distance too). That ring is free and, seeded with the
     * rest, lowers the march's mean error by 5-15 %. */
    int32_t n = 0;
    for (int32_t i = 0; i < ws->n_touched; i++) {
        int32_t v = ws->touched[i];
        double dv = ws->d[v];
        int final = dv <= radius;
        if (!final && dv < INFINITY)
            final = dv - ws->height[v] <= radius;
        if (final) {
            ws->in_patch[v] = 1;
            ws->touched[i] = ws->touched[n];
            ws->touched[n] = v;
            ws->patch_d[n] = ws->d[v];
            n++;
        }
    }
    *n_vertices = n;
    return MFMM_OK;
}

mfmm_status mfmm_exact_patch_check(mfmm_exact_ws *ws, const mfmm_source *src, int32_t *n_vertices,
                                   int32_t *n_rejected)
{
    if (!ws || !src || !n_vertices || !n_rejected)
        return MFMM_ERR_NULL_POINTER;
    *n_rejected = 0;
    int32_t n = *n_vertices;
    if (n <= 0)
        return MFMM_OK;
    const double *X = ws->mesh->xyz;
    /* the source's point, and the real paths that start the edge paths:
     * to the vertex itself, or straight to its face's corners */
    double p[3];
    double *up = ws->emitted; /* edge-path lengths (ex_reset clears them) */
    for (int32_t i = 0; i < n; i++)
        up[ws->touched[i]] = INFINITY;
    if (src->face < 0) {
        memcpy(p, X + 3 * (size_t)src->vertex, sizeof p);
        if (ws->in_patch[src->vertex])
            up[src->vertex] = src->value;
    } else {
        const int32_t *fv = ws->mesh->face_records[src->face].v;
        double w[3], sum = 0.0;
        for (int k = 0; k < 3; k++) {
            w[k] = src->bary[k] > 0.0 ? src->bary[k] : 0.0;
            sum += w[k];
        }
        for (int e = 0; e < 3; e++)
            p[e] = (w[0] * X[3 * (size_t)fv[0] + e] + w[1] * X[3 * (size_t)fv[1] + e] +
                    w[2] * X[3 * (size_t)fv[2] + e]) / sum;
        for (int k = 0; k < 3; k++)
            if (ws->in_patch[fv[k]])
                up[fv[k]] = fmin(up[fv[k]], src->value + vdist(p, X + 3 * (size_t)fv[k]));
    }
    /* edge paths through the patch, each the length of a real path, in one
     * sweep in the order the propagation reached the vertices (about the
     * order of their distances): a vertex reached before its best neighbour
     * gets a longer path, a looser bound (a second sweep, or a Dijkstra's
     * sort, cost 2-5 % of a default row for bounds that need only be real) */
    for (int32_t i = 0; i < n; i++) {
        int32_t v = ws->touched[i];
        double uv = up[v];
        if (uv == INFINITY)
            continue;
        for (int32_t j = ws->vf_offset[v]; j < ws->vf_offset[v + 1]; j++) {
            int32_t c = ex_corner(ws->vf_corner, ws->face_in, j);
            const ex_face *r = ws->fr + c / 3;
            int k = c % 3;
            int32_t a = r->v[ex_next[k]], b = r->v[ex_prev[k]];
            if (ws->in_patch[a])
                up[a] = fmin(up[a], uv + r->len[ex_prev[k]]);
            if (ws->in_patch[b])
                up[b] = fmin(up[b], uv + r->len[ex_next[k]]);
        }
    }
    /* keep, in their order, the vertices within both bounds (to rounding
     * relative to the distance, or to an edge next to the source) */
    double edge = ws->mesh->info.mean_edge_length;
    int32_t kept = 0;
    for (int32_t i = 0; i < n; i++) {
        int32_t v = ws->touched[i];
        double d = ws->patch_d[i];
        double lo = src->value + vdist(p, X + 3 * (size_t)v), hi = up[v];
        double tol = EX_PATCH_TOL * (fmax(fabs(d), fabs(lo)) + edge);
        if (d >= lo - tol && (hi == INFINITY || d <= hi + tol)) {
            ws->touched[i] = ws->touched[kept];
            ws->touched[kept] = v;
            ws->patch_d[kept++] = d;
        } else {
            ws->in_patch[v] = 0;
        }
    }
    *n_rejected = n - kept;
    *n_vertices = kept;
    return MFMM_OK;
}

int mfmm_exact_in_patch(const mfmm_exact_ws *ws, int32_t v)
{
    return ws->in_patch[v];
}
