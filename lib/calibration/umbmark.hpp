// Classic UMBmark calibration (Borenstein & Feng, sections 3-4): centres of
// gravity of the CW and CCW return errors, Type A (alpha) and Type B (beta)
// errors, E_b and E_d, and the correction factors c_L, c_R.
//
// All results are RELATIVE to the parameters the runs were recorded with:
// corrected wheelbase = E_b * b, corrected diameters = c_L * D_L, c_R * D_R
// (c_R / c_L = E_d, mean diameter kept), so a second pass on a compensated
// robot composes.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/robot.hpp"
#include "evaluation/return_error.hpp"
#include "model/true_robot.hpp"

namespace umbmark {

/// Which centre-of-gravity coordinate the alpha/beta formulas use.
enum class UmbmarkEstimator {
  kX,    ///< eqs. 4.20a, 4.24a (the OptiOdom reference implementation)
  kY,    ///< eqs. 4.20b, 4.24b
  kMean  ///< both, E_d and E_b averaged (the paper's footnote 2)
};
const char* UmbmarkEstimatorToString(UmbmarkEstimator e);
std::optional<UmbmarkEstimator> UmbmarkEstimatorFromString(std::string_view s);

struct UmbmarkOptions {
  /// Square side L [m]. Required, > 0.
  double side_m = 0.0;
  /// Default kMean (contract).
  UmbmarkEstimator estimator = UmbmarkEstimator::kMean;
  /// Use the corrected wheelbase E_b*b as b in eq. 4.22 (as the OptiOdom
  /// reference does); false uses the recorded one. They differ by O(1e-6).
  bool ed_with_corrected_wheelbase = true;
  /// A run whose robust score (distance from its direction's median return
  /// error in units of the robust per-axis sigma, pooled over both
  /// directions) exceeds this is flagged.
  /// Default 3.5: P(score > 3.5) = exp(-3.5^2/2) = 0.2% for Gaussian scatter.
  double outlier_threshold = 3.5;
  /// Drop flagged runs from the estimate (they stay listed as rejected).
  bool reject_outliers = false;
  /// Run ids to exclude (listed as excluded in the summary).
  std::vector<std::string> exclude_runs;

  /// Empty when valid, else a message naming the bad field.
  std::string Check() const;
};

/// Statistics of one direction's cluster of return errors (eqs. 3.2, 3.3).
struct ClusterStats {
  int n = 0;
  double x_cg_m = 0.0, y_cg_m = 0.0;  ///< eq. 3.2
  double r_cg_m = 0.0;                ///< eq. 3.3
  /// Standard deviation of the return position errors about the centre of
  /// gravity, sqrt(sum |e_i - cg|^2 / (n - 1)); SEM = sigma / sqrt(n).
  double sigma_m = 0.0;
  double sem_m = 0.0;
};

/// alpha, beta and the derived quantities from one coordinate.
struct UmbmarkEstimate {
  double alpha_rad = 0.0;  ///< eq. 4.24a/b (Type A: erroneous rotation per 90 deg turn)
  double beta_rad = 0.0;   ///< eq. 4.20a/b (Type B: heading change per leg)
  double R_m = 0.0;        ///< eq. 4.21 (infinite when beta = 0)
  double E_b = 1.0;        ///< eq. 4.27
  double E_d = 1.0;        ///< eq. 4.22, relative to the recorded diameter ratio
};

struct RunFlag {
  std::string run;
  std::string direction;
  double ex_m = 0.0, ey_m = 0.0;
  std::optional<double> score;  ///< robust outlier score; empty with < 3 runs in the direction or < 6 in all
  bool outlier = false;
  bool excluded = false;  ///< by --exclude-runs
  bool rejected = false;  ///< by --reject-outliers
  bool used() const { return !excluded && !rejected; }
};

struct UmbmarkSummary {
  UmbmarkEstimator estimator = UmbmarkEstimator::kMean;
  double side_m = 0.0;
  ClusterStats cw, ccw;
  double E_max_syst_m = 0.0;  ///< eq. 3.4
  UmbmarkEstimate from_x, from_y;
  /// The estimate used: from_x, from_y, or (kMean) E_d, E_b averaged over
  /// both, alpha and beta averaged likewise.
  UmbmarkEstimate selected;
  double c_L = 1.0;  ///< eq. 4.31
  double c_R = 1.0;  ///< eq. 4.32
  /// |from_x - from_y|: how far the two estimators disagree.
  double spread_E_d = 0.0, spread_E_b = 0.0;
  RobotParams recorded;
  RobotParams corrected;  ///< wheelbase E_b*b, diameters c_L*D_L, c_R*D_R
  /// 3*SEM rule (section 5): the larger SEM of the two directions.
  double sem_m = 0.0;
  /// E_max,syst > 3*SEM: the systematic error stands out of the scatter, so
  /// a (further) compensation pass is worth it.
  bool compensation_worthwhile = false;
  std::vector<RunFlag> runs;
};

/// Runs UMBmark on `errors` (directions must be "cw" or "ccw"; at least one
/// used run of each). Throws InvalidOptions for bad options and InputError
/// for data it cannot use (unknown direction, a direction with no runs).
UmbmarkSummary CalibrateUmbmark(const std::vector<ReturnError>& errors, const RobotParams& recorded,
                                const UmbmarkOptions& options, const std::string& source = "");

/// alpha, beta, R, E_b, E_d from the two centres of gravity along one axis.
/// `x_axis` selects eqs. 4.20a/4.24a (else 4.20b/4.24b). b_for_Ed is the
/// wheelbase used in eq. 4.22 when not taken from the corrected one.
UmbmarkEstimate EstimateFromCentres(double cw_cg, double ccw_cg, bool x_axis, double side_m,
                                    double recorded_wheelbase_m, bool ed_with_corrected_wheelbase);

/// Centre of gravity (eq. 3.2), its radius (eq. 3.3), sigma and SEM of a
/// cluster of return position errors (ex, ey) [m].
ClusterStats ClusterOf(const std::vector<std::pair<double, double>>& errors_m);

/// Correction factors c_L, c_R: CorrectionLeft/Right (model/true_robot.hpp).

/// Corrected parameters relative to `recorded` (wheelbase E_b*b, c_L*D_L, c_R*D_R).
RobotParams ApplyCorrection(const RobotParams& recorded, double E_d, double E_b);

}  // namespace umbmark
