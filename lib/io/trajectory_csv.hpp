// Reader for the contract's trajectory CSV (one row per encoder sample):
//   run,direction,t_s,ticks_left,ticks_right,x_gt_m,y_gt_m,theta_gt_rad
// ticks_* are cumulative signed 64-bit counts; instead dist_left_m,
// dist_right_m (cumulative travel) may be given. Ground-truth cells may be
// empty per row (all three together); each run needs ground truth at its
// first and last sample. A run is identified by its run id: its rows must be
// contiguous, its direction constant and t_s strictly increasing. Unknown
// columns are an error (a typo must not silently drop data).
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
/// missing ground truth at a run's first/last sample, partial ground truth in
/// a row, a direction change within a run, a tick count that is not a signed
/// 64-bit integer, an encoder jump that can only be a counter wrap
/// (|delta| >= 2^30 ticks between two samples), an empty file or no data rows.
/// Designed for large logs (one pass, no allocation per cell; several
/// hundred MB/s, see bench/parse_bench.sh).
TrajectoryData ParseTrajectoryCsv(std::string_view text, const std::string& name);

}  // namespace umbmark::io
