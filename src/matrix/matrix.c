/* mfmm_distance_matrix: many sources, rows handed out in blocks, on the
 * serial core (one thread or many) or on OpenCL (src/opencl_host.c). */
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/error.h"
#include "rows.h"
#include "mesh/order.h"
#include "start/seed.h"
#include "solve/solve.h"

const char *mfmm_backend_name(mfmm_backend backend)
{
    switch (backend) {
    case MFMM_BACKEND_AUTO: return "auto";
    case MFMM_BACKEND_SERIAL: return "serial";
    case MFMM_BACKEND_THREADS: return "threads";
    case MFMM_BACKEND_OPENCL: return "opencl";
    }
    return "unknown";
}

void mfmm_matrix_options_init(mfmm_matrix_options *options)
{
    if (!options)
        return;
    memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
    options->backend = MFMM_BACKEND_AUTO;
    options->dtype = MFMM_FLOAT32;
    options->cost = NULL;
    options->cost_location = MFMM_COST_NONE;
    options->max_distance = INFINITY;
    options->unfolding = 1;
    options->n_threads = 0;
    options->memory_limit = 0;
    options->out = NULL;
    options->on_rows = NULL;
    options->user = NULL;
    options->backend_used = MFMM_BACKEND_AUTO;
    options->opencl = NULL;
    options->exact_start_radius = MFMM_EXACT_START_AUTO;
}

/* Rows per block for the CPU engines: the budget less the solvers'
 * workspaces, over `ring` blocks of rows. */
static int32_t cpu_block_rows(const mfmm_rows_job *job, int n_workers, int ring)
{
    size_t nv = (size_t)job->mesh->nv;
    size_t row_bytes = job->slot_bytes;
    size_t work = (size_t)n_workers * nv * 32; /* solver + a float64 row */
    /* each solver's exact-start state (the tables are the mesh's, not the job's) */
    if (mfmm_exact_start_on(job->opt->exact_start_radius))
        work += (size_t)n_workers * mfmm_exact_start_bytes(job->mesh);
    size_t left = job->budget > work ? job->budget - work : 0;
    /* ring 0: rows go straight into the caller's buffer */
    size_t rows = left / ((size_t)(ring > 0 ? ring : 1) * row_bytes);
    if (rows > 1024)
        rows = 1024; /* keep callbacks (progress, cancel) frequent */
    if (rows < (size_t)n_workers)
        rows = (size_t)n_workers;
    if (rows > (size_t)job->n_sources)
        rows = (size_t)job->n_sources;
    return rows < 1 ? 1 : (int32_t)rows;
}

static void fill_solve_options(const mfmm_rows_job *job, mfmm_solve_options *so)
{
    mfmm_solve_options_init(so);
    so->cost = job->cost;
    so->cost_location = (mfmm_cost_location)job->cost_location;
    so->max_distance = job->opt->max_distance;
    so->unfolding = job->opt->unfolding != 0;
    so->targets = job->targets;
    so->n_targets = job->targets ? job->width : 0;
    so->exact_start_radius = job->opt->exact_start_radius;
}

