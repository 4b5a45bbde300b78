/* libFuzzer harness: mesh creation, solve, path tracing and the distance
 * matrix on meshes decoded from the input. Properties checked (abort on a
 * break): no NaN in any distance; sources at distance 0 (vertex sources);
 * the matrix rows of every backend equal mfmm_solve's bit for bit (float64);
 * a traced path has finite points in range; isolines of the distances
 * (levels at the target's distance, half of it and one from the input)
 * come in order, have finite points in range on their faces, and a loop
 * ends where it starts. Built twice: serial + threads
 * (default) and, with FUZZ_OPENCL, the OpenCL backend against the serial
 * core (slow to start: run it briefly).
 *
 * Input layout (all optional past the end: zeros):
 *   byte 0: nv - 3 (3..66)      byte 1: nf - 1 (1..128)
 *   byte 2: flags: 1 cost, 2 per-face cost, 4 max_distance, 8 no unfolding,
 *           16 face source, 32 no straighten, 64 MFMM_METHOD_WINDOWS
 *   byte 3: number of vertex sources - 1 (1..4)
 *   then nv * 3 int8 coordinates / 8, nf * 3 vertex bytes (mod nv),
 *   sources, cost bytes ((1 + b) / 16), a max_distance byte, a target,
 *   a level byte (b / 16). */
#include <math.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "meshfmm.h"
#include "byte_reader.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* mfmm_isolines of d at up to three levels: a well-formed result. */
static void check_isolines(const mfmm_mesh *mesh, const double *d, int32_t nf, double target,
                           double level)
{
    double values[3];
    int32_t n = 0;
    if (isfinite(target)) {
        values[n++] = target;
        values[n++] = 0.5 * target;
    }
    values[n++] = level;
    mfmm_surface_point *pts = NULL;
    mfmm_isoline *lines = NULL;
    int64_t np = 0, nl = 0, next = 0;
    mfmm_error err;
    mfmm_status st = mfmm_isolines(mesh, d, values, n, &pts, &np, &lines, &nl, &err);
    if (st != MFMM_OK) {
        if (st != MFMM_ERR_OUT_OF_MEMORY)
            abort();
        return;
    }
    for (int64_t l = 0; l < nl; l++) {
        const mfmm_isoline *L = lines + l;
        if (L->start != next || L->n_points < 2 || L->value < 0 || L->value >= n ||
            (l > 0 && L->value < lines[l - 1].value) || (L->closed & ~1))
            abort();
        next += L->n_points;
        const mfmm_surface_point *P = pts + L->start;
        if (P[0].face != P[1].face ||
            (L->closed && memcmp(P[0].xyz, P[L->n_points - 1].xyz, sizeof P[0].xyz) != 0))
            abort();
        for (int64_t i = 0; i < L->n_points; i++) {
            if (P[i].face < 0 || P[i].face >= nf)
                abort();
            double sum = 0.0;
            for (int k = 0; k < 3; k++) {
                if (!isfinite(P[i].xyz[k]) || !(P[i].bary[k] >= -1e-12))
                    abort();
                sum += P[i].bary[k];
            }
            if (!(fabs(sum - 1.0) <= 1e-9))
                abort();
        }
    }
    if (next != np || (np == 0) != (pts == NULL) || (nl == 0) != (lines == NULL))
        abort();
    mfmm_free(pts);
    mfmm_free(lines);
}

static void check_row(const double *row, int32_t nv)
{
    for (int32_t v = 0; v < nv; v++)
        if (isnan(row[v]) || row[v] < 0)
            abort();
}

#ifdef FUZZ_OPENCL
/* One context for the whole run (the harness's state, not the library's). */
static mfmm_opencl_context *opencl_context(int *unavailable)
{
    static mfmm_opencl_context *ctx = NULL;
    static int failed = 0, announced = 0;
    if (!ctx && !failed) {
        mfmm_error err;
        if (mfmm_opencl_context_create(&ctx, &err) != MFMM_OK) {
            fprintf(stderr, "fuzz_solve_opencl: no OpenCL device (%s): nothing to fuzz\n",
                    err.message);
            failed = 1;
            ctx = NULL;
        }
    }
    if (!failed && !announced) {
        fprintf(stderr, "fuzz_solve_opencl: device %s\n", mfmm_opencl_context_device_name(ctx));
        announced = 1;
    }
    *unavailable = failed;
    return ctx;
}
#endif

