/* meshfmm path MESH --source I [...] --target J -o OUT (.csv or .obj):
 * the minimal geodesic from a target back to the sources (paper section 5). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static void help(FILE *out)
{
    fprintf(out,
            "usage: meshfmm path MESH --source I [--source J ...] [--face-source F W0 W1 W2 ...]\n"
            "                    (--target J | --target-face F W0 W1 W2)\n"
            "                    [--cost FILE [--cost-per-face]] [--max-points N] [--no-straighten]\n"
            "                    -o OUT\n\n"
            "The minimal geodesic from the target back to the nearest source: distances by\n"
            "Fast Marching, then backtracking along -grad T (Heun's method). Prints the\n"
            "path's length on stdout (with --cost: the length and the cost-weighted length).\n\n"
            "  --source I              a vertex source (0-based id); repeatable\n"
            "  --face-source F W0 W1 W2  a point in face F with barycentric coordinates\n"
            "  --target J              the target vertex\n"
            "  --target-face F W0 W1 W2  a target point in face F\n"
            "  --cost FILE             slowness F (.npy or .txt), per vertex (default) or per\n"
            "                          face (--cost-per-face)\n"
            "  --max-points N          most points the path may have (default 100000)\n"
            "  --no-straighten         keep the traced path of section 5 (by default it is\n"
            "                          straightened inside the strip of faces it crossed)\n"
            "  -o OUT                  .csv (face,b0,b1,b2,x,y,z per point, with a header) or\n"
            "                          .obj (v lines and one polyline 'l' element)\n");
}

static int write_path(const char *path, const mfmm_surface_point *p, int32_t n, int obj)
{
    char *tmp;
    FILE *f = cli_partial_open(path, &tmp);
    if (!f)
        return -1;
    int bad = 0;
    if (obj) {
        bad = fprintf(f, "# meshfmm path: %d points, target first\n", (int)n) < 0;
        for (int32_t i = 0; i < n && !bad; i++)
            bad = fprintf(f, "v %.17g %.17g %.17g\n", p[i].xyz[0], p[i].xyz[1], p[i].xyz[2]) < 0;
        if (n >= 2 && !bad) {
            bad = fputs("l", f) < 0;
            for (int32_t i = 0; i < n && !bad; i++)
                bad = fprintf(f, " %d", (int)i + 1) < 0;
            bad |= fputc('\n', f) == EOF;
        }
    } else {
        bad = fputs("face,b0,b1,b2,x,y,z\n", f) < 0;
        for (int32_t i = 0; i < n && !bad; i++)
            bad = fprintf(f, "%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", (int)p[i].face,
                          p[i].bary[0], p[i].bary[1], p[i].bary[2], p[i].xyz[0], p[i].xyz[1],
                          p[i].xyz[2]) < 0;
    }
    return cli_partial_close(f, tmp, path, bad);
}

int cmd_path(int argc, char **argv)
{
    int have_target = 0, rc = CLI_FAIL;
    int32_t max_points = 100000;
    int straighten = 1;
    mfmm_source target = {0, -1, {0, 0, 0}, 0.0};
    cli_sources_and_cost o;
    double *dist = NULL;
    mfmm_surface_point *pts = NULL;
    mfmm_mesh *mesh = NULL;
    if (cli_sources_and_cost_init(&o, "path", help, argc))
        return CLI_FAIL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--target") == 0) {
            if (!cli_parse_vertex_point(argc, argv, i, &target)) {
                rc = cli_usage_error("path", "%s needs a vertex id", a);
                goto done;
            }
            have_target = 1;
            i++;
        } else if (strcmp(a, "--target-face") == 0) {
            if (!cli_parse_face_point(argc, argv, i, &target)) {
                rc = cli_usage_error("path", "%s needs a face id and three barycentric weights",
                                     a);
                goto done;
            }
            have_target = 1;
            i += 4;
        } else if (strcmp(a, "--no-straighten") == 0) {
            straighten = 0;
        } else if (strcmp(a, "--max-points") == 0) {
            if (i + 1 >= argc || !cli_parse_int32(argv[i + 1], &max_points) || max_points < 1) {
                rc = cli_usage_error("path", "--max-points needs a number >= 1");
                goto done;
            }
            i++;
        } else if ((rc = cli_sources_and_cost_arg(&o, argc, argv, &i)) != CLI_OK ||
                   o.help_shown) {
            goto done;
        }
    }
    if ((rc = cli_sources_and_cost_check_inputs(&o)) != CLI_OK)
        goto done;
    if (!have_target) {
        rc = cli_usage_error("path", "no target given (--target or --target-face)");
        goto done;
    }
    int obj;
    if ((rc = cli_sources_and_cost_check_output(&o, "csv", "obj", &obj)) != CLI_OK)
        goto done;
    rc = CLI_FAIL;

    mesh = cli_load_mesh(o.mesh_path, NULL);
    mfmm_solve_options opt;
    mfmm_solve_options_init(&opt);
    if (!mesh || cli_sources_and_cost_load(&o, mesh, 0, &opt))
        goto done;
    pts = malloc((size_t)max_points * sizeof *pts);
    if (!pts) {
        cli_error("out of memory");
        goto done;
    }
    dist = cli_solve_distances(mesh, &o, &opt);
    if (!dist)
        goto done;
    mfmm_path_options po;
    mfmm_path_options_init(&po);
    double wlen = 0.0, len = 0.0;
    int32_t n = 0;
    mfmm_error err;
    po.max_points = max_points;
    po.straighten = straighten;
    po.sources = o.src;
    po.n_sources = o.n_src;
    po.cost = opt.cost;
    po.cost_location = opt.cost_location;
    po.weighted_length = &wlen;
    if (mfmm_trace_path(mesh, dist, &target, &po, pts, max_points, &n, &len, &err) != MFMM_OK) {
        cli_error("%s", err.message);
        goto done;
    }
    if (write_path(o.out_path, pts, n, obj))
        goto done;
    if (o.cost)
        printf("%.17g %.17g\n", len, wlen);
    else
        printf("%.17g\n", len);
    rc = CLI_OK;
done:
    mfmm_mesh_destroy(mesh);
    free(pts);
    free(dist);
    cli_sources_and_cost_free(&o);
    return rc;
}
