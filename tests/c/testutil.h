/* Test helpers: generated meshes with known distances (src/io/generate.h), and
 * the accuracy metrics of docs/methods.md#metrics. */
#ifndef MFMM_TESTUTIL_H
#define MFMM_TESTUTIL_H

#include <stddef.h>
#include <math.h>
#include <stdint.h>
#include "meshfmm.h"
#include "io/generate.h"

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

/* The bytes of the array `name` in mesh's memory report (mfmm_mesh_memory);
 * fails the test if the report has no such entry. */
size_t tm_memory_entry(const mfmm_mesh *mesh, const char *name);

/* The vertex nearest to p. */
int32_t tm_nearest_vertex(const mfmm_gen_mesh *m, const double p[3]);

/* The metrics of docs/methods.md#metrics over vertices with exact[i] > 0 and finite:
 * mean relative error in percent, and max error in percent of `diameter`. */
double tm_mean_rel_error(const double *d, const double *exact, int32_t n);
double tm_max_error(const double *d, const double *exact, int32_t n, double diameter);

/* sum[v] (nv entries, zeroed here) = the angle sum at vertex v of faces F
 * (nf x 3) over positions V (nv x 3): > 2 pi at a saddle. */
void tm_angle_sums(const double *V, const int32_t *F, int32_t nv, int32_t nf, double *sum);

/* Least-squares slope of log(err) against log(h): the order of convergence. */
double tm_fitted_order(const double *h, const double *err, int n);

/* Loads tests/data/<relative> (e.g. "meshes/spot.obj") into an mfmm_mesh
 * (default options); fails the test ("PATH: message") on error. nv_out,
 * nf_out: the counts (either may be NULL). F_out: when not NULL, receives
 * the face array (free with mfmm_free); otherwise it is freed. */
mfmm_mesh *tm_load_data(const char *relative, int32_t *nv_out, int32_t *nf_out,
                          int32_t **F_out);

/* Rows from mfmm_solve (float64, n x nv), one per vertex source src[i]
 * (src NULL: vertex i): the reference for mfmm_distance_matrix. */
double *tm_reference_rows(const mfmm_mesh *mesh, const int32_t *src, int32_t n,
                          const mfmm_solve_options *so);

/* An mfmm_distance_matrix on_rows target: tm_collect_rows copies each block
 * into buf (row_bytes a row), checks that blocks come in order without gaps,
 * and asks to stop after cancel_after calls. */
typedef struct tm_collect {
    char *buf;
    size_t row_bytes;
    int32_t next;         /* the first row expected next */
    int32_t calls;
    int32_t cancel_after; /* calls before asking to stop; < 0: never */
} tm_collect;
int tm_collect_rows(void *user, int32_t first, int32_t n, const void *rows);

/* A generated mesh with its mfmm_mesh, a solver and room for nv distances,
 * and for n_points path points (pts; NULL when n_points is 0). */
typedef struct tm_fixture {
    mfmm_gen_mesh g;
    mfmm_mesh *mesh;
    mfmm_solver *solver;
    double *d;
    mfmm_surface_point *pts;
} tm_fixture;
/* Takes ownership of g; fails the test on error. */
tm_fixture tm_fixture_make(mfmm_gen_mesh g, int32_t n_points);
void tm_fixture_free(tm_fixture *fx);

/* Fails the test unless each of the `total` float32 entries of buf is
 * (float)ref[i], bit for bit. */
void tm_assert_float32_of(const void *buf, const double *ref, size_t total);

/* Per-face costs split at x = 0.5: cost[f] = left where the centroid of
 * face f has x < 0.5, right elsewhere (nf values). */
void tm_split_face_cost(const mfmm_gen_mesh *g, double *cost, double left, double right);

/* The y where the least-cost path from s (cost f1, x < 0.5) to p (cost f2,
 * x > 0.5) crosses the line x = 0.5 (Snell), by golden section: the cost is
 * convex in y. */
double tm_refraction_y(const double *s, const double *p, double f1, double f2);

/* Writes the path of `relative` (e.g. "meshes/spot.obj") under tests/data into out. */
void tm_data_path(char *out, size_t n, const char *relative);

#endif
