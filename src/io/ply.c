/* PLY reader: ascii, binary_little_endian and binary_big_endian; any
 * scalar types; `vertex` (x, y, z; other properties skipped), `face` with a
 * `vertex_indices` or `vertex_index` list (polygons fan-triangulated) and
 * `tristrips` (one list split by -1). Other elements are skipped. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "io.h"
#include "base/error.h"

#define PLY_MAX_ELEMENTS 32
#define PLY_MAX_PROPS 64
#define PLY_NAME 64

enum { T_NONE, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64 };
static const int type_size[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
enum { F_ASCII, F_LE, F_BE };
enum { E_OTHER, E_VERTEX, E_FACE, E_STRIPS };

typedef struct ply_prop {
    int type;       /* item type for lists */
    int count_type; /* T_NONE for scalars */
    char name[PLY_NAME];
} ply_prop;

typedef struct ply_elem {
    char name[PLY_NAME];
    int64_t count;
    int nprops;
    int kind;
    int role[PLY_MAX_PROPS]; /* vertex: 0,1,2 = x,y,z; face/strips: 3 = indices; -1 other */
    ply_prop props[PLY_MAX_PROPS];
} ply_elem;

typedef struct ply_header {
    int format;
    int nelems;
    ply_elem elems[PLY_MAX_ELEMENTS];
} ply_header;

typedef struct ply_reader {
    const unsigned char *p, *end;
    int format;
} ply_reader;

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

static int parse_type(const char *s, size_t n)
{
    static const struct {
        const char *name;
        int type;
    } names[] = {{"char", T_I8},    {"int8", T_I8},     {"uchar", T_U8},   {"uint8", T_U8},
                 {"short", T_I16},  {"int16", T_I16},   {"ushort", T_U16}, {"uint16", T_U16},
                 {"int", T_I32},    {"int32", T_I32},   {"uint", T_U32},   {"uint32", T_U32},
                 {"float", T_F32},  {"float32", T_F32}, {"double", T_F64}, {"float64", T_F64}};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strlen(names[i].name) == n && memcmp(names[i].name, s, n) == 0)
            return names[i].type;
    return T_NONE;
}

/* Splits one header line into at most `max` blank-separated words. */
static int split_words(const char *s, const char *eol, const char **w, size_t *len, int max)
{
    int n = 0;
    while (s < eol) {
        while (s < eol && is_space(*s))
            s++;
        if (s >= eol)
            break;
        const char *b = s;
        while (s < eol && !is_space(*s))
            s++;
        if (n < max) {
            w[n] = b;
            len[n] = (size_t)(s - b);
        }
        n++;
    }
    return n;
}

static int word_is(const char *w, size_t n, const char *s)
{
    return strlen(s) == n && memcmp(w, s, n) == 0;
}

