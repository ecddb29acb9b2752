// Turns the contract's data files into fit-noise runs (wheel_noise_fit.hpp):
//  - endpoint CSV + the commanded path of every run (e.g. D forward then D
//    back, `--distance D`): the covariance basis from the closed forms
//    along that path;
//  - trajectory CSV: the path from the ticks (ComputeWheelTravel), the
//    covariance basis from Kelly's transition-matrix form along it, and the
//    return error from ground truth at the first and last sample
//    (e = GT_end in the GT_start frame - odometry end, contract eq. 3.1).
// Runs are grouped as `group_prefix + direction`; each group gets its own
// systematic mean in the fit.
#pragma once

#include <string>
#include <vector>

#include "core/robot.hpp"
#include "core/runs.hpp"
#include "error_models/wheel_noise_fit.hpp"
#include "error_models/path_spec.hpp"

namespace umbmark {

struct NoiseFitInputOptions {
  /// The reference's noise per measured pose (start and end each) [m, rad].
  double sigma_xy_m = 0.0;
  double sigma_theta_rad = 0.0;
  /// Include the second-order heading term (second_order.hpp).
  bool second_order = true;
};

/// One run per endpoint row; `path` is what every run drove (wheelbase_m
/// resolves turn segments). Rows without etheta use the x-y block.
std::vector<WheelNoiseFitRun> NoiseRunsFromEndpoints(const EndpointData& data, const std::vector<PathSegment>& path,
                                                double wheelbase_m, const std::string& group_prefix,
                                                const NoiseFitInputOptions& options);

/// One run per trajectory run that has ground truth at its first and last
/// sample (others are counted in *skipped). Throws InputError (data.path)
/// when ticks cannot be converted (no ticks_per_rev).
std::vector<WheelNoiseFitRun> NoiseRunsFromTrajectories(const TrajectoryData& data, const RobotParams& robot,
                                                   const std::string& group_prefix,
                                                   const NoiseFitInputOptions& options, int* skipped = nullptr);

}  // namespace umbmark
