/* The window method behind MFMM_METHOD_WINDOWS (internal): window
 * propagation keeping K windows in place on each half-edge ("slots"), in
 * distance order. Every value it writes is the length of a path on the
 * surface, so never below the exact solver's beyond rounding. The design:
 * slots.c. */
#ifndef MFMM_EXACT_SLOTS_H
#define MFMM_EXACT_SLOTS_H

#include <stdint.h>

#include "exact.h"

typedef struct mfmm_slots mfmm_slots;

/* A workspace on the mesh's exact tables (mfmm_exact_tables_of). */
mfmm_status mfmm_slots_create(const mfmm_mesh *mesh, mfmm_slots **out);
void mfmm_slots_destroy(mfmm_slots *s);
/* flat (nv,): 1 where a vertex's offers are redundant once a window's ray
 * reaches it (its neighbourhood unfolds flat, or a wall's vertex of pi or
 * less); the tables built everywhere (mfmm_exact_tables_ensure). */
void mfmm_slots_flat(const mfmm_exact_tables *t, uint8_t *flat);
/* The same on the mesh's tables, once mfmm_slots_tables_of has succeeded. */
void mfmm_slots_flat_of(const mfmm_mesh *mesh, uint8_t *flat);

/* The arrays the window method's OpenCL kernel reads (kernels/windows_rows.cl):
 * the mesh's exact tables, built everywhere. fr: nf face records of
 * fr_size bytes each (face_frame.h's ex_face); vf_offset (nv + 1),
 * vf_corner (3 nf), face_in (nf); nm_he and nm_next (n_nm). */
typedef struct mfmm_slots_tables {
    const void *fr;
    size_t fr_size;
    const int32_t *vf_offset, *vf_corner, *face_in, *nm_he, *nm_next;
    int32_t n_nm;
} mfmm_slots_tables;
mfmm_status mfmm_slots_tables_of(const mfmm_mesh *mesh, mfmm_slots_tables *out);

/* The bytes of one solve's arrays in one block, as the kernel lays them
 * out (K = 2). */
size_t mfmm_slots_block_bytes(const mfmm_mesh *mesh);

/* About the bytes a workspace holds on `mesh` (K = 2), its tables apart. */
size_t mfmm_slots_bytes(const mfmm_mesh *mesh);

/* K windows per half-edge instead of 2 (1 to 8). 0 when out of memory or
 * K is out of range. */
int mfmm_slots_set_k(mfmm_slots *s, int K);

/* Distances from internal vertex `source` to every vertex, in internal
 * order (out: nv, +inf where not reached). */
void mfmm_slots_solve(mfmm_slots *s, int32_t source, double *out);

/* Several vertex sources (internal ids), each with its value (value NULL:
 * all 0); out as mfmm_slots_solve. */
void mfmm_slots_solve_multi(mfmm_slots *s, int32_t n, const int32_t *src, const double *value,
                            double *out);

/* A point in internal face f: w[j] the barycentric weight of internal
 * vertex fv[j] (fv: f's corners in any order). Its corners get their
 * straight distances and its edges windows of the point. A face with no
 * area (or weights summing to 0 or less) reaches nothing: all +inf. */
void mfmm_slots_solve_face(mfmm_slots *s, int32_t f, const int32_t fv[3], const double w[3],
                           double *out);

/* The costs a run with a cost in internal ids, per vertex (cost_location
 * 1) or per face (2), reads, relative to the least cost, which is returned
 * (the run's values are in its units): fout (nf) each exact-table record's
 * (sl_state.fcost): the face's, or per vertex the corners' common cost, -1
 * where they differ; per vertex, vout (nv) the vertices'. */
double mfmm_slots_face_cost(const mfmm_mesh *mesh, const double *cost, int cost_location,
                            double *fout, double *vout);

/* The solve behind MFMM_METHOD_WINDOWS: sources as for mfmm_solve, in
 * internal ids (vertex sources, points in faces, each with its value),
 * stopped once the front passes max_distance (+inf: none) or, with
 * n_targets > 0, once every internal vertex of `targets` has settled and the
 * front has passed the largest of their values. T: (nv,) +inf on entry; the
 * values of the vertices settled by then are written (those within
 * max_distance), the same bits as a solve without the stops (values after
 * a vertex settles only lower it by rounding, 1e-13 relative, and the run
 * goes on past the stop by SL_STOP relative). settled: (nv,) out, may be
 * NULL: the vertices written. cost: NULL, or per vertex (cost_location 1)
 * or per face (2) in internal ids (sl_state.fcost, slots_core.h). Returns
 * how many. */
int32_t mfmm_slots_run(mfmm_slots *s, const mfmm_source *sources, int32_t n_sources,
                       double max_distance, const int32_t *targets, int32_t n_targets,
                       const double *cost, int cost_location, double *T, int32_t *settled);

/* Counters of the last solve. */
typedef struct mfmm_slots_info {
    int64_t crossed;   /* windows passed across a face */
    int64_t emitted;   /* windows offered to a slot (children and vertex offers) */
    int64_t kept;      /* of those, kept in a slot */
    int64_t late;      /* kept in a half-edge already passed */
    int64_t late_vertex; /* lowerings of a settled vertex */
    int64_t settled;
    int64_t narrow, trimmed, evicted; /* offers dropped: too narrow, trimmed away, one of three */
    int64_t merged;    /* offers joined to a slot with the same pseudo-source */
} mfmm_slots_info;
void mfmm_slots_get_info(const mfmm_slots *s, mfmm_slots_info *info);

#endif
