/* .npy (format 1.0) streaming writer and small readers of 1-D float and
 * integer vectors; plain text vectors; vertex id lists. */
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "io/io.h"

static int host_is_little(void)
{
    const uint16_t one = 1;
    unsigned char b[2];
    memcpy(b, &one, 2);
    return b[0] == 1;
}

static void swap_bytes(unsigned char *p, size_t n, size_t itemsize)
{
    for (size_t i = 0; i < n; i++, p += itemsize)
        for (size_t a = 0, b = itemsize - 1; a < b; a++, b--) {
            unsigned char t = p[a];
            p[a] = p[b];
            p[b] = t;
        }
}

int cli_npy_open(cli_npy_writer *w, const char *path, const char *dtype, int64_t rows,
                 int64_t cols)
{
    memset(w, 0, sizeof *w);
    if (strcmp(dtype, "<f4") == 0)
        w->itemsize = 4;
    else if (strcmp(dtype, "<f8") == 0)
        w->itemsize = 8;
    else if (strcmp(dtype, "<i4") == 0)
        w->itemsize = 4;
    else {
        cli_error("npy: unsupported dtype '%s'", dtype);
        return -1;
    }
    if (rows < 0) {
        cli_error("npy: negative row count");
        return -1;
    }
    if (strcmp(path, "-") == 0) {
        cli_error("a .npy file cannot go to standard output ('-' is for text outputs)");
        return -1;
    }
    w->rows = rows;
    w->cols = cols < 0 ? 1 : cols;
    char dict[160];
    if (cols < 0)
        snprintf(dict, sizeof dict, "{'descr': '%s', 'fortran_order': False, 'shape': (%" PRId64 ",), }",
                 dtype, rows);
    else
        snprintf(dict, sizeof dict,
                 "{'descr': '%s', 'fortran_order': False, 'shape': (%" PRId64 ", %" PRId64 "), }",
                 dtype, rows, cols);
    /* magic(6) + version(2) + length(2) + dict, padded with spaces, then '\n'. */
    size_t len = strlen(dict) + 1;
    size_t total = (10 + len + 63) / 64 * 64;
    size_t hlen = total - 10;
    unsigned char header[256];
    memcpy(header, "\x93NUMPY\x01\x00", 8);
    header[8] = (unsigned char)(hlen & 0xff);
    header[9] = (unsigned char)(hlen >> 8);
    memset(header + 10, ' ', hlen);
    memcpy(header + 10, dict, strlen(dict));
    header[total - 1] = '\n';
    if (cli_output_open(&w->out, path))
        return -1;
    if (fwrite(header, 1, total, w->out.f) != total) {
        cli_error("cannot write '%s': %s", w->out.tmp_path, strerror(errno));
        cli_npy_abort(w);
        return -1;
    }
    return 0;
}

int cli_npy_append(cli_npy_writer *w, const void *data, int64_t n_rows)
{
    if (!w->out.f)
        return -1;
    if (n_rows < 0 || n_rows > w->rows - w->rows_written) {
        cli_error("npy: more rows than the header promised (%" PRId64 ")", w->rows);
        return -1;
    }
    size_t n = (size_t)n_rows * (size_t)w->cols;
    FILE *f = w->out.f;
    if (host_is_little()) {
        if (n && fwrite(data, w->itemsize, n, f) != n)
            goto fail;
    } else {
        unsigned char buf[8192];
        const unsigned char *src = data;
        size_t per = sizeof buf / w->itemsize;
        for (size_t i = 0; i < n; i += per) {
            size_t k = n - i < per ? n - i : per;
            memcpy(buf, src + i * w->itemsize, k * w->itemsize);
            swap_bytes(buf, k, w->itemsize);
            if (fwrite(buf, w->itemsize, k, f) != k)
                goto fail;
        }
    }
    w->rows_written += n_rows;
    return 0;
fail:
    cli_error("cannot write '%s': %s", w->out.tmp_path, strerror(errno));
    return -1;
}

int cli_npy_close(cli_npy_writer *w)
{
    if (!w->out.f)
        return -1;
    if (w->rows_written != w->rows) {
        cli_error("npy: %" PRId64 " rows written, %" PRId64 " promised", w->rows_written, w->rows);
        cli_npy_abort(w);
        return -1;
    }
    return cli_output_close(&w->out, 0);
}

void cli_npy_abort(cli_npy_writer *w)
{
    cli_output_abort(&w->out);
}

/* ---- readers: in-memory parsers over whole regular files ---- */

typedef struct npy_info {
    char kind;        /* 'f', 'i' or 'u' */
    int big;          /* big-endian data */
    size_t itemsize;
    int ndim;
    int64_t dims[8];
    int64_t count;    /* product of dims */
    const unsigned char *data;
} npy_info;

