/*
 * meshfmm: geodesic distances and shortest paths on triangle meshes by the
 * Fast Marching Method of Kimmel & Sethian, "Computing geodesic paths on
 * manifolds", PNAS 95 (1998) 8431-8435.
 *
 * This is the one public header. C99, C ABI. Conventions:
 *   - vertices: float64, (nv, 3) row-major; faces: int32, (nf, 3) row-major,
 *     0-based.
 *   - cost F: |grad T| = F, so a path costs F times its length (a slowness).
 *     Per vertex or per face; finite and > 0. Default 1: geodesic distance.
 *   - unreached vertices (other components, beyond max_distance, not settled
 *     before an early stop) are +inf, never NaN.
 *   - every function returns an mfmm_status; mfmm_status_string() names it.
 *     Functions that validate input also fill an optional mfmm_error with
 *     the offending index and a sentence. The library never prints, aborts
 *     or exits, and keeps no global mutable state.
 *   - objects: an mfmm_mesh is immutable after creation and may be shared by
 *     threads; an mfmm_solver is a workspace for one thread at a time.
 */
#ifndef MESHFMM_H
#define MESHFMM_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(_WIN32) && defined(MESHFMM_BUILDING_SHARED)
#define MFMM_API __declspec(dllexport)
#elif defined(__GNUC__)
#define MFMM_API __attribute__((visibility("default")))
#else
#define MFMM_API
#endif

#define MFMM_VERSION_MAJOR 0
#define MFMM_VERSION_MINOR 1
#define MFMM_VERSION_PATCH 0

/* ABI policy. The shared library's soname is libmeshfmm.so.MAJOR (the CMake
 * SOVERSION is the major version). While MAJOR is 0, a MINOR release may break
 * the ABI and the API (the CMake package then accepts only the same MINOR:
 * find_package(meshfmm 0.1) takes 0.1.x); PATCH releases never do. From 1.0
 * on, only a MAJOR release breaks the ABI (and changes the soname).
 * Every option struct starts with `size_t struct_size`, which its _init
 * function sets to the sizeof the caller was compiled with: a struct that
 * later grows gains fields at its end, and the library reads a caller's
 * smaller, older struct by its size. Always fill an option struct with its
 * _init function before setting fields. A struct_size the library does not
 * know (not from an _init, or from a newer header than the library) is
 * refused with MFMM_ERR_BAD_ARGUMENT and a message naming both sizes. */

/* ---------------------------------------------------------------- status */

typedef enum mfmm_status {
    MFMM_OK = 0,
    MFMM_ERR_NULL_POINTER,        /* a required pointer argument is NULL */
    MFMM_ERR_BAD_COUNT,           /* a count is negative, zero where it may not be, or too large */
    MFMM_ERR_NONFINITE_VERTEX,    /* a vertex coordinate is NaN or infinite */
    MFMM_ERR_INDEX_OUT_OF_RANGE,  /* a face index is < 0 or >= nv */
    MFMM_ERR_REPEATED_VERTEX,     /* a face names one vertex twice */
    MFMM_ERR_OUT_OF_MEMORY,       /* an allocation failed */
    MFMM_ERR_BAD_COST,            /* a cost is not finite or not > 0 */
    MFMM_ERR_BAD_SOURCE,          /* a source vertex or face id is out of range */
    MFMM_ERR_DEGENERATE_SOURCE,   /* a source lies on a zero-area face */
    MFMM_ERR_BAD_BARYCENTRIC,     /* barycentric coordinates not finite, < 0, or not summing to 1 */
    MFMM_ERR_BAD_ARGUMENT,        /* another argument is invalid (the mfmm_error says which) */
    MFMM_ERR_WRONG_MESH,          /* the solver was created for another mesh */
    MFMM_ERR_UNREACHED,           /* a path target has an infinite distance */
    MFMM_ERR_PATH_STALLED,        /* path tracing stopped descending, or ran out of steps */
    MFMM_ERR_NO_OPENCL,           /* no OpenCL platform or device is available */
    MFMM_ERR_OPENCL_BUILD,        /* the OpenCL program failed to build */
    MFMM_ERR_OPENCL_RUNTIME,      /* an OpenCL call failed (out of resources, ...) */
    MFMM_ERR_CANCELLED,           /* a callback asked to stop */
    MFMM_ERR_IO,                  /* a file could not be opened, read or written */
    MFMM_ERR_PARSE,               /* a mesh file is malformed */
    MFMM_ERR_MEMORY_LIMIT,        /* a computation needed more memory than its memory_limit */
    MFMM_STATUS_COUNT
} mfmm_status;

/* A sentence naming a status, e.g. "a face names one vertex twice". Never NULL. */
MFMM_API const char *mfmm_status_string(mfmm_status status);

/* Details of a failure: filled by functions that take an `mfmm_error *err`
 * (which may be NULL). `index` is the offending vertex, face, source or file
 * line (-1 when none applies); `message` a sentence that names it. On success
 * status is MFMM_OK and message is empty. */
