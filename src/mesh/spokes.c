/* The march's spokes (local_update.h, mfmm_spoke): for each vertex x, what
 * its settling offers each neighbour at F = 1 with unfolding, read from the
 * face records and the virtual edges, in the face walk's order of offers
 * (march.h). Built once per mesh, on the first march that uses them. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "spokes.h"

/* One triangle's update of c, as x's face walk computes it. */
typedef struct spoke_slot {
    int32_t c, y;
    int x_is_a;
    double len; /* |xc| */
    double ly;  /* |yc| */
    double cs;  /* cos at c */
} spoke_slot;

/* Puts slot q into spoke r's slot s. */
static void spoke_put(mfmm_spoke *r, int s, const spoke_slot *q)
{
    r->y[s] = q->y;
    r->ly[s] = q->ly;
    r->cs[s] = q->cs;
    if (q->x_is_a)
        r->x_is_a |= 1u << s;
}

/* A spoke with slot q and no second triangle (y = c: never Alive while c
 * is updated). */
static void spoke_start(mfmm_spoke *r, const spoke_slot *q)
{
    memset(r, 0, sizeof *r);
    r->c = q->c;
    r->len = q->len;
    r->y[1] = q->c;
    r->ly[1] = 1.0;
    r->cs[1] = 0.0;
    spoke_put(r, 0, q);
}

/* x's spokes into out (NULL: counts them); sl: room for 2 x's faces. */
static int32_t vertex_spokes(const mfmm_march_mesh *m, int32_t x, spoke_slot *sl, mfmm_spoke *out)
{
    int32_t n = 0;
    /* the virtual edges that end at x (x = V): the march's virtual stencil
     * of their corner C with A and B (section 4.2) */
    for (int32_t j = m->virt_first[x]; j < m->virt_first[x + 1]; j++, n++) {
        const mfmm_virt *vr = m->virts + j;
        int32_t fc = vr->corner / 3, jc = vr->corner % 3;
        const mfmm_face *fr = m->faces + fc;
        int32_t ja = (jc + 1) % 3, jb = (ja + 1) % 3;
        /* triangle A, V: T(A) first, a = |CV|, b = |AC|; V, B: a = |BC|, b = |CV| */
        spoke_slot sa = {vr->c, fr->v[ja], 0, vr->len, fr->len[jb], vr->cos_a};
        spoke_slot sb = {vr->c, fr->v[jb], 1, vr->len, fr->len[ja], vr->cos_b};
        if (out) {
            spoke_start(out + n, &sa);
            spoke_put(out + n, 1, &sb);
        }
    }
    /* x's faces in fan order: face (x, p, q) updates p (x = B, q = A) and q
     * (x = A, p = B), through V instead of the third vertex at the corner
     * with a virtual edge */
    int32_t ns = 0;
    for (int32_t j = m->wedge_offset[x]; j < m->wedge_offset[x + 1]; j++) {
        int32_t wc = m->wedge[j], f_id = MFMM_WEDGE_FACE(wc);
        const mfmm_face *fr = m->faces + f_id;
        int32_t jp = MFMM_WEDGE_NEXT(wc), jq = MFMM_WEDGE_PREV(wc), k = 3 - jp - jq;
        int32_t p = fr->v[jp], q = fr->v[jq], jv = fr->virt & 3;
        spoke_slot sp = {p, q, 0, fr->len[jq], fr->len[k], fr->cosv[jp]};
        spoke_slot sq = {q, p, 1, fr->len[jp], fr->len[k], fr->cosv[jq]};
        if (jv == jp || jv == jq) {
            int32_t iv = fr->virt >> 2;
            const mfmm_virt *vr = mfmm_march_virt_of(m, iv, 3 * f_id + jv);
            spoke_slot *s = jv == jp ? &sp : &sq;
            s->y = iv;
            s->ly = vr->len;
            s->cs = jv == jp ? vr->cos_b : vr->cos_a;
        }
        sl[ns++] = sp;
        sl[ns++] = sq;
    }
    /* the first face's p goes last, as the face walk offers it (first):
     * around a closed fan it is the last face's q, and pairs with it */
    if (ns >= 2) {
        spoke_slot s0 = sl[0];
        memmove(sl, sl + 1, (size_t)(ns - 1) * sizeof *sl);
        sl[ns - 1] = s0;
    }
    /* a face's q and the next face's p in one spoke (the face walk's pend) */
    for (int32_t i = 0; i < ns; n++) {
        int pair = i + 1 < ns && sl[i + 1].c == sl[i].c && sl[i + 1].len == sl[i].len;
        if (out) {
            spoke_start(out + n, sl + i);
            if (pair)
                spoke_put(out + n, 1, sl + i + 1);
        }
        i += pair ? 2 : 1;
    }
    return n;
}

