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
    const char *path = NULL, *out_path = NULL, *cost_path = NULL;
    int cost_per_face = 0, rc = CLI_FAIL;
    mfmm_solve_options opt;
    mfmm_solve_options_init(&opt);
    mfmm_source *src = malloc((size_t)argc * sizeof *src); /* at most one per argument */
    int32_t n_src = 0;
    double *cost = NULL, *dist = NULL;
    mfmm_mesh *mesh = NULL;
    mfmm_solver *solver = NULL;
    if (!src) {
        cli_error("out of memory");
        return CLI_FAIL;
    }
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            help(stdout);
            rc = CLI_OK;
            goto done;
        } else if (strcmp(a, "--source") == 0) {
            int32_t v;
            if (i + 1 >= argc || !cli_parse_int32(argv[i + 1], &v)) {
                rc = cli_usage_error("distance", "--source needs a vertex id");
                goto done;
            }
            mfmm_source s = {v, -1, {0, 0, 0}, 0.0};
            src[n_src++] = s;
            i++;
        } else if (strcmp(a, "--face-source") == 0) {
            int32_t fid;
            double w[3];
            if (i + 4 >= argc || !cli_parse_int32(argv[i + 1], &fid) ||
                !cli_parse_double(argv[i + 2], &w[0]) || !cli_parse_double(argv[i + 3], &w[1]) ||
                !cli_parse_double(argv[i + 4], &w[2])) {
                rc = cli_usage_error("distance",
                                     "--face-source needs a face id and three barycentric weights");
                goto done;
            }
            mfmm_source s = {-1, fid, {w[0], w[1], w[2]}, 0.0};
            src[n_src++] = s;
            i += 4;
        } else if (strcmp(a, "--max-distance") == 0) {
            if (i + 1 >= argc || !cli_parse_double(argv[i + 1], &opt.max_distance) ||
                !(opt.max_distance >= 0)) {
                rc = cli_usage_error("distance", "--max-distance needs a number >= 0");
                goto done;
            }
            i++;
        } else if (strcmp(a, "--no-unfolding") == 0) {
            opt.unfolding = 0;
        } else if (strcmp(a, "--cost") == 0) {
            if (i + 1 >= argc) {
                rc = cli_usage_error("distance", "--cost needs a file");
                goto done;
            }
            cost_path = argv[++i];
        } else if (strcmp(a, "--cost-per-face") == 0) {
            cost_per_face = 1;
        } else if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
            if (i + 1 >= argc) {
                rc = cli_usage_error("distance", "-o needs a file name");
                goto done;
            }
            out_path = argv[++i];
        } else if (a[0] == '-' && a[1] != '\0') {
            rc = cli_usage_error("distance", "unknown option '%s'", a);
            goto done;
        } else if (!path) {
            path = a;
        } else {
            rc = cli_usage_error("distance", "one mesh at a time ('%s' is extra)", a);
            goto done;
        }
    }
    if (!path) {
        rc = cli_usage_error("distance", "no mesh file given");
        goto done;
    }
    if (n_src == 0) {
        rc = cli_usage_error("distance", "no source given (--source or --face-source)");
        goto done;
    }
    if (!out_path) {
        rc = cli_usage_error("distance", "no output given (-o OUT.npy or OUT.txt)");
        goto done;
    }
    int npy = cli_has_ext(out_path, "npy");
    if (!npy && !cli_has_ext(out_path, "txt")) {
        rc = cli_usage_error("distance", "the output must end in .npy or .txt");
        goto done;
    }
    if (cost_per_face && !cost_path) {
        rc = cli_usage_error("distance", "--cost-per-face needs --cost");
        goto done;
    }

    mesh = cli_load_mesh(path, NULL);
    if (!mesh)
        goto done;
    int32_t nv = mfmm_mesh_vertex_count(mesh), nf = mfmm_mesh_face_count(mesh);
    if (cost_path) {
        int64_t nc;
        int r = cli_has_ext(cost_path, "npy") ? cli_npy_read_vector(cost_path, &cost, &nc)
                                              : cli_txt_read_vector(cost_path, &cost, &nc);
        if (r)
            goto done;
        int64_t want = cost_per_face ? nf : nv;
        if (nc != want) {
            cli_error("%s: %lld cost values, the mesh has %lld %s%s", cost_path, (long long)nc,
                      (long long)want, cost_per_face ? "faces" : "vertices",
                      !cost_per_face && nc == nf ? " (use --cost-per-face for face costs)" : "");
            goto done;
        }
        opt.cost = cost;
        opt.cost_location = cost_per_face ? MFMM_COST_PER_FACE : MFMM_COST_PER_VERTEX;
    }
    dist = malloc((size_t)nv * sizeof *dist);
    if (!dist) {
        cli_error("out of memory");
        goto done;
    }
    mfmm_status st = mfmm_solver_create(mesh, &solver);
    if (st != MFMM_OK) {
        cli_error("%s", mfmm_status_string(st));
        goto done;
    }
    mfmm_error err;
    st = mfmm_solve(solver, src, n_src, &opt, dist, &err);
    if (st != MFMM_OK) {
        cli_error("%s", err.message);
        goto done;
    }
    if (npy) {
        cli_npy_writer w;
        if (cli_npy_open(&w, out_path, "<f8", nv, -1))
            goto done;
        if (cli_npy_append(&w, dist, nv)) {
            cli_npy_abort(&w);
            goto done;
        }
        if (cli_npy_close(&w))
            goto done;
    } else if (write_txt(out_path, dist, nv)) {
        goto done;
    }
    rc = CLI_OK;
done:
    mfmm_solver_destroy(solver);
    mfmm_mesh_destroy(mesh);
    free(dist);
    free(cost);
    free(src);
    return rc;
}