typedef struct mfmm_error {
    mfmm_status status;
    int64_t index;
    char message[256];
} mfmm_error;

/* "MAJOR.MINOR.PATCH" of the library linked at run time. */
MFMM_API const char *mfmm_version(void);

/* ------------------------------------------------------------------ mesh */

typedef struct mfmm_mesh mfmm_mesh;

typedef struct mfmm_mesh_options {
    size_t struct_size;   /* sizeof(mfmm_mesh_options), set by the _init function */
    /* Most faces one unfolding walk may cross to find the virtual edge of an
     * obtuse corner (paper section 4.2); a walk that needs more fails and the
     * corner keeps its plain stencil. Default 64; must be >= 1. */
    int32_t max_unfold_steps;
    /* 1 (default): the march at F = 1 with unfolding reads per-vertex update
     * records ("spokes"), built on the first such solve and kept with the
     * mesh: about 380 bytes per vertex (mfmm_mesh_memory lists them), for a
     * march 0.63-0.79x as long. 0: never build them; the march walks the
     * faces instead, with the same results bit for bit (memory first: a
     * 1M-vertex mesh holds 0.39 GB less). Other values are refused. */
    int32_t spokes;
} mfmm_mesh_options;

/* Fills `options` with the defaults. */
MFMM_API void mfmm_mesh_options_init(mfmm_mesh_options *options);

/* Validates a triangle mesh and precomputes all a solve reuses: vertex
 * adjacency, edge lengths, corner angles, and a virtual edge for every obtuse
 * corner, found by unfolding (section 4.2).
 *   vertices: (nv, 3) float64, row-major; copied.
 *   faces:    (nf, 3) int32, row-major, 0-based; copied.
 *   options:  NULL for defaults.
 *   out:      receives the mesh; NULL on failure.
 * Refused: nv outside 1 .. 715827882, nf outside 1 .. 134217727
 * (MFMM_ERR_BAD_COUNT), NaN/inf coordinates (MFMM_ERR_NONFINITE_VERTEX),
 * coordinates beyond +-1e100 or a bounding box whose diagonal is below 1e-100
 * (MFMM_ERR_BAD_ARGUMENT: rescale), indices out of
 * range, a face that repeats a vertex. Results do not depend on the mesh's
 * scale (a mesh scaled by s gives distances scaled by s). Accepted: boundaries, several components,
 * unreferenced vertices, non-manifold edges, zero-area and needle faces. A
 * T-junction closed by a zero-area needle A-M-B (M inside edge AB of face
 * A-B-C, or of every face on a non-manifold AB) is closed inside: the
 * faces on AB are split at M and the needle dropped, so
 * distances and paths cross it as the surface does; face ids, per-face
 * costs and points stay the caller's (README, "Imperfect meshes").
 * Inside, vertices are renumbered along a space-filling curve (for memory
 * locality); every function takes and returns the caller's vertex ids and
 * per-vertex arrays in the caller's order, and faces keep their ids, so
 * results do not depend on the order the vertices are given in (but for
 * vertices that share a position). */
MFMM_API mfmm_status mfmm_mesh_create(const double *vertices, int32_t nv,
                                      const int32_t *faces, int32_t nf,
                                      const mfmm_mesh_options *options,
                                      mfmm_mesh **out, mfmm_error *err);

/* Frees a mesh; NULL is a no-op. Solvers made for it must be gone first. */
MFMM_API void mfmm_mesh_destroy(mfmm_mesh *mesh);

/* Counts a mesh's diagnostics, computed once at creation. */
typedef struct mfmm_mesh_info {
    int32_t n_vertices;              /* nv as given */
    int32_t n_faces;                 /* nf as given */
    int32_t n_edges;                 /* distinct undirected edges (this and the counts
                                        below but n_degenerate_faces and
                                        n_duplicate_faces: of the surface built, its
                                        T-junctions closed, mfmm_mesh_create) */
    int32_t n_boundary_edges;        /* edges with one face (copies apart) */
    int32_t n_nonmanifold_edges;     /* edges with three or more faces (copies apart) */
    int32_t n_components;            /* edge-connected components of referenced vertices */
    int32_t n_unreferenced_vertices; /* vertices no face names (always +inf) */
    int32_t n_degenerate_faces;      /* faces of (numerically) zero area, as given
                                        (needles closing a T-junction included) */
    int32_t n_obtuse_corners;        /* corners with an angle > 90 degrees */
    int32_t n_virtual_edges;         /* obtuse corners split by a virtual edge */
    int32_t n_unfold_failures;       /* obtuse corners whose walk failed (boundary,
                                        non-manifold edge, or step limit) */
    double min_edge_length;
    double max_edge_length;
    double mean_edge_length;
    double bbox_diagonal;            /* length of the bounding-box diagonal */
    int32_t n_duplicate_faces;       /* faces that repeat another face's vertices (in
                                        any order): copies, not counted in the edges'
                                        faces (the edges are what the other faces make
                                        them); the march updates through a copy as
                                        through its original */
} mfmm_mesh_info;

