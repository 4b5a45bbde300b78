/* meshfmm: command-line front end. Subcommands are listed in one table. */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

typedef struct cli_command {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
} cli_command;

/* Add a subcommand with one line here (and its declaration in cli.h). */
static const cli_command commands[] = {
    {"info", cmd_info, "print a mesh's counts, boundary, components and defects"},
    {"distance", cmd_distance, "geodesic distances from sources to every vertex"},
    {"generate", cmd_generate, "write a generated mesh (sine, sphere, torus, grid, lattice)"},
    {"allpairs", cmd_allpairs, "the distance matrix of many sources, streamed into a .npy file"},
    {"path", cmd_path, "the minimal geodesic from a target to the sources (.csv or .obj)"},
};

static void print_usage(FILE *out)
{
    fprintf(out, "usage: meshfmm COMMAND [ARGS]   (meshfmm COMMAND --help for details)\n\n"
                 "Geodesic distances on triangle meshes by the Fast Marching Method.\n\n"
                 "commands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        fprintf(out, "  %-10s %s\n", commands[i].name, commands[i].summary);
    fprintf(out, "\noptions:\n  --help     this text\n  --version  the library version\n");
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        cli_error("no command given");
        print_usage(stderr);
        return CLI_USAGE;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 ||
        strcmp(argv[1], "help") == 0) {
        print_usage(stdout);
        return CLI_OK;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("meshfmm %s\n", mfmm_version());
        return CLI_OK;
    }
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (strcmp(argv[1], commands[i].name) == 0)
            return commands[i].run(argc - 1, argv + 1);
    cli_error("unknown command '%s' (try meshfmm --help)", argv[1]);
    return CLI_USAGE;
}

/* ---- shared helpers ---- */

void cli_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("meshfmm: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

int cli_usage_error(const char *sub, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "meshfmm %s: ", sub);
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, " (try meshfmm %s --help)\n", sub);
    va_end(ap);
    return CLI_USAGE;
}

int cli_parse_int32(const char *s, int32_t *out)
{
    char *end;
    if (!s || !*s)
        return 0;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (errno || *end || v < INT32_MIN || v > INT32_MAX)
        return 0;
    *out = (int32_t)v;
    return 1;
}

int cli_parse_double(const char *s, double *out)
{
    char *end;
    if (!s || !*s)
        return 0;
    errno = 0;
    double v = strtod(s, &end);
    if (*end || isnan(v) || (errno == ERANGE && isinf(v)))
        return 0;
    *out = v;
    return 1;
}

int cli_has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), m = strlen(ext);
    if (n < m + 1 || path[n - m - 1] != '.')
        return 0;
    for (size_t i = 0; i < m; i++) {
        char c = path[n - m + i];
        if (c >= 'A' && c <= 'Z')
            c = (char)(c - 'A' + 'a');
        if (c != ext[i])
            return 0;
    }
    return 1;
}

FILE *cli_partial_open(const char *path, char **tmp)
{
    size_t len = strlen(path);
    *tmp = malloc(len + 9);
    if (!*tmp) {
        cli_error("out of memory");
        return NULL;
    }
    memcpy(*tmp, path, len);
    memcpy(*tmp + len, ".partial", 9);
    FILE *f = fopen(*tmp, "w");
    if (!f) {
        cli_error("cannot create '%s': %s", *tmp, strerror(errno));
        free(*tmp);
        *tmp = NULL;
    }
    return f;
}

int cli_partial_close(FILE *f, char *tmp, const char *path, int bad)
{
    bad |= fflush(f) != 0 || ferror(f);
    bad |= fclose(f) != 0;
    if (bad || rename(tmp, path) != 0) {
        cli_error("cannot write '%s': %s", path, strerror(errno));
        remove(tmp);
        free(tmp);
        return -1;
    }
    free(tmp);
    return 0;
}

mfmm_mesh *cli_load_mesh(const char *path, const mfmm_mesh_options *options)
{
    double *V = NULL;
    int32_t *F = NULL, nv = 0, nf = 0;
    mfmm_error err;
    mfmm_status st = mfmm_load_mesh(path, &V, &nv, &F, &nf, &err);
    if (st != MFMM_OK) {
        cli_error("%s", err.message);
        return NULL;
    }
    mfmm_mesh *mesh = NULL;
    st = mfmm_mesh_create(V, nv, F, nf, options, &mesh, &err);
    mfmm_free(V);
    mfmm_free(F);
    if (st != MFMM_OK) {
        cli_error("%s: %s", path, err.message);
        return NULL;
    }
    return mesh;
}
