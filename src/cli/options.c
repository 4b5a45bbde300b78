/* Options shared by `distance` and `path`: the mesh, the sources, the cost
 * file and the output; their checks and the cost loader. */
#include <getopt.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

int cli_sources_and_cost_init(cli_sources_and_cost *o, const char *sub, void (*help)(FILE *out),
                              int argc)
{
    memset(o, 0, sizeof *o);
    o->sub = sub;
    o->help = help;
    o->exact_start_radius = MFMM_EXACT_START_AUTO;
    o->src = malloc((size_t)argc * sizeof *o->src); /* at most one per argument */
    if (!o->src) {
        cli_error("out of memory");
        return -1;
    }
    return 0;
}

void cli_sources_and_cost_free(cli_sources_and_cost *o)
{
    free(o->src);
    free(o->cost);
    o->src = NULL;
    o->cost = NULL;
}

void cli_sources_and_cost_note_in_no_face(const cli_sources_and_cost *o,
                                          const uint8_t *in_no_face)
{
    int64_t count = 0;
    int32_t first = -1;
    for (int32_t i = 0; in_no_face && i < o->n_src; i++)
        if (o->src[i].face < 0 && in_no_face[o->src[i].vertex] && count++ == 0)
            first = o->src[i].vertex;
    cli_note_sources_in_no_face(o->sub, count, first);
}

int cli_sources_and_cost_opt(cli_sources_and_cost *o, int c, int argc, char **argv)
{
    switch (c) {
    case 'h':
        o->help(stdout);
        o->help_shown = 1;
        return CLI_OK;
    case OPT_SOURCE: {
        int32_t v;
        if (!cli_parse_int32(optarg, &v))
            return cli_usage_error(o->sub, "--source needs a vertex id, not '%s'", optarg);
        mfmm_source x = {v, -1, {0, 0, 0}, 0.0};
        o->src[o->n_src++] = x;
        return CLI_OK;
    }
    case OPT_FACE_SOURCE:
        if (!cli_take_face_point(optarg, argc, argv, &o->src[o->n_src]))
            return cli_usage_error(o->sub,
                                   "--face-source needs a face id and three barycentric weights, finite numbers");
        o->n_src++;
        return CLI_OK;
    case OPT_COST:
        o->cost_path = optarg;
        return CLI_OK;
    case OPT_COST_PER_FACE:
        o->cost_per_face = 1;
        return CLI_OK;
    case 'o':
        o->out_path = optarg;
        return CLI_OK;
    case OPT_PLAIN_START:
        o->exact_start_radius = 0.0;
        return cli_start_option(o->sub, 1, &o->start_given);
    case OPT_EXACT_START_RADIUS:
        if (cli_start_option(o->sub, 2, &o->start_given) != CLI_OK)
            return CLI_USAGE;
        return cli_parse_start_radius(o->sub, optarg, &o->exact_start_radius);
    default:
        return cli_getopt_error(o->sub, c, argv);
    }
}

int cli_sources_and_cost_positional(cli_sources_and_cost *o, int argc, char **argv)
{
    for (int i = optind; i < argc; i++) {
        if (!o->mesh_path)
            o->mesh_path = argv[i];
        else
            return cli_usage_error(o->sub, "one mesh at a time ('%s' is extra)", argv[i]);
    }
    return CLI_OK;
}

int cli_sources_and_cost_check_inputs(const cli_sources_and_cost *o)
{
    if (!o->mesh_path)
        return cli_usage_error(o->sub, "no mesh file given");
    if (o->n_src == 0)
        return cli_usage_error(o->sub, "no source given (--source or --face-source)");
    return CLI_OK;
}

int cli_sources_and_cost_check_output(const cli_sources_and_cost *o, const char *ext0,
                                      const char *ext1, int text_which, int *which)
{
    if (!o->out_path)
        return cli_usage_error(o->sub, "no output given (-o OUT.%s, OUT.%s or - for standard output)", ext0, ext1);
    if (strcmp(o->out_path, "-") == 0)
        *which = text_which;
    else if (cli_has_ext(o->out_path, ext0))
        *which = 0;
    else if (cli_has_ext(o->out_path, ext1))
        *which = 1;
    else
        return cli_usage_error(o->sub, "the output must end in .%s or .%s (or be -)", ext0, ext1);
    if (o->cost_per_face && !o->cost_path)
        return cli_usage_error(o->sub, "--cost-per-face needs --cost");
    const char *inputs[2] = {o->mesh_path, o->cost_path};
    return cli_check_output_not_input(o->sub, o->out_path, inputs, 2);
}

int cli_sources_and_cost_load(cli_sources_and_cost *o, const mfmm_mesh *mesh,
                              int hint_per_face, mfmm_solve_options *opt)
{
    if (!o->cost_path)
        return 0;
    int32_t nv = mfmm_mesh_vertex_count(mesh), nf = mfmm_mesh_face_count(mesh);
    int64_t nc;
    int r = cli_has_ext(o->cost_path, "npy") ? cli_npy_read_vector(o->cost_path, &o->cost, &nc)
                                             : cli_txt_read_vector(o->cost_path, &o->cost, &nc);
    if (r)
        return -1;
    int64_t want = o->cost_per_face ? nf : nv;
    if (nc != want) {
        cli_error("%s: %lld cost values, the mesh has %lld %s%s", o->cost_path, (long long)nc,
                  (long long)want, o->cost_per_face ? "faces" : "vertices",
                  hint_per_face && !o->cost_per_face && nc == nf
                      ? " (use --cost-per-face for face costs)"
                      : "");
        return -1;
    }
    opt->cost = o->cost;
    opt->cost_location = o->cost_per_face ? MFMM_COST_PER_FACE : MFMM_COST_PER_VERTEX;
    return 0;
}

double *cli_solve_distances(const mfmm_mesh *mesh, const cli_sources_and_cost *o,
                            const mfmm_solve_options *opt)
{
    int32_t nv = mfmm_mesh_vertex_count(mesh);
    double *dist = malloc((size_t)nv * sizeof *dist);
    if (!dist) {
        cli_error("out of memory");
        return NULL;
    }
    mfmm_solver *solver = NULL;
    mfmm_status st = mfmm_solver_create(mesh, &solver);
    if (st != MFMM_OK) {
        cli_error("%s", mfmm_status_string(st));
        free(dist);
        return NULL;
    }
    mfmm_error err;
    mfmm_solve_options so;
    if (opt)
        so = *opt;
    else
        mfmm_solve_options_init(&so);
    so.exact_start_radius = o->exact_start_radius;
    st = mfmm_solve(solver, o->src, o->n_src, &so, dist, &err);
    mfmm_solver_destroy(solver);
    if (st != MFMM_OK) {
        cli_error("%s", err.message);
        free(dist);
        return NULL;
    }
    return dist;
}

int cli_parse_start_radius(const char *sub, const char *arg, double *radius)
{
    if (strcmp(arg, "auto") == 0) {
        *radius = MFMM_EXACT_START_AUTO;
        return CLI_OK;
    }
    if (!cli_parse_double(arg, radius) || !(*radius >= 0) || !(*radius < INFINITY))
        return cli_usage_error(sub,
                               "--exact-start-radius needs 'auto' or a finite number >= 0, not '%s'",
                               arg);
    return CLI_OK;
}

int cli_start_option(const char *sub, int which, int *given)
{
    *given |= which;
    if (*given == 3)
        return cli_usage_error(sub, "--plain-start and --exact-start-radius are two starts; "
                                    "give one (--plain-start is --exact-start-radius 0)");
    return CLI_OK;
}
