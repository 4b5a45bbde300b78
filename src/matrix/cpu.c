/* The CPU engines of a matrix job: one solver marching the rows in order
 * (serial), or one solver per thread, rows handed out one at a time and
 * delivered in order by the calling thread (threads). */
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/error.h"
#include "cpu.h"
#include "exact/exact.h"
#include "exact/slots.h"
#include "mesh/order.h"
#include "solve/solve.h"
#include "start/seed.h"

/* Rows per block for the CPU engines: the budget less the solvers'
 * workspaces, over `ring` blocks of rows. */
static int32_t cpu_block_rows(const mfmm_rows_job *job, int n_workers, int ring)
{
    size_t nv = (size_t)job->mesh->nv;
    size_t row_bytes = job->slot_bytes;
    size_t work = (size_t)n_workers * nv * 32; /* solver + a float64 row */
    /* each solver's exact-start or window state (the tables are the mesh's,
     * not the job's) */
    if (job->opt->method == MFMM_METHOD_WINDOWS)
        work += (size_t)n_workers * mfmm_slots_bytes(job->mesh);
    else if (mfmm_exact_start_on(job->opt->exact_start_radius))
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
    so->method = job->opt->method;
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
        /* the row's one pass: gathered into input order (mesh/order.h) */
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

/* The exact tables a job's rows read: the mesh's, made now, and built
 * everywhere at once when its rows' patches (a few hundred vertices each)
 * would reach most tiles anyway, so that no row looks for the tiles it
 * needs. 0, or -1 when out of memory. */
static int cpu_exact_tables(const mfmm_rows_job *job)
{
    if (!mfmm_exact_start_on(job->opt->exact_start_radius) &&
        job->opt->method != MFMM_METHOD_WINDOWS)
        return 0;
    const mfmm_exact_tables *tables = NULL;
    if (mfmm_exact_tables_of(job->mesh, &tables) != MFMM_OK)
        return -1;
    if ((int64_t)job->n_sources * 256 >= job->mesh->nv)
        mfmm_exact_tables_ensure(tables, NULL, 0, INFINITY);
    return 0;
}

mfmm_status mfmm_rows_serial(const mfmm_rows_job *job, int32_t start, mfmm_error *err)
{
    size_t row_bytes = job->slot_bytes;
    int direct = job->opt->out != NULL && !job->sparse;
    int32_t block = cpu_block_rows(job, 1, direct ? 0 : 1);
    mfmm_solver *solver = NULL;
    char *buf = NULL;
    if (cpu_exact_tables(job) != 0)
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for the exact start");
    mfmm_status st = mfmm_solver_create(job->mesh, &solver);
    if (st != MFMM_OK)
        return mfmm_fail(err, st, -1, "could not create a solver");
    mfmm_solver_fix_cost(solver, job->cost, job->cost_location);
    mfmm_solver_expect_rows(solver, job->n_sources);
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
            job->info->start_fallbacks += mfmm_solver_start_fallbacks(solver);
        }
        job->info->vertices_settled = settled;
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
    if (st == MFMM_OK) {
        mfmm_solver_fix_cost(solver, job->cost, job->cost_location);
        mfmm_solver_expect_rows(solver, job->n_sources);
    }
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

mfmm_status mfmm_rows_threads(const mfmm_rows_job *job, int32_t start, mfmm_error *err)
{
    int n_threads = job->opt->n_threads > 0 ? job->opt->n_threads : default_threads();
    int32_t rows = job->n_sources - start;
    if (rows <= 0)
        return MFMM_OK;
    if (n_threads > rows)
        n_threads = rows;
    if (n_threads == 1)
        return mfmm_rows_serial(job, start, err);

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
    if (cpu_exact_tables(job) != 0) {
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
        /* read under the lock: the workers are adding the next block's */
        job->info->vertices_settled = p.settled;
        pthread_mutex_unlock(&p.mu);
        int32_t first = start + b * p.block;
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
    job->info->vertices_settled = p.settled;
    job->info->start_fallbacks += p.fallbacks;
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
