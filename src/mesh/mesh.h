/* The mesh's internal layout (private to the library): the type every
 * part of the library takes, and small inline accessors. Built by build.c. */
#ifndef MFMM_MESH_H
#define MFMM_MESH_H

#include <math.h>
#include <pthread.h>

#include "meshfmm.h"
#include "march/march.h"

/* One face of the strip that a virtual edge C -> V crosses (section 4.2).
 * Not stored: mfmm_strip_next re-walks a strip (unfold.c). */
typedef struct mfmm_virt_step {
    int32_t face;   /* the face entered */
    int32_t far;    /* its vertex off the edge crossed (the last step's is V) */
    int32_t e1, e2; /* the edge crossed */
    double t;       /* CV crosses it at e1 + t (e2 - e1) */
} mfmm_virt_step;

struct mfmm_mesh {
    /* nf: the faces built; nf_in: the faces as given (info.n_faces). They
     * differ where T-junctions were closed (tjunction.c): a zero-area needle
     * dropped, the face across its long edge split in two. */
    int32_t nv, nf, nf_in;
    /* Vertices are numbered internally along a space-filling curve, faces
     * by their least internal vertex (order.h): every per-vertex and
     * per-face array below, and the vertex ids in the face records, are in that order;
     * a face keeps its corner order. */
    int32_t *to_internal;      /* (nv,) internal id of each input vertex */
    int32_t *to_external;      /* (nv,) input id of each internal vertex */
    int32_t *face_to_internal; /* (nf_in,) internal id of each input face (its
                                  first piece; -1: a needle dropped, tjunction.c) */
    int32_t *face_to_external; /* (nf,) input id of each internal face */
    /* Only where T-junctions were closed (tjunction.c), else NULL: piece_next
     * (nf,) the next internal face cut from the same input face, -1 after
     * the last; piece_bary (nf, 3, 3): corner j of internal face f in the
     * barycentric coordinates of its input face, piece_bary[9 f + 3 j + i]. */
    int32_t *piece_next;
    double *piece_bary;
    double *xyz;               /* (nv, 3) */
    int32_t *face_neighbor;    /* (nf, 3): face across the edge opposite corner k,
                                  -1 at a boundary or non-manifold edge */
    int32_t *vertex_face_offset; /* (nv+1,) CSR: each vertex's faces, as
                                    MFMM_WEDGE(f, k) (local_update.h), in fan
                                    order (build.c fan_vertex) */
    int32_t *vertex_wedge;
    mfmm_face *face_records;   /* (nf,) for the march (local_update.h), 64-byte aligned;
                                  face f's vertices: face_records[f].v (the
                                  mesh's only copy of the faces) */
    void *face_block;          /* the allocation face_records lies in */
    mfmm_virt *virts;          /* (n_virts,) virtual edges for the march, sorted by V */
    int32_t n_virts;
    int32_t *virt_first;       /* (nv+1,) CSR: virts[virt_first[v]..] end at v */
    int32_t *virt_strip;       /* (n_virts + 1,) CSR by virtual edge (virts' order)
                                  into strip */
    int32_t *strip;            /* each virtual edge's strip: the vertex off the edge
                                  crossed at each step but the last (whose is V),
                                  for the march's cost test (mfmm_march_mesh.strip;
                                  the strip's faces and crossings: mfmm_strip_next) */
    mfmm_mesh_info info;
    /* The exact solver's read-only tables (exact/exact.h: face frames, fans),
     * built on the first exact solve or exact start and then shared by every
     * solver, thread and job on this mesh, so that a job costs what its rows
     * reach, not a table build over all faces.
     * Built under cache_lock; freed with the mesh by exact_tables_free. The
     * one part of a built mesh that changes. */
    pthread_mutex_t cache_lock;
    void *exact_tables;
    void (*exact_tables_free)(void *);
    size_t exact_tables_bytes;
    /* The march's spokes (spokes.c), built under cache_lock once marches at
     * F = 1 with unfolding have settled MFMM_SPOKES_AFTER times nv vertices
     * without them (spoke_credit), or for a job of many rows; then
     * read-only. NULL until then, and always where spokes_allowed is 0
     * (mfmm_mesh_options.spokes). */
    int spokes_allowed;
    int64_t spoke_credit;
    int32_t *spoke_offset;     /* (nv+1,) CSR into spokes */
    mfmm_spoke *spokes;        /* 64-byte aligned, in spoke_block */
    void *spoke_block;
    size_t spokes_bytes;
};

