/* The mesh a command works on: the file loaded and built, its vertices in
 * no face, and with --weld its coincident vertices welded into one, with
 * the maps that keep every argument and result in the file's own vertex
 * and face ids. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

int cli_weld(const double *V, int32_t nv, int32_t *F, int32_t nf, int32_t *map, double *W,
             int32_t *face_in, int32_t *n_welded, int32_t *n_kept)
{
    int32_t nw = 0;
    if (mfmm_weld_map(V, nv, map, &nw, NULL) != MFMM_OK)
        return -1;
    for (int32_t v = 0, next = 0; v < nv; v++)
        if (map[v] == next) /* its first occurrence */
            memcpy(W + 3 * (size_t)next++, V + 3 * (size_t)v, 3 * sizeof *W);
    int32_t kept = 0;
    for (int32_t f = 0; f < nf; f++) {
        int32_t a = map[F[3 * (size_t)f]], b = map[F[3 * (size_t)f + 1]],
                c = map[F[3 * (size_t)f + 2]];
        if (a == b || b == c || a == c)
            continue;
        F[3 * (size_t)kept] = a;
        F[3 * (size_t)kept + 1] = b;
        F[3 * (size_t)kept + 2] = c;
        if (face_in)
            face_in[kept] = f;
        kept++;
    }
    *n_welded = nw;
    *n_kept = kept;
    return 0;
}

/* Finite coordinates and face ids in range: otherwise the mesh is built as
 * given, so that the library names the offending vertex or face. */
static int weldable(const double *V, int32_t nv, const int32_t *F, int32_t nf)
{
    for (size_t i = 0; i < 3 * (size_t)nv; i++)
        if (!isfinite(V[i]))
            return 0;
    for (size_t i = 0; i < 3 * (size_t)nf; i++)
        if (F[i] < 0 || F[i] >= nv)
            return 0;
    return 1;
}

/* The welded arrays and maps of m from the file's V, F (F rewritten in
 * place); *W: the welded vertices (malloc'ed). 0, or -1 out of memory. */
static int weld_into(cli_mesh *m, const double *V, int32_t *F, double **W)
{
    int32_t nv = m->nv_in, nf = m->nf_in, nw = 0, kept = 0;
    m->to_welded = malloc((size_t)nv * sizeof *m->to_welded + 1);
    m->face_in = malloc((size_t)nf * sizeof *m->face_in + 1);
    m->face_welded = malloc((size_t)nf * sizeof *m->face_welded + 1);
    *W = malloc(3 * (size_t)nv * sizeof **W + 1);
    if (!m->to_welded || !m->face_in || !m->face_welded || !*W ||
        cli_weld(V, nv, F, nf, m->to_welded, *W, m->face_in, &nw, &kept))
        return -1;
    m->rep = malloc((size_t)nw * sizeof *m->rep + 1);
    if (!m->rep)
        return -1;
    for (int32_t v = 0, next = 0; v < nv; v++)
        if (m->to_welded[v] == next)
            m->rep[next++] = v; /* numbered by first occurrence: the lowest id */
    for (int32_t f = 0; f < nf; f++)
        m->face_welded[f] = -1;
    for (int32_t f = 0; f < kept; f++)
        m->face_welded[m->face_in[f]] = f;
    m->nv = nw;
    m->nf = kept;
    return 0;
}

/* m->in_no_face from the built faces, in the file's vertex ids; NULL when
 * every vertex is in a face. 0, or -1 out of memory. */
static int flag_in_no_face(cli_mesh *m, const int32_t *F)
{
    uint8_t *flag = malloc((size_t)m->nv + 1);
    if (!flag)
        return -1;
    memset(flag, 1, (size_t)m->nv);
    for (size_t i = 0; i < 3 * (size_t)m->nf; i++)
        flag[F[i]] = 0;
    int any = 0;
    for (int32_t v = 0; v < m->nv && !any; v++)
        any = flag[v];
    if (!any) {
        free(flag);
        return 0;
    }
    if (!m->to_welded) {
        m->in_no_face = flag;
        return 0;
    }
    m->in_no_face = malloc((size_t)m->nv_in + 1);
    if (m->in_no_face)
        for (int32_t v = 0; v < m->nv_in; v++)
            m->in_no_face[v] = flag[m->to_welded[v]];
    free(flag);
    return m->in_no_face ? 0 : -1;
}

