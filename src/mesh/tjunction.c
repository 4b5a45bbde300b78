/* T-junctions closed by needle faces (tjunction.h, mfmm_mesh_close_t_junctions).
 *
 * Exporters and repair tools close a T-junction, a vertex M lying inside
 * the edge AB of face A-B-C, with a zero-area face A-M-B. That face takes no
 * triangle update (section 4.1 needs an area), so the march crossed the
 * junction only along edges, through A or B (the unit square split at
 * (.5, .5) with M = (.25, .25): 1.06 where the surface gives 0.79), and so
 * did paths. The needle stands for M lying on AB: here A-B-C is split at M
 * into the faces it would have had, and the needle dropped; on a
 * non-manifold AB every face on it is (a book with a needle: the march had
 * a page's far vertex at 4.20 for 3.24). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tjunction.h"
#include "build.h"
#include "base/error.h"

/* At most this many rounds (a round splits each face once, so a chain of
 * k vertices on one edge takes k rounds; each round drops a needle of the
 * input, plan_round); needles left after it stay zero-area faces, as
 * before. */
#define MAX_ROUNDS 64
/* At most this many faces across a needle's long edge (a non-manifold
 * edge's pages); a needle with more stays. */
#define MAX_PAGES 16

/* The faces a mesh is built from: vertex ids as given, and for each face
 * the input face it was cut from and its corners' barycentric coordinates
 * in that face. */
typedef struct face_list {
    int32_t n;
    int32_t *v;     /* (n, 3) */
    int32_t *orig;  /* (n,) */
    double *bary;   /* (n, 3, 3) */
} face_list;

static void list_free(face_list *l)
{
    free(l->v);
    free(l->orig);
    free(l->bary);
    memset(l, 0, sizeof *l);
}

static int list_alloc(face_list *l, int32_t n)
{
    size_t k = n > 0 ? (size_t)n : 1;
    l->n = n;
    l->v = malloc(3 * k * sizeof *l->v);
    l->orig = malloc(k * sizeof *l->orig);
    l->bary = malloc(9 * k * sizeof *l->bary);
    return l->v && l->orig && l->bary;
}

/* What a round does to face w of the list it was built from. */
enum { KEEP = 0, DROP = 1, SPLIT = 2 };
typedef struct split_plan {
    int32_t m;     /* M, as given */
    int8_t ja, jb; /* A's and B's corners in the face */
    double s;      /* M = A + s (B - A) */
} split_plan;

/* 1 when face w of list l (NULL: the input) was cut from its input face. */
static int is_piece(const face_list *l, int32_t w)
{
    for (int i = 0; l && i < 9; i++)
        if (l->bary[9 * (size_t)w + i] != (i % 4 == 0 ? 1.0 : 0.0))
            return 1;
    return 0;
}

/* Plans a round on mesh m built from list l (NULL: the input): action per
 * face of l, and where a face splits. Only a face of the input is a needle
 * (a piece may be split again, as along a chain, but a piece of zero area,
 * cut near a corner, is never dropped), so each round drops needles of the
 * input and the rounds end. Returns the number of splits. */