static const char *skip_sp(const char *p)
{
    while (*p == ' ')
        p++;
    return p;
}

/* Value of `key` in a numpy header dict: points just past "'key':" and blanks. */
static const char *dict_value(const char *dict, const char *key)
{
    char pat[40];
    snprintf(pat, sizeof pat, "'%s'", key);
    const char *p = strstr(dict, pat);
    if (!p)
        return NULL;
    p = skip_sp(p + strlen(pat));
    if (*p != ':')
        return NULL;
    return skip_sp(p + 1);
}

static void shape_text(const npy_info *h, char *buf, size_t n)
{
    size_t k = (size_t)snprintf(buf, n, "(");
    for (int i = 0; i < h->ndim && k < n; i++)
        k += (size_t)snprintf(buf + k, n - k, i ? ", %" PRId64 : "%" PRId64, h->dims[i]);
    if (k < n)
        snprintf(buf + k, n - k, h->ndim == 1 ? ",)" : ")");
}

/* Parses and checks the header: magic, version 1-3, header length within
 * the file, descr, fortran_order and shape, and that the data is exactly
 * count * itemsize bytes: nothing is allocated from the header's word.
 * 0, or -1 with the error printed. */
static int npy_header(const unsigned char *d, size_t size, const char *name, npy_info *h)
{
    memset(h, 0, sizeof *h);
    if (size < 10 || memcmp(d, "\x93NUMPY", 6) != 0) {
        cli_error("%s: not a .npy file (no \\x93NUMPY magic)", name);
        return -1;
    }
    size_t hlen, off;
    if (d[6] == 1) {
        hlen = (size_t)d[8] | (size_t)d[9] << 8;
        off = 10;
    } else if ((d[6] == 2 || d[6] == 3) && size >= 12) {
        hlen = (size_t)d[8] | (size_t)d[9] << 8 | (size_t)d[10] << 16 | (size_t)d[11] << 24;
        off = 12;
    } else {
        cli_error("%s: unsupported .npy version %d", name, (int)d[6]);
        return -1;
    }
    if (hlen > size - off) {
        cli_error("%s: truncated .npy header (%zu bytes promised, %zu in the file)", name, hlen,
                  size - off);
        return -1;
    }
    if (hlen > (1u << 20)) {
        cli_error("%s: .npy header too long", name);
        return -1;
    }
    char dict[1024];
    if (hlen >= sizeof dict) {
        cli_error("%s: .npy header too long for a 1-D vector", name);
        return -1;
    }
    memcpy(dict, d + off, hlen);
    dict[hlen] = '\0';
    if (strlen(dict) != hlen) {
        cli_error("%s: NUL byte in the .npy header", name);
        return -1;
    }
    const char *ds = dict_value(dict, "descr");
    const char *fo = dict_value(dict, "fortran_order");
    const char *sh = dict_value(dict, "shape");
    if (!ds || !fo || !sh) {
        cli_error("%s: the .npy header lacks descr, fortran_order or shape", name);
        return -1;
    }
    /* descr: '<f8', '|u1', ...: quote, byte order, kind, size, quote */
    if (!(ds[0] == '\'' && ds[1] && strchr("<>|=", ds[1]) && ds[2] && strchr("fiu", ds[2]) &&
          ds[3] && strchr("1248", ds[3]) && ds[4] == '\'')) {
        char shown[24];
        size_t k = 0;
        while (k + 1 < sizeof shown && ds[k] && ds[k] != ',')
            shown[k] = ds[k], k++;
        shown[k] = '\0';
        cli_error("%s: unsupported dtype %s (integers or float32/float64)", name, shown);
        return -1;
    }
    h->kind = ds[2];
    h->itemsize = (size_t)(ds[3] - '0');
    h->big = ds[1] == '>' || (ds[1] == '=' && !host_is_little());
    if (h->kind == 'f' && h->itemsize < 4) {
        cli_error("%s: unsupported dtype float16", name);
        return -1;
    }
    int fortran = strncmp(fo, "True", 4) == 0;
    if (!fortran && strncmp(fo, "False", 5) != 0) {
        cli_error("%s: bad fortran_order in the .npy header", name);
        return -1;
    }
    const char *p = sh;
    if (*p != '(') {
        cli_error("%s: bad shape in the .npy header", name);
        return -1;
    }
    p = skip_sp(p + 1);
    h->count = 1;
    while (*p != ')') {
        if (*p < '0' || *p > '9' || h->ndim >= 8) {
            cli_error("%s: bad shape in the .npy header", name);
            return -1;
        }
        int64_t v = 0;
        while (*p >= '0' && *p <= '9') {
            if (v > (INT64_MAX - 9) / 10) {
                cli_error("%s: bad shape in the .npy header", name);
                return -1;
            }
            v = v * 10 + (*p++ - '0');
        }
        h->dims[h->ndim++] = v;
        if (v != 0 && h->count > INT64_MAX / v) {
            cli_error("%s: the .npy shape is too large", name);
            return -1;
        }
        h->count *= v;
        p = skip_sp(p);
        if (*p == ',')
            p = skip_sp(p + 1);
        else if (*p != ')') {
            cli_error("%s: bad shape in the .npy header", name);
            return -1;
        }
    }
    if (fortran && h->ndim > 1) {
        int ones = 0;
        for (int i = 0; i < h->ndim; i++)
            ones += h->dims[i] == 1;
        if (ones < h->ndim - 1) {
            cli_error("%s: Fortran-order arrays are not supported", name);
            return -1;
        }
    }
    size_t data_bytes = size - off - hlen;
    if ((uint64_t)h->count > (uint64_t)data_bytes / h->itemsize ||
        (uint64_t)h->count * h->itemsize != data_bytes) {
        char shape[96];
        shape_text(h, shape, sizeof shape);
        cli_error("%s: shape %s of %zu-byte items needs %s bytes of data, the file has %zu",
                  name, shape, h->itemsize,
                  (uint64_t)h->count > (uint64_t)data_bytes / h->itemsize ? "more" : "fewer",
                  data_bytes);
        return -1;
    }
    h->data = d + off + hlen;
    return 0;
}

