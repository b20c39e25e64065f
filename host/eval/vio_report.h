#ifndef ROVER_HOST_EVAL_VIO_REPORT_H_
#define ROVER_HOST_EVAL_VIO_REPORT_H_

// The text report of one `rover-eval vio` run.

#include <ostream>

#include "host/eval/vio_run.h"

namespace rover::host::eval {

/// Prints the report of `run`: inputs and setup, the VO health table, the VO
/// timing table, the accuracy table (fused 4-DoF aligned, fused aligned at
/// the start, VO alone SE(3) aligned), the RPE table per segment length, the
/// relative-pose NEES table, and as the last line
///   RESULT frames=N distance_m=... ate_rmse_m=... final_err_m=... final_err_pct=...
///          rpe_trans_pct=... rpe_rot_deg_per_m=... vo_ms_p50=... vo_ms_p99=...
/// ("nan" for what cannot be computed; see AddVioCommand's help for each field).
void PrintVioReport(const VioRun& run, std::ostream& out);

}  // namespace rover::host::eval

#endif  // ROVER_HOST_EVAL_VIO_REPORT_H_
