/* libFuzzer harness: the exact solver (mfmm_solve_exact, the patch of the
 * exact start) and the march from the exact start, on small meshes decoded
 * from the input. Properties checked (abort on a break): no NaN, no negative
 * distance; a vertex source at its value; the patch
 * (mfmm_exact_patch) equal to the full solve within its radius (at most
 * it where the full solve fell back to walls at non-manifold edges); the march
 * from the exact start without NaN or negative values.
 *
 * Input layout (all optional past the end: zeros):
 *   byte 0: nv - 3 (3..66)      byte 1: nf - 1 (1..128)
 *   byte 2: flags: 1 face source, 2 max_distance, 4 memory_limit, 8 two sources
 *   byte 3: radius of the exact start, in eighths of a mean edge (0..31)
 *   then nv * 3 int8 coordinates / 8, nf * 3 vertex bytes (mod nv),
 *   the source bytes, a max_distance byte. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "meshfmm.h"
#include "byte_reader.h"
#include "core/order.h"
#include "exact/exact.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader r = {data, size};
    int32_t nv = 3 + next(&r) % 64, nf = 1 + next(&r) % 128;
    int flags = next(&r);
    double radius = (double)(next(&r) % 32) / 8.0;
    double V[66 * 3];
    int32_t F[128 * 3];
    read_mesh(&r, nv, nf, V, F);
    mfmm_mesh *mesh = NULL;
    mfmm_error err;
    if (mfmm_mesh_create(V, nv, F, nf, NULL, &mesh, &err) != MFMM_OK)
        return 0;
    mfmm_source src[2];
    int n_src = flags & 8 ? 2 : 1;
    for (int k = 0; k < n_src; k++) {
        memset(&src[k], 0, sizeof src[k]);
        src[k].face = -1;
        src[k].vertex = next(&r) % nv;
        src[k].value = k ? (double)(next(&r) % 8) / 8.0 : 0.0;
    }
    if (flags & 1) { /* the first source a point in a face (maybe on an edge or a corner) */
        src[0].face = next(&r) % nf;
        double w[3] = {next(&r) % 5, next(&r) % 5, next(&r) % 5};
        double s = w[0] + w[1] + w[2];
        if (s == 0) {
            w[0] = 1;
            s = 1;
        }
        for (int k = 0; k < 3; k++)
            src[0].bary[k] = w[k] / s;
    }
    mfmm_exact_options eo;
    mfmm_exact_options_init(&eo);
    if (flags & 2)
        eo.max_distance = (double)next(&r) / 16.0;
    if (flags & 4)
        eo.memory_limit = 4096 + 64 * (size_t)next(&r);
    double *e = malloc((size_t)nv * sizeof *e), *d = malloc((size_t)nv * sizeof *d);
    mfmm_exact_solver *ex = NULL;
    if (!e || !d || mfmm_exact_solver_create(mesh, &ex) != MFMM_OK)
        goto done;
    mfmm_exact_info info;
    mfmm_status st = mfmm_solve_exact(ex, src, n_src, &eo, e, &info, &err);
    if (st == MFMM_ERR_DEGENERATE_SOURCE || st == MFMM_ERR_MEMORY_LIMIT ||
        st == MFMM_ERR_BAD_BARYCENTRIC)
        goto done;
    if (st != MFMM_OK)
        abort();
    for (int32_t v = 0; v < nv; v++)
        if (isnan(e[v]) || e[v] < 0)
            abort();
    /* a vertex source at its value (or less, from another source), unless it
     * is beyond max_distance or on no face of nonzero area (+inf) */
    for (int k = 0; k < n_src; k++)
        if (src[k].face < 0 && !(e[src[k].vertex] <= src[k].value) &&
            e[src[k].vertex] != INFINITY)
            abort();
    /* the triangle inequality along every edge of a face of nonzero area
     * (regressions/exact: a doubled face once broke it by 0.10) */
    for (int32_t f = 0; f < nf; f++) {
        const double *a = V + 3 * F[3 * f], *b = V + 3 * F[3 * f + 1], *c = V + 3 * F[3 * f + 2];
        double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double n2 = pow(u[1] * w[2] - u[2] * w[1], 2) + pow(u[2] * w[0] - u[0] * w[2], 2) +
                    pow(u[0] * w[1] - u[1] * w[0], 2);
        if (!(n2 > 0.0))
            continue;
        for (int k = 0; k < 3; k++) {
            int32_t p = F[3 * f + k], q = F[3 * f + (k + 1) % 3];
            const double *x = V + 3 * p, *y = V + 3 * q;
            double len = sqrt(pow(x[0] - y[0], 2) + pow(x[1] - y[1], 2) + pow(x[2] - y[2], 2));
            if (isfinite(e[p]) && isfinite(e[q]) &&
                !(fabs(e[p] - e[q]) <= len * (1.0 + 1e-9) + 1e-9 * (1.0 + fabs(e[p]))))
                abort();
        }
    }
    /* the patch of the exact start: the full solve's distances within radius */
    if (n_src == 1 && !(flags & 6)) {
        int32_t n = 0;
        const int32_t *pv = NULL;
        const double *pd = NULL;
        double R = radius * 0.5;
        mfmm_source isrc = src[0]; /* the patch API takes internal ids (core/order.h) */
        if (isrc.face < 0)
            isrc.vertex = mfmm_vertex_in(mesh, isrc.vertex);
        else /* faces are numbered internally too, and split at T-junctions */
            isrc.face = mfmm_order_point_in(mesh, isrc.face, isrc.bary, isrc.bary);
        if (mfmm_exact_patch(ex, &isrc, 1, R, 0, &n, &pv, &pd, NULL) == MFMM_OK) {
            int32_t inside = 0, in_r = 0;
            for (int32_t v = 0; v < nv; v++)
                inside += e[v] <= R;
            /* every value exact, those beyond R too (the ring of exact.c);
             * where the full solve fell back to walls at non-manifold edges
             * (its budget passed beyond R), the patch's values are at most
             * its upper bounds */
            for (int32_t i = 0; i < n; i++) {
                double ev = e[mfmm_vertex_out(mesh, pv[i])], tol = 1e-12 * (1.0 + ev);
                if (info.nonmanifold_walls ? !(pd[i] <= ev + tol) : !(fabs(pd[i] - ev) <= tol))
                    abort();
                in_r += pd[i] <= R;
            }
            n = in_r;
            /* ties at the radius itself may go either way */
            if (!info.nonmanifold_walls && (n > inside + 1 || n + 1 < inside)) {
                int32_t near = 0;
                for (int32_t v = 0; v < nv; v++)
                    near += fabs(e[v] - R) <= 1e-12 * (1.0 + R);
                if (abs(n - inside) > near)
                    abort();
            }
        }
    }
    /* the march from the exact start */
    mfmm_solver *solver = NULL;
    if (mfmm_solver_create(mesh, &solver) == MFMM_OK) {
        mfmm_solve_options so;
        mfmm_solve_options_init(&so);
        so.exact_start_radius = radius;
        st = mfmm_solve(solver, src, n_src, &so, d, &err);
        if (st == MFMM_OK)
            for (int32_t v = 0; v < nv; v++)
                if (isnan(d[v]) || d[v] < 0)
                    abort();
        mfmm_solver_destroy(solver);
    }
done:
    mfmm_exact_solver_destroy(ex);
    free(e);
    free(d);
    mfmm_mesh_destroy(mesh);
    return 0;
}
