/* meshfmm generate sine|sphere|torus|grid|lattice N -o OUT.obj */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "io/generate.h"

static void help(FILE *out)
{
    fprintf(out,
            "usage: meshfmm generate SHAPE N -o OUT.obj [--stretch S] [--radii R r]\n\n"
            "Writes a generated mesh as OBJ (coordinates with 17 significant digits);\n"
            "OUT may be - (standard output).\n\n"
            "  grid N      unit square, N x N squares split along alternating diagonals\n"
            "  sine N      z = 0.45 sin(2 pi x) sin(2 pi y) on [0,1]^2, N x N squares\n"
            "              (the paper's Fig. 8a)\n"
            "  sphere N    unit icosphere, subdivision level N (10*4^N + 2 vertices)\n"
            "  torus N     N x N quads split in two; tube centre radius R, tube radius r\n"
            "              (--radii, default 1 0.4)\n"
            "  lattice N   equilateral triangles, N rows of N cells, x stretched by S\n"
            "              (--stretch, default 3: 120-degree corners)\n\n"
            "  -o, --output OUT.obj   the file to write (- for standard output)\n"
            "  --stretch S            lattice: x stretched by S (default 3)\n"
            "  --radii R r            torus: tube centre radius and tube radius\n"
            "  -h, --help             this text\n");
}

int cmd_generate(int argc, char **argv)
{
    const char *shape = NULL, *n_arg = NULL, *out_path = NULL;
    double stretch = 3.0, R = 1.0, r = 0.4;
    int have_stretch = 0, have_radii = 0;
    static const struct option longopts[] = {
        {"help", no_argument, NULL, 'h'},
        {"output", required_argument, NULL, 'o'},
        {"stretch", required_argument, NULL, OPT_STRETCH},
        {"radii", required_argument, NULL, OPT_RADII},
        {NULL, 0, NULL, 0}};
    int c;
    opterr = 0;
    uint32_t seen = 0;
    while ((c = getopt_long(argc, argv, ":ho:", longopts, NULL)) != -1) {
        if (cli_once("generate", c, &seen) != CLI_OK)
            return CLI_USAGE;
        if (c == 'h') {
            help(stdout);
            return CLI_OK;
        } else if (c == 'o') {
            out_path = optarg;
        } else if (c == OPT_STRETCH) {
            if (!cli_parse_double(optarg, &stretch) || !(stretch > 0) || stretch > 1e6)
                return cli_usage_error("generate", "--stretch needs a number > 0");
            have_stretch = 1;
        } else if (c == OPT_RADII) {
            /* two values: R in optarg, r next */
            if (optind >= argc || !cli_parse_double(optarg, &R) ||
                !cli_parse_double(argv[optind], &r) || !(r > 0) || !(R > r) || R > 1e100)
                return cli_usage_error("generate", "--radii needs R > r > 0");
            optind++;
            have_radii = 1;
        } else {
            return cli_getopt_error("generate", c, argv);
        }
    }
    for (int i = optind; i < argc; i++) {
        if (!shape)
            shape = argv[i];
        else if (!n_arg)
            n_arg = argv[i];
        else
            return cli_usage_error("generate", "unexpected argument '%s'", argv[i]);
    }
    if (!shape || !n_arg)
        return cli_usage_error("generate", "needs a shape and a size N");
    if (!out_path)
        return cli_usage_error("generate", "no output given (-o OUT.obj)");
    if (strcmp(out_path, "-") != 0 && !cli_has_ext(out_path, "obj"))
        return cli_usage_error("generate", "the output must end in .obj (or be - for standard output)");
    int32_t n;
    if (!cli_parse_int32(n_arg, &n))
        return cli_usage_error("generate", "N must be an integer, not '%s'", n_arg);

    mfmm_gen_mesh m = {0, 0, NULL, NULL};
    int is_sphere = strcmp(shape, "sphere") == 0;
    int min_n = is_sphere ? 0 : strcmp(shape, "torus") == 0 ? 3 : 1;
    int max_n = is_sphere ? 10 : 20000;
    if (!is_sphere && strcmp(shape, "grid") && strcmp(shape, "sine") && strcmp(shape, "torus") &&
        strcmp(shape, "lattice"))
        return cli_usage_error("generate", "unknown shape '%s'", shape);
    /* an option that shapes another mesh is a mistake, not a no-op */
    if (have_stretch && strcmp(shape, "lattice") != 0)
        return cli_usage_error("generate", "--stretch applies to lattice only, not %s", shape);
    if (have_radii && strcmp(shape, "torus") != 0)
        return cli_usage_error("generate", "--radii applies to torus only, not %s", shape);
    if (n < min_n || n > max_n)
        return cli_usage_error("generate", "N for %s must be in [%d, %d]", shape, min_n, max_n);
    if (is_sphere)
        m = mfmm_gen_icosphere(n);
    else if (strcmp(shape, "grid") == 0)
        m = mfmm_gen_grid(n);
    else if (strcmp(shape, "sine") == 0)
        m = mfmm_gen_sine(n);
    else if (strcmp(shape, "torus") == 0)
        m = mfmm_gen_torus(n, n, R, r);
    else
        m = mfmm_gen_lattice(n, stretch);
    if (!m.V || !m.F || m.nv <= 0 || m.nf <= 0) {
        mfmm_gen_free(&m);
        cli_error("cannot generate %s %d (out of memory or too large)", shape, (int)n);
        return CLI_FAIL;
    }
    char comment[128];
    snprintf(comment, sizeof comment, "meshfmm generate %s %d: %d vertices, %d faces", shape,
             (int)n, (int)m.nv, (int)m.nf);
    cli_signals_install();
    int rc = cli_write_obj(out_path, m.V, m.nv, m.F, m.nf, comment) ? CLI_FAIL : CLI_OK;
    if (rc != CLI_OK && cli_interrupted())
        rc = CLI_EXIT_INTERRUPTED;
    mfmm_gen_free(&m);
    return rc;
}
