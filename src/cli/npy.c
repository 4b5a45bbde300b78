/* .npy (format 1.0) streaming writer and small readers of 1-D float and
 * integer vectors; plain text vectors. */
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

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

static char *str_concat(const char *a, const char *b)
{
    size_t na = strlen(a), nb = strlen(b);
    char *s = malloc(na + nb + 1);
    if (s) {
        memcpy(s, a, na);
        memcpy(s + na, b, nb + 1);
    }
    return s;
}

int cli_npy_open(cli_npy_writer *w, const char *path, const char *dtype, int64_t rows,
                 int64_t cols)
{
    memset(w, 0, sizeof *w);
    if (strcmp(dtype, "<f4") == 0)
        w->itemsize = 4;
    else if (strcmp(dtype, "<f8") == 0)
        w->itemsize = 8;
    else {
        cli_error("npy: unsupported dtype '%s'", dtype);
        return -1;
    }
    if (rows < 0) {
        cli_error("npy: negative row count");
        return -1;
    }
    w->rows = rows;
    w->cols = cols < 0 ? 1 : cols;
    w->path = str_concat(path, "");
    w->tmp_path = str_concat(path, ".partial");
    if (!w->path || !w->tmp_path) {
        cli_error("out of memory");
        cli_npy_abort(w);
        return -1;
    }
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
    w->f = fopen(w->tmp_path, "wb");
    if (!w->f) {
        cli_error("cannot create '%s': %s", w->tmp_path, strerror(errno));
        free(w->path);
        free(w->tmp_path);
        w->path = w->tmp_path = NULL;
        return -1;
    }
    if (fwrite(header, 1, total, w->f) != total) {
        cli_error("cannot write '%s': %s", w->tmp_path, strerror(errno));
        cli_npy_abort(w);
        return -1;
    }
    return 0;
}

int cli_npy_append(cli_npy_writer *w, const void *data, int64_t n_rows)
{
    if (!w->f)
        return -1;
    if (n_rows < 0 || n_rows > w->rows - w->rows_written) {
        cli_error("npy: more rows than the header promised (%" PRId64 ")", w->rows);
        return -1;
    }
    size_t n = (size_t)n_rows * (size_t)w->cols;
    if (host_is_little()) {
        if (n && fwrite(data, w->itemsize, n, w->f) != n)
            goto fail;
    } else {
        unsigned char buf[8192];
        const unsigned char *src = data;
        size_t per = sizeof buf / w->itemsize;
        for (size_t i = 0; i < n; i += per) {
            size_t k = n - i < per ? n - i : per;
            memcpy(buf, src + i * w->itemsize, k * w->itemsize);
            swap_bytes(buf, k, w->itemsize);
            if (fwrite(buf, w->itemsize, k, w->f) != k)
                goto fail;
        }
    }
    w->rows_written += n_rows;
    return 0;
fail:
    cli_error("cannot write '%s': %s", w->tmp_path, strerror(errno));
    return -1;
}

int cli_npy_close(cli_npy_writer *w)
{
    if (!w->f)
        return -1;
    if (w->rows_written != w->rows) {
        cli_error("npy: %" PRId64 " rows written, %" PRId64 " promised", w->rows_written, w->rows);
        cli_npy_abort(w);
        return -1;
    }
    int bad = fflush(w->f) != 0 || ferror(w->f);
    bad |= fclose(w->f) != 0;
    w->f = NULL;
    if (bad) {
        cli_error("cannot write '%s': %s", w->tmp_path, strerror(errno));
        cli_npy_abort(w);
        return -1;
    }
    if (rename(w->tmp_path, w->path) != 0) {
        cli_error("cannot rename '%s' to '%s': %s", w->tmp_path, w->path, strerror(errno));
        cli_npy_abort(w);
        return -1;
    }
    free(w->path);
    free(w->tmp_path);
    w->path = w->tmp_path = NULL;
    return 0;
}

void cli_npy_abort(cli_npy_writer *w)
{
    if (w->f) {
        fclose(w->f);
        w->f = NULL;
    }
    if (w->tmp_path)
        remove(w->tmp_path);
    free(w->path);
    free(w->tmp_path);
    w->path = w->tmp_path = NULL;
}

/* ---- readers ---- */

/* Value of `key` in a numpy header dict: points just past "'key':" and blanks. */
static const char *dict_value(const char *dict, const char *key)
{
    char pat[40];
    snprintf(pat, sizeof pat, "'%s'", key);
    const char *p = strstr(dict, pat);
    if (!p)
        return NULL;
    p += strlen(pat);
    while (*p == ' ')
        p++;
    if (*p != ':')
        return NULL;
    p++;
    while (*p == ' ')
        p++;
    return p;
}

