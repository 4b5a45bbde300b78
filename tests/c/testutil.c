/* Test helpers (see testutil.h). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "testutil.h"

size_t tm_memory_entry(const mfmm_mesh *mesh, const char *name)
{
    const char *names[32];
    size_t bytes[32];
    int n = mfmm_mesh_memory(mesh, names, bytes, 32);
    for (int i = 0; i < n && i < 32; i++)
        if (!strcmp(names[i], name))
            return bytes[i];
    fail_msg("the memory report has no entry \"%s\"", name);
    return 0;
}

mfmm_mesh *tm_make(const mfmm_gen_mesh *m)
{
    assert_non_null(m->V);
    mfmm_mesh *mesh = NULL;
    mfmm_error err;
    mfmm_status st = mfmm_mesh_create(m->V, m->nv, m->F, m->nf, NULL, &mesh, &err);
    if (st != MFMM_OK)
        fail_msg("mfmm_mesh_create: %s", err.message);
    return mesh;
}

mfmm_source tm_vertex_source(int32_t v)
{
    mfmm_source s = {v, -1, {0.0, 0.0, 0.0}, 0.0};
    return s;
}

int32_t tm_nearest_vertex(const mfmm_gen_mesh *m, const double p[3])
{
    int32_t best = -1;
    double bd = INFINITY;
    for (int32_t v = 0; v < m->nv; v++) {
        const double *x = m->V + 3 * (size_t)v;
        double d = (x[0] - p[0]) * (x[0] - p[0]) + (x[1] - p[1]) * (x[1] - p[1]) +
                   (x[2] - p[2]) * (x[2] - p[2]);
        if (d < bd) {
            bd = d;
            best = v;
        }
    }
    return best;
}

double tm_mean_rel_error(const double *d, const double *exact, int32_t n)
{
    double sum = 0.0;
    int32_t count = 0;
    for (int32_t i = 0; i < n; i++) {
        if (!(exact[i] > 0.0) || !isfinite(exact[i]))
            continue;
        sum += fabs(d[i] - exact[i]) / exact[i];
        count++;
    }
    return count ? 100.0 * sum / count : 0.0;
}

double tm_max_error(const double *d, const double *exact, int32_t n, double diameter)
{
    double mx = 0.0;
    for (int32_t i = 0; i < n; i++) {
        if (!(exact[i] > 0.0) || !isfinite(exact[i]))
            continue;
        mx = fmax(mx, fabs(d[i] - exact[i]));
    }
    return 100.0 * mx / diameter;
}

double tm_fitted_order(const double *h, const double *err, int n)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int i = 0; i < n; i++) {
        double x = log(h[i]), y = log(err[i]);
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

void tm_data_path(char *out, size_t n, const char *relative)
{
    snprintf(out, n, "%s/%s", MESHFMM_TEST_DATA_DIR, relative);
}

mfmm_mesh *tm_load_data(const char *relative, int32_t *nv_out, int32_t *nf_out,
                          int32_t **F_out)
{
    char path[1024];
    tm_data_path(path, sizeof path, relative);
    double *V = NULL;
    int32_t *F = NULL, nv = 0, nf = 0;
    mfmm_error err;
    if (mfmm_load_mesh(path, &V, &nv, &F, &nf, &err) != MFMM_OK)
        fail_msg("%s: %s", path, err.message);
    mfmm_mesh *mesh = NULL;
    if (mfmm_mesh_create(V, nv, F, nf, NULL, &mesh, &err) != MFMM_OK)
        fail_msg("%s: %s", path, err.message);
    mfmm_free(V);
    if (F_out)
        *F_out = F;
    else
        mfmm_free(F);
    if (nv_out)
        *nv_out = nv;
    if (nf_out)
        *nf_out = nf;
    return mesh;
}

double *tm_reference_rows(const mfmm_mesh *mesh, const int32_t *src, int32_t n,
                          const mfmm_solve_options *so)
{
    int32_t nv = mfmm_mesh_vertex_count(mesh);
    double *ref = malloc((size_t)n * (size_t)nv * sizeof *ref);
    assert_non_null(ref);
    mfmm_solver *solver = NULL;
    assert_int_equal(mfmm_solver_create(mesh, &solver), MFMM_OK);
    for (int32_t i = 0; i < n; i++) {
        mfmm_source s = tm_vertex_source(src ? src[i] : i);
        mfmm_error err;
        assert_int_equal(mfmm_solve(solver, &s, 1, so, ref + (size_t)i * nv, &err), MFMM_OK);
    }
    mfmm_solver_destroy(solver);
    return ref;
}

int tm_collect_rows(void *user, int32_t first, int32_t n, const void *rows)
{
    tm_collect *c = user;
    assert_int_equal(first, c->next); /* in order, no gaps */
    memcpy(c->buf + (size_t)first * c->row_bytes, rows, (size_t)n * c->row_bytes);
    c->next += n;
    c->calls++;
    return c->cancel_after >= 0 && c->calls >= c->cancel_after;
}

