/* meshfmm voronoi MESH --source I ... | --sources FILE -o LABELS (.npy or
 * .txt) [--distances OUT]: geodesic Voronoi labels, which source each
 * vertex's distance comes from (mfmm_voronoi_labels after one solve). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static void help(FILE *out)
{
    fprintf(out,
            "usage: meshfmm voronoi MESH (--source I ... | --face-source F W0 W1 W2 ... |\n"
            "                       --sources FILE) [--max-distance X] [--no-unfolding]\n"
            "                       [--cost FILE [--cost-per-face]]\n"
            "                       [--exact-start-radius R | --plain-start]\n"
            "                       [--method fmm|windows | --exact] [--weld]\n"
            "                       [--distances OUT] -o OUT\n\n"
            "Geodesic Voronoi labels: one solve from all the sources, then one pass over\n"
            "the vertices' edges (mfmm_voronoi_labels) telling which source each vertex's\n"
            "distance comes from. Labels index the sources in the order given (--source\n"
            "and --face-source first, in command-line order, then the ids of --sources);\n"
            "-1 marks a vertex no source reaches. Inside a cell the label is the nearest\n"
            "source; within about an edge of a cell's border, where two sources'\n"
            "distances differ by less than the march's error, either may be given.\n"
            "Prints the count of cells and of unreached vertices on standard error.\n\n"
            "  --source I              a vertex source (0-based id); repeatable\n"
            "  --face-source F W0 W1 W2  a point in face F with barycentric coordinates\n"
            "  --sources FILE          vertex sources from a file: .txt (ids separated by\n"
            "                          blanks or newlines, as `meshfmm landmarks` writes)\n"
            "                          or .npy (1-D integer array)\n"
            "  --max-distance X        stop past X; farther vertices get the label -1\n"
            "  --no-unfolding          plain stencils at obtuse corners (for comparison)\n"
            CLI_START_HELP
            CLI_METHOD_HELP
            "  --exact                 exact polyhedral distances (as distance --exact); no\n"
            "                          --cost\n"
            "  --cost FILE             slowness F (.npy float64/float32 or .txt), one value\n"
            "                          per vertex (default) or per face (--cost-per-face)\n"
            CLI_WELD_HELP
            "  --distances OUT         also write the distances the labels come from:\n"
            "                          .npy (float64) or .txt (%%.17g, inf when unreached)\n"
            "  -o, --output OUT        the labels: .npy (int32, shape (nv,)) or .txt (one\n"
            "                          per line); - writes the text to standard output\n"
            "  -h, --help              this text\n\n"
            "Outputs are written to a temporary file beside them and renamed when\n"
            "complete; they may not be inputs.\n");
}

/* values: n int32 (labels) or doubles, as .npy or one per line. */
/* Appends the ids of --sources FILE to o's sources. 0, or -1 (printed). */
static int add_file_sources(cli_sources_and_cost *o, const char *path)
{
    int32_t *ids = NULL;
    int64_t n = 0;
    if (cli_read_ids(path, &ids, &n))
        return -1;
    if (n == 0 || n > INT32_MAX - o->n_src) {
        cli_error("%s: %s", path, n ? "too many sources" : "no sources");
        free(ids);
        return -1;
    }
    mfmm_source *src = realloc(o->src, ((size_t)o->n_src + (size_t)n) * sizeof *src);
    if (!src) {
        cli_error("out of memory");
        free(ids);
        return -1;
    }
    o->src = src;
    for (int64_t i = 0; i < n; i++) {
        mfmm_source x = {ids[i], -1, {0, 0, 0}, 0.0};
        o->src[o->n_src++] = x;
    }
    free(ids);
    return 0;
}

