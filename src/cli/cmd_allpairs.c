/* meshfmm allpairs MESH -o OUT.npy: the distance matrix, streamed in blocks
 * of rows into a .npy file (a temporary file beside it, renamed when
 * complete); -o OUT.npz with --max-distance: the sparse local matrix as a
 * scipy .npz; --targets: only those columns. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"

static void help(FILE *out)
{
    fprintf(out,
            "usage: meshfmm allpairs MESH -o OUT.npy|OUT.npz [--dtype float32|float64]\n"
            "                        [--backend auto|opencl|serial|threads] [--sources FILE]\n"
            "                        [--targets FILE]\n"
            "                        [--cost FILE [--cost-per-face]] [--max-distance X]\n"
            "                        [--exact-start-radius R | --plain-start]\n"
            "                        [--method fmm|windows]\n"
            "                        [--threads N] [--memory MB] [--no-spokes] [--quiet]\n"
            "                        [--no-size-check] [--weld]\n\n"
            "The geodesic distance matrix: one row per source (default every vertex), one\n"
            "column per vertex, streamed into a .npy file block by block (the matrix is\n"
            "never held in memory). The file appears under its name only when complete.\n\n"
            "  -o, --output OUT    output; written to a temporary file beside it, then\n"
            "                      renamed (it may not be one of the inputs). OUT.npy: the\n"
            "                      dense matrix; OUT.npz (needs --max-distance): the sparse\n"
            "                      matrix of the pairs within it, scipy.sparse.load_npz's\n"
            "                      CSR format (explicit zeros on the diagonal); memory\n"
            "                      follows the entries, never rows x columns\n"
            "                      (OUT.zarr, a resumable Dask + Zarr job, is the command\n"
            "                      pip installs: `python -m meshfmm allpairs --help`)\n"
            "  --dtype T           float32 (default) or float64; arithmetic is float64\n"
            "  --backend B         auto (default: OpenCL on a device that is not a CPU\n"
            "                      or that MESHFMM_OPENCL_DEVICE names, else threads),\n"
            "                      opencl, serial (one thread) or threads\n"
            "  --sources FILE      source vertex ids: .txt (whitespace separated) or .npy\n"
            "                      (1-D integer array)\n"
            "  --targets FILE      target vertex ids (same formats): columns in this order,\n"
            "                      each row stops once its targets are settled (landmarks)\n"
            "  --cost FILE         slowness F (.npy float64/float32 or .txt), one value per\n"
            "                      vertex (default) or per face (--cost-per-face), as in\n"
            "                      meshfmm distance\n"
            "  --max-distance X    stop each row past X; farther vertices get inf\n"
            "  --exact-start-radius R  each row's march starts from exact distances within\n"
            "                      R mean edge lengths of its source (default auto:\n"
            "                      " CLI_STR(MFMM_EXACT_START_RADIUS) ", times sqrt(vertices / "
            CLI_STR(MFMM_EXACT_START_AUTO_VERTICES) ") above that size\n"
            "                      without --max-distance)\n"
            "  --plain-start       the paper's start (as --exact-start-radius 0)\n"
            "  --method M          fmm (default): Fast Marching; windows: window\n"
            "                      propagation keeping two windows per half-edge, never\n"
            "                      below the geodesic distance, several times as accurate\n"
            "                      and several times the time (auto runs it on threads)\n"
            "  --threads N         threads for the threads backend (0, the default: all cores)\n"
            "  --memory MB         memory for workspaces and blocks in flight (default 16)\n"
            "  --no-spokes         memory first: no per-vertex update records (~380 bytes\n"
            "                      per vertex, built once for the march); the same\n"
            "                      matrix, each row's march 1.25-1.6x as long\n"
            "  --quiet             nothing on stderr but errors (no progress, no notes, no\n"
            "                      summary line)\n"
            "  --no-size-check     write a dense .npy even when it exceeds the free space\n"
            "                      of its file system (by default the size is compared\n"
            "                      with it first and the job refused with both numbers)\n"
            "  --weld              weld vertices at the same position (texture seams,\n"
            "                      unmerged corners) before solving, as `meshfmm weld`\n"
            "                      does; --sources, --targets, rows and columns stay the\n"
            "                      file's ids (every file vertex a row and a column by\n"
            "                      default)\n"
            "  -h, --help          this text\n\n"
            "Environment: MESHFMM_OPENCL_DEVICE (device index or name substring),\n"
            "MESHFMM_CACHE_DIR (OpenCL program cache, default ~/.cache/meshfmm).\n"
            "SIGINT, SIGTERM or SIGHUP stop the run, remove the temporary file and exit\n"
            "with 130.\n"
            "Options take their value as --dtype float64 or --dtype=float64.\n");
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* ---- the run ---- */