int cli_mesh_load(cli_mesh *m, const char *path, const mfmm_mesh_options *options, int weld,
                  int keep_arrays)
{
    memset(m, 0, sizeof *m);
    double *V = NULL, *W = NULL;
    int32_t *F = NULL, nv = 0, nf = 0;
    mfmm_error err;
    if (mfmm_load_mesh(path, &V, &nv, &F, &nf, &err) != MFMM_OK) {
        cli_error("%s", err.message);
        return -1;
    }
    m->nv_in = m->nv = nv;
    m->nf_in = m->nf = nf;
    int rc = -1;
    if (weld && weldable(V, nv, F, nf) && weld_into(m, V, F, &W)) {
        cli_error("out of memory");
        goto done;
    }
    const double *built = W ? W : V;
    mfmm_status st = mfmm_mesh_create(built, m->nv, F, m->nf, options, &m->mesh, &err);
    if (st != MFMM_OK) {
        cli_error("%s: %s", path, err.message);
        goto done;
    }
    if (flag_in_no_face(m, F)) {
        cli_error("out of memory");
        goto done;
    }
    if (keep_arrays) {
        m->V = malloc(3 * (size_t)m->nv * sizeof *m->V + 1);
        m->F = malloc(3 * (size_t)m->nf * sizeof *m->F + 1);
        if (!m->V || !m->F) {
            cli_error("out of memory");
            goto done;
        }
        memcpy(m->V, built, 3 * (size_t)m->nv * sizeof *m->V);
        memcpy(m->F, F, 3 * (size_t)m->nf * sizeof *m->F);
    }
    rc = 0;
done:
    mfmm_free(V);
    mfmm_free(F);
    free(W);
    if (rc)
        cli_mesh_free(m);
    return rc;
}

void cli_mesh_free(cli_mesh *m)
{
    mfmm_mesh_destroy(m->mesh);
    free(m->to_welded);
    free(m->rep);
    free(m->face_in);
    free(m->face_welded);
    free(m->in_no_face);
    free(m->V);
    free(m->F);
    memset(m, 0, sizeof *m);
}

mfmm_mesh *cli_load_mesh(const char *path, const mfmm_mesh_options *options,
                         uint8_t **in_no_face)
{
    cli_mesh m;
    if (cli_mesh_load(&m, path, options, 0, 0))
        return NULL;
    mfmm_mesh *mesh = m.mesh;
    if (in_no_face)
        *in_no_face = m.in_no_face;
    else
        free(m.in_no_face);
    return mesh;
}

/* ---- the file's ids -> the built mesh's ---- */

int cli_mesh_vertex(const cli_mesh *m, const char *what, int32_t *v)
{
    if (!m->to_welded)
        return 0;
    if (*v < 0 || *v >= m->nv_in) {
        cli_error("%s: vertex %ld is outside [0, %ld)", what, (long)*v, (long)m->nv_in);
        return -1;
    }
    *v = m->to_welded[*v];
    return 0;
}

int cli_mesh_face(const cli_mesh *m, const char *what, int32_t *f)
{
    if (!m->to_welded)
        return 0;
    if (*f < 0 || *f >= m->nf_in) {
        cli_error("%s: face %ld is outside [0, %ld)", what, (long)*f, (long)m->nf_in);
        return -1;
    }
    if (m->face_welded[*f] < 0) {
        cli_error("%s: face %ld has zero area once its coincident corners are welded "
                  "(--weld dropped it)", what, (long)*f);
        return -1;
    }
    *f = m->face_welded[*f];
    return 0;
}

int cli_mesh_point(const cli_mesh *m, const char *what, mfmm_source *s)
{
    return s->face < 0 ? cli_mesh_vertex(m, what, &s->vertex) : cli_mesh_face(m, what, &s->face);
}

void cli_mesh_cost(const cli_mesh *m, double *cost, int per_face)
{
    if (!m->to_welded)
        return;
    /* in place: the input id of built entry i is >= i */
    if (per_face)
        for (int32_t f = 0; f < m->nf; f++)
            cost[f] = cost[m->face_in[f]];
    else
        for (int32_t v = 0; v < m->nv; v++)
            cost[v] = cost[m->rep[v]];
}

/* ---- the built mesh's results -> the file's ids ---- */

void *cli_mesh_per_input_vertex(const cli_mesh *m, void *values, size_t itemsize)
{
    if (!m->to_welded)
        return values;
    unsigned char *out = malloc((size_t)m->nv_in * itemsize + 1);
    if (!out) {
        cli_error("out of memory");
        free(values);
        return NULL;
    }
    const unsigned char *in = values;
    for (int32_t v = 0; v < m->nv_in; v++)
        memcpy(out + (size_t)v * itemsize, in + (size_t)m->to_welded[v] * itemsize, itemsize);
    free(values);
    return out;
}

int32_t cli_mesh_input_face(const cli_mesh *m, int32_t f)
{
    return m->to_welded && f >= 0 ? m->face_in[f] : f;
}

int32_t cli_mesh_input_vertex(const cli_mesh *m, int32_t v)
{
    return m->to_welded && v >= 0 ? m->rep[v] : v;
}
