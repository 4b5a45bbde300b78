/*
 * Many sources at once: one work-item runs one source's full heap march
 * (src/march/march.h, the serial core's own code) and writes that source's row.
 * Per-item workspaces are item-contiguous slices of nv entries. With
 * targets (n_targets > 0) a row marches until its targets settle (the
 * serial solver's early stop, the same flags) and writes only their columns.
 *
 * A row starts from its source's vertex, or (exact start, n_seeds > 0) from
 * the seeds the host computed for it (src/start/seed.h): for the batch's row
 * i, vertices seeds[j] at values seed_value[j] for j in [seeds[i],
 * seeds[i + 1]), seeded in that order, as the serial solver does.
 *
 * Built without -cl-mad-enable / -cl-fast-relaxed-math; local_update.h sets
 * FP_CONTRACT OFF, so rows equal the C core's bit for bit in float64.
 * The host embeds this file with the #include lines replaced by the headers.
 */
#include "march/march.h"

/* The march for source sources[first + gid], with T in T_row. */
inline void mfmm_row_march(int nv, __global const int *wedge_offset,
                           __global const int *wedge,
                           __global const mfmm_face *faces, __global const double *cost,
                           int cost_location, double max_distance, int unfolding,
                           int source, __global double *T_row, __global uchar *label,
                           __global double *heap_key, __global int *heap_vertex,
                           __global int *heap_pos, __global const int *strip,
                           __global const double *uniform,
                           __global const int *targets, int n_targets,
                           __global const mfmm_virt *virts, __global const int *strip_offset,
                           __global const int *seeds, int row,
                           __global const double *seed_value,
                           __global const int *virt_first, int use_spokes,
                           __global const int *spoke_offset,
                           __global const mfmm_spoke *spokes)
{
    mfmm_march_mesh m;
    m.nv = nv;
    m.wedge_offset = wedge_offset;
    m.wedge = wedge;
    m.faces = faces;
    m.virts = virts;
    m.virt_first = virt_first;
    m.strip_offset = strip_offset;
    m.strip = strip;
    /* the spokes at F = 1 with unfolding, as the serial solver (solve.c) */
    m.spoke_offset = use_spokes ? spoke_offset : 0;
    m.spokes = use_spokes ? spokes : 0;
    mfmm_march_state s;
    s.T = T_row;
    s.label = label;
    s.heap_key = heap_key;
    s.heap_vertex = heap_vertex;
    s.heap_pos = heap_pos;
    s.heap_size = 0;
    s.cost = cost;
    s.cost_location = cost_location;
    s.max_distance = max_distance;
    s.unfolding = unfolding;
    s.targets_left = 0;
    s.uniform = uniform;
    s.touched = 0; /* no list: the per-item workspace resets all nv */
    s.n_touched = 0;
    mfmm_march_reset(&s, nv);
    for (int j = 0; j < n_targets; j++) { /* as mfmm_solve: flags, then seeds */
        int t = targets[j];
        if (!(label[t] & MFMM_TARGET)) {
            label[t] = (uchar)(label[t] | MFMM_TARGET);
            s.targets_left++;
        }
    }
    if (seeds) {
        int j = seeds[row];
        mfmm_march_seed_patch(&s, &m, seeds + j, seed_value + j, seeds[row + 1] - j, 0.0, 1.0);
    } else {
        mfmm_march_seed(&s, source, 0.0);
    }
    mfmm_march_run(&s, &m);
}

/* float64 rows: T in a workspace slice, the row gathered from it in the
 * caller's vertex order (order: internal id of each input vertex, as
 * src/mesh/order.h), or the target columns copied out. */
__kernel void fmm_rows_f64(int nv, __global const int *wedge_offset,
                           __global const int *wedge,
                           __global const mfmm_face *faces, __global const double *cost,
                           int cost_location, double max_distance, int unfolding,
                           __global const int *sources, int first, int count,
                           __global uchar *label_ws, __global double *key_ws,
                           __global int *vert_ws, __global int *pos_ws, __global double *out,
                           __global const int *strip, __global const double *uniform,
                           __global const int *targets, int n_targets, __global double *T_ws,
                           __global const int *order, __global const mfmm_virt *virts,
                           __global const int *strip_offset,
                           int n_seeds, __global const int *seeds,
                           __global const double *seed_value,
                           __global const int *virt_first, int use_spokes,
                           __global const int *spoke_offset,
                           __global const mfmm_spoke *spokes)
{
    int i = (int)get_global_id(0);
    if (i >= count)
        return;
    ulong o = (ulong)i * (ulong)nv;
    __global double *T = T_ws + o;
    mfmm_row_march(nv, wedge_offset, wedge, faces, cost, cost_location,
                   max_distance, unfolding, sources[first + i], T, label_ws + o,
                   key_ws + o, vert_ws + o, pos_ws + o, strip, uniform, targets, n_targets,
                   virts, strip_offset, n_seeds > 0 ? seeds : 0, i, seed_value,
                   virt_first, use_spokes, spoke_offset, spokes);
    if (n_targets > 0) {
        __global double *row = out + (ulong)i * (ulong)n_targets;
        for (int j = 0; j < n_targets; j++)
            row[j] = T[targets[j]];
        return;
    }
    __global double *row = out + o;
    for (int v = 0; v < nv; v++)
        row[v] = T[order[v]];
}

/* float32 rows: T in a workspace slice, converted (round to nearest) in
 * the caller's vertex order (as float64). */
__kernel void fmm_rows_f32(int nv, __global const int *wedge_offset,
                           __global const int *wedge,
                           __global const mfmm_face *faces, __global const double *cost,
                           int cost_location, double max_distance, int unfolding,
                           __global const int *sources, int first, int count,
                           __global uchar *label_ws, __global double *key_ws,
                           __global int *vert_ws, __global int *pos_ws,
                           __global double *T_ws, __global float *out,
                           __global const int *strip, __global const double *uniform,
                           __global const int *targets, int n_targets, __global double *unused,
                           __global const int *order, __global const mfmm_virt *virts,
                           __global const int *strip_offset,
                           int n_seeds, __global const int *seeds,
                           __global const double *seed_value,
                           __global const int *virt_first, int use_spokes,
                           __global const int *spoke_offset,
                           __global const mfmm_spoke *spokes)
{
    int i = (int)get_global_id(0);
    if (i >= count)
        return;
    ulong o = (ulong)i * (ulong)nv;
    __global double *T = T_ws + o;
    mfmm_row_march(nv, wedge_offset, wedge, faces, cost, cost_location,
                   max_distance, unfolding, sources[first + i], T, label_ws + o,
                   key_ws + o, vert_ws + o, pos_ws + o, strip, uniform, targets, n_targets,
                   virts, strip_offset, n_seeds > 0 ? seeds : 0, i, seed_value,
                   virt_first, use_spokes, spoke_offset, spokes);
    (void)unused;
    if (n_targets > 0) {
        __global float *row = out + (ulong)i * (ulong)n_targets;
        for (int j = 0; j < n_targets; j++)
            row[j] = (float)T[targets[j]];
        return;
    }
    __global float *row = out + o;
    for (int v = 0; v < nv; v++)
        row[v] = (float)T[order[v]];
}
