/* The readers' shared helpers: growable vectors, number scanning and handing
 * the parsed arrays over (used by obj.c, off.c, ply.c). */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io.h"
#include "base/error.h"

void mfmm_io_vec_init(mfmm_io_vec *v, size_t elem)
{
    v->data = NULL;
    v->len = 0;
    v->cap = 0;
    v->elem = elem;
}

int mfmm_io_vec_reserve(mfmm_io_vec *v, size_t extra)
{
    if (extra <= v->cap - v->len)
        return 0;
    if (extra > SIZE_MAX / v->elem - v->len)
        return -1;
    size_t need = v->len + extra;
    size_t cap = v->cap ? v->cap : 64;
    while (cap < need)
        cap = cap > SIZE_MAX / 2 / v->elem ? need : cap * 2;
    void *p = realloc(v->data, cap * v->elem);
    if (!p)
        return -1;
    v->data = p;
    v->cap = cap;
    return 0;
}

void mfmm_io_vec_free(mfmm_io_vec *v)
{
    free(v->data);
    v->data = NULL;
    v->len = v->cap = 0;
}

int mfmm_io_push_tri(mfmm_io_vec *tris, int32_t a, int32_t b, int32_t c)
{
    if (mfmm_io_vec_reserve(tris, 3))
        return -1;
    int32_t *t = (int32_t *)tris->data + tris->len;
    t[0] = a;
    t[1] = b;
    t[2] = c;
    tris->len += 3;
    return 0;
}

int mfmm_io_scan_int(const char **p, int64_t *value)
{
    const char *s = *p;
    int neg = 0;
    if (*s == '+' || *s == '-') {
        neg = *s == '-';
        s++;
    }
    if (*s < '0' || *s > '9')
        return 0;
    int64_t v = 0;
    while (*s >= '0' && *s <= '9') {
        if (v > (INT64_MAX - 9) / 10)
            return 0;
        v = v * 10 + (*s - '0');
        s++;
    }
    *value = neg ? -v : v;
    *p = s;
    return 1;
}

int mfmm_io_scan_double(const char **p, double *value)
{
    const char *s = *p;
    /* A token must start here. */
    if (!(*s == '+' || *s == '-' || *s == '.' || (*s >= '0' && *s <= '9') || *s == 'i' ||
          *s == 'I' || *s == 'n' || *s == 'N'))
        return 0;
    const char *end;
    double v;
    if (!mfmm_io_strtod(s, &end, &v))
        return 0;
    *value = v;
    *p = end;
    return 1;
}

mfmm_status mfmm_io_discard(mfmm_io_vec *verts, mfmm_io_vec *tris, mfmm_status st)
{
    mfmm_io_vec_free(verts);
    mfmm_io_vec_free(tris);
    return st;
}

mfmm_status mfmm_io_finish(mfmm_io_vec *verts, mfmm_io_vec *tris, mfmm_io_result *out,
                           mfmm_error *err)
{
    size_t nv = verts->len / 3, nf = tris->len / 3;
    if (nv == 0) {
        return mfmm_io_discard(verts, tris, mfmm_fail(err, MFMM_ERR_PARSE, -1, "the file has no vertices"));
    }
    if (nf == 0) {
        return mfmm_io_discard(verts, tris, mfmm_fail(err, MFMM_ERR_PARSE, -1, "the file has no faces"));
    }
    if (nv > INT32_MAX || nf > INT32_MAX) {
        return mfmm_io_discard(verts, tris, mfmm_fail(err, MFMM_ERR_PARSE, -1, "the file has more than 2^31-1 vertices or faces"));
    }
    /* Shrink to fit (failure to shrink is harmless). */
    void *p = realloc(verts->data, nv * 3 * sizeof(double));
    if (p)
        verts->data = p;
    p = realloc(tris->data, nf * 3 * sizeof(int32_t));
    if (p)
        tris->data = p;
    out->V = verts->data;
    out->nv = (int32_t)nv;
    out->F = tris->data;
    out->nf = (int32_t)nf;
    verts->data = tris->data = NULL;
    verts->len = verts->cap = tris->len = tris->cap = 0;
    return MFMM_OK;
}

