/* The triangle update (Eq. 4, test of Eq. 5) against plane waves: exact
 * inside the section of directions the triangle supports, the edge
 * fallback outside it. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "march/local_update.h"
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

/* The update with Eq. 5 tested after the root only (the core before its
 * bounds on u were read first): a reference for test_bounds_first. */
static double interior_after_root(double ta, double tb, double a, double b, double cos_c,
                                  double f)
{
    double c2 = a * a + b * b - 2.0 * a * b * cos_c;
    if (!(c2 > 0.0))
        return INFINITY;
    double inv = 1.0 / c2;
    double beta = a * b * sqrt((1.0 - cos_c) * (1.0 + cos_c)) * inv;
    double alpha_a = b * (b - a * cos_c) * inv, alpha_b = a * (a - b * cos_c) * inv;
    int swap = ta > tb;
    double t0 = swap ? tb : ta, u = swap ? ta - tb : tb - ta;
    double alpha = swap ? alpha_b : alpha_a;
    double la = swap ? b : a, lb = swap ? a : b;
    double d = f * f * c2 - u * u;
    d = d > 0.0 ? d : 0.0;
    double t = alpha * u + beta * sqrt(d);
    if (!(t > u))
        return INFINITY;
    double xt = lb * (t - u);
    if (la * cos_c * t < xt && xt * cos_c < la * t)
        return t0 + t;
    return INFINITY;
}

/* Eq. 5's bounds on u, read before the root, only skip updates that the
 * test after the root rejects or that an edge update beats: the same
 * local update (with the edges, as the march always takes it), bit for
 * bit, on random triangles (sides 1e-3..1e3 apart, angles from 1e-6 to
 * pi - 1e-6, costs 0.3..3) and arrival times around both bounds. (The
 * test after the root alone accepts some u > F c on slivers, where no root
 * exists: t = alpha u, above the edge update.) */
static void test_bounds_first(void **state)
{
    (void)state;
    uint64_t x = 88172645463325252ull;
    int inside_wins = 0, edge_wins = 0;
    for (int i = 0; i < 400000; i++) {
        double r[6];
        for (int k = 0; k < 6; k++) { /* xorshift64: uniform in [0, 1) */
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            r[k] = (double)(x >> 11) * (1.0 / 9007199254740992.0);
        }
        double a = pow(10.0, 6.0 * r[0] - 3.0), b = pow(10.0, 6.0 * r[1] - 3.0);
        /* slivers near 0 and near pi, then any angle */
        double theta = i % 4 == 0   ? 1e-6 + PI * r[2] * 1e-3
                       : i % 4 == 1 ? PI - 1e-6 - PI * r[2] * 1e-3
                                    : 1e-6 + (PI - 2e-6) * r[2];
        double cs = cos(theta), f = 0.3 + 2.7 * r[3];
        /* u around the upper bound F (b - a cos) or the lower F (b cos - a) */
        double bound = r[4] < 0.5 ? f * (b - a * cs) : f * (b * cs - a);
        double u = bound * (1.0 + (r[5] - 0.5) * (i % 2 ? 1e-3 : 2.0));
        if (u < 0.0)
            u = -u;
        double ta = 1.0, tb = 1.0 + u;
        if (i % 3 == 0) { /* B reached first */
            ta = 1.0 + u;
            tb = 1.0;
        }
        double edge = fmin(ta + b * f, tb + a * f);
        double inside = interior_after_root(ta, tb, a, b, cs, f);
        double want = inside < edge ? inside : edge;
        double got = mfmm_triangle_update(ta, tb, a, b, cs, f);
        assert_memory_equal(&got, &want, sizeof got);
        if (inside < edge)
            inside_wins++;
        else
            edge_wins++;
    }
    assert_true(inside_wins > 10000 && edge_wins > 10000);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_acute_triangles),
        cmocka_unit_test(test_obtuse_triangles),
        cmocka_unit_test(test_no_nan),
        cmocka_unit_test(test_bounds_first),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