static int cmp_i32(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

static void put_value(const mfmm_rows_job *job, void *dst, size_t j, double t)
{
    if (job->elem_size == sizeof(double))
        ((double *)dst)[j] = t;
    else
        ((float *)dst)[j] = (float)t;
}

/* Solves row r into dst: a dense row of job->width values of the job's
 * dtype, or (sparse) an mfmm_sparse_row whose arrays it allocates. The job
 * was checked once, in mfmm_distance_matrix, so rows skip mfmm_solve's
 * checks. The march runs in the solver's own T; full dense rows are
 * gathered from it into input order in the one pass that writes the row;
 * target columns and sparse rows read it at the touched vertices only
 * (cost ~ the row's reach).
 * Returns the vertices settled, or -1 when out of memory. */
static int64_t solve_row(const mfmm_rows_job *job, mfmm_solver *solver,
                         const mfmm_solve_options *so, int32_t r, void *dst)
{
    mfmm_source src;
    memset(&src, 0, sizeof src);
    src.vertex = job->sources[r];
    src.face = -1;
    src.value = 0.0;
    int32_t nv = job->mesh->nv;
    const double *T;
    const int32_t *touched;
    int32_t n_touched;
    int32_t settled = mfmm_solve_local(solver, &src, 1, so, &T, &touched, &n_touched);
    if (settled < 0)
        return -1;
    if (!job->targets && !job->sparse) {
        /* the row's one pass: gathered into input order (core/order.h) */
        const int32_t *in = job->mesh->to_internal;
        if (job->elem_size == sizeof(double)) {
            double *d = (double *)dst;
            for (int32_t v = 0; v < nv; v++)
                d[v] = T[in[v]];
        } else {
            float *f = (float *)dst;
            for (int32_t v = 0; v < nv; v++)
                f[v] = (float)T[in[v]];
        }
        return settled;
    }
    if (!job->sparse) {
        for (int32_t j = 0; j < job->width; j++)
            put_value(job, dst, (size_t)j, T[job->targets[j]]);
        return settled;
    }
    mfmm_sparse_row *row = dst;
    size_t cap = job->targets ? (size_t)job->width : (size_t)settled;
    row->n = 0;
    row->idx = malloc((cap ? cap : 1) * sizeof *row->idx);
    row->val = malloc((cap ? cap : 1) * job->elem_size);
    if (!row->idx || !row->val)
        return -1;
    int32_t n = 0;
    if (job->targets) {
        for (int32_t j = 0; j < job->width; j++)
            if (T[job->targets[j]] < INFINITY)
                row->idx[n++] = j;
    } else {
        for (int32_t i = 0; i < n_touched; i++)
            if (T[touched[i]] < INFINITY)
                row->idx[n++] = mfmm_vertex_out(job->mesh, touched[i]); /* input ids */
        qsort(row->idx, (size_t)n, sizeof *row->idx, cmp_i32);
    }
    for (int32_t i = 0; i < n; i++)
        put_value(job, row->val, (size_t)i,
                  T[job->targets ? job->targets[row->idx[i]]
                                 : mfmm_vertex_in(job->mesh, row->idx[i])]);
    row->n = n;
    return settled;
}

/* ---- serial: one solver, this thread ---- */

/* Hands a finished block to the caller (dense or sparse). Returns non-zero
 * to stop, with *st the failure. */
static int deliver_block(const mfmm_rows_job *job, int32_t first, int32_t n, char *base,
                         mfmm_status *st)
{
    *st = MFMM_OK;
    if (job->sparse) {
        int r = mfmm_rows_deliver_sparse(job, first, n, (mfmm_sparse_row *)(void *)base, st);
        if (r && *st == MFMM_OK)
            *st = MFMM_ERR_CANCELLED;
        return r;
    }
    if (mfmm_rows_deliver(job, first, n, base)) {
        *st = MFMM_ERR_CANCELLED;
        return 1;
    }
    return 0;
}

static mfmm_status block_failed(mfmm_status st, int32_t first, mfmm_error *err)
{
    if (st == MFMM_ERR_CANCELLED)
        return mfmm_fail(err, st, first, "cancelled by the row callback");
    return mfmm_fail(err, st, first, "out of memory for the rows of a block from row %d",
                     (int)first);
}

static mfmm_status run_serial(const mfmm_rows_job *job, int32_t start, mfmm_error *err)
{
    size_t row_bytes = job->slot_bytes;
    int direct = job->opt->out != NULL && !job->sparse;
    int32_t block = cpu_block_rows(job, 1, direct ? 0 : 1);
    mfmm_solver *solver = NULL;
    char *buf = NULL;
    mfmm_status st = mfmm_solver_create(job->mesh, &solver);
    if (st != MFMM_OK)
        return mfmm_fail(err, st, -1, "could not create a solver");
    mfmm_solver_fix_cost(solver, job->cost, job->cost_location);
    if (!direct)
        buf = calloc((size_t)block, row_bytes);
    if (!direct && !buf) {
        st = mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for a block of %d rows",
                       (int)block);
        goto done;
    }
    mfmm_solve_options so;
    fill_solve_options(job, &so);
    int64_t settled = 0;
    for (int32_t first = start; first < job->n_sources; first += block) {
        int32_t n = job->n_sources - first < block ? job->n_sources - first : block;
        char *base = direct ? (char *)job->opt->out + (size_t)first * row_bytes : buf;
        for (int32_t i = 0; i < n; i++) {
            int64_t k = solve_row(job, solver, &so, first + i, base + (size_t)i * row_bytes);
            if (k < 0) {
                mfmm_sparse_rows_free((mfmm_sparse_row *)(void *)base, i + 1);
                st = block_failed(MFMM_ERR_OUT_OF_MEMORY, first + i, err);
                goto done;
            }
            settled += k;
            job->opt->start_fallbacks += mfmm_solver_start_fallbacks(solver);
        }
        job->opt->vertices_settled = settled;
        mfmm_status bst;
        if (deliver_block(job, first, n, base, &bst)) {
            st = block_failed(bst, first, err);
            goto done;
        }
    }
done:
    free(buf);
    mfmm_solver_destroy(solver);
    return st;
}

