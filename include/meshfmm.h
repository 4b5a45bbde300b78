/*
 * meshfmm: geodesic distances and shortest paths on triangle meshes by the
 * Fast Marching Method of Kimmel & Sethian, "Computing geodesic paths on
 * manifolds", PNAS 95 (1998) 8431-8435, with an exact polyhedral solver
 * beside it.
 *
 * "The paper" below is Kimmel & Sethian's; "section N" alone is a section
 * of this header.
 *
 * The one public header; C99, C ABI. Its sections, essentials first:
 *   1. conventions and ABI policy     6. exact distances
 *   2. status and errors              7. paths
 *   3. mesh                           8. distance matrices (and OpenCL)
 *   4. sources and costs              9. I/O
 *   5. solve (the march)             10. advanced: tuning and diagnostics
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

/* ============================================ 1. conventions and ABI policy
 *
 * Arrays: vertices are float64 (nv, 3) row-major; faces int32 (nf, 3)
 * row-major, 0-based; per-vertex results (nv,) in the caller's vertex order.
 * Cost F: |grad T| = F, so a path costs F times its length (a slowness), per
 * vertex or per face, finite and > 0; without one F = 1 and T is geodesic
 * distance. Unreached vertices (another component, beyond max_distance, not
 * settled before an early stop) are +inf, never NaN.
 *
 * Errors: every function that can fail returns an mfmm_status; those that
 * validate input also fill an optional mfmm_error. The library never prints,
 * aborts or exits, and keeps no global mutable state.
 *
 * Threads: an mfmm_mesh is immutable after creation and may be shared by any
 * number of threads; a solver (mfmm_solver, mfmm_exact_solver) is a workspace
 * for one thread at a time; an mfmm_opencl_context may be shared. An _init
 * function writes only its argument; a _destroy function may not run while
 * any other call uses the object it frees.
 *
 * Structs that can grow start with `size_t struct_size`:
 *   - option structs (inputs): fill them with their _init function, which
 *     sets struct_size to the sizeof the caller was compiled with, then set
 *     fields. The library reads the first struct_size bytes and takes its
 *     defaults for fields beyond them.
 *   - info structs (outputs: mfmm_mesh_info, mfmm_solve_info, mfmm_exact_info,
 *     mfmm_matrix_info) have no _init: the caller sets struct_size to their
 *     sizeof before the call:
 *         mfmm_mesh_info info = {.struct_size = sizeof info};
 *     The library writes no more than struct_size bytes and sets struct_size
 *     to the bytes it wrote (the smaller of the caller's and its own size).
 * A struct_size smaller than sizeof(size_t), or (for an option struct) larger
 * than the library's own struct, is refused with MFMM_ERR_BAD_ARGUMENT. A
 * struct grows only by fields added at its end.
 *
 * Versions: the shared library's soname is libmeshfmm.so.0.MINOR while MAJOR
 * is 0 (a MINOR release may break the API and the ABI; the CMake package then
 * accepts only the same MINOR: find_package(meshfmm 0.2) takes 0.2.x), and
 * libmeshfmm.so.MAJOR from 1.0 on (only a MAJOR release breaks the ABI).
 * PATCH releases never break either. CHANGELOG.md lists every change.
 * Booleans are int32_t, 0 or 1.
 */

#define MFMM_VERSION_MAJOR 0
#define MFMM_VERSION_MINOR 2
#define MFMM_VERSION_PATCH 0

/* "MAJOR.MINOR.PATCH" of the library linked at run time. Thread-safe. */
MFMM_API const char *mfmm_version(void);

/* ==================================================== 2. status and errors */

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
    MFMM_ERR_WRONG_MESH,          /* the solver was created for another mesh (no function
                                     returns it at present; kept so that the values
                                     after it stay the same) */
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

/* A sentence naming a status, e.g. "a face names one vertex twice".
 * Returns a static string, never NULL (also for unknown values). Thread-safe. */
MFMM_API const char *mfmm_status_string(mfmm_status status);

/* Details of a failure, filled by functions that take an `mfmm_error *err`
 * (which may be NULL). On success status is MFMM_OK, index -1 and message "". */
typedef struct mfmm_error {
    mfmm_status status;
    int64_t index;        /* the offending vertex, face, source or file line; -1: none */
    char message[256];    /* a sentence that names it */
} mfmm_error;

/* ================================================================= 3. mesh */

typedef struct mfmm_mesh mfmm_mesh;
typedef struct mfmm_mesh_options mfmm_mesh_options; /* section 10 */

/* Validates a triangle mesh and precomputes what every solve reuses (vertex
 * adjacency, edge lengths, corner angles, a virtual edge for every obtuse
 * corner found by unfolding, the paper's section 4.2).
 *   vertices: (nv, 3) float64; copied. 1 <= nv <= 715827882.
 *   faces:    (nf, 3) int32, 0-based; copied. 1 <= nf <= 134217727.
 *   options:  NULL for defaults (section 10).
 *   out:      receives the mesh; NULL on failure.
 * Accepted: boundaries, several components, unreferenced vertices,
 * non-manifold edges, zero-area and needle faces, copies of a face. A
 * T-junction closed by a zero-area needle A-M-B (M inside edge AB) is closed
 * inside: the faces on AB are split at M, so distances and paths cross it as
 * the surface does. Face ids, vertex ids and per-vertex arrays stay the
 * caller's everywhere (vertices are renumbered inside for locality); results
 * scale with the mesh and do not depend on the order of the vertices.
 * Errors: MFMM_ERR_NULL_POINTER; MFMM_ERR_BAD_COUNT (nv or nf out of range);
 * MFMM_ERR_NONFINITE_VERTEX; MFMM_ERR_INDEX_OUT_OF_RANGE;
 * MFMM_ERR_REPEATED_VERTEX; MFMM_ERR_BAD_ARGUMENT (a coordinate beyond
 * +-1e100 or a bounding-box diagonal below 1e-100: rescale; bad options);
 * MFMM_ERR_OUT_OF_MEMORY. err->index names the vertex or face.
 * Thread-safe. */
