// Fleet summary over many robots' calibrations (`umbmark summarize`): the
// fleet's median and robust spread of each parameter, and the robots whose
// parameters or residuals stand out by a robust z-score
//   z = (v - median) / (1.4826 * MAD)      (MAD: median absolute deviation;
// 1.4826 * MAD estimates the standard deviation of normal data, Hampel 1974),
// so a few odd robots cannot hide themselves by inflating the spread.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace umbmark {

/// The quantities compared across the fleet, in reading order.
enum class FleetQuantity {
  kWheelbase,        ///< corrected wheelbase [m]
  kDiameterLeft,     ///< corrected left wheel diameter [m]
  kDiameterRight,    ///< corrected right wheel diameter [m]
  kEd,               ///< diameter ratio error E_d (B&F eq. 4.22)
  kEb,               ///< wheelbase error E_b (B&F eq. 4.24)
  kEmaxBefore,       ///< E_max,syst before calibration [m]
  kResidualAfter,    ///< max final position error after correction [m] (trajectory input)
};
inline constexpr FleetQuantity kFleetQuantities[] = {
    FleetQuantity::kWheelbase, FleetQuantity::kDiameterLeft, FleetQuantity::kDiameterRight, FleetQuantity::kEd,
    FleetQuantity::kEb,        FleetQuantity::kEmaxBefore,   FleetQuantity::kResidualAfter};
/// JSON/CSV key: "wheelbase_m", "wheel_diameter_left_m", ..., "E_d", "E_b",
/// "E_max_syst_m", "residual_after_m".
const char* FleetQuantityKey(FleetQuantity q);

/// True for the quantities that are relative to the parameters the robot's
/// odometry used when its runs were recorded (E_d, E_b, E_max_syst_m): two
/// robots recorded with different robot files have different E_b for the
/// same true wheelbase, so these are compared only between robots with the
/// same recorded parameters. The corrected parameters and the error left
/// after correction are absolute and compared across the whole fleet.
bool FleetQuantityIsRelative(FleetQuantity q);

struct FleetRobot {
  std::string file;
  std::map<FleetQuantity, double> values;  ///< a quantity the calibration did not give is absent
  /// The recorded parameters (robot file) the calibration started from, as a
  /// key (FleetRecordedKey); robots with equal keys are compared in the
  /// relative quantities. Empty: not known (all such robots form one group).
  std::string recorded;
};

/// The group key of recorded parameters: the three values to 9 significant
/// digits (a robot file written twice compares equal; 0.2 and 0.205 do not).
std::string FleetRecordedKey(double wheelbase_m, double diameter_left_m, double diameter_right_m);

struct FleetOptions {
  /// |robust z| above which a robot is an outlier (default 3.5, Iglewicz &
  /// Hoaglin's recommendation for modified z-scores).
  double threshold = 3.5;
  /// Smallest spread used, relative to |median| (identical robots would
  /// otherwise make any difference infinitely significant). Default 1e-4.
  double min_relative_spread = 1e-4;
  /// Empty when valid, else names the bad field.
  std::string Check() const;
};

struct FleetStat {
  std::size_t n = 0;
  double median = 0.0;
  double mad = 0.0;     ///< 1.4826 * median absolute deviation (robust standard deviation)
  double spread = 0.0;  ///< the spread the scores use (mad, floored)
};

struct FleetRobotResult {
  std::map<FleetQuantity, double> z;  ///< robust z-score per quantity present
  /// The statistics each z-score was taken against: the fleet's, or for a
  /// relative quantity those of the robots with the same recorded parameters.
  std::map<FleetQuantity, FleetStat> reference;
  bool outlier = false;
  std::vector<std::string> reasons;  ///< why, in words, largest |z| first
};

struct FleetSummary {
  /// Over every robot that gives the quantity (for a relative quantity a
  /// mix of recorded-parameter groups when there are several; see groups).
  std::map<FleetQuantity, FleetStat> fleet;
  /// Number of distinct recorded-parameter groups (1 for a uniform fleet).
  std::size_t groups = 0;
  std::vector<FleetRobotResult> robots;  ///< in input order
};

/// Needs at least 3 robots for a spread (for a relative quantity: 3 with the
/// same recorded parameters); fewer give no z-score and no outlier.
FleetSummary SummarizeFleet(const std::vector<FleetRobot>& robots, const FleetOptions& options = {});

}  // namespace umbmark