/* ---- threads: one solver per thread; rows handed out one at a time,
 * blocks delivered in order by the calling thread. At most two blocks are
 * in flight (a ring of two buffers when there is no caller buffer). ---- */

typedef struct pool {
    const mfmm_rows_job *job;
    pthread_mutex_t mu;
    pthread_cond_t cv_main;   /* a block completed, or a failure */
    pthread_cond_t cv_worker; /* a block was delivered, or stop */
    int32_t start, block, next_row, delivered; /* delivered: blocks */
    int32_t done[2];          /* rows finished in the two blocks in flight */
    int stop;
    mfmm_status fail;
    mfmm_error fail_err;
    char *ring;               /* 2 blocks, or NULL when writing into out */
    int64_t settled;          /* vertices settled so far */
    int64_t fallbacks;        /* exact-start vertices the marches computed instead */
} pool;

static int32_t block_len(const pool *p, int32_t b)
{
    int32_t first = p->start + b * p->block;
    int32_t n = p->job->n_sources - first;
    return n < p->block ? n : p->block;
}

static char *row_dest(const pool *p, int32_t r)
{
    size_t row_bytes = p->job->slot_bytes;
    if (!p->ring)
        return (char *)p->job->opt->out + (size_t)r * row_bytes;
    int32_t b = (r - p->start) / p->block;
    int32_t i = (r - p->start) % p->block;
    return p->ring + ((size_t)(b & 1) * (size_t)p->block + (size_t)i) * row_bytes;
}

static void pool_failed(pool *p, mfmm_status st, const mfmm_error *e)
{
    if (p->fail == MFMM_OK) {
        p->fail = st;
        if (e)
            p->fail_err = *e;
        else
            mfmm_fail(&p->fail_err, st, -1, "%s", mfmm_status_string(st));
    }
    p->stop = 1;
    pthread_cond_broadcast(&p->cv_main);
    pthread_cond_broadcast(&p->cv_worker);
}

static void *pool_worker(void *arg)
{
    pool *p = arg;
    const mfmm_rows_job *job = p->job;
    mfmm_solver *solver = NULL;
    mfmm_status st = mfmm_solver_create(job->mesh, &solver);
    if (st == MFMM_OK)
        mfmm_solver_fix_cost(solver, job->cost, job->cost_location);
    mfmm_solve_options so;
    fill_solve_options(job, &so);
    pthread_mutex_lock(&p->mu);
    if (st != MFMM_OK)
        pool_failed(p, st, NULL);
    while (!p->stop && p->next_row < job->n_sources) {
        int32_t r = p->next_row;
        int32_t b = (r - p->start) / p->block;
        if (b >= p->delivered + 2) { /* its block's slot is still in use */
            pthread_cond_wait(&p->cv_worker, &p->mu);
            continue;
        }
        p->next_row++;
        pthread_mutex_unlock(&p->mu);
        int64_t k = solve_row(job, solver, &so, r, row_dest(p, r));
        pthread_mutex_lock(&p->mu);
        if (k < 0) {
            pool_failed(p, MFMM_ERR_OUT_OF_MEMORY, NULL);
            break;
        }
        p->settled += k;
        p->fallbacks += mfmm_solver_start_fallbacks(solver);
        if (++p->done[b & 1] == block_len(p, b))
            pthread_cond_broadcast(&p->cv_main);
    }
    pthread_mutex_unlock(&p->mu);
    mfmm_solver_destroy(solver);
    return NULL;
}

static int default_threads(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : (n > 256 ? 256 : (int)n);
}

