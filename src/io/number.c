/* Locale-free number text: a correctly rounded decimal -> double parser (the
 * readers' strtod, which must not see a decimal comma from setlocale) and a
 * %.17g formatter that always writes '.'.
 *
 * Parsing: the significant digits and the decimal exponent are collected
 * exactly. Clinger's fast path takes mantissas below 2^53 with |exponent| <=
 * 22 (one correctly rounded IEEE operation). Otherwise a first guess within
 * a few ulps is corrected by comparing the exact decimal value with the
 * halfway points next to the guess in big-integer arithmetic (Clinger's
 * AlgorithmR idea), rounding ties to even. Nothing is allocated. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "io.h"

#define MAX_DIGITS 800 /* more digits only matter as a sticky "nonzero" digit */
#define BIG_LIMBS 220  /* 7040 bits: D * 10^e and (2m+1) 2^k 5^e never exceed ~4000 */

typedef struct big {
    uint32_t limb[BIG_LIMBS]; /* little endian */
    int n;                    /* limbs in use; 0 is zero */
} big;

static void big_set(big *b, uint64_t v)
{
    b->n = 0;
    while (v) {
        b->limb[b->n++] = (uint32_t)v;
        v >>= 32;
    }
}

/* b = b * m + a */
static void big_muladd(big *b, uint32_t m, uint32_t a)
{
    uint64_t carry = a;
    for (int i = 0; i < b->n; i++) {
        uint64_t t = (uint64_t)b->limb[i] * m + carry;
        b->limb[i] = (uint32_t)t;
        carry = t >> 32;
    }
    if (carry && b->n < BIG_LIMBS)
        b->limb[b->n++] = (uint32_t)carry;
}

static void big_mul_pow5(big *b, int e)
{
    while (e >= 13) {
        big_muladd(b, 1220703125u, 0); /* 5^13 */
        e -= 13;
    }
    static const uint32_t p5[13] = {1, 5, 25, 125, 625, 3125, 15625, 78125, 390625,
                                    1953125, 9765625, 48828125, 244140625};
    if (e > 0)
        big_muladd(b, p5[e], 0);
}

static void big_shl(big *b, int s)
{
    if (b->n == 0 || s <= 0)
        return;
    int w = s / 32, r = s % 32;
    if (b->n + w + 1 > BIG_LIMBS)
        return; /* cannot happen within the parser's bounds */
    if (r) {
        uint32_t top = 0;
        b->limb[b->n] = 0;
        for (int i = b->n; i > 0; i--)
            b->limb[i] = (b->limb[i] << r) | (b->limb[i - 1] >> (32 - r));
        b->limb[0] <<= r;
        top = b->limb[b->n];
        if (top)
            b->n++;
    }
    if (w) {
        memmove(b->limb + w, b->limb, (size_t)b->n * sizeof b->limb[0]);
        memset(b->limb, 0, (size_t)w * sizeof b->limb[0]);
        b->n += w;
    }
}

static int big_cmp(const big *a, const big *b)
{
    if (a->n != b->n)
        return a->n < b->n ? -1 : 1;
    for (int i = a->n - 1; i >= 0; i--)
        if (a->limb[i] != b->limb[i])
            return a->limb[i] < b->limb[i] ? -1 : 1;
    return 0;
}

/* Compares digits * 10^e10 with M * 2^K: -1, 0 or 1. */
static int compare_exact(const char *digits, int nd, int e10, uint64_t M, int K)
{
    big lhs, rhs;
    big_set(&lhs, 0);
    for (int i = 0; i < nd; i++) {
        if (lhs.n == 0)
            big_set(&lhs, (uint64_t)(digits[i] - '0'));
        else
            big_muladd(&lhs, 10, (uint32_t)(digits[i] - '0'));
    }
    big_set(&rhs, M);
    int l2 = 0, r2 = K;
    if (e10 >= 0) {
        big_mul_pow5(&lhs, e10);
        l2 += e10;
    } else {
        big_mul_pow5(&rhs, -e10);
        r2 -= e10;
    }
    int m2 = l2 < r2 ? l2 : r2;
    big_shl(&lhs, l2 - m2);
    big_shl(&rhs, r2 - m2);
    return big_cmp(&lhs, &rhs);
}

static int lower(int c)
{
    return c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c;
}

static int match_word(const char *s, const char *w)
{
    size_t i = 0;
    for (; w[i]; i++)
        if (lower((unsigned char)s[i]) != w[i])
            return 0;
    return (int)i;
}

/* x = m * 2^k with m < 2^53 an integer (k = -1074 for subnormals). */
static void decompose(double x, uint64_t *m, int *k)
{
    int ex;
    double f = frexp(x, &ex); /* x = f 2^ex, f in [0.5, 1) */
    if (x == 0.0 || ex - 53 < -1074) {
        *k = -1074;
        *m = (uint64_t)ldexp(x, 1074);
    } else {
        *k = ex - 53;
        *m = (uint64_t)ldexp(f, 53);
    }
}

