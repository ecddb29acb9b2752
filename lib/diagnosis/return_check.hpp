// Stage "return-error check" of the diagnosis: the fitted baseline seen the
// way a calibration engineer sees a campaign -- predicted vs observed return
// errors (mean, covariance) per experiment and direction, a cross-check of
// k_L, k_R by the return-error noise estimator (error_models/wheel_noise_fit.hpp),
// and the residual growth per segment type.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "diagnosis/baseline.hpp"

namespace umbmark::diag {

/// Predicted vs observed return errors of one experiment and direction.
struct ReturnPrediction {
  int experiment = 0;
  std::string direction;
  int runs = 0;
  Eigen::Vector3d observed_mean = Eigen::Vector3d::Zero(), predicted_mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d observed_cov = Eigen::Matrix3d::Zero(), predicted_cov = Eigen::Matrix3d::Zero();
};

/// Residual growth per segment type: RMS of the piece residuals, observed
/// and predicted by the baseline.
struct GrowthRow {
  PieceType type = PieceType::kStraight;
  int pieces = 0;
  double mean_travel_m = 0.0;
  Eigen::Vector3d observed_rms = Eigen::Vector3d::Zero(), predicted_rms = Eigen::Vector3d::Zero();
};

struct ReturnCheck {
  std::vector<ReturnPrediction> returns;
  std::vector<GrowthRow> growth;
  /// k_L, k_R from the runs' return errors alone (fit-noise's estimator:
  /// systematic mean per experiment and direction, Kelly's covariance along
  /// each run, the ground truth's noise), with 95 % profile intervals.
  /// Absent when that fit cannot run (too few runs per group); a
  /// disagreement with the piece estimate says the noise does not grow with
  /// distance as eq. 4 has it.
  bool return_fit = false;
  double return_k_L = 0.0, return_k_R = 0.0;
  std::array<double, 2> return_k_L_ci{0.0, 0.0}, return_k_R_ci{0.0, 0.0};
  std::string return_fit_note;
};

ReturnCheck CheckReturns(const CampaignData& c, const MeanModel& model, const BaselineFit& baseline);

}  // namespace umbmark::diag