/* Item i as raw bits (host order). */
static uint64_t npy_item(const npy_info *h, int64_t i)
{
    const unsigned char *p = h->data + (size_t)i * h->itemsize;
    uint64_t u = 0;
    for (size_t k = 0; k < h->itemsize; k++)
        u = (u << 8) | p[h->big ? k : h->itemsize - 1 - k];
    return u;
}

int cli_npy_parse_vector(const unsigned char *data, size_t size, const char *name,
                         double **values, int64_t *n)
{
    *values = NULL;
    *n = 0;
    npy_info h;
    if (npy_header(data, size, name, &h))
        return -1;
    if (h.kind != 'f') {
        cli_error("%s: only float64 or float32 arrays are supported", name);
        return -1;
    }
    if (h.ndim == 0 || h.ndim > 2 || (h.ndim == 2 && h.dims[0] != 1 && h.dims[1] != 1)) {
        char shape[96];
        shape_text(&h, shape, sizeof shape);
        cli_error("%s: expected a 1-D array, got shape %s", name, shape);
        return -1;
    }
    double *out = malloc(h.count ? (size_t)h.count * sizeof *out : 1);
    if (!out) {
        cli_error("out of memory reading '%s'", name);
        return -1;
    }
    for (int64_t i = 0; i < h.count; i++) {
        uint64_t u = npy_item(&h, i);
        if (h.itemsize == 8) {
            memcpy(&out[i], &u, 8);
        } else {
            uint32_t u32 = (uint32_t)u;
            float x;
            memcpy(&x, &u32, 4);
            out[i] = x;
        }
    }
    *values = out;
    *n = h.count;
    return 0;
}

int cli_npy_parse_ints(const unsigned char *data, size_t size, const char *name, int32_t **ids,
                       int64_t *n)
{
    *ids = NULL;
    *n = 0;
    npy_info h;
    if (npy_header(data, size, name, &h))
        return -1;
    if (h.kind == 'f')
        return 1;
    if (h.ndim != 1) {
        char shape[96];
        shape_text(&h, shape, sizeof shape);
        cli_error("%s: expected a 1-D array of vertex ids, got shape %s", name, shape);
        return -1;
    }
    if (h.count > INT32_MAX) {
        cli_error("%s: too many ids", name);
        return -1;
    }
    int32_t *out = malloc(h.count ? (size_t)h.count * sizeof *out : 1);
    if (!out) {
        cli_error("out of memory reading '%s'", name);
        return -1;
    }
    for (int64_t i = 0; i < h.count; i++) {
        uint64_t u = npy_item(&h, i);
        int64_t v;
        if (h.kind == 'i' && h.itemsize < 8 && (u >> (8 * h.itemsize - 1)) & 1)
            v = (int64_t)(u | (~0ull << (8 * h.itemsize)));
        else
            v = (int64_t)u;
        if ((h.kind == 'u' && u > (uint64_t)INT32_MAX) || v < INT32_MIN || v > INT32_MAX) {
            cli_error("%s: source %" PRId64 " is out of range", name, i);
            free(out);
            return -1;
        }
        out[i] = (int32_t)v;
    }
    *ids = out;
    *n = h.count;
    return 0;
}