int cmd_voronoi(int argc, char **argv)
{
    static const struct option longopts[] = {
        CLI_SHARED_LONG_OPTIONS,
        {"sources", required_argument, NULL, OPT_SOURCES},
        {"max-distance", required_argument, NULL, OPT_MAX_DISTANCE},
        {"no-unfolding", no_argument, NULL, OPT_NO_UNFOLDING},
        {"exact", no_argument, NULL, OPT_EXACT},
        {"distances", required_argument, NULL, OPT_DISTANCES},
        {NULL, 0, NULL, 0}};
    int exact = 0, rc = CLI_FAIL;
    const char *sources_path = NULL, *dist_path = NULL;
    mfmm_solve_options opt;
    mfmm_solve_options_init(&opt);
    cli_sources_and_cost o;
    double *dist = NULL;
    int32_t *labels = NULL;
    cli_mesh m = {0};
    if (cli_sources_and_cost_init(&o, "voronoi", help, argc))
        return CLI_FAIL;
    int c;
    opterr = 0;
    uint32_t seen = 0;
    while ((c = getopt_long(argc, argv, CLI_SHARED_SHORT_OPTIONS, longopts, NULL)) != -1) {
        if ((rc = cli_once("voronoi", c, &seen)) != CLI_OK)
            goto done;
        if (c == OPT_MAX_DISTANCE) {
            if (!cli_parse_double(optarg, &opt.max_distance) || !(opt.max_distance >= 0)) {
                rc = cli_usage_error("voronoi", "--max-distance needs a number >= 0");
                goto done;
            }
        } else if (c == OPT_NO_UNFOLDING) {
            opt.unfolding = 0;
        } else if (c == OPT_EXACT) {
            exact = 1;
        } else if (c == OPT_SOURCES) {
            sources_path = optarg;
        } else if (c == OPT_DISTANCES) {
            dist_path = optarg;
        } else if ((rc = cli_sources_and_cost_opt(&o, c, argc, argv)) != CLI_OK || o.help_shown) {
            goto done;
        }
    }
    if ((rc = cli_check_method("voronoi", o.method, o.method_given, exact,
                               o.cost_path != NULL)) != CLI_OK)
        goto done;
    if (exact && (o.cost_path || !opt.unfolding || o.start_given)) {
        rc = cli_usage_error("voronoi", "--exact computes geodesic distance: it takes no "
                                        "--cost, --no-unfolding, --plain-start or "
                                        "--exact-start-radius");
        goto done;
    }
    int labels_txt;
    if ((rc = cli_sources_and_cost_positional(&o, argc, argv)) != CLI_OK)
        goto done;
    if (!o.mesh_path) {
        rc = cli_usage_error("voronoi", "no mesh file given");
        goto done;
    }
    if (o.n_src == 0 && !sources_path) {
        rc = cli_usage_error("voronoi", "no source given (--source, --face-source or "
                                        "--sources FILE)");
        goto done;
    }
    if ((rc = cli_sources_and_cost_check_output(&o, "npy", "txt", 1, &labels_txt)) != CLI_OK)
        goto done;
    (void)labels_txt;
    if (dist_path) {
        if (!cli_has_ext(dist_path, "npy") && !cli_has_ext(dist_path, "txt")) {
            rc = cli_usage_error("voronoi", "--distances must end in .npy or .txt");
            goto done;
        }
        const char *inputs[3] = {o.mesh_path, o.cost_path, sources_path};
        if ((rc = cli_check_output_not_input("voronoi", dist_path, inputs, 3)) != CLI_OK)
            goto done;
        if (strcmp(dist_path, o.out_path) == 0) {
            rc = cli_usage_error("voronoi", "--distances and -o name the same file");
            goto done;
        }
    }
    if (sources_path) {
        const char *inputs[1] = {sources_path};
        if ((rc = cli_check_output_not_input("voronoi", o.out_path, inputs, 1)) != CLI_OK)
            goto done;
    }
    rc = CLI_FAIL;
    cli_signals_install();

    if (sources_path && add_file_sources(&o, sources_path))
        goto done;
    if (cli_sources_and_cost_load(&o, &m, 0, 1, &opt))
        goto done;
    dist = exact ? cli_solve_exact_distances(m.mesh, &o, opt.max_distance)
                 : cli_solve_distances(m.mesh, &o, &opt);
    if (!dist || cli_interrupted())
        goto done;
    cli_sources_and_cost_note_in_no_face(&o, &m);
    labels = malloc((size_t)m.nv * sizeof *labels + 1);
    if (!labels) {
        cli_error("out of memory");
        goto done;
    }
    mfmm_error err;
    if (mfmm_voronoi_labels(m.mesh, dist, o.src, o.n_src, labels, &err) != MFMM_OK) {
        cli_error("%s", err.message);
        goto done;
    }
    labels = cli_mesh_per_input_vertex(&m, labels, sizeof *labels);
    if (!labels || !(dist = cli_mesh_per_input_vertex(&m, dist, sizeof *dist)))
        goto done;
    int32_t nv = m.nv_in, unreached = 0, cells = 0;
    uint8_t *has = calloc((size_t)o.n_src, 1);
    if (!has) {
        cli_error("out of memory");
        goto done;
    }
    for (int32_t v = 0; v < nv; v++) {
        if (labels[v] < 0)
            unreached++;
        else if (!has[labels[v]]) {
            has[labels[v]] = 1;
            cells++;
        }
    }
    free(has);
    if (cli_write_vector(o.out_path, cli_has_ext(o.out_path, "npy"), labels, nv, 0) ||
        (dist_path && cli_write_vector(dist_path, cli_has_ext(dist_path, "npy"), dist, nv, 1)))
        goto done;
    fprintf(stderr, "meshfmm voronoi: %ld vertices in %ld cells of %ld sources", (long)nv,
            (long)cells, (long)o.n_src);
    if (unreached)
        fprintf(stderr, " (%ld vertices unreached: label -1)", (long)unreached);
    fputc('\n', stderr);
    rc = CLI_OK;
done:
    if (rc != CLI_OK && cli_interrupted()) {
        fprintf(stderr, "meshfmm voronoi: interrupted; no output written\n");
        rc = CLI_EXIT_INTERRUPTED;
    }
    cli_mesh_free(&m);
    free(dist);
    free(labels);
    cli_sources_and_cost_free(&o);
    return rc;
}
