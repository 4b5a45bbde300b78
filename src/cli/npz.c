/* A scipy.sparse CSR matrix as a .npz file (scipy.sparse.save_npz's layout:
 * a zip of format.npy, shape.npy, data.npy, indices.npy, indptr.npy, stored
 * uncompressed, zip64 so that members may pass 4 GiB). Rows are streamed into
 * two unlinked temporary files beside the output (values and column ids;
 * the row pointers, one per row, stay in memory), and the zip is written at
 * the end through cli_output (a temporary file renamed when complete), so
 * memory is O(rows), never O(rows x cols). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"

static int host_little(void)
{
    const uint16_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 1;
}

/* An unlinked temporary file beside `path`. */
static FILE *scratch(const char *path)
{
    size_t n = strlen(path);
    char *t = malloc(n + 16);
    if (!t)
        return NULL;
    memcpy(t, path, n);
    memcpy(t + n, ".part.XXXXXX", 13);
    int fd = mkstemp(t);
    FILE *f = NULL;
    if (fd >= 0) {
        unlink(t);
        f = fdopen(fd, "w+b");
        if (!f)
            close(fd);
    }
    if (!f)
        cli_error("cannot create a temporary file beside '%s': %s", path, strerror(errno));
    free(t);
    return f;
}

void cli_npz_abort(cli_npz_writer *w)
{
    if (w->data)
        fclose(w->data);
    if (w->indices)
        fclose(w->indices);
    free(w->indptr);
    free(w->path);
    memset(w, 0, sizeof *w);
}

int cli_npz_open(cli_npz_writer *w, const char *path, int f64, int64_t rows, int64_t cols)
{
    memset(w, 0, sizeof *w);
    w->rows = rows;
    w->cols = cols;
    w->itemsize = f64 ? 8 : 4;
    w->path = malloc(strlen(path) + 1);
    w->indptr = malloc(((size_t)rows + 1) * sizeof *w->indptr);
    if (!w->path || !w->indptr) {
        cli_error("out of memory for %lld row pointers", (long long)rows + 1);
        cli_npz_abort(w);
        return -1;
    }
    strcpy(w->path, path);
    w->indptr[0] = 0;
    w->data = scratch(path);
    w->indices = w->data ? scratch(path) : NULL;
    if (!w->indices) {
        cli_npz_abort(w);
        return -1;
    }
    return 0;
}

int cli_npz_append(cli_npz_writer *w, int32_t n_rows, const int64_t *indptr,
                   const int32_t *indices, const void *values)
{
    if (w->rows_written + n_rows > w->rows) {
        cli_error("%s: more rows than promised", w->path);
        return -1;
    }
    size_t nnz = (size_t)indptr[n_rows];
    if (fwrite(indices, sizeof *indices, nnz, w->indices) != nnz ||
        fwrite(values, w->itemsize, nnz, w->data) != nnz) {
        cli_error("cannot write a temporary file beside '%s': %s", w->path, strerror(errno));
        return -1;
    }
    for (int32_t i = 0; i < n_rows; i++)
        w->indptr[w->rows_written + i + 1] = w->nnz + indptr[i + 1];
    w->rows_written += n_rows;
    w->nnz += (int64_t)nnz;
    return 0;
}

/* ---- zip (stored, zip64) ---- */

static uint32_t crc_table_entry(uint32_t c)
{
    for (int k = 0; k < 8; k++)
        c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    return c;
}

typedef struct zip_out {
    FILE *f;
    uint32_t table[256];
    uint32_t crc;
    uint64_t size;
    int failed;
    struct {
        const char *name;
        uint32_t crc;
        uint64_t size, offset;
    } member[5];
    int n;
} zip_out;

static void put(zip_out *z, const void *p, size_t n)
{
    if (!z->failed && fwrite(p, 1, n, z->f) != n)
        z->failed = 1;
}

static void put_le(zip_out *z, uint64_t v, int bytes)
{
    unsigned char b[8];
    for (int i = 0; i < bytes; i++)
        b[i] = (unsigned char)(v >> (8 * i));
    put(z, b, (size_t)bytes);
}

