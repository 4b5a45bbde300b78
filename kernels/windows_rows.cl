/*
 * The window method's rows (MFMM_METHOD_WINDOWS), many sources at once: one
 * work-item runs one source's solve (src/exact/slots_core.h, the C core's
 * own propagation) and writes that source's row. Each item's arrays lie in
 * its own slice of one workspace buffer (sl_attach). With targets
 * (n_targets > 0) a row stops once its targets settle, as the serial solve
 * does, and writes only their columns.
 *
 * Built without -cl-mad-enable / -cl-fast-relaxed-math; local_update.h sets
 * FP_CONTRACT OFF, so rows equal the C core's bit for bit in float64.
 * The host embeds this file with the #include lines replaced by the headers.
 */
#include "exact/slots_core.h"

/* The solve from sources[first + i] in item i's slice of ws; cost_location
 * 0: no cost (fcost and vcost unread), 1: per vertex (vcost, the vertices'
 * costs), 2: per face; fcost: the records' costs, relative to the least
 * cost (mfmm_slots_face_cost), in whose units max_distance is and the
 * solve's values are. */
inline void mfmm_windows_row(sl_state *s, int nv, int nf, __global const ex_face *fr,
                             __global const int *vf_offset, __global const int *vf_corner,
                             __global const int *face_in, __global const int *nm_he,
                             __global const int *nm_next, int n_nm,
                             __global const uchar *flat, int source, double max_distance,
                             __global const int *targets, int n_targets,
                             __global char *ws, __global const double *fcost,
                             __global const double *vcost, int cost_location)
{
    s->nv = nv;
    s->nf = nf;
    s->fr = fr;
    s->vf_offset = vf_offset;
    s->vf_corner = vf_corner;
    s->face_in = face_in;
    s->nm_he = nm_he;
    s->nm_next = nm_next;
    s->n_nm = n_nm;
    s->flat = flat;
    s->K = 2;
    s->fcost = cost_location != 0 ? fcost : 0;
    s->h.cost = cost_location == 1 ? vcost : 0;
    s->h.cost_location = cost_location == 1 ? 1 : 0;
    sl_attach(s, ws);
    sl_solve_vertex(s, source, max_distance, targets, n_targets);
}

/* windows_rows_f64 and windows_rows_f32: a row per item in the caller's
 * vertex order (order: internal id of each input vertex), or the target
 * columns, as OUT_T (float32: rounded to nearest); the solve's values times
 * scale (the least cost; 1.0 with none). */
#define MFMM_WINDOWS_ROWS(NAME, OUT_T)                                                         \
    __kernel void NAME(int nv, int nf, __global const ex_face *fr,                             \
                       __global const int *vf_offset, __global const int *vf_corner,           \
                       __global const int *face_in, __global const int *nm_he,                 \
                       __global const int *nm_next, int n_nm, __global const uchar *flat,      \
                       __global const int *sources, int first, int count,                      \
                       double max_distance, __global const int *targets, int n_targets,        \
                       __global const int *order, __global char *ws, ulong ws_stride,          \
                       __global OUT_T *out, __global const double *fcost,                      \
                       __global const double *vcost, int cost_location, double scale)          \
    {                                                                                          \
        int i = (int)get_global_id(0);                                                         \
        if (i >= count)                                                                        \
            return;                                                                            \
        sl_state s;                                                                            \
        mfmm_windows_row(&s, nv, nf, fr, vf_offset, vf_corner, face_in, nm_he, nm_next, n_nm,  \
                         flat, sources[first + i], max_distance, targets, n_targets,           \
                         ws + (ulong)i * ws_stride, fcost, vcost, cost_location);              \
        int width = n_targets > 0 ? n_targets : nv;                                            \
        __global OUT_T *row = out + (ulong)i * (ulong)width;                                   \
        for (int j = 0; j < width; j++)                                                        \
            row[j] = (OUT_T)(scale * sl_value(&s, n_targets > 0 ? targets[j] : order[j],       \
                                              max_distance));                                  \
    }

MFMM_WINDOWS_ROWS(windows_rows_f64, double)
MFMM_WINDOWS_ROWS(windows_rows_f32, float)
