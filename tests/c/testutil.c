/* Test helpers (see testutil.h). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <cmocka.h>

#include "testutil.h"

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

void tm_shared_path(char *out, size_t n, const char *relative)
{
    snprintf(out, n, "%s/%s", MESHFMM_SHARED_DIR, relative);
}
