/* One run of the exact solver on a workspace (run.c): sources checked,
 * windows propagated until the queue is empty or past a bound, the
 * distances finished along edges where a run stops. */
#ifndef MFMM_EXACT_RUN_H
#define MFMM_EXACT_RUN_H

#include "state.h"

/* ex_run_once across non-manifold edges; where its windows pass their
 * budget (ex_over_budget), again with those edges as walls: upper bounds
 * there, the solver's behaviour before it crossed them (mfmm_exact_info's
 * nonmanifold_walls says which). A run past its budget otherwise stops, and
 * paths along edges finish it (ex_relax_edges): a defect's values are then
 * too long, never too short, and the solve ends. */
mfmm_status ex_run(mfmm_exact_ws *ws, const mfmm_source *sources, int32_t n_sources,
                          double max_d, size_t memory_limit);

void ex_fill_info(const mfmm_exact_ws *ws, mfmm_exact_info *info);

/* Sources as mfmm_solve checks them, and not in a face this solver skips. */
mfmm_status ex_check_sources(const mfmm_exact_ws *ws, const mfmm_source *sources,
                                    int32_t n_sources, mfmm_error *err);

#endif
