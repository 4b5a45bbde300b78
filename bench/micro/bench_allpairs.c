/* All-pairs throughput: entries per second of mfmm_distance_matrix for
 * serial (1 thread), threads (2) and OpenCL, float32 rows streamed to a
 * callback that drops them, and the peak memory of each run (ru_maxrss of
 * a child process per run).
 *
 *   bench_allpairs [--rows N] [--full] [--memory MB] [MESH ...]
 *
 * Default meshes: camelhead.off and nefertiti-lowres.obj from tests/data/meshes.
 * --rows: rows per run (spread over the mesh), extrapolated to nv x nv;
 * --full: all nv rows with OpenCL and threads (slow on big meshes);
 * --memory: the memory_limit passed to the library. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "bench_util.h"
#include "meshfmm.h"

static double cpu_seconds(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0)
        return 0.0;
    return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
           (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
}

static int drop_rows(void *user, int32_t first, int32_t n, const void *rows)
{
    (void)first;
    (void)rows;
    *(int64_t *)user += n;
    return 0;
}

typedef struct result {
    int status;
    double seconds;
    int64_t rows;
    long maxrss_kb; /* the child's own peak */
    double cpu;     /* CPU seconds (user + system) of the timed call */
    long mesh_kb;   /* resident growth from mfmm_mesh_create: the mesh arrays */
    long run_kb;    /* peak resident growth during the timed call, above what was
                       resident before it (mesh, OpenCL runtime, built program) */
} result;

/* Resident set (VmRSS) or its peak (VmHWM) in kB, from /proc/self/status. */
static long status_kb(const char *key)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    long kb = -1;
    size_t n = strlen(key);
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, key, n) == 0 && line[n] == ':')
            kb = strtol(line + n + 1, NULL, 10);
    if (f)
        fclose(f);
    return kb;
}

/* Resets VmHWM to the current resident set (Linux: clear_refs 5). */
static void reset_peak(void)
{
    FILE *f = fopen("/proc/self/clear_refs", "w");
    if (f) {
        fputs("5", f);
        fclose(f);
    }
}

static size_t memory_limit; /* --memory MB; 0: the library's default */

static void run_child(const char *path, mfmm_backend backend, int threads, int32_t n_rows,
                      int fd)
{
    result r = {1, 0.0, 0, 0, 0.0, 0, 0};
    mfmm_opencl_context *ctx = NULL;
    double *V = NULL;
    int32_t *F = NULL, nv = 0, nf = 0;
    mfmm_error err;
    mfmm_mesh *mesh = NULL;
    if (mfmm_load_mesh(path, &V, &nv, &F, &nf, &err) != MFMM_OK) {
        fprintf(stderr, "%s: %s\n", path, err.message);
        goto out;
    }
    long rss0 = status_kb("VmRSS");
    if (mfmm_mesh_create(V, nv, F, nf, NULL, &mesh, &err) != MFMM_OK) {
        fprintf(stderr, "%s: %s\n", path, err.message);
        goto out;
    }
    r.mesh_kb = status_kb("VmRSS") - rss0;
    mfmm_free(V);
    mfmm_free(F);
    if (n_rows <= 0 || n_rows > nv)
        n_rows = nv;
    int32_t *src = malloc((size_t)n_rows * sizeof *src);
    if (!src)
        goto out;
    for (int32_t i = 0; i < n_rows; i++)
        src[i] = (int32_t)((int64_t)i * nv / n_rows);
    mfmm_matrix_options o;
    mfmm_matrix_info oi = {.struct_size = sizeof oi};
    mfmm_matrix_options_init(&o);
    o.backend = backend;
    o.n_threads = threads;
    o.memory_limit = memory_limit;
    o.on_rows = drop_rows;
    o.user = &r.rows;
    if (backend == MFMM_BACKEND_OPENCL) { /* build (or load) the program first */
        if (mfmm_opencl_context_create(NULL, &ctx, &err) != MFMM_OK) {
            fprintf(stderr, "%s opencl: %s\n", path, err.message);
            free(src);
            goto out;
        }
        o.opencl = ctx;
        int64_t warm = 0;
        o.user = &warm;
        mfmm_distance_matrix(mesh, src, 2, &o, &oi, &err);
        o.user = &r.rows;
    }
    reset_peak();
    long before = status_kb("VmRSS");
    double c0 = cpu_seconds(), t0 = now();
    mfmm_status st = mfmm_distance_matrix(mesh, src, n_rows, &o, &oi, &err);
    r.seconds = now() - t0;
    r.cpu = cpu_seconds() - c0;
    r.run_kb = status_kb("VmHWM") - before;
    if (st != MFMM_OK)
        fprintf(stderr, "%s %s: %s\n", path, mfmm_backend_name(backend), err.message);
    r.status = st;
    free(src);
out:
    mfmm_opencl_context_destroy(ctx);
    mfmm_mesh_destroy(mesh);
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) == 0)
        r.maxrss_kb = ru.ru_maxrss;
    if (write(fd, &r, sizeof r) != (ssize_t)sizeof r)
        _exit(2);
    _exit(0);
}

