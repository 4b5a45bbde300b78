/* Mesh readers: every shared mesh loads with its README counts; small
 * hand-written OBJ, OFF and PLY files give known coordinates and faces;
 * broken files fail with MFMM_ERR_PARSE or MFMM_ERR_IO and a message. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include <cmocka.h>

#include <errno.h>
#include <fcntl.h>
#include <locale.h>
#include <sys/stat.h>

#include "meshfmm.h"
#include "io/io.h"

typedef struct loaded {
    mfmm_status st;
    double *V;
    int32_t *F;
    int32_t nv, nf;
    mfmm_error err;
} loaded;

static loaded load(const char *path)
{
    loaded r;
    memset(&r, 0, sizeof r);
    r.V = (double *)1; /* must be reset by the reader */
    r.F = (int32_t *)1;
    r.st = mfmm_load_mesh(path, &r.V, &r.nv, &r.F, &r.nf, &r.err);
    return r;
}

static void unload(loaded *r)
{
    mfmm_free(r->V);
    mfmm_free(r->F);
    r->V = NULL;
    r->F = NULL;
}

/* A per-test temporary directory (state). */
static int make_dir(void **state)
{
    char *dir = malloc(64);
    if (!dir)
        return -1;
    snprintf(dir, 64, "/tmp/mfmm_test_io_XXXXXX");
    if (!mkdtemp(dir)) {
        free(dir);
        return -1;
    }
    *state = dir;
    return 0;
}

static int remove_dir(void **state)
{
    char *dir = *state;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    int rc = system(cmd);
    free(dir);
    return rc == 0 ? 0 : -1;
}

/* Writes len bytes to dir/name; the path goes to out. */
static void put(const char *dir, const char *name, const void *data, size_t len, char *out,
                size_t n)
{
    snprintf(out, n, "%s/%s", dir, name);
    FILE *f = fopen(out, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, len, f), len);
    assert_int_equal(fclose(f), 0);
}

static void put_str(const char *dir, const char *name, const char *text, char *out, size_t n)
{
    put(dir, name, text, strlen(text), out, n);
}

static void assert_vertex(const loaded *r, int32_t i, double x, double y, double z)
{
    assert_true(i < r->nv);
    assert_true(r->V[3 * i] == x && r->V[3 * i + 1] == y && r->V[3 * i + 2] == z);
}

static void assert_face(const loaded *r, int32_t i, int32_t a, int32_t b, int32_t c)
{
    assert_true(i < r->nf);
    if (!(r->F[3 * i] == a && r->F[3 * i + 1] == b && r->F[3 * i + 2] == c))
        fail_msg("face %d is (%d %d %d), want (%d %d %d)", (int)i, (int)r->F[3 * i],
                 (int)r->F[3 * i + 1], (int)r->F[3 * i + 2], (int)a, (int)b, (int)c);
}

/* ---------------------------------------------------------- real meshes */

static void test_shared_meshes(void **state)
{
    (void)state;
    static const struct {
        const char *name;
        int32_t nv, nf;
    } meshes[] = {
        {"hand_lowres.obj", 810, 1602},          {"beetle.obj", 1148, 2053},
        {"spot.obj", 2930, 5856},                {"wingnut.obj", 3047, 6090},
        {"fertility_FE_10k.off", 4994, 10000},   {"decimated-max.obj", 5272, 10540},
        {"camelhead.off", 11381, 22704},         {"nefertiti-lowres.obj", 35002, 70000},
        {"stanford-bunny.obj", 35947, 69451},    {"igea.ply", 134345, 268686},
    };
    for (size_t i = 0; i < sizeof meshes / sizeof meshes[0]; i++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/meshes/%s", MESHFMM_TEST_DATA_DIR, meshes[i].name);
        clock_t t0 = clock();
        loaded r = load(path);
        double secs = (double)(clock() - t0) / CLOCKS_PER_SEC;
        if (r.st != MFMM_OK)
            fail_msg("%s: %s", meshes[i].name, r.err.message);
        assert_int_equal(r.nv, meshes[i].nv);
        assert_int_equal(r.nf, meshes[i].nf);
        assert_int_equal(r.err.status, MFMM_OK);
        for (int64_t k = 0; k < 3 * (int64_t)r.nf; k++)
            assert_true(r.F[k] >= 0 && r.F[k] < r.nv);
        for (int64_t k = 0; k < 3 * (int64_t)r.nv; k++)
            assert_true(isfinite(r.V[k]));
        print_message("%-22s %6d V %6d F  %.3f s\n", meshes[i].name, (int)r.nv, (int)r.nf, secs);
        /* Readers must not be the bottleneck: a 3 MB file in well under 1 s
         * (a generous guard, also under sanitizers). */
        assert_true(secs < 5.0);
        unload(&r);
    }
}

