/* The meshfmm command line: shared declarations. Each subcommand is a
 * function `int cmd_NAME(int argc, char **argv)` (argv[0] is the
 * subcommand's name) returning an exit status, listed in main.c's table. */
#ifndef MFMM_CLI_H
#define MFMM_CLI_H

#include <stdint.h>
#include <getopt.h>
#include <stdio.h>

#include "meshfmm.h"

enum { CLI_OK = 0, CLI_FAIL = 1, CLI_USAGE = 2 };

int cmd_info(int argc, char **argv);
int cmd_distance(int argc, char **argv);
int cmd_generate(int argc, char **argv);
int cmd_allpairs(int argc, char **argv);
int cmd_path(int argc, char **argv);
int cmd_landmarks(int argc, char **argv);
int cmd_weld(int argc, char **argv);
int cmd_voronoi(int argc, char **argv);

/* Prints "meshfmm: <message>\n" on stderr. */
void cli_error(const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 1, 2)))
#endif
    ;

/* Prints "meshfmm SUB: <message>" and a hint to run --help; returns CLI_USAGE. */
int cli_usage_error(const char *sub, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Strict number parsing of a whole argument: 1 on success, 0 otherwise. */
int cli_parse_int32(const char *s, int32_t *out);
int cli_parse_double(const char *s, double *out);

/* 1 when `path` ends with `.ext` (case-insensitive; ext without the dot). */
int cli_has_ext(const char *path, const char *ext);

/* ---- the mesh of a command (mesh.c) ---- */

/* A mesh file loaded and built; with --weld, vertices at exactly the same
 * position (-0.0 as 0.0) are one vertex, numbered by their lowest file id
 * in file order, faces keep their corner order and a face two of whose
 * corners weld together (zero area) is dropped, as `meshfmm weld` and
 * Python's Mesh(V, F, weld=True) do. Arguments and results stay in the
 * file's ids: the maps below translate them. */
typedef struct cli_mesh {
    mfmm_mesh *mesh;
    int32_t nv_in, nf_in; /* the file's counts */
    int32_t nv, nf;       /* the built mesh's (the same unless welded) */
    /* welded only (NULL otherwise): */
    int32_t *to_welded;   /* (nv_in) the built vertex of each file vertex */
    int32_t *rep;         /* (nv) the lowest file id of each built vertex */
    int32_t *face_in;     /* (nf) the file's face of each built face */
    int32_t *face_welded; /* (nf_in) the built face of each file face, -1: dropped */
    /* (nv_in) 1 for the file's vertices in no face (once welded), or NULL
     * when there are none */
    uint8_t *in_no_face;
    double *V;            /* (nv, 3) and (nf, 3): the built mesh's arrays, */
    int32_t *F;           /* when asked for (keep_arrays), else NULL */
} cli_mesh;

/* 0, or -1 with the error printed (m is then empty). weld: 0 or 1; a file
 * with non-finite coordinates or face ids out of range is built unwelded,
 * so that the library's error names the file's vertex or face. */
int cli_mesh_load(cli_mesh *m, const char *path, const mfmm_mesh_options *options, int weld,
                  int keep_arrays);
void cli_mesh_free(cli_mesh *m);
/* The file's id -> the built mesh's, in place. Welded: checked against the
 * file's counts (and a dropped face refused), the error printed as
 * "WHAT: vertex V is outside [0, N)"; unwelded: unchanged, for the library
 * to check. 0 or -1. */
int cli_mesh_vertex(const cli_mesh *m, const char *what, int32_t *v);
int cli_mesh_face(const cli_mesh *m, const char *what, int32_t *f);
int cli_mesh_point(const cli_mesh *m, const char *what, mfmm_source *s);
/* A cost per file vertex (the lowest file id's value is kept) or face, in
 * place, -> per built vertex or face. */
void cli_mesh_cost(const cli_mesh *m, double *cost, int per_face);
/* Built per-vertex values (malloc'ed, itemsize bytes each) -> per file
 * vertex: `values` itself when unwelded, else a new array (values freed).
 * NULL with "out of memory" printed (values freed). */
void *cli_mesh_per_input_vertex(const cli_mesh *m, void *values, size_t itemsize);
/* A built face or vertex id -> the file's (its lowest id for a vertex). */
int32_t cli_mesh_input_face(const cli_mesh *m, int32_t f);
int32_t cli_mesh_input_vertex(const cli_mesh *m, int32_t v);
/* Welds V (nv) and F (nf, rewritten in place): map[v] the welded id of
 * vertex v (first occurrence order), W (room for nv vertices) the welded
 * vertices, F's first *n_kept faces the faces kept, face_in (room for nf;
 * may be NULL) the input face of each. 0, or -1 out of memory (nothing
 * printed). */
int cli_weld(const double *V, int32_t nv, int32_t *F, int32_t nf, int32_t *map, double *W,
             int32_t *face_in, int32_t *n_welded, int32_t *n_kept);
/* cli_mesh_load without weld, for a command that needs only the mesh:
 * NULL on failure (printed); in_no_face (may be NULL): m.in_no_face, now
 * the caller's. */
mfmm_mesh *cli_load_mesh(const char *path, const mfmm_mesh_options *options,
                         uint8_t **in_no_face);
/* The note for `count` vertex sources on vertices in no face (the first
 * one: `first`): each reaches only itself. */
void cli_note_sources_in_no_face(const char *sub, int64_t count, int32_t first);

/* ---- getopt_long (util.c) ---- */

/* Long-only option codes (above any char). */
enum {
    OPT_SOURCE = 256, OPT_FACE_SOURCE, OPT_COST, OPT_COST_PER_FACE, OPT_MAX_DISTANCE,
    OPT_NO_UNFOLDING, OPT_EXACT, OPT_TARGET, OPT_TARGET_FACE, OPT_MAX_POINTS, OPT_NO_STRAIGHTEN,
    OPT_JSON, OPT_MAX_UNFOLD_STEPS, OPT_STRETCH, OPT_RADII, OPT_DTYPE, OPT_BACKEND,
    OPT_SOURCES, OPT_THREADS, OPT_MEMORY, OPT_TARGETS, OPT_PLAIN_START, OPT_EXACT_START_RADIUS,
    OPT_NO_SPOKES, OPT_START, OPT_NO_SIZE_CHECK, OPT_MAP, OPT_WELD, OPT_DISTANCES, OPT_METHOD
};
/* Refuses a value option given a second time, which getopt_long would let
 * win silently (`-o a.npy -o b.npy`): call it with every code getopt_long
 * returns; *seen (0 at first) records the value options met. Flags and the
 * repeatable --source/--face-source pass. CLI_OK, or CLI_USAGE with the
 * error printed. */
int cli_once(const char *sub, int c, uint32_t *seen);
/* Prints the usage error for getopt_long's '?' or ':' (opterr is 0; the
 * optstring starts with ':'); returns CLI_USAGE. */
int cli_getopt_error(const char *sub, int c, char **argv);
/* After --face-source F: takes the three weights at argv[optind..] (they
 * may start with '-') and advances optind. 1, or 0 when they are missing or
 * malformed. */
int cli_take_face_point(const char *face, int argc, char **argv, mfmm_source *s);

/* ---- inputs and outputs (util.c) ---- */

/* Bytes free to an unprivileged writer on the file system that holds
 * `path` (the folder of a file to be written): 0, or -1 when unknown. */
int cli_free_bytes(const char *path, double *out);
/* Writes an OBJ file (a comment line, then v and f lines; coordinates
 * with 17 significant digits) through a cli_output. 0, or -1 with the
 * error printed. */
int cli_write_obj(const char *path, const double *V, int32_t nv, const int32_t *F, int32_t nf,
                  const char *comment);
/* A byte count as "3.65 TiB", "812 MiB", ... into buf. */
const char *cli_format_bytes(double bytes, char *buf, size_t size);

/* SIGINT and SIGTERM set a flag (cli_interrupted() reads it) instead of
 * killing the process, so that temporary files get removed; the CLI only,
 * never the library. */
void cli_signals_install(void);
int cli_interrupted(void);
#define CLI_EXIT_INTERRUPTED 130

/* Reads a whole regular file (refusing directories, FIFOs, devices) into a
 * malloc'ed NUL-terminated buffer. 0, or -1 with the error printed. */
int cli_read_file(const char *path, unsigned char **data, size_t *size);

/* Refuses an output that is one of the inputs (NULL entries skipped),
 * compared by device and inode, so a hard link or another spelling of the
 * path is caught. CLI_OK, or CLI_USAGE with the error printed. */
int cli_check_output_not_input(const char *sub, const char *out, const char *const *inputs,
                               int n_inputs);

/* An output file: "-" is standard output (text formats only); otherwise a
 * unique temporary file beside the target, created exclusively (mkstemp:
 * O_EXCL, so a planted symlink is never followed), fsync'ed and renamed
 * over the target by cli_output_close; removed on failure or interrupt. */
typedef struct cli_output {
    FILE *f;
    char *path;     /* final name (NULL for stdout) */
    char *tmp_path; /* the temporary file */
} cli_output;

/* 0, or -1 with the error printed. */
int cli_output_open(cli_output *o, const char *path);
/* Flushes and, for a file, fsyncs, closes and renames (`bad`: a write
 * already failed; an interrupt counts as a failure). 0, or -1 with the error
 * printed and the temporary file removed. */
int cli_output_close(cli_output *o, int bad);
/* Closes and removes the temporary file; safe after a failed open. */
void cli_output_abort(cli_output *o);
/* Writes x as %.17g in the C locale, whatever the locale ("inf" for
 * infinities); fputs's result. */
int cli_put_double(FILE *f, double x);

/* ---- options shared by distance and path (options.c) ---- */

/* The positional mesh, --source I, --face-source F W0 W1 W2, --cost FILE,
 * --cost-per-face, -o/--output OUT and --help/-h; `sub` names the
 * subcommand in messages, `help` prints its help. */
typedef struct cli_sources_and_cost {
    const char *sub;
    void (*help)(FILE *out);
    int help_shown;   /* --help was given: stop with CLI_OK */
    const char *mesh_path;
    const char *out_path;
    const char *cost_path;
    int cost_per_face;
    mfmm_source *src; /* room for one source per argument */
    int32_t n_src;
    mfmm_source *src_in; /* with --weld: the sources as given (src: in the built ids) */
    int weld;         /* --weld */
    double *cost;     /* loaded by cli_sources_and_cost_load */
    double exact_start_radius; /* --exact-start-radius R, --plain-start (0) */
    int start_given;  /* 1: --plain-start, 2: --exact-start-radius (both: an error) */
    mfmm_method method; /* --method fmm|windows (default fmm) */
    int method_given; /* --method was given */
} cli_sources_and_cost;

/* The shared options, for a command's getopt_long table. */
#define CLI_SHARED_LONG_OPTIONS                                                              \
    {"help", no_argument, NULL, 'h'}, {"output", required_argument, NULL, 'o'},             \
        {"source", required_argument, NULL, OPT_SOURCE},                                     \
        {"face-source", required_argument, NULL, OPT_FACE_SOURCE},                           \
        {"cost", required_argument, NULL, OPT_COST},                                         \
        {"cost-per-face", no_argument, NULL, OPT_COST_PER_FACE},                             \
        {"plain-start", no_argument, NULL, OPT_PLAIN_START},                                 \
        {"exact-start-radius", required_argument, NULL, OPT_EXACT_START_RADIUS},            \
        {"weld", no_argument, NULL, OPT_WELD},                                               \
        {"method", required_argument, NULL, OPT_METHOD}
/* The help line of --weld. */
#define CLI_WELD_HELP                                                                        \
    "  --weld                  weld vertices at the same position (texture seams,\n"        \
    "                          unmerged corners) before solving, as `meshfmm weld`\n"       \
    "                          does; ids given and written stay the file's\n"
/* A macro's value as a string literal (help texts quote the library's defaults). */
#define CLI_STR_(x) #x
#define CLI_STR(x) CLI_STR_(x)
/* The help lines of the start options (distance, path); `when` ends the
 * auto radius's rule (path has no --max-distance). */
#define CLI_START_HELP_(when)                                                                \
    "  --exact-start-radius R  start the march from exact distances within R mean\n"        \
    "                          edge lengths of each source (default auto: " CLI_STR(       \
        MFMM_EXACT_START_RADIUS) ", times\n"                                                \
    "                          sqrt(vertices / " CLI_STR(MFMM_EXACT_START_AUTO_VERTICES)    \
    ") above that size" when "\n"                                                          \
    "  --plain-start           the paper's start (as --exact-start-radius 0)\n"
#define CLI_START_HELP CLI_START_HELP_(" without\n                          --max-distance)")
#define CLI_START_HELP_NO_LIMIT CLI_START_HELP_(")")
/* Parses --exact-start-radius's value: CLI_OK, or CLI_USAGE with the error printed. */
int cli_parse_start_radius(const char *sub, const char *arg, double *radius);
/* Records a start option (1: --plain-start, 2: --exact-start-radius) in *given:
 * CLI_OK, or CLI_USAGE with the error printed when the other one was given too. */
int cli_start_option(const char *sub, int which, int *given);
#define CLI_SHARED_SHORT_OPTIONS ":ho:"
/* The help lines of --method (distance, path, voronoi, landmarks; allpairs
 * words its own for its narrower column). */
#define CLI_METHOD_HELP                                                                      \
    "  --method M              fmm (default): Fast Marching; windows: window\n"              \
    "                          propagation keeping two windows per half-edge, never\n"      \
    "                          below the geodesic distance, several times as accurate\n"   \
    "                          and several times the time (the start options do\n"        \
    "                          not apply to it)\n"
/* --method's value: "fmm" or "windows" into *method. CLI_OK, or CLI_USAGE
 * with the error printed. */
int cli_parse_method(const char *sub, const char *arg, mfmm_method *method);
/* The method options together: --exact (exact != 0) with --method
 * (method_given), and --method windows with a cost file, are usage errors.
 * CLI_OK, or CLI_USAGE with the error printed. */
int cli_check_method(const char *sub, mfmm_method method, int method_given, int exact,
                     int has_cost);

/* 0, or -1 with "out of memory" printed. argc: the subcommand's. */
int cli_sources_and_cost_init(cli_sources_and_cost *o, const char *sub, void (*help)(FILE *out),
                              int argc);
void cli_sources_and_cost_free(cli_sources_and_cost *o);
/* Takes getopt_long's result c (a shared option; '?' or ':' are usage
 * errors; anything else is the caller's bug). CLI_OK, or CLI_USAGE with the
 * usage error printed. On --help it prints the help on stdout, sets
 * o->help_shown and returns CLI_OK. */
int cli_sources_and_cost_opt(cli_sources_and_cost *o, int c, int argc, char **argv);
/* The positional arguments left after getopt_long (argv[optind..]): one
 * mesh. CLI_OK or CLI_USAGE (printed). */
int cli_sources_and_cost_positional(cli_sources_and_cost *o, int argc, char **argv);
/* After the argument loop: a mesh and at least one source. CLI_OK or
 * CLI_USAGE (printed). */
int cli_sources_and_cost_check_inputs(const cli_sources_and_cost *o);
/* An output ending in .ext0 or .ext1 (*which: 0 or 1; "-", standard output,
 * gives text_which), no --cost-per-face without --cost, and an output that is
 * not an input. CLI_OK or CLI_USAGE (printed). */
int cli_sources_and_cost_check_output(const cli_sources_and_cost *o, const char *ext0,
                                      const char *ext1, int text_which, int *which);
/* Loads the mesh (welded with --weld; keep_arrays as cli_mesh_load), then
 * --cost FILE (if given) into o->cost, checks its length against the
 * file's vertices or faces, carries it to the built mesh and sets
 * opt->cost and opt->cost_location; then takes the sources to the built
 * mesh's ids (with --weld, o->src_in keeps them as given). hint_per_face:
 * suggest --cost-per-face when a per-vertex cost has one value per face.
 * 0, or -1 with the error printed (m is then empty). */
int cli_sources_and_cost_load(cli_sources_and_cost *o, cli_mesh *m, int keep_arrays,
                              int hint_per_face, mfmm_solve_options *opt);
/* cli_note_sources_in_no_face for o's vertex sources as given (in range:
 * after a solve took them) flagged in m->in_no_face. */
void cli_sources_and_cost_note_in_no_face(const cli_sources_and_cost *o, const cli_mesh *m);
/* Distances from o's sources to every vertex of the built mesh
 * (malloc'ed), or NULL with the error printed. */
double *cli_solve_distances(const mfmm_mesh *mesh, const cli_sources_and_cost *o,
                            const mfmm_solve_options *opt);
/* The same by the exact solver (mfmm_solve_exact) within max_distance;
 * notes on standard error when non-manifold edges became walls. */
double *cli_solve_exact_distances(const mfmm_mesh *mesh, const cli_sources_and_cost *o,
                                  double max_distance);

/* ---- .npy files (format 1.0) ---- */

/* Streaming writer on a cli_output (a temporary file renamed by
 * cli_npy_close; cli_npy_abort removes it). Errors are printed. */
typedef struct cli_npy_writer {
    cli_output out;
    int64_t rows;    /* rows promised in the header */
    int64_t cols;    /* values per row (1 for a 1-D array) */
    int64_t rows_written;
    size_t itemsize; /* 4 or 8 */
} cli_npy_writer;

/* dtype "<f4", "<f8" or "<i4". cols < 0 writes a 1-D array of `rows` values;
 * otherwise shape (rows, cols). 0 on success, -1 on error. */
int cli_npy_open(cli_npy_writer *w, const char *path, const char *dtype, int64_t rows,
                 int64_t cols);
/* Appends n_rows rows (n_rows * cols values of the writer's dtype, host
 * byte order). 0 or -1. */
int cli_npy_append(cli_npy_writer *w, const void *data, int64_t n_rows);
/* Checks that all rows were written, closes and renames. 0 or -1; on -1 the
 * temporary file is removed. */
int cli_npy_close(cli_npy_writer *w);
/* Closes and removes the temporary file; safe after a failed open. */
void cli_npy_abort(cli_npy_writer *w);
/* Writes a vector of n values (int32, or double when is_double) to path:
 * a one-dimensional .npy ("<i4" / "<f8") when npy, else text, one value a
 * line (doubles as cli_put_double). 0, or -1 with the error printed and no
 * file left (an interrupt counts as a failure). */
int cli_write_vector(const char *path, int npy, const void *values, int32_t n, int is_double);

/* ---- .npz files: a scipy.sparse CSR matrix (npz.c) ---- */

/* Streaming writer: rows go to unlinked temporary files beside the output,
 * the zip (scipy.sparse.save_npz's members, zip64, stored) is written by
 * cli_npz_close through a cli_output. Errors are printed. */
typedef struct cli_npz_writer {
    char *path;
    FILE *data, *indices; /* values and column ids so far */
    int64_t *indptr;      /* rows + 1 row pointers */
    int64_t rows, cols, rows_written, nnz;
    size_t itemsize;      /* 4 or 8 */
} cli_npz_writer;

/* f64: float64 values, else float32. 0 or -1. */
int cli_npz_open(cli_npz_writer *w, const char *path, int f64, int64_t rows, int64_t cols);
/* Appends a CSR block of n_rows rows (indptr from 0, as the library gives). */
int cli_npz_append(cli_npz_writer *w, int32_t n_rows, const int64_t *indptr,
                   const int32_t *indices, const void *values);
/* Writes the .npz (temporary, then renamed) and frees the writer. 0 or -1. */
int cli_npz_close(cli_npz_writer *w);
/* Frees the writer; the temporary files vanish (they are unlinked). */
void cli_npz_abort(cli_npz_writer *w);

/* Readers of regular files (refusing FIFOs, devices, directories), over
 * in-memory parsers that the fuzzers call. `name` labels messages. */

/* A 1-D float64 or float32 .npy array (a 2-D one with a dimension of 1
 * too) as doubles (malloc'ed). 0 on success, -1 with the error printed. */
int cli_npy_read_vector(const char *path, double **values, int64_t *n);
int cli_npy_parse_vector(const unsigned char *data, size_t size, const char *name,
                         double **values, int64_t *n);

/* A 1-D integer .npy array (i1..i8, u1..u8, either byte order) as int32
 * ids (malloc'ed); other shapes are refused. 0 on success, 1 when the file
 * holds a float dtype (nothing printed: the caller may try
 * cli_npy_read_vector), -1 with the error printed (a value outside int32:
 * "source I is out of range"). */
int cli_npy_read_ints(const char *path, int32_t **ids, int64_t *n);
int cli_npy_parse_ints(const unsigned char *data, size_t size, const char *name, int32_t **ids,
                       int64_t *n);

/* Vertex ids from a file: .npy (a 1-D integer array, or floats that are
 * whole numbers) or text (numbers separated by blanks, newlines or commas).
 * 0 with *ids malloc'ed (*n may be 0), or -1 with the error printed. */
int cli_read_ids(const char *path, int32_t **ids, int64_t *n);

/* Numbers separated by blanks, newlines or commas ('#' comments), read
 * without the locale. data[size] must be '\0'. */
int cli_txt_read_vector(const char *path, double **values, int64_t *n);
int cli_txt_parse_vector(const char *data, size_t size, const char *name, double **values,
                         int64_t *n);

#endif /* MFMM_CLI_H */
