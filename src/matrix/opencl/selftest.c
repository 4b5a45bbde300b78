/* The self-test of an OpenCL program before it goes to or comes from the
 * program cache (selftest.h). */
#ifdef MESHFMM_HAVE_OPENCL

#include <string.h>

#include "base/error.h"
#include "matrix/rows.h"
#include "mesh/mesh.h"
#include "rows.h"
#include "selftest.h"

/* ---- the self-test of a program before it goes to or comes from the cache ----
 * All rows of a small mesh with obtuse corners (a sheared 7 x 6 grid, its
 * vertices jittered so that no two triangles are alike), in float64 and
 * float32, for the march and the window method, against mfmm_solve, bit for
 * bit. A cached binary that fails to
 * make a kernel, to run or to give exactly these rows is not used. (A 5 x 4
 * grid without jitter let a binary built with -cl-fast-relaxed-math
 * -cl-mad-enable pass once the update was written in closed form: its rows
 * happened to round alike there.) */
mfmm_status mfmm_cl_self_test(ocl *cl, mfmm_error *err)
{
    enum { NX = 7, NY = 6, NV = NX * NY, NF = 2 * (NX - 1) * (NY - 1) };
    double xyz[NV * 3];
    int32_t faces[NF * 3];
    for (int j = 0; j < NY; j++)
        for (int i = 0; i < NX; i++) {
            double *p = xyz + 3 * (j * NX + i);
            p[0] = i + 0.7 * j + 0.031 * ((i * 5 + j * 11) % 7);
            p[1] = 0.4 * j + 0.017 * ((i * 3 + j * 7) % 5);
            p[2] = 0.1 * ((i * 7 + j * 3) % 5);
        }
    int32_t *f = faces;
    for (int j = 0; j + 1 < NY; j++)
        for (int i = 0; i + 1 < NX; i++) {
            int32_t a = j * NX + i, b = a + 1, c = a + NX, d = c + 1;
            f[0] = a, f[1] = b, f[2] = d, f[3] = a, f[4] = d, f[5] = c;
            f += 6;
        }
    mfmm_mesh *mesh = NULL;
    mfmm_solver *solver = NULL;
    double ref[NV * NV];
    union {
        double d[NV * NV];
        float f[NV * NV];
    } got;
    int32_t sources[NV];
    mfmm_status st = mfmm_mesh_create(xyz, NV, faces, NF, NULL, &mesh, err);
    if (st == MFMM_OK)
        st = mfmm_solver_create(mesh, &solver);
    for (int k = 0; st == MFMM_OK && k < 4; k++) {
        /* k: the march then the window method, each in float64 then float32 */
        int f64 = !(k & 1);
        mfmm_method method = k < 2 ? MFMM_METHOD_FMM : MFMM_METHOD_WINDOWS;
        mfmm_solve_options so;
        mfmm_solve_options_init(&so);
        so.method = method;
        for (int32_t s = 0; st == MFMM_OK && f64 && s < NV; s++) {
            mfmm_source src;
            memset(&src, 0, sizeof src);
            src.vertex = s;
            sources[s] = mesh->to_internal[s]; /* a job's sources are internal ids */
            src.face = -1;
            st = mfmm_solve(solver, &src, 1, &so, ref + (size_t)s * NV, err);
        }
        if (st != MFMM_OK)
            break;
        mfmm_matrix_options o;
        mfmm_matrix_options_init(&o);
        o.method = method;
        mfmm_matrix_info info;
        memset(&info, 0, sizeof info);
        o.out = &got;
        mfmm_rows_job job;
        memset(&job, 0, sizeof job);
        job.mesh = mesh;
        job.sources = sources;
        job.n_sources = NV;
        job.opt = &o;
        job.info = &info;
        job.elem_size = f64 ? sizeof(double) : sizeof(float);
        job.budget = MFMM_DEFAULT_BUDGET;
        job.width = NV;
        job.slot_bytes = (size_t)NV * job.elem_size;
        int32_t done = 0;
        st = mfmm_cl_run_rows(cl, &job, 0, &done, err);
        for (int i = 0; st == MFMM_OK && i < NV * NV; i++) {
            double r = f64 ? got.d[i] : (double)got.f[i];
            double want = f64 ? ref[i] : (double)(float)ref[i];
            if (memcmp(&r, &want, sizeof r) != 0)
                st = mfmm_fail(err, MFMM_ERR_OPENCL_RUNTIME, i,
                               "OpenCL self-test (%s): row %d vertex %d is %.17g, not %.17g",
                               k < 2 ? "march" : "windows", i / NV, i % NV, r, want);
        }
    }
    mfmm_solver_destroy(solver);
    mfmm_mesh_destroy(mesh);
    return st;
}

#else
typedef int mfmm_opencl_selftest_unused; /* ISO C: no empty translation unit */
#endif /* MESHFMM_HAVE_OPENCL */