typedef struct run_state {
    cli_npy_writer w;
    cli_npz_writer z;
    /* --weld without --targets: rows of the built mesh's columns written in
     * the file's columns (to_welded: the built column of each; inv_ptr,
     * inv_idx: the file columns of each built one, ascending) */
    const int32_t *to_welded;
    int32_t n_file_cols, n_built_cols;
    int64_t *inv_ptr;
    int32_t *inv_idx;
    unsigned char *row;  /* one dense row of the file's columns */
    int64_t *x_ptr;      /* a sparse block in the file's columns */
    int32_t *x_idx;
    unsigned char *x_val;
    struct file_entry *x_sort;
    int64_t x_cap;
    int32_t x_rows;
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

/* A sparse entry in a file column: its column and its entry in the block. */
struct file_entry {
    int64_t e;
    int32_t col;
};

static int by_col(const void *a, const void *b)
{
    int32_t x = ((const struct file_entry *)a)->col, y = ((const struct file_entry *)b)->col;
    return (x > y) - (x < y);
}

/* The inverse of s->to_welded (CSR over the built columns). 0 or -1. */
static int build_inverse(run_state *s)
{
    s->inv_ptr = calloc((size_t)s->n_built_cols + 1, sizeof *s->inv_ptr);
    s->inv_idx = malloc((size_t)s->n_file_cols * sizeof *s->inv_idx + 1);
    if (!s->inv_ptr || !s->inv_idx)
        return -1;
    for (int32_t v = 0; v < s->n_file_cols; v++)
        s->inv_ptr[s->to_welded[v] + 1]++;
    for (int32_t w = 0; w < s->n_built_cols; w++)
        s->inv_ptr[w + 1] += s->inv_ptr[w];
    for (int32_t v = 0; v < s->n_file_cols; v++) /* ascending within each */
        s->inv_idx[s->inv_ptr[s->to_welded[v]]++] = v;
    for (int32_t w = s->n_built_cols; w > 0; w--)
        s->inv_ptr[w] = s->inv_ptr[w - 1];
    s->inv_ptr[0] = 0;
    return 0;
}

/* A CSR block in built columns -> s->x_* in the file's columns (each row's
 * columns ascending). 0, or -1 out of memory (printed). */
static int to_file_columns(run_state *s, int32_t n, const int64_t *indptr,
                           const int32_t *indices, const void *values)
{
    size_t isz = s->z.itemsize;
    int64_t total = 0;
    for (int64_t e = 0; e < indptr[n]; e++)
        total += s->inv_ptr[indices[e] + 1] - s->inv_ptr[indices[e]];
    if (n > s->x_rows) {
        int64_t *p = realloc(s->x_ptr, ((size_t)n + 1) * sizeof *p);
        if (!p)
            goto oom;
        s->x_ptr = p;
        s->x_rows = n;
    }
    if (total > s->x_cap) {
        int32_t *idx = realloc(s->x_idx, (size_t)total * sizeof *idx);
        if (idx)
            s->x_idx = idx;
        unsigned char *val = realloc(s->x_val, (size_t)total * isz);
        if (val)
            s->x_val = val;
        struct file_entry *srt = realloc(s->x_sort, (size_t)total * sizeof *srt);
        if (srt)
            s->x_sort = srt;
        if (!idx || !val || !srt)
            goto oom;
        s->x_cap = total;
    }
    const unsigned char *in = values;
    int64_t k = 0;
    s->x_ptr[0] = 0;
    for (int32_t r = 0; r < n; r++) {
        int64_t row0 = k;
        for (int64_t e = indptr[r]; e < indptr[r + 1]; e++)
            for (int64_t j = s->inv_ptr[indices[e]]; j < s->inv_ptr[indices[e] + 1]; j++) {
                s->x_sort[k].e = e;
                s->x_sort[k].col = s->inv_idx[j];
                k++;
            }
        qsort(s->x_sort + row0, (size_t)(k - row0), sizeof *s->x_sort, by_col);
        for (int64_t j = row0; j < k; j++) {
            s->x_idx[j] = s->x_sort[j].col;
            memcpy(s->x_val + (size_t)j * isz, in + (size_t)s->x_sort[j].e * isz, isz);
        }
        s->x_ptr[r + 1] = k;
    }
    return 0;
oom:
    cli_error("out of memory");
    return -1;
}

static int on_sparse(void *user, int32_t first, int32_t n, const int64_t *indptr,
                     const int32_t *indices, const void *values)
{
    run_state *s = user;
    if (cli_interrupted())
        return 1;
    if (s->to_welded) {
        if (to_file_columns(s, n, indptr, indices, values)) {
            s->write_failed = 1;
            return 1;
        }
        indptr = s->x_ptr;
        indices = s->x_idx;
        values = s->x_val;
    }
    if (cli_npz_append(&s->z, n, indptr, indices, values)) {
        s->write_failed = 1;
        return 1;
    }
    s->done = first + n;
    progress(s, 0);
    return cli_interrupted() ? 1 : 0;
}

static int on_rows(void *user, int32_t first, int32_t n, const void *rows)
{
    run_state *s = user;
    if (cli_interrupted())
        return 1;
    if (s->to_welded) {
        size_t isz = s->w.itemsize;
        for (int32_t r = 0; r < n; r++) {
            const unsigned char *in = (const unsigned char *)rows + (size_t)r * isz *
                                                                    (size_t)s->n_built_cols;
            if (isz == 4)
                for (int32_t v = 0; v < s->n_file_cols; v++)
                    memcpy(s->row + 4 * (size_t)v, in + 4 * (size_t)s->to_welded[v], 4);
            else
                for (int32_t v = 0; v < s->n_file_cols; v++)
                    memcpy(s->row + 8 * (size_t)v, in + 8 * (size_t)s->to_welded[v], 8);
            if (cli_npy_append(&s->w, s->row, 1)) {
                s->write_failed = 1;
                return 1;
            }
        }
    } else if (cli_npy_append(&s->w, rows, n)) {
        s->write_failed = 1;
        return 1;
    }
    s->done = first + n;
    progress(s, 0);
    return cli_interrupted() ? 1 : 0;
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

/* --cost FILE: one value per vertex or per face of the file, as `distance
 * --cost`, carried to the built mesh. */
static int load_cost(const char *path, int per_face, const cli_mesh *m, double **cost)
{
    int64_t nc;
    int r = cli_has_ext(path, "npy") ? cli_npy_read_vector(path, cost, &nc)
                                     : cli_txt_read_vector(path, cost, &nc);
    if (r)
        return -1;
    int32_t nv = m->nv_in, nf = m->nf_in;
    int64_t want = per_face ? nf : nv;
    if (nc != want) {
        cli_error("%s: %lld cost values, the mesh has %lld %s%s", path, (long long)nc,
                  (long long)want, per_face ? "faces" : "vertices",
                  !per_face && nc == nf ? " (use --cost-per-face for face costs)" : "");
        return -1;
    }
    cli_mesh_cost(m, *cost, per_face);
    return 0;
}

int cmd_allpairs(int argc, char **argv)
{
    const char *path = NULL, *out_path = NULL, *sources_path = NULL, *cost_path = NULL,
               *targets_path = NULL;
    int cost_per_face = 0;
    mfmm_matrix_options o;
    mfmm_matrix_options_init(&o);
    mfmm_backend backend = MFMM_BACKEND_AUTO;
    mfmm_mesh_options mo;
    mfmm_mesh_options_init(&mo);
    int quiet = 0, start_given = 0, threads_given = 0, size_check = 1, weld = 0;
    int method_given = 0;
    static const struct option longopts[] = {
        {"help", no_argument, NULL, 'h'},
        {"output", required_argument, NULL, 'o'},
        {"quiet", no_argument, NULL, 'q'},
        {"dtype", required_argument, NULL, OPT_DTYPE},
        {"backend", required_argument, NULL, OPT_BACKEND},
        {"sources", required_argument, NULL, OPT_SOURCES},
        {"targets", required_argument, NULL, OPT_TARGETS},
        {"cost", required_argument, NULL, OPT_COST},
        {"cost-per-face", no_argument, NULL, OPT_COST_PER_FACE},
        {"max-distance", required_argument, NULL, OPT_MAX_DISTANCE},
        {"threads", required_argument, NULL, OPT_THREADS},
        {"memory", required_argument, NULL, OPT_MEMORY},
        {"plain-start", no_argument, NULL, OPT_PLAIN_START},
        {"exact-start-radius", required_argument, NULL, OPT_EXACT_START_RADIUS},
        {"no-spokes", no_argument, NULL, OPT_NO_SPOKES},
        {"no-size-check", no_argument, NULL, OPT_NO_SIZE_CHECK},
        {"weld", no_argument, NULL, OPT_WELD},
        {"method", required_argument, NULL, OPT_METHOD},
        /* not an option of allpairs: named so that getopt does not take it
         * for an abbreviation of --sources */
        {"source", required_argument, NULL, OPT_SOURCE},
        {NULL, 0, NULL, 0}};
    int c;
    opterr = 0;
    uint32_t seen = 0;
    while ((c = getopt_long(argc, argv, ":ho:q", longopts, NULL)) != -1) {
        const char *val = optarg;
        if (cli_once("allpairs", c, &seen) != CLI_OK)
            return CLI_USAGE;
        switch (c) {
        case 'h':
            help(stdout);
            return CLI_OK;
        case 'o':
            out_path = val;
            break;
        case 'q':
            quiet = 1;
            break;
        case OPT_DTYPE:
            if (strcmp(val, "float32") == 0)
                o.dtype = MFMM_FLOAT32;
            else if (strcmp(val, "float64") == 0)
                o.dtype = MFMM_FLOAT64;
            else
                return cli_usage_error("allpairs", "--dtype is float32 or float64");
            break;
        case OPT_BACKEND:
            if (!parse_backend(val, &backend))
                return cli_usage_error("allpairs", "--backend is auto, opencl, serial or threads");
            break;
        case OPT_SOURCE:
            return cli_usage_error("allpairs", "takes its rows' sources as --sources FILE (one "
                                                "source: meshfmm distance --source %s)", val);
        case OPT_SOURCES:
            sources_path = val;
            break;
        case OPT_TARGETS:
            targets_path = val;
            break;
        case OPT_COST:
            cost_path = val;
            break;
        case OPT_COST_PER_FACE:
            cost_per_face = 1;
            break;
        case OPT_MAX_DISTANCE:
            if (!cli_parse_double(val, &o.max_distance) || !(o.max_distance >= 0))
                return cli_usage_error("allpairs", "--max-distance needs a number >= 0");
            break;
        case OPT_THREADS:
            if (!cli_parse_int32(val, &o.n_threads) || o.n_threads < 0)
                return cli_usage_error("allpairs", "--threads needs a count >= 0 (0: all cores)");
            threads_given = 1;
            break;
        case OPT_PLAIN_START:
            if (cli_start_option("allpairs", 1, &start_given) != CLI_OK)
                return CLI_USAGE;
            o.exact_start_radius = 0.0;
            break;
        case OPT_NO_SPOKES:
            mo.spokes = 0;
            break;
        case OPT_NO_SIZE_CHECK:
            size_check = 0;
            break;
        case OPT_WELD:
            weld = 1;
            break;
        case OPT_METHOD:
            method_given = 1;
            if (cli_parse_method("allpairs", val, &o.method) != CLI_OK)
                return CLI_USAGE;
            break;
        case OPT_EXACT_START_RADIUS:
            if (cli_start_option("allpairs", 2, &start_given) != CLI_OK ||
                cli_parse_start_radius("allpairs", val, &o.exact_start_radius) != CLI_OK)
                return CLI_USAGE;
            break;
        case OPT_MEMORY: {
            double mb;
            if (!cli_parse_double(val, &mb) || !(mb > 0) || mb > 1e9)
                return cli_usage_error("allpairs", "--memory takes megabytes, > 0 and at most 1e9");
            o.memory_limit = (size_t)(mb * 1048576.0);
            break;
        }
        default:
            return cli_getopt_error("allpairs", c, argv);
        }
    }
    for (int i = optind; i < argc; i++) {
        if (path)
            return cli_usage_error("allpairs", "one mesh at a time ('%s' is extra)", argv[i]);
        path = argv[i];
    }
    if (!path)
        return cli_usage_error("allpairs", "no mesh file given");
    if (!out_path)
        return cli_usage_error("allpairs", "no output given (-o OUT.npy)");
    int sparse = cli_has_ext(out_path, "npz");
    if (!cli_has_ext(out_path, "npy") && !sparse)
        return cli_usage_error("allpairs", "the output must end in .npy (dense) or .npz (sparse, "
                               "with --max-distance); for .zarr use the command installed by "
                               "pip (python -m meshfmm allpairs)");
    if (sparse && !(o.max_distance < INFINITY))
        return cli_usage_error("allpairs", "a sparse .npz output needs --max-distance R (the "
                               "pairs within R); without it the matrix is dense: use .npy");
    if (cost_per_face && !cost_path)
        return cli_usage_error("allpairs", "--cost-per-face needs --cost");
    if (cli_check_method("allpairs", o.method, method_given, 0, cost_path != NULL) != CLI_OK)
        return CLI_USAGE;
    if (threads_given && (backend == MFMM_BACKEND_SERIAL || backend == MFMM_BACKEND_OPENCL))
        return cli_usage_error("allpairs", "--threads is for the threads backend (and auto's "
                               "fallback to it); --backend %s does not use it",
                               backend == MFMM_BACKEND_SERIAL ? "serial (one thread)"
                                                              : "opencl (the device's cores)");
    const char *inputs[4] = {path, sources_path, cost_path, targets_path};
    if (cli_check_output_not_input("allpairs", out_path, inputs, 4) != CLI_OK)
        return CLI_USAGE;

    int rc = CLI_FAIL;
    int32_t *src = NULL, *tgt = NULL;
    double *cost = NULL;
    int64_t n_src = 0, n_tgt = 0;
    int z_open = 0;
    run_state s;
    memset(&s, 0, sizeof s);
    cli_signals_install();
    cli_mesh m;
    if (cli_mesh_load(&m, path, &mo, weld, 0))
        return CLI_FAIL;
    int32_t nv = m.nv_in; /* ids given and columns written: the file's */
    if (cost_path) {
        if (load_cost(cost_path, cost_per_face, &m, &cost))
            goto done;
        o.cost = cost;
        o.cost_location = cost_per_face ? MFMM_COST_PER_FACE : MFMM_COST_PER_VERTEX;
    }
    if (sources_path) {
        if (cli_read_ids(sources_path, &src, &n_src))
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
        src = malloc((size_t)nv * sizeof *src + 1);
        if (!src) {
            cli_error("out of memory");
            goto done;
        }
        for (int32_t i = 0; i < nv; i++)
            src[i] = i;
    }

    if (targets_path) {
        if (cli_read_ids(targets_path, &tgt, &n_tgt))
            goto done;
        if (n_tgt == 0 || n_tgt > INT32_MAX) {
            cli_error("%s: %s", targets_path, n_tgt ? "too many targets" : "no targets");
            goto done;
        }
        for (int64_t i = 0; i < n_tgt; i++)
            if (tgt[i] < 0 || tgt[i] >= nv) {
                cli_error("%s: target %lld is vertex %ld, outside [0, %ld)", targets_path,
                          (long long)i, (long)tgt[i], (long)nv);
                goto done;
            }
        o.targets = tgt;
        o.n_targets = (int32_t)n_tgt;
    }
    if (m.in_no_face && !quiet) {
        int64_t count = 0;
        int32_t first = -1;
        for (int64_t i = 0; i < n_src; i++)
            if (m.in_no_face[src[i]] && count++ == 0)
                first = src[i];
        cli_note_sources_in_no_face("allpairs", count, first);
    }
    if (m.to_welded) { /* in range: checked above */
        for (int64_t i = 0; i < n_src; i++)
            src[i] = m.to_welded[src[i]];
        for (int64_t i = 0; i < n_tgt; i++)
            tgt[i] = m.to_welded[tgt[i]];
        if (!tgt) {
            s.to_welded = m.to_welded;
            s.n_file_cols = m.nv_in;
            s.n_built_cols = m.nv;
            if (!sparse)
                s.row = malloc((size_t)m.nv_in * (o.dtype == MFMM_FLOAT64 ? 8 : 4) + 1);
            if (sparse ? build_inverse(&s) : !s.row) {
                cli_error("out of memory");
                goto done;
            }
        }
    }
    int64_t n_cols = tgt ? n_tgt : nv;
    if (cli_interrupted())
        goto done;
    double free_bytes;
    if (!sparse && size_check && cli_free_bytes(out_path, &free_bytes) == 0) {
        /* the .npy and its temporary file are one file: it needs its size */
        double need = (double)n_src * (double)n_cols * (o.dtype == MFMM_FLOAT64 ? 8.0 : 4.0) +
                      128.0;
        if (need > free_bytes) {
            char a[32], b[32];
            cli_error("%s would take %s (%lld x %lld %s) but its file system has %s free; "
                      "write fewer rows (--sources), the pairs within a radius "
                      "(--max-distance R -o OUT.npz), or give --no-size-check to start anyway",
                      out_path, cli_format_bytes(need, a, sizeof a), (long long)n_src,
                      (long long)n_cols, o.dtype == MFMM_FLOAT64 ? "float64" : "float32",
                      cli_format_bytes(free_bytes, b, sizeof b));
            goto done;
        }
    }
    if (sparse) {
        if (cli_npz_open(&s.z, out_path, o.dtype == MFMM_FLOAT64, n_src, n_cols))
            goto done;
        z_open = 1;
    } else if (cli_npy_open(&s.w, out_path, o.dtype == MFMM_FLOAT64 ? "<f8" : "<f4", n_src,
                            n_cols)) {
        goto done;
    }
    s.total = (int32_t)n_src;
    s.quiet = quiet;
    s.tty = isatty(2);
    s.t0 = s.last = now();
    if (sparse)
        o.on_sparse = on_sparse;
    else
        o.on_rows = on_rows;
    o.user = &s;
    o.backend = backend;
    mfmm_error err;
    /* auto: the library runs OpenCL, or threads (from the first row not
     * delivered) when OpenCL fails or cannot keep every core busy */
    mfmm_matrix_info info = {.struct_size = sizeof info};
    mfmm_status st = mfmm_distance_matrix(m.mesh, src, (int32_t)n_src, &o, &info, &err);
    mfmm_backend used = info.backend_used;
    if (cli_interrupted()) {
        if (sparse)
            cli_npz_abort(&s.z);
        else
            cli_npy_abort(&s.w);
        z_open = 0;
        if (!quiet && s.tty)
            fputc('\n', stderr);
        fprintf(stderr, "meshfmm allpairs: interrupted after %d of %d rows; removed the "
                        "temporary file\n", (int)s.done, (int)s.total);
        rc = CLI_EXIT_INTERRUPTED;
        goto done;
    }
    if (st != MFMM_OK) {
        if (!s.write_failed)
            cli_error("%s", err.message);
        if (sparse)
            cli_npz_abort(&s.z);
        else
            cli_npy_abort(&s.w);
        z_open = 0;
        goto done;
    }
    if (s.tty)
        progress(&s, 1); /* completes the \r line; the summary says the rest */
    z_open = 0;
    if (sparse ? cli_npz_close(&s.z) : cli_npy_close(&s.w)) {
        if (cli_interrupted())
            rc = CLI_EXIT_INTERRUPTED;
        goto done;
    }
    /* one line: the backend that ran and, under auto, why (a CPU device
     * left to the threads is the expected case, not a failure) */
    if (!quiet)
        fprintf(stderr, "meshfmm allpairs: %lld x %lld %s%s matrix, backend %s%s%s%s, %.2f s, "
                        "wrote %s\n",
                (long long)n_src, (long long)n_cols, sparse ? "sparse " : "",
                o.dtype == MFMM_FLOAT64 ? "float64" : "float32", mfmm_backend_name(used),
                info.backend_reason[0] ? " (auto: " : "", info.backend_reason,
                info.backend_reason[0] ? ")" : "", now() - s.t0, out_path);
    rc = CLI_OK;
done:
    if (rc == CLI_FAIL && cli_interrupted())
        rc = CLI_EXIT_INTERRUPTED;
    if (z_open)
        cli_npz_abort(&s.z);
    free(src);
    free(tgt);
    free(cost);
    free(s.inv_ptr);
    free(s.inv_idx);
    free(s.row);
    free(s.x_ptr);
    free(s.x_idx);
    free(s.x_val);
    free(s.x_sort);
    cli_mesh_free(&m);
    return rc;
}
