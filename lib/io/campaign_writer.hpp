// Writers for the contract's trajectory CSV and campaign manifest, used by
// `import optiodom` and `simulate`. Numbers are written in shortest
// round-trip form, so reading back gives the same doubles.
#pragma once

#include <string>
#include <vector>

#include "core/runs.hpp"

namespace umbmark::io {

/// Trajectory CSV text: run,direction,t_s,ticks_left,ticks_right (or
/// dist_left_m,dist_right_m),x_gt_m,y_gt_m,theta_gt_rad; NaN ground truth is
/// written as empty cells. `comment` lines are written first, prefixed "# ".
std::string FormatTrajectoryCsv(const TrajectoryData& data, const std::vector<std::string>& comment = {});

/// Campaign manifest TOML text for `manifest` (experiment `file` entries are
/// written as given, relative to the manifest).
std::string FormatManifest(const Manifest& manifest, const std::vector<std::string>& comment = {});

}  // namespace umbmark::io
