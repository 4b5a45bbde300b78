/* The mesh's internal layout (private to the library). */
#ifndef MFMM_MESH_H
#define MFMM_MESH_H

#include <pthread.h>

#include "meshfmm.h"
#include "march.h"

/* One face of the strip that a virtual edge C -> V crosses (section 4.2). */
typedef struct mfmm_virt_step {
    int32_t face;   /* the face entered */
    int32_t far;    /* its vertex off the edge crossed (the last step's is V) */
    int32_t e1, e2; /* the edge crossed */
    double t;       /* CV crosses it at e1 + t (e2 - e1) */
} mfmm_virt_step;

/* A corner while the mesh is built (mesh.c, unfold.c), by corner id 3f+k;
 * the march gets records per face (mfmm_face, mfmm_virt) from these. virt:
 * V's id >= 0 (the obtuse corner is split by the virtual edge to V), or one
 * of the MFMM_VIRT_ codes. */
#define MFMM_VIRT_NONE (-1)       /* not obtuse: the plain stencil */
#define MFMM_VIRT_FAILED (-2)     /* obtuse, walk failed: plain stencil */
#define MFMM_VIRT_DEGENERATE (-3) /* zero-area face: edge updates only */
typedef struct mfmm_corner_full {
    int32_t face, a, b, virt;
    double len_a, len_b, cos_c;
    double virt_len, virt_cos_a, virt_cos_b;
} mfmm_corner_full;

struct mfmm_mesh {
    int32_t nv, nf;
    /* Vertices are numbered internally along a space-filling curve, faces
     * by their least internal vertex (order.h): every per-vertex and
     * per-face array below, and the vertex ids in faces, are in that order;
     * a face keeps its corner order. */
    int32_t *to_internal;      /* (nv,) internal id of each input vertex */
    int32_t *to_external;      /* (nv,) input id of each internal vertex */
    int32_t *face_to_internal; /* (nf,) internal id of each input face */
    int32_t *face_to_external; /* (nf,) input id of each internal face */
    double *xyz;               /* (nv, 3) */
    int32_t *faces;            /* (nf, 3) */
    int32_t *face_neighbor;    /* (nf, 3): face across the edge opposite corner k,
                                  -1 at a boundary or non-manifold edge */
    int32_t *vertex_face_offset; /* (nv+1,) CSR: corners (3f+k) at each vertex */
    int32_t *vertex_face_corner;
    int32_t *component;        /* (nv,) component id, -1 for unreferenced vertices */
    uint8_t *degenerate;       /* (nf,) 1 for zero-area faces */
    mfmm_corner_full *full;    /* (3 nf,) while building only, then NULL */
    mfmm_face *face_records;   /* (nf,) for the march (local_update.h), 64-byte aligned */
    void *face_block;          /* the allocation face_records lies in */
    mfmm_virt *virts;          /* (n_virts,) virtual edges for the march, sorted by V */
    int32_t n_virts;
    int32_t *virt_first;       /* (nv+1,) CSR: virts[virt_first[v]..] end at v */
    int32_t *virt_offset;      /* (3 nf + 1,) CSR by corner 3f+k into virt_steps: the
                                  strip of an obtuse corner's virtual edge */
    mfmm_virt_step *virt_steps;
    int32_t *strip;            /* virt_steps[].far, for the march (see
                                  mfmm_march_mesh.strip) */
    mfmm_mesh_info info;
    /* The exact solver's read-only tables (exact/exact.h: face frames, fans),
     * built on the first exact solve or exact start and then shared by every
     * solver, thread and job on this mesh, so that a job costs what its rows
     * reach, not a table build over all faces (0.48 s on a 1M-vertex mesh,
     * issue 11). Built under cache_lock; freed with the mesh by
     * exact_tables_free. The one part of a built mesh that changes. */
    pthread_mutex_t cache_lock;
    void *exact_tables;
    void (*exact_tables_free)(void *);
    size_t exact_tables_bytes;
};

/* The arrays a march reads. */
static inline mfmm_march_mesh mfmm_mesh_march_view(const mfmm_mesh *mesh)
{
    mfmm_march_mesh m;
    m.nv = mesh->nv;
    m.wedge_offset = mesh->vertex_face_offset;
    m.wedge = mesh->vertex_face_corner;
    m.faces = mesh->face_records;
    m.virts = mesh->virts;
    m.virt_first = mesh->virt_first;
    m.strip_offset = mesh->virt_offset;
    m.strip = mesh->strip;
    return m;
}

/* Finds the virtual edge of every obtuse corner by unfolding (section 4.2);
 * fills full[].virt, virt_len, virt_cos_a, virt_cos_b, the strips
 * (virt_offset, virt_steps) and the counts.
 * Needs faces, xyz, face_neighbor, corners' lengths and cosines, with the
 * corners still in face order (corner 3f+k), as mesh creation has them then.
 * MFMM_ERR_OUT_OF_MEMORY or MFMM_OK. */
mfmm_status mfmm_mesh_unfold_obtuse(mfmm_mesh *mesh, int32_t max_steps);

/* For the march's virtual stencils under a cost (march.h): uniform[v] = the
 * cost every face around v has (per face), or that v and every neighbour
 * has (per vertex); -1 where they differ; 0 for vertices in no face.
 * cost_location 1 per vertex, 2 per face. */
void mfmm_uniform_cost(const mfmm_mesh *mesh, const double *cost, int cost_location,
                       double *uniform);

/* The bytes a built mesh holds, array by array (issue 13.3): up to `max`
 * entries of (name, bytes) into names/bytes; returns the number of arrays
 * (all of them, even past max). */
int mfmm_mesh_memory(const mfmm_mesh *mesh, const char **names, size_t *bytes, int max);

/* Fills err (if any) and returns status. */
mfmm_status mfmm_fail(mfmm_error *err, mfmm_status status, int64_t index, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* Marks err as success. */
void mfmm_ok(mfmm_error *err);

/* Checks a public option struct's struct_size (its first field) against the
 * layout this library knows, `known` = sizeof; MFMM_ERR_BAD_ARGUMENT naming
 * `type` when they differ (a struct not filled by its _init function, or
 * compiled against another header version). */
mfmm_status mfmm_check_struct_size(const void *options, size_t known, const char *type,
                                   mfmm_error *err);

#endif /* MFMM_MESH_H */
