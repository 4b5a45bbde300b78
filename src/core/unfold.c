/* Virtual edges for obtuse corners, section 4.2: unfold the faces beyond the
 * edge opposite the obtuse corner C into C's plane until a vertex V falls in
 * the section of directions that make acute angles with both CA and CB; the
 * virtual edge V -> C splits the obtuse angle into two acute ones. */
#include <math.h>
#include <stdlib.h>

#include "mesh.h"

typedef struct vec2 {
    double x, y;
} vec2;

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
        if (m->faces[3 * (size_t)g + k] == v)
            return k;
    return -1;
}

/* The strip of one walk: a step per face entered, and the unfolded ends of
 * the edge it was entered through (to place CV's crossings once V is known). */
typedef struct strip_buf {
    mfmm_virt_step *step;
    vec2 *end; /* 2 per step */
    int32_t n, cap;
} strip_buf;

static int strip_push(strip_buf *sb, mfmm_virt_step st, vec2 p1, vec2 p2)
{
    if (sb->n == sb->cap) {
        if (sb->cap > INT32_MAX / 2)
            return 0;
        int32_t cap = sb->cap ? 2 * sb->cap : 256;
        mfmm_virt_step *s = realloc(sb->step, (size_t)cap * sizeof *s);
        if (!s)
            return 0;
        sb->step = s;
        vec2 *e = realloc(sb->end, 2 * (size_t)cap * sizeof *e);
        if (!e)
            return 0;
        sb->end = e;
        sb->cap = cap;
    }
    sb->step[sb->n] = st;
    sb->end[2 * sb->n] = p1;
    sb->end[2 * sb->n + 1] = p2;
    sb->n++;
    return 1;
}

/* Walks from obtuse corner k of face f; returns 1 and fills the corner's
 * virtual edge and appends its strip to sb, 0 if the walk fails (boundary,
 * non-manifold edge, degenerate face, or more than max_steps faces), -1 when
 * out of memory. */
static int unfold_corner(mfmm_mesh *m, int32_t corner, int32_t max_steps, strip_buf *sb)
{
    int32_t first = sb->n;
    mfmm_corner_full *cr = m->full + corner;
    /* C at the origin, A on the x axis, B above it */
    double cos_c = cr->cos_c, sin_c = sqrt((1.0 - cos_c) * (1.0 + cos_c));
    vec2 pa = {cr->len_b, 0.0}, pb = {cr->len_a * cos_c, cr->len_a * sin_c};
    vec2 p1 = pa, p2 = pb, away = {0.0, 0.0};
    int32_t e1 = cr->a, e2 = cr->b;
    int32_t face = corner / 3, opposite = corner % 3;
    for (int32_t step = 0; step < max_steps; step++) {
        int32_t g = m->face_neighbor[3 * (size_t)face + opposite];
        if (g < 0 || m->degenerate[g])
            break;
        int k1 = local_index(m, g, e1), k2 = local_index(m, g, e2);
        if (k1 < 0 || k2 < 0)
            break;
        int kq = 3 - k1 - k2;
        int32_t q = m->faces[3 * (size_t)g + kq];
        if (q == m->faces[corner] || q == cr->a || q == cr->b)
            break;
        const double *xq = m->xyz + 3 * (size_t)q;
        vec2 pq = unfold_point(p1, p2, dist3(m->xyz + 3 * (size_t)e1, xq),
                               dist3(m->xyz + 3 * (size_t)e2, xq), away);
        mfmm_virt_step rec = {g, q, e1, e2, 0.0};
        if (!strip_push(sb, rec, p1, p2))
            return -1;
        double qa = dot2(pq, pa), qb = dot2(pq, pb);
        if (qa >= 0.0 && qb >= 0.0) {
            /* in the section: both virtual angles are acute */
            double l = sqrt(dot2(pq, pq));
            if (!(l > 0.0))
                break;
            /* where CV crosses each edge of the strip: every edge walked
             * straddles the section, so CV crosses them all, in order */
            for (int32_t i = first; i < sb->n; i++) {
                vec2 u = sb->end[2 * i], w = sb->end[2 * i + 1];
                double den = pq.x * (w.y - u.y) - pq.y * (w.x - u.x);
                double t = den != 0.0 ? -(pq.x * u.y - pq.y * u.x) / den : 0.5;
                sb->step[i].t = t > 0.0 ? (t < 1.0 ? t : 1.0) : 0.0;
            }
            cr->virt = q;
            cr->virt_len = l;
            cr->virt_cos_a = fmin(1.0, qa / (l * cr->len_b));
            cr->virt_cos_b = fmin(1.0, qb / (l * cr->len_a));
            return 1;
        }
        if (qa < 0.0 && qb < 0.0)
            break;
        if (qb < 0.0) { /* on A's side of the section: go on across (q, e2) */
            away = p1;
            p1 = pq;
            e1 = q;
            opposite = k1;
        } else { /* on B's side: go on across (e1, q) */
            away = p2;
            p2 = pq;
            e2 = q;
            opposite = k2;
        }
        face = g;
    }
    sb->n = first;
    return 0;
}

mfmm_status mfmm_mesh_unfold_obtuse(mfmm_mesh *m, int32_t max_steps)
{
    int32_t made = 0, failed = 0;
    size_t nc = 3 * (size_t)m->nf;
    strip_buf sb = {NULL, NULL, 0, 0};
    m->virt_offset = malloc((nc + 1) * sizeof *m->virt_offset);
    if (!m->virt_offset)
        return MFMM_ERR_OUT_OF_MEMORY;
    for (size_t c = 0; c < nc; c++) {
        m->virt_offset[c] = sb.n;
        if (m->full[c].virt != MFMM_VIRT_FAILED)
            continue;
        int r = unfold_corner(m, (int32_t)c, max_steps, &sb);
        if (r < 0) {
            free(sb.step);
            free(sb.end);
            return MFMM_ERR_OUT_OF_MEMORY;
        }
        if (r)
            made++;
        else
            failed++;
    }
    m->virt_offset[nc] = sb.n;
    free(sb.end);
    /* never a NULL array, so that readers need no special case */
    if (sb.n == 0) {
        free(sb.step);
        sb.step = malloc(sizeof *sb.step);
        if (!sb.step)
            return MFMM_ERR_OUT_OF_MEMORY;
    } else {
        mfmm_virt_step *fit = realloc(sb.step, (size_t)sb.n * sizeof *sb.step);
        if (fit)
            sb.step = fit;
    }
    m->virt_steps = sb.step;
    m->info.n_virtual_edges = made;
    m->info.n_unfold_failures = failed;
    return MFMM_OK;
}
