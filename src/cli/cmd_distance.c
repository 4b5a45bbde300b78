/* meshfmm distance MESH --source I [...] -o OUT (.npy or .txt) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static void help(FILE *out)
{
    fprintf(out,
            "usage: meshfmm distance MESH --source I [--source J ...]\n"
            "                        [--face-source F W0 W1 W2 ...] [--max-distance X]\n"
            "                        [--no-unfolding] [--cost FILE [--cost-per-face]]\n"
            "                        [--exact-start-radius R | --plain-start]\n"
            "                        [--method fmm|windows | --exact] [--weld] -o OUT\n\n"
            "Geodesic distance (Fast Marching) from the sources to every vertex of MESH.\n\n"
            "  --source I              a vertex source (0-based id); repeatable\n"
            "  --face-source F W0 W1 W2  a point in face F with barycentric coordinates\n"
            "  --max-distance X        stop past X; farther vertices get inf\n"
            "  --no-unfolding          plain stencils at obtuse corners (for comparison)\n"
            CLI_START_HELP
            CLI_METHOD_HELP
            "  --exact                 exact polyhedral geodesic distance (window\n"
            "                          propagation) instead of Fast Marching; no --cost\n"
            CLI_WELD_HELP
            "  --cost FILE             slowness F (.npy float64/float32 or .txt), one value\n"
            "                          per vertex (default) or per face (--cost-per-face)\n"
            "  -o, --output OUT        .npy (float64, shape (nv,)) or .txt (one value per\n"
            "                          line, %%.17g, inf for unreached vertices); - writes\n"
            "                          the text to standard output\n"
            "  -h, --help              this text\n\n"
            "Options take their value as --source 3 or --source=3. The output is written\n"
            "to a temporary file beside OUT and renamed when complete; it may not be one\n"
            "of the inputs.\n");
}

int cmd_distance(int argc, char **argv)
{
    static const struct option longopts[] = {
        CLI_SHARED_LONG_OPTIONS,
        {"max-distance", required_argument, NULL, OPT_MAX_DISTANCE},
        {"no-unfolding", no_argument, NULL, OPT_NO_UNFOLDING},
        {"exact", no_argument, NULL, OPT_EXACT},
        {NULL, 0, NULL, 0}};
    int exact = 0;
    int rc = CLI_FAIL;
    mfmm_solve_options opt;
    mfmm_solve_options_init(&opt);
    cli_sources_and_cost o;
    double *dist = NULL;
    cli_mesh m = {0};
    if (cli_sources_and_cost_init(&o, "distance", help, argc))
        return CLI_FAIL;
    int c;
    opterr = 0;
    uint32_t seen = 0;
    while ((c = getopt_long(argc, argv, CLI_SHARED_SHORT_OPTIONS, longopts, NULL)) != -1) {
        if ((rc = cli_once("distance", c, &seen)) != CLI_OK)
            goto done;
        if (c == OPT_MAX_DISTANCE) {
            if (!cli_parse_double(optarg, &opt.max_distance) || !(opt.max_distance >= 0)) {
                rc = cli_usage_error("distance", "--max-distance needs a number >= 0");
                goto done;
            }
        } else if (c == OPT_NO_UNFOLDING) {
            opt.unfolding = 0;
        } else if (c == OPT_EXACT) {
            exact = 1;
        } else if ((rc = cli_sources_and_cost_opt(&o, c, argc, argv)) != CLI_OK || o.help_shown) {
            goto done;
        }
    }
    if ((rc = cli_check_method("distance", o.method, o.method_given, exact,
                               o.cost_path != NULL)) != CLI_OK)
        goto done;
    if (exact && (o.cost_path || !opt.unfolding || o.start_given)) {
        rc = cli_usage_error("distance", "--exact computes geodesic distance: it takes no "
                                         "--cost, --no-unfolding, --plain-start or "
                                         "--exact-start-radius");
        goto done;
    }
    int is_txt;
    if ((rc = cli_sources_and_cost_positional(&o, argc, argv)) != CLI_OK ||
        (rc = cli_sources_and_cost_check_inputs(&o)) != CLI_OK ||
        (rc = cli_sources_and_cost_check_output(&o, "npy", "txt", 1, &is_txt)) != CLI_OK)
        goto done;
    rc = CLI_FAIL;
    cli_signals_install();

    if (cli_sources_and_cost_load(&o, &m, 0, 1, &opt))
        goto done;
    int32_t nv = m.nv_in;
    dist = exact ? cli_solve_exact_distances(m.mesh, &o, opt.max_distance)
                 : cli_solve_distances(m.mesh, &o, &opt);
    if (dist)
        dist = cli_mesh_per_input_vertex(&m, dist, sizeof *dist);
    if (!dist || cli_interrupted())
        goto done;
    cli_sources_and_cost_note_in_no_face(&o, &m);
    if (cli_write_vector(o.out_path, !is_txt, dist, nv, 1))
        goto done;
    rc = CLI_OK;
done:
    if (rc != CLI_OK && cli_interrupted()) {
        fprintf(stderr, "meshfmm distance: interrupted; no output written\n");
        rc = CLI_EXIT_INTERRUPTED;
    }
    cli_mesh_free(&m);
    free(dist);
    cli_sources_and_cost_free(&o);
    return rc;
}
