/* A matrix job's rows on an OpenCL device: the mesh uploaded once, then
 * batches of rows, one work-item per source, each batch's seeds computed
 * on the host as the serial solver computes them (start/seed.h), its rows
 * read back and delivered while the next batch runs (rows.h). The window
 * method's rows upload the mesh's exact tables instead, and each item's
 * arrays lie in one slice of a workspace buffer (kernels/windows_rows.cl). */
#ifdef MESHFMM_HAVE_OPENCL

#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "exact/exact.h"
#include "exact/slots.h"
#include "matrix/rows.h"
#include "mesh/check.h"
#include "mesh/spokes.h"
#include "rows.h"
#include "start/seed.h"

/* the mesh's arrays (read-only), then a batch's workspaces (from MB_LABEL);
 * MB_FR to MB_FLAT and MB_WS: the window method's, which also takes the
 * records' costs in MB_UNIFORM and the vertices' in MB_COST */
enum { MB_OFFSET, MB_CORNER, MB_CORNERS, MB_COST, MB_SOURCES, MB_STRIP, MB_UNIFORM, MB_TARGETS, MB_ORDER, MB_VIRTS, MB_STRIPOFF, MB_VFIRST, MB_SPOKEOFF, MB_SPOKES,
       MB_FR, MB_VFOFF, MB_VFCORNER, MB_FACEIN, MB_NMHE, MB_NMNEXT, MB_FLAT, MB_LABEL, MB_KEY, MB_VERT,
       MB_POS, MB_T, MB_WS, MB_OUT, MB_COUNT };

static int windows_job(const mfmm_rows_job *job)
{
    return job->opt->method == MFMM_METHOD_WINDOWS;
}

/* Bytes per work-item on the device (workspace and output row), and on the
 * host (two blocks when rows are not read straight into the caller's buffer). */
static size_t item_bytes(const mfmm_rows_job *job, int direct)
{
    size_t nv = (size_t)job->mesh->nv, w = (size_t)job->width;
    /* label, heap key, vertex and position, T apart from the output row;
     * the window method's block of arrays (slots_core.h) */
    size_t b = windows_job(job) ? mfmm_slots_block_bytes(job->mesh)
                                : nv * (1 + 8 + 4 + 4 + 8);
    b += w * job->elem_size;
    if (!direct)
        b += 2 * w * job->elem_size;
    return b;
}

/* Rows per batch: as many as the budget holds (at most 4096), in whole
 * rounds over the compute units. With the default budget (memory_limit 0) a
 * batch holds at least one row per compute unit, so that every core works
 * whatever the mesh size (a 16 MiB budget held one row of a 227k-vertex
 * mesh, and OpenCL ran on one core). */
static int32_t batch_rows(const ocl *cl, const mfmm_rows_job *job, int direct, int32_t rows)
{
    size_t nv = (size_t)job->mesh->nv;
    size_t budget = job->budget;
    size_t per_round = (size_t)cl->compute_units * item_bytes(job, direct);
    if (job->opt->memory_limit == 0 && budget < per_round)
        budget = per_round;
    if (budget > cl->global_mem / 2)
        budget = (size_t)(cl->global_mem / 2);
    size_t b = budget / item_bytes(job, direct);
    /* the largest buffer: 8 nv per item, or the window method's blocks */
    size_t by_alloc = (size_t)(cl->max_alloc / (windows_job(job) ? mfmm_slots_block_bytes(job->mesh)
                                                                  : nv * 8));
    if (b > by_alloc)
        b = by_alloc;
    if (b > 4096)
        b = 4096;
    size_t cu = cl->compute_units;
    if (b > cu)
        b -= b % cu; /* whole rounds over the compute units */
    if (b < 1)
        b = 1;
    if (b > (size_t)rows)
        b = (size_t)rows;
    return (int32_t)b;
}

static mfmm_status runtime_fail(mfmm_error *err, const char *what, cl_int e)
{
    return mfmm_fail(err, MFMM_ERR_OPENCL_RUNTIME, -1, "%s: %s (%d)", what, mfmm_cl_error_name(e),
                     (int)e);
}

/* OpenCL keeps fewer compute units busy than threads would cores: a batch
 * smaller than both the compute units and the rows left. */
static int starved(const ocl *cl, int32_t batch, int32_t rows)
{
    int32_t want = (int32_t)(cl->compute_units < (cl_uint)rows ? cl->compute_units : (cl_uint)rows);
    return batch < want;
}

/* A batch's exact-start seeds (start/seed.h), as the kernel reads them:
 * idx[0 .. count] the rows' ranges [idx[i], idx[i + 1]) of idx (vertices)
 * and val (values; its first count + 1 entries unused); n entries used. */
typedef struct seed_buf {
    int32_t *idx;
    double *val;
    size_t cap, n;
    int64_t fallbacks; /* patch vertices left to the march (mfmm_exact_start) */
} seed_buf;

