/* Windows at non-manifold edges (nonmanifold.c): those kept per face
 * entered, and the trimming of a later window against them. */
#ifndef MFMM_EXACT_NONMANIFOLD_H
#define MFMM_EXACT_NONMANIFOLD_H

#include "state.h"

/* Trims the window [*s0, *s1] (pseudo-source (px, py), sigma; the frame of
 * a half-edge of length L) against the windows kept at that half-edge's
 * slot: the part where a kept window gives no more is dropped, as MMP does
 * with the windows of an edge (Surazhsky et al. 2005, section 3.3), here
 * only from the ends, so that it stays one interval. Sound in any order:
 * kept windows are never removed, and a kept window trimmed later against
 * a vertex is beaten there by a path through that vertex. Returns 0 when
 * nothing is left. Without it, folded fans of 5-8 faces on one edge passed
 * windows round without bound (fuzz input nonmanifold-fans-window-blowup). */
int ex_dominate(const mfmm_exact_ws *ws, int32_t slot, double L, double *s0p,
                       double *s1p, double px, double py, double sigma);

/* The slot (-2 or below; a non-manifold half-edge's is its index in nm_he)
 * of the windows queued at zero-area half-edge h where a pass was cut
 * (ex_pass_later), made on first use in a run; -1 when memory allows no
 * more. */
int32_t ex_pass_slot(mfmm_exact_ws *ws, int32_t h);

/* Frees every slot of cut passes for a new run (their lists in rec go
 * with it). */
void ex_pass_reset(mfmm_exact_ws *ws);

/* Keeps a fanned-out window (or one queued from a cut pass) at its slot
 * for ex_dominate, while memory allows (one not kept only trims nothing). */
void ex_keep(mfmm_exact_ws *ws, int32_t slot, double b0, double b1, double px, double py,
             double sigma);

#endif
