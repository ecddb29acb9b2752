// Reader for the contract's trajectory CSV (one row per encoder sample):
//   run,direction,t_s,ticks_left,ticks_right,x_gt_m,y_gt_m,theta_gt_rad
// ticks_* are cumulative signed 64-bit counts; instead dist_left_m,
// dist_right_m (cumulative travel) may be given. Ground-truth cells may be
// empty per row; each run needs ground truth at its first and last sample.
// Rows of one run must be contiguous and t_s strictly increasing in a run.
#pragma once

#include <string>
#include <string_view>

#include "core/runs.hpp"

namespace umbmark::io {

/// Reads a trajectory CSV file. Throws InputError (file, line, column) on any
/// fault (see ParseTrajectoryCsv).
TrajectoryData ReadTrajectoryCsv(const std::string& path);

/// Same, from text in memory; `name` is used in error messages. Faults:
/// missing/duplicated/unknown-unit column, text or NaN/Inf in a number,
/// truncated row, non-increasing time, a run split over non-adjacent rows,
/// missing ground truth at a run's first/last sample, an encoder jump that
/// can only be a counter wrap (|delta| >= 2^30 ticks between two samples).
TrajectoryData ParseTrajectoryCsv(std::string_view text, const std::string& name);

}  // namespace umbmark::io
