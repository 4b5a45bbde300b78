/* Wavefront OBJ reader: `v x y z [w]`, `f a b c ...` with `a`, `a/t`, `a//n`
 * or `a/t/n` (only the vertex index is used), negative (relative) indices,
 * polygons fan-triangulated. Other statements are ignored. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "io.h"
#include "base/error.h"

static int is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

static int is_alpha(char c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}

static const char *skip_blank(const char *p)
{
    while (is_blank(*p))
        p++;
    return p;
}

/* End of the current line (points at '\n' or the terminating NUL). */
static const char *line_end(const char *p, const char *end)
{
    const char *q = memchr(p, '\n', (size_t)(end - p));
    return q ? q : end;
}

/* One face index token; on success *idx is 0-based (range-checked later
 * for positive indices, at once for relative ones). */
static int scan_index(const char **pp, int64_t nv_so_far, int64_t *idx)
{
    const char *p = *pp;
    int64_t v;
    if (!mfmm_io_scan_int(&p, &v) || v == 0)
        return 0;
    if (v < 0) {
        v = nv_so_far + v;
        if (v < 0)
            return 0;
    } else {
        v -= 1;
    }
    /* Skip "/vt/vn", "//vn" or "/vt". */
    while (*p == '/') {
        p++;
        int64_t ignored;
        if ((*p >= '0' && *p <= '9') || *p == '-' || *p == '+') {
            if (!mfmm_io_scan_int(&p, &ignored))
                return 0;
        }
    }
    if (!(is_blank(*p) || *p == '\n' || *p == '\0' || *p == '#'))
        return 0;
    *idx = v;
    *pp = p;
    return 1;
}

mfmm_status mfmm_io_parse_obj(const char *data, size_t size, mfmm_io_result *out,
                              mfmm_error *err)
{
    const char *p = data, *end = data + size;
    mfmm_io_vec verts, tris;
    mfmm_io_vec_init(&verts, sizeof(double));
    mfmm_io_vec_init(&tris, sizeof(int32_t));
    /* Positive indices may name vertices defined later: remember the
     * largest one and check it at the end. */
    int64_t max_index = -1, max_index_line = 0;
    int64_t line = 0;
    mfmm_status st = MFMM_OK;

    while (p < end) {
        line++;
        const char *eol = line_end(p, end);
        if (memchr(p, '\0', (size_t)(eol - p))) {
            st = mfmm_fail(err, MFMM_ERR_PARSE, line, "line %lld: NUL byte in a text file",
                           (long long)line);
            goto fail;
        }
        const char *s = skip_blank(p);
        if (s >= eol || *s == '#' || *s == '\n') {
            p = eol + (eol < end);
            continue;
        }
        if (s[0] == 'v' && is_blank(s[1])) {
            double xyz[3];
            const char *q = s + 1;
            for (int k = 0; k < 3; k++) {
                q = skip_blank(q);
                if (!mfmm_io_scan_double(&q, &xyz[k]) ||
                    !(is_blank(*q) || *q == '\n' || *q == '\0' || *q == '#')) {
                    st = mfmm_fail(err, MFMM_ERR_PARSE, line,
                                   "line %lld: a 'v' line needs three numbers", (long long)line);
                    goto fail;
                }
                if (!isfinite(xyz[k])) {
                    st = mfmm_fail(err, MFMM_ERR_PARSE, line,
                                   "line %lld: vertex %lld has a NaN or infinite coordinate",
                                   (long long)line, (long long)(verts.len / 3 + 1));
                    goto fail;
                }
            }
            if (verts.len / 3 >= INT32_MAX) {
                st = mfmm_fail(err, MFMM_ERR_PARSE, line, "line %lld: too many vertices",
                               (long long)line);
                goto fail;
            }
            if (mfmm_io_vec_reserve(&verts, 3)) {
                st = mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, line, "out of memory at line %lld",
                               (long long)line);
                goto fail;
            }
            memcpy((double *)verts.data + verts.len, xyz, sizeof xyz);
            verts.len += 3;
            /* Extra values (w, colours) are ignored. */
        } else if (s[0] == 'f' && is_blank(s[1])) {
            int64_t nv_so_far = (int64_t)(verts.len / 3);
            int64_t first = -1, prev = -1, idx;
            int count = 0;
            const char *q = skip_blank(s + 1);
            while (q < eol && *q != '#' && *q != '\n') {
                if (!scan_index(&q, nv_so_far, &idx)) {
                    st = mfmm_fail(err, MFMM_ERR_PARSE, line,
                                   "line %lld: bad face index (zero, malformed or out of range)",
                                   (long long)line);
                    goto fail;
                }
                if (idx > INT32_MAX - 1) {
                    st = mfmm_fail(err, MFMM_ERR_PARSE, line,
                                   "line %lld: face index out of range", (long long)line);
                    goto fail;
                }
                if (idx > max_index) {
                    max_index = idx;
                    max_index_line = line;
                }
                if (count == 0) {
                    first = idx;
                } else if (count >= 2) {
                    if (mfmm_io_push_tri(&tris, (int32_t)first, (int32_t)prev, (int32_t)idx)) {
                        st = mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, line,
                                       "out of memory at line %lld", (long long)line);
                        goto fail;
                    }
                }
                prev = idx;
                count++;
                q = skip_blank(q);
            }
            if (count < 3) {
                st = mfmm_fail(err, MFMM_ERR_PARSE, line,
                               "line %lld: a face needs at least three vertices", (long long)line);
                goto fail;
            }
            if (tris.len / 3 > INT32_MAX) {
                st = mfmm_fail(err, MFMM_ERR_PARSE, line, "line %lld: too many faces",
                               (long long)line);
                goto fail;
            }
        } else if (is_alpha(s[0])) {
            /* vt, vn, vp, l, p, o, g, s, usemtl, mtllib, ...: ignored. A
             * keyword is letters, digits and '_'. */
            const char *q = s;
            while (is_alpha(*q) || (*q >= '0' && *q <= '9'))
                q++;
            if (!(is_blank(*q) || *q == '\n' || *q == '\0' || *q == '#')) {
                st = mfmm_fail(err, MFMM_ERR_PARSE, line, "line %lld: not an OBJ statement",
                               (long long)line);
                goto fail;
            }
        } else {
            st = mfmm_fail(err, MFMM_ERR_PARSE, line, "line %lld: not an OBJ statement",
                           (long long)line);
            goto fail;
        }
        p = eol + (eol < end);
    }
    if (max_index >= (int64_t)(verts.len / 3)) {
        st = mfmm_fail(err, MFMM_ERR_PARSE, max_index_line,
                       "line %lld: face index %lld is out of range (%lld vertices)",
                       (long long)max_index_line, (long long)max_index + 1,
                       (long long)(verts.len / 3));
        goto fail;
    }
    return mfmm_io_finish(&verts, &tris, out, err);
fail:
    return mfmm_io_discard(&verts, &tris, st);
}
