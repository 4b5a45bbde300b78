/* Options shared by `distance`, `path` and `voronoi`: the mesh, the
 * sources, the cost file, --weld, --method and the output; their checks,
 * the loader of the mesh and the cost, and the solves. */
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
    free(o->src_in);
    free(o->cost);
    o->src = o->src_in = NULL;
    o->cost = NULL;
}

void cli_sources_and_cost_note_in_no_face(const cli_sources_and_cost *o, const cli_mesh *m)
{
    int64_t count = 0;
    int32_t first = -1;
    const mfmm_source *src = o->src_in ? o->src_in : o->src;
    for (int32_t i = 0; m->in_no_face && i < o->n_src; i++)
        if (src[i].face < 0 && m->in_no_face[src[i].vertex] && count++ == 0)
            first = src[i].vertex;
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
    case OPT_WELD:
        o->weld = 1;
        return CLI_OK;
    case OPT_METHOD:
        o->method_given = 1;
        return cli_parse_method(o->sub, optarg, &o->method);
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
    return cli_check_method(o->sub, o->method, o->method_given, 0, o->cost_path != NULL);
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

int cli_sources_and_cost_load(cli_sources_and_cost *o, cli_mesh *m, int keep_arrays,
                              int hint_per_face, mfmm_solve_options *opt)
{
    if (cli_mesh_load(m, o->mesh_path, NULL, o->weld, keep_arrays))
        return -1;
    if (o->cost_path) {
        int64_t nc;
        int r = cli_has_ext(o->cost_path, "npy")
                    ? cli_npy_read_vector(o->cost_path, &o->cost, &nc)
                    : cli_txt_read_vector(o->cost_path, &o->cost, &nc);
        if (r)
            goto fail;
        int64_t want = o->cost_per_face ? m->nf_in : m->nv_in;
        if (nc != want) {
            cli_error("%s: %lld cost values, the mesh has %lld %s%s", o->cost_path,
                      (long long)nc, (long long)want, o->cost_per_face ? "faces" : "vertices",
                      hint_per_face && !o->cost_per_face && nc == m->nf_in
                          ? " (use --cost-per-face for face costs)"
                          : "");
            goto fail;
        }
        cli_mesh_cost(m, o->cost, o->cost_per_face);
        opt->cost = o->cost;
        opt->cost_location = o->cost_per_face ? MFMM_COST_PER_FACE : MFMM_COST_PER_VERTEX;
    }
    if (m->to_welded) {
        o->src_in = malloc((size_t)o->n_src * sizeof *o->src_in + 1);
        if (!o->src_in) {
            cli_error("out of memory");
            goto fail;
        }
        memcpy(o->src_in, o->src, (size_t)o->n_src * sizeof *o->src);
        for (int32_t i = 0; i < o->n_src; i++) {
            char what[32];
            snprintf(what, sizeof what, "source %ld", (long)i);
            if (cli_mesh_point(m, what, &o->src[i]))
                goto fail;
        }
    }
    return 0;
fail:
    cli_mesh_free(m);
    return -1;
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
    so.method = o->method;
    st = mfmm_solve(solver, o->src, o->n_src, &so, dist, &err);
    mfmm_solver_destroy(solver);
    if (st != MFMM_OK) {
        cli_error("%s", err.message);
        free(dist);
        return NULL;
    }
    return dist;
}

double *cli_solve_exact_distances(const mfmm_mesh *mesh, const cli_sources_and_cost *o,
                                  double max_distance)
{
    int32_t nv = mfmm_mesh_vertex_count(mesh);
    double *dist = malloc((size_t)nv * sizeof *dist + 1);
    mfmm_exact_solver *solver = NULL;
    if (!dist) {
        cli_error("out of memory");
        return NULL;
    }
    mfmm_error err;
    mfmm_status st = mfmm_exact_solver_create(mesh, &solver);
    if (st != MFMM_OK) {
        cli_error("%s", mfmm_status_string(st));
        free(dist);
        return NULL;
    }
    mfmm_exact_options eo;
    mfmm_exact_options_init(&eo);
    eo.max_distance = max_distance;
    mfmm_exact_info info = {.struct_size = sizeof info};
    st = mfmm_solve_exact(solver, o->src, o->n_src, &eo, dist, &info, &err);
    mfmm_exact_solver_destroy(solver);
    if (st != MFMM_OK) {
        cli_error("%s", err.message);
        free(dist);
        return NULL;
    }
    if (info.nonmanifold_walls)
        fprintf(stderr, "meshfmm %s: note: windows across the non-manifold edges passed "
                        "their budget (degenerate folded fans); those edges were walls, where "
                        "distances are upper bounds\n", o->sub);
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

int cli_parse_method(const char *sub, const char *arg, mfmm_method *method)
{
    if (strcmp(arg, "fmm") == 0)
        *method = MFMM_METHOD_FMM;
    else if (strcmp(arg, "windows") == 0)
        *method = MFMM_METHOD_WINDOWS;
    else
        return cli_usage_error(sub, "--method is fmm or windows, not '%s'", arg);
    return CLI_OK;
}

int cli_check_method(const char *sub, mfmm_method method, int method_given, int exact,
                     int has_cost)
{
    if (exact && method_given)
        return cli_usage_error(sub, "--exact and --method are two methods; give one (--exact: "
                                    "exact distances; --method fmm or windows)");
    (void)method; /* both methods take a --cost */
    (void)has_cost;
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