static int seed_room(seed_buf *b, size_t need)
{
    if (need <= b->cap)
        return 0;
    size_t cap = b->cap ? b->cap : 1024;
    while (cap < need)
        cap *= 2;
    int32_t *idx = realloc(b->idx, cap * sizeof *idx);
    if (idx)
        b->idx = idx;
    double *val = idx ? realloc(b->val, cap * sizeof *val) : NULL;
    if (val)
        b->val = val;
    if (!idx || !val)
        return -1;
    b->cap = cap;
    return 0;
}

/* The seeds of rows [first, first + count), computed as the serial solver
 * computes them (solve/solve.c's seed_source with a vertex source at value 0). */
static mfmm_status batch_seeds(const mfmm_rows_job *job, mfmm_exact_ws **ws,
                               const double *uniform, int32_t first, int32_t count, seed_buf *b)
{
    size_t pos = (size_t)count + 1;
    if (seed_room(b, pos))
        return MFMM_ERR_OUT_OF_MEMORY;
    for (size_t i = 0; i < pos; i++)
        b->val[i] = 0.0;
    for (int32_t i = 0; i < count; i++) {
        mfmm_source src;
        memset(&src, 0, sizeof src);
        src.vertex = job->sources[first + i];
        src.face = -1;
        src.value = 0.0;
        int32_t n = 0;
        const int32_t *pv = NULL;
        const double *pd = NULL;
        double f = 1.0;
        int32_t n_fallback = 0;
        mfmm_status st = mfmm_exact_start(job->mesh, ws, &src, job->opt->exact_start_radius,
                                          job->opt->max_distance, job->cost,
                                          job->cost ? uniform : NULL, &n, &pv, &pd, &f,
                                          &n_fallback);
        if (st != MFMM_OK)
            return st;
        b->fallbacks += n_fallback;
        b->idx[i] = (int32_t)pos;
        if (seed_room(b, pos + (size_t)(n > 0 ? n : 1)))
            return MFMM_ERR_OUT_OF_MEMORY;
        if (n == 0) { /* the straight start of a vertex: the vertex */
            b->idx[pos] = src.vertex;
            b->val[pos++] = src.value;
        }
        for (int32_t j = 0; j < n; j++) {
            b->idx[pos] = pv[j];
            b->val[pos++] = src.value + f * pd[j];
        }
    }
    b->idx[count] = (int32_t)pos;
    b->n = pos;
    return MFMM_OK;
}

/* One call's run of rows: its device handles (the context's, plus its own
 * queue and kernel), buffers, and what its batches share. */
typedef struct run {
    const mfmm_rows_job *job;
    ocl cl;
    const mfmm_cl_api *api;
    int32_t start, rows, batch;
    int f64, direct, exact, windows;
    size_t nv, row_bytes;
    cl_mem mem[MB_COUNT];
    char *host;          /* two batches of rows, when not read into opt->out */
    double *uniform;     /* the cost around each vertex (march.h), or NULL */
    cl_event ev[2];      /* the reads of the two batches in flight */
    double one;          /* stands in for absent arrays */
    int32_t no_target;
    cl_int n_targets, use_spokes;
    cl_uint seed_arg;    /* the kernel's first seed argument */
    mfmm_exact_ws *ews;
    seed_buf sb;
    uint8_t *flat;       /* the window method's flat flags (mfmm_slots_flat) */
    double *fcost;       /* the window method's record costs (mfmm_slots_face_cost) */
    double *vcost;       /* and vertex costs (per vertex), relative to cost_scale */
    double cost_scale;   /* the least cost (1.0 without a cost) */
    cl_ulong ws_stride;  /* the window method's bytes per item */
} run;

/* The window method's arrays: the mesh's exact tables, built everywhere,
 * its flat flags, the job's sources, targets and vertex order, and with a
 * cost the records' costs and the vertices' (per vertex). */