/* Builds the spokes into mesh (its lock held). */
static mfmm_status spokes_build(mfmm_mesh *mesh)
{
    mfmm_march_mesh m = mfmm_mesh_march_view(mesh);
    int32_t nv = mesh->nv, most = 0;
    for (int32_t x = 0; x < nv; x++)
        if (m.wedge_offset[x + 1] - m.wedge_offset[x] > most)
            most = m.wedge_offset[x + 1] - m.wedge_offset[x];
    spoke_slot *sl = malloc((2 * (size_t)most + 1) * sizeof *sl);
    int32_t *off = malloc(((size_t)nv + 1) * sizeof *off);
    if (!sl || !off) {
        free(sl);
        free(off);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    /* counted first (at most 2 per face corner and 1 per virtual edge:
     * within int32 for nf < 2^27), then written */
    off[0] = 0;
    for (int32_t x = 0; x < nv; x++)
        off[x + 1] = off[x] + vertex_spokes(&m, x, sl, NULL);
    size_t n = (size_t)off[nv];
    void *block = malloc(n * sizeof(mfmm_spoke) + 64);
    if (!block) {
        free(sl);
        free(off);
        return MFMM_ERR_OUT_OF_MEMORY;
    }
    mfmm_spoke *spokes = (mfmm_spoke *)(void *)((char *)block + (64 - (uintptr_t)block % 64) % 64);
    for (int32_t x = 0; x < nv; x++)
        vertex_spokes(&m, x, sl, spokes + off[x]);
    free(sl);
    mesh->spoke_offset = off;
    mesh->spokes = spokes;
    mesh->spoke_block = block;
    mesh->spokes_bytes = n * sizeof(mfmm_spoke) + ((size_t)nv + 1) * sizeof *off;
    return MFMM_OK;
}

mfmm_status mfmm_mesh_spokes_of(const mfmm_mesh *mesh, int eager, const int32_t **offset,
                                const mfmm_spoke **spokes)
{
    /* the mesh's cache is the one mutable part of a built mesh (mesh.h) */
    mfmm_mesh *m = (mfmm_mesh *)(uintptr_t)mesh;
    mfmm_status st = MFMM_OK;
    *offset = NULL;
    *spokes = NULL;
    if (!m->spokes_allowed) /* set at creation: no lock needed */
        return MFMM_OK;
    pthread_mutex_lock(&m->cache_lock);
    if (!m->spokes && (eager || m->spoke_credit >= (int64_t)MFMM_SPOKES_AFTER * m->nv))
        st = spokes_build(m);
    *offset = m->spoke_offset;
    *spokes = m->spokes;
    pthread_mutex_unlock(&m->cache_lock);
    return st;
}

void mfmm_mesh_spokes_count(const mfmm_mesh *mesh, int64_t settled)
{
    mfmm_mesh *m = (mfmm_mesh *)(uintptr_t)mesh;
    if (!m->spokes_allowed || settled <= 0)
        return;
    pthread_mutex_lock(&m->cache_lock);
    if (m->spoke_credit < INT64_MAX - settled)
        m->spoke_credit += settled;
    pthread_mutex_unlock(&m->cache_lock);
}