/* Member content: counted into the CRC and size. */
static void content(zip_out *z, const void *p, size_t n)
{
    const unsigned char *b = p;
    uint32_t c = z->crc;
    for (size_t i = 0; i < n; i++)
        c = z->table[(c ^ b[i]) & 0xFF] ^ (c >> 8);
    z->crc = c;
    z->size += n;
    put(z, p, n);
}

static void local_header(zip_out *z, const char *name, uint32_t crc, uint64_t size)
{
    size_t nl = strlen(name);
    put_le(z, 0x04034b50, 4);
    put_le(z, 45, 2);         /* version needed: zip64 */
    put_le(z, 0, 2);          /* flags */
    put_le(z, 0, 2);          /* stored */
    put_le(z, 0, 2);          /* time */
    put_le(z, (1 << 5) | 1, 2); /* date 1980-01-01 */
    put_le(z, crc, 4);
    put_le(z, 0xFFFFFFFFu, 4);
    put_le(z, 0xFFFFFFFFu, 4);
    put_le(z, nl, 2);
    put_le(z, 20, 2);
    put(z, name, nl);
    put_le(z, 0x0001, 2);
    put_le(z, 16, 2);
    put_le(z, size, 8);
    put_le(z, size, 8);
}

static void member_begin(zip_out *z, const char *name)
{
    long off = ftell(z->f);
    if (off < 0)
        z->failed = 1;
    z->member[z->n].name = name;
    z->member[z->n].offset = (uint64_t)off;
    local_header(z, name, 0, 0);
    z->crc = 0xFFFFFFFFu;
    z->size = 0;
}

/* Patches the member's local header with its CRC and size. */
static void member_end(zip_out *z)
{
    uint32_t crc = z->crc ^ 0xFFFFFFFFu;
    z->member[z->n].crc = crc;
    z->member[z->n].size = z->size;
    if (!z->failed && fseek(z->f, (long)z->member[z->n].offset, SEEK_SET) != 0)
        z->failed = 1;
    local_header(z, z->member[z->n].name, crc, z->size);
    if (!z->failed && fseek(z->f, 0, SEEK_END) != 0)
        z->failed = 1;
    z->n++;
}

/* A .npy v1.0 header for a 1-D array (n < 0: a 0-d scalar). */
static void npy_header(zip_out *z, const char *descr, int64_t n)
{
    char dict[128];
    if (n < 0)
        snprintf(dict, sizeof dict, "{'descr': '%s', 'fortran_order': False, 'shape': (), }",
                 descr);
    else
        snprintf(dict, sizeof dict,
                 "{'descr': '%s', 'fortran_order': False, 'shape': (%lld,), }", descr,
                 (long long)n);
    size_t len = strlen(dict);
    size_t total = 10 + len + 1;
    size_t pad = (64 - total % 64) % 64;
    unsigned char pre[10] = {0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0, 0, 0};
    size_t hl = len + pad + 1;
    pre[8] = (unsigned char)(hl & 0xFF);
    pre[9] = (unsigned char)(hl >> 8);
    content(z, pre, 10);
    content(z, dict, len);
    for (size_t i = 0; i < pad; i++)
        content(z, " ", 1);
    content(z, "\n", 1);
}

static void copy_file(zip_out *z, FILE *src)
{
    unsigned char buf[1 << 16];
    if (fflush(src) != 0 || fseek(src, 0, SEEK_SET) != 0) {
        z->failed = 1;
        return;
    }
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, src)) > 0)
        content(z, buf, n);
    if (ferror(src))
        z->failed = 1;
}