MFMM_API mfmm_status mfmm_mesh_create(const double *vertices, int32_t nv,
                                      const int32_t *faces, int32_t nf,
                                      const mfmm_mesh_options *options,
                                      mfmm_mesh **out, mfmm_error *err);

/* Frees a mesh; NULL is a no-op. Every solver, context call and path on it
 * must have finished. */
MFMM_API void mfmm_mesh_destroy(mfmm_mesh *mesh);

/* A mesh's diagnostics, computed at creation (an output struct: set
 * struct_size, section 1). Edge and component counts are of the surface
 * built (T-junctions closed, copies of a face apart); face counts are of the
 * faces as given. */
typedef struct mfmm_mesh_info {
    size_t struct_size;
    int32_t n_vertices;              /* nv as given */
    int32_t n_faces;                 /* nf as given */
    int32_t n_edges;                 /* distinct undirected edges */
    int32_t n_boundary_edges;        /* edges with one face */
    int32_t n_nonmanifold_edges;     /* edges with three or more faces */
    int32_t n_components;            /* edge-connected components of referenced vertices */
    int32_t n_unreferenced_vertices; /* vertices no face names (always +inf) */
    int32_t n_degenerate_faces;      /* faces of (numerically) zero area, needles included */
    int32_t n_duplicate_faces;       /* faces repeating another face's vertices in any
                                        order; the march updates through a copy as
                                        through its original */
    int32_t n_obtuse_corners;        /* corners with an angle > 90 degrees */
    int32_t n_virtual_edges;         /* obtuse corners split by a virtual edge */
    int32_t n_unfold_failures;       /* obtuse corners whose unfolding walk failed
                                        (boundary, non-manifold edge or step limit) */
    double min_edge_length;
    double max_edge_length;
    double mean_edge_length;
    double bbox_diagonal;            /* length of the bounding-box diagonal */
    int32_t n_coincident_vertices;   /* referenced vertices at exactly the position of
                                        another (texture seams, unmerged STL corners):
                                        the vertices welding them would remove. Each
                                        copy is a separate vertex: the surface is cut
                                        there */
    int32_t n_welded_components;     /* n_components with each group of coincident
                                        vertices welded into one (far below
                                        n_components: the mesh is cut at its seams) */
} mfmm_mesh_info;

/* Fills `info` (up to info->struct_size bytes) with the mesh's diagnostics.
 * Errors: MFMM_ERR_NULL_POINTER; MFMM_ERR_BAD_ARGUMENT (struct_size too
 * small). Thread-safe. */
MFMM_API mfmm_status mfmm_mesh_get_info(const mfmm_mesh *mesh, mfmm_mesh_info *info);

/* nv and nf as given; 0 for NULL. Thread-safe. */
MFMM_API int32_t mfmm_mesh_vertex_count(const mfmm_mesh *mesh);
MFMM_API int32_t mfmm_mesh_face_count(const mfmm_mesh *mesh);

/* Welds coincident vertices (texture seams, unmerged STL corners): the
 * welded id of each vertex. Vertices of exactly equal position (-0.0 equal
 * to 0.0) share an id; ids are numbered by first occurrence, so a mesh
 * without coincident vertices keeps its numbering. The welded surface is
 * the welded vertices (each at its first occurrence's position) with the
 * faces mapped through `map`, less those with a repeated corner: the one
 * mfmm_mesh_info's n_coincident_vertices and n_welded_components describe.
 *   vertices: (nv, 3) float64, finite.
 *   map:      (nv,) int32 out: each vertex's welded id, in [0, *n_welded).
 *   n_welded: out: the number of distinct positions.
 * Errors: MFMM_ERR_NULL_POINTER; MFMM_ERR_BAD_COUNT (nv < 0);
 * MFMM_ERR_NONFINITE_VERTEX (err->index: the vertex); MFMM_ERR_OUT_OF_MEMORY.
 * Thread-safe. */
MFMM_API mfmm_status mfmm_weld_map(const double *vertices, int32_t nv, int32_t *map,
                                   int32_t *n_welded, mfmm_error *err);

/* ===================================================== 4. sources and costs */

/* A source: a vertex (face == -1), or a point in a face by barycentric
 * coordinates of its corners (>= 0, summing to 1 within 1e-9); a point on an
 * edge or at a corner is a point of every face holding it, so T does not
 * depend on which face names it. The result is T(x) = min over sources of
 * (value + cost-weighted distance). */
typedef struct mfmm_source {
    int32_t vertex;     /* vertex id when face == -1; ignored otherwise */
    int32_t face;       /* face id, or -1 for a vertex source */
    double bary[3];     /* barycentric coordinates in the face; ignored for a vertex */
    double value;       /* T at the source (usually 0) */
} mfmm_source;

/* Where a cost array lives. */
typedef enum mfmm_cost_location {
    MFMM_COST_NONE = 0,       /* F = 1 everywhere: geodesic distance */
    MFMM_COST_PER_VERTEX = 1, /* nv entries; F is linear along each edge */
    MFMM_COST_PER_FACE = 2    /* nf entries; paths refract at region borders */
} mfmm_cost_location;

/* ===================================================== 5. solve (the march) */

typedef struct mfmm_solver mfmm_solver;