MFMM_API mfmm_status mfmm_mesh_get_info(const mfmm_mesh *mesh, mfmm_mesh_info *info);

/* The mesh's sizes (convenience; the same numbers as mfmm_mesh_info). */
MFMM_API int32_t mfmm_mesh_vertex_count(const mfmm_mesh *mesh);
MFMM_API int32_t mfmm_mesh_face_count(const mfmm_mesh *mesh);

/* The memory a mesh holds, array by array (workspaces of solvers and
 * matrix calls apart).
 *   names: (max,) receives each array's name, a static string of the
 *          library (never freed);
 *   bytes: (max,) receives its size in bytes;
 *   max:   room in names and bytes; 0 (with NULL arrays) to ask for the count.
 * Returns the number of arrays, all of them even past max; -1 when mesh is
 * NULL, max < 0, or names or bytes is NULL with max > 0. Two entries are
 * built on first use and kept with the mesh, and count 0 until then:
 * "spokes (once built)" (the march's update records, mfmm_mesh_options.spokes)
 * and "exact tables (once built)" (the exact start and mfmm_solve_exact).
 * Safe to call while other threads solve on the mesh. */
MFMM_API int mfmm_mesh_memory(const mfmm_mesh *mesh, const char **names, size_t *bytes,
                              int max);

/* --------------------------------------------------------------- sources */

/* A source: a vertex (face == -1), or a point inside a face given by
 * barycentric coordinates (w0, w1, w2) of the face's corners (>= 0, summing
 * to 1 within 1e-9). `value` is T at the source (usually 0): the result is
 * T(x) = min over sources of (value + cost-weighted distance). By default
 * the march starts from the exact distances of the vertices within
 * exact_start_radius mean edge lengths of each source (see
 * mfmm_solve_options); with that option 0, or where the cost is not uniform
 * near the source, a vertex source starts at its vertex and a point source
 * from straight-segment distances to the vertices near it (through the faces
 * within about two mean edge lengths). Either way a point on an edge or at a
 * corner is a point of every face holding it, so T does not depend on which
 * face names it, and moves continuously with the point. */
typedef struct mfmm_source {
    int32_t vertex;     /* vertex id when face == -1; ignored otherwise */
    int32_t face;       /* face id, or -1 for a vertex source */
    double bary[3];     /* barycentric coordinates in the face; ignored for a vertex */
    double value;       /* initial value of T at the source */
} mfmm_source;

/* Where a cost array lives. */
typedef enum mfmm_cost_location {
    MFMM_COST_NONE = 0,       /* F = 1 everywhere: geodesic distance */
    MFMM_COST_PER_VERTEX = 1, /* cost has nv entries; F is linear along each edge
                                 and local path (trapezoid means, march.h) */
    MFMM_COST_PER_FACE = 2    /* cost has nf entries; paths refract at region borders */
} mfmm_cost_location;

/* ---------------------------------------------------------------- solver */

typedef struct mfmm_solver mfmm_solver;

/* A reusable workspace (heap, labels, a touched list) for one mesh and one
 * thread: about 40 bytes per vertex, plus, made by the first solve that uses
 * the exact start, an exact solver's workspace (about 45 bytes per vertex;
 * the mesh's exact tables, about 156 bytes per face, are built once per mesh
 * and shared: see mfmm_exact_solver_create). The first solve without a cost
 * and with unfolding also builds the mesh's spokes (about 380 bytes per
 * vertex: each neighbour's update data, ready in the order the march reads
 * it, which makes that march 0.63-0.79x as long), likewise built once
 * per mesh under a lock and shared by every solver, thread and job on it
 * (if there is no memory for them, the march reads the faces instead and
 * gives the same distances). After that first solve, solving allocates nothing beyond a copy of
 * its arguments in the mesh's internal vertex order (sources, targets, a
 * per-vertex cost), kept and reused while large enough (the exact start's
 * queue grows only for a larger patch than any before). Between solves the
 * workspace is kept clean by resetting only the vertices the
 * last march reached, so a local solve (max_distance, targets) costs in
 * proportion to what it reaches, apart from filling `distances`. */
MFMM_API mfmm_status mfmm_solver_create(const mfmm_mesh *mesh, mfmm_solver **out);

/* Frees a solver; NULL is a no-op. */
MFMM_API void mfmm_solver_destroy(mfmm_solver *solver);

