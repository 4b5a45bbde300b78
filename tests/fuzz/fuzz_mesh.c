/* libFuzzer harness for the mesh readers through their in-memory entry
 * point mfmm_io_parse (src/io): built once per format (FUZZ_FORMAT = OBJ,
 * OFF, PLY, STL, or UNKNOWN for content sniffing). On success the arrays
 * must be sane (indices in range, finite coordinates) and small meshes go
 * on to mfmm_mesh_create. Any crash, sanitizer report or broken invariant
 * (abort) is a finding. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "meshfmm.h"
#include "io/io.h"

#ifndef FUZZ_FORMAT
#define FUZZ_FORMAT MFMM_IO_FMT_UNKNOWN
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *buf = malloc(size + 1); /* the parsers' contract: data[size] == '\0' */
    if (!buf)
        return 0;
    if (size)
        memcpy(buf, data, size);
    buf[size] = '\0';
    mfmm_io_result r = {NULL, 0, NULL, 0};
    mfmm_error err;
    mfmm_status st = mfmm_io_parse(buf, size, FUZZ_FORMAT, &r, &err);
    free(buf);
    if (st != MFMM_OK) {
        if (r.V || r.F || err.message[0] == '\0')
            abort(); /* failure must hand back nothing and say why */
        return 0;
    }
    if (!r.V || !r.F || r.nv < 1 || r.nf < 1)
        abort();
    for (int64_t k = 0; k < 3 * (int64_t)r.nv; k++)
        if (!isfinite(r.V[k]))
            abort();
    for (int64_t k = 0; k < 3 * (int64_t)r.nf; k++)
        if (r.F[k] < 0 || r.F[k] >= r.nv)
            abort();
    if (r.nv <= 4096 && r.nf <= 8192) {
        mfmm_mesh *mesh = NULL;
        if (mfmm_mesh_create(r.V, r.nv, r.F, r.nf, NULL, &mesh, &err) == MFMM_OK)
            mfmm_mesh_destroy(mesh);
    }
    free(r.V);
    free(r.F);
    return 0;
}