static mfmm_status run_upload_windows(run *r, mfmm_error *err)
{
    const mfmm_rows_job *job = r->job;
    const mfmm_mesh *mesh = job->mesh;
    const mfmm_cl_api *api = r->api;
    cl_mem *mem = r->mem;
    size_t nv = r->nv, nf = (size_t)mesh->nf;
    mfmm_slots_tables t;
    if (mfmm_slots_tables_of(mesh, &t) != MFMM_OK)
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for the exact tables");
    r->flat = malloc(nv + 1);
    if (!r->flat)
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for %d flags", (int)nv);
    mfmm_slots_flat_of(mesh, r->flat);
    cl_int e = CL_SUCCESS;
    cl_mem_flags ro = CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR;
    cl_context c = r->cl.context;
    /* an empty array (no non-manifold edge) stands in as one int */
    const void *nm_he = t.n_nm ? (const void *)t.nm_he : (const void *)&r->no_target;
    const void *nm_next = t.n_nm ? (const void *)t.nm_next : (const void *)&r->no_target;
    size_t n_nm = t.n_nm ? (size_t)t.n_nm : 1;
    mem[MB_FR] = api->clCreateBuffer(c, ro, nf * t.fr_size, (void *)t.fr, &e);
    if (e == CL_SUCCESS)
        mem[MB_VFOFF] = api->clCreateBuffer(c, ro, (nv + 1) * sizeof(int32_t),
                                            (void *)t.vf_offset, &e);
    if (e == CL_SUCCESS)
        mem[MB_VFCORNER] = api->clCreateBuffer(c, ro, 3 * nf * sizeof(int32_t),
                                               (void *)t.vf_corner, &e);
    if (e == CL_SUCCESS)
        mem[MB_FACEIN] = api->clCreateBuffer(c, ro, nf * sizeof(int32_t), (void *)t.face_in, &e);
    if (e == CL_SUCCESS)
        mem[MB_NMHE] = api->clCreateBuffer(c, ro, n_nm * sizeof(int32_t), (void *)nm_he, &e);
    if (e == CL_SUCCESS)
        mem[MB_NMNEXT] = api->clCreateBuffer(c, ro, n_nm * sizeof(int32_t), (void *)nm_next, &e);
    if (e == CL_SUCCESS)
        mem[MB_FLAT] = api->clCreateBuffer(c, ro, nv, r->flat, &e);
    if (e == CL_SUCCESS)
        mem[MB_SOURCES] = api->clCreateBuffer(c, ro, (size_t)job->n_sources * sizeof(int32_t),
                                              (void *)job->sources, &e);
    if (e == CL_SUCCESS)
        mem[MB_TARGETS] = api->clCreateBuffer(c, ro,
                                              (job->targets ? (size_t)job->width : 1) * sizeof(int32_t),
                                              job->targets ? (void *)job->targets : (void *)&r->no_target,
                                              &e);
    if (e == CL_SUCCESS)
        mem[MB_ORDER] = api->clCreateBuffer(c, ro, nv * sizeof(int32_t), mesh->to_internal, &e);
    r->cost_scale = 1.0;
    if (e == CL_SUCCESS && job->cost) {
        r->fcost = malloc((nf + 1) * sizeof *r->fcost);
        r->vcost = malloc((nv + 1) * sizeof *r->vcost);
        if (!r->fcost || !r->vcost)
            return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for %d costs",
                             (int)(nf + nv));
        r->cost_scale = mfmm_slots_face_cost(mesh, job->cost, job->cost_location, r->fcost,
                                             r->vcost);
    }
    /* no cost: one value stands in for each cost array (unread) */
    if (e == CL_SUCCESS)
        mem[MB_UNIFORM] = api->clCreateBuffer(c, ro, (job->cost ? nf : 1) * sizeof(double),
                                              job->cost ? (void *)r->fcost : (void *)&r->one, &e);
    if (e == CL_SUCCESS) {
        int per_vertex = job->cost && job->cost_location == 1;
        mem[MB_COST] = api->clCreateBuffer(c, ro, (per_vertex ? nv : 1) * sizeof(double),
                                           per_vertex ? (void *)r->vcost : (void *)&r->one, &e);
    }
    if (e != CL_SUCCESS)
        return runtime_fail(err, "uploading the exact tables", e);
    return MFMM_OK;
}

/* The window method's kernel arguments that stay the same for every batch
 * (kernels/windows_rows.cl; first and count, 11 and 12, per batch). */