tm_fixture tm_fixture_make(mfmm_gen_mesh g, int32_t n_points)
{
    tm_fixture fx;
    fx.g = g;
    fx.mesh = tm_make(&g);
    assert_int_equal(mfmm_solver_create(fx.mesh, &fx.solver), MFMM_OK);
    fx.d = malloc((size_t)g.nv * sizeof *fx.d);
    fx.pts = n_points > 0 ? malloc((size_t)n_points * sizeof *fx.pts) : NULL;
    assert_true(fx.d && (n_points <= 0 || fx.pts));
    return fx;
}

void tm_fixture_free(tm_fixture *fx)
{
    free(fx->d);
    free(fx->pts);
    mfmm_solver_destroy(fx->solver);
    mfmm_mesh_destroy(fx->mesh);
    mfmm_gen_free(&fx->g);
}

void tm_assert_float32_of(const void *buf, const double *ref, size_t total)
{
    const float *f = (const float *)buf;
    for (size_t i = 0; i < total; i++) {
        float want = (float)ref[i];
        if (memcmp(&f[i], &want, 4) != 0)
            fail_msg("entry %zu: %.9g != (float)%.17g", i, f[i], ref[i]);
    }
}

void tm_split_face_cost(const mfmm_gen_mesh *g, double *cost, double left, double right)
{
    for (int32_t f = 0; f < g->nf; f++) {
        double cx = 0;
        for (int k = 0; k < 3; k++)
            cx += g->V[3 * g->F[3 * f + k]] / 3;
        cost[f] = cx < 0.5 ? left : right;
    }
}

double tm_refraction_y(const double *s, const double *p, double f1, double f2)
{
    double lo = -2.0, hi = 3.0;
    for (int it = 0; it < 200; it++) {
        double m1 = lo + (hi - lo) * 0.381966, m2 = lo + (hi - lo) * 0.618034;
        double c1 = f1 * hypot(0.5 - s[0], m1 - s[1]) + f2 * hypot(p[0] - 0.5, p[1] - m1);
        double c2 = f1 * hypot(0.5 - s[0], m2 - s[1]) + f2 * hypot(p[0] - 0.5, p[1] - m2);
        if (c1 < c2)
            hi = m2;
        else
            lo = m1;
    }
    return 0.5 * (lo + hi);
}

void tm_angle_sums(const double *V, const int32_t *F, int32_t nv, int32_t nf, double *sum)
{
    for (int32_t v = 0; v < nv; v++)
        sum[v] = 0.0;
    for (int32_t f = 0; f < nf; f++)
        for (int k = 0; k < 3; k++) {
            const double *a = V + 3 * (size_t)F[3 * f + k];
            const double *b = V + 3 * (size_t)F[3 * f + (k + 1) % 3];
            const double *c = V + 3 * (size_t)F[3 * f + (k + 2) % 3];
            double uu = 0.0, ww = 0.0, uw = 0.0;
            for (int j = 0; j < 3; j++) {
                double u = b[j] - a[j], w = c[j] - a[j];
                uu += u * u;
                ww += w * w;
                uw += u * w;
            }
            sum[F[3 * f + k]] += acos(fmax(-1.0, fmin(1.0, uw / sqrt(uu * ww))));
        }
}