/* The arrays a march reads. */
static inline mfmm_march_mesh mfmm_mesh_march_view(const mfmm_mesh *mesh)
{
    mfmm_march_mesh m;
    m.nv = mesh->nv;
    m.wedge_offset = mesh->vertex_face_offset;
    m.wedge = mesh->vertex_wedge;
    m.faces = mesh->face_records;
    m.virts = mesh->virts;
    m.virt_first = mesh->virt_first;
    m.strip_offset = mesh->virt_strip;
    m.strip = mesh->strip;
    m.spoke_offset = NULL; /* the face walk (a march that wants spokes sets them) */
    m.spokes = NULL;
    return m;
}

/* 1 when face f has zero area (its record's cosines are NaN), else 0. */
static inline int mfmm_mesh_degenerate(const mfmm_mesh *mesh, int32_t f)
{
    return isnan(mesh->face_records[f].cosv[0]);
}

/* 1 when face f has the vertices of face f - 1, in any order: a copy, as
 * exporters leave them. Faces are ordered by their sorted vertices
 * (order.h), so copies follow the face they copy. A copy takes no part in
 * the adjacency (build_edges: an edge's copies stand aside, and a copy's
 * edges lead where its original's do) nor in the exact solver's surface;
 * the march updates through it as through its original. */
static inline int mfmm_mesh_copy(const mfmm_mesh *mesh, int32_t f)
{
    if (f <= 0)
        return 0;
    const int32_t *a = mesh->face_records[f].v, *b = mesh->face_records[f - 1].v;
    for (int k = 0; k < 3; k++) /* a face's vertices are distinct (validate) */
        if (a[k] != b[0] && a[k] != b[1] && a[k] != b[2])
            return 0;
    return 1;
}

/* The face that face f copies (mfmm_mesh_copy), or f. */
static inline int32_t mfmm_mesh_original(const mfmm_mesh *mesh, int32_t f)
{
    while (mfmm_mesh_copy(mesh, f))
        f--;
    return f;
}

/* The vertex at corner c = 3 f + k: face f's vertex k. */
static inline int32_t mfmm_mesh_corner_vertex(const mfmm_mesh *mesh, int32_t c)
{
    return mesh->face_records[c / 3].v[c % 3];
}

/* The index in virts of corner 3 f + k's virtual edge, or -1 if it has none. */
static inline int32_t mfmm_mesh_virt_index(const mfmm_mesh *mesh, int32_t corner)
{
    const mfmm_face *fr = mesh->face_records + corner / 3;
    if ((fr->virt & 3) != corner % 3)
        return -1;
    mfmm_march_mesh m = mfmm_mesh_march_view(mesh);
    return (int32_t)(mfmm_march_virt_of(&m, fr->virt >> 2, corner) - mesh->virts);
}

/* The point with barycentric coordinates b (summing to 1) in face f. */
static inline void mfmm_bary_to_xyz(const mfmm_mesh *m, int32_t f, const double b[3], double x[3])
{
    for (int i = 0; i < 3; i++)
        x[i] = 0.0;
    for (int k = 0; k < 3; k++) {
        const double *X = m->xyz + 3 * (size_t)m->face_records[f].v[k];
        for (int i = 0; i < 3; i++)
            x[i] += b[k] * X[i];
    }
}

#endif /* MFMM_MESH_H */
