// In-memory form of the data files (docs/formats.md):
// endpoint runs (return errors only) and trajectory runs (encoder samples with
// optional ground truth). Readers live in formats/; this header only holds data.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "core/robot.hpp"
#include "core/pose2.hpp"

namespace umbmark {

/// A square's direction as written in a file: `cw`/`ccw` in any case become
/// "cw"/"ccw"; any other text (free experiments) is kept as written.
inline std::string CanonicalDirection(std::string_view text) {
  auto equals_lower = [&](std::string_view word) {
    if (text.size() != word.size()) return false;
    for (std::size_t i = 0; i < word.size(); ++i) {
      const char c = text[i] >= 'A' && text[i] <= 'Z' ? static_cast<char>(text[i] - 'A' + 'a') : text[i];
      if (c != word[i]) return false;
    }
    return true;
  };
  if (equals_lower("cw")) return "cw";
  if (equals_lower("ccw")) return "ccw";
  return std::string(text);
}

/// The return error of one run, e = absolute - odometry (Borenstein & Feng
/// eq. 3.1) in the run's start frame: a row of an endpoint CSV, or computed
/// from a trajectory (evaluation/return_error.hpp). The one record for it.
struct ReturnError {
  std::string run;        ///< run id as written in the file
  std::string direction;  ///< "cw", "ccw", or free text
  double ex_m = 0.0;
  double ey_m = 0.0;
  std::optional<double> etheta_rad;  ///< empty cell -> not measured; wrapped to (-pi, pi]
  std::size_t line = 0;              ///< 1-based source line (first sample of a trajectory run)
  /// Ground-truth total rotation [rad] (computed from a trajectory only).
  std::optional<double> gt_total_rotation_rad;
};

/// One run of a trajectory CSV, samples in file order.
struct TrajectoryRun {
  std::string run;
  std::string direction;
  std::vector<double> t_s;
  /// Cumulative wheel travel [m] for each sample. When the file gives ticks,
  /// the reader leaves these empty and fills ticks_*; call
  /// ComputeWheelTravel() (trajectory.hpp) to convert with a robot.
  std::vector<double> dist_left_m, dist_right_m;
  std::vector<std::int64_t> ticks_left, ticks_right;  ///< cumulative counts
  /// Ground truth per sample; NaN where not measured.
  std::vector<double> gt_x_m, gt_y_m, gt_theta_rad;
  std::vector<std::size_t> lines;  ///< 1-based source line of each sample

  bool has_ticks() const { return !ticks_left.empty(); }
  std::size_t size() const { return t_s.size(); }
  bool HasGroundTruth(std::size_t i) const {
    return !std::isnan(gt_x_m[i]) && !std::isnan(gt_y_m[i]) && !std::isnan(gt_theta_rad[i]);
  }
  Pose2 GroundTruth(std::size_t i) const { return {gt_x_m[i], gt_y_m[i], gt_theta_rad[i]}; }
};

struct EndpointData {
  std::string path;
  std::vector<ReturnError> runs;
};

struct TrajectoryData {
  std::string path;
  std::vector<TrajectoryRun> runs;
};

/// The data of one experiment: return errors or logged trajectories.
using ExperimentData = std::variant<EndpointData, TrajectoryData>;

/// Experiment kinds of the campaign manifest.
enum class ExperimentKind { kSquare, kBackAndForth, kFree };

inline const char* ExperimentKindToString(ExperimentKind k) {
  switch (k) {
    case ExperimentKind::kSquare: return "square";
    case ExperimentKind::kBackAndForth: return "back_and_forth";
    case ExperimentKind::kFree: return "free";
  }
  return "?";
}

struct Experiment {
  ExperimentKind kind = ExperimentKind::kSquare;
  double side_m = 0.0;      ///< square only
  double distance_m = 0.0;  ///< back_and_forth only
  std::string file;         ///< as written in the manifest (relative to it)
  std::string resolved_file;  ///< path usable from the current directory
};

/// Ground-truth measurement noise, when the manifest states it.
struct GroundTruthNoise {
  double sigma_xy_m = 0.0;
  double sigma_theta_rad = 0.0;
};

struct Manifest {
  std::string path;
  RobotParams robot;
  std::vector<Experiment> experiments;
  std::optional<GroundTruthNoise> ground_truth;
};

}  // namespace umbmark
