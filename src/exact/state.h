/* The exact solver's state (private to src/exact and the exact start's
 * patch, start/patch.c): its constants, a mesh's read-only tables (face
 * records, fans, non-manifold edges), a workspace (one solve's distances
 * and its queue of windows), and small helpers on them. The algorithm:
 * solver.c. */
#ifndef MFMM_EXACT_STATE_H
#define MFMM_EXACT_STATE_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "exact.h"
#include "face_frame.h"
#include "mesh/mesh.h"

#define EX_PI 3.14159265358979323846264338328
#define EX_TWO_PI 6.283185307179586476925286766559
/* the shadow of a saddle is widened by this angle on each side */
#define EX_SHADOW_MARGIN 1e-7
/* buckets in the queue's window (a power of 2), and their width in mean
 * edge lengths */
#define EX_NB 4096
#define EX_BUCKET_WIDTH 0.25
/* a vertex this near (in edge lengths) to the pseudo-source of the path
 * that reached it starts windows all around (ex_set_in) */
#define EX_NEAR 1e-3
/* a vertex this close (in edge lengths) outside a window's rays is
 * reached over the window's end (ex_propagate) */
#define EX_GRAZE 1e-6
/* a patch distance outside its bounds by more than this times (the
 * distance + a mean edge) is a defect (mfmm_exact_patch_check) */
#define EX_PATCH_TOL 1e-9
/* an edge shorter than this times the longest edge of a face at its ends
 * is a wall (ex_wall_short_edges) */
#define EX_SHORT_EDGE 1e-6
/* zero-area faces one window passes through in a row by recursion (ex_pass);
 * past them it is queued and goes on from the queue (ex_pass_later) */
#define EX_MAX_PASS 8
/* a vertex whose angle sum exceeds 2 pi by this much is a saddle */
#define EX_SADDLE_TOL 1e-12
/* vertices in a tile of the lazily built tables, and a tile's levels: its
 * face records, and those with the fans and flags of every vertex and face
 * its records touch (ready to be read) */
#define EX_TILE 32
#define EX_TILE_FACES 1
#define EX_TILE_READY 2
/* tiles in a group, whose box and count of tiles not ready let a run pass
 * over the groups it cannot reach or that are built (a scan of every tile
 * cost a sparse row of a million-vertex mesh 7 % of its time) */
#define EX_GROUP 64

/* An entry of the queue: a window, or a vertex to start as a pseudo-source. */
typedef struct ex_entry {
    double key;      /* the least distance of the window; a vertex's distance */
    double b0, b1;   /* interval on the edge, from its first vertex */
    double px, py;   /* pseudo-source in the edge's frame, py <= 0 */
    double sigma;    /* distance at the pseudo-source */
    int32_t he;      /* >= 0: 3 f + k, the edge opposite corner k of face f, the
                        window about to cross f; < 0: vertex -he-1 */
    int32_t next;    /* the next entry in its bucket or in the free list */
} ex_entry;

/* A window queued into a face through a non-manifold edge (ex_fan_out),
 * kept to trim the later ones there (ex_dominate): its function and the
 * interval it crosses with, in that half-edge's frame. */
typedef struct ex_rec {
    double b0, b1, px, py, sigma;
    int32_t slot, next;
} ex_rec;

/* The read-only tables of a mesh (exact.h): built once, shared by the
 * workspaces of any number of threads. Faces are laid out in the order of
 * their least (internal, Morton-ordered: mesh/order.c) vertex, so that a
 * patch's faces lie together in memory: in the files' order the faces
 * around a vertex were 12,000 records apart on the bunny. */
struct mfmm_exact_tables {
    const mfmm_mesh *mesh;
    int32_t nv, nf;
    const int32_t *vf_offset;
    const int32_t *vf_corner; /* the mesh's vertex -> face CSR, MFMM_WEDGE entries (ex_corner) */
    int32_t *face_in;   /* (nf,) the mesh's face id -> its record (set with the record) */
    /* per face, its three half-edges 3f+k (the edge opposite corner k, from
     * corner k+1 to k+2) in one record, so that crossing a face reads one or
     * two cache lines: see ex_face */
    ex_face *fr;
    void *fr_block;    /* fr's allocation (fr is aligned to 64 bytes in it) */
    uint8_t *pseudo;   /* (nv,) vertices that may bend a path */
    /* the fan of corners around a vertex, by angle: corner 3f+k (at v = f[k])
     * spans the angles between fan_a0 (the direction to f[k+1]) and
     * fan_a0 + sgn * angle (to f[k+2], ex_face); fan_total (nv) is the angle sum,
     * NaN where the fan is not one closed disk (walls, zero-area faces,
     * non-manifold vertices): those start windows in every direction */
    double *fan_a0, *fan_total;
    /* (nv,) a vertex's least height over the opposite edges of its faces
     * (+inf with none): the patch's free ring (mfmm_exact_patch) */
    double *height;
    /* the half-edges of non-manifold edges (flip 2 in their record), sorted,
     * each with the next half-edge of the same edge (a cycle through the
     * edge's faces; ex_fan_out): n_nm of them */
    int32_t *nm_he, *nm_next;
    int32_t n_nm;
    double inv_w;      /* 1 / bucket width */
    /* Built lazily, a tile at a time, under the mesh's lock (tables.c,
     * mfmm_exact_tables_ensure): tile T is the vertices EX_TILE T to
     * EX_TILE (T + 1) - 1 and the records of the faces whose least vertex
     * is one of them (records tile_rec[T] to tile_rec[T + 1] - 1) */
    int32_t n_tiles, n_ready;
    int32_t *tile_rec;   /* (n_tiles + 1,) */
    int32_t *rec_face;   /* (nf,) a record's mesh face (face_in's inverse); NULL: the
                            identity (no pieces of faces: faces already in this order) */
    uint8_t *tile_state; /* (n_tiles,) EX_TILE_FACES | EX_TILE_READY */
    uint8_t *vertex_done; /* (nv,) 1 once a vertex's fan and flags are built */
    double *tile_box;    /* (n_tiles, 6) the bounding box of the tile's vertices */
    double *group_box;   /* (n_groups, 6) the box of a group's tiles (EX_GROUP) */
    int32_t *group_left; /* (n_groups,) its tiles not ready */
    int32_t n_groups;
    double pad;          /* how far beyond a tile's vertices its records and their neighbours reach */
    double short_len;    /* no edge this long or longer is short (ex_wall_short_edge) */
    size_t bytes;        /* built so far */
    size_t full_bytes;   /* once every tile is built */
};