static mfmm_status run_set_args_windows(run *r, mfmm_error *err)
{
    const mfmm_rows_job *job = r->job;
    const mfmm_cl_api *api = r->api;
    cl_kernel k = r->cl.kernel;
    cl_mem *mem = r->mem;
    mfmm_slots_tables t;
    if (mfmm_slots_tables_of(job->mesh, &t) != MFMM_OK)
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for the exact tables");
    cl_int nvi = (cl_int)r->nv, nfi = (cl_int)job->mesh->nf, n_nm = t.n_nm;
    /* the solve runs in units of the least cost (mfmm_slots_run) */
    cl_double maxd = job->opt->max_distance / r->cost_scale, scale = r->cost_scale;
    cl_ulong stride = r->ws_stride;
    cl_int loc = job->cost ? (cl_int)job->cost_location : 0;
    cl_int e = api->clSetKernelArg(k, 0, sizeof nvi, &nvi);
    e |= api->clSetKernelArg(k, 1, sizeof nfi, &nfi);
    e |= api->clSetKernelArg(k, 2, sizeof(cl_mem), &mem[MB_FR]);
    e |= api->clSetKernelArg(k, 3, sizeof(cl_mem), &mem[MB_VFOFF]);
    e |= api->clSetKernelArg(k, 4, sizeof(cl_mem), &mem[MB_VFCORNER]);
    e |= api->clSetKernelArg(k, 5, sizeof(cl_mem), &mem[MB_FACEIN]);
    e |= api->clSetKernelArg(k, 6, sizeof(cl_mem), &mem[MB_NMHE]);
    e |= api->clSetKernelArg(k, 7, sizeof(cl_mem), &mem[MB_NMNEXT]);
    e |= api->clSetKernelArg(k, 8, sizeof n_nm, &n_nm);
    e |= api->clSetKernelArg(k, 9, sizeof(cl_mem), &mem[MB_FLAT]);
    e |= api->clSetKernelArg(k, 10, sizeof(cl_mem), &mem[MB_SOURCES]);
    e |= api->clSetKernelArg(k, 13, sizeof maxd, &maxd);
    e |= api->clSetKernelArg(k, 14, sizeof(cl_mem), &mem[MB_TARGETS]);
    e |= api->clSetKernelArg(k, 15, sizeof r->n_targets, &r->n_targets);
    e |= api->clSetKernelArg(k, 16, sizeof(cl_mem), &mem[MB_ORDER]);
    e |= api->clSetKernelArg(k, 17, sizeof(cl_mem), &mem[MB_WS]);
    e |= api->clSetKernelArg(k, 18, sizeof stride, &stride);
    e |= api->clSetKernelArg(k, 19, sizeof(cl_mem), &mem[MB_OUT]);
    e |= api->clSetKernelArg(k, 20, sizeof(cl_mem), &mem[MB_UNIFORM]);
    e |= api->clSetKernelArg(k, 21, sizeof(cl_mem), &mem[MB_COST]);
    e |= api->clSetKernelArg(k, 22, sizeof loc, &loc);
    e |= api->clSetKernelArg(k, 23, sizeof scale, &scale);
    if (e != CL_SUCCESS)
        return runtime_fail(err, "clSetKernelArg", e);
    return MFMM_OK;
}

/* Uploads the mesh (read-only, used in place where the driver allows), the
 * job's sources, cost, targets and the cost around each vertex. */
