/* meshfmm allpairs MESH -o OUT.npy: the distance matrix, streamed in blocks
 * of rows into a .npy file (OUT.npy.partial, renamed when complete). */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"

#define EXIT_INTERRUPTED 130

static volatile sig_atomic_t interrupted = 0;

static void on_signal(int sig)
{
    (void)sig;
    interrupted = 1;
}

static void help(FILE *out)
{
    fprintf(out,
            "usage: meshfmm allpairs MESH -o OUT.npy [--dtype float32|float64]\n"
            "                        [--backend auto|opencl|serial|threads] [--sources FILE]\n"
            "                        [--max-distance X] [--threads N] [--memory MB] [--quiet]\n\n"
            "The geodesic distance matrix: one row per source (default every vertex), one\n"
            "column per vertex, streamed into a .npy file block by block (the matrix is\n"
            "never held in memory). The file appears under its name only when complete.\n\n"
            "  -o OUT.npy          output; written as OUT.npy.partial, then renamed\n"
            "  --dtype T           float32 (default) or float64; arithmetic is float64\n"
            "  --backend B         auto (default: OpenCL if a device works, else threads),\n"
            "                      opencl, serial (one thread) or threads\n"
            "  --sources FILE      source vertex ids: .txt (whitespace separated) or .npy\n"
            "                      (1-D integer array)\n"
            "  --max-distance X    stop each row past X; farther vertices get inf\n"
            "  --threads N         threads for the threads backend (default: all cores)\n"
            "  --memory MB         memory for workspaces and blocks in flight\n"
            "  --quiet             no progress lines\n\n"
            "Environment: MESHFMM_OPENCL_DEVICE (device index or name substring),\n"
            "MESHFMM_CACHE_DIR (OpenCL program cache, default ~/.cache/meshfmm).\n"
            "SIGINT/SIGTERM stop the run, remove the partial file and exit with 130.\n");
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* ---- --sources FILE ---- */

static int read_sources(const char *path, int32_t **ids, int64_t *n)
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

/* ---- the run ---- */

typedef struct run_state {
    cli_npy_writer w;
    int32_t base;    /* rows already written by an earlier call (fallback) */
    int32_t total;
    int32_t done;
    int write_failed;
    int quiet, tty;
    double t0, last;
} run_state;

static void progress(run_state *s, int final)
{
    double t = now(), el = t - s->t0;
    if (s->quiet || (!final && t - s->last < (s->tty ? 0.25 : 2.0)))
        return;
    s->last = t;
    double rate = el > 0 ? s->done / el : 0.0;
    double left = rate > 0 ? (s->total - s->done) / rate : 0.0;
    fprintf(stderr, "%srows %d/%d (%.1f%%), %.1f rows/s, %.0f s left%s", s->tty ? "\r" : "",
            (int)s->done, (int)s->total, 100.0 * s->done / (s->total ? s->total : 1), rate,
            left, s->tty ? "   " : "\n");
    if (s->tty && final)
        fputc('\n', stderr);
    fflush(stderr);
}

static int on_rows(void *user, int32_t first, int32_t n, const void *rows)
{
    run_state *s = user;
    (void)first;
    if (interrupted)
        return 1;
    if (cli_npy_append(&s->w, rows, n)) {
        s->write_failed = 1;
        return 1;
    }
    s->done = s->base + first + n;
    progress(s, 0);
    return interrupted ? 1 : 0;
}

static int parse_backend(const char *s, mfmm_backend *b)
{
    static const mfmm_backend all[] = {MFMM_BACKEND_AUTO, MFMM_BACKEND_SERIAL,
                                       MFMM_BACKEND_THREADS, MFMM_BACKEND_OPENCL};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
        if (strcmp(s, mfmm_backend_name(all[i])) == 0) {
            *b = all[i];
            return 1;
        }
    return 0;
}

int cmd_allpairs(int argc, char **argv)
{
    const char *path = NULL, *out_path = NULL, *sources_path = NULL;
    mfmm_matrix_options o;
    mfmm_matrix_options_init(&o);
    mfmm_backend backend = MFMM_BACKEND_AUTO;
    int quiet = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *val = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            help(stdout);
            return CLI_OK;
        } else if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
            if (!val)
                return cli_usage_error("allpairs", "-o needs a file name");
            out_path = argv[++i];
        } else if (strcmp(a, "--dtype") == 0) {
            if (val && strcmp(val, "float32") == 0)
                o.dtype = MFMM_FLOAT32;
            else if (val && strcmp(val, "float64") == 0)
                o.dtype = MFMM_FLOAT64;
            else
                return cli_usage_error("allpairs", "--dtype is float32 or float64");
            i++;
        } else if (strcmp(a, "--backend") == 0) {
            if (!val || !parse_backend(val, &backend))
                return cli_usage_error("allpairs", "--backend is auto, opencl, serial or threads");
            i++;
        } else if (strcmp(a, "--sources") == 0) {
            if (!val)
                return cli_usage_error("allpairs", "--sources needs a file");
            sources_path = argv[++i];
        } else if (strcmp(a, "--max-distance") == 0) {
            if (!val || !cli_parse_double(val, &o.max_distance) || !(o.max_distance >= 0))
                return cli_usage_error("allpairs", "--max-distance needs a number >= 0");
            i++;
        } else if (strcmp(a, "--threads") == 0) {
            if (!val || !cli_parse_int32(val, &o.n_threads) || o.n_threads < 1)
                return cli_usage_error("allpairs", "--threads needs a count >= 1");
            i++;
        } else if (strcmp(a, "--memory") == 0) {
            double mb;
            if (!val || !cli_parse_double(val, &mb) || !(mb > 0) || mb > 1e9)
                return cli_usage_error("allpairs", "--memory needs megabytes > 0");
            o.memory_limit = (size_t)(mb * 1048576.0);
            i++;
        } else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) {
            quiet = 1;
        } else if (a[0] == '-' && a[1] != '\0') {
            return cli_usage_error("allpairs", "unknown option '%s'", a);
        } else if (!path) {
            path = a;
        } else {
            return cli_usage_error("allpairs", "one mesh at a time ('%s' is extra)", a);
        }
    }
    if (!path)
        return cli_usage_error("allpairs", "no mesh file given");
    if (!out_path)
        return cli_usage_error("allpairs", "no output given (-o OUT.npy)");
    if (!cli_has_ext(out_path, "npy"))
        return cli_usage_error("allpairs", "the output must end in .npy");

    int rc = CLI_FAIL;
    int32_t *src = NULL;
    int64_t n_src = 0;
    run_state s;
    memset(&s, 0, sizeof s);
    mfmm_mesh *mesh = cli_load_mesh(path, NULL);
    if (!mesh)
        return CLI_FAIL;
    int32_t nv = mfmm_mesh_vertex_count(mesh);
    if (sources_path) {
        if (read_sources(sources_path, &src, &n_src))
            goto done;
        if (n_src == 0) {
            cli_error("%s: no sources", sources_path);
            goto done;
        }
        for (int64_t i = 0; i < n_src; i++)
            if (src[i] < 0 || src[i] >= nv) {
                cli_error("%s: source %lld is vertex %ld, outside [0, %ld)", sources_path,
                          (long long)i, (long)src[i], (long)nv);
                goto done;
            }
    } else {
        n_src = nv;
        src = malloc((size_t)nv * sizeof *src);
        if (!src) {
            cli_error("out of memory");
            goto done;
        }
        for (int32_t i = 0; i < nv; i++)
            src[i] = i;
    }

    struct sigaction sa, old_int, old_term;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int);
    sigaction(SIGTERM, &sa, &old_term);

    if (cli_npy_open(&s.w, out_path, o.dtype == MFMM_FLOAT64 ? "<f8" : "<f4", n_src, nv))
        goto restore;
    s.total = (int32_t)n_src;
    s.quiet = quiet;
    s.tty = isatty(2);
    s.t0 = s.last = now();
    o.on_rows = on_rows;
    o.user = &s;
    o.backend = backend;
    mfmm_error err;
    /* auto: the library runs OpenCL, or threads (from the first row not
     * delivered) when OpenCL fails or cannot keep every core busy */
    mfmm_status st = mfmm_distance_matrix(mesh, src, (int32_t)n_src, &o, &err);
    mfmm_backend used = o.backend_used;
    if (o.fallback_reason[0])
        fprintf(stderr, "meshfmm allpairs: OpenCL not used (%s); falling back to threads\n",
                o.fallback_reason);
    if (interrupted) {
        cli_npy_abort(&s.w);
        if (!quiet && s.tty)
            fputc('\n', stderr);
        fprintf(stderr, "meshfmm allpairs: interrupted after %d of %d rows; removed the "
                        "partial file\n", (int)s.done, (int)s.total);
        rc = EXIT_INTERRUPTED;
        goto restore;
    }
    if (st != MFMM_OK) {
        if (!s.write_failed)
            cli_error("%s", err.message);
        cli_npy_abort(&s.w);
        goto restore;
    }
    if (s.tty)
        progress(&s, 1); /* completes the \r line; the summary says the rest */
    if (cli_npy_close(&s.w))
        goto restore;
    fprintf(stderr, "meshfmm allpairs: %lld x %d %s matrix, backend %s, %.2f s, wrote %s\n",
            (long long)n_src, (int)nv, o.dtype == MFMM_FLOAT64 ? "float64" : "float32",
            mfmm_backend_name(used), now() - s.t0, out_path);
    rc = CLI_OK;
restore:
    sigaction(SIGINT, &old_int, NULL);
    sigaction(SIGTERM, &old_term, NULL);
done:
    free(src);
    mfmm_mesh_destroy(mesh);
    return rc;
}