typedef struct mfmm_solve_options {
    size_t struct_size;              /* sizeof(mfmm_solve_options), set by the _init function */
    const double *cost;              /* NULL: F = 1. Finite and > 0, and small enough that
                                        the largest times the edges' total length stays
                                        below DBL_MAX / 16 (else distances could overflow
                                        to +inf, "not reached"): MFMM_ERR_BAD_COST */
    mfmm_cost_location cost_location;/* ignored when cost is NULL */
    double max_distance;             /* stop past it; vertices beyond are +inf. Default +inf;
                                        NaN or < 0: MFMM_ERR_BAD_ARGUMENT */
    const int32_t *targets;          /* stop once all these vertices are settled; NULL: none */
    int32_t n_targets;
    int32_t unfolding;               /* 1 (default): obtuse corners update through their
                                        virtual edges; 0: plain stencils (for comparison) */
    /* Appended fields. */
    /* The exact start: the march starts from the exact polyhedral
     * distances (mfmm_solve_exact's) of the vertices within this many mean
     * edge lengths of each source (at least the corners of the faces holding
     * it), T = value + F * distance, instead of from the source's vertex (a
     * vertex source) or straight segments (a point source). A first-order
     * march makes most of its error at the source's point singularity and
     * carries it on: this start lowers the mean error by about half at the
     * default (bench/RESULTS.md), for a few hundred microseconds per source.
     * Exact distances hold for F = 1, so with a cost it applies to a source
     * only where the cost is one F over the patch (per vertex: every patch
     * vertex and its neighbours; per face: every face around a patch vertex;
     * then T = value + F * distance); elsewhere that source takes the
     * straight start. Default MFMM_EXACT_START_AUTO (a radius that grows
     * with the mesh, below); 0: the paper's plain start, as before this
     * option existed. MFMM_EXACT_START_AUTO, or finite and >= 0, else
     * MFMM_ERR_BAD_ARGUMENT. */
    double exact_start_radius;
} mfmm_solve_options;

/* exact_start_radius's base, in mean edge lengths (chosen by measurement:
 * bench/RESULTS.md, "Exact start"). The patch also holds the vertices just
 * beyond the radius whose exact distances the propagation has found anyway
 * (within a face's height of it). */
#define MFMM_EXACT_START_RADIUS 7.0

/* exact_start_radius's default: MFMM_EXACT_START_RADIUS mean edge lengths,
 * times sqrt(nv / MFMM_EXACT_START_AUTO_VERTICES) on larger meshes for a
 * march without max_distance (17.5 at 250,000 vertices, 35 at a million).
 * A radius in mean edges covers less of a finer mesh, and the error the
 * source's singularity creates then dominates again (with 7, the mean error
 * over the plain start's is 0.33-0.59 on the meshes of 3-35k vertices, 0.62
 * on igea's 134k, 0.63 on a 251k sine surface); this keeps the patch the same share of the
 * surface, so about the same share of a full march's time. A march with
 * max_distance (a local row) keeps the base radius, so that its cost
 * depends on its reach in mean edges and not on the mesh's size. */
#define MFMM_EXACT_START_AUTO (-1.0)
#define MFMM_EXACT_START_AUTO_VERTICES 40000

/* Fills `options` with the defaults: no cost, no limit, no targets, unfolding on,
 * the exact start with its default radius (MFMM_EXACT_START_AUTO). */
MFMM_API void mfmm_solve_options_init(mfmm_solve_options *options);

/* Marches from the sources and writes T for every vertex.
 *   solver:    from mfmm_solver_create for the mesh being solved.
 *   sources:   n_sources >= 1 sources.
 *   options:   NULL for defaults.
 *   distances: (nv,) float64 out. Settled vertices hold T; all others +inf
 *              (with targets, only settled vertices are final). */
MFMM_API mfmm_status mfmm_solve(mfmm_solver *solver, const mfmm_source *sources,
                                int32_t n_sources, const mfmm_solve_options *options,
                                double *distances, mfmm_error *err);

/* What the last mfmm_solve on a solver did. */
typedef struct mfmm_solve_info {
    size_t struct_size;      /* set by the caller: sizeof(mfmm_solve_info); the library
                                writes no more than this many bytes */
    int64_t start_fallbacks; /* vertices of the exact start whose exact distance failed
                                a bound every distance meets (at least the straight-line
                                distance from the source, at most the shortest edge path
                                to it) and which the march computed instead; 0 unless the
                                exact solver erred on a degenerate mesh */
} mfmm_solve_info;

/* Fills info about the solver's last mfmm_solve (zeros before the first).
 * MFMM_ERR_NULL_POINTER; MFMM_ERR_BAD_ARGUMENT when info->struct_size is
 * smaller than a size_t. Not safe while the solver solves in another thread. */
MFMM_API mfmm_status mfmm_solver_get_info(const mfmm_solver *solver, mfmm_solve_info *info);

/* ----------------------------------------------------------------- exact */

/* Exact polyhedral geodesic distance (F = 1): the length of the shortest
 * path on the surface of the piecewise-flat mesh, by window propagation
 * (Chen & Han with the pruning of Xin & Wang, "ICH"; saddles start windows
 * only in their shadow; see src/exact/exact.c). Equal to Kirsanov's MMP
 * (igl.exact_geodesic, gdist) to rounding (about 1e-14 relative), several
 * times faster than gdist. Boundaries are walls a path may run along but not
 * cross; a non-manifold edge joins every face on it to every other (a path
 * crosses from any into any; on degenerate fans, past a budget of windows,
 * they are walls again: info->nonmanifold_walls); paths may pass through
 * saddle, boundary and non-manifold vertices; a zero-area face is passed
 * through along its line (a T-junction closed by a needle joins both sides);
 * copies of a face are no part of the surface. Not for a cost: see
 * mfmm_solve. */