static mfmm_status run_upload(run *r, mfmm_error *err)
{
    const mfmm_rows_job *job = r->job;
    const mfmm_mesh *mesh = job->mesh;
    const mfmm_cl_api *api = r->api;
    cl_mem *mem = r->mem;
    size_t nv = r->nv;
    cl_int e = CL_SUCCESS;
    cl_mem_flags ro = CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR;
    /* (the march's arrays, march.h: x's faces, face records, virtual edges) */
    size_t n_wedge = 3 * (size_t)mesh->nf;
    mem[MB_OFFSET] = api->clCreateBuffer(r->cl.context, ro, (nv + 1) * sizeof(int32_t),
                                    mesh->vertex_face_offset, &e);
    if (e == CL_SUCCESS)
        mem[MB_CORNER] = api->clCreateBuffer(r->cl.context, ro, n_wedge * sizeof(int32_t),
                                        mesh->vertex_wedge, &e);
    if (e == CL_SUCCESS)
        mem[MB_CORNERS] = api->clCreateBuffer(r->cl.context, ro,
                                         (size_t)mesh->nf * sizeof(mfmm_face),
                                         mesh->face_records, &e);
    if (e == CL_SUCCESS) {
        size_t nc = job->cost_location == 1 ? nv : job->cost_location == 2 ? (size_t)mesh->nf : 1;
        mem[MB_COST] = api->clCreateBuffer(r->cl.context, ro, nc * sizeof(double),
                                      job->cost ? (void *)job->cost : (void *)&r->one, &e);
    }
    if (e == CL_SUCCESS)
        mem[MB_SOURCES] = api->clCreateBuffer(r->cl.context, ro, (size_t)job->n_sources * sizeof(int32_t),
                                         (void *)job->sources, &e);
    /* each slot's corner, virtual edges' strips (march.h) */
    size_t n_strip = (size_t)mesh->virt_strip[mesh->n_virts];
    if (e == CL_SUCCESS)
        mem[MB_STRIP] = api->clCreateBuffer(r->cl.context, ro, (n_strip ? n_strip : 1) * sizeof(int32_t),
                                            mesh->strip, &e);
    if (e == CL_SUCCESS)
        mem[MB_VIRTS] = api->clCreateBuffer(r->cl.context, ro,
                                              (mesh->n_virts ? (size_t)mesh->n_virts : 1) *
                                                  sizeof(mfmm_virt),
                                              mesh->virts, &e);
    if (e == CL_SUCCESS)
        mem[MB_VFIRST] = api->clCreateBuffer(r->cl.context, ro, (nv + 1) * sizeof(int32_t),
                                             mesh->virt_first, &e);
    if (e == CL_SUCCESS)
        mem[MB_STRIPOFF] = api->clCreateBuffer(r->cl.context, ro,
                                               ((size_t)mesh->n_virts + 1) * sizeof(int32_t),
                                               mesh->virt_strip, &e);
    /* F = 1 with unfolding: the mesh's spokes (march.h), as the serial
     * solver reads them (solve.c); out of memory: the face walk, which
     * gives the same rows */
    const int32_t *spoke_offset = NULL;
    const mfmm_spoke *spokes = NULL;
    if (!job->cost && job->opt->unfolding)
        (void)mfmm_mesh_spokes_of(mesh, 1, &spoke_offset, &spokes);
    r->use_spokes = spokes != NULL;
    if (e == CL_SUCCESS)
        mem[MB_SPOKEOFF] = api->clCreateBuffer(r->cl.context, ro, (r->use_spokes ? nv + 1 : 1) * sizeof(int32_t),
                                               r->use_spokes ? (void *)spoke_offset : (void *)&r->no_target, &e);
    if (e == CL_SUCCESS)
        mem[MB_SPOKES] = api->clCreateBuffer(r->cl.context, ro,
                                             r->use_spokes ? (size_t)spoke_offset[nv] * sizeof(mfmm_spoke)
                                                           : sizeof(double),
                                             r->use_spokes ? (void *)spokes : (void *)&r->one, &e);
    /* with a cost: the cost around each vertex, for the virtual stencils
     * (march.h), once for the job */
    if (e == CL_SUCCESS && job->cost && (job->opt->unfolding || r->exact)) {
        r->uniform = malloc(nv * sizeof *r->uniform);
        if (!r->uniform)
            return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for %d costs", (int)nv);
        mfmm_uniform_cost(mesh, job->cost, job->cost_location, r->uniform);
    }
    if (e == CL_SUCCESS)
        mem[MB_UNIFORM] = api->clCreateBuffer(r->cl.context, ro, (r->uniform ? nv : 1) * sizeof(double),
                                         r->uniform ? (void *)r->uniform : (void *)&r->one, &e);
    if (e == CL_SUCCESS)
        mem[MB_TARGETS] = api->clCreateBuffer(r->cl.context, ro,
                                              (job->targets ? (size_t)job->width : 1) * sizeof(int32_t),
                                              job->targets ? (void *)job->targets : (void *)&r->no_target,
                                              &e);
    if (e == CL_SUCCESS) /* rows gathered into the caller's vertex order */
        mem[MB_ORDER] = api->clCreateBuffer(r->cl.context, ro, nv * sizeof(int32_t),
                                            mesh->to_internal, &e);
    if (e != CL_SUCCESS)
        return runtime_fail(err, "uploading the mesh", e);
    return MFMM_OK;
}

/* The workspaces of a batch (r->batch rows), halved until the device
 * accepts them. */
static mfmm_status run_workspaces(run *r, mfmm_error *err)
{
    const mfmm_rows_job *job = r->job;
    const mfmm_cl_api *api = r->api;
    cl_mem *mem = r->mem;
    size_t nv = r->nv;
    cl_int e = CL_SUCCESS;
    r->batch = batch_rows(&r->cl, job, r->direct, r->rows);
    for (;;) {
        if (job->full_batches && starved(&r->cl, r->batch, r->rows))
            return mfmm_fail(err, MFMM_ERR_NO_OPENCL, -1,
                             "OpenCL would run %d row(s) at a time on %u compute units "
                             "(memory_limit %zu bytes, %zu per row); threads keep every core busy",
                             (int)r->batch, (unsigned)r->cl.compute_units, job->budget,
                             item_bytes(job, r->direct));
        size_t b = (size_t)r->batch;
        if (r->windows)
            mem[MB_WS] = api->clCreateBuffer(r->cl.context, CL_MEM_READ_WRITE,
                                             b * (size_t)r->ws_stride, NULL, &e);
        else
            mem[MB_LABEL] = api->clCreateBuffer(r->cl.context, CL_MEM_READ_WRITE, b * nv, NULL, &e);
        if (e == CL_SUCCESS && !r->windows)
            mem[MB_KEY] = api->clCreateBuffer(r->cl.context, CL_MEM_READ_WRITE, b * nv * 8, NULL, &e);
        if (e == CL_SUCCESS && !r->windows)
            mem[MB_VERT] = api->clCreateBuffer(r->cl.context, CL_MEM_READ_WRITE, b * nv * 4, NULL, &e);
        if (e == CL_SUCCESS && !r->windows)
            mem[MB_POS] = api->clCreateBuffer(r->cl.context, CL_MEM_READ_WRITE, b * nv * 4, NULL, &e);
        if (e == CL_SUCCESS && !r->windows)
            mem[MB_T] = api->clCreateBuffer(r->cl.context, CL_MEM_READ_WRITE, b * nv * 8, NULL, &e);
        if (e == CL_SUCCESS)
            mem[MB_OUT] = api->clCreateBuffer(r->cl.context, CL_MEM_READ_WRITE, b * r->row_bytes, NULL, &e);
        if (e == CL_SUCCESS && !r->direct) {
            r->host = malloc(2 * b * r->row_bytes);
            if (!r->host)
                e = CL_OUT_OF_HOST_MEMORY;
        }
        if (e == CL_SUCCESS)
            return MFMM_OK;
        for (int i = MB_LABEL; i < MB_COUNT; i++)
            if (mem[i]) {
                api->clReleaseMemObject(mem[i]);
                mem[i] = NULL;
            }
        free(r->host);
        r->host = NULL;
        if (r->batch == 1)
            return runtime_fail(err, "allocating workspaces for one row", e);
        r->batch /= 2;
    }
}

