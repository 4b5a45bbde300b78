/* The straight start around a point source (private to the library): every
 * vertex that a straight segment from the point reaches through the unfolded
 * faces near it, with that segment. Used to seed a march (the paper's plain
 * start, and where the exact start of src/solve does not apply) and by the
 * tracer to end a path at the source (paths/trace.c). */
#ifndef MFMM_START_H
#define MFMM_START_H

#include <math.h>

#include "mesh/mesh.h"

/* The walk reaches faces whose entry edge is nearer the point than this many
 * mean edge lengths (or the longest edge, if longer), at most
 * MFMM_START_DEPTH edges from it. */
#define MFMM_START_RADIUS 2.0
#define MFMM_START_DEPTH 32

/* Where a checked point source (face >= 0) lies, from its barycentric
 * coordinates (weights <= 0 count as 0): at a vertex (two zero weights), on
 * an edge (one), or inside its face. Shared by the straight start and the
 * exact start (start/seed.c), which must agree on it. */
typedef enum mfmm_source_kind { MFMM_AT_VERTEX, MFMM_ON_EDGE, MFMM_IN_FACE } mfmm_source_kind;
typedef struct mfmm_source_loc {
    mfmm_source_kind kind;
    int32_t vertex; /* at a vertex: it; else the face's corner of largest weight */
    int zero;       /* on an edge: the corner of the face opposite it; else -1 */
    int32_t across; /* on an edge: the face across it (-1 at a wall; may be degenerate) */
    double p[3];    /* the point */
} mfmm_source_loc;

void mfmm_source_locate(const mfmm_mesh *mesh, const mfmm_source *src, mfmm_source_loc *loc);

/* Euclidean distance between two points (3 doubles each). */
static inline double mfmm_dist3(const double *p, const double *q)
{
    double a = p[0] - q[0], b = p[1] - q[1], c = p[2] - q[2];
    return sqrt(a * a + b * b + c * c);
}

/* A vertex the walk reached, with the segment's way there. */
typedef struct mfmm_start_hit {
    int32_t vertex;
    double length;      /* Euclidean length of the segment */
    double cost_length; /* its length weighted by the cost (see mfmm_start_walk) */
    int32_t depth;      /* edges crossed */
    /* edge i crossed (i < depth): ends (a[i], b[i]) at a[i] + t[i] (b[i] - a[i]),
     * from face face[i] into face[i + 1]; face[0] holds the point, face[depth] the vertex */
    const int32_t *a, *b, *face;
    const double *t;
} mfmm_start_hit;

/* Called for each vertex reached (a vertex may be reached several ways);
 * returns non-zero to stop the walk. */
typedef int (*mfmm_start_fn)(void *user, const mfmm_start_hit *hit);

/* Walks from a checked point source (face >= 0): the faces holding the point
 * (one, the two of an edge it lies on, or all around a vertex it is at, so
 * that the result does not depend on which face names it), their corners,
 * then straight on through their edges within MFMM_START_RADIUS. cost NULL:
 * cost_length = length; per vertex: the mean of F at the point (linear in
 * its face) and at the vertex reached, times length (trapezoid, as
 * march.h); per face: the sum over the faces crossed of F times the piece
 * in that face. */
void mfmm_start_walk(const mfmm_mesh *mesh, const mfmm_source *src, const double *cost,
                     int cost_location, mfmm_start_fn fn, void *user);

/* Seeds a checked source into a reset march state (cost fields set): a
 * vertex at its value, a point through mfmm_start_walk at value plus each
 * segment's cost. */
void mfmm_start_seed(const mfmm_mesh *mesh, mfmm_march_state *st, const mfmm_source *src);

#endif