static const double pow10_exact[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                       1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                       1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/* w * 10^e within a few ulps (no overflow or underflow in the steps before
 * the last). */
static double approximate(uint64_t w, int e)
{
    double x = (double)w;
    if (e >= 0) {
        while (e > 22 && x < 1e300) {
            x *= 1e22;
            e -= 22;
        }
        while (e > 22) {
            x *= 1e22; /* -> inf, corrected by the caller's range check */
            e -= 22;
        }
        return x * pow10_exact[e];
    }
    e = -e;
    while (e > 22 && x > 1e-280) {
        x /= 1e22;
        e -= 22;
    }
    while (e > 22) {
        x /= 1e22;
        e -= 22;
    }
    return x / pow10_exact[e];
}

int mfmm_io_strtod(const char *s, const char **end, double *value)
{
    const char *p = s;
    int neg = 0;
    if (*p == '+' || *p == '-') {
        neg = *p == '-';
        p++;
    }
    int n;
    if ((n = match_word(p, "inf")) != 0) {
        p += n;
        if ((n = match_word(p, "inity")) != 0)
            p += n;
        *value = neg ? -HUGE_VAL : HUGE_VAL;
        *end = p;
        return 1;
    }
    if ((n = match_word(p, "nan")) != 0) {
        p += n;
        if (*p == '(') { /* nan(chars) */
            const char *q = p + 1;
            while ((*q >= '0' && *q <= '9') || (*q >= 'a' && *q <= 'z') ||
                   (*q >= 'A' && *q <= 'Z') || *q == '_')
                q++;
            if (*q == ')')
                p = q + 1;
        }
        *value = neg ? -NAN : NAN;
        *end = p;
        return 1;
    }

    char digits[MAX_DIGITS + 1];
    int nd = 0;           /* significant digits kept */
    int dropped = 0;      /* a nonzero digit was dropped past MAX_DIGITS */
    long e10 = 0;         /* value = digits * 10^e10 */
    int any = 0, seen_point = 0;
    for (;; p++) {
        char c = *p;
        if (c == '.' && !seen_point) {
            seen_point = 1;
            continue;
        }
        if (c < '0' || c > '9')
            break;
        any = 1;
        if (nd == 0 && c == '0') {
            if (seen_point)
                e10--;
            continue;
        }
        if (nd < MAX_DIGITS) {
            digits[nd++] = c;
            if (seen_point)
                e10--;
        } else {
            if (c != '0')
                dropped = 1;
            if (!seen_point)
                e10++;
        }
    }
    if (!any)
        return 0;
    if (*p == 'e' || *p == 'E') {
        const char *q = p + 1;
        int eneg = 0;
        if (*q == '+' || *q == '-') {
            eneg = *q == '-';
            q++;
        }
        if (*q >= '0' && *q <= '9') {
            long ev = 0;
            while (*q >= '0' && *q <= '9') {
                if (ev < 100000)
                    ev = ev * 10 + (*q - '0');
                q++;
            }
            e10 += eneg ? -ev : ev;
            p = q;
        }
    }
    *end = p;
    if (dropped) { /* a sticky digit: decides ties, never the rounding otherwise */
        digits[nd++] = '1';
        e10--;
    }
    /* Trailing zeros of the kept digits go into the exponent. */
    while (nd > 0 && digits[nd - 1] == '0') {
        nd--;
        e10++;
    }
    if (nd == 0) {
        *value = neg ? -0.0 : 0.0;
        return 1;
    }
    if (nd + e10 > 310) {
        *value = neg ? -HUGE_VAL : HUGE_VAL;
        return 1;
    }
    if (nd + e10 < -326) {
        *value = neg ? -0.0 : 0.0;
        return 1;
    }
    int e = (int)e10;
    uint64_t w = 0;
    int nw = nd < 19 ? nd : 19;
    for (int i = 0; i < nw; i++)
        w = w * 10 + (uint64_t)(digits[i] - '0');
    if (nd <= 19 && w < ((uint64_t)1 << 53) && e >= -22 && e <= 22) {
        /* Clinger's fast path: both operands exact, one rounding. */
        double x = (double)w;
        x = e >= 0 ? x * pow10_exact[e] : x / pow10_exact[-e];
        *value = neg ? -x : x;
        return 1;
    }
    double x = approximate(w, e + (nd - nw));
    if (isinf(x))
        x = DBL_MAX;
    for (int iter = 0; iter < 4096; iter++) {
        uint64_t m;
        int k;
        decompose(x, &m, &k);
        /* above: (2m+1) 2^(k-1) */
        int c = compare_exact(digits, nd, e, 2 * m + 1, k - 1);
        if (c > 0 || (c == 0 && (m & 1))) {
            if (x == DBL_MAX) {
                x = HUGE_VAL;
                break;
            }
            x = nextafter(x, HUGE_VAL);
            continue;
        }
        if (m == 0)
            break;
        /* below: (2m-1) 2^(k-1), or (4m-1) 2^(k-2) at the bottom of a binade */
        if (m == ((uint64_t)1 << 52) && k > -1074)
            c = compare_exact(digits, nd, e, 4 * m - 1, k - 2);
        else
            c = compare_exact(digits, nd, e, 2 * m - 1, k - 1);
        if (c < 0 || (c == 0 && (m & 1))) {
            x = nextafter(x, 0.0);
            continue;
        }
        break;
    }
    *value = neg ? -x : x;
    return 1;
}

int mfmm_io_format_double(char *buf, size_t size, double x)
{
    char tmp[64];
    int n = snprintf(tmp, sizeof tmp, "%.17g", x);
    if (n < 0 || (size_t)n >= sizeof tmp)
        return -1;
    /* Whatever the locale put between the digits (',' or a multibyte
     * separator) is the decimal point: the only run of bytes that is not
     * a digit, sign, exponent or the letters of inf/nan. */
    size_t j = 0;
    int in_sep = 0;
    for (int i = 0; i < n; i++) {
        char c = tmp[i];
        int plain = (c >= '0' && c <= '9') || c == '-' || c == '+' || c == 'e' || c == 'E' ||
                    c == 'i' || c == 'n' || c == 'f' || c == 'a';
        if (!plain) {
            if (!in_sep) {
                if (j + 1 >= size)
                    return -1;
                buf[j++] = '.';
            }
            in_sep = 1;
            continue;
        }
        in_sep = 0;
        if (j + 1 >= size)
            return -1;
        buf[j++] = c;
    }
    buf[j] = '\0';
    return (int)j;
}