/* The kernel arguments that stay the same for every batch. */
static mfmm_status run_set_args(run *r, mfmm_error *err)
{
    const mfmm_rows_job *job = r->job;
    const mfmm_cl_api *api = r->api;
    cl_kernel kernel = r->cl.kernel;
    cl_mem *mem = r->mem;
    cl_int e;
    cl_int nvi = (cl_int)r->nv, cl_loc = job->cost_location, unfold = job->opt->unfolding != 0;
    cl_double maxd = job->opt->max_distance;
    e = api->clSetKernelArg(kernel, 0, sizeof nvi, &nvi);
    e |= api->clSetKernelArg(kernel, 1, sizeof(cl_mem), &mem[MB_OFFSET]);
    e |= api->clSetKernelArg(kernel, 2, sizeof(cl_mem), &mem[MB_CORNER]);
    e |= api->clSetKernelArg(kernel, 3, sizeof(cl_mem), &mem[MB_CORNERS]);
    e |= api->clSetKernelArg(kernel, 4, sizeof(cl_mem), &mem[MB_COST]);
    e |= api->clSetKernelArg(kernel, 5, sizeof cl_loc, &cl_loc);
    e |= api->clSetKernelArg(kernel, 6, sizeof maxd, &maxd);
    e |= api->clSetKernelArg(kernel, 7, sizeof unfold, &unfold);
    e |= api->clSetKernelArg(kernel, 8, sizeof(cl_mem), &mem[MB_SOURCES]);
    e |= api->clSetKernelArg(kernel, 11, sizeof(cl_mem), &mem[MB_LABEL]);
    e |= api->clSetKernelArg(kernel, 12, sizeof(cl_mem), &mem[MB_KEY]);
    e |= api->clSetKernelArg(kernel, 13, sizeof(cl_mem), &mem[MB_VERT]);
    e |= api->clSetKernelArg(kernel, 14, sizeof(cl_mem), &mem[MB_POS]);
    /* the float32 kernel's last workspace is unused: any buffer stands in */
    cl_mem t_ws = mem[MB_T];
    if (r->f64) {
        e |= api->clSetKernelArg(kernel, 15, sizeof(cl_mem), &mem[MB_OUT]);
        e |= api->clSetKernelArg(kernel, 16, sizeof(cl_mem), &mem[MB_STRIP]);
        e |= api->clSetKernelArg(kernel, 17, sizeof(cl_mem), &mem[MB_UNIFORM]);
        e |= api->clSetKernelArg(kernel, 18, sizeof(cl_mem), &mem[MB_TARGETS]);
        e |= api->clSetKernelArg(kernel, 19, sizeof r->n_targets, &r->n_targets);
        e |= api->clSetKernelArg(kernel, 20, sizeof(cl_mem), &t_ws);
        e |= api->clSetKernelArg(kernel, 21, sizeof(cl_mem), &mem[MB_ORDER]);
        e |= api->clSetKernelArg(kernel, 22, sizeof(cl_mem), &mem[MB_VIRTS]);
        e |= api->clSetKernelArg(kernel, 23, sizeof(cl_mem), &mem[MB_STRIPOFF]);
    } else {
        e |= api->clSetKernelArg(kernel, 15, sizeof(cl_mem), &mem[MB_T]);
        e |= api->clSetKernelArg(kernel, 16, sizeof(cl_mem), &mem[MB_OUT]);
        e |= api->clSetKernelArg(kernel, 17, sizeof(cl_mem), &mem[MB_STRIP]);
        e |= api->clSetKernelArg(kernel, 18, sizeof(cl_mem), &mem[MB_UNIFORM]);
        e |= api->clSetKernelArg(kernel, 19, sizeof(cl_mem), &mem[MB_TARGETS]);
        e |= api->clSetKernelArg(kernel, 20, sizeof r->n_targets, &r->n_targets);
        e |= api->clSetKernelArg(kernel, 21, sizeof(cl_mem), &t_ws);
        e |= api->clSetKernelArg(kernel, 22, sizeof(cl_mem), &mem[MB_ORDER]);
        e |= api->clSetKernelArg(kernel, 23, sizeof(cl_mem), &mem[MB_VIRTS]);
        e |= api->clSetKernelArg(kernel, 24, sizeof(cl_mem), &mem[MB_STRIPOFF]);
    }
    /* the seeds (set per batch with the exact start; else unused) */
    r->seed_arg = r->f64 ? 24 : 25;
    cl_uint seed_arg = r->seed_arg;
    cl_int n_seeds = r->exact;
    e |= api->clSetKernelArg(kernel, seed_arg, sizeof n_seeds, &n_seeds);
    e |= api->clSetKernelArg(kernel, seed_arg + 1, sizeof(cl_mem), &mem[MB_SOURCES]);
    e |= api->clSetKernelArg(kernel, seed_arg + 2, sizeof(cl_mem), &mem[MB_COST]);
    e |= api->clSetKernelArg(kernel, seed_arg + 3, sizeof(cl_mem), &mem[MB_VFIRST]);
    e |= api->clSetKernelArg(kernel, seed_arg + 4, sizeof r->use_spokes, &r->use_spokes);
    e |= api->clSetKernelArg(kernel, seed_arg + 5, sizeof(cl_mem), &mem[MB_SPOKEOFF]);
    e |= api->clSetKernelArg(kernel, seed_arg + 6, sizeof(cl_mem), &mem[MB_SPOKES]);
    if (e != CL_SUCCESS)
        return runtime_fail(err, "clSetKernelArg", e);
    return MFMM_OK;
}