/* Makes a reusable workspace for marches on one mesh, for one thread. Solves
 * build what later solves reuse (the exact start's workspace; the mesh's
 * shared tables, under a lock: the exact start's around the patches it
 * solves, the march's spokes once marches have paid for them, section 10);
 * a solve allocates only copies of its arguments, and costs in proportion
 * to what it reaches (max_distance, targets) apart from filling `distances`
 * (with MFMM_METHOD_WINDOWS, also one pass over the mesh to clear its
 * slots).
 *   mesh: the mesh, which must outlive the solver.
 *   out:  receives the solver; NULL on failure.
 * Errors: MFMM_ERR_NULL_POINTER; MFMM_ERR_OUT_OF_MEMORY. Thread-safe. */
MFMM_API mfmm_status mfmm_solver_create(const mfmm_mesh *mesh, mfmm_solver **out);

/* Frees a solver; NULL is a no-op. */
MFMM_API void mfmm_solver_destroy(mfmm_solver *solver);

/* The default of exact_start_radius: a radius that grows with the mesh
 * (MFMM_EXACT_START_RADIUS, section 10). */
#define MFMM_EXACT_START_AUTO (-1.0)

/* How mfmm_solve computes distances (docs/methods.md compares them). */
typedef enum mfmm_method {
    /* The paper's march (section 2) from the exact start: any cost; its
     * first-order error over-estimates along each path. */
    MFMM_METHOD_FMM = 0,
    /* Window propagation keeping two windows per half-edge: each value is
     * a straight segment from a source or a vertex where geodesics bend,
     * unfolded through the faces it crosses: several times more accurate
     * than the march, never below the geodesic distance beyond rounding,
     * exact on flat regions, several times the march's time. With a cost,
     * windows run within faces of one cost (value sigma + F |segment|) and
     * stop where it changes; a settled vertex updates a face whose corners'
     * costs differ by the march's triangle update (section 4.1) under the
     * march's cost convention. Those updates, as the march's, may lie below
     * the weighted distance. unfolding and exact_start_radius do not
     * apply. */
    MFMM_METHOD_WINDOWS = 1
} mfmm_method;

typedef struct mfmm_solve_options {
    size_t struct_size;              /* set by mfmm_solve_options_init */
    const double *cost;              /* NULL (default): F = 1. Finite and > 0, and its
                                        largest entry times the edges' total length below
                                        DBL_MAX / 16. Both methods take one */
    mfmm_cost_location cost_location;/* ignored when cost is NULL */
    double max_distance;             /* stop past it; vertices beyond are +inf. Default
                                        +inf; >= 0 */
    const int32_t *targets;          /* stop once all these vertices are settled; NULL
                                        (default): none */
    int32_t n_targets;
    int32_t unfolding;               /* 1 (default): obtuse corners update through their
                                        virtual edges; 0: plain stencils */
    /* The exact start: the march starts from the exact polyhedral distances
     * (mfmm_solve_exact's) of the vertices within this many mean edge lengths
     * of each source (at least the corners of its faces), T = value + F *
     * distance, instead of from the source's vertex or straight segments to
     * the vertices near a point source. It removes most of the error a
     * first-order march makes at the source's point singularity. With a cost
     * it applies only to a source around which F is one constant (else that
     * source starts plainly). MFMM_EXACT_START_AUTO (default), or finite and
     * >= 0; 0: the plain start of the paper. */
    double exact_start_radius;
    mfmm_method method;              /* default MFMM_METHOD_FMM */
} mfmm_solve_options;

/* Fills `options` with the defaults: no cost, no limit, no targets,
 * unfolding on, exact_start_radius MFMM_EXACT_START_AUTO, MFMM_METHOD_FMM.
 * NULL is a no-op. */
MFMM_API void mfmm_solve_options_init(mfmm_solve_options *options);

/* Computes T from the sources for every vertex: by default the paper's
 * march (section 2), with section 4.1's local update (Eq. 4-5) and, when
 * unfolding is on, section 4.2's virtual edges; options->method chooses.
 *   solver:    from mfmm_solver_create.
 *   sources:   (n_sources,) n_sources >= 1.
 *   options:   NULL for defaults.
 *   distances: (nv,) float64 out: T at settled vertices, +inf elsewhere (with
 *              targets, only settled vertices are final).
 * Errors: MFMM_ERR_NULL_POINTER; MFMM_ERR_BAD_COUNT; MFMM_ERR_BAD_SOURCE,
 * MFMM_ERR_BAD_BARYCENTRIC, MFMM_ERR_DEGENERATE_SOURCE (err->index: the
 * source); MFMM_ERR_BAD_COST (err->index: the entry); MFMM_ERR_BAD_ARGUMENT
 * (max_distance NaN or < 0; n_targets < 0, or > 0 with targets NULL; a
 * target out of range, err->index: its position; exact_start_radius;
 * method unknown; struct_size);
 * MFMM_ERR_OUT_OF_MEMORY.
 * Thread safety: one call at a time per solver. */
MFMM_API mfmm_status mfmm_solve(mfmm_solver *solver, const mfmm_source *sources,
                                int32_t n_sources, const mfmm_solve_options *options,
                                double *distances, mfmm_error *err);

/* What the last mfmm_solve on a solver did (an output struct: set
 * struct_size, section 1). */
typedef struct mfmm_solve_info {
    size_t struct_size;
    int64_t start_fallbacks; /* exact-start vertices whose exact distance broke a bound
                                every distance meets (at least the straight-line distance
                                from the source, at most the shortest edge path) and
                                which the march computed instead; 0 but on degenerate
                                meshes */
} mfmm_solve_info;

/* Fills `info` about the solver's last mfmm_solve (zeros before the first).
 * Errors: MFMM_ERR_NULL_POINTER; MFMM_ERR_BAD_ARGUMENT (struct_size too
 * small). Not while the solver solves in another thread. */