static mfmm_status parse_header(const char *data, size_t size, ply_header *h, size_t *body,
                                mfmm_error *err)
{
    const char *p = data, *end = data + size;
    int64_t line = 0;
    int have_format = 0;
    h->nelems = 0;
    for (;;) {
        line++;
        const char *eol = memchr(p, '\n', (size_t)(end - p));
        if (!eol)
            return mfmm_fail(err, MFMM_ERR_PARSE, line,
                             "line %lld: the PLY header has no end_header", (long long)line);
        if (memchr(p, '\0', (size_t)(eol - p)))
            return mfmm_fail(err, MFMM_ERR_PARSE, line, "line %lld: NUL byte in the PLY header",
                             (long long)line);
        const char *w[6];
        size_t wl[6];
        int nw = split_words(p, eol, w, wl, 6);
        const char *next = eol + 1;
        if (line == 1) {
            if (nw != 1 || !word_is(w[0], wl[0], "ply"))
                return mfmm_fail(err, MFMM_ERR_PARSE, 1, "line 1: not a PLY file");
        } else if (nw == 0) {
            /* blank line: tolerated */
        } else if (word_is(w[0], wl[0], "comment") || word_is(w[0], wl[0], "obj_info")) {
        } else if (word_is(w[0], wl[0], "format")) {
            if (nw != 3)
                return mfmm_fail(err, MFMM_ERR_PARSE, line, "line %lld: bad format line",
                                 (long long)line);
            if (word_is(w[1], wl[1], "ascii"))
                h->format = F_ASCII;
            else if (word_is(w[1], wl[1], "binary_little_endian"))
                h->format = F_LE;
            else if (word_is(w[1], wl[1], "binary_big_endian"))
                h->format = F_BE;
            else
                return mfmm_fail(err, MFMM_ERR_PARSE, line, "line %lld: unknown PLY format",
                                 (long long)line);
            have_format = 1;
        } else if (word_is(w[0], wl[0], "element")) {
            if (nw != 3 || wl[1] >= PLY_NAME)
                return mfmm_fail(err, MFMM_ERR_PARSE, line, "line %lld: bad element line",
                                 (long long)line);
            if (h->nelems >= PLY_MAX_ELEMENTS)
                return mfmm_fail(err, MFMM_ERR_PARSE, line, "line %lld: too many elements",
                                 (long long)line);
            ply_elem *e = &h->elems[h->nelems];
            memcpy(e->name, w[1], wl[1]);
            e->name[wl[1]] = '\0';
            const char *q = w[2];
            int64_t count;
            if (!mfmm_io_scan_int(&q, &count) || q != w[2] + wl[2] || count < 0)
                return mfmm_fail(err, MFMM_ERR_PARSE, line, "line %lld: bad element count",
                                 (long long)line);
            e->count = count;
            e->nprops = 0;
            e->kind = strcmp(e->name, "vertex") == 0      ? E_VERTEX
                      : strcmp(e->name, "face") == 0      ? E_FACE
                      : strcmp(e->name, "tristrips") == 0 ? E_STRIPS
                                                          : E_OTHER;
            for (int i = 0; i < h->nelems; i++)
                if (e->kind != E_OTHER && h->elems[i].kind == e->kind)
                    return mfmm_fail(err, MFMM_ERR_PARSE, line,
                                     "line %lld: element '%s' declared twice", (long long)line,
                                     e->name);
            h->nelems++;
        } else if (word_is(w[0], wl[0], "property")) {
            if (h->nelems == 0)
                return mfmm_fail(err, MFMM_ERR_PARSE, line,
                                 "line %lld: property before any element", (long long)line);
            ply_elem *e = &h->elems[h->nelems - 1];
            if (e->nprops >= PLY_MAX_PROPS)
                return mfmm_fail(err, MFMM_ERR_PARSE, line, "line %lld: too many properties",
                                 (long long)line);
            ply_prop *pr = &e->props[e->nprops];
            int is_list = nw >= 2 && word_is(w[1], wl[1], "list");
            size_t name_w = is_list ? 4 : 2;
            if ((int)name_w + 1 != nw || wl[name_w] >= PLY_NAME)
                return mfmm_fail(err, MFMM_ERR_PARSE, line, "line %lld: bad property line",
                                 (long long)line);
            if (is_list) {
                pr->count_type = parse_type(w[2], wl[2]);
                pr->type = parse_type(w[3], wl[3]);
                if (pr->count_type == T_NONE || pr->type == T_NONE ||
                    pr->count_type >= T_F32)
                    return mfmm_fail(err, MFMM_ERR_PARSE, line,
                                     "line %lld: bad list property types", (long long)line);
            } else {
                pr->count_type = T_NONE;
                pr->type = parse_type(w[1], wl[1]);
                if (pr->type == T_NONE)
                    return mfmm_fail(err, MFMM_ERR_PARSE, line,
                                     "line %lld: unknown property type", (long long)line);
            }
            memcpy(pr->name, w[name_w], wl[name_w]);
            pr->name[wl[name_w]] = '\0';
            e->nprops++;
        } else if (word_is(w[0], wl[0], "end_header")) {
            *body = (size_t)(next - data);
            break;
        } else {
            return mfmm_fail(err, MFMM_ERR_PARSE, line, "line %lld: unknown PLY header line",
                             (long long)line);
        }
        p = next;
    }
    if (!have_format)
        return mfmm_fail(err, MFMM_ERR_PARSE, -1, "the PLY header has no format line");
    return MFMM_OK;
}

/* Reads one value of `type`. Integers go to *iv (and *dv), floats to *dv. */
static int read_value(ply_reader *r, int type, int64_t *iv, double *dv)
{
    if (r->format == F_ASCII) {
        while (r->p < r->end && is_space((char)*r->p))
            r->p++;
        const char *q = (const char *)r->p;
        if (r->p >= r->end)
            return 0;
        if (type >= T_F32) {
            if (!mfmm_io_scan_double(&q, dv))
                return 0;
            *iv = 0;
        } else {
            if (!mfmm_io_scan_int(&q, iv))
                return 0;
            *dv = (double)*iv;
        }
        if ((const unsigned char *)q < r->end && !is_space(*q))
            return 0;
        r->p = (const unsigned char *)q;
        return 1;
    }
    int n = type_size[type];
    if (r->end - r->p < n)
        return 0;
    uint64_t u = 0;
    for (int i = 0; i < n; i++) {
        int b = r->format == F_LE ? n - 1 - i : i;
        u = (u << 8) | r->p[b];
    }
    r->p += n;
    switch (type) {
    case T_I8: *iv = (int8_t)(uint8_t)u; break;
    case T_U8: *iv = (int64_t)u; break;
    case T_I16: *iv = (int16_t)(uint16_t)u; break;
    case T_U16: *iv = (int64_t)u; break;
    case T_I32: *iv = (int32_t)(uint32_t)u; break;
    case T_U32: *iv = (int64_t)u; break;
    case T_F32: {
        uint32_t u32 = (uint32_t)u;
        float f;
        memcpy(&f, &u32, sizeof f);
        *dv = f;
        *iv = 0;
        return 1;
    }
    default: {
        double d;
        memcpy(&d, &u, sizeof d);
        *dv = d;
        *iv = 0;
        return 1;
    }
    }
    *dv = (double)*iv;
    return 1;
}