/* Where batch k's rows are read to: the caller's buffer, or one of two host
 * blocks. */
static void *run_rows_of(const run *r, int32_t k)
{
    int32_t first = r->start + k * r->batch;
    return r->direct ? (char *)r->job->opt->out + (size_t)first * r->row_bytes
                     : r->host + (size_t)(k & 1) * (size_t)r->batch * r->row_bytes;
}

/* Enqueues batch k: its seeds (with the exact start), the kernel, and the
 * read of its rows (not waited for). */
static mfmm_status run_enqueue(run *r, int32_t k, mfmm_error *err)
{
    const mfmm_rows_job *job = r->job;
    const mfmm_cl_api *api = r->api;
    cl_kernel kernel = r->cl.kernel;
    cl_int e;
    cl_int first = r->start + k * r->batch;
    cl_int count = job->n_sources - first < r->batch ? job->n_sources - first : r->batch;
    int kernel_queued = 0;
    cl_uint arg_first = r->windows ? 11 : 9;
    e = api->clSetKernelArg(kernel, arg_first, sizeof first, &first);
    e |= api->clSetKernelArg(kernel, arg_first + 1, sizeof count, &count);
    if (e != CL_SUCCESS)
        return runtime_fail(err, "clSetKernelArg", e);
    if (r->exact) {
        seed_buf *b = &r->sb;
        mfmm_status st = batch_seeds(job, &r->ews, r->uniform, first, count, b);
        if (st != MFMM_OK)
            return mfmm_fail(err, st, first, "out of memory for the exact start of rows "
                                             "from %d", (int)first);
        /* copied at creation; released now, freed by OpenCL once the
         * kernel that uses them is done */
        cl_mem m_idx = api->clCreateBuffer(r->cl.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                           b->n * sizeof(int32_t), b->idx, &e);
        cl_mem m_val = NULL;
        if (e == CL_SUCCESS)
            m_val = api->clCreateBuffer(r->cl.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                        b->n * sizeof(double), b->val, &e);
        if (e == CL_SUCCESS)
            e = api->clSetKernelArg(kernel, r->seed_arg + 1, sizeof(cl_mem), &m_idx);
        if (e == CL_SUCCESS)
            e = api->clSetKernelArg(kernel, r->seed_arg + 2, sizeof(cl_mem), &m_val);
        if (e == CL_SUCCESS) {
            size_t global = (size_t)count, local = 1;
            e = api->clEnqueueNDRangeKernel(r->cl.queue, kernel, 1, NULL, &global, &local,
                                            0, NULL, NULL);
            kernel_queued = 1;
        }
        if (m_idx)
            api->clReleaseMemObject(m_idx);
        if (m_val)
            api->clReleaseMemObject(m_val);
        if (e != CL_SUCCESS)
            return runtime_fail(err, "uploading the exact start's seeds", e);
    }
    if (!kernel_queued) {
        size_t global = (size_t)count, local = 1;
        e = api->clEnqueueNDRangeKernel(r->cl.queue, kernel, 1, NULL, &global, &local, 0,
                                        NULL, NULL);
        if (e != CL_SUCCESS)
            return runtime_fail(err, "clEnqueueNDRangeKernel", e);
    }
    e = api->clEnqueueReadBuffer(r->cl.queue, r->mem[MB_OUT], CL_FALSE, 0,
                                 (size_t)count * r->row_bytes, run_rows_of(r, k), 0, NULL,
                                 &r->ev[k & 1]);
    if (e != CL_SUCCESS)
        return runtime_fail(err, "clEnqueueReadBuffer", e);
    api->clFlush(r->cl.queue);
    return MFMM_OK;
}

