/* A mesh from the caller's arrays: the options, the checks of the arrays
 * (validate), mfmm_mesh_create (build.c builds, tjunction.c closes
 * T-junctions) and the counts the public API reports. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "build.h"
#include "tjunction.h"

/* Largest coordinate magnitude accepted: lengths are squared once (1e200
 * is far from overflow). */
#define MFMM_MAX_COORDINATE 1e100

void mfmm_mesh_options_init(mfmm_mesh_options *options)
{
    if (!options)
        return;
    memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
    options->max_unfold_steps = 64;
    options->spokes = 1;
}

static mfmm_status validate(const double *vertices, int32_t nv, const int32_t *faces,
                            int32_t nf, mfmm_error *err)
{
    for (int64_t i = 0; i < (int64_t)nv * 3; i++) {
        if (!isfinite(vertices[i]))
            return mfmm_fail(err, MFMM_ERR_NONFINITE_VERTEX, i / 3,
                             "vertex %lld has a coordinate that is NaN or infinite",
                             (long long)(i / 3));
        /* squared lengths must not overflow */
        if (fabs(vertices[i]) > MFMM_MAX_COORDINATE)
            return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, i / 3,
                             "vertex %lld has a coordinate of magnitude %g; coordinates must be "
                             "within +-%g (rescale the mesh)",
                             (long long)(i / 3), fabs(vertices[i]), MFMM_MAX_COORDINATE);
    }
    for (int64_t f = 0; f < nf; f++) {
        const int32_t *t = faces + 3 * f;
        for (int k = 0; k < 3; k++)
            if (t[k] < 0 || t[k] >= nv)
                return mfmm_fail(err, MFMM_ERR_INDEX_OUT_OF_RANGE, f,
                                 "face %lld names vertex %ld, outside [0, %ld) (ids count from 0)",
                                 (long long)f, (long)t[k], (long)nv);
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
            return mfmm_fail(err, MFMM_ERR_REPEATED_VERTEX, f,
                             "face %lld names a vertex twice (%ld, %ld, %ld; ids count from 0)",
                             (long long)f, (long)t[0], (long)t[1], (long)t[2]);
    }
    return MFMM_OK;
}

mfmm_status mfmm_mesh_create(const double *vertices, int32_t nv, const int32_t *faces,
                             int32_t nf, const mfmm_mesh_options *options, mfmm_mesh **out,
                             mfmm_error *err)
{
    mfmm_ok(err);
    if (!out)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "out (the mesh pointer) is NULL");
    *out = NULL;
    if (!vertices || !faces)
        return mfmm_fail(err, MFMM_ERR_NULL_POINTER, -1, "%s is NULL",
                         !vertices ? "vertices" : "faces");
    if (nv < 1 || nf < 1 || nf > MFMM_MAX_FACES || nv > INT32_MAX / 3)
        return mfmm_fail(err, MFMM_ERR_BAD_COUNT, -1,
                         "a mesh needs 1 to %d vertices and 1 to %d faces (got %ld vertices, "
                         "%ld faces)",
                         INT32_MAX / 3, MFMM_MAX_FACES, (long)nv, (long)nf);
    mfmm_mesh_options opt;
    mfmm_mesh_options_init(&opt);
    if (options) {
        if (mfmm_read_options(&opt, options, sizeof opt, "mfmm_mesh_options", err) != MFMM_OK)
            return MFMM_ERR_BAD_ARGUMENT;
    }
    if (opt.max_unfold_steps < 1)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1, "max_unfold_steps must be >= 1 (got %ld)",
                         (long)opt.max_unfold_steps);
    if (opt.spokes != 0 && opt.spokes != 1)
        return mfmm_fail(err, MFMM_ERR_BAD_ARGUMENT, -1, "spokes must be 0 or 1 (got %ld)",
                         (long)opt.spokes);
    mfmm_status st = validate(vertices, nv, faces, nf, err);
    if (st != MFMM_OK)
        return st;
    mfmm_mesh *m = NULL;
    st = mfmm_mesh_build(vertices, nv, faces, nf, &opt, &m, err);
    if (st == MFMM_OK && m->info.n_degenerate_faces > 0)
        st = mfmm_mesh_close_t_junctions(&m, vertices, nv, faces, nf, &opt, err);
    if (st != MFMM_OK)
        return st;
    *out = m;
    return MFMM_OK;
}

mfmm_status mfmm_mesh_get_info(const mfmm_mesh *mesh, mfmm_mesh_info *info)
{
    if (!mesh || !info)
        return MFMM_ERR_NULL_POINTER;
    mfmm_mesh_info all = mesh->info;
    all.struct_size = sizeof all;
    return mfmm_write_info(info, &all, sizeof all);
}

int32_t mfmm_mesh_vertex_count(const mfmm_mesh *mesh)
{
    return mesh ? mesh->nv : 0;
}

int32_t mfmm_mesh_face_count(const mfmm_mesh *mesh)
{
    return mesh ? mesh->nf_in : 0;
}
