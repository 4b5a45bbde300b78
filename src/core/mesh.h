/* The mesh's internal layout (private to the library). */
#ifndef MFMM_MESH_H
#define MFMM_MESH_H

#include <math.h>
#include <pthread.h>

#include "meshfmm.h"
#include "march.h"

/* One face of the strip that a virtual edge C -> V crosses (section 4.2).
 * Not stored: mfmm_strip_next re-walks a strip (unfold.c). */
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
    int32_t strip_at, strip_n; /* its strip's steps in the build's buffer */
    double len_a, len_b, cos_c;
    double virt_len, virt_cos_a, virt_cos_b;
} mfmm_corner_full;

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
                                    order (mesh.c fan_order) */
    int32_t *vertex_wedge;
    mfmm_corner_full *full;    /* (3 nf,) while building only, then NULL */
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
    mfmm_virt_step *build_steps; /* while building only (corner order), then NULL */
    mfmm_mesh_info info;
    /* The exact solver's read-only tables (exact/exact.h: face frames, fans),
     * built on the first exact solve or exact start and then shared by every
     * solver, thread and job on this mesh, so that a job costs what its rows
     * reach, not a table build over all faces (0.48 s on a 1M-vertex mesh).
     * Built under cache_lock; freed with the mesh by exact_tables_free. The
     * one part of a built mesh that changes. */
    pthread_mutex_t cache_lock;
    void *exact_tables;
    void (*exact_tables_free)(void *);
    size_t exact_tables_bytes;
    /* The march's spokes (spokes.c), built on the first march at F = 1 with
     * unfolding, under cache_lock, then read-only; NULL until then, and
     * always where spokes_allowed is 0 (mfmm_mesh_options.spokes). */
    int spokes_allowed;
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

/* The mesh's spokes for the march (march.h: F = 1, unfolding on), built
 * on first use under the mesh's lock and kept until mfmm_mesh_destroy:
 * *offset (nv+1) and *spokes. MFMM_ERR_OUT_OF_MEMORY (both NULL: the
 * face walk gives the same rows) or MFMM_OK (both NULL when the mesh was
 * made with mfmm_mesh_options.spokes = 0). */
mfmm_status mfmm_mesh_spokes_of(const mfmm_mesh *mesh, const int32_t **offset,
                                const mfmm_spoke **spokes);

/* Builds a mesh from checked arrays (mfmm_mesh_create's work, without its
 * argument checks and without closing T-junctions): *out, or an error. */
mfmm_status mfmm_mesh_build(const double *vertices, int32_t nv, const int32_t *faces,
                            int32_t nf, const mfmm_mesh_options *opt, mfmm_mesh **out,
                            mfmm_error *err);

/* Closes the T-junctions of *mesh, built from (vertices, nv, faces, nf), in
 * place (tjunction.c): where a zero-area face is a needle A-M-B with M
 * inside edge AB and one face A-B-C across AB, the needle stands for M
 * lying on AB, and the march (no triangle update through zero area) and the
 * paths would go round through A or B. The needle is dropped and A-B-C
 * split at M into two pieces that keep its corner order, rebuilding the
 * mesh until no such needle is left; input face ids, per-face costs,
 * points and paths map through face_to_internal/external and the pieces
 * (order.h). A mesh with none is left as it is. MFMM_OK or an error (the
 * mesh then destroyed and *mesh NULL). */
mfmm_status mfmm_mesh_close_t_junctions(mfmm_mesh **mesh, const double *vertices, int32_t nv,
                                        const int32_t *faces, int32_t nf,
                                        const mfmm_mesh_options *opt, mfmm_error *err);

/* Finds the virtual edge of every obtuse corner by unfolding (section 4.2);
 * fills full[].virt, virt_len, virt_cos_a, virt_cos_b, strip_at, strip_n, the
 * strips' steps (build_steps, corner order) and the counts.
 * Needs the face records' vertices, lengths and cosines, xyz, face_neighbor
 * and the corners (full, corner 3f+k), as mesh creation has them then.
 * MFMM_ERR_OUT_OF_MEMORY or MFMM_OK. */
mfmm_status mfmm_mesh_unfold_obtuse(mfmm_mesh *mesh, int32_t max_steps);

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

/* A walk along a virtual edge's strip, rebuilding its steps as the build
 * found them (bit for bit): mfmm_strip_begin, then mfmm_strip_next per step.
 * The fields are the walk's. */
typedef struct mfmm_vec2 {
    double x, y;
} mfmm_vec2;
typedef struct mfmm_strip_walk {
    const mfmm_mesh *m;
    int32_t corner, a, b, n, i;
    int32_t e1, e2, face, opposite, k1, k2;
    mfmm_vec2 pa, pb, p1, p2, away, pv;
} mfmm_strip_walk;

/* Starts the walk of virtual edge j's strip (j: index in virts). */
void mfmm_strip_begin(mfmm_strip_walk *w, const mfmm_mesh *mesh, int32_t j);

/* The walk's next step into *step: 1, or 0 past the last (whose far is V). */
int mfmm_strip_next(mfmm_strip_walk *w, mfmm_virt_step *step);

/* For the march's virtual stencils under a cost (march.h): uniform[v] = the
 * cost every face around v has (per face), or that v and every neighbour
 * has (per vertex); -1 where they differ; 0 for vertices in no face.
 * cost_location 1 per vertex, 2 per face. */
void mfmm_uniform_cost(const mfmm_mesh *mesh, const double *cost, int cost_location,
                       double *uniform);

/* Fills err (if any) and returns status. */
mfmm_status mfmm_fail(mfmm_error *err, mfmm_status status, int64_t index, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* Marks err as success. */
void mfmm_ok(mfmm_error *err);

/* Checks a public option struct's struct_size (its first field): from
 * sizeof(size_t) to `known` (this library's sizeof) is read; otherwise
 * MFMM_ERR_BAD_ARGUMENT naming `type` (a struct not filled by its _init
 * function, or from a newer header). */
mfmm_status mfmm_check_struct_size(const void *options, size_t known, const char *type,
                                   mfmm_error *err);

/* Reads a caller's option struct into dst (which holds the defaults, `known`
 * bytes): checks struct_size and copies that prefix, so fields beyond an
 * older caller's struct keep their defaults; dst's struct_size becomes known. */
mfmm_status mfmm_read_options(void *dst, const void *options, size_t known, const char *type,
                              mfmm_error *err);

/* A caller's output struct: MFMM_ERR_BAD_ARGUMENT when its struct_size is
 * below sizeof(size_t). */
mfmm_status mfmm_check_info_size(const void *info);

/* Copies the library's filled output struct `all` (`known` bytes) into the
 * caller's `info`, no more than info's struct_size bytes, and sets info's
 * struct_size to the bytes written. MFMM_ERR_BAD_ARGUMENT as above. */
mfmm_status mfmm_write_info(void *info, const void *all, size_t known);

#endif /* MFMM_MESH_H */
