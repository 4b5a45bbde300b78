/* The triangle update (Eq. 4, test of Eq. 5) against plane waves: exact
 * inside the section of directions the triangle supports, the edge
 * fallback outside it. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include "core/local_update.h"
#include "testutil.h"

static const double PI = 3.14159265358979323846;

/* Triangle with C at the origin, A at angle 0 (|CA| = b), B at angle theta
 * (|CB| = a). A plane wave T(P) = F (k . P) + t0 travels along the unit
 * vector k; it reaches C from inside the triangle iff -k points strictly
 * between CA and CB. */
static void check_triangle(double a, double b, double theta, double F)
{
    double ax = b, ay = 0.0, bx = a * cos(theta), by = a * sin(theta);
    int exact = 0, fallback = 0;
    for (int i = 0; i < 720; i++) {
        double phi = 2 * PI * (i + 0.5) / 720; /* direction of travel */
        double kx = cos(phi), ky = sin(phi);
        double t0 = 3.0;
        double ta = F * (kx * ax + ky * ay) + t0, tb = F * (kx * bx + ky * by) + t0;
        double tc = t0;
        if (!(tc > ta && tc > tb))
            continue; /* only waves that reach A and B before C */
        /* upwind direction from C, as an angle in (-pi, pi] */
        double up = atan2(-ky, -kx);
        double margin = 1e-6;
        int inside = up > margin && up < theta - margin;
        int outside = up < -margin || up > theta + margin;
        double got = mfmm_triangle_update(ta, tb, a, b, cos(theta), F);
        double edge = fmin(ta + b * F, tb + a * F);
        if (inside) {
            tm_assert_close(got, tc, 1e-12 * (1.0 + fabs(tc)));
            exact++;
        } else if (outside) { /* from outside the triangle: edges only */
            tm_assert_close(got, edge, 1e-12 * (1.0 + fabs(edge)));
            fallback++;
        }
    }
    assert_true(exact > 0);
    /* a wave that reaches A and B before C comes from inside an obtuse or
     * right angle; only acute angles see such waves from outside */
    assert_true(fallback > 0 || cos(theta) < 1e-12);
}

static void test_acute_triangles(void **state)
{
    (void)state;
    check_triangle(1.0, 1.0, PI / 3, 1.0);
    check_triangle(0.7, 1.3, 0.9, 1.0);
    check_triangle(2.0, 0.5, 1.4, 2.5);
    check_triangle(1.0, 1.0, PI / 2, 0.3); /* right angle */
}

/* The plain stencil on obtuse corners (used where unfolding failed): the test
 * multiplied through by cos theta still accepts exactly the directions from
 * inside the triangle. */
static void test_obtuse_triangles(void **state)
{
    (void)state;
    check_triangle(1.0, 1.0, 2 * PI / 3, 1.0);
    check_triangle(0.4, 1.5, 2.8, 1.7);
}

/* Degenerate input never yields NaN: zero-length sides, cos = +-1, equal T. */
static void test_no_nan(void **state)
{
    (void)state;
    double cases[][6] = {{0, 0, 1, 1, 1, 1},    {0, 0, 0, 1, 0.5, 1}, {0, 1, 1, 1, -1, 1},
                         {0, 1e-300, 1, 1, 1, 1}, {1, 1, 1e-9, 1e-9, 0, 1}, {0, 100, 1, 1, 0.5, 1}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        double *c = cases[i];
        double t = mfmm_triangle_update(c[0], c[1], c[2], c[3], c[4], c[5]);
        assert_false(isnan(t));
        assert_true(t >= fmax(c[0], c[1]) || t >= fmin(c[0] + c[3] * c[5], c[1] + c[2] * c[5]) - 1e-15);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_acute_triangles),
        cmocka_unit_test(test_obtuse_triangles),
        cmocka_unit_test(test_no_nan),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