MFMM_API mfmm_status mfmm_solver_get_info(const mfmm_solver *solver, mfmm_solve_info *info);

/* Geodesic farthest-point sampling: k vertices, the first `start`, each
 * next the vertex farthest from those chosen so far (the largest distance
 * to its nearest chosen vertex; ties to the lowest vertex id). Vertices in
 * no face are never chosen; a vertex another component holds (+inf from
 * every chosen one) is farther than any reached one, so each component
 * gets a point before any gets a second. One march per point on this
 * solver, each stopped at the current farthest distance (it cannot lower
 * the running minimum beyond it): much less than k full solves, with the
 * values of full solves (the exact start keeps a full solve's radius).
 *   solver:    from mfmm_solver_create.
 *   start:     the first vertex, in a face.
 *   k:         points to choose, 1 <= k <= the vertices in faces.
 *   options:   NULL for defaults; cost, unfolding, exact_start_radius and
 *              method as for mfmm_solve; max_distance must be +inf and
 *              n_targets 0.
 *   points:    (k,) int32 out: the vertex ids in the order chosen.
 *   radii:     (k,) float64 out, may be NULL: radii[i] is points[i]'s
 *              distance to points[0..i-1] when chosen (+inf for i = 0):
 *              non-increasing, each the covering radius of the points before.
 *   distances: (nv,) float64 out, may be NULL: each vertex's distance to
 *              its nearest point (+inf for vertices in no face and
 *              components without a point).
 * Errors: MFMM_ERR_NULL_POINTER; MFMM_ERR_BAD_COUNT (k); MFMM_ERR_BAD_SOURCE
 * (start out of range or in no face); MFMM_ERR_BAD_COST; MFMM_ERR_BAD_ARGUMENT
 * (max_distance, targets, exact_start_radius, method, struct_size);
 * MFMM_ERR_OUT_OF_MEMORY.
 * Thread safety: one call at a time per solver. */
MFMM_API mfmm_status mfmm_farthest_points(mfmm_solver *solver, int32_t start, int32_t k,
                                          const mfmm_solve_options *options, int32_t *points,
                                          double *radii, double *distances, mfmm_error *err);

/* ====================================================== 6. exact distances */

/* Exact polyhedral geodesic distance (F = 1): the length of the shortest path
 * on the surface of the piecewise-flat mesh, by window propagation (Chen &
 * Han with the pruning of Xin & Wang). Equal to Kirsanov's MMP
 * (igl.exact_geodesic, gdist) to rounding; see docs/methods.md. Boundaries
 * are walls a path may run along; a path crosses a non-manifold edge from any
 * face on it into any other (on degenerate folded fans, past a budget of
 * windows, those edges become walls: mfmm_exact_info.nonmanifold_walls); a
 * zero-area face is passed along its line; copies of a face are ignored. For
 * a cost use mfmm_solve. */
typedef struct mfmm_exact_solver mfmm_exact_solver;

/* Makes a workspace for exact solves on one mesh, for one thread; its window
 * queue grows as needed and is kept for the next solve. The mesh's edge
 * tables are built where solves reach (under a lock; a solve to a
 * max_distance builds them near its sources only) and shared by every
 * solver on the mesh.
 *   mesh: the mesh, which must outlive the solver.
 *   out:  receives the solver; NULL on failure.
 * Errors: MFMM_ERR_NULL_POINTER; MFMM_ERR_OUT_OF_MEMORY. Thread-safe. */
MFMM_API mfmm_status mfmm_exact_solver_create(const mfmm_mesh *mesh, mfmm_exact_solver **out);

/* Frees an exact solver; NULL is a no-op. */
MFMM_API void mfmm_exact_solver_destroy(mfmm_exact_solver *solver);

typedef struct mfmm_exact_options {
    size_t struct_size;   /* set by mfmm_exact_options_init */
    double max_distance;  /* vertices farther are +inf and the propagation stops
                             there. Default +inf; >= 0 */
    size_t memory_limit;  /* bytes the solver may hold during the solve, the mesh's
                             tables included; needing more returns
                             MFMM_ERR_MEMORY_LIMIT. 0 (default): no limit */
    int (*interrupt)(void *user); /* NULL (default), or called every few milliseconds
                             of propagation: non-zero stops the solve with
                             MFMM_ERR_CANCELLED */
    void *user;           /* passed to interrupt */
} mfmm_exact_options;

/* Fills `options` with the defaults: no limit on distance or memory, no
 * interrupt. NULL is a no-op. */
MFMM_API void mfmm_exact_options_init(mfmm_exact_options *options);

/* What one exact solve did (an output struct: set struct_size, section 1). */
typedef struct mfmm_exact_info {
    size_t struct_size;
    int64_t n_windows;         /* windows created */
    int64_t n_propagated;      /* windows taken from the queue and carried across a face */
    int64_t n_pseudo_sources;  /* vertex sources and saddle or boundary vertices that
                                  started windows */
    int64_t peak_windows;      /* most windows queued at once */
    size_t peak_bytes;         /* most bytes the solver held (tables and queue) */
    int32_t nonmanifold_walls; /* 1: windows crossing non-manifold edges passed their
                                  budget and the solve was redone with those edges as
                                  walls (values there are upper bounds); 0: crossed */
} mfmm_exact_info;

