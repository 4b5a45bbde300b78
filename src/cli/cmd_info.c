/* meshfmm info MESH [--json] [--max-unfold-steps N] */
#include <stdio.h>
#include <string.h>

#include "cli.h"

static void help(FILE *out)
{
    fprintf(out,
            "usage: meshfmm info MESH [--json] [--max-unfold-steps N]\n\n"
            "Reads MESH (.obj, .off, .ply, .stl) and prints its counts: vertices, faces, edges,\n"
            "boundary and non-manifold edges, components, unreferenced vertices,\n"
            "degenerate faces, obtuse corners, virtual edges found by unfolding and\n"
            "unfolding failures, edge lengths, the bounding-box diagonal, the bytes\n"
            "the built mesh holds (mfmm_mesh_memory), and coincident vertices (at the\n"
            "position of another: texture seams, unmerged corners) with the components\n"
            "once they are welded; when there are any, a note on standard error.\n\n"
            "  --json                 one JSON object instead of text\n"
            "  --max-unfold-steps N   faces one unfolding walk may cross (default 64)\n"
            "  -h, --help             this text\n");
}

/* Prints a path as a JSON string (escaping quotes, backslashes, controls). */
static void json_string(const char *s)
{
    putchar('"');
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            printf("\\%c", c);
        else if (c < 0x20)
            printf("\\u%04x", c);
        else
            putchar(c);
    }
    putchar('"');
}

int cmd_info(int argc, char **argv)
{
    const char *path = NULL;
    int json = 0;
    mfmm_mesh_options opt;
    mfmm_mesh_options_init(&opt);
    static const struct option longopts[] = {
        {"help", no_argument, NULL, 'h'},
        {"json", no_argument, NULL, OPT_JSON},
        {"max-unfold-steps", required_argument, NULL, OPT_MAX_UNFOLD_STEPS},
        {NULL, 0, NULL, 0}};
    int c;
    opterr = 0;
    uint32_t seen = 0;
    while ((c = getopt_long(argc, argv, ":h", longopts, NULL)) != -1) {
        if (cli_once("info", c, &seen) != CLI_OK)
            return CLI_USAGE;
        if (c == 'h') {
            help(stdout);
            return CLI_OK;
        } else if (c == OPT_JSON) {
            json = 1;
        } else if (c == OPT_MAX_UNFOLD_STEPS) {
            if (!cli_parse_int32(optarg, &opt.max_unfold_steps) || opt.max_unfold_steps < 1)
                return cli_usage_error("info", "--max-unfold-steps needs an integer >= 1");
        } else {
            return cli_getopt_error("info", c, argv);
        }
    }
    for (int i = optind; i < argc; i++) {
        if (path)
            return cli_usage_error("info", "one mesh at a time ('%s' is extra)", argv[i]);
        path = argv[i];
    }
    if (!path)
        return cli_usage_error("info", "no mesh file given");

    mfmm_mesh *mesh = cli_load_mesh(path, &opt, NULL);
    if (!mesh)
        return CLI_FAIL;
    mfmm_mesh_info m = {.struct_size = sizeof m};
    mfmm_status st = mfmm_mesh_get_info(mesh, &m);
    /* the built mesh's bytes (the tables a first solve adds are 0 here) */
    const char *names[32];
    size_t bytes[32], mesh_bytes = 0;
    int n_arrays = mfmm_mesh_memory(mesh, names, bytes, 32);
    for (int i = 0; i < n_arrays && i < 32; i++)
        mesh_bytes += bytes[i];
    mfmm_mesh_destroy(mesh);
    if (st != MFMM_OK) {
        cli_error("%s: %s", path, mfmm_status_string(st));
        return CLI_FAIL;
    }
    if (json) {
        printf("{\"file\": ");
        json_string(path);
        printf(", \"vertices\": %d, \"faces\": %d, \"edges\": %d, \"boundary_edges\": %d, "
               "\"nonmanifold_edges\": %d, \"components\": %d, \"unreferenced_vertices\": %d, "
               "\"degenerate_faces\": %d, \"duplicate_faces\": %d, \"obtuse_corners\": %d, \"virtual_edges\": %d, "
               "\"unfold_failures\": %d, \"min_edge_length\": %.17g, "
               "\"max_edge_length\": %.17g, \"mean_edge_length\": %.17g, "
               "\"bbox_diagonal\": %.17g, \"mesh_bytes\": %.0f, \"coincident_vertices\": %d, "
               "\"welded_components\": %d}\n",
               (int)m.n_vertices, (int)m.n_faces, (int)m.n_edges, (int)m.n_boundary_edges,
               (int)m.n_nonmanifold_edges, (int)m.n_components, (int)m.n_unreferenced_vertices,
               (int)m.n_degenerate_faces, (int)m.n_duplicate_faces, (int)m.n_obtuse_corners,
               (int)m.n_virtual_edges,
               (int)m.n_unfold_failures, m.min_edge_length, m.max_edge_length,
               m.mean_edge_length, m.bbox_diagonal, (double)mesh_bytes,
               (int)m.n_coincident_vertices, (int)m.n_welded_components);
    } else {
        printf("file:                  %s\n", path);
        printf("vertices:              %d\n", (int)m.n_vertices);
        printf("faces:                 %d\n", (int)m.n_faces);
        printf("edges:                 %d\n", (int)m.n_edges);
        printf("boundary edges:        %d\n", (int)m.n_boundary_edges);
        printf("non-manifold edges:    %d\n", (int)m.n_nonmanifold_edges);
        printf("components:            %d\n", (int)m.n_components);
        printf("unreferenced vertices: %d\n", (int)m.n_unreferenced_vertices);
        printf("coincident vertices:   %d\n", (int)m.n_coincident_vertices);
        printf("components if welded:  %d\n", (int)m.n_welded_components);
        printf("degenerate faces:      %d\n", (int)m.n_degenerate_faces);
        printf("duplicate faces:       %d\n", (int)m.n_duplicate_faces);
        printf("obtuse corners:        %d\n", (int)m.n_obtuse_corners);
        printf("virtual edges:         %d\n", (int)m.n_virtual_edges);
        printf("unfold failures:       %d\n", (int)m.n_unfold_failures);
        printf("edge length min:       %.6g\n", m.min_edge_length);
        printf("edge length max:       %.6g\n", m.max_edge_length);
        printf("edge length mean:      %.6g\n", m.mean_edge_length);
        printf("bbox diagonal:         %.6g\n", m.bbox_diagonal);
        printf("mesh memory:           %.1f MB (%.0f bytes per vertex; solves add the\n"
               "                       march's spokes and exact tables, up to about 730 more)\n",
               (double)mesh_bytes / 1e6, (double)mesh_bytes / (m.n_vertices > 0 ? m.n_vertices : 1));
    }
    if (m.n_coincident_vertices > 0)
        fprintf(stderr,
                "meshfmm info: note: %d coincident vertices (at the position of another: texture "
                "seams or unmerged corners) cut the surface into %d component(s), %d once "
                "welded; distances and paths do not cross the cuts. Weld them first: "
                "meshfmm weld MESH -o WELDED.obj --map MAP.txt (in Python: "
                "meshfmm.Mesh(V, F, weld=True)).\n",
                (int)m.n_coincident_vertices, (int)m.n_components, (int)m.n_welded_components);
    if (fflush(stdout) != 0) {
        cli_error("cannot write to standard output");
        return CLI_FAIL;
    }
    return CLI_OK;
}
