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
            "                        -o OUT\n\n"
            "Geodesic distance (Fast Marching) from the sources to every vertex of MESH.\n\n"
            "  --source I              a vertex source (0-based id); repeatable\n"
            "  --face-source F W0 W1 W2  a point in face F with barycentric coordinates\n"
            "  --max-distance X        stop past X; farther vertices get inf\n"
            "  --no-unfolding          plain stencils at obtuse corners (for comparison)\n"
            "  --cost FILE             slowness F (.npy float64/float32 or .txt), one value\n"
            "                          per vertex (default) or per face (--cost-per-face)\n"
            "  -o OUT                  .npy (float64, shape (nv,)) or .txt (one value per\n"
            "                          line, %%.17g, inf for unreached vertices)\n");
}

static int write_txt(const char *path, const double *d, int32_t n)
{
    char *tmp;
    FILE *f = cli_partial_open(path, &tmp);
    if (!f)
        return -1;
    int bad = 0;
    for (int32_t i = 0; i < n && !bad; i++) {
        if (isinf(d[i]))
            bad = fputs(d[i] > 0 ? "inf\n" : "-inf\n", f) < 0;
        else
            bad = fprintf(f, "%.17g\n", d[i]) < 0;
    }
    return cli_partial_close(f, tmp, path, bad);
}

int cmd_distance(int argc, char **argv)
{
    int rc = CLI_FAIL;
    mfmm_solve_options opt;
    mfmm_solve_options_init(&opt);
    cli_sources_and_cost o;
    double *dist = NULL;
    mfmm_mesh *mesh = NULL;
    if (cli_sources_and_cost_init(&o, "distance", help, argc))
        return CLI_FAIL;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--max-distance") == 0) {
            if (i + 1 >= argc || !cli_parse_double(argv[i + 1], &opt.max_distance) ||
                !(opt.max_distance >= 0)) {
                rc = cli_usage_error("distance", "--max-distance needs a number >= 0");
                goto done;
            }
            i++;
        } else if (strcmp(a, "--no-unfolding") == 0) {
            opt.unfolding = 0;
        } else if ((rc = cli_sources_and_cost_arg(&o, argc, argv, &i)) != CLI_OK ||
                   o.help_shown) {
            goto done;
        }
    }
    int is_txt;
    if ((rc = cli_sources_and_cost_check_inputs(&o)) != CLI_OK ||
        (rc = cli_sources_and_cost_check_output(&o, "npy", "txt", &is_txt)) != CLI_OK)
        goto done;
    rc = CLI_FAIL;

    mesh = cli_load_mesh(o.mesh_path, NULL);
    if (!mesh || cli_sources_and_cost_load(&o, mesh, 1, &opt))
        goto done;
    int32_t nv = mfmm_mesh_vertex_count(mesh);
    dist = cli_solve_distances(mesh, &o, &opt);
    if (!dist)
        goto done;
    if (!is_txt) {
        cli_npy_writer w;
        if (cli_npy_open(&w, o.out_path, "<f8", nv, -1))
            goto done;
        if (cli_npy_append(&w, dist, nv)) {
            cli_npy_abort(&w);
            goto done;
        }
        if (cli_npy_close(&w))
            goto done;
    } else if (write_txt(o.out_path, dist, nv)) {
        goto done;
    }
    rc = CLI_OK;
done:
    mfmm_mesh_destroy(mesh);
    free(dist);
    cli_sources_and_cost_free(&o);
    return rc;
}