/* Exact geodesic distances from the sources to every vertex.
 *   solver:    from mfmm_exact_solver_create.
 *   sources:   (n_sources,) n_sources >= 1, as for mfmm_solve.
 *   options:   NULL for defaults.
 *   distances: (nv,) float64 out; +inf where no source reaches and beyond
 *              max_distance; all +inf on error.
 *   info:      out, may be NULL.
 * Errors: MFMM_ERR_NULL_POINTER; MFMM_ERR_BAD_COUNT; MFMM_ERR_BAD_SOURCE,
 * MFMM_ERR_BAD_BARYCENTRIC, MFMM_ERR_DEGENERATE_SOURCE (err->index: the
 * source); MFMM_ERR_BAD_ARGUMENT (max_distance NaN or < 0, struct_size);
 * MFMM_ERR_MEMORY_LIMIT; MFMM_ERR_CANCELLED; MFMM_ERR_OUT_OF_MEMORY.
 * Thread safety: one call at a time per solver. */
MFMM_API mfmm_status mfmm_solve_exact(mfmm_exact_solver *solver, const mfmm_source *sources,
                                      int32_t n_sources, const mfmm_exact_options *options,
                                      double *distances, mfmm_exact_info *info,
                                      mfmm_error *err);

/* ================================================================ 7. paths */

/* A point on the surface: a face, barycentric coordinates in it, its position. */
typedef struct mfmm_surface_point {
    int32_t face;
    double bary[3];
    double xyz[3];
} mfmm_surface_point;

typedef struct mfmm_path_options {
    size_t struct_size;   /* set by mfmm_path_options_init */
    int32_t max_points;   /* most points a path may have; default 100000 */
    /* The sources the distances came from: the path ends exactly at the one
     * the target's distance came from. NULL (default): it ends at a vertex
     * where T is 0 and no neighbour is lower (where T stops decreasing above
     * 0, the call fails rather than end there). */
    const mfmm_source *sources;
    int32_t n_sources;
    const double *cost;               /* the cost the distances were solved with, or NULL */
    mfmm_cost_location cost_location;
    double *weighted_length;          /* out, may be NULL: the sum of F times segment
                                         length (without a cost, the length) */
    /* 1 (default): straighten the traced path inside the strip of faces it
     * crossed (the shortest polyline through the shared edges, by the funnel
     * algorithm), removing the drift that T's first-order error gives the
     * gradient; never longer than the traced path. Not applied with a cost (a
     * weighted path refracts). 0: the traced path of the paper's section 5. */
    int32_t straighten;
} mfmm_path_options;

/* Fills `options` with the defaults: 100000 points, no sources, no cost,
 * straighten 1. NULL is a no-op. */
MFMM_API void mfmm_path_options_init(mfmm_path_options *options);

/* Traces the shortest path from `target` back to the source along -grad T
 * (the paper's section 5: Heun's method on T interpolated by a quadratic over each
 * face and its neighbours, then straightened).
 *   distances: (nv,) T from mfmm_solve (or mfmm_solve_exact).
 *   target:    a vertex (face == -1) or a point in a face (value ignored), not
 *              in a zero-area face.
 *   options:   NULL for defaults.
 *   points:    (capacity,) out, NULL when capacity is 0: the polyline from
 *              the target to the source (the target, each edge crossing and
 *              vertex passed, the end); points[i].face (i > 0) is the face
 *              the segment from point i-1 runs through.
 *   n_points:  out: the count (also on MFMM_ERR_BAD_COUNT: the count needed).
 *   length:    out, may be NULL: the polyline's Euclidean length.
 * Errors: MFMM_ERR_NULL_POINTER; MFMM_ERR_BAD_COUNT (capacity too small);
 * MFMM_ERR_BAD_SOURCE, MFMM_ERR_BAD_BARYCENTRIC, MFMM_ERR_DEGENERATE_SOURCE
 * (the target or a source); MFMM_ERR_BAD_COST (err->index: the entry);
 * MFMM_ERR_BAD_ARGUMENT; MFMM_ERR_UNREACHED (T(target) is +inf);
 * MFMM_ERR_PATH_STALLED (T stopped decreasing before a source, or the path
 * needed more than max_points points: never a path that ends elsewhere);
 * MFMM_ERR_OUT_OF_MEMORY. Thread-safe. */
MFMM_API mfmm_status mfmm_trace_path(const mfmm_mesh *mesh, const double *distances,
                                     const mfmm_source *target,
                                     const mfmm_path_options *options,
                                     mfmm_surface_point *points, int32_t capacity,
                                     int32_t *n_points, double *length, mfmm_error *err);

/* Geodesic Voronoi labels: for a distance field from several sources,
 * which source each vertex's distance comes from. One pass over the
 * vertices' edges: a vertex named by a vertex source whose value is its T
 * takes that source, a corner of a face source's face that source when it
 * explains T best (value + the straight distance in the face), any other
 * vertex the label of its lower neighbour u minimizing T(u) + |uv| (ties:
 * a source before a neighbour, then the lowest source index or vertex id).
 * Inside a cell every vertex agrees with the argmin over single-source
 * fields; within about an edge of a cell's border, where two sources' distances
 * differ by less than the march's error, either may be given.
 *   distances: (nv,) T from mfmm_solve or mfmm_solve_exact with `sources`.
 *   sources:   (n_sources,) n_sources >= 1, as given to the solve.
 *   labels:    (nv,) int32 out: an index into sources, -1 where T is +inf.
 * Errors: MFMM_ERR_NULL_POINTER; MFMM_ERR_BAD_COUNT; MFMM_ERR_BAD_SOURCE,
 * MFMM_ERR_BAD_BARYCENTRIC, MFMM_ERR_DEGENERATE_SOURCE (err->index: the
 * source); MFMM_ERR_BAD_ARGUMENT (a NaN distance, err->index: its vertex);
 * MFMM_ERR_OUT_OF_MEMORY. Thread-safe. */
MFMM_API mfmm_status mfmm_voronoi_labels(const mfmm_mesh *mesh, const double *distances,
                                         const mfmm_source *sources, int32_t n_sources,
                                         int32_t *labels, mfmm_error *err);

