/* The state of one path being traced (private to src/paths): the mesh, T,
 * the costs, the sources to end at, and the points so far. Shared by the
 * field (field.c) and the walk (trace.c). */
#ifndef MFMM_PATHS_STATE_H
#define MFMM_PATHS_STATE_H

#include "mesh/mesh.h"

#define SNAP_BARY 1e-9      /* a crossing this close to a corner is at the vertex */
#define OUTWARD_COS 1e-9    /* a direction leaves through an edge it lies on */
#define SONIC_COS 0.70710678118654752 /* predictor and corrector 45 degrees apart: sonic */
#define STALL_STEPS 64      /* steps without T decreasing before giving up */
#define PIVOT_RATIO 1e-7    /* 6x6 fit refused below this pivot ratio */

typedef struct src_key {
    int32_t key; /* vertex id (vertex sources) or face id (face sources) */
    int32_t idx; /* index into options->sources */
} src_key;

typedef struct tracer {
    const mfmm_mesh *m;
    const double *T;
    const mfmm_source *src;
    int32_t n_src;
    const double *cost;
    mfmm_cost_location cost_loc;
    src_key *vkeys, *fkeys;
    int32_t n_vkeys, n_fkeys;
    mfmm_surface_point *pts;
    int32_t cap, n, max_points;
    int grow;             /* pts is the tracer's own, grown as needed */
    double len, wlen;
    double last_xyz[3], last_F;
    mfmm_error *err;
    mfmm_status st;
} tracer;

#endif
