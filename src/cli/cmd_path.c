/* meshfmm path MESH --source I [...] --target J -o OUT (.csv or .obj):
 * the minimal geodesic from the nearest source to a target, traced back
 * from the target (paper section 5) and written from the source. */
#include <errno.h>
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
            "                    [--exact-start-radius R | --plain-start]\n"
            "                    [--method fmm|windows] [--weld] -o OUT\n\n"
            "The minimal geodesic from the nearest source to the target: distances by Fast\n"
            "Marching (or --method windows), then backtracking from the target along\n"
            "-grad T (Heun's method).\n"
            "The path is written from the source (first point) to the target (last), as\n"
            "Python's Mesh.path(source, target). Prints the path's length on stdout (with\n"
            "--cost: the length and the cost-weighted length).\n\n"
            "  --source I              a vertex source (0-based id); repeatable\n"
            "  --face-source F W0 W1 W2  a point in face F with barycentric coordinates\n"
            "  --target J              the target vertex\n"
            "  --target-face F W0 W1 W2  a target point in face F\n"
            "  --cost FILE             slowness F (.npy or .txt), per vertex (default) or per\n"
            "                          face (--cost-per-face)\n"
            "  --max-points N          most points the path may have (default 100000)\n"
            CLI_START_HELP_NO_LIMIT
            CLI_METHOD_HELP
            "  --no-straighten         keep the traced path of section 5 (by default it is\n"
            "                          straightened inside the strip of faces it crossed)\n"
            CLI_WELD_HELP
            "  -o, --output OUT        .csv (face,b0,b1,b2,x,y,z per point, with a header;\n"
            "                          the face of point i > 0 is the one the segment from\n"
            "                          point i-1 runs through, b0-b2 the point's barycentric\n"
            "                          coordinates in it) or .obj (v lines and one polyline\n"
            "                          'l' element); - writes\n"
            "                          the .csv to standard output (the length then goes to\n"
            "                          standard error)\n"
            "  -h, --help              this text\n\n"
            "Options take their value as --target 3 or --target=3. The output is written to\n"
            "a temporary file beside OUT and renamed when complete; it may not be an input.\n");
}

static int write_path(const char *path, const mfmm_surface_point *p, int32_t n, int obj)
{
    cli_output out;
    if (cli_output_open(&out, path))
        return -1;
    FILE *f = out.f;
    int bad = 0;
    if (obj) {
        bad = fprintf(f, "# meshfmm path: %d points, source first\n", (int)n) < 0;
        for (int32_t i = 0; i < n && !bad && !cli_interrupted(); i++)
            for (int k = 0; k < 3 && !bad; k++)
                bad = fputs(k ? " " : "v ", f) < 0 || cli_put_double(f, p[i].xyz[k]) < 0 ||
                      (k == 2 && fputc('\n', f) == EOF);
        if (n >= 2 && !bad) {
            bad = fputs("l", f) < 0;
            for (int32_t i = 0; i < n && !bad; i++)
                bad = fprintf(f, " %d", (int)i + 1) < 0;
            bad |= fputc('\n', f) == EOF;
        }
    } else {
        bad = fputs("face,b0,b1,b2,x,y,z\n", f) < 0;
        for (int32_t i = 0; i < n && !bad && !cli_interrupted(); i++) {
            const double v[6] = {p[i].bary[0], p[i].bary[1], p[i].bary[2],
                                 p[i].xyz[0],  p[i].xyz[1],  p[i].xyz[2]};
            bad = fprintf(f, "%d", (int)p[i].face) < 0;
            for (int k = 0; k < 6 && !bad; k++)
                bad = fputc(',', f) == EOF || cli_put_double(f, v[k]) < 0;
            bad = bad || fputc('\n', f) == EOF;
        }
    }
    return cli_output_close(&out, bad);
}

/* q's barycentric coordinates moved into `face` (built ids), which holds
 * the point on its boundary: by the corners the two faces share, or, when
 * the point is not on them, from its position (least squares in the face's
 * plane, negative weights clamped). */