/* One polyline of mfmm_isolines: points[start .. start + n_points) of the
 * call's points. */
typedef struct mfmm_isoline {
    int64_t start;    /* its first point's index in points */
    int64_t n_points; /* >= 2: its segments plus one */
    int32_t value;    /* its level: an index into values */
    int32_t closed;   /* 1: a loop, its last point at the first's position (on
                         the face of its last segment); 0: it ends at a
                         boundary, a face with a non-finite corner or a
                         non-manifold edge */
} mfmm_isoline;

/* Isolines of a per-vertex field: for each of `values`, where the linear
 * interpolant of `field` over each face equals it, as polylines. One pass
 * over the faces for all the values (each vertex's rank among the sorted
 * values; a face crosses the values between its corners' least and
 * greatest rank), then work in proportion to the segments found.
 * A corner counts as above a value when field >= value; a face whose
 * corners are not all on one side holds one segment per value, between the
 * two points where its edges cross; a face with a non-finite corner holds
 * none. Each crossing point is interpolated along its edge from the edge's
 * lower vertex id p to the higher q (t = (value - field[p]) / (field[q] -
 * field[p]), xyz = p + t (q - p), barycentric 1 - t at p and t at q), so
 * that faces sharing an edge share the point bit for bit.
 * Each value's segments are joined through the edges they share. Its
 * polylines come in this order: first those with an end where a segment
 * meets no other (a boundary, a face with a non-finite corner), each from
 * that end, by the end's edge (lower vertex id, then higher); then the
 * others (loops; lines between non-manifold edges), each from the first
 * segment not yet used (faces ascending) at the crossing on its face's
 * lower-numbered edge (edge k is opposite corner k). Where more than two
 * segments meet at an edge (a non-manifold edge), a polyline goes on with
 * the first one not yet used (faces ascending). On a mesh whose
 * T-junctions were closed (section 3) the faces are those built: a split
 * face's pieces, each point's face and coordinates mapped to the face as
 * given, and a dropped needle holds none.
 *   field:    (nv,) float64, one value per vertex (e.g. distances); no
 *             NaN; +-inf allowed (faces with such a corner hold none).
 *   values:   (n_values,) the levels: finite, any order, repeats allowed
 *             (each has its own polylines); NULL when n_values is 0.
 *   points:   out: (*n_points,) the polylines' points one after another;
 *             points[i].face (i > a polyline's start) is the face the
 *             segment from point i-1 runs through, the start's face that of
 *             the point after it; bary: coordinates in that face; xyz: the
 *             position. Allocated by the library (free with mfmm_free); NULL
 *             when *n_points is 0 and on failure.
 *   n_points: out: the count: the segments plus *n_lines.
 *   lines:    out: (*n_lines,) the polylines by value index, each value's
 *             in the order above; allocated by the library (mfmm_free);
 *             NULL when *n_lines is 0 and on failure.
 *   n_lines:  out: the count.
 * Errors: MFMM_ERR_NULL_POINTER; MFMM_ERR_BAD_COUNT (n_values < 0);
 * MFMM_ERR_BAD_ARGUMENT (a value not finite, err->index: its index; a NaN
 * in field, err->index: its vertex); MFMM_ERR_OUT_OF_MEMORY. Thread-safe. */
MFMM_API mfmm_status mfmm_isolines(const mfmm_mesh *mesh, const double *field,
                                   const double *values, int32_t n_values,
                                   mfmm_surface_point **points, int64_t *n_points,
                                   mfmm_isoline **lines, int64_t *n_lines, mfmm_error *err);

/* ================================================== 8. distance matrices */

typedef enum mfmm_backend {
    MFMM_BACKEND_AUTO = 0,   /* OpenCL on a usable device that is not a CPU (or that the
                                caller named), else threads */
    MFMM_BACKEND_SERIAL = 1, /* one solver, the calling thread */
    MFMM_BACKEND_THREADS = 2,/* one solver per thread */
    MFMM_BACKEND_OPENCL = 3  /* many rows at once on an OpenCL device */
} mfmm_backend;

/* "auto", "serial", "threads", "opencl" ("unknown" otherwise). Thread-safe. */
MFMM_API const char *mfmm_backend_name(mfmm_backend backend);

typedef enum mfmm_dtype {
    MFMM_FLOAT32 = 0,
    MFMM_FLOAT64 = 1
} mfmm_dtype;

/* Receives finished rows [first_row, first_row + n_rows), n_rows x width
 * values of the job's dtype, row-major, valid during the call; rows arrive in
 * order. Returns 0 to go on, non-zero to cancel (MFMM_ERR_CANCELLED). */
typedef int (*mfmm_rows_callback)(void *user, int32_t first_row, int32_t n_rows,
                                  const void *rows);

/* Receives finished rows [first_row, first_row + n_rows) as a CSR block: row
 * i's entries are indices[indptr[i] .. indptr[i+1]) (column ids, ascending)
 * with values[same range] of the job's dtype; indptr has n_rows + 1 entries
 * and starts at 0. Valid during the call; rows arrive in order. Returns 0 to
 * go on, non-zero to cancel (MFMM_ERR_CANCELLED). */
typedef int (*mfmm_sparse_callback)(void *user, int32_t first_row, int32_t n_rows,
                                    const int64_t *indptr, const int32_t *indices,
                                    const void *values);

typedef struct mfmm_opencl_context mfmm_opencl_context;
typedef struct mfmm_opencl_options mfmm_opencl_options;

