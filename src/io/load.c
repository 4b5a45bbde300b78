/* mfmm_load_mesh: reads a whole file and dispatches to the OBJ, OFF or PLY
 * parser by extension (case-insensitive), sniffing the content otherwise. */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io.h"
#include "core/mesh.h"

/* Reads the whole file into a NUL-terminated buffer. */
static mfmm_status read_file(const char *path, char **data, size_t *size, mfmm_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return mfmm_fail(err, MFMM_ERR_IO, -1, "cannot open '%.180s': %.40s", path,
                         strerror(errno));
    /* A first chunk, then the rest sized by the file's length when known
     * (a directory or an unreadable file fails on the first read). */
    size_t cap = 1 << 16, len = 0;
    char *buf = malloc(cap);
    if (!buf)
        goto oom;
    len = fread(buf, 1, cap - 1, f);
    if (len == cap - 1 && fseek(f, 0, SEEK_END) == 0) {
        long end = ftell(f);
        if (fseek(f, (long)len, SEEK_SET) != 0) {
            free(buf);
            fclose(f);
            return mfmm_fail(err, MFMM_ERR_IO, -1, "cannot read '%.180s'", path);
        }
        if (end > 0 && (unsigned long)end > len && (unsigned long)end < SIZE_MAX - 2) {
            char *nb = realloc(buf, (size_t)end + 2); /* room for the NUL and an EOF probe */
            if (!nb)
                goto oom;
            buf = nb;
            cap = (size_t)end + 2;
        }
    }
    while (!ferror(f)) {
        if (len + 1 >= cap) {
            if (cap > SIZE_MAX / 2) {
                free(buf);
                fclose(f);
                return mfmm_fail(err, MFMM_ERR_IO, -1, "'%.180s' is too large", path);
            }
            char *nb = realloc(buf, cap * 2);
            if (!nb)
                goto oom;
            buf = nb;
            cap *= 2;
        }
        size_t got = fread(buf + len, 1, cap - 1 - len, f);
        len += got;
        if (got == 0)
            break;
    }
    if (ferror(f)) {
        int e = errno;
        free(buf);
        fclose(f);
        return mfmm_fail(err, MFMM_ERR_IO, -1, "cannot read '%.180s': %.40s", path,
                         e ? strerror(e) : "read error");
    }
    fclose(f);
    buf[len] = '\0';
    *data = buf;
    *size = len;
    return MFMM_OK;
oom:
    free(buf);
    fclose(f);
    return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory reading '%.180s'", path);
}

static int lower(int c)
{
    return c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c;
}

static int ext_is(const char *ext, const char *want)
{
    while (*ext && *want) {
        if (lower((unsigned char)*ext) != *want)
            return 0;
        ext++;
        want++;
    }
    return *ext == '\0' && *want == '\0';
}

enum { FMT_UNKNOWN, FMT_OBJ, FMT_OFF, FMT_PLY };

static int format_from_path(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    if (!dot)
        return FMT_UNKNOWN;
    if (ext_is(dot + 1, "obj"))
        return FMT_OBJ;
    if (ext_is(dot + 1, "off"))
        return FMT_OFF;
    if (ext_is(dot + 1, "ply"))
        return FMT_PLY;
    return FMT_UNKNOWN;
}

static int format_from_content(const char *data, size_t size)
{
    if (size >= 4 && memcmp(data, "ply", 3) == 0 && (data[3] == '\n' || data[3] == '\r'))
        return FMT_PLY;
    /* OFF headers: OFF, COFF, NOFF, CNOFF, STOFF, 4OFF, ... */
    const char *p = data;
    size_t i = 0;
    while (i < size && i < 8 && p[i] != 'O' && ((p[i] >= 'A' && p[i] <= 'Z') || p[i] == '4'))
        i++;
    if (i + 3 <= size && memcmp(p + i, "OFF", 3) == 0)
        return FMT_OFF;
    return FMT_OBJ;
}

mfmm_status mfmm_load_mesh(const char *path, double **vertices, int32_t *nv,
                           int32_t **faces, int32_t *nf, mfmm_error *err)
{
    if (!path || !vertices || !nv || !faces || !nf)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "mfmm_load_mesh: a pointer is NULL");
    *vertices = NULL;
    *faces = NULL;
    *nv = 0;
    *nf = 0;
    char *data = NULL;
    size_t size = 0;
    mfmm_status st = read_file(path, &data, &size, err);
    if (st != MFMM_OK)
        return st;
    int fmt = format_from_path(path);
    if (fmt == FMT_UNKNOWN)
        fmt = format_from_content(data, size);
    mfmm_io_result r = {NULL, 0, NULL, 0};
    mfmm_error local;
    mfmm_error *e = err ? err : &local;
    switch (fmt) {
    case FMT_PLY:
        st = mfmm_io_parse_ply(data, size, &r, e);
        break;
    case FMT_OFF:
        st = mfmm_io_parse_off(data, size, &r, e);
        break;
    default:
        st = mfmm_io_parse_obj(data, size, &r, e);
        break;
    }
    free(data);
    if (st != MFMM_OK) {
        /* Prefix the file name to the parser's sentence. */
        char msg[sizeof e->message];
        snprintf(msg, sizeof msg, "%s", e->message);
        const char *slash = strrchr(path, '/');
        mfmm_fail(err, st, e->index, "%.60s: %s", slash ? slash + 1 : path, msg);
        return st;
    }
    *vertices = r.V;
    *nv = r.nv;
    *faces = r.F;
    *nf = r.nf;
    mfmm_ok(err);
    return MFMM_OK;
}