static mfmm_status run_threads(const mfmm_rows_job *job, int32_t start, mfmm_error *err)
{
    int n_threads = job->opt->n_threads > 0 ? job->opt->n_threads : default_threads();
    int32_t rows = job->n_sources - start;
    if (rows <= 0)
        return MFMM_OK;
    if (n_threads > rows)
        n_threads = rows;
    if (n_threads == 1)
        return run_serial(job, start, err);

    pool p;
    memset(&p, 0, sizeof p);
    p.job = job;
    p.start = p.next_row = start;
    p.fail = MFMM_OK;
    int use_ring = job->opt->out == NULL || job->sparse;
    p.block = cpu_block_rows(job, n_threads, use_ring ? 2 : 0);
    if (use_ring) {
        p.ring = calloc(2 * (size_t)p.block, job->slot_bytes);
        if (!p.ring)
            return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1,
                             "out of memory for two blocks of %d rows", (int)p.block);
    }
    /* the exact start's tables: the mesh's, built now if not yet (exact.h) */
    const mfmm_exact_tables *tables = NULL;
    if (mfmm_exact_start_on(job->opt->exact_start_radius) &&
        mfmm_exact_tables_of(job->mesh, &tables) != MFMM_OK) {
        free(p.ring);
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for the exact start");
    }
    pthread_t *tid = malloc((size_t)n_threads * sizeof *tid);
    if (!tid) {
        free(p.ring);
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for threads");
    }
    if (pthread_mutex_init(&p.mu, NULL) != 0) {
        free(tid);
        free(p.ring);
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "could not create a mutex");
    }
    if (pthread_cond_init(&p.cv_main, NULL) != 0) {
        pthread_mutex_destroy(&p.mu);
        free(tid);
        free(p.ring);
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "could not create a condition");
    }
    if (pthread_cond_init(&p.cv_worker, NULL) != 0) {
        pthread_cond_destroy(&p.cv_main);
        pthread_mutex_destroy(&p.mu);
        free(tid);
        free(p.ring);
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "could not create a condition");
    }
    int started = 0;
    for (; started < n_threads; started++)
        if (pthread_create(&tid[started], NULL, pool_worker, &p) != 0)
            break;

    mfmm_status st = MFMM_OK;
    pthread_mutex_lock(&p.mu);
    if (started == 0)
        pool_failed(&p, MFMM_ERR_OUT_OF_MEMORY, NULL);
    int32_t n_blocks = (rows + p.block - 1) / p.block;
    for (int32_t b = 0; b < n_blocks; b++) {
        int32_t n = block_len(&p, b);
        while (!p.stop && p.done[b & 1] < n)
            pthread_cond_wait(&p.cv_main, &p.mu);
        if (p.stop)
            break;
        pthread_mutex_unlock(&p.mu);
        int32_t first = start + b * p.block;
        job->opt->vertices_settled = p.settled;
        mfmm_status bst;
        int cancel = deliver_block(job, first, n, row_dest(&p, first), &bst);
        pthread_mutex_lock(&p.mu);
        if (cancel) {
            st = block_failed(bst, first, err);
            p.stop = 1;
            pthread_cond_broadcast(&p.cv_worker);
            break;
        }
        p.done[b & 1] = 0;
        p.delivered++;
        pthread_cond_broadcast(&p.cv_worker);
    }
    pthread_mutex_unlock(&p.mu);
    for (int i = 0; i < started; i++)
        pthread_join(tid[i], NULL);
    job->opt->vertices_settled = p.settled;
    job->opt->start_fallbacks += p.fallbacks;
    if (p.ring && job->sparse) /* rows of blocks not delivered (a failure) */
        mfmm_sparse_rows_free((mfmm_sparse_row *)(void *)p.ring, 2 * p.block);
    if (st == MFMM_OK && p.fail != MFMM_OK) {
        st = p.fail;
        if (err)
            *err = p.fail_err;
    }
    pthread_cond_destroy(&p.cv_worker);
    pthread_cond_destroy(&p.cv_main);
    pthread_mutex_destroy(&p.mu);
    free(tid);
    free(p.ring);
    return st;
}

/* ---- the entry point ---- */