typedef struct mfmm_matrix_options {
    size_t struct_size;              /* set by mfmm_matrix_options_init */
    mfmm_backend backend;            /* default MFMM_BACKEND_AUTO */
    mfmm_dtype dtype;                /* of the output; arithmetic is float64. Default
                                        float32, refused where a distance could pass
                                        FLT_MAX */
    const double *cost;              /* as in mfmm_solve_options */
    mfmm_cost_location cost_location;
    double max_distance;             /* default +inf; >= 0 */
    const int32_t *targets;          /* NULL (default): every vertex is a column (width
                                        nv). Else (n_targets,) vertex ids, any order,
                                        repeats allowed: column j is the distance to
                                        targets[j], and each row's march stops once its
                                        targets are settled */
    int32_t n_targets;
    int32_t unfolding;               /* default 1, as in mfmm_solve_options */
    double exact_start_radius;       /* as in mfmm_solve_options, on every backend */
    int32_t n_threads;               /* threads backend; 0 (default): all cores */
    size_t memory_limit;             /* bytes for workspaces and blocks in flight; 0
                                        (default): 16 MiB, and on OpenCL at least one
                                        row per compute unit */
    void *out;                       /* (n_sources, width) of dtype to fill, or NULL */
    mfmm_rows_callback on_rows;      /* dense rows, block by block, or NULL */
    mfmm_sparse_callback on_sparse;  /* sparse rows: only the finite entries (the
                                        source's own 0 included); out and on_rows must
                                        then be NULL; not on OPENCL */
    void *user;                      /* passed to on_rows and on_sparse */
    mfmm_opencl_context *opencl;     /* OpenCL: a context to reuse, or NULL to make one
                                        for the call */
    const mfmm_opencl_options *opencl_options; /* how to make the call's context when
                                        opencl is NULL; NULL: defaults */
    mfmm_method method;              /* as in mfmm_solve_options (default
                                        MFMM_METHOD_FMM); MFMM_METHOD_WINDOWS runs on
                                        every backend (auto: threads) */
} mfmm_matrix_options;

/* Fills `options` with the defaults (auto backend, float32, no cost, no limit,
 * every vertex a column, unfolding on, MFMM_EXACT_START_AUTO, all cores, no
 * output, MFMM_METHOD_FMM). NULL is a no-op. */
MFMM_API void mfmm_matrix_options_init(mfmm_matrix_options *options);

/* What one mfmm_distance_matrix call did (an output struct: set
 * struct_size, section 1). */
typedef struct mfmm_matrix_info {
    size_t struct_size;
    mfmm_backend backend_used;    /* the backend that ran (the last one, after a
                                     fallback) */
    char backend_reason[256];     /* why another backend than the one asked for ran (the
                                     OpenCL error, a CPU device, too few rows per compute
                                     unit, sparse rows); "" when the requested one ran */
    int64_t vertices_settled;     /* vertices settled over all rows by the serial and
                                     threads backends; 0 from OpenCL */
    int64_t start_fallbacks;      /* over all rows, as mfmm_solve_info.start_fallbacks */
} mfmm_matrix_info;

/* Computes one row per source: row i holds the distances from vertex
 * sources[i] to every vertex (equal to mfmm_solve's), or to options->targets.
 *   mesh:      the mesh.
 *   sources:   (n_sources,) vertex ids; NULL: every vertex in order
 *              (n_sources must be nv).
 *   options:   required: out, on_rows (or both), or on_sparse.
 *   info:      out, may be NULL; filled also on failure.
 * Rows go to the buffer and callbacks in order; the library holds only the
 * blocks in flight. With MFMM_BACKEND_AUTO the threads backend runs instead
 * of OpenCL (from the first row not yet delivered) when OpenCL fails, when
 * the device is a CPU the caller did not name, when a batch would not keep
 * every compute unit busy within memory_limit, and for sparse rows
 * and for MFMM_METHOD_WINDOWS (info->backend_reason says why). Float64 rows
 * equal mfmm_solve's bit for bit on every backend.
 * Errors: MFMM_ERR_NULL_POINTER; MFMM_ERR_BAD_COUNT (n_sources, n_targets);
 * MFMM_ERR_BAD_SOURCE (err->index: the row); MFMM_ERR_BAD_COST;
 * MFMM_ERR_BAD_ARGUMENT (no output, sparse with dense or on OPENCL, a
 * target out of range, dtype, backend, max_distance, exact_start_radius,
 * method as for mfmm_solve, n_threads < 0,
 * float32 range, struct_size);
 * MFMM_ERR_CANCELLED; MFMM_ERR_NO_OPENCL, MFMM_ERR_OPENCL_BUILD,
 * MFMM_ERR_OPENCL_RUNTIME (backend OPENCL); MFMM_ERR_OUT_OF_MEMORY.
 * Thread-safe (calls on one mesh may run at once; callbacks run on the
 * calling thread). */
MFMM_API mfmm_status mfmm_distance_matrix(const mfmm_mesh *mesh, const int32_t *sources,
                                          int32_t n_sources,
                                          const mfmm_matrix_options *options,
                                          mfmm_matrix_info *info, mfmm_error *err);

/* An OpenCL device with meshfmm's program built for it: make one and pass it
 * in mfmm_matrix_options.opencl to build once for many calls. OpenCL is
 * loaded at run time (the library does not link libOpenCL; it opens the ICD
 * loader only when a context is made), so everything else works on a machine
 * without OpenCL. */