static int32_t plan_round(const mfmm_mesh *m, const face_list *l, uint8_t *action,
                          split_plan *plan)
{
    int32_t n_split = 0;
    for (int32_t f = 0; f < m->nf; f++) {
        if (!mfmm_mesh_degenerate(m, f))
            continue;
        int32_t w = m->face_to_external[f];
        if (is_piece(l, w))
            continue;
        int32_t o = mfmm_mesh_original(m, f);
        if (o != f) { /* a copy of a needle goes with it */
            if (action[m->face_to_external[o]] == DROP)
                action[w] = DROP;
            continue;
        }
        const mfmm_face *fr = m->face_records + f;
        int km = 0; /* M: the corner opposite the longest edge */
        for (int k = 1; k < 3; k++)
            if (fr->len[k] > fr->len[km])
                km = k;
        int32_t a = fr->v[(km + 1) % 3], b = fr->v[(km + 2) % 3], mv = fr->v[km];
        const double *pa = m->xyz + 3 * (size_t)a, *pb = m->xyz + 3 * (size_t)b,
                     *pm = m->xyz + 3 * (size_t)mv;
        double ab2 = 0.0, am_ab = 0.0;
        for (int d = 0; d < 3; d++) {
            ab2 += (pb[d] - pa[d]) * (pb[d] - pa[d]);
            am_ab += (pm[d] - pa[d]) * (pb[d] - pa[d]);
        }
        double s = am_ab / ab2;
        /* M strictly inside AB (not a coincident vertex) */
        if (!(s > 0.0 && s < 1.0) || !(fr->len[(km + 1) % 3] > 0.0) ||
            !(fr->len[(km + 2) % 3] > 0.0))
            continue;
        /* the faces across AB: one, or the pages of a non-manifold edge (M
         * lies on AB in each of them, as the exact solver's fan-out has
         * it); each with an area, none a copy (a copy left whole would
         * overlap the pieces), none split this round already. Copies of
         * the needle go with it. */
        int32_t across[MAX_PAGES];
        int8_t ja[MAX_PAGES], jb[MAX_PAGES];
        int n_across = 0, ok = 1;
        for (int32_t i = m->vertex_face_offset[a]; i < m->vertex_face_offset[a + 1] && ok; i++) {
            int32_t g = MFMM_WEDGE_FACE(m->vertex_wedge[i]);
            const int32_t *gv = m->face_records[g].v;
            int jb_g = gv[0] == b ? 0 : gv[1] == b ? 1 : gv[2] == b ? 2 : -1;
            if (g == f || jb_g < 0 || mfmm_mesh_original(m, g) == f)
                continue;
            if (n_across == MAX_PAGES || mfmm_mesh_degenerate(m, g) || mfmm_mesh_copy(m, g) ||
                action[m->face_to_external[g]] != KEEP) {
                ok = 0;
                break;
            }
            across[n_across] = g;
            ja[n_across] = (int8_t)(gv[0] == a ? 0 : gv[1] == a ? 1 : 2);
            jb[n_across++] = (int8_t)jb_g;
        }
        for (int q = 0; q < n_across && ok; q++) /* a face copied later */
            ok = !(across[q] + 1 < m->nf && mfmm_mesh_copy(m, across[q] + 1));
        if (!ok || n_across == 0)
            continue;
        action[w] = DROP;
        for (int q = 0; q < n_across; q++) {
            int32_t wg = m->face_to_external[across[q]];
            action[wg] = SPLIT;
            plan[wg].m = m->to_external[mv];
            plan[wg].ja = ja[q];
            plan[wg].jb = jb[q];
            plan[wg].s = s;
            n_split++;
        }
    }
    return n_split;
}

/* The next round's list: l with its needles dropped and faces split. */
static int apply_round(const face_list *l, const uint8_t *action, const split_plan *plan,
                       face_list *out)
{
    int32_t n = 0;
    for (int32_t w = 0; w < l->n; w++)
        n += action[w] == KEEP ? 1 : action[w] == SPLIT ? 2 : 0;
    if (!list_alloc(out, n))
        return 0;
    int32_t i = 0;
    for (int32_t w = 0; w < l->n; w++) {
        if (action[w] == DROP)
            continue;
        for (int piece = 0; piece < (action[w] == SPLIT ? 2 : 1); piece++, i++) {
            memcpy(out->v + 3 * (size_t)i, l->v + 3 * (size_t)w, 3 * sizeof *out->v);
            memcpy(out->bary + 9 * (size_t)i, l->bary + 9 * (size_t)w, 9 * sizeof *out->bary);
            out->orig[i] = l->orig[w];
            if (action[w] != SPLIT)
                continue;
            /* piece 0 keeps A (M in B's corner), piece 1 keeps B */
            const split_plan *p = plan + w;
            int j = piece == 0 ? p->jb : p->ja;
            const double *ka = l->bary + 9 * (size_t)w + 3 * p->ja,
                         *kb = l->bary + 9 * (size_t)w + 3 * p->jb;
            out->v[3 * (size_t)i + j] = p->m;
            for (int c = 0; c < 3; c++)
                out->bary[9 * (size_t)i + 3 * j + c] = (1.0 - p->s) * ka[c] + p->s * kb[c];
        }
    }
    return 1;
}

