/* Small surface-point helpers shared by path tracing (field.c, trace.c, path.c) and
 * straightening (straighten.c). */
#ifndef MFMM_PATHS_SURFACE_H
#define MFMM_PATHS_SURFACE_H

#include <math.h>

#include "mesh/mesh.h"
#include "start/straight.h" /* mfmm_dist3 */

#define ON_EDGE 1e-12 /* barycentric coordinate treated as 0 (on the edge) */

static inline double mfmm_dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

#endif