static const char *elem_label(const ply_elem *e)
{
    return e->name;
}

mfmm_status mfmm_io_parse_ply(const char *data, size_t size, mfmm_io_result *out,
                              mfmm_error *err)
{
    ply_header h;
    size_t body = 0;
    mfmm_status st = parse_header(data, size, &h, &body, err);
    if (st != MFMM_OK)
        return st;
    size_t remaining = size - body;

    /* Roles of properties; the smallest size an element can take. */
    int64_t nv = -1, min_bytes = 0;
    int have_faces = 0;
    for (int i = 0; i < h.nelems; i++) {
        ply_elem *e = &h.elems[i];
        int64_t per = 0;
        int found[4] = {0, 0, 0, 0};
        for (int k = 0; k < e->nprops; k++) {
            ply_prop *pr = &e->props[k];
            e->role[k] = -1;
            if (e->kind == E_VERTEX && pr->count_type == T_NONE && pr->name[1] == '\0' &&
                pr->name[0] >= 'x' && pr->name[0] <= 'z' && !found[pr->name[0] - 'x'])
                e->role[k] = pr->name[0] - 'x';
            if ((e->kind == E_FACE || e->kind == E_STRIPS) && pr->count_type != T_NONE &&
                (strcmp(pr->name, "vertex_indices") == 0 ||
                 strcmp(pr->name, "vertex_index") == 0) &&
                !found[3]) {
                if (pr->type >= T_F32)
                    return mfmm_fail(err, MFMM_ERR_PARSE, -1,
                                     "element '%s': vertex indices must be integers", e->name);
                e->role[k] = 3;
            }
            if (e->role[k] >= 0)
                found[e->role[k]] = 1;
            per += h.format == F_ASCII ? 2
                   : pr->count_type == T_NONE ? type_size[pr->type]
                                              : type_size[pr->count_type];
        }
        if (e->kind == E_VERTEX) {
            if (!found[0] || !found[1] || !found[2])
                return mfmm_fail(err, MFMM_ERR_PARSE, -1,
                                 "element 'vertex' lacks an x, y or z property");
            nv = e->count;
        }
        if (e->kind == E_FACE || e->kind == E_STRIPS) {
            if (!found[3])
                return mfmm_fail(err, MFMM_ERR_PARSE, -1,
                                 "element '%s' has no vertex_indices list", e->name);
            have_faces = 1;
        }
        if (e->count > 0 && per == 0)
            return mfmm_fail(err, MFMM_ERR_PARSE, -1, "element '%s' has no properties",
                             e->name);
        if (per > 0 && e->count > (int64_t)(remaining / (size_t)per) + 1)
            return mfmm_fail(err, MFMM_ERR_PARSE, -1,
                             "element '%s': header claims %lld, more than the file's %lld "
                             "bytes can hold",
                             e->name, (long long)e->count, (long long)remaining);
        min_bytes += e->count * per;
        if (min_bytes > (int64_t)remaining + 1)
            return mfmm_fail(err, MFMM_ERR_PARSE, -1,
                             "the header's element counts need more than the file's %lld bytes",
                             (long long)remaining);
    }
    if (nv < 0)
        return mfmm_fail(err, MFMM_ERR_PARSE, -1, "the PLY file has no 'vertex' element");
    if (!have_faces)
        return mfmm_fail(err, MFMM_ERR_PARSE, -1,
                         "the PLY file has no 'face' or 'tristrips' element");
    if (nv < 1 || nv > INT32_MAX)
        return mfmm_fail(err, MFMM_ERR_PARSE, -1, "bad vertex count %lld", (long long)nv);

    mfmm_io_vec verts, tris;
    mfmm_io_vec_init(&verts, sizeof(double));
    mfmm_io_vec_init(&tris, sizeof(int32_t));
    ply_reader r = {(const unsigned char *)data + body, (const unsigned char *)data + size,
                    h.format};
    if (mfmm_io_vec_reserve(&verts, (size_t)nv * 3)) {
        st = mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory");
        goto fail;
    }
    verts.len = (size_t)nv * 3;
    double *V = verts.data;

    for (int ei = 0; ei < h.nelems; ei++) {
        ply_elem *e = &h.elems[ei];
        if (e->kind == E_FACE &&
            mfmm_io_vec_reserve(&tris, (size_t)e->count * 3)) {
            st = mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory");
            goto fail;
        }
        for (int64_t i = 0; i < e->count; i++) {
            for (int k = 0; k < e->nprops; k++) {
                const ply_prop *pr = &e->props[k];
                int64_t iv;
                double dv;
                if (pr->count_type == T_NONE) {
                    if (!read_value(&r, pr->type, &iv, &dv))
                        goto truncated;
                    if (e->kind == E_VERTEX && e->role[k] >= 0) {
                        if (!isfinite(dv)) {
                            st = mfmm_fail(err, MFMM_ERR_PARSE, i,
                                           "vertex %lld: NaN or infinite coordinate",
                                           (long long)i);
                            goto fail;
                        }
                        V[3 * i + e->role[k]] = dv;
                    }
                    continue;
                }
                int64_t n;
                if (!read_value(&r, pr->count_type, &n, &dv))
                    goto truncated;
                int64_t item = h.format == F_ASCII ? 2 : type_size[pr->type];
                if (n < 0 || n > (int64_t)((size_t)(r.end - r.p) / (size_t)item) + 1) {
                    st = mfmm_fail(err, MFMM_ERR_PARSE, i,
                                   n < 0 ? "%s %lld: bad list length %lld"
                                         : "%s %lld: a list of %lld values runs past the end of "
                                           "the file (truncated?)",
                                   elem_label(e), (long long)i, (long long)n);
                    goto fail;
                }
                if (e->role[k] != 3) {
                    for (int64_t j = 0; j < n; j++)
                        if (!read_value(&r, pr->type, &iv, &dv))
                            goto truncated;
                    continue;
                }
                if (e->kind == E_FACE && n < 3) {
                    st = mfmm_fail(err, MFMM_ERR_PARSE, i,
                                   "face %lld: %lld vertices, need at least 3", (long long)i,
                                   (long long)n);
                    goto fail;
                }
                /* Faces: fan (first, prev, cur). Strips: window (a, b, cur). */
                int64_t a = -1, b = -1, pos = 0;
                for (int64_t j = 0; j < n; j++) {
                    if (!read_value(&r, pr->type, &iv, &dv))
                        goto truncated;
                    if (e->kind == E_STRIPS &&
                        (iv == -1 || (pr->type == T_U32 && iv == 0xFFFFFFFFLL) ||
                         (pr->type == T_U16 && iv == 0xFFFF))) {
                        pos = 0;
                        continue;
                    }
                    if (iv < 0 || iv >= nv) {
                        st = mfmm_fail(err, MFMM_ERR_PARSE, i,
                                       "%s %lld: vertex index %lld out of range (%lld vertices)",
                                       elem_label(e), (long long)i, (long long)iv,
                                       (long long)nv);
                        goto fail;
                    }
                    int push = 0;
                    int32_t t0 = 0, t1 = 0, t2 = (int32_t)iv;
                    if (e->kind == E_FACE) {
                        if (j == 0)
                            a = iv;
                        else if (j >= 2) {
                            t0 = (int32_t)a;
                            t1 = (int32_t)b;
                            push = 1;
                        }
                        b = iv;
                    } else {
                        if (pos >= 2) {
                            int odd = (int)((pos - 2) & 1);
                            t0 = (int32_t)(odd ? b : a);
                            t1 = (int32_t)(odd ? a : b);
                            push = a != b && a != iv && b != iv;
                        }
                        a = b;
                        b = iv;
                        pos++;
                    }
                    if (push) {
                        if (tris.len / 3 >= INT32_MAX) {
                            st = mfmm_fail(err, MFMM_ERR_PARSE, i, "too many triangles");
                            goto fail;
                        }
                        if (mfmm_io_push_tri(&tris, t0, t1, t2)) {
                            st = mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, i, "out of memory");
                            goto fail;
                        }
                    }
                }
            }
            continue;
        truncated:
            st = mfmm_fail(err, MFMM_ERR_PARSE, i,
                           r.p >= r.end || h.format != F_ASCII
                               ? "%s %lld: unexpected end of file (truncated?)"
                               : "%s %lld: malformed value",
                           elem_label(e), (long long)i);
            goto fail;
        }
    }
    if (h.format == F_ASCII)
        while (r.p < r.end && is_space((char)*r.p))
            r.p++;
    if (r.p < r.end) {
        st = mfmm_fail(err, MFMM_ERR_PARSE, -1,
                       "%lld bytes after the last element (do the header's counts lie?)",
                       (long long)(r.end - r.p));
        goto fail;
    }
    return mfmm_io_finish(&verts, &tris, out, err);
fail:
    return mfmm_io_discard(&verts, &tris, st);
}