struct mfmm_opencl_options {
    size_t struct_size;      /* set by mfmm_opencl_options_init */
    /* Device: an index over all platforms' devices in order ("0", "1", ...) or
     * a case-insensitive substring of a device name ("pthread", "NVIDIA").
     * NULL: $MESHFMM_OPENCL_DEVICE, else the first device with float64 that
     * is not a CPU (a GPU or accelerator), else the first such CPU device,
     * else the first. */
    const char *device;
    /* Folder of the built program binaries (files fmm_rows-<key>.bin, keyed by
     * kernel source, build options, library, platform, device and driver
     * versions; a damaged entry is rebuilt). NULL: $MESHFMM_CACHE_DIR, else
     * $XDG_CACHE_HOME/meshfmm, else $HOME/.cache/meshfmm. "": no disk cache. */
    const char *cache_dir;
    /* The OpenCL ICD loader to open. NULL: $MESHFMM_OPENCL_LIBRARY, else
     * "libOpenCL.so.1" (macOS: the OpenCL framework). */
    const char *library;
};

/* Fills `options` with the defaults (all NULL: the environment, then the
 * built-in defaults). NULL is a no-op. */
MFMM_API void mfmm_opencl_options_init(mfmm_opencl_options *options);

/* Loads OpenCL, selects the device and builds the program (or loads it from
 * the disk cache), checking it against the serial solver on a small mesh.
 *   options: NULL for defaults.
 *   out:     receives the context; NULL on failure.
 * Errors: MFMM_ERR_NULL_POINTER; MFMM_ERR_BAD_ARGUMENT (struct_size);
 * MFMM_ERR_NO_OPENCL (no loader, no matching or working device, or built
 * without OpenCL headers); MFMM_ERR_OPENCL_BUILD; MFMM_ERR_OPENCL_RUNTIME;
 * MFMM_ERR_OUT_OF_MEMORY. Thread-safe. */
MFMM_API mfmm_status mfmm_opencl_context_create(const mfmm_opencl_options *options,
                                                mfmm_opencl_context **out, mfmm_error *err);

/* Frees a context; NULL is a no-op. No call may be using it. */
MFMM_API void mfmm_opencl_context_destroy(mfmm_opencl_context *context);

/* The name of the context's device ("" for NULL). Thread-safe. */
MFMM_API const char *mfmm_opencl_context_device_name(const mfmm_opencl_context *context);

/* ================================================================== 9. I/O */

/* Reads a triangle mesh file: OBJ, OFF, PLY (ascii and binary; faces or
 * tristrips) or STL (binary or ascii; corners welded by exact position,
 * facets with coinciding corners dropped); polygons are fan-triangulated.
 * The format comes from the extension, else from the content. Numbers are
 * read the same in every locale.
 *   path:     a regular file.
 *   vertices: out: (nv, 3) float64, allocated by the library (mfmm_free).
 *   faces:    out: (nf, 3) int32, allocated by the library (mfmm_free).
 * Errors: MFMM_ERR_NULL_POINTER; MFMM_ERR_IO (cannot open or read, not a
 * regular file); MFMM_ERR_PARSE (malformed, another format, an unsupported
 * extension, no vertices or no faces, more than int32 counts; err->index: the
 * line, or -1); MFMM_ERR_OUT_OF_MEMORY. Thread-safe. */
MFMM_API mfmm_status mfmm_load_mesh(const char *path, double **vertices, int32_t *nv,
                                    int32_t **faces, int32_t *nf, mfmm_error *err);

/* Frees memory the library handed out (mfmm_load_mesh); NULL is a no-op.
 * Thread-safe. */
MFMM_API void mfmm_free(void *pointer);

/* ============================================ 10. advanced: tuning, memory
 * Knobs with good defaults, and diagnostics; most programs need none. */

struct mfmm_mesh_options {
    size_t struct_size;        /* set by mfmm_mesh_options_init */
    /* Most faces one unfolding walk may cross to find the virtual edge of an
     * obtuse corner (the paper's section 4.2); a walk that needs more fails and the corner
     * keeps its plain stencil. Default 64; >= 1. */
    int32_t max_unfold_steps;
    /* 1 (default): marches at F = 1 with unfolding read per-vertex update
     * records ("spokes", about 400 bytes a vertex) for a march about 0.7x
     * as long, built once the mesh's marches have settled 8 times its
     * vertices without them (about what building them costs; so a program
     * that asks a few fields never pays for them), or by the first row of a
     * distance matrix of 8 rows or more; kept with the mesh. 0: never build
     * them (less memory). The results are the same bit for bit. */
    int32_t spokes;
};

/* Fills `options` with the defaults. NULL is a no-op. */
MFMM_API void mfmm_mesh_options_init(mfmm_mesh_options *options);

/* exact_start_radius's base under MFMM_EXACT_START_AUTO, in mean edge
 * lengths. The default radius is this times sqrt(nv /
 * MFMM_EXACT_START_AUTO_VERTICES) on meshes larger than that (e.g. 17.5 at
 * 250,000 vertices), so that the patch keeps the same share of a finer
 * surface; a march with a finite max_distance keeps the base radius, so that
 * its cost follows its reach. The patch also holds the vertices just beyond
 * the radius whose exact distances the propagation found anyway. */
#define MFMM_EXACT_START_RADIUS 7.0
#define MFMM_EXACT_START_AUTO_VERTICES 40000

/* The memory a mesh holds, array by array (solvers' and calls' workspaces
 * apart); entries built on use ("spokes (once built)", "exact tables
 * (once built)": the part built so far) count 0 until then.
 *   names: (max,) out: each array's name, a static string of the library.
 *   bytes: (max,) out: its size in bytes.
 *   max:   room in names and bytes; 0 (with NULL arrays) to ask for the count.
 * Returns the number of arrays (all of them, even past max); -1 when mesh is
 * NULL, max < 0, or names or bytes is NULL with max > 0. Thread-safe, also
 * while other threads solve on the mesh. */
MFMM_API int mfmm_mesh_memory(const mfmm_mesh *mesh, const char **names, size_t *bytes,
                              int max);

#ifdef __cplusplus
}
#endif

#endif /* MESHFMM_H */
