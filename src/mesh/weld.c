/* mfmm_weld_map: coincident vertices numbered as one, by first occurrence. */
#include <math.h>
#include <stdlib.h>

#include "base/error.h"
#include "meshfmm.h"
#include "weld.h"

mfmm_status mfmm_weld_map(const double *vertices, int32_t nv, int32_t *map, int32_t *n_welded,
                          mfmm_error *err)
{
    if (!vertices || !map || !n_welded)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "%s is NULL",
                         !vertices ? "vertices" : !map ? "map" : "n_welded");
    *n_welded = 0;
    if (nv < 0)
        return mfmm_fail(err, MFMM_ERR_BAD_COUNT, -1, "nv is %ld; it must be >= 0", (long)nv);
    for (size_t i = 0; i < 3 * (size_t)nv; i++)
        if (!isfinite(vertices[i]))
            return mfmm_fail(err, MFMM_ERR_NONFINITE_VERTEX, (int64_t)(i / 3),
                             "vertex %ld has a coordinate that is not finite", (long)(i / 3));
    size_t cap = mfmm_position_table_size((size_t)nv);
    int32_t *table = malloc(cap * sizeof *table);
    if (!table)
        return mfmm_fail(err, MFMM_ERR_OUT_OF_MEMORY, -1, "out of memory for %ld vertices",
                         (long)nv);
    for (size_t i = 0; i < cap; i++)
        table[i] = -1;
    int32_t n = 0;
    for (int32_t v = 0; v < nv; v++) {
        const double *p = vertices + 3 * (size_t)v;
        size_t i = (size_t)mfmm_position_hash(p) & (cap - 1);
        for (;;) {
            int32_t w = table[i];
            if (w < 0) {
                table[i] = v;
                map[v] = n++;
                break;
            }
            const double *q = vertices + 3 * (size_t)w;
            if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) {
                map[v] = map[w];
                break;
            }
            i = (i + 1) & (cap - 1);
        }
    }
    free(table);
    *n_welded = n;
    return MFMM_OK;
}