typedef struct mfmm_exact_solver mfmm_exact_solver;

/* A workspace for one mesh and one thread: per-vertex state (about 45
 * bytes per vertex) and a queue of windows (56 bytes each) that grows as
 * needed and is kept for the next solve (mfmm_exact_info.peak_bytes tells
 * the total). The mesh's edge geometry (about 156 bytes per face) is built by
 * the first exact solver or exact start on the mesh, under a lock, kept by the
 * mesh until mfmm_mesh_destroy and shared by every solver and thread on it,
 * so a later job does not pay for it again. Several exact solvers may share
 * one mesh, one per thread. */
MFMM_API mfmm_status mfmm_exact_solver_create(const mfmm_mesh *mesh, mfmm_exact_solver **out);

/* Frees an exact solver; NULL is a no-op. */
MFMM_API void mfmm_exact_solver_destroy(mfmm_exact_solver *solver);

typedef struct mfmm_exact_options {
    size_t struct_size;   /* sizeof(mfmm_exact_options), set by the _init function */
    /* Must be NULL: exact distances are for F = 1 (a cost is refused with
     * MFMM_ERR_BAD_ARGUMENT; use mfmm_solve for weighted distances). */
    const double *cost;
    mfmm_cost_location cost_location;
    double max_distance;  /* vertices farther are +inf and the propagation stops
                             there (cost grows with the area reached). Default +inf */
    size_t memory_limit;  /* bytes the solver may hold in all during this solve,
                             its per-mesh tables included (a larger queue kept
                             from an earlier solve is released first); needing
                             more returns MFMM_ERR_MEMORY_LIMIT. 0 (default): no
                             limit */
    int (*interrupt)(void *user); /* NULL (default), or called every few milliseconds
                             of propagation: non-zero stops the solve with
                             MFMM_ERR_CANCELLED (Ctrl-C in a program that solves
                             large meshes) */
    void *user;           /* passed to interrupt */
} mfmm_exact_options;

/* Fills `options` with the defaults: no cost, no limit on distance or memory,
 * no interrupt. */
MFMM_API void mfmm_exact_options_init(mfmm_exact_options *options);

/* What one exact solve did. */
typedef struct mfmm_exact_info {
    int64_t n_windows;        /* windows created */
    int64_t n_propagated;     /* windows taken from the queue and carried across their face */
    int64_t n_pseudo_sources; /* vertex sources and saddle / boundary vertices that
                                 started windows */
    int64_t peak_windows;     /* most windows queued at once */
    size_t peak_bytes;        /* most bytes the solver held (tables + queue) */
    int32_t nonmanifold_walls; /* 1: the windows crossing non-manifold edges passed
                                  their budget (degenerate folded fans) and the solve
                                  was redone with those edges as walls, where values
                                  are then upper bounds; 0: they were crossed */
} mfmm_exact_info;

/* Exact geodesic distances from the sources to every vertex.
 *   solver:    from mfmm_exact_solver_create for the mesh.
 *   sources:   n_sources >= 1 sources, as for mfmm_solve: a vertex, or a point
 *              in a face by barycentric coordinates (on an edge or at a corner
 *              when some are 0), each with an initial value; the result is
 *              min over sources of value + geodesic distance.
 *   options:   NULL for defaults; cost must be NULL.
 *   distances: (nv,) float64 out. Vertices in no component a source reaches,
 *              unreferenced vertices and vertices beyond max_distance are
 *              +inf (never NaN).
 *   info:      (out) may be NULL.
 * Errors: MFMM_ERR_NULL_POINTER, MFMM_ERR_BAD_COUNT (n_sources < 1),
 * MFMM_ERR_BAD_SOURCE / MFMM_ERR_BAD_BARYCENTRIC / MFMM_ERR_DEGENERATE_SOURCE
 * (err->index is the source), MFMM_ERR_BAD_ARGUMENT (a cost given, or
 * max_distance NaN or < 0), MFMM_ERR_MEMORY_LIMIT, MFMM_ERR_OUT_OF_MEMORY;
 * on error distances are all +inf. */
MFMM_API mfmm_status mfmm_solve_exact(mfmm_exact_solver *solver, const mfmm_source *sources,
                                      int32_t n_sources, const mfmm_exact_options *options,
                                      double *distances, mfmm_exact_info *info,
                                      mfmm_error *err);

/* ----------------------------------------------------------------- paths */

/* A point on the surface: a face and barycentric coordinates in it, with its
 * position. */
typedef struct mfmm_surface_point {
    int32_t face;
    double bary[3];
    double xyz[3];
} mfmm_surface_point;