/* mfmm_voronoi_labels of d: a source index where d is finite, -1 where not. */
static void check_voronoi(const mfmm_mesh *mesh, const double *d, int32_t nv,
                          const mfmm_source *src, int32_t n_src)
{
    int32_t labels[66];
    mfmm_error err;
    mfmm_status st = mfmm_voronoi_labels(mesh, d, src, n_src, labels, &err);
    if (st == MFMM_ERR_OUT_OF_MEMORY)
        return;
    if (st != MFMM_OK)
        abort(); /* the solve accepted these sources */
    for (int32_t v = 0; v < nv; v++)
        if (labels[v] < -1 || labels[v] >= n_src || (labels[v] == -1) != !isfinite(d[v]))
            abort();
}

/* mfmm_farthest_points from `start`: k distinct vertices, the first start,
 * radii +inf then non-increasing, distances finite at the points. */
static void check_farthest(mfmm_solver *solver, int32_t nv, int32_t start,
                           const mfmm_solve_options *so)
{
    int32_t pts[3];
    double radii[3], dist[66];
    mfmm_solve_options o = *so;
    o.max_distance = INFINITY;
    mfmm_error err;
    int32_t k = nv < 3 ? nv : 3;
    if (mfmm_farthest_points(solver, start, k, &o, pts, radii, dist, &err) != MFMM_OK)
        return; /* start in no face, or fewer vertices in faces than k */
    if (pts[0] != start || radii[0] != INFINITY)
        abort();
    for (int32_t i = 0; i < k; i++) {
        if (pts[i] < 0 || pts[i] >= nv || dist[pts[i]] != 0.0)
            abort();
        for (int32_t j = 0; j < i; j++)
            if (pts[j] == pts[i])
                abort();
        if (i > 1 && !(radii[i] <= radii[i - 1]))
            abort();
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader r = {data, size};
    int32_t nv = 3 + next(&r) % 64, nf = 1 + next(&r) % 128;
    int flags = next(&r);
    int32_t n_src = 1 + next(&r) % 4;
    double V[66 * 3];
    int32_t F[128 * 3];
    read_mesh(&r, nv, nf, V, F);
    mfmm_mesh *mesh = NULL;
    mfmm_error err;
    if (mfmm_mesh_create(V, nv, F, nf, NULL, &mesh, &err) != MFMM_OK)
        return 0;
    mfmm_source src[5];
    int32_t src_ids[4];
    for (int32_t i = 0; i < n_src; i++) {
        src_ids[i] = next(&r) % nv;
        mfmm_source s = {src_ids[i], -1, {0, 0, 0}, 0.0};
        src[i] = s;
    }
    int32_t n_all = n_src;
    if (flags & 16) { /* a face source too */
        double a = 1 + next(&r) % 16, b = next(&r) % 16, c = next(&r) % 16;
        mfmm_source s = {-1, next(&r) % nf, {a / (a + b + c), b / (a + b + c), 0}, 0.0};
        s.bary[2] = 1.0 - s.bary[0] - s.bary[1];
        src[n_all++] = s;
    }
    double cost[128];
    int per_face = (flags & 2) != 0;
    int32_t nc = per_face ? nf : nv;
    for (int32_t i = 0; i < nc; i++)
        cost[i] = (1 + next(&r)) / 16.0;
    mfmm_solve_options so;
    mfmm_solve_options_init(&so);
    if (flags & 1) {
        so.cost = cost;
        so.cost_location = per_face ? MFMM_COST_PER_FACE : MFMM_COST_PER_VERTEX;
    }
    if (flags & 4)
        so.max_distance = next(&r) / 16.0;
    so.unfolding = (flags & 8) ? 0 : 1;
    if (flags & 64) /* the window method (on OpenCL too) */
        so.method = MFMM_METHOD_WINDOWS;
    int32_t target = next(&r) % nv;
    double level = next(&r) / 16.0;

    mfmm_solver *solver = NULL;
    double *d = malloc((size_t)nv * sizeof *d);
    double *rows = malloc((size_t)n_src * nv * sizeof *rows);
    double *ref = malloc((size_t)n_src * nv * sizeof *ref);
    if (!d || !rows || !ref || mfmm_solver_create(mesh, &solver) != MFMM_OK)
        goto out;
    if (mfmm_solve(solver, src, n_all, &so, d, &err) == MFMM_OK) {
        check_row(d, nv);
        for (int32_t i = 0; i < n_src; i++)
            if (d[src_ids[i]] != 0.0)
                abort();
        check_isolines(mesh, d, nf, d[target], level);
        check_voronoi(mesh, d, nv, src, n_all);
        /* a path from the target, when it was reached */
        mfmm_path_options po;
        mfmm_path_options_init(&po);
        po.max_points = 4096;
        po.sources = src;
        po.n_sources = n_all;
        po.cost = so.cost;
        po.cost_location = so.cost_location;
        po.straighten = (flags & 32) ? 0 : 1;
        mfmm_surface_point pts[4096];
        int32_t np = 0;
        double len = 0;
        mfmm_source t = {target, -1, {0, 0, 0}, 0.0};
        if (isfinite(d[target]) &&
            mfmm_trace_path(mesh, d, &t, &po, pts, 4096, &np, &len, &err) == MFMM_OK) {
            if (np < 1 || np > 4096 || !(len >= 0) || !isfinite(len))
                abort();
            for (int32_t i = 0; i < np; i++) {
                if (pts[i].face < 0 || pts[i].face >= nf)
                    abort();
                for (int k = 0; k < 3; k++)
                    if (!isfinite(pts[i].xyz[k]) || !isfinite(pts[i].bary[k]))
                        abort();
            }
        }
    }
    check_farthest(solver, nv, src_ids[0], &so);
    /* rows of the matrix == mfmm_solve from each vertex source alone */
    int have_ref = 1;
    for (int32_t i = 0; i < n_src && have_ref; i++)
        have_ref = mfmm_solve(solver, &src[i], 1, &so, ref + (size_t)i * nv, &err) == MFMM_OK;
    mfmm_matrix_options mo;
    mfmm_matrix_options_init(&mo);
    mo.dtype = MFMM_FLOAT64;
    mo.cost = so.cost;
    mo.cost_location = so.cost_location;
    mo.max_distance = so.max_distance;
    mo.unfolding = so.unfolding;
    mo.method = so.method;
    mo.out = rows;
#ifdef FUZZ_OPENCL
    int unavailable = 0;
    mo.backend = MFMM_BACKEND_OPENCL;
    mo.opencl = opencl_context(&unavailable);
    if (unavailable)
        goto out;
    static const mfmm_backend backends[] = {MFMM_BACKEND_OPENCL};
#else
    mo.n_threads = 2;
    static const mfmm_backend backends[] = {MFMM_BACKEND_SERIAL, MFMM_BACKEND_THREADS};
#endif
    for (size_t b = 0; b < sizeof backends / sizeof backends[0]; b++) {
        mo.backend = backends[b];
        memset(rows, 0xff, (size_t)n_src * nv * sizeof *rows);
        mfmm_status st = mfmm_distance_matrix(mesh, src_ids, n_src, &mo, NULL, &err);
        if (st != MFMM_OK) {
            if (have_ref && st != MFMM_ERR_OUT_OF_MEMORY && st != MFMM_ERR_NO_OPENCL &&
                st != MFMM_ERR_OPENCL_BUILD && st != MFMM_ERR_OPENCL_RUNTIME)
                abort(); /* solve accepted what the matrix refused */
            continue;
        }
        for (int32_t i = 0; i < n_src; i++)
            check_row(rows + (size_t)i * nv, nv);
        if (have_ref && memcmp(rows, ref, (size_t)n_src * nv * sizeof *rows) != 0)
            abort(); /* a backend's row differs from mfmm_solve's */
    }
out:
    mfmm_solver_destroy(solver);
    mfmm_mesh_destroy(mesh);
    free(d);
    free(rows);
    free(ref);
    return 0;
}
