/* STL reader, binary and ascii. STL stores each facet's three corners, so
 * corners are welded into shared vertices by exact position (-0 == +0);
 * facets whose welded corners coincide (zero-area slivers, common in STL
 * exports) are dropped. Binary: 80-byte header, uint32 facet count, 50 bytes
 * per facet (normal, 3 corners as little-endian float32, attribute).
 * Ascii: solid / facet normal / outer loop / vertex x y z ... / endloop /
 * endfacet / endsolid, keywords in any case; loops of more than three
 * corners are fan-triangulated. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "io.h"
#include "base/error.h"

/* ---- welding: open addressing on the coordinates' bits ---- */

typedef struct weld {
    int32_t *slot; /* vertex index + 1, 0 empty */
    size_t mask;
    mfmm_io_vec *verts;
} weld;

static uint64_t mix(uint64_t h)
{
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
    h *= 0xc4ceb9fe1a85ec53ULL;
    h ^= h >> 33;
    return h;
}

/* q: coordinates with -0 already made +0 */
static uint64_t hash_point(const double q[3])
{
    uint64_t h = 0;
    for (int k = 0; k < 3; k++) {
        uint64_t bits;
        memcpy(&bits, &q[k], sizeof bits);
        h = mix(h ^ bits ^ (uint64_t)k << 61);
    }
    return h;
}

static int weld_alloc(weld *w, size_t cap)
{
    int32_t *slot = calloc(cap, sizeof *slot);
    if (!slot)
        return -1;
    const double *V = w->verts->data;
    size_t n = w->verts->len / 3;
    for (size_t v = 0; v < n; v++) { /* rehash what is there */
        size_t i = (size_t)hash_point(V + 3 * v) & (cap - 1);
        while (slot[i])
            i = (i + 1) & (cap - 1);
        slot[i] = (int32_t)v + 1;
    }
    free(w->slot);
    w->slot = slot;
    w->mask = cap - 1;
    return 0;
}

/* hint: the number of points expected (the table grows past it). */
static int weld_init(weld *w, mfmm_io_vec *verts, size_t hint)
{
    size_t cap = 64;
    while (cap < 2 * hint && cap < ((size_t)1 << 32))
        cap *= 2;
    w->slot = NULL;
    w->verts = verts;
    return weld_alloc(w, cap);
}

/* The index of point p (finite), adding it if new; -1 when out of memory,
 * -2 past INT32_MAX vertices. */
static int64_t weld_point(weld *w, const double p[3])
{
    double q[3];
    for (int k = 0; k < 3; k++)
        q[k] = p[k] == 0.0 ? 0.0 : p[k];
    size_t n = w->verts->len / 3;
    if (2 * (n + 1) > w->mask + 1 && weld_alloc(w, 2 * (w->mask + 1)))
        return -1;
    uint64_t h = hash_point(q);
    const double *V = w->verts->data;
    size_t i = (size_t)h & w->mask;
    for (;;) {
        int32_t s = w->slot[i];
        if (s == 0)
            break;
        const double *v = V + 3 * (size_t)(s - 1);
        if (v[0] == q[0] && v[1] == q[1] && v[2] == q[2])
            return s - 1;
        i = (i + 1) & w->mask;
    }
    if (n >= INT32_MAX - 1)
        return -2;
    if (mfmm_io_vec_reserve(w->verts, 3))
        return -1;
    memcpy((double *)w->verts->data + w->verts->len, q, sizeof q);
    w->verts->len += 3;
    w->slot[i] = (int32_t)n + 1;
    return (int64_t)n;
}