typedef struct mfmm_path_options {
    size_t struct_size;   /* sizeof(mfmm_path_options), set by the _init function */
    int32_t max_points;   /* most points a path may have; default 100000 */
    /* Sources the distances came from (as given to mfmm_solve): the path ends
     * exactly at the one the target's distance came from (a vertex source at
     * its vertex, a face source at its point, straight from the faces near
     * it). NULL: it ends at a vertex where T is 0 and no neighbour (over an
     * edge or a virtual edge) is lower; where T stops decreasing above 0 (a
     * face source, a source value > 0) the call fails rather than end
     * there. */
    const mfmm_source *sources;
    int32_t n_sources;
    const double *cost;               /* the cost the distances were solved with, or NULL */
    mfmm_cost_location cost_location;
    double *weighted_length;          /* out, may be NULL: the cost-weighted length
                                         (sum of F times segment length; with no cost,
                                         the Euclidean length) */
    /* 1 (default): straighten the traced path inside the strip of faces it
     * crossed (unfolded; the shortest polyline through the shared edges, by the
     * funnel algorithm), which removes the drift that T's first-order error
     * gives the gradient. Points where the path passes a vertex between faces
     * without a shared edge stay fixed. With a cost array the path is not
     * straightened (a weighted path refracts where the cost changes, which the
     * traced path does and straight chords do not). Never longer than the
     * traced path. 0: the traced path of section 5 as it is. */
    int straighten;
} mfmm_path_options;

/* Fills `options` with the defaults: 100000 points, no sources, no cost,
 * straighten = 1. */
MFMM_API void mfmm_path_options_init(mfmm_path_options *options);

/* Backtracks from `target` along -grad T to the source (paper section 5):
 * Heun's method on T interpolated by a quadratic over each face and its three
 * neighbours, the face's linear gradient where that fit is ill-posed, and
 * Euler steps at sonic points.
 *   distances: (nv,) from mfmm_solve.
 *   target:    a vertex (face == -1) or a point in a face (value ignored);
 *              not in a zero-area face (MFMM_ERR_DEGENERATE_SOURCE, as for a
 *              source: give the point in a face beside it).
 *   options:   NULL for defaults.
 *   points:    caller buffer of `capacity` points (NULL when capacity is 0);
 *              receives the polyline from the target to the source: the
 *              target, each edge crossing and vertex passed, and the end.
 *              points[i].face (i > 0) is the face the segment from point i-1
 *              ran through; the target's is its own face.
 *   n_points:  receives the count (the status is MFMM_ERR_BAD_COUNT when
 *              capacity is too small, with *n_points the count needed).
 *   length:    receives the polyline's Euclidean length (may be NULL).
 * Where T has no descent over faces and edges at a vertex (its value came
 * through a virtual edge, section 4.2, or straight from a point source), the
 * path follows that straight segment through the faces it crosses.
 * MFMM_ERR_BAD_COST: options->cost has an entry not finite or not > 0
 * (every entry is checked, as mfmm_solve does; err->index names it).
 * MFMM_ERR_UNREACHED: T(target) is +inf. MFMM_ERR_PATH_STALLED: T stopped
 * decreasing before a source (without sources: above 0), or the path needed
 * more than max_points points; never a path that ends elsewhere. */
MFMM_API mfmm_status mfmm_trace_path(const mfmm_mesh *mesh, const double *distances,
                                     const mfmm_source *target,
                                     const mfmm_path_options *options,
                                     mfmm_surface_point *points, int32_t capacity,
                                     int32_t *n_points, double *length, mfmm_error *err);

/* --------------------------------------------------------- matrix (rows) */

typedef enum mfmm_backend {
    MFMM_BACKEND_AUTO = 0,   /* OpenCL on a usable device that is not a CPU (or that the
                                caller named), else threads */
    MFMM_BACKEND_SERIAL = 1, /* one solver, this thread */
    MFMM_BACKEND_THREADS = 2,/* one serial solver per thread */
    MFMM_BACKEND_OPENCL = 3  /* many sources at once on an OpenCL device */
} mfmm_backend;

/* Name of a backend: "auto", "serial", "threads", "opencl". */
MFMM_API const char *mfmm_backend_name(mfmm_backend backend);

/* An OpenCL device with meshfmm's program built for it (building takes
 * 0.03 s with warm caches, about 1 s cold). Make one and pass it in
 * mfmm_matrix_options.opencl to build once for many calls. Thread-safe: each
 * call makes its own queue and kernel.
 *
 * OpenCL is loaded at run time: the library does not link libOpenCL, and
 * opens the ICD loader (libOpenCL.so.1) only when a context is made, so
 * meshfmm loads and solves on a machine without any OpenCL, and only the
 * OpenCL backend needs it. The context holds the loader's function table (no
 * global state). */
typedef struct mfmm_opencl_context mfmm_opencl_context;