static int run(const char *path, mfmm_backend backend, int threads, int32_t n_rows,
               result *r, long *maxrss_kb)
{
    int p[2];
    if (pipe(p) != 0)
        return -1;
    fflush(NULL);
    pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        close(p[0]);
        run_child(path, backend, threads, n_rows, p[1]);
    }
    close(p[1]);
    ssize_t got = read(p[0], r, sizeof *r);
    close(p[0]);
    int status = 0;
    if (waitpid(pid, &status, 0) < 0)
        return -1;
    *maxrss_kb = r->maxrss_kb;
    return got == (ssize_t)sizeof *r && r->status == 0 ? 0 : -1;
}

static void bench_mesh(const char *path, int32_t n_rows, int full)
{
    double *V = NULL;
    int32_t *F = NULL, nv = 0, nf = 0;
    mfmm_error err;
    if (mfmm_load_mesh(path, &V, &nv, &F, &nf, &err) != MFMM_OK) {
        fprintf(stderr, "%s: %s\n", path, err.message);
        return;
    }
    mfmm_free(V);
    mfmm_free(F);
    printf("%s: nv %d, nf %d, full matrix %.3g entries\n", path, (int)nv, (int)nf,
           (double)nv * nv);
    struct {
        const char *name;
        mfmm_backend backend;
        int threads;
        int32_t rows;
    } runs[] = {
        {"serial (1 thread)", MFMM_BACKEND_SERIAL, 1, n_rows},
        {"threads (2)", MFMM_BACKEND_THREADS, 2, full ? nv : n_rows},
        {"opencl", MFMM_BACKEND_OPENCL, 0, full ? nv : n_rows},
    };
    double serial_rate = 0.0;
    for (size_t k = 0; k < sizeof runs / sizeof runs[0]; k++) {
        result r;
        long rss = 0;
        if (run(path, runs[k].backend, runs[k].threads, runs[k].rows, &r, &rss) != 0) {
            printf("  %-18s failed\n", runs[k].name);
            continue;
        }
        double entries = (double)r.rows * nv;
        double rate = entries / r.seconds;
        if (k == 0)
            serial_rate = rate;
        printf("  %-18s %6lld rows %7.2f s %9.3g entries/s  x%.2f serial  full %s%.1f s  "
               "%9.3g entries/cpu-s  peak RSS %.1f MiB (the call: +%.1f MiB; mesh arrays "
               "%.1f MiB)\n",
               runs[k].name, (long long)r.rows, r.seconds, rate,
               serial_rate > 0 ? rate / serial_rate : 0.0, r.rows < nv ? "~" : "",
               (double)nv * nv / rate, r.cpu > 0 ? entries / r.cpu : 0.0,
               (double)rss / 1024.0, (double)r.run_kb / 1024.0, (double)r.mesh_kb / 1024.0);
    }
}

int main(int argc, char **argv)
{
    int32_t n_rows = 400;
    int full = 0;
    const char *meshes[16];
    int n = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--rows") && i + 1 < argc)
            n_rows = (int32_t)atoi(argv[++i]);
        else if (!strcmp(argv[i], "--memory") && i + 1 < argc)
            memory_limit = (size_t)(atof(argv[++i]) * 1048576.0);
        else if (!strcmp(argv[i], "--full"))
            full = 1;
        else if (n < 16)
            meshes[n++] = argv[i];
    }
    static char defaults[2][1024];
    if (n == 0) {
        /* tests/data/meshes beside the repository holding this file */
        const char *names[2] = {"camelhead.off", "nefertiti-lowres.obj"};
        const char *file = __FILE__;
        const char *cut = strstr(file, "/bench/micro/bench_allpairs.c");
        int len = cut ? (int)(cut - file) : 0;
        for (int k = 0; k < 2; k++) {
            snprintf(defaults[k], sizeof defaults[k], "%.*s/tests/data/meshes/%s", len, file,
                     names[k]);
            meshes[n++] = defaults[k];
        }
    }
    printf("meshfmm %s all-pairs benchmark, float32 rows streamed to a callback\n",
           mfmm_version());
    for (int i = 0; i < n; i++)
        bench_mesh(meshes[i], n_rows, full);
    return 0;
}
