/* Test helpers: generated meshes with known distances (src/generate.h), and
 * the accuracy metrics of DESIGN.md. */
#ifndef MFMM_TESTUTIL_H
#define MFMM_TESTUTIL_H

#include <stddef.h>
#include <math.h>
#include <stdint.h>
#include "meshfmm.h"
#include "generate.h"

#define TM_PI 3.14159265358979323846

/* Fails the test unless |a - b| <= tol (cmocka 1.1 compares only floats).
 * Include <cmocka.h> first. */
#define tm_assert_close(a, b, tol)                                                      \
    do {                                                                                \
        double tm_a_ = (a), tm_b_ = (b), tm_t_ = (tol);                                 \
        if (!(fabs(tm_a_ - tm_b_) <= tm_t_))                                            \
            fail_msg("%s = %.17g, %s = %.17g: differ by %.3g > %.3g", #a, tm_a_, #b, tm_b_, \
                     fabs(tm_a_ - tm_b_), tm_t_);                                       \
    } while (0)

/* Builds an mfmm_mesh (default options) from a generated mesh; fails the
 * test (cmocka) on error. */
mfmm_mesh *tm_make(const mfmm_gen_mesh *m);

/* One vertex source, value 0. */
mfmm_source tm_vertex_source(int32_t v);

/* The vertex nearest to p. */
int32_t tm_nearest_vertex(const mfmm_gen_mesh *m, const double p[3]);

/* DESIGN.md's metrics over vertices with exact[i] > 0 and finite:
 * mean relative error in percent, and max error in percent of `diameter`. */
double tm_mean_rel_error(const double *d, const double *exact, int32_t n);
double tm_max_error(const double *d, const double *exact, int32_t n, double diameter);

/* Least-squares slope of log(err) against log(h): the order of convergence. */
double tm_fitted_order(const double *h, const double *err, int n);

/* Writes the path of `relative` (e.g. "meshes/spot.obj") under ../shared into out. */
void tm_shared_path(char *out, size_t n, const char *relative);

#endif
