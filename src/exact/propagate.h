/* Window propagation (propagate.c): a window across a face, through
 * zero-area faces and non-manifold edges; the starts of sources and
 * pseudo-sources. */
#ifndef MFMM_EXACT_PROPAGATE_H
#define MFMM_EXACT_PROPAGATE_H

#include "state.h"

/* Lowers d(v) to dist if that is less. Returns 1 when v is then a
 * pseudo-source to start, with a known fan, and the new distance is less
 * by more than rounding: the caller then gives the direction it came from
 * (ex_set_in). A gain within rounding keeps the direction of the path it
 * ties with: rays that graze a vertex along an edge reach it again from
 * faces they do not cross, with directions that are not theirs. */
int ex_update(mfmm_exact_ws *ws, int32_t v, double dist, int force);

void ex_propagate(mfmm_exact_ws *ws, const ex_entry *w);

/* A pseudo-source at v with distance dv: a window on the far edge of every
 * face around v. */
void ex_start_vertex(mfmm_exact_ws *ws, int32_t v, double dv);

/* A point source in face f (barycentric w, not at a corner): a window on
 * each of f's edges. */
void ex_start_face(mfmm_exact_ws *ws, int32_t f, const double *w, double value);

#endif
