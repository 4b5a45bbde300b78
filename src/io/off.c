/* OFF reader: header `OFF` (also COFF, NOFF, CNOFF, STOFF, ...) with
 * `nv nf [ne]` on the same or a following line, `#` comments, any line
 * endings. One vertex or face per line; extra values on a line (colours,
 * normals) are ignored. Polygons are fan-triangulated. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "io.h"
#include "base/error.h"

typedef struct off_cursor {
    const char *p, *end;
    int64_t line; /* 1-based line of *p */
} off_cursor;

static int is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

static int at_delim(const char *p)
{
    return is_blank(*p) || *p == '\n' || *p == '\0' || *p == '#';
}

/* Skips blanks and a comment on the current line. */
static void skip_blank(off_cursor *c)
{
    while (c->p < c->end && is_blank(*c->p))
        c->p++;
    if (c->p < c->end && *c->p == '#')
        while (c->p < c->end && *c->p != '\n')
            c->p++;
}

/* Skips blanks, comments and newlines: to the next token. */
static void skip_space(off_cursor *c)
{
    for (;;) {
        skip_blank(c);
        if (c->p < c->end && *c->p == '\n') {
            c->p++;
            c->line++;
        } else {
            return;
        }
    }
}

static void skip_line(off_cursor *c)
{
    while (c->p < c->end && *c->p != '\n')
        c->p++;
}

static int at_eol(const off_cursor *c)
{
    return c->p >= c->end || *c->p == '\n';
}

static int scan_int(off_cursor *c, int64_t *v)
{
    const char *q = c->p;
    if (c->p >= c->end || !mfmm_io_scan_int(&q, v) || !at_delim(q))
        return 0;
    c->p = q;
    return 1;
}