static void move_to_face(const cli_mesh *m, mfmm_surface_point *q, int32_t face)
{
    const int32_t *a = m->F + 3 * (size_t)q->face, *b = m->F + 3 * (size_t)face;
    double w[3] = {0.0, 0.0, 0.0}, lost = 0.0;
    for (int i = 0; i < 3; i++) {
        int k = 0;
        while (k < 3 && b[k] != a[i])
            k++;
        if (k < 3)
            w[k] += q->bary[i];
        else
            lost += fabs(q->bary[i]);
    }
    if (lost > 1e-12) {
        const double *A = m->V + 3 * (size_t)b[0], *B = m->V + 3 * (size_t)b[1],
                     *C = m->V + 3 * (size_t)b[2];
        double e1[3], e2[3], r[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = B[k] - A[k];
            e2[k] = C[k] - A[k];
            r[k] = q->xyz[k] - A[k];
        }
        double g11 = 0, g12 = 0, g22 = 0, h1 = 0, h2 = 0;
        for (int k = 0; k < 3; k++) {
            g11 += e1[k] * e1[k];
            g12 += e1[k] * e2[k];
            g22 += e2[k] * e2[k];
            h1 += e1[k] * r[k];
            h2 += e2[k] * r[k];
        }
        double det = g11 * g22 - g12 * g12;
        double l1 = det != 0.0 ? (h1 * g22 - h2 * g12) / det : 0.0;
        double l2 = det != 0.0 ? (h2 * g11 - h1 * g12) / det : 0.0;
        w[0] = fmax(1.0 - l1 - l2, 0.0);
        w[1] = fmax(l1, 0.0);
        w[2] = fmax(l2, 0.0);
    }
    double sum = w[0] + w[1] + w[2];
    for (int k = 0; k < 3; k++)
        q->bary[k] = sum > 0.0 ? w[k] / sum : 1.0 / 3.0;
    q->face = face;
}

/* The traced path (target first) in place from the source to the target,
 * keeping its convention: point i > 0 names the face of the segment from
 * point i-1, and its coordinates are in that face. */
static void reverse_path(const cli_mesh *m, mfmm_surface_point *p, int32_t n)
{
    for (int32_t i = 0, j = n - 1; i < j; i++, j--) {
        mfmm_surface_point t = p[i];
        p[i] = p[j];
        p[j] = t;
    }
    /* the segment from new point j-1 to j was the old segment into old
     * point j-1: its face is p[j-1]'s (not yet moved: j descends) */
    for (int32_t j = n - 1; j >= 1; j--)
        if (p[j - 1].face >= 0 && p[j].face >= 0 && p[j - 1].face != p[j].face)
            move_to_face(m, &p[j], p[j - 1].face);
}

