/* The indexed heap of march.h against a brute-force reference: random
 * inserts, decrease-keys and pops. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <cmocka.h>

#include "march/march.h"

#define N 2000

static void test_heap_random_sequences(void **state)
{
    (void)state;
    static double key[N], T[N];
    static int32_t vert[N], pos[N];
    static uint8_t label[N];
    static double ref[N]; /* reference keys; +inf = not in heap */
    unsigned seed = 12345;
    for (int round = 0; round < 20; round++) {
        mfmm_march_state s = {T, label, key, vert, pos, 0, NULL, 0, INFINITY, 1, 0, NULL, NULL, 0, 0};
        for (int v = 0; v < N; v++) {
            ref[v] = INFINITY;
            label[v] = MFMM_FAR;
        }
        int in_heap = 0;
        for (int op = 0; op < 20000; op++) {
            seed = seed * 1103515245u + 12345u;
            int kind = (seed >> 16) % 4;
            seed = seed * 1103515245u + 12345u;
            int v = (int)((seed >> 8) % N);
            seed = seed * 1103515245u + 12345u;
            /* coarse keys give many ties */
            double k = (double)((seed >> 10) % 512) / 8.0;
            if (kind < 3) {
                if (label[v] == MFMM_ALIVE)
                    continue;
                if (label[v] == MFMM_CLOSE && !(k < ref[v]))
                    continue;
                mfmm_heap_push_or_decrease(&s, v, k, label[v] == MFMM_CLOSE);
                if (label[v] != MFMM_CLOSE)
                    in_heap++;
                label[v] = MFMM_CLOSE;
                ref[v] = k;
            } else if (in_heap > 0) {
                double best = INFINITY;
                for (int u = 0; u < N; u++)
                    if (label[u] == MFMM_CLOSE && ref[u] < best)
                        best = ref[u];
                int top = mfmm_heap_pop(&s);
                assert_int_equal(label[top], MFMM_CLOSE);
                assert_true(ref[top] == best);
                label[top] = MFMM_ALIVE;
                ref[top] = INFINITY;
                in_heap--;
            }
            assert_int_equal(s.heap_size, in_heap);
        }
        /* drain: keys come out in non-decreasing order */
        double last = -INFINITY;
        while (s.heap_size > 0) {
            int top = mfmm_heap_pop(&s);
            assert_true(ref[top] >= last);
            last = ref[top];
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_heap_random_sequences)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