mfmm_status mfmm_io_parse_off(const char *data, size_t size, mfmm_io_result *out,
                              mfmm_error *err)
{
    off_cursor c = {data, data + size, 1};
    mfmm_io_vec verts, tris;
    mfmm_io_vec_init(&verts, sizeof(double));
    mfmm_io_vec_init(&tris, sizeof(int32_t));
    mfmm_status st;

    if (memchr(data, '\0', size))
        return mfmm_fail(err, MFMM_ERR_PARSE, -1, "NUL byte in a text file");
    skip_space(&c);
    /* Header keyword: optional ST, C, N prefixes, then OFF. */
    const char *h = c.p;
    if (c.end - h >= 2 && h[0] == 'S' && h[1] == 'T')
        h += 2;
    if (h < c.end && *h == 'C')
        h++;
    if (h < c.end && *h == 'N')
        h++;
    if (c.end - h < 3 || memcmp(h, "OFF", 3) != 0 || !at_delim(h + 3))
        return mfmm_fail(err, MFMM_ERR_PARSE, c.line, "line %lld: expected the 'OFF' header",
                         (long long)c.line);
    c.p = h + 3;
    skip_blank(&c);
    if (!at_eol(&c) && c.end - c.p >= 6 && memcmp(c.p, "BINARY", 6) == 0)
        return mfmm_fail(err, MFMM_ERR_PARSE, c.line, "binary OFF files are not supported");
    int64_t nv, nf, ne;
    skip_space(&c);
    int64_t count_line = c.line;
    if (!scan_int(&c, &nv)) {
        return mfmm_fail(err, MFMM_ERR_PARSE, c.line,
                         "line %lld: expected the vertex and face counts", (long long)c.line);
    }
    skip_space(&c);
    if (!scan_int(&c, &nf))
        return mfmm_fail(err, MFMM_ERR_PARSE, c.line,
                         "line %lld: expected the vertex and face counts", (long long)c.line);
    skip_blank(&c);
    if (!at_eol(&c) && !scan_int(&c, &ne))
        return mfmm_fail(err, MFMM_ERR_PARSE, c.line, "line %lld: bad edge count",
                         (long long)c.line);
    skip_line(&c);
    if (nv < 1 || nf < 1 || nv > INT32_MAX || nf > INT32_MAX)
        return mfmm_fail(err, MFMM_ERR_PARSE, count_line,
                         "line %lld: bad counts (%lld vertices, %lld faces)",
                         (long long)count_line, (long long)nv, (long long)nf);
    /* A vertex takes at least 6 bytes ("0 0 0\n"), a face 8 ("3 0 1 2\n"). */
    int64_t remaining = (int64_t)(c.end - c.p);
    if (nv * 6 + nf * 8 > remaining + 2)
        return mfmm_fail(err, MFMM_ERR_PARSE, count_line,
                         "line %lld: header claims %lld vertices and %lld faces, more than "
                         "the file's %lld bytes can hold",
                         (long long)count_line, (long long)nv, (long long)nf,
                         (long long)remaining);
    if (mfmm_io_vec_reserve(&verts, (size_t)nv * 3) || mfmm_io_vec_reserve(&tris, (size_t)nf * 3)) {
        st = mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory");
        goto fail;
    }

    double *V = verts.data;
    for (int64_t i = 0; i < nv; i++) {
        skip_space(&c);
        for (int k = 0; k < 3; k++) {
            const char *q = c.p;
            double x;
            if (at_eol(&c) || !mfmm_io_scan_double(&q, &x) || !at_delim(q)) {
                st = mfmm_fail(err, MFMM_ERR_PARSE, c.line,
                               c.p >= c.end ? "vertex %lld: unexpected end of file (line %lld)"
                                            : "vertex %lld: expected three numbers (line %lld)",
                               (long long)i, (long long)c.line);
                goto fail;
            }
            if (!isfinite(x)) {
                st = mfmm_fail(err, MFMM_ERR_PARSE, c.line,
                               "vertex %lld: NaN or infinite coordinate (line %lld)",
                               (long long)i, (long long)c.line);
                goto fail;
            }
            V[3 * i + k] = x;
            c.p = q;
            skip_blank(&c);
        }
        skip_line(&c);
    }
    verts.len = (size_t)nv * 3;

    for (int64_t i = 0; i < nf; i++) {
        skip_space(&c);
        int64_t k, first = -1, prev = -1, idx;
        if (c.p >= c.end) {
            st = mfmm_fail(err, MFMM_ERR_PARSE, c.line,
                           "face %lld: unexpected end of file (line %lld)", (long long)i,
                           (long long)c.line);
            goto fail;
        }
        if (!scan_int(&c, &k) || k < 3) {
            st = mfmm_fail(err, MFMM_ERR_PARSE, c.line,
                           "face %lld: expected a vertex count >= 3 (line %lld)", (long long)i,
                           (long long)c.line);
            goto fail;
        }
        for (int64_t j = 0; j < k; j++) {
            skip_blank(&c);
            if (at_eol(&c) || !scan_int(&c, &idx)) {
                st = mfmm_fail(err, MFMM_ERR_PARSE, c.line,
                               "face %lld: expected %lld vertex indices (line %lld)",
                               (long long)i, (long long)k, (long long)c.line);
                goto fail;
            }
            if (idx < 0 || idx >= nv) {
                st = mfmm_fail(err, MFMM_ERR_PARSE, c.line,
                               "face %lld: vertex index %lld out of range (line %lld)",
                               (long long)i, (long long)idx, (long long)c.line);
                goto fail;
            }
            if (j == 0) {
                first = idx;
            } else if (j >= 2) {
                if (tris.len / 3 >= INT32_MAX) {
                    st = mfmm_fail(err, MFMM_ERR_PARSE, c.line, "too many triangles");
                    goto fail;
                }
                if (mfmm_io_push_tri(&tris, (int32_t)first, (int32_t)prev, (int32_t)idx)) {
                    st = mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, c.line, "out of memory");
                    goto fail;
                }
            }
            prev = idx;
        }
        skip_line(&c); /* face colour, if any */
    }
    skip_space(&c);
    if (c.p < c.end) {
        st = mfmm_fail(err, MFMM_ERR_PARSE, c.line,
                       "line %lld: data after the last face (do the header's counts lie?)",
                       (long long)c.line);
        goto fail;
    }
    return mfmm_io_finish(&verts, &tris, out, err);
fail:
    return mfmm_io_discard(&verts, &tris, st);
}