mfmm_status mfmm_distance_matrix(const mfmm_mesh *mesh, const int32_t *sources,
                                 int32_t n_sources, mfmm_matrix_options *options,
                                 mfmm_error *err)
{
    mfmm_ok(err);
    if (!mesh)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "mesh is NULL");
    if (!options)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "options is NULL");
    mfmm_matrix_options *o = options;
    if (mfmm_check_struct_size(o, sizeof *o, "mfmm_matrix_options", err) != MFMM_OK)
        return MFMM_ERR_BAD_ARGUMENT;
    o->backend_used = o->backend;
    o->fallback_reason[0] = '\0';
    int32_t nv = mesh->nv;
    o->vertices_settled = 0;
    o->start_fallbacks = 0;
    if (!o->out && !o->on_rows && !o->on_sparse)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1,
                         "options give neither an out buffer nor an on_rows or on_sparse callback");
    if (o->on_sparse && (o->out || o->on_rows))
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1,
                         "on_sparse (sparse rows) cannot be combined with out or on_rows (dense rows)");
    if (o->n_targets < 0 || (o->n_targets > 0 && !o->targets) || (o->targets && o->n_targets < 1))
        return mfmm_fail(err, MFMM_ERR_BAD_COUNT, o->n_targets,
                         "n_targets is %ld but targets is %s (give both, n_targets >= 1, or neither)",
                         (long)o->n_targets, o->targets ? "set" : "NULL");
    if (o->on_sparse && o->backend == MFMM_BACKEND_OPENCL)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1,
                         "the OpenCL backend computes dense rows only; use threads (or auto) "
                         "for sparse rows");
    if ((int)o->backend < MFMM_BACKEND_AUTO || (int)o->backend > MFMM_BACKEND_OPENCL)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1, "unknown backend %d", (int)o->backend);
    if (o->dtype != MFMM_FLOAT32 && o->dtype != MFMM_FLOAT64)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1, "unknown dtype %d", (int)o->dtype);
    if (isnan(o->max_distance))
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1, "max_distance is NaN");
    if (o->max_distance < 0.0)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1,
                         "max_distance is %g; it must be >= 0 (+inf: no limit)", o->max_distance);
    if (mfmm_check_exact_start(o->exact_start_radius, err) != MFMM_OK)
        return MFMM_ERR_BAD_ARGUMENT;
    if (o->n_threads < 0)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1, "n_threads is %d, must be >= 0",
                         (int)o->n_threads);
    if (sources == NULL && n_sources != nv)
        return mfmm_fail(err, MFMM_ERR_BAD_COUNT, n_sources,
                         "sources is NULL (all vertices), so n_sources must be nv = %d, not %d",
                         (int)nv, (int)n_sources);
    if (n_sources < 1)
        return mfmm_fail(err, MFMM_ERR_BAD_COUNT, n_sources,
                         "n_sources is %d, must be >= 1", (int)n_sources);
    /* Rows re-read the sources and the cost while out fills up: the job works
     * on its own copies, taken before any row is written and checked there,
     * so an out buffer (or a callback) that overwrites the caller's arrays
     * cannot change later rows. */
    int32_t *own_sources = malloc((size_t)n_sources * sizeof *own_sources);
    if (!own_sources)
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for %d source ids",
                         (int)n_sources);
    for (int32_t i = 0; i < n_sources; i++)
        own_sources[i] = sources ? sources[i] : i;
    for (int32_t i = 0; i < n_sources; i++)
        if (own_sources[i] < 0 || own_sources[i] >= nv) {
            int32_t bad = own_sources[i];
            free(own_sources);
            return mfmm_fail(err, MFMM_ERR_BAD_SOURCE, i, "source %d is vertex %d, outside [0, %d)",
                             (int)i, (int)bad, (int)nv);
        }
    sources = own_sources;
    int32_t *own_targets = NULL;
    if (o->targets) {
        own_targets = malloc((size_t)o->n_targets * sizeof *own_targets);
        if (!own_targets) {
            free(own_sources);
            return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for %d target ids",
                             (int)o->n_targets);
        }
        memcpy(own_targets, o->targets, (size_t)o->n_targets * sizeof *own_targets);
        for (int32_t j = 0; j < o->n_targets; j++)
            if (own_targets[j] < 0 || own_targets[j] >= nv) {
                int32_t bad = own_targets[j];
                free(own_sources);
                free(own_targets);
                return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, j,
                                 "target %d is vertex %d, outside [0, %d)", (int)j, (int)bad,
                                 (int)nv);
            }
    }
    int cost_location = o->cost ? (int)o->cost_location : 0;
    double *own_cost = NULL;
    if (o->cost && (o->cost_location == MFMM_COST_PER_VERTEX || o->cost_location == MFMM_COST_PER_FACE)) {
        size_t n = o->cost_location == MFMM_COST_PER_VERTEX ? (size_t)nv : (size_t)mesh->nf_in;
        own_cost = malloc(n * sizeof *own_cost);
        if (!own_cost) {
            free(own_sources);
            free(own_targets);
            return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for the cost");
        }
        memcpy(own_cost, o->cost, n * sizeof *own_cost);
    }
    const double *cost = own_cost ? own_cost : o->cost;
    mfmm_status cst = mfmm_check_cost(mesh, cost, o->cost_location, err);
    if (cst == MFMM_OK && o->dtype == MFMM_FLOAT32) {
        /* a float32 entry above FLT_MAX would read as +inf, "not reached" */
        double bound = fmin(mfmm_distance_bound(mesh, cost, o->cost_location), o->max_distance);
        if (!(bound <= FLT_MAX))
            cst = mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1,
                            "distances may exceed float32's range (%g) on this mesh (its edges "
                            "are %g long in all%s): use float64, or rescale",
                            (double)FLT_MAX, mesh->info.mean_edge_length * mesh->info.n_edges,
                            cost ? ", times the largest cost" : "");
    }
    /* ids and costs in the mesh's internal order (core/order.h), after the
     * checks (whose messages name the caller's ids) */
    double *mapped_cost = NULL;
    if (cst == MFMM_OK && own_cost) {
        int per_vertex = o->cost_location == MFMM_COST_PER_VERTEX;
        mapped_cost = malloc((per_vertex ? (size_t)nv : (size_t)mesh->nf) * sizeof *mapped_cost);
        if (mapped_cost && per_vertex)
            mfmm_order_values_in(mesh, own_cost, mapped_cost);
        else if (mapped_cost)
            mfmm_order_face_values_in(mesh, own_cost, mapped_cost);
        else
            cst = mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for the cost");
        free(own_cost);
        own_cost = mapped_cost;
        cost = own_cost;
    }
    if (cst != MFMM_OK) {
        free(own_sources);
        free(own_targets);
        free(own_cost);
        return cst;
    }
    mfmm_order_ids_in(mesh, own_sources, n_sources, own_sources);
    if (own_targets)
        mfmm_order_ids_in(mesh, own_targets, o->n_targets, own_targets);
    mfmm_rows_job job;
    memset(&job, 0, sizeof job);
    job.mesh = mesh;
    job.sources = sources;
    job.n_sources = n_sources;
    job.opt = o;
    job.cost = cost;
    job.cost_location = cost_location;
    job.elem_size = o->dtype == MFMM_FLOAT64 ? sizeof(double) : sizeof(float);
    job.budget = o->memory_limit ? o->memory_limit : MFMM_DEFAULT_BUDGET;
    job.targets = own_targets;
    job.width = own_targets ? o->n_targets : nv;
    job.sparse = o->on_sparse != NULL;
    job.slot_bytes = job.sparse ? sizeof(mfmm_sparse_row) : (size_t)job.width * job.elem_size;

    mfmm_status st;
    switch (o->backend) {
    case MFMM_BACKEND_SERIAL:
        st = run_serial(&job, 0, err);
        break;
    case MFMM_BACKEND_THREADS:
        st = run_threads(&job, 0, err);
        break;
    case MFMM_BACKEND_OPENCL: {
        int32_t done = 0;
        st = mfmm_opencl_rows(&job, 0, &done, err);
        break;
    }
    default: { /* auto: OpenCL when it keeps every compute unit busy, else
                * threads from the first row not delivered, saying why */
        int32_t done = 0;
        if (job.sparse) {
            o->backend_used = MFMM_BACKEND_THREADS;
            snprintf(o->fallback_reason, sizeof o->fallback_reason,
                     "the OpenCL backend computes dense rows only, not sparse rows");
            st = run_threads(&job, 0, err);
            break;
        }
        mfmm_error cl_err;
        o->backend_used = MFMM_BACKEND_OPENCL;
        job.full_batches = 1;
        st = mfmm_opencl_rows(&job, 0, &done, &cl_err);
        if (st == MFMM_ERR_NO_OPENCL || st == MFMM_ERR_OPENCL_BUILD ||
            st == MFMM_ERR_OPENCL_RUNTIME || st == MFMM_ERR_OUT_OF_MEMORY) {
            o->backend_used = MFMM_BACKEND_THREADS;
            snprintf(o->fallback_reason, sizeof o->fallback_reason, "%s", cl_err.message);
            st = run_threads(&job, done, err);
        } else if (st != MFMM_OK && err) {
            *err = cl_err;
        }
        break;
    }
    }
    if (st == MFMM_OK)
        mfmm_ok(err);
    free(own_sources);
    free(own_targets);
    free(own_cost);
    return st;
}