/* How to make an OpenCL context. Every field NULL means the default, which
 * an environment variable may set; a field set here wins over the environment.
 *   device:    an index over all platforms' devices in order ("0", "1", ...),
 *              or a case-insensitive substring of a device name ("pthread",
 *              "NVIDIA"). NULL: $MESHFMM_OPENCL_DEVICE, else the first CPU
 *              device, else the first device.
 *   cache_dir: the folder for the built program binary. NULL:
 *              $MESHFMM_CACHE_DIR, else $XDG_CACHE_HOME/meshfmm, else
 *              $HOME/.cache/meshfmm. "" : no disk cache (always build).
 *              Entries are files fmm_rows-<key>.bin, <key> a hash of the kernel
 *              source, build options, library version, platform, device and
 *              driver versions, so a binary from another build or driver is
 *              never loaded; a damaged entry is rebuilt from source and
 *              replaced. Deleting the folder (or its fmm_rows-*.bin files)
 *              clears the cache; it is refilled on the next build.
 *   library:   the OpenCL ICD loader to dlopen. NULL: $MESHFMM_OPENCL_LIBRARY,
 *              else "libOpenCL.so.1". */
typedef struct mfmm_opencl_options {
    size_t struct_size;      /* sizeof(mfmm_opencl_options), set by the _init function */
    const char *device;
    const char *cache_dir;
    const char *library;
} mfmm_opencl_options;

/* Fills `options` with the defaults (all NULL: the environment, then the
 * built-in defaults). */
MFMM_API void mfmm_opencl_options_init(mfmm_opencl_options *options);

/* Loads OpenCL, selects the device and builds the program (from the disk
 * cache when it holds a valid binary for this exact build and driver).
 *   options: NULL for defaults (see mfmm_opencl_options).
 *   out:     receives the context; NULL on failure.
 * MFMM_ERR_NO_OPENCL when the loader cannot be opened, no device matches or
 * works, or meshfmm was built without the OpenCL headers; MFMM_ERR_OPENCL_BUILD
 * when the program does not build. The mfmm_error says which. */
MFMM_API mfmm_status mfmm_opencl_context_create(const mfmm_opencl_options *options,
                                                mfmm_opencl_context **out, mfmm_error *err);

/* Frees a context; NULL is a no-op. No call may be using it. */
MFMM_API void mfmm_opencl_context_destroy(mfmm_opencl_context *context);

/* The name of the context's device ("" for NULL). */
MFMM_API const char *mfmm_opencl_context_device_name(const mfmm_opencl_context *context);

typedef enum mfmm_dtype {
    MFMM_FLOAT32 = 0,
    MFMM_FLOAT64 = 1
} mfmm_dtype;

/* Receives finished rows: rows [first_row, first_row + n_rows) of the matrix,
 * n_rows x nv values (n_targets with targets) of the requested dtype,
 * row-major, valid during the call. Rows arrive in order. Return 0 to go on, non-zero to cancel
 * (mfmm_distance_matrix then returns MFMM_ERR_CANCELLED). */
typedef int (*mfmm_rows_callback)(void *user, int32_t first_row, int32_t n_rows,
                                  const void *rows);

/* Receives finished rows as a CSR block (sparse output, see
 * mfmm_matrix_options.on_sparse): rows [first_row, first_row + n_rows);
 * row i's entries are indices[indptr[i] .. indptr[i+1]) (column ids,
 * ascending) with values[same range] of the requested dtype. indptr has
 * n_rows + 1 entries and starts at 0 for each block. Valid during the call;
 * rows arrive in order. Return 0 to go on, non-zero to cancel. */
typedef int (*mfmm_sparse_callback)(void *user, int32_t first_row, int32_t n_rows,
                                    const int64_t *indptr, const int32_t *indices,
                                    const void *values);

