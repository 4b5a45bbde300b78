/* mfmm_load_mesh: reads a whole regular file and dispatches to the OBJ, OFF,
 * PLY or STL parser by extension (case-insensitive), sniffing the content
 * when the extension says nothing. */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io.h"
#include "base/error.h"

#define FORMATS_READ "meshfmm reads OBJ, OFF, PLY (ascii and binary) and STL (ascii and binary)"

static const char *file_kind(mode_t mode)
{
    if (S_ISDIR(mode))
        return "a directory";
    if (S_ISFIFO(mode))
        return "a FIFO (named pipe)";
    if (S_ISCHR(mode))
        return "a character device";
    if (S_ISBLK(mode))
        return "a block device";
    if (S_ISSOCK(mode))
        return "a socket";
    return "not a regular file";
}

int mfmm_io_open_regular(const char *path, off_t *size, const char **why)
{
    /* O_NONBLOCK: opening a FIFO with no writer must not block. */
    int fd = open(path, O_RDONLY | O_NONBLOCK);
    if (fd < 0) {
        *why = strerror(errno);
        return -1;
    }
    struct stat sb;
    if (fstat(fd, &sb) != 0) {
        *why = strerror(errno);
        close(fd);
        return -1;
    }
    if (!S_ISREG(sb.st_mode)) {
        *why = file_kind(sb.st_mode);
        close(fd);
        errno = EINVAL;
        return -2;
    }
    int fl = fcntl(fd, F_GETFL);
    if (fl != -1)
        fcntl(fd, F_SETFL, fl & ~O_NONBLOCK);
    *size = sb.st_size;
    return fd;
}

/* Reads the whole regular file into a NUL-terminated buffer: the size
 * fstat gives bounds the allocation (a file growing meanwhile is an error). */
static mfmm_status read_file(const char *path, char **data, size_t *size, mfmm_error *err)
{
    off_t fsize = 0;
    const char *why = NULL;
    int fd = mfmm_io_open_regular(path, &fsize, &why);
    if (fd == -2)
        return mfmm_fail(err, MFMM_ERR_IO, -1, "'%.180s' is %s, not a mesh file", path, why);
    if (fd < 0)
        return mfmm_fail(err, MFMM_ERR_IO, -1, "cannot open '%.180s': %.40s", path, why);
    if ((uint64_t)fsize >= (uint64_t)SIZE_MAX - 2 || (uint64_t)fsize > (uint64_t)PTRDIFF_MAX / 2) {
        close(fd);
        return mfmm_fail(err, MFMM_ERR_IO, -1, "'%.180s' is too large", path);
    }
    size_t want = (size_t)fsize, len = 0;
    char *buf = malloc(want + 2); /* the NUL and a probe byte for growth */
    if (!buf) {
        close(fd);
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory reading '%.180s'",
                         path);
    }
    while (len < want + 1) {
        ssize_t got = read(fd, buf + len, want + 1 - len);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            int e = errno;
            free(buf);
            close(fd);
            return mfmm_fail(err, MFMM_ERR_IO, -1, "cannot read '%.180s': %.40s", path,
                             strerror(e));
        }
        if (got == 0)
            break;
        len += (size_t)got;
    }
    close(fd);
    if (len > want) {
        free(buf);
        return mfmm_fail(err, MFMM_ERR_IO, -1, "'%.180s' grew while being read", path);
    }
    buf[len] = '\0';
    *data = buf;
    *size = len;
    return MFMM_OK;
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

/* The extension of path's base name (after the last '.'), or NULL. */
static const char *extension(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    return dot && dot != base ? dot + 1 : NULL;
}

int mfmm_io_format_from_path(const char *path)
{
    static const char *const unsupported[] = {
        "gltf", "glb", "3ds", "fbx", "dae", "blend", "usd", "usda", "usdc", "usdz", "3mf",
        "amf", "x3d", "wrl", "vrml", "step", "stp", "iges", "igs", "ifc", "dxf", "lwo",
        "ma", "mb", "max", "c4d", "skp", "abc", "ase", "md2", "md3", "ms3d",
        "vtk", "vtu", "gz", "zip", "xz", "bz2", "zst"};
    const char *ext = path ? extension(path) : NULL;
    if (!ext)
        return MFMM_IO_FMT_UNKNOWN;
    if (ext_is(ext, "obj"))
        return MFMM_IO_FMT_OBJ;
    if (ext_is(ext, "off"))
        return MFMM_IO_FMT_OFF;
    if (ext_is(ext, "ply"))
        return MFMM_IO_FMT_PLY;
    if (ext_is(ext, "stl"))
        return MFMM_IO_FMT_STL;
    for (size_t i = 0; i < sizeof unsupported / sizeof unsupported[0]; i++)
        if (ext_is(ext, unsupported[i]))
            return MFMM_IO_FMT_UNSUPPORTED;
    return MFMM_IO_FMT_UNKNOWN;
}