/* Waits for batch j's rows and hands them to the caller. */
static mfmm_status run_download(run *r, int32_t j, int32_t *rows_done, mfmm_error *err)
{
    const mfmm_rows_job *job = r->job;
    const mfmm_cl_api *api = r->api;
    cl_event wait = r->ev[j & 1];
    r->ev[j & 1] = NULL;
    cl_int e = api->clWaitForEvents(1, &wait);
    cl_int status = CL_COMPLETE;
    if (e == CL_SUCCESS)
        e = api->clGetEventInfo(wait, CL_EVENT_COMMAND_EXECUTION_STATUS, sizeof status,
                           &status, NULL);
    api->clReleaseEvent(wait);
    if (e == CL_SUCCESS && status < 0)
        e = status;
    if (e != CL_SUCCESS)
        return runtime_fail(err, "running the kernel", e);
    int32_t first = r->start + j * r->batch;
    int32_t count = job->n_sources - first < r->batch ? job->n_sources - first : r->batch;
    if (mfmm_rows_deliver(job, first, count, run_rows_of(r, j)))
        return mfmm_fail(err, MFMM_ERR_CANCELLED, first, "cancelled by the row callback");
    *rows_done += count;
    return MFMM_OK;
}

/* Releases what the run made. */
static void run_release(run *r)
{
    const mfmm_cl_api *api = r->api;
    if (r->cl.queue)
        api->clFinish(r->cl.queue);
    for (int i = 0; i < 2; i++)
        if (r->ev[i])
            api->clReleaseEvent(r->ev[i]);
    for (int i = 0; i < MB_COUNT; i++)
        if (r->mem[i])
            api->clReleaseMemObject(r->mem[i]);
    free(r->host);
    free(r->uniform);
    free(r->flat);
    free(r->fcost);
    free(r->vcost);
    r->job->info->start_fallbacks += r->sb.fallbacks;
    free(r->sb.idx);
    free(r->sb.val);
    mfmm_exact_ws_destroy(r->ews);
    mfmm_cl_release_call(&r->cl);
}

mfmm_status mfmm_cl_run_rows(const ocl *shared, const mfmm_rows_job *job, int32_t start,
                             int32_t *rows_done, mfmm_error *err)
{
    *rows_done = 0;
    int32_t rows = job->n_sources - start;
    if (rows <= 0)
        return MFMM_OK;
    run r;
    memset(&r, 0, sizeof r);
    r.job = job;
    r.cl = *shared;
    r.api = r.cl.api;
    r.start = start;
    r.rows = rows;
    r.f64 = job->elem_size == sizeof(double);
    r.direct = job->opt->out != NULL;
    r.windows = windows_job(job);
    r.exact = !r.windows && mfmm_exact_start_on(job->opt->exact_start_radius);
    r.ws_stride = r.windows ? (cl_ulong)mfmm_slots_block_bytes(job->mesh) : 0;
    r.nv = (size_t)job->mesh->nv;
    r.row_bytes = (size_t)job->width * job->elem_size;
    r.one = 1.0;
    r.no_target = 0;
    r.n_targets = job->targets ? (cl_int)job->width : 0;
    mfmm_status st = mfmm_cl_open_call(&r.cl, r.f64, r.windows, err);
    if (st != MFMM_OK) {
        mfmm_cl_release_call(&r.cl);
        return st;
    }
    st = r.windows ? run_upload_windows(&r, err) : run_upload(&r, err);
    if (st == MFMM_OK)
        st = run_workspaces(&r, err);
    if (st == MFMM_OK)
        st = r.windows ? run_set_args_windows(&r, err) : run_set_args(&r, err);
    /* Batch k runs while the host delivers batch k-1: in an in-order queue,
     * kernel k+1 is enqueued after the read of batch k. */
    int32_t n_batches = st == MFMM_OK ? (rows + r.batch - 1) / r.batch : 0;
    for (int32_t k = 0; st == MFMM_OK && k <= n_batches; k++) {
        if (k < n_batches)
            st = run_enqueue(&r, k, err);
        if (st == MFMM_OK && k > 0)
            st = run_download(&r, k - 1, rows_done, err);
    }
    run_release(&r);
    return st;
}

#else
typedef int mfmm_opencl_rows_unused; /* ISO C: no empty translation unit */
#endif /* MESHFMM_HAVE_OPENCL */