/* Reads the magic string, version and header dict (format 1.0 to 3.0) of
 * a .npy file; *dict is malloc'ed and NUL-terminated, and f is left at the
 * data. 0, -1 when it is not a readable .npy file, -2 when out of memory
 * (nothing printed). */
static int read_header(FILE *f, char **dict)
{
    unsigned char pre[12];
    *dict = NULL;
    if (fread(pre, 1, 10, f) != 10 || memcmp(pre, "\x93NUMPY", 6) != 0)
        return -1;
    size_t hlen;
    if (pre[6] == 1) {
        hlen = (size_t)pre[8] | (size_t)pre[9] << 8;
    } else if (pre[6] == 2 || pre[6] == 3) {
        if (fread(pre + 10, 1, 2, f) != 2)
            return -1;
        hlen = (size_t)pre[8] | (size_t)pre[9] << 8 | (size_t)pre[10] << 16 |
               (size_t)pre[11] << 24;
        if (hlen > 1 << 20)
            return -1;
    } else {
        return -1;
    }
    *dict = malloc(hlen + 1);
    if (!*dict)
        return -2;
    if (fread(*dict, 1, hlen, f) != hlen)
        return -1;
    (*dict)[hlen] = '\0';
    return 0;
}

int cli_npy_read_vector(const char *path, double **values, int64_t *n)
{
    *values = NULL;
    *n = 0;
    FILE *f = fopen(path, "rb");
    if (!f) {
        cli_error("cannot open '%s': %s", path, strerror(errno));
        return -1;
    }
    char *dict = NULL;
    void *raw = NULL;
    double *out = NULL;
    int hr = read_header(f, &dict);
    if (hr == -2)
        goto oom;
    if (hr)
        goto bad;
    const char *d = dict_value(dict, "descr");
    const char *fo = dict_value(dict, "fortran_order");
    const char *sh = dict_value(dict, "shape");
    if (!d || !fo || !sh)
        goto bad;
    size_t itemsize;
    int big;
    if (strncmp(d, "'<f8'", 5) == 0 || strncmp(d, "'>f8'", 5) == 0)
        itemsize = 8;
    else if (strncmp(d, "'<f4'", 5) == 0 || strncmp(d, "'>f4'", 5) == 0)
        itemsize = 4;
    else {
        cli_error("%s: only float64 or float32 arrays are supported", path);
        goto fail;
    }
    big = d[1] == '>';
    /* Shape: (N,) or (N, 1) or (1, N). */
    if (*sh != '(')
        goto bad;
    int64_t dims[2] = {1, 1};
    int ndim = 0;
    const char *p = sh + 1;
    for (;;) {
        while (*p == ' ')
            p++;
        if (*p == ')')
            break;
        char *end;
        errno = 0;
        long long v = strtoll(p, &end, 10);
        if (end == p || errno || v < 0 || ndim >= 2)
            goto shape;
        dims[ndim++] = v;
        p = end;
        while (*p == ' ')
            p++;
        if (*p == ',')
            p++;
        else if (*p != ')')
            goto bad;
    }
    if (ndim == 0 || (ndim == 2 && dims[0] != 1 && dims[1] != 1))
        goto shape;
    int64_t count = dims[0] * dims[1];
    /* Bound by the bytes left in the file. */
    long here = ftell(f);
    if (here < 0 || fseek(f, 0, SEEK_END) != 0)
        goto bad;
    long fend = ftell(f);
    if (fend < here || fseek(f, here, SEEK_SET) != 0)
        goto bad;
    if ((uint64_t)count > (uint64_t)(fend - here) / itemsize) {
        cli_error("%s: truncated .npy file (%" PRId64 " values promised)", path, count);
        goto fail;
    }
    raw = malloc(count ? (size_t)count * itemsize : 1);
    out = malloc(count ? (size_t)count * sizeof(double) : 1);
    if (!raw || !out)
        goto oom;
    if (fread(raw, itemsize, (size_t)count, f) != (size_t)count)
        goto bad;
    if (big == host_is_little())
        swap_bytes(raw, (size_t)count, itemsize);
    for (int64_t i = 0; i < count; i++) {
        if (itemsize == 8) {
            memcpy(&out[i], (unsigned char *)raw + 8 * i, 8);
        } else {
            float x;
            memcpy(&x, (unsigned char *)raw + 4 * i, 4);
            out[i] = x;
        }
    }
    free(raw);
    free(dict);
    fclose(f);
    *values = out;
    *n = count;
    return 0;
shape:
    cli_error("%s: expected a 1-D array", path);
    goto fail;
oom:
    cli_error("out of memory reading '%s'", path);
    goto fail;
bad:
    cli_error("%s: not a readable .npy file", path);
fail:
    free(raw);
    free(out);
    free(dict);
    fclose(f);
    return -1;
}

