// meshfmm.h from C++: extern "C" linkage, the option structs' _init
// functions, output structs, and a solve on the unit square (prints as the
// README example).
#include <meshfmm.h>

#include <cstdio>
#include <vector>

int main()
{
    const double vertices[4 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    const int32_t faces[2 * 3] = {0, 1, 3, 0, 3, 2};
    mfmm_mesh_options mo;
    mfmm_mesh_options_init(&mo);
    mfmm_mesh *mesh = nullptr;
    mfmm_error err;
    if (mfmm_mesh_create(vertices, 4, faces, 2, &mo, &mesh, &err) != MFMM_OK) {
        std::fprintf(stderr, "mesh: %s\n", err.message);
        return 1;
    }
    mfmm_solver *solver = nullptr;
    if (mfmm_solver_create(mesh, &solver) != MFMM_OK)
        return 1;
    mfmm_solve_options so;
    mfmm_solve_options_init(&so);
    mfmm_source source = mfmm_source();
    source.vertex = 0;
    source.face = -1;
    std::vector<double> d(4);
    mfmm_status st = mfmm_solve(solver, &source, 1, &so, d.data(), &err);
    if (st != MFMM_OK) {
        std::fprintf(stderr, "solve: %s\n", err.message);
        return 1;
    }
    // an output struct from C++ (no designated initializers in C++11)
    mfmm_mesh_info mi = mfmm_mesh_info();
    mi.struct_size = sizeof mi;
    if (mfmm_mesh_get_info(mesh, &mi) != MFMM_OK || mi.n_vertices != 4)
        return 1;
    // the same row through the const options and the info of a matrix job
    std::vector<double> row(4);
    mfmm_matrix_options xo;
    mfmm_matrix_options_init(&xo);
    xo.backend = MFMM_BACKEND_SERIAL;
    xo.dtype = MFMM_FLOAT64;
    xo.out = row.data();
    const int32_t first = 0;
    mfmm_matrix_info info = mfmm_matrix_info();
    info.struct_size = sizeof info;
    if (mfmm_distance_matrix(mesh, &first, 1, &xo, &info, &err) != MFMM_OK ||
        info.backend_used != MFMM_BACKEND_SERIAL || row != d)
        return 1;
    for (int v = 0; v < 4; v++)
        std::printf("%d %.12f\n", v, d[v]);
    mfmm_solver_destroy(solver);
    mfmm_mesh_destroy(mesh);
    return 0;
}
