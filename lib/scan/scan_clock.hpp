// The scan clock against the wheels' (as the import does for motion capture):
// the time of a scan's first ray, in the wheels' clock, is its stamp plus an
// offset. A lidar driver stamps the first ray, the end of the sweep, or the
// time it published; a lidar on another computer has another clock. Two
// steps:
//
//   coarse  the scans' own motion signal, the median range change between
//           consecutive scans (a few mm when still, centimetres when
//           moving), correlated with the wheels' motion over the same
//           intervals shifted by the offset (translation plus a 2 m lever
//           times the rotation); the best of a grid over +-search, refined
//           on a 2 ms grid around it. Needs only the scans, before any
//           registration: the still stretches around each run depend on it.
//   fine    after registration, the scans' heading along each run against
//           the wheel odometry's, shifted by a small correction (1 ms grid
//           over +-window), the odometry's heading scaled by a free factor
//           (the wheelbase error).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace umbmark::scan {

/// Two consecutive scans: their times (stamps) and the median |range
/// change| over the beams both returned.
struct ScanChange {
  std::int64_t t_prev_ns = 0, t_ns = 0;
  double median_change_m = 0.0;
};

/// The wheels' cumulative motion at their sample times: travel of the axle
/// plus lever_m times the rotation (both as absolute values, summed).
struct WheelMotion {
  std::vector<std::int64_t> t_ns;
  std::vector<double> cumulative;
  /// From cumulative left/right wheel travel and the wheelbase.
  static WheelMotion FromTravel(const std::vector<std::int64_t>& t_ns, const std::vector<double>& left_m,
                                const std::vector<double>& right_m, double wheelbase_m, double lever_m = 2.0);
  double At(std::int64_t t) const;  ///< linear between samples, constant outside
};

struct ClockOptions {
  double search_s = 2.5;       ///< coarse search over [-search, +search]
  double coarse_step_s = 0.02;
  double fine_step_s = 0.002;
  /// The coarse peak must reach this correlation, else the offset is not
  /// determined (too little motion, or a scene whose ranges barely change).
  double min_correlation = 0.5;
  std::string Validate() const;
};

struct ClockEstimate {
  double offset_s = 0.0;       ///< first ray = stamp + offset (wheels' clock)
  double correlation = 0.0;    ///< at the offset
  bool determined = false;
};

/// Coarse step. `changes` in time order.
ClockEstimate EstimateClockCoarse(const std::vector<ScanChange>& changes, const WheelMotion& wheels,
                                  const ClockOptions& options = {});

/// One run's scan headings (relative to the run's start, unwrapped) and the
/// wheel odometry's at the same times shifted by an offset.
struct HeadingTrack {
  std::vector<std::int64_t> t_ns;         ///< scan times (first rays, with the coarse offset)
  std::vector<double> scan_heading_rad;   ///< relative to the run's start
};

/// Fine step: the correction (seconds, to add to the scan times) that best
/// aligns the scan headings with `odometry_heading(t)` (any fixed frame;
/// relative to each run's start inside) over +-window_s at step_s, and
/// whether it lies inside the window (false: no correction).
struct FineClock {
  double correction_s = 0.0;
  bool determined = false;
  double rms_rad = 0.0;  ///< heading residual at the correction
};
FineClock RefineClock(const std::vector<HeadingTrack>& runs, const std::vector<std::int64_t>& run_start_ns,
                      const std::function<double(std::int64_t)>& odometry_heading, double window_s = 0.1,
                      double step_s = 0.001);

}  // namespace umbmark::scan