int cli_npy_read_ints(const char *path, int32_t **ids, int64_t *n)
{
    *ids = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) {
        cli_error("cannot open '%s': %s", path, strerror(errno));
        return -1;
    }
    char *dict = NULL;
    unsigned char *raw = NULL;
    int rc = -1;
    if (read_header(f, &dict))
        goto bad;
    const char *d = dict_value(dict, "descr");
    const char *sh = dict_value(dict, "shape");
    if (!d || !sh)
        goto bad;
    /* e.g. '<i4', '|u1' */
    if (d[0] != '\'' || !strchr("<>|=", d[1]) || (d[2] != 'i' && d[2] != 'u') ||
        !strchr("1248", d[3]) || d[4] != '\'') {
        rc = 1;
        goto out;
    }
    int big = d[1] == '>', is_signed = d[2] == 'i';
    size_t size = (size_t)(d[3] - '0');
    long long count = -1, other = 1;
    if (sscanf(sh, "(%lld,)", &count) != 1 && sscanf(sh, "(%lld, %lld)", &count, &other) != 2)
        goto bad;
    if (count < 0 || other < 0 || (other != 1 && count != 1))
        goto bad;
    count *= other;
    if (count > INT32_MAX) {
        cli_error("%s: too many sources", path);
        goto out;
    }
    raw = malloc(count ? (size_t)count * size : 1);
    *ids = malloc(count ? (size_t)count * sizeof **ids : 1);
    if (!raw || !*ids) {
        cli_error("out of memory reading '%s'", path);
        goto out;
    }
    if (fread(raw, size, (size_t)count, f) != (size_t)count)
        goto bad;
    for (long long i = 0; i < count; i++) {
        const unsigned char *p = raw + (size_t)i * size;
        unsigned long long u = 0;
        for (size_t k = 0; k < size; k++) {
            size_t byte = big ? k : size - 1 - k;
            u = (u << 8) | p[byte];
        }
        long long v;
        if (is_signed && size < 8 && (u >> (8 * size - 1)) & 1)
            v = (long long)(u | (~0ull << (8 * size)));
        else
            v = (long long)u;
        if ((!is_signed && size == 8 && u > (unsigned long long)INT32_MAX) || v < INT32_MIN ||
            v > INT32_MAX) {
            cli_error("%s: source %lld is out of range", path, i);
            goto out;
        }
        (*ids)[i] = (int32_t)v;
    }
    *n = count;
    rc = 0;
    goto out;
bad:
    cli_error("%s: not a readable .npy file", path);
out:
    if (rc != 0) {
        free(*ids);
        *ids = NULL;
    }
    free(raw);
    free(dict);
    fclose(f);
    return rc;
}

int cli_txt_read_vector(const char *path, double **values, int64_t *n)
{
    *values = NULL;
    *n = 0;
    FILE *f = fopen(path, "r");
    if (!f) {
        cli_error("cannot open '%s': %s", path, strerror(errno));
        return -1;
    }
    size_t cap = 1024, len = 0;
    double *out = malloc(cap * sizeof *out);
    char line[4096];
    int64_t lineno = 0;
    if (!out) {
        cli_error("out of memory reading '%s'", path);
        fclose(f);
        return -1;
    }
    while (fgets(line, sizeof line, f)) {
        lineno++;
        size_t l = strlen(line);
        if (l == sizeof line - 1 && line[l - 1] != '\n' && !feof(f)) {
            cli_error("%s:%" PRId64 ": line too long", path, lineno);
            goto fail;
        }
        char *hash = strchr(line, '#');
        if (hash)
            *hash = '\0';
        char *p = line;
        for (;;) {
            while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n' || *p == ',')
                p++;
            if (!*p)
                break;
            char *end;
            double v = strtod(p, &end);
            if (end == p || !(*end == '\0' || *end == ' ' || *end == '\t' || *end == '\r' ||
                              *end == '\n' || *end == ',')) {
                cli_error("%s:%" PRId64 ": not a number", path, lineno);
                goto fail;
            }
            if (len == cap) {
                double *nb = realloc(out, 2 * cap * sizeof *out);
                if (!nb) {
                    cli_error("out of memory reading '%s'", path);
                    goto fail;
                }
                out = nb;
                cap *= 2;
            }
            out[len++] = v;
            p = end;
        }
    }
    if (ferror(f)) {
        cli_error("cannot read '%s'", path);
        goto fail;
    }
    fclose(f);
    *values = out;
    *n = (int64_t)len;
    return 0;
fail:
    free(out);
    fclose(f);
    return -1;
}
