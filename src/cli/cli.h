/* The meshfmm command line: shared declarations. Each subcommand is a
 * function `int cmd_NAME(int argc, char **argv)` (argv[0] is the
 * subcommand's name) returning an exit status, listed in main.c's table. */
#ifndef MFMM_CLI_H
#define MFMM_CLI_H

#include <stdint.h>
#include <stdio.h>

#include "meshfmm.h"

enum { CLI_OK = 0, CLI_FAIL = 1, CLI_USAGE = 2 };

int cmd_info(int argc, char **argv);
int cmd_distance(int argc, char **argv);
int cmd_generate(int argc, char **argv);
int cmd_allpairs(int argc, char **argv);
int cmd_path(int argc, char **argv);

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

/* Loads a mesh file and builds an mfmm_mesh; prints the error and returns
 * NULL on failure. */
mfmm_mesh *cli_load_mesh(const char *path, const mfmm_mesh_options *options);

/* ---- options shared by distance and path (options.c) ---- */

/* One point argument at argv[i] (the option itself): --source-like "I" or
 * --face-source-like "F W0 W1 W2". 1 with *s filled, 0 when malformed. */
int cli_parse_vertex_point(int argc, char **argv, int i, mfmm_source *s);
int cli_parse_face_point(int argc, char **argv, int i, mfmm_source *s);

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
    double *cost;     /* loaded by cli_sources_and_cost_load */
} cli_sources_and_cost;

/* 0, or -1 with "out of memory" printed. argc: the subcommand's. */
int cli_sources_and_cost_init(cli_sources_and_cost *o, const char *sub, void (*help)(FILE *out),
                              int argc);
void cli_sources_and_cost_free(cli_sources_and_cost *o);
/* Takes argv[*i] (a shared option, with its values, or the mesh) and
 * advances *i past its values; anything else starting with '-' is an unknown
 * option. CLI_OK, or CLI_USAGE with the usage error printed. On --help it
 * prints the help on stdout, sets o->help_shown and returns CLI_OK. */
int cli_sources_and_cost_arg(cli_sources_and_cost *o, int argc, char **argv, int *i);
/* After the argument loop: a mesh and at least one source. CLI_OK or
 * CLI_USAGE (printed). */
int cli_sources_and_cost_check_inputs(const cli_sources_and_cost *o);
/* An output ending in .ext0 or .ext1 (*which: 0 or 1) and no --cost-per-face
 * without --cost. CLI_OK or CLI_USAGE (printed). */
int cli_sources_and_cost_check_output(const cli_sources_and_cost *o, const char *ext0,
                                      const char *ext1, int *which);
/* Loads --cost FILE (if given) into o->cost, checks its length against the
 * mesh and sets opt->cost and opt->cost_location. hint_per_face: suggest
 * --cost-per-face when a per-vertex cost has one value per face. 0, or -1
 * with the error printed. */
int cli_sources_and_cost_load(cli_sources_and_cost *o, const mfmm_mesh *mesh,
                              int hint_per_face, mfmm_solve_options *opt);
/* Distances from o's sources to every vertex (malloc'ed), or NULL with the
 * error printed. */
double *cli_solve_distances(const mfmm_mesh *mesh, const cli_sources_and_cost *o,
                            const mfmm_solve_options *opt);

/* Text output written as "PATH.partial" and renamed to PATH once complete,
 * so a failed write leaves nothing under PATH. cli_partial_open returns the
 * stream and the temporary name (*tmp, malloc'ed), or NULL with the error
 * printed. cli_partial_close flushes, closes and renames (`bad`: a write
 * already failed), removes the temporary file on failure and frees tmp;
 * 0 or -1 (printed). */
FILE *cli_partial_open(const char *path, char **tmp);
int cli_partial_close(FILE *f, char *tmp, const char *path, int bad);

/* ---- .npy files (format 1.0) ---- */

/* Streaming writer: data goes to "PATH.partial", renamed to PATH by
 * cli_npy_close; cli_npy_abort removes the temporary file. Errors are
 * printed (cli_error). */
typedef struct cli_npy_writer {
    FILE *f;
    char *path;      /* final name */
    char *tmp_path;  /* PATH.partial */
    int64_t rows;    /* rows promised in the header */
    int64_t cols;    /* values per row (1 for a 1-D array) */
    int64_t rows_written;
    size_t itemsize; /* 4 or 8 */
} cli_npy_writer;

/* dtype "<f4" or "<f8". cols < 0 writes a 1-D array of `rows` values;
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

/* Reads a 1-D float64 or float32 .npy array (a 2-D one with a dimension of
 * 1 too) as doubles (malloc'ed). 0 on success, -1 with the error printed. */
int cli_npy_read_vector(const char *path, double **values, int64_t *n);

/* Reads a 1-D integer .npy array (i1..i8, u1..u8, either byte order; a 2-D
 * one with a dimension of 1 too) as int32 ids (malloc'ed). 0 on success, 1
 * when the file holds another dtype (nothing printed: the caller may try
 * cli_npy_read_vector), -1 with the error printed (a value outside int32:
 * "source I is out of range"). */
int cli_npy_read_ints(const char *path, int32_t **ids, int64_t *n);

/* Reads whitespace-separated numbers from a text file ('#' comments). */
int cli_txt_read_vector(const char *path, double **values, int64_t *n);

#endif /* MFMM_CLI_H */