static int cmp(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* Known first/last records of three files, read with another tool. */
static void test_shared_mesh_records(void **state)
{
    (void)state;
    char path[1024];
    snprintf(path, sizeof path, "%s/meshes/spot.obj", MESHFMM_TEST_DATA_DIR);
    loaded r = load(path);
    assert_int_equal(r.st, MFMM_OK);
    assert_vertex(&r, 0, 0.348799, -0.334989, -0.0832331);
    assert_face(&r, 0, 738, 734, 735); /* "f 739/1 735/2 736/3" */
    unload(&r);
    snprintf(path, sizeof path, "%s/meshes/camelhead.off", MESHFMM_TEST_DATA_DIR);
    r = load(path);
    assert_int_equal(r.st, MFMM_OK);
    assert_vertex(&r, 0, -0.105873, 0.121359, 0.0271172);
    assert_vertex(&r, 8, 6.14986e-005, -0.105286, 0.256351);
    assert_face(&r, 0, 691, 2839, 2841);
    unload(&r);
    snprintf(path, sizeof path, "%s/meshes/igea.ply", MESHFMM_TEST_DATA_DIR);
    r = load(path);
    assert_int_equal(r.st, MFMM_OK);
    assert_vertex(&r, 0, (double)0.008178f, (double)-0.049651f, (double)0.014658f);
    assert_face(&r, 0, 0, 1, 2);
    /* Closed and consistently oriented: each directed edge once, its
     * reverse once, so the decoded strip parity is right. Check by sorting. */
    int64_t ne = 3 * (int64_t)r.nf;
    int64_t *key = malloc((size_t)ne * sizeof *key);
    assert_non_null(key);
    for (int64_t f = 0; f < r.nf; f++)
        for (int k = 0; k < 3; k++)
            key[3 * f + k] = (int64_t)r.F[3 * f + k] * r.nv + r.F[3 * f + (k + 1) % 3];
    qsort(key, (size_t)ne, sizeof *key, cmp);
    for (int64_t i = 1; i < ne; i++)
        assert_true(key[i] != key[i - 1]);
    for (int64_t i = 0; i < ne; i++) {
        int64_t a = key[i] / r.nv, b = key[i] % r.nv, rev = b * r.nv + a;
        assert_non_null(bsearch(&rev, key, (size_t)ne, sizeof *key, cmp));
    }
    free(key);
    unload(&r);
}

/* ------------------------------------------------------------------ OBJ */

static void test_obj_small(void **state)
{
    char path[256];
    put_str(*state, "a.obj",
            "# comment\n#0 86\nmtllib x.mtl\no thing\ng group\nusemtl m\ns off\n"
            "v 0 0 0\nv 1.5 0 0\r\n  v\t1.5 2 0  # trailing comment\nv 0 2 -1e-3\n"
            "vt 0 0\nvt 1 0\nvn 0 0 1\n"
            "v 3 4 5 1.0\n" /* w ignored */
            "f 1/1/1 2/2/1 3//1\n"
            "f -4 -2 -1\n"          /* 1 3 4 relative to 4 vertices... see below */
            "f 1 2 3 4 5\n"         /* pentagon: 3 fan triangles */
            "l 1 2\n"
            "f 5/1 4/2 3/1\n",
            path, sizeof path);
    loaded r = load(path);
    if (r.st != MFMM_OK)
        fail_msg("%s", r.err.message);
    assert_int_equal(r.nv, 5);
    assert_int_equal(r.nf, 6);
    assert_vertex(&r, 0, 0, 0, 0);
    assert_vertex(&r, 2, 1.5, 2, 0);
    assert_vertex(&r, 3, 0, 2, -1e-3);
    assert_vertex(&r, 4, 3, 4, 5);
    assert_face(&r, 0, 0, 1, 2);
    assert_face(&r, 1, 1, 3, 4); /* 5 vertices so far: -4 = 2nd, -2 = 4th, -1 = 5th */
    assert_face(&r, 2, 0, 1, 2);
    assert_face(&r, 3, 0, 2, 3);
    assert_face(&r, 4, 0, 3, 4);
    assert_face(&r, 5, 4, 3, 2);
    unload(&r);
}

/* Relative indices count the vertices read so far, not the whole file. */
static void test_obj_relative_interleaved(void **state)
{
    char path[256];
    put_str(*state, "b.OBJ", /* upper-case extension */
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n"
            "v 1 1 0\nf -3 -1 -2\n",
            path, sizeof path);
    loaded r = load(path);
    assert_int_equal(r.st, MFMM_OK);
    assert_int_equal(r.nv, 4);
    assert_int_equal(r.nf, 2);
    assert_face(&r, 0, 0, 1, 2);
    assert_face(&r, 1, 1, 3, 2);
    unload(&r);
}

/* ------------------------------------------------------------------ OFF */

static void test_off_small(void **state)
{
    char path[256];
    put_str(*state, "a.off",
            "OFF\r\n# a comment\r\n5 3 0\r\n"
            "0 0 0 \r\n1 0 0\t\r\n1 1 0 \r\n\r\n0 1 0 # corner\r\n0.5 0.5 1e-1\r\n"
            "3 0 1 2\r\n4 0 2 3 4 255 0 0\r\n3 4 3 2\r\n",
            path, sizeof path);
    loaded r = load(path);
    if (r.st != MFMM_OK)
        fail_msg("%s", r.err.message);
    assert_int_equal(r.nv, 5);
    assert_int_equal(r.nf, 4);
    assert_vertex(&r, 3, 0, 1, 0);
    assert_vertex(&r, 4, 0.5, 0.5, 0.1);
    assert_face(&r, 0, 0, 1, 2);
    assert_face(&r, 1, 0, 2, 3);
    assert_face(&r, 2, 0, 3, 4);
    assert_face(&r, 3, 4, 3, 2);
    unload(&r);

    /* Counts on the header line; no edge count. */
    put_str(*state, "b.Off", "OFF 3 1\n0 0 0\n1 0 0\n0 1 0\n3 2 1 0", path, sizeof path);
    r = load(path);
    assert_int_equal(r.st, MFMM_OK);
    assert_int_equal(r.nv, 3);
    assert_face(&r, 0, 2, 1, 0);
    unload(&r);
}

/* ------------------------------------------------------------------ PLY */

typedef struct bytes {
    unsigned char b[4096];
    size_t n;
} bytes;

static void b_str(bytes *o, const char *s)
{
    size_t k = strlen(s);
    assert_true(o->n + k <= sizeof o->b);
    memcpy(o->b + o->n, s, k);
    o->n += k;
}

/* Appends the n-byte integer u in big- or little-endian order. */
static void b_uint(bytes *o, uint64_t u, int n, int big)
{
    assert_true(o->n + (size_t)n <= sizeof o->b);
    for (int i = 0; i < n; i++) {
        int shift = big ? 8 * (n - 1 - i) : 8 * i;
        o->b[o->n++] = (unsigned char)(u >> shift);
    }
}

static void b_f64(bytes *o, double x, int big)
{
    uint64_t u;
    memcpy(&u, &x, 8);
    b_uint(o, u, 8, big);
}

static void b_f32(bytes *o, float x, int big)
{
    uint32_t u;
    memcpy(&u, &x, 4);
    b_uint(o, u, 4, big);
}

static void test_ply_ascii(void **state)
{
    char path[256];
    put_str(*state, "a.ply",
            "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\nobj_info x\r\n"
            "element vertex 4\r\nproperty float nx\r\nproperty double x\r\nproperty float y\r\n"
            "property list uchar int extra\r\nproperty float z\r\nproperty uchar red\r\n"
            "element face 2\r\nproperty uchar flags\r\nproperty list uchar uint vertex_index\r\n"
            "property float quality\r\n"
            "element material 1\r\nproperty list int float values\r\n"
            "end_header\r\n"
            "9 0 0 2 1 2 0 255\r\n9 1 0 0 0 0\r\n9 1.25 1 1 7 -2.5 0\r\n9 0 1 0 0 0\r\n"
            "0 3 0 1 2 0.5\r\n1 4 0 2 1 3 0.5\r\n"
            "3 1 2 3\r\n",
            path, sizeof path);
    loaded r = load(path);
    if (r.st != MFMM_OK)
        fail_msg("%s", r.err.message);
    assert_int_equal(r.nv, 4);
    assert_int_equal(r.nf, 3);
    assert_vertex(&r, 2, 1.25, 1, -2.5);
    assert_face(&r, 0, 0, 1, 2);
    assert_face(&r, 1, 0, 2, 1);
    assert_face(&r, 2, 0, 1, 3);
    unload(&r);
}

static void test_ply_binary(void **state)
{
    for (int big = 0; big < 2; big++) {
        bytes o = {{0}, 0};
        b_str(&o, "ply\nformat ");
        b_str(&o, big ? "binary_big_endian" : "binary_little_endian");
        b_str(&o, " 1.0\nelement vertex 4\nproperty double x\nproperty short s\n"
                  "property double y\nproperty double z\nproperty list ushort char junk\n"
                  "element face 2\nproperty list short uint vertex_indices\n"
                  "property int16 tag\nend_header\n");
        const double xyz[4][3] = {{0, 0, 0}, {1, 0, 0}, {0.1, -1e300, 3}, {-0.0, 1, 2}};
        for (int v = 0; v < 4; v++) {
            b_f64(&o, xyz[v][0], big);
            b_uint(&o, 0xBEEF, 2, big);
            b_f64(&o, xyz[v][1], big);
            b_f64(&o, xyz[v][2], big);
            b_uint(&o, (uint64_t)v, 2, big); /* v junk bytes */
            for (int k = 0; k < v; k++)
                b_uint(&o, 0x80, 1, big);
        }
        b_uint(&o, 3, 2, big);
        b_uint(&o, 0, 4, big);
        b_uint(&o, 1, 4, big);
        b_uint(&o, 2, 4, big);
        b_uint(&o, 7, 2, big);
        b_uint(&o, 4, 2, big);
        b_uint(&o, 3, 4, big);
        b_uint(&o, 2, 4, big);
        b_uint(&o, 1, 4, big);
        b_uint(&o, 0, 4, big);
        b_uint(&o, 7, 2, big);
        char path[256];
        put(*state, big ? "be.ply" : "le.ply", o.b, o.n, path, sizeof path);
        loaded r = load(path);
        if (r.st != MFMM_OK)
            fail_msg("%s", r.err.message);
        assert_int_equal(r.nv, 4);
        assert_int_equal(r.nf, 3);
        for (int v = 0; v < 4; v++)
            assert_vertex(&r, v, xyz[v][0], xyz[v][1], xyz[v][2]);
        assert_face(&r, 0, 0, 1, 2);
        assert_face(&r, 1, 3, 2, 1);
        assert_face(&r, 2, 3, 1, 0);
        unload(&r);
    }
}

/* Tristrips: (s[i], s[i+1], s[i+2]) for even i, (s[i+1], s[i], s[i+2]) for
 * odd i, parity restarting after each -1; repeated-index triangles skipped. */
static void test_ply_tristrips(void **state)
{
    bytes o = {{0}, 0};
    b_str(&o, "ply\nformat binary_big_endian 1.0\nelement vertex 9\n"
              "property float x\nproperty float y\nproperty float z\n"
              "element tristrips 1\nproperty list int int vertex_indices\nend_header\n");
    for (int v = 0; v < 9; v++) {
        b_f32(&o, (float)v, 1);
        b_f32(&o, (float)(v % 2), 1);
        b_f32(&o, 0.5f, 1);
    }
    const int32_t s[] = {0, 1, 2, 3, 4, -1, 5, 6, 7, 7, 8, -1, 2, 3};
    b_uint(&o, sizeof s / sizeof s[0], 4, 1);
    for (size_t i = 0; i < sizeof s / sizeof s[0]; i++)
        b_uint(&o, (uint32_t)s[i], 4, 1);
    char path[256];
    put(*state, "strips.ply", o.b, o.n, path, sizeof path);
    loaded r = load(path);
    if (r.st != MFMM_OK)
        fail_msg("%s", r.err.message);
    assert_int_equal(r.nv, 9);
    assert_vertex(&r, 3, 3, 1, 0.5);
    /* strip 0 1 2 3 4: (0 1 2) (2 1 3) (2 3 4); strip 5 6 7 7 8: (5 6 7),
     * (7 6 7) skipped, (7 7 8) skipped; (7 7 8) odd ... skipped; strip 2 3: none. */
    assert_int_equal(r.nf, 4);
    assert_face(&r, 0, 0, 1, 2);
    assert_face(&r, 1, 2, 1, 3);
    assert_face(&r, 2, 2, 3, 4);
    assert_face(&r, 3, 5, 6, 7);
    unload(&r);

    /* The same strips in ascii, with a fourth strip 6 7 8 5 after i = 2 parity. */
    put_str(*state, "strips_ascii.ply",
            "ply\nformat ascii 1.0\nelement vertex 9\nproperty float x\nproperty float y\n"
            "property float z\nelement tristrips 2\nproperty list int int vertex_indices\n"
            "end_header\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 2 0\n1 2 0\n0 3 0\n1 3 0\n0 4 0\n"
            "5 0 1 2 3 4\n4 6 7 8 5\n",
            path, sizeof path);
    r = load(path);
    if (r.st != MFMM_OK)
        fail_msg("%s", r.err.message);
    assert_int_equal(r.nf, 5);
    assert_face(&r, 1, 2, 1, 3);
    assert_face(&r, 3, 6, 7, 8);
    assert_face(&r, 4, 8, 7, 5); /* odd: (s[2], s[1], s[3]) */
    unload(&r);
}

/* Unknown extensions are recognised from the content. */
static void test_sniff(void **state)
{
    char path[256];
    put_str(*state, "x.mesh", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", path, sizeof path);
    loaded r = load(path);
    assert_int_equal(r.st, MFMM_OK);
    assert_int_equal(r.nf, 1);
    unload(&r);
    put_str(*state, "noext", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", path, sizeof path);
    r = load(path);
    assert_int_equal(r.st, MFMM_OK);
    assert_int_equal(r.nf, 1);
    unload(&r);
    put_str(*state, "x.dat",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
            "end_header\n0 0 0\n1 0 0\n0 1 0\n3 2 1 0\n",
            path, sizeof path);
    r = load(path);
    assert_int_equal(r.st, MFMM_OK);
    assert_face(&r, 0, 2, 1, 0);
    unload(&r);
}

/* ---------------------------------------------------------- broken files */

typedef struct broken {
    const char *name;
    const char *text; /* NULL: use bin */
    mfmm_status want;
    const char *in_message; /* a substring the message must contain, or NULL */
} broken;

static void check_broken(const char *dir, const char *name, const void *data, size_t len,
                         mfmm_status want, const char *in_message)
{
    char path[256];
    put(dir, name, data, len, path, sizeof path);
    clock_t t0 = clock();
    loaded r = load(path);
    double secs = (double)(clock() - t0) / CLOCKS_PER_SEC;
    if (r.st != want)
        fail_msg("%s: status %d (%s), want %d", name, (int)r.st, r.err.message, (int)want);
    assert_int_equal(r.err.status, want);
    assert_null(r.V);
    assert_null(r.F);
    assert_int_equal(r.nv, 0);
    assert_int_equal(r.nf, 0);
    assert_true(strlen(r.err.message) > 0);
    if (in_message && !strstr(r.err.message, in_message))
        fail_msg("%s: message '%s' lacks '%s'", name, r.err.message, in_message);
    assert_true(secs < 1.0); /* fails fast */
}

static void test_broken_text(void **state)
{
    static const broken cases[] = {
        {"empty.obj", "", MFMM_ERR_PARSE, "no vertices"},
        {"empty.off", "", MFMM_ERR_PARSE, "OFF"},
        {"empty.ply", "", MFMM_ERR_PARSE, "line 1"},
        {"comments.obj", "# nothing\n\n", MFMM_ERR_PARSE, "no vertices"},
        {"nofaces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", MFMM_ERR_PARSE, "no faces"},
        {"garbage.obj", "\x7f\x45\x4c\x46\x02\x01\x01\n\x03\x00", MFMM_ERR_PARSE, "line 1"},
        {"garbage.off", "hello world\n", MFMM_ERR_PARSE, "line 1"},
        {"garbage.ply", "ply\nformat ascii 1.0\nbanana\nend_header\n", MFMM_ERR_PARSE,
         "line 3"},
        {"short_v.obj", "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n", MFMM_ERR_PARSE, "line 2"},
        {"junk_v.obj", "v 0 0 0\nv 1 0 0x\nv 0 1 0\nf 1 2 3\n", MFMM_ERR_PARSE, "line 2"},
        {"nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n", MFMM_ERR_PARSE, "line 3"},
        {"inf.obj", "v 0 0 0\nv 1 0 0\nv 0 1e999 0\nf 1 2 3\n", MFMM_ERR_PARSE, "line 3"},
        {"range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", MFMM_ERR_PARSE, "line 4"},
        {"zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", MFMM_ERR_PARSE, "line 4"},
        {"relrange.obj", "v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n", MFMM_ERR_PARSE, "line 3"},
        {"huge_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n",
         MFMM_ERR_PARSE, "line 4"},
        {"twovert.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", MFMM_ERR_PARSE, "line 4"},
        {"slash.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/ 2/x 3\n", MFMM_ERR_PARSE, "line 4"},
        {"nocounts.off", "OFF\n", MFMM_ERR_PARSE, "counts"},
        {"truncated.off",
         "OFF\n4 2 0\n0.0 0.0 0.0\n1.0 0.0 0.0\n0.0 1.0 0.0\n1.0 1.0 0.0\n3 0 1 2\n3 0 1",
         MFMM_ERR_PARSE, "face 1"},
        {"truncated2.off",
         "OFF\n4 2 0\n0.0 0.0 0.0\n1.0 0.0 0.0\n0.0 1.0 0.0\n1.0 1.0 0.0\n3 0 1 2\n",
         MFMM_ERR_PARSE, NULL},
        {"truncated_v.off", "OFF\n4 1 0\n0.00 0.00 0.00\n1.00 0.00 0.00\n0.00 1",
         MFMM_ERR_PARSE, "vertex 2"},
        {"lie_more_v.off", "OFF\n4 1 0\n0.0 0.0 0.0\n1.0 0.0 0.0\n0.0 1.0 0.0\n3 0 1 2\n",
         MFMM_ERR_PARSE, "face 0"},
        {"lie_more_v_short.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
         MFMM_ERR_PARSE, "bytes"},
        {"lie_fewer_v.off", "OFF\n2 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", MFMM_ERR_PARSE, NULL},
        {"lie_fewer_f.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 2 1 0\n",
         MFMM_ERR_PARSE, "line 7"},
        {"huge.off", "OFF\n2147483647 2147483647 0\n0 0 0\n", MFMM_ERR_PARSE, "bytes"},
        {"toolarge.off", "OFF\n99999999999 1 0\n0 0 0\n", MFMM_ERR_PARSE, "counts"},
        {"negative.off", "OFF\n-3 1 0\n0 0 0\n", MFMM_ERR_PARSE, "counts"},
        {"nan.off", "OFF\n3 1 0\n0 0 0\n1 NaN 0\n0 1 0\n3 0 1 2\n", MFMM_ERR_PARSE, "vertex 1"},
        {"range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", MFMM_ERR_PARSE, "face 0"},
        {"negidx.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", MFMM_ERR_PARSE, "face 0"},
        {"bigk.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2000000000 0 1 2\n", MFMM_ERR_PARSE,
         "face 0"},
        {"twoface.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", MFMM_ERR_PARSE, "face 0"},
        {"binary.off", "OFF BINARY\n", MFMM_ERR_PARSE, "binary"},
        {"noend.ply", "ply\nformat ascii 1.0\nelement vertex 3\n", MFMM_ERR_PARSE,
         "end_header"},
        {"noformat.ply", "ply\nelement vertex 0\nend_header\n", MFMM_ERR_PARSE, "format"},
        {"huge.ply",
         "ply\nformat binary_little_endian 1.0\nelement vertex 2147483648\nproperty float x\n"
         "property float y\nproperty float z\nelement face 1\n"
         "property list uchar int vertex_indices\nend_header\n",
         MFMM_ERR_PARSE, "bytes"},
        {"hugeface.ply",
         "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\nelement face 4000000000\nproperty list uchar int vertex_indices\n"
         "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
         MFMM_ERR_PARSE, "bytes"},
        {"noxyz.ply",
         "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
         "0 0\n1 0\n0 1\n3 0 1 2\n",
         MFMM_ERR_PARSE, "x, y or z"},
        {"nofaces.ply",
         "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n",
         MFMM_ERR_PARSE, "face"},
        {"range.ply",
         "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
         "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
         MFMM_ERR_PARSE, "face 0"},
        {"nan.ply",
         "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
         "end_header\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n",
         MFMM_ERR_PARSE, "vertex 1"},
        {"trunc.ply",
         "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
         "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0",
         MFMM_ERR_PARSE, "face 1"},
        {"extra.ply",
         "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
         "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 2 1 0\n",
         MFMM_ERR_PARSE, "after the last element"},
        {"floatidx.ply",
         "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\nelement face 1\nproperty list uchar float vertex_indices\n"
         "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
         MFMM_ERR_PARSE, "integers"},
        {"badtype.ply",
         "ply\nformat ascii 1.0\nelement vertex 3\nproperty quad x\nend_header\n",
         MFMM_ERR_PARSE, "line 4"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        check_broken(*state, cases[i].name, cases[i].text, strlen(cases[i].text),
                     cases[i].want, cases[i].in_message);
    /* A NUL byte inside a text file. */
    static const char nul[] = "v 0 0 0\nv 1 0 0\nv 0 1\0 0\nf 1 2 3\n";
    check_broken(*state, "nul.obj", nul, sizeof nul - 1, MFMM_ERR_PARSE, "line 3");
    check_broken(*state, "nul.off", "OFF\n3 1 0\n0\0 0 0\n", 16, MFMM_ERR_PARSE, "NUL");
}

static void test_broken_binary_ply(void **state)
{
    const char *head = "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
                       "property float x\nproperty float y\nproperty float z\n"
                       "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    bytes good = {{0}, 0};
    b_str(&good, head);
    for (int v = 0; v < 9; v++)
        b_f32(&good, (float)(v == 3 || v == 7), 0);
    b_uint(&good, 3, 1, 0);
    for (int k = 0; k < 3; k++)
        b_uint(&good, (uint64_t)k, 4, 0);
    char path[256];
    put(*state, "good.ply", good.b, good.n, path, sizeof path);
    loaded r = load(path);
    assert_int_equal(r.st, MFMM_OK);
    assert_int_equal(r.nf, 1);
    unload(&r);

    /* Every truncation fails (the header itself or the body). */
    for (size_t n = 0; n < good.n; n++)
        check_broken(*state, "cut.ply", good.b, n, MFMM_ERR_PARSE, NULL);
    /* One trailing byte. */
    bytes more = good;
    b_uint(&more, 0, 1, 0);
    check_broken(*state, "more.ply", more.b, more.n, MFMM_ERR_PARSE, "after the last");
    /* A NaN coordinate. */
    bytes nan = good;
    size_t body = strlen(head);
    float qnan = NAN;
    memcpy(nan.b + body + 4 * 4, &qnan, 4); /* vertex 1, y */
    check_broken(*state, "nan.ply", nan.b, nan.n, MFMM_ERR_PARSE, "vertex 1");
    /* An index out of range, and a negative one. */
    bytes idx = good;
    idx.b[idx.n - 4] = 3;
    check_broken(*state, "idx.ply", idx.b, idx.n, MFMM_ERR_PARSE, "face 0");
    idx.b[idx.n - 4] = 0xff;
    idx.b[idx.n - 1] = 0xff;
    check_broken(*state, "negidx.ply", idx.b, idx.n, MFMM_ERR_PARSE, "face 0");
    /* A list count of 255 in a file too short for it. */
    bytes cnt = good;
    cnt.b[body + 36] = 255;
    check_broken(*state, "count.ply", cnt.b, cnt.n, MFMM_ERR_PARSE, "face 0");
    /* An int list count of 2^31-1. */
    bytes big = {{0}, 0};
    b_str(&big, "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\n"
                "property float y\nproperty float z\nelement face 1\n"
                "property list int int vertex_indices\nend_header\n");
    for (int v = 0; v < 9; v++)
        b_f32(&big, (float)v, 1);
    b_uint(&big, 0x7fffffff, 4, 1);
    b_uint(&big, 0, 4, 1);
    check_broken(*state, "bigcount.ply", big.b, big.n, MFMM_ERR_PARSE, "face 0");
    /* Random bytes after a valid header. */
    bytes junk = {{0}, 0};
    b_str(&junk, head);
    unsigned seed = 7;
    for (int i = 0; i < 200; i++) {
        seed = seed * 1103515245u + 12345u;
        b_uint(&junk, (seed >> 16) & 0xff, 1, 0);
    }
    check_broken(*state, "junk.ply", junk.b, junk.n, MFMM_ERR_PARSE, NULL);
}

/* Every prefix of the shared OBJ and OFF headers and random corruptions
 * of a small file: a status, never a crash (meaningful under ASan). */
static void test_fuzz_small(void **state)
{
    const char *src = "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n4 1 3 2 0\n";
    const char *obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf -3 -1/2 3//1\n";
    const char *names[2] = {"f.off", "f.obj"};
    const char *texts[2] = {src, obj};
    unsigned seed = 99;
    for (int t = 0; t < 2; t++) {
        size_t n = strlen(texts[t]);
        char buf[128];
        for (int round = 0; round < 300; round++) {
            memcpy(buf, texts[t], n);
            for (int k = 0; k < 1 + round % 3; k++) {
                seed = seed * 1103515245u + 12345u;
                size_t at = (seed >> 8) % n;
                seed = seed * 1103515245u + 12345u;
                buf[at] = "0123456789 -+.e\n#/x\r"[(seed >> 8) % 20];
            }
            seed = seed * 1103515245u + 12345u;
            size_t len = round % 2 ? n : (seed >> 8) % (n + 1);
            char path[256];
            put(*state, names[t], buf, len, path, sizeof path);
            loaded r = load(path);
            assert_true(r.st == MFMM_OK || r.st == MFMM_ERR_PARSE);
            if (r.st == MFMM_OK) {
                for (int64_t k = 0; k < 3 * (int64_t)r.nf; k++)
                    assert_true(r.F[k] >= 0 && r.F[k] < r.nv);
                for (int64_t k = 0; k < 3 * (int64_t)r.nv; k++)
                    assert_true(isfinite(r.V[k]));
            } else {
                assert_null(r.V);
                assert_true(strlen(r.err.message) > 0);
            }
            unload(&r);
        }
    }
}

static void test_io_errors(void **state)
{
    char path[256];
    snprintf(path, sizeof path, "%s/does-not-exist.obj", (char *)*state);
    loaded r = load(path);
    assert_int_equal(r.st, MFMM_ERR_IO);
    assert_non_null(strstr(r.err.message, "does-not-exist.obj"));
    assert_null(r.V);
    r = load((char *)*state); /* a directory */
    assert_int_equal(r.st, MFMM_ERR_IO);
    assert_null(r.V);

    double *V;
    int32_t *F, nv, nf;
    assert_int_equal(mfmm_load_mesh(NULL, &V, &nv, &F, &nf, NULL), MFMM_ERR_NULL_POINTER);
    assert_int_equal(mfmm_load_mesh(path, NULL, &nv, &F, &nf, NULL), MFMM_ERR_NULL_POINTER);
    /* err may be NULL. */
    put_str(*state, "ok.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", path, sizeof path);
    assert_int_equal(mfmm_load_mesh(path, &V, &nv, &F, &nf, NULL), MFMM_OK);
    mfmm_free(V);
    mfmm_free(F);
    put_str(*state, "bad.obj", "v 0 0 0\n", path, sizeof path);
    assert_int_equal(mfmm_load_mesh(path, &V, &nv, &F, &nf, NULL), MFMM_ERR_PARSE);
}


/* ------------------------------------------------------------------ STL */

static void put_le32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

/* A binary STL of the unit square (two facets) in buf; its size. */
static size_t binary_square(unsigned char *buf, const char *header)
{
    static const float corners[2][9] = {{0, 0, 0, 1, 0, 0, 1, 1, 0}, {0, 0, 0, 1, 1, 0, -0.0f, 1, 0}};
    memset(buf, 0, 84 + 100);
    memcpy(buf, header, strlen(header));
    put_le32(buf + 80, 2);
    for (int f = 0; f < 2; f++)
        for (int k = 0; k < 9; k++) {
            uint32_t u;
            memcpy(&u, &corners[f][k], 4);
            put_le32(buf + 84 + 50 * f + 12 + 4 * k, u);
        }
    return 84 + 100;
}

static void check_square(const loaded *r)
{
    assert_int_equal(r->st, MFMM_OK);
    assert_int_equal(r->nv, 4); /* welded by position, -0 == +0 */
    assert_int_equal(r->nf, 2);
    assert_vertex(r, 0, 0, 0, 0);
    assert_vertex(r, 1, 1, 0, 0);
    assert_vertex(r, 2, 1, 1, 0);
    assert_vertex(r, 3, 0, 1, 0);
    assert_face(r, 0, 0, 1, 2);
    assert_face(r, 1, 0, 2, 3);
}

static void test_stl(void **state)
{
    char path[256];
    unsigned char bin[184];
    size_t n = binary_square(bin, "binary square");
    put(*state, "sq.stl", bin, n, path, sizeof path);
    loaded r = load(path);
    check_square(&r);
    unload(&r);
    /* A binary header starting with "solid": the size formula decides. */
    n = binary_square(bin, "solid but binary");
    put(*state, "sq2.STL", bin, n, path, sizeof path);
    r = load(path);
    check_square(&r);
    unload(&r);
    /* Sniffed without an extension. */
    put(*state, "sq_noext", bin, n, path, sizeof path);
    r = load(path);
    check_square(&r);
    unload(&r);
    /* Truncated binary: neither binary nor ascii, a clear message. */
    put(*state, "cut.stl", bin, n - 7, path, sizeof path);
    r = load(path);
    assert_int_equal(r.st, MFMM_ERR_PARSE);
    assert_non_null(strstr(r.err.message, "84 + 50 n"));
    assert_null(r.V);

    const char *ascii =
        "solid square\n"
        "  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n"
        "      vertex 1 1 0\n    endloop\n  endfacet\n"
        "  FACET NORMAL 0 0 1\n    OUTER LOOP\n      VERTEX 0.0 0.0 0.0\n      VERTEX 1e0 1 0\n"
        "      VERTEX -0 1.0 0\n    ENDLOOP\n  ENDFACET\n"
        "  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n"
        "      vertex 0 0 0\n    endloop\n  endfacet\n" /* degenerate: dropped */
        "endsolid square\n";
    put_str(*state, "a.stl", ascii, path, sizeof path);
    r = load(path);
    check_square(&r);
    unload(&r);
    put_str(*state, "a.txt", ascii, path, sizeof path); /* sniffed */
    r = load(path);
    check_square(&r);
    unload(&r);
    /* A quad loop is fan-triangulated. */
    put_str(*state, "q.stl",
            "solid q\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\n"
            "vertex 0 1 0\nendloop\nendfacet\nendsolid q\n",
            path, sizeof path);
    r = load(path);
    check_square(&r);
    unload(&r);
    static const struct {
        const char *name, *text, *msg;
    } bad[] = {
        {"b1.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0\nendloop\n", "three numbers"},
        {"b2.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\n",
         "at least three"},
        {"b3.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 nan 0\n"
                   "endloop\nendfacet\n", "NaN"},
        {"b4.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n", "end of"},
        {"b5.stl", "solid x\nendsolid x\n", "no facets"},
        {"b6.stl", "hello\n", "solid"},
        {"b7.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                   "endloop\nbogus\n", "bogus"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        check_broken(*state, bad[i].name, bad[i].text, strlen(bad[i].text), MFMM_ERR_PARSE,
                     bad[i].msg);
}

/* Unsupported formats get one sentence naming the formats read. */
static void test_unsupported(void **state)
{
    const char *names[] = {"m.gltf", "m.glb", "m.3ds", "m.FBX", "m.dae"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        check_broken(*state, names[i], "{\"asset\": {}}", 13, MFMM_ERR_PARSE,
                     "OBJ, OFF, PLY (ascii and binary) and STL");
    unsigned char glb[40] = "glTF\002\000\000\000";
    check_broken(*state, "m.bin", glb, sizeof glb, MFMM_ERR_PARSE, "meshfmm reads OBJ");
    check_broken(*state, "m.unknown", "\001\002\003 garbage", 12, MFMM_ERR_PARSE,
                 "meshfmm reads OBJ");
}

/* /dev/zero, a FIFO with no writer and a directory are refused at once,
 * naming the path and what it is. */
static void test_not_regular(void **state)
{
    loaded r = load("/dev/zero");
    assert_int_equal(r.st, MFMM_ERR_IO);
    assert_non_null(strstr(r.err.message, "/dev/zero"));
    assert_non_null(strstr(r.err.message, "character device"));
    assert_null(r.V);
    r = load(*state);
    assert_int_equal(r.st, MFMM_ERR_IO);
    assert_non_null(strstr(r.err.message, "directory"));
    char fifo[256];
    snprintf(fifo, sizeof fifo, "%s/pipe.obj", (char *)*state);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    time_t t0 = time(NULL);
    r = load(fifo); /* blocked forever before the fix */
    assert_true(time(NULL) - t0 < 5);
    assert_int_equal(r.st, MFMM_ERR_IO);
    assert_non_null(strstr(r.err.message, "FIFO"));
    assert_non_null(strstr(r.err.message, "pipe.obj"));
}

/* ------------------------------------------------ numbers without locale */

/* Bits equal. */
static void assert_same_double(double a, double b, const char *text)
{
    if (memcmp(&a, &b, sizeof a) != 0)
        fail_msg("'%s': %.17g, want %.17g", text, a, b);
}

/* mfmm_io_strtod is correctly rounded: compared with glibc's strtod in the C
 * locale (this test runs before any setlocale) on hard cases and random
 * text. */
static void test_strtod(void **state)
{
    (void)state;
    static const char *cases[] = {
        "0", "-0", "1", "0.1", "1e23", "9007199254740993", "9007199254740992.5",
        "2.2250738585072011e-308", "2.2250738585072012e-308", "4.9406564584124654e-324",
        "2.4703282292062327e-324", "2.4703282292062328e-324", "1.7976931348623157e308",
        "1.7976931348623158e308", "1.7976931348623159e308", "1e-400", "1e400", "-.5e-3", "3.",
        "0.12345678901234567", "123456789012345678901234567890e-10", "7.2057594037927933e16",
        "8.98846567431158e307", "1.00000000000000011102230246251565404236316680908203125",
        "1.00000000000000011102230246251565404236316680908203124",
        "1.00000000000000011102230246251565404236316680908203126"};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *end;
        char *want_end;
        double got, want = strtod(cases[i], &want_end);
        assert_int_equal(mfmm_io_strtod(cases[i], &end, &got), 1);
        assert_same_double(got, want, cases[i]);
        assert_ptr_equal(end, want_end);
    }
    unsigned long long x = 88172645463325252ull;
    char buf[128];
    for (int it = 0; it < 100000; it++) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        double d;
        memcpy(&d, &x, sizeof d);
        if (!isfinite(d))
            continue;
        snprintf(buf, sizeof buf, "%.*g", (int)(x % 19) + 1, d);
        const char *end;
        double got, want = strtod(buf, NULL);
        assert_int_equal(mfmm_io_strtod(buf, &end, &got), 1);
        assert_same_double(got, want, buf);
        assert_true(*end == '\0');
    }
    const char *end;
    double v;
    assert_int_equal(mfmm_io_strtod("inf", &end, &v), 1);
    assert_true(isinf(v) && *end == '\0');
    assert_int_equal(mfmm_io_strtod("-Infinity", &end, &v), 1);
    assert_true(isinf(v) && v < 0 && *end == '\0');
    assert_int_equal(mfmm_io_strtod("nan(0x1)", &end, &v), 1);
    assert_true(isnan(v));
    assert_int_equal(mfmm_io_strtod("1,5", &end, &v), 1); /* stops at the comma */
    assert_true(v == 1.0 && *end == ',');
    assert_int_equal(mfmm_io_strtod("1e+", &end, &v), 1);
    assert_true(v == 1.0 && *end == 'e');
    assert_int_equal(mfmm_io_strtod(".", &end, &v), 0);
    assert_int_equal(mfmm_io_strtod("-", &end, &v), 0);
    assert_int_equal(mfmm_io_strtod("x", &end, &v), 0);
}

/* Sets a decimal-comma locale: de_DE.UTF-8 if installed, else one built
 * by localedef into dir (LOCPATH). 1 on success. */
static int set_comma_locale(const char *dir)
{
    if (setlocale(LC_ALL, "de_DE.UTF-8"))
        return 1;
    char cmd[512];
    snprintf(cmd, sizeof cmd,
             "localedef -i de_DE -f UTF-8 '%s/de_DE.UTF-8' >/dev/null 2>&1", dir);
    int rc = system(cmd); /* localedef may warn and exit 1 yet write the locale */
    (void)rc;
    setenv("LOCPATH", dir, 1);
    if (setlocale(LC_ALL, "de_DE.UTF-8"))
        return 1;
    unsetenv("LOCPATH");
    return 0;
}

/* Under a decimal-comma locale the text readers read '.'
 * numbers and the .txt writers' formatter writes '.'. */
static void test_comma_locale(void **state)
{
    if (!set_comma_locale(*state)) {
        printf("SKIPPED: no de_DE.UTF-8 locale and localedef cannot make one "
               "(install the Debian package 'locales')\n");
        skip();
        return;
    }
    char *e;
    double comma = strtod("1,5", &e);
    int is_comma = comma == 1.5 && *e == '\0';
    char path[256];
    const char *obj = "v 0.5 0 0\nv 1.25 0 0\nv 0 1e-1 0.75\nf 1 2 3\n";
    put_str(*state, "l.obj", obj, path, sizeof path);
    loaded r = load(path);
    if (r.st != MFMM_OK)
        fail_msg("OBJ under de_DE: %s", r.err.message);
    assert_vertex(&r, 0, 0.5, 0, 0);
    assert_vertex(&r, 1, 1.25, 0, 0);
    assert_vertex(&r, 2, 0, 0.1, 0.75);
    unload(&r);
    put_str(*state, "l.off", "OFF\n3 1 0\n0.5 0 0\n1.25 0 0\n0 1e-1 0.75\n3 0 1 2\n", path,
            sizeof path);
    r = load(path);
    if (r.st != MFMM_OK)
        fail_msg("OFF under de_DE: %s", r.err.message);
    assert_vertex(&r, 2, 0, 0.1, 0.75);
    unload(&r);
    put_str(*state, "l.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property double z\nelement face 1\nproperty list uchar int vertex_indices\n"
            "end_header\n0.5 0 0\n1.25 0 0\n0 0.1 0.75\n3 0 1 2\n",
            path, sizeof path);
    r = load(path);
    if (r.st != MFMM_OK)
        fail_msg("PLY under de_DE: %s", r.err.message);
    assert_vertex(&r, 0, 0.5, 0, 0);
    assert_vertex(&r, 2, 0, 0.1, 0.75);
    unload(&r);
    put_str(*state, "l.stl",
            "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0.5 0 0\nvertex 1.25 0 0\n"
            "vertex 0 0.1 0.75\nendloop\nendfacet\nendsolid s\n",
            path, sizeof path);
    r = load(path);
    if (r.st != MFMM_OK)
        fail_msg("STL under de_DE: %s", r.err.message);
    assert_vertex(&r, 2, 0, 0.1, 0.75);
    unload(&r);
    /* The .txt writers' formatter. */
    char buf[40];
    assert_true(mfmm_io_format_double(buf, sizeof buf, 0.5) > 0);
    assert_string_equal(buf, "0.5");
    assert_true(mfmm_io_format_double(buf, sizeof buf, -1.0 / 3.0) > 0);
    assert_string_equal(buf, "-0.33333333333333331");
    assert_true(mfmm_io_format_double(buf, sizeof buf, 0.1) > 0);
    assert_string_equal(buf, "0.10000000000000001");
    assert_true(mfmm_io_format_double(buf, sizeof buf, 1.5e-300) > 0);
    assert_string_equal(buf, "1.5000000000000001e-300");
    assert_true(mfmm_io_format_double(buf, sizeof buf, 2.0) > 0);
    assert_string_equal(buf, "2");
    assert_int_equal(mfmm_io_format_double(buf, 3, 0.5), -1);
    setlocale(LC_ALL, "C");
    unsetenv("LOCPATH");
    assert_true(is_comma); /* the locale really had a decimal comma */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shared_meshes),
        cmocka_unit_test(test_shared_mesh_records),
        cmocka_unit_test_setup_teardown(test_obj_small, make_dir, remove_dir),
        cmocka_unit_test_setup_teardown(test_obj_relative_interleaved, make_dir, remove_dir),
        cmocka_unit_test_setup_teardown(test_off_small, make_dir, remove_dir),
        cmocka_unit_test_setup_teardown(test_ply_ascii, make_dir, remove_dir),
        cmocka_unit_test_setup_teardown(test_ply_binary, make_dir, remove_dir),
        cmocka_unit_test_setup_teardown(test_ply_tristrips, make_dir, remove_dir),
        cmocka_unit_test_setup_teardown(test_sniff, make_dir, remove_dir),
        cmocka_unit_test_setup_teardown(test_broken_text, make_dir, remove_dir),
        cmocka_unit_test_setup_teardown(test_broken_binary_ply, make_dir, remove_dir),
        cmocka_unit_test_setup_teardown(test_fuzz_small, make_dir, remove_dir),
        cmocka_unit_test_setup_teardown(test_io_errors, make_dir, remove_dir),
        cmocka_unit_test_setup_teardown(test_stl, make_dir, remove_dir),
        cmocka_unit_test_setup_teardown(test_unsupported, make_dir, remove_dir),
        cmocka_unit_test_setup_teardown(test_not_regular, make_dir, remove_dir),
        cmocka_unit_test(test_strtod),
        cmocka_unit_test_setup_teardown(test_comma_locale, make_dir, remove_dir),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