/* Welds one triangle's corners and appends it unless degenerate. */
static mfmm_status add_triangle(weld *w, mfmm_io_vec *tris, const double c[9], int64_t facet,
                                mfmm_error *err)
{
    int64_t id[3];
    for (int k = 0; k < 3; k++) {
        for (int j = 0; j < 3; j++)
            if (!isfinite(c[3 * k + j]))
                return mfmm_fail(err, MFMM_ERR_PARSE, facet,
                                 "facet %lld: NaN or infinite coordinate", (long long)facet);
        id[k] = weld_point(w, c + 3 * k);
        if (id[k] == -2)
            return mfmm_fail(err, MFMM_ERR_PARSE, facet, "too many vertices");
        if (id[k] < 0)
            return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, facet, "out of memory");
    }
    if (id[0] == id[1] || id[1] == id[2] || id[0] == id[2])
        return MFMM_OK;
    if (tris->len / 3 >= INT32_MAX)
        return mfmm_fail(err, MFMM_ERR_PARSE, facet, "too many triangles");
    if (mfmm_io_push_tri(tris, (int32_t)id[0], (int32_t)id[1], (int32_t)id[2]))
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, facet, "out of memory");
    return MFMM_OK;
}

static uint32_t le32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

int mfmm_io_stl_is_binary(const char *data, size_t size)
{
    if (size < 84)
        return 0;
    uint64_t n = le32((const unsigned char *)data + 80);
    return (uint64_t)size == 84 + 50 * n;
}

static mfmm_status parse_binary(const unsigned char *d, size_t size, mfmm_io_result *out,
                                mfmm_error *err)
{
    uint32_t n = le32(d + 80);
    if (n == 0)
        return mfmm_fail(err, MFMM_ERR_PARSE, -1, "the binary STL file has no facets");
    if ((uint64_t)size != 84 + 50 * (uint64_t)n)
        return mfmm_fail(err, MFMM_ERR_PARSE, -1,
                         "binary STL: %lu facets need %llu bytes, the file has %llu",
                         (unsigned long)n, (unsigned long long)(84 + 50 * (uint64_t)n),
                         (unsigned long long)size);
    mfmm_io_vec verts, tris;
    mfmm_io_vec_init(&verts, sizeof(double));
    mfmm_io_vec_init(&tris, sizeof(int32_t));
    weld w;
    mfmm_status st;
    if (weld_init(&w, &verts, (size_t)n) || mfmm_io_vec_reserve(&tris, (size_t)n * 3)) {
        st = mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory");
        goto fail;
    }
    for (uint32_t i = 0; i < n; i++) {
        const unsigned char *f = d + 84 + 50 * (size_t)i + 12; /* past the normal */
        double c[9];
        for (int k = 0; k < 9; k++) {
            uint32_t u = le32(f + 4 * k);
            float x;
            memcpy(&x, &u, sizeof x);
            c[k] = x;
        }
        if ((st = add_triangle(&w, &tris, c, i, err)) != MFMM_OK)
            goto fail;
    }
    free(w.slot);
    return mfmm_io_finish(&verts, &tris, out, err);
fail:
    free(w.slot);
    return mfmm_io_discard(&verts, &tris, st);
}

/* ---- ascii ---- */

typedef struct cursor {
    const char *p, *end;
    int64_t line;
} cursor;

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

static void skip_space(cursor *c)
{
    while (c->p < c->end && is_space(*c->p)) {
        if (*c->p == '\n')
            c->line++;
        c->p++;
    }
}

/* Next token [p, p+len); len 0 at the end. */
static size_t token(cursor *c, const char **t)
{
    skip_space(c);
    *t = c->p;
    while (c->p < c->end && !is_space(*c->p))
        c->p++;
    return (size_t)(c->p - *t);
}

static int keyword(const char *t, size_t n, const char *kw)
{
    size_t i = 0;
    for (; i < n && kw[i]; i++) {
        char a = t[i];
        if (a >= 'A' && a <= 'Z')
            a = (char)(a - 'A' + 'a');
        if (a != kw[i])
            return 0;
    }
    return i == n && kw[i] == '\0';
}

static void skip_line(cursor *c)
{
    while (c->p < c->end && *c->p != '\n')
        c->p++;
}

static int number(cursor *c, double *x)
{
    const char *t;
    size_t n = token(c, &t);
    const char *q = t;
    return n > 0 && mfmm_io_scan_double(&q, x) && q == t + n;
}

