/* The exact solver's queue of windows and vertex events (queue.c; the
 * operations on every window inline here). The queue: buckets of keys (a quarter of a mean edge wide) in a
 * circular window of EX_NB buckets, entries beyond the window in one
 * overflow list that is sorted in when the window moves on. Pops come in
 * key order to within a bucket's width (as the "fast wavefront propagation"
 * of Xu et al. 2015 does for MMP and CH): enough for the pruning, and the
 * result does not depend on it (a pseudo-source started before its
 * distance was final is started again when it improves). Inside a bucket,
 * windows come first in first out: a third of the children fall in the
 * current bucket, and taken last in first out each of those was the next
 * pop, waiting on its parent (divisions, a square root); in arrival order
 * the next pop is an older entry the core can start on meanwhile.
 * Vertex events (pseudo-sources to start) come after the bucket's windows,
 * which can still lower them: a saddle started early is started again
 * (first in first out without this: 280 starts for 193 saddles). */
#ifndef MFMM_EXACT_QUEUE_H
#define MFMM_EXACT_QUEUE_H

#include "state.h"

size_t ex_bytes(const mfmm_exact_ws *ws, int32_t heap_cap);

/* Grows the entries by doubling, within memory_limit. */
int ex_grow(mfmm_exact_ws *ws);

/* Moves the overflow entries that now fall in the window into it; with
 * the window empty, first moves the window to the least of them. */
void ex_refill(mfmm_exact_ws *ws);


static inline int64_t ex_bucket(const mfmm_exact_ws *ws, double key)
{
    double b = key * ws->inv_w;
    /* keys are distances, >= 0 but for negative source values: truncation
     * is the floor there and needs no library call or rounding mode */
    if (b >= 0.0 && b < 1e18)
        return (int64_t)b;
    b = floor(b);
    if (!(b > -1e18))
        b = -1e18;
    if (b > 1e18)
        b = 1e18;
    return (int64_t)b;
}

static inline void ex_link(mfmm_exact_ws *ws, int32_t e)
{
    int64_t b = ex_bucket(ws, ws->heap[e].key);
    if (b < ws->cur)
        b = ws->cur;
    if (b >= ws->cur + EX_NB) {
        ws->heap[e].next = ws->over;
        ws->over = e;
        return;
    }
    int32_t i = (int32_t)(b & (EX_NB - 1));
    ws->n_in++;
    if (ws->heap[e].he < 0) {
        ws->heap[e].next = ws->bhead[2 * EX_NB + i];
        ws->bhead[2 * EX_NB + i] = e;
        return;
    }
    ws->heap[e].next = -1;
    if (ws->bhead[i] < 0)
        ws->bhead[i] = e;
    else
        ws->heap[ws->bhead[EX_NB + i]].next = e;
    ws->bhead[EX_NB + i] = e;
}

/* A free entry (its fields to be filled, then ex_queue), or -1. */
static inline int32_t ex_new(mfmm_exact_ws *ws)
{
    int32_t e = ws->qfree;
    if (e >= 0) {
        ws->qfree = ws->heap[e].next;
        return e;
    }
    if (ws->heap_used == ws->heap_cap && !ex_grow(ws))
        return -1;
    return ws->heap_used++;
}

static inline void ex_queue(mfmm_exact_ws *ws, int32_t e)
{
    ws->heap_n++;
    if (ws->heap_n > ws->peak_windows)
        ws->peak_windows = ws->heap_n;
    ex_link(ws, e);
}

/* Takes the next entry out of the queue (which must not be empty) into *out. */
static inline void ex_pop(mfmm_exact_ws *ws, ex_entry *out)
{
    for (;;) {
        if (ws->n_in == 0 || ws->cur >= ws->redist + EX_NB)
            ex_refill(ws);
        int32_t i = (int32_t)(ws->cur & (EX_NB - 1));
        int32_t e = ws->bhead[i];
        if (e < 0) {
            /* the bucket's windows are done: its vertex events */
            i += 2 * EX_NB;
            e = ws->bhead[i];
            if (e < 0) {
                ws->cur++;
                continue;
            }
        }
        ws->bhead[i] = ws->heap[e].next;
#ifdef __GNUC__
        /* the next pop's record: a cold line when its bucket filled earlier */
        if (ws->bhead[i] >= 0)
            __builtin_prefetch(ws->heap + ws->bhead[i]);
#endif
        ws->n_in--;
        ws->heap_n--;
        *out = ws->heap[e];
        ws->heap[e].next = ws->qfree;
        ws->qfree = e;
        return;
    }
}

#endif
