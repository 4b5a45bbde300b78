/* meshfmm weld MESH -o OUT.obj [--map MAP.txt|.npy] */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static void help(FILE *out)
{
    fprintf(out,
            "usage: meshfmm weld MESH -o OUT.obj [--map MAP]\n\n"
            "Welds the vertices of MESH that lie at exactly the same position (texture\n"
            "seams, unmerged corners: `meshfmm info` counts them) into one and writes\n"
            "the welded mesh as OBJ. Welded vertices are numbered by their first\n"
            "occurrence, in input order (as Python's Mesh(V, F, weld=True)); faces keep\n"
            "their order and corner order, and a face two of whose corners weld\n"
            "together (zero area) is dropped. Prints the counts on standard error.\n\n"
            "  -o, --output OUT.obj    the welded mesh (- for standard output)\n"
            "  --map MAP               the welded id of each input vertex: .txt (one per\n"
            "                          line) or .npy (int32), to carry ids across\n"
            "  -h, --help              this text\n\n"
            "Outputs are written to a temporary file beside them and renamed when\n"
            "complete; they may not be the mesh.\n");
}

int cmd_weld(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"help", no_argument, NULL, 'h'},
        {"output", required_argument, NULL, 'o'},
        {"map", required_argument, NULL, OPT_MAP},
        {NULL, 0, NULL, 0}};
    const char *mesh_path = NULL, *out_path = NULL, *map_path = NULL;
    int c, rc;
    opterr = 0;
    uint32_t seen = 0;
    while ((c = getopt_long(argc, argv, ":ho:", longopts, NULL)) != -1) {
        if ((rc = cli_once("weld", c, &seen)) != CLI_OK)
            return rc;
        if (c == 'h') {
            help(stdout);
            return CLI_OK;
        } else if (c == 'o') {
            out_path = optarg;
        } else if (c == OPT_MAP) {
            map_path = optarg;
        } else {
            return cli_getopt_error("weld", c, argv);
        }
    }
    for (int i = optind; i < argc; i++) {
        if (mesh_path)
            return cli_usage_error("weld", "one mesh at a time ('%s' is extra)", argv[i]);
        mesh_path = argv[i];
    }
    if (!mesh_path)
        return cli_usage_error("weld", "no mesh file given");
    if (!out_path || (!cli_has_ext(out_path, "obj") && strcmp(out_path, "-") != 0))
        return cli_usage_error("weld", "-o OUT.obj is required");
    if (map_path && !cli_has_ext(map_path, "txt") && !cli_has_ext(map_path, "npy"))
        return cli_usage_error("weld", "--map must end in .txt or .npy");
    if (map_path && strcmp(map_path, "-") == 0)
        return cli_usage_error("weld", "--map needs a file");
    const char *inputs[1] = {mesh_path};
    if ((rc = cli_check_output_not_input("weld", out_path, inputs, 1)) != CLI_OK ||
        (map_path && (rc = cli_check_output_not_input("weld", map_path, inputs, 1)) != CLI_OK))
        return rc;
    cli_signals_install();

    rc = CLI_FAIL;
    double *V = NULL, *W = NULL;
    int32_t *F = NULL, *map = NULL, nv = 0, nf = 0;
    mfmm_error err;
    if (mfmm_load_mesh(mesh_path, &V, &nv, &F, &nf, &err) != MFMM_OK) {
        cli_error("%s", err.message);
        goto done;
    }
    map = malloc((size_t)nv * sizeof *map);
    W = malloc(3 * (size_t)nv * sizeof *W);
    int32_t nw = 0, kept = 0;
    if (!map || !W || cli_weld(V, nv, F, nf, map, W, NULL, &nw, &kept)) {
        cli_error("out of memory");
        goto done;
    }
    char comment[160];
    snprintf(comment, sizeof comment, "meshfmm weld: %ld vertices welded into %ld, %ld faces "
             "(%ld dropped)", (long)nv, (long)nw, (long)kept, (long)(nf - kept));
    if (cli_write_obj(out_path, W, nw, F, kept, comment))
        goto done;
    if (map_path && cli_write_vector(map_path, cli_has_ext(map_path, "npy"), map, nv, 0))
        goto done;
    fprintf(stderr, "meshfmm weld: %ld vertices, %ld once welded (%ld removed); %ld faces, "
            "%ld dropped (zero area once welded)\n", (long)nv, (long)nw, (long)(nv - nw),
            (long)nf, (long)(nf - kept));
    rc = CLI_OK;
done:
    if (rc != CLI_OK && cli_interrupted()) {
        fprintf(stderr, "meshfmm weld: interrupted; no output written\n");
        rc = CLI_EXIT_INTERRUPTED;
    }
    mfmm_free(V);
    mfmm_free(F);
    free(W);
    free(map);
    return rc;
}
