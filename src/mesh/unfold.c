/* Virtual edges for obtuse corners, section 4.2: unfold the faces beyond the
 * edge opposite the obtuse corner C into C's plane until a vertex V falls in
 * the section of directions that make acute angles with both CA and CB; the
 * virtual edge V -> C splits the obtuse angle into two acute ones. */
#include <math.h>
#include <stdlib.h>

#include "unfold.h"
#include "base/error.h"

typedef mfmm_vec2 vec2;

static double dot2(vec2 a, vec2 b)
{
    return a.x * b.x + a.y * b.y;
}

static double dist3(const double *p, const double *q)
{
    double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

/* The point at distances r1 from p1 and r2 from p2, on the other side of the
 * line p1 p2 than `away`: the third vertex of the next face, unfolded. */
static vec2 unfold_point(vec2 p1, vec2 p2, double r1, double r2, vec2 away)
{
    vec2 d = {p2.x - p1.x, p2.y - p1.y};
    double len = sqrt(dot2(d, d));
    double s = (len * len + r1 * r1 - r2 * r2) / (2.0 * len);
    double h2 = r1 * r1 - s * s;
    double h = h2 > 0.0 ? sqrt(h2) : 0.0;
    vec2 e = {d.x / len, d.y / len}, n = {-e.y, e.x};
    vec2 w = {away.x - p1.x, away.y - p1.y};
    if (dot2(w, n) > 0.0)
        h = -h;
    vec2 q = {p1.x + s * e.x + h * n.x, p1.y + s * e.y + h * n.y};
    return q;
}

/* Local index in face g of vertex v, or -1. */
static int local_index(const mfmm_mesh *m, int32_t g, int32_t v)
{
    for (int k = 0; k < 3; k++)
        if (m->face_records[g].v[k] == v)
            return k;
    return -1;
}

/* One walk from an obtuse corner C across the edge AB opposite it, face by
 * face (section 4.2), in C's plane: C at the origin, A on the x axis, B
 * above it. The build walks until a vertex lands in the section; a re-walk
 * (mfmm_strip_next) repeats the same steps with the same arithmetic. */
static void walk_init(mfmm_strip_walk *w, const mfmm_mesh *m, int32_t corner, int32_t a,
                      int32_t b, double len_a, double len_b, double cos_c)
{
    double sin_c = sqrt((1.0 - cos_c) * (1.0 + cos_c));
    w->m = m;
    w->corner = corner;
    w->a = a;
    w->b = b;
    w->pa = (vec2){len_b, 0.0};
    w->pb = (vec2){len_a * cos_c, len_a * sin_c};
    w->p1 = w->pa;
    w->p2 = w->pb;
    w->away = (vec2){0.0, 0.0};
    w->e1 = a;
    w->e2 = b;
    w->face = corner / 3;
    w->opposite = corner % 3;
}

/* The face g beyond the edge (e1, e2) and its third vertex q, unfolded to
 * *pq; 0 when the walk cannot go on (boundary, non-manifold edge, zero-area
 * face, or back at C, A or B). */
static int walk_cross(mfmm_strip_walk *w, int32_t *g_out, int32_t *q_out, vec2 *pq)
{
    const mfmm_mesh *m = w->m;
    int32_t g = m->face_neighbor[3 * (size_t)w->face + w->opposite];
    if (g < 0 || mfmm_mesh_degenerate(m, g))
        return 0;
    int k1 = local_index(m, g, w->e1), k2 = local_index(m, g, w->e2);
    if (k1 < 0 || k2 < 0)
        return 0;
    int kq = 3 - k1 - k2;
    int32_t q = m->face_records[g].v[kq];
    if (q == mfmm_mesh_corner_vertex(m, w->corner) || q == w->a || q == w->b)
        return 0;
    const double *xq = m->xyz + 3 * (size_t)q;
    *pq = unfold_point(w->p1, w->p2, dist3(m->xyz + 3 * (size_t)w->e1, xq),
                       dist3(m->xyz + 3 * (size_t)w->e2, xq), w->away);
    w->k1 = k1;
    w->k2 = k2;
    *g_out = g;
    *q_out = q;
    return 1;
}

/* Goes on into face g beyond its vertex q (at pq), which lies on A's side
 * of the section (qb < 0: across (q, e2)) or on B's (across (e1, q)). */
static void walk_advance(mfmm_strip_walk *w, int32_t g, int32_t q, vec2 pq, double qb)
{
    if (qb < 0.0) {
        w->away = w->p1;
        w->p1 = pq;
        w->e1 = q;
        w->opposite = w->k1;
    } else {
        w->away = w->p2;
        w->p2 = pq;
        w->e2 = q;
        w->opposite = w->k2;
    }
    w->face = g;
}

/* Where C -> pv crosses the edge from u to v, as a fraction of it, in [0, 1]:
 * every edge walked straddles the section, so CV crosses them all, in order. */
static double crossing_t(vec2 pv, vec2 u, vec2 v)
{
    double den = pv.x * (v.y - u.y) - pv.y * (v.x - u.x);
    double t = den != 0.0 ? -(pv.x * u.y - pv.y * u.x) / den : 0.5;
    return t > 0.0 ? (t < 1.0 ? t : 1.0) : 0.0;
}

/* The strips of the walks: per step, the vertex off the edge crossed, and
 * the unfolded ends of the edge it was entered through (to test the
 * segment C V against once V is known). */
typedef struct strip_buf {
    int32_t *far;
    vec2 *end; /* 2 per step */
    int32_t n, cap;
} strip_buf;

static int strip_push(strip_buf *sb, int32_t far, vec2 p1, vec2 p2)
{
    if (sb->n == sb->cap) {
        if (sb->cap > INT32_MAX / 2)
            return 0;
        int32_t cap = sb->cap ? 2 * sb->cap : 256;
        int32_t *s = realloc(sb->far, (size_t)cap * sizeof *s);
        if (!s)
            return 0;
        sb->far = s;
        vec2 *e = realloc(sb->end, 2 * (size_t)cap * sizeof *e);
        if (!e)
            return 0;
        sb->end = e;
        sb->cap = cap;
    }
    sb->far[sb->n] = far;
    sb->end[2 * sb->n] = p1;
    sb->end[2 * sb->n + 1] = p2;
    sb->n++;
    return 1;
}

/* Whether the segment from C (the origin) to pv crosses every edge of the
 * strip's steps [first, sb->n) between its ends, in order, before pv: then
 * it runs through the strip's faces and its length is a path's on the
 * surface. A strip that folds back over itself in the unfolding put V in
 * the section but beside the strip, on a book of two pages folded 66
 * degrees: 1167 from C where the surface's shortest path is 4966 and the
 * straight line through space 2896. */
static int strip_holds(const strip_buf *sb, int32_t first, vec2 pv)
{
    const double tol = 1e-9;
    double last = 0.0;
    for (int32_t i = first; i < sb->n; i++) {
        vec2 u = sb->end[2 * i], v = sb->end[2 * i + 1];
        vec2 d = {v.x - u.x, v.y - u.y};
        double den = pv.x * d.y - pv.y * d.x;
        if (!(den != 0.0))
            return 0;
        double t = (u.x * pv.y - u.y * pv.x) / den; /* along the edge */
        double s = (u.x * d.y - u.y * d.x) / den;   /* along C -> V */
        if (!(t >= -tol && t <= 1.0 + tol && s > 0.0 && s <= 1.0 + tol && s >= last - tol))
            return 0;
        last = s;
    }
    return 1;
}

/* (A strip is walked from the face record, which holds the lengths and
 * the cosine of the corner.) */
static void strip_init(mfmm_strip_walk *w)
{
    const mfmm_mesh *m = w->m;
    int32_t corner = w->corner, k = corner % 3;
    const mfmm_face *fr = m->face_records + corner / 3;
    int ka = (k + 1) % 3, kb = (k + 2) % 3;
    walk_init(w, m, corner, fr->v[ka], fr->v[kb], fr->len[ka], fr->len[kb], fr->cosv[k]);
}

/* Walks from the obtuse corner ob; returns 1 and fills its virtual edge and
 * appends its strip to sb, 0 if the walk fails (boundary, non-manifold edge,
 * degenerate face, or more than max_steps faces), -1 when out of memory. */
static int unfold_corner(const mfmm_mesh *m, mfmm_obtuse *ob, int32_t max_steps, strip_buf *sb)
{
    int32_t first = sb->n;
    const mfmm_face *fr = m->face_records + ob->corner / 3;
    int k = ob->corner % 3;
    double len_a = fr->len[(k + 1) % 3], len_b = fr->len[(k + 2) % 3];
    mfmm_strip_walk w;
    w.m = m;
    w.corner = ob->corner;
    strip_init(&w);
    for (int32_t step = 0; step < max_steps; step++) {
        int32_t g, q;
        vec2 pq;
        if (!walk_cross(&w, &g, &q, &pq))
            break;
        if (!strip_push(sb, q, w.p1, w.p2))
            return -1;
        double qa = dot2(pq, w.pa), qb = dot2(pq, w.pb);
        if (qa >= 0.0 && qb >= 0.0) {
            /* in the section: both virtual angles are acute */
            double l = sqrt(dot2(pq, pq));
            if (!(l > 0.0) || !strip_holds(sb, first, pq))
                break;
            ob->virt = q;
            ob->len = l;
            ob->cos_a = fmin(1.0, qa / (l * len_b));
            ob->cos_b = fmin(1.0, qb / (l * len_a));
            ob->strip_at = first;
            ob->strip_n = sb->n - first;
            return 1;
        }
        if (qa < 0.0 && qb < 0.0)
            break;
        walk_advance(&w, g, q, pq, qb);
    }
    sb->n = first;
    return 0;
}

void mfmm_strip_begin(mfmm_strip_walk *w, const mfmm_mesh *mesh, int32_t j)
{
    w->m = mesh;
    w->corner = mesh->virts[j].corner;
    w->n = mesh->virt_strip[j + 1] - mesh->virt_strip[j] + 1; /* (and V's step) */
    /* once to V, for the crossings' t; then from the start again */
    strip_init(w);
    for (int32_t i = 0; i < w->n; i++) {
        int32_t g = -1, q = -1;
        vec2 pq = {0.0, 0.0};
        walk_cross(w, &g, &q, &pq); /* (the build's walk went on here) */
        if (i == w->n - 1)
            w->pv = pq;
        else
            walk_advance(w, g, q, pq, dot2(pq, w->pb));
    }
    strip_init(w);
    w->i = 0;
}

int mfmm_strip_next(mfmm_strip_walk *w, mfmm_virt_step *step)
{
    if (w->i >= w->n)
        return 0;
    int32_t g = -1, q = -1;
    vec2 pq = {0.0, 0.0};
    walk_cross(w, &g, &q, &pq);
    step->face = g;
    step->far = q;
    step->e1 = w->e1;
    step->e2 = w->e2;
    step->t = crossing_t(w->pv, w->p1, w->p2);
    if (++w->i < w->n)
        walk_advance(w, g, q, pq, dot2(pq, w->pb));
    return 1;
}

mfmm_status mfmm_mesh_unfold_obtuse(mfmm_mesh *m, int32_t max_steps, mfmm_obtuse *obtuse,
                                    int32_t n, int32_t **strip_far)
{
    int32_t made = 0, failed = 0;
    strip_buf sb = {NULL, NULL, 0, 0};
    for (int32_t i = 0; i < n; i++) {
        obtuse[i].virt = MFMM_VIRT_FAILED;
        obtuse[i].strip_at = sb.n;
        obtuse[i].strip_n = 0;
        int r = unfold_corner(m, obtuse + i, max_steps, &sb);
        if (r < 0) {
            free(sb.far);
            free(sb.end);
            return MFMM_ERR_OUT_OF_MEMORY;
        }
        if (r)
            made++;
        else
            failed++;
    }
    free(sb.end);
    /* never a NULL array, so that readers need no special case */
    if (!sb.far) {
        sb.far = malloc(sizeof *sb.far);
        if (!sb.far)
            return MFMM_ERR_OUT_OF_MEMORY;
    }
    *strip_far = sb.far;
    m->info.n_virtual_edges = made;
    m->info.n_unfold_failures = failed;
    return MFMM_OK;
}
