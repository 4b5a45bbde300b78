/* meshfmm: command-line front end. Subcommands are listed in one table. */
#include <stdio.h>
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
    {"path", cmd_path, "the minimal geodesic from the nearest source to a target"},
    {"landmarks", cmd_landmarks, "geodesic farthest-point sampling: K well-spread vertex ids"},
    {"voronoi", cmd_voronoi, "geodesic Voronoi labels: which source each vertex is nearest"},
    {"weld", cmd_weld, "weld vertices at the same position (seams) and write the mesh"},
};

/* Commands of the Python package's `meshfmm` (python -m meshfmm), listed in
 * the help and named when given here: they draw on numpy (and matplotlib). */
static const cli_command python_commands[] = {
    {"render", NULL, "a PNG of a distance field with isolines and paths (matplotlib)"},
    {"isolines", NULL, "isolines of a distance field as polylines (.obj or .csv)"},
};

static void print_usage(FILE *out)
{
    fprintf(out, "usage: meshfmm COMMAND [ARGS]   (meshfmm COMMAND --help for details)\n\n"
                 "Geodesic distances on triangle meshes by the Fast Marching Method.\n\n"
                 "commands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        fprintf(out, "  %-10s %s\n", commands[i].name, commands[i].summary);
    fprintf(out, "\npython commands (python -m meshfmm COMMAND --help for details):\n");
    for (size_t i = 0; i < sizeof python_commands / sizeof python_commands[0]; i++)
        fprintf(out, "  %-10s %s\n", python_commands[i].name, python_commands[i].summary);
    fprintf(out, "\nThe python commands run through the Python package: `python -m meshfmm`,\n"
                 "or the meshfmm command that pip installs (which runs every command above\n"
                 "too); this program alone does not run them.\n");
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
    for (size_t i = 0; i < sizeof python_commands / sizeof python_commands[0]; i++)
        if (strcmp(argv[1], python_commands[i].name) == 0) {
            cli_error("'%s' is a command of the Python package: run python -m meshfmm %s "
                      "(or the meshfmm command that pip installs)", argv[1], argv[1]);
            return CLI_USAGE;
        }
    cli_error("unknown command '%s' (try meshfmm --help)", argv[1]);
    return CLI_USAGE;
}
