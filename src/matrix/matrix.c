/* mfmm_distance_matrix: many sources, rows handed out in blocks, on the
 * serial core (one thread or many) or on OpenCL (opencl/). */
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/error.h"
#include "exact/exact.h"
#include "mesh/check.h"
#include "cpu.h"
#include "opencl/context.h"
#include "rows.h"
#include "mesh/order.h"
#include "start/seed.h"
#include "solve/solve.h"

/* ---- the entry point ---- */

static mfmm_status matrix_run(const mfmm_mesh *mesh, const int32_t *sources, int32_t n_sources,
                              const mfmm_matrix_options *options, mfmm_matrix_info *info,
                              mfmm_error *err);

mfmm_status mfmm_distance_matrix(const mfmm_mesh *mesh, const int32_t *sources,
                                 int32_t n_sources, const mfmm_matrix_options *options,
                                 mfmm_matrix_info *info, mfmm_error *err)
{
    mfmm_ok(err);
    if (info && mfmm_check_info_size(info) != MFMM_OK)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1,
                         "info->struct_size is below sizeof(size_t): set it to "
                         "sizeof(mfmm_matrix_info)");
    /* the results, written to the caller's info (its struct_size) on return */
    mfmm_matrix_info all;
    memset(&all, 0, sizeof all);
    all.struct_size = sizeof all;
    mfmm_status st = matrix_run(mesh, sources, n_sources, options, &all, err);
    if (info)
        mfmm_write_info(info, &all, sizeof all);
    return st;
}

static mfmm_status matrix_run(const mfmm_mesh *mesh, const int32_t *sources, int32_t n_sources,
                              const mfmm_matrix_options *options, mfmm_matrix_info *info,
                              mfmm_error *err)
{
    if (!mesh)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "mesh is NULL");
    if (!options)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "options is NULL");
    mfmm_matrix_options opt;
    mfmm_matrix_options_init(&opt);
    if (mfmm_read_options(&opt, options, sizeof opt, "mfmm_matrix_options", err) != MFMM_OK)
        return MFMM_ERR_BAD_ARGUMENT;
    const mfmm_matrix_options *o = &opt;
    info->backend_used = o->backend;
    int32_t nv = mesh->nv;
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
    if (mfmm_check_method((int)o->method, o->cost != NULL, err) != MFMM_OK)
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
    /* ids and costs in the mesh's internal order (mesh/order.h), after the
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
    job.info = info;
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
        st = mfmm_rows_serial(&job, 0, err);
        break;
    case MFMM_BACKEND_THREADS:
        st = mfmm_rows_threads(&job, 0, err);
        break;
    case MFMM_BACKEND_OPENCL: {
        int32_t done = 0;
        st = mfmm_opencl_rows(&job, 0, &done, err);
        break;
    }
    default: { /* auto: OpenCL when it keeps every compute unit busy, else
                * threads from the first row not delivered, saying why */
        int32_t done = 0;
        if (job.sparse || o->method == MFMM_METHOD_WINDOWS) {
            info->backend_used = MFMM_BACKEND_THREADS;
            snprintf(info->backend_reason, sizeof info->backend_reason, "%s",
                     job.sparse ? "the OpenCL backend computes dense rows only, not sparse rows"
                                : "auto runs the window method on threads (backend opencl "
                                  "runs it on an OpenCL device)");
            st = mfmm_rows_threads(&job, 0, err);
            break;
        }
        mfmm_error cl_err;
        info->backend_used = MFMM_BACKEND_OPENCL;
        job.full_batches = 1;
        st = mfmm_opencl_rows(&job, 0, &done, &cl_err);
        if (st == MFMM_ERR_NO_OPENCL || st == MFMM_ERR_OPENCL_BUILD ||
            st == MFMM_ERR_OPENCL_RUNTIME || st == MFMM_ERR_OUT_OF_MEMORY) {
            info->backend_used = MFMM_BACKEND_THREADS;
            snprintf(info->backend_reason, sizeof info->backend_reason, "%s", cl_err.message);
            st = mfmm_rows_threads(&job, done, err);
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
