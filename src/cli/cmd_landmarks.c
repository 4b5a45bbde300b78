/* meshfmm landmarks MESH -k K [--start V] -o OUT (.txt or .npy) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static void help(FILE *out)
{
    fprintf(out,
            "usage: meshfmm landmarks MESH -k K [--start V] [--no-unfolding]\n"
            "                         [--exact-start-radius R | --plain-start]\n"
            "                         [--method fmm|windows] [--weld] -o OUT\n\n"
            "Geodesic farthest-point sampling (mfmm_farthest_points): K vertex ids of MESH,\n"
            "the first V, each next the vertex farthest from those chosen (ties to the\n"
            "lowest id). One march per point, each stopped at the farthest distance so\n"
            "far. Prints the covering radius (the largest distance from a vertex to its\n"
            "nearest landmark) on standard error. The ids feed\n"
            "`meshfmm allpairs MESH --sources OUT --targets OUT` (the landmarks' S x S\n"
            "matrix) or --sources OUT alone (S x N).\n\n"
            "  -k, --count K           landmarks to choose, 1 <= K <= the vertices in faces\n"
            "  --start V               the first landmark, a vertex id (default 0)\n"
            "  --no-unfolding          plain stencils at obtuse corners (for comparison)\n"
            CLI_START_HELP_NO_LIMIT
            CLI_METHOD_HELP
            "  --weld                  weld vertices at the same position (texture seams,\n"
            "                          unmerged corners) first, as `meshfmm weld` does; the\n"
            "                          start and the landmarks are the file's ids (of\n"
            "                          coincident vertices, the lowest)\n"
            "  -o, --output OUT        .txt (one id per line; - for standard output) or\n"
            "                          .npy (int32, shape (K,))\n"
            "  -h, --help              this text\n\n"
            "The output is written to a temporary file beside OUT and renamed when\n"
            "complete; it may not be the mesh.\n");
}

int cmd_landmarks(int argc, char **argv)
{
    static const struct option longopts[] = {
        {"help", no_argument, NULL, 'h'},
        {"output", required_argument, NULL, 'o'},
        {"count", required_argument, NULL, 'k'},
        {"start", required_argument, NULL, OPT_START},
        {"no-unfolding", no_argument, NULL, OPT_NO_UNFOLDING},
        {"plain-start", no_argument, NULL, OPT_PLAIN_START},
        {"exact-start-radius", required_argument, NULL, OPT_EXACT_START_RADIUS},
        {"weld", no_argument, NULL, OPT_WELD},
        {"method", required_argument, NULL, OPT_METHOD},
        {NULL, 0, NULL, 0}};
    const char *mesh_path = NULL, *out_path = NULL;
    int32_t k = -1, start = 0;
    int start_given = 0, weld = 0;
    mfmm_solve_options opt;
    mfmm_solve_options_init(&opt);
    int c, rc;
    opterr = 0;
    uint32_t seen = 0;
    while ((c = getopt_long(argc, argv, ":hk:o:", longopts, NULL)) != -1) {
        if ((rc = cli_once("landmarks", c, &seen)) != CLI_OK)
            return rc;
        if (c == 'h') {
            help(stdout);
            return CLI_OK;
        } else if (c == 'o') {
            out_path = optarg;
        } else if (c == 'k') {
            if (!cli_parse_int32(optarg, &k) || k < 1)
                return cli_usage_error("landmarks", "-k needs an integer >= 1");
        } else if (c == OPT_START) {
            if (!cli_parse_int32(optarg, &start) || start < 0)
                return cli_usage_error("landmarks", "--start needs a vertex id >= 0");
        } else if (c == OPT_NO_UNFOLDING) {
            opt.unfolding = 0;
        } else if (c == OPT_WELD) {
            weld = 1;
        } else if (c == OPT_METHOD) {
            if ((rc = cli_parse_method("landmarks", optarg, &opt.method)) != CLI_OK)
                return rc;
        } else if (c == OPT_PLAIN_START) {
            if ((rc = cli_start_option("landmarks", 1, &start_given)) != CLI_OK)
                return rc;
            opt.exact_start_radius = 0.0;
        } else if (c == OPT_EXACT_START_RADIUS) {
            if ((rc = cli_start_option("landmarks", 2, &start_given)) != CLI_OK ||
                (rc = cli_parse_start_radius("landmarks", optarg, &opt.exact_start_radius)) !=
                    CLI_OK)
                return rc;
        } else {
            return cli_getopt_error("landmarks", c, argv);
        }
    }
    for (int i = optind; i < argc; i++) {
        if (mesh_path)
            return cli_usage_error("landmarks", "one mesh at a time ('%s' is extra)", argv[i]);
        mesh_path = argv[i];
    }
    if (!mesh_path)
        return cli_usage_error("landmarks", "no mesh file given");
    if (k < 1)
        return cli_usage_error("landmarks", "-k K is required");
    if (!out_path)
        return cli_usage_error("landmarks", "-o OUT is required (.txt or .npy)");
    int is_npy = cli_has_ext(out_path, "npy");
    if (!is_npy && !cli_has_ext(out_path, "txt") && strcmp(out_path, "-") != 0)
        return cli_usage_error("landmarks", "the output must end in .txt or .npy");
    const char *inputs[1] = {mesh_path};
    if ((rc = cli_check_output_not_input("landmarks", out_path, inputs, 1)) != CLI_OK)
        return rc;
    cli_signals_install();

    rc = CLI_FAIL;
    cli_mesh m;
    mfmm_solver *solver = NULL;
    int32_t *pts = NULL;
    double *dist = NULL;
    if (cli_mesh_load(&m, mesh_path, NULL, weld, 0))
        return CLI_FAIL;
    int32_t nv = m.nv;
    pts = malloc((size_t)k * sizeof *pts);
    dist = malloc((size_t)nv * sizeof *dist + 1);
    if (!pts || !dist) {
        cli_error("out of memory");
        goto done;
    }
    if (cli_mesh_vertex(&m, "start", &start))
        goto done;
    mfmm_status st = mfmm_solver_create(m.mesh, &solver);
    if (st != MFMM_OK) {
        cli_error("%s", mfmm_status_string(st));
        goto done;
    }
    mfmm_error err;
    st = mfmm_farthest_points(solver, start, k, &opt, pts, NULL, dist, &err);
    if (st != MFMM_OK) {
        cli_error("%s: %s", mesh_path, err.message);
        goto done;
    }
    for (int32_t i = 0; i < k; i++)
        pts[i] = cli_mesh_input_vertex(&m, pts[i]);
    dist = cli_mesh_per_input_vertex(&m, dist, sizeof *dist);
    if (!dist)
        goto done;
    double cover = 0.0;
    int32_t unreached = 0;
    for (int32_t v = 0; v < m.nv_in; v++) {
        if (isfinite(dist[v]))
            cover = fmax(cover, dist[v]);
        else
            unreached++;
    }
    if (cli_write_vector(out_path, is_npy, pts, k, 0))
        goto done;
    fprintf(stderr, "meshfmm landmarks: %ld landmarks; every vertex within %.6g of one", (long)k,
            cover);
    if (unreached)
        fprintf(stderr, " (%ld vertices unreached: in no face or in a component without one)",
                (long)unreached);
    fputc('\n', stderr);
    rc = CLI_OK;
done:
    if (rc != CLI_OK && cli_interrupted()) {
        fprintf(stderr, "meshfmm landmarks: interrupted; no output written\n");
        rc = CLI_EXIT_INTERRUPTED;
    }
    mfmm_solver_destroy(solver);
    cli_mesh_free(&m);
    free(pts);
    free(dist);
    return rc;
}
