/* The defaults of a matrix job's options, and the backends' names. */
#include <math.h>
#include <string.h>

#include "meshfmm.h"

const char *mfmm_backend_name(mfmm_backend backend)
{
    switch (backend) {
    case MFMM_BACKEND_AUTO: return "auto";
    case MFMM_BACKEND_SERIAL: return "serial";
    case MFMM_BACKEND_THREADS: return "threads";
    case MFMM_BACKEND_OPENCL: return "opencl";
    }
    return "unknown";
}

void mfmm_matrix_options_init(mfmm_matrix_options *options)
{
    if (!options)
        return;
    memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
    options->backend = MFMM_BACKEND_AUTO;
    options->dtype = MFMM_FLOAT32;
    options->cost = NULL;
    options->cost_location = MFMM_COST_NONE;
    options->max_distance = INFINITY;
    options->unfolding = 1;
    options->n_threads = 0;
    options->memory_limit = 0;
    options->out = NULL;
    options->on_rows = NULL;
    options->user = NULL;
    options->opencl = NULL;
    options->exact_start_radius = MFMM_EXACT_START_AUTO;
    options->method = MFMM_METHOD_FMM;
}