typedef struct mfmm_matrix_options {
    size_t struct_size;              /* sizeof(mfmm_matrix_options), set by the _init function */
    mfmm_backend backend;            /* default MFMM_BACKEND_AUTO */
    mfmm_dtype dtype;                /* output type; arithmetic is always float64. Default
                                        float32, refused (MFMM_ERR_BAD_ARGUMENT) where a
                                        distance could pass FLT_MAX: the edges' total length
                                        times the largest cost, or max_distance if less */
    const double *cost;              /* as in mfmm_solve_options */
    mfmm_cost_location cost_location;
    double max_distance;             /* default +inf; NaN or < 0: MFMM_ERR_BAD_ARGUMENT */
    int32_t unfolding;               /* default 1 */
    int32_t n_threads;               /* threads backend; 0: all cores */
    size_t memory_limit;             /* bytes the library may use for workspaces and
                                        blocks in flight; 0: a default from the device */
    void *out;                       /* n_sources x nv (n_targets with targets) buffer of
                                        dtype to fill, or NULL */
    mfmm_rows_callback on_rows;      /* called with each finished block, or NULL */
    void *user;                      /* passed to on_rows */
    mfmm_backend backend_used;       /* out: the backend that ran */
    mfmm_opencl_context *opencl;     /* for the OpenCL backend: a context to reuse, or
                                        NULL to make one for this call */
    const mfmm_opencl_options *opencl_options; /* how to make the call's context when
                                        opencl is NULL; NULL: defaults */
    char fallback_reason[256];       /* out: with backend AUTO, why threads ran instead of
                                        OpenCL (the OpenCL error, or that OpenCL could not
                                        keep every core busy); "" when OpenCL ran */
    /* Rectangular and sparse jobs (appended fields). */
    const int32_t *targets;          /* NULL: every vertex is a column (rows nv wide).
                                        Else n_targets >= 1 vertex ids: rows are n_targets
                                        wide, column j the distance to targets[j] (any
                                        order, duplicates allowed), and each row's march
                                        stops once all its targets are settled */
    int32_t n_targets;
    int64_t vertices_settled;        /* out: vertices settled over all rows by the serial and
                                        threads backends (the work done); 0 from OpenCL */
    /* Sparse output: rows go to on_sparse as CSR blocks holding only the
     * finite entries (distance <= max_distance; the source's own 0 is an
     * explicit entry), built from each march's touched list, so memory and
     * time follow the entries, never n_sources x nv. out and on_rows must be
     * NULL. Serial and threads backends; OPENCL fails with
     * MFMM_ERR_BAD_ARGUMENT, AUTO runs threads. */
    mfmm_sparse_callback on_sparse;
    /* as in mfmm_solve_options (appended field): each row's march starts from
     * the exact distances within this many mean edge lengths of its source, on
     * every backend (OpenCL: computed on the host, uploaded with the batch).
     * Default MFMM_EXACT_START_AUTO; 0: the plain start */
    double exact_start_radius;
    int64_t start_fallbacks;         /* out: over all rows, on every backend, as
                                        mfmm_solve_info.start_fallbacks */
} mfmm_matrix_options;

MFMM_API void mfmm_matrix_options_init(mfmm_matrix_options *options);

/* One row per source: row i holds the distances from vertex sources[i] to
 * every vertex (equal to mfmm_solve's), or to options->targets (an
 * n_sources x n_targets matrix, see mfmm_matrix_options.targets; on every
 * backend, OpenCL's kernel marching each row to its targets too), densely
 * (out, on_rows: n_sources x width values, width = n_targets or nv) or
 * sparsely (on_sparse; not on OpenCL: OPENCL fails with
 * MFMM_ERR_BAD_ARGUMENT and AUTO runs threads, fallback_reason says so). sources NULL: all vertices, in order
 * (n_sources must then be nv). Rows go to options->out, to options->on_rows,
 * or both; the library holds only the blocks in flight, never n_sources x nv.
 * With backend AUTO, threads run instead of OpenCL when OpenCL fails (from the
 * first row not yet delivered), and when OpenCL could not keep every compute
 * unit busy (a batch of rows smaller than the device's compute units within
 * memory_limit), and when the device is a CPU that the caller did not name
 * (mfmm_opencl_options.device or MESHFMM_OPENCL_DEVICE): on the same cores
 * the threads backend runs the same rows faster (README, "Command line");
 * options->backend_used tells which ran and
 * options->fallback_reason why. OpenCL: the device and program cache are
 * options->opencl's, else options->opencl_options' (see
 * mfmm_opencl_options). A batch holds at least one row per compute unit
 * (each row needs about 37 bytes per vertex for float32 output) unless
 * memory_limit is set and smaller. Float64 rows equal mfmm_solve's bit for bit
 * (OpenCL: built without contraction or relaxed math; tested on PoCL). */
MFMM_API mfmm_status mfmm_distance_matrix(const mfmm_mesh *mesh, const int32_t *sources,
                                          int32_t n_sources, mfmm_matrix_options *options,
                                          mfmm_error *err);

/* ------------------------------------------------------------------- I/O */

/* Reads a triangle mesh: OBJ (v/vt/vn indices, negative indices, polygons
 * fan-triangulated), OFF (CRLF too), PLY (ascii, binary little/big endian;
 * faces or tristrips), STL (binary or ascii, told apart by binary STL's
 * 84 + 50 n size; corners welded into vertices by exact position, facets
 * with coinciding corners dropped). The format comes from the extension
 * (case-insensitive), else from the content; other formats (glTF, FBX,
 * 3DS, DAE, ...) fail with MFMM_ERR_PARSE and a sentence naming the formats
 * read. Only regular files are read (a directory, FIFO or device fails at
 * once with MFMM_ERR_IO). Numbers are read the same whatever the locale
 * (correctly rounded). On success *vertices is (nv,3) float64 and *faces
 * (nf,3) int32, both allocated by the library: free them with mfmm_free. */
MFMM_API mfmm_status mfmm_load_mesh(const char *path, double **vertices, int32_t *nv,
                                    int32_t **faces, int32_t *nf, mfmm_error *err);

/* Frees memory the library handed out (mfmm_load_mesh). NULL is a no-op. */
MFMM_API void mfmm_free(void *pointer);

#ifdef __cplusplus
}
#endif

#endif /* MESHFMM_H */