int cmd_path(int argc, char **argv)
{
    static const struct option longopts[] = {
        CLI_SHARED_LONG_OPTIONS,
        {"target", required_argument, NULL, OPT_TARGET},
        {"target-face", required_argument, NULL, OPT_TARGET_FACE},
        {"no-straighten", no_argument, NULL, OPT_NO_STRAIGHTEN},
        {"max-points", required_argument, NULL, OPT_MAX_POINTS},
        {NULL, 0, NULL, 0}};
    int have_target = 0, rc = CLI_FAIL;
    int32_t max_points = 100000;
    int straighten = 1;
    mfmm_source target = {0, -1, {0, 0, 0}, 0.0};
    cli_sources_and_cost o;
    double *dist = NULL;
    mfmm_surface_point *pts = NULL;
    cli_mesh m = {0};
    if (cli_sources_and_cost_init(&o, "path", help, argc))
        return CLI_FAIL;
    int c;
    opterr = 0;
    uint32_t seen = 0;
    while ((c = getopt_long(argc, argv, CLI_SHARED_SHORT_OPTIONS, longopts, NULL)) != -1) {
        if ((rc = cli_once("path", c, &seen)) != CLI_OK)
            goto done;
        if ((c == OPT_TARGET || c == OPT_TARGET_FACE) && have_target) {
            rc = cli_usage_error("path", "one target (--target or --target-face), given twice");
            goto done;
        }
        if (c == OPT_TARGET) {
            int32_t v;
            if (!cli_parse_int32(optarg, &v)) {
                rc = cli_usage_error("path", "--target needs a vertex id, not '%s'", optarg);
                goto done;
            }
            mfmm_source x = {v, -1, {0, 0, 0}, 0.0};
            target = x;
            have_target = 1;
        } else if (c == OPT_TARGET_FACE) {
            if (!cli_take_face_point(optarg, argc, argv, &target)) {
                rc = cli_usage_error("path",
                                     "--target-face needs a face id and three barycentric weights, finite numbers");
                goto done;
            }
            have_target = 1;
        } else if (c == OPT_NO_STRAIGHTEN) {
            straighten = 0;
        } else if (c == OPT_MAX_POINTS) {
            if (!cli_parse_int32(optarg, &max_points) || max_points < 1) {
                rc = cli_usage_error("path", "--max-points needs a number >= 1");
                goto done;
            }
        } else if ((rc = cli_sources_and_cost_opt(&o, c, argc, argv)) != CLI_OK || o.help_shown) {
            goto done;
        }
    }
    if ((rc = cli_sources_and_cost_positional(&o, argc, argv)) != CLI_OK ||
        (rc = cli_sources_and_cost_check_inputs(&o)) != CLI_OK)
        goto done;
    if (!have_target) {
        rc = cli_usage_error("path", "no target given (--target or --target-face)");
        goto done;
    }
    int obj;
    if ((rc = cli_sources_and_cost_check_output(&o, "csv", "obj", 0, &obj)) != CLI_OK)
        goto done;
    rc = CLI_FAIL;
    cli_signals_install();

    mfmm_solve_options opt;
    mfmm_solve_options_init(&opt);
    if (cli_sources_and_cost_load(&o, &m, 1, 0, &opt) || cli_mesh_point(&m, "target", &target))
        goto done;
    pts = malloc((size_t)max_points * sizeof *pts);
    if (!pts) {
        cli_error("out of memory");
        goto done;
    }
    dist = cli_solve_distances(m.mesh, &o, &opt);
    if (!dist)
        goto done;
    cli_sources_and_cost_note_in_no_face(&o, &m);
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
    if (mfmm_trace_path(m.mesh, dist, &target, &po, pts, max_points, &n, &len, &err) !=
        MFMM_OK) {
        cli_error("%s", err.message);
        goto done;
    }
    reverse_path(&m, pts, n);
    for (int32_t i = 0; i < n; i++)
        pts[i].face = cli_mesh_input_face(&m, pts[i].face);
    if (cli_interrupted() || write_path(o.out_path, pts, n, obj))
        goto done;
    /* The length goes to stdout, or to stderr when stdout holds the path. */
    FILE *lf = strcmp(o.out_path, "-") == 0 ? stderr : stdout;
    cli_put_double(lf, len);
    if (o.cost) {
        fputc(' ', lf);
        cli_put_double(lf, wlen);
    }
    fputc('\n', lf);
    if (fflush(lf) != 0 || ferror(lf)) {
        cli_error("cannot write the path's length to %s: %s",
                  lf == stdout ? "standard output" : "standard error", strerror(errno));
        goto done;
    }
    rc = CLI_OK;
done:
    if (rc != CLI_OK && cli_interrupted()) {
        fprintf(stderr, "meshfmm path: interrupted; no output written\n");
        rc = CLI_EXIT_INTERRUPTED;
    }
    cli_mesh_free(&m);
    free(pts);
    free(dist);
    cli_sources_and_cost_free(&o);
    return rc;
}
