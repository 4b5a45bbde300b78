/* The exact solver's queue: its growth and refill (queue.h). */
#include <stdlib.h>
#include <string.h>

#include "queue.h"

size_t ex_bytes(const mfmm_exact_ws *ws, int32_t heap_cap)
{
    return ws->fixed_bytes + (size_t)heap_cap * sizeof(ex_entry) +
           (size_t)ws->rec_cap * sizeof(ex_rec) + (size_t)ws->pass_cap * 4 * sizeof(int32_t);
}

/* Grows the entries by doubling, within memory_limit. */
int ex_grow(mfmm_exact_ws *ws)
{
    int32_t cap = ws->heap_cap;
    if (cap >= INT32_MAX / 2) {
        ws->failed = MFMM_ERR_MEMORY_LIMIT;
        return 0;
    }
    int32_t ncap = cap ? 2 * cap : 1024;
    if (ws->memory_limit && ex_bytes(ws, ncap) > ws->memory_limit) {
        /* the largest size that fits, if it is any larger */
        size_t room = ws->memory_limit > ws->fixed_bytes ? ws->memory_limit - ws->fixed_bytes : 0;
        if (room / sizeof(ex_entry) <= (size_t)cap) {
            ws->failed = MFMM_ERR_MEMORY_LIMIT;
            return 0;
        }
        ncap = (int32_t)(room / sizeof(ex_entry));
    }
    ex_entry *p = realloc(ws->heap, (size_t)ncap * sizeof *p);
    if (!p) {
        ws->failed = MFMM_ERR_OUT_OF_MEMORY;
        return 0;
    }
    ws->heap = p;
    ws->heap_cap = ncap;
    if (ex_bytes(ws, ncap) > ws->peak_bytes)
        ws->peak_bytes = ex_bytes(ws, ncap);
    return 1;
}

/* Moves the overflow entries that now fall in the window into it; with
 * the window empty, first moves the window to the least of them. */
void ex_refill(mfmm_exact_ws *ws)
{
    if (ws->n_in == 0) {
        int64_t lo = INT64_MAX;
        for (int32_t e = ws->over; e >= 0; e = ws->heap[e].next) {
            int64_t b = ex_bucket(ws, ws->heap[e].key);
            if (b < lo)
                lo = b;
        }
        if (lo > ws->cur)
            ws->cur = lo;
    }
    ws->redist = ws->cur;
    int32_t e = ws->over;
    ws->over = -1;
    while (e >= 0) {
        int32_t next = ws->heap[e].next;
        ex_link(ws, e);
        e = next;
    }
}
