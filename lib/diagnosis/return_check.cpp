// Return-error check of the diagnosis (see return_check.hpp).
#include "diagnosis/return_check.hpp"

#include <cmath>
#include <exception>
#include <map>
#include <utility>

#include <fmt/format.h>

#include "core/angles.hpp"
#include "error_models/wheel_noise_fit.hpp"
#include "error_models/trajectory_covariance.hpp"
#include "kinematics/odometry.hpp"

namespace umbmark::diag {

namespace {

/// Observed and predicted return errors per experiment and direction, and
/// the return-error noise fit on them.
void PredictReturns(const CampaignData& c, const MeanModel& model, const BaselineFit& b, ReturnCheck& out) {
  const ParamVector& p = b.p;
  const NoiseParams& noise = b.noise;
  std::vector<WheelNoiseFitRun> fit_runs;
  std::map<std::pair<int, std::string>, std::vector<int>> groups;
  for (std::size_t r = 0; r < c.runs.size(); ++r) groups[{c.runs[r].experiment, c.runs[r].direction}].push_back(static_cast<int>(r));
  const WheelNoise wn{std::sqrt(noise.kL2), std::sqrt(noise.kR2)};
  for (const auto& [key, runs] : groups) {
    ReturnPrediction rp;
    rp.experiment = key.first;
    rp.direction = key.second;
    std::vector<Eigen::Vector3d> obs;
    for (int ri : runs) {
      const DiagRun& r = c.runs[ri];
      std::size_t g0 = 0, g1 = 0;
      bool any = false;
      for (std::size_t i = 0; i < r.t.size(); ++i)
        if (r.has_gt[i]) {
          if (!any) g0 = i;
          any = true;
          g1 = i;
        }
      if (!any || g1 <= g0) continue;
      Pose2 odo;
      for (std::size_t i = g0; i < g1; ++i)
        odo = DiffDriveStep(odo, r.left[i + 1] - r.left[i], r.right[i + 1] - r.right[i], c.robot.wheelbase_m);
      const std::vector<Pose2> pred = model.PredictRun(ri, p);
      const Pose2 ro = RelativeTo(r.gt[g0], r.gt[g1]);
      const Pose2 rpd = RelativeTo(pred[g0], pred[g1]);
      const Eigen::Vector3d eo(ro.x - odo.x, ro.y - odo.y, r.endpoint && !r.has_heading ? 0.0 : WrapAngle(ro.theta - odo.theta));
      const Eigen::Vector3d ep(rpd.x - odo.x, rpd.y - odo.y, WrapAngle(rpd.theta - odo.theta));
      obs.push_back(eo);
      rp.predicted_mean += ep;
      // Predicted covariance: Kelly's propagation along the run's encoder
      // travel (error_models) plus the ground truth's noise at both ends.
      WheelTravel wt;
      wt.left_m.assign(r.left.begin() + static_cast<std::ptrdiff_t>(g0), r.left.begin() + static_cast<std::ptrdiff_t>(g1 + 1));
      wt.right_m.assign(r.right.begin() + static_cast<std::ptrdiff_t>(g0), r.right.begin() + static_cast<std::ptrdiff_t>(g1 + 1));
      const TrajectoryCovarianceSummary tc = TrajectoryCovariance(wt, c.robot.wheelbase_m * p[kParamEb]);
      WheelNoiseFitRun fr;
      fr.group = fmt::format("exp{}:{}", r.experiment + 1, r.direction);
      fr.run = r.id;
      fr.error = eo;
      fr.has_theta = !r.endpoint || r.has_heading;
      fr.basis = tc.motion;
      fr.measurement = MeasurementCovariance(std::sqrt(noise.sxy2), std::sqrt(noise.sth2), ro);
      fit_runs.push_back(fr);
      Eigen::Matrix3d C = tc.motion.Evaluate(wn);
      C(0, 0) += 2.0 * noise.sxy2;
      C(1, 1) += 2.0 * noise.sxy2;
      C(2, 2) += 2.0 * noise.sth2;
      rp.predicted_cov += C;
    }
    rp.runs = static_cast<int>(obs.size());
    if (rp.runs == 0) continue;
    rp.predicted_mean /= rp.runs;
    rp.predicted_cov /= rp.runs;
    for (const auto& v : obs) rp.observed_mean += v;
    rp.observed_mean /= rp.runs;
    if (rp.runs > 1) {
      for (const auto& v : obs) rp.observed_cov += (v - rp.observed_mean) * (v - rp.observed_mean).transpose();
      rp.observed_cov /= rp.runs - 1;
    }
    out.returns.push_back(rp);
  }
  try {
    const WheelNoiseFitSummary nf = umbmark::FitWheelNoise(fit_runs);
    out.return_fit = true;
    out.return_k_L = nf.k_L;
    out.return_k_R = nf.k_R;
    out.return_k_L_ci = nf.k_L_ci;
    out.return_k_R_ci = nf.k_R_ci;
  } catch (const std::exception& e) {
    out.return_fit_note = std::string("fit-noise on return errors not available: ") + e.what();
  }
}

/// RMS of the piece residuals per segment type, observed and predicted.
void Growth(const CampaignData& c, const BaselineFit& b, ReturnCheck& out) {
  const NoiseParams& noise = b.noise;
  const std::size_t n = c.pieces.size();
  for (PieceType t : {PieceType::kStraight, PieceType::kTurn, PieceType::kArc, PieceType::kStand, PieceType::kReturn}) {
    GrowthRow g;
    g.type = t;
    Eigen::Vector3d so = Eigen::Vector3d::Zero(), sp = Eigen::Vector3d::Zero();
    for (std::size_t j = 0; j < n; ++j) {
      if (c.pieces[j].type != t) continue;
      ++g.pieces;
      g.mean_travel_m += c.pieces[j].travel_m;
      const Eigen::Matrix3d C = PieceCovariance(b.bases[j], noise);
      for (int k = 0; k < 3; ++k) {
        so[k] += b.eps[3 * j + k] * b.eps[3 * j + k];
        sp[k] += C(k, k);
      }
    }
    if (g.pieces == 0) continue;
    g.mean_travel_m /= g.pieces;
    g.observed_rms = (so / g.pieces).cwiseSqrt();
    g.predicted_rms = (sp / g.pieces).cwiseSqrt();
    out.growth.push_back(g);
  }
}

}  // namespace

ReturnCheck CheckReturns(const CampaignData& c, const MeanModel& model, const BaselineFit& baseline) {
  ReturnCheck out;
  PredictReturns(c, model, baseline, out);
  Growth(c, baseline, out);
  return out;
}

}  // namespace umbmark::diag