/* A workspace: shared tables (the mesh's) and one solve's state. */
struct mfmm_exact_solver {
    const mfmm_exact_tables *t;
    const mfmm_mesh *mesh;
    int32_t nv, nf;
    /* the tables' arrays (see mfmm_exact_tables) */
    const int32_t *vf_offset, *vf_corner, *face_in;
    const ex_face *fr;
    const uint8_t *pseudo;
    const double *fan_a0, *fan_total, *height;
    const int32_t *nm_he, *nm_next;
    int32_t n_nm;
    double inv_w;
    /* d is set to +inf a tile at a time, where runs reach (the tables'
     * tiles: ex_run), so that a workspace on a large mesh writes only its
     * patch's share; in_angle and emitted are set when a vertex is first
     * touched */
    double *in_angle;  /* (nv,) direction (fan angle) back along the path that gave d */
    double *d;         /* (nv,) best distance so far, +inf untouched */
    double *emitted;   /* (nv,) the distance a pseudo-source was started with */
    uint8_t *tile_init;       /* (n_tiles,) 1 once the tile's d is set */
    int32_t *group_init_left; /* (n_groups,) tiles of the group whose d is not set */
    int32_t n_init;           /* tiles whose d is set */
    int32_t *touched;  /* vertices with finite d, in order of first touch */
    int32_t n_touched;
    double *patch_d;   /* (nv,) distances of mfmm_exact_patch */
    uint8_t *in_patch; /* (nv,) whether in the last patch (mfmm_exact_in_patch) */
    /* the queue */
    ex_entry *heap;    /* the entries of the bucket queue, linked by next */
    int32_t heap_cap, heap_n, heap_used, qfree;
    /* the buckets in the window: (3 EX_NB,) heads and tails of their FIFO
     * lists of windows, then heads of their lists of vertex events */
    int32_t *bhead;
    int32_t over;      /* entries beyond the window, unsorted */
    int64_t cur, redist; /* current bucket; where the window was last refilled */
    int32_t n_in;      /* entries in the window's buckets */
    size_t fixed_bytes, memory_limit, peak_bytes;
    double max_d;
    int failed; /* MFMM_ERR_MEMORY_LIMIT or MFMM_ERR_OUT_OF_MEMORY once a growth fails,
                   MFMM_ERR_CANCELLED once interrupt asked to stop */
    int (*interrupt)(void *user); /* mfmm_exact_options' (NULL for a patch) */
    void *interrupt_user;
    int pass_depth; /* zero-area faces a window is passing through (ex_pass) */
    int32_t pass_face[EX_MAX_PASS]; /* those faces' records, outermost first */
    /* with non-manifold edges crossed, windows past a budget (over_budget):
     * the run is redone with those edges as walls (walls; ex_run); past it
     * otherwise, the run stops (stalled) and edge paths finish it */
    int over_budget, walls, stalled;
    double budget; /* windows a reached vertex may cost (ex_over_budget) */
    int64_t n_windows, n_propagated, n_pseudo, peak_windows;
    /* the windows fanned out at non-manifold edges, by nm_he slot: (n_nm,)
     * heads of lists in rec, -1: none */
    int32_t *nm_head;
    ex_rec *rec;
    int32_t rec_n, rec_cap;
    /* the windows queued where a pass was cut at EX_MAX_PASS (ex_pass_later),
     * by slot -2 - j: pass_slot (2 pass_cap,) holds slot j's zero-area
     * half-edge and the head of its list in rec, pass_hash (2 pass_cap,)
     * the j of a half-edge by hash (-1: none); pass_n slots in use */
    int32_t *pass_slot, *pass_hash;
    int32_t pass_n, pass_cap;
};

static inline double vdist(const double *p, const double *q)
{
    double a = p[0] - q[0], b = p[1] - q[1], c = p[2] - q[2];
    return sqrt(a * a + b * b + c * c);
}

/* Calls visit(ctx, T) for every tile T within `reach` of any of the n
 * points (n, 3) (every tile when points is NULL or reach is not finite)
 * whose state lacks `bit`, then sets the bit; group_left (n_groups,) counts
 * each group's tiles without it, so that groups done are skipped. Returns
 * the tiles visited. */
int32_t ex_tiles_visit(const mfmm_exact_tables *t, uint8_t *state, uint8_t bit,
                       int32_t *group_left, const double *points, int32_t n, double reach,
                       void (*visit)(void *ctx, int32_t T), void *ctx);

static inline int ex_corner_of(const int32_t *fv, int32_t v)
{
    return fv[0] == v ? 0 : fv[1] == v ? 1 : fv[2] == v ? 2 : -1;
}

#endif