int cli_txt_parse_vector(const char *data, size_t size, const char *name, double **values,
                         int64_t *n)
{
    *values = NULL;
    *n = 0;
    size_t cap = 1024, len = 0;
    double *out = malloc(cap * sizeof *out);
    if (!out) {
        cli_error("out of memory reading '%s'", name);
        return -1;
    }
    const char *p = data, *end = data + size;
    int64_t line = 1;
    while (p < end) {
        char c = *p;
        if (c == '\n') {
            line++;
            p++;
        } else if (c == ' ' || c == '\t' || c == '\r' || c == ',') {
            p++;
        } else if (c == '#') {
            while (p < end && *p != '\n')
                p++;
        } else {
            const char *q;
            double v;
            if (!mfmm_io_strtod(p, &q, &v) ||
                !(q == end || *q == ' ' || *q == '\t' || *q == '\r' || *q == '\n' || *q == ',' ||
                  *q == '#')) {
                cli_error("%s:%" PRId64 ": not a number", name, line);
                free(out);
                return -1;
            }
            if (len == cap) {
                double *nb = cap > SIZE_MAX / 2 / sizeof *out ? NULL : realloc(out, 2 * cap * sizeof *out);
                if (!nb) {
                    cli_error("out of memory reading '%s'", name);
                    free(out);
                    return -1;
                }
                out = nb;
                cap *= 2;
            }
            out[len++] = v;
            p = q;
        }
    }
    *values = out;
    *n = (int64_t)len;
    return 0;
}

int cli_npy_read_vector(const char *path, double **values, int64_t *n)
{
    unsigned char *d;
    size_t size;
    *values = NULL;
    *n = 0;
    if (cli_read_file(path, &d, &size))
        return -1;
    int r = cli_npy_parse_vector(d, size, path, values, n);
    free(d);
    return r;
}

int cli_npy_read_ints(const char *path, int32_t **ids, int64_t *n)
{
    unsigned char *d;
    size_t size;
    *ids = NULL;
    *n = 0;
    if (cli_read_file(path, &d, &size))
        return -1;
    int r = cli_npy_parse_ints(d, size, path, ids, n);
    free(d);
    return r;
}

int cli_txt_read_vector(const char *path, double **values, int64_t *n)
{
    unsigned char *d;
    size_t size;
    *values = NULL;
    *n = 0;
    if (cli_read_file(path, &d, &size))
        return -1;
    if (memchr(d, '\0', size)) {
        cli_error("%s: a binary file (NUL byte), not text; give a .npy file or one number per line", path);
        free(d);
        return -1;
    }
    int r = cli_txt_parse_vector((const char *)d, size, path, values, n);
    free(d);
    return r;
}

int cli_read_ids(const char *path, int32_t **ids, int64_t *n)
{
    *ids = NULL;
    *n = 0;
    double *v = NULL;
    int64_t count = 0;
    if (cli_has_ext(path, "npy")) {
        int r = cli_npy_read_ints(path, ids, n);
        if (r <= 0)
            return r;
        if (cli_npy_read_vector(path, &v, &count))
            return -1;
    } else if (cli_txt_read_vector(path, &v, &count)) {
        return -1;
    }
    *ids = malloc(count ? (size_t)count * sizeof **ids : 1);
    if (!*ids) {
        free(v);
        cli_error("out of memory");
        return -1;
    }
    for (int64_t i = 0; i < count; i++) {
        if (!(v[i] == floor(v[i])) || fabs(v[i]) > 2147483647.0) {
            cli_error("%s: value %lld (%g) is not a vertex id", path, (long long)i, v[i]);
            free(v);
            free(*ids);
            *ids = NULL;
            return -1;
        }
        (*ids)[i] = (int32_t)v[i];
    }
    free(v);
    *n = count;
    return 0;
}

int cli_write_vector(const char *path, int npy, const void *values, int32_t n, int is_double)
{
    if (npy) {
        cli_npy_writer w;
        if (cli_npy_open(&w, path, is_double ? "<f8" : "<i4", n, -1))
            return -1;
        if (cli_npy_append(&w, values, n)) {
            cli_npy_abort(&w);
            return -1;
        }
        return cli_npy_close(&w);
    }
    cli_output out;
    if (cli_output_open(&out, path))
        return -1;
    int bad = 0;
    for (int32_t i = 0; i < n && !bad && !cli_interrupted(); i++) {
        if (is_double)
            bad = cli_put_double(out.f, ((const double *)values)[i]) < 0;
        else
            bad = fprintf(out.f, "%ld", (long)((const int32_t *)values)[i]) < 0;
        bad = bad || fputc('\n', out.f) == EOF;
    }
    return cli_output_close(&out, bad);
}
