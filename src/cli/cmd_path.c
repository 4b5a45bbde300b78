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
            "                    [--cost FILE [--cost-per-face]] [--max-points N] -o OUT\n\n"
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

static int parse_face_point(int argc, char **argv, int i, mfmm_source *s)
{
    int32_t fid;
    double w[3];
    if (i + 4 >= argc || !cli_parse_int32(argv[i + 1], &fid) ||
        !cli_parse_double(argv[i + 2], &w[0]) || !cli_parse_double(argv[i + 3], &w[1]) ||
        !cli_parse_double(argv[i + 4], &w[2]))
        return 0;
    mfmm_source x = {-1, fid, {w[0], w[1], w[2]}, 0.0};
    *s = x;
    return 1;
}

int cmd_path(int argc, char **argv)
{
    const char *path = NULL, *out_path = NULL, *cost_path = NULL;
    int cost_per_face = 0, have_target = 0, rc = CLI_FAIL;
    int32_t max_points = 100000;
    mfmm_source target = {0, -1, {0, 0, 0}, 0.0};
    mfmm_source *src = malloc((size_t)argc * sizeof *src);
    int32_t n_src = 0;
    double *cost = NULL, *dist = NULL;
    mfmm_surface_point *pts = NULL;
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
        } else if (strcmp(a, "--source") == 0 || strcmp(a, "--target") == 0) {
            int32_t v;
            if (i + 1 >= argc || !cli_parse_int32(argv[i + 1], &v)) {
                rc = cli_usage_error("path", "%s needs a vertex id", a);
                goto done;
            }
            mfmm_source s = {v, -1, {0, 0, 0}, 0.0};
            if (a[2] == 's') {
                src[n_src++] = s;
            } else {
                target = s;
                have_target = 1;
            }
            i++;
        } else if (strcmp(a, "--face-source") == 0 || strcmp(a, "--target-face") == 0) {
            mfmm_source s;
            if (!parse_face_point(argc, argv, i, &s)) {
                rc = cli_usage_error("path", "%s needs a face id and three barycentric weights",
                                     a);
                goto done;
            }
            if (a[2] == 'f') {
                src[n_src++] = s;
            } else {
                target = s;
                have_target = 1;
            }
            i += 4;
        } else if (strcmp(a, "--max-points") == 0) {
            if (i + 1 >= argc || !cli_parse_int32(argv[i + 1], &max_points) || max_points < 1) {
                rc = cli_usage_error("path", "--max-points needs a number >= 1");
                goto done;
            }
            i++;
        } else if (strcmp(a, "--cost") == 0) {
            if (i + 1 >= argc) {
                rc = cli_usage_error("path", "--cost needs a file");
                goto done;
            }
            cost_path = argv[++i];
        } else if (strcmp(a, "--cost-per-face") == 0) {
            cost_per_face = 1;
        } else if (strcmp(a, "-o") == 0 || strcmp(a, "--output") == 0) {
            if (i + 1 >= argc) {
                rc = cli_usage_error("path", "-o needs a file name");
                goto done;
            }
            out_path = argv[++i];
        } else if (a[0] == '-' && a[1] != '\0') {
            rc = cli_usage_error("path", "unknown option '%s'", a);
            goto done;
        } else if (!path) {
            path = a;
        } else {
            rc = cli_usage_error("path", "one mesh at a time ('%s' is extra)", a);
            goto done;
        }
    }
    if (!path) {
        rc = cli_usage_error("path", "no mesh file given");
        goto done;
    }
    if (n_src == 0) {
        rc = cli_usage_error("path", "no source given (--source or --face-source)");
        goto done;
    }
    if (!have_target) {
        rc = cli_usage_error("path", "no target given (--target or --target-face)");
        goto done;
    }
    if (!out_path) {
        rc = cli_usage_error("path", "no output given (-o OUT.csv or OUT.obj)");
        goto done;
    }
    int obj = cli_has_ext(out_path, "obj");
    if (!obj && !cli_has_ext(out_path, "csv")) {
        rc = cli_usage_error("path", "the output must end in .csv or .obj");
        goto done;
    }
    if (cost_per_face && !cost_path) {
        rc = cli_usage_error("path", "--cost-per-face needs --cost");
        goto done;
    }

    mesh = cli_load_mesh(path, NULL);
    if (!mesh)
        goto done;
    int32_t nv = mfmm_mesh_vertex_count(mesh), nf = mfmm_mesh_face_count(mesh);
    mfmm_solve_options opt;
    mfmm_solve_options_init(&opt);
    if (cost_path) {
        int64_t nc;
        int r = cli_has_ext(cost_path, "npy") ? cli_npy_read_vector(cost_path, &cost, &nc)
                                              : cli_txt_read_vector(cost_path, &cost, &nc);
        if (r)
            goto done;
        int64_t want = cost_per_face ? nf : nv;
        if (nc != want) {
            cli_error("%s: %lld cost values, the mesh has %lld %s", cost_path, (long long)nc,
                      (long long)want, cost_per_face ? "faces" : "vertices");
            goto done;
        }
        opt.cost = cost;
        opt.cost_location = cost_per_face ? MFMM_COST_PER_FACE : MFMM_COST_PER_VERTEX;
    }
    dist = malloc((size_t)nv * sizeof *dist);
    pts = malloc((size_t)max_points * sizeof *pts);
    if (!dist || !pts) {
        cli_error("out of memory");
        goto done;
    }
    mfmm_status st = mfmm_solver_create(mesh, &solver);
    if (st != MFMM_OK) {
        cli_error("%s", mfmm_status_string(st));
        goto done;
    }
    mfmm_error err;
    if (mfmm_solve(solver, src, n_src, &opt, dist, &err) != MFMM_OK) {
        cli_error("%s", err.message);
        goto done;
    }
    mfmm_path_options po;
    mfmm_path_options_init(&po);
    double wlen = 0.0, len = 0.0;
    int32_t n = 0;
    po.max_points = max_points;
    po.sources = src;
    po.n_sources = n_src;
    po.cost = opt.cost;
    po.cost_location = opt.cost_location;
    po.weighted_length = &wlen;
    if (mfmm_trace_path(mesh, dist, &target, &po, pts, max_points, &n, &len, &err) != MFMM_OK) {
        cli_error("%s", err.message);
        goto done;
    }
    if (write_path(out_path, pts, n, obj))
        goto done;
    if (cost)
        printf("%.17g %.17g\n", len, wlen);
    else
        printf("%.17g\n", len);
    rc = CLI_OK;
done:
    mfmm_solver_destroy(solver);
    mfmm_mesh_destroy(mesh);
    free(pts);
    free(dist);
    free(cost);
    free(src);
    return rc;
}