int cli_npz_close(cli_npz_writer *w)
{
    if (w->rows_written != w->rows) {
        cli_error("%s: %lld of %lld rows written", w->path, (long long)w->rows_written,
                  (long long)w->rows);
        cli_npz_abort(w);
        return -1;
    }
    cli_output out;
    if (cli_output_open(&out, w->path)) {
        cli_npz_abort(w);
        return -1;
    }
    zip_out z;
    memset(&z, 0, sizeof z);
    z.f = out.f;
    for (uint32_t i = 0; i < 256; i++)
        z.table[i] = crc_table_entry(i);
    char e = host_little() ? '<' : '>';
    char d_val[5] = {e, 'f', w->itemsize == 8 ? '8' : '4', 0, 0};
    char d_i4[4] = {e, 'i', '4', 0}, d_i8[4] = {e, 'i', '8', 0};

    member_begin(&z, "format.npy");
    npy_header(&z, "|S3", -1);
    content(&z, "csr", 3);
    member_end(&z);

    member_begin(&z, "shape.npy");
    npy_header(&z, d_i8, 2);
    int64_t shape[2] = {w->rows, w->cols};
    content(&z, shape, sizeof shape);
    member_end(&z);

    member_begin(&z, "data.npy");
    npy_header(&z, d_val, w->nnz);
    copy_file(&z, w->data);
    member_end(&z);

    member_begin(&z, "indices.npy");
    npy_header(&z, d_i4, w->nnz);
    copy_file(&z, w->indices);
    member_end(&z);

    member_begin(&z, "indptr.npy");
    npy_header(&z, d_i8, w->rows + 1);
    content(&z, w->indptr, ((size_t)w->rows + 1) * sizeof *w->indptr);
    member_end(&z);

    /* central directory, zip64 end record and locator, end record */
    long cd = ftell(z.f);
    if (cd < 0)
        z.failed = 1;
    for (int i = 0; i < z.n; i++) {
        size_t nl = strlen(z.member[i].name);
        put_le(&z, 0x02014b50, 4);
        put_le(&z, 45, 2);
        put_le(&z, 45, 2);
        put_le(&z, 0, 2);
        put_le(&z, 0, 2);
        put_le(&z, 0, 2);
        put_le(&z, (1 << 5) | 1, 2);
        put_le(&z, z.member[i].crc, 4);
        put_le(&z, 0xFFFFFFFFu, 4);
        put_le(&z, 0xFFFFFFFFu, 4);
        put_le(&z, nl, 2);
        put_le(&z, 28, 2);
        put_le(&z, 0, 2);
        put_le(&z, 0, 2);
        put_le(&z, 0, 2);
        put_le(&z, 0, 4);
        put_le(&z, 0xFFFFFFFFu, 4);
        put(&z, z.member[i].name, nl);
        put_le(&z, 0x0001, 2);
        put_le(&z, 24, 2);
        put_le(&z, z.member[i].size, 8);
        put_le(&z, z.member[i].size, 8);
        put_le(&z, z.member[i].offset, 8);
    }
    long eocd64 = ftell(z.f);
    if (eocd64 < 0)
        z.failed = 1;
    uint64_t cd_size = (uint64_t)(eocd64 - cd);
    put_le(&z, 0x06064b50, 4);
    put_le(&z, 44, 8);
    put_le(&z, 45, 2);
    put_le(&z, 45, 2);
    put_le(&z, 0, 4);
    put_le(&z, 0, 4);
    put_le(&z, (uint64_t)z.n, 8);
    put_le(&z, (uint64_t)z.n, 8);
    put_le(&z, cd_size, 8);
    put_le(&z, (uint64_t)cd, 8);
    put_le(&z, 0x07064b50, 4);
    put_le(&z, 0, 4);
    put_le(&z, (uint64_t)eocd64, 8);
    put_le(&z, 1, 4);
    put_le(&z, 0x06054b50, 4);
    put_le(&z, 0, 2);
    put_le(&z, 0, 2);
    put_le(&z, (uint64_t)z.n, 2);
    put_le(&z, (uint64_t)z.n, 2);
    put_le(&z, cd_size < 0xFFFFFFFFu ? cd_size : 0xFFFFFFFFu, 4);
    put_le(&z, 0xFFFFFFFFu, 4);
    put_le(&z, 0, 2);
    if (z.failed)
        cli_error("cannot write '%s': %s", out.tmp_path ? out.tmp_path : w->path,
                  strerror(errno));
    int r = cli_output_close(&out, z.failed);
    cli_npz_abort(w);
    return r;
}
