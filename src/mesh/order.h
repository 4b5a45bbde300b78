/* Vertex and face renumbering (private to the library). A mesh
 * numbers its vertices internally along a space-filling curve, so that
 * vertices near each other on the surface are near each other in every
 * per-vertex array the march reads, and its faces along that order (by
 * their least internal vertex id), so that the faces of the vertices that
 * settle together are near each other too. A face keeps its corner order
 * (barycentric coordinates need no mapping). Everything below the public
 * entry points works in internal ids; the entry points map vertex and face
 * ids, per-vertex and per-face arrays in and out with these helpers. */
#ifndef MFMM_ORDER_H
#define MFMM_ORDER_H

#include "mesh.h"

/* The internal order of a mesh's vertices: *to_external (nv,) lists the
 * input ids in internal order, *to_internal (nv,) is its inverse (both
 * malloc'd). Deterministic: a function of the coordinates and the input
 * ids only. *sorted_keys (nv,): each internal vertex's key in that order
 * (malloc'd), where vertices at one position (==) have one key, so that
 * they lie in one run of equal keys; NULL where the order is the input's
 * (MFMM_VERTEX_ORDER 0). MFMM_ERR_OUT_OF_MEMORY or MFMM_OK. */
mfmm_status mfmm_order_build(const double *xyz, int32_t nv, int32_t **to_internal,
                             int32_t **to_external, uint64_t **sorted_keys);

/* The internal order of a mesh's faces, given their corners' internal
 * vertex ids (each in [0, nv)) in input face order, faces (nf, 3): by least
 * vertex id, then the other two (smaller first), then input id, so that it
 * depends on the faces only, not on their input order. *to_external (nf,)
 * lists the input face ids in internal order, *to_internal (nf,) is its
 * inverse (both malloc'd). MFMM_ERR_OUT_OF_MEMORY or MFMM_OK. */
mfmm_status mfmm_order_faces(const int32_t *faces, int32_t nf, int32_t nv,
                             int32_t **to_internal, int32_t **to_external);

/* Internal id of input face f (checked to be in range): its first piece
 * where it was split at a T-junction, -1 for a needle dropped there
 * (mesh.h); points map with mfmm_order_point_in. */
static inline int32_t mfmm_face_in(const mfmm_mesh *mesh, int32_t f)
{
    return mesh->face_to_internal[f];
}

/* The internal face holding the point of barycentric coordinates b in input
 * face f (checked to be in range), and its coordinates there in out (out
 * may be b): f's internal face, or where f was split at T-junctions the
 * piece the point lies in (the one it lies deepest in); -1 for a needle
 * dropped there (zero area). */
int32_t mfmm_order_point_in(const mfmm_mesh *mesh, int32_t f, const double b[3], double out[3]);

/* 1 when the point b of input face f lies in no face with an area: f is a
 * zero-area face (mfmm_mesh_degenerate), or a needle dropped. */
int mfmm_order_point_degenerate(const mfmm_mesh *mesh, int32_t f, const double b[3]);

/* Input id of internal face f. */
static inline int32_t mfmm_face_out(const mfmm_mesh *mesh, int32_t f)
{
    return mesh->face_to_external[f];
}

/* The face ids of n surface points (a path) from internal to input ids, in
 * place, and their barycentric coordinates to the input face's where it
 * was split at a T-junction. */
void mfmm_order_points_out(const mfmm_mesh *mesh, mfmm_surface_point *points, int32_t n);

/* Per-face values (nf,) from input order to internal order (out != in). */
void mfmm_order_face_values_in(const mfmm_mesh *mesh, const double *in, double *out);

/* Internal id of input vertex v (checked to be in range). */
static inline int32_t mfmm_vertex_in(const mfmm_mesh *mesh, int32_t v)
{
    return mesh->to_internal[v];
}

/* Input id of internal vertex v. */
static inline int32_t mfmm_vertex_out(const mfmm_mesh *mesh, int32_t v)
{
    return mesh->to_external[v];
}

/* out[i] = internal id of ids[i], n of them; out may be ids. */
void mfmm_order_ids_in(const mfmm_mesh *mesh, const int32_t *ids, int32_t n, int32_t *out);

/* Per-vertex values (nv,) from input order to internal order (out != in). */
void mfmm_order_values_in(const mfmm_mesh *mesh, const double *in, double *out);

/* Per-vertex values (nv,) from internal order to input order (out != in). */
void mfmm_order_values_out(const mfmm_mesh *mesh, const double *in, double *out);

/* The arguments of a public call, in internal order: copies of checked
 * sources (vertex and face ids mapped), targets, a per-vertex or per-face
 * cost and a per-vertex value array (the user's T), each NULL when not
 * given. The copies live in one block,
 * reused while large enough (a solver keeps it between solves). */
typedef struct mfmm_mapped_args {
    const mfmm_source *sources;
    const int32_t *targets;
    const double *cost;
    const double *values;
    void *block;
    size_t capacity; /* bytes in block */
} mfmm_mapped_args;

/* Fills `a` (whose block/capacity it keeps or grows). cost_location 1 per
 * vertex, 2 per face, 0 none. MFMM_ERR_OUT_OF_MEMORY or MFMM_OK. */
mfmm_status mfmm_order_map_args(const mfmm_mesh *mesh, const mfmm_source *sources,
                                int32_t n_sources, const int32_t *targets, int32_t n_targets,
                                const double *cost, int cost_location, const double *values,
                                mfmm_mapped_args *a);

#endif