static int is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

int mfmm_io_format_from_content(const char *data, size_t size)
{
    if (size >= 4 && memcmp(data, "ply", 3) == 0 && (data[3] == '\n' || data[3] == '\r'))
        return MFMM_IO_FMT_PLY;
    if (mfmm_io_stl_is_binary(data, size))
        return MFMM_IO_FMT_STL;
    if (size >= 4 && (memcmp(data, "glTF", 4) == 0 || memcmp(data, "PK\003\004", 4) == 0 ||
                      memcmp(data, "\037\213", 2) == 0))
        return MFMM_IO_FMT_UNSUPPORTED; /* binary glTF, zip, gzip */
    const char *p = data, *end = data + size;
    /* The first line that is not blank or a '#' comment. */
    for (;;) {
        while (p < end && is_blank(*p))
            p++;
        if (p < end && *p == '#') {
            while (p < end && *p != '\n')
                p++;
            continue;
        }
        break;
    }
    if (p >= end)
        return MFMM_IO_FMT_OBJ; /* empty: the OBJ parser says "no vertices" */
    /* OFF headers: OFF, COFF, NOFF, CNOFF, STOFF, 4OFF, ... */
    size_t i = 0, left = (size_t)(end - p);
    while (i < left && i < 8 && p[i] != 'O' && ((p[i] >= 'A' && p[i] <= 'Z') || p[i] == '4'))
        i++;
    if (i + 3 <= left && memcmp(p + i, "OFF", 3) == 0)
        return MFMM_IO_FMT_OFF;
    /* ascii STL: "solid" then "facet" or "endsolid" */
    if (left >= 6 && memcmp(p, "solid", 5) == 0 && is_blank(p[5]))
        return MFMM_IO_FMT_STL;
    /* OBJ: a statement keyword (letters) then a blank. */
    size_t k = 0;
    while (k < left && ((p[k] >= 'a' && p[k] <= 'z') || (p[k] >= 'A' && p[k] <= 'Z') ||
                        p[k] == '_'))
        k++;
    if (k > 0 && k < 16 && (k == left || is_blank(p[k])))
        return MFMM_IO_FMT_OBJ;
    return MFMM_IO_FMT_UNSUPPORTED;
}

mfmm_status mfmm_io_parse(const char *data, size_t size, int format, mfmm_io_result *out,
                          mfmm_error *err)
{
    if (format == MFMM_IO_FMT_UNKNOWN)
        format = mfmm_io_format_from_content(data, size);
    switch (format) {
    case MFMM_IO_FMT_OBJ:
        return mfmm_io_parse_obj(data, size, out, err);
    case MFMM_IO_FMT_OFF:
        return mfmm_io_parse_off(data, size, out, err);
    case MFMM_IO_FMT_PLY:
        return mfmm_io_parse_ply(data, size, out, err);
    case MFMM_IO_FMT_STL:
        return mfmm_io_parse_stl(data, size, out, err);
    default:
        return mfmm_fail(err, MFMM_ERR_PARSE, -1, "not a mesh format meshfmm reads; " FORMATS_READ);
    }
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
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    int fmt = mfmm_io_format_from_path(path);
    if (fmt == MFMM_IO_FMT_UNSUPPORTED)
        return mfmm_fail(err, MFMM_ERR_PARSE, -1, "%.60s: the .%.16s format is not supported; " FORMATS_READ,
                         base, extension(path));
    char *data = NULL;
    size_t size = 0;
    mfmm_status st = read_file(path, &data, &size, err);
    if (st != MFMM_OK)
        return st;
    mfmm_io_result r = {NULL, 0, NULL, 0};
    mfmm_error local;
    mfmm_error *e = err ? err : &local;
    st = mfmm_io_parse(data, size, fmt, &r, e);
    free(data);
    if (st != MFMM_OK) {
        /* Prefix the file name to the parser's sentence. */
        char msg[sizeof e->message];
        snprintf(msg, sizeof msg, "%s", e->message);
        mfmm_fail(err, st, e->index, "%.60s: %s", base, msg);
        return st;
    }
    *vertices = r.V;
    *nv = r.nv;
    *faces = r.F;
    *nf = r.nf;
    mfmm_ok(err);
    return MFMM_OK;
}