/* Gives mesh m (built from list l) the input's face ids and the pieces. */
static mfmm_status map_to_input(mfmm_mesh *m, const face_list *l, int32_t nf_in)
{
    int32_t *to_internal = malloc((size_t)nf_in * sizeof *to_internal);
    m->piece_next = malloc((size_t)m->nf * sizeof *m->piece_next);
    m->piece_bary = malloc(9 * (size_t)m->nf * sizeof *m->piece_bary);
    if (!to_internal || !m->piece_next || !m->piece_bary) {
        free(to_internal);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    for (int32_t f = 0; f < nf_in; f++)
        to_internal[f] = -1;
    /* backwards, so that each input face's first piece is its least id */
    for (int32_t f = m->nf - 1; f >= 0; f--) {
        int32_t w = m->face_to_external[f], o = l->orig[w];
        memcpy(m->piece_bary + 9 * (size_t)f, l->bary + 9 * (size_t)w, 9 * sizeof *m->piece_bary);
        m->piece_next[f] = to_internal[o];
        to_internal[o] = f;
        m->face_to_external[f] = o;
    }
    free(m->face_to_internal);
    m->face_to_internal = to_internal;
    m->nf_in = nf_in;
    m->info.n_faces = nf_in;
    return MFMM_OK;
}

mfmm_status mfmm_mesh_close_t_junctions(mfmm_mesh **mesh, const double *vertices, int32_t nv,
                                        const int32_t *faces, int32_t nf,
                                        const mfmm_mesh_options *opt, mfmm_error *err)
{
    mfmm_mesh *m = *mesh;
    /* counts of the faces as given (mfmm_mesh_info) */
    int32_t n_degenerate = m->info.n_degenerate_faces, n_copies = m->info.n_duplicate_faces;
    face_list l = {0}, next = {0};
    uint8_t *action = calloc((size_t)nf, sizeof *action);
    split_plan *plan = malloc((size_t)nf * sizeof *plan);
    int32_t cap = nf; /* action's and plan's length */
    mfmm_status st = MFMM_OK;
    if (!action || !plan) {
        st = MFMM_ERR_OUT_OF_MEMORY;
        goto done;
    }
    /* round 1 plans on the mesh as given; no list until a split is found */
    if (plan_round(m, NULL, action, plan) == 0)
        goto done;
    if (!list_alloc(&l, nf)) {
        st = MFMM_ERR_OUT_OF_MEMORY;
        goto done;
    }
    memcpy(l.v, faces, 3 * (size_t)nf * sizeof *l.v);
    for (int32_t f = 0; f < nf; f++) {
        l.orig[f] = f;
        for (int i = 0; i < 9; i++)
            l.bary[9 * (size_t)f + i] = i % 4 == 0 ? 1.0 : 0.0;
    }
    for (int round = 0; round < MAX_ROUNDS; round++) {
        if (round > 0) {
            if (l.n > cap) { /* a needle on a non-manifold edge splits each page */
                uint8_t *na = realloc(action, (size_t)l.n * sizeof *action);
                if (na)
                    action = na;
                split_plan *np = realloc(plan, (size_t)l.n * sizeof *plan);
                if (np)
                    plan = np;
                if (!na || !np) {
                    st = MFMM_ERR_OUT_OF_MEMORY;
                    goto done;
                }
                cap = l.n;
            }
            memset(action, 0, (size_t)l.n);
            if (plan_round(m, &l, action, plan) == 0)
                break;
        }
        if (!apply_round(&l, action, plan, &next)) {
            st = MFMM_ERR_OUT_OF_MEMORY;
            goto done;
        }
        list_free(&l);
        l = next;
        memset(&next, 0, sizeof next);
        mfmm_mesh_destroy(m);
        m = NULL;
        st = mfmm_mesh_build(vertices, nv, l.v, l.n, opt, &m, err);
        if (st != MFMM_OK)
            goto done;
    }
    st = map_to_input(m, &l, nf);
    m->info.n_degenerate_faces = n_degenerate;
    m->info.n_duplicate_faces = n_copies;
done:
    list_free(&l);
    list_free(&next);
    free(action);
    free(plan);
    if (st != MFMM_OK) {
        mfmm_mesh_destroy(m);
        m = NULL;
        if (st == MFMM_ERR_OUT_OF_MEMORY)
            mfmm_fail(err, st, -1, "out of memory closing the mesh's T-junctions");
    }
    *mesh = m;
    return st;
}