static mfmm_status parse_ascii(const char *data, size_t size, mfmm_io_result *out,
                               mfmm_error *err)
{
    if (memchr(data, '\0', size))
        return mfmm_fail(err, MFMM_ERR_PARSE, -1,
                         "NUL byte in an ascii STL file (and its size does not fit binary "
                         "STL's 84 + 50 n bytes)");
    cursor c = {data, data + size, 1};
    const char *t;
    size_t n = token(&c, &t);
    if (!keyword(t, n, "solid"))
        return mfmm_fail(err, MFMM_ERR_PARSE, c.line,
                         "line %lld: an ascii STL file starts with 'solid' (and its size "
                         "does not fit binary STL's 84 + 50 n bytes)",
                         (long long)c.line);
    skip_line(&c); /* the solid's name */
    mfmm_io_vec verts, tris;
    mfmm_io_vec_init(&verts, sizeof(double));
    mfmm_io_vec_init(&tris, sizeof(int32_t));
    weld w;
    mfmm_status st;
    if (weld_init(&w, &verts, 64)) {
        st = mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory");
        goto fail;
    }
    int64_t facet = 0;
    for (;;) {
        n = token(&c, &t);
        if (n == 0)
            break;
        if (keyword(t, n, "endsolid")) {
            skip_line(&c);
            continue;
        }
        if (keyword(t, n, "solid")) {
            skip_line(&c);
            continue;
        }
        if (!keyword(t, n, "facet"))
            goto syntax;
        skip_line(&c); /* normal nx ny nz: not used */
        n = token(&c, &t);
        if (!keyword(t, n, "outer") || (n = token(&c, &t), !keyword(t, n, "loop")))
            goto syntax;
        double first[3], prev[3], cur[3];
        int k = 0;
        for (;;) {
            n = token(&c, &t);
            if (keyword(t, n, "endloop"))
                break;
            if (!keyword(t, n, "vertex"))
                goto syntax;
            for (int j = 0; j < 3; j++)
                if (!number(&c, &cur[j])) {
                    st = mfmm_fail(err, MFMM_ERR_PARSE, c.line,
                                   "line %lld: a 'vertex' needs three numbers",
                                   (long long)c.line);
                    goto fail;
                }
            if (k == 0) {
                memcpy(first, cur, sizeof cur);
            } else if (k >= 2) {
                double tri[9];
                memcpy(tri, first, sizeof first);
                memcpy(tri + 3, prev, sizeof prev);
                memcpy(tri + 6, cur, sizeof cur);
                if ((st = add_triangle(&w, &tris, tri, facet, err)) != MFMM_OK)
                    goto fail;
            }
            memcpy(prev, cur, sizeof cur);
            k++;
        }
        if (k < 3) {
            st = mfmm_fail(err, MFMM_ERR_PARSE, c.line,
                           "line %lld: a facet needs at least three vertices", (long long)c.line);
            goto fail;
        }
        n = token(&c, &t);
        if (!keyword(t, n, "endfacet"))
            goto syntax;
        facet++;
    }
    free(w.slot);
    if (facet == 0)
        return mfmm_io_discard(&verts, &tris,
                               mfmm_fail(err, MFMM_ERR_PARSE, -1, "the STL file has no facets"));
    return mfmm_io_finish(&verts, &tris, out, err);
syntax:
    st = mfmm_fail(err, MFMM_ERR_PARSE, c.line,
                   n ? "line %lld: unexpected '%.*s' in an ascii STL file"
                     : "line %lld: unexpected end of an ascii STL file%.*s",
                   (long long)c.line, (int)(n > 24 ? 24 : n), n ? t : "");
fail:
    free(w.slot);
    return mfmm_io_discard(&verts, &tris, st);
}

mfmm_status mfmm_io_parse_stl(const char *data, size_t size, mfmm_io_result *out,
                              mfmm_error *err)
{
    /* "solid" at the start does not make a file ascii (binary headers often
     * begin with it): the binary size formula decides. */
    if (mfmm_io_stl_is_binary(data, size))
        return parse_binary((const unsigned char *)data, size, out, err);
    return parse_ascii(data, size, out, err);
}
